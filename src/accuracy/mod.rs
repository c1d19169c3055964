//! `rodcube accuracy`: what accuracy costs in time. Every method the project ships, and the
//! ones a user would reach for, is run on the paper's case and on the hard cases (near upright,
//! nearly flat, extreme mass ratios) and compared with the independent high-precision
//! [`reference`](mod@crate::reference): relative error, model evaluations and time per solve, as a
//! table, a CSV and log–log SVG plots of error against time with the Pareto front marked.

pub mod methods;
pub mod plot;

use crate::reference::{self, Family, Inputs, Reference, RootRoute, TimeRoute};
use crate::solve::prior::PRIOR_TOL;
use crate::system::System;
use astro_float::BigFloat;
use indicatif::ProgressBar;
use std::time::{Duration, Instant};

/// Samples in each `theta(t)` series.
pub const SERIES_SAMPLES: usize = 101;

/// Each setting is repeated until this much time has passed (at least [`MIN_REPEATS`] times).
pub const TIMING_BUDGET: Duration = Duration::from_millis(25);

/// Fewest timed repetitions of a setting.
pub const MIN_REPEATS: u32 = 3;

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
}

impl Measured {
    /// Name in the table, the CSV and the file names.
    pub fn name(self) -> &'static str {
        match self {
            Measured::Angle => "separation_angle",
            Measured::Time => "separation_time",
            Measured::Series => "theta_series",
        }
    }
}

