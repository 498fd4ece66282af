/* SPDX-License-Identifier: GPL-3.0-or-later */
/* web_raw.c: a passage's raw samples for /api/passages/ID (web.h), read with
 * amfi_store_raw_get (store.h, "raw samples"; docs/web.md has the shape):
 *
 *   {"window_id", "vehicle": this passage's index in "vehicles",
 *    "rate_hz", "t0_utime" / "t0_utc": the data time of sample 0,
 *    "n_samples": per sensor as stored, "precision": "float64"|"float32",
 *    "t_entry_s": this passage's vehicle's entry after sample 0, s,
 *    "t_last_axle_s": its last axle's entry (entry + sum of spacings / speed),
 *    "exit_marked": false, "exit_reason": why (the span is not stored),
 *    "decimated": k (absent when every sample is sent),
 *    "sensors": [{"id", "at_m", "samples": [...]}],
 *    "vehicles": [{"vehicle_id", "utime_utc", "t_entry_s", "t_last_axle_s",
 *                  "lane", "speed_mps", "n_axles", "spacing_m": [...]}]}
 *
 * The size sent to a browser is bounded: a sensor of more than
 * WEB_RAW_MAX_POINTS samples is cut into buckets of k samples and each
 * bucket sends its minimum and its maximum, in the order they occur, so
 * that peaks survive; point 2b and 2b + 1 are bucket b (samples b·k ..
 * b·k + k − 1).
 *
 * No samples: NULL and *why says which (the central database ships none;
 * the passage's window never weighed; not kept or deleted by retention; a
 * damaged row or blob, named). */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "web.h"

/* Per sensor, at most this many points go to a browser. */
#define WEB_RAW_MAX_POINTS 4000

static json_t *vehicle_json(const amfi_raw_vehicle *v, int64_t t0)
{
    char t[40];
    json_t *o = json_object();
    const double entry = 1e-6 * (double)(v->utime - t0);
    double len = 0.0;
    json_t *sp = json_array();
    for (int a = 0; a + 1 < v->n_axles; a++) {
        len += v->spacing_m[a];
        json_array_append_new(sp, json_real(v->spacing_m[a]));
    }
    json_object_set_new(o, "vehicle_id", json_integer((json_int_t)v->vehicle_id));
    json_object_set_new(o, "utime_utc", json_string(web_format_time(v->utime, t, sizeof t)));
    json_object_set_new(o, "t_entry_s", json_real(entry));
    json_object_set_new(o, "t_last_axle_s", json_real(entry + len / v->speed_mps));
    json_object_set_new(o, "lane", json_integer(v->lane));
    json_object_set_new(o, "speed_mps", json_real(v->speed_mps));
    json_object_set_new(o, "n_axles", json_integer(v->n_axles));
    json_object_set_new(o, "spacing_m", sp);
    return o;
}

/* n samples x into at most WEB_RAW_MAX_POINTS points: every sample (k 1),
 * or the min and max of each bucket of k samples in time order. */
static json_t *samples_json(const double *x, int n, int k)
{
    json_t *a = json_array();
    if (k <= 1) {
        for (int i = 0; i < n; i++)
            json_array_append_new(a, json_real(x[i]));
        return a;
    }
    for (int b = 0; b < n; b += k) {
        const int e = b + k < n ? b + k : n;
        int lo = b, hi = b;
        for (int i = b + 1; i < e; i++) {
            if (x[i] < x[lo])
                lo = i;
            if (x[i] > x[hi])
                hi = i;
        }
        json_array_append_new(a, json_real(x[lo < hi ? lo : hi]));
        json_array_append_new(a, json_real(x[lo < hi ? hi : lo]));
    }
    return a;
}

/* The bucket length for n samples: 1 when they fit. */
static int bucket(int n)
{
    if (n <= WEB_RAW_MAX_POINTS)
        return 1;
    const int half = WEB_RAW_MAX_POINTS / 2;
    return (n + half - 1) / half;
}

