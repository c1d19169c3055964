//! The methods of `rodcube accuracy` on the paper's case and near upright, against the
//! reference: each lands where its numerical analysis says it should (so a broken method, or a
//! broken error measurement, fails here rather than making a misleading table), and the report's
//! CSV, table and plots are produced from rows.

use rodcube::accuracy::{self, Measured, Row, methods, plot};
use rodcube::reference::{Family, relative_error, to_f64};
use rodcube::system::System;

fn case(
    a_over_ell: f64,
) -> (
    System<'static>,
    accuracy::CaseReference,
    rodcube::reference::Reference,
) {
    let model = rodcube::models::find("rod_cube_closed").unwrap();
    let sys = System::from_values(model, &[1.0, 3.0, 1.0, a_over_ell, 1.0]).unwrap();
    let c = accuracy::Case {
        name: "test",
        n: 3.0,
        a_over_ell,
    };
    let (reference, info) = accuracy::case_reference(Family::RodCube, c).unwrap();
    (sys, info, reference)
}

#[test]
fn separation_angle_methods_on_the_papers_case() {
    let (sys, r, _) = case(0.25);
    let err = |f: fn(&System) -> methods::Outcome<f64>| {
        let (theta, _) = f(&sys).unwrap();
        relative_error(theta, &r.angle).abs()
    };
    assert!(err(methods::angle_default) < 3e-16);
    assert!(err(methods::angle_newton) < 3e-16);
    assert!(err(methods::angle_bisection) < 5e-16);
    assert!(err(methods::angle_closed_form) < 1e-13);
    // The paper's linearisation: 9.59 deg instead of 9.61 deg (-0.2 %).
    let lin = err(methods::angle_linearised);
    assert!(lin > 1e-3 && lin < 3e-3, "{lin}");
}

#[test]
fn separation_time_methods_on_the_papers_case_and_near_upright() {
    for (a_over_ell, loose) in [(0.25, 1e-12), (1.0 - 1e-9, 1e-9)] {
        let (sys, r, _) = case(a_over_ell);
        let delta = methods::delta_sep(&sys).unwrap();
        let t_max = 100.0 * to_f64(&r.time);
        let err = |v: methods::Outcome<f64>| relative_error(v.unwrap().0, &r.time).abs();
        // The default quadrature at the planner's default tolerance, and the per-point solver.
        assert!(err(methods::time_default(&sys, delta, 1e-10)) < 1e-12);
        assert!(err(methods::time_lean_fixed(&sys, 8, 12, 1e-12)) < 1e-12);
        // Tanh-sinh copes with the endpoint singularity by itself.
        assert!(err(methods::time_tanh_sinh(&sys, delta, 1.0 / 32.0)) < 1e-12);
        // Adaptive Gauss-Kronrod on the raw integrand converges, slowly.
        let gk = methods::time_gauss_kronrod(&sys, delta, 1e-8).unwrap();
        assert!(
            relative_error(gk.0, &r.time).abs() < 1e-7 && gk.1 > 500,
            "{gk:?}"
        );
        // Runge-Kutta on theta'' and the unreduced equations, both with events.
        assert!(err(methods::time_reduced_ode(&sys, delta, 1e-10, t_max)) < 1e-9);
        assert!(err(methods::time_unreduced(&sys, 1e-10, t_max)) < 1e-9);
        // A single Gauss-Legendre or Gauss-Jacobi panel is excellent from a/ell = 1/4 and poor
        // near upright, where a second singularity approaches the interval.
        let gl = err(methods::time_gl_u2(&sys, delta, 20));
        let gj = err(methods::time_gauss_jacobi(&sys, delta, 20));
        if a_over_ell < 0.5 {
            assert!(gl < loose && gj < loose, "{gl} {gj}");
        } else {
            assert!(gl > 1e-8 && gj > 1e-3, "{gl} {gj}");
        }
    }
}

#[test]
fn series_errors_shrink_with_the_tolerance() {
    let (sys, _, mut reference) = case(0.25);
    let delta = methods::delta_sep(&sys).unwrap();
    let mut worst = |t: &[f64], d: &[f64]| {
        let times = reference.times_at(d).unwrap();
        t.iter()
            .zip(d)
            .zip(&times)
            .map(|((&t, &d), tr)| {
                let dtheta = reference.theta_dot(d) * (t - to_f64(tr));
                (dtheta / (sys.theta_initial() - d)).abs()
            })
            .fold(0.0, f64::max)
    };
    let ((t, d), _) = methods::series_quadrature(&sys, delta, 1e-12, 51).unwrap();
    assert!(worst(&t, &d) < 1e-12);
    let ((t, d), _) = methods::series_ode(&sys, delta, 1e-4, 10.0, 51).unwrap();
    let loose = worst(&t, &d);
    let ((t, d), _) = methods::series_ode(&sys, delta, 1e-10, 10.0, 51).unwrap();
    let tight = worst(&t, &d);
    assert!(tight < 1e-8 && loose > 10.0 * tight, "{loose} {tight}");
}

#[test]
fn the_report_is_written_from_rows() {
    let row = |method: &'static str, error: f64, seconds: f64| Row {
        measured: Measured::Time,
        case: "c",
        method,
        setting: "s".into(),
        error,
        evals: 10,
        seconds,
        note: String::new(),
    };
    let rows = vec![
        row("a", 1e-3, 1e-6),
        row("a", 1e-9, 1e-5),
        row("b", 1e-12, 1e-4),
        row("b", f64::NAN, 0.0),
    ];
    let csv = accuracy::to_csv(&rows);
    assert_eq!(csv.lines().count(), 5);
    assert!(csv.starts_with("quantity,case,method,setting,relative_error"));
    let svg = plot::svg(Measured::Time, "rod_cube", &rows)
        .unwrap()
        .unwrap();
    assert!(svg.contains("Pareto front"));
    assert!(
        plot::svg(Measured::Angle, "rod_cube", &rows)
            .unwrap()
            .is_none()
    );
    let table = accuracy::table(&rows, &[]);
    assert!(table.contains("separation_time") && table.contains("failed"));
}
