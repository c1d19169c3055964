//! Shared test support: the paper's models typed by hand (`paper`), a wrapper that tweaks one
//! of their functions (`tweaked`), used until and alongside the generated models, and references
//! for the models with several contacts derived by hand, independently of the crate (`hand`),
//! seeded random numbers (`numbers`) and every phase of a folder of specs derived (`derived`).
#![allow(dead_code)]

/// `Model` methods that only call the same method of another model: in an `impl Model`,
/// `forward_model!(|m: &Self| <the other model>; name, ...)` writes one per name, so a test
/// double spells out only the methods it changes.
macro_rules! forward_model {
    ($base:expr; $($name:ident),* $(,)?) => {
        $(forward_model!(@ $base; $name);)*
    };
    (@ $base:expr; info) => {
        fn info(&self) -> &'static ModelInfo {
            ($base)(self).info()
        }
    };
    (@ $base:expr; requirements) => {
        fn requirements(&self, p: &[f64], out: &mut [f64]) {
            ($base)(self).requirements(p, out)
        }
    };
    (@ $base:expr; restitutions) => {
        fn restitutions(&self, p: &[f64], out: &mut [f64]) {
            ($base)(self).restitutions(p, out)
        }
    };
    (@ $base:expr; prepare) => {
        fn prepare(&self, p: &[f64], k: &mut [f64]) {
            ($base)(self).prepare(p, k)
        }
    };
    (@ $base:expr; initial_state) => {
        fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]) {
            ($base)(self).initial_state(k, q, qd)
        }
    };
    (@ $base:expr; points) => {
        fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
            ($base)(self).points(k, q, qd, pos, vel)
        }
    };
    (@ $base:expr; energy) => {
        fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
            ($base)(self).energy(k, q, qd)
        }
    };
    (@ $base:expr; momenta) => {
        fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
            ($base)(self).momenta(k, q, qd, out)
        }
    };
    (@ $base:expr; equations) => {
        fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
            ($base)(self).equations(k, q, qd, mass, rhs)
        }
    };
    (@ $base:expr; forces_full) => {
        fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
            ($base)(self).forces_full(k, q, qd, qdd, out)
        }
    };
    (@ $base:expr; gaps) => {
        fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
            ($base)(self).gaps(k, q, out)
        }
    };
    (@ $base:expr; constraints) => {
        fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
            ($base)(self).constraints(k, q, qd, jac, bias)
        }
    };
    (@ $base:expr; edges) => {
        fn edges(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
            ($base)(self).edges(k, q, out)
        }
    };
    (@ $base:expr; friction) => {
        fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
            ($base)(self).friction(k, q, qd, jac, bias)
        }
    };
    (@ $base:expr; monitors_full) => {
        fn monitors_full(&self, k: &[f64], q: &[f64], qd: &[f64], f: &[f64], out: &mut [f64]) {
            ($base)(self).monitors_full(k, q, qd, f, out)
        }
    };
    (@ $base:expr; to_full) => {
        fn to_full(&self, k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]) {
            ($base)(self).to_full(k, q, qd, q_full, qd_full)
        }
    };
    (@ $base:expr; drawing) => {
        fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]) {
            ($base)(self).drawing(k, q, poses, sizes)
        }
    };
}

#[cfg(feature = "derive")]
pub mod derived;
pub mod hand;
pub mod numbers;
pub mod paper;
pub mod tweaked;
