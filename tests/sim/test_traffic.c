/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_traffic.c: the WIM traffic reader (sim_publisher/traffic.c) on good
 * files and on every kind of bad input it must reject with a
 * "FILE:LINE: column: problem" message; and the shipped synthetic population
 * (sim_publisher/data/population.csv) against the ranges documented in
 * docs/simulator-inputs.md.
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
#include <unistd.h>

#include "traffic.h"
#include "vclass.h"

static char dir[64];
static char path[256];
static char err[512];

#define HDR "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m\n"

static const char *file_path(const char *name)
{
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return path;
}

static const char *write_bytes(const char *name, const void *data, size_t n)
{
    const char *p = file_path(name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
    return p;
}

static const char *write_text(const char *name, const char *text)
{
    return write_bytes(name, text, strlen(text));
}

/* The read must fail with "PATH:LINE: COLUMN: ..." (": COLUMN" left out
 * when column is NULL, ":LINE" when line is 0) containing `what`. */
static void expect_error(const char *p, long line, const char *column, const char *what)
{
    amfi_vehicle_rec *r = (amfi_vehicle_rec *)err; /* must be reset to NULL */
    int n = -1;
    int rc = amfi_traffic_read(p, &r, &n, err, sizeof err);
    if (rc == 0)
        fail_msg("%s: accepted, expected line %ld: %s", p, line, what);
    assert_int_equal(rc, AMFI_EINVAL);
    assert_null(r);
    assert_int_equal(n, 0);
    char prefix[400];
    int k = line > 0 ? snprintf(prefix, sizeof prefix, "%s:%ld: ", p, line)
                     : snprintf(prefix, sizeof prefix, "%s: ", p);
    if (column)
        snprintf(prefix + k, sizeof prefix - (size_t)k, "%s: ", column);
    if (strncmp(err, prefix, strlen(prefix)) != 0 || !strstr(err, what))
        fail_msg("got '%s', expected '%s...%s'", err, prefix, what);
    assert_null(strchr(err, '\n'));
}

/* HDR and 5 good rows, row `bad` (0-based; line bad + 2) replaced by `row` */
static const char *with_row(int bad, const char *row)
{
    char text[8192];
    size_t n = (size_t)snprintf(text, sizeof text, HDR);
    for (int k = 0; k < 5; k++) {
        if (k == bad)
            n += (size_t)snprintf(text + n, sizeof text - n, "%s\n", row);
        else
            n += (size_t)snprintf(text + n, sizeof text - n, "%d.5,1,25,9000,4000,5000,4.5\n",
                                  10 * k);
    }
    return write_text("row.csv", text);
}

/* ---- good files --------------------------------------------------------- */

static void test_good(void **state)
{
    (void)state;
    const char *p = write_text("good.csv", HDR "0.000,1,25.00,9000,4000,5000,4.50\n"
                                               "0.000,2,1,500,200,300,0.5\n"
                                               "3.25,8,60,100000,40000,60000,30\n");
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    assert_int_equal(amfi_traffic_read(p, &r, &n, err, sizeof err), 0);
    assert_int_equal(n, 3);
    assert_true(r[0].timestamp_s == 0.0 && r[0].lane == 1 && r[0].speed_mps == 25.0);
    assert_true(r[0].gvw_kg == 9000 && r[0].n_axles == 2);
    assert_true(r[0].axle_kg[0] == 4000 && r[0].axle_kg[1] == 5000 && r[0].axle_kg[2] == 0);
    assert_true(r[0].spacing_m[0] == 4.5 && r[0].spacing_m[1] == 0);
    assert_true(r[1].lane == 2 && r[1].speed_mps == 1 && r[1].gvw_kg == 500);
    assert_true(r[2].timestamp_s == 3.25 && r[2].lane == 8 && r[2].spacing_m[0] == 30);
    amfi_traffic_free(r);
    amfi_traffic_free(NULL);
}

/* Columns in any order, BOM, CRLF, blanks around fields, blank lines at the
 * end, GVW 0.9 % off the axle sum, three axles, a negative timestamp. */
static void test_good_variants(void **state)
{
    (void)state;
    const char *p = write_text("var.csv",
                               "\xEF\xBB\xBF spacing2_m ,axle3_kg,gvw_kg,axle1_kg,spacing1_m,"
                               "speed_mps,\tlane,axle2_kg,timestamp_s\r\n"
                               " 1.3 , 7000 , 18163.5 , 5000 , 4.0 , 22.5 , 3 , 6000 , -5 \r\n"
                               "1.3,7000,17837,5000,4.0,22.5,3,6000,-5\r\n"
                               "\r\n  \n\n");
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    assert_int_equal(amfi_traffic_read(p, &r, &n, err, sizeof err), 0);
    assert_int_equal(n, 2);
    assert_int_equal(r[0].n_axles, 3);
    assert_true(r[0].axle_kg[0] == 5000 && r[0].axle_kg[1] == 6000 && r[0].axle_kg[2] == 7000);
    assert_true(r[0].spacing_m[0] == 4.0 && r[0].spacing_m[1] == 1.3);
    assert_true(r[0].gvw_kg == 18163.5 && r[1].gvw_kg == 17837);
    assert_true(r[0].timestamp_s == -5.0 && r[0].lane == 3 && r[0].speed_mps == 22.5);
    amfi_traffic_free(r);
}

/* AMFI_MAX_AXLES axles is the limit, one more is an error. */
static void test_max_axles(void **state)
{
    (void)state;
    char text[4096];
    size_t k = (size_t)snprintf(text, sizeof text, "timestamp_s,lane,speed_mps,gvw_kg");
    for (int a = 1; a <= AMFI_MAX_AXLES; a++)
        k += (size_t)snprintf(text + k, sizeof text - k, ",axle%d_kg", a);
    for (int a = 1; a < AMFI_MAX_AXLES; a++)
        k += (size_t)snprintf(text + k, sizeof text - k, ",spacing%d_m", a);
    k += (size_t)snprintf(text + k, sizeof text - k, "\n0,1,20,%d", 5000 * AMFI_MAX_AXLES);
    for (int a = 1; a <= AMFI_MAX_AXLES; a++)
        k += (size_t)snprintf(text + k, sizeof text - k, ",5000");
    for (int a = 1; a < AMFI_MAX_AXLES; a++)
        k += (size_t)snprintf(text + k, sizeof text - k, ",1.%d", a);
    snprintf(text + k, sizeof text - k, "\n");
    const char *p = write_text("max.csv", text);
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    assert_int_equal(amfi_traffic_read(p, &r, &n, err, sizeof err), 0);
    assert_int_equal(n, 1);
    assert_int_equal(r[0].n_axles, AMFI_MAX_AXLES);
    assert_true(r[0].spacing_m[AMFI_MAX_AXLES - 2] == 1.0 + (AMFI_MAX_AXLES - 1) / 100.0);
    amfi_traffic_free(r);
    char h[64];
    snprintf(h, sizeof h, "axle%d_kg", AMFI_MAX_AXLES + 1);
    char t2[256];
    snprintf(t2, sizeof t2, "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m,%s\n", h);
    expect_error(write_text("max2.csv", t2), 1, h, "at most 12 axles");
}

/* ---- bad files ---------------------------------------------------------- */

static void test_cannot_open(void **state)
{
    (void)state;
    expect_error(file_path("does-not-exist.csv"), 0, NULL, "cannot open");
    /* a tiny error buffer truncates; NULL with 0 is allowed */
    amfi_vehicle_rec *r;
    int n;
    char small[8];
    assert_int_equal(amfi_traffic_read(file_path("nope"), &r, &n, small, sizeof small),
                     AMFI_EINVAL);
    assert_int_equal(strlen(small), sizeof small - 1);
    assert_int_equal(amfi_traffic_read(file_path("nope"), &r, &n, NULL, 0), AMFI_EINVAL);
}

static void test_header(void **state)
{
    (void)state;
    expect_error(write_text("h.csv", ""), 1, NULL, "empty file");
    expect_error(write_text("h.csv", HDR), 1, NULL, "no vehicles");
    expect_error(write_text("h.csv", HDR "\n\n"), 3, NULL, "no vehicles");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "spacing1_m,weather\n0,1,25,9000,4000,5000,4.5,sunny\n"),
                 1, "weather", "unknown column");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed,gvw_kg,axle1_kg,axle2_kg,"
                                     "spacing1_m\n"),
                 1, "speed", "unknown column");
    expect_error(write_text("h.csv", "0,1,25,9000,4000,5000,4.5\n"), 1, "0", "unknown column");
    expect_error(write_text("h.csv", "timestamp_s,lane,lane,speed_mps,gvw_kg,axle1_kg,"
                                     "axle2_kg,spacing1_m\n"),
                 1, "lane", "duplicate column");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "axle2_kg,spacing1_m\n"),
                 1, "axle2_kg", "duplicate column");
    expect_error(write_text("h.csv", "timestamp_s,lane,gvw_kg,axle1_kg,axle2_kg,spacing1_m\n"),
                 1, "speed_mps", "missing column");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle3_kg,"
                                     "spacing1_m,spacing2_m\n"),
                 1, NULL, "axle2_kg missing");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg\n"), 1,
                 "axle1_kg", "at least two axle columns");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,spacing1_m\n"), 1,
                 NULL, "at least two axle columns");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg\n"),
                 1, NULL, "spacing1_m missing: 2 axles need 1 spacings");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "axle3_kg,spacing1_m\n"),
                 1, NULL, "spacing2_m missing");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "spacing1_m,spacing2_m\n"),
                 1, NULL, "spacing2_m: 2 axles have 1 spacings");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "axle3_kg,spacing2_m\n"),
                 1, NULL, "spacing1_m missing");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "spacing1_m,axle01_kg\n"),
                 1, "axle01_kg", "unknown column");
    expect_error(write_text("h.csv", "timestamp_s,,lane\n"), 1, NULL, "column 2 has an empty name");
    expect_error(write_text("h.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,"
                                     "spacing1_m,spacing12_m\n"),
                 1, "spacing12_m", "at most 12 axles");
    char many[2048] = "timestamp_s";
    for (int i = 0; i < 40; i++)
        strcat(many, ",lane");
    strcat(many, "\n");
    expect_error(write_text("h.csv", many), 1, NULL, "41 columns, more than the 27 of a 12-axle vehicle");
}

