//! The hand-typed test models are self-consistent: their reduced functions, unreduced
//! equations, reaction forces and energy agree, and the general model `rod_cube` with its
//! contacts as constraints moves as each fast phase does, so the solver tests built on them
//! mean something.

mod common;

use common::paper::{FREE_ROD, GENERAL, ROD_CUBE, paper, ratios};
use rodcube::solve::integrated::contacts::{self, Active};
use rodcube::system::{Bound, State, System};

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Along the reduced motion: unreduced accelerations and forces match the reduced ones, energy
/// and momentum are those of the start, and theta'' is half the derivative of theta'^2.
fn check_consistency(sys: &System, delta_end: f64) {
    let e0 = sys.energy(&sys.initial_state()).unwrap();
    let p0 = sys.momenta(&sys.initial_state()).unwrap()[0];
    for i in 1..=20 {
        let delta = delta_end * i as f64 / 20.0;
        let red = sys.reduced(delta).unwrap();
        let theta_dot = -red.theta_dot_sq.sqrt();
        let state = sys.full_state(0.1, delta, theta_dot).unwrap();
        let active = Active::of_model(sys.info());
        let qdd = contacts::dynamics(sys.bound(), &state, &active, 0.0)
            .unwrap()
            .qdd;
        let theta = sys.info().reduced_index.unwrap();
        assert!(
            close(qdd[theta], red.theta_ddot, 1e-12),
            "theta'' {} vs {}",
            qdd[theta],
            red.theta_ddot
        );
        let f_full = sys.forces_full(&state, &qdd).unwrap();
        let f_red = sys.forces(delta).unwrap();
        let f_scale = f_red.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in f_full.iter().zip(&f_red) {
            assert!(
                (a - b).abs() <= 1e-12 * f_scale,
                "force {a} vs {b} at delta {delta}"
            );
        }
        let e = sys.energy(&state).unwrap();
        assert!(close(e, e0, 1e-14), "energy {e} vs {e0}");
        let p = sys.momenta(&state).unwrap()[0];
        assert!(
            (p - p0).abs() <= 1e-13 * sys.p()[0].max(1.0),
            "momentum {p} vs {p0}"
        );
        // theta'' = (1/2) d(theta'^2)/d(theta) = -(1/2) d(theta'^2)/d(delta)
        let h = 1e-5 * delta_end;
        let d = (sys.reduced(delta + h).unwrap().theta_dot_sq
            - sys.reduced(delta - h).unwrap().theta_dot_sq)
            / (2.0 * h);
        assert!(
            close(-0.5 * d, red.theta_ddot, 1e-7),
            "{} vs {}",
            -0.5 * d,
            red.theta_ddot
        );
    }
}

