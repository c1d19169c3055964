//! The picture's text: the time (changing with the frames), the slow-motion factor, the phase,
//! the contact's end, the impacts' captions and the footer.

use super::clock::{Clock, visibility};
use super::layout::{END_COLOUR, IMPACT_TEXT, MARGIN, MAX_IMPACT_MARKS, MAX_TIME_LABELS, WIDTH};
use super::markup::{factor_words, num, num_fixed, xml};
use super::view::View;
use crate::report::motion::animation::Animation;
use std::fmt::Write;

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
pub(super) fn write_labels(
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
    // A clock means an animated picture: at least two keyframes, each a frame's index
    // (`keyframes`), so these are frames.
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
