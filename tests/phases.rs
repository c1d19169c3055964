//! Chaining phases: the free phase after separation gets the right state, energy and momentum
//! carry across the boundary, the floor impact follows from them, and the ODE agrees on the free
//! phase. The system is the hand-typed `rod_cube`, walked from phase to phase by [`Walker`].

mod common;

use common::paper::{FREE_ROD, GENERAL, MODELS, ROD_CUBE, paper};
use gauss_quad::GaussLegendre;
use rodcube::model::Model;
use rodcube::reference::{Family, Inputs, Reference, RootRoute, TimeRoute, to_f64};
use rodcube::results::EndCause;
use rodcube::results::Work;
use rodcube::solve::SolveError;
use rodcube::solve::integrated::contacts::Active;
use rodcube::solve::integrated::unreduced::{Start, integrate};
use rodcube::solve::phases::{Motion, Route, Walker, phase_parameters};
use rodcube::system::Bound;

fn walker(registry: &'static [&'static dyn Model]) -> Walker<'static> {
    Walker::new(
        Bound::new(&GENERAL, &paper(9.81)).unwrap(),
        registry,
        1e-13,
        1e-13,
    )
}

fn paper_motion(work: &mut Work) -> Motion<'static> {
    walker(MODELS).motion(work).unwrap()
}

#[test]
fn the_free_phase_starts_from_the_separation_state() {
    let w = walker(MODELS);
    let mut work = Work::default();
    // At release both contacts push: both stay closed, none opens.
    let (release, opened) = w.release().unwrap();
    assert!(opened.is_empty(), "{opened:?}");
    assert_eq!(release.active.closed, vec![true, true]);
    assert_eq!(release.t, 0.0);
    let first = w.solve(&release, &mut work).unwrap();
    assert_eq!(first.bound().name(), "rod_cube_closed");
    assert!(first.end().is_force_of(0), "{:?}", first.end());
    // After the tip's force vanishes, the foot stays on the floor and the tip opens.
    let next = w.after(&first).unwrap();
    assert_eq!(next.active.closed, vec![false, true]);
    assert_eq!(next.t, first.t_end());
    assert_eq!(next.state, first.full_end_state().unwrap());
    let end = first.end_state().unwrap();
    // The system's state at the separation: x1, y1 = 0 (the foot on the floor), theta, and x2
    // where the tip was.
    let tip = first.bound().points(&end).unwrap().pos[1][0];
    assert_eq!(next.state.q()[0], end.q()[0]);
    assert_eq!(next.state.q()[1], 0.0);
    assert_eq!(next.state.q()[2], end.q()[1]);
    assert!((next.state.q()[3] - tip).abs() <= 1e-15);
    // The free phase takes that state as its parameters, by coordinate name.
    let p = phase_parameters(&w.general, FREE_ROD.info(), &next.state).unwrap();
    let s = &next.state;
    let mut want = vec![1.0, 3.0, 1.0, 0.25, 9.81];
    want.extend([
        s.q()[0],
        s.q()[2],
        s.q()[3],
        s.qd()[0],
        s.qd()[2],
        s.qd()[3],
    ]);
    assert_eq!(p, want);
    // The release phase takes only the spec's parameters.
    let p0 = phase_parameters(&w.general, ROD_CUBE.info(), &release.state).unwrap();
    assert_eq!(p0, vec![1.0, 3.0, 1.0, 0.25, 9.81]);
    let sys = w
        .fast_phase(&next)
        .unwrap()
        .expect("a fast phase for the tip open");
    assert_eq!(sys.name(), "rod_cube_free");
    assert_eq!(sys.bound().p(), &p[..]);
    let start = sys.bound().initial_state();
    // x1 and theta carry over; x2 is where the tip was.
    for (a, b) in [
        (end.q()[0], start.q()[0]),
        (end.q()[1], start.q()[1]),
        (end.qd()[0], start.qd()[0]),
        (end.qd()[1], start.qd()[1]),
    ] {
        assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{a} vs {b}");
    }
    assert!((start.q()[2] - tip).abs() <= 1e-15);
    assert_eq!(sys.param("theta_0"), Some(first.theta_end().unwrap()));
    // The release fast phase serves only at release.
    assert!(w.fast_phase(&release).unwrap().is_some());
    let mut later = release.clone();
    later.t = 0.05;
    assert!(w.fast_phase(&later).unwrap().is_none());
}

