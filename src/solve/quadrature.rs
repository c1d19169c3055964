//! The one time quadrature: `t = integral d(theta) / |theta_dot|` along a falling phase, used by
//! the planner ([`TimeMesh`]), the per-point solver and the sweeps
//! ([`lean`](crate::solve::lean)) and the accuracy report.
//!
//! # The substitution
//! The fall is parametrised by `s = sin(theta)`, which is monotone on a phase
//! (`0 < theta < pi/2`), so no trigonometric function is evaluated inside the integral: the
//! generated [`Reduction::theta_dot_sq_sc`] takes `s`, `cos(theta)` and their drops from the
//! start. With `dt = ds / (cos(theta) |theta_dot|)` the integrand has two square-root
//! singularities: `theta_dot^2` vanishes like the drop `w = sin(theta_i) - s` at the start when
//! released from rest, and `cos(theta) = sqrt((1 - s)(1 + s))` vanishes at `w = -e`,
//! `e = 1 - sin(theta_i)`, just outside the interval when the rod starts nearly upright. With
//! `w = e sinh^2(v)`, `dw / sqrt(w (w + e)) = 2 dv` and `1 - s = e cosh^2(v)` exactly, so
//! `t = integral 2 sqrt(e) sinh(v) / sqrt((1 + s) theta_dot^2) dv` has a smooth integrand of
//! one scale from the flat start (`e -> 1`, where `v ~ sqrt(w)`) to the upright one (`e -> 0`,
//! where the time grows like `v_end ~ log(1/e)`). `cos(theta) = sqrt(e) cosh(v) sqrt(1 + s)` and
//! `cos(theta_i) - cos(theta) = -w (sin(theta_i) + s) / (cos(theta_i) + cos(theta))` are formed
//! without cancellation.
//!
//! Released from rest, `theta_dot^2` vanishes like the drop `w = e sinh^2 v`, so the
//! integrand is `2 / sqrt((1 + s) theta_dot^2 / w)`, an *even* analytic function of `v` (its
//! value at `v = 0` is the limit `2 / sqrt(-2 theta_ddot_i (1 + sin theta_i) / cos theta_i)`),
//! and the first panel `[0, b]` is half of a symmetric rule on `[-b, b]`: a rule of `2m` nodes
//! costs `m` evaluations there. A phase that starts moving (`theta_dot_i < 0`, the free rod
//! after separation) has an integrand that vanishes at `v = 0` and is not even.
//!
//! # With a fall polynomial
//! Where the derivation found `theta_dot^2 = (sin theta_i - s) / P(s)` with a polynomial `P`
//! ([`Reduction::fall_polynomial`]), the integrand is `2 sqrt(P(s) / (1 + s))`: one polynomial,
//! one division and one root per node, no call to the model and no `cos(theta)`, and the same
//! at `v = 0` ([`FallIntegrand`], the one copy that [`Fall`] and the per-point solver's
//! unchecked route share). Each node then takes `sinh^2 v` by itself (a series below 1.5, one
//! `exp` above), which also spares the addition theorem's cancellation on long panels. Nodes
//! are taken four at a time in the same arithmetic ([`LANES`] lanes of [`HalfRule`], the
//! node at 0 and weightless pads filling the last group), with the polynomial's shape decided
//! once per panel, so that the compiler packs them into vector registers through the division
//! and the root: SSE2 pairs in the baseline build, and 4-wide AVX2 in a second copy of the same
//! source (`FallIntegrand::panel_avx2`, compiled with `#[target_feature(enable = "avx2")]` and
//! chosen at run time when the CPU has it). Each lane's sum and the final
//! `((l0 + l1) + l2) + l3` are the same operations in both copies and no fused multiply-add is
//! used, so both give the same bits (tested in `tests/prior.rs`). The
//! per-point solver chooses its rules for such phases a priori
//! ([`prior`](crate::solve::prior)); the verified pairs below serve everything else.
//!
//! # Error control
//! Each panel is integrated by two Gauss–Legendre rules chosen by the panel's length from a
//! [`RuleStep`] schedule (the nearest complex singularities of the integrand lie about `pi/2`
//! off the real `v` axis, or on it beyond the phase's end, so the panel's length sets the
//! convergence rate); the finer value is kept when the two agree to the tolerance, otherwise the
//! panel is halved. Two rules on the same panel do not agree by accident when a near-singularity
//! sits at the panel's end, which is how comparing a panel with its halves is fooled (both then
//! carry the same unresolved error): with the hinged rod and a heavy cube the integrand has
//! complex singularities (`1 + 3 n s^2 = 0`) just past the end of the phase, and a
//! panel-versus-halves test accepted panels with errors of 1e-10 there.

use crate::model::{Reduction, ReductionInfo, start_offsets};
use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::poly::horner;
use crate::system::System;
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

/// Most panels one integral may use before giving up.
pub const MAX_PANELS: usize = 20_000;

