/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_reload: the bus messages of tests/daemon/daemon_reload_keys.sh (a
 * SIGHUP for every live configuration key), as LCM logs for lcm-logplayer,
 * each event signed with the test key as PRODUCER (test_bus_sign.h):
 *
 *   lcm_reload t0 SIMLOG
 *       print the data time (µs) of SIMLOG's first accel block
 *   lcm_reload segment SIMLOG OUT PRODUCER FROM_S TO_S SHIFT_S ID_ADD [HOLE_S HOLE_LEN_S]
 *       SIMLOG's events whose data time is in [t0 + FROM_S, t0 + TO_S),
 *       moved SHIFT_S later (utime, and the accel blocks' seq by as many
 *       blocks), vehicle and truth ids + ID_ADD; with HOLE_S, the accel
 *       blocks of every sensor but sensor 0 starting in [t0 + HOLE_S,
 *       t0 + HOLE_S + HOLE_LEN_S) (before the move) left out (a sensor
 *       silent while the others send)
 *   lcm_reload vehicles OUT PRODUCER UTIME_US ID COUNT SPEED_MPS SPACING_M SOURCE REF_KG
 *       COUNT two-axle vehicle_t, ids ID .., all at UTIME_US (REF_KG 0: none)
 *   lcm_reload truth OUT PRODUCER UTIME_US ID COUNT
 *       COUNT truth_t of a 10 t two-axle vehicle, ids ID ..
 *   lcm_reload env OUT PRODUCER UTIME_US DECK_C COUNT STEP_US
 *       COUNT environment_t, STEP_US apart, deck DECK_C, air DECK_C − 2
 *   lcm_reload accel OUT PRODUCER UTIME_US SEQ COUNT RATE_HZ
 *       COUNT accel blocks of sensor 0 (100 samples of 0 each, back to
 *       back from UTIME_US), seq SEQ ..
 *   lcm_reload list LOG
 *       one line "TIMESTAMP_US CHANNEL" per event of LOG (lcm-logger's record),
 *       with " VEHICLE_ID UTIME_US" for a vehicle_t
 *
 * Exit status 0, 1 (a file error or bad input), 2 (bad command line).
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

static int64_t num;

static int put(lcm_eventlog_t *out, int64_t ts, const char *ch, const void *data, int len)
{
    return test_put(out, &num, ts, ch, data, len);
}

static int64_t first_accel(const char *path)
{
    lcm_eventlog_t *in = lcm_eventlog_create(path, "r");
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

static int64_t arg_i64(const char *s)
{
    char *end;
    long long v = strtoll(s, &end, 10);
    if (*end) {
        fprintf(stderr, "lcm_reload: '%s' is not an integer\n", s);
        exit(2);
    }
    return v;
}

static double arg_d(const char *s)
{
    char *end;
    double v = strtod(s, &end);
    if (*end || !isfinite(v)) {
        fprintf(stderr, "lcm_reload: '%s' is not a number\n", s);
        exit(2);
    }
    return v;
}

/* Re-encode one event of the simulator's log moved by shift µs. 1: left out. */
static int moved(lcm_eventlog_t *out, const lcm_eventlog_event_t *e, int64_t from, int64_t to,
                 int64_t shift, int64_t id_add, int64_t hole0, int64_t hole1, int *rc)
{
    unsigned char buf[65536];
    int n = -1;

    if (strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0) {
        amfi_accel_block_t m;
        if (amfi_accel_block_t_decode(e->data, 0, e->datalen, &m) < 0)
            return 1;
        const int in = m.utime >= from && m.utime < to &&
                       !(m.sensor_id != 0 && m.utime >= hole0 && m.utime < hole1);
        if (in) {
            const double block_s = m.n / m.sample_rate_hz;
            m.seq += llround(1e-6 * (double)shift / block_s);
            m.utime += shift;
            n = amfi_accel_block_t_encode(buf, 0, sizeof buf, &m);
        }
        amfi_accel_block_t_decode_cleanup(&m);
    } else if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0) {
        amfi_vehicle_t m;
        if (amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0)
            return 1;
        if (m.utime >= from && m.utime < to) {
            m.utime += shift;
            m.vehicle_id += id_add;
            n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &m);
        }
        amfi_vehicle_t_decode_cleanup(&m);
    } else if (strcmp(e->channel, AMFI_CHANNEL_TRUTH) == 0) {
        amfi_truth_t m;
        if (amfi_truth_t_decode(e->data, 0, e->datalen, &m) < 0)
            return 1;
        if (m.utime >= from && m.utime < to) {
            m.utime += shift;
            m.vehicle_id += id_add;
            n = amfi_truth_t_encode(buf, 0, sizeof buf, &m);
        }
        amfi_truth_t_decode_cleanup(&m);
    } else if (strcmp(e->channel, AMFI_CHANNEL_ENVIRONMENT) == 0) {
        amfi_environment_t m;
        if (amfi_environment_t_decode(e->data, 0, e->datalen, &m) < 0)
            return 1;
        if (m.utime >= from && m.utime < to) {
            m.utime += shift;
            n = amfi_environment_t_encode(buf, 0, sizeof buf, &m);
        }
        amfi_environment_t_decode_cleanup(&m);
    }
    if (n < 0)
        return 1;
    *rc |= put(out, e->timestamp, e->channel, buf, n);
    return 0;
}

