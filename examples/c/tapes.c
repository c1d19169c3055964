/* tapes.c: a model derived a minute ago, run from C with no compiler: loads a directory of tapes
 * (written by `rodcube derive --tapes-into DIR SPEC`), then solves one of its models by name.
 *
 *   tapes DIR MODEL NAME=VALUE...
 *
 * Prints `loaded=<models in DIR> models=<models registered>`, then
 * `separation_angle=<rad> separation_time=<s>` from the model's per-point solver (every
 * parameter given by name), then the results.json of a scene of the same point run once
 * (`rodcube_run_scene`; its notes say the model ran from its tape). A tape refused prints its
 * code's name and the message, which names the file, and exits 1.
 * Build and run: examples/c/run.sh tapes DIR MODEL NAME=VALUE...
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rodcube.h"

#define MAX_PARAMETERS 64

static int fail(const char *what, int code, const char *err) {
    const char *name = rodcube_error_name(code);
    fprintf(stderr, "tapes: %s failed (code %d, %s): %s\n", what, code,
            name != NULL ? name : "not a rodcube code", err);
    return 1;
}

int main(int argc, char **argv) {
    if (argc < 3 || argc - 3 > MAX_PARAMETERS) {
        fprintf(stderr, "usage: tapes DIR MODEL NAME=VALUE... (at most %d parameters)\n",
                MAX_PARAMETERS);
        return 2;
    }
    char err[1024];
    size_t loaded = 0;
    int code = rodcube_models_load(argv[1], &loaded, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_models_load", code, err);
    }
    printf("loaded=%zu models=%zu\n", loaded, rodcube_model_count());

    /* The parameters by name, as NAME=VALUE arguments; the scene's `parameters` from them. */
    const char *names[MAX_PARAMETERS];
    double values[MAX_PARAMETERS];
    size_t n = (size_t)(argc - 3);
    size_t scene_len = strlen(argv[2]) + 128;
    for (size_t i = 0; i < n; i++) {
        char *arg = argv[3 + i];
        char *eq = strchr(arg, '=');
        char *end = NULL;
        if (eq == NULL) {
            fprintf(stderr, "tapes: `%s` is not NAME=VALUE\n", arg);
            return 2;
        }
        *eq = '\0';
        values[i] = strtod(eq + 1, &end);
        if (end == eq + 1 || *end != '\0') {
            fprintf(stderr, "tapes: the value of `%s` is not a number\n", arg);
            return 2;
        }
        names[i] = arg;
        scene_len += strlen(arg) + 32;
    }

    rodcube_solver *solver = NULL;
    code = rodcube_solver_new(argv[2], &solver, err, sizeof err);
    if (code != RODCUBE_OK) {
        return fail("rodcube_solver_new", code, err);
    }
    rodcube_point point;
    code = rodcube_solve_named(solver, names, values, n, &point, err, sizeof err);
    rodcube_solver_free(solver);
    if (code != RODCUBE_OK) {
        return fail("rodcube_solve_named", code, err);
    }
    printf("separation_angle=%.17g separation_time=%.17g\n", point.separation_angle,
           point.separation_time);

    char *scene = malloc(scene_len);
    if (scene == NULL) {
        return fail("malloc", -1, "out of memory");
    }
    size_t at = (size_t)snprintf(scene, scene_len, "model: %s\nparameters: {", argv[2]);
    for (size_t i = 0; i < n; i++) {
        at += (size_t)snprintf(scene + at, scene_len - at, "%s%s: %.17g", i ? ", " : "",
                               names[i], values[i]);
    }
    snprintf(scene + at, scene_len - at, "}\nwant: [separation_angle, separation_time]\n");
    rodcube_results *results = NULL;
    code = rodcube_run_scene(scene, &results, err, sizeof err);
    free(scene);
    if (code != RODCUBE_OK) {
        return fail("rodcube_run_scene", code, err);
    }
    printf("%s\n", rodcube_results_json(results));
    rodcube_results_free(results);
    return 0;
}
