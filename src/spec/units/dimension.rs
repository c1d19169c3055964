//! The dimension algebra: exact rational exponents ([`Exponent`]), units as exponents of kg,
//! m and s ([`Unit`]) with their products, quotients and powers, the canonical form they print
//! in, and [`UnitError`], the error every unit operation (reading, inferring) returns.

use crate::spec::expr::{FUNCTIONS, MAX_DEPTH, gcd};
use std::fmt;

/// An exact rational exponent `num/den`: `den >= 1` and the fraction is reduced, so that equal
/// exponents compare equal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Exponent {
    num: i64,
    den: i64,
}

impl Exponent {
    /// Zero.
    pub const ZERO: Exponent = Exponent { num: 0, den: 1 };
    /// One.
    pub const ONE: Exponent = Exponent { num: 1, den: 1 };
    /// One half (the power of a square root).
    pub(super) const HALF: Exponent = Exponent { num: 1, den: 2 };

    /// The integer `n`.
    pub const fn integer(n: i64) -> Exponent {
        Exponent { num: n, den: 1 }
    }

    /// `num/den` reduced, with a positive denominator; `None` when `den` is zero or the reduced
    /// fraction does not fit `i64` (`i64::MIN` over `-1`).
    pub fn new(num: i64, den: i64) -> Option<Exponent> {
        Exponent::from_i128(i128::from(num), i128::from(den))
    }

    /// `num/den` reduced; `None` when `den` is zero or the reduced fraction does not fit `i64`.
    pub(super) fn from_i128(num: i128, den: i128) -> Option<Exponent> {
        if den == 0 {
            return None;
        }
        let (num, den) = if den < 0 {
            (num.checked_neg()?, den.checked_neg()?)
        } else {
            (num, den)
        };
        let g = gcd(num.checked_abs()?, den);
        Some(Exponent {
            num: i64::try_from(num / g).ok()?,
            den: i64::try_from(den / g).ok()?,
        })
    }

    /// The numerator (the sign of the exponent).
    pub fn num(self) -> i64 {
        self.num
    }

    /// The denominator, at least 1.
    pub fn den(self) -> i64 {
        self.den
    }

    /// Whether the exponent is zero.
    pub fn is_zero(self) -> bool {
        self.num == 0
    }

    /// Whether the exponent is a whole number.
    pub fn is_integer(self) -> bool {
        self.den == 1
    }

    /// `self + other`, `None` on overflow.
    pub fn checked_add(self, other: Exponent) -> Option<Exponent> {
        let (a, b) = (i128::from(self.num), i128::from(self.den));
        let (c, d) = (i128::from(other.num), i128::from(other.den));
        let num = a.checked_mul(d)?.checked_add(c.checked_mul(b)?)?;
        Exponent::from_i128(num, b.checked_mul(d)?)
    }

    /// `self - other`, `None` on overflow.
    pub fn checked_sub(self, other: Exponent) -> Option<Exponent> {
        self.checked_add(other.checked_neg()?)
    }

    /// `-self`, `None` on overflow (`i64::MIN`).
    pub fn checked_neg(self) -> Option<Exponent> {
        Some(Exponent {
            num: self.num.checked_neg()?,
            den: self.den,
        })
    }

    /// `self * other`, `None` on overflow.
    pub fn checked_mul(self, other: Exponent) -> Option<Exponent> {
        let num = i128::from(self.num).checked_mul(i128::from(other.num))?;
        let den = i128::from(self.den).checked_mul(i128::from(other.den))?;
        Exponent::from_i128(num, den)
    }
}

impl fmt::Display for Exponent {
    /// `2`, `-1`, `1/2`, `-3/2`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// A physical unit: the exponents of kilogram, metre and second, exact rationals.
///
/// Angles are dimensionless (`rad` is [`Unit::DIMENSIONLESS`]), so a `Unit` cannot tell an
/// angle from a ratio, nor a torque (N m) from an energy (J): both are kg m^2 s^-2 and print as
/// `J` (see its `Display`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Unit {
    kg: Exponent,
    m: Exponent,
    s: Exponent,
}

