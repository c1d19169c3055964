//! The JSON writer: the machine-readable record of a model (`generated/<model>.json`).

use super::common::{COMMAND, spec_path};
use super::tex::TexContext;
use crate::derive::algebra::from_sc_over;
use crate::derive::expr::Expr;
use crate::derive::present;
use crate::derive::spec::Checked;
use crate::derive::types::{Derivation, Dimensionless};
use std::collections::BTreeMap;

/// The machine-readable record (`generated/<model>.json`), with `write_up`, the context of the
/// LaTeX write-up (`generated/<model>.tex`) it is rendered from.
pub fn json_record(
    checked: &Checked,
    d: &Derivation,
    write_up: &TexContext,
) -> Result<serde_json::Value, serde_json::Error> {
    let theta = d.theta();
    let infix = |e: &Expr| from_sc_over(e, theta).to_infix();
    let mut expressions = BTreeMap::new();
    let (route, reason) = match &d.reduction {
        Ok(r) => {
            for (k, v) in &r.plain {
                if k == "reduced_inertia" {
                    continue;
                }
                expressions.insert(k.to_string(), from_sc_over(v, theta).to_infix());
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
        Err(why) => ("integrated", why.to_string()),
    };
    expressions.insert("lagrangian".into(), infix(&d.lagrangian));
    let contacts: Vec<serde_json::Value> = (d.contacts.iter().zip(&d.restitutions))
        .map(|(c, e)| {
            let mut v = serde_json::json!({
                "name": c.name,
                "meaning": c.meaning,
                "gap_unit": c.gap_kind.unit(),
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
        record["dimensionless"] = dimensionless_record(dim, theta);
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
    record["write_up"] = serde_json::to_value(write_up)?;
    Ok(record)
}

/// The JSON record's `dimensionless` block: groups, scales, and each result's form, unit and
/// (where the spec gives one) the paper's equation number.
fn dimensionless_record(dim: &Dimensionless, theta: Option<&str>) -> serde_json::Value {
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
        let form = from_sc_over(&r.form, theta).to_infix();
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
