//! Coulomb friction at contact points: each contact slides one way or sticks ([`Mode`]); in a
//! mode, the accelerations and the friction forces solve one linear system ([`dynamics`]); where
//! a contact is at rest, or reaches a switch, the one consistent mode is chosen ([`decide`]).
//!
//! With `m` frictions and `n` coordinates the unknowns are `qdd` and the friction forces `f`:
//!
//! - `M qdd - J^T f = F` (the friction's generalized force is `f J`, with `v = J qd` the slip
//!   velocity);
//! - sliding with slip sign `s`: `f + s mu N(qdd, f) = 0`, the normal force `N` being affine in
//!   `qdd` and `f` (it is read off [`Bound::forces_full`] at the origin and the unit vectors,
//!   exact for an affine function);
//! - sticking: `J qdd + bias = 0` (the slip velocity stays zero).
//!
//! A contact at rest sticks when the force that keeps it stuck is within `mu N`, and otherwise
//! slides the way its slip then accelerates; a stuck contact whose friction reaches `mu N`
//! breaks loose against the friction that held it. Exactly one of these is consistent for an
//! ordinary contact. With a large `mu` a sliding start can also be consistent beside sticking
//! (Painlevé's indeterminacy, the normal force vanishing): a contact at rest that can stick
//! then sticks, the rule of the rigid-body literature (a body at rest stays at rest while
//! friction can hold it). No consistent mode (a normal force that would have to pull), or
//! several with as many stuck contacts, is [`SolveError::FrictionIndeterminate`], never a
//! guess.

use crate::solve::SolveError;
use crate::system::{Bound, State};
use nalgebra::{DMatrix, DVector};

/// Most combinations of modes tried at one switch (`3^m` for `m` contacts at rest).
pub const MAX_COMBINATIONS: usize = 729;

/// A contact at rest is one whose slip speed is below this fraction of the speeds it is made of.
pub const REST: f64 = 1e-9;

/// Where sliding is given up as Painlevé's singularity: the sliding system's determinant over
/// the mass matrix's ([`Dynamics::painleve`], 1 without friction) has fallen to this, so the
/// normal force answers the accelerations a thousand times more weakly than without friction
/// and vanishes altogether a little further on.
pub const PAINLEVE_FLOOR: f64 = 1e-3;

/// How a friction contact moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    /// Sliding with the slip velocity's sign `+1` or `-1`; the friction force is
    /// `-sign mu N`.
    Slide(f64),
    /// Stuck: the slip velocity stays zero, the friction force is what keeps it so.
    Stick,
}

impl Mode {
    /// `slides +`, `slides -` or `sticks`.
    pub fn describe(self) -> &'static str {
        match self {
            Mode::Slide(s) if s > 0.0 => "slides +",
            Mode::Slide(_) => "slides -",
            Mode::Stick => "sticks",
        }
    }
}

/// The accelerations, friction forces and reaction forces at one state in one mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Dynamics {
    /// `qdd`.
    pub qdd: Vec<f64>,
    /// Friction forces, in the order of the model's frictions.
    pub fr: Vec<f64>,
    /// Reaction forces, in the order of the model's forces.
    pub forces: Vec<f64>,
    /// Slip velocities `J qd`.
    pub slip: Vec<f64>,
    /// Slip accelerations `J qdd + bias`.
    pub slip_acc: Vec<f64>,
    /// `det(A) / det(M)` of the system solved (`A` with the friction rows): 1 without sliding
    /// friction, zero at Painlevé's singularity, where sliding has no solution.
    pub painleve: f64,
}

impl Dynamics {
    /// The power of the frictions, `sum f v` (W).
    pub fn friction_power(&self) -> f64 {
        self.fr.iter().zip(&self.slip).map(|(f, v)| f * v).sum()
    }
}

