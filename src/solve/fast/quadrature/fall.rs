//! A falling phase in the variable `v` of the substitution `sin(theta_i) - s = e sinh^2 v`
//! ([`Fall`]): its constants, the checks that it falls, the integrand at a node, one rule on a
//! panel, and the maps between `v`, the drop of `sin(theta)` and the angle fallen.

use super::hyperbolic::{ln_1p, sinh_cosh, sinh_sq};
use super::integrand::{FALL_CHECK_SH2, FallIntegrand, panel_frame};
use super::rules::{Control, HalfRule};
use crate::model::{Reduction, ReductionInfo, start_offsets};
use crate::solve::SolveError;
use crate::solve::fast::poly::horner;
use crate::system::System;

/// Largest `h x` at which a panel's node `mid - h x` is formed by the addition theorem (its
/// rounding then grows by at most `exp(2 h x) = 2`).
const ADDITION_REACH: f64 = 0.35;

/// The angle at one node: `sin`, `cos`, their drops from the start, and `1 + sin`.
struct Node {
    s: f64,
    c: f64,
    ds: f64,
    dc: f64,
    plus: f64,
}

/// `v` where `sin(theta)` has dropped by `drop >= 0` from a start of scale `e`:
/// `asinh(sqrt(q))`, `q = drop / e`, as `log1p(x + q / (1 + sqrt(1 + q)))` (the inlined
/// `hyperbolic::ln_1p`), exact for small and large `q` without `hypot`.
#[inline]
pub fn v_at_drop(e: f64, drop: f64) -> f64 {
    let q = drop.max(0.0) / e;
    ln_1p(q.sqrt() + q / (1.0 + (1.0 + q).sqrt()))
}

/// A falling phase in the variable `v` of the module docs: what the integrand needs.
#[derive(Clone, Copy)]
pub struct Fall<'a> {
    pub(super) model: &'static str,
    red: &'a dyn Reduction,
    k: &'a [f64],
    si: f64,
    ci: f64,
    e: f64,
    root_e: f64,
    pub(super) from_rest: bool,
    /// The fall polynomial's coefficients (empty without one): the integrand is then
    /// `2 sqrt(P(s) / (1 + s))`, without `theta_dot^2`'s call.
    fall: &'a [f64],
    /// That integrand.
    integrand: FallIntegrand<'a>,
    /// The phase's end, for error messages.
    pub(super) delta_end: f64,
}

impl std::fmt::Debug for Fall<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fall")
            .field("model", &self.model)
            .field("sin_theta_i", &self.si)
            .field("e", &self.e)
            .field("from_rest", &self.from_rest)
            .finish()
    }
}

