//! The motion through impacts (`Walker` with an end time, the planner's `until` and `impacts`)
//! against hand impulse–momentum balances and closed forms that share no code with the models:
//! - the paper's rod and cube (`rod_cube_liftoff`, restitution `e` at both ends) landing flat:
//!   the rod's velocities after by hand (the foot resting on the frictionless floor, the tip
//!   striking it), the closing normal velocity zero at `e = 0`, the energy kept at `e = 1`,
//!   the horizontal momentum kept by vertical impulses, and at `e = 1/2` the flight between
//!   the first two bounces against its quadrature from the energy integral;
//! - `fixed_cylinder` (R = 0.2, th0 = 1.2): the rod that left the cylinder at release strikes
//!   it again at the hand strike time, with the hand impulses;
//! - the run's end and its refusals: `until` reached and said so, a non-positive `until`.

mod common;

use common::hand::Gauss;
use rodcube::models::{all, find};
use rodcube::plan::{self, PlanError, Request};
use rodcube::quantity::Quantity;
use rodcube::results::EndCause;
use rodcube::results::Work;
use rodcube::solve::phases::{MAX_IMPACTS, Motion, Walker};
use rodcube::system::Bound;

const G: f64 = 9.81;
/// The paper's rod and cube (m1, m2, ell, a).
const PAPER: [(&str, f64); 5] = [
    ("m1", 1.0),
    ("m2", 3.0),
    ("ell", 1.0),
    ("a", 0.25),
    ("g", G),
];

fn liftoff_walker(e: f64, until: f64) -> Walker<'static> {
    let mut params = PAPER.to_vec();
    params.push(("e", e));
    Walker::new(
        Bound::new(find("rod_cube_liftoff").unwrap(), &params).unwrap(),
        all(),
        1e-12,
        1e-13,
    )
    .with_until(Some(until))
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1.0);
    assert!((a - b).abs() <= tol * scale, "{what}: {a:e} vs {b:e}");
}

/// The state just before and just after the motion's impact `k` (the general model's
/// coordinates `x1, y1, theta, x2` and their rates).
fn around(motion: &Motion, k: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let at = &motion.impacts[k];
    let before = motion.phases[at.phase].full_end_state().unwrap();
    (
        before.q().to_vec(),
        before.qd().to_vec(),
        at.impact.after.qd().to_vec(),
    )
}

/// The rod lying flat (theta = 0) with its foot resting on the floor and its tip striking it,
/// by hand: with `w` the rate before, the foot's vertical velocity stays zero and the tip's
/// becomes `-e` times its own, so `w+ = -e w`, the centre's vertical velocity `ell/2 w+`; the
/// impulses from the vertical momentum and the angular momentum about the centre,
/// `P_tip + P_foot = m ell/2 (w+ - w)`, `(P_tip - P_foot) ell/2 = m ell^2/12 (w+ - w)`.
fn flat_landing(m: f64, ell: f64, w: f64, e: f64) -> (f64, f64, f64) {
    let w_after = -e * w;
    let dw = w_after - w;
    let (sum, diff) = (m * ell / 2.0 * dw, m * ell / 6.0 * dw);
    (w_after, (sum + diff) / 2.0, (sum - diff) / 2.0)
}

#[test]
fn the_rod_landing_flat_obeys_the_hand_impulse_balance_at_every_restitution() {
    for e in [0.0, 0.5, 1.0] {
        let walker = liftoff_walker(e, 0.2);
        let motion = walker.motion(&mut Work::default()).unwrap();
        assert_eq!(motion.last_end(), Some(EndCause::Until), "e = {e}");
        assert_eq!(motion.impacts.len(), 1, "e = {e}: one landing before 0.2 s");
        let at = &motion.impacts[0];
        let names = ["contact_force", "floor_normal", "tip_floor"];
        assert_eq!(names[at.closing], "tip_floor");
        let (q, qd, qd_after) = around(&motion, 0);
        assert!(
            q[2].abs() < 1e-12 && q[1].abs() < 1e-12,
            "flat on the floor: {q:?}"
        );
        let (w_after, p_tip, p_foot) = flat_landing(1.0, 1.0, qd[2], e);
        close(qd_after[2], w_after, 1e-12, "theta' after");
        close(at.impact.impulse[2], p_tip, 1e-12, "P_tip");
        close(at.impact.impulse[1], p_foot, 1e-12, "P_foot");
        // The foot stays on the floor; the tip leaves at e times its approach.
        close(at.impact.normal_velocity_after[1], 0.0, 1e-12, "foot after");
        close(
            at.impact.normal_velocity_after[2],
            -e * at.impact.normal_velocity_before[2],
            1e-12,
            "tip after",
        );
        // Vertical impulses only: the rod's and the cube's horizontal velocities are kept.
        close(qd_after[0], qd[0], 1e-14, "x1'");
        close(qd_after[3], qd[3], 1e-14, "x2'");
        // The energy lost is what the impulses say, and zero at e = 1.
        let b = &walker.general;
        let before = motion.phases[at.phase].full_end_state().unwrap();
        let lost = b.energy(&before).unwrap() - b.energy(&at.impact.after).unwrap();
        close(at.impact.energy_lost, lost, 1e-12, "energy lost");
        let hand_lost = 0.5 * (1.0 / 12.0 + 0.25) * (qd[2] * qd[2] - w_after * w_after);
        close(lost, hand_lost, 1e-12, "energy lost by hand");
        if e == 1.0 {
            assert!(lost.abs() < 1e-12, "{lost}");
        }
    }
}

