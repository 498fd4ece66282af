/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_raw.c: the raw samples of the passages (store.h, "raw samples";
 * schema version 11): the codec of raw_windows.samples, the rows written in
 * a passage's transaction (under a savepoint: a raw row that cannot be
 * written never costs the passage), the read back of one passage's window
 * with every value checked, one stored passage by id, and the retention.
 *
 * The codec is lossless on the float64 values the solver had (or on the
 * samples rounded to float32, daemon.store.raw.precision): each sample's
 * 64-bit (32-bit) pattern XORed with the previous sample's of the same
 * sensor (a slowly varying signal leaves the sign, the exponent and the
 * high mantissa bits zero), the bytes of the result shuffled into eight
 * (four) planes (the zero high bytes of every sample in a run), then zlib
 * (its Adler-32 checks the decoded bytes). docs/results/raw-passages.md has
 * the ratios measured against plain zlib.
 *
 * The handle's thread; the write's buffers and deflate state live in the
 * handle (st_raw) and are grown, never shrunk: no allocation per passage
 * once they fit.
 */
#include <errno.h>
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "store_internal.h"

#define RAW_LEVEL 1 /* zlib level: 1 is 0.6 % larger than 6 on float64 samples and many
                      * times faster (docs/results/raw-passages.md) */

struct st_raw {
    z_stream z;
    int z_init;
    unsigned char *planes, *out; /* the transformed bytes, the compressed */
    size_t planes_cap, out_cap;
    char *text;                  /* the vehicles text */
    size_t text_cap;
    sqlite3_stmt *ins_window, *ins_link;
};

void st_raw_free(amfi_store *s)
{
    if (!s || !s->raw)
        return;
    if (s->raw->z_init)
        deflateEnd(&s->raw->z);
    sqlite3_finalize(s->raw->ins_window);
    sqlite3_finalize(s->raw->ins_link);
    free(s->raw->planes);
    free(s->raw->out);
    free(s->raw->text);
    free(s->raw);
    s->raw = NULL;
}

/* ---- the codec ------------------------------------------------------------ */

/* The bit pattern of sample x as stored: float64, or rounded to float32. */
static uint64_t pattern(double x, int f32)
{
    if (f32) {
        float f = (float)x;
        uint32_t b;
        memcpy(&b, &f, sizeof b);
        return b;
    }
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* n values (sensors runs) into w·n bytes of planes (w = 8, or 4 for
 * float32): plane p holds byte w − 1 − p (the most significant first) of
 * every XORed pattern. */
static void shuffle(const double *x, int64_t n, int sensors, int f32, unsigned char *planes)
{
    const int64_t per = n / sensors;
    const int w = f32 ? 4 : 8;
    for (int s = 0; s < sensors; s++) {
        uint64_t prev = 0;
        for (int64_t k = 0; k < per; k++) {
            const int64_t i = (int64_t)s * per + k;
            const uint64_t b = pattern(x[i], f32);
            const uint64_t d = b ^ prev;
            prev = b;
            for (int p = 0; p < w; p++)
                planes[(int64_t)p * n + i] = (unsigned char)(d >> (8 * (w - 1 - p)));
        }
    }
}

static void unshuffle(const unsigned char *planes, int64_t n, int sensors, int f32, double *x)
{
    const int64_t per = n / sensors;
    const int w = f32 ? 4 : 8;
    for (int s = 0; s < sensors; s++) {
        uint64_t prev = 0;
        for (int64_t k = 0; k < per; k++) {
            const int64_t i = (int64_t)s * per + k;
            uint64_t d = 0;
            for (int p = 0; p < w; p++)
                d |= (uint64_t)planes[(int64_t)p * n + i] << (8 * (w - 1 - p));
            prev ^= d;
            if (f32) {
                const uint32_t b = (uint32_t)prev;
                float f;
                memcpy(&f, &b, sizeof f);
                x[i] = (double)f;
            } else {
                memcpy(&x[i], &prev, sizeof prev);
            }
        }
    }
}

static int check_shape(int64_t n, int sensors, char *err, size_t errlen)
{
    if (sensors < 1 || sensors > AMFI_MAX_SENSORS || n < 1 || n % sensors != 0 ||
        n > AMFI_STORE_RAW_MAX_SAMPLES)
        return st_fail(err, errlen, AMFI_EINVAL,
                       "raw samples: %" PRId64 " samples of %d sensors is not a window "
                       "(1 .. %d sensors, a multiple of them, at most %" PRId64 ")",
                       n, sensors, AMFI_MAX_SENSORS, (int64_t)AMFI_STORE_RAW_MAX_SAMPLES);
    return 0;
}

/* Grow *buf to hold need bytes. */
static int grow(unsigned char **buf, size_t *cap, size_t need)
{
    if (*cap >= need)
        return 0;
    unsigned char *b = realloc(*buf, need);
    if (!b)
        return -1;
    *buf = b;
    *cap = need;
    return 0;
}

/* Deflate len bytes of in with z (initialised) into out (cap bytes, at
 * least deflateBound): *outlen. */
static int deflate_all(z_stream *z, const unsigned char *in, size_t len, unsigned char *out,
                       size_t cap, size_t *outlen, char *err, size_t errlen)
{
    z->next_in = (unsigned char *)in;
    z->avail_in = (uInt)len;
    z->next_out = out;
    z->avail_out = (uInt)cap;
    int zr = deflate(z, Z_FINISH);
    if (zr != Z_STREAM_END)
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: zlib deflate: %s (%d)",
                       z->msg ? z->msg : "no room", zr);
    *outlen = cap - z->avail_out;
    return 0;
}

