//! The integrated route: a model's equations `M(q) qdd = F(q, qd) + J^T lambda + T^T f`
//! integrated with the generic [`ode`](crate::solve::integrated::ode) integrator from a state, with
//! a set of closed contacts, until an event ends the phase: a closed contact's force reaching zero
//! (it would have to pull, so it opens), an open contact's gap closing (the bodies meet), a closed
//! contact running off its edge, or the reduced angle reaching the floor. It is the route of every
//! phase without a fast path, and for the others an independent route to the same events that
//! shares no code with the quadrature.
//!
//! The contacts' forces and the frictions' are solved with the accelerations at every
//! evaluation ([`contacts::dynamics()`]). With Coulomb friction the integration goes in segments,
//! one per combination of friction modes: a segment ends where a sliding contact's slip
//! velocity reaches zero or a stuck contact's friction reaches `mu N`, both located as events;
//! the next segment's modes are the one consistent choice there ([`contacts::decide()`]). The work
//! done by friction is integrated with the motion (the last component of the ODE state), so
//! that the energy check can hold `E(t) - E(0)` to it.
//!
//! A gap that starts at zero (a contact that just opened) or an edge margin that does (a
//! contact point starting at a corner) arms its event only once it has grown past
//! [`DECIDE_TOLERANCE`] of the system's length: its rounding at the
//! start is no crossing.
//!
//! The integrator's state is the deviation `z = y - y0` from the start `y0 = [q, qd]`, so its
//! error control is relative to the motion itself rather than to the absolute angle: a
//! near-upright start lingers by an unstable equilibrium, which amplifies any absolute angle
//! error. The model's equations still take the absolute angle, whose rounding (~1e-16 rad)
//! limits this route to ~1e-11 relative there. The method is chosen by the tolerance
//! ([`Method::for_rtol`]): the 8th-order Dormand–Prince method (DOP853) for tight tolerances,
//! the 5th-order one (DOPRI5) otherwise.
//!
//! The mass matrix is ill-conditioned when the bodies' masses are far apart (for the rod and
//! cube its condition number grows like `m2/m1`): the accelerations then carry a relative
//! rounding error of about `eps * cond(M)`, and so do the contact forces built from them. The
//! integrator's tolerance is therefore never set below [`CONDITION_SAFETY`]` * eps * cond(M)`
//! at the start, and the tolerance actually used is reported in [`UnreducedRun::rtol`].

use crate::model::GapKind;
use crate::results::Work;
use crate::results::{ContactId, ContactSet, EndCause};
use crate::solve::SolveError;
use crate::solve::integrated::contacts::{
    self, Active, ContactOption, DECIDE_TOLERANCE, Dynamics, DynamicsWork, FrictionOption, Mode,
    Options, Sign,
};
use crate::solve::integrated::forward::{self, Forward, Grazing, Measured};
use crate::solve::integrated::ode::{
    Event, Method, OdeOptions, OdeProblem, OdeSolution, integrate as ode_integrate,
};
use crate::system::{Bound, State};
use nalgebra::DMatrix;

/// The tolerance floor is this many times `eps * cond(M)` at the start.
pub const CONDITION_SAFETY: f64 = 10.0;

/// Loosest tolerance worth integrating with.
pub const MAX_RTOL: f64 = 1e-2;

/// Most steps before giving up.
pub const MAX_STEPS: u64 = 200_000;

/// A coordinate's (or velocity's) scale for the absolute tolerances is at least this fraction
/// of the largest of its kind ([`motion_scales`]).
pub const SCALE_FLOOR: f64 = 1e-3;

/// Most stick/slip switches in one integration before giving up (a chattering contact).
pub const MAX_SWITCHES: usize = 1000;

/// The 2-norm condition number of the mass matrix at a state (infinite if singular or not
/// finite).
pub fn mass_condition(sys: &Bound, state: &State) -> Result<f64, SolveError> {
    let n = sys.n_coordinates();
    let (mass, _) = sys.equations(state)?;
    if !mass.iter().all(|m| m.is_finite()) {
        return Ok(f64::INFINITY);
    }
    let sv = DMatrix::from_row_slice(n, n, &mass).singular_values();
    let max = sv.iter().cloned().fold(0.0, f64::max);
    let min = sv.iter().cloned().fold(f64::INFINITY, f64::min);
    Ok(if min > 0.0 && max.is_finite() {
        max / min
    } else {
        f64::INFINITY
    })
}

/// What an event function measures.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Watch {
    /// A closed unilateral contact's force.
    Force(usize),
    /// An open contact's gap.
    Gap(usize),
    /// A closed contact's edge margin.
    Edge(usize),
    /// The reduced angle (the coordinate at this index) above the end angle (a system with
    /// no end angle has no such watch).
    Floor {
        /// The reduced coordinate's index.
        coordinate: usize,
        /// The end angle.
        angle: f64,
    },
    /// A sliding friction's slip velocity (from its offset at the segment's start).
    Slip(usize),
    /// A stuck friction's margin `mu N - |f|`.
    Stuck(usize),
    /// The sliding system's distance from Painlevé's singularity.
    Painleve,
}

