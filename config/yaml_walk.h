/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * yaml_walk.h: the generic half of the site-file loader (internal to
 * config/): a YAML document walked by tables of keys, strict scalar parsers,
 * and "FILE:LINE: key.path: problem" messages. It knows nothing about
 * bridges or daemons; the sections (section_*.c) describe their keys with
 * the `field` rows below and amfi_config.c puts them together.
 *
 * yaml_walk.c: document loading, the walk of a mapping, key paths, the
 *   record of where each key was seen, messages.
 * yaml_scalar.c: the strict scalar parsers and the generic value kinds
 *   (number, integer, name from a list, string, file path, mapping), each
 *   with its parser and its description for the manual (amfi_config_keys.h).
 *
 * Workload and ownership: one ctx per amfi_config_load call, on the caller's
 * thread; no global state. The walk is bounded by the schema, not by the
 * document: it descends only where a table has a mapping or a list, and
 * lists have bounded length, so self-referencing aliases or deep nesting
 * cannot make it loop or recurse.
 */
#ifndef AMFI_YAML_WALK_H
#define AMFI_YAML_WALK_H

#include <stddef.h>

#include <yaml.h>

#define PATH_LEN 96   /* key paths such as "bridge.supports[15].at_m" */
#define MAX_NOTES 256 /* key paths remembered for cross-checks */
#define MAX_FIELDS 32 /* rows per table */
#define SHOW_LEN 40   /* bytes of an offending value quoted in a message */
#define DOC_LEN 160   /* a key's type, range or default, as the manual shows it */

typedef struct note {
    char path[PATH_LEN];
    int line; /* 1-based line of the key */
} note;

typedef struct ctx {
    const char *file;     /* as the caller named it, for messages */
    yaml_document_t *doc; /* the loaded document, owned by the loader */
    char *err;            /* caller's buffer, may be NULL */
    size_t errlen;
    int n_notes;
    note notes[MAX_NOTES]; /* every key path seen, with its line */
} ctx;

typedef struct field field;

/* Parse value node v of key path `path` into base (the struct the row's
 * offsets are relative to). 0 ok, −1 after amfi_cfg_fail(). */
typedef int (*parse_fn)(ctx *x, yaml_node_t *v, const char *path, const field *f,
                        void *base);

/* Describe row f for the manual into buf[DOC_LEN]: its allowed values, or
 * (with base = the defaults) its default value. */
typedef void (*describe_fn)(const field *f, const void *base, char *buf);

enum { NEST_NONE, NEST_MAP, NEST_LIST };

/* Bytes [off, off + len) of the struct a row's offsets are relative to. */
typedef struct span {
    size_t off, len;
} span;

#define MAX_SPANS 6 /* spans of one key's value (sensors: five) */

/* Where row f's value lives: fills out[0 .. n) and returns n (1 .. MAX_SPANS).
 * Everything the row's parse writes lies in these spans and nothing of any
 * other row does, so two configurations hold the same value of the key
 * exactly when the spans' bytes are equal (amfi_config_diff), and copying
 * them copies the key (amfi_config_apply_live). */
typedef int (*spans_fn)(const field *f, span *out);

/* A kind of value: how to read it and how to describe it. */
typedef struct kind {
    const char *type;     /* for the manual: "number", "integer", ... */
    parse_fn parse;
    describe_fn range;    /* the allowed values */
    describe_fn dflt;     /* the value at base (the defaults) */
    int nest;             /* NEST_MAP: aux is a field[] under this key;
                             NEST_LIST: aux is a list_schema for its items */
    spans_fn spans;       /* where the value lives (NULL for NEST_MAP) */
} kind;

/* A list of mappings (bridge.supports, sensors): the table of an item's
 * keys, an item holding their defaults, and what to do with the items read.
 * amfi_cfg_parse_list (the parse of every list kind) reads 1 .. max items,
 * each a mapping walked with `items` over a copy of item_default into an
 * array of item_size-byte items, calls check after each item and store once
 * with them all; the sections write only check and store. */
