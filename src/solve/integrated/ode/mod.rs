//! Explicit Dormand–Prince integrators with dense output and event location, sharing one step
//! loop:
//!
//! - [`dopri5`]: the 5(4) pair, 7 stages (6 derivative evaluations a step, the last stage being
//!   the derivative at the new point), with Hairer's fourth-order continuous extension.
//! - [`dop853`]: the eighth-order method of Dormand and Prince, 12 stages, with the 5th- and
//!   3rd-order error estimates combined as in Hairer's `dop853.f` (12 evaluations a step with
//!   the derivative at the new point), and its seventh-order continuous extension (`contd8`:
//!   three more evaluations an accepted step).
//!
//! [`integrate`] runs either ([`Method`]; [`Method::for_rtol`] picks one for a tolerance). Both
//! share the tolerances (absolute per component, or relative to a running peak), the step-size
//! control (exponent `1/order`), the starting step, the reuse of the derivative at the new
//! point as the next step's first stage, and the event location.
//!
//! Events are located on the dense output and checked on genuine steps: once an event function
//! changes sign over an accepted step `[t_n, t_n + h]`, its root is found by the Illinois method
//! on the step's continuous extension, and one genuine step of the method from `y_n` to it gives
//! the event's state. The root stands where that step's event value is past the crossing (on
//! the step end's side, or zero: where a bracketed search ends too), within the problem's
//! [`OdeProblem::event_slack`], and puts the genuine root, along the extension's slope, within
//! a hundredth of `rtol` of the time integrated (at most of the step) before it; else a Newton step
//! along that slope gets one more genuine step, checked the same way (each trial aimed half
//! that past its estimate of the root). Where that too fails, the root of `g(step(y_n, tau))`
//! is bracketed and refined on genuine steps to adjacent floats, ending past the crossing. The
//! event's state is therefore always a genuine step's, as accurate as any step, on the same
//! side of the zero as the bracketed search's, and the final step is truncated to the event.

use crate::solve::SolveError;
use crate::solve::roots::changes_sign;
use events::{Trial, locate};
use stages::Stages;
use tableau::{DOP853, DOPRI5, Tableau};

mod events;
mod stages;
mod tableau;
#[cfg(test)]
mod tests;

/// A first-order system `y' = f(t, y)` with optional event functions.
pub trait OdeProblem {
    /// Dimension of `y`.
    fn dim(&self) -> usize;
    /// Fills `dy = f(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError>;
    /// Number of event functions.
    fn n_events(&self) -> usize {
        0
    }
    /// Event values at a state (of a step, or of a step's continuous extension) and its
    /// derivative; a sign change is an event.
    fn events(
        &mut self,
        _t: f64,
        _y: &[f64],
        _dy: &[f64],
        _g: &mut [f64],
    ) -> Result<(), SolveError> {
        Ok(())
    }
    /// How far past its zero, in its own units, event function `index` may be at a located
    /// event and still be taken as there (what the problem's next decision tolerates): a root
    /// taken from the continuous extension stands only where the genuine step's value there
    /// is past the crossing by at most this (and within the tolerance's share in time). The
    /// default, infinity, leaves the time bound alone; zero makes every event bracketed on genuine
    /// steps to adjacent floats (unless a trial lands on the zero).
    fn event_slack(&self, _index: usize) -> f64 {
        f64::INFINITY
    }
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct OdeOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per component (length `dim`); any other length means
    /// `rtol` times the running maximum of each component (relative control).
    pub atol: Vec<f64>,
    /// Time limit: the solution ends there when no event came first (its `event` is `None`;
    /// the caller decides whether that is an error).
    pub t_max: f64,
    /// Most steps (accepted plus rejected) before [`SolveError::TooManySteps`].
    pub max_steps: u64,
    /// Keep every step's continuous extension, so that the solution can be sampled between
    /// steps ([`OdeSolution::interpolate`]). Without it only the steps whose events are located
    /// compute one (DOP853 saves its three dense-output evaluations a step elsewhere) and the
    /// solution holds the states at the steps' ends; the steps and events are the same.
    pub dense_output: bool,
    /// How many leading components of `y` the step-size control holds to the tolerances
    /// (`None`: all of them). The others ride along on the same steps without steering them
    /// (forward sensitivities: their state's steps, events and values are then those of the
    /// integration without them, bit for bit). `atol`'s length is compared with this count.
    pub controlled: Option<usize>,
}

