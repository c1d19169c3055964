//! `sinh^2`, `sinh` and `cosh` at the quadrature's nodes, to a few ulps and without a
//! library call where a series serves: [`sinh_sq`] one node at a time, [`SinhSq`] several in
//! the same arithmetic (the lanes of a vector register), [`sinh_cosh`] both from one `exp_m1`,
//! and [`ln_1p`], the logarithm behind the panel's end `v = asinh(sqrt(q))`, inlined.

/// Largest `|y|` at which `sinh(y)^2` is taken from the series of [`sinh_ratio_series`] rather
/// than from one `exp` (a library call costing several times the series' nine multiply-adds).
pub(super) const SERIES_REACH: f64 = 1.5;

/// `sinh(y)^2` within a few ulps: `y^2 (sinh(y) / y)^2` by the Taylor series of `sinh(y) / y`
/// for `|y| <` [`SERIES_REACH`], one `exp` beyond (which then loses at most a factor 1.1 to
/// the difference `e^y - e^-y`).
#[inline(always)]
pub(super) fn sinh_sq(y: f64) -> f64 {
    let ay = y.abs();
    if ay < SERIES_REACH {
        let z = y * y;
        let r = sinh_ratio_series(z);
        z * r * r
    } else {
        let e = ay.exp();
        let sh = 0.5 * (e - 1.0 / e);
        sh * sh
    }
}

/// `sinh^2` of several arguments in the same arithmetic, lane by lane (the compiler packs the
/// lanes): by [`sinh_sq`], or by the series alone for arguments known to lie within
/// [`SERIES_REACH`].
pub(super) trait SinhSq {
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N];
}

/// [`SinhSq`] by [`sinh_sq`]: the series where every lane is within its reach, else each lane
/// by itself.
pub(super) struct AnyReach;

impl SinhSq for AnyReach {
    #[inline(always)]
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N] {
        let mut near = true;
        for v in y {
            near &= v.abs() < SERIES_REACH;
        }
        if near {
            Series::lanes(y)
        } else {
            let mut out = [0.0; N];
            for i in 0..N {
                out[i] = sinh_sq(y[i]);
            }
            out
        }
    }
}

/// [`SinhSq`] by the series alone (every argument within [`SERIES_REACH`]).
pub(super) struct Series;

impl SinhSq for Series {
    #[inline(always)]
    fn lanes<const N: usize>(y: [f64; N]) -> [f64; N] {
        let mut out = [0.0; N];
        for i in 0..N {
            let z = y[i] * y[i];
            let r = sinh_ratio_series(z);
            out[i] = z * r * r;
        }
        out
    }
}

/// `sinh(y) / y` for `z = y^2 <= 2.25` by a polynomial of degree 8 in `z`: the Taylor series
/// `sum z^k / (2k + 1)!` to `z^17`, economized on `[0, 9/4]` by Chebyshev polynomials (the
/// series rewritten in `T_j(8z/9 - 1)` and cut after `T_8`, in exact rational arithmetic), its
/// coefficients rounded to nearest. The cut leaves `9.5e-20` relative and the rounded
/// coefficients `2.8e-18` (`2^-58`), two multiply-adds fewer than the Taylor polynomial's ten
/// for the same reach. All coefficients are positive, so Horner's rule adds no cancellation;
/// the test `sinh_squared_keeps_its_digits_on_both_sides_of_the_series_reach` holds the result
/// within four ulps of std's `sinh`.
#[inline(always)]
fn sinh_ratio_series(z: f64) -> f64 {
    const C: [f64; 8] = [
        0.166_666_666_666_666_66,
        0.008_333_333_333_333_415,
        0.000_198_412_698_412_328_65,
        2.755_731_923_243_199_3e-6,
        2.505_210_730_202_160_7e-8,
        1.605_912_543_432_801_6e-10,
        7.643_585_437_051_482e-13,
        2.895_878_527_457_87e-15,
    ];
    let mut r = C[7];
    for &c in C[..7].iter().rev() {
        r = r * z + c;
    }
    1.0 + z * r
}

/// `(sinh x, cosh x)` from one `exp_m1`, accurate for small and large `x` alike.
#[inline]
pub(super) fn sinh_cosh(x: f64) -> (f64, f64) {
    let em = x.exp_m1();
    let inv = 1.0 / (1.0 + em);
    (0.5 * (em + em * inv), 0.5 * (1.0 + em + inv))
}

