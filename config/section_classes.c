/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_classes.c: the classes: section of a site file, how a passage's
 * axles are grouped and classed and the legal limits they are held against
 * (classify/amfi_classify.h, docs/classes.md): the scheme (eu, the default,
 * or fhwa13), the spacing that joins axles into a group, the gross weight
 * that parts a car or van from a two-axle truck, the gross-weight limit of
 * each European class and the axle limits of EU Directive 96/53/EC, the
 * 44 t container option. Absent, the defaults of amfi_class_params_default.
 * Runs on the loader's thread.
 */
#include "sections.h"

#include <string.h>

#define CL(m) offsetof(amfi_site_config, classes.m)

static const enum_name scheme_names[] = {
    {"eu", AMFI_CLASS_SCHEME_EU}, {"fhwa13", AMFI_CLASS_SCHEME_FHWA13}, {NULL, 0}};

#define GVW(c)                                                                      \
    {.key = #c, .kind = &amfi_cfg_k_double, .off = CL(gvw_limit_kg[AMFI_EU_##c]), .lo = 0, \
     .hi = 100000}

static const field gvw_fields[] = {GVW(CAR), GVW(R2),  GVW(R3),  GVW(R4), GVW(A22),
                                   GVW(A23), GVW(A32), GVW(A33), {.key = NULL}};

const field amfi_cfg_classes_fields[] = {
    {.key = "scheme", .kind = &amfi_cfg_k_enum, .off = CL(scheme), .aux = scheme_names},
    {.key = "group_spacing_m", .kind = &amfi_cfg_k_double, .off = CL(group_spacing_m), .lo = 1.0,
     .hi = 2.5},
    {.key = "light_max_kg", .kind = &amfi_cfg_k_double, .off = CL(light_max_kg), .lo = 500,
     .hi = 7500},
    {.key = "container_44t", .kind = &amfi_cfg_k_enum, .off = CL(container_44t), .aux = amfi_cfg_onoff_names},
    {.key = "gvw_limit_kg", .kind = &amfi_cfg_k_map, .aux = gvw_fields},
    {.key = "single_axle_kg", .kind = &amfi_cfg_k_double, .off = CL(single_axle_kg), .lo = 1000,
     .hi = 30000},
    {.key = "driving_axle_kg", .kind = &amfi_cfg_k_double, .off = CL(driving_axle_kg), .lo = 1000,
     .hi = 30000},
    {.key = "motor_tandem_air", .kind = &amfi_cfg_k_enum, .off = CL(motor_tandem_air),
     .aux = amfi_cfg_onoff_names},
    {.key = NULL}};

/* The rules across keys (a GVW limit 0 or at least 1 t): amfi_class_params_check,
 * blamed on the key's line, else the section's. */
int amfi_cfg_classes_check(ctx *x, amfi_site_config *c)
{
    const char *blamed = NULL;
    char why[256], path[PATH_LEN];
    if (amfi_class_params_check(&c->classes, &blamed, why, sizeof why) == 0)
        return 0;
    int is_class = 0;
    for (int k = 0; k < AMFI_EU_N; k++)
        is_class |= blamed && !strcmp(blamed, amfi_eu_class_name((amfi_eu_class)k));
    amfi_cfg_pathf(path, is_class ? "classes.gvw_limit_kg.%s" : "classes.%s", blamed ? blamed : "");
    int line = amfi_cfg_noted(x, path);
    return amfi_cfg_fail(x, line ? line : amfi_cfg_first_noted(x, "classes", NULL, NULL), path, "%s", why);
}
