/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_daemon.c: the daemon: section of a site file (amfid's bus, store,
 * threads, waits and damage indicators: amfi_daemon_config). The indicator
 * keys fill the engine's own amfi_indicator_params; the rules between them
 * (clear <= alert, ...) are the engine's, checked by
 * amfi_indicator_params_check() and reported here with the line of the key
 * the engine blames. The natural-frequency keys fill the estimator's
 * amfi_natfreq_params (natfreq.h). Runs on the loader's thread.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define DC(m) offsetof(amfi_site_config, daemon.m)
#define STRF(k, m, minlen, fl) \
    {.key = k, .kind = &amfi_cfg_k_string, .off = DC(m), .lo = minlen, \
     .hi = sizeof(((amfi_daemon_config *)0)->m), .flags = fl}
#define STR(k, m, minlen) STRF(k, m, minlen, 0)

static const field channel_fields[] = {
    STR("accel", ch_accel, 1),     STR("vehicle", ch_vehicle, 1),
    STR("truth", ch_truth, 1),     STRF("passage", ch_passage, 1, F_LIVE),
    STRF("indicator", ch_indicator, 1, F_LIVE), STRF("alert", ch_alert, 1, F_LIVE),
    STRF("status", ch_status, 1, F_LIVE),   STR("environment", ch_environment, 1),
    {.key = NULL}};

static const enum_name auth_names[] = {{"off", 0}, {"required", 1}, {NULL, 0}};

static const field bus_fields[] = {
    {.key = "auth", .kind = &amfi_cfg_k_enum, .off = DC(bus_auth), .aux = auth_names},
    STR("key_file", bus_key_file, 1),
    {.key = "max_skew_s", .kind = &amfi_cfg_k_double, .off = DC(bus_max_skew_s), .lo = 1, .hi = 86400},
    {.key = NULL}};

static const enum_name sync_names[] = {{"normal", 0}, {"full", 1}, {NULL, 0}};

static const enum_name raw_keep_names[] = {
    {"none", AMFI_RAW_KEEP_NONE}, {"failed", AMFI_RAW_KEEP_FAILED}, {"all", AMFI_RAW_KEEP_ALL},
    {NULL, 0}};

static const enum_name raw_precision_names[] = {{"float64", 0}, {"float32", 1}, {NULL, 0}};

static const field raw_fields[] = {
    {.key = "keep", .kind = &amfi_cfg_k_enum, .off = DC(raw_keep), .aux = raw_keep_names},
    {.key = "precision", .kind = &amfi_cfg_k_enum, .off = DC(raw_float32), .aux = raw_precision_names},
    {.key = "max_age_days", .kind = &amfi_cfg_k_double, .off = DC(raw_max_age_days), .lo = 0,
     .hi = 36500},
    {.key = "max_mib", .kind = &amfi_cfg_k_double, .off = DC(raw_max_mib), .lo = 0,
     .hi = 1e6},
    {.key = NULL}};

static const field store_fields[] = {
    STR("path", db_path, 1),
    {.key = "sync", .kind = &amfi_cfg_k_enum, .off = DC(sync_full), .aux = sync_names},
    {.key = "held_max_bytes", .kind = &amfi_cfg_k_llong, .off = DC(held_max_bytes),
     .lo = 1048576, .hi = 68719476736.0},
    {.key = "raw", .kind = &amfi_cfg_k_map, .aux = raw_fields},
    {.key = NULL}};

/* Offsets of the engine's amfi_indicator_params inside the site config. */
#define IND(m) DC(indicators.m)

const enum_name amfi_cfg_onoff_names[] = {{"off", 0}, {"on", 1}, {NULL, 0}};
static const enum_name bool_names[] = {{"false", 0}, {"true", 1}, {NULL, 0}};
static const enum_name temperature_names[] = {{"raw", 0}, {"compensated", 1}, {NULL, 0}};

