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
 * file is read, the list of keys for the manual (amfi_config_keys.h), and
 * what a reload compares and applies (amfi_config_diff,
 * amfi_config_apply_live): both walk the same tables, each row's kind
 * saying where its value lives (spans) and its F_LIVE flag whether SIGHUP
 * applies it.
 *
 * Adding a section: its fields in amfi_site_config with their defaults in
 * amfi_config_defaults(), a section_*.c with its table and checks, one row
 * in amfi_cfg_top_fields[] and its check in check_site(); the key, its range and its
 * default then appear in amfi_config_keys(), which the config_man test
 * holds against man/amfid.yaml.5.scd. A key SIGHUP applies at once gets
 * F_LIVE in its row (and the daemon must then read it live:
 * tests/daemon/daemon_reload_keys.sh has a case for every live key).
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
const field amfi_cfg_top_fields[] = {
    {.key = "site", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_site_fields},
    {.key = "bridge", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_bridge_fields},
    {.key = "sensors", .kind = &amfi_cfg_k_sensors, .aux = &amfi_cfg_sensors_list},
    {.key = "solver", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_solver_fields},
    {.key = "daemon", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_daemon_fields},
    {.key = "simulation", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_sim_fields},
    {.key = "alerts", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_alerts_fields},
    {.key = "metrics", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_metrics_fields},
    {.key = "report", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_report_fields},
    {.key = "detector", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_detector_fields},
    {.key = "ingest", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_ingest_fields},
    {.key = "classes", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_classes_fields},
    {.key = NULL}};

/* Checks that involve several keys, once the whole file is read; each finds
 * the line it blames in the record of where each key path was seen. The
 * defaults that follow bridge.span_m are filled first (bridge_check,
 * sensors_check), the model is built last, when every key is valid. */
static int check_site(ctx *x, void *base)
{
    amfi_site_config *c = base;

    if (amfi_cfg_bridge_check(x, c) || amfi_cfg_sensors_check(x, c) || amfi_cfg_solver_check(x, c) ||
        amfi_cfg_daemon_check(x, c) || amfi_cfg_sim_check(x, c) || amfi_cfg_site_check(x, c) || amfi_cfg_ops_check(x, c) ||
        amfi_cfg_ingest_check(x, c) || amfi_cfg_classes_check(x, c))
        return -1;
    return amfi_cfg_model_check(x, c);
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
    /* A site's solver (config/amfid.yaml, the reference of every key):
     * the modes below calc_rate_hz / 2, the same weights as the observable
     * ones at a third of the cost (docs/results/speed-estimation.md,
     * "Modes"), and room for six axles, the EU mix's trucks; a vehicle with
     * more is stored invalid (docs/results/multi-vehicle.md). The paper's
     * own choices (observable, 2) stay in paper-20m.yaml. */
    c->solver.modes = AMFI_MODES_RESOLVED;
    c->solver.n_modes = 0;
    c->solver.max_axles = 6;
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
    d->held_max_bytes = 101760000; /* 20 000 held passages of 5 088 bytes (x86-64) */
    /* every passage's samples, 90 days or 4 GiB of them, whichever is
     * less (docs/results/raw-passages.md: the sizes behind it) */
    d->raw_keep = AMFI_RAW_KEEP_ALL;
    d->raw_float32 = 0; /* exact: a re-weigh is amfid's to the last bit */
    d->raw_max_age_days = 90.0;
    d->raw_max_mib = 4096.0;
    d->workers = 2;
    d->queue_size = 256;
    d->recv_buf_bytes = 4194304;
    d->bus_queue = 20000;
    d->ring_s = 60.0;
    d->environment_max_skew_s = 3600.0;
    d->margin_s = 0.05;
    d->max_wait_s = 10.0;
    d->max_event_s = 10.0;
    d->max_event_axles = AMFI_MAX_EVENT_AXLES;
    d->inseparable_gap_m = 1.0;
    d->inseparable_share = 0.3;
    d->inseparable_quality = 8.0;
    d->inseparable_quality_lanes = 3.0;
    d->single_presence_only = 0;
    d->ind_temp_compensated = 1;
    d->ind_classes[0] = '\0';
    d->ind_min_gvw_kg = 0.0;
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
    c->report.units = AMFI_REPORT_UNITS_SI;
    /* a detector in step with the accelerometers until commissioning says */
    c->detector.clock_offset_s = 0.0;
    c->detector.speed_scale = 1.0;
    amfi_config_ingest_defaults(&c->ingest);
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
    d->natfreq.n_modes = 3;   /* the mode followed and two others: an end-span sensor of
                                 15 + 20 + 15 m sees modes 2 and 3 stronger than mode 1
                                 (docs/results/continuous-sensors.md) */
    d->natfreq_free_s = 2.0;  /* 11 periods of paper-20m's 5.7 Hz (docs/indicators.md) */
    d->natfreq_baseline_n = 200;
    d->natfreq_mode = 1;      /* follow the model's first mode (continuous bridges:
                                 docs/results/continuous-sensors.md) */
    d->natfreq_band = 0.2;
    /* The model_mismatch and natfreq alerts (docs/indicators.md section 10,
     * docs/results/model-fit.md and natural-frequency.md for the figures). */
    d->model_fit_free_s = 0.5;
    d->model_fit_calc_rate_hz = 2000;
    d->model_fit = (amfi_level_params){1, 25, 0.1, 0.05, 10, 25, 0, 0};
    d->natfreq_alert = (amfi_level_params){1, 15, 0.015, 0.0075, 5, 15, 0, 0};
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
    rc = amfi_cfg_walk_file(x, amfi_cfg_top_fields, &tmp, check_site);
    if (rc == 0)
        memcpy(c, &tmp, sizeof tmp);
    free(x);
    return rc;
}

