//! Coulomb friction between the rod's foot and the floor (`rod_cube_friction`, a general model:
//! the foot's height a coordinate and the floor a contact like the cube's face), checked against
//! independent references: mu = 0 is the paper's frictionless case, a foot that never slips is
//! the hinged rod (both held to the 256-bit reference), a hand Newton–Euler balance of each
//! body agrees with the solved contact forces and friction, energy lost equals the work of
//! friction, stick/slip switches sit where their event functions vanish and do not move when the
//! integrator is tightened, a sliding foot past Painlevé's bound (derived by hand) has no
//! consistent motion and says so, and a rod spun fast enough that the floor would have to pull
//! lifts its foot.

mod common;

use common::paper::PAPER_T_SEP;
use rodcube::model::Model;
use rodcube::models::{all, find};
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity;
use rodcube::reference::{Family, Inputs, Reference, RootRoute, TimeRoute, relative_error};
use rodcube::results::{Indeterminacy, RunResults, Work};
use rodcube::solve::SolveError;
use rodcube::solve::integrated::contacts::{
    Active, Mode, Moment, Options, Sign, contact_options, decide, dynamics, friction_options,
};
use rodcube::solve::integrated::ode::Method;
use rodcube::solve::phases::{PhaseRun, PhaseStart, Walker};
use rodcube::system::{Bound, State, SystemError};

/// The active set of the contact phase: both contacts closed, the foot's friction in `mode`.
fn both_closed(mode: &str) -> String {
    format!("contact_force, floor_normal closed; foot_friction {mode}")
}

fn model(name: &str) -> &'static dyn Model {
    find(name).unwrap_or_else(|| panic!("{name} was not generated"))
}

fn paper(mu: f64) -> [(&'static str, f64); 6] {
    [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
        ("mu", mu),
    ]
}

fn ask(name: &str, params: &[(&str, f64)], want: &[Quantity], tolerance: f64) -> RunResults {
    let request = Request::new(model(name), params)
        .with_want(want)
        .with_tolerance(tolerance);
    run(&request).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The 256-bit reference's separation angle and time of `family` at the paper's parameters
/// (`src/reference.rs`: closed forms and arbitrary-precision quadrature, no code shared with
/// the generated models or the planner).
fn reference(family: Family) -> (Reference, rodcube::reference::SeparationReference) {
    let (m1, m2, ell, a, g) = (1.0, 3.0, 1.0, 0.25, 9.81);
    let inputs = Inputs {
        family,
        m1,
        m2,
        ell,
        a,
        g,
    };
    let mut reference = Reference::new(inputs).unwrap();
    let sep = reference.separation(RootRoute::ClosedForm).unwrap();
    (reference, sep)
}

fn value(r: &RunResults, key: &str) -> f64 {
    r.results
        .get(key)
        .unwrap_or_else(|| panic!("no {key} in {:?} (notes {:?})", r.results, r.notes))
        .value
}

const SEPARATION: &[Quantity] = &[
    Quantity::SeparationAngle,
    Quantity::SeparationTime,
    Quantity::ContactEnd,
];

/// The walker of `rod_cube_friction` with the paper's rod and cube and friction `mu`.
fn walker(mu: f64, tol: f64, rtol: f64) -> Walker<'static> {
    Walker::new(
        Bound::new(model("rod_cube_friction"), &paper(mu)).unwrap(),
        all(),
        tol,
        rtol,
    )
}

/// The contact phase (both contacts closed from release) at friction `mu`, solved to its end.
fn contact_phase(mu: f64, tol: f64, rtol: f64) -> PhaseRun<'static> {
    let walker = walker(mu, tol, rtol);
    let (start, opened) = walker.release().unwrap();
    assert!(opened.is_empty(), "mu {mu}: {opened:?} opened at release");
    assert_eq!(start.active.closed, [true, true], "mu {mu}");
    walker.solve(&start, &mut Work::default()).unwrap()
}

