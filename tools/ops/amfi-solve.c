/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-solve: offline A-MFI solve of one recorded passage.
 *
 *   amfi-solve [--config FILE.yaml] --accel CASE.csv[.gz] --speed MPS
 *              --axle-spacing S1[,S2,...] [--entry-time SEC]
 *   amfi-solve ... --vehicle ENTRY_S:SPEED_MPS:S1[,S2,...] (repeated, one per
 *              vehicle on the span, solved jointly; instead of the three above)
 *              [--lambda auto|VALUE] [--formulation NAME]
 *              [--forces OUT.csv] [--lcurve OUT.csv]
 *              [--estimate-speed [--speed-sd FRACTION]]
 *   amfi-solve [--config FILE.yaml] --from-store DB --passage ID
 *              [--lambda auto|VALUE] [--formulation NAME] [--forces OUT.csv] [--lcurve OUT.csv]
 *
 * Reads a passage CSV (tools/accel_csv.h): 't,accel' for a site of one
 * sensor, or 't,accel_ID,...' with a column for every sensor of the site
 * (by its id; a site sensor without a column, a column of no site sensor,
 * or 't,accel' for a site of several sensors is refused, naming them),
 * builds the site's bridge and solver from the configuration (default: the shipped
 * paper-20m.yaml, or the built-in paper-20m defaults when that file is not
 * installed), solves, and prints one JSON object on one line to stdout.
 * With --estimate-speed (or solver.speed: estimate) --speed is the
 * detector's value, the prior of amfi_solve_speed, and the passage is
 * weighed at the estimated speed (JSON speed_mps, speed_given_mps,
 * speed_estimated; the axle spacings are always the given ones).
 *
 * With --from-store, the passage's raw samples kept by amfid
 * (daemon.store.raw; store.h, "raw samples") are re-weighed: the samples,
 * time base, detector records (as amfid corrected them: detector.* is not
 * applied again), the λ policy and the speed settings are the store's, the
 * bridge, sensors and the rest of solver: the site file's (--config; the
 * store does not record them). The JSON line then also holds "stored"
 * (amfid's row) and "difference" (re-weighed − stored, and why: "identical",
 * the λ or formulation given, the passage not solved by amfid, or the site
 * file / libamfi differing from amfid's). A passage without raw samples
 * (not kept, deleted by retention, a store older than version 11) is exit 1
 * with a message saying which.
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
#include "store.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_datafile.h"
#include "amfi_json.h"

#define PROG "amfi-solve"
#define EXIT_DATA 1
#define EXIT_USAGE 2
#define MAX_SPEED_MPS 60.0   /* 216 km/h: anything faster is a typo */
#define MAX_SPACING_M 30.0   /* longer than any road vehicle's axle gap */

/* The shipped configuration looked for when none is named
 * (common/amfi_datafile.h: $AMFI_DATA_DIR, then the installed copies). */
#define DEFAULT_CONFIG_NAME "paper-20m.yaml"

typedef struct options {
    const char *config;      /* NULL: the default search */
    const char *accel;
    const char *forces;      /* NULL: not written */
    const char *lcurve;      /* NULL: not written */
    const char *speed_trace; /* --speed-trace: the search's grid, NULL: not written */
    const char *formulation; /* NULL: the config's */
    const char *lambda;      /* NULL: the config's; "auto" or a number */
    double speed_mps;        /* NaN until given */
    int estimate_speed;      /* 1: --estimate-speed; 0: the config's solver.speed */
    double speed_sd;         /* --speed-sd; NaN: the config's solver.speed_sd */
    double entry_time_s;     /* time of entry on the file's clock, s */
    int n_spacings;          /* 1 .. AMFI_MAX_AXLES − 1, 0 until given */
    double spacing_m[AMFI_MAX_AXLES];
    int entry_given;         /* --entry-time seen (not with --vehicle) */
    int n_vehicles;          /* --vehicle count, 0: the one-vehicle form */
    amfi_vehicle vehicle[AMFI_MAX_VEHICLES]; /* entry on the file's clock */
    const char *store;       /* --from-store DB; NULL: --accel */
    int64_t passage_id;      /* --passage */
    int passage_given;
} options;

static void usage(FILE *f)
{
    char places[512];
    fprintf(f,
            "usage: " PROG " [--config FILE.yaml] --accel CASE.csv[.gz] "
            "--speed MPS --axle-spacing S1[,S2,...]\n"
            "       [--entry-time SEC] [--lambda auto|VALUE] "
            "[--formulation NAME]\n"
            "       [--forces OUT.csv] [--lcurve OUT.csv]\n"
            "       [--estimate-speed [--speed-sd FRACTION]]\n"
            "   or: " PROG " ... --vehicle ENTRY_S:SPEED_MPS:S1[,S2,...] "
            "[--vehicle ...] (instead of --speed/--axle-spacing/--entry-time)\n"
            "   or: " PROG " [--config FILE.yaml] --from-store DB --passage ID [--lambda ...]\n"
            "       [--formulation NAME] [--forces OUT.csv] [--lcurve OUT.csv]\n"
            "\n"
            "Solves one recorded passage (CSV 't,accel', or 't,accel_ID,...' with a column\n"
            "per sensor of the site by its id; plain or gzip) and prints a JSON line.\n"
            "  -c, --config FILE        site configuration (default: paper-20m.yaml\n"
            "                           from %s,\n"
            "                           else the built-in paper-20m values)\n"
            "  -a, --accel FILE         accelerations, t in s, m/s^2 positive "
            "downward\n"
            "  -s, --speed MPS          vehicle speed, 0 < v <= %g m/s\n"
            "  -x, --axle-spacing S     axle spacings, m, comma-separated "
            "(0 < s <= %g)\n"
            "  -e, --entry-time SEC     time on the file's clock when the first "
            "axle enters (default 0)\n"
            "  -v, --vehicle E:V:S      a vehicle entering at E s (file's clock) at V m/s\n"
            "                           with axle spacings S (as -x); repeat for each\n"
            "                           vehicle on the span: all are solved jointly\n"
            "  -l, --lambda L           'auto' (L-curve) or lambda at the config's "
            "lambda reference rate\n"
            "  -f, --formulation F      solver formulation (default: the config's)\n"
            "  -F, --forces FILE        write t,x1,force1_N,... per step\n"
            "  -L, --lcurve FILE        write the L-curve (needs --lambda auto)\n"
            "      --estimate-speed     estimate the speed from the data, --speed as the\n"
            "                           detector's value (default: the config's solver.speed)\n"
            "      --speed-sd FRACTION  the detector's relative SD, 0 < f < 1 (default: the\n"
            "                           config's solver.speed_sd)\n"
            "      --speed-trace FILE   write the speed search's grid: speed_mps,J,dip\n"
            "      --from-store DB      re-weigh a passage from the raw samples amfid kept in\n"
            "                           its store (daemon.store.raw), with the store's detector\n"
            "                           records, lambda and speed settings and this site file's\n"
            "                           bridge and solver; prints the stored result and the\n"
            "                           difference too\n"
            "      --passage ID         the passage (passages.id) to re-weigh\n"
            "  -h, --help               this help\n"
            "  -V, --version            print the version\n"
            "Exit status: 0 ok, 1 data or solver error, 2 usage error.\n",
            amfi_datafile_places(places, sizeof places), MAX_SPEED_MPS, MAX_SPACING_M);
}

/* "amfi-solve: OPT: problem" on stderr; returns −1 */
#define usage_error(opt, ...) (amfi_cli_error(PROG, opt, __VA_ARGS__), -1)

/* Comma-separated axle spacings into out[] (*n of them), for option opt. */
static int parse_spacings(const char *arg, const char *opt, double *out, int *n_out)
{
    char buf[64];
    const char *p = arg;
    *n_out = 0;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t n = comma ? (size_t)(comma - p) : strlen(p);
        if (n == 0)
            return usage_error(opt, "empty value in '%s'", amfi_cli_shown(arg));
        if (n >= sizeof buf)
            return usage_error(opt, "value too long in '%s'", amfi_cli_shown(arg));
        memcpy(buf, p, n);
        buf[n] = '\0';
        if (*n_out == AMFI_MAX_AXLES - 1)
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
        out[(*n_out)++] = s;
        if (!comma)
            return 0;
        p = comma + 1;
    }
}

