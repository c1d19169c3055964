//! Tapes (`generated/<model>.tape.json`): every compiled model's tape, evaluated, equals its
//! compiled code to the bit in every method at random inputs, and describes the same
//! `ModelInfo`; the loader refuses broken tapes with typed errors naming the file.

mod common;

use common::hand::Gauss;
use common::numbers::Uniform;
use rodcube::model::{Model, Reduction, TangentPoint};
use rodcube::models;
use rodcube::tape::{self, TapeError};

fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_bits() == y.to_bits() || x.is_nan() && y.is_nan())
}

/// Calls `f` on the compiled model and on the tape with outputs of `len` numbers each, both
/// starting from the same values, and asserts they wrote the same bits.
fn both(name: &str, what: &str, len: usize, mut f: impl FnMut(bool, &mut [f64])) {
    let mut a = vec![7.25; len];
    let mut b = vec![7.25; len];
    f(false, &mut a);
    f(true, &mut b);
    assert!(same(&a, &b), "{name}.{what}: compiled {a:?}\n tape {b:?}");
}

fn check_model(compiled: &dyn Model, taped: &dyn Model, rng: &mut Uniform) {
    let info = compiled.info();
    let name = info.name;
    assert_eq!(
        format!("{info:?}"),
        format!("{:?}", taped.info()),
        "{name}: info"
    );
    let (n, np, m) = (
        info.coordinates.len(),
        info.parameters.len(),
        info.contacts.len(),
    );
    let nf = info.frictions.len();
    let pick = |tape: bool| if tape { taped } else { compiled };
    for _ in 0..5 {
        let p = rng.vec(np, 0.2, 2.0);
        let mut k = vec![0.0; info.n_constants];
        compiled.prepare(&p, &mut k);
        both(name, "prepare", info.n_constants, |t, out| {
            pick(t).prepare(&p, out)
        });
        let (q, qd, qdd) = (
            rng.vec(n, -1.0, 1.5),
            rng.vec(n, -2.0, 2.0),
            rng.vec(n, -3.0, 3.0),
        );
        let forces = rng.vec(m, -2.0, 5.0);
        let fr = rng.vec(nf, -1.0, 1.0);
        both(name, "requirements", info.requirements.len(), |t, o| {
            pick(t).requirements(&p, o)
        });
        both(name, "restitutions", m, |t, o| pick(t).restitutions(&p, o));
        both(name, "initial_state", 2 * n, |t, o| {
            let (a, b) = o.split_at_mut(n);
            pick(t).initial_state(&k, a, b)
        });
        both(name, "points", 4 * info.points.len(), |t, o| {
            let (a, b) = o.split_at_mut(2 * info.points.len());
            let (a, b) = (a.as_chunks_mut::<2>().0, b.as_chunks_mut::<2>().0);
            pick(t).points(&k, &q, &qd, a, b)
        });
        both(name, "energy", 1, |t, o| o[0] = pick(t).energy(&k, &q, &qd));
        both(name, "momenta", info.cyclic.len(), |t, o| {
            pick(t).momenta(&k, &q, &qd, o)
        });
        both(name, "equations", n * n + n, |t, o| {
            let (a, b) = o.split_at_mut(n * n);
            pick(t).equations(&k, &q, &qd, a, b)
        });
        both(name, "forces_full", m, |t, o| {
            pick(t).forces_full(&k, &q, &qd, &qdd, o)
        });
        both(name, "gaps", m, |t, o| pick(t).gaps(&k, &q, o));
        both(name, "constraints", m * n + m, |t, o| {
            let (a, b) = o.split_at_mut(m * n);
            pick(t).constraints(&k, &q, &qd, a, b)
        });
        both(name, "edges", m, |t, o| pick(t).edges(&k, &q, o));
        both(name, "friction", nf * n + nf, |t, o| {
            let (a, b) = o.split_at_mut(nf * n);
            pick(t).friction(&k, &q, &qd, a, b)
        });
        both(name, "monitors_full", info.monitors.len(), |t, o| {
            pick(t).monitors_full(&k, &q, &qd, &forces, o)
        });
        let ns = info.system_coordinates.len();
        both(name, "to_full", 2 * ns, |t, o| {
            let (a, b) = o.split_at_mut(ns);
            pick(t).to_full(&k, &q, &qd, a, b)
        });
        let nb = info.bodies.len();
        both(name, "drawing", 3 * nb + info.drawing_sizes(), |t, o| {
            let (a, b) = o.split_at_mut(3 * nb);
            pick(t).drawing(&k, &q, a.as_chunks_mut::<3>().0, b)
        });
        match (compiled.tangents(), taped.tangents()) {
            (Some(ct), Some(tt)) => {
                let pick = |tape: bool| if tape { tt } else { ct };
                let at = TangentPoint {
                    q: &q,
                    qd: &qd,
                    qdd: &qdd,
                    forces: &forces,
                    friction: &fr,
                };
                let rows = n + 3 * m + 2 * nf;
                both(name, "tangent_rows", rows * (2 * n + np), |t, o| {
                    pick(t).tangent_rows(&k, &at, o)
                });
                both(name, "initial_tangents", 2 * n * np, |t, o| {
                    pick(t).initial_tangents(&k, o)
                });
            }
            (None, None) => {}
            _ => panic!("{name}: the compiled model and its tape differ in having tangents"),
        }
        assert_eq!(
            compiled.reduction().is_some(),
            taped.reduction().is_some(),
            "{name}"
        );
        if let (Some(a), Some(b)) = (compiled.reduction(), taped.reduction()) {
            check_reduction(name, a, b, &p, &k, rng, info);
        }
        assert_eq!(
            compiled.lean_start(&p).map(|s| format!("{s:?}")),
            taped.lean_start(&p).map(|s| format!("{s:?}")),
            "{name}: lean_start"
        );
    }
}

