//! The physical checks can fail: a monitor that dips below zero, a cube that runs into the
//! tip after separation, and drift beyond the tolerance each give `passed == false`.

mod common;

use common::paper::{MODELS, ROD_CUBE, paper};
use common::tweaked::LOW_MONITORS;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity;
use rodcube::results::Work;
use rodcube::solve::checks;
use rodcube::solve::phases::{Motion, PhaseRun, Route, extend_to_floor};
use rodcube::solve::series::{sample, sample_forces};
use rodcube::system::Bound;

#[test]
fn a_monitor_below_zero_fails_with_its_minimum_as_margin() {
    let bound = Bound::new(&LOW_MONITORS, &paper(9.81)).unwrap();
    let phase = PhaseRun::solve(
        bound.clone(),
        0.0,
        1e-12,
        1e-12,
        Route::Fastest,
        &mut Work::default(),
    )
    .unwrap();
    let samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let forces = sample_forces(&phase, &samples).unwrap();
    let found = checks::monitors(
        &bound,
        &samples,
        &forces,
        1e-12,
        &checks::Context::new("rod_cube"),
    );
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
    // A monitor's margin is its smallest value, in its own unit, with the time it was taken.
    assert_eq!(foot.kind, rodcube::results::CheckKind::Monitor);
    assert_eq!(foot.value, foot.margin);
    assert!(foot.at_time.is_some_and(|t| t >= 0.0), "{foot:?}");
    assert!(tip.passed && tip.margin > 0.0, "{tip:?}");
    // Through the planner too.
    let request = Request::new(&LOW_MONITORS, paper(9.81))
        .with_want(&[Quantity::Checks])
        .with_registry(MODELS);
    let r = run(&request).unwrap();
    assert!(!r.checks["rod_cube.foot_on_floor"].passed);
    assert!(r.checks["rod_cube_free.contact_open"].passed);
}

#[test]
fn a_cube_running_into_the_tip_is_a_catch() {
    let bound = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let mut work = Work::default();
    let first = PhaseRun::solve(bound, 0.0, 1e-12, 1e-12, Route::Fastest, &mut work).unwrap();
    let mut motion = Motion::new(first);
    extend_to_floor(&mut motion, MODELS, 1e-12, 1e-12, Route::Fastest, &mut work).unwrap();
    let free = &motion.phases[1];
    let mut samples = sample(free, 50, &mut work).unwrap();
    let forces = sample_forces(free, &samples).unwrap();
    let open = |samples: &_| {
        checks::monitors(
            free.bound(),
            samples,
            &forces,
            1e-12,
            &checks::Context::new("rod_cube_free"),
        )
        .into_iter()
        .find(|(k, _)| k == "rod_cube_free.contact_open")
        .unwrap()
        .1
    };
    let ok = open(&samples);
    assert!(ok.passed && ok.margin > -1e-15, "{ok:?}");
    // The same motion against a cube thrown back at the rod at 1 m/s.
    for (state, t) in samples.states.iter_mut().zip(&samples.t) {
        state.q[2] -= 1.0 * t;
    }
    let caught = open(&samples);
    assert!(!caught.passed && caught.margin < 0.0, "{caught:?}");
}
