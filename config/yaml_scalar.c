/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * yaml_scalar.c: the strict scalar parsers of the site-file loader and the
 * generic kinds of value (yaml_walk.h): number, integer, name from a list,
 * string, file path, mapping. Each kind reads a value into its row's place
 * with the row's range, and describes that range and a default for the
 * manual (amfi_config_keys()), from the same row, so the two cannot differ.
 *
 * Numbers are strict: plain (unquoted) decimal scalars only, no hex, no
 * inf/nan, no trailing characters. Runs on the caller's thread.
 */
#include "yaml_walk.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- scalars ------------------------------------------------------------- */

static int is_null(const char *s)
{
    return !*s || !strcmp(s, "~") || !strcmp(s, "null") || !strcmp(s, "Null") ||
           !strcmp(s, "NULL");
}

int amfi_cfg_is_plain(const yaml_node_t *v)
{
    return v->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
}

/* The text of scalar node v, or NULL after an error saying what was `want`ed.
 * Numbers must be plain (unquoted) scalars: allow_quoted = 0. */
int amfi_cfg_get_name(ctx *x, const yaml_node_t *v, const char *path, char *dst, size_t cap)
{
    const char *s = amfi_cfg_scalar(x, v, path, "a name", 1);
    size_t n;

    if (!s)
        return -1;
    n = strlen(s);
    if (n == 0 || n >= cap)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be 1 .. %zu bytes long, got %zu", cap - 1, n);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must not contain control characters");
    memset(dst, 0, cap);
    memcpy(dst, s, n);
    return 0;
}

const char *amfi_cfg_scalar(ctx *x, const yaml_node_t *v, const char *path,
                          const char *want, int allow_quoted)
{
    const char *s;
    char buf[SHOW_LEN];

    if (v->type != YAML_SCALAR_NODE) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got %s", want, amfi_cfg_what(v));
        return NULL;
    }
    s = (const char *)v->data.scalar.value;
    if (strlen(s) != v->data.scalar.length) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got a value with a NUL byte", want);
        return NULL;
    }
    if (amfi_cfg_is_plain(v) && is_null(s)) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got no value", want);
        return NULL;
    }
    if (!amfi_cfg_is_plain(v) && !allow_quoted) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got the quoted string '%s'", want,
             amfi_cfg_show(buf, sizeof buf, v));
        return NULL;
    }
    return s;
}

/* Strict decimal floating point: digits, sign, point, exponent; no hex, no
 * inf/nan, no trailing characters. 0 ok, −1 not a number, −2 out of range. */
int amfi_cfg_to_double(const char *s, double *out)
{
    char *end;
    double d;

    if (!*s)
        return -1;
    for (const char *p = s; *p; p++)
        if (!strchr("0123456789+-.eE", *p))
            return -1;
    errno = 0;
    d = strtod(s, &end);
    if (end == s || *end)
        return -1;
    if (errno == ERANGE || !isfinite(d))
        return -2;
    *out = d;
    return 0;
}

/* Strict decimal integer: optional sign, digits. 0 ok, −1 not, −2 range. */
int amfi_cfg_to_llong(const char *s, long long *out)
{
    const char *p = s;
    char *end;
    long long l;

    if (*p == '+' || *p == '-')
        p++;
    if (!*p)
        return -1;
    for (; *p; p++)
        if (*p < '0' || *p > '9')
            return -1;
    errno = 0;
    l = strtoll(s, &end, 10);
    if (errno == ERANGE)
        return -2;
    *out = l;
    return 0;
}

int amfi_cfg_to_long(const char *s, long *out)
{
    long long l;
    int rc = amfi_cfg_to_llong(s, &l);

    if (rc)
        return rc;
    if (l < LONG_MIN || l > LONG_MAX)
        return -2;
    *out = (long)l;
    return 0;
}

int amfi_cfg_get_double(ctx *x, const yaml_node_t *v, const char *path, double *out)
{
    char buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, "a number", 0);
    int rc;

    if (!s)
        return -1;
    rc = amfi_cfg_to_double(s, out);
    if (rc == -1)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected a finite number, got '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    if (rc == -2)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "number out of range: '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    return 0;
}

int amfi_cfg_get_number(ctx *x, const yaml_node_t *v, const char *path, const char *want,
               double *out)
{
    char buf[SHOW_LEN];
    int rc = amfi_cfg_is_plain(v) ? amfi_cfg_to_double((const char *)v->data.scalar.value, out) : -1;

    if (rc == -1)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got '%s'", want,
                    amfi_cfg_show(buf, sizeof buf, v));
    if (rc == -2)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "number out of range: '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    return 0;
}

int amfi_cfg_get_long(ctx *x, const yaml_node_t *v, const char *path, long *out)
{
    char buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, "an integer", 0);
    int rc;

    if (!s)
        return -1;
    rc = amfi_cfg_to_long(s, out);
    if (rc == -1)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected an integer, got '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    if (rc == -2)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "integer out of range: '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    return 0;
}

