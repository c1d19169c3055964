//! How finely an integrated run can place the event that ended it (a contact's force reaching
//! zero, its gap closing, its edge reached): the state's own rounding moves the event's function
//! by an amount that no tolerance of the integrator can remove, and the event's time by that
//! over the function's rate. A spring whose stretch is a difference of nearly equal
//! coordinates (a rod lying at `a/ell = 1e-8` moves its cube by `3e-17` of the cube's place) is
//! lost to rounding there.

use crate::results::EndCause;
use crate::solve::SolveError;
use crate::solve::integrated::contacts::{self, DynamicsWork, Tangent, TangentAt};
use crate::solve::integrated::unreduced::UnreducedRun;
use crate::system::{Bound, State};

/// For a run ended by a contact's event (its force reaching zero, its gap closing, its edge
/// reached): `(end, r)` with `r` the relative uncertainty of the end's time that the rounding
/// of the state there makes. The event's function (the force, the gap, the edge margin)
/// changes by that rounding by the sum over each coordinate and velocity of its derivative, by
/// [`contacts::tangent_into`], times that value's error: its rounding `eps |value|`, and at
/// most its deviation from the segment's start, which the integrator holds apart; `r` is that
/// change over the function's swing (its rate at the end times the run's time, or its value at
/// the start where that is larger). `None` for a run ended otherwise, for a function that does
/// not start positive, and for a model without the derivatives ([`crate::model::Tangents`]).
///
/// A rod lying at `a/ell = 1e-8` on `rod_cube_spring`'s stiff spring (`k = 5000`): `r = 3.9e-8`,
/// where the run's time is `3.9e-8` off a 40-digit reference; at `a/ell = 1.3e-9` on a weak
/// one, `r = 1.1e-11` against `1.1e-11` (`docs/references/flat_spring_separation.py`).
pub fn end_resolution(
    sys: &Bound,
    run: &UnreducedRun,
) -> Result<Option<(EndCause, f64)>, SolveError> {
    let (contact, measure) = match run.end {
        EndCause::Force(c) => (c, Measure::Force),
        EndCause::Contact(c) => (c, Measure::Gap),
        EndCause::Edge(c) => (c, Measure::Edge),
        EndCause::Impact | EndCause::Floor | EndCause::Until => return Ok(None),
    };
    if sys.model().tangents().is_none() {
        return Ok(None);
    }
    let (Some(first), Some(last)) = (run.segments.first(), run.segment_at(run.t_end)) else {
        return Err(no_segment(run));
    };
    let info = sys.info();
    let (i, n, m, nf) = (
        contact.index,
        sys.n_coordinates(),
        info.contacts.len(),
        info.frictions.len(),
    );
    let (Some(q0), Some(qd0)) = (first.y0.get(..n), first.y0.get(n..2 * n)) else {
        return Err(no_segment(run));
    };
    let start = State::new(q0.to_vec(), qd0.to_vec())?;
    let values = match measure {
        Measure::Force => contacts::dynamics(sys, &start, &first.active, first.t_start)?.forces,
        Measure::Gap => sys.gaps(&start)?,
        Measure::Edge => sys.edges(&start)?,
    };
    let Some(&scale) = values.get(i) else {
        return Err(SolveError::PhaseMismatch {
            system: info.system,
            name: info.name,
            why: format!("the run ended at contact {i}, which the system does not have"),
        });
    };
    // A NaN does not start positive either.
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
    // each that error; then the motion itself, `(qd, qdd)`, whose derivative is the rate.
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
    // The event function's derivative along direction `j`: a contact's force, or its row of
    // the tangent rows (`n` residuals, `m` normal and `nf` slip accelerations, then the `m`
    // gaps and the `m` edge margins).
    let rows = n + 3 * m + 2 * nf;
    let along = |j: usize| match measure {
        Measure::Force => out.forces[j * m + i],
        Measure::Gap => out.rows[j * rows + n + m + nf + i],
        Measure::Edge => out.rows[j * rows + n + 2 * m + nf + i],
    };
    let noise: f64 = (0..2 * n).map(|j| along(j).abs()).sum();
    // The function's swing over the run: its rate at the end over the run's time, or its value
    // at the start where the rate is smaller (a function that ends by grazing zero).
    let swing = (along(2 * n).abs() * run.t_end).max(scale);
    Ok(Some((run.end, noise / swing)))
}

/// What a contact's event measures.
#[derive(Clone, Copy)]
enum Measure {
    /// Its force (reaching zero).
    Force,
    /// Its gap (closing).
    Gap,
    /// Its edge margin (reaching the edge).
    Edge,
}

/// The error of a run that holds no segment, none with a step at its end, or a segment start
/// shorter than its state (the integrator ends every run it returns with a whole one; only a
/// run built by hand can lack it).
fn no_segment(run: &UnreducedRun) -> SolveError {
    SolveError::Inversion {
        target: run.t_end,
        duration: run.t_end,
        reason: "an integrated phase without a step at its end",
    }
}