static const field indicator_fields[] = {
    {.key = "window", .kind = &amfi_cfg_k_int, .off = IND(window), .lo = 10, .hi = 1000000},
    {.key = "every", .kind = &amfi_cfg_k_int, .off = IND(every), .lo = 1, .hi = 1000000},
    {.key = "baseline_n", .kind = &amfi_cfg_k_int, .off = IND(baseline_n), .lo = 10, .hi = 1000000},
    {.key = "std_alert_ratio", .kind = &amfi_cfg_k_double, .off = IND(std_alert_ratio), .lo = 1,
     .hi = 10},
    {.key = "std_alert_p", .kind = &amfi_cfg_k_double, .off = IND(std_alert_p), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN},
    {.key = "std_clear_ratio", .kind = &amfi_cfg_k_double, .off = IND(std_clear_ratio), .lo = 0.5,
     .hi = 10},
    {.key = "raise_after", .kind = &amfi_cfg_k_int, .off = IND(raise_after), .lo = 1, .hi = 1000},
    {.key = "clear_after", .kind = &amfi_cfg_k_int, .off = IND(clear_after), .lo = 1, .hi = 1000},
    {.key = "mean_shift", .kind = &amfi_cfg_k_enum, .off = IND(mean_shift), .aux = amfi_cfg_onoff_names},
    {.key = "mean_alert_ratio", .kind = &amfi_cfg_k_double, .off = IND(mean_alert_ratio), .lo = 1,
     .hi = 10},
    {.key = "mean_alert_p", .kind = &amfi_cfg_k_double, .off = IND(mean_alert_p), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN},
    {.key = "mean_clear_ratio", .kind = &amfi_cfg_k_double, .off = IND(mean_clear_ratio), .lo = 0.5,
     .hi = 10},
    /* amfid's filter in front of the engine (pipeline.c), not an engine parameter */
    {.key = "single_presence_only", .kind = &amfi_cfg_k_enum, .off = DC(single_presence_only),
     .aux = amfi_cfg_onoff_names},
    {.key = "temperature", .kind = &amfi_cfg_k_enum, .off = DC(ind_temp_compensated),
     .aux = temperature_names},
    STR("classes", ind_classes, 0),
    {.key = "min_gvw_kg", .kind = &amfi_cfg_k_double, .off = DC(ind_min_gvw_kg), .lo = 0,
     .hi = 100000},
    {.key = NULL}};

/* Offsets of the estimator's amfi_natfreq_params inside the site config. */
#define NF(m) DC(natfreq.m)

static const field natfreq_fields[] = {
    {.key = "free_s", .kind = &amfi_cfg_k_double, .off = DC(natfreq_free_s), .lo = 0, .hi = 30},
    {.key = "f_lo_hz", .kind = &amfi_cfg_k_double, .off = NF(f_lo_hz), .lo = 0, .hi = 1000,
     .flags = F_LO_OPEN},
    {.key = "f_hi_hz", .kind = &amfi_cfg_k_double, .off = NF(f_hi_hz), .lo = 0, .hi = 1000,
     .flags = F_LO_OPEN},
    {.key = "modes", .kind = &amfi_cfg_k_int, .off = NF(n_modes), .lo = 1, .hi = AMFI_NATFREQ_MAX_MODES},
    {.key = "min_periods", .kind = &amfi_cfg_k_double, .off = NF(min_periods), .lo = 1, .hi = 1000},
    {.key = "min_r2", .kind = &amfi_cfg_k_double, .off = NF(min_r2), .lo = 0, .hi = 1,
     .flags = F_HI_OPEN},
    {.key = "max_zeta", .kind = &amfi_cfg_k_double, .off = NF(max_zeta), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "max_se_frac", .kind = &amfi_cfg_k_double, .off = NF(max_se_frac), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN},
    {.key = "baseline_n", .kind = &amfi_cfg_k_int, .off = DC(natfreq_baseline_n), .lo = 10,
     .hi = 100000},
    {.key = "mode", .kind = &amfi_cfg_k_int, .off = DC(natfreq_mode), .lo = 0, .hi = 20},
    {.key = "band", .kind = &amfi_cfg_k_double, .off = DC(natfreq_band), .lo = 0, .hi = 0.5,
     .flags = F_LO_OPEN},
    {.key = NULL}};

