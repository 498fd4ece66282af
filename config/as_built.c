/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * as_built.c: the as-built file of sim_publisher --as-built (amfi_as_built.h):
 * the site file's bridge: table and checks (section_bridge.c, model_check.c)
 * over the design's values, the true sensor positions and the detector's
 * errors, with the site loader's walker and messages. Loader's thread only.
 */
#include "amfi_as_built.h"
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define AB(m) offsetof(amfi_as_built, m)

/* sensors: a list of {id, at_m | offset_m} */
typedef struct ab_sensor {
    int id;
    double at_m;     /* NAN: not given */
    double offset_m; /* NAN: not given */
} ab_sensor;

static const field ab_sensor_fields[] = {
    {.key = "id", .kind = &amfi_cfg_k_int, .off = offsetof(ab_sensor, id), .lo = 0, .hi = 255,
     .flags = F_REQUIRED},
    {.key = "at_m", .kind = &amfi_cfg_k_double, .off = offsetof(ab_sensor, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN},
    {.key = "offset_m", .kind = &amfi_cfg_k_double, .off = offsetof(ab_sensor, offset_m),
     .lo = -HUGE_VAL, .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = NULL}};

/* The design's index of sensor `id`, or -1. */
static int design_sensor(const amfi_site_config *d, int id)
{
    for (int k = 0; k < d->solver.n_sensors; k++)
        if (d->sensor_id[k] == id)
            return k;
    return -1;
}

/* Item i of sensors: a sensor of the design, listed once, one position. */
static int check_ab_sensor(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                           const void *base)
{
    const amfi_site_config *d = &((const amfi_as_built *)base)->site;
    const ab_sensor *s = items;
    char kp[PATH_LEN];
    const int k = design_sensor(d, s[i].id);

    amfi_cfg_pathf(kp, "%s.id", ip);
    if (k < 0)
        return amfi_cfg_fail(x, amfi_cfg_noted(x, kp), kp, "the design has no sensor with id %d",
                             s[i].id);
    for (int j = 0; j < i; j++)
        if (s[j].id == s[i].id)
            return amfi_cfg_fail(x, amfi_cfg_noted(x, kp), kp, "sensor %d is listed twice",
                                 s[i].id);
    amfi_cfg_pathf(kp, "sensor#%d", k); /* where design sensor k was moved (ab_check) */
    amfi_cfg_note_line(x, kp, amfi_cfg_line_of(it));
    if (isnan(s[i].at_m) == isnan(s[i].offset_m))
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "give exactly one of at_m (the true "
                             "position) and offset_m (true minus design)");
    return 0;
}

/* The true positions of the sensors listed; the others stay the design's. */
static void store_ab_sensors(const void *items, int n, void *base)
{
    amfi_as_built *a = base;
    const ab_sensor *s = items;

    for (int i = 0; i < n; i++) {
        const int k = design_sensor(&a->site, s[i].id); /* checked: >= 0 */
        a->sensor_x_m[k] =
            isnan(s[i].at_m) ? a->site.solver.sensor_x_m[k] + s[i].offset_m : s[i].at_m;
    }
}

static void d_ab_sensors(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "0 .. %d sensors, each an id of the design's sensors",
             AMFI_MAX_SENSORS);
}

static void v_ab_sensors(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "every sensor where the design says");
}

static const ab_sensor ab_sensor_default = {0, NAN, NAN};
static const list_schema ab_sensor_list = {ab_sensor_fields, &ab_sensor_default,
                                           sizeof(ab_sensor), AMFI_MAX_SENSORS, "sensors",
                                           check_ab_sensor, store_ab_sensors};
static int s_ab_sensors(const field *f, span *out)
{
    (void)f;
    out[0] = (span){AB(sensor_x_m), sizeof(((amfi_as_built *)0)->sensor_x_m)};
    return 1;
}

static const kind K_AB_SENSORS = {"list", amfi_cfg_parse_list, d_ab_sensors, v_ab_sensors,
                                  NEST_LIST, s_ab_sensors};

/* The site file's detector: section (section_detector.c: what a
 * commissioning finds), here the truth it should find, and the spacings'
 * own scale. */
