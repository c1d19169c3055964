//! Turns a [`Derivation`] into template contexts (flat data, computed here) and renders the
//! tera templates of `templates/` into Rust, LaTeX and JSON text.

use super::expr::Expr;
use super::lower::{Body, Hoisted, Scope, lower};
use super::mechanics::{Derivation, from_sc};
use super::spec::Checked;
use serde::Serialize;
use std::collections::BTreeMap;

/// The command that regenerates `generated/`, named in every file header.
pub const COMMAND: &str = "cargo run --release --features derive -- derive";

/// A straight-line function body: statements, then outputs.
#[derive(Debug, Clone, Serialize, Default)]
pub struct Code {
    stmts: Vec<String>,
    outputs: Vec<String>,
}

impl Code {
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
    k_theta_initial: usize,
    k_theta_dot_initial: usize,
    k_sin_initial: usize,
    k_cos_initial: usize,
    coordinates: Vec<String>,
    reduced: usize,
    cyclic: Vec<usize>,
    end_angle: String,
    forces_info: Vec<Named>,
    contact: Option<String>,
    separation_degree: usize,
    points_info: Vec<Named>,
    falling_point: usize,
    gravity: usize,
    monitors_info: Vec<Named>,
    next_phase: Option<String>,
    requirements: Code,
    prepare: Code,
    reduced_code: Code,
    theta_dot_sq_code: Code,
    forces: Code,
    monitors: Code,
    separation: Code,
    full_state: Code,
    points: Code,
    energy: Code,
    momenta: Code,
    equations: Code,
    forces_full: Code,
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

fn replace_sc(e: &Expr, theta: &str) -> Expr {
    match e {
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "sin" => {
            Expr::sym("rc_s")
        }
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "cos" => {
            Expr::sym("rc_c")
        }
        Expr::Add(v) => Expr::Add(v.iter().map(|x| replace_sc(x, theta)).collect()),
        Expr::Mul(v) => Expr::Mul(v.iter().map(|x| replace_sc(x, theta)).collect()),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(replace_sc(b, theta)),
            Box::new(replace_sc(x, theta)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(|x| replace_sc(x, theta)).collect()),
        _ => e.clone(),
    }
}

fn lit(x: f64) -> String {
    super::expr::float_literal(x)
}

/// Builds the Rust context. `next_params` gives, for the phase after separation, its
/// parameter names in order (looked up in the other specs).
pub fn rust_context(
    checked: &Checked,
    d: &Derivation,
    next_params: Option<&[String]>,
) -> Result<RustContext, String> {
    let spec = &checked.spec;
    let theta = d.coords[d.reduced].clone();
    let np = d.params.len();
    // Constant layout: parameters, then derived constants, then hoisted subexpressions.
    let mut scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        scope.constants.insert(p.clone(), i);
    }
    let mut prepare = Code::default();
    for (j, c) in d.constants.iter().enumerate() {
        let idx = np + j;
        let body = lower(
            std::slice::from_ref(&c.value),
            &scope,
            None,
            &format!("c{j}_"),
        );
        let out = prepare.push_body(body);
        prepare.bind(&format!("k[{idx}]"), out[0].clone());
        scope.constants.insert(c.symbol.clone(), idx);
    }
    let idx = |s: &str| scope.constants.get(s).copied().unwrap_or(0);
    let mut hoisted = Hoisted::new(np + d.constants.len());

    // Reduced motion: rc_s, rc_c, rc_ds, rc_dc are locals set by the template's preamble.
    let mut red_scope = scope.clone();
    for s in ["rc_s", "rc_c", "rc_ds", "rc_dc", "rc_delta", "rc_t", "rc_w"] {
        red_scope.locals.insert(s.into(), s.into());
    }
    red_scope
        .locals
        .insert(theta.clone(), format!("(k[{}] - rc_delta)", idx("rc_thi")));
    let mut reduced_code = Code::default();
    let out = reduced_code.push_body(lower(
        &[d.theta_dot_sq.clone(), d.theta_ddot.clone()],
        &red_scope,
        Some(&mut hoisted),
        "r",
    ));
    reduced_code.outputs = out;

