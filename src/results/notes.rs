//! What a reader should know about a run that is not a number: why a wanted quantity has no
//! value and how the motion was followed, each a [`Note`] of names, keywords and numbers
//! (`report::prose` writes the sentence).

use super::{ContactSet, EndCause, Holding};

/// How many times the integrator's own relative tolerance the cross-check's event time may lie
/// from the fast path's before [`Note::CrossCheckApart`] says so. Over `tests/plan.rs`' grid of
/// extreme mass ratios, angles at release and tolerances the two agree within 1.1 times that
/// tolerance (raised to the mass matrix's conditioning floor); a hundredfold is no rounding.
pub const CROSS_CHECK_APART: f64 = 100.0;

/// How many times an integrated phase's relative tolerance the rounding of its state may make
/// the time of the contact's event that ended it uncertain before [`Note::EndUnresolved`] says
/// so (the planner runs the integrator at a hundredth of the tolerance asked, never below
/// `1e-13`, so this is the tolerance asked or `1e-11`, whichever is larger).
pub const END_UNRESOLVED: f64 = 100.0;

/// Why the motion stopped before its end (the solver's halt).
#[derive(Debug, Clone, PartialEq)]
pub enum Halt {
    /// A contact closed as the contact before it opened, where the run ends at its first
    /// impact.
    ClosesAsOneOpens {
        /// The contact that closed.
        contact: String,
        /// When (s from release).
        t: f64,
    },
    /// The run stopped at its impact limit: the bounces neither came to rest nor converged.
    TooManyImpacts {
        /// The number of the impact it stopped at.
        number: usize,
        /// When (s from release).
        t: f64,
    },
    /// An impact left the system at rest.
    AtRest {
        /// When (s from release).
        t: f64,
        /// How the supports hold it.
        held: Holding,
        /// The supports that hold it.
        set: ContactSet,
    },
}

/// A converging (Zeno) sequence of bounces, closed by a plastic impact.
#[derive(Debug, Clone, PartialEq)]
pub enum Zeno {
    /// The intervals between bounces shrank by a steady ratio, and their limit was within the
    /// run's tolerance of a bounce.
    Limit {
        /// The contacts that closed in it: one that bounced, or two that struck in turn.
        contacts: Vec<String>,
        /// How many impacts of the sequence were resolved one by one.
        bounces: usize,
        /// The mean ratio of successive intervals.
        ratio: f64,
        /// The limit of the bounces' times (s from release).
        t_limit: f64,
        /// The bounce made plastic (s from release).
        t: f64,
    },
    /// A bounce too small to open the gap: the rest of the sequence summed as a geometric
    /// series (each period's flights the impacts' gains times the one's before) and taken as
    /// one plastic impact at its limit.
    Unresolved {
        /// The contacts of the sequence: the one that would bounce, or the two that strike in
        /// turn (the one that would lift first).
        contacts: Vec<String>,
        /// When (s from release).
        t: f64,
        /// How far it would rise, relative to the length scale.
        rise: f64,
        /// The relative gap at which a contact counts as open.
        open_gap: f64,
        /// How many impacts of the sequence were resolved one by one (this one among them).
        bounces: usize,
        /// The limit of the bounces' times, the accumulation time (s from release).
        t_limit: f64,
    },
}

/// Until when a contact held.
#[derive(Debug, Clone, PartialEq)]
pub enum Held {
    /// Until the body landed, where the named contact closed.
    Lands {
        /// The contact that closed.
        contact: String,
        /// When (s from release).
        t: f64,
    },
    /// Until the motion was halted.
    Halted(Halt),
    /// Until the run's end time.
    RunsEnd {
        /// When (s from release).
        t: f64,
    },
    /// Until the reduced angle reached the model's end angle.
    Floor {
        /// The reduced coordinate's name.
        angle: String,
        /// The end angle (rad).
        end_angle: f64,
    },
    /// Until the named contact ran off an edge, where the motion stops.
    Edge {
        /// The contact.
        contact: String,
        /// When (s from release).
        t: f64,
    },
}

/// How the motion ended before the body landed.
#[derive(Debug, Clone, PartialEq)]
pub enum Unlanded {
    /// The motion's last phase ended this way (an edge, a contact closing where the run ends at
    /// its first impact, the run's end).
    At(EndCause),
    /// The motion was halted.
    Halted(Halt),
    /// The motion ended otherwise.
    Ended,
}

/// How the motion went with respect to the run's end time (`until`).
#[derive(Debug, Clone, PartialEq)]
pub enum UntilNote {
    /// The motion was halted.
    Halted(Halt),
    /// It was followed to the run's end.
    Reached {
        /// The end (s from release).
        t: f64,
        /// The impacts on the way.
        impacts: usize,
    },
    /// It ended before the run's end.
    EndedBefore {
        /// When (s from release).
        t: f64,
        /// Why, where the last phase says.
        cause: Option<EndCause>,
        /// The run's end (s).
        until: f64,
        /// The impacts on the way.
        impacts: usize,
    },
}

