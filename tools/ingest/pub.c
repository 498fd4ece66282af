/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pub.c: amfi-ingest's publisher (ingest.h). Samples of each sensor are
 * collected into accel blocks of ingest.block samples; a block's utime is
 * the data time of its first sample, taken from the header of the record
 * (or line) that sample came in, so the published time never drifts from
 * the instrument's. A gap (the next record starts later than the next
 * sample was due, by more than half a sample) ends the block: the next one
 * starts at the record's own time, and no sample is invented. Samples at
 * times already published (an overlap) are dropped and counted. A jump of
 * more than ingest.max_jump_s, forward or back, is counted and reported;
 * the data are published at their time (amfid's rings decide what a far
 * jump means, docs/daemon.md "Time that jumps"). Every message is signed.
 *
 * Thread: amfi-ingest's main thread only.
 */
#include "ingest.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_accel_block_t.h"
#include "amfi_time.h"

#define MAX_UTIME 253402300799000000.0 /* 9999-12-31T23:59:59Z, as amfid's store */

static const char *note_name[NOTE_NKINDS] = {"bad record", "bad line", "unmapped channel",
                                             "gap", "overlap", "time jump", "time back",
                                             "wall clock"};

int ingest_init(ingest *g, const amfi_site_config *cfg, lcm_t *lcm, amfi_auth_signer *signer)
{
    memset(g, 0, sizeof *g);
    g->cfg = cfg;
    g->lcm = lcm;
    g->signer = signer;
    g->n_streams = cfg->solver.n_sensors;
    for (int i = 0; i < g->n_streams; i++) {
        g->st[i].sensor_id = cfg->sensor_id[i];
        g->st[i].rate_hz = cfg->sensor_rate_hz[i];
    }
    return 0;
}

void ingest_free(ingest *g)
{
    free(g->ebuf);
    free(g->sbuf);
    g->ebuf = g->sbuf = NULL;
}

int ingest_sensor_index(const ingest *g, int sensor_id)
{
    for (int i = 0; i < g->n_streams; i++)
        if (g->st[i].sensor_id == sensor_id)
            return i;
    return -1;
}

void ingest_note(ingest *g, int k, const char *where, const char *field, const char *fmt, ...)
{
    g->notes[k]++;
    if (g->notes[k] > INGEST_NOTES)
        return;
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fprintf(stderr, "amfi-ingest: %s: %s%s%s%s\n", where, field ? field : "", field ? ": " : "",
            msg, g->notes[k] == INGEST_NOTES ? " (further ones of this kind counted only)" : "");
}

/* Encode, sign and publish one message. */
static int publish(ingest *g, const char *channel, int len,
                   int (*enc)(void *buf, int off, int max, const void *m), const void *m)
{
    if ((size_t)len + AMFI_AUTH_TRAILER_BYTES > g->ecap) {
        size_t cap = (size_t)len + AMFI_AUTH_TRAILER_BYTES;
        unsigned char *e = realloc(g->ebuf, cap), *s = e ? realloc(g->sbuf, cap) : NULL;
        if (e)
            g->ebuf = e;
        if (!e || !s) {
            g->publish_failed++;
            return -1;
        }
        g->sbuf = s;
        g->ecap = g->scap = cap;
    }
    if (enc(g->ebuf, 0, len, m) != len) {
        g->publish_failed++;
        return -1;
    }
    const unsigned char *out = g->ebuf;
    long n = len;
    if (g->signer) {
        n = amfi_auth_sign_into(g->signer, channel, g->ebuf, (size_t)len, 0, g->sbuf, g->scap);
        out = g->sbuf;
    }
    if (n < 0 || lcm_publish(g->lcm, channel, out, (unsigned)n) != 0) {
        g->publish_failed++;
        if (g->publish_failed <= INGEST_NOTES)
            fprintf(stderr, "amfi-ingest: %s: publishing failed\n", channel);
        return -1;
    }
    return 0;
}

static int enc_accel(void *buf, int off, int max, const void *m)
{
    return amfi_accel_block_t_encode(buf, off, max, m);
}

static int enc_vehicle(void *buf, int off, int max, const void *m)
{
    return amfi_vehicle_t_encode(buf, off, max, m);
}

static void publish_block(ingest *g, ingest_stream *s)
{
    if (s->n == 0)
        return;
    amfi_accel_block_t m = {(int64_t)llround(s->t0_us), s->sensor_id, s->seq++, s->rate_hz,
                            (int16_t)s->n, s->buf};
    if (publish(g, g->cfg->daemon.ch_accel, amfi_accel_block_t_encoded_size(&m), enc_accel,
                &m) == 0) {
        g->blocks++;
        g->samples += s->n;
    }
    s->n = 0;
}

void ingest_flush(ingest *g, double idle_s)
{
    const double now = amfi_mono_s();
    for (int i = 0; i < g->n_streams; i++)
        if (idle_s <= 0 || now - g->st[i].last_wall >= idle_s)
            publish_block(g, &g->st[i]);
}

static double wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec / 1e3;
}

