//! Property tests (proptest) over random valid parameters for every shipped system and fast
//! phase: results are finite and physical; where a system separates on its release fast phase,
//! the planner, the sweep's lean solver and (for the systems with a closed form) the
//! high-precision reference agree; where it does not, each contact ends at a finite time (or
//! holds to the end) with the energy conserved along every phase to the tolerance asked; every
//! fast phase that starts from a given state reaches the floor with its energy and momenta
//! agreeing with the reduced path.

use proptest::prelude::*;
use rodcube::model::Model;
use rodcube::plan::{self, DEFAULT_TOLERANCE, PlanError, Request};
use rodcube::quantity::Quantity;
use rodcube::reference::{Inputs, Reference, RootRoute, TimeRoute, relative_error};
use rodcube::results::EndCause;
use rodcube::results::{CheckKind, Work};
use rodcube::solve::SolveError;
use rodcube::solve::checks::{self, Conserved};
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::fast::quadrature::TimeMesh;
use rodcube::solve::integrated::contacts::DECIDE_TOLERANCE;
use rodcube::solve::phases::{PhaseRun, ReducedEnd, ReducedRun};
use rodcube::system::{Bound, System};

/// Parameter values for `model` from uniforms `u` (one per parameter) and `spread`, which
/// picks `a/ell` near 0, near 1 (on a log scale) or in the middle. The mass ratio spans
/// `1e-12..1e12` on the fast path and `1e-6..1e6` on the integrated route, whose tolerance is
/// floored at `10 eps cond(M)` (a ratio of `1e12` leaves it no digits).
fn parameters(model: &dyn Model, u: &[f64], spread: u8) -> Vec<f64> {
    let info = model.info();
    let lin = |x: f64, lo: f64, hi: f64| lo + x * (hi - lo);
    let log = |x: f64, lo: f64, hi: f64| 10f64.powf(lin(x, lo, hi));
    let mut p = vec![0.0; info.parameters.len()];
    let idx = |name: &str| info.parameters.iter().position(|q| q.name == name);
    for (i, q) in info.parameters.iter().enumerate() {
        p[i] = match q.name {
            "m1" => log(u[i], -3.0, 3.0),
            "ell" => log(u[i], -2.0, 2.0),
            "g" => log(u[i], -1.0, 2.0),
            "theta_0" => lin(u[i], 0.01, 1.56),
            "theta_dot_0" => -lin(u[i], 0.0, 3.0),
            // The rocking block's tilt, below its slenderness angle atan(w/h) (set below).
            "phi0" => u[i],
            // Friction from none to below Painlevé's 4/3 for a free rod sliding on its foot
            // (above it the sliding equations can turn singular: tests/friction.rs).
            "mu" | "mu_f" | "mu_w" => lin(u[i], 0.0, 1.3),
            // A coefficient of restitution, over its whole range [0, 1].
            "e" => u[i],
            _ if q.positive => log(u[i], -1.0, 1.0),
            _ => lin(u[i], -1.0, 1.0),
        };
    }
    // A block that can tip (width `w`, height `h`) adds its own inertia m2 (w^2 + h^2) / 12 to
    // the mass matrix, whose condition (in SI units) then grows like the mass ratio times
    // (1 m / w)^2: three decades of mass ratio on it keep the integrated route's digits.
    let block = idx("w").is_some() && idx("h").is_some();
    let decades = match (info.reduction.is_some(), block) {
        (true, _) => 12.0,
        (false, false) => 6.0,
        (false, true) => 3.0,
    };
    if let (Some(m1), Some(m2)) = (idx("m1"), idx("m2")) {
        p[m2] = p[m1] * log(u[m2], -decades, decades);
    }
    if let (Some(ell), Some(a)) = (idx("ell"), idx("a")) {
        let r = match spread % 3 {
            0 => log(u[a], -10.0, 0.0) * 0.999_999_999,
            1 => 1.0 - log(u[a], -9.0, -1.0),
            _ => lin(u[a], 0.01, 0.99),
        };
        p[a] = p[ell] * r;
    }
    // A ladder with friction at both ends slides only below its static limit, `tan(theta0) <
    // (1 - mu_f mu_w) / (2 mu_f)` (by hand: tests/common/hand.rs, `Ladder::slides`); above it
    // static friction holds it at rest, which is no motion to solve. The release angle is
    // spread over the sliding range as `asin(a/ell)` is over the quarter turn.
    if let (Some(ell), Some(a), Some(f), Some(w)) = (idx("ell"), idx("a"), idx("mu_f"), idx("mu_w"))
    {
        p[w] = p[w].min(0.9 / p[f]);
        let limit = ((1.0 - p[f] * p[w]) / (2.0 * p[f])).atan();
        let theta0 = (p[a] / p[ell]).asin() * limit / std::f64::consts::FRAC_PI_2;
        p[a] = p[ell] * theta0.sin();
    }
    // The block's height and width stay within two decades of the rod's length (see above).
    if let (Some(ell), Some(h), Some(w)) = (idx("ell"), idx("h"), idx("w")) {
        p[h] = p[ell] * lin(u[h], 0.01, 0.99);
        p[w] = p[ell] * log(u[w], -1.0, 0.0);
    }
    // A spring whose period is not far below the fall's time scale sqrt(ell/g): a stiffer one
    // makes the equations stiff, which the explicit integrator follows only with a drift that
    // the energy check then reports (rightly) as failed.
    if let (Some(k), Some(m2), Some(ell), Some(g)) = (idx("k"), idx("m2"), idx("ell"), idx("g")) {
        p[k] = p[m2] * p[g] / p[ell] * log(u[k], -2.0, 2.0);
        // A hinged rod can rest on a spring stiff enough to hold it (a stable equilibrium it
        // would rock about for ever: no event ends that motion). By hand it keeps falling while
        // it touches the cube if its potential drop m1 g (ell/2)(sin th0 - sin) outgrows the
        // spring's energy k ell^2 (cos - cos th0)^2 / 2 everywhere, which holds when
        // k < m1 g cos(th0) / (2 ell sin(th0/2)) (bound sin th0 - sin and cos - cos th0 by
        // 2 cos th0 u and 2 u, u = sin((th0 - theta)/2) <= sin(th0/2)).
        let hinged = info.contacts.iter().any(|c| c.bilateral);
        if let (true, Some(m1), Some(a)) = (hinged, idx("m1"), idx("a")) {
            let th0 = (p[a] / p[ell]).asin();
            let most = p[m1] * p[g] * th0.cos() / (2.0 * p[ell] * (0.5 * th0).sin());
            p[k] = most * lin(u[k], 0.01, 0.99);
        }
    }
    // A free phase starts at the motion's own speed scale sqrt(g ell) (a foot thrown far
    // faster can, with friction, tip the rod over backwards past upright, where no event
    // waits)
    if let (Some(ell), Some(g)) = (idx("ell"), idx("g")) {
        for v in ["x1_dot_0", "x2_dot_0"].into_iter().filter_map(idx) {
            p[v] = lin(u[v], -0.5, 0.5) * (p[g] * p[ell]).sqrt();
        }
        // and at the rod's own size: a cube a hundred rod lengths away on a stiff spring
        // stores a hundred thousand times the rod's energy.
        for x in ["x1_0", "x2_0"].into_iter().filter_map(idx) {
            p[x] = lin(u[x], -1.0, 1.0) * p[ell];
        }
    }
    // A rocking block tilted by a fraction of its slenderness angle atan(w/h).
    if let (Some(w), Some(h), Some(phi0)) = (idx("w"), idx("h"), idx("phi0")) {
        p[phi0] = (p[w] / p[h]).atan() * lin(u[phi0], 0.05, 0.95);
    }
    // A rod on a cylinder: the tangent point R cot(th0/2) must lie on the rod, th0 < pi/2.
    if let (Some(ell), Some(r), Some(th0)) = (idx("ell"), idx("R"), idx("th0")) {
        p[r] = p[ell] * lin(u[r], 0.01, 0.9);
        let lowest = 2.0 * (p[r] / p[ell]).atan();
        p[th0] = lin(u[th0], lowest, std::f64::consts::FRAC_PI_2);
        p[th0] = p[th0].clamp(lowest * 1.01, 1.55);
    }
    p
}

