/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_accel_csv.c: libFuzzer target for the passage CSV reader
 * (accel_csv_read_max, CMake target amfi_accel_csv): plain text and gzip,
 * detected from the content. The input goes through a temporary file; the
 * row limit is 100000 so that one input stays fast. Findings: any sanitizer
 * report, a refusal not starting with "FILE:", an accepted file outside the
 * reader's promises (n rows in range, a finite positive rate). Seeds:
 * fuzz/corpus/accel_csv/. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "accel_csv.h"
#include "fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file_write(data, size);
    accel_csv c;
    char err[512] = "";
    if (accel_csv_read_max(path, 100000, &c, err, sizeof err) != 0) {
        fuzz_file_expect_named(path, err);
        if (c.n != 0 || c.accel != NULL || c.n_channels != 0)
            abort();
        return 0;
    }
    if (c.n < ACCEL_CSV_MIN_ROWS || c.n > 100000 || !c.accel || !(c.rate_hz > 0) ||
        !isfinite(c.rate_hz)) {
        fprintf(stderr, "fuzz_accel_csv: accepted n=%d rate=%g\n", c.n, c.rate_hz);
        abort();
    }
    if (c.n_channels < 1 || c.n_channels > ACCEL_CSV_MAX_CHANNELS || c.accel != c.channel[0]) {
        fprintf(stderr, "fuzz_accel_csv: accepted %d channels\n", c.n_channels);
        abort();
    }
    volatile double sum = 0; /* every value readable (ASan sees a short array) */
    for (int k = 0; k < c.n_channels; k++) {
        /* ids: −1 only for the one 't,accel' column, else 0 .. 255, each once */
        int id = c.channel_id[k];
        if (!c.channel[k] || (id < 0 && !(id == -1 && c.n_channels == 1)) || id > 255)
            abort();
        for (int j = 0; j < k; j++)
            if (c.channel_id[j] == id)
                abort();
        for (int i = 0; i < c.n; i++)
            sum += c.channel[k][i];
    }
    (void)sum;
    accel_csv_free(&c);
    return 0;
}
