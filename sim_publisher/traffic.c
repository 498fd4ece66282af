/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * traffic.c: WIM-style vehicle list reader (format and messages in
 * traffic.h).
 *
 * One pass: the header is mapped to column roles once, then every row is
 * cut at commas, each field parsed and range-checked where it is read, and
 * the record appended to an array that doubles when full. The lines come
 * from the common CSV line reader (common/amfi_csv.h), which also reports
 * NUL bytes, over-long lines and FILE:LINE: COLUMN: in every message.
 */
#include "traffic.h"

#include "amfi_csv.h"
#include "vclass.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_COLS (4 + 2 * AMFI_MAX_AXLES - 1) /* fixed + axles + spacings */

enum role { R_TIME, R_LANE, R_SPEED, R_GVW, R_CLASS, R_NAX, R_AXLES, R_SPACINGS, R_AXLE,
            R_SPACING };

/* the four columns of both formats, then the class format's four */
#define N_NAMED 8
static const char *const role_name[N_NAMED] = {"timestamp_s", "lane",    "speed_mps", "gvw_kg",
                                               "class",       "n_axles", "axle_kg",
                                               "spacings_m"};

typedef struct column {
    enum role role;
    int index;     /* axle or spacing number − 1 */
    char name[24]; /* as in the header */
} column;

typedef struct reader {
    amfi_csv *csv;
    int n_cols, n_axles; /* n_axles: the wide format's, 0 in the class format */
    int class_format;
    column col[MAX_COLS];
} reader;

#define fail(r, line, colname, ...) amfi_csv_fail((r)->csv, line, colname, __VA_ARGS__)
#define quote amfi_csv_quote
#define split amfi_csv_split

/* "axle12_kg" → 12 with prefix "axle", suffix "_kg"; 0 if s is not of that
 * form (digits without a leading zero, at most 4 of them). */
static int numbered(const char *s, size_t n, const char *prefix, const char *suffix)
{
    size_t lp = strlen(prefix), ls = strlen(suffix);
    if (n <= lp + ls || memcmp(s, prefix, lp) != 0 || memcmp(s + n - ls, suffix, ls) != 0)
        return 0;
    size_t nd = n - lp - ls;
    if (nd > 4 || s[lp] == '0')
        return 0;
    int v = 0;
    for (size_t i = lp; i < lp + nd; i++) {
        if (s[i] < '0' || s[i] > '9')
            return 0;
        v = 10 * v + (s[i] - '0');
    }
    return v;
}

