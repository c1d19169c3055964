//! Stage 1 of the derivation: every expression of a spec parsed once, each error placed at its
//! field, with the obstacles' symbols (`cylinder_x`, `cylinder_r`, ...) replaced by their
//! values over the parameters, so that later stages see parameters and coordinates only.

use super::algebra::simplify_inverse_trig;
use super::expr::Expr;
use super::spec::{ShapeSpec, Spec, Text, obstacle_symbols};
use super::types::{DeriveError, FieldStep, Shape, ShapeKind, at, entry, key};
use std::collections::BTreeMap;

/// One body's parsed expressions.
#[derive(Debug, Clone)]
pub struct BodyExprs {
    /// Its name.
    pub name: String,
    /// Mass.
    pub mass: Expr,
    /// Moment of inertia about the centre of mass.
    pub inertia: Expr,
    /// Centre of mass.
    pub position: [Expr; 2],
    /// Orientation.
    pub angle: Expr,
}

/// One contact's parsed expressions.
#[derive(Debug, Clone)]
pub struct ContactExprs {
    /// The gap.
    pub gap: Expr,
    /// The edge margin, if any.
    pub edge: Option<Expr>,
}

/// Every expression of a spec, parsed once.
#[derive(Debug, Clone)]
pub struct Parsed {
    /// The bodies.
    pub bodies: Vec<BodyExprs>,
    /// The named points' positions.
    pub points: Vec<[Expr; 2]>,
    /// The potentials besides gravity.
    pub potentials: Vec<Expr>,
    /// The contacts, in the spec's order.
    pub contacts: Vec<ContactExprs>,
    /// Each friction's contact point and tangent.
    pub friction: Vec<[[Expr; 2]; 2]>,
    /// The monitors.
    pub monitors: Vec<Expr>,
    /// The requirements on the parameters.
    pub requirements: Vec<Expr>,
    /// Each contact's coefficient of restitution over the parameters (`0` where the spec
    /// gives none).
    pub restitutions: Vec<Expr>,
    /// Initial position and velocity per coordinate the spec gives.
    pub initial: BTreeMap<String, [Expr; 2]>,
    /// The drawing: the bodies' shapes, then the obstacles'.
    pub shapes: Vec<Shape>,
}

/// Parses one expression of the spec, its error placed at `path`, with `cos(asin(x))` and the
/// like in the one form the derivation writes them ([`simplify_inverse_trig`]), so that no
/// later stage, and no constant the lowering hoists, holds a second form of the same value.
pub fn parse_text(t: &Text, path: &[FieldStep]) -> Result<Expr, DeriveError> {
    (Expr::parse(&t.text()).map(|e| simplify_inverse_trig(&e))).map_err(|e| at(path, e.message))
}

