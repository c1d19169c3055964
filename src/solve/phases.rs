//! Phases of the motion: one model from its start to separation (or the floor), and the chain
//! to the next model (e.g. the free rod after it leaves the cube) down to the floor.
//!
//! A next phase gets its parameters from [`NextPhase::bindings`](crate::model::NextPhase): a
//! parameter of this model, or a coordinate or velocity of the full state at separation
//! ([`Model::full_state`]). Its clock restarts at zero; the
//! absolute time of its start is kept in [`PhaseRun::t_start`].

use crate::model::{Binding, Model};
use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::quadrature::TimeMesh;
use crate::solve::separation::{Separation, SeparationOutcome, separation};
use crate::solve::series::theta_dot_at;
use crate::system::{State, System};

/// Most phases chained before giving up.
pub const MAX_PHASES: usize = 8;

/// Where a phase ends: its separation if it has a contact that lets go, else the floor.
pub fn phase_end(sys: &System, work: &mut Work) -> Result<(Option<Separation>, f64), SolveError> {
    if sys.info().contact.is_some()
        && let SeparationOutcome::Separates(s) = separation(sys, work)?
    {
        return Ok((Some(s), s.delta));
    }
    Ok((None, sys.delta_to_floor()))
}

/// One phase solved to its end.
#[derive(Debug, Clone)]
pub struct PhaseRun<'m> {
    /// The model and its parameters for this phase.
    pub system: System<'m>,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
    /// The separation that ends it, or `None` when it reaches the floor.
    pub separation: Option<Separation>,
    /// `t(delta)` over the phase.
    pub mesh: TimeMesh,
}

impl<'m> PhaseRun<'m> {
    /// Solves the phase of `sys` starting at absolute time `t_start` to its end.
    pub fn solve(
        sys: System<'m>,
        t_start: f64,
        tol: f64,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        let (separation, delta_end) = phase_end(&sys, work)?;
        Self::with_end(sys, t_start, separation, delta_end, tol, work)
    }

    /// Solves the phase when its end is already known.
    pub fn with_end(
        sys: System<'m>,
        t_start: f64,
        separation: Option<Separation>,
        delta_end: f64,
        tol: f64,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        let mesh = TimeMesh::build(&sys, delta_end, tol, work)?;
        work.phases.push(sys.name().to_string());
        Ok(PhaseRun {
            system: sys,
            t_start,
            separation,
            mesh,
        })
    }

    /// Phase duration (s).
    pub fn duration(&self) -> f64 {
        self.mesh.duration
    }

    /// Absolute end time (s from release).
    pub fn t_end(&self) -> f64 {
        self.t_start + self.mesh.duration
    }

    /// `theta_dot` at the end of the phase (rad/s).
    pub fn theta_dot_end(&self) -> f64 {
        theta_dot_at(&self.system, self.mesh.delta_end)
    }

    /// The full state at the end of the phase.
    pub fn end_state(&self) -> State {
        self.system.full_state(
            self.mesh.duration,
            self.mesh.delta_end,
            self.theta_dot_end(),
        )
    }
}

/// What the pushed surface does after a separation, for the no-recatch check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Absolute time of the separation (s).
    pub t: f64,
    /// Position of the surface point at separation.
    pub surface_pos: [f64; 2],
    /// Its velocity (zero for a fixed surface); it keeps it afterwards.
    pub surface_vel: [f64; 2],
    /// Unit normal from the pusher into the pushed body.
    pub normal: [f64; 2],
    /// Name of the pushing point (looked up by name in the next phase).
    pub point: &'static str,
    /// Name of the surface point.
    pub surface: &'static str,
}

impl Transition {
    /// Speed of the pushed surface along the normal after separation (m/s).
    pub fn surface_speed(&self) -> f64 {
        self.normal[0] * self.surface_vel[0] + self.normal[1] * self.surface_vel[1]
    }

    /// Gap between the surface (moving on at its separation velocity) and a point at absolute
    /// time `t`, along the normal; positive while apart.
    pub fn gap(&self, t: f64, point: [f64; 2]) -> f64 {
        let dt = t - self.t;
        let s = [
            self.surface_pos[0] + self.surface_vel[0] * dt,
            self.surface_pos[1] + self.surface_vel[1] * dt,
        ];
        self.normal[0] * (s[0] - point[0]) + self.normal[1] * (s[1] - point[1])
    }
}