static int read_header(reader *r)
{
    size_t n = 0;
    const char *s = NULL;
    int rc = amfi_csv_next(r->csv, &s, &n);
    if (rc < 0)
        return -1;
    if (rc == 0) {
        fail(r, 1, NULL, "empty file (expected a header: timestamp_s,lane,speed_mps,gvw_kg,"
                         "axle1_kg,axle2_kg,...,spacing1_m,...)");
        return -1;
    }
    amfi_csv_strip_bom(&s, &n);
    const char *f[MAX_COLS];
    size_t fl[MAX_COLS];
    int count = split(s, n, f, fl, MAX_COLS);
    int seen_fixed[N_NAMED] = {0};
    int axle_seen[AMFI_MAX_AXLES + 1] = {0}, spacing_seen[AMFI_MAX_AXLES + 1] = {0};
    int max_axle = 0, max_spacing = 0;
    char q[32];
    if (count > MAX_COLS) {
        fail(r, 1, NULL, "%d columns, more than the %d of a %d-axle vehicle", count, MAX_COLS,
             AMFI_MAX_AXLES);
        return -1;
    }
    for (int i = 0; i < count; i++) {
        column *c = &r->col[i];
        quote(f[i], fl[i], q);
        if (fl[i] == 0) {
            fail(r, 1, NULL, "column %d has an empty name", i + 1);
            return -1;
        }
        if (fl[i] >= sizeof c->name) {
            fail(r, 1, q, "unknown column");
            return -1;
        }
        memcpy(c->name, f[i], fl[i]);
        c->name[fl[i]] = '\0';
        int k, found = 0;
        for (k = 0; k < N_NAMED; k++)
            if (!strcmp(c->name, role_name[k])) {
                found = 1;
                break;
            }
        if (found) {
            if (seen_fixed[k]++) {
                fail(r, 1, c->name, "duplicate column");
                return -1;
            }
            c->role = (enum role)k;
            c->index = 0;
            continue;
        }
        int a = numbered(f[i], fl[i], "axle", "_kg");
        int sp = numbered(f[i], fl[i], "spacing", "_m");
        if (a > 0 || sp > 0) {
            int num = a > 0 ? a : sp;
            int lim = a > 0 ? AMFI_MAX_AXLES : AMFI_MAX_AXLES - 1;
            if (num > lim) {
                fail(r, 1, c->name, "at most %d axles (%d spacings)", AMFI_MAX_AXLES,
                     AMFI_MAX_AXLES - 1);
                return -1;
            }
            int *seen = a > 0 ? axle_seen : spacing_seen;
            if (seen[num]++) {
                fail(r, 1, c->name, "duplicate column");
                return -1;
            }
            c->role = a > 0 ? R_AXLE : R_SPACING;
            c->index = num - 1;
            if (a > 0 && a > max_axle)
                max_axle = a;
            if (sp > 0 && sp > max_spacing)
                max_spacing = sp;
            continue;
        }
        fail(r, 1, q, "unknown column (expected timestamp_s, lane, speed_mps, gvw_kg, "
                      "axle1_kg .. axleN_kg, spacing1_m .. spacingN-1_m, or class, n_axles, "
                      "axle_kg, spacings_m)");
        return -1;
    }
    for (int k = 0; k < 4; k++)
        if (!seen_fixed[k]) {
            fail(r, 1, role_name[k], "missing column");
            return -1;
        }
    int class_cols = 0;
    for (int k = 4; k < N_NAMED; k++)
        class_cols += seen_fixed[k];
    if (class_cols) {
        if (max_axle || max_spacing) {
            fail(r, 1, NULL, "numbered axle or spacing columns and the class format's columns "
                             "(class, n_axles, axle_kg, spacings_m) do not mix");
            return -1;
        }
        for (int k = 4; k < N_NAMED; k++)
            if (!seen_fixed[k]) {
                fail(r, 1, role_name[k], "missing column (the class format has class, "
                                         "n_axles, axle_kg and spacings_m)");
                return -1;
            }
        r->n_cols = count;
        r->n_axles = 0;
        r->class_format = 1;
        return 0;
    }
    for (int a = 1; a <= max_axle; a++)
        if (!axle_seen[a]) {
            fail(r, 1, NULL, "axle%d_kg missing: axle columns must be axle1_kg .. axle%d_kg",
                 a, max_axle);
            return -1;
        }
    if (max_axle < 2) {
        fail(r, 1, max_axle ? "axle1_kg" : NULL,
             "at least two axle columns needed (axle1_kg, axle2_kg)");
        return -1;
    }
    for (int s2 = 1; s2 <= max_spacing; s2++)
        if (!spacing_seen[s2]) {
            fail(r, 1, NULL,
                 "spacing%d_m missing: spacing columns must be spacing1_m .. spacing%d_m", s2,
                 max_spacing);
            return -1;
        }
    if (max_spacing != max_axle - 1) {
        if (max_spacing > max_axle - 1)
            fail(r, 1, NULL, "spacing%d_m: %d axles have %d spacings (spacing1_m .. spacing%d_m)",
                 max_spacing, max_axle, max_axle - 1, max_axle - 1);
        else
            fail(r, 1, NULL, "spacing%d_m missing: %d axles need %d spacings (spacing1_m .. "
                             "spacing%d_m)",
                 max_spacing + 1, max_axle, max_axle - 1, max_axle - 1);
        return -1;
    }
    r->n_cols = count;
    r->n_axles = max_axle;
    return 0;
}

/* Parse field s[0 .. n) of column c as a finite number. */
static int parse_number(reader *r, const column *c, const char *s, size_t n, double *v)
{
    char q[32];
    const long line = amfi_csv_lineno(r->csv);
    switch (amfi_csv_field_double(s, n, v)) {
    case 0:
        return 0;
    case AMFI_CSV_EMPTY:
        return fail(r, line, c->name, "empty value");
    case AMFI_CSV_NOT_NUMBER:
        return fail(r, line, c->name, "'%s' is not a number", quote(s, n, q));
    default:
        return fail(r, line, c->name, "'%s' is not a finite number", quote(s, n, q));
    }
}

static int in_range(reader *r, const column *c, double v, double lo, double hi, const char *unit)
{
    if (v >= lo && v <= hi)
        return 0;
    fail(r, amfi_csv_lineno(r->csv), c->name, "%g is out of range [%g, %g] %s", v, lo, hi, unit);
    return -1;
}

/* The class format's axle_kg and spacings_m (';'-separated) against
 * n_axles and the class. */
