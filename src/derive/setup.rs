//! Stage 2 of the derivation: a phase's view of the spec. Which coordinates move, and what
//! the contacts it holds closed tie: each closed contact's `gap = 0` solved for the coordinate
//! it eliminates, in the spec's order, every tie over the phase's own coordinates only.

use super::algebra::{free_of, to_expr};
use super::cas::{self, A};
use super::expr::Expr;
use super::read::Parsed;
use super::spec::Spec;
use super::types::{DeriveError, PhasePlan, at, entry, key};

/// The total time derivative along a phase's state.
#[derive(Debug, Clone)]
pub struct Kin {
    /// The phase's coordinates (their rates are `dot_<q>`, accelerations `ddot_<q>`).
    pub coords: Vec<String>,
}

impl Kin {
    /// `d f / dt` with `f` over `q`, `dot_q` (and constants).
    pub fn dt(&self, f: &A) -> A {
        let mut out = cas::num(0);
        for c in &self.coords {
            out = out
                + cas::d(f, c) * cas::var(&format!("dot_{c}"))
                + cas::d(f, &format!("dot_{c}")) * cas::var(&format!("ddot_{c}"));
        }
        cas::expand(&out)
    }
}

/// A phase's view of the spec: which coordinates move and what the closed contacts tie.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The phase.
    pub plan: PhasePlan,
    /// Its coordinates: the spec's without the eliminated ones.
    pub coords: Vec<String>,
    /// Index of the reduced coordinate among them (none where the spec names none).
    pub reduced: Option<usize>,
    /// The reduced coordinate's name.
    pub theta: Option<String>,
    /// Each eliminated coordinate with its value over the phase's coordinates.
    pub ties: Vec<(String, A)>,
    /// The time derivative along the phase's state.
    pub kin: Kin,
}

impl Setup {
    /// An expression of the spec with the ties substituted.
    pub fn at(&self, e: &Expr) -> A {
        self.tied(&cas::atom(e))
    }

    /// An atom with the ties substituted.
    pub fn tied(&self, a: &A) -> A {
        let mut out = a.clone();
        for (name, value) in &self.ties {
            out = cas::subs_var(&out, name, value);
        }
        out
    }
}

/// The ties of the contacts `closed` (indices into the spec's contacts): each gap, with the
/// ties before it substituted, solved for its coordinate (it must be linear in it, with a
/// coefficient that is not zero), and the new tie substituted into the earlier ones.
pub fn ties(
    spec: &Spec,
    parsed: &Parsed,
    closed: &[usize],
) -> Result<Vec<(String, A)>, DeriveError> {
    let mut ties: Vec<(String, A)> = Vec::new();
    for &j in closed {
        let c = spec
            .contacts
            .get(j)
            .ok_or_else(|| at(&[key("contacts")], format!("no contact {j}")))?;
        let path = entry("contacts", j, "eliminates");
        let e = c.eliminates.clone().ok_or_else(|| {
            at(
                &path,
                format!("contact `{}` eliminates no coordinate", c.name),
            )
        })?;
        let mut gap = cas::atom(&parsed.contacts[j].gap);
        for (name, value) in &ties {
            gap = cas::subs_var(&gap, name, value);
        }
        let coef = cas::expand(&cas::d(&gap, &e));
        if cas::is_zero(&coef) || !free_of(&coef, &[e.as_str()]) {
            let shown = to_expr(&coef, "gap coefficient")?.to_infix();
            return Err(at(
                &entry("contacts", j, "gap"),
                format!(
                    "contact `{}`: the gap must be linear in `{e}` with a coefficient that is \
                     not zero, so that `gap = 0` can be solved for it (with the contacts before \
                     it closed); d(gap)/d{e} = {shown}",
                    c.name
                ),
            ));
        }
        let value = cas::together(&(cas::var(&e) - gap / coef));
        if !free_of(&value, &[e.as_str()]) {
            return Err(at(
                &entry("contacts", j, "gap"),
                format!("contact `{}`: `gap = 0` cannot be solved for `{e}`", c.name),
            ));
        }
        let value = cas::expand(&value);
        for tie in ties.iter_mut() {
            tie.1 = cas::expand(&cas::subs_var(&tie.1, &e, &value));
        }
        ties.push((e, value));
    }
    Ok(ties)
}

/// Stage 2: the coordinates of a phase and the ties of the contacts it holds closed.
pub fn setup(spec: &Spec, parsed: &Parsed, plan: &PhasePlan) -> Result<Setup, DeriveError> {
    let ties = ties(spec, parsed, &plan.closed)?;
    let coords: Vec<String> = (spec.coordinates.iter())
        .map(|c| c.name.clone())
        .filter(|c| ties.iter().all(|(e, _)| e != c))
        .collect();
    let reduced = match &spec.reduced {
        Some(name) => Some(coords.iter().position(|c| c == name).ok_or_else(|| {
            at(
                &[key("reduced")],
                format!("`{name}` is not a coordinate of the phase"),
            )
        })?),
        None => None,
    };
    Ok(Setup {
        plan: plan.clone(),
        theta: reduced.map(|i| coords[i].clone()),
        kin: Kin {
            coords: coords.clone(),
        },
        coords,
        reduced,
        ties,
    })
}
