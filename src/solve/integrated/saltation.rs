//! The saltation matrix of an impact: how the forward sensitivities `S = dy/dp` (`y = [q, qd]`)
//! jump across an impact, from the derivatives of the impact map with its law set fixed and
//! the derivatives of the impact's time.
//!
//! With the laws that held fixed ([`Law`], from the impact's record: [`laws`]), the impact map
//! is linear in the velocities: `M qd+ - J^T P - T^T P_t = M qd-` with one unknown impulse per
//! law, and per law one row: `J_i qd+ = c_i J_i qd-` for a contact (`c_i = -e_i` where it
//! approached, `0` where it rested or is bilateral), `T_j qd+ = 0` for a friction that stuck,
//! `P_t,j + s mu_j P_i = 0` for one that slid with sign `s`. Differentiated along a direction
//! `(dq, dqd-, dp)`, with `D = qd+ - qd-` and the impulses held in the `d(..)` terms:
//! `M dqd+ - J^T dP - T^T dP_t = M dqd- - d(M D - J^T P - T^T P_t)`,
//! `J_i dqd+ = c_i J_i dqd- + c_i d(J_i qd-) + dc_i v-_i - d(J_i qd+)`,
//! `T_j dqd+ = -d(T_j qd+)` and `dP_t,j + s mu_j dP_i = -s dmu_j P_i`. Those are the model's
//! generated partials ([`Model::tangents`](crate::model::Model::tangents)): its first rows are
//! `M qdd - F - J^T forces - T^T fr`, the next `J qdd + bias` and `T qdd + c`, so the same rows
//! at `qdd = D, forces = P, fr = P_t` less the rows at zero give `d(M D - J^T P - T^T P_t)`,
//! and at `qdd = qd+` (or `qd-`) less zero give `d(J qd+)` and `d(T qd+)`: `F`, `bias` and `c`
//! cancel whatever the velocities. A friction coefficient is a parameter (`dmu_j` its column).
//!
//! The impact happens at `t*(p)`, where `dt*/dp` comes from the closing gap's event
//! ([`crate::solve::integrated::forward`]). Just before it the state's total derivative is
//! `D- = S- + f- dt*`, `f = (qd, qdd)` the state's rate; just after, `D+ = G_y D- + G_p`, and
//! `S+ = D+ - f+ dt*`: `S+_q = S-_q + (qd- - qd+) dt*` (positions are continuous) and
//! `S+_qd = dqd+ [D-] - qdd+ dt*`, which is `S+ = G_y S- + G_p + (G_y f- - f+) dt*` (Aizerman &
//! Gantmacher 1958; Hiskens & Pai 2000).
//!
//! A coefficient of restitution enters through `dc_i = -de_i/dp`: exact where the spec's
//! `restitution` is a parameter's name or a number; any other expression has no generated
//! partials, which is [`SaltationGap::Restitution`], never a guess.

use crate::solve::SolveError;
use crate::solve::integrated::contacts::Sign;
use crate::solve::integrated::impact::{ContactLaw, FrictionLaw, Impact};
use crate::solve::linear;
use crate::system::{Bound, State};

/// One law of an impact that held (a row of the impact map, with its own unknown impulse).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Law {
    /// A unilateral contact's Newton law with equality: `v+ = -e v-` where it approached,
    /// `v+ = 0` where it rested.
    Restitution(usize),
    /// A closed bilateral contact: `v+ = 0`.
    Bilateral(usize),
    /// A friction that stuck: its slip after is zero.
    Stick(usize),
    /// A friction that slid with this sign of its slip after: `P_t = -sign mu P`.
    Slide(usize, Sign),
}

