//! Phases of the motion of a system: at release, and after every event, the contacts that stay
//! closed are decided ([`contacts::decide`]); each stretch with one set of closed contacts is
//! a phase, solved on the fast path where the system has a fast phase for that set, otherwise
//! by integrating the general model with the closed contacts as constraints; the motion goes on
//! from phase to phase until the rod reaches the floor, a contact runs off an edge, or an open
//! contact closes (the bodies meet). Where the run is asked to go on to a time (`until`), a
//! contact that closes is an impact ([`impact::resolve`]): the velocities jump by the impulses
//! of Newton's law with complementarity, the contacts are decided again at the state after,
//! and the motion goes on to that time; bounces whose times converge (Zeno) are caught.
//!
//! A fast phase that starts from a given state takes it as parameters (`<q>_0`,
//! `<q>_dot_0`, bound from the system's state by coordinate name); the one that starts from
//! the spec's release state serves only at release. A phase's clock restarts at zero; the
//! absolute time of its start is kept in [`PhaseRun::t_start`].

use crate::model::{Model, ModelInfo};
use crate::results::{Halt, Work, Zeno};
use crate::solve::SolveError;
use crate::solve::contacts::{
    self, Active, ContactOption, DECIDE_TOLERANCE, FrictionOption, Moment, Options,
    contact_options, friction_options,
};
use crate::solve::impact::{self, Impact, Part};
use crate::solve::inversion::{delta_at_time, theta_dot_at};
use crate::solve::ode::Method;
use crate::solve::quadrature::TimeMesh;
use crate::solve::roots::{self, changes_sign};
use crate::solve::separation::{Separation, SeparationOutcome, edge, force_zero};
use crate::solve::unreduced::{self, Start, UnreducedRun, motion_scales};
use crate::system::{Bound, State, System};

/// Most phases chained between two impacts (or from release to the first) before giving up:
/// contacts that keep opening and closing without an impact are chatter, not a motion.
pub const MAX_PHASES: usize = 16;

/// Most impacts in one run. A run that reaches it stops there with a note (a bouncing sequence
/// that neither converges as Zeno's nor comes to rest).
pub const MAX_IMPACTS: usize = 1000;

/// Bounces at one contact whose intervals shrink by a steady ratio (the last
/// [`ZENO_RATIOS`] ratios below one and within this fraction of each other) converge: once the
/// time left to their limit, `dt r / (1 - r)`, is within the run's tolerance of the time from
/// release, the rest of them is taken as one plastic impact.
pub const ZENO_RATIO_SPREAD: f64 = 0.1;

/// How many successive interval ratios must agree before bounces count as converging.
pub const ZENO_RATIOS: usize = 3;

/// An integrated phase that has not reached an event after this many free-fall times of its
/// falling point is reported as [`SolveError::NoEvent`]. Generous: a light rod that pushes a
/// cube a million times heavier from nearly upright (a stuck foot makes it the hinged rod)
/// takes some ten thousand.
pub const MAX_FALL_TIMES: f64 = 1e5;

/// How far (relative to the system's length) the falling point may be from the floor where
/// the reduced angle reaches its end angle, and still count as landed.
pub const LANDING_TOLERANCE: f64 = 1e-9;

/// Cells of the grid, uniform in the fast path's time variable, on which an open contact's gap
/// is watched for closing (the first cell whose ends differ in sign; a touch without a crossing
/// inside one cell is not seen).
pub const GAP_CELLS: usize = 64;

/// Which route solves a phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Route {
    /// The fast path where the system has one for the phase, integration otherwise.
    #[default]
    Fastest,
    /// Integration of the general model for every phase (to compare the routes).
    Integrated,
}

pub use crate::solve::unreduced::End;

/// Where a phase on the fast path ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedEnd {
    /// Why.
    pub end: End,
    /// The angle where a contact ends (`None` at the floor).
    pub at: Option<Separation>,
    /// The angle fallen at the end.
    pub delta: f64,
}

