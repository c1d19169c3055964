//! The straight-line body of one generated method ([`Code`]) and the arguments the methods
//! share; what every part of the Rust writer builds.

use super::lower::Body;
use super::method::{Preamble, method};
use crate::derive::types::{Derivation, StepError};
use serde::Serialize;
use std::collections::BTreeSet;

/// A straight-line function body: statements, then outputs; `Code::finish` makes it a
/// method's argument list and lines.
#[derive(Debug, Clone, Serialize, Default)]
pub struct Code {
    pub(super) stmts: Vec<String>,
    pub(super) outputs: Vec<String>,
    /// The method's arguments after `&self`, an unread one spelled with a leading `_`.
    pub(super) args: String,
    /// The method's body: the preamble it reads, the statements and the outputs.
    pub(super) lines: Vec<String>,
}

/// Arguments of the generated methods (name, Rust type).
pub(super) const K: (&str, &str) = ("k", "&[f64]");
pub(super) const Q: (&str, &str) = ("q", "&[f64]");
pub(super) const QD: (&str, &str) = ("qd", "&[f64]");
pub(super) const OUT: (&str, &str) = ("out", "&mut [f64]");
pub(super) const DELTA: (&str, &str) = ("delta", "f64");

impl Code {
    /// Fills `args` and `lines` for a method with arguments `args`, whose body may start with
    /// `preamble` (see [`method::method`]).
    pub(super) fn finish(&mut self, args: &[(&str, &str)], preamble: &[Preamble]) {
        let body = self.stmts.iter().chain(&self.outputs).cloned().collect();
        (self.args, self.lines) = method(args, preamble, body);
    }

    pub(super) fn push_body(&mut self, body: Body) -> Vec<String> {
        // A `let` that reads a prepared constant says what it holds in the spec's symbols.
        let lets = body.lets.into_iter().zip(&body.holds);
        self.stmts.extend(
            lets.map(|((name, value), holds)| match value.contains("k[") {
                true => format!("let {name} = {value}; // {}", holds.to_infix()),
                false => format!("let {name} = {value};"),
            }),
        );
        body.outputs
    }
    /// `let name = value;`, or `k[i] = value;` for a constant slot.
    pub(super) fn bind(&mut self, name: &str, value: String) {
        if name.starts_with("k[") {
            self.stmts.push(format!("{name} = {value};"));
        } else {
            self.stmts.push(format!("let {name} = {value};"));
        }
    }
}

/// `out[i] = <output i>;` lines.
pub(super) fn out_lines(outputs: &[String]) -> Vec<String> {
    outputs
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect()
}

/// Names a generated method may already use: its arguments, `self`, and Rust's keywords.
const TAKEN: &[&str] = &[
    "k",
    "p",
    "q",
    "qd",
    "qdd",
    "out",
    "delta",
    "t",
    "theta_dot",
    "mass",
    "rhs",
    "jac",
    "bias",
    "forces",
    "fr",
    "pos",
    "vel",
    "poses",
    "sizes",
    "contact",
    "q_full",
    "qd_full",
    "self",
    "as",
    "break",
    "const",
    "continue",
    "crate",
    "else",
    "enum",
    "extern",
    "false",
    "fn",
    "for",
    "if",
    "impl",
    "in",
    "let",
    "loop",
    "match",
    "mod",
    "move",
    "mut",
    "pub",
    "ref",
    "return",
    "static",
    "struct",
    "super",
    "trait",
    "true",
    "type",
    "unsafe",
    "use",
    "where",
    "while",
    "async",
    "await",
    "dyn",
    "abstract",
    "become",
    "box",
    "do",
    "final",
    "macro",
    "override",
    "priv",
    "typeof",
    "unsized",
    "virtual",
    "yield",
    "try",
    "gen",
];

/// Whether `name` could be a temporary of [`lower`](super::lower::lower) (`qt0`, `h13_t2`)
/// or one of the derivation's internal symbols (`rc_s`).
fn temporary_like(name: &str) -> bool {
    let digits_after = |rest: &str| !rest.is_empty() && rest.chars().all(|c| c.is_ascii_digit());
    name.starts_with("rc_")
        || name
            .match_indices('t')
            .any(|(at, _)| at > 0 && digits_after(&name[at + 1..]))
}

/// The Rust local that reads the spec symbol `symbol` in generated code: its name in lower
/// case, with `suffix` where that is taken ([`TAKEN`]) or could be a temporary (the
/// parameter `k` is `k_param`, `R` is `r`).
fn local_name(symbol: &str, suffix: &str) -> String {
    let lower = symbol.to_lowercase();
    match TAKEN.contains(&lower.as_str()) || temporary_like(&lower) {
        true => format!("{lower}{suffix}"),
        false => lower,
    }
}

/// The local that reads the parameter `name` in generated code.
pub(super) fn parameter_local(name: &str) -> String {
    local_name(name, "_param")
}

/// The local that reads the coordinate `name` in generated code (its rate and acceleration
/// add `_dot` and `_ddot`).
pub(super) fn coordinate_local(name: &str) -> String {
    local_name(name, "_coord")
}

/// The locals that name a phase's parameters and coordinates in the generated methods.
pub(super) struct Locals {
    /// One per parameter, in their order (`k[i]`, `p[i]`).
    pub(super) params: Vec<String>,
    /// One per coordinate, in their order (`q[i]`; with `_dot` `qd[i]`, with `_ddot` `qdd[i]`).
    pub(super) coords: Vec<String>,
}

impl Locals {
    /// The locals of `d`'s symbols; an error if two would be the same.
    pub(super) fn of(d: &Derivation) -> Result<Locals, StepError> {
        let params: Vec<String> = d.params.iter().map(|p| parameter_local(&p.name)).collect();
        let coords: Vec<String> = d.coords.iter().map(|c| coordinate_local(c)).collect();
        let mut seen = BTreeSet::new();
        let state =
            (coords.iter()).flat_map(|c| [c.clone(), format!("{c}_dot"), format!("{c}_ddot")]);
        for name in params.iter().cloned().chain(state) {
            if !seen.insert(name.clone()) {
                return Err(StepError::LocalClash {
                    model: d.name.clone(),
                    local: name,
                });
            }
        }
        Ok(Locals { params, coords })
    }
}
