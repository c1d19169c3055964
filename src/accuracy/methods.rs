//! The methods compared by `rodcube accuracy`, each a function from a validated
//! [`System`] to a value and the model evaluations it took: the project's own solvers, and the
//! alternatives a user would try (closed forms, plain Newton and bisection, Gauss–Jacobi,
//! tanh–sinh and Gauss–Kronrod on the raw integrand, Runge–Kutta with event location). A method
//! with a set-up (a solver, a rule's nodes) has it in its own function, so that the report
//! times the set-up once and the solve alone, as a user who solves many points pays for them.

use super::AccuracyError;
use crate::results::{SensitivityGap, Work};
use crate::solve::SolveError;
use crate::solve::fast::lean::LeanSolver;
use crate::solve::fast::poly::horner;
use crate::solve::fast::quadrature::{TimeMesh, gauss_legendre_rule};
use crate::solve::fast::sensitivity::SensitivityWork;
use crate::solve::fast::separation::{linearised_separation, separation};
use crate::solve::integrated::contacts::Active;
use crate::solve::integrated::ode::{Method, OdeOptions, OdeProblem, dopri5};
use crate::solve::integrated::unreduced;
use crate::solve::phases::{Route, Walker};
use crate::solve::series::sample_phase;
use crate::system::{Bound, System};
use gauss_quad::{FiniteAboveNegOneF64, GaussJacobi};
use std::collections::BinaryHeap;
use std::num::NonZeroUsize;

/// A method's answer and its cost in model evaluations.
pub type Outcome<T> = Result<(T, u64), AccuracyError>;

/// Coefficients of the separation polynomial and the open interval of the phase.
fn polynomial(sys: &System) -> (Vec<f64>, f64, f64) {
    (
        sys.separation_coefficients(),
        sys.end_angle().sin(),
        sys.reduction().reduced(sys.k(), 0.0).sin,
    )
}

// ----------------------------------------------------------------------------------------
// Separation angle
// ----------------------------------------------------------------------------------------

/// The project's default: derivative isolation and bracketed Newton on compensated Horner.
pub fn angle_default(sys: &System) -> Outcome<f64> {
    let mut work = Work::default();
    let s = separation(sys, &mut work)?;
    let s = s.separation().ok_or(AccuracyError::NoSeparation)?;
    Ok((s.theta, work.polynomial_evals))
}

/// The paper's linearised root (terms above degree 1 dropped).
pub fn angle_linearised(sys: &System) -> Outcome<f64> {
    let s = linearised_separation(sys)?;
    Ok((s.separation().ok_or(AccuracyError::NoRoot)?.theta, 0))
}

/// The closed form of the cubic (Viete's trigonometric or hyperbolic form, Cardano for one
/// real root) on the generated coefficients, in `f64`: the largest root in the interval.
pub fn angle_closed_form(sys: &System) -> Outcome<f64> {
    let (c, lo, hi) = polynomial(sys);
    let degree = (c.iter().rposition(|&x| x != 0.0)).ok_or(AccuracyError::ZeroPolynomial)?;
    let roots: Vec<f64> = match degree {
        1 => vec![-c[0] / c[1]],
        2 => {
            let disc = c[1] * c[1] - 4.0 * c[2] * c[0];
            if disc < 0.0 {
                vec![]
            } else {
                let q = -0.5 * (c[1] + c[1].signum() * disc.sqrt());
                vec![q / c[2], c[0] / q]
            }
        }
        3 => {
            // s = t - b/3 with t^3 + p t + q = 0.
            let (a, b, cc, d) = (c[3], c[2] / c[3], c[1] / c[3], c[0] / c[3]);
            let _ = a;
            let p = cc - b * b / 3.0;
            let q = 2.0 * b * b * b / 27.0 - b * cc / 3.0 + d;
            let shift = -b / 3.0;
            let disc = q * q / 4.0 + p * p * p / 27.0;
            if p < 0.0 && disc < 0.0 {
                let m = 2.0 * (-p / 3.0).sqrt();
                let arg = (3.0 * q / (p * m)).clamp(-1.0, 1.0);
                let phi = arg.acos() / 3.0;
                (0..3)
                    .map(|k| m * (phi - 2.0 * std::f64::consts::PI * k as f64 / 3.0).cos() + shift)
                    .collect()
            } else {
                let sq = disc.max(0.0).sqrt();
                vec![(-q / 2.0 + sq).cbrt() + (-q / 2.0 - sq).cbrt() + shift]
            }
        }
        _ => return Err(AccuracyError::NoClosedForm { degree }),
    };
    let s = roots
        .into_iter()
        .filter(|&s| s > lo && s < hi)
        .fold(f64::NAN, f64::max);
    if s.is_nan() {
        return Err(AccuracyError::NoRootInInterval);
    }
    Ok((s.asin(), 1))
}

