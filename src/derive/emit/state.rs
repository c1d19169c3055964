//! The functions of the full state that every generated model has: the initial state,
//! points, energy, momenta, equations of motion, the contacts' forces, gaps, rows and edges,
//! the frictions' slip rows, the monitors, `to_full` and the drawing.

use super::code::{Code, K, Locals, OUT, Q, QD, coordinate_local, out_lines};
use super::lower::{Hoisted, Scope, lower, unbound};
use super::method::Preamble;
use crate::derive::algebra::to_sc_over;
use crate::derive::expr::Expr;
use crate::derive::types::{ContactRow, Derivation, StepError};
use serde::Serialize;

/// The functions of the full state, every model has them.
#[derive(Debug, Clone, Serialize)]
pub(super) struct FullStateCode {
    initial_state: Code,
    points: Code,
    energy: Code,
    momenta: Code,
    equations: Code,
    forces_full: Code,
    gaps: Code,
    constraints: Code,
    edges: Code,
    friction: Code,
    monitors_full: Code,
    to_full: Code,
}

impl FullStateCode {
    /// Every method's code.
    pub(super) fn codes(&self) -> [&Code; 12] {
        [
            &self.initial_state,
            &self.points,
            &self.energy,
            &self.momenta,
            &self.equations,
            &self.forces_full,
            &self.gaps,
            &self.constraints,
            &self.edges,
            &self.friction,
            &self.monitors_full,
            &self.to_full,
        ]
    }

    /// Each method's arguments and lines; `n` is the length of `k`, `reduced` the index of the
    /// reduced coordinate.
    pub(super) fn finish(&mut self, n: usize, reduced: Option<usize>, locals: &Locals) {
        let (slice, angle) = (Preamble::Slice(n), Preamble::Angle(reduced));
        let params = Preamble::Names(&locals.params, "k");
        let state = [slice, angle, params, Preamble::State(&locals.coords)];
        let qm = ("q", "&mut [f64]");
        let qdm = ("qd", "&mut [f64]");
        self.initial_state.finish(&[K, qm, qdm], &[slice, params]);
        let pos = ("pos", "&mut [[f64; 2]]");
        let vel = ("vel", "&mut [[f64; 2]]");
        self.points.finish(&[K, Q, QD, pos, vel], &state);
        self.energy.finish(&[K, Q, QD], &state);
        self.momenta.finish(&[K, Q, QD, OUT], &state);
        let mass = ("mass", "&mut [f64]");
        let rhs = ("rhs", "&mut [f64]");
        self.equations.finish(&[K, Q, QD, mass, rhs], &state);
        let qdd = ("qdd", "&[f64]");
        self.forces_full.finish(&[K, Q, QD, qdd, OUT], &state);
        self.gaps.finish(&[K, Q, OUT], &state);
        let jac = ("jac", "&mut [f64]");
        let bias = ("bias", "&mut [f64]");
        self.constraints.finish(&[K, Q, QD, jac, bias], &state);
        self.edges.finish(&[K, Q, OUT], &state);
        self.friction.finish(&[K, Q, QD, jac, bias], &state);
        let forces = ("forces", "&[f64]");
        self.monitors_full.finish(&[K, Q, QD, forces, OUT], &state);
        let qf = ("q_full", "&mut [f64]");
        let qdf = ("qd_full", "&mut [f64]");
        self.to_full.finish(&[K, Q, QD, qf, qdf], &state);
    }
}

/// The scope of the full-state functions: the constants, `rc_s`, `rc_c` (the template's
/// preamble) and the state by the coordinates' names (bound to `q`, `qd`, `qdd` by the
/// preamble, [`Preamble::State`]).
pub(super) fn state_scope(d: &Derivation, scope: &Scope) -> Scope {
    let mut full_scope = scope.clone();
    full_scope.locals.insert("rc_s".into(), "rc_s".into());
    full_scope.locals.insert("rc_c".into(), "rc_c".into());
    for c in &d.coords {
        let local = coordinate_local(c);
        full_scope
            .locals
            .insert(format!("dot_{c}"), format!("{local}_dot"));
        full_scope
            .locals
            .insert(format!("ddot_{c}"), format!("{local}_ddot"));
        full_scope.locals.insert(c.clone(), local);
    }
    full_scope
}

