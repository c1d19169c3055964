//! Physical units of spec expressions: SI unit strings (`kg`, `m/s^2`, `N m`) parsed into
//! exponents of kg, m and s, printed back in a canonical form, and inferred for an
//! [`Expr`](super::expr::Expr) with a clear error when the expression is not dimensionally
//! consistent.
//!
//! Radians (and steradians) are dimensionless, as in SI: `rad` parses to the dimensionless unit
//! [`Unit::DIMENSIONLESS`], so an angle and a pure number have the same [`Unit`]. The
//! trigonometric functions take a dimensionless argument (an angle in radians or a ratio), and
//! the inverse ones give an angle, which is dimensionless too. Where a unit is reported rather
//! than checked (a sensitivity's unit, an FMU's unit definitions), [`AngularUnit`] keeps the
//! radian as a factor of its own.
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

mod angular;
mod dimension;
mod infer;
mod parse;
#[cfg(test)]
mod tests;

pub use angular::AngularUnit;
pub use dimension::{Exponent, SumMismatch, Unit, UnitError, conjugate_force_unit};
pub use infer::{expect_unit, unit_of};
