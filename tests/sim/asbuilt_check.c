/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * asbuilt_check: measurements for tests/sim_asbuilt.sh.
 *
 *   asbuilt_check f1 DESIGN.yaml [AS_BUILT.yaml]
 *       the first natural frequency of the bridge (the design's, or the
 *       as-built one), Hz, %.6f, from libamfi
 *   asbuilt_check freq FILE.csv COLUMN FROM_S LO_HZ HI_HZ
 *       the frequency of the strongest spectral peak in [LO, HI] Hz of a
 *       record's column (1 = the first after t) from FROM_S to its end: the
 *       maximum of the Hann-windowed discrete-time Fourier transform, on a
 *       0.01 Hz grid and refined by golden section to 1e-6 Hz; %.6f
 *   asbuilt_check welch FILE.csv COLUMN SEG_S LO_HZ HI_HZ
 *       the same peak of Welch's average of the Hann-windowed transforms of
 *       SEG_S-long pieces overlapping by half (an ambient record)
 *   asbuilt_check keys
 *       every key of an as-built file, one path a line (amfi_config_as_built_keys)
 *   asbuilt_check log LOG
 *       the vehicle_t and truth_t of an LCM log, one line each:
 *       "V ID UTIME SPEED SPACING1" and "T ID UTIME SPEED"
 *
 * Exit status 0, 1 on any failure (a message on stderr).
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi/amfi.h"
#include "amfi_as_built.h"
#include "amfi_config.h"
#include "amfi_messages.h"

