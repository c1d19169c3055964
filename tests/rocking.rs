//! Housner's rocking block (`rocking_block`) through its strikes, impacts with friction
//! (`solve::integrated::impact`), against references worked out here by hand, sharing no code with
//! the model:
//! - the angular velocity ratio at every strike, `1 - (3/2) sin^2(alpha)`, `alpha = atan(w/h)`
//!   (angular momentum about the new corner), and the strike times by the corner pendulum's
//!   energy integral (Gauss–Legendre of `tests/common/hand.rs`);
//! - friction holding at the pivot at release (Newton–Euler about the corner) and at the strike
//!   (the impulse ratio `h (1 - r) / (w (1 + r))`);
//! - with a small `mu` the strike slides: an impulse–momentum balance of the sliding case;
//! - `e = 1` without friction keeps the energy through every strike;
//! - no impact creates energy, over random states, contact sets, `mu` and `e` (a property).

mod common;

use common::hand::{Gauss, solve_linear};
use proptest::prelude::*;
use rodcube::models::{all, find};
use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::results::{Halt, Work, Zeno};
use rodcube::solve::SolveError;
use rodcube::solve::integrated::contacts::Sign;
use rodcube::solve::integrated::impact::{ContactLaw, FrictionLaw, Part, resolve};
use rodcube::solve::phases::{Motion, Walker};
use rodcube::system::{Bound, State};

const G: f64 = 9.81;
const M: f64 = 1.0;
const W: f64 = 0.4;
const H: f64 = 1.0;
const PHI0: f64 = 0.2;

/// The block's parameters with friction `mu` and restitution `e`.
fn parameters(mu: f64, e: f64) -> [(&'static str, f64); 7] {
    [
        ("m", M),
        ("w", W),
        ("h", H),
        ("phi0", PHI0),
        ("g", G),
        ("mu", mu),
        ("e", e),
    ]
}

fn bound(mu: f64, e: f64) -> Bound<'static> {
    Bound::new(find("rocking_block").unwrap(), &parameters(mu, e)).unwrap()
}

fn walker(mu: f64, e: f64, until: f64) -> Walker<'static> {
    Walker::new(bound(mu, e), all(), 1e-12, 1e-13)
        .with_until(Some(until))
        .with_dense_output(false)
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1.0);
    assert!((a - b).abs() <= tol * scale, "{what}: {a:e} vs {b:e}");
}

/// `alpha = atan(w/h)`, the half-diagonal `R` and `k = 2 m g R / I_O = 3 g / (2 R)`.
fn geometry() -> (f64, f64, f64) {
    let alpha = (W / H).atan();
    let r = 0.5 * (W * W + H * H).sqrt();
    (alpha, r, 1.5 * G / r)
}

/// Housner's ratio `omega+ / omega-` for a plastic strike that sticks.
fn housner() -> f64 {
    1.0 - 1.5 * geometry().0.sin().powi(2)
}

/// The time the corner pendulum takes from rest at amplitude `a` (tilt from upright) to
/// upright: `int_0^a dpsi / sqrt(k (cos(alpha - a) - cos(alpha - psi)))`. With
/// `a - psi = a s^2` the square-root singularity at the turning point goes, and
/// `cos(alpha - a) - cos(alpha - a + a s^2) = 2 sin(alpha - a + a s^2 / 2) sin(a s^2 / 2)`
/// has no cancellation.
fn quarter(a: f64) -> f64 {
    let (alpha, _, k) = geometry();
    let f = |s: f64| {
        let d = 2.0 * (alpha - a + 0.5 * a * s * s).sin() * (0.5 * a * s * s).sin();
        2.0 * a * s / (k * d).sqrt()
    };
    Gauss::new(20).integrate(f, 0.0, 1.0, 8)
}

