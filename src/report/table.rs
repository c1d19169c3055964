//! The human report: comfy-table tables of parameters, results (angles also in degrees, the
//! paper's figures beside ours when the scene is the paper's), impacts, notes on quantities
//! without a value, checks, series and work; and the `rodcube models` listing.

pub use super::layout::Layout;
pub(crate) use super::layout::{align_right, new_table, no_wrap, wrap};
use super::layout::{section, with_unit};
use crate::model::ModelInfo;
use crate::quantity::{FIXED, Quantity};
pub use crate::results::format_number;
use crate::results::{ContactImpulse, ImpactRecord, LabelValue, RunResults};
use comfy_table::{Cell, CellAlignment, ColumnConstraint, Width};

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
        super::checks::checks(&mut out, results, layout);
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

/// Most stretches of a label listed one by one without `--verbose`.
pub const MAX_STRETCHES_LISTED: usize = 4;

/// A label's cell: its value ([`super::prose::label`]); without `verbose`, a sequence of more
/// than [`MAX_STRETCHES_LISTED`] stretches as its modes with repeats counted, within three
/// lines of the cell.
fn label_cell(value: &LabelValue, layout: &Layout) -> String {
    match value {
        LabelValue::Stretches(stretches)
            if !layout.verbose && stretches.len() > MAX_STRETCHES_LISTED =>
        {
            let sets: Vec<String> = stretches.iter().map(|s| s.set.to_string()).collect();
            let modes: Vec<&str> = sets.iter().map(String::as_str).collect();
            let budget = layout.width.map(|w| 3 * w.saturating_sub(40).max(20));
            format!(
                "{} ({} stretches; --verbose: when each began)",
                super::sequence::summarise(&modes, " -> ", budget),
                stretches.len()
            )
        }
        other => super::prose::label(other),
    }
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
            label_cell(&label.value, layout),
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

/// Most impacts listed without `--verbose`: more are shown as the first and the last
/// [`IMPACTS_AT_EACH_END`], with how many are left out between them.
pub const MAX_IMPACTS_LISTED: usize = 12;

/// Impacts shown at each end of a long list.
pub const IMPACTS_AT_EACH_END: usize = 5;

/// Whether the impacts table shows the part of an impact's energy loss its friction took: where
/// it is more than rounding (1e-9 of the whole loss; `impacts.csv` and the JSON always hold it).
fn friction_shown(r: &ImpactRecord) -> bool {
    let f = r.friction_energy_lost;
    f.abs() > 1e-9 * r.energy_lost.abs()
}

/// A contact's impulse in the impacts table (its unit in the cell unless the header holds it:
/// `shared`), its friction's beside it where it has one.
fn impulse_cell(c: &ContactImpulse, shared: Option<&str>) -> String {
    let cell = |v: f64| match shared {
        Some(_) => format_number(v, 6),
        None => with_unit(v, 6, c.impulse_unit),
    };
    if c.tangential_impulse == 0.0 {
        cell(c.impulse)
    } else {
        format!("{}, {}", cell(c.impulse), cell(c.tangential_impulse))
    }
}

/// The impacts: one row per contact taking part in each impact, the closing one marked `*`;
/// the impact's time and energy lost on its first row, `(Zeno)` beside the energy of an impact
/// that closed a converging sequence of bounces. A unit that every row shares is in the header,
/// else in each cell. Without `verbose`, a list longer than [`MAX_IMPACTS_LISTED`] shows its
/// ends. A line of legend says what the marks mean (another for the Zeno mark, when there is
/// one); with `verbose`, what the table is.
fn impacts(out: &mut String, list: &[ImpactRecord], layout: &Layout) {
    let contacts = || list.iter().flat_map(|r| &r.per_contact);
    let shared = |unit: fn(&ContactImpulse) -> &str| {
        let first = contacts().next().map(unit);
        first.filter(|u| contacts().all(|c| unit(c) == *u))
    };
    let velocity_unit = shared(|c| c.velocity_unit);
    let impulse_unit = shared(|c| c.impulse_unit);
    let in_cell = |v: f64, unit: &str, shared: Option<&str>| match shared {
        Some(_) => format_number(v, 6),
        None => with_unit(v, 6, unit),
    };
    let shown: Vec<Option<&ImpactRecord>> = if layout.verbose || list.len() <= MAX_IMPACTS_LISTED {
        list.iter().map(Some).collect()
    } else {
        let end = IMPACTS_AT_EACH_END;
        let head = list[..end].iter().map(Some);
        head.chain([None])
            .chain(list[list.len() - end..].iter().map(Some))
            .collect()
    };
    let mut rows: Vec<[String; 6]> = Vec::new();
    for r in shown {
        let Some(r) = r else {
            let left = list.len() - 2 * IMPACTS_AT_EACH_END;
            let gap = format!("… {left} more (--verbose, impacts.csv)");
            rows.push([
                "…".into(),
                gap,
                String::new(),
                String::new(),
                String::new(),
                "…".into(),
            ]);
            continue;
        };
        let mut time = format_number(r.time, 6);
        let mut energy = format_number(r.energy_lost, 6);
        if friction_shown(r) {
            energy.push_str(&format!(
                " (friction {})",
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
                in_cell(c.normal_velocity_before, c.velocity_unit, velocity_unit),
                in_cell(c.normal_velocity_after, c.velocity_unit, velocity_unit),
                impulse_cell(c, impulse_unit),
                std::mem::take(&mut energy),
            ]);
        }
    }
    let titled = |title: &str, unit: Option<&str>| match unit {
        Some(u) => format!("{title} ({u})"),
        None => title.to_string(),
    };
    let header = [
        "t (s)".to_string(),
        "contact".to_string(),
        titled("v before", velocity_unit),
        titled("v after", velocity_unit),
        titled("impulse", impulse_unit),
        "energy lost (J)".to_string(),
    ];
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = new_table(&header, layout);
    let mut widths = [0usize; 6];
    for row in rows {
        // The gap's words may wrap; the names and numbers never do.
        if row[0] != "…" {
            for (w, cell) in widths.iter_mut().zip(&row) {
                *w = (*w).max(cell.chars().count());
            }
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
        legend.push("impulse a, b: the normal impulse a and its friction's tangential impulse b");
    }
    if list.iter().any(friction_shown) {
        legend.push(
            "energy lost (friction f): f of it taken by the tangential impulses, the rest by the \
             normal ones (shown where above 1e-9 of the whole; impacts.csv: always)",
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
    let phases: Vec<&str> = w.phases.iter().map(String::as_str).collect();
    let phases = if phases.is_empty() {
        "-".to_string()
    } else if layout.verbose {
        phases.join(" -> ")
    } else {
        // Three lines of the cell at most (its column: the width less `ODE right-hand sides`
        // and the borders).
        let budget = layout.width.map(|w| 3 * w.saturating_sub(28).max(20));
        super::sequence::summarise(&phases, " -> ", budget)
    };
    align_right(&mut t, &[1]);
    t.add_row(vec![
        Cell::new("phases"),
        Cell::new(phases).set_alignment(CellAlignment::Left),
    ]);
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