static int check_speed(const char *opt, const char *val, double *out)
{
    double x;
    if (amfi_cli_double(val, &x) != 0)
        return usage_error(opt, "'%s' is not a number", amfi_cli_shown(val));
    if (!(x > 0))
        return usage_error(opt, "'%s' must be > 0 m/s", amfi_cli_shown(val));
    if (x > MAX_SPEED_MPS)
        return usage_error(opt, "'%s' m/s is absurd for road traffic "
                           "(max %g m/s)", amfi_cli_shown(val), MAX_SPEED_MPS);
    *out = x;
    return 0;
}

/* --vehicle ENTRY_S:SPEED_MPS:S1[,S2,...] */
static int parse_vehicle(const char *arg, options *o)
{
    const char *opt = "--vehicle";
    if (o->n_vehicles == AMFI_MAX_VEHICLES)
        return usage_error(opt, "more than %d vehicles", AMFI_MAX_VEHICLES);
    const char *c1 = strchr(arg, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1 || !c2)
        return usage_error(opt, "'%s' is not ENTRY_S:SPEED_MPS:S1[,S2,...]",
                           amfi_cli_shown(arg));
    char buf[64];
    amfi_vehicle *v = &o->vehicle[o->n_vehicles];
    memset(v, 0, sizeof *v);
    size_t n = (size_t)(c1 - arg);
    if (n == 0 || n >= sizeof buf)
        return usage_error(opt, "bad entry time in '%s'", amfi_cli_shown(arg));
    memcpy(buf, arg, n);
    buf[n] = '\0';
    if (amfi_cli_double(buf, &v->entry_s) != 0)
        return usage_error(opt, "entry time '%s' is not a number", amfi_cli_shown(buf));
    n = (size_t)(c2 - c1 - 1);
    if (n == 0 || n >= sizeof buf)
        return usage_error(opt, "bad speed in '%s'", amfi_cli_shown(arg));
    memcpy(buf, c1 + 1, n);
    buf[n] = '\0';
    if (check_speed(opt, buf, &v->speed_mps) != 0)
        return -1;
    int ns = 0;
    if (c2[1] == '\0')
        return usage_error(opt, "no axle spacings in '%s'", amfi_cli_shown(arg));
    if (parse_spacings(c2 + 1, opt, v->axle_spacing_m, &ns) != 0)
        return -1;
    v->n_axles = ns + 1;
    o->n_vehicles++;
    return 0;
}

