//! Forward sensitivities of integrated phases against references independent of them: the
//! fast path's exact derivatives of the same results (closed-form partial derivatives and the
//! implicit-function theorem, no integration), and fourth-order central differences of the run
//! itself at a tight tolerance (friction with its stick/slip switch, a spring, a lift-off, the
//! landing).

use rodcube::models;
use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::results::{RunResults, Work};
use rodcube::scene::Scene;
use rodcube::solve::phases::{PhaseRun, Route, Walker};
use rodcube::system::Bound;
use std::collections::BTreeMap;
use std::path::Path;

/// The tolerance of every run here: the integrator's error then stays near `1e-12` of the
/// motion, so that a difference with a step of [`STEP`] keeps about nine digits.
const TOL: f64 = 1e-12;

/// The differences' relative step. Their truncation error goes as its fourth power and is
/// large for the friction model, near the `mu` where the foot would no longer stick: the first
/// switch's `dt/dmu` by differences with steps of `1e-3`, `3e-4`, `1e-4`, `3e-5` is
/// -0.880596005, -0.8805992618, -0.8805992879, -0.88059928822 (the forward sensitivity:
/// -0.88059928822). At `1e-4` truncation leaves about `4e-10` of the derivative, and the
/// runs' rounding (about `1e-13` of a time) about `1e-9`. A system near a singular geometry
/// needs a step relative to its distance from it ([`NEAR_SINGULAR_STEP`]).
const STEP: f64 = 1e-4;

/// The step for the tipping block, whose height `h = 0.99` is one hundredth of the rod's
/// length from `ell`: the block's end time's `d/d(ell)` (about -19, an elasticity of -130)
/// by differences with steps `1e-3` to `1e-5` is -19.0383, -19.04405, -19.0440949, -19.04409540,
/// -19.044095409 (forward: -19.044095409).
const NEAR_SINGULAR_STEP: f64 = 1e-5;

/// The scene's model and parameters.
fn scene(name: &str) -> (&'static dyn rodcube::model::Model, BTreeMap<String, f64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.yaml"));
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let model = models::find(scene.info().name).expect("the scene's model is registered");
    (model, scene.parameter_map())
}

fn run(
    model: &'static dyn rodcube::model::Model,
    p: &BTreeMap<String, f64>,
    want: &[Quantity],
    route: Route,
) -> RunResults {
    let request = Request::new(model, p)
        .with_want(want)
        .with_tolerance(TOL)
        .with_route(route);
    plan::run(&request).unwrap_or_else(|e| panic!("{}: {e}", model.info().name))
}

/// `d(key)/d(param)` by the fourth-order central difference of the run's `key` with the
/// relative step `step` (`param` not zero).
fn difference(
    model: &'static dyn rodcube::model::Model,
    p: &BTreeMap<String, f64>,
    (want, key): (&[Quantity], &str),
    param: &str,
    step: f64,
) -> f64 {
    let h = step * p[param].abs();
    let at = |k: f64| {
        let mut q = p.clone();
        *q.get_mut(param).unwrap() += k * h;
        let res = run(model, &q, want, Route::Fastest);
        res.results
            .get(key)
            .unwrap_or_else(|| panic!("{key} missing at {param} + {k} h: {:?}", res.notes))
            .value
    };
    (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h)
}

/// Every `d(key)/d(p)` the run reports, against differences: held to `bound` relative to
/// the result's own scale `|x / p|` (the derivative an elasticity of one would have). A
/// parameter at zero (a restitution or friction coefficient at its bound) has a one-sided
/// derivative only: it must be finite. Returns the worst error.
fn against_differences(
    scene_name: &str,
    want: &[Quantity],
    keys: &[&str],
    (bound, step): (f64, f64),
) -> f64 {
    let (model, p) = scene(scene_name);
    let mut with = want.to_vec();
    with.push(Quantity::Sensitivities);
    let res = run(model, &p, &with, Route::Fastest);
    let mut worst: f64 = 0.0;
    for key in keys {
        let x = res
            .results
            .get(*key)
            .unwrap_or_else(|| panic!("{key}"))
            .value;
        for param in model.info().parameters.iter().map(|q| q.name) {
            let name = format!("d({key})/d({param})");
            let got = (res.sensitivities.get(&name))
                .unwrap_or_else(|| panic!("{scene_name}: {name} missing; notes {:?}", res.notes))
                .value;
            if p[param] == 0.0 {
                assert!(got.is_finite(), "{scene_name} {name}: {got}");
                continue;
            }
            let want_value = difference(model, &p, (want, key), param, step);
            let scale = (x / p[param]).abs();
            let err = (got - want_value).abs() / scale;
            worst = worst.max(err);
            assert!(
                err <= bound,
                "{scene_name} {name}: {got} vs differences {want_value} ({err:.1e} of |x/p|)"
            );
        }
    }
    worst
}

