//! Impacts: where bodies meet with an approach velocity, the impulses at the contacts that close
//! and at those already closed, by Newton's law of restitution with complementarity and
//! Coulomb's friction cone — a velocity-level linear complementarity problem over the same
//! constraint and slip Jacobians as the contact forces — and the velocities after.
//!
//! With `M` the mass matrix, `J` the rows of the contacts taking part and `T` the slip rows of
//! their frictions, the normal impulses `P` and tangential impulses `P_t` change the velocities
//! by `M (qd+ - qd-) = J^T P + T^T P_t`. Each unilateral contact `i` taking part has its normal
//! velocity before, `v-_i = J_i qd-` (negative: approaching; zero: resting, a pivot that may
//! lift), and after, `v+_i`, with `P_i >= 0`, `v+_i + e_i v-_i >= 0` and
//! `P_i (v+_i + e_i v-_i) = 0`; a closed bilateral contact keeps `v+_i = 0` with an impulse of
//! either sign. Each friction `j` at a contact taking part (coefficient `mu_j`, slip
//! `s_j = T_j qd`) keeps its impulse in the planar cone `|P_t,j| <= mu_j P_i`, whose two edges
//! make the problem exact: it sticks (`s+_j = 0`) or slides (`P_t,j = -mu_j P_i sign(s+_j)`).
//!
//! The problem is solved by trying every combination of laws — each unilateral contact open or
//! with Newton's law as an equality, each friction sticking or sliding either way — with the one
//! enumeration of the acceleration-level decision (`contacts::combinations`), each combination a
//! linear system. None consistent, or several with different velocities after, is a typed
//! error, never a guess. The kinetic energy lost is, exactly,
//! `-sum_i P_i (v-_i + v+_i) / 2` (the normal part) plus `-sum_j P_t,j (s-_j + s+_j) / 2` (the
//! friction part); Newton's law with friction can create energy for some geometries, and an
//! impact that would is [`SolveError::ImpactGainsEnergy`]. Each contact's and friction's law
//! ([`ContactLaw`], [`FrictionLaw`]) is recorded: with it fixed, the impact is a linear map,
//! whose derivative is the saltation of the sensitivities.

use crate::model::ModelInfo;
use crate::results::Indeterminacy;
use crate::solve::SolveError;
use crate::solve::integrated::contacts::{
    Active, ContactOption, FrictionOption, Mode, Options, Sign, combinations,
};
use crate::solve::linear;
use crate::system::{Bound, State, SystemError, check_restitutions};
use nalgebra::{DMatrix, DVector};

/// Normal velocities within this fraction of the impact's largest approach or slip speed (or
/// 1 m/s times machine precision) count as zero, and impulses within it (times the largest
/// impulse) as zero, when the complementarity conditions are checked; kinetic energy gained
/// within it (times the kinetic energy before) is rounding.
pub const IMPACT_TOLERANCE: f64 = 1e-9;

/// Most unilateral contacts taking part in one impact (the sets tried are `2^count`, times
/// three per friction).
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

/// The law that held at one contact across an impact. With every contact's and friction's law
/// fixed, the velocities after solve one linear system,
/// `[M -J_E^T -T_F^T; J_E 0 0; rows of F] [qd+; P_E; P_t] = [M qd-; targets; 0]`, with `E` the
/// contacts under [`ContactLaw::Restitution`] or [`ContactLaw::Bilateral`] and `F` the acting
/// frictions' rows ([`FrictionLaw`]): the impact map whose derivative is the saltation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactLaw {
    /// Not taking part ([`Part::None`]): no impulse, no condition.
    Out,
    /// Took part and took no impulse: `v+ >= -e v-` held as an inequality (a resting pivot
    /// that lifts, or a contact that was already leaving).
    Open,
    /// Newton's law held as an equality with an impulse `P >= 0`: `v+ = -e v-` for a contact
    /// that approached, `v+ = 0` for one at rest.
    Restitution,
    /// A closed bilateral contact: `v+ = 0`, an impulse of either sign.
    Bilateral,
}

