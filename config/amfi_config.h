/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_config.h: a bridge site's configuration, loaded from YAML.
 *
 * One file describes one site: the bridge model (docs/model.md §1), the sensors
 * and the solver with its λ policy (docs/model.md §7), the daemon's settings and
 * the simulator's. The shipped files document every key and reproduce
 * amfi_config_defaults() exactly: config/paper-20m.yaml (bridge, sensors,
 * solver), config/sim_publisher.yaml (bridge, sensors, simulation).
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
#include <stdint.h>

#include "amfi/amfi.h"
#include "amfi_classify.h"
#include "indicators.h"
#include "known_truck.h"
#include "scale.h"
#include "natfreq.h"
#include "level_rule.h"
#include "speed_drift.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A sensor's sample rate when the file gives none (sensors[].rate_hz), Hz:
 * sim_publisher's default scan rate (simulation.scan_rate_hz), so that the
 * shipped files and the simulator's default stream agree. */
#define AMFI_CONFIG_DEFAULT_RATE_HZ 1000.0

/* daemon.store.raw.keep */
enum { AMFI_RAW_KEEP_NONE = 0, AMFI_RAW_KEEP_FAILED = 1, AMFI_RAW_KEEP_ALL = 2 };

/* The monitoring daemon's section (daemon: in the site file). */
typedef struct amfi_daemon_config {
    char lcm_url[256];        /* daemon.lcm_url; "" = LCM's default */
    char ch_accel[64], ch_vehicle[64], ch_truth[64]; /* daemon.channels.* (inputs) */
    char ch_passage[64], ch_indicator[64], ch_alert[64], ch_status[64]; /* outputs */
    char ch_environment[64]; /* daemon.channels.environment: in, air/deck temperature */
    int simulation;           /* daemon.simulation: on (1): a simulation, amfid subscribes
                                 the truth channel; off (0, production): not subscribed */
    int bus_auth;             /* daemon.bus.auth: required (1): unsigned, wrongly signed
                                 and replayed messages are refused; off (0): a lab bus */
    char bus_key_file[512];   /* daemon.bus.key_file: the site key; "" = the systemd
                                 credential amfi-bus-key ($CREDENTIALS_DIRECTORY) */
    double bus_max_skew_s;    /* daemon.bus.max_skew_s: a signed message whose sequence
                                 is further than this from its receive time is
                                 refused, s, [1, 86400] */
    char db_path[512];        /* daemon.store.path */
    int sync_full;            /* daemon.store.sync: full (1) | normal (0) */
    long long held_max_bytes; /* daemon.store.held_max_bytes: passages held while the
                                 store cannot write, bytes, 1 MiB .. 64 GiB */
    int raw_keep;             /* daemon.store.raw.keep: the raw samples of every passage
                                 weighed (AMFI_RAW_KEEP_ALL), of those not stored ok
                                 (AMFI_RAW_KEEP_FAILED) or none (AMFI_RAW_KEEP_NONE) */
    int raw_float32;          /* daemon.store.raw.precision: float64 (0, exact) | float32 (1) */
    double raw_max_age_days;  /* daemon.store.raw.max_age_days: windows older than this
                                 (data time) are deleted, days, 0 (no limit) .. 36500 */
    double raw_max_mib;       /* daemon.store.raw.max_mib: the oldest windows are deleted
                                 beyond this many MiB of samples, 0 (no limit) .. 1e6 */
    int workers;              /* daemon.workers: solver threads, 1 .. 64 */
    int queue_size;           /* daemon.queue_size: passages waiting, 1 .. 100000 */
    int recv_buf_bytes;       /* daemon.recv_buf_bytes: UDP receive buffer asked of LCM
                                 (recv_buf_size), 0 (kernel default) .. 1 GiB */
    int bus_queue;            /* daemon.bus_queue: messages LCM keeps per input channel
                                 between its receive thread and amfid, 30 .. 1000000 */
    double ring_s;            /* daemon.ring_s: seconds of samples kept per sensor */
    double environment_max_skew_s; /* daemon.environment_max_skew_s: an environment_t
                                 further than this from the stream's newest data
                                 time is refused, s, 1 .. 864000 */
    double margin_s;          /* daemon.window_margin_s: data around the solver window */
    double max_wait_s;        /* daemon.max_wait_s: data time to wait for a window */
    double max_event_s;       /* daemon.max_event_s: vehicles sharing the span are
                                 weighed together while first entry to last exit
                                 is at most this, s, [0, 600]; 0 = never (multiple) */
    int max_event_axles;      /* daemon.max_event_axles: axles of such an event,
                                 2 .. AMFI_MAX_EVENT_AXLES */
    double inseparable_gap_m; /* daemon.inseparable_gap_m: axles of two vehicles
                                 closer than this load the beam at one point, m */
    double inseparable_share; /* daemon.inseparable_share: a vehicle with an axle that
                                 close to another's for at least this share of its
                                 crossing is not separable (multiple), 0 .. 1 */
    double inseparable_quality; /* daemon.inseparable_quality: a vehicle of an event
                                 with a quality figure above this is not separable */
    double inseparable_quality_lanes; /* daemon.inseparable_quality_lanes: the same for
                                 a vehicle of an event with vehicles of several lanes */
    int single_presence_only; /* daemon.indicators.single_presence_only: the
                                 indicators take only passages weighed alone */
    char ind_classes[128];    /* daemon.indicators.classes: the classes (of classes.scheme)
                                 whose passages feed the STD and mean rules,
                                 comma-separated; "" every passage */
    double ind_min_gvw_kg;    /* daemon.indicators.min_gvw_kg: and whose weight fed is at
                                 least this, kg, [0, 100000]; 0 every weight */
    int ind_temp_compensated; /* daemon.indicators.temperature: 1 compensated
                                 (the STD and mean rules get each GVW at the
                                 calibration temperature), 0 raw */
    double status_period_s;   /* daemon.status_period_s: heartbeat, wall time */
    char alert_command[512];  /* alerts.command: run for each raised and cleared alert;
                                 "" none */
    double alert_timeout_s;   /* alerts.command_timeout_s: killed after, (0, 3600] */
    int alert_max_running;    /* alerts.command_max_running: at once, 1 .. 64 */
    double alert_stop_wait_s; /* alerts.command_stop_wait_s: at stop, notices running or
                                 waiting get this long, then are killed, [0, 30] */
    char metrics_path[512];   /* metrics.textfile: Prometheus text file; "" off */
    double metrics_interval_s; /* metrics.interval_s: rewritten every, [1, 3600] */
    /* alerts.speed_drift.*: the speed-drift alert's parameters (speed_drift.h,
     * docs/indicators.md), defaults from amfi_speed_drift_params_default(). */
    amfi_speed_drift_params speed_drift;
    /* alerts.scale.*: the scale indicator (scale.h, docs/indicators.md
     * section 8), defaults from amfi_scale_params_default(); enabled and
     * max_temp_gap_s are amfid's: a passage without a deck temperature
     * within max_temp_gap_s does not feed it (counted). */
    int scale_enabled;            /* alerts.scale.enabled: on (1) | off */
    double scale_max_temp_gap_s;  /* alerts.scale.max_temp_gap_s, s, [1, 86400] */
    amfi_scale_params scale;
    /* alerts.known_truck.*: the known-truck indicator (known_truck.h), its
     * temperature model alerts.scale's; defaults from
     * amfi_known_truck_params_default(). */
    int known_truck_enabled;      /* alerts.known_truck.enabled: on (1) | off */
    amfi_known_truck_params known_truck;
    /* alerts.model_fit.*: the model_mismatch alert (daemon/modelfit.c,
     * docs/indicators.md section 10): each passage weighed alone is solved
     * again over a window extended free_s past its last exit, and the
     * model's residual over that free vibration, relative to the signal,
     * is watched by a median level rule (level_rule.h). */
    double model_fit_free_s;      /* alerts.model_fit.free_s: s of free vibration fitted,
                                     [0.2, 10], at most daemon.natural_frequency.free_s */
    double model_fit_calc_rate_hz; /* alerts.model_fit.calc_rate_hz: the fit's calculation
                                      rate, (0, 1e6] Hz, at most solver.calc_rate_hz */
    amfi_level_params model_fit;  /* its rule: window, raise, clear, raise_after, clear_after */
    /* alerts.natfreq.*: the natfreq alert (daemon/natalert.c): the relative
     * drop 1 − f1_comp / f1_ref of the temperature-compensated first natural
     * frequency against its baseline, watched by the same rule. */
    amfi_level_params natfreq_alert;
    /* daemon.indicators.*: the indicator engine's own parameters
     * (indicators.h, docs/indicators.md), its defaults from
     * amfi_indicator_params_default() and checked, at load, by
     * amfi_indicator_params_check(). */
    amfi_indicator_params indicators;
    /* daemon.natural_frequency.*: the bridge's first natural frequency from
     * each passage's free vibration (natfreq.h, docs/indicators.md section
     * 9): the estimator's own parameters (amfi_natfreq_params_default(),
     * checked at load by amfi_natfreq_params_check()), and amfid's */
    amfi_natfreq_params natfreq;
    double natfreq_free_s;    /* daemon.natural_frequency.free_s: free vibration after
                                 the last exit, s, [0, 30]; 0: off */
    int natfreq_baseline_n;   /* daemon.natural_frequency.baseline_n: passages with an
                                 f1 whose temperature fit is the baseline, 10 .. 100000 */
    int natfreq_mode;         /* daemon.natural_frequency.mode: the site model's mode
                                 (1-based, ascending frequency) the estimate follows, in a
                                 band around its frequency, 0 .. 20; 0: the strongest peak
                                 in [f_lo_hz, f_hi_hz] (daemon/freevib.c) */
    double natfreq_band;      /* daemon.natural_frequency.band: that band's half-width
                                 relative to the model's frequency, (0, 0.5] */
    /* daemon.intake.*: bounds on what the bus may bring (daemon/intake.c,
     * docs/daemon.md "Bounded intake"); each refusal is counted and stored
     * as a periodic summary (table refusals). */
    double vehicle_ahead_s;   /* vehicle_ahead_s: a vehicle dated more than this after the
                                 newest data time is refused, s, [1, 3600] */
    double min_speed_mps;     /* min_speed_mps: slower vehicles are refused, [1, 60) */
    double max_length_m;      /* max_length_m: longer vehicles (first to last axle)
                                 are refused, m, [1, 360] */
    double accel_margin;      /* accel_margin: accelerometer samples per second taken,
                                 as a multiple of the sensors' rate_hz summed, [1, 1000] */
    double vehicles_per_s;    /* vehicles_per_s: vehicle_t per second taken, [0.1, 1e5] */
    double environment_per_s; /* environment_per_s: environment_t per second, [0.1, 1e5] */
    double truth_per_s;       /* truth_per_s: truth_t per second, [0.1, 1e5] */
    double burst_s;           /* burst_s: each limit's allowance, seconds of its rate,
                                 [1, 3600] */
    double summary_period_s;  /* summary_period_s: refusals summarised every, wall s,
                                 [1, 86400] */
    double env_min_interval_s; /* environment_min_interval_s: readings closer than this
                                 (data time) to the last stored one are not stored,
                                 s, [0, 86400] */
    double deck_max_rate_c_min; /* deck_max_rate_c_per_min: a deck temperature changing
                                 faster than this against the last accepted reading is
                                 refused, °C per minute of data time, (0, 1e6] */
    char calibration_sources[256]; /* calibration_sources: comma-separated vehicle_t
                                 sources whose reference_gvw_kg is taken; "" none */
    double calibration_min_kg, calibration_max_kg; /* calibration_min_kg, _max_kg: a
                                 reference GVW outside is not taken, kg, [1000, 100000] */
} amfi_daemon_config;

