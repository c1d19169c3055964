/* rodcube.h: the C interface of rodcube (cargo feature `capi`, src/ffi.rs).
 *
 * Build the library with
 *   cargo rustc --release --lib --no-default-features --features capi --crate-type cdylib
 * (or --crate-type staticlib) and link with -lrodcube; examples/c/run.sh does both.
 *
 * Every function that can fail returns a status code (RODCUBE_OK or a RODCUBE_ERR_*) and
 * copies the reason into the caller's buffer `err` of `err_len` bytes (NUL-terminated; `err`
 * may be NULL). Strings returned are static; the only object to release is a solver, with
 * rodcube_solver_free. No call panics or aborts: an internal error is RODCUBE_ERR_PANIC.
 */
#ifndef RODCUBE_H
#define RODCUBE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RODCUBE_OK 0
/* A NULL pointer, text that is not UTF-8, or an inconsistent length. */
#define RODCUBE_ERR_ARGUMENT 1
/* No model of that name, or one the per-point solver cannot solve. */
#define RODCUBE_ERR_MODEL 2
/* The parameters were refused (count, value, or a requirement of the model). */
#define RODCUBE_ERR_PARAMETERS 3
/* A solver failed (no separation before the floor, say). */
#define RODCUBE_ERR_SOLVE 4
/* The scene was refused. */
#define RODCUBE_ERR_SCENE 5
/* The output buffer is too small; *needed says how large it must be. */
#define RODCUBE_ERR_BUFFER 6
/* An internal error, caught at the boundary. */
#define RODCUBE_ERR_PANIC 7

/* One point's separation. */
typedef struct rodcube_point {
    double separation_angle; /* theta_sep (rad) */
    double separation_time;  /* time from release to separation (s) */
    double delta;            /* theta_i - theta_sep (rad) */
} rodcube_point;

/* A per-point solver of one model (opaque). */
typedef struct rodcube_solver rodcube_solver;

/* The registered models and their parameters (static strings; NULL past the end). */
size_t rodcube_model_count(void);
const char *rodcube_model_name(size_t model);
size_t rodcube_parameter_count(size_t model);
const char *rodcube_parameter_name(size_t model, size_t parameter);

/* A solver for the model named `model`, or NULL with the reason in `err`. */
rodcube_solver *rodcube_solver_new(const char *model, char *err, size_t err_len);
/* Releases a solver (NULL is ignored). */
void rodcube_solver_free(rodcube_solver *solver);

/* Solves one point: `n_params` values in the model's parameter order. */
int rodcube_solve(rodcube_solver *solver, const double *params, size_t n_params,
                  rodcube_point *out, char *err, size_t err_len);
/* Solves one point with parameters by name, each exactly once, in any order. */
int rodcube_solve_named(rodcube_solver *solver, const char *const *names,
                        const double *values, size_t n, rodcube_point *out, char *err,
                        size_t err_len);

/* Runs a scene given as YAML text and writes its results.json into `json` (NUL-terminated).
 * `*needed` (if not NULL) receives the bytes required, NUL included; with a buffer too small
 * the call returns RODCUBE_ERR_BUFFER, so a first call with json = NULL, json_len = 0 asks the
 * size. */
int rodcube_run_scene(const char *scene_yaml, char *json, size_t json_len, size_t *needed,
                      char *err, size_t err_len);

#ifdef __cplusplus
}
#endif

#endif /* RODCUBE_H */
