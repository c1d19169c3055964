//! The derivation of a spec's phases, stage by stage: [`read`](super::read) (every expression
//! parsed once) → [`setup`](super::setup) (a phase's coordinates and the ties of the contacts
//! it holds closed) → [`lagrangian`](super::lagrangian) → [`equations`](super::equations)
//! (`M(q) qdd = F(q, qd)`, cyclic coordinates, momenta) → [`constraints`]
//! (each contact's gap, Jacobian and bias, or its force in closed form where the phase holds it
//! closed; the frictions' slips) → [`reduction`](super::reduction) (the fast path) →
//! [`forces`] (monitors) → [`tangents`] (the general model's partial derivatives for the
//! forward sensitivities). This module only runs them, in that order, for every
//! phase of a spec; it is the top of the derivation proper.
//!
//! A spec gives its **general model** (named as the spec): every coordinate, every contact a
//! constraint row, the runtime solving the contacts' forces along with the motion. Where
//! contacts declare the coordinate they eliminate, each set of them that may be closed together
//! (bilateral ones always, no friction among them) is derived as a **fast phase** with those
//! coordinates eliminated, and kept when it reduces to one coordinate: `<spec>_closed` (every
//! contact closed), `<spec>_free` (all but the first), `<spec>_open_<names>` otherwise.
//!
//! Internal symbols (never allowed in specs): `dot_q`, `ddot_q` for velocities and
//! accelerations; on the reduced motion `rc_s = sin(theta)`, `rc_c = cos(theta)`,
//! `rc_ds = sin(theta_i) - sin(theta)`, `rc_dc = cos(theta_i) - cos(theta)`,
//! `rc_delta = theta_i - theta`, `rc_t` time, `rc_w = theta_dot`, `rc_w2 = theta_dot^2`,
//! `rc_acc = theta_ddot`, `rc_f<i>` the i-th contact's force, `rc_fr<i>` the i-th friction
//! force; constants `rc_thi`, `rc_wi`, `rc_si`, `rc_ci`, `rc_ai` (reduced inertia at the
//! start), `rc_x<j>i` (initial cyclic positions) and `rc_p<j>` (conserved momenta).

pub use super::algebra::{from_sc, is_zero_trig, reduce_cos_sq, simplify_inverse_trig, to_sc_expr};
pub use super::types::*;

use super::algebra::to_expr;
use super::cas::{self, A};
use super::constraints::{self, ContactAtoms, SlipKinematics, slip_kinematics};
use super::equations::equations;
use super::expr::Expr;
use super::forces;
use super::lagrangian::{Lagrangian, lagrangian};
use super::partials;
use super::read::{Parsed, read};
use super::reduction::Reducer;
use super::setup::{Setup, setup, ties};
use super::spec::{Checked, Spec};
use super::tangents;
use crate::spec::units::Unit;
use std::collections::BTreeMap;

/// The phases a spec derives: its general model first, then every set of eliminable contacts
/// that may be closed together (bilateral ones always among them, none with friction),
/// largest first.
pub fn phase_plans(spec: &Spec) -> Vec<PhasePlan> {
    let mut plans = vec![PhasePlan {
        name: spec.name.clone(),
        closed: Vec::new(),
        start_params: false,
    }];
    let eliminable: Vec<usize> = (0..spec.contacts.len())
        .filter(|&j| spec.contacts[j].eliminates.is_some())
        .collect();
    let bilateral_kept = spec
        .contacts
        .iter()
        .all(|c| !c.bilateral || c.eliminates.is_some());
    if eliminable.is_empty() || !bilateral_kept || eliminable.len() > 8 {
        return plans;
    }
    let with_friction: Vec<usize> = (spec.contacts.iter().enumerate())
        .filter(|(_, c)| spec.friction.iter().any(|f| f.contact == c.name))
        .map(|(j, _)| j)
        .collect();
    let mut sets: Vec<Vec<usize>> = (1u32..(1 << eliminable.len()))
        .map(|mask| {
            (eliminable.iter().enumerate())
                .filter(|(b, _)| mask & (1 << b) != 0)
                .map(|(_, &j)| j)
                .collect::<Vec<usize>>()
        })
        .filter(|set| {
            let keeps_joints =
                (spec.contacts.iter().enumerate()).all(|(j, c)| !c.bilateral || set.contains(&j));
            keeps_joints && set.iter().all(|j| !with_friction.contains(j))
        })
        .collect();
    sets.sort_by_key(|s| (std::cmp::Reverse(s.len()), s.clone()));
    for closed in sets {
        plans.push(PhasePlan {
            name: phase_name(spec, &closed),
            start_params: closed != eliminable,
            closed,
        });
    }
    plans
}

