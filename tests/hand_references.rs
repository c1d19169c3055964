//! Tests of the hand-derived references in `tests/common/hand.rs` against closed forms, limits,
//! second routes (Lagrange, energy balances, quadratures) and the numbers of the sympy/mpmath
//! scripts in `docs/hand_derivations/`, so that the references can be trusted when rodcube is
//! compared with them.

mod common;

use common::hand::{
    BlockEvent, CUBE_TIPPING_SUP, Cylinder, CylinderEvent, Gauss, GaussRk, Ladder, LadderEvent,
    RodBlock, cube_push, cube_tipping_ratio, integrate, ladder_frictionless_separation,
    liftoff_floor_push, liftoff_scan, separation_sin, sin_drop, solve_linear,
};

/// `|a - b| <= tol * max(|b|, floor)`, with a message.
fn close(a: f64, b: f64, tol: f64, what: &str) {
    let err = (a - b).abs() / b.abs().max(1e-300);
    assert!(
        err <= tol,
        "{what}: {a:.17e} vs {b:.17e} (relative {err:.2e} > {tol:.0e})"
    );
}

// ---------------------------------------------------------------------------------------------
// Numerics
// ---------------------------------------------------------------------------------------------

#[test]
fn gauss_rule_is_exact_to_degree_2n_minus_1() {
    for n in [1usize, 2, 5, 12, 30] {
        let rule = Gauss::new(n);
        for deg in 0..2 * n {
            let got = rule.integrate(|x| x.powi(deg as i32), 0.0, 1.0, 1);
            close(
                got,
                1.0 / (deg as f64 + 1.0),
                1e-14,
                &format!("n = {n}, x^{deg}"),
            );
        }
        // degree 2n is not integrated exactly (the error is visible for small n)
        if n > 5 {
            continue;
        }
        let got = rule.integrate(|x| x.powi(2 * n as i32), -1.0, 1.0, 1);
        assert!((got - 2.0 / (2.0 * n as f64 + 1.0)).abs() > 1e-6);
    }
    let rule = Gauss::new(20);
    close(
        rule.integrate(f64::exp, 0.0, 3.0, 2),
        3f64.exp() - 1.0,
        1e-15,
        "exp",
    );
}

#[test]
fn gauss_rk_has_order_ten_and_finds_events() {
    // y'' = -y from (1, 0): y = cos t, energy y^2 + y'^2 = 1.
    let f = |y: &[f64], out: &mut [f64]| {
        out[0] = y[1];
        out[1] = -y[0];
    };
    let rk = GaussRk::new(5);
    let err = |h: f64| {
        let mut y = vec![1.0, 0.0];
        let n = (4.0 / h).round() as usize;
        for _ in 0..n {
            y = rk.step(&f, &y, h);
        }
        (y[0] - 4f64.cos()).abs()
    };
    let (e1, e2) = (err(1.0), err(0.5));
    // order 10: halving h divides the error by ~1024
    assert!(e1 / e2 > 700.0 && e1 / e2 < 1500.0, "ratio {}", e1 / e2);
    // the event y = 0 at t = pi/2, and y' = 0 again at t = pi
    let hit = integrate(&f, &|y, out| out[0] = y[0], 1, &[1.0, 0.0], 0.01, 10.0);
    assert_eq!(hit.event, Some(0));
    close(hit.t, std::f64::consts::FRAC_PI_2, 1e-14, "t at y = 0");
    let hit = integrate(
        &f,
        &|y, out| out[0] = y[0] + 0.5,
        1,
        &[1.0, 0.0],
        0.01,
        10.0,
    );
    close(
        hit.t,
        2.0 * std::f64::consts::FRAC_PI_3,
        1e-14,
        "t at y = -1/2",
    );
    // no event before t_max
    let hit = integrate(&f, &|_, out| out[0] = 1.0, 1, &[1.0, 0.0], 0.03, 1.0);
    assert_eq!(hit.event, None);
    close(hit.y[0], 1f64.cos(), 1e-14, "y(1)");
}

#[test]
fn linear_solve_with_pivoting() {
    // 2y + z = 7, x + y = 3, 3x + z = 6 (a zero first pivot): x = 1, y = 2, z = 3
    let x = solve_linear(
        [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]],
        [7.0, 3.0, 6.0],
    );
    for (a, b) in x.iter().zip([1.0, 2.0, 3.0]) {
        close(*a, b, 1e-15, "x");
    }
    // sin(theta0) - sin(theta) without cancellation: delta = theta0 - theta is exact here
    let theta = 1.2 - 1e-9;
    let delta = 1.2 - theta;
    close(sin_drop(1.2, theta), 1.2f64.cos() * delta, 1e-8, "sin drop");
    close(
        sin_drop(1.2, 0.2),
        1.2f64.sin() - 0.2f64.sin(),
        1e-15,
        "sin drop",
    );
}

