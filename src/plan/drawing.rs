//! The bodies' motion as numbers for `motion.svg`: each solved phase's samples evaluated by its
//! generated drawing ([`record`]), kept in [`RunResults::drawing`](crate::results::RunResults)
//! as plain data, from which `report::motion` computes the animation.

use crate::results::{Drawing, DrawnPhase, DrawnSample, EndCause, Pose};
use crate::solve::series::PhaseSamples;
use crate::system::Bound;

/// One solved phase, as [`record`] reads it.
pub struct PhaseInput<'a, 'm> {
    /// Its model with its parameters.
    pub bound: &'a Bound<'m>,
    /// Its samples (full states at uniform times from its start).
    pub samples: &'a PhaseSamples,
    /// When it starts (s from release).
    pub t_start: f64,
    /// Why it ended.
    pub end: EndCause,
}

/// The drawing of the phases, in order, with the path of the point named `traced` (looked up
/// in each phase's model): every sample's poses, or the model's refusal of its state. The
/// shapes are the first phase's, their sizes read at its first sample (or its initial state,
/// without samples): they depend on the parameters only.
pub fn record(phases: &[PhaseInput], traced: Option<&str>) -> Drawing {
    let mut drawing = Drawing {
        system: String::new(),
        shapes: Vec::new(),
        sizes: Ok(Vec::new()),
        traced: traced.map(str::to_string),
        phases: Vec::new(),
        stopped: None,
    };
    let Some(first) = phases.first() else {
        return drawing;
    };
    let info = first.bound.info();
    drawing.system = info.system.to_string();
    drawing.shapes = info.shapes.to_vec();
    let start = match first.samples.states.first() {
        Some(s) => s.clone(),
        None => first.bound.initial_state(),
    };
    drawing.sizes = (first.bound.drawing(&start))
        .map(|(_, sizes)| sizes)
        .map_err(|e| e.to_string());
    drawing.phases = phases.iter().map(|p| phase(p, traced)).collect();
    drawing
}

/// One phase's samples as drawn.
fn phase(phase: &PhaseInput, traced: Option<&str>) -> DrawnPhase {
    let bound = phase.bound;
    let info = bound.info();
    let point = traced.and_then(|name| bound.point_index(name));
    let end = phase.end;
    let samples = (phase.samples.t.iter().zip(&phase.samples.states))
        .map(|(&t, state)| {
            let pose = bound.drawing(state).and_then(|(poses, _)| {
                let traced = match point {
                    Some(i) => bound.points(state)?.pos.get(i).copied(),
                    None => None,
                };
                Ok(Pose {
                    bodies: poses,
                    traced,
                })
            });
            DrawnSample {
                t,
                pose: pose.map_err(|e| e.to_string()),
            }
        })
        .collect();
    DrawnPhase {
        model: info.name.to_string(),
        bodies: info.bodies.iter().map(|b| b.to_string()).collect(),
        t_start: phase.t_start,
        end,
        samples,
    }
}
