/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_hostile: copy an LCM log, splicing in the hostile datagrams of issue 9
 * after the 50th AMFI_ACCEL event, for tests/daemon/daemon_hostile.sh:
 *   the vehicle_t (64 bytes; 56 before reference_gvw_kg) whose source string length is -16 (read from FILE,
 *   the fuzz corpus' copy of it); an accel_block_t with n = -1; a vehicle_t
 *   with n_spacings = -1; a truth_t with n_axles = -2; a well-formed vehicle
 *   (id 777001) whose utime is past year 9999; then COUNT more refused
 *   messages (the four kinds in turn), to bound amfid's log.
 *
 *   lcm_hostile IN.log OUT.log ISSUE9_VEHICLE_FILE COUNT
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

/* Every event signed with the test key (test_bus_sign.h). */
#define put test_put

/* A big-endian int16 at byte `at` (after the 8-byte fingerprint). */
static void put16(unsigned char *b, int at, int v)
{
    b[at] = (unsigned char)((unsigned)v >> 8);
    b[at + 1] = (unsigned char)v;
}

int main(int argc, char **argv)
{
    if (test_sign_init("test.hostile"))
        return 1;
    if (argc != 5) {
        fprintf(stderr, "usage: lcm_hostile IN.log OUT.log ISSUE9_VEHICLE_FILE COUNT\n");
        return 2;
    }
    unsigned char issue9[256];
    FILE *f = fopen(argv[3], "rb");
    int n9 = f ? (int)fread(issue9, 1, sizeof issue9, f) : -1;
    if (f)
        fclose(f);
    long extra = strtol(argv[4], NULL, 10);
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    lcm_eventlog_t *out = lcm_eventlog_create(argv[2], "w");
    if (n9 <= 0 || !in || !out || extra < 0) {
        fprintf(stderr, "lcm_hostile: cannot read the inputs\n");
        return 1;
    }
    /* The three negative-count messages, from valid encodings. Offsets: the
     * 8-byte fingerprint, then accel: utime 8, sensor_id 4, seq 8, rate 8 ->
     * n at 36; vehicle: utime 8, id 8, lane 2, speed 8, n_axles 2 ->
     * n_spacings at 36; truth: utime 8, id 8, gvw 8 -> n_axles at 32. */
    double acc[4] = {0.1, 0.2, 0.3, 0.4};
    amfi_accel_block_t a = {1, 0, 1, 1000.0, 4, acc};
    unsigned char ba[256];
    int na = amfi_accel_block_t_encode(ba, 0, sizeof ba, &a);
    double sp = 5.0;
    amfi_vehicle_t v = {1, 1, 1, 25.0, 2, 1, &sp, "hostile", 0.0};
    unsigned char bv[256];
    int nv = amfi_vehicle_t_encode(bv, 0, sizeof bv, &v);
    double ax[2] = {5000, 5000}, mf[2] = {49000, 49000};
    amfi_truth_t t = {1, 1, 10000.0, 2, ax, mf, 25.0};
    unsigned char bt[256];
    int nt = amfi_truth_t_encode(bt, 0, sizeof bt, &t);
    if (na < 0 || nv < 0 || nt < 0)
        return 1;
    put16(ba, 36, -1);
    put16(bv, 36, -1);
    put16(bt, 32, -2);

    lcm_eventlog_event_t *e;
    int64_t num = 0;
    int accel = 0, rc = 0;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        rc |= put(out, &num, e->timestamp, e->channel, e->data, e->datalen);
        if (strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0 && ++accel == 50) {
            int64_t ts = e->timestamp;
            rc |= put(out, &num, ts, AMFI_CHANNEL_VEHICLE, issue9, n9);
            rc |= put(out, &num, ts, AMFI_CHANNEL_ACCEL, ba, na);
            rc |= put(out, &num, ts, AMFI_CHANNEL_VEHICLE, bv, nv);
            rc |= put(out, &num, ts, AMFI_CHANNEL_TRUTH, bt, nt);
            amfi_vehicle_t far = {INT64_C(253402300800000000) + 1000000, 777001, 1, 25.0, 2, 1,
                                  &sp, "hostile", 0.0};
            unsigned char bf[256];
            int nf = amfi_vehicle_t_encode(bf, 0, sizeof bf, &far);
            rc |= nf < 0 || put(out, &num, ts, AMFI_CHANNEL_VEHICLE, bf, nf);
            for (long k = 0; k < extra; k++)
                switch (k % 4) {
                case 0: rc |= put(out, &num, ts, AMFI_CHANNEL_VEHICLE, issue9, n9); break;
                case 1: rc |= put(out, &num, ts, AMFI_CHANNEL_ACCEL, ba, na); break;
                case 2: rc |= put(out, &num, ts, AMFI_CHANNEL_VEHICLE, bv, nv); break;
                default: rc |= put(out, &num, ts, AMFI_CHANNEL_TRUTH, bt, nt); break;
                }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc || accel < 50) {
        fprintf(stderr, "lcm_hostile: %s\n", rc ? "write failed" : "the log is too short");
        return 1;
    }
    return 0;
}