typedef struct list_schema {
    const field *items;
    const void *item_default;
    size_t item_size;
    int max;            /* items at most */
    const char *what;   /* "supports": for "expected 1 .. max supports" */
    /* Item i (key path ip, node it) read, items[0 .. i] so far: the checks
     * between an item's keys and against the earlier items; NULL: none.
     * 0, or -1 after amfi_cfg_fail(). Writes nothing to base. */
    int (*check)(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                 const void *base);
    /* The n items read into base (the caller's struct). */
    void (*store)(const void *items, int n, void *base);
} list_schema;

#define F_LO_OPEN 1u  /* lo itself is not allowed */
#define F_HI_OPEN 2u  /* hi itself is not allowed */
#define F_REQUIRED 4u /* the key must be present (list items) */
#define F_FILE_DIR 8u /* amfi_cfg_k_path: a relative path is joined to the file's folder */
#define F_LIVE 16u    /* SIGHUP applies the key at once (amfi_config_apply_live);
                         without it the key applies at the next start. List
                         items take their list's flag. */

struct field {
    const char *key;   /* NULL ends a table */
    const kind *kind;
    size_t off;        /* destination, bytes from base */
    double lo, hi;     /* amfi_cfg_k_double, amfi_cfg_k_int, ...: allowed range (HUGE_VAL: none);
                          amfi_cfg_k_string, amfi_cfg_k_path: lo minimum length, hi capacity */
    unsigned flags;    /* F_* */
    const void *aux;   /* amfi_cfg_k_map and lists: const field[]; amfi_cfg_k_enum: const enum_name[] */
};

typedef struct enum_name {
    const char *name; /* NULL ends the list */
    int value;
} enum_name;

/* ---- messages and key paths (yaml_walk.c) ---- */

/* Write "FILE[:LINE]: [path: ]message" into the caller's buffer; returns −1.
 * line <= 0 omits the line, an empty path omits the path. */
