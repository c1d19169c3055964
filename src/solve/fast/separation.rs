//! Where a fast phase's closed contacts end: the root of a contact's force polynomial in
//! `s = sin(theta)` where its force first reaches zero coming down from `theta_i`, found to full
//! `f64` precision (the first contact's is the separation); and, for a force whose zero is no
//! polynomial root or a contact with an edge, the first sign change of the reduced force (or of
//! the edge margin) as a function of the angle fallen, bracketed on a grid and refined by
//! [`roots::illinois`].
//!
//! The polynomial's roots come from the one isolator, [`poly`].

use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::fast::poly;
use crate::solve::roots::{self, changes_sign};
use crate::system::System;

/// Grid cells over the fall, uniform in `u = sqrt(delta)`, on which a numeric root is
/// bracketed (the first cell whose ends differ in sign; a pair of roots inside one cell, a
/// touch without a crossing, is not seen).
pub const BRACKET_CELLS: usize = 256;

/// Where a phase with a contact separates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separation {
    /// `sin(theta_sep)`.
    pub sin_theta: f64,
    /// `theta_sep` (rad).
    pub theta: f64,
    /// `delta_sep = theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// The outcome of looking for a separation between `theta_i` and the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeparationOutcome {
    /// The contact force vanishes at this angle.
    Separates(Separation),
    /// The polynomial has no sign change between the floor and `theta_i`: contact is kept.
    NoSeparationBeforeFloor,
}

impl SeparationOutcome {
    /// The separation, if there is one.
    pub fn separation(&self) -> Option<Separation> {
        match self {
            SeparationOutcome::Separates(s) => Some(*s),
            SeparationOutcome::NoSeparationBeforeFloor => None,
        }
    }
}

/// The separation of a system: where its first contact's force reaches zero
/// ([`force_zero`] of contact 0).
pub fn separation(sys: &System, work: &mut Work) -> Result<SeparationOutcome, SolveError> {
    force_zero(sys, 0, work)
}

/// `Ok` when `contact` is closed in the phase and `also` holds for it, else
/// [`SolveError::NoContact`] (`edge` says whether an edge was asked for).
fn closed_contact(
    sys: &System,
    contact: usize,
    edge: bool,
    also: impl Fn(&crate::model::ContactInfo) -> bool,
) -> Result<(), SolveError> {
    let info = sys.info();
    if info
        .contacts
        .get(contact)
        .is_some_and(|c| c.closed && also(c))
    {
        Ok(())
    } else {
        Err(SolveError::NoContact {
            model: info.name,
            contact,
            edge,
        })
    }
}

/// Where a closed contact's force reaches zero coming down from `theta_i`: the largest
/// sign-changing root of its force polynomial in `(sin(end_angle), sin(theta_i))`, or without
/// one the first sign change of its reduced force. A contact that is not closed in the phase is
/// [`SolveError::NoContact`].
pub fn force_zero(
    sys: &System,
    contact: usize,
    work: &mut Work,
) -> Result<SeparationOutcome, SolveError> {
    closed_contact(sys, contact, false, |c| !c.bilateral)?;
    let Some(coeffs) = sys.force_coefficients(contact) else {
        // `contact` is one of the model's (checked above).
        let force = |sys: &System, delta: f64| Ok(sys.forces(delta)?[contact]);
        return first_zero(sys, force, work);
    };
    let (lo, hi) = bracket(sys)?;
    Ok(
        match separation_root(sys.info().name, &coeffs, lo, hi, &mut work.polynomial_evals)? {
            Some(s) => SeparationOutcome::Separates(at_sine(sys, s)),
            None => SeparationOutcome::NoSeparationBeforeFloor,
        },
    )
}

/// The separation root of a model's polynomial (coefficients lowest degree first): its largest
/// sign-changing root in `(lo, hi)`, `None` when there is none; coefficients that are not all
/// finite, all zero, or of a degree above [`poly::MAX_DEGREE`] are a
/// [`SolveError::BadPolynomial`]. The planner and the per-point solver both call it.
#[inline]
pub fn separation_root(
    model: &'static str,
    coeffs: &[f64],
    lo: f64,
    hi: f64,
    evals: &mut u64,
) -> Result<Option<f64>, SolveError> {
    let bad = || SolveError::BadPolynomial {
        model,
        coefficients: coeffs.to_vec(),
    };
    if coeffs.iter().any(|c| !c.is_finite()) || coeffs.iter().all(|&c| c == 0.0) {
        return Err(bad());
    }
    poly::largest_root(coeffs, lo, hi, evals).ok_or_else(bad)
}

