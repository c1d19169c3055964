//! No failure is dropped on the way: each place where the solvers or the planner used to turn a
//! failure into a default (a skipped candidate, a zero, an infinite scale, a silent `Ok`) now
//! returns a typed error or records why, and each is driven here by a tweaked model or a crafted
//! input.

#[macro_use]
mod common;

use common::paper::{GENERAL, MODELS, paper};
use common::tweaked::{NAN_FORCE, registry};
use rodcube::model::{Model, ModelInfo, Partials, Reduced, Reduction, Tangents};
use rodcube::plan::drawing::{PhaseInput, record};
use rodcube::plan::{self, PlanError, Request};
use rodcube::quantity::Quantity;
use rodcube::report::motion::Animation;
use rodcube::results::EndCause;
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::fast::quadrature::TimeMesh;
use rodcube::solve::fast::separation::{SeparationOutcome, edge, first_zero, force_zero};
use rodcube::solve::phases::{PhaseRun, ReducedEnd, ReducedRun, Walker};
use rodcube::solve::series::{PhaseSamples, sample_friction, theta_dot_at};
use rodcube::system::{Bound, State, System, SystemError};
use std::sync::OnceLock;

/// The hand-typed general `rod_cube` whose cube has no mass: its mass matrix is singular,
/// while with the tip's contact closed the constrained equations still have one solution.
struct MasslessCube;

impl Model for MasslessCube {
    forward_model!(|_: &Self| &GENERAL; info, requirements, restitutions, prepare, initial_state, points, energy, momenta, forces_full, gaps, constraints, edges, friction, monitors_full, to_full, drawing);

    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        GENERAL.equations(k, q, qd, mass, rhs);
        // The cube's row and column of the mass matrix (x2 is the last of four coordinates).
        mass[15] = 0.0;
    }
    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        None
    }
}

/// Deciding the contacts judges each one's normal acceleration against a scale made with the
/// inverse mass matrix. Without an inverse, that scale used to be infinite, so that every
/// open candidate passed as accelerating apart: the decision rested on no test at all. It is
/// an error now.
#[test]
fn a_mass_matrix_without_an_inverse_is_an_error_not_a_guess() {
    let general = Bound::new(&MasslessCube, &paper(9.81)).unwrap();
    let walker = Walker::new(general, MODELS, 1e-10, 1e-12);
    match walker.release() {
        Err(SolveError::SingularMassMatrix { t, q }) => {
            assert_eq!(t, 0.0);
            assert_eq!(q, walker.general.initial_state().q());
        }
        other => panic!("{other:?}"),
    }
    // The same system with its cube's mass decides as before.
    let plain = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let walker = Walker {
        general: plain,
        ..walker
    };
    let (start, opened) = walker.release().unwrap();
    assert_eq!(start.active.closed, [true, true]);
    assert!(opened.is_empty());
}

