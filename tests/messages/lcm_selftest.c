/* SPDX-License-Identifier: GPL-3.0-or-later */
/* lcm_selftest: one of each amfi message (messages/ *.lcm) with plausible
 * values, for checking the generated C, the bus and lcm-spy.
 *
 *   lcm_selftest URL [N]          publish the seven messages N times (default
 *                                 30) at 10 Hz on URL ("" or "-": LCM's default,
 *                                 $LCM_DEFAULT_URL or udpm://239.255.76.67:7667)
 *   lcm_selftest --roundtrip [URL [N]]
 *                                 publish N rounds (default 20) on URL (default
 *                                 memq://) and receive them in the same process
 *                                 on "AMFI_.*": every field of every type must
 *                                 come back bit for bit (encode -> decode), plus
 *                                 a NaN/empty passage, a wrong-type and a short
 *                                 buffer that must be refused
 *   lcm_selftest --expect I       print round I's messages, one line per
 *                                 channel: CHANNEL<TAB>amfi.TYPE<TAB>field=value;...
 *                                 (doubles as their IEEE-754 bits in hex, arrays
 *                                 as [a,b]), the form tests/messages/test_spy.sh reads
 *                                 back from lcm-spy
 *
 * Round i's values depend on i only (a fixed clock from utime 1.7638e15 µs,
 * 100 ms per round), so --expect reproduces what was published.
 * Exit status: 0 ok, 1 a check or a publish failed, 2 bad command line.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_cli.h"

#include <lcm/lcm.h>

#include "amfi_auth.h"
#include "amfi_messages.h"

/* Every message is signed (messages/amfi_auth.h) with this program's own
 * key, and the round trip verifies and strips the trailer before decoding:
 * lcm-spy (tests/messages/test_spy.sh) decodes the signed messages as they are. */
static amfi_auth_signer signer;
static amfi_auth_verifier verifier;

static int auth_init(void)
{
    amfi_auth_key k;
    memcpy(k.k, "lcm_selftest: not a site's key.", AMFI_AUTH_KEY_BYTES);
    char err[256];
    if (amfi_auth_signer_init(&signer, &k, "lcm_selftest", err, sizeof err) ||
        amfi_auth_verifier_init(&verifier, &k, 300.0)) {
        fprintf(stderr, "lcm_selftest: %s\n", err);
        return -1;
    }
    return 0;
}

