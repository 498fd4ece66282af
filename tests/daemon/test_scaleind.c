/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_scaleind.c: amfid's scale indicator and known-truck runs
 * (daemon/scaleind.c) on a real store and LCM's in-memory bus: the deck
 * temperature taken for each solved passage (and a passage without one
 * skipped, counted), the evaluations stored, and above all the restore: an
 * amfid restarted in the middle of a block (after the baseline) continues
 * exactly as one that never stopped: the same scale_evals rows and the same
 * alerts, raised once; a restart while the alerts are open does not raise
 * them again. Single-threaded: the module is driven through its interface
 * (ctx.h: start, restore, row, on_passage, metrics, stop) with a context
 * of the test's own; one amfid at a time (the modules' state is their
 * files'), so the continuous and the restarted runs go one after the other
 * on stores of their own.
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

#include "amfi_environment_t.h"
#include "ctx.h"
#include "store_testing.h"

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

/* The daemon under test: the context and its configuration. */
static amfid_ctx C;
static amfi_site_config CFG;

static int no_publish(amfid_ctx *c, const char *ch, const void *data, size_t len)
{
    (void)c, (void)ch, (void)data, (void)len;
    return 0;
}

static void collect(amfid_ctx *c, amfid_stats *s)
{
    memset(s, 0, sizeof *s);
    scaleind_module.metrics(c, s);
    environment_module.metrics(c, s);
}

static scaleind_view view(void)
{
    scaleind_view v;
    scaleind_view_of(&v);
    return v;
}

enum { ALL_ON, INDICATORS_OFF, ALL_OFF };

/* mode: ALL_ON (the defaults: the scale indicator, the known truck and the
 * compensated STD and mean rules), INDICATORS_OFF (only the compensation),
 * ALL_OFF (and the rules raw). */
static void open_daemon(const char *dir, const char *name, int with_env, int mode)
{
    char path[128], err[512];
    memset(&C, 0, sizeof C);
    amfi_config_defaults(&CFG);
    amfi_daemon_config *dc = &CFG.daemon;
    dc->scale.block = 50;
    dc->scale.baseline_blocks = 4;
    dc->scale.design_shift = 0.1;
    dc->scale.false_alarms_per_year = 10;
    dc->scale.vehicles_per_day = 500;
    dc->known_truck.baseline_runs = 3;
    if (mode != ALL_ON)
        dc->scale_enabled = dc->known_truck_enabled = 0;
    if (mode == ALL_OFF)
        dc->ind_temp_compensated = 0;
    dc->bus_auth = 0;
    snprintf(dc->lcm_url, sizeof dc->lcm_url, "memq://");
    C.cfg = &CFG;
    C.state = "running";
    C.publish = no_publish;
    C.emit_alert = alert_emit;
    C.collect = collect;
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    assert_int_equal(0, amfi_store_open(path, 0, &C.store, err, sizeof err));
    if (with_env) { /* a reading every 5 minutes over the whole test */
        static amfi_environment_row rows[800];
        for (int k = 0; k < 800; k++)
            rows[k] = (amfi_environment_row){T0 + 5 * k * MIN_US, deck_at(5 * k),
                                             deck_at(5 * k) - 2.0, T0};
        assert_int_equal(0, amfi_store_add_environment(C.store, rows, 800, err, sizeof err));
    }
    assert_int_equal(0, metrics_module.start(&C, err, sizeof err));
    assert_int_equal(0, notify_module.start(&C, err, sizeof err));
    assert_int_equal(0, environment_module.start(&C, err, sizeof err));
    assert_int_equal(0, scaleind_module.start(&C, err, sizeof err));
    assert_int_equal(0, scaleind_module.restore(&C));
}

static void close_daemon(void)
{
    scaleind_module.stop(&C);
    notify_module.stop(&C);
    amfi_store_close(C.store);
}

/* A passage through the module as the pipeline hands it: its row (the deck
 * temperature; feeds: the weight the STD and mean rules get), stored, then
 * on_passage (solved and ok: fed to the indicators). */
