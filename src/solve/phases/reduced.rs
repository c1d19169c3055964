//! A phase on the fast path: where it ends by its roots ([`phase_end`]: the first of its closed
//! contacts' force zeros and edges, else the floor), its time mesh, and the first of its open
//! contacts' gaps to close along it ([`ReducedRun::with_end`]).

use crate::results::Work;
use crate::results::{ContactId, EndCause};
use crate::solve::SolveError;
use crate::solve::fast::inversion::theta_dot_at;
use crate::solve::fast::quadrature::TimeMesh;
use crate::solve::fast::separation::{Separation, SeparationOutcome, edge, force_zero};
use crate::solve::integrated::contacts::DECIDE_TOLERANCE;
use crate::solve::roots::{self, changes_sign};
use crate::system::{State, System};

/// Cells of the grid, uniform in the fast path's time variable, on which an open contact's gap
/// is watched for closing (the first cell whose ends differ in sign; a touch without a crossing
/// inside one cell is not seen).
pub const GAP_CELLS: usize = 64;

/// Where a phase on the fast path ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedEnd {
    /// Why.
    pub end: EndCause,
    /// The angle where a contact ends (`None` at the floor).
    pub at: Option<Separation>,
    /// The angle fallen at the end.
    pub delta: f64,
}

/// Where a phase on the fast path ends, by its roots alone: the first of its closed contacts'
/// force zeros and edges, else the floor. A closed contact whose force pulls at the start ends
/// the phase there (`delta = 0`): it opens at once; a force that is not finite there is
/// [`SolveError::NonFinite`].
pub fn phase_end(sys: &System, work: &mut Work) -> Result<ReducedEnd, SolveError> {
    let info = sys.info();
    let at_start = sys.forces(0.0)?;
    let mut found: Option<(EndCause, Separation)> = None;
    let mut consider = |end: EndCause, outcome: SeparationOutcome| {
        if let SeparationOutcome::Separates(s) = outcome
            && found.is_none_or(|(_, f)| s.delta < f.delta)
        {
            found = Some((end, s));
        }
    };
    for (i, c) in info.contacts.iter().enumerate() {
        if !c.closed || c.bilateral {
            continue;
        }
        if !at_start[i].is_finite() {
            return Err(SolveError::NonFinite {
                model: info.name,
                what: "a closed contact's force at the phase's start",
                delta: 0.0,
                value: at_start[i],
            });
        }
        if at_start[i] < 0.0 {
            let theta = sys.theta_initial();
            return Ok(ReducedEnd {
                end: EndCause::Force(ContactId {
                    index: i,
                    name: c.name,
                }),
                at: Some(Separation {
                    sin_theta: theta.sin(),
                    theta,
                    delta: 0.0,
                }),
                delta: 0.0,
            });
        }
        consider(
            EndCause::Force(ContactId {
                index: i,
                name: c.name,
            }),
            force_zero(sys, i, work)?,
        );
    }
    for (i, c) in info.contacts.iter().enumerate() {
        if c.closed && c.edge {
            consider(
                EndCause::Edge(ContactId {
                    index: i,
                    name: c.name,
                }),
                edge(sys, i, work)?,
            );
        }
    }
    Ok(match found {
        Some((end, at)) => ReducedEnd {
            end,
            at: Some(at),
            delta: at.delta,
        },
        None => ReducedEnd {
            end: EndCause::Floor,
            at: None,
            delta: sys.delta_to_floor(),
        },
    })
}

/// A phase solved on the fast path.
#[derive(Debug, Clone)]
pub struct ReducedRun<'m> {
    /// The model and its parameters for this phase.
    pub system: System<'m>,
    /// Absolute time of the phase start (s from release).
    pub t_start: f64,
    /// Where and why it ends.
    pub end: ReducedEnd,
    /// `t(delta)` over the phase.
    pub mesh: TimeMesh,
}

