//! The physical checks can fail: a monitor that dips below zero, a surface that runs into the
//! tip after separation, and drift beyond the tolerance each give `passed == false`.

mod common;

use common::paper::{MODELS, ROD_CUBE, paper};
use common::tweaked::LOW_MONITORS;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity;
use rodcube::results::Work;
use rodcube::solve::checks;
use rodcube::solve::phases::{Motion, PhaseRun, Transition, extend_to_floor, transition};
use rodcube::solve::series::sample_phase;
use rodcube::system::System;

#[test]
fn a_monitor_below_zero_fails_with_its_minimum_as_margin() {
    let sys = System::new(&LOW_MONITORS, &paper(9.81)).unwrap();
    let phase = PhaseRun::solve(sys.clone(), 0.0, 1e-12, &mut Work::default()).unwrap();
    let samples = sample_phase(&sys, &phase.mesh, 50, &mut Work::default()).unwrap();
    let found = checks::monitors(&sys, &samples);
    let foot = &found
        .iter()
        .find(|(k, _)| k == "rod_cube.foot_on_floor")
        .unwrap()
        .1;
    let tip = &found
        .iter()
        .find(|(k, _)| k == "rod_cube.cube_does_not_tip")
        .unwrap()
        .1;
    assert!(!foot.passed && foot.margin < 0.0, "{foot:?}");
    assert!(tip.passed && tip.margin > 0.0, "{tip:?}");
    // Through the planner too.
    let request = Request::new(&LOW_MONITORS, paper(9.81))
        .with_want(&[Quantity::Checks])
        .with_registry(MODELS);
    let r = run(&request).unwrap();
    assert!(!r.checks["rod_cube.foot_on_floor"].passed);
    assert!(r.checks["free_rod.tip_clears_cube"].passed);
}

#[test]
fn a_surface_running_into_the_tip_is_a_catch() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let mut work = Work::default();
    let mut motion = Motion::new(PhaseRun::solve(sys, 0.0, 1e-12, &mut work).unwrap());
    extend_to_floor(&mut motion, MODELS, 1e-12, &mut work).unwrap();
    let real = transition(&motion.phases[0]).unwrap();
    let free = &motion.phases[1];
    let samples = sample_phase(&free.system, &free.mesh, 50, &mut work).unwrap();
    let (name, ok) =
        checks::no_recatch(&free.system, &samples, free.t_start, &real, 1e-12).unwrap();
    assert_eq!(name, "free_rod.tip_clears_cube");
    assert!(ok.passed && ok.margin > 0.0);
    // The same motion against a cube thrown back at the rod at 1 m/s.
    let thrown = Transition {
        surface_vel: [-1.0, 0.0],
        ..real
    };
    let (_, caught) =
        checks::no_recatch(&free.system, &samples, free.t_start, &thrown, 1e-12).unwrap();
    assert!(!caught.passed && caught.margin < 0.0, "{caught:?}");
}
