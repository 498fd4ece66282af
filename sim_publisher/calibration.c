/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * calibration.c: calibration runs and the ambient record (calibration.h).
 */
#include <errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calibration.h"
#include "passage.h"
#include "vclass.h"

static int failf(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int failf(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (err && errlen)
        vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

/* A comma-separated list of at most max numbers in (0, hi]; the count, or −1. */
static int num_list(const char *s, double *out, int max, double hi)
{
    int n = 0;
    const char *p = s;
    for (;;) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno || !(v > 0 && v <= hi) || n == max)
            return -1;
        out[n++] = v;
        if (*end == ',') {
            p = end + 1;
            continue;
        }
        return *end == '\0' ? n : -1;
    }
}

int amfi_cal_truck_parse(const char *s, amfi_cal_truck *t, char *err, size_t errlen)
{
    char buf[512];
    memset(t, 0, sizeof *t);
    if (strlen(s) >= sizeof buf)
        return failf(err, errlen, "too long");
    strcpy(buf, s);
    char *slash = strchr(buf, '/');
    if (!slash)
        return failf(err, errlen, "expected SPACINGS/LOADS, e.g. 5.0/7000,11000 "
                     "(axle spacings in m, then static axle loads in kg, front to back)");
    *slash = '\0';
    int ns = num_list(buf, t->spacing_m, AMFI_MAX_AXLES - 1, 100.0);
    if (ns < 1)
        return failf(err, errlen, "axle spacings: 1 .. %d numbers in (0, 100] m, "
                     "separated by commas", AMFI_MAX_AXLES - 1);
    int nl = num_list(slash + 1, t->axle_kg, AMFI_MAX_AXLES, 100000.0);
    if (nl < 2)
        return failf(err, errlen, "axle loads: 2 .. %d numbers in (0, 100000] kg, "
                     "separated by commas", AMFI_MAX_AXLES);
    if (nl != ns + 1)
        return failf(err, errlen, "%d axle spacings need %d axle loads, got %d", ns, ns + 1,
                     nl);
    t->n_axles = nl;
    return 0;
}

int amfi_cal_default_trucks(amfi_cal_truck t[AMFI_CAL_MAX_TRUCKS])
{
    memset(t, 0, sizeof *t * 2);
    t[0] = (amfi_cal_truck){.n_axles = 2, .spacing_m = {5.0}, .axle_kg = {7000.0, 11000.0}};
    t[1] = (amfi_cal_truck){.n_axles = 5,
                            .spacing_m = {3.6, 5.5, 1.3, 1.3},
                            .axle_kg = {7000.0, 11000.0, 7300.0, 7300.0, 7400.0}};
    return 2;
}

/* A generator for run i: the same (seed, i), the same draws. */
static void seed_run(gsl_rng *r, unsigned long seed, long i)
{
    unsigned long long h = (unsigned long long)seed * 0xD1B54A32D192ED03ull + 0xCA11u +
                           (unsigned long long)i * 0x9E3779B97F4A7C15ull;
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    gsl_rng_set(r, (unsigned long)(h & 0xffffffffu) | 1u);
}

/* The header: t,accel for one sensor, t,accel_ID,... for several. */
static void write_header(FILE *f, int ns, const int *ids)
{
    fputs("t", f);
    if (ns == 1)
        fputs(",accel", f);
    else
        for (int i = 0; i < ns; i++)
            fprintf(f, ",accel_%d", ids[i]);
    fputc('\n', f);
}

int amfi_sim_write_accel(const char *path, int n, int ns, const int *ids, double rate,
                         const double *acc, char *err, size_t errlen)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return failf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
    write_header(f, ns, ids);
    for (int k = 0; k < n; k++) {
        fprintf(f, "%.6f", k / rate);
        for (int i = 0; i < ns; i++)
            fprintf(f, ",%.9g", acc[(size_t)k * ns + i]);
        fputc('\n', f);
    }
    if (fclose(f) != 0)
        return failf(err, errlen, "%s: write failed", path);
    return 0;
}

/* Noise: a fraction of each sensor's RMS, then a fixed std in m/s². */
static void add_noise(double *acc, int n, int ns, double frac, double ms2, gsl_rng *r)
{
    for (int i = 0; i < ns; i++) {
        if (frac > 0) {
            double rms = 0.0;
            for (int k = 0; k < n; k++)
                rms += acc[(size_t)k * ns + i] * acc[(size_t)k * ns + i];
            rms = sqrt(rms / n);
            for (int k = 0; k < n; k++)
                acc[(size_t)k * ns + i] += gsl_ran_gaussian(r, frac * rms);
        }
        if (ms2 > 0)
            for (int k = 0; k < n; k++)
                acc[(size_t)k * ns + i] += gsl_ran_gaussian(r, ms2);
    }
}

