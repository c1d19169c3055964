//! The doc comment of each generated method: what it computes and its formula from the
//! derivation, in the spec's symbols (an expression too long for a comment is left to the
//! model's LaTeX write-up, `generated/<model>.tex`).

use crate::derive::algebra::from_sc_over;
use crate::derive::expr::Expr;
use crate::derive::spec::Checked;
use crate::derive::types::{Derivation, Reduction};
use std::collections::BTreeMap;

/// Characters of an expression that a doc comment prints; a longer one is named, not printed.
const LONGEST: usize = 160;

/// Each method's doc lines, by the method's name in `templates/model.rs.tera`.
pub type Docs = BTreeMap<&'static str, Vec<String>>;

/// How a doc comment prints the derivation's expressions of one phase.
struct Printer<'a> {
    d: &'a Derivation,
}

impl Printer<'_> {
    /// `name = e` in backticks as a list item, or a pointer to the LaTeX write-up when `e` is too long.
    fn eq(&self, name: &str, e: &Expr) -> String {
        let text = from_sc_over(e, self.d.theta()).to_infix();
        match text.len() <= LONGEST {
            true => format!("- `{name} = {text}`"),
            false => format!(
                "- `{name}`: {} characters, written out in `generated/{}.tex`",
                text.len(),
                self.d.name
            ),
        }
    }

    /// `name_i = e_i` for each pair, one line each; `none` when there are none.
    fn each<'e>(
        &self,
        pairs: impl IntoIterator<Item = (String, &'e Expr)>,
        none: &str,
    ) -> Vec<String> {
        let lines: Vec<String> = pairs.into_iter().map(|(n, e)| self.eq(&n, e)).collect();
        match lines.is_empty() {
            true => vec![none.to_string()],
            false => lines,
        }
    }
}

/// A doc comment: a one-line summary, a blank line, then the details.
fn doc(summary: &str, details: Vec<String>) -> Vec<String> {
    let mut lines = vec![summary.to_string()];
    if !details.is_empty() {
        lines.push(String::new());
        lines.extend(details);
    }
    lines
}

