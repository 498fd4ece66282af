/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_inject: copy an LCM log, splicing in the bad input a site's bus can
 * carry, for amfid's bad-input test (tests/daemon/daemon_bad_input.sh):
 *   after the 50th AMFI_ACCEL event: the same event again (duplicate), its
 *   first half (truncated), 40 random bytes on AMFI_ACCEL, AMFI_VEHICLE and
 *   AMFI_TRUTH, a well-formed vehicle_t with speed −3 m/s, one with five
 *   axles and two spacings, one with 7 axles, an accel block
 *   from sensor 99; the 60th and 61st accel events swapped (out of order).
 *
 *   lcm_inject IN.log OUT.log
 *
 * With --vehicles-only, OUT.log gets IN.log's AMFI_VEHICLE events and
 * nothing else: vehicles whose sensor data never comes (a DAQ that is down;
 * fuzz_intake found amfid crashing on it at shutdown).
 *
 *   lcm_inject --vehicles-only IN.log OUT.log
 *
 * With --scale-accel F, every accel sample is multiplied by F (kept within
 * the intake's ±1000 m/s²): a solver result beyond the store's ranges
 * (fuzz_intake found amfid holding such a passage as if the store had
 * failed, blocking every passage behind it).
 *
 *   lcm_inject --scale-accel F IN.log OUT.log
 *
 * With --scale-spacing F, every vehicle_t's axle spacings are multiplied by
 * F: a detector record the samples do not match, whose solve may split the
 * weight into a negative axle (a load the classification refuses).
 *
 *   lcm_inject --scale-spacing F IN.log OUT.log
 *
 * With --bad-environment, OUT.log gets only environment_t messages after
 * IN.log's last one (tests/daemon/daemon_environment.sh): 40 random bytes
 * (malformed), a reading with deck_c NaN, one with air_c 95 °C, one dated 10
 * days after the stream, then one good reading 1 s after IN.log's last.
 *
 *   lcm_inject --bad-environment IN.log OUT.log
 *
 * With --bad-reference, OUT.log gets only two vehicle_t after IN.log's last
 * one (tests/daemon/daemon_scale.sh), well formed but for their reference GVW (a
 * calibration truck's): 500 kg (ids 434343) and +infinity (434344).
 *
 *   lcm_inject --bad-reference IN.log OUT.log
 *
 * With --twin-lanes, every vehicle_t of IN.log is followed by its twin on
 * the other lane (lane 1 <-> 2, vehicle id + 1000000), same entry time,
 * speed and spacings: two vehicles side by side whose axles coincide all
 * along, carrying together the one vehicle the samples hold
 * (tests/daemon/daemon_bad_input.sh).
 *
 *   lcm_inject --twin-lanes IN.log OUT.log
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

/* Every event signed with the test key (test_bus_sign.h). */
#define put test_put

/* Open IN for reading and OUT for writing: 0, or 1 (reported, both closed). */
static int open_logs(const char *inp, const char *outp, lcm_eventlog_t **in,
                     lcm_eventlog_t **out)
{
    *in = lcm_eventlog_create(inp, "r");
    *out = lcm_eventlog_create(outp, "w");
    if (*in && *out)
        return 0;
    fprintf(stderr, "lcm_inject: cannot open the logs\n");
    if (*in)
        lcm_eventlog_destroy(*in);
    if (*out)
        lcm_eventlog_destroy(*out);
    return 1;
}

/* One event of a rewrite: writes what replaces e in out (nothing, e, a
 * changed copy, or more) with the factor f; counts the vehicles it handled in
 * *n. Returns 0, or non-zero when a write failed. */
typedef int (*rewrite_fn)(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                          double f, int *n);

/* IN to OUT, each event through fn: 0, or 1 (reported) when a write failed
 * or, with need_vehicle, no vehicle was handled. */
static int rewrite(const char *inp, const char *outp, rewrite_fn fn, double f, int need_vehicle)
{
    lcm_eventlog_t *in, *out;
    if (open_logs(inp, outp, &in, &out))
        return 1;
    lcm_eventlog_event_t *e;
    int64_t num = 0;
    int rc = 0, n = 0;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        rc |= fn(out, &num, e, f, &n);
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc || (need_vehicle && n == 0)) {
        fprintf(stderr, "lcm_inject: %s\n", rc ? "write failed" : "no vehicle in the log");
        return 1;
    }
    return 0;
}

static int put_same(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e)
{
    return put(out, num, e->timestamp, e->channel, e->data, e->datalen);
}

/* A decoded vehicle_t, encoded again and written. */
static int put_vehicle(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                       const amfi_vehicle_t *m)
{
    unsigned char b[4096];
    int len = amfi_vehicle_t_encode(b, 0, sizeof b, m);
    return len < 0 || put(out, num, e->timestamp, e->channel, b, len);
}

/* The vehicle_t events only. */
static int ev_vehicles_only(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                            double f, int *n)
{
    (void)f;
    if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) != 0)
        return 0;
    (*n)++;
    return put_same(out, num, e);
}

