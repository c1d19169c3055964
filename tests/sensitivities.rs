//! Exact sensitivities of the separation on the fast path: `d theta_sep/dp` and `d t_sep/dp`
//! from the generated partial derivatives against a hand derivation from the paper's eq. (14)
//! and against central differences of the 256-bit reference (the step taken in high
//! precision) over the hard-case grid, for every model the reference covers.

use rodcube::model::Model;
use rodcube::reference::{self, Family, Inputs};
use rodcube::results::SensitivityGap;
use rodcube::solve::fast::lean::{LeanPoint, LeanSolver};
use rodcube::solve::fast::sensitivity::SensitivityWork;

#[path = "common/grid.rs"]
mod grid;
use grid::{NS, RS};

fn model(name: &str) -> &'static dyn Model {
    rodcube::models::find(name).expect("generated model")
}

/// `(d theta/dp, d t/dp)`, or why there are none.
type Sensitivities = Result<(Vec<f64>, Vec<f64>), SensitivityGap>;

/// Solves a point and its sensitivities.
fn solve(solver: &mut LeanSolver, p: &[f64]) -> (LeanPoint, Sensitivities) {
    let point = solver.solve(p).expect("point");
    let mut work = SensitivityWork::default();
    let (mut angle, mut time) = (vec![0.0; p.len()], vec![0.0; p.len()]);
    let outcome = solver
        .sensitivities(p, &point, &mut work, &mut angle, &mut time)
        .expect("sensitivities");
    (point, outcome.map(|()| (angle, time)))
}

/// The reference's index (`[m1, m2, ell, a, g]`) of a model's parameter.
fn reference_index(name: &str) -> usize {
    (reference::PARAMETERS.iter())
        .position(|n| *n == name)
        .expect("a parameter of the reference's family")
}

/// `|x - reference|` within `bound` of `|reference|` (an exact zero must be matched by a
/// value within `bound` of the scale `x` is compared at).
fn close(x: f64, reference: f64, bound: f64, scale: f64) -> bool {
    reference::derivative_error(x, reference, scale) <= bound
}

fn check_family(family: Family, ns: &[f64]) {
    let m = model(family.name());
    let names: Vec<&str> = m.info().parameters.iter().map(|p| p.name).collect();
    let mut solver = LeanSolver::new(m).unwrap();
    let mut worst = (0.0f64, String::new());
    for &n in ns {
        for &r in &RS {
            let inputs = Inputs::dimensionless(family, n, r);
            let p: Vec<f64> = (names.iter())
                .map(|name| [1.0, n, 1.0, r, 1.0][reference_index(name)])
                .collect();
            let (point, outcome) = solve(&mut solver, &p);
            let (angle, time) = outcome.unwrap_or_else(|why| panic!("n={n} r={r}: {why:?}"));
            for (i, name) in names.iter().enumerate() {
                let (d_theta, d_t) =
                    reference::derivatives(inputs, reference_index(name)).expect("reference");
                // Each derivative is compared at the scale of its quantity per its parameter.
                let scale_theta = point.separation_angle / p[i];
                let scale_t = point.separation_time / p[i];
                for (what, x, reference, scale) in [
                    ("d theta_sep", angle[i], d_theta, scale_theta),
                    ("d t_sep", time[i], d_t, scale_t),
                ] {
                    let error = reference::derivative_error(x, reference, scale);
                    if error > worst.0 {
                        worst = (error, format!("{what}/d {name} at n={n:e} r={r}"));
                    }
                    assert!(
                        close(x, reference, 1e-10, scale),
                        "{family:?} {what}/d {name} at n={n:e} r={r}: {x:e} against {reference:e}"
                    );
                }
            }
        }
    }
    eprintln!(
        "{family:?}: worst relative error {:e} ({})",
        worst.0, worst.1
    );
}

#[test]
fn rod_cube_sensitivities_match_reference_differences_over_the_grid() {
    check_family(Family::RodCube, &NS);
}

#[test]
fn hinged_rod_sensitivities_match_reference_differences_over_the_grid() {
    check_family(Family::HingedRod, &NS);
}

#[test]
fn wall_ladder_sensitivities_match_reference_differences() {
    check_family(Family::WallLadder, &[1.0]);
}

