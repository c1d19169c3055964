//! The one consistent active set where contacts may close or open and frictions stick or
//! slide: the options at a state, every combination of them, and the choice among the
//! consistent ones.

use super::dynamics::{Dynamics, DynamicsWork, Rows, dynamics, solve_filled};
use super::{
    Active, DECIDE_TOLERANCE, MAX_COMBINATIONS, Mode, PAINLEVE_FLOOR, REST, STICK_ROUNDING, Sign,
    check_active,
};
use crate::model::ModelInfo;
use crate::results::{ContactSet, Holding, Indeterminacy};
use crate::solve::SolveError;
use crate::solve::integrated::rest;
use crate::system::{Bound, State};
use nalgebra::{DMatrix, DVector};

/// What may happen to one contact at a decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactOption {
    /// It keeps its state (closed or open).
    Keep(bool),
    /// It touches without moving apart: it may stay closed or open.
    Candidate,
    /// Its force reached zero: it opens.
    Opens,
}

/// What may happen to one friction at a decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionOption {
    /// It keeps its mode (it is sliding and not at rest, or did not switch).
    Keep(Mode),
    /// It is at rest: it may stick or slide either way.
    AtRest,
    /// Its slip stopped while sliding with this sign: it sticks or slides back.
    Stopped(Sign),
    /// Its stuck friction reached `mu N`: it slides with this sign, against the friction that
    /// held it.
    Breaks(Sign),
}

impl FrictionOption {
    fn modes(&self) -> Vec<Mode> {
        match *self {
            FrictionOption::Keep(m) => vec![m],
            FrictionOption::AtRest => vec![
                Mode::Stick,
                Mode::Slide(Sign::Plus),
                Mode::Slide(Sign::Minus),
            ],
            FrictionOption::Stopped(s) => vec![Mode::Stick, Mode::Slide(s.flip())],
            FrictionOption::Breaks(s) => vec![Mode::Slide(s)],
        }
    }
}

/// The options of every contact and friction at a decision.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Per contact.
    pub contacts: Vec<ContactOption>,
    /// Per friction.
    pub frictions: Vec<FrictionOption>,
}

/// The options of every friction at a state: at rest where its slip speed is below [`REST`]
/// of the state's speed scale (`sum_j |T_j|` times the largest `|qd_j|`), otherwise sliding the
/// way it slips.
pub fn friction_options(sys: &Bound, state: &State) -> Result<Vec<FrictionOption>, SolveError> {
    let n = sys.n_coordinates();
    let (jac, _) = sys.friction(state)?;
    let fastest = state.qd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    Ok((0..sys.info().frictions.len())
        .map(|k| {
            let row = &jac[k * n..(k + 1) * n];
            let v: f64 = row.iter().zip(&state.qd).map(|(j, q)| j * q).sum();
            let size: f64 = fastest * row.iter().map(|j| j.abs()).sum::<f64>();
            if v == 0.0 || v.abs() <= REST * size {
                FrictionOption::AtRest
            } else {
                FrictionOption::Keep(Mode::Slide(Sign::of(v)))
            }
        })
        .collect())
}

/// Where contact options are taken: at release, or after a phase that held some contacts
/// closed by integration, whose gaps have drifted within the run's tolerance.
#[derive(Debug, Clone, Copy)]
pub enum Moment<'a> {
    /// The spec's initial state.
    Release,
    /// The end of a phase.
    After {
        /// Absolute time (s from release).
        t: f64,
        /// The contacts the ending phase held closed.
        held: &'a [bool],
        /// The gap (relative to the system's length) a held contact may have drifted by and
        /// still touch: the tolerance its constraint drift is checked against.
        drift: f64,
    },
}

impl Moment<'_> {
    fn t(&self) -> f64 {
        match self {
            Moment::Release => 0.0,
            Moment::After { t, .. } => *t,
        }
    }

    /// How far (relative) contact `i`'s gap may be from zero and still touch.
    fn touching(&self, i: usize) -> f64 {
        match self {
            Moment::After { held, drift, .. } if held.get(i) == Some(&true) => {
                drift.max(DECIDE_TOLERANCE)
            }
            _ => DECIDE_TOLERANCE,
        }
    }
}

