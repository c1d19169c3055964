//! The physical checks can fail: a monitor that dips below zero, a closed contact that would
//! have to pull, drift beyond the tolerance and a closed gap that opens each give
//! `passed == false`; a cube that runs into the tip after separation ends the motion where
//! the open contact's gap closes, on either route.

mod common;

use common::paper::{FREE_ROD, GENERAL, MODELS, ROD_CUBE, free_after, paper};
use common::tweaked::{INFINITE_MONITORS, LOW_MONITORS, registry};
use rodcube::model::Model;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity;
use rodcube::results::{CheckKind, ContactId, EndCause, Work};
use rodcube::solve::SolveError;
use rodcube::solve::checks::{self, Conserved};
use rodcube::solve::integrated::contacts::Active;
use rodcube::solve::integrated::unreduced::{self, Start};
use rodcube::solve::phases::{PhaseRun, ReducedRun, Route, Walker, phase_end};
use rodcube::solve::series::{sample, sample_forces};
use rodcube::system::{Bound, State, System, SystemError};

fn walker(registry: &'static [&'static dyn Model], route: Route) -> Walker<'static> {
    Walker::new(
        Bound::new(&GENERAL, &paper(9.81)).unwrap(),
        registry,
        1e-12,
        1e-12,
    )
    .with_route(route)
}

/// The release phase of the hand-typed system with `registry`'s release model.
fn release_phase(registry: &'static [&'static dyn Model]) -> PhaseRun<'static> {
    let w = walker(registry, Route::Fastest);
    let (start, _) = w.release().unwrap();
    w.solve(&start, &mut Work::default()).unwrap()
}

#[test]
fn a_monitor_below_zero_fails_with_its_minimum_as_value() {
    let phase = release_phase(registry(&LOW_MONITORS));
    assert!(phase.end().is_force_of(0), "{:?}", phase.end());
    let bound = phase.bound();
    let samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let forces = sample_forces(&phase, &samples).unwrap();
    let ctx = checks::Context::new("rod_cube_closed");
    let found = checks::monitors(bound, &samples, &forces, 1e-12, &ctx).unwrap();
    let tip = &found
        .iter()
        .find(|(k, _)| k == "rod_cube_closed.cube_does_not_tip")
        .unwrap()
        .1;
    assert!(!tip.passed && tip.margin < 0.0, "{tip:?}");
    // A monitor's value is its smallest value, in its own unit, with the time it was taken:
    // the untweaked monitor's smallest value less the 4 N m the tweak takes off.
    assert_eq!(tip.kind, CheckKind::Monitor);
    assert_eq!(tip.unit, "N m");
    assert!(tip.limit <= 0.0 && tip.limit > -1e-9, "{tip:?}");
    assert_eq!(tip.margin, tip.value - tip.limit);
    assert!(tip.at_time.is_some_and(|t| t >= 0.0), "{tip:?}");
    let plain = Bound::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let untweaked = checks::monitors(&plain, &samples, &forces, 1e-12, &ctx).unwrap();
    let least = untweaked[0].1.value;
    assert!(untweaked[0].1.passed && least > 3.5, "{:?}", untweaked[0]);
    assert!((tip.value - (least - 4.0)).abs() < 1e-12, "{tip:?}");
    // The contacts' own checks are not monitors: they pass, the floor's push at least m1 g / 4.
    let pushes = checks::contact_forces(
        bound,
        &samples,
        &forces,
        &phase.closed().unwrap(),
        1e-12,
        &ctx,
    )
    .unwrap();
    let keys: Vec<&str> = pushes.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "rod_cube_closed.contact_force_pushes",
            "rod_cube_closed.floor_normal_pushes"
        ]
    );
    assert!(pushes.iter().all(|(_, c)| c.passed), "{pushes:?}");
    assert!(pushes[1].1.margin > 0.25 * 9.81 * (1.0 - 1e-3));
    // Through the planner too: only the tweaked phase's monitor fails.
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::Checks])
        .with_registry(registry(&LOW_MONITORS));
    let r = run(&request).unwrap();
    assert!(!r.checks["rod_cube_closed.cube_does_not_tip"].passed);
    assert!(r.checks["rod_cube_closed.floor_normal_pushes"].passed);
    assert!(r.checks["rod_cube_free.cube_does_not_tip"].passed);
    assert!(r.checks["rod_cube_free.floor_normal_pushes"].passed);
    let failed: Vec<&String> = (r.checks.iter())
        .filter(|(_, c)| !c.passed)
        .map(|(k, _)| k)
        .collect();
    assert_eq!(failed, ["rod_cube_closed.cube_does_not_tip"]);
}

