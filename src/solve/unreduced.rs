//! The unreduced equations `M(q) qdd = F(q, qd)` of a model as an ODE, integrated with
//! [`ode::dopri5`](crate::solve::ode::dopri5) from the release state until the contact force
//! crosses zero (separation), the contact runs off its edge, or the reduced angle reaches the
//! floor: the route of every model without a fast path, and for the others an independent
//! route to the separation time that shares no code with the quadrature.
//!
//! A model with Coulomb friction is integrated in segments, one per combination of contact
//! modes ([`friction::Mode`]): a segment ends where a sliding contact's slip velocity reaches
//! zero or a stuck contact's friction reaches `mu N`, both located as events; the next
//! segment's modes are the one consistent choice there ([`friction::decide`]). The work done by
//! friction is integrated with the motion (the last component of the ODE state), so that the
//! energy check can hold `E(t) - E(0)` to it.
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
use crate::solve::friction::{self, Dynamics, Mode, Options};
use crate::solve::ode::{OdeOptions, OdeProblem, OdeSolution, dopri5};
use crate::system::{Bound, State};
use nalgebra::{DMatrix, DVector};

/// The tolerance floor is this many times `eps * cond(M)` at release.
pub const CONDITION_SAFETY: f64 = 10.0;

/// Loosest tolerance worth integrating with: beyond it the cross-check says nothing.
pub const MAX_RTOL: f64 = 1e-2;

/// Most steps before giving up.
pub const MAX_STEPS: u64 = 200_000;

/// Most stick/slip switches in one integration before giving up (a chattering contact).
pub const MAX_SWITCHES: usize = 1000;

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

