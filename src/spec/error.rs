//! [`SpecError`]: a spec error with its file, line, column and field, shown with the line and
//! the token underlined.

use crate::yaml::{ReadError, excerpt, line_text};
use annotate_snippets::{Group, Level, Renderer};
use std::fmt;
use std::path::{Path, PathBuf};

/// A spec error with its place.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpecError {
    /// Spec file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// Dotted field path (`bodies[0].position[1]`).
    pub field: String,
    /// What is wrong.
    pub message: String,
    /// The text of line `line` (for the snippet), empty when `line` is 0.
    pub source_line: String,
    /// Characters of `source_line` from `column` that the problem covers; 0 without a place.
    pub width: usize,
}

impl SpecError {
    /// A read error (syntax, duplicate key, tag, unknown or missing key, wrong type) named by
    /// the path serde was at: the mapping's for a key problem (`bodies[0]`).
    pub(super) fn read(file: &Path, text: &str, e: ReadError) -> SpecError {
        SpecError {
            file: file.to_path_buf(),
            line: e.mark.line,
            column: e.mark.column,
            field: e.path,
            message: e.message,
            source_line: line_text(text, e.mark.line).to_string(),
            width: e.mark.width,
        }
    }
}

impl fmt::Display for SpecError {
    /// `file:line:column: field `name`: message`, then (with a place) the line with the token
    /// underlined, rendered by annotate-snippets.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: field `{}`: {}",
            self.file.display(),
            self.line,
            self.column,
            self.field,
            self.message
        )?;
        if self.line > 0 {
            let snippet = excerpt(&self.source_line, self.line, self.column, self.width);
            let group = Group::with_level(Level::ERROR).element(snippet);
            let renderer = Renderer::plain().term_width(usize::from(u16::MAX));
            write!(f, "\n{}", renderer.render(&[group]))?;
        }
        Ok(())
    }
}

impl std::error::Error for SpecError {}
