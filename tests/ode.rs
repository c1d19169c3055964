//! The unreduced ODE route (DOPRI5/DOP853 with event location) against the quadrature route:
//! the separation time, the state along the way, and conservation along the ODE path. The route
//! integrates the system's general model (`x1, y1, theta, x2`) with the closed contacts as
//! constraints, as the planner's cross-check does; and both integrators run on the rod and
//! cube's equations with both contacts eliminated (`rod_cube_closed`: `x1, theta`).

mod common;

use common::paper::{FREE_ROD, GENERAL, ROD_CUBE, paper, ratios};
use rodcube::results::EndCause;
use rodcube::results::{CheckKind, Work};
use rodcube::solve::SolveError;
use rodcube::solve::checks::{self, Conserved, free_momenta};
use rodcube::solve::fast::quadrature::TimeMesh;
use rodcube::solve::fast::separation::separation;
use rodcube::solve::integrated::contacts::{self, Active};
use rodcube::solve::integrated::ode::{self, Method, OdeOptions, OdeProblem};
use rodcube::solve::integrated::unreduced::{Start, UnreducedRun, integrate, motion_scales};
use rodcube::solve::phases::fall_time_scale;
use rodcube::solve::series::{delta_at_time, theta_dot_at};
use rodcube::system::{Bound, State, System};

/// Index of `theta` in the general model's coordinates.
const THETA: usize = 2;

fn quadrature_separation(sys: &System) -> (f64, TimeMesh) {
    let de = separation(sys, &mut Work::default())
        .unwrap()
        .separation()
        .unwrap()
        .delta;
    let mesh = TimeMesh::build(sys, de, 1e-14, &mut Work::default()).unwrap();
    (mesh.duration, mesh)
}

/// The general model integrated from `state` with `closed` contacts held, with the motion's
/// own scales for the absolute tolerances (the foot's height, held at zero, has none).
fn integrate_general(
    general: &Bound,
    state: State,
    closed: [bool; 2],
    rtol: f64,
    t_max: f64,
    work: &mut Work,
) -> UnreducedRun {
    let start = Start {
        state,
        active: Active {
            closed: closed.to_vec(),
            modes: vec![],
        },
        frictions: vec![],
        friction_work: 0.0,
        stop_at: None,
        dense_output: true,
        sensitivity: None,
    };
    let d = contacts::dynamics(general, &start.state, &start.active, 0.0).unwrap();
    let scales = motion_scales(
        general,
        &start.state,
        &d.qdd,
        fall_time_scale(general, &start.state).unwrap(),
    )
    .unwrap();
    integrate(general, &start, rtol, Some(&scales), t_max, work).unwrap()
}

/// The general model from release, both contacts closed.
fn from_release(general: &Bound, rtol: f64, t_max: f64, work: &mut Work) -> UnreducedRun {
    integrate_general(
        general,
        general.initial_state(),
        [true, true],
        rtol,
        t_max,
        work,
    )
}

#[test]
fn separation_time_agrees_with_quadrature_and_converges() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let general = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let (t_quad, _) = quadrature_separation(&sys);
    let mut last = f64::INFINITY;
    for rtol in [1e-6, 1e-8, 1e-10, 1e-12, 1e-13] {
        let mut work = Work::default();
        let run = from_release(&general, rtol, 1.0, &mut work);
        assert!(run.end.is_force_of(0), "{:?}", run.end);
        assert_eq!(run.method, Method::for_rtol(run.rtol));
        let rel = ((run.t_end - t_quad) / t_quad).abs();
        println!(
            "rtol {rtol:.0e}: t_ode = {:.15} s, rel diff {rel:.2e}, {} accepted + {} rejected steps, {} event trials",
            run.t_end,
            run.segments[0].solution.accepted,
            run.segments[0].solution.rejected,
            run.segments[0].solution.event_trials
        );
        assert_eq!(work.ode_steps, run.steps());
        if rtol <= 1e-10 {
            assert!(rel < 1e-9, "rtol {rtol}: {rel:e}");
            assert!(
                rel < last.max(1e-13),
                "no convergence: {rel:e} after {last:e}"
            );
        }
        last = rel;
    }
}