/// Where an operation on units overflowed, for [`UnitError::Overflow`].
pub(super) fn overflow(what: String) -> UnitError {
    UnitError::Overflow { what }
}

impl Unit {
    /// A pure number (and an angle in radians): `1`.
    pub const DIMENSIONLESS: Unit = Unit::integers(0, 0, 0);
    /// The kilogram.
    pub const KILOGRAM: Unit = Unit::integers(1, 0, 0);
    /// The metre.
    pub const METRE: Unit = Unit::integers(0, 1, 0);
    /// The second.
    pub const SECOND: Unit = Unit::integers(0, 0, 1);
    /// The newton, kg m s^-2.
    pub const NEWTON: Unit = Unit::integers(1, 1, -2);
    /// The joule (and the newton metre of a torque), kg m^2 s^-2.
    pub const JOULE: Unit = Unit::integers(1, 2, -2);

    /// The unit kg^`kg` m^`m` s^`s`.
    pub const fn new(kg: Exponent, m: Exponent, s: Exponent) -> Unit {
        Unit { kg, m, s }
    }

    /// The unit kg^`kg` m^`m` s^`s` with whole exponents.
    pub const fn integers(kg: i64, m: i64, s: i64) -> Unit {
        Unit::new(
            Exponent::integer(kg),
            Exponent::integer(m),
            Exponent::integer(s),
        )
    }

    /// The exponent of the kilogram.
    pub fn kg(self) -> Exponent {
        self.kg
    }

    /// The exponent of the metre.
    pub fn m(self) -> Exponent {
        self.m
    }

    /// The exponent of the second.
    pub fn s(self) -> Exponent {
        self.s
    }

    /// Whether this is [`Unit::DIMENSIONLESS`] (a pure number or an angle).
    pub fn is_dimensionless(self) -> bool {
        self == Unit::DIMENSIONLESS
    }

    /// The unit of a product, `self * other`; an error when an exponent overflows.
    pub fn checked_mul(self, other: Unit) -> Result<Unit, UnitError> {
        self.combine(other, Exponent::checked_add)
            .ok_or_else(|| overflow(format!("the product of {self} and {other}")))
    }

    /// The unit of a quotient, `self / other`; an error when an exponent overflows.
    pub fn checked_div(self, other: Unit) -> Result<Unit, UnitError> {
        self.combine(other, Exponent::checked_sub)
            .ok_or_else(|| overflow(format!("the quotient of {self} by {other}")))
    }

    /// The unit of `self^power`; an error when an exponent overflows.
    pub fn checked_pow(self, power: Exponent) -> Result<Unit, UnitError> {
        let pow = |e: Exponent| e.checked_mul(power);
        (|| Some(Unit::new(pow(self.kg)?, pow(self.m)?, pow(self.s)?)))()
            .ok_or_else(|| overflow(format!("{self} to the power {power}")))
    }

    fn combine(self, other: Unit, op: fn(Exponent, Exponent) -> Option<Exponent>) -> Option<Unit> {
        Some(Unit::new(
            op(self.kg, other.kg)?,
            op(self.m, other.m)?,
            op(self.s, other.s)?,
        ))
    }

