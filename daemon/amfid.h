/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfid.h: the daemon's state and the functions its files share (amfid's
 * own header; nothing outside daemon/ includes it).
 *
 * Threads and ownership: everything in `daemon_s` except `pool`'s queues is
 * owned by the main thread: the configuration, the bus, the sample rings,
 * the tracker, the reorder buffer, the store, the indicators and the
 * counters. The solver threads touch only the jobs they are handed and
 * their own solvers (pool.h); nothing else is shared between threads.
 *
 * Files: amfid.c (main: start-up, loop, shutdown), options.c (command
 * line), intake.c (bus handlers, validation, windows to jobs), pool.c (job
 * queues, solver threads), pipeline.c (in-order store, indicators,
 * publish), control.c (configuration, heartbeat, reload, restart state),
 * drift.c (the speed-drift alert), environment.c (the environment input),
 * scaleind.c (the scale indicator and the known-truck runs),
 * freevib.c (the natural frequency from the free vibration).
 */
#ifndef AMFID_H
#define AMFID_H

#include <lcm/lcm.h>
#include <stdint.h>
#include <stdio.h>
#include <systemd/sd-daemon.h>

#include "amfi/amfi.h"
#include "amfi_auth.h"
#include "amfi_config.h"
#include "amfi_msg_check.h"
#include "amfi_time.h" /* amfi_mono_s: timeouts, backoff, periods (wall time) */
#include "amfi_version.h"
#include "indicators.h"
#include "known_truck.h"
#include "scale.h"
#include "pool.h"
#include "ring.h"
#include "speed_drift.h"
#include "store.h"
#include "tracker.h"

#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif

/* ---- logging (log.h: stderr, journald reads the <N> prefixes) ---------- */
#include "log.h"

/* ---- command line (options.c) ------------------------------------------- */

typedef struct amfid_options {
    const char *config;   /* --config, default AMFID_DEFAULT_CONFIG */
    const char *db;       /* --db, NULL: the file's */
    const char *lcm_url;  /* --lcm-url, NULL: the file's */
    int check_only;       /* --check-config */
    const char *bus_key;  /* --bus-key FILE, NULL: daemon.bus.key_file, then the
                             systemd credential */
    const char *make_bus_key; /* --make-bus-key FILE: create a site key and exit */
} amfid_options;

/* 0: run. --help and --version print and exit 0; a bad command line is
 * reported on stderr and exits 2 (amfi_cli.h). */
void amfid_parse_options(int argc, char **argv, amfid_options *o);

/* ---- the daemon ---------------------------------------------------------- */

/* Refused bus messages (reject.c): per input and reason. The reasons are
 * the raw-buffer checker's (amfi_msg_reason, messages/amfi_msg_check.h) and
 * REJECT_INVALID, a message that decoded but failed amfid's validation. */
enum { REJECT_ACCEL, REJECT_VEHICLE, REJECT_TRUTH, REJECT_ENVIRONMENT, REJECT_NINPUTS };
#define REJECT_INVALID AMFI_MSG_NREASONS
#define REJECT_QUARANTINE (AMFI_MSG_NREASONS + 1) /* an accel block far from the stream */
#define REJECT_RATE (AMFI_MSG_NREASONS + 2)       /* over its channel's rate limit */
#define REJECT_SOURCE (AMFI_MSG_NREASONS + 3)     /* a value from a source not configured */
#define REJECT_IMPLAUSIBLE (AMFI_MSG_NREASONS + 4) /* against the recent readings */
/* refused by the bus authentication (bus.c): REJECT_AUTH + amfi_auth_reason
 * (unsigned, bad_mac, replay, skew, producers; amfi_auth.h) */
