//! The quadrature's rules and its error control: Gauss–Legendre rules kept as half rules
//! ([`HalfRule`], their nodes [`LANES`] a step), the schedule of rule pairs by panel length
//! ([`RuleStep`], [`SCHEDULE`]), the tolerances, and the [`Control`] that gives a panel its pair
//! of rules and the agreement they must reach.

use gauss_quad::GaussLegendre;
use std::collections::HashMap;
use std::num::NonZeroUsize;
use std::sync::{Mutex, OnceLock};

/// One step of a rule schedule: panels up to `max_len` long (in `v`; a first panel `[0, b]`
/// from rest counts as `[-b, b]`, `2b` long) are integrated by Gauss–Legendre rules of `low` and
/// `high` nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleStep {
    /// Longest panel (in `v`) this step applies to.
    pub max_len: f64,
    /// Nodes of the coarse rule (the error estimate).
    pub low: usize,
    /// Nodes of the fine rule (the value kept).
    pub high: usize,
}

/// The default schedule. The steps were set so that the coarse rule alone is within about
/// 1e-13 of the integral for the reduced models across `n` 1e-3..1e3 and `a/ell` 0.01..0.99
/// (`rodcube accuracy` shows the cost of other settings); the schedule only sets the cost, as
/// every panel is still accepted only by the agreement of its two rules.
pub const SCHEDULE: [RuleStep; 3] = [
    RuleStep {
        max_len: 0.6,
        low: 6,
        high: 10,
    },
    RuleStep {
        max_len: 1.0,
        low: 8,
        high: 12,
    },
    RuleStep {
        max_len: 1.6,
        low: 10,
        high: 14,
    },
];

/// The per-point solver's tolerance: the rules of a panel must agree to 1e-12 relative, which
/// leaves the kept (finer) value within about 1e-15.
pub const ACCEPT: f64 = 1e-12;

/// A phase integrated to a relative tolerance `tol` has its panels accepted when their rules
/// agree to `tol * TOL_SAFETY`: where a singularity sits just past a panel's end the kept rule
/// is only a few times better than the agreement of the two (errors of 1.7e-10 were seen at an
/// agreement of 1e-10 with the hinged rod and a heavy cube), so a hundredfold margin makes the
/// result meet `tol` itself.
pub const TOL_SAFETY: f64 = 1e-2;

/// Smallest relative tolerance honoured (a few ulps: the rounding floor of one panel sum).
pub const MIN_TOL: f64 = 4.0 * f64::EPSILON;

/// Most nodes of a rule.
pub const MAX_NODES: usize = 64;

/// Gauss–Legendre nodes and weights on `[-1, 1]` of any order (a rule has at least one node).
pub fn gauss_legendre_rule(order: NonZeroUsize) -> Vec<(f64, f64)> {
    GaussLegendre::new(order).as_node_weight_pairs().to_vec()
}

/// A Gauss–Legendre rule on `[-1, 1]` kept as its nodes `x > 0` with their weights (each used
/// at `+x` and `-x`) and the weight of the node at 0 (0 for even orders).
#[derive(Debug, Clone, PartialEq)]
pub struct HalfRule {
    /// Nodes in all.
    pub nodes: usize,
    /// `(x, w)` for `x > 0`, ascending.
    pub pairs: Vec<(f64, f64)>,
    /// Weight of the node at 0.
    pub centre: f64,
    /// The largest node (0 for the one-node rule).
    pub reach: f64,
    /// The nodes `x >= 0`: the node at 0 (odd orders) first with half its weight (it is then
    /// counted at `+x` and `-x`, or, on a symmetric panel, once for the half of `[-b, b]`),
    /// then `pairs`.
    pub halved: Vec<(f64, f64)>,
    /// `halved` [`LANES`] at a time, for a loop with nothing but full steps; the last step
    /// padded with its last node again, with weight 0. (Both lists are kept: a panel off
    /// `v = 0` evaluates each node twice, at `c + hx` and `c - hx`, and takes `halved` so that
    /// it pays for no pad.)
    pub lanes: Vec<Lane>,
}

