//! One active set's accelerations, contact forces and friction forces at one state, and their
//! tangents: the linear system of [`contacts`](super)' header, assembled and solved.

use super::{Active, Mode, check_active};
use crate::model::ModelInfo;
use crate::solve::SolveError;
use crate::solve::linear;
use crate::system::{Bound, State};

/// The accelerations, contact and friction forces at one state in one active set.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Dynamics {
    /// `qdd`.
    pub qdd: Vec<f64>,
    /// Every contact's force (zero where open), in the order of the model's contacts.
    pub forces: Vec<f64>,
    /// Friction forces, in the order of the model's frictions (zero where its contact is
    /// open).
    pub fr: Vec<f64>,
    /// Every contact's normal acceleration `J qdd + bias` (zero for one the model eliminates).
    pub normal_acc: Vec<f64>,
    /// Slip velocities `T qd`.
    pub slip: Vec<f64>,
    /// Slip accelerations `T qdd + c`.
    pub slip_acc: Vec<f64>,
    /// `det(A) / det(A0)` of the system solved over the same system without the sliding
    /// frictions' coupling: 1 without sliding friction, zero at Painlevé's singularity, where
    /// sliding has no solution.
    pub painleve: f64,
}

impl Dynamics {
    /// The power of the frictions, `sum f v` (W).
    pub fn friction_power(&self) -> f64 {
        self.fr.iter().zip(&self.slip).map(|(f, v)| f * v).sum()
    }
}

/// The rows of one solve: the model's matrices at a state.
#[derive(Debug, Clone, Default)]
pub(super) struct Rows {
    pub(super) n: usize,
    pub(super) mass: Vec<f64>,
    pub(super) rhs: Vec<f64>,
    pub(super) jac: Vec<f64>,
    pub(super) bias: Vec<f64>,
    pub(super) tjac: Vec<f64>,
    pub(super) tbias: Vec<f64>,
}

impl Rows {
    pub(super) fn at(sys: &Bound, state: &State) -> Result<Rows, SolveError> {
        let mut rows = Rows::default();
        rows.fill(sys, state)?;
        Ok(rows)
    }

    /// The model's matrices at `state`, into the buffers already held.
    pub(super) fn fill(&mut self, sys: &Bound, state: &State) -> Result<(), SolveError> {
        self.n = sys.n_coordinates();
        sys.equations_into(state, &mut self.mass, &mut self.rhs)?;
        sys.constraints_into(state, &mut self.jac, &mut self.bias)?;
        sys.friction_into(state, &mut self.tjac, &mut self.tbias)?;
        Ok(())
    }

    pub(super) fn row<'a>(&self, m: &'a [f64], i: usize) -> &'a [f64] {
        &m[i * self.n..(i + 1) * self.n]
    }

    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }
}

/// Solves for the accelerations, the contacts' forces and the friction forces at `state` in
/// the active set `active`. `t` (from release) labels errors.
pub fn dynamics(
    sys: &Bound,
    state: &State,
    active: &Active,
    t: f64,
) -> Result<Dynamics, SolveError> {
    let mut work = DynamicsWork::default();
    dynamics_into(sys, state, active, t, &mut work)?;
    Ok(work.out)
}

/// The buffers of [`dynamics_into`] and its result ([`DynamicsWork::out`]), kept from call to
/// call: an integration's right-hand sides then allocate nothing.
#[derive(Debug, Clone, Default)]
pub struct DynamicsWork {
    pub(super) rows: Rows,
    /// Closed constraint rows (closed and not eliminated).
    kkt: Vec<usize>,
    /// Acting frictions.
    acting: Vec<usize>,
    mu: Vec<f64>,
    /// The linear system (row-major) and its right-hand side, then its solution.
    a: Vec<f64>,
    x: Vec<f64>,
    /// The system without the sliding frictions' coupling, for Painlevé's ratio.
    a0: Vec<f64>,
    /// The dynamics of the last call.
    pub out: Dynamics,
    /// The system of the last call, assembled again for [`tangent_into`].
    tangent_a: Vec<f64>,
}

/// Derivatives of the dynamics along directions `xi = (dq, dqd, dp)`, one set per direction
/// ([`tangent_into`]), each flat with the direction slowest.
#[derive(Debug, Clone, Default)]
pub struct Tangent {
    /// `d qdd` (`n` per direction).
    pub qdd: Vec<f64>,
    /// `d lambda`: every contact's force (`m` per direction; zero where open).
    pub forces: Vec<f64>,
    /// `d f`: every friction's force (`nf` per direction; zero where it does not act).
    pub fr: Vec<f64>,
    /// The rows of [`Bound::tangents_into`] along the direction, with `qdd` and the forces
    /// held (`n + 3 m + 2 nf` per direction): their residuals, normal and slip accelerations,
    /// gaps, edge margins and slip velocities.
    pub rows: Vec<f64>,
}

