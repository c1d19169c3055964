//! High-precision reference values of the separation angle and time, computed with
//! arbitrary-precision arithmetic (astro-float) from the closed forms of PHYSICS.md, sharing no
//! code with the generated models or the `f64` solvers they are used to judge.
//!
//! # The closed forms
//! The three contact models released from rest all reduce to one family with `r = a/ell`,
//! `s = sin(theta)`, `theta_0 = asin(r)` and a model constant `mu`:
//! - energy integral `theta_dot^2 = 3 (g/ell) (r - s) / (1 + mu s^2)`;
//! - separation where `mu s^3 + 3 s - 2 r = 0`, the root in `(0, r)`.
//!
//! | model | `mu` | separation polynomial |
//! |---|---|---|
//! | `rod_cube` | `-3 / (4 (1 + n))` | `3 s^3 - 12 (1+n) s + 8 r (1+n)` (eq. 14), energy eq. (9) |
//! | `hinged_rod` | `3 n` | `3 n s^3 + 3 s - 2 r` (PHYSICS.md erratum 5) |
//! | `wall_ladder` | `0` | `3 s - 2 r`, i.e. `sin(theta_sep) = 2r/3` |
//!
//! with `n = m2/m1`. For the rod on the cube `4/D = 3/(1 - 3 s^2/(4(1+n)))`, which is eq. (9).
//! For the hinged rod, `T = (ell^2/2)(m1/3 + m2 s^2) theta_dot^2` and `V = m1 g (ell/2) s` give
//! the energy integral; the cube's push `m2 d^2(ell cos theta)/dt^2` vanishes where
//! `theta_dot^2 + (s/2) d(theta_dot^2)/ds = 0`, which is the cubic. The same condition with the
//! rod-cube energy integral gives eq. (14), so one formula covers the family.
//!
//! # Two routes for each quantity
//! - Separation root: the closed form (Viete's trigonometric solution for `mu < 0`,
//!   `s = (2/sqrt(nu)) sin(asin(r sqrt(nu))/3)` with `nu = -mu`; its hyperbolic twin
//!   `s = (2/sqrt(mu)) sinh(asinh(r sqrt(mu))/3)` for `mu > 0`; `2r/3` for `mu = 0`), or
//!   Newton's method on the cubic from `s = 2r/3`. Neither form cancels at any `n`.
//! - Separation time `t = integral_0^delta_sep d(delta) / |theta_dot|` with
//!   `delta = theta_0 - theta`. The root `r - s` is written without cancellation as
//!   `2 sin(delta/2) sin(beta + delta/2)`, `beta = pi/2 - theta_0`: its two factors are the
//!   `1/sqrt` singularity at the start and, near upright (`beta -> 0`), a second one at
//!   `delta = -2 beta` just outside the interval that makes `t` grow like `log(1/beta)`.
//!   - Route [`TimeRoute::TanhSinh`]: double-exponential quadrature directly in `delta`, the
//!     distance to the singular endpoint taken from the transformation itself, never by
//!     subtraction; levels are halved until two agree.
//!   - Route [`TimeRoute::SinhGauss`]: the substitution `delta/2 = beta sinh^2(v)`, under which
//!     `d(delta) / sqrt(sin(delta/2) sin(beta + delta/2))` is `2 sqrt(2) dv` times a smooth
//!     factor: both singular factors are removed exactly, and adaptive Gauss–Legendre (nodes
//!     computed here in high precision) integrates the rest.
//!
//! Inputs are the `f64` parameters taken as exact; everything after is carried at
//! [`PRECISION`] bits, and `r = a/ell` and `n = m2/m1` are formed in that precision.

use astro_float::{BigFloat, Consts, RoundingMode};

/// Working precision in bits (about 77 decimal digits).
pub const PRECISION: usize = 256;

/// Relative tolerance of the high-precision quadratures (far above the working precision).
pub const TOLERANCE: f64 = 1e-40;

/// Gauss–Legendre nodes per panel of route [`TimeRoute::SinhGauss`].
const GL_NODES: usize = 24;

/// Most levels of the tanh–sinh rule (the step is `2^-level`).
const MAX_LEVEL: u32 = 11;

/// The end of the tanh–sinh range in the transformed variable; beyond it the weights are
/// below `1e-60` of the integral.
const TANH_SINH_RANGE: f64 = 5.2;

/// Most panels of the adaptive Gauss–Legendre route.
const MAX_PANELS: usize = 4000;

const RM: RoundingMode = RoundingMode::ToEven;

