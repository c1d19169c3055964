//! A lean per-point solve of the separation angle and time, for sweeps of millions of points:
//! every buffer is allocated once per solver and reused, nothing is kept per point, and the
//! numerics are the project's one copy of each: parameters checked by
//! [`check_parameters`], the root by the isolator of [`poly`], the time by the quadrature of
//! [`quadrature`] (its module docs give the substitution that makes a few Gauss–Legendre nodes
//! reach `f64` accuracy across the whole parameter range, and its error control).
//!
//! Where the model has a fall polynomial of degree at most 2 (rod_cube, hinged_rod, loaded_rod,
//! wall_ladder), the solver prepares only the constants it reads
//! ([`Reduction::prepare_lean`]) and takes the node
//! counts a priori from the integrand's singularities ([`prior`](crate::solve::fast::prior)): about
//! 7 evaluations per point instead of 19, at `2^-53` relative. Such a point is first solved on
//! an unchecked route ([`LeanRoute::lean_point`], implemented here for every model type): its
//! inputs come from [`Model::lean_start`] (a default trait method, so each model's copy is
//! compiled with its generated functions inlined: the parameters' quick test, the start and
//! polynomials, and whether the first contact pushes at release, unless the derivation proved
//! it does), then the same root, integrand and plan with nothing but numbers between them (no
//! error values built); the other contacts' pushes are certified on the way, but those the
//! derivation proved positive over the phase (`derive::positivity`, written out in the model's
//! LaTeX). Anything short of a clean solve there (a parameter the quick test does not pass, a
//! first contact that does not push at release, a value not finite, no root, another contact
//! that lets go first, a phase that does not fall, too many panels)
//! sends the point through the checked route (`LeanSolver::checked`), which solves it again and
//! names what failed; so the unchecked route never decides an error. The unchecked route has a
//! second compiled copy, [`LeanRoute::lean_point_avx2`], the same source built for AVX2 (4-wide
//! division and root in the integrand) and taken when the CPU reports AVX2 at the solver's
//! construction; it gives the same bits as the baseline copy ([`LeanSolver::baseline_only`]
//! turns it off for comparison).
//!
//! `rodcube accuracy` and the tests in `tests/hard_cases.rs` check the result against the
//! high-precision reference (`rodcube::reference`, feature `cli`) across `n = m2/m1` from 1e-12 to
//! 1e12 and `a/ell` from 1e-10 to `1 - 1e-9`.

use crate::model::PhaseInfo;
use crate::model::{
    LeanStart, Model, ModelInfo, Reduction, ReductionInfo, positive_finite, pushes,
};
use crate::results::EndCause;
use crate::results::{SensitivityGap, Work};
use crate::solve::SolveError;
use crate::solve::fast::poly::{self, MAX_DEGREE};
use crate::solve::fast::prior::{PRIOR_TOL, Prior, Singularities, integrate_prior, prior_panels};
use crate::solve::fast::quadrature::{
    self, ACCEPT, Control, Fall, FallIntegrand, HalfRule, PanelSum, RuleStep, SCHEDULE, v_at_drop,
};
use crate::solve::fast::sensitivity::{self, SensitivityWork, SeparationPoint};
use crate::solve::phases::phase_end;
use crate::system::{System, SystemError, check_parameters, ordered_values, prepare_constants};

/// The fast phase a system starts in (its release phase), looked up in the registry; a model
/// that is not a system's general model is taken as it is.
pub(crate) fn release_phase(model: &dyn Model) -> Result<&dyn Model, SolveError> {
    let info = model.info();
    if !info.is_general() || model.reduction().is_some() && info.contacts.iter().all(|c| c.closed) {
        return Ok(model);
    }
    let entry: Option<&PhaseInfo> = info.phases.iter().find(|p| p.release);
    let Some(entry) = entry else {
        return Err(SolveError::NotPerPoint {
            model: info.name,
            why: "it has no fast phase that starts at release",
        });
    };
    crate::models::find(entry.model).ok_or(SolveError::UnknownPhaseModel {
        system: info.name,
        name: entry.model,
    })
}

