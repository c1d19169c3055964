//! A lean per-point solve of the separation angle and time, for sweeps of millions of points:
//! every buffer is allocated once per solver and reused, nothing is kept per point, and the
//! time integral uses a substitution that removes both singularities of the integrand, so a
//! few Gauss–Legendre panels reach `f64` accuracy across the whole parameter range.
//!
//! # The substitution
//! The fall is parametrised by `s = sin(theta)`, which is monotone on the phase
//! (`0 < theta < pi/2`), so no trigonometric function is evaluated inside the integral: the
//! generated [`Model::theta_dot_sq_sc`] takes `s`, `cos(theta)` and their drops from the start.
//! With `dt = d(theta) / |theta_dot| = ds / (cos(theta) |theta_dot|)` the integrand has two
//! square-root singularities: `theta_dot^2` vanishes like `w = sin(theta_i) - s` at the start
//! (released from rest), and `cos(theta) = sqrt((1 - s)(1 + s))` vanishes at `w = -e`,
//! `e = 1 - sin(theta_i)`, just outside the interval when the rod starts nearly upright. With
//! `w = e sinh^2(v)`, `dw / sqrt(w (w + e)) = 2 dv` and `1 - s = e cosh^2(v)` exactly, so
//! `t = integral 2 sqrt(e) sinh(v) / sqrt((1 + s) theta_dot^2) dv` has a smooth integrand of
//! one scale from the flat start (`e -> 1`, where `v ~ sqrt(w)` and this is the `w = u^2`
//! substitution) to the upright one (`e -> 0`, where the time grows like `v_end ~ log(1/e)`).
//! `cos(theta) = sqrt(e) cosh(v) sqrt(1 + s)` and
//! `cos(theta_i) - cos(theta) = -w (sin(theta_i) + s) / (cos(theta_i) + cos(theta))` are formed
//! without cancellation. Released from rest, `theta_dot^2 = (2 beta ds + 2 gamma dc) / I(theta)`
//! for every model the generator accepts (its potential is `alpha + beta sin + gamma cos`), and
//! both drops carry the factor `w`, so the substitution removes the start singularity exactly
//! for all of them.
//!
//! # Cost
//! An evaluation costs two square roots, three divisions and the generated rational function;
//! the symmetric nodes `mid +- h x` of a panel share one `exp_m1` through the addition theorems
//! of `sinh` and `cosh`, and the nodes of a panel go through the integrand stage by stage so
//! that the divisions and roots of different nodes overlap. The separation root costs a few
//! polynomial evaluations ([`largest_root`]).
//!
//! # Error control
//! Each panel is integrated by two Gauss–Legendre rules chosen by the panel's length from
//! [`LEAN_SCHEDULE`] (the nearest complex singularities of the integrand lie about `pi/2` off the
//! real `v` axis, so the panel's length sets the convergence rate); the finer value is kept when
//! the two agree to [`LEAN_ACCEPT`] relative, otherwise the panel is halved. Two rules on the
//! same panel do not agree by accident when a near-singularity sits at the panel's end, which is
//! how comparing a panel with its halves is fooled (both then carry the same unresolved error):
//! with the hinged rod and a heavy cube the integrand has complex singularities
//! (`1 + 3 n s^2 = 0`) just past the end of the phase, and the panel-versus-halves test of the
//! planner's quadrature, or a test on the decay of the integrand's Legendre coefficients,
//! accepted panels with errors of 1e-9 there. The strict tolerance matters for the same reason:
//! where the convergence is algebraic, the kept value is only a few times better than the test.
//! Across the sweep range of `rod_cube` (`n` 1e-3..1e3, `a/ell` 0.01..0.99) a point takes 21
//! integrand evaluations on average (15 at the paper's point) and its error is below 1e-15.
//! `rodcube accuracy` and the tests in `tests/hard_cases.rs` check the result against the
//! high-precision [`reference`](crate::reference) across `n = m2/m1` from 1e-12 to 1e12 and
//! `a/ell` from 1e-10 to `1 - 1e-9`.

