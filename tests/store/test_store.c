/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_store.c: unit tests of amfid's SQLite store (store/store.h).
 *
 * Each test works in a fresh directory under /tmp (removed afterwards) and
 * looks at the file with a second, raw sqlite3 connection: the schema
 * version and identity, what the rows hold (NULL for unknown numbers), that
 * a bad argument or a failure half-way stores nothing, that damaged rows
 * written behind the store's back (CHECK constraints switched off) are
 * reported by table and rowid, and that the views agree with naive C
 * computations of the same figures. docs/schema.md must hold exactly the
 * DDL the store creates. The bulk test stores 10 000 passages and prints
 * the insert rate.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "store.h"
#include "store_fixture.h"
#include "store_testing.h"

#ifndef AMFI_SCHEMA_DOC
#error "AMFI_SCHEMA_DOC (path of docs/schema.md) must be defined"
#endif

#define ERRLEN 512
#define DAY_US INT64_C(86400000000)

/* ---- fixtures ------------------------------------------------------------ */

static int setup(void **state) { return store_fixture_setup(state, "amfi_test_store"); }

static int teardown(void **state)
{
    static const char *const extra[] = {"other.db", "doc.db", "not-sqlite.db", NULL};
    return store_fixture_teardown(state, extra);
}

/* A raw connection to the fixture's file, as a user's sqlite3 would be
 * (store_testing.h). */
typedef amfi_store_test_db raw_db;
static raw_db *raw_open(const char *path)
{
    char err[512];
    raw_db *db = amfi_store_test_open(path, 0, err, sizeof err);
    if (!db)
        fail_msg("%s", err);
    return db;
}

/* The same, creating the file. */
static raw_db *raw_create(const char *path)
{
    char err[512];
    raw_db *db = amfi_store_test_open(path, 1, err, sizeof err);
    if (!db)
        fail_msg("%s", err);
    return db;
}

static void raw_close(raw_db *db) { amfi_store_test_close(db); }

static void raw_exec(raw_db *db, const char *sql)
{
    char err[1024];
    if (amfi_store_test_exec(db, sql, err, sizeof err) != 0)
        fail_msg("%s", err);
}

/* 0 when sql ran, -1 when SQLite refused it. */
static int raw_try(raw_db *db, const char *sql)
{
    char err[1024];
    return amfi_store_test_exec(db, sql, err, sizeof err);
}

/* The store taken back to version v, as that version's amfid left it. */
static void raw_downgrade(raw_db *db, int v)
{
    char err[1024];
    if (amfi_store_test_downgrade(db, v, err, sizeof err) != 0)
        fail_msg("downgrade to %d: %s", v, err);
}

/* First column of the first row as integer (0 when NULL / no row). */
static int64_t raw_int(raw_db *db, const char *sql)
{
    char err[1024];
    int64_t v = 0;
    if (amfi_store_test_int(db, sql, &v, err, sizeof err) != 0)
        fail_msg("%s", err);
    return v;
}

static double raw_real(raw_db *db, const char *sql)
{
    char err[1024];
    double v = NAN;
    if (amfi_store_test_real(db, sql, &v, NULL, err, sizeof err) != 0)
        fail_msg("%s", err);
    return v;
}

/* First column of the first row as text into buf ("" when none). */
static const char *raw_text(raw_db *db, const char *sql, char *buf, size_t len)
{
    char err[1024];
    if (amfi_store_test_text(db, sql, buf, len, err, sizeof err) != 0)
        fail_msg("%s", err);
    return buf;
}

/* An ok two-axle passage: 40 / 60 % of gvw, 4.5 m apart, 25 m/s. */
static void ok_row(amfi_passage_row *r, int64_t vehicle_id, int64_t utime,
                   double gvw_kg)
{
    memset(r, 0, sizeof *r);
    r->vehicle_id = vehicle_id;
    r->utime = utime;
    r->lane = 1;
    r->speed_mps = 25.0;
    r->speed_given_mps = 25.0;
    r->n_axles = 2;
    r->spacing_m[0] = 4.5;
    r->axle_kg[0] = 0.4 * gvw_kg;
    r->axle_kg[1] = 0.6 * gvw_kg;
    r->gvw_kg = gvw_kg;
    r->status = "ok";
    r->reason = "";
    r->lambda = 7.94e-9;
    r->residual_rms = 1e-3;
    r->formulation = "paper";
    r->solve_ms = 15.0;
}

static void add_ok(amfi_store *s, int64_t vehicle_id, int64_t utime,
                   double gvw_kg, int64_t *id)
{
    amfi_passage_row r;
    char err[ERRLEN];
    ok_row(&r, vehicle_id, utime, gvw_kg);
    if (amfi_store_add_passage(s, &r, id, err, sizeof err) != 0)
        fail_msg("add_passage: %s", err);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- open, schema, identity -------------------------------------------- */

static void test_create_and_reopen(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], buf[64];
    raw_db *db = raw_open(f->path);

    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_APPLICATION_ID, raw_int(db, "PRAGMA application_id"));
    assert_string_equal("wal", raw_text(db, "PRAGMA journal_mode", buf, sizeof buf));
    static const char *const objects[] = {
        "passages", "axles", "truth", "truth_axles", "indicators", "alerts",
        "baseline", "meta", "schema_migrations", "daily_trend", "window_trend",
        "passage_errors", "passages_utime", "passages_status_utime", "runs",
        "environment", "environment_utime"};
    for (size_t k = 0; k < sizeof objects / sizeof objects[0]; k++) {
        char q[160];
        snprintf(q, sizeof q, "SELECT count(*) FROM sqlite_schema WHERE name = '%s'", objects[k]);
        if (raw_int(db, q) != 1)
            fail_msg("schema object %s missing", objects[k]);
    }
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    raw_close(db);

    /* reopen: nothing migrates again, data stays */
    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    amfi_store_close(f->s);
    f->s = NULL;
    char wal[128];
    snprintf(wal, sizeof wal, "%s-wal", f->path);
    assert_int_not_equal(0, access(wal, F_OK)); /* checkpointed and removed */
    assert_int_equal(0, amfi_store_open(f->path, 1, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    raw_close(db);
}

static void test_refuse_newer_version(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_store *s2 = NULL;
    raw_db *db;

    amfi_store_close(f->s);
    f->s = NULL;
    db = raw_open(f->path);
    raw_exec(db, "PRAGMA user_version = 99");
    raw_close(db);

    err[0] = '\0';
    assert_int_equal(AMFI_STORE_ESCHEMA,
                     amfi_store_open(f->path, 0, &s2, err, sizeof err));
    assert_null(s2);
    assert_non_null(strstr(err, "schema version 99 is newer"));
    assert_non_null(strstr(err, f->path));
    assert_int_equal(AMFI_STORE_ESCHEMA,
                     amfi_store_open_readonly(f->path, &s2, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(99, raw_int(db, "PRAGMA user_version")); /* untouched */
    raw_close(db);
}

static void test_refuse_foreign_files(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], path[128];
    amfi_store *s2 = NULL;
    raw_db *db;
    FILE *fp;

    /* an SQLite database of something else */
    snprintf(path, sizeof path, "%s/other.db", f->dir);
    db = raw_create(path);
    raw_exec(db, "CREATE TABLE recipes (name TEXT)");
    raw_close(db);
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open(path, 0, &s2, err, sizeof err));
    assert_non_null(strstr(err, "not an amfi store"));
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(path, &s2, err, sizeof err));
    db = raw_open(path);
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM sqlite_schema")); /* untouched */
    raw_close(db);

    /* not SQLite at all */
    snprintf(path, sizeof path, "%s/not-sqlite.db", f->dir);
    fp = fopen(path, "w");
    assert_non_null(fp);
    for (int k = 0; k < 200; k++)
        fputs("this is a text file, not a database\n", fp);
    fclose(fp);
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_open(path, 0, &s2, err, sizeof err));
    assert_non_null(strstr(err, "not an SQLite database"));
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_open_readonly(path, &s2, err, sizeof err));
    assert_null(s2);

    /* missing file (read-only) and missing directory */
    snprintf(path, sizeof path, "%s/missing.db", f->dir);
    assert_int_equal(AMFI_STORE_EDB, amfi_store_open_readonly(path, &s2, err, sizeof err));
    assert_non_null(strstr(err, "No such file"));
    assert_int_not_equal(0, access(path, F_OK));
    snprintf(path, sizeof path, "%s/no/such/dir.db", f->dir);
    assert_int_equal(AMFI_STORE_EDB, amfi_store_open(path, 0, &s2, err, sizeof err));
    assert_non_null(strstr(err, "cannot open"));

    /* bad arguments */
    assert_int_equal(AMFI_EINVAL, amfi_store_open("", 0, &s2, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_open(NULL, 0, &s2, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_open(f->path, 0, NULL, err, sizeof err));
    amfi_store_close(NULL); /* NULL-safe */
    assert_string_equal("damaged database or row",
                        amfi_store_strerror(AMFI_STORE_ECORRUPT));
    assert_string_equal("invalid argument", amfi_store_strerror(AMFI_EINVAL));
}

/* ---- passages --------------------------------------------------------------- */

static void test_passage_with_axles(void **state)
{
    fixture *f = *state;
    amfi_passage_row r;
    char err[ERRLEN], buf[64];
    int64_t id = 0;
    raw_db *db;

    ok_row(&r, 42, 3 * DAY_US + 123, 25000.0);
    r.n_axles = 3;
    r.spacing_m[0] = 3.8;
    r.spacing_m[1] = 1.3;
    r.axle_kg[0] = 7000.0;
    r.axle_kg[1] = 9000.0;
    r.axle_kg[2] = 9000.0;
    r.lane = 2;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id, err, sizeof err));
    assert_true(id > 0);

    db = raw_open(f->path);
    assert_int_equal(42, raw_int(db, "SELECT vehicle_id FROM passages"));
    assert_int_equal(3 * DAY_US + 123, raw_int(db, "SELECT utime FROM passages"));
    assert_int_equal(2, raw_int(db, "SELECT lane FROM passages"));
    assert_int_equal(3, raw_int(db, "SELECT n_axles FROM passages"));
    assert_true(raw_real(db, "SELECT gvw_kg FROM passages") == 25000.0);
    assert_true(raw_real(db, "SELECT lambda FROM passages") == 7.94e-9);
    assert_string_equal("ok", raw_text(db, "SELECT status FROM passages", buf, sizeof buf));
    assert_string_equal("paper", raw_text(db, "SELECT formulation FROM passages", buf, sizeof buf));
    raw_text(db, "SELECT stored_at FROM passages", buf, sizeof buf);
    assert_int_equal(24, (int)strlen(buf)); /* 2026-11-22T05:06:07.123Z */
    assert_int_equal('Z', buf[23]);
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM axles"));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM axles WHERE idx = 1 AND spacing_m IS NULL"));
    assert_true(raw_real(db, "SELECT spacing_m FROM axles WHERE idx = 2") == 3.8);
    assert_true(raw_real(db, "SELECT spacing_m FROM axles WHERE idx = 3") == 1.3);
    assert_true(raw_real(db, "SELECT load_kg FROM axles WHERE idx = 1") == 7000.0);
    assert_true(raw_real(db, "SELECT sum(load_kg) FROM axles") == 25000.0);
    /* the cascade */
    raw_exec(db, "PRAGMA foreign_keys = ON; DELETE FROM passages");
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM axles"));
    raw_close(db);
}

