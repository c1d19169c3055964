//! Turns a [`Derivation`] into template contexts (flat data, computed here) and renders the
//! tera templates of `templates/` into Rust, LaTeX and JSON text.

use super::dimensionless::Dimensionless;
use super::expr::Expr;
use super::lower::{Body, Hoisted, Scope, lower};
use super::mechanics::{self, Binding, Derivation, Reduction, from_sc, to_sc_expr};
use super::method::{Preamble, method};
use super::present;
use super::spec::Checked;
use super::steps::{Shown, Steps};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// The command that regenerates `generated/`, named in every file header.
pub const COMMAND: &str = "cargo run --release --features derive -- derive";

/// A straight-line function body: statements, then outputs; [`Code::finish`] makes it a
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

/// Everything the Rust template needs, all computed.
#[derive(Debug, Clone, Serialize)]
pub struct RustContext {
    command: String,
    name: String,
    type_name: String,
    description: String,
    description_literal: String,
    spec: String,
    params: Vec<Param>,
    requirements_info: Vec<Named>,
    n_params: usize,
    n_constants: usize,
    coordinates: Vec<String>,
    n_coordinates: usize,
    reduced: usize,
    cyclic: Vec<usize>,
    end_angle: String,
    forces_info: Vec<Named>,
    contact: Option<String>,
    /// `FrictionInfo { .. }` literals.
    frictions_info: Vec<String>,
    points_info: Vec<Named>,
    falling_point: usize,
    gravity: usize,
    monitors_info: Vec<Monitor>,
    /// The bodies' names, as Rust string literals.
    bodies: Vec<String>,
    /// `ShapeInfo { .. }` literals.
    shapes_info: Vec<String>,
    /// `Model::drawing`: the bodies' poses and the shapes' numbers.
    drawing: Code,
    next_phase: Option<String>,
    /// `ReductionInfo { .. }` when the phase has the fast path.
    reduction_info: Option<String>,
    /// Why the phase has no fast path (empty when it has one).
    route_note: String,
    requirements: Code,
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
    separation: Code,
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

fn lit(x: f64) -> String {
    super::expr::float_literal(x)
}

/// The Rust spelling of a binding to the next phase.
fn binding(b: &Binding) -> String {
    match b {
        Binding::Param(i) => format!("Binding::Param({i})"),
        Binding::Coordinate(i) => format!("Binding::Coordinate({i})"),
        Binding::Velocity(i) => format!("Binding::Velocity({i})"),
        Binding::Eliminated => "Binding::Eliminated".into(),
        Binding::EliminatedRate => "Binding::EliminatedRate".into(),
    }
}

/// `out[i] = <output i>;` lines.
fn out_lines(outputs: &[String]) -> Vec<String> {
    outputs
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect()
}

/// Builds the Rust context of one derived phase.
///
/// A named constant of the reduction that no generated line reads and the runtime does not
/// read either (`ReductionInfo`'s start slots) gets no slot: the context is built once to find
/// such constants, and again without them.
pub fn rust_context(checked: &Checked, d: &Derivation) -> Result<RustContext, String> {
    let first = context_without(checked, d, &BTreeSet::new())?;
    if first.unread.is_empty() {
        return Ok(first);
    }
    let second = context_without(checked, d, &first.unread)?;
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
    skip: &BTreeSet<String>,
) -> Result<RustContext, String> {
    let spec = &checked.spec;
    let np = d.params.len();
    let (scope, mut prepare, own) = constant_layout(d, skip);
    let mut hoisted = Hoisted::new(np + own.len());
    if let Ok(r) = &d.reduction {
        for &(j, slot) in &own {
            hoisted.known(&r.constants[j].value, slot);
        }
    }
    let general = full_state_code(d, &scope, &mut hoisted)?;
    let reduction = match &d.reduction {
        Ok(r) => Some(reduced_code(d, r, &scope, &mut hoisted)?),
        Err(_) => None,
    };
    let (drawing, shapes_info) = drawing_code(d, &scope, &mut hoisted);

    // Requirements over the parameters (no hoisting: they run before prepare).
    let mut requirements = Code::default();
    let mut req_scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        req_scope.constants.insert(p.name.clone(), i);
    }
    let out = requirements.push_body(lower(&d.requirements, &req_scope, None, "q"));
    requirements.outputs = out_lines(&out);