/// The law that held at one friction across an impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionLaw {
    /// Not acting: its contact took no impulse ([`ContactLaw::Out`] or [`ContactLaw::Open`]).
    Out,
    /// Stuck: the slip after is zero, `|P_t| <= mu P` (the impulse is what keeps it so).
    Stick,
    /// Sliding with this sign of the slip after: `P_t = -sign mu P` (for `mu = 0` too, where the
    /// impulse is zero; its derivative in `mu` is not).
    Slide(Sign),
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
    /// Per friction of the system: the slip velocity before (`T qd-`).
    pub slip_before: Vec<f64>,
    /// Per friction: the slip velocity after.
    pub slip_after: Vec<f64>,
    /// Per friction: the tangential impulse (N s; zero where it does not act).
    pub friction_impulse: Vec<f64>,
    /// Per contact: the law that held.
    pub laws: Vec<ContactLaw>,
    /// Per friction: the law that held.
    pub friction_laws: Vec<FrictionLaw>,
    /// Kinetic energy lost (J), from the impulses: `normal_energy_lost + friction_energy_lost`.
    pub energy_lost: f64,
    /// The normal impulses' part of it, `-sum_i P_i (v-_i + v+_i) / 2`.
    pub normal_energy_lost: f64,
    /// The tangential impulses' part of it, `-sum_j P_t,j (s-_j + s+_j) / 2`.
    pub friction_energy_lost: f64,
    /// The state after: the configuration unchanged, the velocities changed.
    pub after: State,
}

/// The impact at `state` (time `t`, for messages) with each contact's `parts`: the impulses,
/// the velocities after and the energy lost. A part list of the wrong length, impulses that are
/// not unique or do not exist, or an impact that would create energy, are typed errors.
pub fn resolve(sys: &Bound, state: &State, parts: &[Part], t: f64) -> Result<Impact, SolveError> {
    resolve_with(sys, state, parts, sys.restitutions(), t)
}

/// The matrices of one impact: the mass matrix, the contacts' and frictions' rows, the
/// velocities before, the targets of Newton's law and the scales zero is judged by.
struct Problem<'a> {
    info: &'static ModelInfo,
    n: usize,
    mass: DMatrix<f64>,
    jac: Vec<f64>,
    tjac: Vec<f64>,
    qd: DVector<f64>,
    parts: &'a [Part],
    mu: Vec<f64>,
    before: Vec<f64>,
    slip_before: Vec<f64>,
    /// Per contact: `v+` where Newton's law holds with equality.
    target: Vec<f64>,
    /// The largest approach or slip speed of the contacts taking part.
    speed: f64,
}

/// One combination of laws solved: the velocities after, and per contact and per friction the
/// impulses.
struct Solution {
    qd: DVector<f64>,
    impulse: Vec<f64>,
    friction_impulse: Vec<f64>,
    active: Active,
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
    let problem = Problem::at(sys, state, parts, restitution)?;
    let info = problem.info;
    let taking: Vec<usize> = (0..parts.len())
        .filter(|&i| parts[i] != Part::None)
        .collect();
    let indeterminate = |why| undecided(info, &taking, t, why);
    let unilateral = parts.iter().filter(|p| **p == Part::Unilateral).count();
    if unilateral > MAX_IMPACT_CONTACTS {
        return Err(indeterminate(Indeterminacy::ImpactTooManyContacts {
            limit: MAX_IMPACT_CONTACTS,
        }));
    }
    let mut found: Vec<Solution> = Vec::new();
    for active in combinations(sys, &problem.options(), t)? {
        if let Some(s) = problem.solve(active)
            && problem.consistent(&s)
        {
            found.push(s);
        }
    }
    // Of the combinations that hold, one that sticks the most frictions (at the cone's edge a
    // slide that ends at zero slip is the same impact as a stick).
    let stuck = |s: &Solution| {
        (s.active.modes.iter().enumerate())
            .filter(|(j, m)| problem.acts(&s.active, *j) && **m == Mode::Stick)
            .count()
    };
    let Some(best) = (0..found.len()).max_by_key(|&k| (stuck(&found[k]), usize::MAX - k)) else {
        return Err(indeterminate(Indeterminacy::ImpactNoImpulses));
    };
    let chosen = found.swap_remove(best);
    let scale = chosen.qd.iter().fold(problem.speed, |a, v| a.max(v.abs()));
    let differ = |s: &Solution| {
        (s.qd.iter().zip(chosen.qd.iter())).any(|(a, b)| (a - b).abs() > IMPACT_TOLERANCE * scale)
    };
    if found.iter().any(differ) {
        return Err(indeterminate(Indeterminacy::ImpactSeveral {
            count: found.len() + 1,
        }));
    }
    problem.impact(sys, state, chosen, t, &taking)
}