static void test_unsolved_is_null(void **state)
{
    fixture *f = *state;
    amfi_passage_row r;
    char err[ERRLEN], buf[128];
    raw_db *db;

    ok_row(&r, 7, DAY_US, NAN);
    r.status = "gap";
    r.reason = "accelerometer gap of 12 samples in the window";
    r.axle_kg[0] = r.axle_kg[1] = NAN;
    r.lambda = r.residual_rms = r.solve_ms = NAN;
    r.formulation = NULL;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* an invalid event without known speed or axles */
    ok_row(&r, 8, DAY_US + 1, NAN);
    r.status = "invalid";
    r.reason = "speed -3 m/s";
    r.speed_mps = NAN;
    r.n_axles = 0;
    r.reason = NULL;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));

    db = raw_open(f->path);
    assert_string_equal("null", raw_text(db, "SELECT typeof(gvw_kg) FROM passages WHERE vehicle_id = 7", buf, sizeof buf));
    assert_string_equal("null", raw_text(db, "SELECT typeof(lambda) FROM passages WHERE vehicle_id = 7", buf, sizeof buf));
    assert_string_equal("null", raw_text(db, "SELECT typeof(formulation) FROM passages WHERE vehicle_id = 7", buf, sizeof buf));
    assert_string_equal("accelerometer gap of 12 samples in the window",
                        raw_text(db, "SELECT reason FROM passages WHERE vehicle_id = 7", buf, sizeof buf));
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM axles WHERE load_kg IS NULL"));
    assert_string_equal("null", raw_text(db, "SELECT typeof(speed_mps) FROM passages WHERE vehicle_id = 8", buf, sizeof buf));
    assert_string_equal("", raw_text(db, "SELECT reason FROM passages WHERE vehicle_id = 8", buf, sizeof buf));
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM axles"));
    raw_close(db);
}

typedef struct bad_case {
    const char *what;       /* the field changed */
    void (*spoil)(amfi_passage_row *r);
    const char *expect;     /* substring of the message */
} bad_case;

static void spoil_status(amfi_passage_row *r) { r->status = "maybe"; }
static void spoil_status_null(amfi_passage_row *r) { r->status = NULL; }
static void spoil_utime(amfi_passage_row *r) { r->utime = -1; }
static void spoil_lane(amfi_passage_row *r) { r->lane = 40000; }
static void spoil_axles(amfi_passage_row *r) { r->n_axles = AMFI_MAX_AXLES + 1; }
static void spoil_speed_inf(amfi_passage_row *r) { r->speed_mps = INFINITY; }
static void spoil_speed_high(amfi_passage_row *r) { r->speed_mps = 400.0; }
static void spoil_gvw_ok_nan(amfi_passage_row *r) { r->gvw_kg = NAN; }
static void spoil_gvw_ok_neg(amfi_passage_row *r) { r->gvw_kg = -5.0; }
static void spoil_spacing(amfi_passage_row *r) { r->spacing_m[0] = -1.0; }
static void spoil_axle_nan(amfi_passage_row *r) { r->axle_kg[1] = NAN; }
static void spoil_axle_inf(amfi_passage_row *r) { r->status = "error"; r->axle_kg[1] = -INFINITY; }
static void spoil_lambda(amfi_passage_row *r) { r->lambda = 0.0; }
static void spoil_residual(amfi_passage_row *r) { r->residual_rms = -1e-3; }
static void spoil_reason(amfi_passage_row *r) { r->reason = "two\nlines"; }
static void spoil_utf8(amfi_passage_row *r) { r->reason = "bad \xc3\x28 byte"; }
static void spoil_formulation(amfi_passage_row *r) { r->formulation = ""; }
static void spoil_ok_no_axles(amfi_passage_row *r) { r->n_axles = 0; }
static void spoil_ok_no_speed(amfi_passage_row *r) { r->speed_mps = NAN; }

static void test_invalid_rows_store_nothing(void **state)
{
    fixture *f = *state;
    static const bad_case cases[] = {
        {"status", spoil_status, "passages.status: 'maybe' is not one of ok, gap"},
        {"status NULL", spoil_status_null, "passages.status: NULL"},
        {"utime", spoil_utime, "passages.utime: -1 us is out of range"},
        {"lane", spoil_lane, "passages.lane: 40000"},
        {"n_axles", spoil_axles, "passages.n_axles: 13 is out of range [0, 12]"},
        {"speed inf", spoil_speed_inf, "passages.speed_mps: inf is not a finite"},
        {"speed 400", spoil_speed_high, "passages.speed_mps: 400 m/s is out of range [0, 150] m/s"},
        {"ok gvw NaN", spoil_gvw_ok_nan, "status ok: gvw_kg: NaN"},
        {"ok gvw < 0", spoil_gvw_ok_neg, "status ok: gvw_kg: -5 kg is out of range (0"},
        {"spacing", spoil_spacing, "spacing_m[0]: -1 m is out of range (0, 50] m"},
        {"ok axle NaN", spoil_axle_nan, "status ok: axle_kg[1]: NaN"},
        {"axle inf", spoil_axle_inf, "axle_kg[1]: -inf is not a finite"},
        {"lambda", spoil_lambda, "passages.lambda: 0 must be > 0"},
        {"residual", spoil_residual, "passages.residual_rms: -0.001 must be >= 0"},
        {"reason newline", spoil_reason, "passages.reason: control character"},
        {"reason UTF-8", spoil_utf8, "invalid UTF-8 at byte 4"},
        {"formulation", spoil_formulation, "passages.formulation: empty"},
        {"ok no axles", spoil_ok_no_axles, "status ok needs n_axles >= 1"},
        {"ok no speed", spoil_ok_no_speed, "status ok: speed_mps: NaN"},
    };
    amfi_passage_row r;
    char err[ERRLEN];
    raw_db *db = raw_open(f->path);

    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ok_row(&r, 1, DAY_US, 18000.0);
        cases[k].spoil(&r);
        err[0] = '\0';
        int rc = amfi_store_add_passage(f->s, &r, NULL, err, sizeof err);
        if (rc != AMFI_EINVAL || !strstr(err, cases[k].expect))
            fail_msg("%s: rc %d, message '%s', expected '%s'", cases[k].what,
                     rc, err, cases[k].expect);
    }
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, NULL, NULL, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(NULL, &r, NULL, err, sizeof err));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM passages"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM axles"));

    /* a failure half-way (the third axle row) undoes the passage row too */
    raw_exec(db, "CREATE TRIGGER fail_third_axle BEFORE INSERT ON axles "
                 "WHEN NEW.idx = 3 BEGIN SELECT RAISE(ABORT, 'injected'); END");
    ok_row(&r, 1, DAY_US, 18000.0);
    r.n_axles = 3;
    r.spacing_m[1] = 1.3;
    r.axle_kg[2] = 1000.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "axles: insert: injected"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM passages"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM axles"));
    raw_exec(db, "DROP TRIGGER fail_third_axle");
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM axles"));
    raw_close(db);
}

/* WAL: a reader in the middle of a read transaction does not block. */
static void test_reader_does_not_block(void **state)
{
    fixture *f = *state;
    raw_db *db = raw_open(f->path);
    char err[ERRLEN];
    amfi_passage_row r;
    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    raw_exec(db, "BEGIN");
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages"));
    ok_row(&r, 2, DAY_US + 1, 19000.0);
    double t0 = now_s();
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_true(now_s() - t0 < 1.0);
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages")); /* snapshot */
    raw_exec(db, "COMMIT");
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM passages"));
    raw_close(db);
}

/* ---- truth and passage_errors ---------------------------------------------- */

static void test_truth_and_errors_view(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    double axle[2], force[2];
    int64_t id[5];
    raw_db *db;
    static const double inferred[5] = {18000, 20500, 9800, 31000, NAN};
    static const double truth[5] = {18200, 20000, 10000, 30000, 15000};

    for (int k = 0; k < 5; k++) {
        amfi_passage_row r;
        ok_row(&r, 100 + k, DAY_US + k * 1000000, isnan(inferred[k]) ? 1 : inferred[k]);
        if (isnan(inferred[k])) {
            r.status = "multiple";
            r.gvw_kg = r.axle_kg[0] = r.axle_kg[1] = NAN;
        }
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id[k], err, sizeof err));
        axle[0] = 0.4 * truth[k];
        axle[1] = 0.6 * truth[k];
        force[0] = axle[0] * AMFI_GRAVITY;
        force[1] = NAN;
        assert_int_equal(0, amfi_store_add_truth(f->s, 100 + k, DAY_US + k * 1000000,
                                                 truth[k], 2, axle, force, 25.2,
                                                 err, sizeof err));
    }
    /* the same vehicle_id in an earlier simulation run: not the nearest */
    axle[0] = axle[1] = 500;
    assert_int_equal(0, amfi_store_add_truth(f->s, 100, 5, 1000.0, 2, axle, NULL,
                                             NAN, err, sizeof err));

    db = raw_open(f->path);
    assert_int_equal(6, raw_int(db, "SELECT count(*) FROM truth"));
    assert_int_equal(12, raw_int(db, "SELECT count(*) FROM truth_axles"));
    assert_int_equal(7, raw_int(db, "SELECT count(*) FROM truth_axles WHERE mean_force_N IS NULL"));
    assert_int_equal(5, raw_int(db, "SELECT count(*) FROM passage_errors"));
    for (int k = 0; k < 5; k++) {
        char sql[160];
        snprintf(sql, sizeof sql,
                 "SELECT gvw_error_pct FROM passage_errors WHERE passage_id = %lld",
                 (long long)id[k]);
        double e = raw_real(db, sql);
        if (isnan(inferred[k])) {
            assert_true(isnan(e));
        } else {
            double want = 100.0 * (inferred[k] - truth[k]) / truth[k];
            assert_true(fabs(e - want) < 1e-12 * fabs(want) + 1e-12);
        }
    }
    raw_close(db);

    /* bad truth */
    axle[0] = axle[1] = 1000;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_truth(f->s, 1, 0, 0.0, 2, axle, NULL, NAN, err, sizeof err));
    assert_non_null(strstr(err, "truth.gvw_kg"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_truth(f->s, 1, 0, 2000, 0, axle, NULL, NAN, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_truth(f->s, 1, 0, 2000, 2, NULL, NULL, NAN, err, sizeof err));
    axle[1] = NAN;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_truth(f->s, 1, 0, 2000, 2, axle, NULL, NAN, err, sizeof err));
    assert_non_null(strstr(err, "truth: axle_kg[1]: NaN"));
}

