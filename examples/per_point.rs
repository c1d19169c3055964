//! Per-point cost probe: solves the first N points (default 1000) of a fixed set of the paper's
//! model with the public per-point API, single-threaded, and prints the sum of the separation
//! angles plus times to 17 significant digits (run it under `valgrind --tool=callgrind` to count
//! instructions per point; see `benches/README.md`).
//!
//! The set (`examples/common/per_point_set.rs`): the 100 x 100 grid `n_i = 10^(-3 + 6 i / 99)`,
//! `a/ell_j = 0.01 + 0.98 j / 99` (`ell = g = m1 = 1`, `m2 = n`), row-major by `i`; point `k` is
//! grid index `(7919 k) mod 10000`.
//!
//! Usage: `cargo run --release --example per_point -- [N] [--baseline]` (`--baseline`: the
//! baseline instruction set even where the CPU has AVX2; the results are the same to the bit).

use rodcube::models;
use rodcube::solve::lean::LeanSolver;
use std::process::ExitCode;

#[path = "common/per_point_set.rs"]
mod set;

fn main() -> ExitCode {
    let (mut count, mut baseline) = (1000, false);
    for arg in std::env::args().skip(1) {
        if arg == "--baseline" {
            baseline = true;
        } else {
            match arg.parse::<usize>() {
                Ok(n) => count = n,
                Err(_) => {
                    eprintln!(
                        "per_point: expected N (a non-negative integer) or --baseline, got {arg:?}"
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
    for (k, p) in points.iter().enumerate() {
        match solver.solve(p) {
            Ok(r) => sum += r.separation_angle + r.separation_time,
            Err(e) => {
                eprintln!("per_point: point {k} ({p:?}): {e}");
                return ExitCode::FAILURE;
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
