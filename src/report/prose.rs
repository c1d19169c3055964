//! The sentences for people about a run: what each check tested ([`check_meaning`], written
//! as results.json's `meaning`, the table's legend and the Python binding's `meaning`), where
//! it ran ([`check_phase`]), the word-valued results ([`label`]) and why a quantity has no
//! value ([`note`]). Results carry only names and numbers; the words
//! are all here.

use std::fmt;

use crate::results::{
    CROSS_CHECK_APART, Check, CheckKind, CheckPhase, CheckSubject, ContactSet, END_UNRESOLVED,
    EndCause, Halt, Held, Holding, Indeterminacy, LabelValue, Meaning, Mode, Note, Sensitivity,
    SensitivityGap, Sign, TapeReason, Unlanded, UntilNote, Zeno, format_number,
};

/// Where a check ran, as the table's group heading and results.json's `phase` name it:
/// `<labels>`, `impact <k> at t = <t> s`, `<model> (ODE cross-check)`.
pub fn check_phase(phase: &CheckPhase) -> String {
    match phase {
        CheckPhase::Phase(labels) => labels.clone(),
        CheckPhase::Impact { number, t } => {
            format!("impact {number} at t = {} s", format_number(*t, 9))
        }
        CheckPhase::OdeCrossCheck { model } => format!("{model} (ODE cross-check)"),
    }
}

/// A word-valued result as the table and results.json write it: the word, or each stretch as
/// `<modes> from t = <t> s`, joined by `; `.
pub fn label(value: &LabelValue) -> String {
    match value {
        LabelValue::Cause(cause) => cause_keyword(*cause).into(),
        LabelValue::Stretches(stretches) => (stretches.iter())
            .map(|s| format!("{} from t = {} s", s.set, format_number(s.from, 6)))
            .collect::<Vec<_>>()
            .join("; "),
    }
}

/// What a check tested and against what, in a sentence.
pub fn check_meaning(check: &Check) -> String {
    let (samples, tolerance) = (check.samples, check.limit);
    match &check.subject {
        CheckSubject::Monitor { model, meaning, .. } => {
            format!(
                "{meaning}: the smallest value over {samples} samples of `{model}` must be >= 0"
            )
        }
        CheckSubject::Pushes { model, contact } => format!(
            "contact `{contact}` is closed in `{model}`: its force must push (>= 0) at each of \
             {samples} samples, or the contact should have opened"
        ),
        CheckSubject::Gap {
            model,
            contact,
            length,
        } => format!(
            "contact `{contact}` is held closed by the integrator of `{model}`: its largest gap \
             over {samples} states, relative to the system's length ({} m), stays <= {}",
            format_number(*length, 4),
            format_number(tolerance, 3)
        ),
        CheckSubject::Energy {
            model,
            friction,
            rounding,
            scale,
        } => {
            let energy = if *friction {
                "the energy balance (energy lost = work of friction)"
            } else {
                "the total energy"
            };
            let what = format!(
                "{energy}, beyond its rounding ({} J), relative to the largest kinetic energy \
                 plus the potential's range ({} J),",
                format_number(*rounding, 3),
                format_number(*scale, 5)
            );
            conserved(check, &what, model)
        }
        CheckSubject::Momentum { model, name, scale } => {
            let what = format!(
                "the {} conserved, relative to {},",
                name.replace('_', " "),
                format_number(*scale, 5)
            );
            conserved(check, &what, model)
        }
        CheckSubject::Impact {
            energy_lost,
            kinetic_before,
        } => format!(
            "the energy lost in the impact ({} J by its impulses) against the drop of the total \
             energy across it, beyond its rounding, relative to the kinetic energy before \
             ({} J): relative difference <= {}",
            format_number(*energy_lost, 6),
            format_number(*kinetic_before, 6),
            format_number(tolerance, 3)
        ),
    }
}

/// The sentence of a conservation check on `what` along the path of `model`: a drift on an
/// integrated path, an agreement on the reduced path, where it holds by construction.
fn conserved(check: &Check, what: &str, model: &str) -> String {
    let (states, tolerance) = (check.samples, format_number(check.limit, 3));
    match check.kind {
        CheckKind::Identity => format!(
            "{what} is conserved by construction on the reduced path of `{model}`; this checks \
             that the generated function agrees with it over {states} states: relative \
             difference <= {tolerance}"
        ),
        CheckKind::Drift | CheckKind::Monitor => format!(
            "{what} along the {states} integrated states of `{model}`: largest relative drift \
             <= {tolerance}"
        ),
    }
}

