//! The derivation proper, in stages with typed results: a spec is read once ([`read`]), then
//! each phase of its motion (the whole motion, or the contact phase and the free phase after
//! it) goes through setup (which coordinates move, what the contact ties) → Lagrangian →
//! Euler–Lagrange equations `M(q) qdd = F(q, qd)` → reaction forces as expressions of
//! `(q, qd, qdd)` → monitors → the reduction (the fast path), every step by Symbolica.
//!
//! A contact is a unilateral constraint `gap(q) >= 0`. While it holds, `gap = 0` is solved for
//! one coordinate `e` and substituted (the phase has one coordinate fewer); its force is the
//! Lagrange multiplier `lambda = E_e / (d gap / d e)`, with `E_e` the Euler–Lagrange expression
//! of `e` in the unconstrained Lagrangian, so that springs and every other force on `e` are
//! accounted for. The free phase is the same spec with `e` free again and the gap monitored.
//!
//! The reduction applies when every coordinate but the reduced one is cyclic (its momentum is
//! conserved) and the effective potential is `alpha + beta sin(theta) + gamma cos(theta)`; it
//! gives the energy integral, the reduced forces and, with a contact, the separation polynomial.
//! A phase outside that class is not an error: it is solved by integrating `M(q) qdd = F`, and
//! the reason is recorded.
//!
//! Coulomb friction at a contact point acts on a body along a tangent `t`: its slip velocity
//! `v = t . (v_body(p) - v_other(p))` (material velocities at the point) is linear in the
//! velocities, `v = J qd`, and its generalized force is `f J` for a friction force `f` that the
//! runtime solves for together with the accelerations (sliding: `f = -mu N sign v`; sticking:
//! `dv/dt = 0`). Reaction forces then depend on `f` (symbols `rc_fr<i>`): a Newton balance on a
//! body takes out the frictions that act on it, and a contact multiplier the frictions' part of
//! `E_e`. A coordinate a friction acts on is not cyclic, and a phase with friction is integrated.
//!
//! Internal symbols (never allowed in specs): `dot_q`, `ddot_q` for velocities and
//! accelerations; on the reduced motion `rc_s = sin(theta)`, `rc_c = cos(theta)`,
//! `rc_ds = sin(theta_i) - sin(theta)`, `rc_dc = cos(theta_i) - cos(theta)`,
//! `rc_delta = theta_i - theta`, `rc_t` time, `rc_w = theta_dot`, `rc_w2 = theta_dot^2`,
//! `rc_acc = theta_ddot`, `rc_f<i>` the i-th force, `rc_fr<i>` the i-th friction force; constants `rc_thi`, `rc_wi`, `rc_si`,
//! `rc_ci`, `rc_ai` (reduced inertia at the start), `rc_x<j>i` (initial cyclic positions) and
//! `rc_p<j>` (conserved momenta).

use super::cas::{self, A};
use super::expr::{Expr, product};
use super::spec::{Checked, ShapeSpec, Spec, Text};
pub use crate::model::{Binding, ShapeKind};
use std::collections::BTreeMap;

/// Where a derivation error belongs in the spec: a dotted field path and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeriveError {
    /// Field path (`coordinates[0]`), used to find the line.
    pub field: Vec<FieldStep>,
    /// What failed.
    pub message: String,
}

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldStep {
    /// Mapping key.
    Key(String),
    /// Sequence index.
    Index(usize),
}

fn at(path: &[FieldStep], message: String) -> DeriveError {
    DeriveError {
        field: path.to_vec(),
        message,
    }
}

fn key(k: &str) -> FieldStep {
    FieldStep::Key(k.to_string())
}

/// A constant computed once per parameter set (in `prepare`).
#[derive(Debug, Clone)]
pub struct Constant {
    /// Internal symbol.
    pub symbol: String,
    /// Definition over parameters and earlier constants.
    pub value: Expr,
}

/// The separation condition.
#[derive(Debug, Clone)]
pub struct Separation {
    /// Coefficients of the polynomial in `sin(theta)`, lowest degree first, over constants.
    pub coefficients: Vec<Expr>,
    /// The polynomial itself, in `rc_s`.
    pub polynomial: Expr,
}

/// Which part of a spec's motion a derivation describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// A spec without a contact: one phase.
    Whole,
    /// While the contact holds: the eliminated coordinate is tied by `gap = 0`.
    Contact,
    /// After the contact ended: every coordinate free (the model `<name>_free`).
    Free,
}

/// A parameter of a derived model.
#[derive(Debug, Clone)]
pub struct Param {
    /// Symbol.
    pub name: String,
    /// What it is.
    pub meaning: String,
    /// SI unit.
    pub unit: String,
    /// Whether it must be strictly positive.
    pub positive: bool,
}

/// A named output (force or monitor) with its meaning.
#[derive(Debug, Clone)]
pub struct Named {
    /// Identifier.
    pub name: String,
    /// What it means.
    pub meaning: String,
}

/// A monitored assumption of a phase.
#[derive(Debug, Clone)]
pub struct Monitor {
    /// Identifier.
    pub name: String,
    /// What it checks.
    pub meaning: String,
    /// The unit of its value (empty when the spec gives none).
    pub unit: String,
}

/// A shape of the drawing, from a body's `shape` or the spec's `scenery`.
#[derive(Debug, Clone)]
pub struct Shape {
    /// What it is.
    pub kind: ShapeKind,
    /// Index in [`Derivation::bodies`] of the body it moves with (`None`: scenery).
    pub body: Option<usize>,
    /// Its numbers over the parameters, in the order [`ShapeKind`] documents.
    pub numbers: Vec<Expr>,
}

/// The contact of a contact phase.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Index of its force in [`Derivation::forces`].
    pub force: usize,
    /// The coordinate the contact eliminates.
    pub eliminated: String,
    /// That coordinate's value and rate while touching, over the phase's `q` and `dot_q`.
    pub released: [Expr; 2],
    /// The edge margin over `q` (`>= 0` while the contact can exist), if it can end at an edge.
    pub edge: Option<Expr>,
}

/// A Coulomb friction in one phase.
#[derive(Debug, Clone)]
pub struct Friction {
    /// Identifier and meaning.
    pub named: Named,
    /// Index of the coefficient in [`Derivation::params`].
    pub coefficient: usize,
    /// Index of the normal force in [`Derivation::forces`].
    pub normal: usize,
    /// Slip velocity `v = J qd` over the full state.
    pub slip: Expr,
    /// `J`: `dv/dqd_j`, one per coordinate (the generalized force per unit friction force).
    pub jacobian: Vec<Expr>,
    /// `dv/dt` with the accelerations set to zero.
    pub bias: Expr,
}

/// The phase after the contact ends.
#[derive(Debug, Clone)]
pub struct Next {
    /// Its model name.
    pub model: String,
    /// One binding per parameter of that model, in its order.
    pub bindings: Vec<Binding>,
}

/// The fast path of a phase: the cyclic coordinates eliminated through their conserved momenta.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// Constants computed in `prepare`, in order.
    pub constants: Vec<Constant>,
    /// Reduced inertia `A(theta)` in `T = A theta_dot^2 / 2 + ...`.
    pub reduced_inertia: Expr,
    /// Reduced kinetic-plus-potential energy with the cyclic velocities eliminated.
    pub reduced_energy: Expr,
    /// `theta_dot^2` over `rc_s, rc_c, rc_ds, rc_dc` and constants.
    pub theta_dot_sq: Expr,
    /// `theta_ddot` over the same symbols.
    pub theta_ddot: Expr,
    /// Cyclic velocities on the reduced motion (over `rc_s, rc_c, rc_w`).
    pub cyclic_velocity: Vec<Expr>,
    /// Cyclic positions on the reduced motion (over `rc_t, rc_ds, rc_dc, rc_delta`).
    pub cyclic_position: Vec<Expr>,
    /// Reaction forces on the reduced motion (over `rc_s, rc_c, rc_w2, rc_acc`).
    pub forces_reduced: Vec<Expr>,
    /// The separation polynomial, if the phase has a contact whose force's zero is one (else
    /// the runtime finds that zero numerically, from the reduced force).
    pub separation: Option<Separation>,
    /// Coefficients in `sin(theta)` (lowest degree first, over constants) of the fall
    /// polynomial `P(s) = (sin theta_i - s) / theta_dot^2`, where that ratio is a polynomial in
    /// `s` alone: the phase starts from rest, its potential is linear in `sin(theta)` and its
    /// reduced inertia a polynomial in `sin(theta)`. Its zeros and `s = -1` are then the only
    /// singularities of the time integrand, which lets the runtime choose its quadrature rule
    /// a priori.
    pub fall: Option<Vec<Expr>>,
    /// Fully substituted forms over parameters and `theta` for people and other tools.
    pub plain: BTreeMap<String, Expr>,
}