/* The simulator's section (simulation: in the site file). Only
 * sim_publisher reads it; the daemon and the tools accept and ignore it. The
 * ranges are those of sim_publisher's command-line flags, which override
 * these values (docs/simulator.md). Defaults: the ideal conditions listed in
 * amfi_config_defaults(). */
typedef struct amfi_sim_config {
    char population[512];   /* simulation.population: WIM-style CSV; "" = the
                               shipped synthetic population; a relative path in
                               the file is stored joined to the file's folder */
    int vehicles;           /* simulation.vehicles: vehicles simulated, 1 .. 10^7 */
    int first;              /* simulation.first: first population record
                               (0-based), 0 .. 10^7 */
    long long seed;         /* simulation.seed: 0 .. 2^32 − 1 */
    double damage;          /* simulation.damage: stiffness loss δ, [0, 0.9] */
    int damage_step_at;     /* simulation.damage_step_at: streaming: healthy
                               before vehicle K (0-based), damaged from K on,
                               0 .. 10^7; −1 (null|none): damaged from the start */
    int profile_class;      /* simulation.profile: ISO 8608 class 'A' .. 'H';
                               0 = smooth (no roughness) */
    double track_std;       /* simulation.track_std: lateral track spread,
                               in tracks, [0, 100] */
    double scan_rate_hz;    /* simulation.scan_rate_hz: sampling rate, [50, 20000] */
    double noise;           /* simulation.noise: accelerometer noise, fraction
                               of the record's RMS, [0, 1] */
    double speed_err_mean;  /* simulation.speed_error.mean: relative, [−0.5, 0.5] */
    double speed_err_std;   /* simulation.speed_error.std: relative, [0, 0.5] */
    int preceding;          /* simulation.preceding_gap given: 1, null: 0 */
    double gap_lo_s, gap_hi_s; /* simulation.preceding_gap: [lo, hi], s, each
                               in [−2, 30], lo <= hi (0, 0 without) */
    double pre_s, post_s;   /* simulation.pre_s, post_s: record before entry /
                               after exit (--out), s, [0, 30] */
    double dt_s;            /* simulation.dt_s: integration step, s, [1e-6, 1e-3] */
    int environment;        /* simulation.environment: 0 none (constant modulus,
                               the population's mix), 1 site (climate-driven
                               modulus, drifting mix; docs/simulator.md) */
    double time_compression; /* simulation.time_compression: site time / data
                               time of the climate and the mix, [1, 1e6] */
    /* simulation.stream.* (streaming, without --out) */
    char lcm_url[256];      /* lcm_url: "" = LCM's default; "none" = publish nothing */
    char log[512];          /* log: LCM log file to write; "" = none (relative
                               to the working directory, like an output) */
    double speedup;         /* speedup: data time / wall time, [0.01, 1e6];
                               0 = as fast as possible ("max") */
    double headway_s;       /* headway_s: entry to entry, s, [0.1, 3600];
                               0 = the population's timestamps */
    double flow_veh_h;      /* flow_veh_h: Poisson arrivals per lane, vehicles/h,
                               [1, 3600]; 0 = off (headway_s) */
    double min_headway_s;   /* min_headway_s: with flow, per lane, s, [0, 60] */
    int lanes;              /* lanes: with flow, 1 .. 2 */
    double noise_ms2;       /* noise_ms2: extra Gaussian noise, m/s², [0, 10] */
    int block;              /* block: samples per accel message, 1 .. 160 */
    long long start_utime;  /* start_utime: data time of the first sample,
                               µs since 1970, 1 .. 4e15 */
    double detector_lead_s; /* detector_lead_s: vehicle event before entry,
                               s, [0, 60] */
    double environment_period_s; /* environment_period_s: environment_t every
                               this much data time (environment: site), s,
                               [0.1, 86400] */
    int calibration_every;  /* calibration_every: every this many vehicles
                               the pre-weighed calibration truck, its static
                               GVW as vehicle_t.reference_gvw_kg, 0 .. 10^7;
                               0 = none */
} amfi_sim_config;

