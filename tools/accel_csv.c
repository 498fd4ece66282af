/*
 * accel_csv.c: passage CSV reader (see accel_csv.h for the format).
 *
 * Lines are cut from gzread() chunks by hand rather than with gzgets(): that
 * way a NUL byte inside a line is seen (gzgets would end the string there and
 * hide the rest), and the length limit is exact. zlib reads plain files
 * transparently; for gzip data it reports a corrupt stream through gzread()
 * returning −1 and a truncated one through Z_BUF_ERROR ("unexpected end of
 * file"), which zlib treats as non-fatal so that growing files can be
 * followed: we check it after every read and again at gzclose().
 *
 * Cost: one pass, O(rows); t is kept until the uniformity check at the end
 * (it needs the mean step, known only after the last row).
 */
#include "accel_csv.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#define CHUNK (64u * 1024u) /* gzread block, bytes */

typedef struct reader {
    gzFile f;
    const char *path;
    long lineno;       /* line of the last line returned, 1-based */
    size_t pos, len;   /* unread bytes are buf[pos .. len) */
    int at_eof;        /* gzread returned 0 */
    char *err;
    size_t errlen;
    unsigned char buf[CHUNK];
    char line[ACCEL_CSV_MAX_LINE + 2]; /* + one CR + NUL */
} reader;

static void fail(reader *r, long line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void fail(reader *r, long line, const char *fmt, ...)
{
    if (!r->err || r->errlen == 0)
        return;
    int k = line > 0 ? snprintf(r->err, r->errlen, "%s:%ld: ", r->path, line)
                     : snprintf(r->err, r->errlen, "%s: ", r->path);
    if (k < 0 || (size_t)k >= r->errlen)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->err + k, r->errlen - (size_t)k, fmt, ap);
    va_end(ap);
}

/* Copy at most 24 characters of s[0 .. n) into out, replacing anything that
 * is not printable ASCII (and the quote) by '?', so that a message stays one
 * readable line whatever the input. */
static const char *quote(const char *s, size_t n, char out[32])
{
    size_t k = 0;
    for (; k < n && k < 24; k++) {
        unsigned char c = (unsigned char)s[k];
        out[k] = (c >= 0x20 && c < 0x7f && c != '\'') ? (char)c : '?';
    }
    if (k < n) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = '\0';
    return out;
}

/* zlib's state after a read: 0 if fine, −1 (message written) if the stream
 * is corrupt, unreadable or ended early. `line` is the line being read. */
static int check_gz(reader *r, long line)
{
    int errnum = Z_OK;
    const char *msg = gzerror(r->f, &errnum);
    if (errnum == Z_OK)
        return 0;
    if (errnum == Z_BUF_ERROR)
        fail(r, line, "truncated gzip data (unexpected end of file)");
    else if (errnum == Z_ERRNO)
        fail(r, line, "read error: %s", strerror(errno));
    else {
        /* zlib's message is "PATH: problem"; we print the path already */
        size_t n = strlen(r->path);
        if (msg && strncmp(msg, r->path, n) == 0 && strncmp(msg + n, ": ", 2) == 0)
            msg += n + 2;
        fail(r, line, "corrupt gzip data: %s", msg ? msg : "unknown error");
    }
    return -1;
}

/* Next line into r->line (NUL-terminated, without CR/LF), length in *n.
 * Returns 1 for a line, 0 at the end of the file, −1 on error. */
