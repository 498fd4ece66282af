/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_internal.h: what the store's own files share (store_*.c), never
 * included outside store/: the handle's layout, the prepared statements,
 * the ranges and word lists of the checks, and the helpers that write
 * messages, check arguments, run statements and read values back.
 * Threads: as store.h: a handle is used by one thread at a time.
 */
#ifndef AMFI_STORE_INTERNAL_H
#define AMFI_STORE_INTERNAL_H

#include <math.h>
#include <sqlite3.h>
#include <stddef.h>
#include <stdint.h>

#include "store.h"
#include "store_columns.h"

/* ---- schema (store_schema.c) --------------------------------------------- */

typedef struct st_migration {
    int version;             /* user_version once applied, 1, 2, ... */
    const char *description; /* recorded in schema_migrations */
    const char *sql;         /* one or more statements */
} st_migration;

extern const st_migration st_migrations[];
extern const int st_n_migrations;

/* ---- prepared statements (store_open.c) ---------------------------------- */

enum {
    ST_BEGIN,
    ST_COMMIT,
    ST_ROLLBACK,
    ST_INS_PASSAGE,
    ST_INS_AXLE,
    ST_INS_TRUTH,
    ST_INS_TRUTH_AXLE,
    ST_INS_INDICATOR,
    ST_INS_ALERT,
    ST_GET_BASELINE,
    ST_INS_BASELINE,
    ST_RECENT_OK,
    ST_META_GET,
    ST_META_SET,
    ST_INTEGRITY,
    ST_FK_CHECK,
    ST_INS_RUN,
    ST_ALERT_LAST_OF_KIND,
    ST_COUNT_PASSAGES,
    ST_COUNT_INDICATORS,
    ST_COUNT_ALERTS,
    ST_COUNT_TRUTH,
    ST_PASSAGE_SPAN,
    ST_PASSAGE_BY_STATUS,
    ST_ALL_OK_GVW,
    ST_ALL_FED_GVW,
    ST_RECENT_INDICATORS,
    ST_RECENT_ALERTS,
    ST_OPEN_ALERTS,
    ST_GVW_ERRORS,
    N_STMT
};

struct amfi_store {
    sqlite3 *db;
    int readonly;                /* opened with amfi_store_open_readonly */
    sqlite3_stmt *st[N_STMT];    /* prepared at open, reset after each use */
    char path[256];              /* for messages (truncated) */
    struct st_raw *raw;          /* the raw samples' buffers and statements
                                    (store_raw.c), NULL until the first write */
};

/* ---- messages (store_open.c) --------------------------------------------- */