/* A sample float32 cannot hold (beyond its range, or not finite). */
static int64_t beyond_float(const double *x, int64_t n)
{
    for (int64_t k = 0; k < n; k++)
        if (!(fabs(x[k]) <= FLT_MAX))
            return k;
    return -1;
}

int amfi_store_raw_encode(const double *x, int64_t n, int sensors, int level, int float32,
                          unsigned char **out, size_t *outlen, char *err, size_t errlen)
{
    int rc = check_shape(n, sensors, err, errlen);
    if (rc == 0 && (!x || !out || !outlen || level < 1 || level > 9))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: bad argument to encode");
    if (rc == 0 && float32 && beyond_float(x, n) >= 0)
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: sample %" PRId64 " is beyond float32",
                     beyond_float(x, n));
    if (rc != 0)
        return rc;
    const size_t len = (size_t)n * (float32 ? 4 : 8);
    unsigned char *planes = malloc(len);
    z_stream z;
    memset(&z, 0, sizeof z);
    if (!planes || deflateInit(&z, level) != Z_OK) {
        free(planes);
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: out of memory");
    }
    size_t cap = deflateBound(&z, (uLong)len);
    unsigned char *o = malloc(cap);
    if (!o)
        rc = st_fail(err, errlen, AMFI_ENOMEM, "raw samples: out of memory");
    if (rc == 0) {
        shuffle(x, n, sensors, float32, planes);
        rc = deflate_all(&z, planes, len, o, cap, outlen, err, errlen);
    }
    deflateEnd(&z);
    free(planes);
    if (rc != 0) {
        free(o);
        return rc;
    }
    *out = o;
    return 0;
}

int amfi_store_raw_decode(const unsigned char *blob, size_t len, int64_t n, int sensors,
                          int float32, double *x, char *err, size_t errlen)
{
    int rc = check_shape(n, sensors, err, errlen);
    if (rc == 0 && (!blob || !x))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: bad argument to decode");
    if (rc != 0)
        return rc;
    const size_t want = (size_t)n * (float32 ? 4 : 8);
    unsigned char *planes = malloc(want);
    if (!planes)
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: out of memory for %zu bytes",
                       want);
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit(&z) != Z_OK) {
        free(planes);
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: zlib inflateInit failed");
    }
    z.next_in = (unsigned char *)blob;
    z.avail_in = (uInt)len;
    z.next_out = planes;
    z.avail_out = (uInt)want;
    int zr = inflate(&z, Z_FINISH);
    if (zr != Z_STREAM_END || z.total_out != want || z.avail_in != 0) {
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                     "raw samples: the blob of %zu bytes does not decode to %" PRId64
                     " samples (%s: %s after %lu of %zu bytes)",
                     len, n,
                     zr == Z_STREAM_END ? (z.avail_in ? "bytes after the end" : "short")
                     : zr == Z_BUF_ERROR ? "truncated or longer than expected"
                     : zr == Z_DATA_ERROR ? "damaged"
                                          : "zlib error",
                     z.msg ? z.msg : "no zlib message", (unsigned long)z.total_out, want);
    }
    inflateEnd(&z);
    if (rc == 0)
        unshuffle(planes, n, sensors, float32, x);
    free(planes);
    return rc;
}

/* ---- the text columns ------------------------------------------------------- */

