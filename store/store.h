/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store.h: amfid's SQLite store of vehicle passages, truth (simulation),
 * indicators, alerts, the healthy baseline and small daemon state.
 *
 * The schema is a user interface: people query it with sqlite3, so every
 * table, column (unit, meaning) and view is documented in docs/schema.md,
 * which holds the exact DDL this file's store.c creates (tests/store/test_store.c
 * checks that they agree).
 *
 * The store owns every SQL statement: programs get typed rows and queries
 * from the functions below, never the SQLite connection.
 *
 * Files: store_schema.c (the DDL and the migrations), store_open.c (open,
 * close, migrate, the prepared statements, messages), store_check.c
 * (argument checks, statement helpers), store_write.c (inserts),
 * store_read.c (what amfid reads back, maintenance), store_report.c (the
 * queries of reports), store_export.c (the passage listing), store_speed.c
 * (the estimated speeds), store_environment.c (the environment readings),
 * store_web.c (amfi-web's reads),
 * store_natfreq.c (the natural frequencies), store_raw.c (the passages' raw
 * samples; store_web_raw.c the oldest window kept), store_columns.c (the column
 * table, store_columns.h: every stored column once), store_rows.c (the
 * INSERTs, bindings and checks of the tables written from a row struct, from
 * the column table), store_scan.c (rows as column values for amfi-sync,
 * amfi-report --pg, amfi-fleet-bench); store_internal.h is shared by them
 * only. store_testing.c (library amfi_store_testing) gives tests raw SQL on
 * a file; no program links it.
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
#define AMFI_STORE_SCHEMA_VERSION 13
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
 * amfi_store_close); on failure *out is NULL. Every connection is in
 * SQLite's defensive mode (SQLITE_DBCONFIG_DEFENSIVE) with an untrusted
 * schema (SQLITE_DBCONFIG_TRUSTED_SCHEMA off: the file's views may call
 * only innocuous functions) and no extension loading. */
int amfi_store_open(const char *path, int sync_full, amfi_store **out,
                    char *err, size_t errlen);

/* The same for a store this process did not write (amfi-report
 * --set-baseline): triggers are off too (SQLITE_DBCONFIG_ENABLE_TRIGGER),
 * and a file holding a trigger is refused with AMFI_STORE_ESCHEMA. */
int amfi_store_open_foreign(const char *path, int sync_full, amfi_store **out, char *err,
                            size_t errlen);

/* The same, read-only (SQLITE_OPEN_READONLY, query_only), for reports: the
 * file must exist and already be at AMFI_STORE_SCHEMA_VERSION (nothing is
 * created or migrated); triggers off and a file holding one refused, as
 * amfi_store_open_foreign. The add/set functions then fail with
 * AMFI_STORE_EDB. */
int amfi_store_open_readonly(const char *path, amfi_store **out, char *err,
                             size_t errlen);

/* Finalize the statements, run PRAGMA optimize and checkpoint the WAL
 * (truncating it) when writable, close. NULL-safe. */
void amfi_store_close(amfi_store *s);

/* Delete a closed store's files: path and its -wal and -shm (those absent
 * are fine). For temporary stores (tests, amfi-report --pg). */
void amfi_store_remove(const char *path);

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
    double speed_mps;    /* the speed weighed with, 0 .. 150 m/s, or NaN */
    double speed_given_mps; /* the detector's speed, 0 .. 150 m/s, or NaN */
    int speed_estimated; /* 1: speed_mps was estimated from the data, else 0 */
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
    int n_vehicles;      /* vehicles of the event it was weighed in (the
                            ones on the span together), 1 .. 64; 0 is taken
                            as 1 */
    double quality;      /* its weight's separability from the event's other
                            vehicles (amfi_vehicle_result.quality), 1 .. 1e9;
                            NaN or 0: unknown (not solved jointly), NULL */
    double reference_gvw_kg; /* a calibration truck's pre-weighed GVW
                            (vehicle_t.reference_gvw_kg), AMFI_STORE_MIN_REF_KG
                            .. AMFI_STORE_MAX_REF_KG; NaN or 0: none, NULL */
    int has_deck_c;      /* 1: deck_c holds the deck temperature taken for the
                            passage; 0: none (NULL) */
    double deck_c;       /* °C, AMFI_STORE_MIN_TEMP_C .. AMFI_STORE_MAX_TEMP_C */
    double f1_hz;        /* the bridge's first natural frequency from the free
                            vibration after it, Hz, (0, 1000]; NaN or 0: none
                            (NULL, and so are the three below) */
    double f1_comp_hz;   /* f1 at the calibration temperature, (0, 1000]; NaN or
                            0: NULL */
    double f1_zeta;      /* its damping ratio, [0, 1); NaN: NULL */
    double f1_r2;        /* the fit's R², [0, 1]; NaN: NULL */
    double gvw_comp_kg;  /* the weight the STD and mean rules were fed (the GVW
                            at the calibration temperature, or the GVW itself),
                            (0, 1e6] kg; NaN or 0: did not feed them, NULL */
    const char *vclass;  /* the vehicle class (classify/: "A23", "FHWA9",
                            "unknown"), 1 .. 15 bytes; NULL: none (NULL) */
    const char *axle_groups; /* axles per group, front to back, joined by '-'
                            ("1-1-3"), 1 .. 31 bytes; NULL: none (NULL) */
    int has_overload;    /* 1: overload holds the legal-limit check; 0: not
                            decided (not solved), NULL */
    int overload;        /* 1: the GVW or a group above its limit, else 0 */
    /* Not a column: the passage's raw samples, written in its transaction
     * (raw_windows, passage_raw; amfi_raw_put below), or NULL: none. */
    struct amfi_raw_put *raw;
    double fit_ratio;    /* the model fit (amfid's modelfit.c): the RMS residual of
                            the model solved over the free vibration after the last
                            axle, relative to the signal there, (0, 1000]; NaN
                            or 0: not fitted (NULL) */
    const char *loads_refused; /* why the classification refused the loads
                            (classify/ amfi_classification.loads_why: a single
                            axle or a group below zero, or above
                            AMFI_CLASS_IMPLAUSIBLE_FACTOR x any legal load), 1 ..
                            AMFI_STORE_LOADS_REFUSED_MAX bytes, valid UTF-8
                            without control characters; NULL: the loads were
                            judged, or there were none (NULL) */
} amfi_passage_row;
/* The longest passages.loads_refused, bytes (amfi_classification.loads_why
 * holds 111). */