/// Why a quantity has no value, or what the motion needs said, in words.
pub fn note(note: &Note) -> String {
    match note {
        Note::Refused(why) => why.clone(),
        Note::NoSensitivity(gap) => sensitivity_gap(*gap).into(),
        Note::FromTape { model, file, why } => match why {
            TapeReason::Asked => format!(
                "model `{model}` ran from its tape {file} (--interpreted): the same program as \
                 the compiled code, evaluated"
            ),
            TapeReason::NotCompiled => format!(
                "model `{model}` is not compiled into this program; it ran from its tape {file}"
            ),
            TapeReason::DerivedNow => format!(
                "model `{model}` was derived from {file} for this run and ran from its tape"
            ),
            TapeReason::DiffersFromCompiled => format!(
                "model `{model}` ran from its tape {file}, which is another program than the \
                 compiled-in model of that name (its spec was derived again since this program \
                 was built)"
            ),
        },
        Note::SpecChanged { model, spec } => format!(
            "the spec {spec} has changed since model `{model}` was derived from it: these are \
             the results of the model as last derived; run `cargo derive` (or `rodcube derive`) \
             to derive it again"
        ),
        Note::NoSeparationEnded { contact, cause } => format!(
            "no separation: contact `{contact}` ended before its force vanished ({}; \
             `contact_end` says when)",
            cause_words(*cause)
        ),
        Note::NoSeparationHolds { contact, held } => {
            format!(
                "no separation: contact `{contact}` holds {}",
                held_words(held)
            )
        }
        Note::NoSeparationOpen { contact } => {
            format!("no separation: contact `{contact}` is open at release")
        }
        Note::NoLinearisedRoot => {
            "the linearised polynomial has no root between the floor and the start".into()
        }
        Note::Holds { contact, held } => format!("contact `{contact}` holds {}", held_words(held)),
        Note::OpenAtRelease { contact } => format!("contact `{contact}` is open at release"),
        Note::CrossCheckDisagrees { integrated, fast } => format!(
            "the integrated route ended at {}, the fast path at {}: they disagree on the first \
             event",
            event_words(*integrated),
            event_words(*fast)
        ),
        Note::CrossCheckApart { relative, rtol } => format!(
            "the integrated route reached the same event {} (relative) from the fast path's \
             time, over {} times the tolerance it ran with ({}): one of the two routes is \
             ill-conditioned at these parameters, so their digits beyond that difference are \
             not confirmed",
            format_number(*relative, 3),
            format_number(CROSS_CHECK_APART, 3),
            format_number(*rtol, 3)
        ),
        Note::EndUnresolved {
            end,
            t,
            fraction,
            rtol,
        } => format!(
            "the integrated route ends at {} at t = {} s, but the rounding of the state there \
             makes that time uncertain by about {} (relative), over {} times the integrator's \
             tolerance ({}): what it measures is a difference of nearly equal coordinates \
             (e.g. a spring stretched by less than their last digits)",
            event_words(*end),
            format_number(*t, 6),
            format_number(*fraction, 3),
            format_number(END_UNRESOLVED, 3),
            format_number(*rtol, 3)
        ),
        Note::NoLanding { t, path, end } => no_landing(*t, &path.join(" -> "), end),
        Note::FirstImpactEnds { t } => format!(
            "the run ends at its first impact (t = {} s); a scene's `until` carries the motion \
             on through impacts",
            format_number(*t, 6)
        ),
        Note::NoImpact { path } => format!(
            "no contact closed before the motion's end ({})",
            path.join(" -> ")
        ),
        Note::Until(until) => until_words(until),
        Note::Zeno(list) => list.iter().map(zeno_words).collect::<Vec<_>>().join("; "),
    }
}

/// An end's one-word name, as `<contact>_end_cause` and results.json write it: `force`,
/// `edge`, `contact`, `impact`, `floor` or `until`.
pub fn cause_keyword(cause: EndCause) -> &'static str {
    match cause {
        EndCause::Force(_) => "force",
        EndCause::Edge(_) => "edge",
        EndCause::Contact(_) => "contact",
        EndCause::Impact => "impact",
        EndCause::Floor => "floor",
        EndCause::Until => "until",
    }
}