use crate::model::{Model, ModelInfo, Reduction, ReductionInfo};
use crate::solve::SolveError;
use crate::solve::quadrature::gauss_legendre_rule;
use crate::solve::separation::horner_compensated;
use crate::system::SystemError;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::{Mutex, OnceLock};

/// One step of a rule schedule: panels up to `max_len` long (in the variable `v` of the module
/// docs) are integrated by Gauss–Legendre rules of `low` and `high` nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleStep {
    /// Longest panel (in `v`) this step applies to.
    pub max_len: f64,
    /// Nodes of the coarse rule (the error estimate).
    pub low: usize,
    /// Nodes of the fine rule (the value kept).
    pub high: usize,
}

/// The default schedule. The integrand's convergence is governed by the panel's length in `v`
/// (its nearest complex singularities lie about `pi/2` off the real axis), so short panels get
/// cheap rules and longer ones are first cut into pieces no longer than the last step's
/// `max_len`. The steps were set so that the coarse rule alone is within about 1e-13 of the
/// integral for `rod_cube`, `wall_ladder` and `loaded_rod` across `n` 1e-3..1e3 and `a/ell`
/// 0.01..0.99 (`rodcube accuracy` shows the cost of other settings); the schedule only sets the
/// cost, as every panel is still accepted only by the agreement of its two rules.
pub const LEAN_SCHEDULE: [RuleStep; 3] = [
    RuleStep {
        max_len: 0.4,
        low: 6,
        high: 9,
    },
    RuleStep {
        max_len: 0.6,
        low: 7,
        high: 10,
    },
    RuleStep {
        max_len: 1.0,
        low: 8,
        high: 12,
    },
];

/// A panel is kept when its two rules agree to this relative tolerance.
pub const LEAN_ACCEPT: f64 = 1e-12;

/// Highest degree of separation polynomial solved without allocating (higher degrees are
/// refused with [`SolveError::BadPolynomial`]).
pub const MAX_DEGREE: usize = 8;

/// Most panels before giving up.
pub const MAX_PANELS: usize = 4000;

/// One point's separation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeanPoint {
    /// `theta_sep` (rad).
    pub separation_angle: f64,
    /// Time from release to separation (s).
    pub separation_time: f64,
    /// `theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// A reusable per-point solver of one model's separation angle and time.
pub struct LeanSolver<'m> {
    model: &'m dyn Model,
    info: &'static ModelInfo,
    /// The model's fast path and where it keeps its start in `k`.
    red: &'m dyn Reduction,
    layout: &'static ReductionInfo,
    /// `sin(end_angle)`, the low end of the root's bracket.
    sin_end: f64,
    k: Vec<f64>,
    margins: Vec<f64>,
    coeffs: Vec<f64>,
    /// `(max_len, coarse, fine)` per schedule step, shortest first.
    rules: Vec<(f64, &'static HalfRule, &'static HalfRule)>,
    accept: f64,
    stack: Vec<(f64, f64, f64)>,
    nodes: Nodes,
    /// Evaluations of `theta_dot^2` and of the polynomial since the solver was made.
    pub evals: u64,
}

impl std::fmt::Debug for LeanSolver<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LeanSolver")
            .field("model", &self.info.name)
            .field(
                "rules",
                &self
                    .rules
                    .iter()
                    .map(|(len, lo, hi)| (*len, lo.nodes, hi.nodes))
                    .collect::<Vec<_>>(),
            )
            .field("accept", &self.accept)
            .finish()
    }
}

impl<'m> LeanSolver<'m> {
    /// A solver with the default schedule [`LEAN_SCHEDULE`] and tolerance [`LEAN_ACCEPT`].
    /// The model must have a contact whose separation polynomial has degree at most
    /// [`MAX_DEGREE`].
    pub fn new(model: &'m dyn Model) -> Result<Self, SolveError> {
        Self::with_schedule(model, &LEAN_SCHEDULE, LEAN_ACCEPT)
    }

    /// A solver comparing rules of `low` and `high` nodes on every panel, keeping the `high` one
    /// when they agree to `accept` relative, with no panel cut before it fails the test (other
    /// settings are shown by `rodcube accuracy`).
    pub fn with_rules(
        model: &'m dyn Model,
        low: usize,
        high: usize,
        accept: f64,
    ) -> Result<Self, SolveError> {
        let step = RuleStep {
            max_len: f64::INFINITY,
            low,
            high,
        };
        Self::with_schedule(model, &[step], accept)
    }