/* Encode a message of type T and publish it signed: 0 or -1. */
#define PUBLISH(T, lcm, channel, msg)                                                    \
    ({                                                                                   \
        int len_ = T##_encoded_size(msg), rc_ = -1;                                      \
        void *buf_ = len_ > 0 ? malloc((size_t)len_) : NULL;                             \
        if (buf_ && T##_encode(buf_, 0, len_, msg) == len_)                              \
            rc_ = amfi_auth_publish(lcm, &signer, channel, buf_, (size_t)len_);          \
        free(buf_);                                                                      \
        rc_;                                                                             \
    })

#define T0_UTIME   INT64_C(1763800000000000) /* µs, 2025-11-22 08:26:40 UTC */
#define ROUND_US   INT64_C(100000)           /* 10 Hz */
#define FS_HZ      1000.0                    /* accelerometer sample rate */
#define N_SAMPLES  100                       /* samples per block at 10 Hz */
#define G          9.81                      /* m/s² */
#define PI         3.14159265358979323846    /* M_PI is not in strict C11 */

/* Round i's messages. The arrays the messages point at live here too. */
struct round {
    amfi_accel_block_t accel;
    double accel_v[AMFI_ACCEL_BLOCK_MAX_SAMPLES]; /* m/s² */
    amfi_vehicle_t vehicle;
    double spacing_m[AMFI_MAX_AXLES - 1];
    amfi_truth_t truth;
    double truth_axle_kg[AMFI_MAX_AXLES];
    double truth_force_N[AMFI_MAX_AXLES];
    amfi_passage_t passage;      /* solved */
    double passage_axle_kg[AMFI_MAX_AXLES];
    int16_t passage_group_axles[AMFI_MAX_AXLES];
    double passage_group_kg[AMFI_MAX_AXLES];
    amfi_passage_t unsolved;     /* status gap: NaN weights, no axles */
    amfi_indicator_t indicator;
    amfi_alert_t alert;
    amfi_status_t status;
    amfi_environment_t environment;
    char alert_message[128];
};

/* Fill r with round i. The strings are literals or r's own buffers. */
static void round_make(struct round *r, int i)
{
    memset(r, 0, sizeof *r);
    int64_t t = T0_UTIME + i * ROUND_US;

    /* A mid-span accelerometer ringing at the first mode (3.1 Hz) with a
     * little of the second (12.4 Hz). */
    r->accel.utime = t;
    r->accel.sensor_id = 1;
    r->accel.seq = i;
    r->accel.sample_rate_hz = FS_HZ;
    r->accel.n = N_SAMPLES;
    for (int k = 0; k < N_SAMPLES; k++) {
        double ts = (i * N_SAMPLES + k) / FS_HZ;
        r->accel_v[k] = 0.045 * sin(2 * PI * 3.1 * ts) + 0.008 * sin(2 * PI * 12.4 * ts + 0.3);
    }
    r->accel.accel = r->accel_v;

    /* A 2..5-axle truck at 72..90 km/h. */
    int n_axles = 2 + i % 4;
    r->vehicle.utime = t + 50000;
    r->vehicle.vehicle_id = 1000 + i;
    r->vehicle.lane = (int16_t)(1 + i % 2);
    r->vehicle.speed_mps = 20.0 + 0.125 * (i % 40);
    r->vehicle.n_axles = (int16_t)n_axles;
    r->vehicle.n_spacings = (int16_t)(n_axles - 1);
    for (int j = 0; j < n_axles - 1; j++)
        r->spacing_m[j] = j == 0 ? 3.6 + 0.05 * (i % 10) : 1.31;
    r->vehicle.axle_spacing_m = r->spacing_m;
    r->vehicle.source = "lcm_selftest";
    r->vehicle.reference_gvw_kg = i % 4 == 0 ? 14829.0 : 0.0; /* a calibration truck */

    double gvw = 0;
    for (int j = 0; j < n_axles; j++) {
        r->truth_axle_kg[j] = j == 0 ? 6200.0 : 8000.0 + 250.0 * j;
        r->truth_force_N[j] = r->truth_axle_kg[j] * G * (1.0 + 0.013 * (j + 1));
        gvw += r->truth_axle_kg[j];
    }
    r->truth.utime = r->vehicle.utime;
    r->truth.vehicle_id = r->vehicle.vehicle_id;
    r->truth.gvw_kg = gvw;
    r->truth.n_axles = (int16_t)n_axles;
    r->truth.axle_kg = r->truth_axle_kg;
    r->truth.mean_force_N = r->truth_force_N;
    r->truth.speed_true_mps = r->vehicle.speed_mps * 1.012;

    for (int j = 0; j < n_axles; j++)
        r->passage_axle_kg[j] = r->truth_axle_kg[j] * (0.97 + 0.01 * j);
    r->passage.utime = r->vehicle.utime;
    r->passage.passage_id = 500 + i;
    r->passage.vehicle_id = r->vehicle.vehicle_id;
    r->passage.lane = r->vehicle.lane;
    r->passage.speed_mps = r->vehicle.speed_mps;
    r->passage.status = "ok";
    r->passage.reason = "";
    r->passage.gvw_kg = 0;
    for (int j = 0; j < n_axles; j++)
        r->passage.gvw_kg += r->passage_axle_kg[j];
    r->passage.n_axles = (int16_t)n_axles;
    r->passage.axle_kg = r->passage_axle_kg;
    r->passage.lambda = 3.2e-9;
    r->passage.residual_rms = 0.0041;
    r->passage.formulation = "modal";
    r->passage.solve_ms = 14.5 + 0.25 * (i % 8);
    r->passage.site_id = "selftest-site";
    r->passage.speed_given_mps = r->vehicle.speed_mps * 1.02; /* the detector 2 % high */
    r->passage.speed_estimated = 1;
    r->passage.n_vehicles = (int16_t)(1 + i % 3);   /* weighed alone or with others */
    r->passage.quality = 1.0 + 0.5 * (i % 3);
    r->passage.reference_gvw_kg = i % 4 == 0 ? 14829.0 : NAN;
    r->passage.f1_hz = 5.7338 - 0.001 * (i % 5); /* paper-20m's first frequency */
    r->passage.f1_comp_hz = i % 4 ? 5.7201 : NAN; /* before the baseline: NaN */
    /* the class and groups: a two-axle R2 (1-1), or the front axle and the rest */
    r->passage.vehicle_class = n_axles == 2 ? "R2" : "unknown";
    r->passage.n_groups = (int8_t)(n_axles > 1 ? 2 : 1);
    r->passage_group_axles[0] = 1;
    r->passage_group_axles[1] = (int16_t)(n_axles - 1);
    r->passage_group_kg[0] = r->passage_axle_kg[0];
    r->passage_group_kg[1] = r->passage.gvw_kg - r->passage_axle_kg[0];
    r->passage.group_axles = r->passage_group_axles;
    r->passage.group_load_kg = r->passage_group_kg;
    r->passage.overload = (int8_t)(i % 2);
    r->passage.fit_ratio = i % 3 ? 0.0042 : NAN; /* an event's vehicle: not fitted */
    /* every fifth: loads the classification refused (overload not decided) */
    r->passage.loads_refused = i % 5 == 4 ? "group 2 (axles 2-3): load -3200 kg < 0" : "";
    if (i % 5 == 4)
        r->passage.overload = -1;

    r->unsolved = r->passage;
    r->unsolved.passage_id = 100000 + i;
    r->unsolved.status = "gap";
    r->unsolved.reason = "AMFI_ACCEL sensor 1: 350 samples missing during the passage";
    r->unsolved.gvw_kg = NAN;
    r->unsolved.f1_hz = r->unsolved.f1_comp_hz = NAN;
    r->unsolved.n_axles = 0;
    r->unsolved.axle_kg = NULL;
    r->unsolved.lambda = NAN;
    r->unsolved.residual_rms = NAN;
    r->unsolved.formulation = "";
    r->unsolved.solve_ms = 0;
    r->unsolved.vehicle_class = "";
    r->unsolved.n_groups = 0;
    r->unsolved.group_axles = NULL;
    r->unsolved.group_load_kg = NULL;
    r->unsolved.overload = -1;
    r->unsolved.fit_ratio = NAN;
    r->unsolved.loads_refused = "";

    r->indicator.utime = r->vehicle.utime;
    r->indicator.indicator_id = 700 + i;
    r->indicator.n = 200;
    r->indicator.mean_kg = 24850.0 + 10.0 * (i % 7);
    r->indicator.std_kg = 5120.5;
    r->indicator.baseline_mean_kg = 24790.0;
    r->indicator.baseline_std_kg = 4980.0;
    r->indicator.std_ratio = r->indicator.std_kg / r->indicator.baseline_std_kg;
    r->indicator.p_value = 0.274;
    r->indicator.state = "normal";
    r->indicator.site_id = "selftest-site";

    snprintf(r->alert_message, sizeof r->alert_message,
             "GVW spread %.2f x baseline over %d passages", 1.32, 200);
    r->alert.utime = r->vehicle.utime;
    r->alert.alert_id = 90 + i;
    r->alert.level = "warning";
    r->alert.kind = "std_increase";
    r->alert.message = r->alert_message;
    r->alert.indicator_id = r->indicator.indicator_id;
    r->alert.raised = (int8_t)(i % 2 == 0);
    r->alert.site_id = "selftest-site";

    r->status.utime = t + (N_SAMPLES - 1) * 1000;
    r->status.wall_utime = t + 123456;
    r->status.blocks_received = i + 1;
    r->status.blocks_rejected = 0;
    r->status.samples_missing = 350;
    r->status.vehicles_received = i + 1;
    r->status.vehicles_rejected = 0;
    r->status.passages_stored = i + 1;
    r->status.passages_ok = i;
    r->status.queue_depth = i % 3;
    r->status.messages_refused = 2 * i;
    r->status.datagrams_dropped = i / 2;
    r->status.passages_held = i % 4;
    r->status.state = "running";
    r->status.site_id = "selftest-site";
    r->status.last_error = i % 5 == 4 ? "AMFI_VEHICLE: lane 7 not in the site configuration" : "";

    /* A frosty morning warming by 0.1 °C a round, the deck lagging. */
    r->environment.utime = t;
    r->environment.air_c = -4.25 + 0.1 * i;
    r->environment.deck_c = -1.5 + 0.05 * i;
}

/* ---- canonical text (--expect and test_spy.sh) ---- */

static void put_d(const char *name, double v, const char *sep)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    printf("%s=0x%016" PRIx64 "%s", name, bits, sep);
}