#define REJECT_AUTH (AMFI_MSG_NREASONS + 5)
#define REJECT_NREASONS (REJECT_AUTH + AMFI_AUTH_NREASONS)
#define REJECT_EXAMPLE 512
typedef struct reject_state {
    int64_t count[REJECT_NINPUTS][REJECT_NREASONS]; /* since start */
    int64_t total;
    int64_t held, held_by[REJECT_NINPUTS][REJECT_NREASONS]; /* not logged this period */
    int logged;                                             /* lines logged this period */
    double period_start;                                    /* amfi_mono_s() */
    /* the store's summary (table refusals), every daemon.intake.summary_period_s */
    int64_t sum_count[REJECT_NINPUTS][REJECT_NREASONS];     /* this summary period */
    char sum_example[REJECT_NINPUTS][REJECT_NREASONS][REJECT_EXAMPLE]; /* the first's line */
    double sum_start;                                       /* amfi_mono_s() */
    int64_t sum_start_wall;                                 /* µs, wall clock */
    int64_t summaries_stored, summaries_lost;               /* rows */
} reject_state;

/* A token bucket of one input channel (intake.c): `rate` tokens a second,
 * at most `cap`; refilled by the wall time or the data time that passed,
 * whichever is more (a replay at any speed keeps the data's own rate; a
 * flood cannot move the data time). */
typedef struct bucket {
    double tokens, rate, cap;
    double last_wall;     /* amfi_mono_s() of the last refill */
    int64_t last_data;    /* newest_utime at the last refill */
} bucket;

/* Environment readings waiting to be stored (environment.c). */
#define ENV_BUF 64
typedef struct env_state {
    amfi_environment_row buf[ENV_BUF];
    int n;                 /* readings in buf, oldest first */
    int failing;           /* the last flush failed (logged once) */
    int64_t received, rejected, stored, lost; /* since start */
    int64_t thinned;       /* accepted, not stored: within environment_min_interval_s */
    int have_ref;          /* a reading was accepted: ref_* hold it */
    int64_t ref_utime, last_kept_utime;
    double ref_deck;
    /* implausible readings that agree with each other: adopted at the third
     * in a row (a deck sensor replaced or recalibrated, a first reading that
     * was wrong), as the rings adopt a time jump */
    int cand_n;
    int64_t cand_utime;
    double cand_deck;
} env_state;

/* The scale indicator and the known-truck runs (scaleind.c). */
typedef struct scale_state {
    amfi_scale *scale;             /* NULL: alerts.scale.enabled off */
    amfi_known_truck *truck;       /* NULL: alerts.known_truck.enabled off */
    int enabled, truck_enabled;    /* in force (a reload reports changes) */
    int compensate;                /* daemon.indicators.temperature: compensated */
    double max_gap_s;
    amfi_scale_params params;
    amfi_known_truck_params truck_params;
    int64_t fed, no_temp, runs, refused; /* this run's: inputs, solved passages
                                    without a temperature, truck runs, refused */
    int64_t comp_fed, comp_raw;    /* this run's passages fed to the STD and mean
                                    rules compensated, and raw for want of a
                                    deck temperature (compensate on) */
    double last_scale, last_cusum; /* the newest block's (NaN: none yet) */
} scale_state;

/* Alert notices (notify.c). */
#define NOTIFY_MAX_RUNNING 64 /* alerts.command_max_running's upper bound */
#define NOTIFY_QUEUE 256      /* notices waiting; beyond: dropped, counted */
struct notice;
typedef struct notify_state {
    int pid[NOTIFY_MAX_RUNNING];        /* running children, 0: free slot */
    double started[NOTIFY_MAX_RUNNING]; /* amfi_mono_s() at spawn */
    int term_sent[NOTIFY_MAX_RUNNING];  /* SIGTERM sent (timed out, or amfid stopping) */
    int stopping;                       /* notify_finish gave up waiting: killed at stop */
    int running;
    struct notice *queue[NOTIFY_QUEUE];
    int qhead, queued;
    int64_t started_total, ok, failed, timeouts, dropped;
} notify_state;

