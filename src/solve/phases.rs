//! Phases of the motion: one model from its start until its contact ends (the force reaching
//! zero, or the contact running off an edge) or the rod reaches the floor, and the chain to the
//! next model (the same spec with the contact's coordinate free) down to the floor.
//!
//! A phase is solved on one of two routes. A model with a fast path ([`System`]) is solved by
//! the separation root and the time quadrature of its energy integral; any other model
//! ([`Bound`]) by integrating `M(q) qdd = F(q, qd)` with event location on the contact force,
//! the contact's edge and the floor ([`unreduced::integrate`]).
//!
//! A next phase gets its parameters from [`NextPhase::bindings`](crate::model::NextPhase): a
//! parameter of this model, a coordinate or velocity at the end of the phase, or the value and
//! rate of the coordinate the contact tied ([`Model::released`]).
//! Its clock restarts at zero; the absolute time of its start is kept in [`PhaseRun::t_start`].

use crate::model::{Binding, Model};
use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::friction::{self, Mode};
use crate::solve::quadrature::TimeMesh;
use crate::solve::separation::{Separation, SeparationOutcome, edge, separation};
use crate::solve::series::theta_dot_at;
use crate::solve::unreduced::{self, EndEvent, UnreducedRun};
use crate::system::{Bound, State, System};

/// Most phases chained before giving up.
pub const MAX_PHASES: usize = 8;

/// An integrated phase that has not reached an event after this many free-fall times of its
/// falling point is reported as [`SolveError::NoEvent`]. Generous: a light rod that pushes a
/// cube a million times heavier from nearly upright (a stuck foot makes it the hinged rod)
/// takes some ten thousand.
pub const MAX_FALL_TIMES: f64 = 1e5;

/// Which route solves a phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Route {
    /// The fast path where the model has one, integration otherwise.
    #[default]
    Fastest,
    /// Integration of `M(q) qdd = F` for every phase, fast path or not (to compare the routes).
    Integrated,
}

/// Why a phase ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// The contact force reached zero: the bodies separate.
    Separation,
    /// The contact ran off an edge of a body.
    Edge,
    /// The reduced angle reached the model's end angle (the rod lies on the floor).
    Floor,
}

impl End {
    /// `"force"`, `"edge"` or `"floor"`.
    pub fn name(self) -> &'static str {
        match self {
            End::Separation => "force",
            End::Edge => "edge",
            End::Floor => "floor",
        }
    }
}

/// Where a phase on the fast path ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedEnd {
    /// Why: the contact force's zero, the contact's edge, or the floor.
    pub end: End,
    /// The angle where the contact ends (`None` at the floor).
    pub at: Option<Separation>,
    /// The angle fallen at the end.
    pub delta: f64,
}

/// Where a phase on the fast path ends: the first of its separation and its contact's edge,
/// else the floor.
pub fn phase_end(sys: &System, work: &mut Work) -> Result<ReducedEnd, SolveError> {
    let Some(contact) = sys.info().contact else {
        return Ok(ReducedEnd {
            end: End::Floor,
            at: None,
            delta: sys.delta_to_floor(),
        });
    };
    let mut found: Option<(End, Separation)> = None;
    if let SeparationOutcome::Separates(s) = separation(sys, work)? {
        found = Some((End::Separation, s));
    }
    if contact.edge
        && let SeparationOutcome::Separates(e) = edge(sys, work)?
        && found.is_none_or(|(_, s)| e.delta < s.delta)
    {
        found = Some((End::Edge, e));
    }
    Ok(match found {
        Some((end, at)) => ReducedEnd {
            end,
            at: Some(at),
            delta: at.delta,
        },
        None => ReducedEnd {
            end: End::Floor,
            at: None,
            delta: sys.delta_to_floor(),
        },
    })
}

/// A phase solved on the fast path.
#[derive(Debug, Clone)]
pub struct ReducedRun<'m> {
    /// The model and its parameters for this phase.
    pub system: System<'m>,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
    /// Where and why it ends.
    pub end: ReducedEnd,
    /// `t(delta)` over the phase.
    pub mesh: TimeMesh,
}

impl<'m> ReducedRun<'m> {
    /// Solves the phase when its end is already known.
    pub fn with_end(
        sys: System<'m>,
        t_start: f64,
        end: ReducedEnd,
        tol: f64,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        let mesh = TimeMesh::build(&sys, end.delta, tol, work)?;
        work.phases.push(sys.name().to_string());
        Ok(ReducedRun {
            system: sys,
            t_start,
            end,
            mesh,
        })
    }