int ingest_samples(ingest *g, int idx, double start_us, double rate_hz, int n, const double *v,
                   const char *where, int bad)
{
    ingest_stream *s = &g->st[idx];
    const double P = 1e6 / s->rate_hz, jump_us = 1e6 * g->cfg->ingest.max_jump_s;
    if (!(fabs(rate_hz - s->rate_hz) <= 1e-6 * s->rate_hz)) {
        ingest_note(g, bad, where, "sample rate",
                    "%.6g Hz differs from sensors[%d].rate_hz (%.6g Hz) of sensor %d: refused",
                    rate_hz, idx, s->rate_hz, s->sensor_id);
        return -1;
    }
    if (!(start_us > 0 && start_us + n * P <= MAX_UTIME)) {
        ingest_note(g, bad, where, "time", "%.0f µs is not a time amfid can store: refused",
                    start_us);
        return -1;
    }
    for (int k = 0; k < n; k++)
        if (!isfinite(v[k]) || fabs(v[k]) > 1000.0) {
            ingest_note(g, bad, where, "samples",
                        "sample %d is %g m/s² (not finite or beyond 1000 m/s²): record refused",
                        k + 1, v[k]);
            return -1;
        }
    if (g->live && fabs(start_us - wall_us()) > jump_us)
        ingest_note(g, NOTE_WALL, where, "time",
                    "data time %.3f s from the wall clock (ingest.max_jump_s %g): is the "
                    "logger's clock on GPS/NTP?",
                    1e-6 * (start_us - wall_us()), g->cfg->ingest.max_jump_s);
    int k0 = 0;
    if (s->have) {
        const double d = start_us - s->next_us;
        if (d > 0.5 * P) { /* later than due: a gap, or a jump */
            if (d > jump_us)
                ingest_note(g, NOTE_JUMP, where, "time",
                            "sensor %d: the data's time jumped forward by %.3f s "
                            "(ingest.max_jump_s %g): published at its time",
                            s->sensor_id, 1e-6 * d, g->cfg->ingest.max_jump_s);
            else {
                const long long missing = llround(d / P);
                g->notes[NOTE_GAP]++;
                g->gap_samples += missing;
                if (g->notes[NOTE_GAP] <= INGEST_NOTES)
                    fprintf(stderr,
                            "amfi-ingest: %s: sensor %d: gap of %.6f s (%lld samples) before "
                            "this record: a new block starts at its time\n",
                            where, s->sensor_id, 1e-6 * d, missing);
            }
            publish_block(g, s);
        } else if (d < -0.5 * P) { /* earlier than due: an overlap, or the clock went back */
            if (-d > jump_us) {
                ingest_note(g, NOTE_BACK, where, "time",
                            "sensor %d: the data's time went back by %.3f s "
                            "(ingest.max_jump_s %g): published at its time",
                            s->sensor_id, -1e-6 * d, g->cfg->ingest.max_jump_s);
                publish_block(g, s);
            } else {
                /* sample k is at start + k·P; keep those due at or after next */
                k0 = (int)ceil(-d / P - 0.5);
                if (k0 > n)
                    k0 = n;
                g->notes[NOTE_OVERLAP]++;
                g->overlap_samples += k0;
                if (g->notes[NOTE_OVERLAP] <= INGEST_NOTES)
                    fprintf(stderr,
                            "amfi-ingest: %s: sensor %d: overlap: %d of %d samples at times "
                            "already published dropped\n",
                            where, s->sensor_id, k0, n);
                if (k0 == n)
                    return 0; /* nothing new; the stream's time stays */
            }
        }
    }
    const int block = g->cfg->ingest.block;
    for (int k = k0; k < n; k++) {
        if (s->n == 0)
            s->t0_us = start_us + k * P;
        s->buf[s->n++] = v[k];
        if (s->n == block)
            publish_block(g, s);
    }
    s->have = 1;
    s->next_us = start_us + n * P;
    s->last_wall = amfi_mono_s();
    return 0;
}

int ingest_vehicle(ingest *g, const amfi_vehicle_t *m, const char *where)
{
    const double jump_us = 1e6 * g->cfg->ingest.max_jump_s;
    if (g->last_vehicle_us && (double)(g->last_vehicle_us - m->utime) > jump_us)
        ingest_note(g, NOTE_BACK, where, "utime_us",
                    "the detector's time went back by %.3f s (ingest.max_jump_s %g): "
                    "published at its time",
                    1e-6 * (double)(g->last_vehicle_us - m->utime), g->cfg->ingest.max_jump_s);
    if (g->live && fabs((double)m->utime - wall_us()) > jump_us)
        ingest_note(g, NOTE_WALL, where, "utime_us",
                    "data time %.3f s from the wall clock (ingest.max_jump_s %g): is the "
                    "detector's clock on GPS/NTP?",
                    1e-6 * ((double)m->utime - wall_us()), g->cfg->ingest.max_jump_s);
    g->last_vehicle_us = m->utime;
    if (publish(g, g->cfg->daemon.ch_vehicle, amfi_vehicle_t_encoded_size(m), enc_vehicle, m))
        return -1;
    g->vehicles++;
    return 0;
}

void ingest_summary(const ingest *g, FILE *f)
{
    fprintf(f,
            "amfi-ingest: %lld records, %lld lines; published %lld accel blocks (%lld samples) "
            "and %lld vehicles%s\n",
            g->records, g->lines, g->blocks, g->samples, g->vehicles,
            g->signer ? ", signed" : ", UNSIGNED");
    fprintf(f,
            "amfi-ingest: %s %lld, %s %lld, %s %lld, %s %lld (%lld samples missing), "
            "%s %lld (%lld samples dropped), %s %lld, %s %lld, %s %lld, publish failed %lld\n",
            note_name[BAD_RECORD], g->notes[BAD_RECORD], note_name[BAD_LINE], g->notes[BAD_LINE],
            note_name[NOTE_UNMAPPED], g->notes[NOTE_UNMAPPED], note_name[NOTE_GAP],
            g->notes[NOTE_GAP], g->gap_samples, note_name[NOTE_OVERLAP], g->notes[NOTE_OVERLAP],
            g->overlap_samples, note_name[NOTE_JUMP], g->notes[NOTE_JUMP], note_name[NOTE_BACK],
            g->notes[NOTE_BACK], note_name[NOTE_WALL], g->notes[NOTE_WALL], g->publish_failed);
}
