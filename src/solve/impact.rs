//! Impacts: where bodies meet with an approach velocity, the impulses at the contacts that close
//! and at those already closed, by Newton's law of restitution with complementarity — a
//! velocity-level linear complementarity problem over the same constraint Jacobian as the
//! contact forces — and the velocities after.
//!
//! With `M` the mass matrix and `J` the rows of the contacts taking part, the impulses `P` change
//! the velocities by `M (qd+ - qd-) = J^T P`. Each unilateral contact `i` taking part has its
//! normal velocity before, `v-_i = J_i qd-` (negative: approaching; zero: resting), and after,
//! `v+_i`, with `P_i >= 0`, `v+_i + e_i v-_i >= 0` and `P_i (v+_i + e_i v-_i) = 0`; a closed
//! bilateral contact keeps `v+_i = 0` with an impulse of either sign. The problem is solved by
//! trying every set of unilateral contacts whose law holds with equality; more than one set with
//! different velocities after, or none, is a typed error, never a guess. The energy lost is
//! `-sum_i P_i (v-_i + v+_i) / 2`, which is zero for `e = 1` and for resting contacts.

use crate::solve::SolveError;
use crate::solve::linear;
use crate::system::{Bound, State, SystemError, check_restitutions};
use nalgebra::{DMatrix, DVector};

/// Normal velocities within this fraction of the impact's largest approach speed (or 1 m/s
/// times machine precision) count as zero, and impulses within it (times the largest impulse)
/// as zero, when the complementarity conditions are checked.
pub const IMPACT_TOLERANCE: f64 = 1e-9;

/// Most unilateral contacts taking part in one impact (the sets tried are `2^count`).
pub const MAX_IMPACT_CONTACTS: usize = 12;

/// A contact's part in an impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Not taking part (open, and not closing).
    None,
    /// A unilateral contact closed or closing, with its coefficient of restitution
    /// ([`Bound::restitutions`]).
    Unilateral,
    /// A closed bilateral contact.
    Bilateral,
}

/// An impact resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Impact {
    /// Per contact of the system: the normal velocity before (m/s, negative approaching).
    pub normal_velocity_before: Vec<f64>,
    /// Per contact: the normal velocity after.
    pub normal_velocity_after: Vec<f64>,
    /// Per contact: the impulse (N s; zero for a contact that took no part).
    pub impulse: Vec<f64>,
    /// Kinetic energy lost (J), from the impulses.
    pub energy_lost: f64,
    /// The state after: the configuration unchanged, the velocities changed.
    pub after: State,
}

/// The impact at `state` (time `t`, for messages) with each contact's `parts`: the impulses,
/// the velocities after and the energy lost. A part list of the wrong length, impulses that are
/// not unique or do not exist, are typed errors.
pub fn resolve(sys: &Bound, state: &State, parts: &[Part], t: f64) -> Result<Impact, SolveError> {
    resolve_with(sys, state, parts, sys.restitutions(), t)
}

