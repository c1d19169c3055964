//! The derivation's steps as a person writes them (over `rc_s`, `rc_c`, as the derivation's
//! reduced results are): the kinetic and potential energies, the
//! Lagrangian, the Euler–Lagrange equations and the conserved momenta grouped by their
//! velocities and accelerations, each group's coefficient in its presentation form
//! ([`super::present`]: `sin^2 + cos^2 = 1` applied, factored, in conventional order); the
//! reduced results (inertia, energy integral, acceleration, forces, separation condition) in
//! theirs. `T = (m1 + m2) x1'^2 / 2 - l (m1 + 2 m2) sin(theta) x1' theta' / 2 + ...` rather
//! than the expanded sum with `sin^2 + cos^2` left in it.
//!
//! Rule: a step is shown in its grouped form when that has no more operations than the
//! expanded one ([`super::present::operations`]); otherwise, or when no form could be formed
//! (an expression the presenter does not take apart), as derived, with the reason recorded.
//! Every form is checked equal to the derived expression by Symbolica (difference zero modulo
//! `sin^2 + cos^2 = 1`; a condition `= 0` up to its constant factor) before it can be shown; one
//! that is not is not shown, and the step is shown as derived with the reason.

use super::algebra::{is_zero_trig, pythagoras, to_sc_over};
use super::cas::{self, A};
use super::expr::{Expr, product, sum};
use super::present::{Presenter, Shape, operations};
use super::types::{Derivation, StepError};
pub use super::types::{Shown, Steps};
use std::collections::BTreeMap;

/// The steps of `d` as shown.
pub fn derive(d: &Derivation) -> Steps {
    let order: Vec<String> = d.params.iter().map(|p| p.name.clone()).collect();
    let presenter = Presenter::new(&order);
    // Accelerations first, then velocities, each in the coordinates' order.
    let motion: Vec<String> = (d.coords.iter().map(|c| format!("ddot_{c}")))
        .chain(d.coords.iter().map(|c| format!("dot_{c}")))
        .collect();
    // The presenter works over `rc_s`, `rc_c` (so that it can apply sin^2 + cos^2 = 1); the
    // full-state expressions hold `sin(theta)`, `cos(theta)`.
    let theta = d.theta();
    let grouped = |e: &Expr| show(&to_sc_over(e, theta), |a| in_motion(&presenter, a, &motion));
    let mut steps = Steps {
        kinetic: grouped(&d.kinetic),
        potential: grouped(&d.potential),
        lagrangian: grouped(&d.lagrangian),
        euler_lagrange: d.euler_lagrange.iter().map(grouped).collect(),
        momenta: d.momenta.iter().map(grouped).collect(),
        reduced: BTreeMap::new(),
    };
    if let Ok(r) = &d.reduction {
        for (key, e) in &r.plain {
            let shape = if key == "separation_condition" {
                Shape::Polynomial
            } else {
                Shape::Fraction
            };
            let form = show(&to_sc_over(e, theta), |a| {
                presenter.present(a, shape).map(|f| f.expr)
            });
            steps.reduced.insert(key.clone(), form);
        }
    }
    steps
}

/// `e` in the form `form` makes of it (a form checked by its maker) when that has no more
/// operations, else as derived. A form that fails to be made leaves `e` as derived with the
/// reason.
fn show(e: &Expr, form: impl Fn(&A) -> Result<Expr, StepError>) -> Shown {
    let a = cas::atom(e);
    let raw = e.clone();
    let candidate = match form(&a) {
        Ok(f) => f,
        Err(why) => {
            return Shown {
                expr: raw.clone(),
                derived: raw,
                as_derived: Some(why.to_string()),
            };
        }
    };
    if operations(&candidate) <= operations(&raw) {
        Shown {
            expr: candidate,
            derived: raw,
            as_derived: None,
        }
    } else {
        Shown {
            expr: raw.clone(),
            derived: raw,
            as_derived: Some("no grouped form is shorter".into()),
        }
    }
}

/// A polynomial in the `motion` symbols (accelerations and velocities) as a sum over its
/// monomials, each coefficient in its presentation form: accelerations first, then velocity
/// products, then the part without either; within each, in the order of `motion`, higher
/// powers first.
fn in_motion(presenter: &Presenter, a: &A, motion: &[String]) -> Result<Expr, StepError> {
    // `sin^2 + cos^2 = 1` joins terms of every angle first: the presenter applies it to
    // `theta`'s alone (checked with the whole grouped form below).
    let expanded = pythagoras(&cas::expr(&cas::expand(a))?);
    let terms = match expanded {
        Expr::Add(v) => v,
        t => vec![t],
    };
    // Monomial (motion index, -power) ascending -> the coefficient's terms.
    let mut groups: BTreeMap<Vec<(usize, i128)>, Vec<Expr>> = BTreeMap::new();
    for t in terms {
        let factors = match t {
            Expr::Mul(v) => v,
            f => vec![f],
        };
        let (mut monomial, mut rest) = (Vec::new(), Vec::new());
        for f in factors {
            match motion_power(&f, motion) {
                Some((i, k)) => monomial.push((i, -k)),
                None => rest.push(f),
            }
        }
        monomial.sort();
        groups.entry(monomial).or_default().push(product(rest));
    }
    let mut shown = Vec::new();
    // The part free of the motion (the empty monomial sorts first) goes last.
    let mut free = None;
    for (monomial, coefficient) in groups {
        let c = presenter
            .present(&cas::atom(&sum(coefficient)), Shape::Fraction)?
            .expr;
        let mut factors = match c {
            Expr::Mul(v) => v,
            Expr::Rational(1, 1) if !monomial.is_empty() => Vec::new(),
            c => vec![c],
        };
        factors.extend(monomial.iter().map(|&(i, minus_k)| {
            let s = Expr::Sym(motion[i].clone());
            match -minus_k {
                1 => s,
                k => Expr::Pow(Box::new(s), Box::new(Expr::int(k))),
            }
        }));
        let term = product(factors);
        if monomial.is_empty() {
            free = Some(term);
        } else {
            shown.push(term);
        }
    }
    shown.extend(free);
    let grouped = sum(shown);
    if !is_zero_trig(&(cas::atom(&grouped) - a.clone()))? {
        return Err(StepError::Presentation(format!(
            "the grouped form `{}` is not equal to `{}`",
            grouped.to_infix(),
            cas::expr(a)?.to_infix()
        )));
    }
    Ok(grouped)
}

/// `(index in motion, power)` when `f` is a motion symbol or a positive integer power of one.
fn motion_power(f: &Expr, motion: &[String]) -> Option<(usize, i128)> {
    let index = |s: &str| motion.iter().position(|m| m == s);
    match f {
        Expr::Sym(s) => index(s).map(|i| (i, 1)),
        Expr::Pow(b, k) => match (&**b, k.as_integer()) {
            (Expr::Sym(s), Some(k)) if k > 0 => index(s).map(|i| (i, k)),
            _ => None,
        },
        _ => None,
    }
}
