//! One Runge–Kutta step of a tableau: its stages, its error estimate and its continuous
//! extension, in buffers kept from step to step.

use super::Method;
use super::tableau::{DOPRI5_E, Tableau, dop853_coefficients};
use super::{DenseStep, OdeProblem, Tolerance, check_finite};
use crate::solve::SolveError;

/// `out = y + h sum_j row_j k_j` (the products in stage order).
///
/// Every buffer here has the problem's dimension `n`: the stages and `out` are allocated with
/// it and the entry points check `y0.len() == n`. The sums run stage by stage over whole
/// vectors (each component's terms still added in stage order, from `-0.0` as `Iterator::sum`
/// does), which the compiler vectorises.
pub(super) fn combine(out: &mut [f64], y: &[f64], h: f64, row: &[f64], k: &[Vec<f64>]) {
    weighted_sum(out, row, k);
    for (o, yi) in out.iter_mut().zip(y) {
        *o = yi + h * *o;
    }
}

/// `out = sum_j w_j k_j`, stage by stage.
pub(super) fn weighted_sum(out: &mut [f64], w: &[f64], k: &[Vec<f64>]) {
    out.fill(-0.0);
    for (wj, kj) in w.iter().zip(k) {
        for (o, v) in out.iter_mut().zip(kj) {
            *o += wj * v;
        }
    }
}

/// Stage derivatives of one step of a method.
///
/// `k[0]` is the derivative at the step's start and is written only by [`Stages::fsal`], so a
/// step can be re-taken from the same start (event trials) without re-evaluating it.
pub(super) struct Stages {
    pub(super) tab: &'static Tableau,
    /// One derivative per row of the tableau, each of length `n`.
    pub(super) k: Vec<Vec<f64>>,
    /// The new point of the last step.
    pub(super) y1: Vec<f64>,
    pub(super) tmp: Vec<f64>,
    /// Size and end time of the last step.
    pub(super) h: f64,
    pub(super) t1: f64,
    /// Whether `k[solution]` holds the derivative at `(t1, y1)`.
    pub(super) at_end: bool,
}

impl Stages {
    pub(super) fn new(tab: &'static Tableau, n: usize) -> Self {
        Stages {
            tab,
            k: vec![vec![0.0; n]; tab.a.len()],
            y1: vec![0.0; n],
            tmp: vec![0.0; n],
            h: 0.0,
            t1: 0.0,
            at_end: false,
        }
    }

    /// The derivative at the step's start.
    pub(super) fn first(&self) -> &[f64] {
        &self.k[0]
    }

    /// The derivative at the new point (after [`Stages::end_derivative`]).
    pub(super) fn end(&self) -> &[f64] {
        &self.k[self.tab.solution]
    }

    /// One step from `(t, y)` with `k[0] = f(t, y)` already set: fills the stages up to the
    /// new point `y1` (and, for DOPRI5, its derivative, which the error estimate reads).
    pub(super) fn step<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<(), SolveError> {
        let sol = self.tab.solution;
        for s in 1..sol {
            combine(&mut self.tmp, y, h, self.tab.a[s], &self.k);
            p.rhs(t + self.tab.c[s] * h, &self.tmp, &mut self.k[s])?;
        }
        combine(&mut self.y1, y, h, self.tab.a[sol], &self.k);
        self.h = h;
        self.t1 = t + h;
        self.at_end = false;
        if self.tab.error_needs_end {
            p.rhs(t + self.tab.c[sol] * h, &self.y1, &mut self.k[sol])?;
            self.at_end = true;
        }
        check_finite("state", self.t1, &self.y1)?;
        if self.at_end {
            check_finite("derivative", self.t1, self.end())?;
        }
        Ok(())
    }

    /// Evaluates the derivative at the new point if the step has not.
    pub(super) fn end_derivative<P: OdeProblem>(&mut self, p: &mut P) -> Result<(), SolveError> {
        if !self.at_end {
            let sol = self.tab.solution;
            p.rhs(self.t1, &self.y1, &mut self.k[sol])?;
            self.at_end = true;
            check_finite("derivative", self.t1, self.end())?;
        }
        Ok(())
    }

