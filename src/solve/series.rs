//! Samples of a phase at uniform times. On the fast path `theta(t)` comes from inverting the
//! quadrature `t(v)` (the variable `v` of [`quadrature`](crate::solve::fast::quadrature); the
//! inversion is [`inversion`](crate::solve::fast::inversion)'s); on the integrated route from the
//! integrator's dense output.
//!
//! The first-order form of the energy integral (the paper's eq. 17,
//! `theta_dot = -sqrt(theta_dot^2(theta))`) is not integrated: released from rest it also has
//! the solution `theta == theta_i`, and a step-by-step solver may follow it. Instead each sample
//! time `T` is matched by safeguarded Newton on `v`, `t(v) = T`, with `dt/dv` the quadrature
//! integrand itself; `t(v)` is smooth in `v`, so Newton converges quadratically.

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::fast::inversion::invert;
pub use crate::solve::fast::inversion::{delta_at_time, theta_dot_at};
use crate::solve::fast::quadrature::TimeMesh;
use crate::solve::phases::{IntegratedRun, PhaseRun};
use crate::system::{Bound, State, System};

/// Samples of one phase, uniform in time from its start to its end (both included).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PhaseSamples {
    /// Time from the phase start (s).
    pub t: Vec<f64>,
    /// Angle fallen, `theta_i - theta` (rad); on the fast path only (empty when integrated).
    pub delta: Vec<f64>,
    /// `theta` (rad).
    pub theta: Vec<f64>,
    /// `theta_dot` (rad/s, negative while falling).
    pub theta_dot: Vec<f64>,
    /// `theta_ddot` (rad/s^2).
    pub theta_ddot: Vec<f64>,
    /// The full state at each sample.
    pub states: Vec<State>,
}

impl PhaseSamples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

/// `samples` points uniform in time over the phase described by `mesh`.
pub fn sample_phase(
    sys: &System,
    mesh: &TimeMesh,
    samples: usize,
    work: &mut Work,
) -> Result<PhaseSamples, SolveError> {
    sample_reduced_at(sys, mesh, &uniform_times(mesh.duration, samples)?, work)
}

/// `samples` times uniform over `[0, duration]`, both ends included (the last exactly
/// `duration`).
pub fn uniform_times(duration: f64, samples: usize) -> Result<Vec<f64>, SolveError> {
    if samples < 2 {
        return Err(SolveError::TooFewSamples { samples });
    }
    Ok((0..samples)
        .map(|j| {
            if j == samples - 1 {
                duration
            } else {
                duration * j as f64 / (samples - 1) as f64
            }
        })
        .collect())
}

/// Samples of a fast phase at the phase times `times` (ascending, within the phase).
pub fn sample_reduced_at(
    sys: &System,
    mesh: &TimeMesh,
    times: &[f64],
    work: &mut Work,
) -> Result<PhaseSamples, SolveError> {
    let mut out = PhaseSamples::default();
    let (mut v_prev, mut t_prev) = (0.0, 0.0);
    for &target in times {
        let delta = if target <= 0.0 {
            0.0
        } else if target >= mesh.duration {
            mesh.delta_end
        } else {
            let lo = if target >= t_prev {
                (v_prev, t_prev)
            } else {
                (0.0, 0.0)
            };
            let v = invert(sys, mesh, target, lo.0, lo.1, work)?;
            v_prev = v;
            t_prev = target;
            mesh.delta_at_v(sys, v)?
        };
        push(sys, &mut out, target.clamp(0.0, mesh.duration), delta)?;
    }
    Ok(out)
}

fn push(sys: &System, out: &mut PhaseSamples, t: f64, delta: f64) -> Result<(), SolveError> {
    let reduced = sys.reduced(delta)?;
    let theta_dot = theta_dot_at(sys, delta);
    let state = sys.full_state(t, delta, theta_dot)?;
    out.t.push(t);
    out.delta.push(delta);
    out.theta.push(sys.theta_initial() - delta);
    out.theta_dot.push(theta_dot);
    out.theta_ddot.push(reduced.theta_ddot);
    out.states.push(state);
    Ok(())
}

/// `samples` points uniform in time over a phase on either route.
pub fn sample(run: &PhaseRun, samples: usize, work: &mut Work) -> Result<PhaseSamples, SolveError> {
    sample_at(run, &uniform_times(run.duration(), samples)?, work)
}

/// Samples of a phase on either route at the phase times `times` (ascending, within it).
pub fn sample_at(
    run: &PhaseRun,
    times: &[f64],
    work: &mut Work,
) -> Result<PhaseSamples, SolveError> {
    match run {
        PhaseRun::Reduced(r) => sample_reduced_at(&r.system, &r.mesh, times, work),
        PhaseRun::Integrated(r) => sample_integrated_at(r, times),
    }
}

