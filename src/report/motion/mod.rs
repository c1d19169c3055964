//! The motion to watch, `motion.svg`: the bodies of every solved phase moving in real time
//! slowed to a readable pace, as an animated SVG (SMIL, no script), drawn from the spec's shapes.
//!
//! [`Animation::build`] (in `animation.rs`) computes the animation from the run's
//! [`Drawing`](crate::results::Drawing), each phase's generated
//! [`Model::drawing`](crate::model::Model) evaluated at its samples by the planner: one
//! [`Frame`] per sample (every body's pose and the traced point), the shapes' sizes once.
//! [`svg`] (in `svg.rs`) writes the picture: a fixed view box covering every frame, y up,
//! the floor `y = 0`, the scenery, the bodies moved by `<animateTransform>` (linear between at
//! most [`MAX_KEYFRAMES`] keyframes, evenly spread in time), the traced point's path (faint in
//! full, drawn strong as the motion goes), the time and the phase as text that changes with the
//! frames, the moment the first phase's contact ends (a label and a faded copy of the bodies
//! appear then), and every impact (a contact closing between two phases, or at the motion's
//! end): a star where the drawn bodies meet (`report/touch.rs` finds the place) appears at its
//! frame, with a caption `impact at t = … s (contact)` shown until the next impact. The
//! slow-motion factor is a round number chosen so that the motion lasts about
//! [`TARGET_SECONDS`]; it is printed in the picture. The last frame holds for
//! [`PAUSE_SECONDS`], then the animation repeats.
//!
//! Nothing here panics on bad numbers: a frame with a NaN or infinite number, or whose state the
//! model refuses (a length not its own), is left out (and counted in [`Animation::dropped`],
//! the refusal in a note), a shape with one is not drawn; with a single frame, or a
//! motion of zero duration, the picture is static (that frame, with a note saying so); with
//! none, it shows the floor and the note.
//!
//! The SVG root carries `data-slow-motion` (the factor) and `data-t0` (the time of the first
//! frame, s): a frame at time `t` shows at `(t - t0) * factor` seconds into the animation. The
//! world is the group `#world` (world coordinates in metres, y up); each drawn body is the group
//! `#body-<name>` (translated to its centre of mass) holding `#body-<name>-turn` (rotated by its
//! angle), which holds its shapes in the body's own frame.

mod animation;
mod svg;

pub(crate) use animation::place;
pub use animation::{
    Animation, ContactEnd, Frame, ImpactMark, MAX_KEYFRAMES, PAUSE_SECONDS, PhaseSpan, Shape,
    TARGET_SECONDS, slow_motion,
};
// The FMU's model description escapes its text with it.
#[cfg(any(feature = "cli", feature = "fmi"))]
pub(crate) use svg::xml;
pub use svg::{MAX_IMPACT_MARKS, MAX_TIME_LABELS, svg};
