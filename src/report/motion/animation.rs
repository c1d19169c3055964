//! The animation of `motion.svg` computed from the run's [`Drawing`]: the frames (every body's
//! pose and the traced point at each drawn sample), the shapes with their sizes, the phases on
//! the common clock, the first contact's end and the impacts, what could not be drawn; the
//! keyframes and the slow-motion factor that time it.

use crate::model::ShapeKind;
use crate::results::{Drawing, DrawnPhase, EndCause};

/// Most keyframes of the animation: frames are thinned to about this many, evenly in time
/// (every phase's first and last frame kept).
pub const MAX_KEYFRAMES: usize = 300;
/// How long the motion should take on screen, in seconds: the slow-motion factor is the round
/// number (1, 2, 4 or 5 times a power of ten) that brings it closest.
pub const TARGET_SECONDS: f64 = 6.0;
/// How long the last frame holds before the animation repeats, in seconds.
pub const PAUSE_SECONDS: f64 = 1.5;
/// How close, relative to the drawing's size, the drawn bodies must be to touch at an impact.
const TOUCH_TOLERANCE: f64 = 1e-6;

/// A shape of the drawing with its numbers (see [`ShapeKind`] for their order).
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// What it is.
    pub kind: ShapeKind,
    /// Index in [`Animation::bodies`] of the body it moves with; `None` for fixed scenery.
    pub body: Option<usize>,
    /// Its numbers, in its body's frame (or the world's, for scenery), in metres.
    pub numbers: Vec<f64>,
}

/// The bodies at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Time from release (s).
    pub t: f64,
    /// Index in [`Animation::phases`] of the phase it belongs to.
    pub phase: usize,
    /// Every body's pose `[x, y, angle]` (m, m, rad), in the order of [`Animation::bodies`].
    pub poses: Vec<[f64; 3]>,
    /// The traced point's position `[x, y]` (m), when a point is traced.
    pub traced: Option<[f64; 2]>,
}

/// One phase of the motion, on the common clock.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseSpan {
    /// Its model's name.
    pub name: String,
    /// When it starts (s from release).
    pub t_start: f64,
}

/// Where and why the first phase's contact ended.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEnd {
    /// Why, in words (`the push vanishes`, `the contact point runs off an edge`).
    pub cause: String,
    /// The bodies then (its time is the moment of the end).
    pub frame: Frame,
}

/// An impact: a contact closing at the end of a phase (the next one starts from the state after
/// it, or the motion ends there).
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactMark {
    /// Time from release (s).
    pub t: f64,
    /// The contact whose gap closed.
    pub contact: String,
    /// Where the drawn bodies meet then (m, world); `None` when the drawing does not show it
    /// (then only the caption marks the impact).
    pub at: Option<[f64; 2]>,
}

/// Everything `motion.svg` shows ([`svg`](super::svg) draws it).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Animation {
    /// The first phase's model.
    pub model: String,
    /// The bodies' names.
    pub bodies: Vec<String>,
    /// The shapes drawn: the bodies' and the scenery.
    pub shapes: Vec<Shape>,
    /// The phases, in order.
    pub phases: Vec<PhaseSpan>,
    /// The frames, in increasing time.
    pub frames: Vec<Frame>,
    /// The first phase's contact end, if it ended by its force or at an edge.
    pub contact_end: Option<ContactEnd>,
    /// The impacts, in order: every phase that ended where a contact closed.
    pub impacts: Vec<ImpactMark>,
    /// The name of the point whose path is traced, if any.
    pub traced: Option<String>,
    /// Frames left out for a NaN or infinite number, or for a state the model refuses.
    pub dropped: usize,
    /// What could not be drawn, and why.
    pub notes: Vec<String>,
}

impl Animation {
    /// The animation of a run's drawing: its phases in order, with the path of its traced
    /// point. The bodies and shapes are the first phase's; a later phase with other bodies is
    /// not drawn (a note says so), and neither are the phases from one that could not be
    /// sampled (a note says why).
    pub fn build(drawing: &Drawing) -> Animation {
        let mut anim = match drawing.phases.first() {
            Some(first) => from_phases(drawing, first),
            None => Animation {
                notes: vec!["no phase was solved".into()],
                ..Animation::default()
            },
        };
        if let Some((i, why)) = &drawing.stopped {
            anim.notes
                .push(format!("the animation stops before phase {}: {why}", i + 1));
        }
        anim
    }
}

