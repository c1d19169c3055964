//! The sweep's per-point solver (`rodcube::solve::fast::lean`): it agrees with the hand-typed paper
//! model (which uses the trait's default `theta_dot_sq_sc` through `reduced`), with fixed rule
//! pairs and with a much finer setting; its schedule spends fewer
//! evaluations where short panels allow; it solves a system by its release fast phase and
//! refuses what is not one phase from release to the separation; and a model that does not
//! fall, turns back, breaks or lets another contact go inside the phase gets a typed error,
//! never a number.

#[macro_use]
mod common;

use common::paper::ROD_CUBE;
use common::tweaked::{Fault, Tweaked};
use rodcube::model::{Model, ModelInfo, Partials, Reduced, Reduction, ReductionInfo, Tangents};
use rodcube::reference::{Family, Inputs, Reference, RootRoute, TimeRoute, relative_error};
use rodcube::solve::SolveError;
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::fast::prior::PRIOR_MAX_NODES;
use rodcube::solve::fast::quadrature::{RuleStep, SCHEDULE};
use rodcube::system::SystemError;
use std::sync::LazyLock;

/// The paper's case: m1, m2, ell, a, g.
const PAPER: [f64; 5] = [1.0, 3.0, 1.0, 0.25, 9.81];

/// The paper's system (its general model): the solver takes its release fast phase.
fn rod_cube() -> &'static dyn Model {
    rodcube::models::find("rod_cube").expect("rod_cube is generated")
}

/// The system's release fast phase, both contacts closed.
fn rod_cube_closed() -> &'static dyn Model {
    rodcube::models::find("rod_cube_closed").expect("rod_cube_closed is generated")
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn the_papers_point_and_the_hand_typed_model() {
    let mut generated = LeanSolver::new(rod_cube()).unwrap();
    assert_eq!(generated.model().info().name, "rod_cube_closed");
    let out = generated.solve(&PAPER).unwrap();
    // Section 3 of the paper: 9.61 degrees and 0.108 s (truncated, PHYSICS.md); to 1e-12 they
    // are the 256-bit reference's (eq. 14's root and eq. 9 integrated, `src/reference.rs`).
    assert!((out.separation_angle.to_degrees() - 9.61).abs() < 0.005);
    assert_eq!((out.separation_time * 1e3).floor(), 108.0);
    let mut reference = Reference::new(Inputs {
        family: Family::RodCube,
        m1: 1.0,
        m2: 3.0,
        ell: 1.0,
        a: 0.25,
        g: 9.81,
    })
    .unwrap();
    let sep = reference.separation(RootRoute::ClosedForm).unwrap();
    let t_ref = reference.separation_time(TimeRoute::SinhGauss).unwrap();
    assert!(relative_error(out.separation_angle, &sep.theta).abs() < 1e-12);
    assert!(relative_error(out.separation_time, &t_ref).abs() < 1e-12);
    let mut hand = LeanSolver::new(&ROD_CUBE).unwrap();
    for n in [1e-3, 0.1, 1.0, 3.0, 10.0, 1e3] {
        for r in [0.01, 0.25, 0.5, 0.9, 0.99] {
            let p = [1.0, n, 1.0, r, 9.81];
            let (a, b) = (generated.solve(&p).unwrap(), hand.solve(&p).unwrap());
            assert!(
                rel(a.separation_angle, b.separation_angle) < 1e-15,
                "n = {n}, r = {r}: {a:?} vs {b:?}"
            );
            assert!(
                rel(a.separation_time, b.separation_time) < 1e-14,
                "n = {n}, r = {r}: {a:?} vs {b:?}"
            );
        }
    }
}