/// Why a reference could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// The model is not one of the contact models with a closed form here.
    #[error(
        "no closed-form reference for model `{0}` (references exist for rod_cube, hinged_rod, wall_ladder)"
    )]
    Unsupported(String),
    /// A parameter was missing, not finite or not positive.
    #[error("reference: parameter `{name}` is {value}; it must be a positive finite number")]
    BadParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value (NaN when missing).
        value: f64,
    },
    /// `a >= ell`: the rod does not lean.
    #[error("reference: a/ell = {r} is not below 1, so the rod does not lean and never falls")]
    NotLeaning {
        /// `a/ell`.
        r: f64,
    },
    /// A quadrature or root iteration did not converge.
    #[error("reference: {what} did not converge (last change {change:e})")]
    NotConverged {
        /// Which computation.
        what: &'static str,
        /// Its last relative change.
        change: f64,
    },
    /// A parameter index past `[m1, m2, ell, a, g]`.
    #[error("reference: no parameter {index} (there are five: m1, m2, ell, a, g)")]
    NoParameter {
        /// The index asked.
        index: usize,
    },
    /// The asked angle lies outside the phase.
    #[error("reference: delta = {delta:e} is outside [0, {end:e}]")]
    Outside {
        /// The angle fallen asked.
        delta: f64,
        /// The end of the phase.
        end: f64,
    },
}

/// The family member: which closed form applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// The rod leaning on a free cube (the paper's system).
    RodCube,
    /// The rod hinged at its foot, leaning on a free cube.
    HingedRod,
    /// The ladder on a fixed wall (the `n -> infinity` limit of both).
    WallLadder,
}

impl Family {
    /// The family of a model by its registry name.
    pub fn of(model: &str) -> Option<Family> {
        match model {
            "rod_cube" => Some(Family::RodCube),
            "hinged_rod" => Some(Family::HingedRod),
            "wall_ladder" => Some(Family::WallLadder),
            _ => None,
        }
    }

    /// The registry name.
    pub fn name(self) -> &'static str {
        match self {
            Family::RodCube => "rod_cube",
            Family::HingedRod => "hinged_rod",
            Family::WallLadder => "wall_ladder",
        }
    }
}

/// Route to the separation root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootRoute {
    /// Viete's trigonometric (or hyperbolic) solution of the cubic.
    ClosedForm,
    /// Newton's method on the cubic.
    Newton,
}

/// Route to the separation time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeRoute {
    /// Tanh–sinh quadrature in `delta` with the endpoint distance taken from the transformation.
    TanhSinh,
    /// The substitution `delta/2 = beta sinh^2 v` and adaptive Gauss–Legendre in `v`.
    SinhGauss,
}

/// The exact inputs of one case (SI units; `m2` is ignored by the wall ladder).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    /// Which model.
    pub family: Family,
    /// Mass of the rod (kg).
    pub m1: f64,
    /// Mass of the cube (kg).
    pub m2: f64,
    /// Length of the rod (m).
    pub ell: f64,
    /// Height of the contact (side of the cube) (m).
    pub a: f64,
    /// Gravitational acceleration (m/s^2).
    pub g: f64,
}

impl Inputs {
    /// Inputs from a model name and its named parameters.
    pub fn from_named(model: &str, params: &[(&str, f64)]) -> Result<Inputs, ReferenceError> {
        let family =
            Family::of(model).ok_or_else(|| ReferenceError::Unsupported(model.to_string()))?;
        let get = |name: &'static str| params.iter().find(|(k, _)| *k == name).map(|(_, v)| *v);
        let need = |name: &'static str| {
            get(name).ok_or(ReferenceError::BadParameter {
                name,
                value: f64::NAN,
            })
        };
        let m2 = match family {
            Family::WallLadder => 1.0,
            _ => need("m2")?,
        };
        Ok(Inputs {
            family,
            m1: need("m1")?,
            m2,
            ell: need("ell")?,
            a: need("a")?,
            g: need("g")?,
        })
    }

    /// The dimensionless case `m1 = 1`, `m2 = n`, `ell = g = 1`, `a = a_over_ell`.
    pub fn dimensionless(family: Family, n: f64, a_over_ell: f64) -> Inputs {
        Inputs {
            family,
            m1: 1.0,
            m2: n,
            ell: 1.0,
            a: a_over_ell,
            g: 1.0,
        }
    }
}