static json_t *raw_json(const amfi_raw_rec *r)
{
    const amfi_raw_window *w = &r->w;
    char t[40];
    const int64_t t0 = w->utime + (int64_t)llround(w->t_first_s * 1e6);
    json_t *o = json_object();
    json_object_set_new(o, "window_id", json_integer((json_int_t)r->window_id));
    json_object_set_new(o, "vehicle", json_integer(r->vehicle));
    json_object_set_new(o, "rate_hz", json_real(w->rate_hz));
    json_object_set_new(o, "t0_utime", json_integer((json_int_t)t0));
    json_object_set_new(o, "t0_utc", json_string(web_format_time(t0, t, sizeof t)));
    json_object_set_new(o, "n_samples", json_integer(w->n_samples));
    json_object_set_new(o, "precision", json_string(r->float32 ? "float32" : "float64"));
    json_t *vs = json_array();
    for (int v = 0; v < w->n_vehicles; v++)
        json_array_append_new(vs, vehicle_json(&w->vehicle[v], t0));
    json_t *mine = json_array_get(vs, (size_t)r->vehicle);
    json_object_set(o, "t_entry_s", json_object_get(mine, "t_entry_s"));
    json_object_set(o, "t_last_axle_s", json_object_get(mine, "t_last_axle_s"));
    json_object_set_new(o, "exit_marked", json_false());
    json_object_set_new(o, "exit_reason",
                        json_string("the store does not record the span length, which the exit "
                                    "needs (entry + (span + sum of spacings) / speed); "
                                    "t_last_axle_s is the last axle's entry"));
    const int k = bucket(w->n_samples);
    if (k > 1)
        json_object_set_new(o, "decimated", json_integer(k));
    json_t *ss = json_array();
    for (int i = 0; i < w->n_sensors; i++) {
        json_t *s = json_object();
        json_object_set_new(s, "id", json_integer(w->sensor_id[i]));
        json_object_set_new(s, "at_m", json_real(w->sensor_at_m[i]));
        json_object_set_new(s, "samples",
                            samples_json(w->samples + (size_t)i * (size_t)w->n_samples,
                                         w->n_samples, k));
        json_array_append_new(ss, s);
    }
    json_object_set_new(o, "sensors", ss);
    json_object_set_new(o, "vehicles", vs);
    return o;
}

/* Not kept, or deleted by the retention: the retention deletes oldest first
 * (utime, id), so a window of a single vehicle (utime the passage's) after
 * the oldest one kept was never deleted by it. */
static void not_kept(amfi_store *s, const amfi_web_passage *p, char *why, size_t whylen)
{
    static const char keep[] = "not kept (daemon.store.raw.keep: none, or failed and the "
                               "passage was stored ok; or its raw rows could not be written: "
                               "amfid's log says so)";
    int64_t oldest = 0;
    int found = 0;
    char err[300], t[40];
    if (amfi_store_raw_oldest(s, &oldest, &found, err, sizeof err) != 0) {
        snprintf(why, whylen, "no raw samples: %s or deleted by the retention "
                              "(daemon.store.raw.max_age_days, max_mib); the oldest window "
                              "kept could not be read: %s", keep, err);
    } else if (found && oldest < p->row.utime && p->row.n_vehicles <= 1) {
        snprintf(why, whylen, "no raw samples: %s; not the retention, which has deleted no "
                              "window this recent (the oldest kept is from %s)",
                 keep, web_format_time(oldest, t, sizeof t));
    } else {
        snprintf(why, whylen, "no raw samples: %s or deleted by the retention "
                              "(daemon.store.raw.max_age_days, max_mib): %s", keep,
                 found ? "the passage is not newer than the oldest window kept"
                       : "the store holds no raw window");
        if (found) {
            size_t n = strlen(why);
            snprintf(why + n, whylen - n, " (%s)", web_format_time(oldest, t, sizeof t));
        }
    }
}

json_t *web_raw(const web_source *src, const amfi_web_passage *p, char *why, size_t whylen)
{
    if (strcmp(src->kind, "central") == 0) {
        snprintf(why, whylen, "the central database does not ship raw samples (amfi-sync "
                              "leaves them in the site's store): serve the site's store "
                              "(amfi-web --db) to see them");
        return NULL;
    }
    amfi_raw_rec r;
    int found = 0;
    char err[400];
    const char *status = p->status, *reason = p->reason;
    int rc = amfi_store_raw_get(src->store, p->id, &r, &found, err, sizeof err);
    if (rc == AMFI_STORE_ECORRUPT) {
        snprintf(why, whylen, "the raw samples are damaged: %s", err);
        return NULL;
    }
    if (rc != 0) {
        snprintf(why, whylen, "the raw samples could not be read: %s", err);
        return NULL;
    }
    if (!found) {
        if (strcmp(status, "gap") == 0 || strcmp(status, "late") == 0 ||
            strcmp(status, "invalid") == 0 ||
            (strcmp(status, "multiple") == 0 && strncmp(reason, "inseparable:", 12) != 0))
            snprintf(why, whylen, "no raw samples: the passage's window was never complete or "
                                  "never weighed (status %s), so amfid had none to keep",
                     status);
        else
            not_kept(src->store, p, why, whylen);
        return NULL;
    }
    json_t *o = raw_json(&r);
    amfi_store_raw_free(&r);
    return o;
}
