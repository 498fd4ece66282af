/*
 * amfi_config.c: YAML site file -> amfi_site_config, validated, with
 * "FILE:LINE: key.path: problem" errors.
 *
 * The file (at most 1 MiB) is read into memory, checked once with libyaml's
 * event API (syntax, nesting depth, a single document), then loaded with the
 * document API (yaml_parser_load); every node keeps its start mark, so an
 * error names the line of the offending key or value.
 *
 * The schema is a set of tables (struct field), one per YAML mapping: each
 * row names a key, the function that parses its value and where the value
 * goes. walk_map() does what every mapping needs (type
 * check, unknown, duplicate and required keys); the row functions check the
 * value's type and range. Checks that involve several keys (a sensor within
 * the span, lo < hi, ...) run once the whole file is read, in check_site(),
 * and find the line they blame in a record of where each key path was seen.
 *
 * Adding a section (the daemon's `daemon:`, sim_publisher's `simulation:`):
 * its fields in amfi_site_config with their defaults in
 * amfi_config_defaults(), a field table, one row in top_fields[] and, if
 * needed, its cross-checks in check_site().
 *
 * The walk is bounded by the schema, not by the document: it descends only
 * where the schema has a mapping or a list, and lists have bounded length, so
 * self-referencing aliases or deep nesting cannot make it loop or recurse.
 * Workload: a few kB, once at start-up or reload; nothing here is fast-path.
 */
#include "amfi_config.h"

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <yaml.h>

#define MAX_FILE_BYTES (1L << 20) /* a site file is a few kB; refuse odd inputs */
#define PATH_LEN 96       /* key paths such as "bridge.supports[15].at_m" */
#define MAX_NOTES 256     /* key paths remembered for cross-checks */
#define MAX_FIELDS 32     /* rows per table */
#define SHOW_LEN 40       /* bytes of an offending value quoted in a message */
#define MAX_RATE_HZ 1e6   /* calc_rate_hz, lambda_ref_rate_hz: (0, 1e6] Hz */
#define MAX_ROLL_S 60.0   /* pre_roll_s, post_roll_s: [0, 60) s */
#define MAX_DURATION_S 600.0 /* max_duration_s: (0, 600] s; a passage is ~1 s,
                                a slow crossing of a long bridge under a minute */
#define MAX_MODE_NO (2 * (1000 + 1)) /* DOFs of the largest mesh, before supports */
#define MAX_DEPTH 16      /* mapping/list nesting; the schema needs 4 */

/* ---- context and messages ---------------------------------------------- */

typedef struct note {
    char path[PATH_LEN];
    int line; /* 1-based line of the key */
} note;

typedef struct ctx {
    const char *file;     /* as the caller named it, for messages */
    yaml_document_t *doc; /* the loaded document, owned by amfi_config_load */
    char *err;            /* caller's buffer, may be NULL */
    size_t errlen;
    int n_notes;
    note notes[MAX_NOTES]; /* every key path seen, with its line */
} ctx;

static size_t advance(size_t used, int n, size_t len)
{
    if (n < 0)
        return used;
    if (used + (size_t)n >= len)
        return len - 1;
    return used + (size_t)n;
}

/* Write "FILE[:LINE]: [path: ]message" into the caller's buffer; returns −1.
 * line <= 0 omits the line, an empty path omits the path. */
static int fail(ctx *x, int line, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int fail(ctx *x, int line, const char *path, const char *fmt, ...)
{
    va_list ap;
    size_t used = 0;

    if (!x->err || x->errlen == 0)
        return -1;
    if (line > 0)
        used = advance(used, snprintf(x->err, x->errlen, "%s:%d: ", x->file, line),
                       x->errlen);
    else
        used = advance(used, snprintf(x->err, x->errlen, "%s: ", x->file), x->errlen);
    if (path && *path)
        used = advance(used, snprintf(x->err + used, x->errlen - used, "%s: ", path),
                       x->errlen);
    va_start(ap, fmt);
    vsnprintf(x->err + used, x->errlen - used, fmt, ap);
    va_end(ap);
    return -1;
}

static int line_of(const yaml_node_t *n)
{
    return (int)n->start_mark.line + 1; /* the file is < 1 MiB: fits an int */
}

/* Copy at most len − 1 bytes of s into buf, control bytes as '?', so a value
 * or key quoted in a message keeps the message on one line. */
static void sanitise(char *buf, size_t len, const char *s, size_t n)
{
    size_t i, k = 0;

    for (i = 0; i < n && k + 1 < len; i++) {
        unsigned char ch = (unsigned char)s[i];
        buf[k++] = (ch < 0x20 || ch == 0x7f) ? '?' : (char)ch;
    }
    buf[k] = '\0';
}

/* A scalar's value for a message: sanitised, cut at SHOW_LEN bytes. */
static const char *show(char *buf, size_t len, const yaml_node_t *v)
{
    size_t n = v->data.scalar.length;

    sanitise(buf, len, (const char *)v->data.scalar.value, n);
    if (n >= len && len > 4)
        memcpy(buf + len - 4, "...", 4);
    return buf;
}

static const char *what(const yaml_node_t *v)
{
    switch (v->type) {
    case YAML_MAPPING_NODE: return "a mapping";
    case YAML_SEQUENCE_NODE: return "a list";
    case YAML_SCALAR_NODE: return "a single value";
    default: return "nothing";
    }
}

/* Format a key path into out[PATH_LEN]; a path that does not fit is cut. */
static void pathf(char *out, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void pathf(char *out, const char *fmt, ...)
{
    va_list ap;

    va_start(ap, fmt);
    vsnprintf(out, PATH_LEN, fmt, ap);
    va_end(ap);
}

static void join_key(char *out, const char *path, const yaml_node_t *k)
{
    char key[PATH_LEN];

    sanitise(key, sizeof key, (const char *)k->data.scalar.value, k->data.scalar.length);
    if (*path)
        pathf(out, "%s.%s", path, key);
    else
        pathf(out, "%s", key);
}

static void join_index(char *out, const char *path, size_t i)
{
    pathf(out, "%s[%zu]", path, i);
}

static void note_line(ctx *x, const char *path, int line)
{
    /* A full record only loses the line number of a later cross-check error. */
    if (x->n_notes >= MAX_NOTES)
        return;
    pathf(x->notes[x->n_notes].path, "%s", path);
    x->notes[x->n_notes].line = line;
    x->n_notes++;
}

/* Line where key path `path` was given in the file, 0 when it was not. */
static int noted(const ctx *x, const char *path)
{
    for (int i = 0; i < x->n_notes; i++)
        if (strcmp(x->notes[i].path, path) == 0)
            return x->notes[i].line;
    return 0;
}

/* ---- scalars ------------------------------------------------------------ */

static int is_null(const char *s)
{
    return !*s || !strcmp(s, "~") || !strcmp(s, "null") || !strcmp(s, "Null") ||
           !strcmp(s, "NULL");
}

static int is_plain(const yaml_node_t *v)
{
    return v->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
}

/* The text of scalar node v, or NULL after an error saying what was `want`ed.
 * Numbers must be plain (unquoted) scalars: allow_quoted = 0. */
static const char *scalar(ctx *x, const yaml_node_t *v, const char *path,
                          const char *want, int allow_quoted)
{
    const char *s;
    char buf[SHOW_LEN];

    if (v->type != YAML_SCALAR_NODE) {
        fail(x, line_of(v), path, "expected %s, got %s", want, what(v));
        return NULL;
    }
    s = (const char *)v->data.scalar.value;
    if (strlen(s) != v->data.scalar.length) {
        fail(x, line_of(v), path, "expected %s, got a value with a NUL byte", want);
        return NULL;
    }
    if (is_plain(v) && is_null(s)) {
        fail(x, line_of(v), path, "expected %s, got no value", want);
        return NULL;
    }
    if (!is_plain(v) && !allow_quoted) {
        fail(x, line_of(v), path, "expected %s, got the quoted string '%s'", want,
             show(buf, sizeof buf, v));
        return NULL;
    }
    return s;
}

/* Strict decimal floating point: digits, sign, point, exponent; no hex, no
 * inf/nan, no trailing characters. 0 ok, −1 not a number, −2 out of range. */
static int to_double(const char *s, double *out)
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
static int to_llong(const char *s, long long *out)
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

static int to_long(const char *s, long *out)
{
    long long l;
    int rc = to_llong(s, &l);

    if (rc)
        return rc;
    if (l < LONG_MIN || l > LONG_MAX)
        return -2;
    *out = (long)l;
    return 0;
}

static int get_double(ctx *x, const yaml_node_t *v, const char *path, double *out)
{
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, "a number", 0);
    int rc;

    if (!s)
        return -1;
    rc = to_double(s, out);
    if (rc == -1)
        return fail(x, line_of(v), path, "expected a finite number, got '%s'",
                    show(buf, sizeof buf, v));
    if (rc == -2)
        return fail(x, line_of(v), path, "number out of range: '%s'",
                    show(buf, sizeof buf, v));
    return 0;
}

static int get_long(ctx *x, const yaml_node_t *v, const char *path, long *out)
{
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, "an integer", 0);
    int rc;

    if (!s)
        return -1;
    rc = to_long(s, out);
    if (rc == -1)
        return fail(x, line_of(v), path, "expected an integer, got '%s'",
                    show(buf, sizeof buf, v));
    if (rc == -2)
        return fail(x, line_of(v), path, "integer out of range: '%s'",
                    show(buf, sizeof buf, v));
    return 0;
}

