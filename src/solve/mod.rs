//! Numerical solvers for any [`Model`](crate::model::Model), in three rooms by route, with what
//! they share beside them.
//!
//! - [`fast`]: the energy integral's route, for a phase with one coordinate left: where it
//!   ends ([`fast::separation`], over [`fast::poly`]), `t(theta)` by [`fast::quadrature`] and
//!   its inverse ([`fast::inversion`]), the per-point solvers ([`fast::lean`], with
//!   [`fast::prior`]'s certified bounds) and their parameter derivatives
//!   ([`fast::sensitivity`]).
//! - [`integrated`]: the general model's route, `M(q) qdd = F(q, qd)` with the contacts' forces:
//!   the [`integrated::ode`] integrator, one phase of it ([`integrated::unreduced`]), the
//!   contacts' dynamics and the choice of the active set ([`integrated::contacts`], with
//!   [`integrated::active`] and [`integrated::rest`]), impacts ([`integrated::impact`]) and
//!   forward sensitivities ([`integrated::forward`], [`integrated::saltation`]).
//! - [`phases`]: the walk from release through phases and impacts, each phase on the fast route
//!   where it has one and integrated otherwise.
//! - Shared: [`roots`] (the one bracketed root finder), [`linear`] (small dense solves),
//!   [`series`] (a phase sampled at uniform times) and [`checks`] (sampled motion turned into
//!   pass/fail margins).
//!
//! Architecture invariant: nothing here panics or returns NaN on bad numbers; every failure is
//! a [`SolveError`] carrying the offending values. Every evaluation is counted in a
//! [`Work`](crate::results::Work) passed down by the caller.

pub mod checks;
pub mod fast;
pub mod integrated;
pub mod linear;
pub mod phases;
pub mod roots;
pub mod series;