    /// The factors of this unit written as `named^a kg^b m^c s^d` (zero exponents left out),
    /// with `named` one of the derived units and `a` the whole exponent of the kilogram, or
    /// without a derived unit; the cheapest to read of these, base units first on a tie.
    fn canonical_factors(self) -> Vec<(&'static str, Exponent)> {
        let base = [("kg", self.kg), ("m", self.m), ("s", self.s)];
        let mut best: Vec<(&'static str, Exponent)> =
            base.into_iter().filter(|f| !f.1.is_zero()).collect();
        if !self.kg.is_integer() || self.kg.is_zero() {
            return best;
        }
        let a = self.kg;
        for (name, unit) in DERIVED {
            let rest = (|| {
                let m = self.m.checked_sub(unit.m.checked_mul(a)?)?;
                let s = self.s.checked_sub(unit.s.checked_mul(a)?)?;
                Some([(name, a), ("m", m), ("s", s)])
            })();
            let Some(rest) = rest else { continue };
            let candidate: Vec<(&'static str, Exponent)> =
                rest.into_iter().filter(|f| !f.1.is_zero()).collect();
            if reading_cost(&candidate) < reading_cost(&best) {
                best = candidate;
            }
        }
        best
    }
}

/// The derived units [`Display`](fmt::Display) for [`Unit`] may write, each with one kilogram.
const DERIVED: [(&str, Unit); 4] = [
    ("N", Unit::NEWTON),
    ("J", Unit::JOULE),
    ("W", Unit::integers(1, 2, -3)),
    ("Pa", Unit::integers(1, -1, -2)),
];

/// How hard a list of factors is to read: two for each factor and one more for each written
/// power (a factor below the line with exponent -1 is written without one: `N/m`).
fn reading_cost(factors: &[(&str, Exponent)]) -> usize {
    factors
        .iter()
        .map(|(_, e)| {
            if e.num().unsigned_abs() == 1 && e.is_integer() {
                2
            } else {
                3
            }
        })
        .sum()
}

/// Writes `name` with the power `e` (`m`, `m^2`, `s^-1`, `m^(1/2)`, `s^(-1/2)`).
pub(super) fn write_factor(f: &mut fmt::Formatter<'_>, name: &str, e: Exponent) -> fmt::Result {
    if e == Exponent::ONE {
        write!(f, "{name}")
    } else if e.is_integer() {
        write!(f, "{name}^{e}")
    } else {
        write!(f, "{name}^({e})")
    }
}

impl fmt::Display for Unit {
    /// A canonical SI form that [`Unit::parse`] reads back to the same unit:
    ///
    /// - `1` for a dimensionless unit (an angle in radians too);
    /// - base units in the order kg, m, s, with positive powers before a `/` and one factor with
    ///   a negative power after it: `m/s`, `m/s^2`, `kg m^2`, `1/s`, `kg/m^3`;
    /// - a derived unit (`N`, `J`, `W`, `Pa`, raised to the kilogram's whole exponent) in front
    ///   when that is shorter to read: `N`, `N/m`, `N s`, `J s`, `Pa s`, `N^2`, `1/N`. An energy
    ///   and a torque are both `J` (kg m^2 s^-2): a `Unit` cannot tell them apart, and `J` is
    ///   the one canonical form (a spec may still write `N m`, which parses to the same unit);
    /// - otherwise every factor with its signed power, `kg^a m^b s^c` (`m^-1 s^-1`,
    ///   `kg^(1/2) m^(-3/2)`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let factors = self.canonical_factors();
        let above: Vec<_> = factors.iter().filter(|x| x.1.num() > 0).collect();
        let below: Vec<_> = factors.iter().filter(|x| x.1.num() < 0).collect();
        let below_neg = match below.as_slice() {
            [(name, e)] => e.checked_neg().map(|e| (*name, e)),
            _ => None,
        };
        let write_all = |f: &mut fmt::Formatter<'_>, list: &[&(&str, Exponent)]| {
            for (i, (name, e)) in list.iter().enumerate() {
                if i > 0 {
                    f.write_str(" ")?;
                }
                write_factor(f, name, *e)?;
            }
            Ok(())
        };
        if factors.is_empty() {
            return f.write_str("1");
        }
        if below.is_empty() {
            return write_all(f, &above);
        }
        if let Some((name, e)) = below_neg {
            if above.is_empty() {
                f.write_str("1")?;
            } else {
                write_all(f, &above)?;
            }
            f.write_str("/")?;
            return write_factor(f, name, e);
        }
        let all: Vec<_> = factors.iter().collect();
        write_all(f, &all)
    }
}

/// The unit of the Lagrange multiplier of a constraint `gap = 0` whose gap is in `gap`: energy
/// over gap, J / `gap`, since the multiplier times a virtual change of the gap is virtual work.
///
/// A gap in `m` gives a force in `N`; a dimensionless gap (an angle, say) gives a torque in
/// N m, which [`Unit`] writes `J`. An error only when an exponent overflows (a unit no spec
/// writes).
pub fn conjugate_force_unit(gap: Unit) -> Result<Unit, UnitError> {
    Unit::JOULE.checked_div(gap)
}

