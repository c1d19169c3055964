//! Hand-derived references for the models with several unilateral contacts (`ladder_friction`,
//! `fixed_cylinder`, `rod_block_tipping`, `rod_cube_liftoff`), written from Newton–Euler balances
//! (free-body diagrams) and checked with sympy (`docs/hand_derivations/*.py`); the derivations are
//! in `docs/hand_derivations.md`.
//!
//! Nothing here uses the `rodcube` crate: the quadrature (Gauss–Legendre), the ODE integrator
//! (Gauss–Legendre collocation, order 10, fixed step, events located by Illinois regula falsi on
//! the step) and the small linear solves are written in this file, so that a test comparing
//! rodcube with these functions compares two independent routes.
//!
//! Conventions: SI units (kg, m, s, rad, N); y is up, the floor is y = 0, angles are
//! counter-clockwise from +x; every rod is uniform (mass `m1`, length `ell`, moment of inertia
//! `m1 ell^2 / 12` about its centre). "Release" is t = 0, from rest.

use std::f64::consts::PI;

// =============================================================================================
// Numerics
// =============================================================================================

/// `(P_n(z), P_n'(z))`, the Legendre polynomial of degree `n >= 1` and its derivative (`|z| < 1`).
fn legendre(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    (p1, n as f64 * (z * p1 - p0) / (z * z - 1.0))
}

/// A Gauss–Legendre rule: nodes `x` (ascending) and weights `w` on [-1, 1].
#[derive(Clone, Debug)]
pub struct Gauss {
    /// Nodes, the roots of `P_n`.
    pub x: Vec<f64>,
    /// Weights `2 / ((1 - x^2) P_n'(x)^2)`.
    pub w: Vec<f64>,
}

impl Gauss {
    /// The `n`-point rule (`n >= 1`), exact for polynomials of degree `2n - 1`: Newton's method on
    /// `P_n` from the Chebyshev-like guesses `cos(pi (i + 3/4) / (n + 1/2))`.
    pub fn new(n: usize) -> Self {
        assert!(n >= 1);
        let (mut x, mut w) = (vec![0.0; n], vec![0.0; n]);
        for i in 0..n.div_ceil(2) {
            let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(n, z);
                let dz = p / dp;
                z -= dz;
                if dz.abs() <= 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(n, z);
            x[i] = -z;
            x[n - 1 - i] = z;
            w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
            w[n - 1 - i] = w[i];
        }
        if n % 2 == 1 {
            x[n / 2] = 0.0;
        }
        Self { x, w }
    }

    /// `int_a^b f(x) dx` by this rule on `panels` equal panels (`b < a` gives the negative).
    pub fn integrate(&self, f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
        let width = (b - a) / panels as f64;
        let mut sum = 0.0;
        for p in 0..panels {
            let mid = a + width * (p as f64 + 0.5);
            let part: f64 = self
                .x
                .iter()
                .zip(&self.w)
                .map(|(x, w)| w * f(mid + 0.5 * width * x))
                .sum();
            sum += 0.5 * width * part;
        }
        sum
    }
}

/// An autonomous first-order system `y' = f(y)`: `f(y, out)` writes `y'` into `out`.
pub type Rhs<'a> = &'a dyn Fn(&[f64], &mut [f64]);

/// The implicit Runge–Kutta method of Gauss–Legendre collocation with `s` stages (order `2s`,
/// A-stable, symplectic), its stage equations solved by fixed-point iteration (fine for the
/// non-stiff systems here, with `h` well below the inverse Lipschitz constant).
#[derive(Clone, Debug)]
pub struct GaussRk {
    s: usize,
    a: Vec<f64>,
    b: Vec<f64>,
}

impl GaussRk {
    /// The `s`-stage method: `c_i = (1 + x_i)/2` for the Gauss nodes `x_i`, `b_i = w_i / 2`,
    /// `a_ij = int_0^{c_i} L_j(tau) dtau` with `L_j` the Lagrange basis on the `c`'s (integrated
    /// exactly by the `s`-point rule, `L_j` having degree `s - 1`).
    pub fn new(s: usize) -> Self {
        let rule = Gauss::new(s);
        let c: Vec<f64> = rule.x.iter().map(|x| 0.5 * (1.0 + x)).collect();
        let b: Vec<f64> = rule.w.iter().map(|w| 0.5 * w).collect();
        let basis = |j: usize, t: f64| -> f64 {
            (0..s)
                .filter(|&k| k != j)
                .map(|k| (t - c[k]) / (c[j] - c[k]))
                .product()
        };
        let mut a = vec![0.0; s * s];
        for i in 0..s {
            for j in 0..s {
                a[i * s + j] = rule.integrate(|t| basis(j, t), 0.0, c[i], 1);
            }
        }
        Self { s, a, b }
    }

    /// One step of length `h` from `y`. Panics if the stage iteration does not converge (the
    /// step is then too long for fixed-point iteration).
    pub fn step(&self, f: Rhs, y: &[f64], h: f64) -> Vec<f64> {
        let (s, dim) = (self.s, y.len());
        let mut k = vec![0.0; s * dim];
        f(y, &mut k[..dim]);
        for i in 1..s {
            k.copy_within(..dim, i * dim);
        }
        let mut fresh = vec![0.0; s * dim];
        let mut yi = vec![0.0; dim];
        let ymax = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut previous = f64::INFINITY;
        for iteration in 0.. {
            for i in 0..s {
                for d in 0..dim {
                    let inc: f64 = (0..s).map(|j| self.a[i * s + j] * k[j * dim + d]).sum();
                    yi[d] = y[d] + h * inc;
                }
                f(&yi, &mut fresh[i * dim..(i + 1) * dim]);
            }
            // Converged when every component's change is at the rounding level of the step's
            // result (with a floor at 1e-3 of the state's largest component, for components that
            // are zero), or when the change stops shrinking at a level that small.
            let mut done = true;
            let mut worst = 0.0f64;
            for (idx, (kn, ko)) in fresh.iter().zip(&k).enumerate() {
                let d = idx % dim;
                let change = (h * (kn - ko)).abs();
                worst = worst.max(change);
                let scale = y[d].abs() + (h * kn).abs() + 1e-3 * ymax;
                if change > 4.0 * f64::EPSILON * scale {
                    done = false;
                }
            }
            std::mem::swap(&mut k, &mut fresh);
            let stalled = iteration > 5 && worst >= previous && worst <= 1e-12 * (ymax + 1e-300);
            if done || stalled {
                break;
            }
            assert!(
                iteration < 200,
                "GaussRk: stage iteration did not converge (step {h})"
            );
            previous = worst;
        }
        (0..dim)
            .map(|d| y[d] + h * (0..s).map(|i| self.b[i] * k[i * dim + d]).sum::<f64>())
            .collect()
    }
}

/// Where an integration stopped: the first event function to reach zero (`None`: `t_max`), the
/// time and the state there.
#[derive(Clone, Debug, PartialEq)]
pub struct Hit {
    /// Index of the event function that reached zero first, or `None` at `t_max`.
    pub event: Option<usize>,
    /// Time from the start (s).
    pub t: f64,
    /// State at `t`.
    pub y: Vec<f64>,
}

