//! Model specs (`derivations/*.yaml`): their schema, parsing, and checks that name file, line
//! and field for every error.
//!
//! Part of the runtime crate (no Symbolica), so that specs and their expressions can be parsed,
//! checked and fuzzed without the `derive` feature; the derivation tool re-exports this module
//! as `rodcube::derive::spec` (and [`expr`] as `rodcube::derive::expr`).

pub mod expr;
pub mod units;

mod check;
mod dimensionless;
mod error;
mod schema;

pub use check::{RESERVED_PREFIXES, is_identifier};
pub use dimensionless::{DIMENSIONLESS_RESULTS, monomial, solved_parameters};
pub use error::SpecError;
pub use schema::{
    BodySpec, ContactSpec, CoordSpec, DimensionlessSpec, FrictionSpec, GroupSpec, InitialSpec,
    MonitorSpec, ObstacleSpec, ParamSpec, PointSpec, PotentialSpec, RequirementSpec, ScalesSpec,
    ShapeSpec, Spec, Text, obstacle_symbols,
};

use crate::yaml::Document;
use check::Checker;
use std::path::{Path, PathBuf};

/// A parsed and checked spec with its expressions parsed.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The raw spec.
    pub spec: Spec,
    /// Where it came from.
    pub file: PathBuf,
    /// Each contact's gap unit (a length, `m`, or an angle, dimensionless) and its force's
    /// unit (conjugate to the gap), in the spec's order.
    pub units: Vec<(units::Unit, String)>,
    /// The spec's text as read (its digest is recorded in the model's tape).
    pub text: String,
}

impl Checked {
    /// The gap unit and force unit of contact `j` (`(Unit::METRE, "N")`); an error at
    /// `contacts[j]` for an index past the spec's contacts.
    pub fn contact_units(&self, j: usize) -> Result<(units::Unit, String), SpecError> {
        self.units.get(j).cloned().ok_or_else(|| SpecError {
            file: self.file.clone(),
            line: 0,
            column: 0,
            field: format!("contacts[{j}]"),
            message: format!(
                "no contact {j}: the spec has {} ({} with units)",
                self.spec.contacts.len(),
                self.units.len()
            ),
            source_line: String::new(),
            width: 0,
        })
    }
}

/// Reads and checks a spec file.
pub fn load(path: &Path) -> Result<Checked, SpecError> {
    let text = std::fs::read_to_string(path).map_err(|e| SpecError {
        file: path.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read: {e}"),
        source_line: String::new(),
        width: 0,
    })?;
    parse(path, &text)
}

/// Parses and checks spec text (`path` is used in messages).
pub fn parse(path: &Path, text: &str) -> Result<Checked, SpecError> {
    // Every node first (syntax, duplicate keys, tags), then the schema: each error typed and
    // at the parser's mark (crate::yaml).
    let doc = Document::parse(text).map_err(|e| SpecError::read(path, text, e))?;
    let spec: Spec = doc
        .deserialize()
        .map_err(|e| SpecError::read(path, text, e))?;
    let checker = Checker {
        path,
        doc: &doc,
        spec: &spec,
    };
    checker.check()?;
    let units = checker.contact_units()?;
    Ok(Checked {
        spec,
        file: path.to_path_buf(),
        units,
        text: text.to_string(),
    })
}
