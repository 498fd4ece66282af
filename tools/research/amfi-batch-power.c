/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-batch-power: how often a batch experiment like the paper's Table 4
 * shows the STD trend, given the per-vehicle results amfi-paper measured.
 *
 *   amfi-batch-power [--vehicles FILE.csv] [--condition NAME] [--n N1,N2,...]
 *                    [--trials T] [--reps R] [--seed S]
 *
 * Input: amfi-paper's table4_vehicles.csv (header condition, repetition,
 * damage, record, gvw_true_kg, gvw_fixed_kg, ...; default
 * docs/results/table4_vehicles.csv). For the condition chosen (default
 * table5_same: the Table 5 inaccuracies on the same vehicles at every damage
 * level), every (repetition, vehicle) is a unit with one inferred GVW per
 * damage level 0 / 2.5 / 5 / 7.5 / 10 %; the rows of a unit must name the
 * same record at every level.
 *
 * A trial is one experiment of R repetitions (default 3, as the paper) with
 * batches of N vehicles drawn with replacement from the units, in two
 * designs:
 *   same       one batch per repetition, used at every level (the paper's
 *              accurate case);
 *   different  a new batch at every level (the paper's Table 5 case: "a
 *              different batch of 500 vehicles is used for each damage level").
 * Per repetition: the STD of inferred GVW at each level, whether it rises
 * monotonically, and the R² of its linear trend; per trial: R² over all
 * R × 5 batches (the paper's Figure 10 trend line) and the target,
 * monotonic in every repetition and the pooled R² >= 0.9.
 *
 * Reference row ("paper"): normal GVW with the paper's Table 4 STDs (Table 5
 * column: 2.27 / 2.55 / 2.89 / 3.34 / 3.88 t), batches of N drawn afresh at
 * every level, the same statistics: what the paper's effect size gives.
 *
 * Output: a markdown table on stdout; the command line and run time on
 * stderr. Exit status 0; 1 bad input file; 2 bad command line. A bad file
 * gives "FILE:LINE: problem".
 */
#include <errno.h>
#include <gsl/gsl_fit.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_cli.h"
#include "amfi_csv.h"

#define PROG "amfi-batch-power"
#define N_LEVELS 5
#define MAX_N 16
#define MAX_REPS 20
#define MAX_UNITS 1000000

static const double levels[N_LEVELS] = {0.0, 0.025, 0.05, 0.075, 0.10};
static const double paper_std_t[N_LEVELS] = {2.27, 2.55, 2.89, 3.34, 3.88};

typedef struct opts {
    const char *path, *condition;
    int n[MAX_N], n_n, reps;
    long trials;
    unsigned long seed;
} opts;

typedef struct unit {
    int rep, record;
    double gvw[N_LEVELS]; /* t; NAN until read */
} unit;

static void usage(FILE *f)
{
    fprintf(f, "usage: %s [--vehicles FILE.csv] [--condition NAME] [--n N1,N2,...]\n"
               "       [--trials T] [--reps R] [--seed S]\n"
               "  -v, --vehicles FILE   amfi-paper's per-vehicle results\n"
               "                        (default docs/results/table4_vehicles.csv)\n"
               "  -c, --condition NAME  the condition to resample (default table5_same)\n"
               "  -n, --n LIST          batch sizes (default 500,1000,2000,4000)\n"
               "  -t, --trials T        resampled experiments per size (default 20000)\n"
               "  -r, --reps R          repetitions in the file (default 3)\n"
               "  -s, --seed S          random seed (default 1)\n"
               "  -h, --help            this help\n"
               "  -V, --version         print the version\n",
            PROG);
}

static void parse(int argc, char **argv, opts *o)
{
    static const struct option longopts[] = {
        {"vehicles", required_argument, NULL, 'v'},
        {"condition", required_argument, NULL, 'c'},
        {"n", required_argument, NULL, 'n'},
        {"trials", required_argument, NULL, 't'},
        {"reps", required_argument, NULL, 'r'},
        {"seed", required_argument, NULL, 's'},
        AMFI_CLI_END};
    *o = (opts){.path = "docs/results/table4_vehicles.csv", .condition = "table5_same",
                .n = {500, 1000, 2000, 4000}, .n_n = 4, .reps = 3, .trials = 20000, .seed = 1};
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *v = optarg;
        switch (k) {
        case 'v': o->path = v; break;
        case 'c': o->condition = v; break;
        case 't': o->trials = (long)amfi_cli_num(&c, v, 10, 1e7); break;
        case 'r': o->reps = (int)amfi_cli_num(&c, v, 1, MAX_REPS); break;
        case 's': o->seed = (unsigned long)amfi_cli_num(&c, v, 0, 4294967295.0); break;
        case 'n': {
            double n[MAX_N];
            o->n_n = amfi_cli_list(&c, v, n, MAX_N, 3, 1e6);
            for (int i = 0; i < o->n_n; i++)
                o->n[i] = (int)n[i];
            break;
        }
        }
    }
}

