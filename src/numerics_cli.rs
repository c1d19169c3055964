//! The `rodcube sweep` and `rodcube accuracy` subcommands (part of the `rodcube` binary):
//! argument parsing, output files and the summary printed; the work is in
//! [`rodcube::sweep`] and [`rodcube::accuracy`].

use super::{Failure, note, print_stdout};
use clap::Args;
use rodcube::accuracy::{self, Measured};
use rodcube::io::OutDir;
use rodcube::sweep;
use std::io::IsTerminal;
use std::path::PathBuf;

pub const SWEEP_HELP: &str = "\
An axis is named by a parameter of the model (m2, R, ...) or by a ratio of two parameters of
the same unit, written p_over_q (a_over_ell sets a = value * ell); n stands for m2_over_m1.
Its values are START:STOP:lin|log:COUNT, a single value, or values separated by commas. A grid
takes every combination, the first axis varying slowest. Parameters on no axis are fixed with
--set: each needs a value (none is assumed; a missing one is named with its unit). With
--set m1=1,ell=1,g=1 the results read in units of sqrt(ell/g). The CSV's first line says
how each parameter was set; its columns are the axes,
separation_angle, separation_time, then the result keys of each --want quantity (computed by
the planner, much slower). --heatmap draws a two-axis grid.

Examples:
  rodcube sweep --n 1e-3:1e3:log:200 --a-over-ell 0.01:0.99:lin:200 --set m1=1,ell=1,g=1 --heatmap
  rodcube sweep --model hinged_rod --n 0.1,1,10 --a-over-ell 0.05:0.95:lin:19 --set m1=1,ell=1,g=9.81
  rodcube sweep --model rod_cylinder --axis m2_over_m1=0.5:8:log:20 --axis R=0.05:0.3:lin:20 --set m1=1,ell=1,th0=0.9,g=9.81 --heatmap
  rodcube sweep --model wall_ladder --a-over-ell 0.1:0.9:lin:9 --set m1=1,ell=5,g=9.81
  rodcube sweep --points points.csv --want point_mass_fall_time --set m1=1,ell=1,g=9.81";

pub const ACCURACY_HELP: &str = "\
Runs every method on the paper's case (n = 3, a/ell = 1/4) and the hard cases (near upright,
nearly flat, n = 1e12, n = 1e-12) with ell = g = 1, against a reference computed in 256-bit
arithmetic by two independent routes; and the integrators DOPRI5 and DOP853 at rtol 1e-4 to
1e-14 on the models that need them (rod_cube_spring, rod_cube_friction, rod_cylinder at their
scenes' parameters), against the fast path where the model has one, else the other method at
1e-15. A setting's set-up (a solver, a rule's nodes, a bound model) is made once and timed in
its own column; per solve is one solve alone. Writes accuracy.csv and
accuracy_<model>_<quantity>.svg (log-log error vs time per solve, Pareto front circled) and
prints the tables. Models: rod_cube, hinged_rod, wall_ladder, rod_cube_spring,
rod_cube_friction, rod_cylinder (default: rod_cube and the three integrated). Cases: paper,
near_upright, nearly_flat, heavy_cube, light_cube, scene. Methods: --verbose lists them.

Examples:
  rodcube accuracy --quick
  rodcube accuracy --model rod_cube --case paper --method default,per-point
  rodcube accuracy --model hinged_rod --out /tmp/acc";

