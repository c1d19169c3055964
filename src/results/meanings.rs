//! What each scalar and word-valued result is, as data: the quantity with the names and
//! numbers its sentence gives (`report::prose::meaning` writes the sentence).

use super::EndCause;

/// What a result in [`RunResults::results`](super::RunResults) or
/// [`RunResults::labels`](super::RunResults) is. `angle` is always the name of the model's
/// reduced coordinate.
#[derive(Debug, Clone, PartialEq)]
pub enum Meaning {
    /// The reduced angle where the first contact's force vanishes.
    SeparationAngle {
        /// The reduced coordinate.
        angle: String,
    },
    /// The time from release to separation.
    SeparationTime,
    /// The separation angle with the polynomial's terms above degree 1 dropped.
    LinearisedSeparationAngle,
    /// The time from release until a contact ends.
    ContactEndTime {
        /// The contact.
        contact: String,
        /// Why it ended.
        cause: EndCause,
    },
    /// The reduced angle where a contact ends.
    ContactEndAngle {
        /// The reduced coordinate.
        angle: String,
        /// The contact.
        contact: String,
        /// Why it ended.
        cause: EndCause,
    },
    /// Why a contact ended, a word (a label).
    ContactEndCause {
        /// The contact.
        contact: String,
    },
    /// The closed contacts and the frictions' motion over the first contact's phase (a label).
    ContactModes,
    /// The work done by friction over the first contact's phase.
    ContactEndFrictionWork,
    /// The time to the end angle if the release contacts held all the way.
    ContactTimeToFloor {
        /// The reduced coordinate.
        angle: String,
        /// The model's end angle (rad).
        end_angle: f64,
    },
    /// The free fall of a point mass from the falling point's release height.
    PointMassFallTime {
        /// The falling point.
        point: String,
        /// Its height at release (m).
        height: f64,
    },
    /// The work done by friction from release to the end angle.
    FloorImpactFrictionWork {
        /// The reduced coordinate.
        angle: String,
        /// The model's end angle (rad).
        end_angle: f64,
    },
    /// The time from release to the end angle, along the phases in `path`.
    FloorImpactTime {
        /// The reduced coordinate.
        angle: String,
        /// The model's end angle (rad).
        end_angle: f64,
        /// The phases, in order.
        path: Vec<String>,
    },
    /// The rate of the reduced angle where it reaches its end, along the phases in `path`.
    ImpactAngularVelocity {
        /// The reduced coordinate.
        angle: String,
        /// The phases, in order.
        path: Vec<String>,
    },
    /// The cross-check's event time: the general model integrated to its first event.
    CrossCheckTime {
        /// The integration method's name.
        method: String,
        /// Its steps.
        steps: u64,
        /// The event.
        event: EndCause,
    },
    /// The cross-check's event time against the quadrature's, relative.
    CrossCheckRelativeDifference {
        /// The event.
        event: EndCause,
        /// The quadrature's time (s).
        t_quad: f64,
        /// The integrator's relative tolerance.
        rtol: f64,
        /// The mass matrix's condition number.
        condition: f64,
    },
    /// The relative tolerance the cross-check's integrator ran with.
    CrossCheckRtol,
    /// The largest `|t_ode - t(theta_ode)|` over the integrator's steps.
    CrossCheckTimeDeviation {
        /// The steps compared.
        nodes: usize,
    },
    /// The largest relative difference between the integrated and the reduced states.
    CrossCheckStateDeviation {
        /// The steps compared.
        nodes: usize,
    },
}