#define AMFI_STORE_LOADS_REFUSED_MAX 111
/* The range of a reference GVW (a calibration truck), kg. */
#define AMFI_STORE_MIN_REF_KG 1000.0
#define AMFI_STORE_MAX_REF_KG 100000.0
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

/* ---- environment (store_environment.c) --------------------------------- */

/* The temperatures the store accepts, °C (environment_t's plausible range). */
#define AMFI_STORE_MIN_TEMP_C (-60.0)
#define AMFI_STORE_MAX_TEMP_C 80.0

/* One reading of the bridge's environment (AMFI_ENVIRONMENT). */
typedef struct amfi_environment_row {
    int64_t utime;          /* data time of the reading, µs, 0 .. AMFI_STORE_MAX_UTIME */
    double deck_c;          /* deck temperature, °C, -60 .. 80 */
    double air_c;           /* air temperature, °C, -60 .. 80 */
    int64_t received_utime; /* wall clock when amfid received it, µs */
} amfi_environment_row;

/* Store n readings in one transaction (all or nothing; n 0: nothing). */
int amfi_store_add_environment(amfi_store *s, const amfi_environment_row *rows, int n,
                               char *err, size_t errlen);

/* The deck temperature at data time utime: linear between the readings
 * just before and just after it when they are at most max_gap_us apart;
 * otherwise the nearer of them when it is within max_gap_us / 2 of utime;
 * otherwise (or no readings) NaN. 0, or a status. */
int amfi_store_deck_c_at(amfi_store *s, int64_t utime, int64_t max_gap_us, double *deck_c,
                         char *err, size_t errlen);

/* One period's refused bus messages of one input and reason (amfid's
 * daemon.intake.summary_period_s). */
typedef struct amfi_refusal_row {
    int64_t period_start, period_end; /* wall clock, µs, start <= end */
    const char *channel;   /* the bus channel, 1 .. 63 bytes */
    const char *input;     /* accel, vehicle, truth or environment */
    const char *reason;    /* 1 .. 63 bytes (amfid's reason names) */
    int64_t count;         /* >= 1 */
    const char *example;   /* the first refused message's log line (cut at 512 bytes) */
} amfi_refusal_row;

/* Store n summaries in one transaction (all or nothing; n 0: nothing). */
int amfi_store_add_refusals(amfi_store *s, const amfi_refusal_row *rows, int n, char *err,
                            size_t errlen);

typedef struct amfi_environment_summary {
    int64_t n;                    /* readings */
    int64_t utime_first, utime_last; /* µs; 0 when n is 0 */
    double deck_min_c, deck_max_c;   /* NaN when n is 0 */
    double air_min_c, air_max_c;
} amfi_environment_summary;

/* Every stored reading, by utime, into *out (malloc'd, the caller frees;
 * NULL when *n is 0). 0, or a status. */
int amfi_store_environment_rows(amfi_store *s, amfi_environment_row **out, size_t *n, char *err,
                                size_t errlen);

/* Count, time span and temperature ranges of the stored readings. */
int amfi_store_environment_summary(amfi_store *s, amfi_environment_summary *out, char *err,
                                   size_t errlen);

/* ---- scale and known-truck indicators (store_scale.c) ------------------- */

/* One input of the scale or known-truck indicator: an ok passage with the
 * deck temperature amfid took for it (passages.deck_c not NULL). */
typedef struct amfi_scale_input {
    int64_t id;              /* passages.id */
    int64_t utime;           /* µs */
    double gvw_kg;           /* inferred, > 0 */
    double deck_c;           /* °C */
    double reference_gvw_kg; /* NaN: not a calibration truck */
    int n_vehicles;          /* of the event it was weighed in, 1 alone */
} amfi_scale_input;

/* Up to max (>= 1) such passages with id > after_id, by id, into *out
 * (malloc'd, the caller frees; NULL when *n is 0). Pages through a long
 * history: the next call passes the last id. 0, or a status. */
