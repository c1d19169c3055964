//! A model wrapper that changes one thing about a base model (its separation polynomial, its
//! monitors, a force or its `theta_dot^2`), to drive the solvers into outcomes the paper's
//! models never reach. A tweaked fast phase runs in its system through a registry that holds
//! it in place of the original ([`registry`]).

use rodcube::model::{Model, ModelInfo, Partials, Reduced, Reduction, ReductionInfo, Tangents};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// `base` with an optional replacement separation polynomial and monitors shifted by a constant.
pub struct Tweaked {
    /// The model delegated to.
    pub base: &'static dyn Model,
    /// Its fast path (every base tweaked here has one).
    pub reduction: &'static dyn Reduction,
    /// Replacement coefficients (lowest degree first), if any.
    pub polynomial: Option<&'static [f64]>,
    /// Added to every monitor value.
    pub monitor_shift: f64,
    /// Whether the last reaction force comes out NaN (a broken model function).
    pub nan_force: bool,
    /// How `theta_dot^2` is broken, if at all.
    pub theta_dot_sq: Fault,
}

/// A broken `theta_dot^2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fault {
    /// Unchanged.
    None,
    /// Everything mirrored: the rod would rise (`theta_ddot_i > 0`).
    Rises,
    /// Negative where `sin(theta)` is below `below`.
    TurnsBack { below: f64 },
    /// NaN where `sin(theta)` is below `below` (1: everywhere).
    Nan { below: f64 },
}

impl Tweaked {
    /// `base` with only `theta_dot^2` broken.
    pub fn with_fault(base: &'static dyn Model, fault: Fault) -> Self {
        Tweaked {
            base,
            reduction: base
                .reduction()
                .expect("a tweaked model's base has a fast path"),
            polynomial: None,
            monitor_shift: 0.0,
            nan_force: false,
            theta_dot_sq: fault,
        }
    }
}

/// `info` without its fall polynomial: a broken `theta_dot^2` has none, so the solvers take
/// the route that evaluates it (one leaked copy per model, for the test process's life).
fn without_fall(info: &'static ModelInfo) -> &'static ModelInfo {
    static COPIES: OnceLock<Mutex<HashMap<&'static str, &'static ModelInfo>>> = OnceLock::new();
    let mut copies = COPIES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    copies.entry(info.name).or_insert_with(|| {
        let reduction = info.reduction.map(|r| ReductionInfo {
            fall_degree: None,
            lean_constants: &[],
            ..r
        });
        Box::leak(Box::new(ModelInfo { reduction, ..*info }))
    })
}

impl Model for Tweaked {
    forward_model!(|m: &Self| m.base; requirements, restitutions, prepare, initial_state, points, energy, momenta, equations, gaps, constraints, edges, friction, to_full, drawing);

    fn info(&self) -> &'static ModelInfo {
        match self.theta_dot_sq {
            Fault::None => self.base.info(),
            _ => without_fall(self.base.info()),
        }
    }
    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        self.base.forces_full(k, q, qd, qdd, out);
        if self.nan_force
            && let Some(last) = out.last_mut()
        {
            *last = f64::NAN;
        }
    }
    fn monitors_full(&self, k: &[f64], q: &[f64], qd: &[f64], f: &[f64], out: &mut [f64]) {
        self.base.monitors_full(k, q, qd, f, out);
        for v in out.iter_mut() {
            *v += self.monitor_shift;
        }
    }
    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        Some(self)
    }
}

impl Reduction for Tweaked {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        let mut r = self.reduction.reduced(k, delta);
        if self.theta_dot_sq == Fault::Rises {
            r.theta_dot_sq = -r.theta_dot_sq;
            r.theta_ddot = -r.theta_ddot;
        }
        r
    }
    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        let w2 = self.reduction.theta_dot_sq_sc(k, s, c, ds, dc);
        match self.theta_dot_sq {
            Fault::Rises => -w2,
            Fault::TurnsBack { below } if s < below => -w2,
            Fault::Nan { below } if s < below => f64::NAN,
            _ => w2,
        }
    }
    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        self.reduction.forces(k, delta, out);
        if self.nan_force
            && let Some(last) = out.last_mut()
        {
            *last = f64::NAN;
        }
    }
    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]) {
        match (contact, self.polynomial) {
            (0, Some(c)) => out.copy_from_slice(c),
            _ => self.reduction.force_polynomial(k, contact, out),
        }
    }
    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]) {
        self.reduction.fall_polynomial(k, out)
    }
    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        self.reduction.prepare_lean(p, k)
    }
    fn partials(&self) -> Option<&dyn Partials> {
        None
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
        self.reduction.full_state(k, t, delta, theta_dot, q, qd)
    }
}

/// `rod_cube_closed` whose separation polynomial `1 + s^2` never vanishes: contact to the floor.
pub static NEVER_SEPARATES: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    reduction: &super::paper::ROD_CUBE,
    polynomial: Some(&[1.0, 0.0, 1.0, 0.0]),
    monitor_shift: 0.0,
    nan_force: false,
    theta_dot_sq: Fault::None,
};

/// `rod_cube_closed` whose monitor is lowered by 4 N m: the tipping margin (3.51 N m at its
/// least, at release: `m2 g a/2 = 3.679 N m` times `1 - 0.0459`, the cube's tipping ratio
/// `3 c r/(4(1+n) - 3 r^2)` there, docs/hand_derivations.md section C) then dips below zero.
pub static LOW_MONITORS: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    reduction: &super::paper::ROD_CUBE,
    polynomial: None,
    monitor_shift: -4.0,
    nan_force: false,
    theta_dot_sq: Fault::None,
};

/// `rod_cube_closed` whose monitor is minus infinity everywhere (a gap or a margin that
/// overflowed): its check must fail, whatever allowance a finite value would get.
pub static INFINITE_MONITORS: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    reduction: &super::paper::ROD_CUBE,
    polynomial: None,
    monitor_shift: f64::NEG_INFINITY,
    nan_force: false,
    theta_dot_sq: Fault::None,
};

/// `rod_cube_closed` whose floor normal force is NaN.
pub static NAN_FORCE: Tweaked = Tweaked {
    base: &super::paper::ROD_CUBE,
    reduction: &super::paper::ROD_CUBE,
    polynomial: None,
    monitor_shift: 0.0,
    nan_force: true,
    theta_dot_sq: Fault::None,
};

/// A registry of the hand-typed `rod_cube` system with `phase` in place of its release phase
/// (the tweaked models keep the original's name, so the system finds them).
pub fn registry(phase: &'static Tweaked) -> &'static [&'static dyn Model] {
    static REGISTRIES: OnceLock<Mutex<HashMap<usize, &'static [&'static dyn Model]>>> =
        OnceLock::new();
    let mut all = REGISTRIES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let key = phase as *const Tweaked as usize;
    all.entry(key).or_insert_with(|| {
        let models: Vec<&'static dyn Model> =
            vec![&super::paper::GENERAL, phase, &super::paper::FREE_ROD];
        Box::leak(models.into_boxed_slice())
    })
}
