/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model_check.c: the checks that need the model itself, run once the whole
 * site file is read and every key is valid on its own.
 *
 * 1. The bridge is built with libamfi (amfi_bridge_create: assembly and the
 *    eigenproblem, milliseconds for the shipped 20 elements, about a second
 *    for 1000); a refusal ("the supports leave a mechanism", ...) is reported
 *    as FILE:LINE: key: with the key of the bridge section that caused it.
 * 2. The solver's workspace is counted as amfi_solver_create will size it:
 *    (max_duration_s + pre_roll_s + post_roll_s) · calc_rate_hz + 1 steps,
 *    each holding the data, forces, fitted outputs and the gains of every
 *    axle over the state (2m + axles in modal coordinates, with m the modes
 *    kept, counted here from the sensors' mode values like the solver does;
 *    4n + axles in nodal coordinates, which also hold 6 n×n matrices). A
 *    count above AMFI_CONFIG_MAX_STEPS or AMFI_CONFIG_MAX_WORKSPACE_BYTES
 *    (sections.h, documented in amfid.yaml(5)) is refused here, with the
 *    line of the key that set it and the limit, instead of ending later in
 *    "out of memory for N steps".
 * 3. The natural frequency's mode followed (daemon.natural_frequency.mode):
 *    one of the model's modes, its frequency inside [f_lo_hz, f_hi_hz].
 *
 * Runs on the loader's thread; the bridge lives only for the check.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The first of the keys (NULL-terminated) given in the file, for a message;
 * `fallback` when none was. */
static const char *given(const ctx *x, const char *const *keys, const char *fallback)
{
    for (; *keys; keys++)
        if (amfi_cfg_noted(x, *keys))
            return *keys;
    return fallback;
}

/* The key of the bridge section that a libamfi refusal points at. */
static const char *bridge_blame(const ctx *x, const char *why)
{
    static const char *const support_keys[] = {"bridge.supports", "bridge.elements",
                                               "bridge.span_m", NULL};
    static const char *const mode_keys[] = {"bridge.damping.modes", "bridge.elements",
                                            NULL};

    if (strstr(why, "support"))
        return given(x, support_keys, "bridge");
    if (strstr(why, "Rayleigh"))
        return given(x, mode_keys, "bridge");
    return "bridge";
}

/* Modes the modal solver keeps (amfi_solver_create's rule): every mode, or
 * those some sensor sees (|ψ_k(x_s)| > 1e-9 of the largest), at most
 * n_modes for a count. −1 when out of memory. */
static int modes_kept(const amfi_bridge *b, const amfi_solver_params *p)
{
    const int n = amfi_bridge_ndof(b);
    double *phi = malloc(sizeof(double) * (size_t)n * (size_t)p->n_sensors);
    double cmax = 0.0;
    int m = 0;

    if (!phi)
        return -1;
    for (int si = 0; si < p->n_sensors; si++)
        amfi_bridge_mode_values(b, p->sensor_x_m[si], phi + (size_t)si * n);
    for (size_t i = 0; i < (size_t)n * (size_t)p->n_sensors; i++)
        if (fabs(phi[i]) > cmax)
            cmax = fabs(phi[i]);
    for (int k = 0; k < n; k++) {
        int obs = 0;
        for (int si = 0; si < p->n_sensors; si++)
            if (fabs(phi[(size_t)si * n + k]) > 1e-9 * cmax)
                obs = 1;
        m += p->modes == AMFI_MODES_ALL || obs;
    }
    free(phi);
    if (p->modes == AMFI_MODES_COUNT && p->n_modes < m)
        m = p->n_modes;
    return m;
}