/// Most steps of plain Newton.
const NEWTON_STEPS: usize = 200;

/// Plain Newton on the generated polynomial from `sin(theta_i)` (no bracket, no compensation).
pub fn angle_newton(sys: &System) -> Outcome<f64> {
    let (c, _, hi) = polynomial(sys);
    let d: Vec<f64> = (1..c.len()).map(|i| i as f64 * c[i]).collect();
    let mut x = hi;
    let mut evals = 0;
    for _ in 0..NEWTON_STEPS {
        let step = horner(&c, x) / horner(&d, x);
        evals += 2;
        x -= step;
        if !x.is_finite() {
            return Err(AccuracyError::NewtonDiverged);
        }
        if step.abs() <= 2.0 * f64::EPSILON * x.abs() {
            return Ok((x.asin(), evals));
        }
    }
    Err(AccuracyError::NewtonNoConvergence {
        steps: NEWTON_STEPS,
    })
}

/// Bisection on the generated polynomial over `(sin(end), sin(theta_i))` to adjacent floats.
pub fn angle_bisection(sys: &System) -> Outcome<f64> {
    let (c, mut lo, mut hi) = polynomial(sys);
    let mut evals = 2;
    let flo = horner(&c, lo);
    if flo.signum() == horner(&c, hi).signum() {
        return Err(AccuracyError::NoSignChange);
    }
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return Ok((mid.asin(), evals));
        }
        evals += 1;
        if horner(&c, mid).signum() == flo.signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

// ----------------------------------------------------------------------------------------
// Separation time
// ----------------------------------------------------------------------------------------

/// The end of the phase from the project's root.
pub fn delta_sep(sys: &System) -> Result<f64, AccuracyError> {
    let mut work = Work::default();
    Ok(separation(sys, &mut work)?
        .separation()
        .ok_or(AccuracyError::NoSeparation)?
        .delta)
}

/// The project's one quadrature (planner, per-point solver and sweeps): Gauss–Legendre pairs by
/// panel length after the `sin`/`sinh` substitution, at a relative tolerance.
pub fn time_default(sys: &System, delta: f64, tol: f64) -> Outcome<f64> {
    let mut work = Work::default();
    let mesh = TimeMesh::build(sys, delta, tol, &mut work)?;
    Ok((mesh.duration, work.integrand_evals))
}

/// The set-up of the per-point route for a relative error `tol`: the sweeps' solver with its
/// a-priori rule ([`prior`](crate::solve::fast::prior): nodes chosen from where the integrand is
/// singular, without an error estimate) made for `tol`.
pub fn per_point_solver(
    sys: &System<'static>,
    tol: f64,
) -> Result<LeanSolver<'static>, AccuracyError> {
    Ok(LeanSolver::with_tolerance(sys.model(), tol)?)
}

/// The set-up of the per-point solver comparing fixed rules of `low` and `high` nodes on every
/// panel, keeping the `high` one when they agree to `accept`.
pub fn fixed_rules_solver(
    sys: &System<'static>,
    low: usize,
    high: usize,
    accept: f64,
) -> Result<LeanSolver<'static>, AccuracyError> {
    Ok(LeanSolver::with_rules(sys.model(), low, high, accept)?)
}

/// One point solved by a per-point solver from its parameters (root and time, as a sweep
/// solves each point): the separation time and the evaluations it took.
pub fn time_per_point(solver: &mut LeanSolver, sys: &System) -> Outcome<f64> {
    let before = solver.evals;
    let out = solver.solve(sys.p())?;
    Ok((out.separation_time, solver.evals - before))
}

/// One point and its sensitivities by the per-point solver (the generated partial
/// derivatives: the implicit-function theorem for the angle, the differentiated quadrature for
/// the time): `d theta_sep/dp` then `d t_sep/dp` for every parameter in the model's order, and
/// the evaluations the point took.
pub fn sensitivities_exact(
    solver: &mut LeanSolver,
    work: &mut SensitivityWork,
    sys: &System,
) -> Outcome<Vec<f64>> {
    let before = solver.evals;
    let p = sys.p();
    let point = solver.solve(p)?;
    let (mut angle, mut time) = (vec![0.0; p.len()], vec![0.0; p.len()]);
    solver
        .sensitivities(p, &point, work, &mut angle, &mut time)?
        .map_err(|gap| AccuracyError::NoSensitivity { gap })?;
    angle.extend(time);
    Ok((angle, solver.evals - before))
}