/// The general model along a fast phase's motion, with that phase's contacts `closed` as
/// constraint rows: the same state (points, energy, total horizontal momentum), its closed gaps
/// and their rates zero, its Jacobian and bias the derivatives of its gaps (central
/// differences), and the same `theta''` and contact forces from the constrained equations.
fn check_general(sys: &System, closed: [bool; 2], delta_end: f64) {
    let general = Bound::from_values(&GENERAL, &sys.bound().p()[..5]).unwrap();
    let n = 4;
    let active = Active {
        closed: closed.to_vec(),
        modes: vec![],
    };
    for i in 0..=20 {
        let delta = delta_end * i as f64 / 20.0;
        let red = sys.reduced(delta).unwrap();
        let theta_dot = -red.theta_dot_sq.max(0.0).sqrt();
        let state = sys.full_state(0.1, delta, theta_dot).unwrap();
        let full = sys.to_full(&state).unwrap();
        // The same bodies at the same places.
        let (a, b) = (sys.points(&state).unwrap(), general.points(&full).unwrap());
        for (p, q) in a.pos.iter().chain(&a.vel).zip(b.pos.iter().chain(&b.vel)) {
            assert!(
                (p[0] - q[0]).abs() < 1e-15 && (p[1] - q[1]).abs() < 1e-15,
                "{p:?} vs {q:?}"
            );
        }
        let (e, e_general) = (sys.energy(&state).unwrap(), general.energy(&full).unwrap());
        assert!(close(e, e_general, 1e-14), "energy {e} vs {e_general}");
        let total = |p: Vec<f64>| p.iter().sum::<f64>();
        let (p, p_general) = (
            total(sys.momenta(&state).unwrap()),
            total(general.momenta(&full).unwrap()),
        );
        assert!((p - p_general).abs() < 1e-14, "momentum {p} vs {p_general}");
        // Gaps, their Jacobian and bias.
        let gaps = general.gaps(&full).unwrap();
        let (jac, bias) = general.constraints(&full).unwrap();
        for c in 0..2 {
            let row = &jac[c * n..(c + 1) * n];
            let rate: f64 = row.iter().zip(full.qd()).map(|(j, v)| j * v).sum();
            if closed[c] {
                assert!(gaps[c].abs() < 1e-15, "gap {c}: {}", gaps[c]);
                assert!(rate.abs() < 1e-14, "gap {c}'s rate {rate}");
            }
            let h = 1e-6;
            for j in 0..n {
                let shifted = |d: f64| {
                    let mut q = full.q().to_vec();
                    q[j] += d;
                    general
                        .gaps(&State::new(q, full.qd().to_vec()).unwrap())
                        .unwrap()[c]
                };
                let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
                assert!(
                    (fd - row[j]).abs() < 1e-8,
                    "dgap{c}/dq{j}: {fd} vs {}",
                    row[j]
                );
            }
            let moved = |d: f64| {
                let q = (full.q().iter().zip(full.qd()))
                    .map(|(q, v)| q + d * v)
                    .collect();
                let (jac, _) = general
                    .constraints(&State::new(q, full.qd().to_vec()).unwrap())
                    .unwrap();
                (0..n).map(|j| jac[c * n + j] * full.qd()[j]).sum::<f64>()
            };
            let fd = (moved(h) - moved(-h)) / (2.0 * h);
            let size = full.qd().iter().map(|v| v * v).sum::<f64>().max(1.0);
            assert!(
                (fd - bias[c]).abs() < 1e-7 * size,
                "bias {c}: {fd} vs {}",
                bias[c]
            );
        }
        // The constrained equations give the reduced motion and its forces.
        let d = contacts::dynamics(&general, &full, &active, 0.0).unwrap();
        let theta = general.info().reduced_index.unwrap();
        assert!(
            close(d.qdd[theta], red.theta_ddot, 1e-11),
            "theta'' {} vs {}",
            d.qdd[theta],
            red.theta_ddot
        );
        let f_red = sys.forces(delta).unwrap();
        let f_scale = f_red.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for c in 0..2 {
            let want = if closed[c] { f_red[c] } else { 0.0 };
            assert!(
                (d.forces[c] - want).abs() <= 1e-11 * f_scale,
                "force {c}: {} vs {want} at delta {delta}",
                d.forces[c]
            );
            if closed[c] {
                assert!(d.normal_acc[c].abs() < 1e-10, "{:?}", d.normal_acc);
            }
        }
    }
}

#[test]
fn rod_cube_reduced_and_unreduced_forms_agree() {
    for (n, r) in [(3.0, 0.25), (0.01, 0.9), (100.0, 0.05), (1.0, 0.5)] {
        let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
        check_consistency(&sys, 0.99 * sys.theta_initial());
        check_general(&sys, [true, true], 0.99 * sys.theta_initial());
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
        let red = sys.reduced(delta).unwrap();
        let (s, c) = (red.sin, red.cos);
        let d = 4.0 / 3.0 - s * s / (1.0 + n);
        let printed = g / (2.0 * ell)
            * (-4.0 * c / d + (1.0 / (1.0 + n)) * (1.0 - 4.0 * s) * (2.0 * s * c) / (d * d));
        assert!(
            close(red.theta_ddot, printed, 1e-13),
            "{} vs {printed}",
            red.theta_ddot
        );
        let state = sys
            .full_state(0.0, delta, -red.theta_dot_sq.sqrt())
            .unwrap();
        let tip = sys.points(&state).unwrap().pos[1];
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
    check_general(&sys, [false, true], 0.17);
    // The centre of mass keeps its horizontal velocity.
    let v0 = sys.points(&sys.initial_state()).unwrap().vel[2][0];
    let delta = 0.1;
    let state = sys
        .full_state(
            0.05,
            delta,
            -sys.reduced(delta).unwrap().theta_dot_sq.sqrt(),
        )
        .unwrap();
    assert!((sys.points(&state).unwrap().vel[2][0] - v0).abs() < 1e-15);
}
