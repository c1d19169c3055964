//! How a system's motion is solved ([`Walker`]): the contacts decided at release and after every
//! event, each phase on its route, phase after phase until one ends for good, and through
//! impacts (Zeno's bounces caught) where the run goes on to a time; with the limits that halt
//! it and a fast phase's start parameters ([`phase_parameters`]); a converging sequence is
//! closed at its accumulation time.

use super::motion::{ImpactAt, Motion};
use super::reduced::{ReducedEnd, ReducedRun, phase_end};
use super::run::{IntegratedRun, PhaseRun};
use crate::model::{GapKind, Model, ModelInfo};
use crate::results::{Halt, Work, Zeno};
use crate::solve::SolveError;
use crate::solve::contacts::{
    self, Active, ContactOption, DECIDE_TOLERANCE, FrictionOption, Moment, Options,
    contact_options, friction_options,
};
use crate::solve::impact::{self, Impact, Part};
use crate::solve::inversion::delta_at_time;
use crate::solve::ode::Method;
use crate::solve::quadrature::TimeMesh;
use crate::solve::unreduced::{self, End, EndSensitivity, Start, motion_scales};
use crate::system::{Bound, State, System, SystemError};

/// Most phases chained between two impacts (or from release to the first) before giving up:
/// contacts that keep opening and closing without an impact are chatter, not a motion.
pub const MAX_PHASES: usize = 16;

/// Most impacts in one run. A run that reaches it stops there with a note (a bouncing sequence
/// that neither converges as Zeno's nor comes to rest).
pub const MAX_IMPACTS: usize = 1000;

/// Bounces at one contact whose intervals shrink by a steady ratio (the last
/// [`ZENO_RATIOS`] ratios below one and within this fraction of each other) converge: once the
/// time left to their limit, `dt r / (1 - r)`, is within the run's tolerance of the time from
/// release, the rest of them is summed as a geometric series: one plastic impact, listed at
/// their limit.
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
            Err(SolveError::AtRest { t, how, .. }) => {
                let t = (motion.impacts.last()).map_or(t, |i| i.zeno.unwrap_or(t));
                motion.halted = Some(Halt::AtRest { t, how });
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// The impact that ends the motion's last phase, where contact `closing` closed: every
    /// contact closed then, `closing` and any other open one that touches while approaching take
    /// part, with their frictions (`impact::resolve_with`). Bounces
    /// converging as Zeno's (`zeno_limit`) are closed by a plastic impact, with a note.
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
        let name = info.contacts[closing].name;
        let mut restitution = general.restitutions().to_vec();
        let limit = zeno_limit(&motion.impacts, closing, t, self.tol);
        if limit.is_some() {
            restitution[closing] = 0.0;
        }
        let mut impact = impact::resolve_with(general, &state, &parts, &restitution, t)?;
        let mut accumulation = None;
        if let Some((ratio, t_limit, bounces)) = limit {
            accumulation = Some(t_limit);
            motion.notes.push(Zeno::Limit {
                contact: name.to_string(),
                bounces,
                ratio,
                t_limit,
                t,
            });
        } else if let Some((rise, flight)) = self.unresolved_bounce(&impact, &parts, closing, t)? {
            // The bounces left, each `e` times the one before (the pull back constant over
            // them, as under gravity): their flights sum to `flight / (1 - e)`.
            let left = flight / (1.0 - restitution[closing]).max(f64::EPSILON);
            restitution[closing] = 0.0;
            impact = impact::resolve_with(general, &state, &parts, &restitution, t)?;
            accumulation = Some(t + left);
            motion.notes.push(Zeno::Unresolved {
                contact: name.to_string(),
                t,
                rise,
                open_gap: DECIDE_TOLERANCE,
                bounces: sequence_times(&motion.impacts, closing, t).len(),
                t_limit: t + left,
            });
        }
        Ok(ImpactAt {
            t,
            phase,
            closing,
            parts,
            impact,
            zeno: accumulation,
        })
    }

    /// How high (relative to the system's length scale) contact `closing` would rise after
    /// `impact`, where that is below [`DECIDE_TOLERANCE`] (the gap at which a contact counts as
    /// open), and for how long (s): its normal velocity after squared over twice its normal
    /// acceleration pulling it back, and twice the velocity over that acceleration, with it
    /// open and the other contacts decided at the state after. `None` for a contact that stays
    /// closed (its velocity after within [`impact::IMPACT_TOLERANCE`] of its approach speed),
    /// is not pulled back, or rises clear.
    fn unresolved_bounce(
        &self,
        impact: &Impact,
        parts: &[Part],
        closing: usize,
        t: f64,
    ) -> Result<Option<(f64, f64)>, SolveError> {
        let u = impact.normal_velocity_after[closing];
        // A plastic contact's velocity after is zero but for rounding: no bounce to sum (its
        // flight, `2 u / pull`, would be rounding over rounding).
        let rounding = impact::IMPACT_TOLERANCE * impact.normal_velocity_before[closing].abs();
        if u <= rounding {
            return Ok(None);
        }
        let state = &impact.after;
        let (active, _) = self.decide_after(state, parts, t)?;
        let pull = -contacts::dynamics(&self.general, state, &active, t)?.normal_acc[closing];
        if pull <= 0.0 {
            return Ok(None);
        }
        let info = self.general.info();
        let scale = match info.contacts[closing].gap {
            GapKind::Length => self.general.length_scale(state)?,
            GapKind::Angle => 1.0,
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

/// Whether the bounces at contact `closing` before an impact at `t` converge as Zeno's: the
/// last [`ZENO_RATIOS`] ratios of successive intervals between impacts at that contact are
/// below one and agree within [`ZENO_RATIO_SPREAD`], and the time left to their limit is within
/// `tol` of `t`. Returns the ratio, the limit's time and the bounces counted.
fn zeno_limit(impacts: &[ImpactAt], closing: usize, t: f64, tol: f64) -> Option<(f64, f64, usize)> {
    let times = sequence_times(impacts, closing, t);
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

/// The times of the impacts at contact `closing` that end `impacts` (one after another, no
/// other contact's between), and `t`'s: the bounces of a sequence so far.
fn sequence_times(impacts: &[ImpactAt], closing: usize, t: f64) -> Vec<f64> {
    let mut times: Vec<f64> = (impacts.iter().rev())
        .take_while(|i| i.closing == closing)
        .map(|i| i.t)
        .collect();
    times.reverse();
    times.push(t);
    times
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
