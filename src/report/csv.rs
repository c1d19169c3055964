//! One CSV file per series: a header `name [unit]` per column, then one row per sample.
//!
//! Numbers are written with all the digits needed to read them back exactly (`f64`'s shortest
//! round-trip form), in exponent notation when that is shorter.

use super::Error;
use crate::results::Series;

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
