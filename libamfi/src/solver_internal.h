/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * solver_internal.h: the solver workspace shared by solver.c, the two sweeps
 * and the L-curve search. Dimensions use: n bridge DOFs, m modes kept,
 * na axles (≤ na_max), ns sensors, N steps (≤ cap).
 */
#ifndef AMFI_SOLVER_INTERNAL_H
#define AMFI_SOLVER_INTERNAL_H

#include "internal.h"

struct amfi_solver {
    const amfi_bridge *b;
    amfi_solver_params p;
    double h;     /* calculation step, s */
    int n;        /* bridge DOFs */
    int ns;       /* sensors */
    int na_max;   /* axle capacity */
    double w[AMFI_MAX_SENSORS]; /* W = diag(w) */
    double *S;    /* ns × n: sensor shape rows */

    /* modal path */
    int m;          /* modes kept */
    int *mode;      /* m: index into the bridge's modes */
    double *Phi;    /* m × 4: Φ_k row-major 2 × 2 */
    double *Gm;     /* m × 2 */
    double *c;      /* ns × m: sensor modal coefficients ψ_k(x_s) */
    double *Cx;     /* ns × 2m: constant output row (paper: (Φ − I)/h, velocity row) */
    double *Hxx;    /* 2m × 2m: Cxᵀ W Cx */
    double *pe;     /* n_elements × 4 × m: mode values at each element's 4 DOFs */

    /* nodal path */
    double *PhiN;   /* 2n × 2n */
    double *GN;     /* 2n × n */

    /* per passage (capacity cap steps, na_max axles) */
    int cap;        /* steps */
    int na;         /* axles of the current passage */
    int N;          /* steps of the current passage */
    double t0;      /* time of step 0 relative to entry, s */
    double speed;   /* m/s */
    double off[AMFI_MAX_EVENT_AXLES]; /* axle a at x = speed·vf[a]·t − off[a] */
    double vf[AMFI_MAX_EVENT_AXLES];  /* per-axle speed factor: 1 for one vehicle; for
                                   several (multi.c) speed = 1 and vf[a] = the
                                   vehicle's speed, off[a] = speed·entry + offset */
    double *d;      /* (cap + 1) × ns: data at the steps */
    double *force;  /* (cap + 1) × na_max */
    double *y;      /* cap × ns: fitted outputs y_1..y_N */
    double *gain;   /* N × na × (state of na) of the sweep: r_j = −(gain_j z_j + gofs_j) */
    size_t gain_len; /* doubles held: the largest amfi_gain_doubles so far */
    size_t sweep_budget; /* doubles: a modal sweep whose gains would exceed this
                            keeps checkpoints and one block's gains instead
                            (sweep_modal.c); AMFI_MULTI_SEGMENT_BYTES, or
                            amfi_solve_multi's max_segment_bytes */
    double *gofs;   /* cap × na_max */
    int gstride;    /* state size of the widest path */
    double *scratch; /* sweep scratch, sized at create */
    size_t scratch_len;
    size_t bytes;   /* workspace bytes */

    /* L-curve (points sorted by λ): sized at create for the default search
     * (amfi_lambda_default), grown once by a longer one (lcurve.c) */
    int lc_cap, lc_n;
    double *lc_lam, *lc_res, *lc_smo, *lc_kap;

    /* amfi_solve_multi's quality figures (multi.c): the normal matrix and its
     * solves for up to mq_na unknowns, sized at the first event of that many
     * axles, grown by a larger one */
    int mq_na;
    double *mq;
    size_t mq_len;
    /* amfi_solve_multi's segments' result (multi.c), allocated at the first
     * segmented event */
    struct amfi_multi_result *seg;

    /* speed search (speed.c): Brent's minimiser (gsl_min_fminimizer),
     * allocated at the first search, owned and freed with this solver */
    void *brent;

    /* speed search (speed.c): the coarse model, created at the first
     * two-level search, owned and freed with this solver */
    struct amfi_solver *coarse;
    double *grid_f; /* J on the grid, grid_cap points */
    int grid_cap;
};

/* Position of axle a at step j, m (x = speed·vf[a]·t − off[a], t = t0 + j·h):
 * inline beside the passage fields it reads, so the sweeps need no call
 * into solver.c. */