    /// A solver with a rule schedule (steps in any order; an empty one means the default).
    pub fn with_schedule(
        model: &'m dyn Model,
        schedule: &[RuleStep],
        accept: f64,
    ) -> Result<Self, SolveError> {
        let info = model.info();
        if info.contact.is_none() {
            return Err(SolveError::NoContact { model: info.name });
        }
        let (Some(red), Some(layout)) = (model.reduction(), info.reduction.as_ref()) else {
            return Err(SolveError::Parameters(SystemError::NoReduction {
                model: info.name,
                why: info.route_note,
            }));
        };
        let contact = info.contact.is_some_and(|c| c.edge);
        if !layout.polynomial_separation || contact {
            return Err(SolveError::NotPerPoint {
                model: info.name,
                why: if contact {
                    "its contact can end at an edge"
                } else {
                    "its separation is no polynomial root"
                },
            });
        }
        if layout.separation_degree > MAX_DEGREE {
            return Err(SolveError::BadPolynomial {
                model: info.name,
                coefficients: Vec::new(),
            });
        }
        let schedule = if schedule.is_empty() {
            &LEAN_SCHEDULE[..]
        } else {
            schedule
        };
        let mut rules: Vec<(f64, &'static HalfRule, &'static HalfRule)> = schedule
            .iter()
            .map(|st| {
                let len = if st.max_len > 0.0 {
                    st.max_len
                } else {
                    f64::INFINITY
                };
                (len, cached_rule(st.low), cached_rule(st.high))
            })
            .collect();
        rules.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(LeanSolver {
            model,
            info,
            red,
            layout,
            sin_end: info.end_angle.sin(),
            k: vec![0.0; info.n_constants],
            margins: vec![0.0; info.requirements.len()],
            coeffs: vec![0.0; layout.separation_degree + 1],
            rules,
            accept: accept.max(4.0 * f64::EPSILON),
            stack: Vec::with_capacity(64),
            nodes: Nodes::default(),
            evals: 0,
        })
    }