/// One point's separation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeanPoint {
    /// `theta_sep` (rad).
    pub separation_angle: f64,
    /// Time from release to separation (s).
    pub separation_time: f64,
    /// `sin(theta_i)`, `cos(theta_i)` and `sin(theta_sep)`, from which [`LeanPoint::delta`] is
    /// formed when asked (with the drop `sin(theta_i) - sin(theta_sep)`, exact where the two
    /// are within a factor of two, by Sterbenz's lemma, and formed as every route forms it).
    sines: [f64; 3],
}

impl LeanPoint {
    /// `delta = theta_i - theta_sep` (rad), the angle fallen, formed only when asked (its
    /// `atan2` is not part of the per-point cost): `atan2(sin delta, cos delta)` with
    /// `sin delta = (s_i - s)(s_i + s) / (s_i c + c_i s)` from the drop, without the
    /// cancellation of `theta_i - theta_sep` or of `s_i c - c_i s` when `delta` is small.
    pub fn delta(&self) -> f64 {
        let [si, ci, s] = self.sines;
        let drop = si - s;
        let c = ((1.0 - s) * (1.0 + s)).sqrt();
        // sin(theta_i + theta_sep): the identity's denominator; near zero (theta_sep near
        // -theta_i, delta far from small) the plain difference is as accurate.
        let sum = si * c + ci * s;
        let sin_delta = if sum > 0.5 * (si * c).abs() {
            drop * (si + s) / sum
        } else {
            si * c - ci * s
        };
        sin_delta.atan2(ci * c + si * s)
    }
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
    /// The fall polynomial's coefficients (empty without one).
    fall: Vec<f64>,
    control: Control,
    /// The a-priori rule, where the model's fall polynomial allows it and no rules were asked.
    prior: Option<Prior>,
    /// Scratch for parameters given by name.
    named: Vec<f64>,
    stack: Vec<(f64, f64)>,
    /// Whether the unchecked route runs its AVX2 copy (the CPU has it).
    wide: bool,
    /// Evaluations of `theta_dot^2` and of the polynomial since the solver was made.
    pub evals: u64,
}

impl std::fmt::Debug for LeanSolver<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LeanSolver")
            .field("model", &self.info.name)
            .field("rules", &self.control.steps())
            .field("accept", &self.control.accept)
            .finish()
    }
}

impl<'m> LeanSolver<'m> {
    /// A solver with the default schedule [`SCHEDULE`] and tolerance [`ACCEPT`]. The model must
    /// have a contact whose separation polynomial has degree at most [`MAX_DEGREE`]. Where the
    /// model has a fall polynomial of degree at most 2, the time is integrated by the a-priori
    /// rule of [`prior`](crate::solve::fast::prior) to `2^-53` relative, else by the verified pair
    /// of rules.
    pub fn new(model: &'m dyn Model) -> Result<Self, SolveError> {
        let mut solver = Self::with_schedule(model, &SCHEDULE, ACCEPT)?;
        if solver.layout.fall_degree.is_some_and(|d| d <= 2) {
            solver.prior = Some(Prior::new(PRIOR_TOL));
        }
        Ok(solver)
    }

