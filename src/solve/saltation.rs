//! The saltation matrix of an impact: how the forward sensitivities `S = dy/dp` (`y = [q, qd]`)
//! jump across an impact, from the derivatives of the impact map with its law set fixed and
//! the derivatives of the impact's time.
//!
//! With the set of laws that held with equality fixed ([`Law`]), the impact map is linear in
//! the velocities: `[M -J^T; J 0] [qd+; P] = [M qd-; c (J qd-)]`, `J` the law rows, `c_i = -e_i`
//! for a contact approaching before and `0` for one resting or bilateral. Differentiated along a
//! direction `(dq, dqd-, dp)`:
//! `M dqd+ - J^T dP = M dqd- - d(M D - J^T P)` and
//! `J_i dqd+ = c_i J_i dqd- + c_i d(J_i qd-) + dc_i v-_i - d(J_i qd+)`, with `D = qd+ - qd-`
//! and `P` held in the `d(..)` terms. Those are the model's generated partials
//! ([`Model::tangents`](crate::model::Model::tangents)): its first rows are
//! `M qdd - F - J^T forces`, the next `J qdd + bias`, so the same rows at `qdd = D, forces = P`
//! less the rows at zero give `d(M D - J^T P)`, and at `qdd = qd+` (or `qd-`) less zero give
//! `d(J qd+)`: `F` and `bias` cancel whatever the velocities.
//!
//! The impact happens at `t*(p)`, where `dt*/dp` comes from the closing gap's event
//! ([`crate::solve::forward`]). Just before it the state's total derivative is
//! `D- = S- + f- dt*`, `f = (qd, qdd)` the state's rate; just after, `D+ = G_y D- + G_p`, and
//! `S+ = D+ - f+ dt*`: `S+_q = S-_q + (qd- - qd+) dt*` (positions are continuous) and
//! `S+_qd = dqd+ [D-] - qdd+ dt*`, which is `S+ = G_y S- + G_p + (G_y f- - f+) dt*` (Aizerman &
//! Gantmacher 1958; Hiskens & Pai 2000).
//!
//! A coefficient of restitution enters through `dc_i = -de_i/dp`: exact where the spec's
//! `restitution` is a parameter's name or a number; any other expression has no generated
//! partials, which is [`SaltationGap::Restitution`], never a guess.

use crate::solve::SolveError;
use crate::solve::impact::{Impact, Part};
use crate::solve::linear;
use crate::system::{Bound, State};

/// One law of an impact that held with equality: a row of the impact map.
///
/// Frictional impacts will add `Stick(friction)` (a row `T_j qd+ = 0` whose force column is
/// `T_j` itself) and `Slide(friction, sign)` (no row of its own: the force column of its
/// contact's law becomes `J_n - sign mu T_j`, with `d mu/dp` in the map's derivatives).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Law {
    /// A unilateral contact's Newton law with equality: `v+ = -e v-` where it approached,
    /// `v+ = 0` where it rested.
    Restitution(usize),
    /// A closed bilateral contact: `v+ = 0`.
    Bilateral(usize),
}

impl Law {
    /// The contact whose row it is.
    pub fn contact(self) -> usize {
        match self {
            Law::Restitution(i) | Law::Bilateral(i) => i,
        }
    }
}

/// The law set of a frictionless impact resolved with `parts`: every bilateral contact taking
/// part, and every unilateral one whose impulse is positive (its law held with equality; a
/// unilateral contact with no impulse separates, or touches without pushing, and has no row).
pub fn frictionless_laws(parts: &[Part], impact: &Impact) -> Vec<Law> {
    (parts.iter().enumerate())
        .filter_map(|(i, part)| match part {
            Part::None => None,
            Part::Bilateral => Some(Law::Bilateral(i)),
            Part::Unilateral => {
                (impact.impulse.get(i).is_some_and(|p| *p > 0.0)).then_some(Law::Restitution(i))
            }
        })
        .collect()
}

/// Why an impact's sensitivities cannot be carried across it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SaltationGap {
    /// A contact's coefficient of restitution is an expression of the parameters (not a
    /// parameter's name or a number), whose derivatives are not generated.
    Restitution {
        /// The contact.
        contact: &'static str,
    },
    /// The impact map's matrix with the law set's rows is singular (redundant rows).
    Singular,
}

/// One impact as the sensitivities cross it.
#[derive(Debug, Clone, Copy)]
pub struct Crossing<'a> {
    /// The state just before (the configuration and the velocities `qd-`).
    pub before: &'a State,
    /// The impact resolved there (velocities after, impulses).
    pub impact: &'a Impact,
    /// The laws that held with equality.
    pub laws: &'a [Law],
    /// The accelerations just before.
    pub qdd_before: &'a [f64],
    /// The accelerations just after, in the active set the motion goes on with.
    pub qdd_after: &'a [f64],
    /// `dt*/dp`, one per parameter.
    pub dt: &'a [f64],
}

