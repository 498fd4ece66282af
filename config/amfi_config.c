/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_config.c: YAML site file -> amfi_site_config, validated, with
 * "FILE:LINE: key.path: problem" errors (amfi_config.h). This file only puts
 * the pieces together:
 *
 *   yaml_walk.c, yaml_scalar.c   the generic walker, scalars and messages
 *   section_bridge.c             bridge:
 *   section_solver.c             sensors:, solver:
 *   section_daemon.c             daemon:
 *   section_simulation.c         simulation:
 *   section_site.c               site:
 *   section_ops.c                alerts:, metrics:
 *   section_classes.c            classes:
 *   model_check.c                the bridge built, the solver's workspace bounded
 *
 * and holds the defaults, the order of the checks that run once the whole
 * file is read, and the list of keys for the manual (amfi_config_keys.h).
 *
 * Adding a section: its fields in amfi_site_config with their defaults in
 * amfi_config_defaults(), a section_*.c with its table and checks, one row
 * in top_fields[] and its check in check_site(); the key, its range and its
 * default then appear in amfi_config_keys(), which the config_man test
 * holds against man/amfid.yaml.5.scd.
 *
 * Workload: a few kB, once at start-up or reload; nothing here is fast-path.
 * No global state: distinct threads may load distinct files at once.
 */
#include "amfi_config.h"
#include "amfi_config_keys.h"
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The top level of a site file. */
static const field top_fields[] = {
    {.key = "site", .kind = &K_MAP, .aux = site_fields},
    {.key = "bridge", .kind = &K_MAP, .aux = bridge_fields},
    {.key = "sensors", .kind = &K_SENSORS, .aux = &sensors_list},
    {.key = "solver", .kind = &K_MAP, .aux = solver_fields},
    {.key = "daemon", .kind = &K_MAP, .aux = daemon_fields},
    {.key = "simulation", .kind = &K_MAP, .aux = sim_fields},
    {.key = "alerts", .kind = &K_MAP, .aux = alerts_fields},
    {.key = "metrics", .kind = &K_MAP, .aux = metrics_fields},
    {.key = "report", .kind = &K_MAP, .aux = report_fields},
    {.key = "detector", .kind = &K_MAP, .aux = detector_fields},
    {.key = "classes", .kind = &K_MAP, .aux = classes_fields},
    {.key = NULL}};

/* Checks that involve several keys, once the whole file is read; each finds
 * the line it blames in the record of where each key path was seen. The
 * defaults that follow bridge.span_m are filled first (bridge_check,
 * sensors_check), the model is built last, when every key is valid. */
static int check_site(ctx *x, void *base)
{
    amfi_site_config *c = base;

    if (bridge_check(x, c) || sensors_check(x, c) || solver_check(x, c) ||
        daemon_check(x, c) || sim_check(x, c) || site_check(x, c) || ops_check(x, c) ||
        classes_check(x, c))
        return -1;
    return model_check(x, c);
}