/* Every event; after each vehicle_t its twin on the other lane. */
static int ev_twin_lanes(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                         double f, int *n)
{
    (void)f;
    int rc = put_same(out, num, e);
    amfi_vehicle_t m;
    if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0 &&
        amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) >= 0) {
        m.vehicle_id += 1000000;
        m.lane = m.lane == 1 ? 2 : 1;
        rc |= put_vehicle(out, num, e, &m);
        amfi_vehicle_t_decode_cleanup(&m);
        (*n)++;
    }
    return rc;
}

/* Every vehicle_t's axle spacings multiplied by f: a detector record the
 * samples do not match. */
static int ev_scale_spacing(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                            double f, int *n)
{
    amfi_vehicle_t m;
    if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) != 0 ||
        amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0)
        return put_same(out, num, e);
    for (int k = 0; k < m.n_spacings; k++)
        m.axle_spacing_m[k] *= f;
    int rc = put_vehicle(out, num, e, &m);
    amfi_vehicle_t_decode_cleanup(&m);
    (*n)++;
    return rc;
}

/* Every sample multiplied by f, held within ±999. */
static int ev_scale_accel(lcm_eventlog_t *out, int64_t *num, const lcm_eventlog_event_t *e,
                          double f, int *n)
{
    (void)n;
    amfi_accel_block_t m;
    if (strcmp(e->channel, AMFI_CHANNEL_ACCEL) != 0 ||
        amfi_accel_block_t_decode(e->data, 0, e->datalen, &m) < 0)
        return put_same(out, num, e);
    for (int i = 0; i < m.n; i++) {
        double v = m.accel[i] * f;
        m.accel[i] = v > 999 ? 999 : v < -999 ? -999 : v;
    }
    unsigned char b[4096];
    int len = amfi_accel_block_t_encode(b, 0, sizeof b, &m);
    int rc = len < 0 || put(out, num, e->timestamp, e->channel, b, len);
    amfi_accel_block_t_decode_cleanup(&m);
    return rc;
}

static int put_env(lcm_eventlog_t *out, int64_t *num, int64_t ts, int64_t utime, double deck,
                   double air)
{
    amfi_environment_t m = {utime, air, deck};
    unsigned char b[64];
    int n = amfi_environment_t_encode(b, 0, sizeof b, &m);
    return n < 0 || put(out, num, ts, AMFI_CHANNEL_ENVIRONMENT, b, n);
}

/* The utime of an environment_t or a vehicle_t event (0), else −1. */
static int environment_utime(const lcm_eventlog_event_t *e, int64_t *utime)
{
    amfi_environment_t m;
    if (strcmp(e->channel, AMFI_CHANNEL_ENVIRONMENT) != 0 ||
        amfi_environment_t_decode(e->data, 0, e->datalen, &m) < 0)
        return -1;
    *utime = m.utime;
    return 0;
}

