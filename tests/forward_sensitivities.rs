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
/// motion, so that a difference with a step of `1e-3` keeps about nine digits.
const TOL: f64 = 1e-12;

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

/// `d(key)/d(param)` by the fourth-order central difference of the run's `key` with a
/// relative step `step` (an absolute one for a parameter that is zero).
fn difference(
    model: &'static dyn rodcube::model::Model,
    p: &BTreeMap<String, f64>,
    want: &[Quantity],
    key: &str,
    param: &str,
    step: f64,
) -> f64 {
    let h = if p[param] == 0.0 {
        step
    } else {
        step * p[param].abs()
    };
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
/// the result's own scale `|x / p|` (the derivative an elasticity of one would have; `|x|`
/// for a parameter that is zero). Returns the worst such error.
fn against_differences(scene_name: &str, want: &[Quantity], keys: &[&str], bound: f64) -> f64 {
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
            let want_value = difference(model, &p, want, key, param, 1e-3);
            let scale = if p[param] == 0.0 {
                x.abs()
            } else {
                (x / p[param]).abs()
            };
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
    for name in ["paper", "hinged", "ladder", "cylinder", "fixed_cylinder"] {
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
            assert!(
                (other.value - s.value).abs() <= 1e-8,
                "{name} {key}: integrated {} vs exact {}",
                other.value,
                s.value
            );
        }
    }
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
    let worst = against_differences("friction", &want, &keys, 1e-8);
    eprintln!("friction: worst {worst:.1e}");
}

#[test]
fn springs_and_lift_off_agree_with_differences() {
    let want = [Quantity::SeparationAngle, Quantity::SeparationTime];
    let keys = ["separation_angle", "separation_time"];
    for name in ["spring", "liftoff", "ladder_friction"] {
        let worst = against_differences(name, &want, &keys, 1e-8);
        eprintln!("{name}: worst {worst:.1e}");
    }
}

#[test]
fn a_contacts_end_after_the_first_phase_agrees_with_differences() {
    // The paper's rod: the cube's push ends on the fast path; the floor's ends later (or holds
    // to the landing), on the free slide: the landing's time comes from the integrated route.
    let want = [Quantity::ContactEnd, Quantity::FloorImpact];
    let worst = against_differences("paper", &want, &["floor_impact_time"], 1e-8);
    eprintln!("paper landing: worst {worst:.1e}");
}

/// The friction model's walker at `p` on the integrated route.
fn walker(model: &'static dyn rodcube::model::Model, p: &BTreeMap<String, f64>) -> Walker<'static> {
    let pairs: Vec<(&str, f64)> = p.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    let general = Bound::new(model, &pairs).expect("valid parameters");
    Walker {
        general,
        registry: models::all(),
        tol: TOL,
        rtol: TOL,
        route: Route::Integrated,
        until: None,
        dense_output: false,
    }
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
        let h = 1e-3 * p[*name].abs();
        let at = |k: f64| {
            let mut q = p.clone();
            *q.get_mut(*name).unwrap() += k * h;
            switch_times(&walker(model, &q))
        };
        let (a, b, c, d) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        for (s, sw) in switches.iter().enumerate() {
            let diff = (8.0 * (a[s] - b[s]) - (c[s] - d[s])) / (12.0 * h);
            let scale = times[s] / p[*name].abs();
            assert!(
                (sw[j] - diff).abs() <= 1e-8 * scale,
                "switch {s}, d t/d {name}: {} vs differences {diff}",
                sw[j]
            );
        }
    }
}
