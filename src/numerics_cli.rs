//! The `rodcube sweep` and `rodcube accuracy` subcommands (part of the `rodcube` binary):
//! argument parsing, output files and the summary printed; the work is in
//! [`rodcube::sweep`] and [`rodcube::accuracy`].

use super::{Failure, note, print_stdout};
use clap::Args;
use rodcube::accuracy::{self, Measured};
use rodcube::io::OutDir;
use rodcube::sweep::{self, Axis, Mapping, Point};
use std::path::PathBuf;

pub const SWEEP_HELP: &str = "\
Parameters are set as m1 = 1, m2 = n, a = a_over_ell * ell, with ell = g = 1 unless --ell/--g
are given: results are then dimensionless (times in units of sqrt(ell/g)), as the CSV's first
line says. An axis is START:STOP:lin|log:COUNT, a single value, or values separated by commas.
The CSV has columns n,a_over_ell,separation_angle,separation_time (no n for a model without m2)
plus the result keys of each --want quantity (computed by the planner, much slower).

Examples:
  rodcube sweep --n 1e-3:1e3:log:200 --a-over-ell 0.01:0.99:lin:200 --heatmap
  rodcube sweep --model hinged_rod --n 0.1,1,10 --a-over-ell 0.05:0.95:lin:19
  rodcube sweep --model wall_ladder --a-over-ell 0.1:0.9:lin:9
  rodcube sweep --points points.csv --want point_mass_fall_time --ell 1 --g 9.81
  rodcube sweep --n 3 --a-over-ell 0.25 --out /tmp/one";

pub const ACCURACY_HELP: &str = "\
Runs every method on the paper's case (n = 3, a/ell = 1/4) and the hard cases (near upright,
nearly flat, n = 1e12, n = 1e-12) with ell = g = 1, against a reference computed in 256-bit
arithmetic by two independent routes. Writes accuracy.csv and accuracy_<quantity>.svg
(log-log error vs time per solve, Pareto front circled) and prints the table.

Examples:
  rodcube accuracy
  rodcube accuracy --model hinged_rod --out /tmp/acc";

/// Arguments of `rodcube sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// Model to sweep (one with parameters m1, [m2,] ell, a, g)
    #[arg(long, default_value = "rod_cube")]
    model: String,
    /// Mass ratios n = m2/m1: START:STOP:lin|log:COUNT, a value, or a list
    #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
    n: Option<String>,
    /// Values of a/ell in (0, 1): START:STOP:lin|log:COUNT, a value, or a list
    #[arg(long = "a-over-ell", value_name = "SPEC", allow_hyphen_values = true)]
    a_over_ell: Option<String>,
    /// CSV of points with columns n,a_over_ell (instead of a grid)
    #[arg(long, value_name = "FILE", conflicts_with_all = ["n", "a_over_ell", "heatmap"])]
    points: Option<PathBuf>,
    /// More quantities per point, comma-separated (through the planner; slower)
    #[arg(long, value_delimiter = ',', value_name = "QUANTITY")]
    want: Vec<String>,
    /// Rod length ell in m (default 1: dimensionless)
    #[arg(long)]
    ell: Option<f64>,
    /// Gravitational acceleration g in m/s^2 (default 1: dimensionless)
    #[arg(long)]
    g: Option<f64>,
    /// Relative tolerance of the --want quantities
    #[arg(long, default_value_t = rodcube::plan::DEFAULT_TOLERANCE)]
    tolerance: f64,
    /// Also write heat maps separation_angle.svg and separation_time.svg (grids only)
    #[arg(long)]
    heatmap: bool,
    /// Worker threads (default: one per core)
    #[arg(long)]
    threads: Option<usize>,
    /// Output directory [default: out/sweep/]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Arguments of `rodcube accuracy`.
