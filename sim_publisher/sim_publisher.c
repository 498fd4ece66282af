/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim_publisher: simulated vehicles crossing the bridge, written as the
 * passages a site would record.
 *
 *   sim_publisher --out DIR [--config FILE.yaml] [--population FILE.csv]
 *                 [--vehicles N] [--first K] [--damage FRACTION] [--seed S]
 *                 [--profile A..H|smooth] [--track-std TRACKS] [--scan-rate HZ]
 *                 [--noise FRACTION] [--speed-error MEAN,STD]
 *                 [--preceding-gap LO[,HI]|none] [--pre SEC] [--post SEC] [--dt SEC]
 *
 * Configuration: every setting has a built-in default (amfi_config_defaults(),
 * an ideal simulation), which the configuration file's `simulation:` section
 * overrides, which a flag overrides. The file is --config FILE, else the
 * shipped sim_publisher.yaml found by common/amfi_datafile.h
 * ($AMFI_DATA_DIR, then the installed etc/amfi and share/amfi copies) if
 * present; it holds the values built in and documents
 * each key with its flag. The same file gives the bridge, the sensors and
 * the channels the stream is published on (daemon.channels.accel, vehicle,
 * truth), so any site file amfid reads also drives its simulator.
 *
 * Vehicle i is the population's record first + i: its weights, spacing and
 * speed; its Table 2 properties and its carpet track are drawn from a
 * generator seeded by (seed, i), so any vehicle can be reproduced alone and
 * the same seed gives the same bytes. The road is one ISO 8608 carpet per
 * run (seeded by seed). Defaults are ideal: class A, no noise, exact speed,
 * a healthy bridge, one vehicle at a time; every inaccuracy is switched on
 * explicitly. With --preceding-gap, a population vehicle drawn at random
 * crosses first, its rear axle leaving the bridge a gap (uniform in
 * [LO, HI] s) before the target enters.
 *
 * Output: DIR/vNNNNN.csv per vehicle (header t,accel: s from the start of the
 * record, m/s² positive downward at the configuration's first sensor; the
 * format amfi-solve reads) and DIR/meta.csv, one row per vehicle: the speed
 * given to a solver (measured) and the true one, spacing, the time in the
 * file when the front axle enters, the true static weights, the true mean
 * contact forces on the span, and the conditions.
 *
 * Streaming (without --out): continuous traffic on the LCM bus, as a site
 * would publish it, on the configured channels: accelerometer blocks
 * (--block samples each, the bridge's free vibration between vehicles
 * included), a vehicle_t for each vehicle --detector-lead seconds before it
 * enters (utime = its entry), and its truth_t after it has left. Time is the data's time, starting at
 * --start-utime; pacing is real time divided by --speedup (or none with
 * max). --log FILE writes the same events to an LCM log (timestamps = data
 * time), replayable with lcm-logplayer and readable by amfid through LCM's
 * file:// provider; --lcm-url none publishes nothing. Every message is
 * signed with the site's bus key (messages/amfi_auth.h: --bus-key FILE, else
 * the configuration's daemon.bus.key_file, else the systemd credential
 * amfi-bus-key; without one, unsigned with a warning), the same bytes on
 * the bus and in the log, the wall clock as sequence. Vehicles follow each
 * other --headway seconds apart (default: the population's timestamps),
 * or arrive at random with --flow vehicles/h per lane on --lanes 1 or 2
 * (at least --min-headway apart within a lane, no overtaking: flow.h;
 * every vehicle of a lane on that lane's road track);
 * --damage-step-at K switches the bridge to --damage from vehicle K on.
 * --environment site (streaming only) drives the bridge's modulus with the
 * deck temperature of a simulated site climate, set as each vehicle is
 * added, and draws each vehicle from the population's loaded or empty class
 * with a share that drifts with the weekday and the season (site.h,
 * docs/simulator.md "Environment"); --time-compression C runs the climate
 * and the calendar C times faster than the data clock; an environment_t
 * (air and deck temperature) goes out every --environment-period seconds
 * of data time.
 *
 *   sim_publisher [--lcm-url URL|none] [--log FILE] [--speedup X|max]
 *                 [--vehicles N] [--headway SEC] [--damage FRACTION]
 *                 [--damage-step-at K|none] [--noise-ms2 STD] [--block N]
 *                 [--start-utime US] [--detector-lead SEC] ... (as above)
 *
 * As built (--as-built FILE, config/amfi_as_built.h): the bridge the
 * vehicles really cross, the sensors' true positions and the detector's
 * clock offset and speed and spacing scale errors, in a file apart from the
 * configuration (which stays the design). The accelerations come from the
 * as-built bridge; vehicle_t and meta.csv's first columns carry what the
 * detector says, truth_t and meta.csv's appended columns the truth.
 *
 * Commissioning records (offline, no bus, no population; calibration.h):
 * --calibration-runs DIR writes each calibration truck's runs alone on the
 * bridge at speeds spread over --calibration-speeds, with --tail seconds of
 * free vibration, as DIR/runNNN.csv, DIR/RUNS.csv (what the detector said
 * and the weighed axle loads) and DIR/RUNS.truth.csv; --ambient-out FILE an
 * ambient record under white-noise forces.
 *
 *   sim_publisher [--as-built FILE] --calibration-runs DIR [--truck S1,../L1,L2,..]...
 *                 [--runs-per-truck N] [--calibration-speeds LO,HI] [--tail SEC]
 *                 [--ambient-out FILE [--ambient-duration SEC] [--ambient-force N]]
 *
 * Exit status: 0; 1 bad input file, bus or simulation failure; 2 bad command
 * line.
 */
#include <errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <lcm/eventlog.h>
#include "amfi_auth.h"
#include <lcm/lcm.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include "amfi_as_built.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "calibration.h"
#include "amfi_datafile.h"
#include "amfi_messages.h"
#include "passage.h"
#include "profile.h"
#include "site.h"
#include "flow.h"
#include "traffic.h"
#include "vbi.h"
#include "vehicle.h"
#include "amfi_time.h"

#define PROG "sim_publisher"

/* amfid's configuration where it is installed (daemon/amfid.h, set by CMake
 * alike): the bus it names is amfid's production bus. */
#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif
#define AMFID_INSTALLED_CONFIG AMFID_DEFAULT_CONFIG
/* amfid's bus when daemon.lcm_url is "" (daemon/bus.c) */
#define AMFID_BUILTIN_URL "udpm://239.255.76.67:7667?ttl=0"

/* The shipped files looked for when none is named (common/amfi_datafile.h). */
#define DEFAULT_CONFIG_NAME "sim_publisher.yaml"
#define DEFAULT_POPULATION_NAME "population.csv"

/* The effective settings: the built-in defaults (amfi_config_defaults()),
 * then the configuration file's simulation: section, then the flags. The
 * strings point into argv or into main's static configuration. */
typedef struct opts {
    const char *out, *config, *population; /* NULL: none / the shipped population */
    long vehicles, first;
    double damage;
    unsigned long seed;
    char profile_class; /* 0: smooth */
    double track_std, scan_rate, noise, speed_err_mean, speed_err_std;
    int preceding;
    double gap_lo, gap_hi, pre, post, dt;
    /* streaming */
    const char *lcm_url, *log; /* NULL: LCM's default URL / no log */
    const char *bus_key;  /* --bus-key FILE; NULL: the configuration's, the credential */
    int lcm_url_flag;     /* lcm_url came from --lcm-url (for messages) */
    int allow_production_bus; /* --allow-production-bus: amfid's bus on purpose */
    double speedup;       /* <= 0: as fast as possible */
    double headway;       /* <= 0: the population's timestamps */
    double flow;          /* > 0: Poisson arrivals, vehicles/h per lane (flow.h) */
    double min_headway;   /* with flow: per lane, s */
    int lanes;            /* with flow: 1 or 2 */
    long damage_step_at;  /* < 0: --damage from the start */
    double noise_ms2;
    int block;
    long long start_utime;
    double detector_lead;
    int environment;      /* 0 none, 1 site */
    double environment_period; /* s of data time between environment_t */
    double time_compression;
    long calibration_every; /* > 0: every this many vehicles the calibration truck */
    /* the as-built bridge and detector (NULL: the design is the truth) */
    const char *as_built;
    /* offline commissioning records (calibration.h) */
    const char *calib_dir, *ambient_out; /* NULL: not written */
    amfi_cal_params cal;                 /* trucks, runs, speeds, tail */
    int trucks_given;                    /* --truck seen: the defaults replaced */
    double ambient_s, ambient_force_n;
} opts;

static void usage(FILE *f)
{
    char places[512];
    fprintf(f,
            "usage: %s [--out DIR | --lcm-url URL|none [--allow-production-bus]] [--log FILE]\n"
            "       [--speedup X|max]\n"
            "       [--headway SEC] [--damage-step-at K|none] [--noise-ms2 STD] [--block N]\n"
            "       [--start-utime US] [--detector-lead SEC]\n"
            "       [--config FILE.yaml] [--population FILE.csv] [--vehicles N]\n"
            "       [--first K] [--damage FRACTION] [--seed S] [--profile A..H|smooth]\n"
            "       [--track-std TRACKS] [--scan-rate HZ] [--noise FRACTION]\n"
            "       [--speed-error MEAN,STD] [--preceding-gap LO[,HI]|none] [--pre SEC]\n"
            "       [--post SEC] [--dt SEC] [--as-built FILE.yaml]\n"
            "       [--calibration-runs DIR] [--truck S1,../L1,L2,..] [--runs-per-truck N]\n"
            "       [--calibration-speeds LO,HI] [--tail SEC] [--ambient-out FILE.csv]\n"
            "       [--ambient-duration SEC] [--ambient-force N]\n"
            "\n"
            "Simulated vehicles crossing the bridge: passage files (--out) or a live\n"
            "LCM stream (docs/simulator.md).\n"
            "  -o, --out DIR                  write vNNNNN.csv and meta.csv into DIR\n"
            "  -c, --config FILE              site configuration (simulation: section)\n"
            "  -p, --population FILE          WIM-style vehicle list (default population.csv)\n"
            "  -n, --vehicles N               vehicles to simulate\n"
            "      --first K                  first population record (0-based)\n"
            "  -d, --damage FRACTION          stiffness loss of the bridge, 0 .. 0.9\n"
            "  -s, --seed S                   random seed\n"
            "      --profile A..H|smooth      ISO 8608 road class\n"
            "      --track-std TRACKS         spread of the wheel track on the carpet\n"
            "      --scan-rate HZ             accelerometer sampling rate\n"
            "      --noise FRACTION           measurement noise, fraction of the RMS\n"
            "      --speed-error MEAN,STD     relative error of the measured speed\n"
            "      --preceding-gap LO[,HI]|none  a preceding vehicle, gap in s\n"
            "      --pre SEC, --post SEC      record before entry / after exit\n"
            "      --dt SEC                   integration step\n"
            "  -u, --lcm-url URL|none         LCM bus to publish on (none: no bus)\n"
            "  -l, --log FILE                 also write the events to an LCM log\n"
            "  -k, --bus-key FILE             the site's bus key: every message signed\n"
            "                                 (else daemon.bus.key_file, else the\n"
            "                                 credential amfi-bus-key)\n"
            "      --allow-production-bus     publish even on amfid's bus (its default,\n"
            "                                 %s's or the configuration's\n"
            "                                 daemon.lcm_url): refused without this\n"
            "      --speedup X|max            pacing: data time / wall time\n"
            "      --headway SEC              time between vehicles\n"
            "      --flow VEH_PER_H           Poisson arrivals per lane (overrides --headway)\n"
            "      --min-headway SEC          with --flow: minimum headway per lane (0.5)\n"
            "      --lanes 1|2                with --flow: number of lanes (1)\n"
            "      --damage-step-at K|none    --damage from vehicle K on\n"
            "      --noise-ms2 STD            noise on the stream, m/s^2\n"
            "      --block N                  samples per accelerometer message\n"
            "      --start-utime US           data time of the start, µs\n"
            "      --detector-lead SEC        vehicle message this long before entry\n"
            "      --environment none|site    streaming: site climate and drifting mix\n"
            "      --time-compression C       site time / data time, 1 .. 1000000\n"
            "      --environment-period SEC   environment_t every SEC of data time\n"
            "      --calibration-every N      every Nth vehicle the pre-weighed calibration\n"
            "                                 truck, its reference GVW on vehicle_t (0: none)\n"
            "      --as-built FILE            the bridge, sensors and detector as really\n"
            "                                 built (the site file stays the design)\n"
            "      --calibration-runs DIR     offline: calibration trucks one at a time,\n"
            "                                 DIR/runNNN.csv, RUNS.csv, RUNS.truth.csv\n"
            "      --truck S1,../L1,L2,..     a calibration truck: axle spacings m / static\n"
            "                                 axle loads kg (repeat; default 18 t 2-axle, 40 t 5-axle)\n"
            "      --runs-per-truck N         calibration runs of each truck (10)\n"
            "      --calibration-speeds LO,HI true speeds spread over LO..HI m/s (15,25)\n"
            "      --tail SEC                 free vibration recorded after the last axle (3)\n"
            "      --ambient-out FILE         offline: an ambient record (white-noise forces)\n"
            "      --ambient-duration SEC     its length (300)\n"
            "      --ambient-force N          force std at each node per sample (20)\n"
            "  -h, --help                     this help\n"
            "  -V, --version                  print the version\n"
            "Settings: built-in defaults < the configuration file's simulation: section\n"
            "< flags. Without --config: sim_publisher.yaml, and without --population:\n"
            "population.csv, from the first of %s.\n",
            PROG, AMFID_INSTALLED_CONFIG, amfi_datafile_places(places, sizeof places));
}

enum {
    O_FIRST = 256, O_PROFILE, O_TRACK_STD, O_SCAN_RATE, O_NOISE, O_SPEED_ERROR,
    O_PRECEDING_GAP, O_PRE, O_POST, O_DT, O_SPEEDUP, O_HEADWAY, O_DAMAGE_STEP_AT,
    O_NOISE_MS2, O_BLOCK, O_START_UTIME, O_DETECTOR_LEAD, O_ENVIRONMENT,
    O_TIME_COMPRESSION, O_ENVIRONMENT_PERIOD, O_CALIBRATION_EVERY, O_FLOW, O_MIN_HEADWAY, O_LANES,
    O_AS_BUILT, O_CALIB_RUNS, O_TRUCK, O_RUNS_PER_TRUCK, O_CALIB_SPEEDS, O_TAIL, O_AMBIENT_OUT,
    O_AMBIENT_DURATION, O_AMBIENT_FORCE, O_ALLOW_PRODUCTION_BUS
};

static const struct option longopts[] = {
    {"out", required_argument, NULL, 'o'},
    {"config", required_argument, NULL, 'c'},
    {"population", required_argument, NULL, 'p'},
    {"vehicles", required_argument, NULL, 'n'},
    {"first", required_argument, NULL, O_FIRST},
    {"damage", required_argument, NULL, 'd'},
    {"seed", required_argument, NULL, 's'},
    {"profile", required_argument, NULL, O_PROFILE},
    {"track-std", required_argument, NULL, O_TRACK_STD},
    {"scan-rate", required_argument, NULL, O_SCAN_RATE},
    {"noise", required_argument, NULL, O_NOISE},
    {"speed-error", required_argument, NULL, O_SPEED_ERROR},
    {"preceding-gap", required_argument, NULL, O_PRECEDING_GAP},
    {"pre", required_argument, NULL, O_PRE},
    {"post", required_argument, NULL, O_POST},
    {"dt", required_argument, NULL, O_DT},
    {"lcm-url", required_argument, NULL, 'u'},
    {"log", required_argument, NULL, 'l'},
    {"bus-key", required_argument, NULL, 'k'},
    {"allow-production-bus", no_argument, NULL, O_ALLOW_PRODUCTION_BUS},
    {"speedup", required_argument, NULL, O_SPEEDUP},
    {"headway", required_argument, NULL, O_HEADWAY},
    {"flow", required_argument, NULL, O_FLOW},
    {"min-headway", required_argument, NULL, O_MIN_HEADWAY},
    {"lanes", required_argument, NULL, O_LANES},
    {"damage-step-at", required_argument, NULL, O_DAMAGE_STEP_AT},
    {"noise-ms2", required_argument, NULL, O_NOISE_MS2},
    {"block", required_argument, NULL, O_BLOCK},
    {"start-utime", required_argument, NULL, O_START_UTIME},
    {"detector-lead", required_argument, NULL, O_DETECTOR_LEAD},
    {"environment", required_argument, NULL, O_ENVIRONMENT},
    {"time-compression", required_argument, NULL, O_TIME_COMPRESSION},
    {"environment-period", required_argument, NULL, O_ENVIRONMENT_PERIOD},
    {"calibration-every", required_argument, NULL, O_CALIBRATION_EVERY},
    {"as-built", required_argument, NULL, O_AS_BUILT},
    {"calibration-runs", required_argument, NULL, O_CALIB_RUNS},
    {"truck", required_argument, NULL, O_TRUCK},
    {"runs-per-truck", required_argument, NULL, O_RUNS_PER_TRUCK},
    {"calibration-speeds", required_argument, NULL, O_CALIB_SPEEDS},
    {"tail", required_argument, NULL, O_TAIL},
    {"ambient-out", required_argument, NULL, O_AMBIENT_OUT},
    {"ambient-duration", required_argument, NULL, O_AMBIENT_DURATION},
    {"ambient-force", required_argument, NULL, O_AMBIENT_FORCE},
    AMFI_CLI_END};

/* "A" or "A,B" */
static void pair(const amfi_cli *c, const char *s, double lo, double hi, double *a, double *b,
                 int need_two)
{
    double v[2];
    if (need_two && !strchr(s, ','))
        amfi_cli_fail(c, "expected two values 'A,B'");
    int n = amfi_cli_list(c, s, v, 2, lo, hi);
    if (need_two && n != 2)
        amfi_cli_fail(c, "expected two values 'A,B'");
    *a = v[0];
    *b = n == 2 ? v[1] : v[0];
}

/* --config FILE (NULL when not given), read before the other flags, which
 * apply over the file. A bad command line or --help/--version ends the
 * program here, before any file is read. */
static void find_config(int argc, char **argv, const char **config)
{
    amfi_cli c;
    *config = NULL;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;)
        if (k == 'c')
            *config = optarg;
}

/* The configuration: FILE (--config), else the first of the default places
 * that exists, else the built-in defaults (*used = NULL). 0 ok, 1 after a
 * message. */
static int load_config(const char *file, amfi_site_config *cfg, const char **used)
{
    static char found[4096]; /* *used may point here */
    char err[512];

    amfi_config_defaults(cfg);
    *used = NULL;
    if (!file && amfi_datafile_find(DEFAULT_CONFIG_NAME, found, sizeof found) == 0)
        file = found;
    if (!file)
        return 0;
    if (amfi_config_load(file, cfg, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    *used = file;
    return 0;
}

/* The file's simulation: section (or the defaults) as the starting values. */
static void opts_from_config(opts *o, const amfi_sim_config *c, const char *file)
{
    *o = (opts){0};
    o->config = file;
    o->population = c->population[0] ? c->population : NULL;
    o->vehicles = c->vehicles;
    o->first = c->first;
    o->damage = c->damage;
    o->seed = (unsigned long)c->seed;
    o->profile_class = (char)c->profile_class;
    o->track_std = c->track_std;
    o->scan_rate = c->scan_rate_hz;
    o->noise = c->noise;
    o->speed_err_mean = c->speed_err_mean;
    o->speed_err_std = c->speed_err_std;
    o->preceding = c->preceding;
    o->gap_lo = c->gap_lo_s;
    o->gap_hi = c->gap_hi_s;
    o->pre = c->pre_s;
    o->post = c->post_s;
    o->dt = c->dt_s;
    o->lcm_url = c->lcm_url[0] ? c->lcm_url : NULL;
    o->log = c->log[0] ? c->log : NULL;
    o->speedup = c->speedup;
    o->headway = c->headway_s;
    o->flow = c->flow_veh_h;
    o->min_headway = c->min_headway_s;
    o->lanes = c->lanes;
    o->damage_step_at = c->damage_step_at;
    o->noise_ms2 = c->noise_ms2;
    o->block = c->block;
    o->start_utime = c->start_utime;
    o->detector_lead = c->detector_lead_s;
    o->environment = c->environment;
    o->time_compression = c->time_compression;
    o->environment_period = c->environment_period_s;
    o->calibration_every = c->calibration_every;
    o->cal.n_trucks = amfi_cal_default_trucks(o->cal.trucks);
    o->cal.runs_per_truck = 10;
    o->cal.speed_lo = 15.0;
    o->cal.speed_hi = 25.0;
    o->cal.tail_s = 3.0;
    o->ambient_s = 300.0;
    o->ambient_force_n = 20.0;
}

/* The flags over the values already in *o; exits 0 after --help, 2 after a
 * bad command line. */
static void apply_flags(int argc, char **argv, opts *o)
{
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *v = optarg;
        switch (k) {
        case 'o': o->out = v; break;
        case 'c': break; /* read by find_config() */
        case 'p': o->population = v; break;
        case 'n': o->vehicles = (long)amfi_cli_num(&c, v, 1, 1e7); break;
        case O_FIRST: o->first = (long)amfi_cli_num(&c, v, 0, 1e7); break;
        case 'd': o->damage = amfi_cli_num(&c, v, 0, 0.9); break;
        case 's': o->seed = (unsigned long)amfi_cli_num(&c, v, 0, 4294967295.0); break;
        case O_PROFILE:
            if (!strcmp(v, "smooth"))
                o->profile_class = 0;
            else if (strlen(v) == 1 && v[0] >= 'A' && v[0] <= 'H')
                o->profile_class = v[0];
            else
                amfi_cli_fail(&c, "'%s' is not A..H or smooth", amfi_cli_shown(v));
            break;
        case O_TRACK_STD: o->track_std = amfi_cli_num(&c, v, 0, 100); break;
        case O_SCAN_RATE: o->scan_rate = amfi_cli_num(&c, v, 50, 20000); break;
        case O_NOISE: o->noise = amfi_cli_num(&c, v, 0, 1); break;
        case O_SPEED_ERROR:
            pair(&c, v, -0.5, 0.5, &o->speed_err_mean, &o->speed_err_std, 1);
            break;
        case O_PRECEDING_GAP:
            if (!strcmp(v, "none")) {
                o->preceding = 0; /* over a gap in the configuration file */
                o->gap_lo = o->gap_hi = 0.0;
                break;
            }
            pair(&c, v, -2, 30, &o->gap_lo, &o->gap_hi, 0);
            o->preceding = 1;
            if (o->gap_hi < o->gap_lo)
                amfi_cli_fail(&c, "LO must not exceed HI");
            break;
        case O_PRE: o->pre = amfi_cli_num(&c, v, 0, 30); break;
        case O_POST: o->post = amfi_cli_num(&c, v, 0, 30); break;
        case O_DT: o->dt = amfi_cli_num(&c, v, 1e-6, 1e-3); break;
        case 'u':
            o->lcm_url = v;
            o->lcm_url_flag = 1;
            break;
        case 'l': o->log = v; break;
        case 'k': o->bus_key = v; break;
        case O_ALLOW_PRODUCTION_BUS: o->allow_production_bus = 1; break;
        case O_SPEEDUP:
            o->speedup = !strcmp(v, "max") ? 0.0 : amfi_cli_num(&c, v, 0.01, 1e6);
            break;
        case O_HEADWAY: o->headway = amfi_cli_num(&c, v, 0.1, 3600); break;
        case O_FLOW: o->flow = amfi_cli_num(&c, v, 1, 3600); break;
        case O_MIN_HEADWAY: o->min_headway = amfi_cli_num(&c, v, 0, 60); break;
        case O_LANES: o->lanes = (int)amfi_cli_num(&c, v, 1, AMFI_FLOW_MAX_LANES); break;
        case O_DAMAGE_STEP_AT:
            o->damage_step_at = !strcmp(v, "none") ? -1 : (long)amfi_cli_num(&c, v, 0, 1e7);
            break;
        case O_NOISE_MS2: o->noise_ms2 = amfi_cli_num(&c, v, 0, 10); break;
        case O_BLOCK: o->block = (int)amfi_cli_num(&c, v, 1, 160); break;
        case O_START_UTIME: o->start_utime = (long long)amfi_cli_num(&c, v, 1, 4e15); break;
        case O_DETECTOR_LEAD: o->detector_lead = amfi_cli_num(&c, v, 0, 60); break;
        case O_ENVIRONMENT:
            if (!strcmp(v, "none") || !strcmp(v, "site"))
                o->environment = !strcmp(v, "site");
            else
                amfi_cli_fail(&c, "'%s' is not none or site", amfi_cli_shown(v));
            break;
        case O_ENVIRONMENT_PERIOD:
            o->environment_period = amfi_cli_num(&c, v, 0.1, 86400);
            break;
        case O_CALIBRATION_EVERY: o->calibration_every = amfi_cli_integer(&c, v, 0, 1e7); break;
        case O_TIME_COMPRESSION: o->time_compression = amfi_cli_num(&c, v, 1, 1e6); break;
        case O_AS_BUILT: o->as_built = v; break;
        case O_CALIB_RUNS: o->calib_dir = v; break;
        case O_TRUCK: {
            char why[256];
            if (!o->trucks_given)
                o->cal.n_trucks = 0;
            o->trucks_given = 1;
            if (o->cal.n_trucks == AMFI_CAL_MAX_TRUCKS)
                amfi_cli_fail(&c, "at most %d trucks", AMFI_CAL_MAX_TRUCKS);
            if (amfi_cal_truck_parse(v, &o->cal.trucks[o->cal.n_trucks], why, sizeof why))
                amfi_cli_fail(&c, "'%s': %s", amfi_cli_shown(v), why);
            o->cal.n_trucks++;
            break;
        }
        case O_RUNS_PER_TRUCK: o->cal.runs_per_truck = (int)amfi_cli_integer(&c, v, 1, 1000); break;
        case O_CALIB_SPEEDS:
            pair(&c, v, 1, 60, &o->cal.speed_lo, &o->cal.speed_hi, 0);
            if (o->cal.speed_hi < o->cal.speed_lo)
                amfi_cli_fail(&c, "LO must not exceed HI");
            break;
        case O_TAIL: o->cal.tail_s = amfi_cli_num(&c, v, 0, 60); break;
        case O_AMBIENT_OUT: o->ambient_out = v; break;
        case O_AMBIENT_DURATION: o->ambient_s = amfi_cli_num(&c, v, 1, 3600); break;
        case O_AMBIENT_FORCE: o->ambient_force_n = amfi_cli_num(&c, v, 0, 1e7); break;
        }
    }
    if (o->out && (o->calib_dir || o->ambient_out)) {
        fprintf(stderr, "%s: --out and --calibration-runs/--ambient-out are separate modes\n",
                PROG);
        exit(2);
    }
    if (o->speed_err_std < 0) {
        fprintf(stderr, "%s: --speed-error: STD must be >= 0\n", PROG);
        exit(2);
    }
    if (!o->out && !o->calib_dir && !o->ambient_out && o->lcm_url &&
        !strcmp(o->lcm_url, "none") && !o->log) {
        if (o->lcm_url_flag)
            fprintf(stderr, "%s: --lcm-url none without --log would produce nothing\n", PROG);
        else
            fprintf(stderr, "%s: %s: simulation.stream.lcm_url: none without a log "
                    "(stream.log or --log) would produce nothing\n", PROG, o->config ? o->config : "?");
        exit(2);
    }
}

/* The bus an LCM URL reaches, for comparison: "provider://address:port"
 * without the options (ttl, recv_buf_size); for udpm, LCM's default group
 * and port filled in where the URL leaves them out. */
static void bus_identity(const char *url, char *out, size_t n)
{
    const char *q = strchr(url, '?');
    size_t len = q ? (size_t)(q - url) : strlen(url);
    snprintf(out, n, "%.*s", (int)len, url);
    if (strncmp(out, "udpm://", 7) == 0) {
        char addr[256];
        snprintf(addr, sizeof addr, "%s", out + 7);
        if (!addr[0])
            snprintf(addr, sizeof addr, "239.255.76.67:7667");
        else if (!strchr(addr, ':'))
            snprintf(addr + strlen(addr), sizeof addr - strlen(addr), ":7667");
        snprintf(out, n, "udpm://%s", addr);
    }
}

/* Simulated vehicles on amfid's bus would be weighed and stored as real
 * passages (on a site box: the production store, the fleet's central
 * database, the alerts). The bus sim_publisher would publish on (the URL
 * given, else $LCM_DEFAULT_URL, else LCM's default) is refused when it is
 * the bus amfid uses: its built-in default, the daemon.lcm_url of the
 * configuration sim_publisher read (the site file amfid reads too), or that
 * of the installed amfid.yaml. --allow-production-bus lets it through (a
 * bench, a private network namespace). 0: go on; 2 after a message. */
static int refuse_production_bus(const opts *o, const amfi_site_config *cfg)
{
    if (o->allow_production_bus || o->out || o->calib_dir || o->ambient_out ||
        (o->lcm_url && !strcmp(o->lcm_url, "none")))
        return 0;
    const char *env = getenv("LCM_DEFAULT_URL");
    const char *url = o->lcm_url ? o->lcm_url : env && env[0] ? env : AMFID_BUILTIN_URL;
    char mine[300], theirs[300], why[600] = "";
    bus_identity(url, mine, sizeof mine);
    bus_identity(AMFID_BUILTIN_URL, theirs, sizeof theirs);
    if (!strcmp(mine, theirs))
        snprintf(why, sizeof why, "amfid's default bus (daemon.lcm_url \"\")");
    if (!why[0] && cfg->daemon.lcm_url[0]) {
        bus_identity(cfg->daemon.lcm_url, theirs, sizeof theirs);
        if (!strcmp(mine, theirs))
            snprintf(why, sizeof why, "the bus amfid uses by %s: daemon.lcm_url",
                     o->config ? o->config : "the configuration");
    }
    if (!why[0] && (!o->config || strcmp(o->config, AMFID_INSTALLED_CONFIG))) {
        static amfi_site_config inst; /* large */
        char err[512];
        if (access(AMFID_INSTALLED_CONFIG, R_OK) == 0 &&
            amfi_config_load(AMFID_INSTALLED_CONFIG, &inst, err, sizeof err) == 0 &&
            inst.daemon.lcm_url[0]) {
            bus_identity(inst.daemon.lcm_url, theirs, sizeof theirs);
            if (!strcmp(mine, theirs))
                snprintf(why, sizeof why, "the bus of the installed amfid (%s: daemon.lcm_url)",
                         AMFID_INSTALLED_CONFIG);
        }
    }
    if (!why[0])
        return 0;
    fprintf(stderr,
            "%s: refusing to publish on %s (%s): it is %s, and a running amfid would weigh "
            "the simulated vehicles and store them as real passages (and ship them, raise "
            "alerts). Give a private bus (--lcm-url or simulation.stream.lcm_url, and the same "
            "daemon.lcm_url to a test amfid), or --allow-production-bus on a bench or in a "
            "private network namespace\n",
            PROG, url,
            o->lcm_url ? (o->lcm_url_flag ? "--lcm-url" : "simulation.stream.lcm_url")
                       : env && env[0] ? "$LCM_DEFAULT_URL" : "LCM's default",
            why);
    return 2;
}

/* A generator for vehicle i of a run: the same (seed, i), the same draws. */
static void seed_vehicle(gsl_rng *r, unsigned long seed, long i)
{
    unsigned long long h = (unsigned long long)seed * 0x9E3779B97F4A7C15ull + (unsigned long long)i;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    gsl_rng_set(r, (unsigned long)(h & 0xffffffffu) | 1u);
}

/* ---- the simulated world ---------------------------------------------------- */

/* What both modes simulate on: the bridge (healthy; with a damage step
 * while streaming, also the damaged one), the road carpet, the simulation
 * settings and the vehicle property law. Built once per run, by
 * world_build(); owned by main. With --as-built, the bridge and the sensor
 * positions are the as-built ones and det the detector's errors (else the
 * design's and none). */
typedef struct world {
    amfi_bridge *bridge;  /* the bridge the run starts with */
    amfi_bridge *damaged; /* --damage-step-at: the bridge from then on, else NULL */
    amfi_profile *prof;
    amfi_sim_params sp;
    amfi_halfcar_dist dist;
    amfi_bridge_params bp;   /* the simulated bridge, healthy (before any damage) */
    amfi_detector_error det; /* what the detector gets wrong */
    int as_built;            /* 1: --as-built given */
    double damage0;          /* the as-built bridge's own damage, compounded with
                                --damage: 1 − (1 − damage0)(1 − δ) */
} world;

/* The damage simulated for a run's damage d. */
static double world_damage(const world *w, double d)
{
    return 1.0 - (1.0 - w->damage0) * (1.0 - d);
}

static void world_free(world *w)
{
    amfi_profile_destroy(w->prof);
    amfi_bridge_destroy(w->damaged);
    amfi_bridge_destroy(w->bridge);
    memset(w, 0, sizeof *w);
}

/* 0, or 1 after a message. ab: the as-built bridge, sensors and detector,
 * or NULL (the design's). */
static int world_build(const opts *o, const amfi_site_config *cfg, const amfi_as_built *ab,
                       world *w)
{
    char err[512];
    const int step = !o->out && !o->calib_dir && !o->ambient_out && o->damage_step_at >= 0;
    memset(w, 0, sizeof *w);
    w->det = (amfi_detector_error){0.0, 1.0, 1.0}; /* exact */
    amfi_bridge_params bp = ab ? ab->site.bridge : cfg->bridge;
    /* an as-built bridge's own damage and the run's compound: (1 − δ)(1 − δ') */
    const double d0 = ab ? ab->site.bridge.damage : 0.0;
    bp.damage = 0.0;
    if (ab) {
        w->as_built = 1;
        w->det = ab->detector;
    }
    w->bp = bp;
    w->damage0 = d0;
    bp.damage = 1.0 - (1.0 - d0) * (1.0 - (step ? 0.0 : o->damage));
    if (amfi_bridge_create(&bp, &w->bridge, err, sizeof err)) {
        fprintf(stderr, "%s: bridge: %s\n", PROG, err);
        return 1;
    }
    if (step) {
        bp.damage = 1.0 - (1.0 - d0) * (1.0 - o->damage);
        if (amfi_bridge_create(&bp, &w->damaged, err, sizeof err)) {
            fprintf(stderr, "%s: bridge: %s\n", PROG, err);
            world_free(w);
            return 1;
        }
    }
    amfi_sim_params_default(&w->sp, bp.span_m);
    w->sp.dt_s = o->dt;
    w->sp.scan_rate_hz = o->scan_rate;
    w->sp.n_sensors = cfg->solver.n_sensors;
    memcpy(w->sp.sensor_x_m, ab ? ab->sensor_x_m : cfg->solver.sensor_x_m,
           sizeof w->sp.sensor_x_m);
    amfi_profile_params pp;
    amfi_profile_params_default(&pp);
    pp.iso_class = o->profile_class;
    pp.seed = o->seed;
    pp.length_m = w->sp.approach_m + AMFI_SIM_PROFILE_LEAD_M + bp.span_m + 100.0;
    if (amfi_profile_create(&pp, &w->prof, err, sizeof err)) {
        fprintf(stderr, "%s: profile: %s\n", PROG, err);
        world_free(w);
        return 1;
    }
    amfi_halfcar_dist_paper(&w->dist);
    return 0;
}

/* ---- streaming ----------------------------------------------------------- */

static volatile sig_atomic_t stream_stop;
static void on_signal(int sig)
{
    (void)sig;
    stream_stop = 1;
}

typedef struct bus {
    lcm_t *lcm;          /* NULL: not publishing */
    lcm_eventlog_t *log; /* NULL: no log */
    amfi_auth_signer *signer; /* NULL: unsigned (no key) */
    unsigned char *sbuf;      /* the signed message */
    size_t scap;
    int64_t eventnum;
    int64_t sent;        /* messages emitted (bus and/or log) */
    unsigned char *buf;
    int cap;
} bus;

/* Send one encoded message to the bus and/or the log (timestamp = data time). */
static int emit(bus *b, const char *channel, int64_t utime, const void *data, int len)
{
    if (b->signer) { /* signed once, the same bytes on the bus and in the log */
        if ((size_t)len + AMFI_AUTH_TRAILER_BYTES > b->scap) {
            unsigned char *n = realloc(b->sbuf, (size_t)len + AMFI_AUTH_TRAILER_BYTES);
            if (!n)
                return -1;
            b->sbuf = n;
            b->scap = (size_t)len + AMFI_AUTH_TRAILER_BYTES;
        }
        long n = amfi_auth_sign_into(b->signer, channel, data, (size_t)len, 0, b->sbuf, b->scap);
        if (n < 0)
            return -1;
        data = b->sbuf;
        len = (int)n;
    }
    if (b->lcm && lcm_publish(b->lcm, channel, data, (unsigned)len) != 0)
        return -1;
    if (b->log) {
        lcm_eventlog_event_t ev = {b->eventnum++, utime, (int32_t)strlen(channel), len,
                                   (char *)channel, (void *)data};
        if (lcm_eventlog_write_event(b->log, &ev) != 0)
            return -1;
    }
    b->sent++;
    return 0;
}

#define EMIT(b, T, channel, msg)                                                      \
    ({                                                                                \
        int len_ = T##_encoded_size(msg), rc_ = -1;                                   \
        if (len_ > (b)->cap) {                                                        \
            unsigned char *n_ = realloc((b)->buf, (size_t)len_);                      \
            if (n_) {                                                                 \
                (b)->buf = n_;                                                        \
                (b)->cap = len_;                                                      \
            }                                                                         \
        }                                                                             \
        if (len_ <= (b)->cap && T##_encode((b)->buf, 0, len_, msg) == len_)           \
            rc_ = emit(b, channel, (msg)->utime, (b)->buf, len_);                     \
        rc_;                                                                          \
    })

typedef struct planned {
    amfi_sim_vehicle v;  /* id = first + index in the plan + 1 */
    int rec;             /* its population record (first + index without
                            --environment site) */
    double entry_s;      /* sim time */
    int added, announced;
    int n_axles;
    double spacing[AMFI_MAX_AXLES]; /* n_axles − 1 */
    int lane;            /* 1-based */
    double start_s;      /* its approach starts (sim time) */
    double reference_kg; /* the calibration truck: its static GVW; else 0 */
} planned;

static int by_start(const void *a, const void *b)
{
    const planned *p = a, *q = b;
    return (p->start_s > q->start_s) - (p->start_s < q->start_s);
}

/* --environment site: before vehicle `id` is added at data time now, put
 * the bridge of the current deck temperature (and damage) under the
 * traffic; *cur is the bridge simulated so far. 0, or 1 after a message. */
static int site_update(amfi_site *site, amfi_sim *sim, double now, double damage,
                       const amfi_bridge **cur, double deck_range[2])
{
    char err[512];
    const amfi_bridge *b = amfi_site_bridge_at(site, now, damage, err, sizeof err);
    if (!b || (b != *cur && amfi_sim_set_bridge(sim, b, err, sizeof err))) {
        fprintf(stderr, "%s: environment: %s\n", PROG, err);
        return 1;
    }
    *cur = b;
    if (site->env.deck_c < deck_range[0])
        deck_range[0] = site->env.deck_c;
    if (site->env.deck_c > deck_range[1])
        deck_range[1] = site->env.deck_c;
    return 0;
}

/* A record's static weight: the sum of its axle loads (all of them). */
static double rec_static_kg(const amfi_vehicle_rec *r)
{
    double s = 0.0;
    for (int a = 0; a < r->n_axles; a++)
        s += r->axle_kg[a];
    return s;
}

static int stream(const opts *o, const amfi_site_config *cfg, const world *w,
                  const amfi_vehicle_rec *recs, int n_recs, const char *ppath)
{
    amfi_site site = {0};
    const amfi_bridge *cur = w->bridge;
    double deck_range[2] = {1e9, -1e9};
    char err[512];
    int rc = 1;
    bus b = {0};
    amfi_sim *sim = NULL;
    planned *plan = calloc((size_t)o->vehicles, sizeof *plan);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng *frng = gsl_rng_alloc(gsl_rng_mt19937); /* --flow arrivals */
    double *acc = NULL;
    if (!plan || !rng || !frng)
        goto out;
    if (o->environment &&
        amfi_site_init(&site, &w->bp, recs, n_recs, o->start_utime, o->time_compression,
                       o->seed, err, sizeof err)) {
        fprintf(stderr, "%s: %s: %s\n", PROG, ppath, err);
        goto out;
    }
    if (!o->lcm_url || strcmp(o->lcm_url, "none")) {
        b.lcm = lcm_create(o->lcm_url);
        if (!b.lcm) {
            fprintf(stderr, "%s: cannot open the LCM bus '%s'\n", PROG,
                    o->lcm_url ? o->lcm_url : "(default)");
            goto out;
        }
    }
    {
        char kbuf[4096], kerr[4300];
        const char *origin = NULL;
        const char *kp = amfi_auth_key_path(o->bus_key, cfg->daemon.bus_key_file, kbuf,
                                            sizeof kbuf, &origin);
        amfi_auth_key key;
        if (kp && amfi_auth_key_load(kp, &key, kerr, sizeof kerr)) {
            fprintf(stderr, "%s: %s (from the %s)\n", PROG, kerr, origin);
            goto out;
        }
        if (kp) {
            char producer[AMFI_AUTH_PRODUCER_BYTES + 1], pid[32];
            snprintf(pid, sizeof pid, "%ld", (long)getpid());
            amfi_auth_producer_name(producer, "sim.", pid);
            b.signer = calloc(1, sizeof *b.signer);
            if (!b.signer || amfi_auth_signer_init(b.signer, &key, producer, kerr, sizeof kerr)) {
                fprintf(stderr, "%s: bus key: %s\n", PROG, b.signer ? kerr : "out of memory");
                free(b.signer);
                b.signer = NULL;
                goto out;
            }
            memset(&key, 0, sizeof key);
        } else {
            fprintf(stderr, "%s: no bus key (--bus-key, daemon.bus.key_file, credential %s): "
                    "the messages are unsigned; amfid with daemon.bus.auth required refuses "
                    "them\n", PROG, AMFI_AUTH_CREDENTIAL);
        }
    }
    if (o->log) {
        b.log = lcm_eventlog_create(o->log, "w");
        if (!b.log) {
            fprintf(stderr, "%s: %s: cannot create the log: %s\n", PROG, o->log, strerror(errno));
            goto out;
        }
    }
    const amfi_sim_params sp = w->sp;
    amfi_bridge *const damaged = w->damaged;
    if (amfi_sim_create(w->bridge, w->prof, &sp, &sim, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        goto out;
    }
    /* The plan: entries spaced by the headway (or the population's clock),
     * the first after its full approach. */
    double t = 0.0;
    amfi_flow fl;
    /* the calibration truck (--calibration-every): the population's heaviest
     * record (the sum of all its axles), the same vehicle at every run */
    int truck = 0;
    for (int k = 1; k < n_recs; k++)
        if (rec_static_kg(&recs[k]) > rec_static_kg(&recs[truck]))
            truck = k;
    if (frng)
        gsl_rng_set(frng, o->seed ^ 0xf10bu);
    for (long i = 0; i < o->vehicles; i++) {
        /* the clock follows the population's records in order; with
         * --environment site the vehicle is the mix's draw for that time */
        const amfi_vehicle_rec *seq = &recs[o->first + i];
        double gap = o->headway > 0 ? o->headway
                                    : (i ? seq->timestamp_s - recs[o->first + i - 1].timestamp_s
                                         : 0.0);
        const int calib = o->calibration_every > 0 &&
                          (o->first + i + 1) % o->calibration_every == 0;
        const int ri = calib            ? truck
                       : o->environment ? amfi_site_pick(&site, o->seed, o->first + i,
                                                         i ? t + gap : 0.0)
                                        : (int)(o->first + i);
        const amfi_vehicle_rec *rec = &recs[ri];
        amfi_passage_spec spec;
        seed_vehicle(rng, o->seed, o->first + i);
        if (amfi_passage_spec_from_rec(rec, &w->dist, w->prof, o->track_std, rng, &spec, err,
                                       sizeof err)) {
            fprintf(stderr, "%s: %s:%ld: vehicle %d: %s\n", PROG, ppath, rec->line, ri + 1, err);
            goto out;
        }
        t = i ? t + gap : sp.approach_m / spec.speed_mps + 1.0;
        plan[i].lane = 1;
        if (o->flow > 0) {
            if (!i && amfi_flow_init(&fl, o->lanes, 3600.0 / o->flow, o->min_headway,
                                     w->bp.span_m, sp.approach_m, sp.approach_m + 1.0, frng, err,
                                     sizeof err)) {
                fprintf(stderr, "%s: %s\n", PROG, err);
                goto out;
            }
            amfi_flow_next(&fl, spec.speed_mps, frng, &plan[i].lane, &t);
            /* vehicles of one lane run over the same road track: lane 1
             * the carpet's centre track, lane 2 its first (flow.h) */
            if (w->prof)
                spec.track = plan[i].lane == 1 ? amfi_profile_tracks(w->prof) / 2 : 0;
        }
        /* a vehicle cannot start its approach before the previous one: keep order */
        plan[i].entry_s = t;
        plan[i].v.id = o->first + i + 1;
        plan[i].rec = ri;
        plan[i].v.car = spec.car;
        plan[i].v.truck = spec.truck;
        plan[i].v.speed_mps = spec.speed_mps;
        plan[i].v.t_entry_s = t;
        plan[i].start_s = t - sp.approach_m / spec.speed_mps;
        plan[i].v.track = spec.track;
        {
            double W[AMFI_MAX_AXLES], x[AMFI_MAX_AXLES];
            plan[i].n_axles = amfi_passage_axles(&spec, W, x);
            for (int a = 1; a < plan[i].n_axles; a++)
                plan[i].spacing[a - 1] = x[a] - x[a - 1];
        }
        plan[i].reference_kg = calib ? rec_static_kg(rec) : 0.0;
    }
    if (o->flow > 0) {
        /* the simulator takes vehicles in the order their approach starts */
        qsort(plan, (size_t)o->vehicles, sizeof *plan, by_start);
        for (long i = 0; i < o->vehicles; i++)
            plan[i].v.id = o->first + i + 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    const int ns = sp.n_sensors, blk = o->block;
    acc = malloc(sizeof(double) * (size_t)blk * ns);
    int64_t seq[AMFI_MAX_SENSORS] = {0};
    long next_add = 0, next_announce = 0, left = 0;
    const double t_end_extra = 3.0;
    double t_last_left = -1.0;
    const double w0 = amfi_mono_s();
    gsl_rng *noise = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(noise, o->seed ^ 0x5eedu);
    int stepped = 0; /* the damage step has happened */
    double next_env_s = 0.0; /* data time of the next environment_t */
    if (!acc || !noise)
        goto out;
    while (!stream_stop) {
        const double now = amfi_sim_time(sim);
        /* add vehicles before their approach starts */
        while (next_add < o->vehicles &&
               plan[next_add].entry_s - sp.approach_m / plan[next_add].v.speed_mps <=
                   now + (double)blk / o->scan_rate + 1e-9) {
            if (damaged && !stepped && next_add == o->damage_step_at)
                break; /* switch the bridge first (next loop turn) */
            if (o->environment &&
                site_update(&site, sim, now,
                            world_damage(w, damaged && !stepped ? 0.0 : o->damage), &cur,
                            deck_range))
                goto out;
            if (amfi_sim_add(sim, &plan[next_add].v, err, sizeof err)) {
                fprintf(stderr, "%s: vehicle %ld: %s\n", PROG, plan[next_add].v.id, err);
                goto out;
            }
            plan[next_add].added = 1;
            next_add++;
        }
        if (damaged && !stepped && next_add == o->damage_step_at && next_add < o->vehicles) {
            plan[next_add].added = 1; /* marks the step; added after the switch */
            if (amfi_sim_set_bridge(sim, damaged, err, sizeof err)) {
                fprintf(stderr, "%s: %s\n", PROG, err);
                goto out;
            }
            stepped = 1;
            fprintf(stderr, "%s: damage %.3g from vehicle %ld on (t = %.1f s)\n", PROG, o->damage,
                    plan[next_add].v.id, now);
            cur = damaged;
            if (o->environment &&
                site_update(&site, sim, now, world_damage(w, o->damage), &cur, deck_range))
                goto out;
            if (amfi_sim_add(sim, &plan[next_add].v, err, sizeof err)) {
                fprintf(stderr, "%s: vehicle %ld: %s\n", PROG, plan[next_add].v.id, err);
                goto out;
            }
            next_add++;
        }
        /* announce vehicles the detector has seen */
        while (next_announce < next_add &&
               plan[next_announce].entry_s - o->detector_lead <= now + 1e-9) {
            const planned *p = &plan[next_announce];
            double speed = p->v.speed_mps;
            if (o->speed_err_mean != 0 || o->speed_err_std > 0)
                speed *= 1.0 + o->speed_err_mean +
                         (o->speed_err_std > 0 ? gsl_ran_gaussian(noise, o->speed_err_std) : 0.0);
            /* the detector's systematic errors (--as-built; none: zero) */
            speed *= w->det.speed_scale;
            double spacing[AMFI_MAX_AXLES];
            for (int a = 0; a < p->n_axles - 1; a++)
                spacing[a] = p->spacing[a] * w->det.spacing_scale;
            const double entry = p->entry_s + w->det.clock_offset_s;
            amfi_vehicle_t m = {o->start_utime + (int64_t)llround(entry * 1e6), p->v.id, p->lane,
                                speed, (int16_t)p->n_axles, (int16_t)(p->n_axles - 1), spacing,
                                PROG, p->reference_kg};
            if (EMIT(&b, amfi_vehicle_t, cfg->daemon.ch_vehicle, &m)) {
                fprintf(stderr, "%s: publishing failed\n", PROG);
                goto out;
            }
            next_announce++;
        }
        /* the environment, every environment_period of data time */
        if (o->environment && now + 1e-9 >= next_env_s) {
            amfi_env_advance(&site.env, now);
            amfi_environment_t m = {o->start_utime + (int64_t)llround(now * 1e6), site.env.air_c,
                                    site.env.deck_c};
            if (EMIT(&b, amfi_environment_t, cfg->daemon.ch_environment, &m)) {
                fprintf(stderr, "%s: publishing failed\n", PROG);
                goto out;
            }
            do
                next_env_s += o->environment_period;
            while (next_env_s <= now + 1e-9);
        }
        /* one block of samples */
        if (amfi_sim_advance(sim, blk, acc, err, sizeof err)) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            goto out;
        }
        const int64_t u0 = o->start_utime + (int64_t)llround(now * 1e6);
        for (int si = 0; si < ns; si++) {
            double x[160];
            for (int k = 0; k < blk; k++)
                x[k] = acc[(size_t)k * ns + si] +
                       (o->noise_ms2 > 0 ? gsl_ran_gaussian(noise, o->noise_ms2) : 0.0);
            amfi_accel_block_t m = {u0, cfg->sensor_id[si], seq[si]++, o->scan_rate,
                                    (int16_t)blk, x};
            if (EMIT(&b, amfi_accel_block_t, cfg->daemon.ch_accel, &m)) {
                fprintf(stderr, "%s: publishing failed\n", PROG);
                goto out;
            }
        }
        /* the truth of the vehicles that have left */
        amfi_sim_vehicle d;
        while (amfi_sim_pop_done(sim, &d)) {
            const amfi_vehicle_rec *rec = &recs[plan[d.id - 1 - o->first].rec];
            /* the static loads simulated: the record's (a load-sharing
             * group's equalised) */
            const int na = d.truck.n_axles;
            double axle[AMFI_MAX_AXLES], gvw = 0.0;
            for (int a = 0; a < na; a++) {
                axle[a] = na == 2 ? rec->axle_kg[a] : d.truck.W_N[a] / AMFI_GRAVITY;
                gvw += axle[a];
            }
            amfi_truth_t m = {o->start_utime + (int64_t)llround(d.t_entry_s * 1e6), d.id,
                              gvw, (int16_t)na, axle, d.mean_force_N, d.speed_mps};
            if (EMIT(&b, amfi_truth_t, cfg->daemon.ch_truth, &m)) {
                fprintf(stderr, "%s: publishing failed\n", PROG);
                goto out;
            }
            left++;
            t_last_left = amfi_sim_time(sim);
        }
        if (left == o->vehicles && amfi_sim_time(sim) > t_last_left + t_end_extra)
            break;
        /* pacing */
        if (o->speedup > 0) {
            double due = w0 + amfi_sim_time(sim) / o->speedup - amfi_mono_s();
            if (due > 0) {
                struct timespec ts = {(time_t)due, (long)((due - floor(due)) * 1e9)};
                nanosleep(&ts, NULL);
            }
        }
    }
    if (o->environment)
        fprintf(stderr, "%s: environment site: deck %.1f .. %.1f °C over %.1f site days, "
                "%d bridge moduli\n", PROG, deck_range[0], deck_range[1],
                amfi_sim_time(sim) * o->time_compression / 86400.0, site.n_bridges);
    fprintf(stderr, "%s: %ld vehicles streamed over %.1f s of data in %lld messages%s\n", PROG,
            left, amfi_sim_time(sim), (long long)b.sent,
            stream_stop ? " (stopped by a signal)" : "");
    rc = 0;
    gsl_rng_free(noise);
out:
    free(acc);
    amfi_sim_destroy(sim);
    amfi_site_free(&site);
    if (b.log)
        lcm_eventlog_destroy(b.log);
    if (b.lcm)
        lcm_destroy(b.lcm);
    if (b.signer)
        amfi_auth_signer_free(b.signer);
    free(b.signer);
    free(b.sbuf);
    free(b.buf);
    free(plan);
    gsl_rng_free(rng);
    gsl_rng_free(frng);
    return rc;
}

/* ---- commissioning records (--calibration-runs, --ambient-out) ------------ */

/* Offline, no bus, no population: the calibration runs and/or the ambient
 * record on the as-built bridge (ab, or the design's when NULL). 0, or 1
 * after a message. */
static int commissioning(const opts *o, const amfi_site_config *cfg, const amfi_as_built *ab)
{
    char err[512];
    world w;
    int rc = 1;
    if (world_build(o, cfg, ab, &w))
        return 1;
    if (o->calib_dir) {
        if (mkdir(o->calib_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "%s: %s: cannot create: %s\n", PROG, o->calib_dir, strerror(errno));
            goto out;
        }
        amfi_cal_params p = o->cal;
        p.pre_s = o->pre;
        p.noise_frac = o->noise;
        p.noise_ms2 = o->noise_ms2;
        p.speed_err_mean = o->speed_err_mean;
        p.speed_err_std = o->speed_err_std;
        p.track_std = o->track_std;
        p.seed = o->seed;
        p.det = w.det;
        p.sensor_id = cfg->sensor_id;
        if (amfi_cal_runs_write(o->calib_dir, w.bridge, w.prof, &w.sp, &w.dist, &p, err,
                                sizeof err)) {
            fprintf(stderr, "%s: calibration runs: %s\n", PROG, err);
            goto out;
        }
        fprintf(stderr, "%s: %d calibration runs of %d trucks in %s\n", PROG,
                p.n_trucks * p.runs_per_truck, p.n_trucks, o->calib_dir);
    }
    if (o->ambient_out) {
        amfi_ambient_params a = {o->ambient_s, o->ambient_force_n, o->noise, o->noise_ms2,
                                 o->seed, cfg->sensor_id};
        if (amfi_ambient_write(o->ambient_out, w.bridge, &w.sp, &a, err, sizeof err)) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            goto out;
        }
    }
    rc = 0;
out:
    world_free(&w);
    return rc;
}

int main(int argc, char **argv)
{
    opts o;
    static amfi_site_config cfg; /* large; o's strings point into it */
    const char *cfile = NULL, *cused = NULL;
    amfi_config_defaults(&cfg);
    find_config(argc, argv, &cfile);
    if (load_config(cfile, &cfg, &cused))
        return 1;
    opts_from_config(&o, &cfg.sim, cused);
    apply_flags(argc, argv, &o);
    if (refuse_production_bus(&o, &cfg))
        return 2;
    amfi_set_blas_threads(1);
    char err[512];
    cfg.bridge.damage = o.damage;
    static amfi_as_built ab; /* --as-built: large */
    if (o.as_built && amfi_config_as_built_load(o.as_built, &cfg, &ab, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (o.calib_dir || o.ambient_out)
        return commissioning(&o, &cfg, o.as_built ? &ab : NULL);
    char found[4096];
    const char *ppath = o.population;
    if (!ppath) {
        if (amfi_datafile_find(DEFAULT_POPULATION_NAME, found, sizeof found) != 0) {
            char places[512];
            fprintf(stderr, "%s: no --population and no %s in %s (set AMFI_DATA_DIR)\n", PROG,
                    DEFAULT_POPULATION_NAME, amfi_datafile_places(places, sizeof places));
            return 1;
        }
        ppath = found;
    }
    amfi_vehicle_rec *recs = NULL;
    int n_recs = 0;
    if (amfi_traffic_read(ppath, &recs, &n_recs, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (o.first + o.vehicles > n_recs) {
        fprintf(stderr, "%s: %s has %d vehicles; --first %ld --vehicles %ld needs %ld\n", PROG,
                ppath, n_recs, o.first, o.vehicles, o.first + o.vehicles);
        amfi_traffic_free(recs);
        return 2;
    }
    world w;
    if (world_build(&o, &cfg, o.as_built ? &ab : NULL, &w)) {
        amfi_traffic_free(recs);
        return 1;
    }
    if (!o.out) {
        int src = stream(&o, &cfg, &w, recs, n_recs, ppath);
        world_free(&w);
        amfi_traffic_free(recs);
        return src;
    }
    if (o.environment)
        fprintf(stderr, "%s: --environment site is for streaming; --out simulates without it\n",
                PROG);
    if (mkdir(o.out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: %s: cannot create: %s\n", PROG, o.out, strerror(errno));
        world_free(&w);
        amfi_traffic_free(recs);
        return 1;
    }
    amfi_bridge *const b = w.bridge;
    amfi_profile *const prof = w.prof;
    const amfi_sim_params sp = w.sp;
    const amfi_halfcar_dist dist = w.dist;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    double *acc = NULL;
    FILE *meta = NULL;
    int rc = 1;
    const int cap = (int)((o.pre + o.post + 60.0) * o.scan_rate);
    acc = malloc(sizeof(double) * cap * sp.n_sensors);
    char path[4096];
    snprintf(path, sizeof path, "%s/meta.csv", o.out);
    meta = fopen(path, "w");
    if (!acc || !meta) {
        fprintf(stderr, "%s: %s: %s\n", PROG, path, acc ? strerror(errno) : "out of memory");
        goto out;
    }
    /* with --as-built: what the detector reported in the first columns, the
     * design's sensor position, and the truth appended */
    fprintf(meta, "name,speed_mps,speed_true_mps,axle_spacing_m,entry_time_s,gvw_kg,axle1_kg,"
                  "axle2_kg,mean_force1_N,mean_force2_N,damage,noise,profile,track,"
                  "preceding_gap_s,lost_contact_steps,scan_rate_hz,sensor_x_m,n_axles,"
                  "axle_spacings_m,axle_kgs,mean_forces_N%s\n",
            w.as_built ? ",entry_time_true_s,axle_spacing_true_m,sensor_x_true_m" : "");
    for (long i = 0; i < o.vehicles; i++) {
        const amfi_vehicle_rec *rec = &recs[o.first + i];
        amfi_passage_spec spec;
        seed_vehicle(rng, o.seed, o.first + i);
        if (amfi_passage_spec_from_rec(rec, &dist, prof, o.track_std, rng, &spec, err,
                                       sizeof err)) {
            fprintf(stderr, "%s: %s:%ld: vehicle %ld: %s\n", PROG, ppath, rec->line,
                    o.first + i + 1, err);
            goto out;
        }
        spec.pre_s = o.pre;
        spec.post_s = o.post;
        double gap = NAN;
        if (o.preceding) {
            const amfi_vehicle_rec *p = &recs[gsl_rng_uniform_int(rng, (unsigned long)n_recs)];
            amfi_passage_spec ps;
            if (amfi_passage_spec_from_rec(p, &dist, prof, o.track_std, rng, &ps, err,
                                           sizeof err)) {
                fprintf(stderr, "%s: %s:%ld: preceding vehicle: %s\n", PROG, ppath, p->line, err);
                goto out;
            }
            gap = o.gap_lo + (o.gap_hi - o.gap_lo) * gsl_rng_uniform(rng);
            spec.preceding = 1;
            spec.prec_car = ps.car;
            spec.prec_truck = ps.truck;
            spec.prec_speed_mps = ps.speed_mps;
            spec.prec_track = ps.track;
            spec.gap_s = gap;
        }
        amfi_measure m = {o.noise, o.speed_err_mean, o.speed_err_std};
        amfi_passage_rec pr;
        if (amfi_passage_simulate(b, prof, &sp, &spec, &m, rng, acc, cap, &pr, err,
                                  sizeof err)) {
            fprintf(stderr, "%s: vehicle %ld: %s\n", PROG, o.first + i + 1, err);
            goto out;
        }
        char name[32];
        snprintf(name, sizeof name, "v%05ld", o.first + i + 1);
        snprintf(path, sizeof path, "%s/%s.csv", o.out, name);
        /* every sensor of the site: one column, or accel_ID per sensor */
        if (amfi_sim_write_accel(path, pr.n, pr.n_sensors, cfg.sensor_id, o.scan_rate, acc, err,
                                 sizeof err)) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            goto out;
        }
        /* the first two axles in the two-axle columns, every axle in the lists
         * (true spacings; the detector's first one in axle_spacing_m) */
        double Wn[AMFI_MAX_AXLES], xa[AMFI_MAX_AXLES], akg[AMFI_MAX_AXLES], gvw = 0.0;
        const int na = amfi_passage_axles(&spec, Wn, xa);
        const double spacing = xa[1];
        long lost = 0;
        for (int a = 0; a < na; a++) {
            akg[a] = na == 2 ? rec->axle_kg[a] : Wn[a] / AMFI_GRAVITY;
            gvw += akg[a];
            lost += pr.truth.lost_contact_steps[a];
        }
        fprintf(meta, "%s,%.9g,%.9g,%.9g,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%g,%g,%s,%d,%.6g,%ld,%g,",
                name, pr.speed_measured_mps * w.det.speed_scale, spec.speed_mps,
                spacing * w.det.spacing_scale, -pr.t_first_s + w.det.clock_offset_s,
                na == 2 ? rec->axle_kg[0] + rec->axle_kg[1] : gvw, akg[0], akg[1],
                pr.truth.mean_force_N[0], pr.truth.mean_force_N[1], o.damage, o.noise,
                o.profile_class ? (char[]){o.profile_class, 0} : "smooth", spec.track, gap, lost,
                o.scan_rate);
        amfi_sim_put_list(meta, cfg.solver.sensor_x_m, pr.n_sensors, "%g"); /* the design's */
        fprintf(meta, ",%d,", na);
        for (int a = 1; a < na; a++)
            fprintf(meta, "%s%.9g", a > 1 ? ";" : "", xa[a] - xa[a - 1]);
        fputc(',', meta);
        amfi_sim_put_list(meta, akg, na, "%.6f");
        fputc(',', meta);
        amfi_sim_put_list(meta, pr.truth.mean_force_N, na, "%.6f");
        if (w.as_built) {
            fprintf(meta, ",%.6f,%.9g,", -pr.t_first_s, spacing);
            amfi_sim_put_list(meta, sp.sensor_x_m, pr.n_sensors, "%g");
        }
        fputc('\n', meta);
    }
    if (fclose(meta) != 0) {
        meta = NULL;
        fprintf(stderr, "%s: %s/meta.csv: write failed\n", PROG, o.out);
        goto out;
    }
    meta = NULL;
    rc = 0;
out:
    if (meta)
        fclose(meta);
    free(acc);
    gsl_rng_free(rng);
    world_free(&w);
    amfi_traffic_free(recs);
    return rc;
}