#[test]
fn integrated_sensitivities_equal_the_fast_paths_exact_ones() {
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::Sensitivities,
    ];
    let mut worst: f64 = 0.0;
    for name in ["paper", "hinged", "ladder"] {
        let (model, p) = scene(name);
        let fast = run(model, &p, &want, Route::Fastest);
        let integrated = run(model, &p, &want, Route::Integrated);
        assert!(!fast.sensitivities.is_empty(), "{name}: {:?}", fast.notes);
        for (key, s) in &fast.sensitivities {
            if !s.elasticity {
                continue;
            }
            let other = (integrated.sensitivities.get(key))
                .unwrap_or_else(|| panic!("{name}: {key} missing: {:?}", integrated.notes));
            let err = (other.value - s.value).abs();
            worst = worst.max(err);
            assert!(
                err <= 1e-8,
                "{name} {key}: integrated {} vs exact {}",
                other.value,
                s.value
            );
        }
    }
    eprintln!("elasticities, integrated against exact: worst {worst:.1e}");
}

#[test]
fn friction_and_its_stick_slip_switch_agree_with_differences() {
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::FloorImpact,
    ];
    let keys = [
        "separation_angle",
        "separation_time",
        "floor_impact_time",
        "impact_angular_velocity",
    ];
    let worst = against_differences("friction", &want, &keys, (1e-8, STEP));
    eprintln!("friction: worst {worst:.1e}");
}

#[test]
fn springs_lift_off_edges_and_later_contacts_agree_with_differences() {
    use Quantity::{ContactEnd, FloorImpact, SeparationAngle, SeparationTime};
    let cases: [(&str, &[Quantity], &[&str]); 6] = [
        // A spring: integrated from release.
        (
            "spring",
            &[SeparationAngle, SeparationTime],
            &["separation_angle", "separation_time"],
        ),
        // A hinge with a spring: its fast phase has no partial derivatives of the separation.
        (
            "hinged_spring",
            &[SeparationAngle, SeparationTime],
            &["separation_angle", "separation_time"],
        ),
        // The foot may lift: the landing after the free phases.
        (
            "liftoff",
            &[SeparationTime, FloorImpact],
            &["separation_time", "floor_impact_time"],
        ),
        // Friction at two contacts with switches, to the landing.
        (
            "ladder_friction",
            &[SeparationTime, FloorImpact],
            &["separation_time", "floor_impact_time"],
        ),
        // A second contact's end (the block's edge contact), after the first's.
        (
            "block_tipping",
            &[ContactEnd],
            &["block_near_edge_end_time", "block_near_edge_end_angle"],
        ),
        // A contact that ends at an edge.
        (
            "cylinder",
            &[ContactEnd],
            &["contact_end_time", "contact_end_angle"],
        ),
    ];
    for (name, want, keys) in cases {
        let step = if name == "block_tipping" {
            NEAR_SINGULAR_STEP
        } else {
            STEP
        };
        let worst = against_differences(name, want, keys, (1e-8, step));
        eprintln!("{name}: worst {worst:.1e}");
    }
}

#[test]
fn a_contacts_end_after_the_first_phase_agrees_with_differences() {
    // The paper's rod: the cube's push ends on the fast path; the floor's ends later (or holds
    // to the landing), on the free slide: the landing's time comes from the integrated route.
    let want = [Quantity::ContactEnd, Quantity::FloorImpact];
    let worst = against_differences("paper", &want, &["floor_impact_time"], (1e-8, STEP));
    eprintln!("paper landing: worst {worst:.1e}");
}