impl<'a> Fall<'a> {
    /// The phase of a reduced system, ending at `delta_end` (for messages; the integral's end is
    /// given to [`integrate`](super::integrate)). Checks that it falls: from rest
    /// `theta_dot^2` must grow from the start, moving `theta_dot_i` must be negative, and
    /// `theta_i` must be below the vertical.
    ///
    /// `fall` holds the coefficients of the model's fall polynomial
    /// ([`Reduction::fall_polynomial`]) where it has one, else it is empty.
    #[inline(always)]
    pub fn new(
        model: &'static str,
        red: &'a dyn Reduction,
        k: &'a [f64],
        layout: &ReductionInfo,
        fall: &'a [f64],
        delta_end: f64,
    ) -> Result<Fall<'a>, SolveError> {
        let fall = Fall::geometry(model, red, k, layout, fall, delta_end)?;
        fall.check_falls(k[layout.k_theta_dot_initial])?;
        Ok(fall)
    }

    /// The phase's constants, checking only that it does not rise and starts below the
    /// vertical (what [`Fall::new`] checks before asking whether it falls).
    #[inline(always)]
    pub(super) fn geometry(
        model: &'static str,
        red: &'a dyn Reduction,
        k: &'a [f64],
        layout: &ReductionInfo,
        fall: &'a [f64],
        delta_end: f64,
    ) -> Result<Fall<'a>, SolveError> {
        let theta_dot = k[layout.k_theta_dot_initial];
        let (si, ci) = (k[layout.k_sin_initial], k[layout.k_cos_initial]);
        if theta_dot > 0.0 {
            return Err(SolveError::Rising { model, theta_dot });
        }
        // 1 - sin(theta_i) without cancellation near upright.
        let e = ci * ci / (1.0 + si);
        if !(e > 0.0 && e.is_finite() && si.abs() < 1.0 && ci > 0.0) {
            return Err(SolveError::BeyondVertical {
                model,
                // The lean path prepares the start's sine and cosine, not the angle.
                theta_initial: si.atan2(ci),
            });
        }
        let from_rest = theta_dot == 0.0;
        let fall = if from_rest { fall } else { &[] };
        Ok(Fall {
            model,
            red,
            k,
            si,
            ci,
            e,
            root_e: e.sqrt(),
            from_rest,
            fall,
            integrand: FallIntegrand::new(si, e, fall),
            delta_end,
        })
    }

    /// From rest (or with a rate that is not a number) the rod must start to fall.
    #[inline(always)]
    fn check_falls(&self, theta_dot: f64) -> Result<(), SolveError> {
        // With a fall polynomial, one value of fixed shape settles the usual case.
        if self.integrand.low && theta_dot == 0.0 && self.integrand.falls() {
            return Ok(());
        }
        self.check_falls_by_value(theta_dot)
    }

    /// [`Fall::check_falls`] by the integrand's value just past the start.
    #[cold]
    fn check_falls_by_value(&self, theta_dot: f64) -> Result<(), SolveError> {
        let (model, red, k) = (self.model, self.red, self.k);
        let sh2 = FALL_CHECK_SH2;
        if self.from_rest || theta_dot.is_nan() {
            // The rod must start to fall: theta_dot^2 positive just past the start (at
            // sinh v = 1e-4, a drop of 1e-8 e; one rational evaluation, the trigonometry of
            // `reduced` only for the message).
            let falls = self.value(sh2.sqrt(), (1.0 + sh2).sqrt());
            if theta_dot.is_nan() || falls.is_err() {
                let theta_ddot = red.reduced(k, 0.0).theta_ddot;
                return Err(match falls {
                    // It does start to fall, and theta_dot^2 itself is broken just past the start.
                    Err(broken) if theta_ddot < 0.0 && !theta_dot.is_nan() => broken,
                    _ => SolveError::NoMotion {
                        model,
                        theta_dot,
                        theta_ddot,
                    },
                });
            }
        }
        Ok(())
    }

    /// The phase of a reduced [`System`] from its start.
    pub fn of(sys: &'a System, delta_end: f64) -> Result<Fall<'a>, SolveError> {
        Fall::new(
            sys.name(),
            sys.reduction(),
            sys.k(),
            sys.layout(),
            sys.fall_coefficients(),
            delta_end,
        )
    }

    /// Whether the phase starts from rest (its integrand is then even in `v`).
    pub fn from_rest(&self) -> bool {
        self.from_rest
    }

    /// `sin(theta_i)`.
    pub fn sin_initial(&self) -> f64 {
        self.si
    }

    /// `e = 1 - sin(theta_i)`, the scale of the substitution `s = sin(theta_i) - e sinh^2 v`.
    pub fn scale(&self) -> f64 {
        self.e
    }

    /// The fall polynomial's coefficients (empty when the phase has none).
    pub fn fall_polynomial(&self) -> &'a [f64] {
        self.fall
    }

    /// `v` where `sin(theta)` has dropped by `drop >= 0`: `asinh(sqrt(q))`, `q = drop / e`, as
    /// `log1p(x + q / (1 + sqrt(1 + q)))`, exact for small and large `q` without `hypot`.
    pub fn v_at_drop(&self, drop: f64) -> f64 {
        v_at_drop(self.e, drop)
    }

    /// `v` at the angle fallen `delta`.
    pub fn v_at_delta(&self, delta: f64) -> f64 {
        let theta_i = self.si.asin();
        let (_, _, ds, _) = start_offsets(theta_i, self.si, self.ci, delta);
        self.v_at_drop(ds)
    }

    /// The angle fallen at `v`: `atan2(sin(delta), cos(delta))` from the drops, without the
    /// cancellation of `theta_i - theta`.
    pub fn delta_at(&self, v: f64) -> f64 {
        let (sh, ch) = sinh_cosh(v);
        let n = self.node(sh, ch);
        (self.ci * n.ds - self.si * n.dc).atan2(self.ci * n.c + self.si * n.s)
    }

    /// `dt/dv` at `v`.
    pub fn rate(&self, v: f64) -> Result<f64, SolveError> {
        let (sh, ch) = sinh_cosh(v.abs());
        self.value(sh, ch)
    }

    /// The integrand at `v = 0`: 0 when moving; from rest its limit
    /// `2 / sqrt(-2 theta_ddot_i (1 + sin theta_i) / cos theta_i)` (`theta_dot^2 ~ -2
    /// theta_ddot_i delta`, `delta ~ w / cos theta_i`), evaluated only by rules with a node
    /// there.
    fn centre_value(&self) -> Result<f64, SolveError> {
        if !self.from_rest {
            return Ok(0.0);
        }
        let theta_ddot = self.red.reduced(self.k, 0.0).theta_ddot;
        let value = 2.0 / (-2.0 * theta_ddot * (1.0 + self.si) / self.ci).sqrt();
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(SolveError::NonFinite {
                model: self.model,
                what: "the time integrand's limit at the start",
                delta: 0.0,
                value,
            })
        }
    }

    /// The angle at `v` (given by `sinh v`, `cosh v`): `sin(theta)` and `cos(theta)` with their
    /// drops from the start, formed without cancellation (module docs).
    #[inline]
    fn node(&self, sh: f64, ch: f64) -> Node {
        let ds = self.e * sh * sh;
        let s = self.si - ds;
        let plus = 1.0 + s;
        let c = self.root_e * ch * plus.sqrt();
        let dc = -ds * (self.si + s) / (self.ci + c);
        Node { s, c, ds, dc, plus }
    }

    /// The integrand at the node given by its `sinh v` and `cosh v` (`v >= 0`).
    #[inline]
    fn value(&self, sh: f64, ch: f64) -> Result<f64, SolveError> {
        if !self.fall.is_empty() {
            let f = self.integrand.value(sh * sh);
            if f.is_nan() || f.is_infinite() || f <= 0.0 {
                return Err(self.bad_fall(sh * sh));
            }
            return Ok(f);
        }
        if sh == 0.0 {
            return self.centre_value();
        }
        let n = self.node(sh, ch);
        let w2 = self.red.theta_dot_sq_sc(self.k, n.s, n.c, n.ds, n.dc);
        if !(w2 > 0.0 && w2.is_finite()) {
            return Err(self.bad_value(n.s, w2));
        }
        Ok(2.0 * self.root_e * sh / (n.plus * w2).sqrt())
    }

    /// The error for a fall polynomial that is not positive and finite at `sinh^2 v = sh2`.
    fn bad_fall(&self, sh2: f64) -> SolveError {
        let ds = self.e * sh2;
        let s = self.si - ds;
        self.bad_value(s, ds / horner(self.fall, s))
    }

    /// [`Fall::panel`] with a fall polynomial ([`FallIntegrand::panel`]); a panel whose values
    /// are not all positive and finite is searched node by node for the error.
    fn panel_fall(&self, rule: &HalfRule, a: f64, b: f64) -> Result<(f64, u64), SolveError> {
        let symmetric = self.symmetric(a);
        let sum = self.integrand.panel(rule, a, b, symmetric);
        if !sum.ok() {
            let (centre, half) = panel_frame(symmetric, a, b);
            let nodes = std::iter::once(0.0).chain(rule.pairs.iter().flat_map(|&(x, _)| [x, -x]));
            for x in nodes {
                let v = if symmetric {
                    half * x
                } else {
                    centre + half * x
                };
                self.value(sinh_sq(v).sqrt(), 1.0)?;
            }
        }
        Ok((sum.value, sum.evals))
    }

    /// The error for a `theta_dot^2` that is not positive and finite at `sin(theta) = s`.
    fn bad_value(&self, s: f64, w2: f64) -> SolveError {
        let delta = self.si.asin() - s.asin();
        if w2.is_finite() {
            SolveError::TurningPoint {
                model: self.model,
                delta,
                theta_dot_sq: w2,
                delta_end: self.delta_end,
            }
        } else {
            SolveError::NonFinite {
                model: self.model,
                what: "theta_dot^2",
                delta,
                value: w2,
            }
        }
    }

    /// Whether the panel `[a, b]` is the symmetric first panel of a phase from rest.
    fn symmetric(&self, a: f64) -> bool {
        self.from_rest && a == 0.0
    }

    /// The panel's length as its rules see it (a symmetric panel spans `[-b, b]`).
    pub(super) fn span(&self, a: f64, b: f64) -> f64 {
        if self.symmetric(a) { 2.0 * b } else { b - a }
    }

    /// The rule on the panel `[a, b]`: `(integral, evaluations)`.
    ///
    /// On a symmetric panel the nodes are `b x` and the values serve `+x` and `-x`. Otherwise
    /// the nodes `mid +- h x` share one exponential: `sinh(mid +- h x)` and `cosh(mid +- h x)`
    /// follow from those of `mid` and of `h x` by the addition theorems. The difference
    /// `sinh(mid - h x)` loses up to a factor `exp(2 h x)` to cancellation, so beyond
    /// `h x = ADDITION_REACH` (a factor 2) that node takes its own exponential. Iterations do not
    /// depend on each other but through the sum, so the divisions and roots of different nodes
    /// overlap.
    pub(crate) fn panel(&self, rule: &HalfRule, a: f64, b: f64) -> Result<(f64, u64), SolveError> {
        if !self.fall.is_empty() {
            return self.panel_fall(rule, a, b);
        }
        let mut acc = 0.0;
        if self.symmetric(a) {
            if rule.centre != 0.0 {
                acc = 0.5 * rule.centre * self.value(0.0, 1.0)?;
            }
            for &(x, w) in &rule.pairs {
                let (sx, cx) = sinh_cosh(b * x);
                acc += w * self.value(sx, cx)?;
            }
            // integral over [0, b] = half the rule over [-b, b].
            let evals = rule.pairs.len() + usize::from(rule.centre != 0.0);
            return Ok((b * acc, evals as u64));
        }
        let (half, mid) = (0.5 * (b - a), 0.5 * (a + b));
        let (sm, cm) = sinh_cosh(mid);
        let mut evals = 2 * rule.pairs.len() as u64;
        if rule.centre != 0.0 {
            acc = rule.centre * self.value(sm, cm)?;
            evals += 1;
        }
        for &(x, w) in &rule.pairs {
            let hx = half * x;
            let (sx, cx) = sinh_cosh(hx);
            let up = self.value(sm * cx + cm * sx, cm * cx + sm * sx)?;
            // The difference loses a factor up to exp(2 h x): beyond 2 its own exponential.
            let (sd, cd) = if hx <= ADDITION_REACH {
                (sm * cx - cm * sx, cm * cx - sm * sx)
            } else {
                sinh_cosh(mid - hx)
            };
            let down = self.value(sd, cd)?;
            acc += w * (up + down);
        }
        Ok((half * acc, evals))
    }

    /// The fine rule of the step for `span` on `[a, b]`, `a` the start of an accepted panel and
    /// `b` inside it: the time from `a` to `b`.
    pub(super) fn partial(
        &self,
        control: &Control,
        span: f64,
        a: f64,
        b: f64,
    ) -> Result<(f64, u64), SolveError> {
        let (_, fine) = control.step_for(span);
        self.panel(fine, a, b)
    }
}
