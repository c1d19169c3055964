//! The vocabulary of quantities a scene can ask for (`want:`), resolved against a model.

use crate::model::ModelInfo;

/// One quantity a scene can want. Force series and trajectories are named after the system's
/// contacts, frictions and points, so every model gets the quantities its spec declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Quantity {
    /// Angle at which the first contact's force vanishes (rad).
    SeparationAngle,
    /// The paper's approximation: the separation polynomial with its terms above degree 1 dropped.
    LinearisedSeparationAngle,
    /// Time from release to separation (s), eq. (15).
    SeparationTime,
    /// When, at which angle and why (`force`, `edge` or `contact`) each contact ends.
    ContactEnd,
    /// Time to the floor if the rod stayed in contact all the way (s), eq. (10).
    ContactTimeToFloor,
    /// Free-fall time of a point mass from the initial height of the falling centre of mass (s).
    PointMassFallTime,
    /// `t, theta, theta_dot, theta_ddot` from release to separation (or to the floor).
    ThetaSeries,
    /// A contact's force (index into `ModelInfo::contacts`) along the motion:
    /// `<contact>_series`.
    ForceSeries(usize),
    /// A friction (index into `ModelInfo::frictions`) along the motion, with its normal force
    /// and slip velocity: `<friction>_series`.
    FrictionSeries(usize),
    /// A point's path (index into `ModelInfo::points`): `<point>_trajectory`.
    Trajectory(usize),
    /// The motion after separation, phase after phase, up to the rod lying on the floor.
    FloorImpact,
    /// Every impact of the motion: times, contacts, normal velocities, impulses, energy lost.
    Impacts,
    /// The physical assumptions and conservation laws, each pass/fail with its margin.
    Checks,
    /// Integration of the general model's equations, the contacts as constraints, to the
    /// fast path's first event.
    CrossCheck,
    /// `d(<result>)/d(<parameter>)` and the elasticities of the wanted separation angle and
    /// time and contact ends, where the fast path gives them.
    Sensitivities,
}

/// Quantity names that do not depend on the model, with their meaning.
pub const FIXED: &[(&str, Quantity, &str)] = &[
    (
        "separation_angle",
        Quantity::SeparationAngle,
        "value of the reduced coordinate where the contact force vanishes (rad)",
    ),
    (
        "linearised_separation_angle",
        Quantity::LinearisedSeparationAngle,
        "separation angle with the polynomial's terms above degree 1 dropped (rad)",
    ),
    (
        "separation_time",
        Quantity::SeparationTime,
        "time from release to separation (s)",
    ),
    (
        "contact_end",
        Quantity::ContactEnd,
        "when, at which angle and why each contact ends (force, edge or contact)",
    ),
    (
        "contact_time_to_floor",
        Quantity::ContactTimeToFloor,
        "time to the end of the motion if the contact held all the way (s)",
    ),
    (
        "point_mass_fall_time",
        Quantity::PointMassFallTime,
        "free fall of a point mass from the initial height of the centre of mass (s)",
    ),
    (
        "theta_series",
        Quantity::ThetaSeries,
        "t, theta, theta_dot, theta_ddot until separation",
    ),
    (
        "floor_impact",
        Quantity::FloorImpact,
        "the motion after separation, to the floor",
    ),
    (
        "impacts",
        Quantity::Impacts,
        "every impact: time, contacts, normal velocities before and after, impulses, energy lost",
    ),
    (
        "checks",
        Quantity::Checks,
        "physical assumptions and conservation checks",
    ),
    (
        "cross_check",
        Quantity::CrossCheck,
        "the general model's equations integrated to the fast path's first event",
    ),
    (
        "sensitivities",
        Quantity::Sensitivities,
        "d(result)/d(parameter) and elasticities of the wanted separation angle and time, \
         contact ends and floor impact, for every parameter",
    ),
];

/// A scalar result a quantity gives (in `RunResults::results`): its key, its unit, and the key
/// of the note that says why it has no value where it has none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScalarKey {
    /// The result's key (`contact_end_time`), as in results.json and the sweep's CSV.
    pub key: String,
    /// Its SI unit (`s`, `rad`, `J`, `1`).
    pub unit: &'static str,
    /// The key under `RunResults::notes` that explains its absence (`contact_end`).
    pub note: String,
    /// Whether it is one contact's detail (`<contact>_end_time`) rather than the quantity's
    /// own result: where it has none (a floor contact that holds to the end) the quantity
    /// still has its value.
    pub per_contact: bool,
}