/* ---- the schema --------------------------------------------------------- */

typedef struct field field;

/* Parse value node v of key path `path` into base (the struct the row's
 * offsets are relative to). 0 ok, −1 after fail(). */
typedef int (*parse_fn)(ctx *x, yaml_node_t *v, const char *path, const field *f,
                        void *base);

#define F_LO_OPEN 1u  /* lo itself is not allowed */
#define F_HI_OPEN 2u  /* hi itself is not allowed */
#define F_REQUIRED 4u /* the key must be present (list items) */
#define F_FILE_DIR 8u /* p_path: a relative path is joined to the file's folder */

struct field {
    const char *key;   /* NULL ends a table */
    parse_fn parse;
    size_t off;        /* destination, bytes from base */
    double lo, hi;     /* p_double, p_int: allowed range (HUGE_VAL: none) */
    unsigned flags;    /* F_* */
    const void *aux;   /* p_map: const field[]; p_enum: const enum_name[] */
};

typedef struct enum_name {
    const char *name; /* NULL ends the list */
    int value;
} enum_name;

static int walk_map(ctx *x, yaml_node_t *m, const char *path, const field *table,
                    void *base);

static int out_of_range(double d, const field *f)
{
    return d < f->lo || d > f->hi || ((f->flags & F_LO_OPEN) && d == f->lo) ||
           ((f->flags & F_HI_OPEN) && d == f->hi);
}

/* The message for d outside row f's range; returns −1. */
static int range_fail(ctx *x, const yaml_node_t *v, const char *path, const field *f,
                      double d)
{
    if (isinf(f->hi))
        return fail(x, line_of(v), path, "must be %s %g, got %g",
                    (f->flags & F_LO_OPEN) ? ">" : ">=", f->lo, d);
    return fail(x, line_of(v), path, "must be in %c%g, %g%c, got %g",
                (f->flags & F_LO_OPEN) ? '(' : '[', f->lo, f->hi,
                (f->flags & F_HI_OPEN) ? ')' : ']', d);
}

static int p_double(ctx *x, yaml_node_t *v, const char *path, const field *f,
                    void *base)
{
    double d = 0.0;

    if (get_double(x, v, path, &d))
        return -1;
    if (out_of_range(d, f))
        return range_fail(x, v, path, f, d);
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

static int p_int(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    long l = 0;
    int i;

    if (get_long(x, v, path, &l))
        return -1;
    if ((double)l < f->lo || (double)l > f->hi)
        return fail(x, line_of(v), path, "must be %.0f .. %.0f, got %ld", f->lo, f->hi,
                    l);
    i = (int)l;
    memcpy((char *)base + f->off, &i, sizeof i);
    return 0;
}

/* An integer stored as a long long (seeds, µs timestamps). */
static int p_llong(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, "an integer", 0);
    long long l = 0;
    int rc;

    if (!s)
        return -1;
    rc = to_llong(s, &l);
    if (rc == -1)
        return fail(x, line_of(v), path, "expected an integer, got '%s'",
                    show(buf, sizeof buf, v));
    if (rc == -2 || (double)l < f->lo || (double)l > f->hi)
        return fail(x, line_of(v), path, "must be %.0f .. %.0f, got '%s'", f->lo, f->hi,
                    show(buf, sizeof buf, v));
    memcpy((char *)base + f->off, &l, sizeof l);
    return 0;
}

static void list_names(char *buf, size_t len, const enum_name *names)
{
    size_t used = 0;

    buf[0] = '\0';
    for (const enum_name *e = names; e->name; e++)
        used = advance(used, snprintf(buf + used, len - used, "%s%s",
                                      e == names ? "" : ", ", e->name), len);
}

/* One of a fixed set of names, stored as an int (or an enum of int size). */
static int p_enum(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const enum_name *names = f->aux;
    char known[128], buf[SHOW_LEN];
    const char *s = scalar(x, v, path, "a name", 1);

    if (!s)
        return -1;
    for (const enum_name *e = names; e->name; e++)
        if (strcmp(s, e->name) == 0) {
            memcpy((char *)base + f->off, &e->value, sizeof e->value);
            return 0;
        }
    list_names(known, sizeof known, names);
    return fail(x, line_of(v), path, "expected one of %s; got '%s'", known,
                show(buf, sizeof buf, v));
}

static int p_map(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    return walk_map(x, v, path, f->aux, base);
}

/* bridge.name */
static int p_name(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_site_config *c = base;
    const char *s = scalar(x, v, path, "a name", 1);
    size_t n;

    (void)f;
    if (!s)
        return -1;
    n = strlen(s);
    if (n == 0 || n >= sizeof c->name)
        return fail(x, line_of(v), path, "must be 1 .. %zu bytes long, got %zu",
                    sizeof c->name - 1, n);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return fail(x, line_of(v), path, "must not contain control characters");
    memset(c->name, 0, sizeof c->name);
    memcpy(c->name, s, n);
    return 0;
}

