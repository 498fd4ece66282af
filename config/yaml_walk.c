/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * yaml_walk.c: the site file as a YAML document, walked by tables of keys
 * (see yaml_walk.h), and the "FILE:LINE: key.path: problem" messages.
 *
 * The file (at most 1 MiB) is read into memory, checked once with libyaml's
 * event API (syntax, nesting depth, a single document), then loaded with the
 * document API (yaml_parser_load); every node keeps its start mark, so an
 * error names the line of the offending key or value. amfi_cfg_walk_map() does what
 * every mapping needs (type check, unknown, duplicate and required keys) and
 * records the line of every key path it sees, so that checks which involve
 * several keys, run once the whole file is read, can name the line they
 * blame. Runs on the caller's thread; the ctx is the only state.
 */
#include "yaml_walk.h"

#include <errno.h>
#include <locale.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_FILE_BYTES (1L << 20) /* a site file is a few kB; refuse odd inputs */
#define MAX_DEPTH 16              /* mapping/list nesting; the schema needs 4 */

/* ---- messages and key paths ---------------------------------------------- */

size_t amfi_cfg_advance(size_t used, int n, size_t len)
{
    if (n < 0)
        return used;
    if (used + (size_t)n >= len)
        return len - 1;
    return used + (size_t)n;
}

int amfi_cfg_fail(ctx *x, int line, const char *path, const char *fmt, ...)
{
    va_list ap;
    size_t used = 0;

    if (!x->err || x->errlen == 0)
        return -1;
    if (line > 0)
        used = amfi_cfg_advance(used, snprintf(x->err, x->errlen, "%s:%d: ", x->file, line),
                       x->errlen);
    else
        used = amfi_cfg_advance(used, snprintf(x->err, x->errlen, "%s: ", x->file), x->errlen);
    if (path && *path)
        used = amfi_cfg_advance(used, snprintf(x->err + used, x->errlen - used, "%s: ", path),
                       x->errlen);
    va_start(ap, fmt);
    vsnprintf(x->err + used, x->errlen - used, fmt, ap);
    va_end(ap);
    return -1;
}

int amfi_cfg_line_of(const yaml_node_t *n)
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
const char *amfi_cfg_show(char *buf, size_t len, const yaml_node_t *v)
{
    size_t n = v->data.scalar.length;

    sanitise(buf, len, (const char *)v->data.scalar.value, n);
    if (n >= len && len > 4)
        memcpy(buf + len - 4, "...", 4);
    return buf;
}

const char *amfi_cfg_what(const yaml_node_t *v)
{
    switch (v->type) {
    case YAML_MAPPING_NODE: return "a mapping";
    case YAML_SEQUENCE_NODE: return "a list";
    case YAML_SCALAR_NODE: return "a single value";
    default: return "nothing";
    }
}

/* A path that does not fit PATH_LEN is cut. */
void amfi_cfg_pathf(char *out, const char *fmt, ...)
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
        amfi_cfg_pathf(out, "%s.%s", path, key);
    else
        amfi_cfg_pathf(out, "%s", key);
}

void amfi_cfg_join_index(char *out, const char *path, size_t i)
{
    amfi_cfg_pathf(out, "%s[%zu]", path, i);
}

void amfi_cfg_note_line(ctx *x, const char *path, int line)
{
    /* A full record only loses the line number of a later cross-check error. */
    if (x->n_notes >= MAX_NOTES)
        return;
    amfi_cfg_pathf(x->notes[x->n_notes].path, "%s", path);
    x->notes[x->n_notes].line = line;
    x->n_notes++;
}

/* Line where key path `path` was given in the file, 0 when it was not. */
int amfi_cfg_noted(const ctx *x, const char *path)
{
    for (int i = 0; i < x->n_notes; i++)
        if (strcmp(x->notes[i].path, path) == 0)
            return x->notes[i].line;
    return 0;
}

