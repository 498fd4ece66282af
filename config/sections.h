/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sections.h: the sections of a site file (internal to config/), each
 * in its own file: its key tables for the walker (yaml_walk.h), its value
 * kinds that need more than a number or a name, and the checks that involve
 * several of its keys. amfi_config.c puts them under one top-level table and
 * runs the checks across sections.
 *
 *   section_bridge.c      bridge:      the beam, its damping and supports
 *   section_solver.c      sensors:, solver:  positions, solver and λ policy,
 *                         and the bound on the solver's workspace
 *   section_daemon.c      daemon:      amfid's bus, store, threads, indicators
 *   section_simulation.c  simulation:  sim_publisher's settings
 *   section_site.c        site:        which bridge (id, name, position)
 *   section_ops.c         alerts:, metrics:  notices and health metrics
 *   section_report.c      report:      what amfi-report holds passages against
 *   section_detector.c    detector:    the vehicle detector's clock offset and speed scale
 *   section_classes.c     classes:     axle groups, vehicle classes, legal limits
 *
 * Every function runs on the loader's (caller's) thread.
 */
#ifndef AMFI_CONFIG_SECTIONS_H
#define AMFI_CONFIG_SECTIONS_H

#include "amfi_config.h"
#include "yaml_walk.h"

#define MAX_MODE_NO (2 * (1000 + 1)) /* DOFs of the largest mesh, before supports */

/* Offsets into amfi_site_config. */
#define SC(m) offsetof(amfi_site_config, m)

/* Bounds on one solver's workspace (amfi_solver_create sizes it for
 * (max_duration_s + pre_roll_s + post_roll_s) · calc_rate_hz steps; amfid
 * holds one per worker): documented in amfid.yaml(5). */
#define AMFI_CONFIG_MAX_STEPS 10000000.0
#define AMFI_CONFIG_MAX_WORKSPACE_BYTES (1024.0 * 1024.0 * 1024.0)

/* The top level of a site file (amfi_config.c): the sections under it. */
extern const field amfi_cfg_top_fields[];
extern const field amfi_cfg_bridge_fields[]; /* bridge: */
extern const kind amfi_cfg_k_sensors;        /* sensors: (a list of amfi_cfg_sensors_list) */
extern const list_schema amfi_cfg_sensors_list;
extern const field amfi_cfg_solver_fields[]; /* solver: */
extern const field amfi_cfg_daemon_fields[]; /* daemon: */
extern const field amfi_cfg_sim_fields[];    /* simulation: */
extern const field amfi_cfg_site_fields[];   /* site: */
extern const field amfi_cfg_alerts_fields[]; /* alerts: */
extern const field amfi_cfg_metrics_fields[]; /* metrics: */
extern const field amfi_cfg_report_fields[]; /* report: */
extern const field amfi_cfg_detector_fields[]; /* detector: */
extern const field amfi_cfg_ingest_fields[]; /* ingest: (section_ingest.c) */
extern const field amfi_cfg_classes_fields[]; /* classes: (section_classes.c) */

/* The rows of detector.clock_offset_s and detector.speed_scale (names,
 * meanings, ranges), for an amfi_detector_config at byte `at` of the base,
 * with `fl` added to their flags (F_LIVE in the site file, 0 as built):
 * the site file's detector: section and the as-built file's (whose
 * amfi_detector_error starts alike, checked in as_built.c). */
#define AMFI_CFG_DETECTOR_ROWS(at, fl)                                               \
    {.key = "clock_offset_s", .kind = &amfi_cfg_k_double,                            \
     .off = (at) + offsetof(amfi_detector_config, clock_offset_s), .lo = -1, .hi = 1, \
     .flags = (fl)},                                                                 \
    {.key = "speed_scale", .kind = &amfi_cfg_k_double,                               \
     .off = (at) + offsetof(amfi_detector_config, speed_scale), .lo = 0.5, .hi = 2,   \
     .flags = (fl)}
extern const enum_name amfi_cfg_onoff_names[]; /* off | on (section_daemon.c) */

/* Free DOFs of the beam once the supports (snapped to nodes) are applied. */
int amfi_cfg_bridge_free_dofs(const amfi_bridge_params *b);

/* The checks of one section that involve several of its keys (or that
 * follow defaults of another, noted in each); 0 or −1 after amfi_cfg_fail(). */
int amfi_cfg_bridge_check(ctx *x, amfi_site_config *c);
int amfi_cfg_sensors_check(ctx *x, amfi_site_config *c);
int amfi_cfg_solver_check(ctx *x, amfi_site_config *c);
int amfi_cfg_daemon_check(ctx *x, amfi_site_config *c);
int amfi_cfg_sim_check(ctx *x, amfi_site_config *c);
int amfi_cfg_site_check(ctx *x, amfi_site_config *c);
int amfi_cfg_ops_check(ctx *x, amfi_site_config *c);
int amfi_cfg_ingest_check(ctx *x, amfi_site_config *c);
int amfi_cfg_classes_check(ctx *x, amfi_site_config *c);

/* The model itself: the bridge built with libamfi (its refusals reported at
 * the line of the bridge key or section that caused them) and the solver's
 * workspace counted against the bounds above (section_solver.c). */
int amfi_cfg_model_check(ctx *x, amfi_site_config *c);

#endif /* AMFI_CONFIG_SECTIONS_H */
