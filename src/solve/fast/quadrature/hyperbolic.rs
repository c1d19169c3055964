//! `sinh^2`, `sinh` and `cosh` at the quadrature's nodes, to a few ulps and without a
//! library call where a series serves: [`sinh_sq`] one node at a time, [`SinhSq`] several in
//! the same arithmetic (the lanes of a vector register), [`sinh_cosh`] both from one `exp_m1`.

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
    fn sinh_cosh_is_accurate_small_and_large() {
        for x in [1e-300, 1e-8, 0.3, 2.0, 30.0] {
            let (s, c) = sinh_cosh(x);
            assert!(((s - x.sinh()) / x.sinh()).abs() < 4e-16, "{x}");
            assert!(((c - x.cosh()) / x.cosh()).abs() < 4e-16, "{x}");
        }
    }
}