/* The first of the key paths that was given in the file, for a message. */
int amfi_cfg_first_noted(const ctx *x, const char *a, const char *b, const char *c)
{
    int line = amfi_cfg_noted(x, a);

    if (!line && b)
        line = amfi_cfg_noted(x, b);
    if (!line && c)
        line = amfi_cfg_noted(x, c);
    return line;
}

/* The latest line of any key given under `prefix`. */
int amfi_cfg_noted_under(const ctx *x, const char *prefix)
{
    size_t n = strlen(prefix);
    int line = 0;

    for (int i = 0; i < x->n_notes; i++)
        if (strncmp(x->notes[i].path, prefix, n) == 0 && x->notes[i].line > line)
            line = x->notes[i].line;
    return line;
}

/* ---- the walk ------------------------------------------------------------ */

size_t amfi_cfg_append_name(char *buf, size_t len, size_t used, const char *name)
{
    return amfi_cfg_advance(used, snprintf(buf + used, len - used, "%s%s", used ? ", " : "", name),
                   len);
}

static void list_keys(char *buf, size_t len, const field *table)
{
    size_t used = 0;

    buf[0] = '\0';
    for (const field *f = table; f->key; f++)
        used = amfi_cfg_append_name(buf, len, used, f->key);
}

/* Parse mapping m (key path `path`, "" at the top) with `table` into base. */
int amfi_cfg_walk_map(ctx *x, yaml_node_t *m, const char *path, const field *table,
                    void *base)
{
    int seen[MAX_FIELDS] = {0}; /* line of each row's key, 0: not given */
    char sub[PATH_LEN], known[256];
    int nf = 0;

    while (table[nf].key)
        nf++;
    if (nf > MAX_FIELDS)
        return amfi_cfg_fail(x, amfi_cfg_line_of(m), path, "internal: schema table too large");
    if (m->type != YAML_MAPPING_NODE)
        return amfi_cfg_fail(x, amfi_cfg_line_of(m), path, "expected a mapping (key: value), got %s",
                    amfi_cfg_what(m));
    for (yaml_node_pair_t *pr = m->data.mapping.pairs.start;
         pr < m->data.mapping.pairs.top; pr++) {
        yaml_node_t *k = yaml_document_get_node(x->doc, pr->key);
        yaml_node_t *v = yaml_document_get_node(x->doc, pr->value);
        int i;

        if (!k || !v)
            return amfi_cfg_fail(x, amfi_cfg_line_of(m), path, "malformed mapping");
        if (k->type != YAML_SCALAR_NODE)
            return amfi_cfg_fail(x, amfi_cfg_line_of(k), path, "a key must be a plain name, got %s",
                        amfi_cfg_what(k));
        join_key(sub, path, k);
        for (i = 0; i < nf; i++)
            if (strlen(table[i].key) == k->data.scalar.length &&
                memcmp(table[i].key, k->data.scalar.value, k->data.scalar.length) == 0)
                break;
        if (i == nf) {
            list_keys(known, sizeof known, table);
            return amfi_cfg_fail(x, amfi_cfg_line_of(k), sub, "unknown key (known: %s)", known);
        }
        if (seen[i])
            return amfi_cfg_fail(x, amfi_cfg_line_of(k), sub, "duplicate key (first at line %d)", seen[i]);
        seen[i] = amfi_cfg_line_of(k);
        amfi_cfg_note_line(x, sub, amfi_cfg_line_of(k));
        if (table[i].kind->parse(x, v, sub, &table[i], base))
            return -1;
    }
    for (int i = 0; i < nf; i++)
        if ((table[i].flags & F_REQUIRED) && !seen[i]) {
            amfi_cfg_pathf(sub, "%s%s%s", path, *path ? "." : "", table[i].key);
            return amfi_cfg_fail(x, amfi_cfg_line_of(m), sub, "missing (required)");
        }
    return 0;
}