/// Reference separation of one case, each value also rounded to `f64`.
#[derive(Debug, Clone)]
pub struct SeparationReference {
    /// `sin(theta_sep)`.
    pub sin_theta: BigFloat,
    /// `theta_sep` (rad).
    pub theta: BigFloat,
    /// `theta_sep` rounded to `f64`.
    pub theta_f64: f64,
    /// `delta_sep = theta_0 - theta_sep` (rad).
    pub delta: BigFloat,
}

/// Small arithmetic helpers at a fixed precision.
struct Hp {
    p: usize,
    cc: Consts,
}

impl Hp {
    fn new(p: usize) -> Hp {
        Hp {
            p,
            cc: Consts::new().expect("astro-float constants cache"),
        }
    }
    fn c(&self, x: f64) -> BigFloat {
        BigFloat::from_f64(x, self.p)
    }
    fn add(&self, a: &BigFloat, b: &BigFloat) -> BigFloat {
        a.add(b, self.p, RM)
    }
    fn sub(&self, a: &BigFloat, b: &BigFloat) -> BigFloat {
        a.sub(b, self.p, RM)
    }
    fn mul(&self, a: &BigFloat, b: &BigFloat) -> BigFloat {
        a.mul(b, self.p, RM)
    }
    fn div(&self, a: &BigFloat, b: &BigFloat) -> BigFloat {
        a.div(b, self.p, RM)
    }
    fn sqrt(&self, a: &BigFloat) -> BigFloat {
        a.sqrt(self.p, RM)
    }
    fn sin(&mut self, a: &BigFloat) -> BigFloat {
        a.sin(self.p, RM, &mut self.cc)
    }
    fn asin(&mut self, a: &BigFloat) -> BigFloat {
        a.asin(self.p, RM, &mut self.cc)
    }
    fn sinh(&mut self, a: &BigFloat) -> BigFloat {
        a.sinh(self.p, RM, &mut self.cc)
    }
    fn cosh(&mut self, a: &BigFloat) -> BigFloat {
        a.cosh(self.p, RM, &mut self.cc)
    }
    fn asinh(&mut self, a: &BigFloat) -> BigFloat {
        a.asinh(self.p, RM, &mut self.cc)
    }
    fn exp(&mut self, a: &BigFloat) -> BigFloat {
        a.exp(self.p, RM, &mut self.cc)
    }
    fn pi(&mut self) -> BigFloat {
        self.cc.pi(self.p, RM)
    }
}

/// A value rounded to the nearest `f64` (ties aside; NaN for a NaN or infinity).
pub fn to_f64(x: &BigFloat) -> f64 {
    if x.is_zero() {
        return 0.0;
    }
    let Some((words, _, sign, exponent, _)) = x.as_raw_parts() else {
        return f64::NAN;
    };
    let Some(&top) = words.last() else {
        return f64::NAN;
    };
    // The value is 0.m * 2^exponent with the mantissa's leading bit at the top of `top`.
    let mut v = top as f64;
    let mut e = exponent as i64 - 64;
    while e > 0 {
        let k = e.min(1000);
        v *= 2f64.powi(k as i32);
        e -= k;
    }
    while e < 0 {
        let k = (-e).min(1000);
        v *= 2f64.powi(-(k as i32));
        e += k;
    }
    if sign == astro_float::Sign::Neg {
        -v
    } else {
        v
    }
}

/// `(x - reference) / reference` evaluated in high precision, then rounded to `f64`.
pub fn relative_error(x: f64, reference: &BigFloat) -> f64 {
    let p = PRECISION;
    let diff = BigFloat::from_f64(x, p).sub(reference, p, RM);
    to_f64(&diff.div(reference, p, RM))
}

/// `|a - b| / |b|` of two high-precision values, rounded to `f64`.
pub fn relative_difference(a: &BigFloat, b: &BigFloat) -> f64 {
    let p = PRECISION;
    to_f64(&a.sub(b, p, RM).div(b, p, RM)).abs()
}

/// The parameters' names in the order of [`Reference::with_exact`]'s `[m1, m2, ell, a, g]`.
pub const PARAMETERS: [&str; 5] = ["m1", "m2", "ell", "a", "g"];

/// The relative step of [`derivatives`]: `2^-70`, so that at [`PRECISION`] bits the central
/// difference's truncation is near `1e-42` and its rounding near `1e-56`.
pub const DIFFERENCE_STEP: f64 = 1.0 / (1u128 << 70) as f64;