int amfi_store_scale_inputs(amfi_store *s, int64_t after_id, int max, amfi_scale_input **out,
                            size_t *n, char *err, size_t errlen);

/* One scale block or known-truck run (AMFI_SCALE_EVAL). NaN: unknown. */
typedef struct amfi_scale_eval_row {
    int64_t utime;     /* µs */
    const char *kind;  /* "scale_shift" | "known_truck" */
    int n;             /* vehicles in the block / runs so far, >= 0 */
    double value;      /* compensated scale / ratio, (0, 100], or NaN */
    double raw;        /* uncompensated, (0, 100], or NaN */
    double deck_c;     /* °C, -60 .. 80, or NaN */
    double z;          /* |z| <= 1e6, or NaN */
    double cusum, h;   /* 0 .. 1e6, or NaN */
    const char *state; /* "baseline" | "normal" | "watch" | "alert" */
} amfi_scale_eval_row;

int amfi_store_add_scale_eval(amfi_store *s, const amfi_scale_eval_row *r, int64_t *id,
                              char *err, size_t errlen);

/* A stored evaluation as read back (kind and state copied). */
typedef struct amfi_scale_eval_rec {
    int64_t id, utime;
    char kind[16];
    int n;
    double value, raw, deck_c, z, cusum, h;
    char state[12];
} amfi_scale_eval_rec;

/* Every stored evaluation of kind ("scale_shift" | "known_truck"), by
 * utime, into *out (malloc'd; NULL when *n is 0). 0, or a status. */
int amfi_store_scale_evals(amfi_store *s, const char *kind, amfi_scale_eval_rec **out,
                           size_t *n, char *err, size_t errlen);

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

/* The weight the STD and mean rules were fed (passages.gvw_comp_kg; the
 * GVW where that is NULL: rows written before version 8) of the newest (by
 * utime, then id) `max` passages with status ok, oldest first, into
 * gvw[0 .. *n − 1] (*n <= max; gvw holds max values): refills the rolling
 * window after a restart. max >= 1. */
int amfi_store_recent_ok_gvw(amfi_store *s, int max, double *gvw, int *n,
                             char *err, size_t errlen);

/* The same restricted as amfid restricts what feeds the rules
 * (daemon.indicators.classes, min_gvw_kg, single_presence_only): only ok
 * passages whose class is one of classes[0 .. n_classes − 1] (n_classes 0:
 * any class, NULL too), whose weight fed (gvw_comp_kg, else gvw_kg) is at
 * least min_kg and, when single_only, weighed alone (n_vehicles <= 1 or
 * NULL). A class name is 1 .. 15 bytes; n_classes 0 .. 64. */
int amfi_store_recent_fed_gvw(amfi_store *s, int max, const char *const *classes,
                              int n_classes, double min_kg, int single_only, double *gvw,
                              int *n, char *err, size_t errlen);

/* ---- meta: small key/value table for daemon state ---------------------- */

/* key: 1 .. 63 bytes of [A-Za-z0-9_.-]. *found = 0 and val = "" when the
 * key is absent. A value longer than vallen − 1 bytes is an error
 * (AMFI_EINVAL), never truncated. */
int amfi_store_meta_get(amfi_store *s, const char *key, char *val,
                        size_t vallen, int *found, char *err, size_t errlen);
/* Insert or replace; val: 0 .. 4096 bytes of UTF-8 text. */
int amfi_store_meta_set(amfi_store *s, const char *key, const char *val,
                        char *err, size_t errlen);

/* ---- runs: one row per start of amfid ----------------------------------- */

/* Record that a program run started now (wall clock, UTC, in runs.started_at):
 * version: 1 .. 63 bytes of printable text (amfid --version); config_path:
 * 1 .. 4096 bytes of UTF-8 text (the configuration file it read). *id (when
 * not NULL) gets the row's id. */
int amfi_store_add_run(amfi_store *s, const char *version,
                       const char *config_path, int64_t *id, char *err,
                       size_t errlen);

/* ---- alerts read back ---------------------------------------------------- */

/* *open = 1 when the newest alert row (by id) of `kind` is a raise, 0 when
 * it is a clear or there is none: an alert open before a restart stays open. */
int amfi_store_alert_open(amfi_store *s, const char *kind, int *open,
                          char *err, size_t errlen);

/* ---- queries of reports (amfi-report) ------------------------------------ */

/* Number of statuses in AMFI_STORE_STATUSES, and the k-th of them (in that
 * order; NULL outside 0 .. AMFI_STORE_N_STATUS − 1). */
#define AMFI_STORE_N_STATUS 7
const char *amfi_store_status_name(int k);

/* Tables amfi_store_count counts. */
typedef enum amfi_store_table {
    AMFI_STORE_PASSAGES,
    AMFI_STORE_INDICATORS,
    AMFI_STORE_ALERTS,
    AMFI_STORE_TRUTH
} amfi_store_table;

/* *n = the number of rows of the table. */
int amfi_store_count(amfi_store *s, amfi_store_table t, int64_t *n, char *err,
                     size_t errlen);

typedef struct amfi_passage_summary {
    int64_t total;                /* passages */
    int64_t utime_first;          /* min and max utime, µs; 0 when total is 0 */
    int64_t utime_last;
    int64_t by_status[AMFI_STORE_N_STATUS]; /* amfi_store_status_name order */
} amfi_passage_summary;

