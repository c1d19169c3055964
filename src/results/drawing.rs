//! The bodies' motion as the model draws it: plain numbers per solved phase and sample, from
//! which `report::motion` computes the animation.

use super::EndCause;
use crate::model::ShapeInfo;

/// The drawing's numbers at one sample: every body's pose and the traced point.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Every body's pose `[x, y, angle]` (m, m, rad), in the order of the phase's bodies.
    pub bodies: Vec<[f64; 3]>,
    /// The traced point's position `[x, y]` (m), when a point is traced and the phase has it.
    pub traced: Option<[f64; 2]>,
}

/// One sample of a phase as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnSample {
    /// Time from the phase's start (s).
    pub t: f64,
    /// The poses, or the model's refusal of the sample's state (its message).
    pub pose: Result<Pose, String>,
}

/// One solved phase as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnPhase {
    /// Its model's name.
    pub model: String,
    /// Its bodies' names.
    pub bodies: Vec<String>,
    /// When it starts (s from release).
    pub t_start: f64,
    /// Why it ended.
    pub end: EndCause,
    /// Its samples, in order.
    pub samples: Vec<DrawnSample>,
}

/// The bodies' motion as the model draws it, every solved phase sampled: plain numbers from
/// which `report::motion` computes the animation.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawing {
    /// The system drawn (the first phase's).
    pub system: String,
    /// The shapes of the first phase's model: kind, body and where its numbers start in
    /// `sizes`.
    pub shapes: Vec<ShapeInfo>,
    /// The shapes' numbers at the first phase's start, or the model's refusal (its message).
    pub sizes: Result<Vec<f64>, String>,
    /// The name of the point whose path is traced, if any.
    pub traced: Option<String>,
    /// The phases drawn, in order.
    pub phases: Vec<DrawnPhase>,
    /// The phase (its index) before which the drawing stops, when a phase could not be
    /// sampled, with the reason (the error's message).
    pub stopped: Option<(usize, String)>,
}