/* ---- indicators, alerts, window_trend -------------------------------------- */

static void test_indicators_alerts(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], buf[64];
    int64_t i1 = 0, i2 = 0, i3 = 0, a1 = 0;
    amfi_indicator_row r = {DAY_US, 0, NAN, NAN, NAN, NAN, NAN, NAN, "baseline"};
    raw_db *db;

    assert_int_equal(0, amfi_store_add_indicator(f->s, &r, &i1, err, sizeof err));
    r = (amfi_indicator_row){DAY_US + 1000, 200, 18100, 2400, 18000, 2000, 1.2, 0.004, "watch"};
    assert_int_equal(0, amfi_store_add_indicator(f->s, &r, &i2, err, sizeof err));
    r = (amfi_indicator_row){DAY_US + 2000, 200, 18200, 2600, 18000, 2000, 1.3, 1e-5, "alert"};
    assert_int_equal(0, amfi_store_add_indicator(f->s, &r, &i3, err, sizeof err));
    assert_true(i1 < i2 && i2 < i3);
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 2000, "warning", "std_increase",
                                             "STD of GVW 1.30 x baseline (p = 1e-05)",
                                             i3, 1, &a1, err, sizeof err));
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 2000, "info", "mean_shift",
                                             "mean GVW +1.1 %", i3, 1, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 3000, "info", "store",
                                             "no indicator behind this one", 0, 0, NULL,
                                             err, sizeof err));
    db = raw_open(f->path);
    /* i1, i2 without alerts: one row each; i3 with two alerts: two rows */
    assert_int_equal(4, raw_int(db, "SELECT count(*) FROM window_trend"));
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM window_trend WHERE alert_id IS NULL"));
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM window_trend WHERE indicator_id = (SELECT max(id) FROM indicators)"));
    assert_string_equal("1970-01-02 00:00:00", raw_text(db, "SELECT time_utc FROM window_trend LIMIT 1", buf, sizeof buf));
    assert_string_equal("null", raw_text(db, "SELECT typeof(baseline_std_kg) FROM indicators ORDER BY id LIMIT 1", buf, sizeof buf));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM alerts WHERE indicator_id IS NULL"));
    raw_close(db);

    /* bad ones */
    assert_int_equal(AMFI_EINVAL, amfi_store_add_alert(f->s, 0, "warning", "std_increase", "x",
                                                       999, 1, NULL, err, sizeof err));
    assert_non_null(strstr(err, "refers to a row that does not exist"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_alert(f->s, 0, "fatal", "k", "x", 0, 1, NULL, err, sizeof err));
    assert_non_null(strstr(err, "alerts.level: 'fatal' is not one of info, warning"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_alert(f->s, 0, "info", "Bad Kind", "x", 0, 1, NULL, err, sizeof err));
    assert_non_null(strstr(err, "alerts.kind"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_alert(f->s, 0, "info", "k", "", 0, 1, NULL, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_alert(f->s, 0, "info", "k", "x", 0, 2, NULL, err, sizeof err));
    r = (amfi_indicator_row){0, 10, 1, 1, 1, 1, 1, 1.5, "normal"};
    assert_int_equal(AMFI_EINVAL, amfi_store_add_indicator(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "indicators.p_value: 1.5 is out of range [0, 1]"));
    r.p_value = 0.5;
    r.state = "panic";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_indicator(f->s, &r, NULL, err, sizeof err));
    r.state = "normal";
    r.n = -1;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_indicator(f->s, &r, NULL, err, sizeof err));
}

/* ---- baseline, recent GVW, meta --------------------------------------------- */

static void test_baseline(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_baseline b, got;
    int found = -1;

    memset(&got, 0x5a, sizeof got);
    assert_int_equal(0, amfi_store_get_baseline(f->s, &got, &found, err, sizeof err));
    assert_int_equal(0, found);
    memset(&b, 0, sizeof b);
    b = (amfi_baseline){DAY_US, 500, 18000.0, 2070.0, "auto", ""};
    assert_int_equal(0, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    b = (amfi_baseline){2 * DAY_US, 300, 18100.5, 2100.25, "manual", "after bearing repair"};
    assert_int_equal(0, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    assert_int_equal(0, amfi_store_get_baseline(f->s, &got, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_int_equal(2 * DAY_US, got.utime_set);
    assert_int_equal(300, got.n);
    assert_true(got.mean_kg == 18100.5 && got.std_kg == 2100.25);
    assert_string_equal("manual", got.source);
    assert_string_equal("after bearing repair", got.note);

    b.n = 1;
    assert_int_equal(AMFI_EINVAL, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    assert_non_null(strstr(err, "baseline.n: 1"));
    b.n = 10;
    b.std_kg = 0;
    assert_int_equal(AMFI_EINVAL, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    b.std_kg = 1;
    snprintf(b.source, sizeof b.source, "guess");
    assert_int_equal(AMFI_EINVAL, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    snprintf(b.source, sizeof b.source, "auto");
    memset(b.note, 'x', sizeof b.note); /* not terminated */
    assert_int_equal(AMFI_EINVAL, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    assert_non_null(strstr(err, "baseline.note: not terminated"));
}

static void test_recent_ok_gvw(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    double g[16];
    int n = -1;
    amfi_passage_row r;
    /* utimes out of insertion order; every third not ok */
    static const int64_t t[9] = {50, 10, 40, 20, 90, 30, 70, 60, 80};

    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 4, g, &n, err, sizeof err));
    assert_int_equal(0, n);
    for (int k = 0; k < 9; k++) {
        ok_row(&r, k, DAY_US + t[k], 10000.0 + (double)t[k]);
        if (k % 3 == 2) {
            r.status = "late";
            r.reason = "arrived after the window closed";
        }
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    }
    /* ok: t = 50 10 20 90 70 60 → newest 4 oldest first: 50 60 70 90 */
    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 4, g, &n, err, sizeof err));
    assert_int_equal(4, n);
    assert_true(g[0] == 10050 && g[1] == 10060 && g[2] == 10070 && g[3] == 10090);
    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 16, g, &n, err, sizeof err));
    assert_int_equal(6, n);
    for (int k = 1; k < n; k++)
        assert_true(g[k - 1] < g[k]);
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_ok_gvw(f->s, 0, g, &n, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_ok_gvw(f->s, 4, NULL, &n, err, sizeof err));
}

/* The window refill under a class filter: class, weight fed (gvw_comp_kg,
 * else gvw_kg) and single presence select the rows; the order and LIMIT are
 * recent_ok_gvw's. */
static void test_recent_fed_gvw(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    double g[16];
    int n = -1;
    amfi_passage_row r;
    static const char *const cls[8] = {"A23", "R2", "A23", "A33", "A23", NULL, "A23", "A23"};
    for (int k = 0; k < 8; k++) {
        ok_row(&r, k, DAY_US + 10 * (k + 1), 20000.0 + 1000.0 * k);
        r.vclass = cls[k];
        if (k == 2)
            r.gvw_comp_kg = 15000.0; /* light at the calibration temperature */
        if (k == 6)
            r.n_vehicles = 2;        /* weighed with another vehicle */
        if (k == 7) {
            r.status = "late";
            r.reason = "arrived after the window closed";
        }
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    }
    const char *a23[] = {"A23"}, *two[] = {"A23", "A33"};
    /* A23 ok: k = 0 2 4 6; from 18 t: 0 4 6; alone: 0 4 */
    assert_int_equal(0, amfi_store_recent_fed_gvw(f->s, 16, a23, 1, 18000.0, 0, g, &n, err,
                                                  sizeof err));
    assert_int_equal(3, n);
    assert_true(g[0] == 20000.0 && g[1] == 24000.0 && g[2] == 26000.0);
    assert_int_equal(0, amfi_store_recent_fed_gvw(f->s, 16, a23, 1, 18000.0, 1, g, &n, err,
                                                  sizeof err));
    assert_int_equal(2, n);
    assert_true(g[0] == 20000.0 && g[1] == 24000.0);
    /* the LIMIT keeps the newest */
    assert_int_equal(0, amfi_store_recent_fed_gvw(f->s, 1, two, 2, 0.0, 0, g, &n, err,
                                                  sizeof err));
    assert_int_equal(1, n);
    assert_true(g[0] == 26000.0);
    assert_int_equal(0, amfi_store_recent_fed_gvw(f->s, 16, two, 2, 0.0, 0, g, &n, err,
                                                  sizeof err));
    assert_int_equal(5, n);
    assert_true(g[1] == 15000.0 && g[2] == 23000.0);
    /* no class: every ok passage, as recent_ok_gvw */
    assert_int_equal(0, amfi_store_recent_fed_gvw(f->s, 16, NULL, 0, 0.0, 0, g, &n, err,
                                                  sizeof err));
    assert_int_equal(7, n);
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_fed_gvw(f->s, 16, NULL, 1, 0.0, 0, g, &n,
                                                            err, sizeof err));
    const char *bad[] = {""};
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_fed_gvw(f->s, 16, bad, 1, 0.0, 0, g, &n,
                                                            err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_fed_gvw(f->s, 16, a23, 1, -1.0, 0, g, &n,
                                                            err, sizeof err));
}

static void test_meta(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], val[64], big[AMFI_STORE_META_VALUE_MAX + 2];
    int found = -1;

    assert_int_equal(0, amfi_store_meta_get(f->s, "last_vehicle_id", val, sizeof val, &found, err, sizeof err));
    assert_int_equal(0, found);
    assert_string_equal("", val);
    assert_int_equal(0, amfi_store_meta_set(f->s, "last_vehicle_id", "41", err, sizeof err));
    assert_int_equal(0, amfi_store_meta_set(f->s, "last_vehicle_id", "42", err, sizeof err));
    assert_int_equal(0, amfi_store_meta_set(f->s, "empty", "", err, sizeof err));
    assert_int_equal(0, amfi_store_meta_get(f->s, "last_vehicle_id", val, sizeof val, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_string_equal("42", val);
    assert_int_equal(0, amfi_store_meta_get(f->s, "empty", val, sizeof val, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_string_equal("", val);
    /* too long for the caller's buffer: an error, never a truncated value */
    assert_int_equal(AMFI_EINVAL, amfi_store_meta_get(f->s, "last_vehicle_id", val, 2, &found, err, sizeof err));
    assert_non_null(strstr(err, "value is 2 bytes, the buffer holds 1"));
    assert_int_equal(0, found);
    memset(big, 'v', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    assert_int_equal(AMFI_EINVAL, amfi_store_meta_set(f->s, "k", big, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_meta_set(f->s, "bad key", "v", err, sizeof err));
    assert_non_null(strstr(err, "meta.key"));
    assert_int_equal(AMFI_EINVAL, amfi_store_meta_set(f->s, "", "v", err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_meta_get(f->s, "k'; DROP TABLE meta; --", val, sizeof val, &found, err, sizeof err));
}

/* ---- damage ----------------------------------------------------------------- */

static void test_integrity_check(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], result[256];
    raw_db *db;

    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    assert_int_equal(0, amfi_store_integrity_check(f->s, result, sizeof result, err, sizeof err));
    assert_string_equal("ok", result);
    /* an axle row whose passage is gone, written with foreign keys off */
    db = raw_open(f->path);
    raw_exec(db, "PRAGMA foreign_keys = OFF; "
                 "INSERT INTO axles (passage_id, idx, spacing_m, load_kg) VALUES (999, 1, NULL, 10)");
    raw_close(db);
    assert_int_equal(0, amfi_store_integrity_check(f->s, result, sizeof result, err, sizeof err));
    assert_non_null(strstr(result, "foreign key: a axles row refers to a missing passages row"));
    assert_int_equal(AMFI_EINVAL, amfi_store_integrity_check(f->s, NULL, 0, err, sizeof err));
}

/* Rows damaged behind the store's back: CHECK constraints switched off in a
 * raw connection, and a table whose STRICT was edited away so that a text
 * could go into a REAL column. Each read reports table and rowid. */
static void test_corrupt_rows_reported(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], val[64];
    double g[8];
    int n = 0, found = 0;
    int64_t id = 0;
    amfi_baseline b = {DAY_US, 100, 18000.0, 2000.0, "auto", ""};
    raw_db *db;
    char sql[160], expect[96];

    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    add_ok(f->s, 2, DAY_US + 1, 19000.0, &id);
    assert_int_equal(0, amfi_store_set_baseline(f->s, &b, err, sizeof err));
    assert_int_equal(0, amfi_store_meta_set(f->s, "state", "running", err, sizeof err));

    db = raw_open(f->path);
    raw_exec(db, "PRAGMA ignore_check_constraints = ON");
    snprintf(sql, sizeof sql, "UPDATE passages SET gvw_kg = -5 WHERE id = %lld", (long long)id);
    raw_exec(db, sql);
    raw_exec(db, "UPDATE baseline SET std_kg = 0");
    raw_exec(db, "UPDATE meta SET value = 'two' || char(10) || 'lines'");

    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_recent_ok_gvw(f->s, 8, g, &n, err, sizeof err));
    snprintf(expect, sizeof expect, "passages row %lld: gvw_kg: -5 kg is out of range", (long long)id);
    if (!strstr(err, expect))
        fail_msg("got '%s', expected '%s'", err, expect);
    assert_int_equal(0, n);
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_get_baseline(f->s, &b, &found, err, sizeof err));
    assert_non_null(strstr(err, "baseline row 1: std_kg: 0 kg is out of range (0, 1e+06] kg"));
    assert_int_equal(0, found);
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_meta_get(f->s, "state", val, sizeof val, &found, err, sizeof err));
    assert_non_null(strstr(err, "meta row 1: value holds a control character"));
    assert_int_equal(0, found);

    /* an ok passage with no GVW at all */
    snprintf(sql, sizeof sql, "UPDATE passages SET gvw_kg = NULL WHERE id = %lld", (long long)id);
    raw_exec(db, sql);
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_recent_ok_gvw(f->s, 8, g, &n, err, sizeof err));
    assert_non_null(strstr(err, "gvw_kg is NULL, expected a number"));

    /* a text in a REAL column: only possible once STRICT is edited away */
    raw_exec(db, "PRAGMA writable_schema = ON; "
                 "UPDATE sqlite_schema SET sql = replace(sql, ') STRICT', ')') "
                 "WHERE name = 'baseline'; PRAGMA writable_schema = OFF");
    raw_close(db);
    db = raw_open(f->path);
    raw_exec(db, "PRAGMA ignore_check_constraints = ON; "
                 "UPDATE baseline SET std_kg = 2000, mean_kg = 'lots'");
    raw_close(db);
    amfi_store_close(f->s); /* the new schema is seen by a new connection */
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_get_baseline(f->s, &b, &found, err, sizeof err));
    assert_non_null(strstr(err, "baseline row 1: mean_kg is text, expected a number"));
}

static void test_readonly(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_store *ro = NULL;
    amfi_passage_row r;
    amfi_baseline b;
    double g[4];
    int n = 0, found = 0;

    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    assert_int_equal(0, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    ok_row(&r, 2, DAY_US + 1, 18000.0);
    assert_int_equal(AMFI_STORE_EDB, amfi_store_add_passage(ro, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "read-only"));
    assert_int_equal(AMFI_STORE_EDB, amfi_store_meta_set(ro, "k", "v", err, sizeof err));
    assert_int_equal(0, amfi_store_recent_ok_gvw(ro, 4, g, &n, err, sizeof err));
    assert_int_equal(1, n);
    assert_int_equal(0, amfi_store_get_baseline(ro, &b, &found, err, sizeof err));
    /* the read-only handle answers the report queries */
    int64_t count = 0;
    assert_int_equal(0, amfi_store_count(ro, AMFI_STORE_PASSAGES, &count, err, sizeof err));
    assert_int_equal(1, count);
    amfi_store_close(ro);
}

/* ---- version 2: runs; a version-1 file migrates ------------------------------ */

static void test_runs_and_migration_from_v1(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], buf[128];
    int64_t id = 0;
    amfi_store *ro = NULL;
    raw_db *db;

    assert_int_equal(0, amfi_store_add_run(f->s, "0.1.0", "/etc/amfid/amfid.yaml", &id,
                                           err, sizeof err));
    assert_true(id > 0);
    assert_int_equal(AMFI_EINVAL, amfi_store_add_run(f->s, "", "/x", NULL, err, sizeof err));
    assert_non_null(strstr(err, "runs.version"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_run(f->s, "1\n2", "/x", NULL, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_run(f->s, "1", "", NULL, err, sizeof err));
    assert_non_null(strstr(err, "runs.config_path"));
    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    amfi_store_close(f->s);
    f->s = NULL;

    /* make it a version-1 file, as an older amfid left it */
    db = raw_open(f->path);
    assert_string_equal("0.1.0", raw_text(db, "SELECT version FROM runs", buf, sizeof buf));
    assert_string_equal("/etc/amfid/amfid.yaml",
                        raw_text(db, "SELECT config_path FROM runs", buf, sizeof buf));
    assert_int_equal(1, raw_int(db, "SELECT started_at LIKE '____-__-__T__:__:__.___Z' FROM runs"));
    raw_downgrade(db, 1);
    raw_close(db);

    /* read-only openers do not migrate: they say so */
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 1 is older than this program's"));
    assert_null(ro);

    /* read-write: migrated, the data kept */
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM runs"));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages"));
    raw_close(db);
    assert_int_equal(0, amfi_store_add_run(f->s, "0.2.0", "a.yaml", &id, err, sizeof err));
    assert_int_equal(1, id);
}

/* ---- version 3: the detector's speed; a version-2 file migrates -------------- */

static void test_speed_given_and_migration_from_v2(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_passage_row r;
    amfi_store *ro = NULL;
    raw_db *db;

    /* an estimated speed beside the detector's */
    ok_row(&r, 1, DAY_US, 18000.0);
    r.speed_mps = 24.1;
    r.speed_given_mps = 25.0;
    r.speed_estimated = 1;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    r.speed_given_mps = 400.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.speed_given_mps: 400 m/s is out of range"));
    r.speed_given_mps = 25.0;
    r.speed_estimated = 2;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.speed_estimated: 2 is not 0 or 1"));
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    assert_int_equal(1, raw_int(db, "SELECT speed_estimated FROM passages"));
    assert_int_equal(1, raw_int(db, "SELECT speed_given_mps = 25.0 AND speed_mps = 24.1 "
                                    "FROM passages"));
    /* make it a version-2 file: the detector's speed was the one weighed with */
    raw_exec(db, "UPDATE passages SET speed_mps = 25.0");
    raw_downgrade(db, 2);
    raw_close(db);

    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 2 is older than this program's"));
    assert_null(ro);

    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages WHERE speed_given_mps = 25.0 "
                                    "AND speed_mps = 25.0 AND speed_estimated = 0"));
    raw_close(db);
    ok_row(&r, 2, 2 * DAY_US, 18000.0);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
}