/// A `want` entry that names no quantity of the model.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown quantity `{name}` for model `{model}`; it offers: {}", offers.join(", "))]
pub struct UnknownQuantity {
    /// The entry.
    pub name: String,
    /// The model it was asked of.
    pub model: &'static str,
    /// Every quantity the model offers, in a stable order.
    pub offers: Vec<String>,
}

impl Quantity {
    /// Whether the quantity samples the motion between the integrator's steps (series,
    /// trajectories and the drawing made from them, the checks at the samples): the run then
    /// keeps every integrated step's continuous extension, which DOP853 pays with three more
    /// evaluations a step. Every variant is listed, so that a new one must say.
    pub fn samples_motion(&self) -> bool {
        match self {
            Quantity::ThetaSeries
            | Quantity::ForceSeries(_)
            | Quantity::FrictionSeries(_)
            | Quantity::Trajectory(_)
            | Quantity::Checks => true,
            Quantity::SeparationAngle
            | Quantity::LinearisedSeparationAngle
            | Quantity::SeparationTime
            | Quantity::ContactEnd
            | Quantity::ContactTimeToFloor
            | Quantity::PointMassFallTime
            | Quantity::FloorImpact
            | Quantity::Impacts
            | Quantity::CrossCheck
            | Quantity::Sensitivities => false,
        }
    }

    /// Resolves a `want` entry for a model; the error lists what the model offers.
    pub fn parse(name: &str, info: &ModelInfo) -> Result<Quantity, UnknownQuantity> {
        if let Some((_, q, _)) = FIXED.iter().find(|(n, _, _)| *n == name) {
            return Ok(*q);
        }
        if let Some(force) = name.strip_suffix("_series")
            && let Some(i) = info.contacts.iter().position(|c| c.name == force)
        {
            return Ok(Quantity::ForceSeries(i));
        }
        if let Some(friction) = name.strip_suffix("_series")
            && let Some(i) = info.frictions.iter().position(|f| f.name == friction)
        {
            return Ok(Quantity::FrictionSeries(i));
        }
        if let Some(point) = name.strip_suffix("_trajectory")
            && let Some(i) = info.points.iter().position(|p| p.name == point)
        {
            return Ok(Quantity::Trajectory(i));
        }
        Err(UnknownQuantity {
            name: name.to_string(),
            model: info.name,
            offers: Quantity::names(info),
        })
    }

