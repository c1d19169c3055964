//! A lean per-point solve of the separation angle and time, for sweeps of millions of points:
//! every buffer is allocated once per solver and reused, nothing is kept per point, and the
//! time integral uses a substitution that removes both singularities of the integrand, so a
//! few Gauss–Legendre panels reach `f64` accuracy across the whole parameter range.
//!
//! # The substitution
//! Released from rest, `theta_dot^2` vanishes like `delta` at the start; near upright
//! (`theta_i -> pi/2`) it also nearly vanishes at `delta = -2 cot(theta_i)`, just outside the
//! interval, because `sin(theta_i) - sin(theta) ~ sin(theta_i) delta (cot(theta_i) + delta/2)`.
//! With `delta = 2 b sinh^2(v)`, `b = cot(theta_i)`,
//! `d(delta) / sqrt(delta (2b + delta)) = 2 dv`, so the integrand of
//! `t = integral 4 b sinh(v) cosh(v) / |theta_dot| dv` is smooth and of one scale from the flat
//! (`b -> infinity`, where it reduces to the `delta = u^2` substitution of
//! [`quadrature`](crate::solve::quadrature)) to the upright limit (`b -> 0`, where the time
//! grows like `v_end ~ log(1/b)`). The factor is exact for any model whose energy integral has
//! `sin(theta_i) - sin(theta)` as its root, which is every contact model here; for others the
//! substitution is still valid, only less effective, and the adaptive rule makes up for it.
//!
//! # Error control
//! Each panel is integrated by Gauss–Legendre rules of [`LEAN_ORDER`] and [`LEAN_FINE_ORDER`]
//! nodes; the finer value is kept when the two agree to [`LEAN_ACCEPT`] relative, otherwise the
//! panel is halved. Two rules on the same panel do not agree by accident when a near-singularity
//! sits at the panel's end, which is how comparing a panel with its halves is fooled (both then
//! carry the same unresolved error): with the hinged rod and a heavy cube the integrand has
//! complex singularities (`1 + 3 n s^2 = 0`) just past the end of the phase, and the
//! panel-versus-halves test of the planner's quadrature, or a test on the decay of the
//! integrand's Legendre coefficients, accepted panels with errors of 1e-9 there. The strict
//! tolerance matters for the same reason: where the convergence is algebraic, the kept value is
//! only a few times better than the test. Across the sweep range of `rod_cube` (`n` 1e-3..1e3,
//! `a/ell` 0.01..0.99) one panel (20 evaluations) nearly always suffices and the error is below
//! 1e-15. `rodcube accuracy` and the tests in `tests/hard_cases.rs` check the result against the
//! high-precision [`reference`](crate::reference) across `n = m2/m1` from 1e-12 to 1e12 and
//! `a/ell` from 1e-10 to `1 - 1e-9`.

use crate::model::{Model, ModelInfo};
use crate::solve::SolveError;
use crate::solve::quadrature::gauss_legendre_rule;
use crate::solve::separation::horner_compensated;
use crate::system::SystemError;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::{Mutex, OnceLock};

/// Gauss–Legendre nodes of the coarse rule on each panel.
pub const LEAN_ORDER: usize = 8;

/// Gauss–Legendre nodes of the fine rule on each panel (the value kept).
pub const LEAN_FINE_ORDER: usize = 12;

/// A panel is kept when its two rules agree to this relative tolerance.
pub const LEAN_ACCEPT: f64 = 1e-12;

/// Highest degree of separation polynomial solved without allocating (higher degrees are
/// refused with [`SolveError::BadPolynomial`]).
pub const MAX_DEGREE: usize = 8;

/// Most panels before giving up.
pub const MAX_PANELS: usize = 4000;

/// One point's separation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeanPoint {
    /// `theta_sep` (rad).
    pub separation_angle: f64,
    /// Time from release to separation (s).
    pub separation_time: f64,
    /// `theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// A reusable per-point solver of one model's separation angle and time.
