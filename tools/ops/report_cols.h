/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_cols.h: a table amfi-report exports, described once as a list of
 * columns, written as CSV (RFC 4180: a header line, fields with a comma, a
 * quote or a line break quoted, quotes doubled, text that a spreadsheet
 * would read as a formula neutralised) and as JSON (libjansson objects, in
 * the list's order) by the same code (report_cols.c, which calls no other
 * report file). A column is added to both formats by one row of its list.
 *
 * Two shapes:
 *   record tables  one CSV line and one JSON object per row
 *                  (report_cols_csv_header, report_cols_csv_row,
 *                  report_cols_json_row): trend, alerts, passages,
 *                  overloads, histogram bins, speed days;
 *   item tables    the figures of one section, CSV "item,value" lines and
 *                  one JSON object whose members may be grouped into
 *                  sub-objects (report_cols_csv_items,
 *                  report_cols_json_items): summary, errors.
 */
#ifndef REPORT_COLS_H
#define REPORT_COLS_H

#include <stdint.h>
#include <stdio.h>

#include <jansson.h>

typedef enum report_col_type {
    COL_INT,   /* v.i: CSV "%lld", JSON integer */
    COL_NUM,   /* v.x: CSV fmt (empty when NaN), JSON number (null unless finite) */
    COL_TEXT,  /* v.s from the store: CSV quoted and neutralised, JSON string */
    COL_WORD,  /* v.s the program wrote (a time, a word): CSV as is, JSON string */
    COL_BOOL,  /* v.i: CSV 0 or 1, JSON true or false */
    COL_NUMS,  /* v.v[0 .. v.n−1]: CSV `width` columns (empty beyond v.n), JSON array */
    COL_INTS,  /* v.iv[0 .. v.n−1] likewise, integers */
    COL_COUNTS /* v.iv[k] under the key key(k): CSV one item each, JSON an object */
} report_col_type;

/* Where a column appears: CSV, JSON, or a second JSON view of the same
 * rows (the speed section's per-day objects). */
#define COL_CSV 1u
#define COL_JSON 2u
#define COL_JSON2 4u
#define COL_BOTH (COL_CSV | COL_JSON)
/* Item tables: the CSV writes the item even when its group is absent
 * (present() is 0): the JSON group is null, the CSV item as the accessor
 * says (empty, 0). */
#define COL_KEEP 8u

/* A value as the accessor gives it. null: CSV empty, JSON null. */
typedef struct report_val {
    int64_t i;
    double x;
    const char *s;
    const double *v;
    const int64_t *iv;
    int n;
    int null;
} report_val;

typedef struct report_col {
    const char *name;   /* CSV header or item; and JSON key unless json is set */
    report_col_type type;
    const char *unit;   /* "kg", "us", "m/s", "%", "Hz", "": what the value is in (the
                         * names say it too: mean_kg); for the reader of the list */
    const char *fmt;    /* CSV printf of a number (COL_NUM, COL_NUMS) */
    unsigned in;        /* COL_CSV | COL_JSON | COL_JSON2 */
    void (*get)(const void *row, report_val *v);
    const char *json;   /* JSON key when it differs from name, else NULL */
    const char *group;  /* item tables: the JSON sub-object it is in, or NULL */
    /* item tables: 0 makes the item's JSON group null (decided by the
     * group's first item) and leaves the item out of the CSV unless
     * COL_KEEP (NULL: always there) */
    int (*present)(const void *row);
    /* COL_NUMS, COL_INTS: the CSV header's pattern ("axle%d_kg") and its
     * number of columns (0: as many as labels given); COL_COUNTS: the key
     * of the k-th count (CSV "name_KEY") and how many */
    int width;
    const char *(*key)(int k);
} report_col;

/* A row of a column list: name, type, unit, CSV format, where, accessor,
 * then any of .json, .group, .present, .width, .key. */
#define REPORT_COL(name_, type_, unit_, fmt_, in_, get_, ...)                                     \
    {.name = (name_), .type = (type_), .unit = (unit_), .fmt = (fmt_), .in = (in_), .get = (get_), \
     __VA_ARGS__}

#define REPORT_NCOLS(a) (sizeof(a) / sizeof((a)[0]))

/* The CSV header line of a record table. labels (NULL: 1, 2, ...) number
 * the columns of COL_NUMS and COL_INTS (nlabels of them when the column's
 * width is 0). */
void report_cols_csv_header(FILE *f, const report_col *cols, size_t n, const int *labels,
                            int nlabels);
/* One CSV line of a record table. */
void report_cols_csv_row(FILE *f, const report_col *cols, size_t n, const void *row);
/* One JSON object of a record table: the columns marked `view` (COL_JSON or
 * COL_JSON2). NULL when out of memory. */
json_t *report_cols_json_row(const report_col *cols, size_t n, const void *row, unsigned view);

/* An item table: "item,value" then one line per item. */
void report_cols_csv_items(FILE *f, const report_col *cols, size_t n, const void *row);
/* An item table as one JSON object. */
json_t *report_cols_json_items(const report_col *cols, size_t n, const void *row);

/* A text field from the store into a CSV file (quoted and neutralised as
 * above). */
void report_csv_str(FILE *f, const char *s);

#endif /* REPORT_COLS_H */