/* ---- version 4: vehicles weighed together; a version-3 file migrates --------- */

static void test_event_columns_and_migration_from_v3(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_passage_row r;
    amfi_store *ro = NULL;
    raw_db *db;

    ok_row(&r, 1, DAY_US, 18000.0); /* memset: n_vehicles 0 (taken as 1), quality 0 (NULL) */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 2, DAY_US + 500000, 21000.0);
    r.n_vehicles = 3;
    r.quality = 1.7;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    r.n_vehicles = 65;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.n_vehicles: 65 is out of range"));
    r.n_vehicles = 2;
    r.quality = 0.5;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.quality"));
    r.quality = INFINITY;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.quality"));
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages WHERE vehicle_id = 1 AND "
                                    "n_vehicles = 1 AND quality IS NULL"));
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages WHERE vehicle_id = 2 AND "
                                    "n_vehicles = 3 AND quality = 1.7"));
    /* make it a version-3 file, as amfid before issue 13 left it */
    raw_downgrade(db, 3);
    raw_close(db);

    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 3 is older than this program's"));
    assert_null(ro);

    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM passages WHERE n_vehicles = 1 "
                                    "AND quality IS NULL"));
    raw_close(db);
    ok_row(&r, 3, 2 * DAY_US, 18000.0);
    r.n_vehicles = 2;
    r.quality = 4.0;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
}

/* ---- version 5: the environment; a version-4 file migrates ------------------ */