static void test_rows(void **state)
{
    (void)state;
    expect_error(with_row(2, "20.5,1,25,9000,4000,5000"), 4, NULL, "6 fields, the header has 7");
    expect_error(with_row(2, "20.5,1,25,9000,4000,5000,4.5,1"), 4, NULL,
                 "8 fields, the header has 7");
    expect_error(with_row(0, "0,1,,9000,4000,5000,4.5"), 2, "speed_mps", "empty value");
    expect_error(with_row(0, "0,1,fast,9000,4000,5000,4.5"), 2, "speed_mps",
                 "'fast' is not a number");
    expect_error(with_row(0, "0,1,25 m/s,9000,4000,5000,4.5"), 2, "speed_mps",
                 "'25 m/s' is not a number");
    expect_error(with_row(1, "10.5,1,25,nan,4000,5000,4.5"), 3, "gvw_kg",
                 "'nan' is not a finite number");
    expect_error(with_row(1, "inf,1,25,9000,4000,5000,4.5"), 3, "timestamp_s",
                 "'inf' is not a finite number");
    expect_error(with_row(1, "10.5,1,25,1e999,4000,5000,4.5"), 3, "gvw_kg",
                 "not a finite number");
    expect_error(with_row(3, "30.5,0,25,9000,4000,5000,4.5"), 5, "lane", "0 is out of range 1 .. 8");
    expect_error(with_row(3, "30.5,9,25,9000,4000,5000,4.5"), 5, "lane", "9 is out of range 1 .. 8");
    expect_error(with_row(3, "30.5,1.5,25,9000,4000,5000,4.5"), 5, "lane", "'1.5' is not an integer");
    expect_error(with_row(3, "30.5,,25,9000,4000,5000,4.5"), 5, "lane", "empty value");
    expect_error(with_row(4, "40.5,1,0.5,9000,4000,5000,4.5"), 6, "speed_mps",
                 "0.5 is out of range [1, 60] m/s");
    expect_error(with_row(4, "40.5,1,61,9000,4000,5000,4.5"), 6, "speed_mps",
                 "61 is out of range [1, 60] m/s");
    expect_error(with_row(4, "40.5,1,25,400,200,200,4.5"), 6, "gvw_kg",
                 "400 is out of range [500, 100000] kg");
    expect_error(with_row(4, "40.5,1,25,100001,50000,50001,4.5"), 6, "gvw_kg",
                 "100001 is out of range [500, 100000] kg");
    expect_error(with_row(2, "20.5,1,25,9000,0,5000,4.5"), 4, "axle1_kg", "0 is out of range (0, 100000] kg");
    expect_error(with_row(2, "20.5,1,25,9000,4000,-5000,4.5"), 4, "axle2_kg",
                 "-5000 is out of range");
    expect_error(with_row(2, "20.5,1,25,9000,4000,5000,0.4"), 4, "spacing1_m",
                 "0.4 is out of range [0.5, 30] m");
    expect_error(with_row(2, "20.5,1,25,9000,4000,5000,31"), 4, "spacing1_m",
                 "31 is out of range [0.5, 30] m");
    /* GVW against the axle sum: both reported */
    expect_error(with_row(2, "20.5,1,25,9200,4000,5000,4.5"), 4, "gvw_kg",
                 "9200 kg differs by 2.22 % from the sum of the axle loads, 9000 kg (tolerance 1 %)");
    expect_error(with_row(2, "20.5,1,25,8900,4000,5000,4.5"), 4, "gvw_kg",
                 "from the sum of the axle loads, 9000 kg");
    /* timestamps */
    expect_error(with_row(3, "19.5,1,25,9000,4000,5000,4.5"), 5, "timestamp_s",
                 "19.5 is earlier than 20.5 on line 4 (timestamps must be non-decreasing)");
    char ok_equal[] = HDR "5,1,25,9000,4000,5000,4.5\n5,1,25,9000,4000,5000,4.5\n";
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    assert_int_equal(amfi_traffic_read(write_text("eq.csv", ok_equal), &r, &n, err, sizeof err), 0);
    assert_int_equal(n, 2);
    amfi_traffic_free(r);
    /* structure */
    expect_error(write_text("b.csv", HDR "0,1,25,9000,4000,5000,4.5\n\n"
                                         "1,1,25,9000,4000,5000,4.5\n"),
                 3, NULL, "blank line before the end of the data");
    const char nul[] = HDR "0,1,25,9000,4000,5000,4.5\n1,1,25,90\00000,4000,5000,4.5\n";
    expect_error(write_bytes("nul.csv", nul, sizeof nul - 1), 3, NULL, "NUL byte");
    size_t big = AMFI_TRAFFIC_MAX_LINE + 200;
    char *longline = malloc(big + sizeof HDR + 8);
    assert_non_null(longline);
    strcpy(longline, HDR);
    size_t k = strlen(longline);
    memset(longline + k, ' ', big);
    strcpy(longline + k + big, "\n");
    expect_error(write_text("long.csv", longline), 2, NULL, "longer than 4096 characters");
    /* exactly the limit is fine (a CR does not count) */
    const char *row = "0,1,25,9000,4000,5000,4.5";
    memset(longline + k, ' ', AMFI_TRAFFIC_MAX_LINE - strlen(row));
    strcpy(longline + k + AMFI_TRAFFIC_MAX_LINE - strlen(row), row);
    strcat(longline, "\r\n");
    assert_int_equal(amfi_traffic_read(write_text("long2.csv", longline), &r, &n, err, sizeof err),
                     0);
    assert_int_equal(n, 1);
    amfi_traffic_free(r);
    free(longline);
    /* the first error is the one reported */
    expect_error(write_text("two.csv", HDR "0,1,99,9000,4000,5000,4.5\n"
                                           "1,1,25,9000,4000,5000,99\n"),
                 2, "speed_mps", "99 is out of range");
}

