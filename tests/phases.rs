//! Chaining phases: the free rod after separation gets the right state, energy and momentum carry
//! across the boundary, the floor impact follows from them, and the ODE agrees on the free phase.

mod common;

use common::paper::{MODELS, ROD_CUBE, paper};
use rodcube::model::Model;
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::phases::{Motion, PhaseRun, extend_to_floor, next_system, transition};
use rodcube::solve::unreduced::{EndEvent, integrate};
use rodcube::system::System;

fn paper_motion<'m>(registry: &[&'m dyn Model], sys: System<'m>, work: &mut Work) -> Motion<'m> {
    let first = PhaseRun::solve(sys, 0.0, 1e-13, work).unwrap();
    let mut motion = Motion::new(first);
    extend_to_floor(&mut motion, registry, 1e-13, work).unwrap();
    motion
}

#[test]
fn free_rod_starts_from_the_separation_state() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let first = PhaseRun::solve(sys, 0.0, 1e-13, &mut Work::default()).unwrap();
    let next = next_system(&first, MODELS).unwrap().unwrap();
    assert_eq!(next.name(), "free_rod");
    let end = first.end_state();
    let start = next.initial_state();
    for (a, b) in end
        .q
        .iter()
        .chain(&end.qd)
        .zip(start.q.iter().chain(&start.qd))
    {
        assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{a} vs {b}");
    }
    assert_eq!(next.param("theta_s"), Some(first.separation.unwrap().theta));
}

#[test]
fn floor_impact_conserves_energy_and_momentum_across_the_boundary() {
    let mut work = Work::default();
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (m1, m2, a, g, ell) = (1.0, 3.0, 0.25, 9.81, 1.0);
    let motion = paper_motion(MODELS, sys, &mut work);
    assert_eq!(work.phases, vec!["rod_cube", "free_rod"]);
    let (rc, fr) = (&motion.phases[0], &motion.phases[1]);
    let tr = motion.transitions[0];
    // Energy: the rod + cube system at separation = the free rod + the cube gliding on.
    let v_cube = tr.surface_speed();
    let e_rc = rc.system.energy(&rc.end_state());
    let e_fr = fr.system.energy(&fr.system.initial_state());
    let e_cube = 0.5 * m2 * v_cube * v_cube + m2 * g * a / 2.0;
    assert!(
        ((e_fr + e_cube) - e_rc).abs() < 1e-14 * e_rc,
        "{e_fr} + {e_cube} vs {e_rc}"
    );
    // Horizontal momentum stays zero: the rod's centre moves against the cube.
    let v_cm = fr.system.points(&fr.system.initial_state()).vel[2][0];
    assert!((m1 * v_cm + m2 * v_cube).abs() < 1e-15, "{v_cm} {v_cube}");
    // The cube's speed from eqs. (2) and (5): x2' = -ell s theta' / (2 (1 + n)).
    let sep = rc.separation.unwrap();
    let omega_sep = rc.theta_dot_end();
    assert!((v_cube + ell * sep.sin_theta * omega_sep / 8.0).abs() < 1e-15);
    // At the floor all potential energy of the rod is kinetic: m1 v_cm^2 / 2 + m1 ell^2 w^2 / 6.
    let w = motion.impact_angular_velocity();
    let want = -(6.0 * (e_fr - 0.5 * m1 * v_cm * v_cm) / (m1 * ell * ell)).sqrt();
    assert!(((w - want) / want).abs() < 1e-13, "{w} vs {want}");
    let e_end = fr.system.energy(&fr.end_state());
    assert!(((e_end - e_fr) / e_fr).abs() < 1e-14);
    // Times: after separation, and different from the paper's contact-all-the-way 0.18693 s.
    let t = motion.floor_time();
    println!(
        "t_sep = {:.12} s, floor impact at {t:.12} s, omega = {w:.12} rad/s, cube speed {v_cube:.12} m/s",
        rc.t_end()
    );
    assert!(t > rc.t_end() && (t - 0.18693).abs() > 1e-4);
    assert_eq!(fr.t_start, rc.t_end());
    assert_eq!(tr.t, rc.t_end());
}

#[test]
fn ode_agrees_on_the_free_phase() {
    let mut work = Work::default();
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let motion = paper_motion(MODELS, sys, &mut work);
    let fr = &motion.phases[1];
    let run = integrate(&fr.system, 1e-12, None, 1.0, &mut Work::default()).unwrap();
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
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let motion = paper_motion(MODELS, sys, &mut work);
    let tr = transition(&motion.phases[0]).unwrap();
    assert_eq!((tr.point, tr.surface), ("tip", "cube"));
    let fr = &motion.phases[1];
    let tip = fr.system.point_index("tip").unwrap();
    let at = |t: f64| {
        let delta =
            rodcube::solve::series::delta_at_time(&fr.system, &fr.mesh, t, &mut Work::default())
                .unwrap();
        let state = fr.system.full_state(
            t,
            delta,
            rodcube::solve::series::theta_dot_at(&fr.system, delta),
        );
        tr.gap(fr.t_start + t, fr.system.points(&state).pos[tip])
    };
    assert!(at(0.0).abs() < 1e-15);
    let mut last = 0.0;
    for i in 1..=10 {
        let gap = at(fr.duration() * i as f64 / 10.0);
        assert!(gap > last, "gap {gap} after {last}");
        last = gap;
    }
}

#[test]
fn a_missing_next_model_is_a_typed_error() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let first = PhaseRun::solve(sys, 0.0, 1e-13, &mut Work::default()).unwrap();
    let mut motion = Motion::new(first);
    let err = extend_to_floor(&mut motion, &[], 1e-13, &mut Work::default()).unwrap_err();
    assert_eq!(
        err,
        SolveError::UnknownNextModel {
            from: "rod_cube",
            name: "free_rod"
        }
    );
}
