//! The report's checks: phase by phase (each phase or impact its own table, in the order they
//! happen) when there are few phases or with `--verbose`; else every failure in full, phase by
//! phase, and the checks that passed in one table, a row per check with the number of phases
//! or impacts it passed in, its worst value (the least room left) and where that was.

use super::layout::{Layout, align_right, new_table, no_wrap, section, with_unit, wrap};
use super::prose;
use crate::results::format_number;
use crate::results::{Check, CheckKind, CheckPhase, RunResults};
use comfy_table::{ColumnConstraint, Width};

/// Most phases and impacts shown phase by phase without `--verbose`.
pub const MAX_PHASE_TABLES: usize = 8;

/// A check's row: its name (the key's last part), status, what was measured, the bound, and
/// when.
fn check_cells(key: &str, c: &Check) -> [String; 5] {
    let name = check_name(key).to_string();
    let status = if c.passed { "pass" } else { "FAIL" }.to_string();
    let (measured, held_to) = measured_and_bound(c);
    let at = c.at_time.map_or(String::new(), |t| with_unit(t, 4, "s"));
    [name, status, measured, held_to, at]
}

/// The key's last part: what the check is, without its phase.
fn check_name(key: &str) -> &str {
    key.rsplit('.').next().unwrap_or(key)
}

/// What a check measured and the bound it is held to, for people.
fn measured_and_bound(c: &Check) -> (String, String) {
    match c.kind {
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
    }
}

/// The checks section: phase by phase, or summarised (see the module's header).
pub fn checks(out: &mut String, results: &RunResults, layout: &Layout) {
    let mut rows: Vec<(&String, &Check)> = results.checks.iter().collect();
    rows.sort_by_key(|(key, c)| (c.order, c.kind != CheckKind::Monitor, key.as_str()));
    let failed = results.checks.values().filter(|c| !c.passed).count();
    let passed = results.checks.len() - failed;
    let mut places: Vec<&CheckPhase> = Vec::new();
    for (_, c) in &rows {
        if places.last() != Some(&&c.phase) {
            places.push(&c.phase);
        }
    }
    if layout.verbose || places.len() <= MAX_PHASE_TABLES {
        out.push_str(&format!(
            "\nChecks ({passed} passed, {failed} failed), phase by phase\n"
        ));
        phase_tables(out, &rows, layout);
        return;
    }
    let impacts = (places.iter())
        .filter(|p| matches!(p, CheckPhase::Impact { .. }))
        .count();
    out.push('\n');
    out.push_str(&wrap(
        &format!(
            "Checks ({passed} passed, {failed} failed) in {} phases and {impacts} impacts: \
             each failure in full, then each check that passed, once, at its worst (--verbose: \
             phase by phase)",
            places.len() - impacts
        ),
        layout.width,
        2,
    ));
    out.push('\n');
    let failures: Vec<(&String, &Check)> =
        rows.iter().copied().filter(|(_, c)| !c.passed).collect();
    if !failures.is_empty() {
        out.push_str("\nFailed:\n");
        phase_tables(out, &failures, layout);
    }
    let passes: Vec<(&String, &Check)> = rows.iter().copied().filter(|(_, c)| c.passed).collect();
    if !passes.is_empty() {
        worst_table(out, &passes, &rows, layout);
    }
}

/// One table per phase or impact, in the order given (all with the same column widths where
/// they fit the line; else each wraps), each row a check; with `verbose`, the meanings.
fn phase_tables(out: &mut String, rows: &[(&String, &Check)], layout: &Layout) {
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
    let total: usize = widths.iter().map(|w| w + 3).sum::<usize>() + 1;
    let fixed = if layout.width.is_some_and(|w| total > w) {
        &[][..]
    } else {
        &widths[..]
    };
    let mut group = 0;
    while group < cells.len() {
        let phase = &cells[group].0.phase;
        let end = cells[group..]
            .iter()
            .position(|(c, _)| &c.phase != phase)
            .map_or(cells.len(), |n| group + n);
        let mut t = new_table(&header, layout);
        let mut legend = Vec::new();
        for (c, row) in &cells[group..end] {
            t.add_row(row.to_vec());
            legend.push((row[0].clone(), prose::check_meaning(c)));
        }
        for (i, w) in fixed.iter().enumerate() {
            if let Some(col) = t.column_mut(i) {
                let w = u16::try_from(*w + 2).unwrap_or(u16::MAX);
                col.set_constraint(ColumnConstraint::LowerBoundary(Width::Fixed(w)));
            }
        }
        align_right(&mut t, &[4]);
        let title = wrap(&format!("{}:", prose::check_phase(phase)), layout.width, 2);
        section(out, &title, &t, &legend, layout);
        group = end;
    }
}

/// Whether a check ran on an impact (its rows count impacts, not phases).
fn on_impact(c: &Check) -> bool {
    matches!(c.phase, CheckPhase::Impact { .. })
}