/// What a contact's end cause means.
pub fn cause_words(cause: EndCause) -> &'static str {
    match cause {
        EndCause::Force(_) => "its force reached zero (it would have had to pull)",
        EndCause::Edge(_) => "its contact point ran off a body",
        EndCause::Impact => "the impulses of an impact elsewhere moved it away",
        EndCause::Contact(_) => {
            "another contact closed there: the bodies meet, and the run ends at its first impact \
             unless it is given a time to go on to (`until`)"
        }
        EndCause::Floor => "the body reached the floor",
        EndCause::Until => "the run reached its end (`until`)",
    }
}

/// An event that ends a phase, in words (the cross-check's, an FMU's log).
pub fn event_words(end: EndCause) -> String {
    match end {
        EndCause::Force(c) => format!("contact `{}`'s force crossing zero", c.name),
        EndCause::Edge(c) => format!("contact `{}`'s edge", c.name),
        EndCause::Contact(c) => format!("contact `{}` closing", c.name),
        EndCause::Impact => "an impact elsewhere".into(),
        EndCause::Floor => "the floor".into(),
        EndCause::Until => "the run's end".into(),
    }
}

/// `slides +`, `slides -` or `sticks`.
impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::Slide(Sign::Plus) => "slides +",
            Mode::Slide(Sign::Minus) => "slides -",
            Mode::Stick => "sticks",
        })
    }
}

/// `contact_force, floor_normal closed; floor_friction sticks` (`nothing closed` when no
/// contact is).
impl fmt::Display for ContactSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.closed.is_empty() {
            f.write_str("nothing closed")?;
        } else {
            write!(f, "{} closed", self.closed.join(", "))?;
        }
        for (k, (name, mode)) in self.frictions.iter().enumerate() {
            write!(f, "{}{name} {mode}", if k == 0 { "; " } else { ", " })?;
        }
        Ok(())
    }
}

/// How supports hold a system at rest, before the set that holds it: `redundantly, with`,
/// `with` or `in equilibrium, with`.
impl fmt::Display for Holding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Holding::Redundantly => "redundantly, with",
            Holding::Pinned => "with",
            Holding::InEquilibrium => "in equilibrium, with",
        })
    }
}

/// Why no single set was decided, in words (the message of `SolveError::Indeterminate`).
impl fmt::Display for Indeterminacy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sets = |sets: &[ContactSet], sep: &str| {
            (sets.iter().map(ContactSet::to_string))
                .collect::<Vec<_>>()
                .join(sep)
        };
        match self {
            Indeterminacy::TooManyCombinations { limit } => {
                write!(f, "more than {limit} combinations of contact states to try")
            }
            Indeterminacy::NoneConsistent { singular } => {
                f.write_str(
                    "no set of closed contacts and friction modes is consistent: a contact would \
                     have to pull, or sticking needs more than mu N while no sliding direction \
                     accelerates the slip (Painlevé's inconsistency)",
                )?;
                if !singular.is_empty() {
                    write!(
                        f,
                        "; the equations are singular with {}",
                        sets(singular, "; with ")
                    )?;
                }
                Ok(())
            }
            Indeterminacy::SeveralMotions { sets: found, of } => write!(
                f,
                "{} of {of} consistent sets of closed contacts and friction modes give different \
                 motions ({}): rigid bodies with Coulomb friction do not determine the motion here \
                 (Painlevé's indeterminacy)",
                found.len(),
                sets(found, "; ")
            ),
            Indeterminacy::PainleveSingularity { set, q, floor } => write!(
                f,
                "with {set} the sliding equations approach a singularity at q = {q:?} (their \
                 determinant fell to {floor:e} of the frictionless one): the normal force stops \
                 resisting the sliding (Painlevé's paradox), and rigid bodies with Coulomb \
                 friction have no answer from here"
            ),
            Indeterminacy::RestSingular => f.write_str(
                "the support rows pin every coordinate, yet their normal equations are singular: \
                 whether the supports hold the system at rest is not decided",
            ),
            Indeterminacy::RestTooLarge { limit } => write!(
                f,
                "the redundant supports' forces form a family too large to search (more than \
                 {limit} vertices): whether they hold the system at rest is not decided"
            ),
            Indeterminacy::ImpactTooManyContacts { limit } => {
                write!(f, "more than {limit} contacts take part in one impact")
            }
            Indeterminacy::ImpactNoImpulses => f.write_str(
                "no set of impulses satisfies Newton's law and Coulomb's friction cone with the \
                 contacts pushing",
            ),
            Indeterminacy::ImpactSeveral { count } => write!(
                f,
                "{count} sets of impulses satisfy Newton's law and Coulomb's friction cone with \
                 different velocities after"
            ),
            Indeterminacy::ZenoOutsideContact => f.write_str(
                "a converging sequence of impacts ends while a contact outside it takes part",
            ),
            Indeterminacy::ZenoCannotHold => f.write_str(
                "the contacts of a converging sequence cannot all be held closed at once",
            ),
        }
    }
}