    /// The separation that ends it, if its contact force reached zero.
    pub fn separation(&self) -> Option<Separation> {
        match self.end.end {
            End::Separation => self.end.at,
            _ => None,
        }
    }

    /// `theta_dot` at the end of the phase (rad/s).
    pub fn theta_dot_end(&self) -> f64 {
        theta_dot_at(&self.system, self.mesh.delta_end)
    }

    /// This run as a phase of the motion.
    pub fn into_phase(self) -> PhaseRun<'m> {
        PhaseRun::Reduced(self)
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

/// A phase solved by integrating its equations of motion.
#[derive(Debug, Clone)]
pub struct IntegratedRun<'m> {
    /// The model and its parameters for this phase.
    pub bound: Bound<'m>,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
    /// The integration, ended by its event.
    pub run: UnreducedRun,
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
    /// Solves a phase starting at absolute time `t_start` to its end, on the fast path when the
    /// model has one (and `route` allows it). `rtol` is the integrator's tolerance on the other
    /// route.
    pub fn solve(
        bound: Bound<'m>,
        t_start: f64,
        tol: f64,
        rtol: f64,
        route: Route,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        if route == Route::Fastest && bound.model().reduction().is_some() {
            let sys = System::reduce(bound)?;
            let end = phase_end(&sys, work)?;
            let run = ReducedRun::with_end(sys, t_start, end, tol, work)?;
            return Ok(PhaseRun::Reduced(run));
        }
        let time = fall_time_scale(&bound);
        let scales = motion_scales(&bound, time)?;
        let run = unreduced::integrate(&bound, rtol, Some(&scales), time * MAX_FALL_TIMES, work)?;
        if bound.info().frictions.is_empty() {
            work.phases.push(bound.name().to_string());
        } else {
            // One entry per stretch of constant contact modes: `rod_cube_friction (foot_friction sticks)`.
            for (_, modes) in run.switches(&bound) {
                work.phases.push(format!("{} ({modes})", bound.name()));
            }
        }
        Ok(PhaseRun::Integrated(IntegratedRun {
            bound,
            t_start,
            run,
        }))
    }

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
    pub fn end(&self) -> End {
        match self {
            PhaseRun::Reduced(r) => r.end.end,
            PhaseRun::Integrated(r) => match r.run.end {
                EndEvent::Separation => End::Separation,
                EndEvent::Edge => End::Edge,
                EndEvent::Floor => End::Floor,
            },
        }
    }

    /// The full state at the end of the phase.
    pub fn end_state(&self) -> State {
        match self {
            PhaseRun::Reduced(r) => r.end_state(),
            PhaseRun::Integrated(r) => r.run.state_end.clone(),
        }
    }

    /// The reduced angle at the end of the phase (rad).
    pub fn theta_end(&self) -> f64 {
        self.end_state().q[self.bound().info().reduced]
    }

    /// `theta_dot` at the end of the phase (rad/s).
    pub fn theta_dot_end(&self) -> f64 {
        match self {
            PhaseRun::Reduced(r) => r.theta_dot_end(),
            PhaseRun::Integrated(r) => r.run.state_end.qd[r.bound.info().reduced],
        }
    }

    /// Work done by friction over the phase (J, `<= 0`; zero without friction).
    pub fn friction_work(&self) -> f64 {
        match self {
            PhaseRun::Reduced(_) => 0.0,
            PhaseRun::Integrated(r) => r.run.friction_work,
        }
    }