/// `e` with every symbol of `values` replaced by its value.
pub fn substitute(e: &Expr, values: &BTreeMap<String, Expr>) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(|x| substitute(x, values)).collect();
    match e {
        Expr::Sym(s) => values.get(s).cloned().unwrap_or_else(|| e.clone()),
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(substitute(b, values)),
            Box::new(substitute(x, values)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// The obstacles' symbols with their values over the parameters.
fn obstacle_values(spec: &Spec) -> Result<BTreeMap<String, Expr>, DeriveError> {
    let mut out = BTreeMap::new();
    for (i, o) in spec.obstacles.iter().enumerate() {
        for (symbol, text) in obstacle_symbols(o) {
            let path = [key("obstacles"), FieldStep::Index(i)];
            out.insert(symbol, parse_text(&text, &path)?);
        }
    }
    Ok(out)
}

/// Stage 1: parses every expression of the spec, each error placed at its field.
pub fn read(spec: &Spec) -> Result<Parsed, DeriveError> {
    let obstacles = obstacle_values(spec)?;
    // A kinematic expression: parsed, the obstacles' symbols replaced.
    let kin = |t: &Text, path: &[FieldStep]| -> Result<Expr, DeriveError> {
        Ok(substitute(&parse_text(t, path)?, &obstacles))
    };
    let pair = |t: &[Text; 2], path: &[FieldStep]| -> Result<[Expr; 2], DeriveError> {
        Ok([kin(&t[0], path)?, kin(&t[1], path)?])
    };
    let mut bodies = Vec::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        bodies.push(BodyExprs {
            name: b.name.clone(),
            mass: parse_text(&b.mass, &entry("bodies", i, "mass"))?,
            inertia: parse_text(&b.inertia, &entry("bodies", i, "inertia"))?,
            position: pair(&b.position, &entry("bodies", i, "position"))?,
            angle: kin(&b.angle, &entry("bodies", i, "angle"))?,
        });
    }
    let points = (spec.points.iter().enumerate())
        .map(|(i, p)| pair(&p.position, &entry("points", i, "position")))
        .collect::<Result<_, _>>()?;
    let potentials = (spec.potentials.iter().enumerate())
        .map(|(i, p)| kin(&p.expr, &entry("potentials", i, "expr")))
        .collect::<Result<_, _>>()?;
    let contacts = (spec.contacts.iter().enumerate())
        .map(|(i, c)| {
            Ok(ContactExprs {
                gap: kin(&c.gap, &entry("contacts", i, "gap"))?,
                edge: match &c.edge {
                    Some(e) => Some(kin(e, &entry("contacts", i, "edge"))?),
                    None => None,
                },
            })
        })
        .collect::<Result<_, DeriveError>>()?;
    let friction = (spec.friction.iter().enumerate())
        .map(|(i, f)| {
            Ok([
                pair(&f.point, &entry("friction", i, "point"))?,
                pair(&f.direction, &entry("friction", i, "direction"))?,
            ])
        })
        .collect::<Result<_, DeriveError>>()?;
    let monitors = (spec.monitors.iter().enumerate())
        .map(|(i, m)| kin(&m.expr, &entry("monitors", i, "expr")))
        .collect::<Result<_, _>>()?;
    let requirements = (spec.requirements.iter().enumerate())
        .map(|(i, r)| parse_text(&r.expr, &entry("requirements", i, "expr")))
        .collect::<Result<_, _>>()?;
    let restitutions = (spec.contacts.iter().enumerate())
        .map(|(i, c)| match &c.restitution {
            Some(e) => parse_text(e, &entry("contacts", i, "restitution")),
            None => Ok(Expr::Rational(0, 1)),
        })
        .collect::<Result<_, _>>()?;
    let mut initial = BTreeMap::new();
    for (c, s) in &spec.initial {
        let path = [key("initial"), key(c)];
        let value = [
            parse_text(&s.position, &path)?,
            parse_text(&s.velocity, &path)?,
        ];
        initial.insert(c.clone(), value);
    }
    Ok(Parsed {
        shapes: read_shapes(spec)?,
        bodies,
        points,
        potentials,
        contacts,
        friction,
        monitors,
        requirements,
        restitutions,
        initial,
    })
}

/// The drawing: each body's shape in its own frame, then each obstacle's moved to its `at`.
fn read_shapes(spec: &Spec) -> Result<Vec<Shape>, DeriveError> {
    let mut shapes = Vec::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        if let Some(shape) = &b.shape {
            let path = entry("bodies", i, "shape");
            shapes.push(read_shape(shape, Some(i), None, &path)?);
        }
    }
    for (i, o) in spec.obstacles.iter().enumerate() {
        let path = entry("obstacles", i, "shape");
        let at_path = entry("obstacles", i, "at");
        let origin = [
            parse_text(&o.at[0], &at_path)?,
            parse_text(&o.at[1], &at_path)?,
        ];
        shapes.push(read_shape(&o.shape, None, Some(origin), &path)?);
    }
    Ok(shapes)
}

/// A shape's numbers (see [`ShapeKind`]): a rectangle's and a circle's centre first (`at`, or
/// the origin), then its size; every point moved by `origin` when given (an obstacle's place).
fn read_shape(
    shape: &ShapeSpec,
    body: Option<usize>,
    origin: Option<[Expr; 2]>,
    path: &[FieldStep],
) -> Result<Shape, DeriveError> {
    let parse = |t: &Text| parse_text(t, path);
    let shift = |p: [Expr; 2]| -> [Expr; 2] {
        match &origin {
            Some([x0, y0]) => {
                let [x, y] = p;
                [
                    Expr::Add(vec![x0.clone(), x]).tidy(),
                    Expr::Add(vec![y0.clone(), y]).tidy(),
                ]
            }
            None => p,
        }
    };
    let centre = shift(match &shape.at {
        Some([x, y]) => [parse(x)?, parse(y)?],
        None => [Expr::int(0), Expr::int(0)],
    });
    let (kind, numbers) = match (&shape.segment, &shape.rectangle, &shape.circle) {
        (Some([[x1, y1], [x2, y2]]), None, None) => {
            let [a, b] = shift([parse(x1)?, parse(y1)?]);
            let [c, d] = shift([parse(x2)?, parse(y2)?]);
            (ShapeKind::Segment, vec![a, b, c, d])
        }
        (None, Some([w, h]), None) => (
            ShapeKind::Rectangle,
            [centre.to_vec(), vec![parse(w)?, parse(h)?]].concat(),
        ),
        (None, None, Some(r)) => (
            ShapeKind::Circle,
            [centre.to_vec(), vec![parse(r)?]].concat(),
        ),
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
