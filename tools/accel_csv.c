/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * accel_csv.c: passage CSV reader (see accel_csv.h for the format), on the
 * common CSV line reader (common/amfi_csv.h), which cuts the lines, counts
 * them and reports gzip and binary-data problems.
 *
 * Cost: one pass, O(rows); t is kept until the uniformity check at the end
 * (it needs the mean step, known only after the last row).
 */
#include "accel_csv.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_csv.h"

static int parse_number(amfi_csv *r, const char *name, const char *s, size_t n,
                        double *v)
{
    char q[32];
    const long line = amfi_csv_lineno(r);
    switch (amfi_csv_field_double(s, n, v)) {
    case 0:
        return 0;
    case AMFI_CSV_EMPTY:
        return amfi_csv_fail(r, line, NULL, "empty field '%s'", name);
    case AMFI_CSV_NAN:
        return amfi_csv_fail(r, line, name, "NaN is not allowed");
    case AMFI_CSV_INF:
        return amfi_csv_fail(r, line, name, "infinite value '%s' is not allowed",
                             amfi_csv_quote(s, n, q));
    default:
        return amfi_csv_fail(r, line, name, "not a number: '%s'", amfi_csv_quote(s, n, q));
    }
}

#define EXPECTED "expected 't,accel' or 't,accel_ID,...'"

/* "accel_ID", ID 0 .. 255 without sign or leading zeros: the id, else −1. */
static int channel_name_id(const char *s, size_t n)
{
    if (n < 7 || n > 9 || memcmp(s, "accel_", 6) != 0)
        return -1;
    if (n > 7 && s[6] == '0')
        return -1;
    int id = 0;
    for (size_t k = 6; k < n; k++) {
        if (s[k] < '0' || s[k] > '9')
            return -1;
        id = 10 * id + (s[k] - '0');
    }
    return id <= 255 ? id : -1;
}

static int read_header(amfi_csv *r, accel_csv *out)
{
    size_t n = 0;
    const char *s = NULL;
    int rc = amfi_csv_next(r, &s, &n);
    if (rc < 0)
        return -1;
    if (rc == 0)
        return amfi_csv_fail(r, 1, NULL, "empty file (" EXPECTED ")");
    amfi_csv_strip_bom(&s, &n);
    const char *f[ACCEL_CSV_MAX_CHANNELS + 1];
    size_t fl[ACCEL_CSV_MAX_CHANNELS + 1];
    int count = amfi_csv_split(s, n, f, fl, ACCEL_CSV_MAX_CHANNELS + 1);
    char q[32];
    if (count >= 2 && fl[0] == 1 && f[0][0] == 't') {
        if (count == 2 && fl[1] == 5 && memcmp(f[1], "accel", 5) == 0) {
            out->n_channels = 1;
            out->channel_id[0] = -1;
            return 0;
        }
        if (count - 1 > ACCEL_CSV_MAX_CHANNELS)
            return amfi_csv_fail(r, 1, NULL, "%d accel columns: at most %d", count - 1,
                                 ACCEL_CSV_MAX_CHANNELS);
        for (int k = 1; k < count; k++) {
            int id = channel_name_id(f[k], fl[k]);
            if (id < 0) {
                /* 't,accel' with more columns, or a name not accel_ID */
                return amfi_csv_fail(r, 1, NULL,
                                     "bad header: column %d '%s' is not accel_ID (ID a "
                                     "sensor id, 0 .. 255) (" EXPECTED ")",
                                     k + 1, amfi_csv_quote(f[k], fl[k], q));
            }
            for (int j = 0; j < k - 1; j++)
                if (out->channel_id[j] == id)
                    return amfi_csv_fail(r, 1, NULL,
                                         "bad header: column %d repeats sensor %d (column %d)",
                                         k + 1, id, j + 2);
            out->channel_id[k - 1] = id;
        }
        out->n_channels = count - 1;
        return 0;
    }
    double x;
    if (count >= 1 && amfi_csv_field_double(f[0], fl[0], &x) != AMFI_CSV_NOT_NUMBER
        && fl[0] > 0)
        return amfi_csv_fail(r, 1, NULL, "missing header (" EXPECTED ", found data)");
    return amfi_csv_fail(r, 1, NULL, "bad header '%s' (" EXPECTED ")", amfi_csv_quote(s, n, q));
}

/* The times and the nc channels to cap rows (t: one array, a: nc arrays). */
static int grow(double **t, double **a, int nc, size_t *cap)
{
    size_t ncap = *cap ? 2 * *cap : 4096;
    double *nt = realloc(*t, ncap * sizeof **t);
    if (!nt)
        return -1;
    *t = nt;
    for (int c = 0; c < nc; c++) {
        double *na = realloc(a[c], ncap * sizeof **a);
        if (!na)
            return -1;
        a[c] = na;
    }
    *cap = ncap;
    return 0;
}

/* Rows are at lines 2 .. n+1: blank lines are allowed only at the end, so a
 * row's line is its index + 2. */
