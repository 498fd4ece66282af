/*
 * store.h: amfid's SQLite store of vehicle passages, truth (simulation),
 * indicators, alerts, the healthy baseline and small daemon state.
 *
 * The schema is a user interface: people query it with sqlite3, so every
 * table, column (unit, meaning) and view is documented in docs/schema.md,
 * which holds the exact DDL this file's store.c creates (tests/test_store.c
 * checks that they agree).
 *
 * Workload: one writer thread in amfid opens one handle at start-up, adds one
 * passage per vehicle (a few per second at most, one transaction each: the
 * passage row and its axle rows) plus an indicator row per window step and
 * the odd alert; on restart it reads the baseline, the newest ok GVWs and
 * its meta keys back. Readers (amfi-report, sqlite3, dashboards) are other
 * processes: the database is in WAL mode, so they never block the writer.
 * Synchronous NORMAL (the default) loses at most the last commits on power
 * loss, never consistency; FULL syncs every commit.
 *
 * Conventions (as libamfi, amfi.h): every function that can fail returns an
 * int status, 0 ok or a negative code below, and writes a one-line message
 * of at most `errlen` bytes into `err` when err is not NULL. A handle is not
 * thread-safe: one thread uses it at a time. Distinct handles (threads or
 * processes) may use the same file.
 *
 * Validation: every argument is checked before anything is written (finite
 * numbers or NaN for "unknown", stored as NULL; strings valid UTF-8 without
 * control characters and within their length; enumerations in their list),
 * and a row with one bad field stores nothing. The schema's CHECK
 * constraints repeat the same rules for rows written by other tools. Every
 * value read back is checked for type and range: a damaged row gives
 * AMFI_STORE_ECORRUPT and a message naming its table and rowid.
 */
#ifndef AMFI_STORE_H
#define AMFI_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "amfi/amfi.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes beyond amfi.h's (AMFI_EINVAL, AMFI_ENOMEM are used as there). */
#define AMFI_STORE_EDB (-10)      /* SQLite failed: I/O, disk full, locked past
                                     the busy timeout, read-only handle */
#define AMFI_STORE_ECORRUPT (-11) /* a row read back breaks the schema's rules,
                                     or the file is damaged / not SQLite */
#define AMFI_STORE_ESCHEMA (-12)  /* not an amfi store, or a schema version
                                     this program cannot use */

/* Static string for any status of this header or amfi.h; never NULL. */
const char *amfi_store_strerror(int status);

/* Schema version this code creates and migrates to (PRAGMA user_version). */
#define AMFI_STORE_SCHEMA_VERSION 1
/* PRAGMA application_id of an amfi store: "AMFI" in ASCII. */
#define AMFI_STORE_APPLICATION_ID 0x414D4649
/* How long a statement waits for another connection's lock, ms. */
#define AMFI_STORE_BUSY_TIMEOUT_MS 5000

/* Ranges shared by the checks and the schema's CHECK constraints. */
#define AMFI_STORE_MAX_KG 1e6       /* |any mass|, kg (1000 t) */
#define AMFI_STORE_MAX_SPEED_MPS 150.0
#define AMFI_STORE_MAX_SPACING_M 50.0
#define AMFI_STORE_MAX_FORCE_N 1e7  /* |truth mean contact force|, N */
#define AMFI_STORE_MAX_UTIME INT64_C(253402300799999999) /* 9999-12-31 23:59:59.999999 UTC */
#define AMFI_STORE_REASON_MAX 1024  /* bytes of passages.reason, alerts.message */
#define AMFI_STORE_META_KEY_MAX 63  /* bytes of a meta key ([A-Za-z0-9_.-]) */
#define AMFI_STORE_META_VALUE_MAX 4096 /* bytes of a meta value */

typedef struct amfi_store amfi_store; /* opaque */

/* Create `path` (with the whole schema) or open it, migrating an older
 * schema to AMFI_STORE_SCHEMA_VERSION: the missing migrations are applied in
 * order inside one transaction, so a failure leaves the file as it was.
 * Sets WAL mode, busy timeout AMFI_STORE_BUSY_TIMEOUT_MS, foreign keys on,
 * synchronous FULL when sync_full != 0, else NORMAL. Refused with
 * AMFI_STORE_ESCHEMA: a database whose user_version is newer than this code
 * knows, or one that is not an amfi store (other application_id, or
 * user_version 0 with tables in it). A file that is not SQLite gives
 * AMFI_STORE_ECORRUPT. On success *out is the handle (close it with
 * amfi_store_close); on failure *out is NULL. */
