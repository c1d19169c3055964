//! Real roots of a polynomial in an interval, without allocating: the one root isolator of the
//! planner's separation, the per-point solver and the sweeps.
//!
//! The roots of `p'` split the interval into pieces on which `p` is monotone, so each piece holds
//! at most one sign change; each is refined by Halley's method kept inside its shrinking bracket
//! (bisection when a step leaves it or stalls). A cubic's critical points come from the quadratic
//! formula; higher degrees recurse. Signs are reliable: a plain Horner value within its own
//! rounding bound of zero is redone by compensated Horner (twice the working precision), so a
//! root is located to within an ulp or two whenever it is well conditioned, whatever the scale of
//! the coefficients (e.g. `n = m2/m1` from 1e-12 to 1e12).
//!
//! The largest root of a quadratic or cubic (every separation polynomial of the per-point
//! solver) is first sought without the split. A depressed cubic `c0 + c1 s + c3 s^3` (the
//! separation cubic of every generated model that has one) whose root near `-c0 / c1` is a
//! small correction of it takes one Halley step from a start interpolated once for all in
//! the cubic's one shape parameter, and needs no deflation: where the root lies within the
//! start's range, the next root is provably above the interval (`depressed_low`). Other
//! quadratics and cubics take Halley from the root of the linear part corrected by three
//! fixed-point steps, kept when deflation shows the other roots clear of it and of the
//! interval above it (`certified_low`). Either way the last iterate is polished on the
//! compensated value only where the running error bound of its plain value (Higham's) does
//! not already hold it within two ulps; where neither applies, the split decides.

/// Highest degree solved (on the stack; higher degrees are refused with `None`).
pub const MAX_DEGREE: usize = 16;

/// Most Halley or bisection steps for one root (bisection alone needs at most about 2100 to
/// reach adjacent floats from any bracket).
const MAX_STEPS: usize = 4000;

