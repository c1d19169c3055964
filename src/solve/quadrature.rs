//! Time along a phase, `t(delta) = integral of d(delta) / |theta_dot|`, by adaptive
//! Gauss–Legendre quadrature after the substitution `delta = u^2`.
//!
//! Released from rest, `theta_dot^2 ~ -2 theta_ddot_i delta` near the start, so the integrand
//! `1/|theta_dot|` has a `1/sqrt` endpoint singularity (the paper's eqs. 10 and 15). With
//! `delta = u^2` the integral becomes `integral_0^sqrt(delta_end) 2u / sqrt(theta_dot^2(u^2)) du`,
//! whose integrand is smooth and tends to `2 / sqrt(-2 theta_ddot_i)` at `u = 0`. The model
//! functions take `delta` directly, so no `theta_i - theta` cancellation enters. The same
//! substitution is harmless when the phase starts moving (`theta_dot_i != 0`, e.g. the free
//! rod after separation): the integrand is then `~ 2u / |theta_dot_i|`, also smooth.
//!
//! Near-upright starts (`a/ell -> 1`) make `theta_ddot_i -> 0`, and the integrand varies on a
//! scale `u ~ sqrt(cos theta_i)` near the start; the adaptive bisection grades the panels there
//! by itself. Each accepted panel is kept, so `t(u)` at any `u` afterwards costs one partial
//! panel (see [`TimeMesh::time_at_u`]).

use crate::results::Work;
use crate::solve::SolveError;
use crate::system::System;
use gauss_quad::GaussLegendre;
use std::num::NonZeroUsize;
use std::sync::OnceLock;

/// Nodes per Gauss–Legendre panel.
pub const GL_ORDER: usize = 10;

/// Smallest relative tolerance honoured (a few ulps: the rounding floor of one panel sum).
pub const MIN_TOL: f64 = 4.0 * f64::EPSILON;

/// Most panels one adaptive integral may use before giving up.
pub const MAX_PANELS: usize = 20_000;

/// The Gauss–Legendre nodes and weights on `[-1, 1]` of order [`GL_ORDER`], computed once.
pub fn rule() -> &'static [(f64, f64)] {
    static RULE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    RULE.get_or_init(|| gauss_legendre_rule(GL_ORDER))
}

/// Gauss–Legendre nodes and weights on `[-1, 1]` of any order (0 is treated as 1).
pub fn gauss_legendre_rule(order: usize) -> Vec<(f64, f64)> {
    GaussLegendre::new(NonZeroUsize::new(order).unwrap_or(NonZeroUsize::MIN))
        .as_node_weight_pairs()
        .to_vec()
}

/// One panel of an adaptive integral.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Lower limit.
    pub a: f64,
    /// Upper limit.
    pub b: f64,
    /// Integral over `[a, b]`.
    pub value: f64,
}

/// An adaptive integral and the panels it accepted, in ascending order.
#[derive(Debug, Clone, PartialEq)]
pub struct Adaptive {
    /// The integral.
    pub value: f64,
    /// Accepted panels, covering the interval in order.
    pub panels: Vec<Panel>,
}

/// One Gauss–Legendre panel over `[a, b]` with the given rule.
pub fn panel<F>(
    rule: &[(f64, f64)],
    f: &mut F,
    a: f64,
    b: f64,
    evals: &mut u64,
) -> Result<f64, SolveError>
where
    F: FnMut(f64) -> Result<f64, SolveError>,
{
    let (half, centre) = (0.5 * (b - a), 0.5 * (a + b));
    let mut sum = 0.0;
    for &(x, w) in rule {
        sum += w * f(centre + half * x)?;
    }
    *evals += rule.len() as u64;
    Ok(half * sum)
}