// ---------------------------------------------------------------------------------------------
// A. ladder_friction
// ---------------------------------------------------------------------------------------------

fn ladder(a: f64, mu_f: f64, mu_w: f64) -> Ladder {
    Ladder {
        m1: 1.0,
        ell: 1.0,
        a,
        g: 9.81,
        mu_f,
        mu_w,
    }
}

#[test]
fn frictionless_ladder_leaves_the_wall_at_two_thirds_of_the_height() {
    for a in [0.05, 0.3, 0.6, 0.8, 0.95] {
        let lad = ladder(a, 0.0, 0.0);
        let end = lad.run();
        assert_eq!(end.event, LadderEvent::WallSeparation, "a = {a}");
        close(end.theta.sin(), 2.0 * a / 3.0, 1e-13, "sin(theta_sep)");
        let (th_sep, t_sep) = ladder_frictionless_separation(1.0, a, 9.81);
        close(end.theta, th_sep, 1e-13, "theta_sep");
        close(end.t, t_sep, 1e-12, "t_sep vs the energy quadrature");
        // energy conserved, theta'^2 = 3 (g/ell)(s0 - s)
        close(
            end.theta_dot.powi(2),
            3.0 * 9.81 * a / 3.0,
            1e-12,
            "theta'^2 at separation",
        );
        assert_eq!(end.friction_work, 0.0);
    }
    // mpmath (docs/hand_derivations/ladder_friction.py), a = 0.8
    let (th, t) = ladder_frictionless_separation(1.0, 0.8, 9.81);
    close(th, 0.562_536_244_543_855_6, 1e-15, "mpmath theta_sep");
    close(t, 0.277_464_828_053_933_1, 1e-14, "mpmath t_sep");
}

#[test]
fn frictionless_ladder_forces_are_the_closed_forms() {
    let lad = ladder(0.8, 0.0, 0.0);
    let s0 = 0.8;
    for theta in [0.9, 0.8, 0.7, 0.6] {
        let (s, c) = f64::sin_cos(theta);
        let wd = -(3.0 * 9.81 * (s0 - s)).sqrt();
        let tdd = lad.theta_ddot(theta, wd);
        close(tdd, -1.5 * 9.81 * c, 1e-14, "theta''");
        let f = lad.forces(theta, wd, tdd);
        close(
            f.n_wall,
            0.75 * 9.81 * c * (3.0 * s - 2.0 * s0),
            1e-12,
            "N_w",
        );
        close(
            f.n_floor,
            9.81 * (1.0 + 9.0 * s * s - 6.0 * s0 * s) / 4.0,
            1e-12,
            "N_f",
        );
        assert_eq!((f.f_floor, f.f_wall), (0.0, 0.0));
    }
}

#[test]
fn ladder_forces_satisfy_the_balances_about_the_foot() {
    // Horizontal and vertical Newton equations of the centre and the moment balance about the
    // foot, sum M_F = I theta'' + (G - F) x m a_G, none of them the route of `forces`.
    for (mu_f, mu_w) in [(0.0, 0.0), (0.3, 0.0), (0.3, 0.2), (0.1, 0.6)] {
        let lad = ladder(0.8, mu_f, mu_w);
        for (theta, wd) in [(0.9, 0.0), (0.7, -2.0), (0.5, -4.0)] {
            let tdd = lad.theta_ddot(theta, wd);
            let f = lad.forces(theta, wd, tdd);
            let (s, c) = f64::sin_cos(theta);
            let g = 9.81;
            let xg_dd = 0.5 * (s * tdd + c * wd * wd);
            let yg_dd = 0.5 * (c * tdd - s * wd * wd);
            let rx = xg_dd - (f.f_floor - f.n_wall);
            let ry = yg_dd - (f.n_floor + f.f_wall - g);
            let moment = -0.5 * g * c + c * f.f_wall + s * f.n_wall;
            let rm = moment - (tdd / 12.0 + 0.5 * (c * yg_dd - s * xg_dd));
            for r in [rx, ry, rm] {
                assert!(r.abs() < 1e-13, "mu {mu_f} {mu_w}: {rx} {ry} {rm}");
            }
        }
    }
}

