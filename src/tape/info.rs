//! A tape's `info`: the model's [`ModelInfo`] as owned data read from JSON, checked for
//! consistency, and made `'static` once per distinct model (the runtime hands models out as
//! `&'static dyn Model`).

use crate::model::{
    ContactInfo, FrictionInfo, GapKind, ModelInfo, MonitorInfo, NamedInfo, ParamInfo, PhaseInfo,
    ReductionInfo, RequirementInfo, ShapeInfo, ShapeKind,
};
use crate::spec::is_identifier;
use crate::spec::units::AngularUnit;
use serde::{Deserialize, Serialize};

/// The most prepared constants a tape's model may have (a bound on what a caller allocates).
pub const MAX_CONSTANTS: usize = 1 << 20;

/// [`ModelInfo`] as owned data, field for field.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Info {
    pub name: String,
    pub description: String,
    pub spec: String,
    pub system: String,
    pub parameters: Vec<Param>,
    pub requirements: Vec<Requirement>,
    pub n_constants: usize,
    pub coordinates: Vec<String>,
    pub system_coordinates: Vec<String>,
    pub reduced_index: Option<usize>,
    pub cyclic: Vec<usize>,
    pub end_angle: Option<f64>,
    pub contacts: Vec<Contact>,
    pub frictions: Vec<Friction>,
    pub points: Vec<Named>,
    pub falling_point_index: Option<usize>,
    pub gravity_index: usize,
    pub monitors: Vec<Monitor>,
    pub bodies: Vec<String>,
    pub shapes: Vec<Shape>,
    pub start_params: bool,
    pub phases: Vec<Phase>,
    pub reduction: Option<Reduction>,
    pub route_note: String,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Param {
    pub name: String,
    pub meaning: String,
    pub unit: String,
    pub positive: bool,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Named {
    pub name: String,
    pub meaning: String,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Requirement {
    pub name: String,
    pub meaning: String,
    pub parameters: Vec<usize>,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Monitor {
    pub name: String,
    pub meaning: String,
    pub unit: String,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    pub name: String,
    pub meaning: String,
    pub gap: Gap,
    pub unit: String,
    pub bilateral: bool,
    pub edge: bool,
    pub eliminates: Option<String>,
    pub closed: bool,
    pub restitution: String,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    pub name: String,
    pub meaning: String,
    pub coefficient_index: usize,
    pub contact_index: usize,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Gap {
    Length,
    Angle,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Kind {
    Segment,
    Rectangle,
    Circle,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shape {
    pub kind: Kind,
    pub body: Option<usize>,
    pub first: usize,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    pub closed: Vec<usize>,
    pub model: String,
    pub release: bool,
    pub separation_degree: usize,
}

#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reduction {
    pub k_theta_initial: usize,
    pub k_theta_dot_initial: usize,
    pub k_sin_initial: usize,
    pub k_cos_initial: usize,
    pub force_degrees: Vec<usize>,
    /// Empty in a tape written before the field was: no push proven.
    #[serde(default)]
    pub pushes_proven: Vec<bool>,
    /// False in a tape written before the field was.
    #[serde(default)]
    pub release_push_proven: bool,
    pub fall_degree: Option<usize>,
    pub lean_constants: Vec<usize>,
}

impl Info {
    /// What is inconsistent in it, if anything: a model, system or parameter name that is not an
    /// identifier (programs find models and bind parameters by these names, and the C interface
    /// hands them out as C strings), a parameter named twice or with a unit that does not read
    /// as one, or an index past the list it points into.
    pub fn check(&self) -> Result<(), String> {
        for (what, name) in [("name", &self.name), ("system", &self.system)] {
            if !is_identifier(name) {
                return Err(format!("`{what}` is {name:?}, not an identifier"));
            }
        }
        for (i, p) in self.parameters.iter().enumerate() {
            if !is_identifier(&p.name) {
                return Err(format!(
                    "parameter {i} is named {:?}, not an identifier",
                    p.name
                ));
            }
            if self.parameters[..i].iter().any(|q| q.name == p.name) {
                return Err(format!("parameter `{}` is named twice", p.name));
            }
            if let Err(e) = AngularUnit::parse(&p.unit) {
                return Err(format!(
                    "parameter `{}` has the unit {:?}: {e}",
                    p.name, p.unit
                ));
            }
        }
        let n = self.coordinates.len();
        let within = |what: &str, i: usize, len: usize| {
            if i < len {
                Ok(())
            } else {
                Err(format!("`{what}` is {i}, past the {len} it indexes"))
            }
        };
        if n == 0 {
            return Err("`coordinates` is empty".into());
        }
        if let Some(r) = self.reduced_index {
            within("reduced_index", r, n)?;
        }
        for &c in &self.cyclic {
            within("cyclic", c, n)?;
        }
        within("gravity_index", self.gravity_index, self.parameters.len())?;
        if let Some(p) = self.falling_point_index {
            within("falling_point_index", p, self.points.len())?;
        }
        if self.end_angle.is_some() && self.reduced_index.is_none() {
            return Err("`end_angle` is given without a `reduced_index` it is a value of".into());
        }
        for r in &self.requirements {
            for &p in &r.parameters {
                within("requirements.parameters", p, self.parameters.len())?;
            }
        }
        for f in &self.frictions {
            within(
                "coefficient_index",
                f.coefficient_index,
                self.parameters.len(),
            )?;
            within("contact_index", f.contact_index, self.contacts.len())?;
        }
        for s in &self.shapes {
            if let Some(b) = s.body {
                within("shapes.body", b, self.bodies.len())?;
            }
        }
        for p in &self.phases {
            for &c in &p.closed {
                within("phases.closed", c, self.contacts.len())?;
            }
        }
        if self.n_constants > MAX_CONSTANTS {
            return Err(format!(
                "`n_constants` is {}, more than the {MAX_CONSTANTS} a tape may have",
                self.n_constants
            ));
        }
        if self.n_constants < self.parameters.len() {
            return Err(format!(
                "`n_constants` is {}, fewer than the {} parameters `k` starts with",
                self.n_constants,
                self.parameters.len()
            ));
        }
        if let Some(r) = &self.reduction {
            for (what, i) in [
                ("k_theta_initial", r.k_theta_initial),
                ("k_theta_dot_initial", r.k_theta_dot_initial),
                ("k_sin_initial", r.k_sin_initial),
                ("k_cos_initial", r.k_cos_initial),
            ] {
                within(what, i, self.n_constants)?;
            }
            for &i in &r.lean_constants {
                within("lean_constants", i, self.n_constants)?;
            }
            if r.force_degrees.len() != self.contacts.len() {
                return Err(format!(
                    "`force_degrees` has {} entries for {} contacts",
                    r.force_degrees.len(),
                    self.contacts.len()
                ));
            }
            if !r.pushes_proven.is_empty() && r.pushes_proven.len() != self.contacts.len() {
                return Err(format!(
                    "`pushes_proven` has {} entries for {} contacts",
                    r.pushes_proven.len(),
                    self.contacts.len()
                ));
            }
            if r.pushes_proven.first() == Some(&true) {
                return Err(
                    "`pushes_proven` proves the first contact's push, whose zero \
                            ends the phase"
                        .into(),
                );
            }
        }
        Ok(())
    }

    /// The `'static` [`ModelInfo`] it describes. Its strings and lists are leaked: callers
    /// make one per distinct model (the loader keeps them by digest).
    pub fn leak(&self) -> &'static ModelInfo {
        let s = |x: &str| -> &'static str { Box::leak(x.to_owned().into_boxed_str()) };
        fn list<T, U>(v: &[T], f: impl Fn(&T) -> U) -> &'static [U] {
            Box::leak(v.iter().map(f).collect::<Vec<U>>().into_boxed_slice())
        }
        let named = |n: &Named| NamedInfo {
            name: s(&n.name),
            meaning: s(&n.meaning),
        };
        let info = ModelInfo {
            name: s(&self.name),
            description: s(&self.description),
            spec: s(&self.spec),
            system: s(&self.system),
            parameters: list(&self.parameters, |p| ParamInfo {
                name: s(&p.name),
                meaning: s(&p.meaning),
                unit: s(&p.unit),
                positive: p.positive,
            }),
            requirements: list(&self.requirements, |r| RequirementInfo {
                name: s(&r.name),
                meaning: s(&r.meaning),
                parameters: list(&r.parameters, |&p| p),
            }),
            n_constants: self.n_constants,
            coordinates: list(&self.coordinates, |c| s(c)),
            system_coordinates: list(&self.system_coordinates, |c| s(c)),
            reduced_index: self.reduced_index,
            cyclic: list(&self.cyclic, |&c| c),
            end_angle: self.end_angle,
            contacts: list(&self.contacts, |c| ContactInfo {
                name: s(&c.name),
                meaning: s(&c.meaning),
                gap: match c.gap {
                    Gap::Length => GapKind::Length,
                    Gap::Angle => GapKind::Angle,
                },
                unit: s(&c.unit),
                bilateral: c.bilateral,
                edge: c.edge,
                eliminates: c.eliminates.as_deref().map(s),
                closed: c.closed,
                restitution: s(&c.restitution),
            }),
            frictions: list(&self.frictions, |f| FrictionInfo {
                name: s(&f.name),
                meaning: s(&f.meaning),
                coefficient_index: f.coefficient_index,
                contact_index: f.contact_index,
            }),
            points: list(&self.points, named),
            falling_point_index: self.falling_point_index,
            gravity_index: self.gravity_index,
            monitors: list(&self.monitors, |m| MonitorInfo {
                name: s(&m.name),
                meaning: s(&m.meaning),
                unit: s(&m.unit),
            }),
            bodies: list(&self.bodies, |b| s(b)),
            shapes: list(&self.shapes, |sh| ShapeInfo {
                kind: match sh.kind {
                    Kind::Segment => ShapeKind::Segment,
                    Kind::Rectangle => ShapeKind::Rectangle,
                    Kind::Circle => ShapeKind::Circle,
                },
                body: sh.body,
                first: sh.first,
            }),
            start_params: self.start_params,
            phases: list(&self.phases, |p| PhaseInfo {
                closed: list(&p.closed, |&c| c),
                model: s(&p.model),
                release: p.release,
                separation_degree: p.separation_degree,
            }),
            reduction: self.reduction.as_ref().map(|r| ReductionInfo {
                k_theta_initial: r.k_theta_initial,
                k_theta_dot_initial: r.k_theta_dot_initial,
                k_sin_initial: r.k_sin_initial,
                k_cos_initial: r.k_cos_initial,
                force_degrees: list(&r.force_degrees, |&d| d),
                pushes_proven: if r.pushes_proven.is_empty() {
                    list(&self.contacts, |_| false)
                } else {
                    list(&r.pushes_proven, |&b| b)
                },
                release_push_proven: r.release_push_proven,
                fall_degree: r.fall_degree,
                lean_constants: list(&r.lean_constants, |&c| c),
            }),
            route_note: s(&self.route_note),
        };
        Box::leak(Box::new(info))
    }
}