/// Integrates `y' = f(y)` from `y0` at t = 0 with the 5-stage Gauss–Legendre method (order 10)
/// and fixed step `h`, until `t_max` or until one of the `n_events` event functions
/// (`events(y, out)`, each positive while the motion is valid) reaches zero. An event already
/// `<= 0` at the start is reported at t = 0. A crossing is found by Illinois regula falsi on the
/// length of the last step (each trial a fresh step of that length from the step's start, so the
/// located state has the method's full order), to a few ulps of the time. Two crossings inside
/// one step are not seen; the steps used here are far shorter than any such interval.
pub fn integrate(
    f: Rhs,
    events: &dyn Fn(&[f64], &mut [f64]),
    n_events: usize,
    y0: &[f64],
    h: f64,
    t_max: f64,
) -> Hit {
    let rk = GaussRk::new(5);
    let mut e0 = vec![0.0; n_events];
    events(y0, &mut e0);
    if let Some(i) = e0.iter().position(|&e| e <= 0.0) {
        return Hit {
            event: Some(i),
            t: 0.0,
            y: y0.to_vec(),
        };
    }
    let mut y = y0.to_vec();
    let mut e1 = vec![0.0; n_events];
    let mut n = 0usize;
    loop {
        let t = n as f64 * h;
        let last = t + h >= t_max;
        let hh = if last { t_max - t } else { h };
        let y1 = rk.step(f, &y, hh);
        events(&y1, &mut e1);
        let mut best: Option<(f64, usize)> = None;
        for i in 0..n_events {
            if e1[i] > 0.0 {
                continue;
            }
            let g = |x: f64| {
                let mut out = vec![0.0; n_events];
                events(&rk.step(f, &y, x), &mut out);
                out[i]
            };
            let x = illinois(&g, e0[i], hh, e1[i], t);
            if best.is_none_or(|(bx, _)| x < bx) {
                best = Some((x, i));
            }
        }
        if let Some((x, i)) = best {
            return Hit {
                event: Some(i),
                t: t + x,
                y: rk.step(f, &y, x),
            };
        }
        if last {
            return Hit {
                event: None,
                t: t_max,
                y: y1,
            };
        }
        y = y1;
        e0.copy_from_slice(&e1);
        n += 1;
    }
}

/// A root of `g` in (0, b] given `g(0) = ga > 0 >= gb = g(b)`, by the Illinois variant of regula
/// falsi, to a few ulps of the absolute time `t0 + x`.
fn illinois(g: &dyn Fn(f64) -> f64, ga: f64, b: f64, gb: f64, t0: f64) -> f64 {
    let (mut a, mut fa, mut b, mut fb) = (0.0, ga, b, gb);
    let mut side = 0i8;
    for _ in 0..300 {
        if fb == 0.0 || b - a <= 4.0 * f64::EPSILON * (t0 + b).abs().max(1e-300) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let fc = g(c);
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    if fa.abs() < fb.abs() { a } else { b }
}

/// Solves the `N x N` system `a x = b` by Gaussian elimination with partial pivoting.
pub fn solve_linear<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> [f64; N] {
    for col in 0..N {
        let piv = (col..N)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot_row = a[col];
        for row in col + 1..N {
            let factor = a[row][col] / pivot_row[col];
            for (x, p) in a[row].iter_mut().zip(&pivot_row).skip(col) {
                *x -= factor * p;
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let tail: f64 = (row + 1..N).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    x
}

/// `sin(theta0) - sin(theta)` without cancellation near `theta0`:
/// `2 cos((theta0 + theta)/2) sin((theta0 - theta)/2)`.
pub fn sin_drop(theta0: f64, theta: f64) -> f64 {
    2.0 * (0.5 * (theta0 + theta)).cos() * (0.5 * (theta0 - theta)).sin()
}

// =============================================================================================
// A. ladder_friction
// =============================================================================================

/// `ladder_friction`: a uniform ladder (mass `m1`, length `ell`) leaning on a fixed wall whose face
/// is x = 0 (the ladder on its left), its foot on the floor y = 0, released from rest with the top
/// at height `a` (`sin(theta0) = a/ell`), Coulomb friction `mu_f` at the foot and `mu_w` at the
/// top. Foot `(-ell cos(theta), 0)`, top `(0, ell sin(theta))` while both touch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ladder {
    /// Ladder mass (kg).
    pub m1: f64,
    /// Ladder length (m).
    pub ell: f64,
    /// Height of the top at release (m), `0 < a < ell`.
    pub a: f64,
    /// Gravitational acceleration (m/s^2).
    pub g: f64,
    /// Friction coefficient at the foot (floor).
    pub mu_f: f64,
    /// Friction coefficient at the top (wall).
    pub mu_w: f64,
}

/// The contact forces on the ladder while both ends slide (N): the wall's push `n_wall` (along
/// -x, on the top), the floor's push `n_floor` (along +y, on the foot), the floor's friction
/// `f_floor = mu_f n_floor` (along +x, the foot sliding to -x) and the wall's friction
/// `f_wall = mu_w n_wall` (along +y, the top sliding down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LadderForces {
    /// Wall normal force on the top, pointing -x (N).
    pub n_wall: f64,
    /// Floor normal force on the foot, pointing +y (N).
    pub n_floor: f64,
    /// Floor friction on the foot, pointing +x (N).
    pub f_floor: f64,
    /// Wall friction on the top, pointing +y (N).
    pub f_wall: f64,
}

/// How a ladder run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LadderEvent {
    /// Static friction holds the ladder at rest: `2 mu_f tan(theta0) >= 1 - mu_f mu_w`.
    Holds,
    /// The wall's push reached zero: the top leaves the wall.
    WallSeparation,
    /// The floor's push reached zero: the foot lifts.
    FootLifts,
    /// The ladder reached the floor (theta = 0) still touching the wall.
    Floor,
    /// None of the above before the time limit.
    Timeout,
}

/// The end of a ladder run from release.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LadderEnd {
    /// What ended the sliding phase.
    pub event: LadderEvent,
    /// Time from release (s).
    pub t: f64,
    /// Angle there (rad).
    pub theta: f64,
    /// Angular velocity there (rad/s, negative while falling).
    pub theta_dot: f64,
    /// Work done by both friction forces from release (J, <= 0).
    pub friction_work: f64,
}

impl Ladder {
    /// The release angle `asin(a/ell)` (rad).
    pub fn theta0(&self) -> f64 {
        (self.a / self.ell).asin()
    }

    /// `(A, G, B)` with `A theta'' = G - B theta'^2` in the sliding mode (docs, section A):
    /// `D = 1 + mu_f mu_w`, `k1 = (1 - mu_f mu_w)/D`, `alpha = 2 mu_f/D`, `beta = 2 mu_w/D`,
    /// `A = ell (1/6 + (k1 - (alpha - beta) s c)/2)`, `G = g (alpha s - k1 c)`,
    /// `B = (ell/2)(alpha s^2 + beta c^2)`.
    fn coefficients(&self, theta: f64) -> (f64, f64, f64) {
        let (s, c) = theta.sin_cos();
        let d = 1.0 + self.mu_f * self.mu_w;
        let k1 = (1.0 - self.mu_f * self.mu_w) / d;
        let (al, be) = (2.0 * self.mu_f / d, 2.0 * self.mu_w / d);
        let a = self.ell * (1.0 / 6.0 + 0.5 * (k1 - (al - be) * s * c));
        let g = self.g * (al * s - k1 * c);
        let b = 0.5 * self.ell * (al * s * s + be * c * c);
        (a, g, b)
    }

    /// The coefficient `A` of `theta''` in the sliding mode (m): `6 D A / ell = 4 - 2 mu_f mu_w -
    /// 3 (mu_f - mu_w) sin(2 theta)`; it is `>= ell/6` wherever the ladder slides (no Painlevé
    /// paradox, docs section A).
    pub fn mass_coefficient(&self, theta: f64) -> f64 {
        self.coefficients(theta).0
    }