/// Everything derived for one phase (one generated model), as plain expressions.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// Model name (`rod_cube`, or `rod_cube_free` for the phase after the contact).
    pub name: String,
    /// Which phase of the spec.
    pub phase: Phase,
    /// One line for people.
    pub description: String,
    /// Parameters in order (a free phase adds its start state).
    pub params: Vec<Param>,
    /// Coordinate names in order.
    pub coords: Vec<String>,
    /// Index of the reduced coordinate.
    pub reduced: usize,
    /// Indices of the cyclic coordinates (whose momenta are conserved).
    pub cyclic: Vec<usize>,
    /// Kinetic energy (full state).
    pub kinetic: Expr,
    /// Potential energy (full state), gravity and the spec's potentials.
    pub potential: Expr,
    /// The Lagrangian `T - V`.
    pub lagrangian: Expr,
    /// Euler–Lagrange expressions `d/dt dL/dqd - dL/dq` (each `= 0`).
    pub euler_lagrange: Vec<Expr>,
    /// Mass matrix `M(q)`, row-major.
    pub mass: Vec<Vec<Expr>>,
    /// Right-hand side `F(q, qd)` of `M qdd = F`.
    pub rhs: Vec<Expr>,
    /// Conjugate momenta of the cyclic coordinates (full state).
    pub momenta: Vec<Expr>,
    /// Initial position and velocity of every coordinate, over the parameters.
    pub initial: Vec<[Expr; 2]>,
    /// Point positions (full state).
    pub point_pos: Vec<[Expr; 2]>,
    /// Point velocities (full state).
    pub point_vel: Vec<[Expr; 2]>,
    /// Reaction forces: the contact's first, then the spec's `forces`.
    pub forces: Vec<Named>,
    /// Reaction forces over the full state and accelerations.
    pub forces_full: Vec<Expr>,
    /// Monitors (each `>= 0` while the assumption holds).
    pub monitors: Vec<Monitor>,
    /// Monitors over the full state, parameters and the forces `rc_f<i>`.
    pub monitors_full: Vec<Expr>,
    /// Parameter requirements (over parameters).
    pub requirements: Vec<Expr>,
    /// The bodies' names, in the spec's order.
    pub bodies: Vec<String>,
    /// Each body's pose `[x, y, angle]` (centre of mass and orientation) over the full state.
    pub body_pose: Vec<[Expr; 3]>,
    /// The shapes of the drawing: the bodies' (in their order), then the scenery.
    pub shapes: Vec<Shape>,
    /// The contact, in a contact phase.
    pub contact: Option<Contact>,
    /// The frictions acting in this phase (a free phase drops those whose normal force is the
    /// contact's).
    pub frictions: Vec<Friction>,
    /// The phase after the contact, in a contact phase.
    pub next: Option<Next>,
    /// The fast path, or why the phase is integrated instead.
    pub reduction: Result<Reduction, String>,
    /// The results without units, if the spec gives groups and scales.
    pub dimensionless: Option<super::dimensionless::Dimensionless>,
    /// The steps as the LaTeX derivation shows them ([`super::steps`]), once presented.
    pub steps: Option<super::steps::Steps>,
}

impl Derivation {
    /// The reduced coordinate's name.
    pub fn theta(&self) -> &str {
        &self.coords[self.reduced]
    }
}

fn parse_text(t: &Text, path: &[FieldStep]) -> Result<Expr, DeriveError> {
    Expr::parse(&t.text()).map_err(|e| at(path, e.message))
}

fn to_expr(a: &A, what: &str) -> Result<Expr, DeriveError> {
    cas::expr(a).map_err(|m| at(&[], format!("{what}: {m}")))
}

/// `sin(asin(x)) = x`, `cos(asin(x)) = sqrt(1 - x^2)` and the like, applied bottom-up.
pub fn simplify_inverse_trig(e: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(simplify_inverse_trig).collect::<Vec<_>>();
    match e {
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(simplify_inverse_trig(b)),
            Box::new(simplify_inverse_trig(x)),
        ),
        Expr::Fun(f, args) => {
            let args = rec(args);
            if let Some(Expr::Fun(g, inner)) = args.first() {
                let x = inner[0].clone();
                // sqrt((1 - x)(1 + x)): no cancellation in 1 - x^2 as x -> 1.
                let one_minus_sq = || {
                    let minus_x = Expr::Mul(vec![Expr::int(-1), x.clone()]);
                    Expr::Pow(
                        Box::new(Expr::Mul(vec![
                            Expr::Add(vec![Expr::int(1), minus_x]),
                            Expr::Add(vec![Expr::int(1), x.clone()]),
                        ])),
                        Box::new(Expr::Rational(1, 2)),
                    )
                };
                match (f.as_str(), g.as_str()) {
                    ("sin", "asin") | ("cos", "acos") => return x,
                    ("cos", "asin") | ("sin", "acos") => return one_minus_sq(),
                    _ => {}
                }
            }
            Expr::Fun(f.clone(), args)
        }
        _ => e.clone(),
    }
}

/// The total time derivative along the full state.
struct Kin {
    coords: Vec<String>,
}

impl Kin {
    fn dt(&self, f: &A) -> A {
        let mut out = cas::num(0);
        for c in &self.coords {
            out = out
                + cas::d(f, c) * cas::var(&format!("dot_{c}"))
                + cas::d(f, &format!("dot_{c}")) * cas::var(&format!("ddot_{c}"));
        }
        cas::expand(&out)
    }
}

/// Replaces `cos^k` by `cos^(k mod 2) (1 - sin^2)^(k div 2)` in an expanded polynomial of
/// `rc_s`, `rc_c`, so that results are unique modulo `sin^2 + cos^2 = 1`.
pub fn reduce_cos_sq(a: &A) -> A {
    let mut cur = cas::expand(a);
    for _ in 0..16 {
        let mut next = cur.clone();
        let pow =
            |base: &str, n: i128| Expr::Pow(Box::new(Expr::sym(base)), Box::new(Expr::int(n)));
        for k in (2..=12).rev() {
            let pat = cas::atom(&pow("rc_c", k));
            let one_minus_s2 = Expr::Add(vec![
                Expr::int(1),
                Expr::Mul(vec![Expr::int(-1), pow("rc_s", 2)]),
            ]);
            let rep = cas::atom(&Expr::Mul(vec![
                pow("rc_c", k % 2),
                Expr::Pow(Box::new(one_minus_s2), Box::new(Expr::int(k / 2))),
            ]));
            next = cas::subs(&next, &pat, &rep);
        }
        next = cas::expand(&next);
        if next == cur {
            break;
        }
        cur = next;
    }
    cur
}

/// Whether a rational expression of `rc_s`, `rc_c` (and anything else) is zero modulo
/// `sin^2 + cos^2 = 1`.
pub fn is_zero_trig(a: &A) -> Result<bool, String> {
    let t = cas::together(a);
    let e = cas::expr(&t)?;
    let (num, _) = e.num_den();
    let n = cas::atom(&product(num));
    Ok(cas::is_zero(&reduce_cos_sq(&n)))
}