/// Where [`tangent_into`] differentiates: the state and time of the last [`dynamics_into`],
/// its active set and the partial derivatives of the dynamics' rows there.
#[derive(Debug, Clone, Copy)]
pub struct TangentAt<'a> {
    /// The state.
    pub state: &'a State,
    /// Its time (from release; labels errors).
    pub t: f64,
    /// The closed contacts and friction modes.
    pub active: &'a Active,
    /// [`Bound::tangents_into`] at the state.
    pub tan: &'a [f64],
}

/// The derivatives of the accelerations and of the contacts' and frictions' forces along each
/// of the directions `xi` (`2 n + np` values each: `dq`, `dqd`, `dp`), from the partial
/// derivatives `tan` of the dynamics' rows ([`Bound::tangents_into`], at the state and
/// dynamics of the last [`dynamics_into`] with `work`, in the active set `active`): the contact
/// system of [`dynamics`] differentiated, `A dx = -(dA x - db)`, the same matrix with the rows'
/// derivatives as right-hand sides. A sliding friction's law `f + s mu lambda = 0` gives
/// `df + s mu dlambda = -s lambda dmu`.
pub fn tangent_into(
    sys: &Bound,
    at: TangentAt,
    work: &mut DynamicsWork,
    xi: &[f64],
    out: &mut Tangent,
) -> Result<(), SolveError> {
    let TangentAt {
        state,
        t,
        active,
        tan,
    } = at;
    let info = sys.info();
    let (n, m, nf, np) = (
        sys.n_coordinates(),
        info.contacts.len(),
        info.frictions.len(),
        info.parameters.len(),
    );
    let (cols, rows) = (2 * n + np, n + 3 * m + 2 * nf);
    let directions = xi.len() / cols;
    if tan.len() != rows * cols || xi.len() != directions * cols {
        return Err(crate::system::SystemError::Length {
            model: info.name,
            what: "tangent directions",
            expected: rows * cols,
            got: tan.len(),
        }
        .into());
    }
    let dim = n + work.kkt.len() + work.acting.len();
    assemble(work, info, active, dim);
    work.tangent_a.clone_from(&work.a);
    let resize = |v: &mut Vec<f64>, per: usize| {
        v.clear();
        v.resize(directions * per, 0.0);
    };
    resize(&mut out.qdd, n);
    resize(&mut out.forces, m);
    resize(&mut out.fr, nf);
    resize(&mut out.rows, rows);
    for (d, x) in xi.chunks_exact(cols).enumerate() {
        let r = &mut out.rows[d * rows..(d + 1) * rows];
        for (ri, row) in r.iter_mut().zip(tan.chunks_exact(cols)) {
            *ri = row.iter().zip(x).map(|(a, b)| a * b).sum();
        }
        let b = &mut work.x;
        b.clear();
        b.extend(r[..n].iter().map(|v| -v));
        b.extend(work.kkt.iter().map(|&i| -r[n + i]));
        for &j in &work.acting {
            b.push(match active.modes[j] {
                Mode::Stick => -r[n + m + j],
                Mode::Slide(sign) => {
                    let lambda = work.out.forces[info.frictions[j].contact_index];
                    -sign.value() * lambda * x[2 * n + info.frictions[j].coefficient_index]
                }
            });
        }
        work.a.clone_from(&work.tangent_a);
        linear::solve_in_place(&mut work.a, dim, &mut work.x).map_err(|_| {
            SolveError::SingularContacts {
                model: info.name,
                t,
                closed: active.set(info),
                q: state.q.clone(),
            }
        })?;
        out.qdd[d * n..(d + 1) * n].copy_from_slice(&work.x[..n]);
        for (k, &i) in work.kkt.iter().enumerate() {
            out.forces[d * m + i] = work.x[n + k];
        }
        let base = n + work.kkt.len();
        for (k, &j) in work.acting.iter().enumerate() {
            out.fr[d * nf + j] = work.x[base + k];
        }
    }
    Ok(())
}

/// [`dynamics`] into `work.out`, with `work`'s buffers.
pub fn dynamics_into(
    sys: &Bound,
    state: &State,
    active: &Active,
    t: f64,
    work: &mut DynamicsWork,
) -> Result<(), SolveError> {
    check_active(sys.info(), active)?;
    work.rows.fill(sys, state)?;
    solve_filled(sys, state, active, t, work)
}