#[test]
fn elastic_bounces_keep_the_energy_and_plastic_ones_leave_the_rod_lying() {
    // e = 1: through the landing and the bounces after it to 0.6 s, the energy at the end is
    // the energy at release.
    let walker = liftoff_walker(1.0, 0.6);
    let motion = walker.motion(&mut Work::default()).unwrap();
    assert!(motion.impacts.len() >= 2, "{}", motion.impacts.len());
    let b = &walker.general;
    let e0 = b.energy(&b.initial_state()).unwrap();
    let end = motion.phases.last().unwrap().full_end_state().unwrap();
    let e1 = b.energy(&end).unwrap();
    assert!(((e1 - e0) / e0).abs() < 1e-10, "{e0} -> {e1}");
    assert!(
        motion
            .impacts
            .iter()
            .all(|i| i.impact.energy_lost.abs() < 1e-12)
    );
    // e = 0: the rod stays flat on the floor after landing, at rest but for its slide.
    let walker = liftoff_walker(0.0, 0.6);
    let motion = walker.motion(&mut Work::default()).unwrap();
    assert_eq!(motion.impacts.len(), 1);
    let end = motion.phases.last().unwrap().full_end_state().unwrap();
    assert!(
        end.q()[2].abs() < 1e-12 && end.qd()[2].abs() < 1e-12,
        "{end:?}"
    );
    assert!(
        end.q()[1].abs() < 1e-12 && end.qd()[1].abs() < 1e-12,
        "{end:?}"
    );
    close(motion.end_time(), 0.6, 1e-12, "the run's end");
}

