//! Invalid model specs are refused with the file, the line (and column where it is precise) and
//! the field of the mistake: one test per error class, on specs written to a temporary project
//! (its own `derivations/` and a copy of `templates/`) so that nothing in the tree is touched.
//! Specs in the retired schema (`contact:`, `forces:`, `scenery:`, a friction's `normal:`, a
//! potential's `acts_on:`) are refused saying what replaced them; the contacts' own mistakes
//! (a gap of no coordinate, of no consistent unit or in a unit that is neither a length nor an
//! angle, two contacts of one name, a friction at a
//! contact that does not exist or a bilateral one, an obstacle that moves) each name their field.
#![cfg(feature = "derive")]

use rodcube::derive::spec::{self, SpecError};
use rodcube::derive::{Error, derive_all, render_all};
use std::path::{Path, PathBuf};

/// The smallest complete spec: a ladder on a frictionless wall.
const BASE: &str = "\
# A ladder on a wall, the smallest complete spec.
name: ladder
description: A ladder sliding down a frictionless wall.
parameters:
  - {name: m1, meaning: mass, unit: kg}
  - {name: ell, meaning: length, unit: m}
  - {name: a, meaning: start height, unit: m}
  - {name: g, meaning: gravity, unit: m/s^2}
gravity: g
coordinates:
  - {name: x1, meaning: foot position, unit: m}
  - {name: theta, meaning: angle to the floor, unit: rad}
reduced: theta
end_angle: 0
bodies:
  - name: rod
    mass: m1
    inertia: m1*ell^2/12
    position: [x1 + ell/2*cos(theta), ell/2*sin(theta)]
    angle: theta
points:
  - {name: foot, position: [x1, 0], meaning: foot}
  - {name: tip, position: [x1 + ell*cos(theta), ell*sin(theta)], meaning: top}
  - {name: centre, position: [x1 + ell/2*cos(theta), ell/2*sin(theta)], meaning: centre}
  - {name: wall, position: [0, 0], meaning: wall}
falling_point: centre
contacts:
  - {name: push, meaning: wall push, gap: -x1 - ell*cos(theta), eliminates: x1}
initial:
  theta: {position: asin(a/ell), velocity: 0}
";

/// A fresh temporary project with `derivations/` and a copy of `templates/`.
fn project(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rodcube-bad-specs-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("derivations")).unwrap();
    std::fs::create_dir_all(dir.join("templates")).unwrap();
    let templates = Path::new(env!("CARGO_MANIFEST_DIR")).join("templates");
    for entry in std::fs::read_dir(templates).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, dir.join("templates").join(p.file_name().unwrap())).unwrap();
    }
    dir
}

/// `BASE` with `old` (which must occur exactly once) replaced by `new`.
fn edit(old: &str, new: &str) -> String {
    assert_eq!(
        BASE.matches(old).count(),
        1,
        "`{old}` must occur once in BASE"
    );
    BASE.replace(old, new)
}

/// Writes a spec into a fresh project; returns the project root and the spec's path.
fn write(test: &str, text: &str) -> (PathBuf, PathBuf) {
    let root = project(test);
    let path = root.join("derivations").join(format!("{test}.yaml"));
    std::fs::write(&path, text).unwrap();
    (root, path)
}

/// The error of loading, deriving and rendering a spec (the whole `rodcube derive` path).
fn error_of(test: &str, text: &str) -> (PathBuf, SpecError) {
    let (root, path) = write(test, text);
    let err = match render_all(&root, &[]) {
        Ok(_) => panic!("{test}: the spec was accepted"),
        Err(Error::Spec(e)) => e,
        Err(e) => panic!("{test}: not a spec error: {e}"),
    };
    // Nothing was written.
    assert!(!root.join("generated").exists());
    let _ = std::fs::remove_dir_all(&root);
    (path, err)
}

/// 1-based line of the only line containing `marker`, and the 1-based column of `at` in it.
fn place(text: &str, marker: &str, at: &str) -> (usize, usize) {
    let hits: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains(marker))
        .collect();
    assert_eq!(hits.len(), 1, "marker `{marker}` must be on one line");
    let (i, line) = hits[0];
    let col = line
        .find(at)
        .unwrap_or_else(|| panic!("`{at}` not on line `{line}`"));
    (i + 1, col + 1)
}