/// Gauss–Legendre nodes and weights on `[-1, 1]` of any order (0 is treated as 1).
pub fn gauss_legendre_rule(order: usize) -> Vec<(f64, f64)> {
    GaussLegendre::new(NonZeroUsize::new(order).unwrap_or(NonZeroUsize::MIN))
        .as_node_weight_pairs()
        .to_vec()
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
        let full = gauss_legendre_rule(order);
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
    fn step_for(&self, len: f64) -> (&'static HalfRule, &'static HalfRule) {
        let last = self.steps.len().saturating_sub(1);
        let i = self.steps.iter().position(|s| len <= s.0).unwrap_or(last);
        (self.steps[i].1, self.steps[i].2)
    }

    /// The longest panel of the schedule.
    fn longest(&self) -> f64 {
        self.steps.last().map_or(f64::INFINITY, |s| s.0)
    }
}

/// One accepted panel `[a, b]` in `v`, its value and the length its rules were chosen for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Lower limit (in `v`).
    pub a: f64,
    /// Upper limit (in `v`).
    pub b: f64,
    /// Integral over `[a, b]`.
    pub value: f64,
}

/// Largest `|y|` at which `sinh(y)^2` is taken from the series of [`sinh_ratio_series`] rather
/// than from one `exp` (a library call costing several times the series' nine multiply-adds).
const SERIES_REACH: f64 = 1.5;

/// `sinh(y)^2` within a few ulps: `y^2 (sinh(y) / y)^2` by the Taylor series of `sinh(y) / y`
/// for `|y| <` [`SERIES_REACH`], one `exp` beyond (which then loses at most a factor 1.1 to
/// the difference `e^y - e^-y`).
#[inline(always)]
fn sinh_sq(y: f64) -> f64 {
    let ay = y.abs();
    if ay < SERIES_REACH {
        let z = y * y;
        let r = sinh_ratio_series(z);
        z * r * r
    } else {
        let e = ay.exp();
        let sh = 0.5 * (e - 1.0 / e);
        sh * sh
    }
}

/// `sinh^2` of several arguments in the same arithmetic, lane by lane (the compiler packs the
/// lanes): by [`sinh_sq`], or by the series alone for arguments known to lie within
/// [`SERIES_REACH`].
trait SinhSq {
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N];
}

/// [`SinhSq`] by [`sinh_sq`]: the series where every lane is within its reach, else each lane
/// by itself.
struct AnyReach;

impl SinhSq for AnyReach {
    #[inline(always)]
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N] {
        let mut near = true;
        for v in y {
            near &= v.abs() < SERIES_REACH;
        }
        if near {
            Series::lanes(y)
        } else {
            let mut out = [0.0; N];
            for i in 0..N {
                out[i] = sinh_sq(y[i]);
            }
            out
        }
    }
}

/// [`SinhSq`] by the series alone (every argument within [`SERIES_REACH`]).
struct Series;

impl SinhSq for Series {
    #[inline(always)]
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N] {
        let mut out = [0.0; N];
        for i in 0..N {
            let z = y[i] * y[i];
            let r = sinh_ratio_series(z);
            out[i] = z * r * r;
        }
        out
    }
}

/// `sinh(y) / y` for `z = y^2 <= 2.25` by a polynomial of degree 8 in `z`: the Taylor series
/// `sum z^k / (2k + 1)!` to `z^17`, economized on `[0, 9/4]` by Chebyshev polynomials (the
/// series rewritten in `T_j(8z/9 - 1)` and cut after `T_8`, in exact rational arithmetic), its
/// coefficients rounded to nearest. The cut leaves `9.5e-20` relative and the rounded
/// coefficients `2.8e-18` (`2^-58`), two multiply-adds fewer than the Taylor polynomial's ten
/// for the same reach. All coefficients are positive, so Horner's rule adds no cancellation;
/// the test `sinh_squared_keeps_its_digits_on_both_sides_of_the_series_reach` holds the result
/// within four ulps of std's `sinh`.
#[inline(always)]
fn sinh_ratio_series(z: f64) -> f64 {
    const C: [f64; 8] = [
        0.166_666_666_666_666_66,
        0.008_333_333_333_333_415,
        0.000_198_412_698_412_328_65,
        2.755_731_923_243_199_3e-6,
        2.505_210_730_202_160_7e-8,
        1.605_912_543_432_801_6e-10,
        7.643_585_437_051_482e-13,
        2.895_878_527_457_87e-15,
    ];
    let mut r = C[7];
    for &c in C[..7].iter().rev() {
        r = r * z + c;
    }
    1.0 + z * r
}

/// `sinh^2 v` just past the start where [`Fall::new`] asks whether the phase falls.
const FALL_CHECK_SH2: f64 = 1e-8;

/// Largest `h x` at which a panel's node `mid - h x` is formed by the addition theorem (its
/// rounding then grows by at most `exp(2 h x) = 2`).
const ADDITION_REACH: f64 = 0.35;

/// `(sinh x, cosh x)` from one `exp_m1`, accurate for small and large `x` alike.
#[inline]
fn sinh_cosh(x: f64) -> (f64, f64) {
    let em = x.exp_m1();
    let inv = 1.0 / (1.0 + em);
    (0.5 * (em + em * inv), 0.5 * (1.0 + em + inv))
}

/// The angle at one node: `sin`, `cos`, their drops from the start, and `1 + sin`.
struct Node {
    s: f64,
    c: f64,
    ds: f64,
    dc: f64,
    plus: f64,
}

/// `(centre, half-length)` of the panel `[a, b]` as its rule sees it: a symmetric first panel
/// from rest spans `[-b, b]`.
#[inline(always)]
fn panel_frame(symmetric: bool, a: f64, b: f64) -> (f64, f64) {
    if symmetric {
        (0.0, b)
    } else {
        (0.5 * (a + b), 0.5 * (b - a))
    }
}

