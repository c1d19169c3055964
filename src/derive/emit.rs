//! Turns a [`Derivation`] into template contexts (flat data, computed here) and renders the
//! tera templates of `templates/` into Rust, LaTeX and JSON text.

use super::algebra::{from_sc, to_sc_expr};
use super::dimensionless::Dimensionless;
use super::expr::Expr;
use super::lower::{Body, Hoisted, Scope, lower};
use super::method::{Preamble, method};
use super::present;
use super::spec::Checked;
use super::steps::{Shown, Steps};
use super::types::{self as mechanics, Derivation, Reduction};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// The command that regenerates `generated/`, named in every file header.
pub const COMMAND: &str = "cargo run --release --features derive -- derive";

/// A straight-line function body: statements, then outputs; `Code::finish` makes it a
/// method's argument list and lines.
#[derive(Debug, Clone, Serialize, Default)]
pub struct Code {
    stmts: Vec<String>,
    outputs: Vec<String>,
    /// The method's arguments after `&self`, an unread one spelled with a leading `_`.
    args: String,
    /// The method's body: the preamble it reads, the statements and the outputs.
    lines: Vec<String>,
}

/// Arguments of the generated methods (name, Rust type).
const K: (&str, &str) = ("k", "&[f64]");
const Q: (&str, &str) = ("q", "&[f64]");
const QD: (&str, &str) = ("qd", "&[f64]");
const OUT: (&str, &str) = ("out", "&mut [f64]");
const DELTA: (&str, &str) = ("delta", "f64");

impl Code {
    /// Fills `args` and `lines` for a method with arguments `args`, whose body may start with
    /// `preamble` (see [`method::method`]).
    fn finish(&mut self, args: &[(&str, &str)], preamble: &[Preamble]) {
        let body = self.stmts.iter().chain(&self.outputs).cloned().collect();
        (self.args, self.lines) = method(args, preamble, body);
    }

    fn push_body(&mut self, body: Body) -> Vec<String> {
        self.stmts.extend(
            body.lets
                .into_iter()
                .map(|(name, value)| format!("let {name} = {value};")),
        );
        body.outputs
    }
    /// `let name = value;`, or `k[i] = value;` for a constant slot.
    fn bind(&mut self, name: &str, value: String) {
        if name.starts_with("k[") {
            self.stmts.push(format!("{name} = {value};"));
        } else {
            self.stmts.push(format!("let {name} = {value};"));
        }
    }
}

#[derive(Debug, Clone, Serialize)]
struct Named {
    name: String,
    meaning: String,
}

/// A monitor's name, meaning and unit, as Rust literals.
#[derive(Debug, Clone, Serialize)]
struct Monitor {
    name: String,
    meaning: String,
    unit: String,
}

#[derive(Debug, Clone, Serialize)]
struct Param {
    name: String,
    meaning: String,
    unit: String,
    positive: bool,
}

/// A fast phase of a system, as every model of the system lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhaseEntry {
    /// The contacts it holds closed.
    pub closed: Vec<usize>,
    /// Its model's name.
    pub model: String,
    /// Whether it starts from the spec's release state.
    pub release: bool,
    /// Its separation polynomial's degree (0 without one).
    pub separation_degree: usize,
}

/// The static description of a model (`ModelInfo`'s fields), as literals.
#[derive(Debug, Clone, Serialize)]
struct StaticInfo {
    command: String,
    name: String,
    type_name: String,
    description: String,
    description_literal: String,
    spec: String,
    params: Vec<Param>,
    requirements_info: Vec<Named>,
    n_params: usize,
    coordinates: Vec<String>,
    n_coordinates: usize,
    reduced: usize,
    cyclic: Vec<usize>,
    end_angle: String,
    /// The system: the spec's name (its general model) and coordinates.
    system: String,
    system_coordinates: Vec<String>,
    /// `ContactInfo { .. }` literals, one per contact of the spec.
    contacts_info: Vec<String>,
    /// `PhaseInfo { .. }` literals: the system's fast phases.
    phases_info: Vec<String>,
    /// Whether the parameters after the spec's are the phase's start state.
    start_params: bool,
    /// `FrictionInfo { .. }` literals.
    frictions_info: Vec<String>,
    points_info: Vec<Named>,
    falling_point: usize,
    gravity: usize,
    monitors_info: Vec<Monitor>,
    /// The bodies' names, as Rust string literals.
    bodies: Vec<String>,
    /// Why the phase has no fast path (empty when it has one).
    route_note: String,
}

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
    /// The reduction's named constants that nothing reads (see [`rust_context`]).
    #[serde(skip)]
    unread: BTreeSet<String>,
}

/// The fast path's functions.
#[derive(Debug, Clone, Serialize)]
pub struct ReducedCode {
    k_theta_initial: usize,
    k_sin_initial: usize,
    k_cos_initial: usize,
    reduced_code: Code,
    theta_dot_sq_code: Code,
    forces: Code,
    /// `Reduction::force_polynomial`: per contact, its polynomial's coefficients.
    force_polynomial: Code,
    /// The lines of each contact's polynomial (for the constants the per-point solver reads).
    #[serde(skip)]
    polynomial_lines: Vec<Vec<String>>,
    fall: Code,
    full_state: Code,
    /// The constants the per-point solver reads, and the code computing only them.
    prepare_lean: Code,
    lean_constants: Vec<usize>,
}

/// Rust spelling of a model name as a type (`rod_cube` -> `RodCube`).
pub fn type_name(name: &str) -> String {
    name.split('_')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let mut c = s.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect()
}

/// `out[i] = <output i>;` lines.
fn out_lines(outputs: &[String]) -> Vec<String> {
    outputs
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect()
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
) -> Result<RustContext, String> {
    let first = context_without(checked, d, phases, &BTreeSet::new())?;
    if first.unread.is_empty() {
        return Ok(first);
    }
    let second = context_without(checked, d, phases, &first.unread)?;
    match second.unread.is_empty() {
        true => Ok(second),
        false => Err(format!(
            "constants still unread after dropping the unread ones: {:?}",
            second.unread
        )),
    }
}