/// Why the motion was halted.
pub fn halt_words(halt: &Halt) -> String {
    match halt {
        Halt::ClosesAsOneOpens { contact, t } => format!(
            "contact `{contact}` closes at t = {} s, as the contact before it opens: the bodies \
             meet, and the run ends at its first impact unless it is given a time to go on to \
             (`until`)",
            format_number(*t, 9)
        ),
        Halt::TooManyImpacts { number, t } => format!(
            "the run stopped at its impact number {number} at t = {t} s: the bounces neither \
             came to rest nor converged"
        ),
        Halt::AtRest { t, held, set } => format!(
            "the system comes to rest at the impact at t = {} s, held {held} {set}, and stays so",
            format_number(*t, 9)
        ),
    }
}

/// Until when a contact held: `until …`.
fn held_words(held: &Held) -> String {
    match held {
        Held::Lands { contact, t } => format!(
            "until the body lands, where contact `{contact}` closes at t = {} s",
            format_number(*t, 6)
        ),
        Held::Halted(halt) => format!("until {}", halt_words(halt)),
        Held::RunsEnd { t } => {
            format!("until the run's end at t = {} s", format_number(*t, 6))
        }
        Held::Floor { angle, end_angle } => {
            format!("until {}", end_angle_words(angle, *end_angle))
        }
        Held::Edge { contact, t } => format!(
            "until contact `{contact}` ran off an edge at t = {} s, where the motion stops",
            format_number(*t, 6)
        ),
    }
}

/// The end of a model's reduced motion: `` `theta` = 0 rad ``.
pub fn end_angle_words(angle: &str, end_angle: f64) -> String {
    format!("`{angle}` = {} rad", format_number(end_angle, 6))
}

/// Why the body did not land, at `t`, along `path`.
fn no_landing(t: f64, path: &str, end: &Unlanded) -> String {
    let at = format_number(t, 6);
    match end {
        Unlanded::At(EndCause::Edge(c)) => format!(
            "contact `{}` ran off an edge at t = {at} s ({path}); the motion after that is not \
             modelled",
            c.name
        ),
        Unlanded::At(EndCause::Contact(c)) => format!(
            "contact `{}` closed at t = {at} s ({path}): the bodies meet, and the run ends at its \
             first impact unless the scene gives a time to go on to (`until`)",
            c.name
        ),
        Unlanded::At(EndCause::Until) => {
            format!("the run reached its end at t = {at} s before the body landed ({path})")
        }
        Unlanded::At(EndCause::Force(_) | EndCause::Impact | EndCause::Floor) => {
            format!("the motion ended before the floor ({path})")
        }
        Unlanded::Halted(halt) => format!(
            "the motion ended before the floor: {} ({path})",
            halt_words(halt)
        ),
        Unlanded::Ended => format!("the motion ended before the floor ({path})"),
    }
}

/// How the motion went with respect to the run's end time.
fn until_words(until: &UntilNote) -> String {
    match until {
        UntilNote::Halted(halt) => halt_words(halt),
        UntilNote::Reached { t, impacts } => format!(
            "the motion was followed to the run's end, t = {} s (`until`), through {impacts} \
             impact(s)",
            format_number(*t, 6)
        ),
        UntilNote::EndedBefore {
            t,
            cause,
            until,
            impacts,
        } => format!(
            "the motion ended at t = {} s ({}), before the run's end (`until` = {} s), after \
             {impacts} impact(s)",
            format_number(*t, 6),
            cause.map_or("", cause_keyword),
            format_number(*until, 6)
        ),
    }
}

