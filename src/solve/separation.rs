//! Separation: the root of a model's separation polynomial in `s = sin(theta)` where the rod
//! first loses contact coming down from `theta_i`, found to full `f64` precision; and, for a
//! model whose contact force's zero is no polynomial root or whose contact has an edge, the
//! first sign change of the reduced contact force (or of the edge margin) as a function of the
//! angle fallen, bracketed on a grid and refined by [`roots::illinois`].
//!
//! Real roots in an interval are isolated generically (any degree) by recursive derivative
//! isolation: the sign-changing roots of `p'` split the interval into pieces on which `p` is
//! monotone, so each piece holds at most one root, found by bracketed Newton with a bisection
//! safeguard. Signs are taken from a compensated Horner evaluation (twice the working precision),
//! so a root is located to within an ulp or two whenever the polynomial is well conditioned,
//! whatever the scale of its coefficients (e.g. `n = m2/m1` from 1e-12 to 1e12).

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::roots::{self, changes_sign};
use crate::system::System;

/// Grid cells over the fall, uniform in `u = sqrt(delta)`, on which a numeric root is
/// bracketed (the first cell whose ends differ in sign; a pair of roots inside one cell, a
/// touch without a crossing, is not seen).
pub const BRACKET_CELLS: usize = 256;

/// Where a phase with a contact separates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separation {
    /// `sin(theta_sep)`.
    pub sin_theta: f64,
    /// `theta_sep` (rad).
    pub theta: f64,
    /// `delta_sep = theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// The outcome of looking for a separation between `theta_i` and the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeparationOutcome {
    /// The contact force vanishes at this angle.
    Separates(Separation),
    /// The polynomial has no sign change between the floor and `theta_i`: contact is kept.
    NoSeparationBeforeFloor,
}

impl SeparationOutcome {
    /// The separation, if there is one.
    pub fn separation(&self) -> Option<Separation> {
        match self {
            SeparationOutcome::Separates(s) => Some(*s),
            SeparationOutcome::NoSeparationBeforeFloor => None,
        }
    }
}

/// The separation of a system: the largest sign-changing root of its separation polynomial in
/// `(sin(end_angle), sin(theta_i))`, i.e. the first met coming down from `theta_i`; or, without
/// a polynomial, the first zero of the reduced contact force.
pub fn separation(sys: &System, work: &mut Work) -> Result<SeparationOutcome, SolveError> {
    let info = sys.info();
    let Some(contact) = info.contact else {
        return Err(SolveError::NoContact { model: info.name });
    };
    if !sys.layout().polynomial_separation {
        let force = |sys: &System, delta: f64| sys.forces(delta)[contact.force];
        return first_zero(sys, force, work);
    }
    let (coeffs, lo, hi) = setup(sys)?;
    let roots = real_roots(&coeffs, lo, hi, &mut work.polynomial_evals);
    Ok(match roots.last() {
        Some(&s) => SeparationOutcome::Separates(at_sine(sys, s)),
        None => SeparationOutcome::NoSeparationBeforeFloor,
    })
}

/// Where the contact runs off its edge: the first zero of the edge margin, which on the fast
/// path depends on the angle alone (the derivation checks it).
pub fn edge(sys: &System, work: &mut Work) -> Result<SeparationOutcome, SolveError> {
    let margin = |sys: &System, delta: f64| sys.contact_edge(&sys.full_state(0.0, delta, 0.0));
    first_zero(sys, margin, work)
}

