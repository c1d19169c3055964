//! Scene validation against models: every error class names the right file, line, column and
//! field, and a valid scene comes out in the model's parameter order with its defaults.
//!
//! Runs on the hand-typed `rod_cube` and `rod_cube_free` of `tests/common/paper.rs`, so it does not
//! wait for the generated models.

mod common;

use common::paper::MODELS;
use rodcube::quantity::Quantity;
use rodcube::scene::{DEFAULT_SAMPLES, DEFAULT_TOLERANCE, Diagnostic, Kind, Scene, SceneError};
use std::path::Path;

const FILE: &str = "scenes/test.yaml";

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::parse(text, Path::new(FILE), MODELS)
}

/// The single diagnostic of an invalid scene.
fn only(text: &str) -> Diagnostic {
    match parse(text) {
        Ok(s) => panic!("expected an error, got {s:?}"),
        Err(e) => {
            assert_eq!(e.diagnostics.len(), 1, "expected one diagnostic, got:\n{e}");
            e.diagnostics[0].clone()
        }
    }
}

/// Asserts kind, line, column and field.
fn at(d: &Diagnostic, kind: Kind, line: usize, column: usize, field: &str) {
    assert_eq!(
        (d.kind, d.line, d.column, d.field.as_str()),
        (kind, line, column, field),
        "diagnostic was:\n{d}"
    );
    assert_eq!(d.file, Path::new(FILE));
}

const GOOD: &str = "\
# the paper's case
model: rod_cube
parameters:
  g: 9.81
  m1: 1.0
  m2: 3
  ell: 1.0
  a: 0.25
want: [separation_time, separation_angle, contact_force_series, tip_trajectory]
tolerance: 1.0e-12
samples: 1000
";

#[test]
fn a_valid_scene_is_in_model_order_with_its_values() {
    let s = parse(GOOD).unwrap();
    assert_eq!(s.info().name, "rod_cube");
    assert_eq!(s.parameters, vec![1.0, 3.0, 1.0, 0.25, 9.81]);
    assert_eq!(s.parameter("a"), Some(0.25));
    let names: Vec<String> = s.want.iter().map(|q| q.name(s.info())).collect();
    assert_eq!(
        names,
        [
            "separation_time",
            "separation_angle",
            "contact_force_series",
            "tip_trajectory"
        ]
    );
    assert_eq!(s.tolerance, 1e-12);
    assert_eq!(s.samples, 1000);
    assert_eq!(s.stem(), Some("test"));
}

#[test]
fn tolerance_and_samples_default() {
    let text = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n";
    let s = parse(text).unwrap();
    assert_eq!(
        (s.tolerance, s.samples),
        (DEFAULT_TOLERANCE, DEFAULT_SAMPLES)
    );
    assert_eq!(s.want, vec![Quantity::SeparationAngle]);
}

#[test]
fn yaml_syntax_error_names_line_and_enclosing_key() {
    let d = only(
        "model: rod_cube\nwant: [separation_angle]\nparameters: {m1: 1.0, m2: 3.0\nsamples: 10\n",
    );
    assert_eq!(d.kind, Kind::Syntax);
    assert_eq!(d.field, "parameters");
    assert!((3..=4).contains(&d.line), "line {}:\n{d}", d.line);
    assert!(d.message.starts_with("invalid YAML"), "{d}");
}

#[test]
fn bad_indentation_is_a_syntax_error_at_its_line() {
    let d = only("model: rod_cube\nparameters:\n  m1: 1.0\n   m2: 3.0\nwant: []\n");
    assert_eq!(d.kind, Kind::Syntax);
    assert_eq!(d.line, 4, "{d}");
}

#[test]
fn duplicate_key_points_at_the_second_occurrence() {
    let d = only(
        "model: rod_cube\nparameters:\n  m1: 1.0\n  m2: 3.0\n  m1: 2.0\nwant: [separation_angle]\n",
    );
    at(&d, Kind::Syntax, 5, 3, "parameters.m1");
    assert!(d.message.contains("duplicate key `m1`"), "{d}");
    let d = only("model: rod_cube\nwant: [a]\nmodel: rod_cube_free\n");
    at(&d, Kind::Syntax, 3, 1, "model");
}

#[test]
fn unknown_key_is_refused_at_its_line() {
    let text = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n\ntolerence: 1e-9\n";
    let d = only(text);
    at(&d, Kind::UnknownKey, 5, 1, "tolerence");
    assert!(
        d.message
            .contains("model, parameters, want, tolerance, samples, until"),
        "{d}"
    );
}