static void put_da(const char *name, const double *v, int n, const char *sep)
{
    printf("%s=[", name);
    for (int k = 0; k < n; k++) {
        uint64_t bits;
        memcpy(&bits, &v[k], sizeof bits);
        printf("%s0x%016" PRIx64, k ? "," : "", bits);
    }
    printf("]%s", sep);
}

static void put_i16a(const char *name, const int16_t *v, int n, const char *sep)
{
    printf("%s=[", name);
    for (int k = 0; k < n; k++)
        printf("%s%d", k ? "," : "", v[k]);
    printf("]%s", sep);
}

static void put_i(const char *name, long long v, const char *sep)
{
    printf("%s=%lld%s", name, v, sep);
}

static void put_s(const char *name, const char *v, const char *sep)
{
    printf("%s=%s%s", name, v, sep);
}

static void print_round(const struct round *r)
{
    const amfi_accel_block_t *a = &r->accel;
    printf("%s\tamfi.accel_block_t\t", AMFI_CHANNEL_ACCEL);
    put_i("utime", a->utime, ";");
    put_i("sensor_id", a->sensor_id, ";");
    put_i("seq", a->seq, ";");
    put_d("sample_rate_hz", a->sample_rate_hz, ";");
    put_i("n", a->n, ";");
    put_da("accel", a->accel, a->n, "\n");

    const amfi_vehicle_t *v = &r->vehicle;
    printf("%s\tamfi.vehicle_t\t", AMFI_CHANNEL_VEHICLE);
    put_i("utime", v->utime, ";");
    put_i("vehicle_id", v->vehicle_id, ";");
    put_i("lane", v->lane, ";");
    put_d("speed_mps", v->speed_mps, ";");
    put_i("n_axles", v->n_axles, ";");
    put_i("n_spacings", v->n_spacings, ";");
    put_da("axle_spacing_m", v->axle_spacing_m, v->n_spacings, ";");
    put_s("source", v->source, ";");
    put_d("reference_gvw_kg", v->reference_gvw_kg, "\n");

    const amfi_truth_t *t = &r->truth;
    printf("%s\tamfi.truth_t\t", AMFI_CHANNEL_TRUTH);
    put_i("utime", t->utime, ";");
    put_i("vehicle_id", t->vehicle_id, ";");
    put_d("gvw_kg", t->gvw_kg, ";");
    put_i("n_axles", t->n_axles, ";");
    put_da("axle_kg", t->axle_kg, t->n_axles, ";");
    put_da("mean_force_N", t->mean_force_N, t->n_axles, ";");
    put_d("speed_true_mps", t->speed_true_mps, "\n");

    const amfi_passage_t *p = &r->passage;
    printf("%s\tamfi.passage_t\t", AMFI_CHANNEL_PASSAGE);
    put_i("utime", p->utime, ";");
    put_i("passage_id", p->passage_id, ";");
    put_i("vehicle_id", p->vehicle_id, ";");
    put_i("lane", p->lane, ";");
    put_d("speed_mps", p->speed_mps, ";");
    put_s("status", p->status, ";");
    put_s("reason", p->reason, ";");
    put_d("gvw_kg", p->gvw_kg, ";");
    put_i("n_axles", p->n_axles, ";");
    put_da("axle_kg", p->axle_kg, p->n_axles, ";");
    put_d("lambda", p->lambda, ";");
    put_d("residual_rms", p->residual_rms, ";");
    put_s("formulation", p->formulation, ";");
    put_d("solve_ms", p->solve_ms, ";");
    put_s("site_id", p->site_id, ";");
    put_d("speed_given_mps", p->speed_given_mps, ";");
    put_i("speed_estimated", p->speed_estimated, ";");
    put_i("n_vehicles", p->n_vehicles, ";");
    put_d("quality", p->quality, ";");
    put_d("reference_gvw_kg", p->reference_gvw_kg, ";");
    put_d("f1_hz", p->f1_hz, ";");
    put_d("f1_comp_hz", p->f1_comp_hz, ";");
    put_s("vehicle_class", p->vehicle_class, ";");
    put_i("n_groups", p->n_groups, ";");
    put_i16a("group_axles", p->group_axles, p->n_groups, ";");
    put_da("group_load_kg", p->group_load_kg, p->n_groups, ";");
    put_i("overload", p->overload, ";");
    put_d("fit_ratio", p->fit_ratio, ";");
    put_s("loads_refused", p->loads_refused, "\n");

    const amfi_indicator_t *d = &r->indicator;
    printf("%s\tamfi.indicator_t\t", AMFI_CHANNEL_INDICATOR);
    put_i("utime", d->utime, ";");
    put_i("indicator_id", d->indicator_id, ";");
    put_i("n", d->n, ";");
    put_d("mean_kg", d->mean_kg, ";");
    put_d("std_kg", d->std_kg, ";");
    put_d("baseline_mean_kg", d->baseline_mean_kg, ";");
    put_d("baseline_std_kg", d->baseline_std_kg, ";");
    put_d("std_ratio", d->std_ratio, ";");
    put_d("p_value", d->p_value, ";");
    put_s("state", d->state, ";");
    put_s("site_id", d->site_id, "\n");

    const amfi_alert_t *l = &r->alert;
    printf("%s\tamfi.alert_t\t", AMFI_CHANNEL_ALERT);
    put_i("utime", l->utime, ";");
    put_i("alert_id", l->alert_id, ";");
    put_s("level", l->level, ";");
    put_s("kind", l->kind, ";");
    put_s("message", l->message, ";");
    put_i("indicator_id", l->indicator_id, ";");
    put_i("raised", l->raised, ";");
    put_s("site_id", l->site_id, "\n");

    const amfi_status_t *s = &r->status;
    printf("%s\tamfi.status_t\t", AMFI_CHANNEL_STATUS);
    put_i("utime", s->utime, ";");
    put_i("wall_utime", s->wall_utime, ";");
    put_i("blocks_received", s->blocks_received, ";");
    put_i("blocks_rejected", s->blocks_rejected, ";");
    put_i("samples_missing", s->samples_missing, ";");
    put_i("vehicles_received", s->vehicles_received, ";");
    put_i("vehicles_rejected", s->vehicles_rejected, ";");
    put_i("passages_stored", s->passages_stored, ";");
    put_i("passages_ok", s->passages_ok, ";");
    put_i("queue_depth", s->queue_depth, ";");
    put_i("messages_refused", s->messages_refused, ";");
    put_i("datagrams_dropped", s->datagrams_dropped, ";");
    put_i("passages_held", s->passages_held, ";");
    put_s("state", s->state, ";");
    put_s("last_error", s->last_error, ";");
    put_s("site_id", s->site_id, "\n");

    const amfi_environment_t *en = &r->environment;
    printf("%s\tamfi.environment_t\t", AMFI_CHANNEL_ENVIRONMENT);
    put_i("utime", en->utime, ";");
    put_d("air_c", en->air_c, ";");
    put_d("deck_c", en->deck_c, "\n");
}

