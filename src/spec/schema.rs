//! The schema of a model spec: the serde types a spec file is read into ([`Spec`] and its
//! parts), and the symbols an obstacle defines ([`obstacle_symbols`]).

use super::expr;
use serde::Deserialize;
use std::collections::BTreeMap;

/// An expression field: YAML may write it as a string or a bare number. Any plain scalar that
/// is not a number is its source text (the YAML reader takes only `true` and `false` as
/// booleans, so `y`, `n`, `on` and `no` are names here, as a physicist writes them).
#[derive(Debug, Clone)]
pub enum Text {
    /// `"ell/2*sin(theta)"`
    Str(String),
    /// `0`, `0.5`
    Num(f64),
}

impl Text {
    /// The expression text.
    pub fn text(&self) -> String {
        match self {
            Text::Str(s) => s.clone(),
            Text::Num(x) => expr::float_literal(*x),
        }
    }

    /// The number it is, where it is written as one.
    pub fn number(&self) -> Option<f64> {
        match self {
            Text::Num(x) => Some(*x),
            Text::Str(_) => None,
        }
    }
}

impl<'de> Deserialize<'de> for Text {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Text, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Text;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an expression, e.g. `x + 1`, `ell/2*sin(theta)` or `0.5`")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Text, E> {
                Ok(Text::Str(v.to_string()))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Text, E> {
                Ok(Text::Num(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Text, E> {
                Ok(Text::Num(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Text, E> {
                Ok(Text::Num(v as f64))
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// A declared parameter.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSpec {
    /// Symbol (`m1`).
    pub name: String,
    /// What it is.
    pub meaning: String,
    /// SI unit.
    pub unit: String,
    /// Whether it must be strictly positive (default true).
    #[serde(default = "yes")]
    pub positive: bool,
}

fn yes() -> bool {
    true
}

/// A condition on the parameters: `expr` must be strictly positive.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequirementSpec {
    /// Identifier.
    pub name: String,
    /// Margin expression of the parameters.
    pub expr: Text,
    /// What it means when it fails.
    pub meaning: String,
}

/// A generalized coordinate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoordSpec {
    /// Symbol (`x1`, `theta`).
    pub name: String,
    /// What it is.
    pub meaning: String,
    /// SI unit.
    pub unit: String,
}

/// A rigid body moving in the plane.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Identifier.
    pub name: String,
    /// Mass.
    pub mass: Text,
    /// Moment of inertia about the centre of mass.
    pub inertia: Text,
    /// Centre of mass `[x, y]` (y up) as expressions of the coordinates.
    pub position: [Text; 2],
    /// Orientation angle (counter-clockwise).
    pub angle: Text,
    /// How to draw the body (in `motion.svg`), in its own frame: its centre of mass at the
    /// origin, x along its `angle`. None: the body is not drawn.
    #[serde(default)]
    pub shape: Option<ShapeSpec>,
}

/// A shape to draw, with its sizes as expressions of the parameters: exactly one of `segment`,
/// `rectangle` and `circle`. On a body it is in the body's own frame (its centre of mass at the
/// origin, x along its `angle`); on an obstacle, in the obstacle's frame (origin at its `at`,
/// axes along the world's: y up, the floor at y = 0).
///
/// `{segment: [[-ell/2, 0], [ell/2, 0]]}` (a rod), `{rectangle: [a, a]}` (a cube),
/// `{circle: R}` (a cylinder); a rectangle or circle is centred at the origin of its frame
/// unless `at: [x, y]` moves it.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeSpec {
    /// A line between two points `[[x1, y1], [x2, y2]]`.
    #[serde(default)]
    pub segment: Option<[[Text; 2]; 2]>,
    /// A rectangle `[width, height]` with its sides along the frame's axes.
    #[serde(default)]
    pub rectangle: Option<[Text; 2]>,
    /// A circle of this radius.
    #[serde(default)]
    pub circle: Option<Text>,
    /// The centre of a rectangle or circle (default: the origin of the frame).
    #[serde(default)]
    pub at: Option<[Text; 2]>,
}

/// A named point whose trajectory can be reported.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    /// Identifier.
    pub name: String,
    /// `[x, y]` as expressions of the coordinates.
    pub position: [Text; 2],
    /// What it is.
    pub meaning: String,
}

/// A fixed body (a wall, a cylinder, a step): no coordinates, placed by parameters, drawn in
/// `motion.svg`. Gaps, edges, points, frictions and monitors may use its symbols
/// (see [`obstacle_symbols`]): `<name>_x` and `<name>_y` (where `at` puts it), and its shape's
/// sizes, `<name>_r` for a circle, `<name>_w` and `<name>_h` for a rectangle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Identifier (the prefix of its symbols).
    pub name: String,
    /// What it is.
    pub meaning: String,
    /// Its reference point `[x, y]` in world coordinates, over the parameters: the origin of
    /// its shape's frame.
    pub at: [Text; 2],
    /// Its shape in its own frame (origin at `at`, axes along the world's).
    pub shape: ShapeSpec,
}

/// An extra potential-energy term besides gravity (a spring, say).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PotentialSpec {
    /// Identifier.
    pub name: String,
    /// Energy as an expression of parameters and coordinates (J).
    pub expr: Text,
    /// What it is.
    pub meaning: String,
}

