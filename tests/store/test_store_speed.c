/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_store_speed.c: unit tests of the store's estimated-speed queries
 * (store/store_speed.c): which passages count (speed_estimated = 1 with both
 * speeds known), their order, the filter (time range, status, lane), the
 * newest N for amfid's speed-drift window, the argument checks, and a
 * damaged speed written behind the store's back reported by its row. Each
 * test works in a fresh directory under /tmp, removed afterwards.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store.h"
#include "store_fixture.h"

#define ERRLEN 512
#define DAY_US INT64_C(86400000000)

static int setup(void **state) { return store_fixture_setup(state, "amfi_test_store_speed"); }
static int teardown(void **state) { return store_fixture_teardown(state, NULL); }

/* An ok passage on `lane` weighed with `used` m/s, the detector saying `given`. */
static void add(amfi_store *s, int64_t vehicle_id, int64_t utime, int lane, double used,
                double given, int estimated, const char *status)
{
    amfi_passage_row r;
    char err[ERRLEN];
    memset(&r, 0, sizeof r);
    r.vehicle_id = vehicle_id;
    r.utime = utime;
    r.lane = lane;
    r.speed_mps = used;
    r.speed_given_mps = given;
    r.speed_estimated = estimated;
    r.status = status;
    r.reason = strcmp(status, "ok") == 0 ? "" : "no solve";
    if (strcmp(status, "ok") == 0) {
        r.n_axles = 2;
        r.spacing_m[0] = 4.5;
        r.axle_kg[0] = 8000;
        r.axle_kg[1] = 12000;
        r.gvw_kg = 20000;
    }
    r.lambda = r.residual_rms = r.solve_ms = NAN;
    if (amfi_store_add_passage(s, &r, NULL, err, sizeof err) != 0)
        fail_msg("add_passage: %s", err);
}

static void test_none(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    int yes = -1;
    amfi_speed_pair *p = (amfi_speed_pair *)&yes;
    size_t n = 99;
    amfi_passage_filter all = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
    assert_int_equal(0, amfi_store_has_estimated(f->s, &yes, err, sizeof err));
    assert_int_equal(0, yes);
    add(f->s, 1, DAY_US, 1, 27.5, 25.0, 0, "ok"); /* measured: not a correction */
    assert_int_equal(0, amfi_store_has_estimated(f->s, &yes, err, sizeof err));
    assert_int_equal(0, yes);
    assert_int_equal(0, amfi_store_speed_pairs(f->s, &all, &p, &n, err, sizeof err));
    assert_int_equal(0, n);
    assert_null(p);
    assert_int_equal(0, amfi_store_recent_speed_pairs(f->s, 5, &p, &n, err, sizeof err));
    assert_int_equal(0, n);
    assert_null(p);
}

