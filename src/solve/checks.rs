//! Physical checks on a solved phase, each a [`Check`] with a margin that cannot pass wrongly:
//! a value that is not a finite number fails.
//!
//! - The spec's monitors stay `>= 0`, and every closed unilateral contact's force stays
//!   `>= 0` (a contact that would have to pull has opened at its event; a negative force left
//!   in the samples means it did not), each up to rounding: the tolerance times the largest
//!   magnitude the quantity takes over the phase (a monitor that starts at zero may round to
//!   `-1e-17`).
//! - On an integrated phase, each closed contact's gap stays zero: the integrator holds the
//!   contacts at the acceleration level, so the gaps drift like its error; the largest gap
//!   over the system's length must stay within the tolerance.
//! - Energy and momenta do not drift. The energy's drift is measured against a scale that does
//!   not depend on where the potential's zero is: the largest kinetic energy on the path plus
//!   the range the potential spans on it (a constant such as the cube's `m2 g a / 2` moves
//!   neither). A momentum is checked where it is conserved: a cyclic coordinate's on the fast
//!   path; on an integrated phase each combination of cyclic momenta that no closed contact
//!   and no acting friction pushes on (the null space of their rows in the cyclic columns, on
//!   every state of the path), such as the rod's and the cube's horizontal momenta together
//!   while the tip pushes the cube. With friction the energy check is the balance
//!   `E - E(0) = W_friction`.
//!
//! A check carries what it tested as data (a [`CheckSubject`]: the quantity named, with the
//! numbers that scale it); `report::prose::check_meaning` writes its sentence.

use crate::results::{Check, CheckKind, CheckPhase, CheckSubject};
use crate::solve::SolveError;
use crate::solve::integrated::impact::Impact;
use crate::solve::series::PhaseSamples;
use crate::system::{Bound, State, SystemError};
use nalgebra::DMatrix;

/// Where a group of checks ran: the phase's label, its place in the order of the run, and the
/// absolute time its clock starts at (so monitor times read from release).
#[derive(Debug, Clone)]
pub struct Context {
    /// The phase, an impact, or the cross-check's path.
    pub phase: CheckPhase,
    /// Key prefix: `<model>`, or `<model>.ode`.
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
            phase: CheckPhase::Phase(label.to_string()),
            key: label.to_string(),
            order: 0,
            t_start: 0.0,
        }
    }
}

/// The smallest of a series of values with the time it was taken, and the largest finite
/// magnitude (NaN and infinities are the smallest of all, so they fail).
struct Lowest {
    value: f64,
    at: f64,
    scale: f64,
}

impl Lowest {
    fn new() -> Lowest {
        Lowest {
            value: f64::INFINITY,
            at: 0.0,
            scale: 0.0,
        }
    }

    fn add(&mut self, v: f64, t: f64) {
        let worse = !v.is_finite() && self.value.is_finite();
        if v < self.value || worse || (v.is_nan() && !self.value.is_nan()) {
            self.value = v;
            self.at = t;
        }
        if v.is_finite() {
            self.scale = self.scale.max(v.abs());
        }
    }

    /// Whether it stayed `>= 0` up to `tolerance` times the largest magnitude (never when not
    /// finite).
    fn passed(&self, tolerance: f64) -> bool {
        self.value.is_finite() && self.value >= self.limit(tolerance)
    }

    /// The bound it is held to: zero less `tolerance` times the largest magnitude (rounding).
    fn limit(&self, tolerance: f64) -> f64 {
        if self.scale > 0.0 {
            -tolerance * self.scale
        } else {
            0.0
        }
    }
}

/// A "smallest value stays `>= 0`" check.
fn lowest_check(
    low: &Lowest,
    tolerance: f64,
    unit: &str,
    samples: usize,
    ctx: &Context,
    subject: CheckSubject,
) -> Check {
    Check {
        passed: low.passed(tolerance),
        kind: CheckKind::Monitor,
        phase: ctx.phase.clone(),
        order: ctx.order,
        value: low.value,
        limit: low.limit(tolerance),
        unit: unit.to_string(),
        margin: low.value - low.limit(tolerance),
        at_time: Some(ctx.t_start + low.at),
        samples,
        subject,
    }
}

