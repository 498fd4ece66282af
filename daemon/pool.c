/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pool.c: amfid's solver pool (pool.h): the job queues and the solver
 * threads that weigh one passage each with A-MFI.
 *
 * Threads: worker_main runs on the solver threads; it owns its solver and,
 * between a pop and a push, the job; it reads nothing else. The queue
 * functions run on both sides under the queue's mutex. pool_start,
 * pool_join and pool_stop run on the main thread.
 */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "pool.h"
#include "amfi_time.h"

void job_free(job *j)
{
    if (j) {
        free(j->accel);
        free(j->accel_fit);
        free(j);
    }
}

/* ---- queues ------------------------------------------------------------- */

int queue_init(queue *q, int cap)
{
    memset(q, 0, sizeof *q);
    q->items = calloc((size_t)cap, sizeof *q->items);
    q->cap = cap;
    pthread_mutex_init(&q->mu, NULL);
    pthread_cond_init(&q->cv, NULL);
    return q->items ? 0 : -1;
}

void queue_fini(queue *q)
{
    free(q->items);
    q->items = NULL;
    pthread_mutex_destroy(&q->mu);
    pthread_cond_destroy(&q->cv);
}

int queue_push(queue *q, job *j)
{
    int rc = -1;
    pthread_mutex_lock(&q->mu);
    if (q->n < q->cap) {
        q->items[(q->head + q->n) % q->cap] = j;
        q->n++;
        rc = 0;
        pthread_cond_signal(&q->cv);
    }
    pthread_mutex_unlock(&q->mu);
    return rc;
}

job *queue_pop(queue *q, int wait)
{
    job *j = NULL;
    pthread_mutex_lock(&q->mu);
    while (wait && q->n == 0 && !q->closed)
        pthread_cond_wait(&q->cv, &q->mu);
    if (q->n > 0) {
        j = q->items[q->head];
        q->head = (q->head + 1) % q->cap;
        q->n--;
    }
    pthread_mutex_unlock(&q->mu);
    return j;
}

int queue_depth(queue *q)
{
    pthread_mutex_lock(&q->mu);
    int n = q->n;
    pthread_mutex_unlock(&q->mu);
    return n;
}

void queue_close(queue *q)
{
    pthread_mutex_lock(&q->mu);
    q->closed = 1;
    pthread_cond_broadcast(&q->cv);
    pthread_mutex_unlock(&q->mu);
}

/* ---- solver threads ------------------------------------------------------- */

/* The job's samples as a passage's (amfi_passage and amfi_multi_passage
 * share these fields). */
static void job_samples(const job *j, amfi_passage *p)
{
    memset(p, 0, sizeof *p);
    p->n_samples = j->w.n;
    p->scan_rate_hz = j->scan_rate_hz;
    p->t_first_s = j->w.t_first_s;
    for (int i = 0; i < j->n_sensors; i++)
        p->accel[i] = j->accel + (size_t)i * j->w.n;
}

/* Weigh an event's vehicles together (amfi_solve_multi, the job's λ
 * policy, the detector's speeds: the speed search is one vehicle's); the
 * result goes into the job: the event's λ and residual, each vehicle's
 * weight and quality in j->veh. A vehicle whose weight is not positive is
 * an error of its own; a failed solve is every vehicle's. */