    /// The model.
    pub fn model(&self) -> &'m dyn Model {
        self.model
    }

    /// Validates `p` (in the model's parameter order) exactly as
    /// [`System::from_values`](crate::system::System::from_values) does, then solves.
    pub fn solve(&mut self, p: &[f64]) -> Result<LeanPoint, SolveError> {
        self.bind(p).map_err(SolveError::Parameters)?;
        let (theta, drop) = self.separation()?;
        let delta = self.k[self.layout.k_theta_initial] - theta;
        let t = self.time_to(drop, delta)?;
        Ok(LeanPoint {
            separation_angle: theta,
            separation_time: t,
            delta,
        })
    }

    /// Checks the parameters and prepares the constants.
    fn bind(&mut self, p: &[f64]) -> Result<(), SystemError> {
        let info = self.info;
        if p.len() != info.parameters.len() {
            return Err(SystemError::WrongCount {
                model: info.name,
                expected: info.parameters.len(),
                got: p.len(),
            });
        }
        for (&value, param) in p.iter().zip(info.parameters) {
            if !value.is_finite() {
                return Err(SystemError::NotFinite {
                    model: info.name,
                    name: param.name,
                    value,
                });
            }
            if param.positive && value <= 0.0 {
                return Err(SystemError::NotPositive {
                    model: info.name,
                    name: param.name,
                    value,
                });
            }
        }
        self.model.requirements(p, &mut self.margins);
        for (&margin, req) in self.margins.iter().zip(info.requirements) {
            if margin.is_nan() || margin <= 0.0 {
                return Err(SystemError::Requirement {
                    model: info.name,
                    name: req.name,
                    meaning: req.meaning,
                    margin,
                    parameters: describe(info, p),
                });
            }
        }
        self.model.prepare(p, &mut self.k);
        // A branch-free scan first (it vectorises); the index only on failure.
        let all_finite = self.k.iter().fold(true, |ok, v| ok & v.is_finite());
        if !all_finite
            && let Some((index, &value)) = self.k.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(SystemError::BadConstant {
                model: info.name,
                index,
                value,
                parameters: describe(info, p),
            });
        }
        Ok(())
    }

    /// `(theta_sep, sin(theta_i) - sin(theta_sep))` from the largest sign-changing root of the
    /// separation polynomial in `(sin(end_angle), sin(theta_i))`.
    fn separation(&mut self) -> Result<(f64, f64), SolveError> {
        let info = self.info;
        self.red.separation_polynomial(&self.k, &mut self.coeffs);
        if self.coeffs.iter().any(|c| !c.is_finite()) || self.coeffs.iter().all(|&c| c == 0.0) {
            return Err(SolveError::BadPolynomial {
                model: info.name,
                coefficients: self.coeffs.clone(),
            });
        }
        let hi = self.k[self.layout.k_sin_initial];
        match largest_root(&self.coeffs, self.sin_end, hi, &mut self.evals) {
            Some(s) => Ok((s.asin(), hi - s)),
            None => Err(SolveError::NoSeparation {
                model: info.name,
                coefficients: self.coeffs.clone(),
                lo: self.sin_end,
                hi,
            }),
        }
    }

    /// Time from release to where `sin(theta)` has dropped by `drop_end`, by the substitution
    /// `sin(theta_i) - sin(theta) = e sinh^2 v` with `e = 1 - sin(theta_i)` (module docs).
    fn time_to(&mut self, drop_end: f64, delta_end: f64) -> Result<f64, SolveError> {
        let info = self.info;
        let model = info.name;
        if !(drop_end > 0.0 && drop_end.is_finite() && delta_end > 0.0) {
            return Err(SolveError::BadPhaseEnd { model, delta_end });
        }
        let layout = self.layout;
        let theta_dot = self.k[layout.k_theta_dot_initial];
        let (si, ci) = (self.k[layout.k_sin_initial], self.k[layout.k_cos_initial]);
        // Released from rest, theta_dot^2 is linear in the drops (ds, dc), which near the start
        // are in the ratio dc / ds -> -sin(theta_i) / cos(theta_i): its value per unit drop there
        // is -2 theta_ddot_i d(delta)/ds, so it must be positive for the rod to fall. (One
        // rational evaluation instead of the trigonometry of `reduced`, which only the error
        // message needs.)
        let slope = if theta_dot == 0.0 && ci > 0.0 {
            self.red.theta_dot_sq_sc(&self.k, si, ci, 1.0, -si / ci)
        } else {
            f64::NAN
        };
        if !(slope > 0.0 && slope.is_finite()) {
            let start = self.red.reduced(&self.k, 0.0);
            return Err(
                if theta_dot != 0.0 || start.theta_ddot >= 0.0 || start.theta_ddot.is_nan() {
                    SolveError::NoMotion {
                        model,
                        theta_dot,
                        theta_ddot: start.theta_ddot,
                    }
                } else if ci <= 0.0 || ci.is_nan() {
                    SolveError::BeyondVertical {
                        model,
                        theta_initial: self.k[layout.k_theta_initial],
                    }
                } else {
                    SolveError::NonFinite {
                        model,
                        what: "theta_dot^2 per unit drop of sin(theta) at the start",
                        delta: 0.0,
                        value: slope,
                    }
                },
            );
        }
        // 1 - sin(theta_i) without cancellation near upright.
        let e = ci * ci / (1.0 + si);
        if !(e > 0.0 && si.abs() < 1.0) {
            return Err(SolveError::BeyondVertical {
                model,
                theta_initial: self.k[layout.k_theta_initial],
            });
        }
        let root_e = e.sqrt();
        // v_end = asinh(sqrt(q)), q = drop_end / e, as log1p(x + q / (1 + sqrt(1 + q))): exact
        // for small and large q without `hypot`.
        let q = drop_end / e;
        let x = q.sqrt();
        let v_end = (x + q / (1.0 + (1.0 + q).sqrt())).ln_1p();
        let at = Integrand {
            model: self.model,
            red: self.red,
            k: &self.k,
            si,
            ci,
            e,
            root_e,
            delta_end,
        };
        // The schedule step for a panel length, and the a-priori cut of the whole interval.
        let rules = &self.rules;
        let step_for = |len: f64| {
            rules
                .iter()
                .find(|r| len <= r.0)
                .unwrap_or(&rules[rules.len() - 1])
        };
        let longest = rules[rules.len() - 1].0;
        let pieces = if v_end > longest {
            ((v_end / longest).ceil() as usize).min(MAX_PANELS)
        } else {
            1
        };
        self.stack.clear();
        for i in (0..pieces).rev() {
            let lo = v_end * i as f64 / pieces as f64;
            let hi = if i + 1 == pieces {
                v_end
            } else {
                v_end * (i + 1) as f64 / pieces as f64
            };
            self.stack.push((lo, hi, 0.0));
        }
        let mut evals = 0u64;
        let mut total = 0.0;
        let mut panels = 0usize;
        while let Some((lo, hi, _)) = self.stack.pop() {
            let (_, low, high) = step_for(hi - lo);
            let (coarse, fine) = at.panel_pair(&mut self.nodes, low, high, lo, hi)?;
            evals += self.nodes.sh.len() as u64;
            let error = (fine - coarse).abs();
            panels += 1;
            if fine.is_finite() && error <= self.accept * fine.abs() {
                total += fine;
                continue;
            }
            let mid = 0.5 * (lo + hi);
            let splittable = mid > lo && mid < hi;
            if !fine.is_finite() || !splittable || panels > MAX_PANELS {
                self.evals += evals;
                return Err(SolveError::QuadratureNotConverged {
                    a: 0.0,
                    b: v_end,
                    tol: self.accept,
                    estimate: total + fine,
                    error,
                    panels,
                });
            }
            self.stack.push((mid, hi, 0.0));
            self.stack.push((lo, mid, 0.0));
        }
        self.evals += evals;
        Ok(total)
    }
}

