//! The whole motion, phase after phase ([`Motion`]), with the impacts between its phases
//! ([`ImpactAt`]), why it halted and its notes.

use super::run::PhaseRun;
use crate::results::EndCause;
use crate::results::{Halt, Zeno};
use crate::solve::SolveError;
use crate::solve::integrated::impact::{Impact, Part};

/// An impact between two phases of a motion.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactAt {
    /// Absolute time (s from release).
    pub t: f64,
    /// The phase that ended with it (an index into [`Motion::phases`]; the next one starts
    /// from its state after).
    pub phase: usize,
    /// The contact whose gap closed.
    pub closing: usize,
    /// Each contact's part in it.
    pub parts: Vec<Part>,
    /// The impulses, the normal velocities and the state after.
    pub impact: Impact,
    /// Where this impact closed a converging (Zeno) sequence of bounces, made plastic: the
    /// sequence's accumulation time (s from release), extrapolated from its bounces. The
    /// impact is listed there; the motion after it starts at `t` with the contact closed (the
    /// closed contact's motion is what the ever smaller bounces tend to), and a system the
    /// impact leaves at rest comes to rest at the accumulation time.
    pub zeno: Option<f64>,
}

/// The whole motion, phase after phase.
#[derive(Debug, Clone)]
pub struct Motion<'m> {
    /// The phases in order; the last one reaches the floor, an edge, a closing contact (where
    /// the run does not go on through impacts) or the run's end.
    pub phases: Vec<PhaseRun<'m>>,
    /// The contacts that touched at release but opened at once (their force would have had to
    /// pull).
    pub opened_at_release: Vec<usize>,
    /// The impacts between phases, in order.
    pub impacts: Vec<ImpactAt>,
    /// Whether a contact that closes is an impact the motion goes on through (the run has an
    /// end time), or the end of the motion.
    pub through_impacts: bool,
    /// Why the motion stopped before its end, if it did (too many impacts).
    pub halted: Option<Halt>,
    /// What the reader should know about how the motion was followed: each converging (Zeno)
    /// sequence of bounces closed.
    pub notes: Vec<Zeno>,
}

impl<'m> Motion<'m> {
    /// A motion of its first phase.
    pub fn starting(first: PhaseRun<'m>, opened_at_release: Vec<usize>, through: bool) -> Self {
        Motion {
            phases: vec![first],
            opened_at_release,
            impacts: Vec::new(),
            through_impacts: through,
            halted: None,
            notes: Vec::new(),
        }
    }

    /// Absolute time the last phase ends (s).
    pub fn end_time(&self) -> f64 {
        self.phases.last().map_or(0.0, PhaseRun::t_end)
    }

    /// `theta_dot` at the end of the last phase (rad/s); an error without a reduced
    /// coordinate.
    pub fn end_angular_velocity(&self) -> Result<f64, SolveError> {
        self.phases.last().map_or(Ok(0.0), PhaseRun::theta_dot_end)
    }

    /// Why the last phase ended.
    pub fn last_end(&self) -> Option<EndCause> {
        self.phases.last().map(PhaseRun::end)
    }

    /// Whether the motion goes on after a phase that ended by `end`: after a contact that
    /// opens, and after one that closes where the run goes on through impacts.
    pub fn goes_on_after(&self, end: EndCause) -> bool {
        match end {
            EndCause::Force(_) => true,
            EndCause::Contact(_) => self.through_impacts,
            EndCause::Edge(_) | EndCause::Impact | EndCause::Floor | EndCause::Until => false,
        }
    }

    /// Whether the motion is complete: its last phase ends for good (the floor, an edge, the
    /// run's end, or a contact that closes where impacts end the run), or it was halted.
    pub fn complete(&self) -> bool {
        self.halted.is_some() || self.last_end().is_some_and(|e| !self.goes_on_after(e))
    }

    /// The impact that ended phase `k`, if one did.
    pub fn impact_after(&self, k: usize) -> Option<&ImpactAt> {
        self.impacts.iter().find(|i| i.phase == k)
    }
}
