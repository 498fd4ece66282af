/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_solver.c: the sensors: and solver: sections of a site file (the
 * sensor list and the rest of libamfi's amfi_solver_params, and the λ
 * policy amfi_lambda): their keys and the checks between them (sensors on
 * the span, mode counts within the model's DOFs, the L-curve grid, the
 * initial force and state, the speed search of amfi_solve_speed). Runs on the
 * loader's thread.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define MAX_RATE_HZ 1e6      /* calc_rate_hz, lambda_ref_rate_hz: (0, 1e6] Hz */
#define MAX_ROLL_S 60.0      /* pre_roll_s, post_roll_s: [0, 60) s */
#define MAX_DURATION_S 600.0 /* max_duration_s: (0, 600] s; a passage is ~1 s,
                                a slow crossing of a long bridge under a minute */

/* Enums are written as ints: */
_Static_assert(sizeof(amfi_coords) == sizeof(int), "amfi_coords is written as an int");

/* sensors: a list of {id, at_m, weight, rate_hz} */
typedef struct sensor_item {
    int id;         /* 0 .. 255 */
    double at_m;    /* m, >= 0 (<= span checked in check_site) */
    double weight;  /* > 0, default 1 */
    double rate_hz; /* (0, 100000], default AMFI_CONFIG_DEFAULT_RATE_HZ; one for all */
} sensor_item;

static const field sensor_fields[] = {
    {.key = "id", .kind = &amfi_cfg_k_int, .off = offsetof(sensor_item, id), .lo = 0, .hi = 255,
     .flags = F_REQUIRED},
    {.key = "at_m", .kind = &amfi_cfg_k_double, .off = offsetof(sensor_item, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "weight", .kind = &amfi_cfg_k_double, .off = offsetof(sensor_item, weight), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "rate_hz", .kind = &amfi_cfg_k_double, .off = offsetof(sensor_item, rate_hz), .lo = 0,
     .hi = 100000, .flags = F_LO_OPEN},
    {.key = NULL}};

/* Item i of sensors: one rate for all, distinct ids. */
static int check_sensor(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                        const void *base)
{
    const sensor_item *s = items;
    char idp[PATH_LEN];

    (void)base;
    /* the solver takes one sample rate for every sensor of a window */
    if (i > 0 && s[i].rate_hz != s[0].rate_hz) {
        amfi_cfg_pathf(idp, "%s.rate_hz", ip);
        return amfi_cfg_fail(x, amfi_cfg_noted(x, idp) ? amfi_cfg_noted(x, idp) : amfi_cfg_line_of(it), idp,
                    "%g Hz differs from sensors[0].rate_hz (%g Hz): every sensor must send "
                    "at one rate",
                    s[i].rate_hz, s[0].rate_hz);
    }
    for (int j = 0; j < i; j++)
        if (s[j].id == s[i].id) {
            amfi_cfg_pathf(idp, "%s.id", ip);
            return amfi_cfg_fail(x, amfi_cfg_noted(x, idp), idp, "duplicate id %d (also sensors[%d])",
                        s[i].id, j);
        }
    return 0;
}

static void store_sensors(const void *items, int n, void *base)
{
    amfi_site_config *c = base;
    const sensor_item *s = items;

    for (int i = 0; i < AMFI_MAX_SENSORS; i++) {
        c->solver.sensor_x_m[i] = i < n ? s[i].at_m : 0.0;
        c->solver.sensor_weight[i] = i < n ? s[i].weight : 0.0;
        c->sensor_id[i] = i < n ? s[i].id : -1;
        c->sensor_rate_hz[i] = i < n ? s[i].rate_hz : 0.0;
    }
    c->solver.n_sensors = n;
}

static void d_sensors(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %d sensors", AMFI_MAX_SENSORS);
}

static void v_sensors(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "one sensor, id 0, at mid-span");
}

