//! `t(delta)` on one phase kept as its accepted panels ([`TimeMesh`]), the planner's: the time
//! at any `v` or angle fallen by one partial panel, and the angle and rate at any `v`.

use super::adaptive::{Panel, integrate};
use super::fall::Fall;
use super::rules::{ACCEPT, Control, TOL_SAFETY};
use crate::results::Work;
use crate::solve::SolveError;
use crate::system::System;

/// `t(delta)` on one phase, from its start to `delta_end`, kept as accepted panels in `v`.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMesh {
    /// Angle fallen at the end of the phase.
    pub delta_end: f64,
    /// `v` at the end.
    pub v_end: f64,
    /// Accepted panels in `v`.
    pub panels: Vec<Panel>,
    /// Time at the start of each panel.
    starts: Vec<f64>,
    /// Time from the phase start to `delta_end` (s).
    pub duration: f64,
    /// The error control the panels were accepted under.
    control: Control,
}

impl TimeMesh {
    /// The mesh of a phase of no length (a contact that opens at its start).
    pub fn empty() -> TimeMesh {
        TimeMesh {
            delta_end: 0.0,
            v_end: 0.0,
            panels: Vec::new(),
            starts: Vec::new(),
            duration: 0.0,
            control: Control::with_tolerance(ACCEPT),
        }
    }

    /// Integrates the phase of `sys` from its start to `delta_end` to relative tolerance `tol`
    /// (the two rules of every panel agree to `tol * TOL_SAFETY`, raised to
    /// [`MIN_TOL`](super::MIN_TOL)).
    pub fn build(
        sys: &System,
        delta_end: f64,
        tol: f64,
        work: &mut Work,
    ) -> Result<TimeMesh, SolveError> {
        if !(delta_end > 0.0 && delta_end.is_finite()) {
            return Err(SolveError::BadPhaseEnd {
                model: sys.name(),
                delta_end,
            });
        }
        let fall = Fall::of(sys, delta_end)?;
        let control = Control::with_tolerance(tol * TOL_SAFETY);
        let v_end = fall.v_at_delta(delta_end);
        let mut panels = Vec::new();
        let (duration, evals) =
            integrate(&fall, v_end, &control, &mut Vec::new(), |p| panels.push(p))?;
        work.integrand_evals += evals;
        let mut starts = Vec::with_capacity(panels.len());
        let mut t = 0.0;
        for p in &panels {
            starts.push(t);
            t += p.value;
        }
        Ok(TimeMesh {
            delta_end,
            v_end,
            panels,
            starts,
            duration,
            control,
        })
    }

    /// Time from the phase start to `v`, for `0 <= v <= v_end` (a relative overshoot of up to
    /// 1e-6 past the end is extrapolated on the last panel). One partial panel.
    pub fn time_at_v(&self, sys: &System, v: f64, work: &mut Work) -> Result<f64, SolveError> {
        if !(v >= 0.0 && v <= self.v_end * (1.0 + 1e-6)) {
            return Err(SolveError::OutsidePhase {
                model: sys.name(),
                delta: self.delta_at_v(sys, v)?,
                delta_end: self.delta_end,
            });
        }
        if v == 0.0 || self.panels.is_empty() {
            return Ok(0.0);
        }
        let i = self.panels.partition_point(|p| p.a < v).saturating_sub(1);
        let p = self.panels[i];
        if v == p.b {
            return Ok(self.starts[i] + p.value);
        }
        let fall = Fall::of_mesh(sys, self)?;
        let (t, evals) = fall.partial(&self.control, fall.span(p.a, p.b), p.a, v)?;
        work.integrand_evals += evals;
        Ok(self.starts[i] + t)
    }

    /// Time from the phase start to the angle fallen `delta`.
    pub fn time_at_delta(
        &self,
        sys: &System,
        delta: f64,
        work: &mut Work,
    ) -> Result<f64, SolveError> {
        if delta.is_nan() || delta < 0.0 || delta > self.delta_end * (1.0 + 1e-6) {
            return Err(SolveError::OutsidePhase {
                model: sys.name(),
                delta,
                delta_end: self.delta_end,
            });
        }
        let v = if delta == self.delta_end {
            self.v_end
        } else {
            Fall::of_mesh(sys, self)?.v_at_delta(delta)
        };
        self.time_at_v(sys, v, work)
    }

    /// The angle fallen at `v`.
    pub fn delta_at_v(&self, sys: &System, v: f64) -> Result<f64, SolveError> {
        if v == self.v_end {
            return Ok(self.delta_end);
        }
        Ok(Fall::of_mesh(sys, self)?.delta_at(v))
    }

    /// `dt/dv` at `v`.
    pub fn rate_at_v(&self, sys: &System, v: f64, work: &mut Work) -> Result<f64, SolveError> {
        work.integrand_evals += 1;
        Fall::of_mesh(sys, self)?.rate(v)
    }
}

impl<'a> Fall<'a> {
    /// The phase of a [`TimeMesh`] already built (and so checked) on `sys`: its constants only.
    fn of_mesh(sys: &'a System, mesh: &TimeMesh) -> Result<Fall<'a>, SolveError> {
        Fall::geometry(
            sys.name(),
            sys.reduction(),
            sys.k(),
            sys.layout(),
            sys.fall_coefficients(),
            mesh.delta_end,
        )
    }
}
