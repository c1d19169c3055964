//! The registry of generated models: every model in `generated/`, found without hand edits.

/// The generated models as types, one module per model: `generated::rod_cube::RodCube`
/// names the paper's model (a unit struct implementing [`Model`]), for programs that want
/// the compiler to check the name rather than [`find`] at run time.
// A force polynomial's accessor matches on the contact even where one contact has a
// polynomial (the same layout for every model).
#[allow(clippy::single_match)]
#[path = "../generated/mod.rs"]
pub mod generated;

use crate::model::Model;

/// Every generated model, in the order of their specs.
pub fn all() -> &'static [&'static dyn Model] {
    generated::MODELS
}

/// The model with this name, if one was generated.
pub fn find(name: &str) -> Option<&'static dyn Model> {
    all().iter().copied().find(|m| m.info().name == name)
}
