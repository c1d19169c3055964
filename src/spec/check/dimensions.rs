//! The units pass of the checker: the unit of every parameter, coordinate and obstacle symbol,
//! the units the mechanics needs (masses, inertias, positions, potentials), and each contact's
//! gap unit and the unit of its force, conjugate to the gap.

use super::{Checker, Field};
use crate::spec::error::SpecError;
use crate::spec::expr::Expr;
use crate::spec::schema::{Text, obstacle_symbols};
use crate::spec::units::{Unit, conjugate_force_unit, expect_unit, unit_of};
use std::collections::{BTreeMap, BTreeSet};

impl Checker<'_> {
    /// The unit of every parameter, coordinate and obstacle symbol; a unit string that does
    /// not parse is an error at its field.
    fn symbol_units(&self) -> Result<BTreeMap<String, Unit>, SpecError> {
        let s = self.spec;
        let mut out = BTreeMap::new();
        let parameters = s.parameters.iter().map(|p| (&p.name, &p.unit));
        let coordinates = s.coordinates.iter().map(|c| (&c.name, &c.unit));
        let declared = (parameters.enumerate().map(|(i, e)| ("parameters", i, e)))
            .chain(coordinates.enumerate().map(|(i, e)| ("coordinates", i, e)));
        for (list, i, (name, unit)) in declared {
            let u = Unit::parse(unit).map_err(|e| {
                self.err(
                    &Field::key(list).i(i).k("unit"),
                    format!("the unit `{unit}` of `{name}`: {e}"),
                )
            })?;
            out.insert(name.clone(), u);
        }
        let params: BTreeSet<String> = s.parameters.iter().map(|p| p.name.clone()).collect();
        for (i, o) in s.obstacles.iter().enumerate() {
            for (symbol, text) in obstacle_symbols(o) {
                let field = Field::key("obstacles").i(i);
                let e = self.expr(&field, &text, &params)?;
                // Every obstacle symbol is a length: a place or a size.
                let lookup = |n: &str| out.get(n).copied();
                expect_unit(&e, &lookup, Unit::METRE).map_err(|err| {
                    self.err(&field, format!("`{symbol}` = `{}`: {err}", text.text()))
                })?;
                out.insert(symbol, Unit::METRE);
            }
        }
        Ok(out)
    }

    /// The units the mechanics needs: bodies' masses in kg, inertias in kg m^2, positions in
    /// m, potentials in J, and every contact's gap in one unit, whose force is conjugate to it
    /// (N for a gap in metres, N m for one in radians): a gap is a length (m) or an angle
    /// (dimensionless). Returns each contact's gap unit and its force unit, as printed.
    pub(in crate::spec) fn contact_units(&self) -> Result<Vec<(Unit, String)>, SpecError> {
        let s = self.spec;
        let units = self.symbol_units()?;
        let lookup = |n: &str| units.get(n).copied();
        let parse = |field: &Field, text: &Text| {
            Expr::parse(&text.text()).map_err(|e| {
                self.err(
                    field,
                    format!("cannot parse `{}`: {}", text.text(), e.message),
                )
            })
        };
        let expect = |field: Field, text: &Text, unit: Unit, what: &str| {
            let e = parse(&field, text)?;
            expect_unit(&e, &lookup, unit)
                .map_err(|err| self.err(&field, format!("{what} must be in {unit}: {err}")))
        };
        let kg_m2 = Unit::KILOGRAM
            .checked_mul(Unit::METRE)
            .and_then(|u| u.checked_mul(Unit::METRE))
            .map_err(|e| self.err(&Field::key("bodies"), e.to_string()))?;
        for (i, b) in s.bodies.iter().enumerate() {
            let f = Field::key("bodies").i(i);
            expect(f.k("mass"), &b.mass, Unit::KILOGRAM, "a mass")?;
            expect(f.k("inertia"), &b.inertia, kg_m2, "a moment of inertia")?;
            expect(
                f.k("position").i(0),
                &b.position[0],
                Unit::METRE,
                "a position",
            )?;
            expect(
                f.k("position").i(1),
                &b.position[1],
                Unit::METRE,
                "a position",
            )?;
            expect(f.k("angle"), &b.angle, Unit::DIMENSIONLESS, "an angle")?;
        }
        for (i, p) in s.potentials.iter().enumerate() {
            let f = Field::key("potentials").i(i).k("expr");
            expect(f, &p.expr, Unit::JOULE, "a potential energy")?;
        }
        let mut out = Vec::new();
        for (i, c) in s.contacts.iter().enumerate() {
            let field = Field::key("contacts").i(i);
            // The unit of the contact's `gap` or `edge`, which must have one.
            let consistent = |key: &str, text: &Text| -> Result<Unit, SpecError> {
                let f = field.k(key);
                unit_of(&parse(&f, text)?, &lookup).map_err(|err| {
                    self.err(
                        &f,
                        format!(
                            "the {key} of contact `{}` has no consistent unit: {err}",
                            c.name
                        ),
                    )
                })
            };
            let gap_unit = consistent("gap", &c.gap)?;
            if gap_unit != Unit::METRE && !gap_unit.is_dimensionless() {
                return Err(self.err(
                    &field.k("gap"),
                    format!(
                        "the gap of contact `{}` is in {gap_unit}: a gap is a length (m) or \
                         an angle (rad)",
                        c.name
                    ),
                ));
            }
            let force_unit = conjugate_force_unit(gap_unit)
                .map_err(|err| self.err(&field.k("gap"), format!("contact `{}`: {err}", c.name)))?;
            if let Some(edge) = &c.edge {
                consistent("edge", edge)?;
            }
            if let Some(e) = &c.restitution {
                expect(
                    field.k("restitution"),
                    e,
                    Unit::DIMENSIONLESS,
                    "a coefficient of restitution",
                )?;
            }
            // A torque and an energy are both kg m^2 s^-2: a multiplier is a torque.
            let force = if force_unit == Unit::JOULE {
                "N m".to_string()
            } else {
                force_unit.to_string()
            };
            out.push((gap_unit, force));
        }
        Ok(out)
    }
}
