//! The fall polynomial and the a-priori rule of the per-point solver
//! (`rodcube::solve::fast::prior`): the generated `P(s) = (sin theta_i - s) / theta_dot^2` equals
//! the ratio of the generated `theta_dot^2` and, for the paper's model, the ratio from eq. (9)
//! typed by hand; the lean preparation fills the constants it lists exactly as the full one; and
//! the a-priori rule agrees with the verified pair of rules, and with the 256-bit reference to
//! 1e-15, across the hard-case ranges of every model that has a fall polynomial.

mod common;

use common::numbers::Uniform;
use common::paper::ROD_CUBE;
use rodcube::model::{Model, start_offsets};
use rodcube::reference::{Family, Inputs, Reference, RootRoute, TimeRoute, relative_error};
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::system::System;

fn model(name: &str) -> &'static dyn Model {
    rodcube::models::find(name).expect("generated model")
}

/// The models with a fall polynomial, and random valid parameters for each (masses and ratios
/// over many decades, the lean angle up to nearly upright).
fn random_point(name: &str, u: &mut Uniform) -> Vec<f64> {
    let r = 1.0 - u.log(-9.0, 0.0).min(0.999_999);
    let n = u.log(-6.0, 6.0);
    match name {
        "wall_ladder_closed" => vec![1.0, 1.0, r, 9.81],
        "loaded_rod_closed" => {
            let info = model(name).info();
            let mut p: Vec<f64> = vec![0.0; info.parameters.len()];
            for (i, param) in info.parameters.iter().enumerate() {
                p[i] = match param.name {
                    "a" => r,
                    "m2" => n,
                    "g" => 9.81,
                    _ => 1.0,
                };
            }
            p
        }
        _ => vec![1.0, n, 1.0, r, 9.81],
    }
}

/// The fast phases with a fall polynomial: each system's phase with every contact closed, from
/// rest at release.
const WITH_FALL: [&str; 4] = [
    "rod_cube_closed",
    "hinged_rod_closed",
    "loaded_rod_closed",
    "wall_ladder_closed",
];

#[test]
fn every_model_with_a_fall_polynomial_is_listed_here() {
    for m in rodcube::models::all() {
        let info = m.info();
        let degree = info.reduction.and_then(|r| r.fall_degree);
        // A fall polynomial the per-point solver uses: of degree at most 2, on a phase that
        // holds its first contact closed (whose force's zero is the separation).
        let separates = info
            .contacts
            .first()
            .is_some_and(|c| c.closed && !c.bilateral);
        assert_eq!(
            degree.is_some_and(|d| d <= 2) && separates,
            WITH_FALL.contains(&info.name),
            "{}: fall degree {degree:?}",
            info.name
        );
    }
}

#[test]
fn the_fall_polynomial_is_the_drop_over_theta_dot_squared() {
    let mut u = Uniform(0xfa11);
    for name in WITH_FALL {
        let m = model(name);
        for _ in 0..50 {
            let p = random_point(name, &mut u);
            let sys = System::from_values(m, &p).unwrap_or_else(|e| panic!("{name} {p:?}: {e}"));
            let fall = sys.fall_coefficients();
            assert!(!fall.is_empty(), "{name}");
            let (k, layout) = (sys.k(), sys.layout());
            for _ in 0..5 {
                let delta = u.next() * 0.9 * sys.delta_to_floor();
                let (s, c, ds, dc) = start_offsets(
                    k[layout.k_theta_initial],
                    k[layout.k_sin_initial],
                    k[layout.k_cos_initial],
                    delta,
                );
                let w2 = sys.reduction().theta_dot_sq_sc(k, s, c, ds, dc);
                let from_fall = ds / rodcube::solve::fast::poly::horner(fall, s);
                assert!(
                    ((from_fall - w2) / w2).abs() < 1e-12,
                    "{name} {p:?} delta {delta}: {from_fall} vs {w2}"
                );
            }
        }
    }
}

#[test]
fn rod_cubes_fall_polynomial_is_eq_9_of_the_paper() {
    // The hand-typed model writes P from eq. (9): (ell / 4g) (4/3 - sin^2(theta) / (1 + n)).
    let mut u = Uniform(0x9);
    for _ in 0..200 {
        let p = [
            u.log(-2.0, 2.0),
            u.log(-6.0, 6.0),
            u.log(-2.0, 2.0),
            0.0,
            u.log(-1.0, 2.0),
        ];
        let p = [p[0], p[1], p[2], p[2] * u.next(), p[4]];
        let generated = System::from_values(model("rod_cube_closed"), &p).unwrap();
        let hand = System::from_values(&ROD_CUBE, &p).unwrap();
        let (a, b) = (generated.fall_coefficients(), hand.fall_coefficients());
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                (x - y).abs() <= 4.0 * f64::EPSILON * scale,
                "{p:?}: {a:?} vs {b:?}"
            );
        }
    }
}