    /// Whether the ladder starts to slide from rest: the sliding mode's `theta''` at rest is
    /// `G(theta0)/A`, negative iff `2 mu_f sin(theta0) < (1 - mu_f mu_w) cos(theta0)`, i.e.
    /// `tan(theta0) < (1 - mu_f mu_w)/(2 mu_f)`; otherwise static friction holds it (the limiting
    /// equilibrium of statics is the same angle).
    pub fn slides(&self) -> bool {
        let (_, g, _) = self.coefficients(self.theta0());
        g < 0.0
    }

    /// `theta''` (rad/s^2) with both ends touching and sliding (foot to -x, top down), from the
    /// three Newton–Euler balances with the Coulomb laws `F_f = mu_f N_f`, `F_w = mu_w N_w`.
    /// Valid while `theta' <= 0`, `N_w >= 0`, `N_f >= 0` (see [`Ladder::forces`]).
    pub fn theta_ddot(&self, theta: f64, theta_dot: f64) -> f64 {
        let (a, g, b) = self.coefficients(theta);
        (g - b * theta_dot * theta_dot) / a
    }

    /// The contact forces (N) in the sliding mode at `(theta, theta', theta'')`, from the
    /// centre's Newton equations `m xc'' = F_f - N_w`, `m yc'' = N_f + F_w - m g` with
    /// `xc'' = (ell/2)(s theta'' + c theta'^2)`, `yc'' = (ell/2)(c theta'' - s theta'^2)`:
    /// `N_f = m (g + yc'' + mu_w xc'')/D`, `N_w = m (mu_f (g + yc'') - xc'')/D`,
    /// `D = 1 + mu_f mu_w`. (Any `theta''` is accepted, so a test can feed rodcube's.)
    pub fn forces(&self, theta: f64, theta_dot: f64, theta_ddot: f64) -> LadderForces {
        let (s, c) = theta.sin_cos();
        let (m, l, w2) = (self.m1, self.ell, theta_dot * theta_dot);
        let xcdd = 0.5 * l * (s * theta_ddot + c * w2);
        let ycdd = 0.5 * l * (c * theta_ddot - s * w2);
        let d = 1.0 + self.mu_f * self.mu_w;
        let n_floor = m * (self.g + ycdd + self.mu_w * xcdd) / d;
        let n_wall = m * (self.mu_f * (self.g + ycdd) - xcdd) / d;
        LadderForces {
            n_wall,
            n_floor,
            f_floor: self.mu_f * n_floor,
            f_wall: self.mu_w * n_wall,
        }
    }

    /// Total energy with both contacts touching (J): `m ell^2 theta'^2 / 6 + m g (ell/2) sin`.
    pub fn energy(&self, theta: f64, theta_dot: f64) -> f64 {
        self.m1 * self.ell * (self.ell * theta_dot * theta_dot / 6.0 + 0.5 * self.g * theta.sin())
    }

    /// Power of the friction forces (W, <= 0): `F_f x_foot' + F_w y_top'` with
    /// `x_foot' = ell s theta'`, `y_top' = ell c theta'`, in the sliding mode.
    pub fn friction_power(&self, theta: f64, theta_dot: f64) -> f64 {
        let f = self.forces(theta, theta_dot, self.theta_ddot(theta, theta_dot));
        let (s, c) = theta.sin_cos();
        self.ell * theta_dot * (f.f_floor * s + f.f_wall * c)
    }

    /// `theta''` by a second route, Lagrange's equation with generalized friction forces:
    /// `(m ell^2/3) theta'' + m g (ell/2) cos = Q`, `Q = F_f d(x_foot)/dtheta + F_w d(y_top)/dtheta
    /// = ell (F_f sin + F_w cos)`, the friction forces taken from [`Ladder::forces`] (the normal
    /// forces do no virtual work); linear in `theta''`, solved from two evaluations.
    pub fn lagrange_theta_ddot(&self, theta: f64, theta_dot: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let (m, l) = (self.m1, self.ell);
        let residual = |tdd: f64| {
            let f = self.forces(theta, theta_dot, tdd);
            m * l * l / 3.0 * tdd + 0.5 * m * self.g * l * c - l * (f.f_floor * s + f.f_wall * c)
        };
        let (r0, r1) = (residual(0.0), residual(1.0));
        -r0 / (r1 - r0)
    }

    /// The sliding phase from release with the default step (`sqrt(ell/g)/200`): see
    /// [`Ladder::run_with_step`].
    pub fn run(&self) -> LadderEnd {
        self.run_with_step((self.ell / self.g).sqrt() / 200.0)
    }

    /// The sliding phase from release integrated with step `h` (s): state `(theta, theta',
    /// W)` with `W' =` [`Ladder::friction_power`], until the first of `N_w = 0`
    /// (`WallSeparation`), `N_f = 0` (`FootLifts`), `theta = 0` (`Floor`), or 100 `sqrt(ell/g)`.
    /// If the ladder does not slide ([`Ladder::slides`] false) it returns `Holds` at t = 0.
    pub fn run_with_step(&self, h: f64) -> LadderEnd {
        let th0 = self.theta0();
        if !self.slides() {
            return LadderEnd {
                event: LadderEvent::Holds,
                t: 0.0,
                theta: th0,
                theta_dot: 0.0,
                friction_work: 0.0,
            };
        }
        let f = |y: &[f64], out: &mut [f64]| {
            out[0] = y[1];
            out[1] = self.theta_ddot(y[0], y[1]);
            out[2] = self.friction_power(y[0], y[1]);
        };
        let ev = |y: &[f64], out: &mut [f64]| {
            let fo = self.forces(y[0], y[1], self.theta_ddot(y[0], y[1]));
            out[0] = fo.n_wall;
            out[1] = fo.n_floor;
            out[2] = y[0];
        };
        let t_max = 100.0 * (self.ell / self.g).sqrt();
        let hit = integrate(&f, &ev, 3, &[th0, 0.0, 0.0], h, t_max);
        let event = match hit.event {
            Some(0) => LadderEvent::WallSeparation,
            Some(1) => LadderEvent::FootLifts,
            Some(_) => LadderEvent::Floor,
            None => LadderEvent::Timeout,
        };
        LadderEnd {
            event,
            t: hit.t,
            theta: hit.y[0],
            theta_dot: hit.y[1],
            friction_work: hit.y[2],
        }
    }

    /// `theta'^2` at `theta` on the sliding path from rest, by a route that never integrates in
    /// time: `u = theta'^2` obeys the linear ODE `du/dtheta = p - q u` (`p = 2G/A`,
    /// `q = 2B/A`), so `u(theta) = int_theta^theta0 (-p(phi)) exp(int_theta^phi q) dphi`, both
    /// integrals by Gauss–Legendre (20 points, the outer one on 2 panels).
    pub fn quadrature_theta_dot_sq(&self, theta: f64) -> f64 {
        let th0 = self.theta0();
        let rule = Gauss::new(20);
        let pq = |x: f64| {
            let (a, g, b) = self.coefficients(x);
            (2.0 * g / a, 2.0 * b / a)
        };
        rule.integrate(
            |phi| {
                let inner = rule.integrate(|xi| pq(xi).1, theta, phi, 1);
                -pq(phi).0 * inner.exp()
            },
            theta,
            th0,
            2,
        )
    }