/* Append to buf (cap bytes) at *k; -1 when it does not fit. */
static int put(char *buf, size_t cap, size_t *k, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int put(char *buf, size_t cap, size_t *k, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = *k < cap ? vsnprintf(buf + *k, cap - *k, fmt, ap) : -1;
    va_end(ap);
    if (n < 0 || *k + (size_t)n >= cap)
        return -1;
    *k += (size_t)n;
    return 0;
}

static int sensors_text(const amfi_raw_window *w, char *buf, size_t cap)
{
    size_t k = 0;
    for (int i = 0; i < w->n_sensors; i++)
        if (put(buf, cap, &k, "%s%d@%.17g", i ? "," : "", w->sensor_id[i], w->sensor_at_m[i]))
            return -1;
    return 0;
}

static int vehicles_text(const amfi_raw_window *w, char *buf, size_t cap)
{
    size_t k = 0;
    for (int v = 0; v < w->n_vehicles; v++) {
        const amfi_raw_vehicle *e = &w->vehicle[v];
        if (put(buf, cap, &k, "%s%" PRId64 ",%" PRId64 ",%d,%.17g,", v ? ";" : "", e->vehicle_id,
                e->utime, e->lane, e->speed_mps))
            return -1;
        for (int a = 0; a + 1 < e->n_axles; a++)
            if (put(buf, cap, &k, "%s%.17g", a ? "/" : "", e->spacing_m[a]))
                return -1;
    }
    return 0;
}

static int solve_text(const amfi_raw_window *w, char *buf, size_t cap)
{
    const amfi_lambda *l = &w->lambda;
    const amfi_speed_prior *p = &w->speed_prior;
    char lam[40];
    size_t k = 0;
    if (l->automatic)
        snprintf(lam, sizeof lam, "auto");
    else
        snprintf(lam, sizeof lam, "%.17g", l->lambda_ref);
    return put(buf, cap, &k,
               "lambda=%s ref_rate_hz=%.17g lcurve=%.17g:%.17g:%d:%d speed=%s "
               "prior=%.17g:%.17g:%.17g:%.17g:%d:%d:%.17g:%.17g:%s:%s",
               lam, l->ref_rate_hz, l->lcurve_lo, l->lcurve_hi, l->lcurve_per_decade,
               l->lcurve_refine_points, w->speed_estimate ? "estimate" : "measured", p->rel_sd,
               p->range_sd, p->grid_rel, p->tol_rel, p->brent_evals, p->local_half,
               p->coarse_rate_hz, p->data_dof, amfi_speed_criterion_name(p->criterion),
               amfi_speed_pick_name(p->pick));
}

/* Numbers of a text, each followed by one of `ends` (or the end of the
 * text for the last): *p moves past it. -1: not a number there. */
static int num_at(const char **p, const char *ends, double *x)
{
    char *e;
    errno = 0;
    *x = strtod(*p, &e);
    if (e == *p || errno == ERANGE || !isfinite(*x) || (*e && !strchr(ends, *e)))
        return -1;
    *p = *e ? e + 1 : e;
    return 0;
}

static int int_at(const char **p, const char *ends, int64_t lo, int64_t hi, int64_t *x)
{
    char *e;
    errno = 0;
    long long v = strtoll(*p, &e, 10);
    if (e == *p || errno == ERANGE || v < lo || v > hi || (*e && !strchr(ends, *e)))
        return -1;
    *x = v;
    *p = *e ? e + 1 : e;
    return 0;
}

static int parse_sensors(const char *t, amfi_raw_window *w)
{
    const char *p = t;
    w->n_sensors = 0;
    while (*p) {
        int64_t id;
        double at;
        if (w->n_sensors == AMFI_MAX_SENSORS || int_at(&p, "@", 0, 255, &id) ||
            p[-1] != '@' || num_at(&p, ",", &at))
            return -1;
        w->sensor_id[w->n_sensors] = (int)id;
        w->sensor_at_m[w->n_sensors++] = at;
    }
    return w->n_sensors > 0 ? 0 : -1;
}

static int parse_vehicles(const char *t, amfi_raw_window *w)
{
    const char *p = t;
    w->n_vehicles = 0;
    while (*p) {
        if (w->n_vehicles == AMFI_MAX_VEHICLES)
            return -1;
        amfi_raw_vehicle *e = &w->vehicle[w->n_vehicles++];
        memset(e, 0, sizeof *e);
        int64_t lane;
        if (int_at(&p, ",", INT64_MIN, INT64_MAX, &e->vehicle_id) ||
            int_at(&p, ",", 0, AMFI_STORE_MAX_UTIME, &e->utime) ||
            int_at(&p, ",", -32768, 32767, &lane) || num_at(&p, ",", &e->speed_mps) ||
            !(e->speed_mps > 0 && e->speed_mps <= AMFI_STORE_MAX_SPEED_MPS) || p[-1] != ',')
            return -1;
        e->lane = (int)lane;
        e->n_axles = 1;
        while (*p && *p != ';') {
            double s;
            if (e->n_axles == AMFI_MAX_AXLES || num_at(&p, "/;", &s) ||
                !(s > 0 && s <= AMFI_STORE_MAX_SPACING_M))
                return -1;
            e->spacing_m[e->n_axles++ - 1] = s;
            if (p[-1] == ';')
                break;
        }
        if (*p == ';') /* a vehicle of one axle followed by another */
            p++;
    }
    return w->n_vehicles > 0 ? 0 : -1;
}

/* The value after "key=" in t, up to the next space, into buf. */
static int field_of(const char *t, const char *key, char *buf, size_t len)
{
    size_t kl = strlen(key);
    for (const char *p = t; p && *p; p = strchr(p, ' '), p = p ? p + 1 : NULL) {
        if (strncmp(p, key, kl) == 0 && p[kl] == '=') {
            const char *v = p + kl + 1, *e = strchr(v, ' ');
            size_t n = e ? (size_t)(e - v) : strlen(v);
            if (n == 0 || n >= len)
                return -1;
            memcpy(buf, v, n);
            buf[n] = '\0';
            return 0;
        }
    }
    return -1;
}

static int parse_solve(const char *t, amfi_raw_window *w)
{
    char v[256];
    const char *p;
    double x;
    int64_t i;
    amfi_lambda *l = &w->lambda;
    amfi_speed_prior *sp = &w->speed_prior;
    if (field_of(t, "lambda", v, sizeof v))
        return -1;
    l->automatic = strcmp(v, "auto") == 0;
    p = v;
    if (!l->automatic && (num_at(&p, "", &l->lambda_ref) || !(l->lambda_ref > 0)))
        return -1;
    if (field_of(t, "ref_rate_hz", v, sizeof v) || (p = v, num_at(&p, "", &l->ref_rate_hz)) ||
        !(l->ref_rate_hz > 0))
        return -1;
    if (field_of(t, "lcurve", v, sizeof v))
        return -1;
    p = v;
    if (num_at(&p, ":", &l->lcurve_lo) || num_at(&p, ":", &l->lcurve_hi) ||
        int_at(&p, ":", 1, 100, &i))
        return -1;
    l->lcurve_per_decade = (int)i;
    if (int_at(&p, "", 0, 100, &i) || *p)
        return -1;
    l->lcurve_refine_points = (int)i;
    if (field_of(t, "speed", v, sizeof v))
        return -1;
    if (strcmp(v, "estimate") == 0)
        w->speed_estimate = 1;
    else if (strcmp(v, "measured") == 0)
        w->speed_estimate = 0;
    else
        return -1;
    if (field_of(t, "prior", v, sizeof v))
        return -1;
    p = v;
    if (num_at(&p, ":", &sp->rel_sd) || num_at(&p, ":", &sp->range_sd) ||
        num_at(&p, ":", &sp->grid_rel) || num_at(&p, ":", &sp->tol_rel) ||
        int_at(&p, ":", 0, 100, &i))
        return -1;
    sp->brent_evals = (int)i;
    if (int_at(&p, ":", 1, 3, &i))
        return -1;
    sp->local_half = (int)i;
    if (num_at(&p, ":", &sp->coarse_rate_hz) || num_at(&p, ":", &x))
        return -1;
    sp->data_dof = x;
    const char *colon = strchr(p, ':');
    if (!colon)
        return -1;
    char crit[32];
    size_t n = (size_t)(colon - p);
    if (n >= sizeof crit)
        return -1;
    memcpy(crit, p, n);
    crit[n] = '\0';
    if (amfi_speed_criterion_parse(crit, &sp->criterion) != 0)
        return -1;
    if (strcmp(colon + 1, amfi_speed_pick_name(AMFI_SPEED_PICK_MIN)) == 0)
        sp->pick = AMFI_SPEED_PICK_MIN;
    else if (strcmp(colon + 1, amfi_speed_pick_name(AMFI_SPEED_PICK_DIP)) == 0)
        sp->pick = AMFI_SPEED_PICK_DIP;
    else
        return -1;
    return 0;
}

/* ---- checks ------------------------------------------------------------------ */

static int check_window(const amfi_raw_window *w, char *err, size_t errlen)
{
    char name[64];
    int rc = st_check_utime("raw_windows.utime", w->utime, err, errlen);
    static const range R_RATE = {0.0, 100000.0, 1, "Hz", 0};
    static const range R_T = {-3600.0, 3600.0, 0, "s", 0};
    if (rc == 0)
        rc = st_check_known("raw_windows.rate_hz", w->rate_hz, &R_RATE, err, errlen);
    if (rc == 0)
        rc = st_check_known("raw_windows.t_first_s", w->t_first_s, &R_T, err, errlen);
    if (rc == 0 && (w->n_sensors < 1 || w->n_sensors > AMFI_MAX_SENSORS))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw_windows: n_sensors %d is not in 1 .. %d",
                     w->n_sensors, AMFI_MAX_SENSORS);
    if (rc == 0 && (w->n_samples < 1 ||
                    (int64_t)w->n_samples * w->n_sensors > AMFI_STORE_RAW_MAX_SAMPLES))
        rc = st_fail(err, errlen, AMFI_EINVAL,
                     "raw_windows.n_samples: %d per sensor is not in 1 .. %" PRId64 " in all",
                     w->n_samples, (int64_t)AMFI_STORE_RAW_MAX_SAMPLES);
    for (int i = 0; rc == 0 && i < w->n_sensors; i++) {
        if (w->sensor_id[i] < 0 || w->sensor_id[i] > 255)
            rc = st_fail(err, errlen, AMFI_EINVAL, "raw_windows: sensor %d: id %d is not in 0 .. 255",
                         i, w->sensor_id[i]);
        snprintf(name, sizeof name, "raw_windows: sensor %d: at_m", i);
        if (rc == 0)
            rc = st_check_known(name, w->sensor_at_m[i], &R_FINITE, err, errlen);
    }
    if (rc == 0 && (w->n_vehicles < 1 || w->n_vehicles > AMFI_MAX_VEHICLES))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw_windows: n_vehicles %d is not in 1 .. %d",
                     w->n_vehicles, AMFI_MAX_VEHICLES);
    for (int v = 0; rc == 0 && v < w->n_vehicles; v++) {
        const amfi_raw_vehicle *e = &w->vehicle[v];
        snprintf(name, sizeof name, "raw_windows: vehicle %d: utime", v);
        rc = st_check_utime(name, e->utime, err, errlen);
        snprintf(name, sizeof name, "raw_windows: vehicle %d: speed_mps", v);
        if (rc == 0)
            rc = st_check_known(name, e->speed_mps, &R_SPEED_POS, err, errlen);
        if (rc == 0 && (e->lane < -32768 || e->lane > 32767 || e->n_axles < 1 ||
                        e->n_axles > AMFI_MAX_AXLES))
            rc = st_fail(err, errlen, AMFI_EINVAL,
                         "raw_windows: vehicle %d: lane %d or n_axles %d out of range", v,
                         e->lane, e->n_axles);
        for (int a = 0; rc == 0 && a + 1 < e->n_axles; a++) {
            snprintf(name, sizeof name, "raw_windows: vehicle %d: spacing_m[%d]", v, a);
            rc = st_check_known(name, e->spacing_m[a], &R_SPACING, err, errlen);
        }
    }
    if (rc == 0 && !w->samples)
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw_windows: samples is NULL");
    const int64_t n = (int64_t)w->n_samples * w->n_sensors;
    for (int64_t k = 0; rc == 0 && k < n; k++)
        if (!isfinite(w->samples[k]))
            rc = st_fail(err, errlen, AMFI_EINVAL,
                         "raw_windows: sample %" PRId64 " of sensor %d is not finite",
                         k % w->n_samples, (int)(k / w->n_samples));
    return rc;
}