void amfi_sim_put_list(FILE *f, const double *v, int n, const char *fmt)
{
    for (int i = 0; i < n; i++) {
        if (i)
            fputc(';', f);
        fprintf(f, fmt, v[i]);
    }
}

typedef struct forces {
    const double *W_N;
} forces;

static double constant_force(double t_s, int axle, void *user)
{
    (void)t_s;
    return ((const forces *)user)->W_N[axle];
}

/* One run of the constant moving forces of truck t at speed v: the front
 * axle enters at t = pre_s of the record. *n_out samples into *acc
 * (allocated). */
static int run_forces(const amfi_bridge *b, const amfi_sim_params *sp, const amfi_cal_truck *t,
                      double v, double pre_s, double tail_s, double **acc, int *n_out,
                      char *err, size_t errlen)
{
    const double L = amfi_bridge_params_of(b)->span_m;
    double off[AMFI_MAX_AXLES], W[AMFI_MAX_AXLES], len = 0.0;
    off[0] = v * pre_s;
    W[0] = t->axle_kg[0] * AMFI_GRAVITY;
    for (int a = 1; a < t->n_axles; a++) {
        len += t->spacing_m[a - 1];
        off[a] = off[0] + len;
        W[a] = t->axle_kg[a] * AMFI_GRAVITY;
    }
    const double T = pre_s + (L + len) / v + tail_s;
    const int n = (int)ceil(T * sp->scan_rate_hz - 1e-9) + 1;
    *acc = malloc(sizeof(double) * (size_t)n * (size_t)sp->n_sensors);
    if (!*acc)
        return failf(err, errlen, "out of memory");
    forces fu = {W};
    if (amfi_forward_newmark(b, v, t->n_axles, off, constant_force, &fu, sp->n_sensors,
                             sp->sensor_x_m, sp->dt_s, sp->scan_rate_hz, n, *acc, err,
                             errlen))
        return -1;
    *n_out = n;
    return 0;
}