/// Why a wanted quantity has no value, or what the motion needs said, under its key in
/// [`RunResults::notes`](super::RunResults).
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// A refusal: the error's message (the cross-check's matrix too ill-conditioned, an
    /// impact with friction).
    Refused(String),
    /// The first contact ended by another cause than its force (its edge, another contact
    /// closing, an impact), so it does not separate.
    NoSeparationEnded {
        /// The contact.
        contact: String,
        /// Why it ended.
        cause: EndCause,
    },
    /// The first contact held, so it does not separate.
    NoSeparationHolds {
        /// The contact.
        contact: String,
        /// Until when.
        held: Held,
    },
    /// The first contact is open at release, so it does not separate.
    NoSeparationOpen {
        /// The contact.
        contact: String,
    },
    /// The linearised separation polynomial has no root between the floor and the start.
    NoLinearisedRoot,
    /// A contact held.
    Holds {
        /// The contact.
        contact: String,
        /// Until when.
        held: Held,
    },
    /// A contact is open at release.
    OpenAtRelease {
        /// The contact.
        contact: String,
    },
    /// The cross-check's integrated route ended at another event than the fast path.
    CrossCheckDisagrees {
        /// The integrated route's event.
        integrated: EndCause,
        /// The fast path's event.
        fast: EndCause,
    },
    /// The cross-check's integrated route reached the fast path's event at a time further from
    /// the fast path's than [`CROSS_CHECK_APART`] times the tolerance the integrator ran
    /// with: one of the two routes is ill-conditioned at these parameters.
    CrossCheckApart {
        /// `|t_ode - t_quadrature| / t_quadrature`.
        relative: f64,
        /// The integrator's relative tolerance (the one asked, raised to the mass matrix's
        /// conditioning floor).
        rtol: f64,
    },
    /// An integrated phase ended at a contact's event (its force reaching zero, its gap
    /// closing, its edge reached), but the rounding of its state makes that time uncertain by
    /// more than [`END_UNRESOLVED`] times the phase's tolerance.
    EndUnresolved {
        /// The event.
        end: EndCause,
        /// When the phase ended (s from release).
        t: f64,
        /// The relative uncertainty of that time.
        fraction: f64,
        /// The phase's relative tolerance.
        rtol: f64,
    },
    /// The body did not land.
    NoLanding {
        /// When the motion ended (s from release).
        t: f64,
        /// The phases it went through, in order.
        path: Vec<String>,
        /// How it ended.
        end: Unlanded,
    },
    /// The run ends at its first impact.
    FirstImpactEnds {
        /// When (s from release).
        t: f64,
    },
    /// No contact closed before the motion's end.
    NoImpact {
        /// The phases the motion went through, in order.
        path: Vec<String>,
    },
    /// How the motion went with respect to the run's end time.
    Until(UntilNote),
    /// The converging sequences of bounces closed, in order.
    Zeno(Vec<Zeno>),
    /// A wanted sensitivity that has no number, and why.
    NoSensitivity(SensitivityGap),
    /// The model ran from its tape (`generated/<model>.tape.json`) rather than compiled code.
    FromTape {
        /// The model.
        model: String,
        /// The tape's file.
        file: String,
        /// Why.
        why: TapeReason,
    },
    /// The spec the model was derived from has changed since: the results are of the model as
    /// last derived.
    SpecChanged {
        /// The model.
        model: String,
        /// The spec's file.
        spec: String,
    },
}

/// Why a model ran from its tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TapeReason {
    /// Asked for (`--interpreted`).
    Asked,
    /// No model of its name is compiled in.
    NotCompiled,
    /// The compiled model of its name is another program (derived again since).
    DiffersFromCompiled,
    /// Derived from its spec (the note's file) for this run.
    DerivedNow,
}

/// Why a result has no sensitivities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensitivityGap {
    /// The contact opens at release: the time is zero and the angle the release angle's
    /// whatever the parameters; there is no separation to differentiate.
    AtRelease,
    /// The first contact does not separate on the fast phase the motion starts on.
    NoSeparation,
    /// The result is of an impact's impulses, velocities or energy lost, which are not
    /// differentiated (its time is).
    NotBuilt,
    /// The result comes after an impact whose map has no derivatives (a restitution given by
    /// an expression of the parameters, or redundant contacts taking part).
    PastImpact,
    /// The result is the limit of a converging (Zeno) sequence of bounces whose last times
    /// do not give its accumulation time's derivatives (fewer than four impacts resolved, or
    /// a geometric series through them that does not fit the accumulation time).
    PastZeno,
    /// An event on the way to the result is grazing (its function's rate is zero there), where
    /// the time does not move smoothly with the parameters.
    Grazing,
    /// The integrated route that carries the sensitivities ends the result's contact otherwise
    /// (by another event, or at a time that differs from the run's by more than the tolerance
    /// the two routes are held to) than the route the run took.
    RoutesDisagree,
    /// The integrated route that carries the sensitivities failed where the run's route did
    /// not.
    IntegrationFailed,
    /// The model has no generated partial derivatives.
    NoPartials,
    /// The fast phase has no fall polynomial, which the time's sensitivities need.
    NoFallPolynomial,
    /// The separation is a double root of its condition.
    DoubleRoot,
    /// The result's unit over a parameter's cannot be formed (a parameter's unit that does not
    /// read as a unit, or a quotient whose powers overflow).
    NoUnit,
    /// The parameter is the coefficient of restitution of a contact that struck plastically
    /// (it is zero) before the result: any value above zero makes that contact bounce, a
    /// motion of other events, so the derivative in it is one-sided and not the plastic
    /// law's.
    OneSided,
}
