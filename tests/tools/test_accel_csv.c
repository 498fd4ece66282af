/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_accel_csv.c: the passage CSV reader (tools/accel_csv.c) on good
 * files, plain and gzip, and on every kind of bad input it must reject with
 * a "FILE:LINE: problem" message; plus random junk that must never crash.
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

#include <zlib.h>

#include "accel_csv.h"

static char dir[64];
static char path[256];
static char err[512];

static const char *file_path(const char *name)
{
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return path;
}

static const char *write_file(const char *name, const void *data, size_t n)
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
    return write_file(name, text, strlen(text));
}

/* "t,accel\n" and `rows` rows at 1000 Hz, accel = k/100. */
static char *make_csv(int rows)
{
    size_t cap = 16 + (size_t)rows * 40;
    char *s = malloc(cap);
    assert_non_null(s);
    size_t n = (size_t)snprintf(s, cap, "t,accel\n");
    for (int k = 0; k < rows; k++)
        n += (size_t)snprintf(s + n, cap - n, "%.6f,%.4f\n", k * 1e-3,
                              k / 100.0);
    return s;
}

static const char *write_gz(const char *name, const char *text)
{
    const char *p = file_path(name);
    gzFile g = gzopen(p, "wb");
    assert_non_null(g);
    assert_int_equal(gzwrite(g, text, (unsigned)strlen(text)),
                     (int)strlen(text));
    assert_int_equal(gzclose(g), Z_OK);
    return p;
}

static long file_size(const char *p)
{
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

/* The read must fail with "PATH:LINE: ..." containing `what`. */
static void expect_error(const char *p, long line, const char *what)
{
    accel_csv c;
    int rc = accel_csv_read(p, &c, err, sizeof err);
    if (rc == 0)
        fail_msg("%s: accepted, expected line %ld: %s", p, line, what);
    assert_int_equal(rc, -1);
    assert_null(c.accel);
    assert_int_equal(c.n, 0);
    char prefix[300];
    if (line > 0)
        snprintf(prefix, sizeof prefix, "%s:%ld: ", p, line);
    else
        snprintf(prefix, sizeof prefix, "%s: ", p);
    if (strncmp(err, prefix, strlen(prefix)) != 0 || !strstr(err, what))
        fail_msg("got '%s', expected '%s...%s'", err, prefix, what);
    assert_null(strchr(err, '\n'));
}

/* a good file with 16+ rows, except that row `bad_row` (0-based) is `row`;
 * the bad row is at line bad_row + 2 */
static const char *csv_with_row(const char *name, int bad_row, const char *row)
{
    char text[8192];
    size_t n = (size_t)snprintf(text, sizeof text, "t,accel\n");
    for (int k = 0; k < 20; k++) {
        if (k == bad_row)
            n += (size_t)snprintf(text + n, sizeof text - n, "%s\n", row);
        else
            n += (size_t)snprintf(text + n, sizeof text - n, "%.3f,0.5\n",
                                  k * 1e-3);
    }
    return write_text(name, text);
}

/* ---- good files --------------------------------------------------------- */

static void test_good_plain(void **state)
{
    (void)state;
    char *s = make_csv(100);
    const char *p = write_text("good.csv", s);
    free(s);
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 100);
    assert_true(fabs(c.t0_s) < 1e-15);
    assert_true(fabs(c.rate_hz - 1000.0) < 1e-9);
    for (int k = 0; k < 100; k++)
        assert_true(fabs(c.accel[k] - k / 100.0) < 1e-12);
    accel_csv_free(&c);
    assert_null(c.accel);
    accel_csv_free(&c); /* idempotent */
    accel_csv_free(NULL);
}

/* BOM, CRLF, spaces and tabs around everything, trailing blank lines,
 * negative and exponent numbers, t not starting at 0, no final newline */