/* Random junk: an error or a result, never a crash (ASan in CI). */
static void test_junk(void **state)
{
    (void)state;
    unsigned char buf[600];
    unsigned long x = 12345;
    for (int trial = 0; trial < 300; trial++) {
        size_t n = (size_t)(trial * 2) % sizeof buf;
        size_t h = strlen(HDR);
        memcpy(buf, HDR, h);
        for (size_t i = h; i < n + h && i < sizeof buf; i++) {
            x = x * 6364136223846793005UL + 1442695040888963407UL;
            const char pool[] = "0123456789.,-e\n \r";
            buf[i] = trial % 3 ? (unsigned char)pool[(x >> 33) % (sizeof pool - 1)]
                               : (unsigned char)(x >> 56);
        }
        size_t len = n + h < sizeof buf ? n + h : sizeof buf;
        const char *p = write_bytes("junk.csv", buf, len);
        amfi_vehicle_rec *r = NULL;
        int cnt = 0;
        if (amfi_traffic_read(p, &r, &cnt, err, sizeof err) == 0) {
            assert_true(cnt >= 1);
            amfi_traffic_free(r);
        } else {
            assert_null(r);
            assert_true(strncmp(err, p, strlen(p)) == 0);
        }
    }
}

/* ---- the shipped population -------------------------------------------- */