static const field intake_fields[] = {
    {.key = "vehicle_ahead_s", .kind = &amfi_cfg_k_double, .off = DC(vehicle_ahead_s), .lo = 1,
     .hi = 3600, .flags = F_LIVE},
    {.key = "min_speed_mps", .kind = &amfi_cfg_k_double, .off = DC(min_speed_mps), .lo = 1, .hi = 60,
     .flags = F_HI_OPEN | F_LIVE},
    {.key = "max_length_m", .kind = &amfi_cfg_k_double, .off = DC(max_length_m), .lo = 1, .hi = 360, .flags = F_LIVE},
    {.key = "accel_margin", .kind = &amfi_cfg_k_double, .off = DC(accel_margin), .lo = 1, .hi = 1000, .flags = F_LIVE},
    {.key = "vehicles_per_s", .kind = &amfi_cfg_k_double, .off = DC(vehicles_per_s), .lo = 0.1,
     .hi = 1e5, .flags = F_LIVE},
    {.key = "environment_per_s", .kind = &amfi_cfg_k_double, .off = DC(environment_per_s), .lo = 0.1,
     .hi = 1e5, .flags = F_LIVE},
    {.key = "truth_per_s", .kind = &amfi_cfg_k_double, .off = DC(truth_per_s), .lo = 0.1, .hi = 1e5, .flags = F_LIVE},
    {.key = "burst_s", .kind = &amfi_cfg_k_double, .off = DC(burst_s), .lo = 1, .hi = 3600, .flags = F_LIVE},
    {.key = "summary_period_s", .kind = &amfi_cfg_k_double, .off = DC(summary_period_s), .lo = 1,
     .hi = 86400, .flags = F_LIVE},
    {.key = "environment_min_interval_s", .kind = &amfi_cfg_k_double, .off = DC(env_min_interval_s),
     .lo = 0, .hi = 86400, .flags = F_LIVE},
    {.key = "deck_max_rate_c_per_min", .kind = &amfi_cfg_k_double, .off = DC(deck_max_rate_c_min),
     .lo = 0, .hi = 1e6, .flags = F_LO_OPEN | F_LIVE},
    STRF("calibration_sources", calibration_sources, 0, F_LIVE),
    {.key = "calibration_min_kg", .kind = &amfi_cfg_k_double, .off = DC(calibration_min_kg),
     .lo = 1000, .hi = 100000, .flags = F_LIVE},
    {.key = "calibration_max_kg", .kind = &amfi_cfg_k_double, .off = DC(calibration_max_kg),
     .lo = 1000, .hi = 100000, .flags = F_LIVE},
    {.key = NULL}};

