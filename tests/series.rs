//! `theta(t)` series by inverting the quadrature: uniform times, exact end points, agreement with
//! `t(theta)` and with the independent ODE route, also for near-upright and moving starts.

mod common;

use common::paper::{FREE_ROD, GENERAL, MODELS, ROD_CUBE, paper, ratios};
use rodcube::model::Model;
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::fast::quadrature::TimeMesh;
use rodcube::solve::fast::separation::separation;
use rodcube::solve::integrated::contacts::Active;
use rodcube::solve::integrated::unreduced::{Start, integrate};
use rodcube::solve::phases::{Route, Walker};
use rodcube::solve::series::sample_phase;
use rodcube::system::{Bound, System};

fn contact_mesh(sys: &System) -> TimeMesh {
    let de = separation(sys, &mut Work::default())
        .unwrap()
        .separation()
        .unwrap()
        .delta;
    TimeMesh::build(sys, de, 1e-13, &mut Work::default()).unwrap()
}

#[test]
fn paper_series_is_uniform_in_time_and_ends_at_separation() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let mesh = contact_mesh(&sys);
    let mut work = Work::default();
    let s = sample_phase(&sys, &mesh, 201, &mut work).unwrap();
    assert_eq!(s.len(), 201);
    println!(
        "201 samples: {} integrand evals for the inversion",
        work.integrand_evals
    );
    for j in 0..201 {
        assert!((s.t[j] - mesh.duration * j as f64 / 200.0).abs() <= 1e-16);
    }
    assert_eq!(s.theta[0], sys.theta_initial());
    assert_eq!(s.theta_dot[0], 0.0);
    assert!((s.theta[200] - (sys.theta_initial() - mesh.delta_end)).abs() < 1e-16);
    // The paper's 9.61 deg (section 3, PHYSICS.md).
    assert!((s.theta[200].to_degrees() - 9.61).abs() < 0.005);
    for j in 1..201 {
        assert!(s.theta[j] < s.theta[j - 1] && s.theta_dot[j] < 0.0);
        assert_eq!(s.theta_ddot[j], sys.reduced(s.delta[j]).unwrap().theta_ddot);
        // Each sample's angle gives back its time.
        let t = mesh
            .time_at_delta(&sys, s.delta[j], &mut Work::default())
            .unwrap();
        assert!(
            (t - s.t[j]).abs() < 1e-15 * mesh.duration.max(1.0) * 10.0,
            "j = {j}: {t} vs {}",
            s.t[j]
        );
    }
    assert!(work.integrand_evals > 0 && work.ode_steps == 0);
}

#[test]
fn series_agrees_with_the_ode_dense_output() {
    for (n, r) in [(3.0, 0.25), (1e-6, 0.999), (1e6, 1e-4), (3.0, 1.0 - 1e-9)] {
        let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
        let mesh = contact_mesh(&sys);
        let s = sample_phase(&sys, &mesh, 101, &mut Work::default()).unwrap();
        // The system's general model (x1, y1, theta, x2), both contacts held as constraints
        // from release: no energy integral, no quadrature.
        let general = Bound::new(&GENERAL, &ratios(n, r)).unwrap();
        let start = Start {
            state: general.initial_state(),
            active: Active {
                closed: vec![true, true],
                modes: vec![],
            },
            frictions: vec![],
            friction_work: 0.0,
            stop_at: None,
            dense_output: true,
            sensitivity: None,
        };
        // Absolute tolerances from the motion's own scales (the foot's height, held at zero,
        // carries only rounding).
        let walker =
            Walker::new(general.clone(), MODELS, 1e-13, 1e-13).with_route(Route::Integrated);
        let scales = walker.scales(&start.state, &start.active).unwrap();
        let run = integrate(
            &general,
            &start,
            1e-13,
            Some(&scales),
            2.0 * mesh.duration,
            &mut Work::default(),
        )
        .unwrap();
        assert!(run.end.is_force_of(0), "n = {n}, r = {r}");
        let theta = GENERAL.info().reduced_index.unwrap();
        let mut worst = 0.0f64;
        for j in 0..101 {
            let t = s.t[j].min(run.t_end);
            let y = run.state_at(t).unwrap();
            worst = worst.max((y[theta] - s.theta[j]).abs() / sys.theta_initial());
        }
        println!(
            "n = {n:e}, r = {r}: t_sep = {:.6e} s, worst |theta_ode - theta| / theta_i = {worst:.2e}",
            mesh.duration
        );
        assert!(worst < 1e-8, "n = {n}, r = {r}: {worst:e}");
    }
}

#[test]
fn moving_start_is_sampled_too() {
    let params = common::paper::free_after(0.1677, -1.4, -0.01, -0.2);
    let sys = System::new(&FREE_ROD, &params).unwrap();
    let mesh = TimeMesh::build(&sys, sys.delta_to_floor(), 1e-13, &mut Work::default()).unwrap();
    let s = sample_phase(&sys, &mesh, 50, &mut Work::default()).unwrap();
    assert_eq!(s.theta_dot[0], -1.4);
    assert!(s.theta[49].abs() < 1e-15);
    for j in 1..50 {
        let t = mesh
            .time_at_delta(&sys, s.delta[j], &mut Work::default())
            .unwrap();
        assert!((t - s.t[j]).abs() < 1e-14, "j = {j}: {t} vs {}", s.t[j]);
    }
}

#[test]
fn two_samples_need_no_inversion_and_one_is_refused() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let mesh = contact_mesh(&sys);
    let mut work = Work::default();
    let s = sample_phase(&sys, &mesh, 2, &mut work).unwrap();
    assert_eq!(s.t, vec![0.0, mesh.duration]);
    assert_eq!(work.integrand_evals, 0);
    assert_eq!(
        sample_phase(&sys, &mesh, 1, &mut work),
        Err(SolveError::TooFewSamples { samples: 1 })
    );
}
