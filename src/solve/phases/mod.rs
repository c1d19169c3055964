//! Phases of the motion of a system: at release, and after every event, the contacts that stay
//! closed are decided ([`contacts::decide`]); each stretch with one set of closed contacts is
//! a phase, solved on the fast path where the system has a fast phase for that set, otherwise
//! by integrating the general model with the closed contacts as constraints; the motion goes on
//! from phase to phase until the rod reaches the floor, a contact runs off an edge, or an open
//! contact closes (the bodies meet). Where the run is asked to go on to a time (`until`), a
//! contact that closes is an impact ([`impact::resolve`]): the velocities jump by the impulses
//! of Newton's law with complementarity, the contacts are decided again at the state after,
//! and the motion goes on to that time; bounces whose times converge (Zeno) are caught.
//!
//! A fast phase that starts from a given state takes it as parameters (`<q>_0`,
//! `<q>_dot_0`, bound from the system's state by coordinate name); the one that starts from
//! the spec's release state serves only at release. A phase's clock restarts at zero; the
//! absolute time of its start is kept in [`PhaseRun::t_start`].
//!
//! `reduced.rs` holds a phase on the fast path ([`ReducedRun`], [`phase_end`]); `run.rs` a
//! phase on either route ([`PhaseRun`]); `motion.rs` the [`Motion`] with its [`ImpactAt`]s;
//! `walker.rs` the [`Walker`] that solves it; `zeno.rs` converging sequences of impacts and
//! their accumulation time; `sensitive.rs` the motion with the forward sensitivities of its
//! phases' ends ([`SensitiveMotion`]).
//!
//! [`contacts::decide`]: fn@crate::solve::integrated::contacts::decide
//! [`impact::resolve`]: crate::solve::integrated::impact::resolve

mod motion;
mod reduced;
mod run;
mod sensitive;
mod walker;
mod zeno;

pub use motion::{ImpactAt, Motion};
pub use reduced::{GAP_CELLS, ReducedEnd, ReducedRun, phase_end};
pub use run::{IntegratedRun, PhaseRun};
pub use sensitive::{EndDerivatives, SensitiveMotion, Stop};
pub use walker::{
    LANDING_TOLERANCE, MAX_FALL_TIMES, MAX_IMPACTS, MAX_PHASES, PhaseStart, Route, Walker,
    fall_time_scale, phase_parameters,
};
pub use zeno::{ZENO_AGREE, ZENO_RATIO_SPREAD, ZENO_RATIOS};
