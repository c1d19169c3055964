//! Numerical faults are typed errors carrying the offending values, never panics, NaNs or
//! silent results: an ODE whose step size collapses (finite-time blow-up), a non-finite
//! right-hand side, a time or angle outside the phase whose root cannot be bracketed, and a
//! phase end that is not a number.

use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::fast::quadrature::TimeMesh;
use rodcube::solve::fast::separation::separation;
use rodcube::solve::integrated::ode::{OdeOptions, OdeProblem, dopri5};
use rodcube::solve::series::delta_at_time;
use rodcube::system::System;

/// `y' = y^2`, `y(0) = 1`: `y = 1/(1 - t)` blows up at `t = 1`.
struct BlowUp;

impl OdeProblem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}

/// `y' = sqrt(y)` from `y(0) = -1`: not a number from the start.
struct NotANumber;

impl OdeProblem for NotANumber {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
        dy[0] = y[0].sqrt();
        Ok(())
    }
}

fn options() -> OdeOptions {
    OdeOptions {
        controlled: None,
        rtol: 1e-10,
        atol: vec![1e-12],
        t_max: 2.0,
        max_steps: 1_000_000,
        dense_output: true,
    }
}

#[test]
fn step_size_collapse_is_reported_where_it_happens() {
    let err = dopri5(&mut BlowUp, 0.0, &[1.0], &options()).unwrap_err();
    let SolveError::StepSizeTooSmall { t, h } = err else {
        panic!("expected a step-size collapse, got {err:?}");
    };
    // y' = y^2, y(0) = 1 is y = 1/(1 - t): it blows up at t = 1.
    assert!(t > 0.999 && t <= 1.0, "t = {t}");
    assert!(h > 0.0 && h < 1e-12, "h = {h}");
    let message = err.to_string();
    assert!(message.contains(&format!("{t:e}")), "{message}");
}

#[test]
fn a_non_finite_derivative_is_reported_with_the_state() {
    let err = dopri5(&mut NotANumber, 0.0, &[-1.0], &options()).unwrap_err();
    match &err {
        SolveError::OdeNonFinite { what, t, y } => {
            assert_eq!(*what, "initial derivative");
            assert_eq!(*t, 0.0);
            assert!(y[0].is_nan(), "{y:?}");
        }
        other => panic!("expected OdeNonFinite, got {other:?}"),
    }
    assert!(err.to_string().contains("not finite"), "{err}");
}

fn paper_system() -> System<'static> {
    // The paper's contact phase: the fast phase of `rod_cube` with both contacts closed.
    let model = rodcube::models::find("rod_cube_closed").expect("rod_cube_closed is generated");
    let params = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ];
    System::new(model, &params).unwrap()
}

fn contact_mesh(sys: &System) -> TimeMesh {
    let mut work = Work::default();
    let delta = separation(sys, &mut work)
        .unwrap()
        .separation()
        .expect("the paper's rod separates")
        .delta;
    TimeMesh::build(sys, delta, 1e-12, &mut work).unwrap()
}

#[test]
fn a_time_outside_the_phase_cannot_be_bracketed() {
    let sys = paper_system();
    let mesh = contact_mesh(&sys);
    let mut work = Work::default();
    for t in [mesh.duration * 1.5, -1e-3, f64::NAN, f64::INFINITY] {
        match delta_at_time(&sys, &mesh, t, &mut work) {
            Err(SolveError::Inversion {
                target, duration, ..
            }) => {
                assert!(target.to_bits() == t.to_bits(), "{target} vs {t}");
                assert_eq!(duration, mesh.duration);
            }
            other => panic!("t = {t}: expected an inversion error, got {other:?}"),
        }
    }
    // Inside the phase it works, so the errors above are about the values.
    let inside = delta_at_time(&sys, &mesh, mesh.duration / 2.0, &mut work).unwrap();
    assert!(inside > 0.0 && inside < mesh.delta_end);
}

#[test]
fn an_angle_past_the_phase_end_is_refused_with_both_angles() {
    let sys = paper_system();
    let mesh = contact_mesh(&sys);
    let past = mesh.delta_end * 1.01;
    match mesh.time_at_delta(&sys, past, &mut Work::default()) {
        Err(SolveError::OutsidePhase {
            delta, delta_end, ..
        }) => {
            assert!((delta - past).abs() <= 1e-15 * past, "{delta} vs {past}");
            assert_eq!(delta_end, mesh.delta_end);
        }
        other => panic!("expected OutsidePhase, got {other:?}"),
    }
}

#[test]
fn a_phase_end_that_is_not_a_number_is_refused() {
    let sys = paper_system();
    for end in [f64::NAN, f64::INFINITY, -0.1, 0.0] {
        match TimeMesh::build(&sys, end, 1e-12, &mut Work::default()) {
            Err(SolveError::BadPhaseEnd { delta_end, .. }) => {
                assert_eq!(delta_end.to_bits(), end.to_bits());
            }
            other => panic!("end {end}: expected BadPhaseEnd, got {other:?}"),
        }
    }
}
