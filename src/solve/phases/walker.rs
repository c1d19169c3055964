//! How a system's motion is solved ([`Walker`]): the contacts decided at release and after every
//! event, each phase on its route, phase after phase until one ends for good, and through
//! impacts (Zeno's bounces caught) where the run goes on to a time; with the limits that halt
//! it and a fast phase's start parameters ([`phase_parameters`]); a converging sequence is
//! closed at its accumulation time.

use super::motion::{ImpactAt, Motion};
use super::reduced::{ReducedEnd, ReducedRun, phase_end};
use super::run::{IntegratedRun, PhaseRun};
use super::zeno::{self, Flight};
use crate::model::{GapKind, Model, ModelInfo};
use crate::results::EndCause;
use crate::results::{Halt, Work, Zeno};
use crate::solve::SolveError;
use crate::solve::fast::inversion::delta_at_time;
use crate::solve::fast::quadrature::TimeMesh;
use crate::solve::integrated::contacts::{
    self, Active, ContactOption, DECIDE_TOLERANCE, FrictionOption, Moment, Options,
    contact_options, friction_options,
};
use crate::solve::integrated::impact::{self, Impact, Part};
use crate::solve::integrated::ode::Method;
use crate::solve::integrated::unreduced::{self, EndSensitivity, Start, motion_scales};
use crate::system::{Bound, State, System, SystemError};

/// Most phases chained between two impacts (or from release to the first) before giving up:
/// contacts that keep opening and closing without an impact are chatter, not a motion.
pub const MAX_PHASES: usize = 16;

/// Most impacts in one run. A run that reaches it stops there with a note (a bouncing sequence
/// that neither converges as Zeno's nor comes to rest).
pub const MAX_IMPACTS: usize = 1000;

/// An integrated phase that has not reached an event after this many free-fall times of its
/// falling point is reported as [`SolveError::NoEvent`]. Generous: a light rod that pushes a
/// cube a million times heavier from nearly upright (a stuck foot makes it the hinged rod)
/// takes some ten thousand.
pub const MAX_FALL_TIMES: f64 = 1e5;

/// How far (relative to the system's length) the falling point may be from the floor where
/// the reduced angle reaches its end angle, and still count as landed.
pub const LANDING_TOLERANCE: f64 = 1e-9;

/// Which route solves a phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Route {
    /// The fast path where the system has one for the phase, integration otherwise.
    #[default]
    Fastest,
    /// Integration of the general model for every phase (to compare the routes).
    Integrated,
}