/// The name of the fast phase holding `closed` closed (see the module docs).
pub fn phase_name(spec: &Spec, closed: &[usize]) -> String {
    let n = spec.contacts.len();
    if closed.len() == n {
        return format!("{}_closed", spec.name);
    }
    let open: Vec<&str> = (0..n)
        .filter(|j| !closed.contains(j))
        .map(|j| spec.contacts[j].name.as_str())
        .collect();
    if open.len() == 1 && !closed.contains(&0) {
        return format!("{}_free", spec.name);
    }
    format!("{}_open_{}", spec.name, open.join("_"))
}

/// Derives every phase of a checked spec: the general model, and each fast phase that reduces.
pub fn derive(checked: &Checked) -> Result<Vec<Derivation>, DeriveError> {
    let spec = &checked.spec;
    let parsed = read(spec)?;
    let mut out = Vec::new();
    for plan in phase_plans(spec) {
        let general = plan.is_general();
        let d = derive_phase(checked, &parsed, &plan)?;
        if !general && d.reduction.is_err() {
            continue;
        }
        out.push(d);
    }
    Ok(out)
}

/// Every symbol the derivation of these specs can define, in one canonical order (see
/// [`cas::declare`]): the specs' parameters, the phases' start parameters, coordinates with
/// their rates and accelerations, contacts, sorted; then the internal symbols.
pub fn canonical_symbols(specs: &[&Spec]) -> Vec<String> {
    let mut names = std::collections::BTreeSet::new();
    let (mut n_coords, mut n_contacts, mut n_frictions) = (0, 0, 0);
    for spec in specs {
        names.extend(spec.parameters.iter().map(|p| p.name.clone()));
        for c in &spec.coordinates {
            for name in [
                c.name.clone(),
                format!("dot_{}", c.name),
                format!("ddot_{}", c.name),
                format!("{}_0", c.name),
                format!("{}_dot_0", c.name),
            ] {
                names.insert(name);
            }
        }
        names.extend(spec.contacts.iter().map(|c| c.name.clone()));
        n_coords = n_coords.max(spec.coordinates.len());
        n_contacts = n_contacts.max(spec.contacts.len());
        n_frictions = n_frictions.max(spec.friction.len());
    }
    let mut out: Vec<String> = names.into_iter().collect();
    for internal in [
        "rc_s", "rc_c", "rc_ds", "rc_dc", "rc_delta", "rc_t", "rc_w", "rc_w2", "rc_acc", "rc_thi",
        "rc_wi", "rc_si", "rc_ci", "rc_ai",
    ] {
        out.push(internal.to_string());
    }
    for j in 0..n_coords {
        out.push(format!("rc_x{j}i"));
        out.push(format!("rc_p{j}"));
    }
    out.extend((0..n_contacts).map(|i| format!("rc_f{i}")));
    out.extend((0..n_frictions).map(|i| format!("rc_fr{i}")));
    out
}

