//! Systems whose contact phase is outside the fast path, each one YAML file: `rod_cube_spring`
//! (two coordinates move while in contact, a spring potential) and `rod_cylinder` (a curved
//! contact whose point moves along the rod and can run off its end); their contact phases run on
//! the general model with both contacts as constraint rows. Checked against independent
//! references: the spring going slack reproduces the paper, a hand Newton–Euler balance of each
//! body at random states agrees with the solved contact forces, the edge is where
//! `R cot(theta/2) = ell`, and the integrated route agrees with the fast path where both apply.

mod common;

use common::paper::PAPER_T_SEP;
use rodcube::model::Model;
use rodcube::models::find;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity;
use rodcube::results::RunResults;
use rodcube::solve::integrated::contacts::{Active, dynamics};
use rodcube::solve::phases::Route;
use rodcube::system::{Bound, State};

fn model(name: &str) -> &'static dyn Model {
    find(name).unwrap_or_else(|| panic!("{name} was not generated"))
}

fn ask(name: &str, params: &[(&str, f64)], want: &[Quantity], route: Route) -> RunResults {
    let request = Request::new(model(name), params)
        .with_want(want)
        .with_route(route);
    run(&request).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn value(r: &RunResults, key: &str) -> f64 {
    r.results
        .get(key)
        .unwrap_or_else(|| panic!("no {key} in {:?} (notes {:?})", r.results, r.notes))
        .value
}

fn spring(k: f64) -> [(&'static str, f64); 6] {
    [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
        ("k", k),
    ]
}

const CYLINDER: [(&str, f64); 6] = [
    ("m1", 1.0),
    ("m2", 3.0),
    ("ell", 1.0),
    ("R", 0.2),
    ("th0", 0.9),
    ("g", 9.81),
];

#[test]
fn the_new_models_take_the_integrated_route_and_say_why() {
    for name in ["rod_cube_spring", "rod_cylinder"] {
        let info = model(name).info();
        assert!(info.is_general(), "{name}");
        assert!(info.reduction.is_none(), "{name}");
        assert!(info.route_note.contains("`y1` is not cyclic"), "{name}");
        // The contact phase (both contacts closed) has no fast phase: it is integrated.
        assert!(
            !info.phases.iter().any(|p| p.closed == [0, 1]),
            "{name}: {:?}",
            info.phases
        );
    }
    // With the spring the cube's position is in the potential: no phase reduces to the angle,
    // not even the rod alone on the floor with the cube on its spring.
    assert!(model("rod_cube_spring").info().phases.is_empty());
    assert!(find("rod_cube_spring_free").is_none());
    assert!(find("rod_cube_spring_closed").is_none());
    // After the cylinder the rod and cylinder move freely: both cyclic, the fast path again.
    let phases = model("rod_cylinder").info().phases;
    assert_eq!(phases.len(), 1);
    assert_eq!(
        (phases[0].model, phases[0].closed),
        ("rod_cylinder_free", &[1][..])
    );
    assert!(model("rod_cylinder_free").info().reduction.is_some());
}

#[test]
fn a_slack_spring_gives_the_papers_separation() {
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::ContactEnd,
    ];
    for (tol, bound) in [(1e-10, 1e-12), (1e-12, 1e-13)] {
        let request = Request::new(model("rod_cube_spring"), spring(1e-12))
            .with_want(&want)
            .with_tolerance(tol);
        let r = run(&request).unwrap();
        let t = value(&r, "separation_time");
        let rel = (t - PAPER_T_SEP).abs() / PAPER_T_SEP;
        println!("k = 1e-12, tolerance {tol:e}: t_sep = {t:.15} s, {rel:.2e} from the paper");
        assert!(rel < bound, "{t} vs {PAPER_T_SEP}: {rel:e}");
        assert_eq!(value(&r, "contact_end_time"), t);
        assert_eq!(
            rodcube::report::prose::label(&r.labels["contact_end_cause"].value),
            "force"
        );
        // Eq. (14) with n = 3, r = 1/4: sin(theta_sep) = 0.166957...
        let s = value(&r, "separation_angle").sin();
        let eq14 = 3.0 * s.powi(3) - 48.0 * s + 8.0;
        assert!(eq14.abs() < 1e-10, "{eq14}");
    }
}

#[test]
fn a_stiff_spring_holds_the_cube_and_delays_the_separation() {
    let soft = ask(
        "rod_cube_spring",
        &spring(1e-12),
        &[Quantity::SeparationTime],
        Route::Fastest,
    );
    let stiff = ask(
        "rod_cube_spring",
        &spring(50.0),
        &[
            Quantity::SeparationTime,
            Quantity::FloorImpact,
            Quantity::Checks,
        ],
        Route::Fastest,
    );
    assert!(value(&stiff, "separation_time") > value(&soft, "separation_time"));
    // The contact phase, then the rod alone on the floor (both integrated).
    assert_eq!(
        stiff.work.phases,
        vec![
            "rod_cube_spring (contact_force, floor_normal closed)",
            "rod_cube_spring (floor_normal closed)"
        ]
    );
    for (name, c) in &stiff.checks {
        assert!(c.passed, "{name}: {c:?}");
    }
    assert!(value(&stiff, "floor_impact_time") > value(&stiff, "separation_time"));
}

/// A state of the contact phase: the foot on the floor at `x1 = 0.1` with speed `v1`, the angle
/// and its rate, the other body at `x2 = x1 + tie(theta)` (gap zero) moving with the tie; its
/// accelerations and contact forces with both contacts closed.
fn state_and_dynamics(
    bound: &Bound,
    theta: f64,
    omega: f64,
    v1: f64,
    tie: impl Fn(f64) -> (f64, f64),
) -> (State, Vec<f64>, Vec<f64>) {
    let (x2, dx2) = tie(theta);
    let state = State::new(
        vec![0.1, 0.0, theta, 0.1 + x2],
        vec![v1, 0.0, omega, v1 + dx2 * omega],
    )
    .unwrap();
    let active = Active {
        closed: vec![true, true],
        modes: Vec::new(),
    };
    let d = dynamics(bound, &state, &active, 0.0).unwrap();
    for (i, a) in d.normal_acc.iter().enumerate() {
        assert!(
            a.abs() < 1e-12,
            "theta {theta}: contact {i} accelerates apart: {a:e}"
        );
    }
    (state, d.qdd, d.forces)
}

#[test]
fn the_cylinder_forces_balance_each_body_by_hand() {
    let bound = Bound::new(model("rod_cylinder"), &CYLINDER).unwrap();
    let (m1, m2, ell, r, g) = (1.0, 3.0, 1.0, 0.2, 9.81);
    let inertia = m1 * ell * ell / 12.0;
    let mut worst = 0.0f64;
    for (theta, omega, v1) in [(0.9f64, 0.0, 0.0), (0.7, -1.3, 0.4), (0.5, -2.5, -0.3)] {
        // The axis at xc = x1 + R (1 + cos)/sin, with d/dtheta = -R/(1 - cos).
        let tie = |t: f64| (r * (1.0 + t.cos()) / t.sin(), -r / (1.0 - t.cos()));
        let (_, qdd, f) = state_and_dynamics(&bound, theta, omega, v1, tie);
        let (push, floor) = (f[0], f[1]);
        let (s, c) = (theta.sin(), theta.cos());
        let (x1dd, y1dd, thdd, xcdd) = (qdd[0], qdd[1], qdd[2], qdd[3]);
        // The push is normal to the rod (its gap is the distance to the rod's line): on the
        // cylinder N (sin, -cos).
        let n = push;
        let d = r * (1.0 + c) / s; // contact point's distance from the foot
        // The rod's centre of mass and its acceleration.
        let ax = x1dd - 0.5 * ell * (s * thdd + c * omega * omega);
        let ay = y1dd + 0.5 * ell * (c * thdd - s * omega * omega);
        // The cylinder's axis xc = x1 + R (1 + cos)/sin: d/dtheta = -R/(1 - cos),
        // d2/dtheta2 = R sin/(1 - cos)^2.
        let axc = x1dd - r / (1.0 - c) * thdd + r * s / (1.0 - c).powi(2) * omega * omega;
        let residuals = [
            (m1 * ax + n * s) / (m1 * g),
            (m1 * ay - (n * c + floor - m1 * g)) / (m1 * g),
            (inertia * thdd - ((d - 0.5 * ell) * n - 0.5 * ell * c * floor)) / (m1 * g * ell),
            (m2 * xcdd - n * s) / (m1 * g),
            (xcdd - axc) / g,
            y1dd / g,
        ];
        for (i, res) in residuals.iter().enumerate() {
            assert!(
                res.abs() < 1e-13,
                "theta {theta}: balance {i} off by {res:e}"
            );
            worst = worst.max(res.abs());
        }
    }
    println!("largest Newton-Euler residual: {worst:.1e} (relative to m1 g)");
}

#[test]
fn the_spring_forces_balance_each_body_by_hand() {
    let bound = Bound::new(model("rod_cube_spring"), &spring(50.0)).unwrap();
    let (m1, m2, ell, a, g, k): (f64, f64, f64, f64, f64, f64) = (1.0, 3.0, 1.0, 0.25, 9.81, 50.0);
    let inertia = m1 * ell * ell / 12.0;
    let x2_rest = (ell * ell - a * a).sqrt();
    for (theta, omega, v1) in [(0.25f64, 0.0, 0.0), (0.2, -1.1, -0.2), (0.15, -1.6, -0.45)] {
        let tie = |t: f64| (ell * t.cos(), -ell * t.sin());
        let (state, qdd, f) = state_and_dynamics(&bound, theta, omega, v1, tie);
        let (push, floor) = (f[0], f[1]);
        let (s, c) = (theta.sin(), theta.cos());
        let (x1, x1dd, y1dd, thdd, x2dd) = (state.q()[0], qdd[0], qdd[1], qdd[2], qdd[3]);
        let ax = x1dd - 0.5 * ell * (s * thdd + c * omega * omega);
        let ay = y1dd + 0.5 * ell * (c * thdd - s * omega * omega);
        // The cube's face x2 = x1 + ell cos(theta), pushed by the tip and pulled by the spring.
        let x2 = x1 + ell * c;
        let ax2 = x1dd - ell * (s * thdd + c * omega * omega);
        // On the rod: the cube pushes back at the tip (-push, 0), the floor up at the foot.
        let residuals = [
            (m1 * ax + push) / (m1 * g),
            (m1 * ay - (floor - m1 * g)) / (m1 * g),
            (inertia * thdd - (0.5 * ell * s * push - 0.5 * ell * c * floor)) / (m1 * g * ell),
            (m2 * x2dd - (push - k * (x2 - x2_rest))) / (m1 * g),
            (x2dd - ax2) / g,
            y1dd / g,
        ];
        for (i, res) in residuals.iter().enumerate() {
            assert!(
                res.abs() < 1e-13,
                "theta {theta}: balance {i} off by {res:e}"
            );
        }
    }
}

#[test]
fn the_cylinder_runs_off_the_rods_end_where_r_cot_half_theta_is_ell() {
    let r = ask(
        "rod_cylinder",
        &CYLINDER,
        &[
            Quantity::ContactEnd,
            Quantity::FloorImpact,
            Quantity::Checks,
        ],
        Route::Fastest,
    );
    assert_eq!(
        rodcube::report::prose::label(&r.labels["contact_end_cause"].value),
        "edge"
    );
    let want = 2.0 * (0.2f64).atan();
    let theta = value(&r, "contact_end_angle");
    assert!(((theta - want) / want).abs() < 1e-12, "{theta} vs {want}");
    // What follows an edge (the tip on the cylinder's surface) is not modelled: a note.
    assert!(rodcube::report::prose::note(&r.notes["floor_impact"]).contains("edge"));
    for (name, c) in &r.checks {
        assert!(c.passed, "{name}: {c:?}");
    }
}

/// A rod released steeply on a small cylinder leaves it at once, and meets it again lower down.
///
/// By hand: released from rest without the cylinder, the rod's centre falls straight down
/// (`x1'' = (ell/2) sin(th0) theta''`), so the point of the rod at the tangent distance
/// `d = R (1 + cos)/sin` from the foot accelerates along the rod's normal towards the cylinder
/// by `theta'' ((ell/2) sin^2 - d)`, away from it (`theta'' < 0`) when `(ell/2) sin^2 > d`: the
/// push would have to pull, so the contact opens at release. The rod then falls alone (energy:
/// `theta'^2 (1 + 3 cos^2) = 12 (g/ell) (sin th0 - sin)`, its centre's abscissa fixed) past the
/// cylinder at rest, until the gap `xc - x1 - R (1 + cos)/sin` closes again: the bodies meet
/// there, which ends the motion (impacts are not modelled).
#[test]
fn a_steep_rod_on_a_small_cylinder_leaves_it_at_release_and_meets_it_again() {
    let (ell, r, th0, g) = (1.0f64, 0.05f64, 1.4f64, 9.81);
    let params = [
        ("m1", 1.0),
        ("m2", 1.0),
        ("ell", ell),
        ("R", r),
        ("th0", th0),
        ("g", g),
    ];
    let (s0, c0) = th0.sin_cos();
    assert!(0.5 * ell * s0 * s0 > r * (1.0 + c0) / s0);
    let got = ask(
        "rod_cylinder",
        &params,
        &[Quantity::ContactEnd, Quantity::FloorImpact],
        Route::Fastest,
    );
    assert_eq!(
        rodcube::report::prose::label(&got.labels["contact_end_cause"].value),
        "force"
    );
    assert_eq!(value(&got, "contact_end_time"), 0.0);
    assert_eq!(value(&got, "contact_end_angle"), th0);
    // Only the rod alone on the floor runs (on the fast path), until it meets the cylinder.
    assert_eq!(got.work.phases, vec!["rod_cylinder_free"]);
    assert_eq!(
        rodcube::report::prose::label(&got.labels["floor_normal_end_cause"].value),
        "contact"
    );
    assert!(
        rodcube::report::prose::note(&got.notes["floor_impact"]).contains("the bodies meet"),
        "{:?}",
        got.notes
    );
    // Where the gap closes again, by bisection (it is positive just below th0, negative near
    // the floor).
    let gap =
        |t: f64| r * (1.0 + c0) / s0 - 0.5 * ell * (c0 - t.cos()) - r * (1.0 + t.cos()) / t.sin();
    let (mut lo, mut hi) = (0.05, 1.3);
    assert!(gap(lo) < 0.0 && gap(hi) > 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if gap(mid) < 0.0 { lo = mid } else { hi = mid }
    }
    let meet = 0.5 * (lo + hi);
    // The time to fall there, with theta = th0 - u^2 (the integrand is smooth in u).
    let rate = |u: f64| {
        let t = th0 - u * u;
        (12.0 * g / ell * common::hand::sin_drop(th0, t) / (1.0 + 3.0 * t.cos().powi(2))).sqrt()
    };
    let time =
        common::hand::Gauss::new(20).integrate(|u| 2.0 * u / rate(u), 0.0, (th0 - meet).sqrt(), 16);
    let (angle, t) = (
        value(&got, "floor_normal_end_angle"),
        value(&got, "floor_normal_end_time"),
    );
    println!(
        "rod_cylinder R = {r}, th0 = {th0}: meets the cylinder at {t:.15} s, {angle:.15} rad (by hand {time:.15}, {meet:.15})"
    );
    assert!(((angle - meet) / meet).abs() < 1e-10, "{angle} vs {meet}");
    assert!(((t - time) / time).abs() < 1e-10, "{t} vs {time}");
}

#[test]
fn the_integrated_route_agrees_with_the_fast_path() {
    let paper = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ];
    let want = [Quantity::SeparationAngle, Quantity::SeparationTime];
    for name in ["rod_cube", "hinged_rod"] {
        let fast = ask(name, &paper, &want, Route::Fastest);
        let slow = ask(name, &paper, &want, Route::Integrated);
        for key in ["separation_time", "separation_angle"] {
            let (a, b) = (value(&fast, key), value(&slow, key));
            let rel = ((a - b) / a).abs();
            println!("{name} {key}: fast {a:.15}, integrated {b:.15}, {rel:.1e}");
            assert!(rel < 1e-12, "{name} {key}: {a} vs {b} ({rel:e})");
        }
        assert!(slow.work.ode_steps > 0 && slow.work.integrand_evals == 0);
        assert!(fast.work.ode_steps == 0);
    }
}