#[test]
fn the_first_bounce_flies_as_the_energy_integral_says() {
    // e = 1/2: after the landing the tip leaves at w+ = -w/2 and the rod, its foot sliding on
    // the frictionless floor with no horizontal force, rises and falls back. Its centre moves
    // vertically only, so (1/2) m (ell/2 cos th)^2 th'^2 + (1/2) m ell^2/12 th'^2
    // + m g ell/2 sin th = (1/2) m ell^2 (1/4 + 1/12) w+^2, and the flight takes
    // 2 int_0^th_max dth / th'.
    let walker = liftoff_walker(0.5, 0.45);
    let motion = walker.motion(&mut Work::default()).unwrap();
    assert!(motion.impacts.len() >= 2, "{}", motion.impacts.len());
    let (_, _, qd_after) = around(&motion, 0);
    let w = qd_after[2];
    let (ell, g) = (1.0, G);
    let rate_sq = |th: f64| {
        let c = th.cos();
        ((1.0 / 3.0) * w * w - g / ell * th.sin()) / (c * c / 4.0 + 1.0 / 12.0)
    };
    // The highest angle: rate_sq = 0, by bisection.
    let (mut lo, mut hi) = (0.0, 1.0);
    assert!(rate_sq(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if rate_sq(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let top = 0.5 * (lo + hi);
    // th = top (1 - u^2) takes the square-root end out of the integrand.
    let flight = 2.0
        * Gauss::new(20).integrate(
            |u| 2.0 * top * u / rate_sq(top * (1.0 - u * u)).max(f64::MIN_POSITIVE).sqrt(),
            0.0,
            1.0,
            16,
        );
    let dt = motion.impacts[1].t - motion.impacts[0].t;
    println!("first bounce: {dt:.15} s, by hand {flight:.15} s");
    close(dt, flight, 1e-9, "the first flight");
}

#[test]
fn the_rod_that_left_the_cylinder_strikes_it_again_and_goes_on() {
    let model = find("fixed_cylinder").unwrap();
    let params = [
        ("m1", 1.0),
        ("ell", 1.0),
        ("R", 0.2),
        ("th0", 1.2),
        ("g", G),
    ];
    let walker =
        Walker::new(Bound::new(model, &params).unwrap(), all(), 1e-12, 1e-13).with_until(Some(1.0));
    let motion = walker.motion(&mut Work::default()).unwrap();
    assert_eq!(
        motion.opened_at_release,
        [0],
        "the cylinder opens at release"
    );
    let at = &motion.impacts[0];
    assert_eq!(at.closing, 0);
    // The hand strike time (tests/contacts_physics.rs: energy, geometry and quadrature).
    close(at.t, 0.2173103556287, 1e-11, "strike time");
    // Plastic (the spec gives no restitution): the rod stays on the cylinder, the foot lifts.
    assert!(at.impact.normal_velocity_after[0].abs() < 1e-12);
    assert!(at.impact.normal_velocity_after[1] > 0.0 && at.impact.impulse[1] == 0.0);
    // The motion goes on past the strike, on the cylinder with the foot in the air.
    assert!(motion.phases.len() >= 2);
    let next = &motion.phases[at.phase + 1];
    assert_eq!(next.closed().unwrap(), [true, false]);
    assert!(next.t_end() > at.t);
}

#[test]
fn a_run_says_it_reached_its_end_and_refuses_a_bad_one() {
    let mut params = PAPER.to_vec();
    params.push(("e", 0.0));
    let model = find("rod_cube_liftoff").unwrap();
    let want = [
        Quantity::Impacts,
        Quantity::FloorImpact,
        Quantity::ThetaSeries,
    ];
    let run = plan::run(
        &Request::new(model, params.as_slice())
            .with_want(&want)
            .with_tolerance(1e-12)
            .with_until(Some(0.5)),
    )
    .unwrap();
    assert!(
        rodcube::report::prose::note(&run.notes["until"]).contains("followed to the run's end"),
        "{:?}",
        run.notes
    );
    let impacts = run.impacts.as_ref().unwrap();
    assert_eq!(impacts.len(), 1);
    assert_eq!(impacts[0].closing, "tip_floor");
    assert_eq!(impacts[0].contacts, ["floor_normal", "tip_floor"]);
    // The landing is the first impact, at the paper's scene's landing (scenes/liftoff.yaml,
    // 0.187051069750276 s by hand in tests/phases.rs).
    close(
        run.results["floor_impact_time"].value,
        0.187051069750276,
        1e-11,
        "landing",
    );
    close(impacts[0].time, 0.187051069750276, 1e-11, "impact time");
    // The series run to the end of the run.
    let t = &run.series["theta_series"].columns[0];
    assert_eq!(t.name, "t");
    close(*t.values.last().unwrap(), 0.5, 1e-12, "series end");
    // Without an end time the run stops at the landing, resolves it, and says so.
    let first = plan::run(
        &Request::new(model, params.as_slice())
            .with_want(&want)
            .with_tolerance(1e-12),
    )
    .unwrap();
    assert_eq!(first.impacts.as_ref().unwrap().len(), 1);
    assert!(
        rodcube::report::prose::note(&first.notes["impacts"]).contains("ends at its first impact")
    );
    for until in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err =
            plan::run(&Request::new(model, params.as_slice()).with_until(Some(until))).unwrap_err();
        assert!(
            matches!(err, PlanError::BadUntil { .. }),
            "{until}: {err:?}"
        );
    }
}

#[test]
fn a_block_that_tipped_comes_down_on_its_near_edge_by_the_hand_impulse() {
    // rod_block_tipping with a light, tall block: pushed by the rod it tips onto its far edge,
    // the rod lets go, and the block rocks back and strikes the floor with its near edge
    // (plastic: no restitution in the spec). By hand, the block alone (the rod has left it):
    // a vertical impulse P at the near edge, r its arm from the centre,
    // P = -(yb' + phi' r_x) / (1/m2 + r_x^2 / I), I = m2 (w^2 + h^2)/12; xb' is kept, and the
    // far edge lifts (its vertical velocity after is positive, so it takes no impulse).
    let (m2, w, h) = (1.3, 0.099, 0.99);
    let params = [
        ("m1", 1.0),
        ("m2", m2),
        ("ell", 1.0),
        ("w", w),
        ("h", h),
        ("g", G),
    ];
    let walker = Walker::new(
        Bound::new(find("rod_block_tipping").unwrap(), &params).unwrap(),
        all(),
        1e-12,
        1e-13,
    )
    .with_until(Some(0.6));
    let motion = walker.motion(&mut Work::default()).unwrap();
    let info = walker.general.info();
    let index = |name: &str| info.contacts.iter().position(|c| c.name == name).unwrap();
    let (near, far) = (index("block_near_edge"), index("block_far_edge"));
    // The near edge lifted earlier (the block tipped), and closes again here.
    assert!(!motion.phases[0].closed_at_end().unwrap()[near] || motion.phases.len() > 1);
    let at = (motion.impacts.iter())
        .find(|i| i.closing == near)
        .expect("the near edge comes down");
    assert!(at.t > 0.5 && at.t < 0.6, "{}", at.t);
    let before = motion.phases[at.phase].full_end_state().unwrap();
    let (q, qd) = (before.q(), before.qd());
    let (phi, phi_dot, yb_dot) = (q[5], qd[5], qd[4]);
    // It comes down flat (phi = 0, where the near edge touches), rotating back.
    assert!(phi.abs() < 1e-12 && phi_dot > 0.0, "{phi}, {phi_dot}");
    let (s, c) = phi.sin_cos();
    let r_near_x = -w / 2.0 * c + h / 2.0 * s;
    let r_far_x = w / 2.0 * c + h / 2.0 * s;
    let inertia = m2 * (w * w + h * h) / 12.0;
    let p = -(yb_dot + phi_dot * r_near_x) / (1.0 / m2 + r_near_x * r_near_x / inertia);
    let (yb_after, phi_after) = (yb_dot + p / m2, phi_dot + r_near_x * p / inertia);
    let after = at.impact.after.qd();
    close(after[4], yb_after, 1e-12, "yb' after");
    close(after[5], phi_after, 1e-12, "phi' after");
    close(after[3], qd[3], 1e-14, "xb' kept");
    close(at.impact.impulse[near], p, 1e-12, "P at the near edge");
    assert_eq!(at.impact.impulse[far], 0.0);
    let far_after = yb_after + phi_after * r_far_x;
    assert!(far_after > 0.0, "the far edge lifts: {far_after}");
    close(
        at.impact.normal_velocity_after[far],
        far_after,
        1e-12,
        "far edge after",
    );
    // The rod is not touched: its velocities are kept.
    for k in 0..3 {
        close(after[k], qd[k], 1e-14, "the rod's velocities");
    }
    // The motion goes on, the block rocking on its near edge.
    let next = &motion.phases[at.phase + 1];
    assert!(next.closed().unwrap()[near] && !next.closed().unwrap()[far]);
}

#[test]
fn elastic_bounces_that_never_converge_stop_at_the_impact_limit_with_a_note() {
    // e = 1: the rod bounces on its upper end for ever, every flight as long as the first
    // (0.3679 s): no Zeno sequence, no rest. Asked to go on to 400 s, the run stops at its
    // impact limit and says so, having kept the energy through every bounce.
    let walker = liftoff_walker(1.0, 400.0);
    let motion = walker.motion(&mut Work::default()).unwrap();
    assert_eq!(motion.impacts.len(), MAX_IMPACTS);
    let why = rodcube::report::prose::halt_words(motion.halted.as_ref().expect("halted"));
    assert!(why.contains("neither came to rest nor converged"), "{why}");
    assert!(motion.complete());
    let flights: Vec<f64> = (motion.impacts.windows(2))
        .map(|w| w[1].t - w[0].t)
        .collect();
    let first = flights[0];
    assert!(
        flights.iter().all(|f| ((f - first) / first).abs() < 1e-6),
        "{first}"
    );
    let b = &walker.general;
    let e0 = b.energy(&b.initial_state()).unwrap();
    let end = motion.phases.last().unwrap().full_end_state().unwrap();
    let e1 = b.energy(&end).unwrap();
    assert!(((e1 - e0) / e0).abs() < 1e-8, "{e0} -> {e1}");
}
