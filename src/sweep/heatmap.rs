//! Heat maps of a swept quantity over a two-axis grid as SVG (plotters): one cell per
//! grid point, a viridis-like colour scale with its colour bar; log-spaced axes are drawn in
//! `log10`.

use super::Axis;
use plotters::prelude::*;

const WIDTH: u32 = 900;
const HEIGHT: u32 = 700;
const FONT: &str = "sans-serif";

/// Viridis anchors (every eighth of the scale).
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// The colour of `f` in `[0, 1]`.
pub fn colour(f: f64) -> RGBColor {
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = f * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let t = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + t * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Axis coordinates (log10 for a log axis) and the cell edges between them.
fn edges(axis: &Axis) -> (Vec<f64>, Vec<f64>) {
    let c: Vec<f64> = axis
        .values
        .iter()
        .map(|&v| if axis.log { v.log10() } else { v })
        .collect();
    let mut e = Vec::with_capacity(c.len() + 1);
    if c.len() == 1 {
        let w = if c[0] != 0.0 { 0.05 * c[0].abs() } else { 0.5 };
        return (c.clone(), vec![c[0] - w, c[0] + w]);
    }
    e.push(c[0] - 0.5 * (c[1] - c[0]));
    for w in c.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    let k = c.len();
    e.push(c[k - 1] + 0.5 * (c[k - 1] - c[k - 2]));
    (c, e)
}

/// The SVG heat map of `values` (`values[i * x.len() + j]` at `y[i]`, `x[j]`); NaN cells are
/// left white.
pub fn svg(
    title: &str,
    unit: &str,
    y: &Axis,
    x: &Axis,
    values: &[f64],
) -> Result<String, HeatmapError> {
    let (nx, ny) = (x.values.len(), y.values.len());
    if values.len() != nx * ny || nx == 0 || ny == 0 {
        return Err(HeatmapError::Grid {
            values: values.len(),
            ny,
            nx,
        });
    }
    draw(title, unit, y, x, values).map_err(|e| HeatmapError::Draw(e.to_string()))
}

/// Why a heat map could not be drawn.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HeatmapError {
    /// The values do not fill the grid (or an axis is empty).
    #[error("{values} values for a {ny} x {nx} grid")]
    Grid {
        /// How many values were given.
        values: usize,
        /// Rows (values of the y axis).
        ny: usize,
        /// Columns (values of the x axis).
        nx: usize,
    },
    /// The plotting library failed, with its message.
    #[error("{0}")]
    Draw(String),
}

/// An axis's label: its name with `_over_` written as `/` (`a/ell`), `n` spelt out as the mass
/// ratio, under `log10(...)` when the axis is logarithmic.
fn label(axis: &Axis) -> String {
    let name = match axis.name.as_str() {
        "n" => "n = m2/m1".to_string(),
        other => other.replace("_over_", "/"),
    };
    if axis.log {
        format!("log10({name})")
    } else {
        name
    }
}

/// [`svg`]'s drawing, once it has checked that the values fill the grid.
fn draw(
    title: &str,
    unit: &str,
    y: &Axis,
    x: &Axis,
    values: &[f64],
) -> Result<String, Box<dyn std::error::Error>> {
    let (nx, ny) = (x.values.len(), y.values.len());
    let (_, xe) = edges(x);
    let (_, ye) = edges(y);
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo > hi {
        return Err("no finite value to plot".into());
    }
    // A logarithmic colour scale when the values span more than two decades.
    let log = lo > 0.0 && hi / lo > 100.0;
    let map = |v: f64| if log { v.log10() } else { v };
    let (clo, chi) = (map(lo), map(hi));
    let span = if chi > clo { chi - clo } else { 1.0 };
    let frac = |v: f64| (map(v) - clo) / span;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(title, (FONT, 20))?;
        let (main, bar) = root.split_horizontally(WIDTH - 150);
        let (x_desc, y_desc) = (label(x), label(y));
        let mut chart = ChartBuilder::on(&main)
            .margin(10)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xe[0]..xe[nx], ye[0]..ye[ny])?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 13))
            .draw()?;
        let mut cells = Vec::with_capacity(nx * ny);
        for i in 0..ny {
            for j in 0..nx {
                let v = values[i * nx + j];
                if v.is_finite() {
                    cells.push(Rectangle::new(
                        [(xe[j], ye[i]), (xe[j + 1], ye[i + 1])],
                        colour(frac(v)).filled(),
                    ));
                }
            }
        }
        chart.draw_series(cells)?;
        let label = if log {
            format!("log10({unit})")
        } else {
            unit.to_string()
        };
        let mut scale = ChartBuilder::on(&bar)
            .margin(10)
            .margin_left(20)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..1.0, clo..(clo + span))?;
        scale
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(label)
            .axis_desc_style((FONT, 14))
            .label_style((FONT, 12))
            .draw()?;
        let steps = 200;
        scale.draw_series((0..steps).map(|k| {
            let a = clo + span * k as f64 / steps as f64;
            let b = clo + span * (k + 1) as f64 / steps as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                colour((k as f64 + 0.5) / steps as f64).filled(),
            )
        }))?;
        root.present()?;
    }
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_scale_runs_from_purple_to_yellow() {
        assert_eq!(colour(0.0), RGBColor(68, 1, 84));
        assert_eq!(colour(1.0), RGBColor(253, 231, 37));
        assert_eq!(colour(f64::NAN), RGBColor(68, 1, 84));
    }

    #[test]
    fn a_small_grid_draws_one_rectangle_per_cell() {
        let n = Axis {
            name: "n".into(),
            values: vec![0.1, 1.0, 10.0],
            log: true,
        };
        let r = Axis {
            name: "a_over_ell".into(),
            values: vec![0.2, 0.5],
            log: false,
        };
        let values = [1.0, 2.0, 3.0, 4.0, f64::NAN, 6.0];
        let svg = svg("test", "rad", &n, &r, &values).unwrap();
        assert!(svg.starts_with("<svg"));
        // 5 finite cells plus 200 colour-bar steps plus the background rectangles.
        assert!(svg.matches("<rect").count() >= 205);
        assert!(svg.contains("log10(n = m2/m1)") && svg.contains("a/ell"));
    }
}
