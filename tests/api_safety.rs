//! The library cannot be made to panic through its public entry points: arbitrary requests
//! (any quantity index, any parameter values and counts, NaN and infinities, any tolerance,
//! sample count and route) given to `plan::run`, and arbitrary points given to the per-point
//! solver, end in a result or a typed error. Results are read through typed accessors.

use proptest::prelude::*;
use rodcube::model::Model;
use rodcube::plan::{self, PlanError, Request};
use rodcube::quantity::Quantity;
use rodcube::solve::lean::LeanSolver;
use rodcube::solve::phases::Route;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Floats a careless or hostile caller might pass.
fn any_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(-1.0),
        Just(f64::MIN_POSITIVE),
        Just(1e-300),
        Just(1e300),
        Just(f64::MAX),
        0.01f64..10.0,
        -10.0f64..10.0,
    ]
}

/// An index into a model's forces, frictions or points: usually one it has.
fn any_index() -> impl Strategy<Value = usize> {
    prop_oneof![4 => 0usize..2, 1 => 0usize..12]
}

fn any_quantity() -> impl Strategy<Value = Quantity> {
    prop_oneof![
        Just(Quantity::SeparationAngle),
        Just(Quantity::LinearisedSeparationAngle),
        Just(Quantity::SeparationTime),
        Just(Quantity::ContactEnd),
        Just(Quantity::ContactTimeToFloor),
        Just(Quantity::PointMassFallTime),
        Just(Quantity::ThetaSeries),
        any_index().prop_map(Quantity::ForceSeries),
        any_index().prop_map(Quantity::FrictionSeries),
        any_index().prop_map(Quantity::Trajectory),
        Just(Quantity::FloorImpact),
        Just(Quantity::Checks),
        Just(Quantity::CrossCheck),
    ]
}

fn models() -> &'static [&'static dyn Model] {
    rodcube::models::all()
}

/// A model's parameters near a valid point, each perhaps replaced by a hostile value, with
/// perhaps one too few or one too many.
fn parameters(model: usize) -> impl Strategy<Value = Vec<f64>> {
    let n = models()[model].info().parameters.len();
    (
        prop::collection::vec(any_value(), n + 1),
        prop::collection::vec(prop::bool::weighted(0.1), n + 1),
        prop_oneof![6 => Just(0usize), 1 => Just(1), 1 => Just(2)],
    )
        .prop_map(move |(hostile, replace, count)| {
            let mut p: Vec<f64> = (0..n + 1)
                .map(|i| {
                    if replace[i] {
                        hostile[i]
                    } else {
                        valid(model, i)
                    }
                })
                .collect();
            // As many as the model takes, one too few, or one too many.
            p.truncate(match count {
                0 => n,
                1 => n.saturating_sub(1),
                _ => n + 1,
            });
            p
        })
}

/// A plausible valid value of parameter `i` of a model (the rod's defaults: masses 1, lengths
/// 1 with the cube at a quarter, g = 9.81, friction 0.3, start state 0).
fn valid(model: usize, i: usize) -> f64 {
    let info = models()[model].info();
    match info.parameters.get(i).map(|p| p.name) {
        Some("g") => 9.81,
        Some("a") | Some("h") => 0.25,
        Some(name) if name.starts_with("mu") => 0.3,
        Some(_) => 1.0,
        None => 1.0,
    }
}

/// Indices in [`models`] of the systems' general models (the ones the planner runs).
fn systems() -> Vec<usize> {
    (0..models().len())
        .filter(|&i| models()[i].info().is_general())
        .collect()
}

/// A model to run: usually a system's general model (which the planner solves), sometimes any
/// model (a fast phase, which it must refuse with a typed error).
fn any_model() -> impl Strategy<Value = usize> {
    prop_oneof![
        3 => prop::sample::select(systems()),
        1 => 0..models().len(),
    ]
}

fn request_case() -> impl Strategy<Value = (usize, Vec<f64>, Vec<Quantity>, f64, usize, bool)> {
    any_model().prop_flat_map(|m| {
        (
            Just(m),
            parameters(m),
            prop::collection::vec(any_quantity(), 0..3),
            prop_oneof![
                3 => Just(plan::DEFAULT_TOLERANCE),
                3 => Just(1e-6),
                1 => any_value(),
            ],
            prop_oneof![
                1 => Just(0usize),
                1 => Just(1),
                2 => Just(2),
                6 => Just(17),
                1 => Just(plan::MAX_SAMPLES + 1),
                1 => Just(usize::MAX)
            ],
            any::<bool>(),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 600,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5afe),
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_request_ends_in_results_or_a_typed_error(
        (m, p, want, tolerance, samples, integrated) in request_case()
    ) {
        let model = models()[m];
        let request = Request::new(model, p.clone())
            .with_want(&want)
            .with_tolerance(tolerance)
            .with_samples(samples)
            .with_route(if integrated { Route::Integrated } else { Route::Fastest });
        let outcome = catch_unwind(AssertUnwindSafe(|| plan::run(&request)));
        let Ok(outcome) = outcome else {
            return Err(TestCaseError::fail(format!(
                "plan::run panicked: {} {p:?} {want:?} tol {tolerance:e} samples {samples}",
                model.info().name
            )));
        };
        if let Ok(results) = outcome {
            // Every scalar read through its quantity is finite.
            for q in &want {
                if let Some(v) = results.value(*q) {
                    prop_assert!(v.is_finite(), "{q:?} = {v}");
                }
            }
        }
    }

    #[test]
    fn any_point_ends_in_a_solution_or_a_typed_error(
        (m, p) in (0..models().len()).prop_flat_map(|m| (Just(m), parameters(m)))
    ) {
        let model = models()[m];
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            LeanSolver::new(model).map(|mut solver| solver.solve(&p))
        }));
        prop_assert!(outcome.is_ok(), "LeanSolver panicked: {} {p:?}", model.info().name);
    }
}