/// A Gauss–Legendre rule on `[-1, 1]` kept as its nodes `x > 0` with their weights (each used
/// at `+x` and `-x`) and the weight of the node at 0 (0 for even orders).
#[derive(Debug, Clone)]
struct HalfRule {
    nodes: usize,
    pairs: Vec<(f64, f64)>,
    centre: f64,
}

/// `(sinh x, cosh x)` from one `exp_m1`, accurate for small and large `x` alike.
#[inline]
fn sinh_cosh(x: f64) -> (f64, f64) {
    let em = x.exp_m1();
    let inv = 1.0 / (1.0 + em);
    (0.5 * (em + em * inv), 0.5 * (1.0 + em + inv))
}

/// Per-node scratch of one panel (both rules), reused across panels and points.
#[derive(Debug, Default)]
struct Nodes {
    sh: Vec<f64>,
    ch: Vec<f64>,
    s: Vec<f64>,
    c: Vec<f64>,
    ds: Vec<f64>,
    dc: Vec<f64>,
    root_plus: Vec<f64>,
    value: Vec<f64>,
}

/// The integrand of `t = integral dv` for one point (module docs).
struct Integrand<'a> {
    model: &'a dyn Model,
    red: &'a dyn Reduction,
    k: &'a [f64],
    si: f64,
    ci: f64,
    e: f64,
    root_e: f64,
    delta_end: f64,
}