/// Accelerations `qdd` solving `M(q) qdd = F(q, qd)` at a state (`t` labels errors), for a
/// model without friction (whose accelerations depend on the contacts' modes: see
/// [`friction::dynamics`]).
pub fn accelerations(sys: &Bound, state: &State, t: f64) -> Result<Vec<f64>, SolveError> {
    let n = sys.n_coordinates();
    let m = sys.info().frictions.len();
    if m > 0 {
        return Err(SolveError::FrictionModes {
            model: sys.name(),
            expected: m,
            got: 0,
        });
    }
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

/// The accelerations, friction and reaction forces at release, with the friction contacts in
/// their one consistent mode.
pub fn start_dynamics(sys: &Bound) -> Result<Dynamics, SolveError> {
    let start = sys.initial_state();
    let modes = friction::decide(sys, &start, &friction::start_options(sys, &start), 0.0)?;
    friction::dynamics(sys, &start, &modes, 0.0)
}

/// The slip velocity each friction's event measures from at a segment's start: its own slip
/// for a contact that may have switched there, zero for one that keeps its mode.
fn slip_offsets(sys: &Bound, state: &State, options: &[Options]) -> Vec<f64> {
    let n = sys.n_coordinates();
    let (jac, _) = sys.friction(state);
    (options.iter().enumerate())
        .map(|(k, o)| match o {
            Options::Keep(_) => 0.0,
            _ => (0..n).map(|j| jac[k * n + j] * state.qd[j]).sum(),
        })
        .collect()
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

/// One stretch of the integration with the friction contacts in one mode (the whole
/// integration for a model without friction).
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Time of the segment's start (s from the phase's start).
    pub t_start: f64,
    /// The contacts' modes (empty without friction).
    pub modes: Vec<Mode>,
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

/// A finished unreduced integration.
#[derive(Debug, Clone, PartialEq)]
pub struct UnreducedRun {
    /// The segments in order (one without friction).
    pub segments: Vec<Segment>,
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
    /// Work done by friction up to the end (J, `<= 0`; zero without friction).
    pub friction_work: f64,
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

    /// Accelerations, friction and reaction forces at a state at time `t` of the run, in the
    /// contact modes of its segment.
    pub fn dynamics_at(&self, sys: &Bound, state: &State, t: f64) -> Result<Dynamics, SolveError> {
        let seg = self.segment_at(t).ok_or(SolveError::Inversion {
            target: t,
            duration: self.t_end,
            reason: "time outside the integrated phase",
        })?;
        friction::dynamics(sys, state, &seg.modes, t)
    }

    /// Time and `y` at the release and at the end of every accepted step, over every segment.
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

    /// The full state at the release and at the end of every accepted step.
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

    /// The work done by friction at every node of [`Self::nodes`] (zeros without friction,
    /// whose state has no such component).
    pub fn node_friction_work(&self) -> Vec<f64> {
        let n = self.state_end.q.len();
        self.nodes()
            .into_iter()
            .map(|(_, y)| if y.len() > 2 * n { y[2 * n] } else { 0.0 })
            .collect()
    }

    /// When each segment started, with its contact modes described.
    pub fn switches<'a>(&'a self, sys: &'a Bound) -> impl Iterator<Item = (f64, String)> + 'a {
        (self.segments.iter()).map(move |s| (s.t_start, friction::describe(sys.info(), &s.modes)))
    }

    /// Every step taken (accepted, rejected and event trials).
    pub fn steps(&self) -> u64 {
        self.segments.iter().map(|s| s.solution.total_steps()).sum()
    }
}

struct Problem<'a, 'm> {
    sys: &'a Bound<'m>,
    n: usize,
    modes: Vec<Mode>,
    /// Per friction, the slip velocity its event measures from: the rounding-level slip at the
    /// start of a contact that just switched (so that it does not count as a crossing), zero
    /// for one that keeps sliding.
    slip_offset: Vec<f64>,
    contact: Option<usize>,
    edge: bool,
    reduced: usize,
    end_angle: f64,
    y0: Vec<f64>,
    y: Vec<f64>,
    state: State,
    /// With friction, the dynamics of the last right-hand side and the `z` it was at: the
    /// integrator asks for the events at the state it has just evaluated.
    last: Option<(Vec<f64>, Dynamics)>,
}

impl Problem<'_, '_> {
    /// Sets `y = y0 + z` and the state from it.
    fn load(&mut self, z: &[f64]) {
        for ((y, y0), z) in self.y.iter_mut().zip(&self.y0).zip(z) {
            *y = y0 + z;
        }
        self.state.q.copy_from_slice(&self.y[..self.n]);
        self.state.qd.copy_from_slice(&self.y[self.n..2 * self.n]);
    }

    /// At friction event `k` (a contact's slip stopped or its stuck friction reached `mu N`;
    /// `k == m` is Painlevé's singularity), the next modes: the one consistent choice.
    fn switch(&mut self, k: usize, state: &State, t: f64) -> Result<(), SolveError> {
        if k == self.frictions() {
            return Err(friction::painleve_error(self.sys, state, &self.modes, t));
        }
        // A stuck contact breaks loose against the friction that held it.
        let held = friction::dynamics(self.sys, state, &self.modes, t)?;
        let options: Vec<Options> = (self.modes.iter().enumerate())
            .map(|(i, &mode)| match (i == k, mode) {
                (false, mode) => Options::Keep(mode),
                (true, Mode::Slide(s)) => Options::Stopped(s),
                (true, Mode::Stick) => Options::Breaks(-held.fr[i].signum()),
            })
            .collect();
        self.modes = friction::decide(self.sys, state, &options, t)?;
        self.slip_offset = slip_offsets(self.sys, state, &options);
        self.last = None;
        Ok(())
    }

    fn frictions(&self) -> usize {
        self.modes.len()
    }

    /// Events that end the phase (contact, edge, floor); the frictions' come after them.
    fn n_end_events(&self) -> usize {
        1 + usize::from(self.contact.is_some()) + usize::from(self.edge)
    }
}

impl OdeProblem for Problem<'_, '_> {
    fn dim(&self) -> usize {
        2 * self.n + usize::from(self.frictions() > 0)
    }

    fn rhs(&mut self, t: f64, z: &[f64], dz: &mut [f64]) -> Result<(), SolveError> {
        self.load(z);
        dz[..self.n].copy_from_slice(&self.state.qd);
        if self.frictions() == 0 {
            let qdd = accelerations(self.sys, &self.state, t)?;
            dz[self.n..].copy_from_slice(&qdd);
        } else {
            let d = friction::dynamics(self.sys, &self.state, &self.modes, t)?;
            dz[self.n..2 * self.n].copy_from_slice(&d.qdd);
            dz[2 * self.n] = d.friction_power();
            self.last = Some((z.to_vec(), d));
        }
        Ok(())
    }

    fn n_events(&self) -> usize {
        let m = self.frictions();
        self.n_end_events() + m + usize::from(m > 0)
    }

    /// Events in order: the contact force, the edge margin, the floor, then per friction its
    /// slip velocity (sliding) or its margin `mu N - |f|` (stuck), and last the sliding
    /// system's distance from Painlevé's singularity.
    fn events(&mut self, t: f64, z: &[f64], dz: &[f64], g: &mut [f64]) -> Result<(), SolveError> {
        self.load(z);
        let d = match self.last.take() {
            _ if self.frictions() == 0 => None,
            Some((at, d)) if at == z => Some(d),
            _ => Some(friction::dynamics(self.sys, &self.state, &self.modes, t)?),
        };
        let mut i = 0;
        if let Some(c) = self.contact {
            g[i] = match &d {
                Some(d) => d.forces[c],
                None => self.sys.forces_full(&self.state, &dz[self.n..], &[])[c],
            };
            i += 1;
        }
        if self.edge {
            g[i] = self.sys.contact_edge(&self.state);
            i += 1;
        }
        g[i] = self.state.q[self.reduced] - self.end_angle;
        if let Some(d) = d {
            let info = self.sys.info();
            let mu = self.sys.friction_coefficients();
            for (k, (mode, f)) in self.modes.iter().zip(info.frictions).enumerate() {
                g[i + 1 + k] = match mode {
                    Mode::Slide(_) => d.slip[k] - self.slip_offset[k],
                    Mode::Stick => mu[k] * d.forces[f.normal] - d.fr[k].abs(),
                };
            }
            g[i + 1 + self.modes.len()] = d.painleve - friction::PAINLEVE_FLOOR;
        }
        Ok(())
    }
}

/// Integrates the unreduced equations of `sys` from its release state to separation (or the
/// floor) with relative tolerance `rtol`. `scales` (length `2 n`), when given, are typical
/// magnitudes of the motion `y - y0` (e.g. its size at the end of the reduced phase) used for
/// the absolute tolerances; without them the control is relative to the largest deviation
/// seen. `t_max` bounds the search. `rtol` is raised to [`CONDITION_SAFETY`]` * eps * cond(M)`.
/// With friction, the contacts' modes at release are the one consistent choice.
pub fn integrate(
    sys: &Bound,
    rtol: f64,
    scales: Option<&[f64]>,
    t_max: f64,
    work: &mut Work,
) -> Result<UnreducedRun, SolveError> {
    let info = sys.info();
    let n = sys.n_coordinates();
    let m = info.frictions.len();
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
    if m > 0 {
        y0.push(0.0);
    }
    let options = friction::start_options(sys, &start);
    let modes = friction::decide(sys, &start, &options, 0.0)?;
    let slip_offset = slip_offsets(sys, &start, &options);
    let mut problem = Problem {
        sys,
        n,
        modes,
        slip_offset,
        contact: info.contact.map(|c| c.force),
        edge: info.contact.is_some_and(|c| c.edge),
        reduced: info.reduced,
        end_angle: info.end_angle,
        y0: y0.clone(),
        y: y0.clone(),
        state: start,
        last: None,
    };
    let mut atol: Vec<f64> = match scales {
        Some(s) if s.len() == 2 * n => s
            .iter()
            .map(|v| rtol * v.abs().max(f64::MIN_POSITIVE))
            .collect(),
        _ => Vec::new(),
    };
    if m > 0 && !atol.is_empty() {
        // The work of friction is held to the energy's own scale.
        let e = sys.energy(&problem.state).abs();
        atol.push(rtol * if e > 0.0 { e } else { 1.0 });
    }
    let opts = OdeOptions {
        rtol,
        atol,
        t_max,
        max_steps: MAX_STEPS,
    };
    let mut segments = Vec::new();
    let mut t0 = 0.0;
    loop {
        let solution = dopri5(&mut problem, t0, &vec![0.0; y0.len()], &opts)?;
        work.ode_steps += solution.total_steps();
        let Some(event) = solution.event.clone() else {
            return Err(SolveError::NoEvent { t_max });
        };
        let y = (event.y.iter().zip(&y0))
            .map(|(z, y0)| y0 + z)
            .collect::<Vec<f64>>();
        segments.push(Segment {
            t_start: t0,
            modes: problem.modes.clone(),
            y0: y0.clone(),
            solution,
        });
        let state = State {
            q: y[..n].to_vec(),
            qd: y[n..2 * n].to_vec(),
        };
        let n_end = problem.n_end_events();
        if event.index < n_end {
            let n_contact = usize::from(problem.contact.is_some());
            let end = if event.index < n_contact {
                EndEvent::Separation
            } else if problem.edge && event.index == n_contact {
                EndEvent::Edge
            } else {
                EndEvent::Floor
            };
            return Ok(UnreducedRun {
                segments,
                rtol,
                condition,
                end,
                t_end: event.t,
                friction_work: if m > 0 { y[2 * n] } else { 0.0 },
                state_end: state,
            });
        }
        if segments.len() > MAX_SWITCHES {
            return Err(SolveError::TooManySwitches {
                model: info.name,
                switches: segments.len() - 1,
                t: event.t,
            });
        }
        problem.switch(event.index - n_end, &state, event.t)?;
        problem.state = state;
        y0 = y;
        problem.y0 = y0.clone();
        t0 = event.t;
    }
}