/// [`dynamics_into`] with `work.rows` already filled at `state` (an active set checked): the
/// sets [`decide`](fn@super::decide) tries at one state share the model's matrices.
pub(super) fn solve_filled(
    sys: &Bound,
    state: &State,
    active: &Active,
    t: f64,
    work: &mut DynamicsWork,
) -> Result<(), SolveError> {
    let info = sys.info();
    let (n, m, nf) = (
        sys.n_coordinates(),
        info.contacts.len(),
        info.frictions.len(),
    );
    work.kkt.clear();
    work.kkt
        .extend((0..m).filter(|&i| active.closed[i] && !info.contacts[i].closed));
    work.acting.clear();
    work.acting
        .extend((0..nf).filter(|&j| active.friction_acts(info, j)));
    let dim = n + work.kkt.len() + work.acting.len();
    work.mu.clear();
    work.mu.extend(sys.friction_coefficient_values());
    assemble(work, info, active, dim);
    let sliding = (work.acting.iter()).any(|&j| matches!(active.modes[j], Mode::Slide(_)));
    if sliding {
        work.a0.clone_from(&work.a);
    }
    let singular = || SolveError::SingularContacts {
        model: info.name,
        t,
        closed: active.set(info),
        q: state.q.clone(),
    };
    let det = linear::solve_in_place(&mut work.a, dim, &mut work.x).map_err(|_| singular())?;
    if !work.x.iter().all(|v| v.is_finite()) {
        return Err(singular());
    }
    let painleve = if sliding {
        // The same system without the sliding frictions' coupling to their normal forces.
        let base = n + work.kkt.len();
        for (r, &j) in work.acting.iter().enumerate() {
            if matches!(active.modes[j], Mode::Slide(_)) {
                let row = base + r;
                for c in 0..dim {
                    work.a0[row * dim + c] = if c == row { 1.0 } else { 0.0 };
                }
            }
        }
        det / linear::determinant_in_place(&mut work.a0, dim)
    } else {
        1.0
    };
    results(sys, state, work, painleve)
}

/// Fills `work.out` from the solution `work.x` of the system.
fn results(
    sys: &Bound,
    state: &State,
    work: &mut DynamicsWork,
    painleve: f64,
) -> Result<(), SolveError> {
    let (rows, out) = (&work.rows, &mut work.out);
    let n = rows.n;
    let (m, nf) = (rows.bias.len(), rows.tbias.len());
    out.qdd.clear();
    out.qdd.extend_from_slice(&work.x[..n]);
    sys.forces_full_into(state, &out.qdd, &mut out.forces)?;
    for (r, &i) in work.kkt.iter().enumerate() {
        out.forces[i] = work.x[n + r];
    }
    out.fr.clear();
    out.fr.resize(nf, 0.0);
    let base = n + work.kkt.len();
    for (r, &j) in work.acting.iter().enumerate() {
        out.fr[j] = work.x[base + r];
    }
    out.normal_acc.clear();
    out.normal_acc
        .extend((0..m).map(|i| Rows::dot(rows.row(&rows.jac, i), &out.qdd) + rows.bias[i]));
    out.slip.clear();
    out.slip
        .extend((0..nf).map(|j| Rows::dot(rows.row(&rows.tjac, j), &state.qd)));
    out.slip_acc.clear();
    out.slip_acc
        .extend((0..nf).map(|j| Rows::dot(rows.row(&rows.tjac, j), &out.qdd) + rows.tbias[j]));
    out.painleve = painleve;
    Ok(())
}

/// The linear system of [`dynamics`] into `work.a` (row-major, `dim * dim`) and `work.x`: the
/// equations of motion, the closed rows and the frictions' laws.
fn assemble(work: &mut DynamicsWork, info: &ModelInfo, active: &Active, dim: usize) {
    let DynamicsWork {
        rows,
        kkt,
        acting,
        mu,
        a,
        x: b,
        ..
    } = work;
    let n = rows.n;
    a.clear();
    a.resize(dim * dim, 0.0);
    b.clear();
    b.resize(dim, 0.0);
    for r in 0..n {
        a[r * dim..r * dim + n].copy_from_slice(&rows.mass[r * n..(r + 1) * n]);
        b[r] = rows.rhs[r];
        for (k, &i) in kkt.iter().enumerate() {
            a[r * dim + n + k] = -rows.jac[i * n + r];
        }
        for (k, &j) in acting.iter().enumerate() {
            a[r * dim + n + kkt.len() + k] = -rows.tjac[j * n + r];
        }
    }
    for (k, &i) in kkt.iter().enumerate() {
        let r = n + k;
        a[r * dim..r * dim + n].copy_from_slice(&rows.jac[i * n..(i + 1) * n]);
        b[r] = -rows.bias[i];
    }
    for (k, &j) in acting.iter().enumerate() {
        let r = n + kkt.len() + k;
        match active.modes[j] {
            Mode::Slide(sign) => {
                // f + sign mu lambda = 0, lambda the force of the friction's contact (a row).
                let contact = info.frictions[j].contact_index;
                a[r * dim + r] = 1.0;
                if let Some(col) = kkt.iter().position(|&i| i == contact) {
                    a[r * dim + n + col] = sign.value() * mu[j];
                }
            }
            Mode::Stick => {
                a[r * dim..r * dim + n].copy_from_slice(&rows.tjac[j * n..(j + 1) * n]);
                b[r] = -rows.tbias[j];
            }
        }
    }
}
