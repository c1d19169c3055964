//! One phase of the motion on either route ([`PhaseRun`]): on the fast path ([`ReducedRun`]) or
//! integrated ([`IntegratedRun`]), and what both answer: times, end, end state, closed contacts.

use super::reduced::ReducedRun;
use crate::results::{ContactSet, EndCause};
use crate::solve::SolveError;
use crate::solve::integrated::contacts::Active;
use crate::solve::integrated::unreduced::UnreducedRun;
use crate::system::{Bound, State};

/// A phase solved by integrating the general model's equations.
#[derive(Debug, Clone)]
pub struct IntegratedRun<'m> {
    /// The general model and its parameters.
    pub bound: Bound<'m>,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
    /// The integration, ended by its event.
    pub run: UnreducedRun,
}

impl IntegratedRun<'_> {
    /// The refusal of a run that holds no segment, so no active set (the integrator ends every
    /// run it returns with one; only a run built by hand can lack it):
    /// [`SolveError::ActiveSize`], an active set of no contact and no friction.
    pub fn no_active_set(&self) -> SolveError {
        let info = self.bound.info();
        SolveError::ActiveSize {
            model: info.name,
            contacts: info.contacts.len(),
            frictions: info.frictions.len(),
            closed: 0,
            modes: 0,
        }
    }
}

/// One phase of the motion on either route.
#[derive(Debug, Clone)]
pub enum PhaseRun<'m> {
    /// On the fast path.
    Reduced(ReducedRun<'m>),
    /// Integrated.
    Integrated(IntegratedRun<'m>),
}

impl<'m> PhaseRun<'m> {
    /// The model and its parameters.
    pub fn bound(&self) -> &Bound<'m> {
        match self {
            PhaseRun::Reduced(r) => r.system.bound(),
            PhaseRun::Integrated(r) => &r.bound,
        }
    }

    /// Absolute time of the phase start (s from release).
    pub fn t_start(&self) -> f64 {
        match self {
            PhaseRun::Reduced(r) => r.t_start,
            PhaseRun::Integrated(r) => r.t_start,
        }
    }

    /// Phase duration (s).
    pub fn duration(&self) -> f64 {
        match self {
            PhaseRun::Reduced(r) => r.mesh.duration,
            PhaseRun::Integrated(r) => r.run.t_end,
        }
    }

    /// Absolute end time (s from release).
    pub fn t_end(&self) -> f64 {
        self.t_start() + self.duration()
    }

    /// Why the phase ended.
    pub fn end(&self) -> EndCause {
        match self {
            PhaseRun::Reduced(r) => r.end.end,
            PhaseRun::Integrated(r) => r.run.end,
        }
    }

    /// The state at the end of the phase, in its model's coordinates.
    pub fn end_state(&self) -> Result<State, SolveError> {
        match self {
            PhaseRun::Reduced(r) => r.end_state(),
            PhaseRun::Integrated(r) => Ok(r.run.state_end.clone()),
        }
    }

    /// The system's state at the end of the phase (the general model's coordinates).
    pub fn full_end_state(&self) -> Result<State, SolveError> {
        Ok(self.bound().to_full(&self.end_state()?)?)
    }

    /// The reduced angle at the end of the phase (rad): `theta_i - delta_end` on the fast path
    /// (the reduced coordinate of [`ReducedRun::end_state`]), the end state's otherwise.
    /// A system without a reduced coordinate has none: `SystemError::NoReducedCoordinate`.
    pub fn theta_end(&self) -> Result<f64, SolveError> {
        Ok(match self {
            PhaseRun::Reduced(r) => r.system.theta_initial() - r.mesh.delta_end,
            PhaseRun::Integrated(r) => r.run.state_end.q[r.bound.reduced()?.0],
        })
    }

    /// `theta_dot` at the end of the phase (rad/s); as [`PhaseRun::theta_end`] without a
    /// reduced coordinate.
    pub fn theta_dot_end(&self) -> Result<f64, SolveError> {
        Ok(match self {
            PhaseRun::Reduced(r) => r.theta_dot_end(),
            PhaseRun::Integrated(r) => r.run.state_end.qd[r.bound.reduced()?.0],
        })
    }

    /// Work done by friction from release to the end of the phase (J, `<= 0`; zero without
    /// friction).
    pub fn friction_work(&self) -> f64 {
        match self {
            PhaseRun::Reduced(_) => 0.0,
            PhaseRun::Integrated(r) => r.run.friction_work,
        }
    }

    /// The contacts closed during the phase (at its start; a friction switch changes only the
    /// modes). An integrated run without a segment has no active set
    /// ([`IntegratedRun::no_active_set`]).
    pub fn closed(&self) -> Result<Vec<bool>, SolveError> {
        match self {
            PhaseRun::Reduced(r) => Ok(r.system.info().contacts.iter().map(|c| c.closed).collect()),
            PhaseRun::Integrated(r) => (r.run.segments.first())
                .map(|s| s.active.closed.clone())
                .ok_or_else(|| r.no_active_set()),
        }
    }

    /// The contacts closed at the end of the phase (in the general model's order). An
    /// integrated run without a segment has no active set ([`IntegratedRun::no_active_set`]).
    pub fn closed_at_end(&self) -> Result<Vec<bool>, SolveError> {
        match self {
            PhaseRun::Reduced(r) => Ok(r.system.info().contacts.iter().map(|c| c.closed).collect()),
            PhaseRun::Integrated(r) => (r.run.segments.last())
                .map(|s| s.active.closed.clone())
                .ok_or_else(|| r.no_active_set()),
        }
    }

    /// The active sets over the phase: each stretch's start (s from release) and its closed
    /// contacts and friction modes.
    pub fn stretches(&self) -> Vec<(f64, ContactSet)> {
        match self {
            PhaseRun::Reduced(r) => {
                let info = r.system.info();
                vec![(r.t_start, Active::of_model(info).set(info))]
            }
            PhaseRun::Integrated(r) => (r.run)
                .switches(&r.bound)
                .map(|(t, modes)| (r.t_start + t, modes))
                .collect(),
        }
    }

    /// The phase as `work.phases` names it: its model, and for an integrated phase the closed
    /// contacts (and friction modes) of each stretch.
    pub fn labels(&self) -> Vec<String> {
        match self {
            PhaseRun::Reduced(r) => vec![r.system.name().to_string()],
            PhaseRun::Integrated(r) => (r.run)
                .switches(&r.bound)
                .map(|(_, modes)| format!("{} ({modes})", r.bound.name()))
                .collect(),
        }
    }

    /// The phase on the fast path, if it is on it.
    pub fn reduced(&self) -> Option<&ReducedRun<'m>> {
        match self {
            PhaseRun::Reduced(r) => Some(r),
            PhaseRun::Integrated(_) => None,
        }
    }
}

impl<'m> ReducedRun<'m> {
    /// This run as a phase of the motion.
    pub fn into_phase(self) -> PhaseRun<'m> {
        PhaseRun::Reduced(self)
    }
}