fn check_reduction(
    name: &str,
    compiled: &dyn Reduction,
    taped: &dyn Reduction,
    p: &[f64],
    k: &[f64],
    rng: &mut Uniform,
    info: &rodcube::model::ModelInfo,
) {
    let pick = |tape: bool| if tape { taped } else { compiled };
    let layout = info.reduction.expect("a fast path's layout");
    let np = info.parameters.len();
    let delta = rng.next() * 0.3;
    let (s, c, ds, dc) = (rng.next(), rng.next(), rng.next() * 0.1, rng.next() * 0.1);
    both(name, "reduced", 4, |t, o| {
        let r = pick(t).reduced(k, delta);
        o.copy_from_slice(&[r.sin, r.cos, r.theta_dot_sq, r.theta_ddot]);
    });
    both(name, "theta_dot_sq_sc", 1, |t, o| {
        o[0] = pick(t).theta_dot_sq_sc(k, s, c, ds, dc)
    });
    both(name, "forces", info.contacts.len(), |t, o| {
        pick(t).forces(k, delta, o)
    });
    for (contact, degree) in layout.force_degrees.iter().enumerate() {
        both(name, "force_polynomial", degree + 1, |t, o| {
            pick(t).force_polynomial(k, contact, o)
        });
    }
    let fall = layout.fall_degree.map_or(0, |d| d + 1);
    both(name, "fall_polynomial", fall, |t, o| {
        pick(t).fall_polynomial(k, o)
    });
    both(name, "prepare_lean", info.n_constants, |t, o| {
        pick(t).prepare_lean(p, o)
    });
    match (compiled.partials(), taped.partials()) {
        (Some(cp), Some(tp)) => {
            let pick = |tape: bool| if tape { tp } else { cp };
            both(name, "separation_partials", np + 1, |t, o| {
                pick(t).separation_partials(k, s, c, o)
            });
            both(name, "theta_dot_sq_partials", np, |t, o| {
                pick(t).theta_dot_sq_partials(k, s, c, o)
            });
            both(name, "start_partials", np, |t, o| {
                pick(t).start_partials(k, o)
            });
            both(name, "fall_partials", fall * np, |t, o| {
                pick(t).fall_partials(k, o)
            });
        }
        (None, None) => {}
        _ => panic!("{name}: the compiled model and its tape differ in having partials"),
    }
    let n = info.coordinates.len();
    let (time, rate) = (rng.next(), -rng.next());
    both(name, "full_state", 2 * n, |t, o| {
        let (a, b) = o.split_at_mut(n);
        pick(t).full_state(k, time, delta, rate, a, b)
    });
}

#[test]
fn every_compiled_model_and_its_tape_agree_to_the_bit_in_every_method() {
    let mut rng = Uniform(0x9e37_79b9_7f4a_7c15);
    let mut checked = 0;
    for &compiled in models::compiled() {
        let name = compiled.info().name;
        let text = models::embedded_tape(name).expect("every compiled model embeds its tape");
        let taped = tape::parse(text, name).unwrap_or_else(|e| panic!("{e}"));
        check_model(compiled, &taped, &mut rng);
        checked += 1;
    }
    // Every model the registry declares (counted from its source, not from the list walked).
    let registry =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/generated/mod.rs"))
            .expect("generated/mod.rs");
    let declared = registry
        .lines()
        .filter(|l| l.starts_with("pub mod "))
        .count();
    assert!(declared >= 28, "{declared} models declared");
    assert_eq!(checked, declared);
}

fn paper_tape() -> String {
    models::embedded_tape("rod_cube")
        .expect("embedded")
        .to_string()
}