    // theta_dot^2 alone from sin, cos and their drops (the lean solver's integrand): the energy
    // integral has no other dependence on theta, which `mechanics` has checked.
    let mut sc_scope = scope.clone();
    for s in ["rc_s", "rc_c", "rc_ds", "rc_dc"] {
        sc_scope.locals.insert(s.into(), s.into());
    }
    let stray: Vec<String> = d
        .theta_dot_sq
        .symbols()
        .into_iter()
        .filter(|s| !sc_scope.locals.contains_key(s) && !scope.constants.contains_key(s))
        .collect();
    if !stray.is_empty() {
        return Err(format!(
            "theta_dot^2 depends on {} besides sin, cos and constants",
            stray.join(", ")
        ));
    }
    let mut theta_dot_sq_code = Code::default();
    theta_dot_sq_code.outputs = theta_dot_sq_code.push_body(lower(
        std::slice::from_ref(&d.theta_dot_sq),
        &sc_scope,
        Some(&mut hoisted),
        "r",
    ));

    // Forces: theta_dot^2 and theta_ddot first, then the forces over them.
    let mut force_scope = red_scope.clone();
    force_scope.locals.insert("rc_w2".into(), "rc_w2".into());
    force_scope.locals.insert("rc_acc".into(), "rc_acc".into());
    let mut forces = Code::default();
    let wa = forces.push_body(lower(
        &[d.theta_dot_sq.clone(), d.theta_ddot.clone()],
        &red_scope,
        Some(&mut hoisted),
        "r",
    ));
    forces.bind("rc_w2", wa[0].clone());
    forces.bind("rc_acc", wa[1].clone());
    let fo = forces.push_body(lower(
        &d.forces_reduced,
        &force_scope,
        Some(&mut hoisted),
        "f",
    ));
    forces.outputs = fo;

    // Monitors: the forces first, then the monitors over them.
    let mut monitors = Code::default();
    if !d.monitors.is_empty() {
        let wa = monitors.push_body(lower(
            &[d.theta_dot_sq.clone(), d.theta_ddot.clone()],
            &red_scope,
            Some(&mut hoisted),
            "r",
        ));
        monitors.bind("rc_w2", wa[0].clone());
        monitors.bind("rc_acc", wa[1].clone());
        let fo = monitors.push_body(lower(
            &d.forces_reduced,
            &force_scope,
            Some(&mut hoisted),
            "f",
        ));
        let mut mon_scope = force_scope.clone();
        for (i, f) in fo.into_iter().enumerate() {
            monitors.bind(&format!("rc_f{i}"), f);
            mon_scope
                .locals
                .insert(format!("rc_f{i}"), format!("rc_f{i}"));
        }
        monitors.outputs =
            monitors.push_body(lower(&d.monitors, &mon_scope, Some(&mut hoisted), "m"));
    }

    // Separation polynomial: coefficients are constants, hoisted into k.
    let mut separation = Code::default();
    if let Some(sep) = &d.separation {
        separation.outputs =
            separation.push_body(lower(&sep.coefficients, &scope, Some(&mut hoisted), "p"));
    }

    // Full state on the reduced motion.
    let mut full_state = Code::default();
    {
        let mut outs = Vec::new();
        let cy = full_state.push_body(lower(
            &d.cyclic_position,
            &red_scope,
            Some(&mut hoisted),
            "x",
        ));
        let cv = full_state.push_body(lower(
            &d.cyclic_velocity,
            &red_scope,
            Some(&mut hoisted),
            "v",
        ));
        for (j, &ci) in d.cyclic.iter().enumerate() {
            outs.push(format!("q[{ci}] = {};", cy[j]));
            outs.push(format!("qd[{ci}] = {};", cv[j]));
        }
        full_state.outputs = outs;
    }

