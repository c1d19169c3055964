//! The planner's quantities of the motion: the separation, every contact's end, the time to
//! the floor in contact, the point mass's fall, the series over the first contact's span and
//! the landing, each computing only what it needs of the motion.

use super::drawing::{PhaseInput, record};
use super::{Plan, column, phase_labels, scalar};
use crate::model::{GapKind, ModelInfo};
use crate::quantity::Quantity;
use crate::results::{
    ContactId, ContactImpulse, EndCause, Held, ImpactRecord, Label, LabelValue, Meaning, Note,
    RunResults, Series, Stretch, Unlanded, UntilNote,
};
use crate::solve::SolveError;
use crate::solve::fast::separation::{SeparationOutcome, linearised_separation};
use crate::solve::integrated::impact::Part;
use crate::solve::phases::{ImpactAt, LANDING_TOLERANCE, Motion, PhaseRun};
use crate::solve::series::{PhaseSamples, sample_at, sample_forces, sample_friction};
use crate::system::Bound;

/// How a contact fared along the motion.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Fate {
    /// It ended at this time from release and angle, for this cause (`force`, `edge`,
    /// `contact`: the motion stopped where another contact closed, or `impact`: an impact's
    /// impulses separated it).
    Ended {
        /// Time from release (s).
        t: f64,
        /// The reduced angle then (rad).
        theta: f64,
        /// Its own force or edge, another contact closing (where the run ends at its first
        /// impact), or an impact elsewhere.
        cause: EndCause,
    },
    /// It held to the end of the motion, which ended as `until` says.
    Held {
        /// How the motion ended.
        until: Held,
    },
    /// It was open from release on.
    NeverClosed,
}

/// Contact `i`'s fate on `motion` as far as it is solved; `None` when the phases solved so
/// far do not tell yet.
pub(super) fn fate(motion: &Motion, general: &Bound, i: usize) -> Result<Option<Fate>, SolveError> {
    let Some(first) = motion.phases.first() else {
        return Ok(None);
    };
    if motion.opened_at_release.contains(&i) {
        let bound = first.bound();
        let theta = bound.to_full(&bound.initial_state())?.q[general.reduced()?.0];
        return Ok(Some(Fate::Ended {
            t: 0.0,
            theta,
            cause: EndCause::Force(contact_id(general, first, i)?),
        }));
    }
    // A run that ends where a contact closes with the body on the floor (the floor under the
    // rod's end a contact) ends at its landing: the contacts still closed held to it.
    let landed = match (motion.through_impacts, motion.phases.last()) {
        (false, Some(last)) if matches!(last.end(), EndCause::Contact(_)) => {
            is_landing(general, last)?
        }
        _ => false,
    };
    fate_along(motion, general, i, landed)
}

/// Whether contact `i` of the system is closed in `phase`; a phase that does not list it is a
/// [`SolveError::PhaseMismatch`] (every model of a system lists the system's contacts).
fn closed_in(general: &Bound, phase: &PhaseRun, i: usize) -> Result<bool, SolveError> {
    let closed = phase.closed()?;
    closed.get(i).copied().ok_or_else(|| {
        mismatch(
            general,
            phase,
            format!("it lists {} contact(s), not contact {i}", closed.len()),
        )
    })
}

/// Contact `i` of `general`'s system; one it does not have is a [`SolveError::PhaseMismatch`]
/// of `phase`.
fn contact_id(general: &Bound, phase: &PhaseRun, i: usize) -> Result<ContactId, SolveError> {
    ContactId::of(general.info(), i).ok_or_else(|| {
        let why = format!("a fate is asked of contact {i}, which the system does not have");
        mismatch(general, phase, why)
    })
}

/// A phase of `general`'s system that does not fit it, with what does not.
fn mismatch(general: &Bound, phase: &PhaseRun, why: String) -> SolveError {
    SolveError::PhaseMismatch {
        system: general.info().system,
        name: phase.bound().info().name,
        why,
    }
}