/// Where a phase on the fast path ends, by its roots alone: the first of its closed contacts'
/// force zeros and edges, else the floor. A closed contact whose force pulls at the start ends
/// the phase there (`delta = 0`): it opens at once; a force that is not finite there is
/// [`SolveError::NonFinite`].
pub fn phase_end(sys: &System, work: &mut Work) -> Result<ReducedEnd, SolveError> {
    let info = sys.info();
    let at_start = sys.forces(0.0)?;
    let mut found: Option<(End, Separation)> = None;
    let mut consider = |end: End, outcome: SeparationOutcome| {
        if let SeparationOutcome::Separates(s) = outcome
            && found.is_none_or(|(_, f)| s.delta < f.delta)
        {
            found = Some((end, s));
        }
    };
    for (i, c) in info.contacts.iter().enumerate() {
        if !c.closed || c.bilateral {
            continue;
        }
        if !at_start[i].is_finite() {
            return Err(SolveError::NonFinite {
                model: info.name,
                what: "a closed contact's force at the phase's start",
                delta: 0.0,
                value: at_start[i],
            });
        }
        if at_start[i] < 0.0 {
            let theta = sys.theta_initial();
            return Ok(ReducedEnd {
                end: End::Force(i),
                at: Some(Separation {
                    sin_theta: theta.sin(),
                    theta,
                    delta: 0.0,
                }),
                delta: 0.0,
            });
        }
        consider(End::Force(i), force_zero(sys, i, work)?);
    }
    for (i, c) in info.contacts.iter().enumerate() {
        if c.closed && c.edge {
            consider(End::Edge(i), edge(sys, i, work)?);
        }
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
    /// Solves the phase when the end of its closed contacts is already known, then watches its
    /// open contacts' gaps along it: one that closes first ends the phase there.
    pub fn with_end(
        sys: System<'m>,
        t_start: f64,
        end: ReducedEnd,
        tol: f64,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        if end.delta == 0.0 {
            // A contact that opens at once: a phase of no length.
            work.phases.push(sys.name().to_string());
            return Ok(ReducedRun {
                mesh: TimeMesh::empty(),
                system: sys,
                t_start,
                end,
            });
        }
        let mut mesh = TimeMesh::build(&sys, end.delta, tol, work)?;
        let mut end = end;
        if let Some((i, delta)) = first_gap_closing(&sys, &mesh, work)? {
            mesh = TimeMesh::build(&sys, delta, tol, work)?;
            let theta = sys.theta_initial() - delta;
            end = ReducedEnd {
                end: End::Contact(i),
                at: Some(Separation {
                    sin_theta: theta.sin(),
                    theta,
                    delta,
                }),
                delta,
            };
        }
        work.phases.push(sys.name().to_string());
        Ok(ReducedRun {
            system: sys,
            t_start,
            end,
            mesh,
        })
    }

    /// The separation that ends it, if its first contact's force reached zero.
    pub fn separation(&self) -> Option<Separation> {
        match self.end.end {
            End::Force(0) => self.end.at,
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
    pub fn end_state(&self) -> Result<State, SolveError> {
        Ok(self.system.full_state(
            self.mesh.duration,
            self.mesh.delta_end,
            self.theta_dot_end(),
        )?)
    }
}

/// The first open contact whose gap closes along a fast phase, and the angle fallen where it
/// does: each open contact's gap on [`GAP_CELLS`] cells uniform in the time variable `v`,
/// bracketed and refined by [`roots::illinois`] in the angle fallen. A gap that starts at zero
/// (a contact that has just opened) counts only once it has grown past rounding.
fn first_gap_closing(
    sys: &System,
    mesh: &TimeMesh,
    work: &mut Work,
) -> Result<Option<(usize, f64)>, SolveError> {
    let info = sys.info();
    let open: Vec<usize> = (0..info.contacts.len())
        .filter(|&i| !info.contacts[i].closed)
        .collect();
    if open.is_empty() {
        return Ok(None);
    }
    let state_at = |delta: f64, work: &mut Work| -> Result<State, SolveError> {
        let t = mesh.time_at_delta(sys, delta, work)?;
        Ok(sys.full_state(t, delta, theta_dot_at(sys, delta))?)
    };
    let tol = DECIDE_TOLERANCE * sys.length_scale(&state_at(0.0, work)?)?;
    let mut best: Option<(usize, f64)> = None;
    for &i in &open {
        let mut gap = |delta: f64| -> Result<f64, SolveError> {
            let mut w = Work::default();
            let g = sys.gaps(&state_at(delta, &mut w)?)?[i];
            work.integrand_evals += w.integrand_evals;
            Ok(g)
        };
        let mut armed = gap(0.0)? > tol;
        let mut a = (0.0, 1.0);
        for j in 1..=GAP_CELLS {
            let v = mesh.v_end * j as f64 / GAP_CELLS as f64;
            let delta = if j == GAP_CELLS {
                mesh.delta_end
            } else {
                mesh.delta_at_v(sys, v)?
            };
            let g = gap(delta)?;
            if !armed {
                armed = g > tol;
                a = (delta, 1.0);
                continue;
            }
            if changes_sign(a.1, g) {
                let root = roots::illinois(&mut gap, a, (delta, g))?;
                if best.is_none_or(|(_, d)| root < d) {
                    best = Some((i, root));
                }
                break;
            }
            a = (delta, g);
        }
    }
    Ok(best)
}

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
    pub fn end(&self) -> End {
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
    pub fn theta_end(&self) -> f64 {
        match self {
            PhaseRun::Reduced(r) => r.system.theta_initial() - r.mesh.delta_end,
            PhaseRun::Integrated(r) => r.run.state_end.q[r.bound.info().reduced_index],
        }
    }

    /// `theta_dot` at the end of the phase (rad/s).
    pub fn theta_dot_end(&self) -> f64 {
        match self {
            PhaseRun::Reduced(r) => r.theta_dot_end(),
            PhaseRun::Integrated(r) => r.run.state_end.qd[r.bound.info().reduced_index],
        }
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
    /// modes).
    pub fn closed(&self) -> Vec<bool> {
        match self {
            PhaseRun::Reduced(r) => r.system.info().contacts.iter().map(|c| c.closed).collect(),
            PhaseRun::Integrated(r) => (r.run.segments.first())
                .map(|s| s.active.closed.clone())
                .unwrap_or_default(),
        }
    }

    /// The contacts closed at the end of the phase (in the general model's order).
    pub fn closed_at_end(&self) -> Vec<bool> {
        match self {
            PhaseRun::Reduced(r) => r.system.info().contacts.iter().map(|c| c.closed).collect(),
            PhaseRun::Integrated(r) => (r.run.segments.last())
                .map(|s| s.active.closed.clone())
                .unwrap_or_default(),
        }
    }

    /// The active sets over the phase: each stretch's start (s from release) and its closed
    /// contacts and friction modes in words.
    pub fn stretches(&self) -> Vec<(f64, String)> {
        match self {
            PhaseRun::Reduced(r) => {
                let info = r.system.info();
                vec![(r.t_start, Active::of_model(info).describe(info))]
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

/// `sqrt(2 h / g)` for the height `h` of the falling point at `state` (the system's length
/// scale in place of a height within [`LANDING_TOLERANCE`] of it: a body lying on the floor):
/// the time scale of the motion.
pub fn fall_time_scale(bound: &Bound, state: &State) -> Result<f64, SolveError> {
    let info = bound.info();
    let h = bound.points(state)?.pos[info.falling_point_index][1];
    let length = bound.length_scale(state)?;
    let h = if h > LANDING_TOLERANCE * length {
        h
    } else {
        length
    };
    Ok((2.0 * h / bound.gravity()).sqrt())
}

/// An impact between two phases of a motion.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactAt {
    /// Absolute time (s from release).
    pub t: f64,
    /// The phase that ended with it (an index into [`Motion::phases`]; the next one starts
    /// from its state after).
    pub phase: usize,
    /// The contact whose gap closed.
    pub closing: usize,
    /// Each contact's part in it.
    pub parts: Vec<Part>,
    /// The impulses, the normal velocities and the state after.
    pub impact: Impact,
    /// Whether a converging (Zeno) sequence of bounces was closed by making this impact
    /// plastic.
    pub zeno: bool,
}

/// The whole motion, phase after phase.
#[derive(Debug, Clone)]
pub struct Motion<'m> {
    /// The phases in order; the last one reaches the floor, an edge, a closing contact (where
    /// the run does not go on through impacts) or the run's end.
    pub phases: Vec<PhaseRun<'m>>,
    /// The contacts that touched at release but opened at once (their force would have had to
    /// pull).
    pub opened_at_release: Vec<usize>,
    /// The impacts between phases, in order.
    pub impacts: Vec<ImpactAt>,
    /// Whether a contact that closes is an impact the motion goes on through (the run has an
    /// end time), or the end of the motion.
    pub through_impacts: bool,
    /// Why the motion stopped before its end, if it did (too many impacts).
    pub halted: Option<Halt>,
    /// What the reader should know about how the motion was followed: each converging (Zeno)
    /// sequence of bounces closed.
    pub notes: Vec<Zeno>,
}

impl<'m> Motion<'m> {
    /// A motion of its first phase.
    pub fn starting(first: PhaseRun<'m>, opened_at_release: Vec<usize>, through: bool) -> Self {
        Motion {
            phases: vec![first],
            opened_at_release,
            impacts: Vec::new(),
            through_impacts: through,
            halted: None,
            notes: Vec::new(),
        }
    }

    /// Absolute time the last phase ends (s).
    pub fn end_time(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::t_end)
    }

    /// `theta_dot` at the end of the last phase (rad/s).
    pub fn end_angular_velocity(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::theta_dot_end)
    }

    /// Why the last phase ended.
    pub fn last_end(&self) -> Option<End> {
        self.phases.last().map(PhaseRun::end)
    }

    /// Whether the motion goes on after a phase that ended by `end`: after a contact that
    /// opens, and after one that closes where the run goes on through impacts.
    pub fn goes_on_after(&self, end: End) -> bool {
        match end {
            End::Force(_) => true,
            End::Contact(_) => self.through_impacts,
            End::Edge(_) | End::Floor | End::Until => false,
        }
    }

    /// Whether the motion is complete: its last phase ends for good (the floor, an edge, the
    /// run's end, or a contact that closes where impacts end the run), or it was halted.
    pub fn complete(&self) -> bool {
        self.halted.is_some() || self.last_end().is_some_and(|e| !self.goes_on_after(e))
    }

    /// The impact that ended phase `k`, if one did.
    pub fn impact_after(&self, k: usize) -> Option<&ImpactAt> {
        self.impacts.iter().find(|i| i.phase == k)
    }
}

/// How a system's motion is solved: its general model with parameters, where to find its
/// fast phases, the tolerances and the route.
#[derive(Clone)]
pub struct Walker<'m> {
    /// The general model with its parameters.
    pub general: Bound<'m>,
    /// Where the fast phases are looked up by name.
    pub registry: &'m [&'m dyn Model],
    /// Relative tolerance of the fast path's quadrature.
    pub tol: f64,
    /// Relative tolerance of the integrator.
    pub rtol: f64,
    /// Which route solves the phases.
    pub route: Route,
    /// The time the run goes on to (s from release), through impacts: `None` ends it at the
    /// first event that ends the motion (the floor, an edge, or a contact that closes).
    pub until: Option<f64>,
    /// Keep the continuous extension of every integrated step, so that the phases can be
    /// sampled between steps (series, trajectories, checks;
    /// [`crate::quantity::Quantity::samples_motion`]).
    /// Without it a sample inside an integrated step is an error, never a guess.
    pub dense_output: bool,
}

impl std::fmt::Debug for Walker<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Walker")
            .field("general", &self.general)
            .field("tol", &self.tol)
            .field("rtol", &self.rtol)
            .field("route", &self.route)
            .field("until", &self.until)
            .finish()
    }
}