#[test]
fn ladder_starts_to_slide_only_below_the_static_limit() {
    for (mu_f, mu_w) in [(0.3f64, 0.0f64), (0.3, 0.2), (0.5, 0.5), (0.1, 2.0)] {
        let limit = ((1.0 - mu_f * mu_w) / (2.0 * mu_f)).atan();
        let a_at = |theta: f64| theta.sin();
        let above = ladder(a_at(limit * (1.0 + 1e-9)), mu_f, mu_w);
        let below = ladder(a_at(limit * (1.0 - 1e-9)), mu_f, mu_w);
        assert!(!above.slides() && below.slides(), "mu = {mu_f}, {mu_w}");
        assert_eq!(above.run().event, LadderEvent::Holds);
        assert_eq!(above.run().t, 0.0);
        // just below the limit theta'' at rest is small and negative
        let tdd = below.theta_ddot(below.theta0(), 0.0);
        assert!(tdd < 0.0 && tdd > -1e-6, "theta'' = {tdd}");
        // no Painleve paradox: A >= ell/6 wherever it slides
        for k in 0..=100 {
            let th = below.theta0() * k as f64 / 100.0;
            assert!(below.mass_coefficient(th) >= (1.0 - 1e-12) / 6.0);
        }
    }
    // mu_f mu_w >= 1 holds at any angle
    for a in [0.1, 0.5, 0.9] {
        assert!(!ladder(a, 1.0, 1.0).slides());
        assert!(!ladder(a, 2.0, 0.6).slides());
    }
}

#[test]
fn ladder_with_floor_friction_agrees_with_lagrange_energy_and_quadrature() {
    let lad = ladder(0.8, 0.3, 0.0);
    // Lagrange with a generalized friction force gives the same theta''
    for (theta, wd) in [(0.9, -0.0), (0.8, -1.3), (0.6, -3.0), (0.3, -5.0)] {
        close(
            lad.theta_ddot(theta, wd),
            lad.lagrange_theta_ddot(theta, wd),
            1e-13,
            "Lagrange theta''",
        );
    }
    let end = lad.run();
    assert_eq!(end.event, LadderEvent::WallSeparation);
    // energy balance E(t) - E(0) = work of friction
    let de = lad.energy(end.theta, end.theta_dot) - lad.energy(lad.theta0(), 0.0);
    assert!(
        end.friction_work < -0.05,
        "friction work {}",
        end.friction_work
    );
    close(de, end.friction_work, 1e-11, "energy balance");
    // the theta'^2(theta) quadrature and the separation found without time integration
    close(
        lad.quadrature_theta_dot_sq(end.theta),
        end.theta_dot * end.theta_dot,
        1e-11,
        "theta'^2 at separation",
    );
    let (th_q, t_q) = lad.quadrature_separation().unwrap();
    close(end.theta, th_q, 1e-11, "theta_sep: ODE vs quadrature");
    close(end.t, t_q, 1e-11, "t_sep: ODE vs quadrature");
    // mpmath (docs/hand_derivations/ladder_friction.py: Taylor ODE for theta'^2(theta))
    close(
        end.theta,
        0.441_393_529_826_328_95,
        1e-13,
        "mpmath theta_sep",
    );
    close(end.t, 0.512_197_282_398_103, 1e-12, "mpmath t_sep");
    // friction delays separation and lowers it compared with the frictionless ladder
    let (th0, t0) = ladder_frictionless_separation(1.0, 0.8, 9.81);
    assert!(end.t > t0 && end.theta < th0);
    // the step does not matter
    let half = lad.run_with_step(end.t / 2000.0);
    close(half.t, end.t, 1e-12, "t_sep with a shorter step");
}

#[test]
fn ladder_with_wall_friction_agrees_and_reduces_continuously() {
    let lad = ladder(0.8, 0.3, 0.2);
    let end = lad.run();
    assert_eq!(end.event, LadderEvent::WallSeparation);
    let de = lad.energy(end.theta, end.theta_dot) - lad.energy(lad.theta0(), 0.0);
    close(de, end.friction_work, 1e-11, "energy balance");
    let (th_q, t_q) = lad.quadrature_separation().unwrap();
    close(end.theta, th_q, 1e-11, "theta_sep: ODE vs quadrature");
    close(end.t, t_q, 1e-11, "t_sep: ODE vs quadrature");
    close(
        end.theta,
        0.408_322_519_914_016_65,
        1e-13,
        "mpmath theta_sep",
    );
    close(end.t, 0.631_136_909_247_217_1, 1e-12, "mpmath t_sep");
    for (theta, wd) in [(0.9, 0.0), (0.7, -2.0), (0.5, -4.0)] {
        close(
            lad.theta_ddot(theta, wd),
            lad.lagrange_theta_ddot(theta, wd),
            1e-13,
            "Lagrange theta''",
        );
    }
    // mu_w -> 0: the separation moves linearly in mu_w onto the mu_w = 0 one
    let base = ladder(0.8, 0.3, 0.0).run();
    let d3 = ladder(0.8, 0.3, 1e-3).run();
    let d4 = ladder(0.8, 0.3, 1e-4).run();
    let (dt3, dt4) = (d3.t - base.t, d4.t - base.t);
    let (dth3, dth4) = (d3.theta - base.theta, d4.theta - base.theta);
    assert!(dt3.abs() > 1e-7 && dth3.abs() > 1e-7);
    close(dt3 / dt4, 10.0, 2e-3, "t_sep linear in mu_w");
    close(dth3 / dth4, 10.0, 2e-3, "theta_sep linear in mu_w");
    // the forces carry the Coulomb laws
    let f = lad.forces(0.8, -1.0, lad.theta_ddot(0.8, -1.0));
    close(f.f_floor, 0.3 * f.n_floor, 1e-15, "F_f");
    close(f.f_wall, 0.2 * f.n_wall, 1e-15, "F_w");
}