static void solve_event(amfi_solver *s, job *j)
{
    amfi_passage one;
    job_samples(j, &one);
    amfi_multi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = one.n_samples;
    p.scan_rate_hz = one.scan_rate_hz;
    p.t_first_s = one.t_first_s;
    memcpy(p.accel, one.accel, sizeof p.accel);
    p.n_vehicles = j->w.n_vehicles;
    for (int v = 0; v < p.n_vehicles; v++) {
        const amfi_vehicle_ev *e = &j->w.ev[v];
        amfi_vehicle *ve = &p.vehicle[v];
        ve->entry_s = 1e-6 * (double)(e->utime - j->w.v.utime);
        ve->speed_mps = e->speed_mps;
        ve->n_axles = e->n_axles;
        for (int a = 0; a + 1 < e->n_axles; a++)
            ve->axle_spacing_m[a] = e->spacing_m[a];
    }
    amfi_multi_result *r = malloc(sizeof *r);
    char err[256] = "out of memory";
    double t0 = amfi_mono_s();
    int rc = r ? amfi_solve_multi(s, &p, &j->lambda, r, err, sizeof err) : AMFI_ENOMEM;
    j->solve_ms = 1e3 * (amfi_mono_s() - t0);
    if (rc != 0) {
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason, "solver, %d vehicles together: %.150s",
                 p.n_vehicles, err);
        j->gvw_kg = NAN;
        free(r);
        return;
    }
    j->solved = 1;
    snprintf(j->status, sizeof j->status, "ok");
    j->lambda_used = r->all.lambda_ref;
    j->residual_rms = r->all.residual_rms;
    j->gvw_kg = r->total_gvw_kg;
    for (int v = 0; v < p.n_vehicles; v++) {
        const amfi_vehicle_result *vr = &r->vehicle[v];
        job_vehicle *o = &j->veh[v];
        o->quality = vr->quality;
        o->group = vr->group;
        o->group_gvw_kg = vr->group_gvw_kg;
        if (!(vr->gvw_kg > 0.0) || !isfinite(vr->gvw_kg)) {
            snprintf(o->reason, sizeof o->reason,
                     "inferred GVW %.0f kg is not positive in the joint solve of %d vehicles",
                     vr->gvw_kg, p.n_vehicles);
            continue;
        }
        o->solved = 1;
        o->gvw_kg = vr->gvw_kg;
        for (int a = 0; a < vr->n_axles; a++)
            o->axle_kg[a] = vr->axle_kg[a];
    }
    free(r);
}

/* Weigh the job's passage (or event); the result goes into the job. */
static void solve_job(amfi_solver *s, job *j)
{
    if (j->w.n_vehicles > 1) {
        solve_event(s, j);
        return;
    }
    amfi_passage p;
    job_samples(j, &p);
    p.speed_mps = j->w.v.speed_mps;
    p.n_axles = j->w.v.n_axles;
    for (int a = 0; a + 1 < p.n_axles; a++)
        p.axle_spacing_m[a] = j->w.v.spacing_m[a];
    amfi_result r;
    amfi_speed_result sr;
    char err[256];
    double t0 = amfi_mono_s();
    int rc = j->speed_estimate
                 ? amfi_solve_speed(s, &p, &j->lambda, &j->speed_prior, &r, &sr, err, sizeof err)
                 : amfi_solve(s, &p, &j->lambda, &r, err, sizeof err);
    j->solve_ms = 1e3 * (amfi_mono_s() - t0);
    if (rc != 0) {
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason, "solver: %.180s", err);
        j->gvw_kg = NAN;
        return;
    }
    if (!(r.gvw_kg > 0.0) || !isfinite(r.gvw_kg)) {
        /* e.g. a silent sensor: stored as an error with the number, not lost */
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason,
                 "inferred GVW %.0f kg is not positive: no response from the bridge?", r.gvw_kg);
        j->gvw_kg = NAN;
        return;
    }
    j->solved = 1;
    snprintf(j->status, sizeof j->status, "ok");
    if (j->speed_estimate) {
        j->speed_used_mps = sr.speed_mps;
        j->speed_estimated = 1;
    }
    j->gvw_kg = r.gvw_kg;
    for (int a = 0; a < r.n_axles; a++)
        j->axle_kg[a] = r.axle_kg[a];
    j->lambda_used = r.lambda_ref;
    j->residual_rms = r.residual_rms;
}

/* The model fit (docs/indicators.md section 10): the passage solved again
 * with the same λ and speed over a window extended fit_free_s past the last
 * exit, at the fit's calculation rate (alerts.model_fit.calc_rate_hz); the relative residual of the fitted model over that free vibration
 * (every sensor, the calculation steps after the exit, the data linearly
 * interpolated as the solver does). With the model right the free vibration
 * is the state at exit left to itself, which the fit reproduces; with
 * another bridge (stiffness, bearings, sensor position) it is not. */