    // With a fast path, prepare starts with the per-point solver's constants
    // (`prepare_lean`) and computes the others after them, each once; hoisted constants go to
    // the end.
    let n_constants = hoisted.len();
    let mut reduction = reduction;
    let mut lean_indices = Vec::new();
    if let (Ok(r), Some(code)) = (&d.reduction, reduction.as_mut()) {
        let (lean, indices) = lean_prepare(np, r, &own, &scope, &hoisted, code)?;
        code.prepare_lean = lean;
        code.lean_constants = indices.clone();
        prepare = Code::default();
        prepare
            .stmts
            .push("Reduction::prepare_lean(self, p, k);".into());
        for &(j, slot) in &own {
            if !indices.contains(&slot) {
                let c = &r.constants[j];
                bind_constant(
                    &mut prepare,
                    slot,
                    Some(&c.symbol),
                    &c.value,
                    &scope,
                    &format!("c{j}_"),
                );
            }
        }
        lean_indices = indices;
    }
    for (i, e) in &hoisted.entries {
        if !lean_indices.contains(i) {
            bind_constant(&mut prepare, *i, None, e, &scope, &format!("h{i}_"));
        }
    }
    // A named constant that is another one lives in its slot: `prepare` starts by saying so.
    if let Ok(r) = &d.reduction {
        let notes = r
            .constants
            .iter()
            .enumerate()
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

    // Static info.
    let point_index = |name: &str| {
        spec.points
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| format!("`{name}` is not one of the points"))
    };
    let contact = d.contact.as_ref().map(|c| {
        format!(
            "ContactInfo {{ force: {}, eliminated: {:?}, edge: {} }}",
            c.force,
            c.eliminated,
            c.edge.is_some()
        )
    });
    let next_phase = d.next.as_ref().map(|n| {
        format!(
            "NextPhase {{ model: {:?}, bindings: &[{}] }}",
            n.model,
            n.bindings
                .iter()
                .map(binding)
                .collect::<Vec<_>>()
                .join(", ")
        )
    });
    let reduction_info = match (&d.reduction, &reduction) {
        (Ok(r), Some(code)) => {
            let k = |s: &str| {
                scope
                    .constants
                    .get(s)
                    .copied()
                    .ok_or_else(|| format!("the reduction has no constant `{s}`"))
            };
            Some(format!(
                "ReductionInfo {{ k_theta_initial: {}, k_theta_dot_initial: {}, k_sin_initial: {}, k_cos_initial: {}, separation_degree: {}, polynomial_separation: {}, fall_degree: {:?}, lean_constants: &{:?} }}",
                code.k_theta_initial,
                k("rc_wi")?,
                code.k_sin_initial,
                code.k_cos_initial,
                r.separation
                    .as_ref()
                    .map_or(0, |s| s.coefficients.len() - 1),
                r.separation.is_some(),
                r.fall.as_ref().map(|f| f.len() - 1),
                code.lean_constants
            ))
        }
        _ => None,
    };
    // Every method's arguments and lines, now that the code is complete.
    prepare
        .stmts
        .insert(0, format!("k[..{np}].copy_from_slice(p);"));
    prepare.finish(&[("p", "&[f64]"), ("k", "&mut [f64]")], &[]);
    requirements.finish(&[("p", "&[f64]"), OUT], &[Preamble::Let("k", "p")]);
    let mut general = general;
    general.finish(n_constants, d.reduced);
    if let Some(code) = reduction.as_mut() {
        code.finish(n_constants, np, d.reduced);
    }
    let mut drawing = drawing;
    let poses = ("poses", "&mut [[f64; 3]]");
    let sizes = ("sizes", "&mut [f64]");
    drawing.finish(
        &[K, Q, poses, sizes],
        &[Preamble::Slice(n_constants), Preamble::Angle(d.reduced)],
    );
    let named = |v: &[mechanics::Named]| {
        v.iter()
            .map(|n| Named {
                name: n.name.clone(),
                meaning: format!("{:?}", n.meaning),
            })
            .collect()
    };
    let mut codes: Vec<&Code> = vec![&requirements, &prepare, &drawing];
    codes.extend(general.codes());
    codes.extend(reduction.iter().flat_map(ReducedCode::codes));
    let unread = unread_constants(d, &own, &codes);
    Ok(RustContext {
        command: COMMAND.into(),
        name: d.name.clone(),
        type_name: type_name(&d.name),
        // Comments in the generated code: one line, so no spec text can end them.
        description: one_line(&d.description),
        description_literal: format!("{:?}", d.description),
        spec: one_line(&spec_path(checked)),
        params: d
            .params
            .iter()
            .map(|p| Param {
                name: p.name.clone(),
                meaning: format!("{:?}", p.meaning),
                unit: format!("{:?}", p.unit),
                positive: p.positive,
            })
            .collect(),
        requirements_info: spec
            .requirements
            .iter()
            .map(|r| Named {
                name: r.name.clone(),
                meaning: format!("{:?}", r.meaning),
            })
            .collect(),
        n_params: np,
        n_constants,
        coordinates: d.coords.clone(),
        n_coordinates: d.coords.len(),
        reduced: d.reduced,
        cyclic: d.cyclic.clone(),
        end_angle: lit(spec.end_angle),
        forces_info: named(&d.forces),
        contact,
        frictions_info: d
            .frictions
            .iter()
            .map(|f| {
                format!(
                    "FrictionInfo {{ name: {:?}, meaning: {:?}, coefficient: {}, normal: {} }}",
                    f.named.name, f.named.meaning, f.coefficient, f.normal
                )
            })
            .collect(),
        points_info: spec
            .points
            .iter()
            .map(|p| Named {
                name: p.name.clone(),
                meaning: format!("{:?}", p.meaning),
            })
            .collect(),
        falling_point: point_index(&spec.falling_point)?,
        gravity: d
            .params
            .iter()
            .position(|p| p.name == spec.gravity)
            .ok_or_else(|| format!("`{}` is not a parameter", spec.gravity))?,
        monitors_info: d
            .monitors
            .iter()
            .map(|m| Monitor {
                name: format!("{:?}", m.name),
                meaning: format!("{:?}", m.meaning),
                unit: format!("{:?}", m.unit),
            })
            .collect(),
        bodies: d.bodies.iter().map(|b| format!("{b:?}")).collect(),
        shapes_info,
        drawing,
        next_phase,
        reduction_info,
        route_note: match &d.reduction {
            Ok(_) => format!("{:?}", ""),
            Err(why) => format!("{:?}", one_line(why)),
        },
        requirements,
        prepare,
        general,
        reduction,
        unread,
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
    for line in [&code.separation, &code.fall]
        .into_iter()
        .flat_map(|c| c.stmts.iter().chain(&c.outputs))
    {
        stack.extend(k_indices(line));
    }
    let mut needed = std::collections::BTreeSet::new();
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
    friction: Code,
    monitors_full: Code,
    contact_edge: Code,
    released: Code,
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
    fn codes(&self) -> [&Code; 10] {
        [
            &self.initial_state,
            &self.points,
            &self.energy,
            &self.momenta,
            &self.equations,
            &self.forces_full,
            &self.friction,
            &self.monitors_full,
            &self.contact_edge,
            &self.released,
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
        let fr = ("fr", "&[f64]");
        self.forces_full.finish(&[K, Q, QD, qdd, fr, OUT], &state);
        let jac = ("jac", "&mut [f64]");
        let bias = ("bias", "&mut [f64]");
        self.friction.finish(&[K, Q, QD, jac, bias], &state);
        let forces = ("forces", "&[f64]");
        self.monitors_full.finish(&[K, Q, QD, forces, OUT], &state);
        self.contact_edge.finish(&[K, Q], &state);
        self.released.finish(&[K, Q, QD, OUT], &state);
    }
}

impl ReducedCode {
    /// Every method's code.
    fn codes(&self) -> [&Code; 7] {
        [
            &self.reduced_code,
            &self.theta_dot_sq_code,
            &self.forces,
            &self.separation,
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
        self.separation.outputs = out_lines(&self.separation.outputs);
        self.separation.finish(&[K, OUT], &[slice]);
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
    let mut full_scope = state_scope(d, scope);
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

    for j in 0..d.frictions.len() {
        full_scope
            .locals
            .insert(format!("rc_fr{j}"), format!("fr[{j}]"));
    }
    let ff: Vec<Expr> = d.forces_full.iter().map(sc).collect();
    let (mut forces_full, out) = single("f", &ff, &full_scope, hoisted);
    forces_full.outputs = out_lines(&out);

    let mut exprs: Vec<Expr> = Vec::new();
    for f in &d.frictions {
        exprs.extend(f.jacobian.iter().map(sc));
    }
    exprs.extend(d.frictions.iter().map(|f| sc(&f.bias)));
    let (mut friction, out) = single("s", &exprs, &full_scope, hoisted);
    let n_jac = nc * d.frictions.len();
    friction.outputs = (0..n_jac)
        .map(|i| format!("jac[{i}] = {};", out[i]))
        .chain((0..d.frictions.len()).map(|j| format!("bias[{j}] = {};", out[n_jac + j])))
        .collect();

    let mut mon_scope = full_scope.clone();
    for i in 0..d.forces.len() {
        mon_scope
            .locals
            .insert(format!("rc_f{i}"), format!("forces[{i}]"));
    }
    let mo: Vec<Expr> = d.monitors_full.iter().map(sc).collect();
    let (mut monitors_full, out) = single("m", &mo, &mon_scope, hoisted);
    monitors_full.outputs = out_lines(&out);

    let mut contact_edge = Code::default();
    let mut released = Code::default();
    match &d.contact {
        Some(c) => {
            if let Some(edge) = &c.edge {
                let (code, out) = single("g", &[sc(edge)], &full_scope, hoisted);
                contact_edge = code;
                contact_edge.outputs = out;
            } else {
                contact_edge.outputs = vec!["f64::INFINITY".into()];
            }
            let (code, out) = single(
                "r",
                &[sc(&c.released[0]), sc(&c.released[1])],
                &full_scope,
                hoisted,
            );
            released = code;
            released.outputs = out_lines(&out);
        }
        None => contact_edge.outputs = vec!["f64::INFINITY".into()],
    }
    let stray = super::lower::unbound(&d.forces_full, &full_scope);
    if !stray.is_empty() {
        return Err(format!(
            "the forces depend on {} besides the state and the parameters",
            stray.into_iter().collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(FullStateCode {
        initial_state,
        points,
        energy,
        momenta,
        equations,
        forces_full,
        friction,
        monitors_full,
        contact_edge,
        released,
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

    // Separation polynomial: coefficients are constants, hoisted into k.
    let mut separation = Code::default();
    if let Some(sep) = &r.separation {
        separation.outputs =
            separation.push_body(lower(&sep.coefficients, scope, Some(hoisted), "p"));
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
        separation,
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
    if let Some(c) = &d.contact {
        eqs.push(display(
            &format!(
                "Contact: the gap is zero while the bodies touch, which ties ${}$",
                name(&c.eliminated)
            ),
            format!("{} = ", name(&c.eliminated)),
            3,
            &c.released[0],
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
    match &d.reduction {
        Ok(r) => reduced_equations(d, r, steps, &name, &mut eqs)?,
        Err(why) => {
            for (f, e) in d.forces.iter().zip(&d.forces_full) {
                eqs.push(display(
                    &format!(
                        "Force \\texttt{{{}}}: {} (integrated route: {})",
                        tex_text(&f.name),
                        tex_text(&f.meaning),
                        tex_text(why)
                    ),
                    "F = ".into(),
                    2,
                    &sc(e),
                    None,
                    &name,
                ));
            }
        }
    }
    if let Some(edge) = d.contact.as_ref().and_then(|c| c.edge.as_ref()) {
        eqs.push(display(
            "Edge: the contact can exist while this margin is not negative",
            String::new(),
            0,
            &sc(edge),
            None,
            &name,
        ));
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
    for (i, f) in d.forces.iter().enumerate() {
        let key = if i == 0 && d.contact.is_some() {
            "contact_force"
        } else {
            f.name.as_str()
        };
        if let Some(s) = shown(key)? {
            let title = format!(
                "Force \\texttt{{{}}}: {}",
                tex_text(&f.name),
                tex_text(&f.meaning)
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
    let mut expressions = BTreeMap::new();
    let (route, reason) = match &d.reduction {
        Ok(r) => {
            for (k, v) in &r.plain {
                if k == "reduced_inertia" {
                    continue;
                }
                expressions.insert(k.to_string(), from_sc(v, &theta).to_infix());
            }
            let how = match (&d.contact, &r.separation) {
                (Some(_), Some(_)) => "separation: the root of a polynomial in sin(theta)",
                (Some(_), None) => "separation: a bracketed root of the reduced contact force",
                _ => "",
            };
            ("reduced", how.to_string())
        }
        Err(why) => {
            for (f, e) in d.forces.iter().zip(&d.forces_full) {
                expressions.insert(f.name.clone(), from_sc(e, &theta).to_infix());
            }
            ("integrated", why.clone())
        }
    };
    expressions.insert(
        "lagrangian".into(),
        from_sc(&d.lagrangian, &theta).to_infix(),
    );
    let mut record = serde_json::json!({
        "generated_by": COMMAND,
        "note": "Generated file; do not edit by hand.",
        "model": d.name,
        "spec": spec_path(checked),
        "description": d.description,
        "parameters": d.params.iter().map(|p| serde_json::json!({"name": p.name, "meaning": p.meaning, "unit": p.unit})).collect::<Vec<_>>(),
        "coordinates": d.coords,
        "reduced": theta,
        "cyclic": d.cyclic.iter().map(|&i| d.coords[i].clone()).collect::<Vec<_>>(),
        "route": route,
        "route_note": reason,
        "velocity_symbols": "theta_dot, theta_ddot in the reduced expressions are eliminated; dot_q / ddot_q denote velocities and accelerations in `lagrangian` and in integrated forces",
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
                    "normal": d.forces[f.normal].name,
                    "slip_velocity": from_sc(&f.slip, &theta).to_infix(),
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
