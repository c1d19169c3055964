//! The human report: comfy-table tables of parameters, results (angles also in degrees, the
//! paper's figures beside ours when the scene is the paper's), impacts, notes on quantities
//! without a value, checks, series and work; and the `rodcube models` listing.

use crate::model::ModelInfo;
use crate::quantity::{FIXED, Quantity};
pub use crate::results::format_number;
use crate::results::{Check, CheckKind, ContactImpulse, ImpactRecord, RunResults};
use comfy_table::{CellAlignment, ColumnConstraint, ContentArrangement, Table, Width, presets};

/// The paper's published figures (Section 3, three digits), by result key.
pub const PAPER_FIGURES: &[(&str, &str)] = &[
    ("separation_angle", "9.61°"),
    ("linearised_separation_angle", "9.59°"),
    ("separation_time", "0.108 s"),
    ("contact_time_to_floor", "0.187 s"),
    ("point_mass_fall_time", "0.159 s"),
];

/// Whether these results are for the paper's case: model `rod_cube` with `m2/m1 = 3`,
/// `a/ell = 1/4`, `ell = 1 m` and `g` between 9.8 and 9.81 m/s^2 (the paper does not say
/// which; its three digits fit both).
pub fn is_paper_case(results: &RunResults) -> bool {
    let p = |k: &str| results.parameters.get(k).copied();
    let (Some(m1), Some(m2), Some(ell), Some(a), Some(g)) =
        (p("m1"), p("m2"), p("ell"), p("a"), p("g"))
    else {
        return false;
    };
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y.abs();
    results.model == "rod_cube"
        && close(m2 / m1, 3.0)
        && close(a / ell, 0.25)
        && close(ell, 1.0)
        && (9.8 - 1e-9..=9.81 + 1e-9).contains(&g)
}

