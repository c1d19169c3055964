//! Time quadrature: the paper's times, the limits of PHYSICS.md, and <= 1e-13 relative error
//! against references computed without the `delta = u^2` substitution or the adaptive rule
//! (Gauss–Jacobi with the `1/sqrt` weight, and geometrically graded Gauss–Legendre panels).

mod common;

use common::paper::{FREE_ROD, ROD_CUBE, paper, ratios};
use gauss_quad::{FiniteAboveNegOneF64, GaussJacobi, GaussLegendre};
use rodcube::results::Work;
use rodcube::solve::fast::quadrature::{Control, Fall, RuleStep, TimeMesh, integrate};
use rodcube::solve::fast::separation::separation;
use rodcube::system::System;

/// `h(delta) = sqrt(delta / theta_dot^2)`, smooth when the start is not near upright.
fn h(sys: &System, delta: f64) -> f64 {
    (delta / sys.reduced(delta).unwrap().theta_dot_sq).sqrt()
}

/// `t = integral_0^de delta^(-1/2) h(delta) d delta` by Gauss–Jacobi (beta = -1/2 at delta = 0).
fn jacobi_time(sys: &System, delta_end: f64, n: usize) -> f64 {
    let rule = GaussJacobi::new(
        n.try_into().unwrap(),
        FiniteAboveNegOneF64::new(0.0).unwrap(),
        FiniteAboveNegOneF64::new(-0.5).unwrap(),
    );
    let half = 0.5 * delta_end;
    let sum: f64 = rule.iter().map(|(x, w)| w * h(sys, half * (1.0 + x))).sum();
    half.sqrt() * sum
}

/// Reference for any start: Gauss–Jacobi on `[0, d1]` with `d1` well inside the scale
/// `cos(theta_i)` where `h` varies, then Gauss–Legendre panels `[d, 2d]` up to `delta_end`.
fn graded_time(sys: &System, delta_end: f64) -> f64 {
    let c0 = sys.reduced(0.0).unwrap().cos;
    let d1 = (0.05 * c0).min(0.5 * delta_end);
    let mut t = jacobi_time(sys, d1, 60);
    let gl = GaussLegendre::new(40.try_into().unwrap());
    let mut lo = d1;
    while lo < delta_end {
        let hi = (2.0 * lo).min(delta_end);
        t += gl.integrate(lo, hi, |d| {
            1.0 / sys.reduced(d).unwrap().theta_dot_sq.sqrt()
        });
        lo = hi;
    }
    t
}