static void gvw_stats(const amfi_vehicle_rec *v, int n, double *mean, double *std)
{
    double s = 0.0, ss = 0.0;
    for (int i = 0; i < n; i++)
        s += v[i].gvw_kg;
    *mean = s / n;
    for (int i = 0; i < n; i++)
        ss += (v[i].gvw_kg - *mean) * (v[i].gvw_kg - *mean);
    *std = sqrt(ss / (n - 1));
}

/* docs/simulator-inputs.md: 5000 two-axle vehicles, seed 1; every batch of
 * 500 has a GVW mean in [8.1, 9.1] t and a STD in [1.7, 2.1] t (paper
 * Table 4 "Actual": 8.77 / 1.86 t and 9.06 / 1.94 t); every value inside
 * its documented truncation. */
static void test_population(void **state)
{
    (void)state;
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    const char *p = AMFI_SIM_DATA_DIR "/population.csv";
    if (amfi_traffic_read(p, &r, &n, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(n, 5000);
    double lo_share = 1, hi_share = 0, min_gap = 1e9;
    for (int i = 0; i < n; i++) {
        assert_int_equal(r[i].n_axles, 2);
        assert_int_equal(r[i].lane, 1);
        assert_true(r[i].gvw_kg >= 4000 && r[i].gvw_kg <= 15000);
        assert_true(r[i].gvw_kg == r[i].axle_kg[0] + r[i].axle_kg[1]);
        const double share = r[i].axle_kg[0] / r[i].gvw_kg;
        lo_share = fmin(lo_share, share), hi_share = fmax(hi_share, share);
        assert_true(r[i].spacing_m[0] >= 3.5 && r[i].spacing_m[0] <= 6.0);
        assert_true(r[i].speed_mps >= 18 && r[i].speed_mps <= 32);
        if (i)
            min_gap = fmin(min_gap, r[i].timestamp_s - r[i - 1].timestamp_s);
    }
    assert_true(lo_share >= 0.30 - 0.5 / 4000 && hi_share <= 0.65 + 0.5 / 4000);
    assert_true(min_gap >= 1.0 - 1e-3 - 1e-9); /* 1 s minimum headway, 1 ms rounding */
    double mean, std;
    gvw_stats(r, n, &mean, &std);
    print_message("population.csv: %d vehicles, GVW mean %.3f t, STD %.3f t, mean headway "
                  "%.2f s\n",
                  n, mean / 1000, std / 1000, (r[n - 1].timestamp_s - r[0].timestamp_s) / (n - 1));
    for (int b = 0; b < 10; b++) {
        gvw_stats(r + 500 * b, 500, &mean, &std);
        print_message("  batch %d: GVW mean %.3f t, STD %.3f t\n", b + 1, mean / 1000,
                      std / 1000);
        assert_true(mean >= 8100 && mean <= 9100);
        assert_true(std >= 1700 && std <= 2100);
    }
    amfi_traffic_free(r);
}

static int setup(void **state)
{
    (void)state;
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/traffic.XXXXXX", tmp && strlen(tmp) < 30 ? tmp : "/tmp");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* ---- the class format --------------------------------------------------- */

#define CHDR "timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,spacings_m\n"
#define CGOOD "1.0,1,25,A23,33000,5,7000;11000;5000;5000;5000,3.70;6.00;1.31;1.31\n"

static void test_class_format(void **state)
{
    (void)state;
    /* any column order, spaces around list items, different axle counts */
    const char *p = write_text("cls.csv", "class,n_axles, spacings_m ,axle_kg,timestamp_s,lane,"
                                          "speed_mps,gvw_kg\n"
                                          "R2,2,4.5,4000;5000,0,1,25,9000\n"
                                          "A33,6,3.3; 1.35 ;5.3;1.31;1.31,6000;9000;9000;"
                                          "6000;6000;6000,1,1,24,42000\n"
                                          "R4,4,1.9;3.4;1.35,7000;7000;9000;9000,2,2,22,32000\n");
    amfi_vehicle_rec *r = NULL;
    int n = 0;
    assert_int_equal(amfi_traffic_read(p, &r, &n, err, sizeof err), 0);
    assert_int_equal(n, 3);
    assert_int_equal(r[0].n_axles, 2);
    assert_string_equal(amfi_vclass_get(r[0].vclass)->name, "R2");
    assert_int_equal(r[1].n_axles, 6);
    assert_string_equal(amfi_vclass_get(r[1].vclass)->name, "A33");
    assert_true(r[1].spacing_m[1] == 1.35 && r[1].spacing_m[4] == 1.31 &&
                r[1].spacing_m[5] == 0.0);
    assert_true(r[1].axle_kg[5] == 6000 && r[1].axle_kg[6] == 0.0 && r[1].gvw_kg == 42000);
    assert_int_equal(r[2].n_axles, 4);
    assert_int_equal(r[2].line, 4);
    assert_int_equal(r[2].lane, 2);
    amfi_traffic_free(r);
    /* the wide format: a class guessed from the spacings, or none */
    p = write_text("wide.csv", "timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,axle3_kg,"
                               "spacing1_m,spacing2_m\n"
                               "0,1,25,20000,6000,7000,7000,4.6,1.35\n"
                               "1,1,25,20000,6000,7000,7000,4.0,4.0\n");
    assert_int_equal(amfi_traffic_read(p, &r, &n, err, sizeof err), 0);
    assert_string_equal(amfi_vclass_get(r[0].vclass)->name, "R3");
    assert_int_equal(r[1].vclass, -1);
    amfi_traffic_free(r);
    /* the shipped two-axle population: every record R2 */
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population.csv", &r, &n, err,
                                       sizeof err), 0);
    for (int i = 0; i < n; i++)
        assert_int_equal(r[i].vclass, 0);
    amfi_traffic_free(r);
    /* the shipped heavy traffic: every record of its class's layout */
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population-eu.csv", &r, &n, err,
                                       sizeof err), 0);
    assert_int_equal(n, 5000);
    int per[16] = {0};
    for (int i = 0; i < n; i++) {
        const amfi_vclass *c = amfi_vclass_get(r[i].vclass);
        assert_non_null(c);
        assert_int_equal(r[i].n_axles, c->n_axles);
        assert_true(r[i].gvw_kg <= c->gvw_hi);
        per[r[i].vclass]++;
    }
    for (int k = 0; k < amfi_vclass_count(); k++)
        assert_true(per[k] > 100);
    amfi_traffic_free(r);
}

