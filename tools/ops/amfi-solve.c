/*
 * amfi-solve: offline A-MFI solve of one recorded passage.
 *
 *   amfi-solve [--config FILE.yaml] --accel CASE.csv[.gz] --speed MPS
 *              --axle-spacing S1[,S2,...] [--entry-time SEC]
 *              [--lambda auto|VALUE] [--formulation NAME]
 *              [--forces OUT.csv] [--lcurve OUT.csv]
 *
 * Reads a single-sensor passage CSV (tools/accel_csv.h), builds the site's
 * bridge and solver from the configuration (default: the shipped
 * paper-20m.yaml, or the built-in paper-20m defaults when that file is not
 * installed), solves, and prints one JSON object on one line to stdout.
 *
 * Exit status: 0 solved; 1 bad data, configuration, solver failure or an
 * output file that cannot be written; 2 bad command line. Every error is one
 * line on stderr: "FILE:LINE: problem" for the data, "amfi-solve: --option:
 * problem" for the command line.
 *
 * Workload: one passage per run (about 1 s at 5000 Hz); the bridge model and
 * the solver workspace are built once, then torn down in reverse order.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "accel_csv.h"
#include "amfi/amfi.h"
#include "amfi_cli.h"
#include "amfi_config.h"

#define PROG "amfi-solve"
#define EXIT_DATA 1
#define EXIT_USAGE 2
#define MAX_SPEED_MPS 60.0   /* 216 km/h: anything faster is a typo */
#define MAX_SPACING_M 30.0   /* longer than any road vehicle's axle gap */

#ifndef AMFI_DEFAULT_CONFIG
#define AMFI_DEFAULT_CONFIG "paper-20m.yaml"
#endif

/* Where the shipped configuration may be when none is named: the source tree
 * the program was built from, then the installed copies. */
static const char *const default_configs[] = {
    AMFI_DEFAULT_CONFIG,
#ifdef AMFI_INSTALLED_CONFIG
    AMFI_INSTALLED_CONFIG,
#endif
#ifdef AMFI_INSTALLED_CONFIG2
    AMFI_INSTALLED_CONFIG2,
#endif
};

typedef struct options {
    const char *config;      /* NULL: the default search */
    const char *accel;
    const char *forces;      /* NULL: not written */
    const char *lcurve;      /* NULL: not written */
    const char *formulation; /* NULL: the config's */
    const char *lambda;      /* NULL: the config's; "auto" or a number */
    double speed_mps;        /* NaN until given */
    double entry_time_s;     /* time of entry on the file's clock, s */
    int n_spacings;          /* 1 .. AMFI_MAX_AXLES − 1, 0 until given */
    double spacing_m[AMFI_MAX_AXLES];
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: " PROG " [--config FILE.yaml] --accel CASE.csv[.gz] "
            "--speed MPS --axle-spacing S1[,S2,...]\n"
            "       [--entry-time SEC] [--lambda auto|VALUE] "
            "[--formulation NAME]\n"
            "       [--forces OUT.csv] [--lcurve OUT.csv]\n"
            "\n"
            "Solves one recorded passage (CSV 't,accel', plain or gzip) "
            "and prints a JSON line.\n"
            "  --config FILE      site configuration (default: paper-20m)\n"
            "  --accel FILE       accelerations, t in s, m/s^2 positive "
            "downward\n"
            "  --speed MPS        vehicle speed, 0 < v <= %g m/s\n"
            "  --axle-spacing S   axle spacings, m, comma-separated "
            "(0 < s <= %g)\n"
            "  --entry-time SEC   time on the file's clock when the first "
            "axle enters (default 0)\n"
            "  --lambda L         'auto' (L-curve) or lambda at the config's "
            "lambda reference rate\n"
            "  --formulation F    solver formulation (default: the config's)\n"
            "  --forces FILE      write t,x1,force1_N,... per step\n"
            "  --lcurve FILE      write the L-curve (needs --lambda auto)\n"
            "Exit status: 0 ok, 1 data or solver error, 2 usage error.\n",
            MAX_SPEED_MPS, MAX_SPACING_M);
}

/* "amfi-solve: OPT: problem" on stderr; returns −1 */
static int usage_error(const char *opt, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static int usage_error(const char *opt, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, PROG ": %s: ", opt);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return -1;
}

