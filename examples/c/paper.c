/* paper.c: the paper's case (n = 3, a/ell = 1/4, g = 9.81) through rodcube's C interface.
 *
 * Prints `separation_angle=<rad> separation_time=<s>` to full double precision, then a line
 * of its exact sensitivities to every parameter, `d(separation_angle)/d(<p>)=...` and
 * `d(separation_time)/d(<p>)=...` (rodcube_sensitivities). It also
 * solves the point with its parameters in the model's order (the two must agree), shows a
 * refused point's code and message, and runs a scene once to its JSON results, read in place
 * and copied, so every function of rodcube.h is called but rodcube_models_load (tapes.c calls
 * it). Build and run: examples/c/run.sh
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rodcube.h"

static int fail(const char *what, int code, const char *err) {
    const char *name = rodcube_error_name(code);
    fprintf(stderr, "paper: %s failed (code %d, %s): %s\n", what, code,
            name != NULL ? name : "not a rodcube code", err);
    return 1;
}

/* The index of the model named `name`, or -1. */
static long find_model(const char *name) {
    for (size_t i = 0; i < rodcube_model_count(); i++) {
        if (strcmp(rodcube_model_name(i), name) == 0) {
            return (long)i;
        }
    }
    return -1;
}

int main(void) {
    char err[1024];
    rodcube_solver *solver = NULL;
    int code = rodcube_solver_new("rod_cube", &solver, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_solver_new", code, err);
    }

    /* By name, in any order. */
    const char *names[] = {"g", "a", "ell", "m2", "m1"};
    const double values[] = {9.81, 0.25, 1.0, 3.0, 1.0};
    rodcube_point named;
    code = rodcube_solve_named(solver, names, values, 5, &named, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_solve_named", code, err);
    }

    /* In the model's order, read from the registry. */
    long model = find_model("rod_cube");
    if (model < 0 || rodcube_parameter_count((size_t)model) != 5) {
        return fail("the registry", -1, "no rod_cube with 5 parameters");
    }
    double ordered[5];
    for (size_t i = 0; i < 5; i++) {
        const char *p = rodcube_parameter_name((size_t)model, i);
        for (size_t j = 0; j < 5; j++) {
            if (strcmp(p, names[j]) == 0) {
                ordered[i] = values[j];
            }
        }
    }
    rodcube_point point;
    code = rodcube_solve(solver, ordered, 5, &point, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_solve", code, err);
    }
    if (memcmp(&point, &named, sizeof point) != 0) {
        return fail("comparing", -1, "by name and in order differ");
    }

    /* The point's sensitivities to every parameter, in the model's order. */
    double d_angle[5];
    double d_time[5];
    rodcube_point again;
    code = rodcube_sensitivities(solver, ordered, 5, &again, d_angle, d_time, 5, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_sensitivities", code, err);
    }
    if (memcmp(&again, &point, sizeof point) != 0) {
        return fail("comparing", -1, "rodcube_sensitivities' point differs from rodcube_solve's");
    }

    /* A refused point: the cube as high as the rod is long, a requirement of the model, in
     * the group of refused parameters. */
    const double upright[] = {1.0, 3.0, 1.0, 1.0, 9.81};
    rodcube_point unused;
    code = rodcube_solve(solver, upright, 5, &unused, err, sizeof err);
    if (code != RODCUBE_ERR_PARAM_REQUIREMENT ||
        rodcube_error_group(code) != RODCUBE_ERR_PARAMETERS ||
        strcmp(rodcube_error_name(code), "RODCUBE_ERR_PARAM_REQUIREMENT") != 0 ||
        strstr(err, "a < ell") == NULL) {
        return fail("refusing a = ell", code, err);
    }
    rodcube_solver_free(solver);

    /* A scene, solved once; its JSON is read in place, then copied into a buffer of ours. */
    const char *scene =
        "model: rod_cube\n"
        "parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\n"
        "want: [separation_time]\n";
    rodcube_results *results = NULL;
    code = rodcube_run_scene(scene, &results, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_run_scene", code, err);
    }
    const char *text = rodcube_results_json(results);
    size_t needed = rodcube_results_len(results) + 1;
    char *json = malloc(needed);
    if (json == NULL) {
        rodcube_results_free(results);
        return fail("malloc", -1, "out of memory");
    }
    code = rodcube_results_copy(results, json, needed, &needed, err, sizeof err);
    int same = code == RODCUBE_OK && strcmp(json, text) == 0;
    rodcube_results_free(results);
    if (!same || strstr(json, "\"separation_time\"") == NULL) {
        free(json);
        return fail("reading the scene's results", code, err);
    }
    free(json);

    printf("separation_angle=%.17g separation_time=%.17g\n", point.separation_angle,
           point.separation_time);
    for (size_t i = 0; i < 5; i++) {
        const char *p = rodcube_parameter_name((size_t)model, i);
        printf("%sd(separation_angle)/d(%s)=%.17g d(separation_time)/d(%s)=%.17g", i ? " " : "", p,
               d_angle[i], p, d_time[i]);
    }
    printf("\n");
    return 0;
}
