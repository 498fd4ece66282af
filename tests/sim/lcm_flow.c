/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_flow: check the vehicle_t messages of an LCM log written by
 * sim_publisher --flow (issue 13), for tests/sim_flow.sh. Every message is
 * checked before it is decoded. With the span length L, a vehicle is on the
 * span from its entry until entry + (L + its length) / speed; two vehicles
 * overlap when those windows intersect. Within a lane, a follower
 * overtakes when its front axle reaches x = L before its leader's. Prints
 *
 *   vehicles N lanes L1 L2 overlapping K overtaking O unordered U mingap_ms G
 *
 * (lane counts for lanes 1 and 2; K vehicles whose window meets another's;
 * O overtakes; U vehicle_t out of entry order; G the shortest entry to
 * entry time within a lane, ms, rounded down).
 *
 *   lcm_flow LOG SPAN_M
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_auth.h" /* a signed log: the message without its trailer */
#include "amfi_messages.h"
#include "amfi_msg_check.h"

typedef struct veh {
    double entry_s, speed, len_m;
    int lane;
} veh;

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: lcm_flow LOG SPAN_M\n");
        return 2;
    }
    const double span = atof(argv[2]);
    if (!(span > 0)) {
        fprintf(stderr, "lcm_flow: SPAN_M: %s is not > 0\n", argv[2]);
        return 2;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in) {
        fprintf(stderr, "lcm_flow: cannot open %s\n", argv[1]);
        return 1;
    }
    veh *v = NULL;
    long n = 0, cap = 0, unordered = 0;
    int bad = 0;
    char why[160];
    lcm_eventlog_event_t *e;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0) {
            amfi_vehicle_t m;
            if (amfi_msg_decode_checked(AMFI_MSG_VEHICLE_T, e->data,
                                        amfi_auth_bare_len(e->data, (size_t)e->datalen), &m, why,
                                        sizeof why) != AMFI_MSG_OK) {
                fprintf(stderr, "lcm_flow: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
            } else {
                if (n == cap) {
                    cap = cap ? 2 * cap : 64;
                    veh *nv = realloc(v, sizeof *v * (size_t)cap);
                    if (!nv) {
                        fprintf(stderr, "lcm_flow: out of memory\n");
                        return 1;
                    }
                    v = nv;
                }
                double len = 0.0;
                for (int i = 0; i < m.n_spacings; i++)
                    len += m.axle_spacing_m[i];
                v[n] = (veh){1e-6 * (double)m.utime, m.speed_mps, len, m.lane};
                if (n && v[n].entry_s < v[n - 1].entry_s)
                    unordered++;
                n++;
                amfi_vehicle_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    long lanes[3] = {0}, overlapping = 0, overtaking = 0;
    double mingap = 1e9;
    for (long i = 0; i < n; i++) {
        if (v[i].lane >= 1 && v[i].lane <= 2)
            lanes[v[i].lane]++;
        const double a0 = v[i].entry_s, a1 = a0 + (span + v[i].len_m) / v[i].speed;
        int meets = 0;
        for (long j = 0; j < n; j++) {
            if (j == i)
                continue;
            const double b0 = v[j].entry_s, b1 = b0 + (span + v[j].len_m) / v[j].speed;
            if (v[j].lane == v[i].lane && b0 >= a0 && b0 - a0 < mingap)
                mingap = b0 - a0;
            if (a0 < b1 && b0 < a1)
                meets = 1;
            /* j follows i in the same lane: its front axle must leave after i's */
            if (v[j].lane == v[i].lane && b0 > a0 && b0 + span / v[j].speed < a0 + span / v[i].speed)
                overtaking++;
        }
        overlapping += meets;
    }
    free(v);
    printf("vehicles %ld lanes %ld %ld overlapping %ld overtaking %ld unordered %ld mingap_ms %ld\n",
           n, lanes[1], lanes[2], overlapping, overtaking, unordered,
           (long)floor(1e3 * mingap + 1e-6));
    return bad;
}