static const sensor_item sensor_default = {.id = 0, .at_m = 0.0, .weight = 1.0,
                                           .rate_hz = AMFI_CONFIG_DEFAULT_RATE_HZ};
const list_schema amfi_cfg_sensors_list = {sensor_fields, &sensor_default, sizeof(sensor_item),
                                           AMFI_MAX_SENSORS, "sensors", check_sensor,
                                           store_sensors};
static int s_sensors(const field *f, span *out)
{
    const amfi_site_config *c = NULL;

    (void)f;
    out[0] = (span){SC(solver.sensor_x_m), sizeof c->solver.sensor_x_m};
    out[1] = (span){SC(solver.sensor_weight), sizeof c->solver.sensor_weight};
    out[2] = (span){SC(sensor_id), sizeof c->sensor_id};
    out[3] = (span){SC(sensor_rate_hz), sizeof c->sensor_rate_hz};
    out[4] = (span){SC(solver.n_sensors), sizeof c->solver.n_sensors};
    return 5;
}

const kind amfi_cfg_k_sensors = {"list", amfi_cfg_parse_list, d_sensors, v_sensors, NEST_LIST, s_sensors};

static void formulation_names(char *known, size_t len)
{
    size_t used = 0;

    known[0] = '\0';
    for (int i = 0; strcmp(amfi_formulation_name((amfi_formulation)i), "unknown"); i++)
        used = amfi_cfg_append_name(known, len, used, amfi_formulation_name((amfi_formulation)i));
}

/* solver.formulation: a name amfi_formulation_parse() knows */
static int p_formulation(ctx *x, yaml_node_t *v, const char *path, const field *f,
                         void *base)
{
    amfi_site_config *c = base;
    char known[128], buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, "a formulation name", 1);

    (void)f;
    if (!s)
        return -1;
    if (amfi_formulation_parse(s, &c->solver.formulation) == 0)
        return 0;
    formulation_names(known, sizeof known);
    return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected one of %s; got '%s'", known,
                amfi_cfg_show(buf, sizeof buf, v));
}

static void d_formulation(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    formulation_names(buf, DOC_LEN);
}

static void v_formulation(const field *f, const void *base, char *buf)
{
    (void)f;
    snprintf(buf, DOC_LEN, "%s",
             amfi_formulation_name(((const amfi_site_config *)base)->solver.formulation));
}

/* solver.modes: all | observable | resolved (observable below calc_rate_hz / 2) |
 * N (the N lowest observable modes) */
static int p_modes(ctx *x, yaml_node_t *v, const char *path, const field *f,
                   void *base)
{
    amfi_solver_params *p = &((amfi_site_config *)base)->solver;
    const char *want = "all, observable, resolved or a positive mode count";
    char buf[SHOW_LEN];
    const char *s = amfi_cfg_scalar(x, v, path, want, 1);
    long n = 0;

    (void)f;
    if (!s)
        return -1;
    if (strcmp(s, "all") == 0 || strcmp(s, "observable") == 0 || strcmp(s, "resolved") == 0) {
        p->modes = s[0] == 'a' ? AMFI_MODES_ALL
                   : s[0] == 'o' ? AMFI_MODES_OBSERVABLE
                                 : AMFI_MODES_RESOLVED;
        p->n_modes = 0;
        return 0;
    }
    if (!amfi_cfg_is_plain(v) || amfi_cfg_to_long(s, &n) != 0)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected %s, got '%s'", want,
                    amfi_cfg_show(buf, sizeof buf, v));
    if (n < 1 || n > MAX_MODE_NO)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "a mode count must be 1 .. %d, got %ld",
                    MAX_MODE_NO, n);
    p->modes = AMFI_MODES_COUNT;
    p->n_modes = (int)n;
    return 0;
}

