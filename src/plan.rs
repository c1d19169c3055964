//! The planner: turns a [`Request`] (model, parameters, wanted quantities) into [`RunResults`],
//! computing each wanted quantity and its prerequisites and nothing else.
//!
//! Each phase is solved on the fast path where its model has one (the list below), otherwise
//! integrated to its first event, which then gives the angle, time and states of every
//! quantity ([`Route`]). Prerequisites, computed at most once each (lazily, through `Plan`'s
//! caches):
//! - `separation_angle`: the separation root (polynomial evaluations only);
//! - `linearised_separation_angle`: the polynomial's two lowest coefficients (no evaluation);
//! - `separation_time`: root + quadrature of the first phase;
//! - `contact_time_to_floor`: quadrature to the end angle, keeping contact (no root);
//! - `point_mass_fall_time`: the release state only;
//! - `theta_series`, `<force>_series`, `<point>_trajectory`: root + quadrature + inversion at
//!   `samples` uniform times over the first phase (release to separation, or to the floor);
//! - any `<point>_trajectory` also gives the bodies' motion ([`RunResults::motion`], drawn
//!   into `motion.svg`) over every phase the run solved anyway, each sampled once;
//! - `contact_end`: the first phase (where, when and why its contact ends);
//! - `floor_impact`: the first phase and every next phase down to the floor;
//! - `cross_check`: the first phase's quadrature and the unreduced ODE to the separation event;
//! - `checks`: the sampled motion of every phase down to the floor (monitors, among them a free
//!   phase's `contact_open`, and energy and momentum drift of each path), plus the ODE path when `cross_check` is
//!   also wanted.
//!
//! Result keys (SI units): `separation_angle`, `linearised_separation_angle` (rad);
//! `separation_time`, `contact_time_to_floor`, `point_mass_fall_time`, `floor_impact_time` (s);
//! `impact_angular_velocity` (rad/s); `contact_end_time` (s), `contact_end_angle` (rad) and the
//! label `contact_end_cause` (`force` or `edge`); `cross_check_time` (s, the
//! ODE's event time), `cross_check_relative_difference` (1, against the quadrature),
//! `cross_check_time_deviation` (s, largest `|t_ode - t(theta_ode)|` over the ODE's steps),
//! `cross_check_state_deviation` (1, largest relative difference between the ODE state and the
//! reduced state at the same angle), `cross_check_rtol` (1, the ODE's tolerance after the
//! conditioning floor of [`unreduced::CONDITION_SAFETY`]). Series: `theta_series` (`t, theta, theta_dot,
//! theta_ddot`), `<force>_series` (`t, theta, <force>`), `<point>_trajectory`
//! (`t, x, y, vx, vy`). A wanted quantity without a value (e.g. no separation, or a mass matrix
//! too ill-conditioned for the cross-check) is explained in [`RunResults::notes`] under its key.

