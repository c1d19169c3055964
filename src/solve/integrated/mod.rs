//! The integrated route: the general model `M(q) qdd = F(q, qd)` with its contacts' forces.
//! The [`ode`] integrator, one phase of it ([`unreduced`]), the contacts' dynamics and the
//! choice of the active set ([`contacts`], with [`active`] and [`rest`]), impacts
//! ([`impact`]), forward sensitivities through phases and impacts ([`forward`],
//! [`saltation`]) and how finely the state's rounding lets a run place its end ([`resolution`]).

pub mod active;
pub mod contacts;
pub mod forward;
pub mod impact;
pub mod ode;
pub mod resolution;
pub mod rest;
pub mod saltation;
pub mod unreduced;
