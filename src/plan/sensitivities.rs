//! The quantity `sensitivities`: `d(<result>)/d(<parameter>)` and the elasticities
//! `(p/x) dx/dp` of every wanted result that has them, for every parameter: the separation
//! angle and time, every contact's end (time and angle), the floor impact (time and angular
//! velocity). The first contact's separation on the fast phase the motion starts on has them
//! from the fast path's generated partial derivatives (`solve::fast::sensitivity`); every other
//! from the motion integrated with its forward sensitivities (`Walker::sensitive_motion`),
//! whose event is held to the run's: the same contact ending by the same cause, at a time
//! within [`ROUTES_AGREE`]; every impact's time (`impact_<i>_time`, `i` from 1) from the same
//! motion, carried through every impact by its saltation matrix. Where a result has none (past
//! a converging Zeno sequence's limit, at a grazing event, an impact's impulses and energy), a
//! note says why, never a number.

use super::quantities::{Fate, fate, landing};
use super::{DEFAULT_TOLERANCE, ODE_RTOL_FACTOR, Plan};
use crate::model::start_offsets;
use crate::quantity::Quantity;
use crate::results::EndCause;
use crate::results::{Note, RunResults, Sensitivity, SensitivityGap};
use crate::solve::SolveError;
use crate::solve::fast::prior::{PRIOR_TOL, Prior};
use crate::solve::fast::quadrature::ACCEPT;
use crate::solve::fast::sensitivity::{self, SensitivityWork, SeparationPoint};
use crate::solve::phases::{Motion, SensitiveMotion, Stop};
use crate::spec::units::{AngularUnit, UnitError};
use crate::system::SystemError;

/// A result the sensitivities are of: its key, unit and whether it is an angle.
struct Target {
    key: String,
    unit: &'static str,
    angle: bool,
}

/// The keys of the note that says why `key` has no sensitivities.
fn note_key(key: &str) -> String {
    format!("sensitivities.{key}")
}

/// `result` over `parameter` as a unit: `rad/kg`, `s^3/m`, `rad s^2/m`, `rad s/m` (an angular
/// rate over an acceleration), `1` (an angle over an angle). The radian is kept as a factor
/// ([`AngularUnit`]), which the SI algebra drops as dimensionless.
pub fn per(result: &str, parameter: &str) -> Result<String, UnitError> {
    let quotient = AngularUnit::parse(result)?.checked_div(AngularUnit::parse(parameter)?)?;
    Ok(quotient.to_string())
}

/// The relative difference of an event's time on the integrated route that carries the
/// sensitivities from the run's own, past which the two are not the same event: this, or
/// [`ROUTES_AGREE_PER_TOLERANCE`] times the run's tolerance where that is larger (a loose
/// tolerance's fast path may be off by about the tolerance).
pub const ROUTES_AGREE: f64 = 1e-6;

/// See [`ROUTES_AGREE`].
pub const ROUTES_AGREE_PER_TOLERANCE: f64 = 100.0;

/// Where a target's derivatives come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    /// The first contact's separation (fast path where it has one).
    Separation,
    /// Contact `i`'s end (the first contact's from the fast path where it has one).
    End(usize),
    /// The landing.
    Floor,
}

/// The derivatives of one result, or why there are none.
/// A result's derivatives from the integrated route, with the result's time (s from release).
type Timed = Result<(Vec<f64>, f64), SensitivityGap>;