/// [`rust_context`] with the reduction constants `skip` left out of `k`.
fn context_without(
    checked: &Checked,
    d: &Derivation,
    phases: &[PhaseEntry],
    skip: &BTreeSet<String>,
) -> Result<RustContext, String> {
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
    prepare.finish(&[("p", "&[f64]"), ("k", "&mut [f64]")], &[]);
    requirements.finish(&[("p", "&[f64]"), OUT], &[Preamble::Let("k", "p")]);
    restitutions.finish(&[("p", "&[f64]"), OUT], &[Preamble::Let("k", "p")]);
    general.finish(n_constants, d.reduced);
    if let Some(code) = reduction.as_mut() {
        code.finish(n_constants, np, d.reduced);
    }
    let poses = ("poses", "&mut [[f64; 3]]");
    let sizes = ("sizes", "&mut [f64]");
    drawing.finish(
        &[K, Q, poses, sizes],
        &[Preamble::Slice(n_constants), Preamble::Angle(d.reduced)],
    );
    let mut codes: Vec<&Code> = vec![&requirements, &restitutions, &prepare, &drawing];
    codes.extend(general.codes());
    codes.extend(reduction.iter().flat_map(ReducedCode::codes));
    let unread = unread_constants(d, &own, &codes);
    Ok(RustContext {
        info: static_info(checked, d, phases)?,
        n_constants,
        shapes_info,
        drawing,
        reduction_info,
        requirements,
        restitutions,
        prepare,
        general,
        reduction,
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
    }
    let out = code.push_body(lower(exprs, &scope, None, "q"));
    code.outputs = out_lines(&out);
    code
}

/// `Model::prepare` after the parameters: with a fast path, the per-point solver's constants
/// first (`prepare_lean`, filled into `code`), then the others, each once; hoisted constants
/// go last. A named constant that is another one lives in its slot: `prepare` starts by
/// saying so.
fn prepare_code(
    d: &Derivation,
    start: Code,
    own: &[(usize, usize)],
    scope: &Scope,
    hoisted: &Hoisted,
    code: Option<&mut ReducedCode>,
) -> Result<Code, String> {
    let np = d.params.len();
    let mut prepare = start;
    let mut lean_indices = Vec::new();
    if let (Ok(r), Some(code)) = (&d.reduction, code) {
        let (lean, indices) = lean_prepare(np, r, own, scope, hoisted, code)?;
        code.prepare_lean = lean;
        code.lean_constants = indices.clone();
        prepare = Code::default();
        prepare
            .stmts
            .push("Reduction::prepare_lean(self, p, k);".into());
        for &(j, slot) in own {
            if !indices.contains(&slot) {
                let c = &r.constants[j];
                let prefix = format!("c{j}_");
                bind_constant(
                    &mut prepare,
                    slot,
                    Some(&c.symbol),
                    &c.value,
                    scope,
                    &prefix,
                );
            }
        }
        lean_indices = indices;
    }
    for (i, e) in &hoisted.entries {
        if !lean_indices.contains(i) {
            bind_constant(&mut prepare, *i, None, e, scope, &format!("h{i}_"));
        }
    }
    if let Ok(r) = &d.reduction {
        let notes = (r.constants.iter().enumerate())
            .filter(|(j, _)| !own.iter().any(|&(o, _)| o == *j))
            .filter_map(|(_, c)| {
                let i = scope.constants.get(&c.symbol)?;
                Some(format!(
                    "// k[{i}] also holds {} = {}",
                    c.symbol,
                    c.value.to_infix()
                ))
            })
            .collect::<Vec<_>>();
        prepare.stmts.splice(0..0, notes);
    }
    Ok(prepare)
}

/// The `ReductionInfo { .. }` literal of a fast path.
fn reduction_info(
    d: &Derivation,
    r: &Reduction,
    code: &ReducedCode,
    scope: &Scope,
) -> Result<String, String> {
    let wi = scope
        .constants
        .get("rc_wi")
        .copied()
        .ok_or("the reduction has no constant `rc_wi`")?;
    let degrees: Vec<usize> = (r.force_polynomials.iter())
        .map(|p| p.as_ref().map_or(0, |s| s.coefficients.len() - 1))
        .collect();
    debug_assert_eq!(degrees.len(), d.contacts.len());
    Ok(format!(
        "ReductionInfo {{ k_theta_initial: {}, k_theta_dot_initial: {wi}, k_sin_initial: {}, k_cos_initial: {}, force_degrees: &{degrees:?}, fall_degree: {:?}, lean_constants: &{:?} }}",
        code.k_theta_initial,
        code.k_sin_initial,
        code.k_cos_initial,
        r.fall.as_ref().map(|f| f.len() - 1),
        code.lean_constants
    ))
}

/// `ModelInfo`'s fields as literals.
fn static_info(
    checked: &Checked,
    d: &Derivation,
    phases: &[PhaseEntry],
) -> Result<StaticInfo, String> {
    let spec = &checked.spec;
    let np = d.params.len();
    let point_index = |name: &str| {
        (spec.points.iter().position(|p| p.name == name))
            .ok_or_else(|| format!("`{name}` is not one of the points"))
    };
    let lit = |s: &str| format!("{s:?}");
    let contacts_info = (d.contacts.iter())
        .map(|c| {
            let restitution = (spec.contacts.iter())
                .find(|s| s.name == c.name)
                .and_then(|s| s.restitution.as_ref())
                .map_or_else(|| "0".to_string(), |e| e.text());
            format!(
                "ContactInfo {{ name: {:?}, meaning: {:?}, gap_unit: {:?}, unit: {:?}, bilateral: {}, edge: {}, eliminates: {:?}, closed: {}, restitution: {:?} }}",
                c.name,
                c.meaning,
                c.gap_unit,
                c.force_unit,
                c.bilateral,
                c.edge.is_some(),
                c.eliminates.as_deref(),
                c.closed,
                restitution
            )
        })
        .collect();
    let phases_info = (phases.iter())
        .map(|p| {
            format!(
                "PhaseInfo {{ closed: &{:?}, model: {:?}, release: {}, separation_degree: {} }}",
                p.closed, p.model, p.release, p.separation_degree
            )
        })
        .collect();
    let frictions_info = (d.frictions.iter())
        .map(|f| {
            format!(
                "FrictionInfo {{ name: {:?}, meaning: {:?}, coefficient: {}, contact: {} }}",
                f.named.name, f.named.meaning, f.coefficient, f.contact
            )
        })
        .collect();
    Ok(StaticInfo {
        command: COMMAND.into(),
        name: d.name.clone(),
        type_name: type_name(&d.name),
        // Comments in the generated code: one line, so no spec text can end them.
        description: one_line(&d.description),
        description_literal: lit(&d.description),
        spec: one_line(&spec_path(checked)),
        params: (d.params.iter())
            .map(|p| Param {
                name: p.name.clone(),
                meaning: lit(&p.meaning),
                unit: lit(&p.unit),
                positive: p.positive,
            })
            .collect(),
        requirements_info: (spec.requirements.iter())
            .map(|r| Named {
                name: r.name.clone(),
                meaning: lit(&r.meaning),
            })
            .collect(),
        n_params: np,
        coordinates: d.coords.clone(),
        n_coordinates: d.coords.len(),
        reduced: d.reduced,
        cyclic: d.cyclic.clone(),
        end_angle: angle_literal(spec.end_angle),
        system: d.system.clone(),
        system_coordinates: d.full_coords.clone(),
        contacts_info,
        phases_info,
        start_params: d.plan.start_params,
        frictions_info,
        points_info: (spec.points.iter())
            .map(|p| Named {
                name: p.name.clone(),
                meaning: lit(&p.meaning),
            })
            .collect(),
        falling_point: point_index(&spec.falling_point)?,
        gravity: (d.params.iter().position(|p| p.name == spec.gravity))
            .ok_or_else(|| format!("`{}` is not a parameter", spec.gravity))?,
        monitors_info: (d.monitors.iter())
            .map(|m| Monitor {
                name: lit(&m.name),
                meaning: lit(&m.meaning),
                unit: lit(&m.unit),
            })
            .collect(),
        bodies: d.bodies.iter().map(|b| lit(b)).collect(),
        route_note: match &d.reduction {
            Ok(_) => lit(""),
            Err(why) => lit(&one_line(why)),
        },
    })
}

/// The constant layout of `k`: the parameters, then the reduction's constants that hold a
/// slot of their own (computed in `prepare`, which this starts); hoisted subexpressions follow
/// them. Returns the scope, the start of `prepare` and, for each reduction constant with a slot
/// of its own (all but an [`alias`]), its position in the reduction and its slot.
fn constant_layout(d: &Derivation, skip: &BTreeSet<String>) -> (Scope, Code, Vec<(usize, usize)>) {
    let np = d.params.len();
    let mut scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        scope.constants.insert(p.name.clone(), i);
    }
    let mut prepare = Code::default();
    let constants = match &d.reduction {
        Ok(r) => r.constants.as_slice(),
        Err(_) => &[],
    };
    let mut own = Vec::new();
    for (j, c) in constants.iter().enumerate() {
        if skip.contains(&c.symbol) {
            continue;
        }
        if let Some(i) = alias(&c.value, &scope) {
            // Another constant under a new name (a start value that is a parameter, say):
            // read where that one is.
            scope.constants.insert(c.symbol.clone(), i);
            continue;
        }
        let slot = np + own.len();
        bind_constant(
            &mut prepare,
            slot,
            Some(&c.symbol),
            &c.value,
            &scope,
            &format!("c{j}_"),
        );
        scope.constants.insert(c.symbol.clone(), slot);
        own.push((j, slot));
    }
    (scope, prepare, own)
}

/// The slot of the constant that `value` is, when it is just one (a parameter or an earlier
/// constant).
fn alias(value: &Expr, scope: &Scope) -> Option<usize> {
    match value {
        Expr::Sym(s) => scope.constants.get(s).copied(),
        _ => None,
    }
}

