//! The time integrand of a phase from rest with a fall polynomial, `2 sqrt(P(s) / (1 + s))`
//! ([`FallIntegrand`]), and one panel's rule applied to it ([`PanelSum`]): nodes four at a
//! time in the same arithmetic, in a baseline and an AVX2 build of the same source.

use super::hyperbolic::{AnyReach, SERIES_REACH, Series, SinhSq};
use super::rules::{HalfRule, LANES, Lane};
use crate::solve::fast::poly::horner;

/// `sinh^2 v` just past the start where [`Fall::new`] asks whether the phase falls.
pub(super) const FALL_CHECK_SH2: f64 = 1e-8;

/// `(centre, half-length)` of the panel `[a, b]` as its rule sees it: a symmetric first panel
/// from rest spans `[-b, b]`.
#[inline(always)]
pub(super) fn panel_frame(symmetric: bool, a: f64, b: f64) -> (f64, f64) {
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
    pub(super) low: bool,
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
    pub(super) fn value(&self, sh2: f64) -> f64 {
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
    /// result to the bit (the same operations in the same order in every lane). Marked
    /// `#[inline]` like `panel`, so that the AVX2 copy of the per-point route takes it into its
    /// panel's closure rather than calling it (18 instructions a point of
    /// `examples/per_point.rs`).
    ///
    /// # Safety
    /// Callable outside AVX2 code only in an `unsafe` block, and only where the CPU has AVX2
    /// (`is_x86_feature_detected!("avx2")`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
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