/// Asserts file, line, optional column, field and words of the message, in the error and in
/// its displayed form (`file:line:column: field `...`: message`).
fn check(
    path: &Path,
    err: &SpecError,
    (line, column): (usize, Option<usize>),
    field: &str,
    words: &[&str],
) {
    let shown = err.to_string();
    assert_eq!(err.file, path, "{shown}");
    assert_eq!(err.line, line, "wrong line: {shown}");
    if let Some(column) = column {
        assert_eq!(err.column, column, "wrong column: {shown}");
    }
    assert_eq!(err.field, field, "wrong field: {shown}");
    assert!(
        shown.starts_with(&format!("{}:{}:{}: ", path.display(), err.line, err.column)),
        "{shown}"
    );
    assert!(shown.contains(&format!("`{field}`")), "{shown}");
    for w in words {
        assert!(shown.contains(w), "missing {w:?} in: {shown}");
    }
}

/// Writes `text` as the spec of test `test`, expects it refused, and [`check`]s the error at
/// the line where `marker` holds `at`, with no column asked.
fn refused(test: &str, text: &str, (marker, at): (&str, &str), field: &str, words: &[&str]) {
    let (path, err) = error_of(test, text);
    let (line, _) = place(text, marker, at);
    check(&path, &err, (line, None), field, words);
}

