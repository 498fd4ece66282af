/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_simulation.c: the simulation: section of a site file
 * (sim_publisher's amfi_sim_config; the daemon and the tools accept and
 * ignore it): its keys, the words and nulls some of them take (max, none,
 * null), and the check that the integration step divides the sample period.
 * Runs on the loader's thread.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* simulation.stream.speedup: max (stored as 0: no pacing) or a factor in
 * the row's range. */
static int p_speedup(ctx *x, yaml_node_t *v, const char *path, const field *f,
                     void *base)
{
    const char *want = "max or a number";
    const char *s = amfi_cfg_scalar(x, v, path, want, 1);
    double d = 0.0;

    if (!s)
        return -1;
    if (strcmp(s, "max") != 0) {
        if (amfi_cfg_get_number(x, v, path, want, &d))
            return -1;
        if (amfi_cfg_out_of_range(d, f))
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be max or in [%g, %g], got %g", f->lo,
                        f->hi, d);
    }
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

/* simulation.stream.headway_s and flow_veh_h: 0 or null (stored as 0: the
 * population's timestamps / no Poisson flow) or a value in the row's range. */
static int p_headway(ctx *x, yaml_node_t *v, const char *path, const field *f,
                     void *base)
{
    double d = 0.0;

    if (!amfi_cfg_is_null_node(v)) {
        if (amfi_cfg_get_double(x, v, path, &d))
            return -1;
        if (d != 0.0 && amfi_cfg_out_of_range(d, f))
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be 0 or null (%s) or in [%g, %g], got %g",
                        strcmp(f->key, "headway_s") ? "off" : "the population's timestamps",
                        f->lo, f->hi, d);
    }
    memcpy((char *)base + f->off, &d, sizeof d);
    return 0;
}

/* simulation.damage_step_at: none or null (stored as −1) or a 0-based vehicle
 * index in the row's range, stored as an int. */
static int p_step(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    const char *want = "none or a vehicle index";
    char buf[SHOW_LEN];
    const char *s;
    long l = -1;
    int i;

    if (!amfi_cfg_is_null_node(v)) {
        s = amfi_cfg_scalar(x, v, path, want, 1);
        if (!s)
            return -1;
        if (strcmp(s, "none") != 0) {
            if (!amfi_cfg_is_plain(v) || amfi_cfg_to_long(s, &l) != 0)
                return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got '%s'", want,
                            amfi_cfg_show(buf, sizeof buf, v));
            if ((double)l < f->lo || (double)l > f->hi)
                return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be none or %.0f .. %.0f, got %ld",
                            f->lo, f->hi, l);
        }
    }
    i = (int)l;
    memcpy((char *)base + f->off, &i, sizeof i);
    return 0;
}

/* simulation.preceding_gap: null or none (no preceding vehicle), a number
 * (lo = hi) or [lo, hi]; seconds, each in the row's range, lo <= hi. */
static int p_gap(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_sim_config *m = &((amfi_site_config *)base)->sim;
    double g[2] = {0.0, 0.0};
    char ip[PATH_LEN];
    int n = 1;

    if (amfi_cfg_is_null_node(v) || (v->type == YAML_SCALAR_NODE &&
                            v->data.scalar.length == 4 &&
                            memcmp(v->data.scalar.value, "none", 4) == 0)) {
        m->preceding = 0;
        m->gap_lo_s = m->gap_hi_s = 0.0;
        return 0;
    }
    if (v->type == YAML_SEQUENCE_NODE) {
        n = (int)(v->data.sequence.items.top - v->data.sequence.items.start);
        if (n != 2)
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected [lo, hi] (two numbers), got %d", n);
        for (int i = 0; i < 2; i++) {
            yaml_node_t *it =
                yaml_document_get_node(x->doc, v->data.sequence.items.start[i]);
            amfi_cfg_join_index(ip, path, (size_t)i);
            if (!it)
                return amfi_cfg_fail(x, amfi_cfg_line_of(v), ip, "malformed list");
            if (amfi_cfg_get_double(x, it, ip, &g[i]))
                return -1;
            if (amfi_cfg_out_of_range(g[i], f))
                return amfi_cfg_range_fail(x, it, ip, f, g[i]);
        }
    } else if (v->type == YAML_SCALAR_NODE) {
        if (amfi_cfg_get_double(x, v, path, &g[0]))
            return -1;
        if (amfi_cfg_out_of_range(g[0], f))
            return amfi_cfg_range_fail(x, v, path, f, g[0]);
        g[1] = g[0];
    } else {
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected null, a number or [lo, hi], got %s",
                    amfi_cfg_what(v));
    }
    if (g[0] > g[1])
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "lo (%g) must not exceed hi (%g)", g[0], g[1]);
    m->preceding = 1;
    m->gap_lo_s = g[0];
    m->gap_hi_s = g[1];
    return 0;
}

