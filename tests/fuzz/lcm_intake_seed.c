/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_intake_seed: turn an LCM log (sim_publisher --log) into a seed of the
 * fuzz target fuzz_intake (fuzz/fuzz_intake.c): one record per AMFI_ACCEL,
 * AMFI_VEHICLE, AMFI_TRUTH or AMFI_ENVIRONMENT event, [u8 channel 0/1/2/3]
 * [u16 length LE][bytes],
 * in log order; other channels and events over 65535 bytes are skipped.
 * Used by fuzz/make_corpus.sh.
 *
 *   lcm_intake_seed LOG OUT [MAX_EVENTS]
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_auth.h"

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: lcm_intake_seed LOG OUT [MAX_EVENTS]\n");
        return 2;
    }
    long max = argc == 4 ? strtol(argv[3], NULL, 10) : -1;
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in) {
        fprintf(stderr, "lcm_intake_seed: cannot open %s\n", argv[1]);
        return 1;
    }
    FILE *out = fopen(argv[2], "wb");
    if (!out) {
        fprintf(stderr, "lcm_intake_seed: cannot write %s\n", argv[2]);
        lcm_eventlog_destroy(in);
        return 1;
    }
    static const char *const names[4] = {"AMFI_ACCEL", "AMFI_VEHICLE", "AMFI_TRUTH",
                                         "AMFI_ENVIRONMENT"};
    lcm_eventlog_event_t *e;
    long n = 0;
    while ((max < 0 || n < max) && (e = lcm_eventlog_read_next_event(in)) != NULL) {
        for (int c = 0; c < 4; c++) {
            if (strcmp(e->channel, names[c]) || e->datalen < 0 || e->datalen > 65535)
                continue;
            /* the bare message: fuzz_intake signs what it publishes */
            size_t len = amfi_auth_bare_len(e->data, (size_t)e->datalen);
            unsigned char h[3] = {(unsigned char)c, (unsigned char)(len & 0xff),
                                  (unsigned char)(len >> 8)};
            fwrite(h, 1, 3, out);
            fwrite(e->data, 1, len, out);
            n++;
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    if (fclose(out) != 0) {
        fprintf(stderr, "lcm_intake_seed: write error on %s\n", argv[2]);
        return 1;
    }
    return 0;
}