/* ---- input ----------------------------------------------------------------- */

static int level_of(double d)
{
    for (int l = 0; l < N_LEVELS; l++)
        if (fabs(d - levels[l]) < 1e-9)
            return l;
    return -1;
}

/* Split `line` at commas into at most `max` fields; returns the count. */
static int split(char *line, char **f, int max)
{
    int n = 0;
    char *p = line;
    while (n < max) {
        f[n++] = p;
        char *c = strchr(p, ',');
        if (!c)
            break;
        *c = 0;
        p = c + 1;
    }
    return n;
}

static int field_num(const char *s, double *v) { return amfi_cli_double(s, v); }

/* Read the condition's rows into units (index: order within (rep, level)). */
static int read_units(const opts *o, unit **out, long *n_out)
{
    char err[512];
    amfi_csv *f = amfi_csv_open(o->path, AMFI_CSV_MAX_LINE, err, sizeof err);
    if (!f) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        return -1;
    }
    char line[AMFI_CSV_MAX_LINE + 1];
    const char *got_line;
    size_t len;
    int got;
    long lineno = 0, n_units = 0, cap_units = 0;
    unit *u = NULL;
    /* next[rep][level]: rows of (rep, level) seen so far = the unit's index
     * within the repetition */
    long next[MAX_REPS + 1][N_LEVELS];
    memset(next, 0, sizeof next);
    long base[MAX_REPS + 1]; /* first unit of each repetition, −1 unseen */
    for (int r = 0; r <= MAX_REPS; r++)
        base[r] = -1;
    int rc = -1;
    /* the common reader cuts the lines, refuses NUL bytes and over-long lines */
    while ((got = amfi_csv_next(f, &got_line, &len)) > 0) {
        lineno = amfi_csv_lineno(f);
        memcpy(line, got_line, len + 1);
        if (lineno == 1) {
            if (strncmp(line, "condition,repetition,damage,record,gvw_true_kg,gvw_fixed_kg", 59)) {
                fprintf(stderr,
                        "%s:1: header must start with "
                        "condition,repetition,damage,record,gvw_true_kg,gvw_fixed_kg\n",
                        o->path);
                goto out;
            }
            continue;
        }
        if (len == 0)
            continue;
        char *fl[8];
        int nf = split(line, fl, 8);
        if (nf < 6) {
            fprintf(stderr, "%s:%ld: %d fields, expected at least 6\n", o->path, lineno, nf);
            goto out;
        }
        if (strcmp(fl[0], o->condition))
            continue;
        double rep_d, dmg, rec_d, g_true, g_fix;
        if (field_num(fl[1], &rep_d) || rep_d != floor(rep_d) || rep_d < 1 || rep_d > MAX_REPS) {
            fprintf(stderr, "%s:%ld: repetition: '%s' is not an integer in [1, %d]\n", o->path,
                    lineno, amfi_cli_shown(fl[1]), MAX_REPS);
            goto out;
        }
        int lev;
        if (field_num(fl[2], &dmg) || (lev = level_of(dmg)) < 0) {
            fprintf(stderr, "%s:%ld: damage: '%s' is not one of 0, 0.025, 0.05, 0.075, 0.1\n",
                    o->path, lineno, amfi_cli_shown(fl[2]));
            goto out;
        }
        if (field_num(fl[3], &rec_d) || rec_d != floor(rec_d) || rec_d < 1 || rec_d > 1e9) {
            fprintf(stderr, "%s:%ld: record: '%s' is not a positive integer\n", o->path, lineno,
                    amfi_cli_shown(fl[3]));
            goto out;
        }
        if (field_num(fl[4], &g_true) || g_true <= 0 || g_true > 1e6) {
            fprintf(stderr, "%s:%ld: gvw_true_kg: '%s' is not in (0, 1e6]\n", o->path, lineno,
                    amfi_cli_shown(fl[4]));
            goto out;
        }
        if (field_num(fl[5], &g_fix) || fabs(g_fix) > 1e7) {
            fprintf(stderr, "%s:%ld: gvw_fixed_kg: '%s' is not a finite weight\n", o->path,
                    lineno, amfi_cli_shown(fl[5]));
            goto out;
        }
        int rep = (int)rep_d;
        long k = next[rep][lev]++;
        if (lev == 0) {
            if (base[rep] < 0) {
                if (next[rep][0] != 1) {
                    fprintf(stderr, "%s:%ld: internal: repetition %d\n", o->path, lineno, rep);
                    goto out;
                }
                base[rep] = n_units;
            }
            if (base[rep] + k != n_units) {
                fprintf(stderr,
                        "%s:%ld: repetition %d: its rows must be contiguous (another "
                        "repetition's rows came in between)\n",
                        o->path, lineno, rep);
                goto out;
            }
            if (n_units == MAX_UNITS) {
                fprintf(stderr, "%s:%ld: more than %d vehicles\n", o->path, lineno, MAX_UNITS);
                goto out;
            }
            if (n_units == cap_units) {
                long nc = cap_units ? 2 * cap_units : 1024;
                unit *nu = realloc(u, sizeof *u * (size_t)nc);
                if (!nu) {
                    fprintf(stderr, "%s: out of memory\n", PROG);
                    goto out;
                }
                u = nu;
                cap_units = nc;
            }
            u[n_units] = (unit){.rep = rep, .record = (int)rec_d};
            for (int l = 0; l < N_LEVELS; l++)
                u[n_units].gvw[l] = NAN;
            n_units++;
        } else if (base[rep] < 0 || k >= next[rep][0]) {
            fprintf(stderr,
                    "%s:%ld: repetition %d, damage %g: more rows than at damage 0 (each level "
                    "must hold the same vehicles; rows at damage 0 come first)\n",
                    o->path, lineno, rep, dmg);
            goto out;
        }
        unit *x = &u[base[rep] + k];
        if (x->record != (int)rec_d) {
            fprintf(stderr,
                    "%s:%ld: repetition %d, damage %g, vehicle %ld: record %d, but %d at damage "
                    "0 (condition %s must use the same vehicles at every level)\n",
                    o->path, lineno, rep, dmg, k + 1, (int)rec_d, x->record, o->condition);
            goto out;
        }
        x->gvw[lev] = g_fix / 1000.0;
    }
    if (got < 0) {
        fprintf(stderr, "%s\n", err);
        goto out;
    }
    if (lineno == 0) {
        fprintf(stderr, "%s: empty file\n", o->path);
        goto out;
    }
    for (long i = 0; i < n_units; i++)
        for (int l = 0; l < N_LEVELS; l++)
            if (isnan(u[i].gvw[l])) {
                fprintf(stderr,
                        "%s: repetition %d, record %d has no row at damage %g (condition %s)\n",
                        o->path, u[i].rep, u[i].record, levels[l], o->condition);
                goto out;
            }
    if (n_units < 10) {
        fprintf(stderr, "%s: %ld vehicles of condition '%s' (need at least 10)\n", o->path,
                n_units, amfi_cli_shown(o->condition));
        goto out;
    }
    *out = u;
    *n_out = n_units;
    u = NULL;
    rc = 0;