static int parse_lists(reader *r, const char *const *f, const size_t *fl, const int list_col[2],
                       amfi_vehicle_rec *v)
{
    const long line = amfi_csv_lineno(r->csv);
    const amfi_vclass *vc = amfi_vclass_get(v->vclass);
    if (v->n_axles != vc->n_axles) {
        fail(r, line, "n_axles", "%d, but class %s has %d axles", v->n_axles, vc->name,
             vc->n_axles);
        return -1;
    }
    for (int L = 0; L < 2; L++) {
        const column *c = &r->col[list_col[L]];
        const char *s = f[list_col[L]];
        const size_t n = fl[list_col[L]];
        const int want = L ? v->n_axles - 1 : v->n_axles;
        double *out = L ? v->spacing_m : v->axle_kg;
        int k = 0;
        size_t a = 0;
        for (;;) {
            size_t b = a;
            while (b < n && s[b] != ';')
                b++;
            size_t x = a, y = b;
            while (x < y && (s[x] == ' ' || s[x] == '\t'))
                x++;
            while (y > x && (s[y - 1] == ' ' || s[y - 1] == '\t'))
                y--;
            if (k == want) {
                fail(r, line, c->name, "more than %d values for %d axles", want, v->n_axles);
                return -1;
            }
            double val;
            char q[32];
            switch (amfi_csv_field_double(s + x, y - x, &val)) {
            case 0:
                break;
            case AMFI_CSV_EMPTY:
                fail(r, line, c->name, "value %d is empty", k + 1);
                return -1;
            default:
                fail(r, line, c->name, "value %d, '%s', is not a finite number", k + 1,
                     quote(s + x, y - x, q));
                return -1;
            }
            if (L ? !(val >= 0.5 && val <= 30.0) : !(val > 0.0 && val <= 30000.0)) {
                fail(r, line, c->name, L ? "value %d, %g, is out of range [0.5, 30] m"
                                         : "value %d, %g, is out of range (0, 30000] kg",
                     k + 1, val);
                return -1;
            }
            out[k++] = val;
            if (b == n)
                break;
            a = b + 1;
        }
        if (k != want) {
            fail(r, line, c->name, "%d values for %d axles (%d expected)", k, v->n_axles, want);
            return -1;
        }
    }
    char err[200];
    if (amfi_vclass_check(vc, v->n_axles, v->spacing_m, err, sizeof err)) {
        fail(r, line, "spacings_m", "%s", err);
        return -1;
    }
    return 0;
}

static int parse_row(reader *r, const char *line, size_t len, amfi_vehicle_rec *v)
{
    const char *f[MAX_COLS];
    size_t fl[MAX_COLS];
    int count = split(line, len, f, fl, MAX_COLS);
    if (count != r->n_cols) {
        fail(r, amfi_csv_lineno(r->csv), NULL, "%d fields, the header has %d", count, r->n_cols);
        return -1;
    }
    memset(v, 0, sizeof *v);
    v->n_axles = r->n_axles;
    v->line = amfi_csv_lineno(r->csv);
    v->vclass = -1;
    int list_col[2] = {-1, -1}; /* axle_kg, spacings_m: read once n_axles is known */
    for (int i = 0; i < count; i++) {
        const column *c = &r->col[i];
        double x;
        if (c->role == R_AXLES || c->role == R_SPACINGS) {
            list_col[c->role == R_SPACINGS] = i;
            continue;
        }
        if (c->role == R_CLASS) {
            char q[32];
            v->vclass = amfi_vclass_find(f[i], fl[i]);
            if (v->vclass < 0) {
                fail(r, amfi_csv_lineno(r->csv), c->name,
                     fl[i] ? "'%s' is not a known class (%s)" : "empty value%.0s%.0s",
                     quote(f[i], fl[i], q), amfi_vclass_names());
                return -1;
            }
            continue;
        }
        if (c->role == R_LANE || c->role == R_NAX) {
            char q[32], tmp[32];
            long lane = 0;
            int ok = fl[i] > 0 && fl[i] < sizeof tmp;
            if (ok) {
                memcpy(tmp, f[i], fl[i]);
                tmp[fl[i]] = '\0';
                char *end = NULL;
                errno = 0;
                lane = strtol(tmp, &end, 10);
                ok = end != tmp && *end == '\0' && errno == 0;
            }
            if (!ok) {
                fail(r, amfi_csv_lineno(r->csv), c->name, fl[i] ? "'%s' is not an integer" : "empty value%s",
                     quote(f[i], fl[i], q));
                return -1;
            }
            const int hi = c->role == R_LANE ? AMFI_TRAFFIC_MAX_LANE : AMFI_MAX_AXLES;
            const int lo = c->role == R_LANE ? 1 : 2;
            if (lane < lo || lane > hi) {
                fail(r, amfi_csv_lineno(r->csv), c->name, "%ld is out of range %d .. %d", lane,
                     lo, hi);
                return -1;
            }
            if (c->role == R_LANE)
                v->lane = (int)lane;
            else
                v->n_axles = (int)lane;
            continue;
        }
        if (parse_number(r, c, f[i], fl[i], &x) != 0)
            return -1;
        switch (c->role) {
        case R_TIME:
            v->timestamp_s = x;
            break;
        case R_SPEED:
            if (in_range(r, c, x, 1.0, 60.0, "m/s"))
                return -1;
            v->speed_mps = x;
            break;
        case R_GVW:
            if (in_range(r, c, x, 500.0, 100000.0, "kg"))
                return -1;
            v->gvw_kg = x;
            break;
        case R_AXLE:
            if (!(x > 0.0) || x > 100000.0) {
                fail(r, amfi_csv_lineno(r->csv), c->name, "%g is out of range (0, 100000] kg", x);
                return -1;
            }
            v->axle_kg[c->index] = x;
            break;
        case R_SPACING:
            if (in_range(r, c, x, 0.5, 30.0, "m"))
                return -1;
            v->spacing_m[c->index] = x;
            break;
        default:
            break;
        }
    }
    if (r->class_format) {
        if (parse_lists(r, f, fl, list_col, v) != 0)
            return -1;
    } else {
        v->vclass = amfi_vclass_guess(v->n_axles, v->spacing_m);
    }
    double sum = 0.0;
    for (int a = 0; a < v->n_axles; a++)
        sum += v->axle_kg[a];
    if (fabs(v->gvw_kg - sum) > AMFI_TRAFFIC_GVW_TOL * sum) {
        fail(r, amfi_csv_lineno(r->csv), "gvw_kg",
             "%g kg differs by %.3g %% from the sum of the axle loads, %g kg (tolerance %g %%)",
             v->gvw_kg, 100.0 * fabs(v->gvw_kg - sum) / sum, sum, 100.0 * AMFI_TRAFFIC_GVW_TOL);
        return -1;
    }
    return 0;
}