/// The Runge–Kutta method of an integration.
///
/// [`Method::for_rtol`] takes DOP853 below `rtol = 1e-10` ([`Method::CROSSOVER_RTOL`]): there
/// it costs fewer derivative evaluations than DOPRI5 at the same tolerance (both keep the event
/// times' relative errors below `rtol`, within a factor of 6 of each other). Evaluations DOPRI5
/// / DOP853 to the event, relative-only control (`atol` empty), counted by the
/// `step_counts_of_both_methods` unit test (the oscillator `y'' = -y` to `y' = -1/2`, the
/// pendulum `theta'' = -sin(theta)` from rest at 1.5 rad to `theta = 0`) and by
/// `both_integrators_find_the_separation` in `tests/ode.rs` (the rod and cube's unreduced
/// equations to separation):
///
/// | rtol  | oscillator | pendulum  | rod and cube |
/// |-------|------------|-----------|--------------|
/// | 1e-8  | 200 / 218  | 152 / 227 | 134 / 188    |
/// | 1e-9  | 260 / 233  | 200 / 253 | 146 / 260    |
/// | 1e-10 | 374 / 248  | 248 / 283 | 176 / 188    |
/// | 5e-11 | 422 / 284  | 290 / 274 | 188 / 200    |
/// | 3e-11 | 464 / 263  | 296 / 274 | 224 / 203    |
/// | 2e-11 | 494 / 299  | 320 / 310 | 230 / 239    |
/// | 1e-11 | 560 / 302  | 362 / 301 | 236 / 203    |
/// | 1e-12 | 854 / 308  | 536 / 335 | 356 / 242    |
/// | 1e-13 | 1322 / 368 | 830 / 408 | 506 / 233    |
///
/// (Counted when every event was bracketed on genuine steps; since events are found on the
/// dense output, 2026-11-28, an event takes 1 to 2 genuine trials instead of 6 to 14: the
/// `step_counts_of_both_methods` test prints the counts, and still holds the crossover, DOPRI5
/// and DOP853 now tying on the pendulum at 1e-10, 247 each.) At 1e-10 and above DOPRI5 is
/// cheaper on two of the three; below it DOP853 is cheaper on the
/// oscillator and the pendulum at every tolerance measured, and on the rod and cube except at
/// 5e-11 and 2e-11 (by 6 % and 4 %, within the spread of the event location's trial count),
/// by 14 % to 54 % from 1e-11 down. DOP853 takes 1.4 to 12 times fewer accepted steps (more,
/// the tighter the tolerance), but a step costs 12 evaluations (15 with its dense output)
/// against DOPRI5's 6, and on these short integrations to an event the 6 to 14 trial steps of
/// the event location are a large share.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Dormand–Prince 5(4), [`dopri5`].
    Dopri5,
    /// Dormand–Prince 8(5,3), [`dop853`].
    Dop853,
}

impl Method {
    /// Relative tolerances below this are integrated with [`Method::Dop853`] by
    /// [`Method::for_rtol`] (see [`Method`] for the measurement).
    pub const CROSSOVER_RTOL: f64 = 1e-10;

    /// The cheaper method for a relative tolerance: [`Method::Dop853`] below
    /// [`Method::CROSSOVER_RTOL`], [`Method::Dopri5`] otherwise (also for NaN).
    pub fn for_rtol(rtol: f64) -> Method {
        if rtol < Self::CROSSOVER_RTOL {
            Method::Dop853
        } else {
            Method::Dopri5
        }
    }