/* bridge.damping.modes: [a, b], two distinct 1-based mode numbers */
static int p_rayleigh_modes(ctx *x, yaml_node_t *v, const char *path, const field *f,
                            void *base)
{
    amfi_site_config *c = base;
    char ip[PATH_LEN];
    long m[2] = {0, 0};

    (void)f;
    if (v->type != YAML_SEQUENCE_NODE)
        return fail(x, line_of(v), path, "expected a list of two mode numbers such "
                    "as [1, 2], got %s", what(v));
    if (v->data.sequence.items.top - v->data.sequence.items.start != 2)
        return fail(x, line_of(v), path, "expected two mode numbers, got %d",
                    (int)(v->data.sequence.items.top - v->data.sequence.items.start));
    for (int i = 0; i < 2; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, v->data.sequence.items.start[i]);
        join_index(ip, path, (size_t)i);
        if (!it)
            return fail(x, line_of(v), ip, "malformed list");
        if (get_long(x, it, ip, &m[i]))
            return -1;
        if (m[i] < 1 || m[i] > MAX_MODE_NO)
            return fail(x, line_of(it), ip, "must be a mode number 1 .. %d, got %ld",
                        MAX_MODE_NO, m[i]);
    }
    if (m[0] == m[1])
        return fail(x, line_of(v), path, "the two modes must differ, got %ld twice",
                    m[0]);
    c->bridge.rayleigh_mode_a = (int)m[0];
    c->bridge.rayleigh_mode_b = (int)m[1];
    return 0;
}

/* bridge.supports: a list of {at_m, type} */
typedef struct support_item {
    double at_m; /* m, >= 0 (<= span checked in check_site) */
    int type;    /* SUPPORT_* */
} support_item;

enum { SUPPORT_PINNED, SUPPORT_ROLLER, SUPPORT_FIXED };

static const enum_name support_types[] = {
    {"pinned", SUPPORT_PINNED}, {"roller", SUPPORT_ROLLER}, {"fixed", SUPPORT_FIXED},
    {NULL, 0}};

static const field support_fields[] = {
    {.key = "at_m", .parse = p_double, .off = offsetof(support_item, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "type", .parse = p_enum, .off = offsetof(support_item, type),
     .aux = support_types, .flags = F_REQUIRED},
    {.key = NULL}};

/* The items of list node v, checked to be 1 .. max long; NULL after fail(). */
static yaml_node_item_t *list_items(ctx *x, yaml_node_t *v, const char *path,
                                    const char *what_items, int max, int *n)
{
    ptrdiff_t len;

    if (v->type != YAML_SEQUENCE_NODE) {
        fail(x, line_of(v), path, "expected a list of %s, got %s", what_items, what(v));
        return NULL;
    }
    len = v->data.sequence.items.top - v->data.sequence.items.start;
    if (len < 1 || len > max) {
        fail(x, line_of(v), path, "expected 1 .. %d %s, got %td", max, what_items, len);
        return NULL;
    }
    *n = (int)len;
    return v->data.sequence.items.start;
}

static int p_supports(ctx *x, yaml_node_t *v, const char *path, const field *f,
                      void *base)
{
    amfi_bridge_params *b = &((amfi_site_config *)base)->bridge;
    amfi_support s[AMFI_MAX_SUPPORTS];
    yaml_node_item_t *items;
    char ip[PATH_LEN];
    int n = 0;

    (void)f;
    items = list_items(x, v, path, "supports", AMFI_MAX_SUPPORTS, &n);
    if (!items)
        return -1;
    memset(s, 0, sizeof s);
    for (int i = 0; i < n; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, items[i]);
        support_item si = {0.0, SUPPORT_PINNED};

        join_index(ip, path, (size_t)i);
        if (!it)
            return fail(x, line_of(v), ip, "malformed list");
        note_line(x, ip, line_of(it));
        if (walk_map(x, it, ip, support_fields, &si))
            return -1;
        s[i].x_m = si.at_m;
        s[i].restrain_w = 1;
        s[i].restrain_theta = si.type == SUPPORT_FIXED;
    }
    memcpy(b->supports, s, sizeof s);
    b->n_supports = n;
    return 0;
}

/* sensors: a list of {id, at_m, weight} */
typedef struct sensor_item {
    int id;        /* 0 .. 255 */
    double at_m;   /* m, >= 0 (<= span checked in check_site) */
    double weight; /* > 0, default 1 */
} sensor_item;

static const field sensor_fields[] = {
    {.key = "id", .parse = p_int, .off = offsetof(sensor_item, id), .lo = 0, .hi = 255,
     .flags = F_REQUIRED},
    {.key = "at_m", .parse = p_double, .off = offsetof(sensor_item, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "weight", .parse = p_double, .off = offsetof(sensor_item, weight), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = NULL}};

static int p_sensors(ctx *x, yaml_node_t *v, const char *path, const field *f,
                     void *base)
{
    amfi_site_config *c = base;
    sensor_item s[AMFI_MAX_SENSORS];
    yaml_node_item_t *items;
    char ip[PATH_LEN], idp[PATH_LEN];
    int n = 0;

    (void)f;
    items = list_items(x, v, path, "sensors", AMFI_MAX_SENSORS, &n);
    if (!items)
        return -1;
    for (int i = 0; i < n; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, items[i]);

        join_index(ip, path, (size_t)i);
        if (!it)
            return fail(x, line_of(v), ip, "malformed list");
        note_line(x, ip, line_of(it));
        s[i] = (sensor_item){.id = 0, .at_m = 0.0, .weight = 1.0};
        if (walk_map(x, it, ip, sensor_fields, &s[i]))
            return -1;
        for (int j = 0; j < i; j++)
            if (s[j].id == s[i].id) {
                pathf(idp, "%s.id", ip);
                return fail(x, noted(x, idp), idp, "duplicate id %d (also %s[%d])",
                            s[i].id, path, j);
            }
    }
    for (int i = 0; i < AMFI_MAX_SENSORS; i++) {
        c->solver.sensor_x_m[i] = i < n ? s[i].at_m : 0.0;
        c->solver.sensor_weight[i] = i < n ? s[i].weight : 0.0;
        c->sensor_id[i] = i < n ? s[i].id : -1;
    }
    c->solver.n_sensors = n;
    return 0;
}

/* solver.formulation: a name amfi_formulation_parse() knows */
static int p_formulation(ctx *x, yaml_node_t *v, const char *path, const field *f,
                         void *base)
{
    amfi_site_config *c = base;
    char known[128], buf[SHOW_LEN];
    size_t used = 0;
    const char *s = scalar(x, v, path, "a formulation name", 1);

    (void)f;
    if (!s)
        return -1;
    if (amfi_formulation_parse(s, &c->solver.formulation) == 0)
        return 0;
    known[0] = '\0';
    for (int i = 0; strcmp(amfi_formulation_name((amfi_formulation)i), "unknown"); i++)
        used = advance(used, snprintf(known + used, sizeof known - used, "%s%s",
                                      i ? ", " : "",
                                      amfi_formulation_name((amfi_formulation)i)),
                       sizeof known);
    return fail(x, line_of(v), path, "expected one of %s; got '%s'", known,
                show(buf, sizeof buf, v));
}

/* solver.modes: all | observable | N (the N lowest observable modes) */
static int p_modes(ctx *x, yaml_node_t *v, const char *path, const field *f,
                   void *base)
{
    amfi_solver_params *p = &((amfi_site_config *)base)->solver;
    const char *want = "all, observable or a positive mode count";
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, want, 1);
    long n = 0;

    (void)f;
    if (!s)
        return -1;
    if (strcmp(s, "all") == 0 || strcmp(s, "observable") == 0) {
        p->modes = s[0] == 'a' ? AMFI_MODES_ALL : AMFI_MODES_OBSERVABLE;
        p->n_modes = 0;
        return 0;
    }
    if (!is_plain(v) || to_long(s, &n) != 0)
        return fail(x, line_of(v), path, "expected %s, got '%s'", want,
                    show(buf, sizeof buf, v));
    if (n < 1 || n > MAX_MODE_NO)
        return fail(x, line_of(v), path, "a mode count must be 1 .. %d, got %ld",
                    MAX_MODE_NO, n);
    p->modes = AMFI_MODES_COUNT;
    p->n_modes = (int)n;
    return 0;
}

