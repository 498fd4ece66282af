/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ctx.h: the inside of amfid: the context of shared services every module
 * is handed, the module interface, the timers, and what the daemon's files
 * offer each other (functions only: every module's state is private to its
 * own file). docs/architecture.md draws it; tests/common/call_graph.sh
 * checks, on the built objects, that no two files call each other in a
 * circle (the services a module is handed go through this context's
 * function pointers, the table of modules through ctx->modules).
 *
 * The files: amfid.c (the core: start-up, the loop, the table of modules,
 * drain, tear-down, reload), log.c (the log), timer.c (the timers),
 * options.c (command line), bus.c (LCM, authentication, publish), admit.c
 * (decode, count and rate-limit what the inputs hand over), reject.c
 * (refused messages), intake.c (the bus handlers, the rings, the tracker,
 * windows to jobs), pool.c (solver threads), pipeline.c (reorder.c → sink.c
 * → the fan-out of a stored passage), alert.c (one alert out),
 * environment.c, freevib.c, drift.c, stdmean.c, scaleind.c, modelfit.c,
 * natalert.c (the indicators), classes.c (class and axle groups of each
 * passage), raw.c (the passages' raw samples and their retention),
 * notify.c, metrics.c, status.c (heartbeat, intake record).
 *
 * Who calls whom (from the built objects; tests/common/call_graph.sh
 * fails when this list differs from the library, or when it has a circle):
 *   admit.c -> reject.c
 *   alert.c -> log.c metrics.c notify.c
 *   amfid.c -> alert.c bus.c classes.c drift.c environment.c freevib.c intake.c log.c metrics.c modelfit.c natalert.c notify.c pipeline.c pool.c raw.c reject.c scaleind.c status.c stdmean.c timer.c
 *   bus.c -> admit.c log.c reject.c
 *   classes.c -> log.c
 *   drift.c -> log.c metrics.c
 *   environment.c -> admit.c bus.c log.c reject.c
 *   freevib.c -> environment.c log.c pipeline.c timer.c
 *   intake.c -> admit.c bus.c freevib.c log.c modelfit.c pipeline.c pool.c reject.c
 *   metrics.c -> log.c reject.c timer.c
 *   modelfit.c -> freevib.c log.c metrics.c
 *   natalert.c -> freevib.c log.c metrics.c
 *   notify.c -> log.c
 *   pipeline.c -> log.c metrics.c notify.c pool.c reorder.c sink.c
 *   raw.c -> log.c timer.c
 *   reject.c -> log.c timer.c
 *   reorder.c -> pool.c
 *   scaleind.c -> environment.c log.c metrics.c
 *   sink.c -> log.c pool.c
 *   status.c -> bus.c environment.c log.c pipeline.c timer.c
 *   stdmean.c -> log.c metrics.c timer.c
 * log.c and timer.c call nothing of amfid's; a module reaches the core only
 * through the context.
 *
 * Threads: everything here is the main thread's; the solver threads see
 * only the jobs they are handed (pool.h).
 */
#ifndef AMFID_CTX_H
#define AMFID_CTX_H

#include <stdlib.h>

#include "amfi/amfi.h"
#include "amfi_time.h" /* amfi_mono_s: timeouts, backoff, periods (wall time) */
#include "amfi_version.h"
#include "amfid.h"
#include "indicators.h"
#include "pool.h"
#include "ring.h"
#include "tracker.h"

typedef struct amfid_ctx amfid_ctx;
typedef struct amfid_module amfid_module;
typedef struct timers timers;

/* ---- the context: shared services, no module state ------------------------- */

struct amfid_ctx {
    const amfi_site_config *cfg; /* the running configuration (read-only here; a
                                    reload replaces its live keys between turns) */
    const char *config_path;
    const amfi_bridge *bridge;   /* immutable: the solver threads share it */
    amfi_store *store;
    pool *pool;                  /* the solver threads: jobs in, results out */
    timers *timers;              /* periodic work (timer.h) */
    int64_t run_id;              /* this start's row in the store's runs table */
    int64_t newest_utime;        /* the stream's data time: the newest sample (intake) */
    const char *state;           /* "starting", "running", "degraded", "draining" */
    char last_error[256];        /* the newest error (the status message's) */
    /* the modules in table order (the fan-out of a stored passage) */
    const amfid_module *const *modules;
    int n_modules;
    /* services (amfid.c sets them) */
    int (*publish)(amfid_ctx *c, const char *channel, const void *data, size_t len);
    /* One alert event out the way every alert goes: stored (indicator_id <= 0:
     * none), published, counted in the metrics, handed to alerts.command,
     * logged (a raise as a warning). */
    void (*emit_alert)(amfid_ctx *c, int64_t utime, const amfi_alert_event *a,
                       int64_t indicator_id);
    /* Every module's counters (amfid_stats). */
    void (*collect)(amfid_ctx *c, amfid_stats *s);
};

/* The error service: last_error and the log (log.c). */
#define ctx_error(c, ...) amfid_error((c)->last_error, sizeof (c)->last_error, __VA_ARGS__)

/* Encode a message of lcm-gen type T and publish it (signed when amfid has
 * a key). */
#define BUS_PUBLISH(c, T, channel, msg)                                                  \
    do {                                                                                 \
        int len_ = T##_encoded_size(msg);                                                \
        void *buf_ = len_ > 0 ? malloc((size_t)len_) : NULL;                             \
        if (buf_ && T##_encode(buf_, 0, len_, msg) == len_)                              \
            (c)->publish(c, channel, buf_, (size_t)len_);                                \
        free(buf_);                                                                      \
    } while (0)

/* ---- the module interface --------------------------------------------------- */

/* A passage of one vehicle on its way into the store (row) and stored (on_passage). */
typedef struct amfid_passage {
    const job *j;
    const amfi_passage_row *r; /* its row (on_passage: as stored) */
    int64_t id;                /* its row id (on_passage) */
    int feeds;                 /* solved, ok and (single_presence_only) alone: it feeds
                                  the STD and mean rules */
} amfid_passage;

/* Every member may be NULL. start, restore, reload, row, on_passage and tick
 * run in table order; final and stop in reverse. */
struct amfid_module {
    const char *name;
    const char *section; /* the configuration it is built from, for start's errors */
    /* From the configuration, before the store is open (also --check-config):
     * the state zeroed and built. 0, or non-zero with the message in err
     * (the configuration is refused: exit 2). */
    int (*start)(amfid_ctx *c, char *err, size_t errlen);
    /* The store is open: what the store keeps (baselines, open alerts),
     * subscriptions (bus_want), timers (timer_add). 0, or 1 (logged). */
    int (*restore)(amfid_ctx *c);
    /* SIGHUP: old is the configuration that ran until now, n the new running
     * one (old with the file's live keys, the key table's live flag; the core
     * has logged every restart-only key that changed): apply what changed. */
    void (*reload)(amfid_ctx *c, const amfi_site_config *old, const amfi_site_config *n);
    /* A passage about to be stored: its columns (r is the row). */
    void (*row)(amfid_ctx *c, const amfid_passage *p, amfi_passage_row *r);
    /* A passage stored (committed): publish, feed, count. */
    void (*on_passage)(amfid_ctx *c, const amfid_passage *p);
    /* Every turn of the loop. */
    void (*tick)(amfid_ctx *c);
    /* Its counters into s. */
    void (*metrics)(amfid_ctx *c, amfid_stats *s);
    /* Draining (the bus read no more, every passage stored): last work, the log. */
    void (*final)(amfid_ctx *c);
    /* Tear down; NULL-safe on what start did not build. */
    void (*stop)(amfid_ctx *c);
};

/* The modules (amfid.c's table holds them, in order). */
extern const amfid_module environment_lost_module, intake_module, environment_module,
    record_module, metrics_module, notify_module, freevib_module, classes_module,
    pipeline_module, drift_module, stdmean_module, scaleind_module, modelfit_module,
    natalert_module, reject_module, status_module, raw_module;

/* ---- timers (timer.c) ------------------------------------------------------- */

/* A periodic callback: 0 done (due again a period later), 1 not now (tried
 * again at the next turn). */
typedef int (*timer_fn)(amfid_ctx *c);
#define TIMERS_MAX 16
/* fn every *period_s seconds (read at each run: a pointer into the running
 * configuration follows a reload), due at once; called in the order added.
 * 0, or −1 when the list is full. */
int timer_add(timers *t, const double *period_s, timer_fn fn);
timers *timers_create(void);
void timers_destroy(timers *t);
/* Call every timer due at now (amfi_mono_s()). */
void timers_run(timers *t, amfid_ctx *c, double now);

/* ---- the bus (bus.c) --------------------------------------------------------- */

/* The URL amfid opens: the configured one (or LCM's default) with
 * recv_buf_size for a udpm:// bus; warns when the kernel caps it lower. */
void bus_url(const amfi_daemon_config *dc, char *url, size_t n);
/* UDP datagrams the kernel dropped on this process's sockets, or -1. */
int64_t bus_udp_drops(void);
/* Open the bus and its authentication: the site key (key_option, else
 * daemon.bus.key_file, else the systemd credential amfi-bus-key) into the
 * verifier (daemon.bus.auth required) and the signer of amfid's messages.
 * 0, 1 (the bus cannot be opened) or 2 (no key, a key file refused). */
int bus_open(amfid_ctx *c, const char *key_option);
lcm_t *bus_lcm(void);
/* An input to subscribe (from a module's restore): fn sees only messages
 * that passed the authentication, the trailer taken off. */
void bus_want(int input, const char *channel, lcm_msg_handler_t fn);
/* Subscribe every input wanted, each with a queue of daemon.bus_queue
 * messages: 0, or −1 (logged). */
int bus_subscribe_all(amfid_ctx *c);
int bus_publish(amfid_ctx *c, const char *channel, const void *data, size_t len);
void bus_stats(amfid_stats *s);
void bus_close(void);

/* ---- intake admission (admit.c) ---------------------------------------------- */

/* The rate limits from the configuration (start, reload): full buckets at
 * start, the buckets kept at a reload. */
void admit_limits(amfid_ctx *c, const amfi_site_config *cfg);
/* Take `cost` from input's bucket: 1 taken, 0 over the limit. */
int admit_take(amfid_ctx *c, int input, double cost);
double admit_rate(int input);
/* Count a message of `input` and decode it (the raw bytes checked against
 * the type first): 0, or −1 when malformed (counted, logged). */
int admit_decode(amfid_ctx *c, amfi_msg_type type, int input, const char *tname,
                 const lcm_recv_buf_t *rb, const char *ch, void *m);
/* A message the authentication refused (counted as received). */
void admit_count_in(void);
void admit_reset(void);
void admit_stats(amfid_stats *s);

/* ---- refused messages (reject.c) ---------------------------------------------- */

/* Count a refused message of `input` for `reason`; the formatted line becomes
 * last_error and is logged within the rate limit. */
void reject_note(amfid_ctx *c, int input, int reason, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
const char *reject_reason_name(int reason);

/* ---- intake (intake.c) ------------------------------------------------------- */

/* Windows the tracker has decided: to the solvers, or straight to the
 * pipeline (flush: every pending window now, at stop). */
void intake_release(amfid_ctx *c, int flush);

/* ---- environment input (environment.c) ----------------------------------------- */

/* Store the buffered readings in one transaction (heartbeat, full, stop);
 * on failure they stay buffered and the next flush retries. */
void environment_flush(amfid_ctx *c);
/* The deck temperature at utime (µs, data time) interpolated between the
 * stored readings at most max_gap_s apart (the ones received so far are
 * stored first); NaN when there is none, or on a store error. */
double environment_deck_at(amfid_ctx *c, int64_t utime, double max_gap_s);

/* ---- the natural frequency (freevib.c) ---------------------------------------- */

/* At release: the window's free vibration (in rings) into j->f1_* (NaN: none). */
void freevib_estimate(amfid_ctx *c, job *j, amfi_ring *const *rings);
/* The baseline's f1 at the calibration temperature: 1 and *f_ref_hz once the
 * compensation is fitted, else 0. */
int freevib_reference(double *f_ref_hz);
/* f1(T) / f1(calibration temperature) at the deck temperature of utime by the
 * compensation's temperature model (its fitted slopes, or alerts.scale's
 * prior ones halved and turned); 1 without a temperature. */
double freevib_time_scale(amfid_ctx *c, int64_t utime);

/* ---- the model fit (modelfit.c) ------------------------------------------------ */

/* At release: an ok window of one vehicle with enough free vibration gets
 * its samples through alerts.model_fit.free_s past the exit (j->accel_fit)
 * for its solver thread's second solve. */
void modelfit_take(amfid_ctx *c, job *j, amfi_ring *const *rings);

/* ---- the pipeline (pipeline.c) ------------------------------------------------- */

/* Park a finished job by seq; store, feed and publish every consecutive one. */
int pipeline_complete(amfid_ctx *c, job *j);
/* Store a job now, outside the entry order (invalid vehicles); takes it. */
int pipeline_store_now(amfid_ctx *c, job *j);
/* Read the eventfd and complete every result the solvers handed back. */
void pipeline_drain_results(amfid_ctx *c);
/* Retry the held passages (final > 0: stopping, for up to final seconds). */
void pipeline_retry(amfid_ctx *c, double final);
int pipeline_held(void);
int pipeline_degraded(void);

/* ---- the scale indicator (scaleind.c) ------------------------------------------ */

/* What it holds, for its tests. */
typedef struct scaleind_view {
    const char *scale_state, *truck_state; /* NULL: off */
    int64_t fed, no_temp, comp_fed, comp_raw;
    int compensate;
    int fitted;                     /* the scale indicator's temperature model: */
    double warm_slope, frost_slope; /* its fitted slopes */
} scaleind_view;
void scaleind_view_of(scaleind_view *v);

/* ---- alerts (alert.c), notices (notify.c), metrics (metrics.c) ---------------- */

void alert_emit(amfid_ctx *c, int64_t utime, const amfi_alert_event *a, int64_t indicator_id);
/* Run (or queue) alerts.command for one raised or cleared alert; no-op
 * when alerts.command is not set. Never waits. */
void notify_alert(amfid_ctx *c, int64_t utime, int64_t alert_id, const char *level,
                  const char *kind, const char *message, int64_t indicator_id, int raised);
/* An alert kind raised or cleared (open in the metrics); the newest
 * indicator evaluation. */
void metrics_alert(const char *kind, int raised);
void metrics_indicator(double std_ratio, double p_value, double mean_ratio);

#endif /* AMFID_CTX_H */