/// Each contact's state where the motion starts (or goes on after an event) at `state`: a
/// contact the model eliminates is closed; a gap above [`DECIDE_TOLERANCE`] of the system's
/// length scale is open (a contact the phase before held closed touches within its drift
/// tolerance, see [`Moment`]); a touching contact moving apart is open; one at rest is a
/// candidate. A gap below that is [`SolveError::Overlap`]; a touching contact moving together
/// is [`SolveError::ImpactAtRelease`] (impacts are not modelled yet).
pub fn contact_options(
    sys: &Bound,
    state: &State,
    at: Moment,
) -> Result<Vec<ContactOption>, SolveError> {
    let info = sys.info();
    let gaps = sys.gaps(state)?;
    let (jac, _) = sys.constraints(state)?;
    let n = sys.n_coordinates();
    let length = sys.length_scale(state)?;
    let fastest = state.qd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut out = Vec::new();
    for (i, c) in info.contacts.iter().enumerate() {
        if c.closed {
            out.push(ContactOption::Keep(true));
            continue;
        }
        let gap = gaps[i];
        let tol = at.touching(i) * c.gap.scale(length);
        if !gap.is_finite() || gap < -tol {
            return Err(SolveError::Overlap {
                model: info.name,
                contact: c.name,
                gap,
                unit: c.gap.unit(),
                t: at.t(),
            });
        }
        if gap > tol && !c.bilateral {
            out.push(ContactOption::Keep(false));
            continue;
        }
        let row = &jac[i * n..(i + 1) * n];
        let v = normal_velocity(row, state);
        let size: f64 = fastest * row.iter().map(|j| j.abs()).sum::<f64>();
        let at_rest = v == 0.0 || v.abs() <= REST * size;
        out.push(match (c.bilateral, at_rest) {
            (true, _) => ContactOption::Keep(true),
            (false, true) => ContactOption::Candidate,
            (false, false) if v > 0.0 => ContactOption::Keep(false),
            (false, false) => {
                return Err(SolveError::ImpactAtRelease {
                    model: info.name,
                    contact: c.name,
                    velocity: v,
                });
            }
        });
    }
    Ok(out)
}

/// A contact's normal velocity `J_i qd` (negative: closing), from its Jacobian row.
pub fn normal_velocity(row: &[f64], state: &State) -> f64 {
    row.iter().zip(&state.qd).map(|(j, q)| j * q).sum()
}

/// Whether a candidate combination is consistent: closed candidates push (within
/// [`DECIDE_TOLERANCE`] of the largest force, or of their own force's size where that is
/// smaller, [`force_scales`]), open candidates accelerate apart (within
/// [`DECIDE_TOLERANCE`] of the size of their own normal acceleration's terms; a contact that
/// opens at its force's root, within that of the largest force, judged as a force), frictions
/// obey Coulomb's law in their modes, and sliding is clear of Painlevé's singularity.
fn consistent(
    sys: &Bound,
    options: &Options,
    active: &Active,
    d: &Dynamics,
    acc_scale: &[f64],
    own_force: &[f64],
) -> bool {
    let info = sys.info();
    let force_scale = (d.forces.iter())
        .chain(&d.fr)
        .fold(0.0f64, |m, f| m.max(f.abs()));
    let mu = sys.friction_coefficients();
    for (i, opt) in options.contacts.iter().enumerate() {
        let ok = match (opt, active.closed[i]) {
            (ContactOption::Candidate, true) => {
                info.contacts[i].bilateral
                    || d.forces[i] >= -DECIDE_TOLERANCE * force_scale.min(own_force[i])
            }
            (ContactOption::Candidate, false) => {
                d.normal_acc[i] >= -DECIDE_TOLERANCE * acc_scale[i]
            }
            // A contact whose force the phase before took through zero: the state is at that
            // root, where the open set's normal acceleration is zero as the closed set's force
            // is, so what is left is the root's rounding. It is judged as a force (the
            // acceleration times the contact's effective mass, `own_force / acc_scale`) against
            // the largest force of the system, as the force was while it pushed: a fast phase
            // hands over a state formed from its own coordinate, which the general coordinates
            // carry only to their rounding (a low rod's tip at `x2 = ell cos(theta)`: a residue
            // 1e-16 of the hinge's force, but a pull at a light cube's own scale;
            // `tests/contacts_physics.rs`). Only the open state is tried for it, so this
            // cannot make two sets consistent.
            (ContactOption::Opens, false) => {
                let implied = -d.normal_acc[i] * own_force[i] / acc_scale[i];
                d.normal_acc[i] >= 0.0 || implied <= DECIDE_TOLERANCE * force_scale
            }
            _ => true,
        };
        if !ok {
            return false;
        }
    }
    for (j, opt) in options.frictions.iter().enumerate() {
        if !active.friction_acts(info, j) {
            continue;
        }
        let normal = d.forces[info.frictions[j].contact_index];
        let mode = active.modes[j];
        let ok = match (opt, mode) {
            (FrictionOption::Keep(_), _) => true,
            // Within the cone to rounding: relative to `mu N`, and to the largest force, since
            // with `mu = 0` the friction a stick needs is zero only to rounding (a nearly flat
            // ladder's foot at rest where its slip's acceleration vanishes, at the wall's
            // release).
            (_, Mode::Stick) => {
                d.fr[j].abs()
                    <= mu[j] * normal.max(0.0) * (1.0 + STICK_ROUNDING)
                        + STICK_ROUNDING * force_scale
            }
            (FrictionOption::Breaks(_), Mode::Slide(_)) => true,
            (_, Mode::Slide(s)) => s.value() * d.slip_acc[j] > 0.0,
        };
        if !ok {
            return false;
        }
    }
    d.painleve > PAINLEVE_FLOOR
}

