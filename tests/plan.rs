//! The planner: the paper's figures end to end, each quantity computed with its prerequisites
//! and nothing else (proved by the work counters), checks only when asked, typed errors. The
//! system run is the hand-typed `rod_cube` (its general model), whose phases are the hand-typed
//! `rod_cube_closed` and `rod_cube_free`.

mod common;

use common::paper::{FREE_ROD, GENERAL, MODELS, ROD_CUBE, paper};
use common::tweaked::{Tweaked, registry};
use rodcube::model::Model;
use rodcube::plan::{PlanError, Request, run};
use rodcube::quantity::Quantity;
use rodcube::results::RunResults;
use rodcube::solve::SolveError;
use rodcube::system::SystemError;

fn ask(want: &[Quantity]) -> RunResults {
    ask_in(MODELS, want)
}

/// The hand-typed system with its phases looked up in `models`.
fn ask_in(models: &'static [&'static dyn Model], want: &[Quantity]) -> RunResults {
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(want)
        .with_tolerance(1e-12)
        .with_samples(101)
        .with_registry(models);
    run(&request).unwrap()
}

/// The hand-typed system with `phase` as its release phase.
fn ask_tweaked(phase: &'static Tweaked, want: &[Quantity]) -> RunResults {
    ask_in(registry(phase), want)
}

fn value(r: &RunResults, key: &str) -> f64 {
    r.results
        .get(key)
        .unwrap_or_else(|| panic!("no `{key}` in {:?}", r.results.keys()))
        .value
}

#[test]
fn paper_figures_end_to_end() {
    let r = ask(&[
        Quantity::SeparationAngle,
        Quantity::LinearisedSeparationAngle,
        Quantity::SeparationTime,
        Quantity::ContactTimeToFloor,
        Quantity::PointMassFallTime,
    ]);
    assert!((value(&r, "separation_angle").to_degrees() - 9.61).abs() < 0.005);
    assert!((value(&r, "linearised_separation_angle").to_degrees() - 9.59).abs() < 0.005);
    assert!((value(&r, "separation_time") - 0.10849).abs() < 5e-6);
    assert!((value(&r, "contact_time_to_floor") - 0.18693).abs() < 5e-6);
    assert!((value(&r, "point_mass_fall_time") - 0.15964).abs() < 5e-6);
    assert_eq!(r.results["separation_time"].unit, "s");
    assert_eq!(r.model, "rod_cube");
    assert_eq!(r.parameters["a"], 0.25);
    assert!(r.series.is_empty() && r.checks.is_empty() && r.notes.is_empty());
}

#[test]
fn separation_angle_alone_evaluates_only_the_polynomial() {
    let r = ask(&[Quantity::SeparationAngle]);
    assert!(r.work.polynomial_evals > 0);
    assert_eq!(r.work.integrand_evals, 0);
    assert_eq!(r.work.ode_steps, 0);
    assert!(r.work.phases.is_empty(), "{:?}", r.work.phases);
    assert_eq!(
        r.results.keys().collect::<Vec<_>>(),
        vec!["separation_angle"]
    );
    assert!(r.series.is_empty() && r.checks.is_empty());
}

#[test]
fn cheap_quantities_cost_nothing_they_do_not_need() {
    let r = ask(&[
        Quantity::LinearisedSeparationAngle,
        Quantity::PointMassFallTime,
    ]);
    assert_eq!(r.work, Default::default());
    let r = ask(&[Quantity::ContactTimeToFloor]);
    assert_eq!(
        r.work.polynomial_evals, 0,
        "contact to the floor needs no separation root"
    );
    assert!(r.work.integrand_evals > 0);
    assert_eq!(r.work.ode_steps, 0);
    assert!(r.work.phases.is_empty());
    let r = ask(&[Quantity::SeparationTime]);
    assert!(r.work.polynomial_evals > 0 && r.work.integrand_evals > 0);
    assert_eq!(r.work.ode_steps, 0);
    assert_eq!(
        r.work.phases,
        vec!["rod_cube_closed"],
        "no free phase for the separation time"
    );
}

