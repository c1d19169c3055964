//! The checker of spec expressions' units: [`unit_of`] infers the unit of an [`Expr`] from its
//! symbols' units, [`expect_unit`] compares it with the one a field needs.

use super::dimension::{Exponent, SumMismatch, Unit, UnitError, overflow};
use crate::spec::expr::{Expr, FUNCTIONS, MAX_DEPTH, gcd};

/// The unit of `expr`, with `symbols` giving the unit of each symbol it mentions.
///
/// - A number is dimensionless; a sum's terms must have one unit, which the sum has, except
///   that a term that is the constant `0` goes with any unit (`x1 + 0`). A nonzero term
///   without symbols (`1`, `2*3`) added to a quantity with a unit is an error of its own
///   ([`UnitError::BareNumber`]). `0` alone is reported dimensionless: compare it with an
///   expected unit through [`expect_unit`], which accepts it for any unit.
/// - Products and quotients multiply and divide units.
/// - A power `b^e`: when `b` has a unit, `e` must be a constant exact fraction (`2`, `-1`,
///   `1/2`, `0.5`: a float exponent must be a fraction with a power of two below the line),
///   and the exponents of `b` are multiplied by it; when `b` is dimensionless, `e` may be any
///   dimensionless expression and the power is dimensionless.
/// - `sqrt` halves the exponents; `sin`, `cos`, `tan`, `exp`, `log` need a dimensionless
///   argument and give a dimensionless result; `asin`, `acos`, `atan` need a dimensionless
///   argument and give an angle, which is dimensionless.
///
/// Errors: a symbol `symbols` does not know, a function not in [`FUNCTIONS`] or with another
/// number of arguments, the inconsistencies above, exponents that overflow and a tree deeper
/// than [`MAX_DEPTH`]. Subtraction (`a - b`, stored as `a + (-1)*b`) and division (`a / b`,
/// stored as `a * b^-1`) are named as such in messages.
pub fn unit_of(expr: &Expr, symbols: &dyn Fn(&str) -> Option<Unit>) -> Result<Unit, UnitError> {
    infer(expr, symbols, 1)
}

/// Checks that `expr` is in `expected`: [`unit_of`], except that an expression that is the
/// constant `0` (a point on the floor, `[x1, 0]`; a start at rest) is in every unit.
pub fn expect_unit(
    expr: &Expr,
    symbols: &dyn Fn(&str) -> Option<Unit>,
    expected: Unit,
) -> Result<(), UnitError> {
    let found = unit_of(expr, symbols)?;
    if found == expected || is_zero_constant(expr) {
        Ok(())
    } else {
        Err(UnitError::WrongUnit {
            expr: expr.to_infix(),
            found,
            expected,
        })
    }
}

/// Whether `e` has no symbols and evaluates to exactly zero.
fn is_zero_constant(e: &Expr) -> bool {
    e.symbols().is_empty() && e.eval(&|_| None) == 0.0
}

fn infer(
    e: &Expr,
    symbols: &dyn Fn(&str) -> Option<Unit>,
    depth: usize,
) -> Result<Unit, UnitError> {
    if depth > MAX_DEPTH {
        return Err(UnitError::TooDeep);
    }
    match e {
        Expr::Rational(..) | Expr::Float(_) => Ok(Unit::DIMENSIONLESS),
        Expr::Sym(name) if name == crate::spec::expr::PI => Ok(Unit::DIMENSIONLESS),
        Expr::Sym(name) => {
            symbols(name).ok_or_else(|| UnitError::UnknownSymbol { name: name.clone() })
        }
        Expr::Add(terms) => sum_unit(e, terms, symbols, depth),
        Expr::Mul(factors) => {
            let mut unit = Unit::DIMENSIONLESS;
            for f in factors {
                let u = infer(f, symbols, depth + 1)?;
                unit = unit
                    .checked_mul(u)
                    .map_err(|_| overflow(format!("`{}`", e.to_infix())))?;
            }
            Ok(unit)
        }
        Expr::Pow(base, exponent) => power_unit(e, base, exponent, symbols, depth),
        Expr::Fun(name, args) => {
            let arg = match (FUNCTIONS.iter().any(|(f, _)| f == name), args.as_slice()) {
                (true, [arg]) => arg,
                _ => {
                    return Err(UnitError::UnknownFunction {
                        name: name.clone(),
                        arity: args.len(),
                    });
                }
            };
            let u = infer(arg, symbols, depth + 1)?;
            if name == "sqrt" {
                return u
                    .checked_pow(Exponent::HALF)
                    .map_err(|_| overflow(format!("`{}`", e.to_infix())));
            }
            if !u.is_dimensionless() {
                return Err(UnitError::Argument {
                    call: e.to_infix(),
                    function: name.clone(),
                    argument: arg.to_infix(),
                    unit: u,
                });
            }
            Ok(Unit::DIMENSIONLESS)
        }
    }
}

