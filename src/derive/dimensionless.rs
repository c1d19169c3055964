//! Results without units: a phase's closed-form results (energy integral, angular
//! acceleration, reaction forces, separation condition) written in the spec's dimensionless
//! groups and `theta` only, each in units of the spec's scales, in its presentation form.
//!
//! Each group `name = c p1^e1 p2^e2 ...` is solved for the parameter the spec module names
//! ([`solved_parameters`]): `n = m2/m1` gives `m2 = n m1`. A result is multiplied by its scale
//! (`theta_dot^2` by `T^2`, a force by `1/F`), the solved parameters are substituted, and what
//! Symbolica's `together` leaves must depend on the groups, the dimensionless parameters (unit
//! `rad` or `1`) and `theta` alone: otherwise the groups and scales do not make the result
//! dimensionless, which is an error placed at the spec's `dimensionless` field. A free phase
//! (after the contact) also has the group `omega_0 = theta_dot_0 T` for its start rate.

use super::algebra::{positive, strip_positive_factors, to_sc_expr};
use super::cas::{self, A};
use super::expr::Expr;
use super::present::{Presenter, Shape};
use super::spec::{Spec, Text, solved_parameters};
use super::types::{Derivation, DeriveError, FieldStep};
pub use super::types::{Dimensionless, Group, Scaled};

/// The group of a free phase's start rate.
pub const START_RATE_GROUP: &str = "omega_0";

fn at(message: String) -> DeriveError {
    DeriveError {
        field: vec![FieldStep::Key("dimensionless".into())],
        message,
    }
}

fn parse(t: &Text, what: &str) -> Result<Expr, DeriveError> {
    Expr::parse(&t.text()).map_err(|e| at(format!("{what}: {}", e.message)))
}

/// A parameter and its value over the groups and the parameters left.
type Solved = (String, A);

/// The phase's groups with each solved parameter's value over the groups and the remaining
/// parameters (earlier values substituted into later ones).
fn groups(
    spec: &Spec,
    d: &Derivation,
    time: &Expr,
) -> Result<(Vec<Group>, Vec<Solved>), DeriveError> {
    let Some(dim) = &spec.dimensionless else {
        return Ok((Vec::new(), Vec::new()));
    };
    let solved = solved_parameters(&dim.groups).map_err(|i| {
        at(format!(
            "group `{}` cannot be solved for a parameter",
            dim.groups[i].name
        ))
    })?;
    let mut out = Vec::new();
    for (g, p) in dim.groups.iter().zip(solved) {
        out.push(Group {
            name: g.name.clone(),
            definition: parse(&g.expr, &g.name)?,
            meaning: g.meaning.clone(),
            solves: p,
        });
    }
    let rate = d.theta().map(|theta| format!("{theta}_dot_0"));
    if let Some(rate) = rate
        && d.plan.start_params
        && d.params.iter().any(|p| p.name == rate)
    {
        let taken = out.iter().any(|g| g.name == START_RATE_GROUP)
            || d.params.iter().any(|p| p.name == START_RATE_GROUP);
        if taken {
            return Err(at(format!(
                "`{START_RATE_GROUP}` names the free phase's start rate in units of the time \
                 scale; rename the spec's `{START_RATE_GROUP}`"
            )));
        }
        out.push(Group {
            name: START_RATE_GROUP.into(),
            definition: Expr::Mul(vec![Expr::sym(&rate), time.clone()]),
            meaning: format!(
                "the start rate `{rate}` of the phase in units of the inverse time scale"
            ),
            solves: rate,
        });
    }
    let mut values: Vec<Solved> = Vec::new();
    for g in &out {
        let mut v =
            cas::together(&(cas::var(&g.name) * cas::var(&g.solves) / cas::atom(&g.definition)));
        for (p, earlier) in &values {
            v = cas::subs_var(&v, p, earlier);
        }
        values.push((g.solves.clone(), cas::together(&v)));
    }
    Ok((out, values))
}

