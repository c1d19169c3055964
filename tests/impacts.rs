//! Impacts (`solve::impact`) against a hand impulse–momentum balance: the rod of
//! `fixed_cylinder` (R = 0.2, th0 = 1.2) leaves the cylinder at release, falls on its foot and
//! strikes the cylinder again; the impulses of the cylinder and of the floor at the strike, and
//! the rod's velocities after, are solved here by Newton–Euler in world coordinates (the rod's
//! centre and angle, its inertia `m ell^2 / 12`), sharing no code with the model. Then Newton's
//! law at `e = 0`, `e = 1/2` and `e = 1`, the energy lost against the impulses, and the typed
//! refusals.

mod common;

use common::hand::solve_linear;
use rodcube::models::{all, find};
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::impact::{Part, resolve};
use rodcube::solve::phases::{End, Route, Walker};
use rodcube::system::{Bound, State};

const G: f64 = 9.81;
const M: f64 = 1.0;
const ELL: f64 = 1.0;
const R: f64 = 0.2;
const TH0: f64 = 1.2;

/// The system and its state where the rod strikes the cylinder (integrated at rtol 1e-13).
fn strike() -> (Bound<'static>, State, f64) {
    let model = find("fixed_cylinder").unwrap();
    let params = [("m1", M), ("ell", ELL), ("R", R), ("th0", TH0), ("g", G)];
    let w = Walker {
        general: Bound::new(model, &params).unwrap(),
        registry: all(),
        tol: 1e-12,
        rtol: 1e-13,
        route: Route::Integrated,
    };
    let (start, opened) = w.release().unwrap();
    assert_eq!(opened, [0], "the cylinder opens at release");
    let run = w.integrate(&start, &mut Work::default()).unwrap();
    assert_eq!(run.end(), End::Contact(0));
    let state = run.end_state().unwrap();
    (w.general.clone(), state, run.t_end())
}

/// 2-D cross product.
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// The hand balance at the strike with the floor's and the cylinder's restitution: the rod's
/// foot velocity `(x1', y1')` and `theta'` after, and the impulses `(P_cylinder, P_floor)`.
fn hand(state: &State, e_cyl: f64, e_floor: f64) -> ([f64; 3], [f64; 2]) {
    let (q, qd) = (state.q(), state.qd());
    let (x1, y1, th) = (q[0], q[1], q[2]);
    let (s, c) = th.sin_cos();
    let u = [c, s];
    let n_cyl = [-s, c]; // the cylinder pushes the rod away from its axis, normal to the rod
    let n_floor = [0.0, 1.0];
    let centre = [x1 + 0.5 * ELL * c, y1 + 0.5 * ELL * s];
    // The point of the rod nearest the axis (0, R): the contact point.
    let along = (0.0 - x1) * c + (R - y1) * s;
    let touch = [x1 + along * u[0], y1 + along * u[1]];
    let r_touch = [touch[0] - centre[0], touch[1] - centre[1]];
    let r_foot = [x1 - centre[0], y1 - centre[1]];
    let w = qd[2];
    let v_centre = [qd[0] - 0.5 * ELL * s * w, qd[1] + 0.5 * ELL * c * w];
    let vel = |v: [f64; 2], w: f64, r: [f64; 2]| [v[0] - w * r[1], v[1] + w * r[0]];
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let v_touch = dot(vel(v_centre, w, r_touch), n_cyl);
    let v_foot = dot(vel(v_centre, w, r_foot), n_floor);
    assert!(v_touch < 0.0, "the rod approaches the cylinder: {v_touch}");
    let inertia = M * ELL * ELL / 12.0;
    // Unknowns [dvx, dvy, dw, P_cyl, P_floor]: momentum, angular momentum about the centre,
    // and Newton's law at both contacts (the foot rests on the floor: v_foot = 0 before).
    let a = [
        [M, 0.0, 0.0, -n_cyl[0], -n_floor[0]],
        [0.0, M, 0.0, -n_cyl[1], -n_floor[1]],
        [
            0.0,
            0.0,
            inertia,
            -cross(r_touch, n_cyl),
            -cross(r_foot, n_floor),
        ],
        [n_cyl[0], n_cyl[1], cross(r_touch, n_cyl), 0.0, 0.0],
        [n_floor[0], n_floor[1], cross(r_foot, n_floor), 0.0, 0.0],
    ];
    let b = [
        0.0,
        0.0,
        0.0,
        -(1.0 + e_cyl) * v_touch,
        -(1.0 + e_floor) * v_foot,
    ];
    let both = solve_linear(a, b);
    // The floor can only push: if it would have to pull, the foot leaves it and only the
    // cylinder acts (the first four rows without the floor's column).
    let x = if both[4] >= 0.0 {
        both
    } else {
        let a4: [[f64; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| a[i][j]));
        let x = solve_linear(a4, [b[0], b[1], b[2], b[3]]);
        [x[0], x[1], x[2], x[3], 0.0]
    };
    assert!(x[3] > 0.0, "the cylinder pushes: {x:?}");
    let (v, w_after) = ([v_centre[0] + x[0], v_centre[1] + x[1]], w + x[2]);
    let foot = vel(v, w_after, r_foot);
    if x[4] == 0.0 {
        assert!(
            foot[1] > 0.0,
            "a foot the floor does not push leaves it: {foot:?}"
        );
    }
    ([foot[0], foot[1], w_after], [x[3], x[4]])
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1.0);
    assert!((a - b).abs() <= tol * scale, "{what}: {a:e} vs {b:e}");
}

