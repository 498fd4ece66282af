/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * web_fixture: the store the web tests serve, written through store.h's
 * checked inserts. web_fixture PATH [SITE]: 40 passages an hour apart from
 * 2026-01-10T01:00:00Z (ids 1 .. 40): k % 3 == 0 class FHWA9 (groups 1-2-2),
 * 1 A23 (1-1-3), 2 unknown (1-1); k % 10 == 3 invalid (no axles, reason
 * "detector: axle count 0"); k == 7 status error with a hostile reason
 * (HOSTILE below); k == 9 overloaded; axle j (1-based) of passage k weighs
 * 1000 k + 100 j kg; residual 0.001 k; f1 5.7 − 0.001 k Hz on even k; deck
 * 10 °C. Eight indicator rows, a baseline, three alerts (std_increase
 * raised with the hostile message: open; mean_shift raised then cleared),
 * twelve environment readings, site.id SITE (web-test), a hostile
 * site.name and amfid's intake counters.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "store.h"

#define HOSTILE "<img src=x onerror=\"window.__xss=1\">'&amp;</td><script>window.__xss=2</script>"
#define T0 INT64_C(1768006800000000) /* 2026-01-10T01:00:00Z */
#define HOUR INT64_C(3600000000)

static int check(int rc, const char *what, const char *err)
{
    if (rc != 0)
        fprintf(stderr, "web_fixture: %s: %s\n", what, err);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: web_fixture PATH [SITE]\n");
        return 2;
    }
    char err[512];
    amfi_store *s = NULL;
    if (check(amfi_store_open(argv[1], 0, &s, err, sizeof err), argv[1], err))
        return 1;
    int rc = check(amfi_store_meta_set(s, "site.id", argc > 2 ? argv[2] : "web-test", err,
                                       sizeof err), "site.id", err);
    if (!rc)
        rc = check(amfi_store_meta_set(s, "site.name", "Bridge " HOSTILE, err, sizeof err),
                   "site.name", err);
    if (!rc)
        rc = check(amfi_store_meta_set(s, "intake.messages_received", "12345", err, sizeof err),
                   "intake", err);
    if (!rc)
        rc = check(amfi_store_meta_set(s, "intake.passages_lost", "0", err, sizeof err), "intake",
                   err);
    for (int k = 1; rc == 0 && k <= 40; k++) {
        amfi_passage_row r;
        memset(&r, 0, sizeof r);
        r.vehicle_id = 1000 + k;
        r.utime = T0 + (k - 1) * HOUR;
        r.lane = 1 + k % 2;
        r.lambda = r.solve_ms = r.quality = r.reference_gvw_kg = NAN;
        r.f1_hz = r.f1_comp_hz = r.f1_zeta = r.f1_r2 = r.gvw_comp_kg = NAN;
        r.n_vehicles = 1;
        r.has_deck_c = 1;
        r.deck_c = 10.0;
        r.speed_given_mps = NAN;
        for (int j = 0; j < AMFI_MAX_AXLES; j++)
            r.spacing_m[j] = r.axle_kg[j] = NAN;
        if (k % 10 == 3) {
            r.status = "invalid";
            r.reason = "detector: axle count 0";
            r.speed_mps = r.gvw_kg = r.residual_rms = NAN;
        } else {
            const char *cls[] = {"FHWA9", "A23", "unknown"};
            const char *grp[] = {"1-2-2", "1-1-3", "1-1"};
            r.vclass = cls[k % 3];
            r.axle_groups = grp[k % 3];
            r.n_axles = k % 3 == 2 ? 2 : 5;
            r.gvw_kg = 0;
            for (int j = 0; j < r.n_axles; j++) {
                r.axle_kg[j] = 1000.0 * k + 100.0 * (j + 1);
                r.gvw_kg += r.axle_kg[j];
                if (j + 1 < r.n_axles)
                    r.spacing_m[j] = 1.3 + 0.5 * j;
            }
            r.speed_mps = 20.0;
            r.speed_given_mps = 20.5;
            r.residual_rms = 0.001 * k;
            r.formulation = "displacement";
            r.lambda = 1e-3;
            r.solve_ms = 2.5;
            r.has_overload = 1;
            r.overload = k == 9;
            if (k % 2 == 0) {
                r.f1_hz = 5.7 - 0.001 * k;
                r.f1_r2 = 0.95;
                r.f1_zeta = 0.02;
            }
            r.status = k == 7 ? "error" : "ok";
            r.reason = k == 7 ? "solver: " HOSTILE : "";
        }
        rc = check(amfi_store_add_passage(s, &r, NULL, err, sizeof err), "passage", err);
    }
    amfi_baseline b = {.utime_set = T0, .n = 30, .mean_kg = 20000, .std_kg = 4000};
    strcpy(b.source, "auto");
    if (!rc)
        rc = check(amfi_store_set_baseline(s, &b, err, sizeof err), "baseline", err);
    const char *states[] = {"baseline", "normal", "normal", "watch", "alert", "alert", "normal",
                            "normal"};
    for (int k = 0; rc == 0 && k < 8; k++) {
        amfi_indicator_row ir = {.utime = T0 + (5 * k + 2) * HOUR, .n = 10 + k,
                                 .mean_kg = 20000 + 100 * k, .std_kg = 4000 + 200 * k,
                                 .baseline_mean_kg = 20000, .baseline_std_kg = 4000,
                                 .std_ratio = 1.0 + 0.05 * k, .p_value = 0.5 - 0.05 * k,
                                 .state = states[k]};
        rc = check(amfi_store_add_indicator(s, &ir, NULL, err, sizeof err), "indicator", err);
    }
    if (!rc)
        rc = check(amfi_store_add_alert(s, T0 + 20 * HOUR, "warning", "std_increase",
                                        "STD up " HOSTILE, 0, 1, NULL, err, sizeof err),
                   "alert", err);
    if (!rc)
        rc = check(amfi_store_add_alert(s, T0 + 21 * HOUR, "info", "mean_shift", "mean shift", 0,
                                        1, NULL, err, sizeof err), "alert", err);
    if (!rc)
        rc = check(amfi_store_add_alert(s, T0 + 30 * HOUR, "info", "mean_shift",
                                        "mean shift cleared", 0, 0, NULL, err, sizeof err),
                   "alert", err);
    amfi_environment_row env[12];
    for (int k = 0; k < 12; k++)
        env[k] = (amfi_environment_row){.utime = T0 + k * 3 * HOUR, .deck_c = 5.0 + k,
                                        .air_c = 3.0 + k, .received_utime = T0 + k * 3 * HOUR};
    if (!rc)
        rc = check(amfi_store_add_environment(s, env, 12, err, sizeof err), "environment", err);
    amfi_store_close(s);
    return rc ? 1 : 0;
}
