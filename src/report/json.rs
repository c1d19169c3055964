//! results.json: the whole [`RunResults`] as one JSON object.
//!
//! Top-level keys: `model`, `parameters` (name → value, SI), `results` (key → `{value, unit,
//! meaning}`, or `{value, meaning}` with a word as the value, e.g. `contact_end_cause`, or for
//! `impacts` a list of impacts as the value, each `{time, closing, contacts, per_contact:
//! [{contact, normal_velocity_before, normal_velocity_after, impulse, velocity_unit,
//! impulse_unit}], energy_lost, zeno_limit}`), `series` (name → `{columns: [{name, unit,
//! values}]}`), `checks` (name →
//! `{passed, margin, meaning}`), `work` (counters and phases), `notes` (key → sentence) and,
//! when sensitivities were wanted, `sensitivities` (`d(<result>)/d(<parameter>)` and
//! `elasticity(<result>;<parameter>)` → `{value, unit, meaning}`). Values are SI (angles in
//! radians); a non-finite number is written as `null`, as JSON has no NaN.

use super::prose::{check_meaning, check_phase, label, meaning, note, sensitivity_meaning};
use crate::results::RunResults;

/// The meaning written beside `results.impacts`.
pub const IMPACTS_MEANING: &str = "every impact of the motion in order: its time (s from release), the \
     contact that closed, the contacts that took part with their normal velocities before and \
     after (negative: approaching) and impulses (normal, and tangential where a friction acts) by \
     Newton's law of restitution with complementarity and Coulomb's friction cone, and the \
     kinetic energy lost (J), split into what the normal and the friction impulses took";

/// Pretty-printed JSON of the results, ending with a newline.
pub fn to_string(results: &RunResults) -> Result<String, serde_json::Error> {
    let mut value = serde_json::to_value(results)?;
    if let Some(map) = value.get_mut("checks").and_then(|c| c.as_object_mut()) {
        for (key, check) in &results.checks {
            if let Some(entry) = map.get_mut(key).and_then(|e| e.as_object_mut()) {
                entry.insert("meaning".into(), check_meaning(check).into());
                entry.insert("phase".into(), check_phase(&check.phase).into());
            }
        }
    }
    if !results.notes.is_empty()
        && let Some(map) = value.as_object_mut()
    {
        let notes: serde_json::Map<String, serde_json::Value> = (results.notes.iter())
            .map(|(key, n)| (key.clone(), note(n).into()))
            .collect();
        map.insert("notes".into(), notes.into());
    }
    if !results.sensitivities.is_empty()
        && let Some(map) = value.as_object_mut()
    {
        let entries: serde_json::Map<String, serde_json::Value> = (results.sensitivities.iter())
            .map(|(key, s)| {
                let entry = serde_json::json!({
                    "value": s.value,
                    "unit": s.unit,
                    "meaning": sensitivity_meaning(s),
                });
                (key.clone(), entry)
            })
            .collect();
        map.insert("sensitivities".into(), entries.into());
    }
    if let Some(map) = value.get_mut("results").and_then(|r| r.as_object_mut()) {
        for (key, scalar) in &results.results {
            if let Some(entry) = map.get_mut(key).and_then(|e| e.as_object_mut()) {
                entry.insert("meaning".into(), meaning(&scalar.meaning).into());
            }
        }
        for (key, word) in &results.labels {
            let entry = serde_json::json!({
                "value": label(&word.value),
                "meaning": meaning(&word.meaning),
            });
            map.insert(key.clone(), entry);
        }
        if let Some(impacts) = &results.impacts {
            map.insert(
                "impacts".into(),
                serde_json::json!({
                    "value": impacts,
                    "meaning": IMPACTS_MEANING,
                }),
            );
        }
    }
    let mut s = serde_json::to_string_pretty(&value)?;
    s.push('\n');
    Ok(s)
}