/// The amplitude `A` a swing that leaves upright at `omega` reaches:
/// `cos(alpha - A) - cos(alpha) = 2 sin(alpha - A/2) sin(A/2) = omega^2 / k`, by fixed-point
/// iteration on `A = 2 asin(omega^2 / (2 k sin(alpha - A/2)))` (no cancellation for small
/// swings).
fn amplitude(omega_sq: f64) -> f64 {
    let (alpha, _, k) = geometry();
    let mut a = omega_sq / (k * alpha.sin());
    for _ in 0..60 {
        a = 2.0 * (omega_sq / (2.0 * k * (alpha - 0.5 * a).sin())).asin();
    }
    a
}

/// The strike times by hand, plastic and sticking: `t_1 = T(phi0)`, then each half-swing
/// `2 T(A_i)` with `A_i` the amplitude `omega_i = r^i omega_0` reaches ([`amplitude`]).
fn hand_strikes(count: usize) -> Vec<f64> {
    let (alpha, _, k) = geometry();
    let omega0_sq = k * ((alpha - PHI0).cos() - alpha.cos());
    let mut t = vec![quarter(PHI0)];
    let mut omega_sq = omega0_sq;
    for _ in 1..count {
        omega_sq *= housner().powi(2);
        let last = t[t.len() - 1];
        t.push(last + 2.0 * quarter(amplitude(omega_sq)));
    }
    t
}

/// The state just before and just after impact `k` of `motion`.
fn around(motion: &Motion, k: usize) -> (State, State) {
    let at = &motion.impacts[k];
    let before = motion.phases[at.phase].full_end_state().unwrap();
    (before, at.impact.after.clone())
}

#[test]
fn every_strike_keeps_housners_ratio_at_the_energy_integrals_times() {
    // Seven strikes before 2 s (the strikes accumulate near 2.39 s, each swing shorter).
    let w = walker(1.0, 0.0, 2.0);
    let motion = w.motion(&mut Work::default()).unwrap();
    let count = motion.impacts.len();
    assert_eq!(count, 7, "strikes before 2 s");
    let hand = hand_strikes(count);
    for (k, at) in motion.impacts.iter().enumerate() {
        let (before, after) = around(&motion, k);
        assert!(
            before.q()[2].abs() < 1e-9,
            "upright at the strike: {}",
            before.q()[2]
        );
        close(
            after.qd()[2] / before.qd()[2],
            housner(),
            1e-12,
            "omega+/omega-",
        );
        close(at.t, hand[k], 1e-10, &format!("strike {k}'s time"));
        // The new corner strikes and sticks, the old one lifts.
        let (new, old) = if k % 2 == 0 { (1, 0) } else { (0, 1) };
        assert_eq!(at.closing, new);
        assert_eq!(at.impact.laws[new], ContactLaw::Restitution);
        assert_eq!(at.impact.laws[old], ContactLaw::Open);
        assert_eq!(at.impact.friction_laws[new], FrictionLaw::Stick);
        assert_eq!(at.impact.friction_laws[old], FrictionLaw::Out);
        // Plastic and stuck: the energy ratio is r^2, all of it lost by the normal impulse.
        let b = &w.general;
        let lost = b.energy(&before).unwrap() - b.energy(&after).unwrap();
        close(at.impact.energy_lost, lost, 1e-12, "energy lost");
        close(
            at.impact.friction_energy_lost,
            0.0,
            1e-12,
            "friction's part",
        );
        let kinetic = 0.5 * (M * (W * W + H * H) / 3.0) * before.qd()[2].powi(2);
        close(
            lost,
            kinetic * (1.0 - housner().powi(2)),
            1e-11,
            "lost by hand",
        );
    }
}

