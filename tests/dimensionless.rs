//! Results without units (`derive::dimensionless`): those of rod_cube's contact phase
//! (`rod_cube_closed`) are the paper's eqs. (9), (16) and (14) and no longer than them, and its
//! floor's push the hand quartic; the hinged rod's contact phase separates where
//! `3 n s^3 + 3 s - 2 r = 0`; every printed form is bounded in size, and groups that do not make
//! a result dimensionless are refused. Formulas are compared by equivalence (their difference
//! is zero as a rational function modulo sin^2 + cos^2 = 1), never as strings.
#![cfg(feature = "derive")]

use rodcube::derive::cas;
use rodcube::derive::dimensionless::Dimensionless;
use rodcube::derive::expr::Expr;
use rodcube::derive::mechanics::{self, Derivation, to_sc_expr};
use rodcube::derive::present::operations;
use rodcube::derive::{derive_all, on_cas_thread, spec};
use std::path::Path;

/// The phase `name` of the spec `derivations/<spec>.yaml`.
fn phase(spec: &str, name: &str) -> Derivation {
    let phases = derive(spec);
    let names: Vec<String> = phases.iter().map(|d| d.name.clone()).collect();
    (phases.into_iter())
        .find(|d| d.name == name)
        .unwrap_or_else(|| panic!("no phase {name} among {names:?}"))
}

/// Every phase derived from one spec in `derivations/`.
fn derive(name: &str) -> Vec<Derivation> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("derivations")
        .join(format!("{name}.yaml"));
    let checked = spec::load(&path).unwrap_or_else(|e| panic!("{e}"));
    derive_all(&[checked])
        .unwrap_or_else(|e| panic!("{e}"))
        .remove(0)
        .0
}

fn dimensionless(d: &Derivation) -> &Dimensionless {
    d.dimensionless
        .as_ref()
        .unwrap_or_else(|| panic!("{} has no dimensionless block", d.name))
}

/// The dimensionless form of `key`, over `rc_s`, `rc_c` and the groups.
fn form(d: &Derivation, key: &str) -> Expr {
    dimensionless(d)
        .results
        .iter()
        .find(|r| r.key == key)
        .unwrap_or_else(|| panic!("{} has no dimensionless `{key}`", d.name))
        .form
        .clone()
}

/// A formula in the shorthands `S = sin(theta)`, `C = cos(theta)` over the groups.
fn paper(text: &str) -> Expr {
    let e = Expr::parse(&text.replace('S', "sin(theta)").replace('C', "cos(theta)"))
        .unwrap_or_else(|e| panic!("test formula `{text}`: {}", e.message));
    to_sc_expr(&e, "theta")
}

/// `a / b` as one rational function (Symbolica's `together`).
fn ratio(a: &Expr, b: &Expr) -> Expr {
    let q = Expr::Mul(vec![
        a.clone(),
        Expr::Pow(Box::new(b.clone()), Box::new(Expr::int(-1))),
    ]);
    on_cas_thread(move || cas::expr(&cas::together(&cas::atom(&q))))
        .expect("Symbolica worker")
        .expect("readable")
}

fn equivalent(a: &Expr, b: &Expr) -> bool {
    let diff = Expr::Add(vec![a.clone(), Expr::Mul(vec![Expr::int(-1), b.clone()])]);
    on_cas_thread(move || mechanics::is_zero_trig(&cas::atom(&diff)))
        .expect("Symbolica worker")
        .expect("is_zero_trig")
}

/// Asserts `derived` equals the paper's formula and is printed with no more operations.
fn assert_paper(what: &str, derived: &Expr, expected: &str) {
    let expected = paper(expected);
    assert!(
        equivalent(derived, &expected),
        "{what}: {} is not {}",
        derived.to_infix(),
        expected.to_infix()
    );
    assert!(
        operations(derived) <= operations(&expected),
        "{what}: {} ({} operations) is longer than the paper's {} ({})",
        derived.to_infix(),
        operations(derived),
        expected.to_infix(),
        operations(&expected)
    );
}

const EQ9: &str = "4*(r - S)/(4/3 - S^2/(1 + n))";
const EQ14: &str = "3*S^3 - 12*(1 + n)*S + 8*r*(1 + n)";
const EQ16: &str = "-3*C*(8*r*(1 + n) - 12*(1 + n)*S + 3*S^3)/(4*(1 + n) - 3*S^2)^2";

