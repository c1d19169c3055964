//! The a-priori rule: for a phase with a fall polynomial `P` of degree at most 2, the time
//! integrand `2 sqrt(P(s) / (1 + s))` (see [`quadrature`](crate::solve::fast::quadrature)) is
//! singular only where `P(s) = 0` and at `s = -1`, so where its singularities lie in the
//! variable `v` is known before any evaluation, and with it how many Gauss–Legendre nodes a
//! panel needs.
//!
//! # The rule
//! A function analytic inside the Bernstein ellipse of parameter `rho` around a panel (foci at
//! the panel's ends, `rho = a + b` with semi-axes `a`, `b` over the half-length) is integrated by
//! the Gauss–Legendre rule of `N` nodes with an error of order `rho^(-2N)` (Trefethen,
//! *Approximation Theory and Approximation Practice*, ch. 19). The singularities in `s` map to
//! `v` through `sinh^2 v = (sin theta_i - s) / e`; each gives one nearest point `v*` (the
//! others are `-v*` and shifts by `i pi`, farther from a panel on `v >= 0`). A panel takes the
//! fewest nodes `N` with `rho^(2N) >= PRIOR_MARGIN / tol` for the smallest `rho` over the points
//! (a threshold table, scanned from a start that a small table looks up by `rho`'s float
//! bits; the points' real parts are lower bounds from the logarithm's chord
//! between powers of two, within `0.06`, which can only bring them nearer and ask for more
//! nodes); a panel that would need more than
//! [`PRIOR_MAX_NODES`] is halved. From rest the first panel `[0, b]` is half of the symmetric
//! rule on `[-b, b]` and costs half its nodes.
//!
//! This replaces the verified pair of rules of
//! [`integrate`](crate::solve::fast::quadrature::integrate) by a bound: its margin was set by
//! comparing with the verified quadrature and the 256-bit reference (`tests/hard_cases.rs`,
//! `tests/prior.rs`) over every model with a fall polynomial and the hard-case ranges of `n` and
//! `a/ell`. Models whose fall polynomial has a higher degree, or that have none, take the verified
//! route.

use crate::solve::SolveError;
use crate::solve::fast::quadrature::{Fall, HalfRule, half_rule};
use std::f64::consts::FRAC_PI_2;

/// Most nodes of a panel's rule before it is halved.
pub const PRIOR_MAX_NODES: usize = 48;

/// Fewest nodes of a panel's rule.
pub const PRIOR_MIN_NODES: usize = 4;

/// Most panels of one integral before the a-priori route gives way to the verified one.
pub const PRIOR_MAX_PANELS: usize = 64;

/// How far below `ln(y)` the bound of the singular points' real parts may lie:
/// `max over m in [1, 2] of ln m - (m - 1) ln 2`, at `m = 1 / ln 2` (`0.0596`), with room for
/// rounding. Nearer points only ask for more nodes: over the per-point set of
/// `examples/per_point.rs` the integrand takes 0.14 evaluations per point more than with
/// exact logarithms, and the bound costs a tenth of a logarithm.
pub const LN_BELOW_GAP: f64 = 0.0597;

/// Depth of the halving (panels waiting at once; depth `d` leaves at most `d + 1`).
const PRIOR_STACK: usize = 24;

/// The factor on `rho^(-2N)` the rule guards against: the integrand's size on the ellipse
/// relative to its mean (it grows like `|v - v*|^(-1/2)` near `s = -1`) and the bound's
/// constant `64 / (15 (rho^2 - 1))`. Set from the comparisons of the module docs with a
/// hundredfold margin over the largest factor seen.
pub const PRIOR_MARGIN: f64 = 1e2;

/// The relative error the per-point solver asks of the a-priori rule (`2^-53`).
pub const PRIOR_TOL: f64 = f64::EPSILON / 2.0;

/// Mantissa bits of `rho` that index [`Prior`]'s table of scan starts (`2^6` cells per octave:
/// a cell spans under two thresholds where they are densest, near the fewest panels' `rho`).
const START_BITS: u32 = 6;

