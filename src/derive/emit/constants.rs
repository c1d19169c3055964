//! The constant slice `k` of a generated model: its layout (the parameters, the reduction's
//! named constants, then hoisted subexpressions), `prepare`'s lines that fill it, the part the
//! per-point solver reads (`prepare_lean`) and the named constants nothing reads.

use super::code::{Code, parameter_local};
use super::lower::{Hoisted, Scope, hoisted_slot, lower};
use super::reduced::{ReducedCode, missing_constant};
use crate::derive::expr::Expr;
use crate::derive::types::{Derivation, Reduction, StepError};
use std::collections::BTreeSet;

/// `Model::prepare` after the parameters: with a fast path, the per-point solver's constants
/// first (`prepare_lean`, filled into `code`), then the others, each once; hoisted constants
/// go last. A named constant that is another one lives in its slot: `prepare` starts by
/// saying so.
pub(super) fn prepare_code(
    d: &Derivation,
    start: Code,
    own: &[(usize, usize)],
    scope: &Scope,
    hoisted: &Hoisted,
    code: Option<&mut ReducedCode>,
) -> Result<Code, StepError> {
    let np = d.params.len();
    let mut prepare = start;
    let mut lean_indices = Vec::new();
    if let (Ok(r), Some(code)) = (&d.reduction, code) {
        let (lean, indices) = lean_prepare(np, r, own, scope, hoisted, code)?;
        code.prepare_lean = lean;
        code.lean_constants = indices.clone();
        prepare = Code::default();
        prepare
            .stmts
            .push("Reduction::prepare_lean(self, p, k);".into());
        for &(j, slot) in own {
            if !indices.contains(&slot) {
                let c = &r.constants[j];
                let prefix = format!("c{j}_");
                bind_constant(&mut prepare, slot, &c.symbol, &c.value, scope, &prefix);
            }
        }
        lean_indices = indices;
    }
    for (i, e) in &hoisted.entries {
        if !lean_indices.contains(i) {
            bind_hoisted(&mut prepare, *i, e, scope, hoisted);
        }
    }
    if let Ok(r) = &d.reduction {
        let notes = (r.constants.iter().enumerate())
            .filter(|(j, _)| !own.iter().any(|&(o, _)| o == *j))
            .filter_map(|(_, c)| {
                let i = scope.constants.get(&c.symbol)?;
                Some(format!(
                    "// k[{i}] also holds {} = {}",
                    c.symbol,
                    c.value.to_infix()
                ))
            })
            .collect::<Vec<_>>();
        prepare.stmts.splice(0..0, notes);
    }
    Ok(prepare)
}

/// The constant layout of `k`: the parameters, then the reduction's constants that hold a
/// slot of their own (computed in `prepare`, which this starts); hoisted subexpressions follow
/// them. Returns the scope, the start of `prepare` and, for each reduction constant with a slot
/// of its own (all but an [`alias`]), its position in the reduction and its slot.
pub(super) fn constant_layout(
    d: &Derivation,
    skip: &BTreeSet<String>,
) -> (Scope, Code, Vec<(usize, usize)>) {
    let np = d.params.len();
    let mut scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        scope.constants.insert(p.name.clone(), i);
        scope.named.insert(i, parameter_local(&p.name));
    }
    let mut prepare = Code::default();
    let constants = match &d.reduction {
        Ok(r) => r.constants.as_slice(),
        Err(_) => &[],
    };
    let mut own = Vec::new();
    for (j, c) in constants.iter().enumerate() {
        if skip.contains(&c.symbol) {
            continue;
        }
        if let Some(i) = alias(&c.value, &scope) {
            // Another constant under a new name (a start value that is a parameter, say):
            // read where that one is.
            scope.constants.insert(c.symbol.clone(), i);
            continue;
        }
        let slot = np + own.len();
        bind_constant(
            &mut prepare,
            slot,
            &c.symbol,
            &c.value,
            &scope,
            &format!("c{j}_"),
        );
        scope.constants.insert(c.symbol.clone(), slot);
        own.push((j, slot));
    }
    (scope, prepare, own)
}

/// The slot of the constant that `value` is, when it is just one (a parameter or an earlier
/// constant).
fn alias(value: &Expr, scope: &Scope) -> Option<usize> {
    match value {
        Expr::Sym(s) => scope.constants.get(s).copied(),
        _ => None,
    }
}

/// `k[idx] = <value>;` for the hoisted constant `value` (which may read earlier hoisted slots),
/// after a comment saying what it holds in the spec's own symbols.
fn bind_hoisted(code: &mut Code, idx: usize, value: &Expr, scope: &Scope, hoisted: &Hoisted) {
    let holds = hoisted.defined(value).tidy().to_infix();
    bind(code, idx, &holds, value, scope, &format!("h{idx}_"));
}

