//! Model specs (`derivations/*.yaml`): their schema, parsing, and checks that name file, line
//! and field for every error.
//!
//! Part of the runtime crate (no Symbolica), so that specs and their expressions can be parsed,
//! checked and fuzzed without the `derive` feature; the derivation tool re-exports this module
//! as `rodcube::derive::spec` (and [`expr`] as `rodcube::derive::expr`).

pub mod expr;
pub mod units;

use crate::yaml::{At, Document, ReadError, Step, excerpt, line_text};
use annotate_snippets::{Group, Level, Renderer};
use expr::{Expr, FUNCTIONS, gcd};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

/// An expression field: YAML may write it as a string or a bare number.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
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
/// origin, x along its `angle`); in `scenery`, in world coordinates (y up, the floor at y = 0).
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

/// A reaction force measured on one body along one direction.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    /// Identifier.
    pub name: String,
    /// Body whose equation of motion gives the force.
    pub body: String,
    /// Direction `d`, numbers (a unit vector) or expressions of the coordinates: the force is
    /// the body's Newton balance projected on `d`, `m (d . a) + m g d_y`, that is the sum of
    /// the non-gravity forces on `body` dotted with `d`. It measures one force when every other
    /// force on the body is perpendicular to `d`; a force along a direction that another force
    /// also has a component on can be isolated with a `d` perpendicular to that other force,
    /// scaled so that the wanted force comes out whole (the floor's push on a rod that also
    /// leans on a cylinder: `d = [cos(theta)/sin(theta), 1]`, perpendicular to the push).
    pub direction: [Text; 2],
    /// What it is, with its sign convention.
    pub meaning: String,
}

/// An extra potential-energy term besides gravity (a spring, say).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PotentialSpec {
    /// Identifier.
    pub name: String,
    /// Energy as an expression of parameters and coordinates (J).
    pub expr: Text,
    /// The bodies its force acts on. A reaction force in `forces` is measured by a Newton
    /// balance on one body, which is only right when no potential acts on that body besides
    /// gravity: the spec check refuses such a pair.
    pub acts_on: Vec<String>,
    /// What it is.
    pub meaning: String,
}

/// A unilateral contact: `gap(q) >= 0`, touching while `gap = 0` and its force is positive.
///
/// While touching, `gap = 0` is solved for the coordinate `eliminates` (the gap must be linear
/// in it with a constant coefficient `c`), which is substituted everywhere; the contact force
/// is the Lagrange multiplier `lambda = E_e / c`, where `E_e` is the Euler–Lagrange expression
/// of that coordinate with every other force accounted for. The phase after the contact ends is
/// derived from the same spec with the coordinate free again (the model `<name>_free`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Name of the contact force (a result key; not one of `forces`).
    pub force: String,
    /// What the force is, with its sign convention (positive while the bodies push apart).
    pub meaning: String,
    /// Gap: positive when apart, zero when touching (expression of parameters and coordinates).
    pub gap: Text,
    /// The coordinate solved from `gap = 0` while touching.
    pub eliminates: String,
    /// Optional geometric end: an expression that stays `>= 0` while the contact can exist
    /// (a contact point still on the body); its zero ends the contact at an edge.
    #[serde(default)]
    pub edge: Option<Text>,
}

/// Coulomb friction at a point where a body touches another body or the floor.
///
/// The friction force `f` acts on `body` at `point` along the unit tangent `direction` (and
/// `-f` on `against`, when it is a body). Its slip velocity is
/// `v = direction . (v_body(point) - v_against(point))`, the velocity of the body's material point
/// there relative to the other surface's, and its generalized force is `f dv/dqd`. While the
/// contact slides, `f = -mu N sign(v)`; while it sticks, `v` stays zero and `f` is whatever keeps
/// it so, as long as `|f| <= mu N`.
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
    /// The normal force the friction is proportional to: one of `forces`, or the contact force.
    pub normal: String,
    /// The body the friction acts on.
    pub body: String,
    /// The other body at the contact (it feels `-f`); absent for the fixed floor or a wall.
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