fn named(model: &dyn Model, p: &[f64]) -> Vec<(&'static str, f64)> {
    model
        .info()
        .parameters
        .iter()
        .map(|q| q.name)
        .zip(p.iter().copied())
        .collect()
}

fn check_system(model: &'static dyn Model, u: &[f64], spread: u8) -> Result<(), TestCaseError> {
    let info = model.info();
    prop_assert!(info.is_general());
    let p = parameters(model, u, spread);
    // The systems whose release fast phase the per-point solver takes: a polynomial separation,
    // no edge, every contact closed.
    let Ok(mut lean) = LeanSolver::new(model) else {
        return check_contact_end(model, &p);
    };
    // At the planner's default tolerance, which it must meet everywhere (its panels are
    // accepted by the agreement of two rules, which a near-singularity at a panel's end does
    // not fool).
    let request = Request::new(model, p.clone())
        .with_want(&[Quantity::SeparationAngle, Quantity::SeparationTime]);
    let res = plan::run(&request).map_err(|e| TestCaseError::fail(format!("{p:?}: {e}")))?;
    let theta = res.results["separation_angle"].value;
    let t = res.results["separation_time"].value;
    let sin_i = res.parameters["a"] / res.parameters["ell"];
    prop_assert!(theta.is_finite() && t.is_finite());
    prop_assert!(
        theta > 0.0 && theta.sin() < sin_i,
        "{theta} vs sin theta_i {sin_i}"
    );
    prop_assert!(t > 0.0);
    let fast = lean
        .solve(&p)
        .map_err(|e| TestCaseError::fail(format!("{}: {p:?}: {e}", info.name)))?;
    prop_assert!(((fast.separation_angle - theta) / theta).abs() < 1e-12);
    prop_assert!(
        ((fast.separation_time - t) / t).abs() < DEFAULT_TOLERANCE,
        "{} vs {t}",
        fast.separation_time
    );
    if let Ok(inputs) = Inputs::from_named(info.name, &named(model, &p)) {
        // Near upright t_sep is ill-conditioned in a/ell (a relative change of 1 - a/ell
        // moves it by about that much over ln(1/cos theta_0)), so the reference gets the
        // ratio the model sees, a/ell rounded once, with the time scale sqrt(ell/g).
        let inputs = Inputs {
            a: inputs.a / inputs.ell,
            g: inputs.g / inputs.ell,
            ell: 1.0,
            ..inputs
        };
        let mut reference = Reference::new(inputs).unwrap();
        let sep = reference.separation(RootRoute::ClosedForm).unwrap();
        let t_ref = reference.separation_time(TimeRoute::SinhGauss).unwrap();
        let ea = relative_error(theta, &sep.theta).abs();
        prop_assert!(ea < 1e-12, "angle error {ea:e} at {p:?}");
        // The hinged rod's generated functions lose digits as theta_sep << theta_i.
        let bound = 1e-12f64.max(16.0 * f64::EPSILON * sin_i / theta.sin());
        for (who, value, bound) in [
            ("planner", t, bound.max(DEFAULT_TOLERANCE)),
            ("lean", fast.separation_time, bound),
        ] {
            let et = relative_error(value, &t_ref).abs();
            prop_assert!(et < bound, "{who} time error {et:e} > {bound:e} at {p:?}");
        }
    }
    Ok(())
}