int amfi_cal_runs_write(const char *dir, const amfi_bridge *b, const amfi_profile *prof,
                        const amfi_sim_params *sp, const amfi_halfcar_dist *dist,
                        const amfi_cal_params *p, char *err, size_t errlen)
{
    const int ns = sp->n_sensors;
    char path[4096];
    FILE *runs = NULL, *truth = NULL;
    double *acc = NULL;
    int rc = -1;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng)
        return failf(err, errlen, "out of memory");
    snprintf(path, sizeof path, "%s/RUNS.csv", dir);
    runs = fopen(path, "w");
    if (!runs) {
        failf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
        goto out;
    }
    snprintf(path, sizeof path, "%s/RUNS.truth.csv", dir);
    truth = fopen(path, "w");
    if (!truth) {
        failf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
        goto out;
    }
    fprintf(runs, "file,speed_mps,axle_spacings_m,entry_time_s,axle_kg\n");
    fprintf(truth, "file,truck,model,speed_mps,entry_time_s,axle_spacings_m,axle_kg,"
                   "mean_force_N,sensor_x_m,track,lost_contact_steps,detector_speed_mps,"
                   "detector_entry_time_s\n");
    int run = 0;
    for (int ti = 0; ti < p->n_trucks; ti++) {
        const amfi_cal_truck *t = &p->trucks[ti];
        for (int j = 0; j < p->runs_per_truck; j++, run++) {
            const double v = p->runs_per_truck == 1
                                 ? 0.5 * (p->speed_lo + p->speed_hi)
                                 : p->speed_lo + (p->speed_hi - p->speed_lo) * j /
                                                     (p->runs_per_truck - 1);
            double mean_force[AMFI_MAX_AXLES], static_kg[AMFI_MAX_AXLES], entry_true,
                speed_meas;
            long lost = 0;
            int n = 0, track = -1;
            const char *model;
            seed_run(rng, p->seed, run);
            free(acc);
            acc = NULL;
            /* the vehicle model: the half-car for two axles, the class model
             * (vclass.h, the class's mean properties) for a layout a class
             * fits, else constant moving forces */
            const int cls = t->n_axles > 2 ? amfi_vclass_guess(t->n_axles, t->spacing_m) : -1;
            for (int a = 0; a < t->n_axles; a++)
                static_kg[a] = t->axle_kg[a];
            if (t->n_axles == 2 || cls >= 0) {
                /* over the carpet (passage.c) */
                amfi_passage_spec spec;
                memset(&spec, 0, sizeof spec);
                if (t->n_axles == 2) {
                    if (amfi_halfcar_from_weights(t->axle_kg[0] + t->axle_kg[1], t->axle_kg[0],
                                                  t->axle_kg[1], t->spacing_m[0], dist, NULL,
                                                  &spec.car, err, errlen))
                        goto out;
                    model = "halfcar";
                } else {
                    const amfi_vclass *c = amfi_vclass_get(cls);
                    if (amfi_vclass_truck(c, t->axle_kg, t->spacing_m, NULL, &spec.truck, err,
                                          errlen))
                        goto out;
                    /* the class model equalises each load-sharing group (its
                     * sum kept): those are the static loads a weighbridge gives */
                    for (int a = 0; a < t->n_axles; a++)
                        static_kg[a] = spec.truck.W_N[a] / AMFI_GRAVITY;
                    model = c->name;
                }
                spec.speed_mps = v;
                spec.track = prof ? amfi_profile_draw_track(prof, p->track_std, rng) : 0;
                spec.pre_s = p->pre_s;
                spec.post_s = p->tail_s;
                const int cap = amfi_passage_samples(b, sp, &spec) + 1;
                acc = malloc(sizeof(double) * (size_t)cap * (size_t)ns);
                if (!acc) {
                    failf(err, errlen, "out of memory");
                    goto out;
                }
                amfi_measure m = {p->noise_frac, p->speed_err_mean, p->speed_err_std};
                amfi_passage_rec pr;
                if (amfi_passage_simulate(b, prof, sp, &spec, &m, rng, acc, cap, &pr, err,
                                          errlen))
                    goto out;
                n = pr.n;
                entry_true = -pr.t_first_s;
                speed_meas = pr.speed_measured_mps;
                for (int a = 0; a < t->n_axles; a++) {
                    mean_force[a] = pr.truth.mean_force_N[a];
                    lost += pr.truth.lost_contact_steps[a];
                }
                track = spec.track;
                add_noise(acc, n, ns, 0.0, p->noise_ms2, rng);
            } else {
                if (run_forces(b, sp, t, v, p->pre_s, p->tail_s, &acc, &n, err, errlen))
                    goto out;
                entry_true = p->pre_s;
                const double e =
                    p->speed_err_mean +
                    (p->speed_err_std > 0 ? gsl_ran_gaussian(rng, p->speed_err_std) : 0.0);
                speed_meas = v * (1.0 + e);
                for (int a = 0; a < t->n_axles; a++)
                    mean_force[a] = t->axle_kg[a] * AMFI_GRAVITY;
                model = "forces";
                add_noise(acc, n, ns, p->noise_frac, p->noise_ms2, rng);
            }
            char name[32];
            snprintf(name, sizeof name, "run%03d.csv", run + 1);
            snprintf(path, sizeof path, "%s/%s", dir, name);
            if (amfi_sim_write_accel(path, n, ns, p->sensor_id, sp->scan_rate_hz, acc, err, errlen))
                goto out;
            /* what the detector reports: its clock, its speed and spacing scales */
            const double det_speed = speed_meas * p->det.speed_scale;
            const double det_entry = entry_true + p->det.clock_offset_s;
            double det_sp[AMFI_MAX_AXLES - 1];
            for (int a = 0; a + 1 < t->n_axles; a++)
                det_sp[a] = t->spacing_m[a] * p->det.spacing_scale;
            fprintf(runs, "%s,%.6f,", name, det_speed);
            amfi_sim_put_list(runs, det_sp, t->n_axles - 1, "%.4f");
            fprintf(runs, ",%.6f,", det_entry);
            amfi_sim_put_list(runs, static_kg, t->n_axles, "%.1f");
            fputc('\n', runs);
            fprintf(truth, "%s,%d,%s,%.6f,%.6f,", name, ti + 1, model, v, entry_true);
            amfi_sim_put_list(truth, t->spacing_m, t->n_axles - 1, "%.4f");
            fputc(',', truth);
            amfi_sim_put_list(truth, static_kg, t->n_axles, "%.1f");
            fputc(',', truth);
            amfi_sim_put_list(truth, mean_force, t->n_axles, "%.3f");
            fputc(',', truth);
            amfi_sim_put_list(truth, sp->sensor_x_m, ns, "%.4f");
            fprintf(truth, ",%d,%ld,%.6f,%.6f\n", track, lost, det_speed, det_entry);
        }
    }
    if (fclose(runs) != 0) {
        runs = NULL;
        failf(err, errlen, "%s/RUNS.csv: write failed", dir);
        goto out;
    }
    runs = NULL;
    if (fclose(truth) != 0) {
        truth = NULL;
        failf(err, errlen, "%s/RUNS.truth.csv: write failed", dir);
        goto out;
    }
    truth = NULL;
    rc = 0;
