/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_site.c: the site: section of a site file, the identity of the
 * bridge a store and a bus belong to (amfi_site_identity): site.id, the
 * key amfid writes into the store at first start and refuses to open a
 * store under another one with, and that amfid's output messages and the
 * fleet's central database carry; site.name for people; optional
 * coordinates. Runs on the loader's thread.
 */
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define ID_CAP sizeof(((amfi_site_identity *)0)->id)
#define NAME_CAP sizeof(((amfi_site_identity *)0)->name)
#define TYPE_CAP sizeof(((amfi_site_identity *)0)->bridge_type)

int amfi_config_site_id_valid(const char *s)
{
    size_t n = s ? strlen(s) : 0;

    if (n == 0 || n >= ID_CAP)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char ch = s[i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
              (ch >= '0' && ch <= '9') || ch == '_' || ch == '.' || ch == '-'))
            return 0;
    }
    return 1;
}

/* site.id: [A-Za-z0-9_.-], 1 .. 63 bytes */
static int p_id(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_site_config *c = base;
    const char *s = amfi_cfg_scalar(x, v, path, "a site id", 1);

    (void)f;
    if (!s)
        return -1;
    if (!amfi_config_site_id_valid(s)) {
        char shown[SHOW_LEN + 8];
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path,
                    "must be 1 .. %zu bytes of A-Z a-z 0-9 _ . -, got '%s'", ID_CAP - 1,
                    amfi_cfg_show(shown, sizeof shown, v));
    }
    memset(c->site.id, 0, ID_CAP);
    memcpy(c->site.id, s, strlen(s));
    return 0;
}

static void d_id(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %zu bytes of A-Z a-z 0-9 _ . -", ID_CAP - 1);
}

static void v_id(const field *f, const void *base, char *buf)
{
    (void)f;
    snprintf(buf, DOC_LEN, "%s", ((const amfi_site_config *)base)->site.id);
}

/* site.name: free text, no control characters; absent: bridge.name */
static int p_sname(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_site_config *c = base;

    (void)f;
    return amfi_cfg_get_name(x, v, path, c->site.name, NAME_CAP);
}

static void d_sname(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %zu bytes, no control characters", NAME_CAP - 1);
}

static void v_sname(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "bridge.name");
}

/* site.bridge_type: free text for people and the fleet; absent: unknown */
static int p_btype(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    amfi_site_config *c = base;

    (void)f;
    return amfi_cfg_get_name(x, v, path, c->site.bridge_type, TYPE_CAP);
}

static void d_btype(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %zu bytes, no control characters", TYPE_CAP - 1);
}

static void v_btype(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "none");
}

static int s_btype(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(site.bridge_type), TYPE_CAP};
    return 1;
}

/* site.latitude / site.longitude: degrees (WGS 84); absent: unknown (NaN) */
static int p_coord(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    return amfi_cfg_k_double.parse(x, v, path, f, base);
}

static void d_coord(const field *f, const void *base, char *buf)
{
    (void)base;
    amfi_cfg_describe_interval(f, buf);
}

static void v_coord(const field *f, const void *base, char *buf)
{
    double d;

    memcpy(&d, (const char *)base + f->off, sizeof d);
    if (isnan(d))
        snprintf(buf, DOC_LEN, "none");
    else
        snprintf(buf, DOC_LEN, "%g", d);
}

static int s_id(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(site.id), ID_CAP};
    return 1;
}

static int s_sname(const field *f, span *out)
{
    (void)f;
    out[0] = (span){SC(site.name), NAME_CAP};
    return 1;
}

static const kind K_SITE_ID = {"string", p_id, d_id, v_id, NEST_NONE, s_id};
static const kind K_SITE_NAME = {"string", p_sname, d_sname, v_sname, NEST_NONE, s_sname};
static const kind K_BRIDGE_TYPE = {"string", p_btype, d_btype, v_btype, NEST_NONE, s_btype};
static const kind K_COORD = {"number", p_coord, d_coord, v_coord, NEST_NONE,
                             amfi_cfg_spans_double};

const field amfi_cfg_site_fields[] = {
    {.key = "id", .kind = &K_SITE_ID},
    {.key = "name", .kind = &K_SITE_NAME},
    {.key = "latitude", .kind = &K_COORD, .off = SC(site.latitude), .lo = -90, .hi = 90},
    {.key = "longitude", .kind = &K_COORD, .off = SC(site.longitude), .lo = -180,
     .hi = 180},
    {.key = "bridge_type", .kind = &K_BRIDGE_TYPE},
    {.key = NULL}};

/* site.name follows bridge.name when not given (bridge_check runs first);
 * a latitude without a longitude (or the reverse) is half a position. */
int amfi_cfg_site_check(ctx *x, amfi_site_config *c)
{
    if (!amfi_cfg_noted(x, "site.name")) {
        memset(c->site.name, 0, NAME_CAP);
        memcpy(c->site.name, c->name, sizeof c->name);
    }
    if (isnan(c->site.latitude) != isnan(c->site.longitude)) {
        int line = amfi_cfg_first_noted(x, "site.latitude", "site.longitude", NULL);
        return amfi_cfg_fail(x, line, isnan(c->site.latitude) ? "site.longitude" : "site.latitude",
                    "give both site.latitude and site.longitude, or neither");
    }
    return 0;
}