static int read_rows(reader *r, amfi_vehicle_rec **recs, int *n_out)
{
    amfi_vehicle_rec *a = NULL;
    long n = 0, cap = 0, prev_line = 0;
    for (;;) {
        size_t len = 0;
        const char *line = NULL;
        int got = amfi_csv_next_row(r->csv, &line, &len, "blank line before the end of the data");
        if (got < 0)
            goto fail;
        if (got == 0)
            break;
        if (n == AMFI_TRAFFIC_MAX_ROWS) {
            fail(r, amfi_csv_lineno(r->csv), NULL, "more than %ld vehicles", AMFI_TRAFFIC_MAX_ROWS);
            goto fail;
        }
        if (n == cap) {
            long ncap = cap ? 2 * cap : 1024;
            if (ncap > AMFI_TRAFFIC_MAX_ROWS)
                ncap = AMFI_TRAFFIC_MAX_ROWS;
            amfi_vehicle_rec *na = realloc(a, (size_t)ncap * sizeof *a);
            if (!na) {
                fail(r, amfi_csv_lineno(r->csv), NULL, "out of memory");
                free(a);
                return AMFI_ENOMEM;
            }
            a = na;
            cap = ncap;
        }
        if (parse_row(r, line, len, &a[n]) != 0)
            goto fail;
        if (n > 0 && a[n].timestamp_s < a[n - 1].timestamp_s) {
            fail(r, amfi_csv_lineno(r->csv), "timestamp_s",
                 "%.10g is earlier than %.10g on line %ld (timestamps must be non-decreasing)",
                 a[n].timestamp_s, a[n - 1].timestamp_s, prev_line);
            goto fail;
        }
        prev_line = amfi_csv_lineno(r->csv);
        n++;
    }
    if (n == 0) {
        fail(r, amfi_csv_lineno(r->csv), NULL, "no vehicles after the header");
        goto fail;
    }
    *recs = a;
    *n_out = (int)n;
    return 0;
fail:
    free(a);
    return AMFI_EINVAL;
}

int amfi_traffic_read(const char *path, amfi_vehicle_rec **recs, int *n, char *err,
                      size_t errlen)
{
    *recs = NULL;
    *n = 0;
    if (err && errlen)
        err[0] = '\0';
    reader *r = calloc(1, sizeof *r);
    if (!r) {
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return AMFI_ENOMEM;
    }
    int rc = AMFI_EINVAL;
    r->csv = amfi_csv_open(path, AMFI_TRAFFIC_MAX_LINE, err, errlen);
    if (r->csv && read_header(r) == 0)
        rc = read_rows(r, recs, n);
    amfi_csv_close(r->csv, 0);
    free(r);
    return rc;
}

void amfi_traffic_free(amfi_vehicle_rec *recs) { free(recs); }