#[test]
fn a_hinged_rod_on_a_cylinder_takes_the_fast_path_to_its_edge() {
    // One coordinate left after the tie: the fast path applies although the push's zero is no
    // polynomial root (it is looked for numerically) and the contact has an edge (a root in
    // the angle). The integrated route, sharing no code with it, agrees.
    let system = model("hinged_cylinder").info();
    let release = system
        .phases
        .iter()
        .find(|p| p.release)
        .expect("a release phase");
    assert_eq!(release.model, "hinged_cylinder_closed");
    let info = model("hinged_cylinder_closed").info();
    let layout = info
        .reduction
        .expect("hinged_cylinder_closed has a fast path");
    assert!(!layout.polynomial_separation() && info.contacts[0].edge && info.contacts[0].closed);
    let want = [Quantity::ContactEnd, Quantity::SeparationAngle];
    for (r, th0) in [(0.2, 0.9), (0.05, 1.4)] {
        let params = [
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("R", r),
            ("th0", th0),
            ("g", 9.81),
        ];
        let fast = ask("hinged_cylinder", &params, &want, Route::Fastest);
        let slow = ask("hinged_cylinder", &params, &want, Route::Integrated);
        assert_eq!(
            rodcube::report::prose::label(&fast.labels["contact_end_cause"].value),
            "edge"
        );
        assert_eq!(
            rodcube::report::prose::label(&slow.labels["contact_end_cause"].value),
            "edge"
        );
        let edge = 2.0 * (r / 1.0f64).atan();
        let theta = value(&fast, "contact_end_angle");
        assert!(((theta - edge) / edge).abs() < 1e-14, "{theta} vs {edge}");
        let (t_fast, t_slow) = (
            value(&fast, "contact_end_time"),
            value(&slow, "contact_end_time"),
        );
        let rel = ((t_fast - t_slow) / t_fast).abs();
        println!(
            "hinged_cylinder R = {r}: edge at {t_fast:.15} s (integrated {t_slow:.15}, {rel:.1e})"
        );
        assert!(rel < 1e-12, "{t_fast} vs {t_slow}");
        assert!(fast.notes.contains_key("separation_angle"));
        assert_eq!(fast.work.ode_steps, 0);
    }
    // Its per-point solver is refused with the reason, not given a wrong answer.
    let err = rodcube::solve::fast::lean::LeanSolver::new(model("hinged_cylinder")).unwrap_err();
    assert!(err.to_string().contains("edge"), "{err}");
}
