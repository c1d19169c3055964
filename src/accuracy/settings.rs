//! The settings `rodcube accuracy` measures on the closed-form models: every method with its
//! short label (the table's and `--method`'s), its description (the plots' and the legend's),
//! and the values of its setting, with the set-up separated from the solve.

use super::methods::{self, Outcome, Samples};
use super::{AccuracyError, Budget, Measurement, QUICK_SERIES_SAMPLES, SERIES_SAMPLES, measure};
use crate::solve::fast::lean::LeanSolver;
use crate::solve::fast::prior::PRIOR_TOL;
use crate::solve::fast::sensitivity::SensitivityWork;
use crate::system::System;

/// One case as a method sees it: the validated system, the end of its phase (`delta_sep`, from
/// the project's root) and a time bound for the integrators.
#[derive(Debug, Clone, Copy)]
pub struct Point<'p> {
    /// The system at the case's parameters.
    pub sys: &'p System<'static>,
    /// `delta_sep`.
    pub delta: f64,
    /// Time bound of the integrators (s).
    pub t_max: f64,
}

/// Measures a method at one setting on a point.
type Run<T> = Box<dyn Fn(&Point<'_>, &Budget) -> Result<Measurement<T>, AccuracyError>>;

/// One method at one setting.
pub struct Setting<T> {
    /// The method's short label ([`LABELS`]).
    pub label: &'static str,
    /// The setting (nodes, tolerance, step).
    pub setting: String,
    run: Run<T>,
}

impl<T> Setting<T> {
    /// Solves `point` once for the value and its evaluations, then times the set-up (if any)
    /// and the solve apart.
    pub fn measure(
        &self,
        point: &Point<'_>,
        budget: &Budget,
    ) -> Result<Measurement<T>, AccuracyError> {
        (self.run)(point, budget)
    }
}

impl<T> std::fmt::Debug for Setting<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Setting")
            .field("label", &self.label)
            .field("setting", &self.setting)
            .finish()
    }
}

/// A method without a set-up: each solve starts from the system.
fn plain<T: 'static>(
    label: &'static str,
    setting: String,
    solve: impl Fn(&Point<'_>) -> Outcome<T> + 'static,
) -> Setting<T> {
    Setting {
        label,
        setting,
        run: Box::new(move |point, budget| measure(|| Ok(()), |_| solve(point), false, budget)),
    }
}

