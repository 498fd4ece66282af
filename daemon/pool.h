/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pool.h: amfid's solver pool: the job a passage travels in, the bounded
 * queues between the threads, and the solver threads.
 *
 * Threads: the main thread fills a job completely (window, samples, λ
 * policy, sample rate) and pushes it on `jobs`; a solver thread pops it,
 * solves it with its own solver (built from the immutable bridge before
 * the thread started), writes the result into the job and pushes it on
 * `results`, then wakes the main thread through the eventfd. A job
 * belongs to exactly one thread at a time (the queue hands it over under
 * its mutex); a solver thread reads nothing else that is shared.
 */
#ifndef AMFID_POOL_H
#define AMFID_POOL_H

#include <pthread.h>

#include "amfi/amfi.h"
#include "tracker.h"

/* One vehicle's result in a joint solve (an event of several vehicles). */
typedef struct job_vehicle {
    int solved;              /* 1: gvw_kg and axle_kg hold its weight */
    double gvw_kg, axle_kg[AMFI_MAX_AXLES];
    double quality;          /* amfi_vehicle_result.quality */
    int group;               /* amfi_vehicle_result.group: the first vehicle (index
                                in the event) of its group of coincident axles */
    double group_gvw_kg;     /* amfi_vehicle_result.group_gvw_kg: the group's sum */
    char reason[200];        /* why not solved (status "error") */
} job_vehicle;

/* One passage, or one event of several vehicles solved together (w.n_vehicles
 * > 1: the pipeline stores a row per vehicle), between the threads: all a
 * solver thread reads is here. */
typedef struct job {
    amfi_window w;           /* the window (and its status) */
    int n_sensors;
    double *accel;           /* n_sensors × w.n, owned */
    amfi_lambda lambda;      /* λ policy at release (a reload changes the next jobs) */
    double scan_rate_hz;     /* sample rate of the window's samples */
    int speed_estimate;      /* solver.speed at release: 1 estimate (amfi_solve_speed) */
    amfi_speed_prior speed_prior; /* its prior (solver.speed_sd, ...) at release */
    /* result */
    int solved;
    double speed_used_mps;   /* the speed weighed with: the estimate, or w.v.speed_mps */
    int speed_estimated;     /* 1: speed_used_mps is amfi_solve_speed's estimate */
    double gvw_kg, axle_kg[AMFI_MAX_AXLES], lambda_used, residual_rms, solve_ms;
    double quality;          /* a vehicle of an event: its separability; else NaN */
    char status[16];
    char reason[200];
    job_vehicle veh[AMFI_MAX_VEHICLES]; /* an event (w.n_vehicles > 1), solved: per vehicle */
    /* the natural frequency (freevib.c), set by the main thread at release */
    double f1_hz, f1_zeta, f1_r2; /* NaN: none */
    int64_t f1_vehicle_id;   /* the event's vehicle that carries it (left last) */
    /* a vehicle's job of an event (pipeline.c): 1 when some vehicle of the
     * event is not stored ok (raw.c keeps the window's samples: failed) */
    int event_not_ok;
    /* the model fit (modelfit.c): a vehicle weighed alone with free vibration
     * recorded: fit_n samples per sensor from the window's first (w.k0),
     * through free vibration after the last exit, owned (NULL: no fit) */
    double *accel_fit;
    int fit_n;
    double fit_scale;        /* the bridge's frequencies at the deck temperature over
                                the model's (freevib_time_scale): the fit runs on
                                time stretched by it, so that the temperature's
                                stiffness is not taken for a model that fails */
    int fit_done;            /* result: 1 when fit_ratio holds the figure */
    double fit_ratio;        /* the extended solve's residual over the free vibration
                                / the signal there (RMS ratio) */
    char fit_why[64];        /* why not ("" when fit_ratio is set or no fit was asked) */
} job;

void job_free(job *j);

/* A bounded FIFO of jobs, safe between threads. */
typedef struct queue {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    job **items;
    int cap, head, n;
    int closed;
} queue;

int queue_init(queue *q, int cap);     /* 0, or −1 out of memory */
void queue_fini(queue *q);             /* after queue_init succeeded */
int queue_push(queue *q, job *j);      /* 0 queued, −1 full */
job *queue_pop(queue *q, int wait);    /* NULL: empty (and closed when wait) */
int queue_depth(queue *q);
void queue_close(queue *q);            /* wakes every waiting pop */

/* The solver threads and their queues. */
typedef struct pool {
    queue jobs, results;
    int efd;                 /* eventfd: results ready */
    int efd_open;
    int n_threads, started;
    pthread_t *threads;
    amfi_solver **solvers;   /* one per thread, owned by it while it runs */
    amfi_solver **fit_solvers; /* the model fit's (post-roll extended by fit_free_s),
                                  one per thread; NULL: no fit */
    double fit_free_s;       /* free vibration the fit solve takes past the last exit */
    double span_m;
    int init;                /* queues initialised */
} pool;

/* Queues (jobs: queue_size; results: room for every job in flight), the
 * eventfd, one solver per thread and the threads; fit_free_s > 0: a second
 * solver per thread whose post-roll is fit_free_s longer and whose
 * calculation rate is fit_rate_hz (at most sp's), for the model fit (a job
 * with accel_fit is solved again over its free vibration). 0, or −1
 * with the reason in err (the pool is then half built: pool_stop releases
 * it). */
int pool_start(pool *p, const amfi_bridge *bridge, const amfi_solver_params *sp,
               double fit_free_s, double fit_rate_hz, int n_threads, int queue_size,
               char *err, size_t errlen);

/* Close the job queue, let the threads finish what is queued, join them,
 * free the solvers. The results stay queued for the caller. Idempotent. */
void pool_join(pool *p);

/* pool_join, then free the queues (and any job left in them) and close the
 * eventfd. Safe on a zeroed or half-started pool. */
void pool_stop(pool *p);

#endif /* AMFID_POOL_H */
