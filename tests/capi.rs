//! The C ABI: `examples/c/run.sh` builds the library and `examples/c/paper.c` with the system C
//! compiler (which also checks `include/rodcube.h`) and prints the paper's separation angle
//! and time and their sensitivities to every parameter, equal to the bit to the Rust
//! per-point solver's; the header's constants and struct layout, as a C compiler reads them,
//! are the library's; every function answers bad arguments and failures with the code of
//! their kind (each reachable code from a concrete input) and a message, never a crash; a
//! scene is solved once, its results read from the handle as often as wanted; and a model
//! derived by the test from a spec of its own, not compiled in, is loaded from its tapes by
//! `rodcube_models_load` and solved and run from C (`examples/c/tapes.c` too) to the paper's
//! closed forms, while a corrupted tape is refused with its code and a message naming it.

use rodcube::solve::fast::lean::LeanSolver;
use std::path::Path;
use std::process::Command;

const PAPER: [f64; 5] = [1.0, 3.0, 1.0, 0.25, 9.81];

#[test]
fn the_c_example_prints_the_rust_solvers_numbers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Not the test run's target directory; tests/library_only.rs checks the library in this
    // one too, reusing the build scripts and proc macros compiled here.
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi");
    // cargo test puts its own target directories on LD_LIBRARY_PATH, which the dynamic loader
    // searches before the programs' run path: a `librodcube.so` left there by another build
    // (`examples/c/run.sh` run by hand) would be loaded instead of the one built here.
    let out = Command::new(root.join("examples/c/run.sh"))
        .env("CARGO_TARGET_DIR", &target)
        .env("CARGO", env!("CARGO"))
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .expect("run.sh runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "run.sh failed ({:?}):\n{stdout}\n{stderr}",
        out.status
    );
    let line = stdout.lines().next().unwrap_or("");
    let value = |key: &str| -> f64 {
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no {key} in {line:?}"))
    };
    let model = rodcube::models::find("rod_cube").expect("generated model");
    let rust = LeanSolver::new(model).unwrap().solve(&PAPER).unwrap();
    assert_eq!(
        value("separation_angle").to_bits(),
        rust.separation_angle.to_bits()
    );
    assert_eq!(
        value("separation_time").to_bits(),
        rust.separation_time.to_bits()
    );
    // The second line: the point's sensitivities, the Rust per-point solver's to the bit.
    let second = stdout.lines().nth(1).unwrap_or("");
    let mut solver = LeanSolver::new(model).unwrap();
    let point = solver.solve(&PAPER).unwrap();
    let (mut d_angle, mut d_time) = ([0.0; 5], [0.0; 5]);
    let mut work = rodcube::solve::fast::sensitivity::SensitivityWork::default();
    (solver.sensitivities(&PAPER, &point, &mut work, &mut d_angle, &mut d_time))
        .unwrap()
        .unwrap();
    for (i, p) in model.info().parameters.iter().enumerate() {
        for (of, want) in [
            ("separation_angle", d_angle[i]),
            ("separation_time", d_time[i]),
        ] {
            let key = format!("d({of})/d({})=", p.name);
            let got: f64 = (second.split_whitespace())
                .find_map(|kv| kv.strip_prefix(&key)?.parse().ok())
                .unwrap_or_else(|| panic!("no {key} in {second:?}"));
            assert_eq!(got.to_bits(), want.to_bits(), "{key}");
        }
    }

    // The README's C example, inside a `main`, against the library run.sh built: it prints the
    // same line.
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let snippet = readme
        .split("```c\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("a C example in the README");
    let dir = target.join("readme-c");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let source = dir.join("readme.c");
    let program = format!(
        "#include <stdio.h>\n#include \"rodcube.h\"\nint main(void) {{\n{snippet}return 0;\n}}\n"
    );
    std::fs::write(&source, program).expect("write readme.c");
    let lib = target.join("release");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let built = Command::new(cc)
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg(format!("-I{}", root.join("include").display()))
        .arg(&source)
        .arg(format!("-L{}", lib.display()))
        .arg("-lrodcube")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-o")
        .arg(dir.join("readme"))
        .output()
        .expect("the C compiler runs");
    assert!(
        built.status.success(),
        "the README's C example does not compile:\n{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let ran = Command::new(dir.join("readme"))
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .expect("it runs");
    assert!(ran.status.success());
    assert_eq!(
        String::from_utf8_lossy(&ran.stdout).lines().next(),
        Some(line)
    );
}

#[cfg(feature = "capi")]
mod calls {
    use super::PAPER;
    use rodcube::ffi::*;
    use std::collections::BTreeSet;
    use std::ffi::{CStr, CString, c_char, c_int};
    use std::path::Path;
    use std::process::Command;
    use std::ptr::{null, null_mut};
    use std::sync::{Mutex, MutexGuard};

    /// A call's status code and message.
    type Outcome = (c_int, String);

    /// The registry is the process's: a test that reads it whole, or loads tapes into it, holds
    /// this while it does.
    static REGISTRY: Mutex<()> = Mutex::new(());

    fn registry() -> MutexGuard<'static, ()> {
        REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn message(err: &[c_char]) -> String {
        // SAFETY: the functions always NUL-terminate a non-empty buffer.
        unsafe { CStr::from_ptr(err.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    /// `rodcube_error_name` as a Rust string.
    fn name_of(code: c_int) -> Option<String> {
        let p = rodcube_error_name(code);
        // SAFETY: NULL or a static NUL-terminated string.
        (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    fn new_solver(name: &CStr) -> Result<*mut RodcubeSolver, Outcome> {
        let mut err = [0 as c_char; 512];
        let mut s = std::ptr::dangling_mut();
        // SAFETY: valid string, out pointer and buffer.
        let code = unsafe { rodcube_solver_new(name.as_ptr(), &mut s, err.as_mut_ptr(), 512) };
        if code == RODCUBE_OK {
            assert!(!s.is_null());
            Ok(s)
        } else {
            assert!(s.is_null(), "a failed rodcube_solver_new leaves NULL");
            Err((code, message(&err)))
        }
    }

    fn solver(name: &str) -> Result<*mut RodcubeSolver, Outcome> {
        new_solver(&CString::new(name).unwrap())
    }

    fn solve(s: *mut RodcubeSolver, params: &[f64]) -> Outcome {
        let mut err = [0 as c_char; 512];
        let mut out = RodcubePoint::default();
        // SAFETY: a live solver, valid slices and buffers.
        let code = unsafe {
            rodcube_solve(
                s,
                params.as_ptr(),
                params.len(),
                &mut out,
                err.as_mut_ptr(),
                512,
            )
        };
        (code, message(&err))
    }

    fn solve_named(s: *mut RodcubeSolver, names: &[&str], values: &[f64]) -> Outcome {
        let names: Vec<CString> = names.iter().map(|n| CString::new(*n).unwrap()).collect();
        let p: Vec<*const c_char> = names.iter().map(|c| c.as_ptr()).collect();
        let mut err = [0 as c_char; 512];
        let mut out = RodcubePoint::default();
        // SAFETY: a live solver, `n` names and values, valid buffers.
        let code = unsafe {
            rodcube_solve_named(
                s,
                p.as_ptr(),
                values.as_ptr(),
                names.len().min(values.len()),
                &mut out,
                err.as_mut_ptr(),
                512,
            )
        };
        (code, message(&err))
    }

    fn run_scene(yaml: &str) -> Result<*mut RodcubeResults, Outcome> {
        let yaml = CString::new(yaml).unwrap();
        let mut err = [0 as c_char; 2048];
        let mut results = std::ptr::dangling_mut();
        // SAFETY: valid string, out pointer and buffer.
        let code =
            unsafe { rodcube_run_scene(yaml.as_ptr(), &mut results, err.as_mut_ptr(), 2048) };
        if code == RODCUBE_OK {
            assert!(!results.is_null());
            Ok(results)
        } else {
            assert!(results.is_null(), "a failed rodcube_run_scene leaves NULL");
            Err((code, message(&err)))
        }
    }

    fn scene_error(yaml: &str) -> Outcome {
        match run_scene(yaml) {
            Ok(results) => {
                // SAFETY: made by rodcube_run_scene, released once.
                unsafe { rodcube_results_free(results) };
                panic!("the scene ran:\n{yaml}")
            }
            Err(outcome) => outcome,
        }
    }

    const PAPER_SCENE: &str = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle, separation_time, theta_series]\nsamples: 50\n";

    #[test]
    fn models_and_parameters_are_listed() {
        let _registry = registry();
        let n = rodcube_model_count();
        assert_eq!(n, rodcube::models::all().len());
        let names: Vec<String> = (0..n)
            // SAFETY: static NUL-terminated strings.
            .map(|i| unsafe { CStr::from_ptr(rodcube_model_name(i)) })
            .map(|s| s.to_string_lossy().into_owned())
            .collect();
        let i = names.iter().position(|m| m == "rod_cube").unwrap();
        assert_eq!(rodcube_parameter_count(i), 5);
        // SAFETY: as above.
        let a = unsafe { CStr::from_ptr(rodcube_parameter_name(i, 3)) };
        assert_eq!(a.to_str(), Ok("a"));
        assert!(rodcube_model_name(n).is_null());
        assert!(rodcube_parameter_name(i, 5).is_null());
        assert_eq!(rodcube_parameter_count(n), 0);
    }

    /// The header's `#define`s and `rodcube_point`, compiled by the system C compiler: every
    /// constant has the value the library names by `rodcube_error_name`, and the struct has
    /// Rust's size, alignment and field offsets.
    #[test]
    fn the_headers_constants_and_layout_are_the_librarys() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let header = std::fs::read_to_string(root.join("include/rodcube.h")).unwrap();
        let defines: Vec<&str> = header
            .lines()
            .filter_map(|l| l.strip_prefix("#define "))
            .filter_map(|l| l.split_whitespace().next())
            .filter(|n| *n != "RODCUBE_H")
            .collect();
        let mut program = String::from(
            "#include <stddef.h>\n#include <stdio.h>\n#include \"rodcube.h\"\nint main(void) {\n\
             printf(\"size %zu\\n\", sizeof(rodcube_point));\n\
             printf(\"align %zu\\n\", _Alignof(rodcube_point));\n\
             printf(\"separation_angle %zu\\n\", offsetof(rodcube_point, separation_angle));\n\
             printf(\"separation_time %zu\\n\", offsetof(rodcube_point, separation_time));\n\
             printf(\"delta %zu\\n\", offsetof(rodcube_point, delta));\n",
        );
        for name in &defines {
            program.push_str(&format!("printf(\"{name} %d\\n\", {name});\n"));
        }
        program.push_str("return 0;\n}\n");
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-layout");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("layout.c"), program).unwrap();
        let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
        let built = Command::new(cc)
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
            .arg(format!("-I{}", root.join("include").display()))
            .arg(dir.join("layout.c"))
            .arg("-o")
            .arg(dir.join("layout"))
            .output()
            .expect("the C compiler runs");
        assert!(
            built.status.success(),
            "{}",
            String::from_utf8_lossy(&built.stderr)
        );
        let ran = Command::new(dir.join("layout")).output().expect("it runs");
        let stdout = String::from_utf8_lossy(&ran.stdout);
        let mut seen = BTreeSet::new();
        for line in stdout.lines() {
            let (name, value) = line.split_once(' ').unwrap();
            let value: usize = value.parse().unwrap_or_else(|_| {
                // Negative values are no codes.
                panic!("{line}")
            });
            let expected = match name {
                "size" => size_of::<RodcubePoint>(),
                "align" => align_of::<RodcubePoint>(),
                "separation_angle" => std::mem::offset_of!(RodcubePoint, separation_angle),
                "separation_time" => std::mem::offset_of!(RodcubePoint, separation_time),
                "delta" => std::mem::offset_of!(RodcubePoint, delta),
                _ => {
                    let code = c_int::try_from(value).unwrap();
                    assert_eq!(name_of(code).as_deref(), Some(name), "{name} = {value}");
                    seen.insert(code);
                    continue;
                }
            };
            assert_eq!(value, expected, "{name}");
        }
        // And the other way: every code the library names is defined in the header.
        let named: BTreeSet<c_int> = (-10..1000).filter(|&c| name_of(c).is_some()).collect();
        assert_eq!(seen, named);
        assert_eq!(seen.len(), defines.len(), "two names for one value");
    }

    #[test]
    fn codes_have_names_and_groups() {
        assert_eq!(name_of(RODCUBE_OK).as_deref(), Some("RODCUBE_OK"));
        assert_eq!(
            name_of(RODCUBE_ERR_AT_REST).as_deref(),
            Some("RODCUBE_ERR_AT_REST")
        );
        for no_code in [
            -1,
            3,
            4,
            5,
            99,
            117,
            299,
            339,
            416,
            508,
            600,
            c_int::MAX,
            c_int::MIN,
        ] {
            assert_eq!(name_of(no_code), None, "{no_code}");
            assert_eq!(rodcube_error_group(no_code), -1, "{no_code}");
        }
        for (code, group) in [
            (RODCUBE_OK, RODCUBE_OK),
            (RODCUBE_ERR_ARGUMENT, RODCUBE_ERR_ARGUMENT),
            (RODCUBE_ERR_PANIC, RODCUBE_ERR_PANIC),
            (RODCUBE_ERR_PARAMETERS, RODCUBE_ERR_PARAMETERS),
            (RODCUBE_ERR_PARAM_REQUIREMENT, RODCUBE_ERR_PARAMETERS),
            (RODCUBE_ERR_TOO_MANY_SAMPLES, RODCUBE_ERR_REQUEST),
            (RODCUBE_ERR_NO_SEPARATION, RODCUBE_ERR_SOLVE),
            (RODCUBE_ERR_RESULT_NOT_FINITE, RODCUBE_ERR_SOLVE),
            (RODCUBE_ERR_NO_SENSITIVITY, RODCUBE_ERR_SOLVE),
            (RODCUBE_ERR_SCENE_SYNTAX, RODCUBE_ERR_SCENE),
            (RODCUBE_ERR_TAPE, RODCUBE_ERR_TAPE),
            (RODCUBE_ERR_TAPE_DIGEST, RODCUBE_ERR_TAPE),
        ] {
            assert_eq!(rodcube_error_group(code), group, "{code}");
        }
    }

    #[test]
    fn null_pointers_and_bad_text_get_their_codes() {
        let s = solver("rod_cube").unwrap();
        let mut err = [0 as c_char; 256];
        let mut out = RodcubePoint::default();
        let mut handle: *mut RodcubeSolver = null_mut();
        let mut results: *mut RodcubeResults = null_mut();
        // SAFETY: every pointer is valid or deliberately NULL.
        unsafe {
            let e = err.as_mut_ptr();
            let name = c"rod_cube".as_ptr();
            // Each call's code and message, read before the next call.
            let check = |what: &str, code: c_int, err: &[c_char]| {
                assert_eq!(code, RODCUBE_ERR_ARGUMENT, "{what}: {}", message(err));
                assert!(message(err).contains("NULL"), "{what}: {}", message(err));
            };
            let code = rodcube_solver_new(null(), &mut handle, e, 256);
            check("NULL model name", code, &err);
            let code = rodcube_solver_new(name, null_mut(), e, 256);
            check("NULL out pointer", code, &err);
            let code = rodcube_solve(s, null(), 5, &mut out, e, 256);
            check("NULL params", code, &err);
            let code = rodcube_solve(null_mut(), PAPER.as_ptr(), 5, &mut out, e, 256);
            check("NULL solver", code, &err);
            let code = rodcube_solve(s, PAPER.as_ptr(), 5, null_mut(), e, 256);
            check("NULL output", code, &err);
            let code = rodcube_run_scene(null(), &mut results, e, 256);
            check("NULL scene", code, &err);
            let code = rodcube_run_scene(name, null_mut(), e, 256);
            check("NULL results' out pointer", code, &err);
            let code = rodcube_results_copy(null(), null_mut(), 0, null_mut(), e, 256);
            check("NULL results", code, &err);
            let names = [c"m1".as_ptr(), null()];
            let code = rodcube_solve_named(s, names.as_ptr(), PAPER.as_ptr(), 2, &mut out, e, 256);
            assert_eq!(
                (code, message(&err)),
                (RODCUBE_ERR_ARGUMENT, "name 1 is NULL".into())
            );
            // NULL with a count of zero is an empty array, not a NULL argument.
            let code = rodcube_solve(s, null(), 0, &mut out, e, 256);
            assert_eq!(code, RODCUBE_ERR_PARAM_COUNT, "{}", message(&err));
            // Text that is not UTF-8.
            let code = rodcube_solver_new(c"rod\xffcube".as_ptr(), &mut handle, e, 256);
            assert_eq!(code, RODCUBE_ERR_UTF8, "{}", message(&err));
            assert!(handle.is_null());
            let code = rodcube_run_scene(c"model: \xff".as_ptr(), &mut results, e, 256);
            assert_eq!(code, RODCUBE_ERR_UTF8, "{}", message(&err));
            assert!(results.is_null());
            // The readers of NULL results answer NULL and 0; the releases ignore NULL.
            assert!(rodcube_results_json(null()).is_null());
            assert_eq!(rodcube_results_len(null()), 0);
            rodcube_results_free(null_mut());
            rodcube_solver_free(null_mut());
            rodcube_solver_free(s);
        }
    }

    #[test]
    fn messages_are_cut_to_the_buffer_and_cleared_on_success() {
        let s = solver("rod_cube").unwrap();
        let mut err = [1 as c_char; 256];
        let mut out = RodcubePoint::default();
        // SAFETY: valid pointers and sizes.
        unsafe {
            // A NULL error buffer is allowed; success clears the message.
            let code = rodcube_solve(s, PAPER.as_ptr(), 5, &mut out, null_mut(), 0);
            assert_eq!(code, RODCUBE_OK);
            // The paper's case: eq. (14)'s root, 9.61097 deg (PHYSICS.md; to 1e-12 in
            // tests/hard_cases.rs against the 256-bit reference).
            assert!((out.separation_angle.to_degrees() - 9.611).abs() < 1e-3);
            let code = rodcube_solve(s, PAPER.as_ptr(), 5, &mut out, err.as_mut_ptr(), 256);
            assert_eq!((code, message(&err)), (RODCUBE_OK, String::new()));
            // A message longer than the buffer is cut, still NUL-terminated.
            let mut small = [1 as c_char; 8];
            let code = rodcube_solve(s, PAPER.as_ptr(), 2, &mut out, small.as_mut_ptr(), 8);
            assert_eq!(code, RODCUBE_ERR_PARAM_COUNT);
            assert_eq!(message(&small).len(), 7);
            rodcube_solver_free(s);
        }
    }

    /// Every code a concrete input reaches, with the words its message must hold: each kind
    /// gets its own code. (Not reached from C: `RODCUBE_ERR_PANIC`, which no input causes;
    /// `RODCUBE_ERR_JSON`; the request group, which a scene's own validation catches first;
    /// the solver failures that only faulty models give, `tests/lean.rs` and
    /// `tests/numerical_faults.rs` reach them in Rust; and `RODCUBE_ERR_NO_SENSITIVITY`,
    /// which no point the per-point solver takes reaches (its separations all have
    /// sensitivities: the unit test `ffi::tests` maps every `SensitivityGap` to it).)
    #[test]
    fn every_reachable_code_comes_from_a_concrete_input() {
        let s = solver("rod_cube").unwrap();
        let names = ["m1", "m2", "ell", "a", "g"];
        let p = |i: usize, v: f64| {
            let mut p = PAPER;
            p[i] = v;
            p
        };
        let base = "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\n";
        let scene = |rest: &str| scene_error(&format!("{base}{rest}"));
        let cases: Vec<(&str, Outcome, c_int, &str)> = vec![
            (
                "an unknown model",
                solver("rod_cubee").unwrap_err(),
                RODCUBE_ERR_MODEL,
                "no model `rod_cubee`",
            ),
            (
                "4 values for 5 parameters",
                solve(s, &PAPER[..4]),
                RODCUBE_ERR_PARAM_COUNT,
                "5",
            ),
            (
                "m2 = NaN",
                solve(s, &p(1, f64::NAN)),
                RODCUBE_ERR_PARAM_NOT_FINITE,
                "`m2`",
            ),
            (
                "a = 0",
                solve(s, &p(3, 0.0)),
                RODCUBE_ERR_PARAM_NOT_POSITIVE,
                "`a`",
            ),
            (
                "a > ell",
                solve(s, &p(3, 1.5)),
                RODCUBE_ERR_PARAM_REQUIREMENT,
                "a < ell",
            ),
            (
                "m2 = 1e308",
                solve(s, &p(1, 1e308)),
                RODCUBE_ERR_PARAM_BAD_CONSTANT,
                "non-finite constant",
            ),
            (
                "g missing",
                solve_named(s, &names[..4], &PAPER),
                RODCUBE_ERR_PARAM_MISSING,
                "needs parameter `g`",
            ),
            (
                "`mass`",
                solve_named(s, &["m1", "m2", "ell", "a", "mass"], &PAPER),
                RODCUBE_ERR_PARAM_UNKNOWN,
                "no parameter `mass`",
            ),
            (
                "m1 twice",
                solve_named(s, &["m1", "m1", "ell", "a", "g"], &PAPER),
                RODCUBE_ERR_PARAM_DUPLICATE,
                "twice",
            ),
            (
                "a phase without a closed first contact",
                solver("rod_cube_free").unwrap_err(),
                RODCUBE_ERR_NOT_PER_POINT,
                "not for the per-point solver",
            ),
            (
                "a ladder held by friction",
                scene_error(
                    "model: ladder_friction\nparameters: {m1: 1, ell: 1, a: 0.8, g: 9.81, mu_f: 0.5, mu_w: 0.5}\nwant: [separation_time]\n",
                ),
                RODCUBE_ERR_AT_REST,
                "stays at rest",
            ),
            (
                "a stiff spring",
                scene_error(
                    "model: hinged_rod_spring\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, k: 5000}\nwant: [separation_time]\n",
                ),
                RODCUBE_ERR_SWINGS,
                "swings",
            ),
            (
                "unbalanced braces",
                scene_error("model: rod_cube\nparameters: {m1: 1.0\n"),
                RODCUBE_ERR_SCENE_SYNTAX,
                "<scene>:",
            ),
            (
                "a misspelt key",
                scene("want: [separation_angle]\ntolerence: 1e-9\n"),
                RODCUBE_ERR_SCENE_UNKNOWN_KEY,
                "<scene>:4:1",
            ),
            (
                "no want",
                scene(""),
                RODCUBE_ERR_SCENE_STRUCTURE,
                "`want` is missing",
            ),
            (
                "a misspelt model",
                scene_error("model: rod_cubee\nparameters: {}\nwant: [separation_angle]\n"),
                RODCUBE_ERR_SCENE_UNKNOWN_MODEL,
                "<scene>:1:8",
            ),
            (
                "a misspelt quantity",
                scene("want: [sepration_time]\n"),
                RODCUBE_ERR_SCENE_UNKNOWN_QUANTITY,
                "sepration_time",
            ),
            (
                "no fast phase at release",
                scene_error(
                    "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0.1}\nwant: [linearised_separation_angle]\n",
                ),
                RODCUBE_ERR_SCENE_UNAVAILABLE_QUANTITY,
                "no fast phase at release",
            ),
            (
                "a quantity twice",
                scene("want: [checks, checks]\n"),
                RODCUBE_ERR_SCENE_DUPLICATE_QUANTITY,
                "<scene>:3:",
            ),
            (
                "no g",
                scene_error(
                    "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25}\nwant: [checks]\n",
                ),
                RODCUBE_ERR_SCENE_MISSING_PARAMETER,
                "`g`",
            ),
            (
                "a parameter mu",
                scene_error(
                    "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0.3}\nwant: [checks]\n",
                ),
                RODCUBE_ERR_SCENE_UNKNOWN_PARAMETER,
                "`mu`",
            ),
            (
                "m1 = -1 first, among others",
                scene_error(
                    "model: rod_cube\nparameters:\n  m1: -1\n  m2: 3\n  ell: 1\n  a: 0.25\n  g: .inf\n  h: 2\nwant: [separation_angle, nothing]\nsamples: 1\n",
                ),
                RODCUBE_ERR_SCENE_NOT_POSITIVE,
                "5 errors in this scene",
            ),
            (
                "mu = -0.2",
                scene_error(
                    "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: -0.2}\nwant: [checks]\n",
                ),
                RODCUBE_ERR_SCENE_NEGATIVE_FRICTION,
                "-0.2",
            ),
            (
                "tolerance .nan",
                scene("want: [checks]\ntolerance: .nan\n"),
                RODCUBE_ERR_SCENE_NOT_FINITE,
                "tolerance",
            ),
            (
                "one sample",
                scene("want: [checks]\nsamples: 1\n"),
                RODCUBE_ERR_SCENE_OUT_OF_RANGE,
                "samples",
            ),
            (
                "a > ell in a scene",
                scene_error(
                    "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 1.5, g: 9.81}\nwant: [checks]\n",
                ),
                RODCUBE_ERR_SCENE_REQUIREMENT,
                "(a < ell)",
            ),
        ];
        let mut codes = BTreeSet::new();
        for (what, (code, text), expected, needle) in &cases {
            assert_eq!(
                (code, name_of(*code)),
                (expected, name_of(*expected)),
                "{what}: {text}"
            );
            assert!(text.contains(needle), "{what}: no {needle:?} in {text}");
            assert!(codes.insert(*code), "{what}: code {code} twice");
        }
        // A solver failure through the per-point solver: masses of 1e-300 kg underflow the
        // push at release (0/0). tests/lean.rs accepts either of the two failures this can
        // give; either is a code of its own in the solver group.
        let (code, text) = solve(s, &[1e-300, 1e-300, 1.0, 1e-300, 9.81]);
        assert!(
            [RODCUBE_ERR_NON_FINITE, RODCUBE_ERR_NO_SEPARATION].contains(&code),
            "{code}: {text}"
        );
        assert_eq!(rodcube_error_group(code), RODCUBE_ERR_SOLVE);
        // The solver is still usable after every failure.
        assert_eq!(solve(s, &PAPER), (RODCUBE_OK, String::new()));
        // SAFETY: made by rodcube_solver_new, released once.
        unsafe { rodcube_solver_free(s) };
    }

    /// `rodcube_sensitivities(solver, params, n, out, d_angle, d_time, n_out)`.
    fn sensitivities(
        s: *mut RodcubeSolver,
        params: &[f64],
        out: Option<&mut RodcubePoint>,
        d_angle: &mut [f64],
        d_time: &mut [f64],
    ) -> Outcome {
        let mut err = [0 as c_char; 512];
        let out = out.map_or(null_mut(), |o| o as *mut RodcubePoint);
        // SAFETY: a live solver, valid slices (`n_out` is the shorter) and buffers.
        let code = unsafe {
            rodcube_sensitivities(
                s,
                params.as_ptr(),
                params.len(),
                out,
                d_angle.as_mut_ptr(),
                d_time.as_mut_ptr(),
                d_angle.len().min(d_time.len()),
                err.as_mut_ptr(),
                512,
            )
        };
        (code, message(&err))
    }

    /// The C call gives the per-point solver's sensitivities to the bit (the numbers of a
    /// scene's `want: [sensitivities]` and of `rodcube sweep --sensitivities`), with the point
    /// as `rodcube_solve` gives it; wrong lengths, NULL arrays and refused points get their
    /// codes and leave the arrays as they were.
    #[test]
    fn sensitivities_are_the_per_point_solvers() {
        use rodcube::solve::fast::lean::LeanSolver;
        use rodcube::solve::fast::sensitivity::SensitivityWork;
        let model = rodcube::models::find("rod_cube").unwrap();
        let mut rust = LeanSolver::new(model).unwrap();
        let s = solver("rod_cube").unwrap();
        for p in [
            PAPER,
            [1.0, 0.05, 1.0, 0.8, 9.81],
            [2.0, 40.0, 1.5, 0.1, 1.0],
        ] {
            let point = rust.solve(&p).unwrap();
            let (mut want_a, mut want_t) = ([0.0; 5], [0.0; 5]);
            rust.sensitivities(
                &p,
                &point,
                &mut SensitivityWork::default(),
                &mut want_a,
                &mut want_t,
            )
            .unwrap()
            .unwrap();
            let (mut a, mut t) = ([f64::NAN; 5], [f64::NAN; 5]);
            let mut out = RodcubePoint::default();
            assert_eq!(
                sensitivities(s, &p, Some(&mut out), &mut a, &mut t),
                (RODCUBE_OK, String::new())
            );
            assert_eq!(a.map(f64::to_bits), want_a.map(f64::to_bits), "{p:?}");
            assert_eq!(t.map(f64::to_bits), want_t.map(f64::to_bits), "{p:?}");
            assert_eq!(
                out.separation_angle.to_bits(),
                point.separation_angle.to_bits()
            );
            assert_eq!(
                out.separation_time.to_bits(),
                point.separation_time.to_bits()
            );
            // `out` may be NULL.
            let (mut a2, mut t2) = ([0.0; 5], [0.0; 5]);
            assert_eq!(sensitivities(s, &p, None, &mut a2, &mut t2).0, RODCUBE_OK);
            assert_eq!((a2, t2), (a, t));
        }
        let (mut a, mut t) = ([7.0; 5], [7.0; 5]);
        let (code, text) = sensitivities(s, &PAPER, None, &mut a[..4], &mut t[..4]);
        assert_eq!(code, RODCUBE_ERR_PARAM_LENGTH, "{text}");
        let refused = [1.0, 3.0, 1.0, 1.0, 9.81];
        let (code, text) = sensitivities(s, &refused, None, &mut a, &mut t);
        assert_eq!(code, RODCUBE_ERR_PARAM_REQUIREMENT, "{text}");
        assert_eq!((a, t), ([7.0; 5], [7.0; 5]), "a failure writes no number");
        let mut err = [0 as c_char; 512];
        // SAFETY: NULL arrays with a count: refused before anything is read or written.
        let code = unsafe {
            rodcube_sensitivities(
                s,
                PAPER.as_ptr(),
                5,
                null_mut(),
                null_mut(),
                t.as_mut_ptr(),
                5,
                err.as_mut_ptr(),
                512,
            )
        };
        assert_eq!(code, RODCUBE_ERR_ARGUMENT);
        assert!(message(&err).contains("d_angle is NULL"));
        // SAFETY: NULL solver.
        let code = unsafe {
            rodcube_sensitivities(
                null_mut(),
                PAPER.as_ptr(),
                5,
                null_mut(),
                a.as_mut_ptr(),
                t.as_mut_ptr(),
                5,
                null_mut(),
                0,
            )
        };
        assert_eq!(code, RODCUBE_ERR_ARGUMENT);
        // SAFETY: made by rodcube_solver_new, released once.
        unsafe { rodcube_solver_free(s) };
    }

    /// The scene is solved once, by `rodcube_run_scene`: its handle holds the text of one run
    /// (the same bytes, work counters included, as one `plan::run` of the scene from Rust),
    /// and every read after it — the length, copies into a buffer too small and one large
    /// enough, the text in place — gives that text from the same storage, without solving.
    #[test]
    fn a_scene_is_solved_once_and_read_from_its_handle() {
        let results = run_scene(PAPER_SCENE).unwrap();
        // One run from Rust, for the bytes.
        let scene =
            rodcube::scene::Scene::parse(PAPER_SCENE, Path::new("<scene>"), rodcube::models::all())
                .unwrap();
        let request = rodcube::plan::Request::new(scene.model, scene.parameters.clone())
            .with_want(&scene.want)
            .with_tolerance(scene.tolerance)
            .with_samples(scene.samples);
        let run = rodcube::plan::run(&request).unwrap();
        assert!(run.work.integrand_evals > 0, "{:?}", run.work);
        let once = rodcube::report::json::to_string(&run).unwrap();
        let mut err = [0 as c_char; 256];
        // SAFETY: a live handle, valid buffers of the sizes given.
        unsafe {
            let text = rodcube_results_json(results);
            assert_eq!(CStr::from_ptr(text).to_str(), Ok(once.as_str()));
            assert_eq!(rodcube_results_len(results), once.len());
            let mut needed = 0usize;
            let code =
                rodcube_results_copy(results, null_mut(), 0, &mut needed, err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_BUFFER, "{}", message(&err));
            assert_eq!(needed, once.len() + 1);
            let mut small = vec![7 as c_char; needed - 1];
            let code = rodcube_results_copy(
                results,
                small.as_mut_ptr(),
                small.len(),
                &mut needed,
                err.as_mut_ptr(),
                256,
            );
            assert_eq!(code, RODCUBE_ERR_BUFFER);
            assert!(small.iter().all(|&c| c == 7), "a refused copy wrote");
            for _ in 0..2 {
                let mut json = vec![0 as c_char; needed];
                let code = rodcube_results_copy(
                    results,
                    json.as_mut_ptr(),
                    json.len(),
                    null_mut(),
                    err.as_mut_ptr(),
                    256,
                );
                assert_eq!((code, message(&err)), (RODCUBE_OK, String::new()));
                assert_eq!(message(&json), once);
            }
            // The same storage throughout: nothing was made again.
            assert_eq!(rodcube_results_json(results), text);
            let value: serde_json::Value = serde_json::from_str(&once).unwrap();
            let t = value["results"]["separation_time"]["value"]
                .as_f64()
                .unwrap();
            // The paper's 0.108 s (t_sep = 0.10849 s, PHYSICS.md).
            assert!((t - 0.1085).abs() < 5e-4);
            rodcube_results_free(results);
        }
    }

    /// `rodcube_models_load(dir, &n_models, err, err_len)`: its code, message and count.
    fn load(dir: &Path) -> (c_int, String, usize) {
        let dir = CString::new(dir.to_str().expect("UTF-8 path")).unwrap();
        let mut err = [0 as c_char; 2048];
        let mut n = usize::MAX;
        // SAFETY: valid string, out pointer and buffer.
        let code = unsafe { rodcube_models_load(dir.as_ptr(), &mut n, err.as_mut_ptr(), 2048) };
        (code, message(&err), n)
    }

    /// The names the registry lists, through the C calls.
    fn listed() -> Vec<String> {
        (0..rodcube_model_count())
            // SAFETY: static NUL-terminated strings below the count.
            .map(|i| unsafe { CStr::from_ptr(rodcube_model_name(i)) })
            .map(|s| s.to_string_lossy().into_owned())
            .collect()
    }

    /// A refused tape fails the whole load with the code of its kind and a message naming the
    /// file, writes 0 models and installs nothing; each kind of refusal is reached from a copy
    /// of the paper's tape cut short or edited (edits inside the body with its digest brought
    /// up to date, so that the check under test is the one reached).
    #[test]
    fn a_corrupted_tape_is_refused_with_its_code_and_file() {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-tape-refusals");
        let _ = std::fs::remove_dir_all(&root);
        let paper = rodcube::models::embedded_tape("rod_cube").expect("embedded");
        let rebodied = |edit: &dyn Fn(&mut serde_json::Value)| {
            let mut v: serde_json::Value = serde_json::from_str(paper).unwrap();
            edit(&mut v["body"]);
            let body: rodcube::tape::format::Body =
                serde_json::from_value(v["body"].clone()).unwrap();
            v["body_digest"] = body.digest().into();
            serde_json::to_string(&v).unwrap()
        };
        let cases: Vec<(&str, String, c_int, &str)> = vec![
            (
                "cut short",
                paper[..paper.len() / 2].to_string(),
                RODCUBE_ERR_TAPE_SYNTAX,
                "not a rodcube tape",
            ),
            (
                "another format",
                paper.replacen("rodcube-tape", "something-else", 1),
                RODCUBE_ERR_TAPE_FORMAT,
                "something-else",
            ),
            (
                "another version",
                paper.replacen(
                    &format!("\"version\": {},", rodcube::tape::VERSION),
                    &format!("\"version\": {},", rodcube::tape::VERSION - 1),
                    1,
                ),
                RODCUBE_ERR_TAPE_VERSION,
                "cargo derive",
            ),
            (
                "a number edited",
                paper.replacen("[\"const\",", "[\"const\",1", 1),
                RODCUBE_ERR_TAPE_DIGEST,
                "truncated or edited by hand",
            ),
            (
                "another name in its info",
                rebodied(&|body| body["info"]["name"] = "rod_cubes".into()),
                RODCUBE_ERR_TAPE_INFO,
                "rod_cubes",
            ),
            (
                "a method twice",
                rebodied(&|body| {
                    let functions = body["functions"].as_array_mut().unwrap();
                    functions.push(functions[0].clone());
                }),
                RODCUBE_ERR_TAPE_METHOD,
                "given twice",
            ),
        ];
        let before = {
            let _registry = registry();
            listed()
        };
        for (i, (what, text, expected, needle)) in cases.iter().enumerate() {
            let dir = root.join(format!("case{i}"));
            std::fs::create_dir_all(&dir).unwrap();
            let file = dir.join("rod_cube.tape.json");
            std::fs::write(&file, text).unwrap();
            let (code, text, n) = load(&dir);
            assert_eq!(
                (code, name_of(code)),
                (*expected, name_of(*expected)),
                "{what}: {text}"
            );
            assert_eq!(rodcube_error_group(code), RODCUBE_ERR_TAPE, "{what}");
            assert!(
                text.starts_with(&file.display().to_string()),
                "{what}: {text}"
            );
            assert!(text.contains(needle), "{what}: no {needle:?} in {text}");
            assert_eq!(n, 0, "{what}");
        }
        // A directory that is not there, named; NULL and text that is not UTF-8.
        let (code, text, n) = load(&root.join("nowhere"));
        assert_eq!(code, RODCUBE_ERR_TAPE_READ, "{text}");
        assert!(text.contains("nowhere"), "{text}");
        assert_eq!(n, 0);
        let mut err = [0 as c_char; 256];
        // SAFETY: NULL and non-UTF-8 directories, a NULL count, a valid buffer.
        unsafe {
            let code = rodcube_models_load(null(), null_mut(), err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_ARGUMENT, "{}", message(&err));
            assert!(message(&err).contains("the directory is NULL"));
            let code = rodcube_models_load(c"dir\xff".as_ptr(), null_mut(), err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_UTF8, "{}", message(&err));
        }
        // Nothing was installed: the registry is as it was.
        let _registry = registry();
        assert_eq!(listed(), before);
    }

    /// A model of the test's own (a plank on a crate, the paper's system under other names),
    /// with its fast phases, derived by `rodcube derive --tapes-into`: nothing of it is compiled
    /// into the library.
    #[cfg(feature = "derive")]
    const CRATE_SPEC: &str = include_str!("specs/plank.yaml");

    /// The paper's closed forms for a rod on a free block (`PHYSICS.md`), independent of
    /// rodcube: `s = sin(theta_sep)` is the root in `(0, r)` of eq. (14),
    /// `3 s^3 - 12 (1+n) s + 8 r (1+n) = 0` (bisection), and the time is
    /// `int dtheta / sqrt(theta_dot^2)` with eq. (9)'s
    /// `theta_dot^2 = 4 (g/ell) (r - sin theta) / (4/3 - sin^2 theta / (1+n))`, after
    /// `theta = theta_0 - u^2` removes the endpoint's `1/sqrt` and
    /// `r - sin(theta) = 2 cos(theta_0 - u^2/2) sin(u^2/2)` its cancellation (Gauss–Legendre
    /// panels).
    #[cfg(feature = "derive")]
    fn closed_forms(n: f64, r: f64, ell: f64, g: f64) -> (f64, f64) {
        let f = |s: f64| 3.0 * s.powi(3) - 12.0 * (1.0 + n) * s + 8.0 * r * (1.0 + n);
        let (mut lo, mut hi) = (0.0, r);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let theta_sep = (0.5 * (lo + hi)).asin();
        let theta0 = r.asin();
        let integrand = |u: f64| {
            let s = (theta0 - u * u).sin();
            // r - s without cancellation: sin(theta_0) - sin(theta_0 - u^2).
            let drop = 2.0 * (theta0 - 0.5 * u * u).cos() * (0.5 * u * u).sin();
            let rate_sq = 4.0 * (g / ell) * drop / (4.0 / 3.0 - s * s / (1.0 + n));
            2.0 * u / rate_sq.sqrt()
        };
        let rule = gauss_quad::GaussLegendre::new(std::num::NonZeroUsize::new(30).unwrap());
        let (panels, end) = (8, (theta0 - theta_sep).sqrt());
        let width = end / f64::from(panels);
        let mut t_sep = 0.0;
        for p in 0..panels {
            let mid = width * (f64::from(p) + 0.5);
            for &(x, w) in rule.as_node_weight_pairs() {
                t_sep += 0.5 * width * w * integrand(mid + 0.5 * width * x);
            }
        }
        (theta_sep, t_sep)
    }

    /// The whole route from C: a spec derived into a directory of tapes, loaded by
    /// `rodcube_models_load` (refused whole while a corrupted tape is among them), listed,
    /// solved by its per-point solver and run as a scene, by `examples/c/tapes.c` too, each to
    /// the paper's closed forms.
    #[test]
    #[cfg(feature = "derive")]
    fn a_model_derived_into_tapes_is_loaded_solved_and_run_from_c() {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-tapes");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("plank.yaml"), CRATE_SPEC).unwrap();
        let derived = Command::new(env!("CARGO_BIN_EXE_rodcube"))
            .args(["derive", "--tapes-into", "tapes", "plank.yaml"])
            .current_dir(&dir)
            .output()
            .expect("rodcube runs");
        assert!(
            derived.status.success(),
            "{}",
            String::from_utf8_lossy(&derived.stderr)
        );
        let tapes = dir.join("tapes");
        let models = ["plank", "plank_closed", "plank_free"];
        for m in models {
            assert!(tapes.join(format!("{m}.tape.json")).is_file(), "{m}");
            assert!(
                rodcube::models::compiled()
                    .iter()
                    .all(|c| c.info().name != m)
            );
        }
        let _registry = registry();
        // Not there before: the name is unknown.
        assert_eq!(solver("plank").unwrap_err().0, RODCUBE_ERR_MODEL);
        let before = listed();

        // With one of them corrupted, nothing of the directory is loaded.
        let broken = dir.join("broken");
        std::fs::create_dir_all(&broken).unwrap();
        for m in models {
            let file = format!("{m}.tape.json");
            std::fs::copy(tapes.join(&file), broken.join(&file)).unwrap();
        }
        let free = broken.join("plank_free.tape.json");
        let text = std::fs::read_to_string(&free).unwrap();
        std::fs::write(&free, text.replacen("[\"ld\",", "[\"ld\",1", 1)).unwrap();
        let (code, text, n) = load(&broken);
        assert_eq!(code, RODCUBE_ERR_TAPE_DIGEST, "{text}");
        assert!(
            text.starts_with(&free.display().to_string()),
            "the message names the file: {text}"
        );
        assert_eq!((n, listed()), (0, before.clone()));
        assert_eq!(solver("plank").unwrap_err().0, RODCUBE_ERR_MODEL);

        // Loaded: listed after the compiled models, with their parameters.
        assert_eq!(load(&tapes), (RODCUBE_OK, String::new(), 3));
        let now = listed();
        assert_eq!(now[..before.len()], before[..]);
        assert_eq!(now[before.len()..], models.map(String::from));
        let i = before.len();
        let parameters: Vec<String> = (0..rodcube_parameter_count(i))
            // SAFETY: static NUL-terminated strings below the count.
            .map(|j| unsafe { CStr::from_ptr(rodcube_parameter_name(i, j)) })
            .map(|s| s.to_string_lossy().into_owned())
            .collect();
        assert_eq!(parameters, ["mp", "mc", "L", "h", "g"]);
        // Loading again changes nothing.
        assert_eq!(load(&tapes), (RODCUBE_OK, String::new(), 3));
        assert_eq!(listed(), now);

        // Solved by its per-point solver, by name, against the closed forms; two points.
        let s = solver("plank").unwrap();
        let names = ["g", "h", "L", "mc", "mp"];
        for (mp, mc, ell, h) in [(1.0, 3.0, 1.0, 0.25), (2.0, 0.5, 1.5, 0.9)] {
            let (theta_sep, t_sep) = closed_forms(mc / mp, h / ell, ell, 9.81);
            let names: Vec<CString> = names.iter().map(|n| CString::new(*n).unwrap()).collect();
            let p: Vec<*const c_char> = names.iter().map(|c| c.as_ptr()).collect();
            let values = [9.81, h, ell, mc, mp];
            let mut out = RodcubePoint::default();
            let mut err = [0 as c_char; 512];
            // SAFETY: a live solver, five names and values, valid buffers.
            let code = unsafe {
                rodcube_solve_named(
                    s,
                    p.as_ptr(),
                    values.as_ptr(),
                    5,
                    &mut out,
                    err.as_mut_ptr(),
                    512,
                )
            };
            assert_eq!((code, message(&err)), (RODCUBE_OK, String::new()));
            assert!(
                (out.separation_angle - theta_sep).abs() < 1e-13,
                "{} vs {theta_sep}",
                out.separation_angle
            );
            assert!(
                (out.separation_time - t_sep).abs() < 1e-12 * t_sep,
                "{} vs {t_sep}",
                out.separation_time
            );
        }
        // SAFETY: made by rodcube_solver_new, released once.
        unsafe { rodcube_solver_free(s) };

        // Run as a scene: the same numbers, and the note says where the model came from.
        let results = run_scene(
            "model: plank\nparameters: {mp: 1, mc: 3, L: 1, h: 0.25, g: 9.81}\nwant: [separation_angle, separation_time]\ntolerance: 1.0e-12\n",
        )
        .unwrap();
        // SAFETY: a live handle, released once.
        let json = unsafe {
            let json = CStr::from_ptr(rodcube_results_json(results))
                .to_string_lossy()
                .into_owned();
            rodcube_results_free(results);
            json
        };
        let value: serde_json::Value = serde_json::from_str(&json).unwrap();
        let result = |k: &str| value["results"][k]["value"].as_f64().unwrap();
        let (theta_sep, t_sep) = closed_forms(3.0, 0.25, 1.0, 9.81);
        assert!((result("separation_angle") - theta_sep).abs() < 1e-12);
        assert!((result("separation_time") - t_sep).abs() < 1e-11 * t_sep);
        let note = value["notes"]["model"].as_str().unwrap_or_default();
        assert!(note.contains("not compiled into this program"), "{note}");
        assert!(note.contains("plank.tape.json"), "{note}");

        // A C program does the same (examples/c/tapes.c, built by run.sh against the header).
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let out = Command::new(root.join("examples/c/run.sh"))
            .arg("tapes")
            .arg(&tapes)
            .args(["plank", "mp=1", "mc=3", "L=1", "h=0.25", "g=9.81"])
            .env(
                "CARGO_TARGET_DIR",
                Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi"),
            )
            .env("CARGO", env!("CARGO"))
            .env_remove("LD_LIBRARY_PATH")
            .output()
            .expect("run.sh runs");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "tapes.c failed:\n{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let value = |key: &str| -> f64 {
            stdout
                .split_whitespace()
                .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("no {key} in {stdout}"))
        };
        assert_eq!(value("loaded"), 3.0);
        assert!(
            (value("separation_angle") - theta_sep).abs() < 1e-13,
            "{stdout}"
        );
        assert!(
            (value("separation_time") - t_sep).abs() < 1e-12 * t_sep,
            "{stdout}"
        );
        assert!(
            stdout.contains("not compiled into this program"),
            "{stdout}"
        );
    }
}