// ---------------------------------------------------------------------------------------------
// B. fixed_cylinder
// ---------------------------------------------------------------------------------------------

fn cylinder(r: f64, th0: f64) -> Cylinder {
    Cylinder {
        m1: 1.0,
        ell: 1.0,
        r,
        th0,
        g: 9.81,
    }
}

#[test]
fn cylinder_pushes_at_release_iff_r_exceeds_the_threshold() {
    for th0 in [0.3, 0.6, 0.9, 1.2, 1.5] {
        let thr = 0.5 * f64::sin(th0) * (1.0 - f64::cos(th0));
        for k in 1..200 {
            let r = thr * (0.5 + k as f64 / 100.0);
            if k == 50 || 2.0 * r.atan() >= th0 {
                continue; // on the threshold, or the tangent point beyond the top
            }
            let cyl = cylinder(r, th0);
            let (p0, n0) = cyl.release_forces();
            let (tdd, p, n) = cyl.both_solve(th0, 0.0);
            close(p, p0, 1e-12, "P0 closed form vs Newton-Euler");
            close(n, n0, 1e-12, "N0 closed form vs Newton-Euler");
            assert!(tdd < 0.0);
            assert_eq!(p0 > 0.0, cyl.pushes_at_release(), "th0 = {th0}, r = {r}");
            assert_eq!(p0 > 0.0, r > thr);
        }
    }
}

#[test]
fn cylinder_foot_lifts_at_0_1334_s() {
    let cyl = cylinder(0.2, 1.0);
    let end = cyl.run();
    assert_eq!(end.event, CylinderEvent::FootLifts);
    // mpmath (docs/hand_derivations/fixed_cylinder.py)
    close(end.t, 0.133_399_876_833_614, 1e-11, "lift-off time");
    close(end.theta, 0.859_909_991_029_883, 1e-12, "lift-off angle");
    let (p0, n0) = cyl.release_forces();
    close(p0, 0.288_405_763_678_434, 1e-12, "P0");
    close(n0, 5.080_010_369_384_812, 1e-12, "N0");
    // energy integral and the step
    close(
        end.theta_dot.powi(2),
        cyl.theta_dot_sq(end.theta),
        1e-11,
        "theta'^2",
    );
    close(
        cyl.run_with_step(end.t / 3000.0).t,
        end.t,
        1e-12,
        "shorter step",
    );
    // the time by quadrature of the energy integral (theta = th0 - v^2)
    let t_q = Gauss::new(20).integrate(
        |v| 2.0 * v / cyl.theta_dot_sq(1.0 - v * v).sqrt(),
        0.0,
        (1.0 - end.theta).sqrt(),
        4,
    );
    close(end.t, t_q, 1e-11, "lift-off time by quadrature");
}

