//! What the Rust, LaTeX and JSON writers share: the command named in every generated file's
//! header, the spec file's path, and spec text made one line for a comment.

use crate::derive::spec::Checked;

/// The command that regenerates `generated/`, named in every file header.
pub const COMMAND: &str = "cargo run --release --features derive -- derive";

/// `text` on one line (runs of whitespace, newlines included, become one space), for a comment
/// in generated code.
pub fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The spec file, relative to the project root.
pub fn spec_path(checked: &Checked) -> String {
    format!(
        "derivations/{}",
        checked
            .file
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default()
    )
}
