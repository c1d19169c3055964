//! Stage 6b of the derivation, the partial derivatives behind the fast path's sensitivities:
//! the separation condition's in the angle and in every parameter, the energy integral's
//! `theta_dot^2` and the start's `sin(theta_i)` in every parameter, and the fall polynomial's
//! coefficients in every parameter (what the time integrand needs), all over the parameters,
//! `rc_s = sin(theta)` and `rc_c = cos(theta)`.
//!
//! The separation condition `sum_j c_j s^j = 0` holds at the separation for any nonzero factor,
//! so it is divided by the coefficient `c_k` that leaves the parameters in the fewest of the
//! ratios `c_j / c_k`. The implicit-function theorem's `d theta_sep/dp = -F_p / F_theta` is the
//! same for every factor, but its numerator is then free of the cancellation the plain
//! coefficients have: for the rod on the cube, `d/dn` of `3 s^3 - 12 (1 + n) s + 8 r (1 + n)` is
//! `8 r - 12 s`, which vanishes as `n` grows, where `d/dn` of the ratio form is
//! `s^3 / (4 (1 + n)^2)`.

use super::algebra::to_expr;
use super::cas::{self, A};
use super::expr::Expr;
use super::reduction::{over_parameters, plain_constants};
use super::types::{DeriveError, Partials, Reduction};

/// The partial derivatives of a fast path in each of `params` (in order).
pub fn derive(r: &Reduction, params: &[String]) -> Result<Partials, DeriveError> {
    let consts = plain_constants(&r.constants)?;
    let plain = |e: &Expr| cas::together(&over_parameters(&cas::atom(e), &consts));
    let each = |a: &A, what: &str| -> Result<Vec<Expr>, DeriveError> {
        (params.iter())
            .map(|p| to_expr(&cas::together(&cas::d(a, p)), what))
            .collect()
    };
    let separation = match r.separation() {
        Some(sep) => {
            let coefficients: Vec<A> = sep.coefficients.iter().map(plain).collect();
            separation_partials(&coefficients, params)?
        }
        None => Vec::new(),
    };
    let theta_dot_sq = each(&plain(&r.theta_dot_sq), "d(theta_dot^2)/dp")?;
    let start = (consts.iter())
        .find(|(s, _)| s == "rc_si")
        .map(|(_, v)| v.clone())
        .ok_or_else(|| DeriveError {
            field: Vec::new(),
            message: "the reduction has no start sine `rc_si`".into(),
        })?;
    let start_sine = each(&start, "d(sin theta_i)/dp")?;
    let mut fall = Vec::new();
    if let Some(coefficients) = &r.fall {
        let plain_fall: Vec<A> = coefficients.iter().map(plain).collect();
        for p in params {
            for c in &plain_fall {
                fall.push(to_expr(&cas::together(&cas::d(c, p)), "dP_j/dp")?);
            }
        }
    }
    Ok(Partials {
        separation,
        theta_dot_sq,
        start_sine,
        fall,
    })
}

/// `[dF/dtheta, dF/dp_1, ...]` of the separation condition `F = sum_j (c_j / c_k) s^j` over
/// `rc_s`, `rc_c`, with `c_k` the coefficient that leaves the parameters in the fewest ratios.
fn separation_partials(coefficients: &[A], params: &[String]) -> Result<Vec<Expr>, DeriveError> {
    let ratios = |k: usize| -> Vec<A> {
        (coefficients.iter())
            .map(|c| cas::together(&(c.clone() / coefficients[k].clone())))
            .collect()
    };
    let dependence = |ratios: &[A]| -> usize {
        (params.iter())
            .map(|p| {
                ratios
                    .iter()
                    .filter(|c| !cas::is_zero(&cas::d(c, p)))
                    .count()
            })
            .sum()
    };
    let Some(k) = (0..coefficients.len())
        .filter(|&k| !cas::is_zero(&coefficients[k]))
        .min_by_key(|&k| dependence(&ratios(k)))
    else {
        return Err(DeriveError {
            field: Vec::new(),
            message: "the separation polynomial has no nonzero coefficient".into(),
        });
    };
    let ratios = ratios(k);
    let s = cas::var("rc_s");
    let power = |j: usize| -> A { (0..j).fold(cas::num(1), |acc, _| acc * s.clone()) };
    let d_s = (ratios.iter().enumerate().skip(1)).fold(cas::num(0), |acc, (j, c)| {
        acc + c.clone() * cas::num(j as i64) * power(j - 1)
    });
    let mut out = vec![to_expr(&(d_s * cas::var("rc_c")), "dF/dtheta")?];
    for p in params {
        let d_p = (ratios.iter().enumerate())
            .fold(cas::num(0), |acc, (j, c)| acc + cas::d(c, p) * power(j));
        out.push(to_expr(&cas::together(&d_p), "dF/dp")?);
    }
    Ok(out)
}