    /// `"DOPRI5"` or `"DOP853"`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Dopri5 => "DOPRI5",
            Method::Dop853 => "DOP853",
        }
    }

    /// Order of the solution carried from step to step (5 or 8).
    pub fn order(self) -> u32 {
        self.tableau().order
    }

    fn tableau(self) -> &'static Tableau {
        match self {
            Method::Dopri5 => &DOPRI5,
            Method::Dop853 => &DOP853,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One accepted step with its dense-output coefficients (none when the integration did not keep
/// them, [`OdeOptions::dense_output`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DenseStep {
    /// Start time.
    pub t0: f64,
    /// Step size.
    pub h: f64,
    /// `y(t0)`.
    pub y0: Vec<f64>,
    /// `y(t0 + h)`.
    pub y1: Vec<f64>,
    /// The method that took the step.
    method: Method,
    /// Continuous-extension coefficients `c_0..c_{m-1}` of
    /// `y0 + s (c_0 + (1 - s) (c_1 + s (c_2 + (1 - s) (c_3 + ...))))`, `s = (t - t0) / h`:
    /// `rcont2..rcont5` of Hairer's DOPRI5 (`m = 4`), `cont(2..8)` of DOP853's `contd8`
    /// (`m = 7`), each of length `y0.len()`. Empty: the step kept only its ends.
    coeffs: Vec<Vec<f64>>,
}

impl DenseStep {
    /// The interpolated state at `t` in `[t0, t0 + h]`; `None` when the step kept no
    /// continuous extension ([`OdeOptions::dense_output`]) and `t` is not one of its ends.
    pub fn interpolate(&self, t: f64) -> Option<Vec<f64>> {
        if self.coeffs.is_empty() {
            return if t == self.t0 {
                Some(self.y0.clone())
            } else if t == self.t1() {
                Some(self.y1.clone())
            } else {
                None
            };
        }
        Some(self.extension(t))
    }

    /// Whether the step kept its continuous extension.
    pub fn has_extension(&self) -> bool {
        !self.coeffs.is_empty()
    }

    /// The continuous extension at `t` (only for a step that has one). A component beyond a
    /// coefficient's length (only if the public `y0` was lengthened after the step) takes
    /// that coefficient as zero.
    fn extension(&self, t: f64) -> Vec<f64> {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let m = self.coeffs.len();
        (self.y0.iter().enumerate())
            .map(|(i, y0)| {
                // Horner from the innermost coefficient; the factor before `c_j` is `s` for
                // even `j`, `1 - s` for odd.
                let mut acc = 0.0;
                for (j, c) in self.coeffs.iter().enumerate().rev() {
                    let cj = c.get(i).copied().unwrap_or(0.0);
                    let f = if (j + 1) % 2 == 0 { s } else { s1 };
                    acc = if j + 1 == m { cj } else { cj + f * acc };
                }
                y0 + s * acc
            })
            .collect()
    }

    /// End time.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// The method that took the step (and whose continuous extension this is).
    pub fn method(&self) -> Method {
        self.method
    }
}

/// Where an event function changed sign.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Index of the event function.
    pub index: usize,
    /// Time of the root.
    pub t: f64,
    /// State there.
    pub y: Vec<f64>,
}

/// A finished integration.
#[derive(Debug, Clone, PartialEq)]
pub struct OdeSolution {
    /// Accepted steps, the last truncated at the event if one stopped the integration.
    pub steps: Vec<DenseStep>,
    /// The event that stopped the integration, if any.
    pub event: Option<Event>,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Trial steps taken while locating the event.
    pub event_trials: u64,
}

impl OdeSolution {
    /// Every step counted: accepted, rejected and event trials.
    pub fn total_steps(&self) -> u64 {
        self.accepted + self.rejected + self.event_trials
    }

    /// The state at `t` from dense output, if `t` lies in the integrated range and its step
    /// kept its continuous extension (or `t` is a step's end).
    pub fn interpolate(&self, t: f64) -> Option<Vec<f64>> {
        let first = self.steps.first()?;
        let last = self.steps.last()?;
        if !(t >= first.t0 && t <= last.t1()) {
            return None;
        }
        let i = self
            .steps
            .partition_point(|s| s.t1() < t)
            .min(self.steps.len() - 1);
        let step = &self.steps[i];
        if t == step.t1() {
            return Some(step.y1.clone());
        }
        step.interpolate(t)
    }

