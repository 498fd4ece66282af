/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_store_raw: the passages' raw samples (store/store_raw.c, schema
 * version 11): the codec gives back every float64 bit for bit (signals,
 * noise, signed zeros, subnormals, extremes, several sensors); a window
 * written with its passage reads back with every field and its link (an
 * event's later vehicle); a window that cannot be written costs the raw
 * rows, never the passage; a truncated or damaged blob and a damaged text
 * give AMFI_STORE_ECORRUPT naming the passage; retention by age and by size
 * deletes the oldest windows and their links, never a passage; a version-10
 * store migrates and its passages have no raw samples (found 0).
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

#include "store.h"
#include "store_fixture.h"
#include "store_testing.h"

static int setup(void **state) { return store_fixture_setup(state, "amfi_test_raw"); }
static int teardown(void **state)
{
    static const char *const extra[] = {"v10.db", NULL};
    return store_fixture_teardown(state, extra);
}

/* A bit-exact comparison of n doubles. */
static void assert_same_bits(const double *a, const double *b, int64_t n)
{
    for (int64_t k = 0; k < n; k++)
        if (memcmp(&a[k], &b[k], sizeof a[k]) != 0)
            fail_msg("sample %lld: %.17g written, %.17g read", (long long)k, a[k], b[k]);
}

/* A passage's accelerations: a decaying sine plus noise, as a bridge gives. */
static void signal(double *x, int n, int sensor, unsigned seed)
{
    srand(seed);
    for (int k = 0; k < n; k++)
        x[k] = 0.3 * sin(2 * 3.141592653589793 * 5.7 * k / 1000.0 + sensor) * exp(-k / 3000.0) +
               1e-3 * ((double)rand() / RAND_MAX - 0.5);
}

static void test_codec_exact(void **state)
{
    (void)state;
    enum { N = 3000, S = 3 };
    static double x[N * S], y[N * S];
    for (int s = 0; s < S; s++)
        signal(x + s * N, N, s, 7u + (unsigned)s);
    /* the awkward values: signed zeros, subnormals, extremes, a NaN's
     * neighbour patterns are not samples (the writer refuses non-finite) */
    x[0] = -0.0;
    x[1] = 0.0;
    x[2] = 4.9406564584124654e-324;
    x[3] = -2.2250738585072009e-308;
    x[4] = 1.7976931348623157e308;
    x[5] = -1.7976931348623157e308;
    x[N] = 1.0 / 3.0;
    unsigned char *blob = NULL;
    size_t len = 0;
    char err[256];
    /* float32: the extremes within its range (3e38), the rest as is */
    static double xs[N * S], xf[N * S];
    memcpy(xs, x, sizeof xs);
    xs[4] = 3e38;
    xs[5] = -3e38;
    for (int k = 0; k < N * S; k++)
        xf[k] = (double)(float)xs[k];
    size_t len64 = 0; /* float64 at level 1: float32 takes fewer bytes */
    for (int f32 = 0; f32 <= 1; f32++) {
        /* float32: the samples as floats, exactly (subnormal doubles are 0) */
        const double *in = f32 ? xs : x, *want = f32 ? xf : x;
        for (int level = 1; level <= 9; level += 4) {
            assert_int_equal(0, amfi_store_raw_encode(in, N * S, S, level, f32, &blob, &len, err,
                                                      sizeof err));
            assert_true(len > 0 && len < (f32 ? sizeof x / 2 : sizeof x));
            if (level == 1 && !f32)
                len64 = len;
            if (level == 1 && f32)
                assert_true(len < len64);
            memset(y, 0xa5, sizeof y);
            assert_int_equal(0, amfi_store_raw_decode(blob, len, N * S, S, f32, y, err,
                                                      sizeof err));
            assert_same_bits(want, y, N * S);
            /* read as the other width, or a count other than the one encoded: refused */
            assert_int_equal(AMFI_STORE_ECORRUPT,
                             amfi_store_raw_decode(blob, len, N * S, S, !f32, y, err, sizeof err));
            assert_int_equal(AMFI_STORE_ECORRUPT,
                             amfi_store_raw_decode(blob, len, N * S - S, S, f32, y, err,
                                                   sizeof err));
            /* truncated: refused, never half a window */
            assert_int_equal(AMFI_STORE_ECORRUPT,
                             amfi_store_raw_decode(blob, len - 7, N * S, S, f32, y, err,
                                                   sizeof err));
            /* one flipped byte in the middle: zlib's checksum or its stream says so */
            blob[len / 2] ^= 0x40;
            assert_int_equal(AMFI_STORE_ECORRUPT,
                             amfi_store_raw_decode(blob, len, N * S, S, f32, y, err, sizeof err));
            free(blob);
        }
    }
    /* float32 cannot hold 1.8e308: refused, not made infinite */
    assert_int_equal(AMFI_EINVAL, amfi_store_raw_encode(x, N * S, S, 1, 1, &blob, &len, err,
                                                       sizeof err));
    /* not a window: a count that is not a multiple of the sensors */
    assert_int_equal(AMFI_EINVAL, amfi_store_raw_encode(x, 10, 3, 6, 0, &blob, &len, err,
                                                       sizeof err));
}

/* A window of two vehicles and two sensors. */
static double samples[2 * 1500];
static void make_window(amfi_raw_window *w, int64_t utime)
{
    memset(w, 0, sizeof *w);
    w->utime = utime;
    w->rate_hz = 1000;
    w->t_first_s = -0.35000000000000003;
    w->n_samples = 1500;
    w->n_sensors = 2;
    w->sensor_id[0] = 3;
    w->sensor_at_m[0] = 10;
    w->sensor_id[1] = 7;
    w->sensor_at_m[1] = 15.125;
    w->n_vehicles = 2;
    w->vehicle[0] = (amfi_raw_vehicle){41, utime, 1, 22.300000000000001, 3, {3.6, 1.3}};
    w->vehicle[1] = (amfi_raw_vehicle){42, utime + 400000, -2, 19.75, 1, {0}};
    amfi_lambda_default(&w->lambda);
    w->lambda.lambda_ref = 1.2345678901234567e-9;
    amfi_speed_prior_default(&w->speed_prior);
    w->speed_estimate = 1;
    signal(samples, 1500, 0, 1);
    signal(samples + 1500, 1500, 1, 2);
    w->samples = samples;
}

static void make_row(amfi_passage_row *r, int64_t vehicle_id, int64_t utime, amfi_raw_put *put)
{
    memset(r, 0, sizeof *r);
    r->vehicle_id = vehicle_id;
    r->utime = utime;
    r->lane = 1;
    r->speed_mps = 22.3;
    r->speed_given_mps = NAN;
    r->n_axles = 2;
    r->spacing_m[0] = 3.6;
    r->axle_kg[0] = 5000;
    r->axle_kg[1] = 7000;
    r->gvw_kg = 12000;
    r->status = "ok";
    r->lambda = 7.94e-9;
    r->residual_rms = 0.01;
    r->solve_ms = 3;
    r->quality = NAN;
    r->f1_hz = r->f1_comp_hz = r->f1_zeta = r->f1_r2 = NAN;
    r->raw = put;
}

static void test_write_read(void **state)
{
    fixture *f = *state;
    char err[256];
    amfi_raw_window w;
    make_window(&w, 1700000000000000);
    amfi_raw_put put = {.window = &w, .vehicle = 0};
    amfi_passage_row r;
    int64_t id1 = 0, id2 = 0, id3 = 0;
    make_row(&r, 41, w.utime, &put);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id1, err, sizeof err));
    assert_int_equal(0, put.status);
    assert_true(put.stored_window_id > 0);
    assert_true(put.bytes > 0 && put.bytes < put.raw_bytes);
    assert_int_equal(2 * 1500 * 8, put.raw_bytes);
    /* the event's second vehicle: a link */
    amfi_raw_put link = {.window_id = put.stored_window_id, .vehicle = 1};
    make_row(&r, 42, w.utime + 400000, &link);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id2, err, sizeof err));
    assert_int_equal(0, link.status);
    /* a link to a window that does not exist: the passage is stored all
     * the same, without raw rows, and the put says why */
    amfi_raw_put bad = {.window_id = 999999, .vehicle = 0};
    make_row(&r, 43, w.utime + 900000, &bad);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id3, err, sizeof err));
    assert_int_not_equal(0, bad.status);
    assert_non_null(strstr(bad.err, "passage_raw"));
    /* a window with a non-finite sample: refused, the passage kept */
    amfi_raw_window nan_w = w;
    static double nan_samples[2 * 1500];
    memcpy(nan_samples, samples, sizeof nan_samples);
    nan_samples[1700] = NAN;
    nan_w.samples = nan_samples;
    amfi_raw_put nan_put = {.window = &nan_w, .vehicle = 0};
    int64_t id4 = 0;
    make_row(&r, 44, w.utime + 2000000, &nan_put);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id4, err, sizeof err));
    assert_int_equal(AMFI_EINVAL, nan_put.status);
    assert_non_null(strstr(nan_put.err, "sample 200 of sensor 1"));

    amfi_raw_rec rec;
    int found = -1;
    assert_int_equal(0, amfi_store_raw_get(f->s, id1, &rec, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_int_equal(put.stored_window_id, rec.window_id);
    assert_int_equal(0, rec.vehicle);
    assert_int_equal(put.bytes, rec.bytes);
    assert_int_equal(w.utime, rec.w.utime);
    assert_memory_equal(&w.rate_hz, &rec.w.rate_hz, sizeof w.rate_hz);
    assert_memory_equal(&w.t_first_s, &rec.w.t_first_s, sizeof w.t_first_s);
    assert_int_equal(1500, rec.w.n_samples);
    assert_int_equal(2, rec.w.n_sensors);
    assert_int_equal(7, rec.w.sensor_id[1]);
    assert_memory_equal(&w.sensor_at_m[1], &rec.w.sensor_at_m[1], sizeof(double));
    assert_int_equal(2, rec.w.n_vehicles);
    for (int v = 0; v < 2; v++) {
        const amfi_raw_vehicle *a = &w.vehicle[v], *b = &rec.w.vehicle[v];
        assert_int_equal(a->vehicle_id, b->vehicle_id);
        assert_int_equal(a->utime, b->utime);
        assert_int_equal(a->lane, b->lane);
        assert_memory_equal(&a->speed_mps, &b->speed_mps, sizeof(double));
        assert_int_equal(a->n_axles, b->n_axles);
        assert_memory_equal(a->spacing_m, b->spacing_m, sizeof(double) * (size_t)(a->n_axles - 1));
    }
    assert_int_equal(0, rec.w.lambda.automatic);
    assert_memory_equal(&w.lambda.lambda_ref, &rec.w.lambda.lambda_ref, sizeof(double));
    assert_int_equal(w.lambda.lcurve_per_decade, rec.w.lambda.lcurve_per_decade);
    assert_int_equal(1, rec.w.speed_estimate);
    assert_memory_equal(&w.speed_prior.rel_sd, &rec.w.speed_prior.rel_sd, sizeof(double));
    assert_int_equal(w.speed_prior.pick, rec.w.speed_prior.pick);
    assert_int_equal(w.speed_prior.criterion, rec.w.speed_prior.criterion);
    assert_same_bits(samples, rec.w.samples, 3000);
    amfi_store_raw_free(&rec);

    assert_int_equal(0, amfi_store_raw_get(f->s, id2, &rec, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_int_equal(1, rec.vehicle);
    assert_int_equal(put.stored_window_id, rec.window_id);
    amfi_store_raw_free(&rec);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(0, amfi_store_raw_get(f->s, k ? id4 : id3, &rec, &found, err,
                                               sizeof err));
        assert_int_equal(0, found);
    }
    /* the same window kept as float32: read back as the floats, flagged */
    amfi_raw_put p32 = {.window = &w, .float32 = 1, .vehicle = 0};
    int64_t id5 = 0;
    make_row(&r, 45, w.utime + 3000000, &p32);
    assert_int_equal(0, amfi_store_add_passage(f->s, &r, &id5, err, sizeof err));
    assert_int_equal(0, p32.status);
    assert_true(p32.bytes < put.bytes);
    assert_int_equal(0, amfi_store_raw_get(f->s, id5, &rec, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_int_equal(1, rec.float32);
    for (int k = 0; k < 3000; k++)
        assert_true(rec.w.samples[k] == (double)(float)samples[k]);
    amfi_store_raw_free(&rec);
    amfi_stored_passage sp;
    assert_int_equal(0, amfi_store_passage_get(f->s, id1, &sp, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_string_equal("ok", sp.row.status);
    assert_true(sp.row.gvw_kg == 12000 && sp.row.axle_kg[1] == 7000 && sp.row.spacing_m[0] == 3.6);
    assert_int_equal(0, amfi_store_passage_get(f->s, 12345, &sp, &found, err, sizeof err));
    assert_int_equal(0, found);
}

/* Damage applied with raw SQL: the read names the passage. */
static void damaged(fixture *f, const char *sql, int64_t id, const char *expect)
{
    char err[512];
    amfi_store_test_db *db = amfi_store_test_open(f->path, 0, err, sizeof err);
    assert_non_null(db);
    if (amfi_store_test_exec(db, sql, err, sizeof err) != 0)
        fail_msg("%s: %s", sql, err);
    amfi_store_test_close(db);
    amfi_raw_rec rec;
    int found = -1;
    int rc = amfi_store_raw_get(f->s, id, &rec, &found, err, sizeof err);
    if (rc != AMFI_STORE_ECORRUPT)
        fail_msg("%s: status %d, found %d (%s)", sql, rc, found, err);
    char name[64];
    snprintf(name, sizeof name, "passage %lld", (long long)id);
    if (!strstr(err, name) || !strstr(err, expect))
        fail_msg("%s: the message '%s' names neither '%s' nor '%s'", sql, err, name, expect);
    assert_int_equal(0, found);
}

static void test_corrupt(void **state)
{
    fixture *f = *state;
    char err[256], sql[256];
    amfi_raw_window w;
    amfi_passage_row r;
    int64_t ids[4];
    for (int k = 0; k < 4; k++) {
        make_window(&w, 1700000000000000 + k * 10000000);
        w.n_vehicles = 1;
        amfi_raw_put put = {.window = &w};
        make_row(&r, 41 + k, w.utime, &put);
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, &ids[k], err, sizeof err));
        assert_int_equal(0, put.status);
    }
    /* truncated (bytes kept consistent, as a tool cutting a blob would) */
    snprintf(sql, sizeof sql,
             "UPDATE raw_windows SET samples = substr(samples, 1, bytes - 20), bytes = bytes - 20 "
             "WHERE id = (SELECT window_id FROM passage_raw WHERE passage_id = %lld)",
             (long long)ids[0]);
    damaged(f, sql, ids[0], "does not decode");
    /* a byte changed in the middle */
    snprintf(sql, sizeof sql,
             "UPDATE raw_windows SET samples = CAST(substr(samples, 1, bytes / 2) || x'00ff00ff' || "
             "substr(samples, bytes / 2 + 5) AS BLOB) WHERE id = (SELECT window_id FROM passage_raw "
             "WHERE passage_id = %lld)",
             (long long)ids[1]);
    damaged(f, sql, ids[1], "does not decode");
    /* a vehicles text that is not one */
    snprintf(sql, sizeof sql,
             "UPDATE raw_windows SET vehicles = '41,x,1,22' WHERE id = (SELECT window_id FROM "
             "passage_raw WHERE passage_id = %lld)",
             (long long)ids[2]);
    damaged(f, sql, ids[2], "vehicles");
    /* the samples of another window's size */
    snprintf(sql, sizeof sql,
             "UPDATE raw_windows SET n_samples = 1499 WHERE id = (SELECT window_id FROM "
             "passage_raw WHERE passage_id = %lld)",
             (long long)ids[3]);
    damaged(f, sql, ids[3], "does not decode");
}

static void test_retention(void **state)
{
    fixture *f = *state;
    char err[256];
    amfi_raw_window w;
    amfi_passage_row r;
    int64_t ids[10], bytes[10], wid[10];
    const int64_t day = INT64_C(86400000000), t0 = 1700000000000000;
    /* ten windows, a day apart, stored out of time order */
    static const int order[10] = {3, 0, 1, 2, 9, 4, 5, 8, 6, 7};
    for (int i = 0; i < 10; i++) {
        int k = order[i];
        make_window(&w, t0 + k * day);
        w.n_vehicles = 1;
        amfi_raw_put put = {.window = &w};
        make_row(&r, k, w.utime, &put);
        assert_int_equal(0, amfi_store_add_passage(f->s, &r, &ids[k], err, sizeof err));
        assert_int_equal(0, put.status);
        bytes[k] = put.bytes;
        wid[k] = put.stored_window_id;
    }
    int64_t nw = 0, nb = 0, total = 0;
    for (int k = 0; k < 10; k++)
        total += bytes[k];
    assert_int_equal(0, amfi_store_raw_usage(f->s, &nw, &nb, err, sizeof err));
    assert_int_equal(10, nw);
    assert_int_equal(total, nb);
    /* by age: the windows before day 3 (0, 1, 2), at most 2 a call */
    amfi_raw_pruned pr;
    assert_int_equal(0, amfi_store_raw_prune(f->s, t0 + 3 * day, -1, 2, &pr, err, sizeof err));
    assert_int_equal(2, pr.by_age);
    assert_int_equal(0, pr.by_size);
    assert_int_equal(1, pr.more);
    assert_int_equal(bytes[0] + bytes[1], pr.bytes);
    assert_int_equal(0, amfi_store_raw_prune(f->s, t0 + 3 * day, -1, 100, &pr, err, sizeof err));
    assert_int_equal(1, pr.by_age);
    assert_int_equal(0, pr.more);
    amfi_raw_rec rec;
    int found;
    for (int k = 0; k < 10; k++) {
        assert_int_equal(0, amfi_store_raw_get(f->s, ids[k], &rec, &found, err, sizeof err));
        assert_int_equal(k >= 3, found);
        if (found)
            assert_int_equal(wid[k], rec.window_id);
        amfi_store_raw_free(&rec);
    }
    /* by size: keep at most the bytes of the 4 newest: 3 .. 5 go, oldest first */
    int64_t keep = bytes[6] + bytes[7] + bytes[8] + bytes[9];
    assert_int_equal(0, amfi_store_raw_prune(f->s, 0, keep, 100, &pr, err, sizeof err));
    assert_int_equal(0, pr.by_age);
    assert_int_equal(3, pr.by_size);
    assert_int_equal(bytes[3] + bytes[4] + bytes[5], pr.bytes);
    assert_int_equal(0, amfi_store_raw_usage(f->s, &nw, &nb, err, sizeof err));
    assert_int_equal(4, nw);
    assert_int_equal(keep, nb);
    for (int k = 0; k < 10; k++) {
        assert_int_equal(0, amfi_store_raw_get(f->s, ids[k], &rec, &found, err, sizeof err));
        assert_int_equal(k >= 6, found);
        amfi_store_raw_free(&rec);
    }
    /* within the bound: nothing */
    assert_int_equal(0, amfi_store_raw_prune(f->s, 0, keep, 100, &pr, err, sizeof err));
    assert_int_equal(0, pr.by_size);
    /* the passages all stay, and no link is left without its window */
    int64_t n = 0;
    assert_int_equal(0, amfi_store_count(f->s, AMFI_STORE_PASSAGES, &n, err, sizeof err));
    assert_int_equal(10, n);
    amfi_store_test_db *db = amfi_store_test_open(f->path, 0, err, sizeof err);
    assert_non_null(db);
    assert_int_equal(0, amfi_store_test_int(db, "SELECT count(*) FROM passage_raw", &n, err,
                                            sizeof err));
    assert_int_equal(4, n);
    amfi_store_test_close(db);
}

/* A version-10 store (the migrations up to 10) migrates; its passages have
 * no raw samples; new ones do. */
static void test_from_v10(void **state)
{
    fixture *f = *state;
    char path[160], err[512];
    snprintf(path, sizeof path, "%s/v10.db", f->dir);
    assert_int_equal(0, amfi_store_test_create(path, AMFI_STORE_RAW_VERSION - 1, err, sizeof err));
    amfi_store_test_db *db = amfi_store_test_open(path, 0, err, sizeof err);
    assert_non_null(db);
    assert_int_equal(0, amfi_store_test_exec(db,
                                             "INSERT INTO passages (vehicle_id, utime, lane, "
                                             "n_axles, status) VALUES (1, 5, 0, 0, 'gap')",
                                             err, sizeof err));
    amfi_store_test_close(db);
    amfi_store *s = NULL;
    /* read-only before the migration: no table, no samples, no error */
    amfi_store *rd = NULL;
    int version = 0, immutable = 0, found = -1;
    assert_int_equal(0, amfi_store_open_reader(path, 0, &rd, &version, &immutable, err,
                                               sizeof err));
    assert_int_equal(AMFI_STORE_RAW_VERSION - 1, version);
    amfi_raw_rec rec;
    assert_int_equal(0, amfi_store_raw_get(rd, 1, &rec, &found, err, sizeof err));
    assert_int_equal(0, found);
    amfi_store_close(rd);
    assert_int_equal(0, amfi_store_open(path, 0, &s, err, sizeof err));
    assert_int_equal(0, amfi_store_raw_get(s, 1, &rec, &found, err, sizeof err));
    assert_int_equal(0, found);
    amfi_raw_window w;
    make_window(&w, 1700000000000000);
    amfi_raw_put put = {.window = &w, .vehicle = 0};
    amfi_passage_row r;
    int64_t id = 0;
    make_row(&r, 41, w.utime, &put);
    assert_int_equal(0, amfi_store_add_passage(s, &r, &id, err, sizeof err));
    assert_int_equal(0, put.status);
    assert_int_equal(0, amfi_store_raw_get(s, id, &rec, &found, err, sizeof err));
    assert_int_equal(1, found);
    assert_same_bits(samples, rec.w.samples, 3000);
    amfi_store_raw_free(&rec);
    amfi_store_close(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_codec_exact),
        cmocka_unit_test_setup_teardown(test_write_read, setup, teardown),
        cmocka_unit_test_setup_teardown(test_corrupt, setup, teardown),
        cmocka_unit_test_setup_teardown(test_retention, setup, teardown),
        cmocka_unit_test_setup_teardown(test_from_v10, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