out:
    if (runs)
        fclose(runs);
    if (truth)
        fclose(truth);
    free(acc);
    gsl_rng_free(rng);
    return rc;
}

int amfi_ambient_write(const char *path, const amfi_bridge *b, const amfi_sim_params *sp,
                       const amfi_ambient_params *p, char *err, size_t errlen)
{
    const amfi_bridge_params *bp = amfi_bridge_params_of(b);
    const int n = amfi_bridge_ndof(b), ns = sp->n_sensors, nodes = bp->n_elements + 1;
    const double fs = sp->scan_rate_hz, h = 1.0 / fs;
    const double *om = amfi_bridge_omega(b), *ze = amfi_bridge_zeta(b);
    int m = 0;
    while (m < n && om[m] < 3.14159265358979323846 * fs) /* ω below π·fs: f below fs/2 */
        m++;
    if (m == 0)
        return failf(err, errlen, "ambient: no mode below half the sampling rate (%g Hz)",
                     fs / 2);
    const double warm = fmin(60.0, 10.0 / (ze[0] * om[0] > 0 ? ze[0] * om[0] : 0.1));
    const long n_warm = lround(warm * fs), n_rec = lround(p->duration_s * fs);
    double *phi_node = malloc(sizeof(double) * (size_t)nodes * n);
    double *phi_s = malloc(sizeof(double) * (size_t)ns * n);
    double *blk = malloc(sizeof(double) * 4 * (size_t)m), *g = malloc(sizeof(double) * 2 * (size_t)m);
    double *q = calloc((size_t)m, sizeof(double)), *qd = calloc((size_t)m, sizeof(double));
    double *fm = malloc(sizeof(double) * (size_t)m), *F = malloc(sizeof(double) * (size_t)nodes);
    double *acc = malloc(sizeof(double) * (size_t)(n_rec > 0 ? n_rec : 1) * ns);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = -1;
    if (!phi_node || !phi_s || !blk || !g || !q || !qd || !fm || !F || !acc || !r) {
        failf(err, errlen, "ambient: out of memory");
        goto out;
    }
    gsl_rng_set(r, p->seed ^ 0xA3B1E47ul);
    for (int j = 0; j < nodes; j++)
        amfi_bridge_mode_values(b, bp->span_m * j / bp->n_elements, phi_node + (size_t)j * n);
    for (int i = 0; i < ns; i++)
        amfi_bridge_mode_values(b, sp->sensor_x_m[i], phi_s + (size_t)i * n);
    for (int k = 0; k < m; k++)
        amfi_modal_block(om[k], ze[k], h, blk + 4 * k, g + 2 * k);
    for (long s = 0; s < n_warm + n_rec; s++) {
        for (int j = 0; j < nodes; j++)
            F[j] = gsl_ran_gaussian(r, p->force_std_n);
        for (int k = 0; k < m; k++) {
            double f = 0.0;
            for (int j = 0; j < nodes; j++)
                f += phi_node[(size_t)j * n + k] * F[j];
            fm[k] = f;
        }
        if (s >= n_warm) {
            double *a = acc + (size_t)(s - n_warm) * ns;
            for (int i = 0; i < ns; i++) {
                double sum = 0.0;
                for (int k = 0; k < m; k++)
                    sum += phi_s[(size_t)i * n + k] *
                           (fm[k] - 2.0 * ze[k] * om[k] * qd[k] - om[k] * om[k] * q[k]);
                a[i] = sum;
            }
        }
        for (int k = 0; k < m; k++) {
            const double *P = blk + 4 * k;
            const double q1 = P[0] * q[k] + P[1] * qd[k] + g[2 * k] * fm[k];
            const double v1 = P[2] * q[k] + P[3] * qd[k] + g[2 * k + 1] * fm[k];
            q[k] = q1;
            qd[k] = v1;
        }
    }
    add_noise(acc, (int)n_rec, ns, p->noise_frac, p->noise_ms2, r);
    rc = amfi_sim_write_accel(path, (int)n_rec, ns, p->sensor_id, fs, acc, err, errlen);
out:
    free(phi_node);
    free(phi_s);
    free(blk);
    free(g);
    free(q);
    free(qd);
    free(fm);
    free(F);
    free(acc);
    gsl_rng_free(r);
    return rc;
}