/// A support: a unilateral constraint `gap(q) >= 0` (or, `bilateral`, `gap(q) = 0` always).
///
/// Its force is the constraint's Lagrange multiplier `lambda`, conjugate to the gap: the
/// generalized force on the coordinates is `lambda d(gap)/dq`, so a gap in metres gives a force
/// in newtons and a gap in radians a torque in newton metres. A unilateral contact pushes
/// (`lambda >= 0`) while it is closed (`gap = 0`) and opens where its force would have to pull;
/// an open contact closes where its gap reaches zero. A bilateral one (a hinge, a pin) holds
/// with a force of either sign and never opens.
///
/// With `eliminates`, a closed contact may be solved for that coordinate: `gap = 0` must be
/// linear in it, with a coefficient that does not vanish (it may depend on the other
/// coordinates), and the phases in which it is closed are derived with the coordinate
/// eliminated (the fast path, where they reduce to one coordinate). Without it, the coordinate
/// stays and the force is solved along with the motion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Name of its force (a result key: `<name>_series`, `<name>_end_time`, ...).
    pub name: String,
    /// What the force is, with its sign convention (positive while the bodies push apart).
    pub meaning: String,
    /// Gap: positive when apart, zero when touching (expression of parameters, coordinates and
    /// obstacle symbols). Its unit sets the unit of the force.
    pub gap: Text,
    /// The coordinate `gap = 0` is solved for while the contact is closed (optional).
    #[serde(default)]
    pub eliminates: Option<String>,
    /// Optional geometric end: an expression that stays `>= 0` while the contact can exist
    /// (a contact point still on the body); its zero ends the motion at an edge.
    #[serde(default)]
    pub edge: Option<Text>,
    /// A joint rather than a contact: closed for good, its force of either sign.
    #[serde(default)]
    pub bilateral: bool,
    /// Newton's coefficient of restitution where the contact closes with an approach velocity:
    /// an expression of the parameters in `[0, 1]` (0, the default: the bodies stay together;
    /// 1: no energy is lost). A bilateral contact never closes, so it has none.
    #[serde(default)]
    pub restitution: Option<Text>,
}

/// Coulomb friction at a contact: its normal force is that contact's force.
///
/// The friction force `f` acts on `body` at `point` along the unit tangent `direction` (and
/// `-f` on `against`, when it is a body). Its slip velocity is
/// `v = direction . (v_body(point) - v_against(point))`, the velocity of the body's material point
/// there relative to the other surface's, and its generalized force is `f dv/dqd`. While the
/// contact slides, `f = -mu N sign(v)`; while it sticks, `v` stays zero and `f` is whatever keeps
/// it so, as long as `|f| <= mu N`. While the contact is open there is no friction.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Identifier (a result key for the friction force, in newtons).
    pub name: String,
    /// What it is, with its sign convention.
    pub meaning: String,
    /// The friction coefficient: a parameter (declared `positive: false` if it may be zero; a
    /// negative value is refused when the model is bound).
    pub coefficient: String,
    /// The contact it acts at (one of `contacts`, unilateral): its force is the normal force.
    pub contact: String,
    /// The body the friction acts on.
    pub body: String,
    /// The other body at the contact (it feels `-f`); absent for the fixed floor or an
    /// obstacle.
    #[serde(default)]
    pub against: Option<String>,
    /// The contact point `[x, y]` (expressions of the coordinates).
    pub point: [Text; 2],
    /// Unit tangent: the positive sense of the friction force on `body` and of the slip.
    pub direction: [Text; 2],
}

/// A physical assumption: `expr` must stay `>= 0` during the motion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorSpec {
    /// Identifier.
    pub name: String,
    /// Expression of parameters, `theta` and force names.
    pub expr: Text,
    /// What it checks.
    pub meaning: String,
    /// The unit its value is in (`N`, `N m`, `m`, ...); none when omitted.
    #[serde(default)]
    pub unit: Option<String>,
}

/// Initial position and velocity of one coordinate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Position (expression of parameters).
    pub position: Text,
    /// Velocity (expression of parameters).
    pub velocity: Text,
}