/// One stretch of the integration in one active set.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Time of the segment's start (s from the phase's start).
    pub t_start: f64,
    /// The closed contacts and the frictions' modes.
    pub active: Active,
    /// The state `y0 = [q, qd, W]` at the segment's start (`W`, the work of friction so far, only
    /// with friction).
    pub y0: Vec<f64>,
    /// The integration of the deviation `z = y - y0`, in time from the phase's start.
    pub solution: OdeSolution,
}

impl Segment {
    fn add_y0(&self, z: &[f64]) -> Vec<f64> {
        z.iter().zip(&self.y0).map(|(z, y0)| y0 + z).collect()
    }
}

/// A finished integration.
#[derive(Debug, Clone, PartialEq)]
pub struct UnreducedRun {
    /// The segments in order (one without friction).
    pub segments: Vec<Segment>,
    /// The relative tolerance used: the one asked, raised to the conditioning floor.
    pub rtol: f64,
    /// The integration method.
    pub method: Method,
    /// Condition number of the mass matrix at the start.
    pub condition: f64,
    /// Which event ended it.
    pub end: EndCause,
    /// Time of that event (s from the phase's start).
    pub t_end: f64,
    /// The state there.
    pub state_end: State,
    /// Work done by friction up to the end (J, `<= 0`; zero without friction).
    pub friction_work: f64,
    /// The forward sensitivities at the end, where the start had them
    /// ([`Start::sensitivity`]).
    pub sensitivity: Option<EndSensitivity>,
}

/// The forward sensitivities at the end of an integration ([`forward`]).
#[derive(Debug, Clone, PartialEq)]
pub struct EndSensitivity {
    /// `S = dy/dp` at the end, before any jump there: `2 n` values per parameter (`S_q`, then
    /// `S_qd`).
    pub s: Vec<f64>,
    /// `dt_end/dp` (absolute: the start's own dependence is in its `S`), or the grazing event
    /// (this one or a switch before it) whose time has none.
    pub dt: Result<Vec<f64>, Grazing>,
    /// The accelerations at the end in the last active set.
    pub qdd: Vec<f64>,
    /// `dt/dp` of each switch of the friction modes inside the run (the start of each segment
    /// after the first, in order), or the grazing switch whose time has none.
    pub switches: Vec<Result<Vec<f64>, Grazing>>,
}

impl UnreducedRun {
    /// The segment that covers time `t` (the later one at a switch; a few ulps past the end
    /// count as the end, as a sample time `duration * j / (n - 1)` may round there).
    pub fn segment_at(&self, t: f64) -> Option<&Segment> {
        let slack = 4.0 * f64::EPSILON * self.t_end.abs();
        self.segments
            .iter()
            .rev()
            .find(|s| s.t_start <= t && t <= s.solution.t_final() + slack)
    }

    /// `y = [q, qd]` (and `W` with friction) at time `t` from dense output, if `t` lies in the
    /// integrated range.
    pub fn state_at(&self, t: f64) -> Option<Vec<f64>> {
        let seg = self.segment_at(t)?;
        let z = seg.solution.interpolate(t)?;
        Some(seg.add_y0(&z))
    }

    /// Accelerations, contact and friction forces at a state at time `t` of the run, in the
    /// active set of its segment.
    pub fn dynamics_at(&self, sys: &Bound, state: &State, t: f64) -> Result<Dynamics, SolveError> {
        let seg = self.segment_at(t).ok_or(SolveError::Inversion {
            target: t,
            duration: self.t_end,
            reason: "time outside the integrated phase",
        })?;
        contacts::dynamics(sys, state, &seg.active, t)
    }

    /// Time and `y` at the start and at the end of every accepted step, over every segment.
    pub fn nodes(&self) -> Vec<(f64, Vec<f64>)> {
        let mut out = Vec::new();
        for (i, seg) in self.segments.iter().enumerate() {
            // A segment starts where the one before ended: its first node is already there.
            let skip = usize::from(i > 0);
            out.extend(
                (seg.solution.nodes().into_iter().skip(skip)).map(|(t, z)| (t, seg.add_y0(z))),
            );
        }
        out
    }

    /// The full state at the start and at the end of every accepted step.
    pub fn states(&self) -> Vec<State> {
        let n = self.state_end.q.len();
        self.nodes()
            .into_iter()
            .map(|(_, y)| State {
                q: y[..n].to_vec(),
                qd: y[n..2 * n].to_vec(),
            })
            .collect()
    }

    /// The segment of each node of [`Self::nodes`] (by index).
    pub fn node_segments(&self) -> Vec<usize> {
        let mut out = Vec::new();
        for (i, seg) in self.segments.iter().enumerate() {
            let skip = usize::from(i > 0);
            let count = seg.solution.nodes().len().saturating_sub(skip);
            out.extend(std::iter::repeat_n(i, count));
        }
        out
    }

