//! A fast phase's motion at a given time or angle: the angle fallen at a time, by inverting
//! the quadrature `t(v)` (the variable `v` of [`quadrature`](crate::solve::fast::quadrature)) with
//! safeguarded Newton, `dt/dv` being the quadrature integrand itself, and the rate at an angle
//! from the energy integral. `solve::phases` places events with them and `solve::series` samples
//! phases with them (and re-exports them).

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::fast::quadrature::TimeMesh;
use crate::system::System;

/// `theta_dot` at `delta` on a falling phase: `-sqrt(theta_dot^2)`, and exactly the initial rate
/// at the start (zero from rest); NaN for a `delta` that is not finite (or where the model's
/// `theta_dot^2` is NaN).
pub fn theta_dot_at(sys: &System, delta: f64) -> f64 {
    if delta == 0.0 {
        return sys.theta_dot_initial();
    }
    // The model's function itself: a NaN argument gives NaN, which `f64::max` would hide.
    let w2 = sys.reduction().reduced(sys.k(), delta).theta_dot_sq;
    if w2.is_nan() { w2 } else { -w2.max(0.0).sqrt() }
}

/// The angle fallen at time `t` from the phase start.
pub fn delta_at_time(
    sys: &System,
    mesh: &TimeMesh,
    t: f64,
    work: &mut Work,
) -> Result<f64, SolveError> {
    if !(t >= 0.0 && t <= mesh.duration) {
        return Err(SolveError::Inversion {
            target: t,
            duration: mesh.duration,
            reason: "time outside the phase",
        });
    }
    if t == 0.0 {
        return Ok(0.0);
    }
    if t == mesh.duration {
        return Ok(mesh.delta_end);
    }
    let v = invert(sys, mesh, t, 0.0, 0.0, work)?;
    mesh.delta_at_v(sys, v)
}

/// Solves `t(v) = target` for `v` in `[v_lo, v_end]`, knowing `t(v_lo) = t_lo <= target`.
pub(crate) fn invert(
    sys: &System,
    mesh: &TimeMesh,
    target: f64,
    v_lo: f64,
    t_lo: f64,
    work: &mut Work,
) -> Result<f64, SolveError> {
    let fail = |reason| SolveError::Inversion {
        target,
        duration: mesh.duration,
        reason,
    };
    let (mut lo, mut hi) = (v_lo, mesh.v_end);
    // First guess: a Newton step from the bracket's start (dt/dv is finite there).
    let mut v = v_lo + (target - t_lo) / mesh.rate_at_v(sys, v_lo, work)?;
    if !(v > lo && v < hi) {
        v = 0.5 * (lo + hi);
    }
    for _ in 0..200 {
        let t = mesh.time_at_v(sys, v, work)?;
        let residual = t - target;
        if residual == 0.0 {
            return Ok(v);
        }
        if residual < 0.0 {
            lo = v;
        } else {
            hi = v;
        }
        let slope = mesh.rate_at_v(sys, v, work)?;
        let newton = v - residual / slope;
        let step = (newton - v).abs();
        if step <= 2.0 * f64::EPSILON * v {
            return Ok(newton.clamp(lo, hi));
        }
        let mid = 0.5 * (lo + hi);
        if !(mid > lo && mid < hi) {
            return Ok(v);
        }
        v = if newton > lo && newton < hi {
            newton
        } else {
            mid
        };
    }
    Err(fail("Newton on v did not converge in 200 steps"))
}