/// The lesser of `a` and `b` by one comparison (`f64::min`'s NaN rule costs four more
/// instructions per call): a NaN value may be skipped here, as it poisons the panel's sum,
/// which [`PanelSum::ok`] also tests.
#[inline(always)]
fn lesser(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// One panel's rule applied to a [`FallIntegrand`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelSum {
    /// The integral over the panel.
    pub value: f64,
    /// The least value met at a node (a NaN value may be skipped here; it poisons `value`).
    pub least: f64,
    /// Evaluations spent.
    pub evals: u64,
}

impl PanelSum {
    /// Whether every value was positive and finite (`P > 0` at every node).
    #[inline(always)]
    pub fn ok(&self) -> bool {
        self.least > 0.0 && self.value.is_finite()
    }
}

/// The time integrand of a phase from rest with a fall polynomial `P` (module docs): `2 sqrt(P(s)
/// / (1 + s))` at `s = sin(theta_i) - e sinh^2 v`. No trigonometry and no call to the model;
/// a polynomial of degree at most 2 is held padded to a fixed shape.
#[derive(Debug, Clone, Copy)]
pub struct FallIntegrand<'a> {
    si: f64,
    e: f64,
    /// The polynomial padded with zeros when `low` (degree at most 2).
    quadratic: [f64; 3],
    low: bool,
    coeffs: &'a [f64],
}

impl<'a> FallIntegrand<'a> {
    /// The integrand of a phase starting at `sin(theta_i) = si` with scale `e = 1 - si` and fall
    /// polynomial `coeffs` (lowest degree first).
    #[inline(always)]
    pub fn new(si: f64, e: f64, coeffs: &'a [f64]) -> FallIntegrand<'a> {
        let (quadratic, low) = match *coeffs {
            [p0] => ([p0, 0.0, 0.0], true),
            [p0, p1] => ([p0, p1, 0.0], true),
            [p0, p1, p2] => ([p0, p1, p2], true),
            _ => ([0.0; 3], false),
        };
        FallIntegrand {
            si,
            e,
            quadratic,
            low,
            coeffs,
        }
    }

    /// Whether the phase starts to fall: the integrand positive just past the start (at
    /// `sinh^2 v = 1e-8`).
    #[inline(always)]
    pub fn falls(&self) -> bool {
        self.value(FALL_CHECK_SH2) > 0.0
    }

    /// The value where `sinh^2 v = sh2`: `theta_dot^2 = w / P(s)` with `w = e sinh^2 v`, so
    /// `2 sqrt(e) sinh v / sqrt((1 + s) theta_dot^2) = 2 sqrt(P(s) / (1 + s))`, also at `v = 0`.
    /// NaN where `P(s) < 0`.
    #[inline(always)]
    fn value(&self, sh2: f64) -> f64 {
        if self.low {
            let [p0, p1, p2] = self.quadratic;
            self.value_with(sh2, |s| p0 + s * (p1 + s * p2))
        } else {
            self.value_with(sh2, |s| horner(self.coeffs, s))
        }
    }

    /// [`FallIntegrand::value`] with the polynomial `p`.
    #[inline(always)]
    fn value_with(&self, sh2: f64, p: impl Fn(f64) -> f64) -> f64 {
        let s = self.si - self.e * sh2;
        2.0 * (p(s) / (1.0 + s)).sqrt()
    }

    /// Half of [`FallIntegrand::value_with`] (the factor 2 is taken once per panel) at `N`
    /// nodes in the same arithmetic, without a branch between the lanes, so that the compiler
    /// packs them (`mulpd`, `divpd`, `sqrtpd`).
    #[inline(always)]
    fn half_values_with<const N: usize>(&self, sh2: [f64; N], p: &impl Fn(f64) -> f64) -> [f64; N] {
        let mut out = [0.0; N];
        for i in 0..N {
            let s = self.si - self.e * sh2[i];
            out[i] = (p(s) / (1.0 + s)).sqrt();
        }
        out
    }

    /// The rule on the panel `[a, b]` (`symmetric`: the first panel from rest, half of the rule
    /// on `[-b, b]`): each node takes its own `sinh^2`, and the values are checked once for the
    /// whole panel by [`PanelSum::ok`]. The polynomial's shape is decided once per panel.
    #[inline]
    pub fn panel(&self, rule: &HalfRule, a: f64, b: f64, symmetric: bool) -> PanelSum {
        self.panel_near(rule, a, b, symmetric)
    }

    /// [`FallIntegrand::panel`] compiled for AVX2 (four lanes in one register), with the same
    /// result to the bit (the same operations in the same order in every lane).
    ///
    /// # Safety
    /// Callable outside AVX2 code only in an `unsafe` block, and only where the CPU has AVX2
    /// (`is_x86_feature_detected!("avx2")`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub fn panel_avx2(&self, rule: &HalfRule, a: f64, b: f64, symmetric: bool) -> PanelSum {
        self.panel_near(rule, a, b, symmetric)
    }