    /// The work done by friction at every node of [`Self::nodes`] (zeros without friction,
    /// whose state has no such component).
    pub fn node_friction_work(&self) -> Vec<f64> {
        let n = self.state_end.q.len();
        self.nodes()
            .into_iter()
            .map(|(_, y)| if y.len() > 2 * n { y[2 * n] } else { 0.0 })
            .collect()
    }

    /// When each segment started, with its active set by name.
    pub fn switches<'a>(&'a self, sys: &'a Bound) -> impl Iterator<Item = (f64, ContactSet)> + 'a {
        (self.segments.iter()).map(move |s| (s.t_start, s.active.set(sys.info())))
    }

    /// Every step taken (accepted, rejected and event trials).
    pub fn steps(&self) -> u64 {
        self.segments.iter().map(|s| s.solution.total_steps()).sum()
    }
}

struct Problem<'a, 'm> {
    sys: &'a Bound<'m>,
    n: usize,
    active: Active,
    watches: Vec<Watch>,
    /// Per watch, whether it is armed (a gap or edge margin that starts at zero arms once it
    /// has grown past `arm_at`).
    armed: Vec<bool>,
    arm_at: f64,
    /// Per friction, the slip velocity its event measures from: the rounding-level slip at the
    /// start of a contact that just switched (so that it does not count as a crossing), zero
    /// for one that keeps sliding.
    slip_offset: Vec<f64>,
    /// The reduced coordinate's index and the end angle, where the system has one.
    floor: Option<(usize, f64)>,
    y0: Vec<f64>,
    y: Vec<f64>,
    state: State,
    /// The buffers of the contact solve and the dynamics of the last right-hand side
    /// (`work.out`), at `last_z` while `last_valid`: the integrator asks for the events at the
    /// state it has just evaluated.
    work: DynamicsWork,
    last_z: Vec<f64>,
    last_valid: bool,
    with_work: bool,
    /// Right-hand sides evaluated.
    evaluations: u64,
    /// The forward sensitivities riding along after the state's `base` components.
    riders: Option<Riders>,
    base: usize,
}

impl Problem<'_, '_> {
    /// Marks `work.out` as the dynamics at `z`.
    fn remember(&mut self, z: &[f64]) {
        self.last_z.clear();
        self.last_z.extend_from_slice(z);
        self.last_valid = true;
    }

    /// Sets `y = y0 + z` and the state from it.
    fn load(&mut self, z: &[f64]) {
        for ((y, y0), z) in self.y.iter_mut().zip(&self.y0).zip(z) {
            *y = y0 + z;
        }
        self.state.q.copy_from_slice(&self.y[..self.n]);
        self.state.qd.copy_from_slice(&self.y[self.n..2 * self.n]);
    }

    /// The events of the active set: each closed unilateral contact's force (a row's, or in
    /// closed form where the model eliminates it), each open contact's gap, each closed
    /// contact's edge, the floor, then the acting frictions' and Painlevé's; armed where they
    /// start clear of zero.
    fn watch(&mut self, d: &Dynamics) -> Result<(), SolveError> {
        let info = self.sys.info();
        let mut watches = Vec::new();
        for (i, c) in info.contacts.iter().enumerate() {
            match (self.active.closed[i], c.bilateral) {
                (true, false) => watches.push(Watch::Force(i)),
                (false, _) => watches.push(Watch::Gap(i)),
                _ => {}
            }
            if self.active.closed[i] && c.edge {
                watches.push(Watch::Edge(i));
            }
        }
        if let Some((coordinate, angle)) = self.floor {
            watches.push(Watch::Floor { coordinate, angle });
        }
        let mut sliding = false;
        for j in 0..info.frictions.len() {
            if self.active.friction_acts(info, j) {
                watches.push(match self.active.modes[j] {
                    Mode::Slide(_) => {
                        sliding = true;
                        Watch::Slip(j)
                    }
                    Mode::Stick => Watch::Stuck(j),
                });
            }
        }
        if sliding {
            watches.push(Watch::Painleve);
        }
        self.watches = watches;
        let mut g = vec![0.0; self.watches.len()];
        self.values(d, &mut g)?;
        self.armed = (self.watches.iter().zip(&g))
            .map(|(w, v)| match w {
                Watch::Gap(_) | Watch::Edge(_) | Watch::Force(_) => *v > self.arm_at_for(*w),
                _ => true,
            })
            .collect();
        Ok(())
    }

    /// The value past which a watch of this kind arms.
    fn arm_at_for(&self, w: Watch) -> f64 {
        match w {
            Watch::Force(_) => 0.0,
            _ => self.arm_at,
        }
    }