/// Arguments of `rodcube sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// Model to sweep (any model with a contact; `rodcube models` lists them)
    #[arg(long, default_value = "rod_cube")]
    model: String,
    /// An axis: NAME=SPEC, NAME a parameter or a ratio p_over_q (repeat for a grid)
    #[arg(long, value_name = "NAME=SPEC", allow_hyphen_values = true)]
    axis: Vec<String>,
    /// The axis n = m2/m1 (same as --axis n=SPEC)
    #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
    n: Option<String>,
    /// The axis a/ell (same as --axis a_over_ell=SPEC)
    #[arg(long = "a-over-ell", value_name = "SPEC", allow_hyphen_values = true)]
    a_over_ell: Option<String>,
    /// Parameters on no axis: NAME=VALUE, comma-separated or repeated (each needs a value)
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "NAME=VALUE",
        allow_hyphen_values = true
    )]
    set: Vec<String>,
    /// CSV of points whose header names the axes (instead of a grid)
    #[arg(long, value_name = "FILE", conflicts_with_all = ["axis", "n", "a_over_ell", "heatmap"])]
    points: Option<PathBuf>,
    /// More quantities per point, comma-separated: any with a number per point (contact_end,
    /// floor_impact, cross_check, ...), each giving its result keys as columns (through the
    /// planner; slower)
    #[arg(long, value_delimiter = ',', value_name = "QUANTITY")]
    want: Vec<String>,
    /// Also write d(result)/d(parameter) and the elasticities of the separation angle and time
    /// for every parameter (columns after the --want ones)
    #[arg(long)]
    sensitivities: bool,
    /// Relative tolerance of the --want quantities
    #[arg(long, default_value = rodcube::plan::DEFAULT_TOLERANCE_TEXT)]
    tolerance: f64,
    /// Also write heat maps separation_angle.svg and separation_time.svg (two-axis grids)
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
    /// Models, comma-separated or repeated [default: rod_cube and the integrated models]
    #[arg(long, value_delimiter = ',', value_name = "MODEL")]
    model: Vec<String>,
    /// Cases by key, comma-separated or repeated [default: every case]
    #[arg(long, value_delimiter = ',', value_name = "CASE")]
    case: Vec<String>,
    /// Methods by label, comma-separated or repeated [default: every method]
    #[arg(long, value_delimiter = ',', value_name = "LABEL")]
    method: Vec<String>,
    /// Fewer settings per method and a smaller timing budget
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    layout: super::LayoutArgs,
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
        let names: Vec<&str> = (rodcube::models::all().iter().map(|m| m.info()))
            .filter(|i| i.is_general())
            .map(|i| i.name)
            .collect();
        usage(format!(
            "no model `{}`; the models are: {}",
            args.model,
            names.join(", ")
        ))
    })?;
    let info = model.info();
    if !info.is_general() {
        return Err(usage(format!(
            "`{}` is a phase of the system `{}`, which decides its phases itself: sweep `--model {}`",
            info.name, info.system, info.system
        )));
    }
    if info.contacts.first().is_none_or(|c| c.bilateral) {
        return Err(usage(sweep::SweepError::NoContact { model: info.name }));
    }
    let mut extra = sweep::parse_want(model, &args.want).map_err(usage)?;
    if args.sensitivities {
        extra.push(rodcube::quantity::Quantity::Sensitivities);
    }
    let fixed = parse_set(&args.set)?;
    let (points, grid) = match &args.points {
        Some(path) => {
            let points = sweep::read_points(path, info)
                .map_err(|e| Failure::Invalid(anyhow::anyhow!("{e}")))?;
            (points, None)
        }
        None => {
            let axes = grid_axes(&args)?;
            let points = sweep::Points::grid(&axes).map_err(usage)?;
            (points, Some(axes))
        }
    };
    let names: Vec<&str> = points.names.iter().map(String::as_str).collect();
    let fixed_ref: Vec<(&str, f64)> = fixed.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let mapping = rodcube::axes::Mapping::new(info, &names, &fixed_ref).map_err(|e| match e {
        rodcube::axes::AxisError::Missing { ref unset, .. } => {
            let first = unset.first().map_or("g", |u| u.parameter.name);
            let column = if args.points.is_some() { ", as a column of the points file" } else { "" };
            usage(format!(
                "{e}\ngive each with --set NAME=VALUE (--set {first}=...), on an axis (--axis {first}=SPEC){column}"
            ))
        }
        e => usage(e),
    })?;
    sweep::check(&mapping, model, &points).map_err(usage)?;
    let heat_axes = grid.as_ref().filter(|a| a.len() == 2);
    if args.heatmap && heat_axes.is_none() {
        note("note: no heat maps: they need a grid over two axes");
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
    let results = sweep::run(model, &mapping, &points, &extra, args.tolerance, &bar);
    bar.finish_and_clear();
    let write_start = std::time::Instant::now();
    let text = sweep::to_csv(&mapping, &points, &results);
    let csv_path = out.write("sweep.csv", text.as_bytes()).map_err(output)?;
    let write_seconds = write_start.elapsed().as_secs_f64();
    let mut written = vec![csv_path];
    if args.heatmap
        && let Some([y, x]) = heat_axes.map(Vec::as_slice)
    {
        for (name, unit, values) in [
            ("separation_angle", "rad", &results.angle),
            ("separation_time", "s", &results.time),
        ] {
            let title = format!("{}: {name} ({unit})", info.name);
            // A map with no finite value (every point failed) is skipped: the failures are
            // reported below.
            if values.iter().any(|v| v.is_finite()) {
                let svg = sweep::heatmap_svg(&title, unit, y, x, values).map_err(bad)?;
                written.push(
                    out.write(&format!("{name}.svg"), svg.as_bytes())
                        .map_err(output)?,
                );
            }
        }
    }
    let n_points = points.len();
    let threads = rayon::current_num_threads();
    let summary = format!(
        "swept {n_points} points of {} in {:.3} s on {threads} threads: {:.3e} points/s solving ({:.3e} points/s with the CSV, written in {:.3} s)\nwrote {}\n",
        info.name,
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
            note(&format!(
                "point {} ({}): {message}",
                i + 1,
                points.describe(*i)
            ));
        }
        return Err(bad(format!(
            "{} of {n_points} points failed (their cells are empty in the CSV)",
            results.errors.len()
        )));
    }
    Ok(())
}