/// The doc comments of the methods of `Model` for phase `d`.
pub(super) fn model_docs(checked: &Checked, d: &Derivation) -> Docs {
    let spec = &checked.spec;
    let p = Printer { d };
    let contacts = || d.contacts.iter().map(|c| c.name.clone());
    let mut docs = Docs::new();
    let requirements = (spec.requirements.iter().map(|r| r.name.clone())).zip(&d.requirements);
    docs.insert(
        "requirements",
        doc(
            "The requirements' margins over the parameters, each `>= 0` where it holds.",
            p.each(requirements, "The spec states no requirement."),
        ),
    );
    docs.insert(
        "restitutions",
        doc(
            "Each contact's coefficient of restitution over the parameters.",
            p.each(contacts().zip(&d.restitutions), "No contact."),
        ),
    );
    let names: Vec<&str> = d.params.iter().map(|p| p.name.as_str()).collect();
    docs.insert(
        "prepare",
        doc(
            "The constants `k`: the parameters, then the constants derived from them.",
            vec![format!(
                "`k[..{}]` holds the parameters `{}`; each later slot's definition is the \
                 comment above the line that fills it.",
                names.len(),
                names.join(", ")
            )],
        ),
    );
    let initial = (d.coords.iter())
        .zip(&d.initial)
        .flat_map(|(c, [x, v])| [(c.clone(), x), (format!("dot_{c}"), v)]);
    docs.insert(
        "initial_state",
        doc(
            "The state at release, over the parameters.",
            p.each(initial, ""),
        ),
    );
    let points = (spec.points.iter())
        .zip(&d.point_pos)
        .flat_map(|(pt, [x, y])| [(format!("{}_x", pt.name), x), (format!("{}_y", pt.name), y)]);
    docs.insert(
        "points",
        doc(
            "Each point's position over the state (`pos`), and its time derivative (`vel`).",
            p.each(points, "No point."),
        ),
    );
    docs.insert(
        "energy",
        doc(
            "The total energy `E = T + V`.",
            vec![p.eq("T", &d.kinetic), p.eq("V", &d.potential)],
        ),
    );
    let momenta = (d.cyclic.iter().map(|&i| format!("p_{}", d.coords[i]))).zip(&d.momenta);
    docs.insert(
        "momenta",
        doc(
            "The momenta `p_c = dL/d(dot_c)` of the cyclic coordinates, conserved.",
            p.each(momenta, "No cyclic coordinate."),
        ),
    );
    docs.insert(
        "equations",
        doc(
            "The equations of motion `M(q) qdd = F(q, qd)` (`mass` is `M` row by row, `rhs` is `F`).",
            vec![
                "They are the Euler-Lagrange equations `d/dt dL/d(dot_q) - dL/dq = 0` of".into(),
                p.eq("L = T - V", &d.lagrangian),
            ],
        ),
    );
    let forces = (d.contacts.iter()).filter_map(|c| Some((c.name.clone(), c.force.as_ref()?)));
    docs.insert(
        "forces_full",
        doc(
            "Each contact's force: in closed form for a contact this phase holds closed, zero for the others (their forces are solved by the runtime).",
            p.each(forces, "No contact is closed in this phase."),
        ),
    );
    let gaps = (d.contacts.iter())
        .filter(|c| !c.closed)
        .map(|c| (c.name.clone(), &c.gap));
    docs.insert(
        "gaps",
        doc(
            "Each contact's gap `g(q)`, `>= 0` while apart (zero for a contact held closed).",
            p.each(gaps, "No open contact."),
        ),
    );
    docs.insert(
        "constraints",
        doc(
            "Each contact's constraint row: `jac` holds `J = dg/dq`, `bias` holds `dJ/dt qd`, so that `g'' = J qdd + bias`.",
            Vec::new(),
        ),
    );
    let edges = (d.contacts.iter()).filter_map(|c| Some((c.name.clone(), c.edge.as_ref()?)));
    docs.insert(
        "edges",
        doc(
            "Each contact's edge margin, `>= 0` while the contact point is on the edge (infinite without one).",
            p.each(edges, "No contact has an edge."),
        ),
    );
    let slips = (d.frictions.iter()).map(|f| (format!("v_{}", f.named.name), &f.slip));
    docs.insert(
        "friction",
        doc(
            "Each friction's slip velocity `v = J(q) qd`: `jac` holds `J`, `bias` holds `dJ/dt qd`.",
            p.each(slips, "No friction."),
        ),
    );
    let monitors = (d.monitors.iter().map(|m| m.name.clone())).zip(&d.monitors_full);
    docs.insert(
        "monitors_full",
        doc(
            "The monitors over the state and the contacts' forces `rc_f<i>`.",
            p.each(monitors, "No monitor."),
        ),
    );
    let full = (d.full_coords.iter())
        .zip(&d.to_full)
        .flat_map(|(c, [x, v])| [(c.clone(), x), (format!("dot_{c}"), v)]);
    docs.insert(
        "to_full",
        doc(
            "The system's state (its general model's) that this phase's state stands for.",
            p.each(full, ""),
        ),
    );
    docs.insert(
        "drawing",
        doc(
            "Each body's pose `[x, y, angle]` (centre of mass and orientation) over the state, and the shapes' sizes over the parameters.",
            Vec::new(),
        ),
    );
    docs
}

