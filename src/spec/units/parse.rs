//! The reader of unit strings as specs write them ([`Unit::parse`], and [`AngularUnit::parse`]
//! keeping the radian): `kg m^2`, `m/s^2`, `kg/(m s^2)`, refused with the character where the
//! problem is.

use super::angular::AngularUnit;
use super::dimension::{Exponent, Unit, UnitError, overflow};

impl Unit {
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
        AngularUnit::parse(text).map(AngularUnit::si)
    }
}

impl AngularUnit {
    /// Reads a unit string as [`Unit::parse`] does, keeping the power of `rad`.
    pub fn parse(text: &str) -> Result<AngularUnit, UnitError> {
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

    /// The characters from here on while `keep` holds, passed over: a symbol, a number or the
    /// digits of a power (collected as they are passed, so no range of `c` is looked up).
    fn take_while(&mut self, keep: impl Fn(char) -> bool) -> String {
        let mut taken = String::new();
        while let Some(c) = self.peek().filter(|c| keep(*c)) {
            taken.push(c);
            self.i += 1;
        }
        taken
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
    fn product(&mut self) -> Result<AngularUnit, UnitError> {
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
    fn factor(&mut self) -> Result<AngularUnit, UnitError> {
        let start = self.i;
        let base = match self.peek() {
            Some(c) if c.is_alphabetic() => {
                let symbol = self.take_while(char::is_alphabetic);
                if let Some(c) = self.peek().filter(|c| c.is_ascii_digit()) {
                    return Err(self.syntax(format!("write powers with `^`: `{symbol}^{c}`")));
                }
                // Each superscript paired with its digit (or minus) by `zip`.
                let superscript = self.peek().and_then(|c| {
                    let mut pairs = "⁰¹²³⁴⁵⁶⁷⁸⁹⁻".chars().zip("0123456789-".chars());
                    pairs.find(|(x, _)| *x == c).map(|(_, d)| d)
                });
                if let Some(c) = superscript {
                    return Err(self.syntax(format!("write powers with `^`: `{symbol}^{c}`")));
                }
                self.symbol(&symbol, start)?
            }
            Some(c) if c.is_ascii_digit() => {
                let number = self.take_while(|c| c.is_ascii_digit() || c == '.');
                if number != "1" {
                    return Err(self.syntax_at(
                        start,
                        format!(
                            "a unit has no numeric factor: `{number}` (only `1`, for a \
                             dimensionless quantity or in `1/s`)"
                        ),
                    ));
                }
                AngularUnit::from(Unit::DIMENSIONLESS)
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

    fn symbol(&self, symbol: &str, start: usize) -> Result<AngularUnit, UnitError> {
        Ok(AngularUnit::from(match symbol {
            "kg" => Unit::KILOGRAM,
            "m" => Unit::METRE,
            "s" => Unit::SECOND,
            "rad" => return Ok(AngularUnit::RADIAN),
            "sr" => Unit::DIMENSIONLESS,
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
        }))
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
        let digits = self.take_while(|c| c.is_ascii_digit());
        if digits.is_empty() {
            return Err(match self.peek() {
                Some(c) => self.syntax(format!(
                    "expected a whole number for the power, found `{c}`"
                )),
                None => self.syntax("expected a whole number for the power at the end".into()),
            });
        }
        digits
            .parse::<i64>()
            .map_err(|_| self.syntax_at(start, format!("the power `{digits}` is too large")))
    }
}
