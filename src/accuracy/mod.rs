//! `rodcube accuracy`: what accuracy costs in time. Every method the project ships, and the
//! ones a user would reach for, is run on the paper's case and on the hard cases (near upright,
//! nearly flat, extreme mass ratios) and compared with the independent high-precision
//! [`reference`](mod@crate::reference); the integrators are run on the models that need them
//! (springs, friction, curved contacts) against a reference that does not share their route.
//! Each setting's set-up (a solver, a rule, a bound model) is timed apart from its solve, which
//! is timed alone, as a user who solves many points pays for them: relative error, model
//! evaluations, set-up and time per solve, as a table, a CSV and log–log SVG plots of error
//! against time with the Pareto front marked.

pub mod error;
pub mod integrated;
pub mod methods;
pub mod plot;
pub mod settings;
pub mod table;

pub use error::AccuracyError;

use crate::reference::{self, Family, Inputs, Reference, RootRoute, TimeRoute};
use crate::solve::integrated::ode::Method;
use crate::system::System;
use astro_float::BigFloat;
use indicatif::ProgressBar;
use settings::{Point, Setting};
use std::time::{Duration, Instant};

/// Samples in each `theta(t)` series.
pub const SERIES_SAMPLES: usize = 101;

/// Samples in each `theta(t)` series with `--quick`.
pub const QUICK_SERIES_SAMPLES: usize = 21;

/// How long each setting's set-up and solve are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Budget {
    /// Each is repeated until this much time has passed ...
    pub time: Duration,
    /// ... and at least this many times.
    pub min_repeats: u32,
}

impl Budget {
    /// The full report's: 25 ms and 3 repetitions.
    pub const FULL: Budget = Budget {
        time: Duration::from_millis(25),
        min_repeats: 3,
    };
    /// `--quick`: 2 ms and 2 repetitions.
    pub const QUICK: Budget = Budget {
        time: Duration::from_millis(2),
        min_repeats: 2,
    };
}

/// Errors below this are drawn at it (the plots are logarithmic).
pub const ERROR_FLOOR: f64 = 1e-17;

/// What is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Measured {
    /// The separation angle.
    Angle,
    /// The separation time.
    Time,
    /// The `theta(t)` series from release to separation.
    Series,
    /// The time the first contact ends, on the integrated route.
    ContactEnd,
    /// The separation angle's and time's derivatives in every parameter.
    Sensitivities,
}

impl Measured {
    /// Name in the table, the CSV and the file names.
    pub fn name(self) -> &'static str {
        match self {
            Measured::Angle => "separation_angle",
            Measured::Time => "separation_time",
            Measured::Series => "theta_series",
            Measured::ContactEnd => "contact_end_time",
            Measured::Sensitivities => "sensitivities",
        }
    }
}

/// One test case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    /// Short name (the table's and `--case`'s).
    pub key: &'static str,
    /// What it is.
    pub name: &'static str,
    /// `m2/m1`.
    pub n: f64,
    /// `a/ell`.
    pub a_over_ell: f64,
}

/// The cases for a model: the paper's, near upright, nearly flat, and (for models with a
/// mass ratio) a very heavy and a very light cube.
pub fn cases(family: Family) -> Vec<Case> {
    let mut out = vec![
        Case {
            key: "paper",
            name: "paper (n=3, a/ell=1/4)",
            n: 3.0,
            a_over_ell: 0.25,
        },
        Case {
            key: "near_upright",
            name: "near upright (a/ell=1-1e-9)",
            n: 3.0,
            a_over_ell: 1.0 - 1e-9,
        },
        Case {
            key: "nearly_flat",
            name: "nearly flat (a/ell=1e-10)",
            n: 3.0,
            a_over_ell: 1e-10,
        },
    ];
    if family != Family::WallLadder {
        out.push(Case {
            key: "heavy_cube",
            name: "heavy cube (n=1e12)",
            n: 1e12,
            a_over_ell: 0.25,
        });
        out.push(Case {
            key: "light_cube",
            name: "light cube (n=1e-12)",
            n: 1e-12,
            a_over_ell: 0.25,
        });
    }
    out
}

