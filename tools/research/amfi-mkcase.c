/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-mkcase: write a synthetic passage CSV from known moving forces.
 *
 *   amfi-mkcase --out FILE.csv[.gz] [--config FILE.yaml] [--speed MPS]
 *               [--axle-loads-kg W1,W2,...] [--axle-spacing S1,...]
 *               [--scan-rate HZ] [--pre SEC] [--post SEC] [--noise FRACTION]
 *               [--vary FRACTION] [--vary-hz HZ] [--damage FRACTION] [--seed N]
 *
 * The bridge (from the configuration, with --damage applied) carries point
 * forces W_a·g·(1 + vary·sin(2π·vary_hz·t + 1.3a)) moving at --speed; its
 * response at the site's sensors comes from the Newmark integrator of libamfi (the
 * tests' independent reference, dt = 20 µs), sampled at --scan-rate, with
 * --pre seconds of rest before the first axle enters (t = --pre in the file)
 * and --post seconds after the last one leaves, plus Gaussian noise of
 * --noise × each sensor's signal RMS (GSL, Mersenne Twister, --seed).
 * A site of one sensor gives 't,accel'; of several, a column per sensor
 * named by its id, 't,accel_ID,...' (tools/accel_csv.h), in the site
 * file's order.
 * This is not vehicle-bridge interaction: the forces are prescribed. The
 * simulator (sim_publisher) models vehicles.
 *
 * stdout: one JSON line with the truth: entry time, true mean force of each
 * axle while on the span, true GVW.
 */
#include <errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "amfi/amfi.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_json.h"

#define PROG "amfi-mkcase"

typedef struct forces {
    int n;
    double W_N[AMFI_MAX_AXLES];
    double vary, vary_hz;
} forces;

static double force(double t, int a, void *user)
{
    const forces *f = user;
    return f->W_N[a] * (1.0 + f->vary * sin(2.0 * M_PI * f->vary_hz * t + 1.3 * a));
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s --out FILE.csv[.gz] [--config FILE.yaml] [--speed MPS]\n"
            "       [--axle-loads-kg W1,W2,...] [--axle-spacing S1,...] [--scan-rate HZ]\n"
            "       [--pre SEC] [--post SEC] [--noise FRACTION] [--vary FRACTION]\n"
            "       [--vary-hz HZ] [--damage FRACTION] [--seed N]\n"
            "  -o, --out FILE            the passage CSV (gzip when it ends in .gz)\n"
            "  -c, --config FILE         site configuration (default: built-in paper-20m)\n"
            "  -s, --speed MPS           0.5 .. 60 (default 25)\n"
            "  -w, --axle-loads-kg LIST  static axle loads, kg\n"
            "  -x, --axle-spacing LIST   axle spacings, m\n"
            "  -r, --scan-rate HZ        sampling rate (default 1000)\n"
            "      --pre SEC             rest before the first axle enters (default 0.5)\n"
            "      --post SEC            after the last axle leaves (default 0.5)\n"
            "  -n, --noise FRACTION      Gaussian noise, fraction of the RMS\n"
            "      --vary FRACTION       sinusoidal force variation\n"
            "      --vary-hz HZ          its frequency (default 2)\n"
            "  -d, --damage FRACTION     stiffness loss of the bridge\n"
            "  -S, --seed N              noise seed (default 1)\n"
            "  -h, --help                this help\n"
            "  -V, --version             print the version\n"
            "stdout: one JSON line with the truth.\n",
            PROG);
}