/// The animation of the drawing's phases, `first` being the first.
fn from_phases(drawing: &Drawing, first: &DrawnPhase) -> Animation {
    let mut anim = Animation {
        model: drawing.system.clone(),
        bodies: first.bodies.clone(),
        traced: drawing.traced.clone(),
        ..Animation::default()
    };
    anim.shapes = first_shapes(drawing, first, &mut anim.notes);
    for phase in &drawing.phases {
        if phase.bodies != first.bodies {
            anim.notes.push(format!(
                "phase `{}` has other bodies than `{}`: not drawn",
                phase.model, first.model
            ));
            break;
        }
        let index = anim.phases.len();
        anim.phases.push(PhaseSpan {
            name: phase.model.clone(),
            t_start: phase.t_start,
        });
        add_frames(&mut anim, phase, index);
        if let EndCause::Contact(c) = phase.end
            && let Some(mark) = impact_mark(&anim, phase, index, c.name)
        {
            anim.impacts.push(mark);
        }
        let cause = match phase.end {
            EndCause::Force(c) => Some(format!("{} lets go", c.name)),
            EndCause::Edge(c) => Some(format!("{} runs off an edge", c.name)),
            EndCause::Contact(_) | EndCause::Impact | EndCause::Floor | EndCause::Until => None,
        };
        if anim.contact_end.is_none()
            && let Some(cause) = cause
            && let Some(last) = anim.frames.last()
        {
            anim.contact_end = Some(ContactEnd {
                cause,
                frame: last.clone(),
            });
        }
    }
    anim
}

/// The impact that ends `phase` (drawn as phase `index`) at contact `contact`, at its last
/// sample: where the drawn bodies meet then (when that sample was drawn), having been apart in
/// the frame before; `None` when the phase has no sample.
fn impact_mark(
    anim: &Animation,
    phase: &DrawnPhase,
    index: usize,
    contact: &str,
) -> Option<ImpactMark> {
    let t = phase.t_start + phase.samples.last()?.t;
    let at = match anim.frames.split_last() {
        Some((last, earlier)) if last.phase == index && last.t == t => {
            earlier.last().and_then(|before| {
                crate::report::touch::impact_point(
                    &anim.shapes,
                    &before.poses,
                    &last.poses,
                    TOUCH_TOLERANCE,
                )
            })
        }
        _ => None,
    };
    Some(ImpactMark {
        t,
        contact: contact.to_string(),
        at,
    })
}

/// The first phase's shapes with their sizes (those with a NaN or infinite number, or naming a
/// body that does not exist, are left out with a note).
fn first_shapes(drawing: &Drawing, first: &DrawnPhase, notes: &mut Vec<String>) -> Vec<Shape> {
    let sizes = match &drawing.sizes {
        Ok(sizes) => sizes,
        Err(e) => {
            notes.push(format!(
                "the shapes of `{}` are not drawn: {e}",
                first.model
            ));
            return Vec::new();
        }
    };
    let mut shapes = Vec::new();
    for (i, s) in drawing.shapes.iter().enumerate() {
        let numbers = sizes.get(s.first..s.first + s.kind.numbers());
        match numbers {
            Some(n)
                if n.iter().all(|v| v.is_finite())
                    && s.body.is_none_or(|b| b < first.bodies.len()) =>
            {
                shapes.push(Shape {
                    kind: s.kind,
                    body: s.body,
                    numbers: n.to_vec(),
                });
            }
            _ => notes.push(format!(
                "shape {i} of `{}` has no finite size or no body: not drawn",
                first.model
            )),
        }
    }
    shapes
}

/// The frames of one phase (a frame no later than the one before, as a phase's first at the
/// previous one's last, is skipped; one with a NaN or infinite number, or whose state the
/// model refused, is dropped).
fn add_frames(anim: &mut Animation, phase: &DrawnPhase, index: usize) {
    let mut refused = None;
    for sample in &phase.samples {
        let t = phase.t_start + sample.t;
        if anim.frames.last().is_some_and(|f| t <= f.t) {
            continue;
        }
        let pose = match &sample.pose {
            Ok(pose) => pose,
            Err(e) => {
                anim.dropped += 1;
                refused.get_or_insert(e);
                continue;
            }
        };
        let finite = t.is_finite()
            && pose.bodies.iter().flatten().all(|v| v.is_finite())
            && pose.traced.is_none_or(|p| p.iter().all(|v| v.is_finite()));
        if finite {
            anim.frames.push(Frame {
                t,
                phase: index,
                poses: pose.bodies.clone(),
                traced: pose.traced,
            });
        } else {
            anim.dropped += 1;
        }
    }
    if let Some(e) = refused {
        anim.notes
            .push(format!("frames of phase `{}` not drawn: {e}", phase.model));
    }
}