/* Options take a value, as "--name VALUE", "--name=VALUE" or "-n VALUE". */
static int parse_args(int argc, char **argv, options *o)
{
    static const struct option longopts[] = {
        {"config", required_argument, NULL, 'c'},
        {"accel", required_argument, NULL, 'a'},
        {"speed", required_argument, NULL, 's'},
        {"axle-spacing", required_argument, NULL, 'x'},
        {"entry-time", required_argument, NULL, 'e'},
        {"lambda", required_argument, NULL, 'l'},
        {"formulation", required_argument, NULL, 'f'},
        {"forces", required_argument, NULL, 'F'},
        {"lcurve", required_argument, NULL, 'L'},
        {"estimate-speed", no_argument, NULL, 'E'},
        {"speed-sd", required_argument, NULL, 'S'},
        {"speed-trace", required_argument, NULL, 'T'},
        {"vehicle", required_argument, NULL, 'v'},
        {"from-store", required_argument, NULL, 'D'},
        {"passage", required_argument, NULL, 'P'},
        AMFI_CLI_END};
    memset(o, 0, sizeof *o);
    o->speed_mps = NAN;
    o->speed_sd = NAN;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *opt = c.opt, *val = optarg;
        if (k == 'E') { /* the one option without a value */
            o->estimate_speed = 1;
            continue;
        }
        if (val[0] == '\0')
            return usage_error(opt, "empty value");
        double x;
        switch (k) {
        case 'c': o->config = val; break;
        case 'a': o->accel = val; break;
        case 's':
            if (check_speed(opt, val, &o->speed_mps) != 0)
                return -1;
            break;
        case 'x':
            if (parse_spacings(val, opt, o->spacing_m, &o->n_spacings) != 0)
                return -1;
            break;
        case 'v':
            if (parse_vehicle(val, o) != 0)
                return -1;
            break;
        case 'e':
            if (amfi_cli_double(val, &x) != 0)
                return usage_error(opt, "'%s' is not a number", amfi_cli_shown(val));
            o->entry_time_s = x;
            o->entry_given = 1;
            break;
        case 'l':
            if (strcmp(val, "auto") != 0
                && (amfi_cli_double(val, &x) != 0 || !(x > 0)))
                return usage_error(opt, "'%s' is neither 'auto' nor a "
                                   "number > 0", amfi_cli_shown(val));
            o->lambda = val;
            break;
        case 'f': o->formulation = val; break;
        case 'F': o->forces = val; break;
        case 'L': o->lcurve = val; break;
        case 'T': o->speed_trace = val; break;
        case 'D': o->store = val; break;
        case 'P': {
            char *e;
            errno = 0;
            long long id = strtoll(val, &e, 10);
            if (*e || errno || id < 1)
                return usage_error(opt, "'%s' is not a passage id (an integer >= 1)",
                                   amfi_cli_shown(val));
            o->passage_id = id;
            o->passage_given = 1;
            break;
        }
        case 'S':
            if (amfi_cli_double(val, &x) != 0 || !(x > 0 && x < 1))
                return usage_error(opt, "'%s' must be a fraction in (0, 1)",
                                   amfi_cli_shown(val));
            o->speed_sd = x;
            break;
        }
    }
    if (o->store || o->passage_given) {
        if (!o->store)
            return usage_error("--passage", "needs --from-store DB");
        if (!o->passage_given)
            return usage_error("--from-store", "needs --passage ID");
        if (o->accel || o->n_vehicles || !isnan(o->speed_mps) || o->n_spacings ||
            o->entry_given || o->estimate_speed || !isnan(o->speed_sd) || o->speed_trace)
            return usage_error("--from-store",
                               "not with --accel, --vehicle, --speed, --axle-spacing, "
                               "--entry-time, --estimate-speed, --speed-sd or --speed-trace "
                               "(the store has the samples, the detector records and the "
                               "speed settings)");
        return 0;
    }
    if (!o->accel)
        return usage_error("--accel", "missing (see --help)");
    if (o->n_vehicles > 0) {
        if (!isnan(o->speed_mps) || o->n_spacings > 0 || o->entry_given)
            return usage_error("--vehicle", "not with --speed, --axle-spacing or "
                               "--entry-time (give each vehicle's in --vehicle)");
        int total = 0;
        for (int v = 0; v < o->n_vehicles; v++)
            total += o->vehicle[v].n_axles;
        if (total > AMFI_MAX_EVENT_AXLES)
            return usage_error("--vehicle", "%d axles in all (at most %d)", total,
                               AMFI_MAX_EVENT_AXLES);
        return 0;
    }
    if (isnan(o->speed_mps))
        return usage_error("--speed", "missing (see --help, or give --vehicle)");
    if (o->n_spacings == 0)
        return usage_error("--axle-spacing", "missing (see --help)");
    return 0;
}

/* 0 loaded (or defaults because no file exists), −1 error reported. The
 * site's name for messages into name: the file, or "built-in paper-20m". */
