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
    return amfi_cfg_get_name(x, v, path, c->name, sizeof c->name);
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
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected a list of two mode numbers such "
                    "as [1, 2], got %s", amfi_cfg_what(v));
    if (v->data.sequence.items.top - v->data.sequence.items.start != 2)
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "expected two mode numbers, got %d",
                    (int)(v->data.sequence.items.top - v->data.sequence.items.start));
    for (int i = 0; i < 2; i++) {
        yaml_node_t *it = yaml_document_get_node(x->doc, v->data.sequence.items.start[i]);
        amfi_cfg_join_index(ip, path, (size_t)i);
        if (!it)
            return amfi_cfg_fail(x, amfi_cfg_line_of(v), ip, "malformed list");
        if (amfi_cfg_get_long(x, it, ip, &m[i]))
            return -1;
        if (m[i] < 1 || m[i] > MAX_MODE_NO)
            return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "must be a mode number 1 .. %d, got %ld",
                        MAX_MODE_NO, m[i]);
    }
    if (m[0] == m[1])
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path, "the two modes must differ, got %ld twice",
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

static int s_name(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(name), sizeof(((amfi_site_config *)0)->name)};
    return 1;
}

static int s_modes_pair(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(bridge.rayleigh_mode_a), sizeof(int)};
    out[1] = (span){SC(bridge.rayleigh_mode_b), sizeof(int)};
    return 2;
}

static const kind K_NAME = {"string", p_name, d_name, v_name, NEST_NONE, s_name};
static const kind K_RAYLEIGH = {"list", p_rayleigh_modes, d_modes_pair, v_modes_pair,
                                NEST_NONE, s_modes_pair};

/* bridge.supports: a list of {at_m, type, k_w_npm, k_theta_nmprad} */
typedef struct support_item {
    double at_m;           /* m, >= 0 (<= span checked in check_site) */
    int type;              /* SUPPORT_* */
    double k_w_npm;        /* elastic: the vertical spring, N/m, > 0 */
    double k_theta_nmprad; /* pinned, roller, elastic: a rotational spring, N·m/rad */
} support_item;

enum { SUPPORT_PINNED, SUPPORT_ROLLER, SUPPORT_FIXED, SUPPORT_ELASTIC };

static const enum_name support_types[] = {
    {"pinned", SUPPORT_PINNED}, {"roller", SUPPORT_ROLLER}, {"fixed", SUPPORT_FIXED},
    {"elastic", SUPPORT_ELASTIC}, {NULL, 0}};

static const field support_fields[] = {
    {.key = "at_m", .kind = &amfi_cfg_k_double, .off = offsetof(support_item, at_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "type", .kind = &amfi_cfg_k_enum, .off = offsetof(support_item, type),
     .aux = support_types, .flags = F_REQUIRED},
    {.key = "k_w_npm", .kind = &amfi_cfg_k_double, .off = offsetof(support_item, k_w_npm), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN},
    {.key = "k_theta_nmprad", .kind = &amfi_cfg_k_double, .off = offsetof(support_item, k_theta_nmprad),
     .lo = 0, .hi = HUGE_VAL, .flags = F_HI_OPEN},
    {.key = NULL}};

/* Item i of bridge.supports: the springs its type allows. */
static int check_support(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                         const void *base)
{
    const support_item *si = (const support_item *)items + i;

    (void)base;
    if (si->type == SUPPORT_ELASTIC && !(si->k_w_npm > 0))
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "an elastic support needs k_w_npm > 0 "
                    "(its vertical stiffness, N/m)");
    if (si->type != SUPPORT_ELASTIC && si->k_w_npm > 0)
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "k_w_npm is the spring of an elastic support; "
                    "a %s support holds the vertical displacement",
                    si->type == SUPPORT_FIXED ? "fixed" : si->type == SUPPORT_ROLLER ? "roller"
                                                                                : "pinned");
    if (si->type == SUPPORT_FIXED && si->k_theta_nmprad > 0)
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "a fixed support holds the rotation: no "
                    "k_theta_nmprad (use pinned with k_theta_nmprad for a partly "
                    "fixed bearing)");
    return 0;
}