int amfi_cfg_fail(ctx *x, int line, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int amfi_cfg_line_of(const yaml_node_t *n);
const char *amfi_cfg_show(char *buf, size_t len, const yaml_node_t *v); /* a value, sanitised */
const char *amfi_cfg_what(const yaml_node_t *v); /* "a mapping", "a list", ... */
size_t amfi_cfg_advance(size_t used, int n, size_t len); /* snprintf bookkeeping */
/* Append ", name" (or "name" at used = 0) to buf[len]; the new length. */
size_t amfi_cfg_append_name(char *buf, size_t len, size_t used, const char *name);
void amfi_cfg_pathf(char *out, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void amfi_cfg_join_index(char *out, const char *path, size_t i);
void amfi_cfg_note_line(ctx *x, const char *path, int line);
int amfi_cfg_noted(const ctx *x, const char *path); /* line of key path, 0: not given */
/* The line of the first of a, b, c (b and c may be NULL) given in the file. */
int amfi_cfg_first_noted(const ctx *x, const char *a, const char *b, const char *c);
/* The latest line of any key given under `prefix` ("daemon.indicators."). */
int amfi_cfg_noted_under(const ctx *x, const char *prefix);

/* Parse mapping m (key path `path`, "" at the top) with `table` into base:
 * type check, unknown, duplicate and required keys, then each row's kind. */
int amfi_cfg_walk_map(ctx *x, yaml_node_t *m, const char *path, const field *table, void *base);

/* The parse of every list kind: list node v (key path `path`) read with row
 * f's list_schema (f->aux) into base; 0, or -1 after amfi_cfg_fail() (base
 * untouched). */
int amfi_cfg_parse_list(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base);

/* Read `path` (at most 1 MiB, a single YAML document nested at most 16
 * deep), walk its root with `top` into base in the C numeric locale, then
 * run check(x, base) if not NULL. 0 ok, −1 after amfi_cfg_fail(). */
int amfi_cfg_walk_file(ctx *x, const field *top, void *base, int (*check)(ctx *x, void *base));

/* Call visit once per key of `table` and of the tables under it, depth
 * first, in table order, with the key's path ("solver.lcurve.lo", list
 * items as "sensors[].at_m"), kind name, allowed values and default (from
 * base; "required" for a required item key). Stops at and returns the first
 * non-zero value of visit. */
typedef int (*key_visit)(const char *path, const char *type, const char *range,
                         const char *dflt, int required, void *arg);
int amfi_cfg_describe_table(const field *table, const char *prefix, const void *base,
                   key_visit visit, void *arg);

/* Call visit once per key of `table` and of the mappings under it, depth
 * first, in table order, with the key's path, its row and whether it is
 * live (F_LIVE; list items: their list's flag). With items = 1 the keys of
 * a list's items follow their list (path "sensors[].at_m", item_default
 * the list's item of defaults, which the rows' offsets are relative to);
 * item_default is NULL for every other key. Stops at and returns the first
 * non-zero value of visit. */
typedef int (*row_visit)(const char *path, const field *f, const void *item_default, int live,
                         void *arg);
int amfi_cfg_walk_rows(const field *table, const char *prefix, int items, row_visit visit,
                       void *arg);

/* Row f described for the manual: its allowed values into range[DOC_LEN]
 * and its value at base (the defaults; NULL: none) into dflt[DOC_LEN],
 * "required" for a required key. */
void amfi_cfg_describe_row(const field *f, const void *base, char *range, char *dflt);

/* Generic spans: a double, an int, a long long at f->off, char[f->hi] at f->off. */
int amfi_cfg_spans_double(const field *f, span *out);
int amfi_cfg_spans_int(const field *f, span *out);
int amfi_cfg_spans_llong(const field *f, span *out);
int amfi_cfg_spans_chars(const field *f, span *out);

/* ---- scalars and kinds (yaml_scalar.c) ---- */

int amfi_cfg_is_plain(const yaml_node_t *v);
int amfi_cfg_is_null_node(const yaml_node_t *v); /* `key:`, `~`, `null` */
/* The text of scalar node v, or NULL after an error saying what was `want`ed.
 * Numbers must be plain (unquoted) scalars: allow_quoted = 0. */
const char *amfi_cfg_scalar(ctx *x, const yaml_node_t *v, const char *path, const char *want,
                   int allow_quoted);
/* Strict decimal parsers: 0 ok, −1 not a number, −2 out of range. */
int amfi_cfg_to_double(const char *s, double *out);
int amfi_cfg_to_llong(const char *s, long long *out);
int amfi_cfg_to_long(const char *s, long *out);
int amfi_cfg_get_double(ctx *x, const yaml_node_t *v, const char *path, double *out);
/* A name (quoted or not) of 1 .. cap − 1 bytes without control characters
 * into dst[cap] (zero-filled); 0, or −1 after amfi_cfg_fail(). */
int amfi_cfg_get_name(ctx *x, const yaml_node_t *v, const char *path, char *dst, size_t cap);
int amfi_cfg_get_long(ctx *x, const yaml_node_t *v, const char *path, long *out);
/* A plain number in scalar v (already checked by amfi_cfg_scalar()), else "expected
 * `want`" or "number out of range"; 0 or −1 after amfi_cfg_fail(). */
int amfi_cfg_get_number(ctx *x, const yaml_node_t *v, const char *path, const char *want,
               double *out);
int amfi_cfg_out_of_range(double d, const field *f);
int amfi_cfg_range_fail(ctx *x, const yaml_node_t *v, const char *path, const field *f, double d);
/* Row f's [lo, hi] as the messages write it: "[0, 1)", "> 0", "1 .. 64". */
void amfi_cfg_describe_interval(const field *f, char *buf);
void amfi_cfg_describe_count(const field *f, char *buf);
void amfi_cfg_describe_names(const enum_name *names, char *buf); /* "a | b | c" */
const char *amfi_cfg_enum_label(const enum_name *names, int value); /* NULL: not listed */

extern const kind amfi_cfg_k_double; /* double at off, in [lo, hi] (F_*_OPEN) */
extern const kind amfi_cfg_k_int;    /* int at off, lo .. hi */
extern const kind amfi_cfg_k_llong;  /* long long at off, lo .. hi */
extern const kind amfi_cfg_k_enum;   /* int at off, one of aux's names */
extern const kind amfi_cfg_k_string; /* char[hi] at off, printable, lo .. hi − 1 bytes */
extern const kind amfi_cfg_k_path;   /* char[hi] at off; "" or null: none */
extern const kind amfi_cfg_k_map;    /* a mapping walked with aux's table */

#endif /* AMFI_YAML_WALK_H */
