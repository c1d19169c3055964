//! results.json: the whole [`RunResults`] as one JSON object.
//!
//! Top-level keys: `model`, `parameters` (name → value, SI), `results` (key → `{value, unit,
//! meaning}`), `series` (name → `{columns: [{name, unit, values}]}`), `checks` (name →
//! `{passed, margin, meaning}`) and `work` (counters and phases). Values are SI (angles in
//! radians); a non-finite number is written as `null`, as JSON has no NaN.

use crate::results::RunResults;

/// Pretty-printed JSON of the results, ending with a newline.
pub fn to_string(results: &RunResults) -> Result<String, serde_json::Error> {
    let mut s = serde_json::to_string_pretty(results)?;
    s.push('\n');
    Ok(s)
}