static void test_good_variants(void **state)
{
    (void)state;
    char text[4096];
    size_t n = (size_t)snprintf(text, sizeof text,
                                "\xEF\xBB\xBF  t , accel \r\n");
    for (int k = 0; k < 20; k++)
        n += (size_t)snprintf(text + n, sizeof text - n,
                              "\t%.4f ,  %.3e \r\n", 12.5 + k * 2e-4,
                              -1.5e-3 * k);
    n += (size_t)snprintf(text + n, sizeof text - n, "\r\n  \n\t");
    const char *p = write_text("variants.csv", text);
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 20);
    assert_true(fabs(c.t0_s - 12.5) < 1e-12);
    assert_true(fabs(c.rate_hz - 5000.0) < 1e-6);
    assert_true(fabs(c.accel[19] - (-1.5e-3 * 19)) < 1e-6);
    accel_csv_free(&c);
}

static void test_good_gz(void **state)
{
    (void)state;
    char *s = make_csv(20000);
    const char *p = write_gz("good.csv.gz", s);
    free(s);
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 20000);
    assert_true(fabs(c.rate_hz - 1000.0) < 1e-6);
    assert_true(fabs(c.accel[19999] - 199.99) < 1e-9);
    accel_csv_free(&c);
}

/* exactly ACCEL_CSV_MAX_LINE characters (plus CRLF) is allowed */
static void test_longest_line(void **state)
{
    (void)state;
    char *text = malloc(64 * 1024);
    assert_non_null(text);
    size_t n = (size_t)sprintf(text, "t,accel\n");
    for (int k = 0; k < 20; k++) {
        int w = sprintf(text + n, "%.3f,0.5", k * 1e-3);
        if (k == 3) {
            memset(text + n + w, ' ', ACCEL_CSV_MAX_LINE - (size_t)w);
            w = ACCEL_CSV_MAX_LINE;
        }
        n += (size_t)w;
        n += (size_t)sprintf(text + n, "\r\n");
    }
    const char *p = write_file("longest.csv", text, n);
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 20);
    accel_csv_free(&c);
    /* one more character is an error, at line 5 */
    n = (size_t)sprintf(text, "t,accel\n");
    for (int k = 0; k < 20; k++) {
        int w = sprintf(text + n, "%.3f,0.5", k * 1e-3);
        if (k == 3) {
            memset(text + n + w, ' ', ACCEL_CSV_MAX_LINE + 1 - (size_t)w);
            w = ACCEL_CSV_MAX_LINE + 1;
        }
        n += (size_t)w;
        n += (size_t)sprintf(text + n, "\r\n");
    }
    p = write_file("toolong1.csv", text, n);
    expect_error(p, 5, "line longer than 4096");
    free(text);
}

/* ---- bad files ---------------------------------------------------------- */

static void test_cannot_open(void **state)
{
    (void)state;
    expect_error(file_path("does-not-exist.csv"), 0, "cannot open");
    expect_error(dir, 1, "read error"); /* a directory */
}

static void test_header(void **state)
{
    (void)state;
    expect_error(write_text("empty.csv", ""), 1, "empty file");
    expect_error(write_text("bad-header.csv", "time,accel\n0,1\n"), 1,
                 "bad header");
    expect_error(write_text("bad-header2.csv", "t,accel,x\n0,1\n"), 1,
                 "bad header");
    expect_error(write_text("bad-header3.csv", "t\n0\n"), 1, "bad header");
    expect_error(write_text("no-header.csv", "0,1\n0.001,2\n"), 1,
                 "missing header");
}

/* Several sensors: 't,accel_ID,...', a column per sensor id, in the
 * file's order; each id once, 0 .. 255 written plainly, at most
 * ACCEL_CSV_MAX_CHANNELS columns, every row with all of them. */
