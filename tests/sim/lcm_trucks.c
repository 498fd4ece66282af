/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_trucks: the vehicles and truths of an LCM log (sim_publisher --log),
 * for tests/sim_trucks.sh. One line per vehicle_t, "V ID N_AXLES
 * SPACING1;SPACING2;... REFERENCE_GVW_KG" (0 for an ordinary vehicle), and
 * per truth_t, "T ID N_AXLES GVW_KG
 * AXLE1_KG;AXLE2_KG;...". Exit 1 when a message does not decode, or when
 * one is inconsistent: n_spacings other than n_axles − 1, a spacing or a
 * load <= 0, a truth's GVW other than the sum of its axles (1e-9).
 *
 *   lcm_trucks LOG
 */
#include <lcm/eventlog.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amfi_messages.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: lcm_trucks LOG\n");
        return 2;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in) {
        fprintf(stderr, "lcm_trucks: %s: cannot open\n", argv[1]);
        return 1;
    }
    int bad = 0;
    lcm_eventlog_event_t *e;
    while (!bad && (e = lcm_eventlog_read_next_event(in)) != NULL) {
        if (!strcmp(e->channel, AMFI_CHANNEL_VEHICLE)) {
            amfi_vehicle_t m;
            if (amfi_vehicle_t_decode(e->data, 0, e->datalen, &m) < 0) {
                fprintf(stderr, "lcm_trucks: event %lld: vehicle_t does not decode\n",
                        (long long)e->eventnum);
                bad = 1;
            } else {
                printf("V %lld %d ", (long long)m.vehicle_id, m.n_axles);
                bad = m.n_spacings != m.n_axles - 1;
                for (int i = 0; i < m.n_spacings; i++) {
                    printf("%s%.2f", i ? ";" : "", m.axle_spacing_m[i]);
                    bad |= !(m.axle_spacing_m[i] > 0);
                }
                printf(" %.1f\n", isfinite(m.reference_gvw_kg) ? m.reference_gvw_kg : 0.0);
                amfi_vehicle_t_decode_cleanup(&m);
            }
        } else if (!strcmp(e->channel, AMFI_CHANNEL_TRUTH)) {
            amfi_truth_t m;
            if (amfi_truth_t_decode(e->data, 0, e->datalen, &m) < 0) {
                fprintf(stderr, "lcm_trucks: event %lld: truth_t does not decode\n",
                        (long long)e->eventnum);
                bad = 1;
            } else {
                double sum = 0;
                printf("T %lld %d %.1f ", (long long)m.vehicle_id, m.n_axles, m.gvw_kg);
                for (int i = 0; i < m.n_axles; i++) {
                    printf("%s%.1f", i ? ";" : "", m.axle_kg[i]);
                    sum += m.axle_kg[i];
                    bad |= !(m.axle_kg[i] > 0) || !(m.mean_force_N[i] > 0);
                }
                printf("\n");
                bad |= !(fabs(sum - m.gvw_kg) <= 1e-9 * m.gvw_kg);
                amfi_truth_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(e);
        if (bad)
            fprintf(stderr, "lcm_trucks: an inconsistent message (above)\n");
    }
    lcm_eventlog_destroy(in);
    return bad;
}