impl<'m> Plan<'m> {
    /// The sensitivities of every wanted result that has them, and notes for the others.
    pub(super) fn sensitivities(
        &mut self,
        want: &[Quantity],
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let info = self.general().info();
        let mut targets: Vec<(Target, Source)> = Vec::new();
        let target = |key: String, unit: &'static str, angle: bool| Target { key, unit, angle };
        for q in want {
            match q {
                Quantity::SeparationAngle => targets.push((
                    target("separation_angle".into(), "rad", true),
                    Source::Separation,
                )),
                Quantity::SeparationTime => targets.push((
                    target("separation_time".into(), "s", false),
                    Source::Separation,
                )),
                Quantity::ContactEnd => {
                    for (i, c) in info.contacts.iter().enumerate() {
                        let mut keys = vec![format!("{}_end", c.name)];
                        if i == 0 {
                            keys.insert(0, "contact_end".into());
                        }
                        for key in keys {
                            let time = target(format!("{key}_time"), "s", false);
                            targets.push((time, Source::End(i)));
                            let angle = target(format!("{key}_angle"), "rad", true);
                            targets.push((angle, Source::End(i)));
                        }
                    }
                }
                Quantity::FloorImpact => {
                    targets.push((
                        target("floor_impact_time".into(), "s", false),
                        Source::Floor,
                    ));
                    let rate = target("impact_angular_velocity".into(), "rad/s", false);
                    targets.push((rate, Source::Floor));
                }
                Quantity::Impacts => {
                    self.impact_sensitivities(out)?;
                    let gap = Note::NoSensitivity(SensitivityGap::NotBuilt);
                    out.notes.insert(note_key(&q.name(info)), gap);
                }
                _ => {}
            }
        }
        let fast = self.separation_sensitivities()?;
        for (target, source) in &targets {
            let Some(x) = out.results.get(&target.key).map(|r| r.value) else {
                // The run has no such number (a contact that holds or never closes): its
                // own note says why.
                continue;
            };
            let first = matches!(source, Source::Separation | Source::End(0));
            // The fast path's where it has them; where it lacks the partial derivatives (or
            // the time's fall polynomial), the integrated route's.
            let exact = match (&fast, first) {
                (Some(Ok(found)), true) => match (target.angle, &found.d_t) {
                    (true, _) => Some(Ok(found.d_theta.clone())),
                    (false, Ok(d_t)) => Some(Ok(d_t.clone())),
                    (false, Err(SensitivityGap::NoFallPolynomial)) => None,
                    (false, Err(gap)) => Some(Err(*gap)),
                },
                (Some(Err(SensitivityGap::NoPartials)), true) => None,
                (Some(Err(gap)), true) => Some(Err(*gap)),
                _ => None,
            };
            // The fast path's results come before any impact.
            let (found, integrated) = match exact {
                Some(found) => (found.map(|d| (d, f64::NEG_INFINITY)), false),
                None => (self.integrated_derivatives(target, *source)?, true),
            };
            match found.and_then(|(d, t)| self.record(target, (x, &d, t), integrated, out)) {
                Ok(()) => {}
                Err(gap) => {
                    out.notes
                        .insert(note_key(&target.key), Note::NoSensitivity(gap));
                }
            }
        }
        Ok(())
    }

    /// The derivatives of `target` from the motion integrated with its forward
    /// sensitivities, its event held to the run's.
    fn integrated_derivatives(
        &mut self,
        target: &Target,
        source: Source,
    ) -> Result<Timed, SolveError> {
        let general = self.general().clone();
        let contact = match source {
            Source::Separation => 0,
            Source::End(i) => i,
            Source::Floor => usize::MAX,
        };
        // The run's own event: a contact's end, or the landing.
        let run_event = if source == Source::Floor {
            let motion = self.complete()?;
            landing(motion, &general)?.map(|k| (motion.phases[k].t_end(), EndCause::Floor))
        } else {
            match self.fate(contact)? {
                Fate::Ended { t: 0.0, .. } => return Ok(Err(SensitivityGap::AtRelease)),
                Fate::Ended { t, cause, .. } => Some((t, cause)),
                _ => None,
            }
        };
        let Some((t_run, cause_run)) = run_event else {
            return Ok(Err(SensitivityGap::NoSeparation));
        };
        let agree = ROUTES_AGREE.max(ROUTES_AGREE_PER_TOLERANCE * self.walker.tol);
        let sensitive = match self.sensitive() {
            Ok(s) => s,
            Err(gap) => return Ok(Err(gap)),
        };
        let event = if source == Source::Floor {
            landing(&sensitive.motion, &general)?.map(|k| (k, EndCause::Floor))
        } else {
            match fate(&sensitive.motion, &general, contact)? {
                Some(Fate::Ended { t, cause, .. }) => (sensitive.motion.phases.iter())
                    .position(|p| p.t_end() == t)
                    .map(|k| (k, cause)),
                _ => None,
            }
        };
        let Some((k, cause)) = event else {
            return Ok(Err(stop_gap(&sensitive.stop)));
        };
        let t = sensitive.motion.phases[k].t_end();
        if cause != cause_run || (t - t_run).abs() > agree * t_run.abs() {
            return Ok(Err(SensitivityGap::RoutesDisagree));
        }
        Ok(match &sensitive.ends[k] {
            Err(_) => Err(SensitivityGap::Grazing),
            Ok(d) if target.key == "impact_angular_velocity" => Ok((d.theta_dot.clone(), t)),
            Ok(d) if target.angle => Ok((d.theta.clone(), t)),
            Ok(d) => Ok((d.t.clone(), t)),
        })
    }

