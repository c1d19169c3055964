//! The general model's tangents ([`Tangents`]): `Tangents::tangent_rows`, the partial
//! derivatives of its rows over `[q, qd, p]` at a `TangentPoint` (the state, the accelerations
//! and the forces), and `Tangents::initial_tangents`,
//! those of its initial state over the parameters (parameter-only: hoisted into `k`).

use super::code::{Code, K, Locals, OUT};
use super::lower::{Hoisted, Scope, lower, unbound};
use super::method::Preamble;
use super::state::state_scope;
use crate::derive::algebra::to_sc_over;
use crate::derive::expr::Expr;
use crate::derive::types::{Derivation, StepError, Tangents};
use serde::Serialize;

/// The two methods of a general model's tangents.
#[derive(Debug, Clone, Serialize)]
pub(super) struct TangentsCode {
    tangents: Code,
    initial_tangents: Code,
}

impl TangentsCode {
    /// Both methods' code.
    pub(super) fn codes(&self) -> [&Code; 2] {
        [&self.tangents, &self.initial_tangents]
    }

    /// Each method's arguments and lines; `n` is the length of `k`, `reduced` the index of the
    /// reduced coordinate.
    pub(super) fn finish(&mut self, n: usize, reduced: Option<usize>, locals: &Locals) {
        let (slice, params) = (Preamble::Slice(n), Preamble::Names(&locals.params, "k"));
        // The point's fields by the names the body reads, each only where it is read.
        let point = [
            ("q", "at.q"),
            ("qd", "at.qd"),
            ("qdd", "at.qdd"),
            ("forces", "at.forces"),
            ("fr", "at.friction"),
        ]
        .map(|(name, field)| Preamble::Let(name, field));
        let state = (point.into_iter())
            .chain([
                slice,
                Preamble::Angle(reduced),
                params,
                Preamble::State(&locals.coords),
            ])
            .collect::<Vec<_>>();
        let at = ("at", "&TangentPoint<'_>");
        (self.tangents).finish(&[K, at, OUT], &state);
        (self.initial_tangents).finish(&[K, OUT], &[slice, params]);
    }
}

/// `out.fill(0.0);` then `out[i] = ...;` for each entry that is not zero.
fn sparse(code: &mut Code, entries: &[Expr], scope: &Scope, hoisted: &mut Hoisted, prefix: &str) {
    let nonzero: Vec<usize> = (0..entries.len())
        .filter(|&i| !entries[i].is_zero())
        .collect();
    let exprs: Vec<Expr> = nonzero.iter().map(|&i| entries[i].clone()).collect();
    let out = code.push_body(lower(&exprs, scope, Some(hoisted), prefix));
    code.outputs = std::iter::once("out.fill(0.0);".to_string())
        .chain((nonzero.iter().zip(out)).map(|(i, v)| format!("out[{i}] = {v};")))
        .collect();
}

/// The code of `t`, the tangents of the general model `d`.
pub(super) fn tangents_code(
    d: &Derivation,
    t: &Tangents,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<TangentsCode, StepError> {
    let theta = d.theta();
    let mut full_scope = state_scope(d, scope);
    for i in 0..d.contacts.len() {
        (full_scope.locals).insert(format!("rc_f{i}"), format!("forces[{i}]"));
    }
    for j in 0..d.frictions.len() {
        (full_scope.locals).insert(format!("rc_fr{j}"), format!("fr[{j}]"));
    }
    let rows: Vec<Expr> = t.rows.iter().map(|e| to_sc_over(e, theta)).collect();
    for (exprs, scope, what) in [
        (&rows, &full_scope, "the tangents depend on"),
        (&t.initial, scope, "the initial tangents depend on"),
    ] {
        let stray = unbound(exprs, scope);
        if !stray.is_empty() {
            return Err(StepError::Unbound {
                what,
                symbols: stray.into_iter().collect(),
                besides: "the state, the accelerations, the forces and the parameters",
            });
        }
    }
    let mut tangents = Code::default();
    sparse(&mut tangents, &rows, &full_scope, hoisted, "x");
    let mut initial_tangents = Code::default();
    sparse(&mut initial_tangents, &t.initial, scope, hoisted, "y");
    Ok(TangentsCode {
        tangents,
        initial_tangents,
    })
}