    /// Every watch's value at the loaded state with its dynamics `d`.
    fn values(&self, d: &Dynamics, g: &mut [f64]) -> Result<(), SolveError> {
        let info = self.sys.info();
        let needs_gaps = self.watches.iter().any(|w| matches!(w, Watch::Gap(_)));
        let needs_edges = self.watches.iter().any(|w| matches!(w, Watch::Edge(_)));
        let gaps = if needs_gaps {
            self.sys.gaps(&self.state)?
        } else {
            Vec::new()
        };
        let edges = if needs_edges {
            self.sys.edges(&self.state)?
        } else {
            Vec::new()
        };
        let mu = self.sys.friction_coefficients();
        for (v, w) in g.iter_mut().zip(&self.watches) {
            *v = match *w {
                Watch::Force(i) => d.forces[i],
                Watch::Gap(i) => gaps[i],
                Watch::Edge(i) => edges[i],
                Watch::Floor { coordinate, angle } => self.state.q[coordinate] - angle,
                Watch::Slip(j) => {
                    let v = d.slip[j] - self.slip_offset[j];
                    // A slide that starts from zero slip (from rest, or just switched) has its
                    // mode's sign from its first instant: a step that carries the slip out and
                    // back across zero is then a crossing, not a start at zero and an end past it.
                    match self.active.modes[j] {
                        Mode::Slide(sign) if v == 0.0 => sign.value() * f64::MIN_POSITIVE,
                        _ => v,
                    }
                }
                Watch::Stuck(j) => {
                    mu[j] * d.forces[info.frictions[j].contact_index] - d.fr[j].abs()
                }
                Watch::Painleve => d.painleve - contacts::PAINLEVE_FLOOR,
            };
        }
        Ok(())
    }

    /// Contact `i` of the system, as an end names it.
    fn contact(&self, i: usize) -> Result<ContactId, SolveError> {
        let info = self.sys.info();
        ContactId::of(info, i).ok_or_else(|| SolveError::PhaseMismatch {
            system: info.system,
            name: info.name,
            why: format!("an event watches contact {i}, which the system does not have"),
        })
    }

    /// What an event ends: the run (at `until`, the run's end time, or at a contact's event) or
    /// only the segment, at the friction watch whose switch goes on with it. `y` is the state
    /// there (for the error of an event no watch has).
    fn ending(
        &self,
        until: bool,
        event: &Event,
        y: &[f64],
    ) -> Result<Result<EndCause, Watch>, SolveError> {
        if until {
            return Ok(Ok(EndCause::Until));
        }
        Ok(match self.watches.get(event.index).copied() {
            Some(Watch::Force(i)) => Ok(EndCause::Force(self.contact(i)?)),
            Some(Watch::Gap(i)) => Ok(EndCause::Contact(self.contact(i)?)),
            Some(Watch::Edge(i)) => Ok(EndCause::Edge(self.contact(i)?)),
            Some(Watch::Floor { .. }) => Ok(EndCause::Floor),
            // A friction's switch located where the reduced angle is already at or past the
            // end angle: the two roots coincide to the located time's ulps (a ladder lying flat
            // against the wall's foot stops its foot's slip, `ell sin(theta) theta'`, exactly at
            // the floor), and the run ends at the floor, past which the model describes nothing.
            Some(_) if self.floor_reached(y) => Ok(EndCause::Floor),
            Some(watch) => Err(watch),
            None => {
                return Err(SolveError::OdeNonFinite {
                    what: "event index outside the watched events",
                    t: event.t,
                    y: y.to_vec(),
                });
            }
        })
    }

    /// Whether the state `y` has the reduced angle at or past the end angle (where the system
    /// has one, and only where its floor is watched).
    fn floor_reached(&self, y: &[f64]) -> bool {
        (self.watches.iter()).any(|w| match *w {
            Watch::Floor { coordinate, angle } => y[coordinate] - angle <= 0.0,
            _ => false,
        })
    }

    /// At friction watch `w` (a contact's slip stopped or its stuck friction reached `mu N`),
    /// the next modes: the one consistent choice, the contacts kept as they are.
    fn switch(&mut self, w: Watch, state: &State, t: f64) -> Result<(), SolveError> {
        let info = self.sys.info();
        if w == Watch::Painleve {
            return Err(contacts::painleve_error(self.sys, state, &self.active, t));
        }
        // A stuck contact breaks loose against the friction that held it.
        let held = contacts::dynamics(self.sys, state, &self.active, t)?;
        let frictions: Vec<FrictionOption> = (0..info.frictions.len())
            .map(|j| match (w, self.active.modes[j]) {
                (Watch::Slip(k), Mode::Slide(s)) if k == j => FrictionOption::Stopped(s),
                (Watch::Stuck(k), Mode::Stick) if k == j => {
                    FrictionOption::Breaks(Sign::of(-held.fr[j]))
                }
                (_, mode) => FrictionOption::Keep(mode),
            })
            .collect();
        let options = Options {
            contacts: self
                .active
                .closed
                .iter()
                .map(|&c| ContactOption::Keep(c))
                .collect(),
            frictions: frictions.clone(),
        };
        self.active = contacts::decide(self.sys, state, &options, t)?;
        self.slip_offset = slip_offsets(self.sys, state, &frictions)?;
        self.last_valid = false;
        Ok(())
    }
}

