//! The accuracy layer's one error type, [`AccuracyError`]: the options refused (a usage
//! error), a reference that could not be computed, and each method's own failures with their
//! numbers. A failed setting's message becomes its row's note in the report.

use crate::reference::ReferenceError;
use crate::results::EndCause;
use crate::results::SensitivityGap;
use crate::solve::SolveError;
use crate::system::SystemError;

/// Why the report, a reference or a method failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AccuracyError {
    /// A model the report has no reference for.
    #[error("no model `{name}` in the report; its models are: {known}")]
    UnknownModel {
        /// The name given.
        name: String,
        /// The models it has.
        known: String,
    },
    /// A case none of the chosen models has.
    #[error("no case `{name}` for the chosen models; their cases are: {known}")]
    UnknownCase {
        /// The key given.
        name: String,
        /// The keys the chosen models have.
        known: String,
    },
    /// A method label the report does not have.
    #[error("no method `{name}` in the report; its methods are: {known}")]
    UnknownMethod {
        /// The label given.
        name: String,
        /// The labels.
        known: String,
    },
    /// The choices leave nothing to measure.
    #[error("nothing to measure: {why}")]
    Nothing {
        /// Which choices exclude each other.
        why: String,
    },
    /// A reference could not be computed.
    #[error("{model}, case {case}: no reference: {source}")]
    Reference {
        /// The model.
        model: String,
        /// The case.
        case: String,
        /// Why.
        source: Box<AccuracyError>,
    },
    /// A solver of the project failed.
    #[error("{0}")]
    Solve(#[from] SolveError),
    /// A model refused its parameters or a value given to it.
    #[error("{0}")]
    System(#[from] SystemError),
    /// The high-precision reference failed.
    #[error("{0}")]
    HighPrecision(#[from] ReferenceError),
    /// A model the registry does not have.
    #[error("no model `{name}`")]
    NoModel {
        /// Its name.
        name: String,
    },
    /// The project's root found no separation in the phase.
    #[error("no separation")]
    NoSeparation,
    /// The linearised polynomial has no root in the phase.
    #[error("no root")]
    NoRoot,
    /// The separation polynomial is zero.
    #[error("zero polynomial")]
    ZeroPolynomial,
    /// The separation polynomial's degree has no closed form here.
    #[error("no closed form for degree {degree}")]
    NoClosedForm {
        /// The degree.
        degree: usize,
    },
    /// No root of the closed form lies in the phase's interval.
    #[error("no root in the interval")]
    NoRootInInterval,
    /// Plain Newton left the finite numbers.
    #[error("Newton diverged")]
    NewtonDiverged,
    /// Plain Newton did not converge.
    #[error("Newton did not converge in {steps} steps")]
    NewtonNoConvergence {
        /// The steps taken.
        steps: usize,
    },
    /// The polynomial has the same sign at both ends of the interval.
    #[error("no sign change over the interval")]
    NoSignChange,
    /// The raw integrand's `theta_dot^2` is not positive and finite.
    #[error("theta_dot^2 = {value} at delta = {delta:e}")]
    ThetaDotSquared {
        /// `theta_dot^2`.
        value: f64,
        /// Where.
        delta: f64,
    },
    /// Gauss–Jacobi's node count or exponents were refused.
    #[error("bad Gauss-Jacobi parameters")]
    BadGaussJacobi,
    /// A point without sensitivities.
    #[error("{}", crate::report::prose::sensitivity_gap(*.gap))]
    NoSensitivity {
        /// Why there are none.
        gap: SensitivityGap,
    },
    /// A model's parameter that the reference does not have.
    #[error("the reference has no parameter `{name}` (it has m1, m2, ell, a, g)")]
    NoReferenceParameter {
        /// The parameter.
        name: &'static str,
    },
    /// A Gauss–Legendre rule asked with no node.
    #[error("a Gauss–Legendre rule needs at least one node")]
    NoNodes,
    /// Adaptive Gauss–Kronrod ran out of subintervals.
    #[error(
        "not converged after {limit} subintervals (estimate {estimate:.6e}, error {error:.1e})"
    )]
    KronrodNotConverged {
        /// The subintervals allowed.
        limit: usize,
        /// The estimate reached.
        estimate: f64,
        /// Its error estimate.
        error: f64,
    },
    /// An integration reached no event.
    #[error("no event")]
    NoEvent,
    /// The unreduced integration ended before the first contact's force vanished.
    #[error("the phase ended before the first contact's force vanished")]
    ForceNotVanished,
    /// A phase of the integrated routes ended otherwise than by its first contact's end.
    #[error(
        "the phase ended at {} before the first contact ended",
        crate::report::prose::event_words(*end)
    )]
    EndedBefore {
        /// How it ended.
        end: EndCause,
    },
    /// A series sample's time lies outside the dense output.
    #[error("time outside the solution")]
    OutsideSolution {
        /// The time asked for.
        t: f64,
    },
    /// A series' error at a sample is not finite.
    #[error("non-finite error at sample {sample}")]
    NonFiniteSeriesError {
        /// The sample's index.
        sample: usize,
    },
    /// The CSV could not be written.
    #[error("{message}")]
    Csv {
        /// The writer's message.
        message: String,
    },
    /// A plot could not be drawn.
    #[error("{message}")]
    Plot {
        /// The drawing library's message.
        message: String,
    },
}