/// A tape whose body is edited, with its digest brought up to date (so the check under test is
/// the one reached, not the digest's).
fn edited(edit: impl FnOnce(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(&paper_tape()).expect("json");
    edit(&mut v["body"]);
    let body: tape::format::Body = serde_json::from_value(v["body"].clone()).expect("body");
    v["body_digest"] = body.digest().into();
    serde_json::to_string(&v).expect("json")
}

fn refusal(text: &str) -> TapeError {
    match tape::parse(text, "t.tape.json") {
        Ok(_) => panic!("accepted a broken tape"),
        Err(e) => e,
    }
}

#[test]
fn a_truncated_or_hand_edited_tape_is_refused_by_its_digest() {
    let text = paper_tape();
    let cut = &text[..text.len() / 2];
    let e = refusal(cut);
    assert!(matches!(e, TapeError::Syntax { .. }), "{e}");
    assert!(e.to_string().starts_with("t.tape.json:"), "{e}");
    let changed = text.replacen("[\"const\",", "[\"const\",1", 1);
    let e = refusal(&changed);
    assert!(matches!(e, TapeError::Digest { .. }), "{e}");
    assert!(e.to_string().contains("cargo derive"), "{e}");
}

#[test]
fn another_format_version_is_answered_with_the_command_that_regenerates_it() {
    // A tape of the version before this one (its info or methods named otherwise).
    let (now, before) = (tape::VERSION, tape::VERSION - 1);
    let text = paper_tape().replacen(
        &format!("\"version\": {now},"),
        &format!("\"version\": {before},"),
        1,
    );
    let e = refusal(&text);
    assert!(
        matches!(e, TapeError::Version { found, .. } if found == before),
        "{e}"
    );
    assert!(e.to_string().contains("cargo derive"), "{e}");
    let text = paper_tape().replacen("rodcube-tape", "something-else", 1);
    assert!(matches!(refusal(&text), TapeError::Format { .. }));
}

fn method_refusal(method: &str, edit: impl FnOnce(&mut Vec<serde_json::Value>)) -> String {
    let text = edited(|body| {
        let functions = body["functions"].as_array_mut().expect("functions");
        let f = (functions.iter_mut())
            .find(|f| f["name"] == method)
            .expect("method");
        edit(f["code"].as_array_mut().expect("code"));
    });
    let e = refusal(&text);
    assert!(
        matches!(&e, TapeError::Method { method: m, .. } if m == method),
        "{e}"
    );
    e.to_string()
}

#[test]
fn programs_that_could_misbehave_are_refused_naming_the_method_and_instruction() {
    use serde_json::json;
    // An index past the mass matrix's 16 numbers.
    let e = method_refusal("equations", |c| c.push(json!(["st", "mass", 16, 0])));
    assert!(e.contains("past `mass`'s 16 numbers"), "{e}");
    // A register read before anything writes it.
    let e = method_refusal("equations", |c| c.insert(0, json!(["add", 0, 5000, 1])));
    assert!(e.contains("before anything writes it"), "{e}");
    // An argument the method does not have.
    let e = method_refusal("gaps", |c| c.insert(0, json!(["ld", 0, "qdd", 0])));
    assert!(e.contains("`qdd` is not"), "{e}");
    // A register beyond the bound on a tape's registers.
    let e = method_refusal("gaps", |c| {
        c.insert(0, json!(["const", 4_000_000_000u32, 1.0]))
    });
    assert!(e.contains("a tape may use"), "{e}");
    // Methods missing or unknown.
    let text = edited(|b| {
        let f = b["functions"].as_array_mut().expect("functions");
        f.retain(|f| f["name"] != "equations");
    });
    assert!(refusal(&text).to_string().contains("`equations`: missing"));
    let text = edited(|b| b["functions"][0]["name"] = "format_disk".into());
    assert!(refusal(&text).to_string().contains("no such method"));
}

#[test]
fn unknown_operations_and_wrong_arities_are_refused_at_their_line() {
    for (bad, what) in [
        (r#"["jump",0,1]"#, "unknown operation `jump`"),
        (r#"["add",0,1]"#, "takes 3 operands, not 2"),
        (r#"["ld",0,"disk",0]"#, "is not an argument"),
        (r#"["powi",0,1,2.5]"#, "not a 32-bit integer"),
    ] {
        let text = paper_tape().replacen(r#"["ld",0,"p",2]"#, bad, 1);
        assert_ne!(text, paper_tape(), "the paper's tape starts with that load");
        let e = refusal(&text);
        let TapeError::Syntax { line, .. } = &e else {
            panic!("{e}");
        };
        assert!(*line > 1 && e.to_string().contains(what), "{e}");
    }
}

/// A fast path's layout for the paper's two contacts, with these degrees of the second
/// contact's force polynomial and of the fall polynomial.
fn fast_path(force_degree: u64, fall_degree: u64) -> serde_json::Value {
    serde_json::json!({
        "k_theta_initial": 0, "k_theta_dot_initial": 0, "k_sin_initial": 0,
        "k_cos_initial": 0, "force_degrees": [3, force_degree], "fall_degree": fall_degree,
        "lean_constants": []
    })
}

#[test]
fn inconsistent_info_is_refused() {
    use serde_json::json;
    let text = edited(|b| b["info"]["reduced_index"] = 9.into());
    let e = refusal(&text);
    assert!(matches!(e, TapeError::Info { .. }), "{e}");
    assert!(e.to_string().contains("reduced_index"), "{e}");
    let text = edited(|b| b["info"]["n_constants"] = 1u64.into());
    assert!(matches!(refusal(&text), TapeError::Info { .. }));
    // Names that programs look models and parameters up by, and that C gets as C strings.
    for (edit, needle) in [
        (json!(["name", "rod\u{0}cube"]), "`name`"),
        (json!(["system", "rod cube"]), "`system`"),
    ] {
        let text = edited(|b| b["info"][edit[0].as_str().unwrap()] = edit[1].clone());
        let e = refusal(&text);
        assert!(matches!(e, TapeError::Info { .. }), "{e}");
        assert!(e.to_string().contains(needle), "{e}");
    }
    let text = edited(|b| b["info"]["parameters"][1]["name"] = "m1".into());
    let e = refusal(&text);
    assert!(
        e.to_string().contains("parameter `m1` is named twice"),
        "{e}"
    );
    let text = edited(|b| b["info"]["parameters"][0]["name"] = "".into());
    let e = refusal(&text);
    assert!(e.to_string().contains("not an identifier"), "{e}");
    // A unit the runtime cannot read (a sensitivity's unit and an FMU's unit definitions are
    // formed from it), and a requirement's parameter past the list.
    let text = edited(|b| b["info"]["parameters"][0]["unit"] = "furlong".into());
    let e = refusal(&text);
    assert!(e.to_string().contains("parameter `m1` has the unit"), "{e}");
    let text = edited(|b| b["info"]["requirements"][0]["parameters"][0] = 99.into());
    let e = refusal(&text);
    assert!(e.to_string().contains("requirements.parameters"), "{e}");
    // Lengths a caller sizes from the info and could not allocate (the fuzz harness's first
    // finding: a shape's `first` of 2^64 - 1 made the drawing's `sizes` unallocatable, and
    // overflowed where it is summed), or whose sum overflows.
    for edit in [
        (|b: &mut serde_json::Value| b["info"]["shapes"][0]["first"] = u64::MAX.into())
            as fn(&mut serde_json::Value),
        |b| b["info"]["shapes"][0]["first"] = (1u64 << 20).into(),
        |b| b["info"]["reduction"] = fast_path(u64::MAX, 2),
        |b| b["info"]["reduction"] = fast_path(3, 1 << 40),
    ] {
        let e = refusal(&edited(edit));
        assert!(matches!(e, TapeError::Info { .. }), "{e}");
        assert!(
            e.to_string().contains("numbers a method's output may have"),
            "{e}"
        );
    }
}

/// The results.json a scene writes, with `--interpreted` or without, and the run's stderr.
fn scene_results(
    scene: &std::path::Path,
    interpreted: bool,
    out: &std::path::Path,
) -> serde_json::Value {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_rodcube"));
    cmd.arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .arg("--json");
    if interpreted {
        cmd.arg("--interpreted");
    }
    let run = cmd.output().expect("rodcube runs");
    assert!(
        run.status.success(),
        "{}: {}",
        scene.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(out.join("results.json")).expect("results.json");
    serde_json::from_str(&text).expect("results.json is JSON")
}

#[test]
fn every_shipped_scene_gives_the_same_results_json_from_the_tapes_to_the_bit() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("tapes_scenes");
    let mut scenes: Vec<_> = std::fs::read_dir(root.join("scenes"))
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 14, "{scenes:?}");
    for scene in &scenes {
        let stem = scene.file_stem().and_then(|s| s.to_str()).expect("stem");
        let compiled = scene_results(scene, false, &tmp.join(format!("{stem}-compiled")));
        let mut taped = scene_results(scene, true, &tmp.join(format!("{stem}-tape")));
        // The one difference: the tape's run says where its model came from.
        let note = taped["notes"]
            .as_object_mut()
            .and_then(|n| n.remove("model"))
            .unwrap_or_else(|| panic!("{stem}: no note of the tape"));
        assert!(
            note.as_str().is_some_and(|s| s.contains("--interpreted")),
            "{note}"
        );
        if taped["notes"].as_object().is_some_and(|n| n.is_empty()) {
            taped.as_object_mut().expect("object").remove("notes");
        }
        // Serialised by the same writer, equal values print to the same shortest digits: the
        // texts are compared, so a difference in the last bit of any number fails.
        assert_eq!(
            serde_json::to_string_pretty(&compiled).expect("json"),
            serde_json::to_string_pretty(&taped).expect("json"),
            "{stem}: results.json differs between the compiled model and its tape"
        );
    }
}

/// A spec a user writes, with a model not compiled in (its comments say what it is).
const SLED_SPEC: &str = include_str!("specs/sled.yaml");

const SLED_SCENE: &str = "\
model: sled
parameters: {mr: 1.0, mb: 3.0, L: 1.0, h: 0.25, W: 5.0, g: 9.81}
want: [separation_angle, separation_time, push_series]
tolerance: 1.0e-12
samples: 50
";

/// The paper's closed forms for the rod on a free block (`PHYSICS.md`, re-derived by hand):
/// the separation's sine, the root of eq. (14) `3 s^3 - 12 (1+n) s + 8 r (1+n) = 0` in
/// `(0, r)`; its time, `int dtheta / sqrt(theta_dot^2)` of eq. (9) with the substitution
/// `theta = theta_0 - u^2` that removes the endpoint's `1/sqrt`; and the push at release,
/// eq. (16).
fn paper_closed_forms(n: f64, r: f64, ell: f64, g: f64, m2: f64) -> (f64, f64, f64) {
    let f = |s: f64| 3.0 * s.powi(3) - 12.0 * (1.0 + n) * s + 8.0 * r * (1.0 + n);
    let (mut lo, mut hi) = (0.0, r);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    let theta_sep = (0.5 * (lo + hi)).asin();
    let theta0 = r.asin();
    let rate_sq = |theta: f64| {
        let s = theta.sin();
        let d = 4.0 / 3.0 - s * s / (1.0 + n);
        4.0 * (g / ell) * (r - s) / d
    };
    let u_end = (theta0 - theta_sep).sqrt();
    let t_sep =
        Gauss::new(30).integrate(|u| 2.0 * u / rate_sq(theta0 - u * u).sqrt(), 0.0, u_end, 8);
    let (s, c) = (r, theta0.cos());
    let push = m2
        * (-3.0 * g * c * (8.0 * r * (1.0 + n) - 12.0 * (1.0 + n) * s + 3.0 * s.powi(3))
            / (4.0 * (1.0 + n) - 3.0 * s * s).powi(2));
    (theta_sep, t_sep, push)
}

/// An empty directory of this name under the tests' temporary directory.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    dir
}

fn run_in(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("rodcube runs")
}

/// `rodcube ARGS` in `dir`, which must be refused as an invalid scene or spec (exit status 3),
/// and its stderr.
fn refused(dir: &std::path::Path, args: &[&str]) -> String {
    let run = run_in(dir, args);
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(3), "rodcube {args:?}: {err}");
    err
}

/// `rodcube ARGS` in `dir`, which must succeed, and its stdout read as JSON (results.json alone
/// with `--json`).
fn run_json(dir: &std::path::Path, args: &[&str]) -> serde_json::Value {
    let run = run_in(dir, args);
    assert!(
        run.status.success(),
        "rodcube {args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).expect("stdout is JSON alone")
}

fn check_sled(results: &serde_json::Value, what: &str) {
    let value = |k: &str| {
        results["results"][k]["value"]
            .as_f64()
            .unwrap_or_else(|| panic!("{what}: {k}"))
    };
    let (theta_sep, t_sep, push0) = paper_closed_forms(3.0, 0.25, 1.0, 9.81, 3.0);
    let angle = value("separation_angle");
    let time = value("separation_time");
    assert!(
        (angle - theta_sep).abs() < 1e-9,
        "{what}: angle {angle} vs {theta_sep}"
    );
    assert!(
        (time - t_sep).abs() < 1e-9 * t_sep,
        "{what}: time {time} vs {t_sep}"
    );
    let push = &results["series"]["push_series"]["columns"];
    let force = (push.as_array().into_iter().flatten())
        .find(|c| c["name"] == "push")
        .unwrap_or_else(|| panic!("{what}: push_series {push}"));
    let first = force["values"][0].as_f64().expect("a number");
    assert!(
        (first - push0).abs() < 1e-9 * push0.abs(),
        "{what}: push {first} vs {push0}"
    );
}

#[test]
fn a_new_spec_runs_at_once_through_spec_and_through_its_tapes_and_matches_the_closed_forms() {
    let dir = scratch("tapes_sled");
    std::fs::write(dir.join("sled.yaml"), SLED_SPEC).expect("spec");
    std::fs::write(dir.join("scene.yaml"), SLED_SCENE).expect("scene");
    // 1. `--spec`: derived in memory, run at once; stdout is exactly results.json (Symbolica's
    //    banner goes to stderr) and nothing is written but the outputs.
    let derived = run_json(
        &dir,
        &[
            "run",
            "scene.yaml",
            "--spec",
            "sled.yaml",
            "--json",
            "--out",
            "out",
        ],
    );
    check_sled(&derived, "--spec");
    let note = derived["notes"]["model"].as_str().unwrap_or_default();
    assert!(note.contains("derived from sled.yaml"), "{note}");
    assert!(!dir.join("generated").exists());
    // 2. The tapes written by `derive --tapes-into` and found by `--models`: the same numbers
    //    to the bit.
    let tapes = run_in(&dir, &["derive", "--tapes-into", "models", "sled.yaml"]);
    assert!(
        tapes.status.success(),
        "{}",
        String::from_utf8_lossy(&tapes.stderr)
    );
    assert!(dir.join("models/sled.tape.json").is_file());
    let loaded = run_json(
        &dir,
        &[
            "run",
            "scene.yaml",
            "--models",
            "models",
            "--json",
            "--out",
            "out2",
        ],
    );
    check_sled(&loaded, "--models");
    for key in ["separation_angle", "separation_time"] {
        assert_eq!(
            derived["results"][key]["value"].as_f64().map(f64::to_bits),
            loaded["results"][key]["value"].as_f64().map(f64::to_bits),
            "{key}"
        );
    }
    let note = loaded["notes"]["model"].as_str().unwrap_or_default();
    assert!(note.contains("not compiled into this program"), "{note}");
    // 3. A spec with an error is refused with its file, line and field, exit 3, no output.
    std::fs::write(
        dir.join("bad.yaml"),
        SLED_SPEC.replace("inertia: mr*L^2/12", "inertia: mr*L^2/12 +"),
    )
    .expect("spec");
    let run = run_in(
        &dir,
        &["run", "scene.yaml", "--spec", "bad.yaml", "--out", "out3"],
    );
    assert_eq!(
        run.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("bad.yaml:"), "{err}");
    assert!(!dir.join("out3/results.json").exists());
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).expect("directory");
    for entry in std::fs::read_dir(from).expect("readable") {
        let path = entry.expect("entry").path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().expect("name"))).expect("copy");
        }
    }
}