static int segment(int argc, char **argv)
{
    if (argc != 9 && argc != 11)
        return -1;
    const int64_t t0 = first_accel(argv[2]);
    if (t0 < 0) {
        fprintf(stderr, "lcm_reload: no accel_block_t in %s\n", argv[2]);
        return 1;
    }
    const int64_t from = t0 + llround(1e6 * arg_d(argv[5]));
    const int64_t to = t0 + llround(1e6 * arg_d(argv[6]));
    const int64_t shift = llround(1e6 * arg_d(argv[7]));
    const int64_t id_add = arg_i64(argv[8]);
    int64_t hole0 = INT64_MAX, hole1 = INT64_MAX;
    if (argc == 11) {
        hole0 = t0 + llround(1e6 * arg_d(argv[9]));
        hole1 = hole0 + llround(1e6 * arg_d(argv[10]));
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[2], "r");
    lcm_eventlog_t *out = lcm_eventlog_create(argv[3], "w");
    if (!in || !out) {
        fprintf(stderr, "lcm_reload: cannot open %s or %s\n", argv[2], argv[3]);
        return 1;
    }
    lcm_eventlog_event_t *e;
    int rc = 0, kept = 0;
    while (rc == 0 && (e = lcm_eventlog_read_next_event(in)) != NULL) {
        kept += !moved(out, e, from, to, shift, id_add, hole0, hole1, &rc);
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc || kept == 0)
        fprintf(stderr, "lcm_reload: %s\n", rc ? "write failed" : "no event in the segment");
    return rc || kept == 0;
}

