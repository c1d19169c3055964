//! rodcube: a rod leaning on a cube (and models like it), derived symbolically and solved fast.
//!
//! The runtime half of the project: it consumes the model code that `rodcube derive` emitted
//! into `generated/` and never depends on Symbolica.
//!
//! # Guide
//!
//! Every model in `generated/` implements [`model::Model`] and is listed by [`models::all`].
//! The usual entry point is the planner, which computes what you ask for and nothing else:
//!
//! ```
//! use rodcube::{models, plan::{self, Request}, quantity::Quantity};
//!
//! let model = models::find("rod_cube").expect("generated model");
//! let paper = [("m1", 1.0), ("m2", 3.0), ("ell", 1.0), ("a", 0.25), ("g", 9.81)];
//! let request = Request::new(model, paper)
//!     .with_want(&[Quantity::SeparationAngle, Quantity::SeparationTime]);
//! let results = plan::run(&request)?;
//! let theta_sep = results.separation_angle().expect("the paper's rod separates");
//! let t_sep = results.separation_time().expect("wanted");
//! assert!((theta_sep.to_degrees() - 9.61).abs() < 0.005);
//! assert!((t_sep - 0.1085).abs() < 5e-4);
//! assert_eq!(results.work.integrand_evals > 0, true);
//! # Ok::<(), rodcube::plan::PlanError>(())
//! ```
//!
//! For many points, [`solve::fast::lean::LeanSolver`] gives the separation angle and time alone,
//! reusing its buffers (no allocation per point, under a microsecond per point for the paper's
//! model; `rodcube sweep` calls it):
//!
//! ```
//! use rodcube::{models, solve::fast::lean::LeanSolver};
//!
//! let model = models::find("rod_cube").expect("generated model");
//! let names: Vec<&str> = model.info().parameters.iter().map(|p| p.name).collect();
//! assert_eq!(names, ["m1", "m2", "ell", "a", "g"]); // the order `solve` takes them in
//! let mut solver = LeanSolver::new(model)?;
//! for n in [0.5, 1.0, 3.0, 10.0] {
//!     let point = solver.solve(&[1.0, n, 1.0, 0.25, 9.81])?;
//!     assert!(point.separation_angle > 0.0 && point.separation_angle < 0.25f64.asin());
//!     assert!(point.separation_time > 0.0);
//! }
//! # Ok::<(), rodcube::solve::SolveError>(())
//! ```
//!
//! - [`plan`]: [`plan::Request`] → [`results::RunResults`] (scalars, series, checks, work).
//! - [`system::System`]: a model with validated parameters and its prepared constants, for
//!   calling the generated functions directly.
//! - [`solve`]: the numerical building blocks (separation root, quadrature of the time
//!   integral, θ(t) series, Dormand–Prince integration of the unreduced equations, phases,
//!   checks), each with typed errors.
//! - [`scene`] and [`report`]: YAML scenes and their table, JSON, CSV and SVG outputs, as used
//!   by the `rodcube` command line.
//!
//! `examples/paper.rs` reproduces the paper's numbers; `examples/sweep_n.rs` sweeps the mass
//! ratio. The derivation tool lives behind the cargo feature `derive` (it needs Symbolica).

#[cfg(feature = "cli")]
pub mod accuracy;
pub mod axes;
#[cfg(feature = "derive")]
pub mod derive;
#[cfg(feature = "capi")]
pub mod ffi;
#[cfg(any(feature = "cli", feature = "fmi"))]
pub mod fmu;
#[doc(hidden)]
pub mod fuzzing;
pub mod io;
pub mod model;
pub mod models;
pub mod plan;
pub mod quantity;
#[cfg(feature = "cli")]
pub mod reference;
pub mod report;
pub mod results;
pub mod scene;
pub mod solve;
pub mod spec;
#[cfg(feature = "sweep")]
pub mod sweep;
pub mod system;
pub mod tape;
pub mod yaml;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