#[test]
fn cylinder_newton_euler_matches_the_energy_integral() {
    let cyl = cylinder(0.3, 1.2);
    for theta in [1.15, 1.0, 0.8, 0.65] {
        let u = cyl.theta_dot_sq(theta);
        let (tdd, p, n) = cyl.both_solve(theta, -u.sqrt());
        // theta'' = (1/2) d(theta'^2)/dtheta (central difference)
        let h = 1e-5;
        let du = (cyl.theta_dot_sq(theta + h) - cyl.theta_dot_sq(theta - h)) / (2.0 * h);
        close(tdd, 0.5 * du, 1e-8, "theta''");
        // the residuals vanish on the path and see a 1e-6 change of a force
        let (q, qd) = cyl.both_state(theta, -u.sqrt());
        let h2 = (0.5 * theta).sin();
        let x1dd =
            cyl.r / (2.0 * h2 * h2) * tdd - cyl.r * theta.sin() / (2.0 * h2 * h2).powi(2) * u;
        let qdd = [x1dd, 0.0, tdd];
        let res = cyl.residuals_both(&q, &qd, &qdd, p, n);
        for r in res {
            assert!(r.abs() < 1e-12 * 10.0, "residual {res:?}");
        }
        let off = cyl.residuals_both(&q, &qd, &qdd, p * (1.0 + 1e-6), n);
        assert!(off.iter().any(|r| r.abs() > 1e-7), "{off:?}");
        assert!(cyl.gap(&q).abs() < 1e-15);
        close(
            cyl.contact_distance(&q),
            cyl.tangent_distance(theta),
            1e-14,
            "d",
        );
    }
}

#[test]
fn cylinder_other_endings() {
    let edge = cylinder(0.3, 1.0).run();
    assert_eq!(edge.event, CylinderEvent::Edge);
    close(edge.theta, 2.0 * 0.3f64.atan(), 1e-13, "edge angle");
    assert_eq!(
        cylinder(0.05, 1.0).run().event,
        CylinderEvent::LeavesAtRelease
    );
    let lifts = cylinder(0.05, 0.3);
    assert!(lifts.pushes_at_release() && lifts.release_forces().1 < 0.0);
    assert_eq!(lifts.run().event, CylinderEvent::FootLiftsAtRelease);
}

#[test]
fn cylinder_after_lift_off_conserves_energy_and_keeps_the_contact() {
    let cyl = cylinder(0.2, 1.0);
    let end = cyl.run();
    let (q0, qd0) = cyl.both_state(end.theta, end.theta_dot);
    // at lift-off (N = 0) the one-contact accelerations are the two-contact ones
    let (tdd, p, n) = cyl.both_solve(end.theta, end.theta_dot);
    assert!(n.abs() < 1e-9);
    let (acc, p1) = cyl.free_foot_solve(&q0, &qd0);
    close(acc[2], tdd, 1e-9, "theta'' at lift-off");
    close(p1, p, 1e-9, "P at lift-off");
    assert!(acc[1].abs() < 1e-8, "y1'' = {}", acc[1]);
    // integrate the one-contact phase for 0.1 s
    let f = |y: &[f64], out: &mut [f64]| {
        let q = [y[0], y[1], y[2]];
        let qd = [y[3], y[4], y[5]];
        let (a, _) = cyl.free_foot_solve(&q, &qd);
        out[..3].copy_from_slice(&qd);
        out[3..].copy_from_slice(&a);
    };
    let ev = |y: &[f64], out: &mut [f64]| {
        let q = [y[0], y[1], y[2]];
        let (_, p) = cyl.free_foot_solve(&q, &[y[3], y[4], y[5]]);
        out[0] = p;
        out[1] = cyl.ell - cyl.contact_distance(&q);
    };
    let y0 = [q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]];
    let hit = integrate(&f, &ev, 2, &y0, 2e-4, 0.1);
    assert!(hit.t > 0.01, "one-contact phase ended at {}", hit.t);
    let (q, qd) = (
        [hit.y[0], hit.y[1], hit.y[2]],
        [hit.y[3], hit.y[4], hit.y[5]],
    );
    close(cyl.energy(&q, &qd), cyl.energy(&q0, &qd0), 1e-12, "energy");
    assert!(cyl.gap(&q).abs() < 1e-11, "gap drift {}", cyl.gap(&q));
    assert!(q[1] > 0.0, "the foot is above the floor: y1 = {}", q[1]);
    let (acc, p) = cyl.free_foot_solve(&q, &qd);
    for r in cyl.residuals_free_foot(&q, &qd, &acc, p) {
        assert!(r.abs() < 1e-12);
    }
    let off = cyl.residuals_free_foot(&q, &qd, &[acc[0], acc[1], acc[2] * (1.0 + 1e-6)], p);
    assert!(off.iter().any(|r| r.abs() > 1e-9));
}

// ---------------------------------------------------------------------------------------------
// C. rod_block_tipping
// ---------------------------------------------------------------------------------------------

fn block(m2: f64, w: f64, h: f64) -> RodBlock {
    RodBlock {
        m1: 1.0,
        m2,
        ell: 1.0,
        w,
        h,
        g: 9.81,
    }
}

