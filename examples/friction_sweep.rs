//! Separation time and angle of the paper's rod and cube against the foot's friction coefficient
//! mu (0 to 2), with the regions where the foot slides, sticks or keeps the rod on the cube.
//!
//! `cargo run --release --example friction_sweep -- [N] [DIR]` solves N values of mu (default
//! 201) and writes `DIR/friction_sweep.csv` and `DIR/friction_sweep.svg` (default
//! `out/friction_sweep`); it prints the regimes with their boundaries, found by bisection to
//! 1e-6 in mu, beside the hinged rod's separation (the foot that never slips).
use plotters::prelude::*;
use rodcube::io::write_atomic;
use rodcube::models;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity::{SeparationAngle, SeparationTime};
use rodcube::results::EndCause;
use rodcube::results::Work;
use rodcube::solve::phases::{PhaseRun, Walker};
use rodcube::system::Bound;
use std::error::Error;
use std::path::PathBuf;

const PAPER: [(&str, f64); 5] = [
    ("m1", 1.0),
    ("m2", 3.0),
    ("ell", 1.0),
    ("a", 0.25),
    ("g", 9.81),
];
const MU_MAX: f64 = 2.0;

/// The contact phase at one mu: how the foot moves, and where the rod leaves the cube.
struct Point {
    mu: f64,
    /// `slides -, sticks` (the foot's modes in order) and how the contact phase ends.
    regime: String,
    /// Separation time (s) and angle (deg), if the rod leaves the cube.
    separation: Option<(f64, f64)>,
    /// When the foot first changed mode (s).
    first_switch: Option<f64>,
}

fn solve(mu: f64) -> Result<Point, Box<dyn Error>> {
    let model = models::find("rod_cube_friction").ok_or("rod_cube_friction was not generated")?;
    let mut params = PAPER.to_vec();
    params.push(("mu", mu));
    let walker = Walker::new(Bound::new(model, &params)?, models::all(), 1e-12, 1e-13);
    // The contact phase: the first phase from release (the foot's friction acts, so the general
    // model is integrated with both contacts closed), to its first event.
    let (start, _) = walker.release()?;
    let run = walker.solve(&start, &mut Work::default())?;
    let PhaseRun::Integrated(phase) = &run else {
        return Err("the contact phase with friction is integrated".into());
    };
    // The foot's friction is the model's only one: its mode in each stretch of the phase.
    let modes: Vec<(f64, String)> = (phase.run.segments.iter())
        .map(|s| (phase.t_start + s.t_start, s.active.modes[0].to_string()))
        .collect();
    let steps: Vec<&str> = modes.iter().map(|(_, m)| m.as_str()).collect();
    let end = run.end();
    let regime = format!(
        "foot {}; {}",
        steps.join(", then "),
        match end {
            EndCause::Force(c) if c.index == 0 => "leaves the cube",
            EndCause::Force(_) => "the foot lifts off the floor",
            _ => "stays on the cube",
        }
    );
    Ok(Point {
        mu,
        regime,
        separation: match end.is_force_of(0) {
            true => Some((run.t_end(), run.theta_end()?.to_degrees())),
            false => None,
        },
        first_switch: modes.get(1).map(|(t, _)| *t),
    })
}

/// The separation time and angle (deg) of the hinged rod: the foot that never slips.
fn hinged() -> Result<(f64, f64), Box<dyn Error>> {
    let model = models::find("hinged_rod").ok_or("hinged_rod was not generated")?;
    let r = run(&Request::new(model, PAPER)
        .with_want(&[SeparationAngle, SeparationTime])
        .with_tolerance(1e-12))?;
    let value = |k: &str| r.results.get(k).map(|s| s.value).ok_or(format!("no {k}"));
    Ok((
        value("separation_time")?,
        value("separation_angle")?.to_degrees(),
    ))
}

