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
use units::{Unit, conjugate_force_unit, expect_unit, unit_of};

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
    /// Each contact's gap unit and its force's unit (conjugate to the gap), in the spec's
    /// order.
    pub units: Vec<(String, String)>,
}

impl Checked {
    /// The gap unit and force unit of contact `j` (`("m", "N")`); empty strings for an index
    /// out of range.
    pub fn contact_units(&self, j: usize) -> (String, String) {
        self.units.get(j).cloned().unwrap_or_default()
    }
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
    let units = checker.contact_units()?;
    Ok(Checked {
        spec,
        file: path.to_path_buf(),
        units,
    })
}

/// The names a spec declares, by kind, and the scopes they make.
#[derive(Default)]
struct Names {
    /// Parameters, coordinates, obstacle symbols and contacts: one namespace of symbols.
    symbols: BTreeSet<String>,
    params: BTreeSet<String>,
    coords: BTreeSet<String>,
    obstacles: BTreeSet<String>,
    obstacle_symbols: BTreeSet<String>,
    contacts: BTreeSet<String>,
    bodies: BTreeSet<String>,
    points: BTreeSet<String>,
    /// Parameters, coordinates and obstacle symbols: what a position may depend on.
    kinematic: BTreeSet<String>,
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

/// Every expression of a shape with its field.
fn shape_texts<'s>(field: &Field, shape: &'s ShapeSpec) -> Vec<(Field, &'s Text)> {
    let mut out = Vec::new();
    if let Some(ends) = &shape.segment {
        for (j, end) in ends.iter().enumerate() {
            let f = field.k("segment").i(j);
            out.push((f.i(0), &end[0]));
            out.push((f.i(1), &end[1]));
        }
    }
    if let Some([w, h]) = &shape.rectangle {
        out.push((field.k("rectangle").i(0), w));
        out.push((field.k("rectangle").i(1), h));
    }
    if let Some(r) = &shape.circle {
        out.push((field.k("circle"), r));
    }
    if let Some([x, y]) = &shape.at {
        out.push((field.k("at").i(0), x));
        out.push((field.k("at").i(1), y));
    }
    out
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
        let names = self.check_names()?;
        self.check_references(&names)?;
        self.check_kinematics(&names)?;
        self.check_obstacles(&names)?;
        self.check_contacts(&names)?;
        self.check_friction(&names)?;
        self.check_drawing(&names.params)?;
        self.check_monitors(&names)?;
        self.check_initial(&names)?;
        let mut seen = names.symbols.clone();
        self.check_dimensionless(&names.params, &names.contacts, &mut seen)
    }

    /// Every name a plain identifier, declared once; the retired fields named with what
    /// replaced them.
    fn check_names(&self) -> Result<Names, SpecError> {
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
        let retired = [
            (
                s.forces.is_some(),
                "forces",
                "reaction forces projected by hand are retired: make each support a contact \
                 (`contacts:`, a gap that is zero while touching), whose force is its Lagrange \
                 multiplier",
            ),
            (
                s.contact.is_some(),
                "contact",
                "`contact:` is now `contacts:`, a list; its `force:` is the contact's `name:`",
            ),
            (
                s.scenery.is_some(),
                "scenery",
                "`scenery:` is now `obstacles:`, each with a `name`, a `meaning`, its place `at` \
                 and a `shape`",
            ),
        ];
        if let Some((_, key, why)) = retired.iter().find(|r| r.0) {
            return Err(self.err(&Field::key(key), (*why).to_string()));
        }
        let mut names = Names::default();
        let named = |list: &str, i: usize| Field::key(list).i(i).k("name");
        for (i, p) in s.parameters.iter().enumerate() {
            self.identifier(&named("parameters", i), &p.name, &mut names.symbols)?;
            names.params.insert(p.name.clone());
        }
        for (i, c) in s.coordinates.iter().enumerate() {
            self.identifier(&named("coordinates", i), &c.name, &mut names.symbols)?;
            names.coords.insert(c.name.clone());
        }
        for (i, o) in s.obstacles.iter().enumerate() {
            self.identifier(&named("obstacles", i), &o.name, &mut names.obstacles)?;
            for (symbol, _) in obstacle_symbols(o) {
                self.identifier(&named("obstacles", i), &symbol, &mut names.symbols)?;
                names.obstacle_symbols.insert(symbol);
            }
        }
        for (i, c) in s.contacts.iter().enumerate() {
            self.identifier(&named("contacts", i), &c.name, &mut names.symbols)?;
            names.contacts.insert(c.name.clone());
        }
        let mut others = BTreeSet::new();
        for (i, b) in s.bodies.iter().enumerate() {
            self.identifier(&named("bodies", i), &b.name, &mut names.bodies)?;
        }
        for (i, p) in s.points.iter().enumerate() {
            self.identifier(&named("points", i), &p.name, &mut names.points)?;
        }
        for (i, p) in s.potentials.iter().enumerate() {
            self.identifier(&named("potentials", i), &p.name, &mut others)?;
        }
        // Friction forces are result keys beside the contacts' forces: one namespace.
        let mut results = names.symbols.clone();
        for (i, f) in s.friction.iter().enumerate() {
            self.identifier(&named("friction", i), &f.name, &mut results)?;
        }
        let mut monitor_names = BTreeSet::new();
        for (i, m) in s.monitors.iter().enumerate() {
            self.identifier(&named("monitors", i), &m.name, &mut monitor_names)?;
        }
        let mut req_names = BTreeSet::new();
        for (i, r) in s.requirements.iter().enumerate() {
            self.identifier(&named("requirements", i), &r.name, &mut req_names)?;
        }
        names.kinematic = names.params.clone();
        names.kinematic.extend(names.coords.iter().cloned());
        names
            .kinematic
            .extend(names.obstacle_symbols.iter().cloned());
        Ok(names)
    }

    /// `gravity`, `reduced` and `falling_point` name what they should; there is a body.
    fn check_references(&self, names: &Names) -> Result<(), SpecError> {
        let s = self.spec;
        if s.bodies.is_empty() {
            return Err(self.err(
                &Field::key("bodies"),
                "a model needs at least one body".into(),
            ));
        }
        if !names.params.contains(&s.gravity) {
            return Err(self.err(
                &Field::key("gravity"),
                format!("`{}` is not a parameter", s.gravity),
            ));
        }
        if !names.coords.contains(&s.reduced) {
            return Err(self.err(
                &Field::key("reduced"),
                format!("`{}` is not a coordinate", s.reduced),
            ));
        }
        if !names.points.contains(&s.falling_point) {
            return Err(self.err(
                &Field::key("falling_point"),
                format!("`{}` is not one of the points", s.falling_point),
            ));
        }
        Ok(())
    }

    /// Requirements over the parameters; bodies, points and potentials over the state.
    fn check_kinematics(&self, names: &Names) -> Result<(), SpecError> {
        let s = self.spec;
        for (i, r) in s.requirements.iter().enumerate() {
            let f = Field::key("requirements").i(i).k("expr");
            self.expr(&f, &r.expr, &names.params)?;
        }
        for (i, b) in s.bodies.iter().enumerate() {
            let f = Field::key("bodies").i(i);
            self.expr(&f.k("mass"), &b.mass, &names.params)?;
            self.expr(&f.k("inertia"), &b.inertia, &names.params)?;
            self.expr(&f.k("position").i(0), &b.position[0], &names.kinematic)?;
            self.expr(&f.k("position").i(1), &b.position[1], &names.kinematic)?;
            self.expr(&f.k("angle"), &b.angle, &names.kinematic)?;
        }
        for (i, p) in s.points.iter().enumerate() {
            let f = Field::key("points").i(i).k("position");
            self.expr(&f.i(0), &p.position[0], &names.kinematic)?;
            self.expr(&f.i(1), &p.position[1], &names.kinematic)?;
        }
        for (i, p) in s.potentials.iter().enumerate() {
            let f = Field::key("potentials").i(i).k("expr");
            self.expr(&f, &p.expr, &names.kinematic)?;
        }
        Ok(())
    }

    /// The unit of every parameter, coordinate and obstacle symbol; a unit string that does
    /// not parse is an error at its field.
    fn symbol_units(&self) -> Result<BTreeMap<String, Unit>, SpecError> {
        let s = self.spec;
        let mut out = BTreeMap::new();
        let parameters = s.parameters.iter().map(|p| (&p.name, &p.unit));
        let coordinates = s.coordinates.iter().map(|c| (&c.name, &c.unit));
        let declared = (parameters.enumerate().map(|(i, e)| ("parameters", i, e)))
            .chain(coordinates.enumerate().map(|(i, e)| ("coordinates", i, e)));
        for (list, i, (name, unit)) in declared {
            let u = Unit::parse(unit).map_err(|e| {
                self.err(
                    &Field::key(list).i(i).k("unit"),
                    format!("the unit `{unit}` of `{name}`: {e}"),
                )
            })?;
            out.insert(name.clone(), u);
        }
        let params: BTreeSet<String> = s.parameters.iter().map(|p| p.name.clone()).collect();
        for (i, o) in s.obstacles.iter().enumerate() {
            for (symbol, text) in obstacle_symbols(o) {
                let field = Field::key("obstacles").i(i);
                let e = self.expr(&field, &text, &params)?;
                // Every obstacle symbol is a length: a place or a size.
                let lookup = |n: &str| out.get(n).copied();
                expect_unit(&e, &lookup, Unit::METRE).map_err(|err| {
                    self.err(&field, format!("`{symbol}` = `{}`: {err}", text.text()))
                })?;
                out.insert(symbol, Unit::METRE);
            }
        }
        Ok(out)
    }

    /// The units the mechanics needs: bodies' masses in kg, inertias in kg m^2, positions in
    /// m, potentials in J, and every contact's gap in one unit, whose force is conjugate to it
    /// (N for a gap in metres, N m for one in radians). Returns each contact's gap and force
    /// unit, as printed.
    fn contact_units(&self) -> Result<Vec<(String, String)>, SpecError> {
        let s = self.spec;
        let units = self.symbol_units()?;
        let lookup = |n: &str| units.get(n).copied();
        let expect = |field: Field, text: &Text, unit: Unit, what: &str| {
            let e = Expr::parse(&text.text()).map_err(|e| {
                self.err(
                    &field,
                    format!("cannot parse `{}`: {}", text.text(), e.message),
                )
            })?;
            expect_unit(&e, &lookup, unit)
                .map_err(|err| self.err(&field, format!("{what} must be in {unit}: {err}")))
        };
        let kg_m2 = Unit::KILOGRAM
            .checked_mul(Unit::METRE)
            .and_then(|u| u.checked_mul(Unit::METRE))
            .map_err(|e| self.err(&Field::key("bodies"), e.to_string()))?;
        for (i, b) in s.bodies.iter().enumerate() {
            let f = Field::key("bodies").i(i);
            expect(f.k("mass"), &b.mass, Unit::KILOGRAM, "a mass")?;
            expect(f.k("inertia"), &b.inertia, kg_m2, "a moment of inertia")?;
            expect(
                f.k("position").i(0),
                &b.position[0],
                Unit::METRE,
                "a position",
            )?;
            expect(
                f.k("position").i(1),
                &b.position[1],
                Unit::METRE,
                "a position",
            )?;
            expect(f.k("angle"), &b.angle, Unit::DIMENSIONLESS, "an angle")?;
        }
        for (i, p) in s.potentials.iter().enumerate() {
            let f = Field::key("potentials").i(i).k("expr");
            expect(f, &p.expr, Unit::JOULE, "a potential energy")?;
        }
        let mut out = Vec::new();
        for (i, c) in s.contacts.iter().enumerate() {
            let field = Field::key("contacts").i(i);
            let gap = Expr::parse(&c.gap.text()).map_err(|e| {
                self.err(
                    &field.k("gap"),
                    format!("cannot parse `{}`: {}", c.gap.text(), e.message),
                )
            })?;
            let gap_unit = unit_of(&gap, &lookup).map_err(|err| {
                self.err(
                    &field.k("gap"),
                    format!(
                        "the gap of contact `{}` has no consistent unit: {err}",
                        c.name
                    ),
                )
            })?;
            let force_unit = conjugate_force_unit(gap_unit)
                .map_err(|err| self.err(&field.k("gap"), format!("contact `{}`: {err}", c.name)))?;
            if let Some(edge) = &c.edge
                && let Ok(e) = Expr::parse(&edge.text())
                && let Err(err) = unit_of(&e, &lookup)
            {
                return Err(self.err(
                    &field.k("edge"),
                    format!(
                        "the edge of contact `{}` has no consistent unit: {err}",
                        c.name
                    ),
                ));
            }
            if let Some(e) = &c.restitution {
                expect(
                    field.k("restitution"),
                    e,
                    Unit::DIMENSIONLESS,
                    "a coefficient of restitution",
                )?;
            }
            // A torque and an energy are both kg m^2 s^-2: a multiplier is a torque.
            let force = if force_unit == Unit::JOULE {
                "N m".to_string()
            } else {
                force_unit.to_string()
            };
            out.push((gap_unit.to_string(), force));
        }
        Ok(out)
    }

    /// An obstacle is fixed: its place and shape depend on the parameters only.
    fn check_obstacles(&self, names: &Names) -> Result<(), SpecError> {
        for (i, o) in self.spec.obstacles.iter().enumerate() {
            let f = Field::key("obstacles").i(i);
            let mut texts: Vec<(Field, &Text)> =
                vec![(f.k("at").i(0), &o.at[0]), (f.k("at").i(1), &o.at[1])];
            texts.extend(shape_texts(&f.k("shape"), &o.shape));
            for (field, text) in texts {
                if let Ok(e) = Expr::parse(&text.text())
                    && let Some(c) = e.symbols().iter().find(|s| names.coords.contains(*s))
                {
                    return Err(self.err(
                        &field,
                        format!(
                            "obstacle `{}` is fixed: its place and shape may depend on the \
                             parameters only, not on the coordinate `{c}` (a body that moves \
                             is one of `bodies`)",
                            o.name
                        ),
                    ));
                }
                self.expr(&field, text, &names.params)?;
            }
            self.shape(&f.k("shape"), &o.shape, &names.params)?;
        }
        Ok(())
    }

    /// Each contact: a gap of the state that depends on a coordinate, the coordinate it may
    /// eliminate (each at most once, never the reduced one), an edge only on a unilateral one.
    fn check_contacts(&self, names: &Names) -> Result<(), SpecError> {
        let s = self.spec;
        let mut eliminated: BTreeMap<&str, usize> = BTreeMap::new();
        for (i, c) in s.contacts.iter().enumerate() {
            let field = Field::key("contacts").i(i);
            let gap = self.expr(&field.k("gap"), &c.gap, &names.kinematic)?;
            let symbols = gap.symbols();
            if !symbols.iter().any(|x| names.coords.contains(x)) {
                return Err(self.err(
                    &field.k("gap"),
                    format!(
                        "the gap `{}` of contact `{}` depends on no coordinate, so nothing can \
                         open or close it",
                        c.gap.text(),
                        c.name
                    ),
                ));
            }
            if let Some(e) = &c.eliminates {
                let f = field.k("eliminates");
                if !names.coords.contains(e) {
                    return Err(self.err(&f, format!("`{e}` is not a coordinate")));
                }
                if *e == s.reduced {
                    return Err(self.err(
                        &f,
                        format!(
                            "`{e}` is the reduced coordinate, which the motion is reported in; \
                             eliminate another one"
                        ),
                    ));
                }
                if !symbols.contains(e) {
                    return Err(self.err(
                        &f,
                        format!("the gap `{}` does not depend on `{e}`", c.gap.text()),
                    ));
                }
                if let Some(j) = eliminated.insert(e, i) {
                    return Err(self.err(
                        &f,
                        format!(
                            "`{e}` is already eliminated by contact `{}`",
                            s.contacts[j].name
                        ),
                    ));
                }
            }
            if let Some(edge) = &c.edge {
                if c.bilateral {
                    return Err(self.err(
                        &field.k("edge"),
                        "a bilateral contact never ends, so it has no edge".into(),
                    ));
                }
                self.expr(&field.k("edge"), edge, &names.kinematic)?;
            }
            if let Some(e) = &c.restitution {
                self.restitution(&field.k("restitution"), c, e, names)?;
            }
        }
        Ok(())
    }

    /// A contact's restitution: not on a bilateral contact, an expression of the parameters,
    /// and a number in `[0, 1]` where it is one (an expression is checked when the parameters
    /// are bound).
    fn restitution(
        &self,
        field: &Field,
        c: &ContactSpec,
        e: &Text,
        names: &Names,
    ) -> Result<(), SpecError> {
        if c.bilateral {
            return Err(self.err(
                field,
                "a bilateral contact never closes on an approach, so it has no restitution".into(),
            ));
        }
        let expr = self.expr(field, e, &names.params)?;
        if expr.symbols().is_empty() {
            let value = expr.eval(&|_| None);
            if !(0.0..=1.0).contains(&value) {
                return Err(self.err(
                    field,
                    format!(
                        "the restitution of contact `{}` is {value}, outside [0, 1] (0: the \
                         bodies stay together, 1: no energy is lost)",
                        c.name
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Monitors over the state, the parameters and the contacts' forces.
    fn check_monitors(&self, names: &Names) -> Result<(), SpecError> {
        let mut scope = names.kinematic.clone();
        scope.extend(names.contacts.iter().cloned());
        for (i, m) in self.spec.monitors.iter().enumerate() {
            self.expr(&Field::key("monitors").i(i).k("expr"), &m.expr, &scope)?;
        }
        Ok(())
    }

    /// An initial position and velocity for every coordinate but those a contact eliminates
    /// (they start where `gap = 0` puts them), over the parameters.
    fn check_initial(&self, names: &Names) -> Result<(), SpecError> {
        let s = self.spec;
        let eliminated: BTreeMap<&str, &str> = (s.contacts.iter())
            .filter_map(|c| c.eliminates.as_deref().map(|e| (e, c.name.as_str())))
            .collect();
        for c in &s.coordinates {
            if let Some(contact) = eliminated.get(c.name.as_str()) {
                if s.initial.contains_key(&c.name) {
                    return Err(self.err(
                        &Field::key("initial").k(&c.name),
                        format!(
                            "`{}` starts where `gap = 0` puts it (contact `{contact}` \
                             eliminates it); remove its initial value",
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
            self.expr(&f.k("position"), &init.position, &names.params)?;
            self.expr(&f.k("velocity"), &init.velocity, &names.params)?;
        }
        if let Some(extra) = s.initial.keys().find(|k| !names.coords.contains(*k)) {
            return Err(self.err(
                &Field::key("initial").k(extra),
                format!("`{extra}` is not a coordinate"),
            ));
        }
        Ok(())
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

    /// Each friction names a parameter as its coefficient, a unilateral contact whose force
    /// is its normal force, bodies that exist (two different ones), a point and a unit tangent.
    fn check_friction(&self, names: &Names) -> Result<(), SpecError> {
        let s = self.spec;
        for (i, f) in s.friction.iter().enumerate() {
            let field = Field::key("friction").i(i);
            if !names.params.contains(&f.coefficient) {
                return Err(self.err(
                    &field.k("coefficient"),
                    format!(
                        "`{}` is not a parameter: a friction coefficient is a parameter of the \
                         model (declared `positive: false` if it may be zero)",
                        f.coefficient
                    ),
                ));
            }
            match s.contacts.iter().find(|c| c.name == f.contact) {
                None => {
                    let known: Vec<&str> = s.contacts.iter().map(|c| c.name.as_str()).collect();
                    return Err(self.err(
                        &field.k("contact"),
                        format!(
                            "there is no contact `{}`: friction acts at one of the contacts ({})",
                            f.contact,
                            if known.is_empty() {
                                "the model has none".to_string()
                            } else {
                                known.join(", ")
                            }
                        ),
                    ));
                }
                Some(c) if c.bilateral => {
                    return Err(self.err(
                        &field.k("contact"),
                        format!(
                            "contact `{}` is bilateral: Coulomb friction needs a normal force \
                             that pushes",
                            c.name
                        ),
                    ));
                }
                Some(_) => {}
            }
            if !names.bodies.contains(&f.body) {
                return Err(self.err(
                    &field.k("body"),
                    format!("`{}` is not one of the bodies", f.body),
                ));
            }
            if let Some(other) = &f.against {
                if !names.bodies.contains(other) {
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
            self.expr(&p.i(0), &f.point[0], &names.kinematic)?;
            self.expr(&p.i(1), &f.point[1], &names.kinematic)?;
            let d = field.k("direction");
            self.expr(&d.i(0), &f.direction[0], &names.kinematic)?;
            self.expr(&d.i(1), &f.direction[1], &names.kinematic)?;
            if let (Text::Num(x), Text::Num(y)) = (&f.direction[0], &f.direction[1]) {
                self.unit(&d, [*x, *y])?;
            }
        }
        Ok(())
    }

    /// The bodies' shapes, drawn in `motion.svg` (the obstacles' are checked with them).
    fn check_drawing(&self, params: &BTreeSet<String>) -> Result<(), SpecError> {
        for (i, b) in self.spec.bodies.iter().enumerate() {
            if let Some(shape) = &b.shape {
                self.shape(&Field::key("bodies").i(i).k("shape"), shape, params)?;
            }
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
