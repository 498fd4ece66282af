/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_as_built.h: the bridge as it was really built, and the detector as
 * it really measures, for the simulator (sim_publisher --as-built FILE).
 *
 * A site file describes the bridge from its drawings; no real bridge is its
 * drawings. An as-built file describes, apart from the site file, what the
 * simulated vehicles really cross and what the simulated detector really
 * reports, so that a commissioning (amfi-commission) can be tried against a
 * known answer. The site file (the design) is never changed by it: amfid
 * and the commissioning read the design, the simulator the as-built.
 *
 *   bridge:     the site file's bridge: section, every key of it (span_m,
 *               elements, E_pa, I_m4, A_m2, density_kgm3, damping, supports
 *               with their types and springs, segments, damage, name); a key
 *               left out keeps the design's value, a list given (supports,
 *               segments) replaces the design's whole
 *   sensors:    a list of {id, at_m | offset_m}: sensor `id` (one of the
 *               design's sensors ids) really is at at_m, or offset_m from
 *               where the design puts it; sensors not listed are where the
 *               design says
 *   detector:   clock_offset_s (the detector's clock minus the
 *               accelerometers': its entry times are late by this, s,
 *               [-1, 1]; negative: early), speed_scale (reported over true
 *               speed, [0.5, 2]), spacing_scale (reported over true axle
 *               spacings, [0.5, 2]; default: speed_scale, the spacings being
 *               measured from the speed): the names and meanings of the site
 *               file's detector: section, which holds what a commissioning
 *               found; here they are the truth it should find
 *
 * Keys are validated like the site file's ("FILE:LINE: key.path: problem",
 * the same walker and the same bridge: table); the as-built bridge is built
 * with libamfi once every key is valid, a refusal reported at its line.
 *
 * Workload: read once at start-up; no global state; the caller owns both
 * structs.
 */
#ifndef AMFI_AS_BUILT_H
#define AMFI_AS_BUILT_H

#include <stddef.h>

#include "amfi_config.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct amfi_detector_error {
    double clock_offset_s; /* reported entry time − true entry time, s */
    double speed_scale;    /* reported speed / true speed */
    double spacing_scale;  /* reported spacing / true spacing */
} amfi_detector_error;

typedef struct amfi_as_built {
    /* The design with the file's bridge: keys over it (site.bridge, site.name);
     * the rest of site is the design's and is not what the file describes.
     * First member: the bridge: key table's offsets are relative to it. */
    amfi_site_config site;
    /* True sensor positions, m, in the order of the design's sensors
     * (site.solver.sensor_x_m keeps the design's positions). */
    double sensor_x_m[AMFI_MAX_SENSORS];
    amfi_detector_error detector;
} amfi_as_built;

/* The identity: the design's bridge and sensors, an exact detector (0, 1, 1). */
void amfi_config_as_built_from_design(const amfi_site_config *design, amfi_as_built *out);

/* Load `path` over amfi_config_as_built_from_design(design). 0 and *out filled, or
 * −1, *out untouched and one line in err ("FILE:LINE: key.path: problem"). */
int amfi_config_as_built_load(const char *path, const amfi_site_config *design, amfi_as_built *out,
                       char *err, size_t errlen);

/* The keys of an as-built file (for sim_publisher(1) and its test): visit
 * is called with each key path ("detector.clock_offset_s", list items as
 * "sensors[].at_m"), its type, range, default and whether an item must
 * give it; the first non-zero return
 * stops the walk and is returned. */
int amfi_config_as_built_keys(int (*visit)(const char *path, const char *type, const char *range,
                                    const char *dflt, int required, void *arg),
                       void *arg);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_AS_BUILT_H */
