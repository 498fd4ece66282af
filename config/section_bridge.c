/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_bridge.c: the bridge: section of a site file (the finite-element
 * beam of libamfi's amfi_bridge_params): its keys, the supports list, and
 * the checks between its keys (supports on the beam, one per node, not a
 * mechanism; the damping modes within the model's DOFs). The model itself
 * is built once the whole file is read (model_check, section_solver.c).
 * Runs on the loader's thread.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Enums are written as ints: */
_Static_assert(sizeof(amfi_coords) == sizeof(int), "amfi_coords is written as an int");

/* bridge.name */
static int p_name(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_site_config *c = base;

    (void)f;
    return get_name(x, v, path, c->name, sizeof c->name);
}

/* bridge.damping.modes: [a, b], two distinct 1-based mode numbers */
static int p_rayleigh_modes(ctx *x, yaml_node_t *v, const char *path, const field *f,
                            void *base)
{
    amfi_site_config *c = base;
    char ip[PATH_LEN];
    long m[2] = {0, 0};

    (void)f;
    if (v->type != YAML_SEQUENCE_NODE)
        return fail(x, line_of(v), path, "expected a list of two mode numbers such "
                    "as [1, 2], got %s", what(v));
    if (v->data.sequence.items.top - v->data.sequence.items.start != 2)
        return fail(x, line_of(v), path, "expected two mode numbers, got %d",
                    (int)(v->data.sequence.items.top - v->data.sequence.items.start));
    for (int i = 0; i < 2; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, v->data.sequence.items.start[i]);
        join_index(ip, path, (size_t)i);
        if (!it)
            return fail(x, line_of(v), ip, "malformed list");
        if (get_long(x, it, ip, &m[i]))
            return -1;
        if (m[i] < 1 || m[i] > MAX_MODE_NO)
            return fail(x, line_of(it), ip, "must be a mode number 1 .. %d, got %ld",
                        MAX_MODE_NO, m[i]);
    }
    if (m[0] == m[1])
        return fail(x, line_of(v), path, "the two modes must differ, got %ld twice",
                    m[0]);
    c->bridge.rayleigh_mode_a = (int)m[0];
    c->bridge.rayleigh_mode_b = (int)m[1];
    return 0;
}

static void d_name(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %zu bytes, no control characters",
             sizeof(((amfi_site_config *)0)->name) - 1);
}

static void v_name(const field *f, const void *base, char *buf)
{
    (void)f;
    snprintf(buf, DOC_LEN, "%s", ((const amfi_site_config *)base)->name);
}

static void d_modes_pair(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "[a, b], two distinct mode numbers 1 .. %d", MAX_MODE_NO);
}

static void v_modes_pair(const field *f, const void *base, char *buf)
{
    const amfi_bridge_params *b = &((const amfi_site_config *)base)->bridge;

    (void)f;
    snprintf(buf, DOC_LEN, "[%d, %d]", b->rayleigh_mode_a, b->rayleigh_mode_b);
}

static const kind K_NAME = {"string", p_name, d_name, v_name, NEST_NONE};
static const kind K_RAYLEIGH = {"list", p_rayleigh_modes, d_modes_pair, v_modes_pair,
                                NEST_NONE};

/* bridge.supports: a list of {at_m, type} */
typedef struct support_item {
    double at_m; /* m, >= 0 (<= span checked in check_site) */
    int type;    /* SUPPORT_* */
} support_item;

enum { SUPPORT_PINNED, SUPPORT_ROLLER, SUPPORT_FIXED };

static const enum_name support_types[] = {
    {"pinned", SUPPORT_PINNED}, {"roller", SUPPORT_ROLLER}, {"fixed", SUPPORT_FIXED},
    {NULL, 0}};

static const field support_fields[] = {
    {.key = "at_m", .kind = &K_DOUBLE, .off = offsetof(support_item, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "type", .kind = &K_ENUM, .off = offsetof(support_item, type),
     .aux = support_types, .flags = F_REQUIRED},
    {.key = NULL}};

static int p_supports(ctx *x, yaml_node_t *v, const char *path, const field *f,
                      void *base)
{
    amfi_bridge_params *b = &((amfi_site_config *)base)->bridge;
    amfi_support s[AMFI_MAX_SUPPORTS];
    yaml_node_item_t *items;
    char ip[PATH_LEN];
    int n = 0;

    (void)f;
    items = list_items(x, v, path, "supports", AMFI_MAX_SUPPORTS, &n);
    if (!items)
        return -1;
    memset(s, 0, sizeof s);
    for (int i = 0; i < n; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, items[i]);
        support_item si = {0.0, SUPPORT_PINNED};

        join_index(ip, path, (size_t)i);
        if (!it)
            return fail(x, line_of(v), ip, "malformed list");
        note_line(x, ip, line_of(it));
        if (walk_map(x, it, ip, support_fields, &si))
            return -1;
        s[i].x_m = si.at_m;
        s[i].restrain_w = 1;
        s[i].restrain_theta = si.type == SUPPORT_FIXED;
    }
    memcpy(b->supports, s, sizeof s);
    b->n_supports = n;
    return 0;
}