/* ---- write, in the passage's transaction --------------------------------------- */

static int raw_state(amfi_store *s, char *err, size_t errlen)
{
    if (!s->raw) {
        s->raw = calloc(1, sizeof *s->raw);
        if (!s->raw)
            return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: out of memory");
    }
    struct st_raw *r = s->raw;
    int rc = 0;
    if (!r->z_init) {
        if (deflateInit(&r->z, RAW_LEVEL) != Z_OK)
            return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: zlib deflateInit failed");
        r->z_init = 1;
    }
    if (!r->ins_window)
        rc = st_prepare(s,
                        "INSERT INTO raw_windows (utime, rate_hz, t_first_s, n_samples, sensors, "
                        "vehicles, solve, encoding, bytes, samples) "
                        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                        &r->ins_window, "raw_windows: prepare", err, errlen);
    if (rc == 0 && !r->ins_link)
        rc = st_prepare(s,
                        "INSERT INTO passage_raw (passage_id, window_id, vehicle) "
                        "VALUES (?1, ?2, ?3)",
                        &r->ins_link, "passage_raw: prepare", err, errlen);
    return rc;
}

static int run_stmt(amfi_store *s, sqlite3_stmt *st, int b, const char *what, char *err,
                    size_t errlen)
{
    int src = b == SQLITE_OK ? sqlite3_step(st) : b;
    int rc = src == SQLITE_DONE || src == SQLITE_ROW ? 0 : st_db_fail(s, src, what, err, errlen);
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
    return rc;
}

