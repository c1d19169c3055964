//! The generated model code (`generated/*.rs`, no Symbolica) against the paper's formulas typed
//! in by hand, at 1,000 random parameter points each: the contact phase of rod_cube
//! (`rod_cube_closed`) against eq (5), (9), corrected (12), (14), (16), (18) and (22), its tip on
//! the ellipse of eq (21) and the floor's push with its quartic; the contact phases of the hinged
//! rod and of the ladder on a wall against their closed forms (PHYSICS.md), the hinge's two
//! forces and the ladder's floor with theirs. Errors are relative to the size of the terms of
//! each formula, so a formula that crosses zero (the contact force at separation) is judged by
//! the digits it carries, not by the digits it cancels.

use rodcube::model::Model;
use std::collections::BTreeMap;

const POINTS: usize = 1000;
const TOL: f64 = 1e-12;

/// SplitMix64: a deterministic, dependency-free generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in the open interval (lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = ((self.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.uniform(lo.ln(), hi.ln()).exp()
    }
}

/// Largest error seen per quantity, each error already divided by its scale.
#[derive(Default)]
struct Worst(BTreeMap<&'static str, (f64, String)>);

impl Worst {
    /// Records `|got - want| / scale` for `what`.
    fn check(&mut self, what: &'static str, got: f64, want: f64, scale: f64, at: &str) {
        let err = if got == want {
            0.0
        } else {
            (got - want).abs() / scale.abs()
        };
        let entry = self.0.entry(what).or_insert((0.0, String::new()));
        // A NaN error is the worst of all.
        if err.is_nan() || err > entry.0 {
            *entry = (err, at.to_string());
        }
    }
    /// The quantities whose error exceeds `tol`, with where.
    fn above(&self, tol: f64) -> Vec<String> {
        self.0
            .iter()
            .filter(|(_, (err, _))| err.is_nan() || *err > tol)
            .map(|(what, (err, at))| format!("{what}: {err:.3e} at {at}"))
            .collect()
    }
    /// Prints the table (shown with `--nocapture`) and asserts every error is within `tol`.
    fn assert_within(&self, model: &str, tol: f64) {
        for (what, (err, _)) in &self.0 {
            println!("{model:>12} {what:<24} max error {err:.3e}");
        }
        let bad = self.above(tol);
        assert!(
            bad.is_empty(),
            "{model}: errors above {tol:e}:\n{}",
            bad.join("\n")
        );
    }
}

/// Parameter vector in the model's order, from names.
fn params(model: &dyn Model, values: &[(&str, f64)]) -> Vec<f64> {
    model
        .info()
        .parameters
        .iter()
        .map(|p| {
            values
                .iter()
                .find(|(n, _)| *n == p.name)
                .unwrap_or_else(|| panic!("no value for {}", p.name))
                .1
        })
        .collect()
}

fn prepare(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut req = vec![0.0; model.info().requirements.len()];
    model.requirements(p, &mut req);
    assert!(
        req.iter().all(|m| *m > 0.0),
        "requirements {req:?} for {p:?}"
    );
    let mut k = vec![f64::NAN; model.info().n_constants];
    model.prepare(p, &mut k);
    assert!(k.iter().all(|x| x.is_finite()), "prepare left {k:?}");
    k
}

fn find(name: &str) -> &'static dyn Model {
    rodcube::models::find(name).unwrap_or_else(|| panic!("model {name} not generated"))
}

fn index(list: &[rodcube::model::NamedInfo], name: &str) -> usize {
    list.iter()
        .position(|x| x.name == name)
        .unwrap_or_else(|| panic!("no {name}"))
}

fn contact_index(info: &rodcube::model::ModelInfo, name: &str) -> usize {
    (info.contacts.iter())
        .position(|c| c.name == name)
        .unwrap_or_else(|| panic!("no contact {name}"))
}

/// Contact `contact`'s force polynomial of `model` (its degree from the layout).
fn force_polynomial(model: &dyn Model, k: &[f64], contact: usize) -> Vec<f64> {
    let degree = model.info().reduction.unwrap().force_degrees[contact];
    let mut coef = vec![f64::NAN; degree + 1];
    model
        .reduction()
        .unwrap()
        .force_polynomial(k, contact, &mut coef);
    coef
}