/// The parameters of a phase: the spec's, and for a phase that starts from a given state its
/// start state (`<q>_0`, then `<q>_dot_0`, for each of its coordinates).
fn phase_params(spec: &Spec, st: &Setup) -> Result<Vec<Param>, DeriveError> {
    let mut params: Vec<Param> = (spec.parameters.iter())
        .map(|p| Param {
            name: p.name.clone(),
            meaning: p.meaning.clone(),
            unit: p.unit.clone(),
            positive: p.positive,
        })
        .collect();
    if !st.plan.start_params {
        return Ok(params);
    }
    let coordinate = |name: &str| spec.coordinates.iter().find(|c| c.name == name);
    let mut rates = Vec::new();
    for name in &st.coords {
        let c = coordinate(name)
            .ok_or_else(|| at(&[key("coordinates")], format!("no coordinate `{name}`")))?;
        params.push(Param {
            name: format!("{}_0", c.name),
            meaning: format!("{} at the start of the phase", c.meaning),
            unit: c.unit.clone(),
            positive: false,
        });
        rates.push(Param {
            name: format!("{}_dot_0", c.name),
            meaning: format!(
                "rate of change of the {} at the start of the phase",
                c.meaning
            ),
            unit: format!("{}/s", c.unit),
            positive: false,
        });
    }
    params.extend(rates);
    let taken: Vec<&str> = (spec.parameters.iter().map(|p| p.name.as_str()))
        .chain(spec.coordinates.iter().map(|c| c.name.as_str()))
        .collect();
    if let Some(p) = params[spec.parameters.len()..]
        .iter()
        .find(|p| taken.contains(&p.name.as_str()))
    {
        return Err(at(
            &[key("coordinates")],
            format!(
                "phase `{}` takes its start state as parameter `{}`, which the spec already \
                 uses; rename it",
                st.plan.name, p.name
            ),
        ));
    }
    Ok(params)
}

/// The initial state of every coordinate of a phase (in its order), over its parameters: a
/// phase with start parameters starts from them; otherwise from the spec's `initial`, where
/// a coordinate a contact eliminates starts where the ties of every eliminable contact (all
/// closed at release) put it.
fn phase_initial(spec: &Spec, parsed: &Parsed, st: &Setup) -> Result<Vec<[Expr; 2]>, DeriveError> {
    if st.plan.start_params {
        return Ok((st.coords.iter())
            .map(|c| {
                [
                    Expr::sym(&format!("{c}_0")),
                    Expr::sym(&format!("{c}_dot_0")),
                ]
            })
            .collect());
    }
    let eliminable: Vec<usize> = (0..spec.contacts.len())
        .filter(|&j| spec.contacts[j].eliminates.is_some())
        .collect();
    let release = ties(spec, parsed, &eliminable)?;
    let given = |c: &str| {
        parsed.initial.get(c).cloned().ok_or_else(|| {
            at(
                &[key("initial")],
                format!("no initial position and velocity for coordinate `{c}`"),
            )
        })
    };
    // The release ties over the coordinates that stay, evaluated at their initial state.
    let free_coords: Vec<String> = (spec.coordinates.iter())
        .map(|c| c.name.clone())
        .filter(|c| release.iter().all(|(e, _)| e != c))
        .collect();
    let kin = super::setup::Kin {
        coords: free_coords.clone(),
    };
    let at_release = |a: &A| -> Result<Expr, DeriveError> {
        let mut out = a.clone();
        for c in &free_coords {
            let [p, v] = given(c)?;
            out = cas::subs_var(&out, &format!("dot_{c}"), &cas::atom(&v));
            out = cas::subs_var(&out, c, &cas::atom(&p));
        }
        Ok(simplify_inverse_trig(&to_expr(&out, "initial state")?))
    };
    let mut out = Vec::new();
    for c in &st.coords {
        let value = match release.iter().find(|(e, _)| e == c) {
            Some((_, tie)) => [at_release(tie)?, at_release(&kin.dt(tie))?],
            None => given(c)?,
        };
        out.push(value);
    }
    Ok(out)
}

/// Every coordinate of the spec, value and rate, over the phase's state.
fn to_full(spec: &Spec, st: &Setup) -> Result<Vec<[Expr; 2]>, DeriveError> {
    let mut out = Vec::new();
    for c in &spec.coordinates {
        let value = match st.ties.iter().find(|(e, _)| *e == c.name) {
            Some((_, tie)) => [
                to_expr(&cas::expand(tie), "eliminated coordinate")?,
                to_expr(&st.kin.dt(tie), "eliminated rate")?,
            ],
            None => [Expr::sym(&c.name), Expr::sym(&format!("dot_{}", c.name))],
        };
        out.push(value);
    }
    Ok(out)
}