/// The impact that closes a converging sequence of impacts of two contacts or more (a block
/// rocking to rest on two corners), its contacts `parts` [`Part::Bilateral`]: each held closed
/// plastically (its normal velocity after zero), each friction under the law `frictions` it
/// obeyed in the sequence's last impact (stuck, or sliding its way), and no impulse at a
/// friction that did not act there. Its impulses stand for the sequence's impacts still to
/// come, summed (a normal one may be of either sign); those impacts change the velocities by
/// less than the run resolves, and friction acts again in the motion after, as the run decides
/// it. A contact left to decide ([`Part::Unilateral`]) is refused: only the sequence's
/// contacts take part.
pub fn close_sequence(
    sys: &Bound,
    state: &State,
    parts: &[Part],
    frictions: &[FrictionLaw],
    t: f64,
) -> Result<Impact, SolveError> {
    let plastic = vec![0.0; parts.len()];
    let mut problem = Problem::at(sys, state, parts, &plastic)?;
    let info = problem.info;
    let taking: Vec<usize> = (0..parts.len())
        .filter(|&i| parts[i] != Part::None)
        .collect();
    let indeterminate = |why| undecided(info, &taking, t, why);
    if parts.contains(&Part::Unilateral) {
        return Err(indeterminate(Indeterminacy::ZenoOutsideContact));
    }
    let law = |j: usize| frictions.get(j).copied().unwrap_or(FrictionLaw::Out);
    // A friction that did not act takes no impulse: it `slides` under a coefficient of zero.
    let modes = (0..problem.mu.len())
        .map(|j| match law(j) {
            FrictionLaw::Stick => Mode::Stick,
            FrictionLaw::Slide(sign) => Mode::Slide(sign),
            FrictionLaw::Out => Mode::Slide(Sign::Plus),
        })
        .collect();
    for (j, mu) in problem.mu.iter_mut().enumerate() {
        if law(j) == FrictionLaw::Out {
            *mu = 0.0;
        }
    }
    let active = Active {
        closed: parts.iter().map(|p| *p == Part::Bilateral).collect(),
        modes,
    };
    let mut solution =
        (problem.solve(active)).ok_or_else(|| indeterminate(Indeterminacy::ZenoCannotHold))?;
    // Held closed with no way left to move, the system is at rest but for the rounding of the
    // solve: at rest exactly (so that the contacts decided after see no motion).
    let before = problem.qd.iter().fold(problem.speed, |a, v| a.max(v.abs()));
    if (solution.qd.iter()).all(|v| v.abs() <= IMPACT_TOLERANCE * before) {
        solution.qd.fill(0.0);
    }
    let mut impact = problem.impact(sys, state, solution, t, &taking)?;
    for (j, out) in impact.friction_laws.iter_mut().enumerate() {
        if law(j) == FrictionLaw::Out {
            *out = FrictionLaw::Out;
        }
    }
    Ok(impact)
}

/// The contacts `idx` by name, comma-separated.
/// An impact of the contacts `taking` at `t` that no single set of impulses decides, and why.
fn undecided(info: &ModelInfo, taking: &[usize], t: f64, why: Indeterminacy) -> SolveError {
    SolveError::Indeterminate {
        model: info.name,
        t,
        contacts: names(info, taking),
        why: Box::new(why),
    }
}

fn names(info: &ModelInfo, idx: &[usize]) -> Vec<&'static str> {
    (idx.iter().filter_map(|&i| info.contacts.get(i)))
        .map(|c| c.name)
        .collect()
}