typedef struct visit_arg {
    int (*visit)(const amfi_config_key *k, void *arg);
    void *arg;
    const amfi_site_config *dflt; /* the defaults, for the manual's strings */
    const amfi_site_config *a, *b; /* amfi_config_diff: the two compared */
    amfi_site_config *run;         /* amfi_config_apply_live: copied into */
    const amfi_site_config *n;     /* amfi_config_apply_live: copied from */
} visit_arg;

static int visit_key(const char *path, const field *f, const void *item_default, int live,
                     const visit_arg *va)
{
    char range[DOC_LEN], dflt[DOC_LEN];
    amfi_config_key k;

    amfi_cfg_describe_row(f, item_default ? item_default : (const void *)va->dflt, range,
                          dflt);
    k = (amfi_config_key){path, f->kind->type, range, dflt, (f->flags & F_REQUIRED) != 0,
                          live};
    return va->visit(&k, va->arg);
}

static int visit_one(const char *path, const field *f, const void *item_default, int live,
                     void *arg)
{
    return visit_key(path, f, item_default, live, arg);
}

int amfi_config_keys(int (*visit)(const amfi_config_key *k, void *arg), void *arg)
{
    amfi_site_config d;
    visit_arg va = {.visit = visit, .arg = arg, .dflt = &d};

    amfi_config_defaults(&d);
    return amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 1, visit_one, &va);
}

/* The spans of row f of the top table (the site config's offsets). */
static int row_spans(const field *f, span out[MAX_SPANS])
{
    int n = f->kind->spans(f, out);

    for (int i = 0; i < n; i++) /* a row's spans lie in the struct */
        if (out[i].off + out[i].len > sizeof(amfi_site_config) || out[i].len == 0)
            abort();
    return n;
}

static int diff_one(const char *path, const field *f, const void *item_default, int live,
                    void *arg)
{
    const visit_arg *va = arg;
    span sp[MAX_SPANS];
    const int n = row_spans(f, sp);

    (void)item_default; /* walked without items: lists compare as one key */
    for (int i = 0; i < n; i++)
        if (memcmp((const char *)va->a + sp[i].off, (const char *)va->b + sp[i].off,
                   sp[i].len) != 0)
            return visit_key(path, f, NULL, live, va);
    return 0;
}

int amfi_config_diff(const amfi_site_config *a, const amfi_site_config *b,
                     int (*visit)(const amfi_config_key *k, void *arg), void *arg)
{
    amfi_site_config d;
    visit_arg va = {.visit = visit, .arg = arg, .dflt = &d, .a = a, .b = b};

    if (!a || !b || !visit)
        return 0;
    amfi_config_defaults(&d);
    return amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, diff_one, &va);
}

static int apply_one(const char *path, const field *f, const void *item_default, int live,
                     void *arg)
{
    const visit_arg *va = arg;
    span sp[MAX_SPANS];
    int n;

    (void)path;
    (void)item_default;
    if (!live)
        return 0;
    n = row_spans(f, sp);
    for (int i = 0; i < n; i++)
        memcpy((char *)va->run + sp[i].off, (const char *)va->n + sp[i].off, sp[i].len);
    return 0;
}

void amfi_config_apply_live(amfi_site_config *run, const amfi_site_config *n)
{
    visit_arg va = {.run = run, .n = n};

    if (!run || !n || run == n)
        return;
    amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, apply_one, &va);
}
