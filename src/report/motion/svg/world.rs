//! The world group of the picture: the floor, the scenery, the bodies moved over the keyframes,
//! the faded bodies where the first phase's contact ends, the traced path and the impacts' stars.

use super::clock::{Clock, frame_keys, key_times, visibility};
use super::layout::{COLOURS, END_COLOUR, IMPACT_COLOUR, IMPACT_TEXT, MAX_IMPACT_MARKS};
use super::markup::{id_part, num};
use super::view::View;
use crate::model::ShapeKind;
use crate::report::motion::animation::{Animation, ContactEnd, Shape};
use std::fmt::Write;

/// The world group: floor, scenery, the faded bodies at the contact's end, the bodies, the
/// traced path, the impacts' stars.
pub(super) fn write_world(
    out: &mut String,
    anim: &Animation,
    view: &View,
    keys: &[usize],
    clock: Option<&Clock>,
) {
    let _ = writeln!(
        out,
        r#"<g id="world" transform="matrix({s} 0 0 {ms} {ox} {oy})" stroke-linecap="round" stroke-linejoin="round">"#,
        s = num(view.scale, 6),
        ms = num(-view.scale, 6),
        ox = num(view.origin[0], 3),
        oy = num(view.origin[1], 3),
    );
    // The floor, with a band under it.
    let _ = writeln!(
        out,
        r##"<rect id="floor-band" x="{x}" y="{y}" width="{w}" height="{h}" fill="#e8e8e8"/>
<line id="floor" x1="{x}" y1="0" x2="{x2}" y2="0" stroke="#555" stroke-width="{sw}"/>"##,
        x = view.len(view.x[0]),
        x2 = view.len(view.x[1]),
        y = view.px(-8.0),
        w = view.len(view.x[1] - view.x[0]),
        h = view.px(8.0),
        sw = view.px(1.5),
    );
    for shape in anim.shapes.iter().filter(|s| s.body.is_none()) {
        out.push_str(&shape_svg(shape, view, "#777", "#f0f0f0", 2.0));
    }
    if let Some(end) = &anim.contact_end {
        write_ghost(out, anim, view, end, clock);
    }
    for (b, name) in anim.bodies.iter().enumerate() {
        write_body(out, anim, view, keys, clock, b, name);
    }
    // Over the bodies: a path often runs along a body's face.
    write_path(out, anim, view, keys, clock);
    write_impact_marks(out, anim, view, clock);
    out.push_str("</g>\n");
}

/// One shape in its own frame.
fn shape_svg(shape: &Shape, view: &View, stroke: &str, fill: &str, width: f64) -> String {
    let n = &shape.numbers;
    let sw = view.px(width);
    match shape.kind {
        ShapeKind::Segment => format!(
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{stroke}\" stroke-width=\"{}\"/>\n",
            view.len(n[0]),
            view.len(n[1]),
            view.len(n[2]),
            view.len(n[3]),
            view.px(2.5 * width),
        ),
        ShapeKind::Rectangle => format!(
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" stroke=\"{stroke}\" fill=\"{fill}\" stroke-width=\"{sw}\"/>\n",
            view.len(n[0] - 0.5 * n[2].abs()),
            view.len(n[1] - 0.5 * n[3].abs()),
            view.len(n[2].abs()),
            view.len(n[3].abs()),
        ),
        // A radius shows the circle's turning.
        ShapeKind::Circle => format!(
            "<circle cx=\"{cx}\" cy=\"{cy}\" r=\"{r}\" stroke=\"{stroke}\" fill=\"{fill}\" stroke-width=\"{sw}\"/>\n<line x1=\"{cx}\" y1=\"{cy}\" x2=\"{x2}\" y2=\"{cy}\" stroke=\"{stroke}\" stroke-width=\"{sw}\"/>\n",
            cx = view.len(n[0]),
            cy = view.len(n[1]),
            r = view.len(n[2].abs()),
            x2 = view.len(n[0] + n[2].abs()),
        ),
    }
}

/// A body: a group translated to its centre of mass holding a group turned by its angle, which
/// holds its shapes; both animated over the keyframes. A body without a shape is not drawn.
fn write_body(
    out: &mut String,
    anim: &Animation,
    view: &View,
    keys: &[usize],
    clock: Option<&Clock>,
    b: usize,
    name: &str,
) {
    let shapes: Vec<&Shape> = anim.shapes.iter().filter(|s| s.body == Some(b)).collect();
    let poses: Vec<[f64; 3]> = keys
        .iter()
        .filter_map(|&i| anim.frames[i].poses.get(b).copied())
        .collect();
    let (Some(&start), false) = (poses.first(), shapes.is_empty()) else {
        return;
    };
    let colour = COLOURS[b % COLOURS.len()];
    let id = id_part(name);
    let deg = |p: &[f64; 3]| num(p[2].to_degrees(), 4);
    let _ = writeln!(
        out,
        r#"<g id="body-{id}" class="body" transform="translate({})">"#,
        view.pt([start[0], start[1]])
    );
    let moves = poses.iter().any(|p| p[0] != start[0] || p[1] != start[1]);
    let turns = poses.iter().any(|p| p[2] != start[2]);
    // One animation per transform, over the keyframes; the last value holds through the pause.
    let animate = |out: &mut String, kind: &str, mut values: Vec<String>, c: &Clock| {
        if let Some(last) = values.last().cloned() {
            values.push(last);
        }
        let _ = writeln!(
            out,
            r#"<animateTransform attributeName="transform" type="{kind}" calcMode="linear" {} keyTimes="{}" values="{}"/>"#,
            c.timing(),
            frame_keys(anim, keys, c),
            values.join(";")
        );
    };
    if let (Some(c), true) = (clock, moves) {
        let values = poses.iter().map(|p| view.pt([p[0], p[1]])).collect();
        animate(out, "translate", values, c);
    }
    let _ = writeln!(
        out,
        r#"<g id="body-{id}-turn" transform="rotate({})">"#,
        deg(&start)
    );
    if let (Some(c), true) = (clock, turns) {
        animate(out, "rotate", poses.iter().map(deg).collect(), c);
    }
    for shape in shapes {
        out.push_str(&shape_svg(shape, view, colour, "#ffffffb0", 2.0));
    }
    out.push_str("</g>\n</g>\n");
}