/// One check per monitor of a phase: its smallest value over the samples (the margin, in the
/// monitor's unit) must be `>= 0` up to rounding. `forces` are the contacts' forces at each
/// sample (`series::sample_forces`). Keys are `<key>.<monitor>`. A state or forces the model
/// refuses ([`Bound::monitors_full`]) is an error, not a failed check.
pub fn monitors(
    sys: &Bound,
    samples: &PhaseSamples,
    forces: &[Vec<f64>],
    tolerance: f64,
    ctx: &Context,
) -> Result<Vec<(String, Check)>, SolveError> {
    let info = sys.info();
    let mut low: Vec<Lowest> = info.monitors.iter().map(|_| Lowest::new()).collect();
    for ((&t, state), f) in samples.t.iter().zip(&samples.states).zip(forces) {
        for (l, v) in low.iter_mut().zip(sys.monitors_full(state, f)?) {
            l.add(v, t);
        }
    }
    Ok((info.monitors.iter().zip(low))
        .map(|(mon, low)| {
            let subject = CheckSubject::Monitor {
                model: info.name.to_string(),
                monitor: mon.name.to_string(),
                meaning: mon.meaning.to_string(),
            };
            let check = lowest_check(&low, tolerance, mon.unit, samples.len(), ctx, subject);
            (format!("{}.{}", ctx.key, mon.name), check)
        })
        .collect())
}

/// One check per unilateral contact closed in the phase (`closed`, per contact): its smallest
/// force over the samples must be `>= 0` up to rounding. Keys are `<key>.<contact>_pushes`.
/// `closed`, or a sample's forces, not one per contact of the model is
/// [`SystemError::Length`].
pub fn contact_forces(
    sys: &Bound,
    samples: &PhaseSamples,
    forces: &[Vec<f64>],
    closed: &[bool],
    tolerance: f64,
    ctx: &Context,
) -> Result<Vec<(String, Check)>, SolveError> {
    let info = sys.info();
    let length = |what: &'static str, got: usize| SystemError::Length {
        model: info.name,
        what,
        expected: info.contacts.len(),
        got,
    };
    if closed.len() != info.contacts.len() {
        return Err(length("closed", closed.len()).into());
    }
    let mut out = Vec::new();
    for ((i, c), _) in (info.contacts.iter().enumerate())
        .zip(closed)
        .filter(|(_, on)| **on)
    {
        if c.bilateral {
            continue;
        }
        let mut low = Lowest::new();
        for (&t, f) in samples.t.iter().zip(forces) {
            low.add(
                f.get(i).copied().ok_or_else(|| length("forces", f.len()))?,
                t,
            );
        }
        let subject = CheckSubject::Pushes {
            model: info.name.to_string(),
            contact: c.name.to_string(),
        };
        let check = lowest_check(&low, tolerance, c.unit, samples.len(), ctx, subject);
        out.push((format!("{}.{}_pushes", ctx.key, c.name), check));
    }
    Ok(out)
}

/// A drift check: `drift <= tolerance`.
fn drift_check(
    drift: f64,
    tolerance: f64,
    kind: CheckKind,
    ctx: &Context,
    samples: usize,
    subject: CheckSubject,
) -> Check {
    Check {
        passed: drift.is_finite() && drift <= tolerance,
        kind,
        phase: ctx.phase.clone(),
        order: ctx.order,
        value: drift,
        limit: tolerance,
        unit: "1".into(),
        margin: tolerance - drift,
        at_time: None,
        samples,
        subject,
    }
}

