//! The accuracy–time plots: for one measured quantity, one log–log panel per case of relative
//! error against time per solve, one line per method through its settings, and the Pareto
//! front (no other setting is both faster and more accurate) circled and joined by a dashed
//! staircase. A last panel holds the legend.

use super::{AccuracyError, ERROR_FLOOR, Measured, Row};
use plotters::prelude::*;

const FONT: &str = "sans-serif";
const PANEL_W: u32 = 700;
const PANEL_H: u32 = 480;

const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(255, 127, 14),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// `(seconds, error)` of the non-dominated points, fastest first: each is more accurate than
/// every faster one.
pub fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(t, e)| t.is_finite() && *t > 0.0 && e.is_finite())
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if out.last().is_none_or(|l| q.1 < l.1) {
            out.push(q);
        }
    }
    out
}

/// The SVG for one measured quantity over its cases, or `None` when nothing succeeded.
pub fn svg(measured: Measured, model: &str, rows: &[Row]) -> Result<Option<String>, AccuracyError> {
    draw(measured, model, rows).map_err(|e| AccuracyError::Plot {
        message: e.to_string(),
    })
}

fn draw(
    measured: Measured,
    model: &str,
    rows: &[Row],
) -> Result<Option<String>, Box<dyn std::error::Error>> {
    let rows: Vec<&Row> = (rows.iter())
        .filter(|r| r.measured == measured && r.model == model)
        .collect();
    let mut cases: Vec<&str> = Vec::new();
    let mut methods: Vec<&str> = Vec::new();
    for r in &rows {
        if !cases.contains(&r.case) {
            cases.push(r.case);
        }
        if !methods.contains(&r.label) {
            methods.push(r.label);
        }
    }
    let ok = |r: &&&Row| r.error.is_finite() && r.seconds > 0.0;
    if !rows.iter().any(|r| ok(&r)) {
        return Ok(None);
    }
    let point = |r: &Row| (r.seconds, r.error.abs().max(ERROR_FLOOR));
    let (mut t_lo, mut t_hi) = (f64::INFINITY, 0.0f64);
    let mut e_hi = ERROR_FLOOR;
    for r in rows.iter().filter(ok) {
        let (t, e) = point(r);
        t_lo = t_lo.min(t);
        t_hi = t_hi.max(t);
        e_hi = e_hi.max(e);
    }
    let t_range = (t_lo / 2.0, t_hi * 2.0);
    let e_range = (ERROR_FLOOR / 3.0, (e_hi * 3.0).max(1e-2));
    let cols = 2u32;
    let cells = cases.len() as u32 + 1;
    let rows_n = cells.div_ceil(cols);
    let (w, h) = (PANEL_W * cols, PANEL_H * rows_n + 50);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let title = format!(
            "{model}: {} - relative error vs time per solve (errors below {ERROR_FLOOR:.0e} drawn at it; circles: Pareto front)",
            measured.name()
        );
        let root = root.titled(&title, (FONT, 20))?;
        let areas = root.split_evenly((rows_n as usize, cols as usize));
        for (case, area) in cases.iter().zip(&areas) {
            let mut chart = ChartBuilder::on(area)
                .caption(*case, (FONT, 17))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(
                    (t_range.0..t_range.1).log_scale(),
                    (e_range.0..e_range.1).log_scale(),
                )?;
            chart
                .configure_mesh()
                .x_desc("time per solve (s)")
                .y_desc("relative error")
                .axis_desc_style((FONT, 14))
                .label_style((FONT, 12))
                .x_label_formatter(&|v| format!("{v:.0e}"))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()?;
            let here: Vec<&Row> = rows
                .iter()
                .copied()
                .filter(|r| r.case == *case)
                .filter(|r| r.error.is_finite() && r.seconds > 0.0)
                .collect();
            for (k, method) in methods.iter().enumerate() {
                let color = COLORS[k % COLORS.len()];
                let mut pts: Vec<(f64, f64)> = here
                    .iter()
                    .filter(|r| r.label == *method)
                    .map(|r| point(r))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart.draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?;
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
            }
            let all: Vec<(f64, f64)> = here.iter().map(|r| point(r)).collect();
            let front = pareto(&all);
            let mut stairs = Vec::new();
            for (i, &p) in front.iter().enumerate() {
                if i > 0 {
                    stairs.push((p.0, front[i - 1].1));
                }
                stairs.push(p);
            }
            chart.draw_series(DashedLineSeries::new(stairs, 6, 4, BLACK.stroke_width(1)))?;
            chart.draw_series(
                front
                    .iter()
                    .map(|&p| Circle::new(p, 7, BLACK.stroke_width(2))),
            )?;
        }
        // The legend in the next free cell.
        if let Some(area) = areas.get(cases.len()) {
            for (k, method) in methods.iter().enumerate() {
                let y = 30 + 28 * k as i32;
                let color = COLORS[k % COLORS.len()];
                area.draw(&PathElement::new(
                    vec![(30, y), (80, y)],
                    color.stroke_width(3),
                ))?;
                area.draw(&Circle::new((55, y), 3, color.filled()))?;
                area.draw(&Text::new(
                    method.to_string(),
                    (95, y - 8),
                    (FONT, 15).into_font(),
                ))?;
            }
            let y = 30 + 28 * methods.len() as i32;
            area.draw(&Circle::new((55, y), 7, BLACK.stroke_width(2)))?;
            area.draw(&Text::new(
                "Pareto front (dashed: its staircase)",
                (95, y - 8),
                (FONT, 15).into_font(),
            ))?;
        }
        root.present()?;
    }
    Ok(Some(buf))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_keeps_only_points_no_faster_point_beats() {
        let pts = [
            (1.0, 1e-3),
            (2.0, 1e-6),
            (3.0, 1e-5),
            (0.5, 1e-2),
            (4.0, 1e-9),
        ];
        assert_eq!(
            pareto(&pts),
            vec![(0.5, 1e-2), (1.0, 1e-3), (2.0, 1e-6), (4.0, 1e-9)]
        );
    }
}