/// The checks of an integration's start (its active set's size, the mass matrix's
/// conditioning) and the tolerance it is run at, raised to the conditioning floor, with the
/// condition number.
fn checked_start(sys: &Bound, start: &Start, rtol: f64) -> Result<(f64, f64), SolveError> {
    let info = sys.info();
    contacts::check_active(info, &start.active)?;
    if start.frictions.len() != info.frictions.len() {
        return Err(SolveError::ActiveSize {
            model: info.name,
            contacts: info.contacts.len(),
            frictions: info.frictions.len(),
            closed: start.active.closed.len(),
            modes: start.frictions.len(),
        });
    }
    let condition = mass_condition(sys, &start.state)?;
    let rtol = rtol.max(CONDITION_SAFETY * f64::EPSILON * condition);
    if rtol.is_nan() || rtol > MAX_RTOL {
        return Err(SolveError::IllConditioned {
            model: info.name,
            condition,
            rtol,
        });
    }
    Ok((rtol, condition))
}

/// What watch `w` measures, for its time's derivatives.
fn measured(w: Watch) -> Measured {
    match w {
        Watch::Force(i) => Measured::Force(i),
        Watch::Gap(i) => Measured::Gap(i),
        Watch::Edge(i) => Measured::Edge(i),
        Watch::Floor { coordinate, .. } => Measured::Coordinate(coordinate),
        Watch::Slip(j) => Measured::Slip(j),
        Watch::Stuck(j) => Measured::Stuck(j),
        // Painlevé's watch ends the run with an error; its time is never differentiated.
        Watch::Painleve => Measured::Clock,
    }
}

/// The forward sensitivities of an integration ([`forward`]).
struct Riders {
    fw: Forward,
    /// `S` at the last event (or the start).
    s: Vec<f64>,
    /// A switch whose time had no derivative: `S` after it is not defined.
    grazed: Option<Grazing>,
    /// `dt/dp` of each switch so far.
    switches: Vec<Result<Vec<f64>, Grazing>>,
}

impl Riders {
    /// The sensitivities `s0` at a start (none without them), for `sys`'s model, which must
    /// have its tangents.
    fn new(sys: &Bound, s0: Option<&[f64]>) -> Result<Option<Riders>, SolveError> {
        let Some(s0) = s0 else {
            return Ok(None);
        };
        let fw = Forward::new(sys)?;
        if s0.len() != fw.len() {
            return Err(crate::system::SystemError::Length {
                model: sys.info().name,
                what: "sensitivity",
                expected: fw.len(),
                got: s0.len(),
            }
            .into());
        }
        Ok(Some(Riders {
            fw,
            s: s0.to_vec(),
            grazed: None,
            switches: Vec::new(),
        }))
    }

    /// The sensitivities at the run's end, an event measuring `what` at `at` (its state, time
    /// and the active set before it).
    fn at_end(
        mut self,
        sys: &Bound,
        work: &mut DynamicsWork,
        at: (&State, f64, &Active),
        what: Measured,
    ) -> Result<EndSensitivity, SolveError> {
        let (dt, qdd) = self.fw.event_times(sys, at, work, &self.s, what)?;
        let dt = match self.grazed {
            Some(g) => Err(g),
            None => dt,
        };
        Ok(EndSensitivity {
            s: self.s,
            dt,
            qdd,
            switches: self.switches,
        })
    }

    /// `S` across a switch of the friction modes to `after`, an event measuring `what` at `at`
    /// (its state, time and the active set before it).
    fn across(
        &mut self,
        sys: &Bound,
        work: &mut DynamicsWork,
        at: (&State, f64, &Active),
        after: &Active,
        what: Measured,
    ) -> Result<(), SolveError> {
        let (dt, before) = self.fw.event_times(sys, at, work, &self.s, what)?;
        let dt = match self.grazed {
            Some(g) => Err(g),
            None => dt,
        };
        match &dt {
            Ok(dt) => {
                let after = contacts::dynamics(sys, at.0, after, at.1)?;
                forward::jump(&mut self.s, &before, &after.qdd, dt);
            }
            Err(g) => self.grazed = Some(*g),
        }
        self.switches.push(dt);
        Ok(())
    }
}

/// The slip velocity each friction's event measures from at a segment's start: its own slip
/// for a contact that may have switched there, zero for one that keeps its mode.
fn slip_offsets(
    sys: &Bound,
    state: &State,
    options: &[FrictionOption],
) -> Result<Vec<f64>, SolveError> {
    let n = sys.n_coordinates();
    let (jac, _) = sys.friction(state)?;
    // One option per friction (checked by `integrate`): `jac` has a row for each.
    Ok((options.iter().enumerate())
        .map(|(k, o)| match o {
            FrictionOption::Keep(_) => 0.0,
            _ => (0..n).map(|j| jac[k * n + j] * state.qd[j]).sum(),
        })
        .collect())
}