/// One check per contact held closed as a constraint on an integrated phase (`rows`, per state
/// its closed flags): its largest gap over the states, relative to the system's length, must
/// stay within `tolerance`. Keys are `<key>.<contact>_gap`.
pub fn constraint_drift(
    sys: &Bound,
    states: &[State],
    rows: &[Vec<bool>],
    tolerance: f64,
    ctx: &Context,
) -> Result<Vec<(String, Check)>, SolveError> {
    let info = sys.info();
    let Some(first) = states.first() else {
        return Ok(Vec::new());
    };
    let length = sys.length_scale(first)?;
    let m = info.contacts.len();
    let mut worst = vec![None::<f64>; m];
    for (state, closed) in states.iter().zip(rows) {
        let gaps = sys.gaps(state)?;
        for i in (0..m).filter(|&i| closed.get(i) == Some(&true) && !info.contacts[i].closed) {
            let scale = info.contacts[i].gap.scale(length);
            let d = (gaps[i] / scale).abs();
            worst[i] = Some(match worst[i] {
                Some(w) if d.is_nan() || w.is_nan() => f64::NAN,
                Some(w) => w.max(d),
                None => d,
            });
        }
    }
    Ok((0..m)
        .filter_map(|i| {
            let drift = worst[i]?;
            let c = &info.contacts[i];
            let subject = CheckSubject::Gap {
                model: info.name.to_string(),
                contact: c.name.to_string(),
                length,
            };
            let check = drift_check(
                drift,
                tolerance,
                CheckKind::Drift,
                ctx,
                states.len(),
                subject,
            );
            Some((format!("{}.{}_gap", ctx.key, c.name), check))
        })
        .collect())
}

/// The kinetic energy `qd^T M qd / 2` of a state.
fn kinetic(sys: &Bound, s: &State) -> Result<f64, SolveError> {
    let n = sys.n_coordinates();
    let (mass, _) = sys.equations(s)?;
    Ok(0.5
        * (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| s.qd[i] * mass[i * n + j] * s.qd[j])
                    .sum::<f64>()
            })
            .sum::<f64>())
}

/// What conserves along a path: the energy (less the work of friction, when given: the
/// friction's work at each state) and the momenta `directions` (combinations of the cyclic
/// momenta, one row of weights per check, named).
pub struct Conserved<'a> {
    /// The work done by friction by each state (`<= 0`), with friction.
    pub friction_work: Option<&'a [f64]>,
    /// Each conserved combination of cyclic momenta: its name and its weights.
    pub momenta: Vec<(String, Vec<f64>)>,
}

impl Conserved<'_> {
    /// Every cyclic momentum on its own (the fast path, where each one is conserved).
    pub fn each_cyclic(sys: &Bound) -> Conserved<'static> {
        let info = sys.info();
        let k = info.cyclic.len();
        Conserved {
            friction_work: None,
            momenta: (0..k)
                .map(|c| {
                    let mut w = vec![0.0; k];
                    w[c] = 1.0;
                    (format!("momentum_{}", info.coordinates[info.cyclic[c]]), w)
                })
                .collect(),
        }
    }
}

/// The combinations of cyclic momenta that no closed contact and no acting friction pushes on
/// along a path: the null space, in the cyclic columns, of their rows at the first state,
/// kept where every later state agrees. `rows` gives per state the closed contacts and acting
/// frictions.
pub fn free_momenta(
    sys: &Bound,
    states: &[State],
    rows: &[(Vec<bool>, Vec<bool>)],
) -> Result<Vec<(String, Vec<f64>)>, SolveError> {
    let info = sys.info();
    let cyclic = info.cyclic;
    let n = sys.n_coordinates();
    let pushing = |s: &State,
                   (closed, acting): &(Vec<bool>, Vec<bool>)|
     -> Result<Vec<Vec<f64>>, SolveError> {
        let (jac, _) = sys.constraints(s)?;
        let (tjac, _) = sys.friction(s)?;
        let mut out: Vec<Vec<f64>> = (0..info.contacts.len())
            .filter(|&i| closed.get(i) == Some(&true) && !info.contacts[i].closed)
            .map(|i| cyclic.iter().map(|&c| jac[i * n + c]).collect())
            .collect();
        out.extend(
            (0..info.frictions.len())
                .filter(|&j| acting.get(j) == Some(&true))
                .map(|j| cyclic.iter().map(|&c| tjac[j * n + c]).collect()),
        );
        Ok(out)
    };
    let (Some(first), Some(first_rows)) = (states.first(), rows.first()) else {
        return Ok(Vec::new());
    };
    let mut all: Vec<Vec<f64>> = Vec::new();
    for (s, r) in states.iter().zip(rows) {
        all.extend(pushing(s, r)?);
    }
    let candidates = null_space(&pushing(first, first_rows)?, cyclic.len());
    let single = |w: &[f64]| {
        let nonzero: Vec<usize> = (0..w.len()).filter(|&c| w[c].abs() > 1e-12).collect();
        match nonzero.as_slice() {
            [c] => format!("momentum_{}", info.coordinates[cyclic[*c]]),
            _ => format!(
                "momentum_{}",
                nonzero
                    .iter()
                    .map(|&c| info.coordinates[cyclic[c]])
                    .collect::<Vec<_>>()
                    .join("_")
            ),
        }
    };
    Ok(candidates
        .into_iter()
        .filter(|w| {
            all.iter().all(|row| {
                let size: f64 = row.iter().map(|x| x.abs()).sum();
                let dot: f64 = row.iter().zip(w).map(|(a, b)| a * b).sum();
                dot.abs() <= 1e-10 * size.max(f64::MIN_POSITIVE)
            })
        })
        .map(|w| (single(&w), w))
        .collect())
}

