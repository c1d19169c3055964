//! Writing `motion.svg`: the [`Animation`] as an animated SVG (SMIL, no script), laid out as
//! the module `report::motion` describes.
//!
//! [`svg`] writes the root, its title and description; `world.rs` the world group (floor,
//! scenery, bodies, path, impact stars) and `labels.rs` the text, both placed by the `View`
//! (`view.rs`) and timed by the `Clock` (`clock.rs`); `layout.rs` holds the sizes, colours and
//! limits, `markup.rs` the numbers and text as written.

mod clock;
mod labels;
mod layout;
mod markup;
mod view;
mod world;

pub use layout::{MAX_IMPACT_MARKS, MAX_TIME_LABELS};
pub(crate) use markup::xml;

use crate::report::motion::animation::{
    Animation, PAUSE_SECONDS, drawable, keyframes, slow_motion,
};
use clock::Clock;
use labels::write_labels;
use layout::WIDTH;
use markup::{factor_words, num};
use std::fmt::Write;
use view::View;
use world::write_world;

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

#[cfg(test)]
mod tests {
    use super::markup::num_fixed;
    use super::*;
    use crate::model::ShapeKind;
    use crate::report::motion::animation::{
        ContactEnd, Frame, ImpactMark, MAX_KEYFRAMES, PhaseSpan, Shape,
    };

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