static void d_supports(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %d supports", AMFI_MAX_SUPPORTS);
}

static void v_supports(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "pinned at 0, roller at span_m");
}

static const support_item support_default = {0.0, SUPPORT_PINNED};
static const list_schema support_list = {support_fields, &support_default};
static const kind K_SUPPORTS = {"list", p_supports, d_supports, v_supports, NEST_LIST};

static const field damping_fields[] = {
    {.key = "ratio", .kind = &K_DOUBLE, .off = SC(bridge.damping_ratio), .lo = 0,
     .hi = 1, .flags = F_HI_OPEN},
    {.key = "modes", .kind = &K_RAYLEIGH},
    {.key = NULL}};

const field bridge_fields[] = {
    {.key = "name", .kind = &K_NAME},
    {.key = "span_m", .kind = &K_DOUBLE, .off = SC(bridge.span_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "elements", .kind = &K_INT, .off = SC(bridge.n_elements), .lo = 1,
     .hi = 1000},
    {.key = "E_pa", .kind = &K_DOUBLE, .off = SC(bridge.E_pa), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "A_m2", .kind = &K_DOUBLE, .off = SC(bridge.A_m2), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "I_m4", .kind = &K_DOUBLE, .off = SC(bridge.I_m4), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "density_kgm3", .kind = &K_DOUBLE, .off = SC(bridge.density_kgm3), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "damping", .kind = &K_MAP, .aux = damping_fields},
    {.key = "supports", .kind = &K_SUPPORTS, .aux = &support_list},
    {.key = "damage", .kind = &K_DOUBLE, .off = SC(bridge.damage), .lo = 0, .hi = 1,
     .flags = F_HI_OPEN},
    {.key = NULL}};

int bridge_free_dofs(const amfi_bridge_params *b)
{
    int restrained = 0;

    for (int i = 0; i < b->n_supports; i++)
        restrained += b->supports[i].restrain_w + b->supports[i].restrain_theta;
    return 2 * (b->n_elements + 1) - restrained;
}

/* Without `supports` in the file, the roller follows bridge.span_m. */
int bridge_check(ctx *x, amfi_site_config *c)
{
    amfi_bridge_params *b = &c->bridge;
    int node[AMFI_MAX_SUPPORTS];
    int ndof;
    char p[PATH_LEN];

    if (!noted(x, "bridge.supports"))
        b->supports[b->n_supports - 1].x_m = b->span_m;

    /* Supports: on the beam, one per node, and the beam not a mechanism. */
    for (int i = 0; i < b->n_supports; i++) {
        pathf(p, "bridge.supports[%d].at_m", i);
        if (b->supports[i].x_m > b->span_m)
            return fail(x, first_noted(x, p, "bridge.span_m", NULL), p,
                        "%g m is beyond the span (bridge.span_m = %g m)",
                        b->supports[i].x_m, b->span_m);
        node[i] = (int)lround(b->supports[i].x_m / b->span_m * b->n_elements);
        for (int j = 0; j < i; j++)
            if (node[j] == node[i])
                return fail(x, first_noted(x, p, "bridge.elements", NULL), p,
                            "falls on node %d (of %d elements), like "
                            "bridge.supports[%d]", node[i], b->n_elements, j);
    }
    if (b->n_supports == 1 && !b->supports[0].restrain_theta)
        return fail(x, noted(x, "bridge.supports"), "bridge.supports",
                    "a single pinned or roller support leaves the beam free to "
                    "rotate; make it fixed or add a support");

    /* Mode numbers within the model's free DOFs. */
    ndof = bridge_free_dofs(b);
    if (b->rayleigh_mode_a > ndof || b->rayleigh_mode_b > ndof)
        return fail(x, first_noted(x, "bridge.damping.modes", "bridge.elements", NULL),
                    "bridge.damping.modes", "the model has only %d modes (free DOFs)",
                    ndof);
    return 0;
}