/// The results a dimensionless block can hold besides the forces (whose names are the spec's).
pub const DIMENSIONLESS_RESULTS: &[&str] = &["theta_dot_sq", "theta_ddot", "separation_condition"];

/// The factors of a monomial `c * p1^e1 * p2^e2 ...` with `c > 0` rational and rational
/// exponents, in the order written; `None` for anything else (a sum, a function, a negative
/// coefficient).
pub fn monomial(e: &Expr) -> Option<Vec<(String, Expr)>> {
    fn walk(e: &Expr, power: (i128, i128), out: &mut Vec<(String, (i128, i128))>) -> bool {
        match e {
            Expr::Rational(n, _) => *n > 0,
            Expr::Sym(s) => {
                match out.iter_mut().find(|(name, _)| name == s) {
                    Some((_, p)) => {
                        let sum = (p.0.checked_mul(power.1))
                            .zip(power.0.checked_mul(p.1))
                            .and_then(|(a, b)| a.checked_add(b));
                        let (Some(n), Some(d)) = (sum, p.1.checked_mul(power.1)) else {
                            return false;
                        };
                        let g = gcd(n.abs(), d.abs());
                        *p = (n / g, d / g);
                    }
                    None => out.push((s.clone(), power)),
                }
                true
            }
            Expr::Mul(v) => v.iter().all(|f| walk(f, power, out)),
            Expr::Pow(b, x) => match **x {
                Expr::Rational(n, d) => match (power.0.checked_mul(n), power.1.checked_mul(d)) {
                    (Some(pn), Some(pd)) => {
                        let g = gcd(pn.abs(), pd.abs());
                        walk(b, (pn / g, pd / g), out)
                    }
                    _ => false,
                },
                _ => false,
            },
            _ => false,
        }
    }
    let mut out = Vec::new();
    walk(&e.tidy(), (1, 1), &mut out).then(|| {
        out.into_iter()
            .filter(|(_, p)| p.0 != 0)
            .map(|(s, (n, d))| (s, Expr::Rational(n, d)))
            .collect()
    })
}

/// The parameter each group is solved for (see [`GroupSpec`]), in the groups' order; `Err`
/// with the index of the first group that has none.
pub fn solved_parameters(groups: &[GroupSpec]) -> Result<Vec<String>, usize> {
    let mut solved: Vec<String> = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let factors = Expr::parse(&g.expr.text())
            .ok()
            .and_then(|e| monomial(&e))
            .ok_or(i)?;
        let p = factors
            .into_iter()
            .find(|(p, x)| *x == Expr::int(1) && !solved.contains(p))
            .ok_or(i)?;
        solved.push(p.0);
    }
    Ok(solved)
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
    /// others are cyclic and eliminated, and the one whose `end_angle` ends the motion.
    pub reduced: String,
    /// Value of the reduced coordinate where the motion ends (the floor).
    pub end_angle: f64,
    /// Bodies.
    pub bodies: Vec<BodySpec>,
    /// Named points.
    #[serde(default)]
    pub points: Vec<PointSpec>,
    /// Point whose initial height gives the reference free-fall time.
    pub falling_point: String,
    /// Potential energy besides gravity.
    #[serde(default)]
    pub potentials: Vec<PotentialSpec>,
    /// Reaction forces to evaluate.
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
    /// The separating contact, if any.
    #[serde(default)]
    pub contact: Option<ContactSpec>,
    /// Coulomb friction at contacts.
    #[serde(default)]
    pub friction: Vec<FrictionSpec>,
    /// Monitored assumptions.
    #[serde(default)]
    pub monitors: Vec<MonitorSpec>,
    /// Fixed shapes drawn in world coordinates besides the floor (a wall, say); sizes are
    /// expressions of the parameters.
    #[serde(default)]
    pub scenery: Vec<ShapeSpec>,
    /// Initial state, one entry per coordinate (except the one the contact eliminates).
    pub initial: BTreeMap<String, InitialSpec>,
    /// Dimensionless groups and scales in which the results are also written (none: the
    /// results are written in the parameters only).
    #[serde(default)]
    pub dimensionless: Option<DimensionlessSpec>,
}

