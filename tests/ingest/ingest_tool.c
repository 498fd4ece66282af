/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ingest_tool: the ingest tests' helper (the tests of tests/ingest/).
 *
 *   ingest_tool gen DIR
 *       synthetic MiniSEED with libmseed: channel XX.BRG.00.HNZ (sensor 3)
 *       Steim-1 in a1.mseed then Steim-2 after a 0.25 s gap in a2.mseed,
 *       with one record's data corrupted (Steim integrity) and one record
 *       of a channel not configured; XX.BRG.00.HNN (sensor 5) int32 in
 *       b.mseed with a record repeated (overlap), a record whose header is
 *       destroyed, and a last record (int16) that overlaps by 30 samples;
 *       XX.BRG.00.HNE (sensor 7) float32 in c1.mseed, float64 in c2.mseed
 *       (its last record at 500 Hz, not the sensor's rate); huge.mseed: one
 *       float64 record whose header claims 60000 samples.
 *       Sample k of sensor s: round(1000 sin(2π k / 50 + s)) counts at
 *       T0 + k ms. DIR/expect.txt: "SENSOR INTERVALS" of the samples that
 *       must arrive (the corrupted records' missing).
 *   ingest_tool verify LOG KEY T0_US [SENSOR=OFFSET_US]...
 *       every message of the LCM log LOG verified with the key (signature,
 *       producer order), decoded and checked: accel values against the
 *       formula above (gain 1e-3), n <= 160, seq +1 per block and sensor;
 *       prints "sensor S blocks B samples N intervals A-B,C-D" per sensor
 *       and each vehicle as "V utime id lane speed n_axles spacings source".
 *   ingest_tool from-log SIMLOG DIR
 *       sim_publisher's log (--log) as a data logger and a detector would
 *       give it: DIR/sSENSOR.mseed (Steim-2, 512-byte records, 1e-6 m/s²
 *       per count, channel XX.BRG.00.HN<sensor>), DIR/vehicles.txt (V lines)
 *       and DIR/truth.csv (vehicle_id,gvw_kg).
 *   ingest_tool cut IN.mseed OUT.mseed UTIME
 *       IN without the 512-byte record that holds data time UTIME.
 *   ingest_tool mutate IN OUT SEED
 *       IN with 1, 5, 50 or 500 bytes changed (by SEED), every fourth
 *       seed also cut short.
 *   ingest_tool send HOST PORT FILE
 *       FILE's bytes to a TCP listener, then close.
 *   ingest_tool pty FILE NAMEFILE GOFILE DONEFILE
 *       a pseudo-terminal: its slave's path into NAMEFILE; once GOFILE
 *       exists FILE is written to the master; once DONEFILE exists the
 *       master is closed (the reader sees the end).
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <libmseed.h>
#include <lcm/eventlog.h>

#include "amfi_accel_block_t.h"
#include "amfi_auth.h"
#include "amfi_truth_t.h"
#include "amfi_vehicle_t.h"

#define T0_US 1767225600000000LL /* 2026-01-01T00:00:00Z */
#define RATE 1000.0

static int32_t counts(int sensor, long k)
{
    return (int32_t)lround(1000.0 * sin(2.0 * M_PI * (double)k / 50.0 + sensor));
}

/* ---- gen ---- */

typedef struct rec {
    char *b;
    int len;
    long k0, n; /* sample range */
} rec;

typedef struct recs {
    rec r[4096];
    int n;
} recs;

static void collect(char *record, int reclen, void *arg)
{
    recs *rs = arg;
    rec *r = &rs->r[rs->n++];
    r->b = malloc((size_t)reclen);
    memcpy(r->b, record, (size_t)reclen);
    r->len = reclen;
}

/* Pack samples k0 .. k0+n-1 of sensor s on channel cha with encoding enc
 * into rs (appended), each record's sample range noted. */
static double pack_rate = RATE; /* the records' sample rate */

static void pack(recs *rs, int s, const char *cha, long k0, long n, int enc, int reclen)
{
    MSRecord *m = msr_init(NULL);
    strcpy(m->network, "XX");
    strcpy(m->station, "BRG");
    strcpy(m->location, "00");
    strcpy(m->channel, cha);
    m->starttime = (hptime_t)(T0_US + k0 * 1000);
    m->samprate = pack_rate;
    m->reclen = reclen;
    m->encoding = (int8_t)enc;
    m->byteorder = 1;
    m->dataquality = 'D';
    int32_t *iv = malloc(sizeof(int32_t) * (size_t)n);
    float *fv = malloc(sizeof(float) * (size_t)n);
    double *dv = malloc(sizeof(double) * (size_t)n);
    for (long k = 0; k < n; k++) {
        iv[k] = counts(s, k0 + k);
        fv[k] = (float)iv[k];
        dv[k] = (double)iv[k];
    }
    m->sampletype = enc == DE_FLOAT32 ? 'f' : enc == DE_FLOAT64 ? 'd' : 'i';
    m->datasamples = enc == DE_FLOAT32 ? (void *)fv : enc == DE_FLOAT64 ? (void *)dv : (void *)iv;
    m->numsamples = n;
    int first = rs->n;
    int64_t packed = 0;
    if (msr_pack(m, collect, rs, &packed, 1, 0) < 0 || packed != n) {
        fprintf(stderr, "ingest_tool: msr_pack failed (%lld of %ld)\n", (long long)packed, n);
        exit(1);
    }
    long k = k0;
    for (int i = first; i < rs->n; i++) { /* each record's range, from the record */
        MSRecord *u = NULL;
        if (msr_unpack(rs->r[i].b, rs->r[i].len, &u, 0, 0) != MS_NOERROR) {
            fprintf(stderr, "ingest_tool: cannot unpack what was packed\n");
            exit(1);
        }
        rs->r[i].k0 = k;
        rs->r[i].n = u->samplecnt;
        k += u->samplecnt;
        msr_free(&u);
    }
    m->datasamples = NULL;
    msr_free(&m);
    free(iv);
    free(fv);
    free(dv);
}

static void write_recs(const char *dir, const char *name, recs *rs)
{
    char p[4096];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    if (!f) {
        perror(p);
        exit(1);
    }
    for (int i = 0; i < rs->n; i++)
        fwrite(rs->r[i].b, 1, (size_t)rs->r[i].len, f);
    fclose(f);
}

/* Intervals of the sample ranges kept (sorted, merged). */
static void intervals(FILE *f, int sensor, long (*iv)[2], int n)
{
    for (int i = 1; i < n; i++) /* insertion sort */
        for (int j = i; j > 0 && iv[j][0] < iv[j - 1][0]; j--) {
            long t0 = iv[j][0], t1 = iv[j][1];
            iv[j][0] = iv[j - 1][0];
            iv[j][1] = iv[j - 1][1];
            iv[j - 1][0] = t0;
            iv[j - 1][1] = t1;
        }
    fprintf(f, "sensor %d intervals ", sensor);
    long a = iv[0][0], b = iv[0][1];
    int first = 1;
    for (int i = 1; i <= n; i++) {
        if (i < n && iv[i][0] <= b + 1) {
            if (iv[i][1] > b)
                b = iv[i][1];
            continue;
        }
        fprintf(f, "%s%ld-%ld", first ? "" : ",", a, b);
        first = 0;
        if (i < n) {
            a = iv[i][0];
            b = iv[i][1];
        }
    }
    fprintf(f, "\n");
}

static int gen(const char *dir)
{
    static recs a1, a2, b, c1, c2, other;
    static long kept[3][4096][2];
    int nk[3] = {0, 0, 0};
    /* sensor 3: Steim-1 0 .. 1999, then Steim-2 2250 .. 3999 (a gap of 250) */
    pack(&a1, 3, "HNZ", 0, 2000, DE_STEIM1, 512);
    pack(&a2, 3, "HNZ", 2250, 1750, DE_STEIM2, 512);
    if (a2.n < 3) {
        fprintf(stderr, "ingest_tool: too few Steim-2 records\n");
        return 1;
    }
    /* one record's data changed: the Steim integrity check fails */
    rec *bad = &a2.r[1];
    for (int i = 100; i < 140; i++)
        bad->b[i] ^= 0x55;
    /* a record of a channel the site does not map, between them */
    pack(&other, 3, "HN1", 2250, 100, DE_STEIM2, 512);
    for (int i = 0; i < a1.n; i++)
        kept[0][nk[0]][0] = a1.r[i].k0, kept[0][nk[0]++][1] = a1.r[i].k0 + a1.r[i].n - 1;
    for (int i = 0; i < a2.n; i++)
        if (i != 1)
            kept[0][nk[0]][0] = a2.r[i].k0, kept[0][nk[0]++][1] = a2.r[i].k0 + a2.r[i].n - 1;
    recs a2o = {.n = 0};
    a2o.r[a2o.n++] = a2.r[0];
    a2o.r[a2o.n++] = other.r[0];
    for (int i = 1; i < a2.n; i++)
        a2o.r[a2o.n++] = a2.r[i];
    write_recs(dir, "a1.mseed", &a1);
    write_recs(dir, "a2.mseed", &a2o);
    /* sensor 5: int32 0 .. 3999; record 5 repeated after record 6; record 8's
     * header destroyed; then 3970 .. 4099 (30 samples overlap) */
    static recs bb;
    pack(&bb, 5, "HNN", 0, 4000, DE_INT32, 512);
    pack(&bb, 5, "HNN", 3970, 130, DE_INT16, 512); /* one record */
    const int last = bb.n - 1;
    if (bb.n < 12) {
        fprintf(stderr, "ingest_tool: too few int32 records\n");
        return 1;
    }
    for (int i = 0; i < bb.n; i++) {
        b.r[b.n++] = bb.r[i];
        if (i == 6)
            b.r[b.n++] = bb.r[5];
        if (i != 8)
            kept[1][nk[1]][0] = bb.r[i].k0, kept[1][nk[1]++][1] = bb.r[i].k0 + bb.r[i].n - 1;
    }
    (void)last;
    memcpy(bb.r[8].b, "ABCDEFGH", 8); /* b.r holds the same buffers */
    write_recs(dir, "b.mseed", &b);
    /* sensor 7: float32 0 .. 1999 then float64 2000 .. 3999 */
    pack(&c1, 7, "HNE", 0, 2000, DE_FLOAT32, 512);
    pack(&c2, 7, "HNE", 2000, 2000, DE_FLOAT64, 512);
    pack_rate = 500.0; /* a record at another rate than the sensor's: refused */
    pack(&c2, 7, "HNE", 4000, 50, DE_FLOAT64, 512);
    pack_rate = RATE;
    kept[2][nk[2]][0] = 0, kept[2][nk[2]++][1] = 3999;
    /* huge.mseed: a float64 record whose header claims 60000 samples (the
     * fixed header's number of samples, bytes 30-31, big-endian) */
    {
        static recs h;
        h.n = 1;
        h.r[0].len = c2.r[0].len;
        h.r[0].b = malloc((size_t)h.r[0].len);
        memcpy(h.r[0].b, c2.r[0].b, (size_t)h.r[0].len);
        h.r[0].b[30] = (char)(60000 >> 8);
        h.r[0].b[31] = (char)(60000 & 255);
        write_recs(dir, "huge.mseed", &h);
    }
    write_recs(dir, "c1.mseed", &c1);
    write_recs(dir, "c2.mseed", &c2);
    char p[4096];
    snprintf(p, sizeof p, "%s/expect.txt", dir);
    FILE *f = fopen(p, "w");
    intervals(f, 3, kept[0], nk[0]);
    intervals(f, 5, kept[1], nk[1]);
    intervals(f, 7, kept[2], nk[2]);
    fprintf(f, "records %d corrupt-data 1 corrupt-header 1 unmapped 1 repeated %ld partial 30\n",
            a1.n + a2o.n + b.n - 1 + c1.n + c2.n, bb.r[5].n);
    fclose(f);
    return 0;
}

/* ---- verify ---- */

static int verify(int argc, char **argv)
{
    const char *logp = argv[0];
    char err[600];
    amfi_auth_key key;
    if (amfi_auth_key_load(argv[1], &key, err, sizeof err)) {
        fprintf(stderr, "ingest_tool: %s\n", err);
        return 1;
    }
    const long long t0 = atoll(argv[2]);
    long long off[256] = {0};
    for (int i = 3; i < argc; i++) {
        int s;
        long long o;
        if (sscanf(argv[i], "%d=%lld", &s, &o) == 2 && s >= 0 && s < 256)
            off[s] = o;
    }
    static amfi_auth_verifier v;
    amfi_auth_verifier_init(&v, &key, 0);
    lcm_eventlog_t *log = lcm_eventlog_create(logp, "r");
    if (!log) {
        fprintf(stderr, "ingest_tool: %s: cannot open\n", logp);
        return 1;
    }
    static long long blocks[256], samples[256], next_seq[256];
    static long (*iv[256])[2];
    static int niv[256], seen[256];
    int rc = 0;
    for (lcm_eventlog_event_t *e; (e = lcm_eventlog_read_next_event(log));
         lcm_eventlog_free_event(e)) {
        size_t bare = 0;
        char why[300];
        if (amfi_auth_verify(&v, e->channel, e->data, (size_t)e->datalen, 0, &bare, why,
                             sizeof why) != AMFI_AUTH_OK) {
            printf("BAD signature on %s: %s\n", e->channel, why);
            rc = 1;
            continue;
        }
        if (strcmp(e->channel, "AMFI_ACCEL") == 0) {
            amfi_accel_block_t m;
            if (amfi_accel_block_t_decode(e->data, 0, (int)bare, &m) < 0) {
                printf("BAD accel decode\n");
                rc = 1;
                continue;
            }
            const int s = m.sensor_id & 255;
            if (m.n < 1 || m.n > 160 || m.sample_rate_hz != RATE) {
                printf("BAD block sensor %d n %d rate %g\n", s, m.n, m.sample_rate_hz);
                rc = 1;
            }
            if (seen[s] && m.seq != next_seq[s]) {
                printf("BAD seq sensor %d: %lld after %lld\n", s, (long long)m.seq,
                       next_seq[s] - 1);
                rc = 1;
            }
            seen[s] = 1;
            next_seq[s] = m.seq + 1;
            const double kf = (double)(m.utime + off[s] - t0) / 1000.0;
            const long k0 = lround(kf);
            if (fabs(kf - (double)k0) > 0.01) {
                printf("BAD time sensor %d utime %lld is not on a sample\n", s, (long long)m.utime);
                rc = 1;
            }
            for (int i = 0; i < m.n; i++)
                if (fabs(m.accel[i] - 1e-3 * counts(s, k0 + i)) > 1e-9) {
                    printf("BAD value sensor %d sample %ld: %.9g, expected %.9g\n", s, k0 + i,
                           m.accel[i], 1e-3 * counts(s, k0 + i));
                    rc = 1;
                    break;
                }
            iv[s] = realloc(iv[s], sizeof *iv[s] * (size_t)(niv[s] + 1));
            iv[s][niv[s]][0] = k0;
            iv[s][niv[s]++][1] = k0 + m.n - 1;
            blocks[s]++;
            samples[s] += m.n;
            amfi_accel_block_t_decode_cleanup(&m);
        } else if (strcmp(e->channel, "AMFI_VEHICLE") == 0) {
            amfi_vehicle_t m;
            if (amfi_vehicle_t_decode(e->data, 0, (int)bare, &m) < 0) {
                printf("BAD vehicle decode\n");
                rc = 1;
                continue;
            }
            printf("V %lld %lld %d %.6g %d", (long long)m.utime, (long long)m.vehicle_id, m.lane,
                   m.speed_mps, m.n_axles);
            for (int a = 0; a < m.n_spacings; a++)
                printf(" %.6g", m.axle_spacing_m[a]);
            printf(" %s %.6g\n", m.source, m.reference_gvw_kg);
            amfi_vehicle_t_decode_cleanup(&m);
        } else {
            printf("BAD channel %s\n", e->channel);
            rc = 1;
        }
    }
    lcm_eventlog_destroy(log);
    for (int s = 0; s < 256; s++) {
        if (!blocks[s])
            continue;
        printf("sensor %d blocks %lld samples %lld\n", s, blocks[s], samples[s]);
        intervals(stdout, s, iv[s], niv[s]);
        /* every sample once: no overlap on the bus */
        long total = 0;
        for (int i = 0; i < niv[s]; i++)
            total += iv[s][i][1] - iv[s][i][0] + 1;
        if (total != samples[s]) {
            printf("BAD sensor %d: overlapping blocks\n", s);
            rc = 1;
        }
        free(iv[s]);
    }
    return rc;
}

/* ---- from-log ---- */

typedef struct trace {
    int sensor;
    long long t0;
    double *v;
    long n, cap;
} trace;

/* records straight to the file (a long trace is many records) */
static void to_file(char *r, int len, void *arg)
{
    fwrite(r, 1, (size_t)len, (FILE *)arg);
}

static void write_trace(const char *dir, const trace *t)
{
    MSRecord *m = msr_init(NULL);
    strcpy(m->network, "XX");
    strcpy(m->station, "BRG");
    strcpy(m->location, "00");
    snprintf(m->channel, sizeof m->channel, "HN%d", t->sensor % 10);
    m->starttime = (hptime_t)t->t0;
    m->samprate = RATE;
    m->reclen = 512;
    m->encoding = DE_STEIM2;
    m->byteorder = 1;
    m->dataquality = 'D';
    int32_t *iv = malloc(sizeof(int32_t) * (size_t)t->n);
    for (long k = 0; k < t->n; k++)
        iv[k] = (int32_t)lround(t->v[k] / 1e-6);
    m->sampletype = 'i';
    m->datasamples = iv;
    m->numsamples = t->n;
    char p[4096];
    snprintf(p, sizeof p, "%s/s%d.mseed", dir, t->sensor);
    FILE *f = fopen(p, "wb");
    int64_t packed = 0;
    if (!f || msr_pack(m, to_file, f, &packed, 1, 0) < 0 || packed != t->n) {
        fprintf(stderr, "ingest_tool: %s: packing failed\n", p);
        exit(1);
    }
    fclose(f);
    m->datasamples = NULL;
    msr_free(&m);
    free(iv);
}

static int from_log(const char *logp, const char *dir)
{
    lcm_eventlog_t *log = lcm_eventlog_create(logp, "r");
    if (!log) {
        fprintf(stderr, "ingest_tool: %s: cannot open\n", logp);
        return 1;
    }
    static trace tr[8];
    int ntr = 0;
    char p[4096];
    snprintf(p, sizeof p, "%s/vehicles.txt", dir);
    FILE *vf = fopen(p, "w");
    snprintf(p, sizeof p, "%s/truth.csv", dir);
    FILE *tf = fopen(p, "w");
    if (!vf || !tf)
        return 1;
    fprintf(vf, "# the detector's records (line protocol, docs/ingest.md)\n");
    fprintf(tf, "vehicle_id,gvw_kg\n");
    for (lcm_eventlog_event_t *e; (e = lcm_eventlog_read_next_event(log));
         lcm_eventlog_free_event(e)) {
        const int len = (int)amfi_auth_bare_len(e->data, (size_t)e->datalen);
        if (strcmp(e->channel, "AMFI_ACCEL") == 0) {
            amfi_accel_block_t m;
            if (amfi_accel_block_t_decode(e->data, 0, len, &m) < 0)
                return 1;
            int t = 0;
            while (t < ntr && tr[t].sensor != m.sensor_id)
                t++;
            if (t == ntr) {
                if (ntr == 8)
                    return 1;
                tr[ntr++] = (trace){.sensor = m.sensor_id, .t0 = m.utime};
            }
            const long k = lround((double)(m.utime - tr[t].t0) * RATE / 1e6);
            if (k != tr[t].n) {
                fprintf(stderr, "ingest_tool: sensor %d: the simulation's blocks are not "
                        "contiguous\n", m.sensor_id);
                return 1;
            }
            if (tr[t].n + m.n > tr[t].cap) {
                tr[t].cap = 2 * (tr[t].n + m.n);
                tr[t].v = realloc(tr[t].v, sizeof(double) * (size_t)tr[t].cap);
            }
            memcpy(tr[t].v + tr[t].n, m.accel, sizeof(double) * (size_t)m.n);
            tr[t].n += m.n;
            amfi_accel_block_t_decode_cleanup(&m);
        } else if (strcmp(e->channel, "AMFI_VEHICLE") == 0) {
            amfi_vehicle_t m;
            if (amfi_vehicle_t_decode(e->data, 0, len, &m) < 0)
                return 1;
            fprintf(vf, "V %lld %.9g %d %d", (long long)m.utime, m.speed_mps, m.lane, m.n_axles);
            for (int a = 0; a < m.n_spacings; a++)
                fprintf(vf, " %.9g", m.axle_spacing_m[a]);
            fprintf(vf, " id=%lld\n", (long long)m.vehicle_id);
            amfi_vehicle_t_decode_cleanup(&m);
        } else if (strcmp(e->channel, "AMFI_TRUTH") == 0) {
            amfi_truth_t m;
            if (amfi_truth_t_decode(e->data, 0, len, &m) < 0)
                return 1;
            fprintf(tf, "%lld,%.3f\n", (long long)m.vehicle_id, m.gvw_kg);
            amfi_truth_t_decode_cleanup(&m);
        }
    }
    lcm_eventlog_destroy(log);
    fclose(vf);
    fclose(tf);
    for (int t = 0; t < ntr; t++) {
        write_trace(dir, &tr[t]);
        fprintf(stderr, "ingest_tool: sensor %d: %ld samples from %lld\n", tr[t].sensor, tr[t].n,
                tr[t].t0);
        free(tr[t].v);
    }
    return ntr ? 0 : 1;
}

/* ---- cut: a record lost ---- */

/* IN without the record (512 bytes each, as from-log writes them) that
 * holds data time UTIME; prints the record's number and sample range. */
static int cut(const char *in, const char *out, long long utime)
{
    FILE *f = fopen(in, "rb"), *o = fopen(out, "wb");
    char r[512];
    int n = 0, cut_at = 0;
    if (!f || !o)
        return 1;
    while (fread(r, 1, sizeof r, f) == sizeof r) {
        n++;
        MSRecord *m = NULL;
        if (msr_unpack(r, (int)sizeof r, &m, 0, 0) != MS_NOERROR)
            return 1;
        const long long t0 = (long long)m->starttime;
        const long long t1 = t0 + (long long)llround((double)m->samplecnt * 1e6 / m->samprate);
        if (!cut_at && utime >= t0 && utime < t1) {
            cut_at = n;
            printf("record %d: %lld .. %lld cut\n", n, t0, t1);
        } else {
            fwrite(r, 1, sizeof r, o);
        }
        msr_free(&m);
    }
    fclose(f);
    fclose(o);
    return cut_at ? 0 : 1;
}

/* ---- mutate: hostile input ---- */

/* IN with bytes changed (a linear congruential generator seeded with SEED:
 * 1, 5, 50 or 500 bytes set to random values, every fourth copy also cut
 * short) into OUT. */
static unsigned long long lcg;
static unsigned rnd(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (unsigned)(lcg >> 33);
}

static int mutate(const char *in, const char *out, unsigned seed)
{
    FILE *f = fopen(in, "rb");
    if (!f)
        return 1;
    static unsigned char b[1 << 22];
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    lcg = 0x9e3779b97f4a7c15ULL ^ seed;
    const int changes[4] = {1, 5, 50, 500};
    for (int i = changes[seed % 4]; i > 0 && n; i--)
        b[rnd() % n] = (unsigned char)rnd();
    if (seed % 4 == 3 && n)
        n = rnd() % n;
    FILE *o = fopen(out, "wb");
    if (!o || fwrite(b, 1, n, o) != n)
        return 1;
    fclose(o);
    return 0;
}

/* ---- send, pty ---- */

static int send_file(const char *host, int port, const char *path)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, host, &sa.sin_addr);
    for (int i = 0; connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0; i++) {
        if (i == 100) {
            perror("ingest_tool: connect");
            return 1;
        }
        usleep(100000);
    }
    FILE *f = fopen(path, "rb");
    char buf[4096];
    size_t n;
    while (f && (n = fread(buf, 1, sizeof buf, f)) > 0)
        if (write(fd, buf, n) != (ssize_t)n)
            return 1;
    if (f)
        fclose(f);
    close(fd);
    return 0;
}