/// Replaces `sin(theta)`, `cos(theta)` by `rc_s`, `rc_c`.
fn to_sc(a: &A, theta: &str) -> A {
    let s = cas::subs(
        a,
        &cas::atom(&Expr::Fun("sin".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_s"),
    );
    cas::subs(
        &s,
        &cas::atom(&Expr::Fun("cos".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_c"),
    )
}

/// Replaces `rc_s`, `rc_c` by `sin(theta)`, `cos(theta)` in a plain expression.
pub fn from_sc(e: &Expr, theta: &str) -> Expr {
    match e {
        Expr::Sym(s) if s == "rc_s" => Expr::Fun("sin".into(), vec![Expr::sym(theta)]),
        Expr::Sym(s) if s == "rc_c" => Expr::Fun("cos".into(), vec![Expr::sym(theta)]),
        Expr::Add(v) => Expr::Add(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Mul(v) => Expr::Mul(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Pow(b, x) => Expr::Pow(Box::new(from_sc(b, theta)), Box::new(from_sc(x, theta))),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(|x| from_sc(x, theta)).collect()),
        _ => e.clone(),
    }
}

/// Replaces `sin(theta)`, `cos(theta)` by `rc_s`, `rc_c` in a plain expression (the inverse
/// of [`from_sc`]).
pub fn to_sc_expr(e: &Expr, theta: &str) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(|x| to_sc_expr(x, theta)).collect();
    match e {
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "sin" => {
            Expr::sym("rc_s")
        }
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "cos" => {
            Expr::sym("rc_c")
        }
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(to_sc_expr(b, theta)),
            Box::new(to_sc_expr(x, theta)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// Groups the terms of an expanded expression by their factors in `motion` symbols and brings
/// each group's coefficient over one denominator: `sum_m together(sum c_i) * m`.
///
/// Expanded, the reduced forces of a model with a cyclic coordinate hold parameter-only terms
/// that nearly cancel (`m1 ell m2/(2(m1+m2)) - ell m2 + ell m2^2/(m1+m2)` in rod_cube's contact
/// force is `-m1 m2 ell/(2(m1+m2))`): emitted as they are, the force loses `log10(m2/m1)`
/// digits for a heavy cube. Together, each coefficient is one term and keeps them.
fn collect_over(a: &A, motion: &[&str]) -> Result<A, DeriveError> {
    let e = to_expr(a, "expression to collect")?;
    let terms = match e {
        Expr::Add(v) => v,
        e => vec![e],
    };
    // (key, motion factors, coefficient terms), in order of first appearance.
    let mut groups: Vec<(String, Vec<Expr>, Vec<Expr>)> = Vec::new();
    for t in terms {
        let factors = match t {
            Expr::Mul(v) => v,
            t => vec![t],
        };
        let (mut moving, coefficient): (Vec<Expr>, Vec<Expr>) = factors
            .into_iter()
            .partition(|f| f.symbols().iter().any(|s| motion.contains(&s.as_str())));
        moving.sort_by_key(|f| f.to_infix());
        let key = moving
            .iter()
            .map(|f| f.to_infix())
            .collect::<Vec<_>>()
            .join("*");
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.2.push(product(coefficient)),
            None => groups.push((key, moving, vec![product(coefficient)])),
        }
    }
    let mut out = cas::num(0);
    for (_, moving, coefficients) in groups {
        let c = cas::together(&cas::atom(&Expr::Add(coefficients)));
        out += c * cas::atom(&product(moving));
    }
    Ok(out)
}

fn free_of(a: &A, names: &[&str]) -> bool {
    names.iter().all(|n| cas::is_zero(&cas::d(a, n)))
}

/// One body's parsed expressions.
struct BodyExprs {
    name: String,
    mass: Expr,
    inertia: Expr,
    position: [Expr; 2],
    angle: Expr,
}

/// Every expression of a spec, parsed once.
struct Parsed {
    bodies: Vec<BodyExprs>,
    points: Vec<[Expr; 2]>,
    potentials: Vec<Expr>,
    directions: Vec<[Expr; 2]>,
    /// Each friction's contact point and tangent.
    friction: Vec<[[Expr; 2]; 2]>,
    gap: Option<Expr>,
    edge: Option<Expr>,
    monitors: Vec<Expr>,
    requirements: Vec<Expr>,
    initial: BTreeMap<String, [Expr; 2]>,
    shapes: Vec<Shape>,
}

/// Stage 0: parses every expression of the spec, each error placed at its field.
fn read(spec: &Spec) -> Result<Parsed, DeriveError> {
    let field = |k: &str, i: usize, sub: &str| [key(k), FieldStep::Index(i), key(sub)];
    let mut bodies = Vec::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        let pos = field("bodies", i, "position");
        bodies.push(BodyExprs {
            name: b.name.clone(),
            mass: parse_text(&b.mass, &field("bodies", i, "mass"))?,
            inertia: parse_text(&b.inertia, &field("bodies", i, "inertia"))?,
            position: [
                parse_text(&b.position[0], &pos)?,
                parse_text(&b.position[1], &pos)?,
            ],
            angle: parse_text(&b.angle, &field("bodies", i, "angle"))?,
        });
    }
    let pair = |t: &[Text; 2], path: &[FieldStep]| -> Result<[Expr; 2], DeriveError> {
        Ok([parse_text(&t[0], path)?, parse_text(&t[1], path)?])
    };
    let points = (spec.points.iter().enumerate())
        .map(|(i, p)| pair(&p.position, &field("points", i, "position")))
        .collect::<Result<_, _>>()?;
    let potentials = (spec.potentials.iter().enumerate())
        .map(|(i, p)| parse_text(&p.expr, &field("potentials", i, "expr")))
        .collect::<Result<_, _>>()?;
    let directions = (spec.forces.iter().enumerate())
        .map(|(i, f)| pair(&f.direction, &field("forces", i, "direction")))
        .collect::<Result<_, _>>()?;
    let friction = (spec.friction.iter().enumerate())
        .map(|(i, f)| {
            Ok([
                pair(&f.point, &field("friction", i, "point"))?,
                pair(&f.direction, &field("friction", i, "direction"))?,
            ])
        })
        .collect::<Result<_, DeriveError>>()?;
    let contact_field = |k: &str| [key("contact"), key(k)];
    let gap = match &spec.contact {
        Some(c) => Some(parse_text(&c.gap, &contact_field("gap"))?),
        None => None,
    };
    let edge = match spec.contact.as_ref().and_then(|c| c.edge.as_ref()) {
        Some(e) => Some(parse_text(e, &contact_field("edge"))?),
        None => None,
    };
    let monitors = (spec.monitors.iter().enumerate())
        .map(|(i, m)| parse_text(&m.expr, &field("monitors", i, "expr")))
        .collect::<Result<_, _>>()?;
    let requirements = (spec.requirements.iter().enumerate())
        .map(|(i, r)| parse_text(&r.expr, &field("requirements", i, "expr")))
        .collect::<Result<_, _>>()?;
    let mut initial = BTreeMap::new();
    for (c, s) in &spec.initial {
        let path = [key("initial"), key(c)];
        initial.insert(
            c.clone(),
            [
                parse_text(&s.position, &path)?,
                parse_text(&s.velocity, &path)?,
            ],
        );
    }
    let mut shapes = Vec::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        if let Some(shape) = &b.shape {
            let path = field("bodies", i, "shape");
            shapes.push(read_shape(shape, Some(i), &path)?);
        }
    }
    for (i, shape) in spec.scenery.iter().enumerate() {
        let path = [key("scenery"), FieldStep::Index(i)];
        shapes.push(read_shape(shape, None, &path)?);
    }
    Ok(Parsed {
        shapes,
        bodies,
        points,
        potentials,
        directions,
        friction,
        gap,
        edge,
        monitors,
        requirements,
        initial,
    })
}

/// A shape's numbers (see [`ShapeKind`]): a rectangle's and a circle's centre first (`at`, or
/// the origin), then its size.
fn read_shape(
    shape: &ShapeSpec,
    body: Option<usize>,
    path: &[FieldStep],
) -> Result<Shape, DeriveError> {
    let parse = |t: &Text| parse_text(t, path);
    let centre = match &shape.at {
        Some([x, y]) => vec![parse(x)?, parse(y)?],
        None => vec![Expr::int(0), Expr::int(0)],
    };
    let (kind, numbers) = match (&shape.segment, &shape.rectangle, &shape.circle) {
        (Some([[x1, y1], [x2, y2]]), None, None) => (
            ShapeKind::Segment,
            vec![parse(x1)?, parse(y1)?, parse(x2)?, parse(y2)?],
        ),
        (None, Some([w, h]), None) => (
            ShapeKind::Rectangle,
            [centre, vec![parse(w)?, parse(h)?]].concat(),
        ),
        (None, None, Some(r)) => (ShapeKind::Circle, [centre, vec![parse(r)?]].concat()),
        _ => {
            return Err(at(
                path,
                "a shape is exactly one of `segment`, `rectangle` or `circle`".into(),
            ));
        }
    };
    Ok(Shape {
        kind,
        body,
        numbers,
    })
}

/// A phase's view of the spec: which coordinates move and what the contact ties.
struct Setup {
    phase: Phase,
    coords: Vec<String>,
    reduced: usize,
    theta: String,
    /// The eliminated coordinate and its value while the contact holds.
    tie: Option<(String, A)>,
    kin: Kin,
}

impl Setup {
    /// An expression of the spec, with the contact's tie substituted.
    fn at(&self, e: &Expr) -> A {
        let a = cas::atom(e);
        match &self.tie {
            Some((name, value)) => cas::subs_var(&a, name, value),
            None => a,
        }
    }
}

/// Stage 1: the coordinates of a phase and, in a contact phase, `gap = 0` solved for the
/// eliminated coordinate (the gap must be linear in it with a coefficient free of coordinates).
fn setup(spec: &Spec, parsed: &Parsed, phase: Phase) -> Result<Setup, DeriveError> {
    let all: Vec<String> = spec.coordinates.iter().map(|c| c.name.clone()).collect();
    let (coords, tie) = match (phase, &spec.contact, &parsed.gap) {
        (Phase::Contact, Some(c), Some(gap)) => {
            let e = c.eliminates.clone();
            let path = [key("contact"), key("gap")];
            let gap = cas::atom(gap);
            let coef = cas::expand(&cas::d(&gap, &e));
            let names: Vec<&str> = all.iter().map(String::as_str).collect();
            if cas::is_zero(&coef) || !free_of(&coef, &names) {
                let shown = to_expr(&coef, "gap coefficient")?.to_infix();
                return Err(at(
                    &path,
                    format!(
                        "the gap must be linear in `{e}` with a nonzero coefficient free of the \
                         coordinates, so that `gap = 0` can be solved for it; d(gap)/d{e} = {shown}"
                    ),
                ));
            }
            let value = cas::expand(&cas::together(&(cas::var(&e) - gap / coef)));
            let coords = all.iter().filter(|c| **c != e).cloned().collect();
            (coords, Some((e, value)))
        }
        (Phase::Contact, ..) => {
            return Err(at(
                &[key("contact")],
                "a contact phase needs a contact".into(),
            ));
        }
        _ => (all, None),
    };
    let reduced = coords
        .iter()
        .position(|c| *c == spec.reduced)
        .ok_or_else(|| {
            at(
                &[key("reduced")],
                format!("`{}` is not a coordinate of the phase", spec.reduced),
            )
        })?;
    Ok(Setup {
        phase,
        theta: coords[reduced].clone(),
        kin: Kin {
            coords: coords.clone(),
        },
        coords,
        reduced,
        tie,
    })
}

/// Energies and the Lagrangian of a phase, with each body's position and mass.
struct Lagrangian {
    kinetic: A,
    potential: A,
    /// The spec's potentials (part of `potential`), unexpanded.
    springs: A,
    lag: A,
    body_pos: BTreeMap<String, [A; 2]>,
    body_angle: BTreeMap<String, A>,
    body_mass: BTreeMap<String, A>,
}

/// Stage 2: `T`, `V` (gravity and the spec's potentials) and `L = T - V`.
fn lagrangian(spec: &Spec, parsed: &Parsed, st: &Setup) -> Lagrangian {
    let g = cas::var(&spec.gravity);
    let half = cas::atom(&Expr::Rational(1, 2));
    let mut t_kin = cas::num(0);
    let mut v_pot = cas::num(0);
    let mut body_pos = BTreeMap::new();
    let mut body_angle = BTreeMap::new();
    let mut body_mass = BTreeMap::new();
    for b in &parsed.bodies {
        let m = cas::atom(&b.mass);
        let inertia = cas::atom(&b.inertia);
        let (x, y) = (st.at(&b.position[0]), st.at(&b.position[1]));
        let angle = st.at(&b.angle);
        let (vx, vy, w) = (st.kin.dt(&x), st.kin.dt(&y), st.kin.dt(&angle));
        t_kin = t_kin
            + half.clone() * m.clone() * (vx.clone() * vx + vy.clone() * vy)
            + half.clone() * inertia * w.clone() * w;
        v_pot += m.clone() * g.clone() * y.clone();
        body_pos.insert(b.name.clone(), [x, y]);
        body_angle.insert(b.name.clone(), angle);
        body_mass.insert(b.name.clone(), m);
    }
    // The spec's potentials stay as written: expanded, a spring's `(x - x0)^2` would be
    // evaluated as `x^2 - 2 x x0 + x0^2`, which cancels to nothing near its rest length.
    let mut springs = cas::num(0);
    for p in &parsed.potentials {
        springs += st.at(p);
    }
    let kinetic = cas::expand(&t_kin);
    let potential = cas::expand(&v_pot) + springs.clone();
    Lagrangian {
        lag: kinetic.clone() - potential.clone(),
        kinetic,
        potential,
        springs,
        body_pos,
        body_angle,
        body_mass,
    }
}

impl Lagrangian {
    /// The Euler–Lagrange expression `d/dt dL/dqd - dL/dq` of coordinate `c` in two parts:
    /// the kinetic and gravitational part expanded, and the gradient of the spec's potentials
    /// as differentiated (a spring's force `k (x - x0)`, not `k x - k x0`).
    /// The velocity of `body`'s material point at `p` (`v_cm + w x (p - cm)`).
    fn material_velocity(&self, kin: &Kin, body: &str, p: &[A; 2]) -> Option<[A; 2]> {
        let [x, y] = self.body_pos.get(body)?;
        let w = kin.dt(self.body_angle.get(body)?);
        Some([
            kin.dt(x) - w.clone() * (p[1].clone() - y.clone()),
            kin.dt(y) + w * (p[0].clone() - x.clone()),
        ])
    }

    fn euler_lagrange(&self, kin: &Kin, c: &str) -> (A, A) {
        let dot = format!("dot_{c}");
        let inertial = self.kinetic.clone() - (self.potential.clone() - self.springs.clone());
        let expanded = cas::expand(&(kin.dt(&cas::d(&inertial, &dot)) - cas::d(&inertial, c)));
        (expanded, cas::d(&self.springs, c))
    }
}

/// The slip of one friction in one phase.
struct SlipKinematics {
    /// Index in the spec's `friction`.
    spec: usize,
    /// Slip velocity over the full state.
    slip: A,
    /// `dv/dqd_j` per coordinate.
    jacobian: Vec<A>,
    /// `dv/dt` with the accelerations zero.
    bias: A,
}

/// The spec's frictions that act in a phase: all of them, except in a free phase those whose
/// normal force is the contact's (which is gone).
fn active_frictions(spec: &Spec, phase: Phase) -> Vec<usize> {
    let contact_force = spec.contact.as_ref().map(|c| c.force.as_str());
    (0..spec.friction.len())
        .filter(|&i| {
            phase != Phase::Free || Some(spec.friction[i].normal.as_str()) != contact_force
        })
        .collect()
}

/// Stage 2b: the slip velocity of each friction `indices` names, its Jacobian and its bias.
fn slip_kinematics(
    spec: &Spec,
    parsed: &Parsed,
    st: &Setup,
    lag: &Lagrangian,
    indices: &[usize],
) -> Result<Vec<SlipKinematics>, DeriveError> {
    let mut out = Vec::new();
    for &i in indices {
        let f = &spec.friction[i];
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
        let jacobian = (st.coords.iter())
            .map(|c| cas::expand(&cas::d(&slip, &format!("dot_{c}"))))
            .collect();
        let mut bias = st.kin.dt(&slip);
        for c in &st.coords {
            bias = cas::subs_var(&bias, &format!("ddot_{c}"), &cas::num(0));
        }
        out.push(SlipKinematics {
            spec: i,
            slip,
            jacobian,
            bias: cas::expand(&bias),
        });
    }
    Ok(out)
}

/// The Euler–Lagrange equations of a phase.
struct Equations {
    el: Vec<A>,
    mass: Vec<Vec<A>>,
    rhs: Vec<A>,
    cyclic: Vec<usize>,
    momenta: Vec<A>,
}

/// Stage 3: `M(q) qdd = F(q, qd)`, the cyclic coordinates and their momenta.
fn equations(st: &Setup, lag: &Lagrangian, frictions: &[SlipKinematics]) -> Equations {
    let dots: Vec<String> = st.coords.iter().map(|c| format!("dot_{c}")).collect();
    let ddots: Vec<String> = st.coords.iter().map(|c| format!("ddot_{c}")).collect();
    let (mut el, mut mass, mut rhs) = (Vec::new(), Vec::new(), Vec::new());
    for c in &st.coords {
        let (e, spring) = lag.euler_lagrange(&st.kin, c);
        let mut row = Vec::new();
        let mut at_rest = e.clone();
        for dd in &ddots {
            row.push(cas::expand(&cas::d(&e, dd)));
            at_rest = cas::subs_var(&at_rest, dd, &cas::num(0));
        }
        rhs.push(cas::expand(&(cas::num(0) - at_rest)) - spring.clone());
        let e = e + spring;
        mass.push(row);
        el.push(e);
    }
    let cyclic: Vec<usize> = (0..st.coords.len())
        .filter(|&i| i != st.reduced && cas::is_zero(&cas::d(&lag.lag, &st.coords[i])))
        .filter(|&i| frictions.iter().all(|f| cas::is_zero(&f.jacobian[i])))
        .collect();
    let momenta = cyclic
        .iter()
        .map(|&i| cas::expand(&cas::d(&lag.lag, &dots[i])))
        .collect();
    Equations {
        el,
        mass,
        rhs,
        cyclic,
        momenta,
    }
}

/// Stage 4: the reaction forces over `(q, qd, qdd)` and the friction forces `rc_fr<j>`: in a
/// contact phase the contact's multiplier first, then each `forces` entry by a Newton balance
/// of its body projected on its direction `d`, `F = m (d . a) + m g d_y`: the non-gravity force
/// on the body dotted with `d` (the spec chooses `d` so that only the wanted force has a
/// component along it), less the frictions on the body along `d`.
fn forces(
    spec: &Spec,
    parsed: &Parsed,
    st: &Setup,
    lag: &Lagrangian,
    slips: &[SlipKinematics],
) -> Result<(Vec<Named>, Vec<A>), DeriveError> {
    let fr = |j: usize| cas::var(&format!("rc_fr{j}"));
    let mut named = Vec::new();
    let mut full = Vec::new();
    if let (Some(c), Some((e, value))) = (&spec.contact, &st.tie) {
        // E_e of the unconstrained Lagrangian, evaluated on the constrained motion.
        let free = setup(spec, parsed, Phase::Free)?;
        let free_lag = lagrangian(spec, parsed, &free);
        let dot_e = format!("dot_{e}");
        let (inertial, spring) = free_lag.euler_lagrange(&free.kin, e);
        // E_e = lambda d(gap)/de + Q_e, with Q_e the frictions' generalized force on `e`.
        let indices: Vec<usize> = slips.iter().map(|s| s.spec).collect();
        let mut e_e = inertial + spring;
        for (j, free_slip) in slip_kinematics(spec, parsed, &free, &free_lag, &indices)?
            .iter()
            .enumerate()
        {
            e_e -= fr(j) * cas::d(&free_slip.slip, &dot_e);
        }
        let rate = st.kin.dt(value);
        let accel = st.kin.dt(&rate);
        let on_contact = cas::subs_var(
            &cas::subs_var(
                &cas::subs_var(&e_e, &format!("ddot_{e}"), &accel),
                &dot_e,
                &rate,
            ),
            e,
            value,
        );
        let gap = cas::atom(
            parsed
                .gap
                .as_ref()
                .ok_or_else(|| at(&[key("contact")], "a contact needs a gap".into()))?,
        );
        let coef = cas::expand(&cas::d(&gap, e));
        named.push(Named {
            name: c.force.clone(),
            meaning: c.meaning.clone(),
        });
        full.push(on_contact / coef);
    }
    let g = cas::var(&spec.gravity);
    for (i, f) in spec.forces.iter().enumerate() {
        let path = [key("forces"), FieldStep::Index(i)];
        let [x, y] = lag
            .body_pos
            .get(&f.body)
            .ok_or_else(|| at(&path, format!("`{}` is not one of the bodies", f.body)))?;
        let m = lag
            .body_mass
            .get(&f.body)
            .ok_or_else(|| at(&path, format!("`{}` is not one of the bodies", f.body)))?;
        let [d0, d1] = &parsed.directions[i];
        let (d0, d1) = (st.at(d0), st.at(d1));
        let (ax, ay) = (st.kin.dt(&st.kin.dt(x)), st.kin.dt(&st.kin.dt(y)));
        let mut frictions = cas::num(0);
        for (j, sk) in slips.iter().enumerate() {
            let rub = &spec.friction[sk.spec];
            let sign = if rub.body == f.body {
                1
            } else if rub.against.as_deref() == Some(f.body.as_str()) {
                -1
            } else {
                continue;
            };
            let [t0, t1] = &parsed.friction[sk.spec][1];
            let along = st.at(t0) * d0.clone() + st.at(t1) * d1.clone();
            frictions += cas::num(sign) * fr(j) * along;
        }
        named.push(Named {
            name: f.name.clone(),
            meaning: f.meaning.clone(),
        });
        full.push(cas::expand(
            &(m.clone() * (d0 * ax + d1.clone() * ay) + m.clone() * g.clone() * d1 - frictions),
        ));
    }
    Ok((named, full))
}

/// Stage 5: the monitors over the full state, parameters and the forces `rc_f<i>`. A free
/// phase drops the monitors of its contact's force and watches the gap instead (the bodies
/// must not meet again).
fn monitors(
    spec: &Spec,
    parsed: &Parsed,
    st: &Setup,
    forces: &[Named],
) -> Result<(Vec<Monitor>, Vec<A>), DeriveError> {
    let mut named = Vec::new();
    let mut exprs = Vec::new();
    let contact_force = spec.contact.as_ref().map(|c| c.force.as_str());
    for (m, e) in spec.monitors.iter().zip(&parsed.monitors) {
        let symbols = e.symbols();
        if st.phase == Phase::Free && contact_force.is_some_and(|f| symbols.contains(f)) {
            continue;
        }
        let mut a = st.at(e);
        for (fi, f) in forces.iter().enumerate() {
            a = cas::subs_var(&a, &f.name, &cas::var(&format!("rc_f{fi}")));
        }
        named.push(Monitor {
            name: m.name.clone(),
            meaning: m.meaning.clone(),
            unit: m.unit.clone().unwrap_or_default(),
        });
        exprs.push(a);
    }
    if let (Phase::Free, Some(c), Some(gap)) = (st.phase, &spec.contact, &parsed.gap) {
        named.push(Monitor {
            name: "contact_open".into(),
            meaning: format!(
                "the contact of `{}` stays open after it ended (gap >= 0: the bodies do not meet again)",
                c.force
            ),
            // The gap is linear in the eliminated coordinate: read as a distance along it.
            unit: spec
                .coordinates
                .iter()
                .find(|q| q.name == c.eliminates)
                .map(|q| q.unit.clone())
                .unwrap_or_default(),
        });
        exprs.push(cas::atom(gap));
    }
    Ok((named, exprs))
}

/// The parameters of a phase: the spec's, and for a free phase its start state
/// (`<q>_0`, then `<q>_dot_0`, for every coordinate).
fn phase_params(spec: &Spec, phase: Phase) -> Result<Vec<Param>, DeriveError> {
    let mut params: Vec<Param> = spec
        .parameters
        .iter()
        .map(|p| Param {
            name: p.name.clone(),
            meaning: p.meaning.clone(),
            unit: p.unit.clone(),
            positive: p.positive,
        })
        .collect();
    if phase == Phase::Free {
        let mut rates = Vec::new();
        for c in &spec.coordinates {
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
        let taken: Vec<&str> = spec
            .parameters
            .iter()
            .map(|p| p.name.as_str())
            .chain(spec.coordinates.iter().map(|c| c.name.as_str()))
            .collect();
        if let Some(p) = params[spec.parameters.len()..]
            .iter()
            .find(|p| taken.contains(&p.name.as_str()))
        {
            return Err(at(
                &[key("contact")],
                format!(
                    "the phase after the contact takes its start state as parameter `{}`, \
                     which the spec already uses; rename it",
                    p.name
                ),
            ));
        }
    }
    Ok(params)
}

/// The initial state of every coordinate of a phase (in its order), over its parameters.
fn phase_initial(parsed: &Parsed, st: &Setup) -> Result<Vec<[Expr; 2]>, DeriveError> {
    let mut out = Vec::new();
    for c in &st.coords {
        let value = match st.phase {
            Phase::Free => [
                Expr::sym(&format!("{c}_0")),
                Expr::sym(&format!("{c}_dot_0")),
            ],
            _ => parsed.initial.get(c).cloned().ok_or_else(|| {
                at(
                    &[key("initial")],
                    format!("no initial position and velocity for coordinate `{c}`"),
                )
            })?,
        };
        out.push(value);
    }
    Ok(out)
}

/// Derives every phase of a checked spec: one model without a contact; with one, the contact
/// phase (`name`) and the free phase after it (`<name>_free`).
pub fn derive(checked: &Checked) -> Result<Vec<Derivation>, DeriveError> {
    let spec = &checked.spec;
    let parsed = read(spec)?;
    let phases: &[Phase] = match spec.contact {
        None => &[Phase::Whole],
        Some(_) => &[Phase::Contact, Phase::Free],
    };
    let mut out = Vec::new();
    for &phase in phases {
        let mut d = derive_phase(checked, &parsed, phase)?;
        d.dimensionless = super::dimensionless::derive(spec, &d)?;
        d.steps = Some(super::steps::derive(&d));
        out.push(d);
    }
    Ok(out)
}

/// Every symbol the derivation of these specs can define, in one canonical order (see
/// [`cas::declare`]): the specs' parameters, the free phases' start parameters, coordinates
/// with their rates and accelerations, sorted; then the internal symbols.
pub fn canonical_symbols(specs: &[&Spec]) -> Vec<String> {
    let mut names = std::collections::BTreeSet::new();
    let (mut n_coords, mut n_forces, mut n_frictions) = (0, 0, 0);
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
        names.extend(spec.forces.iter().map(|f| f.name.clone()));
        names.extend(spec.contact.iter().map(|c| c.force.clone()));
        n_coords = n_coords.max(spec.coordinates.len());
        n_forces = n_forces.max(spec.forces.len() + 1);
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
    out.extend((0..n_forces).map(|i| format!("rc_f{i}")));
    out.extend((0..n_frictions).map(|i| format!("rc_fr{i}")));
    out
}

/// The name of the model of a phase.
pub fn phase_name(spec: &Spec, phase: Phase) -> String {
    match phase {
        Phase::Free => format!("{}_free", spec.name),
        _ => spec.name.clone(),
    }
}

fn derive_phase(
    checked: &Checked,
    parsed: &Parsed,
    phase: Phase,
) -> Result<Derivation, DeriveError> {
    let spec = &checked.spec;
    let st = setup(spec, parsed, phase)?;
    let params = phase_params(spec, phase)?;
    let lag = lagrangian(spec, parsed, &st);
    let slips = slip_kinematics(spec, parsed, &st, &lag, &active_frictions(spec, phase))?;
    let eqs = equations(&st, &lag, &slips);
    let (force_names, forces_full) = forces(spec, parsed, &st, &lag, &slips)?;
    let frictions = phase_frictions(spec, &params, &force_names, &slips)?;
    let (monitor_names, monitors_full) = monitors(spec, parsed, &st, &force_names)?;
    let initial_list = phase_initial(parsed, &st)?;
    let initial: BTreeMap<String, [Expr; 2]> = st
        .coords
        .iter()
        .cloned()
        .zip(initial_list.iter().cloned())
        .collect();
    let positive: Vec<String> = params
        .iter()
        .filter(|p| p.positive)
        .map(|p| p.name.clone())
        .collect();
    let edge = match (phase, &parsed.edge) {
        (Phase::Contact, Some(e)) => Some(st.at(e)),
        _ => None,
    };
    let reduction = if frictions.is_empty() {
        Reducer {
            st: &st,
            lag: &lag,
            eqs: &eqs,
            initial: &initial,
            positive,
        }
        .reduce(
            &force_names,
            &forces_full,
            phase == Phase::Contact,
            edge.as_ref(),
        )?
    } else {
        let names: Vec<&str> = frictions.iter().map(|f| f.named.name.as_str()).collect();
        Err(format!(
            "Coulomb friction ({}) depends on the direction of slip and switches between \
             sticking and sliding, so the motion is integrated with events at every switch",
            names.join(", ")
        ))
    };

    let mut point_pos = Vec::new();
    let mut point_vel = Vec::new();
    for p in &parsed.points {
        let (x, y) = (st.at(&p[0]), st.at(&p[1]));
        point_vel.push([
            to_expr(&st.kin.dt(&x), "point velocity")?,
            to_expr(&st.kin.dt(&y), "point velocity")?,
        ]);
        point_pos.push([
            to_expr(&cas::expand(&x), "point")?,
            to_expr(&cas::expand(&y), "point")?,
        ]);
    }
    let body_pose = body_poses(parsed, &lag)?;
    let contact = match &st.tie {
        Some((e, value)) => Some(Contact {
            force: 0,
            eliminated: e.clone(),
            released: [
                to_expr(value, "eliminated coordinate")?,
                to_expr(&st.kin.dt(value), "eliminated rate")?,
            ],
            edge: match &parsed.edge {
                Some(edge) => Some(to_expr(&cas::expand(&st.at(edge)), "edge")?),
                None => None,
            },
        }),
        None => None,
    };
    let next = contact.as_ref().map(|_| next_phase(spec, &st));
    let list = |v: &[A], what: &str| -> Result<Vec<Expr>, DeriveError> {
        v.iter().map(|e| to_expr(e, what)).collect()
    };
    let description = match phase {
        Phase::Free => format!(
            "After the contact of `{}` ends: {}",
            spec.name, spec.description
        ),
        _ => spec.description.clone(),
    };
    Ok(Derivation {
        name: phase_name(spec, phase),
        phase,
        description,
        params,
        coords: st.coords.clone(),
        reduced: st.reduced,
        cyclic: eqs.cyclic.clone(),
        kinetic: to_expr(&lag.kinetic, "kinetic energy")?,
        potential: to_expr(&lag.potential, "potential energy")?,
        lagrangian: to_expr(&lag.lag, "lagrangian")?,
        euler_lagrange: list(&eqs.el, "equation")?,
        mass: eqs
            .mass
            .iter()
            .map(|r| list(r, "mass matrix"))
            .collect::<Result<_, _>>()?,
        rhs: list(&eqs.rhs, "forces")?,
        momenta: list(&eqs.momenta, "momentum")?,
        initial: initial_list,
        point_pos,
        point_vel,
        forces: force_names,
        forces_full: list(&forces_full, "force")?,
        monitors: monitor_names,
        monitors_full: list(&monitors_full, "monitor")?,
        requirements: parsed.requirements.clone(),
        bodies: parsed.bodies.iter().map(|b| b.name.clone()).collect(),
        body_pose,
        shapes: parsed.shapes.clone(),
        contact,
        frictions,
        next,
        reduction,
        dimensionless: None,
        steps: None,
    })
}

/// Each body's pose `[x, y, angle]` in a phase (the contact's tie substituted), for the drawing.
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

/// The frictions of a phase for the runtime: coefficient and normal force by index, slip
/// velocity, Jacobian and bias as expressions.
fn phase_frictions(
    spec: &Spec,
    params: &[Param],
    forces: &[Named],
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
        let normal = (forces.iter().position(|n| n.name == f.normal)).ok_or_else(|| {
            at(
                &path("normal"),
                format!("`{}` is not a force of this phase", f.normal),
            )
        })?;
        out.push(Friction {
            named: Named {
                name: f.name.clone(),
                meaning: f.meaning.clone(),
            },
            coefficient,
            normal,
            slip: to_expr(&sk.slip, "slip velocity")?,
            jacobian: (sk.jacobian.iter())
                .map(|j| to_expr(j, "slip Jacobian"))
                .collect::<Result<_, _>>()?,
            bias: to_expr(&sk.bias, "slip bias")?,
        });
    }
    Ok(out)
}

/// The bindings from a contact phase to its free phase: the spec's parameters, then every
/// coordinate's value and rate at the end of the contact.
fn next_phase(spec: &Spec, st: &Setup) -> Next {
    let mut bindings: Vec<Binding> = (0..spec.parameters.len()).map(Binding::Param).collect();
    for rate in [false, true] {
        for c in &spec.coordinates {
            let b = match st.coords.iter().position(|x| *x == c.name) {
                Some(i) if rate => Binding::Velocity(i),
                Some(i) => Binding::Coordinate(i),
                None if rate => Binding::EliminatedRate,
                None => Binding::Eliminated,
            };
            bindings.push(b);
        }
    }
    Next {
        model: phase_name(spec, Phase::Free),
        bindings,
    }
}

/// Why a phase has no fast path: not an error, the phase is integrated instead.
type Unreducible = String;

/// Stage 6, the reduction: the fast path of a phase, from its Lagrangian and equations.
struct Reducer<'a> {
    st: &'a Setup,
    lag: &'a Lagrangian,
    eqs: &'a Equations,
    initial: &'a BTreeMap<String, [Expr; 2]>,
    /// Symbols known to be strictly positive (positive parameters).
    positive: Vec<String>,
}

/// The reduced motion's building blocks, shared by the steps of the reduction.
struct Reduced {
    constants: Vec<Constant>,
    cyc_vel: Vec<A>,
    wsq: A,
    acc: A,
    inertia: A,
    e_red: A,
}

impl Reducer<'_> {
    fn theta(&self) -> &str {
        &self.st.theta
    }

    fn init(&self, c: &str, what: usize) -> Result<Expr, DeriveError> {
        self.initial.get(c).map(|v| v[what].clone()).ok_or_else(|| {
            at(
                &[key("initial")],
                format!("no initial value for coordinate `{c}`"),
            )
        })
    }

    /// The fast path, or why there is none (an `Err` of the outer result is a real error).
    fn reduce(
        &self,
        names: &[Named],
        forces_full: &[A],
        has_contact: bool,
        edge: Option<&A>,
    ) -> Result<Result<Reduction, Unreducible>, DeriveError> {
        // An edge is located on the fast path as a root in the angle: it may depend on theta
        // and the parameters only.
        if let Some(edge) = edge {
            let others: Vec<&str> = (self.st.coords.iter())
                .filter(|c| **c != self.st.theta)
                .map(String::as_str)
                .collect();
            if !free_of(edge, &others) {
                return Ok(Err(format!(
                    "the contact's edge depends on {} besides `{}`, which only the integrated \
                     path follows",
                    others.join(", "),
                    self.st.theta
                )));
            }
        }
        if let Some(why) = self.unreducible_coordinates() {
            return Ok(Err(why));
        }
        let mut constants = self.start_constants()?;
        let cyc_vel = match self.cyclic_velocities(&mut constants)? {
            Ok(v) => v,
            Err(why) => return Ok(Err(why)),
        };
        let red = match self.energy_integral(constants, cyc_vel)? {
            Ok(r) => r,
            Err(why) => return Ok(Err(why)),
        };
        let (cyclic_position, cyc_acc) = match self.cyclic_positions(&red.cyc_vel)? {
            Ok(v) => v,
            Err(why) => return Ok(Err(why)),
        };
        let mut forces_reduced = Vec::new();
        for (i, f) in forces_full.iter().enumerate() {
            match self.reduced_force(f, &red.cyc_vel, &cyc_acc)? {
                Ok(r) => forces_reduced.push(r),
                Err(why) => return Ok(Err(format!("force `{}`: {why}", names[i].name))),
            }
        }
        // Where the contact force's zero is no polynomial root, the runtime finds it as a
        // bracketed root of the reduced force itself.
        let separation = if has_contact {
            self.separation(&red, &forces_reduced[0])?.ok()
        } else {
            None
        };
        let fall = fall_polynomial(&red.wsq, &self.st.coords, self.theta())?;
        let plain = self.plain_forms(
            &red,
            names,
            &forces_reduced,
            separation.as_ref(),
            has_contact,
        )?;
        Ok(Ok(Reduction {
            reduced_inertia: to_expr(&red.inertia, "inertia")?,
            reduced_energy: to_expr(&red.e_red, "reduced energy")?,
            theta_dot_sq: to_expr(&red.wsq, "theta_dot_sq")?,
            theta_ddot: to_expr(&red.acc, "theta_ddot")?,
            cyclic_velocity: (red.cyc_vel.iter())
                .map(|e| to_expr(e, "cyclic velocity"))
                .collect::<Result<_, _>>()?,
            cyclic_position,
            forces_reduced: (forces_reduced.iter())
                .map(|e| to_expr(e, "force"))
                .collect::<Result<_, _>>()?,
            constants: red.constants,
            separation,
            fall,
            plain,
        }))
    }

    /// Every coordinate but the reduced one must be cyclic, with an inertia free of `theta`.
    fn unreducible_coordinates(&self) -> Option<Unreducible> {
        let (st, eqs) = (self.st, self.eqs);
        for (i, c) in st.coords.iter().enumerate() {
            if i != st.reduced && !eqs.cyclic.contains(&i) {
                return Some(format!(
                    "coordinate `{c}` is not cyclic (the Lagrangian depends on it), so it cannot \
                     be eliminated through a conserved momentum"
                ));
            }
        }
        for &i in &eqs.cyclic {
            for &j in &eqs.cyclic {
                if !free_of(&eqs.mass[i][j], &[self.theta()]) {
                    return Some(format!(
                        "the inertia of cyclic coordinate `{}` depends on `{}`",
                        st.coords[i],
                        self.theta()
                    ));
                }
            }
        }
        None
    }

    /// `theta_i`, `theta_dot_i`, their sine and cosine, the initial cyclic positions and the
    /// conserved momenta, as constants over the parameters.
    fn start_constants(&self) -> Result<Vec<Constant>, DeriveError> {
        let theta = self.theta();
        // sin and cos of the start are formed from the start's own expression where it is an
        // inverse function (sin(asin(a/ell)) = a/ell exactly; cos(asin(x)) = sqrt((1-x)(1+x)),
        // which keeps full relative accuracy near upright, unlike cos of an angle near pi/2).
        let theta_i = self.init(theta, 0)?;
        let start_trig = |f: &str| match &theta_i {
            Expr::Fun(g, _) if g == "asin" || g == "acos" => {
                simplify_inverse_trig(&Expr::Fun(f.into(), vec![theta_i.clone()]))
            }
            _ => Expr::Fun(f.into(), vec![Expr::sym("rc_thi")]),
        };
        let mut constants = vec![
            Constant {
                symbol: "rc_thi".into(),
                value: theta_i.clone(),
            },
            Constant {
                symbol: "rc_wi".into(),
                value: self.init(theta, 1)?,
            },
            Constant {
                symbol: "rc_si".into(),
                value: start_trig("sin"),
            },
            Constant {
                symbol: "rc_ci".into(),
                value: start_trig("cos"),
            },
        ];
        let (st, eqs) = (self.st, self.eqs);
        let wi = self.start_rate(&constants);
        let initial_state = |a: &A| -> A {
            let mut out = to_sc(a, theta);
            out = cas::subs_var(&out, "rc_s", &cas::var("rc_si"));
            out = cas::subs_var(&out, "rc_c", &cas::var("rc_ci"));
            out = cas::subs_var(&out, theta, &cas::var("rc_thi"));
            out = cas::subs_var(&out, &format!("dot_{theta}"), &wi);
            for (j, &i) in eqs.cyclic.iter().enumerate() {
                out = cas::subs_var(&out, &st.coords[i], &cas::var(&format!("rc_x{j}i")));
            }
            out
        };
        let mut cyclic_init_vel = Vec::new();
        for (j, &i) in eqs.cyclic.iter().enumerate() {
            constants.push(Constant {
                symbol: format!("rc_x{j}i"),
                value: self.init(&st.coords[i], 0)?,
            });
            cyclic_init_vel.push(cas::atom(&self.init(&st.coords[i], 1)?));
        }
        for (j, p) in eqs.momenta.iter().enumerate() {
            let mut v = initial_state(p);
            for (jj, &i) in eqs.cyclic.iter().enumerate() {
                v = cas::subs_var(&v, &format!("dot_{}", st.coords[i]), &cyclic_init_vel[jj]);
            }
            constants.push(Constant {
                symbol: format!("rc_p{j}"),
                value: to_expr(&cas::expand(&v), "momentum")?,
            });
        }
        Ok(constants)
    }

    /// The start's rate: a number when it is one (a start from rest), so that the derived
    /// forms simplify exactly as a person would simplify them.
    fn start_rate(&self, constants: &[Constant]) -> A {
        constant_value(constants, "rc_wi")
    }

    /// Cyclic velocities from the conserved momenta: `M_CC qd_C = P - M_Cr theta_dot`.
    fn cyclic_velocities(
        &self,
        constants: &mut [Constant],
    ) -> Result<Result<Vec<A>, Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let w = cas::var("rc_w");
        let k = eqs.cyclic.len();
        let momentum: Vec<A> = (0..k)
            .map(|j| constant_value(constants, &format!("rc_p{j}")))
            .collect();
        let mut mat: Vec<Vec<A>> = (eqs.cyclic.iter())
            .map(|&i| {
                eqs.cyclic
                    .iter()
                    .map(|&j| to_sc(&eqs.mass[i][j], theta))
                    .collect()
            })
            .collect();
        let mut vec_b: Vec<A> = (eqs.cyclic.iter().enumerate())
            .map(|(jj, &i)| {
                momentum[jj].clone() - to_sc(&eqs.mass[i][st.reduced], theta) * w.clone()
            })
            .collect();
        for col in 0..k {
            let Some(pivot) = (col..k).find(|&r| !cas::is_zero(&mat[r][col])) else {
                return Ok(Err(
                    "the cyclic velocities cannot be solved from their momenta (singular inertia)"
                        .into(),
                ));
            };
            mat.swap(col, pivot);
            vec_b.swap(col, pivot);
            let p = mat[col][col].clone();
            let pivot_row = mat[col].clone();
            for r in 0..k {
                if r == col {
                    continue;
                }
                let f = cas::together(&(mat[r][col].clone() / p.clone()));
                for (m, pc) in mat[r].iter_mut().zip(&pivot_row) {
                    *m = cas::together(&(m.clone() - f.clone() * pc.clone()));
                }
                vec_b[r] = cas::together(&(vec_b[r].clone() - f.clone() * vec_b[col].clone()));
            }
        }
        Ok(Ok((0..k)
            .map(|r| cas::expand(&cas::together(&(vec_b[r].clone() / mat[r][r].clone()))))
            .collect()))
    }

    /// The energy integral: `theta_dot^2` and `theta_ddot` over the start's drops, with the
    /// reduced inertia `A(theta)` and the effective potential `alpha + beta s + gamma c`.
    fn energy_integral(
        &self,
        mut constants: Vec<Constant>,
        cyc_vel: Vec<A>,
    ) -> Result<Result<Reduced, Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let w = cas::var("rc_w");
        let reduce_state = |a: &A| -> A {
            let mut out = to_sc(a, theta);
            for (jj, &i) in eqs.cyclic.iter().enumerate() {
                out = cas::subs_var(&out, &format!("dot_{}", st.coords[i]), &cyc_vel[jj]);
            }
            cas::subs_var(&out, &format!("dot_{theta}"), &w)
        };
        let total = self.lag.kinetic.clone() + self.lag.potential.clone();
        let e_red = cas::expand(&reduce_state(&total));
        let e_red = cas::expand(&cas::together(&e_red));
        let inertia = reduce_cos_sq(&cas::expand(&cas::d(&cas::d(&e_red, "rc_w"), "rc_w")));
        let inertia = cas::expand(&cas::together(&inertia));
        let linear = cas::subs_var(&cas::d(&e_red, "rc_w"), "rc_w", &cas::num(0));
        if !is_zero_trig(&linear).map_err(|m| at(&[], m))? {
            return Ok(Err(
                "the reduced energy has a term linear in the angular velocity".into(),
            ));
        }
        let v_eff = cas::subs_var(&e_red, "rc_w", &cas::num(0));
        let beta = cas::expand(&cas::d(&v_eff, "rc_s"));
        let gamma = cas::expand(&cas::d(&v_eff, "rc_c"));
        let rest = cas::expand(
            &(v_eff.clone() - beta.clone() * cas::var("rc_s") - gamma.clone() * cas::var("rc_c")),
        );
        let names = ["rc_s", "rc_c", theta];
        let mut coords: Vec<&str> = names.to_vec();
        coords.extend(st.coords.iter().map(String::as_str));
        if !(free_of(&beta, &coords) && free_of(&gamma, &coords) && free_of(&rest, &coords)) {
            return Ok(Err(format!(
                "the effective potential is not of the form alpha + beta sin({theta}) + gamma cos({theta})"
            )));
        }
        let ai = cas::subs_var(
            &cas::subs_var(&inertia, "rc_s", &cas::var("rc_si")),
            "rc_c",
            &cas::var("rc_ci"),
        );
        constants.push(Constant {
            symbol: "rc_ai".into(),
            value: to_expr(&cas::expand(&ai), "initial inertia")?,
        });
        let wi = self.start_rate(&constants);
        let two = cas::num(2);
        let wsq = (cas::var("rc_ai") * wi.clone() * wi
            + two.clone() * beta * cas::var("rc_ds")
            + two * gamma * cas::var("rc_dc"))
            / inertia.clone();
        let wsq = cas::together(&wsq);
        let half = cas::atom(&Expr::Rational(1, 2));
        let acc = cas::together(&(half * d_theta(&wsq)));
        Ok(Ok(Reduced {
            constants,
            cyc_vel,
            wsq,
            acc,
            inertia,
            e_red,
        }))
    }

    /// Cyclic positions in closed form (the velocities must be affine in sin and cos of
    /// `theta`) and the cyclic accelerations, over the reduced motion.
    #[allow(clippy::type_complexity)]
    fn cyclic_positions(
        &self,
        cyc_vel: &[A],
    ) -> Result<Result<(Vec<Expr>, Vec<A>), Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let mut positions = Vec::new();
        let mut accelerations = Vec::new();
        for (jj, v) in cyc_vel.iter().enumerate() {
            let a0 = cas::expand(&cas::subs_var(v, "rc_w", &cas::num(0)));
            let b = cas::expand(&cas::d(v, "rc_w"));
            let bs = cas::expand(&cas::d(&b, "rc_s"));
            let bc = cas::expand(&cas::d(&b, "rc_c"));
            let b0 = cas::expand(
                &(b.clone() - bs.clone() * cas::var("rc_s") - bc.clone() * cas::var("rc_c")),
            );
            let motion = ["rc_s", "rc_c", "rc_w"];
            let ok = [&a0, &bs, &bc, &b0].iter().all(|x| free_of(x, &motion));
            if !ok {
                return Ok(Err(format!(
                    "the velocity of `{}` is not affine in sin and cos of `{theta}`; its position \
                     has no closed form",
                    st.coords[eqs.cyclic[jj]]
                )));
            }
            let pos = cas::var(&format!("rc_x{jj}i"))
                + a0 * cas::var("rc_t")
                + bs.clone() * cas::var("rc_dc")
                - bc.clone() * cas::var("rc_ds")
                - b0 * cas::var("rc_delta");
            positions.push(to_expr(&cas::expand(&pos), "cyclic position")?);
            let bprime = bs * cas::var("rc_c") - bc * cas::var("rc_s");
            accelerations.push(cas::expand(
                &(bprime * cas::var("rc_w2") + b * cas::var("rc_acc")),
            ));
        }
        Ok(Ok((positions, accelerations)))
    }

    /// A force on the reduced motion, which must be `F0 + F2 theta_dot^2` (with `theta_ddot`
    /// kept as a symbol), each coefficient collected over one denominator.
    fn reduced_force(
        &self,
        full: &A,
        cyc_vel: &[A],
        cyc_acc: &[A],
    ) -> Result<Result<A, Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let mut r = to_sc(full, theta);
        for (jj, &ci) in eqs.cyclic.iter().enumerate() {
            let c = &st.coords[ci];
            r = cas::subs_var(&r, &format!("ddot_{c}"), &cyc_acc[jj]);
            r = cas::subs_var(&r, &format!("dot_{c}"), &cyc_vel[jj]);
        }
        r = cas::subs_var(&r, &format!("ddot_{theta}"), &cas::var("rc_acc"));
        r = cas::expand(&cas::subs_var(
            &r,
            &format!("dot_{theta}"),
            &cas::var("rc_w"),
        ));
        let half = cas::atom(&Expr::Rational(1, 2));
        let f0 = cas::subs_var(&r, "rc_w", &cas::num(0));
        let f1 = cas::subs_var(&cas::d(&r, "rc_w"), "rc_w", &cas::num(0));
        let f2 = cas::expand(&(half * cas::d(&cas::d(&r, "rc_w"), "rc_w")));
        let f3 = cas::d(&f2, "rc_w");
        if !cas::is_zero(&f1) || !cas::is_zero(&f3) {
            return Ok(Err(
                "not of the form F0 + F2 theta_dot^2 on the reduced motion".into(),
            ));
        }
        Ok(Ok(collect_over(
            &cas::expand(&(f0 + f2 * cas::var("rc_w2"))),
            &["rc_s", "rc_c", "rc_w2", "rc_acc"],
        )?))
    }

    /// The separation polynomial in `sin(theta)`: the contact force's numerator on the
    /// reduced motion, with `sin^2 + cos^2 = 1` and positive factors removed.
    fn separation(
        &self,
        red: &Reduced,
        contact_force: &A,
    ) -> Result<Result<Separation, Unreducible>, DeriveError> {
        let f = cas::together(&gap_vars(&self.on_motion(red, contact_force)));
        let fe = to_expr(&f, "contact force")?;
        let (num, _) = fe.num_den();
        let numer = reduce_cos_sq(&cas::atom(&product(num)));
        let p0 = cas::expand(&cas::subs_var(&numer, "rc_c", &cas::num(0)));
        let p1 = cas::expand(&cas::subs_var(
            &cas::d(&numer, "rc_c"),
            "rc_c",
            &cas::num(0),
        ));
        let check = cas::expand(&(numer.clone() - p0.clone() - p1.clone() * cas::var("rc_c")));
        if !cas::is_zero(&check) {
            return Ok(Err(
                "the contact force's numerator is not linear in cos(theta) after sin^2 + cos^2 = 1"
                    .into(),
            ));
        }
        let poly = if cas::is_zero(&p1) {
            p0
        } else if cas::is_zero(&p0) {
            p1
        } else {
            return Ok(Err(
                "the separation condition mixes sin(theta) and cos(theta); it is not a polynomial in sin(theta)"
                    .into(),
            ));
        };
        let mut positive = self.positive.clone();
        positive.push("rc_si".into());
        positive.push("rc_ci".into());
        let poly = strip_positive_factors(&poly, &positive)?;
        match coefficients_in_s(&poly, "coefficient")? {
            Some(coefficients) => Ok(Ok(Separation {
                coefficients,
                polynomial: to_expr(&poly, "separation polynomial")?,
            })),
            None => Ok(Err("the separation polynomial has a degree above 16".into())),
        }
    }

    /// A reduced expression with `theta_dot^2` and `theta_ddot` substituted.
    fn on_motion(&self, red: &Reduced, a: &A) -> A {
        let out = cas::subs_var(a, "rc_w2", &red.wsq);
        cas::subs_var(&out, "rc_acc", &red.acc)
    }

    /// Fully substituted forms over parameters and `theta`, for people and other tools.
    fn plain_forms(
        &self,
        red: &Reduced,
        names: &[Named],
        forces_reduced: &[A],
        separation: Option<&Separation>,
        has_contact: bool,
    ) -> Result<BTreeMap<String, Expr>, DeriveError> {
        let theta = self.theta();
        let mut const_plain: Vec<(String, A)> = Vec::new();
        for c in &red.constants {
            let mut v = cas::atom(&simplify_inverse_trig(&c.value));
            for (s, val) in &const_plain {
                v = cas::subs_var(&v, s, val);
            }
            let v = cas::atom(&simplify_inverse_trig(&to_expr(&v, "constant")?));
            const_plain.push((c.symbol.clone(), v));
        }
        let plainify = |a: &A| -> Result<Expr, DeriveError> {
            let mut v = gap_vars(a);
            for (s, val) in const_plain.iter().rev() {
                v = cas::subs_var(&v, s, val);
            }
            let v = to_expr(&cas::together(&v), "plain form")?;
            let (num, den) = v.num_den();
            let num = reduce_cos_sq(&cas::atom(&product(num)));
            let den = reduce_cos_sq(&cas::atom(&product(den)));
            let v = cas::together(&cas::factor(&(num / den)));
            Ok(from_sc(&to_expr(&v, "plain form")?, theta))
        };
        let mut plain = BTreeMap::new();
        plain.insert("theta_dot_sq".to_string(), plainify(&red.wsq)?);
        plain.insert("theta_ddot".to_string(), plainify(&red.acc)?);
        plain.insert("reduced_inertia".to_string(), plainify(&red.inertia)?);
        for (i, (f, n)) in forces_reduced.iter().zip(names).enumerate() {
            let key = if i == 0 && has_contact {
                "contact_force".to_string()
            } else {
                n.name.clone()
            };
            plain.insert(key, plainify(&self.on_motion(red, f))?);
        }
        if let Some(sep) = separation {
            plain.insert(
                "separation_condition".to_string(),
                plainify(&cas::atom(&sep.polynomial))?,
            );
        }
        Ok(plain)
    }
}

