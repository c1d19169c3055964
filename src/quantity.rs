//! The vocabulary of quantities a scene can ask for (`want:`), resolved against a model.

use crate::model::ModelInfo;

/// One quantity a scene can want. Force series and trajectories are named after the model's
/// forces and points, so every model gets the quantities its spec declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Quantity {
    /// Angle at which the contact force vanishes (rad).
    SeparationAngle,
    /// The paper's approximation: the separation polynomial with its terms above degree 1 dropped.
    LinearisedSeparationAngle,
    /// Time from release to separation (s), eq. (15).
    SeparationTime,
    /// When, at which angle and why (`force` or `edge`) the contact ends.
    ContactEnd,
    /// Time to the floor if the rod stayed in contact all the way (s), eq. (10).
    ContactTimeToFloor,
    /// Free-fall time of a point mass from the initial height of the falling centre of mass (s).
    PointMassFallTime,
    /// `t, theta, theta_dot, theta_ddot` from release to separation (or to the floor).
    ThetaSeries,
    /// A reaction force (index into `ModelInfo::forces`) along the motion: `<force>_series`.
    ForceSeries(usize),
    /// A friction (index into `ModelInfo::frictions`) along the motion, with its normal force
    /// and slip velocity: `<friction>_series`.
    FrictionSeries(usize),
    /// A point's path (index into `ModelInfo::points`): `<point>_trajectory`.
    Trajectory(usize),
    /// The free-sliding phase after separation, up to the rod lying on the floor.
    FloorImpact,
    /// The physical assumptions and conservation laws, each pass/fail with its margin.
    Checks,
    /// Integration of the unreduced equations `M(q) qdd = F(q, qd)` to the separation event.
    CrossCheck,
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
        "when, at which angle and why the contact ends (force or edge)",
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
        "free-sliding phase after separation, to the floor",
    ),
    (
        "checks",
        Quantity::Checks,
        "physical assumptions and conservation checks",
    ),
    (
        "cross_check",
        Quantity::CrossCheck,
        "unreduced equations integrated to the separation event",
    ),
];

impl Quantity {
    /// Resolves a `want` entry for a model; the error lists what the model offers.
    pub fn parse(name: &str, info: &ModelInfo) -> Result<Quantity, String> {
        if let Some((_, q, _)) = FIXED.iter().find(|(n, _, _)| *n == name) {
            return Ok(*q);
        }
        if let Some(force) = name.strip_suffix("_series")
            && let Some(i) = info.forces.iter().position(|f| f.name == force)
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
        Err(format!(
            "unknown quantity `{name}` for model `{}`; it offers: {}",
            info.name,
            Quantity::names(info).join(", ")
        ))
    }

    /// The key of this quantity in scenes and results. An index the model does not have is
    /// named for error messages (`force #7_series`); [`Quantity::available`] refuses it.
    pub fn name(&self, info: &ModelInfo) -> String {
        let named = |names: Option<&'static str>, what: &str, i: usize| {
            names.map_or_else(|| format!("{what} #{i}"), str::to_string)
        };
        match self {
            Quantity::ForceSeries(i) => {
                let force = named(info.forces.get(*i).map(|f| f.name), "force", *i);
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
        out.extend((0..info.forces.len()).map(Quantity::ForceSeries));
        out.extend((0..info.frictions.len()).map(Quantity::FrictionSeries));
        out.extend((0..info.points.len()).map(Quantity::Trajectory));
        out
    }

    /// Whether a model can provide this quantity: separation needs a contact, the floor
    /// impact a phase after it, the quantities of the energy integral (the time to the floor in
    /// contact, the cross-check against the quadrature) the fast path, the linearised angle
    /// a separation polynomial, and an indexed quantity an index the model has.
    pub fn available(&self, info: &ModelInfo) -> bool {
        let contact = info.contact.is_some();
        let fast = info.reduction.is_some();
        match self {
            Quantity::SeparationAngle | Quantity::SeparationTime | Quantity::ContactEnd => contact,
            Quantity::LinearisedSeparationAngle => {
                contact && info.reduction.is_some_and(|r| r.polynomial_separation)
            }
            Quantity::ContactTimeToFloor | Quantity::CrossCheck => fast,
            Quantity::FloorImpact => contact && info.next_phase.is_some(),
            Quantity::ForceSeries(i) => *i < info.forces.len(),
            Quantity::FrictionSeries(i) => *i < info.frictions.len(),
            Quantity::Trajectory(i) => *i < info.points.len(),
            Quantity::ThetaSeries | Quantity::Checks | Quantity::PointMassFallTime => true,
        }
    }
}