    /// The wall separation `(theta_sep, t_sep)` by quadrature (no time integration):
    /// `theta_sep` where `N_w(theta, u(theta), (G - B u)/A) = 0` with `u` from
    /// [`Ladder::quadrature_theta_dot_sq`] (a scan down from `theta0` in 400 steps, then
    /// bisection), and `t_sep = int_0^{sqrt(theta0 - theta_sep)} 2 v / sqrt(u(theta0 - v^2)) dv`
    /// (the substitution `theta = theta0 - v^2` removes the `1/sqrt` endpoint singularity).
    /// `None` if the ladder does not slide or `N_w` stays positive down to the floor.
    pub fn quadrature_separation(&self) -> Option<(f64, f64)> {
        if !self.slides() {
            return None;
        }
        let th0 = self.theta0();
        let n_wall = |x: f64| {
            let u = self.quadrature_theta_dot_sq(x);
            let (a, g, b) = self.coefficients(x);
            self.forces(x, -u.sqrt(), (g - b * u) / a).n_wall
        };
        let steps = 400;
        let mut hi = th0;
        let mut lo = None;
        for k in 1..=steps {
            let x = th0 * (1.0 - k as f64 / steps as f64);
            if n_wall(x) <= 0.0 {
                lo = Some(x);
                break;
            }
            hi = x;
        }
        let mut lo = lo?;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if n_wall(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let th_sep = 0.5 * (lo + hi);
        let rule = Gauss::new(20);
        let t = rule.integrate(
            |v| 2.0 * v / self.quadrature_theta_dot_sq(th0 - v * v).sqrt(),
            0.0,
            (th0 - th_sep).sqrt(),
            4,
        );
        Some((th_sep, t))
    }
}

/// The frictionless ladder's wall separation `(theta_sep, t_sep)` in closed form:
/// `sin(theta_sep) = (2/3) a/ell` and `t_sep = int_{theta_sep}^{theta0} dtheta /
/// sqrt(3 (g/ell)(sin(theta0) - sin(theta)))` (energy integral), computed with `theta = theta0 -
/// v^2` and `sin(theta0) - sin(theta0 - v^2) = 2 cos(theta0 - v^2/2) sin(v^2/2)` by 30-point
/// Gauss–Legendre on 8 panels.
pub fn ladder_frictionless_separation(ell: f64, a: f64, g: f64) -> (f64, f64) {
    let th0 = (a / ell).asin();
    let th_sep = (2.0 * a / (3.0 * ell)).asin();
    let k = 3.0 * g / ell;
    let t = Gauss::new(30).integrate(
        |v| {
            let v2 = v * v;
            2.0 * v / (k * 2.0 * (th0 - 0.5 * v2).cos() * (0.5 * v2).sin()).sqrt()
        },
        0.0,
        (th0 - th_sep).sqrt(),
        8,
    );
    (th_sep, t)
}

// =============================================================================================
// B. fixed_cylinder
// =============================================================================================

/// `fixed_cylinder`: a uniform rod (mass `m1`, length `ell`) whose foot `(x1, y1)` slides on the
/// frictionless floor, leaning on a fixed frictionless cylinder of radius `r` with its axis at
/// `(0, r)`; the rod rises to the right from its foot at angle `theta`. Released from rest at
/// `theta = th0` with both contacts touching (`x1 = -r cot(th0/2)`, `y1 = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Rod mass (kg).
    pub m1: f64,
    /// Rod length (m).
    pub ell: f64,
    /// Cylinder radius (m).
    pub r: f64,
    /// Release angle (rad).
    pub th0: f64,
    /// Gravitational acceleration (m/s^2).
    pub g: f64,
}

/// How the both-contacts phase of [`Cylinder`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CylinderEvent {
    /// `P <= 0` already at release: the rod leaves the cylinder at once
    /// (`r <= (ell/2) sin(th0)(1 - cos(th0))`).
    LeavesAtRelease,
    /// `N <= 0` already at release.
    FootLiftsAtRelease,
    /// The floor's push reached zero: the foot lifts.
    FootLifts,
    /// The cylinder's push reached zero: the rod leaves the cylinder.
    LeavesCylinder,
    /// The tangent point reached the rod's top end (`r cot(theta/2) = ell`).
    Edge,
    /// None of the above before the time limit.
    Timeout,
}

/// The end of the both-contacts phase of [`Cylinder`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderEnd {
    /// What ended the phase.
    pub event: CylinderEvent,
    /// Time from release (s).
    pub t: f64,
    /// Angle there (rad).
    pub theta: f64,
    /// Angular velocity there (rad/s).
    pub theta_dot: f64,
}

impl Cylinder {
    /// The moment of inertia about the centre, `m1 ell^2 / 12` (kg m^2).
    fn inertia(&self) -> f64 {
        self.m1 * self.ell * self.ell / 12.0
    }

    /// The tangent point's distance from the foot while the foot is on the floor (m):
    /// `r cot(theta/2) = r (1 + cos)/sin`.
    pub fn tangent_distance(&self, theta: f64) -> f64 {
        self.r / (0.5 * theta).tan()
    }

    /// `(kappa, kappa')`: `kappa = dxG/dtheta = r/(1 - cos) - (ell/2) sin` and its derivative
    /// `-r sin/(1 - cos)^2 - (ell/2) cos`, for the centre `xG = -r cot(theta/2) + (ell/2) cos`.
    fn kappa(&self, theta: f64) -> (f64, f64) {
        let (s, c) = theta.sin_cos();
        let h = (0.5 * theta).sin();
        let omc = 2.0 * h * h; // 1 - cos
        (
            self.r / omc - 0.5 * self.ell * s,
            -self.r * s / (omc * omc) - 0.5 * self.ell * c,
        )
    }

    /// The cylinder's push `P` and the floor's push `N` at release (N), in closed form:
    /// `P0 = m g (ell/2) cos kappa / (sin Q)`, `N0 = m g (kappa^2 + ell^2/12 - (ell/2) cos^2
    /// kappa / sin)/Q`, `Q = kappa^2 + (ell/2)^2 cos^2 + ell^2/12`, all at `th0`.
    pub fn release_forces(&self) -> (f64, f64) {
        let (s, c) = self.th0.sin_cos();
        let (k, _) = self.kappa(self.th0);
        let l = self.ell;
        let q = k * k + 0.25 * l * l * c * c + l * l / 12.0;
        let mg = self.m1 * self.g;
        (
            mg * 0.5 * l * c * k / (s * q),
            mg * (k * k + l * l / 12.0 - 0.5 * l * c * c * k / s) / q,
        )
    }

    /// Whether the cylinder pushes at release: `P0 > 0 <=> kappa(th0) > 0 <=>
    /// r > (ell/2) sin(th0)(1 - cos(th0))` (docs, section B).
    pub fn pushes_at_release(&self) -> bool {
        self.r > 0.5 * self.ell * self.th0.sin() * (1.0 - self.th0.cos())
    }

    /// `theta'^2` on the both-contacts path from rest (energy integral, the contacts doing no
    /// work): `g ell (sin(th0) - sin(theta)) / (kappa^2 + (ell/2)^2 cos^2 + ell^2/12)`.
    pub fn theta_dot_sq(&self, theta: f64) -> f64 {
        let (k, _) = self.kappa(theta);
        let l = self.ell;
        let c = theta.cos();
        self.g * l * sin_drop(self.th0, theta) / (k * k + 0.25 * l * l * c * c + l * l / 12.0)
    }

    /// `(theta'', P, N)` with both contacts closed at `(theta, theta')`, from the rod's three
    /// Newton–Euler balances `m xG'' = -P sin`, `m yG'' = P cos + N - m g`,
    /// `I theta'' = P (d - ell/2) - (ell/2) cos N` (`d = r cot(theta/2)`), with
    /// `xG'' = kappa theta'' + kappa' theta'^2`, `yG'' = (ell/2)(cos theta'' - sin theta'^2)`.
    pub fn both_solve(&self, theta: f64, theta_dot: f64) -> (f64, f64, f64) {
        let (s, c) = theta.sin_cos();
        let (k, dk) = self.kappa(theta);
        let (m, l, w2) = (self.m1, self.ell, theta_dot * theta_dot);
        let d = self.tangent_distance(theta);
        let x = solve_linear(
            [
                [m * k, s, 0.0],
                [0.5 * m * l * c, -c, -1.0],
                [self.inertia(), -(d - 0.5 * l), 0.5 * l * c],
            ],
            [-m * dk * w2, 0.5 * m * l * s * w2 - m * self.g, 0.0],
        );
        (x[0], x[1], x[2])
    }