/// Octaves of `rho` from 1 that the table covers (`rho` beyond `2^8` starts the scan at the
/// fewest nodes; with the tolerance at least `2^-53` every threshold lies below `2^8`).
const START_OCTAVES: usize = 8;

// Every start (at most the count of thresholds) fits the table's bytes.
const _: () = assert!(PRIOR_MAX_NODES - PRIOR_MIN_NODES < u8::MAX as usize);

/// Rules and node-count thresholds for one tolerance, made once per solver.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// `thresholds[j]`: the least `rho` for which `PRIOR_MIN_NODES + j` nodes suffice.
    thresholds: Vec<f64>,
    /// For each cell of `rho` (its float's exponent from 0 and top [`START_BITS`] mantissa
    /// bits), the first `j` whose threshold the cell's top reaches: no `rho` in the cell needs
    /// fewer nodes, so the scan for `rho` starts there (about one step instead of ten).
    starts: Vec<u8>,
    /// The Gauss–Legendre rules of `PRIOR_MIN_NODES + j` nodes.
    rules: Vec<&'static HalfRule>,
    /// Relative error asked.
    pub tol: f64,
}

impl Prior {
    /// Rules for a relative error `tol` (raised to `2^-53`; not finite means `2^-53`).
    pub fn new(tol: f64) -> Prior {
        let tol = if tol.is_finite() {
            tol.max(PRIOR_TOL)
        } else {
            PRIOR_TOL
        };
        let log_ratio = (PRIOR_MARGIN / tol).ln();
        let counts = PRIOR_MIN_NODES..=PRIOR_MAX_NODES;
        let thresholds: Vec<f64> = counts
            .clone()
            .map(|n| (log_ratio / (2.0 * n as f64)).exp())
            .collect();
        let starts = (0..START_OCTAVES << START_BITS)
            .map(|cell| {
                let top = cell_start(cell + 1);
                // At most the count of thresholds, which fits (below).
                first_reached(&thresholds, top, 0) as u8
            })
            .collect();
        Prior {
            thresholds,
            starts,
            rules: counts.map(half_rule).collect(),
            tol,
        }
    }

    /// The rule for a panel whose nearest singularity has Bernstein parameter `rho`, if one of
    /// at most [`PRIOR_MAX_NODES`] nodes suffices: the fewest nodes whose threshold `rho`
    /// reaches, by a scan from the table's start for `rho`'s cell. Always inlined, as
    /// [`prior_panels`] is.
    #[inline(always)]
    fn rule_for(&self, rho: f64) -> Option<&'static HalfRule> {
        // The cell from the float's bits above 1.0's; rho below 1, NaN, or beyond the table
        // (its bits wrap or run past it) scans from the fewest nodes, which is exact too.
        let cell = rho.to_bits().wrapping_sub(1f64.to_bits()) >> (52 - START_BITS);
        let start = usize::try_from(cell)
            .ok()
            .and_then(|c| self.starts.get(c))
            .map_or(0, |&j| usize::from(j));
        self.rules
            .get(first_reached(&self.thresholds, rho, start))
            .copied()
    }
}

/// The least `rho` of table cell `cell` (the float whose bits are 1.0's plus the cell's).
fn cell_start(cell: usize) -> f64 {
    f64::from_bits(1f64.to_bits() + ((cell as u64) << (52 - START_BITS)))
}

/// The first `j >= from` with `rho >= thresholds[j]` (thresholds fall with `j`), or
/// `thresholds.len()` when there is none.
#[inline(always)]
fn first_reached(thresholds: &[f64], rho: f64, from: usize) -> usize {
    let mut j = from;
    while let Some(&t) = thresholds.get(j) {
        if rho >= t {
            return j;
        }
        j += 1;
    }
    thresholds.len()
}

/// The points of the `v` plane where a fall's integrand is singular, one per singular value
/// of `s`, as `(x, y)` for `v* = x + i y` with `x >= 0` and `0 <= y <= pi/2`: the nearest on
/// the real axis, the others off it. A real zero of the polynomial above the start whose point
/// lies on the line `y = pi/2` keeps only its `cosh(x)`: its real part (a logarithm) is taken
/// only for a panel where that line comes nearer than the points already seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Singularities {
    /// `x` of the nearest point on the real axis (a lower bound).
    real: f64,
    /// Points off the real axis, `(x, y)` with `y > 0`.
    points: [(f64, f64); 2],
    len: usize,
    /// `cosh(x)` of points at `x + i pi/2`, `x` not yet bounded.
    on_line: [f64; 2],
    line_len: usize,
}