use crate::model::{Model, ModelInfo};
use crate::quantity::Quantity;
use crate::report::motion::{Animation, PhaseInput};
use crate::results::{
    Check, CheckKind, Column, Label, RunResults, Scalar, Series, Work, format_number,
};
use crate::solve::SolveError;
use crate::solve::checks;
use crate::solve::phases::{
    End, Motion, PhaseRun, ReducedEnd, ReducedRun, Route, extend_to_floor, phase_end,
};
use crate::solve::quadrature::TimeMesh;
use crate::solve::separation::{SeparationOutcome, linearised_separation};
use crate::solve::series::{PhaseSamples, sample, sample_forces, sample_friction, theta_dot_at};
use crate::solve::unreduced::{self, EndEvent, UnreducedRun};
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
/// [`ODE_RTOL_FLOOR`] (below it DOPRI5's rounding dominates): at the default tolerance its
/// event times agree with the fast path's to about `1e-13` relative.
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
    /// The model of the first phase.
    pub model: &'m dyn Model,
    /// Its parameters.
    pub parameters: Parameters,
    /// The quantities wanted (duplicates are ignored).
    pub want: Vec<Quantity>,
    /// Relative tolerance of every numerical result (and of the drift checks).
    pub tolerance: f64,
    /// Points per series.
    pub samples: usize,
    /// Where next phases are looked up by name (default: [`crate::models::all`]).
    pub registry: &'m [&'m dyn Model],
    /// Which route solves the phases (default: the fast path where a model has one).
    pub route: Route,
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
    /// exists (the quantities of the energy integral are then unavailable).
    pub fn with_route(mut self, route: Route) -> Self {
        self.route = route;
        self
    }

    /// Sets the registry for next phases.
    pub fn with_registry(mut self, registry: &'m [&'m dyn Model]) -> Self {
        self.registry = registry;
        self
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

/// Runs a request.
pub fn run(request: &Request) -> Result<RunResults, PlanError> {
    let info = request.model.info();
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
    let bound = match &request.parameters {
        Parameters::Values(v) => Bound::from_values(request.model, v)?,
        Parameters::Named(v) => Bound::new(request.model, v)?,
    };
    let mut plan = Plan::new(bound, request.registry, tol, request.samples, request.route);
    let mut out = RunResults {
        model: info.name.to_string(),
        parameters: plan.bound.parameter_map(),
        ..RunResults::default()
    };
    // The ODE first, so that `checks` can include its path when both are wanted.
    want.sort_by_key(|q| matches!(q, Quantity::Checks));
    for q in &want {
        plan.quantity(*q, &want, &mut out)?;
    }
    if want.iter().any(|q| matches!(q, Quantity::Trajectory(_))) {
        plan.animation(&want, &mut out)?;
    }
    out.work = plan.work;
    check_finite(&out)?;
    Ok(out)
}

/// Refuses a result with a NaN or an infinity (a model function misbehaving), naming it.
fn check_finite(out: &RunResults) -> Result<(), PlanError> {
    for (key, s) in &out.results {
        if !s.value.is_finite() {
            return Err(PlanError::NonFinite {
                key: key.clone(),
                index: 0,
                value: s.value,
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
    /// The first phase's model and parameters.
    bound: Bound<'m>,
    /// The same with its fast path, when it has one.
    sys: Option<System<'m>>,
    registry: &'m [&'m dyn Model],
    tol: f64,
    samples: usize,
    route: Route,
    work: Work,
    end: Option<ReducedEnd>,
    motion: Option<Motion<'m>>,
    complete: bool,
    floor_mesh: Option<TimeMesh>,
    phase_samples: Vec<PhaseSamples>,
    ode: Option<UnreducedRun>,
}

fn scalar(out: &mut RunResults, key: &str, value: f64, unit: &'static str, meaning: String) {
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

/// Why there is no separation: the contact holds until the reduced coordinate reaches its end.
fn no_separation(info: &ModelInfo) -> String {
    format!(
        "no separation before {}: the contact holds all the way",
        motion_end(info)
    )
}

/// The end of a model's motion in its own terms: `` `theta` = 0 rad `` (the reduced coordinate
/// at its `end_angle`).
fn motion_end(info: &ModelInfo) -> String {
    format!(
        "{} = {} rad",
        angle_name(info),
        format_number(info.end_angle, 6)
    )
}

/// The reduced coordinate's name, in backquotes (the derivation tool writes `reduced` as an
/// index into `coordinates`; `theta` names it should a hand-made `ModelInfo` get it wrong).
fn angle_name(info: &ModelInfo) -> String {
    format!(
        "`{}`",
        info.coordinates
            .get(info.reduced)
            .copied()
            .unwrap_or("theta")
    )
}

impl<'m> Plan<'m> {
    fn new(
        bound: Bound<'m>,
        registry: &'m [&'m dyn Model],
        tol: f64,
        samples: usize,
        route: Route,
    ) -> Self {
        let sys = match route {
            Route::Fastest => System::reduce(bound.clone()).ok(),
            Route::Integrated => None,
        };
        Plan {
            bound,
            sys,
            registry,
            tol,
            samples,
            route,
            work: Work::default(),
            end: None,
            motion: None,
            complete: false,
            floor_mesh: None,
            phase_samples: Vec::new(),
            ode: None,
        }
    }

    /// The first phase's fast path (a quantity that needs it is only offered with it).
    fn fast(&self) -> Result<&System<'m>, SolveError> {
        self.sys.as_ref().ok_or_else(|| {
            let info = self.bound.info();
            SolveError::Parameters(SystemError::NoReduction {
                model: info.name,
                why: info.route_note,
            })
        })
    }

    /// Where the first phase ends on the fast path (roots only, no quadrature).
    fn end(&mut self) -> Result<ReducedEnd, SolveError> {
        if let Some(end) = self.end {
            return Ok(end);
        }
        let sys = self.fast()?.clone();
        let end = phase_end(&sys, &mut self.work)?;
        self.end = Some(end);
        Ok(end)
    }

    /// The motion with at least its first phase solved: on the fast path root + quadrature
    /// (a first phase that keeps contact to the floor reuses the contact-to-floor integral if
    /// it exists), otherwise integrated to its first event.
    fn motion(&mut self) -> Result<&mut Motion<'m>, SolveError> {
        let motion = match self.motion.take() {
            Some(m) => m,
            None => {
                let run = match self.sys.clone() {
                    Some(sys) => {
                        let end = self.end()?;
                        match (end.end, &self.floor_mesh) {
                            (End::Floor, Some(mesh)) => {
                                self.work.phases.push(sys.name().to_string());
                                ReducedRun {
                                    system: sys,
                                    t_start: 0.0,
                                    end,
                                    mesh: mesh.clone(),
                                }
                            }
                            _ => ReducedRun::with_end(sys, 0.0, end, self.tol, &mut self.work)?,
                        }
                        .into_phase()
                    }
                    None => PhaseRun::solve(
                        self.bound.clone(),
                        0.0,
                        self.tol,
                        self.ode_rtol(),
                        self.route,
                        &mut self.work,
                    )?,
                };
                Motion::new(run)
            }
        };
        Ok(self.motion.insert(motion))
    }

    /// The first phase solved to its end.
    fn first(&mut self) -> Result<&PhaseRun<'m>, SolveError> {
        Ok(&self.motion()?.phases[0])
    }

    /// Every phase down to the floor.
    fn complete(&mut self) -> Result<&Motion<'m>, SolveError> {
        self.motion()?;
        if !self.complete {
            let rtol = self.ode_rtol();
            if let Some(motion) = self.motion.as_mut() {
                extend_to_floor(
                    motion,
                    self.registry,
                    self.tol,
                    rtol,
                    self.route,
                    &mut self.work,
                )?;
            }
            self.complete = true;
        }
        Ok(self.motion()?)
    }

    /// Samples of the solved phases up to `i` (each sampled once).
    fn samples_of(&mut self, i: usize) -> Result<&PhaseSamples, SolveError> {
        self.motion()?;
        if let Some(motion) = self.motion.as_ref() {
            while self.phase_samples.len() <= i {
                let Some(run) = motion.phases.get(self.phase_samples.len()) else {
                    break;
                };
                let s = sample(run, self.samples, &mut self.work)?;
                self.phase_samples.push(s);
            }
        }
        self.phase_samples
            .get(i)
            .ok_or(SolveError::TooManyPhases { limit: i })
    }

    /// The bodies' motion for `motion.svg`: every phase this run solved (the first always, the
    /// next ones when `floor_impact` or `checks` asked for them), each sampled once, with the
    /// path of the first point whose trajectory is wanted. A later phase that cannot be sampled
    /// ends the animation there, with a note in it.
    fn animation(&mut self, want: &[Quantity], out: &mut RunResults) -> Result<(), SolveError> {
        let n = self.motion()?.phases.len();
        let mut notes = Vec::new();
        for i in 0..n {
            if let Err(e) = self.samples_of(i) {
                notes.push(format!("the animation stops before phase {}: {e}", i + 1));
                break;
            }
        }
        let Some(motion) = self.motion.as_ref() else {
            return Ok(());
        };
        let info = self.bound.info();
        let traced = want.iter().find_map(|q| match q {
            Quantity::Trajectory(i) => info.points.get(*i).map(|p| p.name),
            _ => None,
        });
        let phases: Vec<PhaseInput> = motion
            .phases
            .iter()
            .zip(&self.phase_samples)
            .map(|(run, samples)| PhaseInput {
                bound: run.bound(),
                samples,
                t_start: run.t_start(),
                end: run.end(),
            })
            .collect();
        let mut animation = Animation::build(&phases, traced);
        animation.notes.extend(notes);
        out.motion = Some(animation);
        Ok(())
    }

    fn first_samples(&mut self) -> Result<&PhaseSamples, SolveError> {
        self.samples_of(0)
    }

    /// `t` to the floor keeping contact: the first phase itself when it does not separate.
    fn floor_mesh(&mut self) -> Result<&TimeMesh, SolveError> {
        let mesh = match self.floor_mesh.take() {
            Some(mesh) => mesh,
            None => match (
                &self.end,
                self.motion.as_ref().and_then(|m| m.phases[0].reduced()),
            ) {
                (
                    Some(ReducedEnd {
                        end: End::Floor, ..
                    }),
                    Some(r),
                ) => r.mesh.clone(),
                _ => {
                    let sys = self.fast()?.clone();
                    TimeMesh::build(&sys, sys.delta_to_floor(), self.tol, &mut self.work)?
                }
            },
        };
        Ok(self.floor_mesh.insert(mesh))
    }

    /// Relative tolerance given to the ODE integrator.
    fn ode_rtol(&self) -> f64 {
        (self.tol * ODE_RTOL_FACTOR).max(ODE_RTOL_FLOOR)
    }

    /// The unreduced ODE to the first phase's end event (the cross-check of the fast path).
    fn ode(&mut self) -> Result<&UnreducedRun, SolveError> {
        let run = match self.ode.take() {
            Some(run) => run,
            None => {
                let rtol = self.ode_rtol();
                let duration = self.first()?.duration();
                unreduced::integrate(&self.bound, rtol, None, 2.0 * duration, &mut self.work)?
            }
        };
        Ok(self.ode.insert(run))
    }

    /// The separation angle, its linearised approximation or the separation time, or a note
    /// saying why there is none.
    fn separation_quantity(
        &mut self,
        q: Quantity,
        key: String,
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let info = self.bound.info();
        match q {
            Quantity::SeparationAngle => match self.separation_angle()? {
                Some(theta) => scalar(
                    out,
                    &key,
                    theta,
                    "rad",
                    format!("{} where the contact force vanishes", angle_name(info)),
                ),
                None => {
                    let why = self.why_no_separation()?;
                    out.notes.insert(key, why);
                }
            },
            Quantity::LinearisedSeparationAngle => match linearised_separation(self.fast()?)? {
                SeparationOutcome::Separates(s) => scalar(
                    out,
                    &key,
                    s.theta,
                    "rad",
                    "separation angle with the polynomial's terms above degree 1 dropped".into(),
                ),
                SeparationOutcome::NoSeparationBeforeFloor => {
                    out.notes.insert(
                        key,
                        "the linearised polynomial has no root between the floor and the start"
                            .into(),
                    );
                }
            },
            Quantity::SeparationTime => match self.separation_time()? {
                Some(t) => scalar(out, &key, t, "s", "time from release to separation".into()),
                None => {
                    let why = self.why_no_separation()?;
                    out.notes.insert(key, why);
                }
            },
            // `quantity` sends only the three above here.
            _ => {}
        }
        Ok(())
    }

    fn quantity(
        &mut self,
        q: Quantity,
        want: &[Quantity],
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let info = self.bound.info();
        let key = q.name(info);
        match q {
            Quantity::SeparationAngle
            | Quantity::LinearisedSeparationAngle
            | Quantity::SeparationTime => self.separation_quantity(q, key, out)?,
            Quantity::ContactEnd => self.contact_end(out)?,
            Quantity::ContactTimeToFloor => {
                let t = self.floor_mesh()?.duration;
                scalar(
                    out,
                    &key,
                    t,
                    "s",
                    format!(
                        "time to {} if the contact held all the way",
                        motion_end(info)
                    ),
                );
            }
            Quantity::PointMassFallTime => {
                let pts = self.bound.points(&self.bound.initial_state());
                let h = pts.pos[info.falling_point][1];
                let g = self.bound.gravity();
                if h > 0.0 {
                    let meaning = format!(
                        "free fall of a point mass from the initial height {} m of `{}`",
                        format_number(h, 6),
                        info.points[info.falling_point].name
                    );
                    scalar(out, &key, (2.0 * h / g).sqrt(), "s", meaning);
                } else {
                    out.notes.insert(
                        key,
                        format!(
                            "the falling point starts at height {} m, not above y = 0",
                            format_number(h, 6)
                        ),
                    );
                }
            }
            Quantity::ThetaSeries => {
                let s = self.first_samples()?;
                let series = Series {
                    columns: vec![
                        column("t", "s", s.t.clone()),
                        column("theta", "rad", s.theta.clone()),
                        column("theta_dot", "rad/s", s.theta_dot.clone()),
                        column("theta_ddot", "rad/s^2", s.theta_ddot.clone()),
                    ],
                };
                out.series.insert(key, series);
            }
            Quantity::ForceSeries(i) => {
                self.first_samples()?;
                let (Some(motion), Some(s)) = (self.motion.as_ref(), self.phase_samples.first())
                else {
                    return Ok(());
                };
                let forces = sample_forces(&motion.phases[0], s)?;
                let force: Vec<f64> = forces.iter().map(|f| f[i]).collect();
                let series = Series {
                    columns: vec![
                        column("t", "s", s.t.clone()),
                        column("theta", "rad", s.theta.clone()),
                        column(info.forces[i].name, "N", force),
                    ],
                };
                out.series.insert(key, series);
            }
            Quantity::FrictionSeries(i) => {
                self.first_samples()?;
                let (Some(motion), Some(s)) = (self.motion.as_ref(), self.phase_samples.first())
                else {
                    return Ok(());
                };
                let f = &info.frictions[i];
                let samples = sample_friction(&motion.phases[0], s)?;
                let pick = |k: usize| samples.iter().map(|d| d[k][i]).collect::<Vec<f64>>();
                let series = Series {
                    columns: vec![
                        column("t", "s", s.t.clone()),
                        column("theta", "rad", s.theta.clone()),
                        column(f.name, "N", pick(0)),
                        column(info.forces[f.normal].name, "N", pick(1)),
                        column("slip_velocity", "m/s", pick(2)),
                    ],
                };
                out.series.insert(key, series);
            }
            Quantity::Trajectory(i) => {
                self.first_samples()?;
                let s = &self.phase_samples[0];
                let mut cols: [Vec<f64>; 4] = Default::default();
                for state in &s.states {
                    let pts = self.bound.points(state);
                    let (p, v) = (pts.pos[i], pts.vel[i]);
                    for (c, x) in cols.iter_mut().zip([p[0], p[1], v[0], v[1]]) {
                        c.push(x);
                    }
                }
                let [x, y, vx, vy] = cols;
                let series = Series {
                    columns: vec![
                        column("t", "s", s.t.clone()),
                        column("x", "m", x),
                        column("y", "m", y),
                        column("vx", "m/s", vx),
                        column("vy", "m/s", vy),
                    ],
                };
                out.series.insert(key, series);
            }
            Quantity::FloorImpact => self.floor_impact(out)?,
            Quantity::CrossCheck => self.cross_check(out)?,
            Quantity::Checks => self.checks(want.contains(&Quantity::CrossCheck), out)?,
        }
        Ok(())
    }

    /// The angle where the contact force reaches zero, or `None` when the first phase ends
    /// otherwise (the floor, or an edge). On the fast path this needs the root only.
    fn separation_angle(&mut self) -> Result<Option<f64>, SolveError> {
        if self.sys.is_some() {
            let end = self.end()?;
            return Ok(end
                .at
                .filter(|_| end.end == End::Separation)
                .map(|s| s.theta));
        }
        let first = self.first()?;
        Ok((first.end() == End::Separation).then(|| first.theta_end()))
    }

    /// Why the contact does not separate: it holds to the end of the motion, or its contact
    /// point runs off a body first.
    fn why_no_separation(&mut self) -> Result<String, SolveError> {
        let info = self.bound.info();
        let end = if self.sys.is_some() {
            self.end()?.end
        } else {
            self.first()?.end()
        };
        Ok(match end {
            End::Edge => "no separation: the contact point runs off the edge of a body before \
                          the contact force vanishes (`contact_end` says when)"
                .to_string(),
            _ => no_separation(info),
        })
    }

    /// The time from release to separation, or `None` without a separation.
    fn separation_time(&mut self) -> Result<Option<f64>, SolveError> {
        if self.sys.is_some() && self.end()?.end != End::Separation {
            return Ok(None);
        }
        let first = self.first()?;
        Ok((first.end() == End::Separation).then(|| first.duration()))
    }

    /// How the first phase's contact ends: time, angle and cause (`force` or `edge`).
    fn contact_end(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.bound.info();
        let first = self.first()?;
        let end = first.end();
        friction_report(first, "contact_end", "over the contact phase", out);
        if end == End::Floor {
            out.notes.insert("contact_end".into(), no_separation(info));
            return Ok(());
        }
        let (t, theta) = (first.duration(), first.theta_end());
        let cause = match end {
            End::Edge => "the contact point ran off the edge of a body",
            _ => "the contact force reached zero",
        };
        scalar(
            out,
            "contact_end_time",
            t,
            "s",
            format!("time from release until the contact ends: {cause}"),
        );
        scalar(
            out,
            "contact_end_angle",
            theta,
            "rad",
            format!("{} where the contact ends: {cause}", angle_name(info)),
        );
        out.labels.insert(
            "contact_end_cause".into(),
            Label {
                value: end.name().to_string(),
                meaning: "why the contact ended: `force` (the push reached zero) or `edge` (the contact point ran off a body)".into(),
            },
        );
        Ok(())
    }

    fn floor_impact(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.bound.info();
        let with_friction = !info.frictions.is_empty();
        let motion = self.complete()?;
        if with_friction {
            let work: f64 = motion.phases.iter().map(PhaseRun::friction_work).sum();
            scalar(
                out,
                "floor_impact_friction_work",
                work,
                "J",
                format!(
                    "work done by friction from release until {} (energy lost)",
                    motion_end(info)
                ),
            );
        }
        let names: Vec<&str> = motion.phases.iter().map(|p| p.bound().name()).collect();
        let path = names.join(" -> ");
        match motion.last_end() {
            Some(End::Floor) => {}
            Some(End::Edge) => {
                out.notes.insert(
                    "floor_impact".into(),
                    format!(
                        "the contact ran off an edge ({path}); the motion after that is not modelled"
                    ),
                );
                return Ok(());
            }
            _ => {
                out.notes.insert(
                    "floor_impact".into(),
                    format!("the motion ended before the floor ({path})"),
                );
                return Ok(());
            }
        }
        let time = motion.floor_time();
        let omega = motion.impact_angular_velocity();
        if motion.phases.len() == 1 {
            out.notes.insert("floor_impact".into(), no_separation(info));
        }
        scalar(
            out,
            "floor_impact_time",
            time,
            "s",
            format!("time from release until {} ({path})", motion_end(info)),
        );
        scalar(
            out,
            "impact_angular_velocity",
            omega,
            "rad/s",
            format!(
                "rate of {} when it reaches its end ({path})",
                angle_name(info)
            ),
        );
        Ok(())
    }

    fn cross_check(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        self.first()?;
        match self.ode() {
            Ok(_) => {}
            // Not an error of the run: the unreduced route has nothing to say here.
            Err(e @ SolveError::IllConditioned { .. }) => {
                out.notes.insert("cross_check".into(), e.to_string());
                return Ok(());
            }
            Err(e) => return Err(e),
        }
        let (Some(motion), Some(ode)) = (self.motion.as_ref(), self.ode.as_ref()) else {
            return Ok(());
        };
        let Some(first) = motion.phases[0].reduced() else {
            return Ok(());
        };
        let sys = &first.system;
        let t_quad = first.mesh.duration;
        let rel = (ode.t_end - t_quad).abs() / t_quad;
        let event = match ode.end {
            EndEvent::Separation => "separation (contact force crossing zero)",
            EndEvent::Edge => "the contact's edge",
            EndEvent::Floor => "the floor",
        };
        // Along the path: the quadrature's time and the reduced state at each ODE step's angle.
        let n = sys.n_coordinates();
        let reduced = sys.info().reduced;
        let theta_i = sys.theta_initial();
        let nodes = ode.nodes();
        let mut scale = vec![0.0f64; 2 * n];
        for (_, y) in &nodes {
            for (s, v) in scale.iter_mut().zip(y.iter()) {
                *s = s.max(v.abs());
            }
        }
        let (mut dt_max, mut dy_max) = (0.0f64, 0.0f64);
        let mut work = Work::default();
        for (t, y) in &nodes {
            let delta = (theta_i - y[reduced]).max(0.0);
            let tq = first.mesh.time_at_delta(sys, delta, &mut work)?;
            dt_max = dt_max.max((t - tq).abs());
            let state = sys.full_state(*t, delta, theta_dot_at(sys, delta));
            for (i, (a, b)) in state.q.iter().chain(&state.qd).zip(y.iter()).enumerate() {
                if scale[i] > 0.0 {
                    dy_max = dy_max.max((a - b).abs() / scale[i]);
                }
            }
        }
        self.work.integrand_evals += work.integrand_evals;
        let steps = self.ode.as_ref().map_or(0, UnreducedRun::steps);
        scalar(
            out,
            "cross_check_time",
            ode.t_end,
            "s",
            format!("unreduced equations (DOPRI5, {steps} steps) integrated to {event}"),
        );
        scalar(
            out,
            "cross_check_relative_difference",
            rel,
            "1",
            format!(
                "|t_ode - t_quadrature| / t_quadrature at {event} (quadrature: {t_quad:.15e} s; ODE rtol {:.1e}, mass-matrix condition {:.1e})",
                ode.rtol, ode.condition
            ),
        );
        scalar(
            out,
            "cross_check_rtol",
            ode.rtol,
            "1",
            "relative tolerance the ODE ran with: the one asked, raised to 10 eps cond(M) when the mass matrix is ill-conditioned".into(),
        );
        scalar(
            out,
            "cross_check_time_deviation",
            dt_max,
            "s",
            format!(
                "largest |t_ode - t(theta_ode)| over {} ODE steps",
                nodes.len()
            ),
        );
        scalar(
            out,
            "cross_check_state_deviation",
            dy_max,
            "1",
            format!(
                "largest relative difference between ODE and reduced states over {} steps",
                nodes.len()
            ),
        );
        Ok(())
    }

    fn checks(&mut self, with_ode: bool, out: &mut RunResults) -> Result<(), SolveError> {
        let n_phases = self.complete()?.phases.len();
        let tol = self.tol;
        for i in 0..n_phases {
            self.samples_of(i)?;
            let (Some(motion), Some(samples)) = (self.motion.as_ref(), self.phase_samples.get(i))
            else {
                continue;
            };
            let run = &motion.phases[i];
            let bound = run.bound();
            let forces = sample_forces(run, samples)?;
            let ctx = checks::Context {
                phase: bound.name().to_string(),
                key: bound.name().to_string(),
                order: 2 * i,
                t_start: run.t_start(),
            };
            let mut found: Vec<(String, Check)> =
                checks::monitors(bound, samples, &forces, tol, &ctx);
            match run {
                PhaseRun::Reduced(_) => {
                    found.extend(checks::drift(
                        bound,
                        &samples.states,
                        None,
                        tol,
                        &ctx,
                        CheckKind::Identity,
                    ));
                }
                // Along the integrator's own steps (not the interpolated samples), held to the
                // integrator's accuracy: ten times its rtol at the least.
                PhaseRun::Integrated(r) => {
                    let states = r.run.states();
                    let ode_tol = tol.max(10.0 * r.run.rtol);
                    let friction_work = r.run.node_friction_work();
                    let with_friction = !bound.info().frictions.is_empty();
                    found.extend(checks::drift(
                        bound,
                        &states,
                        with_friction.then_some(&friction_work[..]),
                        ode_tol,
                        &ctx,
                        CheckKind::Drift,
                    ));
                }
            }
            out.checks.extend(found);
        }
        if with_ode && let Some(ode) = self.ode.as_ref() {
            let states = ode.states();
            // The ODE path is held to its own accuracy: ten times its rtol at the least. It
            // integrates the first phase's equations, so its checks come right after that
            // phase's.
            let ode_tol = tol.max(10.0 * ode.rtol);
            let ctx = checks::Context {
                phase: format!("{} (ODE cross-check)", self.bound.name()),
                key: format!("{}.ode", self.bound.name()),
                order: 1,
                t_start: 0.0,
            };
            out.checks.extend(checks::drift(
                &self.bound,
                &states,
                None,
                ode_tol,
                &ctx,
                CheckKind::Drift,
            ));
        }
        Ok(())
    }
}

/// For a phase with friction: the work friction did over it (`<key>_friction_work`, J) and
/// the sequence of contact modes with the time each began (`<key>_contact_modes`).
fn friction_report(run: &PhaseRun, key: &str, until: &str, out: &mut RunResults) {
    let modes = run.contact_modes();
    if modes.is_empty() {
        return;
    }
    scalar(
        out,
        &format!("{key}_friction_work"),
        run.friction_work(),
        "J",
        format!("work done by friction {until} (energy lost)"),
    );
    let sequence = modes
        .iter()
        .map(|(t, m)| format!("{m} from t = {} s", format_number(*t, 6)))
        .collect::<Vec<_>>()
        .join("; ");
    out.labels.insert(
        format!("{key}_contact_modes"),
        Label {
            value: sequence,
            meaning: format!(
                "how each friction contact moves {until}: sticks, or slides + / - along its direction, each from the time the mode began (switches located as events)"
            ),
        },
    );
}
