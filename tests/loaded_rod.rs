//! The sixth system, added as one spec (`derivations/loaded_rod.yaml`, whose general model
//! `loaded_rod` and fast phases `loaded_rod_closed` and `loaded_rod_free` are derived from it)
//! and one `rodcube derive`, with no Rust edited: the paper's rod with a point load `m3` at its
//! upper end. Its contact phase's generated code agrees with a hand computation at 1,000 random
//! points, becomes the paper's (`rod_cube_closed`) as m3 -> 0, conserves energy and momentum
//! along its reduced motion, separates inside (0, theta_i), and the system runs end to end
//! through the `rodcube` binary.
//!
//! By hand, with M = m1+m2+m3, h = m1/2+m3, P = m1/3+m3, K = ((m1/2+m3)^2 + m2 m3)/M: zero
//! horizontal momentum leaves the reduced inertia ell^2 (P - K s^2), so
//! theta'^2 = 2 g h (r - s) / (ell (P - K s^2)); the cube moves with x2' = -(m1 ell/2M) s theta',
//! so F = -m2 (m1 ell/2M)(c theta'^2 + s theta'') = -m2 m1 g h c (K s^3 - 3 P s + 2 P r) /
//! (2 M (P - K s^2)^2), and separation is K s^3 - 3 P s + 2 P r = 0.

