//! Units as results and parameters are reported in ([`AngularUnit`]): a [`Unit`] with the
//! radian kept as a factor of its own, so that an angle, an angular rate and a quotient by an
//! angle are told from a ratio, a frequency and a plain quotient.

use super::dimension::{Exponent, Unit, UnitError, overflow, write_factor};
use std::fmt;

/// A unit with the radian as a factor: the SI [`Unit`] (in which `rad` is dimensionless, as the
/// spec's dimensional checks need) and the radian's power. `rad/s` is an angular rate where
/// [`Unit`] sees `1/s`; `rad/rad` is `1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AngularUnit {
    si: Unit,
    rad: Exponent,
}

impl AngularUnit {
    /// The radian.
    pub const RADIAN: AngularUnit = AngularUnit {
        si: Unit::DIMENSIONLESS,
        rad: Exponent::ONE,
    };

    /// The unit `si` times the radian to the power `rad`.
    pub const fn new(si: Unit, rad: Exponent) -> AngularUnit {
        AngularUnit { si, rad }
    }

    /// Its SI unit (the radian dimensionless).
    pub fn si(self) -> Unit {
        self.si
    }

    /// The power of the radian in it.
    pub fn rad(self) -> Exponent {
        self.rad
    }

    /// Whether it is an angle (`rad`) or an angular rate (`rad/s`).
    pub fn is_angle_or_rate(self) -> bool {
        self.rad == Exponent::ONE
            && (self.si == Unit::DIMENSIONLESS || self.si == Unit::integers(0, 0, -1))
    }

    /// The unit of a product, `self * other`; an error when an exponent overflows.
    pub fn checked_mul(self, other: AngularUnit) -> Result<AngularUnit, UnitError> {
        let rad = self.rad.checked_add(other.rad);
        let rad = rad.ok_or_else(|| overflow(format!("the product of {self} and {other}")))?;
        Ok(AngularUnit::new(self.si.checked_mul(other.si)?, rad))
    }

    /// The unit of a quotient, `self / other`; an error when an exponent overflows.
    pub fn checked_div(self, other: AngularUnit) -> Result<AngularUnit, UnitError> {
        let rad = self.rad.checked_sub(other.rad);
        let rad = rad.ok_or_else(|| overflow(format!("the quotient of {self} by {other}")))?;
        Ok(AngularUnit::new(self.si.checked_div(other.si)?, rad))
    }

    /// The unit of `self^power`; an error when an exponent overflows.
    pub fn checked_pow(self, power: Exponent) -> Result<AngularUnit, UnitError> {
        let rad = self.rad.checked_mul(power);
        let rad = rad.ok_or_else(|| overflow(format!("{self} to the power {power}")))?;
        Ok(AngularUnit::new(self.si.checked_pow(power)?, rad))
    }
}

impl From<Unit> for AngularUnit {
    fn from(si: Unit) -> AngularUnit {
        AngularUnit::new(si, Exponent::ZERO)
    }
}

/// `rad` to the power `e` (`rad`, `rad^2`, `rad^(1/2)`).
struct Radian(Exponent);

impl fmt::Display for Radian {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_factor(f, "rad", self.0)
    }
}

impl fmt::Display for AngularUnit {
    /// [`Unit`]'s canonical form with the radian written in front of it when its power is
    /// positive (`rad`, `rad/s`, `rad s^2/m`, `rad^2`) and below the line when it is negative
    /// (`1/rad`, `s/rad`, `m/(s rad)`), which [`AngularUnit::parse`] reads back to the same unit.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let si = self.si.to_string();
        if self.rad.is_zero() {
            return f.write_str(&si);
        }
        if self.rad.num() > 0 {
            let rad = Radian(self.rad);
            return match (si.as_str(), si.strip_prefix("1/")) {
                ("1", _) => write!(f, "{rad}"),
                (_, Some(below)) => write!(f, "{rad}/{below}"),
                _ => write!(f, "{rad} {si}"),
            };
        }
        let Some(power) = self.rad.checked_neg() else {
            // A power no unit string reaches (its negation overflows): written as it is.
            return write!(f, "{si} {}", Radian(self.rad));
        };
        let rad = Radian(power);
        match si.split_once('/') {
            None => write!(f, "{si}/{rad}"),
            Some((above, below)) => write!(f, "{above}/({below} {rad})"),
        }
    }
}