/// The checks that passed, one row per check (its name and kind, on phases or on impacts):
/// how many times it ran, and the one with the least room left (`margin`), with where (a
/// phase by its number among the phases of `all`, the run's checks).
fn worst_table(
    out: &mut String,
    passes: &[(&String, &Check)],
    all: &[(&String, &Check)],
    layout: &Layout,
) {
    // Groups in the order of their first check.
    let mut groups: Vec<(&str, Vec<&Check>)> = Vec::new();
    for &(key, c) in passes {
        let name = check_name(key);
        let same = |(n, g): &&mut (&str, Vec<&Check>)| {
            *n == name
                && g[0].kind == c.kind
                && g[0].unit == c.unit
                && on_impact(g[0]) == on_impact(c)
        };
        match groups.iter_mut().find(same) {
            Some((_, g)) => g.push(c),
            None => groups.push((name, vec![c])),
        }
    }
    // A phase by its number in the run (its label is the same for many), an impact by its own.
    let mut phase_orders: Vec<usize> = (all.iter())
        .filter(|(_, c)| matches!(c.phase, CheckPhase::Phase(_)))
        .map(|(_, c)| c.order)
        .collect();
    phase_orders.sort_unstable();
    phase_orders.dedup();
    let place = |c: &Check| {
        let at = c
            .at_time
            .map(|t| format!(" at t = {}", with_unit(t, 4, "s")));
        match &c.phase {
            CheckPhase::Phase(_) => {
                let number = phase_orders.binary_search(&c.order).map_or(0, |i| i + 1);
                format!("phase {number}{}", at.unwrap_or_default())
            }
            other => prose::check_phase(other),
        }
    };
    let header = ["check", "passed in", "worst", "held to", "where"];
    let mut t = new_table(&header, layout);
    for (name, group) in &groups {
        let Some(worst) = group
            .iter()
            .copied()
            .min_by(|a, b| a.margin.total_cmp(&b.margin))
        else {
            continue;
        };
        let (count, what) = (
            group.len(),
            if on_impact(worst) { "impact" } else { "phase" },
        );
        let plural = if count == 1 { "" } else { "s" };
        let (measured, held_to) = measured_and_bound(worst);
        t.add_row(vec![
            name.to_string(),
            format!("{count} {what}{plural}"),
            measured,
            held_to,
            place(worst),
        ]);
    }
    no_wrap(&mut t, &[0, 1, 2]);
    out.push_str(&format!("{t}\n"));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::CheckSubject;

    /// A drift check of `name` on phase `order` (an impact on odd orders), held to 1e-12.
    fn check(order: usize, value: f64) -> Check {
        let phase = if order % 2 == 1 {
            CheckPhase::Impact {
                number: order.div_ceil(2),
                t: order as f64,
            }
        } else {
            CheckPhase::Phase("sliding (floor closed)".into())
        };
        Check {
            passed: value <= 1e-12,
            kind: CheckKind::Drift,
            phase,
            order,
            value,
            limit: 1e-12,
            unit: "1".into(),
            margin: 1e-12 - value,
            at_time: None,
            samples: 10,
            subject: CheckSubject::Momentum {
                model: "m".into(),
                name: "momentum_x".into(),
                scale: 1.0,
            },
        }
    }

    #[test]
    fn many_phases_give_the_worst_of_each_check_and_every_failure_in_full() {
        let mut results = RunResults::default();
        for order in 0..40 {
            // The worst pass on phase 10 (the sixth phase), a failure on phase 30 and impact 8.
            let value = match order {
                10 => 9e-13,
                30 | 15 => 5e-12,
                _ => 1e-15 * order as f64,
            };
            results
                .checks
                .insert(format!("p{order}.momentum_x"), check(order, value));
        }
        let mut out = String::new();
        let layout = Layout::default();
        checks(&mut out, &results, &layout);
        assert!(
            out.contains("Checks (38 passed, 2 failed) in 20 phases and 20 impacts"),
            "{out}"
        );
        // The failures, each its own table under its phase, in full.
        assert!(out.contains("\nimpact 8 at t = 15 s:\n"), "{out}");
        assert_eq!(out.matches("FAIL").count(), 2, "{out}");
        assert!(out.contains("drift 5e-12"), "{out}");
        // The passes: one row per check, on phases and on impacts apart, at its worst.
        let row = |what: &str| {
            (out.lines())
                .find(|l| l.contains(what))
                .unwrap_or_else(|| panic!("no {what:?} in\n{out}"))
        };
        let phases = row("19 phases");
        assert!(
            phases.contains("drift 900e-15") && phases.contains("phase 6"),
            "{phases}"
        );
        let impacts = row("19 impacts");
        assert!(impacts.contains("drift 39e-15") && impacts.contains("impact 20 at t = 39 s"));
        assert_eq!(out.matches("│ momentum_x ").count(), 4, "{out}");
        // Few phases, or --verbose: phase by phase, every check.
        let verbose = Layout {
            verbose: true,
            ..Layout::default()
        };
        let mut all = String::new();
        checks(&mut all, &results, &verbose);
        assert!(all.contains("phase by phase"), "{all}");
        let rows = all.matches("┆ pass ").count() + all.matches("┆ FAIL ").count();
        assert_eq!(rows, 40, "{all}");
    }
}