/// Nodes per step of [`HalfRule::lanes`]: four, one AVX register of `f64` (two SSE2
/// registers on the baseline, in the same order, so that both give the same sum to the bit).
pub const LANES: usize = 4;

/// [`LANES`] nodes of [`HalfRule::lanes`] and their weights, aligned so that one packed load
/// (or a packed operation's memory operand) reads each array.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub struct Lane {
    /// The nodes.
    pub x: [f64; LANES],
    /// Their weights.
    pub w: [f64; LANES],
}

/// The rule of `order` nodes (clamped to `1..=MAX_NODES`), computed once per process and kept
/// for its life, so that making a solver is cheap enough to do per call.
pub fn half_rule(order: usize) -> &'static HalfRule {
    type Rules = Mutex<HashMap<usize, &'static HalfRule>>;
    static RULES: OnceLock<Rules> = OnceLock::new();
    let order = order.clamp(1, MAX_NODES);
    let cache = RULES.get_or_init(|| Mutex::new(HashMap::new()));
    let mut map = match cache.lock() {
        Ok(map) => map,
        Err(poisoned) => poisoned.into_inner(),
    };
    map.entry(order).or_insert_with(|| {
        // `order >= 1` after the clamp, so this is `order` itself.
        let full = gauss_legendre_rule(NonZeroUsize::MIN.saturating_add(order - 1));
        // Nodes come in pairs +-x; an odd order adds x = 0 (within rounding).
        let mut pairs: Vec<(f64, f64)> = full.iter().filter(|(x, _)| *x > 1e-12).copied().collect();
        pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
        let centre = full
            .iter()
            .filter(|(x, _)| x.abs() <= 1e-12)
            .map(|(_, w)| *w)
            .sum();
        let mut halved: Vec<(f64, f64)> = Vec::with_capacity(pairs.len() + 1);
        if centre != 0.0 {
            halved.push((0.0, 0.5 * centre));
        }
        halved.extend_from_slice(&pairs);
        let lanes = halved
            .chunks(LANES)
            .map(|chunk| {
                // The pad repeats the last node (a value like the others) with no weight.
                let (last, _) = chunk[chunk.len() - 1];
                let mut lane = Lane {
                    x: [last; LANES],
                    w: [0.0; LANES],
                };
                for (i, &(x, w)) in chunk.iter().enumerate() {
                    (lane.x[i], lane.w[i]) = (x, w);
                }
                lane
            })
            .collect();
        Box::leak(Box::new(HalfRule {
            nodes: full.len(),
            reach: pairs.last().map_or(0.0, |&(x, _)| x),
            pairs,
            centre,
            halved,
            lanes,
        }))
    })
}

/// The error control of the quadrature: a rule pair per panel length, and the relative
/// agreement a panel's two rules must reach.
#[derive(Debug, Clone, PartialEq)]
pub struct Control {
    /// `(max_len, coarse, fine)`, shortest first.
    steps: Vec<(f64, &'static HalfRule, &'static HalfRule)>,
    /// Relative agreement asked of a panel's rules.
    pub accept: f64,
}

impl Control {
    /// A control from a schedule (steps in any order; an empty one means [`SCHEDULE`]) and a
    /// relative tolerance (raised to [`MIN_TOL`]; not finite means [`MIN_TOL`]).
    pub fn new(schedule: &[RuleStep], accept: f64) -> Control {
        let schedule = if schedule.is_empty() {
            &SCHEDULE[..]
        } else {
            schedule
        };
        let mut steps: Vec<_> = schedule
            .iter()
            .map(|st| {
                let len = if st.max_len > 0.0 {
                    st.max_len
                } else {
                    f64::INFINITY
                };
                (len, half_rule(st.low), half_rule(st.high))
            })
            .collect();
        steps.sort_by(|a, b| a.0.total_cmp(&b.0));
        let accept = if accept.is_finite() {
            accept.max(MIN_TOL)
        } else {
            MIN_TOL
        };
        Control { steps, accept }
    }