/// How wide the report may be, and how much it says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Largest line length in characters; `None` for no limit (`--wide`).
    pub width: Option<usize>,
    /// Whether each table is followed by a legend with the meaning of every row.
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
fn with_unit(v: f64, sig: usize, unit: &str) -> String {
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

/// Result keys in the order of the quantity vocabulary (the paper's order), then the rest
/// alphabetically.
fn result_order(key: &str) -> (usize, &str) {
    (
        FIXED
            .iter()
            .position(|(n, _, _)| *n == key)
            .unwrap_or(FIXED.len()),
        key,
    )
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
fn section(
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

/// The full report of a run. `info` supplies parameter units and meanings when known.
pub fn render(results: &RunResults, info: Option<&ModelInfo>, layout: &Layout) -> String {
    let mut out = match info {
        Some(i) => wrap(
            &format!("model {}: {}", results.model, i.description),
            layout.width,
            2,
        ),
        None => format!("model {}", results.model),
    };
    out.push('\n');
    parameters(&mut out, results, info, layout);
    if !results.results.is_empty() || !results.labels.is_empty() {
        scalars(&mut out, results, layout);
    }
    if let Some(list) = results.impacts.as_deref().filter(|l| !l.is_empty()) {
        impacts(&mut out, list, layout);
    }
    // Wanted quantities without a value and why, and what the motion's end and its impacts
    // need said.
    if !results.notes.is_empty() {
        let mut t = new_table(&["about", "note"], layout);
        for (key, why) in &results.notes {
            t.add_row(vec![key.clone(), super::prose::note(why)]);
        }
        no_wrap(&mut t, &[0]);
        out.push_str(&format!("\nNotes\n{t}\n"));
    }
    if !results.checks.is_empty() {
        checks(&mut out, results, layout);
    }
    series(&mut out, results, layout);
    work(&mut out, results, layout);
    if !layout.verbose {
        out.push_str("\nEach row's meaning: rodcube run --verbose. Units are SI; angles in rad.\n");
    }
    out
}

fn parameters(out: &mut String, results: &RunResults, info: Option<&ModelInfo>, layout: &Layout) {
    let mut t = new_table(&["parameter", "value", "unit", "meaning"], layout);
    // In the model's order when it is known, else by name.
    let mut rows: Vec<(&String, &f64)> = results.parameters.iter().collect();
    if let Some(i) = info {
        rows.sort_by_key(|(n, _)| {
            i.parameters
                .iter()
                .position(|p| p.name == n.as_str())
                .unwrap_or(usize::MAX)
        });
    }
    for (name, value) in rows {
        let p = info.and_then(|i| i.parameters.iter().find(|p| p.name == name));
        t.add_row(vec![
            name.clone(),
            format_number(*value, 12),
            p.map_or("", |p| p.unit).to_string(),
            p.map_or("", |p| p.meaning).to_string(),
        ]);
    }
    align_right(&mut t, &[1]);
    no_wrap(&mut t, &[0, 1, 2]);
    out.push_str(&format!("\nParameters\n{t}\n"));
}

fn scalars(out: &mut String, results: &RunResults, layout: &Layout) {
    let paper = is_paper_case(results);
    let mut header = vec!["result", "value", "unit", "degrees"];
    if paper {
        header.push("paper");
    }
    let mut t = new_table(&header, layout);
    let mut legend = Vec::new();
    let mut rows: Vec<_> = results.results.iter().collect();
    rows.sort_by_key(|(k, _)| result_order(k));
    for (key, s) in rows {
        let mut row = vec![
            key.clone(),
            format_number(s.value, 12),
            if s.unit == "1" { "" } else { s.unit }.to_string(),
            if s.unit == "rad" {
                format!("{}°", format_number(s.value.to_degrees(), 6))
            } else {
                String::new()
            },
        ];
        if paper {
            let fig = PAPER_FIGURES
                .iter()
                .find(|(k, _)| k == key)
                .map_or("", |(_, f)| f);
            row.push(fig.to_string());
        }
        t.add_row(row);
        legend.push((key.clone(), super::prose::meaning(&s.meaning)));
    }
    for (key, label) in &results.labels {
        let mut row = vec![
            key.clone(),
            super::prose::label(&label.value),
            String::new(),
            String::new(),
        ];
        if paper {
            row.push(String::new());
        }
        t.add_row(row);
        legend.push((key.clone(), super::prose::meaning(&label.meaning)));
    }
    align_right(&mut t, &[1, 3]);
    no_wrap(&mut t, if paper { &[0, 2, 3, 4] } else { &[0, 2, 3] });
    section(out, "Results", &t, &legend, layout);
    if paper {
        out.push_str(&wrap(
            "paper: the seed paper's Section 3 figures for n = 3, a/ell = 1/4, ell = 1 m, to three \
             digits (contact_time_to_floor is its eq. 10, point_mass_fall_time its sqrt(a/g); \
             it does not say whether g is 9.8 or 9.81 m/s^2)",
            layout.width,
            7,
        ));
        out.push('\n');
    }
}

/// A contact's impulse in the impacts table, its friction's beside it where it has one.
fn impulse_cell(c: &ContactImpulse) -> String {
    let normal = with_unit(c.impulse, 6, c.impulse_unit);
    if c.tangential_impulse == 0.0 {
        normal
    } else {
        format!(
            "{normal}, {}",
            with_unit(c.tangential_impulse, 6, c.impulse_unit)
        )
    }
}

/// The impacts: one row per contact taking part in each impact, the closing one marked `*`;
/// the impact's time and energy lost on its first row, `(Zeno)` beside the energy of an impact
/// that closed a converging sequence of bounces. A line of legend says what the marks mean
/// (another for the Zeno mark, when there is one); with `verbose`, what the table is.
fn impacts(out: &mut String, list: &[ImpactRecord], layout: &Layout) {
    let mut rows: Vec<[String; 6]> = Vec::new();
    for r in list {
        let mut time = format_number(r.time, 6);
        let mut energy = format_number(r.energy_lost, 6);
        if r.friction_energy_lost != 0.0 {
            energy.push_str(&format!(
                " (normal {}, friction {})",
                format_number(r.normal_energy_lost, 6),
                format_number(r.friction_energy_lost, 6)
            ));
        }
        if r.zeno_limit {
            energy.push_str(" (Zeno)");
        }
        let mark = |contact: &str| {
            if contact == r.closing {
                format!("{contact} *")
            } else {
                contact.to_string()
            }
        };
        if r.per_contact.is_empty() {
            let blank = String::new;
            rows.push([time, mark(&r.closing), blank(), blank(), blank(), energy]);
            continue;
        }
        for c in &r.per_contact {
            rows.push([
                std::mem::take(&mut time),
                mark(&c.contact),
                with_unit(c.normal_velocity_before, 6, c.velocity_unit),
                with_unit(c.normal_velocity_after, 6, c.velocity_unit),
                impulse_cell(c),
                std::mem::take(&mut energy),
            ]);
        }
    }
    let header = [
        "t (s)",
        "contact",
        "v before",
        "v after",
        "impulse",
        "energy lost (J)",
    ];
    let mut t = new_table(&header, layout);
    let mut widths = [0usize; 6];
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(&row) {
            *w = (*w).max(cell.chars().count());
        }
        t.add_row(row.to_vec());
    }
    // Names and numbers never wrap (a narrow terminal wraps the headers, or the table runs
    // past its width).
    for (i, w) in widths.iter().enumerate() {
        if let Some(col) = t.column_mut(i) {
            let w = u16::try_from(*w + 2).unwrap_or(u16::MAX);
            col.set_constraint(ColumnConstraint::LowerBoundary(Width::Fixed(w)));
        }
    }
    align_right(&mut t, &[0, 2, 3, 4, 5]);
    out.push_str(&format!("\nImpacts ({})\n{t}\n", list.len()));
    let mut legend = vec![
        "* the contact whose gap closed; v: a contact's normal velocity (negative: approaching)",
    ];
    if list
        .iter()
        .any(|r| r.per_contact.iter().any(|c| c.tangential_impulse != 0.0))
    {
        legend.push(
            "impulse a, b: the normal impulse a and its friction's tangential impulse b; energy \
             lost (normal, friction): what the normal and the tangential impulses took",
        );
    }
    if list.iter().any(|r| r.zeno_limit) {
        legend
            .push("(Zeno): the limit of a converging sequence of bounces, at its accumulation time: the last bounce resolved made plastic");
    }
    for line in legend {
        out.push_str(&wrap(line, layout.width, 2));
        out.push('\n');
    }
    if layout.verbose {
        out.push_str(&wrap(super::json::IMPACTS_MEANING, layout.width, 2));
        out.push('\n');
    }
}

/// Checks grouped by phase, in the order the phases happen (each group its own table, all with
/// the same column widths); each with what it measured, in its own unit, the bound it is held
/// to and, for a monitor, when it came closest.
fn checks(out: &mut String, results: &RunResults, layout: &Layout) {
    let mut rows: Vec<(&String, &Check)> = results.checks.iter().collect();
    rows.sort_by_key(|(key, c)| (c.order, c.kind != CheckKind::Monitor, key.as_str()));
    let cells: Vec<(&Check, [String; 5])> = rows
        .iter()
        .map(|(key, c)| (*c, check_cells(key, c)))
        .collect();
    let header = ["check", "status", "measured", "held to", "at t"];
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for (_, row) in &cells {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let failed = results.checks.values().filter(|c| !c.passed).count();
    out.push_str(&format!(
        "\nChecks ({} passed, {failed} failed), phase by phase\n",
        results.checks.len() - failed
    ));
    let mut legend = Vec::new();
    let mut group = 0;
    while group < cells.len() {
        let phase = &cells[group].0.phase;
        let end = cells[group..]
            .iter()
            .position(|(c, _)| &c.phase != phase)
            .map_or(cells.len(), |n| group + n);
        let mut t = new_table(&header, layout);
        for (c, row) in &cells[group..end] {
            t.add_row(row.to_vec());
            legend.push((row[0].clone(), super::prose::check_meaning(c)));
        }
        // The same widths in every group, where they fit the line; else each group wraps.
        let total: usize = widths.iter().map(|w| w + 3).sum::<usize>() + 1;
        let fixed = if layout.width.is_some_and(|w| total > w) {
            &[][..]
        } else {
            &widths[..]
        };
        for (i, w) in fixed.iter().enumerate() {
            if let Some(col) = t.column_mut(i) {
                let w = u16::try_from(*w + 2).unwrap_or(u16::MAX);
                col.set_constraint(ColumnConstraint::LowerBoundary(Width::Fixed(w)));
            }
        }
        align_right(&mut t, &[4]);
        section(
            out,
            &wrap(
                &format!("{}:", super::prose::check_phase(phase)),
                layout.width,
                2,
            ),
            &t,
            &legend,
            layout,
        );
        legend.clear();
        group = end;
    }
}

/// A check's row: name, status, what was measured, the bound, and when.
fn check_cells(key: &str, c: &Check) -> [String; 5] {
    let name = key.rsplit('.').next().unwrap_or(key).to_string();
    let status = if c.passed { "pass" } else { "FAIL" }.to_string();
    let (measured, held_to) = match c.kind {
        CheckKind::Monitor => (
            format!("min {}", with_unit(c.value, 5, &c.unit)),
            format!(">= {}", with_unit(c.limit, 3, &c.unit)),
        ),
        CheckKind::Drift => (
            format!("drift {}", format_number(c.value, 3)),
            format!("<= {}", format_number(c.limit, 3)),
        ),
        CheckKind::Identity => (
            format!("drift {}", format_number(c.value, 3)),
            format!("<= {} (built in)", format_number(c.limit, 3)),
        ),
    };
    let at = c.at_time.map_or(String::new(), |t| with_unit(t, 4, "s"));
    [name, status, measured, held_to, at]
}

fn series(out: &mut String, results: &RunResults, layout: &Layout) {
    if results.series.is_empty() {
        return;
    }
    let mut t = new_table(&["series", "points", "columns"], layout);
    for (name, s) in &results.series {
        let points = s.columns.first().map_or(0, |c| c.values.len());
        let columns: Vec<String> = s
            .columns
            .iter()
            .map(|c| super::csv::header(&c.name, c.unit))
            .collect();
        t.add_row(vec![name.clone(), points.to_string(), columns.join(", ")]);
    }
    align_right(&mut t, &[1]);
    no_wrap(&mut t, &[0, 1]);
    out.push_str(&format!("\nSeries\n{t}\n"));
}

fn work(out: &mut String, results: &RunResults, layout: &Layout) {
    let w = &results.work;
    let mut t = new_table(&["work", "count"], layout);
    t.add_row(vec![
        "polynomial evaluations".to_string(),
        w.polynomial_evals.to_string(),
    ]);
    t.add_row(vec![
        "integrand evaluations".to_string(),
        w.integrand_evals.to_string(),
    ]);
    t.add_row(vec!["ODE steps".to_string(), w.ode_steps.to_string()]);
    t.add_row(vec![
        "ODE right-hand sides".to_string(),
        w.ode_evaluations.to_string(),
    ]);
    t.add_row(vec![
        "phases".to_string(),
        if w.phases.is_empty() {
            "-".to_string()
        } else {
            w.phases.join(" -> ")
        },
    ]);
    align_right(&mut t, &[1]);
    out.push_str(&format!("\nWork\n{t}\n"));
}

/// What a quantity means, for the `models` listing.
pub fn quantity_meaning(q: Quantity, info: &ModelInfo) -> String {
    match q {
        Quantity::ForceSeries(i) => {
            let c = &info.contacts[i];
            format!(
                "t and {} along the motion ({}): {}",
                c.name, c.unit, c.meaning
            )
        }
        Quantity::Trajectory(i) => format!(
            "path of {}: {}",
            info.points[i].name, info.points[i].meaning
        ),
        q => FIXED
            .iter()
            .find(|(_, f, _)| *f == q)
            .map_or(String::new(), |(_, _, m)| m.to_string()),
    }
}

/// The `rodcube models` listing: each model with its parameters and the quantities it offers.
pub fn models(infos: &[&ModelInfo], layout: &Layout) -> String {
    if infos.is_empty() {
        return "no models are generated yet (run `rodcube derive` with the `derive` feature)\n"
            .into();
    }
    let mut out = String::new();
    for (n, info) in infos.iter().enumerate() {
        if n > 0 {
            out.push('\n');
        }
        out.push_str(&wrap(
            &format!("{}: {}", info.name, info.description),
            layout.width,
            2,
        ));
        out.push_str(&format!("\n  spec: {}\n", info.spec));
        // A contact with a restitution other than the plastic default says which.
        let contacts: Vec<String> = (info.contacts.iter())
            .map(|c| match c.restitution {
                "0" => c.name.to_string(),
                e => format!("{} (restitution {e})", c.name),
            })
            .collect();
        if !contacts.is_empty() {
            out.push_str("  ");
            out.push_str(&wrap(
                &format!("contacts: {}", contacts.join(", ")),
                layout.width.map(|w| w.saturating_sub(2)),
                2,
            ));
            out.push('\n');
        }
        let phases: Vec<String> = (info.phases.iter())
            .map(|p| {
                let closed: Vec<&str> = (p.closed.iter())
                    .filter_map(|&i| info.contacts.get(i).map(|c| c.name))
                    .collect();
                let closed = if closed.is_empty() {
                    "nothing".to_string()
                } else {
                    closed.join(", ")
                };
                format!("{} ({closed} closed)", p.model)
            })
            .collect();
        if !phases.is_empty() {
            out.push_str("  ");
            out.push_str(&wrap(
                &format!("fast phases: {}", phases.join("; ")),
                layout.width.map(|w| w.saturating_sub(2)),
                2,
            ));
            out.push('\n');
        }
        let mut t = new_table(&["parameter", "unit", "meaning"], layout);
        for p in info.parameters {
            let meaning = if p.positive {
                format!("{} (must be > 0)", p.meaning)
            } else {
                p.meaning.to_string()
            };
            t.add_row(vec![p.name.to_string(), p.unit.to_string(), meaning]);
        }
        out.push_str(&format!("{t}\n"));
        if !info.requirements.is_empty() {
            let mut t = new_table(&["requirement", "meaning"], layout);
            for r in info.requirements {
                t.add_row(vec![r.name, r.meaning]);
            }
            out.push_str(&format!("{t}\n"));
        }
        let mut t = new_table(&["quantity (want:)", "meaning"], layout);
        for q in Quantity::all(info) {
            t.add_row(vec![q.name(info), quantity_meaning(q, info)]);
        }
        out.push_str(&format!("{t}\n"));
    }
    out
}