#[test]
fn the_block_comes_to_rest_where_its_strikes_accumulate() {
    // The strikes shrink by Housner's ratio each; their times sum to a finite limit, where
    // the block stands on both corners at rest. By hand: the energy integral's half-swings
    // summed until they no longer change the sum (400 strikes, the last some 1e-40 s).
    let hand = hand_strikes(400);
    let limit = hand[hand.len() - 1];
    let w = walker(1.0, 0.0, 4.0);
    let motion = w.motion(&mut Work::default()).unwrap();
    let Some(Halt::AtRest { t, .. }) = &motion.halted else {
        panic!("not at rest: {:?}", motion.halted);
    };
    close(*t, limit, 1e-10, "the time the block comes to rest");
    let (last, strikes) = motion.impacts.split_last().unwrap();
    close(
        last.zeno.unwrap(),
        limit,
        1e-10,
        "the accumulation time listed",
    );
    assert!(strikes.iter().all(|s| s.zeno.is_none()));
    assert!(strikes.len() > 20, "{} strikes resolved", strikes.len());
    for (k, at) in motion.impacts.iter().enumerate() {
        close(at.t, hand[k], 1e-10, &format!("strike {k}'s time"));
    }
    // Both corners held closed by the impact that closes the sequence, the block at rest.
    assert_eq!(last.parts, [Part::Bilateral, Part::Bilateral]);
    assert!(last.impact.after.qd().iter().all(|v| v.abs() < 1e-15));
    let [Zeno::Unresolved { contacts, .. }] = motion.notes.as_slice() else {
        panic!("{:?}", motion.notes);
    };
    assert_eq!(contacts.len(), 2, "both corners named: {contacts:?}");
}

#[test]
fn friction_holds_at_the_pivot_and_at_the_strike() {
    let (mu, ratio) = (0.7, housner());
    // At the strike the stuck corner's impulses are in the ratio h (1 - r) / (w (1 + r)).
    let by_hand = H * (1.0 - ratio) / (W * (1.0 + ratio));
    assert!(by_hand <= mu, "{by_hand}");
    let motion = walker(mu, 0.0, 1.5).motion(&mut Work::default()).unwrap();
    assert!(motion.impacts.len() >= 3);
    for at in &motion.impacts {
        let c = at.closing;
        let impact = &at.impact;
        close(
            impact.friction_impulse[c].abs() / impact.impulse[c],
            by_hand,
            1e-12,
            "|P_t| / P_n",
        );
    }
    // Along the rocking: the pivot's |F| / N, and at release Newton–Euler about the corner:
    // phi'' = -m g R sin(alpha - phi0) / I_O, the centre's acceleration phi'' z x r (r from the
    // pivot to the centre), F = m a_x, N = m (g + a_y).
    let request = Request::new(find("rocking_block").unwrap(), &parameters(mu, 0.0)[..])
        .with_want(&[Quantity::FrictionSeries(0), Quantity::FrictionSeries(1)])
        .with_tolerance(1e-10)
        .with_samples(400)
        .with_until(Some(1.5));
    let run = plan::run(&request).unwrap();
    let (alpha, r, _) = geometry();
    let phi_dd = -M * G * r * (alpha - PHI0).sin() / (M * (W * W + H * H) / 3.0);
    let (s, c) = PHI0.sin_cos();
    let to_centre = [0.5 * W * c - 0.5 * H * s, 0.5 * W * s + 0.5 * H * c];
    let (fx, n) = (-M * phi_dd * to_centre[1], M * (G + phi_dd * to_centre[0]));
    let mut checked = 0;
    for (corner, friction) in [
        ("left_corner", "left_friction"),
        ("right_corner", "right_friction"),
    ] {
        let name = format!("{friction}_series");
        let series = &run.series[&name];
        let col = |label: &str| {
            let found = series.columns.iter().find(|c| c.name == label);
            &found
                .unwrap_or_else(|| panic!("{name}: no column {label}"))
                .values
        };
        let (t, f, normal) = (col("t"), col(friction), col(corner));
        for i in 0..t.len() {
            if normal[i] > 1e-9 {
                assert!(
                    f[i].abs() <= mu * normal[i] * (1.0 + 1e-9),
                    "{name} at {}",
                    t[i]
                );
                checked += 1;
            }
        }
        if friction == "left_friction" {
            close(f[0], fx, 1e-9, "F at release");
            close(normal[0], n, 1e-9, "N at release");
        }
    }
    assert!(checked > 300, "{checked} samples with a pivot");
}

