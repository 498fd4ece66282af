/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_file.h: for the libFuzzer targets whose reader takes a path
 * (fuzz_config, fuzz_accel_csv, fuzz_traffic): one temporary file per
 * process, rewritten with each input and removed at exit, and the check that
 * a refusal names the file. Single-threaded, as libFuzzer calls the target.
 */
#ifndef AMFI_FUZZ_FILE_H
#define AMFI_FUZZ_FILE_H

#include <stddef.h>
#include <stdint.h>

/* Writes data[0 .. size) to the process's temporary file (in $TMPDIR or
 * /tmp, created on first use) and returns its path. Aborts on an I/O error. */
const char *fuzz_file_write(const uint8_t *data, size_t size);

/* Aborts (a finding) unless err is non-empty and starts with "PATH:". */
void fuzz_file_expect_named(const char *path, const char *err);

#endif /* AMFI_FUZZ_FILE_H */