    /// The default schedule at a relative tolerance.
    pub fn with_tolerance(accept: f64) -> Control {
        Control::new(&SCHEDULE, accept)
    }

    /// `(max_len, low, high)` rule orders of the steps, shortest first.
    pub fn steps(&self) -> Vec<(f64, usize, usize)> {
        self.steps
            .iter()
            .map(|(len, lo, hi)| (*len, lo.nodes, hi.nodes))
            .collect()
    }

    /// The step for a panel of this length (the longest step beyond its reach).
    pub(super) fn step_for(&self, len: f64) -> (&'static HalfRule, &'static HalfRule) {
        // `steps` is never empty: `Control::new`, the only maker of a `Control`, takes
        // `SCHEDULE` for an empty schedule. A panel longer than every step (by a rounding past
        // the cut `integrate` makes at `longest`, or a length that is not a number, whose rules
        // then fail the panel) takes the longest step: the schedule's rule, not a fallback.
        let last = self.steps.len().saturating_sub(1);
        let i = self.steps.iter().position(|s| len <= s.0).unwrap_or(last);
        (self.steps[i].1, self.steps[i].2)
    }

    /// The longest panel of the schedule.
    pub(super) fn longest(&self) -> f64 {
        // Never the infinity: `steps` is never empty (`Control::new`).
        self.steps.last().map_or(f64::INFINITY, |s| s.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_rules_rebuild_the_gauss_legendre_rules() {
        for order in 1..=24 {
            let rule = half_rule(order);
            let odd = usize::from(rule.centre != 0.0);
            assert_eq!(rule.nodes, order);
            assert_eq!(2 * rule.pairs.len() + odd, order, "order {order}");
            // Exact for x^(2j), j < order (odd powers vanish by symmetry).
            for j in 0..order {
                let exact = 2.0 / (2 * j + 1) as f64;
                let sum: f64 = rule.centre * if j == 0 { 1.0 } else { 0.0 }
                    + rule
                        .pairs
                        .iter()
                        .map(|&(x, w)| 2.0 * w * x.powi(2 * j as i32))
                        .sum::<f64>();
                assert!((sum - exact).abs() < 1e-14, "order {order}, x^{}", 2 * j);
                // The same sum from the lanes (each node at +x and -x, the node at 0 halved,
                // the padding weightless).
                let lanes: f64 = (rule.lanes.iter())
                    .flat_map(|l| l.x.into_iter().zip(l.w))
                    .map(|(x, w)| 2.0 * w * x.powi(2 * j as i32))
                    .sum();
                assert!((lanes - exact).abs() < 1e-14, "lanes {order}, x^{}", 2 * j);
            }
            assert_eq!(rule.halved.len(), rule.pairs.len() + odd);
            let largest = rule.pairs.iter().fold(0.0f64, |m, &(x, _)| m.max(x));
            assert_eq!(rule.reach, largest);
            assert_eq!(rule.lanes.len(), rule.halved.len().div_ceil(LANES));
            let flat: Vec<(f64, f64)> = (rule.lanes.iter())
                .flat_map(|l| l.x.into_iter().zip(l.w))
                .collect();
            assert!(flat.starts_with(&rule.halved));
        }
    }

    #[test]
    fn the_schedule_picks_steps_by_length() {
        let c = Control::with_tolerance(1e-12);
        assert_eq!(c.step_for(0.1).1.nodes, SCHEDULE[0].high);
        assert_eq!(c.step_for(0.8).1.nodes, SCHEDULE[1].high);
        assert_eq!(c.step_for(100.0).1.nodes, SCHEDULE[2].high);
        assert_eq!(Control::new(&[], f64::NAN).accept, MIN_TOL);
    }
}