#[test]
fn the_contact_force_vanishes_at_the_event() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let f0 = sys.forces(0.0).unwrap()[0];
    // On the general model: the tip's force as the constraint row's multiplier.
    let general = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let run = from_release(&general, 1e-12, 1.0, &mut Work::default());
    let d = run
        .dynamics_at(&general, &run.state_end, run.t_end)
        .unwrap();
    let f = d.forces[0];
    assert!(f.abs() < 1e-10 * f0, "F = {f} N at the event (F0 = {f0} N)");
    // It is the closed-form force at release (eq. 16).
    let start = contacts::dynamics(
        &general,
        &general.initial_state(),
        &Active {
            closed: vec![true, true],
            modes: vec![],
        },
        0.0,
    )
    .unwrap();
    assert!(((start.forces[0] - f0) / f0).abs() < 1e-14, "{start:?}");
    // On the fast phase's own equations (both contacts eliminated): its closed-form force.
    let bound = sys.bound();
    let active = Active::of_model(bound.info());
    let start = Start {
        state: bound.initial_state(),
        active: active.clone(),
        frictions: vec![],
        friction_work: 0.0,
        stop_at: None,
        dense_output: true,
        sensitivity: None,
    };
    let run = integrate(bound, &start, 1e-12, None, 1.0, &mut Work::default()).unwrap();
    assert!(run.end.is_force_of(0), "{:?}", run.end);
    let d = contacts::dynamics(bound, &run.state_end, &active, run.t_end).unwrap();
    let f = bound.forces_full(&run.state_end, &d.qdd).unwrap()[0];
    assert!(f.abs() < 1e-10 * f0, "F = {f} N at the event (F0 = {f0} N)");
}

#[test]
fn state_along_the_way_matches_the_reduced_motion() {
    for (n, r) in [(3.0, 0.25), (0.1, 0.8), (50.0, 0.05)] {
        let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
        let general = Bound::new(&GENERAL, &ratios(n, r)).unwrap();
        let (t_quad, mesh) = quadrature_separation(&sys);
        let run = from_release(&general, 1e-12, 2.0 * t_quad, &mut Work::default());
        assert!(((run.t_end - t_quad) / t_quad).abs() < 1e-9);
        let scale = sys.theta_initial();
        let omega_scale = sys.reduced(mesh.delta_end).unwrap().theta_dot_sq.sqrt();
        let mut worst = 0.0f64;
        for i in 1..40 {
            let t = t_quad * i as f64 / 40.0;
            let y = run.state_at(t).unwrap();
            let delta = delta_at_time(&sys, &mesh, t, &mut Work::default()).unwrap();
            // The reduced motion in the system's coordinates.
            let reduced = sys
                .to_full(&sys.full_state(t, delta, theta_dot_at(&sys, delta)).unwrap())
                .unwrap();
            worst = worst.max(((y[THETA] - reduced.q()[THETA]) / scale).abs());
            worst = worst.max(((y[4 + THETA] - reduced.qd()[THETA]) / omega_scale).abs());
            worst = worst.max(((y[0] - reduced.q()[0]) / scale).abs());
            worst = worst.max(((y[3] - reduced.q()[3]) / scale).abs());
            // The foot stays on the floor.
            worst = worst.max((y[1] / scale).abs());
        }
        println!("n = {n}, r = {r}: worst relative state difference along the way {worst:.2e}");
        assert!(worst < 1e-9, "n = {n}, r = {r}: {worst:e}");
    }
}

#[test]
fn ode_path_conserves_energy_and_momentum() {
    let general = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let run = from_release(&general, 1e-12, 1.0, &mut Work::default());
    let states = run.states();
    assert_eq!(states.len(), run.nodes().len());
    let rows = vec![(vec![true, true], vec![]); states.len()];
    // The tip pushes x1 back and x2 forward alike: only their sum's momentum is conserved, its
    // unit weights (1, 1)/sqrt(2) (by hand: the tip's row has -1 and +1 in x1 and x2).
    let conserved = Conserved {
        friction_work: None,
        momenta: free_momenta(&general, &states, &rows).unwrap(),
    };
    assert_eq!(conserved.momenta.len(), 1);
    let (name, w) = &conserved.momenta[0];
    assert_eq!(name, "momentum_x1_x2");
    assert!(
        (w[0] - w[1]).abs() < 1e-15 && (w[0] - 0.5f64.sqrt()).abs() < 1e-15,
        "{w:?}"
    );
    let ctx = checks::Context::new("ode");
    let found =
        checks::drift(&general, &states, &conserved, 1e-10, &ctx, CheckKind::Drift).unwrap();
    let keys: Vec<&str> = found.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, ["ode.energy", "ode.momentum_x1_x2"]);
    for (name, check) in &found {
        println!(
            "{name}: drift {:.3e} ({})",
            check.value,
            rodcube::report::prose::check_meaning(check)
        );
        assert_eq!(check.margin, check.limit - check.value);
        assert!(check.passed, "{name}: {check:?}");
    }
    // The gaps of the contacts held closed stay shut.
    let closed: Vec<Vec<bool>> = rows.iter().map(|(c, _)| c.clone()).collect();
    let gaps = checks::constraint_drift(&general, &states, &closed, 1e-10, &ctx).unwrap();
    assert_eq!(gaps.len(), 2);
    assert!(gaps.iter().all(|(_, c)| c.passed), "{gaps:?}");
    // The drift measure can fail: a tolerance below the achieved drift does.
    let strict =
        checks::drift(&general, &states, &conserved, 1e-18, &ctx, CheckKind::Drift).unwrap();
    assert!(!strict[0].1.passed);
}

