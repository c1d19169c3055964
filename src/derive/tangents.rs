//! Stage 8 of the derivation, the general model's tangents: the partial derivatives of its
//! rows over `x = [q, qd, p]` that the integrated route's forward sensitivities need
//! (`Tangents::tangent_rows`), and those of its initial state over the parameters
//! (`Tangents::initial_tangents`).
//!
//! The rows are those `Tangents::tangent_rows` documents: the residual `M qdd - F - J^T f - T^T fr`
//! of the equations of motion, with the accelerations `ddot_<q>`, the contacts' forces
//! `rc_f<i>` and the frictions' forces `rc_fr<j>` as symbols held fixed; each contact's normal
//! acceleration `J qdd + bias`; each friction's slip acceleration `T qdd + bias`; each contact's
//! gap (zero where the phase eliminates the contact) and edge margin (zero without an edge);
//! each friction's slip velocity `T qd`. Each is differentiated as derived (`sin(theta)` still a
//! call, so that its derivative in `theta` is `cos(theta)`), with nothing brought together or
//! expanded: the lowering shares what the entries have in common.

use super::algebra::{root_of_one_minus_square, to_expr};
use super::cas::{self, A};
use super::expr::Expr;
use super::types::{Derivation, DeriveError, Tangents};

/// Functions the CAS does not know: their derivative is taken here, by the chain rule.
const BY_HAND: &[&str] = &["tan", "asin", "acos", "atan"];

/// Whether `e` calls a function of [`BY_HAND`].
fn calls_by_hand(e: &Expr) -> bool {
    match e {
        Expr::Rational(..) | Expr::Float(_) | Expr::Sym(_) => false,
        Expr::Add(v) | Expr::Mul(v) => v.iter().any(calls_by_hand),
        Expr::Pow(b, x) => calls_by_hand(b) || calls_by_hand(x),
        Expr::Fun(f, args) => BY_HAND.contains(&f.as_str()) || args.iter().any(calls_by_hand),
    }
}

/// `d e / d x`: by the CAS where `e` calls only functions it knows, by the sum, product, power
/// and chain rules around the calls of [`BY_HAND`] otherwise.
fn d(e: &Expr, x: &str) -> A {
    if !e.symbols().contains(x) {
        return cas::num(0);
    }
    if !calls_by_hand(e) {
        return cas::d(&cas::atom(e), x);
    }
    match e {
        Expr::Rational(..) | Expr::Float(_) | Expr::Sym(_) => cas::d(&cas::atom(e), x),
        Expr::Add(v) => v.iter().fold(cas::num(0), |sum, t| sum + d(t, x)),
        Expr::Mul(v) => (0..v.len()).fold(cas::num(0), |sum, i| {
            let others = (v.iter().enumerate())
                .filter(|(j, _)| *j != i)
                .fold(cas::num(1), |product, (_, f)| product * cas::atom(f));
            sum + others * d(&v[i], x)
        }),
        Expr::Pow(b, n) => {
            let pow = |base: Expr, exponent: Expr| Expr::Pow(Box::new(base), Box::new(exponent));
            let power = cas::atom(e);
            let less = Expr::Add(vec![(**n).clone(), Expr::Rational(-1, 1)]);
            match n.symbols().contains(x) {
                false => cas::atom(n) * cas::atom(&pow((**b).clone(), less)) * d(b, x),
                true => {
                    let log = cas::atom(&Expr::Fun("log".into(), vec![(**b).clone()]));
                    let over = cas::atom(&pow((**b).clone(), Expr::Rational(-1, 1)));
                    power * (d(n, x) * log + cas::atom(n) * d(b, x) * over)
                }
            }
        }
        Expr::Fun(f, args) => match (args.as_slice(), outer(f, args)) {
            ([u], Some(derivative)) => cas::atom(&derivative) * d(u, x),
            _ => cas::d(&cas::atom(e), x),
        },
    }
}