#[test]
fn flat_phase_push_is_eq_16_and_the_block_balances() {
    let blk = block(3.0, 0.25, 0.25); // the paper's case
    let th0 = blk.theta0();
    let s_sep = separation_sin(3.0, 0.25);
    for k in 1..=10 {
        let theta = (s_sep + (0.25 - s_sep) * k as f64 / 10.0).min(0.25).asin();
        let wd = -blk.theta_dot_sq(theta).sqrt();
        let acc = blk.flat_solve(theta, wd);
        let (s, c) = theta.sin_cos();
        // the paper's eq. (16) as printed, a = h
        let (n, r) = (3.0, 0.25);
        let eq16 = 3.0
            * (-3.0 * 9.81 * c * (8.0 * r * (1.0 + n) - 12.0 * (1.0 + n) * s + 3.0 * s * s * s))
            / (4.0 * (1.0 + n) - 3.0 * s * s).powi(2);
        close(
            acc.p,
            blk.push(theta),
            1e-11,
            "P: Newton-Euler vs closed form",
        );
        close(acc.p, eq16, 1e-11, "P vs eq. 16");
        // the block's balances with N_near, N_far and xb'' = P/m2 hold
        let nn = blk.near_push(theta, acc.p);
        let nf = blk.far_push(theta, acc.p);
        let qb = [1.0 + 0.125, 0.125, 0.0];
        let tip = [1.0, s];
        let res = blk.block_residuals(&qb, &[acc.p / 3.0, 0.0, 0.0], tip, acc.p, nn, nf);
        for r in res {
            assert!(r.abs() < 1e-13, "{res:?}");
        }
        assert!(nf > 0.0 && nn > 0.0);
        // the rod's balances with the push along +x on the block (phi = 0)
        let rr = blk.rod_residuals(
            &[0.0, 0.0, theta],
            &[0.3, 0.0, wd],
            &[acc.x1_ddot, 0.0, acc.theta_ddot],
            acc.p,
            0.0,
            acc.n_foot,
        );
        for r in rr {
            assert!(r.abs() < 1e-12, "{rr:?}");
        }
        // the same near push from the tipping ratio
        close(
            nn,
            0.5 * 3.0 * 9.81 * (1.0 - blk.tipping_ratio(theta, acc.p)),
            1e-12,
            "N_near",
        );
        // the cube's ratio stays below 0.05 (PHYSICS.md)
        assert!(cube_tipping_ratio(3.0, 0.25, theta) < 0.05);
    }
    let end = blk.run_flat();
    assert_eq!(end.event, BlockEvent::Separates);
    close(end.theta.sin(), s_sep, 1e-12, "separation angle");
    close(end.t, 0.108_49, 1e-4, "t_sep of the paper (g = 9.81)");
    close(th0, 0.25f64.asin(), 1e-15, "theta0");
}

#[test]
fn block_inertia_is_the_integral_over_the_rectangle() {
    // I = (m2 / (w h)) int int (x^2 + y^2) dx dy over the block, by 2-D Gauss quadrature
    let blk = block(0.7, 0.3, 0.5);
    let rule = Gauss::new(4);
    let density = blk.m2 / (blk.w * blk.h);
    let i = rule.integrate(
        |x| rule.integrate(|y| density * (x * x + y * y), -0.25, 0.25, 1),
        -0.15,
        0.15,
        1,
    );
    close(blk.block_inertia(), i, 1e-14, "block inertia");
    // and the corners
    let qb = [2.0, 0.25, -0.3];
    let (s, c) = f64::sin_cos(-0.3);
    let near = blk.near_corner(&qb);
    let far = blk.far_corner(&qb);
    close(near[0], 2.0 + c * -0.15 - s * -0.25, 1e-15, "near x");
    close(near[1], 0.25 + s * -0.15 + c * -0.25, 1e-15, "near y");
    close(far[0], 2.0 + c * 0.15 - s * -0.25, 1e-15, "far x");
    close(far[1], 0.25 + s * 0.15 + c * -0.25, 1e-15, "far y");
}