static void d_speedup(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "max or [%g, %g]", f->lo, f->hi);
}

static void v_speedup(const field *f, const void *base, char *buf)
{
    double d;

    memcpy(&d, (const char *)base + f->off, sizeof d);
    if (d == 0.0)
        snprintf(buf, DOC_LEN, "max");
    else
        snprintf(buf, DOC_LEN, "%g", d);
}

static void d_headway(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "0, null or [%g, %g]", f->lo, f->hi);
}

static void v_double(const field *f, const void *base, char *buf)
{
    double d;

    memcpy(&d, (const char *)base + f->off, sizeof d);
    snprintf(buf, DOC_LEN, "%g", d);
}

static void d_step(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "none, null or %.0f .. %.0f", f->lo, f->hi);
}

static void v_step(const field *f, const void *base, char *buf)
{
    int i;

    memcpy(&i, (const char *)base + f->off, sizeof i);
    if (i < 0)
        snprintf(buf, DOC_LEN, "none");
    else
        snprintf(buf, DOC_LEN, "%d", i);
}

static void d_gap(const field *f, const void *base, char *buf)
{
    (void)base;
    snprintf(buf, DOC_LEN, "none, null, a number or [lo, hi], each in [%g, %g]", f->lo,
             f->hi);
}

static void v_gap(const field *f, const void *base, char *buf)
{
    const amfi_sim_config *m = &((const amfi_site_config *)base)->sim;

    (void)f;
    if (!m->preceding)
        snprintf(buf, DOC_LEN, "none");
    else
        snprintf(buf, DOC_LEN, "[%g, %g]", m->gap_lo_s, m->gap_hi_s);
}

static int s_gap(const field *f, span *out)
{
    const amfi_sim_config *m = NULL;

    (void)f;
    out[0] = (span){SC(sim.preceding), sizeof m->preceding};
    out[1] = (span){SC(sim.gap_lo_s), sizeof m->gap_lo_s};
    out[2] = (span){SC(sim.gap_hi_s), sizeof m->gap_hi_s};
    return 3;
}

static const kind K_SPEEDUP = {"name or number", p_speedup, d_speedup, v_speedup, NEST_NONE,
                               amfi_cfg_spans_double};
static const kind K_HEADWAY = {"number", p_headway, d_headway, v_double, NEST_NONE,
                               amfi_cfg_spans_double};
static const kind K_STEP = {"name or integer", p_step, d_step, v_step, NEST_NONE,
                            amfi_cfg_spans_int};
static const kind K_GAP = {"number or list", p_gap, d_gap, v_gap, NEST_NONE, s_gap};

#define SIM(m) offsetof(amfi_site_config, sim.m)
#define SIM_CAP(m) sizeof(((amfi_sim_config *)0)->m)

/* simulation.profile -> profile_class ('A' .. 'H', 0 smooth) */
static const enum_name profile_names[] = {
    {"A", 'A'}, {"B", 'B'}, {"C", 'C'}, {"D", 'D'}, {"E", 'E'},
    {"F", 'F'}, {"G", 'G'}, {"H", 'H'}, {"smooth", 0}, {NULL, 0}};

/* simulation.environment -> environment */
static const enum_name environment_names[] = {{"none", 0}, {"site", 1}, {NULL, 0}};

static const field speed_error_fields[] = {
    {.key = "mean", .kind = &amfi_cfg_k_double, .off = SIM(speed_err_mean), .lo = -0.5, .hi = 0.5},
    {.key = "std", .kind = &amfi_cfg_k_double, .off = SIM(speed_err_std), .lo = 0, .hi = 0.5},
    {.key = NULL}};