    /// Makes the derivative at the new point the next step's first stage.
    pub(super) fn fsal(&mut self) {
        self.k.swap(0, self.tab.solution);
        self.at_end = false;
    }

    /// The step's error norm relative to the tolerances (accept when at most 1).
    pub(super) fn error(&self, y: &[f64], h: f64, tol: &Tolerance) -> f64 {
        let n = tol.n.min(y.len());
        let scale = |i: usize| tol.atol[i] + tol.rtol * y[i].abs().max(self.y1[i].abs());
        let weighted =
            |w: &[f64], i: usize| -> f64 { w.iter().zip(&self.k).map(|(e, k)| e * k[i]).sum() };
        match self.tab.method {
            Method::Dopri5 => {
                let mut sum = 0.0;
                for i in 0..n {
                    let e: f64 = h * weighted(&DOPRI5_E, i);
                    sum += (e / scale(i)).powi(2);
                }
                (sum / n as f64).sqrt()
            }
            Method::Dop853 => {
                // dop853.f: err5^2 / sqrt(err5^2 + 0.01 err3^2), both RMS norms.
                let (mut err5, mut err3) = (0.0, 0.0);
                for i in 0..n {
                    let sc = scale(i);
                    err5 += (weighted(&dop853_coefficients::E5, i) / sc).powi(2);
                    err3 += (weighted(&dop853_coefficients::E3, i) / sc).powi(2);
                }
                let deno = err5 + 0.01 * err3;
                let deno = if deno > 0.0 { deno } else { 1.0 };
                h.abs() * err5 * (1.0 / (n as f64 * deno)).sqrt()
            }
        }
    }

    /// The dense output of the step just taken to `(t0 + h, y1)` (its end derivative
    /// evaluated): DOP853 evaluates its three dense-output stages here.
    pub(super) fn dense<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t0: f64,
        y: &[f64],
        h: f64,
    ) -> Result<DenseStep, SolveError> {
        let sol = self.tab.solution;
        for s in sol + 1..self.tab.a.len() {
            combine(&mut self.tmp, y, h, self.tab.a[s], &self.k);
            let t = t0 + self.tab.c[s] * h;
            p.rhs(t, &self.tmp, &mut self.k[s])?;
            check_finite("derivative", t, &self.k[s])?;
        }
        let n = y.len();
        let mut coeffs = vec![vec![0.0; n]; 3 + self.tab.d.len()];
        for i in 0..n {
            let ydiff = self.y1[i] - y[i];
            let bspl = h * self.k[0][i] - ydiff;
            coeffs[0][i] = ydiff;
            coeffs[1][i] = bspl;
            coeffs[2][i] = ydiff - h * self.k[sol][i] - bspl;
        }
        for (c, d) in coeffs[3..].iter_mut().zip(self.tab.d) {
            weighted_sum(c, d, &self.k);
            for v in c.iter_mut() {
                *v *= h;
            }
        }
        Ok(DenseStep {
            coeffs,
            ..self.ends(t0, y, h)
        })
    }

    /// The step just taken to `(t0 + h, y1)` as the solution keeps it: with its continuous
    /// extension ([`Stages::dense`]) when `extension`, else with its ends only.
    pub(super) fn record<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t0: f64,
        y: &[f64],
        h: f64,
        extension: bool,
    ) -> Result<DenseStep, SolveError> {
        if extension {
            self.dense(p, t0, y, h)
        } else {
            Ok(self.ends(t0, y, h))
        }
    }

    /// The step just taken to `(t0 + h, y1)` with its ends only (no continuous extension).
    fn ends(&self, t0: f64, y: &[f64], h: f64) -> DenseStep {
        DenseStep {
            t0,
            h,
            y0: y.to_vec(),
            y1: self.y1.clone(),
            method: self.tab.method,
            coeffs: Vec::new(),
        }
    }
}
