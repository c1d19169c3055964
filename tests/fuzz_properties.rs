//! Property tests (proptest) that no generated text makes a public parser panic: arbitrary
//! YAML-ish text, structured random scenes and mutated specs, and random expressions go through
//! `Scene::parse`, `spec::parse`, `Expr::parse` (via the fuzz harnesses of `rodcube::fuzzing`)
//! and `rodcube::yaml`; every error they return is placed in the file it names.

use proptest::prelude::*;
use rodcube::scene::{Kind, Scene};
use rodcube::spec::{self, expr::Expr};
use rodcube::yaml;
use std::path::Path;

const SCENE_FILE: &str = "prop_scene.yaml";
const SPEC_FILE: &str = "prop_spec.yaml";

/// YAML-ish noise: the characters YAML gives meaning to, words, numbers and line breaks.
fn yamlish() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("\n".to_string()),
        Just("  ".to_string()),
        Just(": ".to_string()),
        Just("- ".to_string()),
        "[\\[\\]{},:#&*!|>'\"%@`?-]".prop_map(String::from),
        "(model|parameters|want|tolerance|samples|name|bodies|m1|m2|ell|a|g|theta)",
        "(rod_cube|hinged_rod|wall_ladder|separation_angle|theta_series|tip_trajectory)",
        "-?[0-9]{1,4}(\\.[0-9]{0,3})?(e-?[0-9]{1,3})?",
        "(\\.nan|\\.inf|-\\.inf|~|null|true|yes|0x1f|0o17|1_000)",
        "[a-z_]{1,8}",
    ];
    prop::collection::vec(token, 0..60).prop_map(|v| v.concat())
}

/// A YAML value of some kind, often of the wrong kind for where it is put.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        "-?[0-9]{1,3}(\\.[0-9]{1,3})?(e-?[0-9]{1,3})?",
        Just(".nan".to_string()),
        Just("-.inf".to_string()),
        Just("~".to_string()),
        Just("[]".to_string()),
        Just("{}".to_string()),
        Just("\"1.0\"".to_string()),
        "[a-z_]{1,10}",
        Just("[1, 2]".to_string()),
        Just("1e400".to_string()),
        Just("-0.0".to_string()),
        Just("18446744073709551617".to_string()),
    ]
}

/// A scene with keys and values drawn from the right vocabulary and some wrong ones.
fn scene_text() -> impl Strategy<Value = String> {
    let models: Vec<String> = rodcube::models::all()
        .iter()
        .map(|m| m.info().name.to_string())
        .chain(["rod_cubo".to_string(), "".to_string()])
        .collect();
    let param = prop_oneof![
        Just("m1"),
        Just("m2"),
        Just("ell"),
        Just("a"),
        Just("g"),
        Just("theta_s"),
        Just("omega_s"),
        Just("x"),
    ];
    let want = prop_oneof![
        Just("separation_angle"),
        Just("separation_time"),
        Just("floor_impact"),
        Just("theta_series"),
        Just("contact_force_series"),
        Just("tip_trajectory"),
        Just("foot_trajectory"),
        Just("nothing"),
    ];
    (
        prop::sample::select(models),
        prop::collection::vec((param, value()), 0..7),
        prop::collection::vec(want, 0..5),
        prop::option::of(value()),
        prop::option::of(value()),
        any::<bool>(),
        prop::option::of(("[a-z]{1,6}", value())),
    )
        .prop_map(|(model, params, want, tol, samples, flow, extra)| {
            let mut s = format!("model: {model}\n");
            if flow {
                let p: Vec<String> = params.iter().map(|(k, v)| format!("{k}: {v}")).collect();
                s += &format!(
                    "parameters: {{{}}}\nwant: [{}]\n",
                    p.join(", "),
                    want.join(", ")
                );
            } else {
                s += "parameters:\n";
                for (k, v) in &params {
                    s += &format!("  {k}: {v}\n");
                }
                s += "want:\n";
                for w in &want {
                    s += &format!("  - {w}\n");
                }
            }
            if let Some(t) = tol {
                s += &format!("tolerance: {t}\n");
            }
            if let Some(n) = samples {
                s += &format!("samples: {n}\n");
            }
            if let Some((k, v)) = extra {
                s += &format!("{k}: {v}\n");
            }
            s
        })
}