/* Counts by status and the time span of every passage. */
int amfi_store_passage_summary(amfi_store *s, amfi_passage_summary *out,
                               char *err, size_t errlen);

/* GVW of every ok passage, in rowid order: *gvw is malloc'd (free it; NULL
 * when *n is 0). A value outside (0, 1e6] kg is AMFI_STORE_ECORRUPT. */
int amfi_store_all_ok_gvw(amfi_store *s, double **gvw, size_t *n, char *err,
                          size_t errlen);
/* The same of the weights the STD and mean rules were fed
 * (passages.gvw_comp_kg not NULL, store version 8). */
int amfi_store_all_fed_gvw(amfi_store *s, double **gvw, size_t *n, char *err,
                           size_t errlen);

/* An indicator row read back: row.state is a static string. */
typedef struct amfi_indicator_rec {
    int64_t id;
    amfi_indicator_row row;
} amfi_indicator_rec;

/* The newest (by utime, then id) min(max, rows) indicators, newest first,
 * into out[0 .. *n − 1]. max >= 1. */
int amfi_store_recent_indicators(amfi_store *s, int max,
                                 amfi_indicator_rec *out, int *n, char *err,
                                 size_t errlen);

/* An alert row read back. */
typedef struct amfi_alert_rec {
    int64_t id;
    int64_t utime;          /* data time, µs */
    int64_t indicator_id;   /* 0: none */
    const char *level;      /* static: "info" or "warning" */
    char kind[32];
    int raised;             /* 1 raised, 0 cleared */
    char message[AMFI_STORE_REASON_MAX + 1]; /* control characters as '?' */
} amfi_alert_rec;

/* The newest min(max, rows) alerts (by utime, then id), newest first. */
int amfi_store_recent_alerts(amfi_store *s, int max, amfi_alert_rec *out,
                             int *n, char *err, size_t errlen);

/* The alerts open now (the newest event of their kind, by utime then id, is
 * a raise), oldest first: *out is malloc'd (free it; NULL when *n is 0). */
int amfi_store_open_alerts(amfi_store *s, amfi_alert_rec **out, int *n,
                           char *err, size_t errlen);

/* The GVW error of every ok passage matched with a truth row (view
 * passage_errors), %, in the view's order: *pct is malloc'd (free it; NULL
 * when *n is 0); *n_other counts the matched passages not ok. */
int amfi_store_gvw_errors(amfi_store *s, double **pct, size_t *n,
                          int64_t *n_other, char *err, size_t errlen);

/* ---- passage listing (store_export.c) ------------------------------------ */

/* Called once per passage; row->status, row->reason, row->vclass,
   row->axle_groups and row->loads_refused (NULL where the column is NULL;
   has_overload 0 where overload is) are valid during the call only. A nonzero return stops the
   listing and is returned. */
typedef int (*amfi_store_passage_fn)(void *ctx, int64_t id,
                                     const amfi_passage_row *row);

/* Which passages a listing reads; the store turns it into the WHERE clause
   (no row outside it leaves SQLite). */
typedef struct amfi_passage_filter {
    int64_t from, to;      /* from <= utime <= to, µs */
    const char *status;    /* NULL: any; else one of AMFI_STORE_STATUSES */
    int lane_given;        /* 1: only passages of lane `lane` */
    int lane;
} amfi_passage_filter;

/* Every passage the filter selects, oldest first (utime, id), with its axle
   rows (spacing_m[k], axle_kg[k]; NaN where NULL). One row in memory at a
   time. */
int amfi_store_each_passage_where(amfi_store *s, const amfi_passage_filter *f,
                                  amfi_store_passage_fn fn, void *ctx,
                                  char *err, size_t errlen);

/* ---- class rows (store_classrows.c) --------------------------------------- */

/* An ok passage as the class statistics see it; vclass (NULL where the
   column is NULL) is valid during the call only. */
typedef struct amfi_class_row {
    int lane;
    double gvw_kg;      /* > 0 */
    const char *vclass; /* passages.class */
    int overload;       /* passages.overload; 0 where NULL */
    int refused;        /* 1: passages.loads_refused holds a reason */
} amfi_class_row;
typedef int (*amfi_store_class_fn)(void *ctx, const amfi_class_row *row);

/* Every ok passage with a GVW that the filter's time range and lane select
   (its status is ignored: ok), oldest first, without its axle rows (one
   query). A nonzero return of fn stops the listing and is returned. */
int amfi_store_each_class_row(amfi_store *s, const amfi_passage_filter *f,
                              amfi_store_class_fn fn, void *ctx, char *err, size_t errlen);

/* amfi_store_each_passage_where with from, to, status and any lane. */
int amfi_store_each_passage(amfi_store *s, int64_t from, int64_t to,
                            const char *status, amfi_store_passage_fn fn,
                            void *ctx, char *err, size_t errlen);

/* ---- the web dashboard's reads (store_web.c, amfi-web) -------------------- */

/* The newest passage and the counts by status since a time. */
typedef struct amfi_web_status {
    int64_t total;        /* passages */
    int64_t last_id;      /* the newest (by utime, then id); 0: none */
    int64_t last_utime;   /* its data time, µs; 0: none */
    int64_t since_total;  /* passages with utime >= since */
    int64_t since_by_status[AMFI_STORE_N_STATUS]; /* amfi_store_status_name order */
} amfi_web_status;

