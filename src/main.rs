//! The `rodcube` command line: run a scene (table or JSON on stdout; results.json, CSVs and SVG
//! plots in the output directory) and list the models. Results go to stdout, diagnostics to
//! stderr; every failure is a message with a non-zero exit status, never a panic.

use clap::{Args, Parser, Subcommand};
use rodcube::io::{OutDir, check_name};
use rodcube::report;
use rodcube::scene::{RunError, Scene, SceneError, Source};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

mod numerics_cli;

/// Exit status: the computation failed.
const EXIT_FAILED: u8 = 1;
/// Exit status: a bad command line (clap uses it too).
const EXIT_USAGE: u8 = 2;
/// Exit status: the scene is invalid (clap uses 2 for a bad command line).
const EXIT_SCENE: u8 = 3;
/// Exit status: an output could not be written.
const EXIT_OUTPUT: u8 = 4;

const EXAMPLES: &str = "\
Examples:
  rodcube                                    # the same as `rodcube run`: the paper's case
  rodcube run                                # the paper's scene (built in) -> out/paper/
  rodcube run scenes/hinged.yaml             # another scene -> out/hinged/
  rodcube run scenes/paper.yaml --json > r.json
  rodcube run my_scene.yaml --out /tmp/mine  # choose the output directory
  rodcube models                             # models, their parameters and quantities
  rodcube fmu rod_cube --out out/fmu         # an FMI 2.0 co-simulation FMU of a system

Exit status: 0 success, 1 the computation failed, 2 bad command line,
3 invalid scene or input file (the message names file:line:column and the field),
4 an output could not be written (`rodcube fmu`: 2, and no partial .fmu is left).";

const FMU_HELP: &str = "\
The FMU's shared library is rodcube's C library with the FMI 2.0 entry points,
librodcube.so, which the build of rodcube leaves in the target directory: beside the rodcube
binary (`cargo build --release`) or in deps/ there (`cargo run --release`), where
`rodcube fmu` looks for it, the newer of the two (or pass --binary).
The parameters' start values are those of the first scene in scenes/ of the model (the
paper's for rod_cube), or of --scene FILE. The FMU carries the model as data (the tapes of
the system and its fast phases, in resources/), so the library is the same for every model:
one only derived (`rodcube derive --tapes-into DIR SPEC`) exports with --models DIR.

Examples:
  rodcube fmu rod_cube --out out/fmu
  rodcube fmu hinged_rod --out out/fmu --scene my_hinged.yaml
  rodcube fmu sled --models models --scene sled_scene.yaml --out out/fmu";

const RUN_HELP: &str = "\
A scene is a YAML file:
  model: rod_cube
  parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}   # SI units
  want: [separation_angle, separation_time, theta_series, contact_force_series, tip_trajectory]
  tolerance: 1.0e-12        # relative, optional
  samples: 1000             # points in each series, optional
  until: 0.6                # s from release: go on through impacts to this time, optional
`rodcube models` lists each model's parameters and the quantities `want` may name.

Examples:
  rodcube run
  rodcube run scenes/ladder.yaml --out out/ladder-test
  rodcube run scenes/angle_only.yaml --json";

