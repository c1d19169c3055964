//! The fast path's functions over the reduced motion (`Reduction`'s methods: the state on the
//! reduced motion, `theta_dot^2`, the forces, their polynomials, the fall polynomial) and the
//! `ReductionInfo` literal.

use super::code::{Code, DELTA, K, Locals, OUT, out_lines};
use super::lower::{Hoisted, Scope, lower, unbound};
use super::method::Preamble;
use crate::derive::expr::Expr;
use crate::derive::types::{Derivation, Reduction, StepError};

/// The error of a reduction constant that the emitter needs and the derivation lacks.
pub(super) fn missing_constant(name: &str) -> StepError {
    StepError::Missing(format!("the reduction has no constant `{name}`"))
}
use serde::Serialize;

/// The fast path's functions.
#[derive(Debug, Clone, Serialize)]
pub struct ReducedCode {
    pub(super) k_theta_initial: usize,
    pub(super) k_sin_initial: usize,
    pub(super) k_cos_initial: usize,
    pub(super) reduced_code: Code,
    pub(super) theta_dot_sq_code: Code,
    pub(super) forces: Code,
    /// `Reduction::force_polynomial`: per contact, its polynomial's coefficients.
    pub(super) force_polynomial: Code,
    /// The lines of each contact's polynomial (for the constants the per-point solver reads).
    #[serde(skip)]
    pub(super) polynomial_lines: Vec<Vec<String>>,
    pub(super) fall: Code,
    pub(super) full_state: Code,
    /// The constants the per-point solver reads, and the code computing only them.
    pub(super) prepare_lean: Code,
    pub(super) lean_constants: Vec<usize>,
    /// `Reduction::separation_partials`, `theta_dot_sq_partials`, `start_partials` and
    /// `fall_partials`: the partial derivatives behind the sensitivities.
    pub(super) separation_partials: Code,
    pub(super) theta_dot_sq_partials: Code,
    pub(super) start_partials: Code,
    pub(super) fall_partials: Code,
}

impl ReducedCode {
    /// Every method's code.
    pub(super) fn codes(&self) -> [&Code; 11] {
        [
            &self.reduced_code,
            &self.theta_dot_sq_code,
            &self.forces,
            &self.force_polynomial,
            &self.fall,
            &self.full_state,
            &self.prepare_lean,
            &self.separation_partials,
            &self.theta_dot_sq_partials,
            &self.start_partials,
            &self.fall_partials,
        ]
    }

    /// Each method's arguments and lines; `n` is the length of `k`, `np` the number of
    /// parameters, `reduced` the index of the reduced coordinate.
    pub(super) fn finish(&mut self, n: usize, np: usize, reduced: usize, locals: &Locals) {
        let slice = Preamble::Slice(n);
        let params = Preamble::Names(&locals.params, "k");
        let start =
            Preamble::Offsets([self.k_theta_initial, self.k_sin_initial, self.k_cos_initial]);
        let delta = Preamble::Let("rc_delta", "delta");
        if let [w2, acc] = &self.reduced_code.outputs[..] {
            self.reduced_code.outputs = vec![format!(
                "Reduced {{ sin: rc_s, cos: rc_c, theta_dot_sq: {w2}, theta_ddot: {acc} }}"
            )];
        }
        self.reduced_code
            .finish(&[K, DELTA], &[slice, params, start, delta]);
        let sc = ["rc_s", "rc_c", "rc_ds", "rc_dc"].map(|s| (s, "f64"));
        self.theta_dot_sq_code
            .finish(&[K, sc[0], sc[1], sc[2], sc[3]], &[slice, params]);
        self.forces.outputs = out_lines(&self.forces.outputs);
        self.forces
            .finish(&[K, DELTA, OUT], &[slice, params, start, delta]);
        self.force_polynomial
            .finish(&[K, ("contact", "usize"), OUT], &[slice, params]);
        self.fall.outputs = out_lines(&self.fall.outputs);
        self.fall.finish(&[K, OUT], &[slice, params]);
        let at_angle = [K, sc[0], sc[1], OUT];
        for (code, args) in [
            (&mut self.separation_partials, &at_angle[..]),
            (&mut self.theta_dot_sq_partials, &at_angle[..]),
            (&mut self.start_partials, &[K, OUT][..]),
            (&mut self.fall_partials, &[K, OUT][..]),
        ] {
            code.outputs = out_lines(&code.outputs);
            code.finish(args, &[slice, params]);
        }
        // One bounds check for each slice, not one for each parameter read and each slot
        // written (this runs once per point on the per-point route).
        self.prepare_lean.stmts.splice(
            0..0,
            [
                format!("let k = &mut k[..{n}]; // one bounds check for all constant stores"),
                format!("k[..{np}].copy_from_slice(p);"),
            ],
        );
        let p_slice = format!("&p[..{np}]");
        self.prepare_lean.finish(
            &[("p", "&[f64]"), ("k", "&mut [f64]")],
            &[
                Preamble::Let("p", &p_slice),
                Preamble::Names(&locals.params, "p"),
            ],
        );
        let head = [
            format!("q[{reduced}] = k[{}] - delta;", self.k_theta_initial),
            format!("qd[{reduced}] = theta_dot;"),
        ];
        self.full_state.stmts.splice(0..0, head);
        let args = [
            K,
            ("t", "f64"),
            DELTA,
            ("theta_dot", "f64"),
            ("q", "&mut [f64]"),
            ("qd", "&mut [f64]"),
        ];
        let lets = [
            delta,
            Preamble::Let("rc_t", "t"),
            Preamble::Let("rc_w", "theta_dot"),
        ];
        self.full_state
            .finish(&args, &[slice, params, start, lets[0], lets[1], lets[2]]);
    }
}