    /// Time and state at the end of every accepted step, the initial state first.
    pub fn nodes(&self) -> Vec<(f64, &[f64])> {
        let mut out = Vec::with_capacity(self.steps.len() + 1);
        if let Some(first) = self.steps.first() {
            out.push((first.t0, first.y0.as_slice()));
        }
        out.extend(self.steps.iter().map(|s| (s.t1(), s.y1.as_slice())));
        out
    }

    /// Final time.
    pub fn t_final(&self) -> f64 {
        self.steps.last().map_or(0.0, DenseStep::t1)
    }
}

fn check_finite(what: &'static str, t: f64, v: &[f64]) -> Result<(), SolveError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(SolveError::OdeNonFinite {
            what,
            t,
            y: v.to_vec(),
        })
    }
}

/// The error scale: `atol + rtol |y|` per component, where `atol` is given or, for an `atol`
/// of another length than `dim`, `rtol` times the component's running peak (floored at `1e-8`
/// of the largest peak).
struct Tolerance {
    /// How many leading components are controlled.
    n: usize,
    rtol: f64,
    atol: Vec<f64>,
    relative_only: bool,
    peak: Vec<f64>,
}

impl Tolerance {
    fn new(opts: &OdeOptions, y0: &[f64]) -> Self {
        let n = opts.controlled.map_or(y0.len(), |c| c.min(y0.len()));
        let y0 = &y0[..n];
        let relative_only = opts.atol.len() != n;
        Tolerance {
            n,
            rtol: opts.rtol,
            atol: if relative_only {
                vec![0.0; n]
            } else {
                opts.atol.clone()
            },
            relative_only,
            peak: y0.iter().map(|v| v.abs()).collect(),
        }
    }

    /// Seeds the peaks with one unit of time of the initial derivative, so a start from rest
    /// has a scale.
    fn seed(&mut self, f0: &[f64]) {
        for (p, d) in self.peak.iter_mut().zip(f0) {
            *p = p.max(d.abs() * 1e-3);
        }
        self.floor();
    }

    /// Takes an accepted state into the peaks.
    fn observe(&mut self, y: &[f64]) {
        for (p, v) in self.peak.iter_mut().zip(y) {
            *p = p.max(v.abs());
        }
        self.floor();
    }

    fn floor(&mut self) {
        if self.relative_only {
            let top = self.peak.iter().cloned().fold(0.0, f64::max);
            for (a, p) in self.atol.iter_mut().zip(&self.peak) {
                *a = self.rtol * p.max(1e-8 * top).max(f64::MIN_POSITIVE);
            }
        }
    }
}

/// Integrates `problem` from `(t0, y0)` with DOPRI5 until an event function changes sign or
/// `t_max`; [`integrate`] with [`Method::Dopri5`].
pub fn dopri5<P: OdeProblem>(
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    integrate(Method::Dopri5, problem, t0, y0, opts)
}

/// Integrates `problem` from `(t0, y0)` with DOP853 until an event function changes sign or
/// `t_max`; [`integrate`] with [`Method::Dop853`].
pub fn dop853<P: OdeProblem>(
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    integrate(Method::Dop853, problem, t0, y0, opts)
}

