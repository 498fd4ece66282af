/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * web_fixture: the store the web tests serve, written through store.h's
 * checked inserts. web_fixture PATH [SITE]: 40 passages an hour apart from
 * 2026-01-10T01:00:00Z (ids 1 .. 40): k % 3 == 0 class FHWA9 (groups 1-2-2),
 * 1 A23 (1-1-3), 2 unknown (1-1); k % 10 == 3 invalid (no axles, reason
 * "detector: axle count 0"); k == 7 status error with a hostile reason
 * (HOSTILE below); k == 9 overloaded; k == 12 its loads refused by the
 * classification (overload NULL, the reason hostile); axle j (1-based) of passage k weighs
 * 1000 k + 100 j kg; residual 0.001 k; f1 5.7 − 0.001 k Hz on even k;
 * model fit ratio 0.01 k on odd k (15 ok passages); deck 10 °C; amfid's
 * model_mismatch rule recorded (meta alerts.model_fit: MODEL_FIT). Eight indicator rows, a baseline, three alerts (std_increase
 * raised with the hostile message: open; mean_shift raised then cleared),
 * twelve environment readings, site.id SITE (web-test), a hostile
 * site.name and amfid's intake counters.
 *
 * Raw samples (amfi_passage_row.raw, store.h): passage 5 a window of two
 * sensors (ids 3, 7 at 10 and 15.125 m) × 1500 samples at 1000 Hz, float64,
 * sample 0 at −0.5 s; passage 11 a long one, three sensors × 30000 samples
 * at 1000 Hz stored as float32, with one spike of 5.0 at sample 12345 of
 * its second sensor (a browser gets it decimated); passages 14 and 15 one
 * event window of two vehicles (two sensors × 2000 samples at 500 Hz,
 * held by 14, linked by 15, the second vehicle entering 1.2 s after the
 * first); passage 2 a window deleted by the retention (amfi_store_raw_prune)
 * and passage 17 one whose blob is then damaged by raw SQL
 * (store_testing.h).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "store.h"
#include "store_testing.h"

#define HOSTILE "<img src=x onerror=\"window.__xss=1\">'&amp;</td><script>window.__xss=2</script>"
#define MODEL_FIT "enabled=1 window=5 raise=0.2 clear=0.1 raise_after=3 clear_after=4"
#define T0 INT64_C(1768006800000000) /* 2026-01-10T01:00:00Z */
#define HOUR INT64_C(3600000000)

/* The raw window of passage k (2, 5, 11, 14), samples into buf. */
static double buf[3 * 30000];
static void make_window(amfi_raw_window *w, int k, int64_t utime, double speed, int n_axles,
                        const double *spacing)
{
    memset(w, 0, sizeof *w);
    const int long_one = k == 11, event = k == 14;
    w->utime = utime;
    w->rate_hz = event ? 500 : 1000;
    w->t_first_s = -0.5;
    w->n_samples = long_one ? 30000 : event ? 2000 : k == 2 ? 500 : 1500;
    w->n_sensors = long_one ? 3 : k == 2 ? 1 : 2;
    for (int i = 0; i < w->n_sensors; i++) {
        w->sensor_id[i] = 3 + 4 * i;
        w->sensor_at_m[i] = 10.0 + 5.125 * i;
        for (int j = 0; j < w->n_samples; j++)
            buf[i * w->n_samples + j] = 0.01 * (i + 1) * sin(0.013 * j + i) + 1e-4 * (j % 7);
    }
    if (long_one)
        buf[w->n_samples + 12345] = 5.0;
    w->n_vehicles = event ? 2 : 1;
    for (int v = 0; v < w->n_vehicles; v++) {
        amfi_raw_vehicle *e = &w->vehicle[v];
        e->vehicle_id = 1000 + k + v;
        e->utime = utime + v * INT64_C(1200000);
        e->lane = 1 + (k + v) % 2;
        e->speed_mps = speed;
        e->n_axles = n_axles;
        for (int a = 0; a + 1 < n_axles; a++)
            e->spacing_m[a] = spacing[a];
    }
    amfi_lambda_default(&w->lambda);
    amfi_speed_prior_default(&w->speed_prior);
    w->samples = buf;
}

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
    int64_t event_window = 0;
    for (int k = 1; rc == 0 && k <= 40; k++) {
        amfi_passage_row r;
        amfi_raw_window w;
        amfi_raw_put put;
        memset(&put, 0, sizeof put);
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
            r.fit_ratio = k % 2 && k != 7 ? 0.01 * k : NAN; /* amfid fits ok passages */
            r.formulation = "displacement";
            r.lambda = 1e-3;
            r.solve_ms = 2.5;
            r.has_overload = k != 12;
            r.overload = k == 9;
            if (k == 12) /* the classification refused the loads: never an overload */
                r.loads_refused = "group 2: " HOSTILE;
            if (k % 2 == 0) {
                r.f1_hz = 5.7 - 0.001 * k;
                r.f1_r2 = 0.95;
                r.f1_zeta = 0.02;
            }
            r.status = k == 7 ? "error" : "ok";
            r.reason = k == 7 ? "solver: " HOSTILE : "";
        }
        if (k == 2 || k == 5 || k == 11 || k == 14 || k == 17) {
            make_window(&w, k, r.utime, r.speed_mps, r.n_axles, r.spacing_m);
            put.window = &w;
            put.float32 = k == 11;
            r.raw = &put;
            r.n_vehicles = k == 14 ? 2 : 1;
        } else if (k == 15) {
            put.window_id = event_window;
            put.vehicle = 1;
            r.raw = &put;
            r.n_vehicles = 2;
        }
        rc = check(amfi_store_add_passage(s, &r, NULL, err, sizeof err), "passage", err);
        if (rc == 0 && r.raw && put.status != 0)
            rc = check(put.status, "raw samples", put.err);
        if (k == 14)
            event_window = put.stored_window_id;
    }
    /* the retention deletes passage 2's window (the only one before 01:30Z
     * of the second hour) */
    amfi_raw_pruned pr;
    if (!rc)
        rc = check(amfi_store_raw_prune(s, T0 + HOUR + HOUR / 2, -1, 10, &pr, err, sizeof err),
                   "raw retention", err);
    if (!rc && pr.by_age != 1)
        rc = check(1, "raw retention", "not one window deleted");
    if (!rc)
        rc = check(amfi_store_meta_set(s, "alerts.model_fit", MODEL_FIT, err, sizeof err),
                   "meta", err);
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
    /* passage 17's blob damaged in the middle (its length kept) */
    amfi_store_test_db *db = rc ? NULL : amfi_store_test_open(argv[1], 0, err, sizeof err);
    if (!rc && !db)
        rc = check(1, "store_testing", err);
    if (!rc)
        rc = check(amfi_store_test_exec(db,
                                        "UPDATE raw_windows SET samples = CAST(substr(samples, "
                                        "1, bytes / 2) || x'00ff00ff' || substr(samples, bytes "
                                        "/ 2 + 5) AS BLOB) WHERE id = (SELECT window_id FROM "
                                        "passage_raw WHERE passage_id = 17)",
                                        err, sizeof err),
                   "damage", err);
    amfi_store_test_close(db);
    return rc ? 1 : 0;
}