int amfi_store_open(const char *path, int sync_full, amfi_store **out,
                    char *err, size_t errlen);

/* The same, read-only (SQLITE_OPEN_READONLY, query_only), for reports: the
 * file must exist and already be at AMFI_STORE_SCHEMA_VERSION (nothing is
 * created or migrated). The add/set functions then fail with
 * AMFI_STORE_EDB. */
int amfi_store_open_readonly(const char *path, amfi_store **out, char *err,
                             size_t errlen);

/* Finalize the statements, run PRAGMA optimize and checkpoint the WAL
 * (truncating it) when writable, close. NULL-safe. */
void amfi_store_close(amfi_store *s);

/* The SQLite connection, borrowed (valid until amfi_store_close; do not
 * close it or change its pragmas), for tools' own read-only queries.
 * `struct sqlite3` is sqlite3.h's `sqlite3`. */
struct sqlite3 *amfi_store_db(amfi_store *s);

/* ---- passages ---------------------------------------------------------- */

/* Passage status values, as in the AMFI_PASSAGE message. */
#define AMFI_STORE_STATUSES "ok, gap, late, overload, multiple, invalid, error"

/* One stored vehicle passage. Unknown numbers are NaN (stored as NULL).
 * Ranges hold for every status: an impossible value of an invalid vehicle
 * event is passed as NaN, with the raw value in `reason`. */
typedef struct amfi_passage_row {
    int64_t vehicle_id;  /* from the detector, any value */
    int64_t utime;       /* entry of the first axle, data time, µs since 1970
                            UTC, 0 .. AMFI_STORE_MAX_UTIME */
    int lane;            /* −32768 .. 32767 */
    double speed_mps;    /* 0 .. 150 m/s, or NaN */
    int n_axles;         /* 0 (unknown) .. AMFI_MAX_AXLES: axle rows stored */
    double spacing_m[AMFI_MAX_AXLES]; /* spacing_m[k]: axle k to axle k + 1
                            (0-based, as amfi_passage.axle_spacing_m),
                            k < n_axles − 1; 0 < s <= 50 m, or NaN */
    double axle_kg[AMFI_MAX_AXLES];   /* k < n_axles: inferred axle load, kg,
                            |x| <= 1e6, or NaN */
    double gvw_kg;       /* inferred GVW, kg, |x| <= 1e6; NaN not solved */
    const char *status;  /* one of AMFI_STORE_STATUSES, not NULL */
    const char *reason;  /* why not ok, <= 1024 bytes; NULL stored as "" */
    double lambda;       /* λ used, at the reference rate
                            (amfi_result.lambda_ref), > 0, or NaN */
    double residual_rms; /* m/s², >= 0, or NaN */
    const char *formulation; /* solver output equation, 1 .. 63 bytes, or NULL */
    double solve_ms;     /* solver wall time, ms, >= 0, or NaN */
} amfi_passage_row;
/* Status "ok" further needs 1 <= n_axles, 0 < gvw_kg, 0 < speed_mps and
 * every spacing and axle load known. */

/* Store the passage row and its n_axles axle rows in one transaction (all
 * or nothing). *id (when id is not NULL) gets the passage's rowid. */
int amfi_store_add_passage(amfi_store *s, const amfi_passage_row *r,
                           int64_t *id, char *err, size_t errlen);

/* Simulation only: the truth of one vehicle (AMFI_TRUTH) and its n_axles
 * axle rows, in one transaction. gvw_kg: 0 < x <= 1e6; n_axles 1 ..
 * AMFI_MAX_AXLES; axle_kg: n_axles static loads, 0 < x <= 1e6; mean_force_N:
 * n_axles mean contact forces on the span, N, |x| <= 1e7, or NULL (all
 * unknown; single NaN entries are unknown too); speed_true_mps: 0 < v <= 150
 * or NaN. */
int amfi_store_add_truth(amfi_store *s, int64_t vehicle_id, int64_t utime,
                         double gvw_kg, int n_axles, const double *axle_kg,
                         const double *mean_force_N, double speed_true_mps,
                         char *err, size_t errlen);