impl Integrand<'_> {
    /// Both rules of a step on the panel `[a, b]`: `(coarse, fine)`.
    ///
    /// The symmetric nodes `mid +- h x` share one exponential: `sinh(mid +- h x)` and
    /// `cosh(mid +- h x)` follow from those of `mid` and of `h x` by the addition theorems (the
    /// difference loses at most `log2(mid / v)` bits, which the integrand's ratio
    /// `sinh v / |theta_dot|` does not feel). The nodes are then taken through the integrand
    /// stage by stage over all of them, so that the divisions and square roots of different
    /// nodes overlap instead of waiting on each other.
    fn panel_pair(
        &self,
        n: &mut Nodes,
        low: &HalfRule,
        high: &HalfRule,
        a: f64,
        b: f64,
    ) -> Result<(f64, f64), SolveError> {
        let (half, mid) = (0.5 * (b - a), 0.5 * (a + b));
        let (sm, cm) = sinh_cosh(mid);
        n.sh.clear();
        n.ch.clear();
        // Node order: the centre (if either rule has one), then each rule's pairs (+x, -x).
        let has_centre = low.centre != 0.0 || high.centre != 0.0;
        if has_centre {
            n.sh.push(sm);
            n.ch.push(cm);
        }
        for rule in [low, high] {
            for &(x, _) in &rule.pairs {
                let (sx, cx) = sinh_cosh(half * x);
                n.sh.push(sm * cx + cm * sx);
                n.ch.push(cm * cx + sm * sx);
                n.sh.push(sm * cx - cm * sx);
                n.ch.push(cm * cx - sm * sx);
            }
        }
        let count = n.sh.len();
        // s = sin(theta); 1 - s = e cosh^2 v exactly, so cos(theta) keeps full accuracy near
        // upright, and cos(theta_i) - cos(theta) = -(si - s)(si + s) / (ci + c).
        let (e, si, ci, root_e) = (self.e, self.si, self.ci, self.root_e);
        n.ds.clear();
        n.s.clear();
        n.root_plus.clear();
        n.c.clear();
        n.dc.clear();
        for (&sh, &ch) in n.sh.iter().zip(&n.ch) {
            let ds = e * sh * sh;
            let s = si - ds;
            let root_plus = (1.0 + s).sqrt();
            let c = root_e * ch * root_plus;
            n.ds.push(ds);
            n.s.push(s);
            n.root_plus.push(root_plus);
            n.c.push(c);
            n.dc.push(-ds * (si + s) / (ci + c));
        }
        n.value.clear();
        for i in 0..count {
            n.value.push(
                self.red
                    .theta_dot_sq_sc(self.k, n.s[i], n.c[i], n.ds[i], n.dc[i]),
            );
        }
        if let Some(i) = n.value.iter().position(|&w2| !(w2 > 0.0 && w2.is_finite())) {
            return Err(self.bad_value(n.s[i], n.value[i]));
        }
        // dt = d(theta) / |theta_dot| = ds / (c |theta_dot|), ds = 2 e sinh v cosh v dv.
        for i in 0..count {
            n.value[i] = 2.0 * root_e * n.sh[i] / (n.root_plus[i] * n.value[i].sqrt());
        }
        let mut at = 0;
        let centre = if has_centre {
            at = 1;
            n.value[0]
        } else {
            0.0
        };
        let mut sums = [0.0; 2];
        for (sum, rule) in sums.iter_mut().zip([low, high]) {
            let mut acc = rule.centre * centre;
            for &(_, w) in &rule.pairs {
                acc += w * (n.value[at] + n.value[at + 1]);
                at += 2;
            }
            *sum = half * acc;
        }
        Ok((sums[0], sums[1]))
    }

    /// The error for a `theta_dot^2` that is not positive and finite at `sin(theta) = s`.
    fn bad_value(&self, s: f64, w2: f64) -> SolveError {
        let model = self.model.info().name;
        let delta = self.si.asin() - s.asin();
        if w2.is_finite() {
            SolveError::TurningPoint {
                model,
                delta,
                theta_dot_sq: w2,
                delta_end: self.delta_end,
            }
        } else {
            SolveError::NonFinite {
                model,
                what: "theta_dot^2",
                delta,
                value: w2,
            }
        }
    }
}

/// Gauss–Legendre nodes and weights of an order, computed once per process and kept for its
/// life (one small table per order ever asked for), so that making a solver is cheap enough to
/// do per call.
fn cached_rule(order: usize) -> &'static HalfRule {
    type Rules = Mutex<HashMap<usize, &'static HalfRule>>;
    static RULES: OnceLock<Rules> = OnceLock::new();
    let cache = RULES.get_or_init(|| Mutex::new(HashMap::new()));
    let mut map = match cache.lock() {
        Ok(map) => map,
        Err(poisoned) => poisoned.into_inner(),
    };
    map.entry(order.max(1)).or_insert_with(|| {
        let full = gauss_legendre_rule(order.max(1));
        // Nodes come in pairs +-x; an odd order adds x = 0 (within rounding).
        let mut pairs: Vec<(f64, f64)> = full.iter().filter(|(x, _)| *x > 1e-12).copied().collect();
        pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
        let centre = full
            .iter()
            .filter(|(x, _)| x.abs() <= 1e-12)
            .map(|(_, w)| *w)
            .sum();
        Box::leak(Box::new(HalfRule {
            nodes: full.len(),
            pairs,
            centre,
        }))
    })
}

