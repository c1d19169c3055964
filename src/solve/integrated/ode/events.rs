//! Where an event function changes sign within a step: the root found on the step's
//! continuous extension and checked on genuine steps, else bracketed and finished on them.

use super::stages::Stages;
use super::{DenseStep, OdeProblem, OdeSolution, check_finite};
use crate::solve::SolveError;
use crate::solve::roots::{changes_sign, illinois, illinois_to};

/// A step from `(t, y)` of size `h` whose events are being located.
#[derive(Clone, Copy)]
pub(super) struct Trial<'a> {
    /// Where the integration started.
    pub(super) start: f64,
    pub(super) t: f64,
    pub(super) y: &'a [f64],
    pub(super) h: f64,
    /// The relative tolerance it was taken at.
    pub(super) rtol: f64,
}

/// The earliest root among the crossed event functions (none crossed: `None`), as an offset
/// from the step's start. Each root is first found on the step's continuous extension `dense`,
/// then checked on genuine steps from the step's start (the event's state is the integrator's
/// own, [`polish`]); where neither of two trials is past the genuine root and close enough, it
/// is closed in on with genuine re-steps to adjacent floats ([`genuine_root`]). Either way the
/// event's value at the root is past the crossing or zero.
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
    let Trial { t, y, h, rtol, .. } = step;
    let mut g = vec![0.0; g0.len()];
    let mut dz = vec![0.0; y.len()];
    let mut best: Option<(f64, usize)> = None;
    for &idx in crossed {
        let ends = ((0.0, g0[idx]), (h, g1[idx]));
        let slack = problem.event_slack(idx);
        let mut on_extension = |x: f64| -> Result<f64, SolveError> {
            let z = dense.extension(t + x);
            problem.rhs(t + x, &z, &mut dz)?;
            problem.events(t + x, &z, &dz, &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        let estimate = illinois(&mut on_extension, ends.0, ends.1)?;
        let slope = extension_slope(&mut on_extension, estimate, h)?;
        let mut genuine = |x: f64| -> Result<f64, SolveError> {
            st.step(problem, t, y, x)?;
            st.end_derivative(problem)?;
            sol.event_trials += 1;
            problem.events(t + x, &st.y1, st.end(), &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        // How far before a trial the genuine root may lie: the tolerance's share of the time
        // integrated to the event, at most of the step (the extension's error grows with
        // both), at least the bracketed search's own two ulps of the event's time.
        let span = (t - step.start + estimate).min(h);
        let window = (EXTENSION_SHARE * rtol * span).max(2.0 * f64::EPSILON * (t + h).abs());
        let root = match polish(&mut genuine, (estimate, slope), (window, slack), ends)? {
            Polished::Root(x) => x,
            Polished::Bracket(estimate, a, b) => genuine_root(&mut genuine, estimate, step, a, b)?,
        };
        if best.is_none_or(|(tb, ib)| root < tb || (root == tb && idx < ib)) {
            best = Some((root, idx));
        }
    }
    Ok(best)
}

/// The share of `rtol` times the time integrated to an event (at most the step's size) within
/// which the genuine root must lie before a trial past it for that trial to be the event: a
/// hundredth, so that the event's time stays well within the tolerance of the genuine root's
/// (`tests/ode.rs` holds the rod and cube's separation to 1e-12 at `rtol` 1e-10). Not relative to
/// the clock: a run's time since the clock's zero is no measure of how well one step's extension is
/// known (a segment that starts 17.5 s in, on steps of 0.04 s, would allow four hundred times
/// more).
pub(super) const EXTENSION_SHARE: f64 = 0.01;

/// What [`polish`] found.
enum Polished {
    /// The event's offset in the step.
    Root(f64),
    /// No trial passed: the best estimate of the root, and the tightest bracket of it known
    /// (`a` on the step start's side of the crossing, `b` past it).
    Bracket(f64, Point, Point),
}

/// The extension's root `x0` (with the extension's `slope` there) checked on genuine steps,
/// `genuine(x)` being the event function after a genuine step to `x`. A trial `x` is the event
/// where its value is past the crossing (across zero from the start's, `a`'s, or zero: where
/// the bracketed search ends too, so that what follows the event sees it happened), within
/// `slack` of zero, and the slope puts the genuine root within `window` before it. The first
/// trial is `x0`, the second (where the first fails) the Newton step from it along the slope;
/// each is aimed `window / 2` past its estimate of the root, so that it lands past the crossing
/// despite the estimate's error. A slope that does not run from the start's sign to the end's
/// measures no distance: the root is then bracketed at once.
fn polish(
    mut genuine: impl FnMut(f64) -> Result<f64, SolveError>,
    (x0, slope): Point,
    (window, slack): (f64, f64),
    (mut a, mut b): (Point, Point),
) -> Result<Polished, SolveError> {
    let runs = slope * (b.1 - a.1);
    if runs.is_nan() || runs <= 0.0 {
        return Ok(Polished::Bracket(x0, a, b));
    }
    let mut x = x0 + 0.5 * window;
    for _ in 0..2 {
        if !(x > a.0 && x < b.0) {
            break;
        }
        let gx = genuine(x)?;
        // The genuine root's distance ahead of `x` (negative: behind it) along the slope.
        let ahead = -gx / slope;
        if changes_sign(a.1, gx) {
            b = (x, gx);
            if -ahead <= window && gx.abs() <= slack {
                return Ok(Polished::Root(x));
            }
        } else {
            a = (x, gx);
        }
        x += ahead + 0.5 * window;
    }
    Ok(Polished::Bracket(x, a, b))
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
/// start at `t`) in the bracket `(a, b)`, near `estimate`, to two ulps of the event's time
/// `t + x`, past the crossing: around the estimate at the local error's distance, then around
/// the secant root of that bracket at a few ulps, then Illinois.
fn genuine_root(
    mut genuine: impl FnMut(f64) -> Result<f64, SolveError>,
    estimate: f64,
    Trial { t, h, rtol, .. }: Trial,
    a: Point,
    b: Point,
) -> Result<f64, SolveError> {
    let local = rtol.max(f64::EPSILON) * h;
    let (a, b) = bracket(&mut genuine, estimate, local, a, b)?;
    let secant = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
    let ulps = 4.0 * f64::EPSILON * secant.abs();
    let (a, b) = bracket(&mut genuine, secant, ulps, a, b)?;
    // To two ulps of the event's time `t + x`, the most it can hold.
    illinois_to(genuine, a, b, 2.0 * f64::EPSILON * (t + h).abs())
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