/// The traced path: faint in full, and drawn strong as the motion goes (a dash as long as the
/// path, its offset shrinking with the length covered by each keyframe).
fn write_path(
    out: &mut String,
    anim: &Animation,
    view: &View,
    keys: &[usize],
    clock: Option<&Clock>,
) {
    let points: Vec<(usize, [f64; 2])> = keys
        .iter()
        .filter_map(|&i| anim.frames[i].traced.map(|p| (i, p)))
        .collect();
    if points.len() < 2 {
        return;
    }
    let list: Vec<String> = points.iter().map(|(_, p)| view.pt(*p)).collect();
    let list = list.join(" ");
    let _ = writeln!(
        out,
        r##"<polyline id="path-full" points="{list}" fill="none" stroke="#888" stroke-width="{}" stroke-dasharray="{} {}"/>"##,
        view.px(1.2),
        view.px(4.0),
        view.px(3.0),
    );
    // The length covered at each point, and in all (a running sum: nothing to look up).
    let mut covered = vec![0.0];
    let mut total = 0.0;
    for w in points.windows(2) {
        let (a, b) = (w[0].1, w[1].1);
        total += (b[0] - a[0]).hypot(b[1] - a[1]);
        covered.push(total);
    }
    let Some(clock) = clock.filter(|_| total > 0.0) else {
        return;
    };
    let mut values: Vec<String> = covered.iter().map(|c| view.len(total - c)).collect();
    values.push(view.len(0.0));
    let mut k: Vec<f64> = points
        .iter()
        .map(|(i, _)| clock.key(anim.frames[*i].t))
        .collect();
    k.push(1.0);
    let _ = writeln!(
        out,
        r##"<polyline id="path" points="{list}" fill="none" stroke="#111" stroke-width="{}" stroke-dasharray="{t} {t}" stroke-dashoffset="{t}">
<animate attributeName="stroke-dashoffset" calcMode="linear" {} keyTimes="{}" values="{}"/>
</polyline>"##,
        view.px(1.8),
        clock.timing(),
        key_times(&k),
        values.join(";"),
        t = view.len(total),
    );
}

/// The bodies where the first phase's contact ended, faded, shown from then on (and a mark on
/// the traced path).
fn write_ghost(
    out: &mut String,
    anim: &Animation,
    view: &View,
    end: &ContactEnd,
    clock: Option<&Clock>,
) {
    let _ = writeln!(
        out,
        r#"<g id="contact-end" opacity="0.45" visibility="{}">"#,
        if clock.is_some() { "hidden" } else { "visible" }
    );
    if let Some(c) = clock {
        let _ = writeln!(out, "{}", visibility(c, c.key(end.frame.t), None));
    }
    for shape in &anim.shapes {
        let Some(pose) = shape.body.and_then(|b| end.frame.poses.get(b)) else {
            continue;
        };
        let _ = writeln!(
            out,
            r#"<g transform="translate({}) rotate({})" stroke-dasharray="{} {}">"#,
            view.pt([pose[0], pose[1]]),
            num(pose[2].to_degrees(), 4),
            view.px(5.0),
            view.px(3.0),
        );
        out.push_str(&shape_svg(shape, view, END_COLOUR, "none", 1.5));
        out.push_str("</g>\n");
    }
    if let Some(p) = end.frame.traced {
        let _ = writeln!(
            out,
            r#"<circle cx="{}" cy="{}" r="{}" fill="{END_COLOUR}"/>"#,
            view.len(p[0]),
            view.len(p[1]),
            view.px(4.0),
        );
    }
    out.push_str("</g>\n");
}

/// A star where the drawn bodies met at each impact (of the first [`MAX_IMPACT_MARKS`] that
/// have a place), shown from its frame on.
fn write_impact_marks(out: &mut String, anim: &Animation, view: &View, clock: Option<&Clock>) {
    for (i, m) in anim.impacts.iter().take(MAX_IMPACT_MARKS).enumerate() {
        let Some(at) = m.at else {
            continue;
        };
        // Five points, alternately 9 and 4 pixels from the centre.
        let points: Vec<String> = (0..10)
            .map(|k| {
                let r = if k % 2 == 0 { 9.0 } else { 4.0 } / view.scale;
                let a = std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / 5.0;
                view.pt([at[0] + r * a.cos(), at[1] + r * a.sin()])
            })
            .collect();
        let _ = write!(
            out,
            r#"<polygon class="impact-mark" id="impact-{n}" points="{}" fill="{IMPACT_COLOUR}" stroke="{IMPACT_TEXT}" stroke-width="{}" visibility="{}">"#,
            points.join(" "),
            view.px(1.0),
            if clock.is_some() { "hidden" } else { "visible" },
            n = i + 1,
        );
        if let Some(c) = clock {
            out.push_str(&visibility(c, c.key(m.t), None));
        }
        out.push_str("</polygon>\n");
    }
}