#[test]
fn free_rod_reaches_the_floor_event() {
    let params = common::paper::free_after(0.1677, -1.4, -0.01, -0.2);
    let sys = System::new(&FREE_ROD, &params).unwrap();
    let mesh = TimeMesh::build(&sys, sys.delta_to_floor(), 1e-14, &mut Work::default()).unwrap();
    // The general model from the same state, the foot on the floor and the tip off the cube.
    let general = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let state = sys.to_full(&sys.bound().initial_state()).unwrap();
    let run = integrate_general(
        &general,
        state,
        [false, true],
        1e-12,
        1.0,
        &mut Work::default(),
    );
    assert_eq!(run.end, EndCause::Floor);
    assert!(((run.t_end - mesh.duration) / mesh.duration).abs() < 1e-9);
    assert!(run.state_end.q()[THETA].abs() < 1e-12);
}

/// The equations with both contacts eliminated (`rod_cube_closed`) as the integrator sees
/// them, written here from the public API: the deviation `z = y - y0` from the release state,
/// the tip's force as the event.
struct Unreduced<'a> {
    bound: &'a Bound<'a>,
    active: Active,
    y0: Vec<f64>,
    evals: u64,
}

impl Unreduced<'_> {
    fn state(&self, z: &[f64]) -> State {
        let n = self.y0.len() / 2;
        let y: Vec<f64> = z.iter().zip(&self.y0).map(|(z, y0)| y0 + z).collect();
        State::new(y[..n].to_vec(), y[n..].to_vec()).unwrap()
    }
}

impl OdeProblem for Unreduced<'_> {
    fn dim(&self) -> usize {
        self.y0.len()
    }
    fn rhs(&mut self, t: f64, z: &[f64], dz: &mut [f64]) -> Result<(), SolveError> {
        self.evals += 1;
        let n = self.y0.len() / 2;
        let state = self.state(z);
        dz[..n].copy_from_slice(state.qd());
        dz[n..].copy_from_slice(&contacts::dynamics(self.bound, &state, &self.active, t)?.qdd);
        Ok(())
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&mut self, _t: f64, z: &[f64], dz: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        let n = self.y0.len() / 2;
        g[0] = self.bound.forces_full(&self.state(z), &dz[n..]).unwrap()[0];
        Ok(())
    }
}

/// Both integrators on the rod and cube to separation, against the quadrature's time; prints
/// the counts behind [`Method::CROSSOVER_RTOL`]'s choice.
#[test]
fn both_integrators_find_the_separation() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (t_quad, _) = quadrature_separation(&sys);
    let bound = sys.bound();
    let start = bound.initial_state();
    let y0 = [start.q().to_vec(), start.qd().to_vec()].concat();
    for rtol in [
        1e-6, 1e-8, 1e-9, 1e-10, 5e-11, 3e-11, 2e-11, 1e-11, 1e-12, 1e-13,
    ] {
        let opts = OdeOptions {
            controlled: None,
            rtol,
            atol: Vec::new(),
            t_max: 1.0,
            max_steps: 200_000,
            dense_output: true,
        };
        let mut evals = [0; 2];
        for (e, method) in evals.iter_mut().zip([Method::Dopri5, Method::Dop853]) {
            let mut problem = Unreduced {
                bound,
                active: Active::of_model(bound.info()),
                y0: y0.clone(),
                evals: 0,
            };
            let zero = vec![0.0; y0.len()];
            let sol = ode::integrate(method, &mut problem, 0.0, &zero, &opts).unwrap();
            let t = sol.event.as_ref().unwrap().t;
            let rel = ((t - t_quad) / t_quad).abs();
            *e = problem.evals;
            println!(
                "rtol {rtol:.0e} {method}: {} accepted + {} rejected + {} event trials, {} evaluations, rel diff {rel:.2e}",
                sol.accepted, sol.rejected, sol.event_trials, problem.evals
            );
            assert!(rel < rtol, "{method} at rtol {rtol:e}: {rel:e}");
            if rtol <= 1e-10 {
                assert!(rel < 1e-12, "{method} at rtol {rtol:e}: {rel:e}");
            }
        }
        if rtol <= 1e-11 {
            assert!(evals[1] < evals[0], "rtol {rtol:e}: {evals:?}");
        }
    }
}