impl AccuracyError {
    /// Whether the error is in the options (a usage error).
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            AccuracyError::UnknownModel { .. }
                | AccuracyError::UnknownCase { .. }
                | AccuracyError::UnknownMethod { .. }
                | AccuracyError::Nothing { .. }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::AccuracyError as E;
    use crate::results::EndCause;

    /// Each method's message is the text its report note had when it was a string.
    #[test]
    fn accuracy_error_messages_are_the_notes_they_replace() {
        let (w2, delta, total, error, j) = (-1.5e-3, 2.5e-7, 1.234_567_89e-2, 3.2e-9, 7);
        let wall = crate::results::ContactId {
            index: 1,
            name: "wall",
        };
        let end = EndCause::Force(wall);
        let cases = [
            (E::NoSeparation, "no separation".to_string()),
            (E::NoRoot, "no root".into()),
            (E::ZeroPolynomial, "zero polynomial".into()),
            (
                E::NoClosedForm { degree: 4 },
                format!("no closed form for degree {}", 4),
            ),
            (E::NoRootInInterval, "no root in the interval".into()),
            (E::NewtonDiverged, "Newton diverged".into()),
            (
                E::NewtonNoConvergence { steps: 200 },
                "Newton did not converge in 200 steps".into(),
            ),
            (E::NoSignChange, "no sign change over the interval".into()),
            (
                E::ThetaDotSquared { value: w2, delta },
                format!("theta_dot^2 = {w2} at delta = {delta:e}"),
            ),
            (E::BadGaussJacobi, "bad Gauss-Jacobi parameters".into()),
            (
                E::KronrodNotConverged {
                    limit: 2000,
                    estimate: total,
                    error,
                },
                format!(
                    "not converged after {} subintervals (estimate {total:.6e}, error {error:.1e})",
                    2000
                ),
            ),
            (E::NoEvent, "no event".into()),
            (
                E::ForceNotVanished,
                "the phase ended before the first contact's force vanished".into(),
            ),
            (
                E::EndedBefore { end },
                "the phase ended at contact `wall`'s force crossing zero before the first contact \
                 ended"
                    .into(),
            ),
            (
                E::OutsideSolution { t: 1.0 },
                "time outside the solution".into(),
            ),
            (
                E::NonFiniteSeriesError { sample: j },
                format!("non-finite error at sample {j}"),
            ),
            (
                E::NoModel {
                    name: "rod_cube".into(),
                },
                format!("no model `{}`", "rod_cube"),
            ),
        ];
        for (e, old) in cases {
            assert_eq!(e.to_string(), old);
            assert!(!e.is_usage(), "{e}");
        }
        let inner = E::NoSeparation;
        let wrapped = E::Reference {
            model: "rod_cube".into(),
            case: "paper".into(),
            source: Box::new(inner.clone()),
        };
        assert_eq!(
            wrapped.to_string(),
            format!("rod_cube, case paper: no reference: {inner}")
        );
    }
}