/// The results of a phase without units, if its spec gives groups and scales.
pub fn derive(spec: &Spec, d: &Derivation) -> Result<Option<Dimensionless>, DeriveError> {
    let Some(dim) = &spec.dimensionless else {
        return Ok(None);
    };
    let time = parse(&dim.scales.time, "time scale")?;
    let force = parse(&dim.scales.force, "force scale")?;
    let (groups, values) = groups(spec, d, &time)?;
    let dimensionless_params: Vec<String> = (d.params.iter())
        .filter(|p| matches!(p.unit.as_str(), "rad" | "1"))
        .map(|p| p.name.clone())
        .collect();
    let mut order: Vec<String> = groups.iter().map(|g| g.name.clone()).collect();
    order.extend(dimensionless_params.iter().cloned());
    order.extend(d.params.iter().map(|p| p.name.clone()));
    let mut results = Vec::new();
    let Ok(r) = &d.reduction else {
        return Ok(Some(Dimensionless {
            groups,
            time,
            force,
            results,
            sensitivities: Vec::new(),
        }));
    };
    let presenter = Presenter::new(&order);
    let mut allowed: Vec<String> = groups.iter().map(|g| g.name.clone()).collect();
    allowed.extend(dimensionless_params);
    allowed.extend(["rc_s".to_string(), "rc_c".to_string()]);
    let mut positive_symbols: Vec<String> = (d.params.iter())
        .filter(|p| p.positive)
        .map(|p| p.name.clone())
        .collect();
    positive_symbols.extend(
        (groups.iter())
            .filter(|g| positive(&g.definition, &positive_symbols))
            .map(|g| g.name.clone())
            .collect::<Vec<_>>(),
    );
    let substitute = |a: &A| -> A {
        let mut v = a.clone();
        for (p, value) in &values {
            v = cas::subs_var(&v, p, value);
        }
        cas::together(&v)
    };
    let rate_unit = presenter
        .present(
            &cas::together(&(cas::num(1) / cas::atom(&time) / cas::atom(&time))),
            Shape::Fraction,
        )
        .map_err(|m| at(format!("the unit of rates: {m}")))?
        .expr;
    let theta = (d.theta())
        .ok_or_else(|| at("the fast path has no reduced coordinate".into()))?
        .to_string();
    let paper = |key: &str| dim.paper.get(key).cloned();
    // (key, meaning, scale factor, unit, shape)
    let mut wanted: Vec<(String, String, A, Option<Expr>, Shape)> = Vec::new();
    let t2 = cas::atom(&time) * cas::atom(&time);
    wanted.push((
        "theta_dot_sq".into(),
        "energy integral".to_string(),
        t2.clone(),
        Some(rate_unit.clone()),
        Shape::Fraction,
    ));
    wanted.push((
        "theta_ddot".into(),
        "angular acceleration".to_string(),
        t2,
        Some(rate_unit),
        Shape::Fraction,
    ));
    // Forces in units of the force scale (a torque, conjugate to an angle, has another unit
    // and is not written here).
    for c in d
        .contacts
        .iter()
        .filter(|c| c.closed && c.force_unit == "N")
    {
        wanted.push((
            c.name.clone(),
            format!("force {}: {}", c.name, c.meaning),
            cas::num(1) / cas::atom(&force),
            Some(force.clone()),
            Shape::Fraction,
        ));
    }
    wanted.push((
        "separation_condition".into(),
        "separation condition, up to a constant factor".into(),
        cas::num(1),
        None,
        Shape::Polynomial,
    ));
    let mut condition_value = None;
    for (key, meaning, scale, unit, shape) in wanted {
        let Some(plain) = r.plain.get(&key) else {
            continue;
        };
        let raw = cas::atom(&to_sc_expr(plain, &theta));
        let mut value = substitute(&(raw * scale));
        if shape == Shape::Polynomial {
            value = condition(&value, &positive_symbols)?;
            condition_value = Some(value.clone());
        }
        let e = cas::expr(&value).map_err(|m| at(m.to_string()))?;
        if let Some(s) = e.symbols().into_iter().find(|s| !allowed.contains(s)) {
            return Err(at(format!(
                "`{key}` of model `{}` still depends on `{s}` when written in the groups ({}) \
                 and in units of the scales: the groups and scales do not make it dimensionless",
                d.name,
                groups
                    .iter()
                    .map(|g| g.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let form = presenter
            .present(&value, shape)
            .map_err(|m| at(format!("`{key}` of model `{}`: {m}", d.name)))?;
        results.push(Scaled {
            paper: paper(&key),
            key,
            meaning,
            unit,
            form: form.expr,
            operations: form.operations,
        });
    }
    let sensitivities = match &condition_value {
        Some(condition) => separation_sensitivities(condition, &groups, &presenter, d)?,
        None => Vec::new(),
    };
    Ok(Some(Dimensionless {
        groups,
        time,
        force,
        results,
        sensitivities,
    }))
}

/// The prefix of the keys of `d theta_sep / d <group>`.
pub const SEPARATION_SENSITIVITY: &str = "dtheta_sep_d";

/// `d theta_sep / d g` for every group `g` the separation condition `F(sin, cos; groups) = 0`
/// depends on, by the implicit-function theorem: `-F_g / F_theta` with
/// `F_theta = cos F_sin - sin F_cos`, over the groups and the separation angle's sine and cosine.
fn separation_sensitivities(
    condition: &A,
    groups: &[Group],
    presenter: &Presenter,
    d: &Derivation,
) -> Result<Vec<Scaled>, DeriveError> {
    let f_theta =
        cas::d(condition, "rc_s") * cas::var("rc_c") - cas::d(condition, "rc_c") * cas::var("rc_s");
    let mut out = Vec::new();
    for g in groups {
        let f_g = cas::d(condition, &g.name);
        if cas::is_zero(&f_g) {
            continue;
        }
        let value = cas::together(&(cas::num(-1) * f_g / f_theta.clone()));
        let key = format!("{SEPARATION_SENSITIVITY}{}", g.name);
        let form = presenter
            .present(&value, Shape::Fraction)
            .map_err(|m| at(format!("`{key}` of model `{}`: {m}", d.name)))?;
        out.push(Scaled {
            key,
            meaning: format!(
                "how the separation angle moves with {}, at the separation angle (the \
                 implicit-function theorem on the separation condition)",
                g.name
            ),
            unit: None,
            form: form.expr,
            operations: form.operations,
            paper: None,
        });
    }
    Ok(out)
}

/// A condition `value = 0` as a polynomial: its numerator with positive theta-free factors
/// removed (the denominator must be positive).
fn condition(value: &A, positive_symbols: &[String]) -> Result<A, DeriveError> {
    let e = cas::expr(value).map_err(|m| at(m.to_string()))?;
    let (num, den) = e.num_den();
    let den = super::expr::product(den);
    if !positive(&den, positive_symbols) {
        return Err(at(format!(
            "the separation condition's denominator `{}` is not positive",
            den.to_infix()
        )));
    }
    strip_positive_factors(&cas::atom(&super::expr::product(num)), positive_symbols)
}