/// [`fate`] for a contact that did not open at release; `landed`: the motion ends at a landing
/// where a contact closes.
fn fate_along(
    motion: &Motion,
    general: &Bound,
    i: usize,
    landed: bool,
) -> Result<Option<Fate>, SolveError> {
    let Some(first) = motion.phases.first() else {
        return Ok(None);
    };
    if !closed_in(general, first, i)? {
        return Ok(Some(Fate::NeverClosed));
    }
    let me = contact_id(general, first, i)?;
    for (k, phase) in motion.phases.iter().enumerate() {
        let ended = |cause| -> Result<Fate, SolveError> {
            Ok(Fate::Ended {
                t: phase.t_end(),
                theta: phase.theta_end()?,
                cause,
            })
        };
        match phase.end() {
            end @ (EndCause::Force(c) | EndCause::Edge(c)) if c == me => {
                return Ok(Some(ended(end)?));
            }
            EndCause::Contact(j) if !motion.through_impacts && landed => {
                return Ok(Some(Fate::Held {
                    until: Held::Lands {
                        contact: j.name.to_string(),
                        t: phase.t_end(),
                    },
                }));
            }
            end @ EndCause::Contact(_) if !motion.through_impacts => return Ok(Some(ended(end)?)),
            EndCause::Contact(_) => {
                // An impact: it may have separated this contact.
                let Some(next) = motion.phases.get(k + 1) else {
                    return Ok((motion.halted.as_ref()).map(|why| Fate::Held {
                        until: Held::Halted(why.clone()),
                    }));
                };
                if !closed_in(general, next, i)? {
                    return Ok(Some(ended(EndCause::Impact)?));
                }
            }
            EndCause::Until => {
                return Ok(Some(Fate::Held {
                    until: Held::RunsEnd { t: phase.t_end() },
                }));
            }
            EndCause::Floor => {
                return Ok(Some(Fate::Held {
                    until: Held::Floor {
                        angle: general.reduced()?.1.to_string(),
                        end_angle: general.end_angle()?,
                    },
                }));
            }
            EndCause::Edge(j) => {
                return Ok(Some(Fate::Held {
                    until: Held::Edge {
                        contact: j.name.to_string(),
                        t: phase.t_end(),
                    },
                }));
            }
            EndCause::Impact => {
                let why = "it ends at an impact elsewhere, which ends a contact, not a phase";
                return Err(mismatch(general, phase, why.into()));
            }
            EndCause::Force(_) => {
                // Another contact opened; the decision there may have opened this one too.
                let Some(next) = motion.phases.get(k + 1) else {
                    return Ok((motion.halted.as_ref()).map(|why| Fate::Held {
                        until: Held::Halted(why.clone()),
                    }));
                };
                if !closed_in(general, next, i)? {
                    return Ok(Some(ended(EndCause::Force(me))?));
                }
            }
        }
    }
    Ok(None)
}

/// Whether `phase` (of the system whose general model is `general`) ends where the body lands: at
/// the model's end angle, or where a contact closes with the falling point on the floor (within
/// [`LANDING_TOLERANCE`] of the system's length).
fn is_landing(general: &Bound, phase: &PhaseRun) -> Result<bool, SolveError> {
    match phase.end() {
        EndCause::Floor => Ok(true),
        // Without a falling point the system names no body that lands: a contact that closes
        // is an impact.
        EndCause::Contact(_) => match general.info().falling_point_index {
            Some(falling) => {
                let state = phase.full_end_state()?;
                let height = general.points(&state)?.pos[falling][1];
                Ok(height.abs() <= LANDING_TOLERANCE * general.length_scale(&state)?)
            }
            None => Ok(false),
        },
        _ => Ok(false),
    }
}

/// The index of the phase of `motion` (of the system whose general model is `general`) that
/// ends where the body lands ([`is_landing`]), if one does.
pub(super) fn landing(motion: &Motion, general: &Bound) -> Result<Option<usize>, SolveError> {
    for (k, phase) in motion.phases.iter().enumerate() {
        if is_landing(general, phase)? {
            return Ok(Some(k));
        }
    }
    Ok(None)
}