    // Full-state functions: q, qd, qdd locals.
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
    let sc = |e: &Expr| replace_sc(e, &theta);
    let mut points = Code::default();
    {
        let mut exprs = Vec::new();
        for p in &d.point_pos {
            exprs.push(sc(&p[0]));
            exprs.push(sc(&p[1]));
        }
        for v in &d.point_vel {
            exprs.push(sc(&v[0]));
            exprs.push(sc(&v[1]));
        }
        let out = points.push_body(lower(&exprs, &full_scope, Some(&mut hoisted), "p"));
        let n = d.point_pos.len();
        let mut lines = Vec::new();
        for i in 0..n {
            lines.push(format!("pos[{i}] = [{}, {}];", out[2 * i], out[2 * i + 1]));
            lines.push(format!(
                "vel[{i}] = [{}, {}];",
                out[2 * n + 2 * i],
                out[2 * n + 2 * i + 1]
            ));
        }
        points.outputs = lines;
    }
    let mut energy = Code::default();
    let total = Expr::Add(vec![sc(&d.kinetic), sc(&d.potential)]);
    energy.outputs = energy.push_body(lower(&[total], &full_scope, Some(&mut hoisted), "e"));
    let mut momenta = Code::default();
    let mo: Vec<Expr> = d.momenta.iter().map(sc).collect();
    let out = momenta.push_body(lower(&mo, &full_scope, Some(&mut hoisted), "m"));
    momenta.outputs = out
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect();
    let mut equations = Code::default();
    {
        let n = d.coords.len();
        let mut exprs: Vec<Expr> = d.mass.iter().flat_map(|r| r.iter().map(sc)).collect();
        exprs.extend(d.rhs.iter().map(sc));
        let out = equations.push_body(lower(&exprs, &full_scope, Some(&mut hoisted), "q"));
        let mut lines = Vec::new();
        for (i, o) in out.iter().take(n * n).enumerate() {
            lines.push(format!("mass[{i}] = {o};"));
        }
        for i in 0..n {
            lines.push(format!("rhs[{i}] = {};", out[n * n + i]));
        }
        equations.outputs = lines;
    }
    let mut forces_full = Code::default();
    let ff: Vec<Expr> = d.forces_full.iter().map(sc).collect();
    let out = forces_full.push_body(lower(&ff, &full_scope, Some(&mut hoisted), "f"));
    forces_full.outputs = out
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect();

    // Requirements over the parameters (no hoisting: they run before prepare).
    let mut requirements = Code::default();
    let mut req_scope = Scope::default();
    for (i, p) in d.params.iter().enumerate() {
        req_scope.constants.insert(p.clone(), i);
    }
    let out = requirements.push_body(lower(&d.requirements, &req_scope, None, "q"));
    requirements.outputs = out
        .iter()
        .enumerate()
        .map(|(i, o)| format!("out[{i}] = {o};"))
        .collect();

    // Hoisted constants go to the end of prepare.
    for (i, e) in hoisted.entries.clone() {
        let body = lower(
            std::slice::from_ref(&e),
            &scope_with_hoisted(&scope),
            None,
            &format!("h{i}_"),
        );
        let out = prepare.push_body(body);
        prepare.bind(&format!("k[{i}]"), out[0].clone());
    }
    let n_constants = hoisted.len();