static int vehicle_utime(const lcm_eventlog_event_t *e, int64_t *utime)
{
    amfi_vehicle_t m;
    if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) != 0 ||
        amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0)
        return -1;
    *utime = m.utime;
    amfi_vehicle_t_decode_cleanup(&m);
    return 0;
}

/* Read IN to its end: the utime and log timestamp of the last event
 * utime_of recognizes (*last −1: none); IN closed, OUT opened. */
static int scan_last(const char *inp, const char *outp, lcm_eventlog_t **out,
                     int (*utime_of)(const lcm_eventlog_event_t *, int64_t *), int64_t *last,
                     int64_t *ts)
{
    lcm_eventlog_t *in;
    if (open_logs(inp, outp, &in, out))
        return 1;
    lcm_eventlog_event_t *e;
    *last = -1;
    *ts = 0;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        int64_t u;
        if (utime_of(e, &u) == 0) {
            *last = u;
            *ts = e->timestamp;
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    return 0;
}

static int bad_environment(const char *inp, const char *outp)
{
    lcm_eventlog_t *out;
    int64_t num = 0, last, ts;
    if (scan_last(inp, outp, &out, environment_utime, &last, &ts))
        return 1;
    int rc = 0;
    if (last < 0) {
        fprintf(stderr, "lcm_inject: no environment_t in %s\n", inp);
        rc = 1;
    } else {
        unsigned char junk[40];
        srand(11);
        for (size_t k = 0; k < sizeof junk; k++)
            junk[k] = (unsigned char)rand();
        rc |= put(out, &num, ts, AMFI_CHANNEL_ENVIRONMENT, junk, (int)sizeof junk);
        rc |= put_env(out, &num, ts + 1000, last, NAN, 10.0);
        rc |= put_env(out, &num, ts + 2000, last, 10.0, 95.0);
        rc |= put_env(out, &num, ts + 3000, last + INT64_C(864000000000), 10.0, 10.0);
        rc |= put_env(out, &num, ts + 4000, last + 1000000, 5.5, 4.5);
        if (rc)
            fprintf(stderr, "lcm_inject: write failed\n");
    }
    lcm_eventlog_destroy(out);
    return rc ? 1 : 0;
}

static int bad_reference(const char *inp, const char *outp)
{
    lcm_eventlog_t *out;
    int64_t num = 0, last, ts;
    if (scan_last(inp, outp, &out, vehicle_utime, &last, &ts))
        return 1;
    int rc = 0;
    if (last < 0) {
        fprintf(stderr, "lcm_inject: no vehicle_t in %s\n", inp);
        rc = 1;
    }
    const double ref[2] = {500.0, INFINITY};
    for (int k = 0; rc == 0 && k < 2; k++) {
        double spacing = 4.0;
        amfi_vehicle_t v = {last + (k + 1) * INT64_C(3000000), 434343 + k, 1, 20.0, 2, 1,
                            &spacing, "inject", ref[k]};
        unsigned char buf[256];
        int n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &v);
        rc |= n < 0 || put(out, &num, ts + 1000 * (k + 1), AMFI_CHANNEL_VEHICLE, buf, n);
    }
    if (rc && last >= 0)
        fprintf(stderr, "lcm_inject: write failed\n");
    lcm_eventlog_destroy(out);
    return rc ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (test_sign_init("test.inject"))
        return 1;
    if (argc == 4 && strcmp(argv[1], "--bad-reference") == 0)
        return bad_reference(argv[2], argv[3]);
    if (argc == 4 && strcmp(argv[1], "--bad-environment") == 0)
        return bad_environment(argv[2], argv[3]);
    if (argc == 5 && strcmp(argv[1], "--scale-accel") == 0)
        return rewrite(argv[3], argv[4], ev_scale_accel, atof(argv[2]), 0);
    if (argc == 5 && strcmp(argv[1], "--scale-spacing") == 0)
        return rewrite(argv[3], argv[4], ev_scale_spacing, atof(argv[2]), 1);
    if (argc == 4 && strcmp(argv[1], "--vehicles-only") == 0)
        return rewrite(argv[2], argv[3], ev_vehicles_only, 0.0, 1);
    if (argc == 4 && strcmp(argv[1], "--twin-lanes") == 0)
        return rewrite(argv[2], argv[3], ev_twin_lanes, 0.0, 1);
    if (argc != 3) {
        fprintf(stderr, "usage: lcm_inject [--vehicles-only | --bad-environment | --bad-reference | "
                        "--scale-accel F | --scale-spacing F] IN.log OUT.log\n");
        return 2;
    }
    lcm_eventlog_t *in, *out;
    if (open_logs(argv[1], argv[2], &in, &out))
        return 1;
    lcm_eventlog_event_t *e, *held = NULL;
    int64_t num = 0;
    int accel = 0, rc = 0;
    unsigned char junk[40];
    srand(7);
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (unsigned char)(rand() & 0xff);
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        int is_accel = strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0;
        if (is_accel)
            accel++;
        if (is_accel && accel == 60) { /* hold it: written after the 61st */
            held = e;
            continue;
        }
        rc |= put(out, &num, e->timestamp, e->channel, e->data, e->datalen);
        if (is_accel && accel == 61 && held) {
            rc |= put(out, &num, held->timestamp, held->channel, held->data, held->datalen);
            lcm_eventlog_free_event(held);
            held = NULL;
        }
        if (is_accel && accel == 50) {
            rc |= put(out, &num, e->timestamp, e->channel, e->data, e->datalen); /* duplicate */
            rc |= put(out, &num, e->timestamp, e->channel, e->data, e->datalen / 2); /* truncated */
            rc |= put(out, &num, e->timestamp, AMFI_CHANNEL_ACCEL, junk, sizeof junk);
            rc |= put(out, &num, e->timestamp, AMFI_CHANNEL_VEHICLE, junk, sizeof junk);
            rc |= put(out, &num, e->timestamp, AMFI_CHANNEL_TRUTH, junk, sizeof junk);
            double spacing = 5.0;
            amfi_vehicle_t v = {e->timestamp + 500000, 424242, 1, -3.0, 2, 1, &spacing, "inject", 0.0};
            unsigned char buf[256];
            int n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &v);
            rc |= n < 0 || put(out, &num, e->timestamp, AMFI_CHANNEL_VEHICLE, buf, n);
            /* well formed, but its spacings do not match its axle count (an
             * A23's five axles with two spacings), and one with 13 axles */
            double sp[12] = {3.7, 6.0, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3};
            amfi_vehicle_t few = {e->timestamp + 600000, 424243, 1, 25.0, 5, 2, sp, "inject", 0.0};
            n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &few);
            rc |= n < 0 || put(out, &num, e->timestamp, AMFI_CHANNEL_VEHICLE, buf, n);
            amfi_vehicle_t many = {e->timestamp + 700000, 424244, 1, 25.0, 7, 6, sp, "inject", 0.0};
            n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &many);
            rc |= n < 0 || put(out, &num, e->timestamp, AMFI_CHANNEL_VEHICLE, buf, n);
            amfi_accel_block_t m;
            memset(&m, 0, sizeof m);
            if (amfi_accel_block_t_decode(e->data, 0, e->datalen, &m) >= 0) {
                m.sensor_id = 99;
                unsigned char b2[2048];
                n = amfi_accel_block_t_encode(b2, 0, sizeof b2, &m);
                rc |= n < 0 || put(out, &num, e->timestamp, AMFI_CHANNEL_ACCEL, b2, n);
            }
            amfi_accel_block_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc || accel < 61) {
        fprintf(stderr, "lcm_inject: %s\n", rc ? "write failed" : "the log is too short");
        return 1;
    }
    return 0;
}