/// `k[idx] = <value>;`, with the value's shared subexpressions as `let`s named by `prefix`,
/// after a comment saying what it holds in the spec's own symbols (`// k[20] = m1/2 + m2/2`).
/// A named constant (a start value, say) is introduced by its name: `// k[7] = rc_si = a/ell`.
fn bind_constant(
    code: &mut Code,
    idx: usize,
    name: Option<&str>,
    value: &Expr,
    scope: &Scope,
    prefix: &str,
) {
    let named = name.map_or(String::new(), |n| format!("{n} = "));
    code.stmts
        .push(format!("// k[{idx}] = {named}{}", value.tidy().to_infix()));
    let out = code.push_body(lower(std::slice::from_ref(value), scope, None, prefix));
    code.bind(&format!("k[{idx}]"), out[0].clone());
}

/// Indices `i` of every `k[i]` in a line of generated code.
fn k_indices(text: &str) -> Vec<usize> {
    text.match_indices("k[")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            let end = rest.find(']')?;
            rest[..end].parse().ok()
        })
        .collect()
}

/// What the per-point solver reads: the start (`theta_i`, its rate, sine and cosine) and the
/// separation and fall polynomials' coefficients, with every constant they are computed from.
/// Returns the code that computes just those (after the parameters) and their indices.
fn lean_prepare(
    np: usize,
    r: &Reduction,
    own: &[(usize, usize)],
    scope: &Scope,
    hoisted: &Hoisted,
    code: &ReducedCode,
) -> Result<(Code, Vec<usize>), String> {
    let index = |name: &str| scope.constants.get(name).copied();
    let definition = |i: usize| -> Option<&Expr> {
        own.iter()
            .find(|&&(_, slot)| slot == i)
            .map(|&(j, _)| &r.constants[j].value)
            .or_else(|| {
                hoisted
                    .entries
                    .iter()
                    .find(|(j, _)| *j == i)
                    .map(|(_, e)| e)
            })
    };
    let wi = index("rc_wi").ok_or("the reduction has no constant `rc_wi`")?;
    // The start enters the lean path through its sine, cosine and rate only: the angle itself
    // (an `asin`) is left to the full `prepare`.
    let mut stack = vec![code.k_sin_initial, code.k_cos_initial, wi];
    let fall = code.fall.stmts.iter().chain(&code.fall.outputs);
    for line in code.polynomial_lines.iter().flatten().chain(fall) {
        stack.extend(k_indices(line));
    }
    let mut needed = BTreeSet::new();
    while let Some(i) = stack.pop() {
        if needed.insert(i)
            && let Some(e) = definition(i)
        {
            stack.extend(e.symbols().iter().filter_map(|s| index(s)));
        }
    }
    let mut lean = Code::default();
    for &(j, slot) in own {
        let c = &r.constants[j];
        if needed.contains(&slot) {
            bind_constant(
                &mut lean,
                slot,
                Some(&c.symbol),
                &c.value,
                scope,
                &format!("c{j}_"),
            );
        }
    }
    for (i, e) in &hoisted.entries {
        if needed.contains(i) {
            bind_constant(&mut lean, *i, None, e, scope, &format!("h{i}_"));
        }
    }
    Ok((lean, needed.into_iter().filter(|&i| i >= np).collect()))
}

/// The spec file, relative to the project root.
fn spec_path(checked: &Checked) -> String {
    format!(
        "derivations/{}",
        checked
            .file
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default()
    )
}

/// The functions of the full state, every model has them.
#[derive(Debug, Clone, Serialize)]
struct FullStateCode {
    initial_state: Code,
    points: Code,
    energy: Code,
    momenta: Code,
    equations: Code,
    forces_full: Code,
    gaps: Code,
    constraints: Code,
    edges: Code,
    friction: Code,
    monitors_full: Code,
    to_full: Code,
}

/// The reduction's constants with a slot of their own (`own`) that no line of `codes` reads
/// and that the runtime does not read through `ReductionInfo` (the start's angle, rate, sine
/// and cosine).
fn unread_constants(d: &Derivation, own: &[(usize, usize)], codes: &[&Code]) -> BTreeSet<String> {
    let Ok(r) = &d.reduction else {
        return BTreeSet::new();
    };
    let runtime = ["rc_thi", "rc_wi", "rc_si", "rc_ci"];
    let lines =
        || (codes.iter().flat_map(|c| &c.lines)).filter(|l| !l.trim_start().starts_with("//"));
    own.iter()
        .map(|&(j, slot)| (&r.constants[j].symbol, slot))
        .filter(|(symbol, _)| !runtime.contains(&symbol.as_str()))
        .filter(|&(_, slot)| {
            let (read, write) = (format!("k[{slot}]"), format!("k[{slot}] = "));
            lines().all(|l| l.matches(&read).count() == l.matches(&write).count())
        })
        .map(|(symbol, _)| symbol.clone())
        .collect()
}

impl FullStateCode {
    /// Every method's code.
    fn codes(&self) -> [&Code; 12] {
        [
            &self.initial_state,
            &self.points,
            &self.energy,
            &self.momenta,
            &self.equations,
            &self.forces_full,
            &self.gaps,
            &self.constraints,
            &self.edges,
            &self.friction,
            &self.monitors_full,
            &self.to_full,
        ]
    }

    /// Each method's arguments and lines; `n` is the length of `k`, `reduced` the index of the
    /// reduced coordinate.
    fn finish(&mut self, n: usize, reduced: usize) {
        let (slice, angle) = (Preamble::Slice(n), Preamble::Angle(reduced));
        let state = [slice, angle];
        let qm = ("q", "&mut [f64]");
        let qdm = ("qd", "&mut [f64]");
        self.initial_state.finish(&[K, qm, qdm], &[slice]);
        let pos = ("pos", "&mut [[f64; 2]]");
        let vel = ("vel", "&mut [[f64; 2]]");
        self.points.finish(&[K, Q, QD, pos, vel], &state);
        self.energy.finish(&[K, Q, QD], &state);
        self.momenta.finish(&[K, Q, QD, OUT], &state);
        let mass = ("mass", "&mut [f64]");
        let rhs = ("rhs", "&mut [f64]");
        self.equations.finish(&[K, Q, QD, mass, rhs], &state);
        let qdd = ("qdd", "&[f64]");
        self.forces_full.finish(&[K, Q, QD, qdd, OUT], &state);
        self.gaps.finish(&[K, Q, OUT], &state);
        let jac = ("jac", "&mut [f64]");
        let bias = ("bias", "&mut [f64]");
        self.constraints.finish(&[K, Q, QD, jac, bias], &state);
        self.edges.finish(&[K, Q, OUT], &state);
        self.friction.finish(&[K, Q, QD, jac, bias], &state);
        let forces = ("forces", "&[f64]");
        self.monitors_full.finish(&[K, Q, QD, forces, OUT], &state);
        let qf = ("q_full", "&mut [f64]");
        let qdf = ("qd_full", "&mut [f64]");
        self.to_full.finish(&[K, Q, QD, qf, qdf], &state);
    }
}

impl ReducedCode {
    /// Every method's code.
    fn codes(&self) -> [&Code; 7] {
        [
            &self.reduced_code,
            &self.theta_dot_sq_code,
            &self.forces,
            &self.force_polynomial,
            &self.fall,
            &self.full_state,
            &self.prepare_lean,
        ]
    }

    /// Each method's arguments and lines; `n` is the length of `k`, `np` the number of
    /// parameters, `reduced` the index of the reduced coordinate.
    fn finish(&mut self, n: usize, np: usize, reduced: usize) {
        let slice = Preamble::Slice(n);
        let start =
            Preamble::Offsets([self.k_theta_initial, self.k_sin_initial, self.k_cos_initial]);
        let delta = Preamble::Let("rc_delta", "delta");
        if let [w2, acc] = &self.reduced_code.outputs[..] {
            self.reduced_code.outputs = vec![format!(
                "Reduced {{ sin: rc_s, cos: rc_c, theta_dot_sq: {w2}, theta_ddot: {acc} }}"
            )];
        }
        self.reduced_code
            .finish(&[K, DELTA], &[slice, start, delta]);
        let sc = ["rc_s", "rc_c", "rc_ds", "rc_dc"].map(|s| (s, "f64"));
        self.theta_dot_sq_code
            .finish(&[K, sc[0], sc[1], sc[2], sc[3]], &[slice]);
        self.forces.outputs = out_lines(&self.forces.outputs);
        self.forces.finish(&[K, DELTA, OUT], &[slice, start, delta]);
        self.force_polynomial
            .finish(&[K, ("contact", "usize"), OUT], &[slice]);
        self.fall.outputs = out_lines(&self.fall.outputs);
        self.fall.finish(&[K, OUT], &[slice]);
        self.prepare_lean
            .stmts
            .insert(0, format!("k[..{np}].copy_from_slice(p);"));
        self.prepare_lean
            .finish(&[("p", "&[f64]"), ("k", "&mut [f64]")], &[]);
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
            .finish(&args, &[slice, start, lets[0], lets[1], lets[2]]);
    }
}