    /// The body of [`FallIntegrand::panel`], inlined into each instruction set's copy.
    #[inline(always)]
    fn panel_near(&self, rule: &HalfRule, a: f64, b: f64, symmetric: bool) -> PanelSum {
        // Where every node lies within the series' reach (most panels), the lanes take it
        // without a test per node.
        let (centre, half) = panel_frame(symmetric, a, b);
        let farthest = centre.abs() + half * rule.reach;
        if self.low && farthest < SERIES_REACH {
            let [p0, p1, p2] = self.quadratic;
            self.panel_with::<Series>(rule, a, b, symmetric, |s| p0 + s * (p1 + s * p2))
        } else {
            self.panel_far(rule, a, b, symmetric)
        }
    }

    /// [`FallIntegrand::panel`] where a node lies beyond the series' reach or the polynomial's
    /// degree exceeds 2 (out of line, so that the common panel keeps its registers).
    #[cold]
    #[inline(never)]
    fn panel_far(&self, rule: &HalfRule, a: f64, b: f64, symmetric: bool) -> PanelSum {
        if self.low {
            let [p0, p1, p2] = self.quadratic;
            self.panel_with::<AnyReach>(rule, a, b, symmetric, |s| p0 + s * (p1 + s * p2))
        } else {
            self.panel_with::<AnyReach>(rule, a, b, symmetric, |s| horner(self.coeffs, s))
        }
    }

    /// [`FallIntegrand::panel`] with the polynomial `p`.
    #[inline(always)]
    fn panel_with<Sq: SinhSq>(
        &self,
        rule: &HalfRule,
        a: f64,
        b: f64,
        symmetric: bool,
        p: impl Fn(f64) -> f64,
    ) -> PanelSum {
        let (centre, half) = panel_frame(symmetric, a, b);
        // Sums of half values (the integrand over 2), and their least.
        let (acc, least) = if symmetric {
            // Half of the rule on [-b, b]: each node once (the integrand is even), a lane
            // each, summed across the lanes in one fixed order at the end.
            let (mut acc, mut least) = ([0.0; LANES], [f64::INFINITY; LANES]);
            for &Lane { x, w } in &rule.lanes {
                let f = self.half_values_with(Sq::lanes(x.map(|x| half * x)), &p);
                for i in 0..LANES {
                    least[i] = lesser(least[i], f[i]);
                    acc[i] += w[i] * f[i];
                }
            }
            (
                ((acc[0] + acc[1]) + acc[2]) + acc[3],
                lesser(lesser(lesser(least[0], least[1]), least[2]), least[3]),
            )
        } else {
            let (mut acc, mut least) = (0.0, f64::INFINITY);
            for &(x, w) in &rule.halved {
                let hx = half * x;
                let [up, down] = self.half_values_with(Sq::lanes([centre + hx, centre - hx]), &p);
                least = lesser(least, lesser(up, down));
                acc += w * (up + down);
            }
            (acc, least)
        };
        // Each node once; on a symmetric panel the nodes x >= 0 once.
        let evals = if symmetric {
            rule.nodes.div_ceil(2)
        } else {
            rule.nodes
        } as u64;
        PanelSum {
            value: 2.0 * half * acc,
            least: 2.0 * least,
            evals,
        }
    }
}

/// `v` where `sin(theta)` has dropped by `drop >= 0` from a start of scale `e`:
/// `asinh(sqrt(q))`, `q = drop / e`, as `log1p(x + q / (1 + sqrt(1 + q)))`, exact for small and
/// large `q` without `hypot`.
#[inline]
pub fn v_at_drop(e: f64, drop: f64) -> f64 {
    let q = drop.max(0.0) / e;
    (q.sqrt() + q / (1.0 + (1.0 + q).sqrt())).ln_1p()
}

/// A falling phase in the variable `v` of the module docs: what the integrand needs.
#[derive(Clone, Copy)]
pub struct Fall<'a> {
    model: &'static str,
    red: &'a dyn Reduction,
    k: &'a [f64],
    si: f64,
    ci: f64,
    e: f64,
    root_e: f64,
    from_rest: bool,
    /// The fall polynomial's coefficients (empty without one): the integrand is then
    /// `2 sqrt(P(s) / (1 + s))`, without `theta_dot^2`'s call.
    fall: &'a [f64],
    /// That integrand.
    integrand: FallIntegrand<'a>,
    /// The phase's end, for error messages.
    delta_end: f64,
}

impl std::fmt::Debug for Fall<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fall")
            .field("model", &self.model)
            .field("sin_theta_i", &self.si)
            .field("e", &self.e)
            .field("from_rest", &self.from_rest)
            .finish()
    }
}