/// A converging sequence of bounces closed, in words.
fn zeno_words(zeno: &Zeno) -> String {
    match zeno {
        Zeno::Limit {
            contacts,
            bounces,
            ratio,
            t_limit,
            t,
        } => format!(
            "{} {bounces} times with intervals shrinking by a steady ratio {ratio:.4} (Zeno): \
             the rest, summed as a geometric series, accumulate at t = {t_limit:.12} s, where \
             the impact that closes the sequence is listed (the impact at t = {t:.12} s made \
             plastic); {} closed from that impact",
            sequence_words(contacts),
            closed_words(contacts),
        ),
        Zeno::Unresolved {
            contacts,
            t,
            rise,
            open_gap,
            bounces,
            t_limit,
        } => format!(
            "{} {bounces} times, the last at t = {t:.12} s lifting a contact by {rise:.3e} of \
             the length scale, below the {open_gap:e} at which a gap counts as open: the \
             impacts from there (a converging Zeno sequence) are summed as a geometric series \
             in the impacts' gains, which accumulates at t = {t_limit:.12} s, where the impact \
             that closes the sequence is listed (that impact made plastic); {} closed from \
             that impact",
            sequence_words(contacts),
            closed_words(contacts),
        ),
    }
}

/// Who made a converging sequence: one contact bouncing, or contacts striking in turn.
fn sequence_words(contacts: &[String]) -> String {
    match contacts {
        [one] => format!("contact `{one}` bounced"),
        _ => format!("contacts {} struck in turn", names_words(contacts)),
    }
}

/// What the impact closing a sequence holds closed.
fn closed_words(contacts: &[String]) -> String {
    match contacts {
        [one] => format!("`{one}` is held"),
        _ => format!("{} are held", names_words(contacts)),
    }
}

/// `a`, `b` and `c`.
fn names_words(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => quoted.join(""),
    }
}

/// What a scalar or word-valued result is, in words.
pub fn meaning(meaning: &Meaning) -> String {
    match meaning {
        Meaning::SeparationAngle { angle } => {
            format!("`{angle}` where the first contact's force vanishes")
        }
        Meaning::SeparationTime => "time from release to separation".into(),
        Meaning::LinearisedSeparationAngle => {
            "separation angle with the polynomial's terms above degree 1 dropped".into()
        }
        Meaning::ContactEndTime { contact, cause } => format!(
            "time from release until contact `{contact}` ends: {}",
            cause_words(*cause)
        ),
        Meaning::ContactEndAngle {
            angle,
            contact,
            cause,
        } => format!(
            "`{angle}` where contact `{contact}` ends: {}",
            cause_words(*cause)
        ),
        Meaning::ContactEndCause { contact } => format!(
            "why contact `{contact}` ended: `force` (its force reached zero), `edge` (its point \
             ran off a body) or `contact` (another contact closed, where the motion stops)"
        ),
        Meaning::ContactModes => "the closed contacts and how each friction contact moves over \
                                  the first contact's phase: sticks, or slides + / - along its \
                                  direction, each from the time the set began (switches located \
                                  as events)"
            .into(),
        Meaning::ContactEndFrictionWork => {
            "work done by friction over the first contact's phase (energy lost)".into()
        }
        Meaning::ContactTimeToFloor { angle, end_angle } => format!(
            "time to {} if the release contacts held all the way",
            end_angle_words(angle, *end_angle)
        ),
        Meaning::PointMassFallTime { point, height } => format!(
            "free fall of a point mass from the release height of `{point}` ({} m)",
            format_number(*height, 6)
        ),
        Meaning::FloorImpactFrictionWork { angle, end_angle } => format!(
            "work done by friction from release until {} (energy lost)",
            end_angle_words(angle, *end_angle)
        ),
        Meaning::FloorImpactTime {
            angle,
            end_angle,
            path,
        } => format!(
            "time from release until {} ({})",
            end_angle_words(angle, *end_angle),
            path.join(" -> ")
        ),
        Meaning::ImpactAngularVelocity { angle, path } => format!(
            "rate of `{angle}` when it reaches its end ({})",
            path.join(" -> ")
        ),
        Meaning::CrossCheckTime {
            method,
            steps,
            event,
        } => format!(
            "the general model ({method}, {steps} steps) integrated to {}",
            event_words(*event)
        ),
        Meaning::CrossCheckRelativeDifference {
            event,
            t_quad,
            rtol,
            condition,
        } => format!(
            "|t_ode - t_quadrature| / t_quadrature at {} (quadrature: {t_quad:.15e} s; ODE rtol \
             {rtol:.1e}, mass-matrix condition {condition:.1e})",
            event_words(*event)
        ),
        Meaning::CrossCheckRtol => "relative tolerance the integrator ran with: the one asked, \
                                    raised to 10 eps cond(M) when the mass matrix is \
                                    ill-conditioned"
            .into(),
        Meaning::CrossCheckTimeDeviation { nodes } => {
            format!("largest |t_ode - t(theta_ode)| over {nodes} integrator steps")
        }
        Meaning::CrossCheckStateDeviation { nodes } => format!(
            "largest difference between the integrated and the reduced states over {nodes} \
             steps, relative to the largest coordinate (or velocity) on the path"
        ),
    }
}

