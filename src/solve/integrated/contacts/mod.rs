//! Contacts and friction at one state: which contacts are closed and how each friction
//! contact moves ([`Active`]), the accelerations and forces that follow ([`dynamics()`]), and the
//! one consistent choice where they may change ([`decide()`]).
//!
//! With `n` coordinates, the closed contacts that the model does not eliminate (constraint
//! rows `J_r`, bias `b_r`) and the frictions of closed contacts (slip rows `T_j`, bias `c_j`),
//! the unknowns are `qdd`, the rows' forces `lambda_r` and the friction forces `f_j`:
//!
//! - `M qdd - J^T lambda - T^T f = F` (a contact's force acts through its gap's gradient, a
//!   friction's through its slip velocity's);
//! - `J_r qdd + b_r = 0` for every closed row (its gap stays zero);
//! - sliding with slip sign `s`: `f_j + s mu_j lambda_j = 0`, `lambda_j` the force of its
//!   contact; sticking: `T_j qdd + c_j = 0` (the slip velocity stays zero).
//!
//! A contact the model eliminates has its force in closed form
//! ([`Bound::forces_full`](crate::system::Bound::forces_full)).
//!
//! Which contacts are closed is a linear complementarity problem at the acceleration level:
//! among the contacts that touch without moving apart (gap and normal velocity zero), find the
//! set whose forces push (`lambda >= 0`) while every other accelerates apart (normal
//! acceleration `J qdd + b >= 0`). For a handful of contacts every subset is tried
//! ([`MAX_COMBINATIONS`] with the frictions' modes). Frictionless rigid bodies give one
//! acceleration; with friction a contact at rest that can stick does stick (the rule of the
//! rigid-body literature), and no consistent choice, or several with as many stuck contacts and
//! different motions (Painlevé), is
//! [`SolveError::Indeterminate`](crate::solve::SolveError::Indeterminate), naming the time and the
//! contacts, never a guess.
//!
//! [`dynamics`](mod@dynamics) solves one set; [`decide`](mod@decide) chooses the set.

pub mod decide;
pub mod dynamics;

pub use crate::solve::integrated::active::{Active, DECIDE_TOLERANCE, Mode, Sign, check_active};
pub use decide::*;
pub use dynamics::*;

/// Most combinations of contact states and friction modes tried at one decision.
pub const MAX_COMBINATIONS: usize = 4096;

/// A contact or friction at rest is one whose speed is below this fraction of the speeds it
/// is made of.
pub const REST: f64 = 1e-9;

/// Where sliding is given up as Painlevé's singularity: the system's determinant with the
/// sliding frictions over the one without them ([`Dynamics::painleve`]) has fallen to this.
pub const PAINLEVE_FLOOR: f64 = 1e-3;

/// The rounding a stuck friction may pass Coulomb's cone by and still stick: relative to
/// `mu N`, and to the largest force of the set (what a friction that must be zero, `mu = 0`,
/// comes out as when the slip's free acceleration vanishes). Far below [`DECIDE_TOLERANCE`],
/// so a friction `1e-9` short of what sticking needs still slides.
pub const STICK_ROUNDING: f64 = 1e-12;
