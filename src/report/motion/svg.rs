//! Writing `motion.svg`: the [`Animation`] as an animated SVG (SMIL, no script), laid out as
//! the module `report::motion` describes.

use super::animation::{
    Animation, ContactEnd, PAUSE_SECONDS, Shape, drawable, keyframes, place, slow_motion,
};
use crate::model::ShapeKind;
use std::fmt::Write;

/// Most distinct time labels (the time shown changes at most this often).
pub const MAX_TIME_LABELS: usize = 120;
/// Width of the picture in pixels.
const WIDTH: f64 = 720.0;
/// Largest height of the drawing area (below the text) in pixels.
const MAX_DRAWING_HEIGHT: f64 = 460.0;
/// Height of the text band above the drawing, in pixels.
const HEADER: f64 = 74.0;
/// Height of the text band below the drawing, in pixels.
const FOOTER: f64 = 26.0;
/// Margin around the drawing, in pixels.
const MARGIN: f64 = 16.0;
/// Stroke colours of the bodies, in turn.
const COLOURS: &[&str] = &["#1f5fa8", "#d9731a", "#2a8a3e", "#8e44ad", "#b8860b"];
/// Colour of the contact's end (its label, the faded bodies, the mark on the path).
const END_COLOUR: &str = "#c0392b";
/// Fill of an impact's star.
const IMPACT_COLOUR: &str = "#f1c40f";
/// Colour of an impact's caption and of its star's outline.
const IMPACT_TEXT: &str = "#a04000";
/// Most impacts marked (a star and a caption each); the picture's description counts the rest.
pub const MAX_IMPACT_MARKS: usize = 100;

