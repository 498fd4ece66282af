/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_ops.c: the alerts: and metrics: sections of a site file, what
 * amfid tells the people and programs that watch it: a program run for
 * every raised and cleared alert (alerts.command, like smartd's -M exec),
 * and its counters in Prometheus' text format for node-exporter's textfile
 * collector (metrics.textfile). Both are off by default. Also the
 * speed-drift alert's settings (alerts.speed_drift, speed_drift.h), the scale
 * indicator's (alerts.scale, scale.h) and the known truck's
 * (alerts.known_truck, known_truck.h), the model_mismatch alert's
 * (alerts.model_fit) and the natural frequency's (alerts.natfreq), both
 * level_rule.h. Runs on the loader's thread.
 */
#include "sections.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define OPS(m) offsetof(amfi_site_config, daemon.m)
#define OPS_CAP(m) sizeof(((amfi_daemon_config *)0)->m)

#define DRIFT(m) OPS(speed_drift.m)

static const field speed_drift_fields[] = {
    {.key = "enabled", .kind = &amfi_cfg_k_enum, .off = DRIFT(enabled), .aux = amfi_cfg_onoff_names},
    {.key = "window", .kind = &amfi_cfg_k_int, .off = DRIFT(window), .lo = 2,
     .hi = AMFI_SPEED_DRIFT_MAX_WINDOW},
    {.key = "threshold", .kind = &amfi_cfg_k_double, .off = DRIFT(threshold), .lo = 0,
     .hi = AMFI_SPEED_DRIFT_MAX_THRESHOLD, .flags = F_LO_OPEN},
    {.key = NULL}};

#define SCALE(m) OPS(scale.m)

/* alerts.scale: the ranges are amfi_scale_params_check's (ops_check runs it
 * too, for the cross-field rules: floor_c below knee_c, block times
 * baseline_blocks). */
static const field scale_fields[] = {
    {.key = "enabled", .kind = &amfi_cfg_k_enum, .off = OPS(scale_enabled), .aux = amfi_cfg_onoff_names},
    {.key = "max_temp_gap_s", .kind = &amfi_cfg_k_double, .off = OPS(scale_max_temp_gap_s), .lo = 1,
     .hi = 86400},
    {.key = "block", .kind = &amfi_cfg_k_int, .off = SCALE(block), .lo = 50, .hi = 1000000},
    {.key = "baseline_blocks", .kind = &amfi_cfg_k_int, .off = SCALE(baseline_blocks), .lo = 4,
     .hi = 10000},
    {.key = "class_split_kg", .kind = &amfi_cfg_k_double, .off = SCALE(class_split_kg), .lo = 100,
     .hi = AMFI_IND_MAX_GVW_KG},
    {.key = "share_range", .kind = &amfi_cfg_k_double, .off = SCALE(share_range), .lo = 0.01, .hi = 1},
    {.key = "ref_c", .kind = &amfi_cfg_k_double, .off = SCALE(ref_c), .lo = -30, .hi = 40},
    {.key = "knee_c", .kind = &amfi_cfg_k_double, .off = SCALE(knee_c), .lo = -30, .hi = 30},
    {.key = "floor_c", .kind = &amfi_cfg_k_double, .off = SCALE(floor_c), .lo = -60, .hi = 29.5},
    {.key = "warm_slope", .kind = &amfi_cfg_k_double, .off = SCALE(warm_slope), .lo = -0.1, .hi = 0.1},
    {.key = "frost_slope", .kind = &amfi_cfg_k_double, .off = SCALE(frost_slope), .lo = -0.1, .hi = 0.1},
    {.key = "slope_prior_sd", .kind = &amfi_cfg_k_double, .off = SCALE(slope_prior_sd), .lo = 0,
     .hi = 0.1},
    {.key = "design_shift", .kind = &amfi_cfg_k_double, .off = SCALE(design_shift), .lo = 1e-4,
     .hi = 0.5, .flags = F_HI_OPEN},
    {.key = "false_alarms_per_year", .kind = &amfi_cfg_k_double, .off = SCALE(false_alarms_per_year),
     .lo = 1e-4, .hi = 1000},
    {.key = "vehicles_per_day", .kind = &amfi_cfg_k_double, .off = SCALE(vehicles_per_day), .lo = 1,
     .hi = 1e7},
    {.key = "clear_after", .kind = &amfi_cfg_k_int, .off = SCALE(clear_after), .lo = 1, .hi = 1000000},
    {.key = NULL}};

#define TRUCK(m) OPS(known_truck.m)

static const field known_truck_fields[] = {
    {.key = "enabled", .kind = &amfi_cfg_k_enum, .off = OPS(known_truck_enabled), .aux = amfi_cfg_onoff_names},
    {.key = "baseline_runs", .kind = &amfi_cfg_k_int, .off = TRUCK(baseline_runs), .lo = 2, .hi = 1000},
    {.key = "run_sd", .kind = &amfi_cfg_k_double, .off = TRUCK(run_sd), .lo = 1e-4, .hi = 1},
    {.key = "design_shift", .kind = &amfi_cfg_k_double, .off = TRUCK(design_shift), .lo = 1e-4,
     .hi = 0.5, .flags = F_HI_OPEN},
    {.key = "false_alarms_per_year", .kind = &amfi_cfg_k_double, .off = TRUCK(false_alarms_per_year),
     .lo = 1e-4, .hi = 1000},
    {.key = "runs_per_year", .kind = &amfi_cfg_k_double, .off = TRUCK(runs_per_year), .lo = 1,
     .hi = 1e5},
    {.key = "clear_after", .kind = &amfi_cfg_k_int, .off = TRUCK(clear_after), .lo = 1, .hi = 1000000},
    {.key = NULL}};

/* alerts.model_fit and alerts.natfreq: a median level rule each
 * (level_rule.h; amfi_level_params_check in ops_check for clear < raise). */
#define LEVEL_FIELDS(m, unit_hi)                                                                  \
    {.key = "enabled", .kind = &amfi_cfg_k_enum, .off = OPS(m.enabled), .aux = amfi_cfg_onoff_names}, \
    {.key = "window", .kind = &amfi_cfg_k_int, .off = OPS(m.window), .lo = 1, .hi = 10000},      \
    {.key = "raise", .kind = &amfi_cfg_k_double, .off = OPS(m.raise), .lo = 0, .hi = unit_hi,    \
     .flags = F_LO_OPEN},                                                                        \
    {.key = "clear", .kind = &amfi_cfg_k_double, .off = OPS(m.clear), .lo = 0, .hi = unit_hi},   \
    {.key = "raise_after", .kind = &amfi_cfg_k_int, .off = OPS(m.raise_after), .lo = 1,          \
     .hi = 100000},                                                                              \
    {.key = "clear_after", .kind = &amfi_cfg_k_int, .off = OPS(m.clear_after), .lo = 1,          \
     .hi = 100000}

static const field model_fit_fields[] = {
    {.key = "free_s", .kind = &amfi_cfg_k_double, .off = OPS(model_fit_free_s), .lo = 0.2, .hi = 10},
    {.key = "calc_rate_hz", .kind = &amfi_cfg_k_double, .off = OPS(model_fit_calc_rate_hz), .lo = 0,
     .hi = 1e6, .flags = F_LO_OPEN},
    LEVEL_FIELDS(model_fit, 10),
    {.key = NULL}};

static const field natfreq_alert_fields[] = {
    LEVEL_FIELDS(natfreq_alert, 0.5),
    {.key = NULL}};

const field amfi_cfg_alerts_fields[] = {
    {.key = "command", .kind = &amfi_cfg_k_path, .off = OPS(alert_command), .hi = OPS_CAP(alert_command)},
    {.key = "command_timeout_s", .kind = &amfi_cfg_k_double, .off = OPS(alert_timeout_s), .lo = 0,
     .hi = 3600, .flags = F_LO_OPEN},
    {.key = "command_max_running", .kind = &amfi_cfg_k_int, .off = OPS(alert_max_running), .lo = 1,
     .hi = 64},
    {.key = "command_stop_wait_s", .kind = &amfi_cfg_k_double, .off = OPS(alert_stop_wait_s), .lo = 0,
     .hi = 30},
    {.key = "speed_drift", .kind = &amfi_cfg_k_map, .aux = speed_drift_fields},
    {.key = "scale", .kind = &amfi_cfg_k_map, .aux = scale_fields},
    {.key = "known_truck", .kind = &amfi_cfg_k_map, .aux = known_truck_fields},
    {.key = "model_fit", .kind = &amfi_cfg_k_map, .aux = model_fit_fields},
    {.key = "natfreq", .kind = &amfi_cfg_k_map, .aux = natfreq_alert_fields},
    {.key = NULL}};

const field amfi_cfg_metrics_fields[] = {
    {.key = "textfile", .kind = &amfi_cfg_k_path, .off = OPS(metrics_path), .hi = OPS_CAP(metrics_path)},
    {.key = "interval_s", .kind = &amfi_cfg_k_double, .off = OPS(metrics_interval_s), .lo = 1,
     .hi = 3600},
    {.key = NULL}};

/* A parameter check's failure under alerts.SECTION: on the blamed key's
 * line, else the section's, else the alerts: line. */
static int blame(ctx *x, const char *section, const char *blamed, const char *why)
{
    char path[PATH_LEN], sec[PATH_LEN];
    amfi_cfg_pathf(path, "alerts.%s.%s", section, blamed ? blamed : "");
    amfi_cfg_pathf(sec, "alerts.%s", section);
    int line = amfi_cfg_noted(x, path);
    return amfi_cfg_fail(x, line ? line : amfi_cfg_first_noted(x, sec, "alerts", NULL), path, "%s", why);
}

/* The command must be a program amfid can run now (absolute: amfid runs
 * from / under systemd); the metrics file must be an absolute path whose
 * folder exists (node-exporter reads *.prom files there). */
int amfi_cfg_ops_check(ctx *x, amfi_site_config *c)
{
    const char *cmd = c->daemon.alert_command;
    const char *prom = c->daemon.metrics_path;
    struct stat st;
    const char *blamed = NULL;
    char why[256];

    if (amfi_speed_drift_params_check(&c->daemon.speed_drift, &blamed, why, sizeof why) != 0)
        return blame(x, "speed_drift", blamed, why);
    if (amfi_scale_params_check(&c->daemon.scale, &blamed, why, sizeof why) != 0)
        return blame(x, "scale", blamed, why);
    if (amfi_known_truck_params_check(&c->daemon.known_truck, &blamed, why, sizeof why) != 0)
        return blame(x, "known_truck", blamed, why);
    if (amfi_level_params_check(&c->daemon.model_fit, &blamed, why, sizeof why) != 0)
        return blame(x, "model_fit", blamed, why);
    if (amfi_level_params_check(&c->daemon.natfreq_alert, &blamed, why, sizeof why) != 0)
        return blame(x, "natfreq", blamed, why);
    /* the extended solve fits free vibration the tracker recorded */
    if (c->daemon.model_fit.enabled && c->daemon.natfreq_free_s > 0 &&
        c->daemon.model_fit_free_s > c->daemon.natfreq_free_s) {
        char w2[192];
        snprintf(w2, sizeof w2,
                 "%g s is more free vibration than amfid records "
                 "(daemon.natural_frequency.free_s %g s)",
                 c->daemon.model_fit_free_s, c->daemon.natfreq_free_s);
        return blame(x, "model_fit", "free_s", w2);
    }
    if (cmd[0]) {
        int line = amfi_cfg_noted(x, "alerts.command");
        if (cmd[0] != '/')
            return amfi_cfg_fail(x, line, "alerts.command", "must be an absolute path, got '%s'", cmd);
        if (stat(cmd, &st) != 0 || !S_ISREG(st.st_mode))
            return amfi_cfg_fail(x, line, "alerts.command", "'%s' is not a file", cmd);
        if (access(cmd, X_OK) != 0)
            return amfi_cfg_fail(x, line, "alerts.command", "'%s' is not executable", cmd);
    }
    if (prom[0]) {
        int line = amfi_cfg_noted(x, "metrics.textfile");
        const char *slash = strrchr(prom, '/');
        char dir[sizeof c->daemon.metrics_path];
        if (prom[0] != '/')
            return amfi_cfg_fail(x, line, "metrics.textfile", "must be an absolute path, got '%s'", prom);
        size_t n = (size_t)(slash - prom);
        memcpy(dir, prom, n ? n : 1);
        dir[n ? n : 1] = '\0';
        if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
            return amfi_cfg_fail(x, line, "metrics.textfile", "the folder '%s' does not exist", dir);
        if (!slash[1])
            return amfi_cfg_fail(x, line, "metrics.textfile", "'%s' names a folder, not a file", prom);
    }
    return 0;
}