/* The natural frequency's compensation and counters (freevib.c). */
typedef struct freevib_state {
    amfi_natfreq_comp *comp;  /* NULL: off (free_s 0) or not compensated */
    int64_t estimated;        /* passages with an f1 */
    int64_t no_segment;       /* ok passages without free vibration (cut, data missing) */
    int64_t refused[AMFI_NATFREQ_NREFUSALS]; /* by amfi_natfreq_estimate's code; [0] invalid */
    int64_t no_temperature;   /* baseline candidates without a deck temperature */
} freevib_state;

/* What the metrics file reports beyond the status counters (metrics.c). */
#define SOLVE_BUCKETS 12
#define SOLVE_RECENT 1024
#define OPEN_KINDS 8
typedef struct metrics_state {
    int64_t by_status[16];        /* stored passages per amfi_store_status_name(k) */
    int64_t solve_le[SOLVE_BUCKETS]; /* solves of at most metrics_solve_bucket(i) s */
    int64_t solve_count;
    double solve_sum_s;
    double recent_s[SOLVE_RECENT]; /* the newest solve times, a ring */
    int recent_n, recent_at;
    int have_indicator;
    double std_ratio, p_value, mean_ratio; /* the newest evaluation */
    char open_kind[OPEN_KINDS][32];      /* alert kinds seen, and whether open */
    int open[OPEN_KINDS];
    double start_wall;            /* time(NULL) at start */
    double last_write;            /* amfi_mono_s() of the last write */
    int64_t write_errors;
    int failing;                  /* the last write failed (logged once) */
} metrics_state;

typedef struct daemon_s {
    amfi_site_config cfg;
    const char *config_path;
    amfi_bridge *bridge;           /* immutable once built: the solvers share it */
    lcm_t *lcm;
    amfi_store *store;
    amfi_indicators *ind;
    amfi_indicator_params ind_params; /* in force (a reload reports changes) */
    amfi_speed_drift *drift;       /* the speed-drift alert (drift.c) */
    amfi_speed_drift_params drift_params; /* in force (a reload reports changes) */
    amfi_tracker *tracker;
    amfi_ring *rings[AMFI_MAX_SENSORS];
    pool pool;
    /* the pipeline (pipeline.c): results in seq order (reorder.c), then the
     * store sink (sink.c: held in order while the store cannot write) */
    struct reorder *reorder;
    struct sink *sink;
    int64_t released;              /* windows released by the tracker */
    /* counters (status_t) */
    int64_t blocks_received, blocks_rejected, vehicles_received, vehicles_rejected;
    int64_t messages_malformed, passages_stored, passages_ok, truth_received;
    int64_t messages_in;           /* every message the three inputs handed over */
    bucket lim[REJECT_NINPUTS];    /* rate limits per input channel (intake.c) */
    int64_t vehicles_evicted;      /* the tracker was full: the stalest went (stored) */
    int64_t references_refused;    /* calibration references not taken (source, range) */
    int64_t invalid_unstored;      /* refused vehicles over the rate: summarised only */
    int64_t newest_utime;
    int64_t udp_drops, udp_drops_logged; /* kernel drops on our sockets */
    reject_state rej;
    /* the bus authentication (bus.c): the verifier with daemon.bus.auth
     * required (NULL: off), the signer of what amfid publishes (NULL: no
     * key), each input's subscription context */
    amfi_auth_verifier *auth;
    amfi_auth_signer *signer;
    int64_t auth_refused;          /* messages refused by the authentication */
    const char *bus_key_option;    /* --bus-key (argv), NULL none */
    struct bus_sub {
        struct daemon_s *d;
        lcm_msg_handler_t fn;
        int input;
    } bus_subs[REJECT_NINPUTS];
    env_state env;                 /* environment readings (environment.c) */
    scale_state sc;                /* scale indicator, known truck (scaleind.c) */
    freevib_state fv;              /* the natural frequency (freevib.c) */
    /* the store_degraded alert while the sink holds passages (pipeline.c) */
    int64_t degraded_utime;        /* data time the store_degraded alert was raised */
    char degraded_msg[1024];       /* its message, stored once the store writes again */
    char last_error[256];
    const char *state;
    notify_state notify;
    metrics_state metrics;
    int64_t run_id;                /* this start's row in the store's runs table */
    int64_t samples_missing;       /* as of the last heartbeat */
    double intake_recorded;        /* amfi_mono_s() of the last record_intake */
} daemon_s;