static int f1(const char *design, const char *as_built)
{
    static amfi_site_config c;
    static amfi_as_built a;
    char err[512];
    amfi_bridge *b = NULL;
    if (amfi_config_load(design, &c, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    amfi_config_as_built_from_design(&c, &a);
    if (as_built && amfi_config_as_built_load(as_built, &c, &a, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (amfi_bridge_create(&a.site.bridge, &b, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    printf("%.6f\n", amfi_bridge_omega(b)[0] / (2.0 * 3.14159265358979323846));
    amfi_bridge_destroy(b);
    return 0;
}

typedef struct rec {
    double *x;
    int n;
    double dt;
} rec;

/* |Σ hann_k x_k e^{−iωk·dt}|², the rotation by recurrence (renormalised). */
static double power(const rec *r, double f)
{
    const double w = 2.0 * 3.14159265358979323846 * f * r->dt;
    const double cw = cos(w), sw = sin(w), dh = 2.0 * 3.14159265358979323846 / (r->n - 1);
    const double ch = cos(dh), sh = sin(dh);
    double re = 0.0, im = 0.0, c = 1.0, s = 0.0, hc = 1.0, hs = 0.0;
    for (int k = 0; k < r->n; k++) {
        const double hann = 0.5 - 0.5 * hc;
        re += hann * r->x[k] * c;
        im -= hann * r->x[k] * s;
        const double c1 = c * cw - s * sw, s1 = s * cw + c * sw;
        const double h1 = hc * ch - hs * sh, g1 = hs * ch + hc * sh;
        c = c1;
        s = s1;
        hc = h1;
        hs = g1;
        if ((k & 1023) == 1023) {
            const double m = 1.0 / sqrt(c * c + s * s), mh = 1.0 / sqrt(hc * hc + hs * hs);
            c *= m;
            s *= m;
            hc *= mh;
            hs *= mh;
        }
    }
    return re * re + im * im;
}

/* Welch: the mean power of the pieces of seg samples, half overlapping. */
static int welch_seg;
static double welch(const rec *r, double f)
{
    double sum = 0.0;
    int k = 0;
    for (int s = 0; s + welch_seg <= r->n; s += welch_seg / 2, k++) {
        rec piece = {r->x + s, welch_seg, r->dt};
        sum += power(&piece, f);
    }
    return k ? sum / k : 0.0;
}

static int freq(const char *path, int col, double from, double lo, double hi, double seg_s)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    rec r = {NULL, 0, 0.0};
    int cap = 0;
    double t_prev = NAN, t0 = NAN;
    if (!f || !fgets(line, sizeof line, f)) {
        fprintf(stderr, "asbuilt_check: %s: cannot read\n", path);
        return 1;
    }
    while (fgets(line, sizeof line, f)) {
        char *p = line, *end;
        double t = strtod(p, &end);
        for (int c = 0; c < col; c++) {
            p = strchr(end, ',');
            if (!p) {
                fprintf(stderr, "asbuilt_check: %s: no column %d\n", path, col);
                return 1;
            }
            strtod(p + 1, &end);
        }
        double v = strtod(p + 1, NULL);
        if (isnan(t0))
            t0 = t;
        else if (isnan(t_prev) == 0)
            r.dt = t - t_prev;
        t_prev = t;
        if (t < from)
            continue;
        if (r.n == cap) {
            cap = cap ? 2 * cap : 4096;
            r.x = realloc(r.x, sizeof(double) * (size_t)cap);
            if (!r.x)
                return 1;
        }
        r.x[r.n++] = v;
    }
    fclose(f);
    if (r.n < 100 || !(r.dt > 0)) {
        fprintf(stderr, "asbuilt_check: %s: %d samples after %g s\n", path, r.n, from);
        return 1;
    }
    double (*pw)(const rec *, double) = power;
    if (seg_s > 0) {
        welch_seg = (int)lround(seg_s / r.dt);
        if (welch_seg < 16 || welch_seg > r.n) {
            fprintf(stderr, "asbuilt_check: %s: pieces of %g s do not fit\n", path, seg_s);
            return 1;
        }
        pw = welch;
    }
    double best = lo, pb = -1.0;
    for (double fr = lo; fr <= hi; fr += 0.01) {
        double p = pw(&r, fr);
        if (p > pb) {
            pb = p;
            best = fr;
        }
    }
    double a = best - 0.01, b = best + 0.01;
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    while (b - a > 1e-6) {
        if (pw(&r, c) > pw(&r, d))
            b = d;
        else
            a = c;
        c = b - g * (b - a);
        d = a + g * (b - a);
    }
    printf("%.6f\n", 0.5 * (a + b));
    free(r.x);
    return 0;
}

static int logdump(const char *path)
{
    lcm_eventlog_t *in = lcm_eventlog_create(path, "r");
    lcm_eventlog_event_t *e;
    if (!in) {
        fprintf(stderr, "asbuilt_check: %s: cannot open\n", path);
        return 1;
    }
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (!strcmp(e->channel, AMFI_CHANNEL_VEHICLE)) {
            amfi_vehicle_t m;
            if (amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0)
                return 1;
            printf("V %lld %lld %.9g %.9g\n", (long long)m.vehicle_id, (long long)m.utime,
                   m.speed_mps, m.n_spacings > 0 ? m.axle_spacing_m[0] : NAN);
            amfi_vehicle_t_decode_cleanup(&m);
        } else if (!strcmp(e->channel, AMFI_CHANNEL_TRUTH)) {
            amfi_truth_t m;
            if (amfi_truth_t_decode(e->data, 0, e->datalen, &m) < 0)
                return 1;
            printf("T %lld %lld %.9g\n", (long long)m.vehicle_id, (long long)m.utime,
                   m.speed_true_mps);
            amfi_truth_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    return 0;
}

static int print_key(const char *path, const char *type, const char *range,
                     const char *dflt, int required, void *arg)
{
    (void)required;
    (void)type;
    (void)range;
    (void)dflt;
    (void)arg;
    printf("%s\n", path);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "keys"))
        return amfi_config_as_built_keys(print_key, NULL) != 0;
    if (argc >= 3 && argc <= 4 && !strcmp(argv[1], "f1"))
        return f1(argv[2], argc == 4 ? argv[3] : NULL);
    if (argc == 7 && !strcmp(argv[1], "freq"))
        return freq(argv[2], atoi(argv[3]), atof(argv[4]), atof(argv[5]), atof(argv[6]), 0.0);
    if (argc == 7 && !strcmp(argv[1], "welch"))
        return freq(argv[2], atoi(argv[3]), 0.0, atof(argv[5]), atof(argv[6]), atof(argv[4]));
    if (argc == 3 && !strcmp(argv[1], "log"))
        return logdump(argv[2]);
    fprintf(stderr, "usage: asbuilt_check f1 DESIGN [AS_BUILT] | freq FILE COL FROM LO HI | "
                    "welch FILE COL SEG LO HI | keys | log LOG\n");
    return 1;
}