/// Every combination the options allow (contacts first, then the modes of the frictions whose
/// contacts are closed in it); an error past [`MAX_COMBINATIONS`]. The one enumeration of
/// contact states and friction modes: [`decide`]'s at the acceleration level, and the
/// impacts' at the velocity level (`solve::integrated::impact`).
pub fn combinations(sys: &Bound, options: &Options, t: f64) -> Result<Vec<Active>, SolveError> {
    let info = sys.info();
    let contact_lists: Vec<Vec<bool>> = (options.contacts.iter())
        .map(|o| match o {
            ContactOption::Keep(c) => vec![*c],
            ContactOption::Candidate => vec![true, false],
            ContactOption::Opens => vec![false],
        })
        .collect();
    let mode_lists: Vec<Vec<Mode>> = options.frictions.iter().map(|o| o.modes()).collect();
    let total = (contact_lists.iter().map(Vec::len))
        .chain(mode_lists.iter().map(Vec::len))
        .try_fold(1usize, |acc, l| acc.checked_mul(l))
        .filter(|&n| n <= MAX_COMBINATIONS)
        .ok_or_else(|| SolveError::Indeterminate {
            model: info.name,
            t,
            contacts: info.contacts.iter().map(|c| c.name).collect(),
            why: Indeterminacy::TooManyCombinations {
                limit: MAX_COMBINATIONS,
            }
            .into(),
        })?;
    let mut out: Vec<Active> = Vec::new();
    // The canonical form of each set kept, made once (comparing against forms made again for
    // every earlier set allocated quadratically in the count).
    let mut seen: Vec<Active> = Vec::new();
    for mut index in 0..total {
        let mut pick = |l: usize| {
            let k = index % l;
            index /= l;
            k
        };
        let closed: Vec<bool> = contact_lists.iter().map(|l| l[pick(l.len())]).collect();
        let modes: Vec<Mode> = mode_lists.iter().map(|l| l[pick(l.len())]).collect();
        let active = Active { closed, modes };
        // Modes of frictions whose contact is open do not matter: keep one of each.
        let canonical = |a: &Active| Active {
            closed: a.closed.clone(),
            modes: (a.modes.iter().enumerate())
                .map(|(j, m)| {
                    if a.friction_acts(info, j) {
                        *m
                    } else {
                        Mode::Stick
                    }
                })
                .collect(),
        };
        let c = canonical(&active);
        if !seen.contains(&c) {
            seen.push(c);
            out.push(active);
        }
    }
    Ok(out)
}