/// An orthonormal basis of the null space of `rows` (each of length `k`), with the unit
/// vectors where they lie in it (so that a single momentum reads as one).
fn null_space(rows: &[Vec<f64>], k: usize) -> Vec<Vec<f64>> {
    if k == 0 {
        return Vec::new();
    }
    let unit_free: Vec<Vec<f64>> = (0..k)
        .filter(|&c| rows.iter().all(|r| r[c] == 0.0))
        .map(|c| {
            let mut w = vec![0.0; k];
            w[c] = 1.0;
            w
        })
        .collect();
    if rows.is_empty() || unit_free.len() == k {
        return unit_free;
    }
    // The columns some row touches: their null space by SVD.
    let touched: Vec<usize> = (0..k)
        .filter(|&c| rows.iter().any(|r| r[c] != 0.0))
        .collect();
    let a = DMatrix::from_fn(rows.len().max(touched.len()), touched.len(), |r, c| {
        rows.get(r).map_or(0.0, |row| row[touched[c]])
    });
    let svd = a.svd(true, true);
    let mut out = unit_free;
    if let Some(v_t) = svd.v_t {
        let top = svd.singular_values.iter().cloned().fold(0.0, f64::max);
        for (r, sv) in svd.singular_values.iter().enumerate() {
            if *sv <= 1e-12 * top {
                let mut w = vec![0.0; k];
                for (c, &col) in touched.iter().enumerate() {
                    w[col] = v_t[(r, c)];
                }
                // A readable sign: the first weight positive.
                if let Some(first) = w.iter().find(|x| x.abs() > 1e-12)
                    && *first < 0.0
                {
                    w.iter_mut().for_each(|x| *x = -*x);
                }
                out.push(w);
            }
        }
    }
    out
}