#[test]
fn the_base_spec_is_valid() {
    // The control for every test below: only the edit makes a spec invalid.
    let (root, _) = write("base", BASE);
    let (files, _) = render_all(&root, &[]).unwrap_or_else(|e| panic!("{e}"));
    // The general model and the contact phase (the wall's push closed, x1 eliminated).
    for model in ["ladder", "ladder_closed"] {
        let path = Path::new("generated").join(format!("{model}.rs"));
        assert!(
            files.iter().any(|f| f.path == path),
            "no {}",
            path.display()
        );
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn yaml_syntax_error() {
    let text = edit(
        "description: A ladder sliding",
        "description: A ladder: sliding",
    );
    let (path, err) = error_of("syntax", &text);
    let (line, col) = place(&text, "description:", ": sliding");
    check(&path, &err, (line, Some(col)), "", &["mapping values"]);
}

#[test]
fn unknown_key() {
    let text = edit("    angle: theta\n", "    angle: theta\n    colour: red\n");
    let (path, err) = error_of("unknown_key", &text);
    let (line, col) = place(&text, "colour", "colour");
    check(
        &path,
        &err,
        (line, Some(col)),
        "bodies[0]",
        &["unknown field `colour`", "expected one of"],
    );
}

#[test]
fn undefined_symbol_in_an_expression() {
    let text = edit(
        "position: [x1 + ell/2*cos(theta), ell/2*sin(theta)]\n    angle",
        "position: [x1 + ell/2*cos(theta), ell/2*sin(phi)]\n    angle",
    );
    let (path, err) = error_of("undefined_symbol", &text);
    let (line, col) = place(&text, "sin(phi)", "ell/2*sin(phi)");
    check(
        &path,
        &err,
        (line, Some(col)),
        "bodies[0].position[1]",
        &["undefined symbol `phi`", "allowed here"],
    );
}

#[test]
fn unparseable_expression() {
    let text = edit("    mass: m1\n", "    mass: m1*(2 + \n");
    let (path, err) = error_of("unparseable", &text);
    let (line, col) = place(&text, "mass: m1*(2", "mass");
    check(
        &path,
        &err,
        (line, Some(col)),
        "bodies[0].mass",
        &["cannot parse `m1*(2 +`"],
    );
}

#[test]
fn unknown_function() {
    let text = edit("    angle: theta\n", "    angle: sinh(theta)\n");
    let (path, err) = error_of("unknown_function", &text);
    let (line, col) = place(&text, "sinh", "angle");
    check(
        &path,
        &err,
        (line, Some(col)),
        "bodies[0].angle",
        &["unknown function `sinh`"],
    );
}

#[test]
fn a_gap_that_cannot_be_solved_for_its_coordinate() {
    // In metres, but quadratic in x1.
    let text = edit(
        "gap: -x1 - ell*cos(theta)",
        "gap: -x1^2/ell - ell*cos(theta)",
    );
    refused(
        "gap_not_linear",
        &text,
        ("gap: -x1^2", "gap"),
        "contacts[0].gap",
        &["linear in `x1`", "d(gap)/dx1"],
    );
    let (line, _) = place(&text, "gap: -x1^2", "gap");
    // The same through `derive_all` directly.
    let (root, path) = write("gap_not_linear_direct", &text);
    let checked = spec::load(&path).unwrap_or_else(|e| panic!("{e}"));
    match derive_all(&[checked]) {
        Err(Error::Spec(e)) => check(&path, &e, (line, None), "contacts[0].gap", &["x1"]),
        other => panic!("expected a spec error, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_gap_that_depends_on_no_coordinate_is_refused() {
    let text = edit(
        "gap: -x1 - ell*cos(theta), eliminates: x1}",
        "gap: ell - a}",
    );
    refused(
        "gap_no_coordinate",
        &text,
        ("gap: ell - a", "gap"),
        "contacts[0].gap",
        &["`ell - a`", "contact `push` depends on no coordinate"],
    );
}

#[test]
fn a_gap_without_a_consistent_unit_is_refused() {
    // Metres and radians added: no unit for the gap, so none for its force.
    let text = edit("gap: -x1 - ell*cos(theta)", "gap: -x1 - theta");
    refused(
        "gap_units",
        &text,
        ("gap: -x1 - theta", "gap"),
        "contacts[0].gap",
        &["the gap of contact `push` has no consistent unit"],
    );
}

#[test]
fn a_gap_that_is_neither_a_length_nor_an_angle_is_refused() {
    // An area: the runtime scales a gap's tolerances as a length or not at all (an angle).
    let text = edit(
        "gap: -x1 - ell*cos(theta)",
        "gap: -x1*ell - ell^2*cos(theta)",
    );
    refused(
        "gap_area",
        &text,
        ("gap: -x1*ell", "gap"),
        "contacts[0].gap",
        &["contact `push` is in m^2", "a length (m) or an angle (rad)"],
    );
}

#[test]
fn two_contacts_of_one_name_are_refused() {
    let text = edit(
        "initial:\n",
        "  - {name: push, meaning: the floor, gap: ell*sin(theta)}\ninitial:\n",
    );
    let (path, err) = error_of("duplicate_contact", &text);
    let (line, col) = place(&text, "meaning: the floor", "name: push");
    check(
        &path,
        &err,
        (line, Some(col)),
        "contacts[1].name",
        &["`push` is declared twice"],
    );
}

#[test]
fn a_coordinate_that_is_not_cyclic_is_integrated_not_refused() {
    // A spring on the foot: the Lagrangian depends on x1, so the general model (every
    // coordinate, the wall a constraint row) has no fast path; it is derived for the integrated
    // route, with the reason. The contact phase ties x1 to theta and still reduces.
    let text = edit(
        "falling_point: centre\n",
        "falling_point: centre\npotentials:\n  - {name: spring, expr: m1*g/ell*x1^2, meaning: a spring on the foot}\n",
    );
    let (root, _) = write("spring_on_foot", &text);
    let (files, _) = render_all(&root, &[]).unwrap_or_else(|e| panic!("{e}"));
    let record = |model: &str| -> serde_json::Value {
        let path = Path::new("generated").join(format!("{model}.json"));
        let f = (files.iter())
            .find(|f| f.path == path)
            .unwrap_or_else(|| panic!("no {}", path.display()));
        serde_json::from_str(&f.text).unwrap()
    };
    let general = record("ladder");
    assert_eq!(general["route"], "integrated");
    assert!(
        general["route_note"]
            .as_str()
            .unwrap()
            .contains("`x1` is not cyclic"),
        "{}",
        general["route_note"]
    );
    assert_eq!(record("ladder_closed")["route"], "reduced");
    let _ = std::fs::remove_dir_all(&root);
}

/// A spec in the retired schema is refused at the retired field, saying what replaced it.
#[test]
fn the_retired_fields_are_refused_with_what_replaced_them() {
    // The one `contact:` of the old schema (BASE as it was written before `contacts:`).
    let text = edit(
        "contacts:\n  - {name: push, meaning: wall push, gap: -x1 - ell*cos(theta), eliminates: x1}\n",
        "contact: {force: push, meaning: wall push, gap: -x1 - ell*cos(theta), eliminates: x1}\n",
    );
    let (path, err) = error_of("retired_contact", &text);
    let (line, col) = place(&text, "contact: {force", "contact");
    check(
        &path,
        &err,
        (line, Some(col)),
        "contact",
        &["`contact:` is now `contacts:`, a list", "`name:`"],
    );
    // Reaction forces projected by hand.
    let text = edit(
        "falling_point: centre\n",
        "falling_point: centre\nforces:\n  - {name: floor_normal, body: rod, direction: [0, 1], meaning: floor push}\n",
    );
    let (path, err) = error_of("retired_forces", &text);
    let (line, col) = place(&text, "forces:", "forces");
    check(
        &path,
        &err,
        (line, Some(col)),
        "forces",
        &[
            "reaction forces projected by hand are retired",
            "`contacts:`",
        ],
    );
    // Fixed shapes.
    let text = edit(
        "initial:\n",
        "scenery:\n  - {rectangle: [a, ell], at: [a/2, ell/2]}\ninitial:\n",
    );
    let (path, err) = error_of("retired_scenery", &text);
    let (line, col) = place(&text, "scenery:", "scenery");
    check(
        &path,
        &err,
        (line, Some(col)),
        "scenery",
        &["`scenery:` is now `obstacles:`"],
    );
    // A friction's `normal:` (now the `contact:` it acts at) and a potential's `acts_on:`.
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, normal: push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    );
    let (path, err) = error_of("retired_normal", &text);
    let (line, col) = place(&text, "name: wall_friction", "normal");
    check(
        &path,
        &err,
        (line, Some(col)),
        "friction[0]",
        &["unknown field `normal`", "contact"],
    );
    let text = edit(
        "falling_point: centre\n",
        "falling_point: centre\npotentials:\n  - {name: spring, expr: m1*g/ell*x1^2, acts_on: [rod], meaning: a spring}\n",
    );
    let (path, err) = error_of("retired_acts_on", &text);
    let (line, col) = place(&text, "acts_on", "acts_on");
    check(
        &path,
        &err,
        (line, Some(col)),
        "potentials[0]",
        &["unknown field `acts_on`"],
    );
}

#[test]
fn a_model_name_that_is_not_a_plain_identifier() {
    for (i, bad) in ["../x", "a/b", "2fast", "rod cube"].iter().enumerate() {
        let text = edit("name: ladder\n", &format!("name: \"{bad}\"\n"));
        let (path, err) = error_of(&format!("name_{i}"), &text);
        let (line, col) = place(&text, "name: \"", "name");
        check(
            &path,
            &err,
            (line, Some(col)),
            "name",
            &[&format!("`{bad}`"), "plain identifier"],
        );
    }
}

#[test]
fn duplicate_names() {
    let text = edit(
        "  - {name: a, meaning: start height, unit: m}\n",
        "  - {name: m1, meaning: start height, unit: m}\n",
    );
    let (path, err) = error_of("duplicate_parameter", &text);
    let (line, col) = place(&text, "start height", "name: m1");
    check(
        &path,
        &err,
        (line, Some(col)),
        "parameters[2].name",
        &["`m1` is declared twice"],
    );
    // A coordinate may not reuse a parameter's name either.
    let text = edit(
        "  - {name: theta, meaning: angle",
        "  - {name: ell, meaning: angle",
    )
    .replace("theta", "ell");
    let (path, err) = error_of("duplicate_coordinate", &text);
    let (line, col) = place(&text, "meaning: angle", "name: ell");
    check(
        &path,
        &err,
        (line, Some(col)),
        "coordinates[1].name",
        &["`ell` is declared twice"],
    );
    // Two points of one name.
    let text = edit("{name: wall, position", "{name: tip, position");
    let (path, err) = error_of("duplicate_point", &text);
    let (line, col) = place(&text, "meaning: wall}", "name: tip");
    check(
        &path,
        &err,
        (line, Some(col)),
        "points[3].name",
        &["`tip` is declared twice"],
    );
}

#[test]
fn a_hand_written_next_phase_is_an_unknown_field() {
    // The phase after a contact is derived from the same spec; `after_separation` is gone.
    let text = format!(
        "{BASE}after_separation:\n  model: no_such_model\n  parameters: {{m1: m1, ell: ell}}\n"
    );
    refused(
        "missing_next",
        &text,
        ("after_separation:", "after_separation"),
        "",
        &["unknown field `after_separation`"],
    );
}

/// BASE with Coulomb friction (`friction` as given) and its coefficient `mu`.
fn with_friction(friction: &str) -> String {
    edit(
        "falling_point: centre\n",
        &format!("falling_point: centre\nfriction:\n{friction}"),
    )
    .replace(
        "  - {name: g, meaning: gravity, unit: m/s^2}\n",
        "  - {name: g, meaning: gravity, unit: m/s^2}\n  - {name: mu, meaning: friction coefficient, unit: \"1\", positive: false}\n",
    )
}

#[test]
fn a_friction_with_a_well_formed_spec_is_accepted() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, contact: push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    );
    let (root, _) = write("friction_ok", &text);
    let (rendered, _) = render_all(&root, &[]).unwrap_or_else(|e| panic!("refused: {e}"));
    assert!(
        rendered
            .iter()
            .any(|r| r.path.extension().is_some_and(|e| e == "rs")
                && r.text.contains("FrictionInfo")
                && r.text.contains("\"wall_friction\"")),
        "no generated model carries the friction"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_friction_at_a_contact_that_does_not_exist_is_refused() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, contact: wall_push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    );
    refused(
        "friction_no_contact",
        &text,
        ("name: wall_friction", "wall_friction"),
        "friction[0].contact",
        &[
            "there is no contact `wall_push`",
            "one of the contacts (push)",
        ],
    );
}

#[test]
fn a_friction_at_a_bilateral_contact_is_refused() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, contact: push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    )
    .replace("eliminates: x1}", "eliminates: x1, bilateral: true}");
    refused(
        "friction_bilateral",
        &text,
        ("name: wall_friction", "wall_friction"),
        "friction[0].contact",
        &["contact `push` is bilateral", "normal force"],
    );
}