static void fit_job(amfi_solver *s, double span_m, job *j)
{
    amfi_passage p;
    memset(&p, 0, sizeof p);
    /* A bridge of stiffness κ·EI under a load moving at v is, on the time
     * τ = s·t (s = sqrt κ, the ratio of its frequencies), the model under
     * the load over κ moving at v / s (the damping ratios over s): the data
     * resampled on τ (rate / s) with the speed v / s are fitted by the model
     * itself, and the ratio of two accelerations does not see the scale. */
    const double sc = j->fit_scale > 0.5 && j->fit_scale < 2.0 ? j->fit_scale : 1.0;
    p.n_samples = j->fit_n;
    p.scan_rate_hz = j->scan_rate_hz / sc;
    p.t_first_s = j->w.t_first_s * sc;
    for (int i = 0; i < j->n_sensors; i++)
        p.accel[i] = j->accel_fit + (size_t)i * j->fit_n;
    p.speed_mps = (j->speed_estimated ? j->speed_used_mps : j->w.v.speed_mps) / sc;
    p.n_axles = j->w.v.n_axles;
    for (int a = 0; a + 1 < p.n_axles; a++)
        p.axle_spacing_m[a] = j->w.v.spacing_m[a];
    amfi_lambda lam = j->lambda;
    lam.automatic = 0; /* the λ the weighing chose */
    lam.lambda_ref = j->lambda_used;
    amfi_result r;
    char err[256];
    if (amfi_solve(s, &p, &lam, &r, err, sizeof err) != 0) {
        snprintf(j->fit_why, sizeof j->fit_why, "%s", "solve refused");
        return;
    }
    const double exit_s = amfi_passage_window(span_m, p.speed_mps, p.n_axles, p.axle_spacing_m,
                                              0.0, 0.0).on_span_s;
    const int ns = j->n_sensors;
    double e2 = 0.0, s2 = 0.0;
    for (int k = 0; k < r.n_steps; k++) {
        const double t = r.t0_s + (k + 1) * r.h_s; /* model_accel row k is y_{k+1} */
        if (t <= exit_s)
            continue;
        double u = (t - p.t_first_s) * p.scan_rate_hz;
        int i = (int)floor(u);
        if (i < 0 || i > p.n_samples - 2)
            continue;
        const double f = u - i;
        for (int si = 0; si < ns; si++) {
            const double d = (1 - f) * p.accel[si][i] + f * p.accel[si][i + 1];
            const double e = r.model_accel[(size_t)k * ns + si] - d;
            e2 += e * e;
            s2 += d * d;
        }
    }
    if (!(s2 > 0) || !isfinite(e2)) {
        snprintf(j->fit_why, sizeof j->fit_why, "%s", "no free vibration");
        return;
    }
    j->fit_ratio = sqrt(e2 / s2);
    j->fit_done = 1;
}

typedef struct worker_arg {
    pool *p;
    amfi_solver *solver, *fit;
} worker_arg;

static void *worker_main(void *arg)
{
    worker_arg wa = *(worker_arg *)arg;
    free(arg);
    job *j;
    while ((j = queue_pop(&wa.p->jobs, 1)) != NULL) {
        solve_job(wa.solver, j);
        if (j->accel_fit && wa.fit && j->solved && j->w.n_vehicles == 1)
            fit_job(wa.fit, wa.p->span_m, j);
        while (queue_push(&wa.p->results, j) != 0) /* never full: sized with jobs */
            usleep(1000);
        uint64_t one = 1;
        if (write(wa.p->efd, &one, sizeof one) < 0)
            continue; /* the main thread also polls the queue */
    }
    return NULL;
}