/// `x` with `decimals` decimals, trailing zeros dropped, never `-0`.
fn num(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// The factor in words: `×40 slower`, `×2.5 faster`, `real time`.
fn factor_words(f: f64) -> String {
    if f == 1.0 {
        "real time".into()
    } else if f > 1.0 {
        format!("×{} slower", num(f, 3))
    } else {
        format!("×{} faster", num(1.0 / f, 3))
    }
}

/// Text safe inside an XML element or attribute.
fn xml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A name usable in an `id` (ASCII letters, digits, `-` and `_`; anything else becomes `_`).
fn id_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

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
struct View {
    /// Pixels per metre.
    scale: f64,
    /// Picture coordinates of the world's origin.
    origin: [f64; 2],
    /// World range shown in x.
    x: [f64; 2],
    /// Height of the picture in pixels.
    height: f64,
    /// Decimals of world coordinates (a twentieth of a pixel or finer).
    decimals: usize,
}

impl View {
    /// A view covering every shape in every frame, the scenery, the traced path and the floor,
    /// with margins.
    fn covering(anim: &Animation) -> View {
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
    fn len(&self, x: f64) -> String {
        num(x, self.decimals)
    }

    /// A world point `x y`.
    fn pt(&self, p: [f64; 2]) -> String {
        format!("{} {}", self.len(p[0]), self.len(p[1]))
    }

    /// `n` pixels as a world length.
    fn px(&self, n: f64) -> String {
        num(n / self.scale, self.decimals + 2)
    }
}

/// The clock of the animation.
#[derive(Debug, Clone, Copy)]
struct Clock {
    /// Time of the first frame (s).
    t0: f64,
    /// The slow-motion factor.
    factor: f64,
    /// Length of one repetition, pause included (s on screen).
    dur: f64,
}

impl Clock {
    /// Where time `t` falls in a repetition, from 0 to 1.
    fn key(&self, t: f64) -> f64 {
        ((t - self.t0) * self.factor / self.dur).clamp(0.0, 1.0)
    }

    /// `dur="..." repeatCount="indefinite"`.
    fn timing(&self) -> String {
        format!(r#"dur="{}s" repeatCount="indefinite""#, num(self.dur, 4))
    }
}

/// Key times, rounded, never decreasing, from 0 to 1.
fn key_times(keys: &[f64]) -> String {
    let mut last = 0.0f64;
    let n = keys.len();
    keys.iter()
        .enumerate()
        .map(|(i, &k)| {
            let k = if i == 0 {
                0.0
            } else if i + 1 == n {
                1.0
            } else {
                ((k * 1e5).round() / 1e5).clamp(last, 1.0)
            };
            last = k;
            num(k, 5)
        })
        .collect::<Vec<_>>()
        .join(";")
}

/// The picture of an animation (see the module's documentation). Never fails: what cannot be
/// drawn is left out and said in the picture.
pub fn svg(anim: &Animation) -> String {
    let anim = &drawable(anim);
    let view = View::covering(anim);
    let keys = keyframes(&anim.frames);
    let (t0, t1) = match (anim.frames.first(), anim.frames.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0.0, 0.0),
    };
    let duration = t1 - t0;
    let animated = keys.len() >= 2 && duration > 0.0;
    let factor = if animated { slow_motion(duration) } else { 1.0 };
    let clock = Clock {
        t0,
        factor,
        dur: duration * factor + PAUSE_SECONDS,
    };
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" data-slow-motion="{f}" data-t0="{t0}" font-family="sans-serif">
<title>{title}</title>
<desc>{desc}</desc>
<rect width="{w}" height="{h}" fill="white"/>
"#,
        w = WIDTH,
        h = view.height,
        f = num(factor, 6),
        t0 = num(t0, 9),
        title = xml(&format!("{}: the motion", anim.model)),
        desc = xml(&description(anim, factor)),
    );
    write_world(&mut out, anim, &view, &keys, animated.then_some(&clock));
    write_labels(&mut out, anim, &view, &keys, animated.then_some(&clock));
    out.push_str("</svg>\n");
    out
}

/// What the picture shows, in words (its `<desc>`).
fn description(anim: &Animation, factor: f64) -> String {
    let phases: Vec<&str> = anim.phases.iter().map(|p| p.name.as_str()).collect();
    let mut d = format!(
        "The bodies of {} moving ({}; phases: {}), {}.",
        anim.model,
        factor_words(factor),
        if phases.is_empty() {
            "none".into()
        } else {
            phases.join(", ")
        },
        match &anim.traced {
            Some(p) => format!("with the path of `{p}` traced"),
            None => "no path traced".into(),
        }
    );
    if !anim.impacts.is_empty() {
        let list: Vec<String> = (anim.impacts.iter().take(MAX_IMPACT_MARKS))
            .map(|m| format!("t = {} s ({})", num(m.t, 5), m.contact))
            .collect();
        let _ = write!(d, " Impacts at {}", list.join(", "));
        if let Some(rest) = anim.impacts.len().checked_sub(MAX_IMPACT_MARKS)
            && rest > 0
        {
            let _ = write!(d, " and {rest} more, not marked");
        }
        d.push('.');
    }
    if anim.dropped > 0 {
        let _ = write!(
            d,
            " {} frames with a NaN or infinite number left out.",
            anim.dropped
        );
    }
    for note in &anim.notes {
        let _ = write!(d, " {note}.");
    }
    d
}

/// The world group: floor, scenery, the faded bodies at the contact's end, the bodies, the
/// traced path, the impacts' stars.
fn write_world(
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

/// The key times of the keyframes, then 1 (the last frame holds through the pause).
fn frame_keys(anim: &Animation, keys: &[usize], clock: &Clock) -> String {
    let mut k: Vec<f64> = keys.iter().map(|&i| clock.key(anim.frames[i].t)).collect();
    k.push(1.0);
    key_times(&k)
}

/// `values` of a visibility switched on at key `on` and off at key `off` (discrete).
fn visibility(clock: &Clock, on: f64, off: Option<f64>) -> String {
    let on = (on * 1e5).round() / 1e5;
    let (values, times) = match off {
        _ if on <= 0.0 => match off {
            Some(off) if off < 1.0 => ("visible;hidden".to_string(), format!("0;{}", num(off, 5))),
            _ => ("visible".to_string(), "0".to_string()),
        },
        Some(off) if off < 1.0 => (
            "hidden;visible;hidden".to_string(),
            format!("0;{};{}", num(on, 5), num(off.max(on), 5)),
        ),
        _ => ("hidden;visible".to_string(), format!("0;{}", num(on, 5))),
    };
    format!(
        r#"<animate attributeName="visibility" calcMode="discrete" {} keyTimes="{times}" values="{values}"/>"#,
        clock.timing()
    )
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
    let mut covered = vec![0.0];
    for w in points.windows(2) {
        let (a, b) = (w[0].1, w[1].1);
        let last = covered.last().copied().unwrap_or(0.0);
        covered.push(last + (b[0] - a[0]).hypot(b[1] - a[1]));
    }
    let total = covered.last().copied().unwrap_or(0.0);
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

/// The captions of the impacts, at the right under the slow-motion factor: each shown from its
/// impact to the next one (on a static picture, the last one).
fn write_impact_labels(out: &mut String, anim: &Animation, clock: Option<&Clock>) {
    let marks = &anim.impacts[..anim.impacts.len().min(MAX_IMPACT_MARKS)];
    let n = anim.impacts.len();
    for (i, m) in marks.iter().enumerate() {
        let text = if n > 1 {
            format!(
                "impact {} of {n} at t = {} s ({})",
                i + 1,
                num(m.t, 5),
                m.contact
            )
        } else {
            format!("impact at t = {} s ({})", num(m.t, 5), m.contact)
        };
        let shown = clock.is_none() && i + 1 == marks.len();
        let _ = write!(
            out,
            r#"<text class="impact-label" x="{}" y="44" font-size="13" text-anchor="end" fill="{IMPACT_TEXT}" visibility="{}">{}"#,
            WIDTH - MARGIN,
            if shown { "visible" } else { "hidden" },
            xml(&text)
        );
        if let Some(c) = clock {
            let off = marks.get(i + 1).map(|next| c.key(next.t));
            out.push_str(&visibility(c, c.key(m.t), off));
        }
        out.push_str("</text>\n");
    }
}

/// The text: the time (changing with the frames), the slow-motion factor, the phase, the
/// contact's end and the impacts (appearing when they happen) and a footer.
fn write_labels(
    out: &mut String,
    anim: &Animation,
    view: &View,
    keys: &[usize],
    clock: Option<&Clock>,
) {
    let right = WIDTH - MARGIN;
    let _ = writeln!(
        out,
        r##"<text id="slow-motion" x="{right}" y="24" font-size="14" text-anchor="end" fill="#333">{}</text>"##,
        xml(&factor_words(clock.map_or(1.0, |c| c.factor)))
    );
    write_times(out, anim, keys, clock);
    // The phase.
    let n = anim.phases.len();
    for (i, p) in anim.phases.iter().enumerate() {
        let text = if n > 1 {
            format!("phase {} of {n}: {}", i + 1, p.name)
        } else {
            format!("phase: {}", p.name)
        };
        let _ = write!(
            out,
            r##"<text class="phase" x="{MARGIN}" y="44" font-size="13" fill="#333" visibility="{}">{}"##,
            if i == 0 { "visible" } else { "hidden" },
            xml(&text)
        );
        if let (Some(c), true) = (clock, n > 1) {
            let on = if i == 0 { 0.0 } else { c.key(p.t_start) };
            let off = anim.phases.get(i + 1).map(|q| c.key(q.t_start));
            out.push_str(&visibility(c, on, off));
        }
        out.push_str("</text>\n");
    }
    if let Some(end) = &anim.contact_end {
        let _ = write!(
            out,
            r#"<text id="contact-end-label" x="{MARGIN}" y="63" font-size="13" fill="{END_COLOUR}" visibility="{}">{}"#,
            if clock.is_some() { "hidden" } else { "visible" },
            xml(&format!(
                "contact ends at t = {} s: {} (faded: the bodies then)",
                num(end.frame.t, 5),
                end.cause
            ))
        );
        if let Some(c) = clock {
            out.push_str(&visibility(c, c.key(end.frame.t), None));
        }
        out.push_str("</text>\n");
    }
    write_impact_labels(out, anim, clock);
    let mut foot = format!("rodcube: {}", anim.model);
    if let Some(p) = &anim.traced {
        let _ = write!(foot, "; the path of `{p}` traced");
    }
    if clock.is_none() {
        foot.push_str(if anim.frames.is_empty() {
            "; no frame could be drawn"
        } else {
            "; static: a single frame, nothing moves"
        });
    }
    let _ = writeln!(
        out,
        r##"<text id="footer" x="{MARGIN}" y="{}" font-size="11" fill="#777">{}</text>"##,
        num(view.height - 9.0, 1),
        xml(&foot)
    );
}

/// The time labels: one per step of an even grid of at most [`MAX_TIME_LABELS`] times (equal
/// neighbours merged), each visible while its time is the nearest.
fn write_times(out: &mut String, anim: &Animation, keys: &[usize], clock: Option<&Clock>) {
    let label = |t: f64, decimals: usize| format!("t = {} s", num_fixed(t, decimals));
    let Some(c) = clock else {
        let t = anim.frames.first().map_or(0.0, |f| f.t);
        let _ = writeln!(
            out,
            r#"<text class="time" x="{MARGIN}" y="24" font-size="17" font-weight="bold">{}</text>"#,
            xml(&label(t, 4))
        );
        return;
    };
    let (t0, t1) = (anim.frames[keys[0]].t, anim.frames[keys[keys.len() - 1]].t);
    let n = MAX_TIME_LABELS.min(keys.len()).max(2);
    let step = (t1 - t0) / (n - 1) as f64;
    let decimals = (-step.log10()).ceil().clamp(0.0, 9.0) as usize;
    let mut labels: Vec<(f64, String)> = Vec::new();
    for j in 0..n {
        let t = if j + 1 == n { t1 } else { t0 + step * j as f64 };
        let text = label(t, decimals);
        if labels.last().is_none_or(|(_, last)| *last != text) {
            labels.push((t, text));
        }
    }
    // Each label shows from halfway after the previous one's time to halfway before the
    // next's: the time shown is the nearest on the grid.
    for (j, (t, text)) in labels.iter().enumerate() {
        let on = match j.checked_sub(1).and_then(|i| labels.get(i)) {
            Some((before, _)) => c.key(0.5 * (before + t)),
            None => 0.0,
        };
        let off = labels.get(j + 1).map(|(next, _)| c.key(0.5 * (t + next)));
        let _ = writeln!(
            out,
            r#"<text class="time" x="{MARGIN}" y="24" font-size="17" font-weight="bold" visibility="{}">{}{}</text>"#,
            if j == 0 { "visible" } else { "hidden" },
            xml(text),
            visibility(c, on, off)
        );
    }
}

/// `x` with exactly `decimals` decimals (the time labels keep their width), never `-0`.
fn num_fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::super::animation::{Frame, ImpactMark, MAX_KEYFRAMES, PhaseSpan};
    use super::*;

    /// A rod turning about its foot and a square sliding, over `n` frames of one phase and `m`
    /// of a second.
    fn sample(n: usize, m: usize) -> Animation {
        let mut frames = Vec::new();
        for i in 0..n + m {
            let t = 0.2 * i as f64 / (n + m - 1).max(1) as f64;
            let th = 1.2 - 4.0 * t;
            frames.push(Frame {
                t,
                phase: usize::from(i >= n),
                poses: vec![
                    [0.5 * th.cos(), 0.5 * th.sin(), th],
                    [th.cos() + 0.125, 0.125, 0.0],
                ],
                traced: Some([th.cos(), th.sin()]),
            });
        }
        let end = frames[n.saturating_sub(1).min(frames.len() - 1)].clone();
        Animation {
            model: "test <&> model".into(),
            bodies: vec!["rod".into(), "cube".into()],
            shapes: vec![
                Shape {
                    kind: ShapeKind::Segment,
                    body: Some(0),
                    numbers: vec![-0.5, 0.0, 0.5, 0.0],
                },
                Shape {
                    kind: ShapeKind::Rectangle,
                    body: Some(1),
                    numbers: vec![0.0, 0.0, 0.25, 0.25],
                },
                Shape {
                    kind: ShapeKind::Segment,
                    body: None,
                    numbers: vec![0.0, 0.0, 0.0, 1.0],
                },
            ],
            phases: vec![
                PhaseSpan {
                    name: "first".into(),
                    t_start: 0.0,
                },
                PhaseSpan {
                    name: "second".into(),
                    t_start: end.t,
                },
            ],
            contact_end: Some(ContactEnd {
                cause: "the push vanishes".into(),
                frame: end,
            }),
            impacts: Vec::new(),
            frames,
            traced: Some("tip".into()),
            dropped: 0,
            notes: Vec::new(),
        }
    }

    /// Checks that every tag is closed in order and every attribute quoted; returns the tag
    /// names in document order.
    fn well_formed(svg: &str) -> Vec<String> {
        let mut stack: Vec<String> = Vec::new();
        let mut names = Vec::new();
        let mut rest = svg;
        while let Some(at) = rest.find('<') {
            let text = &rest[..at];
            assert!(!text.contains('>'), "stray `>` in text {text:?}");
            rest = &rest[at + 1..];
            let end = rest.find('>').expect("an unclosed tag");
            let tag = &rest[..end];
            rest = &rest[end + 1..];
            assert_eq!(
                tag.matches('"').count() % 2,
                0,
                "unbalanced quotes in <{tag}>"
            );
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(name),
                    "</{name}> closes nothing"
                );
                continue;
            }
            let name: String = tag
                .chars()
                .take_while(|c| !c.is_whitespace() && *c != '/')
                .collect();
            names.push(name.clone());
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed: {stack:?}");
        names
    }

    /// The `values` list of the animateTransform of `type`.
    fn values_of(svg: &str, kind: &str) -> usize {
        let at = svg
            .find(&format!(r#"type="{kind}""#))
            .expect("the animation");
        let v = &svg[at..];
        let v = &v[v.find("values=\"").unwrap() + 8..];
        v[..v.find('"').unwrap()].split(';').count()
    }

    #[test]
    fn the_picture_is_well_formed_animated_and_scriptless() {
        let svg = svg(&sample(1000, 1000));
        let names = well_formed(&svg);
        assert_eq!(names[0], "svg");
        assert!(!svg.contains("<script"), "a script element");
        for (at, _) in svg.match_indices(" on") {
            let attr: String = svg[at + 1..]
                .chars()
                .take_while(|c| c.is_ascii_alphabetic())
                .collect();
            assert!(
                !svg[at + 1 + attr.len()..].starts_with('='),
                "an event attribute `{attr}`"
            );
        }
        assert!(svg.contains("test &lt;&amp;&gt; model"));
        // 2000 frames thinned to at most MAX_KEYFRAMES keyframes, plus the pause.
        let n = values_of(&svg, "translate");
        assert!(n > MAX_KEYFRAMES / 2 && n <= MAX_KEYFRAMES + 1, "{n}");
        assert_eq!(n, values_of(&svg, "rotate"));
        assert!(svg.contains("id=\"body-rod-turn\"") && svg.contains("id=\"body-cube\""));
        assert!(svg.contains("id=\"path\"") && svg.contains("id=\"contact-end\""));
        assert!(svg.contains("phase 2 of 2: second"));
        // 0.2 s shown in 8 s: 40 times slower.
        assert!(svg.contains("×40 slower") && svg.contains("data-slow-motion=\"40\""));
        // The cube does not turn: no rotation animation for it.
        assert_eq!(svg.matches(r#"type="rotate""#).count(), 1);
        assert!(svg.len() < 120_000, "{} bytes", svg.len());
    }

    #[test]
    fn key_times_rise_from_zero_to_one() {
        let svg = svg(&sample(200, 200));
        for part in svg.split("keyTimes=\"").skip(1) {
            let list: Vec<f64> = part[..part.find('"').unwrap()]
                .split(';')
                .map(|k| k.parse().unwrap())
                .collect();
            assert_eq!(list[0], 0.0);
            assert!(list.windows(2).all(|w| w[0] <= w[1]), "{list:?}");
            assert!(*list.last().unwrap() <= 1.0);
        }
    }

    #[test]
    fn few_frames_are_all_kept_and_one_frame_is_static() {
        let svg2 = svg(&sample(3, 2));
        well_formed(&svg2);
        assert_eq!(values_of(&svg2, "translate"), 6);
        let one = svg(&sample(1, 0));
        well_formed(&one);
        assert!(!one.contains("<animate"), "a single frame is static");
        assert!(one.contains("static: a single frame"));
    }

    #[test]
    fn nothing_to_draw_still_gives_a_picture() {
        let empty = svg(&Animation::default());
        well_formed(&empty);
        assert!(empty.contains("id=\"floor\"") && empty.contains("no frame could be drawn"));
        let mut nan = sample(4, 0);
        nan.shapes[0].numbers[0] = f64::NAN;
        for f in &mut nan.frames {
            f.t = 0.0;
        }
        let s = svg(&nan);
        well_formed(&s);
        let desc_end = s.find("</desc>").unwrap();
        let drawn = &s[desc_end..];
        assert!(!drawn.contains("NaN") && !drawn.contains("inf"), "{s}");
        assert!(s[..desc_end].contains("3 frames with a NaN or infinite number left out"));
    }

    #[test]
    fn impacts_get_a_star_where_placed_and_a_caption_each() {
        let mut anim = sample(100, 100);
        let t1 = anim.phases[1].t_start;
        anim.impacts = vec![
            ImpactMark {
                t: t1,
                contact: "floor_normal".into(),
                at: Some([0.3, 0.0]),
            },
            ImpactMark {
                t: 0.2,
                contact: "a <contact>".into(),
                at: None,
            },
            ImpactMark {
                t: 0.2,
                contact: "nan".into(),
                at: Some([f64::NAN, 0.0]),
            },
        ];
        let s = svg(&anim);
        well_formed(&s);
        // A star for the impact with a place only, shown from its frame on.
        assert_eq!(s.matches(r#"class="impact-mark""#).count(), 1);
        let star = &s[s.find(r#"id="impact-1""#).unwrap()..];
        let star = &star[..star.find("</polygon>").unwrap()];
        assert!(star.contains(r#"visibility="hidden""#), "{star}");
        assert!(star.contains(r#"values="hidden;visible""#), "{star}");
        assert!(!s.contains(r#"id="impact-2""#) && !s.contains(r#"id="impact-3""#));
        // A caption each, the first hidden again at the second.
        assert_eq!(s.matches(r#"class="impact-label""#).count(), 3);
        let first = format!("impact 1 of 3 at t = {} s (floor_normal)", num(t1, 5));
        assert!(s.contains(&first), "{s}");
        assert!(s.contains("impact 2 of 3 at t = 0.2 s (a &lt;contact&gt;)"));
        let caption = &s[s.find(&first).unwrap()..];
        assert!(caption.contains(r#"values="hidden;visible;hidden""#));
        assert!(s.contains("Impacts at t = "));
        // A static picture shows every star and the last caption.
        let mut one = sample(1, 0);
        one.impacts = anim.impacts[..1].to_vec();
        let s = svg(&one);
        well_formed(&s);
        assert!(s.contains(r#"class="impact-mark" id="impact-1""#));
        assert!(
            s.contains(r##"fill="#a04000" visibility="visible">impact at t ="##),
            "{s}"
        );
    }

    #[test]
    fn impacts_beyond_the_most_marked_are_counted() {
        let mut anim = sample(10, 10);
        anim.impacts = (0..MAX_IMPACT_MARKS + 7)
            .map(|i| ImpactMark {
                t: 0.001 * i as f64,
                contact: "c".into(),
                at: Some([0.5, 0.0]),
            })
            .collect();
        let s = svg(&anim);
        well_formed(&s);
        assert_eq!(
            s.matches(r#"class="impact-mark""#).count(),
            MAX_IMPACT_MARKS
        );
        assert_eq!(
            s.matches(r#"class="impact-label""#).count(),
            MAX_IMPACT_MARKS
        );
        assert!(s.contains("and 7 more, not marked."));
    }

    #[test]
    fn slow_motion_is_a_round_factor_near_the_target() {
        assert_eq!(slow_motion(0.187), 40.0);
        assert_eq!(slow_motion(6.0), 1.0);
        assert_eq!(slow_motion(30.0), 0.2);
        assert_eq!(slow_motion(0.0), 1.0);
        assert_eq!(slow_motion(f64::NAN), 1.0);
        assert_eq!(factor_words(0.4), "×2.5 faster");
        assert_eq!(num(-0.0000001, 3), "0");
        assert_eq!(num_fixed(-0.0, 3), "0.000");
    }
}