/// An edge asked of a contact without one used to read its margin as `+inf` everywhere (no
/// edge reached, silently), and a contact the model does not have as NaN (an error about a
/// non-finite margin). Both are the refusal that names the contact.
#[test]
fn an_end_asked_of_a_contact_that_cannot_end_so_is_refused_by_name() {
    let model = rodcube::models::find("rod_cube_closed").unwrap();
    let sys = System::new(model, &paper(9.81)).unwrap();
    let mut work = Work::default();
    for contact in [0, 1, 7] {
        match edge(&sys, contact, &mut work) {
            Err(SolveError::NoContact {
                model: "rod_cube_closed",
                contact: c,
                edge: true,
            }) => assert_eq!(c, contact),
            other => panic!("edge of {contact}: {other:?}"),
        }
    }
    match force_zero(&sys, 7, &mut work) {
        Err(
            e @ SolveError::NoContact {
                contact: 7,
                edge: false,
                ..
            },
        ) => {
            assert!(e.to_string().contains("contact 7"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        force_zero(&sys, 0, &mut work),
        Ok(SeparationOutcome::Separates(_))
    ));
    // A function whose evaluation fails: its error, not a value standing in for it.
    let failing = |_: &System, delta: f64| {
        if delta > 0.01 {
            Err(SolveError::NonFinite {
                model: "test",
                what: "a broken margin",
                delta,
                value: f64::NAN,
            })
        } else {
            Ok(1.0)
        }
    };
    match first_zero(&sys, failing, &mut work) {
        Err(SolveError::NonFinite {
            what: "a broken margin",
            delta,
            ..
        }) => assert!(delta > 0.01),
        other => panic!("{other:?}"),
    }
}

/// `theta_dot` from a `theta_dot^2` that is not a number used to come out `-0` (a NaN lost in
/// `max(0)`), so a sample at such an angle was a state at rest. It is NaN, and a state cannot
/// be made of it.
#[test]
fn a_rate_that_is_not_a_number_stays_one() {
    let model = rodcube::models::find("rod_cube_closed").unwrap();
    let sys = System::new(model, &paper(9.81)).unwrap();
    assert!(theta_dot_at(&sys, f64::NAN).is_nan());
    assert!(theta_dot_at(&sys, f64::INFINITY).is_nan());
    assert!(theta_dot_at(&sys, 0.1) < 0.0);
    assert_eq!(theta_dot_at(&sys, 0.0), 0.0);
    assert!(matches!(
        sys.full_state(0.0, 0.1, theta_dot_at(&sys, f64::NAN)),
        Err(SystemError::NotFiniteInput {
            what: "theta_dot",
            ..
        })
    ));
}

/// Where the motion starts on a fast phase, its end by the roots was looked for once with the
/// error dropped (the separation then taken from the motion, which met the same error again).
/// The end's error is the quantity's error at once.
#[test]
fn a_fast_phase_whose_end_fails_fails_the_separation() {
    let request = Request::new(&GENERAL, paper(9.81))
        .with_want(&[Quantity::SeparationAngle])
        .with_registry(registry(&NAN_FORCE));
    match plan::run(&request) {
        Err(PlanError::Solve(SolveError::NonFinite { model, what, .. })) => {
            assert_eq!(model, "rod_cube_closed");
            assert!(what.contains("closed contact's force"), "{what}");
        }
        other => panic!("{other:?}"),
    }
}

/// `rod_cube_closed` listing only its first contact: a phase whose contacts are not its
/// system's (the contract says every model of a system lists the same contacts).
struct OneContact {
    base: &'static dyn Model,
}

fn one_contact_info(base: &'static ModelInfo) -> &'static ModelInfo {
    static INFO: OnceLock<&'static ModelInfo> = OnceLock::new();
    INFO.get_or_init(|| {
        Box::leak(Box::new(ModelInfo {
            contacts: &base.contacts[..1],
            monitors: &[],
            ..*base
        }))
    })
}

impl OneContact {
    fn red(&self) -> &'static dyn Reduction {
        self.base.reduction().expect("a fast phase")
    }
    /// The base's values for both contacts, the first kept.
    fn first(out: &mut [f64], fill: impl FnOnce(&mut [f64])) {
        let mut both = [0.0; 2];
        fill(&mut both);
        out[0] = both[0];
    }
}

impl Model for OneContact {
    forward_model!(|m: &Self| m.base; requirements, prepare, initial_state, points, energy, momenta, equations, friction, to_full, drawing);

    fn info(&self) -> &'static ModelInfo {
        one_contact_info(self.base.info())
    }
    fn restitutions(&self, _p: &[f64], out: &mut [f64]) {
        // The one contact kept is the base's first, which is plastic (the spec gives it none).
        out.fill(0.0);
    }
    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        Self::first(out, |both| self.base.forces_full(k, q, qd, qdd, both))
    }
    fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        Self::first(out, |both| self.base.gaps(k, q, both))
    }
    fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        let n = self.info().coordinates.len();
        let (mut j2, mut b2) = (vec![0.0; 2 * n], [0.0; 2]);
        self.base.constraints(k, q, qd, &mut j2, &mut b2);
        jac.copy_from_slice(&j2[..n]);
        bias[0] = b2[0];
    }
    fn edges(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        Self::first(out, |both| self.base.edges(k, q, both))
    }
    fn monitors_full(&self, _k: &[f64], _q: &[f64], _qd: &[f64], _f: &[f64], _out: &mut [f64]) {}
    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        Some(self)
    }
}

impl Reduction for OneContact {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        self.red().reduced(k, delta)
    }
    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        self.red().theta_dot_sq_sc(k, s, c, ds, dc)
    }
    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        Self::first(out, |both| self.red().forces(k, delta, both))
    }
    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]) {
        self.red().force_polynomial(k, contact, out)
    }
    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]) {
        self.red().fall_polynomial(k, out)
    }
    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        self.red().prepare_lean(p, k)
    }
    fn partials(&self) -> Option<&dyn Partials> {
        None
    }

    fn full_state(
        &self,
        k: &[f64],
        t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) {
        self.red().full_state(k, t, delta, theta_dot, q, qd)
    }
}