impl Singularities {
    /// The singular points of the integrand of a phase starting at `sin(theta_i) = si` with
    /// scale `e = 1 - si` and a fall polynomial `coeffs` (lowest degree first), or `None` when
    /// the polynomial has a degree above 2 or a zero at the start.
    #[inline(always)]
    pub fn of(si: f64, e: f64, coeffs: &[f64]) -> Option<Singularities> {
        let mut out = Singularities::NONE;
        out.find(si, e, coeffs).map(|()| out)
    }

    /// No points (the start of [`Singularities::find`]).
    pub(crate) const NONE: Singularities = Singularities {
        real: 0.0,
        points: [(0.0, 0.0); 2],
        len: 0,
        on_line: [0.0; 2],
        line_len: 0,
    };

    /// [`Singularities::of`] in place, into points that are [`Singularities::NONE`] (so that
    /// the route, which keeps the points where the plan reads them, does not copy them out of
    /// an `Option`).
    #[inline(always)]
    pub(crate) fn find(&mut self, si: f64, e: f64, coeffs: &[f64]) -> Option<()> {
        let out = self;
        // Real singularities below the start lie on the real v axis, the nearest (largest s)
        // hiding the others: s = -1 and the real zeros of P below sin(theta_i).
        let mut below = -1.0f64;
        let mut real = |s: f64, out: &mut Singularities| out.real(si, e, s, &mut below);
        match *coeffs {
            // A constant, also padded to a quadratic with zeros: no zero.
            [] | [_] | [_, 0.0, 0.0] => {}
            [p0, p1] => real(-p0 / p1, out)?,
            [p0, p1, 0.0] => real(-p0 / p1, out)?,
            [p0, p1, p2] => {
                let disc = p1 * p1 - 4.0 * p0 * p2;
                if disc >= 0.0 {
                    // Both real, without cancellation.
                    let q = -0.5 * (p1 + disc.sqrt().copysign(p1));
                    real(q / p2, out)?;
                    real(p0 / q, out)?;
                } else {
                    // A conjugate pair: one representative (the ellipses are symmetric).
                    let p = complex(si, e, -0.5 * p1 / p2, 0.5 * (-disc).sqrt() / p2.abs());
                    out.push(p);
                }
            }
            _ => return None,
        }
        out.real = asinh_sqrt((si - below) / e);
        // Every coordinate is at least 0 (or NaN), and entries not set are zeros: their sum is
        // finite exactly when each is, by one test.
        let sum = out.real
            + out.points.iter().map(|&(x, y)| x + y).sum::<f64>()
            + out.on_line.iter().sum::<f64>();
        sum.is_finite().then_some(())
    }

    /// A real singular `s`: below the start it may be the nearest of those on the real axis
    /// (kept in `below`), above it a point of its own; at the start, none (`None`).
    #[inline(always)]
    fn real(&mut self, si: f64, e: f64, s: f64, below: &mut f64) -> Option<()> {
        if s < si {
            // `s` is no NaN here (it compared below `si`): a plain comparison, not `max`.
            if s > *below {
                *below = s;
            }
            Some(())
        } else if s > si {
            self.above(si, e, s);
            Some(())
        } else {
            None
        }
    }

    /// The point for a real singular `s > sin(theta_i)`: `sinh v = i y`, `y = sqrt((s - si) /
    /// e)`, so `v = i asin(y)` for `y <= 1` and `v = acosh(y) + i pi/2` beyond (kept as `y`).
    #[inline(always)]
    fn above(&mut self, si: f64, e: f64, s: f64) {
        let y = ((s - si) / e).sqrt();
        if y <= 1.0 {
            self.push((0.0, y.asin()));
        } else if self.line_len < self.on_line.len() {
            self.on_line[self.line_len] = y;
            self.line_len += 1;
        }
    }