#[test]
fn without_friction_the_foot_slides_as_in_the_paper() {
    let r = ask("rod_cube_friction", &paper(0.0), SEPARATION, 1e-12);
    let t = value(&r, "separation_time");
    let rel = (t - PAPER_T_SEP).abs() / PAPER_T_SEP;
    println!("mu = 0: t_sep = {t:.15e} s, {rel:.1e} from the paper");
    assert!(rel < 1e-12, "{t} vs {PAPER_T_SEP}");
    // The angle: eq. (14)'s root, from the 256-bit reference.
    let (_, sep) = reference(Family::RodCube);
    let angle = value(&r, "separation_angle");
    let e = relative_error(angle, &sep.theta).abs();
    assert!(e < 1e-12, "{angle} vs {} ({e:e})", sep.theta_f64);
    // The contact phase slides back all the way to the separation, in one stretch; after it the
    // rod runs on its foot alone.
    assert_eq!(
        r.work.phases[0],
        format!("rod_cube_friction ({})", both_closed("slides -"))
    );
    assert!(
        r.work.phases[1].starts_with("rod_cube_friction (floor_normal closed"),
        "{:?}",
        r.work.phases
    );
    assert_eq!(
        rodcube::report::prose::label(&r.labels["contact_end_cause"].value),
        "force"
    );
    assert_eq!(value(&r, "contact_end_friction_work"), 0.0);
}

#[test]
fn a_foot_that_never_slips_is_the_hinged_rod() {
    // The hinged rod's separation (`3 n s^3 + 3 s - 2 r = 0`, PHYSICS.md erratum 5) and its
    // time from the 256-bit reference, which shares no code with either model.
    let (mut hinged, sep) = reference(Family::HingedRod);
    let t_h = hinged.separation_time(TimeRoute::SinhGauss).unwrap();
    for mu in [2.0, 10.0, 1e6] {
        let r = ask("rod_cube_friction", &paper(mu), SEPARATION, 1e-12);
        let (t, angle) = (value(&r, "separation_time"), value(&r, "separation_angle"));
        let (et, ea) = (
            relative_error(t, &t_h).abs(),
            relative_error(angle, &sep.theta).abs(),
        );
        println!("mu = {mu:e}: t_sep {t:.15e}, {et:.1e} off the hinged rod's, angle {ea:.1e} off");
        assert!(et < 1e-12, "mu {mu}: {t} is {et:e} off the reference");
        assert!(ea < 1e-12, "mu {mu}: {angle} is {ea:e} off the reference");
        assert_eq!(
            r.work.phases[0],
            format!("rod_cube_friction ({})", both_closed("sticks"))
        );
        let label = rodcube::report::prose::label(&r.labels["contact_end_contact_modes"].value);
        assert!(!label.contains("slides"), "{label}");
    }
}

