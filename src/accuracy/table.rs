//! The accuracy report as text: the references, then one table per model and quantity (short
//! method labels, set-up and per-solve time apart), laid out by `rodcube run`'s rules (the
//! terminal's or `$COLUMNS`' width, 100 columns when piped, no limit with `--wide`), and under
//! `--verbose` a legend of the labels.

use super::settings::describe;
use super::{Measured, Report, Row};
use crate::reference;
use crate::report::table::{Layout, align_right, new_table, no_wrap, wrap};

/// The report's text.
pub fn render(report: &Report, layout: &Layout) -> String {
    let mut out = String::new();
    for (model, r) in &report.references {
        let line = format!(
            "reference {model} {}: theta_sep = {:.17e} rad (root routes agree to {:.1e}), t_sep = {:.17e} sqrt(ell/g) (quadrature routes agree to {:.1e}); both in 256-bit arithmetic",
            r.case.key,
            reference::to_f64(&r.angle),
            r.angle_routes,
            reference::to_f64(&r.time),
            r.time_routes
        );
        out.push_str(&wrap(&line, layout.width, 2));
        out.push('\n');
    }
    for r in &report.integrated {
        out.push_str(&wrap(
            &format!("reference {}", r.describe()),
            layout.width,
            2,
        ));
        out.push('\n');
    }
    let mut blocks: Vec<(&str, Measured)> = Vec::new();
    for r in &report.rows {
        if !blocks.contains(&(r.model, r.measured)) {
            blocks.push((r.model, r.measured));
        }
    }
    for (model, measured) in blocks {
        let rows: Vec<&Row> = (report.rows.iter())
            .filter(|r| r.model == model && r.measured == measured)
            .collect();
        out.push_str(&format!(
            "\n{model}: {}\n{}\n",
            measured.name(),
            block(&rows, layout)
        ));
    }
    out.push_str(&wrap(
        "set-up: made once per setting and reused by every solve (a solver, a rule's nodes, a \
         bound model); per solve: one solve alone, the set-up excluded.",
        layout.width,
        0,
    ));
    out.push('\n');
    if layout.verbose {
        out.push_str(&legend(&report.rows, layout));
    }
    out
}

/// One model's and quantity's table.
fn block(rows: &[&Row], layout: &Layout) -> String {
    let integrated = rows.iter().any(|r| r.steps.is_some());
    let mut header = vec!["case", "method", "setting", "rel. error", "evals"];
    if integrated {
        header[4] = "RHS";
        header.push("steps");
    }
    header.extend(["set-up", "per solve"]);
    let mut t = new_table(&header, layout);
    for r in rows {
        let error = if r.error.is_nan() {
            format!("failed: {}", r.note)
        } else {
            format!("{:.1e}", r.error.abs())
        };
        let failed = r.error.is_nan();
        let mut cells = vec![
            r.case.to_string(),
            r.label.to_string(),
            r.setting.clone(),
            error,
            if failed {
                "-".into()
            } else {
                r.evals.to_string()
            },
        ];
        if integrated {
            cells.push(r.steps.map_or("-".into(), |s| s.to_string()));
        }
        cells.push(r.setup_seconds.map_or("-".into(), format_seconds));
        cells.push(if failed {
            "-".into()
        } else {
            format_seconds(r.seconds)
        });
        t.add_row(cells);
    }
    let numbers: Vec<usize> = (4..header.len()).collect();
    align_right(&mut t, &numbers);
    let mut fixed = vec![0, 1, 2];
    fixed.extend(&numbers);
    no_wrap(&mut t, &fixed);
    t.to_string()
}

/// The labels used, each with what it is.
fn legend(rows: &[Row], layout: &Layout) -> String {
    let mut labels: Vec<&str> = Vec::new();
    for r in rows {
        if !labels.contains(&r.label) {
            labels.push(r.label);
        }
    }
    let mut out = String::from("\nmethods:\n");
    for l in labels {
        out.push_str(&wrap(&format!("  {l}: {}", describe(l)), layout.width, 4));
        out.push('\n');
    }
    out
}

/// `1.2 us`, `3.4 ms`, `0.56 s`.
pub fn format_seconds(s: f64) -> String {
    if s < 1e-6 {
        format!("{:.0} ns", s * 1e9)
    } else if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}
