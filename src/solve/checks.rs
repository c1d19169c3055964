//! Physical checks on sampled motion, each a [`Check`] with a margin: monitors stay `>= 0`, the
//! pusher does not catch the pushed surface again after separation, and energy and cyclic
//! momenta do not drift along an integrated path.

use crate::results::Check;
use crate::solve::phases::Transition;
use crate::solve::series::PhaseSamples;
use crate::system::{State, System};

/// One check per monitor of `sys`: its smallest value over the samples (the margin) must be
/// `>= 0`. Keys are `<model>.<monitor>`.
pub fn monitors(sys: &System, samples: &PhaseSamples) -> Vec<(String, Check)> {
    let info = sys.info();
    let mut min = vec![(f64::INFINITY, 0.0); info.monitors.len()];
    for (&t, &delta) in samples.t.iter().zip(&samples.delta) {
        for (m, v) in min.iter_mut().zip(sys.monitors(delta)) {
            // NaN never counts as a minimum: it fails the check below through `margin`.
            if v < m.0 || v.is_nan() {
                *m = (v, t);
            }
        }
    }
    info.monitors
        .iter()
        .zip(min)
        .map(|(mon, (margin, t))| {
            let check = Check {
                passed: margin >= 0.0,
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

/// After a separation, the pushing point (looked up by name in the next phase) must stay on its
/// side of the surface, which moves on at its separation velocity:
/// `gap(t) = normal . (surface(t) - point(t)) >= 0`. The gap is zero at separation by
/// construction, so the first sample is skipped and rounding of the positions (relative to
/// `tolerance` times the largest coordinate seen) is not counted as a catch.
/// `t_start` is the absolute start time of the next phase. Key: `<next>.<point>_clears_<surface>`.
pub fn no_recatch(
    next: &System,
    samples: &PhaseSamples,
    t_start: f64,
    transition: &Transition,
    tolerance: f64,
) -> Option<(String, Check)> {
    let point = next.point_index(transition.point)?;
    let mut margin = f64::INFINITY;
    let mut scale: f64 = transition.surface_pos[0]
        .abs()
        .max(transition.surface_pos[1].abs());
    for i in 1..samples.len() {
        let state = next.full_state(samples.t[i], samples.delta[i], samples.theta_dot[i]);
        let pos = next.points(&state).pos[point];
        scale = scale.max(pos[0].abs()).max(pos[1].abs());
        let gap = transition.gap(t_start + samples.t[i], pos);
        if gap < margin || gap.is_nan() {
            margin = gap;
        }
    }
    let check = Check {
        passed: margin >= -tolerance * scale,
        margin,
        meaning: format!(
            "`{}` stays clear of the `{}` surface after separation (smallest gap in m over {} samples of `{}`)",
            transition.point,
            transition.surface,
            samples.len().saturating_sub(1),
            next.name()
        ),
    };
    Some((
        format!(
            "{}.{}_clears_{}",
            next.name(),
            transition.point,
            transition.surface
        ),
        check,
    ))
}

/// The full states along a phase's samples.
pub fn sampled_states(sys: &System, samples: &PhaseSamples) -> Vec<State> {
    (0..samples.len())
        .map(|i| sys.full_state(samples.t[i], samples.delta[i], samples.theta_dot[i]))
        .collect()
}

/// Energy and cyclic-momentum drift along a path of full states: the largest deviation from the
/// first state, relative to the largest of `|E|` and the kinetic energy (for energy) or of the
/// magnitudes `sum_j |M_cj qd_j|` (for momentum `c`) seen on the path. A check passes when the
/// drift is at most `tolerance`; the margin is `tolerance - drift`. Keys: `<label>.energy`,
/// `<label>.momentum_<coordinate>`.
pub fn drift(sys: &System, states: &[State], tolerance: f64, label: &str) -> Vec<(String, Check)> {
    let info = sys.info();
    let Some(first) = states.first() else {
        return Vec::new();
    };
    let n = sys.n_coordinates();
    let e0 = sys.energy(first);
    let p0 = sys.momenta(first);
    let mut e_dev: f64 = 0.0;
    let mut e_scale: f64 = 0.0;
    let mut p_dev = vec![0.0f64; p0.len()];
    let mut p_scale = vec![0.0f64; p0.len()];
    for s in states {
        let e = sys.energy(s);
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
                "total energy drift over {} states of `{}` relative to {e_scale:.6e} J: {e_rel:.3e} (tolerance {tolerance:.1e})",
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
