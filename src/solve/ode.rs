//! An explicit Dormand–Prince 5(4) integrator with dense output and event location.
//!
//! Events are located by re-stepping: once an event function changes sign over an accepted step
//! `[t_n, t_n + h]`, its root `tau` is found by the Illinois method on `g(step(y_n, tau))`, where
//! each trial is a genuine Runge–Kutta step from `y_n`, not the interpolant. The event time and
//! state are therefore as accurate as any step, and the final step is truncated to the event.
//! Dense output between steps uses Hairer's fourth-order continuous extension of DOPRI5.

use crate::solve::SolveError;
use crate::solve::roots::{changes_sign, illinois};

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
    /// Event values at a state and its derivative; a sign change is an event.
    fn events(
        &mut self,
        _t: f64,
        _y: &[f64],
        _dy: &[f64],
        _g: &mut [f64],
    ) -> Result<(), SolveError> {
        Ok(())
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
    /// Time limit: reaching it without an event is [`SolveError::NoEvent`] when events exist.
    pub t_max: f64,
    /// Most steps (accepted plus rejected) before [`SolveError::TooManySteps`].
    pub max_steps: u64,
}

/// One accepted step with its dense-output coefficients.
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
    /// Continuous-extension coefficients (`rcont2..rcont5` of Hairer's DOPRI5).
    coeffs: [Vec<f64>; 4],
}

impl DenseStep {
    /// The interpolated state at `t` in `[t0, t0 + h]`.
    pub fn interpolate(&self, t: f64) -> Vec<f64> {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let [r2, r3, r4, r5] = &self.coeffs;
        (0..self.y0.len())
            .map(|i| self.y0[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * r5[i]))))
            .collect()
    }

    /// End time.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
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

    /// The state at `t` from dense output, if `t` lies in the integrated range.
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
        Some(step.interpolate(t))
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

// Dormand–Prince 5(4) tableau (Hairer, Nørsett, Wanner, dopri5.f).
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Stage derivatives of one step.
struct Stages {
    k: [Vec<f64>; 7],
    y1: Vec<f64>,
    tmp: Vec<f64>,
}

impl Stages {
    fn new(n: usize) -> Self {
        Stages {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y1: vec![0.0; n],
            tmp: vec![0.0; n],
        }
    }

    /// One DOPRI5 step from `(t, y)` with `k[0] = f(t, y)` already set; fills `k[1..7]`, `y1`.
    fn step<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<(), SolveError> {
        for s in 1..7 {
            for (i, (tmp, yi)) in self.tmp.iter_mut().zip(y).enumerate() {
                let acc: f64 = A[s][..s]
                    .iter()
                    .enumerate()
                    .map(|(j, a)| a * self.k[j][i])
                    .sum();
                *tmp = yi + h * acc;
            }
            let (_, tail) = self.k.split_at_mut(s);
            p.rhs(t + C[s] * h, &self.tmp, &mut tail[0])?;
            if s == 6 {
                self.y1.copy_from_slice(&self.tmp);
            }
        }
        check_finite("state", t + h, &self.y1)?;
        check_finite("derivative", t + h, &self.k[6])
    }

    /// Weighted RMS error norm of the step.
    fn error(&self, y: &[f64], h: f64, rtol: f64, atol: &[f64]) -> f64 {
        let n = y.len();
        let mut sum = 0.0;
        for i in 0..n {
            let e: f64 = h * (0..7).map(|s| E[s] * self.k[s][i]).sum::<f64>();
            let sc = atol[i] + rtol * y[i].abs().max(self.y1[i].abs());
            sum += (e / sc).powi(2);
        }
        (sum / n as f64).sqrt()
    }

