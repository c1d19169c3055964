//! The planner: turns a [`Request`] (a system, parameters, wanted quantities) into
//! [`RunResults`], computing each wanted quantity and its prerequisites and nothing else.
//!
//! The motion is solved phase by phase ([`Walker`]): at release the contacts that stay closed
//! are decided, each phase runs on the fast path where the system has one for its closed
//! contacts and is integrated otherwise, and the next phase starts where a contact opens.
//! Prerequisites, computed at most once each (lazily, through `Plan`'s caches):
//! - `separation_angle`: where the first contact's force reaches zero; when the motion starts
//!   on a fast phase that ends so, its polynomial's root alone (polynomial evaluations only);
//! - `linearised_separation_angle`: the release phase's polynomial's two lowest coefficients;
//! - `separation_time`: the phases up to the first contact's end;
//! - `contact_end`: the phases up to every contact's end;
//! - `contact_time_to_floor`: the release fast phase's quadrature to the end angle;
//! - `point_mass_fall_time`: the release state only;
//! - `theta_series`, `<contact>_series`, `<friction>_series`, `<point>_trajectory`: `samples`
//!   uniform times from release to the first contact's end (or to the end of the motion);
//! - any `<point>_trajectory` also gives the bodies' poses ([`RunResults::drawing`], from
//!   which the report computes `motion.svg`) over every phase the run solved anyway, each
//!   sampled once;
//! - `floor_impact`: every phase to the end of the motion;
//! - `cross_check`: the release fast phase and the general model integrated from release with
//!   the same contacts closed, to its first event;
//! - `checks`: the sampled motion of every phase to the end (monitors, the closed contacts'
//!   forces, and energy and momentum drift of each path, with the closed contacts' gaps on
//!   integrated phases), plus the cross-check's path when `cross_check` is also wanted.
//!
//! Result keys (SI units): `separation_angle`, `linearised_separation_angle` (rad);
//! `separation_time`, `contact_time_to_floor`, `point_mass_fall_time`, `floor_impact_time` (s);
//! `impact_angular_velocity` (rad/s); `contact_end_time` (s), `contact_end_angle` (rad) and the
//! label `contact_end_cause` (`force`, `edge` or `contact`) for the first contact, and
//! `<contact>_end_time`, `<contact>_end_angle`, `<contact>_end_cause` for each;
//! `cross_check_time` (s, the integrated route's event time), `cross_check_relative_difference`
//! (1, against the quadrature), `cross_check_time_deviation` (s, largest
//! `|t_ode - t(theta_ode)|` over the integrator's steps), `cross_check_state_deviation` (1,
//! largest relative difference between the integrated and the reduced state at the same
//! angle), `cross_check_rtol` (1, the integrator's tolerance after the conditioning floor of
//! [`unreduced::CONDITION_SAFETY`]). Series: `theta_series` (`t, theta, theta_dot,
//! theta_ddot`), `<contact>_series` (`t, theta, <contact>`), `<point>_trajectory`
//! (`t, x, y, vx, vy`). A wanted quantity without a value (e.g. no separation, or a mass matrix
//! too ill-conditioned for the cross-check) is explained in [`RunResults::notes`] under its key,
//! and so is a cross-check whose event time lies further from the fast path's than
//! [`CROSS_CHECK_APART`](crate::results::CROSS_CHECK_APART) times its tolerance
//! ([`Note::CrossCheckApart`](crate::results::Note::CrossCheckApart)): one route is then
//! ill-conditioned, e.g. the general model carrying a motion of `1e-16` of its coordinates; an
//! integrated phase whose end's time that rounding makes uncertain beyond the tolerance is noted
//! under `<contact>_resolution` ([`Note::EndUnresolved`](crate::results::Note::EndUnresolved)).

pub mod drawing;
mod quantities;
mod sensitivities;
mod verify;

