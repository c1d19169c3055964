//! The unreduced equations `M(q) qdd = F(q, qd)` of a model as an ODE, integrated with
//! [`ode::dopri5`](crate::solve::ode::dopri5) from the release state until the contact force
//! crosses zero (separation), the contact runs off its edge, or the reduced angle reaches the
//! floor: the route of every model without a fast path, and for the others an independent
//! route to the separation time that shares no code with the quadrature.
//!
//! The integrator's state is the deviation `z = y - y0` from the release state `y0 = [q, qd]`,
//! so its error control is relative to the motion itself rather than to the absolute angle: a
//! near-upright start lingers by an unstable equilibrium, which amplifies any absolute angle
//! error. The model's equations still take the absolute angle, whose rounding (~1e-16 rad)
//! limits this route to ~1e-11 relative there.
//!
//! The mass matrix is ill-conditioned when the bodies' masses are far apart (for the rod and
//! cube its condition number grows like `m2/m1`): the accelerations then carry a relative
//! rounding error of about `eps * cond(M)`, and so does the contact force built from them. The
//! integrator's tolerance is therefore never set below [`CONDITION_SAFETY`]` * eps * cond(M)`
//! at release, and the tolerance actually used is reported in [`UnreducedRun::rtol`].

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::ode::{OdeOptions, OdeProblem, OdeSolution, dopri5};
use crate::system::{Bound, State};
use nalgebra::{DMatrix, DVector};

/// The tolerance floor is this many times `eps * cond(M)` at release.
pub const CONDITION_SAFETY: f64 = 10.0;

/// Loosest tolerance worth integrating with: beyond it the cross-check says nothing.
pub const MAX_RTOL: f64 = 1e-2;

/// Most steps before giving up.
pub const MAX_STEPS: u64 = 200_000;

/// The 2-norm condition number of the mass matrix at a state (infinite if singular).
pub fn mass_condition(sys: &Bound, state: &State) -> f64 {
    let n = sys.n_coordinates();
    let (mass, _) = sys.equations(state);
    let sv = DMatrix::from_row_slice(n, n, &mass).singular_values();
    let max = sv.iter().cloned().fold(0.0, f64::max);
    let min = sv.iter().cloned().fold(f64::INFINITY, f64::min);
    if min > 0.0 && max.is_finite() {
        max / min
    } else {
        f64::INFINITY
    }
}

/// Accelerations `qdd` solving `M(q) qdd = F(q, qd)` at a state (`t` labels errors).
pub fn accelerations(sys: &Bound, state: &State, t: f64) -> Result<Vec<f64>, SolveError> {
    let n = sys.n_coordinates();
    let (mass, rhs) = sys.equations(state);
    let m = DMatrix::from_row_slice(n, n, &mass);
    let b = DVector::from_column_slice(&rhs);
    match m.lu().solve(&b) {
        Some(x) if x.iter().all(|v| v.is_finite()) => Ok(x.iter().copied().collect()),
        _ => Err(SolveError::SingularMassMatrix {
            t,
            q: state.q.clone(),
        }),
    }
}

/// How the unreduced integration ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndEvent {
    /// The contact force crossed zero.
    Separation,
    /// The contact's edge margin crossed zero.
    Edge,
    /// The reduced angle reached the model's end angle.
    Floor,
}

/// A finished unreduced integration.
#[derive(Debug, Clone, PartialEq)]
pub struct UnreducedRun {
    /// The integration with dense output, of the deviation `z = y - y0` (see [`Self::state_at`]).
    pub solution: OdeSolution,
    /// The release state `y0 = [q, qd]`.
    pub y0: Vec<f64>,
    /// The relative tolerance used: the one asked, raised to the conditioning floor.
    pub rtol: f64,
    /// Condition number of the mass matrix at release.
    pub condition: f64,
    /// Which event ended it.
    pub end: EndEvent,
    /// Time of that event (s from release).
    pub t_end: f64,
    /// The state there.
    pub state_end: State,
}

impl UnreducedRun {
    /// `y = [q, qd]` at time `t` from dense output, if `t` lies in the integrated range.
    pub fn state_at(&self, t: f64) -> Option<Vec<f64>> {
        let z = self.solution.interpolate(t)?;
        Some(self.add_y0(&z))
    }

    /// Time and `y = [q, qd]` at the release and at the end of every accepted step.
    pub fn nodes(&self) -> Vec<(f64, Vec<f64>)> {
        self.solution
            .nodes()
            .into_iter()
            .map(|(t, z)| (t, self.add_y0(z)))
            .collect()
    }

    /// The full state at the release and at the end of every accepted step.
    pub fn states(&self) -> Vec<State> {
        let n = self.state_end.q.len();
        self.nodes()
            .into_iter()
            .map(|(_, y)| State {
                q: y[..n].to_vec(),
                qd: y[n..].to_vec(),
            })
            .collect()
    }

