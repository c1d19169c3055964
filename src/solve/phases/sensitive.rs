//! The motion with the forward sensitivities of every phase's end ([`Walker::sensitive_motion`]):
//! every phase integrated with `S = dy/dp` riding along ([`forward`]), `S` carried across each
//! phase boundary by the jump of the accelerations there and across each impact by its
//! saltation matrix ([`saltation`]), and each end's time, angle and rate differentiated in every
//! parameter. The accumulation time of a converging (Zeno) sequence is differentiated through
//! the geometric series over its last four impacts' times ([`zeno::extrapolate_derivatives`]),
//! and the motion goes on through the impact that closes it as through any other.

use super::zeno::{self, ZENO_AGREE};
use super::{MAX_PHASES, Motion, PhaseStart, Route, Walker};
use crate::results::EndCause;
use std::collections::BTreeMap;

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::integrated::contacts;
use crate::solve::integrated::forward::{self, Forward, Grazing};
use crate::solve::integrated::saltation::{self, Crossing, SaltationGap};
use crate::solve::integrated::unreduced::EndSensitivity;

/// How one phase's end moves with the parameters (one value per parameter each).
#[derive(Debug, Clone, PartialEq)]
pub struct EndDerivatives {
    /// `d t_end/dp` (the absolute time from release).
    pub t: Vec<f64>,
    /// `d theta_end/dp`, the reduced coordinate at the end (empty for a system with none).
    pub theta: Vec<f64>,
    /// `d theta_dot_end/dp`, its rate at the end (before any jump there; empty likewise).
    pub theta_dot: Vec<f64>,
    /// `dt/dp` of each switch of the friction modes inside the phase, in order (absolute
    /// times, as `t`).
    pub switches: Vec<Vec<f64>>,
}

/// The motion on the integrated route with the derivatives of its phases' ends.
#[derive(Debug, Clone)]
pub struct SensitiveMotion<'m> {
    /// The motion, to its end or to where it stopped ([`SensitiveMotion::stop`]).
    pub motion: Motion<'m>,
    /// Per phase of [`SensitiveMotion::motion`], its end's derivatives, or the grazing event
    /// (its own or one before it) whose time has none.
    pub ends: Vec<Result<EndDerivatives, Grazing>>,
    /// Why the motion stopped before its end, if it did: the phases after are not solved.
    pub stop: Option<Stop>,
    /// Per impact of [`SensitiveMotion::motion`] that closes a converging (Zeno) sequence (its
    /// index in `motion.impacts`): `d t_limit/dp` of its accumulation time, where the
    /// sequence's last four times give it (a geometric series through them agrees with the
    /// accumulation time to [`ZENO_AGREE`] of the time left).
    pub accumulation: BTreeMap<usize, Vec<f64>>,
    /// Per parameter (by index) whose derivatives an impact left one-sided (a plastic contact
    /// whose restitution is that parameter, [`saltation::one_sided`]): the time of the first
    /// such impact (s from release). What comes after it has no derivative in that parameter.
    pub one_sided: BTreeMap<usize, f64>,
}

/// Why the motion with sensitivities stopped before its end.
#[derive(Debug, Clone, PartialEq)]
pub enum Stop {
    /// At an impact whose map has no derivatives (why: the gap).
    Impact(SaltationGap),
    /// At a grazing event, past which `S` is not defined.
    Grazing,
    /// A later phase failed (the first phase's error is the motion's).
    Failed(SolveError),
}

/// The derivatives of a phase's end from its sensitivities (`reduced`: the reduced
/// coordinate's index, where the system has one; `qd` the velocities at the end).
fn derivatives(
    sens: &EndSensitivity,
    reduced: Option<usize>,
    qd: &[f64],
) -> Result<EndDerivatives, Grazing> {
    let dt = sens.dt.clone()?;
    let switches = (sens.switches.iter().cloned()).collect::<Result<Vec<_>, _>>()?;
    let n = qd.len();
    let (theta, theta_dot) = match reduced {
        Some(r) => (sens.s.chunks_exact(2 * n).zip(&dt))
            .map(|(col, dt)| (col[r] + qd[r] * dt, col[n + r] + sens.qdd[r] * dt))
            .unzip(),
        None => (Vec::new(), Vec::new()),
    };
    Ok(EndDerivatives {
        t: dt,
        theta,
        theta_dot,
        switches,
    })
}