/// An impact as results hold it: names, normal velocities and impulses of the contacts that
/// took part, with their units.
fn impact_record(info: &ModelInfo, at: &ImpactAt) -> ImpactRecord {
    let name = |i: usize| {
        info.contacts
            .get(i)
            .map_or("a contact", |c| c.name)
            .to_string()
    };
    let taking: Vec<usize> = (0..at.parts.len())
        .filter(|&i| at.parts[i] != Part::None)
        .collect();
    let per_contact = (taking.iter())
        .map(|&i| {
            let angular = (info.contacts.get(i)).is_some_and(|c| c.gap == GapKind::Angle);
            ContactImpulse {
                contact: name(i),
                normal_velocity_before: at.impact.normal_velocity_before[i],
                normal_velocity_after: at.impact.normal_velocity_after[i],
                impulse: at.impact.impulse[i],
                tangential_impulse: (info.frictions.iter().enumerate())
                    .filter(|(_, f)| f.contact_index == i)
                    .filter_map(|(j, _)| at.impact.friction_impulse.get(j))
                    .sum(),
                velocity_unit: if angular { "rad/s" } else { "m/s" },
                impulse_unit: if angular { "N m s" } else { "N s" },
            }
        })
        .collect();
    ImpactRecord {
        time: at.zeno.unwrap_or(at.t),
        closing: name(at.closing),
        contacts: taking.iter().map(|&i| name(i)).collect(),
        per_contact,
        energy_lost: at.impact.energy_lost,
        normal_energy_lost: at.impact.normal_energy_lost,
        friction_energy_lost: at.impact.friction_energy_lost,
        zeno_limit: at.zeno.is_some(),
    }
}