/// Adaptive bisection with a fixed Gauss–Legendre rule: a panel is accepted when its two halves
/// agree with it to `tol` relative; the halves are kept. For an integrand of one sign the local
/// relative test bounds the global relative error. `tol` below [`MIN_TOL`] is raised to it.
pub fn adaptive<F>(
    rule: &[(f64, f64)],
    f: &mut F,
    a: f64,
    b: f64,
    tol: f64,
    evals: &mut u64,
) -> Result<Adaptive, SolveError>
where
    F: FnMut(f64) -> Result<f64, SolveError>,
{
    let tol = if tol.is_finite() {
        tol.max(MIN_TOL)
    } else {
        MIN_TOL
    };
    let mut panels = Vec::new();
    if b == a {
        return Ok(Adaptive { value: 0.0, panels });
    }
    let whole = panel(rule, f, a, b, evals)?;
    let mut stack = vec![(a, b, whole)];
    while let Some((lo, hi, whole)) = stack.pop() {
        let mid = 0.5 * (lo + hi);
        let left = panel(rule, f, lo, mid, evals)?;
        let right = panel(rule, f, mid, hi, evals)?;
        let refined = left + right;
        let error = (refined - whole).abs();
        if refined.is_finite() && error <= tol * refined.abs() {
            panels.push(Panel {
                a: lo,
                b: mid,
                value: left,
            });
            panels.push(Panel {
                a: mid,
                b: hi,
                value: right,
            });
            continue;
        }
        let splittable = 0.5 * (lo + mid) > lo && 0.5 * (mid + hi) < hi;
        if !refined.is_finite()
            || !error.is_finite()
            || !splittable
            || panels.len() + stack.len() + 2 > MAX_PANELS
        {
            let estimate = panels.iter().map(|p| p.value).sum::<f64>()
                + refined
                + stack.iter().map(|s| s.2).sum::<f64>();
            return Err(SolveError::QuadratureNotConverged {
                a,
                b,
                tol,
                estimate,
                error,
                panels: panels.len() + stack.len(),
            });
        }
        stack.push((mid, hi, right));
        stack.push((lo, mid, left));
    }
    let value = panels.iter().map(|p| p.value).sum();
    Ok(Adaptive { value, panels })
}

/// Checks that a phase can start falling: from rest it needs `theta_ddot_i < 0`, moving it
/// needs `theta_dot_i < 0`.
pub fn check_start(sys: &System) -> Result<(), SolveError> {
    let theta_dot = sys.theta_dot_initial();
    let model = sys.name();
    if theta_dot > 0.0 {
        return Err(SolveError::Rising { model, theta_dot });
    }
    if theta_dot == 0.0 {
        let theta_ddot = sys.reduced(0.0).theta_ddot;
        if theta_ddot.is_nan() || theta_ddot >= 0.0 {
            return Err(SolveError::NoMotion {
                model,
                theta_dot,
                theta_ddot,
            });
        }
    }
    Ok(())
}

/// The integrand `2u / |theta_dot|` at `delta = u^2`, with its limit at `u = 0`.
/// `delta_end` only labels a turning-point error.
pub fn integrand(sys: &System, u: f64, delta_end: f64) -> Result<f64, SolveError> {
    let model = sys.name();
    if u == 0.0 {
        let theta_dot = sys.theta_dot_initial();
        if theta_dot != 0.0 {
            return Ok(0.0);
        }
        let theta_ddot = sys.reduced(0.0).theta_ddot;
        return if theta_ddot < 0.0 {
            Ok(2.0 / (-2.0 * theta_ddot).sqrt())
        } else {
            Err(SolveError::NoMotion {
                model,
                theta_dot,
                theta_ddot,
            })
        };
    }
    let delta = u * u;
    let theta_dot_sq = sys.reduced(delta).theta_dot_sq;
    if !theta_dot_sq.is_finite() {
        return Err(SolveError::NonFinite {
            model,
            what: "theta_dot^2",
            delta,
            value: theta_dot_sq,
        });
    }
    if theta_dot_sq <= 0.0 {
        return Err(SolveError::TurningPoint {
            model,
            delta,
            theta_dot_sq,
            delta_end,
        });
    }
    Ok(2.0 * u / theta_dot_sq.sqrt())
}

