//! The integrated routes in `rodcube accuracy`: the models that springs, friction and curved
//! contacts send to the integrator, each integrated from release to the end of its first
//! contact by DOPRI5 and by DOP853 at tolerances from 1e-4 to 1e-14, against a reference that
//! does not share the route measured (the fast path where the model has one, else the other
//! method at 1e-15), with right-hand sides, steps, set-up and time per solve.

use super::settings::pick;
use super::{AccuracyError, Budget, Measured, Measurement, Row, measure};
use crate::model::Model;
use crate::results::EndCause;
use crate::results::Work;
use crate::solve::integrated::ode::Method;
use crate::solve::phases::{PhaseRun, Route, Walker};
use crate::system::Bound;

/// A model of the integrated routes and the scene it is measured on.
#[derive(Debug, Clone, Copy)]
pub struct IntegratedModel {
    /// The model's name.
    pub model: &'static str,
    /// Its parameters by name.
    pub parameters: &'static [(&'static str, f64)],
    /// What the case is (for the report).
    pub case: &'static str,
}

/// The models measured: the scenes `spring.yaml`, `friction.yaml` and `cylinder.yaml`.
pub const MODELS: [IntegratedModel; 3] = [
    IntegratedModel {
        model: "rod_cube_spring",
        parameters: &[
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", 9.81),
            ("k", 50.0),
        ],
        case: "scene",
    },
    IntegratedModel {
        model: "rod_cube_friction",
        parameters: &[
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", 9.81),
            ("mu", 1.45),
        ],
        case: "scene",
    },
    IntegratedModel {
        model: "rod_cylinder",
        parameters: &[
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("R", 0.2),
            ("th0", 0.9),
            ("g", 9.81),
        ],
        case: "scene",
    },
];

/// The integrated model called `name`.
pub fn find(name: &str) -> Option<&'static IntegratedModel> {
    MODELS.iter().find(|m| m.model == name)
}

/// The tolerances measured (`quick`: first, middle and last).
pub fn tolerances(quick: bool) -> Vec<i32> {
    pick(&[4, 6, 8, 10, 12, 14], quick)
}

/// The tolerance of the reference integrations.
pub const REFERENCE_RTOL: f64 = 1e-15;

/// The reference of one integrated model: the contact-end time by the fast path (if the model
/// has one) and by each method at [`REFERENCE_RTOL`].
#[derive(Debug, Clone, PartialEq)]
pub struct IntegratedReference {
    /// The model.
    pub model: &'static str,
    /// The case.
    pub case: &'static str,
    /// The contact-end time by the fast path (s), if the model has one.
    pub fast: Option<f64>,
    /// By DOPRI5 at [`REFERENCE_RTOL`] (s).
    pub dopri5: f64,
    /// By DOP853 at [`REFERENCE_RTOL`] (s).
    pub dop853: f64,
}

impl IntegratedReference {
    /// The reference for rows of `method`: the fast path, else the other method.
    pub fn for_method(&self, method: Method) -> f64 {
        match (self.fast, method) {
            (Some(t), _) => t,
            (None, Method::Dopri5) => self.dop853,
            (None, Method::Dop853) => self.dopri5,
        }
    }

    /// Its own uncertainty (relative): how far the independent routes to it disagree (the
    /// fast path and DOP853 at 1e-15, or DOPRI5 and DOP853 at 1e-15).
    pub fn uncertainty(&self) -> f64 {
        let other = self.fast.unwrap_or(self.dopri5);
        ((self.dop853 - other) / other).abs()
    }

    /// What it is, in a sentence.
    pub fn describe(&self) -> String {
        match self.fast {
            Some(t) => format!(
                "{} {}: contact-end time {t:.15e} s by the fast path at tol 1e-15; DOP853 at rtol 1e-15 agrees to {:.1e}",
                self.model,
                self.case,
                self.uncertainty()
            ),
            None => format!(
                "{} {}: contact-end time {:.15e} s by DOP853 (the reference of DOPRI5's rows) and {:.15e} s by DOPRI5 (of DOP853's), both at rtol 1e-15: they agree to {:.1e}",
                self.model,
                self.case,
                self.dop853,
                self.dopri5,
                self.uncertainty()
            ),
        }
    }
}