/// Integrates `problem` from `(t0, y0)` with `method` until an event function changes sign
/// (the solution then ends with a step truncated at the [`Event`]) or `t_max` (then its
/// `event` is `None`). Errors: a non-finite state, derivative
/// or event value, or a `y0` whose length is not `problem.dim()`
/// ([`SolveError::OdeNonFinite`]), [`SolveError::StepSizeTooSmall`],
/// [`SolveError::TooManySteps`], and the problem's own errors.
pub fn integrate<P: OdeProblem>(
    method: Method,
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    let tab = method.tableau();
    let n = problem.dim();
    if y0.len() != n {
        // No dedicated variant: the state is refused as unusable, with its values.
        return Err(SolveError::OdeNonFinite {
            what: "initial state (its length is not dim())",
            t: t0,
            y: y0.to_vec(),
        });
    }
    let m = problem.n_events();
    let mut tol = Tolerance::new(opts, y0);
    let mut st = Stages::new(tab, n);
    let mut t = t0;
    let mut y = y0.to_vec();
    check_finite("initial state", t, &y)?;
    problem.rhs(t, &y, &mut st.k[0])?;
    check_finite("initial derivative", t, st.first())?;
    tol.seed(st.first());
    let mut g = vec![0.0; m];
    problem.events(t, &y, st.first(), &mut g)?;
    check_finite("event function", t, &g)?;

    let span = opts.t_max - t0;
    let mut h = initial_step(problem, t, &y, st.first(), &tol, span, tab.order)?;
    let mut sol = OdeSolution {
        steps: Vec::new(),
        event: None,
        accepted: 0,
        rejected: 0,
        event_trials: 0,
    };
    let mut g_new = vec![0.0; m];
    loop {
        if sol.accepted + sol.rejected >= opts.max_steps {
            return Err(SolveError::TooManySteps {
                t,
                steps: sol.accepted + sol.rejected,
                t_max: opts.t_max,
            });
        }
        let last = t + h >= opts.t_max;
        if last {
            h = opts.t_max - t;
        }
        if h <= 8.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE) {
            return Err(SolveError::StepSizeTooSmall { t, h });
        }
        st.step(problem, t, &y, h)?;
        let err = st.error(&y, h, &tol);
        if err.is_nan() || err > 1.0 {
            sol.rejected += 1;
            h *= tab.factor(err, false);
            continue;
        }
        sol.accepted += 1;
        st.end_derivative(problem)?;
        problem.events(t + h, &st.y1, st.end(), &mut g_new)?;
        check_finite("event function", t + h, &g_new)?;
        let crossed: Vec<usize> = (0..m).filter(|&i| changes_sign(g[i], g_new[i])).collect();
        // The extension estimates the events' roots: every step that crossed one needs it.
        let dense = st.record(problem, t, &y, h, opts.dense_output || !crossed.is_empty())?;
        let step = Trial {
            start: t0,
            t,
            y: &y,
            h,
            rtol: opts.rtol,
        };
        let located = locate(
            problem, &mut st, &mut sol, step, &dense, &crossed, &g, &g_new,
        )?;
        if let Some((tau, index)) = located {
            // The step exactly to the event for its state and the truncated dense step (the
            // last trial's, when it was that step).
            if st.h != tau {
                st.step(problem, t, &y, tau)?;
                st.end_derivative(problem)?;
                sol.event_trials += 1;
            }
            sol.steps
                .push(st.record(problem, t, &y, tau, opts.dense_output)?);
            sol.event = Some(Event {
                index,
                t: t + tau,
                y: st.y1.clone(),
            });
            return Ok(sol);
        }
        sol.steps.push(dense);
        t += h;
        y.copy_from_slice(&st.y1);
        st.fsal();
        g.copy_from_slice(&g_new);
        tol.observe(&y);
        if last {
            return Ok(sol);
        }
        h *= tab.factor(err, true);
    }
}

/// Hairer's starting step size for a method of order `order`.
fn initial_step<P: OdeProblem>(
    problem: &mut P,
    t: f64,
    y: &[f64],
    f0: &[f64],
    tol: &Tolerance,
    span: f64,
    order: u32,
) -> Result<f64, SolveError> {
    let n = y.len();
    let controlled = tol.n;
    let sc: Vec<f64> = (0..controlled)
        .map(|i| tol.atol[i] + tol.rtol * y[i].abs())
        .collect();
    let norm = |v: &[f64]| {
        (v.iter().zip(&sc).map(|(x, s)| (x / s).powi(2)).sum::<f64>() / controlled as f64).sqrt()
    };
    let d0 = norm(y);
    let d1 = norm(f0);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6 * span.abs().max(1e-300)
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(span.abs());
    let y1: Vec<f64> = (0..n).map(|i| y[i] + h0 * f0[i]).collect();
    let mut f1 = vec![0.0; n];
    problem.rhs(t + h0, &y1, &mut f1)?;
    let diff: Vec<f64> = (0..n).map(|i| f1[i] - f0[i]).collect();
    let d2 = norm(&diff) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / f64::from(order))
    };
    Ok((100.0 * h0).min(h1).min(span.abs()))
}