/// The laws of an impact as it recorded them: a row for each contact under Newton's law with
/// equality or bilateral, then one for each acting friction (contacts out or open have none).
pub fn laws(impact: &Impact) -> Vec<Law> {
    let contacts = (impact.laws.iter().enumerate()).filter_map(|(i, law)| match law {
        ContactLaw::Out | ContactLaw::Open => None,
        ContactLaw::Restitution => Some(Law::Restitution(i)),
        ContactLaw::Bilateral => Some(Law::Bilateral(i)),
    });
    let frictions = (impact.friction_laws.iter().enumerate()).filter_map(|(j, law)| match law {
        FrictionLaw::Out => None,
        FrictionLaw::Stick => Some(Law::Stick(j)),
        FrictionLaw::Slide(s) => Some(Law::Slide(j, *s)),
    });
    contacts.chain(frictions).collect()
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
    /// The impact map's matrix with the law set's rows is singular (redundant rows), or a
    /// sliding friction's contact has no law of its own.
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

/// The parameters (by index) whose derivatives `impact` leaves one-sided: the coefficient of
/// restitution of a contact that approached and obeyed Newton's law is zero there (plastic)
/// and moves with them. Any coefficient above zero makes that contact bounce, a motion of
/// other events, which the saltation of the plastic law does not describe; below zero there is
/// none. Empty where the restitutions have no partials ([`SaltationGap::Restitution`]).
pub fn one_sided(sys: &Bound, impact: &Impact) -> Vec<usize> {
    let Ok(de) = restitution_partials(sys) else {
        return Vec::new();
    };
    let np = sys.info().parameters.len();
    let restitution = sys.restitutions();
    let plastic = |i: usize| {
        impact.laws.get(i) == Some(&ContactLaw::Restitution)
            && impact
                .normal_velocity_before
                .get(i)
                .is_some_and(|v| *v < 0.0)
            && restitution.get(i) == Some(&0.0)
    };
    (0..np)
        .filter(|&p| (0..restitution.len()).any(|i| plastic(i) && de[i * np + p] != 0.0))
        .collect()
}

/// The model's tangent rows at `state` with `qdd`, contact `forces` and friction forces `fr`,
/// less the same rows at zero: the partial derivatives of the rows' parts linear in them.
fn linear_partials(
    sys: &Bound,
    state: &State,
    (qdd, forces, fr): (&[f64], &[f64], &[f64]),
    zero: &[f64],
) -> Result<Vec<f64>, SolveError> {
    let mut rows = Vec::new();
    sys.tangents_into(state, qdd, forces, fr, &mut rows)?;
    for (r, z) in rows.iter_mut().zip(zero) {
        *r -= z;
    }
    Ok(rows)
}

/// The matrices of one crossing, at the state before.
struct Map<'a> {
    n: usize,
    np: usize,
    m: usize,
    laws: &'a [Law],
    mass: Vec<f64>,
    jac: Vec<f64>,
    tjac: Vec<f64>,
    /// Per contact: the normal velocity before.
    v_minus: Vec<f64>,
    /// Per contact: its restitution, and `d e/dp` (contacts by parameters).
    restitution: Vec<f64>,
    de: Vec<f64>,
    mu: Vec<f64>,
    /// Per friction: its coefficient's parameter, and its contact.
    mu_index: Vec<usize>,
    contact_of: Vec<usize>,
}

impl Map<'_> {
    fn row(&self, i: usize) -> &[f64] {
        &self.jac[i * self.n..(i + 1) * self.n]
    }

    fn trow(&self, j: usize) -> &[f64] {
        &self.tjac[j * self.n..(j + 1) * self.n]
    }

    /// `c_i`, a contact law's factor on `v-` in its target, and `dc_i/dp` for parameter `p`
    /// (both zero but for a contact that approached under Newton's law).
    fn factor(&self, law: Law, p: usize) -> (f64, f64) {
        match law {
            Law::Restitution(i) if self.v_minus[i] < 0.0 => {
                (-self.restitution[i], -self.de[i * self.np + p])
            }
            _ => (0.0, 0.0),
        }
    }

    /// The impact map's matrix (row-major): the momentum rows, then one per law; `None` where
    /// a sliding friction's contact has no law.
    fn matrix(&self) -> Option<Vec<f64>> {
        let (n, k) = (self.n, self.laws.len());
        let dim = n + k;
        let mut a = vec![0.0; dim * dim];
        for r in 0..n {
            a[r * dim..r * dim + n].copy_from_slice(&self.mass[r * n..(r + 1) * n]);
        }
        for (l, law) in self.laws.iter().enumerate() {
            let r = n + l;
            let (force, velocity) = match *law {
                Law::Restitution(i) | Law::Bilateral(i) => (self.row(i), Some(self.row(i))),
                Law::Stick(j) => (self.trow(j), Some(self.trow(j))),
                Law::Slide(j, _) => (self.trow(j), None),
            };
            for c in 0..n {
                a[c * dim + r] = -force[c];
            }
            match (velocity, *law) {
                (Some(v), _) => a[r * dim..r * dim + n].copy_from_slice(v),
                (None, Law::Slide(j, sign)) => {
                    let contact = self.contact_of[j];
                    let col = (self.laws.iter()).position(
                        |l| matches!(l, Law::Restitution(i) | Law::Bilateral(i) if *i == contact),
                    )?;
                    a[r * dim + r] = 1.0;
                    a[r * dim + n + col] = sign.value() * self.mu[j];
                }
                (None, _) => return None,
            }
        }
        Some(a)
    }
}