#[test]
fn rodcube_derive_then_rodcube_run_runs_the_edited_spec_with_no_build() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = scratch("tapes_project");
    for sub in ["derivations", "templates", "generated", "scenes"] {
        copy_dir(&root.join(sub), &dir.join(sub));
    }
    let compiled = run_json(&dir, &["run", "scenes/paper.yaml", "--json", "--out", "o0"]);
    assert!(
        compiled["notes"]["model"].is_null(),
        "the project's own tapes are the compiled ones"
    );
    // The user edits the spec (the rod's inertia about its centre doubled) and derives it with
    // the binary already built: the program changes, and the same binary runs it.
    let spec = dir.join("derivations/rod_cube.yaml");
    let text = std::fs::read_to_string(&spec).expect("spec");
    let edited = text.replacen("inertia: m1*ell^2/12", "inertia: m1*ell^2/6", 1);
    assert_ne!(edited, text, "the paper's spec gives the rod's inertia so");
    std::fs::write(&spec, &edited).expect("spec");
    let derive = run_in(&dir, &["derive", "derivations/rod_cube.yaml"]);
    assert!(
        derive.status.success(),
        "{}",
        String::from_utf8_lossy(&derive.stderr)
    );
    let taped = run_json(&dir, &["run", "scenes/paper.yaml", "--json", "--out", "o1"]);
    let note = taped["notes"]["model"].as_str().unwrap_or_default();
    assert!(
        note.contains("another program than the compiled-in model"),
        "{note}"
    );
    let angle = |v: &serde_json::Value| v["results"]["separation_angle"]["value"].as_f64();
    assert_ne!(
        angle(&taped),
        angle(&compiled),
        "the edit changes the motion"
    );
    // The same edited spec through `--spec` (derived in memory) gives the same bits.
    let fresh = run_json(
        &dir,
        &[
            "run",
            "scenes/paper.yaml",
            "--spec",
            "derivations/rod_cube.yaml",
            "--json",
            "--out",
            "o2",
        ],
    );
    assert_eq!(
        angle(&fresh).map(f64::to_bits),
        angle(&taped).map(f64::to_bits)
    );
    // Edited again without deriving: the tape still runs, and the results say the spec moved on.
    std::fs::write(
        &spec,
        edited.replacen("inertia: m1*ell^2/6", "inertia: m1*ell^2/4", 1),
    )
    .expect("spec");
    let stale = run_json(&dir, &["run", "scenes/paper.yaml", "--json", "--out", "o3"]);
    let note = stale["notes"]["spec"].as_str().unwrap_or_default();
    assert!(
        note.contains("has changed since") && note.contains("cargo derive"),
        "{note}"
    );
    assert_eq!(
        angle(&stale).map(f64::to_bits),
        angle(&taped).map(f64::to_bits)
    );
}