int main(int argc, char **argv)
{
    const char *mode = argc > 1 ? argv[1] : "";
    int rc = 0;

    if (strcmp(mode, "t0") == 0 && argc == 3) {
        const int64_t t0 = first_accel(argv[2]);
        if (t0 < 0)
            return 1;
        printf("%" PRId64 "\n", t0);
        return 0;
    }
    if (strcmp(mode, "list") == 0 && argc == 3) {
        lcm_eventlog_t *in = lcm_eventlog_create(argv[2], "r");
        lcm_eventlog_event_t *e;
        if (!in)
            return 1;
        while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
            amfi_vehicle_t v;
            if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0 &&
                amfi_vehicle_t_decode(e->data, 0, e->datalen, &v) >= 0) {
                printf("%" PRId64 " %s %" PRId64 " %" PRId64 "\n", e->timestamp, e->channel,
                       v.vehicle_id, v.utime);
                amfi_vehicle_t_decode_cleanup(&v);
            } else {
                printf("%" PRId64 " %s\n", e->timestamp, e->channel);
            }
            lcm_eventlog_free_event(e);
        }
        lcm_eventlog_destroy(in);
        return 0;
    }
    if (argc < 5)
        goto usage;
    if (test_sign_init(argv[strcmp(mode, "segment") == 0 ? 4 : 3]))
        return 1;
    if (strcmp(mode, "segment") == 0) {
        rc = segment(argc, argv);
        if (rc < 0)
            goto usage;
        return rc;
    }
    lcm_eventlog_t *out = lcm_eventlog_create(argv[2], "w");
    if (!out) {
        fprintf(stderr, "lcm_reload: cannot write %s\n", argv[2]);
        return 1;
    }
    unsigned char buf[4096];
    int n;
    if (strcmp(mode, "vehicles") == 0 && argc == 11) {
        const int64_t u = arg_i64(argv[4]), id = arg_i64(argv[5]), count = arg_i64(argv[6]);
        double spacing = arg_d(argv[8]);
        for (int64_t i = 0; i < count && rc == 0; i++) {
            amfi_vehicle_t v = {u, id + i, 1, arg_d(argv[7]), 2, 1, &spacing, argv[9],
                                arg_d(argv[10])};
            n = amfi_vehicle_t_encode(buf, 0, sizeof buf, &v);
            rc |= n < 0 || put(out, 0, AMFI_CHANNEL_VEHICLE, buf, n);
        }
    } else if (strcmp(mode, "truth") == 0 && argc == 7) {
        const int64_t u = arg_i64(argv[4]), id = arg_i64(argv[5]), count = arg_i64(argv[6]);
        double kg[2] = {4000.0, 6000.0}, f[2] = {4000.0 * 9.81, 6000.0 * 9.81};
        for (int64_t i = 0; i < count && rc == 0; i++) {
            amfi_truth_t t = {u, id + i, 10000.0, 2, kg, f, 20.0};
            n = amfi_truth_t_encode(buf, 0, sizeof buf, &t);
            rc |= n < 0 || put(out, 0, AMFI_CHANNEL_TRUTH, buf, n);
        }
    } else if (strcmp(mode, "env") == 0 && argc == 8) {
        const int64_t u = arg_i64(argv[4]), count = arg_i64(argv[6]), step = arg_i64(argv[7]);
        const double deck = arg_d(argv[5]);
        for (int64_t i = 0; i < count && rc == 0; i++) {
            amfi_environment_t m = {u + i * step, deck - 2.0, deck};
            n = amfi_environment_t_encode(buf, 0, sizeof buf, &m);
            rc |= n < 0 || put(out, 0, AMFI_CHANNEL_ENVIRONMENT, buf, n);
        }
    } else if (strcmp(mode, "accel") == 0 && argc == 8) {
        const int64_t u = arg_i64(argv[4]), seq = arg_i64(argv[5]), count = arg_i64(argv[6]);
        const double rate = arg_d(argv[7]);
        double x[100] = {0};
        for (int64_t i = 0; i < count && rc == 0; i++) {
            amfi_accel_block_t b = {u + llround(i * 100 * 1e6 / rate), 0, seq + i, rate, 100, x};
            n = amfi_accel_block_t_encode(buf, 0, sizeof buf, &b);
            rc |= n < 0 || put(out, 0, AMFI_CHANNEL_ACCEL, buf, n);
        }
    } else {
        lcm_eventlog_destroy(out);
        goto usage;
    }
    lcm_eventlog_destroy(out);
    if (rc)
        fprintf(stderr, "lcm_reload: write failed\n");
    return rc ? 1 : 0;
usage:
    fprintf(stderr, "usage: lcm_reload t0 SIMLOG | list LOG | segment SIMLOG OUT PRODUCER FROM_S "
                    "TO_S SHIFT_S ID_ADD [HOLE_S HOLE_LEN_S] | vehicles OUT PRODUCER UTIME_US ID "
                    "COUNT SPEED SPACING_M SOURCE REF_KG | truth OUT PRODUCER UTIME_US ID COUNT | "
                    "env OUT PRODUCER UTIME_US DECK_C COUNT STEP_US | accel OUT PRODUCER UTIME_US "
                    "SEQ COUNT RATE_HZ\n");
    return 2;
}