    /// [`LeanSolver::new`] with the a-priori rule made for a relative error `tol` instead of
    /// `2^-53` (raised to `2^-53`; not finite means `2^-53`). A model whose fall polynomial
    /// does not allow the a-priori rule is [`SolveError::NotPerPoint`]: it has no such rule to
    /// loosen.
    pub fn with_tolerance(model: &'m dyn Model, tol: f64) -> Result<Self, SolveError> {
        let mut solver = Self::with_schedule(model, &SCHEDULE, ACCEPT)?;
        if solver.layout.fall_degree.is_none_or(|d| d > 2) {
            return Err(SolveError::NotPerPoint {
                model: solver.info.name,
                why: "its fall polynomial has no a-priori rule (degree above 2)",
            });
        }
        solver.prior = Some(Prior::new(tol));
        Ok(solver)
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

    /// A solver with a rule schedule (steps in any order; an empty one means the default), every
    /// panel verified by its two rules.
    pub fn with_schedule(
        model: &'m dyn Model,
        schedule: &[RuleStep],
        accept: f64,
    ) -> Result<Self, SolveError> {
        let model = release_phase(model)?;
        let info = model.info();
        let (Some(red), Some(layout)) = (model.reduction(), info.reduction.as_ref()) else {
            return Err(SolveError::Parameters(SystemError::NoReduction {
                model: info.name,
                why: info.route_note,
            }));
        };
        let end_angle =
            (info.end_angle).ok_or(SolveError::Parameters(SystemError::NoEndAngle {
                model: info.name,
            }))?;
        let why = if !info
            .contacts
            .first()
            .is_some_and(|c| c.closed && !c.bilateral)
        {
            Some("its first contact is not a closed unilateral contact")
        } else if info.contacts.iter().any(|c| !c.closed) {
            Some("it leaves a contact open, whose gap only the planner watches")
        } else if info.contacts.iter().any(|c| c.edge) {
            Some("a contact can end at an edge")
        } else if !layout.polynomial_separation() {
            Some("its separation is no polynomial root")
        } else if (info.contacts.iter().zip(layout.force_degrees))
            .skip(1)
            .any(|(c, &d)| !c.bilateral && d == 0)
        {
            Some("another contact's force has no polynomial whose roots the solver could check")
        } else {
            None
        };
        if let Some(why) = why {
            return Err(SolveError::NotPerPoint {
                model: info.name,
                why,
            });
        }
        if layout.separation_degree() > MAX_DEGREE {
            return Err(SolveError::BadPolynomial {
                model: info.name,
                coefficients: Vec::new(),
            });
        }
        Ok(LeanSolver {
            model,
            info,
            red,
            layout,
            sin_end: end_angle.sin(),
            k: vec![0.0; info.n_constants],
            margins: vec![0.0; info.requirements.len()],
            fall: vec![0.0; layout.fall_degree.map_or(0, |d| d + 1)],
            control: Control::new(schedule, accept),
            prior: None,
            named: Vec::new(),
            stack: Vec::with_capacity(64),
            wide: has_avx2(),
            evals: 0,
        })
    }

    /// The model.
    pub fn model(&self) -> &'m dyn Model {
        self.model
    }

    /// Validates the values of `p` (in the model's parameter order) and the model's
    /// requirements exactly as [`System::from_values`](crate::system::System::from_values)
    /// does, then solves.
    ///
    /// With the a-priori rule the point is first solved from [`Model::lean_start`] (only the
    /// constants it reads, nothing checked but numbers); a point that fails that way is
    /// validated, and solved again from the lean constants and then from every constant, so
    /// that its error is the one the full preparation reports. So a constant the separation
    /// reads that is not finite is the full preparation's [`SystemError::BadConstant`]; one
    /// it does not read is not formed, and the point is solved where the full model is
    /// refused (a cube of `1e300` kg: the floor's push, which the derivation proved positive,
    /// has `m2^2` among its constants).
    #[inline]
    pub fn solve(&mut self, p: &[f64]) -> Result<LeanPoint, SolveError> {
        if let Some(prior) = &self.prior {
            #[cfg(target_arch = "x86_64")]
            let quick = if self.wide {
                // SAFETY: `wide` is set only where the CPU has AVX2 (`has_avx2`).
                unsafe {
                    self.model
                        .lean_point_avx2(p, prior, self.sin_end, &mut self.evals)
                }
            } else {
                self.model
                    .lean_point(p, prior, self.sin_end, &mut self.evals)
            };
            #[cfg(not(target_arch = "x86_64"))]
            let quick = self
                .model
                .lean_point(p, prior, self.sin_end, &mut self.evals);
            if let Some(point) = quick {
                return Ok(point);
            }
        }
        self.checked(p)
    }