static int write_window(amfi_store *s, const amfi_raw_window *w, int f32, int64_t *wid,
                        int64_t *bytes, char *err, size_t errlen)
{
    struct st_raw *r = s->raw;
    char sensors[1100], solve[1100];
    const int64_t n = (int64_t)w->n_samples * w->n_sensors;
    const size_t len = (size_t)n * (f32 ? 4 : 8);
    if (f32 && beyond_float(w->samples, n) >= 0)
        return st_fail(err, errlen, AMFI_EINVAL,
                       "raw_windows: sample %" PRId64 " of sensor %d is beyond float32",
                       beyond_float(w->samples, n) % w->n_samples,
                       (int)(beyond_float(w->samples, n) / w->n_samples));
    int rc = 0;
    if (sensors_text(w, sensors, sizeof sensors) || solve_text(w, solve, sizeof solve))
        return st_fail(err, errlen, AMFI_EINVAL, "raw_windows: sensors or solve text too long");
    if (grow((unsigned char **)&r->text, &r->text_cap, 32769) ||
        vehicles_text(w, r->text, r->text_cap))
        return st_fail(err, errlen, AMFI_EINVAL, "raw_windows: vehicles text too long");
    if (deflateReset(&r->z) != Z_OK)
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: zlib deflateReset failed");
    const size_t bound = deflateBound(&r->z, (uLong)len);
    if (grow(&r->planes, &r->planes_cap, len) || grow(&r->out, &r->out_cap, bound))
        return st_fail(err, errlen, AMFI_ENOMEM, "raw samples: out of memory for %zu bytes",
                       len + bound);
    shuffle(w->samples, n, w->n_sensors, f32, r->planes);
    size_t olen = 0;
    rc = deflate_all(&r->z, r->planes, len, r->out, r->out_cap, &olen, err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = r->ins_window;
    int b = sqlite3_bind_int64(st, 1, w->utime);
    if (b == SQLITE_OK) b = sqlite3_bind_double(st, 2, w->rate_hz);
    if (b == SQLITE_OK) b = sqlite3_bind_double(st, 3, w->t_first_s);
    if (b == SQLITE_OK) b = sqlite3_bind_int(st, 4, w->n_samples);
    if (b == SQLITE_OK) b = st_bind_text(st, 5, sensors);
    if (b == SQLITE_OK) b = st_bind_text(st, 6, r->text);
    if (b == SQLITE_OK) b = st_bind_text(st, 7, solve);
    if (b == SQLITE_OK) b = st_bind_text(st, 8, f32 ? AMFI_STORE_RAW_F32 : AMFI_STORE_RAW_F64);
    if (b == SQLITE_OK) b = sqlite3_bind_int64(st, 9, (int64_t)olen);
    if (b == SQLITE_OK) b = sqlite3_bind_blob64(st, 10, r->out, olen, SQLITE_STATIC);
    rc = run_stmt(s, st, b, "raw_windows: insert", err, errlen);
    if (rc == 0) {
        *wid = sqlite3_last_insert_rowid(s->db);
        *bytes = (int64_t)olen;
    }
    return rc;
}

/* The raw rows of passage pid (store_write.c, inside its transaction). */
int st_raw_write(amfi_store *s, int64_t pid, amfi_raw_put *put)
{
    char *err = put->err;
    const size_t errlen = sizeof put->err;
    put->err[0] = '\0';
    put->stored_window_id = put->bytes = put->raw_bytes = 0;
    int rc = sqlite3_exec(s->db, "SAVEPOINT raw", NULL, NULL, NULL);
    if (rc != SQLITE_OK)
        return put->status = st_db_fail(s, rc, "raw samples: savepoint", err, errlen);
    rc = raw_state(s, err, errlen);
    const amfi_raw_window *w = put->window;
    int64_t wid = put->window_id, bytes = 0;
    if (rc == 0 && w) {
        rc = check_window(w, err, errlen);
        if (rc == 0 && (put->vehicle < 0 || put->vehicle >= w->n_vehicles))
            rc = st_fail(err, errlen, AMFI_EINVAL,
                         "passage_raw.vehicle: %d is not one of the window's %d", put->vehicle,
                         w->n_vehicles);
        if (rc == 0)
            rc = write_window(s, w, put->float32 != 0, &wid, &bytes, err, errlen);
    } else if (rc == 0 && (wid <= 0 || put->vehicle < 0 || put->vehicle > 63)) {
        rc = st_fail(err, errlen, AMFI_EINVAL,
                     "passage_raw: neither a window nor a window id (%" PRId64 ") to link to",
                     wid);
    }
    if (rc == 0) {
        sqlite3_stmt *st = s->raw->ins_link;
        int b = sqlite3_bind_int64(st, 1, pid);
        if (b == SQLITE_OK) b = sqlite3_bind_int64(st, 2, wid);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 3, put->vehicle);
        rc = run_stmt(s, st, b, "passage_raw: insert", err, errlen);
    }
    if (rc != 0)
        sqlite3_exec(s->db, "ROLLBACK TO raw", NULL, NULL, NULL);
    sqlite3_exec(s->db, "RELEASE raw", NULL, NULL, NULL);
    put->status = rc;
    if (rc == 0) {
        put->stored_window_id = wid;
        put->bytes = bytes;
        put->raw_bytes = w ? (int64_t)w->n_samples * w->n_sensors * 8 : 0; /* as float64 */
    }
    return rc;
}