/* The supports read, as libamfi's amfi_support. */
static void store_supports(const void *items, int n, void *base)
{
    amfi_bridge_params *b = &((amfi_site_config *)base)->bridge;
    const support_item *si = items;

    memset(b->supports, 0, sizeof b->supports);
    for (int i = 0; i < n; i++) {
        amfi_support *s = &b->supports[i];
        s->x_m = si[i].at_m;
        s->restrain_w = si[i].type != SUPPORT_ELASTIC;
        s->restrain_theta = si[i].type == SUPPORT_FIXED;
        s->k_w_npm = si[i].type == SUPPORT_ELASTIC ? si[i].k_w_npm : 0.0;
        s->k_theta_nmprad = si[i].k_theta_nmprad;
    }
    b->n_supports = n;
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

static const support_item support_default = {0.0, SUPPORT_PINNED, 0.0, 0.0};
static const list_schema support_list = {support_fields, &support_default, sizeof(support_item),
                                         AMFI_MAX_SUPPORTS, "supports", check_support,
                                         store_supports};
static int s_supports(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(bridge.supports), sizeof(((amfi_bridge_params *)0)->supports)};
    out[1] = (span){SC(bridge.n_supports), sizeof(int)};
    return 2;
}

static const kind K_SUPPORTS = {"list", amfi_cfg_parse_list, d_supports, v_supports, NEST_LIST,
                                s_supports};

/* bridge.segments: a list of {from_m, to_m, EI_nm2, mass_kgpm} */
static const field segment_fields[] = {
    {.key = "from_m", .kind = &amfi_cfg_k_double, .off = offsetof(amfi_segment, x0_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN | F_REQUIRED},
    {.key = "to_m", .kind = &amfi_cfg_k_double, .off = offsetof(amfi_segment, x1_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN | F_REQUIRED},
    {.key = "EI_nm2", .kind = &amfi_cfg_k_double, .off = offsetof(amfi_segment, EI_nm2), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN},
    {.key = "mass_kgpm", .kind = &amfi_cfg_k_double, .off = offsetof(amfi_segment, mass_kgpm), .lo = 0,
     .hi = HUGE_VAL, .flags = F_HI_OPEN},
    {.key = NULL}};

/* Item i of bridge.segments: a length and something on it. */
static int check_segment(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                         const void *base)
{
    const amfi_segment *g = (const amfi_segment *)items + i;

    (void)base;
    if (!(g->x1_m > g->x0_m))
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "to_m (%g) must be beyond from_m (%g)",
                             g->x1_m, g->x0_m);
    if (g->EI_nm2 == 0 && g->mass_kgpm == 0)
        return amfi_cfg_fail(x, amfi_cfg_line_of(it), ip, "gives neither EI_nm2 nor mass_kgpm");
    return 0;
}

static void store_segments(const void *items, int n, void *base)
{
    amfi_bridge_params *b = &((amfi_site_config *)base)->bridge;

    memset(b->segments, 0, sizeof b->segments);
    memcpy(b->segments, items, (size_t)n * sizeof b->segments[0]);
    b->n_segments = n;
}

static void d_segments(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "0 .. %d segments", AMFI_MAX_SEGMENTS);
}

static void v_segments(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "none: one section over the whole span");
}

static const amfi_segment segment_default = {0.0, 0.0, 0.0, 0.0};
static const list_schema segment_list = {segment_fields, &segment_default, sizeof(amfi_segment),
                                         AMFI_MAX_SEGMENTS, "segments", check_segment,
                                         store_segments};
static int s_segments(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(bridge.segments), sizeof(((amfi_bridge_params *)0)->segments)};
    out[1] = (span){SC(bridge.n_segments), sizeof(int)};
    return 2;
}

static const kind K_SEGMENTS = {"list", amfi_cfg_parse_list, d_segments, v_segments, NEST_LIST,
                                s_segments};

static const field damping_fields[] = {
    {.key = "ratio", .kind = &amfi_cfg_k_double, .off = SC(bridge.damping_ratio), .lo = 0,
     .hi = 1, .flags = F_HI_OPEN},
    {.key = "modes", .kind = &K_RAYLEIGH},
    {.key = NULL}};

