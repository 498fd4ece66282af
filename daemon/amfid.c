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
 * This file: the core, on the main thread (main() is in main.c, so that
 * fuzz/fuzz_intake.c can drive the same daemon): the configuration, the
 * store, the bus, the solver threads, the context of shared services (ctx.h)
 * and ONE table of modules. Start-up builds the core's services, then runs
 * each module's start (from the configuration) and restore (from the
 * store) in table order; the loop gives each module its tick, runs the
 * timers the modules registered and, on SIGHUP, each module's reload in
 * table order; the drain runs each module's final and the tear-down each
 * one's stop, both in reverse. Adding a module is one file and one row of
 * the table (docs/architecture.md).
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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_config_keys.h"
#include "ctx.h"

/* ---- the table of modules ------------------------------------------------------
 * start, restore, reload, row, on_passage and tick in this order; final and
 * stop in reverse. The order is the order of the effects a user sees: a
 * stored passage is counted (metrics), gets its natural frequency's
 * baseline collected, is published on the passage channel, then feeds the
 * speed-drift alert, the STD and mean rules and the scale indicator (their
 * rows and messages in that order); the drain's lines come status first
 * (the last heartbeat), intake last. */
static const amfid_module *const modules[] = {
    &environment_lost_module, /* final: the readings the store never took */
    &intake_module,      /* the bus handlers, rings, tracker; tick: windows released */
    &environment_module, /* the environment input */
    &record_module,      /* the intake counters in the store (60 s) */
    &metrics_module,     /* metrics.textfile */
    &notify_module,      /* alerts.command */
    &freevib_module,     /* the natural frequency */
    &classes_module,     /* row: the class, axle groups and overload */
    &raw_module,         /* row: the passage's raw samples; timer: their retention */
    &pipeline_module,    /* reorder → sink; tick: results stored; on_passage: published */
    &drift_module,       /* the speed-drift alert */
    &stdmean_module,     /* the STD and mean rules */
    &scaleind_module,    /* the scale indicator and the known-truck runs */
    &modelfit_module,    /* the model fit: passages.fit_ratio, the model_mismatch alert */
    &natalert_module,    /* the natfreq alert */
    &reject_module,      /* refused messages: summaries */
    &status_module,      /* the heartbeat */
};
#define N_MODULES ((int)(sizeof modules / sizeof modules[0]))

/* The daemon: the core's own state. Every module's is in its own file. */
struct amfid {
    amfid_ctx c;                 /* the context handed to the modules */
    amfi_site_config cfg;        /* the running configuration (c.cfg points here) */
    amfi_bridge *bridge;
    pool pool;
    timers *timers;
    int started;                 /* modules whose start ran (stop undoes them) */
    int bus_open;
    const char *bus_key_option;  /* --bus-key (argv), NULL none */
    int64_t lcm_errors;          /* receive errors on a live bus */
};

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

static int load_config(const char *path, amfi_site_config *c)
{
    char err[512];
    amfi_config_defaults(c);
    if (amfi_config_load(path, c, err, sizeof err)) {
        fprintf(stderr, "amfid: %s\n", err);
        return -1;
    }
    return 0;
}

/* ---- the context's services --------------------------------------------------- */

static void collect(amfid_ctx *c, amfid_stats *s)
{
    amfid *h = (amfid *)c; /* c is the first member */
    memset(s, 0, sizeof *s);
    s->queue_depth = queue_depth(&h->pool.jobs);
    s->messages_malformed = h->lcm_errors;
    bus_stats(s);
    for (int i = 0; i < N_MODULES; i++)
        if (modules[i]->metrics)
            modules[i]->metrics(c, s);
}

/* ---- start-up ----------------------------------------------------------------------- */

