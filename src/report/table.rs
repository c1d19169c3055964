//! The human report: comfy-table tables of parameters, results (angles also in degrees, the
//! paper's figures beside ours when the scene is the paper's), notes on quantities without a
//! value, checks, series and work; and the `rodcube models` listing.

use crate::model::ModelInfo;
use crate::quantity::{FIXED, Quantity};
use crate::results::RunResults;
use comfy_table::{CellAlignment, ColumnConstraint, ContentArrangement, Table, presets};

/// The paper's published figures (Section 3, three digits), by result key.
pub const PAPER_FIGURES: &[(&str, &str)] = &[
    ("separation_angle", "9.61 deg"),
    ("linearised_separation_angle", "9.59 deg"),
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

/// `v` with `sig` significant digits: plain notation between 1e-4 and 1e7, exponent otherwise.
pub fn format_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let sig = sig.max(1);
    let a = v.abs();
    if (1e-4..1e7).contains(&a) {
        let exponent = a.log10().floor() as i32;
        let decimals = (sig as i32 - 1 - exponent).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.*e}", sig - 1)
    }
}

fn new_table(header: &[&str]) -> Table {
    let mut t = Table::new();
    t.load_style(presets::UTF8_FULL_CONDENSED)
        // Wraps long meanings to the terminal's width on a terminal; one line per row otherwise.
        .set_content_arrangement(ContentArrangement::Dynamic)
        .set_header(header.to_vec());
    t
}

/// Keeps these columns at their content's width (identifiers and numbers must not wrap).
fn no_wrap(t: &mut Table, columns: &[usize]) {
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

fn align_right(t: &mut Table, columns: &[usize]) {
    for &c in columns {
        if let Some(col) = t.column_mut(c) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
}

/// The full report of a run. `info` supplies parameter units and meanings when known.
pub fn render(results: &RunResults, info: Option<&ModelInfo>) -> String {
    let mut out = String::new();
    match info {
        Some(i) => out.push_str(&format!("model {}: {}\n", results.model, i.description)),
        None => out.push_str(&format!("model {}\n", results.model)),
    }

    // Parameters
    let mut t = new_table(&["parameter", "value", "unit", "meaning"]);
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
            format_sig(*value, 12),
            p.map_or("", |p| p.unit).to_string(),
            p.map_or("", |p| p.meaning).to_string(),
        ]);
    }
    align_right(&mut t, &[1]);
    no_wrap(&mut t, &[0, 1, 2]);
    out.push_str(&format!("\nParameters\n{t}\n"));

    // Results
    if !results.results.is_empty() || !results.labels.is_empty() {
        let paper = is_paper_case(results);
        let mut header = vec!["result", "value", "unit", "degrees"];
        if paper {
            header.push("paper");
        }
        header.push("meaning");
        let mut t = new_table(&header);
        let mut rows: Vec<_> = results.results.iter().collect();
        rows.sort_by_key(|(k, _)| result_order(k));
        for (key, s) in rows {
            let mut row = vec![
                key.clone(),
                format_sig(s.value, 12),
                s.unit.to_string(),
                if s.unit == "rad" {
                    format!("{} deg", format_sig(s.value.to_degrees(), 6))
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
            row.push(s.meaning.clone());
            t.add_row(row);
        }
        for (key, label) in &results.labels {
            let mut row = vec![
                key.clone(),
                label.value.clone(),
                String::new(),
                String::new(),
            ];
            if paper {
                row.push(String::new());
            }
            row.push(label.meaning.clone());
            t.add_row(row);
        }
        align_right(&mut t, &[1, 3]);
        no_wrap(
            &mut t,
            if paper {
                &[0, 1, 2, 3, 4]
            } else {
                &[0, 1, 2, 3]
            },
        );
        out.push_str(&format!("\nResults\n{t}\n"));
        if paper {
            out.push_str(
                "paper: the seed paper's Section 3 figures for n = 3, a/ell = 1/4, ell = 1 m, to three \
                 digits (contact_time_to_floor is its eq. 10, point_mass_fall_time its sqrt(a/g); \
                 it does not say whether g is 9.8 or 9.81 m/s^2)\n",
            );
        }
    }

    // Wanted quantities without a value, and why.
    if !results.notes.is_empty() {
        let mut t = new_table(&["quantity", "why it has no value"]);
        for (key, why) in &results.notes {
            t.add_row(vec![key.clone(), why.clone()]);
        }
        no_wrap(&mut t, &[0]);
        out.push_str(&format!("\nNotes\n{t}\n"));
    }

    // Checks
    if !results.checks.is_empty() {
        let mut t = new_table(&["check", "status", "margin", "meaning"]);
        for (name, c) in &results.checks {
            t.add_row(vec![
                name.clone(),
                if c.passed { "pass" } else { "FAIL" }.to_string(),
                format_sig(c.margin, 6),
                c.meaning.clone(),
            ]);
        }
        align_right(&mut t, &[2]);
        no_wrap(&mut t, &[0, 1, 2]);
        let failed = results.checks.values().filter(|c| !c.passed).count();
        out.push_str(&format!(
            "\nChecks ({} passed, {failed} failed)\n{t}\n",
            results.checks.len() - failed
        ));
    }

    // Series
    if !results.series.is_empty() {
        let mut t = new_table(&["series", "points", "columns"]);
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

    // Work
    let w = &results.work;
    let mut t = new_table(&["work", "count"]);
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
        "phases".to_string(),
        if w.phases.is_empty() {
            "-".to_string()
        } else {
            w.phases.join(" -> ")
        },
    ]);
    align_right(&mut t, &[1]);
    out.push_str(&format!("\nWork\n{t}\n"));
    out
}

/// What a quantity means, for the `models` listing.
pub fn quantity_meaning(q: Quantity, info: &ModelInfo) -> String {
    match q {
        Quantity::ForceSeries(i) => {
            format!(
                "t and {} along the motion (N): {}",
                info.forces[i].name, info.forces[i].meaning
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
pub fn models(infos: &[&ModelInfo]) -> String {
    if infos.is_empty() {
        return "no models are generated yet (run `rodcube derive` with the `derive` feature)\n"
            .into();
    }
    let mut out = String::new();
    for (n, info) in infos.iter().enumerate() {
        if n > 0 {
            out.push('\n');
        }
        out.push_str(&format!(
            "{}: {}\n  spec: {}\n",
            info.name, info.description, info.spec
        ));
        let mut t = new_table(&["parameter", "unit", "meaning"]);
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
            let mut t = new_table(&["requirement", "meaning"]);
            for r in info.requirements {
                t.add_row(vec![r.name, r.meaning]);
            }
            out.push_str(&format!("{t}\n"));
        }
        let mut t = new_table(&["quantity (want:)", "meaning"]);
        for q in Quantity::all(info) {
            t.add_row(vec![q.name(info), quantity_meaning(q, info)]);
        }
        out.push_str(&format!("{t}\n"));
    }
    out
}
