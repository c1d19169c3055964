//! Invalid model specs are refused with the file, the line (and column where it is precise) and
//! the field of the mistake: one test per error class, on specs written to a temporary project
//! (its own `derivations/` and a copy of `templates/`) so that nothing in the tree is touched.
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
  - {name: theta, meaning: angle to the floor, unit: rad}
reduced: theta
end_angle: 0
bodies:
  - name: rod
    mass: m1
    inertia: m1*ell^2/12
    position: [-ell/2*cos(theta), ell/2*sin(theta)]
    angle: theta
points:
  - {name: foot, position: [-ell*cos(theta), 0], meaning: foot}
  - {name: tip, position: [0, ell*sin(theta)], meaning: top}
  - {name: centre, position: [-ell/2*cos(theta), ell/2*sin(theta)], meaning: centre}
  - {name: wall, position: [0, 0], meaning: wall}
falling_point: centre
forces:
  - {name: push, body: rod, direction: [-1, 0], meaning: wall push}
contact: {force: push, point: tip, surface: wall, normal: [1, 0]}
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

#[test]
fn the_base_spec_is_valid() {
    // The control for every test below: only the edit makes a spec invalid.
    let (root, _) = write("base", BASE);
    let (files, _) = render_all(&root, &[]).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        files
            .iter()
            .any(|f| f.path == Path::new("generated/ladder.rs"))
    );
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
        "position: [-ell/2*cos(theta), ell/2*sin(theta)]\n    angle",
        "position: [-ell/2*cos(theta), ell/2*sin(phi)]\n    angle",
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
fn a_coordinate_that_cannot_be_eliminated() {
    // A spring potential k x1^2 / 2, made as a bob whose height is x1^2: the Lagrangian depends
    // on x1, so x1 is not cyclic and cannot be eliminated through a conserved momentum.
    let text = edit(
        "coordinates:\n",
        "coordinates:\n  - {name: x1, meaning: spring stretch, unit: m}\n",
    )
    .replace(
        "    angle: theta\n",
        "    angle: theta\n  - name: bob\n    mass: m1\n    inertia: 0\n    position: [x1, x1^2]\n    angle: 0\n",
    )
    .replace(
        "initial:\n",
        "initial:\n  x1: {position: 0, velocity: 0}\n",
    );
    let (path, err) = error_of("not_cyclic", &text);
    let (line, col) = place(&text, "name: x1", "{name: x1");
    check(
        &path,
        &err,
        (line, Some(col)),
        "coordinates[0]",
        &["`x1` cannot be eliminated", "depends on it"],
    );
    // The same through `derive_all` directly.
    let (root, path) = write("not_cyclic_direct", &text);
    let checked = spec::load(&path).unwrap_or_else(|e| panic!("{e}"));
    match derive_all(&[checked]) {
        Err(Error::Spec(e)) => check(&path, &e, (line, Some(col)), "coordinates[0]", &["x1"]),
        other => panic!("expected a spec error, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&root);
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
        "coordinates[0].name",
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
fn after_separation_naming_a_missing_model() {
    let text = format!(
        "{BASE}after_separation:\n  model: no_such_model\n  parameters: {{m1: m1, ell: ell}}\n"
    );
    let (path, err) = error_of("missing_next", &text);
    let (line, col) = place(&text, "no_such_model", "no_such_model");
    check(
        &path,
        &err,
        (line, Some(col)),
        "after_separation.model",
        &["no_such_model"],
    );
}