/* solver.lambda: auto (L-curve) or a fixed λ at lambda_ref_rate_hz, > 0 */
static int p_lambda(ctx *x, yaml_node_t *v, const char *path, const field *f,
                    void *base)
{
    amfi_lambda *l = &((amfi_site_config *)base)->lambda;
    const char *want = "auto or a positive number";
    const char *s = amfi_cfg_scalar(x, v, path, want, 1);
    double d = 0.0;

    (void)f;
    if (!s)
        return -1;
    if (strcmp(s, "auto") == 0) {
        l->automatic = 1;
        return 0;
    }
    if (amfi_cfg_get_number(x, v, path, want, &d))
        return -1;
    if (!(d > 0))
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "must be > 0 (or auto), got %g", d);
    l->automatic = 0;
    l->lambda_ref = d;
    return 0;
}

static void d_modes(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "all, observable, resolved or a count 1 .. %d", MAX_MODE_NO);
}

static void v_modes(const field *f, const void *base, char *buf)
{
    const amfi_solver_params *p = &((const amfi_site_config *)base)->solver;

    (void)f;
    if (p->modes == AMFI_MODES_COUNT)
        snprintf(buf, DOC_LEN, "%d", p->n_modes);
    else
        snprintf(buf, DOC_LEN, "%s",
                 p->modes == AMFI_MODES_ALL        ? "all"
                 : p->modes == AMFI_MODES_RESOLVED ? "resolved"
                                                   : "observable");
}

static void d_lambda(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "auto or > 0");
}

static void v_lambda(const field *f, const void *base, char *buf)
{
    const amfi_lambda *l = &((const amfi_site_config *)base)->lambda;

    (void)f;
    if (l->automatic)
        snprintf(buf, DOC_LEN, "auto");
    else
        snprintf(buf, DOC_LEN, "%g", l->lambda_ref);
}

static int s_formulation(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(solver.formulation), sizeof(amfi_formulation)};
    return 1;
}

static int s_modes(const field *f, span *out)
{
    const amfi_site_config *c = NULL;

    (void)f;
    out[0] = (span){SC(solver.modes), sizeof c->solver.modes};
    out[1] = (span){SC(solver.n_modes), sizeof c->solver.n_modes};
    return 2;
}

static int s_lambda(const field *f, span *out)
{
    const amfi_site_config *c = NULL;

    (void)f;
    out[0] = (span){SC(lambda.automatic), sizeof c->lambda.automatic};
    out[1] = (span){SC(lambda.lambda_ref), sizeof c->lambda.lambda_ref};
    return 2;
}

static const kind K_FORMULATION = {"name", p_formulation, d_formulation, v_formulation,
                                   NEST_NONE, s_formulation};
static const kind K_MODES = {"name or integer", p_modes, d_modes, v_modes, NEST_NONE, s_modes};
static const kind K_LAMBDA = {"name or number", p_lambda, d_lambda, v_lambda, NEST_NONE,
                              s_lambda};


static const enum_name coords_names[] = {
    {"modal", AMFI_COORDS_MODAL}, {"nodal", AMFI_COORDS_NODAL}, {NULL, 0}};

/* solver.initial_force -> fix_initial_force */
static const enum_name initial_force_names[] = {{"free", 0}, {"zero", 1}, {NULL, 0}};

/* solver.speed -> speed_estimate */
static const enum_name speed_names[] = {{"measured", 0}, {"estimate", 1}, {NULL, 0}};

/* solver.speed_criterion -> speed_prior.criterion */
_Static_assert(sizeof(amfi_speed_criterion) == sizeof(int),
               "amfi_speed_criterion is written as an int");
static const enum_name speed_criterion_names[] = {
    {"regularised", AMFI_SPEED_REGULARISED}, {"residual", AMFI_SPEED_RESIDUAL}, {NULL, 0}};

/* solver.speed_pick -> speed_prior.pick */
_Static_assert(sizeof(amfi_speed_pick) == sizeof(int), "amfi_speed_pick is written as an int");
static const enum_name speed_pick_names[] = {
    {"min", AMFI_SPEED_PICK_MIN}, {"dip", AMFI_SPEED_PICK_DIP}, {NULL, 0}};

