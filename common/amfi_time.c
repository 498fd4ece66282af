/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi_time.c: amfi_mono_s (amfi_time.h). Thread-safe. */
#define _POSIX_C_SOURCE 200809L
#include "amfi_time.h"

#include <time.h>

double amfi_mono_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
