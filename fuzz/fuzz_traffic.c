/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_traffic.c: libFuzzer target for the WIM traffic reader of the
 * simulator (sim_publisher/traffic.c, amfi_traffic_read, CMake target
 * amfi_sim). The input goes through a temporary file. Findings: any
 * sanitizer report, a refusal not starting with "FILE:", an accepted list
 * outside the documented ranges (n >= 1, 2 .. AMFI_MAX_AXLES axles). Seeds:
 * fuzz/corpus/traffic/. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "fuzz_file.h"
#include "traffic.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file_write(data, size);
    amfi_vehicle_rec *recs = NULL;
    int n = -1;
    char err[512] = "";
    if (amfi_traffic_read(path, &recs, &n, err, sizeof err) != 0) {
        fuzz_file_expect_named(path, err);
        if (recs != NULL || n != 0)
            abort();
        return 0;
    }
    if (n < 1 || !recs)
        abort();
    for (int i = 0; i < n; i++)
        if (recs[i].n_axles < 2 || recs[i].n_axles > AMFI_MAX_AXLES) {
            fprintf(stderr, "fuzz_traffic: record %d has %d axles\n", i, recs[i].n_axles);
            abort();
        }
    amfi_traffic_free(recs);
    return 0;
}