/// A constant's value where it is a plain number, its symbol otherwise.
fn constant_value(constants: &[Constant], symbol: &str) -> A {
    constants
        .iter()
        .find(|c| c.symbol == symbol)
        .and_then(|c| {
            let t = c.value.tidy();
            t.symbols().is_empty().then(|| cas::atom(&t))
        })
        .unwrap_or_else(|| cas::var(symbol))
}

/// `d/dtheta` of an expression over `rc_s`, `rc_c`, `rc_ds`, `rc_dc`.
fn d_theta(f: &A) -> A {
    cas::d(f, "rc_s") * cas::var("rc_c")
        - cas::d(f, "rc_c") * cas::var("rc_s")
        - cas::d(f, "rc_ds") * cas::var("rc_c")
        + cas::d(f, "rc_dc") * cas::var("rc_s")
}

/// Most coefficients of a polynomial in `sin(theta)` the derivation writes (separation and fall
/// polynomials).
const MAX_POLY_COEFFICIENTS: usize = 17;

/// The coefficients in `rc_s` of `a`, lowest degree first, if `a` is a polynomial in `rc_s` of
/// degree below [`MAX_POLY_COEFFICIENTS`] over symbols free of `rc_s` (checked by comparing
/// `a` with the sum of its Taylor terms).
fn coefficients_in_s(a: &A, what: &str) -> Result<Option<Vec<Expr>>, DeriveError> {
    let mut coefficients = Vec::new();
    let mut terms = Vec::new();
    let mut deriv = a.clone();
    let mut factorial: i64 = 1;
    for deg in 0..MAX_POLY_COEFFICIENTS as i64 {
        if deg > 0 {
            factorial *= deg;
        }
        let c0 = cas::expand(&(cas::subs_var(&deriv, "rc_s", &cas::num(0)) / cas::num(factorial)));
        let power = (0..deg).fold(cas::num(1), |acc, _| acc * cas::var("rc_s"));
        terms.push(c0.clone() * power);
        coefficients.push(to_expr(&c0, what)?);
        deriv = cas::expand(&cas::d(&deriv, "rc_s"));
        if cas::is_zero(&deriv) {
            let sum = terms.iter().fold(cas::num(0), |acc, t| acc + t.clone());
            return Ok(cas::is_zero(&cas::expand(&(a.clone() - sum))).then_some(coefficients));
        }
    }
    Ok(None)
}

