//! Cost of the derivation of every shipped model (`derivations/*.yaml`): the symbolic work
//! alone (`derive_all`, Symbolica on its one thread) and the whole pipeline as `cargo derive`
//! runs it (`render_all`: parse and check specs, derive, lower, render templates, rustfmt).
//! Nothing is written. Needs the `derive` feature.
//!
//! Run: `cargo bench --features derive --bench derive -- --warm-up-time 1 --measurement-time 3`.

use criterion::{Criterion, criterion_group, criterion_main};
use rodcube::derive::{derive_all, render_all, spec, spec_files};
use std::hint::black_box;
use std::path::Path;

fn derive(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = spec_files(root).expect("derivations/ is readable");
    let checked: Vec<_> = files
        .iter()
        .map(|f| spec::load(f).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    let mut g = c.benchmark_group(format!("derive_{}_models", checked.len()));
    g.sample_size(10);
    g.bench_function("symbolic_derive_all", |b| {
        b.iter(|| derive_all(black_box(&checked)).unwrap_or_else(|e| panic!("{e}")))
    });
    g.bench_function("render_all_with_rustfmt", |b| {
        b.iter(|| render_all(black_box(root), &[]).unwrap_or_else(|e| panic!("{e}")))
    });
    g.finish();
}

criterion_group!(benches, derive);
criterion_main!(benches);
