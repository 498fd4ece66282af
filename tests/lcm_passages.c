/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_passages: print the passages an LCM log recorded on AMFI_PASSAGE, one
 * line each, "PASSAGE_ID VEHICLE_ID STATUS", for tests/daemon_kill9.sh (what
 * amfid acknowledged: it publishes a passage only after its commit). Every
 * message is checked before it is decoded.
 *
 *   lcm_passages LOG
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <string.h>

#include "amfi_messages.h"
#include "amfi_msg_check.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: lcm_passages LOG\n");
        return 2;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in) {
        fprintf(stderr, "lcm_passages: cannot open %s\n", argv[1]);
        return 1;
    }
    lcm_eventlog_event_t *e;
    int bad = 0;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (strcmp(e->channel, AMFI_CHANNEL_PASSAGE) == 0) {
            amfi_passage_t m;
            char why[160];
            if (amfi_msg_decode_checked(AMFI_MSG_PASSAGE_T, e->data, (size_t)e->datalen, &m, why,
                                        sizeof why) != AMFI_MSG_OK) {
                fprintf(stderr, "lcm_passages: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
            } else {
                printf("%lld %lld %s\n", (long long)m.passage_id, (long long)m.vehicle_id,
                       m.status);
                amfi_passage_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    return bad;
}