static void through(amfi_passage_row *r, int feeds)
{
    char err[512];
    static job j;
    memset(&j, 0, sizeof j);
    j.solved = 1;
    snprintf(j.status, sizeof j.status, "ok");
    j.w.n_vehicles = r->n_vehicles;
    amfid_passage p = {&j, r, 0, feeds};
    scaleind_module.row(&C, &p, r);
    if (r->vehicle_id > 0)
        assert_int_equal(0, amfi_store_add_passage(C.store, r, &p.id, err, sizeof err));
    scaleind_module.on_passage(&C, &p);
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
static void pass(int k, int damaged)
{
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
    double temp = 1.0 / amfi_scale_temp_factor(&CFG.daemon.scale, 0.0025, 0.018, t);
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
    through(&r, 0);
}

/* scale_evals and alerts after utime `from`, as text, malloc'd. */
struct text { char *p; size_t len, cap; };
static int dump_line(void *ctx, int n, const char *const *t)
{
    struct text *o = ctx;
    size_t k = strlen(n > 0 && t[0] ? t[0] : "");
    if (o->len + k + 2 > o->cap) {
        o->cap = 2 * (o->cap + k + 2);
        o->p = realloc(o->p, o->cap);
        assert_non_null(o->p);
    }
    memcpy(o->p + o->len, n > 0 && t[0] ? t[0] : "", k);
    o->len += k;
    o->p[o->len++] = '\n';
    o->p[o->len] = 0;
    return 0;
}

static char *dump(const char *dir, const char *name, int64_t from)
{
    char path[128], sql[512], err[512];
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    amfi_store_test_db *db = amfi_store_test_open(path, 0, err, sizeof err);
    assert_non_null(db);
    snprintf(sql, sizeof sql,
             "SELECT printf('%%s %%d %%d %%.12g %%.12g %%.12g %%.12g %%.12g %%s', kind, utime, n, "
             "value, raw, deck_c, z, cusum, state) FROM scale_evals WHERE utime > %lld UNION ALL "
             "SELECT printf('alert %%s %%d %%d %%s', kind, utime, raised, message) FROM alerts "
             "WHERE utime > %lld",
             (long long)from, (long long)from);
    struct text out = {calloc(1, 1 << 16), 0, 1 << 16};
    assert_non_null(out.p);
    assert_int_equal(0, amfi_store_test_rows(db, sql, dump_line, &out, err, sizeof err));
    amfi_store_test_close(db);
    return out.p;
}

static int count(const char *dir, const char *name, const char *sql)
{
    char path[128], err[512];
    snprintf(path, sizeof path, "%s/%s.db", dir, name);
    amfi_store_test_db *db = amfi_store_test_open(path, 0, err, sizeof err);
    assert_non_null(db);
    int64_t n = 0;
    assert_int_equal(0, amfi_store_test_int(db, sql, &n, err, sizeof err));
    amfi_store_test_close(db);
    return (int)n;
}

static void test_restart_continues_exactly(void **state)
{
    fixture *f = *state;
    const int split = 333, onset = 420, end = 700;
    /* an amfid that never stops */
    open_daemon(f->dir, "continuous", 1, ALL_ON);
    for (int k = 0; k < end; k++)
        pass(k, k >= onset);
    close_daemon();
    /* one restarted in the middle of a block */
    open_daemon(f->dir, "restarted", 1, ALL_ON);
    for (int k = 0; k < split; k++)
        pass(k, 0);
    /* the baseline is in, a block is under way, the truck's baseline done */
    assert_string_not_equal("baseline", view().scale_state);
    assert_int_equal(split, view().fed);
    assert_int_equal(0, view().no_temp);
    close_daemon();
    open_daemon(f->dir, "restarted", 0, ALL_ON);
    assert_int_equal(0, view().fed); /* the counters are this run's */
    for (int k = split; k < end; k++)
        pass(k, k >= onset);
    close_daemon();
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
    open_daemon(f->dir, "restarted", 0, ALL_ON);
    assert_string_equal("alert", view().scale_state);
    assert_string_equal("alert", view().truck_state);
    for (int k = end; k < end + 100; k++)
        pass(k, 1);
    assert_int_equal(2, count(f->dir, "restarted",
                              "SELECT count(*) FROM alerts WHERE raised = 1"));
    close_daemon();
}

static void test_no_temperature_is_skipped(void **state)
{
    fixture *f = *state;
    open_daemon(f->dir, "notemp", 1, ALL_ON);
    amfi_passage_row r;
    memset(&r, 0, sizeof r);
    r.utime = T0 + 800 * 5 * MIN_US + 3 * 3600 * INT64_C(1000000); /* 3 h after the last */
    r.gvw_kg = 9000;
    r.n_vehicles = 1;
    r.has_deck_c = 1;
    r.deck_c = 99.0;
    through(&r, 0);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(1, view().no_temp);
    assert_int_equal(0, view().fed);
    /* within half the gap of the last reading: its temperature */
    r.utime = T0 + 799 * 5 * MIN_US + 30 * MIN_US;
    through(&r, 0);
    assert_int_equal(1, r.has_deck_c);
    assert_float_equal(deck_at(799 * 5), r.deck_c, 1e-9);
    /* buffered readings are flushed before the lookup: one received on the
     * (in-memory) bus waits in the environment's buffer */
    assert_int_equal(0, bus_open(&C, NULL));
    assert_int_equal(0, environment_module.restore(&C));
    assert_int_equal(0, bus_subscribe_all(&C));
    amfi_environment_t m = {r.utime + 10 * MIN_US, 20.0, 21.5}; /* utime, air, deck */
    unsigned char buf[256];
    int n = amfi_environment_t_encode(buf, 0, sizeof buf, &m);
    assert_true(n > 0);
    assert_int_equal(0, lcm_publish(bus_lcm(), CFG.daemon.ch_environment, buf, (unsigned)n));
    while (lcm_handle_timeout(bus_lcm(), 0) > 0)
        ;
    amfid_stats s;
    collect(&C, &s);
    assert_int_equal(1, s.env_buffered);
    r.utime += 10 * MIN_US;
    through(&r, 0);
    collect(&C, &s);
    assert_int_equal(0, s.env_buffered);
    assert_float_equal(21.5, r.deck_c, 1e-9);
    bus_close();
    close_daemon();
    /* the scale indicator and the known truck off: the lookup is still made
     * for the STD and mean rules' compensation (daemon.indicators.temperature) */
    open_daemon(f->dir, "off", 0, INDICATORS_OFF);
    assert_null(view().scale_state);
    through(&r, 0);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(1, view().no_temp);
    close_daemon();
    /* all three off: no lookup, nothing counted */
    open_daemon(f->dir, "off", 0, ALL_OFF);
    through(&r, 0);
    assert_int_equal(0, r.has_deck_c);
    assert_int_equal(0, view().no_temp);
    close_daemon();
}

/* The prior law (alerts.scale: 0.0025 warm, 0.018 frost, knee 0, floor
 * -10, calibration 10 °C): the factor that brings a GVW measured at t to
 * the calibration temperature. */
static double prior_factor(double t)
{
    if (t >= 0.0)
        return exp(-0.0025 * (t - 10.0));
    return exp(0.0025 * 10.0 + 0.018 * fmin(-t, 10.0));
}

/* The weight the STD and mean rules are fed (daemon.indicators.temperature):
 * the GVW at the calibration temperature by the prior slopes before the
 * scale indicator's baseline, by its fitted slopes after; raw without a
 * deck temperature (counted) and when the setting is raw. */
static void test_std_rules_compensated(void **state)
{
    fixture *f = *state;
    open_daemon(f->dir, "comp", 1, ALL_ON);
    const amfi_scale_params *p = &CFG.daemon.scale;
    assert_int_equal(1, view().compensate); /* the default */
    assert_true(fabs(p->warm_slope - 0.0025) < 1e-12 && fabs(p->frost_slope - 0.018) < 1e-12);
    amfi_passage_row r;
    /* at readings of 14, 11.07, 4, -3.07 and -6 °C (minutes 60, 30, 0, 210, 180) */
    const int minute[5] = {60, 30, 0, 210, 180};
    for (int k = 0; k < 5; k++) {
        memset(&r, 0, sizeof r);
        r.utime = T0 + minute[k] * MIN_US;
        r.n_vehicles = 1;
        r.gvw_kg = 10000.0;
        through(&r, 1);
        assert_int_equal(1, r.has_deck_c);
        assert_float_equal(10000.0 * prior_factor(deck_at(minute[k])), r.gvw_comp_kg, 1e-6);
    }
    assert_int_equal(5, view().comp_fed);
    /* no deck temperature: raw, counted */
    memset(&r, 0, sizeof r);
    r.utime = T0 + 800 * 5 * MIN_US + 3 * 3600 * INT64_C(1000000);
    r.n_vehicles = 1;
    r.gvw_kg = 10000.0;
    through(&r, 1);
    assert_float_equal(10000.0, r.gvw_comp_kg, 0);
    assert_int_equal(1, view().comp_raw);
    /* after the scale baseline: the fitted slopes */
    amfi_passage_row q;
    for (int64_t k = 0; strcmp(view().scale_state, "baseline") == 0; k++) {
        memset(&q, 0, sizeof q);
        q.utime = T0 + k * MIN_US;
        q.n_vehicles = 1;
        q.gvw_kg = (k % 2 ? 12000.0 : 6000.0) + 300.0 * gauss((uint64_t)k);
        through(&q, 0);
        assert_int_equal(1, q.has_deck_c);
        assert_true(k < 1000);
    }
    memset(&r, 0, sizeof r);
    r.utime = T0 + 180 * MIN_US; /* -6 °C */
    r.n_vehicles = 1;
    r.gvw_kg = 10000.0;
    through(&r, 1);
    scaleind_view v = view();
    assert_int_equal(1, v.fitted);
    assert_float_equal(amfi_scale_temp_factor(p, v.warm_slope, v.frost_slope, deck_at(180)) *
                           10000.0,
                       r.gvw_comp_kg, 1e-6);
    assert_float_not_equal(10000.0 * prior_factor(deck_at(180)), r.gvw_comp_kg, 1e-3);
    assert_int_equal(6, view().comp_fed);
    close_daemon();
    /* raw: the GVW, nothing counted */
    open_daemon(f->dir, "raw", 1, ALL_OFF);
    memset(&r, 0, sizeof r);
    r.utime = T0 + 180 * MIN_US;
    r.n_vehicles = 1;
    r.gvw_kg = 10000.0;
    through(&r, 1);
    assert_float_equal(10000.0, r.gvw_comp_kg, 0);
    assert_int_equal(0, view().comp_fed);
    assert_int_equal(0, view().comp_raw);
    close_daemon();
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
