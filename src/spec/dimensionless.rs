//! Dimensionless groups: the results a dimensionless block may name, the monomials a group
//! must be, and the parameter each group is solved for.

use super::expr::{Expr, gcd};
use super::schema::GroupSpec;

/// The results a dimensionless block can hold besides the forces (whose names are the spec's).
pub const DIMENSIONLESS_RESULTS: &[&str] = &["theta_dot_sq", "theta_ddot", "separation_condition"];

/// The factors of a monomial `c * p1^e1 * p2^e2 ...` with `c > 0` rational and rational
/// exponents, in the order written; `None` for anything else (a sum, a function, a negative
/// coefficient).
pub fn monomial(e: &Expr) -> Option<Vec<(String, Expr)>> {
    fn walk(e: &Expr, power: (i128, i128), out: &mut Vec<(String, (i128, i128))>) -> bool {
        match e {
            Expr::Rational(n, _) => *n > 0,
            Expr::Sym(s) => {
                match out.iter_mut().find(|(name, _)| name == s) {
                    Some((_, p)) => {
                        let sum = (p.0.checked_mul(power.1))
                            .zip(power.0.checked_mul(p.1))
                            .and_then(|(a, b)| a.checked_add(b));
                        let (Some(n), Some(d)) = (sum, p.1.checked_mul(power.1)) else {
                            return false;
                        };
                        let g = gcd(n.abs(), d.abs());
                        *p = (n / g, d / g);
                    }
                    None => out.push((s.clone(), power)),
                }
                true
            }
            Expr::Mul(v) => v.iter().all(|f| walk(f, power, out)),
            Expr::Pow(b, x) => match **x {
                Expr::Rational(n, d) => match (power.0.checked_mul(n), power.1.checked_mul(d)) {
                    (Some(pn), Some(pd)) => {
                        let g = gcd(pn.abs(), pd.abs());
                        walk(b, (pn / g, pd / g), out)
                    }
                    _ => false,
                },
                _ => false,
            },
            _ => false,
        }
    }
    let mut out = Vec::new();
    walk(&e.tidy(), (1, 1), &mut out).then(|| {
        out.into_iter()
            .filter(|(_, p)| p.0 != 0)
            .map(|(s, (n, d))| (s, Expr::Rational(n, d)))
            .collect()
    })
}

/// The parameter each group is solved for (see [`GroupSpec`]), in the groups' order; `Err`
/// with the index of the first group that has none.
pub fn solved_parameters(groups: &[GroupSpec]) -> Result<Vec<String>, usize> {
    let mut solved: Vec<String> = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let factors = Expr::parse(&g.expr.text())
            .ok()
            .and_then(|e| monomial(&e))
            .ok_or(i)?;
        let p = factors
            .into_iter()
            .find(|(p, x)| *x == Expr::int(1) && !solved.contains(p))
            .ok_or(i)?;
        solved.push(p.0);
    }
    Ok(solved)
}