/// `Model::drawing` (every body's pose from `q`, then every shape's numbers, which are
/// parameter-only and so hoisted into `k`) and the `ShapeInfo` literals that say where each
/// shape's numbers start.
pub(super) fn drawing_code(
    d: &Derivation,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> (Code, Vec<String>) {
    let theta = d.theta();
    let mut exprs: Vec<Expr> = d
        .body_pose
        .iter()
        .flat_map(|pose| pose.iter().map(|e| to_sc_over(e, theta)))
        .collect();
    let mut infos = Vec::new();
    let mut first = 0;
    for shape in &d.shapes {
        infos.push(format!(
            "ShapeInfo {{ kind: ShapeKind::{:?}, body: {:?}, first: {first} }}",
            shape.kind, shape.body
        ));
        first += shape.numbers.len();
        exprs.extend(shape.numbers.iter().cloned());
    }
    let mut code = Code::default();
    let out = code.push_body(lower(&exprs, &state_scope(d, scope), Some(hoisted), "d"));
    let n_bodies = d.body_pose.len();
    code.outputs = (0..n_bodies)
        .map(|i| {
            format!(
                "poses[{i}] = [{}, {}, {}];",
                out[3 * i],
                out[3 * i + 1],
                out[3 * i + 2]
            )
        })
        .chain(
            out[3 * n_bodies..]
                .iter()
                .enumerate()
                .map(|(j, o)| format!("sizes[{j}] = {o};")),
        )
        .collect();
    (code, infos)
}

pub(super) fn full_state_code(
    d: &Derivation,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<FullStateCode, StepError> {
    let theta = d.theta();
    let full_scope = state_scope(d, scope);
    let sc = |e: &Expr| to_sc_over(e, theta);
    let single = |prefix: &str, exprs: &[Expr], scope: &Scope, hoisted: &mut Hoisted| {
        let mut code = Code::default();
        let out = code.push_body(lower(exprs, scope, Some(hoisted), prefix));
        (code, out)
    };

    // The initial state is over parameters only: each value is hoisted into `k`.
    let inits: Vec<Expr> = d
        .initial
        .iter()
        .flat_map(|[p, v]| [p.clone(), v.clone()])
        .collect();
    let (mut initial_state, out) = single("i", &inits, scope, hoisted);
    initial_state.outputs = (0..d.coords.len())
        .flat_map(|i| {
            [
                format!("q[{i}] = {};", out[2 * i]),
                format!("qd[{i}] = {};", out[2 * i + 1]),
            ]
        })
        .collect();

    let mut exprs = Vec::new();
    for p in &d.point_pos {
        exprs.push(sc(&p[0]));
        exprs.push(sc(&p[1]));
    }
    for v in &d.point_vel {
        exprs.push(sc(&v[0]));
        exprs.push(sc(&v[1]));
    }
    let (mut points, out) = single("p", &exprs, &full_scope, hoisted);
    let n = d.point_pos.len();
    points.outputs = (0..n)
        .flat_map(|i| {
            [
                format!("pos[{i}] = [{}, {}];", out[2 * i], out[2 * i + 1]),
                format!(
                    "vel[{i}] = [{}, {}];",
                    out[2 * n + 2 * i],
                    out[2 * n + 2 * i + 1]
                ),
            ]
        })
        .collect();

    let total = Expr::Add(vec![sc(&d.kinetic), sc(&d.potential)]);
    let (mut energy, out) = single("e", &[total], &full_scope, hoisted);
    energy.outputs = out;

    let mo: Vec<Expr> = d.momenta.iter().map(sc).collect();
    let (mut momenta, out) = single("m", &mo, &full_scope, hoisted);
    momenta.outputs = out_lines(&out);

    let nc = d.coords.len();
    let mut exprs: Vec<Expr> = d.mass.iter().flat_map(|r| r.iter().map(sc)).collect();
    exprs.extend(d.rhs.iter().map(sc));
    let (mut equations, out) = single("q", &exprs, &full_scope, hoisted);
    equations.outputs = (0..nc * nc)
        .map(|i| format!("mass[{i}] = {};", out[i]))
        .chain((0..nc).map(|i| format!("rhs[{i}] = {};", out[nc * nc + i])))
        .collect();

    let contacts = contact_code(d, &full_scope, hoisted)?;
    Ok(FullStateCode {
        initial_state,
        points,
        energy,
        momenta,
        equations,
        forces_full: contacts.forces_full,
        gaps: contacts.gaps,
        constraints: contacts.constraints,
        edges: contacts.edges,
        friction: contacts.friction,
        monitors_full: contacts.monitors_full,
        to_full: contacts.to_full,
    })
}

/// The functions of the contacts, frictions and monitors over the full state.
struct ContactCode {
    forces_full: Code,
    gaps: Code,
    constraints: Code,
    edges: Code,
    friction: Code,
    monitors_full: Code,
    to_full: Code,
}

/// One expression per contact, each lowered where `pick` gives one and `default` elsewhere,
/// as `out[i] = ...;` lines.
fn per_contact(
    d: &Derivation,
    pick: &dyn Fn(&ContactRow) -> Option<Expr>,
    default: &str,
    prefix: &str,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Code {
    let theta = d.theta();
    let picked: Vec<Option<Expr>> = d.contacts.iter().map(pick).collect();
    let exprs: Vec<Expr> = (picked.iter().flatten())
        .map(|e| to_sc_over(e, theta))
        .collect();
    let mut code = Code::default();
    let out = code.push_body(lower(&exprs, scope, Some(hoisted), prefix));
    let mut values = out.into_iter();
    code.outputs = (picked.iter().enumerate())
        .map(|(i, p)| {
            let v = match p {
                Some(_) => values.next().unwrap_or_else(|| default.to_string()),
                None => default.to_string(),
            };
            format!("out[{i}] = {v};")
        })
        .collect();
    code
}

fn contact_code(
    d: &Derivation,
    full_scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<ContactCode, StepError> {
    let theta = d.theta();
    let sc = |e: &Expr| to_sc_over(e, theta);
    let nc = d.coords.len();
    let single = |prefix: &str, exprs: &[Expr], hoisted: &mut Hoisted| {
        let mut code = Code::default();
        let out = code.push_body(lower(exprs, full_scope, Some(hoisted), prefix));
        (code, out)
    };
    let forces: Vec<Expr> = d.contacts.iter().filter_map(|c| c.force.clone()).collect();
    let stray = unbound(&forces, full_scope);
    if !stray.is_empty() {
        return Err(StepError::Unbound {
            what: "the forces depend on",
            symbols: stray.into_iter().collect(),
            besides: "the state and the parameters",
        });
    }
    let forces_full = per_contact(d, &|c| c.force.clone(), "0.0", "f", full_scope, hoisted);
    let open = |c: &ContactRow| (!c.closed).then(|| c.gap.clone());
    let gaps = per_contact(d, &open, "0.0", "g", full_scope, hoisted);
    let edges = per_contact(
        d,
        &|c| c.edge.clone(),
        "f64::INFINITY",
        "e",
        full_scope,
        hoisted,
    );

    // The constraint rows (every contact's Jacobian row, then its bias) and the frictions'
    // slip rows, in the same layout.
    let mut rows = |prefix: &str, jacobians: Vec<&[Expr]>, biases: Vec<&Expr>| {
        let mut exprs: Vec<Expr> = jacobians.iter().flat_map(|j| j.iter().map(sc)).collect();
        exprs.extend(biases.iter().map(|b| sc(b)));
        let (mut code, out) = single(prefix, &exprs, hoisted);
        let n_jac = nc * biases.len();
        code.outputs = (0..n_jac)
            .map(|i| format!("jac[{i}] = {};", out[i]))
            .chain((0..biases.len()).map(|j| format!("bias[{j}] = {};", out[n_jac + j])))
            .collect();
        code
    };
    let constraints = rows(
        "j",
        d.contacts.iter().map(|c| &c.jacobian[..]).collect(),
        d.contacts.iter().map(|c| &c.bias).collect(),
    );
    let friction = rows(
        "s",
        d.frictions.iter().map(|f| &f.jacobian[..]).collect(),
        d.frictions.iter().map(|f| &f.bias).collect(),
    );

    let mut mon_scope = full_scope.clone();
    for i in 0..d.contacts.len() {
        mon_scope
            .locals
            .insert(format!("rc_f{i}"), format!("forces[{i}]"));
    }
    let mo: Vec<Expr> = d.monitors_full.iter().map(sc).collect();
    let mut monitors_full = Code::default();
    let out = monitors_full.push_body(lower(&mo, &mon_scope, Some(hoisted), "m"));
    monitors_full.outputs = out_lines(&out);

    let exprs: Vec<Expr> = (d.to_full.iter())
        .flat_map(|[x, v]| [sc(x), sc(v)])
        .collect();
    let (mut to_full, out) = single("t", &exprs, hoisted);
    to_full.outputs = (0..d.to_full.len())
        .flat_map(|i| {
            [
                format!("q_full[{i}] = {};", out[2 * i]),
                format!("qd_full[{i}] = {};", out[2 * i + 1]),
            ]
        })
        .collect();
    Ok(ContactCode {
        forces_full,
        gaps,
        constraints,
        edges,
        friction,
        monitors_full,
        to_full,
    })
}