    fn dense(&self, t0: f64, y: &[f64], h: f64) -> DenseStep {
        let n = y.len();
        let mut r2 = vec![0.0; n];
        let mut r3 = vec![0.0; n];
        let mut r4 = vec![0.0; n];
        let mut r5 = vec![0.0; n];
        for i in 0..n {
            let ydiff = self.y1[i] - y[i];
            let bspl = h * self.k[0][i] - ydiff;
            r2[i] = ydiff;
            r3[i] = bspl;
            r4[i] = ydiff - h * self.k[6][i] - bspl;
            r5[i] = h * (0..7).map(|s| D[s] * self.k[s][i]).sum::<f64>();
        }
        DenseStep {
            t0,
            h,
            y0: y.to_vec(),
            y1: self.y1.clone(),
            coeffs: [r2, r3, r4, r5],
        }
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

/// Integrates `problem` from `(t0, y0)` until an event function changes sign or `t_max`.
pub fn dopri5<P: OdeProblem>(
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    let n = problem.dim();
    let m = problem.n_events();
    let rtol = opts.rtol;
    let mut atol = if opts.atol.len() == n {
        opts.atol.clone()
    } else {
        vec![0.0; n]
    };
    let relative_only = opts.atol.len() != n;
    let mut peak: Vec<f64> = y0.iter().map(|v| v.abs()).collect();
    let floor = |peak: &[f64], atol: &mut [f64]| {
        if relative_only {
            let top = peak.iter().cloned().fold(0.0, f64::max);
            for (a, p) in atol.iter_mut().zip(peak) {
                *a = rtol * p.max(1e-8 * top).max(f64::MIN_POSITIVE);
            }
        }
    };

    let mut st = Stages::new(n);
    let mut t = t0;
    let mut y = y0.to_vec();
    check_finite("initial state", t, &y)?;
    problem.rhs(t, &y, &mut st.k[0])?;
    check_finite("initial derivative", t, &st.k[0])?;
    // Peaks include one unit of time of the derivative, so a start from rest has a scale.
    for (p, d) in peak.iter_mut().zip(&st.k[0]) {
        *p = p.max(d.abs() * 1e-3);
    }
    floor(&peak, &mut atol);
    let mut g = vec![0.0; m];
    problem.events(t, &y, &st.k[0], &mut g)?;
    check_finite("event function", t, &g)?;

    let mut h = initial_step(problem, t, &y, &st.k[0], rtol, &atol, opts.t_max - t0)?;
    let mut sol = OdeSolution {
        steps: Vec::new(),
        event: None,
        accepted: 0,
        rejected: 0,
        event_trials: 0,
    };
    let mut g_new = vec![0.0; m];
    let mut k1_new = vec![0.0; n];
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
        let err = st.error(&y, h, rtol, &atol);
        if err.is_nan() || err > 1.0 {
            sol.rejected += 1;
            let fac = if err.is_finite() {
                (0.9 * err.powf(-0.2)).clamp(0.2, 1.0)
            } else {
                0.2
            };
            h *= fac;
            continue;
        }
        sol.accepted += 1;
        problem.events(t + h, &st.y1, &st.k[6], &mut g_new)?;
        check_finite("event function", t + h, &g_new)?;
        let crossed: Vec<usize> = (0..m).filter(|&i| changes_sign(g[i], g_new[i])).collect();
        if !crossed.is_empty() {
            let k1 = st.k[0].clone();
            let (tau, index) = locate(
                problem, &mut st, &mut sol, t, &y, &k1, h, &crossed, &g, &g_new,
            )?;
            // Re-step exactly to the event for its state and the truncated dense step.
            st.k[0].copy_from_slice(&k1);
            st.step(problem, t, &y, tau)?;
            sol.event_trials += 1;
            sol.steps.push(st.dense(t, &y, tau));
            sol.event = Some(Event {
                index,
                t: t + tau,
                y: st.y1.clone(),
            });
            return Ok(sol);
        }
        sol.steps.push(st.dense(t, &y, h));
        t += h;
        y.copy_from_slice(&st.y1);
        k1_new.copy_from_slice(&st.k[6]);
        st.k[0].copy_from_slice(&k1_new);
        g.copy_from_slice(&g_new);
        for (p, v) in peak.iter_mut().zip(&y) {
            *p = p.max(v.abs());
        }
        floor(&peak, &mut atol);
        if last {
            if m > 0 {
                return Err(SolveError::NoEvent { t_max: opts.t_max });
            }
            return Ok(sol);
        }
        let fac = (0.9 * err.max(1e-10).powf(-0.2)).clamp(0.2, 5.0);
        h *= fac;
    }
}

/// Finds the earliest root among the crossed event functions by Illinois on re-steps.
#[allow(clippy::too_many_arguments)]
fn locate<P: OdeProblem>(
    problem: &mut P,
    st: &mut Stages,
    sol: &mut OdeSolution,
    t: f64,
    y: &[f64],
    k1: &[f64],
    h: f64,
    crossed: &[usize],
    g0: &[f64],
    g1: &[f64],
) -> Result<(f64, usize), SolveError> {
    let m = g0.len();
    let mut g = vec![0.0; m];
    let mut best = (h, crossed[0]);
    for &idx in crossed {
        // Each trial is a genuine step from `y` to `t + x`, not the interpolant.
        let value_at = |x: f64| -> Result<f64, SolveError> {
            st.k[0].copy_from_slice(k1);
            st.step(problem, t, y, x)?;
            sol.event_trials += 1;
            problem.events(t + x, &st.y1, &st.k[6], &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        let b = illinois(value_at, (0.0, g0[idx]), (h, g1[idx]))?;
        if b < best.0 || (b == best.0 && idx < best.1) {
            best = (b, idx);
        }
    }
    Ok(best)
}

/// Hairer's starting step size.
fn initial_step<P: OdeProblem>(
    problem: &mut P,
    t: f64,
    y: &[f64],
    f0: &[f64],
    rtol: f64,
    atol: &[f64],
    span: f64,
) -> Result<f64, SolveError> {
    let n = y.len();
    let sc: Vec<f64> = (0..n).map(|i| atol[i] + rtol * y[i].abs()).collect();
    let norm = |v: &[f64]| {
        (v.iter().zip(&sc).map(|(x, s)| (x / s).powi(2)).sum::<f64>() / n as f64).sqrt()
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
        (0.01 / d1.max(d2)).powf(0.2)
    };
    Ok((100.0 * h0).min(h1).min(span.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y'' = -y` from `y(0) = 0`, `y'(0) = 1`, with the event `y = 0` (at `t = pi`).
    struct Oscillator;

    impl OdeProblem for Oscillator {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = y[1];
            dy[1] = -y[0];
            Ok(())
        }
        fn n_events(&self) -> usize {
            1
        }
        fn events(
            &mut self,
            _t: f64,
            y: &[f64],
            _dy: &[f64],
            g: &mut [f64],
        ) -> Result<(), SolveError> {
            g[0] = y[1] + 0.5; // y' = -1/2 first at t = 2 pi / 3
            Ok(())
        }
    }

    #[test]
    fn oscillator_event_and_dense_output() {
        let opts = OdeOptions {
            rtol: 1e-12,
            atol: vec![1e-14; 2],
            t_max: 10.0,
            max_steps: 100_000,
        };
        let sol = dopri5(&mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        let ev = sol.event.clone().unwrap();
        let want = 2.0 * std::f64::consts::PI / 3.0;
        assert!((ev.t - want).abs() < 1e-11, "{} vs {want}", ev.t);
        for t in [0.3, 1.0, 1.7, 2.0] {
            let y = sol.interpolate(t).unwrap();
            assert!(
                (y[0] - t.sin()).abs() < 1e-10,
                "t = {t}: {} vs {}",
                y[0],
                t.sin()
            );
        }
        assert!(sol.accepted > 10 && sol.rejected < sol.accepted);
    }

    #[test]
    fn tighter_tolerance_is_more_accurate() {
        // Without events: a tighter tolerance takes more steps and lands closer to sin(1).
        let run = |rtol: f64| {
            let opts = OdeOptions {
                rtol,
                atol: vec![rtol; 2],
                t_max: 1.0,
                max_steps: 100_000,
            };
            struct Free;
            impl OdeProblem for Free {
                fn dim(&self) -> usize {
                    2
                }
                fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
                    dy[0] = y[1];
                    dy[1] = -y[0];
                    Ok(())
                }
            }
            let sol = dopri5(&mut Free, 0.0, &[0.0, 1.0], &opts).unwrap();
            let y = &sol.steps.last().unwrap().y1;
            ((y[0] - 1f64.sin()).abs(), sol.accepted)
        };
        let (e1, n1) = run(1e-6);
        let (e2, n2) = run(1e-11);
        assert!(e2 < e1 && e2 < 1e-10, "{e1} {e2}");
        assert!(n2 > n1);
    }
}
