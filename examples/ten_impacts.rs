//! The ten-impact benchmark's request (`benches/solve.rs`, `impacts`) run `N` times in one
//! process, for instruction counts under callgrind and for the fastest run's time on a host
//! whose other load makes means unreliable.
//!
//! ```text
//! cargo build --release --example ten_impacts
//! target/release/examples/ten_impacts 2000          # fastest, tenth percentile and median run
//! valgrind --tool=callgrind target/release/examples/ten_impacts 21   # minus the run with N = 1
//! target/release/examples/ten_impacts 2000 rocking  # the rocking block's ten strikes
//! ```
//!
//! The request: the paper's rod and cube with every support a contact (`rod_cube_liftoff`,
//! restitution 1/2), to 0.5543 s at a tolerance of 1e-12, only the impacts wanted; with
//! `rocking`, Housner's rocking block of `scenes/rocking.yaml` (friction 0.7 at both corners,
//! plastic strikes) to 2.18 s, ten strikes, at the same tolerance.

use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::scene::Scene;
use std::process::ExitCode;
use std::time::Instant;

/// The paper's rod and cube, and the restitution of both ends.
const PARAMETERS: [(&str, f64); 6] = [
    ("m1", 1.0),
    ("m2", 3.0),
    ("ell", 1.0),
    ("a", 0.25),
    ("g", 9.81),
    ("e", 0.5),
];

fn main() -> ExitCode {
    let runs = match std::env::args().nth(1).map(|s| s.parse::<usize>()) {
        None => 1,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("usage: ten_impacts [RUNS > 0] [rocking]");
            return ExitCode::from(2);
        }
    };
    let rocking = match std::env::args().nth(2).as_deref() {
        None => false,
        Some("rocking") => true,
        Some(other) => {
            eprintln!("usage: ten_impacts [RUNS > 0] [rocking], not `{other}`");
            return ExitCode::from(2);
        }
    };
    let request = if rocking {
        // The rocking block of `scenes/rocking.yaml`, its parameters read from the scene.
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/rocking.yaml");
        match Scene::load(std::path::Path::new(path)) {
            Ok(scene) => Request::new(scene.model, scene.parameters),
            Err(e) => {
                eprintln!("{e}");
                return ExitCode::FAILURE;
            }
        }
    } else {
        let Some(model) = rodcube::models::find("rod_cube_liftoff") else {
            eprintln!("rod_cube_liftoff is not generated");
            return ExitCode::FAILURE;
        };
        Request::new(model, &PARAMETERS[..])
    };
    let until = if rocking { 2.18 } else { 0.5543 };
    let request = request
        .with_want(&[Quantity::Impacts])
        .with_tolerance(1e-12)
        .with_until(Some(until));
    let mut times = Vec::with_capacity(runs);
    let mut impacts = 0;
    for _ in 0..runs {
        let start = Instant::now();
        match plan::run(&request) {
            Ok(run) => impacts = run.impacts.as_ref().map_or(0, Vec::len),
            Err(e) => {
                eprintln!("the run failed: {e}");
                return ExitCode::FAILURE;
            }
        }
        times.push(start.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{impacts} impacts a run, {runs} runs: fastest {:.1} us, tenth percentile {:.1} us, median {:.1} us",
        times[0],
        times[runs / 10],
        times[runs / 2]
    );
    ExitCode::SUCCESS
}