use crate::model::Model;
use crate::quantity::Quantity;
use crate::results::EndCause;
use crate::results::{Column, Meaning, RunResults, Scalar, SensitivityGap, Work};
use crate::solve::SolveError;
use crate::solve::fast::quadrature::TimeMesh;
use crate::solve::integrated::unreduced::{self, UnreducedRun};
use crate::solve::phases::{
    Motion, PhaseRun, PhaseStart, ReducedEnd, ReducedRun, Route, SensitiveMotion, Walker, phase_end,
};
use crate::solve::series::PhaseSamples;
use crate::system::{Bound, System, SystemError};
use std::collections::BTreeMap;

/// Relative tolerance when a request gives none.
pub const DEFAULT_TOLERANCE: f64 = 1e-10;
/// [`DEFAULT_TOLERANCE`] as the command line shows it (a test checks that they agree).
pub const DEFAULT_TOLERANCE_TEXT: &str = "1e-10";
/// Points per series when a request gives none.
pub const DEFAULT_SAMPLES: usize = 500;
/// Most points per series a request may ask for (each series holds `samples` values per
/// column in memory).
pub const MAX_SAMPLES: usize = 10_000_000;
/// Accepted relative tolerances (inclusive).
pub const TOLERANCE_RANGE: (f64, f64) = (1e-14, 1e-2);
/// The integrator runs at `tolerance * ODE_RTOL_FACTOR`, but never tighter than
/// [`ODE_RTOL_FLOOR`] (below it the integrator's rounding dominates): at the default tolerance
/// its event times agree with the fast path's to about `1e-13` relative.
pub const ODE_RTOL_FACTOR: f64 = 0.01;
/// Tightest relative tolerance given to the ODE integrator.
pub const ODE_RTOL_FLOOR: f64 = 1e-13;

/// Parameter values for a request: in the model's order, or by name.
#[derive(Debug, Clone, PartialEq)]
pub enum Parameters {
    /// In the order of [`ModelInfo::parameters`](crate::model::ModelInfo::parameters).
    Values(Vec<f64>),
    /// By name, any order.
    Named(Vec<(String, f64)>),
}

impl From<Vec<f64>> for Parameters {
    fn from(v: Vec<f64>) -> Self {
        Parameters::Values(v)
    }
}

impl From<&[(&str, f64)]> for Parameters {
    fn from(v: &[(&str, f64)]) -> Self {
        Parameters::Named(v.iter().map(|(k, v)| (k.to_string(), *v)).collect())
    }
}

impl<const N: usize> From<[(&str, f64); N]> for Parameters {
    fn from(v: [(&str, f64); N]) -> Self {
        Parameters::from(&v[..])
    }
}

impl From<&BTreeMap<String, f64>> for Parameters {
    fn from(v: &BTreeMap<String, f64>) -> Self {
        Parameters::Named(v.iter().map(|(k, v)| (k.clone(), *v)).collect())
    }
}

/// What to compute.
#[derive(Clone)]
pub struct Request<'m> {
    /// The system: its general model (the one named as its spec).
    pub model: &'m dyn Model,
    /// Its parameters.
    pub parameters: Parameters,
    /// The quantities wanted (duplicates are ignored).
    pub want: Vec<Quantity>,
    /// Relative tolerance of every numerical result (and of the drift checks).
    pub tolerance: f64,
    /// Points per series.
    pub samples: usize,
    /// Where the system's fast phases are looked up by name (default:
    /// [`crate::models::all`]).
    pub registry: &'m [&'m dyn Model],
    /// Which route solves the phases (default: the fast path where a phase has one).
    pub route: Route,
    /// The time (s from release) the motion goes on to, through impacts and phases; `None`
    /// (the default) ends it at its first landing: the floor, an edge or a contact that closes.
    pub until: Option<f64>,
}

impl<'m> Request<'m> {
    /// A request with the default tolerance, samples and registry, wanting nothing yet.
    pub fn new(model: &'m dyn Model, parameters: impl Into<Parameters>) -> Self {
        Request {
            model,
            parameters: parameters.into(),
            want: Vec::new(),
            tolerance: DEFAULT_TOLERANCE,
            samples: DEFAULT_SAMPLES,
            registry: crate::models::all(),
            route: Route::Fastest,
            until: None,
        }
    }