impl OdeProblem for Problem<'_, '_> {
    fn dim(&self) -> usize {
        self.base + self.riders.as_ref().map_or(0, |r| r.fw.len())
    }

    fn rhs(&mut self, t: f64, z: &[f64], dz: &mut [f64]) -> Result<(), SolveError> {
        self.evaluations += 1;
        self.load(z);
        self.last_valid = false;
        contacts::dynamics_into(self.sys, &self.state, &self.active, t, &mut self.work)?;
        let d = &self.work.out;
        dz[..self.n].copy_from_slice(&self.state.qd);
        dz[self.n..2 * self.n].copy_from_slice(&d.qdd);
        if self.with_work {
            dz[2 * self.n] = d.friction_power();
        }
        if let Some(r) = self.riders.as_mut() {
            let at = (&self.state, t, &self.active);
            let (s, ds) = (&z[self.base..], &mut dz[self.base..]);
            r.fw.rhs(self.sys, at, &mut self.work, s, ds)?;
        }
        self.remember(z);
        Ok(())
    }

    fn n_events(&self) -> usize {
        self.watches.len()
    }

    /// A gap or edge margin past its zero is an overlap, which the contact decision after the
    /// event tolerates only within [`DECIDE_TOLERANCE`] (of the system's length for one in
    /// metres): half of that. Past their zeros the others are what the event means and what
    /// follows it expects (a force below zero opens, a slip past zero has stopped, a stuck
    /// friction beyond `mu N` breaks, the angle past the floor has landed), however far.
    fn event_slack(&self, index: usize) -> f64 {
        let info = self.sys.info();
        match self.watches.get(index) {
            Some(Watch::Gap(i)) if info.contacts[*i].gap == GapKind::Angle => {
                0.5 * DECIDE_TOLERANCE
            }
            Some(Watch::Gap(_) | Watch::Edge(_)) => 0.5 * self.arm_at,
            _ => f64::INFINITY,
        }
    }

    fn events(&mut self, t: f64, z: &[f64], _dz: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        self.load(z);
        if !(self.last_valid && self.last_z == z) {
            self.last_valid = false;
            contacts::dynamics_into(self.sys, &self.state, &self.active, t, &mut self.work)?;
            self.remember(z);
        }
        self.values(&self.work.out, g)?;
        for (k, v) in g.iter_mut().enumerate() {
            if !self.armed[k] {
                let watch = self.watches[k];
                let arm_at = self.arm_at_for(watch);
                // A gap or edge margin clear of zero on the wrong side (one that opened and
                // closed again without growing past `arm_at`, or within one step: the bodies
                // now overlap) goes through and arms, so that the integrator locates where it
                // crossed zero itself (its values inside the step are the true ones).
                let through = matches!(watch, Watch::Gap(_) | Watch::Edge(_)) && *v < -arm_at;
                if *v > arm_at || through {
                    self.armed[k] = true;
                } else {
                    // Unarmed: no crossing while it has not grown clear of zero.
                    *v = 1.0;
                }
            }
        }
        Ok(())
    }
}

/// Typical sizes of the motion's deviation from its start over the time scale `time`, for the
/// integrator's absolute tolerances: `|qd0| T + |qdd0| T^2 / 2` for the coordinates and
/// `|qd0| + |qdd0| T` for the velocities, each at least [`SCALE_FLOOR`] of the largest of its
/// kind and at least [`SCALE_FLOOR`] of the change of that coordinate that moves a point of
/// the system by its length (and that change over `T` for the velocities). So a tiny system (a
/// rod of 1 cm nearly flat) is held to its own scale, not to one metre; a coordinate a closed
/// contact holds still (the foot's height on the floor, whose acceleration is rounding noise
/// of the constraint's) is held to the motion's scale, not to its own noise, which would
/// shrink the steps to nothing; and a start that is slow at release (nearly upright) is held
/// to the system's size, not to its first creeping.
///
/// A state or accelerations that do not fit the model are an error.
pub fn motion_scales(
    bound: &Bound,
    start: &State,
    qdd: &[f64],
    time: f64,
) -> Result<Vec<f64>, SolveError> {
    let n = start.q.len();
    let length = bound.length_scale(start)?;
    if qdd.len() != n {
        return Err(crate::system::SystemError::Length {
            model: bound.name(),
            what: "qdd",
            expected: n,
            got: qdd.len(),
        }
        .into());
    }
    // Per coordinate: the change that moves some point by `length` (m per m, or rad).
    let mut reach = Vec::with_capacity(n);
    for j in 0..n {
        let mut unit = State {
            q: start.q.clone(),
            qd: vec![0.0; n],
        };
        unit.qd[j] = 1.0;
        let speed = (bound.points(&unit)?.vel.iter())
            .map(|v| v[0].hypot(v[1]))
            .fold(0.0f64, f64::max);
        reach.push(if speed > 0.0 && speed.is_finite() {
            length / speed
        } else {
            0.0
        });
    }
    let q: Vec<f64> = (start.qd.iter().zip(qdd))
        .map(|(v, a)| v.abs() * time + 0.5 * a.abs() * time * time)
        .collect();
    let v: Vec<f64> = (start.qd.iter().zip(qdd))
        .map(|(v, a)| v.abs() + a.abs() * time)
        .collect();
    let floor = |x: Vec<f64>, per: f64| {
        let top = x.iter().cloned().fold(0.0, f64::max);
        (x.into_iter().zip(&reach))
            .map(|(s, r)| {
                let own = if time > 0.0 { r * per } else { 0.0 };
                s.max(SCALE_FLOOR * top)
                    .max(SCALE_FLOOR * own)
                    .max(f64::MIN_POSITIVE)
            })
            .collect::<Vec<f64>>()
    };
    let mut scales = floor(q, 1.0);
    scales.extend(floor(v, 1.0 / time));
    Ok(scales)
}