impl<'m> ReducedRun<'m> {
    /// Solves the phase when the end of its closed contacts is already known, then watches its
    /// open contacts' gaps along it: one that closes first ends the phase there.
    pub fn with_end(
        sys: System<'m>,
        t_start: f64,
        end: ReducedEnd,
        tol: f64,
        work: &mut Work,
    ) -> Result<Self, SolveError> {
        if end.delta == 0.0 {
            // A contact that opens at once: a phase of no length.
            work.phases.push(sys.name().to_string());
            return Ok(ReducedRun {
                mesh: TimeMesh::empty(),
                system: sys,
                t_start,
                end,
            });
        }
        let mut mesh = TimeMesh::build(&sys, end.delta, tol, work)?;
        let mut end = end;
        if let Some((i, delta)) = first_gap_closing(&sys, &mesh, work)? {
            mesh = TimeMesh::build(&sys, delta, tol, work)?;
            let theta = sys.theta_initial() - delta;
            end = ReducedEnd {
                end: EndCause::Contact(i),
                at: Some(Separation {
                    sin_theta: theta.sin(),
                    theta,
                    delta,
                }),
                delta,
            };
        }
        work.phases.push(sys.name().to_string());
        Ok(ReducedRun {
            system: sys,
            t_start,
            end,
            mesh,
        })
    }

    /// The separation that ends it, if its first contact's force reached zero.
    pub fn separation(&self) -> Option<Separation> {
        match self.end.end {
            end if end.is_force_of(0) => self.end.at,
            _ => None,
        }
    }

    /// `theta_dot` at the end of the phase (rad/s).
    pub fn theta_dot_end(&self) -> f64 {
        theta_dot_at(&self.system, self.mesh.delta_end)
    }

    /// The full state at the end of the phase.
    pub fn end_state(&self) -> Result<State, SolveError> {
        Ok(self.system.full_state(
            self.mesh.duration,
            self.mesh.delta_end,
            self.theta_dot_end(),
        )?)
    }
}

/// The first open contact whose gap closes along a fast phase, and the angle fallen where it
/// does: each open contact's gap on [`GAP_CELLS`] cells uniform in the time variable `v`,
/// bracketed and refined by [`roots::illinois`] in the angle fallen. A gap that starts at zero
/// (a contact that has just opened) counts only once it has grown past rounding.
fn first_gap_closing(
    sys: &System,
    mesh: &TimeMesh,
    work: &mut Work,
) -> Result<Option<(ContactId, f64)>, SolveError> {
    let info = sys.info();
    let open: Vec<ContactId> = (info.contacts.iter().enumerate())
        .filter(|(_, c)| !c.closed)
        .map(|(index, c)| ContactId {
            index,
            name: c.name,
        })
        .collect();
    if open.is_empty() {
        return Ok(None);
    }
    let state_at = |delta: f64, work: &mut Work| -> Result<State, SolveError> {
        let t = mesh.time_at_delta(sys, delta, work)?;
        Ok(sys.full_state(t, delta, theta_dot_at(sys, delta))?)
    };
    let tol = DECIDE_TOLERANCE * sys.length_scale(&state_at(0.0, work)?)?;
    let mut best: Option<(ContactId, f64)> = None;
    for &i in &open {
        let mut gap = |delta: f64| -> Result<f64, SolveError> {
            let mut w = Work::default();
            let g = sys.gaps(&state_at(delta, &mut w)?)?[i.index];
            work.integrand_evals += w.integrand_evals;
            Ok(g)
        };
        let mut armed = gap(0.0)? > tol;
        let mut a = (0.0, 1.0);
        for j in 1..=GAP_CELLS {
            let v = mesh.v_end * j as f64 / GAP_CELLS as f64;
            let delta = if j == GAP_CELLS {
                mesh.delta_end
            } else {
                mesh.delta_at_v(sys, v)?
            };
            let g = gap(delta)?;
            if !armed {
                armed = g > tol;
                a = (delta, 1.0);
                continue;
            }
            if changes_sign(a.1, g) {
                let root = roots::illinois(&mut gap, a, (delta, g))?;
                if best.is_none_or(|(_, d)| root < d) {
                    best = Some((i, root));
                }
                break;
            }
            a = (delta, g);
        }
    }
    Ok(best)
}
