//! The quantity `sensitivities`: `d(<result>)/d(<parameter>)` and the elasticities
//! `(p/x) dx/dp` of the wanted separation angle and time and of the first contact's end where
//! it is that separation, for every parameter, from the fast path's generated partial
//! derivatives (`solve::sensitivity`). Anything else wanted that sensitivities could be asked
//! of (the other contacts' ends, the floor impact, the impacts) gets a note saying they are not
//! available there, never a number.

use super::Plan;
use super::quantities::Fate;
use crate::model::start_offsets;
use crate::quantity::Quantity;
use crate::results::{Note, RunResults, Sensitivity, SensitivityGap};
use crate::solve::SolveError;
use crate::solve::phases::End;
use crate::solve::prior::{PRIOR_TOL, Prior};
use crate::solve::quadrature::ACCEPT;
use crate::solve::sensitivity::{self, SensitivityWork, SeparationPoint};
use crate::spec::units::Unit;

/// A result the sensitivities are of: its key, unit and whether it is an angle.
struct Target {
    key: String,
    unit: &'static str,
    angle: bool,
}

/// The keys of the note that says why `key` has no sensitivities.
fn note_key(key: &str) -> String {
    format!("sensitivities.{key}")
}

/// `result` over `parameter` as a unit: `rad/kg`, `s^3/m`, `rad s^2/m`.
pub fn per(result: &str, parameter: &str) -> String {
    let parsed = |u: &str| Unit::parse(u).ok();
    let (angle, result_unit) = match result {
        "rad" => (true, parsed("1")),
        other => (false, parsed(other)),
    };
    let quotient = result_unit
        .zip(parsed(parameter))
        .and_then(|(r, p)| r.checked_div(p).ok());
    let Some(q) = quotient else {
        return format!("{result}/({parameter})");
    };
    let text = q.to_string();
    match (angle, text.strip_prefix("1/")) {
        (false, _) => text,
        (true, _) if text == "1" => "rad".into(),
        (true, Some(below)) => format!("rad/{below}"),
        (true, None) => format!("rad {text}"),
    }
}

impl Plan<'_> {
    /// The sensitivities of every wanted result that has them, and notes for the others.
    pub(super) fn sensitivities(
        &mut self,
        want: &[Quantity],
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let info = self.general().info();
        let first = info.contacts.first().map_or("contact", |c| c.name);
        let mut targets = Vec::new();
        for q in want {
            match q {
                Quantity::SeparationAngle => targets.push(("separation_angle".into(), true)),
                Quantity::SeparationTime => targets.push(("separation_time".into(), false)),
                Quantity::ContactEnd => {
                    for key in ["contact_end".to_string(), format!("{first}_end")] {
                        targets.push((format!("{key}_time"), false));
                        targets.push((format!("{key}_angle"), true));
                    }
                    for c in info.contacts.iter().skip(1) {
                        let gap = Note::NoSensitivity(SensitivityGap::NotBuilt);
                        out.notes.insert(note_key(&format!("{}_end", c.name)), gap);
                    }
                }
                Quantity::FloorImpact | Quantity::Impacts => {
                    let gap = Note::NoSensitivity(SensitivityGap::NotBuilt);
                    out.notes.insert(note_key(&q.name(info)), gap);
                }
                _ => {}
            }
        }
        let targets: Vec<Target> = (targets.into_iter())
            .map(|(key, angle)| Target {
                key,
                unit: if angle { "rad" } else { "s" },
                angle,
            })
            .collect();
        match self.separation_sensitivities()? {
            Ok(found) => {
                for target in &targets {
                    match (target.angle, &found.d_t) {
                        (true, _) => self.record(target, found.theta, &found.d_theta, out),
                        (false, Ok(d_t)) => self.record(target, found.t, d_t, out),
                        (false, Err(gap)) => {
                            let note = Note::NoSensitivity(*gap);
                            out.notes.insert(note_key(&target.key), note);
                        }
                    }
                }
            }
            Err(gap) => {
                for target in &targets {
                    out.notes
                        .insert(note_key(&target.key), Note::NoSensitivity(gap));
                }
            }
        }
        Ok(())
    }

    /// `d(target)/dp` and its elasticity for every parameter, from `x` and its derivatives.
    fn record(&self, target: &Target, x: f64, dx: &[f64], out: &mut RunResults) {
        let info = self.general().info();
        let p = self.general().p();
        for ((param, &value), &d) in info.parameters.iter().zip(p).zip(dx) {
            let entry = |value: f64, unit: String, elasticity: bool| Sensitivity {
                value,
                unit,
                of: target.key.clone(),
                parameter: param.name.to_string(),
                elasticity,
            };
            out.sensitivities.insert(
                format!("d({})/d({})", target.key, param.name),
                entry(d, per(target.unit, param.unit), false),
            );
            out.sensitivities.insert(
                format!("elasticity({};{})", target.key, param.name),
                entry(value / x * d, "1".into(), true),
            );
        }
    }

    /// The separation on the fast phase the motion starts on with its sensitivities, or why
    /// there are none.
    fn separation_sensitivities(&mut self) -> Result<Result<Found, SensitivityGap>, SolveError> {
        let Fate::Ended {
            t, cause: "force", ..
        } = self.fate(0)?
        else {
            return Ok(Err(SensitivityGap::NoSeparation));
        };
        if t == 0.0 {
            return Ok(Err(SensitivityGap::AtRelease));
        }
        let Some(sys) = self.fast()? else {
            return Ok(Err(SensitivityGap::Integrated));
        };
        let end = self.end()?;
        let (End::Force(0), Some(at)) = (end.end, end.at) else {
            // The first contact separates on a later phase, which is integrated.
            return Ok(Err(SensitivityGap::Integrated));
        };
        let layout = sys.layout();
        let k = sys.k();
        let (si, ci) = (k[layout.k_sin_initial], k[layout.k_cos_initial]);
        let (_, _, drop, _) = start_offsets(sys.theta_initial(), si, ci, at.delta);
        let np = sys.info().parameters.len();
        let point = SeparationPoint {
            red: sys.reduction(),
            k,
            parameters: np,
            sin_initial: si,
            scale: ci * ci / (1.0 + si),
            fall: sys.fall_coefficients(),
            singularities: None,
            sin_sep: at.sin_theta,
            drop,
        };
        let (mut d_theta, mut d_t) = (vec![0.0; np], vec![0.0; np]);
        let prior = Prior::new(PRIOR_TOL);
        let tol = ACCEPT.min(self.walker.tol);
        let mut work = SensitivityWork::default();
        let outcome =
            sensitivity::separation(&point, &prior, tol, &mut work, &mut d_theta, &mut d_t)?;
        let d_t = match outcome {
            Ok(()) => Ok(d_t),
            // The angle's are there; the time's need the fall polynomial.
            Err(SensitivityGap::NoFallPolynomial) => Err(SensitivityGap::NoFallPolynomial),
            Err(why) => return Ok(Err(why)),
        };
        Ok(Ok(Found {
            theta: at.theta,
            t,
            d_theta,
            d_t,
        }))
    }
}

/// A separation with its sensitivities.
struct Found {
    theta: f64,
    t: f64,
    d_theta: Vec<f64>,
    /// The time's, or why there are none.
    d_t: Result<Vec<f64>, SensitivityGap>,
}