    /// The sensitivities of `point`, which this solver solved for the parameters `p`:
    /// `d theta_sep/dp_i` into `angle` and `d t_sep/dp_i` into `time` (one entry per
    /// parameter, in the model's order), by [`sensitivity::separation`], or why they do not
    /// exist. Slices of another length are [`SystemError::Length`].
    pub fn sensitivities(
        &mut self,
        p: &[f64],
        point: &LeanPoint,
        work: &mut SensitivityWork,
        angle: &mut [f64],
        time: &mut [f64],
    ) -> Result<Result<(), SensitivityGap>, SolveError> {
        let np = self.info.parameters.len();
        for (what, len) in [("p", p.len()), ("angle", angle.len()), ("time", time.len())] {
            if len != np {
                return Err(SolveError::Input(SystemError::Length {
                    model: self.info.name,
                    what,
                    expected: np,
                    got: len,
                }));
            }
        }
        let [sin_initial, cos_initial, sin_sep] = point.sines;
        let drop = sin_initial - sin_sep;
        // The partial derivatives read the parameters alone; the fall polynomial comes from
        // the lean constants (formed again here rather than kept in every point: the point's
        // copies cost each solve more than this costs a sensitivity).
        self.red.prepare_lean(p, &mut self.k);
        self.fall.clear();
        if let Some(degree) = self.layout.fall_degree {
            self.fall.resize(degree + 1, 0.0);
            self.red.fall_polynomial(&self.k, &mut self.fall);
        }
        let at = SeparationPoint {
            red: self.red,
            k: &self.k,
            parameters: np,
            sin_initial,
            // 1 - sin(theta_i) without cancellation near upright, as the time's quadrature.
            scale: cos_initial * cos_initial / (1.0 + sin_initial),
            fall: &self.fall,
            singularities: None,
            sin_sep,
            drop,
        };
        let default_prior;
        let prior = match &self.prior {
            Some(prior) => prior,
            None => {
                default_prior = Prior::new(PRIOR_TOL);
                &default_prior
            }
        };
        sensitivity::separation(&at, prior, self.control.accept, work, angle, time)
    }

    /// Solves by the baseline instruction set even where the CPU has AVX2 (the results are
    /// the same to the bit, which `tests/prior.rs` checks; the two can be timed side by side,
    /// as `examples/per_point.rs --baseline` does).
    pub fn baseline_only(&mut self) {
        self.wide = false;
    }

    /// Whether points are solved by the AVX2 copy of the route ([`LeanRoute::lean_point_avx2`]).
    pub fn wide(&self) -> bool {
        self.wide
    }

    /// [`LeanSolver::solve`] by the checked route: every step's failure is a typed error. The
    /// phase's end comes from the planner's one route ([`phase_end`]): a closed contact that
    /// does not push at release, or whose force reaches zero before the separation, leaves the
    /// phase the solver solves, which is [`SolveError::NotThisPhase`].
    #[inline(never)]
    fn checked(&mut self, p: &[f64]) -> Result<LeanPoint, SolveError> {
        check_parameters(self.model, p, &mut self.margins).map_err(SolveError::Parameters)?;
        prepare_constants(self.model, p, &mut self.k).map_err(SolveError::Parameters)?;
        let sys = System::from_values(self.model, p).map_err(SolveError::Parameters)?;
        let mut work = Work::default();
        let end = phase_end(&sys, &mut work)?;
        self.evals += work.polynomial_evals;
        match end.end {
            EndCause::Force(c) if c.index == 0 => {}
            EndCause::Force(c) if end.delta == 0.0 => {
                return Err(SolveError::NotThisPhase {
                    model: self.info.name,
                    contact: c.name,
                    why: "would have to pull",
                });
            }
            EndCause::Force(c) => {
                return Err(SolveError::NotThisPhase {
                    model: self.info.name,
                    contact: c.name,
                    why: "lets go before the separation",
                });
            }
            _ => {
                return Err(SolveError::NoSeparation {
                    model: self.info.name,
                    coefficients: sys.separation_coefficients(),
                    lo: self.sin_end,
                    hi: self.k[self.layout.k_sin_initial],
                });
            }
        }
        let si = self.k[self.layout.k_sin_initial];
        if end.delta == 0.0 {
            // The first contact lets go at once: separation at release.
            return Ok(LeanPoint {
                separation_angle: si.asin(),
                separation_time: 0.0,
                sines: [si, self.k[self.layout.k_cos_initial], si],
            });
        }
        let s = end.at.map_or(f64::NAN, |a| a.sin_theta);
        self.solve_prepared(s, si - s)
    }

    /// [`LeanSolver::solve`] with the parameters by name (any order, each exactly once), put
    /// in the model's order by [`ordered_values`] (unknown, missing and repeated names are
    /// typed errors).
    pub fn solve_named<S: AsRef<str>>(
        &mut self,
        params: &[(S, f64)],
    ) -> Result<LeanPoint, SolveError> {
        let mut p = std::mem::take(&mut self.named);
        p.resize(self.info.parameters.len(), 0.0);
        let outcome = ordered_values(self.info, params, &mut p)
            .map_err(SolveError::Parameters)
            .and_then(|()| self.solve(&p));
        self.named = p;
        outcome
    }