    /// The full state `([x1, y1, theta], [x1', y1', theta'])` on the both-contacts path at
    /// `(theta, theta')`: `x1 = -r cot(theta/2)`, `x1' = (r/(1 - cos)) theta'`, `y1 = 0`.
    pub fn both_state(&self, theta: f64, theta_dot: f64) -> ([f64; 3], [f64; 3]) {
        let h = (0.5 * theta).sin();
        (
            [-self.tangent_distance(theta), 0.0, theta],
            [self.r / (2.0 * h * h) * theta_dot, 0.0, theta_dot],
        )
    }

    /// The both-contacts phase from release with the default step (`sqrt(ell/g)/400`): see
    /// [`Cylinder::run_with_step`].
    pub fn run(&self) -> CylinderEnd {
        self.run_with_step((self.ell / self.g).sqrt() / 400.0)
    }

    /// The both-contacts phase from release integrated with step `h` (s), state
    /// `(theta, theta')`, until the first of `N = 0` (`FootLifts`), `P = 0` (`LeavesCylinder`),
    /// `r cot(theta/2) = ell` (`Edge`), or 100 `sqrt(ell/g)`. A contact force `<= 0` at release
    /// is reported at t = 0 (`LeavesAtRelease` first).
    pub fn run_with_step(&self, h: f64) -> CylinderEnd {
        let (p0, n0) = self.release_forces();
        let at_release = |event| CylinderEnd {
            event,
            t: 0.0,
            theta: self.th0,
            theta_dot: 0.0,
        };
        if p0 <= 0.0 {
            return at_release(CylinderEvent::LeavesAtRelease);
        }
        if n0 <= 0.0 {
            return at_release(CylinderEvent::FootLiftsAtRelease);
        }
        let f = |y: &[f64], out: &mut [f64]| {
            out[0] = y[1];
            out[1] = self.both_solve(y[0], y[1]).0;
        };
        let ev = |y: &[f64], out: &mut [f64]| {
            let (_, p, n) = self.both_solve(y[0], y[1]);
            out[0] = n;
            out[1] = p;
            out[2] = self.ell - self.tangent_distance(y[0]);
        };
        let t_max = 100.0 * (self.ell / self.g).sqrt();
        let hit = integrate(&f, &ev, 3, &[self.th0, 0.0], h, t_max);
        let event = match hit.event {
            Some(0) => CylinderEvent::FootLifts,
            Some(1) => CylinderEvent::LeavesCylinder,
            Some(_) => CylinderEvent::Edge,
            None => CylinderEvent::Timeout,
        };
        CylinderEnd {
            event,
            t: hit.t,
            theta: hit.y[0],
            theta_dot: hit.y[1],
        }
    }

    /// The cylinder's gap for a rod state `q = [x1, y1, theta]` (m): the distance from the axis
    /// `C = (0, r)` to the rod's line minus `r`, `-(C - F).n - r = -sin x1 - cos (r - y1) - r`
    /// with `n = (-sin, cos)` (zero when touching, positive when clear, the cylinder below the
    /// rod).
    pub fn gap(&self, q: &[f64; 3]) -> f64 {
        let (s, c) = q[2].sin_cos();
        -s * q[0] - c * (self.r - q[1]) - self.r
    }

    /// The tangent point's distance from the foot along the rod for a state `q = [x1, y1,
    /// theta]` (m): `d = -x1 cos + (r - y1) sin` (the projection of the axis on the rod's line).
    pub fn contact_distance(&self, q: &[f64; 3]) -> f64 {
        let (s, c) = q[2].sin_cos();
        -q[0] * c + (self.r - q[1]) * s
    }

    /// Residuals (N, N, N m) of the rod's Newton–Euler equations with the cylinder's push `p`
    /// (along `(-sin, cos)` at the tangent point, distance `d` from the foot) and a vertical push
    /// `n` at the foot, for `q = [x1, y1, theta]`, rates `qd`, accelerations `qdd`:
    /// `m xG'' + p sin`, `m yG'' - p cos - n + m g`, `I theta'' - p (d - ell/2) + (ell/2) cos n`,
    /// with `xG'' = x1'' - (ell/2)(sin theta'' + cos theta'^2)`,
    /// `yG'' = y1'' + (ell/2)(cos theta'' - sin theta'^2)`. All three vanish for the true motion
    /// with both contacts closed (`y1 = 0`, the gap zero).
    pub fn residuals_both(
        &self,
        q: &[f64; 3],
        qd: &[f64; 3],
        qdd: &[f64; 3],
        p: f64,
        n: f64,
    ) -> [f64; 3] {
        let (s, c) = q[2].sin_cos();
        let (m, l, w2) = (self.m1, self.ell, qd[2] * qd[2]);
        let xgdd = qdd[0] - 0.5 * l * (s * qdd[2] + c * w2);
        let ygdd = qdd[1] + 0.5 * l * (c * qdd[2] - s * w2);
        let d = self.contact_distance(q);
        [
            m * xgdd + p * s,
            m * ygdd - p * c - n + m * self.g,
            self.inertia() * qdd[2] - p * (d - 0.5 * l) + 0.5 * l * c * n,
        ]
    }

    /// Residuals of the rod's Newton–Euler equations after the foot has lifted (only the
    /// cylinder touching): [`Cylinder::residuals_both`] with `n = 0`. All three vanish for the
    /// true motion (the gap zero, `y1 > 0`).
    pub fn residuals_free_foot(
        &self,
        q: &[f64; 3],
        qd: &[f64; 3],
        qdd: &[f64; 3],
        p: f64,
    ) -> [f64; 3] {
        self.residuals_both(q, qd, qdd, p, 0.0)
    }

    /// Accelerations `[x1'', y1'', theta'']` and the cylinder's push `P` with only the cylinder
    /// touching: the three Newton–Euler equations of [`Cylinder::residuals_free_foot`] and the
    /// gap's second derivative `-sin x1'' + cos y1'' + d theta'' + b = 0`,
    /// `b = -2 theta' (cos x1' + sin y1') + theta'^2 (sin x1 + cos (r - y1))`.
    pub fn free_foot_solve(&self, q: &[f64; 3], qd: &[f64; 3]) -> ([f64; 3], f64) {
        let (s, c) = q[2].sin_cos();
        let (m, l) = (self.m1, self.ell);
        let (x1, y1) = (q[0], q[1]);
        let (v1, u1, w) = (qd[0], qd[1], qd[2]);
        let w2 = w * w;
        let d = self.contact_distance(q);
        let bias =
            -2.0 * c * w * v1 + s * w2 * x1 + c * self.r * w2 - 2.0 * s * w * u1 - c * w2 * y1;
        let x = solve_linear(
            [
                [m, 0.0, -0.5 * m * l * s, s],
                [0.0, m, 0.5 * m * l * c, -c],
                [0.0, 0.0, self.inertia(), -(d - 0.5 * l)],
                [-s, c, d, 0.0],
            ],
            [
                0.5 * m * l * c * w2,
                0.5 * m * l * s * w2 - m * self.g,
                0.0,
                -bias,
            ],
        );
        ([x[0], x[1], x[2]], x[3])
    }