    /// `d(impact_<i>_time)/dp` (`i` from 1) of every impact of the run, from the motion
    /// integrated with its forward sensitivities, each impact held to the run's: the same
    /// closing contact, at a time within [`ROUTES_AGREE`]. An impact with none has a note.
    fn impact_sensitivities(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let run = impact_events(self.complete()?);
        let agree = ROUTES_AGREE.max(ROUTES_AGREE_PER_TOLERANCE * self.walker.tol);
        for (k, ran) in run.into_iter().enumerate() {
            let key = format!("impact_{}_time", k + 1);
            let found = match self.sensitive() {
                Err(gap) => Err(gap),
                Ok(sensitive) => match impact_events(&sensitive.motion).get(k) {
                    Some(at) if at.zeno != ran.zeno => Err(SensitivityGap::RoutesDisagree),
                    Some(at) if at.zeno => match sensitive.accumulation.get(&k) {
                        Some(d)
                            if at.closing == ran.closing
                                && (at.t - ran.t).abs() <= agree * ran.t =>
                        {
                            Ok(d.clone())
                        }
                        Some(_) => Err(SensitivityGap::RoutesDisagree),
                        None => Err(SensitivityGap::PastZeno),
                    },
                    Some(at)
                        if at.closing != ran.closing || (at.t - ran.t).abs() > agree * ran.t =>
                    {
                        Err(SensitivityGap::RoutesDisagree)
                    }
                    Some(at) => match sensitive.ends.get(at.phase) {
                        Some(Ok(d)) => Ok(d.t.clone()),
                        _ => Err(SensitivityGap::Grazing),
                    },
                    None => Err(stop_gap(&sensitive.stop)),
                },
            };
            let t_run = ran.t;
            let target = Target {
                key,
                unit: "s",
                angle: false,
            };
            match found.and_then(|d| self.record(&target, (t_run, &d, t_run), true, out)) {
                Ok(()) => {}
                Err(gap) => {
                    out.notes
                        .insert(note_key(&target.key), Note::NoSensitivity(gap));
                }
            }
        }
        Ok(())
    }