/// The mu between `lo` and `hi` (of different regimes) where the regime changes, to 1e-6.
fn boundary(mut lo: Point, mut hi: Point) -> Result<(Point, Point), Box<dyn Error>> {
    while hi.mu - lo.mu > 1e-6 {
        let mid = solve(0.5 * (lo.mu + hi.mu))?;
        if mid.regime == lo.regime {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok((lo, hi))
}

fn csv(points: &[Point]) -> String {
    let mut out =
        String::from("mu,separation_time_s,separation_angle_deg,regime,first_switch_time_s\n");
    for p in points {
        let (t, a) = p
            .separation
            .map_or((String::new(), String::new()), |(t, a)| {
                (format!("{t:.15e}"), format!("{a:.15e}"))
            });
        let s = p
            .first_switch
            .map_or(String::new(), |t| format!("{t:.15e}"));
        out.push_str(&format!("{:.6},{t},{a},\"{}\",{s}\n", p.mu, p.regime));
    }
    out
}

const SHADES: [RGBColor; 6] = [
    RGBColor(198, 219, 239),
    RGBColor(253, 208, 162),
    RGBColor(199, 233, 192),
    RGBColor(218, 218, 235),
    RGBColor(252, 187, 161),
    RGBColor(217, 217, 217),
];

/// The two panels (time, angle) against mu with the regimes shaded.
fn svg(points: &[Point], hinged: (f64, f64)) -> Result<String, Box<dyn Error>> {
    let mut regimes: Vec<&str> = Vec::new();
    for p in points {
        if !regimes.contains(&p.regime.as_str()) {
            regimes.push(&p.regime);
        }
    }
    // Contiguous runs of one regime, as mu intervals split halfway between grid points.
    let mut runs: Vec<(f64, f64, usize)> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let k = regimes.iter().position(|r| *r == p.regime).unwrap_or(0);
        let lo = if i == 0 {
            p.mu
        } else {
            0.5 * (points[i - 1].mu + p.mu)
        };
        let hi = points.get(i + 1).map_or(p.mu, |q| 0.5 * (p.mu + q.mu));
        match runs.last_mut() {
            Some(r) if r.2 == k => r.1 = hi,
            _ => runs.push((lo, hi, k)),
        }
    }
    let frictionless = points.first().and_then(|p| p.separation);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (900, 760)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(
            "rod_cube_friction (n = 3, a/ell = 1/4): separation against the foot's friction mu",
            ("sans-serif", 18),
        )?;
        let panels = root.split_evenly((2, 1));
        for (k, area) in panels.iter().enumerate() {
            let value = |p: &Point| p.separation.map(|s| if k == 0 { s.0 } else { s.1 });
            let values: Vec<f64> = points.iter().filter_map(value).collect();
            let reference = if k == 0 { hinged.0 } else { hinged.1 };
            let lo = values
                .iter()
                .chain([&reference])
                .cloned()
                .fold(f64::INFINITY, f64::min);
            let hi = values
                .iter()
                .chain([&reference])
                .cloned()
                .fold(f64::NEG_INFINITY, f64::max);
            let pad = 0.08 * (hi - lo).max(1e-9);
            let (lo, hi) = (lo - pad, hi + pad);
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..MU_MAX, lo..hi)?;
            chart
                .configure_mesh()
                .x_desc("mu (foot-floor friction coefficient)")
                .y_desc(if k == 0 {
                    "separation time (s)"
                } else {
                    "separation angle (deg)"
                })
                .draw()?;
            for &(a, b, r) in &runs {
                let shade = SHADES[r % SHADES.len()];
                let drawn = chart.draw_series(std::iter::once(Rectangle::new(
                    [(a, lo), (b, hi)],
                    shade.filled(),
                )))?;
                if k == 1
                    && runs.iter().position(|x| x.2 == r)
                        == runs.iter().position(|x| x == &(a, b, r))
                {
                    drawn.label(regimes[r].to_string()).legend(move |(x, y)| {
                        Rectangle::new([(x, y - 6), (x + 14, y + 6)], shade.filled())
                    });
                }
            }
            // One line per stretch of mu where the rod leaves the cube (no line where it stays).
            let mut pieces: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for p in points {
                match value(p) {
                    Some(v) => pieces.last_mut().map_or((), |l| l.push((p.mu, v))),
                    None if pieces.last().is_some_and(|l| !l.is_empty()) => pieces.push(Vec::new()),
                    None => {}
                }
            }
            for (i, piece) in pieces.into_iter().enumerate() {
                let drawn = chart.draw_series(LineSeries::new(piece, BLUE.stroke_width(2)))?;
                if i == 0 {
                    drawn.label("rod_cube_friction").legend(|(x, y)| {
                        PathElement::new([(x, y), (x + 14, y)], BLUE.stroke_width(2))
                    });
                }
            }
            chart
                .draw_series(LineSeries::new(
                    [(0.0, reference), (MU_MAX, reference)],
                    RED.stroke_width(1),
                ))?
                .label("hinged rod (the foot never slips)")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], RED));
            if let Some(f) = frictionless {
                let v = if k == 0 { f.0 } else { f.1 };
                chart
                    .draw_series(LineSeries::new(
                        [(0.0, v), (MU_MAX, v)],
                        BLACK.stroke_width(1),
                    ))?
                    .label("the paper (mu = 0)")
                    .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], BLACK));
            }
            if k == 1 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::LowerRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 12))
                    .draw()?;
            }
        }
        root.present()?;
    }
    Ok(buf)
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = match args.next() {
        Some(a) => a
            .parse()
            .map_err(|e| format!("N must be a count of mu values: {a}: {e}"))?,
        None => 201,
    };
    if n < 2 {
        return Err(format!("N must be at least 2, not {n}").into());
    }
    let dir = PathBuf::from(args.next().unwrap_or_else(|| "out/friction_sweep".into()));
    let points = (0..n)
        .map(|i| solve(MU_MAX * i as f64 / (n - 1) as f64))
        .collect::<Result<Vec<Point>, _>>()?;
    let hinged = hinged()?;
    println!(
        "hinged rod: separates at {:.15e} s, {:.10} deg",
        hinged.0, hinged.1
    );
    println!("regimes of the foot over mu in [0, {MU_MAX}] ({n} values):");
    let mut start = &points[0];
    for w in points.windows(2) {
        if w[1].regime != w[0].regime {
            let (lo, hi) = boundary(solve(w[0].mu)?, solve(w[1].mu)?)?;
            println!("  mu {:.6} .. {:.6}: {}", start.mu, lo.mu, start.regime);
            println!("  boundary at mu = {:.6}", 0.5 * (lo.mu + hi.mu));
            start = &w[1];
        }
    }
    println!("  mu {:.6} .. {:.6}: {}", start.mu, MU_MAX, start.regime);
    std::fs::create_dir_all(&dir)?;
    let csv_path = dir.join("friction_sweep.csv");
    let svg_path = dir.join("friction_sweep.svg");
    let drawing = svg(&points, hinged)?;
    write_atomic(&csv_path, csv(&points).as_bytes())?;
    write_atomic(&svg_path, drawing.as_bytes())?;
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}
