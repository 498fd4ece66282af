/*
 * amfi_config.h: a bridge site's configuration, loaded from YAML.
 *
 * One file describes one site: the bridge model (MODEL.md §1), the sensors
 * and the solver with its λ policy (MODEL.md §4). The shipped file
 * config/paper-20m.yaml documents every key and reproduces
 * amfi_config_defaults() exactly.
 *
 * Workload: read once at start-up (and on reload) by the daemon, the
 * simulator and the tools. Every value is validated here, at the boundary;
 * a bad file gives one line "FILE:LINE: key.path: problem" and never a crash.
 *
 * Ownership: the caller owns the amfi_site_config and the error buffer;
 * nothing is allocated that outlives a call, and there is no global state,
 * so distinct threads may load distinct configurations at the same time.
 */
#ifndef AMFI_CONFIG_H
#define AMFI_CONFIG_H

#include <stddef.h>

#include "amfi/amfi.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The monitoring daemon's section (daemon: in the site file). */
typedef struct amfi_daemon_config {
    char lcm_url[256];        /* daemon.lcm_url; "" = LCM's default */
    char ch_accel[64], ch_vehicle[64], ch_truth[64]; /* daemon.channels.* (inputs) */
    char ch_passage[64], ch_indicator[64], ch_alert[64], ch_status[64]; /* outputs */
    char db_path[512];        /* daemon.store.path */
    int sync_full;            /* daemon.store.sync: full (1) | normal (0) */
    int workers;              /* daemon.workers: solver threads, 1 .. 64 */
    int queue_size;           /* daemon.queue_size: passages waiting, 1 .. 100000 */
    double ring_s;            /* daemon.ring_s: seconds of samples kept per sensor */
    double margin_s;          /* daemon.window_margin_s: data around the solver window */
    double max_wait_s;        /* daemon.max_wait_s: data time to wait for a window */
    double status_period_s;   /* daemon.status_period_s: heartbeat, wall time */
    /* daemon.indicators.* (docs/indicators.md) */
    int ind_window, ind_every, ind_baseline_n, ind_raise_after, ind_clear_after;
    double ind_std_alert_ratio, ind_std_alert_p, ind_std_clear_ratio;
    int ind_mean_shift;
    double ind_mean_alert_ratio, ind_mean_alert_p, ind_mean_clear_ratio;
} amfi_daemon_config;

typedef struct amfi_site_config {
    char name[64];             /* bridge.name: 1 .. 63 bytes, NUL-terminated */
    amfi_bridge_params bridge; /* bridge.* */
    amfi_solver_params solver; /* solver.* and the sensor list (positions,
                                  weights, n_sensors) */
    amfi_lambda lambda;        /* solver.lambda, lambda_ref_rate_hz, lcurve */
    int sensor_id[AMFI_MAX_SENSORS]; /* sensors[i].id, 0 .. 255, unique;
                                        entry i belongs to solver.sensor_x_m[i];
                                        −1 past solver.n_sensors */
    amfi_daemon_config daemon;       /* daemon.* */
} amfi_site_config;

/* Fill `c` (not NULL) with the paper-20m defaults: amfi_bridge_params_paper20,
 * amfi_solver_params_default(20 m), amfi_lambda_default, name "paper-20m",
 * one sensor with id 0. Every byte is set (the struct may be memcmp'd). */
void amfi_config_defaults(amfi_site_config *c);

/* Load the YAML file `path` over the defaults of amfi_config_defaults().
 * Keys left out keep their default, with two defaults that follow the span
 * when bridge.span_m is given: without `supports`, a pinned support at 0 and
 * a roller at span_m; without `sensors`, one sensor (id 0, weight 1) at
 * mid-span. A list given in the file replaces the default list whole.
 *
 * Returns 0 and fills `c`; or −1, leaves `c` untouched and, when `err` is not
 * NULL and errlen > 0, writes one line (truncated to errlen − 1 bytes):
 *   "FILE:LINE: key.path: problem"   e.g. "site.yaml:12: solver.lamda: unknown key"
 * (without ":LINE" for a missing or unreadable file, and without the key path
 * for a YAML syntax error). Numbers use a decimal point whatever the
 * process locale. */
int amfi_config_load(const char *path, amfi_site_config *c, char *err,
                     size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_CONFIG_H */