static void test_channels(void **state)
{
    (void)state;
    char text[8192];
    size_t n = (size_t)snprintf(text, sizeof text, "\xEF\xBB\xBFt, accel_7 ,accel_0,accel_255\r\n");
    for (int k = 0; k < 20; k++)
        n += (size_t)snprintf(text + n, sizeof text - n, "%.3f,%d,%d.5,-%d\r\n", k * 1e-3, k,
                              2 * k, 3 * k);
    const char *p = write_text("three.csv", text);
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 20);
    assert_int_equal(c.n_channels, 3);
    assert_int_equal(c.channel_id[0], 7);
    assert_int_equal(c.channel_id[1], 0);
    assert_int_equal(c.channel_id[2], 255);
    assert_true(c.accel == c.channel[0]);
    for (int k = 0; k < 20; k++) {
        assert_true(c.channel[0][k] == k);
        assert_true(c.channel[1][k] == 2 * k + 0.5);
        assert_true(c.channel[2][k] == -3 * k);
    }
    accel_csv_free(&c);
    assert_int_equal(c.n_channels, 0);
    /* the one-sensor format: one channel without an id */
    char *one = make_csv(20);
    assert_int_equal(accel_csv_read(write_text("one.csv", one), &c, err, sizeof err), 0);
    free(one);
    assert_int_equal(c.n_channels, 1);
    assert_int_equal(c.channel_id[0], -1);
    accel_csv_free(&c);

    expect_error(write_text("dup.csv", "t,accel_3,accel_4,accel_3\n0,1,2,3\n"), 1,
                 "column 4 repeats sensor 3 (column 2)");
    static const char *const bad[] = {"accel_01", "accel_256", "accel_x", "accel_", "accel_-1",
                                      "accel_+1", "Accel_1", "accel_1000"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        snprintf(text, sizeof text, "t,accel_1,%s\n0,1,2\n", bad[k]);
        char name[64], what[64];
        snprintf(name, sizeof name, "badid%zu.csv", k);
        snprintf(what, sizeof what, "column 3 '%s' is not accel_ID", bad[k]);
        expect_error(write_text(name, text), 1, what);
    }
    /* 'accel' beside named columns */
    expect_error(write_text("mixed.csv", "t,accel_1,accel\n0,1,2\n"), 1, "column 3 'accel'");
    expect_error(write_text("nine.csv", "t,accel_1,accel_2,accel_3,accel_4,accel_5,accel_6,"
                                        "accel_7,accel_8,accel_9\n"),
                 1, "9 accel columns: at most 8");
    /* a row without one of the columns, or a bad value in one, names it */
    n = (size_t)snprintf(text, sizeof text, "t,accel_1,accel_2\n");
    for (int k = 0; k < 20; k++)
        n += (size_t)snprintf(text + n, sizeof text - n, k == 4 ? "%.3f,1\n" : "%.3f,1,2\n",
                              k * 1e-3);
    expect_error(write_text("short-row.csv", text), 6, "expected 3 fields");
    n = (size_t)snprintf(text, sizeof text, "t,accel_1,accel_2\n");
    for (int k = 0; k < 20; k++)
        n += (size_t)snprintf(text + n, sizeof text - n, k == 4 ? "%.3f,1,x\n" : "%.3f,1,2\n",
                              k * 1e-3);
    expect_error(write_text("bad-value.csv", text), 6, "accel_2");
}

static void test_columns(void **state)
{
    (void)state;
    expect_error(csv_with_row("missing.csv", 3, "0.003"), 5,
                 "missing column");
    expect_error(csv_with_row("extra.csv", 3, "0.003,0.5,7"), 5,
                 "extra column");
    expect_error(csv_with_row("extra2.csv", 3, "0.003,0.5,"), 5,
                 "extra column");
    expect_error(csv_with_row("empty-t.csv", 3, " ,0.5"), 5,
                 "empty field 't'");
    expect_error(csv_with_row("empty-a.csv", 3, "0.003,"), 5,
                 "empty field 'accel'");
}

static void test_numbers(void **state)
{
    (void)state;
    expect_error(csv_with_row("text.csv", 4, "0.004,abc"), 6,
                 "accel: not a number: 'abc'");
    expect_error(csv_with_row("garbage.csv", 4, "0.004,1.5x"), 6,
                 "not a number: '1.5x'");
    expect_error(csv_with_row("garbage2.csv", 4, "0.004,1.5 2"), 6,
                 "not a number");
    expect_error(csv_with_row("ttext.csv", 4, "0.00a4,1"), 6,
                 "t: not a number");
    expect_error(csv_with_row("nan.csv", 4, "0.004,nan"), 6, "NaN");
    expect_error(csv_with_row("tnan.csv", 4, "NAN,1"), 6, "t: NaN");
    expect_error(csv_with_row("inf.csv", 4, "0.004,-inf"), 6, "infinite");
    expect_error(csv_with_row("inf2.csv", 4, "0.004,Infinity"), 6,
                 "infinite");
    expect_error(csv_with_row("overflow.csv", 4, "0.004,1e999"), 6,
                 "infinite");
}