/// Why a unit string could not be read or an expression has no consistent unit.
///
/// Positions in unit strings are 1-based characters; expressions are quoted as infix text
/// ([`Expr::to_infix`](crate::spec::expr::Expr::to_infix)) and their units written as [`Unit`]
/// displays them, `dimensionless` for `1`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UnitError {
    /// An empty (or blank) unit string.
    #[error("empty unit: write `1` for a dimensionless quantity")]
    Empty,
    /// A unit string that does not follow the grammar of [`Unit::parse`].
    #[error("cannot read unit `{text}` at character {}: {problem}", .offset.saturating_add(1))]
    Syntax {
        /// The unit string.
        text: String,
        /// 0-based character where the problem is.
        offset: usize,
        /// What is wrong.
        problem: String,
    },
    /// A symbol that is not a known unit.
    #[error(
        "unknown unit `{symbol}` in `{text}` at character {}: {}",
        .offset.saturating_add(1),
        unknown_unit_hint(.symbol)
    )]
    UnknownUnit {
        /// The unit string.
        text: String,
        /// 0-based character where the symbol starts.
        offset: usize,
        /// The symbol.
        symbol: String,
    },
    /// An SI base unit that mechanics does not need (`A`, `K`, `mol`, `cd`).
    #[error(
        "unit `{symbol}` in `{text}` at character {}: only the base units of mechanics \
         (kg, m, s) are supported, not {}",
        .offset.saturating_add(1),
        base_unit_name(.symbol)
    )]
    UnsupportedBaseUnit {
        /// The unit string.
        text: String,
        /// 0-based character where the symbol starts.
        offset: usize,
        /// The symbol.
        symbol: String,
    },
    /// An exponent that does not fit the exact `i64` fractions of [`Exponent`].
    #[error("unit exponents overflow in {what}")]
    Overflow {
        /// The operation that overflowed.
        what: String,
    },
    /// A symbol the lookup given to [`unit_of`](super::unit_of) has no unit for.
    #[error("unknown symbol `{name}`: no unit is known for it")]
    UnknownSymbol {
        /// The symbol.
        name: String,
    },
    /// A function that specs do not have, or a call with the wrong number of arguments.
    #[error(
        "unknown function `{name}` with {arity} argument(s) (the functions are {})",
        function_list()
    )]
    UnknownFunction {
        /// The function's name.
        name: String,
        /// Its number of arguments.
        arity: usize,
    },
    /// Two terms of a sum or difference with different units (boxed: the largest error).
    #[error(transparent)]
    Mismatch(Box<SumMismatch>),
    /// A nonzero number added to (or subtracted from) a quantity with a unit.
    #[error(
        "in `{sum}`: {}: a bare number is dimensionless, and only `0` can be added to a \
         quantity with a unit (multiply the number by a parameter to give it one)",
        bare_number(.number, .other, .other_unit, *.subtract, *.number_first)
    )]
    BareNumber {
        /// The whole sum.
        sum: String,
        /// The number (a term without symbols): with its sign when it comes first, without it
        /// when it is added or subtracted.
        number: String,
        /// The term with a unit: without its sign when it is added or subtracted.
        other: String,
        /// Its unit.
        other_unit: Unit,
        /// Whether the later of the two is subtracted.
        subtract: bool,
        /// Whether the number comes first (`1 - x1` rather than `x1 - 1`).
        number_first: bool,
    },
    /// A function of a quantity with a unit where the function needs a pure number.
    #[error(
        "in `{call}`: `{function}` needs a dimensionless argument (an angle in rad or a ratio), \
         but `{argument}` is in {}",
        .unit
    )]
    Argument {
        /// The call.
        call: String,
        /// The function.
        function: String,
        /// The argument.
        argument: String,
        /// Its unit.
        unit: Unit,
    },
    /// A power of a quantity with a unit whose exponent is not a constant fraction.
    #[error(
        "in `{power}`: `{base}` is in {}, so its exponent must be a constant fraction such as \
         `2` or `1/2`, not `{exponent}`",
        .base_unit
    )]
    Exponent {
        /// The power.
        power: String,
        /// Its base.
        base: String,
        /// The base's unit.
        base_unit: Unit,
        /// Its exponent.
        exponent: String,
    },
    /// An exponent with a unit.
    #[error("in `{power}`: the exponent `{exponent}` is in {}; an exponent must be dimensionless", .unit)]
    DimensionedExponent {
        /// The power.
        power: String,
        /// Its exponent.
        exponent: String,
        /// The exponent's unit.
        unit: Unit,
    },
    /// An expression whose unit is not the one it should have ([`expect_unit`](super::expect_unit)).
    #[error("`{expr}` is {} but should be {}", phrase(.found), phrase(.expected))]
    WrongUnit {
        /// The expression.
        expr: String,
        /// Its unit.
        found: Unit,
        /// The unit it should have.
        expected: Unit,
    },
    /// An expression tree deeper than any parsed expression can be.
    #[error("the expression is nested more than {MAX_DEPTH} deep")]
    TooDeep,
}

