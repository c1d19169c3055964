//! Per-point cost probe: solves the first N points (default 1000) of a fixed set of the paper's
//! model with the public per-point API, single-threaded, and prints the sum of the separation
//! angles plus times to 17 significant digits (run it under `valgrind --tool=callgrind` to count
//! instructions per point; see `benches/README.md`).
//!
//! The set (`examples/common/per_point_set.rs`): the 100 x 100 grid `n_i = 10^(-3 + 6 i / 99)`,
//! `a/ell_j = 0.01 + 0.98 j / 99` (`ell = g = m1 = 1`, `m2 = n`), row-major by `i`; point `k` is
//! grid index `(7919 k) mod 10000`.
//!
//! Usage: `cargo run --release --example per_point -- [N] [--baseline] [--sensitivities]`
//! (`--baseline`: the baseline instruction set even where the CPU has AVX2; the results are the
//! same to the bit. `--sensitivities`: each point also with `d theta_sep/dp` and `d t_sep/dp` for
//! every parameter, `LeanSolver::sensitivities`, their sum added to the printed one).

use rodcube::models;
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::fast::sensitivity::SensitivityWork;
use std::process::ExitCode;

#[path = "common/per_point_set.rs"]
mod set;

fn main() -> ExitCode {
    let (mut count, mut baseline, mut sensitivities) = (1000, false, false);
    for arg in std::env::args().skip(1) {
        if arg == "--baseline" {
            baseline = true;
        } else if arg == "--sensitivities" {
            sensitivities = true;
        } else {
            match arg.parse::<usize>() {
                Ok(n) => count = n,
                Err(_) => {
                    eprintln!(
                        "per_point: expected N (a non-negative integer), --baseline or \
                         --sensitivities, got {arg:?}"
                    );
                    return ExitCode::from(2);
                }
            }
        }
    }
    let Some(model) = models::find("rod_cube") else {
        eprintln!("per_point: the model rod_cube is not generated");
        return ExitCode::FAILURE;
    };
    let points = set::per_point_set(count);
    let mut solver = match LeanSolver::new(model) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("per_point: {e}");
            return ExitCode::FAILURE;
        }
    };
    if baseline {
        solver.baseline_only();
    }
    let mut sum = 0.0;
    let np = model.info().parameters.len();
    let (mut angle, mut time) = (vec![0.0; np], vec![0.0; np]);
    let mut work = SensitivityWork::default();
    for (k, p) in points.iter().enumerate() {
        let r = match solver.solve(p) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("per_point: point {k} ({p:?}): {e}");
                return ExitCode::FAILURE;
            }
        };
        sum += r.separation_angle + r.separation_time;
        if sensitivities {
            match solver.sensitivities(p, &r, &mut work, &mut angle, &mut time) {
                Ok(Ok(())) => sum += angle.iter().chain(&time).sum::<f64>(),
                Ok(Err(why)) => {
                    eprintln!("per_point: point {k} ({p:?}): no sensitivities: {why:?}");
                    return ExitCode::FAILURE;
                }
                Err(e) => {
                    eprintln!("per_point: point {k} ({p:?}): {e}");
                    return ExitCode::FAILURE;
                }
            }
        }
    }
    println!("{sum:.16e}");
    if std::env::var_os("PER_POINT_EVALS").is_some() {
        eprintln!(
            "evaluations per point: {:.2}",
            solver.evals as f64 / count.max(1) as f64
        );
    }
    ExitCode::SUCCESS
}