impl<'a> Problem<'a> {
    /// The problem at `state`, its sizes checked.
    fn at(
        sys: &Bound,
        state: &State,
        parts: &'a [Part],
        restitution: &[f64],
    ) -> Result<Problem<'a>, SolveError> {
        let info = sys.info();
        sys.check_state(state)?;
        let n = sys.n_coordinates();
        let m = info.contacts.len();
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
        let (tjac, _) = sys.friction(state)?;
        let qd = DVector::from_row_slice(state.qd());
        let dot = |row: &[f64]| row.iter().zip(state.qd()).map(|(a, b)| a * b).sum::<f64>();
        let before: Vec<f64> = (0..m).map(|i| dot(&jac[i * n..(i + 1) * n])).collect();
        let nf = info.frictions.len();
        let slip_before: Vec<f64> = (0..nf).map(|j| dot(&tjac[j * n..(j + 1) * n])).collect();
        // The target of a contact whose law holds with equality: v+ = -e v- (approaching), 0
        // (resting or separating; a separating contact that takes part can only stay so).
        let target = (0..m)
            .map(|i| -restitution[i] * before[i].min(0.0))
            .collect();
        let taking = |i: usize| parts[i] != Part::None;
        let speed = ((0..m).filter(|&i| taking(i)).map(|i| before[i].abs()))
            .chain(
                (0..nf)
                    .filter(|&j| taking(info.frictions[j].contact_index))
                    .map(|j| slip_before[j].abs()),
            )
            .fold(f64::EPSILON, f64::max);
        Ok(Problem {
            info,
            n,
            mass: DMatrix::from_row_slice(n, n, &mass),
            jac,
            tjac,
            qd,
            parts,
            mu: sys.friction_coefficients(),
            before,
            slip_before,
            target,
            speed,
        })
    }

    fn row(&self, i: usize) -> &[f64] {
        &self.jac[i * self.n..(i + 1) * self.n]
    }

    fn trow(&self, j: usize) -> &[f64] {
        &self.tjac[j * self.n..(j + 1) * self.n]
    }

    /// What each contact and friction may do: a unilateral contact taking part is open or
    /// closed (its law an equality), a bilateral one closed; a friction at a contact taking part
    /// sticks or slides either way.
    fn options(&self) -> Options {
        let contacts = (self.parts.iter())
            .map(|p| match p {
                Part::None => ContactOption::Keep(false),
                Part::Unilateral => ContactOption::Candidate,
                Part::Bilateral => ContactOption::Keep(true),
            })
            .collect();
        let frictions = (self.info.frictions.iter())
            .map(|f| match self.parts[f.contact_index] {
                Part::None => FrictionOption::Keep(Mode::Stick),
                _ => FrictionOption::AtRest,
            })
            .collect();
        Options {
            contacts,
            frictions,
        }
    }

    /// Whether friction `j` acts in `active` (its contact takes an impulse).
    fn acts(&self, active: &Active, j: usize) -> bool {
        active.friction_acts(self.info, j)
    }

    /// The velocities after and the impulses of `active`:
    /// `M qd+ - J^T P - T^T P_t = M qd-`, `J_i qd+ = target_i` for every closed contact, and per
    /// acting friction `T_j qd+ = 0` (stuck) or `P_t,j + s mu_j P_i = 0` (sliding with sign
    /// `s`); `None` where that system is singular (redundant rows: a smaller set describes the
    /// same impact).
    fn solve(&self, active: Active) -> Option<Solution> {
        let n = self.n;
        let rows: Vec<usize> = (0..self.parts.len())
            .filter(|&i| active.closed[i])
            .collect();
        let fr: Vec<usize> = (0..self.mu.len())
            .filter(|&j| self.acts(&active, j))
            .collect();
        let dim = n + rows.len() + fr.len();
        // Row-major, for `linear::solve_in_place`.
        let mut a = vec![0.0; dim * dim];
        let mut x = vec![0.0; dim];
        let momentum = &self.mass * &self.qd;
        for r in 0..n {
            for c in 0..n {
                a[r * dim + c] = self.mass[(r, c)];
            }
            x[r] = momentum[r];
        }
        for (k, &i) in rows.iter().enumerate() {
            let r = n + k;
            for (c, v) in self.row(i).iter().enumerate() {
                a[c * dim + r] = -v;
                a[r * dim + c] = *v;
            }
            x[r] = self.target[i];
        }
        for (k, &j) in fr.iter().enumerate() {
            let r = n + rows.len() + k;
            for (c, v) in self.trow(j).iter().enumerate() {
                a[c * dim + r] = -v;
            }
            match active.modes[j] {
                Mode::Stick => a[r * dim..r * dim + n].copy_from_slice(self.trow(j)),
                Mode::Slide(s) => {
                    a[r * dim + r] = 1.0;
                    let contact = self.info.frictions[j].contact_index;
                    let col = rows.iter().position(|&i| i == contact)?;
                    a[r * dim + n + col] = s.value() * self.mu[j];
                }
            }
        }
        linear::solve_in_place(&mut a, dim, &mut x).ok()?;
        if !x.iter().all(|v| v.is_finite()) {
            return None;
        }
        let mut impulse = vec![0.0; self.parts.len()];
        for (k, &i) in rows.iter().enumerate() {
            impulse[i] = x[n + k];
        }
        let mut friction_impulse = vec![0.0; self.mu.len()];
        for (k, &j) in fr.iter().enumerate() {
            friction_impulse[j] = x[n + rows.len() + k];
        }
        Some(Solution {
            qd: DVector::from_column_slice(&x[..n]),
            impulse,
            friction_impulse,
            active,
        })
    }

    /// Whether a solved combination obeys every law: closed unilateral contacts push, open ones
    /// leave no faster than Newton's law allows, stuck frictions stay in the cone and sliding
    /// ones slip their way after (each to [`IMPACT_TOLERANCE`]).
    fn consistent(&self, s: &Solution) -> bool {
        let largest = (s.impulse.iter().chain(&s.friction_impulse))
            .fold(f64::MIN_POSITIVE, |a, p| a.max(p.abs()));
        let zero_impulse = IMPACT_TOLERANCE * largest;
        let zero_speed = IMPACT_TOLERANCE * self.speed;
        let dot = |row: &[f64]| row.iter().zip(s.qd.iter()).map(|(a, b)| a * b).sum::<f64>();
        let contacts_hold = (0..self.parts.len())
            .filter(|&i| self.parts[i] == Part::Unilateral)
            .all(|i| match s.active.closed[i] {
                true => s.impulse[i] >= -zero_impulse,
                false => dot(self.row(i)) - self.target[i] >= -zero_speed,
            });
        let frictions_hold =
            (0..self.mu.len())
                .filter(|&j| self.acts(&s.active, j))
                .all(|j| match s.active.modes[j] {
                    Mode::Stick => {
                        let normal = s.impulse[self.info.frictions[j].contact_index];
                        s.friction_impulse[j].abs() <= self.mu[j] * normal.max(0.0) + zero_impulse
                    }
                    Mode::Slide(sign) => sign.value() * dot(self.trow(j)) >= -zero_speed,
                });
        contacts_hold && frictions_hold
    }

    /// The impact of the chosen combination: velocities, laws, the energy lost and its split;
    /// an impact that gains energy is [`SolveError::ImpactGainsEnergy`].
    fn impact(
        &self,
        sys: &Bound,
        state: &State,
        s: Solution,
        t: f64,
        taking: &[usize],
    ) -> Result<Impact, SolveError> {
        let dot = |row: &[f64]| row.iter().zip(s.qd.iter()).map(|(a, b)| a * b).sum::<f64>();
        let after: Vec<f64> = (0..self.parts.len()).map(|i| dot(self.row(i))).collect();
        let slip_after: Vec<f64> = (0..self.mu.len()).map(|j| dot(self.trow(j))).collect();
        let laws: Vec<ContactLaw> = (0..self.parts.len())
            .map(|i| match (self.parts[i], s.active.closed[i]) {
                (Part::None, _) => ContactLaw::Out,
                (Part::Bilateral, _) => ContactLaw::Bilateral,
                (Part::Unilateral, true) => ContactLaw::Restitution,
                (Part::Unilateral, false) => ContactLaw::Open,
            })
            .collect();
        let friction_laws: Vec<FrictionLaw> = (0..self.mu.len())
            .map(|j| match (self.acts(&s.active, j), s.active.modes[j]) {
                (false, _) => FrictionLaw::Out,
                (true, Mode::Stick) => FrictionLaw::Stick,
                (true, Mode::Slide(sign)) => FrictionLaw::Slide(sign),
            })
            .collect();
        let half_work = |p: &[f64], a: &[f64], b: &[f64]| -> f64 {
            -(p.iter().zip(a.iter().zip(b)))
                .map(|(p, (a, b))| 0.5 * p * (a + b))
                .sum::<f64>()
        };
        let normal_energy_lost = half_work(&s.impulse, &self.before, &after);
        let friction_energy_lost = half_work(&s.friction_impulse, &self.slip_before, &slip_after);
        let energy_lost = normal_energy_lost + friction_energy_lost;
        let kinetic = 0.5 * self.qd.dot(&(&self.mass * &self.qd));
        if energy_lost < -IMPACT_TOLERANCE * kinetic {
            return Err(SolveError::ImpactGainsEnergy {
                model: self.info.name,
                t,
                contacts: names(self.info, taking),
                gained: -energy_lost,
                kinetic,
            });
        }
        Ok(Impact {
            normal_velocity_before: self.before.clone(),
            normal_velocity_after: after,
            impulse: s.impulse,
            slip_before: self.slip_before.clone(),
            slip_after,
            friction_impulse: s.friction_impulse,
            laws,
            friction_laws,
            energy_lost,
            normal_energy_lost,
            friction_energy_lost,
            after: sys.state(state.q().to_vec(), s.qd.iter().copied().collect())?,
        })
    }
}