_Static_assert(offsetof(amfi_detector_error, clock_offset_s) ==
                       offsetof(amfi_detector_config, clock_offset_s) &&
                   offsetof(amfi_detector_error, speed_scale) ==
                       offsetof(amfi_detector_config, speed_scale),
               "amfi_detector_error starts as amfi_detector_config");
static const field ab_detector_fields[] = {
    AMFI_CFG_DETECTOR_ROWS(AB(detector), 0),
    {.key = "spacing_scale", .kind = &amfi_cfg_k_double, .off = AB(detector.spacing_scale),
     .lo = 0.5, .hi = 2},
    {.key = NULL}};

static const field ab_top[] = {
    {.key = "bridge", .kind = &amfi_cfg_k_map, .aux = amfi_cfg_bridge_fields},
    {.key = "sensors", .kind = &K_AB_SENSORS, .aux = &ab_sensor_list},
    {.key = "detector", .kind = &amfi_cfg_k_map, .aux = ab_detector_fields},
    {.key = NULL}};

/* The bridge's own checks and the model built (section_bridge.c,
 * model_check.c: the design's solver over the as-built bridge), then the
 * true sensor positions on the as-built span. */
static int ab_check(ctx *x, void *base)
{
    amfi_as_built *a = base;
    char p[PATH_LEN];

    if (amfi_cfg_bridge_check(x, &a->site) || amfi_cfg_model_check(x, &a->site))
        return -1;
    /* spacings measured from the speed: scaled alike unless the file says */
    if (!amfi_cfg_noted(x, "detector.spacing_scale"))
        a->detector.spacing_scale = a->detector.speed_scale;
    for (int k = 0; k < a->site.solver.n_sensors; k++)
        if (!(a->sensor_x_m[k] >= 0 && a->sensor_x_m[k] <= a->site.bridge.span_m)) {
            /* the sensor's item when it was moved, else the span that shrank */
            amfi_cfg_pathf(p, "sensor#%d", k);
            const int line = amfi_cfg_noted(x, p) ? amfi_cfg_noted(x, p) : amfi_cfg_noted(x, "bridge.span_m");
            amfi_cfg_pathf(p, "sensors[id %d]", a->site.sensor_id[k]);
            return amfi_cfg_fail(x, line, p, "at %g m, off the as-built span [0, %g] m",
                        a->sensor_x_m[k], a->site.bridge.span_m);
        }
    return 0;
}

void amfi_config_as_built_from_design(const amfi_site_config *design, amfi_as_built *out)
{
    memset(out, 0, sizeof *out);
    memcpy(&out->site, design, sizeof *design);
    memcpy(out->sensor_x_m, design->solver.sensor_x_m, sizeof out->sensor_x_m);
    out->detector = (amfi_detector_error){0.0, 1.0, 1.0};
}

int amfi_config_as_built_load(const char *path, const amfi_site_config *design, amfi_as_built *out,
                       char *err, size_t errlen)
{
    amfi_as_built *tmp;
    ctx *x;
    int rc;

    if (err && errlen)
        err[0] = '\0';
    if (!path || !design || !out) {
        if (err && errlen)
            snprintf(err, errlen, "amfi_config_as_built_load: NULL argument");
        return -1;
    }
    x = calloc(1, sizeof *x);
    tmp = malloc(sizeof *tmp);
    if (!x || !tmp) {
        free(x);
        free(tmp);
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    x->file = path;
    x->err = err;
    x->errlen = errlen;
    amfi_config_as_built_from_design(design, tmp);
    rc = amfi_cfg_walk_file(x, ab_top, tmp, ab_check);
    if (rc == 0)
        memcpy(out, tmp, sizeof *tmp);
    free(tmp);
    free(x);
    return rc;
}

int amfi_config_as_built_keys(int (*visit)(const char *path, const char *type, const char *range,
                                    const char *dflt, int required, void *arg),
                       void *arg)
{
    amfi_as_built *d = malloc(sizeof *d);
    amfi_site_config *c = malloc(sizeof *c);
    int rc = -1;

    if (d && c) {
        amfi_config_defaults(c);
        amfi_config_as_built_from_design(c, d);
        rc = amfi_cfg_describe_table(ab_top, "", d, visit, arg);
    }
    free(c);
    free(d);
    return rc;
}