/* ---- reads ------------------------------------------------------------------- */

void amfi_store_raw_free(amfi_raw_rec *r)
{
    if (!r)
        return;
    free((double *)r->w.samples);
    memset(r, 0, sizeof *r);
}

int amfi_store_raw_get(amfi_store *s, int64_t passage_id, amfi_raw_rec *out, int *found,
                       char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), yes = 0;
    if (rc == 0 && (!out || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: output is NULL");
    if (rc != 0)
        return rc;
    memset(out, 0, sizeof *out);
    *found = 0;
    rc = st_has_table(s, "passage_raw", &yes, err, errlen);
    if (rc != 0 || !yes)
        return rc;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT pr.window_id, pr.vehicle, w.utime, w.rate_hz, w.t_first_s, "
                    "w.n_samples, w.sensors, w.vehicles, w.solve, w.encoding, w.bytes, w.samples "
                    "FROM passage_raw pr JOIN raw_windows w ON w.id = pr.window_id "
                    "WHERE pr.passage_id = ?1",
                    &st, "raw samples: read", err, errlen);
    if (rc != 0)
        return rc;
    int src = sqlite3_bind_int64(st, 1, passage_id);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_DONE) {
        sqlite3_finalize(st);
        return 0;
    }
    if (src != SQLITE_ROW) {
        rc = st_db_fail(s, src, "raw samples: read", err, errlen);
        sqlite3_finalize(st);
        return rc;
    }
    amfi_raw_window *w = &out->w;
    out->passage_id = passage_id;
    out->window_id = sqlite3_column_int64(st, 0);
    origin o = {"raw_windows", out->window_id};
    static const range R_RATE = {0.0, 100000.0, 1, "Hz", 0};
    static const range R_T = {-3600.0, 3600.0, 0, "s", 0};
    int64_t v = 0, n = 0;
    char what[160];
    snprintf(what, sizeof what, "passage %" PRId64 ": raw window %" PRId64, passage_id,
             out->window_id);
    rc = st_read_int(st, 1, 0, 63, &o, &v, err, errlen);
    out->vehicle = (int)v;
    if (rc == 0)
        rc = st_read_int(st, 2, 0, AMFI_STORE_MAX_UTIME, &o, &w->utime, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 3, &R_RATE, &o, &w->rate_hz, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 4, &R_T, &o, &w->t_first_s, err, errlen);
    if (rc == 0)
        rc = st_read_int(st, 5, 1, INT32_MAX, &o, &n, err, errlen);
    w->n_samples = (int)n;
    const char *t[4];
    for (int k = 0; rc == 0 && k < 4; k++) {
        t[k] = (const char *)sqlite3_column_text(st, 6 + k);
        if (sqlite3_column_type(st, 6 + k) != SQLITE_TEXT || !t[k])
            rc = st_corrupt(&o, st, 6 + k, err, errlen, "is not text");
    }
    if (rc == 0 && parse_sensors(t[0], w))
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: sensors '%.60s' is not ID@AT_M,...",
                     what, t[0]);
    if (rc == 0 && parse_vehicles(t[1], w))
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                     "%s: vehicles '%.60s' is not a list of detector records", what, t[1]);
    if (rc == 0 && parse_solve(t[2], w))
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: solve '%.80s' cannot be read", what,
                     t[2]);
    if (rc == 0 && strcmp(t[3], AMFI_STORE_RAW_F32) == 0)
        out->float32 = 1;
    else if (rc == 0 && strcmp(t[3], AMFI_STORE_RAW_F64) != 0)
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: unknown encoding '%.40s'", what,
                     t[3]);
    if (rc == 0 && out->vehicle >= w->n_vehicles)
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                     "%s: passage_raw.vehicle %d but the window has %d vehicles", what,
                     out->vehicle, w->n_vehicles);
    if (rc == 0 && (int64_t)w->n_samples * w->n_sensors > AMFI_STORE_RAW_MAX_SAMPLES)
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: %d samples of %d sensors: too many",
                     what, w->n_samples, w->n_sensors);
    if (rc == 0)
        rc = st_read_int(st, 10, 1, INT64_MAX, &o, &out->bytes, err, errlen);
    const unsigned char *blob = rc == 0 ? sqlite3_column_blob(st, 11) : NULL;
    const int blen = rc == 0 ? sqlite3_column_bytes(st, 11) : 0;
    if (rc == 0 && (sqlite3_column_type(st, 11) != SQLITE_BLOB || !blob))
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: samples is not a blob", what);
    if (rc == 0 && (int64_t)blen != out->bytes)
        rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                     "%s: samples holds %d bytes, bytes says %" PRId64 " (truncated?)", what,
                     blen, out->bytes);
    double *x = NULL;
    const int64_t total = (int64_t)w->n_samples * w->n_sensors;
    if (rc == 0 && !(x = malloc((size_t)total * sizeof *x)))
        rc = st_fail(err, errlen, AMFI_ENOMEM, "%s: out of memory for %" PRId64 " samples", what,
                     total);
    if (rc == 0) {
        char zerr[200];
        rc = amfi_store_raw_decode(blob, (size_t)blen, total, w->n_sensors, out->float32, x, zerr,
                                   sizeof zerr);
        if (rc != 0)
            st_fail(err, errlen, rc, "%s: %s", what, zerr);
    }
    for (int64_t k = 0; rc == 0 && k < total; k++)
        if (!isfinite(x[k]))
            rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                         "%s: sample %" PRId64 " of sensor %d decodes to a non-finite value",
                         what, k % w->n_samples, (int)(k / w->n_samples));
    sqlite3_finalize(st);
    if (rc != 0) {
        free(x);
        memset(out, 0, sizeof *out);
        return rc;
    }
    w->samples = x;
    *found = 1;
    return 0;
}

