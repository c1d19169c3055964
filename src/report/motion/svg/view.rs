//! The mapping from the world (metres, y up) to the picture (pixels, y down) that covers every
//! shape in every frame, the traced path and the floor ([`View`]).

use super::layout::{FOOTER, HEADER, MARGIN, MAX_DRAWING_HEIGHT, WIDTH};
use super::markup::num;
use crate::model::ShapeKind;
use crate::report::motion::animation::{Animation, Shape, place};

/// The extreme points of a shape in its own frame.
fn outline(shape: &Shape) -> Vec<[f64; 2]> {
    let n = &shape.numbers;
    match shape.kind {
        ShapeKind::Segment => vec![[n[0], n[1]], [n[2], n[3]]],
        ShapeKind::Rectangle => {
            let (w, h) = (0.5 * n[2].abs(), 0.5 * n[3].abs());
            vec![
                [n[0] - w, n[1] - h],
                [n[0] + w, n[1] - h],
                [n[0] + w, n[1] + h],
                [n[0] - w, n[1] + h],
            ]
        }
        ShapeKind::Circle => {
            let r = n[2].abs();
            vec![
                [n[0] - r, n[1] - r],
                [n[0] + r, n[1] - r],
                [n[0] + r, n[1] + r],
                [n[0] - r, n[1] + r],
            ]
        }
    }
}

/// The mapping from the world (metres, y up) to the picture (pixels, y down).
#[derive(Debug, Clone, Copy)]
pub(super) struct View {
    /// Pixels per metre.
    pub(super) scale: f64,
    /// Picture coordinates of the world's origin.
    pub(super) origin: [f64; 2],
    /// World range shown in x.
    pub(super) x: [f64; 2],
    /// Height of the picture in pixels.
    pub(super) height: f64,
    /// Decimals of world coordinates (a twentieth of a pixel or finer).
    decimals: usize,
}

impl View {
    /// A view covering every shape in every frame, the scenery, the traced path and the floor,
    /// with margins.
    pub(super) fn covering(anim: &Animation) -> View {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut add = |p: [f64; 2]| {
            if p.iter().all(|v| v.is_finite()) {
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        };
        for shape in &anim.shapes {
            match shape.body {
                None => outline(shape).into_iter().for_each(&mut add),
                Some(b) => {
                    for f in &anim.frames {
                        if let Some(&pose) = f.poses.get(b) {
                            outline(shape).into_iter().for_each(|p| add(place(pose, p)));
                        }
                    }
                }
            }
        }
        anim.frames
            .iter()
            .filter_map(|f| f.traced)
            .for_each(&mut add);
        if lo[0] > hi[0] {
            (lo, hi) = ([-0.5, 0.0], [0.5, 1.0]);
        }
        // The floor is always in view.
        lo[1] = lo[1].min(0.0);
        hi[1] = hi[1].max(0.0);
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let span = if span > 0.0 && span.is_finite() {
            span
        } else {
            1.0
        };
        let pad = 0.06 * span;
        let (x0, x1) = (lo[0] - pad, hi[0] + pad);
        let (y0, y1) = (lo[1] - pad, hi[1] + pad);
        let scale = ((WIDTH - 2.0 * MARGIN) / (x1 - x0)).min(MAX_DRAWING_HEIGHT / (y1 - y0));
        let decimals = (scale * 20.0).log10().ceil().clamp(0.0, 12.0) as usize;
        // Centred horizontally.
        let left = 0.5 * (WIDTH - scale * (x1 - x0));
        View {
            scale,
            origin: [left - scale * x0, HEADER + scale * y1],
            x: [x0, x1],
            height: (HEADER + scale * (y1 - y0) + FOOTER).ceil(),
            decimals,
        }
    }

    /// A world length in metres.
    pub(super) fn len(&self, x: f64) -> String {
        num(x, self.decimals)
    }

    /// A world point `x y`.
    pub(super) fn pt(&self, p: [f64; 2]) -> String {
        format!("{} {}", self.len(p[0]), self.len(p[1]))
    }

    /// `n` pixels as a world length.
    pub(super) fn px(&self, n: f64) -> String {
        num(n / self.scale, self.decimals + 2)
    }
}