static int workspace_check(ctx *x, const amfi_site_config *c, const amfi_bridge *b)
{
    static const char *const step_keys[] = {"solver.calc_rate_hz", "solver.max_duration_s",
                                            "solver.pre_roll_s", "solver.post_roll_s",
                                            NULL};
    static const char *const space_keys[] = {
        "solver.calc_rate_hz", "solver.max_duration_s", "solver.max_axles",
        "solver.modes",        "solver.coordinates",    "solver.pre_roll_s",
        "solver.post_roll_s",  "bridge.elements",       "sensors",
        NULL};
    const amfi_solver_params *p = &c->solver;
    const double window_s = p->max_duration_s + p->pre_roll_s + p->post_roll_s;
    const double steps = ceil(window_s * p->calc_rate_hz) + 1.0;
    const double n = amfi_bridge_ndof(b), na = p->max_axles, ns = p->n_sensors;
    double gstride, bytes, fixed = 0.0;
    const char *k;

    if (steps > AMFI_CONFIG_MAX_STEPS) {
        k = given(x, step_keys, "solver");
        return amfi_cfg_fail(x, amfi_cfg_noted(x, k), k,
                    "%g Hz over (max_duration_s %g + pre_roll_s %g + post_roll_s %g) s "
                    "is %.0f solver steps, above the limit of %.0f steps; lower "
                    "solver.calc_rate_hz or solver.max_duration_s",
                    p->calc_rate_hz, p->max_duration_s, p->pre_roll_s, p->post_roll_s,
                    steps, AMFI_CONFIG_MAX_STEPS);
    }
    if (p->coords == AMFI_COORDS_MODAL) {
        int m = modes_kept(b, p);
        if (m < 0)
            return amfi_cfg_fail(x, 0, NULL, "out of memory while counting the modes");
        gstride = 2.0 * m + na;
    } else {
        gstride = 4.0 * n + na;
        fixed = 6.0 * n * n * sizeof(double);
    }
    bytes = steps * sizeof(double) * (2.0 * ns + 2.0 * na + na * gstride) + fixed;
    if (bytes > AMFI_CONFIG_MAX_WORKSPACE_BYTES) {
        k = given(x, space_keys, "solver");
        return amfi_cfg_fail(x, amfi_cfg_noted(x, k), k,
                    "the solver's workspace would be %.2f GiB (%.0f steps of %.0f axles "
                    "over %.0f states), above the limit of %.0f GiB per solver; lower "
                    "solver.calc_rate_hz, max_duration_s, max_axles or modes",
                    bytes / (1024.0 * 1024.0 * 1024.0), steps, na, gstride - na,
                    AMFI_CONFIG_MAX_WORKSPACE_BYTES / (1024.0 * 1024.0 * 1024.0));
    }
    return 0;
}

/* The natural frequency's mode followed (natfreq.h, amfi_natfreq_follow):
 * within the model's modes, its frequency inside [f_lo_hz, f_hi_hz]. */
static int natfreq_check(ctx *x, const amfi_site_config *c, const amfi_bridge *b)
{
    static const char *const keys[] = {"daemon.natural_frequency.mode",
                                       "daemon.natural_frequency.f_hi_hz",
                                       "daemon.natural_frequency.f_lo_hz",
                                       "daemon.natural_frequency.band", "bridge", NULL};
    const amfi_daemon_config *d = &c->daemon;
    amfi_natfreq_params out;
    double f;
    char why[256] = "";

    if (!(d->natfreq_free_s > 0) ||
        amfi_natfreq_follow(&d->natfreq, amfi_bridge_omega(b), amfi_bridge_ndof(b),
                            d->natfreq_mode, d->natfreq_band, &out, &f, why, sizeof why) == 0)
        return 0;
    const char *k = given(x, keys, "daemon.natural_frequency.mode");
    return amfi_cfg_fail(x, amfi_cfg_noted(x, k), k, "%s", why);
}

int amfi_cfg_model_check(ctx *x, amfi_site_config *c)
{
    amfi_bridge *b = NULL;
    char why[256] = "";
    const char *k;
    int rc;

    if (amfi_bridge_create(&c->bridge, &b, why, sizeof why)) {
        k = bridge_blame(x, why);
        return amfi_cfg_fail(x, amfi_cfg_noted(x, k), k, "the bridge model is refused: %s", why);
    }
    rc = workspace_check(x, c, b);
    if (rc == 0)
        rc = natfreq_check(x, c, b);
    amfi_bridge_destroy(b);
    return rc;
}