impl<'a> Fall<'a> {
    /// The phase of a reduced system, ending at `delta_end` (for messages; the integral's end is
    /// given to [`integrate`]). Checks that it falls: from rest `theta_dot^2` must grow from the
    /// start, moving `theta_dot_i` must be negative, and `theta_i` must be below the vertical.
    ///
    /// `fall` holds the coefficients of the model's fall polynomial
    /// ([`Reduction::fall_polynomial`]) where it has one, else it is empty.
    #[inline(always)]
    pub fn new(
        model: &'static str,
        red: &'a dyn Reduction,
        k: &'a [f64],
        layout: &ReductionInfo,
        fall: &'a [f64],
        delta_end: f64,
    ) -> Result<Fall<'a>, SolveError> {
        let fall = Fall::geometry(model, red, k, layout, fall, delta_end)?;
        fall.check_falls(k[layout.k_theta_dot_initial])?;
        Ok(fall)
    }

    /// The phase's constants, checking only that it does not rise and starts below the
    /// vertical (what [`Fall::new`] checks before asking whether it falls).
    #[inline(always)]
    fn geometry(
        model: &'static str,
        red: &'a dyn Reduction,
        k: &'a [f64],
        layout: &ReductionInfo,
        fall: &'a [f64],
        delta_end: f64,
    ) -> Result<Fall<'a>, SolveError> {
        let theta_dot = k[layout.k_theta_dot_initial];
        let (si, ci) = (k[layout.k_sin_initial], k[layout.k_cos_initial]);
        if theta_dot > 0.0 {
            return Err(SolveError::Rising { model, theta_dot });
        }
        // 1 - sin(theta_i) without cancellation near upright.
        let e = ci * ci / (1.0 + si);
        if !(e > 0.0 && e.is_finite() && si.abs() < 1.0 && ci > 0.0) {
            return Err(SolveError::BeyondVertical {
                model,
                // The lean path prepares the start's sine and cosine, not the angle.
                theta_initial: si.atan2(ci),
            });
        }
        let from_rest = theta_dot == 0.0;
        let fall = if from_rest { fall } else { &[] };
        Ok(Fall {
            model,
            red,
            k,
            si,
            ci,
            e,
            root_e: e.sqrt(),
            from_rest,
            fall,
            integrand: FallIntegrand::new(si, e, fall),
            delta_end,
        })
    }

    /// From rest (or with a rate that is not a number) the rod must start to fall.
    #[inline(always)]
    fn check_falls(&self, theta_dot: f64) -> Result<(), SolveError> {
        // With a fall polynomial, one value of fixed shape settles the usual case.
        if self.integrand.low && theta_dot == 0.0 && self.integrand.falls() {
            return Ok(());
        }
        self.check_falls_by_value(theta_dot)
    }

    /// [`Fall::check_falls`] by the integrand's value just past the start.
    #[cold]
    fn check_falls_by_value(&self, theta_dot: f64) -> Result<(), SolveError> {
        let (model, red, k) = (self.model, self.red, self.k);
        let sh2 = FALL_CHECK_SH2;
        if self.from_rest || theta_dot.is_nan() {
            // The rod must start to fall: theta_dot^2 positive just past the start (at
            // sinh v = 1e-4, a drop of 1e-8 e; one rational evaluation, the trigonometry of
            // `reduced` only for the message).
            let falls = self.value(sh2.sqrt(), (1.0 + sh2).sqrt());
            if theta_dot.is_nan() || falls.is_err() {
                let theta_ddot = red.reduced(k, 0.0).theta_ddot;
                return Err(match falls {
                    // It does start to fall, and theta_dot^2 itself is broken just past the start.
                    Err(broken) if theta_ddot < 0.0 && !theta_dot.is_nan() => broken,
                    _ => SolveError::NoMotion {
                        model,
                        theta_dot,
                        theta_ddot,
                    },
                });
            }
        }
        Ok(())
    }

    /// The phase of a reduced [`System`] from its start.
    pub fn of(sys: &'a System, delta_end: f64) -> Result<Fall<'a>, SolveError> {
        Fall::new(
            sys.name(),
            sys.reduction(),
            sys.k(),
            sys.layout(),
            sys.fall_coefficients(),
            delta_end,
        )
    }

    /// The phase of a [`TimeMesh`] already built (and so checked) on `sys`: its constants only.
    fn of_mesh(sys: &'a System, mesh: &TimeMesh) -> Result<Fall<'a>, SolveError> {
        Fall::geometry(
            sys.name(),
            sys.reduction(),
            sys.k(),
            sys.layout(),
            sys.fall_coefficients(),
            mesh.delta_end,
        )
    }

    /// Whether the phase starts from rest (its integrand is then even in `v`).
    pub fn from_rest(&self) -> bool {
        self.from_rest
    }

    /// `sin(theta_i)`.
    pub fn sin_initial(&self) -> f64 {
        self.si
    }

    /// `e = 1 - sin(theta_i)`, the scale of the substitution `s = sin(theta_i) - e sinh^2 v`.
    pub fn scale(&self) -> f64 {
        self.e
    }

    /// The fall polynomial's coefficients (empty when the phase has none).
    pub fn fall_polynomial(&self) -> &'a [f64] {
        self.fall
    }

    /// `v` where `sin(theta)` has dropped by `drop >= 0`: `asinh(sqrt(q))`, `q = drop / e`, as
    /// `log1p(x + q / (1 + sqrt(1 + q)))`, exact for small and large `q` without `hypot`.
    pub fn v_at_drop(&self, drop: f64) -> f64 {
        v_at_drop(self.e, drop)
    }

    /// `v` at the angle fallen `delta`.
    pub fn v_at_delta(&self, delta: f64) -> f64 {
        let theta_i = self.si.asin();
        let (_, _, ds, _) = start_offsets(theta_i, self.si, self.ci, delta);
        self.v_at_drop(ds)
    }

    /// The angle fallen at `v`: `atan2(sin(delta), cos(delta))` from the drops, without the
    /// cancellation of `theta_i - theta`.
    pub fn delta_at(&self, v: f64) -> f64 {
        let (sh, ch) = sinh_cosh(v);
        let n = self.node(sh, ch);
        (self.ci * n.ds - self.si * n.dc).atan2(self.ci * n.c + self.si * n.s)
    }

    /// `dt/dv` at `v`.
    pub fn rate(&self, v: f64) -> Result<f64, SolveError> {
        let (sh, ch) = sinh_cosh(v.abs());
        self.value(sh, ch)
    }

    /// The integrand at `v = 0`: 0 when moving; from rest its limit
    /// `2 / sqrt(-2 theta_ddot_i (1 + sin theta_i) / cos theta_i)` (`theta_dot^2 ~ -2
    /// theta_ddot_i delta`, `delta ~ w / cos theta_i`), evaluated only by rules with a node
    /// there.
    fn centre_value(&self) -> Result<f64, SolveError> {
        if !self.from_rest {
            return Ok(0.0);
        }
        let theta_ddot = self.red.reduced(self.k, 0.0).theta_ddot;
        let value = 2.0 / (-2.0 * theta_ddot * (1.0 + self.si) / self.ci).sqrt();
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(SolveError::NonFinite {
                model: self.model,
                what: "the time integrand's limit at the start",
                delta: 0.0,
                value,
            })
        }
    }

    /// The angle at `v` (given by `sinh v`, `cosh v`): `sin(theta)` and `cos(theta)` with their
    /// drops from the start, formed without cancellation (module docs).
    #[inline]
    fn node(&self, sh: f64, ch: f64) -> Node {
        let ds = self.e * sh * sh;
        let s = self.si - ds;
        let plus = 1.0 + s;
        let c = self.root_e * ch * plus.sqrt();
        let dc = -ds * (self.si + s) / (self.ci + c);
        Node { s, c, ds, dc, plus }
    }

    /// The integrand at the node given by its `sinh v` and `cosh v` (`v >= 0`).
    #[inline]
    fn value(&self, sh: f64, ch: f64) -> Result<f64, SolveError> {
        if !self.fall.is_empty() {
            let f = self.integrand.value(sh * sh);
            if f.is_nan() || f.is_infinite() || f <= 0.0 {
                return Err(self.bad_fall(sh * sh));
            }
            return Ok(f);
        }
        if sh == 0.0 {
            return self.centre_value();
        }
        let n = self.node(sh, ch);
        let w2 = self.red.theta_dot_sq_sc(self.k, n.s, n.c, n.ds, n.dc);
        if !(w2 > 0.0 && w2.is_finite()) {
            return Err(self.bad_value(n.s, w2));
        }
        Ok(2.0 * self.root_e * sh / (n.plus * w2).sqrt())
    }

    /// The error for a fall polynomial that is not positive and finite at `sinh^2 v = sh2`.
    fn bad_fall(&self, sh2: f64) -> SolveError {
        let ds = self.e * sh2;
        let s = self.si - ds;
        self.bad_value(s, ds / horner(self.fall, s))
    }

    /// [`Fall::panel`] with a fall polynomial ([`FallIntegrand::panel`]); a panel whose values
    /// are not all positive and finite is searched node by node for the error.
    fn panel_fall(&self, rule: &HalfRule, a: f64, b: f64) -> Result<(f64, u64), SolveError> {
        let symmetric = self.symmetric(a);
        let sum = self.integrand.panel(rule, a, b, symmetric);
        if !sum.ok() {
            let (centre, half) = panel_frame(symmetric, a, b);
            let nodes = std::iter::once(0.0).chain(rule.pairs.iter().flat_map(|&(x, _)| [x, -x]));
            for x in nodes {
                let v = if symmetric {
                    half * x
                } else {
                    centre + half * x
                };
                self.value(sinh_sq(v).sqrt(), 1.0)?;
            }
        }
        Ok((sum.value, sum.evals))
    }

    /// The error for a `theta_dot^2` that is not positive and finite at `sin(theta) = s`.
    fn bad_value(&self, s: f64, w2: f64) -> SolveError {
        let delta = self.si.asin() - s.asin();
        if w2.is_finite() {
            SolveError::TurningPoint {
                model: self.model,
                delta,
                theta_dot_sq: w2,
                delta_end: self.delta_end,
            }
        } else {
            SolveError::NonFinite {
                model: self.model,
                what: "theta_dot^2",
                delta,
                value: w2,
            }
        }
    }

    /// Whether the panel `[a, b]` is the symmetric first panel of a phase from rest.
    fn symmetric(&self, a: f64) -> bool {
        self.from_rest && a == 0.0
    }

    /// The panel's length as its rules see it (a symmetric panel spans `[-b, b]`).
    fn span(&self, a: f64, b: f64) -> f64 {
        if self.symmetric(a) { 2.0 * b } else { b - a }
    }

    /// The rule on the panel `[a, b]`: `(integral, evaluations)`.
    ///
    /// On a symmetric panel the nodes are `b x` and the values serve `+x` and `-x`. Otherwise
    /// the nodes `mid +- h x` share one exponential: `sinh(mid +- h x)` and `cosh(mid +- h x)`
    /// follow from those of `mid` and of `h x` by the addition theorems. The difference
    /// `sinh(mid - h x)` loses up to a factor `exp(2 h x)` to cancellation, so beyond
    /// `h x = ADDITION_REACH` (a factor 2) that node takes its own exponential. Iterations do not depend on each other but through the sum, so the divisions and
    /// roots of different nodes overlap.
    pub(crate) fn panel(&self, rule: &HalfRule, a: f64, b: f64) -> Result<(f64, u64), SolveError> {
        if !self.fall.is_empty() {
            return self.panel_fall(rule, a, b);
        }
        let mut acc = 0.0;
        if self.symmetric(a) {
            if rule.centre != 0.0 {
                acc = 0.5 * rule.centre * self.value(0.0, 1.0)?;
            }
            for &(x, w) in &rule.pairs {
                let (sx, cx) = sinh_cosh(b * x);
                acc += w * self.value(sx, cx)?;
            }
            // integral over [0, b] = half the rule over [-b, b].
            let evals = rule.pairs.len() + usize::from(rule.centre != 0.0);
            return Ok((b * acc, evals as u64));
        }
        let (half, mid) = (0.5 * (b - a), 0.5 * (a + b));
        let (sm, cm) = sinh_cosh(mid);
        let mut evals = 2 * rule.pairs.len() as u64;
        if rule.centre != 0.0 {
            acc = rule.centre * self.value(sm, cm)?;
            evals += 1;
        }
        for &(x, w) in &rule.pairs {
            let hx = half * x;
            let (sx, cx) = sinh_cosh(hx);
            let up = self.value(sm * cx + cm * sx, cm * cx + sm * sx)?;
            // The difference loses a factor up to exp(2 h x): beyond 2 its own exponential.
            let (sd, cd) = if hx <= ADDITION_REACH {
                (sm * cx - cm * sx, cm * cx - sm * sx)
            } else {
                sinh_cosh(mid - hx)
            };
            let down = self.value(sd, cd)?;
            acc += w * (up + down);
        }
        Ok((half * acc, evals))
    }

    /// The fine rule of the step for `span` on `[a, b]`, `a` the start of an accepted panel and
    /// `b` inside it: the time from `a` to `b`.
    fn partial(
        &self,
        control: &Control,
        span: f64,
        a: f64,
        b: f64,
    ) -> Result<(f64, u64), SolveError> {
        let (_, fine) = control.step_for(span);
        self.panel(fine, a, b)
    }
}