#[test]
fn a_monitor_at_minus_infinity_fails() {
    // An allowance scaled by the monitor's own largest magnitude would be infinite here, and
    // `-inf >= -inf` would pass: the check must not depend on the value it judges.
    let phase = release_phase(registry(&INFINITE_MONITORS));
    let samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let forces = sample_forces(&phase, &samples).unwrap();
    let ctx = checks::Context::new("rod_cube_closed");
    let found = checks::monitors(phase.bound(), &samples, &forces, 1e-12, &ctx).unwrap();
    let tip = &found[0].1;
    assert_eq!(found[0].0, "rod_cube_closed.cube_does_not_tip");
    assert!(!tip.passed && tip.value == f64::NEG_INFINITY, "{tip:?}");
    assert!(tip.limit.is_finite(), "{tip:?}");
    // Through the planner: the run goes on, and its checks say the monitor failed.
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::Checks])
        .with_registry(registry(&INFINITE_MONITORS));
    let r = run(&request).unwrap();
    assert!(!r.checks["rod_cube_closed.cube_does_not_tip"].passed);
}

#[test]
fn energy_drift_is_judged_against_the_motion_not_a_constant_potential() {
    // m2 = 1e6 m1: the cube's potential m2 g a / 2 is about 1.2e6 J and constant (the cube
    // slides on the floor), while the motion's energies are of order m1 g ell = 10 J. A drift
    // of 1e-6 of the motion's energy (a million times the tolerance) must fail at 1e-12;
    // measured against |E| it would look like 1e-12 and pass. (Rounding in E itself, 16 ulps
    // of 1.2e6 J or about 4e-9 J, is allowed: a drift below that is not measurable in f64.)
    let mut p = paper(9.81);
    p[1].1 = 1e6;
    let sys = Bound::new(&ROD_CUBE, &p).unwrap();
    let w = Walker::new(Bound::new(&GENERAL, &p).unwrap(), MODELS, 1e-12, 1e-12);
    let (start, _) = w.release().unwrap();
    let phase = w.solve(&start, &mut Work::default()).unwrap();
    assert_eq!(phase.bound().info().name, sys.info().name);
    let mut samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let ctx = checks::Context::new("rod_cube_closed");
    let conserved = Conserved::each_cyclic(phase.bound());
    let ok = checks::drift(
        phase.bound(),
        &samples.states,
        &conserved,
        1e-12,
        &ctx,
        CheckKind::Identity,
    )
    .unwrap();
    assert!(ok.iter().all(|(_, c)| c.passed), "{ok:?}");
    // The rod's angular velocity 5e-7 too fast at the last sample: its kinetic energy (most
    // of the motion's there) 1e-6 of itself too large.
    let last = samples.states.len() - 1;
    let (q, mut qd) = samples.states[last].clone().into_parts();
    qd[1] *= 1.0 + 5e-7;
    samples.states[last] = State::new(q, qd).unwrap();
    let bad = checks::drift(
        phase.bound(),
        &samples.states,
        &conserved,
        1e-12,
        &ctx,
        CheckKind::Drift,
    )
    .unwrap();
    let energy = &bad[0].1;
    assert_eq!(bad[0].0, "rod_cube_closed.energy");
    assert!(!energy.passed, "{energy:?}");
    assert!(energy.value > 1e-8 && energy.value < 1e-5, "{energy:?}");
}

