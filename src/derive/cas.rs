//! The only module that calls Symbolica: conversions between [`Expr`] and Symbolica atoms (by
//! building and walking their structure, never through printed text) and
//! the handful of operations the derivation needs (derivative, expansion, substitution,
//! rational normalisation, factorisation).
//!
//! Symbolica runs restricted without a licence: one thread per process. Every function here
//! must run on the derivation thread started by [`super::on_cas_thread`].

use super::expr::Expr;
use super::types::{StepError, Unheld};
use symbolica::atom::{Atom, AtomCore, AtomView, FunctionBuilder, Symbol};
use symbolica::coefficient::CoefficientView;
use symbolica::prelude::RealLike;
use symbolica::symbol;

/// A Symbolica expression.
pub type A = Atom;

/// Converts an expression to Symbolica, node by node (no text in between).
pub fn atom(e: &Expr) -> A {
    match e {
        Expr::Rational(n, d) => Atom::num((*n, *d)),
        Expr::Float(x) => Atom::num(*x),
        Expr::Sym(s) => var(s),
        Expr::Add(v) => balanced(v, &|a, b| a + b).unwrap_or_else(|| num(0)),
        Expr::Mul(v) => balanced(v, &|a, b| a * b).unwrap_or_else(|| num(1)),
        Expr::Pow(b, x) => atom(b).pow(atom(x)),
        Expr::Fun(f, args) => args
            .iter()
            .fold(FunctionBuilder::new(function(f)), |call, a| {
                call.add_arg(atom(a))
            })
            .finish(),
    }
}

/// The terms (or factors) `v` combined pairwise as a balanced tree (`None` when there are
/// none): each operation normalises its result, so a left fold over `n` terms would normalise
/// sums of 1, 2, ..., n terms, a balanced tree sums of `n` terms `log2 n` times.
fn balanced(v: &[Expr], op: &impl Fn(A, A) -> A) -> Option<A> {
    match v {
        [] => None,
        [one] => Some(atom(one)),
        _ => {
            let (left, right) = v.split_at(v.len() / 2);
            Some(op(balanced(left, op)?, balanced(right, op)?))
        }
    }
}

/// Symbolica's own symbol for a function it knows (so that it differentiates and simplifies
/// it), a new one for any other.
fn function(name: &str) -> Symbol {
    match name {
        "sin" => Symbol::SIN,
        "cos" => Symbol::COS,
        "sqrt" => Symbol::SQRT,
        "exp" => Symbol::EXP,
        "log" => Symbol::LOG,
        other => symbol!(other),
    }
}

/// Converts a Symbolica expression back by walking its structure (its public atom views), so
/// that no change in how Symbolica prints can change what the tool reads.
pub fn expr(a: &A) -> Result<Expr, StepError> {
    view(a.as_view())
        .map(|e| e.tidy())
        .map_err(|why| StepError::Unreadable {
            atom: a.to_string(),
            why,
        })
}

fn view(v: AtomView) -> Result<Expr, Unheld> {
    let all = |items: &mut dyn Iterator<Item = AtomView>| -> Result<Vec<Expr>, Unheld> {
        items.map(view).collect()
    };
    Ok(match v {
        AtomView::Num(n) => number(n.get_coeff_view())?,
        AtomView::Var(x) => match x.get_symbol().get_stripped_name() {
            // Symbolica's own constant: a spec's `pi` comes back as it.
            "𝜋" => Expr::Sym(crate::derive::expr::PI.to_string()),
            name => Expr::Sym(name.to_string()),
        },
        AtomView::Fun(f) => Expr::Fun(
            f.get_symbol().get_stripped_name().to_string(),
            all(&mut f.iter())?,
        ),
        AtomView::Pow(p) => {
            let (base, exponent) = p.get_base_exp();
            Expr::Pow(Box::new(view(base)?), Box::new(view(exponent)?))
        }
        AtomView::Mul(m) => Expr::Mul(all(&mut m.iter())?),
        AtomView::Add(s) => Expr::Add(all(&mut s.iter())?),
    })
}

/// A real rational (or float) coefficient; anything else (complex, infinite, undefined, a
/// finite-field element) has no place in a mechanics derivation and is an error.
fn number(c: CoefficientView) -> Result<Expr, Unheld> {
    let too_large = |_| Unheld::TooLarge;
    match c {
        CoefficientView::Natural(n, d, 0, _) => Ok(Expr::Rational(n.into(), d.into())),
        CoefficientView::Large(re, im) if im.is_zero() => {
            let r = re.to_rat();
            Ok(Expr::Rational(
                i128::try_from(r.numerator()).map_err(too_large)?,
                i128::try_from(r.denominator()).map_err(too_large)?,
            ))
        }
        CoefficientView::Float(re, im) if im.is_zero() => Ok(Expr::Float(re.to_float().to_f64())),
        _ => Err(Unheld::NotReal),
    }
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
    thread_local! {
        /// The variables made so far (only the Symbolica thread makes any): a symbol's lookup
        /// by name costs more than a copy of its atom.
        static VARS: std::cell::RefCell<std::collections::HashMap<String, A>> =
            Default::default();
    }
    VARS.with(|vars| {
        let mut vars = vars.borrow_mut();
        if let Some(a) = vars.get(name) {
            return a.clone();
        }
        let a = Atom::var(symbol!(name));
        vars.insert(name.to_string(), a.clone());
        a
    })
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

/// Most results a memo keeps before it starts afresh.
const MEMO_CAPACITY: usize = 20_000;

/// The operations whose results are remembered by their input ([`memo`]).
#[derive(Debug, Clone, Copy)]
pub enum Memo {
    /// [`together`].
    Together = 0,
    /// [`factor`].
    Factor = 1,
    /// `algebra::reduce_cos_sq`.
    CosSquares = 2,
}

thread_local! {
    /// Results of [`together`], [`factor`] and `algebra::reduce_cos_sq` by their input: the
    /// presentation asks for the same rational normalisations, factorisations and
    /// `sin^2 + cos^2 = 1` rewritings many times over (every candidate form of a result,
    /// every phase of a spec). The derivation runs on one thread, so the memo is that thread's.
    static MEMO: std::cell::RefCell<[std::collections::HashMap<A, A>; 3]> =
        std::cell::RefCell::new(Default::default());
}

/// `op(a)`, remembered in the memo of `which` (`op` must be that operation).
pub fn memo(which: Memo, a: &A, op: impl FnOnce(&A) -> A) -> A {
    let slot = which as usize;
    if let Some(hit) = MEMO.with(|m| m.borrow()[slot].get(a).cloned()) {
        return hit;
    }
    let out = op(a);
    MEMO.with(|m| {
        let mut m = m.borrow_mut();
        if m[slot].len() >= MEMO_CAPACITY {
            m[slot].clear();
        }
        m[slot].insert(a.clone(), out.clone());
    });
    out
}

/// One rational function `numerator / denominator` with common factors cancelled.
pub fn together(a: &A) -> A {
    memo(Memo::Together, a, |a| a.together())
}

/// Factorised form.
pub fn factor(a: &A) -> A {
    memo(Memo::Factor, a, |a| a.factor())
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