static void test_environment_and_migration_from_v4(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    double t = 0.0;
    amfi_environment_summary sum;
    const int64_t H = INT64_C(3600000000); /* an hour, µs */
    amfi_environment_row rows[3] = {
        {DAY_US, 10.0, 8.0, DAY_US + 5},
        {DAY_US + H, 14.0, 9.5, DAY_US + H + 5},
        {DAY_US + 5 * H, -2.0, -4.0, DAY_US + 5 * H + 5},
    };

    /* empty table: NaN, a summary of nothing */
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US, H, &t, err, sizeof err));
    assert_true(isnan(t));
    assert_int_equal(0, amfi_store_environment_summary(f->s, &sum, err, sizeof err));
    assert_int_equal(0, sum.n);
    assert_true(isnan(sum.deck_min_c));

    assert_int_equal(0, amfi_store_add_environment(f->s, rows, 3, err, sizeof err));
    assert_int_equal(0, amfi_store_add_environment(f->s, rows, 0, err, sizeof err));
    /* at a reading, between two within the gap (linear), between two too far
     * apart (the nearer within half the gap, else NaN), outside the readings */
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US, H, &t, err, sizeof err));
    assert_float_equal(10.0, t, 1e-12);
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + H / 4, H, &t, err, sizeof err));
    assert_float_equal(11.0, t, 1e-12);
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + H + H / 4, H, &t, err, sizeof err));
    assert_float_equal(14.0, t, 1e-12); /* 4 h gap: nearest, 15 min away */
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + 3 * H, H, &t, err, sizeof err));
    assert_true(isnan(t)); /* 2 h from either */
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + 3 * H, 4 * H, &t, err, sizeof err));
    assert_float_equal(6.0, t, 1e-12); /* gap 4 h allowed: linear, halfway */
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + 5 * H + H / 2, H, &t, err, sizeof err));
    assert_float_equal(-2.0, t, 1e-12);
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US - H, H, &t, err, sizeof err));
    assert_true(isnan(t));
    assert_int_equal(0, amfi_store_environment_summary(f->s, &sum, err, sizeof err));
    assert_int_equal(3, sum.n);
    assert_int_equal(DAY_US, sum.utime_first);
    assert_int_equal(DAY_US + 5 * H, sum.utime_last);
    assert_float_equal(-2.0, sum.deck_min_c, 0);
    assert_float_equal(14.0, sum.deck_max_c, 0);
    assert_float_equal(-4.0, sum.air_min_c, 0);
    assert_float_equal(9.5, sum.air_max_c, 0);

    /* a batch with one bad row stores nothing, and the message names it */
    amfi_environment_row bad[2] = {{DAY_US + 6 * H, 1.0, 1.0, 1}, {DAY_US + 7 * H, NAN, 1.0, 1}};
    assert_int_equal(AMFI_EINVAL, amfi_store_add_environment(f->s, bad, 2, err, sizeof err));
    assert_non_null(strstr(err, "environment[1].deck_c: NaN"));
    bad[1].deck_c = 81.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_environment(f->s, bad, 2, err, sizeof err));
    assert_non_null(strstr(err, "environment[1].deck_c"));
    bad[1].deck_c = 1.0;
    bad[1].air_c = -61.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_environment(f->s, bad, 2, err, sizeof err));
    assert_non_null(strstr(err, "environment[1].air_c"));
    bad[1].air_c = 1.0;
    bad[1].utime = -1;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_environment(f->s, bad, 2, err, sizeof err));
    assert_non_null(strstr(err, "environment[1].utime"));
    assert_int_equal(AMFI_EINVAL, amfi_store_add_environment(f->s, NULL, 1, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_deck_c_at(f->s, DAY_US, -1, &t, err, sizeof err));
    assert_int_equal(0, amfi_store_environment_summary(f->s, &sum, err, sizeof err));
    assert_int_equal(3, sum.n);
    amfi_store_close(f->s);
    f->s = NULL;

    /* the schema refuses what the checks refuse */
    raw_db *db = raw_open(f->path);
    assert_int_not_equal(0, raw_try(db, "INSERT INTO environment (utime, deck_c, "
                                                     "air_c, received_utime) VALUES (1, 90, 0, 1)"));
    /* make it a version-4 file, as amfid before issue 14 left it */
    raw_downgrade(db, 4);
    raw_close(db);
    amfi_store *ro = NULL;
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 4 is older than this program's"));
    assert_null(ro);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM environment"));
    raw_close(db);
    assert_int_equal(0, amfi_store_add_environment(f->s, rows, 2, err, sizeof err));
    assert_int_equal(0, amfi_store_deck_c_at(f->s, DAY_US + H / 2, H, &t, err, sizeof err));
    assert_float_equal(12.0, t, 1e-12);
}


/* ---- version 6: reference GVW, deck temperature, scale_evals; a version-5
 * file migrates --------------------------------------------------------- */

static void test_scale_rows_and_migration_from_v5(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_passage_row r;
    amfi_scale_input *in = NULL;
    amfi_scale_eval_rec *ev = NULL;
    size_t n = 0;
    int64_t id = 0;

    /* passages: a plain one, one with a temperature, a calibration truck */
    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    ok_row(&r, 2, DAY_US + 10, 17000.0);
    r.has_deck_c = 1;
    r.deck_c = 0.0; /* 0 °C is a temperature, not "none" */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 3, DAY_US + 20, 14100.0);
    r.has_deck_c = 1;
    r.deck_c = -12.5;
    r.reference_gvw_kg = 14000.0;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id, err, sizeof err));
    /* refused: a reference out of [1 t, 100 t] or not finite, a temperature
     * out of range or NaN when given; the message names the column */
    r.reference_gvw_kg = 999.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.reference_gvw_kg"));
    r.reference_gvw_kg = INFINITY;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.reference_gvw_kg"));
    r.reference_gvw_kg = 14000.0;
    r.deck_c = NAN;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.deck_c"));
    r.deck_c = 81.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.deck_c"));

    /* the inputs: ok with a temperature, by id, paged */
    assert_int_equal(0, amfi_store_scale_inputs(f->s, 0, 10, &in, &n, err, sizeof err));
    assert_int_equal(2, n);
    assert_float_equal(17000.0, in[0].gvw_kg, 0);
    assert_float_equal(0.0, in[0].deck_c, 0);
    assert_true(isnan(in[0].reference_gvw_kg));
    assert_int_equal(1, in[0].n_vehicles);
    assert_int_equal(id, in[1].id);
    assert_float_equal(-12.5, in[1].deck_c, 0);
    assert_float_equal(14000.0, in[1].reference_gvw_kg, 0);
    int64_t first = in[0].id;
    free(in);
    assert_int_equal(0, amfi_store_scale_inputs(f->s, first, 1, &in, &n, err, sizeof err));
    assert_int_equal(1, n);
    assert_int_equal(id, in[0].id);
    free(in);
    assert_int_equal(0, amfi_store_scale_inputs(f->s, id, 10, &in, &n, err, sizeof err));
    assert_int_equal(0, n);
    assert_null(in);
    assert_int_equal(AMFI_EINVAL, amfi_store_scale_inputs(f->s, 0, 0, &in, &n, err, sizeof err));

    /* evaluations: stored, read back by kind and time, checked */
    amfi_scale_eval_row e = {DAY_US + 30, "scale_shift", 500, 1.01, 1.03, 12.0, 0.4, 0.0, 9.5,
                             "normal"};
    assert_int_equal(0, amfi_store_add_scale_eval(f->s, &e, &id, err, sizeof err));
    amfi_scale_eval_row k = {DAY_US + 20, "known_truck", 1, 1.007, 1.02, -12.5, NAN, NAN, NAN,
                             "baseline"};
    assert_int_equal(0, amfi_store_add_scale_eval(f->s, &k, NULL, err, sizeof err));
    e.utime = DAY_US + 25;
    e.cusum = 2.5;
    e.state = "watch";
    assert_int_equal(0, amfi_store_add_scale_eval(f->s, &e, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_scale_evals(f->s, "scale_shift", &ev, &n, err, sizeof err));
    assert_int_equal(2, n);
    assert_int_equal(DAY_US + 25, ev[0].utime); /* by time */
    assert_string_equal("watch", ev[0].state);
    assert_float_equal(2.5, ev[0].cusum, 0);
    assert_int_equal(id, ev[1].id);
    assert_float_equal(1.01, ev[1].value, 0);
    assert_float_equal(1.03, ev[1].raw, 0);
    assert_float_equal(12.0, ev[1].deck_c, 0);
    assert_int_equal(500, ev[1].n);
    assert_string_equal("scale_shift", ev[1].kind);
    free(ev);
    assert_int_equal(0, amfi_store_scale_evals(f->s, "known_truck", &ev, &n, err, sizeof err));
    assert_int_equal(1, n);
    assert_true(isnan(ev[0].cusum));
    assert_string_equal("baseline", ev[0].state);
    free(ev);
    e.kind = "scale";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_scale_eval(f->s, &e, NULL, err, sizeof err));
    assert_non_null(strstr(err, "scale_evals.kind"));
    e.kind = "scale_shift";
    e.value = 0.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_scale_eval(f->s, &e, NULL, err, sizeof err));
    assert_non_null(strstr(err, "scale_evals.value"));
    e.value = 1.0;
    e.cusum = -1.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_scale_eval(f->s, &e, NULL, err, sizeof err));
    assert_non_null(strstr(err, "scale_evals.cusum"));
    e.cusum = 0.0;
    e.state = "raised";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_scale_eval(f->s, &e, NULL, err, sizeof err));
    assert_non_null(strstr(err, "scale_evals.state"));
    assert_int_equal(AMFI_EINVAL, amfi_store_scale_evals(f->s, "std_increase", &ev, &n, err,
                                                         sizeof err));
    amfi_store_close(f->s);
    f->s = NULL;

    /* the schema refuses what the checks refuse */
    raw_db *db = raw_open(f->path);
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET reference_gvw_kg = 500"));
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET deck_c = -61"));
    /* make it a version-5 file, as amfid before this step left it */
    raw_downgrade(db, 5);
    raw_close(db);
    amfi_store *ro = NULL;
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 5 is older than this program's"));
    assert_null(ro);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM passages WHERE deck_c IS NULL AND "
                                    "reference_gvw_kg IS NULL"));
    assert_int_equal(0, raw_int(db, "SELECT count(*) FROM scale_evals"));
    raw_close(db);
    /* old rows are no inputs (no temperature); new ones are */
    assert_int_equal(0, amfi_store_scale_inputs(f->s, 0, 10, &in, &n, err, sizeof err));
    assert_int_equal(0, n);
    ok_row(&r, 4, DAY_US + 40, 15000.0);
    r.has_deck_c = 1;
    r.deck_c = 5.0;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_scale_inputs(f->s, 0, 10, &in, &n, err, sizeof err));
    assert_int_equal(1, n);
    assert_float_equal(5.0, in[0].deck_c, 0);
    free(in);
}

/* ---- version 7: the natural frequency; a version-6 file migrates ------------ */

