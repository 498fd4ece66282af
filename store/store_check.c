/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_check.c: the checks every argument passes before anything is
 * written (numbers in their ranges or NaN, UTF-8 text without control
 * characters within its length, words of the schema's lists), and the
 * helpers that bind, step and reset the prepared statements and run the
 * transactions. The caller's thread; no state of its own.
 */
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

/* ---- argument checks ----------------------------------------------------- */

int st_in_range(double x, const range *rg)
{
    return (rg->lo_open ? x > rg->lo : x >= rg->lo) && (rg->hi_open ? x < rg->hi : x <= rg->hi);
}

/* "NAME: X UNIT is out of range ..." (x finite, outside rg). */
int st_range_fail(const char *prefix, const char *name, double x,
                      const range *rg, int status, char *err, size_t errlen)
{
    const char *sp = rg->unit[0] ? " " : "";
    if (isinf(rg->hi))
        return st_fail(err, errlen, status, "%s%s: %g%s%s must be %s %g%s%s",
                    prefix, name, x, sp, rg->unit, rg->lo_open ? ">" : ">=",
                    rg->lo, sp, rg->unit);
    return st_fail(err, errlen, status, "%s%s: %g%s%s is out of range %c%g, %g%c%s%s",
                prefix, name, x, sp, rg->unit, rg->lo_open ? '(' : '[',
                rg->lo, rg->hi, rg->hi_open ? ')' : ']', sp, rg->unit);
}

/* x is NaN (unknown, stored as NULL) or finite and within rg. */
int st_check_num(const char *name, double x, const range *rg, char *err,
                     size_t errlen)
{
    if (isnan(x))
        return 0;
    if (isinf(x))
        return st_fail(err, errlen, AMFI_EINVAL, "%s: %g is not a finite number",
                    name, x);
    if (!st_in_range(x, rg))
        return st_range_fail("", name, x, rg, AMFI_EINVAL, err, errlen);
    return 0;
}

/* A number that must be known (not NaN). */
int st_check_known(const char *name, double x, const range *rg, char *err,
                       size_t errlen)
{
    if (isnan(x))
        return st_fail(err, errlen, AMFI_EINVAL, "%s: NaN, a value is needed",
                    name);
    return st_check_num(name, x, rg, err, errlen);
}

int st_check_utime(const char *name, int64_t t, char *err, size_t errlen)
{
    if (t < 0 || t > AMFI_STORE_MAX_UTIME)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "%s: %lld us is out of range [0, %lld] (1970 .. 9999 UTC)",
                    name, (long long)t, (long long)AMFI_STORE_MAX_UTIME);
    return 0;
}

/* Length of the valid UTF-8 prefix of s; *bad set when s holds a control
 * byte (< 0x20, 0x7f) or invalid UTF-8 (overlong, surrogate, > U+10FFFF). */
size_t st_utf8_scan(const unsigned char *s, size_t n, int *bad)
{
    size_t k = 0;
    *bad = 0;
    while (k < n) {
        unsigned c = s[k];
        int len;
        unsigned cp;
        if (c < 0x80) {
            if (c < 0x20 || c == 0x7f) {
                *bad = 1;
                return k;
            }
            k++;
            continue;
        }
        if (c >= 0xc2 && c <= 0xdf) { len = 2; cp = c & 0x1f; }
        else if (c >= 0xe0 && c <= 0xef) { len = 3; cp = c & 0x0f; }
        else if (c >= 0xf0 && c <= 0xf4) { len = 4; cp = c & 0x07; }
        else { *bad = 1; return k; }
        if (k + (size_t)len > n) { *bad = 1; return k; }
        for (int j = 1; j < len; j++) {
            unsigned cc = s[k + (size_t)j];
            if ((cc & 0xc0) != 0x80) { *bad = 1; return k; }
            cp = (cp << 6) | (cc & 0x3f);
        }
        if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff)))
            || (len == 4 && (cp < 0x10000 || cp > 0x10ffff))) {
            *bad = 1;
            return k;
        }
        k += (size_t)len;
    }
    return k;
}

/* s: valid UTF-8 text of min .. max bytes without control characters. */
int st_check_text(const char *name, const char *s, size_t min, size_t max,
                      char *err, size_t errlen)
{
    char ex[48];
    int bad;
    if (!s)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: NULL", name);
    size_t n = strlen(s);
    if (n < min)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: empty", name);
    if (n > max)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "%s: %zu bytes, at most %zu allowed ('%s')", name, n, max,
                    st_excerpt(s, ex));
    size_t ok = st_utf8_scan((const unsigned char *)s, n, &bad);
    if (bad)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "%s: control character or invalid UTF-8 at byte %zu ('%s')",
                    name, ok, st_excerpt(s, ex));
    return 0;
}

/* s is one of list (NULL-terminated); `shown` lists them for the message. */
int st_check_enum(const char *name, const char *s,
                      const char *const *list, const char *shown, char *err,
                      size_t errlen)
{
    char ex[48];
    if (!s)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: NULL (one of %s)", name,
                    shown);
    for (; *list; list++)
        if (strcmp(s, *list) == 0)
            return 0;
    return st_fail(err, errlen, AMFI_EINVAL, "%s: '%s' is not one of %s", name,
                st_excerpt(s, ex), shown);
}