/// The scope of the full-state functions: the constants, `rc_s`, `rc_c` (the template's
/// preamble) and the state `q`, `qd`, `qdd`.
fn state_scope(d: &Derivation, scope: &Scope) -> Scope {
    let mut full_scope = scope.clone();
    full_scope.locals.insert("rc_s".into(), "rc_s".into());
    full_scope.locals.insert("rc_c".into(), "rc_c".into());
    for (i, c) in d.coords.iter().enumerate() {
        full_scope.locals.insert(c.clone(), format!("q[{i}]"));
        full_scope
            .locals
            .insert(format!("dot_{c}"), format!("qd[{i}]"));
        full_scope
            .locals
            .insert(format!("ddot_{c}"), format!("qdd[{i}]"));
    }
    full_scope
}

/// `Model::drawing` (every body's pose from `q`, then every shape's numbers, which are
/// parameter-only and so hoisted into `k`) and the `ShapeInfo` literals that say where each
/// shape's numbers start.
fn drawing_code(d: &Derivation, scope: &Scope, hoisted: &mut Hoisted) -> (Code, Vec<String>) {
    let theta = d.theta();
    let mut exprs: Vec<Expr> = d
        .body_pose
        .iter()
        .flat_map(|pose| pose.iter().map(|e| to_sc_expr(e, theta)))
        .collect();
    let mut infos = Vec::new();
    let mut first = 0;
    for shape in &d.shapes {
        infos.push(format!(
            "ShapeInfo {{ kind: ShapeKind::{:?}, body: {:?}, first: {first} }}",
            shape.kind, shape.body
        ));
        first += shape.numbers.len();
        exprs.extend(shape.numbers.iter().cloned());
    }
    let mut code = Code::default();
    let out = code.push_body(lower(&exprs, &state_scope(d, scope), Some(hoisted), "d"));
    let n_bodies = d.body_pose.len();
    code.outputs = (0..n_bodies)
        .map(|i| {
            format!(
                "poses[{i}] = [{}, {}, {}];",
                out[3 * i],
                out[3 * i + 1],
                out[3 * i + 2]
            )
        })
        .chain(
            out[3 * n_bodies..]
                .iter()
                .enumerate()
                .map(|(j, o)| format!("sizes[{j}] = {o};")),
        )
        .collect();
    (code, infos)
}