#[test]
fn series_share_one_set_of_samples() {
    let theta = ask(&[Quantity::ThetaSeries]);
    let all = ask(&[
        Quantity::ThetaSeries,
        Quantity::ForceSeries(0),
        Quantity::ForceSeries(1),
        Quantity::Trajectory(1),
        Quantity::Trajectory(3),
    ]);
    assert_eq!(
        theta.work, all.work,
        "forces and trajectories reuse the theta samples"
    );
    assert_eq!(all.work.phases, vec!["rod_cube_closed"]);
    let s = &all.series["theta_series"];
    let names: Vec<&str> = s.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["t", "theta", "theta_dot", "theta_ddot"]);
    assert!(s.columns.iter().all(|c| c.values.len() == 101));
    // The contact force vanishes at the last sample (separation) and is largest at the start.
    let f = &all.series["contact_force_series"].columns[2].values;
    assert!(f[100].abs() < 1e-12 * f[0] && f.iter().all(|v| *v <= f[0]));
    // The tip runs on the ellipse of PHYSICS.md erratum 3.
    let tip = &all.series["tip_trajectory"];
    let names: Vec<&str> = tip.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["t", "x", "y", "vx", "vy"]);
    let beta = (1.0f64 - 0.0625).sqrt();
    for (x, y) in tip.columns[1].values.iter().zip(&tip.columns[2].values) {
        let e = (8.0 * x - 7.0 * beta).powi(2) + y * y;
        assert!((e - 1.0).abs() < 1e-13, "{e}");
    }
    assert!(
        all.series.contains_key("cube_trajectory")
            && all.series.contains_key("floor_normal_series")
    );
}

#[test]
fn floor_impact_simulates_the_free_phase_only_when_asked() {
    let r = ask(&[Quantity::FloorImpact]);
    assert_eq!(r.work.phases, vec!["rod_cube_closed", "rod_cube_free"]);
    assert_eq!(r.work.ode_steps, 0);
    let t = value(&r, "floor_impact_time");
    assert!(t > 0.10849 && t < 0.2, "{t}");
    assert!(value(&r, "impact_angular_velocity") < 0.0);
    assert!(r.notes.is_empty());
}

#[test]
fn cross_check_agrees_to_1e_9_and_runs_no_free_phase() {
    let r = ask(&[Quantity::CrossCheck]);
    assert!(r.work.ode_steps > 0);
    assert_eq!(r.work.phases, vec!["rod_cube_closed"]);
    let rel = value(&r, "cross_check_relative_difference");
    println!(
        "ODE {:.15} s, rel diff {rel:.2e}, time dev {:.2e} s, state dev {:.2e}, {} ODE steps",
        value(&r, "cross_check_time"),
        value(&r, "cross_check_time_deviation"),
        value(&r, "cross_check_state_deviation"),
        r.work.ode_steps
    );
    assert!(rel < 1e-9, "{rel:e}");
    assert!(value(&r, "cross_check_time_deviation") < 1e-9 * 0.10849);
    assert!(value(&r, "cross_check_state_deviation") < 1e-9);
    assert!(r.checks.is_empty(), "checks only when asked");
}

#[test]
fn checks_cover_every_phase_and_pass_for_the_paper() {
    let r = ask(&[
        Quantity::Checks,
        Quantity::CrossCheck,
        Quantity::FloorImpact,
    ]);
    let names: Vec<&str> = r.checks.keys().map(String::as_str).collect();
    // Each fast phase: its monitor, each closed contact's push, energy and each cyclic momentum.
    // The cross-check integrates the general model (x1, y1, theta, x2) with both contacts as
    // constraints: its energy, the gaps it holds closed, and the one combination of the cyclic
    // momenta (x1 and x2) that the tip's push (row -1 on x1, +1 on x2) does not change.
    assert_eq!(
        names,
        [
            "rod_cube.ode.contact_force_gap",
            "rod_cube.ode.energy",
            "rod_cube.ode.floor_normal_gap",
            "rod_cube.ode.momentum_x1_x2",
            "rod_cube_closed.contact_force_pushes",
            "rod_cube_closed.cube_does_not_tip",
            "rod_cube_closed.energy",
            "rod_cube_closed.floor_normal_pushes",
            "rod_cube_closed.momentum_x1",
            "rod_cube_free.cube_does_not_tip",
            "rod_cube_free.energy",
            "rod_cube_free.floor_normal_pushes",
            "rod_cube_free.momentum_x1",
            "rod_cube_free.momentum_x2",
        ]
    );
    for (name, c) in &r.checks {
        println!("{name}: passed {}, margin {:.3e}", c.passed, c.margin);
        assert!(c.passed, "{name}: {c:?}");
    }
    // PHYSICS.md: N >= 0.25 m1 g (to two digits) and the tipping ratio stays below 0.05.
    let n_min = r.checks["rod_cube_closed.floor_normal_pushes"].margin / 9.81;
    assert!((n_min - 0.25).abs() < 5e-3, "{n_min}");
    let restoring = 3.0 * 9.81 * 0.25 / 2.0;
    assert!(1.0 - r.checks["rod_cube_closed.cube_does_not_tip"].margin / restoring < 0.05);
    // The push is positive until it vanishes at separation, the phase's last sample.
    let push = &r.checks["rod_cube_closed.contact_force_pushes"];
    assert!(push.margin.abs() < 1e-9, "{push:?}");
    // The cube does not run into the tip again: the free phase reaches the floor (an open
    // contact's gap that closed would have ended the motion there, with a note).
    assert!(!r.notes.contains_key("floor_impact"), "{:?}", r.notes);
    assert!(value(&r, "floor_impact_time") > 0.10849);
    assert_eq!(r.work.phases, vec!["rod_cube_closed", "rod_cube_free"]);
}