#[test]
fn a_contact_that_would_pull_fails_its_check() {
    let phase = release_phase(MODELS);
    let samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let mut forces = sample_forces(&phase, &samples).unwrap();
    let ctx = checks::Context::new("rod_cube_closed");
    let closed = phase.closed().unwrap();
    let ok =
        checks::contact_forces(phase.bound(), &samples, &forces, &closed, 1e-12, &ctx).unwrap();
    assert!(ok.iter().all(|(_, c)| c.passed), "{ok:?}");
    // The floor pulling the foot down by 1 N at one sample.
    forces[20][1] = -1.0;
    let pulled =
        checks::contact_forces(phase.bound(), &samples, &forces, &closed, 1e-12, &ctx).unwrap();
    let floor = &pulled[1].1;
    assert_eq!(pulled[1].0, "rod_cube_closed.floor_normal_pushes");
    assert!(!floor.passed && floor.value == -1.0, "{floor:?}");
    assert_eq!(floor.margin, floor.value - floor.limit);
    assert_eq!(floor.unit, "N");
    assert_eq!(floor.at_time, Some(samples.t[20]));
    assert!(pulled[0].1.passed);
    // A NaN force fails too.
    forces[20][1] = f64::NAN;
    let nan =
        checks::contact_forces(phase.bound(), &samples, &forces, &closed, 1e-12, &ctx).unwrap();
    assert!(!nan[1].1.passed, "{:?}", nan[1]);
    // An open contact has no push to check.
    let none = checks::contact_forces(
        phase.bound(),
        &samples,
        &forces,
        &[false, false],
        1e-12,
        &ctx,
    )
    .unwrap();
    assert!(none.is_empty());
    // A sample without the contact's force, or closed flags not one per contact, is an error,
    // not a NaN that fails the check.
    let mut short = forces.clone();
    short[20].truncate(1);
    for (what, forces, closed) in [
        ("forces", &short, &closed[..]),
        ("closed", &forces, &[true]),
    ] {
        match checks::contact_forces(phase.bound(), &samples, forces, closed, 1e-12, &ctx) {
            Err(SolveError::Input(SystemError::Length {
                what: w,
                expected: 2,
                got: 1,
                ..
            })) if w == what => {}
            other => panic!("{what}: {other:?}"),
        }
    }
}

#[test]
fn drift_beyond_the_tolerance_fails() {
    let phase = release_phase(MODELS);
    let bound = phase.bound();
    let mut samples = sample(&phase, 50, &mut Work::default()).unwrap();
    let ctx = checks::Context::new("rod_cube_closed");
    let conserved = Conserved::each_cyclic(bound);
    let ok = checks::drift(
        bound,
        &samples.states,
        &conserved,
        1e-12,
        &ctx,
        CheckKind::Identity,
    )
    .unwrap();
    let keys: Vec<&str> = ok.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        ["rod_cube_closed.energy", "rod_cube_closed.momentum_x1"]
    );
    assert!(ok.iter().all(|(_, c)| c.passed), "{ok:?}");
    // Velocities 1e-6 too fast at the last sample (kinetic energy 2e-6 of itself too large),
    // and the foot 1e-6 m/s faster still (the horizontal momentum, zero throughout, off by
    // (m1 + m2) 1e-6 kg m/s).
    let last = samples.states.len() - 1;
    let (q, mut qd) = samples.states[last].clone().into_parts();
    for v in &mut qd {
        *v *= 1.0 + 1e-6;
    }
    qd[0] += 1e-6;
    samples.states[last] = State::new(q, qd).unwrap();
    let bad = checks::drift(
        bound,
        &samples.states,
        &conserved,
        1e-12,
        &ctx,
        CheckKind::Drift,
    )
    .unwrap();
    for (key, c) in &bad {
        assert!(
            !c.passed && c.value > 1e-8 && c.margin < 0.0,
            "{key}: {c:?}"
        );
        assert_eq!(c.kind, CheckKind::Drift);
    }
    // The same drift passes a tolerance above it.
    let loose = checks::drift(
        bound,
        &samples.states,
        &conserved,
        1e-4,
        &ctx,
        CheckKind::Drift,
    )
    .unwrap();
    assert!(loose.iter().all(|(_, c)| c.passed), "{loose:?}");
}

