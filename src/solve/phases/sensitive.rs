//! The motion with the forward sensitivities of every phase's end ([`Walker::sensitive_motion`]):
//! every phase integrated with `S = dy/dp` riding along ([`forward`]), `S` carried across each
//! phase boundary by the jump of the accelerations there, and each end's time, angle and rate
//! differentiated in every parameter. The derivatives of an impact's map are not built: the
//! motion stops at its first impact, and the phases after it have none.

use super::{MAX_PHASES, Motion, Route, Walker};
use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::contacts;
use crate::solve::forward::{self, Forward, Grazing};
use crate::solve::unreduced::{End, EndSensitivity};

/// How one phase's end moves with the parameters (one value per parameter each).
#[derive(Debug, Clone, PartialEq)]
pub struct EndDerivatives {
    /// `d t_end/dp` (the absolute time from release).
    pub t: Vec<f64>,
    /// `d theta_end/dp`, the reduced coordinate at the end.
    pub theta: Vec<f64>,
    /// `d theta_dot_end/dp`, its rate at the end (before any jump there).
    pub theta_dot: Vec<f64>,
    /// `dt/dp` of each switch of the friction modes inside the phase, in order (absolute
    /// times, as `t`).
    pub switches: Vec<Vec<f64>>,
}

/// The motion on the integrated route with the derivatives of its phases' ends.
#[derive(Debug, Clone)]
pub struct SensitiveMotion<'m> {
    /// The motion, to its end or to its first impact.
    pub motion: Motion<'m>,
    /// Per phase of [`SensitiveMotion::motion`], its end's derivatives, or the grazing event
    /// (its own or one before it) whose time has none.
    pub ends: Vec<Result<EndDerivatives, Grazing>>,
    /// Whether the motion stopped at an impact it would have gone on through: the phases after
    /// it are not solved.
    pub stopped_at_impact: bool,
}

/// The derivatives of a phase's end from its sensitivities (`reduced`: the reduced
/// coordinate's index; `qd` the velocities at the end).
fn derivatives(
    sens: &EndSensitivity,
    reduced: usize,
    qd: &[f64],
) -> Result<EndDerivatives, Grazing> {
    let dt = sens.dt.clone()?;
    let switches = (sens.switches.iter().cloned()).collect::<Result<Vec<_>, _>>()?;
    let n = qd.len();
    let (theta, theta_dot) = (sens.s.chunks_exact(2 * n).zip(&dt))
        .map(|(col, dt)| {
            (
                col[reduced] + qd[reduced] * dt,
                col[n + reduced] + sens.qdd[reduced] * dt,
            )
        })
        .unzip();
    Ok(EndDerivatives {
        t: dt,
        theta,
        theta_dot,
        switches,
    })
}

impl<'m> Walker<'m> {
    /// The motion from release on the integrated route, with the derivatives of every phase's
    /// end in every parameter (a model without
    /// [`Model::tangents`](crate::model::Model::tangents) is
    /// [`SystemError::NoTangents`](crate::system::SystemError::NoTangents)). It stops at the
    /// first impact it would go on through, and at a grazing event (the phases after that have
    /// no sensitivities).
    pub fn sensitive_motion(&self, work: &mut Work) -> Result<SensitiveMotion<'m>, SolveError> {
        let walker = Walker {
            route: Route::Integrated,
            dense_output: false,
            ..self.clone()
        };
        let general = &walker.general;
        let reduced = general.info().reduced_index;
        let (mut start, opened) = walker.release()?;
        let mut s = Forward::new(general)?.initial(general)?;
        let mut motion: Option<Motion<'m>> = None;
        let mut ends = Vec::new();
        loop {
            let (run, sens) = walker.integrate_sensitive(&start, s, work)?;
            let end_state = run.full_end_state()?;
            let end = derivatives(&sens, reduced, &end_state.qd);
            let dt = end.as_ref().ok().map(|e| e.t.clone());
            ends.push(end);
            let motion = match motion.as_mut() {
                Some(m) => {
                    m.phases.push(run);
                    m
                }
                None => motion.insert(Motion::starting(
                    run,
                    opened.clone(),
                    walker.until.is_some(),
                )),
            };
            let last = motion.phases.last();
            let closes = matches!(motion.last_end(), Some(End::Contact(_)));
            let next = match (dt, last) {
                (Some(dt), Some(last)) if !motion.complete() && !closes => {
                    if motion.phases.len() >= MAX_PHASES {
                        return Err(SolveError::TooManyPhases { limit: MAX_PHASES });
                    }
                    match walker.after(last) {
                        Ok(next) => Some((next, dt)),
                        // Another contact closes as this one opens: an impact.
                        Err(SolveError::ImpactAtRelease { .. }) => None,
                        Err(e) => return Err(e),
                    }
                }
                _ => None,
            };
            let Some((next, dt)) = next else {
                let stopped_at_impact =
                    !motion.complete() && ends.last().is_some_and(Result::is_ok);
                return Ok(SensitiveMotion {
                    motion: motion.clone(),
                    ends,
                    stopped_at_impact,
                });
            };
            // `S` across the boundary: the accelerations jump to the next active set's.
            let after = contacts::dynamics(general, &next.state, &next.active, next.t)?;
            s = sens.s;
            forward::jump(&mut s, &sens.qdd, &after.qdd, &dt);
            start = next;
        }
    }
}
