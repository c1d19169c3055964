//! results.json: the whole [`RunResults`] as one JSON object.
//!
//! Top-level keys: `model`, `parameters` (name → value, SI), `results` (key → `{value, unit,
//! meaning}`, or `{value, meaning}` with a word as the value, e.g. `contact_end_cause`), `series` (name → `{columns: [{name, unit, values}]}`), `checks` (name →
//! `{passed, margin, meaning}`) and `work` (counters and phases). Values are SI (angles in
//! radians); a non-finite number is written as `null`, as JSON has no NaN.

use crate::results::RunResults;

/// Pretty-printed JSON of the results, ending with a newline.
pub fn to_string(results: &RunResults) -> Result<String, serde_json::Error> {
    let mut value = serde_json::to_value(results)?;
    if let Some(map) = value.get_mut("results").and_then(|r| r.as_object_mut()) {
        for (key, label) in &results.labels {
            map.insert(key.clone(), serde_json::to_value(label)?);
        }
    }
    let mut s = serde_json::to_string_pretty(&value)?;
    s.push('\n');
    Ok(s)
}