/// Why a result has no sensitivities, in words.
pub fn sensitivity_gap(gap: SensitivityGap) -> &'static str {
    match gap {
        SensitivityGap::AtRelease => {
            "no sensitivity: the contact opens at release, so there is no separation to \
             differentiate (the time is zero whatever the parameters)"
        }
        SensitivityGap::NoSeparation => {
            "no sensitivity: the first contact does not separate on the fast phase the motion \
             starts on"
        }
        SensitivityGap::NotBuilt => {
            "sensitivities of impacts are given for their times only \
             (d(impact_<i>_time)/d(<parameter>)): their impulses, normal velocities and \
             energies lost are not differentiated"
        }
        SensitivityGap::PastImpact => {
            "no sensitivity: the result comes after an impact whose map has no derivatives (a \
             restitution given by an expression of the parameters, or redundant contacts)"
        }
        SensitivityGap::PastZeno => {
            "no sensitivity: the result is the limit of a converging (Zeno) sequence of \
             bounces, and the sequence's last times do not give its derivatives (fewer than \
             four impacts resolved, or a geometric series through them does not fit it)"
        }
        SensitivityGap::Grazing => {
            "no sensitivity: an event on the way is grazing (its function's rate is zero \
             there), where the time does not move smoothly with the parameters"
        }
        SensitivityGap::RoutesDisagree => {
            "no sensitivity: the integrated route that carries the sensitivities ends this \
             contact otherwise than the run's route (another event, or another time)"
        }
        SensitivityGap::IntegrationFailed => {
            "no sensitivity: the integrated route that carries the sensitivities failed where \
             the run's route did not"
        }
        SensitivityGap::NoPartials => "no sensitivity: the model has no partial derivatives",
        SensitivityGap::NoFallPolynomial => {
            "no sensitivity of the time: the fast phase has no fall polynomial (it is not \
             from rest, or its potential or inertia are not of that form)"
        }
        SensitivityGap::DoubleRoot => {
            "no sensitivity: the separation is a double root of its condition, where the angle \
             does not move smoothly with the parameters"
        }
        SensitivityGap::NoUnit => {
            "no sensitivity: its unit cannot be formed from the result's and a parameter's \
             (a unit that does not read as one, or powers that overflow)"
        }
        SensitivityGap::OneSided => {
            "no sensitivity in this parameter: it is the restitution of a contact that struck \
             plastically (zero) before the result, and any value above zero makes the contact \
             bounce, a motion of other events: the derivative is one-sided"
        }
    }
}

/// What a sensitivity is, in words (results.json's `meaning`).
pub fn sensitivity_meaning(s: &Sensitivity) -> String {
    if s.elasticity {
        format!(
            "elasticity of {} in {}: ({}/{}) d({})/d({}), the relative change of the result \
             per relative change of the parameter",
            s.of, s.parameter, s.parameter, s.of, s.of, s.parameter
        )
    } else if s.integrated {
        format!(
            "how {} changes with {}: the derivative d({})/d({}) from the motion integrated with \
             its forward sensitivities (the derivation's partial derivatives of the dynamics)",
            s.of, s.parameter, s.of, s.parameter
        )
    } else {
        format!(
            "how {} changes with {}: the exact derivative d({})/d({}) from the derivation's \
             partial derivatives",
            s.of, s.parameter, s.of, s.parameter
        )
    }
}