/* The items of list node v, checked to be 1 .. max long; NULL after amfi_cfg_fail(). */
static yaml_node_item_t *list_items(ctx *x, yaml_node_t *v, const char *path,
                                    const char *what_items, int max, int *n)
{
    ptrdiff_t len;

    if (v->type != YAML_SEQUENCE_NODE) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected a list of %s, got %s", what_items, amfi_cfg_what(v));
        return NULL;
    }
    len = v->data.sequence.items.top - v->data.sequence.items.start;
    if (len < 1 || len > max) {
        amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected 1 .. %d %s, got %td", max, what_items, len);
        return NULL;
    }
    *n = (int)len;
    return v->data.sequence.items.start;
}

int amfi_cfg_parse_list(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const list_schema *ls = f->aux;
    yaml_node_item_t *items;
    unsigned char *buf;
    char ip[PATH_LEN];
    int n = 0, rc = 0;

    items = list_items(x, v, path, ls->what, ls->max, &n);
    if (!items)
        return -1;
    buf = calloc((size_t)ls->max, ls->item_size);
    if (!buf)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "out of memory");
    for (int i = 0; i < n && rc == 0; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, items[i]);
        void *item = buf + (size_t)i * ls->item_size;

        amfi_cfg_join_index(ip, path, (size_t)i);
        if (!it) {
            rc = amfi_cfg_fail(x, amfi_cfg_line_of(v), ip, "malformed list");
            break;
        }
        amfi_cfg_note_line(x, ip, amfi_cfg_line_of(it));
        memcpy(item, ls->item_default, ls->item_size);
        rc = amfi_cfg_walk_map(x, it, ip, ls->items, item);
        if (rc == 0 && ls->check)
            rc = ls->check(x, it, ip, buf, i, base);
    }
    if (rc == 0)
        ls->store(buf, n, base);
    free(buf);
    return rc;
}

static int walk_rows(const field *table, const char *prefix, int items,
                     const void *item_default, int parent_live, row_visit visit, void *arg)
{
    char path[PATH_LEN];
    int rc;

    for (const field *f = table; f->key; f++) {
        const int live = item_default ? parent_live : (f->flags & F_LIVE) != 0;

        amfi_cfg_pathf(path, "%s%s%s", prefix, *prefix ? "." : "", f->key);
        if (f->kind->nest == NEST_MAP) {
            rc = walk_rows(f->aux, path, items, item_default, live, visit, arg);
        } else {
            rc = visit(path, f, item_default, live, arg);
            if (!rc && items && f->kind->nest == NEST_LIST) {
                const list_schema *ls = f->aux;
                amfi_cfg_pathf(path, "%s%s%s[]", prefix, *prefix ? "." : "", f->key);
                rc = walk_rows(ls->items, path, items, ls->item_default, live, visit, arg);
            }
        }
        if (rc)
            return rc;
    }
    return 0;
}

int amfi_cfg_walk_rows(const field *table, const char *prefix, int items, row_visit visit,
                       void *arg)
{
    return walk_rows(table, prefix, items, NULL, 0, visit, arg);
}

void amfi_cfg_describe_row(const field *f, const void *base, char *range, char *dflt)
{
    f->kind->range(f, base, range);
    if (base)
        f->kind->dflt(f, base, dflt);
    else
        dflt[0] = '\0';
    if ((f->flags & F_REQUIRED))
        snprintf(dflt, DOC_LEN, "required");
}

typedef struct describe_arg {
    const void *base;
    key_visit visit;
    void *arg;
} describe_arg;

static int describe_one(const char *path, const field *f, const void *item_default, int live,
                        void *arg)
{
    const describe_arg *da = arg;
    char range[DOC_LEN], dflt[DOC_LEN];

    (void)live;
    amfi_cfg_describe_row(f, item_default ? item_default : da->base, range, dflt);
    return da->visit(path, f->kind->type, range, dflt, (f->flags & F_REQUIRED) != 0, da->arg);
}

int amfi_cfg_describe_table(const field *table, const char *prefix, const void *base,
                            key_visit visit, void *arg)
{
    describe_arg da = {base, visit, arg};

    return amfi_cfg_walk_rows(table, prefix, 1, describe_one, &da);
}

