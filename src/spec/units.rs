//! Physical units of spec expressions: SI unit strings (`kg`, `m/s^2`, `N m`) parsed into
//! exponents of kg, m and s, printed back in a canonical form, and inferred for an [`Expr`] with
//! a clear error when the expression is not dimensionally consistent.
//!
//! Radians (and steradians) are dimensionless, as in SI: `rad` parses to the dimensionless unit
//! [`Unit::DIMENSIONLESS`], so an angle and a pure number have the same [`Unit`]. The
//! trigonometric functions take a dimensionless argument (an angle in radians or a ratio), and
//! the inverse ones give an angle, which is dimensionless too.
//!
//! Only the base units that mechanics uses are supported: kg, m and s. The other SI base units
//! (A, K, mol, cd) are refused by [`Unit::parse`] with a message saying so.
//!
//! ```
//! use rodcube::spec::{expr::Expr, units::{Unit, unit_of, conjugate_force_unit}};
//!
//! let metre = Unit::parse("m")?;
//! let symbols = |name: &str| match name {
//!     "x1" | "x2" | "ell" => Some(metre),
//!     "theta" => Some(Unit::parse("rad").ok()?),
//!     _ => None,
//! };
//! let gap = Expr::parse("x2 - x1 - ell*cos(theta)").expect("parses");
//! let unit = unit_of(&gap, &symbols)?;
//! assert_eq!(unit.to_string(), "m");
//! assert_eq!(conjugate_force_unit(unit)?.to_string(), "N");
//!
//! let bad = Expr::parse("x1 + theta").expect("parses");
//! let err = unit_of(&bad, &symbols).unwrap_err();
//! assert!(err.to_string().contains("cannot add `theta` (dimensionless) to `x1` (m)"));
//! # Ok::<(), rodcube::spec::units::UnitError>(())
//! ```