    // Static info.
    let point_index = |name: &str| spec.points.iter().position(|p| p.name == name).unwrap_or(0);
    let contact = spec.contact.as_ref().map(|c| {
        let force = spec.forces.iter().position(|f| f.name == c.force).unwrap_or(0);
        format!(
            "ContactInfo {{ force: {force}, point: {}, surface: {}, normal: [{}, {}], surface_moves: {} }}",
            point_index(&c.point),
            point_index(&c.surface),
            lit(c.normal[0]),
            lit(c.normal[1]),
            d.surface_moves
        )
    });
    let next_phase = match (&spec.after_separation, next_params) {
        (Some(after), Some(names)) => {
            let mut bindings = Vec::new();
            for n in names {
                let src = after.parameters.get(n).ok_or_else(|| {
                    format!(
                        "after_separation.parameters: no value for `{n}`, a parameter of `{}`",
                        after.model
                    )
                })?;
                let b = if let Some(i) = d.params.iter().position(|p| p == src) {
                    format!("Binding::Param({i})")
                } else if let Some(i) = d.coords.iter().position(|c| c == src) {
                    format!("Binding::Coordinate({i})")
                } else if let Some(i) = src
                    .strip_suffix("_dot")
                    .and_then(|c| d.coords.iter().position(|x| x == c))
                {
                    format!("Binding::Velocity({i})")
                } else if let Some((p, axis)) = src.split_once('.') {
                    let index = point_index(p);
                    match axis {
                        "x" => format!("Binding::Point {{ index: {index}, axis: 0 }}"),
                        "y" => format!("Binding::Point {{ index: {index}, axis: 1 }}"),
                        "x_dot" => format!("Binding::PointVelocity {{ index: {index}, axis: 0 }}"),
                        _ => format!("Binding::PointVelocity {{ index: {index}, axis: 1 }}"),
                    }
                } else {
                    return Err(format!(
                        "after_separation.parameters.{n}: cannot bind `{src}`"
                    ));
                };
                bindings.push(b);
            }
            if let Some(extra) = after.parameters.keys().find(|k| !names.contains(k)) {
                return Err(format!(
                    "after_separation.parameters.{extra}: `{}` has no parameter `{extra}`",
                    after.model
                ));
            }
            Some(format!(
                "NextPhase {{ model: {:?}, bindings: &[{}] }}",
                after.model,
                bindings.join(", ")
            ))
        }
        _ => None,
    };
    let named = |v: Vec<(String, String)>| {
        v.into_iter()
            .map(|(name, meaning)| Named {
                name,
                meaning: format!("{meaning:?}"),
            })
            .collect()
    };
    Ok(RustContext {
        command: COMMAND.into(),
        name: spec.name.clone(),
        type_name: type_name(&spec.name),
        // Comments in the generated code: one line, so no spec text can end them.
        description: one_line(&spec.description),
        description_literal: format!("{:?}", spec.description),
        spec: one_line(&format!(
            "derivations/{}",
            checked
                .file
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default()
        )),
        params: spec
            .parameters
            .iter()
            .map(|p| Param {
                name: p.name.clone(),
                meaning: format!("{:?}", p.meaning),
                unit: format!("{:?}", p.unit),
                positive: p.positive,
            })
            .collect(),
        requirements_info: named(
            spec.requirements
                .iter()
                .map(|r| (r.name.clone(), r.meaning.clone()))
                .collect(),
        ),
        n_params: np,
        n_constants,
        k_theta_initial: idx("rc_thi"),
        k_theta_dot_initial: idx("rc_wi"),
        k_sin_initial: idx("rc_si"),
        k_cos_initial: idx("rc_ci"),
        coordinates: d.coords.clone(),
        reduced: d.reduced,
        cyclic: d.cyclic.clone(),
        end_angle: lit(spec.end_angle),
        forces_info: named(
            spec.forces
                .iter()
                .map(|f| (f.name.clone(), f.meaning.clone()))
                .collect(),
        ),
        contact,
        separation_degree: d
            .separation
            .as_ref()
            .map(|s| s.coefficients.len() - 1)
            .unwrap_or(0),
        points_info: named(
            spec.points
                .iter()
                .map(|p| (p.name.clone(), p.meaning.clone()))
                .collect(),
        ),
        falling_point: point_index(&spec.falling_point),
        gravity: d
            .params
            .iter()
            .position(|p| *p == spec.gravity)
            .unwrap_or(0),
        monitors_info: named(
            spec.monitors
                .iter()
                .map(|m| (m.name.clone(), m.meaning.clone()))
                .collect(),
        ),
        next_phase,
        requirements,
        prepare,
        reduced_code,
        theta_dot_sq_code,
        forces,
        monitors,
        separation,
        full_state,
        points,
        energy,
        momenta,
        equations,
        forces_full,
    })
}

fn scope_with_hoisted(scope: &Scope) -> Scope {
    scope.clone()
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
}