/// Two terms of a sum or difference with different units: [`UnitError::Mismatch`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "in `{sum}`: cannot {} `{right}` ({}) {} `{left}` ({}): the terms of a sum must have the \
     same unit",
    if *.subtract { "subtract" } else { "add" },
    describe(.right_unit),
    if *.subtract { "from" } else { "to" },
    describe(.left_unit)
)]
pub struct SumMismatch {
    /// The whole sum.
    pub sum: String,
    /// The term whose unit the sum has so far (with its sign).
    pub left: String,
    /// Its unit.
    pub left_unit: Unit,
    /// The term that differs, without its sign.
    pub right: String,
    /// Its unit.
    pub right_unit: Unit,
    /// Whether `right` is subtracted.
    pub subtract: bool,
}

/// `m`, or `dimensionless` for `1`.
fn describe(u: &Unit) -> String {
    if u.is_dimensionless() {
        "dimensionless".into()
    } else {
        u.to_string()
    }
}

/// `the number `1` is added to `x1` (m)`, or `x1` (m) subtracted from the number that comes
/// first.
fn bare_number(
    number: &str,
    other: &str,
    other_unit: &Unit,
    subtract: bool,
    number_first: bool,
) -> String {
    let verb = if subtract {
        "subtracted from"
    } else {
        "added to"
    };
    let other = format!("`{other}` ({})", describe(other_unit));
    if number_first {
        format!("{other} is {verb} the number `{number}`")
    } else {
        format!("the number `{number}` is {verb} {other}")
    }
}

/// `in m`, or `dimensionless` for `1`.
fn phrase(u: &Unit) -> String {
    if u.is_dimensionless() {
        "dimensionless".into()
    } else {
        format!("in {u}")
    }
}

fn function_list() -> String {
    let names: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
    names.join(", ")
}

/// The name of an SI base unit besides kg, m and s; any other symbol (a [`UnitError`] built by
/// hand) quoted as it is.
fn base_unit_name(symbol: &str) -> String {
    match symbol {
        "A" => "the ampere".into(),
        "K" => "the kelvin".into(),
        "mol" => "the mole".into(),
        "cd" => "the candela".into(),
        other => format!("`{other}`"),
    }
}

fn unknown_unit_hint(symbol: &str) -> String {
    let known = "the units are kg, m, s, rad, sr, N, J, W, Pa, Hz and 1";
    match symbol {
        "deg" => format!("degrees are not coherent SI units; write angles in rad ({known})"),
        "g" => format!("write masses in kg ({known})"),
        "C" | "V" | "Ohm" | "T" | "F" | "H" | "S" | "Wb" | "lm" | "lx" => {
            format!("it needs a base unit besides kg, m and s ({known})")
        }
        _ => format!("{known}; prefixed units (mm, ms, kN) are not supported"),
    }
}