/// `t(delta)` on one phase, from its start to `delta_end`, kept as adaptive panels in `u`.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMesh {
    /// Angle fallen at the end of the phase.
    pub delta_end: f64,
    /// `sqrt(delta_end)`.
    pub u_end: f64,
    /// Accepted panels in `u`.
    pub panels: Vec<Panel>,
    /// Time at the start of each panel.
    starts: Vec<f64>,
    /// Time from the phase start to `delta_end` (s).
    pub duration: f64,
}

impl TimeMesh {
    /// Integrates the phase of `sys` from its start to `delta_end` to relative tolerance `tol`.
    pub fn build(
        sys: &System,
        delta_end: f64,
        tol: f64,
        work: &mut Work,
    ) -> Result<TimeMesh, SolveError> {
        if !(delta_end > 0.0 && delta_end.is_finite()) {
            return Err(SolveError::BadPhaseEnd {
                model: sys.name(),
                delta_end,
            });
        }
        check_start(sys)?;
        let u_end = delta_end.sqrt();
        let mut f = |u: f64| integrand(sys, u, delta_end);
        let adaptive = adaptive(rule(), &mut f, 0.0, u_end, tol, &mut work.integrand_evals)?;
        let mut starts = Vec::with_capacity(adaptive.panels.len());
        let mut t = 0.0;
        for p in &adaptive.panels {
            starts.push(t);
            t += p.value;
        }
        Ok(TimeMesh {
            delta_end,
            u_end,
            panels: adaptive.panels,
            starts,
            duration: t,
        })
    }

    /// Time from the phase start to `delta = u^2`, for `0 <= u <= u_end` (a relative overshoot of
    /// up to 1e-6 past the end is extrapolated on the last panel). One partial panel.
    pub fn time_at_u(&self, sys: &System, u: f64, work: &mut Work) -> Result<f64, SolveError> {
        if !(u >= 0.0 && u <= self.u_end * (1.0 + 1e-6)) {
            return Err(SolveError::OutsidePhase {
                model: sys.name(),
                delta: u * u,
                delta_end: self.delta_end,
            });
        }
        if u == 0.0 {
            return Ok(0.0);
        }
        let i = self.panels.partition_point(|p| p.a < u).saturating_sub(1);
        let p = self.panels[i];
        if u == p.b {
            return Ok(self.starts[i] + p.value);
        }
        let delta_end = self.delta_end;
        let mut f = |v: f64| integrand(sys, v, delta_end);
        Ok(self.starts[i] + panel(rule(), &mut f, p.a, u, &mut work.integrand_evals)?)
    }

    /// Time from the phase start to the angle fallen `delta`.
    pub fn time_at_delta(
        &self,
        sys: &System,
        delta: f64,
        work: &mut Work,
    ) -> Result<f64, SolveError> {
        self.time_at_u(sys, delta.max(0.0).sqrt(), work)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adaptive_integrates_a_peaked_function() {
        // integral_0^1 1/sqrt(eps + x^2) dx = asinh(1/sqrt(eps))
        let eps: f64 = 1e-9;
        let mut evals = 0;
        let mut f = |x: f64| Ok(1.0 / (eps + x * x).sqrt());
        let got = adaptive(rule(), &mut f, 0.0, 1.0, 1e-14, &mut evals).unwrap();
        let want = (1.0 / eps.sqrt()).asinh();
        assert!(
            ((got.value - want) / want).abs() < 1e-13,
            "{} vs {want}",
            got.value
        );
        assert!(got.panels.windows(2).all(|w| w[0].b == w[1].a));
        assert_eq!(evals % GL_ORDER as u64, 0);
    }

    #[test]
    fn a_divergent_integral_is_an_error() {
        let mut evals = 0;
        let mut f = |x: f64| Ok(1.0 / x);
        let err = adaptive(rule(), &mut f, 0.0, 1.0, 1e-12, &mut evals).unwrap_err();
        assert!(
            matches!(err, SolveError::QuadratureNotConverged { .. }),
            "{err}"
        );
    }
}