static void test_f1_and_migration_from_v6(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_passage_row r;
    amfi_store *ro = NULL;
    amfi_f1_rec *a = NULL;
    size_t n = 9;
    raw_db *db;

    ok_row(&r, 1, DAY_US, 18000.0); /* memset: f1_hz 0, none (NULL) */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 2, DAY_US + 1000, 18000.0);
    r.f1_hz = 5.73;
    r.f1_comp_hz = 5.70;
    r.f1_zeta = 0.03;
    r.f1_r2 = 0.98;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 3, DAY_US + 2000, 18000.0);
    r.f1_hz = 5.6;
    r.f1_comp_hz = NAN; /* before the baseline */
    r.f1_zeta = 0.031;
    r.f1_r2 = 0.9;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* refused, naming the field */
    r.f1_hz = 2000;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.f1_hz"));
    r.f1_hz = -1;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.f1_hz"));
    r.f1_hz = 5.6;
    r.f1_comp_hz = INFINITY;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.f1_comp_hz"));
    r.f1_comp_hz = NAN;
    r.f1_zeta = 1.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.f1_zeta"));
    r.f1_zeta = 0.03;
    r.f1_r2 = 1.5;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.f1_r2"));
    /* the series: the two with an f1, oldest first; a limit */
    assert_int_equal(0, amfi_store_f1_series(f->s, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err,
                                             sizeof err));
    assert_int_equal(2, n);
    assert_float_equal(5.73, a[0].f1_hz, 0);
    assert_float_equal(5.70, a[0].f1_comp_hz, 0);
    assert_float_equal(0.03, a[0].f1_zeta, 0);
    assert_float_equal(0.98, a[0].f1_r2, 0);
    assert_true(a[0].utime == DAY_US + 1000);
    assert_true(isnan(a[1].f1_comp_hz));
    free(a);
    assert_int_equal(0, amfi_store_f1_series(f->s, 0, AMFI_STORE_MAX_UTIME, 1, &a, &n, err,
                                             sizeof err));
    assert_int_equal(1, n);
    assert_float_equal(5.73, a[0].f1_hz, 0);
    free(a);
    assert_int_equal(0, amfi_store_f1_series(f->s, 0, DAY_US, 0, &a, &n, err, sizeof err));
    assert_int_equal(0, n);
    assert_null(a);
    assert_int_equal(AMFI_EINVAL,
                     amfi_store_f1_series(f->s, 0, DAY_US, -1, &a, &n, err, sizeof err));
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages WHERE vehicle_id = 1 AND "
                                    "f1_hz IS NULL AND f1_comp_hz IS NULL AND f1_zeta IS NULL "
                                    "AND f1_r2 IS NULL"));
    /* the schema refuses what the checks refuse */
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET f1_hz = 0 WHERE vehicle_id = 2"));
    /* make it a version-6 file, as amfid before the natural frequency left it */
    raw_downgrade(db, 6);
    raw_close(db);
    assert_int_equal(AMFI_STORE_ESCHEMA, amfi_store_open_readonly(f->path, &ro, err, sizeof err));
    assert_non_null(strstr(err, "schema version 6 is older than this program's"));
    assert_null(ro);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "SELECT count(*) FROM schema_migrations"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM passages WHERE f1_hz IS NULL"));
    raw_close(db);
    assert_int_equal(0, amfi_store_f1_series(f->s, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err,
                                             sizeof err));
    assert_int_equal(0, n);
    ok_row(&r, 4, 2 * DAY_US, 18000.0);
    r.f1_hz = 5.5;
    r.f1_zeta = 0.02;
    r.f1_r2 = 0.95;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_f1_series(f->s, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err,
                                             sizeof err));
    assert_int_equal(1, n);
    free(a);
}

/* ---- version 10: class, axle groups, overload; a version-9 file migrates ----- */

static void test_class_and_migration_from_v9(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], buf[64];
    amfi_passage_row r;
    raw_db *db;

    ok_row(&r, 1, DAY_US, 18000.0); /* memset: no class, groups, overload (NULL) */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 2, DAY_US + 1000, 41000.0);
    r.vclass = "A23";
    r.axle_groups = "1-1-3";
    r.has_overload = 1;
    r.overload = 1;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    r.has_overload = 1;
    r.overload = 0; /* decided: not over (0, not NULL) */
    r.vehicle_id = 3;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* refused, naming the field */
    r.overload = 2;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.overload"));
    r.overload = 0;
    r.vclass = "A-class-name-too-long";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.class"));
    r.vclass = "";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.class"));
    r.vclass = "A23";
    r.axle_groups = "1-1\n3";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.axle_groups"));
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    assert_int_equal(1, raw_int(db, "SELECT count(*) FROM passages WHERE vehicle_id = 1 AND "
                                    "class IS NULL AND axle_groups IS NULL AND overload IS NULL"));
    assert_string_equal("A23 1-1-3 1",
                        raw_text(db, "SELECT class || ' ' || axle_groups || ' ' || overload "
                                     "FROM passages WHERE vehicle_id = 2", buf, sizeof buf));
    assert_int_equal(0, raw_int(db, "SELECT overload FROM passages WHERE vehicle_id = 3"));
    /* the schema refuses what the checks refuse */
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET overload = 2 WHERE vehicle_id = 2"));
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET class = '' WHERE vehicle_id = 2"));
    /* make it a version-9 file, as amfid before the classes left it */
    raw_downgrade(db, 9);
    raw_close(db);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM passages WHERE class IS NULL AND "
                                    "axle_groups IS NULL AND overload IS NULL"));
    raw_close(db);
    ok_row(&r, 4, 2 * DAY_US, 18000.0);
    r.vclass = "R2";
    r.axle_groups = "1-1";
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
}

/* ---- version 13: why the loads were refused; a version-12 file migrates ------- */

/* The reasons read back, by vehicle id ("-" where NULL). */
typedef struct refused_seen {
    char why[4][AMFI_STORE_LOADS_REFUSED_MAX + 1];
    int n;
} refused_seen;

static int each_refused(void *ctx, int64_t id, const amfi_passage_row *r)
{
    (void)id;
    refused_seen *c = ctx;
    if (r->vehicle_id >= 1 && r->vehicle_id <= 4)
        snprintf(c->why[r->vehicle_id - 1], sizeof c->why[0], "%s",
                 r->loads_refused ? r->loads_refused : "-");
    c->n++;
    return 0;
}

static void test_loads_refused_and_migration_from_v12(void **state)
{
    fixture *f = *state;
    char err[ERRLEN], buf[AMFI_STORE_LOADS_REFUSED_MAX + 2];
    const char *why = "group 3: load 276000 kg, over 10 x any legal load of 3 axles (24000 kg)";
    amfi_passage_row r;
    refused_seen c;
    raw_db *db;

    ok_row(&r, 1, DAY_US, 18000.0); /* memset: judged (NULL) */
    r.vclass = "R2";
    r.axle_groups = "1-1";
    r.has_overload = 1;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 2, DAY_US + 1000, 300000.0);
    r.vclass = "R2";
    r.axle_groups = "1-1";
    r.loads_refused = why; /* refused: overload NULL */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* refused when written, naming the field: empty, too long, a control character */
    r.vehicle_id = 3;
    r.loads_refused = "";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.loads_refused"));
    memset(buf, 'x', sizeof buf - 1);
    buf[sizeof buf - 1] = '\0'; /* 112 bytes */
    r.loads_refused = buf;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.loads_refused"));
    r.loads_refused = "axle 2: load -683 kg\n< 0";
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.loads_refused"));
    buf[sizeof buf - 2] = '\0'; /* 111 bytes: the limit */
    r.loads_refused = buf;
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* read back by the reports' listing */
    memset(&c, 0, sizeof c);
    assert_int_equal(0, amfi_store_each_passage(f->s, 0, AMFI_STORE_MAX_UTIME, "ok", each_refused,
                                                &c, err, sizeof err));
    assert_int_equal(3, c.n);
    assert_string_equal("-", c.why[0]);
    assert_string_equal(why, c.why[1]);
    assert_string_equal(buf, c.why[2]);
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    /* the schema refuses an empty or too long reason */
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET loads_refused = '' WHERE vehicle_id = 2"));
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET loads_refused = loads_refused || 'y' "
                                        "WHERE vehicle_id = 3"));
    /* a control character the schema lets through is refused when read back */
    assert_int_equal(0, raw_try(db, "UPDATE passages SET loads_refused = 'a' || char(9) || 'b' "
                                    "WHERE vehicle_id = 3"));
    raw_close(db);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    memset(&c, 0, sizeof c);
    assert_int_equal(AMFI_STORE_ECORRUPT,
                     amfi_store_each_passage(f->s, 0, AMFI_STORE_MAX_UTIME, "ok", each_refused, &c,
                                             err, sizeof err));
    assert_non_null(strstr(err, "loads_refused"));
    assert_non_null(strstr(err, "control character"));
    amfi_store_close(f->s);
    f->s = NULL;

    /* make it a version-12 file, as amfid before the reason left it: migrated,
     * every row NULL (the reports recompute the refusal), then written */
    db = raw_open(f->path);
    raw_downgrade(db, 12);
    assert_int_not_equal(0, raw_try(db, "SELECT loads_refused FROM passages"));
    raw_close(db);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM passages WHERE loads_refused IS NULL"));
    raw_close(db);
    ok_row(&r, 4, 2 * DAY_US, 18000.0);
    r.loads_refused = "axle 2: load -683 kg < 0 (a single axle)";
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    memset(&c, 0, sizeof c);
    assert_int_equal(0, amfi_store_each_passage(f->s, 0, AMFI_STORE_MAX_UTIME, "ok", each_refused,
                                                &c, err, sizeof err));
    assert_int_equal(4, c.n);
    assert_string_equal("-", c.why[1]);
    assert_string_equal("axle 2: load -683 kg < 0 (a single axle)", c.why[3]);
}

/* ---- version 8: the weight the STD and mean rules were fed; a version-7 file --- */

static void test_gvw_comp_and_migration_from_v7(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_passage_row r;
    double g[8];
    int n = -1;
    raw_db *db;

    ok_row(&r, 1, DAY_US, 10000.0); /* memset: gvw_comp_kg 0, did not feed (NULL) */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 2, DAY_US + 1000, 11000.0);
    r.gvw_comp_kg = 10890.0; /* compensated */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    ok_row(&r, 3, DAY_US + 2000, 12000.0);
    r.gvw_comp_kg = NAN; /* NaN: NULL as well */
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    /* refused, naming the field */
    r.gvw_comp_kg = -5.0;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.gvw_comp_kg"));
    r.gvw_comp_kg = 2e6;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.gvw_comp_kg"));
    r.gvw_comp_kg = INFINITY;
    assert_int_equal(AMFI_EINVAL, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    assert_non_null(strstr(err, "passages.gvw_comp_kg"));
    /* the rolling window's refill: the weight fed where stored, else the GVW */
    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 8, g, &n, err, sizeof err));
    assert_int_equal(3, n);
    assert_float_equal(10000.0, g[0], 0);
    assert_float_equal(10890.0, g[1], 0);
    assert_float_equal(12000.0, g[2], 0);
    amfi_store_close(f->s);
    f->s = NULL;

    db = raw_open(f->path);
    assert_int_equal(2, raw_int(db, "SELECT count(*) FROM passages WHERE gvw_comp_kg IS NULL"));
    /* the schema refuses what the checks refuse */
    assert_int_not_equal(0, raw_try(db, "UPDATE passages SET gvw_comp_kg = 0 WHERE vehicle_id = 2"));
    /* make it a version-7 file, as amfid before compensated rules left it */
    raw_downgrade(db, 7);
    raw_close(db);
    assert_int_equal(0, amfi_store_open(f->path, 0, &f->s, err, sizeof err));
    db = raw_open(f->path);
    assert_int_equal(AMFI_STORE_SCHEMA_VERSION, raw_int(db, "PRAGMA user_version"));
    assert_int_equal(3, raw_int(db, "SELECT count(*) FROM passages WHERE gvw_comp_kg IS NULL"));
    raw_close(db);
    /* rows of before: their GVW is what the rules were fed */
    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 8, g, &n, err, sizeof err));
    assert_int_equal(3, n);
    assert_float_equal(11000.0, g[1], 0);
}

