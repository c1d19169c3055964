//! The only module that calls Symbolica: conversions between [`Expr`] and Symbolica atoms and
//! the handful of operations the derivation needs (derivative, expansion, substitution,
//! rational normalisation, factorisation).
//!
//! Symbolica runs restricted without a licence: one thread per process. Every function here
//! must run on the derivation thread started by [`super::on_cas_thread`].

use super::expr::Expr;
use symbolica::atom::{Atom, AtomCore};
use symbolica::{parse, symbol};

/// A Symbolica expression.
pub type A = Atom;

/// Converts an expression to Symbolica.
pub fn atom(e: &Expr) -> A {
    let text = e.to_infix();
    parse!(&text)
}

/// Converts a Symbolica expression back (through its plain-text form).
pub fn expr(a: &A) -> Result<Expr, String> {
    let text = format!("{a}");
    Expr::parse(&text)
        .map(|e| e.tidy())
        .map_err(|e| format!("cannot read back Symbolica output `{text}`: {}", e.message))
}

/// Defines symbols in the order given, before any expression uses them. Symbolica orders the
/// terms of its normal form by the order in which the process first defined each symbol, so
/// declaring every symbol of every spec in one canonical order first makes a derivation's
/// output independent of which specs the process derived before.
pub fn declare(names: &[String]) {
    for n in names {
        let _ = symbol!(n.as_str());
    }
}

/// A symbol.
pub fn var(name: &str) -> A {
    Atom::var(symbol!(name))
}

/// An integer.
pub fn num(n: i64) -> A {
    Atom::num(n)
}

/// Partial derivative with respect to a symbol.
pub fn d(a: &A, name: &str) -> A {
    a.derivative(symbol!(name))
}

/// Expanded form.
pub fn expand(a: &A) -> A {
    a.expand()
}

/// One rational function `numerator / denominator` with common factors cancelled.
pub fn together(a: &A) -> A {
    a.together()
}

/// Factorised form.
pub fn factor(a: &A) -> A {
    a.factor()
}

/// Replaces every occurrence of a pattern (a symbol or a function call) by `value`.
pub fn subs(a: &A, pattern: &A, value: &A) -> A {
    a.replace(pattern.clone()).with(value.clone())
}

/// Replaces a symbol by a value.
pub fn subs_var(a: &A, name: &str, value: &A) -> A {
    subs(a, &var(name), value)
}

/// Whether `a` is identically zero after expansion.
pub fn is_zero(a: &A) -> bool {
    a.expand().is_zero()
}
