//! The LaTeX writer: [`TexContext`], the derivation's steps as displayed equations broken to
//! fit the page, and spec text escaped for LaTeX.

use super::common::{COMMAND, one_line, spec_path};
use crate::derive::algebra::{from_sc, from_sc_over};
use crate::derive::dimensionless::SEPARATION_SENSITIVITY;
use crate::derive::expr::Expr;
use crate::derive::present;
use crate::derive::read::substitute;
use crate::derive::spec::Checked;
use crate::derive::types::{
    ContactRow, Derivation, Dimensionless, ProofStep, PushProof, Reduction, Shown, StepError, Steps,
};
use serde::Serialize;
use std::collections::BTreeMap;

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

/// A name as its base and subscript: after an underscore (`x_rest`), trailing digits (`m1`,
/// `theta0`) or trailing capitals after a lower-case base (`mA`, `yB`); otherwise no subscript.
fn base_and_subscript(s: &str) -> (&str, Option<&str>) {
    if let Some((base, sub)) = s.split_once('_') {
        return (base, Some(sub));
    }
    let trailing = |pred: fn(char) -> bool| s.len() - s.trim_end_matches(pred).len();
    let digits = trailing(|c| c.is_ascii_digit());
    if digits > 0 && digits < s.len() {
        return (&s[..s.len() - digits], Some(&s[s.len() - digits..]));
    }
    let capitals = trailing(|c| c.is_ascii_uppercase());
    let base = &s[..s.len() - capitals];
    if capitals > 0 && base.chars().all(|c| c.is_ascii_lowercase()) && !base.is_empty() {
        return (base, Some(&s[base.len()..]));
    }
    (s, None)
}

/// LaTeX spelling of a symbol: `m1` -> `m_{1}`, `mA` -> `m_{A}`, `ell` -> `\ell`,
/// `theta0` -> `\theta_{0}`, `dot_theta` -> `\dot{\theta}`, `dot_xA` -> `\dot{x}_{A}` (the dot
/// over the letter, the subscript after it). The reduced motion's symbols (`rc_s` for
/// `sin(theta)`, ...) are spelled over the reduced coordinate `theta`, where there is one.
pub fn latex_name(s: &str, theta: Option<&str>) -> String {
    if let Some(theta) = theta {
        let t = latex_name(theta, None);
        match s {
            "rc_s" => return format!("\\sin {t}"),
            "rc_c" => return format!("\\cos {t}"),
            "rc_thi" => return format!("{t}_{{\\mathrm{{i}}}}"),
            "rc_wi" => return format!("\\dot{{{t}}}_{{\\mathrm{{i}}}}"),
            "rc_si" => return format!("\\sin {t}_{{\\mathrm{{i}}}}"),
            "rc_ci" => return format!("\\cos {t}_{{\\mathrm{{i}}}}"),
            _ => {}
        }
    }
    for (prefix, accent) in [("ddot_", "ddot"), ("dot_", "dot")] {
        if let Some(rest) = s.strip_prefix(prefix) {
            let (base, sub) = base_and_subscript(rest);
            return with_subscript(format!("\\{accent}{{{}}}", letters(base)), sub);
        }
    }
    let (base, sub) = base_and_subscript(s);
    with_subscript(letters(base), sub)
}

/// A name's letters: a Greek letter's command (and `\ell`), a single letter as it is, a longer
/// word upright.
fn letters(base: &str) -> String {
    const GREEK: &[&str] = &[
        "alpha", "beta", "gamma", "delta", "epsilon", "theta", "kappa", "lambda", "mu", "nu", "xi",
        "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega", "ell",
    ];
    if GREEK.contains(&base) {
        format!("\\{base}")
    } else if base.chars().count() > 1 {
        format!("\\mathrm{{{base}}}")
    } else {
        base.to_string()
    }
}

