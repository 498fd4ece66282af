/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfid: the bridge monitoring daemon.
 *
 *   amfid [--config FILE] [--db PATH] [--lcm-url URL] [--bus-key FILE] [--check-config]
 *   amfid --make-bus-key FILE
 *         [--help] [--version]
 *
 * Listens on LCM to accelerometer blocks and vehicle events (and, from a
 * simulation, the truth), cuts the stream into vehicle passages, weighs each
 * vehicle with A-MFI on solver threads, stores every passage in SQLite (one
 * transaction each, in the order of the vehicles' entry), watches the spread
 * of the inferred weights and raises alerts; publishes passages, indicators,
 * alerts and a heartbeat. Runs in the foreground, logs to stderr (journald
 * takes it), speaks sd_notify (READY, STATUS, WATCHDOG). Time is the data's
 * time (message utimes): replaying a log at any speed stores the same rows.
 *
 * This file: start-up, the loop and shutdown, on the main thread (main()
 * is in main.c, so that fuzz/fuzz_intake.c can drive the same daemon).
 * Start-up builds the daemon in dependency order; whatever happens, one
 * function (amfid_stop) tears down whatever was built, in reverse. The other
 * files and who owns what: amfid.h.
 *
 * Signals: SIGTERM/SIGINT stop reading the bus, let the solver threads
 * finish what is queued, store every pending passage (those whose data never
 * came as "gap") and close the database; SIGHUP reloads the configuration
 * (what cannot change while running is reported and kept).
 *
 * Exit status: 0 after a signal; 1 a runtime failure (store, bus); 2 bad
 * command line or configuration.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfid.h"

static volatile sig_atomic_t stop_flag, reload_flag;
static void on_stop(int sig)
{
    (void)sig;
    stop_flag = 1;
}
static void on_hup(int sig)
{
    (void)sig;
    reload_flag = 1;
}

/* The configuration and what it builds: 0, or 2 (reported). */
static int start_config(daemon_s *d, const amfid_options *o)
{
    char err[512];
    d->config_path = o->config;
    d->state = "starting";
    if (load_config(o->config, &d->cfg))
        return 2;
    if (o->db)
        snprintf(d->cfg.daemon.db_path, sizeof d->cfg.daemon.db_path, "%s", o->db);
    if (o->lcm_url)
        snprintf(d->cfg.daemon.lcm_url, sizeof d->cfg.daemon.lcm_url, "%s", o->lcm_url);
    if (amfi_bridge_create(&d->cfg.bridge, &d->bridge, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: bridge: %s\n", o->config, err);
        return 2;
    }
    indicator_params(&d->cfg.daemon, &d->ind_params);
    if (amfi_indicators_create(&d->ind_params, &d->ind, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: daemon.indicators: %s\n", o->config, err);
        return 2;
    }
    if (drift_create(d, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: alerts.speed_drift: %s\n", o->config, err);
        return 2;
    }
    if (scaleind_create(d, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: alerts.scale / alerts.known_truck: %s\n", o->config, err);
        return 2;
    }
    /* A solver is built once here to check the solver section. */
    amfi_solver *probe = NULL;
    if (amfi_solver_create(d->bridge, &d->cfg.solver, &probe, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: solver: %s\n", o->config, err);
        return 2;
    }
    amfi_solver_destroy(probe);
    return 0;
}

/* The store belongs to one bridge: at its first start amfid writes the
 * configuration's site.id (and name, position) into the store's meta table;
 * later starts refuse a store that holds another site.id, so two bridges'
 * passages never mix in one store (or in a fleet's central database, which
 * keys rows by site). A changed site.name or position is written over the
 * stored one. 0, or 1 after a logged error. */
static int claim_site(daemon_s *d)
{
    const amfi_site_identity *site = &d->cfg.site;
    char err[512], stored[AMFI_STORE_META_VALUE_MAX + 1];
    int found = 0;

    if (amfi_store_meta_get(d->store, "site.id", stored, sizeof stored, &found, err,
                            sizeof err)) {
        LOG_ERR("store %s: %s", d->cfg.daemon.db_path, err);
        return 1;
    }
    if (found && strcmp(stored, site->id) != 0) {
        LOG_ERR("store %s belongs to site '%s', but %s configures site.id '%s': refusing "
                "to mix two sites in one store (give this site its own daemon.store.path, "
                "or correct site.id)",
                d->cfg.daemon.db_path, stored, d->config_path, site->id);
        return 1;
    }
    if (!found)
        LOG_INFO("store %s: first start of site '%s' (%s)", d->cfg.daemon.db_path, site->id,
                 site->name);
    struct {
        const char *key, *val;
    } kv[4] = {{"site.id", site->id}, {"site.name", site->name}, {NULL, NULL}, {NULL, NULL}};
    char lat[32], lon[32];
    if (!isnan(site->latitude)) {
        snprintf(lat, sizeof lat, "%.7f", site->latitude);
        snprintf(lon, sizeof lon, "%.7f", site->longitude);
        kv[2].key = "site.latitude", kv[2].val = lat;
        kv[3].key = "site.longitude", kv[3].val = lon;
    }
    for (int i = 0; i < 4 && kv[i].key; i++) {
        if (amfi_store_meta_get(d->store, kv[i].key, stored, sizeof stored, &found, err,
                                sizeof err) ||
            ((!found || strcmp(stored, kv[i].val)) &&
             amfi_store_meta_set(d->store, kv[i].key, kv[i].val, err, sizeof err))) {
            LOG_ERR("store %s: %s", d->cfg.daemon.db_path, err);
            return 1;
        }
        if (found && strcmp(stored, kv[i].val) && i > 0)
            LOG_INFO("store %s: %s changed from '%s' to '%s'", d->cfg.daemon.db_path,
                     kv[i].key, stored, kv[i].val);
    }
    return 0;
}

/* The store, the tracker, the bus and the solver threads: 0, or 1. */
static int start_runtime(daemon_s *d)
{
    char err[512];
    /* First: a signal during start-up is remembered (the loop then stops
     * at once, or reloads), never the default action. */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = on_hup;
    sigaction(SIGHUP, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    amfi_set_blas_threads(1);
    if (amfi_store_open(d->cfg.daemon.db_path, d->cfg.daemon.sync_full, &d->store, err,
                        sizeof err)) {
        LOG_ERR("store %s: %s", d->cfg.daemon.db_path, err);
        return 1;
    }
    if (claim_site(d))
        return 1;
    d->metrics.start_wall = (double)time(NULL);
    char abs[PATH_MAX];
    const char *cfg_path = realpath(d->config_path, abs) ? abs : d->config_path;
    if (amfi_store_add_run(d->store, amfi_version(), cfg_path, &d->run_id, err, sizeof err)) {
        LOG_ERR("store %s: %s", d->cfg.daemon.db_path, err);
        return 1;
    }
    restore_indicator_state(d);
    drift_restore(d);
    scaleind_restore(d);
    freevib_start(d);
    amfi_tracker_params tp = {d->cfg.bridge.span_m,
                              d->cfg.solver.pre_roll_s + d->cfg.daemon.margin_s,
                              d->cfg.solver.post_roll_s + d->cfg.daemon.margin_s,
                              d->cfg.daemon.max_wait_s, d->cfg.solver.n_sensors,
                              d->cfg.daemon.max_event_s, d->cfg.daemon.max_event_axles,
                              /* room for the speed search, also when a reload
                                 turns it on */
                              amfi_speed_slowest_frac(&d->cfg.speed_prior),
                              d->cfg.daemon.natfreq_free_s};
    d->tracker = amfi_tracker_create(&tp);
    if (!d->tracker || pipeline_start(d)) {
        LOG_ERR("out of memory at start-up");
        return 1;
    }
    intake_limits(d); /* the rate limits of the inputs: full buckets */
    char url[512];
    bus_url(&d->cfg.daemon, url, sizeof url);
    d->lcm = lcm_create(url);
    if (!d->lcm) {
        LOG_ERR("cannot open the LCM bus '%s'", url);
        return 1;
    }
    int arc = bus_auth_start(d, d->bus_key_option);
    if (arc)
        return arc;
    if (intake_subscribe(d))
        return 1;
    if (pool_start(&d->pool, d->bridge, &d->cfg.solver, d->cfg.daemon.workers,
                   d->cfg.daemon.queue_size, err, sizeof err)) {
        LOG_ERR("%s", err);
        return 1;
    }
    return 0;
}

/* Read the bus until a signal or its end, then drain: every pending
 * passage is stored, solved or with its reason. 0, or 1. */
int amfid_run(daemon_s *d)
{
    int rc = 0;
    d->state = "running";
    sd_notify(0, "READY=1");
    LOG_INFO("running: amfid %s, bus '%s', store %s, %d solver thread(s), bridge %s",
             amfi_version(), d->cfg.daemon.lcm_url[0] ? d->cfg.daemon.lcm_url : "(default)",
             d->cfg.daemon.db_path, d->pool.n_threads, d->cfg.name);
    uint64_t wd_usec = 0;
    int wd = sd_watchdog_enabled(0, &wd_usec) > 0;
    double last_beat = 0.0, last_wd = 0.0;
    int lfd = lcm_get_fileno(d->lcm);
    const int replay = strncmp(d->cfg.daemon.lcm_url, "file://", 7) == 0;
    while (!stop_flag) {
        /* Replaying a log, the bus waits for the solvers (no overload,
         * the same rows at any speed); a live bus is always read. */
        const int hold = replay && queue_depth(&d->pool.jobs) >= d->cfg.daemon.queue_size;
        struct pollfd pf[2] = {{hold ? -1 : lfd, POLLIN, 0}, {d->pool.efd, POLLIN, 0}};
        int pr = poll(pf, 2, 100);
        if (pr < 0 && errno != EINTR) {
            LOG_ERR("poll: %s", strerror(errno));
            rc = 1;
            break;
        }
        if (pr > 0 && (pf[0].revents & POLLIN) && lcm_handle(d->lcm) != 0) {
            if (replay) { /* file:// provider: the end of the log */
                LOG_INFO("the bus has no more data (end of log)");
                break;
            }
            /* a live bus: a receive error is logged and counted, not fatal */
            d->messages_malformed++;
            set_error(d, "LCM receive error on '%s'", d->cfg.daemon.lcm_url);
        }
        /* A live bus: every message already queued, up to a bound that
         * keeps the heartbeat and the watchdog going in a flood; one at a
         * time (one poll round each) left LCM's queues to overflow. */
        for (int k = 0; !replay && pr > 0 && (pf[0].revents & POLLIN) && k < 512; k++)
            if (lcm_handle_timeout(d->lcm, 0) <= 0)
                break;
        if (pr > 0 && (pf[0].revents & (POLLHUP | POLLERR | POLLNVAL))) {
            LOG_INFO("the bus closed");
            break;
        }
        release_windows(d, 0);
        pipeline_drain_results(d);
        if (pipeline_held(d) > 0)
            pipeline_retry(d, 0);
        if (reload_flag) {
            reload_flag = 0;
            reload(d);
        }
        double now = amfi_mono_s();
        if (now - last_beat >= d->cfg.daemon.status_period_s) {
            heartbeat(d);
            reject_tick(d);
            last_beat = now;
        }
        notify_tick(d);
        metrics_tick(d, 0);
        if (!pipeline_degraded(d))
            record_intake(d, 0);
        if (wd && now - last_wd >= 0.5e-6 * (double)wd_usec) {
            sd_notify(0, "WATCHDOG=1");
            last_wd = now;
        }
    }
    int drc = amfid_drain(d);
    return rc ? rc : drc;
}

int amfid_drain(daemon_s *d)
{
    int rc = 0;
    d->state = "draining";
    sd_notify(0, "STOPPING=1");
    release_windows(d, 1);
    pool_join(&d->pool);
    pipeline_drain_results(d);
    if (pipeline_held(d) > 0) { /* the store still refuses: keep trying a while */
        LOG_WARN("store: %d passages held at shutdown; retrying for up to 20 s",
                 pipeline_held(d));
        pipeline_retry(d, 20.0);
    }
    heartbeat(d);
    reject_final(d);
    scaleind_final(d);
    freevib_final(d);
    notify_finish(d);
    metrics_tick(d, 1);
    if (!pipeline_degraded(d))
        record_intake(d, 1);
    if (pipeline_lost(d) > 0)
        rc = 1; /* acknowledged passages are safe; these never were */
    if (d->env.received + d->env.rejected > 0)
        LOG_INFO("environment: %lld readings decoded, %lld refused, %lld stored%s",
                 (long long)d->env.received, (long long)d->env.rejected,
                 (long long)d->env.stored,
                 d->env.lost + d->env.n > 0 ? ", some not stored (the store refused them)" : "");
    if (d->env.thinned > 0)
        LOG_INFO("environment: %lld accepted readings not stored (within "
                 "daemon.intake.environment_min_interval_s of a stored one)",
                 (long long)d->env.thinned);
    if (d->vehicles_evicted + d->references_refused + d->invalid_unstored > 0)
        LOG_INFO("intake: %lld waiting vehicles evicted (stored as overload), %lld calibration "
                 "references not taken, %lld refused vehicles over the rate limit (summarised, "
                 "no row)",
                 (long long)d->vehicles_evicted, (long long)d->references_refused,
                 (long long)d->invalid_unstored);
    if (d->env.lost + d->env.n > 0)
        LOG_WARN("environment: %lld readings dropped while the store refused them, %d still "
                 "buffered at stop: not stored",
                 (long long)d->env.lost, d->env.n);
    LOG_INFO("stopped: %lld passages stored (%lld ok), %lld not stored, %lld messages received: "
             "%lld blocks, %lld vehicles, %lld rejected messages, %lld refused by the bus "
             "authentication",
             (long long)d->passages_stored, (long long)d->passages_ok,
             (long long)pipeline_lost(d), (long long)d->messages_in,
             (long long)d->blocks_received, (long long)d->vehicles_received,
             (long long)(d->blocks_rejected + d->vehicles_rejected + d->messages_malformed),
             (long long)d->auth_refused);
    return rc;
}

/* The one tear-down: whatever start_* built, in reverse; NULL-safe. */
void amfid_stop(daemon_s *d)
{
    notify_free(d);
    pool_stop(&d->pool);
    if (d->lcm)
        lcm_destroy(d->lcm);
    bus_auth_stop(d);
    pipeline_stop(d);
    for (int i = 0; i < AMFI_MAX_SENSORS; i++)
        amfi_ring_destroy(d->rings[i]);
    amfi_tracker_destroy(d->tracker);
    amfi_store_close(d->store);
    amfi_indicators_destroy(d->ind);
    drift_destroy(d);
    scaleind_destroy(d);
    freevib_stop(d);
    amfi_bridge_destroy(d->bridge);
}

int amfid_start(daemon_s *d, const amfid_options *o)
{
    if (o->make_bus_key) {
        char err[PATH_MAX + 200];
        if (amfi_auth_key_make(o->make_bus_key, err, sizeof err)) {
            fprintf(stderr, "amfid: %s\n", err);
            return 1;
        }
        printf("amfid: new bus key %s (mode 0600): give it to every producer of the bus and "
               "to amfid (docs/messages.md)\n",
               o->make_bus_key);
        return 0;
    }
    d->bus_key_option = o->bus_key;
    int rc = start_config(d, o);
    if (rc == 0 && o->check_only)
        printf("amfid: %s: ok (site %s, bridge %s, %d sensor(s), %d worker(s), store %s)\n", o->config,
               d->cfg.site.id, d->cfg.name, d->cfg.solver.n_sensors, d->cfg.daemon.workers,
               d->cfg.daemon.db_path);
    else if (rc == 0)
        rc = start_runtime(d);
    return rc;
}