static inline double axle_x(const struct amfi_solver *s, int a, int j)
{
    return s->speed * s->vf[a] * (s->t0 + j * s->h) - s->off[a];
}

/* Mean force of axle a over the steps it is on the span after the last
 * sweep (s->force), N; NaN when it never is (solver.c). */
double amfi_axle_mean_force(const struct amfi_solver *s, int a);

/* One backward and forward sweep at per-step λ: fills s->force (N + 1 rows),
 * s->y, and the two norms (sweep_modal.c, sweep_nodal.c). */
int amfi_sweep_modal(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm);
int amfi_sweep_nodal(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm);
size_t amfi_sweep_modal_scratch(int m, int na, int ns);
/* Doubles of a modal sweep's gain array (N steps, na axles, m modes) under
 * a budget of doubles: all N steps' gains when they fit, else checkpoints
 * and one block of *seg steps' gains (*seg = N when they fit). */
size_t amfi_sweep_modal_gain_doubles(int m, int na, int N, size_t budget, int *seg);
size_t amfi_sweep_nodal_scratch(int n, int na, int ns);

/* Run the sweep of the solver's coordinates (sweep.c). */
int amfi_sweep(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm);

/* Factor from a rate-independent λ (given at l->ref_rate_hz) to the per-step
 * λ_h at the solver's calculation rate: λ_h = λ_ref·(h_ref/h)² (docs/model.md §7:
 * the residual sum has N ∝ 1/h terms and r ∝ h). */
static inline double amfi_lambda_scale(const struct amfi_solver *s, const amfi_lambda *l)
{
    return (s->p.calc_rate_hz / l->ref_rate_hz) * (s->p.calc_rate_hz / l->ref_rate_hz);
}

/* L-curve search over λ_ref; each sweep runs at λ_ref·scale, scale from
 * amfi_lambda_scale(). Returns the chosen per-step λ in *lam_h (lcurve.c). */
int amfi_lcurve(struct amfi_solver *s, const amfi_lambda *l, double scale, double *lam_h,
                int *n_solves);
/* The L-curve's points for the search l (0, or AMFI_ENOMEM): at most one
 * reallocation, only when l needs more points than any search before. */
int amfi_lcurve_reserve(struct amfi_solver *s, const amfi_lambda *l);

/* amfi_solve in three steps, so that a search (speed.c) can run several
 * sweeps over one window (solver.c):
 *   begin: validate the passage, set the window for window_speed (the
 *     passage's own speed when <= 0; a slower one gives a longer window),
 *     resample the data; s->speed is the passage's speed;
 *   lambda: the per-step λ (the L-curve at s->speed when automatic);
 *   end: one sweep at s->speed and λ_h, and the result (n_solves counts the
 *     sweeps run before it). */
int amfi_solve_begin(struct amfi_solver *s, const amfi_passage *ps, const amfi_lambda *lam,
                     double window_speed, char *err, size_t errlen);
int amfi_solve_lambda(struct amfi_solver *s, const amfi_lambda *lam, double *lam_h,
                      int *n_solves, char *err, size_t errlen);
/* Shared with amfi_solve_multi (multi.c):
 *   check_samples_lambda: the samples (count, rate, t_first, a pointer per
 *     sensor) and λ, as amfi_solve_begin checks them;
 *   grow_axles: the workspace for na axles (outside any time loop);
 *     AMFI_EINVAL above AMFI_MAX_EVENT_AXLES, AMFI_ENOMEM;
 *   window: na axles over [t_start, t_end] (off[], vf[], speed set by the
 *     caller): size N, resample the data. */
int amfi_check_samples_lambda(const struct amfi_solver *s, const amfi_passage *ps,
                              const amfi_lambda *lam, char *err, size_t errlen);
int amfi_solver_grow_axles(struct amfi_solver *s, int na);
/* Doubles of the gain array of a sweep of N steps and na axles (solver.c). */
size_t amfi_gain_doubles(const struct amfi_solver *s, int N, int na);
int amfi_solve_window(struct amfi_solver *s, const amfi_passage *ps, int na, double t_start,
                      double t_end, char *err, size_t errlen);
int amfi_solve_end(struct amfi_solver *s, const amfi_lambda *lam, double lam_h, int n_solves,
                   amfi_result *res, char *err, size_t errlen);

#endif