int amfi_cfg_out_of_range(double d, const field *f)
{
    return d < f->lo || d > f->hi || ((f->flags & F_LO_OPEN) && d == f->lo) ||
           ((f->flags & F_HI_OPEN) && d == f->hi);
}

/* The message for d outside row f's range; returns −1. */
int amfi_cfg_range_fail(ctx *x, const yaml_node_t *v, const char *path, const field *f,
                      double d)
{
    char range[DOC_LEN];

    amfi_cfg_describe_interval(f, range);
    return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be %s%s, got %g", isinf(f->hi) ? "" : "in ",
                range, d);
}

void amfi_cfg_describe_interval(const field *f, char *buf)
{
    if (isinf(f->hi))
        snprintf(buf, DOC_LEN, "%s %g", (f->flags & F_LO_OPEN) ? ">" : ">=", f->lo);
    else
        snprintf(buf, DOC_LEN, "%c%g, %g%c", (f->flags & F_LO_OPEN) ? '(' : '[', f->lo,
                 f->hi, (f->flags & F_HI_OPEN) ? ')' : ']');
}

void amfi_cfg_describe_count(const field *f, char *buf)
{
    snprintf(buf, DOC_LEN, "%.0f .. %.0f", f->lo, f->hi);
}

static int p_double(ctx *x, yaml_node_t *v, const char *path, const field *f,
                    void *base)
{
    double d = 0.0;

    if (amfi_cfg_get_double(x, v, path, &d))
        return -1;
    if (amfi_cfg_out_of_range(d, f))
        return amfi_cfg_range_fail(x, v, path, f, d);
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

static int p_int(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    long l = 0;
    int i;

    if (amfi_cfg_get_long(x, v, path, &l))
        return -1;
    if ((double)l < f->lo || (double)l > f->hi)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be %.0f .. %.0f, got %ld", f->lo, f->hi,
                    l);
    i = (int)l;
    memcpy((char *)base + f->off, &i, sizeof i);
    return 0;
}

/* An integer stored as a long long (seeds, µs timestamps). */
static int p_llong(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    char buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, "an integer", 0);
    long long l = 0;
    int rc;

    if (!s)
        return -1;
    rc = amfi_cfg_to_llong(s, &l);
    if (rc == -1)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected an integer, got '%s'",
                    amfi_cfg_show(buf, sizeof buf, v));
    if (rc == -2 || (double)l < f->lo || (double)l > f->hi)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be %.0f .. %.0f, got '%s'", f->lo, f->hi,
                    amfi_cfg_show(buf, sizeof buf, v));
    memcpy((char *)base + f->off, &l, sizeof l);
    return 0;
}

static void list_names(char *buf, size_t len, const enum_name *names)
{
    size_t used = 0;

    buf[0] = '\0';
    for (const enum_name *e = names; e->name; e++)
        used = amfi_cfg_append_name(buf, len, used, e->name);
}

void amfi_cfg_describe_names(const enum_name *names, char *buf)
{
    list_names(buf, DOC_LEN, names);
}

const char *amfi_cfg_enum_label(const enum_name *names, int value)
{
    for (const enum_name *e = names; e->name; e++)
        if (e->value == value)
            return e->name;
    return NULL;
}

/* One of a fixed set of names, stored as an int (or an enum of int size). */
static int p_enum(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const enum_name *names = f->aux;
    char known[128], buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, "a name", 1);

    if (!s)
        return -1;
    for (const enum_name *e = names; e->name; e++)
        if (strcmp(s, e->name) == 0) {
            memcpy((char *)base + f->off, &e->value, sizeof e->value);
            return 0;
        }
    list_names(known, sizeof known, names);
    return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected one of %s; got '%s'", known,
                amfi_cfg_show(buf, sizeof buf, v));
}

static int p_map(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    return amfi_cfg_walk_map(x, v, path, f->aux, base);
}

/* A string of printable characters, stored in char[f->hi] at f->off; lo is
 * the minimum length. */
static int p_string(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const char *s = amfi_cfg_scalar(x, v, path, "a string", 1);
    size_t n, cap = (size_t)f->hi;

    if (!s)
        return -1;
    n = strlen(s);
    if ((double)n < f->lo || n >= cap)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be %.0f .. %zu characters long, got %zu",
                    f->lo, cap - 1, n);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must not contain control characters");
    memset((char *)base + f->off, 0, cap);
    memcpy((char *)base + f->off, s, n);
    return 0;
}

/* A plain null (`key:`, `~`, `null`): "no value" for the keys that allow it. */
int amfi_cfg_is_null_node(const yaml_node_t *v)
{
    return v->type == YAML_SCALAR_NODE && amfi_cfg_is_plain(v) &&
           strlen((const char *)v->data.scalar.value) == v->data.scalar.length &&
           is_null((const char *)v->data.scalar.value);
}