int main(int argc, char **argv)
{
    const char *out = NULL, *config = NULL;
    double speed = 25.0, scan = 1000.0, pre = 0.5, post = 0.5, noise = 0.0, damage = -1;
    double loads_kg[AMFI_MAX_AXLES] = {102000.0 / AMFI_GRAVITY, 74600.0 / AMFI_GRAVITY};
    double spacing[AMFI_MAX_AXLES] = {5.0};
    int n_loads = 2, n_spacing = 1;
    unsigned long seed = 1;
    forces f = {0};
    f.vary_hz = 2.0;
    enum { O_PRE = 256, O_POST, O_VARY, O_VARY_HZ };
    static const struct option longopts[] = {
        {"out", required_argument, NULL, 'o'},
        {"config", required_argument, NULL, 'c'},
        {"speed", required_argument, NULL, 's'},
        {"axle-loads-kg", required_argument, NULL, 'w'},
        {"axle-spacing", required_argument, NULL, 'x'},
        {"scan-rate", required_argument, NULL, 'r'},
        {"pre", required_argument, NULL, O_PRE},
        {"post", required_argument, NULL, O_POST},
        {"noise", required_argument, NULL, 'n'},
        {"vary", required_argument, NULL, O_VARY},
        {"vary-hz", required_argument, NULL, O_VARY_HZ},
        {"damage", required_argument, NULL, 'd'},
        {"seed", required_argument, NULL, 'S'},
        AMFI_CLI_END};
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *v = optarg;
        switch (k) {
        case 'o': out = v; break;
        case 'c': config = v; break;
        case 's': speed = amfi_cli_num(&c, v, 0.5, 60.0); break;
        case 'r': scan = amfi_cli_num(&c, v, 10.0, 1e5); break;
        case O_PRE: pre = amfi_cli_num(&c, v, 0.0, 60.0); break;
        case O_POST: post = amfi_cli_num(&c, v, 0.0, 60.0); break;
        case 'n': noise = amfi_cli_num(&c, v, 0.0, 1.0); break;
        case O_VARY: f.vary = amfi_cli_num(&c, v, 0.0, 0.9); break;
        case O_VARY_HZ: f.vary_hz = amfi_cli_num(&c, v, 0.0, 1000.0); break;
        case 'd': damage = amfi_cli_num(&c, v, 0.0, 0.99); break;
        case 'S': seed = (unsigned long)amfi_cli_num(&c, v, 0.0, 4294967295.0); break;
        case 'w': n_loads = amfi_cli_list(&c, v, loads_kg, AMFI_MAX_AXLES, 1.0, 1e5); break;
        case 'x':
            n_spacing = amfi_cli_list(&c, v, spacing, AMFI_MAX_AXLES - 1, 0.1, 30.0);
            break;
        }
    }
    if (!out) {
        fprintf(stderr, "%s: --out is required\n", PROG);
        usage(stderr);
        return 2;
    }
    if (n_spacing != n_loads - 1) {
        fprintf(stderr, "%s: %d axle loads need %d spacings, got %d\n", PROG, n_loads,
                n_loads - 1, n_spacing);
        return 2;
    }
    amfi_set_blas_threads(1);
    amfi_site_config cfg;
    char err[512];
    amfi_config_defaults(&cfg);
    if (config && amfi_config_load(config, &cfg, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (damage >= 0)
        cfg.bridge.damage = damage;
    amfi_bridge *b = NULL;
    if (amfi_bridge_create(&cfg.bridge, &b, err, sizeof err)) {
        fprintf(stderr, "%s: bridge: %s\n", PROG, err);
        return 1;
    }
    f.n = n_loads;
    double off[AMFI_MAX_AXLES] = {0.0};
    for (int a = 0; a < n_loads; a++) {
        f.W_N[a] = loads_kg[a] * AMFI_GRAVITY;
        if (a > 0)
            off[a] = off[a - 1] + spacing[a - 1];
    }
    /* the recording: pre seconds at rest, then entry .. last exit + post */
    const double L = cfg.bridge.span_m,
                 T = amfi_passage_window(L, speed, n_loads, spacing, pre, post).end_s;
    const int n_rest = (int)lround(pre * scan), n_move = (int)floor(T * scan) + 1;
    const int n = n_rest + n_move;
    const int ns = cfg.solver.n_sensors;
    double *acc = calloc((size_t)n * ns, sizeof(double)); /* n × ns, row-major */
    if (!acc) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        return 1;
    }
    /* dt = 20 µs, or the nearest step that divides the sample interval */
    double dt = 1.0 / (scan * ceil(1.0 / (scan * 2e-5)));
    if (amfi_forward_newmark(b, speed, n_loads, off, force, &f, ns, cfg.solver.sensor_x_m, dt,
                             scan, n_move, acc + (size_t)n_rest * ns, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        return 1;
    }
    if (noise > 0) {
        gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
        gsl_rng_set(rng, seed);
        for (int si = 0; si < ns; si++) {
            double rms = 0.0;
            for (int i = 0; i < n; i++)
                rms += acc[(size_t)i * ns + si] * acc[(size_t)i * ns + si];
            rms = sqrt(rms / n);
            for (int i = 0; i < n; i++)
                acc[(size_t)i * ns + si] += gsl_ran_gaussian(rng, noise * rms);
        }
        gsl_rng_free(rng);
    }
    size_t len = strlen(out);
    int gz = len > 3 && !strcmp(out + len - 3, ".gz");
    gzFile gzf = NULL;
    FILE *fp = NULL;
    if (gz)
        gzf = gzopen(out, "wb9");
    else
        fp = fopen(out, "w");
    if (!gzf && !fp) {
        fprintf(stderr, "%s: %s: cannot create: %s\n", PROG, out, strerror(errno));
        return 1;
    }
    int bad = 0;
    char line[64 + 24 * AMFI_MAX_SENSORS];
    for (int i = -1; i < n && !bad; i++) {
        int k = i < 0 ? snprintf(line, sizeof line, "t")
                      : snprintf(line, sizeof line, "%.6f", i / scan);
        for (int si = 0; si < ns; si++) {
            if (i >= 0)
                k += snprintf(line + k, sizeof line - k, ",%.9g", acc[(size_t)i * ns + si]);
            else if (ns == 1)
                k += snprintf(line + k, sizeof line - k, ",accel");
            else
                k += snprintf(line + k, sizeof line - k, ",accel_%d", cfg.sensor_id[si]);
        }
        k += snprintf(line + k, sizeof line - k, "\n");
        bad = gz ? gzwrite(gzf, line, (unsigned)k) != k : fwrite(line, 1, k, fp) != (size_t)k;
    }
    bad |= gz ? gzclose(gzf) != Z_OK : fclose(fp) != 0;
    if (bad) {
        fprintf(stderr, "%s: %s: write failed\n", PROG, out);
        return 1;
    }
    /* Truth: mean of each axle's force over the time it is on the span,
     * sampled at 5000 Hz. */
    double gvw = 0.0;
    json_t *mean = json_array();
    for (int a = 0; a < n_loads; a++) {
        double sum = 0.0;
        int cnt = 0;
        for (double t = off[a] / speed; speed * t - off[a] <= L; t += 2e-4, cnt++)
            sum += force(t, a, &f);
        json_array_append_new(mean, amfi_json_num(sum / cnt));
        gvw += sum / cnt / AMFI_GRAVITY;
    }
    json_t *truth = json_pack("{s:s, s:o, s:o, s:o, s:o, s:o, s:o, s:I}", "file", out,
                              "entry_time_s", amfi_json_num(n_rest / scan), "speed_mps",
                              amfi_json_num(speed), "mean_force_N", mean, "gvw_kg",
                              amfi_json_num(gvw), "damage", amfi_json_num(cfg.bridge.damage),
                              "noise", amfi_json_num(noise), "seed", (json_int_t)seed);
    if (amfi_json_print(stdout, truth) != 0) {
        fprintf(stderr, "%s: stdout: cannot write the truth\n", PROG);
        free(acc);
        amfi_bridge_destroy(b);
        return 1;
    }
    free(acc);
    amfi_bridge_destroy(b);
    return 0;
}