#[test]
fn a_friction_coefficient_that_is_not_a_parameter_is_refused() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: 0.3, contact: push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    );
    refused(
        "friction_number",
        &text,
        ("name: wall_friction", "wall_friction"),
        "friction[0].coefficient",
        &["is not a parameter"],
    );
}

#[test]
fn a_friction_direction_that_is_not_a_unit_vector_is_refused() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, contact: push, body: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 2]}\n",
    );
    refused(
        "friction_direction",
        &text,
        ("name: wall_friction", "wall_friction"),
        "friction[0].direction",
        &["not a unit vector"],
    );
}

#[test]
fn a_body_rubbing_against_itself_is_refused() {
    let text = with_friction(
        "  - {name: wall_friction, meaning: wall friction, coefficient: mu, contact: push, body: rod, against: rod, point: [x1 + ell*cos(theta), ell*sin(theta)], direction: [0, 1]}\n",
    );
    refused(
        "friction_itself",
        &text,
        ("name: wall_friction", "wall_friction"),
        "friction[0].against",
        &["cannot rub against itself"],
    );
}

#[test]
fn a_shape_over_the_coordinates_is_refused() {
    let text = edit(
        "    angle: theta\n",
        "    angle: theta\n    shape: {segment: [[0, 0], [ell*cos(theta), 0]]}\n",
    );
    refused(
        "shape_coordinates",
        &text,
        ("shape:", "shape"),
        "bodies[0].shape.segment[1][0]",
        &["undefined symbol `theta`", "allowed here: a, ell, g, m1"],
    );
}

