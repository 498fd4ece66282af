/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_daemon_reload_wait.c: a reload of daemon.max_wait_s reaches the
 * passage tracker (amfid.yaml(5): it "changes at once"). The whole daemon
 * (amfid_lib) on LCM's in-memory bus (memq://, no network): two sensors,
 * one of which never sends, and one vehicle. With max_wait_s 300 its window
 * waits for the silent sensor (30 s of data past its end are not enough);
 * after the configuration is rewritten with max_wait_s 2 and reloaded (the
 * SIGHUP path), the same data releases it at once, stored as "gap". Before
 * the fix the tracker kept the wait it was created with and the window
 * stayed pending. The same reload changes daemon.workers, a restart-only
 * key: reported by name (the key table's live flag), not applied.
 *
 * usage: test_daemon_reload_wait CONFIG (the shipped config/amfid.yaml)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amfi_accel_block_t.h"
#include "amfi_vehicle_t.h"
#include "amfid.h"

static char dir[] = "/tmp/amfid_reload_wait.XXXXXX";
static char cfg_path[300], db_path[300];

static void fail(const char *what)
{
    fprintf(stderr, "FAIL: %s\n", what);
    exit(1);
}

/* The shipped file with two sensors, the bus unauthenticated (memq:// is
 * this process's own) and the given max_wait_s and workers. */
static void write_config(const char *shipped, const char *max_wait, const char *workers)
{
    FILE *in = fopen(shipped, "r");
    char tmp[320];
    snprintf(tmp, sizeof tmp, "%s.tmp", cfg_path);
    FILE *out = fopen(tmp, "w");
    if (!in || !out)
        fail("cannot copy the configuration");
    char line[1024];
    int sensors = 0, auth = 0, wait = 0, work = 0;
    while (fgets(line, sizeof line, in)) {
        if (strncmp(line, "  - {id: 0, at_m: 10, weight: 1}", 32) == 0) {
            fputs("  - {id: 0, at_m: 10, weight: 1}\n  - {id: 1, at_m: 5, weight: 1}\n", out);
            sensors = 1;
        } else if (strncmp(line, "    auth: required", 18) == 0) {
            fputs("    auth: off\n", out);
            auth = 1;
        } else if (strncmp(line, "  max_wait_s: 10 ", 17) == 0) {
            fprintf(out, "  max_wait_s: %s\n", max_wait);
            wait = 1;
        } else if (strncmp(line, "  workers: 2 ", 13) == 0) {
            fprintf(out, "  workers: %s\n", workers);
            work = 1;
        } else {
            fputs(line, out);
        }
    }
    fclose(in);
    if (fclose(out) != 0 || !sensors || !auth || !wait || !work)
        fail("the shipped configuration lacks a line this test rewrites");
    if (rename(tmp, cfg_path) != 0)
        fail("rename");
}

static void publish(lcm_t *lcm, const char *ch, const void *buf, int len)
{
    if (len <= 0 || lcm_publish(lcm, ch, buf, (unsigned)len) != 0)
        fail("publish");
}

static const int64_t T0 = 1700000000000000LL; /* µs */

/* Sensor 0's samples from `from` to `to` s after T0, 1000 Hz, blocks of 100. */
static void accel(amfid *d, double from, double to)
{
    static double a[100];
    static unsigned char buf[4096];
    static int64_t seq;
    for (double t = from; t < to - 1e-9; t += 0.1) {
        amfi_accel_block_t m = {T0 + (int64_t)llround(t * 1e6), 0, ++seq, 1000.0, 100, a};
        int n = amfi_accel_block_t_encode(buf, 0, sizeof buf, &m);
        publish(amfid_lcm(d), amfid_config(d)->daemon.ch_accel, buf, n);
        amfid_turn(d); /* handled, windows released, results stored */
    }
}

static int64_t passages(amfid *d)
{
    int64_t n = -1;
    char err[256];
    if (amfi_store_count(amfid_store(d), AMFI_STORE_PASSAGES, &n, err, sizeof err))
        fail(err);
    return n;
}

int main(int argc, char **argv)
{
    if (argc != 2)
        fail("usage: test_daemon_reload_wait CONFIG");
    if (!mkdtemp(dir))
        fail("mkdtemp");
    snprintf(cfg_path, sizeof cfg_path, "%s/amfid.yaml", dir);
    snprintf(db_path, sizeof db_path, "%s/amfi.db", dir);
    write_config(argv[1], "300", "2");
    char log_path[320];
    snprintf(log_path, sizeof log_path, "%s/amfid.log", dir);
    amfid_log_stream = fopen(log_path, "w+");
    if (!amfid_log_stream)
        fail("the log file");
    amfid *d = NULL;
    amfid_options o = {.config = cfg_path, .db = db_path, .lcm_url = "memq://"};
    if (amfid_start(&d, &o) != 0)
        fail("amfid_start");
    accel(d, 0.0, 6.0);
    double sp[1] = {4.0};
    amfi_vehicle_t v = {T0 + 5000000, 1, 1, 20.0, 2, 1, sp, (char *)"", 0.0};
    unsigned char buf[512];
    publish(amfid_lcm(d), amfid_config(d)->daemon.ch_vehicle, buf,
            amfi_vehicle_t_encode(buf, 0, sizeof buf, &v));
    accel(d, 6.0, 40.0); /* 30 s of data past the window's end */
    amfid_stats st;
    amfid_counts(d, &st);
    if (passages(d) != 0 || st.vehicles_received != 1)
        fail("with max_wait_s 300 the window should still wait for sensor 1");
    write_config(argv[1], "2", "3");
    amfid_reload(d); /* the SIGHUP path */
    if (amfid_config(d)->daemon.max_wait_s != 2.0)
        fail("the reload did not apply max_wait_s");
    if (amfid_config(d)->daemon.workers != 2)
        fail("the reload applied daemon.workers, a restart-only key");
    fflush(amfid_log_stream);
    rewind(amfid_log_stream);
    char line[1024];
    int reported = 0;
    while (fgets(line, sizeof line, amfid_log_stream))
        reported |= strstr(line, "reload: daemon.workers changed; takes effect at the next "
                                 "start") != NULL;
    if (!reported)
        fail("the reload did not report daemon.workers by name");
    amfid_turn(d);
    int64_t n = passages(d);
    printf("test_daemon_reload_wait: %lld passage(s) stored after the reload\n", (long long)n);
    if (n != 1)
        fail("after the reload to max_wait_s 2 the window was not released: the tracker "
             "still waits with the old max_wait_s");
    int rc = amfid_drain(d);
    amfid_stop(d);
    fclose(amfid_log_stream);
    amfid_log_stream = NULL;
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fail("rm");
    if (rc != 0)
        fail("amfid_drain");
    puts("ok");
    return 0;
}
