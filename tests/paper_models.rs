//! The hand-typed test models are self-consistent: their reduced functions, unreduced
//! equations, reaction forces and energy agree, so the solver tests built on them mean something.

mod common;

use common::paper::{FREE_ROD, ROD_CUBE, paper, ratios};
use rodcube::solve::unreduced::accelerations;
use rodcube::system::System;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Along the reduced motion: unreduced accelerations and forces match the reduced ones, energy
/// and momentum are those of the start, and theta'' is half the derivative of theta'^2.
fn check_consistency(sys: &System, delta_end: f64) {
    let e0 = sys.energy(&sys.initial_state());
    let p0 = sys.momenta(&sys.initial_state())[0];
    for i in 1..=20 {
        let delta = delta_end * i as f64 / 20.0;
        let red = sys.reduced(delta);
        let theta_dot = -red.theta_dot_sq.sqrt();
        let state = sys.full_state(0.1, delta, theta_dot);
        let qdd = accelerations(sys, &state, 0.0).unwrap();
        assert!(
            close(qdd[1], red.theta_ddot, 1e-12),
            "theta'' {} vs {}",
            qdd[1],
            red.theta_ddot
        );
        let f_full = sys.forces_full(&state, &qdd, &[]);
        let f_red = sys.forces(delta);
        let f_scale = f_red.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in f_full.iter().zip(&f_red) {
            assert!(
                (a - b).abs() <= 1e-12 * f_scale,
                "force {a} vs {b} at delta {delta}"
            );
        }
        let e = sys.energy(&state);
        assert!(close(e, e0, 1e-14), "energy {e} vs {e0}");
        let p = sys.momenta(&state)[0];
        assert!(
            (p - p0).abs() <= 1e-13 * sys.p()[0].max(1.0),
            "momentum {p} vs {p0}"
        );
        // theta'' = (1/2) d(theta'^2)/d(theta) = -(1/2) d(theta'^2)/d(delta)
        let h = 1e-5 * delta_end;
        let d =
            (sys.reduced(delta + h).theta_dot_sq - sys.reduced(delta - h).theta_dot_sq) / (2.0 * h);
        assert!(
            close(-0.5 * d, red.theta_ddot, 1e-7),
            "{} vs {}",
            -0.5 * d,
            red.theta_ddot
        );
    }
}

#[test]
fn rod_cube_reduced_and_unreduced_forms_agree() {
    for (n, r) in [(3.0, 0.25), (0.01, 0.9), (100.0, 0.05), (1.0, 0.5)] {
        let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
        check_consistency(&sys, 0.99 * sys.theta_initial());
    }
}

#[test]
fn rod_cube_matches_the_printed_equations_at_r_one_quarter() {
    // Eq. (12) as printed holds at r = 1/4; eq. (16) is the contact force; eq. (22) the tip.
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (g, ell, n) = (9.81, 1.0, 3.0);
    let beta = (1.0f64 - 0.0625).sqrt();
    for i in 0..10 {
        let delta = 0.2 * i as f64 / 10.0;
        let red = sys.reduced(delta);
        let (s, c) = (red.sin, red.cos);
        let d = 4.0 / 3.0 - s * s / (1.0 + n);
        let printed = g / (2.0 * ell)
            * (-4.0 * c / d + (1.0 / (1.0 + n)) * (1.0 - 4.0 * s) * (2.0 * s * c) / (d * d));
        assert!(
            close(red.theta_ddot, printed, 1e-13),
            "{} vs {printed}",
            red.theta_ddot
        );
        let state = sys.full_state(0.0, delta, -red.theta_dot_sq.sqrt());
        let tip = sys.points(&state).pos[1];
        let x2 = ell * c / (2.0 * (1.0 + n)) + (1.0 + 2.0 * n) / (2.0 * (1.0 + n)) * ell * beta;
        assert!((tip[0] - x2).abs() < 1e-15 && (tip[1] - ell * s).abs() < 1e-15);
        // eq. (21): the tip is on the ellipse
        let e = (2.0 * (1.0 + n) * tip[0] / ell - (1.0 + 2.0 * n) * beta).powi(2)
            + (tip[1] / ell).powi(2);
        assert!((e - 1.0).abs() < 1e-14);
    }
}

#[test]
fn free_rod_reduced_and_unreduced_forms_agree() {
    let params = common::paper::free_after(0.17, -1.3, -0.01, -0.2);
    let sys = System::new(&FREE_ROD, &params).unwrap();
    check_consistency(&sys, 0.17);
    // The centre of mass keeps its horizontal velocity.
    let v0 = sys.points(&sys.initial_state()).vel[2][0];
    let delta = 0.1;
    let state = sys.full_state(0.05, delta, -sys.reduced(delta).theta_dot_sq.sqrt());
    assert!((sys.points(&state).vel[2][0] - v0).abs() < 1e-15);
}