pub struct LeanSolver<'m> {
    model: &'m dyn Model,
    info: &'static ModelInfo,
    k: Vec<f64>,
    margins: Vec<f64>,
    coeffs: Vec<f64>,
    low: Vec<(f64, f64)>,
    high: Vec<(f64, f64)>,
    accept: f64,
    stack: Vec<(f64, f64, f64)>,
    /// Evaluations of `theta_dot^2` and of the polynomial since the solver was made.
    pub evals: u64,
}

impl std::fmt::Debug for LeanSolver<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LeanSolver")
            .field("model", &self.info.name)
            .field("order", &self.low.len())
            .field("accept", &self.accept)
            .finish()
    }
}

impl<'m> LeanSolver<'m> {
    /// A solver with the default rules ([`LEAN_ORDER`], [`LEAN_FINE_ORDER`], [`LEAN_ACCEPT`]).
    /// The model must have a contact whose separation polynomial has degree at most
    /// [`MAX_DEGREE`].
    pub fn new(model: &'m dyn Model) -> Result<Self, SolveError> {
        Self::with_rules(model, LEAN_ORDER, LEAN_FINE_ORDER, LEAN_ACCEPT)
    }

    /// A solver comparing rules of `low` and `high` nodes on each panel, keeping the `high` one
    /// when they agree to `accept` relative (other settings are shown by `rodcube accuracy`).
    pub fn with_rules(
        model: &'m dyn Model,
        low: usize,
        high: usize,
        accept: f64,
    ) -> Result<Self, SolveError> {
        let info = model.info();
        if info.contact.is_none() {
            return Err(SolveError::NoContact { model: info.name });
        }
        if info.separation_degree > MAX_DEGREE {
            return Err(SolveError::BadPolynomial {
                model: info.name,
                coefficients: Vec::new(),
            });
        }
        Ok(LeanSolver {
            model,
            info,
            k: vec![0.0; info.n_constants],
            margins: vec![0.0; info.requirements.len()],
            coeffs: vec![0.0; info.separation_degree + 1],
            low: cached_rule(low.max(1)),
            high: cached_rule(high.max(1)),
            accept: accept.max(4.0 * f64::EPSILON),
            stack: Vec::with_capacity(64),
            evals: 0,
        })
    }