/// `t` from the phase's start (`v = 0`) to `v_end`, panel by panel under `control`; each
/// accepted panel goes to `keep`, in ascending order. Returns the integral and the integrand
/// evaluations. `stack` is scratch, reused across calls.
pub fn integrate(
    fall: &Fall,
    v_end: f64,
    control: &Control,
    stack: &mut Vec<(f64, f64)>,
    mut keep: impl FnMut(Panel),
) -> Result<(f64, u64), SolveError> {
    if !(v_end >= 0.0 && v_end.is_finite()) {
        return Err(SolveError::BadPhaseEnd {
            model: fall.model,
            delta_end: fall.delta_end,
        });
    }
    stack.clear();
    if v_end == 0.0 {
        return Ok((0.0, 0));
    }
    // The a-priori cut: a first panel of span at most the longest step's, then equal pieces.
    let longest = control.longest();
    let first = if fall.from_rest {
        v_end.min(0.5 * longest)
    } else {
        v_end.min(longest)
    };
    let rest = v_end - first;
    let pieces = if rest > 0.0 {
        ((rest / longest).ceil() as usize).clamp(1, MAX_PANELS)
    } else {
        0
    };
    for i in (0..pieces).rev() {
        let lo = first + rest * i as f64 / pieces as f64;
        let hi = if i + 1 == pieces {
            v_end
        } else {
            first + rest * (i + 1) as f64 / pieces as f64
        };
        stack.push((lo, hi));
    }
    stack.push((0.0, first));
    let (mut total, mut evals, mut panels) = (0.0, 0u64, 0usize);
    while let Some((lo, hi)) = stack.pop() {
        let (coarse, fine) = control.step_for(fall.span(lo, hi));
        let (coarse, n_coarse) = fall.panel(coarse, lo, hi)?;
        let (fine, n_fine) = fall.panel(fine, lo, hi)?;
        evals += n_coarse + n_fine;
        let error = (fine - coarse).abs();
        panels += 1;
        if fine.is_finite() && error <= control.accept * fine.abs() {
            total += fine;
            keep(Panel {
                a: lo,
                b: hi,
                value: fine,
            });
            continue;
        }
        let mid = 0.5 * (lo + hi);
        if !(fine.is_finite() && mid > lo && mid < hi) || panels + stack.len() > MAX_PANELS {
            return Err(SolveError::QuadratureNotConverged {
                a: 0.0,
                b: v_end,
                tol: control.accept,
                estimate: total + fine,
                error,
                panels,
            });
        }
        stack.push((mid, hi));
        stack.push((lo, mid));
    }
    Ok((total, evals))
}