/// The `ReductionInfo { .. }` literal of a fast path.
pub(super) fn reduction_info(
    d: &Derivation,
    r: &Reduction,
    code: &ReducedCode,
    scope: &Scope,
) -> Result<String, StepError> {
    let wi = scope
        .constants
        .get("rc_wi")
        .copied()
        .ok_or_else(|| missing_constant("rc_wi"))?;
    let degrees: Vec<usize> = (r.force_polynomials.iter())
        .map(|p| p.as_ref().map_or(0, |s| s.coefficients.len() - 1))
        .collect();
    debug_assert_eq!(degrees.len(), d.contacts.len());
    let proven: Vec<bool> = r.push_proofs.iter().map(Option::is_some).collect();
    Ok(format!(
        "ReductionInfo {{ k_theta_initial: {}, k_theta_dot_initial: {wi}, k_sin_initial: {}, k_cos_initial: {}, force_degrees: &{degrees:?}, pushes_proven: &{proven:?}, release_push_proven: {}, fall_degree: {:?}, lean_constants: &{:?} }}",
        code.k_theta_initial,
        code.k_sin_initial,
        code.k_cos_initial,
        r.release_proof.is_some(),
        r.fall.as_ref().map(|f| f.len() - 1),
        code.lean_constants
    ))
}