/// Energy and momentum drift along a path of full states: the largest deviation from the
/// first state, relative to the energy's scale (the largest kinetic energy plus the range of
/// the potential on the path) or to a momentum's (the largest `sum_j |w . M_cj qd_j|`). A
/// check passes when the drift is at most `tolerance` (a drift that is not finite fails).
/// Keys: `<key>.energy`, `<key>.<momentum>`.
///
/// `kind` says what the drift means: [`CheckKind::Drift`] on a path that must conserve on its
/// own (an integration), [`CheckKind::Identity`] on one that conserves by construction (the
/// reduced path), where it tests that the generated energy and momenta agree with it.
pub fn drift(
    sys: &Bound,
    states: &[State],
    conserved: &Conserved,
    tolerance: f64,
    ctx: &Context,
    kind: CheckKind,
) -> Result<Vec<(String, Check)>, SolveError> {
    let info = sys.info();
    let Some(first) = states.first() else {
        return Ok(Vec::new());
    };
    let n = sys.n_coordinates();
    // A state without its work of friction is an error (the work is one per state).
    let work_at = |i: usize| match conserved.friction_work {
        Some(w) => w.get(i).copied().ok_or(SystemError::Length {
            model: info.name,
            what: "friction_work",
            expected: states.len(),
            got: w.len(),
        }),
        None => Ok(0.0),
    };
    let e0 = sys.energy(first)? - work_at(0)?;
    let combine = |p: &[f64], w: &[f64]| -> f64 { p.iter().zip(w).map(|(a, b)| a * b).sum() };
    let p_first = sys.momenta(first)?;
    let p0: Vec<f64> = conserved
        .momenta
        .iter()
        .map(|(_, w)| combine(&p_first, w))
        .collect();
    let (mut e_dev, mut kin_max, mut size_max) = (0.0f64, 0.0f64, 0.0f64);
    let (mut v_min, mut v_max) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut p_dev = vec![0.0f64; p0.len()];
    let mut p_scale = vec![0.0f64; p0.len()];
    for (i, s) in states.iter().enumerate() {
        let total = sys.energy(s)?;
        let ke = kinetic(sys, s)?;
        let work = work_at(i)?;
        e_dev = nan_max(e_dev, (total - work - e0).abs());
        kin_max = kin_max.max(ke.abs());
        size_max = size_max.max(ke.abs() + (total - ke).abs() + work.abs());
        v_min = v_min.min(total - ke);
        v_max = v_max.max(total - ke);
        let (mass, _) = sys.equations(s)?;
        let p = sys.momenta(s)?;
        for (c, (_, w)) in conserved.momenta.iter().enumerate() {
            p_dev[c] = nan_max(p_dev[c], (combine(&p, w) - p0[c]).abs());
            let terms: f64 = (0..n)
                .map(|j| {
                    let row: f64 = (info.cyclic.iter().zip(w))
                        .map(|(&ci, wc)| wc * mass[ci * n + j])
                        .sum();
                    (row * s.qd[j]).abs()
                })
                .sum();
            p_scale[c] = p_scale[c].max(terms);
        }
    }
    let e_scale = kin_max + (v_max - v_min).max(0.0);
    // What rounding alone leaves in `E` (a potential's large constant, such as `m2 g R`,
    // cancels in its differences but not in its rounding): not counted as drift.
    let rounding = ROUNDING_ULPS * f64::EPSILON * size_max;
    let e_dev = if e_dev.is_nan() {
        e_dev
    } else {
        (e_dev - rounding).max(0.0)
    };
    let rel = |dev: f64, scale: f64| if scale > 0.0 { dev / scale } else { dev };
    let check = |drift: f64, subject: CheckSubject| {
        drift_check(drift, tolerance, kind, ctx, states.len(), subject)
    };
    let energy = CheckSubject::Energy {
        model: info.name.to_string(),
        friction: conserved.friction_work.is_some(),
        rounding,
        scale: e_scale,
    };
    let mut out = vec![(
        format!("{}.energy", ctx.key),
        check(rel(e_dev, e_scale), energy),
    )];
    for (c, (name, _)) in conserved.momenta.iter().enumerate() {
        let momentum = CheckSubject::Momentum {
            model: info.name.to_string(),
            name: name.clone(),
            scale: p_scale[c],
        };
        out.push((
            format!("{}.{name}", ctx.key),
            check(rel(p_dev[c], p_scale[c]), momentum),
        ));
    }
    Ok(out)
}

/// The energy an impact took out, two ways: the drop of the total energy across it (the
/// configuration does not move, so it is the kinetic energy's) against the loss its impulses
/// give, `-sum P (v- + v+) / 2`, relative to the kinetic energy before, beyond their rounding.
/// Key `<key>.energy`.
pub fn impact_energy(
    sys: &Bound,
    before: &State,
    impact: &Impact,
    tolerance: f64,
    ctx: &Context,
) -> Result<(String, Check), SolveError> {
    let (e_before, e_after) = (sys.energy(before)?, sys.energy(&impact.after)?);
    let kinetic_before = kinetic(sys, before)?;
    let rounding = ROUNDING_ULPS * f64::EPSILON * (e_before.abs() + e_after.abs());
    let dev = ((e_before - e_after - impact.energy_lost).abs() - rounding).max(0.0);
    let drift = if kinetic_before > 0.0 {
        dev / kinetic_before
    } else {
        dev
    };
    let subject = CheckSubject::Impact {
        energy_lost: impact.energy_lost,
        kinetic_before,
    };
    Ok((
        format!("{}.energy", ctx.key),
        drift_check(drift, tolerance, CheckKind::Identity, ctx, 2, subject),
    ))
}

/// How many units of rounding of the energy's largest terms the energy check allows.
pub const ROUNDING_ULPS: f64 = 16.0;

/// `max` that keeps a NaN (so a NaN drift fails its check).
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