/// The hand impulse–momentum balance of a plastic strike on the right corner of the upright
/// block pivoting about its left corner at `omega` (< 0), the right corner sliding with
/// `P_t = -s mu P_n`: unknowns `(v_x, v_y, omega+, P_n)` after, from
/// `m (v+ - v-) = (P_t, P_n)`, `I_c (omega+ - omega-) = (w/2) P_n + (h/2) P_t` (the corner at
/// `(w/2, -h/2)` from the centre) and the corner's normal velocity after
/// `v_y + omega+ w/2 = 0`. Returns the velocities after, `P_n`, `P_t` and the slip after
/// `v_x + omega+ h/2`, for the sign `s` whose slip after has that sign.
fn sliding_strike(omega: f64, mu: f64) -> ([f64; 3], f64, f64, f64) {
    let ic = M * (W * W + H * H) / 12.0;
    let v0 = [-omega * H / 2.0, omega * W / 2.0];
    for s in [1.0, -1.0] {
        let a = [
            [M, 0.0, 0.0, s * mu],
            [0.0, M, 0.0, -1.0],
            [0.0, 0.0, ic, -(W / 2.0) + s * mu * H / 2.0],
            [0.0, 1.0, W / 2.0, 0.0],
        ];
        let b = [M * v0[0], M * v0[1], ic * omega, 0.0];
        let [vx, vy, om, pn] = solve_linear(a, b);
        let slip = vx + om * H / 2.0;
        if s * slip > 0.0 {
            return ([vx, vy, om], pn, -s * mu * pn, slip);
        }
    }
    panic!("no sliding solution");
}

#[test]
fn with_little_friction_the_strike_slides_as_the_hand_balance_says() {
    let mu = 0.1;
    assert!(mu < H * (1.0 - housner()) / (W * (1.0 + housner())));
    let b = bound(mu, 0.0);
    // Upright, pivoting about the left corner at omega = -1.3 rad/s, both corners on the floor.
    let omega = -1.3;
    let state = b
        .state(
            vec![0.0, H / 2.0, 0.0],
            vec![-omega * H / 2.0, omega * W / 2.0, omega],
        )
        .unwrap();
    let impact = resolve(&b, &state, &[Part::Unilateral; 2], 0.0).unwrap();
    let (v, pn, pt, slip) = sliding_strike(omega, mu);
    for (i, what) in ["v_x", "v_y", "omega"].iter().enumerate() {
        close(impact.after.qd()[i], v[i], 1e-12, what);
    }
    close(impact.impulse[1], pn, 1e-12, "P_n");
    close(impact.friction_impulse[1], pt, 1e-12, "P_t");
    close(impact.slip_after[1], slip, 1e-12, "slip after");
    let sign = if slip > 0.0 { Sign::Plus } else { Sign::Minus };
    assert_eq!(impact.friction_laws[1], FrictionLaw::Slide(sign));
    assert_eq!(impact.laws, [ContactLaw::Open, ContactLaw::Restitution]);
    // The slide takes energy: its part is -P_t (s- + s+) / 2 with s- = 0.
    close(
        impact.friction_energy_lost,
        -0.5 * pt * slip,
        1e-12,
        "friction's part",
    );
    assert!(impact.friction_energy_lost > 0.0);
    // In the motion, every strike slides.
    let motion = walker(mu, 0.0, 1.0).motion(&mut Work::default()).unwrap();
    assert!(!motion.impacts.is_empty());
    for at in &motion.impacts {
        assert!(
            matches!(at.impact.friction_laws[at.closing], FrictionLaw::Slide(_)),
            "{:?}",
            at.impact.friction_laws
        );
    }
}