#[test]
fn floor_impact_conserves_energy_and_momentum_across_the_boundary() {
    let mut work = Work::default();
    let (m1, m2, g, ell) = (1.0, 3.0, 9.81, 1.0);
    let motion = paper_motion(&mut work);
    assert_eq!(work.phases, vec!["rod_cube_closed", "rod_cube_free"]);
    assert!(motion.opened_at_release.is_empty());
    assert!(motion.complete());
    assert_eq!(motion.last_end(), Some(EndCause::Floor));
    let (rc, fr) = (&motion.phases[0], &motion.phases[1]);
    // Energy: the rod + cube system at separation = the free phase's (rod and gliding cube).
    let e_rc = rc.bound().energy(&rc.end_state().unwrap()).unwrap();
    let start = fr.bound().initial_state();
    let e_fr = fr.bound().energy(&start).unwrap();
    assert!((e_fr - e_rc).abs() < 1e-14 * e_rc, "{e_fr} vs {e_rc}");
    // Horizontal momentum stays zero: the rod's centre moves against the cube.
    let v_cm = fr.bound().points(&start).unwrap().vel[2][0];
    let v_cube = start.qd()[2];
    assert!((m1 * v_cm + m2 * v_cube).abs() < 1e-15, "{v_cm} {v_cube}");
    // The cube's speed from eqs. (2) and (5): x2' = -ell s theta' / (2 (1 + n)).
    let sep = rc.reduced().unwrap().separation().unwrap();
    let omega_sep = rc.theta_dot_end().unwrap();
    assert!((v_cube + ell * sep.sin_theta * omega_sep / 8.0).abs() < 1e-15);
    // At the floor all potential energy of the rod is kinetic: m1 v_cm^2 / 2 + m1 ell^2 w^2 / 6.
    let w = motion.end_angular_velocity().unwrap();
    let e_cube = 0.5 * m2 * v_cube * v_cube + m2 * g * 0.25 / 2.0;
    let want = -(6.0 * (e_fr - e_cube - 0.5 * m1 * v_cm * v_cm) / (m1 * ell * ell)).sqrt();
    assert!(((w - want) / want).abs() < 1e-13, "{w} vs {want}");
    let e_end = fr.bound().energy(&fr.end_state().unwrap()).unwrap();
    assert!(((e_end - e_fr) / e_fr).abs() < 1e-14);
    // Times: after separation, and different from the paper's contact-all-the-way 0.18693 s.
    let t = motion.end_time();
    assert!(t > rc.t_end() && (t - 0.18693).abs() > 1e-4);
    // The landing by hand (0.187051069750276 s, -2.70536110443833 rad/s; mpmath agrees):
    // t_sep and sin(theta_sep) from the 256-bit reference, theta'^2 there from eq. (9), the
    // rod's centre then moving at v = x1' - (ell/2) s theta' = (3/8) ell s theta' (eq. 5,
    // n = 3) for good; the free rod's energy per m1, e = v^2/2 + (c^2/4 + 1/12) ell^2 w^2/2
    // + g ell s/2, gives w^2(theta), integrated from theta_sep to 0 by Gauss–Legendre (w != 0
    // on the way: a smooth integrand).
    let mut reference = Reference::new(Inputs {
        family: Family::RodCube,
        m1,
        m2,
        ell,
        a: 0.25,
        g,
    })
    .unwrap();
    let s_sep = to_f64(
        &reference
            .separation(RootRoute::ClosedForm)
            .unwrap()
            .sin_theta,
    );
    let t_sep = to_f64(&reference.separation_time(TimeRoute::SinhGauss).unwrap());
    let (n, r) = (m2 / m1, 0.25 / ell);
    let c_sep = (1.0 - s_sep * s_sep).sqrt();
    let w_sep = -(4.0 * g / ell * (r - s_sep) / (4.0 / 3.0 - s_sep * s_sep / (1.0 + n))).sqrt();
    let v = ((1.0 + 2.0 * n) / (2.0 * (1.0 + n)) - 0.5) * ell * s_sep * w_sep;
    let e = 0.5 * v * v
        + 0.5 * (0.25 * c_sep * c_sep + 1.0 / 12.0) * ell * ell * w_sep * w_sep
        + 0.5 * g * ell * s_sep;
    let w_sq = |theta: f64| {
        (2.0 * e - v * v - g * ell * theta.sin())
            / (ell * ell * (0.25 * theta.cos().powi(2) + 1.0 / 12.0))
    };
    let rule = GaussLegendre::new(40.try_into().unwrap());
    let landing = t_sep + rule.integrate(0.0, s_sep.asin(), |theta| 1.0 / w_sq(theta).sqrt());
    assert!(((t - landing) / landing).abs() < 1e-12, "{t} vs {landing}");
    let w_end = -w_sq(0.0).sqrt();
    assert!(((w - w_end) / w_end).abs() < 1e-12, "{w} vs {w_end}");
    assert_eq!(fr.t_start(), rc.t_end());
}

