//! Bracketed roots of a scalar function by the Illinois method (regula falsi with the stale
//! end's value halved), to adjacent floats: the one root finder of the integrator's events and
//! of the fast path's numerically found separations and edges.

/// A root of `f` in `[a, b]`, where `fa = f(a)` and `fb = f(b)` differ in sign (or one is
/// zero): the end of the final bracket on `b`'s side, so the value there has `fb`'s sign (or is
/// zero). Stops when the bracket is two ulps wide, `f` is exactly zero, or after 200 steps.
/// Errors of `f` are passed through.
pub fn illinois<E>(
    f: impl FnMut(f64) -> Result<f64, E>,
    a: (f64, f64),
    b: (f64, f64),
) -> Result<f64, E> {
    illinois_to(f, a, b, 0.0)
}

/// [`illinois`], stopping also once the bracket is at most `width` wide: an offset from a
/// later origin (an event's time within a step that starts at `t`) needs no more digits than
/// the sum `t + x` can hold.
pub fn illinois_to<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    width: f64,
) -> Result<f64, E> {
    let mut side = 0i8;
    for _ in 0..200 {
        let width = width.max(2.0 * f64::EPSILON * a.abs().max(b.abs()));
        if fb == 0.0 || (b - a).abs() <= width {
            break;
        }
        let mut x = (a * fb - b * fa) / (fb - fa);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !(x > lo && x < hi) {
            x = 0.5 * (a + b);
        }
        let fx = f(x)?;
        if changes_sign(fa, fx) {
            b = x;
            fb = fx;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = x;
            fa = fx;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    Ok(b)
}

/// Whether `b` is across zero from `a` (`a` nonzero).
pub fn changes_sign(a: f64, b: f64) -> bool {
    (a > 0.0 && b <= 0.0) || (a < 0.0 && b >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_root_of_a_cubic_to_adjacent_floats() {
        let f = |x: f64| Ok::<f64, ()>(x * x * x - 2.0);
        let r = illinois(f, (0.0, -2.0), (2.0, 6.0)).unwrap();
        let want = 2f64.cbrt();
        assert!(
            (r - want).abs() <= 2.0 * f64::EPSILON * want,
            "{r} vs {want}"
        );
    }

    #[test]
    fn passes_errors_through() {
        let f = |_: f64| Err::<f64, &str>("broken");
        assert_eq!(illinois(f, (0.0, -1.0), (1.0, 1.0)), Err("broken"));
    }
}
