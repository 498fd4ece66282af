/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_passages: print the passages an LCM log recorded on AMFI_PASSAGE, one
 * line each, "PASSAGE_ID VEHICLE_ID STATUS", for tests/daemon/daemon_kill9.sh (what
 * amfid acknowledged: it publishes a passage only after its commit). Every
 * message is checked before it is decoded. With --site, one line
 * "CHANNEL SITE_ID" per passage, indicator, alert and status message instead
 * (tests/daemon/daemon_site.sh). With --f1, "PASSAGE_ID VEHICLE_ID STATUS F1_HZ
 * F1_COMP_HZ" (%.6f, nan when none; tests/daemon/daemon_natfreq.sh). With --class,
 * "PASSAGE_ID VEHICLE_ID STATUS CLASS GROUPS GROUP_LOADS_KG OVERLOAD" (CLASS
 * "-" when empty, GROUPS the groups' axles joined by '-', GROUP_LOADS_KG the
 * sum of the groups' loads, %.3f, nan when not solved;
 * tests/daemon/daemon_classes.sh). With --site
 * and the test's bus key ($CREDENTIALS_DIRECTORY/amfi-bus-key), every
 * message must also carry amfid's valid signature (the trailer verified, each
 * producer's sequence increasing; docs/messages.md).
 *
 *   lcm_passages [--site | --f1 | --class] LOG
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <string.h>

#include "amfi_auth.h" /* a signed log: the message without its trailer */
#include "amfi_messages.h"
#include "amfi_msg_check.h"

/* --site: one line "CHANNEL site_id" per amfid output message of the log
 * (passage, indicator, alert, status), each decoded through the checker. */
static int print_sites(lcm_eventlog_t *in)
{
    static const struct {
        const char *channel;
        amfi_msg_type type;
    } outs[] = {{AMFI_CHANNEL_PASSAGE, AMFI_MSG_PASSAGE_T},
                {AMFI_CHANNEL_INDICATOR, AMFI_MSG_INDICATOR_T},
                {AMFI_CHANNEL_ALERT, AMFI_MSG_ALERT_T},
                {AMFI_CHANNEL_STATUS, AMFI_MSG_STATUS_T}};
    lcm_eventlog_event_t *e;
    int bad = 0;
    /* amfid signs what it publishes: verified with the test's key */
    static amfi_auth_verifier v;
    char kpath[4096], kerr[4400];
    amfi_auth_key key;
    int verify = amfi_auth_key_path(NULL, NULL, kpath, sizeof kpath, NULL) != NULL;
    if (verify && (amfi_auth_key_load(kpath, &key, kerr, sizeof kerr) ||
                   amfi_auth_verifier_init(&v, &key, 0.0))) {
        fprintf(stderr, "lcm_passages: %s\n", kerr);
        return 1;
    }

    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        for (size_t k = 0; k < sizeof outs / sizeof outs[0]; k++) {
            if (strcmp(e->channel, outs[k].channel))
                continue;
            size_t len = amfi_auth_bare_len(e->data, (size_t)e->datalen);
            char awhy[256];
            if (verify && amfi_auth_verify(&v, e->channel, e->data, (size_t)e->datalen, 0, &len,
                                           awhy, sizeof awhy) != AMFI_AUTH_OK) {
                fprintf(stderr, "lcm_passages: event %lld on %s: %s\n", (long long)e->eventnum,
                        e->channel, awhy);
                bad = 1;
                continue;
            }
            union {
                amfi_passage_t p;
                amfi_indicator_t i;
                amfi_alert_t a;
                amfi_status_t s;
            } m;
            char why[160];
            if (amfi_msg_decode_checked(outs[k].type, e->data, len, &m, why, sizeof why) !=
                AMFI_MSG_OK) {
                fprintf(stderr, "lcm_passages: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
                continue;
            }
            const char *site = k == 0   ? m.p.site_id
                               : k == 1 ? m.i.site_id
                               : k == 2 ? m.a.site_id
                                        : m.s.site_id;
            printf("%s %s\n", e->channel, site);
            if (k == 0)
                amfi_passage_t_decode_cleanup(&m.p);
            else if (k == 1)
                amfi_indicator_t_decode_cleanup(&m.i);
            else if (k == 2)
                amfi_alert_t_decode_cleanup(&m.a);
            else
                amfi_status_t_decode_cleanup(&m.s);
        }
        lcm_eventlog_free_event(e);
    }
    return bad;
}

int main(int argc, char **argv)
{
    int sites = argc == 3 && strcmp(argv[1], "--site") == 0;
    int f1 = argc == 3 && strcmp(argv[1], "--f1") == 0;
    int cls = argc == 3 && strcmp(argv[1], "--class") == 0;
    if (argc != 2 && !sites && !f1 && !cls) {
        fprintf(stderr, "usage: lcm_passages [--site | --f1 | --class] LOG\n");
        return 2;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[argc - 1], "r");
    if (!in) {
        fprintf(stderr, "lcm_passages: cannot open %s\n", argv[argc - 1]);
        return 1;
    }
    if (sites) {
        int bad = print_sites(in);
        lcm_eventlog_destroy(in);
        return bad;
    }
    lcm_eventlog_event_t *e;
    int bad = 0;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (strcmp(e->channel, AMFI_CHANNEL_PASSAGE) == 0) {
            amfi_passage_t m;
            char why[160];
            if (amfi_msg_decode_checked(AMFI_MSG_PASSAGE_T, e->data,
                                        amfi_auth_bare_len(e->data, (size_t)e->datalen), &m, why,
                                        sizeof why) != AMFI_MSG_OK) {
                fprintf(stderr, "lcm_passages: event %lld: %s\n", (long long)e->eventnum, why);
                bad = 1;
            } else {
                printf("%lld %lld %s", (long long)m.passage_id, (long long)m.vehicle_id,
                       m.status);
                if (f1)
                    printf(" %.6f %.6f", m.f1_hz, m.f1_comp_hz);
                if (cls) {
                    double sum = 0.0;
                    printf(" %s ", m.vehicle_class[0] ? m.vehicle_class : "-");
                    for (int g = 0; g < m.n_groups; g++) {
                        printf("%s%d", g ? "-" : "", m.group_axles[g]);
                        sum += m.group_load_kg[g];
                    }
                    printf("%s %.3f %d", m.n_groups ? "" : "-", sum, m.overload);
                }
                printf("\n");
                amfi_passage_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    return bad;
}
