/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-raw-bench: the raw samples a store kept (daemon.store.raw), encoded
 * other ways, to judge the store's codec (docs/results/raw-passages.md).
 *
 *   amfi-raw-bench --db STORE [--max N]
 *
 * Reads every raw window of the store (amfi_store_raw_get, the first
 * vehicle's passage of each; at most N windows) and prints, per encoding,
 * the bytes (total and per window), the ratio to the float64 bytes and the
 * encode and decode times per window:
 *   f64-zlib6            the float64 bytes as they are, zlib level 6
 *   f64-shuffle-zlib6    byte planes, zlib 6 (no XOR)
 *   f64-xor-shuffle-zlibL  the store's encoding at zlib levels 1 (the
 *                        store's), 6 and 9 (checked: decodes bit for bit)
 *   f32-shuffle-zlib6    rounded to float32 (lossy: the largest relative
 *                        change of a sample is printed), byte planes, zlib 6
 *   f32-xor-shuffle-zlib1  the store's float32 encoding
 *                        (daemon.store.raw.precision: float32), checked:
 *                        decodes to the samples rounded to float32
 * Exit 0, 1 (a store or window error), 2 (command line).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <zlib.h>

#include "store.h"

enum { V_PLAIN, V_SHUF, V_X1, V_X6, V_X9, V_F32, V_F32X1, NV };
static const char *const names[NV] = {"f64-zlib6",          "f64-shuffle-zlib6",
                                      "f64-xor-shuffle-zlib1 (store)", "f64-xor-shuffle-zlib6",
                                      "f64-xor-shuffle-zlib9", "f32-shuffle-zlib6 (lossy)",
                                      "f32-xor-shuffle-zlib1 (store, float32)"};

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static size_t deflated(const unsigned char *in, size_t len, int level)
{
    uLongf cap = compressBound((uLong)len);
    unsigned char *out = malloc(cap);
    if (!out || compress2(out, &cap, in, (uLong)len, level) != Z_OK) {
        free(out);
        return 0;
    }
    free(out);
    return cap;
}

/* n values of `size` bytes into byte planes. */
static void planes(const unsigned char *in, size_t n, int size, unsigned char *out)
{
    for (size_t i = 0; i < n; i++)
        for (int b = 0; b < size; b++)
            out[(size_t)b * n + i] = in[i * (size_t)size + (size_t)(size - 1 - b)];
}

static int64_t *ids;
static size_t n_ids, cap_ids;
static int collect(void *ctx, int64_t id, const amfi_passage_row *row)
{
    (void)ctx, (void)row;
    if (n_ids == cap_ids) {
        cap_ids = cap_ids ? 2 * cap_ids : 1024;
        int64_t *p = realloc(ids, cap_ids * sizeof *p);
        if (!p)
            return 1;
        ids = p;
    }
    ids[n_ids++] = id;
    return 0;
}

int main(int argc, char **argv)
{
    const char *db = NULL;
    long max = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--db") == 0 && i + 1 < argc)
            db = argv[++i];
        else if (strcmp(argv[i], "--max") == 0 && i + 1 < argc)
            max = strtol(argv[++i], NULL, 10);
        else {
            fprintf(stderr, "usage: amfi-raw-bench --db STORE [--max N]\n");
            return 2;
        }
    }
    if (!db) {
        fprintf(stderr, "usage: amfi-raw-bench --db STORE [--max N]\n");
        return 2;
    }
    char err[512];
    amfi_store *s = NULL;
    if (amfi_store_open_readonly(db, &s, err, sizeof err) != 0) {
        fprintf(stderr, "amfi-raw-bench: %s\n", err);
        return 1;
    }
    if (amfi_store_each_passage(s, 0, AMFI_STORE_MAX_UTIME, NULL, collect, NULL, err,
                                sizeof err) != 0) {
        fprintf(stderr, "amfi-raw-bench: %s\n", err);
        return 1;
    }
    double bytes[NV] = {0}, enc_s[NV] = {0}, dec_s = 0, raw_bytes = 0, max_rel32 = 0;
    long windows = 0, samples = 0;
    for (size_t k = 0; k < n_ids && (max <= 0 || windows < max); k++) {
        amfi_raw_rec r;
        int found = 0;
        if (amfi_store_raw_get(s, ids[k], &r, &found, err, sizeof err) != 0) {
            fprintf(stderr, "amfi-raw-bench: %s\n", err);
            return 1;
        }
        if (!found || r.vehicle != 0) {
            amfi_store_raw_free(&r);
            continue;
        }
        const size_t n = (size_t)r.w.n_samples * (size_t)r.w.n_sensors;
        const size_t len = n * 8;
        const unsigned char *x = (const unsigned char *)r.w.samples;
        unsigned char *pl = malloc(len);
        float *f = malloc(n * sizeof *f);
        double *back = malloc(len);
        if (!pl || !f || !back) {
            fprintf(stderr, "amfi-raw-bench: out of memory\n");
            return 1;
        }
        double t = now_s();
        bytes[V_PLAIN] += (double)deflated(x, len, 6);
        enc_s[V_PLAIN] += now_s() - t;
        t = now_s();
        planes(x, n, 8, pl);
        bytes[V_SHUF] += (double)deflated(pl, len, 6);
        enc_s[V_SHUF] += now_s() - t;
        static const int levels[3] = {1, 6, 9};
        for (int v = V_X1; v <= V_X9; v++) {
            unsigned char *blob = NULL;
            size_t blen = 0;
            t = now_s();
            if (amfi_store_raw_encode(r.w.samples, (int64_t)n, r.w.n_sensors, levels[v - V_X1], 0,
                                      &blob, &blen, err, sizeof err) != 0) {
                fprintf(stderr, "amfi-raw-bench: %s\n", err);
                return 1;
            }
            enc_s[v] += now_s() - t;
            bytes[v] += (double)blen;
            if (v == V_X1) {
                t = now_s();
                if (amfi_store_raw_decode(blob, blen, (int64_t)n, r.w.n_sensors, 0, back, err,
                                          sizeof err) != 0 ||
                    memcmp(back, r.w.samples, len) != 0) {
                    fprintf(stderr, "amfi-raw-bench: passage %lld: not decoded bit for bit\n",
                            (long long)ids[k]);
                    return 1;
                }
                dec_s += now_s() - t;
            }
            free(blob);
        }
        t = now_s();
        for (size_t i = 0; i < n; i++) {
            f[i] = (float)r.w.samples[i];
            double a = fabs(r.w.samples[i]);
            if (a > 0) {
                double rel = fabs((double)f[i] - r.w.samples[i]) / a;
                if (rel > max_rel32)
                    max_rel32 = rel;
            }
        }
        planes((const unsigned char *)f, n, 4, pl);
        bytes[V_F32] += (double)deflated(pl, n * 4, 6);
        enc_s[V_F32] += now_s() - t;
        {
            unsigned char *blob = NULL;
            size_t blen = 0;
            t = now_s();
            if (amfi_store_raw_encode(r.w.samples, (int64_t)n, r.w.n_sensors, 1, 1, &blob, &blen,
                                      err, sizeof err) != 0) {
                fprintf(stderr, "amfi-raw-bench: %s\n", err);
                return 1;
            }
            enc_s[V_F32X1] += now_s() - t;
            bytes[V_F32X1] += (double)blen;
            if (amfi_store_raw_decode(blob, blen, (int64_t)n, r.w.n_sensors, 1, back, err,
                                      sizeof err) != 0) {
                fprintf(stderr, "amfi-raw-bench: %s\n", err);
                return 1;
            }
            for (size_t i = 0; i < n; i++)
                if (back[i] != (double)f[i]) {
                    fprintf(stderr, "amfi-raw-bench: passage %lld: float32 not decoded exactly\n",
                            (long long)ids[k]);
                    return 1;
                }
            free(blob);
        }
        raw_bytes += (double)len;
        samples += (long)n;
        windows++;
        free(pl);
        free(f);
        free(back);
        amfi_store_raw_free(&r);
    }
    amfi_store_close(s);
    free(ids);
    if (windows == 0) {
        fprintf(stderr, "amfi-raw-bench: %s has no raw windows\n", db);
        return 1;
    }
    printf("amfi-raw-bench: %ld windows, %.0f samples each, %.0f float64 bytes a window\n",
           windows, (double)samples / (double)windows, raw_bytes / (double)windows);
    printf("%-31s %12s %10s %7s %10s\n", "encoding", "bytes", "a window", "ratio", "encode ms");
    for (int v = 0; v < NV; v++)
        printf("%-31s %12.0f %10.0f %7.3f %10.3f\n", names[v], bytes[v],
               bytes[v] / (double)windows, raw_bytes / bytes[v],
               1e3 * enc_s[v] / (double)windows);
    printf("decode (store's, checked bit for bit): %.3f ms a window\n",
           1e3 * dec_s / (double)windows);
    printf("float32: largest relative change of a sample %.3g\n", max_rel32);
    return 0;
}
