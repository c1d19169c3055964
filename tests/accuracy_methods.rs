//! The methods of `rodcube accuracy` on the paper's case and near upright, against the
//! reference: each lands where its numerical analysis says it should (so a broken method, or a
//! broken error measurement, fails here rather than making a misleading table); the timing
//! harness makes a set-up once and never inside the timed solves; the per-point rows are the
//! sweeps' solver; the integrators converge on the integrated models; and the report's CSV,
//! table and plots are produced from rows.

use rodcube::accuracy::{self, Budget, Measured, Row, integrated, methods, plot};
use rodcube::reference::{Family, relative_error, to_f64};
use rodcube::report::table::Layout;
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::integrated::ode::Method;
use rodcube::system::System;
use std::cell::RefCell;
use std::time::Duration;

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
        key: "test",
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
        let mut fixed = methods::fixed_rules_solver(&sys, 8, 12, 1e-12).unwrap();
        assert!(err(methods::time_per_point(&mut fixed, &sys)) < 1e-12);
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
        let rule = methods::jacobi_rule(20).unwrap();
        let gj = err(methods::time_gauss_jacobi(&sys, delta, &rule));
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

/// The smallest budget: each set-up and solve timed twice.
const TINY: Budget = Budget {
    time: Duration::ZERO,
    min_repeats: 2,
};

#[test]
fn a_setup_is_timed_apart_and_never_runs_inside_the_timed_solves() {
    let log = RefCell::new(Vec::new());
    let m = accuracy::measure(
        || {
            log.borrow_mut().push('p');
            Ok(10u64)
        },
        |state: &mut u64| {
            log.borrow_mut().push('s');
            *state += 1;
            Ok((*state, 3))
        },
        true,
        &TINY,
    )
    .unwrap();
    let log: String = log.into_inner().into_iter().collect();
    // One set-up and one solve for the answer, the set-up's timing, then the solves' timing on
    // the first set-up's state, with no set-up among them.
    let solves = log.rfind('p').map(|i| &log[i + 1..]).unwrap();
    assert!(log.starts_with("ps") && solves.len() >= 2, "{log}");
    assert!(solves.chars().all(|c| c == 's'), "{log}");
    assert_eq!((m.value, m.evals), (11, 3));
    assert!(m.setup_seconds.is_some() && m.seconds >= 0.0);
    // A method without a set-up has no set-up column, and its preparation runs once.
    let prepared = RefCell::new(0);
    let m = accuracy::measure(
        || {
            *prepared.borrow_mut() += 1;
            Ok(())
        },
        |_| Ok((1.0, 1)),
        false,
        &TINY,
    )
    .unwrap();
    assert_eq!((*prepared.borrow(), m.setup_seconds), (1, None));
}

#[test]
fn the_per_point_rows_are_the_sweeps_solver_on_the_same_point() {
    let (sys, r, _) = case(0.25);
    // At 2^-53 the report's per-point setting is the solver `LeanSolver::new` makes, which the
    // sweeps and `benches/solve.rs` (`per_point/lean_solver_separation_time`) call.
    let mut swept = LeanSolver::new(sys.model()).unwrap();
    let bench = swept.solve(sys.p()).unwrap();
    let mut report = methods::per_point_solver(&sys, f64::EPSILON / 2.0).unwrap();
    let (t, evals) = methods::time_per_point(&mut report, &sys).unwrap();
    assert_eq!(t.to_bits(), bench.separation_time.to_bits());
    assert_eq!(evals, swept.evals);
    assert!(relative_error(t, &r.time).abs() < 3e-16);
    // What makes it the faster route in the report and in the bench alike, counted rather than
    // timed: root and time together take fewer evaluations (7) than the default quadrature
    // alone at the planner's tolerance (10), with no set-up inside the solve.
    let delta = methods::delta_sep(&sys).unwrap();
    let (_, default_evals) = methods::time_default(&sys, delta, 1e-10).unwrap();
    assert!(evals < default_evals, "{evals} vs {default_evals}");
    // A looser tolerance takes fewer nodes and lands within it.
    let mut loose = methods::per_point_solver(&sys, 1e-6).unwrap();
    let (t6, evals6) = methods::time_per_point(&mut loose, &sys).unwrap();
    assert!(evals6 < evals, "{evals6} {evals}");
    assert!(relative_error(t6, &r.time).abs() < 1e-6);
}