#[test]
fn elastic_frictionless_strikes_keep_the_energy() {
    let w = walker(0.0, 1.0, 1.5);
    let motion = w.motion(&mut Work::default()).unwrap();
    assert!(motion.impacts.len() >= 3, "{}", motion.impacts.len());
    let b = &w.general;
    let e0 = b.energy(&b.initial_state()).unwrap();
    for k in 0..motion.impacts.len() {
        let (before, after) = around(&motion, k);
        let (e1, e2) = (b.energy(&before).unwrap(), b.energy(&after).unwrap());
        close(e1, e0, 1e-10, "energy before the strike");
        close(e2, e0, 1e-10, "energy after the strike");
        assert!(motion.impacts[k].impact.energy_lost.abs() < 1e-12);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Whatever the state, the contacts taking part, `mu` and `e`: an impact resolved never
    /// gives energy back (to rounding), the energy it reports lost is the kinetic energy's drop,
    /// and one that cannot be resolved is a typed refusal.
    #[test]
    fn no_impact_creates_energy(
        q in prop::array::uniform3(-1.0f64..1.0),
        qd in prop::array::uniform3(-3.0f64..3.0),
        parts in prop::array::uniform2(0u8..3),
        mu in 0.0f64..2.0,
        e in 0.0f64..1.0,
    ) {
        let b = bound(mu, e);
        let state = b
            .state(vec![q[0], 0.5 + 0.2 * q[1], 0.35 * q[2]], qd.to_vec())
            .unwrap();
        let part = |p: u8| match p {
            0 => Part::None,
            _ => Part::Unilateral,
        };
        let parts = [part(parts[0]), part(parts[1])];
        match resolve(&b, &state, &parts, 0.0) {
            Ok(impact) => {
                let (e0, e1) = (b.energy(&state).unwrap(), b.energy(&impact.after).unwrap());
                let kinetic = e0 - b.energy(&b.state(state.q().to_vec(), vec![0.0; 3]).unwrap()).unwrap();
                prop_assert!(e1 <= e0 + 1e-9 * kinetic.max(1e-300), "{e0} -> {e1}");
                prop_assert!(((e0 - e1) - impact.energy_lost).abs() <= 1e-10 * kinetic.max(1.0));
                let split = impact.normal_energy_lost + impact.friction_energy_lost;
                prop_assert!((split - impact.energy_lost).abs() <= 1e-12 * kinetic.max(1.0));
            }
            Err(SolveError::ImpactGainsEnergy { .. } | SolveError::Indeterminate { .. }) => {}
            Err(other) => prop_assert!(false, "{other}"),
        }
    }
}

#[test]
fn series_are_named_by_the_blocks_own_angle_phi() {
    // The block's reduced coordinate is `phi`: its series and the angle column beside each
    // force and friction carry that name, with the rate and acceleration named after it, and
    // the angle column holds the coordinate itself (the release tilt first).
    let request = Request::new(find("rocking_block").unwrap(), &parameters(0.7, 0.0)[..])
        .with_want(&[
            Quantity::ThetaSeries,
            Quantity::ForceSeries(0),
            Quantity::FrictionSeries(1),
        ])
        .with_tolerance(1e-10)
        .with_samples(50)
        .with_until(Some(0.5));
    let run = plan::run(&request).unwrap();
    let names = |key: &str| -> Vec<String> {
        (run.series[key].columns.iter())
            .map(|c| c.name.clone())
            .collect()
    };
    assert_eq!(names("theta_series"), ["t", "phi", "phi_dot", "phi_ddot"]);
    assert_eq!(names("left_corner_series"), ["t", "phi", "left_corner"]);
    assert_eq!(
        names("right_friction_series"),
        [
            "t",
            "phi",
            "right_friction",
            "right_corner",
            "slip_velocity"
        ]
    );
    let phi = &run.series["theta_series"].columns[1];
    assert_eq!((phi.unit, phi.values[0]), ("rad", PHI0));
    // No end angle: the block rocks on to the run's end, 0.5 s.
    let t = &run.series["theta_series"].columns[0].values;
    close(*t.last().unwrap(), 0.5, 1e-15, "the last sample's time");
}
