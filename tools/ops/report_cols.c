/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_cols.c: CSV and JSON of a column list (report_cols.h). Calls no
 * other report file.
 */
#include "report_cols.h"

#include <math.h>
#include <string.h>

#include "amfi_json.h"

/* Would a spreadsheet read this text cell as a formula? It starts, after
 * any blanks, with = + - @ (or their full-width forms U+FF1D U+FF0B
 * U+FF0D U+FF20), or with a tab, carriage return or line feed (the OWASP
 * CSV-injection set). */
static int csv_formula_like(const char *s)
{
    while (*s == ' ')
        s++;
    if (*s && strchr("=+-@\t\r\n", *s))
        return 1;
    const unsigned char *u = (const unsigned char *)s;
    return u[0] == 0xef && ((u[1] == 0xbc && (u[2] == 0x9d || u[2] == 0x8b || u[2] == 0x8d))
                            || (u[1] == 0xbc && u[2] == 0xa0));
}

/* A text field from the store, RFC 4180: quoted when it holds a comma, a
 * quote or a line break, and a cell that would start a formula neutralised
 * with a leading single quote (the text is still all there). Numbers are
 * written by csv_num and fprintf, never through here. */
void report_csv_str(FILE *f, const char *s)
{
    int neutral = csv_formula_like(s);
    if (!strpbrk(s, ",\"\r\n")) {
        if (neutral)
            fputc('\'', f);
        fputs(s, f);
        return;
    }
    fputc('"', f);
    if (neutral)
        fputc('\'', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* A number field: empty when unknown (NaN). */
static void csv_num(FILE *f, double x, const char *fmt)
{
    if (!isnan(x))
        fprintf(f, fmt, x);
}

/* ---- one value ------------------------------------------------------------- */

static void csv_value(FILE *f, const report_col *c, const report_val *v)
{
    if (v->null)
        return;
    switch (c->type) {
    case COL_INT:
    case COL_BOOL:
        fprintf(f, "%lld", (long long)v->i);
        break;
    case COL_NUM:
        csv_num(f, v->x, c->fmt);
        break;
    case COL_TEXT:
        report_csv_str(f, v->s ? v->s : "");
        break;
    case COL_WORD:
        fputs(v->s ? v->s : "", f);
        break;
    case COL_NUMS:
    case COL_INTS:
    case COL_COUNTS:
        break; /* written by the callers, one field per element */
    }
}

static json_t *json_value(const report_col *c, const report_val *v)
{
    if (v->null)
        return json_null();
    switch (c->type) {
    case COL_INT:
        return json_integer(v->i);
    case COL_BOOL:
        return json_boolean(v->i);
    case COL_NUM:
        return amfi_json_num(v->x);
    case COL_TEXT:
    case COL_WORD:
        return json_string(v->s ? v->s : "");
    case COL_NUMS: {
        json_t *a = json_array();
        for (int k = 0; a && k < v->n; k++)
            json_array_append_new(a, amfi_json_num(v->v[k]));
        return a;
    }
    case COL_INTS: {
        json_t *a = json_array();
        for (int k = 0; a && k < v->n; k++)
            json_array_append_new(a, json_integer(v->iv[k]));
        return a;
    }
    case COL_COUNTS: {
        json_t *o = json_object();
        for (int k = 0; o && k < c->width; k++)
            json_object_set_new(o, c->key(k), json_integer(v->iv[k]));
        return o;
    }
    }
    return json_null();
}

static const char *json_key(const report_col *c)
{
    return c->json ? c->json : c->name;
}

/* ---- record tables ------------------------------------------------------------- */

void report_cols_csv_header(FILE *f, const report_col *cols, size_t n, const int *labels,
                            int nlabels)
{
    int first = 1;
    for (size_t i = 0; i < n; i++) {
        const report_col *c = &cols[i];
        if (!(c->in & COL_CSV))
            continue;
        if (c->type == COL_NUMS || c->type == COL_INTS) {
            int w = c->width ? c->width : nlabels;
            for (int k = 0; k < w; k++) {
                if (!first)
                    fputc(',', f);
                fprintf(f, c->name, labels ? labels[k] : k + 1);
                first = 0;
            }
            continue;
        }
        fprintf(f, "%s%s", first ? "" : ",", c->name);
        first = 0;
    }
    fputc('\n', f);
}

void report_cols_csv_row(FILE *f, const report_col *cols, size_t n, const void *row)
{
    int first = 1;
    for (size_t i = 0; i < n; i++) {
        const report_col *c = &cols[i];
        if (!(c->in & COL_CSV))
            continue;
        report_val v;
        memset(&v, 0, sizeof v);
        c->get(row, &v);
        if (c->type == COL_NUMS || c->type == COL_INTS) {
            int w = c->width ? c->width : v.n;
            for (int k = 0; k < w; k++) {
                if (!first)
                    fputc(',', f);
                first = 0;
                if (k >= v.n)
                    continue;
                if (c->type == COL_NUMS)
                    csv_num(f, v.v[k], c->fmt);
                else
                    fprintf(f, "%lld", (long long)v.iv[k]);
            }
            continue;
        }
        if (!first)
            fputc(',', f);
        first = 0;
        csv_value(f, c, &v);
    }
    fputc('\n', f);
}

json_t *report_cols_json_row(const report_col *cols, size_t n, const void *row, unsigned view)
{
    json_t *o = json_object();
    for (size_t i = 0; o && i < n; i++) {
        const report_col *c = &cols[i];
        if (!(c->in & view))
            continue;
        report_val v;
        memset(&v, 0, sizeof v);
        c->get(row, &v);
        json_object_set_new(o, json_key(c), json_value(c, &v));
    }
    return o;
}

/* ---- item tables --------------------------------------------------------------- */

void report_cols_csv_items(FILE *f, const report_col *cols, size_t n, const void *row)
{
    fputs("item,value\n", f);
    for (size_t i = 0; i < n; i++) {
        const report_col *c = &cols[i];
        if (!(c->in & COL_CSV) || (c->present && !(c->in & COL_KEEP) && !c->present(row)))
            continue;
        report_val v;
        memset(&v, 0, sizeof v);
        c->get(row, &v);
        if (c->type == COL_COUNTS) {
            for (int k = 0; k < c->width; k++)
                fprintf(f, "%s_%s,%lld\n", c->name, c->key(k), (long long)v.iv[k]);
            continue;
        }
        fprintf(f, "%s,", c->name);
        csv_value(f, c, &v);
        fputc('\n', f);
    }
}

json_t *report_cols_json_items(const report_col *cols, size_t n, const void *row)
{
    json_t *o = json_object(), *g = NULL;
    const char *gname = NULL;
    int gnull = 0;
    for (size_t i = 0; o && i < n; i++) {
        const report_col *c = &cols[i];
        if (!(c->in & COL_JSON))
            continue;
        if (!c->group) {
            g = NULL;
            gname = NULL;
        } else if (!gname || strcmp(gname, c->group) != 0) {
            /* a new group: an object, or null when its items are absent */
            gname = c->group;
            gnull = c->present && !c->present(row);
            g = gnull ? NULL : json_object();
            json_object_set_new(o, gname, g ? g : json_null()); /* o holds g */
        }
        if (c->group && gnull)
            continue;
        report_val v;
        memset(&v, 0, sizeof v);
        c->get(row, &v);
        json_object_set_new(g ? g : o, json_key(c), json_value(c, &v));
    }
    return o;
}