static int parse_spacings(const char *arg, options *o)
{
    const char *opt = "--axle-spacing";
    char buf[64];
    const char *p = arg;
    o->n_spacings = 0;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t n = comma ? (size_t)(comma - p) : strlen(p);
        if (n == 0)
            return usage_error(opt, "empty value in '%s'", amfi_cli_shown(arg));
        if (n >= sizeof buf)
            return usage_error(opt, "value too long in '%s'", amfi_cli_shown(arg));
        memcpy(buf, p, n);
        buf[n] = '\0';
        if (o->n_spacings == AMFI_MAX_AXLES - 1)
            return usage_error(opt, "more than %d spacings (at most %d axles)",
                               AMFI_MAX_AXLES - 1, AMFI_MAX_AXLES);
        double s;
        if (amfi_cli_double(buf, &s) != 0)
            return usage_error(opt, "'%s' is not a number", amfi_cli_shown(buf));
        if (!(s > 0))
            return usage_error(opt, "'%s' must be > 0 m", amfi_cli_shown(buf));
        if (s > MAX_SPACING_M)
            return usage_error(opt, "'%s' m is not an axle spacing (max %g m)",
                               amfi_cli_shown(buf), MAX_SPACING_M);
        o->spacing_m[o->n_spacings++] = s;
        if (!comma)
            return 0;
        p = comma + 1;
    }
}

/* Options take a value, as "--name VALUE" or "--name=VALUE". */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->speed_mps = NAN;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        static const char *const names[] = {
            "--config", "--accel", "--speed", "--axle-spacing", "--entry-time",
            "--lambda", "--formulation", "--forces", "--lcurve"};
        int which = -1;
        const char *val = NULL;
        for (int k = 0; k < (int)(sizeof names / sizeof names[0]); k++) {
            size_t n = strlen(names[k]);
            if (strncmp(a, names[k], n) == 0
                && (a[n] == '\0' || a[n] == '=')) {
                which = k;
                val = a[n] == '=' ? a + n + 1 : NULL;
                break;
            }
        }
        if (which < 0) {
            if (a[0] == '-')
                return usage_error(amfi_cli_shown(a), "unknown option (see --help)");
            return usage_error(amfi_cli_shown(a), "unexpected argument (see --help)");
        }
        const char *opt = names[which];
        if (!val) {
            if (i + 1 >= argc)
                return usage_error(opt, "needs a value");
            val = argv[++i];
        }
        if (val[0] == '\0')
            return usage_error(opt, "empty value");
        double x;
        switch (which) {
        case 0: o->config = val; break;
        case 1: o->accel = val; break;
        case 2:
            if (amfi_cli_double(val, &x) != 0)
                return usage_error(opt, "'%s' is not a number", amfi_cli_shown(val));
            if (!(x > 0))
                return usage_error(opt, "'%s' must be > 0 m/s", amfi_cli_shown(val));
            if (x > MAX_SPEED_MPS)
                return usage_error(opt, "'%s' m/s is absurd for road traffic "
                                   "(max %g m/s)", amfi_cli_shown(val), MAX_SPEED_MPS);
            o->speed_mps = x;
            break;
        case 3:
            if (parse_spacings(val, o) != 0)
                return -1;
            break;
        case 4:
            if (amfi_cli_double(val, &x) != 0)
                return usage_error(opt, "'%s' is not a number", amfi_cli_shown(val));
            o->entry_time_s = x;
            break;
        case 5:
            if (strcmp(val, "auto") != 0
                && (amfi_cli_double(val, &x) != 0 || !(x > 0)))
                return usage_error(opt, "'%s' is neither 'auto' nor a "
                                   "number > 0", amfi_cli_shown(val));
            o->lambda = val;
            break;
        case 6: o->formulation = val; break;
        case 7: o->forces = val; break;
        case 8: o->lcurve = val; break;
        }
    }
    if (!o->accel)
        return usage_error("--accel", "missing (see --help)");
    if (isnan(o->speed_mps))
        return usage_error("--speed", "missing (see --help)");
    if (o->n_spacings == 0)
        return usage_error("--axle-spacing", "missing (see --help)");
    return 0;
}