#[test]
fn a_spec_with_coordinates_x_and_y_and_a_parameter_n_written_bare_derives_and_runs() {
    // YAML 1.1 would read a bare `y` or `n` as a boolean; rodcube reads them as the names they
    // are. The paper's rod on a cube with every support a contact, renamed: coordinates `x`,
    // `y` for the foot, and the restitution `n`.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let spec =
        std::fs::read_to_string(root.join("derivations/rod_cube_liftoff.yaml")).expect("spec");
    let spec = spec
        .replace("name: rod_cube_liftoff", "name: renamed")
        .replace("x1", "x")
        .replace("y1", "y")
        .replace("{name: e,", "{name: n,")
        .replace("restitution: e", "restitution: n")
        .replace(
            "- {name: n, expr: m2/m1",
            "- {name: mass_ratio, expr: m2/m1",
        );
    assert!(spec.contains("position: [x, y]") && spec.contains("restitution: n"));
    let dir = scratch("tapes_renamed");
    std::fs::write(dir.join("renamed.yaml"), &spec).expect("spec");
    let scene = "model: renamed\nparameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81, n: 0}\n\
                 want: [separation_time]\ntolerance: 1.0e-12\n";
    std::fs::write(dir.join("scene.yaml"), scene).expect("scene");
    let results = run_json(
        &dir,
        &[
            "run",
            "scene.yaml",
            "--spec",
            "renamed.yaml",
            "--json",
            "--out",
            "o",
        ],
    );
    let time = results["results"]["separation_time"]["value"]
        .as_f64()
        .expect("a time");
    let (_, t_sep, _) = paper_closed_forms(3.0, 0.25, 1.0, 9.81, 3.0);
    assert!((time - t_sep).abs() < 1e-9 * t_sep, "{time} vs {t_sep}");
}