/// `(d theta_sep/dp, d t_sep/dp)` of a case in its parameter `j` (of [`PARAMETERS`]): central
/// differences of the reference (the closed-form root, the sinh route's time) with the step
/// [`DIFFERENCE_STEP`] relative, taken at [`PRECISION`] bits, so that the difference is exact
/// to far below an `f64` ulp. An independent check of the generated partial derivatives.
pub fn derivatives(inputs: Inputs, j: usize) -> Result<(f64, f64), ReferenceError> {
    let p = PRECISION;
    let values = [inputs.m1, inputs.m2, inputs.ell, inputs.a, inputs.g];
    let x = values
        .get(j)
        .map(|&v| BigFloat::from_f64(v, p))
        .ok_or(ReferenceError::NoParameter { index: j })?;
    let h = x.mul(&BigFloat::from_f64(DIFFERENCE_STEP, p), p, RM);
    let at = |sign: f64| -> Result<(BigFloat, BigFloat), ReferenceError> {
        let mut exact = values.map(|v| BigFloat::from_f64(v, p));
        exact[j] = x.add(&h.mul(&BigFloat::from_f64(sign, p), p, RM), p, RM);
        let mut r = Reference::with_exact(inputs, exact)?;
        let theta = r.separation(RootRoute::ClosedForm)?.theta;
        Ok((theta, r.separation_time(TimeRoute::SinhGauss)?))
    };
    let (theta_plus, t_plus) = at(1.0)?;
    let (theta_minus, t_minus) = at(-1.0)?;
    let two_h = h.mul(&BigFloat::from_f64(2.0, p), p, RM);
    let d = |a: &BigFloat, b: &BigFloat| to_f64(&a.sub(b, p, RM).div(&two_h, p, RM));
    Ok((d(&theta_plus, &theta_minus), d(&t_plus, &t_minus)))
}

/// The error of a derivative `x` against its `reference`, relative to `|reference|`; a
/// derivative that is (nearly) zero is compared at `1e-3` of `scale`, the size of its
/// quantity per its parameter (`theta_sep / p`), rather than at its own size.
pub fn derivative_error(x: f64, reference: f64, scale: f64) -> f64 {
    (x - reference).abs() / reference.abs().max(1e-3 * scale.abs())
}

/// The reference solver for one case.
pub struct Reference {
    hp: Hp,
    inputs: Inputs,
    r: BigFloat,
    mu: BigFloat,
    /// `3 g / ell`.
    kappa: BigFloat,
    theta0: BigFloat,
    beta: BigFloat,
    gl: Vec<(BigFloat, BigFloat)>,
}

impl std::fmt::Debug for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reference")
            .field("inputs", &self.inputs)
            .finish()
    }
}

impl Reference {
    /// Prepares a case: checks the inputs and forms `r`, `n`, `mu`, `theta_0` and `beta` in high
    /// precision.
    pub fn new(inputs: Inputs) -> Result<Reference, ReferenceError> {
        let exact = [inputs.m1, inputs.m2, inputs.ell, inputs.a, inputs.g]
            .map(|x| BigFloat::from_f64(x, PRECISION));
        Reference::with_exact(inputs, exact)
    }