#[test]
fn ode_agrees_on_the_free_phase() {
    let mut work = Work::default();
    let w = walker(MODELS);
    let motion = w.motion(&mut work).unwrap();
    let fr = &motion.phases[1];
    // The general model integrated from the separation with only the foot's contact closed.
    let start = Start {
        state: motion.phases[0].full_end_state().unwrap(),
        active: Active {
            closed: vec![false, true],
            modes: vec![],
        },
        frictions: vec![],
        friction_work: 0.0,
        stop_at: None,
        dense_output: true,
        sensitivity: None,
    };
    let run = integrate(&w.general, &start, 1e-12, None, 1.0, &mut Work::default()).unwrap();
    assert_eq!(run.end, EndCause::Floor);
    assert!(
        ((run.t_end - fr.duration()) / fr.duration()).abs() < 1e-9,
        "{} vs {}",
        run.t_end,
        fr.duration()
    );
    let theta_dot = run.state_end.qd()[GENERAL.info().reduced_index.unwrap()];
    assert!(((theta_dot - fr.theta_dot_end().unwrap()) / fr.theta_dot_end().unwrap()).abs() < 1e-9);
    // The walker's own integrated route gives the same phase.
    let integrated = (w.clone())
        .with_route(Route::Integrated)
        .with_until(None)
        .with_dense_output(true);
    let next = integrated.after(&motion.phases[0]).unwrap();
    let phase = integrated.solve(&next, &mut Work::default()).unwrap();
    assert!(phase.reduced().is_none());
    assert_eq!(phase.end(), EndCause::Floor);
    assert!(((phase.duration() - fr.duration()) / fr.duration()).abs() < 1e-9);
}

#[test]
fn the_tip_leaves_the_cube_behind() {
    let mut work = Work::default();
    let motion = paper_motion(&mut work);
    let fr = &motion.phases[1];
    let s = rodcube::solve::series::sample(fr, 11, &mut work).unwrap();
    let gap = |i: usize| {
        let q = &s.states[i].q();
        q[2] - q[0] - q[1].cos()
    };
    assert!(gap(0).abs() < 1e-15);
    let mut last = 0.0;
    for i in 1..11 {
        assert!(gap(i) > last, "gap {} after {last}", gap(i));
        last = gap(i);
        // The system's gap of the open contact is the same.
        let g = fr.bound().gaps(&s.states[i]).unwrap()[0];
        assert!((g - gap(i)).abs() <= 1e-15, "{g} vs {}", gap(i));
    }
}

#[test]
fn a_missing_phase_model_is_a_typed_error() {
    static WITHOUT_FREE: [&dyn Model; 2] = [&GENERAL, &ROD_CUBE];
    let err = walker(&WITHOUT_FREE)
        .motion(&mut Work::default())
        .unwrap_err();
    assert_eq!(
        err,
        SolveError::UnknownPhaseModel {
            system: "rod_cube",
            name: "rod_cube_free"
        }
    );
    let err = walker(&[]).motion(&mut Work::default()).unwrap_err();
    assert_eq!(
        err,
        SolveError::UnknownPhaseModel {
            system: "rod_cube",
            name: "rod_cube_closed"
        }
    );
}

#[test]
fn an_integrated_run_without_a_segment_has_no_closed_set() {
    // The integrator ends every run with a segment; one emptied by hand is refused, not read as
    // "no contact closed".
    let w = walker(MODELS).with_route(Route::Integrated);
    let mut work = Work::default();
    let (release, _) = w.release().unwrap();
    let mut phase = w.solve(&release, &mut work).unwrap();
    assert_eq!(phase.closed().unwrap(), vec![true, true]);
    assert_eq!(phase.closed_at_end().unwrap(), vec![true, true]);
    let rodcube::solve::phases::PhaseRun::Integrated(run) = &mut phase else {
        panic!("the integrated route gave a fast phase");
    };
    run.run.segments.clear();
    for got in [phase.closed(), phase.closed_at_end()] {
        assert!(
            matches!(
                got,
                Err(SolveError::ActiveSize {
                    contacts: 2,
                    closed: 0,
                    ..
                })
            ),
            "{got:?}"
        );
    }
}