/// A shipped spec with a few lines deleted, duplicated, swapped or with a value replaced.
fn mutated_spec() -> impl Strategy<Value = String> {
    let base = include_str!("../derivations/rod_cube.yaml");
    let mutation = (
        0..4u8,
        any::<prop::sample::Index>(),
        any::<prop::sample::Index>(),
        value(),
    );
    prop::collection::vec(mutation, 1..5).prop_map(move |ms| {
        let mut lines: Vec<String> = base.lines().map(String::from).collect();
        for (kind, i, j, v) in ms {
            if lines.is_empty() {
                break;
            }
            let (i, j) = (i.index(lines.len()), j.index(lines.len()));
            match kind {
                0 => {
                    lines.remove(i);
                }
                1 => {
                    let l = lines[i].clone();
                    lines.insert(j, l);
                }
                2 => lines.swap(i, j),
                _ => {
                    if let Some((k, _)) = lines[i].split_once(": ") {
                        lines[i] = format!("{k}: {v}");
                    } else {
                        lines[i] = format!("{}{v}", lines[i]);
                    }
                }
            }
        }
        lines.join("\n") + "\n"
    })
}

/// Random expression text from the spec grammar, with some near-misses.
fn expression() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        "[0-9]{1,3}",
        "[0-9]{1,2}\\.[0-9]{0,2}(e-?[0-9]{1,3})?",
        Just("170141183460469231731687303715884105727".to_string()),
        Just("99999999999999999999999999999999999999999".to_string()),
        "(x|y|theta|ell|m1|_a|pi)",
    ];
    leaf.prop_recursive(6, 64, 4, |inner| {
        prop_oneof![
            (inner.clone(), "[-+*/^]", inner.clone()).prop_map(|(a, op, b)| format!("{a}{op}{b}")),
            inner.clone().prop_map(|a| format!("({a})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            (
                "(sin|cos|tan|asin|acos|atan|sqrt|exp|log|f)",
                prop::collection::vec(inner, 1..3)
            )
                .prop_map(|(f, args)| format!("{f}({})", args.join(", "))),
        ]
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn yamlish_text_never_panics(text in yamlish()) {
        rodcube::fuzzing::scene(text.as_bytes());
        rodcube::fuzzing::spec(text.as_bytes());
        rodcube::fuzzing::expr(text.as_bytes());
        // Inside the text: at most one line past the last (the end of a text that ends in a
        // line break), at most one column past the end of its line.
        let inside = |m: yaml::Mark| {
            let lines = text.lines().count();
            let width = yaml::line_text(&text, m.line).chars().count();
            m.line >= 1 && m.line <= lines + 1 && m.column >= 1 && m.column <= width + 1
        };
        match yaml::Document::parse(&text) {
            Err(e) => prop_assert!(inside(e.mark), "{:?}\n{:?}", e, text),
            Ok(doc) => {
                if let Err(e) = doc.deserialize::<std::collections::BTreeMap<String, f64>>() {
                    prop_assert!(inside(e.mark), "{:?}\n{:?}", e, text);
                }
            }
        }
        let steps = yaml::parse_path("parameters.m1");
        let (mark, _) = yaml::locate_nearest(&text, &steps, yaml::At::Key);
        prop_assert!(inside(mark), "{:?}\n{:?}", mark, text);
    }

    #[test]
    fn scene_errors_are_placed(text in scene_text()) {
        match Scene::parse(&text, Path::new(SCENE_FILE), rodcube::models::all()) {
            Ok(scene) => prop_assert!(scene.tolerance > 0.0 && scene.samples >= 2),
            Err(e) => {
                prop_assert!(!e.diagnostics.is_empty());
                for d in &e.diagnostics {
                    prop_assert_eq!(d.file.as_path(), Path::new(SCENE_FILE));
                    prop_assert!(d.kind == Kind::Read || d.line >= 1, "{}\n{}", e, text);
                    prop_assert!(!d.message.is_empty());
                }
                prop_assert!(e.to_string().contains(SCENE_FILE));
            }
        }
    }

    #[test]
    fn spec_errors_are_placed(text in mutated_spec()) {
        match spec::parse(Path::new(SPEC_FILE), &text) {
            Ok(checked) => prop_assert!(spec::is_identifier(&checked.spec.name)),
            Err(e) => {
                prop_assert_eq!(e.file.as_path(), Path::new(SPEC_FILE));
                prop_assert!(e.line >= 1, "{}\n{}", e, text);
                prop_assert!(e.to_string().starts_with(SPEC_FILE));
            }
        }
        rodcube::fuzzing::spec(text.as_bytes());
    }

    #[test]
    fn expressions_parse_print_and_reparse(text in expression()) {
        // Everything the grammar makes parses, except function calls that are fine to refuse
        // later (unknown names, arity) and integers too large for i128.
        let parsed = Expr::parse(&text);
        if !text.contains("999999999999999999999") {
            prop_assert!(parsed.is_ok(), "{text}: {parsed:?}");
        }
        rodcube::fuzzing::expr(text.as_bytes());
    }
}
