/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_environment: summarise the environment_t and truth_t messages of an
 * LCM log, for tests/sim_environment.sh. Every message is checked before it
 * is decoded. Prints one line:
 *
 *   env N FIRST_US LAST_US MIN_STEP_US MAX_STEP_US AIR_MIN AIR_MAX DECK_MIN DECK_MAX
 *   truth N MEAN_GVW_KG
 *
 *   lcm_environment LOG
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "amfi_auth.h" /* a signed log: the message without its trailer */
#include "amfi_messages.h"
#include "amfi_msg_check.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: lcm_environment LOG\n");
        return 2;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in) {
        fprintf(stderr, "lcm_environment: cannot open %s\n", argv[1]);
        return 1;
    }
    lcm_eventlog_event_t *e;
    int bad = 0;
    long n = 0, nt = 0;
    int64_t first = 0, last = 0, smin = INT64_MAX, smax = 0;
    double amin = 1e9, amax = -1e9, dmin = 1e9, dmax = -1e9, gvw = 0.0;
    char why[160];
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (strcmp(e->channel, AMFI_CHANNEL_ENVIRONMENT) == 0) {
            amfi_environment_t m;
            if (amfi_msg_decode_checked(AMFI_MSG_ENVIRONMENT_T, e->data,
                                        amfi_auth_bare_len(e->data, (size_t)e->datalen), &m,
                                        why, sizeof why) != AMFI_MSG_OK) {
                fprintf(stderr, "lcm_environment: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
            } else {
                if (!isfinite(m.air_c) || !isfinite(m.deck_c)) {
                    fprintf(stderr, "lcm_environment: event %lld: not finite\n",
                            (long long)e->eventnum);
                    bad = 1;
                }
                if (n) {
                    const int64_t st = m.utime - last;
                    smin = st < smin ? st : smin;
                    smax = st > smax ? st : smax;
                } else {
                    first = m.utime;
                }
                last = m.utime;
                amin = fmin(amin, m.air_c), amax = fmax(amax, m.air_c);
                dmin = fmin(dmin, m.deck_c), dmax = fmax(dmax, m.deck_c);
                n++;
                amfi_environment_t_decode_cleanup(&m);
            }
        } else if (strcmp(e->channel, AMFI_CHANNEL_TRUTH) == 0) {
            amfi_truth_t m;
            if (amfi_msg_decode_checked(AMFI_MSG_TRUTH_T, e->data,
                                        amfi_auth_bare_len(e->data, (size_t)e->datalen), &m, why,
                                        sizeof why) != AMFI_MSG_OK) {
                fprintf(stderr, "lcm_environment: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
            } else {
                gvw += m.gvw_kg;
                nt++;
                amfi_truth_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    printf("env %ld %lld %lld %lld %lld %.2f %.2f %.2f %.2f\n", n, (long long)first,
           (long long)last, (long long)(n > 1 ? smin : 0), (long long)smax, n ? amin : 0.0,
           n ? amax : 0.0, n ? dmin : 0.0, n ? dmax : 0.0);
    printf("truth %ld %.1f\n", nt, nt ? gvw / nt : 0.0);
    return bad;
}
