//! Stage 5 of the derivation: the contacts and frictions of a phase.
//!
//! - An open contact (or any contact of the general model) is a constraint row: its gap `g(q)`,
//!   its Jacobian `J = dg/dq` and its bias `dJ/dt qd`, so that while it is closed the runtime
//!   solves `M qdd = F + J^T lambda` with `J qdd + bias = 0` for the accelerations and its
//!   force `lambda` together.
//! - A contact the phase holds closed by elimination has its force in closed form: with `e_k`
//!   the eliminated coordinates, the unconstrained Euler–Lagrange expressions satisfy
//!   `E_{e_k} = sum_j lambda_j d g_j / d e_k` on the constrained motion (every other
//!   generalized force acts through the coordinates that stay), a small linear system for the
//!   closed contacts' `lambda`. With one contact this is `lambda = E_e / (d gap / d e)`.
//! - Coulomb friction at a contact point acts on a body along a tangent `t`: its slip velocity
//!   `v = t . (v_body(p) - v_other(p))` (material velocities at the point) is linear in the
//!   velocities, `v = J qd`, and its generalized force is `f J` for a friction force `f` that
//!   the runtime solves for together with the accelerations.

use super::algebra::solve_linear;
use super::cas::{self, A};
use super::lagrangian::{Lagrangian, lagrangian};
use super::read::Parsed;
use super::setup::{Setup, setup};
use super::spec::Spec;
use super::types::{DeriveError, FieldStep, PhasePlan, at, entry, key};

/// The slip of one friction in one phase.
pub struct SlipKinematics {
    /// Index in the spec's `friction`.
    pub spec: usize,
    /// Slip velocity over the phase's state.
    pub slip: A,
    /// `dv/dqd_j` per coordinate.
    pub jacobian: Vec<A>,
    /// `dv/dt` with the accelerations zero.
    pub bias: A,
}

/// The slip velocity of every friction of the spec, its Jacobian and its bias.
pub fn slip_kinematics(
    spec: &Spec,
    parsed: &Parsed,
    st: &Setup,
    lag: &Lagrangian,
) -> Result<Vec<SlipKinematics>, DeriveError> {
    let mut out = Vec::new();
    for (i, f) in spec.friction.iter().enumerate() {
        let path = [key("friction"), FieldStep::Index(i)];
        let unknown = |b: &str| at(&path, format!("`{b}` is not one of the bodies"));
        let [p, t] = &parsed.friction[i];
        let p = [st.at(&p[0]), st.at(&p[1])];
        let [va_x, va_y] = lag
            .material_velocity(&st.kin, &f.body, &p)
            .ok_or_else(|| unknown(&f.body))?;
        let (rel_x, rel_y) = match &f.against {
            Some(b) => {
                let [vb_x, vb_y] = lag
                    .material_velocity(&st.kin, b, &p)
                    .ok_or_else(|| unknown(b))?;
                (va_x - vb_x, va_y - vb_y)
            }
            None => (va_x, va_y),
        };
        let slip = cas::expand(&(st.at(&t[0]) * rel_x + st.at(&t[1]) * rel_y));
        out.push(SlipKinematics {
            spec: i,
            jacobian: velocity_jacobian(st, &slip),
            bias: acceleration_bias(st, &slip),
            slip,
        });
    }
    Ok(out)
}

/// `d v / d qd_j` for each coordinate of the phase, of a velocity `v` linear in `qd`.
fn velocity_jacobian(st: &Setup, v: &A) -> Vec<A> {
    (st.coords.iter())
        .map(|c| cas::expand(&cas::d(v, &format!("dot_{c}"))))
        .collect()
}

/// `dv/dt` with the accelerations set to zero.
fn acceleration_bias(st: &Setup, v: &A) -> A {
    let mut bias = st.kin.dt(v);
    for c in &st.coords {
        bias = cas::subs_var(&bias, &format!("ddot_{c}"), &cas::num(0));
    }
    cas::expand(&bias)
}