/// What an integration starts from and how long it may run.
#[derive(Debug, Clone)]
pub struct Start {
    /// The state.
    pub state: State,
    /// The closed contacts and friction modes there (see [`contacts::decide()`]).
    pub active: Active,
    /// The friction options it was decided from (their slips' offsets start the slip events).
    pub frictions: Vec<FrictionOption>,
    /// Work done by friction before the start (J).
    pub friction_work: f64,
    /// Where the run is asked to stop (s from this start) if no event comes first: it then
    /// ends there with [`EndCause::Until`]. `None`: only an event ends it.
    pub stop_at: Option<f64>,
    /// Keep every step's continuous extension, for sampling the run between its steps
    /// ([`UnreducedRun::state_at`]; [`OdeOptions::dense_output`]).
    pub dense_output: bool,
    /// The forward sensitivities `S = dy/dp` at the start (`2 n` values per parameter: `S_q`,
    /// then `S_qd`; [`forward`]), to integrate with the motion: the run's end then has them
    /// ([`UnreducedRun::sensitivity`]). The model must have
    /// [`Model::tangents`](crate::model::Model::tangents). `None`: no sensitivities.
    pub sensitivity: Option<Vec<f64>>,
}

/// The integrator's absolute tolerances: `rtol` times each of `scales` (length `2 n`; none
/// without them), and with friction the work's, held to the energy's own scale.
fn absolute_tolerances(
    sys: &Bound,
    start: &Start,
    scales: Option<&[f64]>,
    rtol: f64,
    with_work: bool,
) -> Result<Vec<f64>, SolveError> {
    let n = sys.n_coordinates();
    let mut atol: Vec<f64> = match scales {
        Some(s) if s.len() == 2 * n => s
            .iter()
            .map(|v| rtol * v.abs().max(f64::MIN_POSITIVE))
            .collect(),
        _ => Vec::new(),
    };
    if with_work && !atol.is_empty() {
        let e = sys.energy(&start.state)?.abs();
        atol.push(rtol * if e > 0.0 { e } else { 1.0 });
    }
    Ok(atol)
}

/// The end of a solution that reached the start's `stop_at` without an event, as an event at
/// that time (its index is never read).
fn until_event(solution: &OdeSolution, stop_at: Option<f64>) -> Option<Event> {
    let stop = stop_at?;
    let last = solution.steps.last()?;
    let reached = (solution.t_final() - stop).abs() <= 4.0 * f64::EPSILON * stop.abs();
    reached.then(|| Event {
        index: usize::MAX,
        t: stop,
        y: last.y1.clone(),
    })
}

/// Integrates `sys` from `start` until an event ends the phase, with relative tolerance
/// `rtol` (raised to [`CONDITION_SAFETY`]` * eps * cond(M)`) by the method
/// [`Method::for_rtol`] picks for it. `scales` (length `2 n`), when given, are typical
/// magnitudes of the motion `y - y0` for the absolute tolerances; without them the control is
/// relative to the largest deviation seen. `t_max` bounds the search: reaching it is
/// [`SolveError::NoEvent`], unless the start's `stop_at` comes first (the run then ends there,
/// [`EndCause::Until`]).
pub fn integrate(
    sys: &Bound,
    start: &Start,
    rtol: f64,
    scales: Option<&[f64]>,
    t_max: f64,
    work: &mut Work,
) -> Result<UnreducedRun, SolveError> {
    integrate_with(sys, start, rtol, None, scales, t_max, work)
}