/* site.*: which bridge this is (section_site.c). */
typedef struct amfi_site_identity {
    char id[64];      /* site.id: [A-Za-z0-9_.-], 1 .. 63 bytes; stored in the store
                         at first start, carried by amfid's output messages */
    char name[128];   /* site.name: 1 .. 127 bytes; default bridge.name */
    double latitude;  /* site.latitude, degrees WGS 84, [-90, 90]; NaN unknown */
    double longitude; /* site.longitude, degrees, [-180, 180]; NaN unknown */
    char bridge_type[64]; /* site.bridge_type: 1 .. 63 bytes for people and the
                         fleet ("steel girder", "box girder", ...); "" unknown */
} amfi_site_identity;

/* 1 when s is a valid site.id ([A-Za-z0-9_.-], 1 .. 63 bytes), else 0. */
int amfi_config_site_id_valid(const char *s);

/* report.*: what amfi-report holds passages against (section_report.c). */
typedef struct amfi_report_config {
    double gvw_limit_kg;   /* report.limits.gvw_kg: legal GVW, (0, 1e6] */
    double axle_limit_kg;  /* report.limits.axle_kg: legal load of any axle, (0, 1e6] */
    double bin_kg;         /* report.histogram_bin_kg: GVW histogram bins, [100, 1e5] */
    int units;             /* report.units: AMFI_REPORT_UNITS_* of amfi-report's tables and plots */
} amfi_report_config;

