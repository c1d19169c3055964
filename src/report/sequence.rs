//! A sequence in a table cell (a run's phases, a label's contact modes) for people: repeats
//! counted (`bouncing (nothing closed) ×111`; a repeated pattern as `(a -> b) ×55`), and, given
//! a length budget, cut in the middle with the count of what was left out, so a run of a
//! hundred bounces fills a line or two rather than fifty.

/// Longest pattern looked for, in items.
const MAX_PERIOD: usize = 8;

/// One piece of a summary: `period` items repeated `times` times, consecutively.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Piece {
    /// Index of the pattern's first item.
    start: usize,
    /// The pattern's length in items.
    period: usize,
    /// How many times it repeats (1: once).
    times: usize,
}

/// `items` as pieces, left to right: at each place the pattern (of at most [`MAX_PERIOD`]
/// items) whose consecutive repeats cover the most items, the shorter pattern on a tie.
fn pieces<T: PartialEq>(items: &[T]) -> Vec<Piece> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < items.len() {
        let mut best = Piece {
            start: i,
            period: 1,
            times: 1,
        };
        for period in 1..=MAX_PERIOD.min((items.len() - i) / 2) {
            let pattern = &items[i..i + period];
            let times = 1
                + (items[i + period..].chunks_exact(period))
                    .take_while(|c| *c == pattern)
                    .count();
            if times > 1 && period * times > best.period * best.times {
                best = Piece {
                    start: i,
                    period,
                    times,
                };
            }
        }
        i += best.period * best.times;
        out.push(best);
    }
    out
}

/// `items` summarised, joined by `separator`: each run of repeats counted (`x ×3`, a pattern
/// `(x -> y) ×3`). With a `budget` (characters), a summary longer than it keeps pieces from
/// both ends and says between them how many items it left out (`… 40 more …`).
pub fn summarise(items: &[&str], separator: &str, budget: Option<usize>) -> String {
    let texts: Vec<(String, usize)> = (pieces(items).iter())
        .map(|p| {
            let pattern = items[p.start..p.start + p.period].join(separator);
            let text = match (p.times, p.period) {
                (1, _) => pattern,
                (_, 1) => format!("{pattern} ×{}", p.times),
                _ => format!("({pattern}) ×{}", p.times),
            };
            (text, p.period * p.times)
        })
        .collect();
    let joined = |parts: &[&(String, usize)]| {
        (parts.iter().map(|(t, _)| t.as_str()))
            .collect::<Vec<_>>()
            .join(separator)
    };
    let all: Vec<&(String, usize)> = texts.iter().collect();
    let full = joined(&all);
    let Some(budget) = budget.filter(|&b| full.chars().count() > b) else {
        return full;
    };
    // Pieces from the front and the back in turn while the line stays within the budget.
    let (mut head, mut tail) = (0, 0);
    let line = |head: usize, tail: usize| {
        let left: usize = texts[head..texts.len() - tail].iter().map(|(_, n)| n).sum();
        let gap = format!("… {left} more …");
        let mut parts: Vec<String> = texts[..head].iter().map(|(t, _)| t.clone()).collect();
        parts.push(gap);
        parts.extend(texts[texts.len() - tail..].iter().map(|(t, _)| t.clone()));
        parts.join(separator)
    };
    loop {
        let (h, t) = if head <= tail {
            (head + 1, tail)
        } else {
            (head, tail + 1)
        };
        if h + t >= texts.len() || line(h, t).chars().count() > budget {
            break;
        }
        (head, tail) = (h, t);
    }
    line(head, tail)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consecutive_repeats_and_patterns_are_counted() {
        let bounce = ["fall", "bounce", "bounce", "bounce", "rest"];
        assert_eq!(
            summarise(&bounce, " -> ", None),
            "fall -> bounce ×3 -> rest"
        );
        let mut pairs = vec!["start"];
        for _ in 0..55 {
            pairs.extend(["slide", "fly"]);
        }
        pairs.push("slide");
        assert_eq!(
            summarise(&pairs, " -> ", None),
            "start -> (slide -> fly) ×55 -> slide"
        );
        // A pattern of one repeated item is the item's run, not pairs of it.
        assert_eq!(summarise(&["a"; 4], ", ", None), "a ×4");
        assert_eq!(summarise(&["a", "b", "c"], ", ", None), "a, b, c");
        assert_eq!(summarise(&[], ", ", None), "");
    }

    #[test]
    fn a_long_summary_keeps_both_ends_and_counts_what_it_left_out() {
        let items: Vec<String> = (0..100).map(|i| format!("phase{i}")).collect();
        let items: Vec<&str> = items.iter().map(String::as_str).collect();
        let text = summarise(&items, " -> ", Some(80));
        assert!(text.chars().count() <= 80, "{text}");
        assert!(
            text.starts_with("phase0 -> ") && text.ends_with(" -> phase99"),
            "{text}"
        );
        // The items shown and those counted as left out are all of them.
        let shown = text.matches("phase").count();
        let left: usize = text
            .split("… ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|n| n.parse().ok())
            .expect("a count of the items left out");
        assert_eq!(shown + left, 100, "{text}");
        // Within the budget, nothing is cut.
        assert_eq!(
            summarise(&items[..3], " -> ", Some(80)),
            "phase0 -> phase1 -> phase2"
        );
    }
}