#[test]
fn the_integrators_converge_on_the_integrated_models_against_their_references() {
    for m in &integrated::MODELS {
        let reference = integrated::reference(m).unwrap();
        // The two methods at 1e-15 agree far below the tolerances the rows are judged at.
        assert!(reference.uncertainty() < 1e-13, "{reference:?}");
        for method in [Method::Dopri5, Method::Dop853] {
            let loose = integrated::measure_one(m, &reference, method, 6, &TINY);
            let tight = integrated::measure_one(m, &reference, method, 12, &TINY);
            let (el, et) = (loose.error.abs(), tight.error.abs());
            assert!(
                el < 1e-4 && et < 1e-10 && et < el,
                "{} {method}: {el} {et}",
                m.model
            );
            assert!(tight.evals > 0 && tight.steps.unwrap() > 0 && tight.setup_seconds.is_some());
        }
    }
}

#[test]
fn options_that_name_nothing_are_refused_before_anything_runs() {
    let opts = |models: &[&str], cases: &[&str], methods: &[&str]| accuracy::Options {
        models: models.iter().map(|s| s.to_string()).collect(),
        cases: cases.iter().map(|s| s.to_string()).collect(),
        methods: methods.iter().map(|s| s.to_string()).collect(),
        quick: true,
    };
    let usage = |o: accuracy::Options| {
        let e = o.choose().unwrap_err();
        assert!(e.is_usage(), "{e}");
        e.to_string()
    };
    assert!(usage(opts(&["rod_cubes"], &[], &[])).contains("rod_cylinder"));
    assert!(usage(opts(&[], &["upright"], &[])).contains("near_upright"));
    assert!(usage(opts(&["rod_cylinder"], &["paper"], &[])).contains("scene"));
    assert!(usage(opts(&[], &[], &["rk4"])).contains("dopri5"));
    assert!(usage(opts(&["rod_cylinder"], &[], &["halley"])).contains("nothing to measure"));
    // The defaults: rod_cube's five cases and the three integrated models.
    let all = opts(&[], &[], &[]).choose().unwrap();
    assert_eq!(all.closed.len(), 1);
    assert_eq!(all.closed[0].2.len(), 5);
    assert_eq!(all.integrated.len(), 3);
    let one = opts(&["rod_cube"], &["paper"], &["halley"])
        .choose()
        .unwrap();
    assert_eq!(one.settings(), 1);
}

fn row(label: &'static str, error: f64, seconds: f64) -> Row {
    Row {
        model: "rod_cube",
        measured: Measured::Time,
        case: "paper",
        label,
        setting: "s".into(),
        error,
        evals: 10,
        steps: None,
        setup_seconds: None,
        seconds,
        note: String::new(),
    }
}

#[test]
fn the_report_is_written_from_rows() {
    let mut failed = row("per-point", f64::NAN, 0.0);
    failed.note = "a long reason why this setting failed, long enough to need wrapping in a \
                   table of a hundred columns"
        .into();
    let mut integrated = row("dop853", 1e-12, 1e-3);
    (integrated.model, integrated.measured) = ("rod_cube_spring", Measured::ContactEnd);
    integrated.steps = Some(42);
    integrated.setup_seconds = Some(5e-7);
    let rows = vec![
        row("default", 1e-3, 1e-6),
        row("default", 1e-9, 1e-5),
        row("gk15", 1e-12, 1e-4),
        failed,
        integrated,
    ];
    let csv = accuracy::to_csv(&rows).unwrap();
    assert_eq!(csv.lines().count(), 6);
    assert!(csv.starts_with(
        "model,quantity,case,method,setting,relative_error,evaluations,steps,setup_seconds,seconds_per_solve,note"
    ));
    assert!(csv.contains("rod_cube_spring,contact_end_time,paper,dop853,s,1e-12,10,42,5e-7,1e-3,"));
    let svg = plot::svg(Measured::Time, "rod_cube", &rows)
        .unwrap()
        .unwrap();
    assert!(svg.contains("Pareto front"));
    assert!(
        plot::svg(Measured::Angle, "rod_cube", &rows)
            .unwrap()
            .is_none()
    );
    let report = accuracy::Report {
        rows,
        ..Default::default()
    };
    let text = accuracy::table::render(&report, &Layout::default());
    assert!(text.contains("rod_cube: separation_time") && text.contains("failed"));
    assert!(text.contains("rod_cube_spring: contact_end_time") && text.contains("steps"));
    let widest = text.lines().map(|l| l.chars().count()).max().unwrap();
    assert!(widest <= Layout::PIPE_WIDTH, "{widest}:\n{text}");
    assert!(!text.contains("methods:"), "the legend is for --verbose");
    let verbose = Layout {
        verbose: true,
        ..Layout::default()
    };
    let text = accuracy::table::render(&report, &verbose);
    assert!(text.contains("methods:") && text.contains("gk15: global adaptive Gauss-Kronrod"));
}

