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

/// The earliest root among the crossed event functions (none crossed: `None`), to adjacent
/// floats of genuine re-steps from the step's start (each trial a step to `t + x`, not the
/// interpolant: the event's state is the integrator's own). The step's continuous extension
/// `dense` gives each root's first estimate ([`bracket`] then closes in on it with few trials).
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
        let mut genuine = |x: f64| -> Result<f64, SolveError> {
            st.step(problem, t, y, x)?;
            st.end_derivative(problem)?;
            sol.event_trials += 1;
            problem.events(t + x, &st.y1, st.end(), &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        // Close in on the genuine root: around the extension's at the local error's distance,
        // then around the secant root of that bracket at a few ulps.
        let local = rtol.max(f64::EPSILON) * h;
        let (a, b) = bracket(&mut genuine, estimate, local, (0.0, g0[idx]), (h, g1[idx]))?;
        let secant = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
        let ulps = 4.0 * f64::EPSILON * secant.abs();
        let (a, b) = bracket(&mut genuine, secant, ulps, a, b)?;
        // To two ulps of the event's time `t + x`, the most it can hold.
        let root = illinois_to(genuine, a, b, 2.0 * f64::EPSILON * (t + h).abs())?;
        if best.is_none_or(|(tb, ib)| root < tb || (root == tb && idx < ib)) {
            best = Some((root, idx));
        }
    }
    Ok(best)
}

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
/// bracket as it is.
pub(super) fn bracket<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    estimate: f64,
    delta: f64,
    (a, fa): Point,
    (b, fb): Point,
) -> Result<(Point, Point), E> {
    if !(estimate > a && estimate < b) {
        return Ok(((a, fa), (b, fb)));
    }
    let (mut x, mut fx) = (estimate, f(estimate)?);
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