/// A spec error with its place.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpecError {
    /// Spec file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// Dotted field path (`bodies[0].position[1]`).
    pub field: String,
    /// What is wrong.
    pub message: String,
    /// The text of line `line` (for the snippet), empty when `line` is 0.
    pub source_line: String,
    /// Characters of `source_line` from `column` that the problem covers; 0 without a place.
    pub width: usize,
}

impl SpecError {
    /// A read error (syntax, duplicate key, tag, unknown or missing key, wrong type) named by
    /// the path serde was at: the mapping's for a key problem (`bodies[0]`).
    fn read(file: &Path, text: &str, e: ReadError) -> SpecError {
        SpecError {
            file: file.to_path_buf(),
            line: e.mark.line,
            column: e.mark.column,
            field: e.path,
            message: e.message,
            source_line: line_text(text, e.mark.line).to_string(),
            width: e.mark.width,
        }
    }
}

impl fmt::Display for SpecError {
    /// `file:line:column: field `name`: message`, then (with a place) the line with the token
    /// underlined, rendered by annotate-snippets.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: field `{}`: {}",
            self.file.display(),
            self.line,
            self.column,
            self.field,
            self.message
        )?;
        if self.line > 0 {
            let snippet = excerpt(&self.source_line, self.line, self.column, self.width);
            let group = Group::with_level(Level::ERROR).element(snippet);
            let renderer = Renderer::plain().term_width(usize::from(u16::MAX));
            write!(f, "\n{}", renderer.render(&[group]))?;
        }
        Ok(())
    }
}

impl std::error::Error for SpecError {}

/// A parsed and checked spec with its expressions parsed.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The raw spec.
    pub spec: Spec,
    /// Where it came from.
    pub file: PathBuf,
}

/// Names the derivation uses internally; specs may not use them.
pub const RESERVED_PREFIXES: &[&str] = &["rc_", "dot_", "ddot_"];

/// Reads and checks a spec file.
pub fn load(path: &Path) -> Result<Checked, SpecError> {
    let text = std::fs::read_to_string(path).map_err(|e| SpecError {
        file: path.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read: {e}"),
        source_line: String::new(),
        width: 0,
    })?;
    parse(path, &text)
}

/// Parses and checks spec text (`path` is used in messages).
pub fn parse(path: &Path, text: &str) -> Result<Checked, SpecError> {
    // Every node first (syntax, duplicate keys, tags), then the schema: each error typed and
    // at the parser's mark (crate::yaml).
    let doc = Document::parse(text).map_err(|e| SpecError::read(path, text, e))?;
    let spec: Spec = doc
        .deserialize()
        .map_err(|e| SpecError::read(path, text, e))?;
    let checker = Checker {
        path,
        doc: &doc,
        spec: &spec,
    };
    checker.check()?;
    Ok(Checked {
        spec,
        file: path.to_path_buf(),
    })
}

struct Checker<'a> {
    path: &'a Path,
    doc: &'a Document<'a>,
    spec: &'a Spec,
}

/// A field path as both YAML steps and a dotted name.
#[derive(Clone)]
struct Field(Vec<(Option<String>, Option<usize>)>);