/// Where a phase starts: the system's state, its active set and the friction options it was
/// decided from, and the absolute time.
#[derive(Debug, Clone)]
pub struct PhaseStart {
    /// The system's state.
    pub state: State,
    /// The closed contacts and friction modes.
    pub active: Active,
    /// The friction options the modes were decided from.
    pub frictions: Vec<FrictionOption>,
    /// Absolute time (s from release).
    pub t: f64,
    /// Work done by friction before (J).
    pub friction_work: f64,
}

impl<'m> Walker<'m> {
    /// The release: the system's initial state and the contacts that stay closed there (the
    /// acceleration-level complementarity problem), with those that touched but opened.
    pub fn release(&self) -> Result<(PhaseStart, Vec<usize>), SolveError> {
        let state = self.general.initial_state();
        let contacts = contact_options(&self.general, &state, Moment::Release)?;
        let frictions = friction_options(&self.general, &state)?;
        let options = Options {
            contacts: contacts.clone(),
            frictions: frictions.clone(),
        };
        let active = contacts::decide(&self.general, &state, &options, 0.0)?;
        let opened = (0..contacts.len())
            .filter(|&i| contacts[i] == ContactOption::Candidate && !active.closed[i])
            .collect();
        Ok((
            PhaseStart {
                state,
                active,
                frictions,
                t: 0.0,
                friction_work: 0.0,
            },
            opened,
        ))
    }