/// `name = value` pairs for messages.
fn describe(info: &ModelInfo, p: &[f64]) -> String {
    let mut out = String::new();
    for (i, (param, v)) in info.parameters.iter().zip(p).enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{} = {v}", param.name);
    }
    out
}

/// The largest root of `p` in `(lo, hi)` where `p` changes sign, without allocating
/// (degree at most [`MAX_DEGREE`]; coefficients lowest degree first).
pub fn largest_root(coeffs: &[f64], lo: f64, hi: f64, evals: &mut u64) -> Option<f64> {
    let degree = coeffs.iter().rposition(|&c| c != 0.0)?;
    if degree > MAX_DEGREE {
        return None;
    }
    let mut out = [0.0; MAX_DEGREE];
    let n = roots_into(&coeffs[..=degree], lo, hi, &mut out, evals);
    (n > 0).then(|| out[n - 1])
}

/// Every sign-changing root of `c` (trimmed, degree at most [`MAX_DEGREE`]) in `(lo, hi)`,
/// ascending, into `out`; returns how many. The roots of the derivative split the interval into
/// pieces where `c` is monotone, each refined by bracketed Newton.
fn roots_into(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE], evals: &mut u64) -> usize {
    let degree = c.len().saturating_sub(1);
    if degree == 0 || lo.is_nan() || hi.is_nan() || lo >= hi {
        return 0;
    }
    if degree == 1 {
        let x = -c[0] / c[1];
        if x > lo && x < hi {
            out[0] = x;
            return 1;
        }
        return 0;
    }
    let mut deriv = [0.0; MAX_DEGREE];
    for i in 1..=degree {
        deriv[i - 1] = i as f64 * c[i];
    }
    let d = &deriv[..degree];
    let d_trim = match d.iter().rposition(|&x| x != 0.0) {
        Some(k) => &d[..=k],
        None => &d[..1],
    };
    let mut crit = [0.0; MAX_DEGREE];
    // The critical points only split the interval into monotone pieces: for a quadratic
    // derivative the closed form is exact enough and costs no iteration.
    let nc = if d_trim.len() == 3 {
        quadratic_roots(d_trim, lo, hi, &mut crit)
    } else {
        roots_into(d_trim, lo, hi, &mut crit, evals)
    };
    let mut knots = [0.0; MAX_DEGREE + 2];
    let mut values = [0.0; MAX_DEGREE + 2];
    knots[0] = lo;
    knots[1..=nc].copy_from_slice(&crit[..nc]);
    knots[nc + 1] = hi;
    let nk = nc + 2;
    for i in 0..nk {
        values[i] = filtered(c, knots[i]);
    }
    *evals += nk as u64;
    let mut count = 0;
    for i in 0..nk - 1 {
        let (fa, fb) = (values[i], values[i + 1]);
        if fa == 0.0 && i > 0 {
            let before = values[i - 1];
            if before != 0.0 && fb != 0.0 && before.signum() != fb.signum() {
                out[count] = knots[i];
                count += 1;
            }
            continue;
        }
        if fa != 0.0 && fb != 0.0 && fa.signum() != fb.signum() {
            out[count] = refine(c, d, (knots[i], knots[i + 1]), (fa, fb), evals);
            count += 1;
        }
    }
    count
}