/// The first sign change of `f(delta)` coming down from the start: bracketed on
/// [`BRACKET_CELLS`] cells uniform in `sqrt(delta)` (fine near the start, where the fall is
/// slow), then refined to adjacent floats. Each evaluation counts as a polynomial evaluation.
fn first_zero(
    sys: &System,
    f: impl Fn(&System, f64) -> f64,
    work: &mut Work,
) -> Result<SeparationOutcome, SolveError> {
    let end = sys.delta_to_floor();
    let model = sys.info().name;
    let mut value = |delta: f64| -> Result<f64, SolveError> {
        work.polynomial_evals += 1;
        let v = f(sys, delta);
        if v.is_nan() {
            return Err(SolveError::NonFinite {
                model,
                what: "contact force or edge margin",
                delta,
                value: v,
            });
        }
        Ok(v)
    };
    // At the start itself the contact holds (a force of zero there is no separation yet).
    let u_end = end.sqrt();
    let mut a = (0.0, value(0.0)?);
    if a.1 == 0.0 {
        let tiny = (u_end / BRACKET_CELLS as f64 * 1e-6).powi(2);
        a = (tiny, value(tiny)?);
    }
    for i in 1..=BRACKET_CELLS {
        let u = u_end * i as f64 / BRACKET_CELLS as f64;
        let delta = if i == BRACKET_CELLS { end } else { u * u };
        // A model may be singular at the floor itself (a cylinder's tangent point runs off to
        // infinity as theta -> 0): no value there means no zero met before it.
        if i == BRACKET_CELLS && f(sys, delta).is_nan() {
            break;
        }
        let b = (delta, value(delta)?);
        if changes_sign(a.1, b.1) {
            let delta = roots::illinois(&mut value, a, b)?;
            let theta = sys.theta_initial() - delta;
            return Ok(SeparationOutcome::Separates(Separation {
                sin_theta: theta.sin(),
                theta,
                delta,
            }));
        }
        a = b;
    }
    Ok(SeparationOutcome::NoSeparationBeforeFloor)
}

/// The paper's approximation: the root of the polynomial with its terms above degree 1 dropped.
pub fn linearised_separation(sys: &System) -> Result<SeparationOutcome, SolveError> {
    let (coeffs, lo, hi) = setup(sys)?;
    let (c0, c1) = (coeffs[0], coeffs.get(1).copied().unwrap_or(0.0));
    if c1 == 0.0 {
        return Ok(SeparationOutcome::NoSeparationBeforeFloor);
    }
    let s = -c0 / c1;
    Ok(if s > lo && s < hi {
        SeparationOutcome::Separates(at_sine(sys, s))
    } else {
        SeparationOutcome::NoSeparationBeforeFloor
    })
}

/// Coefficients (checked) and the open interval `(sin(end_angle), sin(theta_i))`.
fn setup(sys: &System) -> Result<(Vec<f64>, f64, f64), SolveError> {
    let info = sys.info();
    if info.contact.is_none() {
        return Err(SolveError::NoContact { model: info.name });
    }
    let coeffs = sys.separation_coefficients();
    if coeffs.iter().any(|c| !c.is_finite()) || coeffs.iter().all(|&c| c == 0.0) {
        return Err(SolveError::BadPolynomial {
            model: info.name,
            coefficients: coeffs,
        });
    }
    let hi = sys.reduced(0.0).sin;
    let lo = sys.end_angle().sin();
    if !hi.is_finite() {
        return Err(SolveError::NonFinite {
            model: info.name,
            what: "sin(theta_i)",
            delta: 0.0,
            value: hi,
        });
    }
    Ok((coeffs, lo, hi))
}

/// The angle of a root in `s`: `theta = asin(s)`, `delta = theta_i - theta`.
fn at_sine(sys: &System, s: f64) -> Separation {
    let theta = s.asin();
    Separation {
        sin_theta: s,
        theta,
        delta: sys.theta_initial() - theta,
    }
}

/// `p(x)` by Horner's rule (coefficients lowest degree first), with separate multiplies and
/// adds (without a hardware FMA target feature `f64::mul_add` is a library call several times
/// slower than the arithmetic).
pub fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

/// `p(x)` by compensated Horner (Graillat, Langlois, Louvet 2005): as accurate as Horner in
/// twice the working precision, then rounded.
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