/// The slow-motion factor for a motion of `duration` seconds: the number `f` among 1, 2, 4 and
/// 5 times a power of ten that brings `duration * f` closest to [`TARGET_SECONDS`] (in ratio);
/// 1 for a duration that is not positive and finite.
pub fn slow_motion(duration: f64) -> f64 {
    if !(duration > 0.0 && duration.is_finite()) {
        return 1.0;
    }
    let ideal = TARGET_SECONDS / duration;
    let decade = 10f64.powf(ideal.log10().floor());
    let mut best = 1.0;
    let mut best_err = f64::INFINITY;
    for scale in [decade / 10.0, decade, decade * 10.0] {
        for m in [1.0, 2.0, 4.0, 5.0] {
            let f = m * scale;
            let err = (duration * f / TARGET_SECONDS).ln().abs();
            if f.is_finite() && f > 0.0 && err < best_err {
                best = f;
                best_err = err;
            }
        }
    }
    best
}

/// A point of a shape moved into the world by a body's pose.
pub(crate) fn place(pose: [f64; 3], p: [f64; 2]) -> [f64; 2] {
    let (s, c) = pose[2].sin_cos();
    [pose[0] + c * p[0] - s * p[1], pose[1] + s * p[0] + c * p[1]]
}

/// The indices of the keyframes: about [`MAX_KEYFRAMES`] frames evenly spread in time (the
/// nearest frame to each of as many even times), every phase's first and last frame, and the
/// last frame; all of them when there are few.
pub(super) fn keyframes(frames: &[Frame]) -> Vec<usize> {
    let n = frames.len();
    if n <= MAX_KEYFRAMES {
        return (0..n).collect();
    }
    let mut keep: Vec<usize> = vec![0, n - 1];
    for i in 1..n {
        if frames[i].phase != frames[i - 1].phase {
            keep.extend([i - 1, i]);
        }
    }
    let budget = MAX_KEYFRAMES.saturating_sub(keep.len()).max(2);
    let (t0, t1) = (frames[0].t, frames[n - 1].t);
    for j in 0..budget {
        let target = t0 + (t1 - t0) * j as f64 / (budget - 1) as f64;
        let i = frames.partition_point(|f| f.t < target).min(n - 1);
        let nearer = if i > 0 && (target - frames[i - 1].t) < (frames[i].t - target) {
            i - 1
        } else {
            i
        };
        keep.push(nearer);
    }
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// `anim` with only what can be drawn: shapes with as many finite numbers as their kind has,
/// frames with finite numbers in increasing time (the others counted in `dropped`), a
/// contact end with a finite frame, and impacts at a finite time (a place with a NaN or
/// infinite number forgotten).
pub(super) fn drawable(anim: &Animation) -> Animation {
    let finite = |f: &Frame| {
        f.t.is_finite()
            && f.poses.iter().flatten().all(|v| v.is_finite())
            && f.traced.is_none_or(|p| p.iter().all(|v| v.is_finite()))
    };
    let mut out = Animation {
        frames: Vec::with_capacity(anim.frames.len()),
        shapes: anim
            .shapes
            .iter()
            .filter(|s| {
                s.numbers.len() == s.kind.numbers() && s.numbers.iter().all(|v| v.is_finite())
            })
            .cloned()
            .collect(),
        contact_end: anim.contact_end.clone().filter(|e| finite(&e.frame)),
        impacts: (anim.impacts.iter())
            .filter(|m| m.t.is_finite())
            .map(|m| ImpactMark {
                at: m.at.filter(|p| p.iter().all(|v| v.is_finite())),
                ..m.clone()
            })
            .collect(),
        ..anim.clone()
    };
    for f in &anim.frames {
        if finite(f) && out.frames.last().is_none_or(|last| f.t > last.t) {
            out.frames.push(f.clone());
        } else {
            out.dropped += 1;
        }
    }
    out
}