/// The solved accelerations, contact forces and friction satisfy Newton's and Euler's laws for
/// the rod and the cube, written by hand: the floor pushes the foot with (F, N), the cube pushes
/// the tip with (-P, 0), and the cube alone feels P; the closed contacts keep the foot on the
/// floor and the cube's face at the tip.
#[test]
fn the_forces_and_the_friction_balance_each_body_by_hand() {
    let (m1, m2, ell, g) = (1.0, 3.0, 1.0, 9.81);
    let inertia = m1 * ell * ell / 12.0;
    let mut worst = 0.0f64;
    for mu in [0.0, 0.4, 1.3] {
        let bound = Bound::new(model("rod_cube_friction"), &paper(mu)).unwrap();
        for (theta, omega, v1) in [(0.25f64, 0.0, 0.0), (0.2, -1.1, -0.2), (0.15, -1.6, 0.35)] {
            let (s, c) = (theta.sin(), theta.cos());
            // The foot on the floor and the cube's face at the tip, moving with it.
            let state = State::new(
                vec![0.1, 0.0, theta, 0.1 + ell * c],
                vec![v1, 0.0, omega, v1 - ell * s * omega],
            )
            .unwrap();
            let mode = if v1 == 0.0 {
                Mode::Stick
            } else {
                Mode::Slide(Sign::of(v1))
            };
            let active = Active {
                closed: vec![true, true],
                modes: vec![mode],
            };
            let d = dynamics(&bound, &state, &active, 0.0).unwrap();
            let (push, floor, friction) = (d.forces[0], d.forces[1], d.fr[0]);
            let (x1dd, y1dd, thdd, x2dd) = (d.qdd[0], d.qdd[1], d.qdd[2], d.qdd[3]);
            let ax = x1dd - 0.5 * ell * (s * thdd + c * omega * omega);
            let ay = y1dd + 0.5 * ell * (c * thdd - s * omega * omega);
            let tip_ax = x1dd - ell * (s * thdd + c * omega * omega);
            // Torques about the centre: the foot at -(ell/2)(c, s), the tip at +(ell/2)(c, s).
            let torque = -0.5 * ell * c * floor + 0.5 * ell * s * friction + 0.5 * ell * s * push;
            let coulomb = match mode {
                Mode::Slide(sign) => friction + sign.value() * mu * floor,
                Mode::Stick => x1dd,
            };
            let residuals = [
                (m1 * ax - (friction - push)) / (m1 * g),
                (m1 * ay - (floor - m1 * g)) / (m1 * g),
                (inertia * thdd - torque) / (m1 * g * ell),
                (m2 * x2dd - push) / (m1 * g),
                (x2dd - tip_ax) / g,
                y1dd / g,
                coulomb / (m1 * g),
            ];
            for (i, r) in residuals.iter().enumerate() {
                assert!(
                    r.abs() < 1e-13,
                    "mu {mu}, theta {theta}: balance {i} off by {r:e}"
                );
                worst = worst.max(r.abs());
            }
            // The solved normal accelerations of the closed contacts vanish too.
            for (i, a) in d.normal_acc.iter().enumerate() {
                assert!(
                    a.abs() < 1e-13 * g,
                    "mu {mu}, theta {theta}: contact {i}: {a:e}"
                );
            }
        }
    }
    println!("largest Newton-Euler residual: {worst:.1e} (relative to m1 g)");
}

#[test]
fn energy_lost_is_the_work_of_friction() {
    for mu in [0.3, 0.8, 1.3, 1.45] {
        let want = [Quantity::FloorImpact, Quantity::Checks];
        let r = ask("rod_cube_friction", &paper(mu), &want, 1e-10);
        let work = value(&r, "floor_impact_friction_work");
        assert!(work < 0.0, "mu {mu}: friction did work {work}");
        let energy: Vec<_> = r
            .checks
            .iter()
            .filter(|(k, _)| k.ends_with(".energy"))
            .collect();
        assert!(!energy.is_empty());
        for (k, c) in energy {
            assert!(c.passed, "mu {mu}: {k}: {c:?}");
            let meaning = rodcube::report::prose::check_meaning(c);
            assert!(meaning.contains("work of friction"), "{k}: {meaning}");
        }
        println!(
            "mu = {mu}: friction work {work:.6e} J, phases {:?}",
            r.work.phases
        );
    }
}

/// Switch times of the contact phase (s) at tolerance `tol`.
fn switches(mu: f64, tol: f64) -> Vec<f64> {
    let rtol = (tol * 0.01).max(1e-13);
    contact_phase(mu, tol, rtol)
        .stretches()
        .iter()
        .map(|(t, _)| *t)
        .collect()
}