/* ---- publishing ---- */

/* Publish round r (with the unsolved passage too when all is set).
 * Returns the number of failed publishes. */
static int publish_round(lcm_t *lcm, const struct round *r, int all)
{
    int bad = 0;
    bad += PUBLISH(amfi_accel_block_t, lcm, AMFI_CHANNEL_ACCEL, &r->accel) != 0;
    bad += PUBLISH(amfi_vehicle_t, lcm, AMFI_CHANNEL_VEHICLE, &r->vehicle) != 0;
    bad += PUBLISH(amfi_truth_t, lcm, AMFI_CHANNEL_TRUTH, &r->truth) != 0;
    bad += PUBLISH(amfi_passage_t, lcm, AMFI_CHANNEL_PASSAGE, &r->passage) != 0;
    if (all)
        bad += PUBLISH(amfi_passage_t, lcm, AMFI_CHANNEL_PASSAGE, &r->unsolved) != 0;
    bad += PUBLISH(amfi_indicator_t, lcm, AMFI_CHANNEL_INDICATOR, &r->indicator) != 0;
    bad += PUBLISH(amfi_alert_t, lcm, AMFI_CHANNEL_ALERT, &r->alert) != 0;
    bad += PUBLISH(amfi_status_t, lcm, AMFI_CHANNEL_STATUS, &r->status) != 0;
    bad += PUBLISH(amfi_environment_t, lcm, AMFI_CHANNEL_ENVIRONMENT, &r->environment) != 0;
    return bad;
}