/// Builds the LaTeX context: the derivation's steps as displayed equations.
pub fn tex_context(checked: &Checked, d: &Derivation) -> TexContext {
    let theta = d.coords[d.reduced].clone();
    let name = |s: &str| latex_name(s, &theta);
    let sc = |e: &Expr| from_sc(e, &theta);
    let mut eqs = Vec::new();
    eqs.push(display(
        "Kinetic energy",
        "T = ".into(),
        2,
        &sc(&d.kinetic),
        None,
        &name,
    ));
    eqs.push(display(
        "Potential energy",
        "V = ".into(),
        2,
        &sc(&d.potential),
        None,
        &name,
    ));
    eqs.push(display(
        "Lagrangian",
        "L = T - V = ".into(),
        8,
        &sc(&d.plain["lagrangian"]),
        None,
        &name,
    ));
    for (i, c) in d.coords.iter().enumerate() {
        eqs.push(display(
            &format!("Euler--Lagrange equation for ${}$", name(c)),
            format!(
                "\\frac{{d}}{{dt}}\\frac{{\\partial L}}{{\\partial {}}} - \\frac{{\\partial L}}{{\\partial {}}} = ",
                name(&format!("dot_{c}")),
                name(c),
            ),
            14,
            &sc(&d.euler_lagrange[i]),
            Some(&Expr::int(0)),
            &name,
        ));
    }
    for (j, &ci) in d.cyclic.iter().enumerate() {
        let c = &d.coords[ci];
        let conserved = d
            .constants
            .iter()
            .find(|k| k.symbol == format!("rc_p{j}"))
            .map(|k| sc(&k.value));
        eqs.push(display(
            &format!(
                "${}$ is cyclic: its conjugate momentum is conserved",
                name(c)
            ),
            format!(
                "p_{{{}}} = \\frac{{\\partial L}}{{\\partial {}}} = ",
                name(c),
                name(&format!("dot_{c}")),
            ),
            10,
            &sc(&d.momenta[j]),
            conserved.as_ref(),
            &name,
        ));
    }
    eqs.push(display(
        "Reduced inertia (kinetic energy $\\tfrac12 A(\\theta)\\dot\\theta^2$ after elimination)",
        "A = ".into(),
        2,
        &sc(&d.plain["reduced_inertia"]),
        None,
        &name,
    ));
    eqs.push(display(
        "Energy integral",
        format!("{}^2 = ", name(&format!("dot_{theta}"))),
        4,
        &sc(&d.plain["theta_dot_sq"]),
        None,
        &name,
    ));
    eqs.push(display(
        "Angular acceleration, $\\tfrac12\\,d(\\dot\\theta^2)/d\\theta$",
        format!("{} = ", name(&format!("ddot_{theta}"))),
        3,
        &sc(&d.plain["theta_ddot"]),
        None,
        &name,
    ));
    for f in &checked.spec.forces {
        let key = if checked
            .spec
            .contact
            .as_ref()
            .is_some_and(|c| c.force == f.name)
        {
            "contact_force"
        } else {
            f.name.as_str()
        };
        if let Some(e) = d.plain.get(key) {
            eqs.push(display(
                &format!(
                    "Force \\texttt{{{}}}: {}",
                    tex_text(&f.name),
                    tex_text(&f.meaning)
                ),
                "F = ".into(),
                2,
                &sc(e),
                None,
                &name,
            ));
        }
    }
    if let Some(e) = d.plain.get("separation_condition") {
        eqs.push(display(
            "Separation condition (contact force zero; positive factors and $\\cos\\theta$ removed)",
            String::new(),
            0,
            &sc(e),
            Some(&Expr::int(0)),
            &name,
        ));
    }
    TexContext {
        command: COMMAND.into(),
        name: tex_text(&checked.spec.name),
        description: tex_text(&checked.spec.description),
        spec: tex_text(&format!(
            "derivations/{}",
            checked
                .file
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default()
        )),
        params: checked
            .spec
            .parameters
            .iter()
            .map(|p| TexParam {
                symbol: name(&p.name),
                meaning: tex_text(&p.meaning),
                unit: tex_text(&p.unit),
            })
            .collect(),
        equations: eqs,
    }
}

/// The machine-readable record (`generated/<model>.json`).
pub fn json_record(checked: &Checked, d: &Derivation) -> serde_json::Value {
    let theta = d.coords[d.reduced].clone();
    let mut expressions = BTreeMap::new();
    for (k, v) in &d.plain {
        if *k == "reduced_inertia" || *k == "lagrangian" {
            continue;
        }
        expressions.insert(k.to_string(), from_sc(v, &theta).to_infix());
    }
    expressions.insert(
        "lagrangian".into(),
        from_sc(&d.plain["lagrangian"], &theta).to_infix(),
    );
    serde_json::json!({
        "generated_by": COMMAND,
        "note": "Generated file; do not edit by hand.",
        "model": checked.spec.name,
        "description": checked.spec.description,
        "parameters": checked.spec.parameters.iter().map(|p| serde_json::json!({"name": p.name, "meaning": p.meaning, "unit": p.unit})).collect::<Vec<_>>(),
        "coordinates": d.coords,
        "reduced": theta,
        "cyclic": d.cyclic.iter().map(|&i| d.coords[i].clone()).collect::<Vec<_>>(),
        "velocity_symbols": "theta_dot, theta_ddot in the expressions below are eliminated; dot_q / ddot_q denote velocities and accelerations in `lagrangian`",
        "expressions": expressions,
    })
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