/// The pushed surface at the end of a phase that separated.
pub fn transition(run: &PhaseRun) -> Option<Transition> {
    let info = run.system.info();
    let contact = info.contact?;
    run.separation?;
    let pts = run.system.points(&run.end_state());
    let vel = if contact.surface_moves {
        pts.vel[contact.surface]
    } else {
        [0.0; 2]
    };
    Some(Transition {
        t: run.t_end(),
        surface_pos: pts.pos[contact.surface],
        surface_vel: vel,
        normal: contact.normal,
        point: info.points[contact.point].name,
        surface: info.points[contact.surface].name,
    })
}

/// The system of the phase after `run` (which must have separated), from the registry.
pub fn next_system<'m>(
    run: &PhaseRun<'m>,
    registry: &[&'m dyn Model],
) -> Result<Option<System<'m>>, SolveError> {
    let info = run.system.info();
    let (Some(next), Some(_)) = (info.next_phase, run.separation) else {
        return Ok(None);
    };
    let Some(model) = registry
        .iter()
        .copied()
        .find(|m| m.info().name == next.model)
    else {
        return Err(SolveError::UnknownNextModel {
            from: info.name,
            name: next.model,
        });
    };
    let expected = model.info().parameters.len();
    let bad = || SolveError::BadBindings {
        from: info.name,
        name: next.model,
        expected,
        got: next.bindings.len(),
    };
    if next.bindings.len() != expected {
        return Err(bad());
    }
    let end = run.end_state();
    let pts = run.system.points(&end);
    let p = run.system.p();
    let values = next
        .bindings
        .iter()
        .map(|b| match *b {
            Binding::Param(i) => p.get(i).copied(),
            Binding::Coordinate(i) => end.q.get(i).copied(),
            Binding::Velocity(i) => end.qd.get(i).copied(),
            Binding::Point { index, axis } => pts.pos.get(index).and_then(|v| v.get(axis)).copied(),
            Binding::PointVelocity { index, axis } => {
                pts.vel.get(index).and_then(|v| v.get(axis)).copied()
            }
        })
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(bad)?;
    Ok(Some(System::from_values(model, &values)?))
}

/// The whole motion from release to the floor, phase after phase.
#[derive(Debug, Clone)]
pub struct Motion<'m> {
    /// The phases in order; the last one reaches the floor.
    pub phases: Vec<PhaseRun<'m>>,
    /// One per separation followed by a next phase (`transitions[i]` ends `phases[i]`).
    pub transitions: Vec<Transition>,
}

impl<'m> Motion<'m> {
    /// A motion made of its first phase.
    pub fn new(first: PhaseRun<'m>) -> Self {
        Motion {
            phases: vec![first],
            transitions: Vec::new(),
        }
    }

    /// Absolute time the rod reaches the floor (s).
    pub fn floor_time(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::t_end)
    }

    /// `theta_dot` when the rod reaches the floor (rad/s).
    pub fn impact_angular_velocity(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::theta_dot_end)
    }
}

/// Continues the motion from its last phase through every next phase to the floor.
pub fn extend_to_floor<'m>(
    motion: &mut Motion<'m>,
    registry: &[&'m dyn Model],
    tol: f64,
    work: &mut Work,
) -> Result<(), SolveError> {
    loop {
        let last = &motion.phases[motion.phases.len() - 1];
        let Some(transition) = transition(last) else {
            return Ok(());
        };
        let Some(next) = next_system(last, registry)? else {
            return Ok(());
        };
        if motion.phases.len() >= MAX_PHASES {
            return Err(SolveError::TooManyPhases { limit: MAX_PHASES });
        }
        if next.point_index(transition.point).is_none() {
            return Err(SolveError::MissingPoint {
                from: last.system.name(),
                name: next.name(),
                point: transition.point,
            });
        }
        let t_start = last.t_end();
        let run = PhaseRun::solve(next, t_start, tol, work)?;
        motion.transitions.push(transition);
        motion.phases.push(run);
    }
}
