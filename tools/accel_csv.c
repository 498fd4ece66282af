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

static int read_header(amfi_csv *r)
{
    size_t n = 0;
    const char *s = NULL;
    int rc = amfi_csv_next(r, &s, &n);
    if (rc < 0)
        return -1;
    if (rc == 0)
        return amfi_csv_fail(r, 1, NULL, "empty file (expected header 't,accel')");
    amfi_csv_strip_bom(&s, &n);
    const char *f[2];
    size_t fl[2];
    int count = amfi_csv_split(s, n, f, fl, 2);
    if (count == 2 && fl[0] == 1 && f[0][0] == 't' && fl[1] == 5
        && memcmp(f[1], "accel", 5) == 0)
        return 0;
    char q[32];
    double x;
    if (count >= 1 && amfi_csv_field_double(f[0], fl[0], &x) != AMFI_CSV_NOT_NUMBER
        && fl[0] > 0)
        return amfi_csv_fail(r, 1, NULL, "missing header (expected 't,accel', found data)");
    return amfi_csv_fail(r, 1, NULL, "bad header '%s' (expected 't,accel')",
                         amfi_csv_quote(s, n, q));
}

static int grow(double **a, double **b, size_t *cap)
{
    size_t ncap = *cap ? 2 * *cap : 4096;
    double *na = realloc(*a, ncap * sizeof **a);
    if (!na)
        return -1;
    *a = na;
    double *nb = realloc(*b, ncap * sizeof **b);
    if (!nb)
        return -1;
    *b = nb;
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
    double *t = NULL, *a = NULL;
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
        const char *f[2];
        size_t fl[2];
        int count = amfi_csv_split(line, len, f, fl, 2);
        if (count != 2) {
            amfi_csv_fail(r, lineno, NULL,
                          "%s column: expected 2 fields (t,accel), found %d",
                          count < 2 ? "missing" : "extra", count);
            goto done;
        }
        double tv, av;
        if (parse_number(r, "t", f[0], fl[0], &tv) != 0
            || parse_number(r, "accel", f[1], fl[1], &av) != 0)
            goto done;
        if (n > 0 && !(tv > t[n - 1])) {
            amfi_csv_fail(r, lineno, NULL, "t not increasing: %.10g after %.10g", tv,
                          t[n - 1]);
            goto done;
        }
        if (n == cap && grow(&t, &a, &cap) != 0) {
            amfi_csv_fail(r, lineno, NULL, "out of memory");
            goto done;
        }
        t[n] = tv;
        a[n] = av;
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
    double *shrunk = realloc(a, n * sizeof *a);
    if (shrunk)
        a = shrunk;
    out->n = (int)n;
    out->t0_s = t[0];
    out->rate_hz = rate;
    out->accel = a;
    a = NULL;
    rc = 0;
done:
    free(t);
    free(a);
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
    int rc = read_header(r) == 0 ? read_rows(r, max_rows, out) : -1;
    if (amfi_csv_close(r, rc == 0) != 0) {
        accel_csv_free(out);
        rc = -1;
    }
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
    free(c->accel);
    memset(c, 0, sizeof *c);
}
