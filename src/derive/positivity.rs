//! A derivation-time proof that a closed contact's push stays positive over the whole phase,
//! for every admissible parameter: the force polynomial `P(s)` in `s = sin(theta)` (its sign
//! the force's) is bounded below by a quadratic `a + b s + c s^2` on `0 <= s <= sin(theta_i)
//! <= 1`, whose positivity on `[0, 1]` is then read off signs of polynomials in the positive
//! parameters, term by term. Where it succeeds the per-point route need not certify that push
//! point by point; where it does not, nothing is claimed and the runtime certifies as before.
//! [`release_proof`] shows the same way that the first contact pushes at release.
//!
//! The bound, monomial by monomial (`r` a positive number times positive parameters):
//! - `-r si^i ci^j s^k >= -r s^min(k, 2)`: `si = sin(theta_i)` and `ci = cos(theta_i)` lie in
//!   `[0, 1]`, and `s^k <= s^2` for `k >= 2` on `[0, 1]`;
//! - `+r si^i s^k >= +r s^(i + k)` (`s <= si` on the phase), kept where `i + k <= 2`;
//! - `+r ci^j ...` with `j > 0`, and `+r s^k` with `k > 2`, are at least 0 and dropped.
//!
//! Then `Q(s) = a + b s + c s^2 > 0` on `[0, 1]` by one of: `a > 0` with `b, c >= 0` (signs);
//! `a > 0`, `c <= 0` and `a + b + c > 0` (concave: least at an end); `a > 0` and
//! `4 a c - b^2 > 0` (no real root). Each sign is that of an expanded polynomial all of whose
//! terms have it, the parameters being positive. The test is sufficient, not necessary.

use super::algebra::{coefficients_in_s, to_expr};
use super::cas;
use super::expr::Expr;
use super::types::{DeriveError, ProofStep, PushProof, ReleaseProof};

/// The spec's symbols for `sin(theta_i)` and `cos(theta_i)` in a force polynomial's
/// coefficients, both in `[0, 1]` on a phase that starts between flat and upright.
const SIN_START: &str = "rc_si";
const COS_START: &str = "rc_ci";

/// The proof that the polynomial with `coefficients` (in `s`, lowest degree first, over the
/// parameters and `rc_si`, `rc_ci`, the start's sine and cosine) is positive for
/// `0 <= s <= sin(theta_i)` and every admissible parameter, the symbols in `pos` being
/// strictly positive; `None` where the test above cannot show it (a symbol of unknown sign, a
/// term that is no monomial, a bound too weak). The caller must know that `s >= 0` on the
/// phase (its end angle is at least 0).
pub fn push_proof(coefficients: &[Expr], pos: &[String]) -> Result<Option<PushProof>, DeriveError> {
    let mut bound: [Vec<Expr>; 3] = Default::default();
    for (k, c) in coefficients.iter().enumerate() {
        let expanded = to_expr(&cas::expand(&cas::atom(c)), "push coefficient")?;
        let terms = match expanded {
            Expr::Add(v) => v,
            e if e.is_zero() => Vec::new(),
            e => vec![e],
        };
        for term in terms {
            let Some((negative, sin_power, cos_power, magnitude)) = monomial(&term, pos) else {
                return Ok(None);
            };
            let degree = if negative {
                k.min(2)
            } else if cos_power > 0 {
                continue;
            } else {
                k + sin_power
            };
            if let Some(slot) = bound.get_mut(degree) {
                slot.push(if negative {
                    Expr::Mul(vec![Expr::int(-1), magnitude])
                } else {
                    magnitude
                });
            }
        }
    }
    let sum = |v: Vec<Expr>| -> Result<Expr, DeriveError> {
        let total = v
            .into_iter()
            .fold(cas::num(0), |acc, t| acc + cas::atom(&t));
        to_expr(&cas::expand(&total), "push bound")
    };
    let [a, b, c] = bound;
    let (a, b, c) = (sum(a)?, sum(b)?, sum(c)?);
    if !all_terms_positive(&a, pos) {
        return Ok(None);
    }
    let at_least_zero = |e: &Expr| e.is_zero() || all_terms_positive(e, pos);
    let negated_c = to_expr(&cas::expand(&(cas::num(0) - cas::atom(&c))), "push bound")?;
    let step = if at_least_zero(&b) && at_least_zero(&c) {
        ProofStep::Signs
    } else if at_least_zero(&negated_c) {
        let (aa, ba, ca) = (cas::atom(&a), cas::atom(&b), cas::atom(&c));
        let end = to_expr(&cas::expand(&(aa + ba + ca)), "push bound at s = 1")?;
        if !all_terms_positive(&end, pos) {
            return Ok(None);
        }
        ProofStep::Ends(end)
    } else {
        let (aa, ba, ca) = (cas::atom(&a), cas::atom(&b), cas::atom(&c));
        let four = cas::num(4);
        let disc = cas::expand(&(four * aa * ca - ba.clone() * ba));
        let disc = to_expr(&disc, "push bound's discriminant")?;
        if !all_terms_positive(&disc, pos) {
            return Ok(None);
        }
        ProofStep::Discriminant(disc)
    };
    Ok(Some(PushProof {
        bound: [a, b, c],
        step,
    }))
}