int amfi_store_web_status(amfi_store *s, int64_t since, amfi_web_status *out, char *err,
                          size_t errlen);

/* One passage as stored: row's strings point into the buffers here. */
typedef struct amfi_web_passage {
    int64_t id;
    amfi_passage_row row;
    char status[16];
    char reason[AMFI_STORE_REASON_MAX + 1];
    char formulation[64];
    char vclass[16];
    char groups[32];
    char refused[AMFI_STORE_LOADS_REFUSED_MAX + 1];
} amfi_web_passage;

/* Called once per passage (valid during the call only); nonzero stops. */
typedef int (*amfi_web_passage_fn)(void *ctx, const amfi_web_passage *p);

#define AMFI_WEB_MAX_LIMIT 1000 /* passages in one listing */
typedef struct amfi_web_query {
    int64_t from, to;     /* from <= utime <= to, µs */
    const char *status;   /* NULL: any; else one of AMFI_STORE_STATUSES */
    const char *vclass;   /* NULL: any; else the class (1 .. 15 bytes) */
    int limit;            /* 1 .. AMFI_WEB_MAX_LIMIT */
} amfi_web_query;

/* The newest `limit` passages the query selects, newest first (utime, id),
   without their axle rows (spacing_m, axle_kg NaN). */
int amfi_store_web_passages(amfi_store *s, const amfi_web_query *q, amfi_web_passage_fn fn,
                            void *ctx, char *err, size_t errlen);

/* Passage id with its axle rows: *found 1, or 0 when there is none. */
int amfi_store_web_passage(amfi_store *s, int64_t id, amfi_web_passage *out, int *found,
                           char *err, size_t errlen);

/* The trend series: ok GVW (passages.gvw_kg), the STD indicator's ratio
   (indicators.std_ratio), the natural frequency (passages.f1_hz), the fit
   residual (passages.residual_rms), the deck temperature (environment.deck_c),
   the model fit over the free vibration (passages.fit_ratio). */
enum { AMFI_WEB_GVW, AMFI_WEB_INDICATOR, AMFI_WEB_NATFREQ, AMFI_WEB_RESIDUAL,
       AMFI_WEB_TEMPERATURE, AMFI_WEB_FIT_RATIO, AMFI_WEB_N_SERIES };
#define AMFI_WEB_MAX_BUCKETS 2000
/* "gvw", "indicator", "natfreq", "residual", "temperature", "fit_ratio";
   NULL outside. */
const char *amfi_store_web_series_name(int k);

typedef struct amfi_web_bucket {
    int64_t t0;             /* start of the bucket, µs */
    int64_t n;              /* values in it, >= 1 */
    double mean, min, max;  /* of those values */
} amfi_web_bucket;

/* Series `which` between from and to, narrowed to where it has values, in
   at most nbuckets (1 .. AMFI_WEB_MAX_BUCKETS) buckets of *width µs each,
   grouped in SQL: out (nbuckets entries) gets the non-empty ones, oldest
   first, *n of them (0: no values). */
int amfi_store_web_trend(amfi_store *s, int which, int64_t from, int64_t to, int nbuckets,
                         amfi_web_bucket *out, int *n, int64_t *width, char *err, size_t errlen);

/* One vehicle class's passages in a time range. */
typedef struct amfi_web_class {
    char vclass[16];        /* "" : none recorded (rows before version 10) */
    int64_t n, n_ok, n_overload;
    int64_t n_refused;      /* loads refused by the classification (stored from version 13) */
    double gvw_mean_kg, gvw_max_kg; /* of the ok ones; NaN: none */
} amfi_web_class;

/* The classes of the passages with from <= utime <= to, most passages first,
   at most max of them into out. */
int amfi_store_web_classes(amfi_store *s, int64_t from, int64_t to, amfi_web_class *out, int max,
                           int *n, char *err, size_t errlen);

/* Every meta key starting with prefix (0 .. 63 bytes; "" all), by key;
   key and value valid during the call only; nonzero stops. */
typedef int (*amfi_web_meta_fn)(void *ctx, const char *key, const char *value);
int amfi_store_web_meta(amfi_store *s, const char *prefix, amfi_web_meta_fn fn, void *ctx,
                        char *err, size_t errlen);

/* ---- estimated speeds (store_speed.c) ----------------------------------- */

/* The two speeds of one passage whose speed was estimated (speed_estimated
 * = 1, both speeds known and > 0): its correction is
 * speed_mps / speed_given_mps − 1. */
typedef struct amfi_speed_pair {
    int64_t utime;          /* data time, µs */
    double speed_mps;       /* the speed weighed with (the estimate), m/s */
    double speed_given_mps; /* the detector's, m/s */
} amfi_speed_pair;

/* *yes = 1 when some passage has an estimated speed (both speeds known). */
int amfi_store_has_estimated(amfi_store *s, int *yes, char *err, size_t errlen);

/* The estimated passages the filter selects (time range, status or NULL,
   lane), oldest first (utime, id): *out is malloc'd (free it; NULL when *n
   is 0). A speed outside (0, 150] m/s is AMFI_STORE_ECORRUPT. */
