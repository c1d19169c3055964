//! Exact sensitivities of a fast phase's separation: `d theta_sep/dp` and `d t_sep/dp` for
//! every parameter, from the generated partial derivatives (`Partials::separation_partials`,
//! `start_partials`, `fall_partials`).
//!
//! The angle follows from the implicit-function theorem on the separation condition
//! `F(theta, p) = 0`: `d theta_sep/dp = -F_p / F_theta`.
//!
//! The time is the quadrature's own integral in the variable `v` of the substitution
//! `sin(theta) = s_i - e sinh^2 v` (`e = 1 - s_i`, `s_i = sin theta_i`), for a phase from rest
//! with a fall polynomial `P`: `t = integral_0^v_sep g(v, p) dv`, `g = 2 sqrt(P(s) / (1 + s))`.
//! The substitution maps the release angle to `v = 0` whatever the parameters, so a parameter
//! that moves the release angle moves no lower limit, and `g` stays smooth there (the
//! `1/sqrt` singularity of `1/theta_dot` is gone). Differentiating under the integral:
//! `d t/dp = g(v_sep) dv_sep/dp + integral_0^v_sep dg/dp|_v dv` with, at fixed `v`,
//! `ds/dp = (ds_i/dp) cosh^2 v` and
//! `dg/dp = sqrt(P / (1 + s)) [(P_p(s) + P'(s) ds/dp) / P - (ds/dp) / (1 + s)]`, which has the
//! singularities of `g` itself (the zeros of `P`, `s = -1`): the integral takes the same
//! a-priori rule as the time ([`prior_panels`]) or, where that rule does not apply, Gauss–Legendre
//! panels halved until two rules agree. The upper limit moves with
//! `sinh^2 v_sep = (s_i - s_sep) / e`:
//! `2 sinh cosh dv_sep/dp = ((ds_i/dp)(1 - s_sep) - (ds_sep/dp) e) / e^2`,
//! `ds_sep/dp = cos(theta_sep) d theta_sep/dp`.

use crate::model::Reduction;
use crate::results::SensitivityGap;
use crate::solve::SolveError;
use crate::solve::fast::poly::horner;
use crate::solve::fast::prior::{Prior, Singularities, prior_panels};
use crate::solve::fast::quadrature::{HalfRule, MAX_PANELS, half_rule, v_at_drop};

/// The separation of one fast phase from rest, as the solvers found it.
#[derive(Clone, Copy)]
pub struct SeparationPoint<'a> {
    /// Its fast path.
    pub red: &'a dyn Reduction,
    /// Its constants, at the model's length, the parameters first (the partial derivatives
    /// read nothing else).
    pub k: &'a [f64],
    /// How many parameters.
    pub parameters: usize,
    /// `sin(theta_i)`.
    pub sin_initial: f64,
    /// `e = 1 - sin(theta_i)`, formed without cancellation near upright
    /// (`cos^2 theta_i / (1 + sin theta_i)`), the scale of the substitution.
    pub scale: f64,
    /// The time integrand's singularities where the caller has them (else found here).
    pub singularities: Option<Singularities>,
    /// The fall polynomial's coefficients, lowest degree first (empty without one).
    pub fall: &'a [f64],
    /// `sin(theta_sep)`.
    pub sin_sep: f64,
    /// `sin(theta_i) - sin(theta_sep) >= 0`, formed without cancellation by the solver.
    pub drop: f64,
}

/// Basis integrals the a-priori route keeps on the stack (a fall polynomial of degree 2 and the
/// start's).
const PRIOR_BASIS: usize = 4;

/// Buffers of [`separation`], kept across points.
#[derive(Debug, Clone, Default)]
pub struct SensitivityWork {
    partials: Vec<f64>,
    start: Vec<f64>,
    fall: Vec<f64>,
    panel: Vec<f64>,
    coarse: Vec<f64>,
    fine: Vec<f64>,
    magnitude: Vec<f64>,
    stack: Vec<(f64, f64)>,
}