#[test]
fn pi_is_a_constant_in_expressions() {
    // The sled again with its rod's angle written through `pi`: `cos(th) = -cos(pi - th)`,
    // `sin(th) = sin(pi - th)`, an angle `th + 2*pi` (the same orientation) and a release at
    // `pi/2 - acos(h/L)`: the same motion, the paper's closed forms again.
    let spec = SLED_SPEC
        .replace("name: sled", "name: sled_pi")
        .replace(
            "position: [xf + L/2*cos(th), yf + L/2*sin(th)], angle: th,",
            "position: [xf - L/2*cos(pi - th), yf + L/2*sin(pi - th)], angle: th + 2*pi,",
        )
        .replace("gap: xb - xf - L*cos(th)", "gap: xb - xf + L*cos(pi - th)")
        .replace(
            "th: {position: asin(h/L)",
            "th: {position: pi/2 - acos(h/L)",
        );
    assert_eq!(spec.matches("(pi - th)").count(), 3, "{spec}");
    assert!(
        spec.contains("th + 2*pi") && spec.contains("pi/2 - acos"),
        "{spec}"
    );
    let dir = scratch("tapes_pi");
    std::fs::write(dir.join("sled_pi.yaml"), &spec).expect("spec");
    std::fs::write(
        dir.join("scene.yaml"),
        SLED_SCENE.replace("model: sled", "model: sled_pi"),
    )
    .expect("scene");
    let results = run_json(
        &dir,
        &[
            "run",
            "scene.yaml",
            "--spec",
            "sled_pi.yaml",
            "--json",
            "--out",
            "o",
        ],
    );
    check_sled(&results, "pi");
    // `pi` is no name to declare.
    let taken = spec.replace("{name: W, meaning", "{name: pi, meaning");
    std::fs::write(dir.join("taken.yaml"), taken).expect("spec");
    let err = refused(
        &dir,
        &["run", "scene.yaml", "--spec", "taken.yaml", "--out", "o2"],
    );
    assert!(err.contains("`pi` is the constant"), "{err}");
}

