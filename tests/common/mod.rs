//! Shared test support: the paper's models typed by hand (`paper`) and a wrapper that tweaks one
//! of their functions (`tweaked`), used until and alongside the generated models.
#![allow(dead_code)]

pub mod paper;
pub mod tweaked;