/// A fast phase that starts from a state given as parameters (the rod after a contact ends):
/// from random start states it reaches the floor in a finite positive time, and the generated
/// energy and momenta agree with its reduced path (as the planner checks a fast phase).
fn check_fast_phase(model: &'static dyn Model, u: &[f64], spread: u8) -> Result<(), TestCaseError> {
    let info = model.info();
    let tol = 1e-8;
    let p = parameters(model, u, spread);
    let fail =
        |e: &dyn std::fmt::Display| TestCaseError::fail(format!("{}: {p:?}: {e}", info.name));
    let sys = System::from_values(model, &p).map_err(|e| fail(&e))?;
    let mut work = Work::default();
    let delta = sys.delta_to_floor();
    let mesh = TimeMesh::build(&sys, delta, tol, &mut work).map_err(|e| fail(&e))?;
    prop_assert!(
        mesh.duration.is_finite() && mesh.duration > 0.0,
        "{}",
        mesh.duration
    );
    let end = ReducedEnd {
        end: EndCause::Floor,
        at: None,
        delta,
    };
    let run = PhaseRun::Reduced(ReducedRun {
        system: sys.clone(),
        t_start: 0.0,
        end,
        mesh,
    });
    let samples = rodcube::solve::series::sample(&run, 100, &mut work).map_err(|e| fail(&e))?;
    let bound = sys.bound();
    let found = checks::drift(
        bound,
        &samples.states,
        &Conserved::each_cyclic(bound),
        tol,
        &checks::Context::new(info.name),
        CheckKind::Identity,
    )
    .expect("the samples are the model's states");
    prop_assert!(found.iter().any(|(k, _)| k.ends_with(".energy")));
    for (key, check) in found {
        prop_assert!(
            check.passed,
            "{key}: {} at {p:?}",
            rodcube::report::prose::check_meaning(&check)
        );
    }
    Ok(())
}