#[test]
fn a_closed_gap_that_opens_fails_its_check() {
    // The paper's contact phase integrated on the general model with both contacts as rows.
    let w = walker(MODELS, Route::Integrated);
    let (start, _) = w.release().unwrap();
    let phase = w.solve(&start, &mut Work::default()).unwrap();
    let PhaseRun::Integrated(run) = &phase else {
        panic!("integrated route");
    };
    assert!(run.run.end.is_force_of(0), "{:?}", run.run.end);
    let mut states = run.run.states();
    let closed = vec![vec![true, true]; states.len()];
    let ctx = checks::Context::new("rod_cube.1");
    let ok = checks::constraint_drift(&w.general, &states, &closed, 1e-10, &ctx).unwrap();
    let keys: Vec<&str> = ok.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "rod_cube.1.contact_force_gap",
            "rod_cube.1.floor_normal_gap"
        ]
    );
    assert!(ok.iter().all(|(_, c)| c.passed), "{ok:?}");
    // The foot 1 um above the floor at one state: 1e-6 of the system's length (the tip's
    // reach, 1 m), far beyond 1e-10.
    let k = states.len() / 2;
    let (mut q, qd) = states[k].clone().into_parts();
    q[1] = 1e-6;
    states[k] = State::new(q, qd).unwrap();
    let lifted = checks::constraint_drift(&w.general, &states, &closed, 1e-10, &ctx).unwrap();
    let floor = &lifted[1].1;
    assert!(!floor.passed, "{floor:?}");
    assert!((floor.value - 1e-6).abs() < 1e-9, "{floor:?}");
    assert!(lifted[0].1.passed);
    // A contact open at that state is not held to its gap.
    let mut open = closed.clone();
    open[k][1] = false;
    let excused = checks::constraint_drift(&w.general, &states, &open, 1e-10, &ctx).unwrap();
    assert!(excused.iter().all(|(_, c)| c.passed), "{excused:?}");
}

#[test]
fn a_cube_running_into_the_tip_ends_the_motion() {
    // The paper's free phase: the tip draws away from the cube, to the floor.
    let w = walker(MODELS, Route::Fastest);
    let motion = w.motion(&mut Work::default()).unwrap();
    assert_eq!(motion.last_end(), Some(EndCause::Floor));
    // The rod alone from theta = 0.2 rad, falling at 1 rad/s, its foot at x1 = 0 sliding at
    // 1 m/s towards the cube, whose face is at 1 m gliding at 0.1 m/s: the gap
    // 1 - cos(0.2) = 0.0199 m closes at about 1.1 m/s, long before the rod lies flat.
    let p = free_after(0.2, -1.0, 0.0, 1.0);
    let sys = System::new(&FREE_ROD, &p).unwrap();
    let gap0 = sys.bound().gaps(&sys.bound().initial_state()).unwrap()[0];
    assert!((gap0 - (1.0 - 0.2f64.cos())).abs() < 1e-15, "{gap0}");
    let mut work = Work::default();
    let end = phase_end(&sys, &mut work).unwrap();
    assert_eq!(
        end.end,
        EndCause::Floor,
        "the closed contact alone reaches the floor"
    );
    let run = ReducedRun::with_end(sys.clone(), 0.0, end, 1e-12, &mut work).unwrap();
    assert!(
        matches!(run.end.end, EndCause::Contact(c) if c.index == 0),
        "{:?}",
        run.end.end
    );
    let t_meet = run.mesh.duration;
    assert!(t_meet > 0.0 && t_meet < 0.03, "{t_meet}");
    let at = run.end_state().unwrap();
    let gap = sys.bound().gaps(&at).unwrap()[0];
    assert!(gap.abs() < 1e-12, "{gap}");
    // The integrated route from the same state (the general model, only the foot's contact
    // closed) meets the cube at the same time.
    let start = Start {
        state: sys.to_full(&sys.bound().initial_state()).unwrap(),
        active: Active {
            closed: vec![false, true],
            modes: vec![],
        },
        frictions: vec![],
        friction_work: 0.0,
        stop_at: None,
        dense_output: true,
        sensitivity: None,
    };
    let ode = unreduced::integrate(&w.general, &start, 1e-12, None, 1.0, &mut work).unwrap();
    assert!(
        matches!(ode.end, EndCause::Contact(c) if c.index == 0),
        "{:?}",
        ode.end
    );
    assert!(
        ((ode.t_end - t_meet) / t_meet).abs() < 1e-9,
        "{} vs {t_meet}",
        ode.t_end
    );
    // The closing ends a motion that does not go on through impacts, and only that one.
    let motion = rodcube::solve::phases::Motion::starting(run.clone().into_phase(), vec![], false);
    let first = EndCause::Contact(ContactId::of(w.general.info(), 0).expect("contact 0"));
    assert!(!motion.goes_on_after(first) && motion.complete());
    let through = rodcube::solve::phases::Motion::starting(run.into_phase(), vec![], true);
    assert!(through.goes_on_after(first) && !through.complete());
    assert!(!through.goes_on_after(EndCause::Until));
    assert_eq!(rodcube::report::prose::cause_keyword(first), "contact");
}
