//! SVG plots of series with plotters: a series with a time column becomes stacked panels (one
//! per other column, angles in degrees) against `t`; a trajectory becomes a y–x path drawn with
//! equal scales on both axes, so its shape is not distorted.
//!
//! For the paper's scene this gives its figures: `theta_series.svg` (Figure 2, top panel),
//! `contact_force_series.svg` (Figure 3) and `tip_trajectory.svg` (Figure 4, which is nearly a
//! vertical line because the tip's ellipse is eight times narrower than tall).

use super::Error;
use crate::results::{Column, Series};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Width of every plot in pixels.
pub const WIDTH: u32 = 900;
/// Height of one time panel in pixels.
pub const PANEL_HEIGHT: u32 = 300;
/// Height of a trajectory plot in pixels.
pub const TRAJECTORY_HEIGHT: u32 = 700;
/// At most this many panels per series (the first columns after time).
pub const MAX_PANELS: usize = 6;

/// Drawing is done at this multiple of the declared size and scaled down by the viewer: the SVG
/// backend rounds coordinates to whole units, which makes curves visibly stepped at 1x.
const SCALE: u32 = 2;
/// Height of the title above the panels (display pixels).
const CAPTION: u32 = 40;
const FONT: &str = "sans-serif";

/// Dark, distinguishable line colours (one per panel).
const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(255, 127, 14),
];

/// A size in drawing units.
const fn px(v: u32) -> u32 {
    v * SCALE
}

/// Declares the display size (`width` x `height`) on an SVG drawn at [`SCALE`] times it; the
/// `viewBox` keeps the drawing units.
fn declare_size(svg: String, width: u32, height: u32) -> String {
    let drawn = format!("width=\"{}\" height=\"{}\"", px(width), px(height));
    svg.replacen(&drawn, &format!("width=\"{width}\" height=\"{height}\""), 1)
}

/// What a series looks like to the plotter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A trajectory: indices of its `x` and `y` columns.
    Trajectory {
        /// Index of the horizontal coordinate column.
        x: usize,
        /// Index of the vertical coordinate column.
        y: usize,
    },
    /// A time series: the index of the time column.
    Time {
        /// Index of the time column.
        t: usize,
    },
    /// Nothing to plot.
    None,
}

/// Classifies a series: a trajectory if it has `x` and `y` columns (or `<p>_x`, `<p>_y`),
/// else a time series if one column is `t` (or `time`), else nothing.
pub fn shape(series: &Series) -> Shape {
    let find = |axis: &str| {
        series.columns.iter().position(|c| {
            c.name == axis
                || c.name.ends_with(&format!("_{axis}"))
                || c.name.ends_with(&format!(".{axis}"))
        })
    };
    if let (Some(x), Some(y)) = (find("x"), find("y")) {
        return Shape::Trajectory { x, y };
    }
    match series
        .columns
        .iter()
        .position(|c| c.name == "t" || c.name == "time")
    {
        Some(t) if series.columns.len() > 1 => Shape::Time { t },
        _ => Shape::None,
    }
}

/// A column's values and unit as plotted: radians become degrees.
pub fn display_column(c: &Column) -> (Vec<f64>, &'static str) {
    if c.unit == "rad" {
        (c.values.iter().map(|v| v.to_degrees()).collect(), "deg")
    } else {
        (c.values.clone(), c.unit)
    }
}

/// An axis label: `theta (deg)`.
pub fn label(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({unit})")
    }
}

/// Finite min and max of `v`, widened by 5 % (and made non-empty for a constant); `None` if
/// there is no finite value or the range overflows.
pub fn padded_range(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let v: Vec<f64> = v.collect();
    let (lo, hi) = finite_range(&v)?;
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else if lo != 0.0 {
        0.05 * lo.abs()
    } else {
        1.0
    };
    finite((lo - pad, hi + pad))
}

/// Finite min and max of `v`.
fn finite_range(v: &[f64]) -> Option<(f64, f64)> {
    let (lo, hi) = v
        .iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    (lo <= hi).then_some((lo, hi))
}