    /// A request for a model found by name in `registry`.
    pub fn by_name(
        name: &str,
        parameters: impl Into<Parameters>,
        registry: &'m [&'m dyn Model],
    ) -> Result<Self, PlanError> {
        let model = registry
            .iter()
            .copied()
            .find(|m| m.info().name == name)
            .ok_or_else(|| PlanError::UnknownModel {
                name: name.to_string(),
            })?;
        Ok(Request::new(model, parameters).with_registry(registry))
    }

    /// Sets the wanted quantities.
    pub fn with_want(mut self, want: &[Quantity]) -> Self {
        self.want = want.to_vec();
        self
    }

    /// Sets the tolerance.
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Sets the points per series.
    pub fn with_samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// Sets the route: [`Route::Integrated`] integrates every phase, even where a fast path
    /// exists.
    pub fn with_route(mut self, route: Route) -> Self {
        self.route = route;
        self
    }

    /// Sets the time the motion goes on to, through impacts (`None`: to its first landing).
    pub fn with_until(mut self, until: Option<f64>) -> Self {
        self.until = until;
        self
    }

    /// Sets the registry for the fast phases.
    pub fn with_registry(mut self, registry: &'m [&'m dyn Model]) -> Self {
        self.registry = registry;
        self
    }
}

impl Request<'_> {
    /// Checks what does not depend on the parameters (the model is a system that offers every
    /// wanted quantity, the tolerance, `until`, the samples) without solving anything: a sweep
    /// refuses a request once rather than at every point.
    pub fn check(&self) -> Result<(), PlanError> {
        wanted(self).map(|_| ())
    }
}

/// Why a request could not be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// No model of that name.
    #[error("no model `{name}` in the registry")]
    UnknownModel {
        /// The name asked.
        name: String,
    },
    /// A fast phase was given where a system is run.
    #[error(
        "model `{name}` is a phase of the system `{system}`, which decides its phases itself: run `{system}`"
    )]
    NotASystem {
        /// The phase model.
        name: &'static str,
        /// Its system.
        system: &'static str,
    },
    /// The model cannot provide a wanted quantity.
    #[error("model `{model}` cannot provide `{quantity}` (it offers: {offers})")]
    Unavailable {
        /// The quantity's key.
        quantity: String,
        /// Model name.
        model: &'static str,
        /// What it offers, comma-separated.
        offers: String,
    },
    /// Tolerance outside [`TOLERANCE_RANGE`].
    #[error("tolerance {tolerance:e} is outside [{:e}, {:e}]", TOLERANCE_RANGE.0, TOLERANCE_RANGE.1)]
    BadTolerance {
        /// The tolerance given.
        tolerance: f64,
    },
    /// `until` is not a positive, finite time.
    #[error("until {until} s: the run's end must be a positive, finite time from release")]
    BadUntil {
        /// The time given.
        until: f64,
    },
    /// Fewer than 2 samples while a series or check is wanted.
    #[error("{samples} samples asked; series and checks need at least 2")]
    TooFewSamples {
        /// The samples given.
        samples: usize,
    },
    /// More than [`MAX_SAMPLES`] samples.
    #[error("{samples} samples asked; at most {MAX_SAMPLES} per series")]
    TooManySamples {
        /// The samples given.
        samples: usize,
    },
    /// The parameters were refused.
    #[error(transparent)]
    System(#[from] SystemError),
    /// A solver failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A result came out NaN or infinite (a model function misbehaving).
    #[error(
        "result `{key}` is {value} (sample {index}): a model function returned a non-finite value"
    )]
    NonFinite {
        /// The result key, or `<series>.<column>`.
        key: String,
        /// The sample index within a series (0 for a scalar).
        index: usize,
        /// The value.
        value: f64,
    },
}