/* The error service (log.c): last_error and the log. */
#define set_error(d, ...) amfid_error((d)->last_error, sizeof (d)->last_error, __VA_ARGS__)

/* ---- life cycle (amfid.c), main thread ----------------------------------- */

/* d zeroed. The configuration (with o's overrides) and what it builds; with
 * o->check_only print the result and stop there; else the store (site
 * claimed), the tracker, the bus (subscribed) and the solver threads.
 * 0, 1 (runtime) or 2 (configuration), reported. */
int amfid_start(daemon_s *d, const amfid_options *o);
/* The loop: read the bus until SIGTERM/SIGINT or the end of a replayed log,
 * then amfid_drain. 0, or 1. */
int amfid_run(daemon_s *d);
/* Stop reading: release every window, let the solvers finish, store every
 * pending passage (retrying a refusing store for up to 20 s). 0, or 1 when
 * a passage could not be stored. */
int amfid_drain(daemon_s *d);
/* Tear down whatever amfid_start built, in reverse; NULL-safe. */
void amfid_stop(daemon_s *d);

/* ---- the bus (bus.c), main thread ----------------------------------------- */

/* The URL amfid opens: the configured one (or LCM's default) with
 * recv_buf_size for a udpm:// bus; warns when the kernel caps it lower. */
void bus_url(const amfi_daemon_config *dc, char *url, size_t n);
/* UDP datagrams the kernel dropped on this process's sockets, or -1. */
int64_t bus_udp_drops(void);
/* The bus authentication: the site key (key_option, else daemon.bus.key_file,
 * else the systemd credential amfi-bus-key) loaded into the verifier (when
 * daemon.bus.auth is required) and the signer of amfid's own messages; with
 * auth off a warning, and the signer only if a key is found. 0, or 2
 * (reported: no key, or a key file refused). */
int bus_auth_start(daemon_s *d, const char *key_option);
void bus_auth_stop(daemon_s *d);
/* lcm_subscribe through the authentication: fn sees only messages that
 * passed it, with the trailer taken off (refusals counted under `input`,
 * by reason); with auth off, a trailer is taken off unchecked. NULL on
 * failure. */
lcm_subscription_t *bus_subscribe(daemon_s *d, const char *channel, lcm_msg_handler_t fn,
                                  int input);