int amfi_store_speed_pairs(amfi_store *s, const amfi_passage_filter *f, amfi_speed_pair **out,
                           size_t *n, char *err, size_t errlen);

/* The newest min(max, rows) estimated passages (by utime, then id), oldest
   first: refills amfid's speed-drift window after a restart. max >= 1. */
int amfi_store_recent_speed_pairs(amfi_store *s, int max, amfi_speed_pair **out, size_t *n,
                                  char *err, size_t errlen);

/* ---- the solver's fit per passage (store_residual.c) --------------------- */

/* One ok passage's fit: passages.residual_rms (not NULL) and quality. */
typedef struct amfi_residual_rec {
    int64_t passage_id;
    int64_t utime;       /* data time, µs */
    double residual_rms; /* RMS of the fit's residual, m/s², >= 0 */
    double quality;      /* separability from the event's other vehicles, 1 ..; NaN: NULL */
} amfi_residual_rec;

/* The ok passages with a residual and from <= utime <= to, oldest first
   (utime, id): *out is malloc'd (free it; NULL when *n is 0). A value
   outside the schema's range is AMFI_STORE_ECORRUPT. */
int amfi_store_residual_series(amfi_store *s, int64_t from, int64_t to, amfi_residual_rec **out,
                               size_t *n, char *err, size_t errlen);

/* ---- natural frequencies (store_natfreq.c) ------------------------------ */

/* One passage's natural frequency (f1_hz not NULL). */
typedef struct amfi_f1_rec {
    int64_t passage_id;
    int64_t utime;          /* data time, µs */
    double f1_hz;           /* as estimated, Hz */
    double f1_comp_hz;      /* at the calibration temperature, Hz; NaN: NULL */
    double f1_zeta, f1_r2;  /* damping ratio and the fit's R²; NaN: NULL */
} amfi_f1_rec;

/* The passages with an f1 and from <= utime <= to, oldest first (utime, id),
   at most max (0: all): *out is malloc'd (free it; NULL when *n is 0). A
   value outside the schema's range is AMFI_STORE_ECORRUPT. */
int amfi_store_f1_series(amfi_store *s, int64_t from, int64_t to, int max, amfi_f1_rec **out,
                         size_t *n, char *err, size_t errlen);


/* ---- raw samples of the passages (store_raw.c; schema version 11) ------- */
/* amfid keeps the samples it weighed each passage with (daemon.store.raw):
 * one raw window per solve (a vehicle, or an event of several weighed
 * together), every sensor's samples exactly as the solver had them (the
 * float64 values, losslessly compressed: each sample's bit pattern XORed
 * with the previous one's, the bytes shuffled into planes, zlib), with the
 * time base, the sensors, the detector records and the solver's live
 * settings; each passage of the window links to it. amfi-solve
 * --from-store re-weighs a passage from it; retention deletes whole
 * windows, oldest first, never the passages. */

/* One vehicle of a raw window: its detector record as the solver took it
 * (amfid's detector.* corrections applied). */
typedef struct amfi_raw_vehicle {
    int64_t vehicle_id;
    int64_t utime;       /* entry of its first axle, data time, µs */
    int lane;            /* −32768 .. 32767 */
    double speed_mps;    /* the detector's (corrected) speed, (0, 150] m/s */
    int n_axles;         /* 1 .. AMFI_MAX_AXLES */
    double spacing_m[AMFI_MAX_AXLES]; /* n_axles − 1, (0, 50] m */
} amfi_raw_vehicle;

/* The schema version whose migration added raw_windows and passage_raw
 * (store_schema.c): older stores have no raw samples. */
#define AMFI_STORE_RAW_VERSION 11

/* The encodings of raw_windows.samples: the float64 values exactly, or
 * rounded to float32 (each sample changed by at most 2^-24 of itself,
 * about half the bytes; daemon.store.raw.precision). */
#define AMFI_STORE_RAW_F64 "f64-xor-shuffle-zlib"
#define AMFI_STORE_RAW_F32 "f32-xor-shuffle-zlib"
/* The largest raw window the store writes or reads, in samples (all
 * sensors): 2^26 (512 MiB of float64). */
#define AMFI_STORE_RAW_MAX_SAMPLES (INT64_C(1) << 26)

/* A window's raw samples: written from it (samples given), read into it
 * (samples malloc'd by amfi_store_raw_get: free with amfi_store_raw_free). */
typedef struct amfi_raw_window {
    int64_t utime;       /* data time of vehicle[0]'s entry: t = 0 of the
                            samples, µs, 0 .. AMFI_STORE_MAX_UTIME */
    double rate_hz;      /* sample rate, (0, 100000] Hz */
    double t_first_s;    /* time of sample 0 after utime, s, [-3600, 3600] */
    int n_samples;       /* per sensor, >= 1 */
    int n_sensors;       /* 1 .. AMFI_MAX_SENSORS */
    int sensor_id[AMFI_MAX_SENSORS];        /* 0 .. 255, in the samples' order */
    double sensor_at_m[AMFI_MAX_SENSORS];   /* position on the span, m, finite */
    int n_vehicles;      /* 1 .. AMFI_MAX_VEHICLES, by entry time */
    amfi_raw_vehicle vehicle[AMFI_MAX_VEHICLES];
    /* the solver's settings the window was weighed with (a reload changes
     * the λ policy between passages) */
    amfi_lambda lambda;
    int speed_estimate;  /* 1: amfi_solve_speed with speed_prior (one vehicle) */
    amfi_speed_prior speed_prior;
    /* sample k of sensor i (at t_first_s + k / rate_hz) is
     * samples[i * n_samples + k], m/s² */
    const double *samples;
} amfi_raw_window;