/// The wanted quantities, checked against the model, without duplicates; and whether they
/// need samples.
fn wanted(request: &Request) -> Result<Vec<Quantity>, PlanError> {
    let info = request.model.info();
    if !info.is_general() {
        return Err(PlanError::NotASystem {
            name: info.name,
            system: info.system,
        });
    }
    let mut want: Vec<Quantity> = Vec::new();
    for q in &request.want {
        if !q.available(info) {
            return Err(PlanError::Unavailable {
                quantity: q.name(info),
                model: info.name,
                offers: Quantity::names(info).join(", "),
            });
        }
        if !want.contains(q) {
            want.push(*q);
        }
    }
    let tol = request.tolerance;
    if !(tol >= TOLERANCE_RANGE.0 && tol <= TOLERANCE_RANGE.1) {
        return Err(PlanError::BadTolerance { tolerance: tol });
    }
    if let Some(until) = request.until
        && !(until > 0.0 && until.is_finite())
    {
        return Err(PlanError::BadUntil { until });
    }
    let needs_samples = want.iter().any(|q| {
        matches!(
            q,
            Quantity::ThetaSeries
                | Quantity::ForceSeries(_)
                | Quantity::FrictionSeries(_)
                | Quantity::Trajectory(_)
                | Quantity::Checks
        )
    });
    if needs_samples && request.samples < 2 {
        return Err(PlanError::TooFewSamples {
            samples: request.samples,
        });
    }
    if request.samples > MAX_SAMPLES {
        return Err(PlanError::TooManySamples {
            samples: request.samples,
        });
    }
    Ok(want)
}

/// Runs a request.
pub fn run(request: &Request) -> Result<RunResults, PlanError> {
    let info = request.model.info();
    let mut want = wanted(request)?;
    let bound = match &request.parameters {
        Parameters::Values(v) => Bound::from_values(request.model, v)?,
        Parameters::Named(v) => Bound::new(request.model, v)?,
    };
    let walker = Walker::new(
        bound,
        request.registry,
        request.tolerance,
        (request.tolerance * ODE_RTOL_FACTOR).max(ODE_RTOL_FLOOR),
    )
    .with_route(request.route)
    .with_until(request.until)
    .with_dense_output(want.iter().any(Quantity::samples_motion));
    let mut plan = Plan::new(walker, request.samples);
    let mut out = RunResults {
        model: info.name.to_string(),
        parameters: plan.walker.general.parameter_map(),
        ..RunResults::default()
    };
    // The cross-check first, so that `checks` can include its path when both are wanted; the
    // sensitivities last, of the results computed before them.
    want.sort_by_key(|q| match q {
        Quantity::Checks => 1,
        Quantity::Sensitivities => 2,
        _ => 0,
    });
    for q in &want {
        plan.quantity(*q, &want, &mut out)?;
    }
    if want.iter().any(|q| matches!(q, Quantity::Trajectory(_))) {
        plan.drawing(&want, &mut out)?;
    }
    plan.motion_notes(&mut out);
    plan.resolution_notes(&mut out)?;
    provenance_notes(info.name, &mut out);
    out.work = plan.work;
    check_finite(&out)?;
    Ok(out)
}

/// Where the model came from, when a reader should know: run from a tape, or derived from a
/// spec that has changed since.
fn provenance_notes(model: &str, out: &mut RunResults) {
    use crate::models::{Provenance, TapeRoute};
    use crate::results::{Note, TapeReason};
    let Some(entry) = crate::models::entry(model) else {
        return;
    };
    if let Provenance::Tape { file, why } = entry.provenance {
        let why = match why {
            TapeRoute::Asked => TapeReason::Asked,
            TapeRoute::NotCompiled => TapeReason::NotCompiled,
            TapeRoute::DiffersFromCompiled => TapeReason::DiffersFromCompiled,
            TapeRoute::DerivedNow => TapeReason::DerivedNow,
        };
        let model = model.to_string();
        out.notes
            .insert("model".into(), Note::FromTape { model, file, why });
    }
    if let Some(spec) = entry.stale_spec {
        let (model, spec) = (model.to_string(), spec.display().to_string());
        out.notes
            .insert("spec".into(), Note::SpecChanged { model, spec });
    }
}