#[test]
fn switches_are_located_where_their_event_functions_vanish() {
    // mu = 1.3: the foot slides back, sticks, then breaks loose forwards.
    let run = contact_phase(1.3, 1e-12, 1e-14);
    let PhaseRun::Integrated(r) = &run else {
        panic!("friction is integrated")
    };
    let bound = &r.bound;
    let modes: Vec<String> = r.run.switches(bound).map(|(_, m)| m.to_string()).collect();
    assert_eq!(
        modes,
        [
            both_closed("slides -"),
            both_closed("sticks"),
            both_closed("slides +")
        ]
    );
    // y0 = [x1, y1, theta, x2, x1', y1', theta', x2', W]. Where the foot stopped, its speed is
    // nothing next to the rod's tip speed.
    let stop = &r.run.segments[1];
    let tip_speed = stop.y0[6].abs(); // ell = 1
    assert!(stop.y0[4].abs() < 1e-13 * tip_speed, "{:?}", stop.y0);
    // Where it broke loose, the friction it needed was mu N.
    let slip = &r.run.segments[2];
    let state = State::new(slip.y0[..4].to_vec(), slip.y0[4..8].to_vec()).unwrap();
    let stuck = Active {
        closed: vec![true, true],
        modes: vec![Mode::Stick],
    };
    let d = dynamics(bound, &state, &stuck, slip.t_start).unwrap();
    let margin = 1.3 * d.forces[1] - d.fr[0].abs();
    assert!(margin.abs() < 1e-12 * d.forces[1], "margin {margin:e}");
    // A tighter integrator moves the switches by less than 1e-12 of their time.
    let (loose, tight) = (switches(1.3, 1e-10), switches(1.3, 1e-11));
    assert_eq!(loose.len(), 3);
    for (a, b) in loose.iter().zip(&tight).skip(1) {
        let rel = (a - b).abs() / b;
        println!("switch at {b:.15e} s moves by {rel:.1e} relative");
        assert!(rel < 1e-12, "{a} vs {b}");
    }
}

/// A stop the integrator steps over. At mu = 1.45 the foot slides back from rest and stops at
/// 0.0965 s; DOP853 forced to rtol 1e-4 takes its first step to 0.109 s, so the slip goes out
/// from zero and back through it within one step. The slip watch starts with its mode's sign
/// (it leaves zero that way), so that step is a crossing: the stop is found, the foot sticks, and
/// the contact ends where a tight integration by the other method puts it (before, the stop
/// was never seen and the phase ran on to the floor at 0.218 s, friction pushing the foot).
#[test]
fn a_stop_inside_one_long_step_is_found() {
    let w = walker(1.45, 1e-12, 1e-4);
    let start = w.release().unwrap().0;
    let run = w
        .integrate_with(&start, Some(Method::Dop853), &mut Work::default())
        .unwrap();
    let PhaseRun::Integrated(r) = &run else {
        panic!("forced onto the integrator")
    };
    let modes: Vec<String> = (r.run.switches(&r.bound))
        .map(|(_, m)| m.to_string())
        .collect();
    assert_eq!(modes, [both_closed("slides -"), both_closed("sticks")]);
    assert!(run.end().is_force_of(0), "{:?}", run.end());
    let tight = walker(1.45, 1e-12, 1e-13);
    let reference = tight
        .integrate_with(&start, Some(Method::Dopri5), &mut Work::default())
        .unwrap();
    let rel = (run.t_end() - reference.t_end()).abs() / reference.t_end();
    // DOP853 at 1e-4 against DOPRI5 at 1e-13: the loose run's own tolerance, with margin.
    assert!(
        rel < 1e-5,
        "{} vs {}: {rel:e}",
        run.t_end(),
        reference.t_end()
    );
}

#[test]
fn a_negative_coefficient_is_refused() {
    let err = Bound::new(model("rod_cube_friction"), &paper(-0.1)).unwrap_err();
    assert!(
        matches!(err, SystemError::NegativeFriction { name: "mu", .. }),
        "{err}"
    );
    assert!(err.to_string().contains("must not be negative"), "{err}");
}

/// The rod alone after the cube has gone (paper's masses and sizes, the cube's face 3 m away at
/// rest), its foot on the floor at angle `theta`, foot speed `v1` and rate `omega`.
fn free_rod_state(theta: f64, v1: f64, omega: f64) -> State {
    State::new(vec![0.0, 0.0, theta, 3.0], vec![v1, 0.0, omega, 0.0]).unwrap()
}