fn with_subscript(base: String, sub: Option<&str>) -> String {
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

/// Context of the LaTeX template, which the JSON record carries too (`write_up`) for the Python
/// package's notebook helpers: every text and equation of the write-up is here, the template
/// adds only its layout and headings.
#[derive(Debug, Clone, Serialize)]
pub struct TexContext {
    command: String,
    name: String,
    description: String,
    spec: String,
    /// The model section's paragraph: its description and where it was derived from.
    intro: String,
    params: Vec<TexParam>,
    equations: Vec<Equation>,
    /// The dimensionless groups (`n = m_2/m_1`) with their meanings.
    groups: Vec<TexParam>,
    /// The scales and the rule of the presentation forms, in words (and that there are no
    /// results to write this way, where there are none).
    scales: String,
    /// The results without units, numbered.
    results: Vec<Equation>,
    /// Where the model carries its tangents (`Tangents::tangent_rows`), which are not
    /// printed: the paragraph that says so.
    tangents: Option<String>,
}

/// The paragraph of a model that carries its tangents.
const TANGENTS: &str = "The model also carries the partial derivatives of its equations of \
                        motion, of its contacts' and\nfrictions' rows and of its initial state in \
                        its coordinates, velocities and parameters, derived\nsymbolically from \
                        the expressions above for the forward sensitivities of the integrated \
                        route;\nthey are not printed here.";

/// Builds the LaTeX context: the derivation's steps as displayed equations.
pub fn tex_context(checked: &Checked, d: &Derivation) -> Result<TexContext, StepError> {
    let steps = d.steps.as_ref().ok_or_else(|| {
        StepError::Missing("the steps were not presented before the LaTeX".into())
    })?;
    let theta = d.theta();
    let name = |s: &str| match s
        .strip_prefix("rc_fr")
        .and_then(|j| j.parse::<usize>().ok())
        .and_then(|j| d.frictions.get(j))
    {
        Some(f) => format!("F_{{\\mathrm{{{}}}}}", tex_text(&f.named.name)),
        None => latex_name(s, theta),
    };
    let sc = |e: &Expr| from_sc_over(e, theta);
    let mut eqs = Vec::new();
    for (c, e, row) in d.contacts.iter().filter(|c| c.closed).filter_map(|c| {
        let e = c.eliminates.as_ref()?;
        let i = d.full_coords.iter().position(|q| q == e)?;
        Some((c, e, d.to_full.get(i)?))
    }) {
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
                            tex_text(&why.to_string())
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
        Some(dim) => tex_dimensionless(dim, theta, &name),
        None => (Vec::new(), String::new(), Vec::new()),
    };
    let description = tex_text(&d.description);
    let spec = tex_text(&spec_path(checked));
    Ok(TexContext {
        command: COMMAND.into(),
        name: tex_text(&d.name),
        intro: format!(
            "{description} Derived from \\texttt{{{spec}}} by Symbolica; every expression \
             below was\nproduced by the derivation tool, none was typed by hand."
        ),
        description,
        spec,
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
        tangents: d.tangents.as_ref().map(|_| TANGENTS.to_string()),
    })
}

/// A gradient entry's `\frac{\partial g}{\partial q} = ` counts this many characters of width.
const GRADIENT_HEAD: usize = 6;

/// The constraint rows of the contacts a phase does not hold closed: each gap, its gradient
/// in the phase's coordinates and its bias, with what the runtime solves while a set of them is
/// closed.
fn constraint_equations(d: &Derivation, name: &dyn Fn(&str) -> String, eqs: &mut Vec<Equation>) {
    let theta = d.theta();
    let sc = |e: &Expr| from_sc_over(e, theta);
    let open: Vec<(&ContactRow, &Expr)> = (d.contacts.iter().zip(&d.restitutions))
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
                tex_text(c.gap_kind.unit()),
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
    let part = |v: Vec<Expr>| crate::derive::expr::product(v).to_latex(name);
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
    theta: Option<&str>,
    name: &dyn Fn(&str) -> String,
) -> (Vec<TexParam>, String, Vec<Equation>) {
    let groups = (dim.groups.iter())
        .map(|g| TexParam {
            symbol: format!("{} = {}", name(&g.name), g.definition.to_latex(name)),
            meaning: tex_text(&g.meaning),
            unit: format!("solved for ${}$", name(&g.solves)),
        })
        .collect();
    // The results are the fast path's, which keeps the reduced coordinate: a system without
    // one has none to write.
    let Some(theta) = theta else {
        let scales = format!(
            "Time is in units of $T = {}$ and forces in units of ${}$.",
            dim.time.to_latex(name),
            dim.force.to_latex(name),
        );
        return (groups, scales + NO_RESULTS, Vec::new());
    };
    let mut scales = format!(
        "Time is in units of $T = {}$ and forces in units of ${}$. Each result below is written \
         in the groups and ${}$ alone; its form was chosen by the derivation tool among \
         candidates by {}.",
        dim.time.to_latex(name),
        dim.force.to_latex(name),
        name(theta),
        tex_text(present::RULE)
    );
    let mut results = Vec::new();
    for (i, r) in dim.results.iter().chain(&dim.sensitivities).enumerate() {
        let form = from_sc(&r.form, theta);
        let quantity = match r.key.as_str() {
            "theta_dot_sq" => format!("{}^2", name(&format!("dot_{theta}"))),
            "theta_ddot" => name(&format!("ddot_{theta}")),
            key => format!("F_{{\\mathrm{{{}}}}}", tex_text(key)),
        };
        let derivative = r.key.strip_prefix(SEPARATION_SENSITIVITY);
        let (lhs, width, rhs) = match (&r.unit, derivative) {
            (_, Some(group)) => (
                format!(
                    "\\frac{{\\mathrm{{d}}{}_{{\\mathrm{{sep}}}}}}{{\\mathrm{{d}}{}}} = ",
                    name(theta),
                    name(group)
                ),
                6,
                None,
            ),
            (Some(u), None) => (
                format!("\\frac{{{quantity}}}{{{}}} = ", inline_unit(u, name)),
                6,
                None,
            ),
            (None, None) => (String::new(), 0, Some(Expr::int(0))),
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
    if results.is_empty() {
        scales.push_str(NO_RESULTS);
    }
    (groups, scales, results)
}

/// What the scales' paragraph adds where there are no results to write without units.
const NO_RESULTS: &str = " The integrated route has no closed-form results to write this way.";

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
) -> Result<(), StepError> {
    // Every result the reduction derived is shown in its presented form.
    let shown = |key: &str| -> Result<Option<&Shown>, StepError> {
        match (r.plain.get(key), steps.reduced.get(key)) {
            (None, _) => Ok(None),
            (Some(_), Some(s)) => Ok(Some(s)),
            (Some(_), None) => Err(StepError::Missing(format!(
                "the result `{key}` was not presented"
            ))),
        }
    };
    let theta = d
        .theta()
        .ok_or_else(|| StepError::Missing("the fast path's reduced coordinate".into()))?;
    let sc = |e: &Expr| from_sc(e, theta);
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
    push_proofs(d, r, theta, name, eqs);
    Ok(())
}

/// The proofs that the first contact pushes at release and that another closed contact's push
/// stays positive over the phase ([`positivity`](crate::derive::positivity)): the force
/// polynomial, the quadratic below it and why that quadratic is positive.
fn push_proofs(
    d: &Derivation,
    r: &Reduction,
    theta: &str,
    name: &dyn Fn(&str) -> String,
    eqs: &mut Vec<Equation>,
) {
    let sin_start = Expr::Fun("sin".into(), vec![Expr::sym(&format!("{theta}_i"))]);
    let start = BTreeMap::from([("rc_si".to_string(), sin_start.clone())]);
    let over_angle = |e: &Expr| from_sc(&substitute(e, &start), theta);
    let unchecked = "the per-point solver does not check it point by point";
    if let (Some(first), Some(release)) = (d.contacts.first(), &r.release_proof) {
        // R in sin(theta_i): written over `rc_s`, shown over the start's sine.
        let s_is_start = BTreeMap::from([("rc_s".to_string(), sin_start.clone())]);
        let factor = &release.polynomial;
        let power = match release.power {
            0 => String::new(),
            1 => "\\sin\\theta_i\\,".into(),
            m => format!("\\sin^{{{m}}}\\theta_i\\,"),
        };
        eqs.push(display(
            &format!(
                "Force \\texttt{{{}}} at release: its polynomial at $\\sin\\theta = \\sin\\theta_i$ \
                 is ${power} R$, with",
                tex_text(&first.name)
            ),
            "R = ".into(),
            4,
            &over_angle(&substitute(factor, &s_is_start)),
            None,
            name,
        ));
        let below = "A quadratic below $R$ for $0 \\le \\sin\\theta_i \\le 1$, $R \\ge a + b \\sin\\theta_i + c \\sin^2\\theta_i$ \
                     ($\\cos\\theta_i$ at most 1 in a negative term, $\\sin^k\\theta_i \\le \\sin^2\\theta_i$ for \
                     $k > 2$)";
        let outcome = format!("so it pushes at release for every parameter ({unchecked})");
        quadratic_proof(&release.proof, below, "\\sin\\theta_i", &outcome, name, eqs);
    }
    let proven = (d.contacts.iter())
        .zip(&r.force_polynomials)
        .zip(&r.push_proofs);
    for ((c, poly), proof) in proven {
        let (Some(poly), Some(proof)) = (poly, proof) else {
            continue;
        };
        let contact = tex_text(&c.name);
        eqs.push(display(
            &format!(
                "Force \\texttt{{{contact}}} as a polynomial $P$ in $\\sin\\theta$ (positive \
                 factors removed; its sign the force's)"
            ),
            "P = ".into(),
            4,
            &over_angle(&poly.polynomial),
            None,
            name,
        ));
        let below = "A quadratic below it, $P \\ge a + b \\sin\\theta + c \\sin^2\\theta$ for \
                     $0 \\le \\sin\\theta \\le \\sin\\theta_i \\le 1$ ($\\sin\\theta_i$ and \
                     $\\cos\\theta_i$ at most 1 in a negative term, $\\sin\\theta_i$ at least \
                     $\\sin\\theta$ in a positive one, $\\sin^k\\theta \\le \\sin^2\\theta$ for \
                     $k > 2$)";
        let outcome =
            format!("so the push stays positive over the phase for every parameter ({unchecked})");
        quadratic_proof(proof, below, "\\sin\\theta", &outcome, name, eqs);
    }
}

/// A [`PushProof`]'s quadratic `a + b x + c x^2` (`x` printed as `x`) under the title `below`,
/// and why it is positive, ending with `outcome`.
fn quadratic_proof(
    proof: &PushProof,
    below: &str,
    x: &str,
    outcome: &str,
    name: &dyn Fn(&str) -> String,
    eqs: &mut Vec<Equation>,
) {
    let [a, b, c] = &proof.bound;
    for (title, lhs, e) in [
        (below, "a = ", a),
        ("Its coefficient $b$", "b = ", b),
        ("Its coefficient $c$", "c = ", c),
    ] {
        eqs.push(display(title, lhs.into(), 4, e, None, name));
    }
    let (title, lhs, e) = match &proof.step {
        ProofStep::Signs => {
            eqs.push(Equation {
                title: format!("Its coefficients' signs, term by term, {outcome}"),
                env: "equation*",
                latex: "a > 0, \\quad b \\ge 0, \\quad c \\ge 0".into(),
                tag: None,
                small: false,
            });
            return;
        }
        ProofStep::Ends(e) => (
            format!(
                "The quadratic is concave or straight, so least at an end: $a > 0$ term by term, \
                 and so is its value at ${x} = 1$, {outcome}"
            ),
            "a + b + c = ",
            e,
        ),
        ProofStep::Discriminant(e) => (
            format!(
                "The quadratic has no real root: $a > 0$ and $4ac - b^2 > 0$ term by term, \
                 {outcome}"
            ),
            "4 a c - b^2 = ",
            e,
        ),
    };
    let mut eq = display(&title, lhs.into(), 8, e, None, name);
    eq.latex.push_str(" > 0");
    eqs.push(eq);
}