/// Solves for the accelerations and the friction forces at `state` with the contacts in
/// `modes` (one per friction; empty without friction). `t` labels errors.
pub fn dynamics(
    sys: &Bound,
    state: &State,
    modes: &[Mode],
    t: f64,
) -> Result<Dynamics, SolveError> {
    let info = sys.info();
    let (n, m) = (sys.n_coordinates(), info.frictions.len());
    if modes.len() != m {
        return Err(SolveError::FrictionModes {
            model: info.name,
            expected: m,
            got: modes.len(),
        });
    }
    let (mass, rhs) = sys.equations(state);
    let (jac, bias) = sys.friction(state);
    let dim = n + m;
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut b = DVector::<f64>::zeros(dim);
    for r in 0..n {
        for c in 0..n {
            a[(r, c)] = mass[r * n + c];
        }
        for k in 0..m {
            a[(r, n + k)] = -jac[k * n + r];
        }
        b[r] = rhs[r];
    }
    if m > 0 {
        normal_rows(sys, state, modes, &jac, &bias, &mut a, &mut b);
    }
    let singular = || SolveError::SingularMassMatrix {
        t,
        q: state.q.clone(),
    };
    let lu = a.lu();
    let x = lu.solve(&b).ok_or_else(singular)?;
    if !x.iter().all(|v| v.is_finite()) {
        return Err(singular());
    }
    let painleve = if modes.iter().any(|m| matches!(m, Mode::Slide(_))) {
        lu.determinant() / DMatrix::from_row_slice(n, n, &mass).determinant()
    } else {
        1.0
    };
    let qdd: Vec<f64> = x.iter().take(n).copied().collect();
    let fr: Vec<f64> = x.iter().skip(n).copied().collect();
    let forces = sys.forces_full(state, &qdd, &fr);
    let row = |k: usize, v: &[f64]| -> f64 { (0..n).map(|j| jac[k * n + j] * v[j]).sum() };
    let slip = (0..m).map(|k| row(k, &state.qd)).collect();
    let slip_acc = (0..m).map(|k| row(k, &qdd) + bias[k]).collect();
    Ok(Dynamics {
        qdd,
        fr,
        forces,
        slip,
        slip_acc,
        painleve,
    })
}

/// The error for sliding that has reached Painlevé's singularity ([`PAINLEVE_FLOOR`]).
pub fn painleve_error(sys: &Bound, state: &State, modes: &[Mode], t: f64) -> SolveError {
    SolveError::FrictionIndeterminate {
        model: sys.info().name,
        t,
        why: format!(
            "with {} the sliding equations approach a singularity at q = {:?} (their determinant \
             fell to {PAINLEVE_FLOOR:e} of the frictionless one): the normal force stops \
             resisting the sliding (Painlevé's paradox), and rigid bodies with Coulomb friction \
             have no answer from here",
            describe(sys.info(), modes),
            state.q
        ),
    }
}

/// Fills the friction rows `n..n+m` of the system: the sliding law or the sticking constraint.
fn normal_rows(
    sys: &Bound,
    state: &State,
    modes: &[Mode],
    jac: &[f64],
    bias: &[f64],
    a: &mut DMatrix<f64>,
    b: &mut DVector<f64>,
) {
    let info = sys.info();
    let (n, m) = (sys.n_coordinates(), info.frictions.len());
    let mu = sys.friction_coefficients();
    // N(qdd, f) = N0 + dN/dqdd qdd + dN/df f: the value at the origin and one column per unit.
    let (mut qdd, mut fr) = (vec![0.0; n], vec![0.0; m]);
    let origin = sys.forces_full(state, &qdd, &fr);
    let mut columns = Vec::with_capacity(n + m);
    for j in 0..n + m {
        if j < n {
            qdd[j] = 1.0;
        } else {
            fr[j - n] = 1.0;
        }
        columns.push(sys.forces_full(state, &qdd, &fr));
        qdd.iter_mut().for_each(|v| *v = 0.0);
        fr.iter_mut().for_each(|v| *v = 0.0);
    }
    for (i, (f, mode)) in info.frictions.iter().zip(modes).enumerate() {
        let r = n + i;
        match *mode {
            Mode::Slide(sign) => {
                let scale = sign * mu[i];
                a[(r, r)] += 1.0;
                for (j, col) in columns.iter().enumerate() {
                    a[(r, j)] += scale * (col[f.normal] - origin[f.normal]);
                }
                b[r] = -scale * origin[f.normal];
            }
            Mode::Stick => {
                for c in 0..n {
                    a[(r, c)] = jac[i * n + c];
                }
                b[r] = -bias[i];
            }
        }
    }
}

/// What may happen to one contact at a switch.
#[derive(Debug, Clone, PartialEq)]
pub enum Options {
    /// It keeps its mode (it is sliding and not at rest, or did not switch).
    Keep(Mode),
    /// It is at rest: it may stick or slide either way.
    AtRest,
    /// Its slip stopped while sliding with this sign: it sticks or slides back.
    Stopped(f64),
    /// Its stuck friction reached `mu N`: it slides with this sign, against the friction that
    /// held it.
    Breaks(f64),
}

impl Options {
    fn modes(&self) -> Vec<Mode> {
        match *self {
            Options::Keep(m) => vec![m],
            Options::AtRest => vec![Mode::Stick, Mode::Slide(1.0), Mode::Slide(-1.0)],
            Options::Stopped(s) => vec![Mode::Stick, Mode::Slide(-s)],
            Options::Breaks(s) => vec![Mode::Slide(s)],
        }
    }
}