/// Every real root of `p` in the open interval `(lo, hi)` at which `p` changes sign, ascending,
/// each to full precision. Roots of even multiplicity (touching zero) are not reported.
/// Coefficients are lowest degree first; `evals` counts evaluations of `p` and its derivatives.
pub fn real_roots(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Vec<f64> {
    let degree = match coeffs.iter().rposition(|&c| c != 0.0) {
        Some(d) => d,
        None => return Vec::new(),
    };
    let c = &coeffs[..=degree];
    if degree == 0 || lo.is_nan() || hi.is_nan() || lo >= hi {
        return Vec::new();
    }
    if degree == 1 {
        let x = -c[0] / c[1];
        return if x > lo && x < hi {
            vec![x]
        } else {
            Vec::new()
        };
    }
    let deriv: Vec<f64> = c
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, &a)| i as f64 * a)
        .collect();
    let mut knots = vec![lo];
    knots.extend(real_roots(&deriv, lo, hi, evals));
    knots.push(hi);
    let values: Vec<f64> = knots
        .iter()
        .map(|&x| {
            *evals += 1;
            horner_compensated(c, x)
        })
        .collect();
    let mut roots = Vec::new();
    for i in 0..knots.len() - 1 {
        let (fa, fb) = (values[i], values[i + 1]);
        if fa == 0.0 && i > 0 {
            // An exact zero at a critical point: a sign change through it is a root.
            let before = values[i - 1];
            if before != 0.0 && fb != 0.0 && before.signum() != fb.signum() {
                roots.push(knots[i]);
            }
            continue;
        }
        if fa != 0.0 && fb != 0.0 && fa.signum() != fb.signum() {
            roots.push(refine(c, &deriv, knots[i], knots[i + 1], fa, evals));
        }
    }
    roots
}

/// The root of `p` in `(a, b)` where `p` is monotone and changes sign (`fa = p(a)`), to within
/// an ulp: Newton steps kept inside the bracket, bisection when they leave it or stall.
fn refine(c: &[f64], deriv: &[f64], mut a: f64, mut b: f64, fa: f64, evals: &mut u64) -> f64 {
    let sa = fa.signum();
    let mut x = 0.5 * (a + b);
    let mut last_step = f64::INFINITY;
    for _ in 0..4000 {
        *evals += 1;
        let fx = horner_compensated(c, x);
        if fx == 0.0 {
            return x;
        }
        let left_of_root = fx.signum() == sa;
        if left_of_root {
            a = x;
        } else {
            b = x;
        }
        let mid = 0.5 * (a + b);
        if mid <= a || mid >= b {
            // `a` and `b` are adjacent floats: return the one closer to the root.
            *evals += 2;
            let (pa, pb) = (horner_compensated(c, a), horner_compensated(c, b));
            return if pa.abs() <= pb.abs() { a } else { b };
        }
        *evals += 1;
        let newton = x - fx / horner(deriv, x);
        let step = (newton - x).abs();
        // Newton is kept while it stays in the bracket and converges (each step at most half the
        // previous one); otherwise bisect. Once its step is below an ulp or two it has converged
        // from one side: probe just across the root to close the bracket.
        let tiny = 2.0 * f64::EPSILON * x.abs();
        x = if step < tiny {
            let base = newton.clamp(a, b);
            let probe = if left_of_root {
                base + tiny
            } else {
                base - tiny
            };
            if probe > a && probe < b { probe } else { mid }
        } else if newton > a && newton < b && step < 0.5 * last_step {
            last_step = step;
            newton
        } else {
            last_step = f64::INFINITY;
            mid
        };
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_a_product_are_found_in_order() {
        // (x - 0.1)(x - 0.5)(x - 0.9) = x^3 - 1.5 x^2 + 0.59 x - 0.045
        let c = [-0.045, 0.59, -1.5, 1.0];
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals);
        assert_eq!(roots.len(), 3);
        for (r, want) in roots.iter().zip([0.1, 0.5, 0.9]) {
            assert!((r - want).abs() < 4e-16, "{r} vs {want}");
        }
        assert!(evals > 0);
    }

    #[test]
    fn double_roots_do_not_count_as_sign_changes() {
        // (x - 0.5)^2 (x - 0.25)
        let c = [-0.0625, 0.5, -1.25, 1.0];
        let mut evals = 0;
        let roots = real_roots(&c, 0.0, 1.0, &mut evals);
        assert_eq!(roots.len(), 1);
        assert!((roots[0] - 0.25).abs() < 1e-15);
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
        assert!(real_roots(&[1.0, -2.0, 0.0, 0.0], 0.0, 1.0, &mut evals) == vec![0.5]);
        assert!(real_roots(&[0.0, 0.0], 0.0, 1.0, &mut evals).is_empty());
        assert!(real_roots(&[1.0, -2.0], 1.0, 0.0, &mut evals).is_empty());
    }
}
