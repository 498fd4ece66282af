/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_scaleind.c: amfid's scale indicator and known-truck runs
 * (daemon/scaleind.c) on a real store and LCM's in-memory bus: the deck
 * temperature taken for each solved passage (and a passage without one
 * skipped, counted), the evaluations stored, and above all the restore: an
 * amfid restarted in the middle of a block (after the baseline) continues
 * exactly as one that never stopped: the same scale_evals rows and the same
 * alerts, raised once; a restart while the alerts are open does not raise
 * them again. Single-threaded (the main thread's functions, called here).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <sqlite3.h>

#include "amfid.h"

#define T0 INT64_C(1767225600000000) /* 2026-01-01, µs */
#define MIN_US INT64_C(60000000)
#define PI 3.14159265358979323846

typedef struct fixture {
    char dir[64];
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    snprintf(f->dir, sizeof f->dir, "/tmp/test_scaleind.XXXXXX");
    assert_non_null(mkdtemp(f->dir));
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    assert_int_equal(0, system(cmd));
    free(f);
    return 0;
}

/* The deck temperature of the test's environment at minute k: a daily-like
 * swing across the frost knee, -6 .. 14 °C. */
static double deck_at(int64_t minute)
{
    return 4.0 + 10.0 * sin(2.0 * PI * (double)minute / 240.0);
}

static void open_daemon(daemon_s *d, const char *dir, const char *name, int with_env)
{
    char path[128], err[512];
    memset(d, 0, sizeof *d);
    amfi_config_defaults(&d->cfg);
    amfi_daemon_config *dc = &d->cfg.daemon;
    dc->scale.block = 50;
    dc->scale.baseline_blocks = 4;
    dc->scale.design_shift = 0.1;
    dc->scale.false_alarms_per_year = 10;
    dc->scale.vehicles_per_day = 500;
    dc->known_truck.baseline_runs = 3;
    d->lcm = lcm_create("memq://");
    assert_non_null(d->lcm);
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    assert_int_equal(0, amfi_store_open(path, 0, &d->store, err, sizeof err));
    if (with_env) { /* a reading every 5 minutes over the whole test */
        static amfi_environment_row rows[800];
        for (int k = 0; k < 800; k++)
            rows[k] = (amfi_environment_row){T0 + 5 * k * MIN_US, deck_at(5 * k),
                                             deck_at(5 * k) - 2.0, T0};
        assert_int_equal(0, amfi_store_add_environment(d->store, rows, 800, err, sizeof err));
    }
    assert_int_equal(0, scaleind_create(d, err, sizeof err));
    scaleind_restore(d);
}

static void close_daemon(daemon_s *d)
{
    scaleind_destroy(d);
    amfi_store_close(d->store);
    lcm_destroy(d->lcm);
}

/* A reproducible normal draw for vehicle k (xorshift, Box-Muller). */
static double gauss(uint64_t k)
{
    uint64_t x = k * 0x9E3779B97F4A7C15u + 1;
    double u[2];
    for (int i = 0; i < 2; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        u[i] = ((double)(x >> 11) + 0.5) / 9007199254740992.0;
    }
    return sqrt(-2.0 * log(u[0])) * cos(2.0 * PI * u[1]);
}

/* Passage k (one a minute) as amfid would store and feed it: half empty,
 * half loaded, stretched by the temperature (the indicator's prior law) and
 * by 1 / 0.9 when damaged; every 10th the calibration truck (14 t). */
static void pass(daemon_s *d, int k, int damaged)
{
    char err[512];
    amfi_passage_row r;
    memset(&r, 0, sizeof r);
    r.vehicle_id = k + 1;
    r.utime = T0 + k * MIN_US;
    r.lane = 1;
    r.speed_mps = r.speed_given_mps = 20.0;
    r.n_axles = 2;
    r.spacing_m[0] = 4.0;
    double true_kg = (k % 10 == 9)   ? 14000.0
                     : (k % 2 == 0) ? 6500.0 + 900.0 * gauss((uint64_t)k)
                                    : 11000.0 + 1300.0 * gauss((uint64_t)k);
    double t = deck_at(k);
    double temp = 1.0 / amfi_scale_temp_factor(&d->cfg.daemon.scale, 0.0025, 0.018, t);
    r.gvw_kg = true_kg * temp * (damaged ? 1.0 / 0.9 : 1.0) * (1.0 + 0.01 * gauss(k + 7919u));
    r.axle_kg[0] = 0.4 * r.gvw_kg;
    r.axle_kg[1] = 0.6 * r.gvw_kg;
    r.status = "ok";
    r.reason = "";
    r.lambda = 1e-8;
    r.residual_rms = 1e-3;
    r.formulation = "paper";
    r.solve_ms = 5;
    r.n_vehicles = 1;
    r.reference_gvw_kg = k % 10 == 9 ? 14000.0 : 0.0;
    scaleind_deck(d, &r);
    assert_int_equal(0, amfi_store_add_passage(d->store, &r, NULL, err, sizeof err));
    scaleind_feed(d, &r);
}

/* scale_evals and alerts after utime `from`, as text, malloc'd. */
static char *dump(const char *dir, const char *name, int64_t from)
{
    char path[128], sql[512];
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    assert_int_equal(SQLITE_OK, sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL));
    snprintf(sql, sizeof sql,
             "SELECT printf('%%s %%d %%d %%.12g %%.12g %%.12g %%.12g %%.12g %%s', kind, utime, n, "
             "value, raw, deck_c, z, cusum, state) FROM scale_evals WHERE utime > %lld UNION ALL "
             "SELECT printf('alert %%s %%d %%d %%s', kind, utime, raised, message) FROM alerts "
             "WHERE utime > %lld",
             (long long)from, (long long)from);
    assert_int_equal(SQLITE_OK, sqlite3_prepare_v2(db, sql, -1, &st, NULL));
    size_t cap = 1 << 16, len = 0;
    char *out = calloc(1, cap);
    while (sqlite3_step(st) == SQLITE_ROW) {
        const char *line = (const char *)sqlite3_column_text(st, 0);
        size_t n = strlen(line);
        if (len + n + 2 > cap) {
            cap *= 2;
            out = realloc(out, cap);
        }
        memcpy(out + len, line, n);
        len += n;
        out[len++] = '\n';
        out[len] = 0;
    }
    sqlite3_finalize(st);
    sqlite3_close(db);
    return out;
}