    /// The separation angle and time from prepared constants, the separation at `sin(theta)
    /// = s`, `drop = sin(theta_i) - s` below the start.
    fn solve_prepared(&mut self, s: f64, drop: f64) -> Result<LeanPoint, SolveError> {
        let (si, ci) = (
            self.k[self.layout.k_sin_initial],
            self.k[self.layout.k_cos_initial],
        );
        let point = |separation_time| LeanPoint {
            separation_angle: s.asin(),
            separation_time,
            sines: [si, ci, s],
        };
        // The phase's end for messages, formed only for one.
        let delta_end = || point(f64::NAN).delta();
        if !(drop > 0.0 && drop.is_finite()) {
            return Err(SolveError::BadPhaseEnd {
                model: self.info.name,
                delta_end: delta_end(),
            });
        }
        match self.time(drop) {
            Ok(t) => Ok(point(t)),
            Err(SolveError::TurningPoint {
                model,
                delta,
                theta_dot_sq,
                ..
            }) => Err(SolveError::TurningPoint {
                model,
                delta,
                theta_dot_sq,
                delta_end: delta_end(),
            }),
            Err(e) => Err(e),
        }
    }

    /// The time from the start to the drop `sin(theta_i) - sin(theta_sep) = drop > 0`.
    fn time(&mut self, drop: f64) -> Result<f64, SolveError> {
        if !self.fall.is_empty() {
            self.red.fall_polynomial(&self.k, &mut self.fall);
        }
        // The phase's end is given to messages by the caller.
        let fall = Fall::new(
            self.info.name,
            self.red,
            &self.k,
            self.layout,
            &self.fall,
            f64::NAN,
        )?;
        let v_end = fall.v_at_drop(drop);
        let prior = match &self.prior {
            Some(prior) => integrate_prior(&fall, v_end, prior)?,
            None => None,
        };
        let (t, evals) = match prior {
            Some(done) => done,
            None => quadrature::integrate(&fall, v_end, &self.control, &mut self.stack, |_| {})?,
        };
        self.evals += evals;
        Ok(t)
    }
}

/// The per-point solver's unchecked route of one model: [`Model::lean_start`] and the root,
/// integrand and a-priori plan of `quick_route`, with `evals` counting the evaluations.
/// `None` says nothing about why: [`LeanSolver`] then takes its checked route, which decides
/// and names the error.
///
/// Implemented for every model by the blanket impl below. [`LeanSolver`] runs the copy for
/// `dyn Model`, which calls the model's own compiled [`Model::lean_start`] (its generated
/// functions inlined) once per point and has the rest of the route inlined into the solver's
/// caller; a program holding a generated model's type
/// ([`generated`](crate::models::generated)) can call that type's copy, with the start
/// inlined too.
pub trait LeanRoute {
    /// The route for the parameters `p`, to `prior`'s tolerance, with the root's bracket's low
    /// end at `sin_end`.
    fn lean_point(
        &self,
        p: &[f64],
        prior: &Prior,
        sin_end: f64,
        evals: &mut u64,
    ) -> Option<LeanPoint>;

    /// [`LeanRoute::lean_point`] compiled for AVX2 (VEX encoding and four lanes), with the
    /// same result to the bit: the same operations in the same order, correctly rounded in
    /// every lane (no fused multiply-add). [`LeanSolver`] calls it where the CPU has AVX2.
    ///
    /// # Safety
    /// The CPU must have AVX2 (`is_x86_feature_detected!("avx2")`).
    #[cfg(target_arch = "x86_64")]
    unsafe fn lean_point_avx2(
        &self,
        p: &[f64],
        prior: &Prior,
        sin_end: f64,
        evals: &mut u64,
    ) -> Option<LeanPoint>;
}

impl<M: Model + ?Sized> LeanRoute for M {
    #[inline]
    fn lean_point(
        &self,
        p: &[f64],
        prior: &Prior,
        sin_end: f64,
        evals: &mut u64,
    ) -> Option<LeanPoint> {
        quick_route(
            &self.lean_start(p),
            prior,
            sin_end,
            evals,
            |f, rule, a, b| f.panel(rule, a, b, a == 0.0),
        )
    }