    /// A case whose parameters `[m1, m2, ell, a, g]` are given at [`PRECISION`] bits (so that a
    /// difference can take a step far below an `f64` ulp); `inputs` holds them rounded to
    /// `f64`, which are checked as [`Reference::new`] checks them.
    pub fn with_exact(inputs: Inputs, exact: [BigFloat; 5]) -> Result<Reference, ReferenceError> {
        for (name, value) in [
            ("m1", inputs.m1),
            ("m2", inputs.m2),
            ("ell", inputs.ell),
            ("a", inputs.a),
            ("g", inputs.g),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ReferenceError::BadParameter { name, value });
            }
        }
        if inputs.a >= inputs.ell {
            return Err(ReferenceError::NotLeaning {
                r: inputs.a / inputs.ell,
            });
        }
        Reference::build(Hp::new(PRECISION), inputs, exact)
    }

    /// Forms `r`, `n`, `mu`, `theta_0` and `beta` from the exact parameters.
    fn build(
        mut hp: Hp,
        inputs: Inputs,
        exact: [BigFloat; 5],
    ) -> Result<Reference, ReferenceError> {
        let [m1, m2, ell, a, g] = exact;
        let r = hp.div(&a, &ell);
        let n = hp.div(&m2, &m1);
        let one = hp.c(1.0);
        let mu = match inputs.family {
            Family::RodCube => hp.div(&hp.c(-3.0), &hp.mul(&hp.c(4.0), &hp.add(&one, &n))),
            Family::HingedRod => hp.mul(&hp.c(3.0), &n),
            Family::WallLadder => hp.c(0.0),
        };
        let kappa = hp.div(&hp.mul(&hp.c(3.0), &g), &ell);
        let pi = hp.pi();
        let half_pi = hp.div(&pi, &hp.c(2.0));
        // Far from upright asin(r) is well conditioned; near upright beta = asin(cos theta_0)
        // with cos theta_0 = sqrt((1 - r)(1 + r)) formed without cancellation.
        let (theta0, beta) = if inputs.a / inputs.ell <= std::f64::consts::FRAC_1_SQRT_2 {
            let theta0 = hp.asin(&r);
            let beta = hp.sub(&half_pi, &theta0);
            (theta0, beta)
        } else {
            let cos0 = hp.sqrt(&hp.mul(&hp.sub(&one, &r), &hp.add(&one, &r)));
            let beta = hp.asin(&cos0);
            (hp.sub(&half_pi, &beta), beta)
        };
        let gl = gauss_legendre(&hp, GL_NODES);
        Ok(Reference {
            hp,
            inputs,
            r,
            mu,
            kappa,
            theta0,
            beta,
            gl,
        })
    }

    /// The inputs.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// `theta_0 = asin(a/ell)`.
    pub fn theta0(&self) -> &BigFloat {
        &self.theta0
    }

    /// `sin(theta_sep)` by the chosen route.
    pub fn separation_sine(&mut self, route: RootRoute) -> Result<BigFloat, ReferenceError> {
        let hp = &mut self.hp;
        let (two, three) = (hp.c(2.0), hp.c(3.0));
        let r = self.r.clone();
        if self.mu.is_zero() {
            return Ok(hp.div(&hp.mul(&two, &r), &three));
        }
        match route {
            RootRoute::ClosedForm => {
                if self.mu.is_negative() {
                    // s = (2/sqrt(nu)) sin(asin(r sqrt(nu)) / 3), nu = -mu.
                    let root = hp.sqrt(&self.mu.neg());
                    let y = hp.asin(&hp.mul(&r, &root));
                    let s = hp.sin(&hp.div(&y, &three));
                    Ok(hp.div(&hp.mul(&two, &s), &root))
                } else {
                    // s = (2/sqrt(mu)) sinh(asinh(r sqrt(mu)) / 3).
                    let root = hp.sqrt(&self.mu);
                    let y = hp.asinh(&hp.mul(&r, &root));
                    let s = hp.sinh(&hp.div(&y, &three));
                    Ok(hp.div(&hp.mul(&two, &s), &root))
                }
            }
            RootRoute::Newton => {
                // f(s) = mu s^3 + 3 s - 2 r is monotone on (0, r) in both cases and convex or
                // concave on the side that makes Newton from 2r/3 converge monotonically.
                let mut s = hp.div(&hp.mul(&two, &r), &three);
                let two_r = hp.mul(&two, &r);
                let mut change = f64::INFINITY;
                for _ in 0..400 {
                    let s2 = hp.mul(&s, &s);
                    let f = hp.sub(
                        &hp.add(&hp.mul(&self.mu, &hp.mul(&s2, &s)), &hp.mul(&three, &s)),
                        &two_r,
                    );
                    let df = hp.add(&hp.mul(&hp.mul(&three, &self.mu), &s2), &three);
                    let step = hp.div(&f, &df);
                    s = hp.sub(&s, &step);
                    change = to_f64(&hp.div(&step, &s)).abs();
                    if change < 1e-70 {
                        return Ok(s);
                    }
                }
                Err(ReferenceError::NotConverged {
                    what: "Newton on the separation cubic",
                    change,
                })
            }
        }
    }

    /// The separation angle and the angle fallen to it.
    pub fn separation(&mut self, route: RootRoute) -> Result<SeparationReference, ReferenceError> {
        let s = self.separation_sine(route)?;
        let theta = self.hp.asin(&s);
        let delta = self.hp.sub(&self.theta0, &theta);
        Ok(SeparationReference {
            theta_f64: to_f64(&theta),
            sin_theta: s,
            theta,
            delta,
        })
    }

    /// `theta_dot^2 = kappa (r - s) / (1 + mu s^2)` at `delta`, with
    /// `r - s = 2 sin(delta/2) sin(beta + delta/2)`.
    fn theta_dot_sq(&mut self, delta: &BigFloat) -> BigFloat {
        let hp = &mut self.hp;
        let half = hp.div(delta, &hp.c(2.0));
        let f1 = hp.sin(&half);
        let f2 = hp.sin(&hp.add(&self.beta, &half));
        let drop = hp.mul(&hp.c(2.0), &hp.mul(&f1, &f2));
        let s = hp.sin(&hp.sub(&self.theta0, delta));
        let denom = hp.add(&hp.c(1.0), &hp.mul(&self.mu, &hp.mul(&s, &s)));
        hp.div(&hp.mul(&self.kappa, &drop), &denom)
    }

    /// `|theta_dot|` at an angle fallen `delta` (rad/s), rounded to `f64`.
    pub fn theta_dot(&mut self, delta: f64) -> f64 {
        let d = self.hp.c(delta);
        to_f64(&self.theta_dot_sq(&d)).max(0.0).sqrt()
    }

    /// The integrand of route [`TimeRoute::SinhGauss`] at `v`:
    /// `d(delta)/dv / |theta_dot|` with `delta = 2 beta sinh^2 v`, written so that nothing
    /// cancels: `2 sqrt(2) sqrt(x (beta + x) / (sin x sin(beta + x))) sqrt((1 + mu s^2)/kappa)`,
    /// `x = delta/2`.
    fn sinh_integrand(&mut self, v: &BigFloat) -> BigFloat {
        let hp = &mut self.hp;
        let sh = hp.sinh(v);
        let x = hp.mul(&self.beta, &hp.mul(&sh, &sh));
        let bx = hp.add(&self.beta, &x);
        let num = hp.mul(&x, &bx);
        if num.is_zero() {
            // v = 0: sin x / x -> 1.
            let sin_beta = hp.sin(&self.beta);
            let ratio = hp.div(&self.beta, &sin_beta);
            let s = hp.sin(&self.theta0);
            let denom = hp.add(&hp.c(1.0), &hp.mul(&self.mu, &hp.mul(&s, &s)));
            let inner = hp.mul(&ratio, &hp.div(&denom, &self.kappa));
            return hp.mul(&hp.sqrt(&hp.c(8.0)), &hp.sqrt(&inner));
        }
        let (sx, sbx) = (hp.sin(&x), hp.sin(&bx));
        let den = hp.mul(&sx, &sbx);
        let s = hp.sin(&hp.sub(&self.theta0, &hp.mul(&hp.c(2.0), &x)));
        let factor = hp.add(&hp.c(1.0), &hp.mul(&self.mu, &hp.mul(&s, &s)));
        let inner = hp.mul(&hp.div(&num, &den), &hp.div(&factor, &self.kappa));
        hp.mul(&hp.sqrt(&hp.c(8.0)), &hp.sqrt(&inner))
    }

    /// `v` with `delta = 2 beta sinh^2 v`.
    fn v_of_delta(&mut self, delta: &BigFloat) -> BigFloat {
        let hp = &mut self.hp;
        let q = hp.div(delta, &hp.mul(&hp.c(2.0), &self.beta));
        let root = hp.sqrt(&q);
        hp.asinh(&root)
    }

    /// One Gauss–Legendre panel of the sinh route over `[a, b]` in `v`.
    fn gl_panel(&mut self, a: &BigFloat, b: &BigFloat) -> BigFloat {
        let half = self.hp.div(&self.hp.sub(b, a), &self.hp.c(2.0));
        let mid = self.hp.div(&self.hp.add(a, b), &self.hp.c(2.0));
        let mut sum = self.hp.c(0.0);
        for i in 0..self.gl.len() {
            let (x, w) = self.gl[i].clone();
            let v = self.hp.add(&mid, &self.hp.mul(&half, &x));
            let f = self.sinh_integrand(&v);
            sum = self.hp.add(&sum, &self.hp.mul(&w, &f));
        }
        self.hp.mul(&half, &sum)
    }

    /// Adaptive Gauss–Legendre of the sinh route over `[a, b]` in `v`.
    fn adaptive_gl(&mut self, a: BigFloat, b: BigFloat) -> Result<BigFloat, ReferenceError> {
        let whole = self.gl_panel(&a, &b);
        let mut stack = vec![(a, b, whole)];
        let mut total = self.hp.c(0.0);
        let mut panels = 0usize;
        while let Some((lo, hi, whole)) = stack.pop() {
            let mid = self.hp.div(&self.hp.add(&lo, &hi), &self.hp.c(2.0));
            let left = self.gl_panel(&lo, &mid);
            let right = self.gl_panel(&mid, &hi);
            let refined = self.hp.add(&left, &right);
            let change = relative_difference(&whole, &refined);
            panels += 1;
            if change <= TOLERANCE {
                total = self.hp.add(&total, &refined);
                continue;
            }
            if panels > MAX_PANELS {
                return Err(ReferenceError::NotConverged {
                    what: "adaptive Gauss-Legendre of the sinh route",
                    change,
                });
            }
            stack.push((mid.clone(), hi, right));
            stack.push((lo, mid, left));
        }
        Ok(total)
    }

    /// Time from release to the angle fallen `delta` by the sinh route.
    fn time_sinh(&mut self, delta: &BigFloat) -> Result<BigFloat, ReferenceError> {
        if delta.is_zero() {
            return Ok(self.hp.c(0.0));
        }
        let v_end = self.v_of_delta(delta);
        let zero = self.hp.c(0.0);
        self.adaptive_gl(zero, v_end)
    }

    /// The tanh–sinh integrand `d(delta)/d(tau) / |theta_dot|` at `tau` over `[0, end]`;
    /// `delta = end / (1 + e^{-2y})`, `y = (pi/2) sinh tau`.
    fn tanh_sinh_term(&mut self, tau: &BigFloat, end: &BigFloat) -> BigFloat {
        let hp = &mut self.hp;
        let pi = hp.pi();
        let half_pi = hp.div(&pi, &hp.c(2.0));
        let sh = hp.sinh(tau);
        let y = hp.mul(&half_pi, &sh);
        let m2y = hp.mul(&hp.c(-2.0), &y);
        let e = hp.exp(&m2y);
        let one_e = hp.add(&hp.c(1.0), &e);
        let delta = hp.div(end, &one_e);
        // d(delta)/d(tau) = end * 2 y' e / (1 + e)^2 with y' = (pi/2) cosh tau.
        let ch = hp.cosh(tau);
        let dy = hp.mul(&half_pi, &ch);
        let jac = hp.div(
            &hp.mul(&hp.mul(end, &hp.c(2.0)), &hp.mul(&dy, &e)),
            &hp.mul(&one_e, &one_e),
        );
        if delta.is_zero() || jac.is_zero() {
            return hp.c(0.0);
        }
        let w2 = self.theta_dot_sq(&delta);
        let hp = &mut self.hp;
        hp.div(&jac, &hp.sqrt(&w2))
    }

    /// Time from release to the angle fallen `delta` by the tanh–sinh route.
    fn time_tanh_sinh(&mut self, delta: &BigFloat) -> Result<BigFloat, ReferenceError> {
        let mut h = 0.5f64;
        let k_max = (TANH_SINH_RANGE / h) as i64;
        let mut sum = self.hp.c(0.0);
        for k in -k_max..=k_max {
            let tau = self.hp.c(k as f64 * h);
            let term = self.tanh_sinh_term(&tau, delta);
            sum = self.hp.add(&sum, &term);
        }
        let mut estimate = self.hp.mul(&sum, &self.hp.c(h));
        let mut change = f64::INFINITY;
        for _ in 1..MAX_LEVEL {
            h *= 0.5;
            let k_max = (TANH_SINH_RANGE / h) as i64;
            // Only the odd multiples of the new step are new points.
            let mut k = -k_max + if k_max % 2 == 0 { 1 } else { 0 };
            while k <= k_max {
                let tau = self.hp.c(k as f64 * h);
                let term = self.tanh_sinh_term(&tau, delta);
                sum = self.hp.add(&sum, &term);
                k += 2;
            }
            let next = self.hp.mul(&sum, &self.hp.c(h));
            change = relative_difference(&estimate, &next);
            estimate = next;
            // The error of a tanh-sinh level is about the square of the change from the last.
            if change < 1e-24 {
                return Ok(estimate);
            }
        }
        Err(ReferenceError::NotConverged {
            what: "tanh-sinh quadrature",
            change,
        })
    }

    /// Time from release to separation by the chosen route (s), with the separation from
    /// the closed form.
    pub fn separation_time(&mut self, route: TimeRoute) -> Result<BigFloat, ReferenceError> {
        let sep = self.separation(RootRoute::ClosedForm)?;
        self.time_to(&sep.delta, route)
    }

    /// Time from release to the angle fallen `delta` (s) by the chosen route.
    pub fn time_to(
        &mut self,
        delta: &BigFloat,
        route: TimeRoute,
    ) -> Result<BigFloat, ReferenceError> {
        match route {
            TimeRoute::TanhSinh => self.time_tanh_sinh(delta),
            TimeRoute::SinhGauss => self.time_sinh(delta),
        }
    }

    /// Times from release to each of the angles fallen `deltas` (any order), by the sinh route,
    /// integrating between consecutive angles so each costs one short integral. Each must lie
    /// in `[0, delta_sep]` of the closed-form separation (up to `1e-9` relative past it).
    pub fn times_at(&mut self, deltas: &[f64]) -> Result<Vec<BigFloat>, ReferenceError> {
        let end = to_f64(&self.separation(RootRoute::ClosedForm)?.delta);
        let mut order: Vec<usize> = (0..deltas.len()).collect();
        order.sort_by(|&i, &j| deltas[i].total_cmp(&deltas[j]));
        let mut out = vec![self.hp.c(0.0); deltas.len()];
        let mut v_prev = self.hp.c(0.0);
        let mut t = self.hp.c(0.0);
        for i in order {
            let d = deltas[i];
            if !(d >= 0.0 && d <= end * (1.0 + 1e-9)) {
                return Err(ReferenceError::Outside { delta: d, end });
            }
            if d > 0.0 {
                let v = self.v_of_delta(&self.hp.c(d));
                if v.cmp(&v_prev).is_some_and(|c| c > 0) {
                    let piece = self.adaptive_gl(v_prev.clone(), v.clone())?;
                    t = self.hp.add(&t, &piece);
                    v_prev = v;
                }
            }
            out[i] = t.clone();
        }
        Ok(out)
    }
}