#[derive(Parser)]
#[command(
    name = "rodcube",
    version,
    about = "A rod leaning on a cube, released from rest: separation angle and time, \
             contact force, trajectories, and the physics checks the paper skips",
    after_help = EXAMPLES
)]
struct Cli {
    #[command(subcommand)]
    /// What to do (default: `run`, the paper's scene)
    command: Option<Command>,
    /// Also look for models' tapes (`<model>.tape.json`) in DIR, before `generated/` under the
    /// current directory: a model derived there runs with no build
    #[arg(long, value_name = "DIR", global = true)]
    models: Option<PathBuf>,
    /// Run every compiled-in model from its tape instead (the same program, evaluated; every
    /// result equal to the bit)
    #[arg(long, global = true)]
    interpreted: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene: print a table (or JSON) and write results.json, CSVs and SVG plots
    #[command(after_help = RUN_HELP)]
    Run(RunArgs),
    /// List the models with their parameters (name, unit, meaning) and the quantities they offer
    Models(LayoutArgs),
    /// Sweep the separation angle and time over a grid of (n, a/ell) or a CSV of points
    #[command(after_help = numerics_cli::SWEEP_HELP)]
    Sweep(numerics_cli::SweepArgs),
    /// Write DIR/MODEL.fmu, an FMI 2.0 co-simulation FMU of a system
    #[command(after_help = FMU_HELP)]
    Fmu(FmuArgs),
    /// Compare every method against a high-precision reference: error, evaluations, time
    #[command(after_help = numerics_cli::ACCURACY_HELP)]
    Accuracy(numerics_cli::AccuracyArgs),
    // ---- `derive` subcommand: exists only with the cargo feature `derive` -----------------
    // LEAD: wire `Command::Derive` (below, in `main`) to `rodcube::derive::run(...)` and put
    // its arguments in `DeriveArgs`. Nothing else in this file depends on the feature.
    /// Derive the models from derivations/*.yaml into generated/ (feature `derive`)
    #[cfg(feature = "derive")]
    Derive(DeriveArgs),
}

/// Arguments of `rodcube derive`.
#[cfg(feature = "derive")]
#[derive(Args)]
struct DeriveArgs {
    /// Specs to derive (default: every derivations/*.yaml)
    specs: Vec<PathBuf>,
    /// Write nothing; exit non-zero naming the files that regenerating would change
    #[arg(long)]
    check: bool,
    /// Overwrite generated files even where they were edited by hand
    #[arg(long)]
    force: bool,
    /// Write only the tapes of SPECS, into DIR, and nothing into generated/ (what `run --spec`
    /// does before it runs the scene)
    #[arg(long, value_name = "DIR", requires = "specs")]
    tapes_into: Option<PathBuf>,
}

#[derive(Args)]
struct RunArgs {
    /// Scene file (YAML) [default: the paper's scene, scenes/paper.yaml as built in]
    scene: Option<PathBuf>,
    /// Print results.json on stdout instead of the table
    #[arg(long)]
    json: bool,
    /// Output directory [default: out/<scene stem>/]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Derive this model spec now (in memory: nothing is written to generated/) and run the
    /// scene on it, with no build
    #[cfg(feature = "derive")]
    #[arg(long, value_name = "SPEC")]
    spec: Option<PathBuf>,
    #[command(flatten)]
    layout: LayoutArgs,
}