/* report.units: si (kg, m/s) or engineering (t, km/h) */
enum { AMFI_REPORT_UNITS_SI = 0, AMFI_REPORT_UNITS_ENGINEERING = 1 };

/* detector.*: what commissioning found of the vehicle detector
 * (section_detector.c): its clock runs clock_offset_s ahead of the
 * accelerometers' (a vehicle's true entry is its reported time minus the
 * offset) and it reports speed_scale times the true speed (and spacings,
 * measured from its speed, alike). Applied by amfi-solve and amfid. */
typedef struct amfi_detector_config {
    double clock_offset_s; /* [-1, 1], default 0 */
    double speed_scale;    /* [0.5, 2], default 1 */
} amfi_detector_config;

/* A vehicle as the detector reported it, corrected as `d` says (the one
 * formula of amfi-solve and amfid, section_detector.c): the true entry is
 * the reported one minus clock_offset_s (*entry_s in s, *utime in µs,
 * rounded to the µs; either may be NULL), the true speed and each of the
 * n_spacings spacings the reported ones divided by speed_scale. */
void amfi_config_detector_correct(const amfi_detector_config *d, double *entry_s, int64_t *utime,
                           double *speed_mps, double *spacing_m, int n_spacings);

/* ingest.*: what amfi-ingest(1) reads (section_ingest.c, docs/ingest.md). */
#define AMFI_INGEST_MAX_CHANNELS AMFI_MAX_SENSORS
typedef struct amfi_ingest_channel {
    char seed[24];   /* NET.STA.LOC.CHA */
    int sensor_id;   /* a sensors[].id */
    double gain;     /* m/s² per count, > 0 */
    double offset_s; /* the logger's latency: published time = header time − offset_s */
} amfi_ingest_channel;