/// The real roots of `c0 + c1 x + c2 x^2` (`c2 != 0`) in `(lo, hi)`, ascending, by the
/// cancellation-free form of the quadratic formula; returns how many.
fn quadratic_roots(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE]) -> usize {
    let (c0, c1, c2) = (c[0], c[1], c[2]);
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc.is_nan() || disc <= 0.0 {
        return 0;
    }
    let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
    let (mut x1, mut x2) = (q / c2, if q != 0.0 { c0 / q } else { 0.0 });
    if x1 > x2 {
        std::mem::swap(&mut x1, &mut x2);
    }
    let mut n = 0;
    for x in [x1, x2] {
        if x > lo && x < hi {
            out[n] = x;
            n += 1;
        }
    }
    n
}

/// `p(x)` by plain Horner (no fused multiply-add: without a hardware FMA target feature
/// `f64::mul_add` is a library call several times slower than the arithmetic).
#[inline]
fn plain(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &a| acc * x + a)
}

/// `p(x)` with a reliable sign: plain Horner, redone in twice the working precision
/// ([`horner_compensated`]) when the result is within the plain evaluation's rounding bound
/// `4 (d+1) eps sum |c_i| |x|^i` of zero.
#[inline]
fn filtered(c: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    let (mut v, mut bound) = (0.0, 0.0);
    for &a in c.iter().rev() {
        v = v * x + a;
        bound = bound * ax + a.abs();
    }
    if v.abs() <= 4.0 * c.len() as f64 * f64::EPSILON * bound {
        horner_compensated(c, x)
    } else {
        v
    }
}

/// The root of `c` in `(a, b)` where it is monotone with `c(a) = fa` of the other sign than
/// `c(b)`: Newton kept inside the shrinking bracket, bisection otherwise, to adjacent floats.
fn refine(
    c: &[f64],
    deriv: &[f64],
    (mut a, mut b): (f64, f64),
    (fa, fb): (f64, f64),
    evals: &mut u64,
) -> f64 {
    let sa = fa.signum();
    // Start from the secant through the bracket's ends (the midpoint if it falls outside).
    let secant = (a * fb - b * fa) / (fb - fa);
    let mut x = if secant > a && secant < b {
        secant
    } else {
        0.5 * (a + b)
    };
    let mut last_step = f64::INFINITY;
    for _ in 0..4000 {
        *evals += 1;
        let fx = filtered(c, x);
        if fx == 0.0 {
            return x;
        }
        if fx.signum() == sa {
            a = x;
        } else {
            b = x;
        }
        let newton = x - fx / plain(deriv, x);
        let step = (newton - x).abs();
        if step <= 2.0 * f64::EPSILON * x.abs() {
            // Newton has converged on a residual of reliable sign: within an ulp or two.
            return newton.clamp(a, b);
        }
        if newton > a && newton < b && step < 0.5 * last_step {
            last_step = step;
            x = newton;
        } else {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                return if filtered(c, a).abs() <= filtered(c, b).abs() {
                    a
                } else {
                    b
                };
            }
            last_step = f64::INFINITY;
            x = mid;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn largest_root_of_a_product() {
        // (x - 0.1)(x - 0.5)(x - 0.9)
        let c = [-0.045, 0.59, -1.5, 1.0];
        let mut evals = 0;
        let r = largest_root(&c, 0.0, 1.0, &mut evals).unwrap();
        assert!((r - 0.9).abs() < 4e-16, "{r}");
        let r = largest_root(&c, 0.0, 0.7, &mut evals).unwrap();
        assert!((r - 0.5).abs() < 4e-16, "{r}");
        assert!(largest_root(&c, 0.95, 1.0, &mut evals).is_none());
        assert!(largest_root(&[0.0, 0.0], 0.0, 1.0, &mut evals).is_none());
        assert!(evals > 0);
    }

    #[test]
    fn half_rules_rebuild_the_gauss_legendre_rules() {
        for order in 1..=24 {
            let rule = cached_rule(order);
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
                if 2 * j < 2 * order {
                    assert!((sum - exact).abs() < 1e-14, "order {order}, x^{}", 2 * j);
                }
            }
        }
    }

    #[test]
    fn degree_above_the_limit_is_refused() {
        let mut c = [0.0; MAX_DEGREE + 2];
        c[0] = -0.5;
        c[MAX_DEGREE + 1] = 1.0;
        let mut evals = 0;
        assert!(largest_root(&c, 0.0, 1.0, &mut evals).is_none());
    }
}