const field amfi_cfg_daemon_fields[] = {
    STR("lcm_url", lcm_url, 0),
    {.key = "channels", .kind = &amfi_cfg_k_map, .aux = channel_fields},
    {.key = "bus", .kind = &amfi_cfg_k_map, .aux = bus_fields},
    {.key = "simulation", .kind = &amfi_cfg_k_enum, .off = DC(simulation), .aux = bool_names},
    {.key = "store", .kind = &amfi_cfg_k_map, .aux = store_fields},
    {.key = "workers", .kind = &amfi_cfg_k_int, .off = DC(workers), .lo = 1, .hi = 64},
    {.key = "queue_size", .kind = &amfi_cfg_k_int, .off = DC(queue_size), .lo = 1, .hi = 100000},
    {.key = "recv_buf_bytes", .kind = &amfi_cfg_k_int, .off = DC(recv_buf_bytes), .lo = 0,
     .hi = 1073741824},
    {.key = "bus_queue", .kind = &amfi_cfg_k_int, .off = DC(bus_queue), .lo = 30, .hi = 1000000},
    {.key = "ring_s", .kind = &amfi_cfg_k_double, .off = DC(ring_s), .lo = 5, .hi = 3600},
    {.key = "environment_max_skew_s", .kind = &amfi_cfg_k_double, .off = DC(environment_max_skew_s),
     .lo = 1, .hi = 864000, .flags = F_LIVE},
    {.key = "window_margin_s", .kind = &amfi_cfg_k_double, .off = DC(margin_s), .lo = 0, .hi = 5},
    {.key = "max_wait_s", .kind = &amfi_cfg_k_double, .off = DC(max_wait_s), .lo = 0, .hi = 3600,
     .flags = F_LO_OPEN | F_LIVE},
    {.key = "max_event_s", .kind = &amfi_cfg_k_double, .off = DC(max_event_s), .lo = 0, .hi = 600},
    {.key = "max_event_axles", .kind = &amfi_cfg_k_int, .off = DC(max_event_axles), .lo = 2,
     .hi = AMFI_MAX_EVENT_AXLES},
    {.key = "inseparable_gap_m", .kind = &amfi_cfg_k_double, .off = DC(inseparable_gap_m), .lo = 0,
     .hi = 10},
    {.key = "inseparable_share", .kind = &amfi_cfg_k_double, .off = DC(inseparable_share), .lo = 0,
     .hi = 1, .flags = F_LO_OPEN},
    {.key = "inseparable_quality", .kind = &amfi_cfg_k_double, .off = DC(inseparable_quality), .lo = 1,
     .hi = 1e9},
    {.key = "inseparable_quality_lanes", .kind = &amfi_cfg_k_double,
     .off = DC(inseparable_quality_lanes), .lo = 1, .hi = 1e9},
    {.key = "status_period_s", .kind = &amfi_cfg_k_double, .off = DC(status_period_s), .lo = 0.1,
     .hi = 3600, .flags = F_LIVE},
    {.key = "indicators", .kind = &amfi_cfg_k_map, .aux = indicator_fields},
    {.key = "natural_frequency", .kind = &amfi_cfg_k_map, .aux = natfreq_fields},
    {.key = "intake", .kind = &amfi_cfg_k_map, .aux = intake_fields},
    {.key = NULL}};