/// The contacts and friction mode the solver decides at a free rod's state, with friction `mu`.
fn decide_free_rod(mu: f64, state: &State) -> Result<Active, SolveError> {
    let bound = Bound::new(model("rod_cube_friction"), &paper(mu)).unwrap();
    let options = Options {
        contacts: contact_options(&bound, state, Moment::Release)?,
        frictions: friction_options(&bound, state)?,
    };
    decide(&bound, state, &options, 0.0)
}

/// Painlevé's inconsistency, by hand: a rod of mass m sliding on its foot with slip sign `s`
/// (`F = -s mu N`) has the foot's vertical acceleration `b + (N / m) K`, with `b = -g +
/// omega^2 (ell/2) sin(theta)` its value in free flight and `K = 1 + 3 cos^2 + 3 s mu sin cos`
/// (Newton and Euler with `I = m ell^2 / 12`). Sliding back (`s = -1`) past
/// `mu = (1 + 3 cos^2) / (3 sin cos)` makes `K < 0`: without spin (`b = -g < 0`) the closed
/// floor would have to pull (`N = -b m / K < 0`) and the open one lets the foot fall through
/// it (`b < 0`). No set is consistent, and the solver says so instead of choosing. Below the
/// bound (`K > 0`) the floor pushes and the foot slides on.
#[test]
fn a_sliding_foot_past_painleves_bound_has_no_consistent_motion() {
    let theta = std::f64::consts::FRAC_PI_4;
    let (s, c) = theta.sin_cos();
    let bound = (1.0 + 3.0 * c * c) / (3.0 * s * c); // 5/3 at 45 degrees
    let state = free_rod_state(theta, -1.0, 0.0);
    let below = decide_free_rod(0.9 * bound, &state).unwrap();
    assert_eq!(below.closed, [false, true]);
    assert_eq!(below.modes, [Mode::Slide(Sign::Minus)]);
    match decide_free_rod(1.1 * bound, &state) {
        Err(SolveError::Indeterminate { why, contacts, .. }) => {
            assert!(
                matches!(*why, Indeterminacy::NoneConsistent { .. }),
                "{why}"
            );
            let words = why.to_string();
            assert!(words.contains("no set of closed contacts"), "{words}");
            assert!(words.contains("Painlevé"), "{words}");
            assert!(contacts.contains(&"floor_normal"), "{contacts:?}");
        }
        Err(e) => panic!("not an inconsistent start: {e}"),
        Ok(active) => panic!("decided {active:?}"),
    }
}

/// A rod spinning fast enough that the floor would have to pull its foot down (the start that
/// had no consistent mode while the floor was held closed): by hand, pinned it needs
/// `N = m (g - 3 g cos^2/4 - omega^2 (ell/2) sin) < 0`, sliding either way `N = -b m / K < 0`
/// (or `K < 0`), while in free flight the foot accelerates up, `b > 0`. The floor opens.
#[test]
fn a_rod_spun_off_the_floor_lifts_its_foot() {
    let (theta, omega, mu): (f64, f64, f64) = (1.0, -12.0, 5.0);
    let (s, c) = theta.sin_cos();
    let (g, ell) = (9.81, 1.0);
    let b = -g + omega * omega * 0.5 * ell * s;
    assert!(b > 0.0);
    assert!(g - 0.75 * g * c * c - omega * omega * 0.5 * ell * s < 0.0);
    let active = decide_free_rod(mu, &free_rod_state(theta, 0.0, omega)).unwrap();
    assert_eq!(active.closed, [false, false]);
}