/* solver.lambda: auto (L-curve) or a fixed λ at lambda_ref_rate_hz, > 0 */
static int p_lambda(ctx *x, yaml_node_t *v, const char *path, const field *f,
                    void *base)
{
    amfi_lambda *l = &((amfi_site_config *)base)->lambda;
    const char *want = "auto or a positive number";
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, want, 1);
    double d = 0.0;
    int rc;

    (void)f;
    if (!s)
        return -1;
    if (strcmp(s, "auto") == 0) {
        l->automatic = 1;
        return 0;
    }
    rc = is_plain(v) ? to_double(s, &d) : -1;
    if (rc == -1)
        return fail(x, line_of(v), path, "expected %s, got '%s'", want,
                    show(buf, sizeof buf, v));
    if (rc == -2)
        return fail(x, line_of(v), path, "number out of range: '%s'",
                    show(buf, sizeof buf, v));
    if (!(d > 0))
        return fail(x, line_of(v), path, "must be > 0 (or auto), got %g", d);
    l->automatic = 0;
    l->lambda_ref = d;
    return 0;
}

/* Offsets into amfi_site_config. Enums are written as ints: */
#define SC(m) offsetof(amfi_site_config, m)
_Static_assert(sizeof(amfi_coords) == sizeof(int), "amfi_coords is written as an int");

static const field damping_fields[] = {
    {.key = "ratio", .parse = p_double, .off = SC(bridge.damping_ratio), .lo = 0,
     .hi = 1, .flags = F_HI_OPEN},
    {.key = "modes", .parse = p_rayleigh_modes},
    {.key = NULL}};