/* The raw part of a passage written with it (amfi_passage_row.raw): either
 * a new window (window != NULL, the passage is its vehicle `vehicle`) or a
 * link to a window stored before (window NULL, window_id > 0: a later
 * vehicle of the same event). Written in the passage's transaction, under
 * a savepoint: when the raw rows cannot be written (a bad window, the link's
 * window deleted, out of memory) the passage is stored without them and
 * status says why. The handle keeps the buffers the encoding needs (grown,
 * never shrunk: no allocation per passage once they fit). */
typedef struct amfi_raw_put {
    const amfi_raw_window *window;
    int float32;         /* 1: the window's samples rounded to float32
                            (AMFI_STORE_RAW_F32), 0: exact (AMFI_STORE_RAW_F64) */
    int64_t window_id;   /* the window linked to (window NULL) */
    int vehicle;         /* the passage's index in the window's vehicles */
    /* out */
    int status;          /* 0: written; else a status (message in err) */
    char err[256];
    int64_t stored_window_id; /* the window written or linked */
    int64_t bytes;       /* compressed bytes written (0 for a link) */
    int64_t raw_bytes;   /* their float64 bytes (0 for a link) */
} amfi_raw_put;

/* A passage's raw samples read back. */
typedef struct amfi_raw_rec {
    int64_t passage_id, window_id;
    int vehicle;         /* the passage's index in w.vehicle[] */
    int64_t bytes;       /* compressed bytes stored */
    int float32;         /* 1: stored rounded to float32 (w.samples are those
                            floats as doubles), 0: the float64 values */
    amfi_raw_window w;   /* w.samples malloc'd */
} amfi_raw_rec;

/* The raw samples of passage `passage_id`: *found = 0 when it has none
 * (never kept, deleted by retention, a store older than version 11: then 0
 * is returned too, with nothing read); else *found = 1 and *out filled,
 * every value checked and the samples decoded and verified (zlib's
 * checksum, their count): a damaged row or blob is AMFI_STORE_ECORRUPT
 * with a message naming the passage and its window. Works on any handle
 * (amfi_store_open_readonly too). Free with amfi_store_raw_free. */
int amfi_store_raw_get(amfi_store *s, int64_t passage_id, amfi_raw_rec *out, int *found,
                       char *err, size_t errlen);
void amfi_store_raw_free(amfi_raw_rec *r); /* NULL-safe; zeroes it */

/* The oldest raw window kept (store_web_raw.c): its utime, *found 0 when
 * there is none (or the store is older than version 11). The retention
 * deletes oldest first (utime, id): a window of a later utime was not
 * deleted by it (amfi-web's raw_reason). Any handle. */
int amfi_store_raw_oldest(amfi_store *s, int64_t *utime, int *found, char *err, size_t errlen);

/* One stored passage by id (amfi-solve --from-store; a page per passage):
 * vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
 * lambda, residual_rms, n_vehicles and the axles' spacing_m and axle_kg
 * (NaN where NULL; the other fields 0). row.status and row.reason point
 * into the struct. *found = 0 when there is no such passage. Any handle. */
typedef struct amfi_stored_passage {
    amfi_passage_row row;
    char status[16];
    char reason[AMFI_STORE_REASON_MAX + 1];
} amfi_stored_passage;
int amfi_store_passage_get(amfi_store *s, int64_t id, amfi_stored_passage *out, int *found,
                           char *err, size_t errlen);

/* The raw windows stored: count and compressed bytes. */
int amfi_store_raw_usage(amfi_store *s, int64_t *windows, int64_t *bytes, char *err,
                         size_t errlen);

/* Retention, oldest first (by utime, then id), in one transaction, at most
 * max_windows windows (>= 1) a call: the windows whose utime is before
 * before_utime (0: none by age), then the oldest while the windows' bytes
 * are above max_bytes (< 0: no bound). The passages stay. */
typedef struct amfi_raw_pruned {
    int64_t by_age, by_size;     /* windows deleted */
    int64_t bytes;               /* their compressed bytes */
    int more;                    /* 1: max_windows reached with more to delete */
} amfi_raw_pruned;
int amfi_store_raw_prune(amfi_store *s, int64_t before_utime, int64_t max_bytes, int max_windows,
                         amfi_raw_pruned *out, char *err, size_t errlen);

/* The codec alone (tests, measurements): n values in `sensors` runs of
 * n / sensors into a zlib blob, *out malloc'd (*outlen bytes), at zlib
 * level 1 .. 9, as float64 (float32 0) or rounded to float32 (float32 1: a
 * value beyond float's range is AMFI_EINVAL); and back (exactly n values,
 * else AMFI_STORE_ECORRUPT). */
int amfi_store_raw_encode(const double *x, int64_t n, int sensors, int level, int float32,
                          unsigned char **out, size_t *outlen, char *err, size_t errlen);
