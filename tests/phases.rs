//! Chaining phases: the free phase after separation gets the right state, energy and momentum
//! carry across the boundary, the floor impact follows from them, and the ODE agrees on the free
//! phase.

mod common;

use common::paper::{MODELS, ROD_CUBE, paper};
use rodcube::model::Model;
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::phases::{End, Motion, PhaseRun, Route, extend_to_floor, next_bound};
use rodcube::solve::unreduced::{EndEvent, integrate};
use rodcube::system::Bound;

fn paper_motion<'m>(registry: &[&'m dyn Model], bound: Bound<'m>, work: &mut Work) -> Motion<'m> {
    let first = PhaseRun::solve(bound, 0.0, 1e-13, 1e-13, Route::Fastest, work).unwrap();
    let mut motion = Motion::new(first);
    extend_to_floor(&mut motion, registry, 1e-13, 1e-13, Route::Fastest, work).unwrap();
    motion
}

#[test]
fn the_free_phase_starts_from_the_separation_state() {
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let first = PhaseRun::solve(
        bound,
        0.0,
        1e-13,
        1e-13,
        Route::Fastest,
        &mut Work::default(),
    )
    .unwrap();
    assert_eq!(first.end(), End::Separation);
    let next = next_bound(&first, MODELS).unwrap().unwrap();
    assert_eq!(next.name(), "rod_cube_free");
    let end = first.end_state();
    let start = next.initial_state();
    // x1 and theta carry over; x2 is where the tip was.
    for (a, b) in [
        (end.q[0], start.q[0]),
        (end.q[1], start.q[1]),
        (end.qd[0], start.qd[0]),
        (end.qd[1], start.qd[1]),
    ] {
        assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{a} vs {b}");
    }
    let tip = first.bound().points(&end).pos[1][0];
    assert!((start.q[2] - tip).abs() <= 1e-15);
    assert_eq!(next.param("theta_0"), Some(first.theta_end()));
}

#[test]
fn floor_impact_conserves_energy_and_momentum_across_the_boundary() {
    let mut work = Work::default();
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (m1, m2, g, ell) = (1.0, 3.0, 9.81, 1.0);
    let motion = paper_motion(MODELS, bound, &mut work);
    assert_eq!(work.phases, vec!["rod_cube", "rod_cube_free"]);
    let (rc, fr) = (&motion.phases[0], &motion.phases[1]);
    // Energy: the rod + cube system at separation = the free phase's (rod and gliding cube).
    let e_rc = rc.bound().energy(&rc.end_state());
    let start = fr.bound().initial_state();
    let e_fr = fr.bound().energy(&start);
    assert!((e_fr - e_rc).abs() < 1e-14 * e_rc, "{e_fr} vs {e_rc}");
    // Horizontal momentum stays zero: the rod's centre moves against the cube.
    let v_cm = fr.bound().points(&start).vel[2][0];
    let v_cube = start.qd[2];
    assert!((m1 * v_cm + m2 * v_cube).abs() < 1e-15, "{v_cm} {v_cube}");
    // The cube's speed from eqs. (2) and (5): x2' = -ell s theta' / (2 (1 + n)).
    let sep = rc.reduced().unwrap().separation().unwrap();
    let omega_sep = rc.theta_dot_end();
    assert!((v_cube + ell * sep.sin_theta * omega_sep / 8.0).abs() < 1e-15);
    // At the floor all potential energy of the rod is kinetic: m1 v_cm^2 / 2 + m1 ell^2 w^2 / 6.
    let w = motion.impact_angular_velocity();
    let e_cube = 0.5 * m2 * v_cube * v_cube + m2 * g * 0.25 / 2.0;
    let want = -(6.0 * (e_fr - e_cube - 0.5 * m1 * v_cm * v_cm) / (m1 * ell * ell)).sqrt();
    assert!(((w - want) / want).abs() < 1e-13, "{w} vs {want}");
    let e_end = fr.bound().energy(&fr.end_state());
    assert!(((e_end - e_fr) / e_fr).abs() < 1e-14);
    // Times: after separation, and different from the paper's contact-all-the-way 0.18693 s.
    let t = motion.floor_time();
    assert!(t > rc.t_end() && (t - 0.18693).abs() > 1e-4);
    assert_eq!(fr.t_start(), rc.t_end());
}

#[test]
fn ode_agrees_on_the_free_phase() {
    let mut work = Work::default();
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let motion = paper_motion(MODELS, bound, &mut work);
    let fr = &motion.phases[1];
    let run = integrate(fr.bound(), 1e-12, None, 1.0, &mut Work::default()).unwrap();
    assert_eq!(run.end, EndEvent::Floor);
    assert!(
        ((run.t_end - fr.duration()) / fr.duration()).abs() < 1e-9,
        "{} vs {}",
        run.t_end,
        fr.duration()
    );
    assert!(((run.state_end.qd[1] - fr.theta_dot_end()) / fr.theta_dot_end()).abs() < 1e-9);
}

#[test]
fn the_tip_leaves_the_cube_behind() {
    let mut work = Work::default();
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let motion = paper_motion(MODELS, bound, &mut work);
    let fr = &motion.phases[1];
    let s = rodcube::solve::series::sample(fr, 11, &mut work).unwrap();
    let gap = |i: usize| {
        let q = &s.states[i].q;
        q[2] - q[0] - q[1].cos()
    };
    assert!(gap(0).abs() < 1e-15);
    let mut last = 0.0;
    for i in 1..11 {
        assert!(gap(i) > last, "gap {} after {last}", gap(i));
        last = gap(i);
    }
}

#[test]
fn a_missing_next_model_is_a_typed_error() {
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let first = PhaseRun::solve(
        bound,
        0.0,
        1e-13,
        1e-13,
        Route::Fastest,
        &mut Work::default(),
    )
    .unwrap();
    let mut motion = Motion::new(first);
    let err = extend_to_floor(
        &mut motion,
        &[],
        1e-13,
        1e-13,
        Route::Fastest,
        &mut Work::default(),
    )
    .unwrap_err();
    assert_eq!(
        err,
        SolveError::UnknownNextModel {
            from: "rod_cube",
            name: "rod_cube_free"
        }
    );
}