#[test]
fn wrong_type_and_missing_key_are_structure_errors() {
    let d = only(
        "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\nsamples: many\n",
    );
    at(&d, Kind::Structure, 4, 10, "samples");
    let d = only("model: rod_cube\nparameters:\n  m1: heavy\nwant: [separation_angle]\n");
    at(&d, Kind::Structure, 3, 7, "parameters.m1");
    let d = only("model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\n");
    assert_eq!((d.kind, d.field.as_str()), (Kind::Structure, "want"), "{d}");
    assert!(d.message.contains("`want` is missing"), "{d}");
}

#[test]
fn unknown_model_lists_the_available_ones() {
    let d = only("# comment\nmodel: rod_cubee\nparameters: {}\nwant: [separation_angle]\n");
    at(&d, Kind::UnknownModel, 2, 8, "model");
    assert!(
        d.message.contains("available models: rod_cube\n")
            || d.message.ends_with("available models: rod_cube"),
        "{d}"
    );
}

#[test]
fn unknown_quantity_lists_what_the_model_offers() {
    let text = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant:\n  - separation_angle\n  - sepration_time\n";
    let d = only(text);
    at(&d, Kind::UnknownQuantity, 5, 5, "want[1]");
    assert!(d.message.contains("sepration_time"), "{d}");
    assert!(
        d.message
            .contains("separation_time, contact_end, contact_time_to_floor"),
        "{d}"
    );
    assert!(d.message.contains("tip_trajectory"), "{d}");
}

#[test]
fn a_quantity_the_model_cannot_provide_is_refused() {
    // With friction the system has no fast phase at release, so no linearised separation.
    let text = "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0.1}\nwant: [theta_series, linearised_separation_angle]\n";
    let d = match Scene::parse(text, Path::new(FILE), rodcube::models::all()) {
        Ok(s) => panic!("expected an error, got {s:?}"),
        Err(e) => {
            assert_eq!(e.diagnostics.len(), 1, "{e}");
            e.diagnostics[0].clone()
        }
    };
    at(&d, Kind::UnavailableQuantity, 3, 22, "want[1]");
    assert!(d.message.contains("no fast phase at release"), "{d}");
}

#[test]
fn a_phase_of_a_system_is_refused_naming_the_system() {
    let text = "model: rod_cube_free\nparameters: {m1: 1}\nwant: [separation_time]\n";
    let d = only(text);
    at(&d, Kind::UnknownModel, 1, 8, "model");
    assert!(
        d.message.contains("phase of the system `rod_cube`")
            && d.message.contains("write `model: rod_cube`"),
        "{d}"
    );
}

#[test]
fn a_quantity_wanted_twice_is_refused() {
    let text = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle, checks, separation_angle]\n";
    at(&only(text), Kind::DuplicateQuantity, 3, 34, "want[2]");
}

#[test]
fn missing_parameters_are_each_named_at_the_parameters_key() {
    let e = parse("model: rod_cube\nwant: [separation_angle]\nparameters:\n  m1: 1.0\n  ell: 1.0\n  g: 9.81\n").unwrap_err();
    assert_eq!(e.diagnostics.len(), 2, "{e}");
    for (d, name) in e.diagnostics.iter().zip(["m2", "a"]) {
        at(
            d,
            Kind::MissingParameter,
            3,
            1,
            &format!("parameters.{name}"),
        );
        assert!(d.message.contains(&format!("`{name}`")), "{d}");
    }
    assert!(
        e.diagnostics[1].message.contains("cube side, in m"),
        "{}",
        e.diagnostics[1]
    );
}

#[test]
fn unknown_parameter_is_refused_at_its_key() {
    let text = "model: rod_cube\nparameters:\n  m1: 1.0\n  m2: 3.0\n  ell: 1.0\n  a: 0.25\n  g: 9.81\n  mu: 0.3\nwant: [separation_angle]\n";
    let d = only(text);
    at(&d, Kind::UnknownParameter, 8, 3, "parameters.mu");
    assert!(d.message.contains("m1, m2, ell, a, g"), "{d}");
}

#[test]
fn non_positive_values_are_refused_at_their_value() {
    let text = "model: rod_cube\nparameters:\n  m1: 1.0\n  m2: 3.0\n  ell: 1.0\n  a: 0.25\n  g: -9.81\nwant: [separation_angle]\n";
    let d = only(text);
    at(&d, Kind::NotPositive, 7, 6, "parameters.g");
    assert!(d.message.contains("-9.81"), "{d}");
    let d = only(
        "model: rod_cube\nparameters: {m1: 0, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n",
    );
    at(&d, Kind::NotPositive, 2, 18, "parameters.m1");
}