/// The friction model's walker at `p` on the integrated route.
fn walker(model: &'static dyn rodcube::model::Model, p: &BTreeMap<String, f64>) -> Walker<'static> {
    let pairs: Vec<(&str, f64)> = p.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    let general = Bound::new(model, &pairs).expect("valid parameters");
    Walker::new(general, models::all(), TOL, TOL)
        .with_route(Route::Integrated)
        .with_dense_output(false)
}

/// The absolute times of the stick/slip switches inside the motion's phases.
fn switch_times(walker: &Walker) -> Vec<f64> {
    let motion = walker.motion(&mut Work::default()).expect("solves");
    let mut out = Vec::new();
    for phase in &motion.phases {
        if let PhaseRun::Integrated(r) = phase {
            out.extend(r.run.segments.iter().skip(1).map(|s| r.t_start + s.t_start));
        }
    }
    out
}

#[test]
fn a_stick_slip_switch_time_moves_as_differences_across_it_say() {
    let (model, p) = scene("friction");
    let sensitive = walker(model, &p)
        .sensitive_motion(&mut Work::default())
        .expect("solves with sensitivities");
    let switches: Vec<Vec<f64>> = (sensitive.ends.iter())
        .flat_map(|e| e.as_ref().expect("no grazing event").switches.clone())
        .collect();
    let times = switch_times(&walker(model, &p));
    assert!(!times.is_empty(), "the foot sticks: at least one switch");
    assert_eq!(switches.len(), times.len());
    let names: Vec<&str> = model.info().parameters.iter().map(|q| q.name).collect();
    for (j, name) in names.iter().enumerate() {
        let h = STEP * p[*name].abs();
        let at = |k: f64| {
            let mut q = p.clone();
            *q.get_mut(*name).unwrap() += k * h;
            switch_times(&walker(model, &q))
        };
        let (a, b, c, d) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        for (s, sw) in switches.iter().enumerate() {
            let diff = (8.0 * (a[s] - b[s]) - (c[s] - d[s])) / (12.0 * h);
            let scale = (times[s] / p[*name]).abs().max(diff.abs());
            assert!(
                (sw[j] - diff).abs() <= 1e-8 * scale,
                "switch {s}, d t/d {name}: {} vs differences {diff}",
                sw[j]
            );
        }
    }
}

/// The times of `walker`'s impacts that close no Zeno sequence, in order.
fn impact_times(walker: &Walker) -> Vec<f64> {
    let motion = walker.motion(&mut Work::default()).expect("solves");
    (motion.impacts.iter())
        .filter(|i| i.zeno.is_none())
        .map(|i| i.t)
        .collect()
}

#[test]
fn the_sensitive_motion_goes_through_every_impact_and_its_times_move_as_differences_say() {
    // The bouncing rod goes on through its impacts to 0.6 s: `S` crosses each by its saltation
    // matrix, through the limit of the converging (Zeno) sequence, whose accumulation time is
    // differentiated through the sequence's last times.
    let (model, p) = scene("bounce");
    let mut w = walker(model, &p);
    w.until = Some(0.6);
    let sensitive = w.sensitive_motion(&mut Work::default()).expect("solves");
    assert_eq!(sensitive.stop, None);
    assert_eq!(sensitive.ends.len(), sensitive.motion.phases.len());
    let full = w.motion(&mut Work::default()).expect("solves");
    assert_eq!(sensitive.motion.impacts.len(), full.impacts.len());
    let crossed = &sensitive.motion.impacts[..sensitive.motion.impacts.len() - 1];
    assert!(crossed.len() >= 4, "{} impacts", crossed.len());
    // The first four impacts' times against fourth-order central differences of the run.
    let names = ["e", "a", "ell", "g", "m2"];
    impact_times_agree((model, &p, 0.6), &sensitive.ends, &crossed[..4], &names);
}

/// The rocking block (scenes/rocking.yaml) with friction `mu`, to `until`: the first
/// `count` strikes' times differentiated through the earlier strikes' saltation matrices, with
/// their frictions' laws (`stick`: sticking at every strike, else sliding at some), against
/// fourth-order central differences of the run.
fn rocking_strikes_agree(mu: f64, until: f64, count: usize, stick: bool) {
    use rodcube::solve::integrated::impact::FrictionLaw;
    let (model, mut p) = scene("rocking");
    *p.get_mut("mu").expect("mu") = mu;
    let mut w = walker(model, &p);
    w.until = Some(until);
    let sensitive = w.sensitive_motion(&mut Work::default()).expect("solves");
    assert_eq!(sensitive.stop, None);
    let all = &sensitive.motion.impacts;
    let strikes = &all[..all.iter().take_while(|i| i.zeno.is_none()).count()];
    assert!(strikes.len() >= count, "{} strikes", strikes.len());
    let laws = |i: usize| &strikes[i].impact.friction_laws;
    let slides =
        (0..strikes.len()).any(|i| laws(i).iter().any(|l| matches!(l, FrictionLaw::Slide(_))));
    assert_eq!(slides, !stick);
    assert!((0..strikes.len()).all(|i| laws(i).iter().any(|l| *l != FrictionLaw::Out)));
    let names = ["w", "h", "phi0", "g", "mu"];
    impact_times_agree(
        (model, &p, until),
        &sensitive.ends,
        &strikes[..count],
        &names,
    );
}

/// The times of `impacts` (the first of a motion of `model` with parameters `p` to `until`,
/// none closing a Zeno sequence), differentiated in each parameter of `names` by the
/// sensitivities' `ends`, against fourth-order central differences of the run, within `1e-7`
/// of the result's own scale `|t / p|`.
fn impact_times_agree(
    run: (
        &'static dyn rodcube::model::Model,
        &BTreeMap<String, f64>,
        f64,
    ),
    ends: &[Result<
        rodcube::solve::phases::EndDerivatives,
        rodcube::solve::integrated::forward::Grazing,
    >],
    impacts: &[rodcube::solve::phases::ImpactAt],
    names: &[&str],
) {
    let (model, p, until) = run;
    for name in names {
        let j = (model.info().parameters.iter())
            .position(|q| q.name == *name)
            .expect("a parameter");
        let h = STEP * p[*name].abs();
        let at = |k: f64| {
            let mut q = p.clone();
            *q.get_mut(*name).expect("a parameter") += k * h;
            let mut w = walker(model, &q);
            w.until = Some(until);
            impact_times(&w)
        };
        let (a, b, c, d) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        for (k, impact) in impacts.iter().enumerate() {
            let dt = ends[impact.phase].as_ref().expect("not grazing").t[j];
            let diff = (8.0 * (a[k] - b[k]) - (c[k] - d[k])) / (12.0 * h);
            let scale = (impact.t / p[*name]).abs().max(diff.abs());
            assert!(
                (dt - diff).abs() <= 1e-7 * scale,
                "{}, impact {}, d t/d {name}: {dt} vs differences {diff}",
                model.info().name,
                k + 1
            );
        }
    }
}

#[test]
fn rocking_strikes_that_stick_move_as_differences_say() {
    // mu = 0.7: every strike sticks (Housner's); the strike times do not move with mu.
    rocking_strikes_agree(0.7, 1.5, 4, true);
}

#[test]
fn rocking_strikes_that_slide_move_as_differences_say() {
    // mu = 0.1: the strike slides, its impulse on the cone's edge, whose derivative in mu
    // moves every later strike.
    rocking_strikes_agree(0.1, 1.0, 2, false);
}

#[test]
fn the_rocking_blocks_rest_time_moves_as_differences_say() {
    // The strikes accumulate near 2.39 s, where the block comes to rest on both corners; the
    // accumulation time's derivatives, through the series over the last strikes' times,
    // against fourth-order central differences of the accumulation time the run finds.
    let (model, p) = scene("rocking");
    let rest = |q: &BTreeMap<String, f64>| -> (f64, usize, Option<Vec<f64>>) {
        let mut w = walker(model, q);
        w.until = Some(4.0);
        let sensitive = w.sensitive_motion(&mut Work::default()).expect("solves");
        assert_eq!(sensitive.stop, None);
        let impacts = &sensitive.motion.impacts;
        let k = impacts.len() - 1;
        let t = impacts[k]
            .zeno
            .expect("the last impact closes the sequence");
        (t, k, sensitive.accumulation.get(&k).cloned())
    };
    let (t, _, d) = rest(&p);
    let d = d.expect("the accumulation time's derivatives");
    for (j, name) in model.info().parameters.iter().map(|q| q.name).enumerate() {
        if ["m", "mu"].contains(&name) {
            // Mass scales out; the strikes stick inside the cone.
            assert!(d[j].abs() <= 1e-9 * t, "d t/d {name} = {}", d[j]);
            continue;
        }
        if name == "e" {
            // At e = 0 the derivative is the plastic law's; any e above adds a bounce of the
            // striking corner at every strike, a motion of other events: the planner refuses
            // it (`a_plastic_restitution_has_no_derivative_after_its_impact`).
            continue;
        }
        let h = 1e-4 * p[name];
        let at = |k: f64| {
            let mut q = p.clone();
            *q.get_mut(name).expect("a parameter") += k * h;
            rest(&q).0
        };
        let diff = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h);
        assert!(
            (d[j] - diff).abs() <= 1e-6 * diff.abs().max(t / p[name]),
            "d t_rest/d {name}: {} vs differences {diff}",
            d[j]
        );
    }
}