/// The grid's axes, in the order given: `--n`, `--a-over-ell`, then each `--axis`.
fn grid_axes(args: &SweepArgs) -> Result<Vec<sweep::Axis>, Failure> {
    let mut specs: Vec<(String, String)> = Vec::new();
    if let Some(spec) = &args.n {
        specs.push(("n".into(), spec.clone()));
    }
    if let Some(spec) = &args.a_over_ell {
        specs.push(("a_over_ell".into(), spec.clone()));
    }
    for a in &args.axis {
        let (name, spec) = a.split_once('=').ok_or_else(|| {
            usage(format!(
                "--axis {a:?}: expected NAME=SPEC (e.g. --axis m2=0.5:8:log:20)"
            ))
        })?;
        specs.push((name.trim().to_string(), spec.to_string()));
    }
    if specs.is_empty() {
        return Err(usage(
            "give the axes (--axis NAME=SPEC, or --n / --a-over-ell), or --points FILE",
        ));
    }
    specs
        .iter()
        .map(|(name, spec)| sweep::parse_axis(name, spec).map_err(usage))
        .collect()
}

/// `--set NAME=VALUE` entries.
fn parse_set(entries: &[String]) -> Result<Vec<(String, f64)>, Failure> {
    entries
        .iter()
        .map(|e| {
            let (name, value) = e
                .split_once('=')
                .ok_or_else(|| usage(format!("--set {e:?}: expected NAME=VALUE")))?;
            let v = value
                .trim()
                .parse::<f64>()
                .map_err(|_| usage(format!("--set {e:?}: {value:?} is not a number")))?;
            Ok((name.trim().to_string(), v))
        })
        .collect()
}

/// `rodcube accuracy`.
pub fn accuracy(args: AccuracyArgs) -> Result<(), Failure> {
    let options = accuracy::Options {
        models: args.model,
        cases: args.case,
        methods: args.method,
        quick: args.quick,
    };
    let chosen = options.choose().map_err(usage)?;
    let layout = args.layout.layout();
    let out_dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join("accuracy"));
    let out = OutDir::create(&out_dir).map_err(output)?;
    let bar = indicatif::ProgressBar::new(chosen.settings() as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {wide_msg}",
    ) {
        bar.set_style(style);
    }
    // A progress bar on a terminal; a line per model and case otherwise.
    let lines: Option<accuracy::LineSink> = if std::io::stderr().is_terminal() {
        None
    } else {
        Some(Box::new(note))
    };
    let progress = accuracy::Progress::new(bar, lines);
    let report = accuracy::run(&chosen, &progress).map_err(bad)?;
    progress.bar().finish_and_clear();
    let csv = accuracy::to_csv(&report.rows).map_err(bad)?;
    let mut written = vec![out.write("accuracy.csv", csv.as_bytes()).map_err(output)?];
    let mut plots: Vec<(&str, Measured)> = Vec::new();
    for r in &report.rows {
        if !plots.contains(&(r.model, r.measured)) {
            plots.push((r.model, r.measured));
        }
    }
    for (model, measured) in plots {
        if let Some(svg) = accuracy::plot::svg(measured, model, &report.rows).map_err(bad)? {
            let name = format!("accuracy_{model}_{}.svg", measured.name());
            written.push(out.write(&name, svg.as_bytes()).map_err(output)?);
        }
    }
    print_stdout(&accuracy::table::render(&report, &layout))?;
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