/// A walker of `model` at its scene's parameters on `route`, with the integrator at `rtol`.
fn walker(
    m: &IntegratedModel,
    model: &'static dyn Model,
    route: Route,
    rtol: f64,
) -> Result<Walker<'static>, AccuracyError> {
    let general = Bound::new(model, m.parameters)?;
    Ok(Walker::new(general, crate::models::all(), REFERENCE_RTOL, rtol).with_route(route))
}

/// The end of the first contact's phase from release by `method` (its time, the steps and
/// right-hand sides it took); a phase that ends otherwise is an error saying how.
pub fn contact_end(walker: &Walker, method: Option<Method>) -> Result<(f64, Work), AccuracyError> {
    let start = walker.release()?.0;
    let mut work = Work::default();
    let run = match method {
        Some(_) => walker.integrate_with(&start, method, &mut work),
        None => walker.solve(&start, &mut work),
    }?;
    first_contact_ended(&run)?;
    Ok((run.t_end(), work))
}

/// Whether a phase ended with its first contact's end (its force at zero, or its point off an
/// edge).
fn first_contact_ended(run: &PhaseRun) -> Result<(), AccuracyError> {
    match run.end() {
        EndCause::Force(c) | EndCause::Edge(c) if c.index == 0 => Ok(()),
        end => Err(AccuracyError::EndedBefore { end }),
    }
}

/// The reference of `m`.
pub fn reference(m: &IntegratedModel) -> Result<IntegratedReference, AccuracyError> {
    let model = crate::models::find(m.model).ok_or_else(|| AccuracyError::NoModel {
        name: m.model.into(),
    })?;
    let fastest = walker(m, model, Route::Fastest, REFERENCE_RTOL)?;
    let start = fastest.release()?.0;
    let fast = match fastest.fast_phase(&start)? {
        Some(_) => Some(contact_end(&fastest, None)?.0),
        None => None,
    };
    let integrated = walker(m, model, Route::Integrated, REFERENCE_RTOL)?;
    Ok(IntegratedReference {
        model: m.model,
        case: m.case,
        fast,
        dopri5: contact_end(&integrated, Some(Method::Dopri5))?.0,
        dop853: contact_end(&integrated, Some(Method::Dop853))?.0,
    })
}

/// The label of a method in the report.
pub fn label(method: Method) -> &'static str {
    match method {
        Method::Dopri5 => "dopri5",
        Method::Dop853 => "dop853",
    }
}

/// Measures `method` at `rtol = 10^-k` on `m`: the set-up is the walker (the model bound to
/// its parameters), the solve the release's decision and the integration to the contact's end.
pub fn measure_one(
    m: &IntegratedModel,
    reference: &IntegratedReference,
    method: Method,
    k: i32,
    budget: &Budget,
) -> Row {
    let rtol = 10f64.powi(-k);
    let mut row = Row::unmeasured(
        m.model,
        Measured::ContactEnd,
        m.case,
        label(method),
        format!("rtol 1e-{k}"),
    );
    let Some(model) = crate::models::find(m.model) else {
        row.note = AccuracyError::NoModel {
            name: m.model.into(),
        }
        .to_string();
        return row;
    };
    let measured: Result<Measurement<(f64, u64)>, AccuracyError> = measure(
        || walker(m, model, Route::Integrated, rtol),
        |w| {
            let (t, work) = contact_end(w, Some(method))?;
            Ok(((t, work.ode_steps), work.ode_evaluations))
        },
        true,
        budget,
    );
    match measured {
        Ok(done) => {
            let (t, steps) = done.value;
            let t_ref = reference.for_method(method);
            row.error = (t - t_ref) / t_ref;
            row.evals = done.evals;
            row.steps = Some(steps);
            row.setup_seconds = done.setup_seconds;
            row.seconds = done.seconds;
        }
        Err(e) => row.note = e.to_string(),
    }
    row
}