/// The doc comments of the methods of `Reduction` for phase `d` with fast path `r`.
pub(super) fn reduction_docs(d: &Derivation, r: &Reduction) -> Docs {
    let p = Printer { d };
    let plain = |key: &str| r.plain.get(key);
    let one = |key: &str, name: &str| plain(key).map(|e| p.eq(name, e)).into_iter().collect();
    let mut docs = Docs::new();
    let mut motion: Vec<String> = one("theta_dot_sq", "theta_dot^2");
    motion.extend(one("theta_ddot", "theta_ddot"));
    docs.insert(
        "reduced",
        doc(
            "The reduced motion at `theta = theta_i - delta`: `theta_dot^2` from the energy integral, and `theta_ddot`.",
            motion,
        ),
    );
    docs.insert(
        "theta_dot_sq_sc",
        doc(
            "`theta_dot^2` over `sin(theta)`, `cos(theta)` and their drops from the start (the per-point solver's integrand).",
            one("theta_dot_sq", "theta_dot^2"),
        ),
    );
    let forces = (d.contacts.iter()).filter_map(|c| Some((c.name.clone(), plain(&c.name)?)));
    docs.insert(
        "forces",
        doc(
            "Each contact's force on the reduced motion (zero for a contact open in the phase).",
            p.each(forces, "No contact is closed in this phase."),
        ),
    );
    docs.insert(
        "force_polynomial",
        doc(
            "The coefficients, constant term first, of a contact's force zero as a polynomial in `sin(theta)`, where it is one.",
            one("separation_condition", "separation condition (= 0)"),
        ),
    );
    docs.insert(
        "prepare_lean",
        doc(
            "The constants of `prepare` that the per-point solver reads, and only those.",
            Vec::new(),
        ),
    );
    docs.insert(
        "fall_polynomial",
        doc(
            "The coefficients, constant term first, of the fall polynomial `P(s) = (sin(theta_i) - s) / theta_dot^2` in `s = sin(theta)`.",
            Vec::new(),
        ),
    );
    docs.insert(
        "separation_partials",
        doc(
            "`[dF/dtheta, dF/dp_1, ...]` at `sin(theta)`, `cos(theta)`, of the separation condition `F = 0` divided by the coefficient that leaves the parameters in the fewest terms (the implicit-function theorem's `d theta_sep/dp = -F_p / F_theta` is the same for any factor).",
            Vec::new(),
        ),
    );
    docs.insert(
        "theta_dot_sq_partials",
        doc(
            "`d(theta_dot^2)/dp` for each parameter at a fixed angle given by `sin(theta)`, `cos(theta)`.",
            Vec::new(),
        ),
    );
    docs.insert(
        "start_partials",
        doc("`d(sin theta_i)/dp` for each parameter.", Vec::new()),
    );
    docs.insert(
        "fall_partials",
        doc(
            "`dP_j/dp` of the fall polynomial's coefficients, parameter by parameter (`j` fastest).",
            Vec::new(),
        ),
    );
    docs.insert(
        "full_state",
        doc(
            "The full state on the reduced motion: `theta = theta_i - delta`, its rate, and the cyclic coordinates from their conserved momenta.",
            Vec::new(),
        ),
    );
    docs
}

/// The doc comments of the general model `d`'s `Tangents::tangent_rows` and
/// `Tangents::initial_tangents`.
pub(super) fn tangents_docs(d: &Derivation) -> Docs {
    let (n, np) = (d.coords.len(), d.params.len());
    let (m, nf) = (d.contacts.len(), d.frictions.len());
    let mut docs = Docs::new();
    docs.insert(
        "tangents",
        doc(
            "The partial derivatives over `[q, qd, p]` of the residual `M qdd - F - J^T forces - T^T fr`, the contacts' normal accelerations, the frictions' slip accelerations, the gaps, the edge margins and the slip velocities at the point `at` (its accelerations and forces held fixed), row-major.",
            vec![format!(
                "{} rows ({n} + 3 x {m} + 2 x {nf}) by {} columns (2 x {n} + {np}), differentiated symbolically from the expressions of `equations`, `constraints`, `friction`, `gaps` and `edges`.",
                n + 3 * m + 2 * nf,
                2 * n + np,
            )],
        ),
    );
    docs.insert(
        "initial_tangents",
        doc(
            "`d(initial state)/dp`: the rows `d q_0/dp`, then `d qd_0/dp`, by the parameters.",
            Vec::new(),
        ),
    );
    docs
}