#[test]
fn a_negative_friction_coefficient_is_refused_at_its_value() {
    let text = "model: rod_cube_friction\nparameters:\n  m1: 1.0\n  m2: 3.0\n  ell: 1.0\n  a: 0.25\n  g: 9.81\n  mu: -0.2\nwant: [separation_angle]\n";
    let registry = rodcube::models::all();
    let err = Scene::parse(text, Path::new(FILE), registry).unwrap_err();
    assert_eq!(err.diagnostics.len(), 1, "{err}");
    let d = err.diagnostics[0].clone();
    at(&d, Kind::NegativeFriction, 8, 7, "parameters.mu");
    assert!(d.message.contains("foot_friction"), "{d}");
    assert!(d.message.contains("-0.2"), "{d}");
    // Zero is no friction, the paper's case.
    let ok = "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0}\nwant: [separation_angle]\n";
    assert!(
        Scene::parse(ok, Path::new(FILE), registry).is_ok(),
        "mu = 0 refused"
    );
}

#[test]
fn nan_and_infinities_are_refused() {
    for (value, shown) in [
        (".nan", ".nan"),
        (".inf", ".inf"),
        ("-.inf", "-.inf"),
        (".NaN", ".nan"),
    ] {
        let text = format!(
            "model: rod_cube\nparameters:\n  m1: 1.0\n  m2: {value}\n  ell: 1.0\n  a: 0.25\n  g: 9.81\nwant: [separation_angle]\n"
        );
        let d = only(&text);
        at(&d, Kind::NotFinite, 4, 7, "parameters.m2");
        assert!(d.message.contains(shown), "{d}");
    }
}

#[test]
fn a_parameter_that_is_not_positive_by_declaration_may_be_zero() {
    // A friction coefficient is not declared positive: zero is frictionless (a negative one is
    // refused by the friction's own rule, see `negative-friction`).
    let text = "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0}\nwant: [theta_series]\n";
    let all = rodcube::models::all();
    assert!(all.iter().any(|m| m.info().name == "rod_cube_friction"));
    let parsed = Scene::parse(text, Path::new(FILE), all);
    assert!(parsed.is_ok(), "{:?}", parsed.err());
}

#[test]
fn tolerance_and_samples_out_of_range() {
    let base = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n";
    for (line, kind) in [
        ("tolerance: 0", Kind::OutOfRange),
        ("tolerance: -1e-9", Kind::OutOfRange),
        ("tolerance: 0.5", Kind::OutOfRange),
        ("tolerance: 1e-16", Kind::OutOfRange),
        ("tolerance: .nan", Kind::NotFinite),
        ("tolerance: .inf", Kind::NotFinite),
    ] {
        let d = only(&format!("{base}{line}\n"));
        at(&d, kind, 4, 12, "tolerance");
    }
    for line in [
        "samples: 1",
        "samples: 0",
        "samples: -5",
        "samples: 10000000",
    ] {
        let d = only(&format!("{base}{line}\n"));
        at(&d, Kind::OutOfRange, 4, 10, "samples");
    }
    let d =
        only("model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: []\n");
    at(&d, Kind::OutOfRange, 3, 7, "want");
}

#[test]
fn until_must_be_a_positive_time_and_is_kept() {
    let base = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n";
    for (line, kind) in [
        ("until: 0", Kind::OutOfRange),
        ("until: -0.5", Kind::OutOfRange),
        ("until: .nan", Kind::NotFinite),
        ("until: .inf", Kind::NotFinite),
    ] {
        let d = only(&format!("{base}{line}\n"));
        at(&d, kind, 4, 8, "until");
        assert!(d.message.contains("seconds from release"), "{d}");
    }
    let parse_all = |t: &str| Scene::parse(t, Path::new(FILE), rodcube::models::all());
    let s = parse_all(&format!("{base}until: 0.75\n")).unwrap();
    assert_eq!(s.until, Some(0.75));
    assert_eq!(s.request().until, Some(0.75));
    assert_eq!(parse_all(base).unwrap().until, None);
}

#[test]
fn a_failed_requirement_points_at_the_first_involved_parameter() {
    // a >= ell: `a` comes before `ell` in this file.
    let text = "model: rod_cube\nparameters:\n  m1: 1.0\n  m2: 3.0\n  a: 1.5\n  ell: 1.0\n  g: 9.81\nwant: [separation_angle]\n";
    let d = only(text);
    at(&d, Kind::Requirement, 5, 3, "parameters.a");
    assert!(d.message.contains("a_below_ell"), "{d}");
    assert!(d.message.contains("involves ell, a"), "{d}");
}