/* solver.initial_state -> free_initial_state */
static const enum_name initial_state_names[] = {{"rest", 0}, {"free", 1}, {NULL, 0}};

static const field lcurve_fields[] = {
    {.key = "lo", .kind = &amfi_cfg_k_double, .off = SC(lambda.lcurve_lo), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN | F_LIVE},
    {.key = "hi", .kind = &amfi_cfg_k_double, .off = SC(lambda.lcurve_hi), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN | F_LIVE},
    {.key = "per_decade", .kind = &amfi_cfg_k_int, .off = SC(lambda.lcurve_per_decade), .lo = 1,
     .hi = 100, .flags = F_LIVE},
    {.key = "refine", .kind = &amfi_cfg_k_int, .off = SC(lambda.lcurve_refine_points), .lo = 0,
     .hi = 100, .flags = F_LIVE},
    {.key = NULL}};

const field amfi_cfg_solver_fields[] = {
    {.key = "formulation", .kind = &K_FORMULATION},
    {.key = "coordinates", .kind = &amfi_cfg_k_enum, .off = SC(solver.coords),
     .aux = coords_names},
    {.key = "modes", .kind = &K_MODES},
    {.key = "calc_rate_hz", .kind = &amfi_cfg_k_double, .off = SC(solver.calc_rate_hz), .lo = 0,
     .hi = MAX_RATE_HZ, .flags = F_LO_OPEN},
    {.key = "initial_force", .kind = &amfi_cfg_k_enum, .off = SC(solver.fix_initial_force),
     .aux = initial_force_names},
    {.key = "initial_state", .kind = &amfi_cfg_k_enum, .off = SC(solver.free_initial_state),
     .aux = initial_state_names},
    {.key = "pre_roll_s", .kind = &amfi_cfg_k_double, .off = SC(solver.pre_roll_s), .lo = 0,
     .hi = MAX_ROLL_S, .flags = F_HI_OPEN},
    {.key = "post_roll_s", .kind = &amfi_cfg_k_double, .off = SC(solver.post_roll_s), .lo = 0,
     .hi = MAX_ROLL_S, .flags = F_HI_OPEN},
    {.key = "max_axles", .kind = &amfi_cfg_k_int, .off = SC(solver.max_axles), .lo = 1,
     .hi = AMFI_MAX_AXLES},
    {.key = "max_duration_s", .kind = &amfi_cfg_k_double, .off = SC(solver.max_duration_s),
     .lo = 0, .hi = MAX_DURATION_S, .flags = F_LO_OPEN},
    {.key = "lambda", .kind = &K_LAMBDA, .flags = F_LIVE},
    {.key = "lambda_ref_rate_hz", .kind = &amfi_cfg_k_double, .off = SC(lambda.ref_rate_hz),
     .lo = 0, .hi = MAX_RATE_HZ, .flags = F_LO_OPEN | F_LIVE},
    {.key = "lcurve", .kind = &amfi_cfg_k_map, .aux = lcurve_fields},
    {.key = "speed", .kind = &amfi_cfg_k_enum, .off = SC(speed_estimate), .aux = speed_names},
    {.key = "speed_sd", .kind = &amfi_cfg_k_double, .off = SC(speed_prior.rel_sd), .lo = 0, .hi = 1,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "speed_range_sd", .kind = &amfi_cfg_k_double, .off = SC(speed_prior.range_sd), .lo = 0,
     .hi = 50, .flags = F_LO_OPEN},
    {.key = "speed_grid", .kind = &amfi_cfg_k_double, .off = SC(speed_prior.grid_rel), .lo = 1e-4,
     .hi = 0.05},
    {.key = "speed_coarse_rate_hz", .kind = &amfi_cfg_k_double, .off = SC(speed_prior.coarse_rate_hz),
     .lo = 0, .hi = MAX_RATE_HZ},
    {.key = "speed_criterion", .kind = &amfi_cfg_k_enum, .off = SC(speed_prior.criterion),
     .aux = speed_criterion_names},
    {.key = "speed_pick", .kind = &amfi_cfg_k_enum, .off = SC(speed_prior.pick), .aux = speed_pick_names},
    {.key = NULL}};