/// [`resolve`] with the coefficients of restitution `restitution` (one per contact) in place of
/// the system's: a bounce sequence converging as Zeno's is closed by a plastic impact.
pub fn resolve_with(
    sys: &Bound,
    state: &State,
    parts: &[Part],
    restitution: &[f64],
    t: f64,
) -> Result<Impact, SolveError> {
    let info = sys.info();
    sys.check_state(state)?;
    let n = sys.n_coordinates();
    let m = info.contacts.len();
    let names = |idx: &[usize]| {
        idx.iter()
            .map(|&i| info.contacts[i].name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (what, got) in [
        ("impact parts", parts.len()),
        ("restitutions", restitution.len()),
    ] {
        if got != m {
            return Err(SystemError::Length {
                model: info.name,
                what,
                expected: m,
                got,
            }
            .into());
        }
    }
    check_restitutions(info, restitution, || {
        "the coefficients given to the impact".into()
    })?;
    let (mass, _) = sys.equations(state)?;
    let (jac, _) = sys.constraints(state)?;
    let mass = DMatrix::from_row_slice(n, n, &mass);
    let row = |i: usize| DVector::from_row_slice(&jac[i * n..(i + 1) * n]);
    let qd = DVector::from_row_slice(state.qd());
    let before: Vec<f64> = (0..m).map(|i| row(i).dot(&qd)).collect();
    let unilateral: Vec<usize> = (0..m).filter(|&i| parts[i] == Part::Unilateral).collect();
    let bilateral: Vec<usize> = (0..m).filter(|&i| parts[i] == Part::Bilateral).collect();
    let indeterminate = |why: String| SolveError::Indeterminate {
        model: info.name,
        t,
        contacts: names(&unilateral),
        why,
    };
    if unilateral.len() > MAX_IMPACT_CONTACTS {
        return Err(indeterminate(format!(
            "more than {MAX_IMPACT_CONTACTS} contacts take part in one impact"
        )));
    }
    // The target of a contact whose law holds with equality: v+ = -e v- (approaching), 0
    // (resting or separating; a separating contact that takes part can only stay so).
    let target = |i: usize| -restitution[i] * before[i].min(0.0);
    let speed = (unilateral.iter().map(|&i| before[i].abs())).fold(f64::EPSILON, f64::max);
    let mut found: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for set in 0..(1usize << unilateral.len()) {
        let rows: Vec<usize> = (unilateral.iter().enumerate())
            .filter(|(k, _)| set >> k & 1 == 1)
            .map(|(_, &i)| i)
            .chain(bilateral.iter().copied())
            .collect();
        let Some((qd_after, impulses)) = solve_set(&mass, &row, &qd, &rows, &target) else {
            continue;
        };
        let after: Vec<f64> = (0..m).map(|i| row(i).dot(&qd_after)).collect();
        let largest = impulses
            .iter()
            .fold(f64::MIN_POSITIVE, |a, p| a.max(p.abs()));
        let pushes = (rows.iter().zip(&impulses))
            .all(|(&i, &p)| parts[i] == Part::Bilateral || p >= -IMPACT_TOLERANCE * largest);
        let holds = (unilateral.iter())
            .filter(|i| !rows.contains(i))
            .all(|&i| after[i] - target(i) >= -IMPACT_TOLERANCE * speed);
        if pushes && holds {
            let mut impulse = vec![0.0; m];
            for (&i, &p) in rows.iter().zip(&impulses) {
                impulse[i] = p;
            }
            found.push((qd_after.iter().copied().collect(), impulse));
        }
    }
    let Some((qd_after, impulse)) = found.first().cloned() else {
        return Err(indeterminate(
            "no set of impulses satisfies Newton's law with the contacts pushing".into(),
        ));
    };
    let scale = qd_after.iter().fold(speed, |a, v| a.max(v.abs()));
    if found.iter().any(|(other, _)| {
        (other.iter().zip(&qd_after)).any(|(a, b)| (a - b).abs() > IMPACT_TOLERANCE * scale)
    }) {
        return Err(indeterminate(format!(
            "{} sets of impulses satisfy Newton's law with different velocities after",
            found.len()
        )));
    }
    let qd_after_v = DVector::from_row_slice(&qd_after);
    let after: Vec<f64> = (0..m).map(|i| row(i).dot(&qd_after_v)).collect();
    let energy_lost = -(0..m)
        .map(|i| 0.5 * impulse[i] * (before[i] + after[i]))
        .sum::<f64>();
    Ok(Impact {
        normal_velocity_before: before,
        normal_velocity_after: after,
        impulse,
        energy_lost,
        after: sys.state(state.q().to_vec(), qd_after)?,
    })
}

/// The velocities after and the impulses when the contacts `rows` meet their targets with
/// equality: `[M -J^T; J 0] [qd+; P] = [M qd-; target]`, or `None` where that system is
/// singular (redundant rows: a smaller set describes the same impact).
fn solve_set(
    mass: &DMatrix<f64>,
    row: &impl Fn(usize) -> DVector<f64>,
    qd: &DVector<f64>,
    rows: &[usize],
    target: &impl Fn(usize) -> f64,
) -> Option<(DVector<f64>, Vec<f64>)> {
    let n = qd.len();
    let dim = n + rows.len();
    // Row-major, for `linear::solve_in_place`.
    let mut a = vec![0.0; dim * dim];
    let mut x = vec![0.0; dim];
    let momentum = mass * qd;
    for r in 0..n {
        for c in 0..n {
            a[r * dim + c] = mass[(r, c)];
        }
        x[r] = momentum[r];
    }
    for (r, &i) in rows.iter().enumerate() {
        let j = row(i);
        for c in 0..n {
            a[c * dim + n + r] = -j[c];
            a[(n + r) * dim + c] = j[c];
        }
        x[n + r] = target(i);
    }
    linear::solve_in_place(&mut a, dim, &mut x).ok()?;
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some((DVector::from_column_slice(&x[..n]), x[n..].to_vec()))
}