/* ---- what amfid and amfi-report read back ------------------------------------ */

static void test_alert_open_and_report_queries(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    int open = -1, n = 0;
    int64_t ind = 0, count = -1, other = -1;
    amfi_indicator_rec irec[4];
    amfi_alert_rec arec[4], *open_alerts = NULL;
    amfi_passage_summary sum;
    double *g = NULL;
    size_t ng = 0;
    raw_db *db;

    assert_int_equal(0, amfi_store_alert_open(f->s, "std_increase", &open, err, sizeof err));
    assert_int_equal(0, open);
    assert_int_equal(AMFI_EINVAL, amfi_store_alert_open(f->s, "Bad Kind", &open, err, sizeof err));
    assert_int_equal(0, amfi_store_passage_summary(f->s, &sum, err, sizeof err));
    assert_int_equal(0, sum.total);
    assert_int_equal(0, sum.utime_last);

    amfi_indicator_row r = {DAY_US + 5, 20, 18000, 2000, 18000, 1900, 1.05, 0.3, "normal"};
    assert_int_equal(0, amfi_store_add_indicator(f->s, &r, &ind, err, sizeof err));
    r = (amfi_indicator_row){DAY_US + 9, 20, NAN, NAN, NAN, NAN, NAN, NAN, "baseline"};
    assert_int_equal(0, amfi_store_add_indicator(f->s, &r, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 5, "warning", "std_increase",
                                             "raised once", ind, 1, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 6, "info", "mean_shift", "up",
                                             0, 1, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_alert_open(f->s, "std_increase", &open, err, sizeof err));
    assert_int_equal(1, open);
    assert_int_equal(0, amfi_store_add_alert(f->s, DAY_US + 7, "info", "mean_shift", "back",
                                             0, 0, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_alert_open(f->s, "mean_shift", &open, err, sizeof err));
    assert_int_equal(0, open);

    add_ok(f->s, 1, DAY_US, 18000.0, NULL);
    add_ok(f->s, 2, DAY_US + 3, 20000.0, NULL);
    amfi_passage_row gap;
    ok_row(&gap, 3, DAY_US + 4, NAN);
    gap.status = "gap";
    gap.reason = "samples missing";
    gap.axle_kg[0] = gap.axle_kg[1] = NAN;
    assert_int_equal(0, amfi_store_add_passage(f->s, &gap, NULL, err, sizeof err));
    assert_int_equal(0, amfi_store_add_truth(f->s, 1, DAY_US, 17640.0, 2,
                                             (double[]){7056, 10584}, NULL, 25.0, err,
                                             sizeof err));
    assert_int_equal(0, amfi_store_add_truth(f->s, 3, DAY_US + 4, 10000.0, 2,
                                             (double[]){4000, 6000}, NULL, 25.0, err,
                                             sizeof err));

    assert_int_equal(0, amfi_store_count(f->s, AMFI_STORE_ALERTS, &count, err, sizeof err));
    assert_int_equal(3, count);
    assert_int_equal(0, amfi_store_count(f->s, AMFI_STORE_TRUTH, &count, err, sizeof err));
    assert_int_equal(2, count);
    assert_int_equal(0, amfi_store_passage_summary(f->s, &sum, err, sizeof err));
    assert_int_equal(3, sum.total);
    assert_int_equal(DAY_US, sum.utime_first);
    assert_int_equal(DAY_US + 4, sum.utime_last);
    assert_int_equal(2, sum.by_status[0]);
    assert_string_equal("gap", amfi_store_status_name(1));
    assert_int_equal(1, sum.by_status[1]);
    assert_null(amfi_store_status_name(AMFI_STORE_N_STATUS));
    assert_int_equal(0, amfi_store_all_ok_gvw(f->s, &g, &ng, err, sizeof err));
    assert_int_equal(2, ng);
    assert_true(g[0] == 18000.0 && g[1] == 20000.0);
    free(g);

    assert_int_equal(0, amfi_store_recent_indicators(f->s, 4, irec, &n, err, sizeof err));
    assert_int_equal(2, n);
    assert_string_equal("baseline", irec[0].row.state); /* newest first */
    assert_true(isnan(irec[0].row.std_kg));
    assert_int_equal(ind, irec[1].id);
    assert_true(irec[1].row.std_ratio == 1.05);
    assert_int_equal(0, amfi_store_recent_alerts(f->s, 2, arec, &n, err, sizeof err));
    assert_int_equal(2, n);
    assert_string_equal("back", arec[0].message);
    assert_int_equal(0, arec[0].indicator_id);
    /* a message with a control character, written by another program */
    db = raw_open(f->path);
    raw_exec(db, "UPDATE alerts SET message = 'raised' || char(9) || 'once' WHERE id = 1");
    raw_close(db);
    assert_int_equal(0, amfi_store_open_alerts(f->s, &open_alerts, &n, err, sizeof err));
    assert_int_equal(1, n);
    assert_string_equal("std_increase", open_alerts[0].kind);
    assert_string_equal("warning", open_alerts[0].level);
    assert_string_equal("raised?once", open_alerts[0].message); /* one line */
    assert_int_equal(ind, open_alerts[0].indicator_id);
    free(open_alerts);
    assert_int_equal(0, amfi_store_gvw_errors(f->s, &g, &ng, &other, err, sizeof err));
    assert_int_equal(1, ng);
    assert_int_equal(1, other);
    assert_true(fabs(g[0] - 100.0 * (18000.0 - 17640.0) / 17640.0) < 1e-9);
    free(g);

    /* damaged rows behind the store's back: named by table, row and column */
    db = raw_open(f->path);
    raw_exec(db, "PRAGMA ignore_check_constraints = ON; "
                 "UPDATE passages SET gvw_kg = -1 WHERE vehicle_id = 2; "
                 "UPDATE alerts SET raised = 7 WHERE kind = 'std_increase'");
    raw_close(db);
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_all_ok_gvw(f->s, &g, &ng, err, sizeof err));
    assert_non_null(strstr(err, "passages row 2: gvw_kg is out of range for an ok passage"));
    assert_int_equal(AMFI_STORE_ECORRUPT,
                     amfi_store_alert_open(f->s, "std_increase", &open, err, sizeof err));
    assert_non_null(strstr(err, "alerts row 1: raised"));
}

/* ---- the DDL in docs/schema.md -------------------------------------------- */

/* The SQL between "<!-- ddl:begin -->" and "<!-- ddl:end -->" lines of the
 * document, fence lines dropped; malloc'd. */
static char *doc_ddl(void)
{
    FILE *fp = fopen(AMFI_SCHEMA_DOC, "r");
    char line[1024];
    size_t cap = 1 << 16, len = 0;
    char *out = malloc(cap);
    int in = 0, blocks = 0;
    assert_non_null(fp);
    assert_non_null(out);
    out[0] = '\0';
    while (fgets(line, sizeof line, fp)) {
        if (strncmp(line, "<!-- ddl:begin -->", 18) == 0) {
            in = 1;
            blocks++;
            continue;
        }
        if (strncmp(line, "<!-- ddl:end -->", 16) == 0) {
            in = 0;
            continue;
        }
        if (!in || strncmp(line, "```", 3) == 0)
            continue;
        size_t n = strlen(line);
        assert_true(len + n + 1 < cap);
        memcpy(out + len, line, n + 1);
        len += n;
    }
    fclose(fp);
    assert_true(blocks >= 1);
    return out;
}

/* Whitespace runs collapsed to one space, ends trimmed, in place. */
static void squeeze(char *s)
{
    char *w = s;
    int space = 1;
    for (char *p = s; *p; p++) {
        if (*p == ' ' || *p == '\n' || *p == '\t' || *p == '\r') {
            if (!space)
                *w++ = ' ';
            space = 1;
        } else {
            *w++ = *p;
            space = 0;
        }
    }
    if (w > s && w[-1] == ' ')
        w--;
    *w = '\0';
}

/* "type name tbl_name sql" of every schema object, sorted, one per line. */
struct dump {
    char *out;
    size_t len, cap;
};
static int dump_row(void *ctx, int n, const char *const *t)
{
    struct dump *d = ctx;
    char item[16384];
    assert_int_equal(4, n);
    snprintf(item, sizeof item, "%s %s %s %s", t[0] ? t[0] : "", t[1] ? t[1] : "",
             t[2] ? t[2] : "", t[3] ? t[3] : "");
    squeeze(item);
    size_t k = strlen(item);
    assert_true(d->len + k + 2 < d->cap);
    memcpy(d->out + d->len, item, k);
    d->len += k;
    d->out[d->len++] = '\n';
    d->out[d->len] = '\0';
    return 0;
}

/* "type name tbl_name sql" of every schema object, sorted, one per line. */
static char *schema_dump(raw_db *db)
{
    char err[512];
    struct dump d = {malloc(1 << 17), 0, 1 << 17};
    assert_non_null(d.out);
    d.out[0] = '\0';
    if (amfi_store_test_rows(db,
                             "SELECT type, name, tbl_name, coalesce(sql, '') FROM sqlite_schema "
                             "ORDER BY type, name",
                             dump_row, &d, err, sizeof err) != 0)
        fail_msg("%s", err);
    return d.out;
}

static void test_schema_doc_matches(void **state)
{
    fixture *f = *state;
    char path[128], *ddl = doc_ddl(), msg[1024];
    raw_db *db = raw_open(f->path);

    snprintf(path, sizeof path, "%s/doc.db", f->dir);
    raw_db *doc = raw_create(path);
    if (amfi_store_test_exec(doc, ddl, msg, sizeof msg) != 0)
        fail_msg("docs/schema.md DDL: %.300s", msg);
    char *a = schema_dump(db), *b = schema_dump(doc);
    if (strcmp(a, b) != 0) {
        /* show the first differing line */
        const char *p = a, *q = b;
        while (*p && *p == *q) {
            p++;
            q++;
        }
        while (p > a && p[-1] != '\n') {
            p--;
            q--;
        }
        fail_msg("docs/schema.md differs from the store's schema:\n store: %.300s\n doc:   %.300s", p, q);
    }
    assert_int_equal(AMFI_STORE_APPLICATION_ID, raw_int(doc, "PRAGMA application_id"));
    free(a);
    free(b);
    free(ddl);
    raw_close(doc);
    raw_close(db);
}

/* ---- volume: 10 000 passages and the daily_trend view ---------------------- */

static void test_many_passages(void **state)
{
    fixture *f = *state;
    enum { N = 10000, DAYS = 4 };
    char err[ERRLEN];
    amfi_passage_row r;
    static double gvw[N];
    double sum[DAYS] = {0}, mean[DAYS], ss[DAYS] = {0};
    int cnt[DAYS] = {0}, bad[DAYS] = {0};
    raw_db *db;
    uint64_t x = 88172645463325252ULL; /* xorshift64 */

    double t0 = now_s();
    for (int k = 0; k < N; k++) {
        int64_t utime = DAY_US * 20000 + (int64_t)k * (DAYS * DAY_US / N);
        int day = (int)((int64_t)k * DAYS / N);
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        gvw[k] = 3000.0 + (double)(x % 4000000) / 100.0; /* 3 .. 43 t */
        ok_row(&r, k, utime, gvw[k]);
        if (k % 50 == 7) {
            r.status = "gap";
            r.gvw_kg = NAN;
            bad[day]++;
        } else {
            sum[day] += gvw[k];
            cnt[day]++;
        }
        if (amfi_store_add_passage(f->s, &r, NULL, err, sizeof err) != 0)
            fail_msg("passage %d: %s", k, err);
    }
    double dt = now_s() - t0;
    printf("store: %d passages (2 axles each, one transaction each, synchronous "
           "NORMAL) in %.2f s: %.0f passages/s\n", N, dt, N / dt);
    assert_true(dt < 120.0); /* sanitizers on a busy box; amfid needs ~10/s */

    /* synchronous FULL: an fsync per commit */
    amfi_store_close(f->s); /* checkpointed: the main file holds everything */
    struct stat sb;
    assert_int_equal(0, stat(f->path, &sb));
    printf("store: file of %d passages: %.2f MB, %.0f bytes a passage\n", N,
           (double)sb.st_size / 1e6, (double)sb.st_size / N);
    assert_int_equal(0, amfi_store_open(f->path, 1, &f->s, err, sizeof err));
    t0 = now_s();
    for (int k = 0; k < 200; k++) {
        ok_row(&r, N + k, DAY_US * 30000 + k, 18000.0);
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, NULL, err, sizeof err));
    }
    dt = now_s() - t0;
    printf("store: 200 passages with synchronous FULL in %.2f s: %.0f passages/s\n",
           dt, 200 / dt);

    double g[1000];
    int n = 0;
    t0 = now_s();
    assert_int_equal(0, amfi_store_recent_ok_gvw(f->s, 1000, g, &n, err, sizeof err));
    printf("store: recent_ok_gvw(1000) in %.1f ms\n", 1e3 * (now_s() - t0));
    assert_int_equal(1000, n);

    /* daily_trend against a naive two-pass computation */
    for (int d = 0; d < DAYS; d++)
        mean[d] = sum[d] / cnt[d];
    for (int k = 0; k < N; k++) {
        int day = (int)((int64_t)k * DAYS / N);
        if (k % 50 != 7)
            ss[day] += (gvw[k] - mean[day]) * (gvw[k] - mean[day]);
    }
    db = raw_open(f->path);
    for (int d = 0; d < DAYS; d++) {
        char sql[200];
        int64_t utime = DAY_US * (20000 + d);
        snprintf(sql, sizeof sql, "SELECT %%s FROM daily_trend WHERE day = date(%lld, 'unixepoch')",
                 (long long)(utime / 1000000));
        char q[256];
        snprintf(q, sizeof q, sql, "n_ok");
        assert_int_equal(cnt[d], raw_int(db, q));
        snprintf(q, sizeof q, sql, "n_not_ok");
        assert_int_equal(bad[d], raw_int(db, q));
        snprintf(q, sizeof q, sql, "mean_kg");
        assert_true(fabs(raw_real(db, q) - mean[d]) < 1e-9 * mean[d]);
        snprintf(q, sizeof q, sql, "std_kg");
        double sd = sqrt(ss[d] / (cnt[d] - 1));
        assert_true(fabs(raw_real(db, q) - sd) < 1e-9 * sd);
    }
    raw_close(db);
}