/// The x and y ranges of a path, both padded by 5 % of the larger extent (so a path that is
/// flat along one axis is drawn as a line at the other's scale, not inflated to fill the plot).
pub fn trajectory_ranges(points: &[(f64, f64)]) -> Option<((f64, f64), (f64, f64))> {
    let xs: Vec<f64> = points.iter().map(|p| p.0).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1).collect();
    let (x, y) = (finite_range(&xs)?, finite_range(&ys)?);
    let extent = (x.1 - x.0).max(y.1 - y.0);
    let pad = if extent > 0.0 {
        0.05 * extent
    } else {
        let size = x.0.abs().max(y.0.abs());
        if size > 0.0 { 0.05 * size } else { 1.0 }
    };
    Some((
        finite((x.0 - pad, x.1 + pad))?,
        finite((y.0 - pad, y.1 + pad))?,
    ))
}

/// The range if both ends and its width are finite (values near `f64::MAX` overflow).
fn finite(r: (f64, f64)) -> Option<(f64, f64)> {
    (r.0.is_finite() && r.1.is_finite() && (r.1 - r.0).is_finite()).then_some(r)
}

/// Widens `x` or `y` so that one unit takes as many pixels on both axes of a `w` x `h` area.
pub fn equal_aspect(x: (f64, f64), y: (f64, f64), w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
    let per_pixel = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let cx = 0.5 * (x.0 + x.1);
    let cy = 0.5 * (y.0 + y.1);
    let hw = 0.5 * per_pixel * w;
    let hh = 0.5 * per_pixel * h;
    ((cx - hw, cx + hw), (cy - hh, cy + hh))
}

/// The SVG of `series` (named `name`, from model `model`), or `None` if it has no time
/// column, no trajectory and no finite values.
pub fn svg(name: &str, series: &Series, model: &str) -> Result<Option<String>, Error> {
    super::csv::check_lengths(name, series)?;
    let fail = |e: &dyn std::fmt::Display| Error::Plot {
        series: name.to_string(),
        message: e.to_string(),
    };
    match shape(series) {
        Shape::None => Ok(None),
        Shape::Trajectory { x, y } => trajectory(name, series, model, x, y).map_err(|e| fail(&e)),
        Shape::Time { t } => time_panels(name, series, model, t).map_err(|e| fail(&e)),
    }
}

type Failure = Box<dyn std::error::Error>;

/// One panel of a time plot: a column's values as displayed, with their unit and y range.
struct Panel<'a> {
    column: &'a Column,
    values: Vec<f64>,
    unit: &'static str,
    range: (f64, f64),
}