static int run_publish(const char *url, int n)
{
    lcm_t *lcm = lcm_create(url);
    if (!lcm) {
        fprintf(stderr, "lcm_selftest: cannot create LCM on %s\n", url ? url : "the default URL");
        return 1;
    }
    struct round *r = malloc(sizeof *r);
    if (!r) {
        lcm_destroy(lcm);
        return 1;
    }
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    int bad = 0;
    for (int i = 0; i < n; i++) {
        round_make(r, i);
        bad += publish_round(lcm, r, 0);
        next.tv_nsec += ROUND_US * 1000;
        if (next.tv_nsec >= 1000000000L) {
            next.tv_nsec -= 1000000000L;
            next.tv_sec++;
        }
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR)
            ;
    }
    free(r);
    lcm_destroy(lcm);
    printf("lcm_selftest: published %d rounds of 7 messages on %s, %d failed\n", n,
           url ? url : "the default URL", bad);
    return bad ? 1 : 0;
}

/* ---- round trip ---- */

static int same_i(const char *ch, const char *f, long long a, long long b)
{
    if (a == b)
        return 0;
    fprintf(stderr, "FAIL %s.%s: sent %lld, received %lld\n", ch, f, a, b);
    return 1;
}

/* Bit for bit, so that NaN (an unsolved passage) round-trips too. */
static int same_d(const char *ch, const char *f, double a, double b)
{
    if (memcmp(&a, &b, sizeof a) == 0)
        return 0;
    fprintf(stderr, "FAIL %s.%s: sent %.17g, received %.17g\n", ch, f, a, b);
    return 1;
}

static int same_da(const char *ch, const char *f, const double *a, const double *b, int n)
{
    for (int k = 0; k < n; k++)
        if (memcmp(&a[k], &b[k], sizeof a[k]) != 0) {
            fprintf(stderr, "FAIL %s.%s[%d]: sent %.17g, received %.17g\n", ch, f, k, a[k], b[k]);
            return 1;
        }
    return 0;
}

static int same_s(const char *ch, const char *f, const char *a, const char *b)
{
    if (a && b && strcmp(a, b) == 0)
        return 0;
    fprintf(stderr, "FAIL %s.%s: sent \"%s\", received \"%s\"\n", ch, f, a ? a : "(null)",
            b ? b : "(null)");
    return 1;
}

static int same_accel(const char *c, const amfi_accel_block_t *a, const amfi_accel_block_t *b)
{
    int e = same_i(c, "utime", a->utime, b->utime) + same_i(c, "sensor_id", a->sensor_id, b->sensor_id) +
            same_i(c, "seq", a->seq, b->seq) +
            same_d(c, "sample_rate_hz", a->sample_rate_hz, b->sample_rate_hz) +
            same_i(c, "n", a->n, b->n);
    return e ? e : same_da(c, "accel", a->accel, b->accel, a->n);
}

static int same_vehicle(const char *c, const amfi_vehicle_t *a, const amfi_vehicle_t *b)
{
    int e = same_i(c, "utime", a->utime, b->utime) +
            same_i(c, "vehicle_id", a->vehicle_id, b->vehicle_id) +
            same_i(c, "lane", a->lane, b->lane) + same_d(c, "speed_mps", a->speed_mps, b->speed_mps) +
            same_i(c, "n_axles", a->n_axles, b->n_axles) +
            same_i(c, "n_spacings", a->n_spacings, b->n_spacings) +
            same_s(c, "source", a->source, b->source) +
            same_d(c, "reference_gvw_kg", a->reference_gvw_kg, b->reference_gvw_kg);
    return e ? e : same_da(c, "axle_spacing_m", a->axle_spacing_m, b->axle_spacing_m, a->n_spacings);
}