/// One measured setting of one method on one case.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The model.
    pub model: &'static str,
    /// What was measured.
    pub measured: Measured,
    /// The case's key.
    pub case: &'static str,
    /// The method's short label ([`settings::LABELS`] describes it).
    pub label: &'static str,
    /// Its setting (nodes, tolerance, step).
    pub setting: String,
    /// Relative error against the reference (for a series, the largest over its samples);
    /// NaN when the method failed.
    pub error: f64,
    /// Model evaluations (integrand, polynomial or right-hand side).
    pub evals: u64,
    /// Integrator steps (accepted, rejected and event trials), for the integrated routes.
    pub steps: Option<u64>,
    /// Seconds of the set-up, made once and reused by every solve; `None` for a method
    /// without one.
    pub setup_seconds: Option<f64>,
    /// Seconds per solve, the set-up excluded.
    pub seconds: f64,
    /// Why it failed, or a remark.
    pub note: String,
}

impl Row {
    /// A setting not measured yet: no error (NaN), no evaluations, no time, no note.
    pub fn unmeasured(
        model: &'static str,
        measured: Measured,
        case: &'static str,
        label: &'static str,
        setting: String,
    ) -> Row {
        Row {
            model,
            measured,
            case,
            label,
            setting,
            error: f64::NAN,
            evals: 0,
            steps: None,
            setup_seconds: None,
            seconds: 0.0,
            note: String::new(),
        }
    }
}

/// The reference values of one case, with the agreement of the two routes.
#[derive(Debug, Clone)]
pub struct CaseReference {
    /// The case.
    pub case: Case,
    /// `theta_sep` (closed form).
    pub angle: BigFloat,
    /// `t_sep` (sinh route).
    pub time: BigFloat,
    /// Relative difference of the two root routes.
    pub angle_routes: f64,
    /// Relative difference of the two time routes.
    pub time_routes: f64,
}

/// A setting's answer, its cost in evaluations, and its times.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement<T> {
    /// The answer of the first solve.
    pub value: T,
    /// Model evaluations of one solve.
    pub evals: u64,
    /// Seconds per set-up, if the method has one.
    pub setup_seconds: Option<f64>,
    /// Seconds per solve, the set-up made once before the timing.
    pub seconds: f64,
}

/// Measures a method with set-up `prepare` and solve `solve`: one set-up and one solve for the
/// answer, then (if `has_setup`) the set-up alone timed, then the solve alone timed on the
/// first set-up's state. No set-up runs once the solve's timing has begun.
pub fn measure<S, T>(
    mut prepare: impl FnMut() -> Result<S, AccuracyError>,
    mut solve: impl FnMut(&mut S) -> methods::Outcome<T>,
    has_setup: bool,
    budget: &Budget,
) -> Result<Measurement<T>, AccuracyError> {
    let mut state = prepare()?;
    let (value, evals) = solve(&mut state)?;
    let setup_seconds = has_setup.then(|| time_per_call(budget, &mut prepare));
    let seconds = time_per_call(budget, || solve(&mut state));
    Ok(Measurement {
        value,
        evals,
        setup_seconds,
        seconds,
    })
}

/// Seconds per call of `f`, repeated until the budget has passed: in batches that double, so
/// that reading the clock costs nothing next to a call of a fraction of a microsecond.
fn time_per_call<T>(budget: &Budget, mut f: impl FnMut() -> T) -> f64 {
    let start = Instant::now();
    let (mut n, mut batch) = (0u64, 1u64);
    while n < u64::from(budget.min_repeats) || start.elapsed() < budget.time {
        for _ in 0..batch {
            std::hint::black_box(f());
        }
        n += batch;
        batch = (2 * batch).min(1 << 16);
    }
    start.elapsed().as_secs_f64() / n.max(1) as f64
}

/// The reference of one case.
pub fn case_reference(
    family: Family,
    case: Case,
) -> Result<(Reference, CaseReference), AccuracyError> {
    let mut r = Reference::new(Inputs::dimensionless(family, case.n, case.a_over_ell))?;
    let a1 = r.separation(RootRoute::ClosedForm)?;
    let a2 = r.separation(RootRoute::Newton)?;
    let t1 = r.separation_time(TimeRoute::SinhGauss)?;
    let t2 = r.separation_time(TimeRoute::TanhSinh)?;
    let info = CaseReference {
        case,
        angle_routes: reference::relative_difference(&a1.theta, &a2.theta),
        time_routes: reference::relative_difference(&t1, &t2),
        angle: a1.theta,
        time: t1,
    };
    Ok((r, info))
}