fn sep_delta(sys: &System) -> f64 {
    separation(sys, &mut Work::default())
        .unwrap()
        .separation()
        .unwrap()
        .delta
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn paper_times() {
    // PHYSICS.md's figures of the paper's case to five digits (eq. 15 to the separation,
    // eq. 10 to the floor in contact, sqrt(a/g)), for both values of g the paper may have used.
    for (g, t_sep, t_floor, t_point) in [
        (9.81, 0.10849, 0.18693, 0.15964),
        (9.8, 0.10855, 0.18702, 0.15972),
    ] {
        let sys = System::new(&ROD_CUBE, &paper(g)).unwrap();
        let mut work = Work::default();
        let sep = TimeMesh::build(&sys, sep_delta(&sys), 1e-13, &mut work).unwrap();
        let floor = TimeMesh::build(&sys, sys.delta_to_floor(), 1e-13, &mut work).unwrap();
        println!(
            "g = {g}: t_sep = {:.15} s, t_floor = {:.15} s ({} integrand evals)",
            sep.duration, floor.duration, work.integrand_evals
        );
        assert!((sep.duration - t_sep).abs() < 5e-6, "{}", sep.duration);
        assert!(
            (floor.duration - t_floor).abs() < 5e-6,
            "{}",
            floor.duration
        );
        assert!(((0.25 / g).sqrt() - t_point).abs() < 5e-6);
        // Against the references, to 1e-13.
        assert!(rel(sep.duration, jacobi_time(&sys, sep_delta(&sys), 60)) < 1e-13);
        assert!(rel(floor.duration, jacobi_time(&sys, sys.delta_to_floor(), 60)) < 1e-13);
        assert!(rel(sep.duration, graded_time(&sys, sep_delta(&sys))) < 1e-13);
    }
}

#[test]
fn error_falls_with_nodes_per_panel() {
    // One symmetric Gauss–Legendre panel in v over the paper's contact phase: spectral
    // convergence (n nodes on [-v_end, v_end] cost n/2 evaluations).
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let de = sep_delta(&sys);
    let reference = jacobi_time(&sys, de, 80);
    let fall = Fall::of(&sys, de).unwrap();
    let v_end = fall.v_at_delta(de);
    let mut errors = Vec::new();
    for n in [2, 4, 6, 8, 10, 12, 16, 20] {
        // A tolerance of 1 accepts the first panel whatever its rules say.
        let step = RuleStep {
            max_len: f64::INFINITY,
            low: 1,
            high: n,
        };
        let control = Control::new(&[step], 1.0);
        let (t, evals) = integrate(&fall, v_end, &control, &mut Vec::new(), |_| {}).unwrap();
        assert_eq!(evals as usize, 1 + n / 2);
        let e = rel(t, reference);
        println!("GL nodes {n:2}: relative error {e:.2e}");
        errors.push((n, e));
    }
    assert!(
        errors[0].1 > 1e-8,
        "two nodes cannot be that good: {:?}",
        errors[0]
    );
    let at = |n: usize| errors.iter().find(|e| e.0 == n).map(|e| e.1).unwrap();
    assert!(
        at(4) < 1e-5 && at(8) < 1e-11 && at(12) < 1e-14,
        "{errors:?}"
    );
}

#[test]
fn near_upright_and_nearly_flat_starts_keep_1e_13() {
    let mut table = Vec::new();
    for n in [1e-12, 3.0, 1e12] {
        for r in [1e-10, 1e-3, 0.25, 0.9, 0.999, 1.0 - 1e-6, 1.0 - 1e-9] {
            let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
            for de in [sep_delta(&sys), sys.delta_to_floor()] {
                let mut work = Work::default();
                let mesh = TimeMesh::build(&sys, de, 1e-13, &mut work).unwrap();
                let reference = graded_time(&sys, de);
                let e = rel(mesh.duration, reference);
                table.push((n, r, e, work.integrand_evals, mesh.panels.len()));
                assert!(
                    e < 1e-13,
                    "n = {n}, r = {r}, delta_end = {de}: {} vs {reference} ({e:e})",
                    mesh.duration
                );
            }
        }
    }
    for (n, r, e, evals, panels) in table {
        println!("n = {n:e}, r = {r:e}: rel err {e:.1e}, {evals} evals, {panels} panels");
    }
}

#[test]
fn flat_rod_separates_after_two_thirds_of_the_point_mass_time() {
    // r -> 0: t_sep -> (2/3) sqrt(a/g) for any n, with a relative correction O(r).
    for n in [1e-6, 3.0, 1e6] {
        let mut last = f64::INFINITY;
        for r in [1e-2, 1e-4, 1e-6, 1e-8] {
            let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
            let t = TimeMesh::build(&sys, sep_delta(&sys), 1e-13, &mut Work::default())
                .unwrap()
                .duration;
            let limit = 2.0 / 3.0 * (r / 9.81f64).sqrt();
            let dev = rel(t, limit);
            assert!(dev < 2.0 * r, "n = {n}, r = {r}: {t} vs {limit} ({dev:e})");
            assert!(dev < last);
            last = dev;
        }
    }
}

#[test]
fn near_upright_time_grows_like_log_of_one_over_cos_theta_i() {
    // t ~ sqrt(D ell / (2 g)) ln(1 / cos theta_i) + const, D = 4/3 - 1/(1+n) at the top.
    for n in [0.0 + 1e-9, 3.0, 1e9] {
        let time = |c0: f64| {
            let r = (1.0 - c0 * c0).sqrt();
            let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
            let t = TimeMesh::build(&sys, sep_delta(&sys), 1e-13, &mut Work::default())
                .unwrap()
                .duration;
            (sys.reduced(0.0).unwrap().cos, t)
        };
        let (c1, t1) = time(1e-4);
        let (c2, t2) = time(1e-5);
        let slope = (t2 - t1) / (c1 / c2).ln();
        let want = ((4.0 / 3.0 - 1.0 / (1.0 + n)) / (2.0 * 9.81)).sqrt();
        assert!(rel(slope, want) < 1e-3, "n = {n}: slope {slope} vs {want}");
    }
}

#[test]
fn free_phase_without_endpoint_singularity() {
    let params = common::paper::free_after(0.1677, -1.4, -0.01, -0.2);
    let sys = System::new(&FREE_ROD, &params).unwrap();
    let mut work = Work::default();
    let mesh = TimeMesh::build(&sys, sys.delta_to_floor(), 1e-13, &mut work).unwrap();
    let gl = GaussLegendre::new(60.try_into().unwrap());
    let reference = gl.integrate(0.0, sys.delta_to_floor(), |d| {
        1.0 / sys.reduced(d).unwrap().theta_dot_sq.sqrt()
    });
    assert!(
        rel(mesh.duration, reference) < 1e-13,
        "{} vs {reference}",
        mesh.duration
    );
    // A moving start puts branch points of the integrand at v = +-i theta_dot_i / sqrt(e F),
    // near the start when the rate is small: more panels than from rest.
    assert!(
        work.integrand_evals <= 200,
        "{} evals",
        work.integrand_evals
    );
}

#[test]
fn time_at_any_angle_matches_a_fresh_integral() {
    let sys = System::new(&ROD_CUBE, &ratios(3.0, 0.999)).unwrap();
    let de = sep_delta(&sys);
    let mut work = Work::default();
    let mesh = TimeMesh::build(&sys, de, 1e-13, &mut work).unwrap();
    for f in [1e-6, 1e-3, 0.1, 0.5, 0.77, 1.0] {
        let d = f * de;
        let t = mesh.time_at_delta(&sys, d, &mut work).unwrap();
        let fresh = TimeMesh::build(&sys, d, 1e-13, &mut work).unwrap().duration;
        assert!(rel(t, fresh) < 1e-13, "delta = {d}: {t} vs {fresh}");
    }
}