/// `k[idx] = <value>;` for the named constant `name` (a start value, say), introduced by its
/// name: `// k[7] = rc_si = a/ell`.
fn bind_constant(
    code: &mut Code,
    idx: usize,
    name: &str,
    value: &Expr,
    scope: &Scope,
    prefix: &str,
) {
    let holds = format!("{name} = {}", value.tidy().to_infix());
    bind(code, idx, &holds, value, scope, prefix);
}

/// `// k[idx] = <holds>` (what the slot holds in the spec's own symbols,
/// `// k[20] = m1/2 + m2/2`) and the lines that compute `value` into `k[idx]`, its shared
/// subexpressions as `let`s named by `prefix`.
fn bind(code: &mut Code, idx: usize, holds: &str, value: &Expr, scope: &Scope, prefix: &str) {
    code.stmts.push(format!("// k[{idx}] = {holds}"));
    let out = code.push_body(lower(std::slice::from_ref(value), scope, None, prefix));
    code.bind(&format!("k[{idx}]"), out[0].clone());
}

/// Indices `i` of every `k[i]` in a line of generated code.
fn k_indices(text: &str) -> Vec<usize> {
    text.match_indices("k[")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            let end = rest.find(']')?;
            rest[..end].parse().ok()
        })
        .collect()
}

/// What the per-point solver reads: the start (`theta_i`, its rate, sine and cosine) and the
/// separation and fall polynomials' coefficients, with every constant they are computed from.
/// Returns the code that computes just those (after the parameters) and their indices.
fn lean_prepare(
    np: usize,
    r: &Reduction,
    own: &[(usize, usize)],
    scope: &Scope,
    hoisted: &Hoisted,
    code: &ReducedCode,
) -> Result<(Code, Vec<usize>), StepError> {
    let index = |name: &str| scope.constants.get(name).copied();
    let definition = |i: usize| -> Option<&Expr> {
        own.iter()
            .find(|&&(_, slot)| slot == i)
            .map(|&(j, _)| &r.constants[j].value)
            .or_else(|| {
                hoisted
                    .entries
                    .iter()
                    .find(|(j, _)| *j == i)
                    .map(|(_, e)| e)
            })
    };
    let wi = index("rc_wi").ok_or_else(|| missing_constant("rc_wi"))?;
    // The start enters the lean path through its sine, cosine and rate only: the angle itself
    // (an `asin`) is left to the full `prepare`.
    let mut stack = vec![code.k_sin_initial, code.k_cos_initial, wi];
    let fall = code.fall.stmts.iter().chain(&code.fall.outputs);
    // A push the derivation proved positive is not certified point by point: its
    // polynomial is no part of the lean start.
    let certified = (code.polynomial_lines.iter().zip(&r.push_proofs))
        .filter(|(_, proof)| proof.is_none())
        .flat_map(|(lines, _)| lines);
    for line in certified.chain(fall) {
        stack.extend(k_indices(line));
    }
    let mut needed = BTreeSet::new();
    while let Some(i) = stack.pop() {
        if needed.insert(i)
            && let Some(e) = definition(i)
        {
            stack.extend((e.symbols().iter()).filter_map(|s| index(s).or_else(|| hoisted_slot(s))));
        }
    }
    let mut lean = Code::default();
    for &(j, slot) in own {
        let c = &r.constants[j];
        if needed.contains(&slot) {
            bind_constant(
                &mut lean,
                slot,
                &c.symbol,
                &c.value,
                scope,
                &format!("c{j}_"),
            );
        }
    }
    for (i, e) in &hoisted.entries {
        if needed.contains(i) {
            bind_hoisted(&mut lean, *i, e, scope, hoisted);
        }
    }
    Ok((lean, needed.into_iter().filter(|&i| i >= np).collect()))
}

/// The reduction's constants with a slot of their own (`own`) that no line of `codes` reads
/// and that the runtime does not read through `ReductionInfo` (the start's angle, rate, sine
/// and cosine).
pub(super) fn unread_constants(
    d: &Derivation,
    own: &[(usize, usize)],
    codes: &[&Code],
) -> BTreeSet<String> {
    let Ok(r) = &d.reduction else {
        return BTreeSet::new();
    };
    let runtime = ["rc_thi", "rc_wi", "rc_si", "rc_ci"];
    let lines =
        || (codes.iter().flat_map(|c| &c.lines)).filter(|l| !l.trim_start().starts_with("//"));
    own.iter()
        .map(|&(j, slot)| (&r.constants[j].symbol, slot))
        .filter(|(symbol, _)| !runtime.contains(&symbol.as_str()))
        .filter(|&(_, slot)| {
            let (read, write) = (format!("k[{slot}]"), format!("k[{slot}] = "));
            lines().all(|l| l.matches(&read).count() == l.matches(&write).count())
        })
        .map(|(symbol, _)| symbol.clone())
        .collect()
}
