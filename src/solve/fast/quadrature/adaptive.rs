//! The adaptive quadrature of a phase: [`integrate`] cuts `[0, v_end]` into panels of the
//! schedule's lengths and halves a panel until its two rules agree, under a [`Control`].

use super::fall::Fall;
use super::rules::Control;
use crate::solve::SolveError;

/// Most panels one integral may use before giving up.
pub const MAX_PANELS: usize = 20_000;

/// One accepted panel `[a, b]` in `v`, its value and the length its rules were chosen for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Lower limit (in `v`).
    pub a: f64,
    /// Upper limit (in `v`).
    pub b: f64,
    /// Integral over `[a, b]`.
    pub value: f64,
}

/// `t` from the phase's start (`v = 0`) to `v_end`, panel by panel under `control`; each
/// accepted panel goes to `keep`, in ascending order. Returns the integral and the integrand
/// evaluations. `stack` is scratch, reused across calls.
pub fn integrate(
    fall: &Fall,
    v_end: f64,
    control: &Control,
    stack: &mut Vec<(f64, f64)>,
    mut keep: impl FnMut(Panel),
) -> Result<(f64, u64), SolveError> {
    if !(v_end >= 0.0 && v_end.is_finite()) {
        return Err(SolveError::BadPhaseEnd {
            model: fall.model,
            delta_end: fall.delta_end,
        });
    }
    stack.clear();
    if v_end == 0.0 {
        return Ok((0.0, 0));
    }
    // The a-priori cut: a first panel of span at most the longest step's, then equal pieces.
    let longest = control.longest();
    let first = if fall.from_rest {
        v_end.min(0.5 * longest)
    } else {
        v_end.min(longest)
    };
    let rest = v_end - first;
    let pieces = if rest > 0.0 {
        ((rest / longest).ceil() as usize).clamp(1, MAX_PANELS)
    } else {
        0
    };
    for i in (0..pieces).rev() {
        let lo = first + rest * i as f64 / pieces as f64;
        let hi = if i + 1 == pieces {
            v_end
        } else {
            first + rest * (i + 1) as f64 / pieces as f64
        };
        stack.push((lo, hi));
    }
    stack.push((0.0, first));
    let (mut total, mut evals, mut panels) = (0.0, 0u64, 0usize);
    while let Some((lo, hi)) = stack.pop() {
        let (coarse, fine) = control.step_for(fall.span(lo, hi));
        let (coarse, n_coarse) = fall.panel(coarse, lo, hi)?;
        let (fine, n_fine) = fall.panel(fine, lo, hi)?;
        evals += n_coarse + n_fine;
        let error = (fine - coarse).abs();
        panels += 1;
        if fine.is_finite() && error <= control.accept * fine.abs() {
            total += fine;
            keep(Panel {
                a: lo,
                b: hi,
                value: fine,
            });
            continue;
        }
        let mid = 0.5 * (lo + hi);
        if !(fine.is_finite() && mid > lo && mid < hi) || panels + stack.len() > MAX_PANELS {
            return Err(SolveError::QuadratureNotConverged {
                a: 0.0,
                b: v_end,
                tol: control.accept,
                estimate: total + fine,
                error,
                panels,
            });
        }
        stack.push((mid, hi));
        stack.push((lo, mid));
    }
    Ok((total, evals))
}