/// A friction's normal force read off a fast phase that lacks the friction's contact used to
/// be zero (a lookup defaulted); it is the mismatch, named.
#[test]
fn a_friction_whose_contact_the_phase_lacks_is_a_mismatch_not_zero() {
    static PHASE: OnceLock<OneContact> = OnceLock::new();
    let phase = PHASE.get_or_init(|| OneContact {
        base: rodcube::models::find("rod_cube_closed").unwrap(),
    });
    let system = System::new(phase, &paper(9.81)).unwrap();
    let friction = rodcube::models::find("rod_cube_friction").unwrap();
    let mut p = paper(9.81).to_vec();
    p.push(("mu", 0.3));
    let general = Bound::new(friction, &p).unwrap();
    let state = system
        .full_state(0.0, 0.1, theta_dot_at(&system, 0.1))
        .unwrap();
    let samples = PhaseSamples {
        t: vec![0.0],
        delta: vec![0.1],
        states: vec![state],
        ..PhaseSamples::default()
    };
    let run = PhaseRun::Reduced(ReducedRun {
        system,
        t_start: 0.0,
        end: ReducedEnd {
            end: EndCause::Floor,
            at: None,
            delta: 0.2,
        },
        mesh: TimeMesh::empty(),
    });
    match sample_friction(&run, &general, &samples) {
        Err(SolveError::PhaseMismatch { system, name, why }) => {
            assert_eq!((system, name), ("rod_cube_friction", "rod_cube_closed"));
            assert!(why.contains("1 contacts, the system 2"), "{why}");
        }
        other => panic!("{other:?}"),
    }
}

/// A frame whose state the model refuses used to panic in the generated drawing; it is left
/// out, counted, and the refusal noted.
#[test]
fn a_frame_the_model_refuses_is_dropped_with_a_note() {
    let bound = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    let good = bound.initial_state();
    let short = State::new(vec![0.0; 3], vec![0.0; 3]).unwrap();
    let samples = PhaseSamples {
        t: vec![0.0, 0.1, 0.2],
        states: vec![good.clone(), short, good],
        ..PhaseSamples::default()
    };
    let input = PhaseInput {
        bound: &bound,
        samples: &samples,
        t_start: 0.0,
        end: EndCause::Floor,
    };
    let animation = Animation::build(&record(&[input], Some("tip")));
    assert_eq!(animation.frames.len(), 2);
    assert_eq!(animation.dropped, 1);
    assert!(
        animation
            .notes
            .iter()
            .any(|n| n.contains("not drawn") && n.contains("takes 4 values in `state`, got 3")),
        "{:?}",
        animation.notes
    );
    // A first state the model refuses leaves the shapes out, with a note, and no frame.
    let bad = PhaseSamples {
        t: vec![0.0],
        states: vec![State::new(vec![], vec![]).unwrap()],
        ..PhaseSamples::default()
    };
    let input = PhaseInput {
        bound: &bound,
        samples: &bad,
        t_start: 0.0,
        end: EndCause::Floor,
    };
    let animation = Animation::build(&record(&[input], None));
    assert!(animation.shapes.is_empty() && animation.frames.is_empty());
    assert_eq!(animation.dropped, 1);
    assert!(
        animation
            .notes
            .iter()
            .any(|n| n.contains("shapes of `rod_cube` are not drawn")),
        "{:?}",
        animation.notes
    );
}

/// The general `rod_cube` whose `reduced_index` names no coordinate (a malformed generated
/// model): the planner used to call its angle `theta` anyway.
struct NoReducedCoordinate;

impl Model for NoReducedCoordinate {
    forward_model!(|_: &Self| &GENERAL; requirements, restitutions, prepare, initial_state, points, energy, momenta, equations, forces_full, gaps, constraints, edges, friction, monitors_full, to_full, drawing);

    fn info(&self) -> &'static ModelInfo {
        static INFO: OnceLock<&'static ModelInfo> = OnceLock::new();
        INFO.get_or_init(|| {
            Box::leak(Box::new(ModelInfo {
                reduced_index: Some(4),
                ..*GENERAL.info()
            }))
        })
    }
    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        None
    }
}

#[test]
fn a_model_whose_reduced_index_names_no_coordinate_is_refused_when_bound() {
    match Bound::new(&NoReducedCoordinate, &paper(9.81)) {
        Err(SystemError::ReducedIndex {
            model: "rod_cube",
            index: 4,
            coordinates: 4,
        }) => {}
        other => panic!("{other:?}"),
    }
    let plain = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    assert_eq!(plain.reduced_coordinate(), Some("theta"));
}