/// The same derivatives from the system's general model's motion integrated with its forward
/// sensitivities (`Walker::sensitive_motion` at the integrator's tolerance `rtol`, every phase
/// as a run takes them), read at the first contact's separation, and the right-hand sides it
/// evaluated.
pub fn sensitivities_forward(sys: &System, rtol: f64) -> Outcome<Vec<f64>> {
    let info = sys.info();
    let model = crate::models::find(info.system).ok_or(SolveError::UnknownPhaseModel {
        system: info.system,
        name: info.system,
    })?;
    let walker = Walker::new(
        Bound::from_values(model, sys.p())?,
        crate::models::all(),
        rtol,
        rtol,
    )
    .with_route(Route::Integrated)
    .with_dense_output(false);
    let mut work = Work::default();
    let motion = walker.sensitive_motion(&mut work)?;
    let k = (motion.motion.phases.iter())
        .position(|p| p.end().is_force_of(0))
        .ok_or(AccuracyError::ForceNotVanished)?;
    let ends = motion.ends[k]
        .as_ref()
        .map_err(|_| AccuracyError::NoSensitivity {
            gap: SensitivityGap::Grazing,
        })?;
    let mut out = ends.theta.clone();
    out.extend_from_slice(&ends.t);
    Ok((out, work.ode_evaluations))
}

/// The same derivatives by central differences of the per-point solver, each parameter moved by
/// `step` relative (two solves a parameter), as a user without exact derivatives would take
/// them.
pub fn sensitivities_differences(
    solver: &mut LeanSolver,
    sys: &System,
    step: f64,
) -> Outcome<Vec<f64>> {
    let before = solver.evals;
    let p = sys.p();
    let (mut angle, mut time) = (Vec::with_capacity(p.len()), Vec::with_capacity(p.len()));
    let mut moved = p.to_vec();
    for i in 0..p.len() {
        let h = step * p[i].abs();
        moved[i] = p[i] + h;
        let plus = solver.solve(&moved)?;
        moved[i] = p[i] - h;
        let minus = solver.solve(&moved)?;
        moved[i] = p[i];
        // The step actually taken, as the floats hold it.
        let taken = (p[i] + h) - (p[i] - h);
        angle.push((plus.separation_angle - minus.separation_angle) / taken);
        time.push((plus.separation_time - minus.separation_time) / taken);
    }
    angle.extend(time);
    Ok((angle, solver.evals - before))
}

/// One Gauss–Legendre panel of `nodes` after `delta = u^2`.
pub fn time_gl_u2(sys: &System, delta: f64, nodes: usize) -> Outcome<f64> {
    let Some(order) = NonZeroUsize::new(nodes) else {
        return Err(AccuracyError::NoNodes);
    };
    let rule = gauss_legendre_rule(order);
    let u_end = delta.sqrt();
    let half = 0.5 * u_end;
    let mut sum = 0.0;
    for &(x, w) in &rule {
        sum += w * u_integrand(sys, half * (1.0 + x))?;
    }
    Ok((half * sum, nodes as u64))
}

/// `2u / |theta_dot|` at `delta = u^2` (the integrand after `delta = u^2`), with its limit at
/// `u = 0` released from rest.
fn u_integrand(sys: &System, u: f64) -> Result<f64, AccuracyError> {
    if u == 0.0 {
        let theta_ddot = sys.reduction().reduced(sys.k(), 0.0).theta_ddot;
        return if sys.starts_at_rest() && theta_ddot < 0.0 {
            Ok(2.0 / (-2.0 * theta_ddot).sqrt())
        } else {
            Ok(0.0)
        };
    }
    Ok(2.0 * u * raw(sys, u * u)?)
}

/// `1 / |theta_dot|` at `delta` (the raw integrand, singular at 0).
fn raw(sys: &System, delta: f64) -> Result<f64, AccuracyError> {
    let w2 = sys.reduced(delta)?.theta_dot_sq;
    if w2 > 0.0 && w2.is_finite() {
        Ok(1.0 / w2.sqrt())
    } else {
        Err(AccuracyError::ThetaDotSquared { value: w2, delta })
    }
}