    /// The motion integrated with its forward sensitivities (solved once, at the run's
    /// tolerance or the default one where that is tighter), or why there is none.
    fn sensitive(&mut self) -> Result<&SensitiveMotion<'m>, SensitivityGap> {
        if self.sensitive.is_none() {
            // Never looser than the default run's: at a loose tolerance the integrated route
            // may meet events the run does not have (a contact that just opened touching
            // again within the integration's error).
            let mut walker = self.walker.clone();
            walker.tol = walker.tol.min(DEFAULT_TOLERANCE);
            walker.rtol = walker.rtol.min(DEFAULT_TOLERANCE * ODE_RTOL_FACTOR);
            let solved = walker.sensitive_motion(&mut self.work);
            self.sensitive = Some(solved.map_err(|e| match e {
                SolveError::System(SystemError::NoTangents { .. }) => SensitivityGap::NoPartials,
                _ => SensitivityGap::IntegrationFailed,
            }));
        }
        match &self.sensitive {
            Some(Ok(s)) => Ok(s),
            Some(Err(gap)) => Err(*gap),
            None => Err(SensitivityGap::IntegrationFailed),
        }
    }

    /// `d(target)/dp` and its elasticity for every parameter, from `x`, its derivatives and
    /// its time `t` (`integrated`: by the integrated route); a parameter whose derivatives an
    /// impact before `t` left one-sided ([`SensitiveMotion::one_sided`]) gets a note under
    /// `sensitivities.d(<target>)/d(<p>)` instead.
    /// [`SensitivityGap::NoUnit`], recording nothing, where a unit cannot be formed.
    fn record(
        &self,
        target: &Target,
        x: (f64, &[f64], f64),
        integrated: bool,
        out: &mut RunResults,
    ) -> Result<(), SensitivityGap> {
        let (x, dx, t) = x;
        let one_sided = |j: usize| match &self.sensitive {
            Some(Ok(s)) => s.one_sided.get(&j).is_some_and(|&at| at < t),
            _ => false,
        };
        let info = self.general().info();
        let p = self.general().p();
        let units = (info.parameters.iter())
            .map(|param| per(target.unit, param.unit))
            .collect::<Result<Vec<String>, _>>()
            .map_err(|_| SensitivityGap::NoUnit)?;
        let each = info.parameters.iter().zip(p).zip(dx).zip(units);
        for (j, (((param, &value), &d), unit)) in each.enumerate() {
            let key = format!("d({})/d({})", target.key, param.name);
            if one_sided(j) {
                let gap = Note::NoSensitivity(SensitivityGap::OneSided);
                out.notes.insert(note_key(&key), gap);
                continue;
            }
            let entry = |value: f64, unit: String, elasticity: bool| Sensitivity {
                value,
                unit,
                of: target.key.clone(),
                parameter: param.name.to_string(),
                elasticity,
                integrated,
            };
            out.sensitivities.insert(key, entry(d, unit, false));
            out.sensitivities.insert(
                format!("elasticity({};{})", target.key, param.name),
                entry(value / x * d, "1".into(), true),
            );
        }
        Ok(())
    }

    /// The first contact's separation on the fast phase the motion starts on with its
    /// sensitivities, or why there are none; `None` where it does not separate there (it
    /// ends otherwise, or on an integrated phase).
    fn separation_sensitivities(
        &mut self,
    ) -> Result<Option<Result<Found, SensitivityGap>>, SolveError> {
        let Fate::Ended {
            t,
            cause: EndCause::Force(_),
            ..
        } = self.fate(0)?
        else {
            return Ok(None);
        };
        if t == 0.0 {
            return Ok(Some(Err(SensitivityGap::AtRelease)));
        }
        let Some(sys) = self.fast()? else {
            return Ok(None);
        };
        let end = self.end()?;
        let (true, Some(at)) = (end.end.is_force_of(0), end.at) else {
            // The first contact separates on a later phase, which is integrated.
            return Ok(None);
        };
        let layout = sys.layout();
        let k = sys.k();
        let (si, ci) = (k[layout.k_sin_initial], k[layout.k_cos_initial]);
        let (_, _, drop, _) = start_offsets(sys.theta_initial(), si, ci, at.delta);
        let np = sys.info().parameters.len();
        let point = SeparationPoint {
            red: sys.reduction(),
            k,
            parameters: np,
            sin_initial: si,
            scale: ci * ci / (1.0 + si),
            fall: sys.fall_coefficients(),
            singularities: None,
            sin_sep: at.sin_theta,
            drop,
        };
        let (mut d_theta, mut d_t) = (vec![0.0; np], vec![0.0; np]);
        let prior = Prior::new(PRIOR_TOL);
        let tol = ACCEPT.min(self.walker.tol);
        let mut work = SensitivityWork::default();
        let outcome =
            sensitivity::separation(&point, &prior, tol, &mut work, &mut d_theta, &mut d_t)?;
        let d_t = match outcome {
            Ok(()) => Ok(d_t),
            // The angle's are there; the time's need the fall polynomial.
            Err(SensitivityGap::NoFallPolynomial) => Err(SensitivityGap::NoFallPolynomial),
            Err(why) => return Ok(Some(Err(why))),
        };
        Ok(Some(Ok(Found { d_theta, d_t })))
    }
}

/// An impact of a motion, as its time's sensitivities are matched.
struct ImpactEvent {
    /// Its time as listed (a Zeno limit's accumulation time).
    t: f64,
    closing: usize,
    /// Whether it closes a Zeno sequence.
    zeno: bool,
    /// The phase that ended with it.
    phase: usize,
}

/// The impacts of `motion` in order, with the one that ends it where it does not go on
/// through impacts (a contact that closes ends a run without `until`).
fn impact_events(motion: &Motion) -> Vec<ImpactEvent> {
    let mut events: Vec<ImpactEvent> = (motion.impacts.iter())
        .map(|i| ImpactEvent {
            t: i.zeno.unwrap_or(i.t),
            closing: i.closing,
            zeno: i.zeno.is_some(),
            phase: i.phase,
        })
        .collect();
    if let (false, Some(EndCause::Contact(closing))) = (motion.through_impacts, motion.last_end()) {
        events.push(ImpactEvent {
            t: motion.end_time(),
            closing: closing.index,
            zeno: false,
            phase: motion.phases.len() - 1,
        });
    }
    events
}

/// Why a result the motion with sensitivities did not reach has none: why it stopped.
fn stop_gap(stop: &Option<Stop>) -> SensitivityGap {
    match stop {
        Some(Stop::Impact(_)) => SensitivityGap::PastImpact,
        Some(Stop::Grazing) => SensitivityGap::Grazing,
        Some(Stop::Failed(_)) => SensitivityGap::IntegrationFailed,
        None => SensitivityGap::RoutesDisagree,
    }
}

/// A separation with its sensitivities.
struct Found {
    d_theta: Vec<f64>,
    /// The time's, or why there are none.
    d_t: Result<Vec<f64>, SensitivityGap>,
}
