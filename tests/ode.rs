//! The unreduced ODE route (DOPRI5 with event location) against the quadrature route: the
//! separation time, the state along the way, and conservation along the ODE path; and both
//! integrators (DOPRI5 and DOP853) on the rod and cube's unreduced equations.

mod common;

use common::paper::{FREE_ROD, ROD_CUBE, paper, ratios};
use rodcube::results::{CheckKind, Work};
use rodcube::solve::SolveError;
use rodcube::solve::checks;
use rodcube::solve::ode::{self, Method, OdeOptions, OdeProblem};
use rodcube::solve::quadrature::TimeMesh;
use rodcube::solve::separation::separation;
use rodcube::solve::series::{delta_at_time, theta_dot_at};
use rodcube::solve::unreduced::{EndEvent, accelerations, integrate};
use rodcube::system::{State, System};

fn quadrature_separation(sys: &System) -> (f64, TimeMesh) {
    let de = separation(sys, &mut Work::default())
        .unwrap()
        .separation()
        .unwrap()
        .delta;
    let mesh = TimeMesh::build(sys, de, 1e-14, &mut Work::default()).unwrap();
    (mesh.duration, mesh)
}

#[test]
fn separation_time_agrees_with_quadrature_and_converges() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (t_quad, _) = quadrature_separation(&sys);
    let mut last = f64::INFINITY;
    for rtol in [1e-6, 1e-8, 1e-10, 1e-12, 1e-13] {
        let mut work = Work::default();
        let run = integrate(&sys, rtol, None, 1.0, &mut work).unwrap();
        assert_eq!(run.end, EndEvent::Separation);
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
    let run = integrate(&sys, 1e-12, None, 1.0, &mut Work::default()).unwrap();
    let qdd = rodcube::solve::unreduced::accelerations(&sys, &run.state_end, run.t_end).unwrap();
    let f = sys.forces_full(&run.state_end, &qdd, &[])[0];
    let f0 = sys.forces(0.0)[0];
    assert!(f.abs() < 1e-10 * f0, "F = {f} N at the event (F0 = {f0} N)");
}

#[test]
fn state_along_the_way_matches_the_reduced_motion() {
    for (n, r) in [(3.0, 0.25), (0.1, 0.8), (50.0, 0.05)] {
        let sys = System::new(&ROD_CUBE, &ratios(n, r)).unwrap();
        let (t_quad, mesh) = quadrature_separation(&sys);
        let run = integrate(&sys, 1e-12, None, 2.0 * t_quad, &mut Work::default()).unwrap();
        assert!(((run.t_end - t_quad) / t_quad).abs() < 1e-9);
        let scale = sys.theta_initial();
        let mut worst = 0.0f64;
        for i in 1..40 {
            let t = t_quad * i as f64 / 40.0;
            let y = run.state_at(t).unwrap();
            let delta = delta_at_time(&sys, &mesh, t, &mut Work::default()).unwrap();
            let reduced = sys.full_state(t, delta, theta_dot_at(&sys, delta));
            let omega_scale = sys.reduced(mesh.delta_end).theta_dot_sq.sqrt();
            worst = worst.max(((y[1] - reduced.q[1]) / scale).abs());
            worst = worst.max(((y[3] - reduced.qd[1]) / omega_scale).abs());
            worst = worst.max(((y[0] - reduced.q[0]) / scale).abs());
        }
        println!("n = {n}, r = {r}: worst relative state difference along the way {worst:.2e}");
        assert!(worst < 1e-9, "n = {n}, r = {r}: {worst:e}");
    }
}

#[test]
fn ode_path_conserves_energy_and_momentum() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let run = integrate(&sys, 1e-12, None, 1.0, &mut Work::default()).unwrap();
    let states: Vec<State> = run
        .nodes()
        .iter()
        .map(|(_, y)| State {
            q: y[..2].to_vec(),
            qd: y[2..].to_vec(),
        })
        .collect();
    let ctx = checks::Context::new("ode");
    let found = checks::drift(&sys, &states, None, 1e-10, &ctx, CheckKind::Drift);
    assert_eq!(found.len(), 2);
    for (name, check) in &found {
        println!("{name}: drift {:.3e} ({})", check.value, check.meaning);
        assert_eq!(check.margin, check.limit - check.value);
        assert!(check.passed, "{name}: {check:?}");
    }
    // The drift measure can fail: a tolerance below the achieved drift does.
    let strict = checks::drift(&sys, &states, None, 1e-18, &ctx, CheckKind::Drift);
    assert!(!strict[0].1.passed);
}

#[test]
fn free_rod_reaches_the_floor_event() {
    let params = common::paper::free_after(0.1677, -1.4, -0.01, -0.2);
    let sys = System::new(&FREE_ROD, &params).unwrap();
    let mesh = TimeMesh::build(&sys, sys.delta_to_floor(), 1e-14, &mut Work::default()).unwrap();
    let run = integrate(&sys, 1e-12, None, 1.0, &mut Work::default()).unwrap();
    assert_eq!(run.end, EndEvent::Floor);
    assert!(((run.t_end - mesh.duration) / mesh.duration).abs() < 1e-9);
    assert!(run.state_end.q[1].abs() < 1e-12);
}

/// The unreduced equations as the integrator sees them, written here from the public API: the
/// deviation `z = y - y0` from the release state, the contact force as the event.
struct Unreduced<'a> {
    sys: &'a System<'a>,
    y0: Vec<f64>,
    evals: u64,
}

impl Unreduced<'_> {
    fn state(&self, z: &[f64]) -> State {
        let n = self.y0.len() / 2;
        let y: Vec<f64> = z.iter().zip(&self.y0).map(|(z, y0)| y0 + z).collect();
        State {
            q: y[..n].to_vec(),
            qd: y[n..].to_vec(),
        }
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
        dz[..n].copy_from_slice(&state.qd);
        dz[n..].copy_from_slice(&accelerations(self.sys, &state, t)?);
        Ok(())
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&mut self, _t: f64, z: &[f64], dz: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        let n = self.y0.len() / 2;
        let contact = self.sys.info().contact.map_or(0, |c| c.force);
        g[0] = self.sys.forces_full(&self.state(z), &dz[n..], &[])[contact];
        Ok(())
    }
}

/// Both integrators on the rod and cube to separation, against the quadrature's time; prints
/// the counts behind [`Method::CROSSOVER_RTOL`]'s choice.
#[test]
fn both_integrators_find_the_separation() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    let (t_quad, _) = quadrature_separation(&sys);
    let start = sys.initial_state();
    let y0 = [start.q.clone(), start.qd.clone()].concat();
    for rtol in [
        1e-6, 1e-8, 1e-9, 1e-10, 5e-11, 3e-11, 2e-11, 1e-11, 1e-12, 1e-13,
    ] {
        let opts = OdeOptions {
            rtol,
            atol: Vec::new(),
            t_max: 1.0,
            max_steps: 200_000,
        };
        let mut evals = [0; 2];
        for (e, method) in evals.iter_mut().zip([Method::Dopri5, Method::Dop853]) {
            let mut problem = Unreduced {
                sys: &sys,
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
