//! Impacts (`solve::integrated::impact`) against hand impulse–momentum balances solved here by
//! Newton–Euler in world coordinates (each body's centre and angle, the rod's inertia
//! `m ell^2 / 12`), sharing no code with the models:
//! - the rod of `fixed_cylinder` (R = 0.2, th0 = 1.2) leaves the cylinder at release, falls on
//!   its foot and strikes the cylinder again (plastic: the spec gives no restitution);
//! - `rod_cube_liftoff` (restitution `e` at the tip on the cube and at the foot on the floor)
//!   with its rod driven into the cube and the floor at once, at `e = 0`, `1/2` and `1`: Newton's
//!   law at both contacts, horizontal momentum kept (the floor's impulse is vertical), energy
//!   kept at `e = 1`, and the energy lost equal to what the impulses say;
//! - the typed refusals: a restitution outside `[0, 1]` from the parameters, and a part list
//!   of the wrong length.

mod common;

use common::hand::solve_linear;
use rodcube::models::{all, find};
use rodcube::results::EndCause;
use rodcube::results::Work;
use rodcube::solve::integrated::impact::{Part, resolve};
use rodcube::solve::phases::{Route, Walker};
use rodcube::system::{Bound, State, SystemError};

const G: f64 = 9.81;
const M: f64 = 1.0;
const ELL: f64 = 1.0;
const R: f64 = 0.2;
const TH0: f64 = 1.2;

/// The system and its state where the rod strikes the cylinder (integrated at rtol 1e-13).
fn strike() -> (Bound<'static>, State, f64) {
    let model = find("fixed_cylinder").unwrap();
    let params = [("m1", M), ("ell", ELL), ("R", R), ("th0", TH0), ("g", G)];
    let w = Walker::new(Bound::new(model, &params).unwrap(), all(), 1e-12, 1e-13)
        .with_route(Route::Integrated);
    let (start, opened) = w.release().unwrap();
    assert_eq!(opened, [0], "the cylinder opens at release");
    let run = w.integrate(&start, &mut Work::default()).unwrap();
    assert!(
        matches!(run.end(), EndCause::Contact(c) if c.index == 0),
        "{:?}",
        run.end()
    );
    let state = run.end_state().unwrap();
    (w.general.clone(), state, run.t_end())
}