/// Gauss–Legendre nodes and weights on `[-1, 1]` in high precision: Newton on `P_n` from the
/// usual cosine guesses, `w = 2 / ((1 - x^2) P_n'(x)^2)`.
fn gauss_legendre(hp: &Hp, n: usize) -> Vec<(BigFloat, BigFloat)> {
    let one = hp.c(1.0);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let guess = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut x = hp.c(guess);
        let mut dp = one.clone();
        for _ in 0..100 {
            // P_0 = 1, P_1 = x, (k+1) P_{k+1} = (2k+1) x P_k - k P_{k-1}.
            let (mut p0, mut p1) = (one.clone(), x.clone());
            for k in 1..n {
                let kf = k as f64;
                let a = hp.mul(&hp.c(2.0 * kf + 1.0), &hp.mul(&x, &p1));
                let b = hp.mul(&hp.c(kf), &p0);
                let p2 = hp.div(&hp.sub(&a, &b), &hp.c(kf + 1.0));
                p0 = p1;
                p1 = p2;
            }
            // P_n' = n (x P_n - P_{n-1}) / (x^2 - 1).
            let x2m1 = hp.sub(&hp.mul(&x, &x), &one);
            dp = hp.div(
                &hp.mul(&hp.c(n as f64), &hp.sub(&hp.mul(&x, &p1), &p0)),
                &x2m1,
            );
            let step = hp.div(&p1, &dp);
            x = hp.sub(&x, &step);
            if step.is_zero() || to_f64(&step).abs() < 1e-75 {
                break;
            }
        }
        let x2 = hp.mul(&x, &x);
        let w = hp.div(&hp.c(2.0), &hp.mul(&hp.sub(&one, &x2), &hp.mul(&dp, &dp)));
        out.push((x, w));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_to_f64_round_trips() {
        for x in [
            0.75,
            -3.0,
            1e-300,
            6.02e23,
            std::f64::consts::PI,
            1.0 - 1e-16,
        ] {
            assert_eq!(to_f64(&BigFloat::from_f64(x, PRECISION)), x);
        }
        assert_eq!(to_f64(&BigFloat::from_f64(0.0, PRECISION)), 0.0);
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let hp = Hp::new(PRECISION);
        let rule = gauss_legendre(&hp, GL_NODES);
        // integral_{-1}^{1} x^46 dx = 2/47 (degree 2n - 1 = 47 is exact).
        let mut sum = hp.c(0.0);
        for (x, w) in &rule {
            sum = hp.add(&sum, &hp.mul(w, &x.powi(46, PRECISION, RM)));
        }
        let want = hp.div(&hp.c(2.0), &hp.c(47.0));
        assert!(relative_difference(&sum, &want) < 1e-70);
    }

    #[test]
    fn wall_ladder_root_is_two_thirds() {
        let mut r = Reference::new(Inputs::dimensionless(Family::WallLadder, 1.0, 0.75)).unwrap();
        let s = to_f64(&r.separation_sine(RootRoute::Newton).unwrap());
        assert_eq!(s, 0.5);
    }
}