/* A file path stored in char[f->hi] at f->off; "" or null: none. With
 * F_FILE_DIR a relative path is joined to the folder of the file being read
 * (a site file names its neighbours wherever the program runs). */
static int p_path(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    char *dst = (char *)base + f->off;
    size_t cap = (size_t)f->hi, n, dir = 0;
    const char *s, *slash;

    if (amfi_cfg_is_null_node(v)) {
        memset(dst, 0, cap);
        return 0;
    }
    s = amfi_cfg_scalar(x, v, path, "a file path", 1);
    if (!s)
        return -1;
    n = strlen(s);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must not contain control characters");
    if (n && s[0] != '/' && (f->flags & F_FILE_DIR) && (slash = strrchr(x->file, '/')))
        dir = (size_t)(slash - x->file) + 1;
    if (dir + n >= cap)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "too long: %zu characters%s, at most %zu",
                    dir + n, dir ? " with the file's folder" : "", cap - 1);
    memset(dst, 0, cap);
    memcpy(dst, x->file, dir);
    memcpy(dst + dir, s, n);
    return 0;
}


/* ---- descriptions for the manual ----------------------------------------- */

static void d_interval(const field *f, const void *base, char *buf)
{
    (void)base;
    amfi_cfg_describe_interval(f, buf);
}

static void d_count(const field *f, const void *base, char *buf)
{
    (void)base;
    amfi_cfg_describe_count(f, buf);
}

static void d_names(const field *f, const void *base, char *buf)
{
    (void)base;
    amfi_cfg_describe_names(f->aux, buf);
}

static void d_length(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "%.0f .. %.0f characters", f->lo, f->hi - 1);
}

static void d_path_length(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "at most %.0f characters", f->hi - 1);
}

static void d_none(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    buf[0] = '\0';
}

static void v_double(const field *f, const void *base, char *buf)
{
    double d;

    memcpy(&d, (const char *)base + f->off, sizeof d);
    snprintf(buf, DOC_LEN, "%g", d);
}

static void v_int(const field *f, const void *base, char *buf)
{
    int i;

    memcpy(&i, (const char *)base + f->off, sizeof i);
    snprintf(buf, DOC_LEN, "%d", i);
}

static void v_llong(const field *f, const void *base, char *buf)
{
    long long l;

    memcpy(&l, (const char *)base + f->off, sizeof l);
    snprintf(buf, DOC_LEN, "%lld", l);
}

static void v_enum(const field *f, const void *base, char *buf)
{
    int i;
    const char *s;

    memcpy(&i, (const char *)base + f->off, sizeof i);
    s = amfi_cfg_enum_label(f->aux, i);
    snprintf(buf, DOC_LEN, "%s", s ? s : "?");
}

static void v_string(const field *f, const void *base, char *buf)
{
    const char *s = (const char *)base + f->off;

    snprintf(buf, DOC_LEN, "%s", *s ? s : "\"\"");
}

static void v_path(const field *f, const void *base, char *buf)
{
    const char *s = (const char *)base + f->off;

    snprintf(buf, DOC_LEN, "%s", *s ? s : "none");
}

/* ---- where the values live ---------------------------------------------- */

static int one_span(size_t off, size_t len, span *out)
{
    out[0] = (span){off, len};
    return 1;
}

int amfi_cfg_spans_double(const field *f, span *out)
{
    return one_span(f->off, sizeof(double), out);
}

int amfi_cfg_spans_int(const field *f, span *out)
{
    return one_span(f->off, sizeof(int), out);
}

int amfi_cfg_spans_llong(const field *f, span *out)
{
    return one_span(f->off, sizeof(long long), out);
}

int amfi_cfg_spans_chars(const field *f, span *out)
{
    return one_span(f->off, (size_t)f->hi, out);
}

const kind amfi_cfg_k_double = {"number", p_double, d_interval, v_double, NEST_NONE,
                                amfi_cfg_spans_double};
const kind amfi_cfg_k_int = {"integer", p_int, d_count, v_int, NEST_NONE, amfi_cfg_spans_int};
const kind amfi_cfg_k_llong = {"integer", p_llong, d_count, v_llong, NEST_NONE,
                               amfi_cfg_spans_llong};
const kind amfi_cfg_k_enum = {"name", p_enum, d_names, v_enum, NEST_NONE, amfi_cfg_spans_int};
const kind amfi_cfg_k_string = {"string", p_string, d_length, v_string, NEST_NONE,
                                amfi_cfg_spans_chars};
const kind amfi_cfg_k_path = {"file path", p_path, d_path_length, v_path, NEST_NONE,
                              amfi_cfg_spans_chars};
const kind amfi_cfg_k_map = {"mapping", p_map, d_none, d_none, NEST_MAP, NULL};