#[test]
fn a_plastic_restitution_has_no_derivative_after_its_impact() {
    // The rocking block's corners strike plastically (e = 0). Any e > 0 makes each strike
    // bounce (its rest time's one-sided differences in e are 10.95 where the plastic law's
    // saltation gives 52.95): every result after the first strike has a note for `e`, and its
    // derivatives in the other parameters.
    let (model, p) = scene("rocking");
    let want = [Quantity::Impacts, Quantity::Sensitivities];
    let request = Request::new(model, &p)
        .with_want(&want)
        .with_until(Some(1.0));
    let res = plan::run(&request).expect("runs");
    let n = res.impacts.as_ref().expect("impacts").len();
    assert!(n >= 2, "{n} strikes");
    // The first strike's time does not depend on e: it comes before any bounce.
    assert!(res.sensitivities.contains_key("d(impact_1_time)/d(e)"));
    for i in 2..=n {
        let key = format!("d(impact_{i}_time)/d(e)");
        assert!(!res.sensitivities.contains_key(&key), "{key}");
        assert_eq!(
            res.notes.get(&format!("sensitivities.{key}")),
            Some(&rodcube::results::Note::NoSensitivity(
                rodcube::results::SensitivityGap::OneSided
            )),
            "{key}"
        );
        assert!(
            res.sensitivities
                .contains_key(&format!("d(impact_{i}_time)/d(w)"))
        );
    }
}