static const field bridge_fields[] = {
    {.key = "name", .parse = p_name},
    {.key = "span_m", .parse = p_double, .off = SC(bridge.span_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "elements", .parse = p_int, .off = SC(bridge.n_elements), .lo = 1,
     .hi = 1000},
    {.key = "E_pa", .parse = p_double, .off = SC(bridge.E_pa), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "A_m2", .parse = p_double, .off = SC(bridge.A_m2), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "I_m4", .parse = p_double, .off = SC(bridge.I_m4), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "density_kgm3", .parse = p_double, .off = SC(bridge.density_kgm3), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "damping", .parse = p_map, .aux = damping_fields},
    {.key = "supports", .parse = p_supports},
    {.key = "damage", .parse = p_double, .off = SC(bridge.damage), .lo = 0, .hi = 1,
     .flags = F_HI_OPEN},
    {.key = NULL}};

static const enum_name coords_names[] = {
    {"modal", AMFI_COORDS_MODAL}, {"nodal", AMFI_COORDS_NODAL}, {NULL, 0}};

/* solver.initial_force -> fix_initial_force */
static const enum_name initial_force_names[] = {{"free", 0}, {"zero", 1}, {NULL, 0}};

/* solver.initial_state -> free_initial_state */
static const enum_name initial_state_names[] = {{"rest", 0}, {"free", 1}, {NULL, 0}};

static const field lcurve_fields[] = {
    {.key = "lo", .parse = p_double, .off = SC(lambda.lcurve_lo), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "hi", .parse = p_double, .off = SC(lambda.lcurve_hi), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "per_decade", .parse = p_int, .off = SC(lambda.lcurve_per_decade), .lo = 1,
     .hi = 100},
    {.key = "refine", .parse = p_int, .off = SC(lambda.lcurve_refine_points), .lo = 0,
     .hi = 100},
    {.key = NULL}};

static const field solver_fields[] = {
    {.key = "formulation", .parse = p_formulation},
    {.key = "coordinates", .parse = p_enum, .off = SC(solver.coords),
     .aux = coords_names},
    {.key = "modes", .parse = p_modes},
    {.key = "calc_rate_hz", .parse = p_double, .off = SC(solver.calc_rate_hz), .lo = 0,
     .hi = MAX_RATE_HZ, .flags = F_LO_OPEN},
    {.key = "initial_force", .parse = p_enum, .off = SC(solver.fix_initial_force),
     .aux = initial_force_names},
    {.key = "initial_state", .parse = p_enum, .off = SC(solver.free_initial_state),
     .aux = initial_state_names},
    {.key = "pre_roll_s", .parse = p_double, .off = SC(solver.pre_roll_s), .lo = 0,
     .hi = MAX_ROLL_S, .flags = F_HI_OPEN},
    {.key = "post_roll_s", .parse = p_double, .off = SC(solver.post_roll_s), .lo = 0,
     .hi = MAX_ROLL_S, .flags = F_HI_OPEN},
    {.key = "max_axles", .parse = p_int, .off = SC(solver.max_axles), .lo = 1,
     .hi = AMFI_MAX_AXLES},
    {.key = "max_duration_s", .parse = p_double, .off = SC(solver.max_duration_s),
     .lo = 0, .hi = MAX_DURATION_S, .flags = F_LO_OPEN},
    {.key = "lambda", .parse = p_lambda},
    {.key = "lambda_ref_rate_hz", .parse = p_double, .off = SC(lambda.ref_rate_hz),
     .lo = 0, .hi = MAX_RATE_HZ, .flags = F_LO_OPEN},
    {.key = "lcurve", .parse = p_map, .aux = lcurve_fields},
    {.key = NULL}};

/* A string of printable characters, stored in char[f->hi] at f->off; lo is
 * the minimum length. */
static int p_string(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const char *s = scalar(x, v, path, "a string", 1);
    size_t n, cap = (size_t)f->hi;

    if (!s)
        return -1;
    n = strlen(s);
    if ((double)n < f->lo || n >= cap)
        return fail(x, line_of(v), path, "must be %.0f .. %zu characters long, got %zu",
                    f->lo, cap - 1, n);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return fail(x, line_of(v), path, "must not contain control characters");
    memset((char *)base + f->off, 0, cap);
    memcpy((char *)base + f->off, s, n);
    return 0;
}

#define DC(m) offsetof(amfi_site_config, daemon.m)
#define STR(k, m, minlen) \
    {.key = k, .parse = p_string, .off = DC(m), .lo = minlen, \
     .hi = sizeof(((amfi_daemon_config *)0)->m)}

static const field channel_fields[] = {
    STR("accel", ch_accel, 1),     STR("vehicle", ch_vehicle, 1),
    STR("truth", ch_truth, 1),     STR("passage", ch_passage, 1),
    STR("indicator", ch_indicator, 1), STR("alert", ch_alert, 1),
    STR("status", ch_status, 1),   {.key = NULL}};

static const enum_name sync_names[] = {{"normal", 0}, {"full", 1}, {NULL, 0}};

static const field store_fields[] = {
    STR("path", db_path, 1),
    {.key = "sync", .parse = p_enum, .off = DC(sync_full), .aux = sync_names},
    {.key = NULL}};

static const enum_name onoff_names[] = {{"off", 0}, {"on", 1}, {NULL, 0}};

static const field indicator_fields[] = {
    {.key = "window", .parse = p_int, .off = DC(ind_window), .lo = 10, .hi = 1000000},
    {.key = "every", .parse = p_int, .off = DC(ind_every), .lo = 1, .hi = 1000000},
    {.key = "baseline_n", .parse = p_int, .off = DC(ind_baseline_n), .lo = 10, .hi = 1000000},
    {.key = "std_alert_ratio", .parse = p_double, .off = DC(ind_std_alert_ratio), .lo = 1,
     .hi = 10},
    {.key = "std_alert_p", .parse = p_double, .off = DC(ind_std_alert_p), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN},
    {.key = "std_clear_ratio", .parse = p_double, .off = DC(ind_std_clear_ratio), .lo = 0.5,
     .hi = 10},
    {.key = "raise_after", .parse = p_int, .off = DC(ind_raise_after), .lo = 1, .hi = 1000},
    {.key = "clear_after", .parse = p_int, .off = DC(ind_clear_after), .lo = 1, .hi = 1000},
    {.key = "mean_shift", .parse = p_enum, .off = DC(ind_mean_shift), .aux = onoff_names},
    {.key = "mean_alert_ratio", .parse = p_double, .off = DC(ind_mean_alert_ratio), .lo = 1,
     .hi = 10},
    {.key = "mean_alert_p", .parse = p_double, .off = DC(ind_mean_alert_p), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN},
    {.key = "mean_clear_ratio", .parse = p_double, .off = DC(ind_mean_clear_ratio), .lo = 0.5,
     .hi = 10},
    {.key = NULL}};

static const field daemon_fields[] = {
    STR("lcm_url", lcm_url, 0),
    {.key = "channels", .parse = p_map, .aux = channel_fields},
    {.key = "store", .parse = p_map, .aux = store_fields},
    {.key = "workers", .parse = p_int, .off = DC(workers), .lo = 1, .hi = 64},
    {.key = "queue_size", .parse = p_int, .off = DC(queue_size), .lo = 1, .hi = 100000},
    {.key = "ring_s", .parse = p_double, .off = DC(ring_s), .lo = 5, .hi = 3600},
    {.key = "window_margin_s", .parse = p_double, .off = DC(margin_s), .lo = 0, .hi = 5},
    {.key = "max_wait_s", .parse = p_double, .off = DC(max_wait_s), .lo = 0, .hi = 3600,
     .flags = F_LO_OPEN},
    {.key = "status_period_s", .parse = p_double, .off = DC(status_period_s), .lo = 0.1,
     .hi = 3600},
    {.key = "indicators", .parse = p_map, .aux = indicator_fields},
    {.key = NULL}};

/* ---- simulation: sim_publisher's settings --------------------------------- */

/* A plain null (`key:`, `~`, `null`): "no value" for the keys that allow it. */
static int is_null_node(const yaml_node_t *v)
{
    return v->type == YAML_SCALAR_NODE && is_plain(v) &&
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

    if (is_null_node(v)) {
        memset(dst, 0, cap);
        return 0;
    }
    s = scalar(x, v, path, "a file path", 1);
    if (!s)
        return -1;
    n = strlen(s);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            return fail(x, line_of(v), path, "must not contain control characters");
    if (n && s[0] != '/' && (f->flags & F_FILE_DIR) && (slash = strrchr(x->file, '/')))
        dir = (size_t)(slash - x->file) + 1;
    if (dir + n >= cap)
        return fail(x, line_of(v), path, "too long: %zu characters%s, at most %zu",
                    dir + n, dir ? " with the file's folder" : "", cap - 1);
    memset(dst, 0, cap);
    memcpy(dst, x->file, dir);
    memcpy(dst + dir, s, n);
    return 0;
}

/* simulation.stream.speedup: max (stored as 0: no pacing) or a factor in
 * the row's range. */
static int p_speedup(ctx *x, yaml_node_t *v, const char *path, const field *f,
                     void *base)
{
    const char *want = "max or a number";
    char buf[SHOW_LEN];
    const char *s = scalar(x, v, path, want, 1);
    double d = 0.0;
    int rc;

    if (!s)
        return -1;
    if (strcmp(s, "max") != 0) {
        rc = is_plain(v) ? to_double(s, &d) : -1;
        if (rc == -1)
            return fail(x, line_of(v), path, "expected %s, got '%s'", want,
                        show(buf, sizeof buf, v));
        if (rc == -2)
            return fail(x, line_of(v), path, "number out of range: '%s'",
                        show(buf, sizeof buf, v));
        if (out_of_range(d, f))
            return fail(x, line_of(v), path, "must be max or in [%g, %g], got %g", f->lo,
                        f->hi, d);
    }
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

/* simulation.stream.headway_s: 0 or null (stored as 0: the population's
 * timestamps) or seconds in the row's range. */
static int p_headway(ctx *x, yaml_node_t *v, const char *path, const field *f,
                     void *base)
{
    double d = 0.0;

    if (!is_null_node(v)) {
        if (get_double(x, v, path, &d))
            return -1;
        if (d != 0.0 && out_of_range(d, f))
            return fail(x, line_of(v), path, "must be 0 or null (the population's "
                        "timestamps) or in [%g, %g], got %g", f->lo, f->hi, d);
    }
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

/* simulation.damage_step_at: none or null (stored as −1) or a 0-based vehicle
 * index in the row's range, stored as an int. */
static int p_step(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const char *want = "none or a vehicle index";
    char buf[SHOW_LEN];
    const char *s;
    long l = -1;
    int i;

    if (!is_null_node(v)) {
        s = scalar(x, v, path, want, 1);
        if (!s)
            return -1;
        if (strcmp(s, "none") != 0) {
            if (!is_plain(v) || to_long(s, &l) != 0)
                return fail(x, line_of(v), path, "expected %s, got '%s'", want,
                            show(buf, sizeof buf, v));
            if ((double)l < f->lo || (double)l > f->hi)
                return fail(x, line_of(v), path, "must be none or %.0f .. %.0f, got %ld",
                            f->lo, f->hi, l);
        }
    }
    i = (int)l;
    memcpy((char *)base + f->off, &i, sizeof i);
    return 0;
}

/* simulation.preceding_gap: null or none (no preceding vehicle), a number
 * (lo = hi) or [lo, hi]; seconds, each in the row's range, lo <= hi. */
static int p_gap(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_sim_config *m = &((amfi_site_config *)base)->sim;
    double g[2] = {0.0, 0.0};
    char ip[PATH_LEN];
    int n = 1;

    if (is_null_node(v) || (v->type == YAML_SCALAR_NODE &&
                            v->data.scalar.length == 4 &&
                            memcmp(v->data.scalar.value, "none", 4) == 0)) {
        m->preceding = 0;
        m->gap_lo_s = m->gap_hi_s = 0.0;
        return 0;
    }
    if (v->type == YAML_SEQUENCE_NODE) {
        n = (int)(v->data.sequence.items.top - v->data.sequence.items.start);
        if (n != 2)
            return fail(x, line_of(v), path, "expected [lo, hi] (two numbers), got %d", n);
        for (int i = 0; i < 2; i++) {
            yaml_node_t *it =
                yaml_document_get_node(x->doc, v->data.sequence.items.start[i]);
            join_index(ip, path, (size_t)i);
            if (!it)
                return fail(x, line_of(v), ip, "malformed list");
            if (get_double(x, it, ip, &g[i]))
                return -1;
            if (out_of_range(g[i], f))
                return range_fail(x, it, ip, f, g[i]);
        }
    } else if (v->type == YAML_SCALAR_NODE) {
        if (get_double(x, v, path, &g[0]))
            return -1;
        if (out_of_range(g[0], f))
            return range_fail(x, v, path, f, g[0]);
        g[1] = g[0];
    } else {
        return fail(x, line_of(v), path, "expected null, a number or [lo, hi], got %s",
                    what(v));
    }
    if (g[0] > g[1])
        return fail(x, line_of(v), path, "lo (%g) must not exceed hi (%g)", g[0], g[1]);
    m->preceding = 1;
    m->gap_lo_s = g[0];
    m->gap_hi_s = g[1];
    return 0;
}

#define SIM(m) offsetof(amfi_site_config, sim.m)
#define SIM_CAP(m) sizeof(((amfi_sim_config *)0)->m)

/* simulation.profile -> profile_class ('A' .. 'H', 0 smooth) */
static const enum_name profile_names[] = {
    {"A", 'A'}, {"B", 'B'}, {"C", 'C'}, {"D", 'D'}, {"E", 'E'},
    {"F", 'F'}, {"G", 'G'}, {"H", 'H'}, {"smooth", 0}, {NULL, 0}};

static const field speed_error_fields[] = {
    {.key = "mean", .parse = p_double, .off = SIM(speed_err_mean), .lo = -0.5, .hi = 0.5},
    {.key = "std", .parse = p_double, .off = SIM(speed_err_std), .lo = 0, .hi = 0.5},
    {.key = NULL}};

static const field stream_fields[] = {
    {.key = "lcm_url", .parse = p_string, .off = SIM(lcm_url), .lo = 0,
     .hi = SIM_CAP(lcm_url)},
    {.key = "log", .parse = p_path, .off = SIM(log), .hi = SIM_CAP(log)},
    {.key = "speedup", .parse = p_speedup, .off = SIM(speedup), .lo = 0.01, .hi = 1e6},
    {.key = "headway_s", .parse = p_headway, .off = SIM(headway_s), .lo = 0.1,
     .hi = 3600},
    {.key = "noise_ms2", .parse = p_double, .off = SIM(noise_ms2), .lo = 0, .hi = 10},
    {.key = "block", .parse = p_int, .off = SIM(block), .lo = 1, .hi = 160},
    {.key = "start_utime", .parse = p_llong, .off = SIM(start_utime), .lo = 1,
     .hi = 4e15},
    {.key = "detector_lead_s", .parse = p_double, .off = SIM(detector_lead_s), .lo = 0,
     .hi = 60},
    {.key = NULL}};

static const field sim_fields[] = {
    {.key = "population", .parse = p_path, .off = SIM(population),
     .hi = SIM_CAP(population), .flags = F_FILE_DIR},
    {.key = "vehicles", .parse = p_int, .off = SIM(vehicles), .lo = 1, .hi = 1e7},
    {.key = "first", .parse = p_int, .off = SIM(first), .lo = 0, .hi = 1e7},
    {.key = "seed", .parse = p_llong, .off = SIM(seed), .lo = 0, .hi = 4294967295.0},
    {.key = "damage", .parse = p_double, .off = SIM(damage), .lo = 0, .hi = 0.9},
    {.key = "damage_step_at", .parse = p_step, .off = SIM(damage_step_at), .lo = 0,
     .hi = 1e7},
    {.key = "profile", .parse = p_enum, .off = SIM(profile_class), .aux = profile_names},
    {.key = "track_std", .parse = p_double, .off = SIM(track_std), .lo = 0, .hi = 100},
    {.key = "scan_rate_hz", .parse = p_double, .off = SIM(scan_rate_hz), .lo = 50,
     .hi = 20000},
    {.key = "noise", .parse = p_double, .off = SIM(noise), .lo = 0, .hi = 1},
    {.key = "speed_error", .parse = p_map, .aux = speed_error_fields},
    {.key = "preceding_gap", .parse = p_gap, .lo = -2, .hi = 30},
    {.key = "pre_s", .parse = p_double, .off = SIM(pre_s), .lo = 0, .hi = 30},
    {.key = "post_s", .parse = p_double, .off = SIM(post_s), .lo = 0, .hi = 30},
    {.key = "dt_s", .parse = p_double, .off = SIM(dt_s), .lo = 1e-6, .hi = 1e-3},
    {.key = "stream", .parse = p_map, .aux = stream_fields},
    {.key = NULL}};

/* The top level of a site file. */
static const field top_fields[] = {
    {.key = "bridge", .parse = p_map, .aux = bridge_fields},
    {.key = "sensors", .parse = p_sensors},
    {.key = "solver", .parse = p_map, .aux = solver_fields},
    {.key = "daemon", .parse = p_map, .aux = daemon_fields},
    {.key = "simulation", .parse = p_map, .aux = sim_fields},
    {.key = NULL}};

/* ---- the walk ----------------------------------------------------------- */

static void list_keys(char *buf, size_t len, const field *table)
{
    size_t used = 0;

    buf[0] = '\0';
    for (const field *f = table; f->key; f++)
        used = advance(used, snprintf(buf + used, len - used, "%s%s",
                                      f == table ? "" : ", ", f->key), len);
}

/* Parse mapping m (key path `path`, "" at the top) with `table` into base. */
static int walk_map(ctx *x, yaml_node_t *m, const char *path, const field *table,
                    void *base)
{
    int seen[MAX_FIELDS] = {0}; /* line of each row's key, 0: not given */
    char sub[PATH_LEN], known[256];
    int nf = 0;

    while (table[nf].key)
        nf++;
    if (nf > MAX_FIELDS)
        return fail(x, line_of(m), path, "internal: schema table too large");
    if (m->type != YAML_MAPPING_NODE)
        return fail(x, line_of(m), path, "expected a mapping (key: value), got %s",
                    what(m));
    for (yaml_node_pair_t *pr = m->data.mapping.pairs.start;
         pr < m->data.mapping.pairs.top; pr++) {
        yaml_node_t *k = yaml_document_get_node(x->doc, pr->key);
        yaml_node_t *v = yaml_document_get_node(x->doc, pr->value);
        int i;

        if (!k || !v)
            return fail(x, line_of(m), path, "malformed mapping");
        if (k->type != YAML_SCALAR_NODE)
            return fail(x, line_of(k), path, "a key must be a plain name, got %s",
                        what(k));
        join_key(sub, path, k);
        for (i = 0; i < nf; i++)
            if (strlen(table[i].key) == k->data.scalar.length &&
                memcmp(table[i].key, k->data.scalar.value, k->data.scalar.length) == 0)
                break;
        if (i == nf) {
            list_keys(known, sizeof known, table);
            return fail(x, line_of(k), sub, "unknown key (known: %s)", known);
        }
        if (seen[i])
            return fail(x, line_of(k), sub, "duplicate key (first at line %d)", seen[i]);
        seen[i] = line_of(k);
        note_line(x, sub, line_of(k));
        if (table[i].parse(x, v, sub, &table[i], base))
            return -1;
    }
    for (int i = 0; i < nf; i++)
        if ((table[i].flags & F_REQUIRED) && !seen[i]) {
            pathf(sub, "%s%s%s", path, *path ? "." : "", table[i].key);
            return fail(x, line_of(m), sub, "missing (required)");
        }
    return 0;
}

/* ---- checks across keys ------------------------------------------------- */

/* The first of the key paths that was given in the file, for a message. */
static int first_noted(const ctx *x, const char *a, const char *b, const char *c)
{
    int line = noted(x, a);

    if (!line && b)
        line = noted(x, b);
    if (!line && c)
        line = noted(x, c);
    return line;
}

static int check_site(ctx *x, amfi_site_config *c)
{
    amfi_bridge_params *b = &c->bridge;
    amfi_solver_params *s = &c->solver;
    amfi_lambda *l = &c->lambda;
    int node[AMFI_MAX_SUPPORTS];
    int restrained = 0, ndof;
    char p[PATH_LEN];

    /* Defaults that follow the span when the file does not list them. */
    if (!noted(x, "bridge.supports"))
        b->supports[b->n_supports - 1].x_m = b->span_m;
    if (!noted(x, "sensors"))
        s->sensor_x_m[0] = 0.5 * b->span_m;

    /* Supports: on the beam, one per node, and the beam not a mechanism. */
    for (int i = 0; i < b->n_supports; i++) {
        pathf(p, "bridge.supports[%d].at_m", i);
        if (b->supports[i].x_m > b->span_m)
            return fail(x, first_noted(x, p, "bridge.span_m", NULL), p,
                        "%g m is beyond the span (bridge.span_m = %g m)",
                        b->supports[i].x_m, b->span_m);
        node[i] = (int)lround(b->supports[i].x_m / b->span_m * b->n_elements);
        for (int j = 0; j < i; j++)
            if (node[j] == node[i])
                return fail(x, first_noted(x, p, "bridge.elements", NULL), p,
                            "falls on node %d (of %d elements), like "
                            "bridge.supports[%d]", node[i], b->n_elements, j);
        restrained += b->supports[i].restrain_w + b->supports[i].restrain_theta;
    }
    if (b->n_supports == 1 && !b->supports[0].restrain_theta)
        return fail(x, noted(x, "bridge.supports"), "bridge.supports",
                    "a single pinned or roller support leaves the beam free to "
                    "rotate; make it fixed or add a support");

    /* Mode numbers within the model's free DOFs. */
    ndof = 2 * (b->n_elements + 1) - restrained;
    if (b->rayleigh_mode_a > ndof || b->rayleigh_mode_b > ndof)
        return fail(x, first_noted(x, "bridge.damping.modes", "bridge.elements", NULL),
                    "bridge.damping.modes", "the model has only %d modes (free DOFs)",
                    ndof);
    if (s->modes == AMFI_MODES_COUNT && s->n_modes > ndof)
        return fail(x, noted(x, "solver.modes"), "solver.modes",
                    "%d modes asked, the model has only %d (free DOFs)", s->n_modes,
                    ndof);

    /* Sensors on the beam. */
    for (int i = 0; i < s->n_sensors; i++) {
        pathf(p, "sensors[%d].at_m", i);
        if (s->sensor_x_m[i] > b->span_m)
            return fail(x, first_noted(x, p, "bridge.span_m", NULL), p,
                        "%g m is beyond the span (bridge.span_m = %g m)",
                        s->sensor_x_m[i], b->span_m);
    }

    /* λ search grid. */
    if (!(l->lcurve_lo < l->lcurve_hi))
        return fail(x, first_noted(x, "solver.lcurve.hi", "solver.lcurve.lo",
                                   "solver.lcurve"),
                    "solver.lcurve", "lo (%g) must be below hi (%g)", l->lcurve_lo,
                    l->lcurve_hi);

    /* g_0 = 0 forces a ramp at entry unless the window starts before it. */
    if (s->fix_initial_force && !(s->pre_roll_s > 0))
        return fail(x, first_noted(x, "solver.initial_force", "solver.pre_roll_s", NULL),
                    "solver.initial_force", "zero needs solver.pre_roll_s > 0");
    if (s->free_initial_state && s->fix_initial_force)
        return fail(x, first_noted(x, "solver.initial_state", "solver.initial_force", NULL),
                    "solver.initial_state", "free needs solver.initial_force: free");
    if (s->free_initial_state && s->coords != AMFI_COORDS_MODAL)
        return fail(x, first_noted(x, "solver.initial_state", "solver.coordinates", NULL),
                    "solver.initial_state", "free needs solver.coordinates: modal");
    if (c->daemon.ind_std_clear_ratio > c->daemon.ind_std_alert_ratio)
        return fail(x, first_noted(x, "daemon.indicators.std_clear_ratio",
                                   "daemon.indicators.std_alert_ratio", NULL),
                    "daemon.indicators.std_clear_ratio", "must not exceed std_alert_ratio");
    if (c->daemon.ind_mean_clear_ratio > c->daemon.ind_mean_alert_ratio)
        return fail(x, first_noted(x, "daemon.indicators.mean_clear_ratio",
                                   "daemon.indicators.mean_alert_ratio", NULL),
                    "daemon.indicators.mean_clear_ratio", "must not exceed mean_alert_ratio");

    /* The simulator steps an integer number of times per sample (vbi.c);
     * blame dt_s, or scan_rate_hz when only the rate was given. */
    double sub = 1.0 / (c->sim.scan_rate_hz * c->sim.dt_s);
    if (fabs(sub - round(sub)) > 1e-9 * sub) {
        const char *k = !noted(x, "simulation.dt_s") && noted(x, "simulation.scan_rate_hz")
                            ? "simulation.scan_rate_hz" : "simulation.dt_s";
        return fail(x, noted(x, k), k, "1/(scan_rate_hz*dt_s) = %g steps per sample is "
                    "not an integer", sub);
    }
    return 0;
}

/* ---- entry points ------------------------------------------------------- */

void amfi_config_defaults(amfi_site_config *c)
{
    memset(c, 0, sizeof *c);
    memcpy(c->name, "paper-20m", sizeof "paper-20m");
    amfi_bridge_params_paper20(&c->bridge);
    amfi_solver_params_default(&c->solver, c->bridge.span_m);
    /* The site recommendation (docs/results/paper.md): the bridge may still
     * vibrate from earlier traffic, so its state is estimated with the
     * forces, from a window starting 0.3 s before the first axle enters. */
    c->solver.free_initial_state = 1;
    c->solver.pre_roll_s = 0.3;
    amfi_lambda_default(&c->lambda);
    for (int i = 0; i < AMFI_MAX_SENSORS; i++)
        c->sensor_id[i] = i < c->solver.n_sensors ? i : -1;
    amfi_daemon_config *d = &c->daemon;
    strcpy(d->ch_accel, "AMFI_ACCEL");
    strcpy(d->ch_vehicle, "AMFI_VEHICLE");
    strcpy(d->ch_truth, "AMFI_TRUTH");
    strcpy(d->ch_passage, "AMFI_PASSAGE");
    strcpy(d->ch_indicator, "AMFI_INDICATOR");
    strcpy(d->ch_alert, "AMFI_ALERT");
    strcpy(d->ch_status, "AMFI_STATUS");
    strcpy(d->db_path, "amfi.db");
    d->sync_full = 1;
    d->workers = 2;
    d->queue_size = 256;
    d->ring_s = 60.0;
    d->margin_s = 0.05;
    d->max_wait_s = 10.0;
    d->status_period_s = 1.0;
    /* amfi_indicator_params_default() (daemon/indicators.c) and the
     * simulation behind each value in docs/indicators.md */
    d->ind_window = 500;
    d->ind_every = 100;
    d->ind_baseline_n = 10000;
    d->ind_std_alert_ratio = 1.08;
    d->ind_std_alert_p = 0.01;
    d->ind_std_clear_ratio = 1.00;
    d->ind_raise_after = 6;
    d->ind_clear_after = 6;
    d->ind_mean_shift = 1;
    d->ind_mean_alert_ratio = 1.05;
    d->ind_mean_alert_p = 0.01;
    d->ind_mean_clear_ratio = 1.03;
    /* sim_publisher's ideal simulation (docs/simulator.md): every inaccuracy
     * is switched on explicitly. */
    amfi_sim_config *m = &c->sim;
    m->vehicles = 10;
    m->first = 0;
    m->seed = 1;
    m->damage = 0.0;
    m->damage_step_at = -1;
    m->profile_class = 'A';
    m->track_std = 2.0;
    m->scan_rate_hz = 1000.0;
    m->noise = 0.0;
    m->speed_err_mean = 0.0;
    m->speed_err_std = 0.0;
    m->preceding = 0;
    m->gap_lo_s = m->gap_hi_s = 0.0;
    m->pre_s = 0.5;
    m->post_s = 0.5;
    m->dt_s = 1e-4;
    m->speedup = 1.0;
    m->headway_s = 0.0;
    m->noise_ms2 = 0.0;
    m->block = 100;
    m->start_utime = 1767225600000000LL; /* 2026-01-01T00:00:00Z */
    m->detector_lead_s = 1.0;
}

/* Line (1-based) holding byte `offset` of buf[len]. */
static int line_at_offset(const unsigned char *buf, size_t len, size_t offset)
{
    int line = 1;

    for (size_t i = 0; i < offset && i < len; i++)
        line += buf[i] == '\n';
    return line;
}

static void yaml_error(ctx *x, const yaml_parser_t *p, const unsigned char *buf,
                       size_t len)
{
    const char *problem = p->problem ? p->problem : "unknown problem";

    switch (p->error) {
    case YAML_MEMORY_ERROR:
        fail(x, 0, NULL, "out of memory while reading YAML");
        break;
    case YAML_READER_ERROR: /* bad encoding: libyaml gives a byte offset */
        fail(x, line_at_offset(buf, len, p->problem_offset), NULL,
             "cannot read: %s (byte %zu)", problem, p->problem_offset);
        break;
    default: /* scanner, parser, composer */
        if (p->context)
            fail(x, (int)p->problem_mark.line + 1, NULL,
                 "YAML syntax error: %s (%s at line %d)", problem, p->context,
                 (int)p->context_mark.line + 1);
        else
            fail(x, (int)p->problem_mark.line + 1, NULL, "YAML syntax error: %s",
                 problem);
        break;
    }
}

/* First pass over the events, before any document is built: syntax errors,
 * nesting deeper than MAX_DEPTH, and a second document (which the loader
 * would silently ignore). The depth bound matters: libyaml's scanner is
 * quadratic in the flow nesting depth (100000 nested '[' take 30 s), and the
 * schema needs 4 levels; this pass stops at the first level too many. */
static int check_stream(ctx *x, const unsigned char *buf, size_t len)
{
    yaml_parser_t p;
    yaml_event_t ev;
    int depth = 0, docs = 0, rc = -1, done = 0;

    if (!yaml_parser_initialize(&p))
        return fail(x, 0, NULL, "out of memory");
    yaml_parser_set_input_string(&p, buf, len);
    while (!done) {
        int line;

        if (!yaml_parser_parse(&p, &ev)) {
            yaml_error(x, &p, buf, len);
            goto fail;
        }
        line = (int)ev.start_mark.line + 1;
        switch (ev.type) {
        case YAML_DOCUMENT_START_EVENT:
            docs++;
            break;
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT:
            depth++;
            break;
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            depth--;
            break;
        case YAML_STREAM_END_EVENT:
            done = 1;
            break;
        default:
            break;
        }
        yaml_event_delete(&ev);
        if (docs > 1) {
            fail(x, line, NULL, "a second YAML document; a site file holds one");
            goto fail;
        }
        if (depth > MAX_DEPTH) {
            fail(x, line, NULL, "nested deeper than %d levels", MAX_DEPTH);
            goto fail;
        }
    }
    rc = 0;
fail:
    yaml_parser_delete(&p);
    return rc;
}

int amfi_config_load(const char *path, amfi_site_config *c, char *err, size_t errlen)
{
    ctx *x = NULL;
    FILE *fp = NULL;
    unsigned char *buf = NULL;
    size_t len = 0;
    yaml_parser_t parser;
    yaml_document_t doc;
    int have_parser = 0, have_doc = 0, rc = -1, walk;
    yaml_node_t *root;
    amfi_site_config tmp;
    struct stat st;
    locale_t cloc, old;

    if (err && errlen)
        err[0] = '\0';
    if (!path || !c) {
        if (err && errlen)
            snprintf(err, errlen, "amfi_config_load: %s is NULL",
                     path ? "config" : "path");
        return -1;
    }
    x = calloc(1, sizeof *x);
    if (!x) {
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    x->file = path;
    x->err = err;
    x->errlen = errlen;

    /* The whole file in memory (at most MAX_FILE_BYTES), read by two passes. */
    fp = fopen(path, "rb");
    if (!fp) {
        fail(x, 0, NULL, "cannot open: %s", strerror(errno));
        goto fail;
    }
    if (fstat(fileno(fp), &st) != 0) {
        fail(x, 0, NULL, "cannot stat: %s", strerror(errno));
        goto fail;
    }
    if (!S_ISREG(st.st_mode)) {
        fail(x, 0, NULL, "not a regular file");
        goto fail;
    }
    if (st.st_size > MAX_FILE_BYTES) {
        fail(x, 0, NULL, "too large (%lld bytes, a site file is at most %ld)",
             (long long)st.st_size, MAX_FILE_BYTES);
        goto fail;
    }
    buf = malloc((size_t)st.st_size + 1);
    if (!buf) {
        fail(x, 0, NULL, "out of memory");
        goto fail;
    }
    len = fread(buf, 1, (size_t)st.st_size, fp);
    if (ferror(fp)) {
        fail(x, 0, NULL, "cannot read: %s", strerror(errno));
        goto fail;
    }
    fclose(fp);
    fp = NULL;

    if (check_stream(x, buf, len))
        goto fail;
    if (!yaml_parser_initialize(&parser)) {
        fail(x, 0, NULL, "out of memory");
        goto fail;
    }
    have_parser = 1;
    yaml_parser_set_input_string(&parser, buf, len);
    if (!yaml_parser_load(&parser, &doc)) {
        yaml_error(x, &parser, buf, len);
        goto fail;
    }
    have_doc = 1;
    root = yaml_document_get_root_node(&doc);
    if (!root) {
        fail(x, 1, NULL, "empty file: expected the sections bridge, sensors, solver");
        goto fail;
    }

    amfi_config_defaults(&tmp);
    x->doc = &doc;
    /* Parse numbers with a decimal point whatever the process locale. */
    cloc = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    old = cloc ? uselocale(cloc) : (locale_t)0;
    walk = walk_map(x, root, "", top_fields, &tmp);
    if (cloc) {
        uselocale(old);
        freelocale(cloc);
    }
    if (walk || check_site(x, &tmp))
        goto fail;
    memcpy(c, &tmp, sizeof tmp);
    rc = 0;

fail:
    if (have_doc)
        yaml_document_delete(&doc);
    if (have_parser)
        yaml_parser_delete(&parser);
    if (fp)
        fclose(fp);
    free(buf);
    free(x);
    return rc;
}