/* Publish an encoded message, signed when amfid has a key. */
int bus_publish(daemon_s *d, const char *channel, const void *data, size_t len);
/* Encode a message of lcm-gen type T and bus_publish it. */
#define BUS_PUBLISH(d, T, channel, msg)                                                  \
    do {                                                                                 \
        int len_ = T##_encoded_size(msg);                                                \
        void *buf_ = len_ > 0 ? malloc((size_t)len_) : NULL;                             \
        if (buf_ && T##_encode(buf_, 0, len_, msg) == len_)                              \
            bus_publish(d, channel, buf_, (size_t)len_);                                 \
        free(buf_);                                                                      \
    } while (0)

/* ---- refused messages (reject.c), main thread ----------------------------- */

/* Count a refused message of `input` for `reason`; the formatted line becomes
 * last_error and is logged within the rate limit. */
void reject_note(daemon_s *d, int input, int reason, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The period's summary line when the period is over, and the store's
 * summary rows when daemon.intake.summary_period_s is (from the loop). */
void reject_tick(daemon_s *d);
/* The last summary and the totals by channel and reason (at stop). */
void reject_final(daemon_s *d);
const char *reject_reason_name(int reason);

/* ---- bus intake (intake.c), main thread ---------------------------------- */

/* Subscribe the three inputs with queues of daemon.bus_queue messages:
 * 0, or −1 (logged). */
int intake_subscribe(daemon_s *d);
/* The rate limits from the configuration (start, reload): full buckets. */
void intake_limits(daemon_s *d);
/* Take `cost` from input's bucket: 1 taken, 0 over the limit. */
int intake_take(daemon_s *d, int input, double cost);
/* Count a message of `input` and decode it (the raw bytes checked against
 * the type first): 0, or −1 when malformed (counted, logged, nothing left
 * to free). tname: the type's name for the message. */
int intake_decode(daemon_s *d, amfi_msg_type type, int input, const char *tname,
                  const lcm_recv_buf_t *rb, const char *ch, void *m);
/* Windows the tracker has decided: to the solvers, or straight to the store. */
void release_windows(daemon_s *d, int flush);

/* ---- environment input (environment.c), main thread ----------------------- */

/* The LCM handler of daemon.channels.environment: check, count, buffer. */
void environment_on_message(const lcm_recv_buf_t *rb, const char *ch, void *user);
/* Store the buffered readings in one transaction (heartbeat, full, stop);
 * on failure they stay buffered and the next flush retries. */
void environment_flush(daemon_s *d);
/* The deck temperature at utime (µs, data time) interpolated between the
 * stored readings at most max_gap_s apart (the ones received so far are
 * stored first: the heartbeat's flush may be a second of wall time behind,
 * many seconds of data in a fast replay); NaN when there is none, or on a
 * store error (set_error). Shared by the scale indicator and the natural
 * frequency. */
double environment_deck_at(daemon_s *d, int64_t utime, double max_gap_s);

/* ---- in-order pipeline (pipeline.c), main thread -------------------------- */

/* Park a finished job by seq; store, feed and publish every consecutive one. */
int pipeline_complete(daemon_s *d, job *j);
/* Store a job now, outside the entry order (invalid vehicles); takes the job
 * (held, in order, if the store cannot write). */
int pipeline_store_now(daemon_s *d, job *j);
/* One alert event out the way every alert goes: stored (indicator_id <= 0:
 * none), published on the alert channel, counted in the metrics, handed to
 * alerts.command and logged (a raise as a warning). */
void emit_alert(daemon_s *d, int64_t utime, const amfi_alert_event *a, int64_t indicator_id);
/* Read the eventfd and complete every result the solvers handed back. */
void pipeline_drain_results(daemon_s *d);
/* Retry the held passages when their time has come (the loop); with
 * final != 0 (stopping) keep trying for up to final seconds. */
void pipeline_retry(daemon_s *d, double final);
/* The reorder buffer and the sink (daemon.store.held_max_bytes): 0, or −1
 * out of memory; stop frees whatever they still hold. */
int pipeline_start(daemon_s *d);
void pipeline_stop(daemon_s *d);
/* Passages held now, not stored since start (all causes), degraded. */
int pipeline_held(const daemon_s *d);
int64_t pipeline_lost(const daemon_s *d);
int pipeline_degraded(const daemon_s *d);

/* ---- alert notices (notify.c), main thread -------------------------------- */

/* Run (or queue) alerts.command for one raised or cleared alert; no-op
 * when alerts.command is not set. Never waits. */
void notify_alert(daemon_s *d, int64_t utime, int64_t alert_id, const char *level,
                  const char *kind, const char *message, int64_t indicator_id, int raised);
/* From the loop: reap children, SIGTERM/SIGKILL overdue ones, start queued. */
void notify_tick(daemon_s *d);
/* At stop: let running and queued notices finish (each within its timeout). */
void notify_finish(daemon_s *d);
/* Tear-down: free the queue, kill what still runs. */
void notify_free(daemon_s *d);

/* ---- health metrics (metrics.c), main thread ------------------------------- */

/* Account one stored passage (status, solve time) and one alert raise/clear. */
void metrics_passage(daemon_s *d, const char *status, int solved, double solve_ms);
void metrics_indicator(daemon_s *d, double std_ratio, double p_value, double mean_ratio);
void metrics_alert(daemon_s *d, const char *kind, int raised);
/* Rewrite metrics.textfile when metrics.interval_s has passed (force: now). */
void metrics_tick(daemon_s *d, int force);

/* ---- the speed-drift alert (drift.c), main thread -------------------------- */

/* The engine from alerts.speed_drift: 0, or an amfi_speed_drift_create code
 * with the message in err. */
int drift_create(daemon_s *d, char *err, size_t errlen);
/* The window from the store's newest estimated passages, the open alert. */
void drift_restore(daemon_s *d);
/* One stored passage whose speed was estimated: its two speeds, m/s. */
void drift_feed(daemon_s *d, int64_t utime, double speed_mps, double speed_given_mps);
/* SIGHUP: a changed alerts.speed_drift is reported (applies at the next start). */
void drift_reload(daemon_s *d, const amfi_site_config *n);
void drift_destroy(daemon_s *d);

/* ---- the scale indicator and known-truck runs (scaleind.c), main thread --- */

/* Both from alerts.scale and alerts.known_truck (each may be off): 0, or
 * a create code with the message in err. */
int scaleind_create(daemon_s *d, char *err, size_t errlen);
/* Replay the stored inputs (ok passages with a deck temperature); the open
 * alerts from the store. */
void scaleind_restore(daemon_s *d);
/* A solved passage's row: its deck temperature (has_deck_c, deck_c) from
 * the environment readings, or none (counted). */
void scaleind_deck(daemon_s *d, amfi_passage_row *r);
/* A solved passage's row, its deck taken: r->gvw_comp_kg, the weight the
 * STD and mean rules are fed. With daemon.indicators.temperature
 * compensated and a deck temperature: the GVW brought to the calibration
 * temperature by the scale indicator's temperature model (its fitted slopes
 * once its baseline exists, alerts.scale's prior slopes before, also with
 * the scale indicator off); else the GVW (counted when for want of a
 * temperature). */
void scaleind_comp(daemon_s *d, amfi_passage_row *r);
/* A stored ok passage's row: feeds the indicators when it has a
 * temperature (and passes daemon.indicators.single_presence_only). */
void scaleind_feed(daemon_s *d, const amfi_passage_row *r);
/* SIGHUP: a change is reported (applies at the next start). */
void scaleind_reload(daemon_s *d, const amfi_site_config *n);
/* At stop: the counters in the log. */
void scaleind_final(daemon_s *d);
void scaleind_destroy(daemon_s *d);
/* ---- the natural frequency (freevib.c), main thread ----------------------- */

/* The compensation, its baseline refilled from the store (free_s > 0). */
void freevib_start(daemon_s *d);
void freevib_stop(daemon_s *d);
/* SIGHUP: a changed daemon.natural_frequency is reported (applies at the next start). */
void freevib_reload(daemon_s *d, const amfi_site_config *n);
/* At release: the window's free vibration into j->f1_* (NaN: none). */
void freevib_estimate(daemon_s *d, job *j);
/* A row's f1 columns (the event's vehicle that left last carries them). */
void freevib_row(daemon_s *d, const job *j, amfi_passage_row *r);
/* After the row is stored: the baseline's collection. */
void freevib_stored(daemon_s *d, const job *j);
/* The counters into the store's meta table (natfreq.*), and the log at stop. */
void freevib_record(daemon_s *d);
void freevib_final(daemon_s *d);

/* ---- configuration, state, heartbeat, reload (control.c), main thread ----- */

int load_config(const char *path, amfi_site_config *c);
void indicator_params(const amfi_daemon_config *dc, amfi_indicator_params *p);
/* The baseline, the window's GVWs and the open alerts from the store. */
void restore_indicator_state(daemon_s *d);
void heartbeat(daemon_s *d);
/* The intake counters of this run into the store's meta table (intake.*:
 * run, messages received and refused, kernel drops, samples missing,
 * passages not stored, as of when), for amfi-report: every 60 s from the
 * loop (force: now, at stop). A failure is logged, never fatal. */
void record_intake(daemon_s *d, int force);
/* SIGHUP: apply what can change while running, report the rest. */
void reload(daemon_s *d);

#endif /* AMFID_H */