/// Every sign-changing real root of `coeffs` (lowest degree first) in the open interval
/// `(lo, hi)`, ascending; `None` when the degree exceeds [`MAX_DEGREE`]. Roots of even
/// multiplicity (touching zero) are not reported. `evals` counts evaluations of the polynomial.
pub fn real_roots(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<Vec<f64>> {
    let mut out = [0.0; MAX_DEGREE];
    let n = roots_in(coeffs, lo, hi, &mut out, evals)?;
    Some(out[..n].to_vec())
}

/// The largest sign-changing root of `coeffs` in `(lo, hi)`: `Some(None)` when there is none,
/// `None` when the degree exceeds [`MAX_DEGREE`].
#[inline(always)]
pub fn largest_root(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<Option<f64>> {
    let degree = coeffs.iter().rposition(|&c| c != 0.0).unwrap_or(0);
    // A quadratic or cubic, as a cubic (a quadratic's leading coefficient 0) of known length,
    // so that every evaluation below unrolls.
    let low = match coeffs.get(..=degree) {
        Some(&[c0, c1, c2]) => Some([c0, c1, c2, 0.0]),
        Some(&[c0, c1, c2, c3]) => Some([c0, c1, c2, c3]),
        _ => None,
    };
    if let Some(c4) = low
        && lo < hi
    {
        return Some(largest_low(c4, lo, hi, evals));
    }
    let mut out = [0.0; MAX_DEGREE];
    let n = roots_in(coeffs, lo, hi, &mut out, evals)?;
    Some((n > 0).then(|| out[n - 1]))
}

/// [`largest_root`] for a quadratic or cubic (trimmed, `lo < hi`): the critical points by the
/// quadratic formula, then only the highest piece with a sign change is refined.
#[inline(always)]
fn largest_low(c4: [f64; 4], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    // A depressed cubic (no square term, as every separation cubic generated so far) in the
    // range of its start; else the general start.
    if c4[2] == 0.0
        && let Some(root) = depressed_low(c4, lo, hi, evals)
    {
        return Some(root);
    }
    if let Some(root) = certified_low(c4, lo, hi, evals) {
        return Some(root);
    }
    largest_split(c4, lo, hi, evals)
}

/// [`largest_low`] by the monotone split, for a root the certified path left (out of line: the
/// rare path).
#[cold]
#[inline(never)]
fn largest_split(c4: [f64; 4], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    let c = &c4[..];
    // Knots ascending: lo, the critical points inside, hi.
    let mut crit = [0.0; MAX_DEGREE];
    let nc = if c[3] != 0.0 {
        quadratic_roots(&[c[1], 2.0 * c[2], 3.0 * c[3]], lo, hi, &mut crit)
    } else {
        let x = -c[1] / (2.0 * c[2]);
        crit[0] = x;
        usize::from(x > lo && x < hi)
    };
    let mut knots = [lo; 4];
    knots[1..=nc].copy_from_slice(&crit[..nc]);
    knots[nc + 1] = hi;
    let nk = nc + 2;
    let mut values = [0.0; 4];
    for (v, &x) in values.iter_mut().zip(&knots[..nk]) {
        *v = value(c, x);
    }
    *evals += nk as u64;
    // From the top: the first piece with a root holds the largest.
    for i in (0..nk - 1).rev() {
        if let Some(root) = piece_root(c, &knots[..nk], &values[..nk], i, evals) {
            return Some(root);
        }
    }
    None
}

/// The largest sign-changing root of a quadratic or cubic `c` in `(lo, hi)` when it can be
/// certified cheaply, else `None` (the caller then isolates by the bracketed path, which also
/// decides that there is no root).
///
/// Halley's method on plain Horner values from the root of the linear part `-c0 / c1` (most
/// separation polynomials are dominated by it near their root) after three fixed-point
/// corrections, stopped once a step is below 1e-7 relative (Halley's own error is then far
/// below an ulp). The last step came from a plain value within its running error bound `mu`
/// (Higham, *Accuracy and Stability of Numerical Algorithms*, Algorithm 5.1), so the iterate
/// lies within `mu / |p'|` of the root, plus the step's rounding: where that is more than two
/// ulps, one Newton step on the compensated value follows, as in [`refine`]. The result
/// is certified by deflation: `p(s) = (s - x) q(s)` up to the remainder, and the real roots of
/// the quadratic (or linear) `q` must all lie clear of `(x - gap, hi + gap)`, so that `x` is a
/// simple root (a sign change) and none larger lies in the interval. Anything less clear (a
/// root near an end of the interval or near another root, no convergence) is left to the
/// bracketed path.
#[inline(always)]
fn certified_low(c: [f64; 4], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    let [c0, c1, c2, c3] = c;
    let width = hi - lo;
    // The root of the linear part, corrected three times by the fixed point `x = -(c0 + c2 x^2
    // + c3 x^3) / c1` (at the linear root `c0 + c1 x = 0`, so `p(x) = x^2 (c2 + c3 x)`): each
    // step multiplies the relative error by about `t ~ c3 x^2 / c1`, which saves Halley steps
    // wherever `t` is small (on the rod on the cube's cubics, before they took
    // [`depressed_low`], three steps took 1.93 to 1.45 Halley steps per point of
    // `examples/per_point.rs`' set).
    let linear = -c0 / c1;
    let mut fixed = linear;
    for _ in 0..3 {
        fixed = linear - fixed * fixed * (c2 + c3 * fixed) / c1;
    }
    let mut x = if fixed > lo && fixed < hi {
        fixed
    } else if linear > lo && linear < hi {
        linear
    } else {
        lo + 0.5 * width
    };
    let mut converged = false;
    // Higham's running bound on the last plain value's rounding error (its Algorithm 5.1).
    let mut bound = f64::INFINITY;
    let mut slope = 0.0;
    for _ in 0..CERTIFIED_STEPS {
        *evals += 1;
        let step;
        (step, bound, slope) = halley_step(c, x);
        x -= step;
        // NaN fails both tests and leaves the loop unconverged.
        if step.abs() <= 1e-7 * x.abs() {
            converged = true;
            break;
        }
        if !step.is_finite() {
            break;
        }
    }
    // Clear of the ends by more than the deflated roots' uncertainty.
    let gap = 1e-6 * width;
    if !(converged && x > lo + gap && x < hi - gap) {
        return None;
    }
    let x = held_or_polished(c, x, bound, slope, lo, hi, evals)?;
    // q(s) = c3 s^2 + q1 s + q0: the other roots.
    let (q1, q0) = (c2 + x * c3, c1 + x * (c2 + x * c3));
    let clear = |y: f64| !(y > x - gap && y < hi + gap);
    let certified = if c3 == 0.0 {
        q1 != 0.0 && clear(-q0 / q1)
    } else {
        // A discriminant near zero (a near double root, real or not up to rounding) must
        // also lie clear.
        let disc = q1 * q1 - 4.0 * c3 * q0;
        let doubt = 1e-8 * (q1 * q1 + (4.0 * c3 * q0).abs());
        if disc < -doubt {
            true
        } else if disc >= -doubt {
            let q = -0.5 * (q1 + disc.max(0.0).sqrt().copysign(q1));
            q != 0.0 && clear(q / c3) && clear(q0 / q)
        } else {
            false
        }
    };
    certified.then_some(x)
}

/// One Halley step for the cubic `c` at `x` from its plain Horner value: `(step, bound,
/// slope)`, the step to subtract, Higham's running bound on the value's rounding error (his
/// Algorithm 5.1) and `p'(x)`.
#[inline(always)]
fn halley_step(c: [f64; 4], x: f64) -> (f64, f64, f64) {
    let [c0, c1, c2, c3] = c;
    let ax = x.abs();
    let y2 = c3 * x + c2;
    let y1 = y2 * x + c1;
    let p = y1 * x + c0;
    let mu = ((0.5 * c3.abs() * ax + y2.abs()) * ax + y1.abs()) * ax + p.abs();
    let bound = f64::EPSILON * mu - 0.5 * f64::EPSILON * p.abs();
    let d1 = (3.0 * c3 * x + 2.0 * c2) * x + c1;
    let d2 = 6.0 * c3 * x + 2.0 * c2;
    (2.0 * p * d1 / (2.0 * d1 * d1 - p * d2), bound, d1)
}

/// The root `x` of the cubic `c` in `(lo, hi)` reached by a Halley step from a plain value
/// within `bound` of the exact one where the slope was `slope`: the root is then within
/// `bound / |p'|` (and the step's rounding) of `x`, which is kept where that is at most two
/// ulps; elsewhere one Newton step on the compensated value, as in [`refine`]. `None` when that
/// step leaves the interval or moves `x` by more than a polish (a NaN bound is not held).
#[inline(always)]
fn held_or_polished(
    c: [f64; 4],
    x: f64,
    bound: f64,
    slope: f64,
    lo: f64,
    hi: f64,
    evals: &mut u64,
) -> Option<f64> {
    let held = bound <= 2.0 * f64::EPSILON * x.abs() * slope.abs();
    if held {
        return Some(x);
    }
    *evals += 1;
    let f = horner_compensated(&c, x);
    let d1 = (3.0 * c[3] * x + 2.0 * c[2]) * x + c[1];
    let newton = x - f / d1;
    (newton > lo && newton < hi && polish(x, newton)).then_some(newton)
}

/// Largest `epsilon = -c3 L^2 / c1` (with `L = -c0 / c1`) of a depressed cubic that
/// [`depressed_low`] solves: there the root `t1` of `epsilon t^3 - t + 1` near 1 lies in
/// `[1, sqrt(5) - 1]` and the next root `t2` at or above 2 (`t^3 - 8 t + 8 = (t - 2)(t^2 + 2t
/// - 4)` at `epsilon = 1/8`; `t2` falls as `epsilon` grows, to the double root 3/2 at 4/27).
const DEPRESSED_MAX: f64 = 0.125;

/// `t1` as a polynomial in `u = sqrt(1 - 27 epsilon / 4)` for `epsilon` in `[0, 1/8]` (`u` in
/// `[0.395, 1]`), lowest degree first: the interpolant of degree 6 at the Chebyshev points of
/// that interval, computed at 50 digits and rounded; within 2.7e-8 relative of `t1` (the
/// double root at `u = 0` is no singularity of `t1(u)`: its nearest lies at `u = -1`, where
/// `epsilon = 0` sends `t2` to infinity). Tested in `the_depressed_start_is_within_its_bound`.
const DEPRESSED_START: [f64; 7] = [
    1.499_307_168_710_495_5,
    -0.857_678_971_849_920_3,
    0.622_903_137_876_594_6,
    -0.428_913_129_886_526_7,
    0.233_290_052_930_634_15,
    -0.082_608_742_007_146_68,
    0.013_700_507_477_155_418,
];

/// Relative error of [`DEPRESSED_START`] that [`depressed_low`] allows its Halley step (a
/// fortyfold margin over the interpolant's; the step then leaves an error of order
/// `1e-18` relative, Halley's being cubic with a constant below 2 on the range).
const DEPRESSED_STEP: f64 = 1e-6;

/// The largest root in `(lo, hi)` of a depressed cubic `c0 + c1 s + c3 s^3` (`c[2] == 0`)
/// with `epsilon` (see [`DEPRESSED_MAX`]) in `[0, 1/8]`, when the interval's top lies below
/// the next root: `s = L t` with `t` from [`DEPRESSED_START`] and one Halley step, kept or
/// polished by [`held_or_polished`]. The next root is at least `2 L` for `L > 0` (`L t2`) and
/// at least `3 |L|` for `L < 0` (`L t3`, with `t3 = -(t1 + t2)`), so when `hi` lies below that
/// bound the root is the largest in the interval without deflation. `None` outside that
/// range, for a root within `1e-6` of the interval's width from an end, or for a Halley step
/// larger than [`DEPRESSED_STEP`]: [`certified_low`] then decides.
#[inline(always)]
fn depressed_low(c: [f64; 4], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    let [c0, c1, _, c3] = c;
    let l = -c0 / c1;
    let eps = c3 * l * l / -c1;
    let next = if l > 0.0 { 2.0 * l } else { -3.0 * l };
    // The margin covers the rounding of `l` and `eps` (NaN fails every test).
    if !((0.0..=DEPRESSED_MAX).contains(&eps) && hi < next * (1.0 - 1e-9)) {
        return None;
    }
    let u = (1.0 - 6.75 * eps).sqrt();
    let mut t = DEPRESSED_START[6];
    for &a in DEPRESSED_START[..6].iter().rev() {
        t = t * u + a;
    }
    let x0 = l * t;
    *evals += 1;
    let (step, bound, slope) = halley_step(c, x0);
    let x = x0 - step;
    let gap = 1e-6 * (hi - lo);
    if !(step.abs() <= DEPRESSED_STEP * x.abs() && x > lo + gap && x < hi - gap) {
        return None;
    }
    held_or_polished(c, x, bound, slope, lo, hi, evals)
}

/// Most Halley steps of [`certified_low`] before it leaves the root to the bracketed path.
const CERTIFIED_STEPS: usize = 8;

/// The sign-changing root of `c` on piece `i` of a monotone split (from `knots[i]` to
/// `knots[i + 1]`, with `values` at the knots): an exact zero at the interior knot `knots[i]`
/// is a root when the sign changes through it; otherwise a sign change over the piece is
/// refined. The one rule of [`isolate`] and the quadratic and cubic path.
#[inline(always)]
fn piece_root(c: &[f64], knots: &[f64], values: &[f64], i: usize, evals: &mut u64) -> Option<f64> {
    let (fa, fb) = (values[i], values[i + 1]);
    if fa == 0.0 {
        let before = if i > 0 { values[i - 1] } else { 0.0 };
        return (before != 0.0 && fb != 0.0 && before.signum() != fb.signum()).then(|| knots[i]);
    }
    // An `if`, not `bool::then` with a closure: `refine` must inline into its caller for the
    // quadratic and cubic path's evaluations to unroll.
    if fb != 0.0 && fa.signum() != fb.signum() {
        Some(refine(c, (knots[i], knots[i + 1]), (fa, fb), evals))
    } else {
        None
    }
}

/// The roots of [`real_roots`] into `out`, returning how many.
pub fn roots_in(
    coeffs: &[f64],
    lo: f64,
    hi: f64,
    out: &mut [f64; MAX_DEGREE],
    evals: &mut u64,
) -> Option<usize> {
    let Some(degree) = coeffs.iter().rposition(|&c| c != 0.0) else {
        return Some(0);
    };
    if degree > MAX_DEGREE {
        return None;
    }
    Some(isolate(&coeffs[..=degree], lo, hi, out, evals))
}

/// [`roots_in`] for trimmed coefficients (nonzero leading one, degree at most [`MAX_DEGREE`]).
fn isolate(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE], evals: &mut u64) -> usize {
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
    let mut crit = [0.0; MAX_DEGREE];
    // The critical points only split the interval into monotone pieces: for a quadratic
    // derivative the closed form is exact enough and costs no iteration.
    let nc = if d.len() == 3 {
        quadratic_roots(d, lo, hi, &mut crit)
    } else {
        isolate(d, lo, hi, &mut crit, evals)
    };
    let mut knots = [0.0; MAX_DEGREE + 2];
    let mut values = [0.0; MAX_DEGREE + 2];
    knots[0] = lo;
    knots[1..=nc].copy_from_slice(&crit[..nc]);
    knots[nc + 1] = hi;
    let nk = nc + 2;
    for i in 0..nk {
        values[i] = value(c, knots[i]);
    }
    *evals += nk as u64;
    let mut count = 0;
    for i in 0..nk - 1 {
        if let Some(root) = piece_root(c, &knots[..nk], &values[..nk], i, evals) {
            out[count] = root;
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

/// Whether `coeffs` (lowest degree first, degree below `N`) is certainly positive on
/// `[lo, hi]`. A sufficient test, cheap next to isolating roots: `false` says nothing, and the
/// caller then looks for roots. `false` too past [`MAX_DEGREE`] or for a value that is not
/// finite. Three stages, each tried where the one before cannot decide: on an interval of
/// non-negative `x`, each term at its own least (`positive_by_signs`, one pass; it decides
/// 813 of the 1,000 floor pushes of `examples/per_point.rs`' set); Taylor's formula at `hi`
/// with a bound of the curvature (`positive_by_curvature`, `O(N)` flops), which decides
/// every floor push of the per-point route; the Bernstein form (`positive_by_bernstein`,
/// `O(N^2)`). Only the first is inlined into the caller: the others are one call out of line
/// (inlined, their set-up was hoisted into the per-point route and spilled around it, 39
/// instructions a point more over `examples/per_point.rs`' set).
#[inline]
pub fn positive_on<const N: usize>(coeffs: &[f64; N], lo: f64, hi: f64) -> bool {
    if N == 0 || N > MAX_DEGREE || lo.partial_cmp(&hi).is_none_or(|o| o.is_gt()) {
        return false;
    }
    positive_by_signs(coeffs, lo, hi) || positive_past_signs(coeffs, lo, hi)
}

/// The stages of [`positive_on`] after the first, out of line.
#[cold]
#[inline(never)]
fn positive_past_signs<const N: usize>(coeffs: &[f64; N], lo: f64, hi: f64) -> bool {
    positive_by_curvature(coeffs, lo, hi) || positive_by_bernstein(coeffs, lo, hi)
}

/// The first stage of [`positive_on`] (`lo <= hi`, `coeffs` not empty): for `0 <= lo`, each
/// term `c_j x^j` is least on `[lo, hi]` at `lo` where `c_j >= 0` and at `hi` where `c_j < 0`,
/// so their sum of those leasts bounds `p` from below. It must exceed `d^2`
/// [`BERNSTEIN_MARGIN`] times `S = sum |c_j| hi^j` (`d` the degree), far above the sum's
/// rounding (at most `(d + 2) eps S`), as in `positive_by_curvature`. `false` for `lo < 0` and
/// for any value that is not finite (a NaN fails the comparison).
#[inline]
fn positive_by_signs(c: &[f64], lo: f64, hi: f64) -> bool {
    if lo.is_nan() || lo < 0.0 {
        return false;
    }
    let (mut least, mut size) = (0.0, 0.0);
    let (mut low_power, mut high_power) = (1.0, 1.0);
    for &a in c {
        least += a * if a >= 0.0 { low_power } else { high_power };
        size += a.abs() * high_power;
        low_power *= lo;
        high_power *= hi;
    }
    let d = (c.len() - 1) as f64;
    size.is_finite() && least > BERNSTEIN_MARGIN * d * d * size
}

/// The second stage of [`positive_on`] (`lo <= hi`, `coeffs` not empty): with `t = hi - x` in
/// `[0, h]`, Taylor's formula with Lagrange's remainder gives
/// `p(x) >= p(hi) - p'(hi) t + C t^2 / 2`, `C` a lower bound of `p''` on `[lo, hi]` taken term
/// by term (`j (j - 1) c_j x^(j-2)` is smallest at an end of the interval, or at 0 where the
/// interval holds it). The minimum of that parabola over `[0, h]` (an end, or its vertex when
/// `C > 0` puts it inside) must exceed `d^2` [`BERNSTEIN_MARGIN`] times
/// `S = sum |c_j| M^j`, `M = max(|lo|, |hi|)`, `d` the degree: the rounding of the value, the
/// slope times `h <= 2 M` and the curvature times `h^2 / 2 <= 2 M^2` is below
/// `(2d + 1)(1 + 2d + 2d^2) eps S`, far below that floor for every degree up to [`MAX_DEGREE`].
#[inline]
fn positive_by_curvature(c: &[f64], lo: f64, hi: f64) -> bool {
    let m = lo.abs().max(hi.abs());
    let (mut v, mut d1, mut size) = (0.0, 0.0, 0.0);
    for &a in c.iter().rev() {
        d1 = d1 * hi + v;
        v = v * hi + a;
        size = size * m + a.abs();
    }
    let straddles = (lo < 0.0) & (hi > 0.0);
    let (mut low_power, mut high_power, mut curvature) = (1.0, 1.0, 0.0);
    for (j, &a) in c.iter().enumerate().skip(2) {
        let w = (j * (j - 1)) as f64 * a;
        let least = (w * low_power).min(w * high_power);
        curvature += if straddles { least.min(0.0) } else { least };
        low_power *= lo;
        high_power *= hi;
    }
    let (h, slope) = (hi - lo, -d1);
    let end = v + slope * h + 0.5 * curvature * h * h;
    let least = if (curvature > 0.0) & (slope < 0.0) & (-slope < curvature * h) {
        v - slope * slope / (2.0 * curvature)
    } else {
        v.min(end)
    };
    let d = (c.len() - 1) as f64;
    // A value that is not finite (a NaN is skipped by `min`) fails the sum's test.
    (v + d1 + curvature + end + size).is_finite() && least > BERNSTEIN_MARGIN * d * d * size
}

/// The third stage of [`positive_on`] (`lo <= hi`), by the shifted polynomial
/// `p(lo + h u) = sum a_j u^j` (`h = hi - lo`, `u` in `[0, 1]`): first the bound
/// `a_0 + sum_j min(a_j, 0) > margin`, else every coefficient of its Bernstein form of degree
/// `N - 1` above the margin (the Bernstein form's convex hull holds the graph). The margin is
/// [`BERNSTEIN_MARGIN`] times the same shift done on `|coeffs|` and `|lo|`, which bounds the
/// shift's rounding. Out of line: the per-point route rarely needs it.
#[inline(never)]
fn positive_by_bernstein<const N: usize>(coeffs: &[f64; N], lo: f64, hi: f64) -> bool {
    let d = N - 1;
    // The Taylor shift to `lo` (repeated synthetic division), and its bound on `|coeffs|`.
    let (mut a, mut m) = (*coeffs, coeffs.map(f64::abs));
    for i in 0..d {
        for j in (i..d).rev() {
            a[j] += lo * a[j + 1];
            m[j] += lo.abs() * m[j + 1];
        }
    }
    let h = hi - lo;
    let (mut power, mut size) = (1.0, 0.0);
    for (aj, mj) in a.iter_mut().zip(m) {
        *aj *= power;
        size += mj * power;
        power *= h;
    }
    if !size.is_finite() || size == 0.0 {
        return false;
    }
    let floor = BERNSTEIN_MARGIN * size;
    let falling: f64 = a[1..].iter().map(|&aj| aj.min(0.0)).sum();
    if a[0] + falling > floor {
        return true;
    }
    // b_k = sum_{j <= k} C(k, j) / C(d, j) a_j.
    (0..=d).all(|k| {
        let (mut b, mut ratio) = (0.0, 1.0);
        for (j, aj) in a.iter().enumerate().take(k + 1) {
            b += ratio * aj;
            // C(k, j+1)/C(d, j+1) = C(k, j)/C(d, j) * (k - j)/(d - j).
            if j < k {
                ratio *= (k - j) as f64 / (d - j) as f64;
            }
        }
        b > floor
    })
}

/// How far above zero, relative to the shift of the coefficients' magnitudes, the bound of
/// [`positive_on`] must be: far above the shift's rounding (at most `2 N` units in the last
/// place of that size).
pub const BERNSTEIN_MARGIN: f64 = 1e-12;

/// `p(x)` by Horner's rule, [`model::horner`](crate::model::horner): it lives with the model
/// contract, whose [`Model::lean_start`](crate::model::Model::lean_start) evaluates the
/// separation polynomial at release.
pub use crate::model::horner;

/// `p(x)` with a reliable sign: plain Horner, redone by [`horner_compensated`] when the result
/// is within the plain evaluation's rounding bound `4 (d+1) eps sum |c_i| |x|^i` of zero (the
/// loop of `with_derivatives` without the derivatives, which the knots do not need).
#[inline]
pub fn value(c: &[f64], x: f64) -> f64 {
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

/// `(p(x), p'(x), p''(x))` in one plain Horner pass, with the rounding bound of `p(x)`
/// (`4 (d+1) eps sum |c_i| |x|^i`): below it, the sign of the plain value is not reliable.
#[inline]
fn with_derivatives(c: &[f64], x: f64) -> (f64, f64, f64, f64) {
    let ax = x.abs();
    let (mut v, mut d1, mut d2, mut bound) = (0.0, 0.0, 0.0, 0.0);
    for &a in c.iter().rev() {
        d2 = d2 * x + d1;
        d1 = d1 * x + v;
        v = v * x + a;
        bound = bound * ax + a.abs();
    }
    (v, d1, 2.0 * d2, 4.0 * c.len() as f64 * f64::EPSILON * bound)
}

/// `p(x)` by compensated Horner (Graillat, Langlois, Louvet 2005): as accurate as Horner in
/// twice the working precision, then rounded.
#[inline]
pub fn horner_compensated(coeffs: &[f64], x: f64) -> f64 {
    let Some((&last, rest)) = coeffs.split_last() else {
        return 0.0;
    };
    let xs = split(x);
    let (mut s, mut c) = (last, 0.0f64);
    for &a in rest.iter().rev() {
        let (p, pi) = two_product(s, x, xs);
        let t = p + a;
        let bb = t - p;
        let sigma = (p - (t - bb)) + (a - bb);
        s = t;
        c = c * x + (pi + sigma);
    }
    s + c
}

/// `a` split into two halves of 26 significant bits whose products are exact (Veltkamp).
#[inline]
fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a; // 2^27 + 1
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a * b` rounded and its exact rounding error (Dekker's TwoProduct), with `b` already
/// [`split`]. Falls back to a fused multiply-add where the splitting overflows (`|a|` or `|b|`
/// above about 1e299).
#[inline]
fn two_product(a: f64, b: f64, (bh, bl): (f64, f64)) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let err = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    if err.is_finite() {
        (p, err)
    } else {
        (p, a.mul_add(b, -p))
    }
}

/// The root of `c` in `(a, b)` where it is monotone with `c(a) = fa` of the other sign than
/// `c(b) = fb`: Halley's method on plain Horner values from the secant point, kept inside the
/// shrinking bracket (bisection when a step leaves it or does not halve); once a step is below
/// 1e-7 relative (Halley's error is then far below an ulp) or the value is within its rounding
/// bound, one Newton step on the compensated value lands within an ulp or two.
#[inline(always)]
fn refine(c: &[f64], (mut a, mut b): (f64, f64), (fa, fb): (f64, f64), evals: &mut u64) -> f64 {
    let sa = fa.signum();
    let secant = (a * fb - b * fa) / (fb - fa);
    let mut x = if secant > a && secant < b {
        secant
    } else {
        0.5 * (a + b)
    };
    let mut last_step = f64::INFINITY;
    for _ in 0..MAX_STEPS {
        *evals += 1;
        let (fx, d1, d2, bound) = with_derivatives(c, x);
        if fx.abs() <= bound {
            break;
        }
        if fx.signum() == sa {
            a = x;
        } else {
            b = x;
        }
        let halley = x - 2.0 * fx * d1 / (2.0 * d1 * d1 - fx * d2);
        let step = (halley - x).abs();
        if halley > a && halley < b && step < 0.5 * last_step {
            last_step = step;
            x = halley;
            if step <= 1e-7 * x.abs() {
                break;
            }
        } else {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            last_step = f64::INFINITY;
            x = mid;
        }
    }
    // The last step on the compensated residual, kept in the bracket.
    *evals += 1;
    let fx = horner_compensated(c, x);
    if fx == 0.0 {
        return x;
    }
    let (_, d1, _, _) = with_derivatives(c, x);
    let newton = x - fx / d1;
    // A polishing step only: near a multiple root the derivative vanishes, and a long step
    // would leave the root for a point of the bracket that is none.
    if newton >= a && newton <= b && polish(x, newton) {
        newton
    } else {
        x.clamp(a, b)
    }
}

/// Whether the last Newton step from `x` to `newton` is a polish (below `1e-6` relative, as
/// after a Halley step below `1e-7`), not a jump off a vanishing derivative.
#[inline(always)]
fn polish(x: f64, newton: f64) -> bool {
    (newton - x).abs() <= 1e-6 * x.abs() + f64::MIN_POSITIVE
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::uniform;

    #[test]
    fn roots_of_a_product_are_found_in_order() {
        // (x - 0.1)(x - 0.5)(x - 0.9) = x^3 - 1.5 x^2 + 0.59 x - 0.045
        let c = [-0.045, 0.59, -1.5, 1.0];
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals).unwrap();
        assert_eq!(roots.len(), 3);
        for (r, want) in roots.iter().zip([0.1, 0.5, 0.9]) {
            assert!((r - want).abs() < 4e-16, "{r} vs {want}");
        }
        assert_eq!(largest_root(&c, 0.0, 0.7, &mut evals), Some(Some(roots[1])));
        assert_eq!(largest_root(&c, 0.95, 1.0, &mut evals), Some(None));
        assert!(evals > 0);
    }

    /// A polynomial of `degree` with a random leading coefficient (either sign, 1e-4 to 1e4)
    /// and roots in `[-1, 2]`, and an interval inside `[-0.2, 1.2]` near and across them.
    fn random_from_roots(next: &mut impl FnMut() -> f64, degree: usize) -> (Vec<f64>, f64, f64) {
        let lead = if next() < 0.5 { -1.0 } else { 1.0 } * 10f64.powf(next() * 8.0 - 4.0);
        let mut c = vec![lead];
        for _ in 0..degree {
            // Multiply by (x - r).
            let r = next() * 3.0 - 1.0;
            let mut m = vec![0.0; c.len() + 1];
            for (i, ci) in c.iter().enumerate() {
                m[i + 1] += ci;
                m[i] -= r * ci;
            }
            c = m;
        }
        let lo = next() * 1.4 - 0.2;
        (c, lo, lo + next() * (1.2 - lo))
    }

    /// The least of `c` on `[lo, hi]` as the root isolator sees it: the compensated values at
    /// the ends, at every critical point (the derivative's sign-changing roots) and at every
    /// sign change of `c` itself (a value of about zero there).
    fn least_on(c: &[f64], lo: f64, hi: f64) -> f64 {
        let mut evals = 0;
        let derivative: Vec<f64> = (1..c.len()).map(|j| j as f64 * c[j]).collect();
        let critical = real_roots(&derivative, lo, hi, &mut evals).expect("degree <= 16");
        let roots = real_roots(c, lo, hi, &mut evals).expect("degree <= 16");
        let at = |x: f64| horner_compensated(c, x);
        let least = critical
            .iter()
            .fold(at(lo).min(at(hi)), |m, &x| m.min(at(x)));
        if roots.is_empty() {
            least
        } else {
            least.min(0.0)
        }
    }

    #[test]
    fn the_sign_and_curvature_bounds_never_certify_a_polynomial_that_reaches_zero() {
        // Property: random polynomials of degree 0..=7 built from their roots, and the floor
        // push's shape `c0 - c1 x + c2 x^2 - c4 x^4` (positive coefficients) shifted down so
        // that its least on the interval is within 1e-3 .. 1e-13 of zero, of either sign
        // (touching and just crossing): whenever the first or the second stage says yes, the
        // least value the root isolation finds is positive. Each must also say yes often
        // (cheap bound useful; the curvature's also near zero, where the coarse sign bound
        // rarely can), and never where the shift put the least at or below zero.
        let signs: fn(&[f64], f64, f64) -> bool = positive_by_signs;
        never_certifies_a_zero("signs", [3_000, 0], signs);
        never_certifies_a_zero("curvature", [5_000, 100], positive_by_curvature);
        // A double root far from zero (x - 10)^2, and a touching quartic (x^2 - 1/4)^2 + 0.
        for bound in [positive_by_signs, positive_by_curvature] {
            assert!(!bound(&[100.0, -20.0, 1.0], 9.0, 11.0));
            assert!(!bound(&[0.0625, 0.0, -0.5, 0.0, 1.0], 0.0, 1.0));
            assert!(!bound(&[1.0, f64::NAN], 0.0, 1.0));
            assert!(!bound(&[1.0, 0.0, 0.0, 1e300], 0.0, 1e300));
        }
        // The sign bound needs x >= 0; a positive constant is certified by both.
        assert!(!positive_by_signs(&[2.0, 0.0, 1.0], -1.0, 1.0));
        assert!(positive_by_signs(&[2.0], 0.0, 1.0) && positive_by_curvature(&[2.0], 0.0, 1.0));
    }

    /// The property of the test above for one stage of [`positive_on`], which must say yes more
    /// than `often` times, and at least `hard_often` times near zero.
    fn never_certifies_a_zero(
        stage: &str,
        [often, hard_often]: [usize; 2],
        bound: fn(&[f64], f64, f64) -> bool,
    ) {
        let mut next = uniform(0x5eed_c0de_0042_1234);
        let (mut said_yes, mut hard_yes, mut hard) = (0, 0, 0);
        for case in 0..40_000 {
            let (c, lo, hi) = if case % 2 == 0 {
                random_from_roots(&mut next, (case / 2) % 8)
            } else {
                let scale = 10f64.powf(next() * 12.0 - 6.0);
                let mut c = vec![
                    next() * scale,
                    -next() * 4.0 * scale,
                    next() * 8.0 * scale,
                    0.0,
                    -next() * 4.0 * scale,
                ];
                let lo = next() * 0.9;
                let hi = lo + next() * (1.0 - lo);
                // Put the least within `gap` of zero, below or above it.
                let gap = 10f64.powf(-3.0 - next() * 10.0) * scale;
                let sign = if next() < 0.5 { -1.0 } else { 1.0 };
                c[0] += sign * gap - least_on(&c, lo, hi);
                hard += 1;
                (c, lo, hi)
            };
            let mut fixed = [0.0; 8];
            fixed[..c.len()].copy_from_slice(&c);
            if !(lo <= hi && bound(&fixed, lo, hi)) {
                continue;
            }
            said_yes += 1;
            hard_yes += case % 2;
            let least = least_on(&c, lo, hi);
            assert!(least > 0.0, "{stage}: {c:?} on [{lo}, {hi}]: least {least}");
        }
        assert!(said_yes > often, "{stage}: {said_yes}");
        assert!(
            hard_yes >= hard_often && hard_yes < hard,
            "{stage}: {hard_yes} of {hard}"
        );
    }

    #[test]
    fn a_bernstein_certificate_never_contradicts_the_roots() {
        // Random polynomials of degree 0..=6, with roots placed near and inside the interval:
        // whenever `positive_on` says yes, the polynomial has no root there and is positive at
        // its ends; and away from roots it says yes often enough to save the root search.
        let mut next = uniform(0x0bad_5eed_1234_5678);
        let mut said_yes = 0;
        for case in 0..20_000 {
            let (c, lo, hi) = random_from_roots(&mut next, case % 7);
            let mut fixed = [0.0; 7];
            fixed[..c.len()].copy_from_slice(&c);
            if !positive_on(&fixed, lo, hi) {
                continue;
            }
            said_yes += 1;
            let mut evals = 0;
            let roots = real_roots(&c, lo, hi, &mut evals).expect("degree <= 6");
            assert!(roots.is_empty(), "{c:?} on [{lo}, {hi}]: roots {roots:?}");
            assert!(
                horner(&c, lo) > 0.0 && horner(&c, hi) > 0.0,
                "{c:?} on [{lo}, {hi}]"
            );
        }
        assert!(said_yes > 2_000, "{said_yes}");
        // Exact cases: a positive constant, a line through zero inside, nothing at all.
        assert!(positive_on(&[2.0], -1.0, 1.0));
        assert!(!positive_on(&[0.0, 1.0], -1.0, 1.0));
        assert!(positive_on(&[0.0, 1.0], 0.5, 1.0));
        assert!(!positive_on(&[0.0; 3], 0.0, 1.0));
        // A double root far from zero, where the shift cancels: (x - 10)^2.
        assert!(!positive_on(&[100.0, -20.0, 1.0], 9.0, 11.0));
        assert!(positive_on(&[100.0, -20.0, 1.0], 10.5, 11.0));
        assert!(!positive_on::<0>(&[], 0.0, 1.0));
        assert!(!positive_on(&[1.0, f64::NAN], 0.0, 1.0));
        assert!(!positive_on(&[1.0], 1.0, 0.0));
    }

    #[test]
    fn the_certified_path_agrees_with_the_bracketed_isolator() {
        // Random cubics and quadratics (many with several roots in the interval, double roots
        // and roots at the ends): the largest root is the bracketed isolator's last one.
        let mut next = uniform(0x2545_f491_4f6c_dd1d);
        let mut certified = 0;
        for case in 0..20_000 {
            // Roots r1 <= r2 <= r3 in [-0.5, 1.5]; some repeated, some on an end.
            let mut r = [next() * 2.0 - 0.5, next() * 2.0 - 0.5, next() * 2.0 - 0.5];
            r.sort_by(f64::total_cmp);
            let double = case % 7 == 0;
            match case % 7 {
                0 => r[1] = r[2],
                1 => r[2] = 1.0,
                _ => {}
            }
            let scale = 10f64.powf(next() * 24.0 - 12.0);
            let [a, b, c] = r;
            let cubic = [
                -a * b * c * scale,
                (a * b + b * c + a * c) * scale,
                -(a + b + c) * scale,
                scale,
            ];
            let quadratic = [a * b * scale, -(a + b) * scale, scale, 0.0];
            for coeffs in [cubic, quadratic] {
                let (mut e1, mut e2) = (0, 0);
                let mut out = [0.0; MAX_DEGREE];
                let n = roots_in(&coeffs, 0.0, 1.0, &mut out, &mut e1).expect("degree <= 3");
                let want = (n > 0).then(|| out[n - 1]);
                let got = largest_root(&coeffs, 0.0, 1.0, &mut e2).expect("degree <= 3");
                if certified_low(coeffs, 0.0, 1.0, &mut 0).is_some() {
                    certified += 1;
                }
                // A double root splits by rounding into two or none: both paths must then
                // land on it to about sqrt(eps), or agree that there is none.
                let tol = if double { 2e-7 } else { 1e-12 };
                match (got, want) {
                    (Some(g), Some(w)) => {
                        let e = (g - w).abs() / w.abs().max(1e-3);
                        assert!(e <= tol, "{coeffs:?}: {g} vs {w}");
                        assert!(horner(&coeffs, g).abs() <= 1e-6 * scale, "{coeffs:?}: {g}");
                    }
                    (None, None) => {}
                    _ if double => {}
                    _ => panic!("{coeffs:?}: {got:?} vs {want:?}"),
                }
            }
        }
        // Most cases take the certified path; the rest fall back.
        assert!((10_000..38_000).contains(&certified), "{certified}");
    }

    #[test]
    fn the_certified_root_is_within_two_ulps_of_the_compensated_one() {
        // Where the running bound of the last plain value allows, the certified path keeps
        // Halley's last iterate; elsewhere it polishes it on the compensated value. Either way
        // the root must lie within two ulps (and the final step's rounding) of the root
        // polished twice on the compensated value.
        let mut next = uniform(0x9e37_79b9_7f4a_7c15);
        let mut certified = 0;
        for case in 0..20_000 {
            // The separation cubics' shape (rod on cube, n over 24 decades, a/ell in (0, 1)),
            // and cubics whose root in the interval has another just above the interval (a
            // small slope there: the plain value's bound asks for the compensated step).
            let n = 10f64.powf(next() * 24.0 - 12.0);
            let si = next();
            let (c, hi) = if case % 2 == 0 {
                ([8.0 * (1.0 + n) * si, -12.0 * (1.0 + n), 0.0, 3.0], si)
            } else {
                let root = 0.05 + 0.9 * si;
                let near = 10f64.powf(-1.0 - 4.0 * next());
                let r = [-1.0 - next(), root, root + near];
                let c = [
                    -r[0] * r[1] * r[2],
                    r[0] * r[1] + r[1] * r[2] + r[0] * r[2],
                    -(r[0] + r[1] + r[2]),
                    1.0,
                ];
                (c, root + 0.1 * near)
            };
            let mut evals = 0;
            let Some(x) = certified_low(c, 0.0, hi, &mut evals) else {
                continue;
            };
            let slope = |x: f64| (3.0 * c[3] * x + 2.0 * c[2]) * x + c[1];
            let mut best = x;
            for _ in 0..2 {
                best -= horner_compensated(&c, best) / slope(best);
            }
            assert!(
                (x - best).abs() <= 2.5 * f64::EPSILON * best.abs(),
                "{c:?}: {x} vs {best}"
            );
            certified += 1;
        }
        // Nearly every case is certified, so the bound was tested on them.
        assert!(certified > 15_000, "{certified}");
    }

    #[test]
    fn the_certified_path_leaves_unclear_roots_to_the_bracketed_one() {
        let mut evals = 0;
        // Three roots in (0, 1), the linear part's root (0.0763) near the smallest: Halley
        // finds 0.1, the deflation sees 0.5 and 0.9 above it.
        let c = [-0.045, 0.59, -1.5, 1.0];
        assert_eq!(certified_low(c, 0.0, 1.0, &mut evals), None);
        let root = largest_root(&c, 0.0, 1.0, &mut evals).flatten();
        assert!(root.is_some_and(|r| (r - 0.9).abs() < 1e-15), "{root:?}");
        // A double root at 0.5 beside a simple one at 0.25: near another root, not certified.
        let c = [-0.0625, 0.5, -1.25, 1.0];
        assert_eq!(
            certified_low([c[0], c[1], c[2], c[3]], 0.0, 0.6, &mut evals),
            None
        );
        // The rod on the cube (n = 1, a/ell = 1/2): certified, and a root of the cubic.
        let c = [8.0, -24.0, 0.0, 3.0];
        let root = certified_low(c, 0.0, 0.5, &mut evals).expect("one clear root");
        assert!(horner(&c, root).abs() < 1e-14 && root > 0.33 && root < 0.34);
    }

    /// The root near 1 of `epsilon t^3 - t + 1` by bisection on `[1, 3/2]` (where the cubic
    /// falls from 1 - 1 + epsilon > 0 through its root), to adjacent floats.
    fn depressed_t1(eps: f64) -> f64 {
        let (mut a, mut b) = (1.0f64, 1.5f64);
        while b - a > f64::EPSILON {
            let m = 0.5 * (a + b);
            if horner_compensated(&[1.0, -1.0, 0.0, eps], m) > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }

    #[test]
    fn the_depressed_start_is_within_its_bound() {
        // The interpolant of `t1(u)` over the whole range of `epsilon` (ends included), within
        // 3e-8 of the bisected root; and the bound the Halley step allows is forty times that.
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let eps = DEPRESSED_MAX * i as f64 / 20_000.0;
            let u = (1.0 - 6.75 * eps).sqrt();
            let start = horner(&DEPRESSED_START, u);
            let t1 = depressed_t1(eps);
            worst = worst.max((start - t1).abs() / t1);
        }
        assert!(worst < 3e-8 && worst > 1e-9, "{worst:e}");
        assert!(DEPRESSED_STEP > 30.0 * worst);
        // At the top of the range the roots are 2 and sqrt(5) - 1 (the bounds of the docs).
        assert!((depressed_t1(DEPRESSED_MAX) - (5f64.sqrt() - 1.0)).abs() < 1e-15);
        assert!(horner(&[1.0, -1.0, 0.0, DEPRESSED_MAX], 2.0) == 0.0);
    }

    #[test]
    fn the_depressed_path_agrees_with_the_bracketed_isolator_to_two_ulps() {
        // Depressed cubics of both signs of `L` over 24 decades of scale, with `epsilon` over
        // and past its range and intervals reaching past the next root: where the depressed
        // path answers, its root is the bracketed isolator's largest and within 2.5 ulps of
        // the root polished twice on the compensated value; elsewhere it leaves the root.
        let mut next = uniform(0x5851_f42d_4c95_7f2d);
        let (mut taken, mut left) = (0, 0);
        for case in 0..20_000 {
            let l = (next() + 0.01) * if case % 3 == 0 { -1.0 } else { 1.0 };
            let eps = next() * 0.15;
            let scale = 10f64.powf(next() * 24.0 - 12.0) * if case % 5 == 0 { -1.0 } else { 1.0 };
            // c1 = -scale, c0 = scale L, c3 = eps scale / L^2.
            let c = [scale * l, -scale, 0.0, eps * scale / (l * l)];
            let t1 = depressed_t1(eps.min(4.0 / 27.0));
            let root = l * t1;
            let (lo, hi) = if l > 0.0 {
                (0.5 * root, root * (1.0 + 1.5 * next()))
            } else {
                (root * (1.0 + next()), -root * (2.0 + 2.0 * next()))
            };
            let mut out = [0.0; MAX_DEGREE];
            let n = roots_in(&c, lo, hi, &mut out, &mut 0).expect("a cubic");
            let want = (n > 0).then(|| out[n - 1]);
            match depressed_low(c, lo, hi, &mut 0) {
                Some(x) => {
                    taken += 1;
                    assert!(eps <= DEPRESSED_MAX, "{c:?}");
                    let w = want.expect("the isolator finds the root");
                    assert!(
                        (x - w).abs() <= 4.0 * f64::EPSILON * w.abs(),
                        "{c:?}: {x} vs {w}"
                    );
                    let slope = |x: f64| 3.0 * c[3] * x * x + c[1];
                    let mut best = x;
                    for _ in 0..2 {
                        best -= horner_compensated(&c, best) / slope(best);
                    }
                    let e = (x - best).abs() / (f64::EPSILON * best.abs());
                    assert!(e <= 2.5, "{c:?}: {x} vs {best} ({e} ulps)");
                }
                None => left += 1,
            }
            // Whichever path answers, the largest root is the isolator's.
            let got = largest_root(&c, lo, hi, &mut 0).expect("a cubic");
            match (got, want) {
                (Some(g), Some(w)) => assert!((g - w).abs() <= 1e-12 * w.abs(), "{c:?}"),
                (None, None) => {}
                _ => panic!("{c:?}: {got:?} vs {want:?}"),
            }
        }
        // Both branches are exercised: out-of-range epsilon and intervals past the next root.
        assert!(taken > 8_000 && left > 4_000, "{taken} taken, {left} left");
    }

    #[test]
    fn a_rounded_double_root_gives_no_root_off_it() {
        // (x - 0.167) (x - 0.958)^2 rounded: its derivative vanishes at the double root, where
        // a last Newton step once jumped to points that are no roots (0.79 and 0.98).
        let c = [
            -0.000_137_417_567_662_949_5,
            0.001_109_804_544_969_235_6,
            -0.001_867_390_865_559_559_8,
            0.000_896_306_762_819_939_1,
        ];
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals).expect("a cubic");
        assert!(!roots.is_empty() && (roots[0] - 0.166_973_904_032_291_98).abs() < 1e-15);
        for r in &roots[1..] {
            assert!((r - 0.958_227_19).abs() < 1e-7, "{roots:?}");
        }
    }

    #[test]
    fn double_roots_do_not_count_as_sign_changes() {
        // (x - 0.5)^2 (x - 0.25)
        let c = [-0.0625, 0.5, -1.25, 1.0];
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals).unwrap();
        assert_eq!(roots.len(), 1);
        assert!((roots[0] - 0.25).abs() < 1e-15);
    }

    #[test]
    fn high_degrees_recurse_and_too_high_is_refused() {
        // prod (x - j/10), j = 1..9: degree 9, every root found.
        let mut c = vec![1.0];
        for j in 1..=9 {
            let r = j as f64 / 10.0;
            let mut next = vec![0.0; c.len() + 1];
            for (i, &a) in c.iter().enumerate() {
                next[i + 1] += a;
                next[i] -= r * a;
            }
            c = next;
        }
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals).unwrap();
        assert_eq!(roots.len(), 9);
        for (j, r) in roots.iter().enumerate() {
            // The expanded coefficients are rounded: the roots are that ill-conditioned.
            assert!((r - (j + 1) as f64 / 10.0).abs() < 1e-10, "{roots:?}");
        }
        let mut big = [0.0; MAX_DEGREE + 2];
        big[0] = -0.5;
        big[MAX_DEGREE + 1] = 1.0;
        assert_eq!(real_roots(&big, 0.0, 1.0, &mut evals), None);
    }

    #[test]
    fn two_product_is_exact_and_falls_back_beyond_the_splitting_range() {
        let mut x = 0.123_456_789_f64;
        for _ in 0..1000 {
            x = (x * 7.3 + 0.1).fract();
            let (a, b) = (x * 1e5 - 3.0, (x * 13.1).fract() * 1e-3 + 1.0 / 3.0);
            let (p, e) = two_product(a, b, split(b));
            assert_eq!(p, a * b);
            assert_eq!(e, a.mul_add(b, -p), "a = {a}, b = {b}");
        }
        let (a, b) = (1e305, 0.3);
        let (p, e) = two_product(a, b, split(b));
        assert_eq!((p, e), (a * b, a.mul_add(b, -p)));
    }

    #[test]
    fn compensated_horner_beats_horner_near_a_cluster() {
        // (x - 1)^5 expanded, evaluated close to its quintuple root.
        let c = [-1.0, 5.0, -10.0, 10.0, -5.0, 1.0];
        let x: f64 = 1.0 + 1e-3;
        let exact = 1e-15;
        let err_c = (horner_compensated(&c, x) - exact).abs() / exact;
        assert!(err_c < 1e-3, "compensated error {err_c}");
    }

    #[test]
    fn leading_zeros_and_degenerate_input_are_handled() {
        let mut evals = 0;
        assert_eq!(
            real_roots(&[1.0, -2.0, 0.0, 0.0], 0.0, 1.0, &mut evals),
            Some(vec![0.5])
        );
        assert_eq!(real_roots(&[0.0, 0.0], 0.0, 1.0, &mut evals), Some(vec![]));
        assert_eq!(real_roots(&[1.0, -2.0], 1.0, 0.0, &mut evals), Some(vec![]));
        assert_eq!(
            real_roots(&[1.0, -2.0], f64::NAN, 1.0, &mut evals),
            Some(vec![])
        );
    }
}