int amfi_cfg_daemon_check(ctx *x, amfi_site_config *c)
{
    const char *blamed = NULL;
    char why[256], path[PATH_LEN];
    int line;

    /* an event's samples must still be in the ring when its last vehicle
     * has left (tracker.h): the ring holds more than the longest event */
    if (c->daemon.max_event_s >= c->daemon.ring_s)
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "daemon.max_event_s", "daemon.ring_s", "daemon"),
                    "daemon.max_event_s",
                    "%g s is not below daemon.ring_s (%g s): an event's samples would leave "
                    "the ring before it ends",
                    c->daemon.max_event_s, c->daemon.ring_s);

    /* and the free vibration after it (the natural frequency) */
    if (c->daemon.max_event_s + c->daemon.natfreq_free_s >= c->daemon.ring_s)
        return amfi_cfg_fail(x,
                    amfi_cfg_first_noted(x, "daemon.natural_frequency.free_s", "daemon.ring_s", "daemon"),
                    "daemon.natural_frequency.free_s",
                    "%g s after an event of up to daemon.max_event_s (%g s) is not below "
                    "daemon.ring_s (%g s): the free vibration would leave the ring first",
                    c->daemon.natfreq_free_s, c->daemon.max_event_s, c->daemon.ring_s);

    /* the calibration trucks' range, and their sources: names separated by
     * commas, each 1 .. 63 bytes of A-Z a-z 0-9 _ . - (vehicle_t.source) */
    if (c->daemon.calibration_min_kg > c->daemon.calibration_max_kg)
        return amfi_cfg_fail(x,
                    amfi_cfg_first_noted(x, "daemon.intake.calibration_max_kg",
                                "daemon.intake.calibration_min_kg", "daemon"),
                    "daemon.intake.calibration_max_kg", "%g kg is below calibration_min_kg (%g kg)",
                    c->daemon.calibration_max_kg, c->daemon.calibration_min_kg);
    {
        const char *s = c->daemon.calibration_sources;
        size_t len = 0;
        for (const char *p = s;; p++) {
            if (*p == ',' || *p == '\0') {
                if (len == 0 && (*p == ',' || p != s))
                    return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "daemon.intake.calibration_sources", "daemon", NULL),
                                "daemon.intake.calibration_sources",
                                "an empty name in '%s' (names separated by single commas)", s);
                if (len > 63)
                    return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "daemon.intake.calibration_sources", "daemon", NULL),
                                "daemon.intake.calibration_sources",
                                "a name longer than 63 bytes in '%s'", s);
                if (*p == '\0')
                    break;
                len = 0;
            } else if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
                       (*p >= '0' && *p <= '9') || *p == '_' || *p == '.' || *p == '-') {
                len++;
            } else {
                return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "daemon.intake.calibration_sources", "daemon", NULL),
                            "daemon.intake.calibration_sources",
                            "'%c' in '%s': names are A-Z a-z 0-9 _ . - separated by commas", *p,
                            s);
            }
        }
    }

    /* the classes that feed the STD and mean rules: names of classes.scheme
     * separated by single commas, each once */
    {
        const char *s = c->daemon.ind_classes;
        unsigned seen = 0;
        const int cls_line = amfi_cfg_first_noted(x, "daemon.indicators.classes", "daemon", NULL);
        for (const char *p = s; *s;) {
            const char *e = strchr(p, ',');
            const size_t len = e ? (size_t)(e - p) : strlen(p);
            char name[32];
            if (len == 0)
                return amfi_cfg_fail(x, cls_line, "daemon.indicators.classes",
                                     "an empty name in '%s' (class names separated by single "
                                     "commas)", s);
            snprintf(name, sizeof name, "%.*s", (int)(len < sizeof name ? len : sizeof name - 1),
                     p);
            const int k = len < sizeof name ? amfi_class_index(c->classes.scheme, name) : -1;
            if (k < 0)
                return amfi_cfg_fail(x, cls_line, "daemon.indicators.classes",
                                     "'%.*s' is not a class of classes.scheme %s (%s)", (int)len,
                                     p, amfi_class_scheme_name(c->classes.scheme),
                                     c->classes.scheme == AMFI_CLASS_SCHEME_FHWA13
                                         ? "FHWA1 .. FHWA13"
                                         : "CAR, R2, R3, R4, A22, A23, A32, A33");
            if (seen & (1u << k))
                return amfi_cfg_fail(x, cls_line, "daemon.indicators.classes",
                                     "'%s' twice in '%s'", name, s);
            seen |= 1u << k;
            if (!e)
                break;
            p = e + 1;
        }
    }

    /* the band's two ends (each key's own range is the table's) */
    if (amfi_natfreq_params_check(&c->daemon.natfreq, why, sizeof why) != 0)
        return amfi_cfg_fail(x,
                    amfi_cfg_first_noted(x, "daemon.natural_frequency.f_hi_hz",
                                "daemon.natural_frequency.f_lo_hz", "daemon"),
                    "daemon.natural_frequency.f_hi_hz", "%s", why);

    if (amfi_indicator_params_check(&c->daemon.indicators, &blamed, why, sizeof why) == 0)
        return 0;
    amfi_cfg_pathf(path, "daemon.indicators.%s", blamed ? blamed : "");
    /* The key blamed, else the latest indicator key given (the one that
     * moved a limit past the blamed key's default), else the section. */
    line = amfi_cfg_noted(x, path);
    if (!line)
        line = amfi_cfg_noted_under(x, "daemon.indicators.");
    if (!line)
        line = amfi_cfg_first_noted(x, "daemon.indicators", "daemon", NULL);
    return amfi_cfg_fail(x, line, path, "%s", why);
}
