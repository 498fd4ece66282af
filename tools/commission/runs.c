/* SPDX-License-Identifier: GPL-3.0-or-later */
/* runs.c: RUNS.csv and the runs' acceleration files (commission.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel_csv.h"
#include "amfi_csv.h"
#include "commission.h"

#define MIN_SPEED_MPS 0.5
#define MAX_SPEED_MPS 60.0
#define MAX_SPACING_M 30.0
#define MIN_AXLE_KG 100.0
#define MAX_AXLE_KG 40000.0
#define PRE_S 0.3  /* data needed before entry */
#define POST_S 0.5 /* and after the last axle leaves */

void cm_runs_free(cm_runs *r)
{
    if (!r)
        return;
    for (int i = 0; i < r->n; i++)
        for (int s = 0; s < AMFI_MAX_SENSORS; s++) {
            free(r->run[i].accel[s]);
            r->run[i].accel[s] = NULL;
        }
    r->n = 0;
}

/* A ';'-separated list of numbers in field f[0 .. n): count, or −1 with the
 * problem in why. */
static int parse_list(const char *f, size_t n, double *out, int max, double lo, double hi,
                      char *why, size_t whylen)
{
    int k = 0;
    size_t i = 0;
    if (n == 0) {
        snprintf(why, whylen, "empty");
        return -1;
    }
    while (i <= n) {
        size_t j = i;
        while (j < n && f[j] != ';')
            j++;
        if (k == max) {
            snprintf(why, whylen, "more than %d values", max);
            return -1;
        }
        double v;
        char q[32];
        if (amfi_csv_field_double(f + i, j - i, &v) != 0) {
            snprintf(why, whylen, "'%s' is not a number", amfi_csv_quote(f + i, j - i, q));
            return -1;
        }
        if (!(v >= lo && v <= hi)) {
            snprintf(why, whylen, "%g is outside [%g, %g]", v, lo, hi);
            return -1;
        }
        out[k++] = v;
        i = j + 1;
    }
    return k;
}

/* The run's file, relative to the folder of RUNS.csv. */
static void resolve(const char *runs_path, const char *file, char *out, size_t outlen)
{
    const char *slash = strrchr(runs_path, '/');
    if (file[0] == '/' || !slash)
        snprintf(out, outlen, "%s", file);
    else
        snprintf(out, outlen, "%.*s/%s", (int)(slash - runs_path), runs_path, file);
}

static void add_id(char *list, size_t len, const char *prefix, int id)
{
    size_t used = strlen(list);
    if (used < len)
        snprintf(list + used, len - used, "%s%s%d", used ? ", " : "", prefix, id);
}

/* The column of each site sensor in a run file: 't,accel' is the sensor of
 * a one-sensor site; otherwise every sensor needs its column 'accel_ID' and
 * every column its sensor (as amfi-solve reads them). 0, or −1 with the
 * problem in why. */
static int map_channels(const amfi_site_config *site, const accel_csv *c, int *col, char *why,
                        size_t whylen)
{
    const int ns = site->solver.n_sensors;
    char ids[128] = "", missing[128] = "", unknown[160] = "";
    for (int i = 0; i < ns; i++)
        add_id(ids, sizeof ids, "", site->sensor_id[i]);
    if (c->channel_id[0] < 0) { /* 't,accel' */
        if (ns == 1) {
            col[0] = 0;
            return 0;
        }
        snprintf(why, whylen,
                 "one column 't,accel', but the site has %d sensors (ids %s): give each its "
                 "column, 't,accel_ID,...'",
                 ns, ids);
        return -1;
    }
    for (int k = 0; k < c->n_channels; k++) {
        int i = 0;
        while (i < ns && site->sensor_id[i] != c->channel_id[k])
            i++;
        if (i == ns)
            add_id(unknown, sizeof unknown, "accel_", c->channel_id[k]);
    }
    for (int i = 0; i < ns; i++) {
        int k = 0;
        while (k < c->n_channels && c->channel_id[k] != site->sensor_id[i])
            k++;
        if (k == c->n_channels)
            add_id(missing, sizeof missing, "", site->sensor_id[i]);
        col[i] = k;
    }
    if (!missing[0] && !unknown[0])
        return 0;
    snprintf(why, whylen, "the site has sensors %s:%s%s%s%s%s", ids,
             missing[0] ? " no column for sensor(s) " : "", missing,
             missing[0] && unknown[0] ? ";" : "",
             unknown[0] ? " column(s) of no sensor of the site: " : "", unknown);
    return -1;
}

