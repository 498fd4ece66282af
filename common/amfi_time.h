/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_time.h: the one monotonic clock of the amfi programs, for timing
 * and timeouts (never for data time). Thread-safe.
 */
#ifndef AMFI_COMMON_TIME_H
#define AMFI_COMMON_TIME_H

/* Seconds on CLOCK_MONOTONIC (arbitrary origin). */
double amfi_mono_s(void);

#endif