    #[inline(always)]
    fn push(&mut self, p: (f64, f64)) {
        if self.len < self.points.len() {
            self.points[self.len] = p;
            self.len += 1;
        }
    }

    /// The Bernstein parameter of the nearest point for the panel of centre `c` and
    /// half-length `h`: `rho = alpha + sqrt(alpha^2 - 1)`, `alpha` the least over the points
    /// of the mean distance to the panel's ends over `h`. Points on the line `y = pi/2` are
    /// passed over while `alpha <= sqrt(1 + (pi / 2h)^2)`, their least (the ellipse through a
    /// point has a semi-minor axis of at least its `y`).
    #[inline(always)]
    fn rho(&self, c: f64, h: f64) -> f64 {
        let mut alpha = mean_distance(self.real, 0.0, c, h);
        for &(x, y) in &self.points[..self.len] {
            alpha = alpha.min(mean_distance(x, y, c, h));
        }
        if self.line_len > 0 {
            let w = FRAC_PI_2 / h;
            if 1.0 + w * w < alpha * alpha {
                for &y in &self.on_line[..self.line_len] {
                    alpha = alpha.min(mean_distance(acosh_below(y), FRAC_PI_2, c, h));
                }
            }
        }
        alpha + ((alpha - 1.0) * (alpha + 1.0)).max(0.0).sqrt()
    }
}

/// The mean distance from `x + i y` to the ends of the panel of centre `c` and half-length `h`,
/// over `h` (the ellipse's semi-major axis): `max(|u|, 1)` on the real axis.
#[inline(always)]
fn mean_distance(x: f64, y: f64, c: f64, h: f64) -> f64 {
    let u = (x - c) / h;
    if y == 0.0 {
        u.abs().max(1.0)
    } else {
        let w2 = (y / h) * (y / h);
        0.5 * (((u - 1.0) * (u - 1.0) + w2).sqrt() + ((u + 1.0) * (u + 1.0) + w2).sqrt())
    }
}

/// A lower bound of `asinh(sqrt(z))` for `z >= 0`: for `u = sqrt(z) < 1/2` its series to
/// `u^7` (alternating, cut after a negative term; within `1.2e-4` relative), else
/// [`ln_below`] of `u + sqrt(1 + u^2)` (within [`LN_BELOW_GAP`]). A singular point placed
/// nearer than it is only asks for more nodes, so a bound serves where the logarithm would cost
/// several times as much.
#[inline(always)]
fn asinh_sqrt(z: f64) -> f64 {
    let u = z.sqrt();
    if u < 0.5 {
        let z = u * u;
        u * (1.0 - z * (1.0 / 6.0 - z * (3.0 / 40.0 - z * (15.0 / 336.0)))) * (1.0 - 1e-15)
    } else {
        ln_below(u + (1.0 + z).sqrt())
    }
}

/// A lower bound of `ln(y)` for `y >= 1`, within [`LN_BELOW_GAP`]: `y = 2^k m` with `m` in
/// `[1, 2)` (the exponent and mantissa of the float), and `ln m` bounded below by its chord
/// `(m - 1) ln 2` (the logarithm is concave); the factor `1 - 1e-15` covers the rounding of
/// `k + m - 1` and of `ln 2`. Infinity and NaN are returned as they are.
#[inline(always)]
fn ln_below(y: f64) -> f64 {
    if !y.is_finite() {
        return y;
    }
    let bits = y.to_bits();
    let k = ((bits >> 52) & 0x7ff) as f64 - 1023.0;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    (k + m - 1.0) * std::f64::consts::LN_2 * (1.0 - 1e-15)
}

/// A lower bound of `acosh(y)` for `y > 1` (within [`LN_BELOW_GAP`]), as [`ln_below`] of
/// `y + sqrt(y^2 - 1)`.
#[inline(always)]
fn acosh_below(y: f64) -> f64 {
    ln_below(y + ((y - 1.0) * (y + 1.0)).sqrt()).max(0.0)
}