/// One contact of a phase, as atoms.
pub struct ContactAtoms {
    /// Gap over the phase's coordinates (zero where the phase holds it closed).
    pub gap: A,
    /// Its Jacobian row.
    pub jacobian: Vec<A>,
    /// Its bias.
    pub bias: A,
    /// Its edge margin, if any.
    pub edge: Option<A>,
    /// Its force, where the phase holds it closed.
    pub force: Option<A>,
}

/// Every contact of the spec as the phase sees it: a constraint row where it is not held
/// closed, its force in closed form where it is.
pub fn contacts(
    spec: &Spec,
    parsed: &Parsed,
    st: &Setup,
) -> Result<Vec<ContactAtoms>, DeriveError> {
    let forces = multipliers(spec, parsed, st)?;
    let n = st.coords.len();
    let mut out = Vec::new();
    for (j, c) in parsed.contacts.iter().enumerate() {
        let edge = c.edge.as_ref().map(|e| cas::expand(&st.at(e)));
        let row = match st.plan.closed.iter().position(|&k| k == j) {
            Some(k) => ContactAtoms {
                gap: cas::num(0),
                jacobian: vec![cas::num(0); n],
                bias: cas::num(0),
                edge,
                force: forces.get(k).cloned(),
            },
            None => {
                let gap = cas::expand(&st.at(&c.gap));
                let rate = (st.coords.iter()).fold(cas::num(0), |acc, q| {
                    acc + cas::d(&gap, q) * cas::var(&format!("dot_{q}"))
                });
                let rate = cas::expand(&rate);
                ContactAtoms {
                    jacobian: velocity_jacobian(st, &rate),
                    bias: acceleration_bias(st, &rate),
                    gap,
                    edge,
                    force: None,
                }
            }
        };
        out.push(row);
    }
    Ok(out)
}

/// The forces of the contacts the phase holds closed (in the order of `st.plan.closed`), from
/// the unconstrained Euler–Lagrange expressions of the coordinates they eliminate, evaluated on
/// the constrained motion.
fn multipliers(spec: &Spec, parsed: &Parsed, st: &Setup) -> Result<Vec<A>, DeriveError> {
    if st.ties.is_empty() {
        return Ok(Vec::new());
    }
    let general = PhasePlan {
        name: spec.name.clone(),
        closed: Vec::new(),
        start_params: false,
    };
    let free = setup(spec, parsed, &general)?;
    let free_lag = lagrangian(spec, parsed, &free);
    // The eliminated coordinates' values, rates and accelerations on the constrained motion.
    let motion: Vec<(String, A, A, A)> = (st.ties.iter())
        .map(|(e, value)| {
            let rate = st.kin.dt(value);
            let accel = st.kin.dt(&rate);
            (e.clone(), value.clone(), rate, accel)
        })
        .collect();
    let on_motion = |a: &A| -> A {
        let mut out = a.clone();
        for (e, _, _, accel) in &motion {
            out = cas::subs_var(&out, &format!("ddot_{e}"), accel);
        }
        for (e, _, rate, _) in &motion {
            out = cas::subs_var(&out, &format!("dot_{e}"), rate);
        }
        for (e, value, _, _) in &motion {
            out = cas::subs_var(&out, e, value);
        }
        out
    };
    let mut lhs = Vec::new();
    let mut rhs = Vec::new();
    for (e, ..) in &motion {
        let (inertial, spring) = free_lag.euler_lagrange(&free.kin, e);
        rhs.push(on_motion(&(inertial + spring)));
        let row = (st.plan.closed.iter())
            .map(|&j| on_motion(&cas::d(&cas::atom(&parsed.contacts[j].gap), e)))
            .collect();
        lhs.push(row);
    }
    solve_linear(lhs, rhs).ok_or_else(|| {
        // At the first closed contact's `eliminates`; at the contacts where none is closed.
        let field = match st.plan.closed.first() {
            Some(&first) => entry("contacts", first, "eliminates").to_vec(),
            None => vec![key("contacts")],
        };
        at(
            &field,
            format!(
                "phase `{}`: the closed contacts' forces cannot be solved from the coordinates \
                 they eliminate (their gaps' derivatives in those coordinates are singular)",
                st.plan.name
            ),
        )
    })
}