static int next_line(reader *r, size_t *n)
{
    const long line = r->lineno + 1;
    size_t len = 0;
    int got_any = 0;
    for (;;) {
        if (r->pos == r->len) {
            if (r->at_eof)
                break;
            int k = gzread(r->f, r->buf, CHUNK);
            if (check_gz(r, line) != 0)
                return -1;
            if (k < 0) { /* not expected without an error state */
                fail(r, line, "read error");
                return -1;
            }
            if (k == 0) {
                r->at_eof = 1;
                break;
            }
            r->pos = 0;
            r->len = (size_t)k;
        }
        got_any = 1;
        const unsigned char *p = r->buf + r->pos;
        size_t avail = r->len - r->pos;
        const unsigned char *nl = memchr(p, '\n', avail);
        size_t take = nl ? (size_t)(nl - p) : avail;
        /* room for ACCEL_CSV_MAX_LINE characters plus a CR before the LF */
        if (take > ACCEL_CSV_MAX_LINE + 1 - len) {
            fail(r, line, "line longer than %d characters",
                 ACCEL_CSV_MAX_LINE);
            return -1;
        }
        memcpy(r->line + len, p, take);
        len += take;
        r->pos += take + (nl ? 1 : 0);
        if (nl)
            break;
    }
    if (!got_any)
        return 0;
    r->lineno = line;
    if (len > 0 && r->line[len - 1] == '\r')
        len--;
    if (len > ACCEL_CSV_MAX_LINE) {
        fail(r, line, "line longer than %d characters", ACCEL_CSV_MAX_LINE);
        return -1;
    }
    r->line[len] = '\0';
    if (memchr(r->line, '\0', len)) {
        fail(r, line, "NUL byte in line (binary data?)");
        return -1;
    }
    *n = len;
    return 1;
}

static int is_blank(int c) { return c == ' ' || c == '\t'; }

/* Split s[0 .. n) at commas into at most `max` trimmed fields (start, len).
 * Returns the number of fields found (which may exceed max; only the first
 * max are stored). */
static int split(const char *s, size_t n, const char *start[], size_t flen[],
                 int max)
{
    int count = 0;
    size_t a = 0;
    for (;;) {
        size_t b = a;
        while (b < n && s[b] != ',')
            b++;
        size_t x = a, y = b;
        while (x < y && is_blank((unsigned char)s[x]))
            x++;
        while (y > x && is_blank((unsigned char)s[y - 1]))
            y--;
        if (count < max) {
            start[count] = s + x;
            flen[count] = y - x;
        }
        count++;
        if (b == n)
            return count;
        a = b + 1;
    }
}

static int parse_number(reader *r, const char *name, const char *s, size_t n,
                        double *v)
{
    char q[32];
    if (n == 0) {
        fail(r, r->lineno, "empty field '%s'", name);
        return -1;
    }
    /* the field is NUL-terminated in a copy so that strtod cannot run on
     * into the next field */
    char tmp[ACCEL_CSV_MAX_LINE + 1];
    memcpy(tmp, s, n);
    tmp[n] = '\0';
    char *end = NULL;
    errno = 0;
    double x = strtod(tmp, &end);
    if (end == tmp || *end != '\0') {
        fail(r, r->lineno, "%s: not a number: '%s'", name, quote(s, n, q));
        return -1;
    }
    if (isnan(x)) {
        fail(r, r->lineno, "%s: NaN is not allowed", name);
        return -1;
    }
    if (isinf(x)) {
        fail(r, r->lineno, "%s: infinite value '%s' is not allowed", name,
             quote(s, n, q));
        return -1;
    }
    *v = x;
    return 0;
}