/* Writes the message into err (when there is room) and returns status. */
int st_fail(char *err, size_t errlen, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* At most 40 bytes of s, control bytes as '?', "..." when cut. */
const char *st_excerpt(const char *s, char out[48]);
/* SQLite result code (extended) to amfi status. */
int st_status_of(int sqlite_rc);
/* "WHAT: sqlite's message" for a failed call on s->db. */
int st_db_fail(amfi_store *s, int sqlite_rc, const char *what, char *err,
               size_t errlen);

/* ---- argument checks (store_check.c) ------------------------------------- */

/* Closed or half-open range of a number. */
typedef struct range {
    double lo, hi;   /* bounds; hi may be HUGE_VAL (no upper bound) */
    int lo_open;     /* 1: x > lo, 0: x >= lo */
    const char *unit;
    int hi_open;     /* 1: x < hi, 0: x <= hi */
} range;

static const range R_SPEED = {0.0, AMFI_STORE_MAX_SPEED_MPS, 0, "m/s", 0};
static const range R_SPEED_POS = {0.0, AMFI_STORE_MAX_SPEED_MPS, 1, "m/s", 0};
static const range R_SPACING = {0.0, AMFI_STORE_MAX_SPACING_M, 1, "m", 0};
static const range R_KG = {-AMFI_STORE_MAX_KG, AMFI_STORE_MAX_KG, 0, "kg", 0};
static const range R_KG_POS = {0.0, AMFI_STORE_MAX_KG, 1, "kg", 0};
static const range R_KG_NONNEG = {0.0, AMFI_STORE_MAX_KG, 0, "kg", 0};
static const range R_FORCE = {-AMFI_STORE_MAX_FORCE_N, AMFI_STORE_MAX_FORCE_N, 0, "N", 0};
static const range R_POS = {0.0, HUGE_VAL, 1, "", 0};
static const range R_NONNEG = {0.0, HUGE_VAL, 0, "", 0};
static const range R_MS = {0.0, HUGE_VAL, 0, "ms", 0};
static const range R_RATIO = {0.0, 1e6, 0, "", 0};
static const range R_PROB = {0.0, 1.0, 0, "", 0};
static const range R_QUALITY = {1.0, 1e9, 0, "", 0};
static const range R_REF_KG = {AMFI_STORE_MIN_REF_KG, AMFI_STORE_MAX_REF_KG, 0, "kg", 0};
static const range R_TEMP_C = {AMFI_STORE_MIN_TEMP_C, AMFI_STORE_MAX_TEMP_C, 0, "°C", 0};
static const range R_HZ = {0.0, 1000.0, 1, "Hz", 0};
static const range R_ZETA = {0.0, 1.0, 0, "", 1};
static const range R_FINITE = {-HUGE_VAL, HUGE_VAL, 0, "", 0};

/* NULL-terminated word lists of the schema's enumerations. */
static const char *const st_statuses[] = {"ok", "gap", "late", "overload",
                                          "multiple", "invalid", "error", NULL};
static const char *const st_states[] = {"baseline", "normal", "watch", "alert",
                                        NULL};
static const char *const st_levels[] = {"info", "warning", NULL};
static const char *const st_sources[] = {"auto", "manual", NULL};

int st_in_range(double x, const range *rg);
int st_range_fail(const char *prefix, const char *name, double x,
                  const range *rg, int status, char *err, size_t errlen);
int st_check_num(const char *name, double x, const range *rg, char *err,
                 size_t errlen);
int st_check_known(const char *name, double x, const range *rg, char *err,
                   size_t errlen);
int st_check_utime(const char *name, int64_t t, char *err, size_t errlen);
size_t st_utf8_scan(const unsigned char *s, size_t n, int *bad);
int st_check_text(const char *name, const char *s, size_t min, size_t max,
                  char *err, size_t errlen);
int st_check_enum(const char *name, const char *s, const char *const *list,
                  const char *shown, char *err, size_t errlen);
int st_check_token(const char *name, const char *s, size_t max,
                   const char *allowed, int lower, char *err, size_t errlen);
int st_check_handle(const amfi_store *s, int write, char *err, size_t errlen);
int st_check_meta_key(const char *key, char *err, size_t errlen);

/* ---- statement helpers (store_check.c) ----------------------------------- */

int st_bind_real(sqlite3_stmt *st, int i, double x);
int st_bind_text(sqlite3_stmt *st, int i, const char *t);
void st_done_with(sqlite3_stmt *st);
int st_run(amfi_store *s, int which, int sqlite_rc, const char *what,
           char *err, size_t errlen);
int st_begin(amfi_store *s, char *err, size_t errlen);
int st_commit(amfi_store *s, char *err, size_t errlen);
void st_rollback(amfi_store *s);
/* Prepare sql on the handle's connection (*st NULL on failure). */
int st_prepare(amfi_store *s, const char *sql, sqlite3_stmt **st, const char *what, char *err,
               size_t errlen);
int st_one_off(amfi_store *s, const char *sql, const char *what,
               int64_t *ival, char *text, size_t textlen, char *err,
               size_t errlen);

/* ---- reads: every value checked (store_read.c) --------------------------- */

/* Where a value read back came from, for the message; rowid < 0: an
 * aggregate (no row). */
typedef struct origin {
    const char *table;
    int64_t rowid;
} origin;

int st_corrupt(const origin *o, sqlite3_stmt *st, int col, char *err,
               size_t errlen, const char *problem);
int st_read_real(sqlite3_stmt *st, int col, const range *rg,
                 const origin *o, double *out, char *err, size_t errlen);
/* The same, NULL read as NaN. */
int st_read_real_or_null(sqlite3_stmt *st, int col, const range *rg,
                         const origin *o, double *out, char *err,
                         size_t errlen);
int st_read_int(sqlite3_stmt *st, int col, int64_t lo, int64_t hi,
                const origin *o, int64_t *out, char *err, size_t errlen);
int st_read_text(sqlite3_stmt *st, int col, size_t max, const origin *o,
                 char *buf, size_t buflen, char *err, size_t errlen);

/* One row of st into *rec, a record of the caller's type (ctx: the
 * caller's, passed through). */
typedef int (*st_row_fn)(sqlite3_stmt *st, const void *ctx, void *rec, char *err,
                         size_t errlen);
/* Step st (prepared and bound) to its end, each row read by `row` into a
 * growing array of `size`-byte records (the first allocation holds cap0);
 * then finalize st. rc 0 with rows: *arr (malloc'd, the caller's) and *n;
 * no row or a failure: *arr NULL, *n 0. A database failure names `what`
 * ("passages: read residuals"), running out of memory "out of memory for
 * N <noun>". */
int st_collect(amfi_store *s, sqlite3_stmt *st, st_row_fn row, const void *ctx, size_t size,
               size_t cap0,
               const char *what, const char *noun, void **arr, size_t *n, char *err,
               size_t errlen);
/* *yes 1 when the store has table `name` (a store older than the table's
 * schema version has none); failures name "raw samples: schema". */
int st_has_table(amfi_store *s, const char *name, int *yes, char *err, size_t errlen);
/* Step st (columns idx, spacing_m, load_kg of passage `id`'s axles, bound)
 * into r->spacing_m and r->axle_kg (idx 1 .. r->n_axles); *seen (may be
 * NULL) the rows read; a database failure names `what`. Does not finalize. */
int st_read_axles(amfi_store *s, sqlite3_stmt *st, int64_t id, amfi_passage_row *r, int *seen,
                  const char *what, char *err, size_t errlen);

/* ---- rows from the column table (store_rows.c) --------------------------- */

/* amfi_store_add_alert's arguments as a row (the alerts column table). */
typedef struct st_alert_row {
    int64_t utime;
    const char *level, *kind, *message;
    int64_t indicator_id; /* <= 0: none (NULL) */
    int raised;
} st_alert_row;

/* "INSERT INTO t (the columns of the row struct) VALUES (?1, ...)" into
 * buf; 0, or -1 when it does not fit. */
int st_insert_sql(const amfi_store_tabledef *t, char *buf, size_t len);
/* Every column of the row struct `row` checked by its rule; a message
 * names the column as PREFIX.NAME ("passages.speed_mps",
 * "environment[3].deck_c"). */
int st_check_row(const amfi_store_tabledef *t, const void *row, const char *prefix, char *err,
                 size_t errlen);
/* Bind the row's columns to st (prepared from st_insert_sql): an SQLite
 * status. The row's strings must live until st is reset. */
int st_bind_row(sqlite3_stmt *st, const amfi_store_tabledef *t, const void *row);
/* Check all n rows (stride bytes apart) of table `name`, then insert them
 * in one transaction (all or nothing; n 0: nothing); *id (when not NULL)
 * gets the last row's rowid. Messages name a row as TABLE[k].COLUMN when
 * batch, else TABLE.COLUMN. */
int st_insert_rows(amfi_store *s, const char *name, const void *rows, int n, size_t stride,
                   int batch, int64_t *id, char *err, size_t errlen);

/* ", "-separated names of the row struct's columns of t (those with a C
 * type, in the table's order), for a SELECT; 0, or -1 when it does not fit. */
int st_select_list(const amfi_store_tabledef *t, char *buf, size_t len);
/* Those columns read from st's columns first, first + 1, ... into the row
 * struct, each checked by its column's rule as st_read_* do (type, range,
 * NULL only where allowed, read back as NaN, 0 or a NULL pointer; an enum
 * as its static word). Text other than enums is not read this way (an
 * AMFI_EINVAL). */
int st_read_row(sqlite3_stmt *st, int first, const amfi_store_tabledef *t, void *row,
                const origin *o, char *err, size_t errlen);

/* ---- raw samples (store_raw.c) ------------------------------------------ */

/* The raw rows of passage pid, in its open transaction, under a savepoint
 * (rolled back alone on failure): 0, or the status also in put. */
int st_raw_write(amfi_store *s, int64_t pid, amfi_raw_put *put);
/* The handle's raw buffers and statements freed (close). */
void st_raw_free(amfi_store *s);

#endif /* AMFI_STORE_INTERNAL_H */
