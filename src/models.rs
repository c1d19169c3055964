//! The registry of generated models: every model in `generated/`, found without hand edits.

#[path = "../generated/mod.rs"]
mod generated;

use crate::model::Model;

/// Every generated model, in the order of their specs.
pub fn all() -> &'static [&'static dyn Model] {
    generated::MODELS
}

/// The model with this name, if one was generated.
pub fn find(name: &str) -> Option<&'static dyn Model> {
    all().iter().copied().find(|m| m.info().name == name)
}
