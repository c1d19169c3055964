//! Presentation forms (`derive::present`): the form chosen is equal to the result, follows the
//! stated order and rule, and a wrong candidate cannot be printed.
#![cfg(feature = "derive")]

use rodcube::derive::cas;
use rodcube::derive::expr::Expr;
use rodcube::derive::on_cas_thread;
use rodcube::derive::present::{Presenter, Shape, operations};

/// The presentation form of `text` (over `rc_s`, `rc_c` and the symbols `order`), as infix.
fn present(text: &str, shape: Shape, order: &[&str]) -> String {
    let text = text.to_string();
    let order: Vec<String> = order.iter().map(|s| s.to_string()).collect();
    on_cas_thread(move || {
        let e = Expr::parse(&text).expect("test formula");
        Presenter::new(&order)
            .present(&cas::atom(&e), shape)
            .map(|f| f.expr.to_infix())
    })
    .expect("Symbolica worker")
    .expect("presentation")
}

#[test]
fn a_theta_free_part_of_a_sum_is_not_bracketed() {
    let got = present(
        "(4*w^2 + 12*z - 3*w^2*z^2 - 12*rc_s)/(4 - 3*rc_s^2)",
        Shape::Fraction,
        &["w", "z"],
    );
    assert!(!got.starts_with("(("), "{got}");
}

#[test]
fn the_paper_s_eq_9_is_found_from_the_expanded_result() {
    // 12 (1 + n)(r - s)/(4 (1 + n) - 3 s^2) with everything multiplied out.
    let got = present(
        "(12*r + 12*n*r - 12*rc_s - 12*n*rc_s)/(4 + 4*n - 3*rc_s^2)",
        Shape::Fraction,
        &["n", "r"],
    );
    assert_eq!(got, "4*(r - rc_s)/(4/3 - rc_s^2/(1 + n))");
    let e = Expr::parse(&got).expect("printed form");
    assert_eq!(operations(&e), 8);
}

#[test]
fn a_condition_runs_from_its_highest_power_with_that_term_positive() {
    let got = present("2*r - 3*rc_s - 3*n*rc_s^3", Shape::Polynomial, &["n", "r"]);
    assert_eq!(got, "3*n*rc_s^3 + 3*rc_s - 2*r");
}

#[test]
fn sin_squared_plus_cos_squared_is_one() {
    let got = present("a*rc_s^2 + a*rc_c^2", Shape::Fraction, &["a"]);
    assert_eq!(got, "a");
}

#[test]
fn operations_count_operators_and_function_calls() {
    let e = Expr::parse("4*(r - sin(theta))/(4/3 - sin(theta)^2/(1 + n))").expect("formula");
    assert_eq!(operations(&e), 10);
}
