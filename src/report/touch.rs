//! Where the drawn bodies meet at an impact, for the marker in `motion.svg`.
//!
//! A model names its contacts by their gaps, not by points, so the place of an impact is read
//! from the drawing: every body's shapes are set in the world at the impact's frame (a
//! rectangle as its four edges) and every pair that belongs to two different owners (two
//! bodies, a body and the scenery, a body and the floor `y = 0`) is measured, with the point
//! where it comes closest. The impact is where a pair touches (its distance within the
//! tolerance) that was farther apart in the frame before: a contact that was already closed
//! touches in both, the one that closed only now. When no pair touches, or none came closer,
//! there is no place (the drawing is not the contact's geometry) and no marker is drawn.
//!
//! Only finite numbers come in (the animation has dropped the others); every distance is still
//! compared with `>`/`<=`, which a NaN fails, so nothing here panics or invents a place.

use super::motion::{Shape, place};
use crate::model::ShapeKind;

/// A drawn primitive in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Prim {
    /// A segment between two points.
    Segment([f64; 2], [f64; 2]),
    /// A circle: centre and radius.
    Circle([f64; 2], f64),
}

/// Who a primitive belongs to (primitives of one owner never touch each other).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Owner {
    /// Fixed scenery.
    Scenery,
    /// A body, by its index.
    Body(usize),
}