/// The parameters of a case for a model of the family (`ell = g = 1`).
fn parameters(family: Family, case: Case) -> Vec<f64> {
    match family {
        Family::WallLadder => vec![1.0, 1.0, case.a_over_ell, 1.0],
        _ => vec![1.0, case.n, 1.0, case.a_over_ell, 1.0],
    }
}

/// What `rodcube accuracy` measures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Options {
    /// Models by name: closed-form ones ([`CLOSED_MODELS`]) and integrated ones
    /// ([`integrated::MODELS`]); empty means `rod_cube` and every integrated model.
    pub models: Vec<String>,
    /// Case keys (`paper`, `near_upright`, ..., `scene`); empty means every case.
    pub cases: Vec<String>,
    /// Method labels ([`settings::LABELS`]); empty means every method.
    pub methods: Vec<String>,
    /// Fewer settings per method and a smaller timing budget ([`Budget::QUICK`]).
    pub quick: bool,
}

/// The models with a closed-form reference.
pub const CLOSED_MODELS: [&str; 3] = ["rod_cube", "hinged_rod", "wall_ladder"];

/// A report's rows and the references they were measured against.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Every measured setting.
    pub rows: Vec<Row>,
    /// The closed-form models' references, by model.
    pub references: Vec<(&'static str, CaseReference)>,
    /// The integrated models' references.
    pub integrated: Vec<integrated::IntegratedReference>,
}

/// Receives a sentence per model and case.
pub type LineSink = Box<dyn Fn(&str)>;

/// How [`run`] says what it is doing: a bar advanced once per setting, and a line per model
/// and case (for output that is not a terminal).
pub struct Progress {
    bar: ProgressBar,
    line: Option<LineSink>,
}

impl Progress {
    /// Advances `bar`; `line`, if given, receives a sentence per model and case.
    pub fn new(bar: ProgressBar, line: Option<LineSink>) -> Progress {
        Progress { bar, line }
    }

    /// Says nothing.
    pub fn hidden() -> Progress {
        Progress::new(ProgressBar::hidden(), None)
    }

    /// The bar.
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    fn case(&self, model: &str, case: &str, settings: usize) {
        if let Some(line) = &self.line {
            line(&format!(
                "accuracy: {model}, case {case}: {settings} settings"
            ));
        }
    }

    fn step(&self, message: String) {
        self.bar.set_message(message);
        self.bar.inc(1);
    }
}

/// The options checked against what the report has.
#[derive(Debug, Clone)]
pub struct Chosen {
    /// Closed-form models with their cases.
    pub closed: Vec<(&'static str, Family, Vec<Case>)>,
    /// Integrated models.
    pub integrated: Vec<&'static integrated::IntegratedModel>,
    methods: Vec<String>,
    quick: bool,
}

impl Chosen {
    fn wants(&self, label: &str) -> bool {
        self.methods.is_empty() || self.methods.iter().any(|m| m == label)
    }

    fn angle(&self) -> Vec<Setting<f64>> {
        let mut s = settings::angle();
        s.retain(|x| self.wants(x.label));
        s
    }

    fn time(&self) -> Vec<Setting<f64>> {
        let mut s = settings::time(self.quick);
        s.retain(|x| self.wants(x.label));
        s
    }

    fn series(&self) -> Vec<Setting<methods::Samples>> {
        let mut s = settings::series(self.quick);
        s.retain(|x| self.wants(x.label));
        s
    }

    fn sensitivities(&self) -> Vec<Setting<Vec<f64>>> {
        let mut s = settings::sensitivities(self.quick);
        s.retain(|x| self.wants(x.label));
        s
    }

    fn integrators(&self) -> Vec<Method> {
        [Method::Dopri5, Method::Dop853]
            .into_iter()
            .filter(|m| self.wants(integrated::label(*m)))
            .collect()
    }