/// `t(delta)` on one phase, from its start to `delta_end`, kept as accepted panels in `v`.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMesh {
    /// Angle fallen at the end of the phase.
    pub delta_end: f64,
    /// `v` at the end.
    pub v_end: f64,
    /// Accepted panels in `v`.
    pub panels: Vec<Panel>,
    /// Time at the start of each panel.
    starts: Vec<f64>,
    /// Time from the phase start to `delta_end` (s).
    pub duration: f64,
    /// The error control the panels were accepted under.
    control: Control,
}

impl TimeMesh {
    /// The mesh of a phase of no length (a contact that opens at its start).
    pub fn empty() -> TimeMesh {
        TimeMesh {
            delta_end: 0.0,
            v_end: 0.0,
            panels: Vec::new(),
            starts: Vec::new(),
            duration: 0.0,
            control: Control::with_tolerance(ACCEPT),
        }
    }

    /// Integrates the phase of `sys` from its start to `delta_end` to relative tolerance `tol`
    /// (the two rules of every panel agree to `tol * TOL_SAFETY`, raised to [`MIN_TOL`]).
    pub fn build(
        sys: &System,
        delta_end: f64,
        tol: f64,
        work: &mut Work,
    ) -> Result<TimeMesh, SolveError> {
        if !(delta_end > 0.0 && delta_end.is_finite()) {
            return Err(SolveError::BadPhaseEnd {
                model: sys.name(),
                delta_end,
            });
        }
        let fall = Fall::of(sys, delta_end)?;
        let control = Control::with_tolerance(tol * TOL_SAFETY);
        let v_end = fall.v_at_delta(delta_end);
        let mut panels = Vec::new();
        let (duration, evals) =
            integrate(&fall, v_end, &control, &mut Vec::new(), |p| panels.push(p))?;
        work.integrand_evals += evals;
        let mut starts = Vec::with_capacity(panels.len());
        let mut t = 0.0;
        for p in &panels {
            starts.push(t);
            t += p.value;
        }
        Ok(TimeMesh {
            delta_end,
            v_end,
            panels,
            starts,
            duration,
            control,
        })
    }