/// The point for a complex singular `s = re + i im`: `v* = asinh(sqrt(z))`, `z = (si - s) / e`,
/// as `log(sqrt(z) + sqrt(z + 1))`, then brought to `x >= 0`, `0 <= y <= pi/2`.
fn complex(si: f64, e: f64, re: f64, im: f64) -> (f64, f64) {
    let z = ((si - re) / e, -im / e);
    let a = csqrt(z);
    let b = csqrt((z.0 + 1.0, z.1));
    let (sr, si_) = (a.0 + b.0, a.1 + b.1);
    let (mut x, mut y) = ((sr * sr + si_ * si_).sqrt().ln(), si_.atan2(sr));
    if x < 0.0 {
        (x, y) = (-x, -y);
    }
    // y modulo pi into (-pi/2, pi/2], then its size (the conjugate is a singularity too).
    y -= std::f64::consts::PI * (y / std::f64::consts::PI).round();
    (x, y.abs())
}

/// Principal square root of `re + i im`.
fn csqrt((re, im): (f64, f64)) -> (f64, f64) {
    let r = (re * re + im * im).sqrt();
    let a = (0.5 * (r + re.abs())).sqrt();
    if a == 0.0 {
        return (0.0, 0.0);
    }
    if re >= 0.0 {
        (a, 0.5 * im / a)
    } else {
        (0.5 * im.abs() / a, a.copysign(im))
    }
}

/// `t` from the start of a fall (from rest, with a fall polynomial) to `v_end` by the a-priori
/// rule: `Ok(None)` when the rule does not apply (no fall polynomial of degree at most 2, a
/// singularity on the path, or more than [`PRIOR_MAX_PANELS`] panels), so that the caller
/// takes the verified route. Returns the integral and the integrand evaluations.
pub fn integrate_prior(
    fall: &Fall,
    v_end: f64,
    prior: &Prior,
) -> Result<Option<(f64, u64)>, SolveError> {
    if !(fall.from_rest() && v_end > 0.0 && v_end.is_finite()) {
        return Ok(None);
    }
    if fall.fall_polynomial().is_empty() {
        return Ok(None);
    }
    let Some(sing) = Singularities::of(fall.sin_initial(), fall.scale(), fall.fall_polynomial())
    else {
        return Ok(None);
    };
    prior_panels(&sing, v_end, prior, |rule, a, b| fall.panel(rule, a, b))
}