/// The shapes as primitives in the world, for the bodies' `poses`; a shape whose body has no
/// pose is left out.
fn primitives(shapes: &[Shape], poses: &[[f64; 3]]) -> Vec<(Owner, Prim)> {
    let mut out = Vec::new();
    for shape in shapes {
        let (owner, pose) = match shape.body {
            None => (Owner::Scenery, [0.0; 3]),
            Some(b) => match poses.get(b) {
                Some(&pose) => (Owner::Body(b), pose),
                None => continue,
            },
        };
        let n = &shape.numbers;
        let at = |x: f64, y: f64| place(pose, [x, y]);
        match (shape.kind, n.as_slice()) {
            (ShapeKind::Segment, &[x0, y0, x1, y1]) => {
                out.push((owner, Prim::Segment(at(x0, y0), at(x1, y1))));
            }
            (ShapeKind::Rectangle, &[x, y, w, h]) => {
                let (w, h) = (0.5 * w.abs(), 0.5 * h.abs());
                let c = [
                    at(x - w, y - h),
                    at(x + w, y - h),
                    at(x + w, y + h),
                    at(x - w, y + h),
                ];
                for k in 0..4 {
                    out.push((owner, Prim::Segment(c[k], c[(k + 1) % 4])));
                }
            }
            (ShapeKind::Circle, &[x, y, r]) => out.push((owner, Prim::Circle(at(x, y), r.abs()))),
            _ => {}
        }
    }
    out
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The point of segment `a`–`b` nearest `p`.
fn nearest_on(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = sub(b, a);
    let len2 = d[0] * d[0] + d[1] * d[1];
    let s = if len2 > 0.0 {
        ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2
    } else {
        0.0
    };
    let s = s.clamp(0.0, 1.0);
    [a[0] + s * d[0], a[1] + s * d[1]]
}

/// The distance between two segments and the point (on the first) where they come closest:
/// where they cross, zero there; otherwise the nearest of an end to the other segment.
fn segments(a: ([f64; 2], [f64; 2]), b: ([f64; 2], [f64; 2])) -> (f64, [f64; 2]) {
    let (r, s) = (sub(a.1, a.0), sub(b.1, b.0));
    let den = cross(r, s);
    if den != 0.0 {
        let q = sub(b.0, a.0);
        let (u, v) = (cross(q, s) / den, cross(q, r) / den);
        if (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
            return (0.0, [a.0[0] + u * r[0], a.0[1] + u * r[1]]);
        }
    }
    let candidates = [
        (a.0, nearest_on(a.0, b.0, b.1)),
        (a.1, nearest_on(a.1, b.0, b.1)),
        (nearest_on(b.0, a.0, a.1), b.0),
        (nearest_on(b.1, a.0, a.1), b.1),
    ];
    let mut best = (f64::INFINITY, a.0);
    for (p, q) in candidates {
        let d = dist(p, q);
        if d < best.0 {
            best = (d, p);
        }
    }
    best
}

/// The distance between two primitives (negative where circles overlap) and a point where they
/// come closest.
fn between(a: Prim, b: Prim) -> (f64, [f64; 2]) {
    match (a, b) {
        (Prim::Segment(a0, a1), Prim::Segment(b0, b1)) => segments((a0, a1), (b0, b1)),
        (Prim::Segment(a0, a1), Prim::Circle(c, r))
        | (Prim::Circle(c, r), Prim::Segment(a0, a1)) => {
            let p = nearest_on(c, a0, a1);
            (dist(p, c) - r, p)
        }
        (Prim::Circle(c, r), Prim::Circle(e, s)) => {
            let d = dist(c, e);
            let k = if d > 0.0 { r / d } else { 0.0 };
            (
                d - r - s,
                [c[0] + k * (e[0] - c[0]), c[1] + k * (e[1] - c[1])],
            )
        }
    }
}

/// The height of a primitive's lowest point above the floor `y = 0`, and that point on the
/// floor.
fn to_floor(a: Prim) -> (f64, [f64; 2]) {
    match a {
        Prim::Segment(p, q) => {
            let low = if q[1] < p[1] { q } else { p };
            (low[1], [low[0], 0.0])
        }
        Prim::Circle(c, r) => (c[1] - r, [c[0], 0.0]),
    }
}

/// Every pair's distance and closest point: each body primitive with the floor, then each pair
/// of primitives of two owners one of which is a body, in a fixed order (the same shapes and
/// bodies give the same list).
fn pairs(prims: &[(Owner, Prim)]) -> Vec<(f64, [f64; 2])> {
    let mut out = Vec::new();
    for (i, &(owner, a)) in prims.iter().enumerate() {
        if owner != Owner::Scenery {
            out.push(to_floor(a));
        }
        for &(other, b) in &prims[i + 1..] {
            if other != owner && (owner != Owner::Scenery || other != Owner::Scenery) {
                out.push(between(a, b));
            }
        }
    }
    out
}

/// Where the drawn bodies meet in the frame with poses `at`, having been apart in the frame
/// with poses `before` (see the module's documentation): the touching pair (distance within
/// `tolerance` times the drawing's size) that came closest since; `None` when none did.
pub(crate) fn impact_point(
    shapes: &[Shape],
    before: &[[f64; 3]],
    at: &[[f64; 3]],
    tolerance: f64,
) -> Option<[f64; 2]> {
    let now = primitives(shapes, at);
    let then = primitives(shapes, before);
    if now.len() != then.len() {
        return None;
    }
    let size = drawing_size(&now);
    let (now, then) = (pairs(&now), pairs(&then));
    let mut best: Option<(f64, [f64; 2])> = None;
    for (&(d, p), &(d0, _)) in now.iter().zip(&then) {
        let closer = d0 - d;
        if d.abs() <= tolerance * size && closer > 0.0 && best.is_none_or(|(c, _)| closer > c) {
            best = Some((closer, p));
        }
    }
    best.map(|(_, p)| p)
}

/// The larger side of the box around the primitives (1 when they have no extent).
fn drawing_size(prims: &[(Owner, Prim)]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (_, p) in prims {
        let (a, b) = match *p {
            Prim::Segment(a, b) => (a, b),
            Prim::Circle(c, r) => ([c[0] - r, c[1] - r], [c[0] + r, c[1] + r]),
        };
        for q in [a, b] {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if size > 0.0 && size.is_finite() {
        size
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn segment(body: Option<usize>, n: [f64; 4]) -> Shape {
        Shape {
            kind: ShapeKind::Segment,
            body,
            numbers: n.to_vec(),
        }
    }

    #[test]
    fn a_rod_end_landing_on_the_floor_is_found_at_the_end() {
        // A unit rod about its centre, tilted by -a: its right end lands at
        // (1 + cos(a) / 2, 0).
        let shapes = [segment(Some(0), [-0.5, 0.0, 0.5, 0.0])];
        let a: f64 = 0.4;
        let at = [[1.0, 0.5 * a.sin(), -a]];
        let before = [[1.0, 0.5 * a.sin() + 0.01, -a]];
        let p = impact_point(&shapes, &before, &at, 1e-9).unwrap();
        assert!((p[0] - (1.0 + 0.5 * a.cos())).abs() < 1e-12, "{p:?}");
        assert!(p[1].abs() < 1e-12);
    }

    #[test]
    fn a_contact_closed_all_along_is_not_the_impact() {
        // A rod from its foot at (0, y), at angle th, its tip on a square's left face in both
        // frames (both bodies 0.01 higher before), while its foot reaches the floor: the foot
        // is the impact.
        let th: f64 = 0.5;
        let shapes = [
            segment(Some(0), [0.0, 0.0, 1.0, 0.0]),
            Shape {
                kind: ShapeKind::Rectangle,
                body: Some(1),
                numbers: vec![0.0, 0.0, 0.2, 0.2],
            },
        ];
        let poses = |y: f64| [[0.0, y, th], [th.cos() + 0.1, y + th.sin(), 0.0]];
        let p = impact_point(&shapes, &poses(0.01), &poses(0.0), 1e-9).unwrap();
        assert!(p[0].abs() < 1e-12 && p[1].abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn touching_shapes_of_two_bodies_and_no_touch_at_all() {
        // A rod's end reaching a square's face.
        let shapes = [
            segment(Some(0), [-0.5, 0.0, 0.5, 0.0]),
            Shape {
                kind: ShapeKind::Rectangle,
                body: Some(1),
                numbers: vec![0.0, 0.0, 0.2, 0.2],
            },
        ];
        let at = [[0.0, 0.5, 0.0], [0.6, 0.5, 0.0]];
        let before = [[0.0, 0.5, 0.0], [0.65, 0.5, 0.0]];
        let p = impact_point(&shapes, &before, &at, 1e-9).unwrap();
        assert!(
            (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12,
            "{p:?}"
        );
        // Still apart: no place.
        let apart = [[0.0, 0.5, 0.0], [0.62, 0.5, 0.0]];
        assert_eq!(impact_point(&shapes, &before, &apart, 1e-9), None);
        // No body at all, or a NaN: no place.
        assert_eq!(impact_point(&shapes, &[], &[], 1e-9), None);
        let nan = [[f64::NAN, 0.5, 0.0], [0.6, 0.5, 0.0]];
        assert_eq!(impact_point(&shapes, &before, &nan, 1e-9), None);
    }

    #[test]
    fn circles_meet_on_the_line_between_their_centres() {
        let (d, p) = between(Prim::Circle([0.0, 0.0], 1.0), Prim::Circle([3.0, 0.0], 2.0));
        assert_eq!((d, p), (0.0, [1.0, 0.0]));
        let (d, p) = segments(([0.0, 0.0], [2.0, 2.0]), ([0.0, 2.0], [2.0, 0.0]));
        assert_eq!((d, p), (0.0, [1.0, 1.0]));
    }
}