#[test]
fn a_shape_of_two_kinds_or_an_unknown_kind_is_refused() {
    let text = edit(
        "    angle: theta\n",
        "    angle: theta\n    shape: {rectangle: [ell, a], circle: a}\n",
    );
    refused(
        "shape_two_kinds",
        &text,
        ("shape:", "shape"),
        "bodies[0].shape",
        &["exactly one of", "found rectangle and circle"],
    );
    let text = edit(
        "    angle: theta\n",
        "    angle: theta\n    shape: {polygon: [[0, 0], [ell, 0]]}\n",
    );
    refused(
        "shape_unknown_kind",
        &text,
        ("shape:", "shape"),
        "bodies[0].shape",
        &["unknown field `polygon`"],
    );
}

#[test]
fn an_obstacle_given_a_coordinate_is_refused() {
    // Its place...
    let text = edit(
        "initial:\n",
        "obstacles:\n  - {name: step, meaning: a step, at: [x1, 0], shape: {rectangle: [a, a]}}\ninitial:\n",
    );
    refused(
        "obstacle_place",
        &text,
        ("name: step", "step"),
        "obstacles[0].at[0]",
        &["obstacle `step` is fixed", "not on the coordinate `x1`"],
    );
    // ...or its shape.
    let text = edit(
        "initial:\n",
        "obstacles:\n  - {name: step, meaning: a step, at: [0, 0], shape: {segment: [[0, 0], [x1, ell]]}}\ninitial:\n",
    );
    refused(
        "obstacle_shape",
        &text,
        ("name: step", "step"),
        "obstacles[0].shape.segment[1][0]",
        &["obstacle `step` is fixed", "not on the coordinate `x1`"],
    );
}