/// The partials the right-hand sides read: `d(M D - J^T P - T^T P_t)`, `d(J qd+), d(T qd+)`
/// and `d(J qd-)` (each the model's tangent rows, less those at zero).
struct Partials {
    momentum: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
}

/// `S` across the impact `at`, in place (`2 n` values per parameter, `S_q` then `S_qd`), or
/// why it cannot be.
pub fn cross(
    sys: &Bound,
    at: &Crossing,
    s: &mut [f64],
) -> Result<Result<(), SaltationGap>, SolveError> {
    let info = sys.info();
    let (n, np, m, nf) = (
        sys.n_coordinates(),
        info.parameters.len(),
        info.contacts.len(),
        info.frictions.len(),
    );
    let de = match restitution_partials(sys) {
        Ok(de) => de,
        Err(gap) => return Ok(Err(gap)),
    };
    let state = at.before;
    let (qd_minus, qd_plus) = (state.qd(), at.impact.after.qd());
    let (mass, _) = sys.equations(state)?;
    let (jac, _) = sys.constraints(state)?;
    let (tjac, _) = sys.friction(state)?;
    let v_minus = (0..m)
        .map(|i| dot(&jac[i * n..(i + 1) * n], qd_minus))
        .collect();
    let map = Map {
        n,
        np,
        m,
        laws: at.laws,
        mass,
        jac,
        tjac,
        v_minus,
        restitution: sys.restitutions().to_vec(),
        de,
        mu: sys.friction_coefficients(),
        mu_index: info.frictions.iter().map(|f| f.coefficient_index).collect(),
        contact_of: info.frictions.iter().map(|f| f.contact_index).collect(),
    };
    let Some(kkt) = map.matrix() else {
        return Ok(Err(SaltationGap::Singular));
    };
    let mut zero = Vec::new();
    let (no_qdd, no_force, no_fr) = (vec![0.0; n], vec![0.0; m], vec![0.0; nf]);
    sys.tangents_into(state, &no_qdd, &no_force, &no_fr, &mut zero)?;
    let jump: Vec<f64> = qd_plus.iter().zip(qd_minus).map(|(a, b)| a - b).collect();
    let impulses = (
        jump.as_slice(),
        at.impact.impulse.as_slice(),
        at.impact.friction_impulse.as_slice(),
    );
    let partials = Partials {
        momentum: linear_partials(sys, state, impulses, &zero)?,
        plus: linear_partials(sys, state, (qd_plus, &no_force, &no_fr), &zero)?,
        minus: linear_partials(sys, state, (qd_minus, &no_force, &no_fr), &zero)?,
    };
    let dim = n + at.laws.len();
    let mut x = vec![0.0; dim];
    for (p, (col, dt)) in s.chunks_exact_mut(2 * n).zip(at.dt).enumerate() {
        // `D-`, the state's total derivative just before.
        let (dq, dqd): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|r| {
                (
                    col[r] + qd_minus[r] * dt,
                    col[n + r] + at.qdd_before[r] * dt,
                )
            })
            .unzip();
        map.rhs(&partials, at.impact, (p, &dq, &dqd), &mut x);
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Map<'_> {
    /// The right-hand side of the differentiated map for parameter `p` into `x`, along `D-`
    /// (`dq`, `dqd`) with the unit step in `p`.
    fn rhs(
        &self,
        partials: &Partials,
        impact: &Impact,
        at: (usize, &[f64], &[f64]),
        x: &mut [f64],
    ) {
        let (p, dq, dqd) = at;
        let (n, np, m) = (self.n, self.np, self.m);
        let cols = 2 * n + np;
        // Along `xi = (dq, 0, e_p)`: the rows used are linear in the velocities and cancel
        // there.
        let along = |rows: &[f64], r: usize| {
            let row = &rows[r * cols..(r + 1) * cols];
            dot(&row[..n], dq) + row[2 * n + p]
        };
        for (r, (v, mass)) in x.iter_mut().zip(self.mass.chunks_exact(n)).enumerate() {
            *v = dot(mass, dqd) - along(&partials.momentum, r);
        }
        for (l, law) in self.laws.iter().enumerate() {
            x[n + l] = match *law {
                Law::Restitution(i) | Law::Bilateral(i) => {
                    let (c, dc) = self.factor(*law, p);
                    c * (dot(self.row(i), dqd) + along(&partials.minus, n + i))
                        + dc * self.v_minus[i]
                        - along(&partials.plus, n + i)
                }
                Law::Stick(j) => -along(&partials.plus, n + m + j),
                Law::Slide(j, sign) => {
                    let dmu = if self.mu_index[j] == p { 1.0 } else { 0.0 };
                    -sign.value() * dmu * impact.impulse[self.contact_of[j]]
                }
            };
        }
    }
}