/// The fall polynomial `(sin theta_i - s) / theta_dot^2` in `s = rc_s`, where it is one (see
/// [`Reduction::fall`]); `None` for a phase that does not start from rest, whose potential
/// has a `cos(theta)` term, or whose inertia is no polynomial in `sin(theta)`.
fn fall_polynomial(
    wsq: &A,
    coords: &[String],
    theta: &str,
) -> Result<Option<Vec<Expr>>, DeriveError> {
    if cas::is_zero(wsq) {
        return Ok(None);
    }
    let ratio = reduce_cos_sq(&cas::together(&(cas::var("rc_ds") / wsq.clone())));
    let ratio = cas::expand(&ratio);
    let mut motion = vec!["rc_ds", "rc_dc", "rc_c", theta];
    motion.extend(coords.iter().map(String::as_str));
    if !free_of(&ratio, &motion) {
        return Ok(None);
    }
    // Each coefficient over one denominator, common factors cancelled (`l (m1 + m2) / (3 g
    // (m1 + m2))` is `l / (3 g)`).
    let Some(coefficients) = coefficients_in_s(&ratio, "fall polynomial coefficient")? else {
        return Ok(None);
    };
    let tidy = |c: &Expr| to_expr(&cas::together(&cas::atom(c)), "fall polynomial coefficient");
    Ok(Some(
        coefficients.iter().map(tidy).collect::<Result<_, _>>()?,
    ))
}