#[test]
fn shapes_obstacles_and_monitor_units_reach_the_generated_code() {
    let text = edit(
        "initial:\n",
        "obstacles:\n  - {name: block, meaning: a block by the wall, at: [0, 0], shape: {rectangle: [a, ell], at: [a/2, ell/2]}}\nmonitors:\n  - {name: leaning, expr: theta, meaning: the ladder leans, unit: rad}\ninitial:\n",
    )
    .replace(
        "    angle: theta\n",
        "    angle: theta\n    shape: {segment: [[-ell/2, 0], [ell/2, 0]]}\n",
    );
    let (root, _) = write("shapes", &text);
    let (files, _) = render_all(&root, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&root);
    for model in ["ladder", "ladder_closed"] {
        let rust = files
            .iter()
            .find(|f| f.path == Path::new("generated").join(format!("{model}.rs")))
            .unwrap_or_else(|| panic!("no generated/{model}.rs"));
        let code = rust.text.split_whitespace().collect::<Vec<_>>().join(" ");
        for want in [
            "bodies: &[\"rod\"]",
            "kind: ShapeKind::Segment, body: Some(0), first: 0",
            "kind: ShapeKind::Rectangle, body: None, first: 4",
            "unit: \"rad\"",
            "fn drawing(",
            "sizes[7] =",
        ] {
            assert!(code.contains(want), "{model}: no `{want}` in\n{code}");
        }
    }
}

/// `BASE` with a `dimensionless:` block of these groups and force scale.
fn with_dimensionless(groups: &str, force: &str, paper: &str) -> String {
    format!(
        "{BASE}dimensionless:\n  groups:\n{groups}  scales: {{time: sqrt(ell/g), force: {force}}}\n{paper}"
    )
}

