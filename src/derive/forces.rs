//! Stage 7 of the derivation: what a phase reports besides its motion. Each contact's force is
//! named by its contact (a closed contact's in closed form, from stage 5, the general model's
//! solved by the runtime); the spec's monitors are written over the phase's state, the
//! parameters and the contacts' forces `rc_f<i>` (a contact open in the phase has force zero).

use super::cas::{self, A};
use super::read::Parsed;
use super::setup::Setup;
use super::spec::Spec;
use super::types::Monitor;

/// The monitors over the phase's state, parameters and the contacts' forces `rc_f<i>`.
pub fn monitors(spec: &Spec, parsed: &Parsed, st: &Setup) -> (Vec<Monitor>, Vec<A>) {
    let mut named = Vec::new();
    let mut exprs = Vec::new();
    for (m, e) in spec.monitors.iter().zip(&parsed.monitors) {
        let mut a = st.at(e);
        for (i, c) in spec.contacts.iter().enumerate() {
            a = cas::subs_var(&a, &c.name, &cas::var(&format!("rc_f{i}")));
        }
        named.push(Monitor {
            name: m.name.clone(),
            meaning: m.meaning.clone(),
            unit: m.unit.clone().unwrap_or_default(),
        });
        exprs.push(a);
    }
    (named, exprs)
}