    /// The friction contacts' modes over the phase: each stretch's start (s from release) and
    /// its modes (`foot_friction sticks`); empty without friction.
    pub fn contact_modes(&self) -> Vec<(f64, String)> {
        match self {
            PhaseRun::Integrated(r) if !r.bound.info().frictions.is_empty() => (r.run)
                .switches(&r.bound)
                .map(|(t, modes)| (r.t_start + t, modes))
                .collect(),
            _ => Vec::new(),
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

/// `sqrt(2 h / g)` for the initial height `h` of the falling point (`sqrt(2 m / g)` when it
/// starts on the floor): the time scale of the motion.
fn fall_time_scale(bound: &Bound) -> f64 {
    let info = bound.info();
    let h = bound.points(&bound.initial_state()).pos[info.falling_point][1];
    let h = if h > 0.0 { h } else { 1.0 };
    (2.0 * h / bound.gravity()).sqrt()
}

/// Typical sizes of the motion's deviation from the release state over the time scale `time`,
/// for the integrator's absolute tolerances: `|qd0| T + |qdd0| T^2 / 2` for the coordinates and
/// `|qd0| + |qdd0| T` for the velocities, each at least `1e-8` of the largest of its kind, so
/// that a tiny system (a rod of 1 cm nearly flat) is held to its own scale, not to one metre.
fn motion_scales(bound: &Bound, time: f64) -> Result<Vec<f64>, SolveError> {
    let start = bound.initial_state();
    let mut qdd = unreduced::start_dynamics(bound)?.qdd;
    // A stuck contact's coordinate has no acceleration at the start but may slide later: its
    // scale is the one it would have sliding (else rounding noise in the stuck phase sets the
    // step size).
    let m = bound.info().frictions.len();
    if m > 0
        && let Ok(sliding) = friction::dynamics(bound, &start, &vec![Mode::Slide(1.0); m], 0.0)
    {
        for (a, s) in qdd.iter_mut().zip(&sliding.qdd) {
            *a = a.abs().max(s.abs());
        }
    }
    let q: Vec<f64> = (start.qd.iter().zip(&qdd))
        .map(|(v, a)| v.abs() * time + 0.5 * a.abs() * time * time)
        .collect();
    let v: Vec<f64> = (start.qd.iter().zip(&qdd))
        .map(|(v, a)| v.abs() + a.abs() * time)
        .collect();
    let floor = |x: Vec<f64>| {
        let top = x.iter().cloned().fold(0.0, f64::max);
        x.into_iter()
            .map(|s| s.max(1e-8 * top).max(f64::MIN_POSITIVE))
            .collect::<Vec<f64>>()
    };
    let mut scales = floor(q);
    scales.extend(floor(v));
    Ok(scales)
}

/// The bound model of the phase after `run`, from the registry: only after a separation (the
/// motion after a contact runs off an edge is not modelled).
pub fn next_bound<'m>(
    run: &PhaseRun<'m>,
    registry: &[&'m dyn Model],
) -> Result<Option<Bound<'m>>, SolveError> {
    let bound = run.bound();
    let info = bound.info();
    let Some(next) = info.next_phase else {
        return Ok(None);
    };
    if run.end() != End::Separation {
        return Ok(None);
    }
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
    let released = bound.released(&end);
    let p = bound.p();
    let values = next
        .bindings
        .iter()
        .map(|b| match *b {
            Binding::Param(i) => p.get(i).copied(),
            Binding::Coordinate(i) => end.q.get(i).copied(),
            Binding::Velocity(i) => end.qd.get(i).copied(),
            Binding::Eliminated => released.map(|r| r[0]),
            Binding::EliminatedRate => released.map(|r| r[1]),
        })
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(bad)?;
    Ok(Some(Bound::from_values(model, &values)?))
}

/// The whole motion from release to the floor, phase after phase.
#[derive(Debug, Clone)]
pub struct Motion<'m> {
    /// The phases in order; the last one reaches the floor (or ends at an edge).
    pub phases: Vec<PhaseRun<'m>>,
}

impl<'m> Motion<'m> {
    /// A motion made of its first phase.
    pub fn new(first: PhaseRun<'m>) -> Self {
        Motion {
            phases: vec![first],
        }
    }

    /// Absolute time the last phase ends (s): the rod on the floor, unless it ended at an edge.
    pub fn floor_time(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::t_end)
    }

    /// `theta_dot` at the end of the last phase (rad/s).
    pub fn impact_angular_velocity(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::theta_dot_end)
    }

    /// Why the last phase ended.
    pub fn last_end(&self) -> Option<End> {
        self.phases.last().map(PhaseRun::end)
    }
}

/// Continues the motion from its last phase through every next phase to the floor.
pub fn extend_to_floor<'m>(
    motion: &mut Motion<'m>,
    registry: &[&'m dyn Model],
    tol: f64,
    rtol: f64,
    route: Route,
    work: &mut Work,
) -> Result<(), SolveError> {
    loop {
        let last = &motion.phases[motion.phases.len() - 1];
        let Some(next) = next_bound(last, registry)? else {
            return Ok(());
        };
        if motion.phases.len() >= MAX_PHASES {
            return Err(SolveError::TooManyPhases { limit: MAX_PHASES });
        }
        let t_start = last.t_end();
        let run = PhaseRun::solve(next, t_start, tol, rtol, route, work)?;
        motion.phases.push(run);
    }
}