static void test_nul_byte(void **state)
{
    (void)state;
    static const char text[] = "t,accel\n0,1\n0.001,1\0002\n";
    expect_error(write_file("nul.csv", text, sizeof text - 1), 3, "NUL byte");
}

static void test_time(void **state)
{
    (void)state;
    expect_error(csv_with_row("equal.csv", 6, "0.005,1"), 8,
                 "not increasing");
    expect_error(csv_with_row("decr.csv", 6, "0.001,1"), 8,
                 "not increasing");
    /* 0.0061 instead of 0.006: steps 1.1 ms and 0.9 ms */
    expect_error(csv_with_row("nonuni.csv", 6, "0.0061,1"), 8,
                 "non-uniform");
    /* just inside the tolerance (1e-6·1e-3 + 1e-9 = 2e-9 s) */
    const char *p = csv_with_row("nearly.csv", 6, "0.0060000015,1");
    accel_csv c;
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), 0);
    accel_csv_free(&c);
    /* just outside */
    expect_error(csv_with_row("nonuni2.csv", 6, "0.0060000030,1"), 8,
                 "non-uniform");
}

static void test_blank_line(void **state)
{
    (void)state;
    expect_error(csv_with_row("blank.csv", 6, "  "), 8, "empty line");
}

static void test_too_few(void **state)
{
    (void)state;
    char *s = make_csv(15);
    expect_error(write_text("few.csv", s), 16, "too few samples: 15");
    free(s);
    expect_error(write_text("none.csv", "t,accel\n"), 1,
                 "too few samples: 0");
    s = make_csv(16);
    accel_csv c;
    assert_int_equal(accel_csv_read(write_text("sixteen.csv", s), &c, err,
                                    sizeof err), 0);
    assert_int_equal(c.n, 16);
    accel_csv_free(&c);
    free(s);
}

static void test_too_long(void **state)
{
    (void)state;
    char *text = malloc(20000);
    assert_non_null(text);
    size_t n = (size_t)sprintf(text, "t,accel\n0,1\n0.001,1\n");
    memset(text + n, '1', 10000);
    n += 10000;
    n += (size_t)sprintf(text + n, ",2\n");
    expect_error(write_file("long.csv", text, n), 4, "line longer than 4096");
    /* a long line at the end of the file, no newline */
    n -= 3;
    expect_error(write_file("long2.csv", text, n), 4, "line longer");
    free(text);
}

static void test_too_many_rows(void **state)
{
    (void)state;
    char *s = make_csv(30);
    const char *p = write_text("many.csv", s);
    free(s);
    accel_csv c;
    assert_int_equal(accel_csv_read_max(p, 20, &c, err, sizeof err), -1);
    char want[300];
    snprintf(want, sizeof want, "%s:22: more than 20 rows", p);
    assert_string_equal(err, want);
    assert_null(c.accel);
    assert_int_equal(accel_csv_read_max(p, 30, &c, err, sizeof err), 0);
    assert_int_equal(c.n, 30);
    accel_csv_free(&c);
}