#[test]
fn the_schedule_agrees_with_fixed_pairs_and_is_cheaper_over_the_sweep_range() {
    let m = rod_cube();
    let mut schedule = LeanSolver::new(m).unwrap();
    let mut fixed = LeanSolver::with_rules(m, 8, 12, 1e-12).unwrap();
    let mut fine = LeanSolver::with_rules(m, 24, 32, 1e-15).unwrap();
    for i in 0..40 {
        for j in 0..40 {
            let n = 10f64.powf(-3.0 + 6.0 * i as f64 / 39.0);
            let r = 0.01 + 0.98 * j as f64 / 39.0;
            let p = [1.0, n, 1.0, r, 1.0];
            let reference = fine.solve(&p).unwrap().separation_time;
            for (who, solver) in [("schedule", &mut schedule), ("8 vs 12", &mut fixed)] {
                let t = solver.solve(&p).unwrap().separation_time;
                assert!(
                    rel(t, reference) < 2e-15,
                    "{who} at n = {n}, r = {r}: {t} vs {reference}"
                );
            }
        }
    }
    // Short panels get cheaper rules, long ones are cut before they fail: fewer evaluations
    // over the grid than one fixed pair.
    assert!(
        schedule.evals < fixed.evals,
        "{} vs {}",
        schedule.evals,
        fixed.evals
    );
}

#[test]
fn long_intervals_near_upright_are_cut_and_still_accurate() {
    let m = rod_cube();
    let mut fine = LeanSolver::with_rules(m, 24, 32, 1e-15).unwrap();
    let mut evals = Vec::new();
    for r in [0.999, 1.0 - 1e-6, 1.0 - 1e-9] {
        let p = [1.0, 3.0, 1.0, r, 1.0];
        let mut schedule = LeanSolver::new(m).unwrap();
        let t = schedule.solve(&p).unwrap().separation_time;
        let reference = fine.solve(&p).unwrap().separation_time;
        assert!(rel(t, reference) < 1e-14, "r = {r}: {t} vs {reference}");
        evals.push(schedule.evals);
    }
    // The phase grows like log(1 / cos(theta_i)) in v: nearer upright it takes more nodes, and
    // at 1 - 1e-9 more than one symmetric panel of the most nodes the a-priori rule takes.
    assert!(evals.windows(2).all(|w| w[0] < w[1]), "{evals:?}");
    assert!(evals[2] > (PRIOR_MAX_NODES / 2) as u64, "{evals:?}");
}

#[test]
fn a_custom_schedule_is_sorted_and_an_empty_one_is_the_default() {
    let m = rod_cube();
    let steps = [
        RuleStep {
            max_len: 1.0,
            low: 8,
            high: 12,
        },
        RuleStep {
            max_len: 0.3,
            low: 5,
            high: 8,
        },
    ];
    let mut custom = LeanSolver::with_schedule(m, &steps, 1e-12).unwrap();
    let mut empty = LeanSolver::with_schedule(m, &[], 1e-12).unwrap();
    let mut schedule = LeanSolver::with_schedule(m, &SCHEDULE, 1e-12).unwrap();
    let t = schedule.solve(&PAPER).unwrap().separation_time;
    assert!(rel(custom.solve(&PAPER).unwrap().separation_time, t) < 1e-15);
    assert_eq!(empty.solve(&PAPER).unwrap().separation_time, t);
    assert_eq!(empty.evals, schedule.evals);
    // The default solver's a-priori rule agrees with the verified schedule.
    let default = LeanSolver::new(m).unwrap().solve(&PAPER).unwrap();
    assert!(rel(default.separation_time, t) < 1e-15);
}

fn solve_broken(fault: Fault) -> SolveError {
    let model = Tweaked::with_fault(rod_cube_closed(), fault);
    let mut solver = LeanSolver::new(&model).unwrap();
    match solver.solve(&PAPER) {
        Ok(out) => panic!("{fault:?} solved: {out:?}"),
        Err(e) => e,
    }
}

#[test]
fn broken_models_get_typed_errors() {
    // The paper's phase runs from sin(theta) = 0.25 down to 0.167.
    match solve_broken(Fault::Rises) {
        SolveError::NoMotion { theta_ddot, .. } => assert!(theta_ddot > 0.0),
        e => panic!("{e}"),
    }
    match solve_broken(Fault::TurnsBack { below: 0.2 }) {
        SolveError::TurningPoint {
            delta, delta_end, ..
        } => assert!(delta > 0.0 && delta < delta_end, "{delta} {delta_end}"),
        e => panic!("{e}"),
    }
    match solve_broken(Fault::Nan { below: 0.2 }) {
        SolveError::NonFinite { what, .. } => assert_eq!(what, "theta_dot^2"),
        e => panic!("{e}"),
    }
    match solve_broken(Fault::Nan { below: 1.0 }) {
        SolveError::NonFinite { what, delta, .. } => {
            assert_eq!(what, "theta_dot^2");
            assert!(delta > 0.0 && delta < 0.01, "{delta}");
        }
        e => panic!("{e}"),
    }
    // A control: the same wrapper without a fault in reach solves.
    let model = Tweaked::with_fault(rod_cube_closed(), Fault::TurnsBack { below: 0.1 });
    assert!(LeanSolver::new(&model).unwrap().solve(&PAPER).is_ok());
}