#[test]
fn well_formed_groups_and_scales_are_accepted() {
    let text = with_dimensionless(
        "    - {name: r, expr: a/ell, meaning: start height over length}\n",
        "m1*g",
        "  paper: {separation_condition: \"7\"}\n",
    );
    let (root, _) = write("groups_ok", &text);
    render_all(&root, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_group_that_is_a_sum_is_refused() {
    let text = with_dimensionless(
        "    - {name: r, expr: a + ell, meaning: not a ratio}\n",
        "m1*g",
        "",
    );
    let (path, err) = error_of("group_sum", &text);
    let (line, col) = place(&text, "a + ell", "expr");
    check(
        &path,
        &err,
        (line, Some(col)),
        "dimensionless.groups[0].expr",
        &["not a product of powers of parameters"],
    );
}

#[test]
fn a_group_without_a_parameter_to_solve_for_is_refused() {
    let text = with_dimensionless(
        "    - {name: r, expr: a/ell, meaning: ratio}\n    - {name: s, expr: a^2/g^2, meaning: squares only}\n",
        "m1*g",
        "",
    );
    let (path, err) = error_of("group_unsolvable", &text);
    let (line, col) = place(&text, "a^2/g^2", "expr");
    check(
        &path,
        &err,
        (line, Some(col)),
        "dimensionless.groups[1].expr",
        &["no parameter to the first power"],
    );
}

#[test]
fn scales_that_leave_a_unit_are_refused() {
    // Forces in units of g alone keep the mass m1.
    let text = with_dimensionless("    - {name: r, expr: a/ell, meaning: ratio}\n", "g", "");
    let (path, err) = error_of("scales_units", &text);
    let (line, col) = place(&text, "dimensionless:", "dimensionless");
    check(
        &path,
        &err,
        (line, Some(col)),
        "dimensionless",
        &["still depends on `m1`", "do not make it dimensionless"],
    );
}

#[test]
fn a_paper_number_for_an_unknown_result_is_refused() {
    let text = with_dimensionless(
        "    - {name: r, expr: a/ell, meaning: ratio}\n",
        "m1*g",
        "  paper: {energy: \"9\"}\n",
    );
    let (path, err) = error_of("paper_key", &text);
    let (line, col) = place(&text, "paper:", "energy");
    check(
        &path,
        &err,
        (line, Some(col)),
        "dimensionless.paper.energy",
        &["`energy` is not a result of this model"],
    );
}

#[test]
fn a_restitution_outside_zero_to_one_of_a_coordinate_or_with_a_unit_is_refused() {
    let with = |e: &str| {
        edit(
            "eliminates: x1}",
            &format!("eliminates: x1, restitution: {e}}}"),
        )
    };
    // A number outside [0, 1].
    refused(
        "restitution_range",
        &with("1.5"),
        ("name: push", "push"),
        "contacts[0].restitution",
        &["restitution of contact `push` is 1.5", "outside [0, 1]"],
    );
    // An expression of a coordinate (the coefficient is a property of the contact).
    refused(
        "restitution_coordinate",
        &with("x1"),
        ("name: push", "push"),
        "contacts[0].restitution",
        &["x1"],
    );
    // A length is not a coefficient.
    refused(
        "restitution_unit",
        &with("ell"),
        ("name: push", "push"),
        "contacts[0].restitution",
        &["coefficient of restitution"],
    );
    // A bilateral contact never closes on an approach.
    refused(
        "restitution_bilateral",
        &edit(
            "eliminates: x1}",
            "eliminates: x1, bilateral: true, restitution: 0.5}",
        ),
        ("name: push", "push"),
        "contacts[0].restitution",
        &["bilateral contact", "no restitution"],
    );
}

#[test]
fn a_value_that_is_not_an_expression_says_what_an_expression_is() {
    // Not "did not match any variant of untagged enum Text": what is expected, with examples.
    let text = edit("    mass: m1\n", "    mass: [m1]\n");
    refused(
        "not_an_expression",
        &text,
        ("mass:", "mass"),
        "bodies[0].mass",
        &["expected an expression, e.g. `x + 1`"],
    );
    // `true` is YAML's boolean; a bare `y`, `n`, `on` or `no` is a name.
    let text = edit("    angle: theta\n", "    angle: true\n");
    refused(
        "a_boolean",
        &text,
        ("angle: true", "angle"),
        "bodies[0].angle",
        &["boolean", "expected an expression"],
    );
    let text = edit("    angle: theta\n", "    angle: on\n");
    refused(
        "on_is_a_name",
        &text,
        ("angle: on", "angle"),
        "bodies[0].angle",
        &["`on`"],
    );
}
