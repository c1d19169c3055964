//! The C ABI (cargo feature `capi`): the per-point solver of any registered model, by handle,
//! with parameters in the model's order or by name, and a whole scene run to a JSON string.
//! `include/rodcube.h` is generated from this file by cbindgen (`cbindgen.toml`;
//! `cargo run --example c_header` writes it, `tests/capi_header.rs` fails when it is stale), so
//! the doc comments of the public items here are the header's documentation: they are written
//! for a C reader and name C functions and types plainly. `examples/c/` builds a C program
//! against them.
//!
//! Conventions, for every function:
//! - a status code is returned (`RODCUBE_OK` = 0, else one of the `RODCUBE_ERR_*` codes);
//! - the message of a failure is copied into the caller's buffer `err` of `err_len` bytes
//!   (NUL-terminated, cut at a character boundary; `err` may be NULL);
//! - nothing the caller must free with its own allocator is returned: a solver handle is
//!   released by [`rodcube_solver_free`], strings are either static or copied into the
//!   caller's buffers;
//! - no panic crosses the boundary: one would be caught and reported as `RODCUBE_ERR_PANIC`.

use crate::model::Model;
use crate::plan::{self, Request};
use crate::scene::Scene;
use crate::solve::SolveError;
use crate::solve::lean::{LeanPoint, LeanSolver};
use crate::system::ordered_values;
use std::ffi::{CStr, CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::OnceLock;

/// Success.
pub const RODCUBE_OK: c_int = 0;
/// A null pointer, text that is not UTF-8, or an inconsistent length.
pub const RODCUBE_ERR_ARGUMENT: c_int = 1;
/// No model of that name, or one the per-point solver cannot solve.
pub const RODCUBE_ERR_MODEL: c_int = 2;
/// The parameters were refused (count, value, or a requirement of the model).
pub const RODCUBE_ERR_PARAMETERS: c_int = 3;
/// A solver failed (no separation before the floor, say).
pub const RODCUBE_ERR_SOLVE: c_int = 4;
/// The scene was refused.
pub const RODCUBE_ERR_SCENE: c_int = 5;
/// The output buffer is too small; `*needed` says how large it must be.
pub const RODCUBE_ERR_BUFFER: c_int = 6;
/// An internal error (a panic, caught at the boundary).
pub const RODCUBE_ERR_PANIC: c_int = 7;

/// One point's separation, as the per-point solver returns it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RodcubePoint {
    /// `theta_sep` (rad).
    pub separation_angle: f64,
    /// Time from release to separation (s).
    pub separation_time: f64,
    /// `theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// A per-point solver of one model (opaque), owned by the caller through a pointer: made by
/// `rodcube_solver_new`, released by `rodcube_solver_free`.
pub struct RodcubeSolver {
    solver: LeanSolver<'static>,
    /// Scratch for parameters given by name.
    values: Vec<f64>,
}

/// A failure: its code and message.
struct Failure(c_int, String);

fn failure(code: c_int, message: impl Into<String>) -> Failure {
    Failure(code, message.into())
}

/// The code of a solver error.
fn solve_failure(e: SolveError) -> Failure {
    let code = match e {
        SolveError::Parameters(_) => RODCUBE_ERR_PARAMETERS,
        SolveError::NoContact { .. } | SolveError::NotPerPoint { .. } => RODCUBE_ERR_MODEL,
        _ => RODCUBE_ERR_SOLVE,
    };
    failure(code, e.to_string())
}

/// Copies `message` into `err` (NUL-terminated, cut at a character boundary).
///
/// # Safety
/// `err` is NULL or points to `err_len` writable bytes.
unsafe fn write_message(err: *mut c_char, err_len: usize, message: &str) {
    if err.is_null() || err_len == 0 {
        return;
    }
    let mut n = message.len().min(err_len - 1);
    while !message.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: the caller gives `err_len` writable bytes; `n < err_len`.
    unsafe {
        std::ptr::copy_nonoverlapping(message.as_ptr(), err.cast::<u8>(), n);
        *err.add(n) = 0;
    }
}

/// Runs `body`, turning a failure or a panic into its code and message.
///
/// # Safety
/// As [`write_message`].
unsafe fn guarded(
    err: *mut c_char,
    err_len: usize,
    body: impl FnOnce() -> Result<(), Failure>,
) -> c_int {
    let outcome = catch_unwind(AssertUnwindSafe(body)).unwrap_or_else(|_| {
        Err(failure(
            RODCUBE_ERR_PANIC,
            "internal error: rodcube panicked (please report it)",
        ))
    });
    match outcome {
        Ok(()) => {
            // SAFETY: forwarded from the caller.
            unsafe { write_message(err, err_len, "") };
            RODCUBE_OK
        }
        Err(Failure(code, message)) => {
            // SAFETY: forwarded from the caller.
            unsafe { write_message(err, err_len, &message) };
            code
        }
    }
}

/// A C string argument as `&str`.
///
/// # Safety
/// `s` is NULL or a NUL-terminated string that lives for `'a`.
unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if s.is_null() {
        return Err(failure(RODCUBE_ERR_ARGUMENT, format!("{what} is NULL")));
    }
    // SAFETY: the caller gives a NUL-terminated string.
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|e| failure(RODCUBE_ERR_ARGUMENT, format!("{what} is not UTF-8: {e}")))
}