const field amfi_cfg_bridge_fields[] = {
    {.key = "name", .kind = &K_NAME},
    {.key = "span_m", .kind = &amfi_cfg_k_double, .off = SC(bridge.span_m), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "elements", .kind = &amfi_cfg_k_int, .off = SC(bridge.n_elements), .lo = 1,
     .hi = 1000},
    {.key = "E_pa", .kind = &amfi_cfg_k_double, .off = SC(bridge.E_pa), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "A_m2", .kind = &amfi_cfg_k_double, .off = SC(bridge.A_m2), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "I_m4", .kind = &amfi_cfg_k_double, .off = SC(bridge.I_m4), .lo = 0, .hi = HUGE_VAL,
     .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "density_kgm3", .kind = &amfi_cfg_k_double, .off = SC(bridge.density_kgm3), .lo = 0,
     .hi = HUGE_VAL, .flags = F_LO_OPEN | F_HI_OPEN},
    {.key = "damping", .kind = &amfi_cfg_k_map, .aux = damping_fields},
    {.key = "supports", .kind = &K_SUPPORTS, .aux = &support_list},
    {.key = "segments", .kind = &K_SEGMENTS, .aux = &segment_list},
    {.key = "damage", .kind = &amfi_cfg_k_double, .off = SC(bridge.damage), .lo = 0, .hi = 1,
     .flags = F_HI_OPEN},
    {.key = NULL}};

int amfi_cfg_bridge_free_dofs(const amfi_bridge_params *b)
{
    int restrained = 0;

    for (int i = 0; i < b->n_supports; i++)
        restrained += b->supports[i].restrain_w + b->supports[i].restrain_theta;
    return 2 * (b->n_elements + 1) - restrained;
}

/* Without `supports` in the file, the roller follows bridge.span_m. */
int amfi_cfg_bridge_check(ctx *x, amfi_site_config *c)
{
    amfi_bridge_params *b = &c->bridge;
    int node[AMFI_MAX_SUPPORTS];
    int ndof;
    char p[PATH_LEN];

    if (!amfi_cfg_noted(x, "bridge.supports"))
        b->supports[b->n_supports - 1].x_m = b->span_m;

    /* Supports: on the beam, one per node, and the beam not a mechanism. */
    for (int i = 0; i < b->n_supports; i++) {
        amfi_cfg_pathf(p, "bridge.supports[%d].at_m", i);
        if (b->supports[i].x_m > b->span_m)
            return amfi_cfg_fail(x, amfi_cfg_first_noted(x, p, "bridge.span_m", NULL), p,
                        "%g m is beyond the span (bridge.span_m = %g m)",
                        b->supports[i].x_m, b->span_m);
        node[i] = (int)lround(b->supports[i].x_m / b->span_m * b->n_elements);
        for (int j = 0; j < i; j++)
            if (node[j] == node[i])
                return amfi_cfg_fail(x, amfi_cfg_first_noted(x, p, "bridge.elements", NULL), p,
                            "falls on node %d (of %d elements), like "
                            "bridge.supports[%d]", node[i], b->n_elements, j);
    }
    if (b->n_supports == 1 && !b->supports[0].restrain_theta &&
        !(b->supports[0].k_theta_nmprad > 0))
        return amfi_cfg_fail(x, amfi_cfg_noted(x, "bridge.supports"), "bridge.supports",
                    "a single support without a held or sprung rotation leaves the beam "
                    "free to rotate; make it fixed or add a support");

    /* Segments: on the beam, apart. */
    for (int i = 0; i < b->n_segments; i++) {
        amfi_cfg_pathf(p, "bridge.segments[%d]", i);
        if (b->segments[i].x1_m > b->span_m)
            return amfi_cfg_fail(x, amfi_cfg_first_noted(x, p, "bridge.span_m", NULL), p,
                        "to_m %g m is beyond the span (bridge.span_m = %g m)",
                        b->segments[i].x1_m, b->span_m);
        for (int j = 0; j < i; j++)
            if (b->segments[i].x0_m < b->segments[j].x1_m &&
                b->segments[j].x0_m < b->segments[i].x1_m)
                return amfi_cfg_fail(x, amfi_cfg_noted(x, p), p, "overlaps bridge.segments[%d] ([%g, %g) m)", j,
                            b->segments[j].x0_m, b->segments[j].x1_m);
    }

    /* Mode numbers within the model's free DOFs. */
    ndof = amfi_cfg_bridge_free_dofs(b);
    if (b->rayleigh_mode_a > ndof || b->rayleigh_mode_b > ndof)
        return amfi_cfg_fail(x, amfi_cfg_first_noted(x, "bridge.damping.modes", "bridge.elements", NULL),
                    "bridge.damping.modes", "the model has only %d modes (free DOFs)",
                    ndof);
    return 0;
}