/// Each body's pose `[x, y, angle]` in a phase (the ties substituted), for the drawing.
fn body_poses(parsed: &Parsed, lag: &Lagrangian) -> Result<Vec<[Expr; 3]>, DeriveError> {
    let mut poses = Vec::new();
    for b in &parsed.bodies {
        let missing = || at(&[key("bodies")], format!("no pose for body `{}`", b.name));
        let [x, y] = lag.body_pos.get(&b.name).ok_or_else(missing)?;
        let angle = lag.body_angle.get(&b.name).ok_or_else(missing)?;
        poses.push([
            to_expr(&cas::expand(x), "body position")?,
            to_expr(&cas::expand(y), "body position")?,
            to_expr(&cas::expand(angle), "body angle")?,
        ]);
    }
    Ok(poses)
}

/// Positions and velocities of the named points over the phase's state.
#[allow(clippy::type_complexity)]
fn point_kinematics(
    parsed: &Parsed,
    st: &Setup,
) -> Result<(Vec<[Expr; 2]>, Vec<[Expr; 2]>), DeriveError> {
    let mut pos = Vec::new();
    let mut vel = Vec::new();
    for p in &parsed.points {
        let (x, y) = (st.at(&p[0]), st.at(&p[1]));
        vel.push([
            to_expr(&st.kin.dt(&x), "point velocity")?,
            to_expr(&st.kin.dt(&y), "point velocity")?,
        ]);
        pos.push([
            to_expr(&cas::expand(&x), "point")?,
            to_expr(&cas::expand(&y), "point")?,
        ]);
    }
    Ok((pos, vel))
}

/// The contacts of a phase as the runtime and the write-up see them.
fn contact_rows(checked: &Checked, atoms: &[ContactAtoms]) -> Result<Vec<ContactRow>, DeriveError> {
    let spec = &checked.spec;
    let mut out = Vec::new();
    for (j, (c, a)) in spec.contacts.iter().zip(atoms).enumerate() {
        let (gap_unit, force_unit) = checked
            .contact_units(j)
            .map_err(|e| at(&[key("contacts"), FieldStep::Index(j)], e.message))?;
        let gap = match gap_unit {
            u if u == Unit::METRE => GapKind::Length,
            u if u.is_dimensionless() => GapKind::Angle,
            u => {
                return Err(at(
                    &[key("contacts"), FieldStep::Index(j), key("gap")],
                    format!("a gap in {u} is neither a length (m) nor an angle (rad)"),
                ));
            }
        };
        let opt = |x: &Option<A>, what: &str| -> Result<Option<Expr>, DeriveError> {
            x.as_ref().map(|e| to_expr(e, what)).transpose()
        };
        out.push(ContactRow {
            name: c.name.clone(),
            meaning: c.meaning.clone(),
            gap_kind: gap,
            force_unit,
            bilateral: c.bilateral,
            eliminates: c.eliminates.clone(),
            closed: a.force.is_some(),
            gap: to_expr(&a.gap, "gap")?,
            jacobian: (a.jacobian.iter())
                .map(|e| to_expr(e, "gap Jacobian"))
                .collect::<Result<_, _>>()?,
            bias: to_expr(&a.bias, "gap bias")?,
            edge: opt(&a.edge, "edge")?,
            force: opt(&a.force, "contact force")?,
        });
    }
    Ok(out)
}

/// The frictions of a phase for the runtime: coefficient and contact by index, slip velocity,
/// Jacobian and bias as expressions.
fn phase_frictions(
    spec: &Spec,
    params: &[Param],
    slips: &[SlipKinematics],
) -> Result<Vec<Friction>, DeriveError> {
    let mut out = Vec::new();
    for sk in slips {
        let f = &spec.friction[sk.spec];
        let path = |k: &str| [key("friction"), FieldStep::Index(sk.spec), key(k)];
        let coefficient =
            (params.iter().position(|p| p.name == f.coefficient)).ok_or_else(|| {
                at(
                    &path("coefficient"),
                    format!("`{}` is not a parameter", f.coefficient),
                )
            })?;
        let contact = (spec.contacts.iter().position(|c| c.name == f.contact))
            .ok_or_else(|| at(&path("contact"), format!("no contact `{}`", f.contact)))?;
        out.push(Friction {
            named: Named {
                name: f.name.clone(),
                meaning: f.meaning.clone(),
            },
            coefficient,
            contact,
            slip: to_expr(&sk.slip, "slip velocity")?,
            jacobian: (sk.jacobian.iter())
                .map(|j| to_expr(j, "slip Jacobian"))
                .collect::<Result<_, _>>()?,
            bias: to_expr(&sk.bias, "slip bias")?,
        });
    }
    Ok(out)
}