#[test]
fn unavailable_quantities_and_bad_requests_are_typed_errors() {
    // The planner runs systems: a fast phase decides nothing about its contacts.
    let free = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
        ("x1_0", 0.0),
        ("theta_0", 0.2),
        ("x2_0", 1.0),
        ("x1_dot_0", 0.0),
        ("theta_dot_0", -1.0),
        ("x2_dot_0", 0.0),
    ];
    let request = Request::new(&FREE_ROD, free)
        .with_want(&[Quantity::SeparationAngle])
        .with_registry(MODELS);
    let err = run(&request).unwrap_err();
    assert_eq!(
        err,
        PlanError::NotASystem {
            name: "rod_cube_free",
            system: "rod_cube"
        }
    );
    assert!(err.to_string().contains("run `rod_cube`"), "{err}");
    let err = run(&Request::new(&ROD_CUBE, paper(9.81)).with_want(&[Quantity::SeparationAngle]))
        .unwrap_err();
    assert_eq!(
        err,
        PlanError::NotASystem {
            name: "rod_cube_closed",
            system: "rod_cube"
        }
    );
    // A quantity the system does not have.
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::FrictionSeries(0)])
        .with_registry(MODELS);
    let err = run(&request).unwrap_err();
    assert!(
        matches!(&err, PlanError::Unavailable { quantity, model: "rod_cube", offers } if quantity == "friction #0_series" && offers.contains("floor_normal_series")),
        "{err}"
    );
    // The time to the floor in contact is the release fast phase's: a system without one
    // (the ladder with friction, integrated throughout) does not offer it.
    let ladder = rodcube::models::find("ladder_friction").expect("generated model");
    let err = run(
        &Request::new(ladder, vec![1.0; ladder.info().parameters.len()])
            .with_want(&[Quantity::ContactTimeToFloor]),
    )
    .unwrap_err();
    assert!(
        matches!(&err, PlanError::Unavailable { quantity, model: "ladder_friction", .. } if quantity == "contact_time_to_floor"),
        "{err}"
    );

    let mut p = paper(9.81);
    p[3].1 = 2.0;
    let err = run(&Request::new(&GENERAL, p)
        .with_want(&[Quantity::SeparationAngle])
        .with_registry(MODELS))
    .unwrap_err();
    assert!(
        matches!(err, PlanError::System(SystemError::Requirement { .. })),
        "{err}"
    );
    let err = run(&Request::new(&GENERAL, paper(9.81)).with_tolerance(0.5)).unwrap_err();
    assert_eq!(err, PlanError::BadTolerance { tolerance: 0.5 });
    let err = run(&Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::ThetaSeries])
        .with_samples(1))
    .unwrap_err();
    assert_eq!(err, PlanError::TooFewSamples { samples: 1 });
    // Without `rod_cube_free` in the registry the floor impact cannot be followed past the
    // separation; without `rod_cube_closed` the motion cannot even start on the fast path.
    static WITHOUT_FREE: [&dyn Model; 2] = [&GENERAL, &ROD_CUBE];
    let err = run(&Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::FloorImpact])
        .with_registry(&WITHOUT_FREE))
    .unwrap_err();
    assert_eq!(
        err,
        PlanError::Solve(SolveError::UnknownPhaseModel {
            system: "rod_cube",
            name: "rod_cube_free"
        })
    );
    let err = run(&Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::FloorImpact])
        .with_registry(&[]))
    .unwrap_err();
    assert_eq!(
        err,
        PlanError::Solve(SolveError::UnknownPhaseModel {
            system: "rod_cube",
            name: "rod_cube_closed"
        })
    );
    assert!(matches!(
        Request::by_name("nope", paper(9.81), MODELS),
        Err(PlanError::UnknownModel { .. })
    ));
    assert!(Request::by_name("rod_cube", paper(9.81), MODELS).is_ok());
}