/// [`integrate`] by `method` when one is given (`rodcube accuracy` compares the two at every
/// tolerance), else by the method [`Method::for_rtol`] picks for the raised tolerance.
pub fn integrate_with(
    sys: &Bound,
    start: &Start,
    rtol: f64,
    method: Option<Method>,
    scales: Option<&[f64]>,
    t_max: f64,
    work: &mut Work,
) -> Result<UnreducedRun, SolveError> {
    let info = sys.info();
    let n = sys.n_coordinates();
    let with_work = !info.frictions.is_empty();
    let (rtol, condition) = checked_start(sys, start, rtol)?;
    let method = method.unwrap_or_else(|| Method::for_rtol(rtol));
    let mut y0 = start.state.q.clone();
    y0.extend_from_slice(&start.state.qd);
    if with_work {
        y0.push(start.friction_work);
    }
    let mut problem = Problem {
        sys,
        n,
        active: start.active.clone(),
        watches: Vec::new(),
        armed: Vec::new(),
        arm_at: DECIDE_TOLERANCE * sys.length_scale(&start.state)?,
        slip_offset: slip_offsets(sys, &start.state, &start.frictions)?,
        floor: (info.reduced_index).zip(info.end_angle),
        y0: y0.clone(),
        y: y0.clone(),
        state: start.state.clone(),
        work: DynamicsWork::default(),
        last_z: Vec::new(),
        last_valid: false,
        with_work,
        evaluations: 0,
        riders: None,
        base: y0.len(),
    };
    // The sensitivities ride after the state; `S` is integrated as itself, not as a deviation.
    problem.riders = Riders::new(sys, start.sensitivity.as_deref())?;
    let d = contacts::dynamics(sys, &start.state, &problem.active, 0.0)?;
    problem.watch(&d)?;
    let atol = absolute_tolerances(sys, start, scales, rtol, with_work)?;
    let stop_at = start.stop_at.filter(|s| *s <= t_max);
    let opts = OdeOptions {
        controlled: Some(y0.len()),
        rtol,
        atol,
        t_max: stop_at.unwrap_or(t_max),
        max_steps: MAX_STEPS,
        dense_output: start.dense_output,
    };
    let mut segments = Vec::new();
    let mut t0 = 0.0;
    loop {
        let mut z0 = vec![0.0; y0.len()];
        if let Some(r) = &problem.riders {
            z0.extend_from_slice(&r.s);
        }
        let solution = ode_integrate(method, &mut problem, t0, &z0, &opts);
        work.ode_evaluations += std::mem::take(&mut problem.evaluations);
        let solution = solution?;
        work.ode_steps += solution.total_steps();
        let Some(event) = solution
            .event
            .clone()
            .or_else(|| until_event(&solution, stop_at))
        else {
            return Err(SolveError::NoEvent { t_max });
        };
        let y: Vec<f64> = (event.y.iter().zip(&y0)).map(|(z, y0)| y0 + z).collect();
        if let Some(r) = problem.riders.as_mut() {
            r.s.copy_from_slice(&event.y[y0.len()..]);
        }
        segments.push(Segment {
            t_start: t0,
            active: problem.active.clone(),
            y0: y0.clone(),
            solution,
        });
        let state = State {
            q: y[..n].to_vec(),
            qd: y[n..2 * n].to_vec(),
        };
        // The run's end, or the watch whose switch goes on with it.
        let until = segments.last().is_some_and(|g| g.solution.event.is_none());
        let watch = match problem.ending(until, &event, &y)? {
            Ok(end) => {
                let measured = match end {
                    EndCause::Force(c) => Measured::Force(c.index),
                    EndCause::Contact(c) => Measured::Gap(c.index),
                    EndCause::Edge(c) => Measured::Edge(c.index),
                    // An impact elsewhere ends a contact's hold, never an integrated run.
                    EndCause::Impact => {
                        return Err(SolveError::PhaseMismatch {
                            system: problem.sys.info().system,
                            name: problem.sys.info().name,
                            why: "an integrated run ended at an impact elsewhere".into(),
                        });
                    }
                    EndCause::Floor => match problem.floor {
                        Some((coordinate, _)) => Measured::Coordinate(coordinate),
                        None => Measured::Clock,
                    },
                    EndCause::Until => Measured::Clock,
                };
                let at = (&state, event.t, &problem.active);
                let sensitivity = match problem.riders.take() {
                    Some(r) => Some(r.at_end(problem.sys, &mut problem.work, at, measured)?),
                    None => None,
                };
                return Ok(UnreducedRun {
                    sensitivity,
                    segments,
                    rtol,
                    method,
                    condition,
                    end,
                    t_end: event.t,
                    friction_work: if with_work { y[2 * n] } else { 0.0 },
                    state_end: state,
                });
            }
            Err(watch) => watch,
        };
        if segments.len() > MAX_SWITCHES {
            return Err(SolveError::TooManySwitches {
                model: info.name,
                switches: segments.len() - 1,
                t: event.t,
            });
        }
        let before = problem.active.clone();
        problem.switch(watch, &state, event.t)?;
        if let Some(r) = problem.riders.as_mut() {
            let at = (&state, event.t, &before);
            let (work, after) = (&mut problem.work, &problem.active);
            r.across(sys, work, at, after, measured(watch))?;
        }
        problem.state = state;
        y0 = y;
        problem.y0 = y0.clone();
        let d = contacts::dynamics(sys, &problem.state, &problem.active, event.t)?;
        problem.watch(&d)?;
        t0 = event.t;
    }
}