/// A system outside the per-point solver (integrated, or with a numeric separation or an
/// edge): its first contact ends (at the force's zero, an edge, or where another contact
/// closes) at a finite time inside the fall, or holds to the end, and energy is conserved along
/// each phase to the tolerance. A contact that would have to pull at release opens there: its
/// end is at t = 0 by its force, at the release angle.
fn check_contact_end(model: &'static dyn Model, p: &[f64]) -> Result<(), TestCaseError> {
    let request = Request::new(model, p.to_vec())
        .with_want(&[Quantity::ContactEnd, Quantity::Checks])
        .with_samples(50);
    let res = match plan::run(&request) {
        Ok(res) => res,
        // A rod whose foot lifts can pivot over its support and reach the end angle in the
        // air (a rod lying across a cylinder's top): the spec's end angle is no landing
        // there, and the planner says so. Only a foot free to lift can do that.
        Err(PlanError::Solve(SolveError::AboveFloor { height, .. })) => {
            let info = model.info();
            let lifts = (info.contacts.iter()).any(|c| c.name == "floor_normal" && !c.bilateral);
            prop_assert!(lifts && height > 0.0, "{}: {p:?}: above floor", info.name);
            return Ok(());
        }
        // A rod released within the contact tolerance of lying flat (its upper end that close
        // to the floor that `tip_floor` closes at release) rests on both ends: an equilibrium,
        // no motion. Only a model with that contact, started that low, may say so.
        Err(PlanError::Solve(SolveError::AtRest { .. })) => {
            let info = model.info();
            let bound =
                Bound::from_values(model, p).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let state = bound.initial_state();
            let tip = info.contacts.iter().position(|c| c.name == "tip_floor");
            let height = tip.map(|i| bound.gaps(&state).unwrap()[i]);
            let touch = DECIDE_TOLERANCE * bound.length_scale(&state).unwrap();
            prop_assert!(
                height.is_some_and(|h| h <= touch),
                "{}: {p:?}: at rest with the tip {height:?} m up",
                info.name
            );
            return Ok(());
        }
        Err(e) => {
            return Err(TestCaseError::fail(format!(
                "{}: {p:?}: {e}",
                model.info().name
            )));
        }
    };
    match res.results.get("contact_end_time") {
        Some(t) => {
            let theta = res.results["contact_end_angle"].value;
            let cause = rodcube::report::prose::label(&res.labels["contact_end_cause"].value);
            prop_assert!(t.value.is_finite() && t.value >= 0.0, "{p:?}: {}", t.value);
            // A fall ends above its end angle; a system with none (the rocking block) ends a
            // contact at a strike, where its angle is zero to the rounding of its tilt.
            match model.info().end_angle {
                Some(end) => prop_assert!(theta.is_finite() && theta > end, "{p:?}: {theta}"),
                None => prop_assert!(theta.is_finite(), "{p:?}: {theta}"),
            }
            prop_assert!(
                cause == "force" || cause == "edge" || cause == "contact",
                "{cause}"
            );
            prop_assert!(
                t.value > 0.0 || cause == "force",
                "{p:?}: {cause} at release"
            );
        }
        None => prop_assert!(res.notes.contains_key("contact_end")),
    }
    let energy: Vec<_> = (res.checks.iter())
        .filter(|(k, _)| k.ends_with(".energy"))
        .collect();
    prop_assert!(!energy.is_empty());
    for (key, check) in energy {
        prop_assert!(
            check.passed,
            "{key}: {} at {p:?}",
            rodcube::report::prose::check_meaning(check)
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 40,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x0dd_c0be),
        ..ProptestConfig::default()
    })]

    #[test]
    fn every_system_and_fast_phase_solves_random_valid_parameters(
        u in proptest::collection::vec(0.0f64..1.0, 16),
        spread in 0u8..3,
    ) {
        for &model in rodcube::models::all() {
            let info = model.info();
            if info.is_general() {
                check_system(model, &u, spread)?;
            } else if info.start_params {
                check_fast_phase(model, &u, spread)?;
            }
        }
    }
}