/// The one consistent active set among `options` at `state` (`t` from release). Among the
/// consistent sets, those that stick the most frictions are kept; if several remain and all
/// give the same accelerations (a contact whose force and normal acceleration both vanish),
/// the one with the most contacts closed; otherwise [`SolveError::Indeterminate`].
pub fn decide(sys: &Bound, state: &State, options: &Options, t: f64) -> Result<Active, SolveError> {
    let info = sys.info();
    sys.check_state(state)?;
    if options.contacts.len() != info.contacts.len()
        || options.frictions.len() != info.frictions.len()
    {
        return Err(SolveError::ActiveSize {
            model: info.name,
            contacts: info.contacts.len(),
            frictions: info.frictions.len(),
            closed: options.contacts.len(),
            modes: options.frictions.len(),
        });
    }
    let mut found: Vec<(Active, Dynamics)> = Vec::new();
    let mut singular: Vec<ContactSet> = Vec::new();
    // The model's matrices at the state, and its inverse mass matrix once one is needed, are
    // shared by every set tried.
    let mut work = DynamicsWork::default();
    work.rows.fill(sys, state)?;
    let mut inverse: Option<DMatrix<f64>> = None;
    for active in combinations(sys, options, t)? {
        check_active(info, &active)?;
        match solve_filled(sys, state, &active, t, &mut work) {
            Ok(()) => {}
            // Redundant supports that hold the system at rest (a ladder stuck at both ends):
            // its motion is none, whatever share of the load each support takes.
            Err(SolveError::SingularContacts { .. })
                if rest::holds(sys, state, &active, t)?.is_some() =>
            {
                return Err(at_rest(info, &active, t, Holding::Redundantly));
            }
            // Other singular sets (Painlevé's singularity exactly, or redundant contacts that
            // cannot hold) are not a motion; the error says so if no set is. Nothing is lost
            // where another set is consistent: a set whose rows are redundant describes the
            // motion of a smaller set (one redundant row left open), which is tried on its own.
            Err(SolveError::SingularContacts { .. }) => {
                singular.push(active.set(info));
                continue;
            }
            Err(e) => return Err(e),
        }
        let inverse = match &inverse {
            Some(inv) => inv,
            None => inverse.insert(inverse_mass(&work.rows, state, t)?),
        };
        let d = &work.out;
        let scales = acc_scales(&work.rows, inverse, info, &active, d);
        let forces = force_scales(&work.rows, inverse, &scales);
        if consistent(sys, options, &active, d, &scales, &forces) {
            found.push((active, d.clone()));
        }
    }
    let active = pick(info, options, found, singular, t)?;
    if rest::pins(sys, state, &active)? {
        return Err(at_rest(info, &active, t, Holding::Pinned));
    }
    if in_equilibrium(sys, state, &active, t)? {
        return Err(at_rest(info, &active, t, Holding::InEquilibrium));
    }
    Ok(active)
}

/// The size of each contact's normal acceleration `J qdd + bias` in `d`, what its rounding is
/// relative to: `sum_j |J_ij| s_j + |bias_i|`, where `s_j` sums the sizes of what each force
/// (the applied ones, then each closed contact's and acting friction's) contributes to
/// `qdd_j`. So a contact whose motion is slow next to gravity (a rod nearly flat on a thin
/// block) is judged at its own scale, and one whose acceleration cancels to rounding noise
/// (a foot just lifting) at the scale of the forces that cancel.
///
/// `inverse` is the inverse of `rows`' mass matrix ([`inverse_mass`]).
fn acc_scales(
    rows: &Rows,
    inverse: &DMatrix<f64>,
    info: &ModelInfo,
    active: &Active,
    d: &Dynamics,
) -> Vec<f64> {
    let size = coordinate_scales(rows, inverse, info, active, d);
    (0..info.contacts.len())
        .map(|i| {
            let row = rows.row(&rows.jac, i);
            let terms: f64 = row.iter().zip(&size).map(|(j, s)| (j * s).abs()).sum();
            terms + rows.bias[i].abs()
        })
        .collect()
}

