//! Cost of running a model from its tape (`src/tape/`) against its compiled code, side by
//! side in one run: the integrated route's right-hand side (`contacts::dynamics_into`: the
//! model's mass matrix, right-hand side, constraint and friction rows, the contact system's
//! solve and the forces) and a bare `equations` call, for `rod_cube_liftoff` and
//! `ladder_friction` at their release; the whole scene (`plan::run` of `scenes/liftoff.yaml`
//! and `scenes/ladder_friction.yaml`, nothing written); and the loading of a tape.
//!
//! Run: `cargo bench --all-features --bench tape -- --warm-up-time 1 --measurement-time 3`.

use criterion::{Criterion, criterion_group, criterion_main};
use rodcube::model::Model;
use rodcube::models;
use rodcube::plan;
use rodcube::scene::Scene;
use rodcube::solve::integrated::contacts::{self, DynamicsWork, Moment, Options};
use rodcube::system::Bound;
use rodcube::tape::{self, TapeModel};
use std::hint::black_box;
use std::path::Path;

/// The models and the scenes that run them.
const CASES: [(&str, &str); 2] = [
    ("rod_cube_liftoff", "scenes/liftoff.yaml"),
    ("ladder_friction", "scenes/ladder_friction.yaml"),
];

fn scene(file: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).expect("a shipped scene")
}

/// The compiled model of this name and the same model from its embedded tape, kept for the
/// program's life (as `rodcube run --interpreted` does).
fn both(name: &str) -> (&'static dyn Model, &'static TapeModel) {
    let compiled = (models::compiled().iter().copied())
        .find(|m| m.info().name == name)
        .expect("compiled");
    let text = models::embedded_tape(name).expect("an embedded tape");
    let taped = tape::load_text(text, name).expect("the embedded tape loads");
    (compiled, taped)
}

/// The right-hand side of the integrated route at the scene's release, in the active set its
/// release decides, and the bare `equations` call, on both routes.
fn rhs(c: &mut Criterion) {
    let mut g = c.benchmark_group("tape_rhs");
    for (name, file) in CASES {
        let (compiled, taped) = both(name);
        let scene = scene(file);
        let mut outputs = Vec::new();
        for (route, model) in [("compiled", compiled), ("tape", taped as &dyn Model)] {
            let sys = Bound::from_values(model, &scene.parameters).expect("valid parameters");
            let state = sys.initial_state();
            let options = Options {
                contacts: contacts::contact_options(&sys, &state, Moment::Release)
                    .expect("a release"),
                frictions: contacts::friction_options(&sys, &state).expect("frictions"),
            };
            let active = contacts::decide(&sys, &state, &options, 0.0).expect("decided");
            let mut work = DynamicsWork::default();
            contacts::dynamics_into(&sys, &state, &active, 0.0, &mut work).expect("solves");
            outputs.push(format!("{:?}", work.out));
            g.bench_function(format!("{name}/dynamics_into/{route}"), |b| {
                b.iter(|| {
                    contacts::dynamics_into(black_box(&sys), &state, &active, 0.0, &mut work)
                        .expect("solves")
                })
            });
            let n = sys.n_coordinates();
            let (mut mass, mut rhs) = (vec![0.0; n * n], vec![0.0; n]);
            let (q, qd) = (state.q(), state.qd());
            g.bench_function(format!("{name}/equations/{route}"), |b| {
                b.iter(|| model.equations(black_box(sys.k()), q, qd, &mut mass, &mut rhs))
            });
        }
        assert_eq!(outputs[0], outputs[1], "{name}: the tape's solve differs");
    }
    g.finish();
}

/// The whole scene through the planner (every quantity it wants; nothing rendered or
/// written), the compiled model against its tape.
fn scenes(c: &mut Criterion) {
    let mut g = c.benchmark_group("tape_scene");
    g.sample_size(10);
    for (name, file) in CASES {
        let (_, taped) = both(name);
        let scene = scene(file);
        let compiled = scene.request();
        let mut interpreted = scene.request();
        interpreted.model = taped;
        let a = plan::run(&compiled).expect("the scene solves");
        let b = plan::run(&interpreted).expect("the scene solves");
        assert_eq!(
            format!("{:?}", (&a.results, &a.series)),
            format!("{:?}", (&b.results, &b.series)),
            "{name}: the tape's results differ"
        );
        let stem = file.trim_start_matches("scenes/").trim_end_matches(".yaml");
        g.bench_function(format!("{stem}/compiled"), |b| {
            b.iter(|| plan::run(black_box(&compiled)).expect("the scene solves"))
        });
        g.bench_function(format!("{stem}/interpreted"), |b| {
            b.iter(|| plan::run(black_box(&interpreted)).expect("the scene solves"))
        });
    }
    g.finish();
}

/// Reading and checking a tape (`tape::parse`: JSON, digest, info, every method's program).
fn load(c: &mut Criterion) {
    let mut g = c.benchmark_group("tape_load");
    for (name, _) in CASES {
        let text = models::embedded_tape(name).expect("an embedded tape");
        g.bench_function(name, |b| {
            b.iter(|| tape::parse(black_box(text), name).expect("loads"))
        });
    }
    g.finish();
}

criterion_group!(benches, rhs, scenes, load);
criterion_main!(benches);