/// The system's state (the general model's coordinates, positions and velocities) at the
/// phase time `t` of `run` (within it), and the work done by friction from release to then
/// (J): what a motion taken up there starts from ([`crate::solve::phases::Walker::resume`]).
pub fn full_state_at(run: &PhaseRun, t: f64, work: &mut Work) -> Result<(State, f64), SolveError> {
    let samples = sample_at(run, &[t], work)?;
    let state = samples.states.first().ok_or(SolveError::Inversion {
        target: t,
        duration: run.duration(),
        reason: "the phase gave no sample",
    })?;
    let full = run.bound().to_full(state)?;
    let friction_work = match run {
        // No friction acts on the fast path.
        PhaseRun::Reduced(_) => 0.0,
        PhaseRun::Integrated(r) if t < r.run.t_end => {
            let n = r.bound.n_coordinates();
            let y = r.run.state_at(t).ok_or(SolveError::Inversion {
                target: t,
                duration: r.run.t_end,
                reason: "time outside the integrated phase",
            })?;
            // The work is integrated (the last component) only where friction acts; without
            // it the run's is zero.
            match y.get(2 * n) {
                Some(w) => *w,
                None => r.run.friction_work,
            }
        }
        PhaseRun::Integrated(r) => r.run.friction_work,
    };
    Ok((full, friction_work))
}

/// `samples` points uniform in time over an integrated phase, from its dense output (the last
/// one is the event state itself).
pub fn sample_integrated(run: &IntegratedRun, samples: usize) -> Result<PhaseSamples, SolveError> {
    sample_integrated_at(run, &uniform_times(run.run.t_end, samples)?)
}

/// Samples of an integrated phase at the phase times `times`, from its dense output (a time
/// at the end is the event state itself).
pub fn sample_integrated_at(
    run: &IntegratedRun,
    times: &[f64],
) -> Result<PhaseSamples, SolveError> {
    let bound = &run.bound;
    let n = bound.n_coordinates();
    // The reduced coordinate's samples, where the system has one (empty otherwise).
    let r = bound.info().reduced_index;
    let duration = run.run.t_end;
    let mut out = PhaseSamples::default();
    for &t in times {
        let state = if t >= duration {
            run.run.state_end.clone()
        } else {
            let y = run.run.state_at(t).ok_or(SolveError::Inversion {
                target: t,
                duration,
                reason: "time outside the integrated phase",
            })?;
            State {
                q: y[..n].to_vec(),
                qd: y[n..2 * n].to_vec(),
            }
        };
        let t = t.min(duration);
        let qdd = run.run.dynamics_at(bound, &state, t)?.qdd;
        out.t.push(t);
        if let Some(r) = r {
            out.theta.push(state.q[r]);
            out.theta_dot.push(state.qd[r]);
            out.theta_ddot.push(qdd[r]);
        }
        out.states.push(state);
    }
    Ok(out)
}

/// Every contact's force at every sample of a phase: from the energy integral on the fast path
/// (its cancellation-free forms), solved with the accelerations otherwise.
pub fn sample_forces(run: &PhaseRun, s: &PhaseSamples) -> Result<Vec<Vec<f64>>, SolveError> {
    match run {
        PhaseRun::Reduced(r) => (s.delta.iter()).map(|&d| Ok(r.system.forces(d)?)).collect(),
        PhaseRun::Integrated(r) => s
            .states
            .iter()
            .zip(&s.t)
            .map(|(state, &t)| Ok(r.run.dynamics_at(&r.bound, state, t)?.forces))
            .collect(),
    }
}

/// The friction forces, their normal forces and slip velocities at every sample of a phase
/// (`[f, N, v]`, each one value per friction of the system's general model `general`), in the
/// active set of the sample's time. No friction acts in a fast phase (a contact with friction
/// is never held closed by elimination): its forces are zero there and its slip is read off the
/// general model at the system's state.
pub fn sample_friction(
    run: &PhaseRun,
    general: &Bound,
    s: &PhaseSamples,
) -> Result<Vec<[Vec<f64>; 3]>, SolveError> {
    let info = general.info();
    let nf = info.frictions.len();
    match run {
        PhaseRun::Reduced(r) => (s.states.iter().zip(&s.delta))
            .map(|(state, &delta)| {
                let full = r.system.to_full(state)?;
                let n = general.n_coordinates();
                let (jac, _) = general.friction(&full)?;
                let slip = (0..nf)
                    .map(|j| (0..n).map(|c| jac[j * n + c] * full.qd[c]).sum())
                    .collect();
                let forces = r.system.forces(delta)?;
                let normals = (info.frictions.iter())
                    .map(|f| {
                        forces.get(f.contact_index).copied().ok_or_else(|| {
                            SolveError::PhaseMismatch {
                                system: info.name,
                                name: r.system.name(),
                                why: format!(
                                    "it has {} contacts, the system {}",
                                    forces.len(),
                                    info.contacts.len()
                                ),
                            }
                        })
                    })
                    .collect::<Result<_, _>>()?;
                Ok([vec![0.0; nf], normals, slip])
            })
            .collect(),
        PhaseRun::Integrated(r) => s
            .states
            .iter()
            .zip(&s.t)
            .map(|(state, &t)| {
                let d = r.run.dynamics_at(&r.bound, state, t)?;
                let normals = info
                    .frictions
                    .iter()
                    .map(|f| d.forces[f.contact_index])
                    .collect();
                Ok([d.fr, normals, d.slip])
            })
            .collect(),
    }
}