/// A phase's description: the spec's, and for a fast phase the contacts it holds closed.
fn phase_description(spec: &Spec, plan: &PhasePlan) -> String {
    if plan.is_general() {
        return spec.description.clone();
    }
    let closed: Vec<&str> = (plan.closed.iter())
        .map(|&j| spec.contacts[j].name.as_str())
        .collect();
    format!(
        "Phase of `{}` with {} closed: {}",
        spec.name,
        closed.join(", "),
        spec.description
    )
}

/// Derives one phase: every stage in order.
fn derive_phase(
    checked: &Checked,
    parsed: &Parsed,
    plan: &PhasePlan,
) -> Result<Derivation, DeriveError> {
    let spec = &checked.spec;
    let st = setup(spec, parsed, plan)?;
    let params = phase_params(spec, &st)?;
    let lag = lagrangian(spec, parsed, &st);
    let eqs = equations(&st, &lag, &[]);
    let atoms = constraints::contacts(spec, parsed, &st)?;
    let slips = if plan.is_general() {
        slip_kinematics(spec, parsed, &st, &lag)?
    } else {
        Vec::new()
    };
    let frictions = phase_frictions(spec, &params, &slips)?;
    let initial_list = phase_initial(spec, parsed, &st)?;
    let initial: BTreeMap<String, [Expr; 2]> = (st.coords.iter().cloned())
        .zip(initial_list.iter().cloned())
        .collect();
    let positive: Vec<String> = (params.iter())
        .filter(|p| p.positive)
        .map(|p| p.name.clone())
        .collect();
    let mut reduction = match (st.reduced, st.theta.as_deref()) {
        (Some(i), Some(theta)) => {
            let reducer = Reducer {
                spec,
                st: &st,
                reduced: (i, theta),
                lag: &lag,
                eqs: &eqs,
                initial: &initial,
                positive,
            };
            reducer.reduce(&atoms)?
        }
        _ => Err(Unreducible::NoReducedCoordinate),
    };
    if let Ok(r) = &mut reduction {
        let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
        r.partials = partials::derive(r, &names)?;
    }
    let (monitor_names, monitors_full) = forces::monitors(spec, parsed, &st);
    let (point_pos, point_vel) = point_kinematics(parsed, &st)?;
    let list = |v: &[A], what: &str| -> Result<Vec<Expr>, DeriveError> {
        v.iter().map(|e| to_expr(e, what)).collect()
    };
    let mut d = Derivation {
        name: plan.name.clone(),
        system: spec.name.clone(),
        plan: plan.clone(),
        description: phase_description(spec, plan),
        params,
        coords: st.coords.clone(),
        full_coords: spec.coordinates.iter().map(|c| c.name.clone()).collect(),
        reduced: st.reduced,
        cyclic: eqs.cyclic.clone(),
        kinetic: to_expr(&lag.kinetic, "kinetic energy")?,
        potential: to_expr(&lag.potential, "potential energy")?,
        lagrangian: to_expr(&lag.lag, "lagrangian")?,
        euler_lagrange: list(&eqs.el, "equation")?,
        mass: (eqs.mass.iter())
            .map(|r| list(r, "mass matrix"))
            .collect::<Result<_, _>>()?,
        rhs: list(&eqs.rhs, "forces")?,
        momenta: list(&eqs.momenta, "momentum")?,
        initial: initial_list,
        point_pos,
        point_vel,
        contacts: contact_rows(checked, &atoms)?,
        monitors: monitor_names,
        monitors_full: list(&monitors_full, "monitor")?,
        requirements: parsed.requirements.clone(),
        restitutions: parsed.restitutions.clone(),
        bodies: parsed.bodies.iter().map(|b| b.name.clone()).collect(),
        body_pose: body_poses(parsed, &lag)?,
        shapes: parsed.shapes.clone(),
        frictions,
        to_full: to_full(spec, &st)?,
        reduction,
        tangents: None,
        dimensionless: None,
        steps: None,
    };
    if plan.is_general() {
        d.tangents = Some(tangents::derive(&d)?);
    }
    Ok(d)
}