/// Refuses a result with a NaN or an infinity (a model function misbehaving), naming it.
fn check_finite(out: &RunResults) -> Result<(), PlanError> {
    let sensitivities = (out.sensitivities.iter()).map(|(k, s)| (k, s.value));
    for (key, value) in (out.results.iter())
        .map(|(k, s)| (k, s.value))
        .chain(sensitivities)
    {
        if !value.is_finite() {
            return Err(PlanError::NonFinite {
                key: key.clone(),
                index: 0,
                value,
            });
        }
    }
    for (key, series) in &out.series {
        for c in &series.columns {
            if let Some((index, &value)) = c.values.iter().enumerate().find(|(_, v)| !v.is_finite())
            {
                let key = format!("{key}.{}", c.name);
                return Err(PlanError::NonFinite { key, index, value });
            }
        }
    }
    Ok(())
}

/// Caches of one run: each prerequisite is computed at most once, only when asked for.
struct Plan<'m> {
    walker: Walker<'m>,
    samples: usize,
    work: Work,
    /// The release state and closed contacts, with the contacts that opened at once.
    release: Option<(PhaseStart, Vec<usize>)>,
    /// The fast phase the motion starts on, once asked: where it has one.
    fast: Asked<Option<System<'m>>>,
    /// Where that fast phase ends, by its roots alone.
    end: Option<ReducedEnd>,
    /// The motion, as far as it has been solved.
    motion: Option<Motion<'m>>,
    /// `t` to the floor keeping the release contacts closed.
    floor_mesh: Option<TimeMesh>,
    /// Each solved phase's samples, uniform over it (checks and the animation).
    phase_samples: Vec<PhaseSamples>,
    /// The series' samples over the first contact's span: per phase touched, its index, its
    /// samples and their times from release.
    span: Option<Vec<(usize, PhaseSamples, Vec<f64>)>>,
    /// The cross-check's integration.
    ode: Option<UnreducedRun>,
    /// The motion integrated with its forward sensitivities, or why there is none.
    sensitive: Option<Result<SensitiveMotion<'m>, SensitivityGap>>,
}

/// A question the plan answers once: not asked yet, or its answer (which may itself be "none").
enum Asked<T> {
    /// Not asked yet.
    NotYet,
    /// The answer.
    Answered(T),
}

fn scalar(out: &mut RunResults, key: &str, value: f64, unit: &'static str, meaning: Meaning) {
    out.results.insert(
        key.to_string(),
        Scalar {
            value,
            unit,
            meaning,
        },
    );
}

fn column(name: &str, unit: &'static str, values: Vec<f64>) -> Column {
    Column {
        name: name.to_string(),
        unit,
        values,
    }
}

impl<'m> Plan<'m> {
    fn new(walker: Walker<'m>, samples: usize) -> Self {
        Plan {
            walker,
            samples,
            work: Work::default(),
            release: None,
            fast: Asked::NotYet,
            end: None,
            motion: None,
            floor_mesh: None,
            phase_samples: Vec::new(),
            span: None,
            ode: None,
            sensitive: None,
        }
    }