    /// Total energy of the rod (J) for any state `q = [x1, y1, theta]`, `qd`: kinetic energy of
    /// the centre and about it plus `m g yG`.
    pub fn energy(&self, q: &[f64; 3], qd: &[f64; 3]) -> f64 {
        let (s, c) = q[2].sin_cos();
        let l = self.ell;
        let xgd = qd[0] - 0.5 * l * s * qd[2];
        let ygd = qd[1] + 0.5 * l * c * qd[2];
        0.5 * self.m1 * (xgd * xgd + ygd * ygd)
            + 0.5 * self.inertia() * qd[2] * qd[2]
            + self.m1 * self.g * (q[1] + 0.5 * l * s)
    }
}

// =============================================================================================
// C. rod_block_tipping (and the contact phase of D. rod_cube_liftoff)
// =============================================================================================

/// `rod_block_tipping`: the paper's rod (foot `(x1, y1)` on the frictionless floor, tip
/// `T = (x1 + ell cos, y1 + ell sin)`) pushing on the near (left) face of a block of width `w`,
/// height `h`, mass `m2` (moment of inertia `m2 (w^2 + h^2)/12`) on the frictionless floor.
/// Block centre `(xb, yb)`, angle `phi` (tipping forward about the far edge is `phi < 0`).
/// Released from rest with the tip at the block's top near corner: `sin(theta0) = h/ell`,
/// `x1 = y1 = 0`, `phi = 0`, `yb = h/2`, `xb = ell cos(theta0) + w/2`. With `w = h` it is the
/// paper's rod and cube with `a = h` (`rod_cube_liftoff`'s contact phase).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodBlock {
    /// Rod mass (kg).
    pub m1: f64,
    /// Block mass (kg).
    pub m2: f64,
    /// Rod length (m).
    pub ell: f64,
    /// Block width (m).
    pub w: f64,
    /// Block height (m), `< ell`.
    pub h: f64,
    /// Gravitational acceleration (m/s^2).
    pub g: f64,
}

/// Accelerations and forces while the block is flat and the rod touches it (both of the rod's
/// contacts closed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatAccel {
    /// `x1''` (m/s^2).
    pub x1_ddot: f64,
    /// `theta''` (rad/s^2).
    pub theta_ddot: f64,
    /// The push `P` between tip and block, normal to the face (N; +x on the block).
    pub p: f64,
    /// The floor's push on the rod's foot (N).
    pub n_foot: f64,
}

/// How the flat phase of [`RodBlock`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockEvent {
    /// `N_near <= 0` already at release: the block tips at once.
    TipsAtRelease,
    /// The near edge's floor push reached zero: the block starts to tip about its far edge.
    Tips,
    /// The far edge's floor push reached zero (never happens during contact: docs, section C).
    FarLifts,
    /// The push reached zero: the rod leaves the block (eq. 14 of the paper).
    Separates,
    /// The floor's push on the rod's foot reached zero (never happens: docs, section D).
    FootLifts,
    /// The rod reached the floor still touching.
    Floor,
    /// None of the above before the time limit.
    Timeout,
}

/// The end of the flat phase of [`RodBlock`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockEnd {
    /// What ended the phase.
    pub event: BlockEvent,
    /// Time from release (s).
    pub t: f64,
    /// Rod angle (rad).
    pub theta: f64,
    /// Rod angular velocity (rad/s).
    pub theta_dot: f64,
    /// Foot position (m).
    pub x1: f64,
    /// Foot velocity (m/s).
    pub x1_dot: f64,
}

impl RodBlock {
    /// The release angle `asin(h/ell)` (rad).
    pub fn theta0(&self) -> f64 {
        (self.h / self.ell).asin()
    }

    /// The rod's moment of inertia about its centre (kg m^2).
    fn inertia(&self) -> f64 {
        self.m1 * self.ell * self.ell / 12.0
    }

    /// The block's moment of inertia about its centre, `m2 (w^2 + h^2)/12` (kg m^2).
    pub fn block_inertia(&self) -> f64 {
        self.m2 * (self.w * self.w + self.h * self.h) / 12.0
    }

    /// Accelerations and forces with the block flat and sliding, the foot on the floor and the
    /// tip on the face (`x2 = x1 + ell cos`), at `(theta, theta')`: the four Newton–Euler
    /// equations `m1 xG'' = -P`, `m1 yG'' = N - m1 g`, `I theta'' = (ell/2)(sin P - cos N)`,
    /// `m2 x2'' = P` with `xG'' = x1'' - (ell/2)(sin theta'' + cos theta'^2)`,
    /// `yG'' = (ell/2)(cos theta'' - sin theta'^2)`,
    /// `x2'' = x1'' - ell (sin theta'' + cos theta'^2)`.
    pub fn flat_solve(&self, theta: f64, theta_dot: f64) -> FlatAccel {
        let (s, c) = theta.sin_cos();
        let (m1, m2, l, w2) = (self.m1, self.m2, self.ell, theta_dot * theta_dot);
        // unknowns [x1'', theta'', P, N]
        let x = solve_linear(
            [
                [m1, -0.5 * m1 * l * s, 1.0, 0.0],
                [0.0, 0.5 * m1 * l * c, 0.0, -1.0],
                [0.0, self.inertia(), -0.5 * l * s, 0.5 * l * c],
                [m2, -m2 * l * s, -1.0, 0.0],
            ],
            [
                0.5 * m1 * l * c * w2,
                0.5 * m1 * l * s * w2 - m1 * self.g,
                0.0,
                m2 * l * c * w2,
            ],
        );
        FlatAccel {
            x1_ddot: x[0],
            theta_ddot: x[1],
            p: x[2],
            n_foot: x[3],
        }
    }

    /// `theta'^2` on the contact path from rest (momentum and energy integrals):
    /// `4 (g/ell)(r - sin)/(4/3 - sin^2/(1 + n))`, `r = h/ell`, `n = m2/m1` (paper eq. 9).
    pub fn theta_dot_sq(&self, theta: f64) -> f64 {
        let n = self.m2 / self.m1;
        let s = theta.sin();
        4.0 * self.g / self.ell * sin_drop(self.theta0(), theta) / (4.0 / 3.0 - s * s / (1.0 + n))
    }

    /// The push on the contact path from rest (N): `m2 g` times [`cube_push`] with `r = h/ell`
    /// (the paper's eq. 16 with `a = h`).
    pub fn push(&self, theta: f64) -> f64 {
        self.m2 * self.g * cube_push(self.m2 / self.m1, self.h / self.ell, theta)
    }

    /// The floor's push on the block's near bottom edge while flat (N), from the block's moment
    /// balance: `N_near = m2 g/2 - P (y_tip - h/2)/w` with `y_tip = ell sin`.
    pub fn near_push(&self, theta: f64, p: f64) -> f64 {
        0.5 * self.m2 * self.g - p * (self.ell * theta.sin() - 0.5 * self.h) / self.w
    }

    /// The floor's push on the block's far bottom edge while flat (N):
    /// `N_far = m2 g/2 + P (y_tip - h/2)/w`.
    pub fn far_push(&self, theta: f64, p: f64) -> f64 {
        0.5 * self.m2 * self.g + p * (self.ell * theta.sin() - 0.5 * self.h) / self.w
    }

    /// The tipping ratio `P (y_tip - h/2) / (m2 g w/2)`: the near edge unloads (`N_near = 0`)
    /// when it reaches 1.
    pub fn tipping_ratio(&self, theta: f64, p: f64) -> f64 {
        p * (self.ell * theta.sin() - 0.5 * self.h) / (0.5 * self.m2 * self.g * self.w)
    }

    /// The flat phase from release with the default step (`sqrt(ell/g)/400`): see
    /// [`RodBlock::run_flat_with_step`].
    pub fn run_flat(&self) -> BlockEnd {
        self.run_flat_with_step((self.ell / self.g).sqrt() / 400.0)
    }

