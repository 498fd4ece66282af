/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * passage.c: simulate and measure one passage (see passage.h).
 */
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "passage.h"
#include "vclass.h"

/* the length from the first to the last axle */
static double length_m(const amfi_halfcar *c, const amfi_truck *t)
{
    return t->n_axles ? t->x_m[t->n_axles - 1] : c->D1_m + c->D2_m;
}

static double on_span_s(double L, const amfi_halfcar *c, const amfi_truck *t, double v)
{
    return (L + length_m(c, t)) / v;
}

int amfi_passage_axles(const amfi_passage_spec *spec, double *W_N, double *x_m)
{
    if (spec->truck.n_axles) {
        for (int i = 0; i < spec->truck.n_axles; i++) {
            W_N[i] = spec->truck.W_N[i];
            x_m[i] = spec->truck.x_m[i];
        }
        return spec->truck.n_axles;
    }
    amfi_halfcar c = spec->car;
    amfi_halfcar_finish(&c, NULL, 0);
    W_N[0] = c.W_N[0];
    W_N[1] = c.W_N[1];
    x_m[0] = 0.0;
    x_m[1] = c.D1_m + c.D2_m;
    return 2;
}

int amfi_passage_spec_from_rec(const amfi_vehicle_rec *rec, const amfi_halfcar_dist *d,
                               const amfi_profile *prof, double std_tracks, gsl_rng *rng,
                               amfi_passage_spec *spec, char *err, size_t errlen)
{
    memset(spec, 0, sizeof *spec);
    if (rec->n_axles == 2) {
        if (amfi_halfcar_from_weights(rec->gvw_kg, rec->axle_kg[0], rec->axle_kg[1],
                                      rec->spacing_m[0], d, rng, &spec->car, err, errlen))
            return -1;
    } else {
        const amfi_vclass *c = amfi_vclass_get(rec->vclass);
        if (!c) {
            snprintf(err, errlen, "no vehicle class (%s) fits its %d axles and spacings",
                     amfi_vclass_names(), rec->n_axles);
            return -1;
        }
        char e2[200];
        if (amfi_vclass_truck(c, rec->axle_kg, rec->spacing_m, rng, &spec->truck, e2,
                              sizeof e2)) {
            snprintf(err, errlen, "class %s: %s", c->name, e2);
            return -1;
        }
    }
    spec->speed_mps = rec->speed_mps;
    spec->track = prof ? (rng ? amfi_profile_draw_track(prof, std_tracks, rng)
                              : amfi_profile_tracks(prof) / 2)
                       : 0;
    return 0;
}

int amfi_passage_samples(const amfi_bridge *b, const amfi_sim_params *sp,
                         const amfi_passage_spec *spec)
{
    const double L = amfi_bridge_params_of(b)->span_m;
    double T = spec->pre_s + on_span_s(L, &spec->car, &spec->truck, spec->speed_mps) +
               spec->post_s;
    return (int)ceil(T * sp->scan_rate_hz - 1e-9) + 1;
}