int amfi_store_raw_usage(amfi_store *s, int64_t *windows, int64_t *bytes, char *err,
                         size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), yes = 0;
    if (rc == 0 && (!windows || !bytes))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: output is NULL");
    if (rc == 0)
        *windows = *bytes = 0;
    if (rc == 0)
        rc = st_has_table(s, "raw_windows", &yes, err, errlen);
    if (rc != 0 || !yes)
        return rc;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s, "SELECT count(*), coalesce(sum(bytes), 0) FROM raw_windows", &st,
                    "raw_windows: usage", err, errlen);
    if (rc != 0)
        return rc;
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        *windows = sqlite3_column_int64(st, 0);
        *bytes = sqlite3_column_int64(st, 1);
    } else {
        rc = st_db_fail(s, src, "raw_windows: usage", err, errlen);
    }
    sqlite3_finalize(st);
    return rc;
}

/* Collect up to max (id, bytes) of the oldest windows (utime < before when
 * before > 0), oldest first. */
static int oldest(amfi_store *s, int64_t before, int max, int64_t *ids, int64_t *bytes, int *n,
                  char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_prepare(s,
                        before > 0 ? "SELECT id, bytes FROM raw_windows WHERE utime < ?1 "
                                     "ORDER BY utime, id LIMIT ?2"
                                   : "SELECT id, bytes FROM raw_windows "
                                     "ORDER BY utime, id LIMIT ?2",
                        &st, "raw_windows: retention", err, errlen);
    if (rc != 0)
        return rc;
    int src = before > 0 ? sqlite3_bind_int64(st, 1, before) : SQLITE_OK;
    if (src == SQLITE_OK)
        src = sqlite3_bind_int(st, 2, max);
    *n = 0;
    while (src == SQLITE_OK || src == SQLITE_ROW) {
        src = sqlite3_step(st);
        if (src != SQLITE_ROW)
            break;
        ids[*n] = sqlite3_column_int64(st, 0);
        bytes[(*n)++] = sqlite3_column_int64(st, 1);
    }
    if (src != SQLITE_DONE)
        rc = st_db_fail(s, src, "raw_windows: retention", err, errlen);
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_raw_prune(amfi_store *s, int64_t before_utime, int64_t max_bytes, int max_windows,
                         amfi_raw_pruned *out, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 1, err, errlen), yes = 0;
    if (rc == 0 && (!out || max_windows < 1))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw retention: bad argument");
    if (rc != 0)
        return rc;
    memset(out, 0, sizeof *out);
    rc = st_has_table(s, "raw_windows", &yes, err, errlen);
    if (rc != 0 || !yes)
        return rc;
    int64_t *ids = malloc((size_t)max_windows * sizeof *ids);
    int64_t *by = malloc((size_t)max_windows * sizeof *by);
    sqlite3_stmt *del = NULL;
    if (!ids || !by)
        rc = st_fail(err, errlen, AMFI_ENOMEM, "raw retention: out of memory");
    if (rc == 0)
        rc = st_prepare(s, "DELETE FROM raw_windows WHERE id = ?1", &del,
                        "raw_windows: delete", err, errlen);
    if (rc == 0)
        rc = st_begin(s, err, errlen);
    int n = 0, left = max_windows;
    if (rc == 0 && before_utime > 0) {
        rc = oldest(s, before_utime, left, ids, by, &n, err, errlen);
        for (int k = 0; rc == 0 && k < n; k++) {
            rc = run_stmt(s, del, sqlite3_bind_int64(del, 1, ids[k]), "raw_windows: delete",
                          err, errlen);
            out->by_age++;
            out->bytes += by[k];
        }
        left -= n;
        out->more = n == max_windows;
    }
    if (rc == 0 && max_bytes >= 0 && left > 0) {
        int64_t w = 0, total = 0;
        rc = amfi_store_raw_usage(s, &w, &total, err, errlen);
        if (rc == 0 && total > max_bytes)
            rc = oldest(s, 0, left, ids, by, &n, err, errlen);
        else
            n = 0;
        for (int k = 0; rc == 0 && k < n && total > max_bytes; k++) {
            rc = run_stmt(s, del, sqlite3_bind_int64(del, 1, ids[k]), "raw_windows: delete",
                          err, errlen);
            out->by_size++;
            out->bytes += by[k];
            total -= by[k];
        }
        if (rc == 0 && total > max_bytes)
            out->more = 1;
    }
    if (rc == 0)
        rc = st_commit(s, err, errlen);
    if (rc != 0) {
        st_rollback(s);
        memset(out, 0, sizeof *out);
    }
    sqlite3_finalize(del);
    free(ids);
    free(by);
    return rc;
}