fn full_state_code(
    d: &Derivation,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<FullStateCode, String> {
    let theta = d.theta().to_string();
    let full_scope = state_scope(d, scope);
    let sc = |e: &Expr| to_sc_expr(e, &theta);
    let single = |prefix: &str, exprs: &[Expr], scope: &Scope, hoisted: &mut Hoisted| {
        let mut code = Code::default();
        let out = code.push_body(lower(exprs, scope, Some(hoisted), prefix));
        (code, out)
    };

    // The initial state is over parameters only: each value is hoisted into `k`.
    let inits: Vec<Expr> = d
        .initial
        .iter()
        .flat_map(|[p, v]| [p.clone(), v.clone()])
        .collect();
    let (mut initial_state, out) = single("i", &inits, scope, hoisted);
    initial_state.outputs = (0..d.coords.len())
        .flat_map(|i| {
            [
                format!("q[{i}] = {};", out[2 * i]),
                format!("qd[{i}] = {};", out[2 * i + 1]),
            ]
        })
        .collect();

    let mut exprs = Vec::new();
    for p in &d.point_pos {
        exprs.push(sc(&p[0]));
        exprs.push(sc(&p[1]));
    }
    for v in &d.point_vel {
        exprs.push(sc(&v[0]));
        exprs.push(sc(&v[1]));
    }
    let (mut points, out) = single("p", &exprs, &full_scope, hoisted);
    let n = d.point_pos.len();
    points.outputs = (0..n)
        .flat_map(|i| {
            [
                format!("pos[{i}] = [{}, {}];", out[2 * i], out[2 * i + 1]),
                format!(
                    "vel[{i}] = [{}, {}];",
                    out[2 * n + 2 * i],
                    out[2 * n + 2 * i + 1]
                ),
            ]
        })
        .collect();

    let total = Expr::Add(vec![sc(&d.kinetic), sc(&d.potential)]);
    let (mut energy, out) = single("e", &[total], &full_scope, hoisted);
    energy.outputs = out;

    let mo: Vec<Expr> = d.momenta.iter().map(sc).collect();
    let (mut momenta, out) = single("m", &mo, &full_scope, hoisted);
    momenta.outputs = out_lines(&out);

    let nc = d.coords.len();
    let mut exprs: Vec<Expr> = d.mass.iter().flat_map(|r| r.iter().map(sc)).collect();
    exprs.extend(d.rhs.iter().map(sc));
    let (mut equations, out) = single("q", &exprs, &full_scope, hoisted);
    equations.outputs = (0..nc * nc)
        .map(|i| format!("mass[{i}] = {};", out[i]))
        .chain((0..nc).map(|i| format!("rhs[{i}] = {};", out[nc * nc + i])))
        .collect();

    let contacts = contact_code(d, &full_scope, hoisted)?;
    Ok(FullStateCode {
        initial_state,
        points,
        energy,
        momenta,
        equations,
        forces_full: contacts.forces_full,
        gaps: contacts.gaps,
        constraints: contacts.constraints,
        edges: contacts.edges,
        friction: contacts.friction,
        monitors_full: contacts.monitors_full,
        to_full: contacts.to_full,
    })
}

/// The functions of the contacts, frictions and monitors over the full state.
struct ContactCode {
    forces_full: Code,
    gaps: Code,
    constraints: Code,
    edges: Code,
    friction: Code,
    monitors_full: Code,
    to_full: Code,
}

/// One expression per contact, each lowered where `pick` gives one and `default` elsewhere,
/// as `out[i] = ...;` lines.
fn per_contact(
    d: &Derivation,
    pick: &dyn Fn(&mechanics::ContactRow) -> Option<Expr>,
    default: &str,
    prefix: &str,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Code {
    let theta = d.theta().to_string();
    let picked: Vec<Option<Expr>> = d.contacts.iter().map(pick).collect();
    let exprs: Vec<Expr> = (picked.iter().flatten())
        .map(|e| to_sc_expr(e, &theta))
        .collect();
    let mut code = Code::default();
    let out = code.push_body(lower(&exprs, scope, Some(hoisted), prefix));
    let mut values = out.into_iter();
    code.outputs = (picked.iter().enumerate())
        .map(|(i, p)| {
            let v = match p {
                Some(_) => values.next().unwrap_or_else(|| default.to_string()),
                None => default.to_string(),
            };
            format!("out[{i}] = {v};")
        })
        .collect();
    code
}

fn contact_code(
    d: &Derivation,
    full_scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<ContactCode, String> {
    let theta = d.theta().to_string();
    let sc = |e: &Expr| to_sc_expr(e, &theta);
    let nc = d.coords.len();
    let single = |prefix: &str, exprs: &[Expr], hoisted: &mut Hoisted| {
        let mut code = Code::default();
        let out = code.push_body(lower(exprs, full_scope, Some(hoisted), prefix));
        (code, out)
    };
    let forces: Vec<Expr> = d.contacts.iter().filter_map(|c| c.force.clone()).collect();
    let stray = super::lower::unbound(&forces, full_scope);
    if !stray.is_empty() {
        return Err(format!(
            "the forces depend on {} besides the state and the parameters",
            stray.into_iter().collect::<Vec<_>>().join(", ")
        ));
    }
    let forces_full = per_contact(d, &|c| c.force.clone(), "0.0", "f", full_scope, hoisted);
    let open = |c: &mechanics::ContactRow| (!c.closed).then(|| c.gap.clone());
    let gaps = per_contact(d, &open, "0.0", "g", full_scope, hoisted);
    let edges = per_contact(
        d,
        &|c| c.edge.clone(),
        "f64::INFINITY",
        "e",
        full_scope,
        hoisted,
    );

    // The constraint rows (every contact's Jacobian row, then its bias) and the frictions'
    // slip rows, in the same layout.
    let mut rows = |prefix: &str, jacobians: Vec<&[Expr]>, biases: Vec<&Expr>| {
        let mut exprs: Vec<Expr> = jacobians.iter().flat_map(|j| j.iter().map(sc)).collect();
        exprs.extend(biases.iter().map(|b| sc(b)));
        let (mut code, out) = single(prefix, &exprs, hoisted);
        let n_jac = nc * biases.len();
        code.outputs = (0..n_jac)
            .map(|i| format!("jac[{i}] = {};", out[i]))
            .chain((0..biases.len()).map(|j| format!("bias[{j}] = {};", out[n_jac + j])))
            .collect();
        code
    };
    let constraints = rows(
        "j",
        d.contacts.iter().map(|c| &c.jacobian[..]).collect(),
        d.contacts.iter().map(|c| &c.bias).collect(),
    );
    let friction = rows(
        "s",
        d.frictions.iter().map(|f| &f.jacobian[..]).collect(),
        d.frictions.iter().map(|f| &f.bias).collect(),
    );

    let mut mon_scope = full_scope.clone();
    for i in 0..d.contacts.len() {
        mon_scope
            .locals
            .insert(format!("rc_f{i}"), format!("forces[{i}]"));
    }
    let mo: Vec<Expr> = d.monitors_full.iter().map(sc).collect();
    let mut monitors_full = Code::default();
    let out = monitors_full.push_body(lower(&mo, &mon_scope, Some(hoisted), "m"));
    monitors_full.outputs = out_lines(&out);

    let exprs: Vec<Expr> = (d.to_full.iter())
        .flat_map(|[x, v]| [sc(x), sc(v)])
        .collect();
    let (mut to_full, out) = single("t", &exprs, hoisted);
    to_full.outputs = (0..d.to_full.len())
        .flat_map(|i| {
            [
                format!("q_full[{i}] = {};", out[2 * i]),
                format!("qd_full[{i}] = {};", out[2 * i + 1]),
            ]
        })
        .collect();
    Ok(ContactCode {
        forces_full,
        gaps,
        constraints,
        edges,
        friction,
        monitors_full,
        to_full,
    })
}

/// The fast path's functions over the reduced motion.
fn reduced_code(
    d: &Derivation,
    r: &Reduction,
    scope: &Scope,
    hoisted: &mut Hoisted,
) -> Result<ReducedCode, String> {
    let theta = d.theta().to_string();
    let idx = |s: &str| {
        scope
            .constants
            .get(s)
            .copied()
            .ok_or_else(|| format!("the reduction has no constant `{s}`"))
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
    let stray = super::lower::unbound(std::slice::from_ref(&r.theta_dot_sq), &sc_scope);
    if !stray.is_empty() {
        return Err(format!(
            "theta_dot^2 depends on {} besides sin, cos and constants",
            stray.into_iter().collect::<Vec<_>>().join(", ")
        ));
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
    Ok(ReducedCode {
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

/// `text` on one line (runs of whitespace, newlines included, become one space), for a comment
/// in generated code.
pub fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `text` as LaTeX text on one line: every character TeX would read as a command or as
/// markup is escaped, so spec text is printed, never run.
pub fn tex_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in one_line(text).chars() {
        match c {
            '\\' => out.push_str("\\textbackslash{}"),
            '{' | '}' | '$' | '&' | '#' | '_' | '%' => {
                out.push('\\');
                out.push(c);
            }
            '^' => out.push_str("\\^{}"),
            '~' => out.push_str("\\~{}"),
            '<' => out.push_str("\\textless{}"),
            '>' => out.push_str("\\textgreater{}"),
            c => out.push(c),
        }
    }
    out
}

/// LaTeX spelling of a symbol: `m1` -> `m_{1}`, `ell` -> `\ell`, `dot_theta` -> `\dot{\theta}`.
pub fn latex_name(s: &str, theta: &str) -> String {
    match s {
        "rc_s" => return format!("\\sin {}", latex_name(theta, theta)),
        "rc_c" => return format!("\\cos {}", latex_name(theta, theta)),
        "rc_thi" => return format!("{}_{{\\mathrm{{i}}}}", latex_name(theta, theta)),
        "rc_wi" => return format!("\\dot{{{}}}_{{\\mathrm{{i}}}}", latex_name(theta, theta)),
        "rc_si" => return format!("\\sin {}_{{\\mathrm{{i}}}}", latex_name(theta, theta)),
        "rc_ci" => return format!("\\cos {}_{{\\mathrm{{i}}}}", latex_name(theta, theta)),
        _ => {}
    }
    if let Some(rest) = s.strip_prefix("ddot_") {
        return format!("\\ddot{{{}}}", latex_name(rest, theta));
    }
    if let Some(rest) = s.strip_prefix("dot_") {
        return format!("\\dot{{{}}}", latex_name(rest, theta));
    }
    const GREEK: &[&str] = &[
        "alpha", "beta", "gamma", "delta", "epsilon", "theta", "kappa", "lambda", "mu", "nu", "xi",
        "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega", "ell",
    ];
    let (base, sub) = match s.split_once('_') {
        Some((b, sub)) => (b.to_string(), Some(sub.to_string())),
        None => {
            let digits = s.trim_start_matches(|c: char| !c.is_ascii_digit());
            if !digits.is_empty()
                && digits.len() < s.len()
                && digits.chars().all(|c| c.is_ascii_digit())
            {
                (
                    s[..s.len() - digits.len()].to_string(),
                    Some(digits.to_string()),
                )
            } else {
                (s.to_string(), None)
            }
        }
    };
    let base = if GREEK.contains(&base.as_str()) {
        format!("\\{base}")
    } else if base.len() > 1 {
        format!("\\mathrm{{{base}}}")
    } else {
        base
    };
    match sub {
        Some(sub) => format!("{base}_{{\\mathrm{{{}}}}}", sub.replace('_', ",")),
        None => base,
    }
}

/// One displayed equation of the LaTeX derivation.
#[derive(Debug, Clone, Serialize)]
pub struct Equation {
    title: String,
    /// `equation*` for one line, `multline*` for several.
    env: &'static str,
    /// The lines, joined by `\\`.
    latex: String,
    /// The number printed beside it (`(3)`, `(3) = paper (9)`), if any.
    tag: Option<String>,
    /// Set in a smaller type, because a term too wide for a line cannot be broken.
    small: bool,
}

/// Characters of math that fit on one display line of the LaTeX page (A4, 2 cm margins,
/// 10 pt), as counted by [`Expr::latex_width`].
const TEX_LINE: usize = 90;

/// A displayed equation `lhs expr` or `lhs expr = rhs`, broken into lines that fit the page;
/// `lhs_width` is the printed width of `lhs`. A right-hand side that does not fit after
/// `expr` gets lines of its own.
fn display(
    title: &str,
    lhs: String,
    lhs_width: usize,
    e: &Expr,
    rhs: Option<&Expr>,
    name: &dyn Fn(&str) -> String,
) -> Equation {
    let mut lines = e.to_latex_lines(name, TEX_LINE, lhs_width);
    if let Some(first) = lines.first_mut() {
        first.insert_str(0, &lhs);
    }
    if let Some(rhs) = rhs {
        let w = rhs.latex_width(name) + 3;
        let one_line = lines.len() == 1 && lhs_width + e.latex_width(name) + w <= TEX_LINE;
        let short = lines.len() > 1 && w <= 10;
        let mut rest = rhs.to_latex_lines(name, TEX_LINE, 3);
        if one_line || short {
            let first = rest.remove(0);
            if let Some(last) = lines.last_mut() {
                last.push_str(" = ");
                last.push_str(&first);
            }
        } else if let Some(first) = rest.first_mut() {
            first.insert_str(0, "{} = ");
        }
        lines.extend(rest);
    }
    Equation {
        title: title.into(),
        env: if lines.len() > 1 {
            "multline*"
        } else {
            "equation*"
        },
        latex: lines.join(" \\\\\n"),
        tag: None,
        small: false,
    }
}

/// The widest term of the sums of `e` (outside fractions' denominators), which the line
/// breaker cannot split, as counted by [`Expr::latex_width`].
fn widest_term(e: &Expr, name: &dyn Fn(&str) -> String) -> usize {
    match e {
        Expr::Add(terms) => (terms.iter())
            .map(|t| t.split_sign().1.latex_width(name))
            .max()
            .unwrap_or(0),
        Expr::Mul(v) => v.iter().map(|f| widest_term(f, name)).max().unwrap_or(0),
        _ => 0,
    }
}

/// A parameter row of the LaTeX table.
#[derive(Debug, Clone, Serialize)]
pub struct TexParam {
    symbol: String,
    meaning: String,
    unit: String,
}

/// Context of the LaTeX template.
#[derive(Debug, Clone, Serialize)]
pub struct TexContext {
    command: String,
    name: String,
    description: String,
    spec: String,
    params: Vec<TexParam>,
    equations: Vec<Equation>,
    /// The dimensionless groups (`n = m_2/m_1`) with their meanings.
    groups: Vec<TexParam>,
    /// The scales and the rule of the presentation forms, in words.
    scales: String,
    /// The results without units, numbered.
    results: Vec<Equation>,
}

/// Builds the LaTeX context: the derivation's steps as displayed equations.
pub fn tex_context(checked: &Checked, d: &Derivation) -> Result<TexContext, String> {
    let steps = d
        .steps
        .as_ref()
        .ok_or("the steps were not presented before the LaTeX")?;
    let theta = d.theta().to_string();
    let name = |s: &str| match s
        .strip_prefix("rc_fr")
        .and_then(|j| j.parse::<usize>().ok())
        .and_then(|j| d.frictions.get(j))
    {
        Some(f) => format!("F_{{\\mathrm{{{}}}}}", tex_text(&f.named.name)),
        None => latex_name(s, &theta),
    };
    let sc = |e: &Expr| from_sc(e, &theta);
    let mut eqs = Vec::new();
    for (c, row) in d.contacts.iter().filter(|c| c.closed).filter_map(|c| {
        let e = c.eliminates.as_ref()?;
        let i = d.full_coords.iter().position(|q| q == e)?;
        Some((c, d.to_full.get(i)?))
    }) {
        let e = c.eliminates.as_deref().unwrap_or_default();
        eqs.push(display(
            &format!(
                "Contact \\texttt{{{}}} is closed: its gap is zero, which ties ${}$",
                tex_text(&c.name),
                name(e)
            ),
            format!("{} = ", name(e)),
            3,
            &sc(&row[0]),
            None,
            &name,
        ));
    }
    let energies = [
        ("Kinetic energy", "T = ", 2, &steps.kinetic),
        ("Potential energy", "V = ", 2, &steps.potential),
        ("Lagrangian", "L = T - V = ", 8, &steps.lagrangian),
    ];
    for (title, lhs, width, shown) in energies {
        let (title, e) = step(title, shown, &name);
        eqs.push(display(&title, lhs.into(), width, &sc(&e), None, &name));
    }
    for (c, shown) in d.coords.iter().zip(&steps.euler_lagrange) {
        let (title, e) = step(
            &format!("Euler--Lagrange equation for ${}$", name(c)),
            shown,
            &name,
        );
        eqs.push(display(
            &title,
            format!(
                "\\frac{{d}}{{dt}}\\frac{{\\partial L}}{{\\partial {}}} - \\frac{{\\partial L}}{{\\partial {}}} = ",
                name(&format!("dot_{c}")),
                name(c),
            ),
            14,
            &sc(&e),
            Some(&Expr::int(0)),
            &name,
        ));
    }
    for f in &d.frictions {
        eqs.push(display(
            &format!(
                "Friction \\texttt{{{}}}: {}. Slip velocity $v$, whose friction force $F$ has \
                 the generalized force $F\\,\\partial v/\\partial\\dot q$ (sliding: \
                 $F = -\\mu N \\operatorname{{sign}} v$; sticking: $\\dot v = 0$ while \
                 $|F| \\le \\mu N$)",
                tex_text(&f.named.name),
                tex_text(&f.named.meaning)
            ),
            "v = ".into(),
            2,
            &sc(&f.slip),
            None,
            &name,
        ));
    }
    constraint_equations(d, &name, &mut eqs);
    match &d.reduction {
        Ok(r) => reduced_equations(d, r, steps, &name, &mut eqs)?,
        Err(why) if d.contacts.iter().any(|c| c.closed) => {
            for c in d.contacts.iter().filter(|c| c.closed) {
                if let Some(f) = &c.force {
                    eqs.push(display(
                        &format!(
                            "Force \\texttt{{{}}}: {} (integrated route: {})",
                            tex_text(&c.name),
                            tex_text(&c.meaning),
                            tex_text(why)
                        ),
                        "F = ".into(),
                        2,
                        &sc(f),
                        None,
                        &name,
                    ));
                }
            }
        }
        Err(_) => {}
    }
    for c in &d.contacts {
        if let Some(edge) = &c.edge {
            eqs.push(display(
                &format!(
                    "Edge of contact \\texttt{{{}}}: it can exist while this margin is not negative",
                    tex_text(&c.name)
                ),
                String::new(),
                0,
                &sc(edge),
                None,
                &name,
            ));
        }
    }
    let (dim_groups, dim_scales, dim_results) = match &d.dimensionless {
        Some(dim) => tex_dimensionless(dim, &theta, &name),
        None => (Vec::new(), String::new(), Vec::new()),
    };
    Ok(TexContext {
        command: COMMAND.into(),
        name: tex_text(&d.name),
        description: tex_text(&d.description),
        spec: tex_text(&spec_path(checked)),
        params: d
            .params
            .iter()
            .map(|p| TexParam {
                symbol: name(&p.name),
                meaning: tex_text(&p.meaning),
                unit: tex_text(&p.unit),
            })
            .collect(),
        equations: eqs,
        groups: dim_groups,
        scales: dim_scales,
        results: dim_results,
    })
}

/// A gradient entry's `\frac{\partial g}{\partial q} = ` counts this many characters of width.
const GRADIENT_HEAD: usize = 6;

/// The constraint rows of the contacts a phase does not hold closed: each gap, its gradient
/// in the phase's coordinates and its bias, with what the runtime solves while a set of them is
/// closed.
fn constraint_equations(d: &Derivation, name: &dyn Fn(&str) -> String, eqs: &mut Vec<Equation>) {
    let theta = d.theta().to_string();
    let sc = |e: &Expr| from_sc(e, &theta);
    let open: Vec<(&mechanics::ContactRow, &Expr)> = (d.contacts.iter().zip(&d.restitutions))
        .filter(|(c, _)| !c.closed)
        .collect();
    for (k, (c, e)) in open.iter().enumerate() {
        let kind = if c.bilateral {
            "a joint: its gap stays zero and its force $\\lambda$ may have either sign".to_string()
        } else {
            format!(
                "a contact: its gap stays $\\ge 0$; while it is zero its force $\\lambda \\ge 0$ \
                 pushes; where it closes with an approach velocity $v^-$ it leaves with \
                 $v^+ = -e\\,v^-$, $e = {}$",
                sc(e).to_latex(name)
            )
        };
        let mut gap = display(
            &format!(
                "Contact \\texttt{{{}}} ({}, {}): gap in {}, force in {}",
                tex_text(&c.name),
                tex_text(&c.meaning),
                kind,
                tex_text(&c.gap_unit),
                tex_text(&c.force_unit)
            ),
            format!("g_{{{}}} = ", k + 1),
            4,
            &sc(&c.gap),
            None,
            name,
        );
        // The gradient's entries, as many to a line as fit, a long one on lines of its own.
        let mut lines: Vec<String> = Vec::new();
        let mut used = TEX_LINE;
        for (q, j) in (d.coords.iter().zip(&c.jacobian)).filter(|(_, j)| !j.is_zero()) {
            let head = format!(
                "\\frac{{\\partial g_{{{}}}}}{{\\partial {}}} = ",
                k + 1,
                name(q)
            );
            let j = sc(j);
            let width = GRADIENT_HEAD + j.latex_width(name);
            match lines.last_mut() {
                Some(last) if used + 3 + width <= TEX_LINE => {
                    last.push_str(",\\quad ");
                    last.push_str(&head);
                    last.push_str(&j.to_latex(name));
                    used += 3 + width;
                }
                _ => {
                    let own = j.to_latex_lines(name, TEX_LINE, GRADIENT_HEAD);
                    used = if own.len() == 1 { width } else { TEX_LINE };
                    for (i, line) in own.into_iter().enumerate() {
                        lines.push(if i == 0 {
                            format!("{head}{line}")
                        } else {
                            line
                        });
                    }
                }
            }
        }
        gap.latex.push_str(" \\\\\n");
        gap.latex.push_str(&lines.join(" \\\\\n"));
        gap.env = "multline*";
        eqs.push(gap);
        if !c.bias.is_zero() {
            eqs.push(display(
                &format!(
                    "Its normal acceleration is $\\sum_j \\partial g_{{{}}}/\\partial q_j\\,\\ddot q_j$ plus",
                    k + 1
                ),
                String::new(),
                0,
                &sc(&c.bias),
                None,
                name,
            ));
        }
    }
    if !open.is_empty() {
        eqs.push(Equation {
            title: "While a set $A$ of these contacts is closed, the runtime solves for the \
                    accelerations and the closed contacts' forces together"
                .into(),
            env: "equation*",
            latex: "M(q)\\,\\ddot q = F(q, \\dot q) + \\sum_{j \\in A} \\lambda_j \\frac{\\partial g_j}{\\partial q}, \\qquad \\frac{\\partial g_j}{\\partial q}\\,\\ddot q + \\dot{\\Big(\\frac{\\partial g_j}{\\partial q}\\Big)}\\,\\dot q = 0 \\quad (j \\in A)".into(),
            tag: None,
            small: false,
        });
    }
}

/// A step's title and the form to print (over `rc_s`, `rc_c`): its presented form, unless
/// that holds a term wider than the page which the derived form does not; the title says
/// when the derived form is printed, and why.
fn step(title: &str, shown: &Shown, name: &dyn Fn(&str) -> String) -> (String, Expr) {
    let too_wide = |e: &Expr| widest_term(e, name) > TEX_LINE;
    let why = match &shown.as_derived {
        Some(why) => Some(why.as_str()),
        None if too_wide(&shown.expr) && !too_wide(&shown.derived) => {
            Some("the grouped form has a term wider than the page")
        }
        None => None,
    };
    match why {
        None => (title.to_string(), shown.expr.clone()),
        Some(why) => (
            format!("{title} (as derived: {})", tex_text(why)),
            shown.derived.clone(),
        ),
    }
}

/// A unit as inline LaTeX, `g/\ell` rather than a display fraction.
fn inline_unit(unit: &Expr, name: &dyn Fn(&str) -> String) -> String {
    let (num, den) = unit.num_den();
    let part = |v: Vec<Expr>| super::expr::product(v).to_latex(name);
    if den.is_empty() {
        part(num)
    } else {
        format!("{}/{}", part(num), part(den))
    }
}

/// The LaTeX of the results without units: the groups, the scales in words and the
/// numbered results (the paper's number beside each that the spec gives one for).
fn tex_dimensionless(
    dim: &Dimensionless,
    theta: &str,
    name: &dyn Fn(&str) -> String,
) -> (Vec<TexParam>, String, Vec<Equation>) {
    let groups = (dim.groups.iter())
        .map(|g| TexParam {
            symbol: format!("{} = {}", name(&g.name), g.definition.to_latex(name)),
            meaning: tex_text(&g.meaning),
            unit: format!("solved for ${}$", name(&g.solves)),
        })
        .collect();
    let scales = format!(
        "Time is in units of $T = {}$ and forces in units of ${}$. Each result below is written \
         in the groups and ${}$ alone; its form was chosen by the derivation tool among \
         candidates by {}.",
        dim.time.to_latex(name),
        dim.force.to_latex(name),
        name(theta),
        tex_text(present::RULE)
    );
    let mut results = Vec::new();
    for (i, r) in dim.results.iter().enumerate() {
        let form = from_sc(&r.form, theta);
        let quantity = match r.key.as_str() {
            "theta_dot_sq" => format!("{}^2", name(&format!("dot_{theta}"))),
            "theta_ddot" => name(&format!("ddot_{theta}")),
            key => format!("F_{{\\mathrm{{{}}}}}", tex_text(key)),
        };
        let (lhs, width, rhs) = match &r.unit {
            Some(u) => (
                format!("\\frac{{{quantity}}}{{{}}} = ", inline_unit(u, name)),
                6,
                None,
            ),
            None => (String::new(), 0, Some(Expr::int(0))),
        };
        let unit = match &r.unit {
            Some(u) => format!(", in units of ${}$", inline_unit(u, name)),
            None => String::new(),
        };
        let paper = match &r.paper {
            Some(p) => format!(" (the paper's eq.~({}))", tex_text(p)),
            None => String::new(),
        };
        let title = format!("{}{unit}{paper}", upper_first(&tex_text(&r.meaning)));
        let mut eq = display(&title, lhs, width, &form, rhs.as_ref(), name);
        eq.small = widest_term(&form, name) + width > TEX_LINE;
        eq.tag = Some(match &r.paper {
            Some(p) => format!("({})\\quad\\text{{paper ({})}}", i + 1, tex_text(p)),
            None => format!("({})", i + 1),
        });
        results.push(eq);
    }
    (groups, scales, results)
}

/// `text` with its first letter upper case.
fn upper_first(text: &str) -> String {
    let mut c = text.chars();
    match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

/// The fast path's steps: conserved momenta, reduced inertia, energy integral, forces and
/// the separation condition.
fn reduced_equations(
    d: &Derivation,
    r: &Reduction,
    steps: &Steps,
    name: &dyn Fn(&str) -> String,
    eqs: &mut Vec<Equation>,
) -> Result<(), String> {
    // Every result the reduction derived is shown in its presented form.
    let shown = |key: &str| -> Result<Option<&Shown>, String> {
        match (r.plain.get(key), steps.reduced.get(key)) {
            (None, _) => Ok(None),
            (Some(_), Some(s)) => Ok(Some(s)),
            (Some(_), None) => Err(format!("the result `{key}` was not presented")),
        }
    };
    let theta = d.theta().to_string();
    let sc = |e: &Expr| from_sc(e, &theta);
    for ((j, &ci), momentum) in d.cyclic.iter().enumerate().zip(&steps.momenta) {
        let c = &d.coords[ci];
        let conserved = r
            .constants
            .iter()
            .find(|k| k.symbol == format!("rc_p{j}"))
            .map(|k| sc(&k.value));
        let (title, e) = step(
            &format!(
                "${}$ is cyclic: its conjugate momentum is conserved",
                name(c)
            ),
            momentum,
            name,
        );
        eqs.push(display(
            &title,
            format!(
                "p_{{{}}} = \\frac{{\\partial L}}{{\\partial {}}} = ",
                name(c),
                name(&format!("dot_{c}")),
            ),
            10,
            &sc(&e),
            conserved.as_ref(),
            name,
        ));
    }
    let results = [
        (
            "reduced_inertia",
            "Reduced inertia (kinetic energy $\\tfrac12 A(\\theta)\\dot\\theta^2$ after elimination)",
            "A = ".to_string(),
            2,
        ),
        (
            "theta_dot_sq",
            "Energy integral",
            format!("{}^2 = ", name(&format!("dot_{theta}"))),
            4,
        ),
        (
            "theta_ddot",
            "Angular acceleration, $\\tfrac12\\,d(\\dot\\theta^2)/d\\theta$",
            format!("{} = ", name(&format!("ddot_{theta}"))),
            3,
        ),
    ];
    for (key, title, lhs, width) in results {
        if let Some(s) = shown(key)? {
            let (title, e) = step(title, s, name);
            eqs.push(display(&title, lhs, width, &sc(&e), None, name));
        }
    }
    for c in d.contacts.iter().filter(|c| c.closed) {
        if let Some(s) = shown(&c.name)? {
            let title = format!(
                "Force \\texttt{{{}}}: {}",
                tex_text(&c.name),
                tex_text(&c.meaning)
            );
            let (title, e) = step(&title, s, name);
            eqs.push(display(&title, "F = ".into(), 2, &sc(&e), None, name));
        }
    }
    if let Some(s) = shown("separation_condition")? {
        let (title, e) = step(
            "Separation condition (contact force zero; positive factors and $\\cos\\theta$ removed)",
            s,
            name,
        );
        eqs.push(display(
            &title,
            String::new(),
            0,
            &sc(&e),
            Some(&Expr::int(0)),
            name,
        ));
    }
    Ok(())
}

/// The machine-readable record (`generated/<model>.json`).
pub fn json_record(checked: &Checked, d: &Derivation) -> serde_json::Value {
    let theta = d.theta().to_string();
    let infix = |e: &Expr| from_sc(e, &theta).to_infix();
    let mut expressions = BTreeMap::new();
    let (route, reason) = match &d.reduction {
        Ok(r) => {
            for (k, v) in &r.plain {
                if k == "reduced_inertia" {
                    continue;
                }
                expressions.insert(k.to_string(), from_sc(v, &theta).to_infix());
            }
            let how = match (d.contacts.first(), r.separation()) {
                (Some(c), Some(_)) if c.closed => {
                    "separation: the root of a polynomial in sin(theta)"
                }
                (Some(c), None) if c.closed => {
                    "separation: a bracketed root of the reduced contact force"
                }
                _ => "",
            };
            ("reduced", how.to_string())
        }
        Err(why) => ("integrated", why.clone()),
    };
    expressions.insert("lagrangian".into(), infix(&d.lagrangian));
    let contacts: Vec<serde_json::Value> = (d.contacts.iter().zip(&d.restitutions))
        .map(|(c, e)| {
            let mut v = serde_json::json!({
                "name": c.name,
                "meaning": c.meaning,
                "gap_unit": c.gap_unit,
                "force_unit": c.force_unit,
                "bilateral": c.bilateral,
                "eliminates": c.eliminates,
                "closed": c.closed,
                "restitution": infix(e),
            });
            match &c.force {
                Some(f) => v["force"] = infix(f).into(),
                None => {
                    v["gap"] = infix(&c.gap).into();
                    v["jacobian"] = (d.coords.iter().zip(&c.jacobian))
                        .map(|(q, j)| (q.clone(), serde_json::Value::from(infix(j))))
                        .collect::<serde_json::Map<_, _>>()
                        .into();
                    v["bias"] = infix(&c.bias).into();
                }
            }
            if let Some(e) = &c.edge {
                v["edge"] = infix(e).into();
            }
            v
        })
        .collect();
    let closed: Vec<&str> = (d.plan.closed.iter())
        .filter_map(|&j| d.contacts.get(j).map(|c| c.name.as_str()))
        .collect();
    let mut record = serde_json::json!({
        "generated_by": COMMAND,
        "note": "Generated file; do not edit by hand.",
        "model": d.name,
        "system": d.system,
        "closed": closed,
        "start_params": d.plan.start_params,
        "spec": spec_path(checked),
        "description": d.description,
        "parameters": d.params.iter().map(|p| serde_json::json!({"name": p.name, "meaning": p.meaning, "unit": p.unit})).collect::<Vec<_>>(),
        "coordinates": d.coords,
        "reduced": theta,
        "cyclic": d.cyclic.iter().map(|&i| d.coords[i].clone()).collect::<Vec<_>>(),
        "route": route,
        "route_note": reason,
        "velocity_symbols": "theta_dot, theta_ddot in the reduced expressions are eliminated; dot_q / ddot_q denote velocities and accelerations in `lagrangian`, the contacts' rows and forces",
        "mass_matrix": d.mass.iter().map(|row| row.iter().map(infix).collect::<Vec<_>>()).collect::<Vec<_>>(),
        "rhs": d.rhs.iter().map(infix).collect::<Vec<_>>(),
        "contacts": contacts,
        "expressions": expressions,
    });
    if let Some(dim) = &d.dimensionless {
        record["dimensionless"] = dimensionless_record(dim, &theta);
    }
    if !d.frictions.is_empty() {
        record["frictions"] = d
            .frictions
            .iter()
            .enumerate()
            .map(|(j, f)| {
                serde_json::json!({
                    "name": f.named.name,
                    "meaning": f.named.meaning,
                    "coefficient": d.params[f.coefficient].name,
                    "contact": d.contacts[f.contact].name,
                    "slip_velocity": infix(&f.slip),
                    "force_symbol": format!("rc_fr{j}"),
                })
            })
            .collect();
    }
    record
}

/// The JSON record's `dimensionless` block: groups, scales, and each result's form, unit and
/// (where the spec gives one) the paper's equation number.
fn dimensionless_record(dim: &Dimensionless, theta: &str) -> serde_json::Value {
    let groups: Vec<serde_json::Value> = (dim.groups.iter())
        .map(|g| {
            serde_json::json!({
                "name": g.name,
                "definition": g.definition.to_infix(),
                "meaning": g.meaning,
                "solved_for": g.solves,
            })
        })
        .collect();
    let mut expressions = serde_json::Map::new();
    let mut units = serde_json::Map::new();
    let mut paper = serde_json::Map::new();
    for r in &dim.results {
        let form = from_sc(&r.form, theta).to_infix();
        expressions.insert(r.key.clone(), form.into());
        let unit = match &r.unit {
            Some(u) => u.to_infix(),
            None => "none: a condition = 0, written up to a constant factor".into(),
        };
        units.insert(r.key.clone(), unit.into());
        if let Some(p) = &r.paper {
            paper.insert(r.key.clone(), format!("({p})").into());
        }
    }
    let mut block = serde_json::json!({
        "groups": groups,
        "scales": {"time": dim.time.to_infix(), "force": dim.force.to_infix()},
        "expressions": expressions,
        "units": units,
        "forms": present::RULE,
    });
    if !paper.is_empty() {
        block["paper_equations"] = paper.into();
    }
    if dim.results.is_empty() {
        block["note"] = "the integrated route has no closed-form results".into();
    }
    block
}

/// An angle as Rust source: `std::f64::consts::FRAC_PI_2` and the like (with their sign) where
/// the value is exactly one of them, so the generated code names the angle a reader knows;
/// otherwise its exact float literal.
fn angle_literal(x: f64) -> String {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_4, FRAC_PI_6, PI};
    let named = [
        (PI, "PI"),
        (FRAC_PI_2, "FRAC_PI_2"),
        (FRAC_PI_3, "FRAC_PI_3"),
        (FRAC_PI_4, "FRAC_PI_4"),
        (FRAC_PI_6, "FRAC_PI_6"),
    ];
    match named.iter().find(|(v, _)| *v == x.abs()) {
        Some((_, name)) => {
            let sign = if x < 0.0 { "-" } else { "" };
            format!("{sign}std::f64::consts::{name}")
        }
        None => super::expr::float_literal(x),
    }
}

#[cfg(test)]
mod tests {
    use super::{one_line, tex_text};

    #[test]
    fn spec_text_cannot_leave_a_comment_or_run_as_tex() {
        assert_eq!(one_line("a\n  pub fn evil() {}\r\n"), "a pub fn evil() {}");
        assert_eq!(
            tex_text("\\input{/etc/passwd} 50% of m_1 & N >= 0\n\\end"),
            "\\textbackslash{}input\\{/etc/passwd\\} 50\\% of m\\_1 \\& N \\textgreater{}= 0 \\textbackslash{}end"
        );
        assert_eq!(tex_text("m/s^2"), "m/s\\^{}2");
    }
}
