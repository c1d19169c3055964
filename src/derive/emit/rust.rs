//! The Rust writer: [`RustContext`], everything `templates/model.rs.tera` needs for one
//! phase, built from the parts ([`info`](super::info), [`docs`](super::docs), [`constants`](super::constants),
//! [`state`](super::state), [`reduced`](super::reduced)) once the constant layout is known.

use super::code::{Code, K, Locals, OUT, Q, out_lines, parameter_local};
use super::constants::{constant_layout, prepare_code, unread_constants};
use super::docs::{Docs, model_docs, reduction_docs, tangents_docs};
use super::info::{PhaseEntry, StaticInfo, static_info};
use super::lower::{Hoisted, Scope, lower};
use super::method::Preamble;
use super::reduced::{ReducedCode, reduced_code, reduction_info};
use super::state::{FullStateCode, drawing_code, full_state_code};
use super::tangents::{TangentsCode, tangents_code};
use crate::derive::expr::Expr;
use crate::derive::spec::Checked;
use crate::derive::types::{Derivation, StepError};
use serde::Serialize;
use std::collections::BTreeSet;

/// Everything the Rust template needs, all computed.
#[derive(Debug, Clone, Serialize)]
pub struct RustContext {
    #[serde(flatten)]
    info: StaticInfo,
    n_constants: usize,
    /// `ShapeInfo { .. }` literals.
    shapes_info: Vec<String>,
    /// `Model::drawing`: the bodies' poses and the shapes' numbers.
    drawing: Code,
    /// `ReductionInfo { .. }` when the phase has the fast path.
    reduction_info: Option<String>,
    requirements: Code,
    restitutions: Code,
    prepare: Code,
    #[serde(flatten)]
    general: FullStateCode,
    reduction: Option<ReducedCode>,
    /// The general model's `Tangents::tangent_rows` and `Tangents::initial_tangents`.
    tangents: Option<TangentsCode>,
    /// Each method's doc comment, by the method's name.
    docs: Docs,
    /// The reduction's named constants that nothing reads (see [`rust_context`]).
    #[serde(skip)]
    unread: BTreeSet<String>,
}

/// Builds the Rust context of one derived phase; `phases` are its system's fast phases.
///
/// A named constant of the reduction that no generated line reads and the runtime does not
/// read either (`ReductionInfo`'s start slots) gets no slot: the context is built once to find
/// such constants, and again without them.
pub fn rust_context(
    checked: &Checked,
    d: &Derivation,
    phases: &[PhaseEntry],
) -> Result<RustContext, StepError> {
    let first = context_without(checked, d, phases, &BTreeSet::new())?;
    if first.unread.is_empty() {
        return Ok(first);
    }
    let second = context_without(checked, d, phases, &first.unread)?;
    match second.unread.is_empty() {
        true => Ok(second),
        false => Err(StepError::Unread(second.unread)),
    }
}

/// [`rust_context`] with the reduction constants `skip` left out of `k`.
fn context_without(
    checked: &Checked,
    d: &Derivation,
    phases: &[PhaseEntry],
    skip: &BTreeSet<String>,
) -> Result<RustContext, StepError> {
    let np = d.params.len();
    let (scope, start, own) = constant_layout(d, skip);
    let mut hoisted = Hoisted::new(np + own.len());
    if let Ok(r) = &d.reduction {
        for &(j, slot) in &own {
            hoisted.known(&r.constants[j].value, slot);
        }
    }
    let mut general = full_state_code(d, &scope, &mut hoisted)?;
    let mut reduction = match &d.reduction {
        Ok(r) => Some(reduced_code(d, r, &scope, &mut hoisted)?),
        Err(_) => None,
    };
    let (mut drawing, shapes_info) = drawing_code(d, &scope, &mut hoisted);
    // Last, so that the other methods' constants keep their slots.
    let mut tangents = (d.tangents.as_ref())
        .map(|t| tangents_code(d, t, &scope, &mut hoisted))
        .transpose()?;
    let mut requirements = parameters_code(&d.requirements, d);
    let mut restitutions = parameters_code(&d.restitutions, d);
    let n_constants = hoisted.len();
    let mut prepare = prepare_code(d, start, &own, &scope, &hoisted, reduction.as_mut())?;
    let reduction_info = match (&d.reduction, &reduction) {
        (Ok(r), Some(code)) => Some(reduction_info(d, r, code, &scope)?),
        _ => None,
    };
    // Every method's arguments and lines, now that the code is complete.
    prepare
        .stmts
        .insert(0, format!("k[..{np}].copy_from_slice(p);"));
    let locals = Locals::of(d)?;
    let from_p = [
        Preamble::Let("k", "p"),
        Preamble::Names(&locals.params, "p"),
    ];
    prepare.finish(&[("p", "&[f64]"), ("k", "&mut [f64]")], &from_p[1..]);
    requirements.finish(&[("p", "&[f64]"), OUT], &from_p);
    restitutions.finish(&[("p", "&[f64]"), OUT], &from_p);
    general.finish(n_constants, d.reduced, &locals);
    if let Some(code) = reduction.as_mut() {
        let reduced = (d.reduced)
            .ok_or_else(|| StepError::Missing("the fast path's reduced coordinate".into()))?;
        code.finish(n_constants, np, reduced, &locals);
    }
    if let Some(code) = tangents.as_mut() {
        code.finish(n_constants, d.reduced, &locals);
    }
    let poses = ("poses", "&mut [[f64; 3]]");
    let sizes = ("sizes", "&mut [f64]");
    drawing.finish(
        &[K, Q, poses, sizes],
        &[
            Preamble::Slice(n_constants),
            Preamble::Angle(d.reduced),
            Preamble::Names(&locals.params, "k"),
            Preamble::State(&locals.coords),
        ],
    );
    let mut codes: Vec<&Code> = vec![&requirements, &restitutions, &prepare, &drawing];
    codes.extend(general.codes());
    codes.extend(reduction.iter().flat_map(ReducedCode::codes));
    codes.extend(tangents.iter().flat_map(TangentsCode::codes));
    let unread = unread_constants(d, &own, &codes);
    let mut docs = model_docs(checked, d);
    if let Ok(r) = &d.reduction {
        docs.extend(reduction_docs(d, r));
    }
    if tangents.is_some() {
        docs.extend(tangents_docs(d));
    }
    Ok(RustContext {
        info: static_info(checked, d, phases)?,
        docs,
        n_constants,
        shapes_info,
        drawing,
        reduction_info,
        requirements,
        restitutions,
        prepare,
        general,
        reduction,
        tangents,
        unread,
    })
}

/// A method over the parameters alone, `Model::requirements` (the margins) or
/// `Model::restitutions` (no hoisting: they run before `prepare`, or without it).
fn parameters_code(exprs: &[Expr], d: &Derivation) -> Code {
    let mut code = Code::default();
    let mut scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        scope.constants.insert(p.name.clone(), i);
        scope.named.insert(i, parameter_local(&p.name));
    }
    let out = code.push_body(lower(exprs, &scope, None, "q"));
    code.outputs = out_lines(&out);
    code
}
