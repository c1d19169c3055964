//! The fixed per-point set of issue 13, shared by `examples/per_point.rs` and
//! `benches/solve.rs`: the 100 x 100 grid `n_i = 10^(-3 + 6 i / 99)`,
//! `a/ell_j = 0.01 + 0.98 j / 99` (`ell = g = m1 = 1`, `m2 = n`), row-major by `i`; point `k` is
//! grid index `(7919 k) mod 10000`.

/// Parameters `[m1, m2, ell, a, g]` of rod_cube for the first `count` points of the set.
pub fn per_point_set(count: usize) -> Vec<[f64; 5]> {
    let n: Vec<f64> = (0..100)
        .map(|i| 10f64.powf(-3.0 + 6.0 * i as f64 / 99.0))
        .collect();
    (0..count)
        .map(|k| {
            let index = (7919 * k) % 10_000;
            let (i, j) = (index / 100, index % 100);
            let a = 0.01 + 0.98 * j as f64 / 99.0;
            [1.0, n[i], 1.0, a, 1.0]
        })
        .collect()
}