#[test]
fn the_command_measures_each_chosen_model_and_writes_its_files() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("accuracy_command");
    let _ = std::fs::remove_dir_all(&dir);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(["accuracy", "--quick", "--case", "paper,scene"])
        .args(["--model", "rod_cube,rod_cube_spring"])
        .args(["--method", "halley,per-point,dopri5"])
        .arg("--out")
        .arg(&dir)
        .env("COLUMNS", "100")
        .output()
        .unwrap();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{err}");
    // Not a terminal: a line per model and case on stderr instead of a bar.
    assert!(err.contains("accuracy: rod_cube, case paper") && err.contains("rod_cube_spring"));
    for block in [
        "rod_cube: separation_angle",
        "rod_cube: separation_time",
        "rod_cube_spring: contact_end_time",
    ] {
        assert!(out.contains(block), "{block}:\n{out}");
    }
    assert!(out.lines().all(|l| l.chars().count() <= 100), "{out}");
    let csv = std::fs::read_to_string(dir.join("accuracy.csv")).unwrap();
    // One angle row, three per-point tolerances, three DOPRI5 tolerances, and the header.
    assert_eq!(csv.lines().count(), 1 + 1 + 3 + 3, "{csv}");
    // Every setting solved: its error (the sixth column) is there.
    for line in csv.lines().skip(1) {
        assert!(!line.split(',').nth(5).unwrap().is_empty(), "{line}");
    }
    for svg in [
        "accuracy_rod_cube_separation_time.svg",
        "accuracy_rod_cube_spring_contact_end_time.svg",
    ] {
        assert!(dir.join(svg).exists(), "{svg}");
    }
}

/// The sensitivities' rows: the exact ones (the generated partial derivatives) agree with the
/// 256-bit reference's differences to a few ulps on the paper's case and near upright; central
/// differences of the same solver lose about half the digits at their best step (the
/// truncation `h^2` against the rounding `eps/h`) and more at the others; and near upright a
/// difference in `ell` cannot straddle `a < ell`, so it fails with the model's requirement.
#[test]
fn exact_sensitivities_keep_the_digits_that_differences_lose() {
    let chosen = accuracy::Options {
        models: vec!["rod_cube".into()],
        cases: vec!["paper".into(), "near_upright".into()],
        methods: vec!["exact".into(), "differences".into()],
        quick: true,
    }
    .choose()
    .unwrap();
    let report = accuracy::run(&chosen, &accuracy::Progress::hidden()).unwrap();
    let rows = |case: &str, label: &str| -> Vec<Row> {
        (report.rows.iter())
            .filter(|r| r.case == case && r.label == label)
            .cloned()
            .collect()
    };
    for case in ["paper", "near_upright"] {
        let exact = rows(case, "exact");
        assert_eq!(exact.len(), 1);
        assert_eq!(exact[0].measured, Measured::Sensitivities);
        assert!(exact[0].error < 1e-13, "{case}: {:?}", exact[0]);
    }
    let differences = rows("paper", "differences");
    assert_eq!(differences.len(), 3, "{differences:?}");
    let best = differences
        .iter()
        .map(|r| r.error)
        .fold(f64::INFINITY, f64::min);
    assert!(best > 1e-11 && best < 1e-7, "{differences:?}");
    for r in rows("near_upright", "differences") {
        assert!(r.error.is_nan() && r.note.contains("a < ell"), "{r:?}");
    }
}