    /// Time from the phase start to `v`, for `0 <= v <= v_end` (a relative overshoot of up to
    /// 1e-6 past the end is extrapolated on the last panel). One partial panel.
    pub fn time_at_v(&self, sys: &System, v: f64, work: &mut Work) -> Result<f64, SolveError> {
        if !(v >= 0.0 && v <= self.v_end * (1.0 + 1e-6)) {
            return Err(SolveError::OutsidePhase {
                model: sys.name(),
                delta: self.delta_at_v(sys, v)?,
                delta_end: self.delta_end,
            });
        }
        if v == 0.0 || self.panels.is_empty() {
            return Ok(0.0);
        }
        let i = self.panels.partition_point(|p| p.a < v).saturating_sub(1);
        let p = self.panels[i];
        if v == p.b {
            return Ok(self.starts[i] + p.value);
        }
        let fall = Fall::of_mesh(sys, self)?;
        let (t, evals) = fall.partial(&self.control, fall.span(p.a, p.b), p.a, v)?;
        work.integrand_evals += evals;
        Ok(self.starts[i] + t)
    }

    /// Time from the phase start to the angle fallen `delta`.
    pub fn time_at_delta(
        &self,
        sys: &System,
        delta: f64,
        work: &mut Work,
    ) -> Result<f64, SolveError> {
        if delta.is_nan() || delta < 0.0 || delta > self.delta_end * (1.0 + 1e-6) {
            return Err(SolveError::OutsidePhase {
                model: sys.name(),
                delta,
                delta_end: self.delta_end,
            });
        }
        let v = if delta == self.delta_end {
            self.v_end
        } else {
            Fall::of_mesh(sys, self)?.v_at_delta(delta)
        };
        self.time_at_v(sys, v, work)
    }

    /// The angle fallen at `v`.
    pub fn delta_at_v(&self, sys: &System, v: f64) -> Result<f64, SolveError> {
        if v == self.v_end {
            return Ok(self.delta_end);
        }
        Ok(Fall::of_mesh(sys, self)?.delta_at(v))
    }

    /// `dt/dv` at `v`.
    pub fn rate_at_v(&self, sys: &System, v: f64, work: &mut Work) -> Result<f64, SolveError> {
        work.integrand_evals += 1;
        Fall::of_mesh(sys, self)?.rate(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinh_squared_keeps_its_digits_on_both_sides_of_the_series_reach() {
        // Against the library's sinh (within an ulp), squared: a few ulps apart at most, on a
        // grid dense around SERIES_REACH, where the series is at its longest reach.
        let mut worst = 0.0f64;
        let ys = (1..=4000).map(|i| 3.0 * i as f64 / 4000.0);
        let near = (-50..=50).map(|i| SERIES_REACH + i as f64 * f64::EPSILON);
        for y in ys.chain(near).chain([1e-300, 1e-8, 1e-3, 0.3]) {
            let want = y.sinh().powi(2);
            for got in [
                sinh_sq(y),
                sinh_sq(-y),
                AnyReach::lanes([y, 0.1])[0],
                AnyReach::lanes([2.0, y, 0.3, 1.0])[1],
            ] {
                worst = worst.max(((got - want) / want).abs());
            }
        }
        assert!(
            worst <= 4.0 * f64::EPSILON,
            "worst {:.2} ulps",
            worst / f64::EPSILON
        );
    }

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

    #[test]
    fn sinh_cosh_is_accurate_small_and_large() {
        for x in [1e-300, 1e-8, 0.3, 2.0, 30.0] {
            let (s, c) = sinh_cosh(x);
            assert!(((s - x.sinh()) / x.sinh()).abs() < 4e-16, "{x}");
            assert!(((c - x.cosh()) / x.cosh()).abs() < 4e-16, "{x}");
        }
    }
}
