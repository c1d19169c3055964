//! The picture's fixed layout: its sizes in pixels, its colours, and how many time labels and
//! impact marks it holds at most.

/// Most distinct time labels (the time shown changes at most this often).
pub const MAX_TIME_LABELS: usize = 120;
/// Width of the picture in pixels.
pub(super) const WIDTH: f64 = 720.0;
/// Largest height of the drawing area (below the text) in pixels.
pub(super) const MAX_DRAWING_HEIGHT: f64 = 460.0;
/// Height of the text band above the drawing, in pixels.
pub(super) const HEADER: f64 = 74.0;
/// Height of the text band below the drawing, in pixels.
pub(super) const FOOTER: f64 = 26.0;
/// Margin around the drawing, in pixels.
pub(super) const MARGIN: f64 = 16.0;
/// Stroke colours of the bodies, in turn.
pub(super) const COLOURS: &[&str] = &["#1f5fa8", "#d9731a", "#2a8a3e", "#8e44ad", "#b8860b"];
/// Colour of the contact's end (its label, the faded bodies, the mark on the path).
pub(super) const END_COLOUR: &str = "#c0392b";
/// Fill of an impact's star.
pub(super) const IMPACT_COLOUR: &str = "#f1c40f";
/// Colour of an impact's caption and of its star's outline.
pub(super) const IMPACT_TEXT: &str = "#a04000";
/// Most impacts marked (a star and a caption each); the picture's description counts the rest.
pub const MAX_IMPACT_MARKS: usize = 100;
