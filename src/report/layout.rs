//! How the report is laid out: [`Layout`] (the width, or none with `--wide`, and whether it
//! is `--verbose`), comfy-table tables that fit it, text wrapped to it, and a section (a title,
//! its table and with `--verbose` the meaning of each row). The tables of `table.rs` and
//! `checks.rs` are made with these.

use crate::results::format_number;
use comfy_table::{CellAlignment, ColumnConstraint, ContentArrangement, Table, presets};

/// How wide the report may be, and how much it says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Largest line length in characters; `None` for no limit (`--wide`).
    pub width: Option<usize>,
    /// Whether each table is followed by a legend with the meaning of every row, and what a
    /// long run summarises is listed in full.
    pub verbose: bool,
}

impl Layout {
    /// The width of piped output (and of a terminal whose width cannot be read).
    pub const PIPE_WIDTH: usize = 100;

    /// The layout of stdout: `COLUMNS` when set to a number, else the terminal's width, else
    /// [`Layout::PIPE_WIDTH`]; no limit with `wide`.
    pub fn detect(wide: bool, verbose: bool) -> Layout {
        let width = if wide {
            None
        } else {
            let columns = std::env::var("COLUMNS")
                .ok()
                .and_then(|c| c.trim().parse::<usize>().ok())
                .filter(|&c| c > 0);
            let terminal = || {
                use std::io::IsTerminal;
                std::io::stdout()
                    .is_terminal()
                    .then(|| Table::new().width().map(usize::from))
                    .flatten()
            };
            Some(columns.or_else(terminal).unwrap_or(Self::PIPE_WIDTH))
        };
        Layout { width, verbose }
    }
}

impl Default for Layout {
    /// [`Layout::PIPE_WIDTH`] columns, no legends.
    fn default() -> Self {
        Layout {
            width: Some(Self::PIPE_WIDTH),
            verbose: false,
        }
    }
}

/// `v` and its unit (`0.1085 s`; a pure number without one).
pub(super) fn with_unit(v: f64, sig: usize, unit: &str) -> String {
    match unit {
        "" | "1" => format_number(v, sig),
        _ => format!("{} {unit}", format_number(v, sig)),
    }
}

pub(crate) fn new_table(header: &[&str], layout: &Layout) -> Table {
    let mut t = Table::new();
    t.load_style(presets::UTF8_FULL_CONDENSED)
        .set_header(header.to_vec());
    match layout.width {
        // Wraps the free-text columns (at spaces) so that no line is longer than `width`.
        Some(w) => {
            t.set_content_arrangement(ContentArrangement::Dynamic)
                .set_width(u16::try_from(w).unwrap_or(u16::MAX));
        }
        None => {
            t.set_content_arrangement(ContentArrangement::Disabled);
        }
    }
    t
}

/// Keeps these columns at their content's width (identifiers and numbers must not wrap).
pub(crate) fn no_wrap(t: &mut Table, columns: &[usize]) {
    for &c in columns {
        if let Some(col) = t.column_mut(c) {
            col.set_constraint(ColumnConstraint::ContentWidth);
        }
    }
}

pub(crate) fn align_right(t: &mut Table, columns: &[usize]) {
    for &c in columns {
        if let Some(col) = t.column_mut(c) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
}

/// `text` broken at spaces into lines of at most `width` characters (a longer word stays
/// whole), each line after the first indented by `indent` spaces.
pub(crate) fn wrap(text: &str, width: Option<usize>, indent: usize) -> String {
    let Some(width) = width else {
        return text.to_string();
    };
    let mut out = String::new();
    let mut line_len = 0;
    for word in text.split_whitespace() {
        let len = word.chars().count();
        if line_len > indent && line_len + 1 + len > width {
            out.push('\n');
            out.push_str(&" ".repeat(indent));
            line_len = indent;
        } else if !out.is_empty() {
            out.push(' ');
            line_len += 1;
        }
        out.push_str(word);
        line_len += len;
    }
    out
}

/// A section: its title, the table, and with `verbose` a legend of what each row means.
pub(super) fn section(
    out: &mut String,
    title: &str,
    table: &Table,
    legend: &[(String, String)],
    layout: &Layout,
) {
    out.push_str(&format!("\n{title}\n{table}\n"));
    if layout.verbose && legend.iter().any(|(_, m)| !m.is_empty()) {
        let mut t = new_table(&["", "meaning"], layout);
        for (name, meaning) in legend.iter().filter(|(_, m)| !m.is_empty()) {
            t.add_row(vec![name.clone(), meaning.clone()]);
        }
        no_wrap(&mut t, &[0]);
        out.push_str(&format!("{t}\n"));
    }
}