impl Field {
    fn key(k: &str) -> Field {
        Field(vec![(Some(k.to_string()), None)])
    }
    fn k(&self, k: &str) -> Field {
        let mut v = self.0.clone();
        v.push((Some(k.to_string()), None));
        Field(v)
    }
    fn i(&self, i: usize) -> Field {
        let mut v = self.0.clone();
        v.push((None, Some(i)));
        Field(v)
    }
    fn dotted(&self) -> String {
        let mut s = String::new();
        for (k, i) in &self.0 {
            match (k, i) {
                (Some(k), _) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                (None, Some(i)) => s.push_str(&format!("[{i}]")),
                _ => {}
            }
        }
        s
    }
}

impl Checker<'_> {
    fn err(&self, field: &Field, message: String) -> SpecError {
        let steps: Vec<Step<'_>> = field
            .0
            .iter()
            .map(|(k, i)| match (k, i) {
                (Some(k), _) => Step::Key(k.as_str()),
                (None, Some(i)) => Step::Index(*i),
                _ => Step::Index(0),
            })
            .collect();
        let mark = self.doc.locate_nearest(&steps, At::Key);
        SpecError {
            file: self.path.to_path_buf(),
            line: mark.line,
            column: mark.column,
            field: field.dotted(),
            message,
            source_line: self.doc.line_text(mark.line).to_string(),
            width: mark.width,
        }
    }

    fn check(&self) -> Result<(), SpecError> {
        let s = self.spec;
        if !is_identifier(&s.name) {
            return Err(self.err(
                &Field::key("name"),
                format!(
                    "model name `{}` must be a plain identifier (letters, digits, `_`, not starting \
                     with a digit): it becomes a file name",
                    s.name
                ),
            ));
        }
        let mut seen = BTreeSet::new();
        let params: BTreeSet<String> = s.parameters.iter().map(|p| p.name.clone()).collect();
        let coords: BTreeSet<String> = s.coordinates.iter().map(|c| c.name.clone()).collect();
        let named = |list: &str, i: usize| Field::key(list).i(i).k("name");
        for (i, p) in s.parameters.iter().enumerate() {
            self.identifier(&named("parameters", i), &p.name, &mut seen)?;
        }
        for (i, c) in s.coordinates.iter().enumerate() {
            self.identifier(&named("coordinates", i), &c.name, &mut seen)?;
        }
        let mut names = BTreeSet::new();
        for (i, b) in s.bodies.iter().enumerate() {
            self.identifier(&named("bodies", i), &b.name, &mut names)?;
        }
        let mut point_names = BTreeSet::new();
        for (i, p) in s.points.iter().enumerate() {
            self.identifier(&named("points", i), &p.name, &mut point_names)?;
        }
        let mut force_names = BTreeSet::new();
        for (i, f) in s.forces.iter().enumerate() {
            self.identifier(&named("forces", i), &f.name, &mut force_names)?;
            if seen.contains(&f.name) {
                return Err(self.err(
                    &named("forces", i),
                    format!("`{}` is already a parameter or coordinate", f.name),
                ));
            }
        }
        if let Some(c) = &s.contact {
            let field = Field::key("contact").k("force");
            self.identifier(&field, &c.force, &mut force_names)?;
            if seen.contains(&c.force) {
                return Err(self.err(
                    &field,
                    format!("`{}` is already a parameter or coordinate", c.force),
                ));
            }
        }
        let mut potential_names = BTreeSet::new();
        for (i, p) in s.potentials.iter().enumerate() {
            self.identifier(&named("potentials", i), &p.name, &mut potential_names)?;
        }
        let mut friction_names = force_names.clone();
        for (i, f) in s.friction.iter().enumerate() {
            self.identifier(&named("friction", i), &f.name, &mut friction_names)?;
            if seen.contains(&f.name) {
                return Err(self.err(
                    &named("friction", i),
                    format!("`{}` is already a parameter or coordinate", f.name),
                ));
            }
        }
        let mut monitor_names = BTreeSet::new();
        for (i, m) in s.monitors.iter().enumerate() {
            self.identifier(&named("monitors", i), &m.name, &mut monitor_names)?;
        }
        let mut req_names = BTreeSet::new();
        for (i, r) in s.requirements.iter().enumerate() {
            self.identifier(&named("requirements", i), &r.name, &mut req_names)?;
        }
        if s.bodies.is_empty() {
            return Err(self.err(
                &Field::key("bodies"),
                "a model needs at least one body".into(),
            ));
        }
        if !params.contains(&s.gravity) {
            return Err(self.err(
                &Field::key("gravity"),
                format!("`{}` is not a parameter", s.gravity),
            ));
        }
        if !coords.contains(&s.reduced) {
            return Err(self.err(
                &Field::key("reduced"),
                format!("`{}` is not a coordinate", s.reduced),
            ));
        }
        if !point_names.contains(&s.falling_point) {
            return Err(self.err(
                &Field::key("falling_point"),
                format!("`{}` is not one of the points", s.falling_point),
            ));
        }
        let only_params: BTreeSet<String> = params.clone();
        let mut kinematic = params.clone();
        kinematic.extend(coords.iter().cloned());
        for (i, r) in s.requirements.iter().enumerate() {
            self.expr(
                &Field::key("requirements").i(i).k("expr"),
                &r.expr,
                &only_params,
            )?;
        }
        for (i, b) in s.bodies.iter().enumerate() {
            let f = Field::key("bodies").i(i);
            self.expr(&f.k("mass"), &b.mass, &only_params)?;
            self.expr(&f.k("inertia"), &b.inertia, &only_params)?;
            self.expr(&f.k("position").i(0), &b.position[0], &kinematic)?;
            self.expr(&f.k("position").i(1), &b.position[1], &kinematic)?;
            self.expr(&f.k("angle"), &b.angle, &kinematic)?;
        }
        for (i, p) in s.points.iter().enumerate() {
            let f = Field::key("points").i(i).k("position");
            self.expr(&f.i(0), &p.position[0], &kinematic)?;
            self.expr(&f.i(1), &p.position[1], &kinematic)?;
        }
        let bodies: BTreeSet<String> = s.bodies.iter().map(|b| b.name.clone()).collect();
        for (i, p) in s.potentials.iter().enumerate() {
            let field = Field::key("potentials").i(i);
            self.expr(&field.k("expr"), &p.expr, &kinematic)?;
            for (j, b) in p.acts_on.iter().enumerate() {
                if !bodies.contains(b) {
                    return Err(self.err(
                        &field.k("acts_on").i(j),
                        format!("`{b}` is not one of the bodies"),
                    ));
                }
            }
        }
        for (i, f) in s.forces.iter().enumerate() {
            let field = Field::key("forces").i(i);
            if !bodies.contains(&f.body) {
                return Err(self.err(
                    &field.k("body"),
                    format!("`{}` is not one of the bodies", f.body),
                ));
            }
            if let Some(p) = s.potentials.iter().find(|p| p.acts_on.contains(&f.body)) {
                return Err(self.err(
                    &field.k("body"),
                    format!(
                        "force `{}` is measured by a Newton balance on `{}`, but potential `{}` \
                         also acts on that body, so the balance would not isolate the force; \
                         measure it on another body or make it a contact",
                        f.name, f.body, p.name
                    ),
                ));
            }
            let d = field.k("direction");
            self.expr(&d.i(0), &f.direction[0], &kinematic)?;
            self.expr(&d.i(1), &f.direction[1], &kinematic)?;
            if let (Text::Num(x), Text::Num(y)) = (&f.direction[0], &f.direction[1]) {
                self.unit(&d, [*x, *y])?;
            }
        }
        if let Some(c) = &s.contact {
            let field = Field::key("contact");
            self.expr(&field.k("gap"), &c.gap, &kinematic)?;
            if !coords.contains(&c.eliminates) {
                return Err(self.err(
                    &field.k("eliminates"),
                    format!("`{}` is not a coordinate", c.eliminates),
                ));
            }
            if c.eliminates == s.reduced {
                return Err(self.err(
                    &field.k("eliminates"),
                    format!(
                        "`{}` is the reduced coordinate, which the motion is reported in; \
                         eliminate another one",
                        c.eliminates
                    ),
                ));
            }
            if s.coordinates.len() < 2 {
                return Err(self.err(
                    &field.k("eliminates"),
                    "a contact needs a coordinate besides the reduced one to eliminate".into(),
                ));
            }
            if let Some(edge) = &c.edge {
                self.expr(&field.k("edge"), edge, &kinematic)?;
            }
        }
        self.check_friction(&params, &bodies, &force_names, &kinematic)?;
        self.check_drawing(&only_params)?;
        let mut monitor_scope = kinematic.clone();
        monitor_scope.extend(force_names.iter().cloned());
        for (i, m) in s.monitors.iter().enumerate() {
            self.expr(
                &Field::key("monitors").i(i).k("expr"),
                &m.expr,
                &monitor_scope,
            )?;
        }
        let eliminated = s.contact.as_ref().map(|c| c.eliminates.as_str());
        for c in &s.coordinates {
            if Some(c.name.as_str()) == eliminated {
                if s.initial.contains_key(&c.name) {
                    return Err(self.err(
                        &Field::key("initial").k(&c.name),
                        format!(
                            "`{}` starts where `gap = 0` puts it (the contact eliminates it); \
                             remove its initial value",
                            c.name
                        ),
                    ));
                }
                continue;
            }
            let Some(init) = s.initial.get(&c.name) else {
                return Err(self.err(
                    &Field::key("initial"),
                    format!(
                        "no initial position and velocity for coordinate `{}`",
                        c.name
                    ),
                ));
            };
            let f = Field::key("initial").k(&c.name);
            self.expr(&f.k("position"), &init.position, &only_params)?;
            self.expr(&f.k("velocity"), &init.velocity, &only_params)?;
        }
        if let Some(extra) = s.initial.keys().find(|k| !coords.contains(*k)) {
            return Err(self.err(
                &Field::key("initial").k(extra),
                format!("`{extra}` is not a coordinate"),
            ));
        }
        self.check_dimensionless(&only_params, &force_names, &mut seen)
    }

    /// Each group a new identifier and a monomial of the parameters that can be solved for
    /// one of them; the scales expressions of the parameters; the paper's equation numbers
    /// attached to results the model has.
    fn check_dimensionless(
        &self,
        params: &BTreeSet<String>,
        force_names: &BTreeSet<String>,
        seen: &mut BTreeSet<String>,
    ) -> Result<(), SpecError> {
        let Some(dim) = &self.spec.dimensionless else {
            return Ok(());
        };
        let field = Field::key("dimensionless");
        for (i, g) in dim.groups.iter().enumerate() {
            let f = field.k("groups").i(i);
            self.identifier(&f.k("name"), &g.name, seen)?;
            let e = self.expr(&f.k("expr"), &g.expr, params)?;
            if monomial(&e).is_none() {
                return Err(self.err(
                    &f.k("expr"),
                    format!(
                        "`{}` is not a product of powers of parameters with a positive \
                         coefficient (such as `m2/m1` or `k*ell/(m1*g)`)",
                        g.expr.text()
                    ),
                ));
            }
        }
        if let Err(i) = solved_parameters(&dim.groups) {
            return Err(self.err(
                &field.k("groups").i(i).k("expr"),
                format!(
                    "`{}` has no parameter to the first power that an earlier group was not \
                     solved for; each group is solved for one parameter (`m2 = n m1` from \
                     `n: m2/m1`)",
                    dim.groups[i].expr.text()
                ),
            ));
        }
        let scales = field.k("scales");
        self.expr(&scales.k("time"), &dim.scales.time, params)?;
        self.expr(&scales.k("force"), &dim.scales.force, params)?;
        for (key, label) in &dim.paper {
            let known = DIMENSIONLESS_RESULTS.contains(&key.as_str()) || force_names.contains(key);
            if !known {
                let mut names: Vec<&str> = DIMENSIONLESS_RESULTS.to_vec();
                names.extend(force_names.iter().map(String::as_str));
                return Err(self.err(
                    &field.k("paper").k(key),
                    format!(
                        "`{key}` is not a result of this model (one of: {})",
                        names.join(", ")
                    ),
                ));
            }
            if label.trim().is_empty() {
                return Err(self.err(
                    &field.k("paper").k(key),
                    "an equation number cannot be empty".into(),
                ));
            }
        }
        Ok(())
    }

    /// Each friction names a parameter as its coefficient, a force or the contact force as its
    /// normal force, bodies that exist (two different ones), a point and a unit tangent.
    fn check_friction(
        &self,
        params: &BTreeSet<String>,
        bodies: &BTreeSet<String>,
        force_names: &BTreeSet<String>,
        kinematic: &BTreeSet<String>,
    ) -> Result<(), SpecError> {
        for (i, f) in self.spec.friction.iter().enumerate() {
            let field = Field::key("friction").i(i);
            if !params.contains(&f.coefficient) {
                return Err(self.err(
                    &field.k("coefficient"),
                    format!(
                        "`{}` is not a parameter: a friction coefficient is a parameter of the \
                         model (declared `positive: false` if it may be zero)",
                        f.coefficient
                    ),
                ));
            }
            if !force_names.contains(&f.normal) {
                let known: Vec<&str> = force_names.iter().map(String::as_str).collect();
                return Err(self.err(
                    &field.k("normal"),
                    format!(
                        "`{}` is not a normal force of the model; friction is proportional to \
                         one of its forces or its contact force ({})",
                        f.normal,
                        if known.is_empty() {
                            "it has none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                ));
            }
            if !bodies.contains(&f.body) {
                return Err(self.err(
                    &field.k("body"),
                    format!("`{}` is not one of the bodies", f.body),
                ));
            }
            if let Some(other) = &f.against {
                if !bodies.contains(other) {
                    return Err(self.err(
                        &field.k("against"),
                        format!("`{other}` is not one of the bodies"),
                    ));
                }
                if *other == f.body {
                    return Err(self.err(
                        &field.k("against"),
                        format!("a body cannot rub against itself (`{other}`)"),
                    ));
                }
            }
            let p = field.k("point");
            self.expr(&p.i(0), &f.point[0], kinematic)?;
            self.expr(&p.i(1), &f.point[1], kinematic)?;
            let d = field.k("direction");
            self.expr(&d.i(0), &f.direction[0], kinematic)?;
            self.expr(&d.i(1), &f.direction[1], kinematic)?;
            if let (Text::Num(x), Text::Num(y)) = (&f.direction[0], &f.direction[1]) {
                self.unit(&d, [*x, *y])?;
            }
        }
        Ok(())
    }

    /// The bodies' shapes and the scenery, drawn in `motion.svg`.
    fn check_drawing(&self, params: &BTreeSet<String>) -> Result<(), SpecError> {
        for (i, b) in self.spec.bodies.iter().enumerate() {
            if let Some(shape) = &b.shape {
                self.shape(&Field::key("bodies").i(i).k("shape"), shape, params)?;
            }
        }
        for (i, shape) in self.spec.scenery.iter().enumerate() {
            self.shape(&Field::key("scenery").i(i), shape, params)?;
        }
        Ok(())
    }

    /// A shape has exactly one kind, `at` only with a rectangle or circle, and every size an
    /// expression of the parameters.
    fn shape(
        &self,
        field: &Field,
        shape: &ShapeSpec,
        params: &BTreeSet<String>,
    ) -> Result<(), SpecError> {
        let kinds = [
            ("segment", shape.segment.is_some()),
            ("rectangle", shape.rectangle.is_some()),
            ("circle", shape.circle.is_some()),
        ];
        let given: Vec<&str> = kinds.iter().filter(|k| k.1).map(|k| k.0).collect();
        if given.len() != 1 {
            return Err(self.err(
                field,
                format!(
                    "a shape is exactly one of `segment: [[x1, y1], [x2, y2]]`, \
                     `rectangle: [width, height]` or `circle: radius` (found {})",
                    if given.is_empty() {
                        "none".to_string()
                    } else {
                        given.join(" and ")
                    }
                ),
            ));
        }
        if let Some(ends) = &shape.segment {
            for (j, end) in ends.iter().enumerate() {
                let f = field.k("segment").i(j);
                self.expr(&f.i(0), &end[0], params)?;
                self.expr(&f.i(1), &end[1], params)?;
            }
            if shape.at.is_some() {
                return Err(self.err(
                    &field.k("at"),
                    "`at` places a rectangle or a circle; a segment gives its ends itself".into(),
                ));
            }
        }
        if let Some(size) = &shape.rectangle {
            let f = field.k("rectangle");
            self.expr(&f.i(0), &size[0], params)?;
            self.expr(&f.i(1), &size[1], params)?;
        }
        if let Some(radius) = &shape.circle {
            self.expr(&field.k("circle"), radius, params)?;
        }
        if let Some(at) = &shape.at {
            let f = field.k("at");
            self.expr(&f.i(0), &at[0], params)?;
            self.expr(&f.i(1), &at[1], params)?;
        }
        Ok(())
    }

    fn identifier(
        &self,
        field: &Field,
        name: &str,
        seen: &mut BTreeSet<String>,
    ) -> Result<(), SpecError> {
        if !is_identifier(name) {
            return Err(self.err(field, format!("`{name}` is not a plain identifier")));
        }
        if let Some(p) = RESERVED_PREFIXES.iter().find(|p| name.starts_with(*p)) {
            return Err(self.err(
                field,
                format!("`{name}`: names starting with `{p}` are reserved"),
            ));
        }
        if FUNCTIONS.iter().any(|(f, _)| *f == name) || name == "pi" {
            return Err(self.err(field, format!("`{name}` is the name of a function")));
        }
        if !seen.insert(name.to_string()) {
            return Err(self.err(field, format!("`{name}` is declared twice")));
        }
        Ok(())
    }

    fn unit(&self, field: &Field, v: [f64; 2]) -> Result<(), SpecError> {
        let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
        if !n.is_finite() || (n - 1.0).abs() > 1e-12 {
            return Err(self.err(field, format!("[{}, {}] is not a unit vector", v[0], v[1])));
        }
        Ok(())
    }

    fn expr(
        &self,
        field: &Field,
        text: &Text,
        scope: &BTreeSet<String>,
    ) -> Result<Expr, SpecError> {
        let src = text.text();
        let e = Expr::parse(&src).map_err(|e| {
            self.err(
                field,
                format!(
                    "cannot parse `{src}`: {} at character {}",
                    e.message,
                    e.offset + 1
                ),
            )
        })?;
        for (f, n) in e.functions() {
            match FUNCTIONS.iter().find(|(name, _)| *name == f) {
                None => return Err(self.err(field, format!("unknown function `{f}` in `{src}`"))),
                Some((_, arity)) if *arity != n => {
                    return Err(
                        self.err(field, format!("`{f}` takes {arity} argument(s) in `{src}`"))
                    );
                }
                _ => {}
            }
        }
        if let Some(sym) = e.symbols().into_iter().find(|s| !scope.contains(s)) {
            let allowed: Vec<&str> = scope.iter().map(String::as_str).collect();
            return Err(self.err(
                field,
                format!(
                    "undefined symbol `{sym}` in `{src}` (allowed here: {})",
                    allowed.join(", ")
                ),
            ));
        }
        Ok(e)
    }
}

/// Whether `s` is a plain ASCII identifier.
pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}