/// The proof that the polynomial with `coefficients` (as for [`push_proof`]) is positive at
/// `s = sin(theta_i)` for `0 < sin(theta_i) <= 1` and every admissible parameter: its value
/// there, a polynomial in `sin(theta_i)`, is `sin(theta_i)^m R`, and [`push_proof`] shows `R`
/// positive on `[0, 1]` (with no `sin(theta_i)` left in `R`'s coefficients, its bound holds
/// there). `None` where that cannot be shown.
pub fn release_proof(
    coefficients: &[Expr],
    pos: &[String],
) -> Result<Option<ReleaseProof>, DeriveError> {
    let sin_start = cas::var(SIN_START);
    let mut power = cas::num(1);
    let mut at_start = cas::num(0);
    for c in coefficients {
        at_start += cas::atom(c) * power.clone();
        power *= sin_start.clone();
    }
    // The value at release as a polynomial in `sin(theta_i)`, written in `rc_s`.
    let at_start = cas::subs_var(&cas::expand(&at_start), SIN_START, &cas::var("rc_s"));
    let Some(mut factor) = coefficients_in_s(&at_start, "push at release")? else {
        return Ok(None);
    };
    let power = factor.iter().take_while(|c| c.is_zero()).count();
    factor.drain(..power);
    if factor.is_empty() {
        return Ok(None);
    }
    let Some(proof) = push_proof(&factor, pos)? else {
        return Ok(None);
    };
    let mut polynomial = cas::num(0);
    for (k, c) in factor.iter().enumerate() {
        let power = (0..k).fold(cas::num(1), |acc, _| acc * cas::var("rc_s"));
        polynomial += cas::atom(c) * power;
    }
    let polynomial = to_expr(&cas::expand(&polynomial), "push at release")?;
    Ok(Some(ReleaseProof {
        power,
        polynomial,
        proof,
    }))
}

/// Whether every term of the expanded `e` is a positive monomial (so `e > 0` wherever the
/// symbols in `pos` are; an empty sum is not).
fn all_terms_positive(e: &Expr, pos: &[String]) -> bool {
    let terms = match e {
        Expr::Add(v) => v.as_slice(),
        e => std::slice::from_ref(e),
    };
    !e.is_zero()
        && terms
            .iter()
            .all(|t| matches!(monomial(t, pos), Some((false, 0, 0, _))))
}

/// A term of an expanded coefficient as `(negative, i, j, m)`: `+-m si^i ci^j` with `m` a
/// product of positive numbers and integer powers of positive symbols; `None` for anything
/// else (a symbol of unknown sign, a function, a fractional power).
fn monomial(term: &Expr, pos: &[String]) -> Option<(bool, usize, usize, Expr)> {
    let (negative, magnitude) = term.split_sign();
    let factors = match magnitude {
        Expr::Mul(v) => v,
        e => vec![e],
    };
    let (mut sin_power, mut cos_power) = (0usize, 0usize);
    let mut kept = Vec::new();
    for f in factors {
        let (name, power) = match &f {
            Expr::Rational(n, d) if *n > 0 && *d > 0 => {
                kept.push(f);
                continue;
            }
            Expr::Float(x) if *x > 0.0 => {
                kept.push(f);
                continue;
            }
            Expr::Sym(s) => (s.as_str(), 1),
            Expr::Pow(base, exp) => match (base.as_ref(), exp.as_integer()) {
                (Expr::Sym(s), Some(n)) if n > 0 => (s.as_str(), usize::try_from(n).ok()?),
                _ => return None,
            },
            _ => return None,
        };
        match name {
            SIN_START => sin_power += power,
            COS_START => cos_power += power,
            _ if pos.iter().any(|p| p == name) => kept.push(f),
            _ => return None,
        }
    }
    let magnitude = match kept.len() {
        0 => Expr::int(1),
        1 => kept.pop()?,
        _ => Expr::Mul(kept),
    };
    Some((negative, sin_power, cos_power, magnitude))
}