/* 0 loaded (or defaults because no file exists), −1 error reported. */
static int load_config(const options *o, amfi_site_config *c)
{
    char err[512];
    if (o->config) {
        if (amfi_config_load(o->config, c, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return -1;
        }
        return 0;
    }
    for (size_t k = 0; k < sizeof default_configs / sizeof default_configs[0];
         k++) {
        struct stat st;
        if (stat(default_configs[k], &st) != 0)
            continue;
        if (amfi_config_load(default_configs[k], c, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return -1;
        }
        return 0;
    }
    amfi_config_defaults(c);
    return 0;
}

static double elapsed_ms(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) * 1e3
           + (double)(b->tv_nsec - a->tv_nsec) * 1e-6;
}

/* JSON has no NaN or Inf: write null for them. */
static void json_num(FILE *f, double x)
{
    if (isfinite(x))
        fprintf(f, "%.10g", x);
    else
        fputs("null", f);
}

static void csv_num(FILE *f, double x)
{
    if (isnan(x))
        fputs("nan", f);
    else
        fprintf(f, "%.10g", x);
}

/* Close f and report any write error against `what`/`path`. */
static int finish_file(FILE *f, const char *what, const char *path)
{
    int bad = ferror(f);
    int saved = errno;
    if (fclose(f) != 0 && !bad) {
        bad = 1;
        saved = errno;
    }
    if (bad) {
        fprintf(stderr, PROG ": %s: cannot write '%s': %s\n", what, path,
                strerror(saved));
        return -1;
    }
    return 0;
}

static FILE *open_out(const char *what, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        fprintf(stderr, PROG ": %s: cannot open '%s': %s\n", what, path,
                strerror(errno));
    return f;
}

/* One row per step j = 0 .. N: t relative to entry, x of axle 1, forces. */
static int write_forces(const char *path, const amfi_result *r,
                        double speed_mps)
{
    FILE *f = open_out("--forces", path);
    if (!f)
        return -1;
    fputs("t,x1", f);
    for (int a = 0; a < r->n_axles; a++)
        fprintf(f, ",force%d_N", a + 1);
    fputc('\n', f);
    for (int j = 0; j <= r->n_steps; j++) {
        double t = r->t0_s + j * r->h_s;
        csv_num(f, t);
        fputc(',', f);
        csv_num(f, speed_mps * t);
        for (int a = 0; a < r->n_axles; a++) {
            fputc(',', f);
            csv_num(f, r->force_N[(size_t)j * (size_t)r->n_axles + (size_t)a]);
        }
        fputc('\n', f);
    }
    return finish_file(f, "--forces", path);
}

static int write_lcurve(const char *path, const amfi_result *r)
{
    FILE *f = open_out("--lcurve", path);
    if (!f)
        return -1;
    fputs("lambda_ref,residual_norm,smoothing_norm,curvature\n", f);
    for (int k = 0; k < r->lcurve_n; k++) {
        csv_num(f, r->lcurve_lambda_ref[k]);
        fputc(',', f);
        csv_num(f, r->lcurve_residual[k]);
        fputc(',', f);
        csv_num(f, r->lcurve_smoothing[k]);
        fputc(',', f);
        csv_num(f, r->lcurve_curvature[k]);
        fputc('\n', f);
    }
    return finish_file(f, "--lcurve", path);
}

static void print_json(const amfi_site_config *c, const amfi_result *r,
                       double scan_rate_hz, double solve_ms)
{
    FILE *f = stdout;
    fputs("{\"gvw_kg\":", f);
    json_num(f, r->gvw_kg);
    fputs(",\"axle_kg\":[", f);
    for (int a = 0; a < r->n_axles; a++) {
        if (a)
            fputc(',', f);
        json_num(f, r->axle_kg[a]);
    }
    fputs("],\"mean_force_N\":[", f);
    for (int a = 0; a < r->n_axles; a++) {
        if (a)
            fputc(',', f);
        json_num(f, r->mean_force_N[a]);
    }
    fputs("],\"lambda\":", f);
    json_num(f, r->lambda_h);
    fputs(",\"lambda_ref\":", f);
    json_num(f, r->lambda_ref);
    fputs(",\"lambda_ref_rate_hz\":", f);
    json_num(f, c->lambda.ref_rate_hz);
    fprintf(f, ",\"formulation\":\"%s\",\"coordinates\":\"%s\",\"modes\":%d",
            amfi_formulation_name(c->solver.formulation),
            c->solver.coords == AMFI_COORDS_NODAL ? "nodal" : "modal",
            r->n_modes);
    fputs(",\"calc_rate_hz\":", f);
    json_num(f, c->solver.calc_rate_hz);
    fputs(",\"scan_rate_hz\":", f);
    json_num(f, scan_rate_hz);
    fprintf(f, ",\"n_steps\":%d", r->n_steps);
    fputs(",\"residual_rms\":", f);
    json_num(f, r->residual_rms);
    fputs(",\"signal_rms\":", f);
    json_num(f, r->signal_rms);
    fputs(",\"solve_ms\":", f);
    json_num(f, solve_ms);
    fprintf(f, ",\"lcurve_points\":%d}\n", r->lcurve_n);
}

int main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return EXIT_USAGE;
    amfi_set_blas_threads(1); /* small matrices: threads only spin */

    static amfi_site_config cfg; /* large; zeroed */
    if (load_config(&o, &cfg) != 0)
        return EXIT_DATA;
    if (o.lambda) {
        if (strcmp(o.lambda, "auto") == 0) {
            cfg.lambda.automatic = 1;
        } else {
            cfg.lambda.automatic = 0;
            cfg.lambda.lambda_ref = strtod(o.lambda, NULL); /* checked */
        }
    }
    if (o.formulation
        && amfi_formulation_parse(o.formulation, &cfg.solver.formulation)
               != 0) {
        fprintf(stderr, PROG ": --formulation: unknown formulation '%s'\n",
                amfi_cli_shown(o.formulation));
        return EXIT_USAGE;
    }
    if (o.lcurve && !cfg.lambda.automatic) {
        fprintf(stderr, PROG ": --lcurve needs --lambda auto\n");
        return EXIT_USAGE;
    }

    int n_axles = o.n_spacings + 1;
    double wheelbase_m = 0;
    for (int k = 0; k < o.n_spacings; k++)
        wheelbase_m += o.spacing_m[k];
    /* the window, relative to entry (amfi.h: entry − pre_roll .. last exit
     * + post_roll) */
    const double span_m = cfg.bridge.span_m;
    const double crossing_s = (span_m + wheelbase_m) / o.speed_mps;
    const double win_lo = 0.0 - cfg.solver.pre_roll_s; /* never "-0" */
    const double win_hi = crossing_s + cfg.solver.post_roll_s;

    /* single-sensor CSV: sensor 0 of the configuration */
    cfg.solver.n_sensors = 1;
    if (cfg.solver.max_axles < n_axles)
        cfg.solver.max_axles = n_axles;
    if (cfg.solver.max_duration_s < crossing_s)
        cfg.solver.max_duration_s = crossing_s;

    int status = EXIT_DATA;
    char err[512];
    accel_csv csv = {0};
    amfi_bridge *bridge = NULL;
    amfi_solver *solver = NULL;

    if (accel_csv_read(o.accel, &csv, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        goto done;
    }
    if (amfi_bridge_create(&cfg.bridge, &bridge, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": bridge model: %s\n", err);
        goto done;
    }
    if (amfi_solver_create(bridge, &cfg.solver, &solver, err, sizeof err)
        != 0) {
        fprintf(stderr, PROG ": solver: %s\n", err);
        goto done;
    }

    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = csv.n;
    p.scan_rate_hz = csv.rate_hz;
    p.t_first_s = csv.t0_s - o.entry_time_s;
    p.accel[0] = csv.accel;
    p.speed_mps = o.speed_mps;
    p.n_axles = n_axles;
    for (int k = 0; k < o.n_spacings; k++)
        p.axle_spacing_m[k] = o.spacing_m[k];

    amfi_result res;
    memset(&res, 0, sizeof res);
    struct timespec t_a, t_b;
    clock_gettime(CLOCK_MONOTONIC, &t_a);
    int rc = amfi_solve(solver, &p, &cfg.lambda, &res, err, sizeof err);
    clock_gettime(CLOCK_MONOTONIC, &t_b);
    if (rc == AMFI_ERANGE) {
        double lo = p.t_first_s;
        double hi = lo + (double)(csv.n - 1) / csv.rate_hz;
        fprintf(stderr,
                "%s: passage not covered: the data spans [%.6g, %.6g] s but "
                "the window needs [%.6g, %.6g] s\n",
                o.accel, lo, hi, win_lo, win_hi);
        goto done;
    }
    if (rc != 0) {
        fprintf(stderr, PROG ": %s: solve failed: %s\n", o.accel,
                err[0] ? err : amfi_strerror(rc));
        goto done;
    }
    if (o.forces && write_forces(o.forces, &res, o.speed_mps) != 0)
        goto done;
    if (o.lcurve && write_lcurve(o.lcurve, &res) != 0)
        goto done;
    print_json(&cfg, &res, csv.rate_hz, elapsed_ms(&t_a, &t_b));
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, PROG ": stdout: %s\n", strerror(errno));
        goto done;
    }
    status = 0;
done:
    amfi_solver_destroy(solver);
    amfi_bridge_destroy(bridge);
    accel_csv_free(&csv);
    return status;
}