/// The set-up of Gauss–Jacobi: the nodes and weights of `nodes` points for the weight
/// `(1 + x)^(-1/2)` (by Golub–Welsch, which costs far more than the integral itself).
pub fn jacobi_rule(nodes: usize) -> Result<Vec<(f64, f64)>, AccuracyError> {
    let (Some(n), Some(alpha), Some(beta)) = (
        NonZeroUsize::new(nodes),
        FiniteAboveNegOneF64::new(0.0),
        FiniteAboveNegOneF64::new(-0.5),
    ) else {
        return Err(AccuracyError::BadGaussJacobi);
    };
    Ok(GaussJacobi::new(n, alpha, beta)
        .as_node_weight_pairs()
        .to_vec())
}

/// Gauss–Jacobi with the endpoint weight `(1 + x)^(-1/2)` absorbing the `1/sqrt(delta)`.
/// `rule` is [`jacobi_rule`]'s.
pub fn time_gauss_jacobi(sys: &System, delta: f64, rule: &[(f64, f64)]) -> Outcome<f64> {
    let mut sum = 0.0;
    for &(x, w) in rule {
        // delta = delta_sep (1 + x)/2; the smooth factor is sqrt(delta) / |theta_dot|.
        let d = 0.5 * delta * (1.0 + x);
        sum += w * d.sqrt() * raw(sys, d)?;
    }
    Ok(((0.5 * delta).sqrt() * sum, rule.len() as u64))
}

/// Tanh–sinh on the raw integrand over `[0, delta]` with step `h`; the distance to the
/// singular end comes from the transformation, `delta / (1 + e^(2y))`.
pub fn time_tanh_sinh(sys: &System, delta: f64, h: f64) -> Outcome<f64> {
    let range = 4.5;
    let k_max = (range / h) as i64;
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut sum = 0.0;
    for k in -k_max..=k_max {
        let tau = k as f64 * h;
        let y = half_pi * tau.sinh();
        let e = (-2.0 * y).exp();
        let d = delta / (1.0 + e);
        let jac = delta * 2.0 * half_pi * tau.cosh() * e / ((1.0 + e) * (1.0 + e));
        if d > 0.0 && jac > 0.0 && jac.is_finite() {
            sum += jac * raw(sys, d)?;
        }
    }
    Ok((h * sum, (2 * k_max + 1) as u64))
}

// QUADPACK's qk15: Kronrod nodes (largest first), their weights, and the 7-point Gauss weights.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// The 15-point Kronrod value and `|K15 - G7|` over `[a, b]`.
pub fn kronrod15<F: FnMut(f64) -> Result<f64, AccuracyError>>(
    f: &mut F,
    a: f64,
    b: f64,
) -> Result<(f64, f64), AccuracyError> {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let fc = f(c)?;
    let (mut k, mut g) = (WGK[7] * fc, WG[3] * fc);
    for j in 0..7 {
        let s = f(c - h * XGK[j])? + f(c + h * XGK[j])?;
        k += WGK[j] * s;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    Ok((h * k, (h * (k - g)).abs()))
}

#[derive(PartialEq)]
struct Interval {
    error: f64,
    a: f64,
    b: f64,
    value: f64,
}
impl Eq for Interval {}
impl PartialOrd for Interval {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Interval {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.error.total_cmp(&other.error)
    }
}

/// Most subintervals of the global adaptive Gauss–Kronrod rule.
pub const GK_LIMIT: usize = 2000;

/// Global adaptive Gauss–Kronrod (7/15) on the raw integrand, bisecting the interval with the
/// largest error estimate until the sum of estimates is below `tol` relative.
pub fn time_gauss_kronrod(sys: &System, delta: f64, tol: f64) -> Outcome<f64> {
    let mut evals = 0u64;
    let mut f = |d: f64| {
        evals += 1;
        raw(sys, d)
    };
    let (v, e) = kronrod15(&mut f, 0.0, delta)?;
    let mut heap = BinaryHeap::new();
    heap.push(Interval {
        error: e,
        a: 0.0,
        b: delta,
        value: v,
    });
    let (mut total, mut error) = (v, e);
    while error > tol * total.abs() {
        if heap.len() >= GK_LIMIT {
            return Err(AccuracyError::KronrodNotConverged {
                limit: GK_LIMIT,
                estimate: total,
                error,
            });
        }
        let Some(worst) = heap.pop() else { break };
        let m = 0.5 * (worst.a + worst.b);
        let (v1, e1) = kronrod15(&mut f, worst.a, m)?;
        let (v2, e2) = kronrod15(&mut f, m, worst.b)?;
        total += v1 + v2 - worst.value;
        error += e1 + e2 - worst.error;
        heap.push(Interval {
            error: e1,
            a: worst.a,
            b: m,
            value: v1,
        });
        heap.push(Interval {
            error: e2,
            a: m,
            b: worst.b,
            value: v2,
        });
    }
    // Re-sum to shed the running sum's rounding.
    let total: f64 = heap.iter().map(|i| i.value).sum();
    Ok((total, evals))
}

/// `delta'' = -theta''(delta)` from rest, with the event `delta = delta_sep`.
struct Reduced<'a, 'm> {
    sys: &'a System<'m>,
    end: f64,
    calls: u64,
}

impl OdeProblem for Reduced<'_, '_> {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
        self.calls += 1;
        let acc = -self.sys.reduced(y[0])?.theta_ddot;
        if !acc.is_finite() {
            return Err(SolveError::OdeNonFinite {
                what: "theta_ddot",
                t,
                y: y.to_vec(),
            });
        }
        dy[0] = y[1];
        dy[1] = acc;
        Ok(())
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&mut self, _t: f64, y: &[f64], _dy: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        g[0] = y[0] - self.end;
        Ok(())
    }
}