    /// The body repeats `lean_point`'s with the panel's AVX2 build named: calling
    /// `self.lean_point` here instead left the panel out of line in the baseline instruction
    /// set (1,023 instructions per point against 851, `examples/per_point.rs`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn lean_point_avx2(
        &self,
        p: &[f64],
        prior: &Prior,
        sin_end: f64,
        evals: &mut u64,
    ) -> Option<LeanPoint> {
        quick_route(
            &self.lean_start(p),
            prior,
            sin_end,
            evals,
            |f, rule, a, b| f.panel_avx2(rule, a, b, a == 0.0),
        )
    }
}

/// Whether the CPU has AVX2 (where the unchecked route has a copy for it).
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The unchecked route from a point's start ([`Model::lean_start`]) with nothing but numbers
/// in between: the separation polynomial's root ([`poly::largest_root`]) in `(sin_end,
/// sin(theta_i))`, the fall's integrand ([`FallIntegrand`]) and the a-priori plan
/// ([`prior_panels`]), each the one copy the checked route also uses. `None` without a start (`Model::lean_start` gave none) and on anything short
/// of a phase that falls from rest to a separation inside it with positive finite values at
/// every node: the checked route ([`LeanSolver::solve`]) then solves the point again and names
/// what failed. Called from [`LeanRoute::lean_point`], once per compiled copy of the route.
#[inline(always)]
pub(crate) fn quick_route(
    start: &Option<LeanStart>,
    prior: &Prior,
    sin_end: f64,
    evals: &mut u64,
    rule_on: impl Fn(&FallIntegrand, &HalfRule, f64, f64) -> PanelSum,
) -> Option<LeanPoint> {
    // Matched by reference, not moved out of the `Option` by `?` (a copy of the start).
    let Some(start) = start else {
        return None;
    };
    let (si, ci) = (start.sin_initial, start.cos_initial);
    // Every coefficient finite, by one test (`0 c` is 0 exactly when `c` is finite; no
    // iterator adapter, which each copy of the route would call out of line).
    let ([c0, c1, c2, c3], [p0, p1, p2]) = (start.separation, start.fall);
    let zero = 0.0 * c0 + 0.0 * c1 + 0.0 * c2 + 0.0 * c3 + 0.0 * p0 + 0.0 * p1 + 0.0 * p2;
    if !((zero == 0.0) & (start.theta_dot_initial == 0.0)) {
        return None;
    }
    let (sep, fall) = (&start.separation[..], &start.fall[..]);
    // The first contact pushes at release (`Model::lean_start` tested it, or the derivation
    // proved it); no other closed contact lets go before the separation (each polynomial has
    // its force's sign). The release test in the route rather than the start cost 34
    // instructions a point of `examples/per_point.rs`, in spills around it.
    let s = poly::largest_root(sep, sin_end, si, evals)??;
    for other in start.others.iter().take(start.n_others) {
        // Certainly positive on [s, si] (so at release too), else pushing at release and no
        // root in between (out of line: `positive_on` decides every push of the per-point
        // set, mostly by its first stage).
        if !poly::positive_on(other, s, si) && !pushes_until(other, s, si, evals)? {
            return None;
        }
    }
    let drop = si - s;
    // 1 - sin(theta_i) without cancellation near upright.
    let e = ci * ci / (1.0 + si);
    // Below the vertical, and a drop inside the phase (integer tests, without branches).
    if !(positive_finite(e) & positive_finite(drop) & (si.abs() < 1.0) & (ci > 0.0)) {
        return None;
    }
    // Whether the phase falls needs no test of its own here: the plan integrates no panel
    // with a zero of the fall polynomial on it (the zero is then a singular point on the
    // path, whose rho is 1) and takes every node's value positive, so the polynomial is
    // positive over the whole path, its start included.
    let integrand = FallIntegrand::new(si, e, fall);
    let v_end = v_at_drop(e, drop);
    let mut sing = Singularities::NONE;
    sing.find(si, e, fall)?;
    let panel = |rule: &HalfRule, a: f64, b: f64| {
        let sum = rule_on(&integrand, rule, a, b);
        if sum.ok() {
            Ok((sum.value, sum.evals))
        } else {
            Err(())
        }
    };
    let (t, n) = prior_panels(&sing, v_end, prior, panel).ok()??;
    *evals += n;
    Some(LeanPoint {
        separation_angle: s.asin(),
        separation_time: t,
        sines: [si, ci, s],
    })
}