#[test]
fn an_index_the_model_lacks_is_a_typed_error_naming_what_it_offers() {
    let model = rodcube::models::find("rod_cube").expect("generated model");
    let paper = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ];
    for q in [
        Quantity::ForceSeries(7),
        Quantity::Trajectory(99),
        Quantity::FrictionSeries(0),
    ] {
        match plan::run(&Request::new(model, paper).with_want(&[q])) {
            Err(PlanError::Unavailable {
                quantity, offers, ..
            }) => {
                assert!(offers.contains("contact_force_series"), "{offers}");
                assert!(!offers.contains(&quantity), "{quantity} in {offers}");
            }
            other => panic!("{q:?}: {other:?}"),
        }
    }
}

#[test]
fn results_are_read_through_typed_accessors() {
    let model = rodcube::models::find("rod_cube").expect("generated model");
    let info = model.info();
    let paper = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ];
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::ForceSeries(0),
    ];
    let results = plan::run(&Request::new(model, paper).with_want(&want)).expect("paper's case");
    let angle = results.separation_angle().expect("wanted");
    assert!((angle.to_degrees() - 9.61).abs() < 0.005);
    assert!(
        results
            .separation_time()
            .is_some_and(|t| (t - 0.1085).abs() < 5e-4)
    );
    // Not wanted: absent, not a panic.
    assert_eq!(results.value(Quantity::ContactTimeToFloor), None);
    assert_eq!(
        results.value(Quantity::ForceSeries(0)),
        None,
        "a series is no scalar"
    );
    let force = results
        .series_of(Quantity::ForceSeries(0), info)
        .expect("wanted");
    let t = force.column("t").expect("time column");
    assert_eq!(t.len(), plan::DEFAULT_SAMPLES);
    assert!(results.series_of(Quantity::ForceSeries(5), info).is_none());
    assert!(results.series_of(Quantity::ThetaSeries, info).is_none());
}

#[test]
fn the_per_point_solver_takes_parameters_by_name() {
    use rodcube::solve::SolveError;
    use rodcube::system::SystemError;
    let model = rodcube::models::find("rod_cube").expect("generated model");
    let mut solver = LeanSolver::new(model).expect("rod_cube solves per point");
    let named = solver
        .solve_named(&[
            ("g", 9.81),
            ("a", 0.25),
            ("ell", 1.0),
            ("m2", 3.0),
            ("m1", 1.0),
        ])
        .expect("paper's case");
    let ordered = solver
        .solve(&[1.0, 3.0, 1.0, 0.25, 9.81])
        .expect("paper's case");
    assert_eq!(named, ordered);
    let mut refused = |params: &[(&str, f64)]| match solver.solve_named(params) {
        Err(SolveError::Parameters(e)) => e,
        other => panic!("{params:?}: {other:?}"),
    };
    assert!(matches!(
        refused(&[("m1", 1.0), ("m2", 3.0), ("ell", 1.0), ("a", 0.25)]),
        SystemError::MissingParameter { name: "g", .. }
    ));
    assert!(matches!(
        refused(&[
            ("m1", 1.0),
            ("m1", 2.0),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", 1.0)
        ]),
        SystemError::DuplicateParameter { .. }
    ));
    assert!(matches!(
        refused(&[("mass", 1.0)]),
        SystemError::UnknownParameter { .. }
    ));
}

#[test]
fn models_can_be_named_as_types() {
    use rodcube::models::generated::rod_cube::RodCube;
    let mut solver = LeanSolver::new(&RodCube).expect("rod_cube solves per point");
    let by_type = solver
        .solve(&[1.0, 3.0, 1.0, 0.25, 9.81])
        .expect("paper's case");
    let model = rodcube::models::find("rod_cube").expect("generated model");
    let by_name = LeanSolver::new(model)
        .and_then(|mut s| s.solve(&[1.0, 3.0, 1.0, 0.25, 9.81]))
        .expect("paper's case");
    assert_eq!(by_type, by_name);
    assert_eq!(RodCube.info().name, "rod_cube");
    // The system's release fast phase, named as a type, is what the per-point solver runs for
    // the system: the same answer to the bit.
    use rodcube::models::generated::rod_cube_closed::RodCubeClosed;
    let by_phase = LeanSolver::new(&RodCubeClosed)
        .and_then(|mut s| s.solve(&[1.0, 3.0, 1.0, 0.25, 9.81]))
        .expect("paper's case");
    assert_eq!(by_phase, by_type);
    assert_eq!(RodCubeClosed.info().name, "rod_cube_closed");
    assert_eq!(RodCubeClosed.info().system, "rod_cube");
}