/// Integrates `theta'' ` (as `delta'' = -theta''(delta)`) by DOPRI5 from rest to the event
/// `delta = delta_sep`; `t_max` bounds the search.
fn reduced_ode(
    sys: &System,
    delta: f64,
    rtol: f64,
    t_max: f64,
) -> Result<(crate::solve::integrated::ode::OdeSolution, u64), AccuracyError> {
    let mut problem = Reduced {
        sys,
        end: delta,
        calls: 0,
    };
    let opts = OdeOptions {
        controlled: None,
        rtol,
        atol: Vec::new(),
        t_max,
        max_steps: 2_000_000,
        dense_output: true,
    };
    let sol = dopri5(&mut problem, 0.0, &[0.0, 0.0], &opts)?;
    Ok((sol, problem.calls))
}

/// The separation time from the reduced ODE's event.
pub fn time_reduced_ode(sys: &System, delta: f64, rtol: f64, t_max: f64) -> Outcome<f64> {
    let (sol, calls) = reduced_ode(sys, delta, rtol, t_max)?;
    let event = sol.event.ok_or(AccuracyError::NoEvent)?;
    Ok((event.t, calls))
}

/// The separation time from the unreduced equations with the contact-force event.
pub fn time_unreduced(sys: &System, rtol: f64, t_max: f64) -> Outcome<f64> {
    let mut work = Work::default();
    let start = unreduced::Start {
        state: sys.initial_state(),
        active: Active::of_model(sys.info()),
        frictions: Vec::new(),
        friction_work: 0.0,
        stop_at: None,
        dense_output: true,
        sensitivity: None,
    };
    let run = unreduced::integrate_with(
        sys,
        &start,
        rtol,
        Some(Method::Dopri5),
        None,
        t_max,
        &mut work,
    )?;
    if !run.end.is_force_of(0) {
        return Err(AccuracyError::ForceNotVanished);
    }
    Ok((run.t_end, work.ode_evaluations))
}

// ----------------------------------------------------------------------------------------
// theta(t) series
// ----------------------------------------------------------------------------------------

/// Samples `(t_j, delta_j)` of a series.
pub type Samples = (Vec<f64>, Vec<f64>);

/// The project's series: the quadrature `t(u)` inverted by Newton at uniform times.
pub fn series_quadrature(sys: &System, delta: f64, tol: f64, samples: usize) -> Outcome<Samples> {
    let mut work = Work::default();
    let mesh = TimeMesh::build(sys, delta, tol, &mut work)?;
    let s = sample_phase(sys, &mesh, samples, &mut work)?;
    Ok(((s.t, s.delta), work.integrand_evals))
}

/// DOPRI5's dense output of the reduced ODE at uniform times up to its event.
pub fn series_ode(
    sys: &System,
    delta: f64,
    rtol: f64,
    t_max: f64,
    samples: usize,
) -> Outcome<Samples> {
    let (sol, calls) = reduced_ode(sys, delta, rtol, t_max)?;
    let end = sol.event.as_ref().ok_or(AccuracyError::NoEvent)?.t;
    let mut t = Vec::with_capacity(samples);
    let mut d = Vec::with_capacity(samples);
    for j in 0..samples {
        let tj = if j + 1 == samples {
            end
        } else {
            end * j as f64 / (samples - 1) as f64
        };
        let y = (sol.interpolate(tj)).ok_or(AccuracyError::OutsideSolution { t: tj })?;
        t.push(tj);
        d.push(y[0].clamp(0.0, delta));
    }
    Ok(((t, d), calls))
}