/// What follows a phase of the motion with sensitivities.
enum Next {
    /// The next phase's start, with `S` there.
    Go(PhaseStart, Vec<f64>),
    /// The motion ends here, complete or for the reason given.
    Stop(Option<Stop>),
}

impl<'m> Walker<'m> {
    /// The motion from release on the integrated route, with the derivatives of every phase's
    /// end in every parameter (a model without
    /// [`Model::tangents`](crate::model::Model::tangents) is
    /// [`SystemError::NoTangents`](crate::system::SystemError::NoTangents), as is any error
    /// of the first phase). It goes on through impacts as the run does, and stops early
    /// ([`SensitiveMotion::stop`]) at an impact whose map has no derivatives, at a grazing
    /// event, or where a later phase fails.
    pub fn sensitive_motion(&self, work: &mut Work) -> Result<SensitiveMotion<'m>, SolveError> {
        let walker = (self.clone())
            .with_route(Route::Integrated)
            .with_dense_output(false);
        let general = &walker.general;
        let (mut start, opened) = walker.release()?;
        let mut s = Forward::new(general)?.initial(general)?;
        let (run, mut sens) = walker.integrate_sensitive(&start, s, work)?;
        let mut ends = Vec::new();
        let mut accumulation = BTreeMap::new();
        let mut motion = Motion::starting(run, opened, walker.until.is_some());
        loop {
            let next = walker.next_sensitive(&mut motion, &mut ends, &mut accumulation, sens);
            let stop = match next {
                Ok(Next::Go(next, s_next)) => {
                    (start, s) = (next, s_next);
                    match walker.integrate_sensitive(&start, s, work) {
                        Ok((run, sens_next)) => {
                            motion.phases.push(run);
                            sens = sens_next;
                            continue;
                        }
                        Err(e) => Some(Stop::Failed(e)),
                    }
                }
                Ok(Next::Stop(stop)) => stop,
                Err(e) => Some(Stop::Failed(e)),
            };
            let mut one_sided = BTreeMap::new();
            for at in &motion.impacts {
                for p in saltation::one_sided(general, &at.impact) {
                    one_sided.entry(p).or_insert(at.t);
                }
            }
            return Ok(SensitiveMotion {
                motion,
                ends,
                stop,
                accumulation,
                one_sided,
            });
        }
    }

    /// The derivatives of the end of `motion`'s last phase (into `ends`) from its
    /// sensitivities `sens`, and what follows it (an impact there is resolved and added to
    /// `motion`, `S` carried across it).
    fn next_sensitive(
        &self,
        motion: &mut Motion<'m>,
        ends: &mut Vec<Result<EndDerivatives, Grazing>>,
        accumulation: &mut BTreeMap<usize, Vec<f64>>,
        sens: EndSensitivity,
    ) -> Result<Next, SolveError> {
        let general = &self.general;
        let Some(last) = motion.phases.last() else {
            return Ok(Next::Stop(None));
        };
        let end_state = last.full_end_state()?;
        let reduced = general.info().reduced_index;
        let end = derivatives(&sens, reduced, &end_state.qd);
        let dt = end.as_ref().ok().map(|e| e.t.clone());
        ends.push(end);
        if motion.complete() {
            return Ok(Next::Stop(None));
        }
        let Some(dt) = dt else {
            return Ok(Next::Stop(Some(Stop::Grazing)));
        };
        let since = motion.phases.len() - motion.impacts.last().map_or(0, |i| i.phase + 1);
        if since >= MAX_PHASES {
            return Err(SolveError::TooManyPhases { limit: MAX_PHASES });
        }
        if let Some(EndCause::Contact(i)) = motion.last_end() {
            return self.sensitive_impact(
                motion,
                i.index,
                (end_state, sens, dt),
                ends,
                accumulation,
            );
        }
        let next = match self.after(last) {
            Ok(next) => next,
            // Another contact closes as this one opens: an impact.
            Err(e @ SolveError::ImpactAtRelease { contact, .. }) => {
                let info = general.info();
                let Some(j) = info.contacts.iter().position(|c| c.name == contact) else {
                    return Err(e);
                };
                return self.sensitive_impact(motion, j, (end_state, sens, dt), ends, accumulation);
            }
            Err(e) => return Err(e),
        };
        // `S` across the boundary: the accelerations jump to the next active set's.
        let after = contacts::dynamics(general, &next.state, &next.active, next.t)?;
        let mut s = sens.s;
        forward::jump(&mut s, &sens.qdd, &after.qdd, &dt);
        Ok(Next::Go(next, s))
    }

    /// The impact where contact `closing` closes at the end of `motion`'s last phase (its
    /// state there, its sensitivities and `dt/dp` of its end in `before`), resolved as the run
    /// resolves it and added to `motion`, and `S` carried across it by its saltation matrix;
    /// where it closes a converging sequence, its accumulation time's derivatives into
    /// `accumulation` (from the derivatives of the ends so far, `ends`).
    fn sensitive_impact(
        &self,
        motion: &mut Motion<'m>,
        closing: usize,
        before: (crate::system::State, EndSensitivity, Vec<f64>),
        ends: &[Result<EndDerivatives, Grazing>],
        accumulation: &mut BTreeMap<usize, Vec<f64>>,
    ) -> Result<Next, SolveError> {
        let (state, sens, dt) = before;
        let friction_work = motion.phases.last().map_or(0.0, |p| p.friction_work());
        let through = self.through_impact(motion, closing, friction_work)?;
        let Some((k, at)) = motion.impacts.iter().enumerate().next_back() else {
            return Ok(Next::Stop(None));
        };
        if let Some(d) = accumulation_derivatives(&motion.impacts, ends, &dt, self.tol) {
            accumulation.insert(k, d);
        }
        let Some(start) = through else {
            // Halted: too many impacts, or at rest after it.
            return Ok(Next::Stop(None));
        };
        let after = contacts::dynamics(&self.general, &start.state, &start.active, start.t)?;
        let laws = saltation::laws(&at.impact);
        let crossing = Crossing {
            before: &state,
            impact: &at.impact,
            laws: &laws,
            qdd_before: &sens.qdd,
            qdd_after: &after.qdd,
            dt: &dt,
        };
        let mut s = sens.s;
        Ok(match saltation::cross(&self.general, &crossing, &mut s)? {
            Ok(()) => Next::Go(start, s),
            Err(gap) => Next::Stop(Some(Stop::Impact(gap))),
        })
    }
}