#[test]
fn bad_parameters_are_refused_by_name_not_as_a_next_phase() {
    let mut solver = LeanSolver::new(rod_cube()).unwrap();
    for (p, needle) in [
        (vec![1.0, 3.0, 1.0, 0.0, 9.81], "`a`"),
        (vec![1.0, 3.0, 1.0, 1.5, 9.81], "a < ell"),
        (vec![1.0, f64::NAN, 1.0, 0.25, 9.81], "`m2`"),
        (vec![1.0, 3.0, 1.0, 0.25], "5"),
    ] {
        match solver.solve(&p) {
            Err(e @ SolveError::Parameters(_)) => {
                let text = e.to_string();
                assert!(text.contains(needle), "{p:?}: {text}");
                assert!(!text.contains("next phase"), "{text}");
            }
            other => panic!("{p:?}: {other:?}"),
        }
    }
    // The solver is still usable afterwards.
    assert!(solver.solve(&PAPER).is_ok());
}

#[test]
fn a_polynomial_without_a_sign_change_is_named() {
    // Masses of 1e-300 kg: the polynomial's coefficients (products of masses) underflow, and so
    // does the push at release. The true separation is at sin(theta) = 2r/3 after
    // (2/3) sqrt(a/g) = 2.1e-151 s (PHYSICS.md's flat-rod limit), which the solver cannot form:
    // a typed error (the push at release is 0/0), not a separation at release.
    let mut solver = LeanSolver::new(rod_cube()).unwrap();
    match solver.solve(&[1e-300, 1e-300, 1.0, 1e-300, 9.81]) {
        Err(SolveError::NoSeparation { lo, hi, .. }) => assert!(lo < hi),
        Err(SolveError::NonFinite { value, delta, .. }) => assert!(value.is_nan() && delta == 0.0),
        other => panic!("{other:?}"),
    }
    // A tweaked polynomial that never vanishes (the contact holds to the floor).
    match LeanSolver::new(&common::tweaked::NEVER_SEPARATES)
        .unwrap()
        .solve(&PAPER)
    {
        Err(e @ SolveError::NoSeparation { .. }) => {
            assert!(e.to_string().contains("holds to the floor"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_default_theta_dot_sq_sc_keeps_its_digits_near_the_start() {
    // The hand-typed models recover delta by atan2 from the drops;
    // it must agree with `reduced` to the last digits even a hair below the start, where a
    // plain `theta_i - atan2(s, c)` would have lost them.
    let models: [(&dyn Model, Vec<f64>); 2] = [
        (&ROD_CUBE, PAPER.to_vec()),
        (
            &common::paper::FREE_ROD,
            vec![1.0, 3.0, 1.0, 0.25, 9.81, 0.2, 0.1677, 1.0, 0.3, -1.5, 0.1],
        ),
    ];
    for (model, p) in models {
        let info = model.info();
        let mut k = vec![0.0; info.n_constants];
        model.prepare(&p, &mut k);
        let (ti, si, ci) = (
            k[info.reduction.unwrap().k_theta_initial],
            k[info.reduction.unwrap().k_sin_initial],
            k[info.reduction.unwrap().k_cos_initial],
        );
        for delta in [1e-14, 1e-9, 1e-4, 0.05, 0.9 * ti] {
            let (s, c, ds, dc) = rodcube::model::start_offsets(ti, si, ci, delta);
            let default = model.reduction().unwrap().theta_dot_sq_sc(&k, s, c, ds, dc);
            let direct = model.reduction().unwrap().reduced(&k, delta).theta_dot_sq;
            assert!(
                rel(default, direct) < 1e-14,
                "{} at delta = {delta}: {default} vs {direct}",
                info.name
            );
        }
    }
}

#[test]
fn the_angle_fallen_agrees_with_the_difference_of_the_angles() {
    // `delta()` is formed from the sines without the subtraction; where delta is a good part
    // of theta_i the subtraction `theta_i - theta_sep` loses little and the two must agree to
    // its rounding (a few ulps of theta_i, relative to delta).
    let mut solver = LeanSolver::new(rod_cube()).unwrap();
    for n in [1e-3, 0.3, 3.0, 1e3] {
        for r in [0.01, 0.2, 0.5, 0.8, 0.99] {
            let out = solver.solve(&[1.0, n, 1.0, r, 9.81]).unwrap();
            let theta_i = r.asin();
            let difference = theta_i - out.separation_angle;
            let allowed = 4.0 * f64::EPSILON * theta_i / difference;
            assert!(
                rel(out.delta(), difference) <= allowed,
                "n = {n}, r = {r}: {} vs {difference}",
                out.delta()
            );
        }
    }
}

#[test]
fn a_constant_that_overflows_gets_the_full_preparations_error() {
    // Lengths of 1e300 m under a gravity of 1e-10 m/s^2: a time scale ell/g overflows. The
    // lean preparation forms only some constants and checks none of them; the overflow must
    // still come back as the full preparation's typed error, never as a number.
    let mut overflowed = 0;
    for &model in rodcube::models::all() {
        let Ok(mut solver) = LeanSolver::new(model) else {
            continue;
        };
        let info = model.info();
        let p: Vec<f64> = (info.parameters.iter())
            .map(|q| match q.name {
                "ell" => 1e300,
                "a" => 0.25e300,
                "g" => 1e-10,
                _ => 1.0,
            })
            .collect();
        // The model the solver solves: a system's release fast phase.
        let full = rodcube::system::Bound::from_values(solver.model(), &p).map(|_| ());
        match (full, solver.solve(&p)) {
            (Err(want @ SystemError::BadConstant { .. }), Err(SolveError::Parameters(got))) => {
                assert_eq!(got, want, "{}", info.name);
                overflowed += 1;
            }
            (Err(want), got) => panic!("{}: {want} but the lean solver gave {got:?}", info.name),
            (Ok(()), _) => {}
        }
    }
    assert!(overflowed >= 2, "only {overflowed} models overflowed");
}

#[test]
fn a_first_contact_that_would_pull_at_release_gets_no_lean_start() {
    // The hand model has no proof that its first contact pushes at release, so
    // `Model::lean_start` evaluates the separation polynomial there: one that is -1 (the
    // contact would pull) gives no start, and the checked route decides and names what is
    // wrong (this polynomial has no root: no separation).
    assert!(!ROD_CUBE.info().reduction.unwrap().release_push_proven);
    assert!(ROD_CUBE.lean_start(&PAPER).is_some());
    let pulls = Tweaked {
        base: &ROD_CUBE,
        reduction: &ROD_CUBE,
        polynomial: Some(&[-1.0, 0.0, 0.0, 0.0]),
        monitor_shift: 0.0,
        nan_force: false,
        theta_dot_sq: Fault::None,
    };
    assert!(pulls.lean_start(&PAPER).is_none());
    match LeanSolver::new(&pulls).unwrap().solve(&PAPER) {
        Err(SolveError::NoSeparation { coefficients, .. }) => {
            assert_eq!(coefficients, [-1.0, 0.0, 0.0, 0.0]);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_cube_too_heavy_for_the_full_model_is_solved_at_the_fixed_cubes_separation() {
    // m2 = 1e300 kg: the full preparation's constants overflow (the floor's push has m2^2,
    // and the acceleration g m2), so the full model is refused; the separation reads none of
    // them (the derivation proved the floor's push positive, so the per-point route does
    // not form it) and is solved. It is the limit of a cube that does not move: the tip
    // leaves the cube where 3 m1 s^3 - 12 M s + 8 M s_i = 0 with M -> infinity, at
    // sin(theta) = 2 a / (3 ell), and the time converges to that of heavy cubes that the
    // full model accepts.
    let model = rodcube::models::find("rod_cube").expect("rod_cube");
    let mut solver = LeanSolver::new(model).expect("a per-point solver");
    let (ell, a) = (1.0, 0.25);
    let heavy = [1.0, 1e300, ell, a, 9.81];
    let full = rodcube::system::Bound::from_values(solver.model(), &heavy).map(|_| ());
    assert!(
        matches!(full, Err(SystemError::BadConstant { .. })),
        "{full:?}"
    );
    let point = solver
        .solve(&heavy)
        .expect("the separation of a fixed cube");
    let fixed = (2.0 * a / (3.0 * ell)).asin();
    assert!(
        (point.separation_angle - fixed).abs() <= 2.0 * f64::EPSILON * fixed,
        "{} vs {fixed}",
        point.separation_angle
    );
    let accepted = solver
        .solve(&[1.0, 1e150, ell, a, 9.81])
        .expect("a cube of 1e150 kg");
    assert!(
        rodcube::system::Bound::from_values(solver.model(), &[1.0, 1e150, ell, a, 9.81]).is_ok()
    );
    let e = (point.separation_time - accepted.separation_time).abs() / accepted.separation_time;
    assert!(e < 1e-14, "{point:?} vs {accepted:?}");
}

#[test]
fn the_lean_start_is_the_prepared_start_or_nothing() {
    // Model::lean_start forms the unchecked route's inputs in one call. Where it gives some,
    // the full check must accept the point and every number must be the one the prepared
    // constants and the model's polynomials give; a point the quick test cannot pass gets none.
    let mut served = 0;
    for &model in rodcube::models::all() {
        let info = model.info();
        let (Some(layout), Some(red)) = (info.reduction.as_ref(), model.reduction()) else {
            continue;
        };
        for (ell, a) in [(1.0, 0.25), (2.0, 1.9), (1.0, 1e-9), (1.0, 1.0), (1.0, 1.5)] {
            let p: Vec<f64> = (info.parameters.iter())
                .map(|q| match q.name {
                    "ell" => ell,
                    "a" => a,
                    "g" => 9.81,
                    _ => 1.0,
                })
                .collect();
            let mut margins = vec![0.0; info.requirements.len()];
            let accepted = rodcube::system::check_parameters(model, &p, &mut margins).is_ok();
            let Some(start) = model.lean_start(&p) else {
                continue;
            };
            assert!(accepted, "{}: a start for refused {p:?}", info.name);
            let mut k = vec![0.0; info.n_constants];
            model.prepare(&p, &mut k);
            let mut sep = vec![0.0; layout.separation_degree() + 1];
            red.force_polynomial(&k, 0, &mut sep);
            let mut fall = vec![0.0; layout.fall_degree.unwrap() + 1];
            red.fall_polynomial(&k, &mut fall);
            assert_eq!(start.sin_initial, k[layout.k_sin_initial], "{}", info.name);
            assert_eq!(start.cos_initial, k[layout.k_cos_initial], "{}", info.name);
            let rate = k[layout.k_theta_dot_initial];
            assert_eq!(start.theta_dot_initial, rate, "{}", info.name);
            assert_eq!(start.separation[..sep.len()], sep[..], "{}", info.name);
            assert!(start.separation[sep.len()..].iter().all(|&c| c == 0.0));
            assert_eq!(start.fall[..fall.len()], fall[..], "{}", info.name);
            assert!(start.fall[fall.len()..].iter().all(|&c| c == 0.0));
            // Every other closed unilateral contact's force polynomial, in order, but those
            // whose push the derivation proved positive over the phase.
            let others: Vec<usize> = (1..info.contacts.len())
                .filter(|&i| !info.contacts[i].bilateral && !layout.pushes_proven[i])
                .collect();
            assert_eq!(start.n_others, others.len(), "{}", info.name);
            for (row, &i) in start.others.iter().zip(&others) {
                let mut poly = vec![0.0; layout.force_degrees[i] + 1];
                red.force_polynomial(&k, i, &mut poly);
                assert_eq!(row[..poly.len()], poly[..], "{} contact {i}", info.name);
                assert!(row[poly.len()..].iter().all(|&c| c == 0.0));
            }
            // prepare_lean writes every constant the start's polynomials read: from a scratch
            // of NaNs they are the same.
            let mut lean = vec![f64::NAN; info.n_constants];
            red.prepare_lean(&p, &mut lean);
            let mut again = vec![0.0; sep.len()];
            red.force_polynomial(&lean, 0, &mut again);
            assert_eq!(again, sep, "{}", info.name);
            let mut again = vec![0.0; fall.len()];
            red.fall_polynomial(&lean, &mut again);
            assert_eq!(again, fall, "{}", info.name);
            for &i in &others {
                let (mut from_lean, mut from_full) = (
                    vec![0.0; layout.force_degrees[i] + 1],
                    vec![0.0; layout.force_degrees[i] + 1],
                );
                red.force_polynomial(&lean, i, &mut from_lean);
                red.force_polynomial(&k, i, &mut from_full);
                assert_eq!(from_lean, from_full, "{} contact {i}", info.name);
            }
            for i in [
                layout.k_sin_initial,
                layout.k_cos_initial,
                layout.k_theta_dot_initial,
            ] {
                assert_eq!(lean[i], k[i], "{} constant {i}", info.name);
            }
            served += 1;
            // What the quick test cannot pass: a value not positive and finite, a wrong count.
            for bad in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
                let mut q = p.clone();
                q[0] = bad;
                assert_eq!(model.lean_start(&q), None, "{}: {q:?}", info.name);
            }
            assert_eq!(model.lean_start(&p[1..]), None, "{}", info.name);
        }
        // A requirement that fails (the rod shorter than the cube is tall, where the model has
        // that requirement) gives none.
        if info.parameters.iter().any(|q| q.name == "a") {
            let p: Vec<f64> = (info.parameters.iter())
                .map(|q| if q.name == "a" { 2.0 } else { 1.0 })
                .collect();
            let mut margins = vec![0.0; info.requirements.len()];
            if rodcube::system::check_parameters(model, &p, &mut margins).is_err() {
                assert_eq!(model.lean_start(&p), None, "{}", info.name);
            }
        }
    }
    // rod_cube_closed, hinged_rod_closed, loaded_rod_closed and wall_ladder_closed at least, at
    // two points each.
    assert!(served >= 8, "only {served} starts were formed");
}

#[test]
fn a_system_is_solved_by_its_release_phase_and_other_phases_are_refused() {
    // The system and its release phase give the same numbers to the bit.
    let mut system = LeanSolver::new(rod_cube()).unwrap();
    let mut phase = LeanSolver::new(rod_cube_closed()).unwrap();
    assert_eq!(phase.model().info().name, "rod_cube_closed");
    for p in [
        PAPER,
        [1.0, 1e-3, 1.0, 0.9, 9.81],
        [1.0, 1e3, 2.0, 0.1, 1.0],
    ] {
        assert_eq!(system.solve(&p).unwrap(), phase.solve(&p).unwrap(), "{p:?}");
    }
    // A phase that leaves the tip open has no separation of its own to find.
    let free = rodcube::models::find("rod_cube_free").expect("rod_cube_free is generated");
    match LeanSolver::new(free) {
        Err(SolveError::NotPerPoint { model, why }) => {
            assert_eq!(model, "rod_cube_free");
            assert!(why.contains("contact"), "{why}");
        }
        other => panic!("{other:?}"),
    }
    // A system without a fast phase from release (the ladder with friction, integrated).
    let ladder = rodcube::models::find("ladder_friction").expect("generated model");
    match LeanSolver::new(ladder) {
        Err(SolveError::NotPerPoint { model, why }) => {
            assert_eq!(model, "ladder_friction");
            assert!(why.contains("release"), "{why}");
        }
        other => panic!("{other:?}"),
    }
}

/// `rod_cube_closed` (hand-typed) whose floor normal force is replaced by `m1 g P(sin theta)`
/// with the linear polynomial `P`: a floor that lets the foot go where `P` vanishes.
struct FloorLetsGo {
    /// `P`'s coefficients, lowest degree first.
    floor: [f64; 3],
    info: &'static ModelInfo,
}

/// `rod_cube_closed`'s description with the floor's force polynomial of degree 2.
static FLOOR_INFO: LazyLock<ModelInfo> = LazyLock::new(|| {
    let base = ROD_CUBE.info();
    ModelInfo {
        reduction: base.reduction.map(|r| ReductionInfo {
            force_degrees: &[3, 2],
            pushes_proven: &[false, false],
            release_push_proven: false,
            ..r
        }),
        ..*base
    }
});

impl FloorLetsGo {
    fn new(floor: [f64; 3]) -> FloorLetsGo {
        FloorLetsGo {
            floor,
            info: &FLOOR_INFO,
        }
    }

    fn floor_force(&self, k: &[f64], s: f64) -> f64 {
        let [c0, c1, c2] = self.floor;
        k[0] * k[4] * (c0 + s * (c1 + s * c2))
    }
}

impl Model for FloorLetsGo {
    forward_model!(|_: &Self| &ROD_CUBE; requirements, restitutions, prepare, initial_state, points, energy, momenta, equations, gaps, constraints, edges, friction, monitors_full, to_full, drawing);

    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        ROD_CUBE.forces_full(k, q, qd, qdd, out);
        out[1] = self.floor_force(k, q[1].sin());
    }
    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        Some(self)
    }
}

impl Reduction for FloorLetsGo {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        ROD_CUBE.reduced(k, delta)
    }
    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        ROD_CUBE.theta_dot_sq_sc(k, s, c, ds, dc)
    }
    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        ROD_CUBE.forces(k, delta, out);
        out[1] = self.floor_force(k, ROD_CUBE.reduced(k, delta).sin);
    }
    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]) {
        match contact {
            1 => out.copy_from_slice(&self.floor),
            _ => ROD_CUBE.force_polynomial(k, contact, out),
        }
    }
    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]) {
        ROD_CUBE.fall_polynomial(k, out)
    }
    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        ROD_CUBE.prepare_lean(p, k)
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
        ROD_CUBE.full_state(k, t, delta, theta_dot, q, qd)
    }
}