    /// The model.
    pub fn model(&self) -> &'m dyn Model {
        self.model
    }

    /// Validates `p` (in the model's parameter order) exactly as
    /// [`System::from_values`](crate::system::System::from_values) does, then solves.
    pub fn solve(&mut self, p: &[f64]) -> Result<LeanPoint, SolveError> {
        self.bind(p)?;
        let (theta, delta) = self.separation()?;
        let t = self.time_to(delta)?;
        Ok(LeanPoint {
            separation_angle: theta,
            separation_time: t,
            delta,
        })
    }

    /// Checks the parameters and prepares the constants.
    fn bind(&mut self, p: &[f64]) -> Result<(), SystemError> {
        let info = self.info;
        if p.len() != info.parameters.len() {
            return Err(SystemError::WrongCount {
                model: info.name,
                expected: info.parameters.len(),
                got: p.len(),
            });
        }
        for (&value, param) in p.iter().zip(info.parameters) {
            if !value.is_finite() {
                return Err(SystemError::NotFinite {
                    model: info.name,
                    name: param.name,
                    value,
                });
            }
            if param.positive && value <= 0.0 {
                return Err(SystemError::NotPositive {
                    model: info.name,
                    name: param.name,
                    value,
                });
            }
        }
        self.model.requirements(p, &mut self.margins);
        for (&margin, req) in self.margins.iter().zip(info.requirements) {
            if margin.is_nan() || margin <= 0.0 {
                return Err(SystemError::Requirement {
                    model: info.name,
                    name: req.name,
                    meaning: req.meaning,
                    margin,
                    parameters: describe(info, p),
                });
            }
        }
        self.model.prepare(p, &mut self.k);
        if let Some((index, &value)) = self.k.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(SystemError::BadConstant {
                model: info.name,
                index,
                value,
                parameters: describe(info, p),
            });
        }
        Ok(())
    }

    /// `(theta_sep, delta_sep)` from the largest sign-changing root of the separation
    /// polynomial in `(sin(end_angle), sin(theta_i))`.
    fn separation(&mut self) -> Result<(f64, f64), SolveError> {
        let info = self.info;
        self.model.separation_polynomial(&self.k, &mut self.coeffs);
        if self.coeffs.iter().any(|c| !c.is_finite()) || self.coeffs.iter().all(|&c| c == 0.0) {
            return Err(SolveError::BadPolynomial {
                model: info.name,
                coefficients: self.coeffs.clone(),
            });
        }
        let theta_i = self.k[info.k_theta_initial];
        let hi = theta_i.sin();
        let lo = info.end_angle.sin();
        match largest_root(&self.coeffs, lo, hi, &mut self.evals) {
            Some(s) => {
                let theta = s.asin();
                Ok((theta, theta_i - theta))
            }
            None => Err(SolveError::BadPhaseEnd {
                model: info.name,
                delta_end: f64::NAN,
            }),
        }
    }

    /// Time from release to `delta_end` by the substitution `delta = 2 b sinh^2 v`.
    fn time_to(&mut self, delta_end: f64) -> Result<f64, SolveError> {
        let info = self.info;
        let model = info.name;
        if !(delta_end > 0.0 && delta_end.is_finite()) {
            return Err(SolveError::BadPhaseEnd { model, delta_end });
        }
        let theta_dot = self.k[info.k_theta_dot_initial];
        let start = self.model.reduced(&self.k, 0.0);
        if theta_dot != 0.0 || start.theta_ddot >= 0.0 || start.theta_ddot.is_nan() {
            return Err(SolveError::NoMotion {
                model,
                theta_dot,
                theta_ddot: start.theta_ddot,
            });
        }
        let b = if start.sin > 0.0 && start.cos > 0.0 {
            start.cos / start.sin
        } else {
            1.0
        };
        let v_end = (delta_end / (2.0 * b)).sqrt().asinh();
        let (model_ref, k) = (self.model, &self.k);
        let mut evals = 0u64;
        let mut f = |v: f64| -> Result<f64, SolveError> {
            // sinh v and cosh v from one expm1, accurate for small and large v alike.
            let em = v.exp_m1();
            let inv = 1.0 / (1.0 + em);
            let sh = 0.5 * (em + em * inv);
            let ch = 0.5 * (1.0 + em + inv);
            let delta = 2.0 * b * sh * sh;
            let w2 = model_ref.reduced(k, delta).theta_dot_sq;
            if !(w2 > 0.0 && w2.is_finite()) {
                return Err(if w2.is_finite() {
                    SolveError::TurningPoint {
                        model,
                        delta,
                        theta_dot_sq: w2,
                        delta_end,
                    }
                } else {
                    SolveError::NonFinite {
                        model,
                        what: "theta_dot^2",
                        delta,
                        value: w2,
                    }
                });
            }
            Ok(4.0 * b * sh * ch / w2.sqrt())
        };
        let (low, high) = (&self.low, &self.high);
        let panel = |f: &mut dyn FnMut(f64) -> Result<f64, SolveError>,
                     rule: &[(f64, f64)],
                     a: f64,
                     c: f64,
                     evals: &mut u64|
         -> Result<f64, SolveError> {
            let (half, mid) = (0.5 * (c - a), 0.5 * (a + c));
            let mut sum = 0.0;
            for &(x, w) in rule {
                sum += w * f(mid + half * x)?;
            }
            *evals += rule.len() as u64;
            Ok(half * sum)
        };
        self.stack.clear();
        self.stack.push((0.0, v_end, 0.0));
        let mut total = 0.0;
        let mut panels = 0usize;
        while let Some((lo, hi, _)) = self.stack.pop() {
            let coarse = panel(&mut f, low, lo, hi, &mut evals)?;
            let fine = panel(&mut f, high, lo, hi, &mut evals)?;
            let error = (fine - coarse).abs();
            panels += 1;
            if fine.is_finite() && error <= self.accept * fine.abs() {
                total += fine;
                continue;
            }
            let mid = 0.5 * (lo + hi);
            let splittable = mid > lo && mid < hi;
            if !fine.is_finite() || !splittable || panels > MAX_PANELS {
                self.evals += evals;
                return Err(SolveError::QuadratureNotConverged {
                    a: 0.0,
                    b: v_end,
                    tol: self.accept,
                    estimate: total + fine,
                    error,
                    panels,
                });
            }
            self.stack.push((mid, hi, 0.0));
            self.stack.push((lo, mid, 0.0));
        }
        self.evals += evals;
        Ok(total)
    }
}

