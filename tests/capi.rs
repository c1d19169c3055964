//! The C ABI: `examples/c/run.sh` builds the library and `examples/c/paper.c` with the system C
//! compiler (which also checks `include/rodcube.h`) and prints the paper's separation angle
//! and time, equal to the bit to the Rust per-point solver's; and every function answers bad
//! arguments with its typed code and a message, never a crash.

use rodcube::solve::lean::LeanSolver;
use std::path::Path;
use std::process::Command;

const PAPER: [f64; 5] = [1.0, 3.0, 1.0, 0.25, 9.81];

#[test]
fn the_c_example_prints_the_rust_solvers_numbers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
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
    use std::ffi::{CStr, CString, c_char};

    fn message(err: &[c_char]) -> String {
        // SAFETY: the functions always NUL-terminate a non-empty buffer.
        unsafe { CStr::from_ptr(err.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    fn solver(name: &str) -> Result<*mut RodcubeSolver, String> {
        let name = CString::new(name).unwrap();
        let mut err = [0 as c_char; 256];
        // SAFETY: valid string and buffer.
        let s = unsafe { rodcube_solver_new(name.as_ptr(), err.as_mut_ptr(), err.len()) };
        if s.is_null() {
            Err(message(&err))
        } else {
            Ok(s)
        }
    }

    #[test]
    fn models_and_parameters_are_listed() {
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

    #[test]
    fn bad_arguments_get_their_codes_and_messages() {
        assert!(
            solver("no_such_model")
                .unwrap_err()
                .contains("no model `no_such_model`")
        );
        assert!(
            solver("rod_cube_free")
                .unwrap_err()
                .contains("rod_cube_free")
        );
        let s = solver("rod_cube").unwrap();
        let mut err = [0 as c_char; 256];
        let mut out = RodcubePoint::default();
        // SAFETY: every pointer is valid or deliberately NULL.
        unsafe {
            let code = rodcube_solve(s, PAPER.as_ptr(), 4, &mut out, err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_PARAMETERS, "{}", message(&err));
            assert!(message(&err).contains('5'), "{}", message(&err));
            let nan = [1.0, f64::NAN, 1.0, 0.25, 9.81];
            let code = rodcube_solve(s, nan.as_ptr(), 5, &mut out, err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_PARAMETERS);
            assert!(message(&err).contains("`m2`"), "{}", message(&err));
            let code = rodcube_solve(s, std::ptr::null(), 5, &mut out, err.as_mut_ptr(), 256);
            assert_eq!(code, RODCUBE_ERR_ARGUMENT);
            let code = rodcube_solve(
                std::ptr::null_mut(),
                PAPER.as_ptr(),
                5,
                &mut out,
                err.as_mut_ptr(),
                256,
            );
            assert_eq!(code, RODCUBE_ERR_ARGUMENT);
            let code = rodcube_solve(
                s,
                PAPER.as_ptr(),
                5,
                std::ptr::null_mut(),
                err.as_mut_ptr(),
                256,
            );
            assert_eq!(code, RODCUBE_ERR_ARGUMENT);
            // A NULL error buffer is allowed; success clears the message.
            let code = rodcube_solve(s, PAPER.as_ptr(), 5, &mut out, std::ptr::null_mut(), 0);
            assert_eq!(code, RODCUBE_OK);
            assert!((out.separation_angle.to_degrees() - 9.611).abs() < 1e-3);
            let code = rodcube_solve(s, PAPER.as_ptr(), 5, &mut out, err.as_mut_ptr(), 256);
            assert_eq!((code, message(&err)), (RODCUBE_OK, String::new()));
            // A message longer than the buffer is cut, still NUL-terminated.
            let mut small = [1 as c_char; 8];
            let code = rodcube_solve(s, PAPER.as_ptr(), 2, &mut out, small.as_mut_ptr(), 8);
            assert_eq!(code, RODCUBE_ERR_PARAMETERS);
            assert_eq!(message(&small).len(), 7);
            rodcube_solver_free(s);
            rodcube_solver_free(std::ptr::null_mut());
        }
    }

    #[test]
    fn parameters_by_name_are_checked() {
        let s = solver("rod_cube").unwrap();
        let names = ["m1", "m2", "ell", "a", "g"].map(|n| CString::new(n).unwrap());
        let bad = ["m1", "m2", "ell", "a", "mass"].map(|n| CString::new(n).unwrap());
        let twice = ["m1", "m1", "ell", "a", "g"].map(|n| CString::new(n).unwrap());
        // `rodcube_solve_named` on the first `n` of `names` with the paper's values: its code
        // and message.
        let named = |names: &[CString; 5], n: usize| {
            let p = names.each_ref().map(|c| c.as_ptr());
            let mut err = [0 as c_char; 256];
            let mut out = RodcubePoint::default();
            // SAFETY: valid pointers and counts.
            let code = unsafe {
                rodcube_solve_named(
                    s,
                    p.as_ptr(),
                    PAPER.as_ptr(),
                    n,
                    &mut out,
                    err.as_mut_ptr(),
                    256,
                )
            };
            (code, message(&err))
        };
        let (code, err) = named(&names, 5);
        assert_eq!(code, RODCUBE_OK, "{err}");
        let (code, err) = named(&names, 4);
        assert_eq!(code, RODCUBE_ERR_PARAMETERS);
        assert!(err.contains("needs parameter `g`"), "{err}");
        let (code, err) = named(&bad, 5);
        assert_eq!(code, RODCUBE_ERR_PARAMETERS);
        assert!(err.contains("no parameter `mass`"), "{err}");
        let (code, err) = named(&twice, 5);
        assert_eq!(code, RODCUBE_ERR_PARAMETERS);
        assert!(err.contains("twice"), "{err}");
        // SAFETY: made by rodcube_solver_new, released once.
        unsafe { rodcube_solver_free(s) };
    }

    #[test]
    fn scenes_run_to_json_or_say_where_they_are_wrong() {
        let scene = CString::new(
            "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\n\
             want: [separation_angle, separation_time]\n",
        )
        .unwrap();
        let mut err = [0 as c_char; 512];
        let mut needed = 0usize;
        // SAFETY: valid pointers; the buffer is as large as said.
        unsafe {
            let code = rodcube_run_scene(
                scene.as_ptr(),
                std::ptr::null_mut(),
                0,
                &mut needed,
                err.as_mut_ptr(),
                512,
            );
            assert_eq!(code, RODCUBE_ERR_BUFFER, "{}", message(&err));
            let mut json = vec![0 as c_char; needed];
            let code = rodcube_run_scene(
                scene.as_ptr(),
                json.as_mut_ptr(),
                needed,
                &mut needed,
                err.as_mut_ptr(),
                512,
            );
            assert_eq!(code, RODCUBE_OK, "{}", message(&err));
            let text = message(&json);
            assert_eq!(text.len() + 1, needed);
            let value: serde_json::Value = serde_json::from_str(&text).unwrap();
            let t = value["results"]["separation_time"]["value"]
                .as_f64()
                .unwrap();
            assert!((t - 0.1085).abs() < 5e-4);
            let wrong =
                CString::new("model: rod_cube\nparameters: {m1: 1}\nwant: [nothing]\n").unwrap();
            let code = rodcube_run_scene(
                wrong.as_ptr(),
                json.as_mut_ptr(),
                needed,
                &mut needed,
                err.as_mut_ptr(),
                512,
            );
            assert_eq!(code, RODCUBE_ERR_SCENE);
            assert!(message(&err).contains("<scene>:2:1"), "{}", message(&err));
        }
    }
}