int amfi_passage_simulate(const amfi_bridge *b, const amfi_profile *prof,
                          const amfi_sim_params *sp, const amfi_passage_spec *spec,
                          const amfi_measure *m, gsl_rng *rng, double *accel, int cap,
                          amfi_passage_rec *out, char *err, size_t errlen)
{
    const double L = amfi_bridge_params_of(b)->span_m;
    const double f = sp->scan_rate_hz;
    const int ns = sp->n_sensors;
    if (!(spec->speed_mps > 0) || !(spec->pre_s >= 0) || !(spec->post_s >= 0) ||
        (spec->preceding && !(spec->prec_speed_mps > 0))) {
        snprintf(err, errlen, "passage: speeds must be > 0 and the record window >= 0");
        return -1;
    }
    if ((m->noise_frac > 0 || m->speed_err_std > 0) && !rng) {
        snprintf(err, errlen, "passage: noise or speed error needs a random generator");
        return -1;
    }
    amfi_halfcar car = spec->car, pcar = spec->prec_car;
    if ((!spec->truck.n_axles && amfi_halfcar_finish(&car, err, errlen)) ||
        (spec->preceding && !spec->prec_truck.n_axles && amfi_halfcar_finish(&pcar, err, errlen)))
        return -1;
    /* Times, with the target's entry at T_e; the simulation starts (t = 0) when
     * the first vehicle starts its approach, snapped to a sample. */
    double t0_target = -sp->approach_m / spec->speed_mps; /* relative to T_e */
    double t0 = t0_target, prec_entry = 0.0;
    if (spec->preceding) {
        prec_entry = -spec->gap_s - on_span_s(L, &pcar, &spec->prec_truck, spec->prec_speed_mps);
        t0 = fmin(t0, prec_entry - sp->approach_m / spec->prec_speed_mps);
    }
    t0 = fmin(t0, -spec->pre_s);
    const double Te = ceil(-t0 * f) / f; /* target entry on the sample grid */
    const int n = amfi_passage_samples(b, sp, spec);
    if (n > cap) {
        snprintf(err, errlen, "passage: %d samples exceed the buffer of %d", n, cap);
        return -1;
    }
    amfi_sim *s = NULL;
    if (amfi_sim_create(b, prof, sp, &s, err, errlen))
        return -1;
    amfi_sim_vehicle v;
    memset(&v, 0, sizeof v);
    int rc = -1;
    if (spec->preceding) {
        v.id = 1;
        v.car = pcar;
        v.truck = spec->prec_truck;
        v.speed_mps = spec->prec_speed_mps;
        v.t_entry_s = Te + prec_entry;
        v.track = spec->prec_track;
        if (amfi_sim_add(s, &v, err, errlen))
            goto out;
    }
    v.id = 0;
    v.car = car;
    v.truck = spec->truck;
    v.speed_mps = spec->speed_mps;
    v.t_entry_s = Te;
    v.track = spec->track;
    if (amfi_sim_add(s, &v, err, errlen))
        goto out;
    /* Run up to the record's start, sample by sample into the buffer (it
     * is overwritten by the record), then record. */
    const long skip = lround((Te - spec->pre_s) * f);
    for (long k = 0; k < skip; k += cap) {
        int chunk = (int)(skip - k < cap ? skip - k : cap);
        if (amfi_sim_advance(s, chunk, accel, err, errlen))
            goto out;
    }
    if (amfi_sim_advance(s, n, accel, err, errlen))
        goto out;
    /* Let the target leave so that its truth is complete. */
    memset(&out->truth, 0, sizeof out->truth);
    int found = 0;
    for (int guard = 0; guard < 100000 && !found; guard++) {
        amfi_sim_vehicle d;
        while (amfi_sim_pop_done(s, &d))
            if (d.id == 0) {
                out->truth = d;
                found = 1;
            }
        if (!found) {
            double scratch[AMFI_MAX_SENSORS];
            if (amfi_sim_advance(s, 1, scratch, err, errlen))
                goto out;
        }
    }
    if (!found) {
        snprintf(err, errlen, "passage: the vehicle did not leave the simulation");
        goto out;
    }
    /* Measurement model. */
    for (int i = 0; i < ns && m->noise_frac > 0; i++) {
        double rms = 0.0;
        for (int k = 0; k < n; k++)
            rms += accel[(size_t)k * ns + i] * accel[(size_t)k * ns + i];
        rms = sqrt(rms / n);
        for (int k = 0; k < n; k++)
            accel[(size_t)k * ns + i] += gsl_ran_gaussian(rng, m->noise_frac * rms);
    }
    double e = m->speed_err_mean + (m->speed_err_std > 0 ? gsl_ran_gaussian(rng, m->speed_err_std) : 0.0);
    out->speed_measured_mps = spec->speed_mps * (1.0 + e);
    out->n = n;
    out->n_sensors = ns;
    out->t_first_s = skip / f - Te; /* −pre_s, on the sample grid */
    rc = 0;
out:
    amfi_sim_destroy(s);
    return rc;
}