#[test]
fn every_impact_time_has_its_sensitivities_the_zeno_limit_too() {
    let (model, p) = scene("bounce");
    let want = [
        Quantity::ContactEnd,
        Quantity::Impacts,
        Quantity::Sensitivities,
    ];
    let request = Request::new(model, &p)
        .with_want(&want)
        .with_until(Some(0.6));
    let res = plan::run(&request).expect("runs");
    let impacts = res.impacts.as_ref().expect("impacts");
    let last = impacts.len();
    assert!(impacts[last - 1].zeno_limit && last >= 5);
    for i in 1..=last {
        for q in ["m1", "m2", "ell", "a", "g", "e"] {
            let key = format!("d(impact_{i}_time)/d({q})");
            let s = res
                .sensitivities
                .get(&key)
                .unwrap_or_else(|| panic!("{key}"));
            assert!(s.value.is_finite() && s.integrated, "{key}: {s:?}");
        }
    }
    assert_eq!(res.sensitivities["d(impact_1_time)/d(m1)"].unit, "s/kg");
    assert_eq!(res.sensitivities["d(impact_2_time)/d(e)"].unit, "s");
    assert_eq!(
        res.notes.get(&format!("sensitivities.impact_{last}_time")),
        None
    );
    // Without `until` the run ends at its first impact, the landing: its time's derivatives
    // are the landing's.
    let request = Request::new(model, &p).with_want(&[
        Quantity::FloorImpact,
        Quantity::Impacts,
        Quantity::Sensitivities,
    ]);
    let first = plan::run(&request).expect("runs");
    assert_eq!(first.impacts.as_ref().map(Vec::len), Some(1));
    for q in ["m1", "m2", "ell", "a", "g", "e"] {
        let d = |key: &str| first.sensitivities[&format!("d({key})/d({q})")].value;
        assert_eq!(d("impact_1_time"), d("floor_impact_time"), "{q}");
    }
    // The impulses have none, and say so.
    assert_eq!(
        res.notes.get("sensitivities.impacts"),
        Some(&rodcube::results::Note::NoSensitivity(
            rodcube::results::SensitivityGap::NotBuilt
        ))
    );
}

#[test]
fn a_loose_tolerance_still_finds_the_same_events() {
    // At a tolerance of 1e-4 the fast path's separation may be off by about that much: the
    // integrated route's events are still taken as the run's, and their derivatives agree with
    // the tight run's to about the tolerance.
    let (model, p) = scene("paper");
    let want = [
        Quantity::ContactEnd,
        Quantity::FloorImpact,
        Quantity::Sensitivities,
    ];
    let loose = plan::run(
        &Request::new(model, &p)
            .with_want(&want)
            .with_tolerance(1e-4),
    )
    .expect("runs");
    let tight = run(model, &p, &want, Route::Fastest);
    assert!(
        !loose.notes.keys().any(|k| k.starts_with("sensitivities.")),
        "{:?}",
        loose.notes
    );
    for (key, s) in &tight.sensitivities {
        let other = &loose.sensitivities[key];
        if s.elasticity {
            assert!(
                (other.value - s.value).abs() <= 1e-3,
                "{key}: {} vs {}",
                other.value,
                s.value
            );
        }
    }
}