/// `n` values at `p` as a slice (empty for `n == 0`, whatever `p`).
///
/// # Safety
/// For `n > 0`, `p` points to `n` readable values of `T`.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], Failure> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(failure(
            RODCUBE_ERR_ARGUMENT,
            format!("{what} is NULL with a count of {n}"),
        ));
    }
    // SAFETY: the caller gives `n` readable values.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// The solver behind a handle.
///
/// # Safety
/// `solver` is NULL or a live pointer from `rodcube_solver_new`.
unsafe fn solver_mut<'a>(solver: *mut RodcubeSolver) -> Result<&'a mut RodcubeSolver, Failure> {
    // SAFETY: as the caller promises.
    unsafe { solver.as_mut() }.ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, "the solver is NULL"))
}

/// The caller's output.
///
/// # Safety
/// `out` is NULL or points to one writable `rodcube_point`.
unsafe fn output<'a>(out: *mut RodcubePoint) -> Result<&'a mut RodcubePoint, Failure> {
    // SAFETY: as the caller promises.
    unsafe { out.as_mut() }.ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, "the output is NULL"))
}

impl From<LeanPoint> for RodcubePoint {
    fn from(point: LeanPoint) -> Self {
        RodcubePoint {
            separation_angle: point.separation_angle,
            separation_time: point.separation_time,
            delta: point.delta(),
        }
    }
}

fn find_model(name: &str) -> Result<&'static dyn Model, Failure> {
    crate::models::find(name).ok_or_else(|| {
        let names: Vec<&str> = crate::models::all().iter().map(|m| m.info().name).collect();
        failure(
            RODCUBE_ERR_MODEL,
            format!("no model `{name}`; there are: {}", names.join(", ")),
        )
    })
}

/// The registered models' names and their parameters' names as C strings, made once.
fn names() -> &'static [(CString, Vec<CString>)] {
    static NAMES: OnceLock<Vec<(CString, Vec<CString>)>> = OnceLock::new();
    NAMES.get_or_init(|| {
        let c = |s: &str| CString::new(s).unwrap_or_default();
        crate::models::all()
            .iter()
            .map(|m| {
                let info = m.info();
                (
                    c(info.name),
                    info.parameters.iter().map(|p| c(p.name)).collect(),
                )
            })
            .collect()
    })
}

/// How many models are registered.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_model_count() -> usize {
    catch_unwind(|| names().len()).unwrap_or(0)
}

/// The name of model `model` (an index below `rodcube_model_count()`; static storage), or
/// NULL past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_model_name(model: usize) -> *const c_char {
    catch_unwind(|| {
        names()
            .get(model)
            .map_or(std::ptr::null(), |(n, _)| n.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// How many parameters model `model` (an index) takes; 0 past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_parameter_count(model: usize) -> usize {
    catch_unwind(|| names().get(model).map_or(0, |(_, p)| p.len())).unwrap_or(0)
}

/// The name of parameter `parameter` of model `model` (indices; static storage, in the order
/// `rodcube_solve` takes the values), or NULL past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_parameter_name(model: usize, parameter: usize) -> *const c_char {
    catch_unwind(|| {
        names()
            .get(model)
            .and_then(|(_, p)| p.get(parameter))
            .map_or(std::ptr::null(), |n| n.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// A per-point solver for the model named `model`, or NULL with the reason in `err`. Release
/// it with `rodcube_solver_free`.
///
/// # Safety
/// `model` is a NUL-terminated string; `err` is NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solver_new(
    model: *const c_char,
    err: *mut c_char,
    err_len: usize,
) -> *mut RodcubeSolver {
    let mut made = std::ptr::null_mut();
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let m = find_model(text(model, "the model name")?)?;
            let solver = LeanSolver::new(m).map_err(solve_failure)?;
            made = Box::into_raw(Box::new(RodcubeSolver {
                solver,
                values: vec![0.0; m.info().parameters.len()],
            }));
            Ok(())
        })
    };
    made
}

/// Releases a solver (NULL is ignored).
///
/// # Safety
/// `solver` is NULL or a pointer from `rodcube_solver_new` not yet released.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solver_free(solver: *mut RodcubeSolver) {
    if !solver.is_null() {
        // SAFETY: made by `Box::into_raw` in `rodcube_solver_new`, released once.
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(solver) })));
    }
}