/// A method whose set-up `prepare` (a solver, a rule) is made once and reused by every solve.
fn prepared<S: 'static, T: 'static>(
    label: &'static str,
    setting: String,
    prepare: impl Fn(&Point<'_>) -> Result<S, AccuracyError> + 'static,
    solve: impl Fn(&mut S, &Point<'_>) -> Outcome<T> + 'static,
) -> Setting<T> {
    Setting {
        label,
        setting,
        run: Box::new(move |point, budget| {
            measure(|| prepare(point), |s| solve(s, point), true, budget)
        }),
    }
}

/// Every method's short label and what it is, in the order of the report.
pub const LABELS: &[(&str, &str)] = &[
    (
        "halley",
        "default root: derivative isolation + bracketed Halley on filtered Horner",
    ),
    ("viete", "closed form of the cubic (Viete / Cardano) in f64"),
    ("newton", "plain Newton from sin(theta_i), plain Horner"),
    ("bisect", "bisection to adjacent floats"),
    ("linear", "the paper's linearised root (cubic term dropped)"),
    (
        "default",
        "default quadrature: sin/sinh substitution, Gauss-Legendre pairs by panel length",
    ),
    (
        "per-point",
        "per-point solver (root and time from the parameters): Gauss-Legendre nodes a priori from the singularities; set-up: the solver and its rule table",
    ),
    (
        "fixed-gl",
        "per-point solver with one fixed Gauss-Legendre pair on every panel; set-up: the solver",
    ),
    ("gl-u2", "one Gauss-Legendre panel after delta = u^2"),
    (
        "jacobi",
        "Gauss-Jacobi with weight (1+x)^-1/2; set-up: the nodes (Golub-Welsch)",
    ),
    ("tanh-sinh", "tanh-sinh on the raw integrand"),
    (
        "gk15",
        "global adaptive Gauss-Kronrod 7/15 on the raw integrand",
    ),
    ("rk-theta", "DOPRI5 on theta'' with an event at delta_sep"),
    (
        "rk-full",
        "DOPRI5 on the unreduced equations with the contact-force event",
    ),
    (
        "series",
        "default series: the quadrature t(v) inverted by Newton",
    ),
    (
        "exact",
        "sensitivities from the generated partial derivatives (implicit-function theorem, differentiated quadrature); set-up: the per-point solver",
    ),
    (
        "forward",
        "sensitivities from the general model's motion integrated on every phase with its forward sensitivities (the generated tangents), read at the separation",
    ),
    (
        "differences",
        "sensitivities by central differences of the per-point solver (two solves a parameter); set-up: the solver",
    ),
    ("rk-dense", "DOPRI5 on theta'' with dense output"),
    (
        "dopri5",
        "DOPRI5 (order 5) on the unreduced equations, events located on its dense output",
    ),
    (
        "dop853",
        "DOP853 (order 8) on the unreduced equations, events located on its dense output",
    ),
];

/// The description of a label (the label itself if it has none).
pub fn describe(label: &str) -> &str {
    LABELS
        .iter()
        .find(|(l, _)| *l == label)
        .map_or(label, |(_, d)| d)
}

/// `all`, or with `quick` its first, middle and last values.
pub fn pick<T: Copy>(all: &[T], quick: bool) -> Vec<T> {
    if !quick || all.len() <= 3 {
        return all.to_vec();
    }
    let picked = [0, all.len() / 2, all.len() - 1];
    picked.iter().filter_map(|&i| all.get(i).copied()).collect()
}

/// The separation angle's methods.
pub fn angle() -> Vec<Setting<f64>> {
    vec![
        plain("halley", "filtered Horner".into(), |p| {
            methods::angle_default(p.sys)
        }),
        plain("viete", "f64".into(), |p| methods::angle_closed_form(p.sys)),
        plain("newton", "plain Horner".into(), |p| {
            methods::angle_newton(p.sys)
        }),
        plain("bisect", "to adjacent floats".into(), |p| {
            methods::angle_bisection(p.sys)
        }),
        plain("linear", "cubic term dropped".into(), |p| {
            methods::angle_linearised(p.sys)
        }),
    ]
}

fn rtol_label(k: i32) -> String {
    format!("rtol 1e-{k}")
}

/// The separation time's methods (`quick`: fewer settings each).
pub fn time(quick: bool) -> Vec<Setting<f64>> {
    let mut out = Vec::new();
    for tol in pick(&[1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14], quick) {
        out.push(plain("default", format!("tol {tol:.0e}"), move |p| {
            methods::time_default(p.sys, p.delta, tol)
        }));
    }
    for tol in pick(&[1e-6, 1e-10, 1e-14, PRIOR_TOL], quick) {
        out.push(prepared(
            "per-point",
            format!("tol {tol:.0e}"),
            move |p| methods::per_point_solver(p.sys, tol),
            |s: &mut LeanSolver<'static>, p| methods::time_per_point(s, p.sys),
        ));
    }
    for (low, high) in [(6, 9), (8, 12)] {
        out.push(prepared(
            "fixed-gl",
            format!("GL {low} vs {high}"),
            move |p| methods::fixed_rules_solver(p.sys, low, high, 1e-12),
            |s: &mut LeanSolver<'static>, p| methods::time_per_point(s, p.sys),
        ));
    }
    for nodes in pick(&[5, 10, 20, 40, 80], quick) {
        out.push(plain("gl-u2", format!("{nodes} nodes"), move |p| {
            methods::time_gl_u2(p.sys, p.delta, nodes)
        }));
    }
    for nodes in pick(&[5, 10, 20, 40, 80], quick) {
        out.push(prepared(
            "jacobi",
            format!("{nodes} nodes"),
            move |_| methods::jacobi_rule(nodes),
            |rule: &mut Vec<(f64, f64)>, p| methods::time_gauss_jacobi(p.sys, p.delta, rule),
        ));
    }
    for level in pick(&[1, 2, 3, 4, 5, 6, 7], quick) {
        let h = 0.5f64.powi(level);
        out.push(plain("tanh-sinh", format!("h = 2^-{level}"), move |p| {
            methods::time_tanh_sinh(p.sys, p.delta, h)
        }));
    }
    for tol in pick(&[1e-4, 1e-6, 1e-8, 1e-10, 1e-12], quick) {
        out.push(plain("gk15", format!("tol {tol:.0e}"), move |p| {
            methods::time_gauss_kronrod(p.sys, p.delta, tol)
        }));
    }
    for k in pick(&[3, 4, 6, 8, 10, 12], quick) {
        let rtol = 10f64.powi(-k);
        out.push(plain("rk-theta", rtol_label(k), move |p| {
            methods::time_reduced_ode(p.sys, p.delta, rtol, p.t_max)
        }));
    }
    for k in pick(&[3, 4, 6, 8, 10, 12], quick) {
        let rtol = 10f64.powi(-k);
        out.push(plain("rk-full", rtol_label(k), move |p| {
            methods::time_unreduced(p.sys, rtol, p.t_max)
        }));
    }
    out
}

/// The `theta(t)` series' methods, each sampled [`SERIES_SAMPLES`] times (`quick`: fewer
/// settings, and [`QUICK_SERIES_SAMPLES`] samples: the reference's time at each sample is a
/// 256-bit quadrature, the report's largest cost).
pub fn series(quick: bool) -> Vec<Setting<Samples>> {
    let samples = if quick {
        QUICK_SERIES_SAMPLES
    } else {
        SERIES_SAMPLES
    };
    let mut out = Vec::new();
    for tol in pick(&[1e-4, 1e-6, 1e-8, 1e-10, 1e-12], quick) {
        out.push(plain("series", format!("tol {tol:.0e}"), move |p| {
            methods::series_quadrature(p.sys, p.delta, tol, samples)
        }));
    }
    for k in pick(&[3, 4, 6, 8, 10, 12], quick) {
        let rtol = 10f64.powi(-k);
        out.push(plain("rk-dense", rtol_label(k), move |p| {
            methods::series_ode(p.sys, p.delta, rtol, p.t_max, samples)
        }));
    }
    out
}

/// The sensitivities' methods (`d theta_sep/dp` and `d t_sep/dp` for every parameter): the
/// exact ones and central differences at relative steps around the best one for `f64`
/// (`eps^(1/3)`, about `6e-6`), on the per-point solver at its default tolerance.
pub fn sensitivities(quick: bool) -> Vec<Setting<Vec<f64>>> {
    let mut out = vec![prepared(
        "exact",
        format!("tol {PRIOR_TOL:.0e}"),
        |p| {
            Ok((
                methods::per_point_solver(p.sys, PRIOR_TOL)?,
                SensitivityWork::default(),
            ))
        },
        |(solver, work): &mut (LeanSolver<'static>, SensitivityWork), p| {
            methods::sensitivities_exact(solver, work, p.sys)
        },
    )];
    for rtol in pick(&[1e-8, 1e-10, 1e-12], quick) {
        out.push(plain("forward", format!("rtol {rtol:.0e}"), move |p| {
            methods::sensitivities_forward(p.sys, rtol)
        }));
    }
    for step in pick(&[1e-3, 1e-4, 1e-5, 6e-6, 1e-6, 1e-7, 1e-8], quick) {
        out.push(prepared(
            "differences",
            format!("step {step:.0e}"),
            |p| methods::per_point_solver(p.sys, PRIOR_TOL),
            move |solver: &mut LeanSolver<'static>, p| {
                methods::sensitivities_differences(solver, p.sys, step)
            },
        ));
    }
    out
}
