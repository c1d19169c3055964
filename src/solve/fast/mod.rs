//! The fast route: a phase with one coordinate left, solved through its energy integral. Where
//! the phase ends ([`separation`], on [`poly`]), its time by [`quadrature`] and the inverse
//! ([`inversion`]), the per-point solvers ([`lean`], with [`prior`]'s certified bounds) and
//! their parameter derivatives ([`sensitivity`]).

pub mod inversion;
pub mod lean;
pub mod poly;
pub mod prior;
pub mod quadrature;
pub mod sensitivity;
pub mod separation;
