/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * mix.c: the drifting loaded/empty traffic mix (mix.h; the figures and
 * their sources in docs/simulator.md, "Traffic mix"). Pure computation;
 * any thread.
 */
#include "mix.h"

#include <math.h>

#define TWO_PI 6.283185307179586
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void amfi_mix_params_site(amfi_mix_params *p)
{
    memset(p, 0, sizeof *p);
    p->split_kg = 8800.0;
    p->weekday_share = 0.52;
    p->weekend_share = 0.40;
    p->seasonal_amp = 0.05;
    p->weekend_flow = 0.35;
    p->day0_weekday = 3; /* 2026-01-01 is a Thursday */
}

int amfi_mix_weekday(const amfi_mix_params *p, double day)
{
    long d = (long)floor(day) + p->day0_weekday;
    return (int)(((d % 7) + 7) % 7);
}

double amfi_mix_loaded_share(const amfi_mix_params *p, double day)
{
    const int wd = amfi_mix_weekday(p, day);
    double s = wd >= 5 ? p->weekend_share : p->weekday_share;
    s -= p->seasonal_amp * cos(TWO_PI * (day - 15.0) / 365.25);
    return s < 0.02 ? 0.02 : s > 0.98 ? 0.98 : s;
}

double amfi_mix_flow_factor(const amfi_mix_params *p, double day)
{
    return amfi_mix_weekday(p, day) >= 5 ? p->weekend_flow : 1.0;
}

void amfi_mix_classes_free(amfi_mix_classes *c)
{
    if (!c)
        return;
    free(c->empty);
    free(c->loaded);
    memset(c, 0, sizeof *c);
}

int amfi_mix_classify(const amfi_vehicle_rec *recs, int n, double split_kg,
                      amfi_mix_classes *c, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->empty = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    c->loaded = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!c->empty || !c->loaded) {
        amfi_mix_classes_free(c);
        if (errlen)
            snprintf(err, errlen, "traffic mix: out of memory");
        return AMFI_ENOMEM;
    }
    for (int i = 0; i < n; i++) {
        if (recs[i].gvw_kg >= split_kg)
            c->loaded[c->n_loaded++] = i;
        else
            c->empty[c->n_empty++] = i;
    }
    if (!c->n_empty || !c->n_loaded) {
        if (errlen)
            snprintf(err, errlen, "traffic mix: splitting %d vehicles at %g kg leaves no %s "
                     "vehicle", n, split_kg, c->n_empty ? "loaded" : "empty");
        amfi_mix_classes_free(c);
        return AMFI_EINVAL;
    }
    return 0;
}

int amfi_mix_pick(const amfi_mix_classes *c, double share, double u_class, double u_pick)
{
    const int loaded = u_class < share;
    const int n = loaded ? c->n_loaded : c->n_empty;
    int k = (int)(u_pick * n);
    if (k >= n)
        k = n - 1;
    if (k < 0)
        k = 0;
    return loaded ? c->loaded[k] : c->empty[k];
}

static int cmp_double(const void *a, const void *b);

int amfi_mix_classify_by_class(const amfi_vehicle_rec *recs, int n, amfi_mix_classes *c,
                               char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    int nk = 1; /* class k at k + 1, no class at 0 */
    for (int i = 0; i < n; i++)
        if (recs[i].vclass + 2 > nk)
            nk = recs[i].vclass + 2;
    double *split = calloc((size_t)nk, sizeof *split), *g = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    if (!split || !g) {
        free(split);
        free(g);
        if (errlen)
            snprintf(err, errlen, "traffic mix: out of memory");
        return AMFI_ENOMEM;
    }
    for (int k = 0; k < nk; k++) {
        int m = 0;
        for (int i = 0; i < n; i++)
            if (recs[i].vclass + 1 == k)
                g[m++] = recs[i].gvw_kg;
        if (!m)
            continue;
        qsort(g, (size_t)m, sizeof *g, cmp_double);
        split[k] = m % 2 ? g[m / 2] : 0.5 * (g[m / 2 - 1] + g[m / 2]);
    }
    free(g);
    c->empty = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    c->loaded = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!c->empty || !c->loaded) {
        free(split);
        amfi_mix_classes_free(c);
        if (errlen)
            snprintf(err, errlen, "traffic mix: out of memory");
        return AMFI_ENOMEM;
    }
    for (int i = 0; i < n; i++) {
        if (recs[i].gvw_kg >= split[recs[i].vclass + 1])
            c->loaded[c->n_loaded++] = i;
        else
            c->empty[c->n_empty++] = i;
    }
    free(split);
    if (!c->n_empty || !c->n_loaded) {
        if (errlen)
            snprintf(err, errlen, "traffic mix: splitting %d vehicles at their classes' median "
                     "GVW leaves no %s vehicle", n, c->n_empty ? "loaded" : "empty");
        amfi_mix_classes_free(c);
        return AMFI_EINVAL;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double amfi_mix_median_gvw(const amfi_vehicle_rec *recs, int n)
{
    double *g = malloc(sizeof(double) * (size_t)n), m;
    if (!g)
        return recs[n / 2].gvw_kg;
    for (int i = 0; i < n; i++)
        g[i] = recs[i].gvw_kg;
    qsort(g, (size_t)n, sizeof *g, cmp_double);
    m = n % 2 ? g[n / 2] : 0.5 * (g[n / 2 - 1] + g[n / 2]);
    free(g);
    return m;
}