/// Gauss–Legendre nodes and weights of an order, computed once per process (making a solver
/// is then cheap enough to do per call).
fn cached_rule(order: usize) -> Vec<(f64, f64)> {
    type Rules = Mutex<HashMap<usize, Vec<(f64, f64)>>>;
    static RULES: OnceLock<Rules> = OnceLock::new();
    let cache = RULES.get_or_init(|| Mutex::new(HashMap::new()));
    let mut map = match cache.lock() {
        Ok(map) => map,
        Err(poisoned) => poisoned.into_inner(),
    };
    map.entry(order)
        .or_insert_with(|| gauss_legendre_rule(order))
        .clone()
}

/// `name = value` pairs for messages.
fn describe(info: &ModelInfo, p: &[f64]) -> String {
    let mut out = String::new();
    for (i, (param, v)) in info.parameters.iter().zip(p).enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{} = {v}", param.name);
    }
    out
}

/// The largest root of `p` in `(lo, hi)` where `p` changes sign, without allocating
/// (degree at most [`MAX_DEGREE`]; coefficients lowest degree first).
pub fn largest_root(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    let degree = coeffs.iter().rposition(|&c| c != 0.0)?;
    if degree > MAX_DEGREE {
        return None;
    }
    let mut out = [0.0; MAX_DEGREE];
    let n = roots_into(&coeffs[..=degree], lo, hi, &mut out, evals);
    (n > 0).then(|| out[n - 1])
}

/// Every sign-changing root of `c` (trimmed, degree at most [`MAX_DEGREE`]) in `(lo, hi)`,
/// ascending, into `out`; returns how many. The roots of the derivative split the interval into
/// pieces where `c` is monotone, each refined by bracketed Newton.
fn roots_into(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE], evals: &mut u64) -> usize {
    let degree = c.len().saturating_sub(1);
    if degree == 0 || lo.is_nan() || hi.is_nan() || lo >= hi {
        return 0;
    }
    if degree == 1 {
        let x = -c[0] / c[1];
        if x > lo && x < hi {
            out[0] = x;
            return 1;
        }
        return 0;
    }
    let mut deriv = [0.0; MAX_DEGREE];
    for i in 1..=degree {
        deriv[i - 1] = i as f64 * c[i];
    }
    let d = &deriv[..degree];
    let d_trim = match d.iter().rposition(|&x| x != 0.0) {
        Some(k) => &d[..=k],
        None => &d[..1],
    };
    let mut crit = [0.0; MAX_DEGREE];
    // The critical points only split the interval into monotone pieces: for a quadratic
    // derivative the closed form is exact enough and costs no iteration.
    let nc = if d_trim.len() == 3 {
        quadratic_roots(d_trim, lo, hi, &mut crit)
    } else {
        roots_into(d_trim, lo, hi, &mut crit, evals)
    };
    let mut knots = [0.0; MAX_DEGREE + 2];
    let mut values = [0.0; MAX_DEGREE + 2];
    knots[0] = lo;
    knots[1..=nc].copy_from_slice(&crit[..nc]);
    knots[nc + 1] = hi;
    let nk = nc + 2;
    for i in 0..nk {
        values[i] = filtered(c, knots[i]);
    }
    *evals += nk as u64;
    let mut count = 0;
    for i in 0..nk - 1 {
        let (fa, fb) = (values[i], values[i + 1]);
        if fa == 0.0 && i > 0 {
            let before = values[i - 1];
            if before != 0.0 && fb != 0.0 && before.signum() != fb.signum() {
                out[count] = knots[i];
                count += 1;
            }
            continue;
        }
        if fa != 0.0 && fb != 0.0 && fa.signum() != fb.signum() {
            out[count] = refine(c, d, (knots[i], knots[i + 1]), (fa, fb), evals);
            count += 1;
        }
    }
    count
}