#[test]
fn a_restitution_outside_zero_to_one_points_at_its_parameter() {
    // rod_cube_liftoff's contacts take the restitution `e`.
    let text = "model: rod_cube_liftoff\nparameters:\n  m1: 1.0\n  m2: 3.0\n  ell: 1.0\n  a: 0.25\n  e: 1.5\n  g: 9.81\nwant: [separation_angle]\n";
    let parse_all = |t: &str| Scene::parse(t, Path::new(FILE), rodcube::models::all());
    let e = parse_all(text).unwrap_err();
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    let d = &e.diagnostics[0];
    at(d, Kind::OutOfRange, 7, 3, "parameters.e");
    assert!(
        d.message
            .contains("contact `contact_force` has restitution 1.5"),
        "{d}"
    );
    assert!(d.message.contains("outside [0, 1]"), "{d}");
    // In range, it is a valid scene.
    assert!(parse_all(&text.replace("e: 1.5", "e: 1")).is_ok());
}

#[test]
fn every_problem_is_reported_in_file_order() {
    let text = "model: rod_cube\nparameters:\n  m1: -1\n  m2: 3\n  ell: 1\n  a: 0.25\n  g: .inf\n  h: 2\nwant: [separation_angle, nothing]\nsamples: 1\n";
    let e = parse(text).unwrap_err();
    let got: Vec<(Kind, usize)> = e.diagnostics.iter().map(|d| (d.kind, d.line)).collect();
    assert_eq!(
        got,
        [
            (Kind::NotPositive, 3),
            (Kind::NotFinite, 7),
            (Kind::UnknownParameter, 8),
            (Kind::UnknownQuantity, 9),
            (Kind::OutOfRange, 10)
        ]
    );
    assert!(e.to_string().ends_with("5 errors in this scene"), "{e}");
}

#[test]
fn the_message_shows_place_field_and_caret() {
    let d = only(
        "model: rod_cube\nparameters: {m1: 1.0, m2: -3.0, ell: 1.0, a: 0.25, g: 9.81}\nwant: [separation_angle]\n",
    );
    let shown = d.to_string();
    assert!(
        shown.starts_with("error[not-positive]: parameters.m2: "),
        "{shown}"
    );
    assert!(shown.contains("--> scenes/test.yaml:2:27"), "{shown}");
    let lines: Vec<&str> = shown.lines().collect();
    let source = lines
        .iter()
        .position(|l| l.starts_with("2 | "))
        .expect("source line");
    let caret = lines[source + 1];
    assert_eq!(
        caret.find('^'),
        Some(lines[source].find("-3.0").unwrap()),
        "{shown}"
    );
    assert_eq!(caret.matches('^').count(), 4, "{shown}");
    assert_eq!(
        d.headline(),
        format!("{FILE}:2:27: parameters.m2: {}", d.message)
    );
}

#[test]
fn empty_and_unreadable_files() {
    let d = only("# nothing here\n\n");
    at(&d, Kind::Syntax, 1, 1, "");
    assert!(d.message.contains("empty"), "{d}");
    let e = Scene::load_with(Path::new("/nonexistent/scene.yaml"), MODELS).unwrap_err();
    assert_eq!(e.diagnostics[0].kind, Kind::Read);
    assert_eq!(e.diagnostics[0].line, 0);
    assert!(e.to_string().contains("--> /nonexistent/scene.yaml"), "{e}");
}

#[test]
fn a_top_level_list_is_a_structure_error() {
    let d = only("- model: rod_cube\n");
    assert_eq!(d.kind, Kind::Structure, "{d}");
    assert!(d.message.contains("mapping of scene keys"), "{d}");
}

#[test]
fn later_errors_are_placed_at_the_field_or_its_nearest_ancestor() {
    let s = parse(GOOD).unwrap();
    let e = s.error_at("parameters.a", Kind::Requirement, "too tall");
    at(&e.diagnostics[0], Kind::Requirement, 8, 3, "parameters.a");
    let e = s.error_at("want[3]", Kind::UnavailableQuantity, "no");
    assert_eq!(e.diagnostics[0].line, 9);
    let e = s.error_at("parameters.zz", Kind::UnknownParameter, "no");
    assert_eq!((e.diagnostics[0].line, e.diagnostics[0].column), (3, 1));
    let e = s.error_at_parameters(&["a", "g"], Kind::Requirement, "both");
    assert_eq!(e.diagnostics[0].field, "parameters.g");
    assert_eq!(e.diagnostics[0].line, 4);
    let e = s.requirement_error("a_below_ell", "fails");
    assert_eq!(
        (e.diagnostics[0].field.as_str(), e.diagnostics[0].line),
        ("parameters.ell", 7)
    );
}
