//! Where an event function changes sign within a step: the root estimated on the step's
//! continuous extension, then bracketed and finished on genuine steps.

use super::stages::Stages;
use super::{DenseStep, OdeProblem, OdeSolution, check_finite};
use crate::solve::SolveError;
use crate::solve::roots::{changes_sign, illinois, illinois_to};

/// A step from `(t, y)` of size `h` whose events are being located.
#[derive(Clone, Copy)]
pub(super) struct Trial<'a> {
    pub(super) t: f64,
    pub(super) y: &'a [f64],
    pub(super) h: f64,
    /// The relative tolerance it was taken at.
    pub(super) rtol: f64,
}

/// The earliest root among the crossed event functions (none crossed: `None`), as an offset
/// from the step's start. Each root is first found on the step's continuous extension
/// `dense`, then checked by one genuine step to it (the event's state is the integrator's
/// own): where the event function's value there over its slope on the extension puts the
/// genuine root within [`EXTENSION_SHARE`] of `rtol` of the event's time, the extension's root
/// is the event's time. Else one more genuine step to the Newton step from it is checked the
/// same way; where that too is not close enough, the root is closed in on with genuine
/// re-steps to adjacent floats ([`genuine_root`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn locate<P: OdeProblem>(
    problem: &mut P,
    st: &mut Stages,
    sol: &mut OdeSolution,
    step: Trial,
    dense: &DenseStep,
    crossed: &[usize],
    g0: &[f64],
    g1: &[f64],
) -> Result<Option<(f64, usize)>, SolveError> {
    let Trial { t, y, h, rtol } = step;
    let mut g = vec![0.0; g0.len()];
    let mut dz = vec![0.0; y.len()];
    let mut best: Option<(f64, usize)> = None;
    for &idx in crossed {
        let mut on_extension = |x: f64| -> Result<f64, SolveError> {
            let z = dense.extension(t + x);
            problem.rhs(t + x, &z, &mut dz)?;
            problem.events(t + x, &z, &dz, &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        let estimate = illinois(&mut on_extension, (0.0, g0[idx]), (h, g1[idx]))?;
        let slope = extension_slope(&mut on_extension, estimate, h)?;
        let mut genuine = |x: f64| -> Result<f64, SolveError> {
            st.step(problem, t, y, x)?;
            st.end_derivative(problem)?;
            sol.event_trials += 1;
            problem.events(t + x, &st.y1, st.end(), &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        // One genuine step to the extension's root; where it is not close enough, one more to
        // the Newton step from it along the extension's slope; else the bracketed search.
        let close = |x: f64, at: f64| {
            at == 0.0 || (at / slope).abs() <= EXTENSION_SHARE * rtol * (t + x).abs()
        };
        let (mut x, mut known, mut root) = (estimate, (estimate, f64::NAN), None);
        for _ in 0..2 {
            if !(x > 0.0 && x < h) {
                break;
            }
            let at = genuine(x)?;
            known = (x, at);
            if close(x, at) {
                root = Some(x);
                break;
            }
            x -= at / slope;
        }
        let root = match root {
            Some(x) => x,
            None => genuine_root(&mut genuine, known, step, (g0[idx], g1[idx]))?,
        };
        if best.is_none_or(|(tb, ib)| root < tb || (root == tb && idx < ib)) {
            best = Some((root, idx));
        }
    }
    Ok(best)
}

/// The slope of `f` (an event function on a step's continuous extension, a polynomial in
/// time) at `x` in `[0, h]`, by a central difference a millionth of the step wide, one-sided
/// at an end.
fn extension_slope<E>(mut f: impl FnMut(f64) -> Result<f64, E>, x: f64, h: f64) -> Result<f64, E> {
    let d = 1e-6 * h;
    let (a, b) = ((x - d).max(0.0), (x + d).min(h));
    Ok((f(b)? - f(a)?) / (b - a))
}

/// The root `x` of `genuine` (the event function after a genuine step to `x` from the step's
/// start) near the extension's `estimate` (with its value there, NaN where not evaluated),
/// inside the step whose ends have the values `ends`, to two ulps of the event's time `t + x`:
/// around the estimate at the local error's distance, then around the secant root of that
/// bracket at a few ulps, then Illinois.
fn genuine_root(
    mut genuine: impl FnMut(f64) -> Result<f64, SolveError>,
    (estimate, at): Point,
    Trial { t, h, rtol, .. }: Trial,
    (g0, g1): (f64, f64),
) -> Result<f64, SolveError> {
    let local = rtol.max(f64::EPSILON) * h;
    let known = (!at.is_nan()).then_some(at);
    let (a, b) = bracket(&mut genuine, (estimate, known), local, (0.0, g0), (h, g1))?;
    let secant = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
    let ulps = 4.0 * f64::EPSILON * secant.abs();
    let (a, b) = bracket(&mut genuine, (secant, None), ulps, a, b)?;
    // To two ulps of the event's time `t + x`, the most it can hold.
    illinois_to(genuine, a, b, 2.0 * f64::EPSILON * (t + h).abs())
}

/// The share of the run's relative tolerance within which the genuine root must lie of the
/// extension's (to first order) for the extension's to be the event's time: a hundredth, so that
/// the event's time, and what follows from its state, stay well within the tolerance of the
/// genuine root's.
pub(super) const EXTENSION_SHARE: f64 = 0.01;

/// A point and the function's value there.
type Point = (f64, f64);

/// How much [`bracket`]'s distance from its estimate grows at each look that finds no sign
/// change.
const BRACKET_GROWTH: f64 = 16.0;

/// Most looks of one [`bracket`]: from an ulp, sixteen-fold growth covers any interval of
/// floats in 14.
const BRACKET_LOOKS: usize = 16;

/// A bracket `(a', b')` inside `(a, b)` of a root of `f` near `estimate` (`f(a')` of `fa`'s
/// sign, `f(b')` across zero from it or zero), found by looking at distances from the estimate
/// growing from `delta` (at least an ulp of it), on the side where the root lies. `a < b`, and
/// `fa` and `fb` differ in sign; an estimate outside `(a, b)` (or not a number) leaves the
/// bracket as it is. `known`: `f(estimate)` where the caller has it.
pub(super) fn bracket<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (estimate, known): (f64, Option<f64>),
    delta: f64,
    (a, fa): Point,
    (b, fb): Point,
) -> Result<(Point, Point), E> {
    if !(estimate > a && estimate < b) {
        return Ok(((a, fa), (b, fb)));
    }
    let fx = match known {
        Some(v) => v,
        None => f(estimate)?,
    };
    let (mut x, mut fx) = (estimate, fx);
    let below = changes_sign(fa, fx);
    let mut delta = delta
        .max(f64::EPSILON * estimate.abs())
        .max(f64::MIN_POSITIVE);
    for _ in 0..BRACKET_LOOKS {
        if fx == 0.0 {
            break;
        }
        let next = if below { x - delta } else { x + delta };
        if (below && next <= a) || (!below && next >= b) {
            break;
        }
        let fn_ = f(next)?;
        match (below, changes_sign(fa, fn_)) {
            (true, false) => return Ok(((next, fn_), (x, fx))),
            (false, true) => return Ok(((x, fx), (next, fn_))),
            _ => (x, fx) = (next, fn_),
        }
        delta *= BRACKET_GROWTH;
    }
    // The root lies between the last point and the end on its side.
    Ok(if below {
        ((a, fa), (x, fx))
    } else {
        ((x, fx), (b, fb))
    })
}