#[test]
fn a_strike_on_the_cylinder_matches_the_hand_impulse_balance() {
    let (bound, state, t) = strike();
    let energy = bound.energy(&state).unwrap();
    for e in [0.0, 0.5, 1.0] {
        let parts = [Part::Unilateral(e), Part::Unilateral(0.0)];
        let impact = resolve(&bound, &state, &parts, t).unwrap();
        let (velocities, impulses) = hand(&state, e, 0.0);
        let what = format!("e = {e}");
        for (k, name) in ["x1'", "y1'", "theta'"].iter().enumerate() {
            close(
                impact.after.qd()[k],
                velocities[k],
                1e-12,
                &format!("{what}: {name}"),
            );
        }
        close(
            impact.impulse[0],
            impulses[0],
            1e-12,
            &format!("{what}: P_cyl"),
        );
        close(
            impact.impulse[1],
            impulses[1],
            1e-12,
            &format!("{what}: P_floor"),
        );
        // Newton's law at the cylinder, and the foot staying on the floor.
        let (before, after) = (
            impact.normal_velocity_before[0],
            impact.normal_velocity_after[0],
        );
        close(after, -e * before, 1e-12, &format!("{what}: v+ = -e v-"));
        // The foot: held on the floor where the floor pushes, else leaving it.
        if impulses[1] > 0.0 {
            assert!(impact.normal_velocity_after[1].abs() < 1e-12, "{what}");
        } else {
            assert!(impact.normal_velocity_after[1] > 0.0, "{what}");
        }
        println!(
            "{what}: impulses {:?}, foot {:?}",
            impact.impulse,
            &impact.after.qd()
        );
        // The energy lost from the impulses is the kinetic energy the impact took.
        let lost = energy - bound.energy(&impact.after).unwrap();
        close(
            impact.energy_lost,
            lost,
            1e-12,
            &format!("{what}: energy lost"),
        );
        // Restitution conserves energy at e = 1, and loses it otherwise.
        if e == 1.0 {
            assert!(lost.abs() < 1e-12 * energy.abs(), "{lost:e}");
        } else {
            assert!(lost > 0.0, "{what}: {lost:e}");
        }
        // The configuration does not move in an impact.
        assert_eq!(impact.after.q(), state.q());
    }
}

#[test]
fn restitution_outside_zero_to_one_and_wrong_lengths_are_refused() {
    let (bound, state, t) = strike();
    for e in [-0.1, 1.5, f64::NAN, f64::INFINITY] {
        let parts = [Part::Unilateral(e), Part::Unilateral(0.0)];
        match resolve(&bound, &state, &parts, t) {
            Err(SolveError::Restitution { contact, value, .. }) => {
                assert_eq!(contact, "cylinder_push");
                assert!(value.is_nan() || value == e);
            }
            other => panic!("e = {e}: {other:?}"),
        }
    }
    let err = resolve(&bound, &state, &[Part::Unilateral(0.0)], t).unwrap_err();
    assert!(err.to_string().contains("impact parts"), "{err}");
}

#[test]
fn a_contact_that_takes_no_part_is_left_alone() {
    let (bound, state, t) = strike();
    // Only the cylinder takes part: the foot is free to leave the floor, and no impulse acts
    // there; the rod then leaves the floor if the strike lifts its foot.
    let impact = resolve(&bound, &state, &[Part::Unilateral(0.0), Part::None], t).unwrap();
    assert_eq!(impact.impulse[1], 0.0);
    assert!(impact.impulse[0] > 0.0);
    assert!(impact.normal_velocity_after[0].abs() < 1e-12);
}