static const field stream_fields[] = {
    {.key = "lcm_url", .kind = &amfi_cfg_k_string, .off = SIM(lcm_url), .lo = 0,
     .hi = SIM_CAP(lcm_url)},
    {.key = "log", .kind = &amfi_cfg_k_path, .off = SIM(log), .hi = SIM_CAP(log)},
    {.key = "speedup", .kind = &K_SPEEDUP, .off = SIM(speedup), .lo = 0.01, .hi = 1e6},
    {.key = "headway_s", .kind = &K_HEADWAY, .off = SIM(headway_s), .lo = 0.1,
     .hi = 3600},
    {.key = "flow_veh_h", .kind = &K_HEADWAY, .off = SIM(flow_veh_h), .lo = 1, .hi = 3600},
    {.key = "min_headway_s", .kind = &amfi_cfg_k_double, .off = SIM(min_headway_s), .lo = 0, .hi = 60},
    {.key = "lanes", .kind = &amfi_cfg_k_int, .off = SIM(lanes), .lo = 1, .hi = 2},
    {.key = "noise_ms2", .kind = &amfi_cfg_k_double, .off = SIM(noise_ms2), .lo = 0, .hi = 10},
    {.key = "block", .kind = &amfi_cfg_k_int, .off = SIM(block), .lo = 1, .hi = 160},
    {.key = "start_utime", .kind = &amfi_cfg_k_llong, .off = SIM(start_utime), .lo = 1,
     .hi = 4e15},
    {.key = "detector_lead_s", .kind = &amfi_cfg_k_double, .off = SIM(detector_lead_s), .lo = 0,
     .hi = 60},
    {.key = "environment_period_s", .kind = &amfi_cfg_k_double, .off = SIM(environment_period_s),
     .lo = 0.1, .hi = 86400},
    {.key = "calibration_every", .kind = &amfi_cfg_k_int, .off = SIM(calibration_every), .lo = 0,
     .hi = 1e7},
    {.key = NULL}};

const field amfi_cfg_sim_fields[] = {
    {.key = "population", .kind = &amfi_cfg_k_path, .off = SIM(population),
     .hi = SIM_CAP(population), .flags = F_FILE_DIR},
    {.key = "vehicles", .kind = &amfi_cfg_k_int, .off = SIM(vehicles), .lo = 1, .hi = 1e7},
    {.key = "first", .kind = &amfi_cfg_k_int, .off = SIM(first), .lo = 0, .hi = 1e7},
    {.key = "seed", .kind = &amfi_cfg_k_llong, .off = SIM(seed), .lo = 0, .hi = 4294967295.0},
    {.key = "damage", .kind = &amfi_cfg_k_double, .off = SIM(damage), .lo = 0, .hi = 0.9},
    {.key = "damage_step_at", .kind = &K_STEP, .off = SIM(damage_step_at), .lo = 0,
     .hi = 1e7},
    {.key = "profile", .kind = &amfi_cfg_k_enum, .off = SIM(profile_class), .aux = profile_names},
    {.key = "track_std", .kind = &amfi_cfg_k_double, .off = SIM(track_std), .lo = 0, .hi = 100},
    {.key = "scan_rate_hz", .kind = &amfi_cfg_k_double, .off = SIM(scan_rate_hz), .lo = 50,
     .hi = 20000},
    {.key = "noise", .kind = &amfi_cfg_k_double, .off = SIM(noise), .lo = 0, .hi = 1},
    {.key = "speed_error", .kind = &amfi_cfg_k_map, .aux = speed_error_fields},
    {.key = "preceding_gap", .kind = &K_GAP, .lo = -2, .hi = 30},
    {.key = "pre_s", .kind = &amfi_cfg_k_double, .off = SIM(pre_s), .lo = 0, .hi = 30},
    {.key = "post_s", .kind = &amfi_cfg_k_double, .off = SIM(post_s), .lo = 0, .hi = 30},
    {.key = "dt_s", .kind = &amfi_cfg_k_double, .off = SIM(dt_s), .lo = 1e-6, .hi = 1e-3},
    {.key = "environment", .kind = &amfi_cfg_k_enum, .off = SIM(environment), .aux = environment_names},
    {.key = "time_compression", .kind = &amfi_cfg_k_double, .off = SIM(time_compression), .lo = 1,
     .hi = 1e6},
    {.key = "stream", .kind = &amfi_cfg_k_map, .aux = stream_fields},
    {.key = NULL}};

/* The simulator steps an integer number of times per sample (vbi.c); blame
 * dt_s, or scan_rate_hz when only the rate was given. */
int amfi_cfg_sim_check(ctx *x, amfi_site_config *c)
{
    double sub = 1.0 / (c->sim.scan_rate_hz * c->sim.dt_s);

    if (fabs(sub - round(sub)) > 1e-9 * sub) {
        const char *k = !amfi_cfg_noted(x, "simulation.dt_s") && amfi_cfg_noted(x, "simulation.scan_rate_hz")
                            ? "simulation.scan_rate_hz" : "simulation.dt_s";
        return amfi_cfg_fail(x, amfi_cfg_noted(x, k), k, "1/(scan_rate_hz*dt_s) = %g steps per sample is "
                    "not an integer", sub);
    }
    return 0;
}
