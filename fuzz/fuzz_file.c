/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_file.c: the temporary input file of the path-based fuzz targets
 * (fuzz_file.h). Single-threaded. */
#include "fuzz_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char path[4096];
static int fd = -1;

static void remove_file(void)
{
    if (fd >= 0)
        unlink(path);
}

const char *fuzz_file_write(const uint8_t *data, size_t size)
{
    if (fd < 0) {
        const char *dir = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/amfi-fuzz-XXXXXX", dir && *dir ? dir : "/tmp");
        fd = mkstemp(path);
        if (fd < 0) {
            perror(path);
            abort();
        }
        atexit(remove_file);
    }
    if (ftruncate(fd, 0) != 0) {
        perror(path);
        abort();
    }
    size_t done = 0;
    while (done < size) {
        ssize_t k = pwrite(fd, data + done, size - done, (off_t)done);
        if (k <= 0) {
            perror(path);
            abort();
        }
        done += (size_t)k;
    }
    return path;
}

void fuzz_file_expect_named(const char *p, const char *err)
{
    size_t n = strlen(p);
    if (strncmp(err, p, n) != 0 || err[n] != ':') {
        fprintf(stderr, "fuzz: a refusal that does not name the file %s: \"%s\"\n", p, err);
        abort();
    }
}
