//! The checker of a spec: every name declared once and a plain identifier, every reference to
//! something declared, every expression parsed over the symbols its field may use, and the
//! rules of contacts, friction, obstacles, shapes, initial values and dimensionless groups;
//! each error placed at its field. The units pass is in `dimensions.rs`.

mod dimensions;

use super::dimensionless::{DIMENSIONLESS_RESULTS, monomial, solved_parameters};
use super::error::SpecError;
use super::expr::{Expr, FUNCTIONS};
use super::schema::{ContactSpec, ShapeSpec, Spec, Text, obstacle_symbols};
use crate::yaml::{At, Document, Step};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Names the derivation uses internally; specs may not use them.
pub const RESERVED_PREFIXES: &[&str] = &["rc_", "dot_", "ddot_"];

/// Whether `s` is a plain ASCII identifier.
pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
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

pub(super) struct Checker<'a> {
    pub(super) path: &'a Path,
    pub(super) doc: &'a Document<'a>,
    pub(super) spec: &'a Spec,
}

/// A field path as both YAML steps and a dotted name.
#[derive(Clone)]
struct Field(Vec<Part>);

/// One step of a [`Field`]: a mapping key or a sequence index.
#[derive(Clone)]
enum Part {
    Key(String),
    Index(usize),
}

impl Field {
    fn key(k: &str) -> Field {
        Field(vec![Part::Key(k.to_string())])
    }
    fn k(&self, k: &str) -> Field {
        let mut v = self.0.clone();
        v.push(Part::Key(k.to_string()));
        Field(v)
    }
    fn i(&self, i: usize) -> Field {
        let mut v = self.0.clone();
        v.push(Part::Index(i));
        Field(v)
    }
    fn dotted(&self) -> String {
        let mut s = String::new();
        for part in &self.0 {
            match part {
                Part::Key(k) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                Part::Index(i) => s.push_str(&format!("[{i}]")),
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
            .map(|part| match part {
                Part::Key(k) => Step::Key(k.as_str()),
                Part::Index(i) => Step::Index(*i),
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

    pub(super) fn check(&self) -> Result<(), SpecError> {
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
        if let Some(r) = &s.reduced
            && !names.coords.contains(r)
        {
            return Err(self.err(&Field::key("reduced"), format!("`{r}` is not a coordinate")));
        }
        if let Some(p) = &s.falling_point
            && !names.points.contains(p)
        {
            return Err(self.err(
                &Field::key("falling_point"),
                format!("`{p}` is not one of the points"),
            ));
        }
        self.check_ends()
    }

    /// The motion's end needs what it is measured by: `end_angle` is a value of the `reduced`
    /// coordinate, and a landing there is told from a support holding the body up by the
    /// `falling_point`'s height; a fast phase (a contact that `eliminates` a coordinate) keeps
    /// the reduced coordinate and falls to the end angle.
    fn check_ends(&self) -> Result<(), SpecError> {
        let s = self.spec;
        if s.end_angle.is_some() {
            for (what, given) in [
                ("reduced", s.reduced.is_some()),
                ("falling_point", s.falling_point.is_some()),
            ] {
                if !given {
                    return Err(self.err(
                        &Field::key("end_angle"),
                        format!("an `end_angle` needs `{what}` too"),
                    ));
                }
            }
        }
        if let Some(i) = s.contacts.iter().position(|c| c.eliminates.is_some())
            && (s.reduced.is_none() || s.end_angle.is_none())
        {
            return Err(self.err(
                &Field::key("contacts").i(i).k("eliminates"),
                "a contact that eliminates a coordinate gives a fast phase, which keeps the                  `reduced` coordinate and falls to the `end_angle`: give both"
                    .into(),
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
                if s.reduced.as_ref() == Some(e) {
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
                    // `j` is an earlier `i` of this loop over `s.contacts`: in range.
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
            // `i` is the index of one of `dim.groups` (see `solved_parameters`): in range.
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
            if let (Some(x), Some(y)) = (f.direction[0].number(), f.direction[1].number()) {
                self.unit(&d, [x, y])?;
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
        if FUNCTIONS.iter().any(|(f, _)| *f == name) {
            return Err(self.err(field, format!("`{name}` is the name of a function")));
        }
        if name == super::expr::PI {
            return Err(self.err(field, format!("`{name}` is the constant 3.14159...")));
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