/// `rc_ds`, `rc_dc` written as differences from the start.
fn gap_vars(a: &A) -> A {
    let out = cas::subs_var(a, "rc_ds", &(cas::var("rc_si") - cas::var("rc_s")));
    cas::subs_var(&out, "rc_dc", &(cas::var("rc_ci") - cas::var("rc_c")))
}

/// Whether an expression is structurally positive when the symbols `pos` are.
pub(super) fn positive(e: &Expr, pos: &[String]) -> bool {
    match e {
        Expr::Rational(n, _) => *n > 0,
        Expr::Float(x) => *x > 0.0,
        Expr::Sym(s) => pos.contains(s),
        Expr::Add(v) | Expr::Mul(v) => v.iter().all(|x| positive(x, pos)),
        Expr::Pow(b, x) => positive(b, pos) || x.as_integer().is_some_and(|n| n % 2 == 0),
        Expr::Fun(..) => false,
    }
}

/// Factorises and drops the factors free of `rc_s` that are strictly positive (or negative
/// constants), so that what is left is the separation polynomial up to a positive factor.
pub(super) fn strip_positive_factors(poly: &A, pos: &[String]) -> Result<A, DeriveError> {
    let f = to_expr(&cas::factor(poly), "factorised separation polynomial")?;
    let factors = match f {
        Expr::Mul(v) => v,
        e => vec![e],
    };
    let mut kept = Vec::new();
    for x in factors {
        let has_s = x.symbols().contains("rc_s");
        if has_s {
            kept.push(x);
            continue;
        }
        let (neg, mag) = x.split_sign();
        if positive(&mag, pos) || (neg && mag.symbols().is_empty()) {
            continue;
        }
        kept.push(x);
    }
    Ok(cas::expand(&cas::atom(&product(kept))))
}
