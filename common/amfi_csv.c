/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_csv.c: the CSV line reader (see amfi_csv.h).
 *
 * zlib reports a corrupt stream through gzread() returning −1 and a
 * truncated one through Z_BUF_ERROR ("unexpected end of file"), which zlib
 * treats as non-fatal so that growing files can be followed: it is checked
 * after every read and again at gzclose().
 */
#include "amfi_csv.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#define CHUNK (64u * 1024u) /* gzread block, bytes */

struct amfi_csv {
    gzFile f;
    const char *path;
    size_t max_line;
    long lineno;     /* line of the last line returned, 1-based */
    size_t pos, len; /* unread bytes are buf[pos .. len) */
    int at_eof;      /* gzread returned 0 */
    char *err;
    size_t errlen;
    unsigned char buf[CHUNK];
    char line[AMFI_CSV_MAX_LINE + 2]; /* + one CR + NUL */
};

int amfi_csv_fail(amfi_csv *r, long line, const char *column, const char *fmt, ...)
{
    if (!r->err || r->errlen == 0)
        return -1;
    int k = line > 0 ? snprintf(r->err, r->errlen, "%s:%ld: ", r->path, line)
                     : snprintf(r->err, r->errlen, "%s: ", r->path);
    if (k >= 0 && (size_t)k < r->errlen && column)
        k += snprintf(r->err + k, r->errlen - (size_t)k, "%s: ", column);
    if (k < 0 || (size_t)k >= r->errlen)
        return -1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->err + k, r->errlen - (size_t)k, fmt, ap);
    va_end(ap);
    return -1;
}

const char *amfi_csv_quote(const char *s, size_t n, char out[32])
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
static int check_gz(amfi_csv *r, long line)
{
    int errnum = Z_OK;
    const char *msg = gzerror(r->f, &errnum);
    if (errnum == Z_OK)
        return 0;
    if (errnum == Z_BUF_ERROR)
        amfi_csv_fail(r, line, NULL, "truncated gzip data (unexpected end of file)");
    else if (errnum == Z_ERRNO)
        amfi_csv_fail(r, line, NULL, "read error: %s", strerror(errno));
    else {
        /* zlib's message is "PATH: problem"; we print the path already */
        size_t n = strlen(r->path);
        if (msg && strncmp(msg, r->path, n) == 0 && strncmp(msg + n, ": ", 2) == 0)
            msg += n + 2;
        amfi_csv_fail(r, line, NULL, "corrupt gzip data: %s", msg ? msg : "unknown error");
    }
    return -1;
}

static int ends_with_gz(const char *path)
{
    size_t n = strlen(path);
    return n >= 3 && (strcmp(path + n - 3, ".gz") == 0 || strcmp(path + n - 3, ".GZ") == 0);
}

amfi_csv *amfi_csv_open(const char *path, size_t max_line, char *err, size_t errlen)
{
    if (err && errlen)
        err[0] = '\0';
    amfi_csv *r = calloc(1, sizeof *r);
    if (!r) {
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return NULL;
    }
    r->path = path;
    r->err = err;
    r->errlen = errlen;
    r->max_line = max_line < 1 || max_line > AMFI_CSV_MAX_LINE ? AMFI_CSV_MAX_LINE : max_line;
    errno = 0;
    r->f = gzopen(path, "rb");
    if (!r->f) {
        /* errno 0 means zlib itself could not allocate */
        amfi_csv_fail(r, 0, NULL, "cannot open: %s", errno ? strerror(errno) : "out of memory");
        free(r);
        return NULL;
    }
    /* right after gzopen, gzdirect() reads the start of the file to decide */
    if (ends_with_gz(path) && gzdirect(r->f)) {
        if (check_gz(r, 1) == 0)
            amfi_csv_fail(r, 1, NULL, "not in gzip format (the name ends in .gz)");
        gzclose(r->f);
        free(r);
        return NULL;
    }
    return r;
}

int amfi_csv_next(amfi_csv *r, const char **out, size_t *n)
{
    const long line = r->lineno + 1;
    const size_t max = r->max_line;
    size_t len = 0;
    int got_any = 0;
    for (;;) {
        if (r->pos == r->len) {
            if (r->at_eof)
                break;
            int k = gzread(r->f, r->buf, CHUNK);
            if (check_gz(r, line) != 0)
                return -1;
            if (k < 0) /* not expected without an error state */
                return amfi_csv_fail(r, line, NULL, "read error");
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
        /* room for max characters plus a CR before the LF */
        if (take > max + 1 - len)
            return amfi_csv_fail(r, line, NULL, "line longer than %zu characters", max);
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
    if (len > max)
        return amfi_csv_fail(r, line, NULL, "line longer than %zu characters", max);
    r->line[len] = '\0';
    if (memchr(r->line, '\0', len))
        return amfi_csv_fail(r, line, NULL, "NUL byte in line (binary data?)");
    *out = r->line;
    *n = len;
    return 1;
}

static int is_blank(int c) { return c == ' ' || c == '\t'; }

int amfi_csv_next_row(amfi_csv *r, const char **line, size_t *len, const char *blank_msg)
{
    long blank_line = 0; /* first blank line seen, 0 if none */
    for (;;) {
        int got = amfi_csv_next(r, line, len);
        if (got <= 0)
            return got;
        size_t k = 0;
        while (k < *len && is_blank((unsigned char)(*line)[k]))
            k++;
        if (k < *len) {
            if (blank_line)
                return amfi_csv_fail(r, blank_line, NULL, "%s", blank_msg);
            return 1;
        }
        if (!blank_line)
            blank_line = r->lineno;
    }
}

long amfi_csv_lineno(const amfi_csv *r) { return r->lineno; }

const char *amfi_csv_path(const amfi_csv *r) { return r->path; }

int amfi_csv_close(amfi_csv *r, int check)
{
    if (!r)
        return 0;
    int rc = 0;
    int zrc = gzclose(r->f);
    if (check && zrc != Z_OK) {
        if (zrc == Z_BUF_ERROR)
            amfi_csv_fail(r, r->lineno, NULL, "truncated gzip data (unexpected end of file)");
        else
            amfi_csv_fail(r, r->lineno, NULL, "error closing the file (zlib %d)", zrc);
        rc = -1;
    }
    free(r);
    return rc;
}

int amfi_csv_split(const char *s, size_t n, const char *start[], size_t flen[], int max)
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

void amfi_csv_strip_bom(const char **s, size_t *n)
{
    if (*n >= 3 && memcmp(*s, "\xEF\xBB\xBF", 3) == 0) {
        *s += 3;
        *n -= 3;
    }
}

int amfi_csv_field_double(const char *s, size_t n, double *v)
{
    if (n == 0)
        return AMFI_CSV_EMPTY;
    /* a NUL-terminated copy, so that strtod cannot run on into the next field */
    char tmp[AMFI_CSV_MAX_LINE + 1];
    if (n > AMFI_CSV_MAX_LINE)
        return AMFI_CSV_NOT_NUMBER;
    memcpy(tmp, s, n);
    tmp[n] = '\0';
    char *end = NULL;
    double x = strtod(tmp, &end);
    if (end == tmp || *end != '\0')
        return AMFI_CSV_NOT_NUMBER;
    if (isnan(x))
        return AMFI_CSV_NAN;
    if (isinf(x))
        return AMFI_CSV_INF;
    *v = x;
    return 0;
}