    /// The flat phase from release integrated with step `h` (s), state `(x1, theta, x1',
    /// theta')` with [`RodBlock::flat_solve`], until the first of `P = 0` (`Separates`),
    /// `N_near = 0` (`Tips`), `N_far = 0`, `N = 0` (foot), `theta = 0`, or 100 `sqrt(ell/g)`;
    /// `N_near <= 0` at release gives `TipsAtRelease` at t = 0.
    pub fn run_flat_with_step(&self, h: f64) -> BlockEnd {
        let th0 = self.theta0();
        let f = |y: &[f64], out: &mut [f64]| {
            let a = self.flat_solve(y[1], y[3]);
            out[0] = y[2];
            out[1] = y[3];
            out[2] = a.x1_ddot;
            out[3] = a.theta_ddot;
        };
        let ev = |y: &[f64], out: &mut [f64]| {
            let a = self.flat_solve(y[1], y[3]);
            out[0] = a.p;
            out[1] = self.near_push(y[1], a.p);
            out[2] = self.far_push(y[1], a.p);
            out[3] = a.n_foot;
            out[4] = y[1];
        };
        let t_max = 100.0 * (self.ell / self.g).sqrt();
        let hit = integrate(&f, &ev, 5, &[0.0, th0, 0.0, 0.0], h, t_max);
        let event = match (hit.event, hit.t) {
            (Some(1), 0.0) => BlockEvent::TipsAtRelease,
            (Some(0), _) => BlockEvent::Separates,
            (Some(1), _) => BlockEvent::Tips,
            (Some(2), _) => BlockEvent::FarLifts,
            (Some(3), _) => BlockEvent::FootLifts,
            (Some(_), _) => BlockEvent::Floor,
            (None, _) => BlockEvent::Timeout,
        };
        BlockEnd {
            event,
            t: hit.t,
            theta: hit.y[1],
            theta_dot: hit.y[3],
            x1: hit.y[0],
            x1_dot: hit.y[2],
        }
    }

    /// The six-coordinate state `q = [x1, y1, theta, xb, yb, phi]`, `qd` at a point of the flat
    /// phase: `y1 = 0`, `xb = x1 + ell cos + w/2`, `yb = h/2`, `phi = 0`,
    /// `xb' = x1' - ell sin theta'`.
    pub fn flat_state(&self, end: &BlockEnd) -> ([f64; 6], [f64; 6]) {
        let (s, c) = end.theta.sin_cos();
        let l = self.ell;
        (
            [
                end.x1,
                0.0,
                end.theta,
                end.x1 + l * c + 0.5 * self.w,
                0.5 * self.h,
                0.0,
            ],
            [
                end.x1_dot,
                0.0,
                end.theta_dot,
                end.x1_dot - l * s * end.theta_dot,
                0.0,
                0.0,
            ],
        )
    }

    /// The block's bottom near corner `(xb, yb) + Rot(phi)(-w/2, -h/2)` for `qb = [xb, yb, phi]`.
    pub fn near_corner(&self, qb: &[f64; 3]) -> [f64; 2] {
        let (sp, cp) = qb[2].sin_cos();
        let (hw, hh) = (0.5 * self.w, 0.5 * self.h);
        [qb[0] - hw * cp + hh * sp, qb[1] - hw * sp - hh * cp]
    }

    /// The block's bottom far corner `(xb, yb) + Rot(phi)(w/2, -h/2)` for `qb = [xb, yb, phi]`.
    pub fn far_corner(&self, qb: &[f64; 3]) -> [f64; 2] {
        let (sp, cp) = qb[2].sin_cos();
        let (hw, hh) = (0.5 * self.w, 0.5 * self.h);
        [qb[0] + hw * cp + hh * sp, qb[1] + hw * sp - hh * cp]
    }

    /// Residuals (N, N, N m) of the block's Newton–Euler equations for `qb = [xb, yb, phi]`,
    /// accelerations `qbdd`, the rod's push `p` at the point `tip` (on the near face, along the
    /// face's inward normal `(cos phi, sin phi)`) and the floor's vertical pushes `n_near`,
    /// `n_far` on the bottom corners: `m2 xb'' - p cos phi`,
    /// `m2 yb'' - (p sin phi + n_near + n_far - m2 g)`,
    /// `I_b phi'' - [(tip - B) x p (cos phi, sin phi) + (near - B) x (0, n_near) +
    /// (far - B) x (0, n_far)]`. (No velocity enters a rigid body's balances about its centre.)
    pub fn block_residuals(
        &self,
        qb: &[f64; 3],
        qbdd: &[f64; 3],
        tip: [f64; 2],
        p: f64,
        n_near: f64,
        n_far: f64,
    ) -> [f64; 3] {
        let (sp, cp) = qb[2].sin_cos();
        let (dx, dy) = (tip[0] - qb[0], tip[1] - qb[1]);
        let near = self.near_corner(qb);
        let far = self.far_corner(qb);
        let torque =
            p * (dx * sp - dy * cp) + (near[0] - qb[0]) * n_near + (far[0] - qb[0]) * n_far;
        [
            self.m2 * qbdd[0] - p * cp,
            self.m2 * qbdd[1] - (p * sp + n_near + n_far - self.m2 * self.g),
            self.block_inertia() * qbdd[2] - torque,
        ]
    }

    /// Residuals (N, N, N m) of the rod's Newton–Euler equations for `q = [x1, y1, theta]`,
    /// `qd`, `qdd`, with the block's push `-p (cos phi, sin phi)` at the tip and the floor's
    /// vertical push `n_foot` at the foot: `m1 xG'' + p cos phi`,
    /// `m1 yG'' - n_foot + p sin phi + m1 g`,
    /// `I theta'' + (ell/2) cos n_foot - (ell/2) sin(theta - phi) p`.
    pub fn rod_residuals(
        &self,
        q: &[f64; 3],
        qd: &[f64; 3],
        qdd: &[f64; 3],
        p: f64,
        phi: f64,
        n_foot: f64,
    ) -> [f64; 3] {
        let (s, c) = q[2].sin_cos();
        let (sp, cp) = phi.sin_cos();
        let (m1, l, w2) = (self.m1, self.ell, qd[2] * qd[2]);
        let xgdd = qdd[0] - 0.5 * l * (s * qdd[2] + c * w2);
        let ygdd = qdd[1] + 0.5 * l * (c * qdd[2] - s * w2);
        [
            m1 * xgdd + p * cp,
            m1 * ygdd - n_foot + p * sp + m1 * self.g,
            self.inertia() * qdd[2] + 0.5 * l * c * n_foot - 0.5 * l * (q[2] - phi).sin() * p,
        ]
    }