impl Plan<'_> {
    /// Contact `i`'s fate, solving the motion as far as needed.
    pub(super) fn fate(&mut self, i: usize) -> Result<Fate, SolveError> {
        let general = self.general().clone();
        // An error stops the extension; the call after it returns that error.
        let motion = self.extend_until(|m| !matches!(fate(m, &general, i), Ok(None)))?;
        fate(motion, &general, i)?.ok_or(SolveError::TooManyPhases {
            limit: crate::solve::phases::MAX_PHASES,
        })
    }

    /// The separation angle or time, or a note saying why there is none. Where the motion
    /// starts on a fast phase that ends by the first contact's force, its roots alone give the
    /// angle.
    pub(super) fn separation_quantity(
        &mut self,
        q: Quantity,
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let info = self.general().info();
        let key = q.name(info);
        // Where the motion starts on a fast phase its end by the roots is the motion's own
        // first step: an error there is the quantity's error.
        let end = if q == Quantity::SeparationAngle && self.fast()?.is_some() {
            Some(self.end()?)
        } else {
            None
        };
        if let Some(end) = end
            && end.end.is_force_of(0)
            && let Some(at) = end.at
        {
            let angle = self.general().reduced()?.1.to_string();
            scalar(
                out,
                &key,
                at.theta,
                "rad",
                Meaning::SeparationAngle { angle },
            );
            return Ok(());
        }
        match self.fate(0)? {
            Fate::Ended {
                t,
                theta,
                cause: EndCause::Force(_),
            } => {
                if q == Quantity::SeparationAngle {
                    let angle = self.general().reduced()?.1.to_string();
                    scalar(out, &key, theta, "rad", Meaning::SeparationAngle { angle });
                } else {
                    scalar(out, &key, t, "s", Meaning::SeparationTime);
                }
            }
            other => {
                out.notes.insert(key, self.why_no_separation(&other));
            }
        }
        Ok(())
    }

    /// Why the first contact does not separate.
    fn why_no_separation(&self, fate: &Fate) -> Note {
        let info = self.general().info();
        let contact = (info.contacts.first())
            .map_or("the first contact", |c| c.name)
            .to_string();
        match fate {
            Fate::Ended { cause, .. } => Note::NoSeparationEnded {
                contact,
                cause: *cause,
            },
            Fate::Held { until } => Note::NoSeparationHolds {
                contact,
                held: until.clone(),
            },
            Fate::NeverClosed => Note::NoSeparationOpen { contact },
        }
    }

    /// The release phase's separation polynomial with its terms above degree 1 dropped.
    pub(super) fn linearised(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let key = Quantity::LinearisedSeparationAngle.name(self.general().info());
        let sys = self.fast_required()?;
        match linearised_separation(&sys)? {
            SeparationOutcome::Separates(s) => scalar(
                out,
                &key,
                s.theta,
                "rad",
                Meaning::LinearisedSeparationAngle,
            ),
            SeparationOutcome::NoSeparationBeforeFloor => {
                out.notes.insert(key, Note::NoLinearisedRoot);
            }
        }
        Ok(())
    }

    /// Every contact's end: time, angle and cause, the first contact's under
    /// `contact_end_*` as well as its own name; notes for those that hold or never close.
    pub(super) fn contact_ends(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.general().info();
        for i in 0..info.contacts.len() {
            let fate = self.fate(i)?;
            let name = info.contacts[i].name;
            let keys: Vec<String> = if i == 0 {
                vec!["contact_end".into(), format!("{name}_end")]
            } else {
                vec![format!("{name}_end")]
            };
            for key in keys {
                match &fate {
                    Fate::Ended { t, theta, cause } => {
                        let contact = name.to_string();
                        let meaning = Meaning::ContactEndTime {
                            contact: contact.clone(),
                            cause: *cause,
                        };
                        scalar(out, &format!("{key}_time"), *t, "s", meaning);
                        let meaning = Meaning::ContactEndAngle {
                            angle: self.general().reduced()?.1.to_string(),
                            contact: contact.clone(),
                            cause: *cause,
                        };
                        scalar(out, &format!("{key}_angle"), *theta, "rad", meaning);
                        out.labels.insert(
                            format!("{key}_cause"),
                            Label {
                                value: LabelValue::Cause(*cause),
                                meaning: Meaning::ContactEndCause { contact },
                            },
                        );
                    }
                    Fate::Held { until } => {
                        let held = until.clone();
                        let contact = name.to_string();
                        out.notes.insert(key, Note::Holds { contact, held });
                    }
                    Fate::NeverClosed => {
                        let contact = name.to_string();
                        out.notes.insert(key, Note::OpenAtRelease { contact });
                    }
                }
            }
        }
        self.friction_report(out)
    }

    /// With friction, over the first contact's span: the work friction did
    /// (`contact_end_friction_work`, J) and the sequence of active sets
    /// (`contact_end_contact_modes`).
    fn friction_report(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.general().info();
        if info.frictions.is_empty() {
            return Ok(());
        }
        let end = self.span_end()?;
        let motion = &*self.motion()?;
        let phases: Vec<&PhaseRun> = (motion.phases.iter())
            .filter(|p| p.t_start() < end || (end == 0.0 && p.t_start() == 0.0))
            .collect();
        let work = phases.last().map_or(0.0, |p| p.friction_work());
        scalar(
            out,
            "contact_end_friction_work",
            work,
            "J",
            Meaning::ContactEndFrictionWork,
        );
        let sequence = (phases.iter().flat_map(|p| p.stretches()))
            .map(|(from, set)| Stretch { from, set })
            .collect();
        out.labels.insert(
            "contact_end_contact_modes".into(),
            Label {
                value: LabelValue::Stretches(sequence),
                meaning: Meaning::ContactModes,
            },
        );
        Ok(())
    }

    /// The time to the end angle keeping the release contacts closed.
    pub(super) fn contact_time_to_floor(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.general().info();
        let t = self.floor_mesh()?.duration;
        let key = Quantity::ContactTimeToFloor.name(info);
        let meaning = Meaning::ContactTimeToFloor {
            angle: self.general().reduced()?.1.to_string(),
            end_angle: self.general().end_angle()?,
        };
        scalar(out, &key, t, "s", meaning);
        Ok(())
    }

    /// `sqrt(2 h / g)` from the falling point's height at release.
    pub(super) fn point_mass_fall_time(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let general = self.general();
        let info = general.info();
        let pts = general.points(&general.initial_state())?;
        let falling = general.falling_point()?;
        let h = pts.pos[falling][1];
        let t = (2.0 * h.max(0.0) / general.gravity()).sqrt();
        let meaning = Meaning::PointMassFallTime {
            point: info.points[falling].name.to_string(),
            height: h,
        };
        scalar(
            out,
            &Quantity::PointMassFallTime.name(info),
            t,
            "s",
            meaning,
        );
        Ok(())
    }

    /// Where the series end (s from release): the first contact's end, or the end of the
    /// motion; where that is the release itself (a contact open at once), the end of the first
    /// phase that lasts.
    pub(super) fn span_end(&mut self) -> Result<f64, SolveError> {
        let info = self.general().info();
        let fate = if info.contacts.is_empty() {
            Fate::NeverClosed
        } else {
            self.fate(0)?
        };
        if self.walker.until.is_some() {
            // A run with an end time covers the whole motion.
            return Ok(self.complete()?.end_time());
        }
        let end = match fate {
            Fate::Ended { t, .. } if t > 0.0 => t,
            Fate::Held { .. } => self.complete()?.end_time(),
            _ => {
                let motion = self.extend_until(|m| m.phases.iter().any(|p| p.duration() > 0.0))?;
                (motion.phases.iter())
                    .find(|p| p.duration() > 0.0)
                    .map_or(0.0, PhaseRun::t_end)
            }
        };
        Ok(end)
    }

    /// Samples at `samples` uniform times from release to [`Plan::span_end`], each in its
    /// phase: per phase touched, its index, its samples (times from the phase's start) and the
    /// same times from release. Sampled once and shared by every series.
    fn span_samples(&mut self) -> Result<Vec<(usize, PhaseSamples, Vec<f64>)>, SolveError> {
        if let Some(done) = &self.span {
            return Ok(done.clone());
        }
        let end = self.span_end()?;
        let times = crate::solve::series::uniform_times(end, self.samples)?;
        let motion = self.take_motion()?;
        let Plan {
            motion: slot, work, ..
        } = self;
        let motion = &*slot.insert(motion);
        let mut groups: Vec<(usize, Vec<f64>)> = Vec::new();
        for &t in &times {
            // The phase that runs at `t`: the last one starting at or before it that lasts; at
            // the span's end the one ending there, never one that begins there, so that a
            // series is the same however much of the motion other quantities solved (the
            // phases cover the span, so there is one).
            let runs = |p: &PhaseRun| p.t_start() <= t && t < p.t_end();
            let ends = |p: &PhaseRun| p.t_start() < end && p.t_end() >= end;
            let last = |p: &PhaseRun| p.t_start() <= t && p.t_end() >= end;
            let phases = || motion.phases.iter();
            let k = (if t < end {
                phases().rposition(runs)
            } else {
                phases()
                    .rposition(ends)
                    .or_else(|| phases().rposition(last))
            })
            .ok_or(SolveError::Inversion {
                target: t,
                duration: end,
                reason: "no solved phase runs at this time",
            })?;
            match groups.last_mut() {
                Some((g, ts)) if *g == k => ts.push(t),
                _ => groups.push((k, vec![t])),
            }
        }
        let mut out = Vec::new();
        for (k, ts) in groups {
            let phase = &motion.phases[k];
            let local: Vec<f64> = ts.iter().map(|t| (t - phase.t_start()).max(0.0)).collect();
            let s = sample_at(phase, &local, work)?;
            out.push((k, s, ts));
        }
        self.span = Some(out.clone());
        Ok(out)
    }

    /// A series over the first contact's span: the angle, a contact's force, a friction, or a
    /// point's path. Columns are named by the reduced coordinate's own name (`theta`, `phi`);
    /// a system without one has no angle column beside its forces.
    pub(super) fn series(&mut self, q: Quantity, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.general().info();
        let groups = self.span_samples()?;
        let general = self.general().clone();
        let angle = general.reduced_coordinate();
        let motion = &*self.motion()?;
        let mut cols: Vec<Vec<f64>> = Vec::new();
        let mut push = |row: &[f64]| {
            cols.resize(row.len(), Vec::new());
            for (c, v) in cols.iter_mut().zip(row) {
                c.push(*v);
            }
        };
        // The time and, where the system has a reduced coordinate, the angle: a force's row
        // starts with them.
        let lead = |s: &PhaseSamples, t: f64, j: usize| -> Vec<f64> {
            match (angle, s.theta.get(j)) {
                (Some(_), Some(&theta)) => vec![t, theta],
                _ => vec![t],
            }
        };
        for (k, s, t) in &groups {
            let phase = &motion.phases[*k];
            match q {
                Quantity::ThetaSeries => {
                    for (j, tj) in t.iter().enumerate().take(s.len()) {
                        push(&[*tj, s.theta[j], s.theta_dot[j], s.theta_ddot[j]]);
                    }
                }
                Quantity::ForceSeries(i) => {
                    for (j, f) in sample_forces(phase, s)?.iter().enumerate() {
                        let force = f.get(i).copied().ok_or_else(|| {
                            let why = format!("it gives {} force(s), not contact {i}'s", f.len());
                            mismatch(&general, phase, why)
                        })?;
                        let mut row = lead(s, t[j], j);
                        row.push(force);
                        push(&row);
                    }
                }
                Quantity::FrictionSeries(i) => {
                    for (j, [f, n, v]) in sample_friction(phase, &general, s)?.iter().enumerate() {
                        let at = |x: &[f64]| {
                            x.get(i).copied().ok_or_else(|| {
                                let why =
                                    format!("it gives {} friction(s), not friction {i}", x.len());
                                mismatch(&general, phase, why)
                            })
                        };
                        let mut row = lead(s, t[j], j);
                        row.extend([at(f)?, at(n)?, at(v)?]);
                        push(&row);
                    }
                }
                Quantity::Trajectory(i) => {
                    for (j, state) in s.states.iter().enumerate() {
                        let pts = phase.bound().points(state)?;
                        let (p, v) = (pts.pos[i], pts.vel[i]);
                        push(&[t[j], p[0], p[1], v[0], v[1]]);
                    }
                }
                _ => {}
            }
        }
        let mut names: Vec<(String, &'static str)> = vec![("t".into(), "s")];
        if let Some(a) = angle
            && matches!(
                q,
                Quantity::ThetaSeries | Quantity::ForceSeries(_) | Quantity::FrictionSeries(_)
            )
        {
            names.push((a.into(), "rad"));
        }
        match q {
            Quantity::ThetaSeries => {
                let a = general.reduced()?.1;
                names.push((format!("{a}_dot"), "rad/s"));
                names.push((format!("{a}_ddot"), "rad/s^2"));
            }
            Quantity::ForceSeries(i) => {
                names.push((info.contacts[i].name.into(), info.contacts[i].unit));
            }
            Quantity::FrictionSeries(i) => {
                let f = &info.frictions[i];
                names.push((f.name.into(), "N"));
                let c = &info.contacts[f.contact_index];
                names.push((c.name.into(), c.unit));
                names.push(("slip_velocity".into(), "m/s"));
            }
            _ => names.extend([
                ("x".into(), "m"),
                ("y".into(), "m"),
                ("vx".into(), "m/s"),
                ("vy".into(), "m/s"),
            ]),
        }
        cols.resize(names.len(), Vec::new());
        let series = Series {
            columns: (names.into_iter().zip(cols))
                .map(|((name, unit), values)| column(&name, unit, values))
                .collect(),
        };
        out.series.insert(q.name(info), series);
        Ok(())
    }

    /// The motion to its end: the landing time and rate where it reaches the floor, a note
    /// otherwise; with friction, the work it did.
    pub(super) fn floor_impact(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        let info = self.general().info();
        let general = self.general().clone();
        let motion = self.complete()?;
        if !info.frictions.is_empty() {
            let work = motion.phases.last().map_or(0.0, PhaseRun::friction_work);
            scalar(
                out,
                "floor_impact_friction_work",
                work,
                "J",
                Meaning::FloorImpactFrictionWork {
                    angle: general.reduced()?.1.to_string(),
                    end_angle: general.end_angle()?,
                },
            );
        }
        let Some(landing) = landing(motion, &general)?.map(|k| &motion.phases[k]) else {
            let end = match motion.last_end() {
                Some(end @ (EndCause::Edge(_) | EndCause::Contact(_) | EndCause::Until)) => {
                    Unlanded::At(end)
                }
                _ => match &motion.halted {
                    Some(why) => Unlanded::Halted(why.clone()),
                    None => Unlanded::Ended,
                },
            };
            let note = Note::NoLanding {
                t: motion.end_time(),
                path: phase_labels(motion),
                end,
            };
            out.notes.insert("floor_impact".into(), note);
            return Ok(());
        };
        let (time, omega) = (landing.t_end(), landing.theta_dot_end()?);
        let (angle, path) = (general.reduced()?.1.to_string(), phase_labels(motion));
        let meaning = Meaning::FloorImpactTime {
            angle: angle.clone(),
            end_angle: general.end_angle()?,
            path: path.clone(),
        };
        scalar(out, "floor_impact_time", time, "s", meaning);
        let meaning = Meaning::ImpactAngularVelocity { angle, path };
        scalar(out, "impact_angular_velocity", omega, "rad/s", meaning);
        Ok(())
    }

    /// Every impact of the motion (the motion to its end): where the run does not go on
    /// through impacts and ends at a contact that closes, that impact is resolved too, and a
    /// note says the run ends there.
    pub(super) fn impacts(&mut self, out: &mut RunResults) -> Result<(), SolveError> {
        self.complete()?;
        let motion = self.take_motion()?;
        let Plan {
            motion: slot,
            walker,
            ..
        } = self;
        let motion = slot.insert(motion);
        let info = walker.general.info();
        let mut list = motion.impacts.clone();
        if let (false, Some(EndCause::Contact(i))) = (motion.through_impacts, motion.last_end()) {
            match walker.impact(motion, i.index) {
                Ok(at) => list.push(at),
                Err(e @ SolveError::ImpactGainsEnergy { .. }) => {
                    out.notes
                        .insert("impacts".into(), Note::Refused(e.to_string()));
                }
                Err(e) => return Err(e),
            }
            (out.notes.entry("impacts".into())).or_insert(Note::FirstImpactEnds {
                t: motion.end_time(),
            });
        }
        if list.is_empty() {
            let path = phase_labels(motion);
            out.notes.insert("impacts".into(), Note::NoImpact { path });
        }
        out.impacts = Some(list.iter().map(|a| impact_record(info, a)).collect());
        Ok(())
    }

    /// What the whole motion needs said, where it was solved to its end: whether it reached
    /// the run's end time (`until`), a converging (Zeno) sequence of bounces closed, a run
    /// halted at too many impacts.
    pub(super) fn motion_notes(&self, out: &mut RunResults) {
        let Some(motion) = self.motion.as_ref().filter(|m| m.complete()) else {
            return;
        };
        if let Some(until) = self.walker.until {
            let (t, impacts) = (motion.end_time(), motion.impacts.len());
            let note = match (&motion.halted, motion.last_end()) {
                (Some(why), _) => UntilNote::Halted(why.clone()),
                (None, Some(EndCause::Until)) => UntilNote::Reached { t, impacts },
                (None, end) => UntilNote::EndedBefore {
                    t,
                    cause: end,
                    until,
                    impacts,
                },
            };
            out.notes.insert("until".into(), Note::Until(note));
        }
        if !motion.notes.is_empty() {
            out.notes
                .insert("zeno".into(), Note::Zeno(motion.notes.clone()));
        }
    }

    /// The bodies' poses for `motion.svg`: every phase this run solved (the first always, the
    /// next ones when other quantities asked for them), each sampled once, with the path of the
    /// first point whose trajectory is wanted. A later phase that cannot be sampled ends the
    /// drawing there, which says why.
    pub(super) fn drawing(
        &mut self,
        want: &[Quantity],
        out: &mut RunResults,
    ) -> Result<(), SolveError> {
        let n = self.motion()?.phases.len();
        let mut stopped = None;
        for i in 0..n {
            if let Err(e) = self.samples_of(i) {
                stopped = Some((i, e.to_string()));
                break;
            }
        }
        let motion = self.take_motion()?;
        let Plan {
            motion: slot,
            walker,
            phase_samples,
            ..
        } = self;
        let motion = &*slot.insert(motion);
        let info = walker.general.info();
        let traced = want.iter().find_map(|q| match q {
            Quantity::Trajectory(i) => info.points.get(*i).map(|p| p.name),
            _ => None,
        });
        // The phases sampled (all of them, or those before the one that could not be).
        let phases: Vec<PhaseInput> = (motion.phases.iter().zip(phase_samples.iter()))
            .map(|(run, samples)| PhaseInput {
                bound: run.bound(),
                samples,
                t_start: run.t_start(),
                end: run.end(),
            })
            .collect();
        let mut drawing = record(&phases, traced);
        drawing.stopped = stopped;
        out.drawing = Some(drawing);
        Ok(())
    }
}