/// The real roots of `c0 + c1 x + c2 x^2` (`c2 != 0`) in `(lo, hi)`, ascending, by the
/// cancellation-free form of the quadratic formula; returns how many.
fn quadratic_roots(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE]) -> usize {
    let (c0, c1, c2) = (c[0], c[1], c[2]);
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc.is_nan() || disc <= 0.0 {
        return 0;
    }
    let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
    let (mut x1, mut x2) = (q / c2, if q != 0.0 { c0 / q } else { 0.0 });
    if x1 > x2 {
        std::mem::swap(&mut x1, &mut x2);
    }
    let mut n = 0;
    for x in [x1, x2] {
        if x > lo && x < hi {
            out[n] = x;
            n += 1;
        }
    }
    n
}

/// `p(x)` by plain Horner (no fused multiply-add: without a hardware FMA target feature
/// `f64::mul_add` is a library call several times slower than the arithmetic).
#[inline]
fn plain(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &a| acc * x + a)
}

/// `p(x)` with a reliable sign: plain Horner, redone in twice the working precision
/// ([`horner_compensated`]) when the result is within the plain evaluation's rounding bound
/// `4 (d+1) eps sum |c_i| |x|^i` of zero.
#[inline]
fn filtered(c: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    let (mut v, mut bound) = (0.0, 0.0);
    for &a in c.iter().rev() {
        v = v * x + a;
        bound = bound * ax + a.abs();
    }
    if v.abs() <= 4.0 * c.len() as f64 * f64::EPSILON * bound {
        horner_compensated(c, x)
    } else {
        v
    }
}

/// The root of `c` in `(a, b)` where it is monotone with `c(a) = fa` of the other sign than
/// `c(b)`: Newton kept inside the shrinking bracket, bisection otherwise, to adjacent floats.
fn refine(
    c: &[f64],
    deriv: &[f64],
    (mut a, mut b): (f64, f64),
    (fa, fb): (f64, f64),
    evals: &mut u64,
) -> f64 {
    let sa = fa.signum();
    // Start from the secant through the bracket's ends (the midpoint if it falls outside).
    let secant = (a * fb - b * fa) / (fb - fa);
    let mut x = if secant > a && secant < b {
        secant
    } else {
        0.5 * (a + b)
    };
    let mut last_step = f64::INFINITY;
    for _ in 0..4000 {
        *evals += 1;
        let fx = filtered(c, x);
        if fx == 0.0 {
            return x;
        }
        if fx.signum() == sa {
            a = x;
        } else {
            b = x;
        }
        let newton = x - fx / plain(deriv, x);
        let step = (newton - x).abs();
        if step <= 2.0 * f64::EPSILON * x.abs() {
            // Newton has converged on a residual of reliable sign: within an ulp or two.
            return newton.clamp(a, b);
        }
        if newton > a && newton < b && step < 0.5 * last_step {
            last_step = step;
            x = newton;
        } else {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                return if filtered(c, a).abs() <= filtered(c, b).abs() {
                    a
                } else {
                    b
                };
            }
            last_step = f64::INFINITY;
            x = mid;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn largest_root_of_a_product() {
        // (x - 0.1)(x - 0.5)(x - 0.9)
        let c = [-0.045, 0.59, -1.5, 1.0];
        let mut evals = 0;
        let r = largest_root(&c, 0.0, 1.0, &mut evals).unwrap();
        assert!((r - 0.9).abs() < 4e-16, "{r}");
        let r = largest_root(&c, 0.0, 0.7, &mut evals).unwrap();
        assert!((r - 0.5).abs() < 4e-16, "{r}");
        assert!(largest_root(&c, 0.95, 1.0, &mut evals).is_none());
        assert!(largest_root(&[0.0, 0.0], 0.0, 1.0, &mut evals).is_none());
        assert!(evals > 0);
    }

    #[test]
    fn degree_above_the_limit_is_refused() {
        let mut c = [0.0; MAX_DEGREE + 2];
        c[0] = -0.5;
        c[MAX_DEGREE + 1] = 1.0;
        let mut evals = 0;
        assert!(largest_root(&c, 0.0, 1.0, &mut evals).is_none());
    }
}