#[test]
fn parameters_by_value_or_by_name_give_the_same_run() {
    let want = [Quantity::SeparationTime];
    let by_name = run(&Request::new(&GENERAL, paper(9.81))
        .with_want(&want)
        .with_registry(MODELS))
    .unwrap();
    let by_value = run(&Request::new(&GENERAL, vec![1.0, 3.0, 1.0, 0.25, 9.81])
        .with_want(&want)
        .with_registry(MODELS))
    .unwrap();
    assert_eq!(by_name, by_value);
}

#[test]
fn no_separation_is_a_note_and_the_floor_is_reached_in_contact() {
    use common::tweaked::NEVER_SEPARATES;
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::FloorImpact,
        Quantity::ContactTimeToFloor,
    ];
    let r = ask_tweaked(&NEVER_SEPARATES, &want);
    assert!(
        !r.results.contains_key("separation_angle") && !r.results.contains_key("separation_time")
    );
    assert!(rodcube::report::prose::note(&r.notes["separation_angle"]).contains("no separation"));
    assert!(rodcube::report::prose::note(&r.notes["separation_time"]).contains("no separation"));
    // The contact holds to the floor, which the motion reaches: a landing, not a note.
    assert!(
        rodcube::report::prose::note(&r.notes["separation_angle"]).contains("holds until"),
        "{:?}",
        r.notes["separation_angle"]
    );
    assert!(!r.notes.contains_key("floor_impact"), "{:?}", r.notes);
    assert_eq!(r.work.phases, vec!["rod_cube_closed"]);
    // The contact phase to the floor is integrated once and serves both quantities.
    assert_eq!(
        value(&r, "floor_impact_time"),
        value(&r, "contact_time_to_floor")
    );
    let alone = ask_tweaked(&NEVER_SEPARATES, &[Quantity::ContactTimeToFloor]);
    assert_eq!(r.work.integrand_evals, alone.work.integrand_evals);
}

#[test]
fn without_separation_the_contact_integral_is_shared_in_either_order() {
    use common::tweaked::NEVER_SEPARATES;
    let a = ask_tweaked(
        &NEVER_SEPARATES,
        &[Quantity::ContactTimeToFloor, Quantity::FloorImpact],
    );
    let b = ask_tweaked(
        &NEVER_SEPARATES,
        &[Quantity::FloorImpact, Quantity::ContactTimeToFloor],
    );
    let alone = ask_tweaked(&NEVER_SEPARATES, &[Quantity::ContactTimeToFloor]);
    assert_eq!(a.work.integrand_evals, alone.work.integrand_evals);
    assert_eq!(b.work.integrand_evals, alone.work.integrand_evals);
    assert_eq!(a.results, b.results);
}

#[test]
fn every_quantity_runs_across_extreme_ratios_and_tolerances() {
    use common::paper::ratios;
    let mut worst = 0.0f64;
    for n in [1e-12, 3.0, 1e12] {
        for r in [1e-10, 0.25, 1.0 - 1e-9] {
            for tol in [1e-14, 1e-8, 1e-2] {
                let model: &'static dyn Model = &GENERAL;
                let request = Request::new(model, ratios(n, r))
                    .with_want(&Quantity::all(model.info()))
                    .with_tolerance(tol)
                    .with_samples(20)
                    .with_registry(MODELS);
                let r_ =
                    run(&request).unwrap_or_else(|e| panic!("n = {n}, r = {r}, tol = {tol}: {e}"));
                for (name, c) in &r_.checks {
                    assert!(c.passed, "n = {n}, r = {r}, tol = {tol}: {name} {c:?}");
                }
                assert!(r_.results.values().all(|s| s.value.is_finite()));
                assert!(value(&r_, "floor_impact_time") > value(&r_, "separation_time"));
                // Conditioning of the ODE route: near upright (cos theta_i ~ 4e-5) the equations
                // take the absolute angle, whose rounding limits it to ~1e-11; cond(M) grows like
                // n, and the ODE's tolerance is raised to 10 eps cond(M).
                let Some(rel) = r_
                    .results
                    .get("cross_check_relative_difference")
                    .map(|s| s.value)
                else {
                    // Only the 1e12 cube is beyond the unreduced route (cond(M) ~ 1e13).
                    let note = rodcube::report::prose::note(&r_.notes["cross_check"]);
                    assert!(n >= 1e12 && note.contains("condition"), "{note}");
                    continue;
                };
                // The bound from the physics, not from the run's own figures: the mass
                // matrix's condition grows like the mass ratio (max(n, 1/n), times a geometric
                // factor of order ten), and the integrator cannot do better than some ulps of
                // that.
                let wanted = if tol <= 1e-8 { 1e-9 } else { 10.0 * tol };
                let conditioning = 100.0 * f64::EPSILON * n.max(1.0 / n);
                let bound = wanted.max(conditioning);
                let rtol = value(&r_, "cross_check_rtol");
                assert!(
                    rel < bound,
                    "n = {n}, r = {r}, tol = {tol}: ODE differs by {rel:e}"
                );
                println!(
                    "n = {n:e}, r = {r:e}, tol = {tol:e}: ODE rtol {rtol:.1e}, rel diff {rel:.1e}"
                );
                if tol <= 1e-8 && n < 1e3 {
                    worst = worst.max(rel);
                }
            }
        }
    }
    println!("worst ODE/quadrature relative difference for n < 1e3, tol <= 1e-8: {worst:.2e}");
}