/* amfi_store_each_passage_where: 60 passages on lanes 1..3, one a minute,
 * every fourth a gap: each filter's rows equal a raw sqlite3 count of the
 * same WHERE, arrive oldest first, carry their axles, and a callback's
 * nonzero return stops the listing and is returned. */
typedef struct each_ctx {
    int n, bad_order, bad_filter, stop_at;
    int64_t last_utime;
    const amfi_passage_filter *f;
} each_ctx;

static int each_count(void *vctx, int64_t id, const amfi_passage_row *r)
{
    each_ctx *c = vctx;
    (void)id;
    c->n++;
    if (r->utime < c->last_utime)
        c->bad_order++;
    c->last_utime = r->utime;
    if (r->utime < c->f->from || r->utime > c->f->to
        || (c->f->status && strcmp(r->status, c->f->status) != 0)
        || (c->f->lane_given && r->lane != c->f->lane)
        || r->n_axles != 2 || !(fabs(r->axle_kg[0] + r->axle_kg[1] - r->gvw_kg) < 1e-6))
        c->bad_filter++;
    return c->stop_at && c->n == c->stop_at ? 7 : 0;
}

static void test_each_passage_filtered(void **state)
{
    fixture *f = *state;
    amfi_passage_row r;
    char err[ERRLEN], sql[256];
    int64_t id = 0;
    const int64_t t0 = 5 * DAY_US, min = INT64_C(60000000);
    for (int k = 0; k < 60; k++) {
        ok_row(&r, k + 1, t0 + k * min, 20000.0 + 100.0 * k);
        r.lane = 1 + k % 3;
        if (k % 4 == 3) {
            r.status = "gap";
            r.reason = "test";
        }
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id, err, sizeof err));
    }
    raw_db *db = raw_open(f->path);
    const struct {
        int64_t from, to;
        const char *status;
        int lane_given, lane;
    } cases[] = {
        {0, AMFI_STORE_MAX_UTIME, NULL, 0, 0},
        {0, AMFI_STORE_MAX_UTIME, "ok", 0, 0},
        {0, AMFI_STORE_MAX_UTIME, NULL, 1, 2},
        {t0 + 10 * min, t0 + 40 * min, "gap", 1, 1},
        {t0 + 10 * min, t0 + 40 * min, "ok", 1, 3},
        {t0 + 59 * min, t0 + 59 * min, NULL, 0, 0},
        {0, t0 - 1, NULL, 0, 0},
        {0, AMFI_STORE_MAX_UTIME, NULL, 1, 9},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        amfi_passage_filter flt = {.from = cases[k].from, .to = cases[k].to,
                                   .status = cases[k].status,
                                   .lane_given = cases[k].lane_given,
                                   .lane = cases[k].lane};
        each_ctx c = {.f = &flt};
        assert_int_equal(0, amfi_store_each_passage_where(f->s, &flt, each_count, &c,
                                                          err, sizeof err));
        char lane[32] = "", st[32] = "";
        if (flt.lane_given)
            snprintf(lane, sizeof lane, " AND lane = %d", flt.lane);
        if (flt.status)
            snprintf(st, sizeof st, " AND status = '%s'", flt.status);
        snprintf(sql, sizeof sql,
                 "SELECT count(*) FROM passages WHERE utime BETWEEN %lld AND %lld%s%s",
                 (long long)flt.from, (long long)flt.to, st, lane);
        assert_int_equal(raw_int(db, sql), c.n);
        assert_int_equal(0, c.bad_order);
        assert_int_equal(0, c.bad_filter);
    }
    /* the four cases with rows are not all the table: the filter filters */
    assert_int_equal(60, raw_int(db, "SELECT count(*) FROM passages"));
    assert_int_equal(20, raw_int(db, "SELECT count(*) FROM passages WHERE lane = 2"));
    raw_close(db);
    /* a stop, a bad status, a bad lane, no filter */
    amfi_passage_filter all = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
    each_ctx c = {.f = &all, .stop_at = 5};
    assert_int_equal(7, amfi_store_each_passage_where(f->s, &all, each_count, &c, err,
                                                      sizeof err));
    assert_int_equal(5, c.n);
    amfi_passage_filter bad = {.from = 0, .to = 1, .status = "fine"};
    assert_int_not_equal(0, amfi_store_each_passage_where(f->s, &bad, each_count, &c, err,
                                                          sizeof err));
    assert_non_null(strstr(err, "status"));
    amfi_passage_filter badlane = {.from = 0, .to = 1, .lane_given = 1, .lane = 40000};
    assert_int_not_equal(0, amfi_store_each_passage_where(f->s, &badlane, each_count, &c,
                                                          err, sizeof err));
    assert_non_null(strstr(err, "lane 40000"));
    assert_int_not_equal(0, amfi_store_each_passage_where(f->s, NULL, each_count, &c, err,
                                                          sizeof err));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_create_and_reopen, setup, teardown),
        cmocka_unit_test_setup_teardown(test_refuse_newer_version, setup, teardown),
        cmocka_unit_test_setup_teardown(test_refuse_foreign_files, setup, teardown),
        cmocka_unit_test_setup_teardown(test_passage_with_axles, setup, teardown),
        cmocka_unit_test_setup_teardown(test_unsolved_is_null, setup, teardown),
        cmocka_unit_test_setup_teardown(test_invalid_rows_store_nothing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_reader_does_not_block, setup, teardown),
        cmocka_unit_test_setup_teardown(test_truth_and_errors_view, setup, teardown),
        cmocka_unit_test_setup_teardown(test_indicators_alerts, setup, teardown),
        cmocka_unit_test_setup_teardown(test_baseline, setup, teardown),
        cmocka_unit_test_setup_teardown(test_recent_ok_gvw, setup, teardown),
        cmocka_unit_test_setup_teardown(test_recent_fed_gvw, setup, teardown),
        cmocka_unit_test_setup_teardown(test_meta, setup, teardown),
        cmocka_unit_test_setup_teardown(test_integrity_check, setup, teardown),
        cmocka_unit_test_setup_teardown(test_corrupt_rows_reported, setup, teardown),
        cmocka_unit_test_setup_teardown(test_readonly, setup, teardown),
        cmocka_unit_test_setup_teardown(test_runs_and_migration_from_v1, setup, teardown),
        cmocka_unit_test_setup_teardown(test_event_columns_and_migration_from_v3, setup, teardown),
        cmocka_unit_test_setup_teardown(test_environment_and_migration_from_v4, setup, teardown),
        cmocka_unit_test_setup_teardown(test_scale_rows_and_migration_from_v5, setup, teardown),
        cmocka_unit_test_setup_teardown(test_speed_given_and_migration_from_v2, setup, teardown),
        cmocka_unit_test_setup_teardown(test_f1_and_migration_from_v6, setup, teardown),
        cmocka_unit_test_setup_teardown(test_gvw_comp_and_migration_from_v7, setup, teardown),
        cmocka_unit_test_setup_teardown(test_class_and_migration_from_v9, setup, teardown),
        cmocka_unit_test_setup_teardown(test_loads_refused_and_migration_from_v12, setup, teardown),
        cmocka_unit_test_setup_teardown(test_alert_open_and_report_queries, setup, teardown),
        cmocka_unit_test_setup_teardown(test_schema_doc_matches, setup, teardown),
        cmocka_unit_test_setup_teardown(test_many_passages, setup, teardown),
        cmocka_unit_test_setup_teardown(test_each_passage_filtered, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
