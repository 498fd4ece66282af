/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * traffic.h: reader for a weigh-in-motion (WIM) style vehicle list, the
 * traffic the simulator drives over the bridge (docs/simulator-inputs.md).
 *
 * Format: CSV, one vehicle per line, a header naming the columns (any order):
 *
 *     timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m
 *     12.480,1,24.31,9120,4310,4810,4.62
 *
 *   timestamp_s   arrival time, s, finite, non-decreasing down the file
 *   lane          integer 1 .. AMFI_TRAFFIC_MAX_LANE
 *   speed_mps     1 .. 60 m/s
 *   gvw_kg        500 .. 100000 kg, equal to the sum of the axle loads
 *                 within AMFI_TRAFFIC_GVW_TOL (1 %) of that sum
 *   axleI_kg      I = 1 .. n, n = 2 .. AMFI_MAX_AXLES; > 0 kg (front first)
 *   spacingI_m    I = 1 .. n − 1, distance from axle I to axle I+1, 0.5 .. 30 m
 *
 * Any other column is an error, as are a duplicate, a gap in the axle or
 * spacing numbering and a spacing count other than n − 1. The vehicle
 * class of such a record is guessed from its axle count and spacings
 * (amfi_vclass_guess: R2 for two axles; −1 when no class fits).
 *
 * The class format (amfi-population's; every vehicle its own axle count):
 *
 *     timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,spacings_m
 *     12.480,1,24.31,A23,37400,5,6800;10600;6667;6667;6666,3.71;6.02;1.31;1.31
 *
 *   class         a class of vclass.h (R2, R3, R4, A22, A23, A32, A33)
 *   n_axles       2 .. AMFI_MAX_AXLES, the class's axle count
 *   axle_kg       n_axles loads separated by ';', each (0, 30000] kg
 *   spacings_m    n_axles − 1 spacings separated by ';', 0.5 .. 30 m,
 *                 fitting the class's groups (amfi_vclass_check: inside a
 *                 group 0.9 .. 2.5 m, between groups >= 2 m)
 *
 * The two formats do not mix in one header. Spaces and tabs
 * around a field, CRLF line ends and a UTF-8 BOM are allowed; blank lines
 * only at the end. No quoting, no comments.
 *
 * Errors are one line, "FILE:LINE: column: problem" (LINE 1-based, the
 * header is line 1), e.g.
 *     pop.csv:7: speed_mps: 75 is out of range [1, 60] m/s
 *     pop.csv:9: gvw_kg: 9000 kg differs by 12.5 % from the sum of the axle
 *         loads, 8000 kg (tolerance 1 %)
 * without the column for a problem of the whole line, and without LINE for
 * a file that cannot be opened.
 *
 * Workload: read once at start-up; the whole list is held in memory
 * (sizeof(amfi_vehicle_rec) = 248 bytes per vehicle on x86-64), at most
 * AMFI_TRAFFIC_MAX_ROWS vehicles, lines of at most AMFI_TRAFFIC_MAX_LINE
 * characters. O(rows).
 */
#ifndef AMFI_SIM_TRAFFIC_H
#define AMFI_SIM_TRAFFIC_H

#include <stddef.h>

#include "amfi/amfi.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AMFI_TRAFFIC_MAX_LINE 4096
#define AMFI_TRAFFIC_MAX_ROWS 10000000L
#define AMFI_TRAFFIC_MAX_LANE 8
#define AMFI_TRAFFIC_GVW_TOL 0.01 /* |gvw − Σ axles| <= TOL · Σ axles */

typedef struct amfi_vehicle_rec {
    double timestamp_s;                 /* arrival, s (the file's clock) */
    int lane;                           /* 1 .. AMFI_TRAFFIC_MAX_LANE */
    double speed_mps;                   /* 1 .. 60 m/s */
    double gvw_kg;                      /* 500 .. 100000 kg, as in the file */
    int n_axles;                        /* 2 .. AMFI_MAX_AXLES */
    double axle_kg[AMFI_MAX_AXLES];     /* static axle loads, kg, > 0, front
                                           first; 0 past n_axles */
    double spacing_m[AMFI_MAX_AXLES];   /* spacing_m[i]: axle i to axle i+1,
                                           0.5 .. 30 m; n_axles − 1 used, 0
                                           past them */
    int vclass;                         /* vclass.h class index; −1: none fits
                                           (a wide-format record) */
    long line;                          /* its line in the file */
} amfi_vehicle_rec;

/* Read `path`. Returns 0 with *recs (an array of *n >= 1 records in file
 * order; free with amfi_traffic_free) or AMFI_EINVAL (bad or unreadable
 * file, empty list) / AMFI_ENOMEM, *recs = NULL, *n = 0, and one line in err
 * (may be NULL when errlen is 0). */
int amfi_traffic_read(const char *path, amfi_vehicle_rec **recs, int *n, char *err,
                      size_t errlen);

void amfi_traffic_free(amfi_vehicle_rec *recs); /* NULL-safe */

#ifdef __cplusplus
}
#endif
#endif /* AMFI_SIM_TRAFFIC_H */