fn time_panels(
    name: &str,
    series: &Series,
    model: &str,
    t: usize,
) -> Result<Option<String>, Failure> {
    let time = &series.columns[t];
    // Time runs edge to edge: the range is the data's own unless it is a single instant.
    let Some(padded) = padded_range(time.values.iter().copied()) else {
        return Ok(None);
    };
    let (lo, hi) = finite_range(&time.values).unwrap_or(padded);
    let t_range = if hi > lo { (lo, hi) } else { padded };
    let mut panels: Vec<Panel> = series
        .columns
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != t)
        .filter_map(|(_, c)| {
            let (v, unit) = display_column(c);
            let range = padded_range(v.iter().copied())?;
            Some(Panel {
                column: c,
                values: v,
                unit,
                range,
            })
        })
        .collect();
    // The series' own quantity first (`contact_force` in `contact_force_series`), then the rest.
    let own = name.strip_suffix("_series").unwrap_or(name);
    if let Some(i) = panels.iter().position(|p| p.column.name == own) {
        let p = panels.remove(i);
        panels.insert(0, p);
    }
    panels.truncate(MAX_PANELS);
    if panels.is_empty() {
        return Ok(None);
    }
    let names: Vec<&str> = panels.iter().map(|p| p.column.name.as_str()).collect();
    let title = format!("{model}: {} vs {} ({name})", names.join(", "), time.name);
    let height = CAPTION + PANEL_HEIGHT * panels.len() as u32;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (px(WIDTH), px(height))).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(&title, (FONT, px(22)))?;
        let areas = root.split_evenly((panels.len(), 1));
        for (
            k,
            (
                Panel {
                    column: c,
                    values,
                    unit,
                    range,
                },
                area,
            ),
        ) in panels.iter().zip(&areas).enumerate()
        {
            let mut chart = ChartBuilder::on(area)
                .margin(px(12))
                .x_label_area_size(px(45))
                .y_label_area_size(px(85))
                .build_cartesian_2d(t_range.0..t_range.1, range.0..range.1)?;
            chart
                .configure_mesh()
                .x_desc(label(&time.name, time.unit))
                .y_desc(label(&c.name, unit))
                .axis_desc_style((FONT, px(16)))
                .label_style((FONT, px(13)))
                .axis_style(BLACK.stroke_width(px(1)))
                .draw()?;
            let color = COLORS[k % COLORS.len()];
            chart.draw_series(LineSeries::new(
                finite_points(&time.values, values),
                ShapeStyle::from(&color).stroke_width(px(2)),
            ))?;
        }
        root.present()?;
    }
    Ok(Some(declare_size(buf, WIDTH, height)))
}

fn trajectory(
    name: &str,
    series: &Series,
    model: &str,
    x: usize,
    y: usize,
) -> Result<Option<String>, Failure> {
    let (xc, yc) = (&series.columns[x], &series.columns[y]);
    let points = finite_points(&xc.values, &yc.values);
    let Some((xr, yr)) = trajectory_ranges(&points) else {
        return Ok(None);
    };
    let title = format!("{model}: {name}, {} vs {} (equal scales)", yc.name, xc.name);
    // Lay the chart out once on scratch to learn the plotting area's size in pixels.
    let (w, h) = {
        let mut scratch = String::new();
        let root = SVGBackend::with_string(&mut scratch, (px(WIDTH), px(TRAJECTORY_HEIGHT)))
            .into_drawing_area();
        let root = root.titled(&title, (FONT, px(22)))?;
        let chart = trajectory_builder(&root).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
        chart.plotting_area().dim_in_pixel()
    };
    let (xr, yr) = equal_aspect(xr, yr, f64::from(w.max(1)), f64::from(h.max(1)));
    let (Some(xr), Some(yr)) = (finite(xr), finite(yr)) else {
        return Ok(None);
    };
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (px(WIDTH), px(TRAJECTORY_HEIGHT)))
            .into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(&title, (FONT, px(22)))?;
        let mut chart = trajectory_builder(&root).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
        chart
            .configure_mesh()
            .x_desc(label(&xc.name, xc.unit))
            .y_desc(label(&yc.name, yc.unit))
            .axis_desc_style((FONT, px(16)))
            .label_style((FONT, px(13)))
            .axis_style(BLACK.stroke_width(px(1)))
            .draw()?;
        chart.draw_series(LineSeries::new(
            points.clone(),
            ShapeStyle::from(&BLUE).stroke_width(px(2)),
        ))?;
        // Start (filled) and end (open) of the path.
        if let (Some(&first), Some(&last)) = (points.first(), points.last()) {
            chart.draw_series([
                Circle::new(first, px(5), BLUE.filled()),
                Circle::new(last, px(5), BLUE.stroke_width(px(2))),
            ])?;
        }
        root.present()?;
    }
    Ok(Some(declare_size(buf, WIDTH, TRAJECTORY_HEIGHT)))
}

/// The layout of a trajectory chart (the same for the scratch and the real drawing).
fn trajectory_builder<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(area);
    b.margin(px(15))
        .x_label_area_size(px(45))
        .y_label_area_size(px(85));
    b
}

/// Pairs of finite values.
fn finite_points(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter()
        .zip(y)
        .map(|(a, b)| (*a, *b))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect()
}
