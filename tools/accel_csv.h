/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * accel_csv.h: reader for one recorded passage as CSV, plain or gzip.
 *
 * Format (one sensor):
 *
 *     t,accel                header, exactly these two names (spaces around a
 *     0.0000,0.0123          name, CRLF line ends and a UTF-8 BOM allowed)
 *     0.0002,-0.0456         t in s, strictly increasing and uniformly sampled;
 *     ...                    accel in m/s², positive downward
 *
 * or several sensors, one column each, named by the sensor's id (the `id`
 * of the site file's sensors, 0 .. 255, decimal without sign or leading
 * zeros), in any order, each id once, 1 .. ACCEL_CSV_MAX_CHANNELS of them:
 *
 *     t,accel_0,accel_1,accel_2
 *     0.0000,0.0123,0.0101,0.0098
 *
 * Uniform means |Δt_k − Δt_mean| <= 1e-6·Δt_mean + 1e-9 s for every step, with
 * Δt_mean = (t_last − t_first)/(n − 1). Blank lines are allowed only at the end.
 *
 * Workload: files of a few thousand rows (1 s at 5000 Hz), read once by a
 * tool; the whole file is held in memory (16 bytes per row while reading,
 * 8 bytes per row after). Hard limits: 4096 characters per line (without
 * the line end), ACCEL_CSV_MAX_ROWS rows, at least ACCEL_CSV_MIN_ROWS rows.
 *
 * Errors are one line, "FILE:LINE: problem" (LINE is 1-based; the header is
 * line 1). Any input, binary junk included, gives either a result or such a
 * message: never a crash, never a hang, never a silently shortened file (a
 * truncated or corrupt .gz is an error).
 */
#ifndef AMFI_TOOLS_ACCEL_CSV_H
#define AMFI_TOOLS_ACCEL_CSV_H

#include <stddef.h>

#define ACCEL_CSV_MAX_LINE 4096     /* characters per line, without CR/LF */
#define ACCEL_CSV_MIN_ROWS 16       /* fewer samples is an error */
#define ACCEL_CSV_MAX_ROWS 50000000 /* more rows is an error */

#define ACCEL_CSV_MAX_CHANNELS 8     /* accel columns (amfi.h's AMFI_MAX_SENSORS) */

typedef struct accel_csv {
    int n;          /* samples, ACCEL_CSV_MIN_ROWS .. ACCEL_CSV_MAX_ROWS */
    double t0_s;    /* time of the first sample, s (the file's own clock) */
    double rate_hz; /* (n − 1) / (t_last − t_first), Hz */
    double *accel;  /* n values, m/s², positive downward: the first column
                       (channel[0]); owned, free with accel_csv_free() */
    int n_channels; /* accel columns, 1 .. ACCEL_CSV_MAX_CHANNELS */
    int channel_id[ACCEL_CSV_MAX_CHANNELS]; /* sensor id of column k + 2
                                               (accel_ID), −1 for 't,accel' */
    double *channel[ACCEL_CSV_MAX_CHANNELS]; /* n values each, in the file's
                                                column order; owned */
} accel_csv;

/* Read `path` (plain text or gzip, detected from the content; a name ending
 * in ".gz" must hold gzip data). Returns 0 and fills *out, or −1, leaves *out
 * empty (n = 0, accel = NULL) and writes a one-line message into err (may be
 * NULL when errlen is 0). */
int accel_csv_read(const char *path, accel_csv *out, char *err, size_t errlen);

/* The same with a smaller row limit (1 .. ACCEL_CSV_MAX_ROWS), for tests and
 * callers that know their passages are short. */
int accel_csv_read_max(const char *path, long max_rows, accel_csv *out,
                       char *err, size_t errlen);

/* Frees c->accel and empties *c. NULL-safe, idempotent. */
void accel_csv_free(accel_csv *c);

#endif /* AMFI_TOOLS_ACCEL_CSV_H */
