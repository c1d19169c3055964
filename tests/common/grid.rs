//! The hard-case grid: mass ratios `n` from 1e-12 to 1e12 and `a/ell` from 1e-10 (nearly flat)
//! to `1 - 1e-9` (nearly upright), shared by the tests held to the high-precision reference
//! (included with `#[path]`, as `tests/hard_cases.rs` and `tests/sensitivities.rs` do).

/// Mass ratios `n = m2/m1`.
pub const NS: [f64; 10] = [1e-12, 1e-8, 1e-4, 1e-2, 1.0, 3.0, 1e2, 1e4, 1e8, 1e12];

/// Ratios `a/ell`.
pub const RS: [f64; 10] = [
    1e-10,
    1e-7,
    1e-4,
    0.01,
    0.25,
    0.5,
    0.9,
    0.99,
    1.0 - 1e-6,
    1.0 - 1e-9,
];