/// `d theta_sep/dp` into `angle` and `d t_sep/dp` into `time` (each one entry per parameter),
/// or why they do not exist. `prior` is the a-priori rule to use where it applies; `tol` the
/// relative agreement asked of two rules elsewhere.
pub fn separation(
    at: &SeparationPoint,
    prior: &Prior,
    tol: f64,
    work: &mut SensitivityWork,
    angle: &mut [f64],
    time: &mut [f64],
) -> Result<Result<(), SensitivityGap>, SolveError> {
    let np = at.parameters;
    let Some(partials) = at.red.partials() else {
        return Ok(Err(SensitivityGap::NoPartials));
    };
    if at.drop <= 0.0 {
        return Ok(Err(SensitivityGap::AtRelease));
    }
    work.partials.resize(np + 1, f64::NAN);
    let cos_sep = ((1.0 - at.sin_sep) * (1.0 + at.sin_sep)).sqrt();
    partials.separation_partials(at.k, at.sin_sep, cos_sep, &mut work.partials);
    let f_theta = work.partials[0];
    if f_theta.is_nan() {
        return Ok(Err(SensitivityGap::NoPartials));
    }
    if f_theta == 0.0 || !f_theta.is_finite() {
        return Ok(Err(SensitivityGap::DoubleRoot));
    }
    for (a, f_p) in angle.iter_mut().zip(&work.partials[1..]) {
        // `+ 0.0` writes a parameter the angle does not depend on as 0, not -0.
        *a = -f_p / f_theta + 0.0;
    }
    if at.fall.is_empty() {
        return Ok(Err(SensitivityGap::NoFallPolynomial));
    }
    let degree = at.fall.len();
    work.start.resize(np, 0.0);
    work.fall.resize(np * degree, 0.0);
    partials.start_partials(at.k, &mut work.start);
    partials.fall_partials(at.k, &mut work.fall);
    let e = at.scale;
    let v_sep = v_at_drop(e, at.drop);
    // The moving upper limit (`sinh^2 v_sep = drop / e` exactly, no transcendental call).
    let sh2 = at.drop / e;
    let (sh, ch) = (sh2.sqrt(), (1.0 + sh2).sqrt());
    let g_sep = 2.0 * (horner(at.fall, at.sin_sep) / (1.0 + at.sin_sep)).sqrt();
    let one_minus_sep = e + at.drop;
    for i in 0..np {
        let ds_sep = cos_sep * angle[i];
        let dv = (work.start[i] * one_minus_sep - ds_sep * e) / (e * e * 2.0 * sh * ch);
        time[i] = g_sep * dv;
    }
    integral(at, e, v_sep, prior, tol, work)?;
    // Each parameter's integral from the basis integrals (`work.panel`).
    let (basis, start) = (&work.panel, &work.start);
    for (i, t) in time.iter_mut().enumerate() {
        let fall = &work.fall[i * degree..(i + 1) * degree];
        let from_fall: f64 = fall.iter().zip(basis).map(|(d, b)| d * b).sum();
        *t += from_fall + start[i] * basis[degree];
    }
    Ok(Ok(()))
}

/// `P(s)` and `P'(s)`.
fn horner_d(c: &[f64], s: f64) -> (f64, f64) {
    c.iter()
        .rev()
        .fold((0.0, 0.0), |(p, d), &x| (p * s + x, d * s + p))
}

/// The values one node shares between the parameters.
struct Node {
    s: f64,
    ch2: f64,
    p: f64,
    dp: f64,
    one_plus: f64,
    /// The weight times `sqrt(P / (1 + s))`.
    weight: f64,
}

/// The node at `v` with weight `w`.
fn node_at(at: &SeparationPoint, e: f64, v: f64, w: f64) -> Node {
    // `sinh v` from one exponential: its absolute error (an ulp of `cosh v`) moves `s` by an
    // ulp of `e sinh v`, far below what the integrand notices.
    let x = v.exp();
    let sh = 0.5 * (x - 1.0 / x);
    let sh2 = sh * sh;
    let s = at.sin_initial - e * sh2;
    let one_plus = (1.0 + at.sin_initial) - e * sh2;
    let (p, dp) = horner_d(at.fall, s);
    Node {
        s,
        ch2: 1.0 + sh2,
        p,
        dp,
        one_plus,
        weight: w * (p / one_plus).sqrt(),
    }
}

/// The basis integrands at one node, weighted, into `acc` (and `|.|` into `mag`): with
/// `root = sqrt(P / (1 + s))`, `root s^j / P` for each power `j` of the fall polynomial and
/// `root cosh^2 v (P'/P - 1/(1 + s))`. `dg/dp_i` is `sum_j (dP_j/dp_i) b_j + (ds_i/dp_i) b_last`:
/// linear in the partial derivatives, so the nodes pay for the polynomial's degree, not for
/// the number of parameters.
fn accumulate(node: &Node, acc: &mut [f64], mag: Option<&mut [f64]>) {
    let inv_p = 1.0 / node.p;
    let last = acc.len() - 1;
    let start = node.weight * node.ch2 * (node.dp * inv_p - 1.0 / node.one_plus);
    let mut b = node.weight * inv_p;
    match mag {
        None => {
            for x in &mut acc[..last] {
                *x += b;
                b *= node.s;
            }
        }
        Some(mag) => {
            for (x, m) in acc[..last].iter_mut().zip(mag[..last].iter_mut()) {
                *x += b;
                *m += b.abs();
                b *= node.s;
            }
            mag[last] += start.abs();
        }
    }
    acc[last] += start;
}