/* ---- the file ------------------------------------------------------------ */

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
        amfi_cfg_fail(x, 0, NULL, "out of memory while reading YAML");
        break;
    case YAML_READER_ERROR: /* bad encoding: libyaml gives a byte offset */
        amfi_cfg_fail(x, line_at_offset(buf, len, p->problem_offset), NULL,
             "cannot read: %s (byte %zu)", problem, p->problem_offset);
        break;
    default: /* scanner, parser, composer */
        if (p->context)
            amfi_cfg_fail(x, (int)p->problem_mark.line + 1, NULL,
                 "YAML syntax error: %s (%s at line %d)", problem, p->context,
                 (int)p->context_mark.line + 1);
        else
            amfi_cfg_fail(x, (int)p->problem_mark.line + 1, NULL, "YAML syntax error: %s",
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
        return amfi_cfg_fail(x, 0, NULL, "out of memory");
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
            amfi_cfg_fail(x, line, NULL, "a second YAML document; a site file holds one");
            goto fail;
        }
        if (depth > MAX_DEPTH) {
            amfi_cfg_fail(x, line, NULL, "nested deeper than %d levels", MAX_DEPTH);
            goto fail;
        }
    }
    rc = 0;
fail:
    yaml_parser_delete(&p);
    return rc;
}

int amfi_cfg_walk_file(ctx *x, const field *top, void *base, int (*check)(ctx *x, void *base))
{
    FILE *fp = NULL;
    unsigned char *buf = NULL;
    size_t len = 0;
    yaml_parser_t parser;
    yaml_document_t doc;
    int have_parser = 0, have_doc = 0, rc = -1, walk;
    yaml_node_t *root;
    struct stat st;
    locale_t cloc, old;
    char known[256];

    /* The whole file in memory (at most MAX_FILE_BYTES), read by two passes. */
    fp = fopen(x->file, "rb");
    if (!fp) {
        amfi_cfg_fail(x, 0, NULL, "cannot open: %s", strerror(errno));
        goto fail;
    }
    if (fstat(fileno(fp), &st) != 0) {
        amfi_cfg_fail(x, 0, NULL, "cannot stat: %s", strerror(errno));
        goto fail;
    }
    if (!S_ISREG(st.st_mode)) {
        amfi_cfg_fail(x, 0, NULL, "not a regular file");
        goto fail;
    }
    if (st.st_size > MAX_FILE_BYTES) {
        amfi_cfg_fail(x, 0, NULL, "too large (%lld bytes, a site file is at most %ld)",
             (long long)st.st_size, MAX_FILE_BYTES);
        goto fail;
    }
    buf = malloc((size_t)st.st_size + 1);
    if (!buf) {
        amfi_cfg_fail(x, 0, NULL, "out of memory");
        goto fail;
    }
    len = fread(buf, 1, (size_t)st.st_size, fp);
    if (ferror(fp)) {
        amfi_cfg_fail(x, 0, NULL, "cannot read: %s", strerror(errno));
        goto fail;
    }
    fclose(fp);
    fp = NULL;

    if (check_stream(x, buf, len))
        goto fail;
    if (!yaml_parser_initialize(&parser)) {
        amfi_cfg_fail(x, 0, NULL, "out of memory");
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
        list_keys(known, sizeof known, top);
        amfi_cfg_fail(x, 1, NULL, "empty file: expected the sections %s", known);
        goto fail;
    }

    x->doc = &doc;
    /* Parse numbers with a decimal point whatever the process locale. */
    cloc = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    old = cloc ? uselocale(cloc) : (locale_t)0;
    walk = amfi_cfg_walk_map(x, root, "", top, base);
    if (cloc) {
        uselocale(old);
        freelocale(cloc);
    }
    if (walk || (check && check(x, base)))
        goto fail;
    rc = 0;

fail:
    x->doc = NULL;
    if (have_doc)
        yaml_document_delete(&doc);
    if (have_parser)
        yaml_parser_delete(&parser);
    if (fp)
        fclose(fp);
    free(buf);
    return rc;
}
