//! The static description of a model (`ModelInfo`'s fields) as Rust literals: its name,
//! parameters, coordinates, contacts, the system's fast phases, frictions, points, monitors.

use super::common::{COMMAND, one_line, spec_path};
use crate::derive::spec::Checked;
use crate::derive::types::{Derivation, StepError};
use serde::Serialize;

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

/// A requirement's name, meaning and the indices of the parameters its margin reads.
#[derive(Debug, Clone, Serialize)]
struct Requirement {
    name: String,
    meaning: String,
    parameters: Vec<usize>,
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
pub(super) struct StaticInfo {
    command: String,
    name: String,
    type_name: String,
    description: String,
    description_literal: String,
    spec: String,
    params: Vec<Param>,
    requirements_info: Vec<Requirement>,
    n_params: usize,
    coordinates: Vec<String>,
    n_coordinates: usize,
    /// `Some(i)` or `None`, as Rust.
    reduced: String,
    cyclic: Vec<usize>,
    /// `Some(angle)` or `None`, as Rust.
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
    /// `Some(i)` or `None`, as Rust.
    falling_point: String,
    gravity: usize,
    monitors_info: Vec<Monitor>,
    /// The bodies' names, as Rust string literals.
    bodies: Vec<String>,
    /// Why the phase has no fast path (empty when it has one).
    route_note: String,
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

/// `ModelInfo`'s fields as literals.
pub(super) fn static_info(
    checked: &Checked,
    d: &Derivation,
    phases: &[PhaseEntry],
) -> Result<StaticInfo, StepError> {
    let spec = &checked.spec;
    let np = d.params.len();
    let point_index = |name: &str| {
        (spec.points.iter().position(|p| p.name == name))
            .ok_or_else(|| StepError::Missing(format!("`{name}` is not one of the points")))
    };
    let lit = |s: &str| format!("{s:?}");
    let contacts_info = (d.contacts.iter())
        .map(|c| {
            let restitution = (spec.contacts.iter())
                .find(|s| s.name == c.name)
                .and_then(|s| s.restitution.as_ref())
                .map_or_else(|| "0".to_string(), |e| e.text());
            format!(
                "ContactInfo {{ name: {:?}, meaning: {:?}, gap: GapKind::{:?}, unit: {:?}, bilateral: {}, edge: {}, eliminates: {:?}, closed: {}, restitution: {:?} }}",
                c.name,
                c.meaning,
                c.gap_kind,
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
                "FrictionInfo {{ name: {:?}, meaning: {:?}, coefficient_index: {}, contact_index: {} }}",
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
        requirements_info: (spec.requirements.iter().zip(&d.requirements))
            .map(|(r, e)| {
                let read = e.symbols();
                Requirement {
                    name: r.name.clone(),
                    meaning: lit(&r.meaning),
                    parameters: (0..np)
                        .filter(|&i| read.contains(&d.params[i].name))
                        .collect(),
                }
            })
            .collect(),
        n_params: np,
        coordinates: d.coords.clone(),
        n_coordinates: d.coords.len(),
        reduced: option(d.reduced),
        cyclic: d.cyclic.clone(),
        end_angle: option(spec.end_angle.map(angle_literal)),
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
        falling_point: option(spec.falling_point.as_deref().map(point_index).transpose()?),
        gravity: (d.params.iter().position(|p| p.name == spec.gravity))
            .ok_or_else(|| StepError::Missing(format!("`{}` is not a parameter", spec.gravity)))?,
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
            Err(why) => lit(&one_line(&why.to_string())),
        },
    })
}

/// An optional value as Rust source.
fn option<T: std::fmt::Display>(x: Option<T>) -> String {
    x.map_or_else(|| "None".to_string(), |x| format!("Some({x})"))
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
        None => crate::derive::expr::float_literal(x),
    }
}
