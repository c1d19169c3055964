//! The CSV files: one per series (a header `name [unit]` per column, then one row per sample),
//! and `impacts.csv` ([`impacts`]: one row per contact taking part in each impact).
//!
//! Numbers are written with all the digits needed to read them back exactly (`f64`'s shortest
//! round-trip form), in exponent notation when that is shorter.

use super::Error;
use crate::results::{ImpactRecord, Series};

/// The header of `impacts.csv`. The normal velocities and the impulse have their units in
/// their own columns, as they may differ from contact to contact (`m/s` and `N s` for a
/// distance gap, `rad/s` and `N m s` for an angular one).
pub const IMPACTS_HEADER: [&str; 13] = [
    "time [s]",
    "contact",
    "closing",
    "normal_velocity_before",
    "normal_velocity_after",
    "velocity_unit",
    "impulse",
    "impulse_unit",
    "tangential_impulse",
    "energy_lost [J]",
    "normal_energy_lost [J]",
    "friction_energy_lost [J]",
    "zeno_limit",
];

/// The header cell of a column: `t [s]`, `theta [rad]` (`name` alone when it has no unit).
pub fn header(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

/// A number in its shortest exact form: plain between 1e-4 and 1e15, exponent otherwise.
pub fn number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || (1e-4..1e15).contains(&a) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The CSV text of `series` (named `name` in messages).
pub fn to_string(name: &str, series: &Series) -> Result<String, Error> {
    check_lengths(name, series)?;
    let csv_error = |e: &dyn std::fmt::Display| Error::Csv {
        series: name.to_string(),
        message: e.to_string(),
    };
    let mut w = ::csv::Writer::from_writer(Vec::new());
    w.write_record(series.columns.iter().map(|c| header(&c.name, c.unit)))
        .map_err(|e| csv_error(&e))?;
    let rows = series.columns.first().map_or(0, |c| c.values.len());
    for i in 0..rows {
        w.write_record(series.columns.iter().map(|c| number(c.values[i])))
            .map_err(|e| csv_error(&e))?;
    }
    let bytes = w.into_inner().map_err(|e| csv_error(&e))?;
    String::from_utf8(bytes).map_err(|e| csv_error(&e))
}

/// The text of `impacts.csv`: [`IMPACTS_HEADER`], then one row per contact that took part in
/// each impact, impacts in order and contacts in each impact's order. `time`, `energy_lost`
/// and its split into the normal and the friction impulses' parts (the impact's, repeated on
/// each of its rows) and `zeno_limit` are the impact's; `tangential_impulse` is the contact's
/// friction impulse (in the unit of `impulse`); `closing` is
/// `true` on the row of the contact whose gap closed. An impact that names no contact taking
/// part still has a row: its closing contact, with the velocity and impulse cells empty.
pub fn impacts(records: &[ImpactRecord]) -> Result<String, Error> {
    let csv_error = |e: &dyn std::fmt::Display| Error::Csv {
        series: "impacts".to_string(),
        message: e.to_string(),
    };
    let mut w = ::csv::Writer::from_writer(Vec::new());
    w.write_record(IMPACTS_HEADER).map_err(|e| csv_error(&e))?;
    for r in records {
        let impact = |contact: &str, cells: [String; 6]| {
            let [before, after, v_unit, impulse, p_unit, tangential] = cells;
            [
                number(r.time),
                contact.to_string(),
                (contact == r.closing).to_string(),
                before,
                after,
                v_unit,
                impulse,
                p_unit,
                tangential,
                number(r.energy_lost),
                number(r.normal_energy_lost),
                number(r.friction_energy_lost),
                r.zeno_limit.to_string(),
            ]
        };
        if r.per_contact.is_empty() {
            w.write_record(impact(&r.closing, Default::default()))
                .map_err(|e| csv_error(&e))?;
        }
        for c in &r.per_contact {
            let cells = [
                number(c.normal_velocity_before),
                number(c.normal_velocity_after),
                c.velocity_unit.to_string(),
                number(c.impulse),
                c.impulse_unit.to_string(),
                number(c.tangential_impulse),
            ];
            w.write_record(impact(&c.contact, cells))
                .map_err(|e| csv_error(&e))?;
        }
    }
    let bytes = w.into_inner().map_err(|e| csv_error(&e))?;
    String::from_utf8(bytes).map_err(|e| csv_error(&e))
}

/// Fails unless every column of `series` has as many values as the first.
pub fn check_lengths(name: &str, series: &Series) -> Result<(), Error> {
    let Some(first) = series.columns.first() else {
        return Ok(());
    };
    for c in &series.columns[1..] {
        if c.values.len() != first.values.len() {
            return Err(Error::Ragged {
                series: name.to_string(),
                first: first.name.clone(),
                expected: first.values.len(),
                column: c.name.clone(),
                len: c.values.len(),
            });
        }
    }
    Ok(())
}