void amfi_config_defaults(amfi_site_config *c)
{
    memset(c, 0, sizeof *c);
    memcpy(c->name, "paper-20m", sizeof "paper-20m");
    memcpy(c->site.id, "local", sizeof "local");
    memcpy(c->site.name, "paper-20m", sizeof "paper-20m");
    c->site.latitude = NAN;
    c->site.longitude = NAN;
    amfi_bridge_params_paper20(&c->bridge);
    amfi_solver_params_default(&c->solver, c->bridge.span_m);
    /* The site recommendation (docs/results/paper.md): the bridge may still
     * vibrate from earlier traffic, so its state is estimated with the
     * forces, from a window starting 0.3 s before the first axle enters. */
    c->solver.free_initial_state = 1;
    c->solver.pre_roll_s = 0.3;
    amfi_lambda_default(&c->lambda);
    /* Speed estimation stays off by default: it costs ~100 sweeps a passage
     * and lets a 10 % stiffness loss into the speed (docs/results/speed-estimation.md). */
    c->speed_estimate = 0;
    amfi_speed_prior_default(&c->speed_prior);
    for (int i = 0; i < AMFI_MAX_SENSORS; i++) {
        c->sensor_id[i] = i < c->solver.n_sensors ? i : -1;
        c->sensor_rate_hz[i] = i < c->solver.n_sensors ? AMFI_CONFIG_DEFAULT_RATE_HZ : 0.0;
    }
    amfi_daemon_config *d = &c->daemon;
    strcpy(d->ch_accel, "AMFI_ACCEL");
    strcpy(d->ch_vehicle, "AMFI_VEHICLE");
    strcpy(d->ch_truth, "AMFI_TRUTH");
    strcpy(d->ch_passage, "AMFI_PASSAGE");
    strcpy(d->ch_indicator, "AMFI_INDICATOR");
    strcpy(d->ch_alert, "AMFI_ALERT");
    strcpy(d->ch_status, "AMFI_STATUS");
    strcpy(d->ch_environment, "AMFI_ENVIRONMENT");
    strcpy(d->db_path, "amfi.db");
    d->simulation = 0;
    d->bus_auth = 1;
    d->bus_max_skew_s = 300.0;
    d->sync_full = 1;
    d->workers = 2;
    d->queue_size = 256;
    d->recv_buf_bytes = 4194304;
    d->bus_queue = 20000;
    d->ring_s = 60.0;
    d->environment_max_skew_s = 3600.0;
    d->margin_s = 0.05;
    d->max_wait_s = 10.0;
    d->max_event_s = 10.0;
    d->max_event_axles = AMFI_MAX_AXLES;
    d->inseparable_gap_m = 1.0;
    d->inseparable_share = 0.3;
    d->inseparable_quality = 5.0;
    d->inseparable_quality_lanes = 3.0;
    d->single_presence_only = 0;
    d->ind_temp_compensated = 1;
    d->status_period_s = 1.0;
    d->alert_timeout_s = 30.0;
    d->alert_max_running = 4;
    d->alert_stop_wait_s = 10.0;
    d->metrics_interval_s = 15.0;
    /* EU Directive 96/53/EC, Annex I: 40 t for a vehicle combination
     * (2.2.2), 11.5 t for a driving axle (3.2); the site may set its own. */
    c->report.gvw_limit_kg = 40000.0;
    c->report.axle_limit_kg = 11500.0;
    c->report.bin_kg = 2000.0;
    /* a detector in step with the accelerometers until commissioning says */
    c->detector.clock_offset_s = 0.0;
    c->detector.speed_scale = 1.0;
    amfi_class_params_default(&c->classes); /* the European classes, 96/53/EC's limits */
    /* The engine's defaults (docs/indicators.md has the simulation behind
     * each value); set field by field, so the padding stays zero. */
    amfi_indicator_params_default(&d->indicators);
    amfi_speed_drift_params_default(&d->speed_drift);
    amfi_scale_params_default(&d->scale);
    d->scale_enabled = 1;
    d->scale_max_temp_gap_s = 7200.0;
    amfi_known_truck_params_default(&d->known_truck);
    d->known_truck_enabled = 1;
    amfi_natfreq_params_default(&d->natfreq);
    d->natfreq_free_s = 2.0;  /* 11 periods of paper-20m's 5.7 Hz (docs/indicators.md) */
    d->natfreq_baseline_n = 200;
    /* Bounded intake (docs/daemon.md): generous against real traffic. */
    d->vehicle_ahead_s = 120.0;
    d->min_speed_mps = 2.0;
    d->max_length_m = 40.0;
    d->accel_margin = 4.0;
    d->vehicles_per_s = 10.0;
    d->environment_per_s = 10.0;
    d->truth_per_s = 50.0;
    d->burst_s = 10.0;
    d->summary_period_s = 60.0;
    d->env_min_interval_s = 1.0;
    d->deck_max_rate_c_min = 2.0;
    strcpy(d->calibration_sources, "sim_publisher");
    d->calibration_min_kg = 3500.0;
    d->calibration_max_kg = 60000.0;
    /* sim_publisher's ideal simulation (docs/simulator.md): every inaccuracy
     * is switched on explicitly. */
    amfi_sim_config *m = &c->sim;
    m->vehicles = 10;
    m->first = 0;
    m->seed = 1;
    m->damage = 0.0;
    m->damage_step_at = -1;
    m->profile_class = 'A';
    m->track_std = 2.0;
    m->environment = 0;
    m->time_compression = 1.0;
    m->environment_period_s = 60.0;
    m->scan_rate_hz = AMFI_CONFIG_DEFAULT_RATE_HZ; /* the sensors' default rate_hz */
    m->noise = 0.0;
    m->speed_err_mean = 0.0;
    m->speed_err_std = 0.0;
    m->preceding = 0;
    m->gap_lo_s = m->gap_hi_s = 0.0;
    m->pre_s = 0.5;
    m->post_s = 0.5;
    m->dt_s = 1e-4;
    m->speedup = 1.0;
    m->headway_s = 0.0;
    m->flow_veh_h = 0.0;
    m->min_headway_s = 0.5;
    m->lanes = 1;
    m->noise_ms2 = 0.0;
    m->block = 100;
    m->start_utime = 1767225600000000LL; /* 2026-01-01T00:00:00Z */
    m->detector_lead_s = 1.0;
}

int amfi_config_load(const char *path, amfi_site_config *c, char *err, size_t errlen)
{
    amfi_site_config tmp;
    ctx *x;
    int rc;

    if (err && errlen)
        err[0] = '\0';
    if (!path || !c) {
        if (err && errlen)
            snprintf(err, errlen, "amfi_config_load: %s is NULL",
                     path ? "config" : "path");
        return -1;
    }
    x = calloc(1, sizeof *x); /* the record of key lines: 25 kB */
    if (!x) {
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    x->file = path;
    x->err = err;
    x->errlen = errlen;
    amfi_config_defaults(&tmp);
    rc = walk_file(x, top_fields, &tmp, check_site);
    if (rc == 0)
        memcpy(c, &tmp, sizeof tmp);
    free(x);
    return rc;
}

typedef struct visit_arg {
    int (*visit)(const amfi_config_key *k, void *arg);
    void *arg;
} visit_arg;

static int visit_one(const char *path, const char *type, const char *range,
                     const char *dflt, int required, void *arg)
{
    const visit_arg *va = arg;
    amfi_config_key k = {path, type, range, dflt, required};

    return va->visit(&k, va->arg);
}

int amfi_config_keys(int (*visit)(const amfi_config_key *k, void *arg), void *arg)
{
    amfi_site_config d;
    visit_arg va = {visit, arg};

    amfi_config_defaults(&d);
    return describe_table(top_fields, "", &d, visit_one, &va);
}