/// `d t_limit/dp` of the accumulation time of the converging sequence that the last of
/// `impacts` closes (`dt` the derivatives of its own time, `ends` those of every phase's end
/// before it): the geometric series through the sequence's last four times
/// ([`zeno::extrapolate_derivatives`]), where that series agrees with the accumulation time
/// listed to [`ZENO_AGREE`] of the time left (or to `tol` of the time); `None` for an impact
/// that closes no sequence, one with fewer than four times, or one the series does not fit.
fn accumulation_derivatives(
    impacts: &[super::ImpactAt],
    ends: &[Result<EndDerivatives, Grazing>],
    dt: &[f64],
    tol: f64,
) -> Option<Vec<f64>> {
    let (last, before) = impacts.split_last()?;
    let t_limit = last.zeno?;
    let sequence = zeno::sequence(before, last.closing, last.t);
    let (series, _) = zeno::extrapolate(&sequence.times)?;
    let left = t_limit - last.t;
    if (series - t_limit).abs() > (ZENO_AGREE * left).max(tol * t_limit) {
        return None;
    }
    let [a, b, c] = *sequence.listed.last_chunk::<3>()?;
    let of = |i: usize| -> Option<&[f64]> {
        let end = ends.get(before[i].phase)?.as_ref().ok()?;
        Some(end.t.as_slice())
    };
    zeno::extrapolate_derivatives(&sequence.times, [of(a)?, of(b)?, of(c)?, dt])
}
