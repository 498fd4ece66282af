/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-bench: speed and memory of the A-MFI solver on the baseline passage.
 *
 * A 1 s passage (2 axles, 102 + 74.6 kN, 5 m apart, 25 m/s over the 20 m
 * paper bridge), recorded at 1000 Hz by the independent Newmark integrator,
 * solved at 5000 Hz: milliseconds per fixed-λ solve for each formulation ×
 * coordinates × modes, the L-curve solve, the workspace and the process's
 * peak resident memory; and the cost of a passage whose speed is estimated
 * (amfi_solve_speed, issue 12) from a detector speed 4 % high, in sweeps
 * (fixed-λ solves) and ms. Each timing is the minimum and median over repeats.
 * OpenBLAS runs single-threaded (the daemon parallelises across passages).
 *
 *   amfi-bench [--repeat N] [--no-nodal]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "amfi/amfi.h"
#include "amfi_cli.h"
#include "amfi_time.h"

static double force(double t, int a, void *user)
{
    (void)t;
    (void)user;
    return a == 0 ? 102000.0 : 74600.0;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct row {
    const char *coords, *modes;
    amfi_coords c;
    amfi_modes m;
    int k;
    int automatic;
    int estimate; /* amfi_solve_speed from a detector speed 4 % high: 1 two levels
                     (the coarse model at 1000 Hz, the default), 2 the grid on the
                     full model (coarse_rate_hz 0) */
} row;

static void usage(FILE *f)
{
    fprintf(f, "usage: amfi-bench [--repeat N] [--no-nodal]\n"
               "  -r, --repeat N    timings per configuration, 1 .. 1000 (default 15)\n"
               "      --no-nodal    skip the slow nodal reference\n"
               "  -h, --help        this help\n"
               "  -V, --version     print the version\n");
}

int main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"repeat", required_argument, NULL, 'r'},
        {"no-nodal", no_argument, NULL, 256},
        AMFI_CLI_END};
    int repeat = 15, nodal = 1;
    amfi_cli c;
    amfi_cli_init(&c, "amfi-bench", argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        if (k == 'r')
            repeat = (int)amfi_cli_integer(&c, optarg, 1, 1000);
        else if (k == 256)
            nodal = 0;
    }
    amfi_set_blas_threads(1);
    char err[256];
    amfi_bridge_params bp;
    amfi_bridge *b;
    amfi_bridge_params_paper20(&bp);
    if (amfi_bridge_create(&bp, &b, err, sizeof err)) {
        fprintf(stderr, "amfi-bench: %s\n", err);
        return 1;
    }
    const double scan = 1000.0, off[2] = {0.0, 5.0}, xs = 10.0;
    const int n = (int)(1.2 * scan) + 1; /* the speed search's slowest window too */
    double *acc = malloc(sizeof(double) * n);
    if (!acc || amfi_forward_newmark(b, 25.0, 2, off, force, NULL, 1, &xs, 2e-5, scan, n, acc,
                                     err, sizeof err)) {
        fprintf(stderr, "amfi-bench: forward response failed: %s\n", err);
        return 1;
    }
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = n;
    p.scan_rate_hz = scan;
    p.accel[0] = acc;
    p.speed_mps = 25.0;
    p.n_axles = 2;
    p.axle_spacing_m[0] = 5.0;
    const double true_gvw = (102000.0 + 74600.0) / AMFI_GRAVITY;

    const row rows[] = {
        {"modal", "all", AMFI_COORDS_MODAL, AMFI_MODES_ALL, 0, 0, 0},
        {"modal", "observable", AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 0, 0, 0},
        {"modal", "10", AMFI_COORDS_MODAL, AMFI_MODES_COUNT, 10, 0, 0},
        {"modal", "resolved", AMFI_COORDS_MODAL, AMFI_MODES_RESOLVED, 0, 0, 0},
        {"modal", "5", AMFI_COORDS_MODAL, AMFI_MODES_COUNT, 5, 0, 0},
        {"nodal", "all", AMFI_COORDS_NODAL, AMFI_MODES_ALL, 0, 0, 0},
        {"modal", "observable", AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 0, 1, 0},
        {"modal", "observable", AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 0, 0, 2},
        {"modal", "observable", AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 0, 0, 1},
        {"modal", "resolved", AMFI_COORDS_MODAL, AMFI_MODES_RESOLVED, 0, 0, 2},
        {"modal", "resolved", AMFI_COORDS_MODAL, AMFI_MODES_RESOLVED, 0, 0, 1},
    };
    printf("amfi-bench: 1 s passage, 2 axles, data %.0f Hz, calculation 5000 Hz, "
           "OpenBLAS 1 thread, %d repeats\n\n",
           scan, repeat);
    printf("%-10s %-6s %-11s %-8s %6s %9s %9s %12s %10s %8s\n", "formulation", "coords",
           "modes", "lambda", "m", "min ms", "median ms", "GVW kg", "GVW err %", "sweeps");
    double t_modal_all = NAN, t_nodal = NAN, gvw_modal_all = NAN, gvw_nodal = NAN;
    size_t ws_max = 0;
    double *t = malloc(sizeof(double) * repeat);
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        const row *r = &rows[i];
        if (r->c == AMFI_COORDS_NODAL && !nodal)
            continue;
        amfi_solver_params sp;
        amfi_solver *s;
        amfi_solver_params_default(&sp, bp.span_m);
        sp.coords = r->c;
        sp.modes = r->m;
        sp.n_modes = r->k;
        if (amfi_solver_create(b, &sp, &s, err, sizeof err)) {
            fprintf(stderr, "amfi-bench: %s\n", err);
            return 1;
        }
        amfi_lambda lam;
        amfi_lambda_default(&lam);
        lam.automatic = r->automatic;
        int reps = r->c == AMFI_COORDS_NODAL || r->estimate ? (repeat < 3 ? repeat : 3) : repeat;
        amfi_result res;
        amfi_speed_prior prior;
        amfi_speed_prior_default(&prior);
        if (r->estimate == 2)
            prior.coarse_rate_hz = 0;
        amfi_speed_result sres;
        amfi_passage pe = p;
        pe.speed_mps = 26.0;
        for (int k = 0; k < reps; k++) {
            double t0 = (1e3 * amfi_mono_s());
            if (r->estimate ? amfi_solve_speed(s, &pe, &lam, &prior, &res, &sres, err, sizeof err)
                            : amfi_solve(s, &p, &lam, &res, err, sizeof err)) {
                fprintf(stderr, "amfi-bench: %s\n", err);
                return 1;
            }
            t[k] = (1e3 * amfi_mono_s()) - t0;
        }
        qsort(t, reps, sizeof *t, cmp);
        printf("%-10s %-6s %-11s %-8s %6d %9.2f %9.2f %12.2f %+10.3f %8d\n", "paper", r->coords,
               r->modes, r->automatic ? "L-curve" : r->estimate ? "speed" : "fixed", res.n_modes, t[0], t[reps / 2],
               res.gvw_kg, 100 * (res.gvw_kg / true_gvw - 1), res.n_solves);
        if (r->estimate)
            printf("    speed estimated from 26 m/s (true 25), %s: %.4f m/s (%+.3f %%), one "
                   "passage = %d fixed-lambda solves + %d coarse (%.0f Hz) sweeps\n",
                   r->estimate == 1 ? "two levels" : "grid on the full model", sres.speed_mps,
                   100 * (sres.speed_mps / 25.0 - 1), res.n_solves, sres.n_coarse,
                   prior.coarse_rate_hz);
        if (r->c == AMFI_COORDS_MODAL && r->m == AMFI_MODES_ALL) {
            t_modal_all = t[0];
            gvw_modal_all = res.gvw_kg;
        }
        if (r->c == AMFI_COORDS_NODAL) {
            t_nodal = t[0];
            gvw_nodal = res.gvw_kg;
        }
        size_t ws = amfi_solver_workspace_bytes(s);
        if (ws > ws_max)
            ws_max = ws;
        amfi_solver_destroy(s);
    }
    if (nodal)
        printf("\nmodal (all modes) vs nodal dense: %.0fx faster, GVW differs by %.2g kg (%.1e relative)\n",
               t_nodal / t_modal_all, fabs(gvw_modal_all - gvw_nodal),
               fabs(gvw_modal_all / gvw_nodal - 1));
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("largest solver workspace: %.2f MB; peak resident memory of this process: %.1f MB\n",
           ws_max / 1048576.0, ru.ru_maxrss / 1024.0);
    free(t);
    free(acc);
    amfi_bridge_destroy(b);
    return 0;
}