/// Where a closed contact runs off its edge: the first zero of its edge margin, which on the
/// fast path depends on the angle alone (the derivation checks it). A contact that is not
/// closed with an edge in the phase is [`SolveError::NoContact`].
pub fn edge(
    sys: &System,
    contact: usize,
    work: &mut Work,
) -> Result<SeparationOutcome, SolveError> {
    closed_contact(sys, contact, true, |c| c.edge)?;
    // `contact` is one of the model's (checked above).
    let margin =
        |sys: &System, delta: f64| Ok(sys.edges(&sys.full_state(0.0, delta, 0.0)?)?[contact]);
    first_zero(sys, margin, work)
}

/// The first sign change of `f(delta)` coming down from the start: bracketed on
/// [`BRACKET_CELLS`] cells uniform in `sqrt(delta)` (fine near the start, where the fall is
/// slow), then refined to adjacent floats. Each evaluation counts as a polynomial evaluation;
/// one that fails is the error.
pub fn first_zero(
    sys: &System,
    f: impl Fn(&System, f64) -> Result<f64, SolveError>,
    work: &mut Work,
) -> Result<SeparationOutcome, SolveError> {
    let end = sys.delta_to_floor();
    let model = sys.info().name;
    let mut value = |delta: f64| -> Result<f64, SolveError> {
        work.polynomial_evals += 1;
        let v = f(sys, delta)?;
        if v.is_nan() {
            return Err(SolveError::NonFinite {
                model,
                what: "contact force or edge margin",
                delta,
                value: v,
            });
        }
        Ok(v)
    };
    // At the start itself the contact holds (a force of zero there is no separation yet).
    let u_end = end.sqrt();
    let mut a = (0.0, value(0.0)?);
    if a.1 == 0.0 {
        let tiny = (u_end / BRACKET_CELLS as f64 * 1e-6).powi(2);
        a = (tiny, value(tiny)?);
    }
    for i in 1..=BRACKET_CELLS {
        let u = u_end * i as f64 / BRACKET_CELLS as f64;
        let delta = if i == BRACKET_CELLS { end } else { u * u };
        // A model may be singular at the floor itself (a cylinder's tangent point runs off to
        // infinity as theta -> 0): no value there means no zero met before it.
        if i == BRACKET_CELLS && f(sys, delta)?.is_nan() {
            break;
        }
        let b = (delta, value(delta)?);
        if changes_sign(a.1, b.1) {
            let delta = roots::illinois(&mut value, a, b)?;
            let theta = sys.theta_initial() - delta;
            return Ok(SeparationOutcome::Separates(Separation {
                sin_theta: theta.sin(),
                theta,
                delta,
            }));
        }
        a = b;
    }
    Ok(SeparationOutcome::NoSeparationBeforeFloor)
}

/// The paper's approximation: the root of the polynomial with its terms above degree 1 dropped.
pub fn linearised_separation(sys: &System) -> Result<SeparationOutcome, SolveError> {
    let coeffs = sys.separation_coefficients();
    if coeffs.is_empty() {
        return Err(SolveError::NoContact {
            model: sys.info().name,
            contact: 0,
            edge: false,
        });
    }
    let (lo, hi) = bracket(sys)?;
    let (c0, c1) = (coeffs[0], coeffs.get(1).copied().unwrap_or(0.0));
    if c1 == 0.0 {
        return Ok(SeparationOutcome::NoSeparationBeforeFloor);
    }
    let s = -c0 / c1;
    Ok(if s > lo && s < hi {
        SeparationOutcome::Separates(at_sine(sys, s))
    } else {
        SeparationOutcome::NoSeparationBeforeFloor
    })
}

/// The open interval `(sin(end_angle), sin(theta_i))` the phase's roots lie in.
fn bracket(sys: &System) -> Result<(f64, f64), SolveError> {
    let hi = sys.reduced(0.0)?.sin;
    let lo = sys.end_angle().sin();
    if !hi.is_finite() {
        return Err(SolveError::NonFinite {
            model: sys.info().name,
            what: "sin(theta_i)",
            delta: 0.0,
            value: hi,
        });
    }
    Ok((lo, hi))
}

/// The angle of a root in `s`: `theta = asin(s)`, `delta = theta_i - theta`.
fn at_sine(sys: &System, s: f64) -> Separation {
    let theta = s.asin();
    Separation {
        sin_theta: s,
        theta,
        delta: sys.theta_initial() - theta,
    }
}
