//! Small dense linear systems solved in place by Gaussian elimination with partial pivoting:
//! the contact systems of every right-hand side and every impact, without allocating.
//!
//! Matrices are row-major slices of `dim * dim` values. The pivot of each column is its entry
//! of largest magnitude on or below the diagonal (the first of equal ones), as in LAPACK's
//! `getrf`; a column with no non-zero entry there makes the matrix singular.

/// A matrix with a column of zeros on and below the diagonal after elimination: no unique
/// solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singular;

/// Eliminates below the diagonal of `a` and applies the same row operations to `b`, leaving
/// the upper triangle. Returns the determinant of `a` (zero when singular,
/// where it stops).
///
/// The sizes of contact systems (a few coordinates and rows) each get their own compiled copy
/// of [`eliminate_dim`], with the size a constant the loops are unrolled for.
fn eliminate(a: &mut [f64], dim: usize, b: &mut [f64]) -> f64 {
    match dim {
        1 => eliminate_dim(a, 1, b),
        2 => eliminate_dim(a, 2, b),
        3 => eliminate_dim(a, 3, b),
        4 => eliminate_dim(a, 4, b),
        5 => eliminate_dim(a, 5, b),
        6 => eliminate_dim(a, 6, b),
        7 => eliminate_dim(a, 7, b),
        8 => eliminate_dim(a, 8, b),
        _ => eliminate_dim(a, dim, b),
    }
}

/// [`eliminate`] for one size.
#[inline(always)]
fn eliminate_dim(a: &mut [f64], dim: usize, b: &mut [f64]) -> f64 {
    // Lengths the compiler knows for a constant `dim`, so that it can drop the index checks.
    let (Some(a), Some(b)) = (a.get_mut(..dim * dim), b.get_mut(..dim)) else {
        return 0.0;
    };
    let mut det = 1.0;
    for k in 0..dim {
        let mut p = k;
        for i in k + 1..dim {
            if a[i * dim + k].abs() > a[p * dim + k].abs() {
                p = i;
            }
        }
        let pivot = a[p * dim + k];
        if pivot == 0.0 {
            return 0.0;
        }
        if p != k {
            // Only the columns from `k` on are read again (the upper triangle and the columns
            // still to eliminate).
            let (top, bottom) = a.split_at_mut(p * dim);
            top[k * dim + k..(k + 1) * dim].swap_with_slice(&mut bottom[k..dim]);
            b.swap(k, p);
            det = -det;
        }
        det *= pivot;
        let (upper, lower) = a.split_at_mut((k + 1) * dim);
        let pivot_row = &upper[k * dim + k + 1..(k + 1) * dim];
        for (r, row) in lower.chunks_exact_mut(dim).enumerate() {
            let factor = row[k] / pivot;
            if factor == 0.0 {
                continue;
            }
            for (x, p) in row[k + 1..].iter_mut().zip(pivot_row) {
                *x -= factor * p;
            }
            b[k + 1 + r] -= factor * b[k];
        }
    }
    det
}

/// Solves `a x = b` for `x`, written over `b`; `a` (row-major, `dim * dim`) is overwritten by
/// its elimination. Returns the determinant of `a`, or [`Singular`] when it is zero (an
/// exactly zero pivot column; a nearly singular system gives large or non-finite values, which
/// the caller checks).
pub fn solve_in_place(a: &mut [f64], dim: usize, b: &mut [f64]) -> Result<f64, Singular> {
    if a.len() != dim * dim || b.len() != dim {
        return Err(Singular);
    }
    let det = eliminate(a, dim, b);
    if det == 0.0 {
        return Err(Singular);
    }
    // Back substitution by columns: each unknown, once found, is taken out of the rows above.
    for k in (0..dim).rev() {
        b[k] /= a[k * dim + k];
        let x = b[k];
        for i in 0..k {
            b[i] -= a[i * dim + k] * x;
        }
    }
    Ok(det)
}

/// The determinant of `a` (row-major, `dim * dim`; zero when singular or of the wrong
/// length), which is overwritten by its elimination.
pub fn determinant_in_place(a: &mut [f64], dim: usize) -> f64 {
    if a.len() != dim * dim {
        return 0.0;
    }
    eliminate(a, dim, &mut vec![0.0; dim])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        // The first pivot is zero: the rows must be exchanged.
        let mut a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 2.0, 0.0, 3.0];
        let x = [1.0, -2.0, 0.5];
        let mut b = [2.0 * x[1] + x[2], x[0] + x[1], 2.0 * x[0] + 3.0 * x[2]];
        let det = solve_in_place(&mut a, 3, &mut b).expect("regular");
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-15, "{got} vs {want}");
        }
        // det = 0(3 - 0) - 2(3 - 0) + 1(0 - 2) = -8.
        assert!((det + 8.0).abs() < 1e-14, "{det}");
    }

    #[test]
    fn a_singular_system_is_refused_and_its_determinant_is_zero() {
        let mut a = [1.0, 2.0, 2.0, 4.0];
        let mut b = [1.0, 2.0];
        assert_eq!(solve_in_place(&mut a, 2, &mut b), Err(Singular));
        let mut a = [1.0, 2.0, 2.0, 4.0];
        assert_eq!(determinant_in_place(&mut a, 2), 0.0);
        let mut a = [1.0, 2.0, 3.0];
        assert_eq!(solve_in_place(&mut a, 2, &mut b), Err(Singular));
    }
}