/* s: 1 .. max bytes, each in `allowed` or alphanumeric (lower case only
 * when lower != 0). */
int st_check_token(const char *name, const char *s, size_t max,
                       const char *allowed, int lower, char *err,
                       size_t errlen)
{
    char ex[48];
    if (!s || !*s)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: empty", name);
    size_t n = strlen(s);
    if (n > max)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: '%s' is longer than %zu bytes",
                    name, st_excerpt(s, ex), max);
    for (size_t k = 0; k < n; k++) {
        unsigned char c = (unsigned char)s[k];
        int ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')
                 || (!lower && c >= 'A' && c <= 'Z')
                 || (c != 0 && strchr(allowed, c) != NULL);
        if (!ok)
            return st_fail(err, errlen, AMFI_EINVAL,
                        "%s: '%s' has a character outside [%s%s]", name,
                        st_excerpt(s, ex), lower ? "a-z0-9" : "A-Za-z0-9", allowed);
    }
    return 0;
}

int st_check_handle(const amfi_store *s, int write, char *err,
                        size_t errlen)
{
    if (!s)
        return st_fail(err, errlen, AMFI_EINVAL, "store: handle is NULL");
    if (write && s->readonly)
        return st_fail(err, errlen, AMFI_STORE_EDB,
                    "%s: store opened read-only", s->path);
    return 0;
}

int st_check_meta_key(const char *key, char *err, size_t errlen)
{
    return st_check_token("meta.key", key, AMFI_STORE_META_KEY_MAX, "_.-", 0, err,
                       errlen);
}

/* ---- statement helpers --------------------------------------------------- */

int st_bind_real(sqlite3_stmt *st, int i, double x)
{
    return isnan(x) ? sqlite3_bind_null(st, i) : sqlite3_bind_double(st, i, x);
}

/* The strings are the caller's and live until the statement is reset and
 * its bindings cleared (done before returning), hence SQLITE_STATIC. */
int st_bind_text(sqlite3_stmt *st, int i, const char *t)
{
    return t ? sqlite3_bind_text(st, i, t, -1, SQLITE_STATIC)
             : sqlite3_bind_null(st, i);
}

void st_done_with(sqlite3_stmt *st)
{
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
}

/* Step statement `which` (its values bound, sqlite_rc the bindings'
 * status) to completion: no row expected. Resets it. */
int st_run(amfi_store *s, int which, int sqlite_rc, const char *what,
               char *err, size_t errlen)
{
    sqlite3_stmt *st = s->st[which];
    int rc = 0;
    if (sqlite_rc == SQLITE_OK)
        sqlite_rc = sqlite3_step(st);
    else
        rc = st_fail(err, errlen, st_status_of(sqlite_rc), "%s: binding: %s", what,
                  sqlite3_errstr(sqlite_rc));
    if (rc == 0 && sqlite_rc != SQLITE_DONE)
        rc = sqlite_rc == SQLITE_ROW
                 ? st_fail(err, errlen, AMFI_STORE_EDB, "%s: unexpected row", what)
                 : st_db_fail(s, sqlite_rc, what, err, errlen);
    st_done_with(st);
    return rc;
}

int st_begin(amfi_store *s, char *err, size_t errlen)
{
    return st_run(s, ST_BEGIN, SQLITE_OK, "begin transaction", err, errlen);
}

int st_commit(amfi_store *s, char *err, size_t errlen)
{
    return st_run(s, ST_COMMIT, SQLITE_OK, "commit", err, errlen);
}

/* Undo the open transaction, if any (after a failure; keeps its message). */
void st_rollback(amfi_store *s)
{
    if (!sqlite3_get_autocommit(s->db)) {
        sqlite3_step(s->st[ST_ROLLBACK]);
        sqlite3_reset(s->st[ST_ROLLBACK]);
    }
}

/* One-off statement (open and migration only): run sql, every row ignored
 * except that the first row's first column goes to *ival / text (when not
 * NULL). */
int st_prepare(amfi_store *s, const char *sql, sqlite3_stmt **st, const char *what, char *err,
               size_t errlen)
{
    int src = sqlite3_prepare_v2(s->db, sql, -1, st, NULL);
    if (src != SQLITE_OK) {
        *st = NULL;
        return st_db_fail(s, src, what, err, errlen);
    }
    return 0;
}

int st_one_off(amfi_store *s, const char *sql, const char *what,
                   int64_t *ival, char *text, size_t textlen, char *err,
                   size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int src = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    int rc = 0, first = 1;
    if (src != SQLITE_OK)
        rc = st_db_fail(s, src, what, err, errlen);
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (first && ival)
            *ival = sqlite3_column_int64(st, 0);
        if (first && text && textlen > 0) {
            const unsigned char *t = sqlite3_column_text(st, 0);
            snprintf(text, textlen, "%s", t ? (const char *)t : "");
        }
        first = 0;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, what, err, errlen);
    sqlite3_finalize(st);
    return rc;
}