/// `d e_i/dp` of every contact's coefficient of restitution (row-major, contacts by
/// parameters), or the contact whose restitution has none.
fn restitution_partials(sys: &Bound) -> Result<Vec<f64>, SaltationGap> {
    let info = sys.info();
    let np = info.parameters.len();
    let mut out = vec![0.0; info.contacts.len() * np];
    for (i, c) in info.contacts.iter().enumerate() {
        let text = c.restitution.trim();
        if let Some(j) = info.parameters.iter().position(|p| p.name == text) {
            out[i * np + j] = 1.0;
        } else if text.parse::<f64>().is_err() {
            return Err(SaltationGap::Restitution { contact: c.name });
        }
    }
    Ok(out)
}

/// The model's tangent rows at `state` with `qdd` and contact `forces` (frictions' zero), less
/// the same rows at zero: the partial derivatives of the rows' parts linear in `qdd` and
/// `forces`.
fn linear_partials(
    sys: &Bound,
    state: &State,
    qdd: &[f64],
    forces: &[f64],
    zero: &[f64],
) -> Result<Vec<f64>, SolveError> {
    let nf = sys.info().frictions.len();
    let mut rows = Vec::new();
    sys.tangents_into(state, qdd, forces, &vec![0.0; nf], &mut rows)?;
    for (r, z) in rows.iter_mut().zip(zero) {
        *r -= z;
    }
    Ok(rows)
}

/// `S` across the impact `at`, in place (`2 n` values per parameter, `S_q` then `S_qd`), or
/// why it cannot be.
pub fn cross(
    sys: &Bound,
    at: &Crossing,
    s: &mut [f64],
) -> Result<Result<(), SaltationGap>, SolveError> {
    let info = sys.info();
    let (n, np, m) = (
        sys.n_coordinates(),
        info.parameters.len(),
        info.contacts.len(),
    );
    let de = match restitution_partials(sys) {
        Ok(de) => de,
        Err(gap) => return Ok(Err(gap)),
    };
    let state = at.before;
    let (qd_minus, qd_plus) = (state.qd(), at.impact.after.qd());
    let jump: Vec<f64> = qd_plus.iter().zip(qd_minus).map(|(a, b)| a - b).collect();
    let nf = info.frictions.len();
    let mut zero = Vec::new();
    sys.tangents_into(
        state,
        &vec![0.0; n],
        &vec![0.0; m],
        &vec![0.0; nf],
        &mut zero,
    )?;
    let momentum = linear_partials(sys, state, &jump, &at.impact.impulse, &zero)?;
    let no_force = vec![0.0; m];
    let rows_plus = linear_partials(sys, state, qd_plus, &no_force, &zero)?;
    let rows_minus = linear_partials(sys, state, qd_minus, &no_force, &zero)?;
    let (mass, _) = sys.equations(state)?;
    let (jac, _) = sys.constraints(state)?;
    let restitution = sys.restitutions();
    let row = |i: usize| &jac[i * n..(i + 1) * n];
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let v_minus: Vec<f64> = (0..m).map(|i| dot(row(i), qd_minus)).collect();
    // `c_i`: the target's factor on `v-`.
    let factor = |law: Law| match law {
        Law::Restitution(i) if v_minus[i] < 0.0 => -restitution[i],
        _ => 0.0,
    };
    let k = at.laws.len();
    let dim = n + k;
    let mut kkt = vec![0.0; dim * dim];
    for r in 0..n {
        kkt[r * dim..r * dim + n].copy_from_slice(&mass[r * n..(r + 1) * n]);
    }
    for (l, law) in at.laws.iter().enumerate() {
        let j = row(law.contact());
        for c in 0..n {
            kkt[c * dim + n + l] = -j[c];
            kkt[(n + l) * dim + c] = j[c];
        }
    }
    let cols = 2 * n + np;
    let tangent = |rows: &[f64], r: usize, xi: &[f64]| dot(&rows[r * cols..(r + 1) * cols], xi);
    let mut xi = vec![0.0; cols];
    let mut x = vec![0.0; dim];
    for (p, (col, dt)) in s.chunks_exact_mut(2 * n).zip(at.dt).enumerate() {
        // `D-`, the state's total derivative just before; `xi` its direction in the tangents'
        // columns (the velocities' columns are not needed: the rows used are linear in them
        // and cancel).
        let (dq, dqd): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|r| {
                (
                    col[r] + qd_minus[r] * dt,
                    col[n + r] + at.qdd_before[r] * dt,
                )
            })
            .unzip();
        xi.fill(0.0);
        xi[..n].copy_from_slice(&dq);
        xi[2 * n + p] = 1.0;
        for r in 0..n {
            x[r] = dot(&mass[r * n..(r + 1) * n], &dqd) - tangent(&momentum, r, &xi);
        }
        for (l, law) in at.laws.iter().enumerate() {
            let i = law.contact();
            let c = factor(*law);
            let dc = if c == 0.0 { 0.0 } else { -de[i * np + p] };
            x[n + l] = c * (dot(row(i), &dqd) + tangent(&rows_minus, n + i, &xi)) + dc * v_minus[i]
                - tangent(&rows_plus, n + i, &xi);
        }
        let mut a = kkt.clone();
        if linear::solve_in_place(&mut a, dim, &mut x).is_err() || !x.iter().all(|v| v.is_finite())
        {
            return Ok(Err(SaltationGap::Singular));
        }
        for r in 0..n {
            col[r] = dq[r] - qd_plus[r] * dt;
            col[n + r] = x[r] - at.qdd_after[r] * dt;
        }
    }
    Ok(Ok(()))
}