static void wait_file(const char *p)
{
    struct stat sb;
    for (int i = 0; i < 6000 && stat(p, &sb) != 0; i++)
        usleep(50000);
}

static int pty(const char *path, const char *namefile, const char *go, const char *done)
{
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m < 0 || grantpt(m) || unlockpt(m))
        return 1;
    FILE *nf = fopen(namefile, "w");
    fprintf(nf, "%s\n", ptsname(m));
    fclose(nf);
    wait_file(go);
    FILE *f = fopen(path, "rb");
    char buf[256];
    size_t n;
    while (f && (n = fread(buf, 1, sizeof buf, f)) > 0)
        if (write(m, buf, n) != (ssize_t)n)
            return 1;
    if (f)
        fclose(f);
    wait_file(done);
    close(m);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "gen"))
        return gen(argv[2]);
    if (argc >= 5 && !strcmp(argv[1], "verify"))
        return verify(argc - 2, argv + 2);
    if (argc == 4 && !strcmp(argv[1], "from-log"))
        return from_log(argv[2], argv[3]);
    if (argc == 5 && !strcmp(argv[1], "cut"))
        return cut(argv[2], argv[3], atoll(argv[4]));
    if (argc == 5 && !strcmp(argv[1], "mutate"))
        return mutate(argv[2], argv[3], (unsigned)atoi(argv[4]));
    if (argc == 5 && !strcmp(argv[1], "send"))
        return send_file(argv[2], atoi(argv[3]), argv[4]);
    if (argc == 6 && !strcmp(argv[1], "pty"))
        return pty(argv[2], argv[3], argv[4], argv[5]);
    fprintf(stderr, "usage: ingest_tool gen DIR | verify LOG KEY T0_US [S=OFF]... | "
            "from-log SIMLOG DIR | cut IN OUT UTIME | mutate IN OUT SEED | send HOST PORT FILE | pty FILE NAMEFILE GO DONE\n");
    return 2;
}