/// The fuzz target's harness (`rodcube::fuzzing::tape`, `fuzz/fuzz_targets/tape.rs`) on edits
/// drawn from a seeded generator: the paper's tape edited 4,000 ways and every other compiled
/// model's 40 (operands replaced or moved by one, operations renamed, instructions deleted,
/// duplicated or swapped, methods dropped or renamed, numbers and lists of the info changed,
/// digits of the text replaced; the digest brought up to date unless an edit says not to).
/// Each must be refused with a `TapeError` naming the file, or accepted with every method of
/// every trait running on it; the edits reach every check (each kind of refusal is seen) and
/// some are accepted.
#[test]
fn edited_tapes_are_refused_or_run_every_method_without_a_panic() {
    use rodcube::fuzzing::{TapeOutcome, tape as harness};
    let compiled = models::compiled();
    let paper = (compiled.iter())
        .position(|m| m.info().name == "rod_cube")
        .expect("rod_cube is compiled") as u8;
    let mut rng = Uniform(0x2545_f491_4f6c_dd1d);
    let mut byte = move || (rng.next() * 256.0) as u8;
    let mut inputs = Vec::new();
    for (model, count) in std::iter::once((
        paper,
        std::env::var("N").map_or(4000, |v| v.parse().unwrap()),
    ))
    .chain(
        (0..compiled.len() as u8)
            .filter(|&i| i != paper)
            .map(|i| (i, 40)),
    ) {
        for _ in 0..count {
            let len = 1 + (byte() % 24) as usize;
            let mut data = vec![model];
            data.extend((0..len).map(|_| byte()));
            inputs.push(data);
        }
    }
    let mut seen = std::collections::BTreeMap::<&str, usize>::new();
    let mut panics = Vec::new();
    for data in &inputs {
        let kind = match std::panic::catch_unwind(|| harness(data)) {
            Err(_) => {
                panics.push(data.iter().map(|b| format!("{b:02x}")).collect::<String>());
                continue;
            }
            Ok(TapeOutcome::Accepted) => "accepted",
            Ok(TapeOutcome::Skipped) => "skipped",
            Ok(TapeOutcome::Refused(e)) => match e {
                TapeError::Syntax { .. } => "syntax",
                TapeError::Format { .. } | TapeError::Version { .. } => "format",
                TapeError::Digest { .. } => "digest",
                TapeError::Info { .. } => "info",
                TapeError::Method { .. } => "method",
                TapeError::Io { .. } => "io",
            },
        };
        *seen.entry(kind).or_default() += 1;
    }
    assert!(
        panics.is_empty(),
        "{} of {} inputs panic (hex, as the fuzz target reads them): {panics:#?}",
        panics.len(),
        inputs.len()
    );
    for kind in ["accepted", "syntax", "format", "digest", "info", "method"] {
        assert!(
            seen.get(kind).copied().unwrap_or(0) >= 10,
            "{kind}: {seen:?}"
        );
    }
    // The unedited tapes are accepted, and so is a whole tape given as text.
    for i in 0..compiled.len() as u8 {
        assert!(matches!(harness(&[i]), TapeOutcome::Accepted));
    }
    assert!(matches!(
        harness(paper_tape().as_bytes()),
        TapeOutcome::Accepted
    ));
}

