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
pub fn largest_root(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<Option<f64>> {
    let degree = coeffs.iter().rposition(|&c| c != 0.0).unwrap_or(0);
    if (2..=3).contains(&degree) && lo < hi {
        return Some(largest_low(&coeffs[..=degree], lo, hi, evals));
    }
    let mut out = [0.0; MAX_DEGREE];
    let n = roots_in(coeffs, lo, hi, &mut out, evals)?;
    Some((n > 0).then(|| out[n - 1]))
}

/// [`largest_root`] for a quadratic or cubic (trimmed, `lo < hi`): the critical points by the
/// quadratic formula, then only the highest piece with a sign change is refined.
fn largest_low(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    // As a cubic (a quadratic's leading coefficient 0) of known length, so that every
    // evaluation below unrolls.
    let mut c4 = [0.0; 4];
    c4[..coeffs.len()].copy_from_slice(coeffs);
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

/// `p(x)` by Horner's rule (coefficients lowest degree first), with separate multiplies and
/// adds (without a hardware FMA target feature `f64::mul_add` is a library call several times
/// slower than the arithmetic).
#[inline]
pub fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

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
    if newton >= a && newton <= b {
        newton
    } else {
        x.clamp(a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
