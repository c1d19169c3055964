//! The planner's evidence: the cross-check of the fast path against the general model
//! integrated with the same contacts closed, and the physical checks of every phase.

use super::{Plan, scalar};
use crate::results::{
    CROSS_CHECK_APART, CheckKind, CheckPhase, END_UNRESOLVED, Meaning, Note, RunResults, Work,
};
use crate::solve::SolveError;
use crate::solve::checks::{self, Conserved, free_momenta};
use crate::solve::integrated::resolution;
use crate::solve::integrated::unreduced::UnreducedRun;
use crate::solve::phases::PhaseRun;
use crate::solve::series::{sample_forces, theta_dot_at};

impl Plan<'_> {
    /// The fast path's first phase against the general model integrated from release with the
    /// same contacts closed: the event time, and along the path the quadrature's time and the
    /// reduced state at each step's angle.
    pub(super) fn cross_check(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        self.fast_required()?;
        let ode = match self.take_ode() {
            Ok(ode) => ode,
            // Not an error of the run: the integrated route has nothing to say here.
            Err(e @ SolveError::IllConditioned { .. }) => {
                out.notes
                    .insert("cross_check".into(), Note::Refused(e.to_string()));
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        let motion = self.take_motion()?;
        let Plan {
            motion: motion_slot,
            ode: ode_slot,
            walker,
            work,
            ..
        } = self;
        let (motion, ode) = (&*motion_slot.insert(motion), &*ode_slot.insert(ode));
        let info = walker.general.info();
        // The motion starts on the fast phase (`fast_required`), whose first phase from rest
        // is never integrated instead (one that turns back is `SolveError::Swings`).
        let Some(first) = motion.phases[0].reduced() else {
            return Err(SolveError::NotOnFastPath {
                model: info.name,
                why: "its first phase was integrated, so there is no fast path to cross-check"
                    .into(),
            });
        };
        let t_quad = first.mesh.duration;
        let same = ode.end == first.end.end;
        if !same {
            let note = Note::CrossCheckDisagrees {
                integrated: ode.end,
                fast: first.end.end,
            };
            out.notes.insert("cross_check".into(), note);
        }
        let rel = if t_quad > 0.0 {
            (ode.t_end - t_quad).abs() / t_quad
        } else {
            (ode.t_end - t_quad).abs()
        };
        // The same event, reached at times further apart than the integrator's tolerance
        // explains (a NaN is not apart: the figures below show it).
        if same && rel > CROSS_CHECK_APART * ode.rtol {
            let note = Note::CrossCheckApart {
                relative: rel,
                rtol: ode.rtol,
            };
            out.notes.insert("cross_check".into(), note);
        }
        let (dt_max, dy_max, nodes) =
            // The integrated state is the general model's: its reduced coordinate's index
            // there (the fast phase's own model orders its coordinates otherwise).
            path_deviation(first, ode, walker.general.reduced()?.0, work)?;
        let steps = ode.steps();
        let event = ode.end;
        let meaning = Meaning::CrossCheckTime {
            method: ode.method.name().to_string(),
            steps,
            event,
        };
        scalar(out, "cross_check_time", ode.t_end, "s", meaning);
        let meaning = Meaning::CrossCheckRelativeDifference {
            event,
            t_quad,
            rtol: ode.rtol,
            condition: ode.condition,
        };
        scalar(out, "cross_check_relative_difference", rel, "1", meaning);
        let meaning = Meaning::CrossCheckRtol;
        scalar(out, "cross_check_rtol", ode.rtol, "1", meaning);
        let meaning = Meaning::CrossCheckTimeDeviation { nodes };
        scalar(out, "cross_check_time_deviation", dt_max, "s", meaning);
        let meaning = Meaning::CrossCheckStateDeviation { nodes };
        scalar(out, "cross_check_state_deviation", dy_max, "1", meaning);
        Ok(())
    }

    /// For every integrated phase solved that ended at a contact's event (its force reaching
    /// zero, its gap closing, its edge reached), where the rounding of the state there makes
    /// the end's time uncertain by more than [`END_UNRESOLVED`] times the phase's tolerance
    /// ([`resolution::end_resolution`]): a note under `<contact>_resolution` (the last such
    /// phase's). Over the test suite's 991 such ends (629 forces, 273 gaps, 89 edges) the
    /// largest ratio is 5.3.
    pub(super) fn resolution_notes(&self, out: &mut RunResults) -> Result<(), SolveError> {
        let Some(motion) = &self.motion else {
            return Ok(());
        };
        for run in &motion.phases {
            let PhaseRun::Integrated(phase) = run else {
                continue;
            };
            let Some((end, fraction)) = resolution::end_resolution(&phase.bound, &phase.run)?
            else {
                continue;
            };
            let rtol = phase.run.rtol;
            let Some(contact) = end.contact() else {
                continue;
            };
            if fraction > END_UNRESOLVED * rtol {
                let note = Note::EndUnresolved {
                    end,
                    t: phase.t_start + phase.run.t_end,
                    fraction,
                    rtol,
                };
                out.notes
                    .insert(format!("{}_resolution", contact.name), note);
            }
        }
        Ok(())
    }

    /// The checks of every phase to the end of the motion, and of the cross-check's path when
    /// it was solved.
    pub(super) fn checks(
        &mut self,
        with_ode: bool,
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let n_phases = self.complete()?.phases.len();
        let tol = self.walker.tol;
        for i in 0..n_phases {
            self.samples_of(i)?;
        }
        let motion = self.take_motion()?;
        let Plan {
            motion: slot,
            phase_samples,
            ode,
            walker,
            ..
        } = self;
        let motion = &*slot.insert(motion);
        for (i, run) in motion.phases.iter().enumerate() {
            let solved = phase_samples.len();
            let samples = phase_samples
                .get(i)
                .ok_or(SolveError::NoSuchPhase { index: i, solved })?;
            let bound = run.bound();
            let label = run.labels().join(" then ");
            let ctx = checks::Context {
                phase: CheckPhase::Phase(label),
                key: if matches!(run, PhaseRun::Reduced(_)) {
                    bound.name().to_string()
                } else {
                    format!("{}.{}", bound.name(), i + 1)
                },
                order: 2 * i,
                t_start: run.t_start(),
            };
            let forces = sample_forces(run, samples)?;
            let mut found = checks::monitors(bound, samples, &forces, tol, &ctx)?;
            found.extend(checks::contact_forces(
                bound,
                samples,
                &forces,
                &run.closed()?,
                tol,
                &ctx,
            )?);
            found.extend(path_checks(run, samples, tol, &ctx)?);
            out.checks.extend(found);
        }
        for (k, at) in motion.impacts.iter().enumerate() {
            let general = &walker.general;
            let before = (motion.phases.get(at.phase))
                .ok_or(SolveError::NoSuchPhase {
                    index: at.phase,
                    solved: motion.phases.len(),
                })?
                .full_end_state()?;
            let ctx = checks::Context {
                phase: CheckPhase::Impact {
                    number: k + 1,
                    t: at.t,
                },
                key: format!("impact_{}", k + 1),
                order: 2 * at.phase + 1,
                t_start: at.t,
            };
            let (key, check) = checks::impact_energy(general, &before, &at.impact, tol, &ctx)?;
            out.checks.insert(key, check);
        }
        if with_ode && let Some(ode) = ode.as_ref() {
            // The cross-check's path is held to its own accuracy: ten times its rtol at the
            // least. It integrates the first phase, so its checks come right after that phase's.
            let general = &walker.general;
            let ode_tol = tol.max(10.0 * ode.rtol);
            let ctx = checks::Context {
                phase: CheckPhase::OdeCrossCheck {
                    model: general.name().to_string(),
                },
                key: format!("{}.ode", general.name()),
                order: 1,
                t_start: 0.0,
            };
            out.checks
                .extend(integrated_checks(general, ode, ode_tol, &ctx)?);
        }
        Ok(())
    }
}

/// The conservation checks of a phase's own path: by construction on the fast path (the
/// generated functions agree with it at the samples), along the integrator's steps otherwise,
/// held to the integrator's accuracy (ten times its rtol at the least).
fn path_checks(
    run: &PhaseRun,
    samples: &crate::solve::series::PhaseSamples,
    tol: f64,
    ctx: &checks::Context,
) -> Result<Vec<(String, crate::results::Check)>, SolveError> {
    match run {
        PhaseRun::Reduced(r) => {
            let bound = r.system.bound();
            let conserved = Conserved::each_cyclic(bound);
            checks::drift(
                bound,
                &samples.states,
                &conserved,
                tol,
                ctx,
                CheckKind::Identity,
            )
        }
        PhaseRun::Integrated(r) => {
            integrated_checks(&r.bound, &r.run, tol.max(10.0 * r.run.rtol), ctx)
        }
    }
}

/// Energy (with the work of friction), the momenta no closed contact or acting friction pushes
/// on, and the closed contacts' gaps, along an integration's steps.
fn integrated_checks(
    bound: &crate::system::Bound,
    run: &UnreducedRun,
    tol: f64,
    ctx: &checks::Context,
) -> Result<Vec<(String, crate::results::Check)>, SolveError> {
    let info = bound.info();
    let states = run.states();
    let segments = run.node_segments();
    let rows: Vec<(Vec<bool>, Vec<bool>)> = segments
        .iter()
        .map(|&k| {
            let active = &run.segments[k].active;
            let acting = (0..info.frictions.len())
                .map(|j| active.friction_acts(info, j))
                .collect();
            (active.closed.clone(), acting)
        })
        .collect();
    let work = run.node_friction_work();
    let conserved = Conserved {
        friction_work: (!info.frictions.is_empty()).then_some(&work[..]),
        momenta: free_momenta(bound, &states, &rows)?,
    };
    let mut out = checks::drift(bound, &states, &conserved, tol, ctx, CheckKind::Drift)?;
    let closed: Vec<Vec<bool>> = rows.into_iter().map(|(c, _)| c).collect();
    out.extend(checks::constraint_drift(bound, &states, &closed, tol, ctx)?);
    Ok(out)
}

/// Along the integrated cross-check's steps: the largest `|t_ode - t(theta_ode)|` and the
/// largest relative difference between its state and the reduced one at the same angle (in the
/// system's coordinates), and the number of steps.
fn path_deviation(
    first: &crate::solve::phases::ReducedRun,
    ode: &UnreducedRun,
    reduced: usize,
    work: &mut Work,
) -> Result<(f64, f64, usize), SolveError> {
    let sys = &first.system;
    let theta_i = sys.theta_initial();
    let nodes = ode.nodes();
    // Each component against the largest of its kind on the path (coordinates, velocities):
    // a coordinate a joint holds at zero carries only rounding, not a scale of its own.
    let n = nodes.first().map_or(0, |(_, y)| y.len() / 2);
    let mut scale = vec![0.0f64; 2 * n];
    for (_, y) in &nodes {
        for (s, v) in scale.iter_mut().zip(y.iter()) {
            *s = s.max(v.abs());
        }
    }
    for kind in [0..n, n..2 * n] {
        let top = scale[kind.clone()].iter().cloned().fold(0.0, f64::max);
        for s in &mut scale[kind] {
            *s = top;
        }
    }
    let (mut dt_max, mut dy_max) = (0.0f64, 0.0f64);
    let mut w = Work::default();
    for (t, y) in &nodes {
        let delta = (theta_i - y[reduced]).clamp(0.0, first.mesh.delta_end);
        let tq = first.mesh.time_at_delta(sys, delta, &mut w)?;
        dt_max = dt_max.max((t - tq).abs());
        let full = sys.to_full(&sys.full_state(*t, delta, theta_dot_at(sys, delta))?)?;
        for (i, (a, b)) in full.q.iter().chain(&full.qd).zip(y.iter()).enumerate() {
            if scale[i] > 0.0 {
                dy_max = dy_max.max((a - b).abs() / scale[i]);
            }
        }
    }
    work.integrand_evals += w.integrand_evals;
    Ok((dt_max, dy_max, nodes.len()))
}
