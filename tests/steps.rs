//! The derivation's steps as the LaTeX shows them (`derive::steps`): the kinetic energy,
//! Euler–Lagrange equations and conserved momenta of rod_cube's contact phase
//! (`rod_cube_closed`) and of its general model (`rod_cube`, every coordinate) equal a hand
//! Newton–Euler/Koenig derivation and are grouped in the velocities with `sin^2 + cos^2 = 1`
//! applied; in every model every shown step equals the derived one and has no more operations.
//! Formulas are compared by equivalence (difference zero modulo sin^2 + cos^2 = 1), never as
//! strings.
#![cfg(feature = "derive")]

mod common;

use common::derived::phases_in;

use rodcube::derive::cas;
use rodcube::derive::expr::Expr;
use rodcube::derive::mechanics::{self, to_sc_expr};
use rodcube::derive::on_cas_thread;
use rodcube::derive::present::operations;
use rodcube::derive::steps::Shown;

fn parse(text: &str) -> Expr {
    let e = Expr::parse(text).unwrap_or_else(|e| panic!("test formula `{text}`: {}", e.message));
    to_sc_expr(&e, "theta")
}

fn difference_vanishes(a: &Expr, b: &Expr) -> bool {
    let diff = Expr::Add(vec![a.clone(), Expr::Mul(vec![Expr::int(-1), b.clone()])]);
    on_cas_thread(move || mechanics::is_zero_trig(&cas::atom(&diff)))
        .expect("Symbolica worker")
        .expect("is_zero_trig")
}

/// Asserts a step is shown grouped, equal to `expected`, over sin(theta) alone (no `cos^2`
/// left beside a `sin^2`), with one term per monomial in the velocities.
fn assert_grouped(what: &str, shown: &Shown, expected: &str, terms: usize) {
    assert_eq!(shown.as_derived, None, "{what} is shown as derived");
    let expected = parse(expected);
    assert!(
        difference_vanishes(&shown.expr, &expected),
        "{what}: {} is not {}",
        shown.expr.to_infix(),
        expected.to_infix()
    );
    let n = match &shown.expr {
        Expr::Add(v) => v.len(),
        _ => 1,
    };
    assert_eq!(n, terms, "{what}: {}", shown.expr.to_infix());
    assert!(
        operations(&shown.expr) <= operations(&shown.derived),
        "{what}: {} is longer than as derived",
        shown.expr.to_infix()
    );
}

#[test]
fn rod_cube_s_contact_phase_steps_are_the_hand_derivation_grouped_in_the_velocities() {
    let phases = phases_in("derivations");
    let d = phases
        .iter()
        .find(|d| d.name == "rod_cube_closed")
        .expect("rod_cube_closed");
    let steps = d.steps.as_ref().expect("steps");
    // By hand: the rod's centre at (x1 + l cos/2, l sin/2), its own rotation m1 l^2/12; the
    // cube at x2 = x1 + l cos(theta).
    let t = "(m1 + m2)/2*dot_x1^2 - ell*(m1 + 2*m2)/2*sin(theta)*dot_x1*dot_theta \
             + ell^2*(m1 + 3*m2*sin(theta)^2)/6*dot_theta^2";
    assert_grouped("T", &steps.kinetic, t, 3);
    assert!(
        !steps.kinetic.expr.symbols().contains("rc_c"),
        "sin^2 + cos^2 left in T: {}",
        steps.kinetic.expr.to_infix()
    );
    assert_grouped("V", &steps.potential, "g*(m2*a + m1*ell*sin(theta))/2", 1);
    // Newton–Euler for the pair along x, and about the rod's foot.
    assert_grouped(
        "Euler-Lagrange x1",
        &steps.euler_lagrange[0],
        "(m1 + m2)*ddot_x1 - ell*(m1 + 2*m2)/2*sin(theta)*ddot_theta \
         - ell*(m1 + 2*m2)/2*cos(theta)*dot_theta^2",
        3,
    );
    assert_grouped(
        "Euler-Lagrange theta",
        &steps.euler_lagrange[1],
        "-ell*(m1 + 2*m2)/2*sin(theta)*ddot_x1 + ell^2*(m1 + 3*m2*sin(theta)^2)/3*ddot_theta \
         + m2*ell^2*sin(theta)*cos(theta)*dot_theta^2 + m1*g*ell/2*cos(theta)",
        4,
    );
    assert_grouped(
        "p_x1",
        &steps.momenta[0],
        "(m1 + m2)*dot_x1 - ell*(m1 + 2*m2)/2*sin(theta)*dot_theta",
        2,
    );
}

