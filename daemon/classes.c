/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * classes.c: the vehicle class and axle groups of every stored passage
 * (classify/, the site file's classes: section, docs/classes.md). A module
 * (ctx.h): restore records the classes and limits in force in the store's
 * meta (daemon.classes) for the reports; row fills the passage's class, its groups (the
 * axles per group front to back, "1-1-3") and, when it was solved, whether
 * its GVW or a group is above the legal limit. Classification needs only
 * the axle count and the detector's spacings, so passages that were not
 * solved get their class and groups too (their overload stays NULL, as it
 * does when the classifier refuses the loads: a single axle or a whole
 * group below zero; an axle below zero inside a group is not separable and
 * its group's sum is judged; or a group above ten times any legal load:
 * the reason is stored, passages.loads_refused); a
 * passage without axles or with a spacing the classifier refuses gets none
 * (NULL), which the detector's checks make rare (intake validates the
 * spacings before a vehicle becomes a passage).
 *
 * Thread: the main thread only. The row's strings point into this file's
 * state, valid until the next passage's row hook (the pipeline stores and
 * publishes one passage before it fills the next one's row).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amfi_classify.h"
#include "ctx.h"

static struct {
    char name[AMFI_CLASS_NAME_LEN];
    char groups[32];
    char refused[sizeof(((amfi_classification *)0)->loads_why)];
} C;

/* "1-1-3": the axles per group, front to back; 0 when it does not fit. */
static int groups_text(const amfi_classification *k, char *buf, size_t len)
{
    size_t n = 0;
    buf[0] = '\0';
    for (int g = 0; g < k->n_groups; g++) {
        int w = snprintf(buf + n, len - n, "%s%d", g ? "-" : "", k->group[g].n_axles);
        if (w < 0 || (size_t)w >= len - n)
            return 0;
        n += (size_t)w;
    }
    return n > 0;
}

static void classes_row(amfid_ctx *c, const amfid_passage *p, amfi_passage_row *r)
{
    (void)p;
    r->vclass = r->axle_groups = r->loads_refused = NULL;
    r->has_overload = r->overload = 0;
    if (r->n_axles < 1 || r->n_axles > AMFI_MAX_AXLES)
        return;
    /* finite loads go to the classifier as they are: an axle below zero
     * inside a group is the solve's split of the group's load (not
     * separable), the group's sum is judged; a single axle or a group below
     * zero, or one above ten times any legal load of its axle count,
     * refuses the loads (k.loads_ok 0): class and groups still stored, the
     * overload NULL, the reason in loads_refused */
    int loads = !isnan(r->gvw_kg);
    for (int a = 0; loads && a < r->n_axles; a++)
        loads = isfinite(r->axle_kg[a]);
    amfi_classification k;
    char err[160];
    if (amfi_classify(&c->cfg->classes, r->n_axles, r->spacing_m, loads ? r->axle_kg : NULL, &k,
                      err, sizeof err) != 0 &&
        (!loads || amfi_classify(&c->cfg->classes, r->n_axles, r->spacing_m, NULL, &k, err,
                                 sizeof err) != 0))
        return;
    snprintf(C.name, sizeof C.name, "%s", k.name);
    r->vclass = C.name;
    if (groups_text(&k, C.groups, sizeof C.groups))
        r->axle_groups = C.groups;
    if (loads && k.loads_ok) {
        r->has_overload = 1;
        r->overload = k.over != 0;
    } else if (loads && k.loads_why[0]) {
        snprintf(C.refused, sizeof C.refused, "%s", k.loads_why);
        r->loads_refused = C.refused;
    }
}

/* The store is open: the classes and limits this run uses, for the reports
 * (meta daemon.classes; a reload does not change them). */
static int classes_restore(amfid_ctx *c)
{
    char text[1024], err[512];
    snprintf(err, sizeof err, "the text is longer than %zu bytes", sizeof text);
    if (amfi_class_params_format(&c->cfg->classes, text, sizeof text) != 0
        || amfi_store_meta_set(c->store, "daemon.classes", text, err, sizeof err) != 0)
        LOG_WARN("store: the classes' parameters not recorded: %s", err);
    return 0;
}

const amfid_module classes_module = {
    .name = "classes", .section = "classes", .restore = classes_restore, .row = classes_row,
};