int amfi_store_raw_decode(const unsigned char *blob, size_t len, int64_t n, int sensors,
                          int float32, double *x, char *err, size_t errlen);

/* ---- the model fit and the natfreq alert (store_modelfit.c) -------------- */

/* The newest max (>= 1) passages' fit_ratio, or f1_comp_hz, that are not
 * NULL, oldest first: *out malloc'd (free it; NULL when *n is 0). A value
 * outside the schema's range is AMFI_STORE_ECORRUPT. */
int amfi_store_recent_fit_ratios(amfi_store *s, int max, double **out, size_t *n, char *err,
                                 size_t errlen);
int amfi_store_recent_f1_comp(amfi_store *s, int max, double **out, size_t *n, char *err,
                              size_t errlen);

/* One passage's model fit (passages.fit_ratio not NULL). */
typedef struct amfi_fit_rec {
    int64_t passage_id;
    int64_t utime;    /* data time, µs */
    double fit_ratio; /* RMS of (model − data) over the free vibration / RMS of the data */
} amfi_fit_rec;

/* The passages with a fit_ratio and from <= utime <= to, oldest first
 * (utime, id): *out is malloc'd (free it; NULL when *n is 0). A value
 * outside the schema's range is AMFI_STORE_ECORRUPT. */
int amfi_store_fit_ratio_series(amfi_store *s, int64_t from, int64_t to, amfi_fit_rec **out,
                                size_t *n, char *err, size_t errlen);

/* ---- rows as column values, for other programs (store_scan.c) ----------- */
/* amfi-sync ships a store's rows, amfi-report --pg and amfi-fleet-bench
 * write rows they did not compute: they see rows as the values of the
 * columns of store_columns.h (amfi_store_value), never the connection. Table
 * and column names are checked against the column table (nothing else
 * reaches SQL). */

#include "store_columns.h"

/* Open `path` read-only to read rows from elsewhere (amfi-sync): SQLite's
 * defensive mode, an untrusted schema, no extension loading, triggers and
 * views off, query_only, every setting read back; any schema version (the
 * caller checks *version, PRAGMA user_version) and no prepared statements
 * (only this section's functions and amfi_store_meta_get apply). When the
 * file cannot be read because its -shm can neither be opened nor created
 * and no -wal file exists (a reader without write access to the directory,
 * amfid stopped), and immutable_ok, it is opened immutable (no locks: right
 * only while nobody writes it) and *immutable is 1. Statuses: AMFI_STORE_EDB
 * (cannot open or read it), AMFI_STORE_ECORRUPT (not SQLite),
 * AMFI_STORE_ESCHEMA (a defence cannot be set). */
int amfi_store_open_reader(const char *path, int immutable_ok, amfi_store **out, int *version,
                           int *immutable, char *err, size_t errlen);

/* The type of schema object `name` ("table", "view", "index", "trigger";
 * "virtual table" for a CREATE VIRTUAL TABLE; "" when there is none) into
 * type (len >= 16). */
int amfi_store_object_type(amfi_store *s, const char *name, char *type, size_t len, char *err,
                           size_t errlen);

/* *max = the largest value of the table's key column
 * (amfi_store_tabledef.key), 0 when it has no rows. */
int amfi_store_max_key(amfi_store *s, const char *table, int64_t *max, char *err,
                       size_t errlen);

/* Called once per row with the values of the columns asked, in their order;
 * text values are valid during the call only. Nonzero stops the scan and
 * is returned. */
typedef int (*amfi_store_values_fn)(void *ctx, const amfi_store_value *v, int n);

/* The rows of `table` whose key column is in (lo, hi], by key, at most
 * limit (0: all), as the values of cols[0 .. ncols − 1] as the file holds
 * them (unchecked: amfi_store_value_problem says what is wrong). */
int amfi_store_scan(amfi_store *s, const char *table, const char *const *cols, int ncols,
                    int64_t lo, int64_t hi, int limit, amfi_store_values_fn fn, void *ctx,
                    char *err, size_t errlen);

/* Transactions around several calls of this section: a read snapshot
 * (BEGIN), a write (BEGIN IMMEDIATE), their end. */
enum { AMFI_STORE_TX_READ, AMFI_STORE_TX_WRITE, AMFI_STORE_TX_COMMIT, AMFI_STORE_TX_ROLLBACK };
int amfi_store_transaction(amfi_store *s, int what, char *err, size_t errlen);

/* Inserting rows of one table by column values (in an open write
 * transaction for speed): cols are the columns given, in the order of the
 * values. Every value is bound as given (text is converted by the STRICT
 * table as it would be from SQL); the schema's constraints judge the row:
 * a refused row gives AMFI_EINVAL with SQLite's message alone in err
 * ("CHECK constraint failed: ..."). */
typedef struct amfi_store_inserter amfi_store_inserter;
int amfi_store_inserter_open(amfi_store *s, const char *table, const char *const *cols, int ncols,
                             amfi_store_inserter **out, char *err, size_t errlen);
int amfi_store_insert_values(amfi_store_inserter *ins, const amfi_store_value *v, char *err,
                             size_t errlen);
void amfi_store_inserter_close(amfi_store_inserter *ins); /* NULL-safe */

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