static int same_truth(const char *c, const amfi_truth_t *a, const amfi_truth_t *b)
{
    int e = same_i(c, "utime", a->utime, b->utime) +
            same_i(c, "vehicle_id", a->vehicle_id, b->vehicle_id) +
            same_d(c, "gvw_kg", a->gvw_kg, b->gvw_kg) + same_i(c, "n_axles", a->n_axles, b->n_axles) +
            same_d(c, "speed_true_mps", a->speed_true_mps, b->speed_true_mps);
    return e ? e
             : same_da(c, "axle_kg", a->axle_kg, b->axle_kg, a->n_axles) +
                   same_da(c, "mean_force_N", a->mean_force_N, b->mean_force_N, a->n_axles);
}

static int same_passage(const char *c, const amfi_passage_t *a, const amfi_passage_t *b)
{
    int e = same_i(c, "utime", a->utime, b->utime) +
            same_i(c, "passage_id", a->passage_id, b->passage_id) +
            same_i(c, "vehicle_id", a->vehicle_id, b->vehicle_id) +
            same_i(c, "lane", a->lane, b->lane) + same_d(c, "speed_mps", a->speed_mps, b->speed_mps) +
            same_s(c, "status", a->status, b->status) + same_s(c, "reason", a->reason, b->reason) +
            same_d(c, "gvw_kg", a->gvw_kg, b->gvw_kg) + same_i(c, "n_axles", a->n_axles, b->n_axles) +
            same_d(c, "lambda", a->lambda, b->lambda) +
            same_d(c, "residual_rms", a->residual_rms, b->residual_rms) +
            same_s(c, "formulation", a->formulation, b->formulation) +
            same_d(c, "solve_ms", a->solve_ms, b->solve_ms) +
            same_d(c, "reference_gvw_kg", a->reference_gvw_kg, b->reference_gvw_kg) +
            same_s(c, "vehicle_class", a->vehicle_class, b->vehicle_class) +
            same_i(c, "n_groups", a->n_groups, b->n_groups) +
            same_i(c, "overload", a->overload, b->overload) +
            same_d(c, "fit_ratio", a->fit_ratio, b->fit_ratio) +
            same_s(c, "loads_refused", a->loads_refused, b->loads_refused);
    for (int k = 0; !e && k < a->n_groups; k++)
        e += same_i(c, "group_axles", a->group_axles[k], b->group_axles[k]);
    if (!e && a->n_groups)
        e += same_da(c, "group_load_kg", a->group_load_kg, b->group_load_kg, a->n_groups);
    return e ? e : same_da(c, "axle_kg", a->axle_kg, b->axle_kg, a->n_axles);
}

static int same_indicator(const char *c, const amfi_indicator_t *a, const amfi_indicator_t *b)
{
    return same_i(c, "utime", a->utime, b->utime) +
           same_i(c, "indicator_id", a->indicator_id, b->indicator_id) + same_i(c, "n", a->n, b->n) +
           same_d(c, "mean_kg", a->mean_kg, b->mean_kg) + same_d(c, "std_kg", a->std_kg, b->std_kg) +
           same_d(c, "baseline_mean_kg", a->baseline_mean_kg, b->baseline_mean_kg) +
           same_d(c, "baseline_std_kg", a->baseline_std_kg, b->baseline_std_kg) +
           same_d(c, "std_ratio", a->std_ratio, b->std_ratio) +
           same_d(c, "p_value", a->p_value, b->p_value) + same_s(c, "state", a->state, b->state);
}

static int same_alert(const char *c, const amfi_alert_t *a, const amfi_alert_t *b)
{
    return same_i(c, "utime", a->utime, b->utime) + same_i(c, "alert_id", a->alert_id, b->alert_id) +
           same_s(c, "level", a->level, b->level) + same_s(c, "kind", a->kind, b->kind) +
           same_s(c, "message", a->message, b->message) +
           same_i(c, "indicator_id", a->indicator_id, b->indicator_id) +
           same_i(c, "raised", a->raised, b->raised);
}

static int same_status(const char *c, const amfi_status_t *a, const amfi_status_t *b)
{
    return same_i(c, "utime", a->utime, b->utime) +
           same_i(c, "wall_utime", a->wall_utime, b->wall_utime) +
           same_i(c, "blocks_received", a->blocks_received, b->blocks_received) +
           same_i(c, "blocks_rejected", a->blocks_rejected, b->blocks_rejected) +
           same_i(c, "samples_missing", a->samples_missing, b->samples_missing) +
           same_i(c, "vehicles_received", a->vehicles_received, b->vehicles_received) +
           same_i(c, "vehicles_rejected", a->vehicles_rejected, b->vehicles_rejected) +
           same_i(c, "passages_stored", a->passages_stored, b->passages_stored) +
           same_i(c, "passages_ok", a->passages_ok, b->passages_ok) +
           same_i(c, "queue_depth", a->queue_depth, b->queue_depth) +
           same_i(c, "messages_refused", a->messages_refused, b->messages_refused) +
           same_i(c, "datagrams_dropped", a->datagrams_dropped, b->datagrams_dropped) +
           same_i(c, "passages_held", a->passages_held, b->passages_held) +
           same_s(c, "state", a->state, b->state) +
           same_s(c, "last_error", a->last_error, b->last_error);
}