static int load_config(const options *o, amfi_site_config *c, char *name, size_t namelen)
{
    char err[512], found[4096];
    const char *file = o->config;
    if (!file && amfi_datafile_find(DEFAULT_CONFIG_NAME, found, sizeof found) == 0)
        file = found;
    snprintf(name, namelen, "%s", file ? file : "built-in paper-20m");
    if (!file) {
        amfi_config_defaults(c);
        return 0;
    }
    if (amfi_config_load(file, c, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

/* Append ", " and an id to a list. */
static void add_id(char *list, size_t len, const char *prefix, int id)
{
    size_t used = strlen(list);
    if (used < len)
        snprintf(list + used, len - used, "%s%s%d", used ? ", " : "", prefix, id);
}

/* The CSV column of each site sensor: col[i] for sensor i of the site
 * (c->sensor_id[i]). 't,accel' is the sensor of a one-sensor site; with
 * several sensors every one needs its column 'accel_ID' and every column
 * its sensor. 0, or −1 with one line on stderr naming the sensors and
 * columns. */
static int map_sensors(const char *path, const char *site, const amfi_site_config *c,
                       const accel_csv *csv, int *col)
{
    const int ns = c->solver.n_sensors;
    char ids[128] = "", missing[128] = "", unknown[160] = "";
    for (int i = 0; i < ns; i++)
        add_id(ids, sizeof ids, "", c->sensor_id[i]);
    if (csv->channel_id[0] < 0) { /* 't,accel' */
        if (ns == 1) {
            col[0] = 0;
            return 0;
        }
        fprintf(stderr,
                "%s:1: one column 't,accel', but the site (%s) has %d sensors (ids %s): "
                "give each its column, 't,accel_ID,...'\n",
                path, site, ns, ids);
        return -1;
    }
    for (int k = 0; k < csv->n_channels; k++) {
        int i = 0;
        while (i < ns && c->sensor_id[i] != csv->channel_id[k])
            i++;
        if (i == ns)
            add_id(unknown, sizeof unknown, "accel_", csv->channel_id[k]);
    }
    for (int i = 0; i < ns; i++) {
        int k = 0;
        while (k < csv->n_channels && csv->channel_id[k] != c->sensor_id[i])
            k++;
        if (k == csv->n_channels)
            add_id(missing, sizeof missing, "", c->sensor_id[i]);
        col[i] = k;
    }
    if (!missing[0] && !unknown[0])
        return 0;
    fprintf(stderr, "%s:1: the site (%s) has sensors %s:%s%s%s%s%s\n", path, site, ids,
            missing[0] ? " no column for sensor(s) " : "", missing,
            missing[0] && unknown[0] ? ";" : "",
            unknown[0] ? " column(s) of no sensor of the site: " : "", unknown);
    return -1;
}

static double elapsed_ms(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) * 1e3
           + (double)(b->tv_nsec - a->tv_nsec) * 1e-6;
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

/* One row per step j = 0 .. N: t relative to entry (with --vehicle: on the
 * file's clock), x of axle 1 (first vehicle's, entering at entry_s), forces. */
static int write_forces(const char *path, const amfi_result *r,
                        double speed_mps, double entry_s)
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
        csv_num(f, speed_mps * (t - entry_s));
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

/* The speed search's grid: the trial speed, J, and J minus its trend
 * (solver.speed_pick dip's measure; empty where the trend is not defined). */
static int write_speed_trace(const char *path, const amfi_speed_result *sr,
                             const amfi_speed_prior *prior)
{
    FILE *f = open_out("--speed-trace", path);
    if (!f)
        return -1;
    fputs("speed_mps,J,dip\n", f);
    for (int k = 0; k < sr->grid_n; k++) {
        csv_num(f, sr->grid_lo_mps + k * sr->grid_step_mps);
        fputc(',', f);
        csv_num(f, sr->grid_j[k]);
        fputc(',', f);
        csv_num(f, amfi_speed_dip_at(prior, sr->grid_j, sr->grid_n, k));
        fputc('\n', f);
    }
    return finish_file(f, "--speed-trace", path);
}

/* The vehicle's class and axle groups under the site's classes: section
 * (classify/amfi_classify.h) into o: "class", "groups" (each group's axles,
 * 0-based within the vehicle, its load, kind and legal limit),
 * "axle_separable" (false for an axle inside a group: its load is the
 * solve's split of the group's, which may be below zero), "gvw_limit_kg",
 * "overload" (its gross weight or a group above its limit; null when the
 * loads were refused) and "loads_refused" (null, or why: a single axle or a
 * group below zero, also said on stderr). 0, or −1 with the message on
 * stderr. */
static int class_json(const amfi_class_params *cp, int n_axles, const double *spacing_m,
                      const double *axle_kg, json_t *o, int vehicle)
{
    amfi_classification k;
    char err[256], who[32] = "";
    if (vehicle >= 0)
        snprintf(who, sizeof who, "vehicle %d: ", vehicle + 1);
    if (amfi_classify(cp, n_axles, spacing_m, axle_kg, &k, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": %sclassification: %s\n", who, err);
        return -1;
    }
    if (!k.loads_ok)
        fprintf(stderr, PROG ": %sloads refused for the limits: %s\n", who, k.loads_why);
    json_t *gs = json_array();
    for (int i = 0; gs && i < k.n_groups; i++) {
        const amfi_axle_group *g = &k.group[i];
        json_t *ax = json_array();
        for (int a = 0; ax && a < g->n_axles; a++)
            json_array_append_new(ax, json_integer(g->first + a));
        json_t *go = json_pack("{s:o, s:o, s:s, s:o}", "axles", ax, "load_kg",
                               amfi_json_num(g->load_kg), "kind", amfi_group_kind_name(g->kind),
                               "limit_kg", amfi_json_num(g->limit_kg));
        if (!go || json_array_append_new(gs, go)) {
            json_decref(gs);
            fprintf(stderr, PROG ": out of memory\n");
            return -1;
        }
    }
    if (!gs || json_object_set_new(o, "class", json_string(k.name)) ||
        json_object_set_new(o, "groups", gs) ||
        json_object_set_new(o, "gvw_limit_kg", amfi_json_num(k.gvw_limit_kg)) ||
        json_object_set_new(o, "overload",
                            k.loads_ok ? json_boolean(k.over != 0) : json_null())) {
        fprintf(stderr, PROG ": out of memory\n");
        return -1;
    }
    json_t *sep = json_array();
    for (int a = 0; sep && a < n_axles; a++)
        json_array_append_new(sep, json_boolean(k.separable[a]));
    if (!sep || json_object_set_new(o, "axle_separable", sep) ||
        json_object_set_new(o, "loads_refused",
                            k.loads_ok ? json_null() : json_string(k.loads_why))) {
        fprintf(stderr, PROG ": out of memory\n");
        return -1;
    }
    return 0;
}

/* The result as one JSON line on stdout (common/amfi_json.h). spacing_m:
 * the one vehicle's spacings; with m, mp's vehicles hold each one's. */
static int print_json(const amfi_site_config *c, const amfi_result *r,
                      const amfi_speed_result *sr, int estimated,
                      const amfi_multi_result *m, const double *spacing_m,
                      const amfi_multi_passage *mp, double scan_rate_hz, double solve_ms,
                      json_t *extra)
{
    json_t *axle = json_array(), *force = json_array();
    for (int a = 0; a < r->n_axles; a++) {
        json_array_append_new(axle, amfi_json_num(r->axle_kg[a]));
        json_array_append_new(force, amfi_json_num(r->mean_force_N[a]));
    }
    json_t *o = json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:o, s:s, s:s, s:i, s:o, s:o, s:i, s:o, s:o, s:o, s:i}",
        "gvw_kg", amfi_json_num(r->gvw_kg), "axle_kg", axle, "mean_force_N", force,
        "lambda", amfi_json_num(r->lambda_h), "lambda_ref", amfi_json_num(r->lambda_ref),
        "lambda_ref_rate_hz", amfi_json_num(c->lambda.ref_rate_hz),
        "formulation", amfi_formulation_name(c->solver.formulation),
        "coordinates", c->solver.coords == AMFI_COORDS_NODAL ? "nodal" : "modal",
        "modes", r->n_modes, "calc_rate_hz", amfi_json_num(c->solver.calc_rate_hz),
        "scan_rate_hz", amfi_json_num(scan_rate_hz), "n_steps", r->n_steps,
        "residual_rms", amfi_json_num(r->residual_rms),
        "signal_rms", amfi_json_num(r->signal_rms), "solve_ms", amfi_json_num(solve_ms),
        "lcurve_points", r->lcurve_n);
    if (o && (json_object_set_new(o, "speed_mps", amfi_json_num(sr->speed_mps)) ||
              json_object_set_new(o, "speed_given_mps", amfi_json_num(sr->speed_given_mps)) ||
              json_object_set_new(o, "speed_estimated", json_boolean(estimated)) ||
              json_object_set_new(o, "speed_coarse_sweeps", json_integer(sr->n_coarse)) ||
              json_object_set_new(o, "speed_dip", amfi_json_num(sr->dip)) ||
              json_object_set_new(o, "speed_aliases", json_integer(sr->n_aliases)) ||
              json_object_set_new(o, "speed_aliases_judged", json_integer(sr->n_aliases_judged)) ||
              json_object_set_new(o, "speed_alias", json_boolean(sr->alias)) ||
              json_object_set_new(o, "n_solves", json_integer(r->n_solves)))) {
        json_decref(o);
        o = NULL;
    }
    json_t *ids = o ? json_array() : NULL; /* the site's sensors, all in the solve */
    for (int i = 0; ids && i < c->solver.n_sensors; i++)
        json_array_append_new(ids, json_integer(c->sensor_id[i]));
    if (o && json_object_set_new(o, "sensor_ids", ids)) {
        json_decref(o);
        o = NULL;
    }
    if (o && !m && class_json(&c->classes, r->n_axles, spacing_m, r->axle_kg, o, -1) != 0) {
        json_decref(o);
        return -1;
    }
    if (o && m) { /* --vehicle: one object per vehicle, in the order given */
        json_t *vs = json_array();
        for (int v = 0; v < m->n_vehicles; v++) {
            const amfi_vehicle_result *vr = &m->vehicle[v];
            json_t *ak = json_array();
            for (int a = 0; a < vr->n_axles; a++)
                json_array_append_new(ak, amfi_json_num(vr->axle_kg[a]));
            json_t *vo = json_pack("{s:o, s:o, s:o, s:o, s:o}", "gvw_kg",
                                   amfi_json_num(vr->gvw_kg), "axle_kg", ak, "quality",
                                   amfi_json_num(vr->quality), "gvw_sd_kg",
                                   amfi_json_num(vr->gvw_sd_kg), "separability",
                                   amfi_json_num(vr->separability));
            int grouped = 0; /* axles shared with another vehicle's (coincident) */
            for (int w = 0; w < m->n_vehicles; w++)
                grouped |= w != v && m->vehicle[w].group == vr->group;
            if (vo && grouped) {
                json_object_set_new(vo, "group", json_integer(vr->group));
                json_object_set_new(vo, "n_merged", json_integer(vr->n_merged));
                json_object_set_new(vo, "group_gvw_kg", amfi_json_num(vr->group_gvw_kg));
            }
            if (vo && class_json(&c->classes, vr->n_axles, mp->vehicle[v].axle_spacing_m,
                                 vr->axle_kg, vo, v) != 0) {
                json_decref(vo);
                json_decref(vs);
                json_decref(o);
                return -1;
            }
            json_array_append_new(vs, vo);
        }
        json_object_set_new(o, "vehicles", vs);
    }
    if (o && extra && json_object_update(o, extra) != 0) {
        json_decref(o);
        o = NULL;
    }
    json_decref(extra);
    if (!o) {
        fprintf(stderr, PROG ": out of memory\n");
        return -1;
    }
    if (amfi_json_print(stdout, o) != 0) {
        fprintf(stderr, PROG ": stdout: %s\n", ferror(stdout) ? strerror(errno) : "write failed");
        return -1;
    }
    return 0;
}

/* --from-store: the passage's raw samples and its stored row into *raw and
 * *stored, and what the solve takes from them into o and cfg (the samples'
 * time base and channels into csv, which then does not own them). 0, or
 * −1 with the message on stderr. */
static int load_from_store(options *o, amfi_site_config *cfg, amfi_raw_rec *raw,
                           amfi_stored_passage *stored, accel_csv *csv, char *name,
                           size_t namelen)
{
    char err[512];
    amfi_store *s = NULL;
    int version = 0, immutable = 0, found = 0, rc = -1;
    const long long id = (long long)o->passage_id;
    snprintf(name, namelen, "%s: passage %lld", o->store, id);
    if (amfi_store_open_reader(o->store, 1, &s, &version, &immutable, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": --from-store: %s\n", err);
        return -1;
    }
    if (version > AMFI_STORE_SCHEMA_VERSION) {
        fprintf(stderr, PROG ": %s: store version %d is newer than this program's (%d)\n",
                o->store, version, AMFI_STORE_SCHEMA_VERSION);
        goto out;
    }
    if (version < AMFI_STORE_RAW_VERSION) {
        fprintf(stderr,
                PROG ": %s: passage %lld has no raw samples: the store is at version %d, older "
                "than raw samples (version %d; amfid migrates it at its next start)\n",
                o->store, id, version, AMFI_STORE_RAW_VERSION);
        goto out;
    }
    if (amfi_store_passage_get(s, o->passage_id, stored, &found, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": %s: %s\n", o->store, err);
        goto out;
    }
    if (!found) {
        fprintf(stderr, PROG ": %s: there is no passage %lld\n", o->store, id);
        goto out;
    }
    if (amfi_store_raw_get(s, o->passage_id, raw, &found, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": %s: %s\n", o->store, err);
        goto out;
    }
    if (!found) {
        fprintf(stderr,
                PROG ": %s: passage %lld (vehicle %lld, status %s) has no raw samples: not "
                "kept (daemon.store.raw.keep, or its window was not complete: status gap, "
                "late, multiple, invalid) or deleted by retention (max_age_days, max_mib)\n",
                o->store, id, (long long)stored->row.vehicle_id, stored->status);
        goto out;
    }
    const amfi_raw_window *w = &raw->w;
    /* the detector records as the solver took them: the entries relative to
     * the first vehicle's, as pool.c computes them */
    if (w->n_vehicles > 1) {
        int axles = 0;
        o->n_vehicles = w->n_vehicles;
        for (int v = 0; v < w->n_vehicles; v++) {
            const amfi_raw_vehicle *e = &w->vehicle[v];
            amfi_vehicle *ve = &o->vehicle[v];
            memset(ve, 0, sizeof *ve);
            ve->entry_s = 1e-6 * (double)(e->utime - w->utime);
            ve->speed_mps = e->speed_mps;
            ve->n_axles = e->n_axles;
            for (int a = 0; a + 1 < e->n_axles; a++)
                ve->axle_spacing_m[a] = e->spacing_m[a];
            axles += e->n_axles;
        }
        if (axles > AMFI_MAX_AXLES) {
            fprintf(stderr, PROG ": %s: %d axles in the event (at most %d)\n", name, axles,
                    AMFI_MAX_AXLES);
            goto out;
        }
        cfg->speed_estimate = 0; /* the joint solve takes the detector's speeds */
    } else {
        const amfi_raw_vehicle *e = &w->vehicle[0];
        o->speed_mps = e->speed_mps;
        o->n_spacings = e->n_axles - 1;
        for (int a = 0; a + 1 < e->n_axles; a++)
            o->spacing_m[a] = e->spacing_m[a];
        o->entry_time_s = 1e-6 * (double)(e->utime - w->utime);
        cfg->speed_estimate = w->speed_estimate;
    }
    cfg->lambda = w->lambda;
    cfg->speed_prior = w->speed_prior;
    memset(csv, 0, sizeof *csv);
    csv->n = w->n_samples;
    csv->t0_s = w->t_first_s;
    csv->rate_hz = w->rate_hz;
    csv->n_channels = w->n_sensors;
    for (int k = 0; k < w->n_sensors; k++) {
        csv->channel_id[k] = w->sensor_id[k];
        csv->channel[k] = (double *)w->samples + (size_t)k * (size_t)w->n_samples;
    }
    csv->accel = csv->channel[0];
    if (cfg->solver.max_duration_s < (double)w->n_samples / w->rate_hz)
        cfg->solver.max_duration_s = (double)w->n_samples / w->rate_hz;
    rc = 0;
out:
    amfi_store_close(s);
    return rc;
}

/* The stored row and the difference of the re-weighed passage from it. */
static json_t *store_json(const options *o, const amfi_raw_rec *raw,
                          const amfi_stored_passage *sp, const char *site, double gvw_kg,
                          const double *axle_kg, int n_axles, double lambda_ref,
                          const char *position_note)
{
    const amfi_passage_row *r = &sp->row;
    json_t *ax = json_array(), *dax = json_array();
    int same = r->gvw_kg == gvw_kg;
    for (int a = 0; a < r->n_axles; a++) {
        json_array_append_new(ax, amfi_json_num(r->axle_kg[a]));
        double d = a < n_axles ? axle_kg[a] - r->axle_kg[a] : NAN;
        same &= d == 0;
        json_array_append_new(dax, amfi_json_num(d));
    }
    same &= r->n_axles == n_axles;
    char why[700];
    if (isnan(r->gvw_kg))
        snprintf(why, sizeof why, "amfid stored it as %s without a weight: %.500s", sp->status,
                 sp->reason);
    else if (same)
        snprintf(why, sizeof why,
                 "identical: the same samples, detector records and settings as amfid's");
    else if (raw->float32 && !o->lambda && !o->formulation && !position_note[0])
        snprintf(why, sizeof why,
                 "the samples were kept rounded to float32 (daemon.store.raw.precision), each "
                 "changed by at most 6e-8 of itself; amfid weighed the float64 values");
    else if (o->lambda || o->formulation)
        snprintf(why, sizeof why, "the %s given here is not the one amfid weighed it with",
                 o->lambda && o->formulation ? "lambda and formulation"
                 : o->lambda                 ? "lambda"
                                             : "formulation");
    else if (position_note[0])
        snprintf(why, sizeof why, "%s", position_note);
    else
        snprintf(why, sizeof why,
                 "the site file (%.300s) or this libamfi is not what amfid ran with: the store "
                 "records the samples, detector records, lambda policy and speed settings, not "
                 "the bridge model or the rest of solver:%s",
                 site,
                 !isnan(r->lambda) && r->lambda != lambda_ref ? " (lambda differs too)" : "");
    json_t *st = json_pack("{s:s, s:s, s:o, s:o, s:o, s:o, s:i}", "status", sp->status, "reason",
                           sp->reason, "gvw_kg", amfi_json_num(r->gvw_kg), "axle_kg", ax,
                           "lambda_ref", amfi_json_num(r->lambda), "speed_mps",
                           amfi_json_num(r->speed_mps), "n_vehicles", r->n_vehicles);
    json_t *df = json_pack("{s:o, s:o, s:o, s:s}", "gvw_kg", amfi_json_num(gvw_kg - r->gvw_kg),
                           "gvw_rel",
                           amfi_json_num(r->gvw_kg != 0 ? (gvw_kg - r->gvw_kg) / r->gvw_kg : NAN),
                           "axle_kg", dax, "explained", why);
    json_t *fs = json_pack("{s:s, s:I, s:I, s:i, s:I, s:s, s:s}", "db", o->store, "passage_id",
                           (json_int_t)o->passage_id, "window_id", (json_int_t)raw->window_id,
                           "vehicle", raw->vehicle, "raw_bytes", (json_int_t)raw->bytes,
                           "precision", raw->float32 ? "float32" : "float64", "config", site);
    return json_pack("{s:o, s:o, s:o, s:o}", "from_store", fs, "passage_gvw_kg",
                     amfi_json_num(gvw_kg), "stored", st, "difference", df);
}

int main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return EXIT_USAGE;
    amfi_set_blas_threads(1); /* small matrices: threads only spin */

    static amfi_site_config cfg; /* large; zeroed */
    char site[4096];
    if (load_config(&o, &cfg, site, sizeof site) != 0)
        return EXIT_DATA;
    static amfi_raw_rec raw;
    static amfi_stored_passage stored;
    accel_csv csv = {0};
    char from[4200] = "";
    if (o.store && load_from_store(&o, &cfg, &raw, &stored, &csv, from, sizeof from) != 0) {
        amfi_store_raw_free(&raw);
        return EXIT_DATA;
    }
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
    if (o.n_vehicles > 0) {
        if (o.estimate_speed || !isnan(o.speed_sd)) {
            fprintf(stderr, PROG ": --vehicle: not with --estimate-speed or --speed-sd "
                            "(the joint solve takes the given speeds)\n");
            return EXIT_USAGE;
        }
        cfg.speed_estimate = 0; /* a configured estimate applies to one vehicle */
    }
    if (o.estimate_speed)
        cfg.speed_estimate = 1;
    if (o.speed_trace && !cfg.speed_estimate) {
        fprintf(stderr, PROG ": --speed-trace needs --estimate-speed (or solver.speed: "
                        "estimate in the configuration)\n");
        return EXIT_USAGE;
    }
    if (!isnan(o.speed_sd)) {
        if (!cfg.speed_estimate) {
            fprintf(stderr, PROG ": --speed-sd needs --estimate-speed (or solver.speed: "
                            "estimate in the configuration)\n");
            return EXIT_USAGE;
        }
        cfg.speed_prior.rel_sd = o.speed_sd;
    }
    if (cfg.speed_estimate) {
        char perr[256];
        if (amfi_speed_prior_check(&cfg.speed_prior, o.speed_mps, perr, sizeof perr) != 0) {
            fprintf(stderr, PROG ": --speed-sd: %s\n", perr);
            return EXIT_USAGE;
        }
    }

    /* the detector as commissioning found it (detector.*): true entry =
     * reported − clock offset, true speed and spacings = reported / scale,
     * as amfid corrects every vehicle (amfi_config_detector_correct) */
    if (!o.store) /* the store's records are corrected already */
        amfi_config_detector_correct(&cfg.detector, &o.entry_time_s, NULL, &o.speed_mps,
                                     o.spacing_m, o.n_spacings);
    for (int v = 0; v < o.n_vehicles && !o.store; v++)
        amfi_config_detector_correct(&cfg.detector, &o.vehicle[v].entry_s, NULL,
                              &o.vehicle[v].speed_mps, o.vehicle[v].axle_spacing_m,
                              o.vehicle[v].n_axles - 1);

    int n_axles = o.n_spacings + 1;
    /* the window, relative to entry (amfi.h: entry − pre_roll .. last exit
     * + post_roll); with --vehicle, first entry .. last exit on the file's clock */
    amfi_multi_passage mp;
    memset(&mp, 0, sizeof mp);
    amfi_passage_times win;
    double crossing_s;
    if (o.n_vehicles > 0) {
        mp.n_vehicles = o.n_vehicles;
        n_axles = 0;
        for (int v = 0; v < o.n_vehicles; v++) {
            mp.vehicle[v] = o.vehicle[v];
            n_axles += o.vehicle[v].n_axles;
        }
        win = amfi_multi_window(cfg.bridge.span_m, &mp, cfg.solver.pre_roll_s,
                                cfg.solver.post_roll_s);
        crossing_s = win.on_span_s - (win.start_s + cfg.solver.pre_roll_s);
    } else {
        win = amfi_passage_window(cfg.bridge.span_m, o.speed_mps, n_axles, o.spacing_m,
                                  cfg.solver.pre_roll_s, cfg.solver.post_roll_s);
        crossing_s = win.on_span_s;
    }
    const double win_lo = win.start_s; /* never "-0" */
    const double win_hi = win.end_s;

    if (cfg.solver.max_axles < n_axles)
        cfg.solver.max_axles = n_axles;
    /* the speed search reaches down to v·(1 − range·sd): a longer window */
    const double slowest = cfg.speed_estimate
                               ? 1.0 - cfg.speed_prior.range_sd * cfg.speed_prior.rel_sd
                               : 1.0;
    if (cfg.solver.max_duration_s < crossing_s / slowest)
        cfg.solver.max_duration_s = crossing_s / slowest;

    int status = EXIT_DATA;
    char err[512];
    amfi_bridge *bridge = NULL;
    amfi_solver *solver = NULL;

    if (!o.store && accel_csv_read(o.accel, &csv, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        goto done;
    }
    const char *data_name = o.store ? from : o.accel;
    int col[AMFI_MAX_SENSORS]; /* the CSV column of each site sensor */
    if (map_sensors(data_name, site, &cfg, &csv, col) != 0)
        goto done;
    char position_note[400] = "";
    for (int i = 0; o.store && i < cfg.solver.n_sensors; i++)
        if (cfg.solver.sensor_x_m[i] != raw.w.sensor_at_m[col[i]])
            snprintf(position_note, sizeof position_note,
                     "the site file puts sensor %d at %.6g m, amfid had it at %.6g m",
                     cfg.sensor_id[i], cfg.solver.sensor_x_m[i], raw.w.sensor_at_m[col[i]]);
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
    for (int i = 0; i < cfg.solver.n_sensors; i++)
        p.accel[i] = csv.channel[col[i]];
    p.speed_mps = o.speed_mps;
    p.n_axles = n_axles;
    for (int k = 0; k < o.n_spacings; k++)
        p.axle_spacing_m[k] = o.spacing_m[k];

    mp.n_samples = csv.n;
    mp.scan_rate_hz = csv.rate_hz;
    mp.t_first_s = csv.t0_s;
    for (int i = 0; i < cfg.solver.n_sensors; i++)
        mp.accel[i] = csv.channel[col[i]];

    amfi_result res;
    memset(&res, 0, sizeof res);
    amfi_speed_result sres;
    memset(&sres, 0, sizeof sres);
    sres.speed_mps = sres.speed_given_mps =
        o.n_vehicles > 0 ? o.vehicle[0].speed_mps : o.speed_mps;
    sres.dip = NAN;
    static amfi_multi_result mres;
    struct timespec t_a, t_b;
    clock_gettime(CLOCK_MONOTONIC, &t_a);
    int rc;
    if (o.n_vehicles > 0) {
        rc = amfi_solve_multi(solver, &mp, &cfg.lambda, &mres, err, sizeof err);
        res = mres.all;
    } else {
        rc = cfg.speed_estimate ? amfi_solve_speed(solver, &p, &cfg.lambda, &cfg.speed_prior,
                                                   &res, &sres, err, sizeof err)
                                : amfi_solve(solver, &p, &cfg.lambda, &res, err, sizeof err);
    }
    clock_gettime(CLOCK_MONOTONIC, &t_b);
    if (rc == AMFI_ERANGE) {
        double lo = o.n_vehicles > 0 ? mp.t_first_s : p.t_first_s;
        double hi = lo + (double)(csv.n - 1) / csv.rate_hz;
        fprintf(stderr,
                "%s: passage not covered: the data spans [%.6g, %.6g] s but "
                "the window needs [%.6g, %.6g] s\n",
                data_name, lo, hi, win_lo, win_hi);
        goto done;
    }
    if (rc != 0) {
        fprintf(stderr, PROG ": %s: solve failed: %s\n", data_name,
                err[0] ? err : amfi_strerror(rc));
        goto done;
    }
    if (o.forces &&
        write_forces(o.forces, &res, sres.speed_mps,
                     o.n_vehicles ? o.vehicle[0].entry_s : 0.0) != 0)
        goto done;
    if (o.lcurve && write_lcurve(o.lcurve, &res) != 0)
        goto done;
    if (o.speed_trace && write_speed_trace(o.speed_trace, &sres, &cfg.speed_prior) != 0)
        goto done;
    json_t *extra = NULL;
    if (o.store) {
        const int k = raw.vehicle; /* this passage's vehicle in the event */
        const int multi = o.n_vehicles > 0;
        extra = store_json(&o, &raw, &stored, site, multi ? mres.vehicle[k].gvw_kg : res.gvw_kg,
                           multi ? mres.vehicle[k].axle_kg : res.axle_kg,
                           multi ? mres.vehicle[k].n_axles : res.n_axles, res.lambda_ref,
                           position_note);
    }
    if (print_json(&cfg, &res, &sres, cfg.speed_estimate, o.n_vehicles ? &mres : NULL,
                   o.spacing_m, &mp, csv.rate_hz,
                   elapsed_ms(&t_a, &t_b), extra) != 0)
        goto done; /* print_json said why */
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, PROG ": stdout: %s\n", strerror(errno));
        goto done;
    }
    status = 0;
done:
    amfi_solver_destroy(solver);
    amfi_bridge_destroy(bridge);
    if (!o.store)
        accel_csv_free(&csv);
    amfi_store_raw_free(&raw);
    return status;
}