/* The configuration and what it builds, each module's start: 0, or 2 (reported). */
static int start_config(amfid *h, const amfid_options *o)
{
    char err[512];
    amfid_ctx *c = &h->c;
    c->config_path = o->config;
    c->state = "starting";
    c->cfg = &h->cfg;
    c->modules = modules;
    c->n_modules = N_MODULES;
    c->publish = bus_publish;
    c->emit_alert = alert_emit;
    c->collect = collect;
    if (load_config(o->config, &h->cfg))
        return 2;
    if (o->db)
        snprintf(h->cfg.daemon.db_path, sizeof h->cfg.daemon.db_path, "%s", o->db);
    if (o->lcm_url)
        snprintf(h->cfg.daemon.lcm_url, sizeof h->cfg.daemon.lcm_url, "%s", o->lcm_url);
    if (amfi_bridge_create(&h->cfg.bridge, &h->bridge, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: bridge: %s\n", o->config, err);
        return 2;
    }
    c->bridge = h->bridge;
    for (; h->started < N_MODULES; h->started++) {
        const amfid_module *m = modules[h->started];
        if (m->start && m->start(c, err, sizeof err)) {
            h->started++; /* its stop frees what it built before failing */
            fprintf(stderr, "amfid: %s: %s: %s\n", o->config, m->section ? m->section : m->name,
                    err);
            return 2;
        }
    }
    /* A solver is built once here to check the solver section. */
    amfi_solver *probe = NULL;
    if (amfi_solver_create(h->bridge, &h->cfg.solver, &probe, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: solver: %s\n", o->config, err);
        return 2;
    }
    amfi_solver_destroy(probe);
    return 0;
}

/* --check-config's warnings: "amfid: FILE:LINE: key: WARNING: ..." */
static void print_warning(const char *line, void *arg)
{
    (void)arg;
    printf("amfid: %s\n", line);
}

/* The store belongs to one bridge: at its first start amfid writes the
 * configuration's site.id (and name, position, bridge type) into the store's meta table;
 * later starts refuse a store that holds another site.id, so two bridges'
 * passages never mix in one store (or in a fleet's central database, which
 * keys rows by site). A changed site.name or position is written over the
 * stored one. 0, or 1 after a logged error. */
static int claim_site(amfid *h)
{
    const amfi_site_identity *site = &h->cfg.site;
    amfi_store *st = h->c.store;
    char err[512], stored[AMFI_STORE_META_VALUE_MAX + 1];
    int found = 0;

    if (amfi_store_meta_get(st, "site.id", stored, sizeof stored, &found, err, sizeof err)) {
        LOG_ERR("store %s: %s", h->cfg.daemon.db_path, err);
        return 1;
    }
    if (found && strcmp(stored, site->id) != 0) {
        LOG_ERR("store %s belongs to site '%s', but %s configures site.id '%s': refusing "
                "to mix two sites in one store (give this site its own daemon.store.path, "
                "or correct site.id)",
                h->cfg.daemon.db_path, stored, h->c.config_path, site->id);
        return 1;
    }
    if (!found)
        LOG_INFO("store %s: first start of site '%s' (%s)", h->cfg.daemon.db_path, site->id,
                 site->name);
    struct {
        const char *key, *val;
    } kv[5] = {{"site.id", site->id}, {"site.name", site->name}, {NULL, NULL}, {NULL, NULL},
               {NULL, NULL}};
    char lat[32], lon[32];
    int nkv = 2;
    if (!isnan(site->latitude)) {
        snprintf(lat, sizeof lat, "%.7f", site->latitude);
        snprintf(lon, sizeof lon, "%.7f", site->longitude);
        kv[nkv].key = "site.latitude", kv[nkv++].val = lat;
        kv[nkv].key = "site.longitude", kv[nkv++].val = lon;
    }
    if (site->bridge_type[0])
        kv[nkv].key = "site.bridge_type", kv[nkv++].val = site->bridge_type;
    for (int i = 0; i < nkv; i++) {
        if (amfi_store_meta_get(st, kv[i].key, stored, sizeof stored, &found, err,
                                sizeof err) ||
            ((!found || strcmp(stored, kv[i].val)) &&
             amfi_store_meta_set(st, kv[i].key, kv[i].val, err, sizeof err))) {
            LOG_ERR("store %s: %s", h->cfg.daemon.db_path, err);
            return 1;
        }
        if (found && strcmp(stored, kv[i].val) && i > 0)
            LOG_INFO("store %s: %s changed from '%s' to '%s'", h->cfg.daemon.db_path,
                     kv[i].key, stored, kv[i].val);
    }
    return 0;
}

/* The store, each module's restore, the bus and the solver threads: 0, 1 or 2. */
static int start_runtime(amfid *h)
{
    char err[512];
    amfid_ctx *c = &h->c;
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
    if (amfi_store_open(h->cfg.daemon.db_path, h->cfg.daemon.sync_full, &c->store, err,
                        sizeof err)) {
        LOG_ERR("store %s: %s", h->cfg.daemon.db_path, err);
        return 1;
    }
    if (claim_site(h))
        return 1;
    char abs[PATH_MAX];
    const char *cfg_path = realpath(c->config_path, abs) ? abs : c->config_path;
    if (amfi_store_add_run(c->store, amfi_version(), cfg_path, &c->run_id, err, sizeof err)) {
        LOG_ERR("store %s: %s", h->cfg.daemon.db_path, err);
        return 1;
    }
    h->timers = c->timers = timers_create();
    if (!h->timers) {
        LOG_ERR("out of memory at start-up");
        return 1;
    }
    c->pool = &h->pool;
    for (int i = 0; i < N_MODULES; i++)
        if (modules[i]->restore && modules[i]->restore(c))
            return 1;
    int brc = bus_open(c, h->bus_key_option);
    h->bus_open = 1;
    if (brc)
        return brc;
    if (bus_subscribe_all(c))
        return 1;
    if (pool_start(&h->pool, h->bridge, &h->cfg.solver,
                   h->cfg.daemon.model_fit.enabled && h->cfg.daemon.natfreq_free_s > 0
                       ? h->cfg.daemon.model_fit_free_s
                       : 0.0,
                   h->cfg.daemon.model_fit_calc_rate_hz, h->cfg.daemon.workers,
                   h->cfg.daemon.queue_size, err, sizeof err)) {
        LOG_ERR("%s", err);
        return 1;
    }
    return 0;
}

int amfid_start(amfid **out, const amfid_options *o)
{
    amfid *h = calloc(1, sizeof *h);
    *out = h;
    if (!h) {
        fprintf(stderr, "amfid: out of memory\n");
        return 1;
    }
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
    h->bus_key_option = o->bus_key;
    int rc = start_config(h, o);
    if (rc == 0 && o->check_only) {
        /* what is still the shipped example's: a WARNING line each (stdout,
         * with the verdict), exit 2 with --strict */
        int nw = amfi_config_example_warnings(o->config, print_warning, NULL);
        printf("amfid: %s: ok (site %s, bridge %s, %d sensor(s), %d worker(s), store %s)",
               o->config, h->cfg.site.id, h->cfg.name, h->cfg.solver.n_sensors,
               h->cfg.daemon.workers, h->cfg.daemon.db_path);
        if (nw > 0)
            printf(" with %d warning(s)%s", nw, o->strict ? ": refused (--strict)" : "");
        printf("\n");
        if (nw != 0 && o->strict)
            rc = 2;
    } else if (rc == 0)
        rc = start_runtime(h);
    return rc;
}

/* ---- reload ---------------------------------------------------------------------------- */

/* A key that differs between the running configuration and the file: a
 * restart-only one (the key table's live flag 0) is reported by name. */
static int report_restart_only(const amfi_config_key *k, void *arg)
{
    (void)arg;
    if (!k->live)
        LOG_WARN("reload: %s changed; takes effect at the next start", k->path);
    return 0;
}

/* SIGHUP: the file read again (refused: the running configuration is kept);
 * every restart-only key that changed reported by name; the running
 * configuration takes the file's live keys (the key table's live flag:
 * the λ policy, the output channels, status_period_s, max_wait_s,
 * environment_max_skew_s, daemon.intake.*), then each module's reload in
 * table order with the configuration that ran until now and the new
 * running one (the intake gives the tracker the new max_wait_s and re-reads
 * its rate limits). */
void amfid_reload(amfid *h)
{
    static amfi_site_config n, old; /* large */
    if (load_config(h->c.config_path, &n)) {
        LOG_ERR("reload: the new configuration is refused; keeping the running one");
        return;
    }
    /* keep the command-line overrides */
    memcpy(n.daemon.db_path, h->cfg.daemon.db_path, sizeof n.daemon.db_path);
    memcpy(n.daemon.lcm_url, h->cfg.daemon.lcm_url, sizeof n.daemon.lcm_url);
    amfi_config_diff(&h->cfg, &n, report_restart_only, NULL);
    old = h->cfg;
    amfi_config_apply_live(&h->cfg, &n);
    for (int i = 0; i < N_MODULES; i++)
        if (modules[i]->reload)
            modules[i]->reload(&h->c, &old, &h->cfg);
    LOG_INFO("reload: configuration %s applied", h->c.config_path);
}

/* ---- the loop ---------------------------------------------------------------------------- */

void amfid_turn(amfid *h)
{
    lcm_t *lcm = bus_lcm();
    while (lcm && lcm_handle_timeout(lcm, 0) > 0)
        ;
    for (int i = 0; i < N_MODULES; i++)
        if (modules[i]->tick)
            modules[i]->tick(&h->c);
    timers_run(h->timers, &h->c, amfi_mono_s());
}

/* Read the bus until a signal or its end, then drain: every pending
 * passage is stored, solved or with its reason. 0, or 1. */
int amfid_run(amfid *h)
{
    int rc = 0;
    amfid_ctx *c = &h->c;
    c->state = "running";
    sd_notify(0, "READY=1");
    LOG_INFO("running: amfid %s, bus '%s', store %s, %d solver thread(s), bridge %s",
             amfi_version(), h->cfg.daemon.lcm_url[0] ? h->cfg.daemon.lcm_url : "(default)",
             h->cfg.daemon.db_path, h->pool.n_threads, h->cfg.name);
    uint64_t wd_usec = 0;
    int wd = sd_watchdog_enabled(0, &wd_usec) > 0;
    double last_wd = 0.0;
    lcm_t *lcm = bus_lcm();
    int lfd = lcm_get_fileno(lcm);
    const int replay = strncmp(h->cfg.daemon.lcm_url, "file://", 7) == 0;
    while (!stop_flag) {
        /* Replaying a log, the bus waits for the solvers (no overload,
         * the same rows at any speed); a live bus is always read. */
        const int hold = replay && queue_depth(&h->pool.jobs) >= h->cfg.daemon.queue_size;
        struct pollfd pf[2] = {{hold ? -1 : lfd, POLLIN, 0}, {h->pool.efd, POLLIN, 0}};
        int pr = poll(pf, 2, 100);
        if (pr < 0 && errno != EINTR) {
            LOG_ERR("poll: %s", strerror(errno));
            rc = 1;
            break;
        }
        if (pr > 0 && (pf[0].revents & POLLIN) && lcm_handle(lcm) != 0) {
            if (replay) { /* file:// provider: the end of the log */
                LOG_INFO("the bus has no more data (end of log)");
                break;
            }
            /* a live bus: a receive error is logged and counted, not fatal */
            h->lcm_errors++;
            ctx_error(c, "LCM receive error on '%s'", h->cfg.daemon.lcm_url);
        }
        /* A live bus: every message already queued, up to a bound that
         * keeps the heartbeat and the watchdog going in a flood; one at a
         * time (one poll round each) left LCM's queues to overflow. */
        for (int k = 0; !replay && pr > 0 && (pf[0].revents & POLLIN) && k < 512; k++)
            if (lcm_handle_timeout(lcm, 0) <= 0)
                break;
        if (pr > 0 && (pf[0].revents & (POLLHUP | POLLERR | POLLNVAL))) {
            LOG_INFO("the bus closed");
            break;
        }
        for (int i = 0; i < N_MODULES; i++) /* windows released, results stored, ... */
            if (modules[i]->tick)
                modules[i]->tick(c);
        if (reload_flag) {
            reload_flag = 0;
            amfid_reload(h);
        }
        double now = amfi_mono_s();
        timers_run(h->timers, c, now); /* heartbeat, summaries, metrics, records */
        if (wd && now - last_wd >= 0.5e-6 * (double)wd_usec) {
            sd_notify(0, "WATCHDOG=1");
            last_wd = now;
        }
    }
    int drc = amfid_drain(h);
    return rc ? rc : drc;
}

int amfid_drain(amfid *h)
{
    amfid_ctx *c = &h->c;
    c->state = "draining";
    sd_notify(0, "STOPPING=1");
    intake_release(c, 1);
    pool_join(&h->pool);
    pipeline_drain_results(c);
    if (pipeline_held() > 0) { /* the store still refuses: keep trying a while */
        LOG_WARN("store: %d passages held at shutdown; retrying for up to 20 s",
                 pipeline_held());
        pipeline_retry(c, 20.0);
    }
    for (int i = N_MODULES - 1; i >= 0; i--)
        if (modules[i]->final)
            modules[i]->final(c);
    amfid_stats s;
    collect(c, &s);
    LOG_INFO("stopped: %lld passages stored (%lld ok), %lld not stored, %lld messages received: "
             "%lld blocks, %lld vehicles, %lld rejected messages, %lld refused by the bus "
             "authentication",
             (long long)s.passages_stored, (long long)s.passages_ok,
             (long long)s.passages_lost, (long long)s.messages_in,
             (long long)s.blocks_received, (long long)s.vehicles_received,
             (long long)(s.blocks_rejected + s.vehicles_rejected + s.messages_malformed),
             (long long)s.auth_refused);
    return s.passages_lost > 0; /* acknowledged passages are safe; these never were */
}

/* The one tear-down: whatever amfid_start built, in reverse; NULL-safe. */
void amfid_stop(amfid *h)
{
    if (!h)
        return;
    pool_stop(&h->pool);
    for (int i = h->started - 1; i >= 0; i--)
        if (modules[i]->stop)
            modules[i]->stop(&h->c);
    if (h->bus_open)
        bus_close();
    timers_destroy(h->timers);
    amfi_store_close(h->c.store);
    amfi_bridge_destroy(h->bridge);
    free(h);
}

/* ---- for embedders ---------------------------------------------------------------------- */

void amfid_counts(amfid *h, amfid_stats *s)
{
    collect(&h->c, s);
}

lcm_t *amfid_lcm(amfid *h)
{
    (void)h;
    return bus_lcm();
}

amfi_store *amfid_store(amfid *h)
{
    return h->c.store;
}

const amfi_site_config *amfid_config(const amfid *h)
{
    return &h->cfg;
}
