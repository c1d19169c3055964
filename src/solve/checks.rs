//! Physical checks on sampled motion, each a [`Check`] with a margin: monitors stay `>= 0`
//! (after a contact ends, the free phase's `contact_open` monitor says the bodies do not meet
//! again), and energy and cyclic momenta do not drift along a path.

use crate::results::Check;
use crate::solve::series::PhaseSamples;
use crate::system::{Bound, State};

/// One check per monitor of a phase: its smallest value over the samples (the margin) must be
/// `>= 0`, up to rounding: `tolerance` times the largest magnitude the monitor takes (a
/// monitor that starts at zero, as a gap that has just opened, may round to `-1e-17`).
/// `forces` are the reaction forces at each sample (`series::sample_forces`). Keys are
/// `<model>.<monitor>`.
pub fn monitors(
    sys: &Bound,
    samples: &PhaseSamples,
    forces: &[Vec<f64>],
    tolerance: f64,
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
                margin,
                meaning: format!(
                    "{} (model `{}`): smallest value over {} samples, at t = {t:.6e} s from the phase start",
                    mon.meaning,
                    info.name,
                    samples.len()
                ),
            };
            (format!("{}.{}", info.name, mon.name), check)
        })
        .collect()
}

/// Energy and cyclic-momentum drift along a path of full states: the largest deviation from the
/// first state, relative to the largest of `|E|` and the kinetic energy (for energy) or of the
/// magnitudes `sum_j |M_cj qd_j|` (for momentum `c`) seen on the path. A check passes when the
/// drift is at most `tolerance`; the margin is `tolerance - drift`. Keys: `<label>.energy`,
/// `<label>.momentum_<coordinate>`.
///
/// With friction, `friction_work` holds the work friction has done by each state (`<= 0`) and
/// the check is the energy balance `E - E(0) = W` instead of conservation.
pub fn drift(
    sys: &Bound,
    states: &[State],
    friction_work: Option<&[f64]>,
    tolerance: f64,
    label: &str,
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
    let mut out = Vec::new();
    let rel = |dev: f64, scale: f64| if scale > 0.0 { dev / scale } else { dev };
    let e_rel = rel(e_dev, e_scale);
    out.push((
        format!("{label}.energy"),
        Check {
            passed: e_rel <= tolerance,
            margin: tolerance - e_rel,
            meaning: format!(
                "{} over {} states of `{}` relative to {e_scale:.6e} J: {e_rel:.3e} (tolerance {tolerance:.1e})",
                if friction_work.is_some() {
                    "energy balance (energy lost minus the work of friction)"
                } else {
                    "total energy drift"
                },
                states.len(),
                info.name
            ),
        },
    ));
    for (c, &ci) in info.cyclic.iter().enumerate() {
        let r = rel(p_dev[c], p_scale[c]);
        out.push((
            format!("{label}.momentum_{}", info.coordinates[ci]),
            Check {
                passed: r <= tolerance,
                margin: tolerance - r,
                meaning: format!(
                    "drift of the momentum conjugate to `{}` over {} states of `{}`, relative to {:.6e}: {r:.3e} (tolerance {tolerance:.1e})",
                    info.coordinates[ci],
                    states.len(),
                    info.name,
                    p_scale[c]
                ),
            },
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