#[test]
fn rod_cube_is_the_paper_in_its_groups() {
    let d = &phase("rod_cube", "rod_cube_closed");
    let dim = dimensionless(d);
    let groups: Vec<(&str, String)> = (dim.groups.iter())
        .map(|g| (g.name.as_str(), g.definition.to_infix()))
        .collect();
    assert_eq!(groups, [("n", "m2/m1".into()), ("r", "a/ell".into())]);
    assert_paper("theta_dot_sq, eq. (9)", &form(d, "theta_dot_sq"), EQ9);
    assert_paper("contact_force, eq. (16)", &form(d, "contact_force"), EQ16);
    // Eq. (14) is a condition = 0: the same up to a constant factor, and no longer.
    let sep = form(d, "separation_condition");
    let q = ratio(&sep, &paper(EQ14));
    assert!(q.symbols().is_empty() && !q.is_zero(), "{}", q.to_infix());
    assert!(
        operations(&sep) <= operations(&paper(EQ14)),
        "{}",
        sep.to_infix()
    );
    // The units: theta_dot^2 in g/ell, the push in m2 g; the paper's numbers beside them.
    let result = |key: &str| dim.results.iter().find(|r| r.key == key).expect("result");
    let unit = |key: &str| result(key).unit.as_ref().map(Expr::to_infix);
    assert_eq!(unit("theta_dot_sq").as_deref(), Some("g/ell"));
    assert_eq!(unit("contact_force").as_deref(), Some("m2*g"));
    // The floor's push under the foot, in the same unit: N = m1 (g + y_cm'') with eqs. (9) and
    // (12), N / (m2 g) = (4/9 + (2 mu r - 8 r/3) S + (4 - 11 mu/3) S^2 + (mu^2 - mu) S^4) /
    // (n (4/3 - mu S^2)^2), mu = 1/(1+n) (tests/common/paper.rs).
    assert_eq!(unit("floor_normal").as_deref(), Some("m2*g"));
    let quartic = "(4/9 + (2*r/(1 + n) - 8*r/3)*S + (4 - 11/(3*(1 + n)))*S^2 \
                   + (1/(1 + n)^2 - 1/(1 + n))*S^4)/(n*(4/3 - S^2/(1 + n))^2)";
    assert!(
        equivalent(&form(d, "floor_normal"), &paper(quartic)),
        "{}",
        form(d, "floor_normal").to_infix()
    );
    assert_eq!(unit("separation_condition"), None);
    assert_eq!(result("theta_dot_sq").paper.as_deref(), Some("9"));
    assert_eq!(result("contact_force").paper.as_deref(), Some("16"));
    assert_eq!(result("separation_condition").paper.as_deref(), Some("14"));
}

#[test]
fn the_hinged_rod_separates_where_3_n_s3_plus_3_s_equals_2_r() {
    let d = &phase("hinged_rod", "hinged_rod_closed");
    let sep = form(d, "separation_condition");
    let q = ratio(&sep, &paper("3*n*S^3 + 3*S - 2*r"));
    assert!(q.symbols().is_empty() && !q.is_zero(), "{}", q.to_infix());
    assert!(operations(&sep) <= operations(&paper("3*n*S^3 + 3*S - 2*r")));
    assert_paper(
        "hinged_rod theta_dot_sq",
        &form(d, "theta_dot_sq"),
        "3*(r - S)/(1 + 3*n*S^2)",
    );
    assert_paper(
        "hinged_rod contact_force",
        &form(d, "contact_force"),
        "3/2*C*(3*n*S^3 + 3*S - 2*r)/(1 + 3*n*S^2)^2",
    );
}

/// Every spec in `derivations/` has groups and scales, every phase on the fast path writes its
/// results in them alone (and the general models, integrated, none), and no printed form is
/// longer than the raw result it came from (nor than [`MOST_OPERATIONS`]). Every violation is
/// listed.
/// The longest printed form allowed, a guard against presentation regressions. The paper's
/// family stays below 160; the closed phases with a curved contact and a second contact
/// (`fixed_cylinder_closed`'s floor push, `hinged_cylinder_closed`'s hinge forces) are
/// polynomials of degree 7 in sin and cos with three parameters, about 220 operations after
/// factoring, and set this bound.
const MOST_OPERATIONS: usize = 240;

#[test]
fn every_printed_form_is_bounded_and_free_of_units() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("derivations");
    let specs =
        rodcube::derive::spec_files(Path::new(env!("CARGO_MANIFEST_DIR"))).expect("derivations/");
    assert!(specs.len() >= 8, "{}", dir.display());
    let mut bad = Vec::new();
    let mut fast = 0;
    for path in specs {
        let name = path.file_stem().and_then(|s| s.to_str()).expect("name");
        for d in derive(name) {
            let dim = dimensionless(&d);
            let mut allowed: Vec<String> = dim.groups.iter().map(|g| g.name.clone()).collect();
            allowed.extend(["rc_s", "rc_c", "th0", "mu", "theta_0"].map(String::from));
            let Ok(red) = &d.reduction else {
                assert!(dim.results.is_empty(), "{}", d.name);
                continue;
            };
            assert!(!d.is_general(), "{}", d.name);
            assert!(!dim.results.is_empty(), "{}", d.name);
            fast += 1;
            for r in &dim.results {
                let what = format!("{} {}", d.name, r.key);
                for s in r.form.symbols() {
                    if !allowed.contains(&s) {
                        bad.push(format!("{what}: `{s}` in {}", r.form.to_infix()));
                    }
                }
                let raw = red.plain.get(&r.key).expect("a plain form");
                if r.operations > operations(raw) {
                    bad.push(format!(
                        "{what}: {} operations, the raw result {}: {}",
                        r.operations,
                        operations(raw),
                        r.form.to_infix()
                    ));
                }
                if d.name.starts_with("rod_cube") && r.operations > 160 {
                    bad.push(format!("{what}: {} operations > 160", r.operations));
                }
                if r.operations > MOST_OPERATIONS {
                    bad.push(format!(
                        "{what}: {} operations > {MOST_OPERATIONS}: {}",
                        r.operations,
                        r.form.to_infix()
                    ));
                }
                assert_eq!(r.operations, operations(&r.form), "{what}");
            }
        }
    }
    assert!(fast >= 8, "{fast} fast phases");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