#[test]
fn a_nan_from_the_model_is_an_error_naming_the_series() {
    // The release phase's floor normal force is NaN everywhere: a broken model function, which
    // must be reported as such (not read as a force that stopped pushing, and never returned).
    use common::tweaked::NAN_FORCE;
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::ForceSeries(1)])
        .with_samples(5)
        .with_registry(registry(&NAN_FORCE));
    let err = run(&request).unwrap_err();
    let named = match &err {
        PlanError::NonFinite { key, index, value } => {
            key == "floor_normal_series.floor_normal" && *index == 0 && value.is_nan()
        }
        // Or refused where the phase's end is sought, before any series.
        PlanError::Solve(SolveError::NonFinite { model, value, .. }) => {
            *model == "rod_cube_closed" && value.is_nan()
        }
        _ => false,
    };
    assert!(named, "{err:?}: {err}");
}

/// Each quantity asked alone gives, to the bit, what it gives asked beside every other: the
/// integrated phases keep their steps' continuous extensions only when a quantity samples the
/// motion (`Quantity::samples_motion`), and that changes neither the steps nor the events. A
/// quantity that sampled without saying so would be an error here (a sample inside a step
/// without its extension is refused), and one whose motion changed would differ. The run is
/// the paper's rod and cube with every support a contact, bouncing at e = 1/2 to 0.4 s
/// (integrated phases, impacts, a floor), and a friction model for its series.
#[test]
fn each_quantity_alone_equals_itself_beside_every_other() {
    let mut bounce = paper(9.81).to_vec();
    bounce.push(("e", 0.5));
    let ladder = [
        ("m1", 1.0),
        ("ell", 1.0),
        ("a", 0.8),
        ("g", 9.81),
        ("mu_f", 0.2),
        ("mu_w", 0.2),
    ];
    /// A model, its parameters and how long the run goes on.
    type Case<'a> = (&'a str, &'a [(&'a str, f64)], Option<f64>);
    let cases: [Case; 2] = [
        ("rod_cube_liftoff", &bounce, Some(0.4)),
        ("ladder_friction", &ladder, None),
    ];
    for (name, params, until) in cases {
        let model = rodcube::models::find(name).unwrap();
        let info = model.info();
        let all: Vec<Quantity> = (Quantity::all(info).into_iter())
            .filter(|q| q.available(info))
            .collect();
        let ask = |want: &[Quantity]| {
            let request = Request::new(model, params)
                .with_want(want)
                .with_tolerance(1e-12)
                .with_samples(51)
                .with_until(until);
            run(&request).unwrap_or_else(|e| panic!("{name} {want:?}: {e}"))
        };
        let every = ask(&all);
        for q in &all {
            let alone = ask(std::slice::from_ref(q));
            let label = format!("{name}: {}", q.name(info));
            for (key, v) in &alone.results {
                assert_eq!(Some(v), every.results.get(key), "{label}: result {key}");
            }
            for (key, v) in &alone.series {
                assert_eq!(Some(v), every.series.get(key), "{label}: series {key}");
            }
            for (key, v) in &alone.labels {
                assert_eq!(Some(v), every.labels.get(key), "{label}: label {key}");
            }
            if alone.impacts.is_some() {
                assert_eq!(alone.impacts, every.impacts, "{label}: impacts");
            }
        }
    }
}