static int read_header(reader *r)
{
    size_t n = 0;
    int rc = next_line(r, &n);
    if (rc < 0)
        return -1;
    if (rc == 0) {
        fail(r, 1, "empty file (expected header 't,accel')");
        return -1;
    }
    const char *s = r->line;
    if (n >= 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0) {
        s += 3;
        n -= 3;
    }
    const char *f[2];
    size_t fl[2];
    int count = split(s, n, f, fl, 2);
    if (count == 2 && fl[0] == 1 && f[0][0] == 't' && fl[1] == 5
        && memcmp(f[1], "accel", 5) == 0)
        return 0;
    char q[32];
    char *end = NULL;
    if (count >= 1 && fl[0] > 0) {
        char tmp[ACCEL_CSV_MAX_LINE + 1];
        memcpy(tmp, f[0], fl[0]);
        tmp[fl[0]] = '\0';
        strtod(tmp, &end);
        if (end != tmp && *end == '\0') {
            fail(r, 1, "missing header (expected 't,accel', found data)");
            return -1;
        }
    }
    fail(r, 1, "bad header '%s' (expected 't,accel')", quote(s, n, q));
    return -1;
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
static int check_uniform(reader *r, const double *t, size_t n, double *rate)
{
    double span = t[n - 1] - t[0];
    double mean = span / (double)(n - 1);
    double tol = 1e-6 * mean + 1e-9;
    for (size_t k = 1; k < n; k++) {
        double dt = t[k] - t[k - 1];
        if (fabs(dt - mean) > tol) {
            fail(r, (long)k + 2,
                 "non-uniform sampling: step %.10g s, mean step %.10g s",
                 dt, mean);
            return -1;
        }
    }
    if (!(mean > 0) || !isfinite(1.0 / mean)) {
        fail(r, (long)n + 1, "time span %.10g s is too small", span);
        return -1;
    }
    *rate = 1.0 / mean;
    return 0;
}

static int read_rows(reader *r, long max_rows, accel_csv *out)
{
    double *t = NULL, *a = NULL;
    size_t n = 0, cap = 0;
    long blank_line = 0; /* first blank line seen, 0 if none */
    int rc = -1;
    for (;;) {
        size_t len = 0;
        int got = next_line(r, &len);
        if (got < 0)
            goto done;
        if (got == 0)
            break;
        const char *f[2];
        size_t fl[2];
        size_t k = 0;
        while (k < len && is_blank((unsigned char)r->line[k]))
            k++;
        if (k == len) {
            if (!blank_line)
                blank_line = r->lineno;
            continue;
        }
        if (blank_line) {
            fail(r, blank_line, "empty line before the end of the data");
            goto done;
        }
        if ((long)n >= max_rows) {
            fail(r, r->lineno, "more than %ld rows", max_rows);
            goto done;
        }
        int count = split(r->line, len, f, fl, 2);
        if (count < 2) {
            fail(r, r->lineno, "missing column: expected 2 fields (t,accel), "
                 "found %d", count);
            goto done;
        }
        if (count > 2) {
            fail(r, r->lineno, "extra column: expected 2 fields (t,accel), "
                 "found %d", count);
            goto done;
        }
        double tv, av;
        if (parse_number(r, "t", f[0], fl[0], &tv) != 0
            || parse_number(r, "accel", f[1], fl[1], &av) != 0)
            goto done;
        if (n > 0 && !(tv > t[n - 1])) {
            fail(r, r->lineno, "t not increasing: %.10g after %.10g", tv,
                 t[n - 1]);
            goto done;
        }
        if (n == cap && grow(&t, &a, &cap) != 0) {
            fail(r, r->lineno, "out of memory");
            goto done;
        }
        t[n] = tv;
        a[n] = av;
        n++;
    }
    if (n < ACCEL_CSV_MIN_ROWS) {
        fail(r, r->lineno, "too few samples: %zu (need at least %d)", n,
             ACCEL_CSV_MIN_ROWS);
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

static int ends_with_gz(const char *path)
{
    size_t n = strlen(path);
    return n >= 3 && (strcmp(path + n - 3, ".gz") == 0
                      || strcmp(path + n - 3, ".GZ") == 0);
}

int accel_csv_read_max(const char *path, long max_rows, accel_csv *out,
                       char *err, size_t errlen)
{
    if (err && errlen)
        err[0] = '\0';
    memset(out, 0, sizeof *out);
    if (max_rows < 1 || max_rows > ACCEL_CSV_MAX_ROWS)
        max_rows = ACCEL_CSV_MAX_ROWS;
    reader *r = calloc(1, sizeof *r);
    if (!r) {
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    r->path = path;
    r->err = err;
    r->errlen = errlen;
    int rc = -1;
    errno = 0;
    r->f = gzopen(path, "rb");
    if (!r->f) {
        /* errno 0 means zlib itself could not allocate */
        fail(r, 0, "cannot open: %s", errno ? strerror(errno) : "out of memory");
        goto done;
    }
    /* right after gzopen, gzdirect() reads the start of the file to decide */
    if (ends_with_gz(path) && gzdirect(r->f)) {
        if (check_gz(r, 1) == 0)
            fail(r, 1, "not in gzip format (the name ends in .gz)");
        goto done;
    }
    if (read_header(r) != 0)
        goto done;
    rc = read_rows(r, max_rows, out);
done:
    if (r->f) {
        int zrc = gzclose(r->f);
        if (rc == 0 && zrc != Z_OK) {
            if (zrc == Z_BUF_ERROR)
                fail(r, r->lineno, "truncated gzip data (unexpected end of file)");
            else
                fail(r, r->lineno, "error closing the file (zlib %d)", zrc);
            accel_csv_free(out);
            rc = -1;
        }
    }
    free(r);
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