    /// What follows a phase that ended with contact `opened`'s force at zero: the contacts
    /// that stay closed there, that one open.
    pub fn after(&self, run: &PhaseRun<'m>) -> Result<PhaseStart, SolveError> {
        let state = run.full_end_state()?;
        let t = run.t_end();
        let held = run.closed_at_end();
        let at = Moment::After {
            t,
            held: &held,
            drift: self.tol,
        };
        let mut contacts = contact_options(&self.general, &state, at)?;
        if let End::Force(i) = run.end()
            && let Some(c) = contacts.get_mut(i)
        {
            *c = ContactOption::Opens;
        }
        let frictions = friction_options(&self.general, &state)?;
        let options = Options {
            contacts,
            frictions: frictions.clone(),
        };
        let active = contacts::decide(&self.general, &state, &options, t)?;
        Ok(PhaseStart {
            state,
            active,
            frictions,
            t,
            friction_work: run.friction_work(),
        })
    }

    /// The fast phase for `start`'s closed contacts, bound to start there, if the route allows
    /// it and the system has one that applies (no friction acting; a phase that starts from
    /// the spec's release state only at release; a phase that falls).
    pub fn fast_phase(&self, start: &PhaseStart) -> Result<Option<System<'m>>, SolveError> {
        let info = self.general.info();
        if self.route != Route::Fastest
            || (0..info.frictions.len()).any(|j| start.active.friction_acts(info, j))
        {
            return Ok(None);
        }
        let closed: Vec<usize> = (0..start.active.closed.len())
            .filter(|&i| start.active.closed[i])
            .collect();
        let Some(entry) = info.phases.iter().find(|p| p.closed == closed.as_slice()) else {
            return Ok(None);
        };
        let Some(model) = (self.registry.iter().copied()).find(|m| m.info().name == entry.model)
        else {
            return Err(SolveError::UnknownPhaseModel {
                system: info.name,
                name: entry.model,
            });
        };
        let phase = model.info();
        if !phase.start_params && start.t != 0.0 {
            return Ok(None);
        }
        let p = phase_parameters(&self.general, phase, &start.state)?;
        let sys = System::from_values(model, &p).map_err(SolveError::System)?;
        // The fast path follows a falling angle from below the vertical.
        let falls = sys.theta_dot_initial() <= 0.0 && sys.theta_initial().cos() > 0.0;
        Ok(falls.then_some(sys))
    }

    /// Solves one phase from `start` to its end: on the fast path where [`Walker::fast_phase`]
    /// gives one (and its motion does not turn back before the end), else integrated.
    pub fn solve(&self, start: &PhaseStart, work: &mut Work) -> Result<PhaseRun<'m>, SolveError> {
        match self.fast_phase(start)? {
            Some(sys) => {
                let end = phase_end(&sys, work)?;
                self.follow(sys, start, end, work)
            }
            None => self.integrate(start, work),
        }
    }

    /// Follows the fast phase `sys` from `start` to `end` (its roots' end). If the angle turns
    /// back first: a phase that starts at rest swings for ever ([`SolveError::Swings`]: with
    /// one degree of freedom, no friction and no momentum, its configuration is a function of
    /// the angle and its forces of the angle and `theta_dot^2`, so it retraces its path to the
    /// start and back); any other is integrated.
    pub fn follow(
        &self,
        sys: System<'m>,
        start: &PhaseStart,
        end: ReducedEnd,
        work: &mut Work,
    ) -> Result<PhaseRun<'m>, SolveError> {
        match ReducedRun::with_end(sys, start.t, end, self.tol, work) {
            Ok(run) => Ok(PhaseRun::Reduced(self.cut(run, work)?)),
            Err(SolveError::TurningPoint { model, delta, .. })
                if start.state.qd.iter().all(|v| *v == 0.0) =>
            {
                Err(SolveError::Swings {
                    model,
                    t: start.t,
                    delta,
                })
            }
            Err(SolveError::TurningPoint { .. }) => self.integrate(start, work),
            Err(e) => Err(e),
        }
    }

    /// A fast phase that runs past the run's end ([`Walker::until`]) cut there: its mesh to the
    /// angle fallen at that time, ended by [`End::Until`].
    fn cut(&self, run: ReducedRun<'m>, work: &mut Work) -> Result<ReducedRun<'m>, SolveError> {
        let Some(until) = self.until else {
            return Ok(run);
        };
        let local = until - run.t_start;
        if run.t_start + run.mesh.duration <= until || local.is_nan() || local <= 0.0 {
            return Ok(run);
        }
        let delta = delta_at_time(&run.system, &run.mesh, local, work)?;
        let mesh = TimeMesh::build(&run.system, delta, self.tol, work)?;
        Ok(ReducedRun {
            end: ReducedEnd {
                end: End::Until,
                at: None,
                delta,
            },
            mesh,
            ..run
        })
    }

    /// Typical sizes of the motion from `state` with `active` closed over the fall's time
    /// scale, for the integrator's absolute tolerances ([`motion_scales`]).
    pub fn scales(&self, state: &State, active: &Active) -> Result<Vec<f64>, SolveError> {
        let time = fall_time_scale(&self.general, state)?;
        let d = contacts::dynamics(&self.general, state, active, 0.0)?;
        motion_scales(&self.general, state, &d.qdd, time)
    }

    /// Integrates the general model from `start` to its first event.
    pub fn integrate(
        &self,
        start: &PhaseStart,
        work: &mut Work,
    ) -> Result<PhaseRun<'m>, SolveError> {
        self.integrate_with(start, None, work)
    }

    /// [`Walker::integrate`] by `method` when one is given, else by the method the integrator
    /// picks for the walker's tolerance ([`unreduced::integrate_with`]).
    pub fn integrate_with(
        &self,
        start: &PhaseStart,
        method: Option<Method>,
        work: &mut Work,
    ) -> Result<PhaseRun<'m>, SolveError> {
        let bound = self.general.clone();
        let time = fall_time_scale(&bound, &start.state)?;
        let scales = self.scales(&start.state, &start.active)?;
        let from = Start {
            state: start.state.clone(),
            active: start.active.clone(),
            frictions: start.frictions.clone(),
            friction_work: start.friction_work,
            stop_at: self.until.map(|u| u - start.t),
            dense_output: self.dense_output,
        };
        // A run with an end time may go on to it however long its phases last.
        let t_max = (time * MAX_FALL_TIMES).max(from.stop_at.unwrap_or(0.0));
        let run =
            unreduced::integrate_with(&bound, &from, self.rtol, method, Some(&scales), t_max, work)
                .map_err(|e| at_time(e, start.t))?;
        if run.end == End::Floor {
            self.landed(&run.state_end, start.t + run.t_end)?;
        }
        let phase = PhaseRun::Integrated(IntegratedRun {
            bound,
            t_start: start.t,
            run,
        });
        work.phases.extend(phase.labels());
        Ok(phase)
    }

    /// Whether the system has landed where its reduced angle reaches the end angle: the
    /// falling point on the floor (within [`LANDING_TOLERANCE`] of the system's length, or
    /// the walker's tolerance if looser). A support that lifted the body (a rod pivoting over
    /// a cylinder, its foot in the air) brings it to the end angle above the floor: the motion
    /// goes on past it, which the spec's end angle does not describe, so that is an error, not
    /// a landing.
    fn landed(&self, state: &State, t: f64) -> Result<(), SolveError> {
        let info = self.general.info();
        let height = self.general.points(state)?.pos[info.falling_point_index][1];
        let length = self.general.length_scale(state)?;
        if height.abs() <= LANDING_TOLERANCE.max(self.tol) * length {
            return Ok(());
        }
        Err(SolveError::AboveFloor {
            model: info.name,
            t,
            angle: info.end_angle,
            point: info.points[info.falling_point_index].name,
            height,
        })
    }

    /// The whole motion from release: phase after phase until one ends for good.
    pub fn motion(&self, work: &mut Work) -> Result<Motion<'m>, SolveError> {
        let (start, opened) = self.release()?;
        let first = self.solve(&start, work)?;
        let mut motion = Motion::starting(first, opened, self.until.is_some());
        self.extend(&mut motion, work)?;
        Ok(motion)
    }

    /// Continues a motion from its last phase until one ends for good.
    pub fn extend(&self, motion: &mut Motion<'m>, work: &mut Work) -> Result<(), SolveError> {
        while !motion.complete() {
            self.step(motion, work)?;
        }
        Ok(())
    }

    /// Adds the next phase to a motion that goes on: after a contact that opens, the contacts
    /// decided again; after one that closes, the impact first. A motion that has had
    /// [`MAX_IMPACTS`] impacts is halted instead, with a note.
    pub fn step(&self, motion: &mut Motion<'m>, work: &mut Work) -> Result<(), SolveError> {
        let (end, friction_work) = {
            let last = last_phase(motion)?;
            (last.end(), last.friction_work())
        };
        let since = motion.phases.len() - motion.impacts.last().map_or(0, |i| i.phase + 1);
        if since >= MAX_PHASES {
            return Err(SolveError::TooManyPhases { limit: MAX_PHASES });
        }
        let start = match end {
            End::Contact(i) => self.through_impact(motion, i, friction_work)?,
            _ => match self.after(last_phase(motion)?) {
                Ok(start) => Some(start),
                // Another contact closes at the very moment this one opened (within the
                // contacts' tolerance): an impact there.
                Err(e @ SolveError::ImpactAtRelease { contact, .. }) => {
                    let info = self.general.info();
                    let Some(j) = info.contacts.iter().position(|c| c.name == contact) else {
                        return Err(e);
                    };
                    if motion.through_impacts {
                        self.through_impact(motion, j, friction_work)?
                    } else {
                        motion.halted = Some(Halt::ClosesAsOneOpens {
                            contact: contact.to_string(),
                            t: motion.end_time(),
                        });
                        None
                    }
                }
                Err(e) => return Err(e),
            },
        };
        let Some(start) = start else {
            return Ok(());
        };
        let next = self.solve(&start, work)?;
        motion.phases.push(next);
        Ok(())
    }

    /// The impact at the end of the motion's last phase where contact `closing` closes, and
    /// where the motion starts again after it; `None` (with the motion halted and why) past
    /// [`MAX_IMPACTS`], or where the impact leaves the system at rest.
    fn through_impact(
        &self,
        motion: &mut Motion<'m>,
        closing: usize,
        friction_work: f64,
    ) -> Result<Option<PhaseStart>, SolveError> {
        if motion.impacts.len() >= MAX_IMPACTS {
            motion.halted = Some(Halt::TooManyImpacts {
                number: MAX_IMPACTS + 1,
                t: motion.end_time(),
            });
            return Ok(None);
        }
        let at = self.impact(motion, closing)?;
        let start = self.after_impact(&at, friction_work);
        motion.impacts.push(at);
        match start {
            Ok(start) => Ok(Some(start)),
            // An impact that leaves the system at rest ends its motion.
            Err(SolveError::AtRest { t, how, .. }) => {
                motion.halted = Some(Halt::AtRest { t, how });
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// The impact that ends the motion's last phase, where contact `closing` closed: every
    /// contact closed then, `closing` and any other open one that touches while approaching take
    /// part; a contact with friction taking part is [`SolveError::FrictionalImpact`]. Bounces
    /// converging as Zeno's (`zeno_limit`) are closed by a plastic impact, with a note.
    pub fn impact(&self, motion: &mut Motion<'m>, closing: usize) -> Result<ImpactAt, SolveError> {
        let general = &self.general;
        let info = general.info();
        let phase = motion.phases.len() - 1;
        let last = &motion.phases[phase];
        let (state, t, held) = (last.full_end_state()?, last.t_end(), last.closed_at_end());
        let approaching = approaching_touches(general, &state)?;
        let parts: Vec<Part> = (info.contacts.iter().enumerate())
            .map(|(c, contact)| {
                let takes_part = held.get(c) == Some(&true) || c == closing || approaching[c];
                match (contact.closed, takes_part, contact.bilateral) {
                    (true, _, _) | (false, false, _) => Part::None,
                    (false, true, true) => Part::Bilateral,
                    (false, true, false) => Part::Unilateral,
                }
            })
            .collect();
        let mu = general.friction_coefficients();
        if let Some(f) = (info.frictions.iter().enumerate())
            .find(|(j, f)| parts[f.contact_index] != Part::None && mu[*j] != 0.0)
            .map(|(_, f)| f)
        {
            return Err(SolveError::FrictionalImpact {
                model: info.name,
                t,
                contact: info.contacts[f.contact_index].name,
            });
        }
        let name = info.contacts[closing].name;
        let mut restitution = general.restitutions().to_vec();
        let limit = zeno_limit(&motion.impacts, closing, t, self.tol);
        if limit.is_some() {
            restitution[closing] = 0.0;
        }
        let mut impact = impact::resolve_with(general, &state, &parts, &restitution, t)?;
        let mut plastic = limit.is_some();
        if let Some((ratio, t_limit, bounces)) = limit {
            motion.notes.push(Zeno::Limit {
                contact: name.to_string(),
                bounces,
                ratio,
                t_limit,
                t,
            });
        } else if let Some((rise, flight)) = self.unresolved_bounce(&impact, &parts, closing, t)? {
            // The bounces left, each `e` times the one before: their flights sum to about
            // `flight / (1 - e)`.
            let left = flight / (1.0 - restitution[closing]).max(f64::EPSILON);
            restitution[closing] = 0.0;
            impact = impact::resolve_with(general, &state, &parts, &restitution, t)?;
            plastic = true;
            motion.notes.push(Zeno::Unresolved {
                contact: name.to_string(),
                t,
                rise,
                open_gap: DECIDE_TOLERANCE,
                left,
            });
        }
        Ok(ImpactAt {
            t,
            phase,
            closing,
            parts,
            impact,
            zeno: plastic,
        })
    }

    /// How high (relative to the system's length scale) contact `closing` would rise after
    /// `impact`, where that is below [`DECIDE_TOLERANCE`] (the gap at which a contact counts as
    /// open), and for how long (s): its normal velocity after squared over twice its normal
    /// acceleration pulling it back, and twice the velocity over that acceleration, with it
    /// open and the other contacts decided at the state after. `None` for a contact that stays
    /// closed, is not pulled back, or rises clear.
    fn unresolved_bounce(
        &self,
        impact: &Impact,
        parts: &[Part],
        closing: usize,
        t: f64,
    ) -> Result<Option<(f64, f64)>, SolveError> {
        let u = impact.normal_velocity_after[closing];
        if u <= 0.0 {
            return Ok(None);
        }
        let state = &impact.after;
        let (active, _) = self.decide_after(state, parts, t)?;
        let pull = -contacts::dynamics(&self.general, state, &active, t)?.normal_acc[closing];
        if pull <= 0.0 {
            return Ok(None);
        }
        let info = self.general.info();
        let scale = if info.contacts[closing].gap_unit == "m" {
            self.general.length_scale(state)?
        } else {
            1.0
        };
        let rise = u * u / (2.0 * pull) / scale;
        Ok((rise < DECIDE_TOLERANCE).then_some((rise, 2.0 * u / pull)))
    }

    /// What follows an impact at the end of `run`: the contacts decided again at the state
    /// after it (a contact that took part and rests closes or opens as its force says; one
    /// that separates is open).
    fn after_impact(&self, at: &ImpactAt, friction_work: f64) -> Result<PhaseStart, SolveError> {
        let (active, frictions) = self.decide_after(&at.impact.after, &at.parts, at.t)?;
        Ok(PhaseStart {
            state: at.impact.after.clone(),
            active,
            frictions,
            t: at.t,
            friction_work,
        })
    }

    /// The contacts and friction modes at `state`, just after an impact at `t` in which
    /// `parts` took part (those touch within the run's drift), with the friction options they
    /// were decided from.
    fn decide_after(
        &self,
        state: &State,
        parts: &[Part],
        t: f64,
    ) -> Result<(Active, Vec<FrictionOption>), SolveError> {
        let held: Vec<bool> = parts.iter().map(|p| *p != Part::None).collect();
        let moment = Moment::After {
            t,
            held: &held,
            drift: self.tol,
        };
        let frictions = friction_options(&self.general, state)?;
        let options = Options {
            contacts: contact_options(&self.general, state, moment)?,
            frictions: frictions.clone(),
        };
        Ok((
            contacts::decide(&self.general, state, &options, t)?,
            frictions,
        ))
    }
}

/// The motion's last phase (a motion always has its first).
fn last_phase<'a, 'm>(motion: &'a Motion<'m>) -> Result<&'a PhaseRun<'m>, SolveError> {
    motion.phases.last().ok_or(SolveError::NoSuchPhase {
        index: 0,
        solved: 0,
    })
}

/// Per contact: whether it is open (not eliminated, not bilateral), touches (a gap within
/// [`contacts::DECIDE_TOLERANCE`] of the system's length) and approaches (a negative normal
/// velocity) at `state`: it takes part in an impact there even if its own event was not the
/// one that fired.
fn approaching_touches(sys: &Bound, state: &State) -> Result<Vec<bool>, SolveError> {
    let info = sys.info();
    let n = sys.n_coordinates();
    let gaps = sys.gaps(state)?;
    let (jac, _) = sys.constraints(state)?;
    let length = sys.length_scale(state)?;
    Ok((info.contacts.iter().enumerate())
        .map(|(i, c)| {
            let scale = if c.gap_unit == "m" { length } else { 1.0 };
            let v = contacts::normal_velocity(&jac[i * n..(i + 1) * n], state);
            !c.closed && !c.bilateral && gaps[i] <= DECIDE_TOLERANCE * scale && v < 0.0
        })
        .collect())
}

/// Whether the bounces at contact `closing` before an impact at `t` converge as Zeno's: the
/// last [`ZENO_RATIOS`] ratios of successive intervals between impacts at that contact are
/// below one and agree within [`ZENO_RATIO_SPREAD`], and the time left to their limit is within
/// `tol` of `t`. Returns the ratio, the limit's time and the bounces counted.
fn zeno_limit(impacts: &[ImpactAt], closing: usize, t: f64, tol: f64) -> Option<(f64, f64, usize)> {
    let times: Vec<f64> = (impacts.iter().rev())
        .take_while(|i| i.closing == closing)
        .map(|i| i.t)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .chain([t])
        .collect();
    if times.len() < ZENO_RATIOS + 2 {
        return None;
    }
    let dt: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let ratios: Vec<f64> = dt.windows(2).map(|w| w[1] / w[0]).collect();
    let recent = &ratios[ratios.len() - ZENO_RATIOS..];
    let r = recent[recent.len() - 1];
    let steady = recent
        .iter()
        .all(|q| *q > 0.0 && *q < 1.0 && (q - r).abs() <= ZENO_RATIO_SPREAD * r);
    let left = dt[dt.len() - 1] * r / (1.0 - r);
    (steady && left <= tol * t).then_some((r, t + left, times.len()))
}

/// A phase's error with the phase's start time added to the time it names (the integrator
/// counts from the phase's start).
fn at_time(e: SolveError, t0: f64) -> SolveError {
    match e {
        SolveError::Indeterminate {
            model,
            t,
            contacts,
            why,
        } => SolveError::Indeterminate {
            model,
            t: t + t0,
            contacts,
            why,
        },
        other => other,
    }
}

/// The parameters of fast phase `phase` starting at the system's `state`: the spec's (the
/// general model's), then for a phase that takes its start state each of its coordinates'
/// values and rates, found by name among the system's coordinates.
pub fn phase_parameters(
    general: &Bound,
    phase: &'static ModelInfo,
    state: &State,
) -> Result<Vec<f64>, SolveError> {
    let info = general.info();
    general.check_state(state)?;
    let mut p = general.p().to_vec();
    if !phase.start_params {
        if phase.parameters.len() != p.len() {
            return Err(SolveError::PhaseMismatch {
                system: info.name,
                name: phase.name,
                why: format!(
                    "it takes {} parameters, the system {}",
                    phase.parameters.len(),
                    p.len()
                ),
            });
        }
        return Ok(p);
    }
    let index = |c: &str| {
        (info.coordinates.iter().position(|q| *q == c)).ok_or_else(|| SolveError::PhaseMismatch {
            system: info.name,
            name: phase.name,
            why: format!("its coordinate `{c}` is not one of the system's"),
        })
    };
    let indices: Vec<usize> = (phase.coordinates.iter())
        .map(|c| index(c))
        .collect::<Result<_, _>>()?;
    p.extend(indices.iter().map(|&i| state.q[i]));
    p.extend(indices.iter().map(|&i| state.qd[i]));
    if p.len() != phase.parameters.len() {
        return Err(SolveError::PhaseMismatch {
            system: info.name,
            name: phase.name,
            why: format!(
                "it takes {} parameters, the system's state gives {}",
                phase.parameters.len(),
                p.len()
            ),
        });
    }
    Ok(p)
}