/// Whether a push `other` that [`poly::positive_on`] could not certify on `[s, si]` pushes at
/// release and has no root in between (`None` past the root finder's degree). Out of line:
/// the rare path.
#[cold]
#[inline(never)]
fn pushes_until(other: &[f64], s: f64, si: f64, evals: &mut u64) -> Option<bool> {
    Some(pushes(other, si) && poly::largest_root(other, s, si, evals)?.is_none())
}

#[cfg(test)]
mod tests {
    use super::{LeanPoint, LeanRoute};
    use crate::model::Model;
    use crate::models::generated::rod_cube_closed::RodCubeClosed;
    use crate::solve::fast::prior::{PRIOR_TOL, Prior};

    #[test]
    fn a_model_types_route_is_the_dyn_route() {
        // The copy compiled for the generated type and the one the solver runs (`dyn Model`)
        // give the same bits, the same refusals and the same evaluation counts.
        let prior = Prior::new(PRIOR_TOL);
        let dynamic: &dyn Model = &RodCubeClosed;
        let Some(end_angle) = dynamic.info().end_angle else {
            panic!("rod_cube_closed has an end angle");
        };
        let sin_end = end_angle.sin();
        let mut served = 0;
        for (m2, a) in [
            (3.0, 0.25),
            (1e-3, 0.01),
            (1e3, 0.99),
            (1.0, 2.0),
            (f64::NAN, 0.5),
        ] {
            let p = [1.0, m2, 1.0, a, 9.81];
            let (mut e1, mut e2) = (0, 0);
            let typed = RodCubeClosed.lean_point(&p, &prior, sin_end, &mut e1);
            let erased = dynamic.lean_point(&p, &prior, sin_end, &mut e2);
            assert_eq!(typed, erased, "{p:?}");
            assert_eq!(e1, e2, "{p:?}");
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                let mut e3 = 0;
                // SAFETY: the CPU has AVX2.
                let wide = unsafe { RodCubeClosed.lean_point_avx2(&p, &prior, sin_end, &mut e3) };
                assert_eq!(wide, erased, "{p:?}");
                assert_eq!(e3, e2, "{p:?}");
            }
            served += usize::from(typed.is_some());
        }
        assert_eq!(served, 3);
    }

    fn point(si: f64, s: f64) -> LeanPoint {
        LeanPoint {
            separation_angle: s.asin(),
            separation_time: 0.0,
            sines: [si, ((1.0 - si) * (1.0 + si)).sqrt(), s],
        }
    }

    #[test]
    fn a_tiny_angle_fallen_keeps_its_digits() {
        // delta = asin(si) - asin(si - d) = d / c - d^2 si / (2 c^3) + d^3 (1 + 2 si^2) /
        // (6 c^5) + O(d^4): with d = 1e-9 si the series is exact to 1e-20 relative, while
        // `theta_i - theta_sep` would keep only about 7 digits.
        for si in [0.01f64, 0.3, 0.7, 0.99] {
            // The drop as the floats hold it (exact, by Sterbenz's lemma).
            let s = si - 1e-9 * si;
            let d = si - s;
            let c = ((1.0 - si) * (1.0 + si)).sqrt();
            let u = d / (c * c);
            let series = d / c * (1.0 - u * si / 2.0 + u * u * (1.0 + 2.0 * si * si) / 6.0);
            let got = point(si, s).delta();
            assert!(
                ((got - series) / series).abs() < 4.0 * f64::EPSILON,
                "si = {si}: {got} vs {series}"
            );
        }
        // A large angle fallen, and one past theta_sep = -theta_i (the identity's denominator
        // vanishes there; the plain difference of products serves).
        for (si, s) in [(0.9f64, 0.1f64), (0.5, -0.5), (0.6, -0.59)] {
            let want = si.asin() - s.asin();
            let got = point(si, s).delta();
            assert!(
                ((got - want) / want).abs() < 1e-15,
                "{si} {s}: {got} vs {want}"
            );
        }
    }
}
