//! Shared test support: the paper's models typed by hand (`paper`), a wrapper that tweaks one
//! of their functions (`tweaked`), used until and alongside the generated models, and references
//! for the models with several contacts derived by hand, independently of the crate (`hand`).
#![allow(dead_code)]

pub mod hand;
pub mod paper;
pub mod tweaked;