    /// Every step taken (accepted, rejected and event trials).
    pub fn steps(&self) -> u64 {
        self.solution.total_steps()
    }

    fn add_y0(&self, z: &[f64]) -> Vec<f64> {
        z.iter().zip(&self.y0).map(|(z, y0)| y0 + z).collect()
    }
}

struct Problem<'a, 'm> {
    sys: &'a Bound<'m>,
    n: usize,
    contact: Option<usize>,
    edge: bool,
    reduced: usize,
    end_angle: f64,
    y0: Vec<f64>,
    y: Vec<f64>,
    state: State,
}

impl Problem<'_, '_> {
    /// Sets `y = y0 + z` and the state from it.
    fn load(&mut self, z: &[f64]) {
        for ((y, y0), z) in self.y.iter_mut().zip(&self.y0).zip(z) {
            *y = y0 + z;
        }
        self.state.q.copy_from_slice(&self.y[..self.n]);
        self.state.qd.copy_from_slice(&self.y[self.n..]);
    }
}

impl OdeProblem for Problem<'_, '_> {
    fn dim(&self) -> usize {
        2 * self.n
    }

    fn rhs(&mut self, t: f64, z: &[f64], dz: &mut [f64]) -> Result<(), SolveError> {
        self.load(z);
        let qdd = accelerations(self.sys, &self.state, t)?;
        dz[..self.n].copy_from_slice(&self.state.qd);
        dz[self.n..].copy_from_slice(&qdd);
        Ok(())
    }

    fn n_events(&self) -> usize {
        1 + usize::from(self.contact.is_some()) + usize::from(self.edge)
    }

    /// Events in order: the contact force, the edge margin, the floor.
    fn events(&mut self, _t: f64, z: &[f64], dz: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        self.load(z);
        let mut i = 0;
        if let Some(c) = self.contact {
            g[i] = self.sys.forces_full(&self.state, &dz[self.n..])[c];
            i += 1;
        }
        if self.edge {
            g[i] = self.sys.contact_edge(&self.state);
            i += 1;
        }
        g[i] = self.state.q[self.reduced] - self.end_angle;
        Ok(())
    }
}

/// Integrates the unreduced equations of `sys` from its release state to separation (or the
/// floor) with relative tolerance `rtol`. `scales` (length `2 n`), when given, are typical
/// magnitudes of the motion `y - y0` (e.g. its size at the end of the reduced phase) used for
/// the absolute tolerances; without them the control is relative to the largest deviation
/// seen. `t_max` bounds the search. `rtol` is raised to [`CONDITION_SAFETY`]` * eps * cond(M)`.
pub fn integrate(
    sys: &Bound,
    rtol: f64,
    scales: Option<&[f64]>,
    t_max: f64,
    work: &mut Work,
) -> Result<UnreducedRun, SolveError> {
    let info = sys.info();
    let n = sys.n_coordinates();
    let start = sys.initial_state();
    let condition = mass_condition(sys, &start);
    let rtol = rtol.max(CONDITION_SAFETY * f64::EPSILON * condition);
    if rtol.is_nan() || rtol > MAX_RTOL {
        return Err(SolveError::IllConditioned {
            model: info.name,
            condition,
            rtol,
        });
    }
    let mut y0 = start.q.clone();
    y0.extend_from_slice(&start.qd);
    let mut problem = Problem {
        sys,
        n,
        contact: info.contact.map(|c| c.force),
        edge: info.contact.is_some_and(|c| c.edge),
        reduced: info.reduced,
        end_angle: info.end_angle,
        y0: y0.clone(),
        y: y0.clone(),
        state: start,
    };
    let atol = match scales {
        Some(s) if s.len() == 2 * n => s
            .iter()
            .map(|v| rtol * v.abs().max(f64::MIN_POSITIVE))
            .collect(),
        _ => Vec::new(),
    };
    let opts = OdeOptions {
        rtol,
        atol,
        t_max,
        max_steps: MAX_STEPS,
    };
    let solution = dopri5(&mut problem, 0.0, &vec![0.0; 2 * n], &opts)?;
    work.ode_steps += solution.total_steps();
    let Some(event) = solution.event.clone() else {
        return Err(SolveError::NoEvent { t_max });
    };
    let n_contact = usize::from(problem.contact.is_some());
    let end = if event.index < n_contact {
        EndEvent::Separation
    } else if problem.edge && event.index == n_contact {
        EndEvent::Edge
    } else {
        EndEvent::Floor
    };
    let mut run = UnreducedRun {
        solution,
        y0,
        rtol,
        condition,
        end,
        t_end: event.t,
        state_end: State {
            q: Vec::new(),
            qd: Vec::new(),
        },
    };
    let y = run.add_y0(&event.y);
    run.state_end = State {
        q: y[..n].to_vec(),
        qd: y[n..].to_vec(),
    };
    Ok(run)
}