/* Impossible vehicles: FILE:LINE: COLUMN: the reason. */
static void test_class_refused(void **state)
{
    (void)state;
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,X5,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "class", "'X5' is not a known class (R2, R3, R4, A22, A23, A32, A33)");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "class", "empty value");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,6,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "n_axles", "6, but class A23 has 5 axles");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,13,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "n_axles", "13 is out of range 2 .. 12");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31;1.31\n"),
                 3, "spacings_m", "more than 4 values for 5 axles");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31\n"),
                 3, "spacings_m", "3 values for 5 axles (4 expected)");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;10000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "4 values for 5 axles (5 expected)");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;;5000;10000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "value 3 is empty");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;x;5000;10000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "value 3, 'x', is not a finite number");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;nan;5000;5000;15000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "value 2, 'nan', is not a finite number");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;-5000;10000;10000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "value 3, -5000, is out of range (0, 30000] kg");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,73000,5,7000;11000;5000;5000;45000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "axle_kg", "value 5, 45000, is out of range");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;0.2;1.31;1.31\n"),
                 3, "spacings_m", "value 2, 0.2, is out of range [0.5, 30] m");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;3.50;1.31\n"),
                 3, "spacings_m", "spacing 3: 3.5 m between axles 3 and 4 of a group");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,33000,5,7000;11000;5000;5000;5000,"
                                     "1.70;6.00;1.31;1.31\n"),
                 3, "spacings_m", "spacing 1: 1.7 m between axles 1 and 2, which are in "
                                  "different groups");
    expect_error(write_text("c.csv", CHDR CGOOD "2,1,25,A23,39000,5,7000;11000;5000;5000;5000,"
                                     "3.70;6.00;1.31;1.31\n"),
                 3, "gvw_kg", "differs by");
    /* headers: the formats do not mix; the class format needs its four */
    expect_error(write_text("c.csv", "timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,"
                                     "spacings_m,axle1_kg\n" CGOOD),
                 1, NULL, "do not mix");
    expect_error(write_text("c.csv", "timestamp_s,lane,speed_mps,class,gvw_kg,axle_kg,"
                                     "spacings_m\n1,1,25,A23,33000,7000,3.7\n"),
                 1, "n_axles", "missing column");
    expect_error(write_text("c.csv", "timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,"
                                     "spacings_m,class\n"),
                 1, "class", "duplicate column");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good),
        cmocka_unit_test(test_good_variants),
        cmocka_unit_test(test_max_axles),
        cmocka_unit_test(test_cannot_open),
        cmocka_unit_test(test_header),
        cmocka_unit_test(test_rows),
        cmocka_unit_test(test_junk),
        cmocka_unit_test(test_population),
        cmocka_unit_test(test_class_format),
        cmocka_unit_test(test_class_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
