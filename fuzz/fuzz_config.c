/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_config.c: libFuzzer target for the YAML site loader
 * (config/amfi_config.c, amfi_config_load). The input is written to a
 * temporary file (the loader reads files only). Findings: any sanitizer
 * report, and a refusal whose message does not start with "FILE:". Seeds:
 * fuzz/corpus/config/. */
#include <stddef.h>
#include <stdint.h>

#include "amfi_config.h"
#include "fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file_write(data, size);
    amfi_site_config c;
    char err[512] = "";
    if (amfi_config_load(path, &c, err, sizeof err) != 0)
        fuzz_file_expect_named(path, err);
    return 0;
}