const BALL_SPEC: &str = include_str!("specs/ball.yaml");

/// The ball of `tests/specs/ball.yaml` (no reduced coordinate, no end angle, no falling point)
/// dropped from `H = 1.1 m` with `R = 0.1 m`, `e = 0.5`, run to `until` (the line is the
/// scene's last).
const BALL_SCENE: &str = "model: ball\n\
    parameters: {m: 1.0, R: 0.1, H: 1.1, v0: 0.5, g: 9.81, e: 0.5}\n\
    want: [impacts, floor_series, centre_trajectory]\n\
    tolerance: 1.0e-12\n\
    until: 1.2\n";

/// The ball's results: its impacts at the closed form of a body bouncing under gravity,
/// `t_n = t_1 + 2 t_1 sum_{k=1}^{n-1} e^k` with `t_1 = sqrt(2 (H - R) / g)` (the third at
/// 1.129 s, the fourth past `until`), the run to `until` with the horizontal motion uniform,
/// and the floor's series with no angle column (the system has none).
fn check_ball(results: &serde_json::Value, what: &str) {
    let t1 = (2.0 * 1.0 / 9.81_f64).sqrt();
    let impacts = results["results"]["impacts"]["value"]
        .as_array()
        .unwrap_or_else(|| panic!("{what}: impacts {}", results["results"]));
    let times: Vec<f64> = (impacts.iter())
        .map(|i| i["time"].as_f64().expect("a time"))
        .collect();
    let want = [t1, 2.0 * t1, 2.5 * t1];
    assert_eq!(times.len(), want.len(), "{what}: impacts at {times:?}");
    for (t, w) in times.iter().zip(want) {
        assert!((t - w).abs() < 1e-9 * w, "{what}: impact at {t} vs {w}");
    }
    let columns = |key: &str| -> Vec<(String, Vec<f64>)> {
        let cols = results["series"][key]["columns"].as_array();
        (cols.into_iter().flatten())
            .map(|c| {
                let values = (c["values"].as_array().into_iter().flatten())
                    .map(|v| v.as_f64().expect("a number"))
                    .collect();
                (c["name"].as_str().expect("a name").to_string(), values)
            })
            .collect()
    };
    let floor = columns("floor_series");
    let names: Vec<&str> = floor.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["t", "floor"], "{what}");
    let centre = columns("centre_trajectory");
    let (t, x) = (&centre[0].1, &centre[1].1);
    let (end, x_end) = (t[t.len() - 1], x[x.len() - 1]);
    assert_eq!(end, 1.2, "{what}: the run ends at until");
    assert!((x_end - 0.5 * 1.2).abs() < 1e-12, "{what}: x = {x_end}");
    let notes = results["notes"].to_string();
    assert!(notes.contains("until"), "{what}: {notes}");
}

#[test]
fn a_spec_without_an_angle_an_end_or_a_falling_point_runs_to_its_scenes_until() {
    let dir = scratch("tapes_ball");
    std::fs::write(dir.join("ball.yaml"), BALL_SPEC).expect("spec");
    std::fs::write(dir.join("scene.yaml"), BALL_SCENE).expect("scene");
    let json = ["--json", "--out"];
    let spec = ["run", "scene.yaml", "--spec", "ball.yaml"];
    let derived = run_json(&dir, &[&spec[..], &json[..], &["o1"]].concat());
    check_ball(&derived, "--spec");
    let tapes = run_in(&dir, &["derive", "--tapes-into", "models", "ball.yaml"]);
    assert!(tapes.status.success(), "{tapes:?}");
    let taped = run_json(
        &dir,
        &[
            "run",
            "scene.yaml",
            "--models",
            "models",
            "--json",
            "--out",
            "o2",
        ],
    );
    check_ball(&taped, "tapes");
    // Without `until` the motion has no end: the scene is refused at `model`'s line, naming
    // `until`, with exit status 3 and nothing written.
    let endless = BALL_SCENE.replace("until: 1.2\n", "");
    std::fs::write(dir.join("endless.yaml"), endless).expect("scene");
    let stderr = refused(
        &dir,
        &["run", "endless.yaml", "--spec", "ball.yaml", "--out", "o3"],
    );
    assert!(stderr.contains("endless.yaml:1:"), "{stderr}");
    assert!(
        stderr.contains("error[structure]: until: ") && stderr.contains("no end angle"),
        "{stderr}"
    );
    assert!(!dir.join("o3").exists());
    // And what is measured in an angle the system does not have is refused by name.
    let angled = BALL_SCENE.replace("want: [impacts,", "want: [theta_series, impacts,");
    std::fs::write(dir.join("angled.yaml"), angled).expect("scene");
    let stderr = refused(
        &dir,
        &["run", "angled.yaml", "--spec", "ball.yaml", "--out", "o4"],
    );
    assert!(
        stderr.contains("want[0]") && stderr.contains("no reduced coordinate"),
        "{stderr}"
    );
}