typedef struct amfi_ingest_config {
    char producer[17];  /* ingest.producer: the bus producer id */
    int block;          /* ingest.block: samples per accel block, 1 .. 160 */
    double max_jump_s;  /* ingest.max_jump_s: a larger jump of the data's time is reported */
    int n_channels;     /* ingest.channels[] */
    amfi_ingest_channel ch[AMFI_INGEST_MAX_CHANNELS];
    char listen[64];    /* ingest.line.listen: IPv4:PORT, "" none */
    char serial[256];   /* ingest.line.serial: device, "" none */
    int baud;           /* ingest.line.baud */
    double line_offset_s; /* ingest.line.offset_s */
    char source[64];    /* ingest.line.source: vehicle_t.source */
    int max_clients;    /* ingest.line.max_clients */
} amfi_ingest_config;

void amfi_config_ingest_defaults(amfi_ingest_config *g);
/* 1 when s is a SEED channel id NET.STA.LOC.CHA, else 0. */
int amfi_config_ingest_seed_valid(const char *s);
/* "A.B.C.D:PORT" into host and *port; 0 or -1. */
int amfi_config_ingest_listen_parse(const char *s, char host[64], int *port);

typedef struct amfi_site_config {
    amfi_site_identity site;   /* site.* */
    char name[64];             /* bridge.name: 1 .. 63 bytes, NUL-terminated */
    amfi_bridge_params bridge; /* bridge.* */
    amfi_solver_params solver; /* solver.* and the sensor list (positions,
                                  weights, n_sensors) */
    amfi_lambda lambda;        /* solver.lambda, lambda_ref_rate_hz, lcurve */
    int sensor_id[AMFI_MAX_SENSORS]; /* sensors[i].id, 0 .. 255, unique;
                                        entry i belongs to solver.sensor_x_m[i];
                                        −1 past solver.n_sensors */
    double sensor_rate_hz[AMFI_MAX_SENSORS]; /* sensors[i].rate_hz: the sample rate
                                        the sensor sends at, Hz, (0, 100000], one for
                                        all sensors; default 1000 (sim_publisher's
                                        default scan rate); 0 past n_sensors */
    amfi_daemon_config daemon;       /* daemon.* */
    amfi_sim_config sim;             /* simulation.* */
    amfi_report_config report;       /* report.* */
    int speed_estimate;              /* solver.speed: 0 measured (default), 1 estimate */
    amfi_speed_prior speed_prior;    /* solver.speed_sd, speed_range_sd, speed_grid,
                                        speed_coarse_rate_hz, speed_criterion,
                                        speed_pick (amfi_speed_prior_default) */
    amfi_detector_config detector;   /* detector.* */
    amfi_ingest_config ingest;       /* ingest.* (amfi-ingest) */
    amfi_class_params classes;       /* classes.* (amfi_class_params_default) */
} amfi_site_config;