use super::expr::{Expr, FUNCTIONS, MAX_DEPTH, gcd};
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
    fn from_i128(num: i128, den: i128) -> Option<Exponent> {
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
fn overflow(what: String) -> UnitError {
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

    /// Parses an SI unit string as specs write it: a product of unit symbols, each with an
    /// optional power, and optionally one `/` followed by one factor or a parenthesized product.
    ///
    /// Symbols: `kg`, `m`, `s`; `rad` and `sr` (dimensionless); `N`, `J`, `W`, `Pa`, `Hz`; `1`
    /// (dimensionless, alone or as the numerator of `1/s`). Products are written with spaces,
    /// `*` or `·` (`N m`, `kg*m^2`); powers with `^` and an integer or a parenthesized fraction
    /// (`m^2`, `s^-1`, `m^(1/2)`, `s^(-3/2)`). Examples: `m/s^2`, `N/m`, `kg m^2`, `rad/s`,
    /// `kg/(m s^2)`.
    ///
    /// Refused, with the character where the problem is: an empty string, unknown symbols
    /// (prefixed units such as `mm` or `ms`, degrees, grams), the base units mechanics does not
    /// use (`A`, `K`, `mol`, `cd`), numbers other than `1`, powers without `^` (`m2`), more than
    /// one `/`, and `/` followed by a product without parentheses (`N/m s`, which readers take
    /// either way).
    pub fn parse(text: &str) -> Result<Unit, UnitError> {
        if text.trim().is_empty() {
            return Err(UnitError::Empty);
        }
        let mut p = UnitParser {
            text,
            c: text.chars().collect(),
            i: 0,
        };
        p.ws();
        let numerator = p.product()?;
        p.ws();
        let mut unit = numerator;
        if p.peek() == Some('/') {
            p.i += 1;
            p.ws();
            let denominator = if p.peek() == Some('(') {
                p.i += 1;
                p.ws();
                let d = p.product()?;
                p.ws();
                if p.peek() != Some(')') {
                    return Err(p.syntax("missing `)` after the denominator".into()));
                }
                p.i += 1;
                d
            } else {
                p.factor()?
            };
            unit = numerator
                .checked_div(denominator)
                .map_err(|_| p.too_large())?;
            p.ws();
            match p.peek() {
                Some('/') => {
                    return Err(p.syntax(
                        "a second `/`: write one `/` with a parenthesized denominator \
                         (`kg/(m s^2)`) or negative powers (`kg m^-1 s^-2`)"
                            .into(),
                    ));
                }
                Some(c) if c.is_alphanumeric() || is_product_sign(c) => {
                    return Err(p.syntax(
                        "only one factor may follow `/` without parentheses: write `N/(m s)` \
                         or `N m^-1 s^-1`"
                            .into(),
                    ));
                }
                _ => {}
            }
        }
        p.ws();
        match p.peek() {
            None => Ok(unit),
            Some(')') => Err(p.syntax("`)` without a matching `(`".into())),
            Some(c) => Err(p.syntax(format!("unexpected `{c}`"))),
        }
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
fn write_factor(f: &mut fmt::Formatter<'_>, name: &str, e: Exponent) -> fmt::Result {
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
/// ([`Expr::to_infix`]) and their units written as [`Unit`] displays them, `dimensionless` for
/// `1`.
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
    /// A symbol the lookup given to [`unit_of`] has no unit for.
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
    /// An expression whose unit is not the one it should have ([`expect_unit`]).
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

fn base_unit_name(symbol: &str) -> &'static str {
    match symbol {
        "A" => "the ampere",
        "K" => "the kelvin",
        "mol" => "the mole",
        _ => "the candela",
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

fn is_product_sign(c: char) -> bool {
    matches!(c, '*' | '·' | '⋅')
}

struct UnitParser<'a> {
    text: &'a str,
    c: Vec<char>,
    i: usize,
}

impl UnitParser<'_> {
    fn peek(&self) -> Option<char> {
        self.c.get(self.i).copied()
    }

    /// Skips whitespace; whether there was any.
    fn ws(&mut self) -> bool {
        let start = self.i;
        while self.peek().is_some_and(char::is_whitespace) {
            self.i += 1;
        }
        self.i > start
    }

    fn syntax(&self, problem: String) -> UnitError {
        self.syntax_at(self.i, problem)
    }

    fn syntax_at(&self, offset: usize, problem: String) -> UnitError {
        UnitError::Syntax {
            text: self.text.to_string(),
            offset,
            problem,
        }
    }

    fn too_large(&self) -> UnitError {
        overflow(format!("unit `{}`", self.text))
    }

    /// Factors joined by whitespace or a product sign; stops before `/`, `)` or the end.
    fn product(&mut self) -> Result<Unit, UnitError> {
        let mut unit = self.factor()?;
        loop {
            let spaced = self.ws();
            match self.peek() {
                Some(c) if is_product_sign(c) => {
                    self.i += 1;
                    self.ws();
                }
                Some(c) if spaced && (c.is_alphanumeric() || c == '(') => {}
                _ => return Ok(unit),
            }
            let f = self.factor()?;
            unit = unit.checked_mul(f).map_err(|_| self.too_large())?;
        }
    }

    /// A symbol or `1`, with an optional power.
    fn factor(&mut self) -> Result<Unit, UnitError> {
        let start = self.i;
        let base = match self.peek() {
            Some(c) if c.is_alphabetic() => {
                while self.peek().is_some_and(char::is_alphabetic) {
                    self.i += 1;
                }
                let symbol: String = self.c.get(start..self.i).unwrap_or(&[]).iter().collect();
                if let Some(c) = self.peek().filter(|c| c.is_ascii_digit()) {
                    return Err(self.syntax(format!("write powers with `^`: `{symbol}^{c}`")));
                }
                let superscript = self.peek().and_then(|c| {
                    let i = "⁰¹²³⁴⁵⁶⁷⁸⁹⁻".chars().position(|x| x == c)?;
                    "0123456789-".chars().nth(i)
                });
                if let Some(c) = superscript {
                    return Err(self.syntax(format!("write powers with `^`: `{symbol}^{c}`")));
                }
                self.symbol(&symbol, start)?
            }
            Some(c) if c.is_ascii_digit() => {
                while self.peek().is_some_and(|c| c.is_ascii_digit() || c == '.') {
                    self.i += 1;
                }
                let number: String = self.c.get(start..self.i).unwrap_or(&[]).iter().collect();
                if number != "1" {
                    return Err(self.syntax_at(
                        start,
                        format!(
                            "a unit has no numeric factor: `{number}` (only `1`, for a \
                             dimensionless quantity or in `1/s`)"
                        ),
                    ));
                }
                Unit::DIMENSIONLESS
            }
            Some('(') => {
                return Err(self.syntax(
                    "parentheses only group a denominator (`kg/(m s^2)`) or a fractional \
                     power (`m^(1/2)`)"
                        .into(),
                ));
            }
            Some(c) => return Err(self.syntax(format!("expected a unit symbol, found `{c}`"))),
            None => return Err(self.syntax("expected a unit symbol at the end".into())),
        };
        let before = self.i;
        self.ws();
        if self.peek() != Some('^') {
            self.i = before;
            return Ok(base);
        }
        self.i += 1;
        self.ws();
        let power = self.power()?;
        base.checked_pow(power).map_err(|_| self.too_large())
    }

    fn symbol(&self, symbol: &str, start: usize) -> Result<Unit, UnitError> {
        Ok(match symbol {
            "kg" => Unit::KILOGRAM,
            "m" => Unit::METRE,
            "s" => Unit::SECOND,
            "rad" | "sr" => Unit::DIMENSIONLESS,
            "N" => Unit::NEWTON,
            "J" => Unit::JOULE,
            "W" => Unit::integers(1, 2, -3),
            "Pa" => Unit::integers(1, -1, -2),
            "Hz" => Unit::integers(0, 0, -1),
            "A" | "K" | "mol" | "cd" => {
                return Err(UnitError::UnsupportedBaseUnit {
                    text: self.text.to_string(),
                    offset: start,
                    symbol: symbol.to_string(),
                });
            }
            _ => {
                return Err(UnitError::UnknownUnit {
                    text: self.text.to_string(),
                    offset: start,
                    symbol: symbol.to_string(),
                });
            }
        })
    }

    /// `2`, `-1`, `+3`, `(1/2)`, `(-3/2)`, `(2)`.
    fn power(&mut self) -> Result<Exponent, UnitError> {
        let start = self.i;
        if self.peek() == Some('(') {
            self.i += 1;
            self.ws();
            let num = self.signed()?;
            self.ws();
            let den = if self.peek() == Some('/') {
                self.i += 1;
                self.ws();
                let at = self.i;
                let d = self.digits()?;
                if d == 0 {
                    return Err(self.syntax_at(at, "a power's denominator cannot be 0".into()));
                }
                self.ws();
                d
            } else {
                1
            };
            if self.peek() != Some(')') {
                return Err(self.syntax("missing `)` after the power".into()));
            }
            self.i += 1;
            return Exponent::new(num, den).ok_or_else(|| {
                self.syntax_at(start, "the power does not fit 64-bit integers".into())
            });
        }
        Ok(Exponent::integer(self.signed()?))
    }

    fn signed(&mut self) -> Result<i64, UnitError> {
        let negative = match self.peek() {
            Some('-') => true,
            Some('+') => false,
            _ => return self.digits(),
        };
        self.i += 1;
        let n = self.digits()?;
        Ok(if negative { -n } else { n })
    }

    /// A non-negative integer that fits `i64` (so that its negation fits too).
    fn digits(&mut self) -> Result<i64, UnitError> {
        let start = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.i += 1;
        }
        if self.i == start {
            return Err(match self.peek() {
                Some(c) => self.syntax(format!(
                    "expected a whole number for the power, found `{c}`"
                )),
                None => self.syntax("expected a whole number for the power at the end".into()),
            });
        }
        let digits: String = self.c.get(start..self.i).unwrap_or(&[]).iter().collect();
        digits
            .parse::<i64>()
            .map_err(|_| self.syntax_at(start, format!("the power `{digits}` is too large")))
    }
}

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
                    .checked_pow(Exponent { num: 1, den: 2 })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{Text, load};
    use proptest::prelude::*;
    use std::collections::BTreeMap;
    use std::path::Path;

    fn u(text: &str) -> Unit {
        Unit::parse(text).unwrap_or_else(|e| panic!("`{text}`: {e}"))
    }

    fn frac(n: i64, d: i64) -> Exponent {
        Exponent::new(n, d).unwrap()
    }

    #[test]
    fn parses_the_units_specs_write() {
        for (text, (kg, m, s)) in [
            ("kg", (1, 0, 0)),
            ("m", (0, 1, 0)),
            ("s", (0, 0, 1)),
            ("rad", (0, 0, 0)),
            ("1", (0, 0, 0)),
            ("N", (1, 1, -2)),
            ("J", (1, 2, -2)),
            ("W", (1, 2, -3)),
            ("Pa", (1, -1, -2)),
            ("Hz", (0, 0, -1)),
            ("N m", (1, 2, -2)),
            ("N*m", (1, 2, -2)),
            ("N·m", (1, 2, -2)),
            ("N/m", (1, 0, -2)),
            ("m/s^2", (0, 1, -2)),
            ("m/s", (0, 1, -1)),
            ("rad/s", (0, 0, -1)),
            ("rad/s^2", (0, 0, -2)),
            ("kg m^2", (1, 2, 0)),
            ("kg*m^2", (1, 2, 0)),
            (" kg * m ^ 2 ", (1, 2, 0)),
            ("kg/m^3", (1, -3, 0)),
            ("s^-1", (0, 0, -1)),
            ("1/s", (0, 0, -1)),
            ("kg/(m s^2)", (1, -1, -2)),
            ("N s", (1, 1, -1)),
            ("m^(2/4)", (0, 0, 0)),
        ] {
            let want = if text == "m^(2/4)" {
                Unit::new(Exponent::ZERO, frac(1, 2), Exponent::ZERO)
            } else {
                Unit::integers(kg, m, s)
            };
            assert_eq!(u(text), want, "{text}");
        }
        assert_eq!(
            u("m^(1/2)"),
            Unit::new(Exponent::ZERO, frac(1, 2), Exponent::ZERO)
        );
        assert_eq!(
            u("s^(-3/2)"),
            Unit::new(Exponent::ZERO, Exponent::ZERO, frac(-3, 2))
        );
        assert_eq!(u("N m"), u("J"));
    }

    #[test]
    fn refuses_with_the_place() {
        assert_eq!(Unit::parse(""), Err(UnitError::Empty));
        assert_eq!(Unit::parse("  "), Err(UnitError::Empty));
        for (text, offset, words) in [
            ("A", 0, "the ampere"),
            ("kg K", 3, "the kelvin"),
            ("mol/s", 0, "the mole"),
            ("m cd", 2, "the candela"),
        ] {
            let e = Unit::parse(text).unwrap_err();
            assert!(
                matches!(&e, UnitError::UnsupportedBaseUnit { offset: o, .. } if *o == offset),
                "{text}: {e:?}"
            );
            assert!(e.to_string().contains(words), "{e}");
            assert!(
                e.to_string().contains("only the base units of mechanics"),
                "{e}"
            );
        }
        for (text, offset) in [
            ("mm", 0),
            ("kg deg", 3),
            ("m2", 1),
            ("2 m", 0),
            ("m/s/s", 3),
            ("N/m s", 4),
            ("m^", 2),
            ("m^(1/0)", 5),
            ("m^(1/2", 6),
            ("m)", 1),
            ("kg/(m s", 7),
            ("m^99999999999999999999", 2),
            ("(m)", 0),
            ("m +", 2),
        ] {
            let e = Unit::parse(text).unwrap_err();
            let at = match &e {
                UnitError::Syntax { offset, .. } | UnitError::UnknownUnit { offset, .. } => *offset,
                other => panic!("{text}: {other:?}"),
            };
            assert_eq!(at, offset, "{text}: {e}");
            assert!(
                e.to_string().contains(&format!("character {}", offset + 1)),
                "{e}"
            );
        }
        let e = Unit::parse("N/m s").unwrap_err().to_string();
        assert!(e.contains("`N/(m s)`"), "{e}");
        let e = Unit::parse("m2").unwrap_err().to_string();
        assert!(e.contains("`m^2`"), "{e}");
        let e = Unit::parse("kg·m³").unwrap_err().to_string();
        assert!(e.contains("`m^3`") && e.contains("character 5"), "{e}");
        let e = Unit::parse("kg deg").unwrap_err().to_string();
        assert!(e.contains("unknown unit `deg`") && e.contains("rad"), "{e}");
        // Exponents that overflow are errors, not panics.
        let big = format!("m^{} m^{}", i64::MAX, i64::MAX);
        assert!(matches!(Unit::parse(&big), Err(UnitError::Overflow { .. })));
        let big = format!("m^(1/{}) m^(1/{})", i64::MAX, i64::MAX - 1);
        assert!(matches!(Unit::parse(&big), Err(UnitError::Overflow { .. })));
        let big = format!("1/m^-{}", i64::MAX);
        assert!(Unit::parse(&big).is_ok());
        let big = format!("m^{} m", i64::MAX);
        assert!(matches!(Unit::parse(&big), Err(UnitError::Overflow { .. })));
    }

    #[test]
    fn displays_canonically() {
        for (text, shown) in [
            ("1", "1"),
            ("rad", "1"),
            ("m", "m"),
            ("kg", "kg"),
            ("s", "s"),
            ("kg m s^-2", "N"),
            ("N m", "J"),
            ("J", "J"),
            ("m/s", "m/s"),
            ("m/s^2", "m/s^2"),
            ("kg m^2", "kg m^2"),
            ("N/m", "N/m"),
            ("N s", "N s"),
            ("Hz", "1/s"),
            ("rad/s^2", "1/s^2"),
            ("kg/m^3", "kg/m^3"),
            ("kg/s", "kg/s"),
            ("W", "W"),
            ("Pa", "Pa"),
            ("Pa s", "Pa s"),
            ("J s", "J s"),
            ("N^2", "N^2"),
            ("1/N", "1/N"),
            ("m^-1 s^-1", "m^-1 s^-1"),
            ("m^(1/2)", "m^(1/2)"),
            ("s^(-1/2)", "1/s^(1/2)"),
            ("kg^(1/2) m^(-3/2)", "kg^(1/2)/m^(3/2)"),
            ("kg^(1/2) m^(-3/2) s^-1", "kg^(1/2) m^(-3/2) s^-1"),
            ("kg m", "kg m"),
        ] {
            assert_eq!(u(text).to_string(), shown, "{text}");
        }
    }

    fn exponent() -> impl Strategy<Value = Exponent> {
        (-6i64..=6, 1i64..=4).prop_map(|(n, d)| frac(n, d))
    }

    proptest! {
        #[test]
        fn display_parses_back(kg in exponent(), m in exponent(), s in exponent()) {
            let unit = Unit::new(kg, m, s);
            prop_assert_eq!(Unit::parse(&unit.to_string()), Ok(unit), "{}", unit);
        }

        #[test]
        fn products_and_quotients_undo(
            a in (exponent(), exponent(), exponent()),
            b in (exponent(), exponent(), exponent()),
        ) {
            let (a, b) = (Unit::new(a.0, a.1, a.2), Unit::new(b.0, b.1, b.2));
            prop_assert_eq!(a.checked_mul(b)?.checked_div(b), Ok(a));
        }
    }

    /// Units of the symbols of a small spec-like scope.
    fn rod(name: &str) -> Option<Unit> {
        Some(match name {
            "x1" | "x2" | "ell" | "a" => Unit::METRE,
            "theta" | "mu" => Unit::DIMENSIONLESS,
            "m1" => Unit::KILOGRAM,
            "g" => u("m/s^2"),
            "contact_force" => Unit::NEWTON,
            _ => return None,
        })
    }

    fn unit(text: &str) -> Result<Unit, UnitError> {
        unit_of(&Expr::parse(text).unwrap(), &rod)
    }

    fn message(text: &str) -> String {
        unit(text).unwrap_err().to_string()
    }

    #[test]
    fn infers_units() {
        for (text, want) in [
            ("x2 - x1 - ell*cos(theta)", "m"),
            ("-x1 - ell*cos(theta)", "m"),
            ("m1*g*a/2 - contact_force*(ell*sin(theta) - a/2)", "J"),
            ("m1*ell^2/12", "kg m^2"),
            ("sqrt(ell/g)", "s"),
            ("ell^(1/2)", "m^(1/2)"),
            ("ell^0.5", "m^(1/2)"),
            ("ell^-2", "1/m^2"),
            ("ell^(2^-1*3)", "m^(3/2)"),
            ("asin(a/ell)", "1"),
            ("1 + cos(theta)", "1"),
            ("x1 + 0", "m"),
            ("0 - x1", "m"),
            ("0.0 + x1 + 0*1", "m"),
            ("0", "1"),
            ("mu^theta", "1"),
            ("2^(a/ell)", "1"),
            ("exp(-theta)*log(2)", "1"),
        ] {
            assert_eq!(
                unit(text).map(|u| u.to_string()),
                Ok(want.to_string()),
                "{text}"
            );
        }
    }

    #[test]
    fn explains_inconsistencies() {
        assert_eq!(
            message("x1 + theta"),
            "in `x1 + theta`: cannot add `theta` (dimensionless) to `x1` (m): the terms of a \
             sum must have the same unit"
        );
        let e = message("x2 - x1 - theta");
        assert!(
            e.contains("cannot subtract `theta` (dimensionless) from `x2` (m)"),
            "{e}"
        );
        let Err(UnitError::Mismatch(m)) = unit("x1 - theta") else {
            panic!("a mismatch");
        };
        assert_eq!((m.left.as_str(), m.left_unit), ("x1", Unit::METRE));
        assert_eq!(
            (m.right.as_str(), m.right_unit),
            ("theta", Unit::DIMENSIONLESS)
        );
        assert!(m.subtract);
        assert_eq!(
            message("sin(x1)"),
            "in `sin(x1)`: `sin` needs a dimensionless argument (an angle in rad or a ratio), \
             but `x1` is in m"
        );
        assert!(matches!(unit("acos(ell)"), Err(UnitError::Argument { .. })));
        assert_eq!(
            message("ell^theta"),
            "in `ell^theta`: `ell` is in m, so its exponent must be a constant fraction such as \
             `2` or `1/2`, not `theta`"
        );
        assert!(matches!(unit("ell^0.1"), Err(UnitError::Exponent { .. })));
        assert!(matches!(
            unit("mu^x1"),
            Err(UnitError::DimensionedExponent { .. })
        ));
        let e = message("x1 + 1");
        assert!(matches!(unit("x1 + 1"), Err(UnitError::BareNumber { .. })));
        assert!(e.contains("the number `1` is added to `x1` (m)"), "{e}");
        let e = message("-2 - x1");
        assert!(
            e.contains("`x1` (m) is subtracted from the number `-2`"),
            "{e}"
        );
        let e = message("1 + x1");
        assert!(e.contains("`x1` (m) is added to the number `1`"), "{e}");
        assert_eq!(
            message("x1 + 1"),
            "in `x1 + 1`: the number `1` is added to `x1` (m): a bare number is dimensionless, \
             and only `0` can be added to a quantity with a unit (multiply the number by a \
             parameter to give it one)"
        );
        let e = message("x1 - 1/2");
        assert!(
            e.contains("the number `1/2` is subtracted from `x1` (m)"),
            "{e}"
        );
        assert_eq!(
            message("x1 + x9"),
            "unknown symbol `x9`: no unit is known for it"
        );
        assert!(matches!(
            unit("foo(x1)"),
            Err(UnitError::UnknownFunction { .. })
        ));
        assert!(matches!(
            unit("sin(x1, x2)"),
            Err(UnitError::UnknownFunction { .. })
        ));
        // Division reads as division; an error inside a quotient names it.
        let e = message("ell/(x1 + theta)");
        assert!(e.contains("in `x1 + theta`"), "{e}");
    }

    #[test]
    fn guards_against_overflow_and_depth() {
        let huge = Unit::new(Exponent::integer(i64::MAX), Exponent::ZERO, Exponent::ZERO);
        let look = |name: &str| (name == "h").then_some(huge);
        let e = unit_of(&Expr::parse("h*h").unwrap(), &look).unwrap_err();
        assert!(matches!(e, UnitError::Overflow { .. }), "{e}");
        let e = unit_of(&Expr::parse("ell^(10^30)").unwrap(), &rod).unwrap_err();
        assert!(matches!(e, UnitError::Overflow { .. }), "{e}");
        let e = unit_of(&Expr::parse("sqrt(h)").unwrap(), &look);
        assert!(e.is_ok(), "{e:?}");
        let tiny = Unit::new(
            Exponent::new(1, i64::MAX).unwrap(),
            Exponent::ZERO,
            Exponent::ZERO,
        );
        let look = |name: &str| (name == "t").then_some(tiny);
        let e = unit_of(&Expr::parse("sqrt(t)").unwrap(), &look).unwrap_err();
        assert!(matches!(e, UnitError::Overflow { .. }), "{e}");
        assert!(matches!(
            conjugate_force_unit(Unit::new(
                Exponent::integer(i64::MIN),
                Exponent::ZERO,
                Exponent::ZERO
            )),
            Err(UnitError::Overflow { .. })
        ));
        let mut deep = Expr::sym("x1");
        for _ in 0..1000 {
            deep = Expr::Fun("sin".into(), vec![deep]);
        }
        assert_eq!(unit_of(&deep, &rod), Err(UnitError::TooDeep));
        assert_eq!(Exponent::new(i64::MIN, -1), None);
        assert_eq!(Exponent::new(1, 0), None);
        assert_eq!(Exponent::new(-4, -6), Some(frac(2, 3)));
    }

    #[test]
    fn conjugate_forces() {
        assert_eq!(conjugate_force_unit(Unit::METRE), Ok(Unit::NEWTON));
        assert_eq!(conjugate_force_unit(Unit::DIMENSIONLESS), Ok(u("N m")));
        assert_eq!(
            conjugate_force_unit(u("rad")).map(|u| u.to_string()),
            Ok("J".into())
        );
    }

    /// The units of a spec's symbols: parameters and coordinates as declared, obstacle symbols
    /// in m, friction forces in N, each contact's force conjugate to its gap.
    fn scope(spec: &crate::spec::Spec) -> BTreeMap<String, Unit> {
        let mut units = BTreeMap::new();
        for p in &spec.parameters {
            units.insert(p.name.clone(), u(&p.unit));
        }
        for c in &spec.coordinates {
            units.insert(c.name.clone(), u(&c.unit));
        }
        for o in &spec.obstacles {
            for (symbol, _) in crate::spec::obstacle_symbols(o) {
                units.insert(symbol, Unit::METRE);
            }
        }
        for f in &spec.friction {
            units.insert(f.name.clone(), Unit::NEWTON);
        }
        for c in &spec.contacts {
            let gap = unit_of(&parse(&c.gap), &|s| units.get(s).copied()).unwrap();
            units.insert(c.name.clone(), conjugate_force_unit(gap).unwrap());
        }
        units
    }

    fn parse(text: &Text) -> Expr {
        Expr::parse(&text.text()).unwrap()
    }

    #[test]
    fn every_spec_is_dimensionally_consistent() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("derivations");
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
            .collect();
        files.sort();
        assert!(files.len() >= 8, "{files:?}");
        let (m, kg, s) = (Unit::METRE, Unit::KILOGRAM, Unit::SECOND);
        for file in &files {
            let spec = load(file).unwrap_or_else(|e| panic!("{e}")).spec;
            let units = scope(&spec);
            let look = |name: &str| units.get(name).copied();
            let at = |what: &str, text: &Text, want: Unit| {
                expect_unit(&parse(text), &look, want)
                    .unwrap_or_else(|e| panic!("{}: {what}: {e}", file.display()));
            };
            let consistent = |what: &str, text: &Text| {
                unit_of(&parse(text), &look)
                    .unwrap_or_else(|e| panic!("{}: {what}: {e}", file.display()))
            };
            for b in &spec.bodies {
                at("position", &b.position[0], m);
                at("position", &b.position[1], m);
                at("mass", &b.mass, kg);
                at("inertia", &b.inertia, u("kg m^2"));
                at("angle", &b.angle, Unit::DIMENSIONLESS);
            }
            for p in &spec.points {
                at("point", &p.position[0], m);
                at("point", &p.position[1], m);
            }
            for p in &spec.potentials {
                at("potential", &p.expr, Unit::JOULE);
            }
            for c in &spec.contacts {
                at("gap", &c.gap, m);
                assert_eq!(units.get(&c.name), Some(&Unit::NEWTON));
                if let Some(edge) = &c.edge {
                    consistent("edge", edge);
                }
            }
            for mon in &spec.monitors {
                match &mon.unit {
                    Some(unit) => at("monitor", &mon.expr, u(unit)),
                    None => {
                        consistent("monitor", &mon.expr);
                    }
                }
            }
            for r in &spec.requirements {
                consistent("requirement", &r.expr);
            }
            for f in &spec.friction {
                at("friction point", &f.point[0], m);
                at("friction point", &f.point[1], m);
                at("friction direction", &f.direction[0], Unit::DIMENSIONLESS);
                at("friction direction", &f.direction[1], Unit::DIMENSIONLESS);
                assert_eq!(look(&f.coefficient), Some(Unit::DIMENSIONLESS));
            }
            for (name, init) in &spec.initial {
                let q = units[name];
                at("initial position", &init.position, q);
                at(
                    "initial velocity",
                    &init.velocity,
                    q.checked_div(s).unwrap(),
                );
            }
            if let Some(d) = &spec.dimensionless {
                for g in &d.groups {
                    at("group", &g.expr, Unit::DIMENSIONLESS);
                }
                at("time scale", &d.scales.time, s);
                at("force scale", &d.scales.force, Unit::NEWTON);
            }
        }
    }

    #[test]
    fn expect_unit_names_both_units() {
        let e = expect_unit(&Expr::parse("x1*ell").unwrap(), &rod, Unit::METRE).unwrap_err();
        assert_eq!(e.to_string(), "`x1*ell` is in m^2 but should be in m");
        assert!(expect_unit(&Expr::parse("0").unwrap(), &rod, Unit::NEWTON).is_ok());
        assert!(expect_unit(&Expr::parse("1").unwrap(), &rod, Unit::NEWTON).is_err());
    }
}