static int check_uniform(amfi_csv *r, const double *t, size_t n, double *rate)
{
    double span = t[n - 1] - t[0];
    double mean = span / (double)(n - 1);
    double tol = 1e-6 * mean + 1e-9;
    for (size_t k = 1; k < n; k++) {
        double dt = t[k] - t[k - 1];
        if (fabs(dt - mean) > tol) {
            return amfi_csv_fail(r, (long)k + 2, NULL,
                                 "non-uniform sampling: step %.10g s, mean step %.10g s",
                                 dt, mean);
        }
    }
    if (!(mean > 0) || !isfinite(1.0 / mean)) {
        return amfi_csv_fail(r, (long)n + 1, NULL, "time span %.10g s is too small", span);
    }
    *rate = 1.0 / mean;
    return 0;
}

static int read_rows(amfi_csv *r, long max_rows, accel_csv *out)
{
    const int nc = out->n_channels;
    double *t = NULL, *a[ACCEL_CSV_MAX_CHANNELS] = {NULL};
    char names[ACCEL_CSV_MAX_CHANNELS][24];
    for (int c = 0; c < nc; c++) {
        if (out->channel_id[c] < 0)
            snprintf(names[c], sizeof names[c], "accel");
        else
            snprintf(names[c], sizeof names[c], "accel_%d", out->channel_id[c]);
    }
    size_t n = 0, cap = 0;
    int rc = -1;
    for (;;) {
        size_t len = 0;
        const char *line = NULL;
        int got = amfi_csv_next_row(r, &line, &len, "empty line before the end of the data");
        if (got < 0)
            goto done;
        if (got == 0)
            break;
        const long lineno = amfi_csv_lineno(r);
        if ((long)n >= max_rows) {
            amfi_csv_fail(r, lineno, NULL, "more than %ld rows", max_rows);
            goto done;
        }
        const char *f[ACCEL_CSV_MAX_CHANNELS + 1];
        size_t fl[ACCEL_CSV_MAX_CHANNELS + 1];
        int count = amfi_csv_split(line, len, f, fl, ACCEL_CSV_MAX_CHANNELS + 1);
        if (count != nc + 1) {
            amfi_csv_fail(r, lineno, NULL, "%s column: expected %d fields (t,%s%s), found %d",
                          count < nc + 1 ? "missing" : "extra", nc + 1, names[0],
                          nc > 1 ? ",..." : "", count);
            goto done;
        }
        double tv, av[ACCEL_CSV_MAX_CHANNELS];
        if (parse_number(r, "t", f[0], fl[0], &tv) != 0)
            goto done;
        for (int c = 0; c < nc; c++)
            if (parse_number(r, names[c], f[c + 1], fl[c + 1], &av[c]) != 0)
                goto done;
        if (n > 0 && !(tv > t[n - 1])) {
            amfi_csv_fail(r, lineno, NULL, "t not increasing: %.10g after %.10g", tv,
                          t[n - 1]);
            goto done;
        }
        if (n == cap && grow(&t, a, nc, &cap) != 0) {
            amfi_csv_fail(r, lineno, NULL, "out of memory");
            goto done;
        }
        t[n] = tv;
        for (int c = 0; c < nc; c++)
            a[c][n] = av[c];
        n++;
    }
    if (n < ACCEL_CSV_MIN_ROWS) {
        amfi_csv_fail(r, amfi_csv_lineno(r), NULL, "too few samples: %zu (need at least %d)",
                      n, ACCEL_CSV_MIN_ROWS);
        goto done;
    }
    double rate = 0;
    if (check_uniform(r, t, n, &rate) != 0)
        goto done;
    for (int c = 0; c < nc; c++) {
        double *shrunk = realloc(a[c], n * sizeof *a[c]);
        if (shrunk)
            a[c] = shrunk;
        out->channel[c] = a[c];
        a[c] = NULL;
    }
    out->n = (int)n;
    out->t0_s = t[0];
    out->rate_hz = rate;
    out->accel = out->channel[0];
    rc = 0;
done:
    free(t);
    for (int c = 0; c < nc; c++)
        free(a[c]);
    return rc;
}

int accel_csv_read_max(const char *path, long max_rows, accel_csv *out,
                       char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (max_rows < 1 || max_rows > ACCEL_CSV_MAX_ROWS)
        max_rows = ACCEL_CSV_MAX_ROWS;
    amfi_csv *r = amfi_csv_open(path, ACCEL_CSV_MAX_LINE, err, errlen);
    if (!r)
        return -1;
    int rc = read_header(r, out) == 0 ? read_rows(r, max_rows, out) : -1;
    if (amfi_csv_close(r, rc == 0) != 0)
        rc = -1;
    if (rc != 0)
        accel_csv_free(out); /* nothing left behind, n_channels 0 */
    return rc;
}

int accel_csv_read(const char *path, accel_csv *out, char *err, size_t errlen)
{
    return accel_csv_read_max(path, ACCEL_CSV_MAX_ROWS, out, err, errlen);
}

void accel_csv_free(accel_csv *c)
{
    if (!c)
        return;
    for (int k = 0; k < c->n_channels && k < ACCEL_CSV_MAX_CHANNELS; k++)
        free(c->channel[k]);
    memset(c, 0, sizeof *c);
}