/* Without `sensors` in the file, the one sensor follows bridge.span_m. */
int amfi_cfg_sensors_check(ctx *x, amfi_site_config *c)
{
    amfi_solver_params *s = &c->solver;
    int ndof = amfi_cfg_bridge_free_dofs(&c->bridge);
    char p[PATH_LEN];

    if (!amfi_cfg_noted(x, "sensors"))
        s->sensor_x_m[0] = 0.5 * c->bridge.span_m;
    if (s->modes == AMFI_MODES_COUNT && s->n_modes > ndof)
        return amfi_cfg_fail(x, amfi_cfg_noted(x, "solver.modes"), "solver.modes",
                    "%d modes asked, the model has only %d (free DOFs)", s->n_modes,
                    ndof);
    for (int i = 0; i < s->n_sensors; i++) {
        amfi_cfg_pathf(p, "sensors[%d].at_m", i);
        if (s->sensor_x_m[i] > c->bridge.span_m)
            return amfi_cfg_fail(x, amfi_cfg_first_noted(x, p, "bridge.span_m", NULL), p,
                        "%g m is beyond the span (bridge.span_m = %g m)",
                        s->sensor_x_m[i], c->bridge.span_m);
    }
    return 0;
}

int amfi_cfg_solver_check(ctx *x, amfi_site_config *c)
{
    const amfi_solver_params *s = &c->solver;
    const amfi_lambda *l = &c->lambda;

    /* λ search grid. */
    if (!(l->lcurve_lo < l->lcurve_hi))
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.lcurve.hi", "solver.lcurve.lo",
                                   "solver.lcurve"),
                    "solver.lcurve", "lo (%g) must be below hi (%g)", l->lcurve_lo,
                    l->lcurve_hi);

    /* g_0 = 0 forces a ramp at entry unless the window starts before it. */
    if (s->fix_initial_force && !(s->pre_roll_s > 0))
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.initial_force", "solver.pre_roll_s", NULL),
                    "solver.initial_force", "zero needs solver.pre_roll_s > 0");
    if (s->free_initial_state && s->fix_initial_force)
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.initial_state", "solver.initial_force", NULL),
                    "solver.initial_state", "free needs solver.initial_force: free");
    if (s->free_initial_state && s->coords != AMFI_COORDS_MODAL)
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.initial_state", "solver.coordinates", NULL),
                    "solver.initial_state", "free needs solver.coordinates: modal");

    /* The speed search: v0·(1 ± range·sd) stays well above 0, the grid within it. */
    const amfi_speed_prior *sp = &c->speed_prior;
    if (!(sp->range_sd * sp->rel_sd < 0.5))
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.speed_range_sd", "solver.speed_sd", NULL),
                    "solver.speed_range_sd", "speed_range_sd x speed_sd (%g) must be < 0.5",
                    sp->range_sd * sp->rel_sd);
    if (!(sp->grid_rel <= sp->range_sd * sp->rel_sd))
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.speed_grid", "solver.speed_range_sd",
                                   "solver.speed_sd"),
                    "solver.speed_grid", "%g is wider than the range (speed_range_sd x "
                    "speed_sd = %g)", sp->grid_rel, sp->range_sd * sp->rel_sd);
    if (sp->coarse_rate_hz > 0 && sp->coarse_rate_hz < 100)
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "solver.speed_coarse_rate_hz", NULL, NULL),
                    "solver.speed_coarse_rate_hz", "%g Hz: 0 (no coarse model) or >= 100",
                    sp->coarse_rate_hz);
    return 0;
}