static int count(const char *dir, const char *name, const char *sql)
{
    char path[128];
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    assert_int_equal(SQLITE_OK, sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL));
    assert_int_equal(SQLITE_OK, sqlite3_prepare_v2(db, sql, -1, &st, NULL));
    assert_int_equal(SQLITE_ROW, sqlite3_step(st));
    int n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    return n;
}

static void test_restart_continues_exactly(void **state)
{
    fixture *f = *state;
    daemon_s a, c;
    const int split = 333, onset = 420, end = 700;
    open_daemon(&c, f->dir, "continuous", 1);
    open_daemon(&a, f->dir, "restarted", 1);
    for (int k = 0; k < split; k++) {
        pass(&c, k, 0);
        pass(&a, k, 0);
    }
    /* the baseline is in, a block is under way, the truck's baseline done */
    assert_string_not_equal("baseline", amfi_scale_state(a.sc.scale));
    assert_int_equal(split, a.sc.fed);
    assert_int_equal(0, a.sc.no_temp);
    close_daemon(&a);
    open_daemon(&a, f->dir, "restarted", 0);
    assert_int_equal(0, a.sc.fed); /* the counters are this run's */
    for (int k = split; k < end; k++) {
        pass(&c, k, k >= onset);
        pass(&a, k, k >= onset);
    }
    char *x = dump(f->dir, "continuous", T0 + (split - 1) * MIN_US);
    char *y = dump(f->dir, "restarted", T0 + (split - 1) * MIN_US);
    assert_string_equal(x, y);
    /* and the test means something: blocks after the restart, both alerts
     * raised once, after the onset */
    assert_non_null(strstr(x, "scale_shift "));
    assert_non_null(strstr(x, "known_truck "));
    assert_int_equal(1, count(f->dir, "restarted",
                              "SELECT count(*) FROM alerts WHERE kind = 'scale_shift' AND "
                              "raised = 1"));
    assert_int_equal(1, count(f->dir, "restarted",
                              "SELECT count(*) FROM alerts WHERE kind = 'known_truck' AND "
                              "raised = 1"));
    char sql[256];
    snprintf(sql, sizeof sql,
             "SELECT count(*) FROM alerts WHERE raised = 1 AND utime < %lld",
             (long long)(T0 + onset * MIN_US));
    assert_int_equal(0, count(f->dir, "restarted", sql));
    assert_int_equal(1, count(f->dir, "restarted",
                              "SELECT count(*) FROM scale_evals WHERE state = 'baseline' AND "
                              "kind = 'scale_shift'"));
    free(x);
    free(y);

    /* a restart with both alerts open: restored, not raised again */
    close_daemon(&a);
    open_daemon(&a, f->dir, "restarted", 0);
    assert_string_equal("alert", amfi_scale_state(a.sc.scale));
    assert_string_equal("alert", amfi_known_truck_state(a.sc.truck));
    for (int k = end; k < end + 100; k++)
        pass(&a, k, 1);
    assert_int_equal(2, count(f->dir, "restarted",
                              "SELECT count(*) FROM alerts WHERE raised = 1"));
    close_daemon(&a);
    close_daemon(&c);
}