int pool_start(pool *p, const amfi_bridge *bridge, const amfi_solver_params *sp,
               double fit_free_s, double fit_rate_hz, int n_threads, int queue_size,
               char *err, size_t errlen)
{
    memset(p, 0, sizeof *p);
    p->fit_free_s = fit_free_s;
    p->span_m = amfi_bridge_params_of(bridge)->span_m;
    amfi_solver_params fsp = *sp;
    fsp.post_roll_s += fit_free_s;
    /* The fit needs the free vibration's modes, not the weights: a coarser
     * step solves it for a fraction of the weighing's CPU (the figures of
     * the as-built cases agree to 3 digits at 2000 and 5000 Hz;
     * docs/results/model-fit.md). */
    if (fit_rate_hz > 0 && fit_rate_hz < fsp.calc_rate_hz)
        fsp.calc_rate_hz = fit_rate_hz;
    p->efd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    p->efd_open = p->efd >= 0;
    if (p->efd < 0 || queue_init(&p->jobs, queue_size)) {
        snprintf(err, errlen, "out of memory at start-up");
        return -1;
    }
    if (queue_init(&p->results, queue_size + n_threads + 1)) {
        queue_fini(&p->jobs);
        snprintf(err, errlen, "out of memory at start-up");
        return -1;
    }
    p->init = 1;
    p->n_threads = n_threads;
    p->threads = calloc((size_t)n_threads, sizeof *p->threads);
    p->solvers = calloc((size_t)n_threads, sizeof *p->solvers);
    p->fit_solvers = fit_free_s > 0 ? calloc((size_t)n_threads, sizeof *p->fit_solvers) : NULL;
    if (!p->threads || !p->solvers || (fit_free_s > 0 && !p->fit_solvers)) {
        snprintf(err, errlen, "out of memory at start-up");
        return -1;
    }
    for (int i = 0; i < n_threads; i++) {
        char serr[256] = "";
        worker_arg *wa = malloc(sizeof *wa);
        if (!wa || amfi_solver_create(bridge, sp, &p->solvers[i], serr, sizeof serr)) {
            snprintf(err, errlen, "solver thread %d: %s", i, wa ? serr : "out of memory");
            free(wa);
            return -1;
        }
        if (p->fit_solvers &&
            amfi_solver_create(bridge, &fsp, &p->fit_solvers[i], serr, sizeof serr)) {
            snprintf(err, errlen, "solver thread %d, the model fit's: %s", i, serr);
            free(wa);
            return -1;
        }
        wa->p = p;
        wa->solver = p->solvers[i];
        wa->fit = p->fit_solvers ? p->fit_solvers[i] : NULL;
        if (pthread_create(&p->threads[i], NULL, worker_main, wa) != 0) {
            snprintf(err, errlen, "solver thread %d: cannot start it", i);
            free(wa);
            return -1;
        }
        p->started++;
    }
    return 0;
}

void pool_join(pool *p)
{
    if (!p->init)
        return;
    queue_close(&p->jobs);
    for (int i = 0; i < p->started; i++)
        pthread_join(p->threads[i], NULL);
    p->started = 0;
    for (int i = 0; p->solvers && i < p->n_threads; i++) {
        amfi_solver_destroy(p->solvers[i]);
        p->solvers[i] = NULL;
        if (p->fit_solvers) {
            amfi_solver_destroy(p->fit_solvers[i]);
            p->fit_solvers[i] = NULL;
        }
    }
}

void pool_stop(pool *p)
{
    pool_join(p);
    if (p->init) {
        job *j;
        while ((j = queue_pop(&p->jobs, 0)) != NULL)
            job_free(j);
        while ((j = queue_pop(&p->results, 0)) != NULL)
            job_free(j);
        queue_fini(&p->jobs);
        queue_fini(&p->results);
        p->init = 0;
    }
    free(p->threads);
    free(p->solvers);
    free(p->fit_solvers);
    p->threads = NULL;
    p->solvers = NULL;
    p->fit_solvers = NULL;
    if (p->efd_open)
        close(p->efd);
    p->efd_open = 0;
    p->efd = -1;
}
