/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfid.h: the daemon as its main() and its embedders (fuzz/fuzz_intake.c,
 * the daemon's C tests) see it: an opaque handle, its life cycle, and the
 * counters it reports. The inside (the context of shared services, the
 * module interface and the table of modules) is ctx.h; docs/architecture.md
 * draws it.
 */
#ifndef AMFID_H
#define AMFID_H

#include <lcm/lcm.h>
#include <stdint.h>

#include "amfi_auth.h"
#include "amfi_config.h"
#include "amfi_msg_check.h"
#include "log.h"
#include "store.h"

#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif

/* ---- command line (options.c) ------------------------------------------- */

typedef struct amfid_options {
    const char *config;   /* --config, default AMFID_DEFAULT_CONFIG */
    const char *db;       /* --db, NULL: the file's */
    const char *lcm_url;  /* --lcm-url, NULL: the file's */
    int check_only;       /* --check-config */
    int strict;           /* --strict: --check-config's warnings fail it (exit 2) */
    const char *bus_key;  /* --bus-key FILE, NULL: daemon.bus.key_file, then the
                             systemd credential */
    const char *make_bus_key; /* --make-bus-key FILE: create a site key and exit */
} amfid_options;

/* 0: run. --help and --version print and exit 0; a bad command line is
 * reported on stderr and exits 2 (amfi_cli.h). */
void amfid_parse_options(int argc, char **argv, amfid_options *o);

/* ---- refused messages: inputs and reasons (reject.c) ----------------------- */

/* The reasons are the raw-buffer checker's (amfi_msg_reason,
 * messages/amfi_msg_check.h) and these. */
enum { REJECT_ACCEL, REJECT_VEHICLE, REJECT_TRUTH, REJECT_ENVIRONMENT, REJECT_NINPUTS };
#define REJECT_INVALID AMFI_MSG_NREASONS           /* decoded, failed amfid's validation */
#define REJECT_QUARANTINE (AMFI_MSG_NREASONS + 1) /* an accel block far from the stream */
#define REJECT_RATE (AMFI_MSG_NREASONS + 2)       /* over its channel's rate limit */
#define REJECT_SOURCE (AMFI_MSG_NREASONS + 3)     /* a value from a source not configured */
#define REJECT_IMPLAUSIBLE (AMFI_MSG_NREASONS + 4) /* against the recent readings */
/* refused by the bus authentication (bus.c): REJECT_AUTH + amfi_auth_reason */
#define REJECT_AUTH (AMFI_MSG_NREASONS + 5)
#define REJECT_NREASONS (REJECT_AUTH + AMFI_AUTH_NREASONS)

/* ---- what the daemon counts ------------------------------------------------ */

/* Every module adds its own counters (its metrics hook); the heartbeat, the
 * metrics file and the intake record read one such snapshot. */
typedef struct amfid_stats {
    /* intake (intake.c, admit.c, bus.c) */
    int64_t messages_in, messages_malformed, auth_refused;
    int64_t blocks_received, blocks_rejected, vehicles_received, vehicles_rejected;
    int64_t truth_received, vehicles_evicted, references_refused, invalid_unstored;
    int64_t samples_missing, ring_rejected; /* over the sample rings */
    /* refused messages (reject.c) */
    int64_t refused_total, refused[REJECT_NINPUTS][REJECT_NREASONS], summaries_lost;
    /* environment readings (environment.c) */
    int64_t env_received, env_rejected, env_stored, env_lost, env_thinned;
    int env_buffered;
    /* the pipeline (pipeline.c): stored, held and lost passages */
    int64_t passages_stored, passages_ok, passages_lost;
    int passages_held, degraded;
    int queue_depth; /* passages waiting for a solver thread */
    /* the scale indicator (scaleind.c) */
    double last_scale, last_cusum;
    int64_t scale_fed, scale_no_temp;
    /* alert notices (notify.c) */
    int64_t notices_ok, notices_failed, notices_timeouts, notices_dropped;
    int notices_running, notices_queued;
    /* the passages' raw samples (raw.c) */
    int64_t raw_windows, raw_links;      /* windows written, passages linked to one */
    int64_t raw_bytes, raw_bytes_in;     /* their bytes compressed, and as float64 */
    int64_t raw_failed;                  /* not written (the passages stored without) */
    int64_t raw_pruned_age, raw_pruned_size, raw_pruned_bytes; /* deleted by retention */
    int64_t raw_kept_windows, raw_kept_bytes; /* in the store now */
    /* kernel drops on amfid's sockets (status.c, as of the last heartbeat) */
    int64_t udp_drops;
} amfid_stats;

/* ---- life cycle (amfid.c), main thread ----------------------------------- */

typedef struct amfid amfid;

/* The configuration (with o's overrides) and what it builds; with
 * o->check_only print the result and stop there; else the store (site
 * claimed), the modules, the bus (subscribed) and the solver threads.
 * *h is set whatever happens (amfid_stop tears down what was built).
 * 0, 1 (runtime) or 2 (configuration), reported. */
int amfid_start(amfid **h, const amfid_options *o);
/* The loop: read the bus until SIGTERM/SIGINT or the end of a replayed log,
 * then amfid_drain. 0, or 1. */
int amfid_run(amfid *h);
/* Stop reading: release every window, let the solvers finish, store every
 * pending passage (retrying a refusing store for up to 20 s), each module's
 * last work (in reverse). 0, or 1 when a passage could not be stored. */
int amfid_drain(amfid *h);
/* Tear down whatever amfid_start built, in reverse, and free h; NULL-safe. */
void amfid_stop(amfid *h);

/* ---- for embedders (fuzz/fuzz_intake.c, tests) ------------------------------ */

/* One turn of the loop without waiting: the messages LCM has queued, every
 * module's turn (windows released, results stored, held passages retried,
 * notices reaped) and the timers that are due. */
void amfid_turn(amfid *h);
/* The SIGHUP path, now: the file read again, each module's reload. */
void amfid_reload(amfid *h);
void amfid_counts(amfid *h, amfid_stats *s);
lcm_t *amfid_lcm(amfid *h);
amfi_store *amfid_store(amfid *h);
const amfi_site_config *amfid_config(const amfid *h);

#endif /* AMFID_H */