/// The a-priori plan on `[0, v_end]` (`v_end > 0`) for a phase from rest with singular points
/// `sing`: one panel when a rule of at most [`PRIOR_MAX_NODES`] nodes suffices, else halves,
/// depth first, each integrated by `panel(rule, a, b)` (the first one from rest symmetric).
/// `Ok(None)` past [`PRIOR_MAX_PANELS`] panels; the integral and the evaluations otherwise.
/// Always inlined: the per-point route's copies otherwise call it out of line.
#[inline(always)]
pub fn prior_panels<E>(
    sing: &Singularities,
    v_end: f64,
    prior: &Prior,
    mut panel: impl FnMut(&'static HalfRule, f64, f64) -> Result<(f64, u64), E>,
) -> Result<Option<(f64, u64)>, E> {
    // Most phases take one panel; the others are halved, depth first (out of line).
    if let Some(rule) = prior.rule_for(sing.rho(0.0, v_end)) {
        return panel(rule, 0.0, v_end).map(Some);
    }
    halved_panels(sing, v_end, prior, panel)
}

/// [`prior_panels`] past its first panel: halves, depth first.
#[cold]
#[inline(never)]
fn halved_panels<E>(
    sing: &Singularities,
    v_end: f64,
    prior: &Prior,
    mut panel: impl FnMut(&'static HalfRule, f64, f64) -> Result<(f64, u64), E>,
) -> Result<Option<(f64, u64)>, E> {
    let mut stack = [(0.0, 0.0); PRIOR_STACK];
    stack[0] = (0.0, 0.5 * v_end);
    stack[1] = (0.5 * v_end, v_end);
    let (mut top, mut panels) = (2usize, 1usize);
    let (mut total, mut evals) = (0.0, 0u64);
    while top > 0 {
        top -= 1;
        let (a, b) = stack[top];
        // The first panel from rest is the symmetric one [-b, b].
        let (c, h) = if a == 0.0 {
            (0.0, b)
        } else {
            (0.5 * (a + b), 0.5 * (b - a))
        };
        panels += 1;
        match prior.rule_for(sing.rho(c, h)) {
            Some(rule) => {
                let (value, n) = panel(rule, a, b)?;
                total += value;
                evals += n;
            }
            None => {
                let mid = 0.5 * (a + b);
                if !(mid > a && mid < b) || top + 2 > PRIOR_STACK || panels > PRIOR_MAX_PANELS {
                    return Ok(None);
                }
                stack[top] = (mid, b);
                stack[top + 1] = (a, mid);
                top += 2;
            }
        }
    }
    Ok(Some((total, evals)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sinh^2(v*)` must give back `(si - s) / e` at every point found.
    fn sinh_sq(x: f64, y: f64) -> (f64, f64) {
        // sinh(x + i y) = sinh x cos y + i cosh x sin y.
        let (a, b) = (x.sinh() * y.cos(), x.cosh() * y.sin());
        (a * a - b * b, 2.0 * a * b)
    }

    #[test]
    fn points_map_back_to_their_singular_sine() {
        let (si, e) = (0.7, 0.3);
        for s in [1.5, 0.9, -0.4] {
            // Real parts are lower bounds within LN_BELOW_GAP: sinh^2 comes back below, and
            // the exact point lies at most that far beyond.
            // The point as the rule sees it, from a polynomial with its one zero at s.
            let sing = Singularities::of(si, e, &[-s, 1.0]).expect("a zero off the start");
            let (x, y) = match (sing.len, sing.line_len) {
                (1, 0) => sing.points[0],
                (0, 1) => (acosh_below(sing.on_line[0]), FRAC_PI_2),
                _ => (sing.real, 0.0),
            };
            let want = (si - s) / e;
            let (re, im) = sinh_sq(x, y);
            assert!(
                re.abs() <= want.abs() + 1e-12 && im.abs() < 1e-12,
                "{s}: {re} {im}"
            );
            let (re, _) = sinh_sq(x + LN_BELOW_GAP, y);
            assert!(re.abs() >= want.abs(), "{s}: {re} short of {want}");
        }
        for (re_s, im_s) in [(0.2, 0.05), (-3.0, 2.0), (0.69, 1e-3)] {
            let (x, y) = complex(si, e, re_s, im_s);
            assert!(x >= 0.0 && (0.0..=FRAC_PI_2 + 1e-15).contains(&y));
            let (re, im) = sinh_sq(x, y);
            let (zr, zi) = ((si - re_s) / e, -im_s / e);
            // v* or its conjugate.
            assert!(
                (re - zr).abs() < 1e-9 && (im.abs() - zi.abs()).abs() < 1e-9,
                "{re_s} {im_s}"
            );
        }
    }

    #[test]
    fn points_on_the_line_are_bounded_only_where_they_can_be_nearest() {
        // Quadratics with zeros above the start (on the line y = pi/2 or below it), below it
        // and complex, on panels from rest and off it: the rule's rho equals the least over
        // every point's real part bounded up front.
        let mut next = crate::solve::uniform(0x853c_49e6_748f_ea9b);
        let (mut passed, mut bounded) = (0, 0);
        for _ in 0..20_000 {
            let si = next() * 1.98 - 0.99;
            let e = 1.0 - si;
            let coeffs = [next() * 4.0 - 1.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0];
            let Some(sing) = Singularities::of(si, e, &coeffs) else {
                continue;
            };
            let h = 0.01 + 3.0 * next();
            let c = if next() < 0.5 { 0.0 } else { h + 3.0 * next() };
            let mut alpha = mean_distance(sing.real, 0.0, c, h);
            for &(x, y) in &sing.points[..sing.len] {
                alpha = alpha.min(mean_distance(x, y, c, h));
            }
            let seen = alpha;
            for &y in &sing.on_line[..sing.line_len] {
                alpha = alpha.min(mean_distance(acosh_below(y), FRAC_PI_2, c, h));
            }
            let eager = alpha + ((alpha - 1.0) * (alpha + 1.0)).max(0.0).sqrt();
            assert_eq!(sing.rho(c, h), eager, "{si} {coeffs:?} {c} {h}");
            if sing.line_len > 0 {
                let w = FRAC_PI_2 / h;
                if 1.0 + w * w < seen * seen {
                    bounded += 1;
                } else {
                    passed += 1;
                }
            }
        }
        // Both branches ran many times.
        assert!(
            passed > 1_000 && bounded > 1_000,
            "{passed} passed, {bounded} bounded"
        );
    }

    #[test]
    fn the_logarithm_and_asinh_bounds_hold_from_below() {
        let (mut y, mut widest) = (1.0f64, 0.0f64);
        while y < 1e300 {
            // 1 / ln 2: where the chord lies farthest below.
            let worst = y * std::f64::consts::LOG2_E;
            for t in [
                y,
                y * 1.000_000_1,
                y * std::f64::consts::SQRT_2,
                worst,
                y * 1.9,
            ] {
                let (low, exact) = (ln_below(t), t.ln());
                assert!(
                    low <= exact && exact - low <= LN_BELOW_GAP,
                    "ln {t}: {low} vs {exact}"
                );
                widest = widest.max(exact - low);
            }
            y *= 1.37;
        }
        // The gap is the bound's, not a loose constant.
        assert!(widest > 0.059, "widest gap {widest}");
        assert!(ln_below(f64::INFINITY).is_infinite() && ln_below(f64::NAN).is_nan());
        for z in [
            0.0f64, 1e-30, 1e-8, 0.01, 0.2499, 0.25, 0.7, 3.0, 1e8, 1e200,
        ] {
            let exact = z.sqrt().asinh();
            let low = asinh_sqrt(z);
            assert!(
                low <= exact && exact - low <= LN_BELOW_GAP + 1.2e-4 * exact,
                "asinh {z}"
            );
        }
    }

    #[test]
    fn the_tables_start_gives_the_plain_scans_rule() {
        for tol in [PRIOR_TOL, 1e-12, 1e-6, 0.1] {
            let prior = Prior::new(tol);
            let plain = |rho: f64| {
                let j = prior.thresholds.iter().position(|&t| rho >= t);
                j.and_then(|j| prior.rules.get(j)).map(|r| r.nodes)
            };
            let mut rhos = vec![f64::NAN, -1.0, 0.0, 0.5, 1.0, 256.0, 1e300, f64::INFINITY];
            // Each threshold, the floats beside it, and a dense geometric sweep.
            for &t in &prior.thresholds {
                rhos.extend([t, t.next_down(), t.next_up()]);
            }
            rhos.extend((0..20_000).map(|i| 1.0 + 400.0 * (i as f64 / 20_000.0).powi(3)));
            for rho in rhos {
                assert_eq!(
                    prior.rule_for(rho).map(|r| r.nodes),
                    plain(rho),
                    "tol {tol:e}, rho {rho}"
                );
            }
        }
    }

    #[test]
    fn more_nodes_for_nearer_singularities_and_none_on_the_path() {
        let prior = Prior::new(PRIOR_TOL);
        let far = prior.rule_for(10.0).map(|r| r.nodes);
        let near = prior.rule_for(2.0).map(|r| r.nodes);
        assert!(far.is_some() && far < near, "{far:?} {near:?}");
        assert_eq!(prior.rule_for(1.2), None, "too near: halve the panel");
        assert_eq!(prior.rule_for(1.0), None);
        // A singular point on the panel gives rho = 1.
        let sing = Singularities::of(0.5, 0.5, &[]).expect("no polynomial: s = -1 alone");
        assert_eq!(sing.real, asinh_sqrt(3.0));
        assert_eq!(sing.rho(0.0, asinh_sqrt(3.0)), 1.0);
        assert_eq!(Singularities::of(0.5, 0.5, &[1.0, 0.0, 0.0, 1.0]), None);
        assert_eq!(Singularities::of(0.5, 0.5, &[-0.5, 1.0]), None);
    }
}