    /// The tipping phase (the foot on the floor, the tip on the near face, the block on its far
    /// edge, the near edge lifted): accelerations `q''` for `q = [x1, y1, theta, xb, yb, phi]`
    /// and forces `[n_foot, p, n_far]`, from the six Newton–Euler equations of
    /// [`RodBlock::rod_residuals`] and [`RodBlock::block_residuals`] (`n_near = 0`) and the
    /// second derivatives of the three contact conditions `y1 = 0`,
    /// `yb + (w/2) sin phi - (h/2) cos phi = 0`, `(T - B).(cos phi, sin phi) + w/2 = 0`.
    pub fn tipping_solve(&self, q: &[f64; 6], qd: &[f64; 6]) -> ([f64; 6], [f64; 3]) {
        let (m1, m2, l) = (self.m1, self.m2, self.ell);
        let (s, c) = q[2].sin_cos();
        let (sp, cp) = q[5].sin_cos();
        let (w, wp) = (qd[2], qd[5]);
        let (hw, hh) = (0.5 * self.w, 0.5 * self.h);
        let tip = [q[0] + l * c, q[1] + l * s];
        let (dx, dy) = (tip[0] - q[3], tip[1] - q[4]);
        let (ddx, ddy) = (qd[0] - l * s * w - qd[3], qd[1] + l * c * w - qd[4]);
        let far_arm = hw * cp + hh * sp; // (far - B)_x
        let d_uperp = -dx * sp + dy * cp;
        let d_u = dx * cp + dy * sp;
        let dd_uperp = -ddx * sp + ddy * cp;
        // unknowns [x1'', y1'', theta'', xb'', yb'', phi'', N, P, N_far]
        let a = [
            [m1, 0.0, -0.5 * m1 * l * s, 0.0, 0.0, 0.0, 0.0, cp, 0.0],
            [0.0, m1, 0.5 * m1 * l * c, 0.0, 0.0, 0.0, -1.0, sp, 0.0],
            [
                0.0,
                0.0,
                self.inertia(),
                0.0,
                0.0,
                0.0,
                0.5 * l * c,
                -0.5 * l * (q[2] - q[5]).sin(),
                0.0,
            ],
            [0.0, 0.0, 0.0, m2, 0.0, 0.0, 0.0, -cp, 0.0],
            [0.0, 0.0, 0.0, 0.0, m2, 0.0, 0.0, -sp, -1.0],
            [
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                self.block_inertia(),
                0.0,
                -(dx * sp - dy * cp),
                -far_arm,
            ],
            [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 1.0, hw * cp + hh * sp, 0.0, 0.0, 0.0],
            [
                cp,
                sp,
                -l * (q[2] - q[5]).sin(),
                -cp,
                -sp,
                d_uperp,
                0.0,
                0.0,
                0.0,
            ],
        ];
        let b = [
            0.5 * m1 * l * c * w * w,
            0.5 * m1 * l * s * w * w - m1 * self.g,
            0.0,
            0.0,
            -m2 * self.g,
            0.0,
            0.0,
            hw * sp * wp * wp - hh * cp * wp * wp,
            l * w * w * (c * cp + s * sp) - 2.0 * wp * dd_uperp + wp * wp * d_u,
        ];
        let x = solve_linear(a, b);
        ([x[0], x[1], x[2], x[3], x[4], x[5]], [x[6], x[7], x[8]])
    }

    /// Total energy (J) of rod and block for `q = [x1, y1, theta, xb, yb, phi]`, `qd`.
    pub fn energy(&self, q: &[f64; 6], qd: &[f64; 6]) -> f64 {
        let (s, c) = q[2].sin_cos();
        let l = self.ell;
        let xgd = qd[0] - 0.5 * l * s * qd[2];
        let ygd = qd[1] + 0.5 * l * c * qd[2];
        0.5 * self.m1 * (xgd * xgd + ygd * ygd)
            + 0.5 * self.inertia() * qd[2] * qd[2]
            + self.m1 * self.g * (q[1] + 0.5 * l * s)
            + 0.5 * self.m2 * (qd[3] * qd[3] + qd[4] * qd[4])
            + 0.5 * self.block_inertia() * qd[5] * qd[5]
            + self.m2 * self.g * q[4]
    }
}

// =============================================================================================
// C/D. Dimensionless closed forms on the contact path (n = m2/m1, r = a/ell, M = 1 + n)
// =============================================================================================

/// `K = M (12 sin - 8 r) - 3 sin^3`: the push is `m2 g 3 cos K/(4M - 3 sin^2)^2`, positive while
/// the rod touches the cube.
fn contact_k(n: f64, r: f64, s: f64) -> f64 {
    (1.0 + n) * (12.0 * s - 8.0 * r) - 3.0 * s * s * s
}

/// `sin(theta_sep)`, the root of `K = (1 + n)(12 s - 8 r) - 3 s^3` in `(2r/3, r)` (the paper's
/// eq. 14; `K(2r/3) = -8 r^3/9 < 0 < K(r) = r (4(1 + n) - 3 r^2)`), by bisection on
/// `K/(1 + n)` to the last bit.
pub fn separation_sin(n: f64, r: f64) -> f64 {
    let f = |s: f64| 12.0 * s - 8.0 * r - 3.0 * s * s * s / (1.0 + n);
    let (mut lo, mut hi) = (2.0 * r / 3.0, r);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The push `P/(m2 g)` on the contact path from rest, `3 cos K / (4M - 3 sin^2)^2` (re-derived
/// from Newton–Euler with the momentum and energy integrals; the paper's eq. 16 divided by
/// `m2 g`).
pub fn cube_push(n: f64, r: f64, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    let den = 4.0 * (1.0 + n) - 3.0 * s * s;
    3.0 * c * contact_k(n, r, s) / (den * den)
}

/// The cube's (`w = h = a`) tipping ratio `P (y_tip - a/2)/(m2 g a/2)` on the contact path:
/// `3 cos K (2 sin - r) / (r (4M - 3 sin^2)^2)`. It is `<= 3 cos sin/(1 + 3 cos^2) <= 3/4`
/// (docs, section C), so a cube never tips; a block of width `w` has this times `h/w`.
pub fn cube_tipping_ratio(n: f64, r: f64, theta: f64) -> f64 {
    cube_push(n, r, theta) * (2.0 * theta.sin() - r) / r
}

/// The supremum of [`cube_tipping_ratio`] over `n > 0`, `r` in (0, 1) and the contact phase:
/// 3/4, approached at release as `n -> 0` with `r = 2/sqrt(5)` (`cos^2(theta0) = 1/5`).
pub const CUBE_TIPPING_SUP: f64 = 0.75;

/// The floor's push on the rod's foot `N/(m1 g)` on the paper's contact path from rest,
/// `1/4 + 3 sin (4M - 3) K / (4 (4M - 3 sin^2)^2)`, i.e. `N = m1 g/4 + (1 + 4n) tan P/(4n)`:
/// above `m1 g/4` during contact, exactly `m1 g/4` at separation (docs, section D).
pub fn liftoff_floor_push(n: f64, r: f64, theta: f64) -> f64 {
    let s = theta.sin();
    let m = 1.0 + n;
    let den = 4.0 * m - 3.0 * s * s;
    0.25 + 3.0 * s * (4.0 * m - 3.0) * contact_k(n, r, s) / (4.0 * den * den)
}

/// Extremes of `N/(m1 g)` over a scan of the contact phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiftScan {
    /// The smallest `N/(m1 g)` seen.
    pub min: f64,
    /// `(n, r, theta)` where it was seen.
    pub at_min: (f64, f64, f64),
    /// The largest `N/(m1 g)` seen.
    pub max: f64,
    /// `(n, r, theta)` where it was seen.
    pub at_max: (f64, f64, f64),
}

/// Scans [`liftoff_floor_push`] over `ns` x `rs`, each contact phase sampled at `samples + 1`
/// angles evenly spaced in `sin` from `sin(theta_sep)` to `r` (both ends included).
pub fn liftoff_scan(ns: &[f64], rs: &[f64], samples: usize) -> LiftScan {
    let mut out = LiftScan {
        min: f64::INFINITY,
        at_min: (0.0, 0.0, 0.0),
        max: f64::NEG_INFINITY,
        at_max: (0.0, 0.0, 0.0),
    };
    for &n in ns {
        for &r in rs {
            let ss = separation_sin(n, r);
            for k in 0..=samples {
                let s = ss + (r - ss) * k as f64 / samples as f64;
                let theta = s.min(r).asin();
                let v = liftoff_floor_push(n, r, theta);
                if v < out.min {
                    out.min = v;
                    out.at_min = (n, r, theta);
                }
                if v > out.max {
                    out.max = v;
                    out.at_max = (n, r, theta);
                }
            }
        }
    }
    out
}