    /// The key of this quantity in scenes and results. An index the model does not have is
    /// named for error messages (`force #7_series`); [`Quantity::available`] refuses it.
    pub fn name(&self, info: &ModelInfo) -> String {
        let named = |names: Option<&'static str>, what: &str, i: usize| {
            names.map_or_else(|| format!("{what} #{i}"), str::to_string)
        };
        match self {
            Quantity::ForceSeries(i) => {
                let force = named(info.contacts.get(*i).map(|c| c.name), "contact", *i);
                format!("{force}_series")
            }
            Quantity::FrictionSeries(i) => {
                let friction = named(info.frictions.get(*i).map(|f| f.name), "friction", *i);
                format!("{friction}_series")
            }
            Quantity::Trajectory(i) => {
                let point = named(info.points.get(*i).map(|p| p.name), "point", *i);
                format!("{point}_trajectory")
            }
            q => q.fixed_name().unwrap_or("unnamed").to_string(),
        }
    }

    /// The key of a quantity that does not depend on the model (`None` for the indexed ones).
    pub fn fixed_name(&self) -> Option<&'static str> {
        FIXED.iter().find(|(_, f, _)| f == self).map(|(n, _, _)| *n)
    }

    /// Every quantity name a model offers, in a stable order.
    pub fn names(info: &ModelInfo) -> Vec<String> {
        Quantity::all(info).iter().map(|q| q.name(info)).collect()
    }

    /// Every quantity a model can provide.
    pub fn all(info: &ModelInfo) -> Vec<Quantity> {
        let mut out: Vec<Quantity> = FIXED
            .iter()
            .map(|(_, q, _)| *q)
            .filter(|q| q.available(info))
            .collect();
        out.extend((0..info.contacts.len()).map(Quantity::ForceSeries));
        out.extend((0..info.frictions.len()).map(Quantity::FrictionSeries));
        out.extend((0..info.points.len()).map(Quantity::Trajectory));
        out
    }

    /// The scalar results the planner gives for this quantity of a model, whatever the
    /// parameters, the quantity's own first: where one has no value at a point, its `note`
    /// explains why. Empty for the quantities that are no numbers (series, checks, impacts,
    /// sensitivities). The planner writes these keys (`plan::quantities`); the tests of
    /// `sweep::planned` hold the two together on every shipped scene.
    pub fn scalar_keys(&self, info: &ModelInfo) -> Vec<ScalarKey> {
        let key = |key: String, unit: &'static str, note: &str| ScalarKey {
            key,
            unit,
            note: note.to_string(),
            per_contact: false,
        };
        let own = |unit| vec![key(self.name(info), unit, &self.name(info))];
        let friction = !info.frictions.is_empty();
        match self {
            Quantity::SeparationAngle | Quantity::LinearisedSeparationAngle => own("rad"),
            Quantity::SeparationTime
            | Quantity::ContactTimeToFloor
            | Quantity::PointMassFallTime => own("s"),
            Quantity::ContactEnd => {
                let names = std::iter::once(("contact_end".to_string(), false))
                    .chain((info.contacts.iter()).map(|c| (format!("{}_end", c.name), true)));
                let mut out: Vec<ScalarKey> = names
                    .flat_map(|(n, per_contact)| {
                        [(format!("{n}_time"), "s"), (format!("{n}_angle"), "rad")].map(
                            |(k, unit)| ScalarKey {
                                per_contact,
                                ..key(k, unit, &n)
                            },
                        )
                    })
                    .collect();
                if friction {
                    out.push(key("contact_end_friction_work".into(), "J", "contact_end"));
                }
                out
            }
            Quantity::FloorImpact => {
                let mut out = vec![
                    key("floor_impact_time".into(), "s", "floor_impact"),
                    key("impact_angular_velocity".into(), "rad/s", "floor_impact"),
                ];
                if friction {
                    out.push(key(
                        "floor_impact_friction_work".into(),
                        "J",
                        "floor_impact",
                    ));
                }
                out
            }
            Quantity::CrossCheck => [
                ("cross_check_time", "s"),
                ("cross_check_relative_difference", "1"),
                ("cross_check_rtol", "1"),
                ("cross_check_time_deviation", "s"),
                ("cross_check_state_deviation", "1"),
            ]
            .into_iter()
            .map(|(k, unit)| key(k.into(), unit, "cross_check"))
            .collect(),
            Quantity::ThetaSeries
            | Quantity::ForceSeries(_)
            | Quantity::FrictionSeries(_)
            | Quantity::Trajectory(_)
            | Quantity::Impacts
            | Quantity::Checks
            | Quantity::Sensitivities => Vec::new(),
        }
    }

    /// Whether a model can provide this quantity: the separation needs a unilateral first
    /// contact, the contacts' ends a contact, the quantities of the energy integral (the time
    /// to the floor in contact, the cross-check against the quadrature) a fast phase that
    /// starts at release, the linearised angle one with a separation polynomial, the impacts a
    /// unilateral contact the model does not eliminate (one that can close), and an indexed
    /// quantity an index the model has. What is measured in the reduced coordinate (its
    /// series, the angles and times where contacts end) needs one, the sensitivities one or
    /// impacts (whose times they differentiate), the motion to the floor an end angle, and the
    /// point mass's fall a falling point.
    pub fn available(&self, info: &ModelInfo) -> bool {
        let angle = info.reduced_index.is_some();
        let separates = angle && info.contacts.first().is_some_and(|c| !c.bilateral);
        let release = info.phases.iter().find(|p| p.release);
        let impacts = (info.contacts.iter()).any(|c| !c.closed && !c.bilateral);
        match self {
            Quantity::SeparationAngle | Quantity::SeparationTime => separates,
            Quantity::ContactEnd => angle && !info.contacts.is_empty(),
            Quantity::Impacts => impacts,
            Quantity::LinearisedSeparationAngle => {
                separates && release.is_some_and(|p| p.separation_degree > 0)
            }
            Quantity::ContactTimeToFloor | Quantity::CrossCheck => release.is_some(),
            Quantity::ForceSeries(i) => *i < info.contacts.len(),
            Quantity::FrictionSeries(i) => *i < info.frictions.len(),
            Quantity::Trajectory(i) => *i < info.points.len(),
            Quantity::ThetaSeries => angle,
            Quantity::Sensitivities => angle || impacts,
            Quantity::FloorImpact => info.end_angle.is_some(),
            Quantity::PointMassFallTime => info.falling_point_index.is_some(),
            Quantity::Checks => true,
        }
    }
}