fn sum_unit(
    e: &Expr,
    terms: &[Expr],
    symbols: &dyn Fn(&str) -> Option<Unit>,
    depth: usize,
) -> Result<Unit, UnitError> {
    // The first term that is not the constant 0 sets the unit.
    let mut reference: Option<(&Expr, Unit)> = None;
    for t in terms {
        let u = infer(t, symbols, depth + 1)?;
        if is_zero_constant(t) {
            continue;
        }
        let Some((first, first_unit)) = reference else {
            reference = Some((t, u));
            continue;
        };
        if u == first_unit {
            continue;
        }
        let (subtract, magnitude) = t.split_sign();
        let sum = e.to_infix();
        let first_is_number = first.symbols().is_empty();
        if first_is_number || t.symbols().is_empty() {
            let (number, other, other_unit) = if first_is_number {
                (first.to_infix(), magnitude.to_infix(), u)
            } else {
                (magnitude.to_infix(), first.to_infix(), first_unit)
            };
            return Err(UnitError::BareNumber {
                sum,
                number,
                other,
                other_unit,
                subtract,
                number_first: first_is_number,
            });
        }
        return Err(UnitError::Mismatch(Box::new(SumMismatch {
            sum,
            left: first.to_infix(),
            left_unit: first_unit,
            right: magnitude.to_infix(),
            right_unit: u,
            subtract,
        })));
    }
    Ok(reference.map_or(Unit::DIMENSIONLESS, |r| r.1))
}

fn power_unit(
    e: &Expr,
    base: &Expr,
    exponent: &Expr,
    symbols: &dyn Fn(&str) -> Option<Unit>,
    depth: usize,
) -> Result<Unit, UnitError> {
    let base_unit = infer(base, symbols, depth + 1)?;
    let exponent_unit = infer(exponent, symbols, depth + 1)?;
    if base_unit.is_dimensionless() {
        if !exponent_unit.is_dimensionless() {
            return Err(UnitError::DimensionedExponent {
                power: e.to_infix(),
                exponent: exponent.to_infix(),
                unit: exponent_unit,
            });
        }
        return Ok(Unit::DIMENSIONLESS);
    }
    let Some((num, den)) = constant(exponent) else {
        return Err(UnitError::Exponent {
            power: e.to_infix(),
            base: base.to_infix(),
            base_unit,
            exponent: exponent.to_infix(),
        });
    };
    Exponent::from_i128(num, den)
        .ok_or_else(|| overflow(format!("`{}`", e.to_infix())))
        .and_then(|p| {
            base_unit
                .checked_pow(p)
                .map_err(|_| overflow(format!("`{}`", e.to_infix())))
        })
}

/// The exact value `(num, den)` of a constant expression made of fractions, floats that are
/// exact binary fractions, sums, products and whole powers; `None` for anything else (symbols,
/// functions, other floats) and on overflow. The denominator is nonzero, not always positive.
fn constant(e: &Expr) -> Option<(i128, i128)> {
    let reduce = |n: i128, d: i128| -> Option<(i128, i128)> {
        if d == 0 {
            return None;
        }
        let g = gcd(n.checked_abs()?, d.checked_abs()?);
        Some((n / g, d / g))
    };
    match e {
        Expr::Rational(n, d) => reduce(*n, *d),
        Expr::Float(x) => float_fraction(*x),
        Expr::Add(v) => v.iter().try_fold((0i128, 1i128), |(a, b), t| {
            let (c, d) = constant(t)?;
            reduce(
                a.checked_mul(d)?.checked_add(c.checked_mul(b)?)?,
                b.checked_mul(d)?,
            )
        }),
        Expr::Mul(v) => v.iter().try_fold((1i128, 1i128), |(a, b), t| {
            let (c, d) = constant(t)?;
            reduce(a.checked_mul(c)?, b.checked_mul(d)?)
        }),
        Expr::Pow(b, x) => {
            let (n, d) = constant(b)?;
            let (p, q) = constant(x)?;
            if q.checked_abs()? != 1 {
                return None;
            }
            let p = p.checked_mul(q)?;
            if p.unsigned_abs() > 128 {
                return None;
            }
            let (mut rn, mut rd) = (1i128, 1i128);
            for _ in 0..p.unsigned_abs() {
                rn = rn.checked_mul(n)?;
                rd = rd.checked_mul(d)?;
            }
            if p < 0 {
                reduce(rd, rn)
            } else {
                reduce(rn, rd)
            }
        }
        Expr::Sym(_) | Expr::Fun(..) => None,
    }
}

/// A finite float as an exact fraction with a power of two up to 2^30 below the line (`0.5`,
/// `-1.25`, `3.0`); `None` for other floats (`0.1` is not exactly a tenth).
fn float_fraction(x: f64) -> Option<(i128, i128)> {
    if !x.is_finite() {
        return None;
    }
    let mut scaled = x;
    let mut den: i128 = 1;
    for _ in 0..=30 {
        if scaled.fract() == 0.0 && scaled.abs() < 1e18 {
            // A whole float below 1e18 converts to i128 exactly.
            let num = scaled as i128;
            let g = gcd(num.abs(), den);
            return Some((num / g, den / g));
        }
        scaled *= 2.0;
        den *= 2;
    }
    None
}
