//! The sentences for people about a run: what each check tested ([`check_meaning`], written
//! as results.json's `meaning`, the table's legend and the Python binding's `meaning`) and
//! why a quantity has no value ([`note`]). Results carry only names and numbers; the words
//! are all here.

use crate::results::{Check, CheckKind, CheckSubject, format_number};

/// What a check tested and against what, in a sentence.
pub fn check_meaning(check: &Check) -> String {
    let (samples, tolerance) = (check.samples, check.limit);
    match &check.subject {
        CheckSubject::Monitor { model, meaning, .. } => {
            format!(
                "{meaning}: the smallest value over {samples} samples of `{model}` must be >= 0"
            )
        }
        CheckSubject::Pushes { model, contact } => format!(
            "contact `{contact}` is closed in `{model}`: its force must push (>= 0) at each of \
             {samples} samples, or the contact should have opened"
        ),
        CheckSubject::Gap {
            model,
            contact,
            length,
        } => format!(
            "contact `{contact}` is held closed by the integrator of `{model}`: its largest gap \
             over {samples} states, relative to the system's length ({} m), stays <= {}",
            format_number(*length, 4),
            format_number(tolerance, 3)
        ),
        CheckSubject::Energy {
            model,
            friction,
            rounding,
            scale,
        } => {
            let energy = if *friction {
                "the energy balance (energy lost = work of friction)"
            } else {
                "the total energy"
            };
            let what = format!(
                "{energy}, beyond its rounding ({} J), relative to the largest kinetic energy \
                 plus the potential's range ({} J),",
                format_number(*rounding, 3),
                format_number(*scale, 5)
            );
            conserved(check, &what, model)
        }
        CheckSubject::Momentum { model, name, scale } => {
            let what = format!(
                "the {} conserved, relative to {},",
                name.replace('_', " "),
                format_number(*scale, 5)
            );
            conserved(check, &what, model)
        }
        CheckSubject::Impact {
            energy_lost,
            kinetic_before,
        } => format!(
            "the energy lost in the impact ({} J by its impulses) against the drop of the total \
             energy across it, beyond its rounding, relative to the kinetic energy before \
             ({} J): relative difference <= {}",
            format_number(*energy_lost, 6),
            format_number(*kinetic_before, 6),
            format_number(tolerance, 3)
        ),
    }
}

/// The sentence of a conservation check on `what` along the path of `model`: a drift on an
/// integrated path, an agreement on the reduced path, where it holds by construction.
fn conserved(check: &Check, what: &str, model: &str) -> String {
    let (states, tolerance) = (check.samples, format_number(check.limit, 3));
    match check.kind {
        CheckKind::Identity => format!(
            "{what} is conserved by construction on the reduced path of `{model}`; this checks \
             that the generated function agrees with it over {states} states: relative \
             difference <= {tolerance}"
        ),
        CheckKind::Drift | CheckKind::Monitor => format!(
            "{what} along the {states} integrated states of `{model}`: largest relative drift \
             <= {tolerance}"
        ),
    }
}
