//! Tests of units: reading and printing unit strings, inferring the units of expressions, and
//! every spec in `derivations/` dimensionally consistent.

use super::*;
use crate::spec::expr::Expr;
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

#[test]
fn angular_units_keep_the_radian() {
    let a = |t: &str| AngularUnit::parse(t).unwrap_or_else(|e| panic!("{t}: {e}"));
    // The radian's power is kept apart from the SI unit, which is the same as `Unit::parse`'s.
    for (text, rad) in [
        ("rad", 1),
        ("rad/s", 1),
        ("m", 0),
        ("rad^2 m", 2),
        ("s/rad", -1),
    ] {
        assert_eq!(a(text).rad(), Exponent::integer(rad), "{text}");
        assert_eq!(a(text).si(), u(text), "{text}");
    }
    assert!(a("rad").is_angle_or_rate() && a("rad/s").is_angle_or_rate());
    assert!(!a("1").is_angle_or_rate() && !a("1/s").is_angle_or_rate());
    assert!(!a("rad/m").is_angle_or_rate() && !a("rad^2").is_angle_or_rate());
    // Quotients, as a sensitivity's unit is formed, and what they print.
    let per = |r: &str, p: &str| a(r).checked_div(a(p)).map(|q| q.to_string());
    for (r, p, want) in [
        ("rad", "kg", "rad/kg"),
        ("rad", "m/s^2", "rad s^2/m"),
        ("rad/s", "m/s^2", "rad s/m"),
        ("s", "m/s^2", "s^3/m"),
        ("rad", "rad", "1"),
        ("s", "rad", "s/rad"),
        ("m/s", "rad", "m/(s rad)"),
        ("1", "rad^2", "1/rad^2"),
        ("N m", "kg", "m^2/s^2"),
    ] {
        assert_eq!(per(r, p), Ok(want.to_string()), "{r} / {p}");
    }
}

proptest! {
    /// Whatever powers of kg, m, s and rad, the printed unit reads back to the same unit.
    #[test]
    fn angular_units_read_back(kg in -3i64..=3, m in -3i64..=3, s in -3i64..=3, rad in -3i64..=3) {
        let unit = AngularUnit::new(Unit::integers(kg, m, s), Exponent::integer(rad));
        let text = unit.to_string();
        prop_assert_eq!(AngularUnit::parse(&text), Ok(unit), "{}", text);
    }
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
