/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_intake_forge: copy an LCM log of sim_publisher's, splicing in the messages
 * that once stopped amfid from weighing (a misbehaving or misconfigured
 * instrument would send the same), for tests/daemon/daemon_intake.sh:
 *
 *   lcm_intake_forge MODE IN.log OUT.log
 *
 *   rate       before the first message: one accel block of sensor 0 at
 *              999 Hz (12 samples, 1 s before the stream); it once fixed
 *              the sensor's rate and turned every passage into gap
 *   future     before the first message: 256 vehicle_t dated in 2286, 100 s apart
 *              (ids 800000 ..), and one more after the first vehicle (801000);
 *              they once filled the tracker and made every real vehicle invalid
 *   slow       after the first vehicle: one vehicle_t at 1 m/s entering
 *              0.5 s after it (id 810000); it once made the real passages
 *              around it multiple
 *   flood      after the first vehicle: 3000 vehicle_t with speed −3 m/s
 *              (ids 820000 ..); each was once one fsync'd row
 *   environment  every 20 s of data time from the first accel block: a
 *              reading at 10 °C, and 10 s later a forged one at 35 °C; and,
 *              after the first vehicle, 2000 readings within one second of
 *              data time (12 °C): the temperature compensation once took
 *              them all, one row each
 *   reference  every vehicle_t with a calibration truck's reference GVW of
 *              14 829 kg: odd ids from source "rogue-detector", even ids
 *              from sim_publisher but 90 000 kg; once taken as references
 *
 * Prints nothing; exits 0, or 1 with a message.
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

static int64_t num;

/* Every event signed with the test key (test_bus_sign.h): a misbehaving
 * instrument of the site's own holds the key; the bounds are the intake's. */
static int put(lcm_eventlog_t *out, int64_t ts, const char *ch, const void *data, int len)
{
    return test_put(out, &num, ts, ch, data, len);
}

static int put_vehicle(lcm_eventlog_t *out, int64_t ts, int64_t utime, int64_t id, double speed,
                       const char *source, double ref)
{
    double spacing = 4.0;
    amfi_vehicle_t v = {utime, id, 1, speed, 2, 1, &spacing, (char *)source, ref};
    unsigned char buf[256];
    int n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &v);
    return n < 0 || put(out, ts, AMFI_CHANNEL_VEHICLE, buf, n);
}

static int put_env(lcm_eventlog_t *out, int64_t ts, int64_t utime, double deck)
{
    amfi_environment_t m = {utime, deck - 2.0, deck};
    unsigned char b[64];
    int n = amfi_environment_t_encode(b, 0, sizeof b, &m);
    return n < 0 || put(out, ts, AMFI_CHANNEL_ENVIRONMENT, b, n);
}

/* The data time of the first accel block in IN (−1 none). */
static int64_t first_accel(const char *inp)
{
    lcm_eventlog_t *in = lcm_eventlog_create(inp, "r");
    lcm_eventlog_event_t *e;
    int64_t u = -1;
    while (in && u < 0 && (e = lcm_eventlog_read_next_event(in)) != NULL) {
        amfi_accel_block_t m;
        if (strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0 &&
            amfi_accel_block_t_decode(e->data, 0, e->datalen, &m) >= 0) {
            u = m.utime;
            amfi_accel_block_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(e);
    }
    if (in)
        lcm_eventlog_destroy(in);
    return u;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: lcm_intake_forge rate|future|slow|flood|environment|reference IN OUT\n");
        return 2;
    }
    const char *mode = argv[1];
    if (test_sign_init("test.intake"))
        return 1;
    const int64_t t0 = first_accel(argv[2]);
    if (t0 < 0) {
        fprintf(stderr, "lcm_intake_forge: no accel_block_t in %s\n", argv[2]);
        return 1;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[2], "r");
    lcm_eventlog_t *out = lcm_eventlog_create(argv[3], "w");
    if (!in || !out) {
        fprintf(stderr, "lcm_intake_forge: cannot open the logs\n");
        return 1;
    }
    lcm_eventlog_event_t *e;
    int rc = 0, first = 1, vehicles = 0;
    int64_t next_env = t0; /* environment: the next real reading's data time */
    while (rc == 0 && (e = lcm_eventlog_read_next_event(in)) != NULL) {
        const int64_t ts = e->timestamp;
        if (first && strcmp(mode, "rate") == 0) {
            double x[12] = {0};
            amfi_accel_block_t b = {t0 - 1000000, 0, 0, 999.0, 12, x};
            unsigned char buf[512];
            int n = amfi_accel_block_t_encode(buf, 0, sizeof buf, &b);
            rc |= n < 0 || put(out, ts, AMFI_CHANNEL_ACCEL, buf, n);
        }
        if (first && strcmp(mode, "future") == 0)
            for (int i = 0; i < 256; i++) /* 2286-11-20 */
                rc |= put_vehicle(out, ts, INT64_C(10000000000000000) + i * INT64_C(100000000),
                                  800000 + i, 20.0, "sim_publisher", 0.0);
        first = 0;
        amfi_vehicle_t v;
        const int is_vehicle = strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0 &&
                               amfi_vehicle_t_decode(e->data, 0, e->datalen, &v) >= 0;
        if (is_vehicle && strcmp(mode, "reference") == 0) {
            const int odd = v.vehicle_id % 2 != 0;
            char *src = v.source;
            v.source = odd ? "rogue-detector" : "sim_publisher";
            v.reference_gvw_kg = odd ? 14829.0 : 90000.0;
            unsigned char buf[512];
            int n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &v);
            v.source = src;
            rc |= n < 0 || put(out, ts, e->channel, buf, n);
        } else {
            rc |= put(out, ts, e->channel, e->data, e->datalen);
        }
        if (strcmp(mode, "environment") == 0 && strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0) {
            amfi_accel_block_t a;
            if (amfi_accel_block_t_decode(e->data, 0, e->datalen, &a) >= 0) {
                if (a.utime >= next_env) {
                    rc |= put_env(out, ts, next_env, 10.0);
                    next_env += INT64_C(20000000);
                } else if (a.utime >= next_env - INT64_C(10000000) &&
                           a.utime < next_env - INT64_C(9900000)) {
                    rc |= put_env(out, ts, a.utime, 35.0);
                }
                amfi_accel_block_t_decode_cleanup(&a);
            }
        }
        if (is_vehicle) {
            if (vehicles++ == 0) {
                if (strcmp(mode, "future") == 0) /* and one once the data flow */
                    rc |= put_vehicle(out, ts, INT64_C(10000000000000000), 801000, 20.0,
                                      "sim_publisher", 0.0);
                if (strcmp(mode, "slow") == 0)
                    rc |= put_vehicle(out, ts, v.utime + 500000, 810000, 1.0, "sim_publisher",
                                      0.0);
                if (strcmp(mode, "flood") == 0)
                    for (int i = 0; i < 3000; i++)
                        rc |= put_vehicle(out, ts, v.utime, 820000 + i, -3.0, "sim_publisher",
                                          0.0);
                if (strcmp(mode, "environment") == 0)
                    for (int i = 0; i < 2000; i++)
                        rc |= put_env(out, ts, v.utime - 1000000 + i * 500, 12.0);
            }
            amfi_vehicle_t_decode_cleanup(&v);
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc)
        fprintf(stderr, "lcm_intake_forge: write failed\n");
    return rc ? 1 : 0;
}