/// `f'(u)` of a spec's function of one argument `[u]`.
fn outer(f: &str, args: &[Expr]) -> Option<Expr> {
    let [u] = args else {
        return None;
    };
    let call = |g: &str| Expr::Fun(g.into(), vec![u.clone()]);
    let pow =
        |base: Expr, n: i128, m: i128| Expr::Pow(Box::new(base), Box::new(Expr::Rational(n, m)));
    let one = || Expr::Rational(1, 1);
    let u_sq = || pow(u.clone(), 2, 1);
    let minus = |e: Expr| Expr::Mul(vec![Expr::Rational(-1, 1), e]);
    Some(match f {
        "sin" => call("cos"),
        "cos" => minus(call("sin")),
        "tan" => Expr::Add(vec![one(), pow(call("tan"), 2, 1)]),
        "asin" => root_of_one_minus_square(u, -1),
        "acos" => minus(root_of_one_minus_square(u, -1)),
        "atan" => pow(Expr::Add(vec![one(), u_sq()]), -1, 1),
        "sqrt" => Expr::Mul(vec![Expr::Rational(1, 2), pow(call("sqrt"), -1, 1)]),
        "exp" => call("exp"),
        "log" => pow(u.clone(), -1, 1),
        _ => return None,
    })
}

/// `sum_j row_j * symbol_j` over the atoms of `row` and the symbols `symbols`.
fn dot(row: &[Expr], symbols: &[String]) -> A {
    (row.iter().zip(symbols)).fold(cas::num(0), |sum, (r, s)| sum + cas::atom(r) * cas::var(s))
}

/// The rows of [`Tangents::rows`] before they are differentiated, as expressions.
fn rows(d: &Derivation) -> Result<Vec<Expr>, DeriveError> {
    let ddot: Vec<String> = d.coords.iter().map(|c| format!("ddot_{c}")).collect();
    let forces: Vec<String> = (0..d.contacts.len()).map(|i| format!("rc_f{i}")).collect();
    let frictions: Vec<String> = (0..d.frictions.len())
        .map(|j| format!("rc_fr{j}"))
        .collect();
    let dots: Vec<String> = d.coords.iter().map(|c| format!("dot_{c}")).collect();
    let mut out = Vec::new();
    for (i, (mass, rhs)) in d.mass.iter().zip(&d.rhs).enumerate() {
        let contacts: Vec<Expr> = d.contacts.iter().map(|c| c.jacobian[i].clone()).collect();
        let slips: Vec<Expr> = d.frictions.iter().map(|f| f.jacobian[i].clone()).collect();
        let residual =
            dot(mass, &ddot) - cas::atom(rhs) - dot(&contacts, &forces) - dot(&slips, &frictions);
        out.push(to_expr(&residual, "equation of motion's residual")?);
    }
    for c in &d.contacts {
        let acceleration = dot(&c.jacobian, &ddot) + cas::atom(&c.bias);
        out.push(to_expr(&acceleration, "normal acceleration")?);
    }
    for f in &d.frictions {
        let acceleration = dot(&f.jacobian, &ddot) + cas::atom(&f.bias);
        out.push(to_expr(&acceleration, "slip acceleration")?);
    }
    let zero = Expr::Rational(0, 1);
    out.extend((d.contacts.iter()).map(|c| {
        if c.closed {
            zero.clone()
        } else {
            c.gap.clone()
        }
    }));
    out.extend((d.contacts.iter()).map(|c| c.edge.clone().unwrap_or_else(|| zero.clone())));
    for f in &d.frictions {
        out.push(to_expr(&dot(&f.jacobian, &dots), "slip velocity")?);
    }
    Ok(out)
}

/// The tangents of the general model `d` (see the module docs).
pub fn derive(d: &Derivation) -> Result<Tangents, DeriveError> {
    let params: Vec<&str> = d.params.iter().map(|p| p.name.as_str()).collect();
    let columns: Vec<String> = (d.coords.iter().cloned())
        .chain(d.coords.iter().map(|c| format!("dot_{c}")))
        .chain(params.iter().map(|p| p.to_string()))
        .collect();
    let mut out = Tangents::default();
    for row in rows(d)? {
        for x in &columns {
            out.rows.push(to_expr(&self::d(&row, x), "tangent")?);
        }
    }
    let initial = (d.initial.iter().map(|[q, _]| q)).chain(d.initial.iter().map(|[_, v]| v));
    for value in initial {
        for p in &params {
            out.initial
                .push(to_expr(&self::d(value, p), "initial tangent")?);
        }
    }
    Ok(out)
}
