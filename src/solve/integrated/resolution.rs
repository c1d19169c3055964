//! How finely an integrated run can place the zero of the force that ended it: the state's own
//! rounding (each coordinate and velocity known only to `eps |value|`) moves that force by an
//! amount that no tolerance of the integrator can remove. Where it is a sizeable part of the
//! force's value at the run's start, the event's time is uncertain by about that fraction: a
//! spring whose stretch is a difference of nearly equal coordinates (a rod lying at
//! `a/ell = 1e-8` moves its cube by `3e-17` of the cube's place) is lost to rounding there.

use crate::results::{ContactId, EndCause};
use crate::solve::SolveError;
use crate::solve::integrated::contacts::{self, DynamicsWork, Tangent, TangentAt};
use crate::solve::integrated::unreduced::UnreducedRun;
use crate::system::{Bound, State};

/// For a run ended by contact `c`'s force reaching zero: `(c, r)` with `r` the relative
/// uncertainty of the end's time that the rounding of the state there makes: the change of the
/// force by that rounding (the sum over each coordinate and velocity of the force's derivative,
/// by [`contacts::tangent_into`], times that value's error: its rounding `eps |value|`, and at
/// most its deviation from the segment's start, which the integrator holds apart) over the
/// force's swing (its rate at the end times the run's time, or its value at the start where
/// that is larger). `None` for a run ended otherwise, for a force that does not push at the
/// start, and for a model without the derivatives ([`crate::model::Tangents`]).
///
/// A rod lying at `a/ell = 1e-8` on `rod_cube_spring`'s stiff spring (`k = 5000`): `r = 3.9e-8`,
/// where the run's time is `3.9e-8` off a 40-digit reference; at `a/ell = 1.3e-9` on a weak
/// one, `r = 1.1e-11` against `1.1e-11` (`docs/references/flat_spring_separation.py`).
pub fn force_resolution(
    sys: &Bound,
    run: &UnreducedRun,
) -> Result<Option<(ContactId, f64)>, SolveError> {
    let EndCause::Force(contact) = &run.end else {
        return Ok(None);
    };
    if sys.model().tangents().is_none() {
        return Ok(None);
    }
    let (Some(first), Some(last)) = (run.segments.first(), run.segment_at(run.t_end)) else {
        return Err(no_segment(run));
    };
    let i = contact.index;
    let n = sys.n_coordinates();
    let start = State::new(first.y0[..n].to_vec(), first.y0[n..2 * n].to_vec())?;
    let at_start = contacts::dynamics(sys, &start, &first.active, first.t_start)?;
    let info = sys.info();
    let Some(&scale) = at_start.forces.get(i) else {
        return Err(SolveError::PhaseMismatch {
            system: info.system,
            name: info.name,
            why: format!("the run ended at contact {i}, which the system does not have"),
        });
    };
    // A NaN force does not push either.
    if scale.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Ok(None);
    }
    let end = &run.state_end;
    let mut work = DynamicsWork::default();
    contacts::dynamics_into(sys, end, &last.active, run.t_end, &mut work)?;
    let mut tan = Vec::new();
    let d = &work.out;
    sys.tangents_into(end, &d.qdd, &d.forces, &d.fr, &mut tan)?;
    // The integrator holds the deviation `z` from the segment's start `y0` and forms the state
    // as `y0 + z`: each value is off by at most its rounding, `eps |value|`, and by at most
    // `|z|` (`y0` itself is a float that near). One direction per coordinate and velocity,
    // each that error; then the motion itself, `(qd, qdd)`, whose derivative is the force's
    // rate.
    let Some(&(_, z)) = last.solution.nodes().last() else {
        return Err(no_segment(run));
    };
    let cols = 2 * n + info.parameters.len();
    let mut xi = vec![0.0; (2 * n + 1) * cols];
    for (j, (v, dz)) in end.q.iter().chain(&end.qd).zip(z).enumerate() {
        xi[j * cols + j] = (f64::EPSILON * v.abs()).min(dz.abs());
    }
    let motion = &mut xi[2 * n * cols..];
    motion[..n].copy_from_slice(&end.qd);
    motion[n..2 * n].copy_from_slice(&d.qdd);
    let at = TangentAt {
        state: end,
        t: run.t_end,
        active: &last.active,
        tan: &tan,
    };
    let mut out = Tangent::default();
    contacts::tangent_into(sys, at, &mut work, &xi, &mut out)?;
    let m = info.contacts.len();
    let noise: f64 = (0..2 * n).map(|j| out.forces[j * m + i].abs()).sum();
    // The force's swing over the run: its rate at the end over the run's time, or its value at
    // the start where the rate is smaller (a force that ends by grazing zero).
    let rate = out.forces[2 * n * m + i];
    let swing = (rate.abs() * run.t_end).max(scale);
    Ok(Some((*contact, noise / swing)))
}

/// The error of a run that holds no segment, or none with a step, at its end (the integrator
/// ends every run it returns with one; only a run built by hand can lack it).
fn no_segment(run: &UnreducedRun) -> SolveError {
    SolveError::Inversion {
        target: run.t_end,
        duration: run.t_end,
        reason: "an integrated phase without a step at its end",
    }
}