/* Fill `c` (not NULL) with the paper-20m defaults: amfi_bridge_params_paper20,
 * amfi_solver_params_default(20 m), amfi_lambda_default, name "paper-20m",
 * one sensor with id 0; the daemon's defaults; and sim_publisher's ideal
 * simulation: 10 vehicles from record 0, seed 1, healthy, class A, track
 * std 2, 1000 Hz, no noise, exact speed, no preceding vehicle, 0.5 s before
 * and after, dt 1e-4 s; streaming in real time on LCM's default URL, no log,
 * the population's headways, blocks of 100 samples from 2026-01-01T00:00Z,
 * the detector 1 s ahead. Every byte is set (the struct may be memcmp'd). */
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
 * process locale. Once every key is valid the bridge model is built with
 * libamfi (a refusal is reported at the line of the bridge key or section
 * that caused it), and a solver workspace above 10^7 steps or 1 GiB is
 * refused (amfid.yaml(5), LIMITS). Every key, its range and default:
 * amfi_config_keys() (amfi_config_keys.h) and amfid.yaml(5). */
int amfi_config_load(const char *path, amfi_site_config *c, char *err,
                     size_t errlen);

/* The file `path` (already loaded without error) read again for what is
 * still the shipped example's (config/amfid.yaml, site_example.c): the
 * example's site.id 'local', the paper's 20 m bridge (bridge.name
 * paper-20m, or its span, stiffness, section and density unchanged), no
 * site.name of its own. Each finding is one line "FILE:LINE: key:
 * WARNING: ..." (":LINE" left out for a key not in the file) given to
 * warn(line, arg); returns their number (0: none), or −1 when the file
 * cannot be read again (a line through warn says so). */
int amfi_config_example_warnings(const char *path, void (*warn)(const char *line, void *arg),
                                 void *arg);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_CONFIG_H */
