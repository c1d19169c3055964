//! Physical checks on sampled motion, each a [`Check`] with a margin: monitors stay `>= 0`
//! (after a contact ends, the free phase's `contact_open` monitor says the bodies do not meet
//! again), and energy and cyclic momenta do not drift along a path.

use crate::results::{Check, CheckKind, format_number};
use crate::solve::series::PhaseSamples;
use crate::system::{Bound, State};

/// Where a group of checks ran: the phase's label, its place in the order of the run, and the
/// absolute time its clock starts at (so monitor times read from release).
#[derive(Debug, Clone)]
pub struct Context {
    /// `<model>` for a phase, `<model> (ODE cross-check)` for the unreduced equations.
    pub phase: String,
    /// Key prefix: `<model>` or `<model>.ode`.
    pub key: String,
    /// Position of the group in the run (phases in the order they happen).
    pub order: usize,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
}

impl Context {
    /// A phase that starts at release and comes first, labelled and keyed `label`.
    pub fn new(label: &str) -> Context {
        Context {
            phase: label.to_string(),
            key: label.to_string(),
            order: 0,
            t_start: 0.0,
        }
    }
}

/// One check per monitor of a phase: its smallest value over the samples (the margin, in the
/// monitor's unit) must be `>= 0`, up to rounding: `tolerance` times the largest magnitude the
/// monitor takes (a monitor that starts at zero, as a gap that has just opened, may round to
/// `-1e-17`). `forces` are the reaction forces at each sample (`series::sample_forces`). Keys
/// are `<key>.<monitor>`.
pub fn monitors(
    sys: &Bound,
    samples: &PhaseSamples,
    forces: &[Vec<f64>],
    tolerance: f64,
    ctx: &Context,
) -> Vec<(String, Check)> {
    let info = sys.info();
    let mut min = vec![(f64::INFINITY, 0.0); info.monitors.len()];
    let mut scale = vec![0.0f64; info.monitors.len()];
    for ((&t, state), f) in samples.t.iter().zip(&samples.states).zip(forces) {
        for ((m, v), sc) in min
            .iter_mut()
            .zip(sys.monitors_full(state, f))
            .zip(scale.iter_mut())
        {
            // NaN never counts as a minimum: it fails the check below through `margin`.
            if v < m.0 || v.is_nan() {
                *m = (v, t);
            }
            *sc = sc.max(v.abs());
        }
    }
    info.monitors
        .iter()
        .zip(min)
        .zip(scale)
        .map(|((mon, (margin, t)), scale)| {
            let check = Check {
                passed: margin >= -tolerance * scale,
                kind: CheckKind::Monitor,
                phase: ctx.phase.clone(),
                order: ctx.order,
                value: margin,
                limit: 0.0,
                unit: mon.unit.to_string(),
                margin,
                at_time: Some(ctx.t_start + t),
                samples: samples.len(),
                meaning: format!(
                    "{}: the smallest value over {} samples of `{}` must be >= 0",
                    mon.meaning,
                    samples.len(),
                    info.name,
                ),
            };
            (format!("{}.{}", ctx.key, mon.name), check)
        })
        .collect()
}

/// Energy and cyclic-momentum drift along a path of full states: the largest deviation from the
/// first state, relative to the largest of `|E|` and the kinetic energy (for energy) or of the
/// magnitudes `sum_j |M_cj qd_j|` (for momentum `c`) seen on the path. A check passes when the
/// drift is at most `tolerance`; the margin is `tolerance - drift`. Keys: `<key>.energy`,
/// `<key>.momentum_<coordinate>`.
///
/// `kind` says what the drift means: [`CheckKind::Drift`] on a path that must conserve on its
/// own (an integration), [`CheckKind::Identity`] on one that conserves by construction (the
/// reduced path), where it tests that the generated energy and momenta agree with it.
///
/// With friction, `friction_work` holds the work friction has done by each state (`<= 0`) and
/// the check is the energy balance `E - E(0) = W` instead of conservation.
pub fn drift(
    sys: &Bound,
    states: &[State],
    friction_work: Option<&[f64]>,
    tolerance: f64,
    ctx: &Context,
    kind: CheckKind,
) -> Vec<(String, Check)> {
    let info = sys.info();
    let Some(first) = states.first() else {
        return Vec::new();
    };
    let n = sys.n_coordinates();
    // A state without its work of friction counts as NaN, which fails the check.
    let work_at = |i: usize| match friction_work {
        Some(w) => w.get(i).copied().unwrap_or(f64::NAN),
        None => 0.0,
    };
    let e0 = sys.energy(first) - work_at(0);
    let p0 = sys.momenta(first);
    let mut e_dev: f64 = 0.0;
    let mut e_scale: f64 = 0.0;
    let mut p_dev = vec![0.0f64; p0.len()];
    let mut p_scale = vec![0.0f64; p0.len()];
    for (i, s) in states.iter().enumerate() {
        let e = sys.energy(s) - work_at(i);
        let (mass, _) = sys.equations(s);
        let kinetic: f64 = 0.5
            * (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| s.qd[i] * mass[i * n + j] * s.qd[j])
                        .sum::<f64>()
                })
                .sum::<f64>();
        e_dev = nan_max(e_dev, (e - e0).abs());
        e_scale = e_scale.max(e.abs()).max(kinetic.abs());
        for (c, (&ci, p)) in info.cyclic.iter().zip(sys.momenta(s)).enumerate() {
            p_dev[c] = nan_max(p_dev[c], (p - p0[c]).abs());
            let terms: f64 = (0..n).map(|j| (mass[ci * n + j] * s.qd[j]).abs()).sum();
            p_scale[c] = p_scale[c].max(terms);
        }
    }
    let rel = |dev: f64, scale: f64| if scale > 0.0 { dev / scale } else { dev };
    let check = |drift: f64, what: String| Check {
        passed: drift <= tolerance,
        kind,
        phase: ctx.phase.clone(),
        order: ctx.order,
        value: drift,
        limit: tolerance,
        unit: "1".into(),
        margin: tolerance - drift,
        at_time: None,
        samples: states.len(),
        meaning: match kind {
            CheckKind::Identity => format!(
                "{what} is conserved by construction on the reduced path of `{}`; this checks that the generated function agrees with it over {} states: relative difference <= {}",
                info.name,
                states.len(),
                format_number(tolerance, 3)
            ),
            _ => format!(
                "{what} along the {} integrated states of `{}`: largest relative drift <= {}",
                states.len(),
                info.name,
                format_number(tolerance, 3)
            ),
        },
    };
    let energy = if friction_work.is_some() {
        format!(
            "the energy balance (energy lost = work of friction), relative to {} J,",
            format_number(e_scale, 5)
        )
    } else {
        format!(
            "the total energy, relative to {} J,",
            format_number(e_scale, 5)
        )
    };
    let mut out = vec![(
        format!("{}.energy", ctx.key),
        check(rel(e_dev, e_scale), energy),
    )];
    for (c, &ci) in info.cyclic.iter().enumerate() {
        let coordinate = info.coordinates[ci];
        out.push((
            format!("{}.momentum_{coordinate}", ctx.key),
            check(
                rel(p_dev[c], p_scale[c]),
                format!(
                    "the momentum conjugate to `{coordinate}`, relative to {},",
                    format_number(p_scale[c], 5)
                ),
            ),
        ));
    }
    out
}

/// `max` that keeps a NaN (so a NaN drift fails its check).
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