static void test_pairs_filtered_and_recent(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    int yes = 0;
    amfi_speed_pair *p = NULL;
    size_t n = 0;
    /* inserted out of time order; c = used / 25 − 1 = k % */
    static const int64_t t[6] = {50, 10, 40, 20, 60, 30};
    for (int k = 0; k < 6; k++)
        add(f->s, k, DAY_US + t[k] * 1000000, k == 4 ? 2 : 1, 25.0 * (1 + 0.01 * (double)t[k]),
            25.0, 1, "ok");
    add(f->s, 10, DAY_US + 35000000, 1, 30.0, 25.0, 0, "ok");   /* not estimated */
    add(f->s, 11, DAY_US + 36000000, 1, NAN, 25.0, 1, "error"); /* speed unknown */
    add(f->s, 12, DAY_US + 37000000, 1, 24.0, 25.0, 1, "late"); /* counts, not ok */
    assert_int_equal(0, amfi_store_has_estimated(f->s, &yes, err, sizeof err));
    assert_int_equal(1, yes);

    amfi_passage_filter all = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
    assert_int_equal(0, amfi_store_speed_pairs(f->s, &all, &p, &n, err, sizeof err));
    assert_int_equal(7, n);
    static const double want_t[7] = {10, 20, 30, 37, 40, 50, 60};
    for (size_t k = 0; k < n; k++) {
        assert_true(p[k].utime == DAY_US + (int64_t)want_t[k] * 1000000);
        assert_true(p[k].speed_given_mps == 25.0);
        if (want_t[k] == 37)
            assert_true(p[k].speed_mps == 24.0);
        else
            assert_true(fabs(p[k].speed_mps / 25.0 - 1 - 0.01 * want_t[k]) < 1e-12);
    }
    free(p);

    amfi_passage_filter f2 = {.from = DAY_US + 20000000, .to = DAY_US + 50000000,
                              .status = "ok", .lane_given = 1, .lane = 1};
    assert_int_equal(0, amfi_store_speed_pairs(f->s, &f2, &p, &n, err, sizeof err));
    assert_int_equal(4, n); /* 20 30 40 50; 37 is late, 60 on lane 2 and out of range */
    assert_true(p[0].utime == DAY_US + 20000000 && p[3].utime == DAY_US + 50000000);
    free(p);

    /* the newest 3, oldest first */
    assert_int_equal(0, amfi_store_recent_speed_pairs(f->s, 3, &p, &n, err, sizeof err));
    assert_int_equal(3, n);
    assert_true(p[0].utime == DAY_US + 40000000 && p[1].utime == DAY_US + 50000000
                && p[2].utime == DAY_US + 60000000);
    free(p);
    assert_int_equal(0, amfi_store_recent_speed_pairs(f->s, 100, &p, &n, err, sizeof err));
    assert_int_equal(7, n);
    free(p);
}

static void test_bad_arguments_and_damage(void **state)
{
    fixture *f = *state;
    char err[ERRLEN];
    amfi_speed_pair *p = NULL;
    size_t n = 0;
    amfi_passage_filter bad_status = {.from = 0, .to = 1, .status = "maybe"};
    amfi_passage_filter bad_lane = {.from = 0, .to = 1, .lane_given = 1, .lane = 40000};
    assert_int_equal(AMFI_EINVAL, amfi_store_has_estimated(f->s, NULL, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, amfi_store_speed_pairs(f->s, NULL, &p, &n, err, sizeof err));
    assert_int_equal(AMFI_EINVAL,
                     amfi_store_speed_pairs(f->s, &bad_status, &p, &n, err, sizeof err));
    assert_non_null(strstr(err, "status"));
    assert_int_equal(AMFI_EINVAL, amfi_store_speed_pairs(f->s, &bad_lane, &p, &n, err, sizeof err));
    assert_non_null(strstr(err, "lane 40000"));
    assert_int_equal(AMFI_EINVAL, amfi_store_recent_speed_pairs(f->s, 0, &p, &n, err, sizeof err));

    add(f->s, 1, DAY_US, 1, 24.0, 25.0, 1, "ok");
    add(f->s, 2, DAY_US + 1, 1, 24.0, 25.0, 1, "ok");
    sqlite3 *db = NULL;
    assert_int_equal(SQLITE_OK, sqlite3_open(f->path, &db));
    assert_int_equal(SQLITE_OK,
                     sqlite3_exec(db, "PRAGMA ignore_check_constraints = ON; "
                                      "UPDATE passages SET speed_given_mps = 500 WHERE id = 2",
                                  NULL, NULL, NULL));
    sqlite3_close(db);
    amfi_passage_filter all = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
    p = NULL;
    assert_int_equal(AMFI_STORE_ECORRUPT, amfi_store_speed_pairs(f->s, &all, &p, &n, err, sizeof err));
    assert_null(p);
    assert_non_null(strstr(err, "passages row 2"));
    assert_non_null(strstr(err, "speed_given_mps"));
    assert_int_equal(AMFI_STORE_ECORRUPT,
                     amfi_store_recent_speed_pairs(f->s, 5, &p, &n, err, sizeof err));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_none, setup, teardown),
        cmocka_unit_test_setup_teardown(test_pairs_filtered_and_recent, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_arguments_and_damage, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