#[test]
fn another_contact_that_lets_go_first_is_not_this_phase() {
    // The paper's phase runs from sin(theta) = 0.25 down to the separation at 0.167 (eq. 14's
    // root, 0.1669575...: PHYSICS.md's 9.61 deg).
    let mut solver = LeanSolver::new(&ROD_CUBE).unwrap();
    let paper = solver.solve(&PAPER).unwrap();
    assert!((paper.separation_angle.sin() - 0.167).abs() < 1e-3);
    // A floor that lets go at sin(theta) = 0.1, after the separation: the same answer.
    let after = FloorLetsGo::new([-0.1, 1.0, 0.0]);
    let out = LeanSolver::new(&after).unwrap().solve(&PAPER).unwrap();
    assert_eq!(out, paper);
    // A floor whose push comes within 1e-15 of zero at sin(theta) = 0.2 and pushes again:
    // too close for `positive_on`'s bounds, so the route asks the root finder, which finds
    // no sign change (the same answer).
    let grazes = FloorLetsGo::new([0.04 + 1e-15, -0.4, 1.0]);
    let out = LeanSolver::new(&grazes).unwrap().solve(&PAPER).unwrap();
    assert_eq!(out, paper);
    assert!(!rodcube::solve::fast::poly::positive_on(
        &[0.04 + 1e-15, -0.4, 1.0],
        0.167,
        0.25
    ));
    // At sin(theta) = 0.2, before it: the phase the solver solves ends with the foot lifting.
    let before = FloorLetsGo::new([-0.2, 1.0, 0.0]);
    match LeanSolver::new(&before).unwrap().solve(&PAPER) {
        Err(SolveError::NotThisPhase {
            model,
            contact,
            why,
        }) => {
            assert_eq!((model, contact), ("rod_cube_closed", "floor_normal"));
            assert!(why.contains("before the separation"), "{why}");
        }
        other => panic!("{other:?}"),
    }
    // A floor that would have to pull from the start (P < 0 on the whole phase).
    let pulls = FloorLetsGo::new([-1.0, 1.0, 0.0]);
    match LeanSolver::new(&pulls).unwrap().solve(&PAPER) {
        Err(SolveError::NotThisPhase {
            model,
            contact,
            why,
        }) => {
            assert_eq!((model, contact), ("rod_cube_closed", "floor_normal"));
            assert!(why.contains("pull"), "{why}");
        }
        other => panic!("{other:?}"),
    }
}
