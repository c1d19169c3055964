/* paper.c: the paper's case (n = 3, a/ell = 1/4, g = 9.81) through rodcube's C interface.
 *
 * Prints `separation_angle=<rad> separation_time=<s>` to full double precision. It also
 * solves the point with its parameters in the model's order (the two must agree), shows a
 * refused point's message, and runs a scene to JSON, so every function of rodcube.h is
 * called. Build and run: examples/c/run.sh
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rodcube.h"

static int fail(const char *what, int code, const char *err) {
    fprintf(stderr, "paper: %s failed (code %d): %s\n", what, code, err);
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
    rodcube_solver *solver = rodcube_solver_new("rod_cube", err, sizeof err);
    if (solver == NULL) {
        return fail("rodcube_solver_new", -1, err);
    }

    /* By name, in any order. */
    const char *names[] = {"g", "a", "ell", "m2", "m1"};
    const double values[] = {9.81, 0.25, 1.0, 3.0, 1.0};
    rodcube_point named;
    int code = rodcube_solve_named(solver, names, values, 5, &named, err, sizeof err);
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

    /* A refused point: the cube as high as the rod is long. */
    const double upright[] = {1.0, 3.0, 1.0, 1.0, 9.81};
    rodcube_point unused;
    code = rodcube_solve(solver, upright, 5, &unused, err, sizeof err);
    if (code != RODCUBE_ERR_PARAMETERS || strstr(err, "a < ell") == NULL) {
        return fail("refusing a = ell", code, err);
    }
    rodcube_solver_free(solver);

    /* A scene to JSON: ask the size, then fill. */
    const char *scene =
        "model: rod_cube\n"
        "parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\n"
        "want: [separation_time]\n";
    size_t needed = 0;
    code = rodcube_run_scene(scene, NULL, 0, &needed, err, sizeof err);
    if (code != RODCUBE_ERR_BUFFER || needed == 0) {
        return fail("sizing the scene's JSON", code, err);
    }
    char *json = malloc(needed);
    if (json == NULL) {
        return fail("malloc", -1, "out of memory");
    }
    code = rodcube_run_scene(scene, json, needed, &needed, err, sizeof err);
    if (code != RODCUBE_OK || strstr(json, "\"separation_time\"") == NULL) {
        free(json);
        return fail("rodcube_run_scene", code, err);
    }
    free(json);

    printf("separation_angle=%.17g separation_time=%.17g\n", point.separation_angle,
           point.separation_time);
    return 0;
}