#[test]
fn the_lean_preparation_fills_its_constants_as_the_full_one() {
    let mut u = Uniform(0x1ea);
    for name in WITH_FALL {
        let m = model(name);
        let (info, red) = (m.info(), m.reduction().unwrap());
        let layout = info.reduction.unwrap();
        assert!(!layout.lean_constants.is_empty(), "{name}");
        for _ in 0..20 {
            let p = random_point(name, &mut u);
            let mut full = vec![0.0; info.n_constants];
            let mut lean = vec![f64::NAN; info.n_constants];
            m.prepare(&p, &mut full);
            red.prepare_lean(&p, &mut lean);
            assert_eq!(lean[..p.len()], p[..], "{name}");
            for &i in layout.lean_constants {
                assert_eq!(
                    lean[i].to_bits(),
                    full[i].to_bits(),
                    "{name} k[{i}] at {p:?}"
                );
            }
            // What the per-point solver reads is listed (or is a parameter); the start's
            // angle, an `asin` it never reads, is not formed.
            let read = [
                layout.k_theta_dot_initial,
                layout.k_sin_initial,
                layout.k_cos_initial,
            ];
            assert!(
                read.iter()
                    .all(|i| *i < p.len() || layout.lean_constants.contains(i)),
                "{name}"
            );
            assert!(
                !layout.lean_constants.contains(&layout.k_theta_initial),
                "{name}"
            );
        }
    }
}

#[test]
fn the_a_priori_rule_agrees_with_the_verified_rules() {
    let mut u = Uniform(0xa9);
    for name in WITH_FALL {
        let m = model(name);
        let mut prior = LeanSolver::new(m).unwrap();
        let mut verified = LeanSolver::with_schedule(m, &[], 1e-14).unwrap();
        for _ in 0..300 {
            let p = random_point(name, &mut u);
            let (a, b) = (prior.solve(&p).unwrap(), verified.solve(&p).unwrap());
            assert_eq!(a.separation_angle, b.separation_angle, "{name} {p:?}");
            let e = ((a.separation_time - b.separation_time) / b.separation_time).abs();
            assert!(e < 2e-15, "{name} {p:?}: {a:?} vs {b:?} ({e:e})");
        }
    }
}

#[test]
fn the_avx2_route_gives_the_baseline_results_to_the_bit() {
    // The same operations in the same order in every lane, correctly rounded, so the copy of
    // the route compiled for AVX2 returns the baseline's numbers exactly, with as many
    // evaluations; over every model with a fall polynomial, nearly upright and heavy cubes
    // included (long panels, halved panels and the checked route all taken).
    #[cfg(target_arch = "x86_64")]
    let wide_cpu = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let wide_cpu = false;
    let mut u = Uniform(0x5eed);
    for name in WITH_FALL {
        let m = model(name);
        let mut wide = LeanSolver::new(m).unwrap();
        let mut base = LeanSolver::new(m).unwrap();
        base.baseline_only();
        assert_eq!(
            wide.wide(),
            wide_cpu,
            "{name}: the AVX2 copy is used exactly where it runs"
        );
        assert!(!base.wide());
        for _ in 0..3000 {
            let p = random_point(name, &mut u);
            let (a, b) = (wide.solve(&p), base.solve(&p));
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.separation_angle.to_bits(), b.separation_angle.to_bits());
                    assert_eq!(
                        a.separation_time.to_bits(),
                        b.separation_time.to_bits(),
                        "{name} {p:?}: {a:?} vs {b:?}"
                    );
                }
                (a, b) => assert_eq!(a.is_ok(), b.is_ok(), "{name} {p:?}"),
            }
            assert_eq!(wide.evals, base.evals, "{name} {p:?}");
        }
    }
}

#[test]
fn the_per_point_solver_matches_the_reference_to_1e_15() {
    // The hard-case ranges: n from 1e-12 to 1e12, a/ell from 1e-10 to 1 - 1e-15.
    let ns = [1e-12, 1e-8, 1e-4, 1e-2, 1.0, 3.0, 1e2, 1e4, 1e8, 1e12];
    let rs = [
        1e-10,
        1e-5,
        0.01,
        0.1,
        0.25,
        0.5,
        0.75,
        0.9,
        0.99,
        0.999_9,
        1.0 - 1e-6,
        1.0 - 1e-9,
        1.0 - 1e-12,
        1.0 - 1e-15,
    ];
    for family in [Family::RodCube, Family::HingedRod, Family::WallLadder] {
        let m = model(family.name());
        let mut lean = LeanSolver::new(m).unwrap();
        let ns: &[f64] = if family == Family::WallLadder {
            &[1.0]
        } else {
            &ns
        };
        for &n in ns {
            for &r in &rs {
                let mut reference = Reference::new(Inputs::dimensionless(family, n, r)).unwrap();
                let sep = reference.separation(RootRoute::ClosedForm).unwrap();
                let t_ref = reference.separation_time(TimeRoute::SinhGauss).unwrap();
                let p = match family {
                    Family::WallLadder => vec![1.0, 1.0, r, 1.0],
                    _ => vec![1.0, n, 1.0, r, 1.0],
                };
                let out = lean.solve(&p).unwrap();
                let ea = relative_error(out.separation_angle, &sep.theta).abs();
                let et = relative_error(out.separation_time, &t_ref).abs();
                // The hinged rod with a heavy cube separates far below its start, where
                // s = sin(theta_i) - (sin(theta_i) - s) loses digits (tests/hard_cases.rs).
                let bound = match family {
                    Family::HingedRod => {
                        1e-15f64.max(16.0 * f64::EPSILON * r / sep.theta_f64.sin())
                    }
                    _ => 1e-15,
                };
                assert!(ea <= 1e-15, "{family:?} n={n:e} r={r}: angle error {ea:e}");
                assert!(
                    et <= bound,
                    "{family:?} n={n:e} r={r}: time error {et:e} > {bound:e}"
                );
            }
        }
    }
}