static int same_environment(const char *c, const amfi_environment_t *a,
                            const amfi_environment_t *b)
{
    return same_i(c, "utime", a->utime, b->utime) + same_d(c, "air_c", a->air_c, b->air_c) +
           same_d(c, "deck_c", a->deck_c, b->deck_c);
}

/* What the receiver of one round has seen. */
enum { K_ACCEL, K_VEHICLE, K_TRUTH, K_PASSAGE, K_UNSOLVED, K_INDICATOR, K_ALERT, K_STATUS, K_ENVIRONMENT,
       K_N };

struct rx {
    const struct round *want; /* the round being received */
    int seen[K_N];            /* messages per kind this round, decoded */
    int round_msgs;           /* messages this round, any channel */
    int failures;             /* mismatches, decode errors, strays */
};

/* Decode as type T (decode/cleanup/compare functions, expected value);
 * cleanup runs on the zeroed struct whether or not decode succeeded. */
#define DECODE_CHECK(T, same, want, kind)                                                          \
    do {                                                                                           \
        T got;                                                                                     \
        memset(&got, 0, sizeof got);                                                               \
        int used = T##_decode(rbuf->data, 0, (int)rbuf->data_size, &got);                          \
        if (used != (int)rbuf->data_size) {                                                        \
            fprintf(stderr, "FAIL %s: " #T "_decode returned %d for %u bytes\n", channel, used,    \
                    rbuf->data_size);                                                              \
            rx->failures++;                                                                        \
        } else {                                                                                   \
            rx->failures += same(channel, (want), &got) != 0;                                      \
            rx->seen[kind]++;                                                                      \
        }                                                                                          \
        T##_decode_cleanup(&got);                                                                  \
    } while (0)

static void on_amfi(const lcm_recv_buf_t *signed_buf, const char *channel, void *user)
{
    struct rx *rx = user;
    const struct round *w = rx->want;
    rx->round_msgs++;
    size_t bare = 0;
    char why[256];
    if (amfi_auth_verify(&verifier, channel, signed_buf->data, signed_buf->data_size,
                         signed_buf->recv_utime, &bare, why, sizeof why) != AMFI_AUTH_OK) {
        fprintf(stderr, "FAIL %s: %s\n", channel, why);
        rx->failures++;
        return;
    }
    lcm_recv_buf_t stripped = *signed_buf;
    stripped.data_size = (uint32_t)bare;
    const lcm_recv_buf_t *rbuf = &stripped;
    if (strcmp(channel, AMFI_CHANNEL_ACCEL) == 0) {
        DECODE_CHECK(amfi_accel_block_t, same_accel, &w->accel, K_ACCEL);
    } else if (strcmp(channel, AMFI_CHANNEL_VEHICLE) == 0) {
        DECODE_CHECK(amfi_vehicle_t, same_vehicle, &w->vehicle, K_VEHICLE);
    } else if (strcmp(channel, AMFI_CHANNEL_TRUTH) == 0) {
        DECODE_CHECK(amfi_truth_t, same_truth, &w->truth, K_TRUTH);
    } else if (strcmp(channel, AMFI_CHANNEL_PASSAGE) == 0) {
        /* Solved first, then the unsolved one: publish order. */
        if (rx->seen[K_PASSAGE] == 0)
            DECODE_CHECK(amfi_passage_t, same_passage, &w->passage, K_PASSAGE);
        else
            DECODE_CHECK(amfi_passage_t, same_passage, &w->unsolved, K_UNSOLVED);
    } else if (strcmp(channel, AMFI_CHANNEL_INDICATOR) == 0) {
        DECODE_CHECK(amfi_indicator_t, same_indicator, &w->indicator, K_INDICATOR);
    } else if (strcmp(channel, AMFI_CHANNEL_ALERT) == 0) {
        DECODE_CHECK(amfi_alert_t, same_alert, &w->alert, K_ALERT);
    } else if (strcmp(channel, AMFI_CHANNEL_STATUS) == 0) {
        DECODE_CHECK(amfi_status_t, same_status, &w->status, K_STATUS);
    } else if (strcmp(channel, AMFI_CHANNEL_ENVIRONMENT) == 0) {
        DECODE_CHECK(amfi_environment_t, same_environment, &w->environment, K_ENVIRONMENT);
    } else {
        fprintf(stderr, "FAIL: message on unexpected channel %s\n", channel);
        rx->failures++;
    }
}

/* Decoding must refuse another type's bytes and a short buffer. */
static int check_refusals(const struct round *r)
{
    int fails = 0;
    int size = amfi_vehicle_t_encoded_size(&r->vehicle);
    unsigned char *buf = malloc((size_t)size);
    if (!buf)
        return 1;
    int used = amfi_vehicle_t_encode(buf, 0, size, &r->vehicle);
    if (used != size) {
        fprintf(stderr, "FAIL: amfi_vehicle_t_encode wrote %d bytes, encoded_size said %d\n", used, size);
        fails++;
    }
    amfi_truth_t truth;
    memset(&truth, 0, sizeof truth);
    if (amfi_truth_t_decode(buf, 0, size, &truth) >= 0) {
        fprintf(stderr, "FAIL: a vehicle_t decoded as truth_t (fingerprint not checked)\n");
        fails++;
    }
    amfi_truth_t_decode_cleanup(&truth);
    for (int cut = 1; cut <= size - 8; cut += 7) {
        amfi_vehicle_t v;
        memset(&v, 0, sizeof v);
        if (amfi_vehicle_t_decode(buf, 0, size - cut, &v) >= 0) {
            fprintf(stderr, "FAIL: vehicle_t decoded from %d of its %d bytes\n", size - cut, size);
            fails++;
        }
        amfi_vehicle_t_decode_cleanup(&v);
    }
    free(buf);
    return fails;
}