#[test]
fn a_cube_never_tips() {
    // dense sampling of n over 18 decades, r over (0, 1), the whole contact phase
    let mut sup: f64 = 0.0;
    let mut arg = (0.0, 0.0, 0.0);
    for i in 0..=72 {
        let n = 10f64.powf(-9.0 + 18.0 * i as f64 / 72.0);
        for j in 1..200 {
            let r = j as f64 / 200.0;
            let ss = separation_sin(n, r);
            for k in 0..=100 {
                let s = ss + (r - ss) * k as f64 / 100.0;
                let theta = s.min(r).asin();
                let rho = cube_tipping_ratio(n, r, theta);
                // the hand bound 3 c s/(4 (1 + n) - 3 s^2) <= 3 c s/(1 + 3 c^2) <= 3/4
                let c = theta.cos();
                let bound = 3.0 * c * s / (4.0 * (1.0 + n) - 3.0 * s * s);
                assert!(rho <= bound * (1.0 + 1e-12) + 1e-15, "n {n} r {r} s {s}");
                assert!(bound <= 3.0 * c * s / (1.0 + 3.0 * c * c) * (1.0 + 1e-12));
                if rho > sup {
                    sup = rho;
                    arg = (n, r, s);
                }
            }
        }
    }
    assert!(sup < CUBE_TIPPING_SUP, "sup {sup} at {arg:?}");
    assert!(sup > 0.7499, "sup {sup} at {arg:?}");
    // the supremum: release, n -> 0, cos^2 = 1/5
    let r_star = 2.0 / 5f64.sqrt();
    let rho = cube_tipping_ratio(1e-12, r_star, r_star.asin());
    close(rho, 0.75, 1e-11, "ratio at the supremum point");
}

#[test]
fn tall_light_block_tips_at_release() {
    let blk = block(0.1, 0.05, 0.5);
    let th0 = blk.theta0();
    let p0 = blk.push(th0);
    // At release eq. (16) gives P/(m2 g) = 3 c r/(4 (1+n) - 3 r^2) (the bracket is
    // -r (4 (1+n) - 3 r^2) at s = r) and y_tip - h/2 = h/2, so the ratio is h/w times that:
    // 3.559008508703 (docs/hand_derivations.md, section C).
    let (r, c) = (0.5f64, 0.5f64.asin().cos());
    close(
        blk.tipping_ratio(th0, p0),
        (0.5 / 0.05) * 3.0 * c * r / (4.0 * 1.1 - 3.0 * r * r),
        1e-12,
        "ratio at release",
    );
    let end = blk.run_flat();
    assert_eq!(end.event, BlockEvent::TipsAtRelease);
    assert_eq!(end.t, 0.0);
    // the tipping mode at release is consistent: all pushes >= 0, the near edge rises
    let (q, qd) = blk.flat_state(&end);
    let (acc, forces) = blk.tipping_solve(&q, &qd);
    assert!(forces.iter().all(|&f| f > 0.0), "{forces:?}");
    assert!(acc[5] < 0.0, "phi'' = {}", acc[5]);
    let near_y_dd = acc[4] - 0.5 * blk.w * acc[5]; // phi = phi' = 0
    assert!(near_y_dd > 0.0);
    // while the flat mode's near push would be negative
    assert!(blk.near_push(th0, p0) < 0.0);
}