static void test_gzip_errors(void **state)
{
    (void)state;
    /* random bytes named .gz */
    unsigned char junk[3000];
    srand(7);
    for (size_t k = 0; k < sizeof junk; k++)
        junk[k] = (unsigned char)(rand() & 0xff);
    junk[0] = 'x';
    expect_error(write_file("junk.csv.gz", junk, sizeof junk), 1,
                 "not in gzip format");
    /* a gzip header followed by junk */
    junk[0] = 0x1f;
    junk[1] = 0x8b;
    junk[2] = 8;
    junk[3] = 0;
    expect_error(write_file("junk2.csv.gz", junk, sizeof junk), 1,
                 "gzip");

    /* a real file, truncated: in the middle and just before the trailer */
    char *s = make_csv(20000);
    const char *p = write_gz("whole.csv.gz", s);
    free(s);
    long size = file_size(p);
    unsigned char *gz = malloc((size_t)size);
    assert_non_null(gz);
    FILE *f = fopen(p, "rb");
    assert_int_equal(fread(gz, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    accel_csv c;
    const char *cut[] = {"half.csv.gz", "trailer.csv.gz", "crc.csv.gz",
                         "one.csv.gz"};
    const long cut_len[] = {size / 2, size - 4, size - 7, 11};
    for (int i = 0; i < 4; i++) {
        p = write_file(cut[i], gz, (size_t)cut_len[i]);
        assert_int_equal(accel_csv_read(p, &c, err, sizeof err), -1);
        assert_null(c.accel);
        assert_non_null(strstr(err, "truncated gzip"));
        assert_int_equal(strncmp(err, p, strlen(p)), 0);
        assert_true(err[strlen(p)] == ':');
    }
    /* a flipped byte inside the compressed data, and a wrong CRC */
    gz[size / 2] ^= 0x55;
    p = write_file("flipped.csv.gz", gz, (size_t)size);
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), -1);
    assert_non_null(strstr(err, p));
    gz[size / 2] ^= 0x55;
    gz[size - 6] ^= 0x01; /* CRC-32 */
    p = write_file("badcrc.csv.gz", gz, (size_t)size);
    assert_int_equal(accel_csv_read(p, &c, err, sizeof err), -1);
    assert_non_null(strstr(err, "corrupt gzip data"));
    free(gz);
}

/* random junk, random mutations of a good file: any result, never a crash
 * (this test is meant to run under ASan/UBSan) */
static void test_junk(void **state)
{
    (void)state;
    char *good = make_csv(40);
    size_t good_n = strlen(good);
    unsigned char buf[8192];
    srand(12345);
    for (int iter = 0; iter < 400; iter++) {
        size_t n;
        if (iter % 2) {
            n = (size_t)(rand() % (int)sizeof buf);
            for (size_t k = 0; k < n; k++)
                buf[k] = (unsigned char)(rand() & 0xff);
        } else {
            n = good_n;
            memcpy(buf, good, n);
            for (int m = 0; m < 1 + rand() % 4; m++)
                buf[(size_t)rand() % n] = (unsigned char)(rand() & 0xff);
        }
        const char *p = write_file(iter % 3 ? "junk.csv" : "junk.gz", buf, n);
        accel_csv c;
        err[0] = '\0';
        int rc = accel_csv_read(p, &c, err, sizeof err);
        assert_true(rc == 0 || rc == -1);
        if (rc == 0) {
            assert_true(c.n >= ACCEL_CSV_MIN_ROWS);
            assert_true(c.rate_hz > 0);
        } else {
            assert_int_equal(strncmp(err, p, strlen(p)), 0);
            assert_null(strchr(err, '\n'));
        }
        accel_csv_free(&c);
    }
    free(good);
    /* a tiny error buffer truncates, NULL with 0 is allowed */
    accel_csv c;
    char small[8];
    assert_int_equal(accel_csv_read(file_path("nope"), &c, small,
                                    sizeof small), -1);
    assert_true(strlen(small) == sizeof small - 1);
    assert_int_equal(accel_csv_read(file_path("nope"), &c, NULL, 0), -1);
}

static int setup(void **state)
{
    (void)state;
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/accel_csv.XXXXXX",
             tmp && strlen(tmp) < 30 ? tmp : "/tmp");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_plain),
        cmocka_unit_test(test_good_variants),
        cmocka_unit_test(test_good_gz),
        cmocka_unit_test(test_longest_line),
        cmocka_unit_test(test_cannot_open),
        cmocka_unit_test(test_header),
        cmocka_unit_test(test_channels),
        cmocka_unit_test(test_columns),
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_nul_byte),
        cmocka_unit_test(test_time),
        cmocka_unit_test(test_blank_line),
        cmocka_unit_test(test_too_few),
        cmocka_unit_test(test_too_long),
        cmocka_unit_test(test_too_many_rows),
        cmocka_unit_test(test_gzip_errors),
        cmocka_unit_test(test_junk),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