/// `sum c_k s^k`.
fn horner(c: &[f64], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, ck| acc * s + ck)
}

/// The root in (0, hi) of `sum c_k s^k` by bisection to the last bit (one sign change assumed).
fn root(c: &[f64], hi: f64) -> f64 {
    let p = |s: f64| c.iter().rev().fold(0.0, |acc, ck| acc * s + ck);
    let (mut lo, mut hi) = (0.0f64, hi);
    let (plo, phi) = (p(lo), p(hi));
    assert!(
        plo * phi < 0.0,
        "no sign change: p(0) = {plo}, p(hi) = {phi}, c = {c:?}"
    );
    for _ in 0..2000 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if (p(mid) < 0.0) == (plo < 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `sin(theta_i) - sin(theta)` and `cos(theta) - cos(theta_i)` at `theta = theta_i - delta`,
/// from sum-to-product identities (no cancellation; independent of the model's own formula).
fn gaps(theta_i: f64, delta: f64) -> (f64, f64) {
    let h = (0.5 * delta).sin();
    (
        2.0 * (theta_i - 0.5 * delta).cos() * h,
        2.0 * (theta_i - 0.5 * delta).sin() * h,
    )
}

/// Full state and points on the reduced motion.
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    pos: Vec<[f64; 2]>,
    vel: Vec<[f64; 2]>,
}

fn state(model: &dyn Model, k: &[f64], t: f64, delta: f64, theta_dot: f64) -> State {
    let info = model.info();
    let n = info.coordinates.len();
    let (mut q, mut qd) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    model
        .reduction()
        .unwrap()
        .full_state(k, t, delta, theta_dot, &mut q, &mut qd);
    let m = info.points.len();
    let (mut pos, mut vel) = (vec![[f64::NAN; 2]; m], vec![[f64::NAN; 2]; m]);
    model.points(k, &q, &qd, &mut pos, &mut vel);
    State { q, qd, pos, vel }
}

// ---------------------------------------------------------------------------------------------

#[test]
fn rod_cube_agrees_with_the_papers_formulas_at_1000_random_points() {
    let model = find("rod_cube_closed");
    let info = model.info();
    assert_eq!(info.coordinates, ["x1", "theta"]);
    assert_eq!(info.reduction.unwrap().separation_degree(), 3);
    assert_eq!(info.reduction.unwrap().force_degrees, [3, 4]);
    let (contact, floor) = (
        contact_index(info, "contact_force"),
        contact_index(info, "floor_normal"),
    );
    let (foot, tip, centre, cube) = (
        index(info.points, "foot"),
        index(info.points, "tip"),
        index(info.points, "rod_centre"),
        index(info.points, "cube"),
    );
    let mut rng = Rng(0x0D0C_0BE5);
    let mut worst = Worst::default();
    for i in 0..POINTS {
        let m1 = rng.log_uniform(0.1, 10.0);
        let n = rng.log_uniform(1e-3, 1e3);
        let ell = rng.log_uniform(0.1, 10.0);
        let r = rng.uniform(0.01, 0.99);
        let g = rng.uniform(1.0, 30.0);
        let (m2, a) = (n * m1, r * ell);
        let r = a / ell; // the ratio the model sees
        let theta_i = r.asin();
        let delta = rng.uniform(0.0, theta_i);
        let at = format!("#{i}: m1={m1:e} n={n:e} ell={ell:e} r={r} g={g} delta={delta:e}");
        let p = params(
            model,
            &[("m1", m1), ("m2", m2), ("ell", ell), ("a", a), ("g", g)],
        );
        let k = prepare(model, &p);
        assert!((k[info.reduction.unwrap().k_theta_initial] - theta_i).abs() <= 1e-15 * theta_i);
        assert_eq!(k[info.reduction.unwrap().k_theta_dot_initial], 0.0);

        let theta = theta_i - delta;
        let (s, c) = theta.sin_cos();
        let (r_minus_s, c_minus_beta) = gaps(theta_i, delta);
        let beta = (1.0 - r * r).sqrt();
        let red = model.reduction().unwrap().reduced(&k, delta);
        worst.check("sin", red.sin, s, 1.0, &at);
        worst.check("cos", red.cos, c, 1.0, &at);

        // Eq (9).
        let dd = 4.0 / 3.0 - s * s / (1.0 + n);
        let w2 = 4.0 * (g / ell) * r_minus_s / dd;
        worst.check("eq9 theta_dot_sq", red.theta_dot_sq, w2, w2, &at);
        // The same from sin, cos and their drops (the lean solver's integrand).
        assert_eq!(k[info.reduction.unwrap().k_sin_initial], r);
        worst.check(
            "cos theta_i",
            k[info.reduction.unwrap().k_cos_initial],
            beta,
            1.0,
            &at,
        );
        let w2_sc = model
            .reduction()
            .unwrap()
            .theta_dot_sq_sc(&k, s, c, r_minus_s, -c_minus_beta);
        worst.check("eq9 theta_dot_sq_sc", w2_sc, w2, w2, &at);
        // PHYSICS.md erratum 2, the corrected eq (12).
        let (t1, t2) = (-c / dd, r_minus_s * 2.0 * s * c / ((1.0 + n) * dd * dd));
        let acc = 2.0 * g / ell * (t1 + t2);
        let acc_scale = 2.0 * g / ell * (t1.abs() + t2.abs());
        worst.check("eq12 theta_ddot", red.theta_ddot, acc, acc_scale, &at);

        // Eq (16) and the floor's push N = m1 (g + y_cm'').
        let mut f = vec![f64::NAN; info.contacts.len()];
        model.reduction().unwrap().forces(&k, delta, &mut f);
        let bracket = 8.0 * r * (1.0 + n) - 12.0 * (1.0 + n) * s + 3.0 * s.powi(3);
        let bracket_scale = 8.0 * r * (1.0 + n) + 12.0 * (1.0 + n) * s + 3.0 * s.powi(3);
        let den = (4.0 * (1.0 + n) - 3.0 * s * s).powi(2);
        let f16 = m2 * (-3.0 * g * c * bracket / den);
        let f16_scale = m2 * 3.0 * g * c * bracket_scale / den;
        worst.check("eq16 contact_force", f[contact], f16, f16_scale, &at);
        let normal = m1 * (g + 0.5 * ell * (c * acc - s * w2));
        let normal_scale = m1 * (g + 0.5 * ell * (c * acc_scale + s * w2));
        worst.check("floor_normal", f[floor], normal, normal_scale, &at);
        // The floor's push as a quartic: N D^2 / (m1 g) with D = 4/3 - mu s^2, mu = 1/(1+n),
        // from N above and eqs (9), (12) (tests/common/paper.rs), up to a positive factor.
        let mu = 1.0 / (1.0 + n);
        let quartic = [
            4.0 / 9.0,
            2.0 * mu * r - 8.0 * r / 3.0,
            4.0 - 11.0 * mu / 3.0,
            0.0,
            mu * mu - mu,
        ];
        let floor_coef = force_polynomial(model, &k, floor);
        let factor = floor_coef[0] / quartic[0];
        assert!(factor > 0.0, "{at}: {floor_coef:?}");
        for (j, (got, want)) in floor_coef.iter().zip(quartic).enumerate() {
            let name = ["floor c0", "floor c1", "floor c2", "floor c3", "floor c4"][j];
            worst.check(name, got / factor, want, 4.0, &at);
        }
        let quartic_scale: f64 = quartic.iter().map(|q| q.abs()).sum();
        worst.check(
            "floor quartic",
            horner(&quartic, s),
            normal * dd * dd / (m1 * g),
            quartic_scale,
            &at,
        );

        // Eq (14): compare the polynomial up to scale (divided by 1+n) and its root in (0, r).
        let coef = force_polynomial(model, &k, contact);
        assert_eq!(coef.len(), 4);
        let eq14 = [8.0 * r, -12.0, 0.0, 3.0 / (1.0 + n)];
        let scale = coef[1] / eq14[1];
        for (j, (got, want)) in coef.iter().zip(eq14).enumerate() {
            let name = ["eq14 c0", "eq14 c1", "eq14 c2", "eq14 c3"][j];
            worst.check(name, got / scale, want, 12.0, &at);
        }
        let s_sep = root(&coef, r);
        worst.check("eq14 root", s_sep, root(&eq14, r), s_sep, &at);
        assert!(s_sep > 0.0 && s_sep < r);

        // Eq (18) and eq (5) from the full state (theta' < 0 while falling).
        let theta_dot = -red.theta_dot_sq.sqrt();
        let st = state(model, &k, 0.37, delta, theta_dot);
        let lever = (1.0 + 2.0 * n) / (2.0 * (1.0 + n)) * ell;
        worst.check(
            "eq18 x1",
            st.q[0],
            -lever * c_minus_beta,
            lever * c_minus_beta,
            &at,
        );
        worst.check("theta", st.q[1], theta, theta, &at);
        let x1_dot = lever * s * theta_dot;
        worst.check("eq5 x1_dot", st.qd[0], x1_dot, x1_dot, &at);
        assert_eq!(st.qd[1], theta_dot);

        // Eq (22): the tip; eq (21): it stays on the ellipse.
        let x2 = ell * c / (2.0 * (1.0 + n)) + (1.0 + 2.0 * n) * ell * beta / (2.0 * (1.0 + n));
        worst.check("eq22 tip x", st.pos[tip][0], x2, x2, &at);
        worst.check("eq22 tip y", st.pos[tip][1], ell * s, ell * s, &at);
        let u = 2.0 * (1.0 + n) * st.pos[tip][0] / ell;
        let v = st.pos[tip][1] / ell;
        let on_ellipse = (u - (1.0 + 2.0 * n) * beta).powi(2) + v * v;
        // The residual carries the rounding of u, whose size is up to (1+2n) beta + 1.
        let ellipse_scale = 2.0 * (u.abs() + (1.0 + 2.0 * n) * beta) + 1.0;
        worst.check("eq21 ellipse", on_ellipse, 1.0, ellipse_scale, &at);
        // x2' = x1' - ell s theta' is computed from two terms that nearly cancel for a heavy
        // cube (ratio 2(1+n)), so its error is measured against their size.
        let x2_dot = -ell * s * theta_dot / (2.0 * (1.0 + n));
        let x2_dot_scale = (x1_dot.abs() + ell * s * theta_dot.abs()).max(x2_dot.abs());
        worst.check("tip x_dot", st.vel[tip][0], x2_dot, x2_dot_scale, &at);
        worst.check(
            "tip y_dot",
            st.vel[tip][1],
            ell * c * theta_dot,
            ell * theta_dot,
            &at,
        );
        // The other points: foot on the floor at x1, the rod's centre, the cube's corner at x2.
        worst.check("foot x", st.pos[foot][0], st.q[0], ell, &at);
        assert_eq!(st.pos[foot][1], 0.0);
        worst.check(
            "centre x",
            st.pos[centre][0],
            st.q[0] + 0.5 * ell * c,
            ell,
            &at,
        );
        worst.check("centre y", st.pos[centre][1], 0.5 * ell * s, ell, &at);
        worst.check("cube x", st.pos[cube][0], x2, x2, &at);
        // The system's state this phase stands for: the foot on the floor, the cube's face at
        // the tip (eq 22), moving with it.
        let (mut q_full, mut qd_full) = (vec![f64::NAN; 4], vec![f64::NAN; 4]);
        model.to_full(&k, &st.q, &st.qd, &mut q_full, &mut qd_full);
        assert_eq!(
            (q_full[0], q_full[1], q_full[2]),
            (st.q[0], 0.0, st.q[1]),
            "{at}"
        );
        assert_eq!(
            (qd_full[0], qd_full[1], qd_full[2]),
            (st.qd[0], 0.0, st.qd[1]),
            "{at}"
        );
        worst.check("to_full x2", q_full[3], x2, x2, &at);
        worst.check("to_full x2_dot", qd_full[3], x2_dot, x2_dot_scale, &at);

        // Energy is that of the start (eq 8) and the horizontal momentum stays zero (eq 4).
        let e0 = m1 * g * a / 2.0 + m2 * g * a / 2.0;
        worst.check("eq8 energy", model.energy(&k, &st.q, &st.qd), e0, e0, &at);
        let mut mom = [f64::NAN];
        model.momenta(&k, &st.q, &st.qd, &mut mom);
        let mom_scale = (m1 + m2) * ell * theta_dot.abs();
        worst.check("eq4 momentum", mom[0], 0.0, mom_scale, &at);
    }
    worst.assert_within("rod_cube_closed", TOL);
}

#[test]
fn rod_cube_keeps_its_digits_at_extreme_mass_ratios() {
    // PHYSICS.md: n from 1e-12 to 1e12 must not lose digits. The contact force once did (its
    // expanded coefficients nearly cancelled, ~n eps relative error: 1.6e-3 at n = 1e12).
    let model = find("rod_cube_closed");
    let info = model.info();
    let contact = contact_index(info, "contact_force");
    let mut worst = Worst::default();
    for e in -12..=12 {
        let n = 10f64.powi(e);
        for (r, frac) in [(0.25, 0.3), (0.9, 0.05), (0.02, 0.7)] {
            let (m1, ell, g) = (1.0, 1.0, 9.81);
            let p = params(
                model,
                &[("m1", m1), ("m2", n * m1), ("ell", ell), ("a", r), ("g", g)],
            );
            let k = prepare(model, &p);
            let theta_i = f64::asin(r);
            let delta = frac * theta_i;
            let at = format!("n = {n:e}, r = {r}");
            let (s, c) = (theta_i - delta).sin_cos();
            let (r_minus_s, _) = gaps(theta_i, delta);
            let red = model.reduction().unwrap().reduced(&k, delta);
            let dd = 4.0 / 3.0 - s * s / (1.0 + n);
            let w2 = 4.0 * (g / ell) * r_minus_s / dd;
            worst.check("theta_dot_sq", red.theta_dot_sq, w2, w2, &at);
            let (t1, t2) = (-c / dd, r_minus_s * 2.0 * s * c / ((1.0 + n) * dd * dd));
            let acc = 2.0 * g / ell * (t1 + t2);
            worst.check("theta_ddot", red.theta_ddot, acc, acc, &at);
            let mut f = vec![f64::NAN; info.contacts.len()];
            model.reduction().unwrap().forces(&k, delta, &mut f);
            // Eq (16) divided through by (1+n)^2, so that it is exact for any n.
            let cubic = 8.0 * r - 12.0 * s + 3.0 * s.powi(3) / (1.0 + n);
            let den = (4.0 - 3.0 * s * s / (1.0 + n)).powi(2);
            let f16 = -3.0 * g * c * cubic / den * (n * m1 / (1.0 + n));
            worst.check("contact_force", f[contact], f16, f16, &at);
            let coef = force_polynomial(model, &k, contact);
            let eq14 = [8.0 * r, -12.0, 0.0, 3.0 / (1.0 + n)];
            let s_sep = root(&coef, r);
            worst.check("separation root", s_sep, root(&eq14, r), s_sep, &at);
        }
    }
    worst.assert_within("rod_cube_closed extreme n", TOL);
}

#[test]
fn hinged_rod_agrees_with_its_closed_forms() {
    // theta'^2 = 3 (g/ell) (r - s)/(1 + 3 n s^2); separation 3 n s^3 + 3 s - 2 r = 0;
    // F = (3/2) m2 g c (3 n s^3 + 3 s - 2 r)/(1 + 3 n s^2)^2. The hinge holds the rod's foot:
    // Newton for the rod's centre (ell/2)(c, s) gives its two forces.
    let model = find("hinged_rod_closed");
    let info = model.info();
    assert_eq!(info.coordinates, ["theta"]);
    assert_eq!(info.reduction.unwrap().separation_degree(), 3);
    let (contact, horizontal, vertical) = (
        contact_index(info, "contact_force"),
        contact_index(info, "hinge_horizontal"),
        contact_index(info, "hinge_vertical"),
    );
    assert!(info.contacts[horizontal].bilateral && info.contacts[vertical].bilateral);
    let tip = index(info.points, "tip");
    let mut rng = Rng(0x41_4E_47_45);
    let mut worst = Worst::default();
    for i in 0..POINTS {
        let m1 = rng.log_uniform(0.1, 10.0);
        let n = rng.log_uniform(1e-3, 1e3);
        let ell = rng.log_uniform(0.1, 10.0);
        let r = rng.uniform(0.01, 0.99);
        let g = rng.uniform(1.0, 30.0);
        let (m2, a) = (n * m1, r * ell);
        let r = a / ell; // the ratio the model sees
        let theta_i = r.asin();
        let delta = rng.uniform(0.0, theta_i);
        let at = format!("#{i}: n={n:e} r={r} delta={delta:e}");
        let p = params(
            model,
            &[("m1", m1), ("m2", m2), ("ell", ell), ("a", a), ("g", g)],
        );
        let k = prepare(model, &p);
        let (s, c) = (theta_i - delta).sin_cos();
        let (r_minus_s, _) = gaps(theta_i, delta);
        let red = model.reduction().unwrap().reduced(&k, delta);
        let den = 1.0 + 3.0 * n * s * s;
        let w2 = 3.0 * (g / ell) * r_minus_s / den;
        worst.check("theta_dot_sq", red.theta_dot_sq, w2, w2, &at);
        let acc = 1.5 * g * c / ell * (-den - 6.0 * n * s * r_minus_s) / (den * den);
        worst.check("theta_ddot", red.theta_ddot, acc, acc, &at);
        let mut f = vec![f64::NAN; info.contacts.len()];
        model.reduction().unwrap().forces(&k, delta, &mut f);
        let cubic = 3.0 * n * s.powi(3) + 3.0 * s - 2.0 * r;
        let cubic_scale = 3.0 * n * s.powi(3) + 3.0 * s + 2.0 * r;
        let lead = 1.5 * m2 * g * c / (den * den);
        worst.check(
            "contact_force",
            f[contact],
            lead * cubic,
            lead * cubic_scale,
            &at,
        );
        let normal = m1 * (g + 0.5 * ell * (c * acc - s * w2));
        let normal_scale = m1 * (g + 0.5 * ell * (c * acc.abs() + s * w2));
        worst.check("hinge_vertical", f[vertical], normal, normal_scale, &at);
        // m1 x_cm'' = H - F, x_cm'' = -(ell/2)(s theta'' + c theta'^2): the cube pushes back.
        let along = -0.5 * m1 * ell * (s * acc + c * w2);
        let along_scale = 0.5 * m1 * ell * (s * acc.abs() + c * w2) + lead * cubic_scale;
        worst.check(
            "hinge_horizontal",
            f[horizontal],
            along + lead * cubic,
            along_scale,
            &at,
        );
        let coef = force_polynomial(model, &k, contact);
        assert_eq!(coef.len(), 4);
        let want = [-2.0 * r, 3.0, 0.0, 3.0 * n];
        let scale = coef[1] / want[1];
        for (j, (got, w)) in coef.iter().zip(want).enumerate() {
            let name = [
                "separation c0",
                "separation c1",
                "separation c2",
                "separation c3",
            ][j];
            worst.check(name, got / scale, w, w.abs().max(3.0), &at);
        }
        let s_sep = root(&coef, r);
        worst.check("separation root", s_sep, root(&want, r), s_sep, &at);
        let theta_dot = -red.theta_dot_sq.sqrt();
        let st = state(model, &k, 0.0, delta, theta_dot);
        worst.check("tip x", st.pos[tip][0], ell * c, ell, &at);
        worst.check("tip y", st.pos[tip][1], ell * s, ell, &at);
        let e0 = (m1 + m2) * g * a / 2.0;
        worst.check("energy", model.energy(&k, &st.q, &st.qd), e0, e0, &at);
    }
    worst.assert_within("hinged_rod_closed", TOL);
}

#[test]
fn wall_ladder_agrees_with_its_closed_forms() {
    // theta'^2 = 3 (g/ell) (r - s), theta'' = -3 g c/(2 ell), F = (3/4) m1 g c (3 s - 2 r):
    // the ladder leaves the wall at s = 2r/3. The floor: N = m1 (g + y_cm''), that is
    // N / (m1 g) = 1/4 - (3/2) r s + (9/4) s^2.
    let model = find("wall_ladder_closed");
    let info = model.info();
    assert_eq!(info.reduction.unwrap().separation_degree(), 1);
    assert_eq!(info.reduction.unwrap().force_degrees, [1, 2]);
    let (contact, floor) = (
        contact_index(info, "contact_force"),
        contact_index(info, "floor_normal"),
    );
    let (foot, tip, centre) = (
        index(info.points, "foot"),
        index(info.points, "tip"),
        index(info.points, "rod_centre"),
    );
    let mut rng = Rng(0x001A_DDE5);
    let mut worst = Worst::default();
    for i in 0..POINTS {
        let m1 = rng.log_uniform(0.1, 10.0);
        let ell = rng.log_uniform(0.1, 10.0);
        let r = rng.uniform(0.01, 0.99);
        let g = rng.uniform(1.0, 30.0);
        let a = r * ell;
        let theta_i = r.asin();
        let delta = rng.uniform(0.0, theta_i);
        let at = format!("#{i}: r={r} delta={delta:e}");
        let p = params(model, &[("m1", m1), ("ell", ell), ("a", a), ("g", g)]);
        let k = prepare(model, &p);
        let (s, c) = (theta_i - delta).sin_cos();
        let (r_minus_s, _) = gaps(theta_i, delta);
        let red = model.reduction().unwrap().reduced(&k, delta);
        let w2 = 3.0 * g / ell * r_minus_s;
        worst.check("theta_dot_sq", red.theta_dot_sq, w2, w2, &at);
        let acc = -1.5 * g * c / ell;
        worst.check("theta_ddot", red.theta_ddot, acc, acc, &at);
        let mut f = vec![f64::NAN; info.contacts.len()];
        model.reduction().unwrap().forces(&k, delta, &mut f);
        let push = 0.75 * m1 * g * c * (3.0 * s - 2.0 * r);
        let push_scale = 0.75 * m1 * g * c * (3.0 * s + 2.0 * r);
        worst.check("contact_force", f[contact], push, push_scale, &at);
        let normal = m1 * (g + 0.5 * ell * (c * acc - s * w2));
        let normal_scale = m1 * (g + 0.5 * ell * (c * acc.abs() + s * w2));
        worst.check("floor_normal", f[floor], normal, normal_scale, &at);
        let quadratic = [0.25, -1.5 * r, 2.25];
        let quadratic_scale = 0.25 + 1.5 * r * s + 2.25 * s * s;
        worst.check(
            "floor quadratic",
            horner(&quadratic, s),
            normal / (m1 * g),
            quadratic_scale,
            &at,
        );
        let floor_coef = force_polynomial(model, &k, floor);
        let factor = floor_coef[0] / quadratic[0];
        assert!(factor > 0.0, "{at}: {floor_coef:?}");
        for (j, (got, want)) in floor_coef.iter().zip(quadratic).enumerate() {
            let name = ["floor c0", "floor c1", "floor c2"][j];
            worst.check(name, got / factor, want, 2.25, &at);
        }
        let coef = force_polynomial(model, &k, contact);
        assert_eq!(coef.len(), 2);
        worst.check("separation root", -coef[0] / coef[1], 2.0 * r / 3.0, r, &at);
        let st = state(model, &k, 0.0, delta, -red.theta_dot_sq.sqrt());
        worst.check("foot x", st.pos[foot][0], -ell * c, ell, &at);
        worst.check("tip y", st.pos[tip][1], ell * s, ell, &at);
        assert_eq!(st.pos[tip][0], 0.0);
        // The ladder's centre runs on a circle of radius ell/2 about the wall's foot.
        let [x, y] = st.pos[centre];
        worst.check("centre circle", x.hypot(y), 0.5 * ell, ell, &at);
        let e0 = m1 * g * a / 2.0;
        worst.check("energy", model.energy(&k, &st.q, &st.qd), e0, e0, &at);
    }
    worst.assert_within("wall_ladder_closed", TOL);
}

#[test]
fn the_comparison_can_fail() {
    // A control: the same check with eq (9)'s 4/3 replaced by 1.3 is far outside the tolerance.
    let model = find("rod_cube_closed");
    let p = params(
        model,
        &[
            ("m1", 1.0),
            ("m2", 3.0),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", 9.81),
        ],
    );
    let k = prepare(model, &p);
    let delta = 0.05;
    let (s, _) = (0.25f64.asin() - delta).sin_cos();
    let (r_minus_s, _) = gaps(0.25f64.asin(), delta);
    let wrong = 4.0 * 9.81 * r_minus_s / (1.3 - s * s / 4.0);
    let mut worst = Worst::default();
    let red = model.reduction().unwrap().reduced(&k, delta);
    worst.check("wrong eq9", red.theta_dot_sq, wrong, wrong, "paper case");
    let err = worst.0["wrong eq9"].0;
    assert!(err > 1e-3, "{err}");
    assert_eq!(worst.above(TOL).len(), 1);
}

/// Every push the derivation proved positive over its phase (`ReductionInfo::pushes_proven`,
/// `derive::positivity`), and every first contact it proved to push at release
/// (`release_push_proven`, checked at `delta = 0`), is positive where the generated code
/// evaluates it: the contact's force
/// from the reduced motion (`Reduction::forces`, not the polynomial the proof read) and its
/// force polynomial, at 2,000 admissible parameter points per model (each parameter from 1e-3
/// to 1e3, log-uniform, kept where the model's requirements pass) and 50 angles each from
/// `sin(theta) = 0` to `sin(theta_i)`. Both of rod_cube's and the loaded rod's contact phases
/// are among them: the proof decides their floor's push.
#[test]
fn every_push_proved_positive_is_positive_where_the_force_is_evaluated() {
    let mut rng = Rng(0x9_05e);
    let (mut proved, mut at_release) = (Vec::new(), Vec::new());
    for &model in rodcube::models::all() {
        let info = model.info();
        let (Some(layout), Some(red)) = (info.reduction, model.reduction()) else {
            continue;
        };
        let contacts: Vec<usize> = (0..info.contacts.len())
            .filter(|&i| layout.pushes_proven[i])
            .collect();
        if contacts.is_empty() && !layout.release_push_proven {
            continue;
        }
        if !contacts.is_empty() {
            proved.push(info.name);
        }
        if layout.release_push_proven {
            at_release.push(info.name);
        }
        let (np, nc) = (info.parameters.len(), info.contacts.len());
        let mut margins = vec![0.0; info.requirements.len()];
        let (mut k, mut forces) = (vec![0.0; info.n_constants], vec![0.0; nc]);
        let mut points = 0;
        while points < 2000 {
            let p: Vec<f64> = (0..np).map(|_| rng.log_uniform(1e-3, 1e3)).collect();
            if rodcube::system::check_parameters(model, &p, &mut margins).is_err() {
                continue;
            }
            points += 1;
            model.prepare(&p, &mut k);
            let (theta_i, si) = (k[layout.k_theta_initial], k[layout.k_sin_initial]);
            if layout.release_push_proven {
                // The first contact at release: its force and its polynomial at sin(theta_i).
                red.forces(&k, 0.0, &mut forces);
                let mut poly = vec![0.0; layout.force_degrees[0] + 1];
                red.force_polynomial(&k, 0, &mut poly);
                let value = poly.iter().rev().fold(0.0, |acc, &a| acc * si + a);
                assert!(
                    forces[0] > 0.0 && value > 0.0,
                    "{}: contact {} at release, p = {p:?}: force {}, polynomial {value}",
                    info.name,
                    info.contacts[0].name,
                    forces[0]
                );
            }
            for j in 0..=50 {
                let s = si * f64::from(j) / 50.0;
                let delta = theta_i - s.asin();
                red.forces(&k, delta, &mut forces);
                for &c in &contacts {
                    let mut poly = vec![0.0; layout.force_degrees[c] + 1];
                    red.force_polynomial(&k, c, &mut poly);
                    let value = poly.iter().rev().fold(0.0, |acc, &a| acc * s + a);
                    assert!(
                        forces[c] > 0.0 && value > 0.0,
                        "{}: contact {} at p = {p:?}, sin(theta) = {s}: force {}, polynomial {value}",
                        info.name,
                        info.contacts[c].name,
                        forces[c]
                    );
                }
            }
        }
    }
    assert_eq!(proved, ["loaded_rod_closed", "rod_cube_closed"]);
    assert_eq!(
        at_release,
        [
            "hinged_rod_closed",
            "loaded_rod_closed",
            "rod_cube_closed",
            "wall_ladder_closed"
        ]
    );
}