#[derive(Args)]
struct FmuArgs {
    /// The system (`rodcube models` lists them)
    model: String,
    /// Output directory: the FMU is DIR/MODEL.fmu
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Scene whose parameters are the start values [default: the model's scene in scenes/]
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    /// The shared library with the FMI entry points [default: librodcube.so beside rodcube,
    /// or in deps/ there]
    #[arg(long, value_name = "FILE")]
    binary: Option<PathBuf>,
}

/// How the printed tables are laid out.
#[derive(Args, Clone, Copy, Default)]
struct LayoutArgs {
    /// Follow each table with the meaning of every row, and list everything a long run
    /// summarises (every phase's checks, every impact, every phase in the work)
    #[arg(long, short)]
    verbose: bool,
    /// Do not wrap lines (by default they fit $COLUMNS, the terminal, or 100 columns)
    #[arg(long)]
    wide: bool,
}

impl LayoutArgs {
    fn layout(self) -> report::table::Layout {
        report::table::Layout::detect(self.wide, self.verbose)
    }
}

/// With no subcommand, `rodcube` runs the paper's scene (`rodcube run`).
fn default_command() -> Command {
    Command::Run(RunArgs {
        scene: None,
        json: false,
        out: None,
        #[cfg(feature = "derive")]
        spec: None,
        layout: LayoutArgs::default(),
    })
}

/// The paper's scene, built into the binary so that a bare `rodcube` works from any directory.
const PAPER_SCENE: &str = include_str!("../scenes/paper.yaml");

/// The scene of `rodcube run`: the file given, or the built-in paper's scene (named as the
/// file it was built from, so its messages and its output directory, `out/paper/`, are the
/// same as the file's).
fn load_scene(path: Option<&PathBuf>) -> Result<Scene, Failure> {
    let source = match path {
        Some(path) => Source::File(path),
        None => Source::Text {
            text: PAPER_SCENE,
            file: std::path::Path::new("scenes/paper.yaml"),
        },
    };
    Scene::read(source).map_err(Failure::Scene)
}

/// Why a command failed; each kind has its exit status.
enum Failure {
    /// The scene is invalid (or the planner found its parameters inconsistent).
    Scene(SceneError),
    /// The computation failed.
    Solve(anyhow::Error),
    /// The command line asks for something that cannot be (an unknown model, an axis a model
    /// lacks): exit status 2, as for the errors clap reports.
    Usage(anyhow::Error),
    /// An output could not be written.
    Output(anyhow::Error),
    /// An input file is invalid: a model spec or a sweep's points (its message names the file
    /// and the line).
    Invalid(anyhow::Error),
}

impl From<RunError> for Failure {
    /// A scene's refusal (the planner's of its values included, placed at their field) is
    /// [`Failure::Scene`], a failed solve [`Failure::Solve`] naming the scene's file.
    fn from(e: RunError) -> Self {
        match e {
            RunError::Scene(e) => Failure::Scene(e),
            RunError::Solve { file, error } => Failure::Solve(
                anyhow::Error::from(error).context(format!("solving {} failed", file.display())),
            ),
        }
    }
}

impl Failure {
    fn report(&self) -> ExitCode {
        match self {
            Failure::Scene(e) => {
                note(&e.to_string());
                ExitCode::from(EXIT_SCENE)
            }
            Failure::Solve(e) => {
                note(&format!("error: {e:#}"));
                ExitCode::from(EXIT_FAILED)
            }
            Failure::Usage(e) => {
                note(&format!("error: {e:#}"));
                ExitCode::from(EXIT_USAGE)
            }
            Failure::Output(e) => {
                note(&format!("error: {e:#}"));
                ExitCode::from(EXIT_OUTPUT)
            }
            Failure::Invalid(e) => {
                note(&format!("error: {e:#}"));
                ExitCode::from(EXIT_SCENE)
            }
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or_else(default_command);
    #[cfg(feature = "derive")]
    let deriving = matches!(command, Command::Derive(_));
    #[cfg(not(feature = "derive"))]
    let deriving = false;
    // `derive` writes the tapes; every other command may run them.
    if !deriving && let Err(f) = load_models(cli.models.as_deref(), cli.interpreted) {
        return f.report();
    }
    let outcome = match command {
        Command::Run(args) => run(args),
        Command::Models(args) => models(args),
        Command::Fmu(args) => fmu(args),
        Command::Sweep(args) => numerics_cli::sweep(args),
        Command::Accuracy(args) => numerics_cli::accuracy(args),
        #[cfg(feature = "derive")]
        Command::Derive(args) => derive(args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => f.report(),
    }
}

/// Puts the models of the tapes found (`--models DIR`, then `generated/` here) into the
/// registry, and with `--interpreted` every compiled model's own tape in place of its code. A
/// tape the loader refuses is an invalid input file (exit 3, naming it).
fn load_models(dir: Option<&std::path::Path>, interpreted: bool) -> Result<(), Failure> {
    if let Some(d) = dir
        && !d.is_dir()
    {
        return Err(Failure::Usage(anyhow::anyhow!(
            "--models {}: not a directory",
            d.display()
        )));
    }
    let invalid = |e: rodcube::tape::TapeError| Failure::Invalid(e.into());
    if interpreted {
        rodcube::models::interpret_compiled().map_err(invalid)?;
    }
    rodcube::models::load_search_path(dir).map_err(invalid)
}

/// `rodcube derive`: regenerate `generated/` (or check that it is fresh).
#[cfg(feature = "derive")]
fn derive(args: DeriveArgs) -> Result<(), Failure> {
    use rodcube::derive::{Error, Options, run};
    if let Some(dir) = &args.tapes_into {
        return write_tapes(&args.specs, dir);
    }
    let opts = Options {
        root: PathBuf::from("."),
        specs: args.specs,
        check: args.check,
        force: args.force,
    };
    match run(&opts) {
        Ok(outcome) => {
            for (model, took) in &outcome.timings {
                note(&format!(
                    "derived {model} in {:.1} ms",
                    took.as_secs_f64() * 1e3
                ));
            }
            for f in &outcome.written {
                note(&format!("wrote {}", f.display()));
            }
            if !outcome.stale.is_empty() {
                let list: Vec<String> = outcome
                    .stale
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect();
                return Err(Failure::Solve(anyhow::anyhow!(
                    "generated files are stale: {}; run `{}` and commit the result",
                    list.join(", "),
                    rodcube::derive::emit::COMMAND
                )));
            }
            note(&format!(
                "{} files up to date",
                outcome.unchanged.len() + outcome.written.len()
            ));
            Ok(())
        }
        Err(Error::Spec(e)) => Err(Failure::Invalid(anyhow::anyhow!("{e}"))),
        Err(e) => Err(Failure::Solve(anyhow::anyhow!("{e}"))),
    }
}

/// `rodcube derive --tapes-into DIR SPECS`: the specs' tapes, written together (or none).
#[cfg(feature = "derive")]
fn write_tapes(specs: &[PathBuf], dir: &std::path::Path) -> Result<(), Failure> {
    use rodcube::derive::Error;
    let mut files = Vec::new();
    for spec in specs {
        match rodcube::derive::tapes(spec) {
            Ok(tapes) => files.extend(tapes.into_iter().map(|t| (dir.join(&t.path), t.text))),
            Err(Error::Spec(e)) => return Err(Failure::Invalid(anyhow::anyhow!("{e}"))),
            Err(e) => return Err(Failure::Solve(anyhow::anyhow!("{e}"))),
        }
    }
    OutDir::create(dir).map_err(|e| Failure::Output(e.into()))?;
    rodcube::io::write_all_atomic(&files).map_err(|e| Failure::Output(e.into()))?;
    for (path, _) in &files {
        note(&format!("wrote {}", path.display()));
    }
    Ok(())
}

/// `rodcube run --spec SPEC`: derives the spec's models in a child process of this program
/// (Symbolica prints its licence banner on stdout, which goes to this program's stderr there,
/// so `--json` keeps stdout exactly results.json), into a temporary directory, and loads their
/// tapes into the registry. Nothing is written to generated/.
#[cfg(feature = "derive")]
fn derive_spec(spec: &std::path::Path) -> Result<(), Failure> {
    let failed = |what: &str, e: &dyn std::fmt::Display| {
        Failure::Solve(anyhow::anyhow!("--spec {}: {what}: {e}", spec.display()))
    };
    let dir = std::env::temp_dir().join(format!("rodcube-spec-{}", std::process::id()));
    let exe = std::env::current_exe().map_err(|e| failed("cannot find this program", &e))?;
    let status = std::process::Command::new(exe)
        .arg("derive")
        .arg("--tapes-into")
        .arg(&dir)
        .arg(spec)
        .stdin(std::process::Stdio::null())
        .stdout(std::io::stderr())
        .status()
        .map_err(|e| failed("cannot start the derivation", &e))?;
    let loaded = if status.success() {
        rodcube::models::load_derived(&dir, spec).map_err(|e| Failure::Invalid(e.into()))
    } else {
        // The child has said why on stderr; its status says what kind of failure it was.
        Err(match status.code() {
            Some(code) if code == i32::from(EXIT_SCENE) => Failure::Invalid(anyhow::anyhow!(
                "--spec {}: the spec is invalid",
                spec.display()
            )),
            _ => failed("the derivation failed", &status),
        })
    };
    let _ = std::fs::remove_dir_all(&dir);
    loaded.map(|_| ())
}

/// `rodcube run`.
fn run(args: RunArgs) -> Result<(), Failure> {
    #[cfg(feature = "derive")]
    if let Some(spec) = &args.spec {
        derive_spec(spec)?;
    }
    let scene = load_scene(args.scene.as_ref())?;
    let out_dir = match args.out {
        Some(dir) => dir,
        None => default_out_dir(&scene)?,
    };
    // Before solving, so an unwritable output fails at once.
    let out = OutDir::create(&out_dir).map_err(|e| Failure::Output(e.into()))?;
    let results = scene.run().map_err(Failure::from)?;
    let text = if args.json {
        report::json::to_string(&results).map_err(|e| Failure::Output(e.into()))?
    } else {
        report::table::render(&results, Some(scene.info()), &args.layout.layout())
    };
    // Write the files first, print the results either way, then report a write failure.
    let written = report::write_all(&out, &results);
    print_stdout(&text)?;
    match written {
        Ok(paths) => {
            note(&format!(
                "wrote {} files to {}",
                paths.len(),
                out_dir.display()
            ));
            Ok(())
        }
        Err(e) => Err(Failure::Output(
            anyhow::Error::from(e).context("the results were not all saved"),
        )),
    }
}

/// `out/<scene stem>/`, if the stem is a plain name.
fn default_out_dir(scene: &Scene) -> Result<PathBuf, Failure> {
    let stem = scene.stem().unwrap_or("");
    check_name(stem).map_err(|e| {
        Failure::Output(
            anyhow::Error::from(e)
                .context("cannot name the output directory after the scene; pass --out DIR"),
        )
    })?;
    Ok(PathBuf::from("out").join(stem))
}

/// `rodcube fmu`: every refusal (an unknown model, a missing library, an output directory
/// that cannot be written) exits 2, a refused scene 3; the archive is written atomically.
fn fmu(args: FmuArgs) -> Result<(), Failure> {
    use rodcube::fmu::export::{self, ExportError};
    let usage = |e: ExportError| Failure::Usage(e.into());
    let model = export::find_system(&args.model, rodcube::models::all()).map_err(usage)?;
    let scene = match &args.scene {
        Some(path) => Some(Scene::load(path).map_err(Failure::Scene)?),
        None => None,
    };
    let defaults = export::defaults(model, scene.as_ref()).map_err(|e| match e {
        ExportError::Scene(e) => Failure::Scene(e),
        e => usage(e),
    })?;
    let binary = match args.binary {
        Some(path) => path,
        None => export::default_binary().ok_or_else(|| {
            Failure::Usage(anyhow::anyhow!(
                "cannot locate the rodcube executable to find {} beside it; pass --binary FILE",
                export::LIBRARY_NAME
            ))
        })?,
    };
    let tapes = export::tapes(model).map_err(usage)?;
    let library = export::read_binary(&binary).map_err(usage)?;
    // The message alone: it already ends with the system's reason.
    let out = OutDir::create(&args.out).map_err(|e| Failure::Usage(anyhow::anyhow!("{e}")))?;
    let path = export::write_fmu(model, &defaults, &tapes, &library, &out).map_err(usage)?;
    note(&format!("wrote {}", path.display()));
    Ok(())
}

/// `rodcube models`.
fn models(args: LayoutArgs) -> Result<(), Failure> {
    // The systems a scene may name; their fast phases are listed under them.
    let infos: Vec<_> = (rodcube::models::all().iter().map(|m| m.info()))
        .filter(|i| i.is_general())
        .collect();
    print_stdout(&report::table::models(&infos, &args.layout()))
}

/// A diagnostic line on stderr (ignoring a closed stderr rather than panicking like `eprintln!`).
fn note(message: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{message}");
}

/// Writes to stdout; a closed pipe (`rodcube run | head`) is not an error.
fn print_stdout(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::Output(
            anyhow::Error::from(e).context("cannot write to stdout"),
        )),
        _ => Ok(()),
    }
}