int cm_runs_read(const char *path, const amfi_site_config *site, cm_runs *out, char *err,
                 size_t errlen)
{
    memset(out, 0, sizeof *out);
    amfi_csv *r = amfi_csv_open(path, AMFI_CSV_MAX_LINE, err, errlen);
    if (!r)
        return -1;
    static const char *const header[5] = {"file", "speed_mps", "axle_spacings_m",
                                          "entry_time_s", "axle_kg"};
    const char *line, *f[6];
    size_t len, fl[6];
    int got = amfi_csv_next(r, &line, &len);
    if (got <= 0) {
        if (got == 0)
            amfi_csv_fail(r, 0, NULL, "empty file: expected the header "
                                      "file,speed_mps,axle_spacings_m,entry_time_s,axle_kg");
        goto fail;
    }
    amfi_csv_strip_bom(&line, &len);
    int nf = amfi_csv_split(line, len, f, fl, 6), ok = nf == 5;
    for (int i = 0; ok && i < 5; i++)
        ok = fl[i] == strlen(header[i]) && memcmp(f[i], header[i], fl[i]) == 0;
    if (!ok) {
        amfi_csv_fail(r, 1, NULL,
                      "the header must be file,speed_mps,axle_spacings_m,entry_time_s,axle_kg");
        goto fail;
    }
    const double span = site->bridge.span_m;
    for (;;) {
        got = amfi_csv_next_row(r, &line, &len, "empty line before the end of the runs");
        if (got < 0)
            goto fail;
        if (got == 0)
            break;
        long ln = amfi_csv_lineno(r);
        if (out->n == CM_MAX_RUNS) {
            amfi_csv_fail(r, ln, NULL, "more than %d runs", CM_MAX_RUNS);
            goto fail;
        }
        nf = amfi_csv_split(line, len, f, fl, 6);
        if (nf != 5) {
            amfi_csv_fail(r, ln, NULL, "%d fields, expected 5 (%s,...)", nf, header[0]);
            goto fail;
        }
        cm_run *run = &out->run[out->n];
        memset(run, 0, sizeof *run);
        run->line = ln;
        if (fl[0] == 0 || fl[0] >= sizeof run->file) {
            amfi_csv_fail(r, ln, "file", fl[0] ? "name too long" : "empty");
            goto fail;
        }
        memcpy(run->file, f[0], fl[0]);
        char why[160], q[32];
        if (amfi_csv_field_double(f[1], fl[1], &run->speed_mps) != 0 ||
            !(run->speed_mps >= MIN_SPEED_MPS && run->speed_mps <= MAX_SPEED_MPS)) {
            amfi_csv_fail(r, ln, "speed_mps", "'%s' is not a speed in [%g, %g] m/s",
                          amfi_csv_quote(f[1], fl[1], q), MIN_SPEED_MPS, MAX_SPEED_MPS);
            goto fail;
        }
        run->speed_ref_mps = run->speed_mps;
        int ns = 0;
        if (fl[2] > 0 && !(fl[2] == 1 && f[2][0] == '-')) {
            ns = parse_list(f[2], fl[2], run->spacing_m, AMFI_MAX_AXLES - 1, 0.3, MAX_SPACING_M,
                            why, sizeof why);
            if (ns < 0) {
                amfi_csv_fail(r, ln, "axle_spacings_m", "%s", why);
                goto fail;
            }
        }
        run->n_axles = ns + 1;
        if (amfi_csv_field_double(f[3], fl[3], &run->entry_s) != 0 || !isfinite(run->entry_s)) {
            amfi_csv_fail(r, ln, "entry_time_s", "'%s' is not a number",
                          amfi_csv_quote(f[3], fl[3], q));
            goto fail;
        }
        int na = parse_list(f[4], fl[4], run->axle_kg, AMFI_MAX_AXLES, MIN_AXLE_KG, MAX_AXLE_KG,
                            why, sizeof why);
        if (na < 0) {
            amfi_csv_fail(r, ln, "axle_kg", "%s", why);
            goto fail;
        }
        if (na != run->n_axles) {
            amfi_csv_fail(r, ln, "axle_kg",
                          "%d loads for %d axles (axle_spacings_m gives %d spacing%s)", na,
                          run->n_axles, ns, ns == 1 ? "" : "s");
            goto fail;
        }
        if (run->n_axles > site->solver.max_axles && run->n_axles > AMFI_MAX_AXLES) {
            amfi_csv_fail(r, ln, "axle_kg", "%d axles, at most %d", run->n_axles,
                          AMFI_MAX_AXLES);
            goto fail;
        }
        for (int a = 0; a < run->n_axles; a++)
            run->gvw_kg += run->axle_kg[a];
        /* the samples */
        char full[1024], aerr[600];
        resolve(path, run->file, full, sizeof full);
        accel_csv c = {0};
        if (accel_csv_read(full, &c, aerr, sizeof aerr) != 0) {
            amfi_csv_fail(r, ln, "file", "%s", aerr);
            goto fail;
        }
        int col[AMFI_MAX_SENSORS];
        if (map_channels(site, &c, col, aerr, sizeof aerr) != 0) {
            accel_csv_free(&c);
            amfi_csv_fail(r, ln, "file", "%s:1: %s", full, aerr);
            goto fail;
        }
        run->n_samples = c.n;
        run->rate_hz = c.rate_hz;
        run->t0_s = c.t0_s;
        /* the site's sensors take their columns; the others are freed */
        for (int i = 0; i < site->solver.n_sensors; i++) {
            run->accel[i] = c.channel[col[i]];
            c.channel[col[i]] = NULL;
        }
        accel_csv_free(&c);
        out->n++;
        amfi_passage_times w =
            amfi_passage_window(span, run->speed_mps, run->n_axles, run->spacing_m, PRE_S, POST_S);
        double t_end = run->t0_s + (run->n_samples - 1) / run->rate_hz;
        if (run->entry_s + w.start_s < run->t0_s || run->entry_s + w.end_s > t_end) {
            amfi_csv_fail(r, ln, "entry_time_s",
                          "the run (%.3f .. %.3f s on the file's clock: %.1f s before entry, "
                          "%.1f s after the last axle leaves) is not inside %s (%.3f .. %.3f s)",
                          run->entry_s + w.start_s, run->entry_s + w.end_s, PRE_S, POST_S,
                          run->file, run->t0_s, t_end);
            goto fail;
        }
    }
    if (amfi_csv_close(r, 1) != 0) {
        cm_runs_free(out);
        return -1;
    }
    if (out->n < CM_MIN_RUNS) {
        snprintf(err, errlen, "%s: %d run%s; commissioning needs at least %d (COST 323 "
                 "practice: about ten runs of each calibration truck)",
                 path, out->n, out->n == 1 ? "" : "s", CM_MIN_RUNS);
        cm_runs_free(out);
        return -1;
    }
    return 0;
fail:
    amfi_csv_close(r, 0);
    cm_runs_free(out);
    return -1;
}
