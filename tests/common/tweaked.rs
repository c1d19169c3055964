//! A model wrapper that changes one thing about a base model (its separation polynomial or its
//! monitors), to drive the solvers into outcomes the paper's models never reach.

use rodcube::model::{Model, ModelInfo, Reduced};

/// `base` with an optional replacement separation polynomial and monitors shifted by a constant.
pub struct Tweaked {
    /// The model delegated to.
    pub base: &'static dyn Model,
    /// Replacement coefficients (lowest degree first), if any.
    pub polynomial: Option<&'static [f64]>,
    /// Added to every monitor value.
    pub monitor_shift: f64,
    /// Whether the last reaction force comes out NaN (a broken model function).
    pub nan_force: bool,
}

impl Model for Tweaked {
    fn info(&self) -> &'static ModelInfo {
        self.base.info()
    }
    fn requirements(&self, p: &[f64], out: &mut [f64]) {
        self.base.requirements(p, out)
    }
    fn prepare(&self, p: &[f64], k: &mut [f64]) {
        self.base.prepare(p, k)
    }
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        self.base.reduced(k, delta)
    }
    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        self.base.forces(k, delta, out);
        if self.nan_force
            && let Some(last) = out.last_mut()
        {
            *last = f64::NAN;
        }
    }
    fn monitors(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        self.base.monitors(k, delta, out);
        for v in out.iter_mut() {
            *v += self.monitor_shift;
        }
    }
    fn separation_polynomial(&self, k: &[f64], out: &mut [f64]) {
        match self.polynomial {
            Some(c) => out.copy_from_slice(c),
            None => self.base.separation_polynomial(k, out),
        }
    }
    fn full_state(
        &self,
        k: &[f64],
        t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) {
        self.base.full_state(k, t, delta, theta_dot, q, qd)
    }
    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
        self.base.points(k, q, qd, pos, vel)
    }
    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
        self.base.energy(k, q, qd)
    }
    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.base.momenta(k, q, qd, out)
    }
    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        self.base.equations(k, q, qd, mass, rhs)
    }
    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        self.base.forces_full(k, q, qd, qdd, out)
    }
}

/// `rod_cube` whose separation polynomial `1 + s^2` never vanishes: contact to the floor.
pub static NEVER_SEPARATES: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    polynomial: Some(&[1.0, 0.0, 1.0, 0.0]),
    monitor_shift: 0.0,
    nan_force: false,
};

/// `rod_cube` whose monitors are lowered by 3 (N or N m): the floor normal then dips below zero
/// near separation, while the tipping margin (>= 3.5) stays positive.
pub static LOW_MONITORS: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    polynomial: None,
    monitor_shift: -3.0,
    nan_force: false,
};

/// `rod_cube` whose floor normal force is NaN.
pub static NAN_FORCE: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    polynomial: None,
    monitor_shift: 0.0,
    nan_force: true,
};