/// One test case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    /// Short name.
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
            name: "paper (n=3, a/ell=1/4)",
            n: 3.0,
            a_over_ell: 0.25,
        },
        Case {
            name: "near upright (a/ell=1-1e-9)",
            n: 3.0,
            a_over_ell: 1.0 - 1e-9,
        },
        Case {
            name: "nearly flat (a/ell=1e-10)",
            n: 3.0,
            a_over_ell: 1e-10,
        },
    ];
    if family != Family::WallLadder {
        out.push(Case {
            name: "heavy cube (n=1e12)",
            n: 1e12,
            a_over_ell: 0.25,
        });
        out.push(Case {
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
    /// What was measured.
    pub measured: Measured,
    /// The case's name.
    pub case: &'static str,
    /// The method.
    pub method: &'static str,
    /// Its setting (nodes, tolerance, step).
    pub setting: String,
    /// Relative error against the reference (for a series, the largest over its samples);
    /// NaN when the method failed.
    pub error: f64,
    /// Model evaluations (integrand, polynomial or right-hand side).
    pub evals: u64,
    /// Seconds per solve.
    pub seconds: f64,
    /// Why it failed, or a remark.
    pub note: String,
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

/// A method setting: its name, setting label and the function computing its answer.
type AngleFn = Box<dyn Fn(&System) -> methods::Outcome<f64>>;
type TimeFn = Box<dyn Fn(&System, f64, f64) -> methods::Outcome<f64>>;
type SeriesFn = Box<dyn Fn(&System, f64, f64) -> methods::Outcome<methods::Samples>>;

fn angle_methods() -> Vec<(&'static str, String, AngleFn)> {
    vec![
        (
            "default: isolation + bracketed Halley",
            "filtered Horner".into(),
            Box::new(methods::angle_default),
        ),
        (
            "closed form (Viete)",
            "f64".into(),
            Box::new(methods::angle_closed_form),
        ),
        (
            "Newton from sin(theta_i)",
            "plain Horner".into(),
            Box::new(methods::angle_newton),
        ),
        (
            "bisection",
            "to adjacent floats".into(),
            Box::new(methods::angle_bisection),
        ),
        (
            "linearised (paper)",
            "cubic term dropped".into(),
            Box::new(methods::angle_linearised),
        ),
    ]
}

/// Time methods; the function gets the system, `delta_sep` and a time bound for the ODEs.
fn time_methods() -> Vec<(&'static str, String, TimeFn)> {
    let mut out: Vec<(&'static str, String, TimeFn)> = Vec::new();
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14] {
        out.push((
            "default: sin/sinh subst., GL pairs by panel length",
            format!("tol {tol:.0e}"),
            Box::new(move |s, d, _| methods::time_default(s, d, tol)),
        ));
    }
    for tol in [1e-6, 1e-10, 1e-14, PRIOR_TOL] {
        out.push((
            "per point: sin/sinh subst., GL nodes a priori from singularities",
            format!("tol {tol:.0e}"),
            Box::new(move |s, d, _| methods::time_prior(s, d, tol)),
        ));
    }
    for (low, high) in [(6, 9), (8, 12)] {
        out.push((
            "per point: sin/sinh subst., fixed GL pair per panel",
            format!("GL {low} vs {high}"),
            Box::new(move |s, _, _| methods::time_lean_fixed(s, low, high, 1e-12)),
        ));
    }
    for nodes in [5, 10, 20, 40, 80] {
        out.push((
            "GL after delta=u^2, one panel",
            format!("{nodes} nodes"),
            Box::new(move |s, d, _| methods::time_gl_u2(s, d, nodes)),
        ));
    }
    for nodes in [5, 10, 20, 40, 80] {
        out.push((
            "Gauss-Jacobi, weight (1+x)^-1/2",
            format!("{nodes} nodes"),
            Box::new(move |s, d, _| methods::time_gauss_jacobi(s, d, nodes)),
        ));
    }
    for level in 1..=7 {
        let h = 0.5f64.powi(level);
        out.push((
            "tanh-sinh, raw integrand",
            format!("h = 2^-{level}"),
            Box::new(move |s, d, _| methods::time_tanh_sinh(s, d, h)),
        ));
    }
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        out.push((
            "adaptive Gauss-Kronrod 7/15, raw integrand",
            format!("tol {tol:.0e}"),
            Box::new(move |s, d, _| methods::time_gauss_kronrod(s, d, tol)),
        ));
    }
    for k in [3, 4, 6, 8, 10, 12] {
        let rtol = 10f64.powi(-k);
        out.push((
            "DOPRI5 on theta'' with event",
            format!("rtol 1e-{k}"),
            Box::new(move |s, d, t| methods::time_reduced_ode(s, d, rtol, t)),
        ));
    }
    for k in [3, 4, 6, 8, 10, 12] {
        let rtol = 10f64.powi(-k);
        out.push((
            "unreduced equations, DOPRI5 + contact event",
            format!("rtol 1e-{k}"),
            Box::new(move |s, _, t| methods::time_unreduced(s, rtol, t)),
        ));
    }
    out
}

fn series_methods() -> Vec<(&'static str, String, SeriesFn)> {
    let mut out: Vec<(&'static str, String, SeriesFn)> = Vec::new();
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        out.push((
            "default: quadrature t(v) inverted by Newton",
            format!("tol {tol:.0e}"),
            Box::new(move |s, d, _| methods::series_quadrature(s, d, tol, SERIES_SAMPLES)),
        ));
    }
    for k in [3, 4, 6, 8, 10, 12] {
        let rtol = 10f64.powi(-k);
        out.push((
            "DOPRI5 on theta'', dense output",
            format!("rtol 1e-{k}"),
            Box::new(move |s, d, t| methods::series_ode(s, d, rtol, t, SERIES_SAMPLES)),
        ));
    }
    out
}

/// How many settings [`run`] measures per case (for a progress bar).
pub fn settings_per_case() -> usize {
    angle_methods().len() + time_methods().len() + series_methods().len()
}

/// Seconds per call of `f`, repeated until [`TIMING_BUDGET`] has passed.
fn time_per_call<T>(mut f: impl FnMut() -> T) -> f64 {
    let start = Instant::now();
    let mut n = 0u32;
    while n < MIN_REPEATS || start.elapsed() < TIMING_BUDGET {
        std::hint::black_box(f());
        n += 1;
        if n >= 100_000 {
            break;
        }
    }
    start.elapsed().as_secs_f64() / f64::from(n)
}

/// The reference of one case.
pub fn case_reference(family: Family, case: Case) -> Result<(Reference, CaseReference), String> {
    let mut r = Reference::new(Inputs::dimensionless(family, case.n, case.a_over_ell))
        .map_err(|e| e.to_string())?;
    let a1 = r
        .separation(RootRoute::ClosedForm)
        .map_err(|e| e.to_string())?;
    let a2 = r.separation(RootRoute::Newton).map_err(|e| e.to_string())?;
    let t1 = r
        .separation_time(TimeRoute::SinhGauss)
        .map_err(|e| e.to_string())?;
    let t2 = r
        .separation_time(TimeRoute::TanhSinh)
        .map_err(|e| e.to_string())?;
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

/// Runs every method on every case of `model` (one of `rod_cube`, `hinged_rod`,
/// `wall_ladder`), advancing `progress` once per setting.
pub fn run(model: &str, progress: &ProgressBar) -> Result<(Vec<Row>, Vec<CaseReference>), String> {
    let family = Family::of(model).ok_or_else(|| {
        format!(
            "`rodcube accuracy` needs a model with a closed-form reference (rod_cube, hinged_rod, wall_ladder), not `{model}`"
        )
    })?;
    let m = crate::models::find(model).ok_or_else(|| format!("no model `{model}`"))?;
    let mut rows = Vec::new();
    let mut refs = Vec::new();
    for case in cases(family) {
        let (mut reference, cref) = case_reference(family, case)?;
        let sys = System::from_values(m, &parameters(family, case)).map_err(|e| e.to_string())?;
        let delta = methods::delta_sep(&sys)?;
        let t_ref = reference::to_f64(&cref.time);
        let t_max = 100.0 * t_ref;
        let row =
            |measured, method, setting: String, error: f64, evals, seconds, note: String| Row {
                measured,
                case: case.name,
                method,
                setting,
                error,
                evals,
                seconds,
                note,
            };
        for (method, setting, f) in angle_methods() {
            progress.set_message(format!("{}: {method}", case.name));
            match f(&sys) {
                Ok((theta, evals)) => {
                    let seconds = time_per_call(|| f(&sys));
                    let e = reference::relative_error(theta, &cref.angle);
                    rows.push(row(
                        Measured::Angle,
                        method,
                        setting,
                        e,
                        evals,
                        seconds,
                        String::new(),
                    ));
                }
                Err(note) => rows.push(row(
                    Measured::Angle,
                    method,
                    setting,
                    f64::NAN,
                    0,
                    0.0,
                    note,
                )),
            }
            progress.inc(1);
        }
        for (method, setting, f) in time_methods() {
            progress.set_message(format!("{}: {method} {setting}", case.name));
            match f(&sys, delta, t_max) {
                Ok((t, evals)) => {
                    let seconds = time_per_call(|| f(&sys, delta, t_max));
                    let e = reference::relative_error(t, &cref.time);
                    rows.push(row(
                        Measured::Time,
                        method,
                        setting,
                        e,
                        evals,
                        seconds,
                        String::new(),
                    ));
                }
                Err(note) => {
                    rows.push(row(Measured::Time, method, setting, f64::NAN, 0, 0.0, note))
                }
            }
            progress.inc(1);
        }
        for (method, setting, f) in series_methods() {
            progress.set_message(format!("{}: {method} {setting}", case.name));
            match f(&sys, delta, t_max) {
                Ok(((t, d), evals)) => {
                    let seconds = time_per_call(|| f(&sys, delta, t_max));
                    let (e, note) = match series_error(&mut reference, &sys, &t, &d) {
                        Ok(e) => (e, String::new()),
                        Err(note) => (f64::NAN, note),
                    };
                    rows.push(row(
                        Measured::Series,
                        method,
                        setting,
                        e,
                        evals,
                        seconds,
                        note,
                    ));
                }
                Err(note) => rows.push(row(
                    Measured::Series,
                    method,
                    setting,
                    f64::NAN,
                    0,
                    0.0,
                    note,
                )),
            }
            progress.inc(1);
        }
        refs.push(cref);
    }
    Ok((rows, refs))
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
) -> Result<f64, String> {
    let times = reference.times_at(d).map_err(|e| e.to_string())?;
    let theta_i = sys.theta_initial();
    let mut worst: f64 = 0.0;
    for j in 0..t.len() {
        let dt = t[j] - reference::to_f64(&times[j]);
        let dtheta = reference.theta_dot(d[j]) * dt;
        let theta = theta_i - d[j];
        let e = (dtheta / theta).abs();
        if !e.is_finite() {
            return Err(format!("non-finite error at sample {j}"));
        }
        worst = worst.max(e);
    }
    Ok(worst)
}

/// The rows as CSV (`quantity,case,method,setting,relative_error,evaluations,seconds_per_solve,note`).
pub fn to_csv(rows: &[Row]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record([
        "quantity",
        "case",
        "method",
        "setting",
        "relative_error",
        "evaluations",
        "seconds_per_solve",
        "note",
    ]);
    for r in rows {
        let _ = w.write_record([
            r.measured.name().to_string(),
            r.case.to_string(),
            r.method.to_string(),
            r.setting.clone(),
            if r.error.is_nan() {
                String::new()
            } else {
                format!("{:e}", r.error)
            },
            r.evals.to_string(),
            format!("{:e}", r.seconds),
            r.note.clone(),
        ]);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// The human table: one block per quantity and case.
pub fn table(rows: &[Row], refs: &[CaseReference]) -> String {
    use comfy_table::{Table, presets::UTF8_FULL_CONDENSED};
    let mut out = String::new();
    for r in refs {
        out.push_str(&format!(
            "reference {}: theta_sep = {:.17e} rad (root routes agree to {:.1e}), t_sep = {:.17e} sqrt(ell/g) (quadrature routes agree to {:.1e})\n",
            r.case.name,
            reference::to_f64(&r.angle),
            r.angle_routes,
            reference::to_f64(&r.time),
            r.time_routes
        ));
    }
    for measured in [Measured::Angle, Measured::Time, Measured::Series] {
        let mut table = Table::new();
        table.load_style(UTF8_FULL_CONDENSED);
        table.set_header([
            "case",
            "method",
            "setting",
            "rel. error",
            "evals",
            "time/solve",
        ]);
        for r in rows.iter().filter(|r| r.measured == measured) {
            let error = if r.error.is_nan() {
                format!("failed: {}", shorten(&r.note, 60))
            } else {
                format!("{:.1e}", r.error.abs())
            };
            table.add_row([
                r.case.to_string(),
                r.method.to_string(),
                r.setting.clone(),
                error,
                r.evals.to_string(),
                if r.seconds > 0.0 {
                    format_seconds(r.seconds)
                } else {
                    "-".into()
                },
            ]);
        }
        out.push_str(&format!("\n{}\n{table}\n", measured.name()));
    }
    out
}

fn shorten(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        let cut: String = s.chars().take(n).collect();
        format!("{cut}...")
    }
}

/// `1.2 us`, `3.4 ms`, `0.56 s`.
pub fn format_seconds(s: f64) -> String {
    if s < 1e-6 {
        format!("{:.0} ns", s * 1e9)
    } else if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}
