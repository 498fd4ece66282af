/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * control.c: amfid's configuration and control: loading the configuration,
 * the indicator parameters taken from it, the indicator state restored
 * from the store at start-up (baseline, window, open alerts), the
 * heartbeat (status message, sd_notify STATUS) and the SIGHUP reload.
 *
 * Thread: the main thread only. Owns d->cfg: a reload changes it here,
 * between two turns of the loop; the solver threads never read it (each
 * job carries its own copy of the λ policy, intake.c).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_status_t.h"
#include "amfid.h"

static int64_t wall_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

int load_config(const char *path, amfi_site_config *c)
{
    char err[512];
    amfi_config_defaults(c);
    if (amfi_config_load(path, c, err, sizeof err)) {
        fprintf(stderr, "amfid: %s\n", err);
        return -1;
    }
    return 0;
}

void indicator_params(const amfi_daemon_config *dc, amfi_indicator_params *p)
{
    *p = dc->indicators;
}

/* 1 when the newest alert of `kind` in the store was a raise (still open). */
static int last_alert_raised(amfi_store *st, const char *kind)
{
    char err[256];
    int open = 0;
    if (amfi_store_alert_open(st, kind, &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    return open;
}

void restore_indicator_state(daemon_s *d)
{
    amfi_baseline b;
    int found = 0;
    char err[512];
    if (amfi_store_get_baseline(d->store, &b, &found, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return;
    }
    if (!found)
        return;
    amfi_indicators_set_baseline(d->ind, b.mean_kg, b.std_kg, b.n);
    LOG_INFO("baseline from the store: mean %.0f kg, STD %.0f kg (%d, %s)", b.mean_kg,
             b.std_kg, b.n, b.source);
    double *g = malloc(sizeof(double) * (size_t)d->ind_params.window);
    int n = 0;
    if (g && amfi_store_recent_ok_gvw(d->store, d->ind_params.window, g, &n, err, sizeof err) == 0)
        amfi_indicators_prefill(d->ind, g, n);
    free(g);
    /* An alert open before a restart stays open, not raised twice. */
    int open_std = last_alert_raised(d->store, "std_increase");
    int open_mean = last_alert_raised(d->store, "mean_shift");
    amfi_indicators_set_alerted(d->ind, open_std, open_mean);
    metrics_alert(d, "std_increase", open_std);
    metrics_alert(d, "mean_shift", open_mean);
    if (open_std || open_mean)
        LOG_INFO("open alerts restored from the store:%s%s", open_std ? " std_increase" : "",
                 open_mean ? " mean_shift" : "");
}

/* ---- the intake in the store (for amfi-report) ------------------------------ */

#define INTAKE_PERIOD_S 60.0

void record_intake(daemon_s *d, int force)
{
    double now = amfi_mono_s();
    if (!force && d->intake_recorded > 0 && now - d->intake_recorded < INTAKE_PERIOD_S)
        return;
    d->intake_recorded = now;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    char when[32];
    time_t sec = ts.tv_sec;
    gmtime_r(&sec, &tm);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
    struct {
        const char *key;
        long long v;
    } kv[] = {{"intake.run", (long long)d->run_id},
              {"intake.messages_received", (long long)d->messages_in},
              {"intake.messages_refused", (long long)d->rej.total},
              {"intake.datagrams_dropped", (long long)(d->udp_drops > 0 ? d->udp_drops : 0)},
              {"intake.samples_missing", (long long)d->samples_missing},
              {"intake.passages_lost", (long long)pipeline_lost(d)},
              {"intake.environment_received", (long long)d->env.received},
              {"intake.environment_refused", (long long)d->env.rejected},
              {"intake.environment_stored", (long long)d->env.stored},
              {"intake.environment_lost", (long long)d->env.lost}};
    char err[256], val[32];
    int rc = 0;
    for (size_t i = 0; rc == 0 && i < sizeof kv / sizeof kv[0]; i++) {
        snprintf(val, sizeof val, "%lld", kv[i].v);
        rc = amfi_store_meta_set(d->store, kv[i].key, val, err, sizeof err);
    }
    if (rc == 0)
        rc = amfi_store_meta_set(d->store, "intake.as_of", when, err, sizeof err);
    if (rc)
        LOG_WARN("store: the intake counters: %s", err);
    else
        freevib_record(d);
}

/* ---- heartbeat ---------------------------------------------------------- */

void heartbeat(daemon_s *d)
{
    environment_flush(d);
    int64_t missing = 0, rejected_ring = 0;
    for (int i = 0; i < d->cfg.solver.n_sensors; i++)
        if (d->rings[i]) {
            const amfi_ring_stats *st = amfi_ring_stats_of(d->rings[i]);
            missing += st->missing;
            rejected_ring += st->late + st->duplicates;
        }
    amfi_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = d->newest_utime;
    m.wall_utime = wall_us();
    m.blocks_received = d->blocks_received;
    m.blocks_rejected = d->blocks_rejected + rejected_ring + d->messages_malformed;
    m.samples_missing = missing;
    d->samples_missing = missing;
    m.vehicles_received = d->vehicles_received;
    m.vehicles_rejected = d->vehicles_rejected;
    m.passages_stored = d->passages_stored;
    m.passages_ok = d->passages_ok;
    m.queue_depth = queue_depth(&d->pool.jobs);
    int64_t drops = bus_udp_drops();
    if (drops > d->udp_drops)
        d->udp_drops = drops;
    if (d->udp_drops > d->udp_drops_logged) {
        LOG_WARN("the kernel dropped %lld UDP datagrams on amfid's sockets since start (%lld "
                 "new): the receive buffer overflowed; raise daemon.recv_buf_bytes and "
                 "net.core.rmem_max, or add solver threads",
                 (long long)d->udp_drops, (long long)(d->udp_drops - d->udp_drops_logged));
        d->udp_drops_logged = d->udp_drops;
    }
    m.messages_refused = d->rej.total;
    m.datagrams_dropped = d->udp_drops;
    m.passages_held = pipeline_held(d);
    m.state = (char *)d->state;
    m.last_error = d->last_error;
    m.site_id = d->cfg.site.id;
    BUS_PUBLISH(d, amfi_status_t, d->cfg.daemon.ch_status, &m);
    sd_notifyf(0, "STATUS=%s: %lld passages stored (%lld ok), %d queued, %lld blocks",
               d->state, (long long)d->passages_stored, (long long)d->passages_ok,
               m.queue_depth, (long long)d->blocks_received);
}

/* SIGHUP: apply what can change while running, report the rest. */
void reload(daemon_s *d)
{
    amfi_site_config n;
    if (load_config(d->config_path, &n)) {
        LOG_ERR("reload: the new configuration is refused; keeping the running one");
        return;
    }
    /* keep the command-line overrides */
    memcpy(n.daemon.db_path, d->cfg.daemon.db_path, sizeof n.daemon.db_path);
    memcpy(n.daemon.lcm_url, d->cfg.daemon.lcm_url, sizeof n.daemon.lcm_url);
    if (memcmp(&n.bridge, &d->cfg.bridge, sizeof n.bridge) ||
        memcmp(&n.solver, &d->cfg.solver, sizeof n.solver) ||
        memcmp(n.sensor_id, d->cfg.sensor_id, sizeof n.sensor_id) ||
        memcmp(n.sensor_rate_hz, d->cfg.sensor_rate_hz, sizeof n.sensor_rate_hz))
        LOG_WARN("reload: bridge, sensors and solver changes take effect at the next start");
    if (strcmp(n.site.id, d->cfg.site.id) || strcmp(n.site.name, d->cfg.site.name))
        LOG_WARN("reload: site.id and site.name take effect at the next start (a store "
                 "that holds another site.id is then refused)");
    if (strcmp(n.daemon.ch_accel, d->cfg.daemon.ch_accel) ||
        strcmp(n.daemon.ch_vehicle, d->cfg.daemon.ch_vehicle) ||
        strcmp(n.daemon.ch_truth, d->cfg.daemon.ch_truth) ||
        strcmp(n.daemon.ch_environment, d->cfg.daemon.ch_environment) ||
        n.daemon.workers != d->cfg.daemon.workers ||
        n.daemon.queue_size != d->cfg.daemon.queue_size || n.daemon.ring_s != d->cfg.daemon.ring_s ||
        n.daemon.sync_full != d->cfg.daemon.sync_full ||
        n.daemon.max_event_s != d->cfg.daemon.max_event_s ||
        n.daemon.max_event_axles != d->cfg.daemon.max_event_axles)
        LOG_WARN("reload: channels, workers, queue, ring, event limits and store changes take "
                 "effect at the next start");
    if (n.daemon.bus_auth != d->cfg.daemon.bus_auth ||
        strcmp(n.daemon.bus_key_file, d->cfg.daemon.bus_key_file) ||
        n.daemon.bus_max_skew_s != d->cfg.daemon.bus_max_skew_s ||
        n.daemon.simulation != d->cfg.daemon.simulation)
        LOG_WARN("reload: daemon.bus (authentication, key, skew) and daemon.simulation take "
                 "effect at the next start");
    /* λ policy, output channels, heartbeat, waits: now. The λ policy is
     * copied into each job at release (intake.c): passages released from
     * now on are solved with the new one, those already queued with theirs. */
    d->cfg.lambda = n.lambda;
    memcpy(d->cfg.daemon.ch_passage, n.daemon.ch_passage, sizeof n.daemon.ch_passage);
    memcpy(d->cfg.daemon.ch_indicator, n.daemon.ch_indicator, sizeof n.daemon.ch_indicator);
    memcpy(d->cfg.daemon.ch_alert, n.daemon.ch_alert, sizeof n.daemon.ch_alert);
    memcpy(d->cfg.daemon.ch_status, n.daemon.ch_status, sizeof n.daemon.ch_status);
    d->cfg.daemon.status_period_s = n.daemon.status_period_s;
    d->cfg.daemon.max_wait_s = n.daemon.max_wait_s;
    amfi_tracker_set_max_wait(d->tracker, n.daemon.max_wait_s); /* its own copy */
    d->cfg.daemon.environment_max_skew_s = n.daemon.environment_max_skew_s;
    /* the intake's bounds (daemon.intake.*): now, the buckets kept (a
     * lower limit cuts what is left of the allowance) */
    {
        amfi_daemon_config *c = &d->cfg.daemon;
        const amfi_daemon_config *m = &n.daemon;
        c->vehicle_ahead_s = m->vehicle_ahead_s;
        c->min_speed_mps = m->min_speed_mps;
        c->max_length_m = m->max_length_m;
        c->accel_margin = m->accel_margin;
        c->vehicles_per_s = m->vehicles_per_s;
        c->environment_per_s = m->environment_per_s;
        c->truth_per_s = m->truth_per_s;
        c->burst_s = m->burst_s;
        c->summary_period_s = m->summary_period_s;
        c->env_min_interval_s = m->env_min_interval_s;
        c->deck_max_rate_c_min = m->deck_max_rate_c_min;
        memcpy(c->calibration_sources, m->calibration_sources, sizeof c->calibration_sources);
        c->calibration_min_kg = m->calibration_min_kg;
        c->calibration_max_kg = m->calibration_max_kg;
        intake_limits(d);
    }
    amfi_indicator_params ip;
    indicator_params(&n.daemon, &ip);
    if (!amfi_indicator_params_equal(&ip, &d->ind_params) ||
        n.daemon.single_presence_only != d->cfg.daemon.single_presence_only ||
        n.daemon.ind_temp_compensated != d->sc.compensate)
        LOG_WARN("reload: indicator settings take effect at the next start");
    drift_reload(d, &n);
    scaleind_reload(d, &n);
    freevib_reload(d, &n);
    LOG_INFO("reload: configuration %s applied", d->config_path);
}