/// A free rod sliding on its foot with mu above Painlevé's 4/3, rising into the angles where
/// `mu > (tan^2 + 4) / (3 tan)` (here 41.5 to 77.5 degrees): the sliding equations turn
/// singular at the boundary and the solver says so, naming the paradox, rather than reporting a
/// singular mass matrix, a step size too small or a made-up motion.
#[test]
fn a_sliding_rod_that_reaches_painleves_singularity_is_a_typed_error() {
    let state = free_rod_state(0.6, -4.0, 2.0);
    let walker = walker(1.8, 1e-10, 1e-12);
    let active = decide_free_rod(1.8, &state).unwrap();
    assert_eq!(active.closed, [false, true]);
    assert_eq!(active.modes, [Mode::Slide(Sign::Minus)]);
    let start = PhaseStart {
        frictions: friction_options(&walker.general, &state).unwrap(),
        state,
        active,
        t: 0.0,
        friction_work: 0.0,
    };
    match walker.solve(&start, &mut Work::default()) {
        Err(SolveError::Indeterminate { why, .. }) => {
            assert!(
                matches!(*why, Indeterminacy::PainleveSingularity { .. }),
                "{why}"
            );
            let words = why.to_string();
            assert!(words.contains("Painlevé's paradox"), "{words}");
            assert!(words.contains("approach a singularity"), "{words}");
        }
        Err(e) => panic!("not Painlevé's singularity: {e}"),
        Ok(run) => panic!("solved, ending by {:?}", run.end()),
    }
}

/// At release the foot needs `|F| / N` of friction to stay still, by a hand Newton–Euler
/// balance of the rod hinged at its foot pushing the cube from rest: just above that mu it
/// sticks, just below it slides.
#[test]
fn the_foot_sticks_at_release_exactly_above_the_friction_it_needs() {
    let (m1, m2, ell, a, g): (f64, f64, f64, f64, f64) = (1.0, 3.0, 1.0, 0.25, 9.81);
    let (s, c) = (a / ell, (1.0 - (a / ell).powi(2)).sqrt());
    // (m1 ell^2/3 + m2 ell^2 s^2) theta'' = -m1 g ell c / 2 at rest.
    let thdd = -m1 * g * ell * c / 2.0 / (m1 * ell * ell / 3.0 + m2 * ell * ell * s * s);
    let push = m2 * (-ell * s * thdd); // the cube's x2 = ell cos(theta)
    let friction = m1 * (-0.5 * ell * s * thdd) + push; // m1 a_x = F - P
    let normal = m1 * (g + 0.5 * ell * c * thdd);
    let critical = friction / normal;
    println!("critical mu at release: {critical:.15}");
    for (mu, want) in [
        (critical * (1.0 + 1e-9), "sticks"),
        (critical * (1.0 - 1e-9), "slides -"),
    ] {
        let run = contact_phase(mu, 1e-10, 1e-12);
        let first = run.stretches()[0].1.to_string();
        assert_eq!(first, both_closed(want), "mu {mu}");
    }
}

/// The friction series follows Coulomb's law sample by sample: `F = -mu N sign(v)` while the
/// foot slides, `|F| <= mu N` with no slip once it sticks.
#[test]
fn the_friction_series_obeys_coulombs_law() {
    let mu = 1.45;
    let r = ask(
        "rod_cube_friction",
        &paper(mu),
        &[Quantity::parse("foot_friction_series", model("rod_cube_friction").info()).unwrap()],
        1e-10,
    );
    let series = &r.series["foot_friction_series"];
    let col = |name: &str| {
        &series
            .columns
            .iter()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("no column {name}"))
            .values
    };
    let (t, f, n, v) = (
        col("t"),
        col("foot_friction"),
        col("floor_normal"),
        col("slip_velocity"),
    );
    // When the foot stopped and stuck (the one switch at this mu).
    let stick = switches(mu, 1e-10)[1];
    let (mut sliding, mut stuck) = (0, 0);
    for k in 0..t.len() {
        if t[k] < stick - 1e-6 && v[k] != 0.0 {
            assert!(
                (f[k] + mu * n[k] * v[k].signum()).abs() < 1e-12 * mu * n[k],
                "t {}",
                t[k]
            );
            sliding += 1;
        } else if t[k] > stick + 1e-6 {
            assert!(
                f[k].abs() <= mu * n[k],
                "t {}: |F| {} > mu N {}",
                t[k],
                f[k],
                mu * n[k]
            );
            assert!(v[k].abs() < 1e-9, "t {}: slip {}", t[k], v[k]);
            stuck += 1;
        }
    }
    assert!(
        sliding > 10 && stuck > 10,
        "{sliding} sliding, {stuck} stuck samples"
    );
}