/// `theta_dot_sq_sc` (the lean solver's integrand, fed `sin`, `cos` and their drops) equals
/// `reduced(k, delta).theta_dot_sq` along the whole phase of every model.
fn check_theta_dot_sq_sc(model: &'static dyn Model, u: &[f64], spread: u8, frac: f64) {
    let info = model.info();
    if info.reduction.is_none() {
        return;
    }
    let p = parameters(model, u, spread);
    let sys = System::from_values(model, &p).expect("valid parameters");
    let k = sys.k();
    let (theta_i, sin_i, cos_i) = (
        k[info.reduction.unwrap().k_theta_initial],
        k[info.reduction.unwrap().k_sin_initial],
        k[info.reduction.unwrap().k_cos_initial],
    );
    assert!((sin_i - theta_i.sin()).abs() <= 1e-15 * sin_i.abs().max(1e-300));
    assert!((cos_i - theta_i.cos()).abs() <= 1e-15);
    let delta = frac * (theta_i - info.end_angle.unwrap());
    let (s, c, ds, dc) = rodcube::model::start_offsets(theta_i, sin_i, cos_i, delta);
    let sc = model.reduction().unwrap().theta_dot_sq_sc(k, s, c, ds, dc);
    let full = model.reduction().unwrap().reduced(k, delta).theta_dot_sq;
    assert!(
        (sc - full).abs() <= 1e-14 * full.abs().max(f64::MIN_POSITIVE),
        "{}: {p:?}, delta = {delta}: {sc} vs {full}",
        info.name
    );
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5c_5c),
        ..ProptestConfig::default()
    })]

    #[test]
    fn theta_dot_sq_from_sin_and_cos_equals_the_reduced_one(
        u in proptest::collection::vec(0.0f64..1.0, 16),
        spread in 0u8..3,
        frac in 0.0f64..1.0,
    ) {
        for &model in rodcube::models::all() {
            check_theta_dot_sq_sc(model, &u, spread, frac);
        }
    }
}

#[test]
fn the_generator_covers_every_model() {
    // Every shipped model gets parameters it accepts (so the property above tests them all).
    let u = [0.5; 16];
    for &model in rodcube::models::all() {
        for spread in 0..3 {
            let p = parameters(model, &u, spread);
            assert!(
                Bound::from_values(model, &p).is_ok(),
                "{}: {p:?}",
                model.info().name
            );
        }
    }
    assert!(rodcube::models::all().len() >= 5);
}