/// `d theta_sep/dn` for the rod on the cube by hand: the paper's eq. (14),
/// `F(s, n) = 3 s^3 - 12 (1 + n) s + 8 r (1 + n) = 0` with `s = sin(theta_sep)`, `r = a/ell`.
/// The implicit-function theorem gives `d theta/dn = -F_n / (F_s cos theta)` with
/// `F_n = 8 r - 12 s` and `F_s = 9 s^2 - 12 (1 + n)`; with `n = m2/m1`,
/// `d theta/d m2 = (1/m1) d theta/dn` and `d theta/d m1 = -(m2/m1^2) d theta/dn`.
#[test]
fn rod_cube_d_theta_dn_matches_the_implicit_function_theorem_on_eq_14() {
    let m = model("rod_cube");
    let names: Vec<&str> = m.info().parameters.iter().map(|p| p.name).collect();
    let mut solver = LeanSolver::new(m).unwrap();
    for (m1, m2, ell, a) in [
        (1.0, 1.0, 1.0, 0.5),
        (2.0, 0.5, 1.5, 0.3),
        (0.3, 3.0, 2.0, 1.2),
        (1.0, 10.0, 1.0, 0.9),
    ] {
        let p: Vec<f64> = (names.iter())
            .map(|name| match *name {
                "m1" => m1,
                "m2" => m2,
                "ell" => ell,
                "a" => a,
                _ => 9.81,
            })
            .collect();
        let (point, outcome) = solve(&mut solver, &p);
        let (angle, _) = outcome.expect("a separation");
        let (n, r) = (m2 / m1, a / ell);
        let theta = point.separation_angle;
        let s = theta.sin();
        let f_n = 8.0 * r - 12.0 * s;
        let f_s = 9.0 * s * s - 12.0 * (1.0 + n);
        let d_theta_dn = -f_n / (f_s * theta.cos());
        let at = |name: &str| angle[names.iter().position(|x| *x == name).unwrap()];
        for (what, got, want) in [
            ("m2", at("m2"), d_theta_dn / m1),
            ("m1", at("m1"), -d_theta_dn * m2 / (m1 * m1)),
        ] {
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "d theta/d {what} at n={n} r={r}: {got:e}, by hand {want:e}"
            );
        }
    }
}

/// Parameter values that most fast phases accept (a phase that refuses them is skipped, and
/// the test asks that enough were checked).
fn plausible(model: &dyn Model) -> Vec<f64> {
    (model.info().parameters.iter())
        .map(|p| match p.name {
            "m2" => 3.0,
            "a" => 0.25,
            "g" => 9.81,
            "theta_0" => 0.8,
            "theta_dot_0" => -0.5,
            "th0" => 1.2,
            "R" | "r" => 0.2,
            "e" => 0.5,
            _ => 1.0,
        })
        .collect()
}

/// The generated partial derivatives of `theta_dot^2` at a fixed angle, of `sin(theta_i)` and
/// of the fall polynomial's coefficients against central differences of the generated
/// functions themselves (step `1e-5` relative: agreement to about `1e-8`), for every fast
/// phase that takes the plausible parameters.
#[test]
fn generated_partials_match_differences_of_the_generated_functions() {
    let mut checked = 0;
    for &m in rodcube::models::all() {
        let (Some(red), Some(layout)) = (m.reduction(), m.info().reduction.as_ref()) else {
            continue;
        };
        let partials = (red.partials()).unwrap_or_else(|| panic!("{}: no partials", m.info().name));
        let p = plausible(m);
        let Ok(sys) = rodcube::system::System::from_values(m, &p) else {
            continue;
        };
        let n = m.info().n_constants;
        let theta = 0.7 * sys.theta_initial();
        let (s, c) = theta.sin_cos();
        let degree = layout.fall_degree.map_or(0, |d| d + 1);
        // theta_dot^2 at the fixed angle, sin(theta_i) and the fall coefficients at `q`.
        let values = |q: &[f64]| -> Vec<f64> {
            let mut k = vec![0.0; n];
            m.prepare(q, &mut k);
            let (si, ci) = (k[layout.k_sin_initial], k[layout.k_cos_initial]);
            let mut out = vec![red.theta_dot_sq_sc(&k, s, c, si - s, ci - c), si];
            let mut fall = vec![0.0; degree];
            red.fall_polynomial(&k, &mut fall);
            out.extend(fall);
            out
        };
        let np = p.len();
        let mut k = vec![0.0; n];
        m.prepare(&p, &mut k);
        let (mut w, mut si, mut fall) = (vec![0.0; np], vec![0.0; np], vec![0.0; np * degree]);
        partials.theta_dot_sq_partials(&k, s, c, &mut w);
        partials.start_partials(&k, &mut si);
        partials.fall_partials(&k, &mut fall);
        let base = values(&p);
        for i in 0..np {
            let h = 1e-5 * p[i].abs().max(1e-3);
            let (mut up, mut down) = (p.clone(), p.clone());
            up[i] += h;
            down[i] -= h;
            let (vu, vd) = (values(&up), values(&down));
            let mut exact = vec![w[i], si[i]];
            exact.extend(&fall[i * degree..(i + 1) * degree]);
            for (j, e) in exact.iter().enumerate() {
                let diff = (vu[j] - vd[j]) / (2.0 * h);
                let scale = base[j].abs() / p[i].abs().max(1e-3) + e.abs();
                assert!(
                    (diff - e).abs() <= 1e-7 * scale.max(1e-300),
                    "{}: value {j} in {}: {e:e}, differences {diff:e}",
                    m.info().name,
                    m.info().parameters[i].name
                );
            }
        }
        checked += 1;
    }
    assert!(
        checked >= 10,
        "only {checked} fast phases took the parameters"
    );
}