/// The fast path's functions over the reduced motion.
pub(super) fn reduced_code(
    d: &Derivation,
    r: &Reduction,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<ReducedCode, StepError> {
    let theta = (d.theta())
        .ok_or_else(|| StepError::Missing("the fast path's reduced coordinate".into()))?
        .to_string();
    let idx = |s: &str| {
        scope
            .constants
            .get(s)
            .copied()
            .ok_or_else(|| missing_constant(s))
    };
    // rc_s, rc_c, rc_ds, rc_dc are locals set by the template's preamble.
    let mut red_scope = scope.clone();
    for s in ["rc_s", "rc_c", "rc_ds", "rc_dc", "rc_delta", "rc_t", "rc_w"] {
        red_scope.locals.insert(s.into(), s.into());
    }
    red_scope
        .locals
        .insert(theta.clone(), format!("(k[{}] - rc_delta)", idx("rc_thi")?));
    let mut reduced = Code::default();
    reduced.outputs = reduced.push_body(lower(
        &[r.theta_dot_sq.clone(), r.theta_ddot.clone()],
        &red_scope,
        Some(hoisted),
        "r",
    ));

    // theta_dot^2 alone from sin, cos and their drops (the lean solver's integrand).
    let mut sc_scope = scope.clone();
    for s in ["rc_s", "rc_c", "rc_ds", "rc_dc"] {
        sc_scope.locals.insert(s.into(), s.into());
    }
    let stray = unbound(std::slice::from_ref(&r.theta_dot_sq), &sc_scope);
    if !stray.is_empty() {
        return Err(StepError::Unbound {
            what: "theta_dot^2 depends on",
            symbols: stray.into_iter().collect(),
            besides: "sin, cos and constants",
        });
    }
    let mut theta_dot_sq = Code::default();
    theta_dot_sq.outputs = theta_dot_sq.push_body(lower(
        std::slice::from_ref(&r.theta_dot_sq),
        &sc_scope,
        Some(hoisted),
        "r",
    ));

    // Forces: theta_dot^2 and theta_ddot first, then the forces over them.
    let mut force_scope = red_scope.clone();
    force_scope.locals.insert("rc_w2".into(), "rc_w2".into());
    force_scope.locals.insert("rc_acc".into(), "rc_acc".into());
    let mut forces = Code::default();
    let wa = forces.push_body(lower(
        &[r.theta_dot_sq.clone(), r.theta_ddot.clone()],
        &red_scope,
        Some(hoisted),
        "r",
    ));
    forces.bind("rc_w2", wa[0].clone());
    forces.bind("rc_acc", wa[1].clone());
    let fo = forces.push_body(lower(&r.forces_reduced, &force_scope, Some(hoisted), "f"));
    forces.outputs = fo;

    // Each contact's force polynomial: coefficients are constants, hoisted into k; one arm of
    // `match contact` per contact that has one.
    let mut force_polynomial = Code::default();
    let mut polynomial_lines = Vec::new();
    let mut arms = Vec::new();
    for (i, p) in r.force_polynomials.iter().enumerate() {
        let mut lines = Vec::new();
        if let Some(sep) = p {
            let mut arm = Code::default();
            let out = arm.push_body(lower(&sep.coefficients, scope, Some(hoisted), "p"));
            lines = arm.stmts.iter().cloned().chain(out_lines(&out)).collect();
            arms.push(format!("{i} => {{"));
            arms.extend(lines.iter().cloned());
            arms.push("}".into());
        }
        polynomial_lines.push(lines);
    }
    if !arms.is_empty() {
        force_polynomial.stmts.push("match contact {".into());
        force_polynomial.stmts.extend(arms);
        force_polynomial.stmts.push("_ => {}".into());
        force_polynomial.stmts.push("}".into());
    }
    // Fall polynomial: coefficients are constants too.
    let mut fall = Code::default();
    if let Some(coefficients) = &r.fall {
        fall.outputs = fall.push_body(lower(coefficients, scope, Some(hoisted), "p"));
    }

    // Full state on the reduced motion.
    let mut full_state = Code::default();
    let cy = full_state.push_body(lower(&r.cyclic_position, &red_scope, Some(hoisted), "x"));
    let cv = full_state.push_body(lower(&r.cyclic_velocity, &red_scope, Some(hoisted), "v"));
    full_state.outputs = d
        .cyclic
        .iter()
        .enumerate()
        .flat_map(|(j, &ci)| {
            [
                format!("q[{ci}] = {};", cy[j]),
                format!("qd[{ci}] = {};", cv[j]),
            ]
        })
        .collect();
    // The partial derivatives: over the parameters (read by name, nothing hoisted, so that
    // `prepare` does no work for them), `rc_s` and `rc_c`.
    let mut sc_only = scope.clone();
    for s in ["rc_s", "rc_c"] {
        sc_only.locals.insert(s.into(), s.into());
    }
    let partial = |exprs: &[Expr]| -> Code {
        let mut code = Code::default();
        if !exprs.is_empty() {
            code.outputs = code.push_body(lower(exprs, &sc_only, None, "d"));
        }
        code
    };
    let pd = &r.partials;
    Ok(ReducedCode {
        separation_partials: partial(&pd.separation),
        theta_dot_sq_partials: partial(&pd.theta_dot_sq),
        start_partials: partial(&pd.start_sine),
        fall_partials: partial(&pd.fall),
        k_theta_initial: idx("rc_thi")?,
        k_sin_initial: idx("rc_si")?,
        k_cos_initial: idx("rc_ci")?,
        reduced_code: reduced,
        theta_dot_sq_code: theta_dot_sq,
        forces,
        force_polynomial,
        polynomial_lines,
        fall,
        full_state,
        prepare_lean: Code::default(),
        lean_constants: Vec::new(),
    })
}