    /// The system's general model with its parameters.
    fn general(&self) -> &Bound<'m> {
        &self.walker.general
    }

    /// The release: its state and closed contacts, and the contacts that opened at once.
    fn release(&mut self) -> Result<&(PhaseStart, Vec<usize>), SolveError> {
        let release = match self.release.take() {
            Some(release) => release,
            None => self.walker.release()?,
        };
        Ok(self.release.insert(release))
    }

    /// The fast phase the motion starts on, where the release's closed contacts have one.
    fn fast(&mut self) -> Result<Option<System<'m>>, SolveError> {
        if let Asked::Answered(fast) = &self.fast {
            return Ok(fast.clone());
        }
        let start = self.release()?.0.clone();
        let fast = self.walker.fast_phase(&start)?;
        self.fast = Asked::Answered(fast.clone());
        Ok(fast)
    }

    /// The fast phase the motion starts on, or the error that says why there is none (for a
    /// quantity of the energy integral).
    fn fast_required(&mut self) -> Result<System<'m>, SolveError> {
        match self.fast()? {
            Some(sys) => Ok(sys),
            None => {
                let info = self.general().info();
                let start = self.release()?.0.clone();
                Err(SolveError::NotOnFastPath {
                    model: info.name,
                    why: if self.walker.route == Route::Integrated {
                        "the route asked integrates every phase".into()
                    } else if (info.phases.iter()).any(|p| p.release) {
                        format!(
                            "the motion does not start in the system's release fast phase: at \
                             release {}",
                            start.active.set(info)
                        )
                    } else {
                        info.route_note.to_string()
                    },
                })
            }
        }
    }

    /// Where the release fast phase ends, by its roots alone.
    fn end(&mut self) -> Result<ReducedEnd, SolveError> {
        if let Some(end) = self.end {
            return Ok(end);
        }
        let sys = self.fast_required()?;
        let end = phase_end(&sys, &mut self.work)?;
        self.end = Some(end);
        Ok(end)
    }

    /// The motion with at least its first phase solved: on the fast path root + quadrature
    /// (a first phase that ends at the floor reuses the contact-to-floor integral if it
    /// exists), otherwise integrated to its first event.
    fn motion(&mut self) -> Result<&mut Motion<'m>, SolveError> {
        let motion = self.take_motion()?;
        Ok(self.motion.insert(motion))
    }

    /// The motion as [`Plan::motion`] has it, taken out of the cache (the caller puts it back:
    /// `self.motion.insert(motion)` gives it to the caller next to the plan's other fields).
    fn take_motion(&mut self) -> Result<Motion<'m>, SolveError> {
        if let Some(motion) = self.motion.take() {
            return Ok(motion);
        }
        let (start, opened) = self.release()?.clone();
        let first = match self.fast()? {
            Some(sys) => {
                let end = self.end()?;
                match (end.end, &self.floor_mesh) {
                    (EndCause::Floor, Some(mesh)) => {
                        self.work.phases.push(sys.name().to_string());
                        ReducedRun {
                            system: sys,
                            t_start: 0.0,
                            end,
                            mesh: mesh.clone(),
                        }
                        .into_phase()
                    }
                    _ => self.walker.follow(sys, &start, end, &mut self.work)?,
                }
            }
            None => self.walker.solve(&start, &mut self.work)?,
        };
        Ok(Motion::starting(first, opened, self.walker.until.is_some()))
    }

    /// Extends the motion phase by phase until `done` says so or it ends for good.
    fn extend_until(
        &mut self,
        done: impl Fn(&Motion<'m>) -> bool,
    ) -> Result<&Motion<'m>, SolveError> {
        let motion = self.take_motion()?;
        let Plan {
            motion: slot,
            walker,
            work,
            ..
        } = self;
        let motion = slot.insert(motion);
        while !(done(motion) || motion.complete()) {
            walker.step(motion, work)?;
        }
        Ok(motion)
    }

    /// Every phase to the end of the motion.
    fn complete(&mut self) -> Result<&Motion<'m>, SolveError> {
        self.extend_until(|_| false)
    }

    /// Samples of the solved phases up to `i` (each sampled once, uniform over it); a phase
    /// the motion does not have is [`SolveError::NoSuchPhase`].
    fn samples_of(&mut self, i: usize) -> Result<&PhaseSamples, SolveError> {
        let motion = self.take_motion()?;
        let Plan {
            motion: slot,
            phase_samples,
            span,
            samples,
            work,
            ..
        } = self;
        let motion = slot.insert(motion);
        while phase_samples.len() <= i {
            let k = phase_samples.len();
            let Some(run) = motion.phases.get(k) else {
                break;
            };
            let times = crate::solve::series::uniform_times(run.duration(), *samples)?;
            // The series' samples where they are this phase's own (a span that is the
            // whole of it, from the release): the same times, so not sampled twice.
            let shared = (span.iter().flatten())
                .find(|(g, s, _)| *g == k && run.t_start() == 0.0 && s.t == times)
                .map(|(_, s, _)| s.clone());
            let s = match shared {
                Some(s) => s,
                None => crate::solve::series::sample_at(run, &times, work)?,
            };
            phase_samples.push(s);
        }
        let solved = phase_samples.len();
        phase_samples
            .get(i)
            .ok_or(SolveError::NoSuchPhase { index: i, solved })
    }

    /// `t` to the floor keeping the release contacts closed: the first phase itself when it
    /// ends at the floor.
    fn floor_mesh(&mut self) -> Result<&TimeMesh, SolveError> {
        let mesh = match self.floor_mesh.take() {
            Some(mesh) => mesh,
            None => self.build_floor_mesh()?,
        };
        Ok(self.floor_mesh.insert(mesh))
    }

    /// [`Plan::floor_mesh`] computed.
    fn build_floor_mesh(&mut self) -> Result<TimeMesh, SolveError> {
        let reuse = match (
            &self.end,
            self.motion.as_ref().and_then(|m| m.phases[0].reduced()),
        ) {
            (
                Some(ReducedEnd {
                    end: EndCause::Floor,
                    ..
                }),
                Some(r),
            ) => Some(r.mesh.clone()),
            _ => None,
        };
        let mesh = match reuse {
            Some(mesh) => mesh,
            None => {
                let sys = self.fast_required()?;
                TimeMesh::build(&sys, sys.delta_to_floor(), self.walker.tol, &mut self.work)?
            }
        };
        Ok(mesh)
    }

    /// The general model integrated from release with the release's contacts closed, to its
    /// first event (the cross-check of the fast path), taken out of the cache (the caller puts
    /// it back).
    fn take_ode(&mut self) -> Result<UnreducedRun, SolveError> {
        if let Some(run) = self.ode.take() {
            return Ok(run);
        }
        let duration = self.motion()?.phases[0].duration();
        let start = self.release()?.0.clone();
        let from = unreduced::Start {
            state: start.state,
            active: start.active,
            frictions: start.frictions,
            friction_work: 0.0,
            stop_at: None,
            dense_output: self.walker.dense_output,
            sensitivity: None,
        };
        let bound = self.general().clone();
        let t_max = 2.0 * duration.max(f64::MIN_POSITIVE);
        let scales = self.walker.scales(&from.state, &from.active)?;
        let run = unreduced::integrate(
            &bound,
            &from,
            self.walker.rtol,
            Some(&scales),
            t_max,
            &mut self.work,
        )?;
        Ok(run)
    }

    fn quantity(
        &mut self,
        q: Quantity,
        want: &[Quantity],
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        match q {
            Quantity::SeparationAngle | Quantity::SeparationTime => {
                self.separation_quantity(q, out)
            }
            Quantity::LinearisedSeparationAngle => self.linearised(out),
            Quantity::ContactEnd => self.contact_ends(out),
            Quantity::ContactTimeToFloor => self.contact_time_to_floor(out),
            Quantity::PointMassFallTime => self.point_mass_fall_time(out),
            Quantity::ThetaSeries
            | Quantity::ForceSeries(_)
            | Quantity::FrictionSeries(_)
            | Quantity::Trajectory(_) => self.series(q, out),
            Quantity::FloorImpact => self.floor_impact(out),
            Quantity::Impacts => self.impacts(out),
            Quantity::CrossCheck => self.cross_check(out),
            Quantity::Checks => self.checks(want.contains(&Quantity::CrossCheck), out),
            Quantity::Sensitivities => self.sensitivities(want, out),
        }
    }
}

/// The labels of the phases the motion went through, in order.
fn phase_labels(motion: &Motion) -> Vec<String> {
    motion.phases.iter().flat_map(PhaseRun::labels).collect()
}
