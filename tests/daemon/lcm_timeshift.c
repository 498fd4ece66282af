/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_timeshift: copy an LCM log with the data's time made to jump, for
 * tests/daemon/daemon_timejump.sh (issue 9, finding 2):
 *   lcm_timeshift poison IN OUT   a copy of the first accel block dated one
 *                                 hour ahead, written before everything else
 *   lcm_timeshift outage IN OUT K every accel, vehicle and truth message after
 *                                 the K-th vehicle event is dated two hours
 *                                 later (a DAQ and detector outage)
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

#define HOUR INT64_C(3600000000)

/* Every event signed with the test key (test_bus_sign.h). */
#define put test_put

/* Re-encode the event with its utime moved by dt; 0 on success. */
static int shifted(const lcm_eventlog_event_t *e, int64_t dt, unsigned char *buf, int cap, int *len)
{
    if (strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0) {
        amfi_accel_block_t m;
        if (amfi_accel_block_t_decode(e->data, 0, e->datalen, &m) < 0)
            return -1;
        m.utime += dt;
        *len = amfi_accel_block_t_encode(buf, 0, cap, &m);
        amfi_accel_block_t_decode_cleanup(&m);
    } else if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0) {
        amfi_vehicle_t m;
        if (amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0)
            return -1;
        m.utime += dt;
        *len = amfi_vehicle_t_encode(buf, 0, cap, &m);
        amfi_vehicle_t_decode_cleanup(&m);
    } else if (strcmp(e->channel, AMFI_CHANNEL_TRUTH) == 0) {
        amfi_truth_t m;
        if (amfi_truth_t_decode(e->data, 0, e->datalen, &m) < 0)
            return -1;
        m.utime += dt;
        *len = amfi_truth_t_encode(buf, 0, cap, &m);
        amfi_truth_t_decode_cleanup(&m);
    } else {
        if (e->datalen > cap)
            return -1;
        memcpy(buf, e->data, (size_t)e->datalen);
        *len = e->datalen;
    }
    return *len < 0 ? -1 : 0;
}

int main(int argc, char **argv)
{
    if (test_sign_init("test.timeshift"))
        return 1;
    int poison = argc == 4 && strcmp(argv[1], "poison") == 0;
    int outage = argc == 5 && strcmp(argv[1], "outage") == 0;
    if (!poison && !outage) {
        fprintf(stderr, "usage: lcm_timeshift poison IN OUT | outage IN OUT K\n");
        return 2;
    }
    long k_after = outage ? strtol(argv[4], NULL, 10) : 0;
    lcm_eventlog_t *in = lcm_eventlog_create(argv[2], "r");
    lcm_eventlog_t *out = lcm_eventlog_create(argv[3], "w");
    if (!in || !out) {
        fprintf(stderr, "lcm_timeshift: cannot open the logs\n");
        return 1;
    }
    static unsigned char buf[1 << 16];
    lcm_eventlog_event_t *e;
    int64_t num = 0;
    long vehicles = 0;
    int rc = 0, first_accel = 1, len;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        int is_accel = strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0;
        if (poison && is_accel && first_accel) {
            first_accel = 0;
            rc |= shifted(e, HOUR, buf, sizeof buf, &len) ||
                  put(out, &num, e->timestamp, e->channel, buf, len);
        }
        int64_t dt = outage && vehicles >= k_after ? 2 * HOUR : 0;
        if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0)
            vehicles++;
        rc |= shifted(e, dt, buf, sizeof buf, &len) ||
              put(out, &num, e->timestamp + dt, e->channel, buf, len);
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc) {
        fprintf(stderr, "lcm_timeshift: cannot copy the log\n");
        return 1;
    }
    return 0;
}