    /// How many settings [`run`] measures (for a progress bar).
    pub fn settings(&self) -> usize {
        let per_case = self.angle().len()
            + self.time().len()
            + self.series().len()
            + self.sensitivities().len();
        let closed: usize = self.closed.iter().map(|(_, _, c)| c.len() * per_case).sum();
        let integrated = self.integrated.len()
            * self.integrators().len()
            * integrated::tolerances(self.quick).len();
        closed + integrated
    }

    /// The timing budget.
    pub fn budget(&self) -> Budget {
        if self.quick {
            Budget::QUICK
        } else {
            Budget::FULL
        }
    }
}

fn known(names: impl IntoIterator<Item = impl AsRef<str>>) -> String {
    names
        .into_iter()
        .map(|n| n.as_ref().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

impl Options {
    /// Checks every model, case and method named, and what they leave to measure.
    pub fn choose(&self) -> Result<Chosen, AccuracyError> {
        let models: Vec<&str> = if self.models.is_empty() {
            let mut m = vec!["rod_cube"];
            m.extend(integrated::MODELS.iter().map(|i| i.model));
            m
        } else {
            self.models.iter().map(String::as_str).collect()
        };
        let mut closed = Vec::new();
        let mut integrated_models = Vec::new();
        for name in models {
            if let (Some(family), Some(&model)) =
                (Family::of(name), CLOSED_MODELS.iter().find(|m| **m == name))
            {
                closed.push((model, family, cases(family)));
            } else if let Some(m) = integrated::find(name) {
                integrated_models.push(m);
            } else {
                return Err(AccuracyError::UnknownModel {
                    name: name.to_string(),
                    known: known(
                        CLOSED_MODELS
                            .iter()
                            .copied()
                            .chain(integrated::MODELS.iter().map(|m| m.model)),
                    ),
                });
            }
        }
        let mut keys: Vec<&str> = Vec::new();
        for key in (closed.iter().flat_map(|(_, _, c)| c.iter().map(|c| c.key)))
            .chain(integrated_models.iter().map(|m| m.case))
        {
            if !keys.contains(&key) {
                keys.push(key);
            }
        }
        if let Some(bad) = self.cases.iter().find(|c| !keys.contains(&c.as_str())) {
            return Err(AccuracyError::UnknownCase {
                name: bad.clone(),
                known: known(&keys),
            });
        }
        let labels = settings::LABELS.iter().map(|(l, _)| *l);
        if let Some(bad) = (self.methods.iter()).find(|m| !labels.clone().any(|l| l == m.as_str()))
        {
            return Err(AccuracyError::UnknownMethod {
                name: bad.clone(),
                known: known(labels),
            });
        }
        let wants_case = |key: &str| self.cases.is_empty() || self.cases.iter().any(|c| c == key);
        for (_, _, c) in &mut closed {
            c.retain(|c| wants_case(c.key));
        }
        closed.retain(|(_, _, c)| !c.is_empty());
        integrated_models.retain(|m| wants_case(m.case));
        let chosen = Chosen {
            closed,
            integrated: integrated_models,
            methods: self.methods.clone(),
            quick: self.quick,
        };
        if chosen.settings() == 0 {
            return Err(AccuracyError::Nothing {
                why: "no chosen method applies to a chosen model and case (the closed-form models \
                      rod_cube, hinged_rod and wall_ladder have the root, quadrature, series and \
                      sensitivity methods; the integrated models have dopri5 and dop853)"
                    .into(),
            });
        }
        Ok(chosen)
    }
}

/// Runs what `chosen` names, advancing `progress` once per setting.
pub fn run(chosen: &Chosen, progress: &Progress) -> Result<Report, AccuracyError> {
    let mut report = Report::default();
    let budget = chosen.budget();
    for (model, family, cases) in &chosen.closed {
        for case in cases {
            let (rows, cref) = run_case(chosen, model, *family, *case, &budget, progress)?;
            report.rows.extend(rows);
            report.references.push((model, cref));
        }
    }
    let integrators = chosen.integrators();
    let tolerances = integrated::tolerances(chosen.quick);
    for m in &chosen.integrated {
        progress.case(m.model, m.case, integrators.len() * tolerances.len());
        let reference = integrated::reference(m).map_err(|e| AccuracyError::Reference {
            model: m.model.into(),
            case: m.case.into(),
            source: Box::new(e),
        })?;
        for &method in &integrators {
            for &k in &tolerances {
                report
                    .rows
                    .push(integrated::measure_one(m, &reference, method, k, &budget));
                progress.step(format!("{}: {} rtol 1e-{k}", m.model, method.name()));
            }
        }
        report.integrated.push(reference);
    }
    Ok(report)
}

/// Every chosen method on one case of a closed-form model.
fn run_case(
    chosen: &Chosen,
    model: &'static str,
    family: Family,
    case: Case,
    budget: &Budget,
    progress: &Progress,
) -> Result<(Vec<Row>, CaseReference), AccuracyError> {
    let failed = |e: AccuracyError| AccuracyError::Reference {
        model: model.into(),
        case: case.key.into(),
        source: Box::new(e),
    };
    let (angle, time, series) = (chosen.angle(), chosen.time(), chosen.series());
    let sensitivities = chosen.sensitivities();
    let settings = angle.len() + time.len() + series.len() + sensitivities.len();
    progress.case(model, case.key, settings);
    let (mut reference, cref) = case_reference(family, case).map_err(failed)?;
    let m = crate::models::find(model)
        .ok_or_else(|| failed(AccuracyError::NoModel { name: model.into() }))?;
    // The phase the reference describes: the contact closed from release.
    let m = crate::solve::fast::lean::release_phase(m).map_err(|e| failed(e.into()))?;
    let sys = System::from_values(m, &parameters(family, case)).map_err(|e| failed(e.into()))?;
    let delta = methods::delta_sep(&sys).map_err(failed)?;
    let point = Point {
        sys: &sys,
        delta,
        t_max: 100.0 * reference::to_f64(&cref.time),
    };
    let mut rows = Vec::new();
    let row =
        |measured, s: &dyn Labelled, outcome: Result<(f64, Measurement<()>), AccuracyError>| {
            let mut r = Row::unmeasured(model, measured, case.key, s.label(), s.setting());
            match outcome {
                Ok((error, m)) => {
                    r.error = error;
                    r.evals = m.evals;
                    r.setup_seconds = m.setup_seconds;
                    r.seconds = m.seconds;
                }
                Err(e) => r.note = e.to_string(),
            }
            r
        };
    for s in &angle {
        let outcome = s.measure(&point, budget).map(|m| {
            (
                reference::relative_error(m.value, &cref.angle),
                m.without_value(),
            )
        });
        rows.push(row(Measured::Angle, s, outcome));
        progress.step(format!("{model} {}: {} {}", case.key, s.label, s.setting));
    }
    for s in &time {
        let outcome = s.measure(&point, budget).map(|m| {
            (
                reference::relative_error(m.value, &cref.time),
                m.without_value(),
            )
        });
        rows.push(row(Measured::Time, s, outcome));
        progress.step(format!("{model} {}: {} {}", case.key, s.label, s.setting));
    }
    for s in &series {
        let outcome = s.measure(&point, budget).and_then(|m| {
            let (t, d) = &m.value;
            let e = series_error(&mut reference, &sys, t, d)?;
            Ok((e, m.without_value()))
        });
        rows.push(row(Measured::Series, s, outcome));
        progress.step(format!("{model} {}: {} {}", case.key, s.label, s.setting));
    }
    if !sensitivities.is_empty() {
        let exact = reference_sensitivities(family, case, &sys, &cref).map_err(failed)?;
        for s in &sensitivities {
            let outcome = s.measure(&point, budget).map(|m| {
                let worst = (m.value.iter().zip(&exact))
                    .map(|(x, (reference, scale))| {
                        reference::derivative_error(*x, *reference, *scale)
                    })
                    .fold(0.0, f64::max);
                (worst, m.without_value())
            });
            rows.push(row(Measured::Sensitivities, s, outcome));
            progress.step(format!("{model} {}: {} {}", case.key, s.label, s.setting));
        }
    }
    Ok((rows, cref))
}

/// The reference's derivatives of a case, `d theta_sep/dp` then `d t_sep/dp` in the order of
/// the system's parameters, each with the scale it is compared at (its quantity over its
/// parameter: [`reference::derivative_error`]): 256-bit central differences
/// ([`reference::derivatives`]).
fn reference_sensitivities(
    family: Family,
    case: Case,
    sys: &System,
    cref: &CaseReference,
) -> Result<Vec<(f64, f64)>, AccuracyError> {
    let inputs = Inputs::dimensionless(family, case.n, case.a_over_ell);
    let (angle, time) = (
        reference::to_f64(&cref.angle),
        reference::to_f64(&cref.time),
    );
    let (mut d_angle, mut d_time) = (Vec::new(), Vec::new());
    for (spec, &value) in sys.model().info().parameters.iter().zip(sys.p()) {
        let j = (reference::PARAMETERS.iter())
            .position(|n| *n == spec.name)
            .ok_or(AccuracyError::NoReferenceParameter { name: spec.name })?;
        let (dt, dtime) = reference::derivatives(inputs, j)?;
        d_angle.push((dt, angle / value));
        d_time.push((dtime, time / value));
    }
    d_angle.extend(d_time);
    Ok(d_angle)
}

/// A setting's label and setting, whatever it computes.
trait Labelled {
    fn label(&self) -> &'static str;
    fn setting(&self) -> String;
}

impl<T> Labelled for Setting<T> {
    fn label(&self) -> &'static str {
        self.label
    }
    fn setting(&self) -> String {
        self.setting.clone()
    }
}

impl<T> Measurement<T> {
    /// The evaluations and times without the answer.
    fn without_value(&self) -> Measurement<()> {
        Measurement {
            value: (),
            evals: self.evals,
            setup_seconds: self.setup_seconds,
            seconds: self.seconds,
        }
    }
}

/// The largest relative error of `theta` over a series `(t_j, delta_j)`: the reference time
/// `t_ref(delta_j)` in high precision, and `theta_ref(t_j) - theta_j` to first order,
/// `|theta_dot(delta_j)| (t_j - t_ref(delta_j))` (relative to `theta_j`), exact to a relative
/// `O(error)`.
fn series_error(
    reference: &mut Reference,
    sys: &System,
    t: &[f64],
    d: &[f64],
) -> Result<f64, AccuracyError> {
    let times = reference.times_at(d)?;
    let theta_i = sys.theta_initial();
    let mut worst: f64 = 0.0;
    for j in 0..t.len() {
        let dt = t[j] - reference::to_f64(&times[j]);
        let dtheta = reference.theta_dot(d[j]) * dt;
        let theta = theta_i - d[j];
        let e = (dtheta / theta).abs();
        if !e.is_finite() {
            return Err(AccuracyError::NonFiniteSeriesError { sample: j });
        }
        worst = worst.max(e);
    }
    Ok(worst)
}

/// The rows as CSV (`model,quantity,case,method,setting,relative_error,evaluations,steps,
/// setup_seconds,seconds_per_solve,note`; an empty cell is a value the row has not).
pub fn to_csv(rows: &[Row]) -> Result<String, AccuracyError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let fail = |e: csv::Error| csv_error(&e);
    w.write_record([
        "model",
        "quantity",
        "case",
        "method",
        "setting",
        "relative_error",
        "evaluations",
        "steps",
        "setup_seconds",
        "seconds_per_solve",
        "note",
    ])
    .map_err(fail)?;
    let or_empty = |v: Option<String>| v.unwrap_or_default();
    for r in rows {
        let failed = r.error.is_nan();
        w.write_record([
            r.model.to_string(),
            r.measured.name().to_string(),
            r.case.to_string(),
            r.label.to_string(),
            r.setting.clone(),
            or_empty((!failed).then(|| format!("{:e}", r.error))),
            or_empty((!failed).then(|| r.evals.to_string())),
            or_empty(r.steps.map(|s| s.to_string())),
            or_empty(r.setup_seconds.map(|s| format!("{s:e}"))),
            or_empty((!failed).then(|| format!("{:e}", r.seconds))),
            r.note.clone(),
        ])
        .map_err(fail)?;
    }
    let bytes = w.into_inner().map_err(|e| csv_error(&e))?;
    String::from_utf8(bytes).map_err(|e| csv_error(&e))
}

/// The CSV writer's failure, by its message.
fn csv_error(e: &dyn std::fmt::Display) -> AccuracyError {
    AccuracyError::Csv {
        message: e.to_string(),
    }
}
