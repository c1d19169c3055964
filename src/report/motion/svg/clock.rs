//! The animation's clock: where a time falls in one repetition, and the SMIL timing, key times
//! and visibility switches written from it.

use super::markup::num;
use crate::report::motion::animation::Animation;

/// The clock of the animation.
#[derive(Debug, Clone, Copy)]
pub(super) struct Clock {
    /// Time of the first frame (s).
    pub(super) t0: f64,
    /// The slow-motion factor.
    pub(super) factor: f64,
    /// Length of one repetition, pause included (s on screen).
    pub(super) dur: f64,
}

impl Clock {
    /// Where time `t` falls in a repetition, from 0 to 1.
    pub(super) fn key(&self, t: f64) -> f64 {
        ((t - self.t0) * self.factor / self.dur).clamp(0.0, 1.0)
    }

    /// `dur="..." repeatCount="indefinite"`.
    pub(super) fn timing(&self) -> String {
        format!(r#"dur="{}s" repeatCount="indefinite""#, num(self.dur, 4))
    }
}

/// Key times, rounded, never decreasing, from 0 to 1.
pub(super) fn key_times(keys: &[f64]) -> String {
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

/// The key times of the keyframes, then 1 (the last frame holds through the pause).
pub(super) fn frame_keys(anim: &Animation, keys: &[usize], clock: &Clock) -> String {
    let mut k: Vec<f64> = keys.iter().map(|&i| clock.key(anim.frames[i].t)).collect();
    k.push(1.0);
    key_times(&k)
}

/// `values` of a visibility switched on at key `on` and off at key `off` (discrete).
pub(super) fn visibility(clock: &Clock, on: f64, off: Option<f64>) -> String {
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