/// A dimensionless group: a product of powers of parameters (`m2/m1`, `k*ell/(m1*g)`), named
/// so that results can be written in it. The derivation tool solves each group for its first
/// parameter that appears to the first power and that no earlier group was solved for (`m2`
/// in `n = m2/m1`, giving `m2 = n m1`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupSpec {
    /// Symbol of the group (`n`).
    pub name: String,
    /// Its definition over the parameters (`m2/m1`).
    pub expr: Text,
    /// What it is.
    pub meaning: String,
}

/// The units in which the dimensionless results are written: expressions of the parameters.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalesSpec {
    /// A time (`sqrt(ell/g)`): rates are in units of its inverse, `theta_dot^2` of its inverse
    /// square.
    pub time: Text,
    /// A force (`m2*g`): every reaction force is in units of it.
    pub force: Text,
}

/// How a model's results are written without units: its groups, its scales and, where the
/// results are a paper's, that paper's equation numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DimensionlessSpec {
    /// The dimensionless groups, in the order they are solved and listed.
    pub groups: Vec<GroupSpec>,
    /// The time and force scales.
    pub scales: ScalesSpec,
    /// The paper's equation number of a result (`theta_dot_sq: "9"`), printed beside it.
    #[serde(default)]
    pub paper: BTreeMap<String, String>,
}

/// A whole model spec.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// Model name: a plain identifier, the stem of the generated files.
    pub name: String,
    /// One line for people.
    pub description: String,
    /// Parameters, in the order the generated functions take them.
    pub parameters: Vec<ParamSpec>,
    /// Conditions on the parameters.
    #[serde(default)]
    pub requirements: Vec<RequirementSpec>,
    /// Name of the gravity parameter (gravity acts along -y).
    pub gravity: String,
    /// Generalized coordinates.
    pub coordinates: Vec<CoordSpec>,
    /// The coordinate reported as the angle of the motion (`theta`): the one kept when the
    /// others are cyclic and eliminated, and the one whose `end_angle` ends the motion. None:
    /// the system has no such angle (no fast phase, no angle in its results); it runs to its
    /// scene's `until`.
    #[serde(default)]
    pub reduced: Option<String>,
    /// Value of the reduced coordinate where the motion ends (the floor). None: the motion has
    /// no end of its own and runs to its scene's `until`.
    #[serde(default)]
    pub end_angle: Option<f64>,
    /// Bodies.
    pub bodies: Vec<BodySpec>,
    /// Named points.
    #[serde(default)]
    pub points: Vec<PointSpec>,
    /// Point whose initial height gives the reference free-fall time, and whose height tells a
    /// landing at `end_angle` from a support holding the body up. None: no such reference.
    #[serde(default)]
    pub falling_point: Option<String>,
    /// Potential energy besides gravity.
    #[serde(default)]
    pub potentials: Vec<PotentialSpec>,
    /// Fixed bodies (walls, cylinders, steps): drawn, and usable in gaps through their
    /// symbols.
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// Every support: unilateral contacts and bilateral joints, in the order results list
    /// them (the first is the one whose end is the "separation").
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// Coulomb friction at contacts.
    #[serde(default)]
    pub friction: Vec<FrictionSpec>,
    /// Monitored assumptions.
    #[serde(default)]
    pub monitors: Vec<MonitorSpec>,
    /// Retired (reaction forces projected by hand): read only to say what replaced it.
    #[serde(default)]
    pub forces: Option<serde::de::IgnoredAny>,
    /// Retired (the one contact): read only to say what replaced it.
    #[serde(default)]
    pub contact: Option<serde::de::IgnoredAny>,
    /// Retired (fixed shapes): read only to say what replaced it.
    #[serde(default)]
    pub scenery: Option<serde::de::IgnoredAny>,
    /// Initial state, one entry per coordinate except those a contact eliminates (they start
    /// where `gap = 0` puts them).
    pub initial: BTreeMap<String, InitialSpec>,
    /// Dimensionless groups and scales in which the results are also written (none: the
    /// results are written in the parameters only).
    #[serde(default)]
    pub dimensionless: Option<DimensionlessSpec>,
}

/// The symbols an obstacle defines, with their values over the parameters: `<name>_x` and
/// `<name>_y` (its `at`), and its shape's sizes (`<name>_r` for a circle, `<name>_w` and
/// `<name>_h` for a rectangle; a segment's ends are its own business).
pub fn obstacle_symbols(o: &ObstacleSpec) -> Vec<(String, Text)> {
    let mut out = vec![
        (format!("{}_x", o.name), o.at[0].clone()),
        (format!("{}_y", o.name), o.at[1].clone()),
    ];
    if let Some(r) = &o.shape.circle {
        out.push((format!("{}_r", o.name), r.clone()));
    }
    if let Some([w, h]) = &o.shape.rectangle {
        out.push((format!("{}_w", o.name), w.clone()));
        out.push((format!("{}_h", o.name), h.clone()));
    }
    out
}