/// Solves one point: `n_params` values in the model's parameter order
/// (`rodcube_parameter_name`). Writes `*out` on success.
///
/// # Safety
/// `solver` comes from `rodcube_solver_new`; `params` points to `n_params` values; `out` to
/// one writable `rodcube_point`; `err` is NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solve(
    solver: *mut RodcubeSolver,
    params: *const f64,
    n_params: usize,
    out: *mut RodcubePoint,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let s = solver_mut(solver)?;
            let out = output(out)?;
            let p = slice(params, n_params, "the parameters")?;
            *out = s.solver.solve(p).map_err(solve_failure)?.into();
            Ok(())
        })
    }
}

/// Solves one point with its parameters by name: `names[i]` is given `values[i]`, each of
/// the model's parameters exactly once, in any order.
///
/// # Safety
/// As `rodcube_solve`; `names` points to `n` NUL-terminated strings and `values` to `n`
/// values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solve_named(
    solver: *mut RodcubeSolver,
    names: *const *const c_char,
    values: *const f64,
    n: usize,
    out: *mut RodcubePoint,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let s = solver_mut(solver)?;
            let given = slice(names, n, "the names")?;
            let vals = slice(values, n, "the values")?;
            let mut pairs = Vec::with_capacity(n);
            for (i, (&name, &value)) in given.iter().zip(vals).enumerate() {
                pairs.push((text(name, &format!("name {i}"))?, value));
            }
            ordered_values(s.solver.model().info(), &pairs, &mut s.values)
                .map_err(|e| failure(RODCUBE_ERR_PARAMETERS, e.to_string()))?;
            let out = output(out)?;
            *out = s.solver.solve(&s.values).map_err(solve_failure)?.into();
            Ok(())
        })
    }
}

/// Runs a scene given as YAML text (the format of the files in `scenes/`) and writes its
/// results as JSON (the `results.json` of `rodcube run`) into `json`, NUL-terminated. When
/// `json_len` is too small, returns `RODCUBE_ERR_BUFFER` and sets `*needed` (also on success)
/// to the bytes required, NUL included: call again with a buffer that large.
///
/// # Safety
/// `scene_yaml` is a NUL-terminated string; `json` is NULL (with `json_len` 0) or points to
/// `json_len` writable bytes; `needed` is NULL or points to a writable `size_t`; `err` as
/// `rodcube_solve`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_run_scene(
    scene_yaml: *const c_char,
    json: *mut c_char,
    json_len: usize,
    needed: *mut usize,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let yaml = text(scene_yaml, "the scene")?;
            let scene = Scene::parse(yaml, Path::new("<scene>"), crate::models::all())
                .map_err(|e| failure(RODCUBE_ERR_SCENE, e.to_string()))?;
            let request = Request::new(scene.model, scene.parameters.clone())
                .with_want(&scene.want)
                .with_tolerance(scene.tolerance)
                .with_samples(scene.samples);
            let results = plan::run(&request).map_err(|e| {
                let code = match e {
                    plan::PlanError::Solve(_) | plan::PlanError::NonFinite { .. } => {
                        RODCUBE_ERR_SOLVE
                    }
                    _ => RODCUBE_ERR_SCENE,
                };
                failure(code, e.to_string())
            })?;
            let text = crate::report::json::to_string(&results)
                .map_err(|e| failure(RODCUBE_ERR_SOLVE, e.to_string()))?;
            let size = text.len() + 1;
            if let Some(n) = needed.as_mut() {
                *n = size;
            }
            if json.is_null() || json_len < size {
                return Err(failure(
                    RODCUBE_ERR_BUFFER,
                    format!("the results need {size} bytes; the buffer has {json_len}"),
                ));
            }
            std::ptr::copy_nonoverlapping(text.as_ptr(), json.cast::<u8>(), text.len());
            *json.add(text.len()) = 0;
            Ok(())
        })
    }
}
