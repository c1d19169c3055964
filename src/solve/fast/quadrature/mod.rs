//! The one time quadrature: `t = integral d(theta) / |theta_dot|` along a falling phase, used by
//! the planner ([`TimeMesh`]), the per-point solver and the sweeps
//! ([`lean`](crate::solve::fast::lean)) and the accuracy report.
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
//! ([`prior`](crate::solve::fast::prior)); the verified pairs below serve everything else.
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
//!
//! # Files
//! `rules.rs` holds the rules, the schedule and the [`Control`]; `hyperbolic.rs` the `sinh` and
//! `cosh` of the nodes; `integrand.rs` the [`FallIntegrand`] and its panel sum; `fall.rs` the
//! [`Fall`]; `adaptive.rs` [`integrate`]; `mesh.rs` the [`TimeMesh`].
//!
//! [`Reduction::theta_dot_sq_sc`]: crate::model::Reduction::theta_dot_sq_sc
//! [`Reduction::fall_polynomial`]: crate::model::Reduction::fall_polynomial

mod adaptive;
mod fall;
mod hyperbolic;
mod integrand;
mod mesh;
mod rules;

pub use adaptive::{MAX_PANELS, Panel, integrate};
pub use fall::{Fall, v_at_drop};
pub use integrand::{FallIntegrand, PanelSum};
pub use mesh::TimeMesh;
pub use rules::{
    ACCEPT, Control, HalfRule, LANES, Lane, MAX_NODES, MIN_TOL, RuleStep, SCHEDULE, TOL_SAFETY,
    gauss_legendre_rule, half_rule,
};
