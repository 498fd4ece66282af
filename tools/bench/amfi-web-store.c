/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi-web-store PATH N [DAYS]: a new store of N passages over DAYS days
 * (365) from 2025-01-01 for amfi-web's benchmark (tools/bench/amfi-web-bench,
 * docs/results/web.md): evenly spaced passages of five classes (2 to 5 axles
 * with their axle rows), 95 % ok, the rest gap, multiple and invalid with a
 * reason; the fit residual on all weighed ones, a natural frequency on every
 * tenth, a deck temperature; an indicator row per 500 passages, an alert
 * raised and cleared every 200 indicators, an environment reading every 10
 * minutes. Written by the store's inserter in one transaction (store.h,
 * rows as column values). Deterministic (a fixed LCG). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store.h"

static amfi_store_value vi(int64_t x) { return (amfi_store_value){.type = AMFI_SQL_INTEGER, .i = x}; }
static amfi_store_value vr(double x) { return (amfi_store_value){.type = AMFI_SQL_REAL, .r = x}; }
static amfi_store_value vt(const char *t) { return (amfi_store_value){.type = AMFI_SQL_TEXT, .text = t}; }
static const amfi_store_value vnull = {0};

static uint64_t lcg = 88172645463325252ULL;
static double uni(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc > 4) {
        fprintf(stderr, "usage: amfi-web-store PATH N [DAYS]\n");
        return 2;
    }
    const char *path = argv[1];
    long n = strtol(argv[2], NULL, 10), days = argc > 3 ? strtol(argv[3], NULL, 10) : 365;
    if (n < 1 || n > 100000000 || days < 1 || days > 36500) {
        fprintf(stderr, "amfi-web-store: N in [1, 1e8], DAYS in [1, 36500]\n");
        return 2;
    }
    if (access(path, F_OK) == 0) {
        fprintf(stderr, "amfi-web-store: %s exists\n", path);
        return 1;
    }
    static const char *const pcols[] = {"id", "vehicle_id", "utime", "lane", "speed_mps",
                                        "n_axles", "gvw_kg", "status", "reason", "residual_rms",
                                        "class", "axle_groups", "overload", "f1_hz", "deck_c"};
    static const char *const acols[] = {"passage_id", "idx", "spacing_m", "load_kg"};
    static const char *const icols[] = {"utime", "n", "mean_kg", "std_kg", "baseline_mean_kg",
                                        "baseline_std_kg", "std_ratio", "p_value", "state"};
    static const char *const lcols[] = {"utime", "level", "kind", "message", "raised"};
    static const char *const ecols[] = {"utime", "deck_c", "air_c", "received_utime"};
    static const struct { const char *cls, *groups; int axles; } kinds[] = {
        {"FHWA5", "1-1", 2}, {"FHWA6", "1-2", 3}, {"FHWA9", "1-2-2", 5}, {"A23", "1-1-3", 5},
        {"unknown", "1-1", 2}};
    char err[512];
    amfi_store *s = NULL;
    amfi_store_inserter *ps = NULL, *ax = NULL, *ind = NULL, *al = NULL, *env = NULL;
    int rc = 1;
    const int64_t t0 = INT64_C(1735689600000000); /* 2025-01-01 */
    const double step_us = (double)days * 86400e6 / (double)n;
    if (amfi_store_open(path, 0, &s, err, sizeof err) != 0
        || amfi_store_meta_set(s, "site.id", "web-bench", err, sizeof err) != 0
        || amfi_store_meta_set(s, "intake.messages_received", "123456789", err, sizeof err) != 0
        || amfi_store_inserter_open(s, "passages", pcols, 15, &ps, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "axles", acols, 4, &ax, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "indicators", icols, 9, &ind, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "alerts", lcols, 5, &al, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "environment", ecols, 4, &env, err, sizeof err) != 0
        || amfi_store_transaction(s, AMFI_STORE_TX_WRITE, err, sizeof err) != 0)
        goto out;
    long nind = 0;
    for (long i = 1; i <= n; i++) {
        int64_t ut = t0 + (int64_t)((double)(i - 1) * step_us);
        int k = (int)(uni() * 5);
        double u = uni();
        const char *status = u < 0.95 ? "ok" : u < 0.97 ? "gap" : u < 0.99 ? "multiple" : "invalid";
        int weighed = strcmp(status, "ok") == 0;
        int na = kinds[k].axles;
        double load[5], gvw = 0;
        for (int a = 0; a < na; a++) {
            load[a] = 3000 + 6000 * uni();
            gvw += load[a];
        }
        amfi_store_value pv[15] = {
            vi(i), vi(i), vi(ut), vi(1 + (int)(i % 2)), vr(22 + 6 * uni()), vi(na),
            weighed ? vr(gvw) : vnull, vt(status),
            vt(weighed ? "" : u < 0.97 ? "gap in the accelerations" : u < 0.99
               ? "another vehicle on the span" : "detector: axle count 0"),
            weighed ? vr(0.01 + 0.002 * uni()) : vnull, vt(kinds[k].cls), vt(kinds[k].groups),
            weighed ? vi(gvw > 40000) : vnull, i % 10 == 0 ? vr(5.7 + 0.1 * uni()) : vnull,
            vr(10 + 10 * uni())};
        if (amfi_store_insert_values(ps, pv, err, sizeof err) != 0)
            goto out;
        for (int a = 1; a <= na; a++) {
            amfi_store_value av[4] = {vi(i), vi(a), a == 1 ? vnull : vr(1.3 + 3 * uni()),
                                      weighed ? vr(load[a - 1]) : vnull};
            if (amfi_store_insert_values(ax, av, err, sizeof err) != 0)
                goto out;
        }
        if (i % 500 == 0) {
            nind++;
            double ratio = 0.9 + 0.3 * uni();
            amfi_store_value iv[9] = {vi(ut), vi(500), vr(20000 + 1000 * uni()),
                                      vr(9000 * ratio), vr(20000), vr(9000), vr(ratio),
                                      vr(0.5 * uni()), vt(ratio > 1.15 ? "watch" : "normal")};
            if (amfi_store_insert_values(ind, iv, err, sizeof err) != 0)
                goto out;
            if (nind % 200 == 100 || nind % 200 == 101) {
                amfi_store_value lv[5] = {vi(ut), vt("warning"), vt("std_increase"),
                                          vt("bench alert"), vi(nind % 200 == 100)};
                if (amfi_store_insert_values(al, lv, err, sizeof err) != 0)
                    goto out;
            }
        }
    }
    for (int64_t t = t0; t < t0 + (int64_t)days * INT64_C(86400000000); t += INT64_C(600000000)) {
        amfi_store_value ev[4] = {vi(t), vr(5 + 20 * uni()), vr(3 + 20 * uni()), vi(t)};
        if (amfi_store_insert_values(env, ev, err, sizeof err) != 0)
            goto out;
    }
    if (amfi_store_transaction(s, AMFI_STORE_TX_COMMIT, err, sizeof err) != 0)
        goto out;
    rc = 0;
out:
    if (rc)
        fprintf(stderr, "amfi-web-store: %s: %s\n", path, err);
    amfi_store_inserter_close(ps);
    amfi_store_inserter_close(ax);
    amfi_store_inserter_close(ind);
    amfi_store_inserter_close(al);
    amfi_store_inserter_close(env);
    amfi_store_close(s);
    return rc;
}