#[test]
fn tall_block_with_upright_rod_tips_after_release() {
    let blk = block(1.0, 0.099, 0.99);
    let th0 = blk.theta0();
    assert!(blk.tipping_ratio(th0, blk.push(th0)) < 0.83);
    let end = blk.run_flat();
    assert_eq!(end.event, BlockEvent::Tips);
    // mpmath (docs/hand_derivations/rod_block_tipping.py)
    close(end.t, 0.148_266_098_687_190_3, 1e-10, "onset time");
    close(end.theta, 1.391_721_254_605_654, 1e-12, "onset angle");
    let acc = blk.flat_solve(end.theta, end.theta_dot);
    close(
        blk.tipping_ratio(end.theta, acc.p),
        1.0,
        1e-10,
        "ratio at onset",
    );
    assert!(end.theta.sin() > separation_sin(1.0, 0.99));
    // the tipping mode at onset has the flat accelerations (phi'' = 0, N_near = 0 in both)
    let (q, qd) = blk.flat_state(&end);
    let (a6, forces) = blk.tipping_solve(&q, &qd);
    close(a6[0], acc.x1_ddot, 1e-8, "x1''");
    close(a6[2], acc.theta_ddot, 1e-8, "theta''");
    assert!(a6[5].abs() < 1e-7, "phi'' = {}", a6[5]);
    close(forces[1], acc.p, 1e-8, "P");
    close(forces[0], acc.n_foot, 1e-8, "N");
    close(forces[2], 9.81, 1e-7, "N_far = m2 g");
    // the tipping phase: energy, contacts, residuals
    let f = |y: &[f64], out: &mut [f64]| {
        let q: [f64; 6] = y[..6].try_into().unwrap();
        let qd: [f64; 6] = y[6..].try_into().unwrap();
        let (a, _) = blk.tipping_solve(&q, &qd);
        out[..6].copy_from_slice(&qd);
        out[6..].copy_from_slice(&a);
    };
    let ev = |y: &[f64], out: &mut [f64]| {
        let q: [f64; 6] = y[..6].try_into().unwrap();
        let qd: [f64; 6] = y[6..].try_into().unwrap();
        let (_, fo) = blk.tipping_solve(&q, &qd);
        out.copy_from_slice(&fo);
    };
    let mut y0 = [0.0; 12];
    y0[..6].copy_from_slice(&q);
    y0[6..].copy_from_slice(&qd);
    let hit = integrate(&f, &ev, 3, &y0, 2e-4, 0.05);
    let q1: [f64; 6] = hit.y[..6].try_into().unwrap();
    let qd1: [f64; 6] = hit.y[6..].try_into().unwrap();
    assert!(hit.t > 0.01);
    close(blk.energy(&q1, &qd1), blk.energy(&q, &qd), 1e-12, "energy");
    assert!(q1[5] < -1e-4, "the block tipped forward: phi = {}", q1[5]);
    assert!(q1[1].abs() < 1e-12);
    assert!(blk.far_corner(&[q1[3], q1[4], q1[5]])[1].abs() < 1e-12);
    assert!(blk.near_corner(&[q1[3], q1[4], q1[5]])[1] > 0.0);
    let (sp, cp) = q1[5].sin_cos();
    let tip = [q1[0] + q1[2].cos(), q1[1] + q1[2].sin()];
    let face = (tip[0] - q1[3]) * cp + (tip[1] - q1[4]) * sp + 0.5 * blk.w;
    assert!(face.abs() < 1e-12, "tip off the face by {face}");
    let (a, fo) = blk.tipping_solve(&q1, &qd1);
    let rb = blk.block_residuals(
        &[q1[3], q1[4], q1[5]],
        &[a[3], a[4], a[5]],
        tip,
        fo[1],
        0.0,
        fo[2],
    );
    let rr = blk.rod_residuals(
        &[q1[0], q1[1], q1[2]],
        &[qd1[0], qd1[1], qd1[2]],
        &[a[0], a[1], a[2]],
        fo[1],
        q1[5],
        fo[0],
    );
    for r in rb.iter().chain(&rr) {
        assert!(r.abs() < 1e-12, "{rb:?} {rr:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// D. rod_cube_liftoff
// ---------------------------------------------------------------------------------------------

#[test]
fn floor_push_closed_form_matches_newton_euler_and_is_a_quarter_at_separation() {
    for (n, r) in [(3.0, 0.25), (0.01, 0.9), (100.0, 0.05), (1.0, 0.6)] {
        let blk = block(n, r, r);
        let ss = separation_sin(n, r);
        for k in 0..=8 {
            let theta = (ss + (r - ss) * k as f64 / 8.0).min(r).asin();
            let acc = blk.flat_solve(theta, -blk.theta_dot_sq(theta).sqrt());
            close(
                acc.n_foot / 9.81,
                liftoff_floor_push(n, r, theta),
                1e-11,
                "N/(m1 g)",
            );
            // N = m1 g/4 + (1 + 4n) tan P/(4n)
            let p = cube_push(n, r, theta) * n * 9.81;
            close(
                acc.n_foot,
                9.81 / 4.0 + (1.0 + 4.0 * n) * theta.tan() * p / (4.0 * n),
                1e-11,
                "identity",
            );
        }
        close(
            liftoff_floor_push(n, r, ss.asin()),
            0.25,
            1e-12,
            "N at separation",
        );
        let th0 = r.asin();
        let c2 = 1.0 - r * r;
        close(
            liftoff_floor_push(n, r, th0),
            1.0 - c2 / (4.0 / 3.0 - r * r / (1.0 + n)),
            1e-13,
            "N at release",
        );
    }
}

#[test]
fn foot_never_lifts_before_separation() {
    let ns: Vec<f64> = (0..=40)
        .map(|i| 10f64.powf(-10.0 + 20.0 * i as f64 / 40.0))
        .collect();
    let rs: Vec<f64> = (1..100)
        .map(|j| j as f64 / 100.0)
        .chain([1e-6, 0.999_999])
        .collect();
    let scan = liftoff_scan(&ns, &rs, 200);
    assert!(scan.min >= 0.25 * (1.0 - 1e-12), "{scan:?}");
    close(scan.min, 0.25, 1e-12, "the minimum is m1 g/4");
    // the minimum sits at separation, the maximum at release
    let (n, r, th) = scan.at_min;
    close(
        th.sin(),
        separation_sin(n, r),
        1e-12,
        "minimum at separation",
    );
    let (n, r, th) = scan.at_max;
    close(th.sin(), r, 1e-15, "maximum at release");
    assert!(scan.max < 1.0 && scan.max > 0.9999, "{scan:?}");
    let _ = n;
}
