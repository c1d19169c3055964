//! The straight-line body of one generated method ([`Code`]) and the arguments the methods
//! share; what every part of the Rust writer builds.

use super::lower::Body;
use super::method::{Preamble, method};
use serde::Serialize;

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
        self.stmts.extend(
            body.lets
                .into_iter()
                .map(|(name, value)| format!("let {name} = {value};")),
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