use rodcube::model::Model;
use std::process::Command;

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
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = ((self.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.uniform(lo.ln(), hi.ln()).exp()
    }
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

#[derive(Clone, Copy, Debug)]
struct Params {
    m1: f64,
    m2: f64,
    m3: f64,
    ell: f64,
    a: f64,
    g: f64,
}

impl Params {
    fn random(rng: &mut Rng, load: (f64, f64)) -> Params {
        let m1 = rng.log_uniform(0.1, 10.0);
        let ell = rng.log_uniform(0.1, 10.0);
        Params {
            m1,
            m2: m1 * rng.log_uniform(1e-3, 1e3),
            m3: m1 * rng.log_uniform(load.0, load.1),
            ell,
            a: ell * rng.uniform(0.01, 0.99),
            g: rng.uniform(1.0, 30.0),
        }
    }
    /// The parameter vector of `model`, by name (`rod_cube_closed` ignores m3).
    fn vector(&self, model: &dyn Model) -> Vec<f64> {
        model
            .info()
            .parameters
            .iter()
            .map(|p| match p.name {
                "m1" => self.m1,
                "m2" => self.m2,
                "m3" => self.m3,
                "ell" => self.ell,
                "a" => self.a,
                "g" => self.g,
                other => panic!("unexpected parameter {other}"),
            })
            .collect()
    }
    fn theta_i(&self) -> f64 {
        (self.a / self.ell).asin()
    }
    /// The hand constants of the header: `(h, P, K)`.
    fn hand(&self) -> (f64, f64, f64) {
        let mm = self.m1 + self.m2 + self.m3;
        let h = self.m1 / 2.0 + self.m3;
        (h, self.m1 / 3.0 + self.m3, (h * h + self.m2 * self.m3) / mm)
    }
    /// `sin(theta_sep)` by hand: the root in `(0, r)` of `K s^3 - 3 P s + 2 P r`.
    fn hand_separation_sine(&self) -> f64 {
        let (_, pp, kk) = self.hand();
        let r = self.a / self.ell;
        root(&[2.0 * pp * r, -3.0 * pp, 0.0, kk], r)
    }
    /// `t_sep` by hand: `integral dtheta / |theta'|` with the header's
    /// `theta'^2 = 2 g h (r - s) / (ell (P - K s^2))`, substituting `theta = theta_i - v^2`
    /// (which removes the `1/sqrt` at the start), by 60-point Gauss–Legendre.
    fn hand_separation_time(&self) -> f64 {
        let (h, pp, kk) = self.hand();
        let theta_i = self.theta_i();
        let v_end = (theta_i - self.hand_separation_sine().asin()).sqrt();
        let rule = gauss_quad::GaussLegendre::new(60.try_into().unwrap());
        rule.integrate(0.0, v_end, |v| {
            let (theta, d) = (theta_i - v * v, v * v);
            let r_minus_s = 2.0 * (theta_i - 0.5 * d).cos() * (0.5 * d).sin();
            let s = theta.sin();
            let w2 = 2.0 * self.g * h * r_minus_s / (self.ell * (pp - kk * s * s));
            2.0 * v / w2.sqrt()
        })
    }
}

fn prepare(model: &dyn Model, p: &Params) -> Vec<f64> {
    let p = p.vector(model);
    let mut req = vec![0.0; model.info().requirements.len()];
    model.requirements(&p, &mut req);
    assert!(req.iter().all(|m| *m > 0.0));
    let mut k = vec![f64::NAN; model.info().n_constants];
    model.prepare(&p, &mut k);
    assert!(k.iter().all(|x| x.is_finite()));
    k
}

fn rel(got: f64, want: f64, scale: f64) -> f64 {
    if got == want {
        0.0
    } else {
        (got - want).abs() / scale.abs()
    }
}

/// The root in (0, hi) of `sum c_k s^k` by bisection to the last bit.
fn root(c: &[f64], hi: f64) -> f64 {
    let p = |s: f64| c.iter().rev().fold(0.0, |acc, ck| acc * s + ck);
    let (mut lo, mut hi) = (0.0f64, hi);
    let plo = p(lo);
    assert!(plo * p(hi) < 0.0, "no sign change in (0, {hi}): {c:?}");
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        if (p(mid) < 0.0) == (plo < 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

fn full_state(model: &dyn Model, k: &[f64], delta: f64, theta_dot: f64) -> (Vec<f64>, Vec<f64>) {
    let n = model.info().coordinates.len();
    let (mut q, mut qd) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    model
        .reduction()
        .unwrap()
        .full_state(k, 0.5, delta, theta_dot, &mut q, &mut qd);
    (q, qd)
}

fn points(model: &dyn Model, k: &[f64], q: &[f64], qd: &[f64]) -> Vec<[f64; 2]> {
    let m = model.info().points.len();
    let (mut pos, mut vel) = (vec![[f64::NAN; 2]; m], vec![[f64::NAN; 2]; m]);
    model.points(k, q, qd, &mut pos, &mut vel);
    pos
}

#[test]
fn it_is_registered_with_its_phases() {
    let system = find("loaded_rod").info();
    assert!(system.is_general());
    assert_eq!(system.spec, "derivations/loaded_rod.yaml");
    assert_eq!(system.coordinates, ["x1", "y1", "theta", "x2"]);
    assert!(system.reduction.is_none());
    let names: Vec<&str> = system.parameters.iter().map(|p| p.name).collect();
    assert_eq!(names, ["m1", "m2", "m3", "ell", "a", "g"]);
    let contacts: Vec<(&str, Option<&str>)> = (system.contacts.iter())
        .map(|c| (c.name, c.eliminates))
        .collect();
    assert_eq!(
        contacts,
        [("contact_force", Some("x2")), ("floor_normal", Some("y1"))]
    );
    // The contact phase: both contacts closed, from the release state.
    let info = find("loaded_rod_closed").info();
    assert_eq!((info.system, info.spec), ("loaded_rod", system.spec));
    assert_eq!(info.parameters, system.parameters);
    assert_eq!(info.coordinates, ["x1", "theta"]);
    assert_eq!(info.cyclic, [0]);
    assert_eq!(info.reduction.unwrap().separation_degree(), 3);
    assert_eq!(
        info.points[info.falling_point_index.unwrap()].name,
        "mass_centre"
    );
    assert!(info.contacts.iter().all(|c| c.closed));
    // The free phase: the tip open, starting from the state it is handed.
    let free = find("loaded_rod_free").info();
    assert_eq!(free.coordinates, ["x1", "theta", "x2"]);
    assert!(free.start_params && !free.contacts[0].closed && free.contacts[1].closed);
    let free_names: Vec<&str> = free.parameters.iter().map(|p| p.name).collect();
    assert_eq!(
        free_names,
        [
            "m1",
            "m2",
            "m3",
            "ell",
            "a",
            "g",
            "x1_0",
            "theta_0",
            "x2_0",
            "x1_dot_0",
            "theta_dot_0",
            "x2_dot_0"
        ]
    );
    // Every model of the system lists the same phases.
    let phases: Vec<(&[usize], &str, bool)> = (system.phases.iter())
        .map(|p| (p.closed, p.model, p.release))
        .collect();
    assert_eq!(
        phases,
        [
            (&[0, 1][..], "loaded_rod_closed", true),
            (&[1][..], "loaded_rod_free", false)
        ]
    );
    assert_eq!(info.phases, system.phases);
    assert_eq!(free.phases, system.phases);
}

#[test]
fn it_agrees_with_the_hand_computation_at_1000_random_points() {
    let model = find("loaded_rod_closed");
    let info = model.info();
    let (contact, floor) = (
        contact_index(info, "contact_force"),
        contact_index(info, "floor_normal"),
    );
    let (tip, centre) = (index(info.points, "tip"), index(info.points, "mass_centre"));
    let mut rng = Rng(0x10AD);
    let mut worst = [0.0f64; 9];
    for _ in 0..1000 {
        let p = Params::random(&mut rng, (1e-3, 1e3));
        let Params {
            m1,
            m2,
            m3,
            ell,
            a,
            g,
        } = p;
        let k = prepare(model, &p);
        let (r, theta_i) = (a / ell, p.theta_i());
        let delta = rng.uniform(0.0, theta_i);
        let (s, c) = (theta_i - delta).sin_cos();
        let r_minus_s = 2.0 * (theta_i - 0.5 * delta).cos() * (0.5 * delta).sin();
        let mm = m1 + m2 + m3;
        let h = m1 / 2.0 + m3;
        let pp = m1 / 3.0 + m3;
        let kk = (h * h + m2 * m3) / mm;
        let inertia = pp - kk * s * s;
        let red = model.reduction().unwrap().reduced(&k, delta);
        let w2 = 2.0 * g * h * r_minus_s / (ell * inertia);
        worst[0] = worst[0].max(rel(red.theta_dot_sq, w2, w2));
        let (t1, t2) = (-inertia, 2.0 * kk * s * r_minus_s);
        let lead = g * h * c / (ell * inertia * inertia);
        let acc = lead * (t1 + t2);
        worst[1] = worst[1].max(rel(red.theta_ddot, acc, lead * (t1.abs() + t2.abs())));
        let mut f = vec![f64::NAN; info.contacts.len()];
        model.reduction().unwrap().forces(&k, delta, &mut f);
        let cubic = kk * s.powi(3) - 3.0 * pp * s + 2.0 * pp * r;
        let cubic_scale = kk * s.powi(3) + 3.0 * pp * s + 2.0 * pp * r;
        let lead = m2 * m1 * g * h * c / (2.0 * mm * inertia * inertia);
        worst[2] = worst[2].max(rel(f[contact], -lead * cubic, lead * cubic_scale));
        // The floor carries rod and load: N = (m1+m3)(g + y_cm''), y_cm = ell h s/(m1+m3).
        let d = ell * h / (m1 + m3);
        let normal = (m1 + m3) * g + (m1 + m3) * d * (c * acc - s * w2);
        let normal_scale = (m1 + m3) * (g + d * (c * acc.abs() + s * w2));
        worst[3] = worst[3].max(rel(f[floor], normal, normal_scale));
        let mut coef = [f64::NAN; 4];
        model
            .reduction()
            .unwrap()
            .force_polynomial(&k, contact, &mut coef);
        let want = [2.0 * r, -3.0, 0.0, kk / pp];
        let scale = coef[1] / want[1];
        for (got, w) in coef.iter().zip(want) {
            worst[4] = worst[4].max(rel(got / scale, w, 3.0));
        }
        let s_sep = root(&coef, r);
        worst[5] = worst[5].max(rel(s_sep, root(&want, r), s_sep));
        // Full state: x1' = ell (1 - m1/2M) s theta', x1 = -ell (1 - m1/2M)(cos - cos_i).
        let theta_dot = -red.theta_dot_sq.sqrt();
        let (q, qd) = full_state(model, &k, delta, theta_dot);
        let lever = ell * (1.0 - m1 / (2.0 * mm));
        let c_minus_beta = 2.0 * (theta_i - 0.5 * delta).sin() * (0.5 * delta).sin();
        worst[6] = worst[6].max(rel(q[0], -lever * c_minus_beta, lever * c_minus_beta));
        worst[6] = worst[6].max(rel(qd[0], lever * s * theta_dot, lever * s * theta_dot));
        let pos = points(model, &k, &q, &qd);
        worst[7] = worst[7].max(rel(pos[tip][1], ell * s, ell));
        worst[7] = worst[7].max(rel(pos[centre][1], d * s, ell));
        worst[7] = worst[7].max(rel(pos[centre][0], q[0] + d * c, ell));
        // Energy of the start: the load and the rod's centre at their initial heights.
        let e0 = g * a * h + m2 * g * a / 2.0;
        worst[8] = worst[8].max(rel(model.energy(&k, &q, &qd), e0, e0));
    }
    let names = [
        "theta_dot_sq",
        "theta_ddot",
        "contact_force",
        "floor_normal",
        "separation coefficients",
        "separation root",
        "x1, x1_dot",
        "points",
        "energy",
    ];
    for (n, w) in names.iter().zip(worst) {
        println!("loaded_rod {n:<24} max error {w:.3e}");
    }
    for (n, w) in names.iter().zip(worst) {
        assert!(w <= TOL, "{n}: {w:e}");
    }
}

#[test]
fn a_vanishing_load_gives_the_papers_rod() {
    let (loaded, paper) = (find("loaded_rod_closed"), find("rod_cube_closed"));
    let info = loaded.info();
    let forces = info.contacts.len();
    let names = |m: &dyn Model| m.info().contacts.iter().map(|c| c.name).collect::<Vec<_>>();
    assert_eq!(names(loaded), names(paper));
    let mut rng = Rng(0xF1A7);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let p = Params::random(&mut rng, (1e-14, 1e-14 * (1.0 + 1e-9)));
        let (kl, kp) = (prepare(loaded, &p), prepare(paper, &p));
        let theta_i = p.theta_i();
        let delta = rng.uniform(0.0, theta_i);
        let (rl, rp) = (
            loaded.reduction().unwrap().reduced(&kl, delta),
            paper.reduction().unwrap().reduced(&kp, delta),
        );
        worst = worst.max(rel(rl.theta_dot_sq, rp.theta_dot_sq, rp.theta_dot_sq));
        let acc_scale = rp.theta_ddot.abs() + rp.theta_dot_sq;
        worst = worst.max(rel(rl.theta_ddot, rp.theta_ddot, acc_scale));
        let (mut fl, mut fp) = (vec![0.0; forces], vec![0.0; forces]);
        loaded.reduction().unwrap().forces(&kl, delta, &mut fl);
        paper.reduction().unwrap().forces(&kp, delta, &mut fp);
        // Compare in units of the forces' own size along the motion (the weights).
        let weight = (p.m1 + p.m2) * p.g;
        for (a, b) in fl.iter().zip(&fp) {
            worst = worst.max(rel(*a, *b, weight));
        }
        let (mut cl, mut cp) = ([0.0; 4], [0.0; 4]);
        loaded
            .reduction()
            .unwrap()
            .force_polynomial(&kl, 0, &mut cl);
        paper.reduction().unwrap().force_polynomial(&kp, 0, &mut cp);
        let r = p.a / p.ell;
        let s_sep = root(&cp, r);
        worst = worst.max(rel(root(&cl, r), s_sep, s_sep));
        let theta_dot = -rp.theta_dot_sq.sqrt();
        let (ql, qdl) = full_state(loaded, &kl, delta, theta_dot);
        let (qp, qdp) = full_state(paper, &kp, delta, theta_dot);
        for (a, b) in ql.iter().zip(&qp).chain(qdl.iter().zip(&qdp)) {
            worst = worst.max(rel(*a, *b, a.abs().max(b.abs()).max(1e-300)));
        }
        let (pl, pp) = (
            points(loaded, &kl, &ql, &qdl),
            points(paper, &kp, &qp, &qdp),
        );
        for name in ["foot", "tip", "rod_centre", "cube"] {
            let (i, j) = (index(info.points, name), index(paper.info().points, name));
            for axis in 0..2 {
                worst = worst.max(rel(pl[i][axis], pp[j][axis], p.ell));
            }
        }
    }
    println!("loaded_rod_closed with m3 = 1e-14 m1 vs rod_cube_closed: max error {worst:.3e}");
    assert!(worst <= TOL, "{worst:e}");
}

#[test]
fn energy_and_momentum_are_conserved_along_the_reduced_motion() {
    let model = find("loaded_rod_closed");
    let mut rng = Rng(0xE4E7);
    let mut worst = 0.0f64;
    for _ in 0..50 {
        let p = Params::random(&mut rng, (1e-3, 1e3));
        let k = prepare(model, &p);
        let theta_i = p.theta_i();
        let (q0, qd0) = full_state(model, &k, 0.0, 0.0);
        let e0 = model.energy(&k, &q0, &qd0);
        for j in 1..=40 {
            let delta = theta_i * j as f64 / 40.0;
            let w2 = model.reduction().unwrap().reduced(&k, delta).theta_dot_sq;
            assert!(w2 >= 0.0);
            let (q, qd) = full_state(model, &k, delta, -w2.sqrt());
            worst = worst.max(rel(model.energy(&k, &q, &qd), e0, e0));
            let mut mom = [f64::NAN];
            model.momenta(&k, &q, &qd, &mut mom);
            let scale = (p.m1 + p.m2 + p.m3) * p.ell * w2.sqrt();
            worst = worst.max(rel(mom[0], 0.0, scale.max(f64::MIN_POSITIVE)));
        }
    }
    println!("loaded_rod energy and momentum: max relative drift {worst:.3e}");
    assert!(worst <= TOL, "{worst:e}");
}

#[test]
fn it_separates_between_the_start_and_the_floor() {
    let model = find("loaded_rod_closed");
    let info = model.info();
    let contact = contact_index(info, "contact_force");
    let mut rng = Rng(0x5E9A);
    for _ in 0..200 {
        let p = Params::random(&mut rng, (1e-3, 1e3));
        let k = prepare(model, &p);
        let theta_i = p.theta_i();
        let mut coef = [0.0; 4];
        model
            .reduction()
            .unwrap()
            .force_polynomial(&k, contact, &mut coef);
        let theta_sep = root(&coef, p.a / p.ell).asin();
        assert!(theta_sep > 0.0 && theta_sep < theta_i, "{p:?}: {theta_sep}");
        // The contact force pushes before separation and would pull after it.
        let force = |theta: f64| {
            let mut f = vec![0.0; info.contacts.len()];
            model
                .reduction()
                .unwrap()
                .forces(&k, theta_i - theta, &mut f);
            f[contact]
        };
        assert!(force(theta_i) > 0.0);
        assert!(force(0.5 * (theta_i + theta_sep)) > 0.0, "{p:?}");
        assert!(force(0.5 * theta_sep) < 0.0, "{p:?}");
    }
    // The paper's case n = 3, r = 1/4, with and without a load m3 = m1.
    let p = Params {
        m1: 1.0,
        m2: 3.0,
        m3: 1.0,
        ell: 1.0,
        a: 0.25,
        g: 9.81,
    };
    let k = prepare(model, &p);
    let mut coef = [0.0; 4];
    model
        .reduction()
        .unwrap()
        .force_polynomial(&k, contact, &mut coef);
    let loaded = root(&coef, 0.25).asin();
    // The header's hand cubic K s^3 - 3 P s + 2 P r (here P = 4/3, K = 21/20).
    let hand = p.hand_separation_sine();
    assert!(rel(loaded.sin(), hand, hand) < 1e-14, "{loaded} vs {hand}");
    let bare = find("rod_cube_closed");
    let kb = prepare(bare, &p);
    bare.reduction()
        .unwrap()
        .force_polynomial(&kb, 0, &mut coef);
    let paper = root(&coef, 0.25).asin();
    // The paper's section 3: 9.61 degrees.
    assert!(
        (paper.to_degrees() - 9.61).abs() < 0.005,
        "{}",
        paper.to_degrees()
    );
    println!(
        "separation at n = 3, r = 1/4: bare rod {:.4} deg, with m3 = m1 {:.4} deg",
        paper.to_degrees(),
        loaded.to_degrees()
    );
    assert!(loaded > 0.0 && loaded < p.theta_i());
}

#[test]
fn the_binary_runs_a_loaded_rod_scene_end_to_end() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("loaded_rod_scene");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("loaded.yaml");
    std::fs::write(
        &scene,
        "model: loaded_rod\nparameters: {m1: 1.0, m2: 3.0, m3: 0.5, ell: 1.0, a: 0.25, g: 9.81}\n\
         want: [separation_angle, separation_time, floor_impact, checks, cross_check]\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(&dir)
        .args(["run", "loaded.yaml", "--json", "--out", "o"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr:\n{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The header's hand derivation: the cubic's root and the energy integral's time.
    let p = Params {
        m1: 1.0,
        m2: 3.0,
        m3: 0.5,
        ell: 1.0,
        a: 0.25,
        g: 9.81,
    };
    let theta_sep = v["results"]["separation_angle"]["value"].as_f64().unwrap();
    let want = p.hand_separation_sine().asin();
    assert!(rel(theta_sep, want, want) < 1e-12, "{theta_sep} vs {want}");
    let t_sep = v["results"]["separation_time"]["value"].as_f64().unwrap();
    let want = p.hand_separation_time();
    // The scene asks the default tolerance, 1e-10 relative.
    assert!(rel(t_sep, want, want) < 1e-10, "{t_sep} vs {want}");
    let checks = v["checks"].as_object().unwrap();
    assert!(!checks.is_empty());
    for (name, c) in checks {
        assert_eq!(c["passed"], true, "check {name} failed: {c}");
    }
    assert_eq!(v["work"]["phases"][0], "loaded_rod_closed");
    assert_eq!(v["work"]["phases"][1], "loaded_rod_free");
    let _ = std::fs::remove_dir_all(&dir);
}
