/* per_point.c: the fixed set of examples/per_point.rs through rodcube's C interface, to count
 * what a call across the boundary costs (run it under `valgrind --tool=callgrind`).
 *
 * Solves the first N points (argument, default 1000) of the 100 x 100 grid
 * n_i = 10^(-3 + 6 i / 99), a/ell_j = 0.01 + 0.98 j / 99 (ell = g = m1 = 1, m2 = n), point k
 * being grid index (7919 k) mod 10000, and prints the sum of separation angles plus times to
 * 17 significant digits. Build and run: examples/c/run.sh per_point [N]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rodcube.h"

int main(int argc, char **argv) {
    long count = argc > 1 ? strtol(argv[1], NULL, 10) : 1000;
    if (count < 0) {
        fprintf(stderr, "per_point: N must be a non-negative integer\n");
        return 2;
    }
    double n[100];
    for (int i = 0; i < 100; i++) {
        n[i] = pow(10.0, -3.0 + 6.0 * i / 99.0);
    }
    double *points = malloc(sizeof(double) * 5 * (size_t)(count > 0 ? count : 1));
    if (points == NULL) {
        return 1;
    }
    for (long k = 0; k < count; k++) {
        long index = (7919 * k) % 10000;
        double *p = points + 5 * k;
        p[0] = 1.0;
        p[1] = n[index / 100];
        p[2] = 1.0;
        p[3] = 0.01 + 0.98 * (double)(index % 100) / 99.0;
        p[4] = 1.0;
    }
    char err[512];
    rodcube_solver *solver = NULL;
    if (rodcube_solver_new("rod_cube", &solver, err, sizeof err) != RODCUBE_OK) {
        fprintf(stderr, "per_point: %s\n", err);
        return 1;
    }
    double sum = 0.0;
    for (long k = 0; k < count; k++) {
        rodcube_point out;
        if (rodcube_solve(solver, points + 5 * k, 5, &out, err, sizeof err) != RODCUBE_OK) {
            fprintf(stderr, "per_point: point %ld: %s\n", k, err);
            return 1;
        }
        sum += out.separation_angle + out.separation_time;
    }
    rodcube_solver_free(solver);
    free(points);
    printf("%.16e\n", sum);
    return 0;
}