/// The general model keeps every coordinate (`x1, y1, theta, x2`): by hand, the rod's centre at
/// `(x1 + l cos/2, y1 + l sin/2)` with its own rotation `m1 l^2/12`, the cube at `x2` alone.
#[test]
fn rod_cube_s_general_steps_are_the_hand_derivation_grouped_in_the_velocities() {
    let phases = phases_in("derivations");
    let d = phases
        .iter()
        .find(|d| d.name == "rod_cube")
        .expect("rod_cube");
    let steps = d.steps.as_ref().expect("steps");
    let t = "m1/2*dot_x1^2 + m1/2*dot_y1^2 - m1*ell/2*sin(theta)*dot_x1*dot_theta \
             + m1*ell/2*cos(theta)*dot_y1*dot_theta + m1*ell^2/6*dot_theta^2 + m2/2*dot_x2^2";
    assert_grouped("T", &steps.kinetic, t, 6);
    assert_grouped(
        "V",
        &steps.potential,
        "m1*g*y1 + g*(m2*a + m1*ell*sin(theta))/2",
        1,
    );
    assert_eq!(steps.euler_lagrange.len(), 4);
    // Newton for the rod's centre along x and y, Euler about the foot, Newton for the cube.
    assert_grouped(
        "Euler-Lagrange x1",
        &steps.euler_lagrange[0],
        "m1*ddot_x1 - m1*ell/2*sin(theta)*ddot_theta - m1*ell/2*cos(theta)*dot_theta^2",
        3,
    );
    assert_grouped(
        "Euler-Lagrange y1",
        &steps.euler_lagrange[1],
        "m1*ddot_y1 + m1*ell/2*cos(theta)*ddot_theta - m1*ell/2*sin(theta)*dot_theta^2 + m1*g",
        4,
    );
    assert_grouped(
        "Euler-Lagrange theta",
        &steps.euler_lagrange[2],
        "-m1*ell/2*sin(theta)*ddot_x1 + m1*ell/2*cos(theta)*ddot_y1 + m1*ell^2/3*ddot_theta \
         + m1*g*ell/2*cos(theta)",
        4,
    );
    assert_grouped(
        "Euler-Lagrange x2",
        &steps.euler_lagrange[3],
        "m2*ddot_x2",
        1,
    );
    assert_eq!(steps.momenta.len(), 2);
    assert_grouped(
        "p_x1",
        &steps.momenta[0],
        "m1*dot_x1 - m1*ell/2*sin(theta)*dot_theta",
        2,
    );
    assert_grouped("p_x2", &steps.momenta[1], "m2*dot_x2", 1);
}

#[test]
fn every_shown_step_equals_the_derived_one_and_is_no_longer() {
    for d in phases_in("derivations") {
        let steps = d
            .steps
            .as_ref()
            .unwrap_or_else(|| panic!("{} has no steps", d.name));
        let mut shown: Vec<(String, &Shown)> = vec![
            ("T".into(), &steps.kinetic),
            ("V".into(), &steps.potential),
            ("L".into(), &steps.lagrangian),
        ];
        shown.extend((steps.euler_lagrange.iter().enumerate()).map(|(i, s)| (format!("EL{i}"), s)));
        shown.extend((steps.momenta.iter().enumerate()).map(|(i, s)| (format!("p{i}"), s)));
        // A condition `= 0` is shown up to its constant factor (the presenter checks that).
        shown.extend(
            (steps.reduced.iter())
                .filter(|(k, _)| k.as_str() != "separation_condition")
                .map(|(k, s)| (k.clone(), s)),
        );
        for (what, s) in shown {
            let what = format!("{} {what}", d.name);
            assert!(
                difference_vanishes(&s.expr, &s.derived),
                "{what}: {} is not {}",
                s.expr.to_infix(),
                s.derived.to_infix()
            );
            assert!(
                operations(&s.expr) <= operations(&s.derived),
                "{what}: {} is longer than {}",
                s.expr.to_infix(),
                s.derived.to_infix()
            );
            if s.as_derived.is_some() {
                assert_eq!(
                    s.expr, s.derived,
                    "{what}: shown as derived, yet another form"
                );
            }
        }
    }
}