/// 2-D cross product.
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// The hand balance at the strike, plastic at both contacts: the rod's foot velocity
/// `(x1', y1')` and `theta'` after, and the impulses `(P_cylinder, P_floor)`.
fn hand(state: &State) -> ([f64; 3], [f64; 2]) {
    let (e_cyl, e_floor) = (0.0, 0.0);
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
fn a_plastic_strike_on_the_cylinder_matches_the_hand_impulse_balance() {
    let (bound, state, t) = strike();
    assert_eq!(
        bound.restitutions(),
        [0.0, 0.0],
        "the spec gives no restitution"
    );
    let impact = resolve(&bound, &state, &[Part::Unilateral; 2], t).unwrap();
    let (velocities, impulses) = hand(&state);
    for (k, name) in ["x1'", "y1'", "theta'"].iter().enumerate() {
        close(impact.after.qd()[k], velocities[k], 1e-12, name);
    }
    close(impact.impulse[0], impulses[0], 1e-12, "P_cylinder");
    close(impact.impulse[1], impulses[1], 1e-12, "P_floor");
    // The strike lifts the foot: the floor takes no impulse and the foot rises.
    assert_eq!(impulses[1], 0.0);
    assert!(impact.normal_velocity_after[1] > 0.0);
    // Plastic: the rod stays on the cylinder, and the energy lost is what the impact took.
    assert!(impact.normal_velocity_after[0].abs() < 1e-12);
    let lost = bound.energy(&state).unwrap() - bound.energy(&impact.after).unwrap();
    assert!(lost > 0.0);
    close(impact.energy_lost, lost, 1e-12, "energy lost");
    assert_eq!(
        impact.after.q(),
        state.q(),
        "the configuration does not move"
    );
}

/// `rod_cube_liftoff` at its release configuration (paper's rod and cube), the rod driven into
/// the cube and into the floor: its foot at `(x1', y1') = (0.3, -0.2)` m/s, `theta' = -0.5`
/// rad/s (the tip moving towards the cube at 0.425 m/s), the cube at rest.
fn liftoff(e: f64) -> (Bound<'static>, State) {
    let (m2, a) = (3.0, 0.25);
    let params = [
        ("m1", M),
        ("m2", m2),
        ("ell", ELL),
        ("a", a),
        ("g", G),
        ("e", e),
    ];
    let bound = Bound::new(find("rod_cube_liftoff").unwrap(), &params).unwrap();
    let theta = (a / ELL).asin();
    let q = vec![0.0, 0.0, theta, (ELL * ELL - a * a).sqrt()];
    let state = bound.state(q, vec![0.3, -0.2, -0.5, 0.0]).unwrap();
    (bound, state)
}

/// The hand balance of the rod and the cube at restitution `e`: `[x1', y1', theta', x2']` after
/// and the impulses `(P_tip, P_floor)`. The tip pushes the cube along +x (and the cube the rod
/// along -x); the floor pushes the foot along +y; the cube only slides.
fn hand_liftoff(state: &State, e: f64) -> ([f64; 4], [f64; 2]) {
    let m2 = 3.0;
    let (q, qd) = (state.q(), state.qd());
    let (s, c) = q[2].sin_cos();
    let w = qd[2];
    let r_tip = [0.5 * ELL * c, 0.5 * ELL * s];
    let r_foot = [-0.5 * ELL * c, -0.5 * ELL * s];
    let v_centre = [qd[0] - 0.5 * ELL * s * w, qd[1] + 0.5 * ELL * c * w];
    let tip_x = v_centre[0] - w * r_tip[1];
    let foot_y = v_centre[1] + w * r_foot[0];
    let (gap_rate, foot_rate) = (qd[3] - tip_x, foot_y);
    assert!(gap_rate < 0.0 && foot_rate < 0.0, "both approach");
    let inertia = M * ELL * ELL / 12.0;
    // Unknowns [dvx, dvy, dw, dx2', P_tip, P_floor].
    let a6 = [
        [M, 0.0, 0.0, 0.0, 1.0, 0.0],
        [0.0, M, 0.0, 0.0, 0.0, -1.0],
        [
            0.0,
            0.0,
            inertia,
            0.0,
            -cross(r_tip, [-1.0, 0.0]),
            -cross(r_foot, [0.0, 1.0]),
        ],
        [0.0, 0.0, 0.0, m2, -1.0, 0.0],
        [-1.0, 0.0, r_tip[1], 1.0, 0.0, 0.0],
        [0.0, 1.0, r_foot[0], 0.0, 0.0, 0.0],
    ];
    let b = [
        0.0,
        0.0,
        0.0,
        0.0,
        -(1.0 + e) * gap_rate,
        -(1.0 + e) * foot_rate,
    ];
    let x = solve_linear(a6, b);
    assert!(x[4] > 0.0 && x[5] > 0.0, "both push: {x:?}");
    let v = [v_centre[0] + x[0], v_centre[1] + x[1]];
    let w_after = w + x[2];
    let foot = [v[0] - w_after * r_foot[1], v[1] + w_after * r_foot[0]];
    ([foot[0], foot[1], w_after, qd[3] + x[3]], [x[4], x[5]])
}

#[test]
fn the_rod_driven_into_cube_and_floor_obeys_newton_at_both_contacts() {
    for e in [0.0, 0.5, 1.0] {
        let (bound, state) = liftoff(e);
        // The tip's floor contact (third) is open, a rod's height above it: it takes no part.
        assert_eq!(bound.restitutions(), [e, e, e]);
        let parts = [Part::Unilateral, Part::Unilateral, Part::None];
        let impact = resolve(&bound, &state, &parts, 0.0).unwrap();
        assert_eq!(impact.impulse[2], 0.0);
        let (velocities, impulses) = hand_liftoff(&state, e);
        let what = format!("e = {e}");
        for (k, name) in ["x1'", "y1'", "theta'", "x2'"].iter().enumerate() {
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
            &format!("{what}: P_tip"),
        );
        close(
            impact.impulse[1],
            impulses[1],
            1e-12,
            &format!("{what}: P_floor"),
        );
        // Newton's law at both contacts.
        for i in 0..2 {
            let (before, after) = (
                impact.normal_velocity_before[i],
                impact.normal_velocity_after[i],
            );
            close(after, -e * before, 1e-12, &format!("{what}: contact {i}"));
        }
        // Horizontal momentum: the tip's impulse is internal, the floor's vertical.
        let momentum = |qd: &[f64]| {
            let v_centre_x = qd[0] - 0.5 * ELL * state.q()[2].sin() * qd[2];
            M * v_centre_x + 3.0 * qd[3]
        };
        close(
            momentum(impact.after.qd()),
            momentum(state.qd()),
            1e-14,
            &format!("{what}: horizontal momentum"),
        );
        let lost = bound.energy(&state).unwrap() - bound.energy(&impact.after).unwrap();
        close(
            impact.energy_lost,
            lost,
            1e-12,
            &format!("{what}: energy lost"),
        );
        if e == 1.0 {
            assert!(lost.abs() < 1e-14, "{what}: {lost:e}");
        } else {
            assert!(lost > 0.0, "{what}: {lost:e}");
        }
    }
}

#[test]
fn restitution_outside_zero_to_one_and_wrong_lengths_are_refused() {
    let model = find("rod_cube_liftoff").unwrap();
    for e in [-0.1, 1.5] {
        let params = [
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", G),
            ("e", e),
        ];
        match Bound::new(model, &params) {
            Err(SystemError::Restitution { contact, value, .. }) => {
                assert_eq!(contact, "contact_force");
                assert_eq!(value, e);
            }
            other => panic!("e = {e}: {other:?}"),
        }
    }
    let (bound, state, t) = strike();
    let err = resolve(&bound, &state, &[Part::Unilateral], t).unwrap_err();
    assert!(err.to_string().contains("impact parts"), "{err}");
}

#[test]
fn a_contact_that_takes_no_part_is_left_alone() {
    let (bound, state, t) = strike();
    // Only the cylinder takes part: no impulse acts at the floor.
    let impact = resolve(&bound, &state, &[Part::Unilateral, Part::None], t).unwrap();
    assert_eq!(impact.impulse[1], 0.0);
    assert!(impact.impulse[0] > 0.0);
    assert!(impact.normal_velocity_after[0].abs() < 1e-12);
}