static int run_roundtrip(const char *url, int rounds)
{
    struct round *r = malloc(sizeof *r);
    lcm_t *lcm = lcm_create(url);
    if (!lcm || !r) {
        fprintf(stderr, "lcm_selftest: cannot create LCM on %s\n", url ? url : "the default URL");
        free(r);
        if (lcm)
            lcm_destroy(lcm);
        return 1;
    }
    struct rx rx;
    memset(&rx, 0, sizeof rx);
    rx.want = r;
    lcm_subscription_t *sub = lcm_subscribe(lcm, AMFI_CHANNEL_ALL, on_amfi, &rx);
    int fails = sub ? 0 : 1;

    for (int i = 0; i < rounds && sub; i++) {
        round_make(r, i);
        memset(rx.seen, 0, sizeof rx.seen);
        rx.round_msgs = 0;
        if (publish_round(lcm, r, 1) != 0) {
            fprintf(stderr, "FAIL: round %d: a publish failed\n", i);
            fails++;
            break;
        }
        /* Not an amfi channel: the subscription must not see it. */
        lcm_publish(lcm, "NOT_AMFI", "x", 1);
        while (rx.round_msgs < K_N && lcm_handle_timeout(lcm, 2000) > 0)
            ;
        for (int k = 0; k < K_N; k++)
            if (rx.seen[k] != 1) {
                fprintf(stderr, "FAIL: round %d: message kind %d received %d times\n", i, k, rx.seen[k]);
                fails++;
            }
        if (fails || rx.failures)
            break;
    }
    /* Drain anything left over (a stray would show up here). */
    while (sub && lcm_handle_timeout(lcm, 50) > 0)
        ;
    fails += rx.failures;
    fails += check_refusals(r);
    if (sub)
        lcm_unsubscribe(lcm, sub);
    lcm_destroy(lcm);
    free(r);
    if (fails) {
        fprintf(stderr, "messages_roundtrip: %d failures on %s\n", fails, url);
        return 1;
    }
    printf("messages_roundtrip: %d rounds x 9 messages (8 types) on %s: signed, verified, every "
           "field equal; "
           "wrong type and short buffers refused\n", rounds, url);
    return 0;
}

static int parse_count(const char *s, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < 0 || v > 1000000)
        return -1;
    *out = (int)v;
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: lcm_selftest URL [N]            publish N rounds at 10 Hz (URL \"\": default)\n"
               "       lcm_selftest --roundtrip [URL [N]] publish and check every field (memq://)\n"
               "       lcm_selftest --expect I           print round I as text\n"
               "  -r, --roundtrip    publish and receive in this process, check every field\n"
               "  -e, --expect I     print round I's messages as text\n"
               "  -h, --help         this help\n"
               "  -V, --version      print the version\n");
}

int main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"roundtrip", no_argument, NULL, 'r'},
        {"expect", required_argument, NULL, 'e'},
        AMFI_CLI_END};
    int roundtrip = 0, expect = -1;
    amfi_cli c;
    amfi_cli_init(&c, "lcm_selftest", argc, argv, longopts, usage);
    amfi_cli_allow_operands(&c);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        if (k == 'r')
            roundtrip = 1;
        else if (k == 'e' && parse_count(optarg, &expect) != 0)
            amfi_cli_fail(&c, "'%s' is not a round number", amfi_cli_shown(optarg));
    }
    const int nargs = argc - optind;
    char **args = argv + optind;
    if (auth_init())
        return 1;
    if (expect >= 0) {
        if (nargs != 0 || roundtrip) {
            usage(stderr);
            return 2;
        }
        struct round *r = malloc(sizeof *r);
        if (!r)
            return 1;
        round_make(r, expect);
        print_round(r);
        free(r);
        return 0;
    }
    if (roundtrip) {
        const char *url = nargs > 0 ? args[0] : "memq://";
        int n = 20;
        if (nargs > 2 || (nargs == 2 && (parse_count(args[1], &n) != 0 || n < 1))) {
            usage(stderr);
            return 2;
        }
        return run_roundtrip(url, n);
    }
    if (nargs < 1) {
        usage(stderr);
        return 2;
    }
    const char *url = args[0][0] == 0 || strcmp(args[0], "-") == 0 ? NULL : args[0];
    int n = 30;
    if (nargs > 2 || (nargs == 2 && parse_count(args[1], &n) != 0)) {
        usage(stderr);
        return 2;
    }
    return run_publish(url, n);
}