/// `sum_nodes w b_j` of the basis integrands on the panel `[a, b]` (symmetric about 0 where
/// `a == 0`: the integrand is even in `v`), scaled by the panel's half-length, added into
/// `acc` (and their `|.|` into `mag` where given), both zero on entry.
fn panel(
    at: &SeparationPoint,
    e: f64,
    rule: &HalfRule,
    (a, b): (f64, f64),
    acc: &mut [f64],
    mut mag: Option<&mut [f64]>,
) -> u64 {
    let mut evals = 0;
    let mut node = |v: f64, w: f64, acc: &mut [f64], mag: &mut Option<&mut [f64]>| {
        accumulate(&node_at(at, e, v, w), acc, mag.as_deref_mut());
        evals += 1;
    };
    let scale = if a == 0.0 {
        if rule.centre != 0.0 {
            node(0.0, 0.5 * rule.centre, acc, &mut mag);
        }
        for &(x, w) in &rule.pairs {
            node(b * x, w, acc, &mut mag);
        }
        b
    } else {
        let (half, mid) = (0.5 * (b - a), 0.5 * (a + b));
        if rule.centre != 0.0 {
            node(mid, rule.centre, acc, &mut mag);
        }
        for &(x, w) in &rule.pairs {
            node(mid + half * x, w, acc, &mut mag);
            node(mid - half * x, w, acc, &mut mag);
        }
        half
    };
    acc.iter_mut().for_each(|x| *x *= scale);
    if let Some(m) = mag {
        m.iter_mut().for_each(|x| *x *= scale);
    }
    evals
}

/// The basis integrals of [`accumulate`] over `[0, v_sep]` into `work.panel`: the a-priori
/// rule's panels where it applies, else panels halved until a 16- and a 24-node rule agree to
/// `tol` of the integral of each basis integrand's `|.|` (so that one the time barely depends on
/// asks no impossible digits).
fn integral(
    at: &SeparationPoint,
    e: f64,
    v_sep: f64,
    prior: &Prior,
    tol: f64,
    work: &mut SensitivityWork,
) -> Result<(), SolveError> {
    // The basis integrals: one per coefficient of the fall polynomial, one for the start.
    let np = at.fall.len() + 1;
    let SensitivityWork {
        panel: total,
        coarse,
        fine,
        magnitude,
        stack,
        ..
    } = work;
    total.clear();
    total.resize(np, 0.0);
    coarse.resize(np, 0.0);
    magnitude.resize(np, 0.0);
    let sing = match at.singularities {
        Some(sing) => Some(sing),
        None => Singularities::of(at.sin_initial, e, at.fall),
    };
    // The a-priori rule takes fall polynomials of degree at most 2: at most four basis
    // integrals, kept on the stack.
    if let Some(sing) = sing.filter(|_| np <= PRIOR_BASIS) {
        let mut sum = [0.0; PRIOR_BASIS];
        let done = prior_panels(&sing, v_sep, prior, |rule, a, b| {
            let mut acc = [0.0; PRIOR_BASIS];
            let n = panel(at, e, rule, (a, b), &mut acc[..np], None);
            for (t, x) in sum.iter_mut().zip(acc) {
                *t += x;
            }
            Ok::<_, SolveError>((0.0, n))
        })?;
        if done.is_some() {
            total.copy_from_slice(&sum[..np]);
            return Ok(());
        }
    }
    let (low, high) = (half_rule(16), half_rule(24));
    fine.resize(np, 0.0);
    stack.clear();
    stack.push((0.0, v_sep));
    let mut panels = 0;
    while let Some((a, b)) = stack.pop() {
        coarse.fill(0.0);
        fine.fill(0.0);
        magnitude.fill(0.0);
        panel(at, e, low, (a, b), coarse, None);
        panel(at, e, high, (a, b), fine, Some(magnitude));
        panels += 1;
        let agree = (fine.iter().zip(coarse.iter()).zip(magnitude.iter()))
            .all(|((f, c), m)| (f - c).abs() <= tol * m);
        if agree {
            for (t, f) in total.iter_mut().zip(fine.iter()) {
                *t += f;
            }
            continue;
        }
        let mid = 0.5 * (a + b);
        if !(mid > a && mid < b) || panels + stack.len() > MAX_PANELS {
            return Err(SolveError::QuadratureNotConverged {
                a: 0.0,
                b: v_sep,
                tol,
                estimate: total.iter().sum(),
                error: (fine.iter().zip(coarse.iter()))
                    .map(|(f, c)| (f - c).abs())
                    .fold(0.0, f64::max),
                panels,
            });
        }
        stack.push((mid, b));
        stack.push((a, mid));
    }
    Ok(())
}