out:
    free(u);
    amfi_csv_close(f, 0);
    return rc;
}

/* ---- the experiment ------------------------------------------------------- */

typedef struct tally {
    long mono_rep, r2_rep, all_mono, pooled_r2, target, trials, reps;
    double *r2_pooled; /* per trial, for the median */
} tally;

static double r2_of(const double *x, const double *y, int n)
{
    double c0, c1, cov00, cov01, cov11, sumsq;
    gsl_fit_linear(x, 1, y, 1, (size_t)n, &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
    double var = gsl_stats_variance(y, 1, (size_t)n) * (n - 1);
    return var > 0 ? 1.0 - sumsq / var : 0.0;
}

/* STD (t) of N draws: from units at level `lev` (idx given) or normal. */
static double batch_std(const unit *u, const long *idx, int n, int lev, double *buf)
{
    for (int i = 0; i < n; i++)
        buf[i] = u[idx[i]].gvw[lev];
    return gsl_stats_sd(buf, 1, (size_t)n);
}

static void draw(gsl_rng *r, long n_units, int n, long *idx)
{
    for (int i = 0; i < n; i++)
        idx[i] = (long)gsl_rng_uniform_int(r, (unsigned long)n_units);
}

/* design: 0 same, 1 different, 2 paper (normal, different) */
static void run(const opts *o, const unit *u, long n_units, int n, int design, gsl_rng *r,
                tally *t)
{
    long *idx = malloc(sizeof(long) * (size_t)n);
    double *buf = malloc(sizeof(double) * (size_t)n);
    double X[MAX_REPS * N_LEVELS], Y[MAX_REPS * N_LEVELS];
    memset(t, 0, sizeof *t);
    t->r2_pooled = malloc(sizeof(double) * (size_t)o->trials);
    if (!idx || !buf || !t->r2_pooled) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        exit(1);
    }
    for (long tr = 0; tr < o->trials; tr++) {
        int all_mono = 1;
        for (int rep = 0; rep < o->reps; rep++) {
            double *x = X + rep * N_LEVELS, *y = Y + rep * N_LEVELS;
            if (design == 0)
                draw(r, n_units, n, idx);
            for (int l = 0; l < N_LEVELS; l++) {
                x[l] = 100.0 * levels[l];
                if (design == 1)
                    draw(r, n_units, n, idx);
                if (design == 2) {
                    for (int i = 0; i < n; i++)
                        buf[i] = gsl_ran_gaussian_ziggurat(r, paper_std_t[l]);
                    y[l] = gsl_stats_sd(buf, 1, (size_t)n);
                } else
                    y[l] = batch_std(u, idx, n, l, buf);
            }
            int mono = 1;
            for (int l = 1; l < N_LEVELS; l++)
                mono &= y[l] > y[l - 1];
            all_mono &= mono;
            t->mono_rep += mono;
            t->r2_rep += r2_of(x, y, N_LEVELS) >= 0.9;
            t->reps++;
        }
        double rp = r2_of(X, Y, o->reps * N_LEVELS);
        t->r2_pooled[tr] = rp;
        t->all_mono += all_mono;
        t->pooled_r2 += rp >= 0.9;
        t->target += all_mono && rp >= 0.9;
        t->trials++;
    }
    free(idx);
    free(buf);
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void print_row(const char *what, int n, tally *t)
{
    qsort(t->r2_pooled, (size_t)t->trials, sizeof(double), cmp_d);
    double med = t->r2_pooled[t->trials / 2];
    printf("| %s | %d | %.1f %% | %.1f %% | %.1f %% | %.3f | %.1f %% | **%.1f %%** |\n", what, n,
           100.0 * t->mono_rep / t->reps, 100.0 * t->r2_rep / t->reps,
           100.0 * t->all_mono / t->trials, med, 100.0 * t->pooled_r2 / t->trials,
           100.0 * t->target / t->trials);
    free(t->r2_pooled);
    t->r2_pooled = NULL;
}

int main(int argc, char **argv)
{
    opts o;
    parse(argc, argv, &o);
    unit *u = NULL;
    long n_units = 0;
    if (read_units(&o, &u, &n_units))
        return 1;
    double mean_std[N_LEVELS];
    double *buf = malloc(sizeof(double) * (size_t)n_units);
    if (!buf) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        return 1;
    }
    for (int l = 0; l < N_LEVELS; l++) {
        for (long i = 0; i < n_units; i++)
            buf[i] = u[i].gvw[l];
        mean_std[l] = gsl_stats_sd(buf, 1, (size_t)n_units);
    }
    free(buf);
    clock_t c0 = clock();
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, o.seed);
    printf("<!-- amfi-batch-power: %s, condition %s (%ld vehicles), %ld trials of %d "
           "repetitions, seed %lu -->\n",
           o.path, o.condition, n_units, o.trials, o.reps, o.seed);
    printf("STD of inferred GVW over all %ld vehicles of `%s`, damage 0 / 2.5 / 5 / 7.5 / 10 %%: "
           "%.3f / %.3f / %.3f / %.3f / %.3f t (×%.3f at 10 %%); the paper's Table 4 (Table 5 "
           "column): 2.27 / 2.55 / 2.89 / 3.34 / 3.88 t (×1.709).\n\n",
           n_units, o.condition, mean_std[0], mean_std[1], mean_std[2], mean_std[3],
           mean_std[4], mean_std[4] / mean_std[0]);
    printf("| batches | N per batch | monotonic, one repetition | R² >= 0.9, one repetition | "
           "monotonic in all %d | median R² of all %d batches | R² of all batches >= 0.9 | "
           "target (all monotonic and R² >= 0.9) |\n",
           o.reps, o.reps * N_LEVELS);
    printf("|---|---|---|---|---|---|---|---|\n");
    static const char *names[3] = {"same vehicles at every level", "a different batch per level",
                                   "paper's STDs, a different batch per level"};
    for (int d = 0; d < 3; d++)
        for (int k = 0; k < o.n_n; k++) {
            tally t;
            run(&o, u, n_units, o.n[k], d, r, &t);
            print_row(names[d], o.n[k], &t);
        }
    gsl_rng_free(r);
    free(u);
    fprintf(stderr, "%s: %.1f s\n", PROG, (double)(clock() - c0) / CLOCKS_PER_SEC);
    return 0;
}