#[derive(Args)]
pub struct AccuracyArgs {
    /// Model (rod_cube, hinged_rod or wall_ladder)
    #[arg(long, default_value = "rod_cube")]
    model: String,
    /// Output directory [default: out/accuracy/]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

fn bad(e: impl std::fmt::Display) -> Failure {
    Failure::Solve(anyhow::anyhow!("{e}"))
}

/// A command-line argument that cannot be honoured (exit status 2).
fn usage(e: impl std::fmt::Display) -> Failure {
    Failure::Usage(anyhow::anyhow!("{e}"))
}

fn output(e: impl Into<anyhow::Error>) -> Failure {
    Failure::Output(e.into())
}

/// `rodcube sweep`.
pub fn sweep(args: SweepArgs) -> Result<(), Failure> {
    let model = rodcube::models::find(&args.model).ok_or_else(|| {
        let names: Vec<&str> = rodcube::models::all()
            .iter()
            .map(|m| m.info().name)
            .collect();
        usage(format!(
            "no model `{}`; the models are: {}",
            args.model,
            names.join(", ")
        ))
    })?;
    let mapping = Mapping::new(model, args.ell, args.g).map_err(usage)?;
    let extra = sweep::parse_want(model, &args.want).map_err(usage)?;
    let (points, has_n, grid): (Vec<Point>, bool, Option<(Axis, Axis)>) = match &args.points {
        Some(path) => {
            let (points, has_n) =
                sweep::read_points(path).map_err(|e| Failure::Invalid(anyhow::anyhow!("{e}")))?;
            (points, has_n, None)
        }
        None => {
            let r_spec = args.a_over_ell.as_deref().ok_or_else(|| {
                usage("give --a-over-ell (and --n for a model with m2), or --points FILE")
            })?;
            let r = sweep::parse_axis("a-over-ell", r_spec).map_err(usage)?;
            let n = match &args.n {
                Some(spec) => Some(sweep::parse_axis("n", spec).map_err(usage)?),
                None => None,
            };
            let ns = n.as_ref().map_or(vec![f64::NAN], |a| a.values.clone());
            let total = ns.len().saturating_mul(r.values.len());
            if total > sweep::MAX_POINTS {
                return Err(usage(format!(
                    "{total} points is more than {}",
                    sweep::MAX_POINTS
                )));
            }
            let mut points = Vec::with_capacity(total);
            for &nv in &ns {
                for &rv in &r.values {
                    points.push(Point {
                        n: nv,
                        a_over_ell: rv,
                    });
                }
            }
            let has_n = n.is_some();
            let grid = n.map(|n| (n, r));
            (points, has_n, grid)
        }
    };
    mapping.check(&points, has_n).map_err(usage)?;
    if args.heatmap && grid.is_none() {
        note("note: no heat maps: they need a grid over both n and a/ell");
    }
    let out_dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join("sweep"));
    let out = OutDir::create(&out_dir).map_err(output)?;
    if let Some(t) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t.max(1))
            .build_global()
            .map_err(bad)?;
    }
    let bar = sweep::progress_bar(points.len());
    let results = sweep::run(&mapping, &points, &extra, args.tolerance, &bar);
    bar.finish_and_clear();
    let write_start = std::time::Instant::now();
    let text = sweep::to_csv(&mapping, &points, &results);
    let csv_path = out.write("sweep.csv", text.as_bytes()).map_err(output)?;
    let write_seconds = write_start.elapsed().as_secs_f64();
    let mut written = vec![csv_path];
    if args.heatmap
        && let Some((n, r)) = &grid
    {
        for (name, unit, values) in [
            ("separation_angle", "rad", &results.angle),
            ("separation_time", time_unit(&mapping), &results.time),
        ] {
            let title = format!("{}: {name} ({unit})", model.info().name);
            let svg = sweep::heatmap_svg(&title, unit, n, r, values).map_err(bad)?;
            written.push(
                out.write(&format!("{name}.svg"), svg.as_bytes())
                    .map_err(output)?,
            );
        }
    }
    let n_points = points.len();
    let threads = rayon::current_num_threads();
    let summary = format!(
        "swept {n_points} points of {} in {:.3} s on {threads} threads: {:.3e} points/s solving ({:.3e} points/s with the CSV, written in {:.3} s)\nwrote {}\n",
        model.info().name,
        results.seconds,
        n_points as f64 / results.seconds,
        n_points as f64 / (results.seconds + write_seconds),
        write_seconds,
        written
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    print_stdout(&summary)?;
    if !results.errors.is_empty() {
        for (i, message) in results.errors.iter().take(5) {
            let p = points[*i];
            note(&format!(
                "point {} (n = {}, a_over_ell = {}): {message}",
                i + 1,
                p.n,
                p.a_over_ell
            ));
        }
        return Err(bad(format!(
            "{} of {n_points} points failed (their cells are empty in the CSV)",
            results.errors.len()
        )));
    }
    Ok(())
}

fn time_unit(mapping: &Mapping) -> &'static str {
    if mapping.dimensionless {
        "sqrt(ell/g)"
    } else {
        "s"
    }
}

/// `rodcube accuracy`.
pub fn accuracy(args: AccuracyArgs) -> Result<(), Failure> {
    let family = rodcube::reference::Family::of(&args.model).ok_or_else(|| {
        usage(format!(
            "`rodcube accuracy` needs a model with a closed-form reference (rod_cube, hinged_rod, wall_ladder), not `{}`",
            args.model
        ))
    })?;
    let out_dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join("accuracy"));
    let out = OutDir::create(&out_dir).map_err(output)?;
    let total = accuracy::cases(family).len() * accuracy::settings_per_case();
    let bar = sweep::progress_bar(total);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {wide_msg}",
    ) {
        bar.set_style(style);
    }
    let (rows, refs) = accuracy::run(&args.model, &bar).map_err(bad)?;
    bar.finish_and_clear();
    let mut written = vec![
        out.write("accuracy.csv", accuracy::to_csv(&rows).as_bytes())
            .map_err(output)?,
    ];
    for measured in [Measured::Angle, Measured::Time, Measured::Series] {
        if let Some(svg) = accuracy::plot::svg(measured, &args.model, &rows).map_err(bad)? {
            let name = format!("accuracy_{}.svg", measured.name());
            written.push(out.write(&name, svg.as_bytes()).map_err(output)?);
        }
    }
    print_stdout(&accuracy::table(&rows, &refs))?;
    note(&format!(
        "wrote {}",
        written
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    Ok(())
}
