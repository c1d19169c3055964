//! Per-call cost of the generated model functions against hand-written formulas: the contact
//! force of eq. (16) (with the floor's normal force, which the generated `forces` computes in
//! the same call) and the reduced state `theta_dot^2`, `theta_ddot` of eqs. (9) and (12).
//!
//! Run: `cargo bench --bench eval -- --warm-up-time 1 --measurement-time 3`.

use criterion::{Criterion, criterion_group, criterion_main};
use rodcube::model::{Model, start_offsets};
use rodcube::system::System;
use std::hint::black_box;

/// The paper's case: m1, m2, ell, a, g.
const PAPER: [f64; 5] = [1.0, 3.0, 1.0, 0.25, 9.81];

/// Eq. (16) and the floor's normal force `N = m1 (g + y_cm'')`, written by hand from
/// PHYSICS.md at `theta = theta_i - delta`; `theta_dot^2` is eq. (9) and `theta_ddot` its
/// corrected derivative (erratum 2). Returns `[F12, N]`.
#[inline(never)]
fn hand_forces(p: &[f64; 5], theta_i: f64, delta: f64) -> [f64; 2] {
    let [m1, m2, ell, a, g] = *p;
    let n1 = 1.0 + m2 / m1;
    let r = a / ell;
    let (s, c) = (theta_i - delta).sin_cos();
    let d = 4.0 / 3.0 - s * s / n1;
    let w2 = 4.0 * (g / ell) * (r - s) / d;
    let acc = (2.0 * g / ell) * (-c / d + (r - s) * (2.0 * s * c) / (n1 * d * d));
    let q = 4.0 * n1 - 3.0 * s * s;
    let f12 = m2 * (-3.0 * g * c * (8.0 * r * n1 - 12.0 * n1 * s + 3.0 * s * s * s) / (q * q));
    let normal = m1 * (g + 0.5 * ell * (c * acc - s * w2));
    [f12, normal]
}

/// [`hand_forces`] with the runtime's convention: `sin theta`, `cos theta` and
/// `r - sin theta = sin theta_i - sin theta` from [`start_offsets`], free of cancellation near
/// the start (the plain `r - s` of [`hand_forces`] loses digits there).
#[inline(never)]
fn hand_forces_offsets(p: &[f64; 5], t: &[f64; 3], delta: f64) -> [f64; 2] {
    let [m1, m2, ell, a, g] = *p;
    let n1 = 1.0 + m2 / m1;
    let r = a / ell;
    let (s, c, ds, _) = start_offsets(t[0], t[1], t[2], delta);
    let d = 4.0 / 3.0 - s * s / n1;
    let w2 = 4.0 * (g / ell) * ds / d;
    let acc = (2.0 * g / ell) * (-c / d + ds * (2.0 * s * c) / (n1 * d * d));
    let q = 4.0 * n1 - 3.0 * s * s;
    let f12 = m2 * (-3.0 * g * c * (8.0 * r * n1 - 12.0 * n1 * s + 3.0 * s * s * s) / (q * q));
    let normal = m1 * (g + 0.5 * ell * (c * acc - s * w2));
    [f12, normal]
}

/// Eq. (16) alone.
#[inline(never)]
fn hand_contact_force(p: &[f64; 5], theta_i: f64, delta: f64) -> f64 {
    let [m1, m2, ell, a, g] = *p;
    let n1 = 1.0 + m2 / m1;
    let r = a / ell;
    let (s, c) = (theta_i - delta).sin_cos();
    let q = 4.0 * n1 - 3.0 * s * s;
    m2 * (-3.0 * g * c * (8.0 * r * n1 - 12.0 * n1 * s + 3.0 * s * s * s) / (q * q))
}

/// Eq. (9) and the corrected eq. (12).
#[inline(never)]
fn hand_reduced(p: &[f64; 5], theta_i: f64, delta: f64) -> [f64; 2] {
    let [m1, m2, ell, a, g] = *p;
    let n1 = 1.0 + m2 / m1;
    let r = a / ell;
    let (s, c) = (theta_i - delta).sin_cos();
    let d = 4.0 / 3.0 - s * s / n1;
    let w2 = 4.0 * (g / ell) * (r - s) / d;
    let acc = (2.0 * g / ell) * (-c / d + (r - s) * (2.0 * s * c) / (n1 * d * d));
    [w2, acc]
}

fn eval(c: &mut Criterion) {
    let model: &dyn Model = rodcube::models::find("rod_cube").expect("rod_cube is generated");
    let sys = System::from_values(model, &PAPER).expect("the paper's parameters are valid");
    let k = sys.k().to_vec();
    let theta_i = sys.theta_initial();
    // Half-way to separation (about 2.4 degrees fallen).
    let delta = 0.5 * (theta_i - 0.167_743_082_035);

    // The generated and the hand-written formulas agree before they are timed.
    let mut out = [0.0; 2];
    model
        .reduction()
        .expect("rod_cube has a fast path")
        .forces(&k, delta, &mut out);
    let hand = hand_forces(&PAPER, theta_i, delta);
    for (x, h) in out.iter().zip(hand) {
        assert!(
            (x - h).abs() <= 1e-12 * h.abs(),
            "generated {out:?} vs hand {hand:?}"
        );
    }
    let red = model
        .reduction()
        .expect("rod_cube has a fast path")
        .reduced(&k, delta);
    let hand = hand_reduced(&PAPER, theta_i, delta);
    assert!((red.theta_dot_sq - hand[0]).abs() <= 1e-12 * hand[0].abs());
    assert!((red.theta_ddot - hand[1]).abs() <= 1e-12 * hand[1].abs());

    let mut g = c.benchmark_group("eq16_per_call");
    g.bench_function("generated_forces_via_trait", |b| {
        let mut out = [0.0; 2];
        b.iter(|| {
            model.reduction().expect("rod_cube has a fast path").forces(
                black_box(&k),
                black_box(delta),
                &mut out,
            );
            black_box(out)
        })
    });
    g.bench_function("hand_written_forces", |b| {
        b.iter(|| hand_forces(black_box(&PAPER), black_box(theta_i), black_box(delta)))
    });
    let t = [theta_i, theta_i.sin(), theta_i.cos()];
    let hand = hand_forces_offsets(&PAPER, &t, delta);
    for (x, h) in out.iter().zip(hand) {
        assert!(
            (x - h).abs() <= 1e-12 * h.abs(),
            "generated {out:?} vs hand {hand:?}"
        );
    }
    g.bench_function("hand_written_forces_start_offsets", |b| {
        b.iter(|| hand_forces_offsets(black_box(&PAPER), black_box(&t), black_box(delta)))
    });
    g.bench_function("hand_written_eq16_only", |b| {
        b.iter(|| hand_contact_force(black_box(&PAPER), black_box(theta_i), black_box(delta)))
    });
    g.finish();

    let mut g = c.benchmark_group("reduced_per_call");
    g.bench_function("generated_reduced_via_trait", |b| {
        b.iter(|| {
            model
                .reduction()
                .expect("rod_cube has a fast path")
                .reduced(black_box(&k), black_box(delta))
        })
    });
    g.bench_function("hand_written_reduced", |b| {
        b.iter(|| hand_reduced(black_box(&PAPER), black_box(theta_i), black_box(delta)))
    });
    g.finish();
}

criterion_group!(benches, eval);
criterion_main!(benches);