/// Deterministic uniform numbers in `[0, 1)` for the unit tests (xorshift64 from `state`).
#[cfg(test)]
pub(crate) fn uniform(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

use crate::results::{ContactSet, Holding, Indeterminacy};
use crate::system::SystemError;

/// Everything that can go wrong while solving a validated [`System`](crate::system::System).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The parameters handed to a next phase were refused.
    #[error("next phase: {0}")]
    System(SystemError),
    /// A state, slice or value given to a model's function was refused (a length that is not
    /// the model's, a value that is not finite): see [`Bound`](crate::system::Bound).
    #[error("{0}")]
    Input(#[from] SystemError),
    /// The parameters handed to a per-point solver were refused (the same checks as
    /// [`System::from_values`](crate::system::System::from_values)).
    #[error("{0}")]
    Parameters(SystemError),
    /// A contact's end was asked of a model that does not hold it closed as a unilateral
    /// contact (with an edge, where its edge was asked), or that has no such contact.
    #[error(
        "model `{model}` does not hold contact {contact} closed as a unilateral contact{}, so it cannot end there",
        if *edge { " with an edge" } else { "" }
    )]
    NoContact {
        /// Model name.
        model: &'static str,
        /// The contact's index in the model's contacts (0: the separation's).
        contact: usize,
        /// Whether its edge was asked.
        edge: bool,
    },
    /// The separation polynomial is identically zero or has a non-finite coefficient.
    #[error("separation polynomial of model `{model}` is unusable: {coefficients:?}")]
    BadPolynomial {
        /// Model name.
        model: &'static str,
        /// Its coefficients, lowest degree first.
        coefficients: Vec<f64>,
    },
    /// The separation polynomial has no sign change inside the phase (the per-point solver
    /// needs a separation; the planner reports a contact kept to the floor instead).
    #[error(
        "model `{model}`: the separation polynomial {coefficients:?} (in sin(theta), lowest degree first) does not change sign between sin(theta) = {lo:e} and sin(theta_i) = {hi:e}: the contact holds to the floor, or the coefficients under- or overflowed"
    )]
    NoSeparation {
        /// Model name.
        model: &'static str,
        /// The polynomial's coefficients, lowest degree first.
        coefficients: Vec<f64>,
        /// `sin(end_angle)`.
        lo: f64,
        /// `sin(theta_i)`.
        hi: f64,
    },
    /// Released from rest where the angular acceleration does not make it fall.
    #[error(
        "model `{model}` does not start falling: theta_dot_i = {theta_dot}, theta_ddot_i = {theta_ddot}"
    )]
    NoMotion {
        /// Model name.
        model: &'static str,
        /// Initial rate.
        theta_dot: f64,
        /// Initial acceleration.
        theta_ddot: f64,
    },
    /// The phase starts at or beyond the vertical, where `sin(theta)` does not fall monotonically.
    #[error(
        "model `{model}` starts at theta_i = {theta_initial} rad, not below the vertical; the per-point solver needs 0 < cos(theta_i)"
    )]
    BeyondVertical {
        /// Model name.
        model: &'static str,
        /// Initial angle (rad).
        theta_initial: f64,
    },
    /// The initial rate makes the angle grow, so `delta` would be negative.
    #[error("model `{model}` starts rising (theta_dot_i = {theta_dot} > 0); phases must fall")]
    Rising {
        /// Model name.
        model: &'static str,
        /// Initial rate.
        theta_dot: f64,
    },
    /// `theta_dot^2` reached zero (a turning point) before the end of the phase.
    #[error(
        "model `{model}`: theta_dot^2 = {theta_dot_sq:e} <= 0 at delta = {delta:e} before the phase end (delta_end = {delta_end:e})"
    )]
    TurningPoint {
        /// Model name.
        model: &'static str,
        /// Where.
        delta: f64,
        /// The value.
        theta_dot_sq: f64,
        /// Where the phase should have ended.
        delta_end: f64,
    },
    /// A model function returned NaN or an infinity.
    #[error("model `{model}`: {what} is {value} at delta = {delta:e}")]
    NonFinite {
        /// Model name.
        model: &'static str,
        /// Which quantity.
        what: &'static str,
        /// Where.
        delta: f64,
        /// The value.
        value: f64,
    },
    /// The phase end is not a positive, finite angle fallen.
    #[error("model `{model}`: the phase would end at delta = {delta_end}, not a positive angle")]
    BadPhaseEnd {
        /// Model name.
        model: &'static str,
        /// The requested end.
        delta_end: f64,
    },
    /// An angle outside the phase was asked of its time integral.
    #[error("model `{model}`: delta = {delta:e} is outside the phase [0, {delta_end:e}]")]
    OutsidePhase {
        /// Model name.
        model: &'static str,
        /// The angle fallen asked (NaN if it was not a number).
        delta: f64,
        /// The phase's end.
        delta_end: f64,
    },
    /// The adaptive quadrature did not converge.
    #[error(
        "quadrature on [{a:e}, {b:e}] missed relative tolerance {tol:e}: estimate {estimate}, error {error:e} after {panels} panels"
    )]
    QuadratureNotConverged {
        /// Lower limit.
        a: f64,
        /// Upper limit.
        b: f64,
        /// Relative tolerance asked.
        tol: f64,
        /// Best estimate.
        estimate: f64,
        /// Its error estimate on the worst panel.
        error: f64,
        /// Panels used.
        panels: usize,
    },
    /// `t(theta)` could not be inverted at a time.
    #[error("cannot invert t(theta) at t = {target:e} s (phase lasts {duration:e} s): {reason}")]
    Inversion {
        /// The time asked.
        target: f64,
        /// The phase duration.
        duration: f64,
        /// Why.
        reason: &'static str,
    },
    /// An active set whose size does not match the model's contacts or frictions.
    #[error(
        "model `{model}` has {contacts} contact(s) and {frictions} friction(s); the active set given has {closed} and {modes}"
    )]
    ActiveSize {
        /// Model name.
        model: &'static str,
        /// Contacts of the model.
        contacts: usize,
        /// Frictions of the model.
        frictions: usize,
        /// Contact states given.
        closed: usize,
        /// Friction modes given.
        modes: usize,
    },
    /// No single consistent set of closed contacts and friction modes (a contact that would
    /// have to pull, Painlevé's paradox of friction, or several sets with different motions).
    #[error("model `{model}` at t = {t:e} s ({}): {why}", contacts.join(", "))]
    Indeterminate {
        /// Model name.
        model: &'static str,
        /// Time from release.
        t: f64,
        /// The contacts and frictions concerned.
        contacts: Vec<&'static str>,
        /// What was found (its words: `report::prose`), boxed to keep the error small.
        why: Box<Indeterminacy>,
    },
    /// The reduced angle reaches its end angle with the body above the floor.
    #[error(
        "model `{model}` at t = {t:e} s: the angle reaches its end ({angle} rad) with `{point}` {height:e} m above the floor, so the body has not landed (a support lifted it); the spec's end angle does not describe the motion from here, and rodcube stops rather than report a landing"
    )]
    AboveFloor {
        /// Model name.
        model: &'static str,
        /// Time from release (s).
        t: f64,
        /// The end angle (rad).
        angle: f64,
        /// The falling point.
        point: &'static str,
        /// Its height (m).
        height: f64,
    },
    /// A phase that starts at rest and turns back before any contact ends: it swings for ever.
    #[error(
        "model `{model}`: the motion from rest at t = {t:e} s turns back after falling {delta:e} rad, before any contact ends; with one degree of freedom and no friction it swings between its two turning points for ever, so no contact ends and the motion never reaches the floor"
    )]
    Swings {
        /// The phase's model.
        model: &'static str,
        /// Where the phase starts (s from release).
        t: f64,
        /// The angle fallen to the turning point (rad).
        delta: f64,
    },
    /// The supports hold the system at rest: nothing moves, so no contact ends.
    #[error(
        "model `{model}` at t = {t:e} s: the system stays at rest, held {held} {set} (each within its law: contacts push, stuck frictions within mu N); nothing moves from here, so no contact ends and there is no motion to report"
    )]
    AtRest {
        /// Model name.
        model: &'static str,
        /// Time from release (s).
        t: f64,
        /// How the supports hold it (its words: `report::prose`).
        held: Holding,
        /// The supports that hold it.
        set: ContactSet,
    },
    /// Bodies that overlap where a phase starts (a gap below zero).
    #[error(
        "model `{model}`: contact `{contact}` overlaps at t = {t:e} s (gap {gap:e} {unit}): {}",
        if *t == 0.0 { "the initial state puts the bodies into each other" } else { "the bodies have moved into each other beyond the tolerance" }
    )]
    Overlap {
        /// Time from release (s).
        t: f64,
        /// Model name.
        model: &'static str,
        /// The contact.
        contact: &'static str,
        /// Its gap.
        gap: f64,
        /// The gap's unit.
        unit: &'static str,
    },
    /// A contact that closes with a velocity where a phase starts (at release, or after an
    /// event that was not an impact).
    #[error(
        "model `{model}`: contact `{contact}` is closing with normal velocity {velocity:e} where a phase starts: the bodies would strike at once, which only an impact at a contact's closing resolves"
    )]
    ImpactAtRelease {
        /// Model name.
        model: &'static str,
        /// The contact.
        contact: &'static str,
        /// Its normal velocity (negative: closing).
        velocity: f64,
    },
    /// An impact whose impulses would create kinetic energy (Newton's law of restitution
    /// with friction can, for some geometries): the law does not describe it.
    #[error(
        "model `{model}` at t = {t:e} s ({}): the impulses of Newton's law of restitution with Coulomb friction would create {gained:e} J of kinetic energy (of {kinetic:e} J before the impact), so this law does not describe the impact; rodcube stops rather than continue with it",
        contacts.join(", ")
    )]
    ImpactGainsEnergy {
        /// Model name.
        model: &'static str,
        /// Time from release (s).
        t: f64,
        /// The contacts taking part.
        contacts: Vec<&'static str>,
        /// The kinetic energy the impulses would create (J).
        gained: f64,
        /// The kinetic energy before the impact (J).
        kinetic: f64,
    },
    /// The phase the per-point solver solves is not the one the system starts in.
    #[error(
        "model `{model}`: at release contact `{contact}` {why}, so the motion does not start in this phase; solve the system with the planner (`rodcube run`)"
    )]
    NotThisPhase {
        /// Model name.
        model: &'static str,
        /// The contact.
        contact: &'static str,
        /// What it does.
        why: &'static str,
    },
    /// The closed contacts' constraints and the mass matrix form a singular system
    /// (contacts that are redundant, or a mass matrix that is not invertible).
    #[error(
        "model `{model}` at t = {t:e} s: the equations with {closed} are singular at q = {q:?} (redundant contacts, or a singular mass matrix)"
    )]
    SingularContacts {
        /// Model name.
        model: &'static str,
        /// Time.
        t: f64,
        /// The closed contacts and friction modes.
        closed: ContactSet,
        /// Coordinates.
        q: Vec<f64>,
    },
    /// The friction contacts switched between sticking and sliding too often (chatter).
    #[error(
        "model `{model}`: the friction contacts switched {switches} times by t = {t:e} s; stopped (the switches accumulate)"
    )]
    TooManySwitches {
        /// Model name.
        model: &'static str,
        /// Switches made.
        switches: usize,
        /// Time reached.
        t: f64,
    },
    /// The mass matrix could not be solved.
    #[error("singular mass matrix at t = {t:e} s, q = {q:?}")]
    SingularMassMatrix {
        /// Time.
        t: f64,
        /// Coordinates.
        q: Vec<f64>,
    },
    /// The ODE right-hand side or an event function was not finite.
    #[error("ODE: {what} not finite at t = {t:e} s, y = {y:?}")]
    OdeNonFinite {
        /// Which value.
        what: &'static str,
        /// Time.
        t: f64,
        /// State.
        y: Vec<f64>,
    },
    /// The ODE step size fell below what `f64` can resolve.
    #[error("ODE step size {h:e} s too small at t = {t:e} s")]
    StepSizeTooSmall {
        /// Time.
        t: f64,
        /// Step size.
        h: f64,
    },
    /// The mass matrix is too ill-conditioned for the unreduced equations to mean anything.
    #[error(
        "model `{model}`: the mass matrix's condition number {condition:e} leaves the unreduced equations no accuracy (tolerance floor {rtol:e})"
    )]
    IllConditioned {
        /// Model name.
        model: &'static str,
        /// Condition number at release.
        condition: f64,
        /// The tolerance it would need.
        rtol: f64,
    },
    /// The ODE took too many steps.
    #[error("ODE gave up after {steps} steps at t = {t:e} s (limit t = {t_max:e} s)")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// Steps taken.
        steps: u64,
        /// The time limit.
        t_max: f64,
    },
    /// The ODE reached its time limit without an event.
    #[error("ODE reached t = {t_max:e} s without the separation or floor event")]
    NoEvent {
        /// The time limit.
        t_max: f64,
    },
    /// A quantity of the energy integral was asked where the motion does not start on a fast
    /// phase.
    #[error("model `{model}` does not start on the fast path: {why}")]
    NotOnFastPath {
        /// Model name.
        model: &'static str,
        /// Why.
        why: String,
    },
    /// A phase's model is not in the registry.
    #[error("system `{system}` continues with `{name}`, which is not in the registry")]
    UnknownPhaseModel {
        /// The system.
        system: &'static str,
        /// The missing model.
        name: &'static str,
    },
    /// A phase model whose parameters or coordinates do not fit its system's.
    #[error("phase `{name}` of system `{system}` does not fit it: {why}")]
    PhaseMismatch {
        /// The system.
        system: &'static str,
        /// The phase model.
        name: &'static str,
        /// What does not fit.
        why: String,
    },
    /// The per-point solver handles separations that are polynomial roots, without edges.
    #[error(
        "model `{model}` is not for the per-point solver: {why}; solve it with the planner (`rodcube run`)"
    )]
    NotPerPoint {
        /// Model name.
        model: &'static str,
        /// What it lacks.
        why: &'static str,
    },
    /// A phase the motion does not have was asked for (an index past its solved phases).
    #[error("phase {index} was asked of a motion with {solved} solved phase(s)")]
    NoSuchPhase {
        /// The index asked (from 0).
        index: usize,
        /// How many phases are solved.
        solved: usize,
    },
    /// Phases kept separating without reaching the floor.
    #[error("more than {limit} phases without reaching the floor")]
    TooManyPhases {
        /// The limit.
        limit: usize,
    },
    /// Fewer than two samples asked for a series.
    #[error("a series needs at least 2 samples, got {samples}")]
    TooFewSamples {
        /// Samples asked.
        samples: usize,
    },
}