/// `ln(1 + x)` for `x >= 0` within an ulp, inlined into its caller (the per-point route takes
/// it once per point, for the end of the fall's panel, where the system library's `log1p` is a
/// call costing about twice this). The classical reduction (P. T. P. Tang's and fdlibm's): `u =
/// 1 + x` rounded and `c = (x - (u - 1)) / u` the part of `x` the rounding lost; `u = 2^k m` with
/// `m` in `[sqrt(2)/2, sqrt(2))` and `f = m - 1` exact; `ln(1 + f) = 2 atanh(s)`, `s = f / (2 +
/// f)`, as `f - f^2/2 + s (f^2/2 + R(s^2))` with `R` the minimax polynomial of degree 7 of
/// [`LN_1P_R`] (error below `2^-58.45` on the range); `ln 2` split in two so that `k ln2_hi` is
/// exact. Below `sqrt(2) - 1`, `f = x` with nothing lost. A NaN, a negative `x` or `u` from
/// `2^53` on take the library's `ln_1p`. Tested against it in
/// `ln_1p_is_the_librarys_within_an_ulp`.
#[inline(always)]
pub(super) fn ln_1p(x: f64) -> f64 {
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    if !(0.0..9.007_199_254_740_992e15).contains(&x) {
        return x.ln_1p();
    }
    let (k, f, c) = if x < std::f64::consts::SQRT_2 - 1.0 {
        (0.0, x, 0.0)
    } else {
        let u = 1.0 + x;
        // The part of `x` that `u` lost, over `u` (exact to first order: ln(u + d) = ln u +
        // d / u).
        let lost = if u < 2.0 {
            x - (u - 1.0)
        } else {
            1.0 - (u - x)
        };
        let bits = u.to_bits();
        let mut k = (bits >> 52) as i64 - 1023;
        let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
        if m >= std::f64::consts::SQRT_2 {
            m *= 0.5;
            k += 1;
        }
        (k as f64, m - 1.0, lost / u)
    };
    let s = f / (2.0 + f);
    let z = s * s;
    let [r1, r2, r3, r4, r5, r6, r7] = LN_1P_R;
    let r = z * (r1 + z * (r2 + z * (r3 + z * (r4 + z * (r5 + z * (r6 + z * r7))))));
    let hfsq = 0.5 * f * f;
    k * LN2_HI - ((hfsq - (s * (hfsq + r) + (k * LN2_LO + c))) - f)
}

/// The coefficients of `R(z)` in [`ln_1p`], `2 atanh(s) = 2s + s R(s^2)` approximately:
/// `R(z) = z (r1 + r2 z + ... + r7 z^6)`, minimax on `z` in `[0, 0.1716^2]` (fdlibm's `Lp1` to
/// `Lp7`; near `2/3, 2/5, 2/7, ...`, the series' own).
const LN_1P_R: [f64; 7] = [
    6.666_666_666_666_735e-1,
    3.999_999_999_940_942e-1,
    2.857_142_874_366_239e-1,
    2.222_219_843_214_978_4e-1,
    1.818_357_216_161_805e-1,
    1.531_383_769_920_937_3e-1,
    1.479_819_860_511_658_6e-1,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinh_squared_keeps_its_digits_on_both_sides_of_the_series_reach() {
        // Against the library's sinh (within an ulp), squared: a few ulps apart at most, on a
        // grid dense around SERIES_REACH, where the series is at its longest reach.
        let mut worst = 0.0f64;
        let ys = (1..=4000).map(|i| 3.0 * i as f64 / 4000.0);
        let near = (-50..=50).map(|i| SERIES_REACH + i as f64 * f64::EPSILON);
        for y in ys.chain(near).chain([1e-300, 1e-8, 1e-3, 0.3]) {
            let want = y.sinh().powi(2);
            for got in [
                sinh_sq(y),
                sinh_sq(-y),
                AnyReach::lanes([y, 0.1])[0],
                AnyReach::lanes([2.0, y, 0.3, 1.0])[1],
            ] {
                worst = worst.max(((got - want) / want).abs());
            }
        }
        assert!(
            worst <= 4.0 * f64::EPSILON,
            "worst {:.2} ulps",
            worst / f64::EPSILON
        );
    }

    #[test]
    fn ln_1p_is_the_librarys_within_an_ulp() {
        // Every octave from 1e-300 to 2^60, densely near the reduction's seams (sqrt(2) - 1,
        // where u reaches 2, powers of two times sqrt(2)), and random mantissas: within one
        // ulp of the library's correctly rounded-or-nearly result, and equal past 2^53.
        let mut x: f64 = 1e-300;
        let mut worst = 0.0f64;
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut check = |x: f64| {
            let (got, want) = (ln_1p(x), x.ln_1p());
            let ulp = f64::from_bits(want.to_bits() + 1) - want;
            worst = worst.max((got - want).abs() / ulp);
        };
        while x < 1.2e18 {
            for _ in 0..64 {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                let frac = (seed >> 11) as f64 / (1u64 << 53) as f64;
                check(x * (1.0 + frac));
            }
            x *= 2.0;
        }
        for seam in [
            std::f64::consts::SQRT_2 - 1.0,
            1.0,
            std::f64::consts::SQRT_2 * 2.0 - 1.0,
            std::f64::consts::SQRT_2 * 1024.0 - 1.0,
        ] {
            for i in -2000..=2000 {
                check(seam * (1.0 + i as f64 * f64::EPSILON));
            }
        }
        assert!(worst <= 1.0, "worst {worst} ulps");
        for x in [0.0, 9.007_199_254_740_992e15, 1e300, f64::INFINITY] {
            assert_eq!(ln_1p(x), x.ln_1p(), "{x}");
        }
        assert!(ln_1p(f64::NAN).is_nan() && ln_1p(-0.5) == (-0.5f64).ln_1p());
    }

    #[test]
    fn sinh_cosh_is_accurate_small_and_large() {
        for x in [1e-300, 1e-8, 0.3, 2.0, 30.0] {
            let (s, c) = sinh_cosh(x);
            assert!(((s - x.sinh()) / x.sinh()).abs() < 4e-16, "{x}");
            assert!(((c - x.cosh()) / x.cosh()).abs() < 4e-16, "{x}");
        }
    }
}