/* ---- one stored passage -------------------------------------------------------- */

int amfi_store_passage_get(amfi_store *s, int64_t id, amfi_stored_passage *out, int *found,
                           char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "passage: output is NULL");
    if (rc != 0)
        return rc;
    memset(out, 0, sizeof *out);
    *found = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason, "
                    "lambda, residual_rms, n_vehicles FROM passages WHERE id = ?1",
                    &st, "passages: read", err, errlen);
    if (rc != 0)
        return rc;
    int src = sqlite3_bind_int64(st, 1, id);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    amfi_passage_row *r = &out->row;
    origin o = {"passages", id};
    int64_t v = 0;
    if (src == SQLITE_ROW) {
        r->vehicle_id = sqlite3_column_int64(st, 0);
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
        if (rc == 0)
            rc = st_read_int(st, 2, -32768, 32767, &o, &v, err, errlen);
        r->lane = (int)v;
        if (rc == 0)
            rc = st_read_real_or_null(st, 3, &R_SPEED, &o, &r->speed_mps, err, errlen);
        if (rc == 0)
            rc = st_read_int(st, 4, 0, AMFI_MAX_AXLES, &o, &v, err, errlen);
        r->n_axles = (int)v;
        if (rc == 0)
            rc = st_read_real_or_null(st, 5, &R_KG, &o, &r->gvw_kg, err, errlen);
        if (rc == 0)
            rc = st_read_text(st, 6, sizeof out->status - 1, &o, out->status, sizeof out->status,
                              err, errlen);
        if (rc == 0)
            rc = st_read_text(st, 7, AMFI_STORE_REASON_MAX, &o, out->reason, sizeof out->reason,
                              err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 8, &R_POS, &o, &r->lambda, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 9, &R_NONNEG, &o, &r->residual_rms, err, errlen);
        if (rc == 0)
            rc = st_read_int(st, 10, 1, 64, &o, &v, err, errlen);
        r->n_vehicles = (int)v;
        *found = rc == 0;
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "passages: read", err, errlen);
    }
    sqlite3_finalize(st);
    r->status = out->status;
    r->reason = out->reason;
    for (int a = 0; a < AMFI_MAX_AXLES; a++)
        r->axle_kg[a] = r->spacing_m[a] = NAN;
    if (rc != 0 || !*found)
        return rc;
    rc = st_prepare(s, "SELECT idx, spacing_m, load_kg FROM axles WHERE passage_id = ?1",
                    &st, "axles: read", err, errlen);
    if (rc != 0)
        return rc;
    rc = st_read_axles(s, st, id, r, NULL, "axles: read", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0)
        *found = 0;
    return rc;
}