static void test_no_temperature_is_skipped(void **state)
{
    fixture *f = *state;
    daemon_s d;
    char err[512];
    open_daemon(&d, f->dir, "notemp", 1);
    amfi_passage_row r;
    memset(&r, 0, sizeof r);
    r.utime = T0 + 800 * 5 * MIN_US + 3 * 3600 * INT64_C(1000000); /* 3 h after the last */
    r.gvw_kg = 9000;
    r.n_vehicles = 1;
    r.has_deck_c = 1;
    r.deck_c = 99.0;
    scaleind_deck(&d, &r);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(1, d.sc.no_temp);
    scaleind_feed(&d, &r);
    assert_int_equal(0, d.sc.fed);
    /* within half the gap of the last reading: its temperature */
    r.utime = T0 + 799 * 5 * MIN_US + 30 * MIN_US;
    scaleind_deck(&d, &r);
    assert_int_equal(1, r.has_deck_c);
    assert_float_equal(deck_at(799 * 5), r.deck_c, 1e-9);
    /* buffered readings are flushed before the lookup */
    d.env.buf[0] = (amfi_environment_row){r.utime + 10 * MIN_US, 21.5, 20.0, T0};
    d.env.n = 1;
    r.utime += 10 * MIN_US;
    scaleind_deck(&d, &r);
    assert_int_equal(0, d.env.n);
    assert_float_equal(21.5, r.deck_c, 1e-9);
    /* the scale indicator and the known truck off: the lookup is still made
     * for the STD and mean rules' compensation (daemon.indicators.temperature) */
    close_daemon(&d);
    open_daemon(&d, f->dir, "off", 0);
    scaleind_destroy(&d);
    d.sc.no_temp = 0;
    scaleind_deck(&d, &r);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(1, d.sc.no_temp);
    /* all three off: no lookup, nothing counted */
    d.sc.compensate = 0;
    d.sc.no_temp = 0;
    scaleind_deck(&d, &r);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(0, d.sc.no_temp);
    (void)err;
    close_daemon(&d);
}

/* The weight the STD and mean rules are fed (daemon.indicators.temperature):
 * the GVW at the calibration temperature by the prior slopes before the
 * scale indicator's baseline, by its fitted slopes after; raw without a
 * deck temperature (counted) and when the setting is raw. */
static void test_std_rules_compensated(void **state)
{
    fixture *f = *state;
    daemon_s d;
    open_daemon(&d, f->dir, "comp", 1);
    const amfi_scale_params *p = &d.sc.params;
    assert_int_equal(1, d.sc.compensate); /* the default */
    amfi_passage_row r;
    memset(&r, 0, sizeof r);
    r.gvw_kg = 10000.0;
    r.has_deck_c = 1;
    /* prior slopes (0.0025 warm, 0.018 frost, knee 0, floor -10, ref 10 °C) */
    const double t[5] = {30.0, 10.0, 0.0, -5.0, -25.0};
    const double want[5] = {10000.0 * exp(-0.0025 * 20.0), 10000.0,
                            10000.0 * exp(0.0025 * 10.0),
                            10000.0 * exp(0.0025 * 10.0 + 0.018 * 5.0),
                            10000.0 * exp(0.0025 * 10.0 + 0.018 * 10.0)};
    for (int k = 0; k < 5; k++) {
        r.deck_c = t[k];
        scaleind_comp(&d, &r);
        assert_float_equal(want[k], r.gvw_comp_kg, 1e-6);
    }
    assert_true(fabs(p->warm_slope - 0.0025) < 1e-12 && fabs(p->frost_slope - 0.018) < 1e-12);
    assert_int_equal(5, d.sc.comp_fed);
    /* no deck temperature: raw, counted */
    r.has_deck_c = 0;
    scaleind_comp(&d, &r);
    assert_float_equal(10000.0, r.gvw_comp_kg, 0);
    assert_int_equal(1, d.sc.comp_raw);
    /* after the scale baseline: the fitted slopes */
    amfi_passage_row q;
    for (int64_t k = 0; !amfi_scale_has_baseline(d.sc.scale); k++) {
        memset(&q, 0, sizeof q);
        q.utime = T0 + k * MIN_US;
        q.n_vehicles = 1;
        q.gvw_kg = (k % 2 ? 12000.0 : 6000.0) + 300.0 * gauss((uint64_t)k);
        scaleind_deck(&d, &q);
        assert_int_equal(1, q.has_deck_c);
        scaleind_feed(&d, &q);
        assert_true(k < 1000);
    }
    amfi_scale_model m;
    assert_int_equal(AMFI_IND_OK, amfi_scale_get_model(d.sc.scale, &m));
    r.has_deck_c = 1;
    r.deck_c = -5.0;
    scaleind_comp(&d, &r);
    assert_float_equal(amfi_scale_temp_factor(p, m.warm_slope, m.frost_slope, -5.0) * 10000.0,
                       r.gvw_comp_kg, 1e-6);
    /* raw: the GVW, nothing counted */
    d.sc.compensate = 0;
    scaleind_comp(&d, &r);
    assert_float_equal(10000.0, r.gvw_comp_kg, 0);
    assert_int_equal(6, d.sc.comp_fed);
    assert_int_equal(1, d.sc.comp_raw);
    close_daemon(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_restart_continues_exactly, setup, teardown),
        cmocka_unit_test_setup_teardown(test_no_temperature_is_skipped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_std_rules_compensated, setup, teardown),
    };
    amfid_log_stream = fopen("/dev/null", "w");
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    fclose(amfid_log_stream);
    return rc;
}