/// The size of each contact's force that its acceleration scale (`acc_scale`, [`acc_scales`])
/// stands for: that scale times the contact's effective mass `1 / (J M^-1 J^T)`. So the force
/// of a contact that pushes a light body (a cube of 1e-9 kg beside a rod of 1e-3 kg) is judged
/// at its own size, not at the size of the largest force of the system, which would take a
/// pull that opens it for rounding. Infinite for a row that moves nothing.
fn force_scales(rows: &Rows, inverse: &DMatrix<f64>, acc_scale: &[f64]) -> Vec<f64> {
    (acc_scale.iter().enumerate())
        .map(|(i, a)| {
            let row = DVector::from_column_slice(rows.row(&rows.jac, i));
            let effective = row.dot(&(inverse * &row));
            if effective > 0.0 {
                a / effective
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// The inverse of the mass matrix of `rows` (at `state`, time `t` from release). One that
/// cannot be inverted (while a constrained system could be solved) gives no scale to judge a
/// contact by: [`SolveError::SingularMassMatrix`], not a guess.
fn inverse_mass(rows: &Rows, state: &State, t: f64) -> Result<DMatrix<f64>, SolveError> {
    let mass = DMatrix::from_row_slice(rows.n, rows.n, &rows.mass);
    mass.try_inverse()
        .ok_or_else(|| SolveError::SingularMassMatrix {
            t,
            q: state.q.clone(),
        })
}

/// The size of each coordinate's acceleration in `d`, what its rounding is relative to: the
/// sum of the sizes of what each force (the applied ones, then each closed contact's and acting
/// friction's) contributes to it through the inverse mass matrix.
fn coordinate_scales(
    rows: &Rows,
    inverse: &DMatrix<f64>,
    info: &ModelInfo,
    active: &Active,
    d: &Dynamics,
) -> Vec<f64> {
    let n = rows.n;
    let mut size = vec![0.0f64; n];
    let mut add = |force: &[f64], times: f64| {
        let f = DVector::from_iterator(n, force.iter().map(|v| v * times));
        for (s, c) in size.iter_mut().zip((inverse * f).iter()) {
            *s += c.abs();
        }
    };
    add(&rows.rhs, 1.0);
    for i in (0..info.contacts.len()).filter(|&i| active.closed[i] && !info.contacts[i].closed) {
        add(rows.row(&rows.jac, i), d.forces[i]);
    }
    for j in (0..info.frictions.len()).filter(|&j| active.friction_acts(info, j)) {
        add(rows.row(&rows.tjac, j), d.fr[j]);
    }
    size
}

/// Whether the system at `state` stays where it is with `active`: no coordinate moves and
/// none accelerates beyond rounding ([`DECIDE_TOLERANCE`] of what the forces contribute to it).
/// Such an equilibrium has no motion to follow (a rod lying flat on the floor against a
/// cube, the supports taking its weight), whatever its free coordinates.
fn in_equilibrium(sys: &Bound, state: &State, active: &Active, t: f64) -> Result<bool, SolveError> {
    if state.qd.iter().any(|v| *v != 0.0) {
        return Ok(false);
    }
    let d = dynamics(sys, state, active, t)?;
    let rows = Rows::at(sys, state)?;
    let mass = DMatrix::from_row_slice(rows.n, rows.n, &rows.mass);
    let Some(inverse) = mass.try_inverse() else {
        return Ok(false);
    };
    let size = coordinate_scales(&rows, &inverse, sys.info(), active, &d);
    Ok((d.qdd.iter().zip(&size)).all(|(a, s)| a.abs() <= DECIDE_TOLERANCE * s))
}

/// The outcome of a system its supports hold at rest.
fn at_rest(info: &ModelInfo, active: &Active, t: f64, held: Holding) -> SolveError {
    SolveError::AtRest {
        model: info.name,
        t,
        held,
        set: active.set(info),
    }
}

/// [`decide`]'s choice among the consistent sets.
fn pick(
    info: &ModelInfo,
    options: &Options,
    mut found: Vec<(Active, Dynamics)>,
    singular: Vec<ContactSet>,
    t: f64,
) -> Result<Active, SolveError> {
    let concerned = || {
        (info.contacts.iter().zip(&options.contacts))
            .filter(|(_, o)| !matches!(o, ContactOption::Keep(false)))
            .map(|(c, _)| c.name)
            .chain(info.frictions.iter().map(|f| f.name))
            .collect()
    };
    let stuck = |a: &Active| {
        (0..a.modes.len())
            .filter(|&j| a.friction_acts(info, j) && a.modes[j] == Mode::Stick)
            .count()
    };
    let most = found.iter().map(|(a, _)| stuck(a)).max().unwrap_or(0);
    let all = found.len();
    found.retain(|(a, _)| stuck(a) == most);
    let Some((first, d0)) = found.first() else {
        return Err(SolveError::Indeterminate {
            model: info.name,
            t,
            contacts: concerned(),
            why: Indeterminacy::NoneConsistent { singular }.into(),
        });
    };
    let scale = d0
        .qdd
        .iter()
        .fold(0.0f64, |m, a| m.max(a.abs()))
        .max(1e-300);
    let same =
        |d: &Dynamics| (d.qdd.iter().zip(&d0.qdd)).all(|(a, b)| (a - b).abs() <= 1e-9 * scale);
    if found.iter().all(|(_, d)| same(d)) {
        let closed = |a: &Active| a.closed.iter().filter(|c| **c).count();
        let best = found.iter().map(|(a, _)| closed(a)).max().unwrap_or(0);
        if let Some((a, _)) = found.iter().find(|(a, _)| closed(a) == best) {
            return Ok(a.clone());
        }
        return Ok(first.clone());
    }
    Err(SolveError::Indeterminate {
        model: info.name,
        t,
        contacts: concerned(),
        why: Indeterminacy::SeveralMotions {
            sets: found.iter().map(|(a, _)| a.set(info)).collect(),
            of: all,
        }
        .into(),
    })
}

/// The error for sliding that has reached Painlevé's singularity ([`PAINLEVE_FLOOR`]).
pub fn painleve_error(sys: &Bound, state: &State, active: &Active, t: f64) -> SolveError {
    let info = sys.info();
    SolveError::Indeterminate {
        model: info.name,
        t,
        contacts: active.closed_names(info),
        why: Indeterminacy::PainleveSingularity {
            set: active.set(info),
            q: state.q.clone(),
            floor: PAINLEVE_FLOOR,
        }
        .into(),
    }
}