/// The options of each contact at the start of a phase: at rest where its slip speed is below
/// [`REST`] of the state's speed scale (`sum_j |J_j|` times the largest `|qd_j|`: a contact
/// that stuck in the phase before keeps only rounding noise), otherwise sliding the way it
/// slips.
pub fn start_options(sys: &Bound, state: &State) -> Vec<Options> {
    let n = sys.n_coordinates();
    let (jac, _) = sys.friction(state);
    let fastest = state.qd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (0..sys.info().frictions.len())
        .map(|k| {
            let row = &jac[k * n..(k + 1) * n];
            let v: f64 = row.iter().zip(&state.qd).map(|(j, q)| j * q).sum();
            let size: f64 = fastest * row.iter().map(|j| j.abs()).sum::<f64>();
            if v == 0.0 || v.abs() <= REST * size {
                Options::AtRest
            } else {
                Options::Keep(Mode::Slide(v.signum()))
            }
        })
        .collect()
}

/// Whether a mode is consistent for a contact that could switch: its normal force pushes
/// (without friction a pull changes nothing here: the monitors report it), a stuck contact's
/// force is within `mu N`, a contact that starts sliding from rest accelerates its slip the way
/// it slides (one that breaks loose starts with zero slip acceleration).
fn consistent(opt: &Options, mode: Mode, d: &Dynamics, i: usize, mu: f64, normal: f64) -> bool {
    let frictionless = mu == 0.0 && matches!(mode, Mode::Slide(_));
    match (opt, mode) {
        (Options::Keep(_), _) => true,
        _ if !frictionless && (normal.is_nan() || normal < 0.0) => false,
        (_, Mode::Stick) => d.fr[i].abs() <= mu * normal,
        (Options::Breaks(_), Mode::Slide(_)) => true,
        (_, Mode::Slide(s)) => s * d.slip_acc[i] > 0.0,
    }
}

/// The one consistent combination of modes among `options` at `state`.
pub fn decide(
    sys: &Bound,
    state: &State,
    options: &[Options],
    t: f64,
) -> Result<Vec<Mode>, SolveError> {
    let info = sys.info();
    let lists: Vec<Vec<Mode>> = options.iter().map(Options::modes).collect();
    let total: usize = lists.iter().map(Vec::len).product();
    if total > MAX_COMBINATIONS {
        return Err(SolveError::FrictionIndeterminate {
            model: info.name,
            t,
            why: format!("{total} combinations of contact modes to try"),
        });
    }
    let mu = sys.friction_coefficients();
    let mut found: Vec<Vec<Mode>> = Vec::new();
    for mut index in 0..total {
        let modes: Vec<Mode> = lists
            .iter()
            .map(|l| {
                let mode = l[index % l.len()];
                index /= l.len();
                mode
            })
            .collect();
        let Ok(d) = dynamics(sys, state, &modes, t) else {
            continue;
        };
        let ok = d.painleve > PAINLEVE_FLOOR
            && (info.frictions.iter().enumerate())
                .all(|(i, f)| consistent(&options[i], modes[i], &d, i, mu[i], d.forces[f.normal]));
        if ok {
            found.push(modes);
        }
    }
    // Among consistent choices, contacts at rest that can stick do stick.
    let stuck = |m: &Vec<Mode>| m.iter().filter(|m| **m == Mode::Stick).count();
    let most = found.iter().map(stuck).max().unwrap_or(0);
    let all = found.len();
    found.retain(|m| stuck(m) == most);
    match found.len() {
        1 => Ok(found.remove(0)),
        0 => Err(SolveError::FrictionIndeterminate {
            model: info.name,
            t,
            why: "no contact mode is consistent: sticking needs more than mu N and no sliding \
                  direction accelerates the slip (a normal force that pulls, or Painlevé's \
                  inconsistency)"
                .into(),
        }),
        _ => Err(SolveError::FrictionIndeterminate {
            model: info.name,
            t,
            why: format!(
                "{} of {all} consistent contact modes stick as many contacts ({}): the motion \
                 is not determined by rigid bodies with Coulomb friction (Painlevé's \
                 indeterminacy)",
                found.len(),
                found
                    .iter()
                    .map(|m| describe(info, m))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        }),
    }
}

/// `foot_friction sticks, tip_friction slides +`.
pub fn describe(info: &crate::model::ModelInfo, modes: &[Mode]) -> String {
    info.frictions
        .iter()
        .zip(modes)
        .map(|(f, m)| format!("{} {}", f.name, m.describe()))
        .collect::<Vec<_>>()
        .join(", ")
}