/* ---- indicators and alerts --------------------------------------------- */

/* One step of the rolling-window indicator (AMFI_INDICATOR). NaN: unknown. */
typedef struct amfi_indicator_row {
    int64_t utime;      /* data time of the newest passage in the window, µs */
    int n;              /* ok passages in the window, >= 0 */
    double mean_kg;     /* window mean GVW, kg, |x| <= 1e6, or NaN */
    double std_kg;      /* window sample STD, kg, 0 .. 1e6, or NaN */
    double baseline_mean_kg; /* kg, 0 < x <= 1e6, or NaN (no baseline yet) */
    double baseline_std_kg;  /* kg, 0 < x <= 1e6, or NaN */
    double std_ratio;   /* std_kg / baseline_std_kg, 0 .. 1e6, or NaN */
    double p_value;     /* one-sided variance-ratio test, 0 .. 1, or NaN */
    const char *state;  /* "baseline", "normal", "watch" or "alert" */
} amfi_indicator_row;

int amfi_store_add_indicator(amfi_store *s, const amfi_indicator_row *r,
                             int64_t *id, char *err, size_t errlen);

/* level: "info" or "warning"; kind: 1 .. 31 bytes of [a-z0-9_]
 * ("std_increase", "mean_shift", ...); message: 1 .. 1024 bytes;
 * indicator_id: an existing indicator's id, or <= 0 for none (NULL);
 * raised: 1 raised, 0 cleared. */
int amfi_store_add_alert(amfi_store *s, int64_t utime, const char *level,
                         const char *kind, const char *message,
                         int64_t indicator_id, int raised, int64_t *id,
                         char *err, size_t errlen);

/* ---- baseline ---------------------------------------------------------- */

/* The healthy GVW statistics the indicator compares against. The table
 * keeps every baseline ever set; the newest row is the one in force. */
typedef struct amfi_baseline {
    int64_t utime_set; /* data time from which it applies, µs */
    int n;             /* ok passages behind it, >= 2 */
    double mean_kg;    /* 0 < x <= 1e6 */
    double std_kg;     /* 0 < x <= 1e6 */
    char source[16];   /* "auto" (amfid) | "manual" (amfi-report) */
    char note[128];    /* free text, NUL-terminated, may be empty */
} amfi_baseline;

/* *found = 1 and *b filled from the newest baseline row; *found = 0 (and
 * *b untouched) when there is none. */
int amfi_store_get_baseline(amfi_store *s, amfi_baseline *b, int *found,
                            char *err, size_t errlen);
int amfi_store_set_baseline(amfi_store *s, const amfi_baseline *b, char *err,
                            size_t errlen);

/* GVW of the newest (by utime, then id) `max` passages with status ok,
 * oldest first, into gvw[0 .. *n − 1] (*n <= max; gvw holds max values):
 * refills the rolling window after a restart. max >= 1. */
int amfi_store_recent_ok_gvw(amfi_store *s, int max, double *gvw, int *n,
                             char *err, size_t errlen);

/* ---- meta: small key/value table for daemon state ---------------------- */

/* key: 1 .. 63 bytes of [A-Za-z0-9_.-]. *found = 0 and val = "" when the
 * key is absent. A value longer than vallen − 1 bytes is an error
 * (AMFI_EINVAL), never truncated. */
int amfi_store_meta_get(amfi_store *s, const char *key, char *val,
                        size_t vallen, int *found, char *err, size_t errlen);
/* Insert or replace; val: 0 .. 4096 bytes of UTF-8 text. */
int amfi_store_meta_set(amfi_store *s, const char *key, const char *val,
                        char *err, size_t errlen);

/* ---- maintenance ------------------------------------------------------- */

/* PRAGMA integrity_check, then PRAGMA foreign_key_check. `result` (len > 0)
 * gets "ok" when both are clean, else the first problems, "; "-separated
 * and truncated to len − 1 bytes; the return is 0 in both cases. A file too
 * damaged to run the check returns AMFI_STORE_ECORRUPT, with the message in
 * both err and result. Cost: reads the whole file. */
int amfi_store_integrity_check(amfi_store *s, char *result, size_t len,
                               char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_STORE_H */