/// `sqrt(2 h / g)` for the height `h` of the falling point at `state` (the system's length
/// scale in place of a height within [`LANDING_TOLERANCE`] of it, a body lying on the floor,
/// or where the system names no falling point): the time scale of the motion.
pub fn fall_time_scale(bound: &Bound, state: &State) -> Result<f64, SolveError> {
    let length = bound.length_scale(state)?;
    let h = match bound.info().falling_point_index {
        Some(i) => bound.points(state)?.pos[i][1],
        None => length,
    };
    let h = if h > LANDING_TOLERANCE * length {
        h
    } else {
        length
    };
    Ok((2.0 * h / bound.gravity()).sqrt())
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
    /// A walker of `general`'s system, its fast phases looked up in `registry`, the quadrature
    /// at `tol` and the integrator at `rtol`: on the fastest route, to the first event that ends
    /// the motion (no `until`), keeping every integrated step's continuous extension. The
    /// `with_*` methods change one setting each.
    pub fn new(
        general: Bound<'m>,
        registry: &'m [&'m dyn Model],
        tol: f64,
        rtol: f64,
    ) -> Walker<'m> {
        Walker {
            general,
            registry,
            tol,
            rtol,
            route: Route::Fastest,
            until: None,
            dense_output: true,
        }
    }

    /// The same walker on `route`.
    pub fn with_route(mut self, route: Route) -> Walker<'m> {
        self.route = route;
        self
    }

    /// The same walker going on to `until` (s from release) through impacts, or (`None`) to
    /// the first event that ends the motion.
    pub fn with_until(mut self, until: Option<f64>) -> Walker<'m> {
        self.until = until;
        self
    }

    /// The same walker keeping (or not) every integrated step's continuous extension.
    pub fn with_dense_output(mut self, dense_output: bool) -> Walker<'m> {
        self.dense_output = dense_output;
        self
    }

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
        let held = run.closed_at_end()?;
        // The held contacts' gaps drift like the phase's error: the run's tolerance, or the
        // integrator's where the mass matrix's conditioning raised it (a light block under a
        // rod, condition 1e9: rtol 2e-6, gaps 1e-9 of the system's size).
        let drift = match run {
            PhaseRun::Integrated(r) => self.tol.max(r.run.rtol),
            PhaseRun::Reduced(_) => self.tol,
        };
        let at = Moment::After {
            t,
            held: &held,
            drift,
        };
        let mut contacts = contact_options(&self.general, &state, at)?;
        if let EndCause::Force(i) = run.end()
            && let Some(c) = contacts.get_mut(i.index)
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
    /// angle fallen at that time, ended by [`EndCause::Until`].
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
                end: EndCause::Until,
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
        self.integrate_from(start, method, None, work)
    }

    /// [`Walker::integrate`] with the forward sensitivities `s` at the start
    /// ([`Start::sensitivity`]), and those at its end.
    pub fn integrate_sensitive(
        &self,
        start: &PhaseStart,
        s: Vec<f64>,
        work: &mut Work,
    ) -> Result<(PhaseRun<'m>, EndSensitivity), SolveError> {
        let mut run = self.integrate_from(start, None, Some(s), work)?;
        let sens = match &mut run {
            PhaseRun::Integrated(r) => r.run.sensitivity.take(),
            PhaseRun::Reduced(_) => None,
        };
        // The integration returns them whenever it starts with them.
        let model = self.general.info().name;
        let sens = sens.ok_or(SystemError::NoTangents { model })?;
        Ok((run, sens))
    }

    /// [`Walker::integrate_with`] with the sensitivities at the start, if any.
    fn integrate_from(
        &self,
        start: &PhaseStart,
        method: Option<Method>,
        sensitivity: Option<Vec<f64>>,
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
            sensitivity,
        };
        // A run with an end time may go on to it however long its phases last.
        let t_max = (time * MAX_FALL_TIMES).max(from.stop_at.unwrap_or(0.0));
        let run =
            unreduced::integrate_with(&bound, &from, self.rtol, method, Some(&scales), t_max, work)
                .map_err(|e| at_time(e, start.t))?;
        if run.end == EndCause::Floor {
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
        let falling = self.general.falling_point()?;
        let height = self.general.points(state)?.pos[falling][1];
        let length = self.general.length_scale(state)?;
        if height.abs() <= LANDING_TOLERANCE.max(self.tol) * length {
            return Ok(());
        }
        Err(SolveError::AboveFloor {
            model: info.name,
            t,
            angle: self.general.end_angle()?,
            point: info.points[falling].name,
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
            EndCause::Contact(i) => self.through_impact(motion, i.index, friction_work)?,
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
    pub(super) fn through_impact(
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
            // At the accumulation time where the impact closed a converging sequence.
            Err(SolveError::AtRest { t, held, set, .. }) => {
                let t = (motion.impacts.last()).map_or(t, |i| i.zeno.unwrap_or(t));
                motion.halted = Some(Halt::AtRest { t, held, set });
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// The impact that ends the motion's last phase, where contact `closing` closed: every
    /// contact closed then, `closing` and any other open one that touches while approaching take
    /// part, with their frictions (`impact::resolve_with`). A sequence converging as Zeno's
    /// (its times, `zeno::limit`, or a flight too small to resolve,
    /// `Walker::unresolved_bounce`) is closed by an impact that holds its contacts closed,
    /// listed at the sequence's accumulation time, with a note.
    pub fn impact(&self, motion: &mut Motion<'m>, closing: usize) -> Result<ImpactAt, SolveError> {
        let general = &self.general;
        let info = general.info();
        let phase = motion.phases.len() - 1;
        let last = &motion.phases[phase];
        let (state, t, held) = (last.full_end_state()?, last.t_end(), last.closed_at_end()?);
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
        let names = |of: &[usize]| -> Vec<String> {
            (of.iter())
                .map(|&c| info.contacts[c].name.to_string())
                .collect()
        };
        let mut impact = impact::resolve(general, &state, &parts, t)?;
        let mut parts = parts;
        let mut zeno = None;
        if let Some(limit) = zeno::limit(&motion.impacts, closing, t, self.tol) {
            impact = close(general, &state, &mut parts, &limit.contacts, &impact, t)?;
            zeno = Some(limit.t_limit);
            motion.notes.push(Zeno::Limit {
                contacts: names(&limit.contacts),
                bounces: limit.bounces,
                ratio: limit.ratio,
                t_limit: limit.t_limit,
                t,
            });
        } else if let Some(bounce) =
            self.unresolved_bounce(&impact, &parts, closing, t, motion.impacts.last())?
        {
            // The rest of the sequence summed: one impact holding its contacts closed.
            let sequence = zeno::sequence(&motion.impacts, closing, t);
            let mut held = sequence.contacts.clone();
            if !held.contains(&bounce.contact) {
                held.push(bounce.contact);
            }
            impact = close(general, &state, &mut parts, &held, &impact, t)?;
            zeno = Some(t + bounce.left);
            let lifted = info.contacts[bounce.contact].name.to_string();
            let others = names(&sequence.contacts)
                .into_iter()
                .filter(|n| *n != lifted);
            motion.notes.push(Zeno::Unresolved {
                contacts: std::iter::once(lifted.clone()).chain(others).collect(),
                t,
                rise: bounce.rise,
                open_gap: DECIDE_TOLERANCE,
                bounces: sequence.times.len(),
                t_limit: t + bounce.left,
            });
        }
        Ok(ImpactAt {
            t,
            phase,
            closing,
            parts,
            impact,
            zeno,
        })
    }

    /// The flight that `impact` (where contact `closing` closed at `t`, after `previous`)
    /// starts, where it is too small to resolve: the contact that took part and leaves fastest
    /// would rise less than [`DECIDE_TOLERANCE`] (relative to the system's length scale) under
    /// its normal acceleration pulling it back, with the other contacts decided at the state
    /// after. The time left to the sequence's limit ([`zeno::time_left`]) treats the flights
    /// to come as repeating this one: the same contact bouncing, or, where another contact
    /// lifts, the two in turn, the previous impact (where the lifted contact closed and lifted
    /// `closing`) giving the other half of the period. `None` where no contact leaves faster
    /// than rounding, none is pulled back, it rises clear, or the period is not known.
    fn unresolved_bounce(
        &self,
        impact: &Impact,
        parts: &[Part],
        closing: usize,
        t: f64,
        previous: Option<&ImpactAt>,
    ) -> Result<Option<Bounce>, SolveError> {
        // A plastic contact's velocity after is zero but for rounding: no bounce to sum (its
        // flight would be rounding over rounding).
        let approach = -impact.normal_velocity_before[closing];
        let rounding = impact::IMPACT_TOLERANCE * approach.abs();
        let Some((c, lift)) = fastest_lift(impact, parts, rounding) else {
            return Ok(None);
        };
        let state = &impact.after;
        let (active, _) = self.decide_after(state, parts, t)?;
        let pull = -contacts::dynamics(&self.general, state, &active, t)?.normal_acc[c];
        if pull <= 0.0 {
            return Ok(None);
        }
        let scale = match self.general.info().contacts[c].gap {
            GapKind::Length => self.general.length_scale(state)?,
            GapKind::Angle => 1.0,
        };
        let rise = lift * lift / (2.0 * pull) / scale;
        if rise >= DECIDE_TOLERANCE {
            return Ok(None);
        }
        let now = Flight {
            lift,
            approach,
            pull,
        };
        let before = match previous {
            _ if c == closing => None,
            // Two contacts in turn: `c` closed at the previous impact and lifted `closing`,
            // which flew until now.
            Some(p) if p.closing == c && t > p.t => {
                let lift = p.impact.normal_velocity_after[closing];
                Some(Flight {
                    lift,
                    approach: -p.impact.normal_velocity_before[c],
                    pull: 2.0 * lift / (t - p.t),
                })
            }
            _ => return Ok(None),
        };
        Ok(zeno::time_left(now, before).map(|left| Bounce {
            contact: c,
            rise,
            left,
        }))
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
        self.decide_held(state, &held, t)
    }

    /// Where the motion starts again from the system's `state` at `t` (s from release), as
    /// after an event: the contacts and friction modes decided there, those `held` (closed
    /// just before) closed where they touch within the run's drift; `friction_work` is the
    /// work done by friction before (J). For a motion taken up mid-phase (the parameters
    /// changed at a time the motion passes through, velocities kept).
    pub fn resume(
        &self,
        state: State,
        t: f64,
        held: &[bool],
        friction_work: f64,
    ) -> Result<PhaseStart, SolveError> {
        let (active, frictions) = self.decide_held(&state, held, t)?;
        Ok(PhaseStart {
            state,
            active,
            frictions,
            t,
            friction_work,
        })
    }

    /// The contacts and friction modes at `state` at `t`, those `held` closed where they touch
    /// within the run's drift, with the friction options they were decided from.
    fn decide_held(
        &self,
        state: &State,
        held: &[bool],
        t: f64,
    ) -> Result<(Active, Vec<FrictionOption>), SolveError> {
        let moment = Moment::After {
            t,
            held,
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
            let scale = c.gap.scale(length);
            let v = contacts::normal_velocity(&jac[i * n..(i + 1) * n], state);
            !c.closed && !c.bilateral && gaps[i] <= DECIDE_TOLERANCE * scale && v < 0.0
        })
        .collect())
}

/// The impact at `state` (at `t`) that closes a converging sequence whose contacts are `held`,
/// in place of `resolved` (the impact as it would be): one contact's bounce made plastic, or,
/// for two contacts or more, each of them held closed, each friction under its law in
/// `resolved` ([`impact::close_sequence`]; `parts` marks them [`Part::Bilateral`]).
fn close(
    sys: &Bound,
    state: &State,
    parts: &mut [Part],
    held: &[usize],
    resolved: &Impact,
    t: f64,
) -> Result<Impact, SolveError> {
    if let [one] = held {
        let mut restitution = sys.restitutions().to_vec();
        restitution[*one] = 0.0;
        return impact::resolve_with(sys, state, parts, &restitution, t);
    }
    for &c in held {
        if parts[c] == Part::Unilateral {
            parts[c] = Part::Bilateral;
        }
    }
    impact::close_sequence(sys, state, parts, &resolved.friction_laws, t)
}

/// The contact that takes part in `impact` and leaves it fastest, faster than `rounding`, with
/// its normal velocity after.
fn fastest_lift(impact: &Impact, parts: &[Part], rounding: f64) -> Option<(usize, f64)> {
    (impact.normal_velocity_after.iter().enumerate())
        .filter(|&(c, &u)| parts[c] == Part::Unilateral && u > rounding)
        .map(|(c, &u)| (c, u))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// A flight too small to resolve ([`Walker::unresolved_bounce`]).
struct Bounce {
    /// The contact that would lift.
    contact: usize,
    /// How far it would rise, relative to the length scale.
    rise: f64,
    /// The time left to the sequence's limit (s).
    left: f64,
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
