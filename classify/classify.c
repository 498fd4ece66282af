/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * classify.c: axle groups, classes and legal limits (amfi_classify.h; the
 * rules and their sources in docs/classes.md).
 */
#include "amfi_classify.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A two-axle front of a four-axle rigid truck (twin steer, 1.7 .. 2.1 m in
 * the simulated population) when farther apart than the group threshold:
 * a first spacing up to this is a twin steer, above it (3.3 m and more for
 * a two-axle tractor) a tractor's wheelbase. */
#define TWIN_STEER_MAX_M 2.5

static const char *const eu_names[AMFI_EU_N] = {"CAR", "R2",  "R3",  "R4",
                                                "A22", "A23", "A32", "A33"};

const char *amfi_eu_class_name(amfi_eu_class c)
{
    return c >= 0 && c < AMFI_EU_N ? eu_names[c] : "unknown";
}

const char *amfi_class_scheme_name(amfi_class_scheme s)
{
    return s == AMFI_CLASS_SCHEME_FHWA13 ? "fhwa13" : "eu";
}

int amfi_class_count(amfi_class_scheme s)
{
    return s == AMFI_CLASS_SCHEME_FHWA13 ? 13 : AMFI_EU_N;
}

int amfi_class_index(amfi_class_scheme s, const char *name)
{
    if (!name)
        return -1;
    if (s == AMFI_CLASS_SCHEME_FHWA13) {
        char buf[AMFI_CLASS_NAME_LEN];
        for (int k = 1; k <= 13; k++) {
            snprintf(buf, sizeof buf, "FHWA%d", k);
            if (strcmp(name, buf) == 0)
                return k - 1;
        }
        return -1;
    }
    for (int k = 0; k < AMFI_EU_N; k++)
        if (strcmp(name, eu_names[k]) == 0)
            return k;
    return -1;
}

const char *amfi_group_kind_name(amfi_group_kind k)
{
    switch (k) {
    case AMFI_GROUP_SINGLE: return "single";
    case AMFI_GROUP_DRIVING: return "driving";
    case AMFI_GROUP_STEER_PAIR: return "steer pair";
    case AMFI_GROUP_MOTOR_TANDEM: return "motor tandem";
    case AMFI_GROUP_TANDEM: return "tandem";
    case AMFI_GROUP_TRIDEM: return "tridem";
    default: return "other";
    }
}

void amfi_class_params_default(amfi_class_params *p)
{
    memset(p, 0, sizeof *p);
    p->scheme = AMFI_CLASS_SCHEME_EU;
    p->group_spacing_m = 2.0;
    p->light_max_kg = 3500.0;
    p->container_44t = 0;
    /* Directive 96/53/EC, Annex I, point 2 (docs/classes.md) */
    p->gvw_limit_kg[AMFI_EU_CAR] = 0.0; /* none: not a heavy vehicle */
    p->gvw_limit_kg[AMFI_EU_R2] = 18000.0;
    p->gvw_limit_kg[AMFI_EU_R3] = 26000.0;
    p->gvw_limit_kg[AMFI_EU_R4] = 32000.0;
    p->gvw_limit_kg[AMFI_EU_A22] = 36000.0;
    p->gvw_limit_kg[AMFI_EU_A23] = 40000.0;
    p->gvw_limit_kg[AMFI_EU_A32] = 40000.0;
    p->gvw_limit_kg[AMFI_EU_A33] = 40000.0;
    /* Annex I, point 3 */
    p->single_axle_kg = 10000.0;
    p->driving_axle_kg = 11500.0;
    p->motor_tandem_air = 1;
}

#define WHY(name, ...)                                                    \
    do {                                                                  \
        if (blamed)                                                       \
            *blamed = (name);                                             \
        if (why && whylen)                                                \
            snprintf(why, whylen, __VA_ARGS__);                           \
        return -1;                                                        \
    } while (0)

int amfi_class_params_check(const amfi_class_params *p, const char **blamed, char *why,
                            size_t whylen)
{
    if (p->scheme != AMFI_CLASS_SCHEME_EU && p->scheme != AMFI_CLASS_SCHEME_FHWA13)
        WHY("scheme", "scheme %d: eu or fhwa13", (int)p->scheme);
    if (!(p->group_spacing_m >= 1.0 && p->group_spacing_m <= 2.5))
        WHY("group_spacing_m",
            "group_spacing_m %g: 1.0 .. 2.5 m (tandem and tridem axles are about 1.3 m "
            "apart, the groups of a truck 2.6 m and more)",
            p->group_spacing_m);
    if (!(p->light_max_kg >= 500.0 && p->light_max_kg <= 7500.0))
        WHY("light_max_kg", "light_max_kg %g: 500 .. 7500 kg", p->light_max_kg);
    if (p->container_44t != 0 && p->container_44t != 1)
        WHY("container_44t", "container_44t %d: 0 or 1", p->container_44t);
    if (p->motor_tandem_air != 0 && p->motor_tandem_air != 1)
        WHY("motor_tandem_air", "motor_tandem_air %d: 0 or 1", p->motor_tandem_air);
    for (int c = 0; c < AMFI_EU_N; c++) {
        const double v = p->gvw_limit_kg[c];
        if (!(v == 0.0 || (v >= 1000.0 && v <= 100000.0)))
            WHY(eu_names[c], "gvw_limit_kg.%s %g: 0 (none) or 1000 .. 100000 kg", eu_names[c],
                v);
    }
    if (!(p->single_axle_kg >= 1000.0 && p->single_axle_kg <= 30000.0))
        WHY("single_axle_kg", "single_axle_kg %g: 1000 .. 30000 kg", p->single_axle_kg);
    if (!(p->driving_axle_kg >= 1000.0 && p->driving_axle_kg <= 30000.0))
        WHY("driving_axle_kg", "driving_axle_kg %g: 1000 .. 30000 kg", p->driving_axle_kg);
    return 0;
}

int amfi_axle_groups(int n_axles, const double *spacing_m, const double *axle_kg,
                     double group_spacing_m, amfi_axle_group *g)
{
    if (n_axles < 1 || n_axles > AMFI_MAX_AXLES || (n_axles > 1 && !spacing_m) || !g ||
        !(group_spacing_m > 0.0))
        return -1;
    for (int a = 0; a + 1 < n_axles; a++)
        if (!(isfinite(spacing_m[a]) && spacing_m[a] > 0.0))
            return -1;
    int ng = 0;
    for (int a = 0; a < n_axles;) {
        int b = a + 1;
        double sum_sp = 0.0;
        while (b < n_axles && spacing_m[b - 1] <= group_spacing_m) {
            sum_sp += spacing_m[b - 1];
            b++;
        }
        amfi_axle_group *gr = &g[ng++];
        gr->first = a;
        gr->n_axles = b - a;
        gr->spacing_m = gr->n_axles > 1 ? sum_sp / (gr->n_axles - 1) : 0.0;
        gr->load_kg = NAN;
        if (axle_kg) {
            gr->load_kg = 0.0;
            for (int k = a; k < b; k++)
                gr->load_kg += axle_kg[k];
        }
        gr->kind = AMFI_GROUP_OTHER;
        gr->limit_kg = NAN;
        a = b;
    }
    return ng;
}

/* ---- the European classes -------------------------------------------------- */

/* Group sizes as a number: [1,1,3] is 113; 0 (no class) for more than four
 * groups: no class has more than three, and twelve single axles would
 * overflow the number. */
static int pattern(const amfi_classification *c)
{
    int v = 0;
    if (c->n_groups > 4)
        return 0;
    for (int i = 0; i < c->n_groups; i++)
        v = 10 * v + (c->group[i].n_axles < 9 ? c->group[i].n_axles : 9);
    return v;
}

static int eu_class(const amfi_class_params *p, const amfi_classification *c,
                    const double *spacing_m)
{
    switch (pattern(c)) {
    case 11: /* two single axles: a car or van up to light_max_kg */
        return c->loads_ok && c->gvw_kg <= p->light_max_kg ? AMFI_EU_CAR : AMFI_EU_R2;
    case 12:
        return AMFI_EU_R3;
    case 22:
        return AMFI_EU_R4;
    case 112: /* twin steer wider than the threshold, or a two-axle tractor */
        return spacing_m[0] <= TWIN_STEER_MAX_M ? AMFI_EU_R4 : AMFI_EU_A22;
    case 113:
        return AMFI_EU_A23;
    case 122:
        return AMFI_EU_A32;
    case 123:
        return AMFI_EU_A33;
    default:
        return -1;
    }
}

/* Directive 96/53/EC, Annex I, point 3, by the group's (mean) spacing d. */
static double group_limit(const amfi_class_params *p, amfi_group_kind k, double d)
{
    switch (k) {
    case AMFI_GROUP_SINGLE: return p->single_axle_kg;
    case AMFI_GROUP_DRIVING: return p->driving_axle_kg;
    case AMFI_GROUP_STEER_PAIR: return 2.0 * p->single_axle_kg;
    case AMFI_GROUP_MOTOR_TANDEM: /* 3.5: bands up to 1.8 m; beyond, the last band's */
        return d < 1.0 ? 11500.0 : d < 1.3 ? 16000.0 : p->motor_tandem_air ? 19000.0 : 18000.0;
    case AMFI_GROUP_TANDEM: /* 3.2 */
        return d < 1.0 ? 11000.0 : d < 1.3 ? 16000.0 : d < 1.8 ? 18000.0 : 20000.0;
    case AMFI_GROUP_TRIDEM: /* 3.3: bands up to 1.4 m; beyond, the last band's */
        return d <= 1.3 ? 21000.0 : 24000.0;
    default: return NAN;
    }
}

/* The largest legal load of any group of n axles under p's limits (Council
 * Directive 96/53/EC, Annex I, 3: a single driving axle, the widest trailer
 * tandem or twin steer, the widest tridem; a longer group as that many
 * driving axles), whatever the class and scheme: the scale against which a
 * load is implausible (AMFI_CLASS_IMPLAUSIBLE_FACTOR). */
static double largest_legal_kg(const amfi_class_params *p, int n)
{
    const double single = fmax(p->single_axle_kg, p->driving_axle_kg);
    if (n <= 1)
        return single;
    if (n == 2)
        return fmax(fmax(group_limit(p, AMFI_GROUP_TANDEM, 1.8),
                         group_limit(p, AMFI_GROUP_MOTOR_TANDEM, 1.8)),
                    group_limit(p, AMFI_GROUP_STEER_PAIR, 0.0));
    if (n == 3)
        return group_limit(p, AMFI_GROUP_TRIDEM, 1.4);
    return n * single;
}

/* The kinds of the groups of a European class. */
static void eu_kinds(int cls, amfi_classification *c)
{
    const int ng = c->n_groups;
    for (int i = 0; i < ng; i++)
        c->group[i].kind = AMFI_GROUP_SINGLE;
    switch (cls) {
    case AMFI_EU_R2:
        c->group[1].kind = AMFI_GROUP_DRIVING;
        break;
    case AMFI_EU_R3:
        c->group[1].kind = AMFI_GROUP_MOTOR_TANDEM;
        break;
    case AMFI_EU_R4:
        if (ng == 2) {
            c->group[0].kind = AMFI_GROUP_STEER_PAIR;
            c->group[1].kind = AMFI_GROUP_MOTOR_TANDEM;
        } else {
            c->group[2].kind = AMFI_GROUP_MOTOR_TANDEM;
        }
        break;
    case AMFI_EU_A22:
        c->group[1].kind = AMFI_GROUP_DRIVING;
        c->group[2].kind = AMFI_GROUP_TANDEM;
        break;
    case AMFI_EU_A23:
        c->group[1].kind = AMFI_GROUP_DRIVING;
        c->group[2].kind = AMFI_GROUP_TRIDEM;
        break;
    case AMFI_EU_A32:
        c->group[1].kind = AMFI_GROUP_MOTOR_TANDEM;
        c->group[2].kind = AMFI_GROUP_TANDEM;
        break;
    case AMFI_EU_A33:
        c->group[1].kind = AMFI_GROUP_MOTOR_TANDEM;
        c->group[2].kind = AMFI_GROUP_TRIDEM;
        break;
    default:
        break;
    }
}

/* ---- the FHWA 13 classes --------------------------------------------------- */

#define FT 0.3048

/* FHWA Traffic Monitoring Guide's 13 classes from the axle count and the
 * groups (docs/classes.md gives the table and its simplifications). */
static int fhwa_class(const amfi_classification *c, const double *spacing_m)
{
    const int n = c->n_axles, ng = c->n_groups;
    if (n < 2)
        return -1;
    if (n == 2) {
        const double s = spacing_m[0];
        if (s < 6.0 * FT)
            return 1;  /* motorcycle */
        if (s < 10.2 * FT)
            return 2;  /* passenger car */
        if (s < 13.3 * FT)
            return 3;  /* pickup, van */
        if (s < 23.0 * FT)
            return 5;  /* two-axle six-tyre single unit */
        return 4;      /* bus */
    }
    if (n == 3) {
        if (ng == 2 && c->group[0].n_axles == 1)
            return spacing_m[0] >= 23.0 * FT ? 4 : 6; /* bus, or three-axle single unit */
        return 8;
    }
    if (n == 4)
        return ng == 2 && c->group[0].n_axles == 1 ? 7 : 8;
    if (n == 5)
        return ng == 2 ? 7 : ng == 3 ? 9 : 11;
    if (n == 6)
        return ng == 2 ? 7 : ng == 3 ? 10 : 12;
    return ng <= 3 ? 10 : 13;
}

int amfi_classify(const amfi_class_params *p, int n_axles, const double *spacing_m,
                  const double *axle_kg, amfi_classification *out, char *err,
                  size_t errlen)
{
#define BAD(...)                                                          \
    do {                                                                  \
        if (err && errlen)                                                \
            snprintf(err, errlen, __VA_ARGS__);                           \
        return -1;                                                        \
    } while (0)
    if (!p || !out)
        BAD("classify: NULL argument");
    if (n_axles < 1 || n_axles > AMFI_MAX_AXLES)
        BAD("%d axles: 1 .. %d", n_axles, AMFI_MAX_AXLES);
    if (n_axles > 1 && !spacing_m)
        BAD("%d axles but no spacings", n_axles);
    for (int a = 0; a + 1 < n_axles; a++)
        if (!(isfinite(spacing_m[a]) && spacing_m[a] > 0.0))
            BAD("spacing %d (axles %d-%d): %g m, must be > 0", a + 1, a + 1, a + 2,
                spacing_m[a]);
    if (axle_kg)
        for (int a = 0; a < n_axles; a++)
            if (!isfinite(axle_kg[a]))
                BAD("axle %d: load %g kg, must be finite", a + 1, axle_kg[a]);
    memset(out, 0, sizeof *out);
    out->n_axles = n_axles;
    out->n_groups = amfi_axle_groups(n_axles, spacing_m, axle_kg, p->group_spacing_m,
                                     out->group);
    if (out->n_groups < 1)
        BAD("group_spacing_m %g: must be > 0", p->group_spacing_m);
    for (int i = 0; i < out->n_groups; i++)
        for (int k = 0; k < out->group[i].n_axles; k++)
            out->separable[out->group[i].first + k] = out->group[i].n_axles == 1;
    out->gvw_kg = NAN;
    if (axle_kg) {
        out->gvw_kg = 0.0;
        for (int a = 0; a < n_axles; a++)
            out->gvw_kg += axle_kg[a];
        /* An axle inside a group is not separable: only the group's sum is
         * judged, a negative share of it is how the solve split the group.
         * A single axle or a group below zero is a load the solve could not
         * give: the loads are refused (reported as they are, no limits). */
        out->loads_ok = 1;
        for (int i = 0; i < out->n_groups && out->loads_ok; i++) {
            const amfi_axle_group *g = &out->group[i];
            const double most = AMFI_CLASS_IMPLAUSIBLE_FACTOR * largest_legal_kg(p, g->n_axles);
            if (g->load_kg > most) {
                /* no vehicle carries that: a broken solve or a wrong
                 * detector record, not an overload */
                out->loads_ok = 0;
                snprintf(out->loads_why, sizeof out->loads_why,
                         "%s %d: load %.0f kg, over %g x any legal load of %d axle%s (%.0f kg)",
                         g->n_axles == 1 ? "single axle" : "group",
                         g->n_axles == 1 ? g->first + 1 : i + 1,
                         g->load_kg, AMFI_CLASS_IMPLAUSIBLE_FACTOR, g->n_axles,
                         g->n_axles == 1 ? "" : "s", most / AMFI_CLASS_IMPLAUSIBLE_FACTOR);
                break;
            }
            if (g->load_kg >= 0.0)
                continue;
            out->loads_ok = 0;
            if (g->n_axles == 1)
                snprintf(out->loads_why, sizeof out->loads_why,
                         "axle %d: load %.0f kg < 0 (a single axle)", g->first + 1, g->load_kg);
            else
                snprintf(out->loads_why, sizeof out->loads_why,
                         "group %d (axles %d-%d): load %.0f kg < 0", i + 1, g->first + 1,
                         g->first + g->n_axles, g->load_kg);
        }
    }
    out->gvw_limit_kg = NAN;
    int cls;
    if (p->scheme == AMFI_CLASS_SCHEME_FHWA13) {
        cls = fhwa_class(out, spacing_m);
        if (cls > 0)
            snprintf(out->name, sizeof out->name, "FHWA%d", cls);
    } else {
        cls = eu_class(p, out, spacing_m);
        if (cls >= 0) {
            snprintf(out->name, sizeof out->name, "%s", eu_names[cls]);
            double lim = p->gvw_limit_kg[cls];
            if (cls == AMFI_EU_A33 && p->container_44t)
                lim = 44000.0;
            out->gvw_limit_kg = lim > 0.0 ? lim : NAN;
            if (cls != AMFI_EU_CAR) {
                eu_kinds(cls, out);
                for (int i = 0; i < out->n_groups; i++)
                    out->group[i].limit_kg =
                        group_limit(p, out->group[i].kind, out->group[i].spacing_m);
            }
        }
    }
    out->known = cls >= 0;
    if (!out->known)
        snprintf(out->name, sizeof out->name, "unknown");
    if (out->loads_ok && isfinite(out->gvw_limit_kg) && out->gvw_kg > out->gvw_limit_kg)
        out->over |= AMFI_OVER_GVW;
    for (int i = 0; out->loads_ok && i < out->n_groups; i++)
        if (isfinite(out->group[i].load_kg) && isfinite(out->group[i].limit_kg) &&
            out->group[i].load_kg > out->group[i].limit_kg)
            out->over |= AMFI_OVER_GROUP;
    return 0;
#undef BAD
}

/* ---- the text form (meta daemon.classes) ------------------------------------------ */

#define N_CLASS_KEYS (7 + AMFI_EU_N)

/* The k-th key of the text form and a pointer to its value in p: *is_int
 * 1 for an int, 2 for the scheme, 0 for a double. */
static void *class_key(amfi_class_params *p, int k, char *key, size_t len, int *is_int)
{
    static const char *const fixed[] = {"scheme", "group_spacing_m", "light_max_kg",
                                        "container_44t", "single_axle_kg", "driving_axle_kg",
                                        "motor_tandem_air"};
    if (k >= 4 && k < 4 + AMFI_EU_N) {
        snprintf(key, len, "gvw_limit_kg.%s", amfi_eu_class_name((amfi_eu_class)(k - 4)));
        *is_int = 0;
        return &p->gvw_limit_kg[k - 4];
    }
    int f = k < 4 ? k : k - AMFI_EU_N;
    snprintf(key, len, "%s", fixed[f]);
    switch (f) {
    case 0: *is_int = 2; return &p->scheme;
    case 1: *is_int = 0; return &p->group_spacing_m;
    case 2: *is_int = 0; return &p->light_max_kg;
    case 3: *is_int = 1; return &p->container_44t;
    case 4: *is_int = 0; return &p->single_axle_kg;
    case 5: *is_int = 0; return &p->driving_axle_kg;
    default: *is_int = 1; return &p->motor_tandem_air;
    }
}

int amfi_class_params_format(const amfi_class_params *p, char *buf, size_t len)
{
    amfi_class_params q = *p;
    size_t at = 0;
    if (!buf || len == 0)
        return -1;
    buf[0] = '\0';
    for (int k = 0; k < N_CLASS_KEYS; k++) {
        char key[48];
        int kind = 0;
        void *v = class_key(&q, k, key, sizeof key, &kind);
        int n = kind == 2   ? snprintf(buf + at, len - at, "%s%s=%s", k ? " " : "", key,
                                       amfi_class_scheme_name(*(amfi_class_scheme *)v))
                : kind == 1 ? snprintf(buf + at, len - at, "%s%s=%d", k ? " " : "", key,
                                       *(int *)v)
                            : snprintf(buf + at, len - at, "%s%s=%.17g", k ? " " : "", key,
                                       *(double *)v);
        if (n < 0 || (size_t)n >= len - at)
            return -1;
        at += (size_t)n;
    }
    return 0;
}

int amfi_class_params_parse(const char *s, amfi_class_params *p, char *why, size_t whylen)
{
    amfi_class_params q;
    int seen[N_CLASS_KEYS] = {0};
    const char *blamed = NULL;
    amfi_class_params_default(&q);
    if (!s || !p) {
        snprintf(why, whylen, "NULL argument");
        return -1;
    }
    for (const char *c = s; *c;) {
        while (*c == ' ')
            c++;
        if (!*c)
            break;
        const char *eq = strchr(c, '='), *end = strchr(c, ' ');
        if (!end)
            end = c + strlen(c);
        int k = 0, kind = 0;
        char key[48], val[64];
        void *v = NULL;
        for (; eq && eq < end && k < N_CLASS_KEYS; k++) {
            v = class_key(&q, k, key, sizeof key, &kind);
            if (strlen(key) == (size_t)(eq - c) && strncmp(c, key, (size_t)(eq - c)) == 0)
                break;
        }
        if (!eq || eq >= end || k == N_CLASS_KEYS) {
            snprintf(why, whylen, "unknown field at '%.40s'", c);
            return -1;
        }
        if (seen[k]++) {
            snprintf(why, whylen, "%s given twice", key);
            return -1;
        }
        size_t vl = (size_t)(end - eq - 1);
        if (vl == 0 || vl >= sizeof val) {
            snprintf(why, whylen, "%s: no value, or too long", key);
            return -1;
        }
        memcpy(val, eq + 1, vl);
        val[vl] = '\0';
        char *stop = NULL;
        if (kind == 2) {
            if (strcmp(val, "eu") == 0)
                *(amfi_class_scheme *)v = AMFI_CLASS_SCHEME_EU;
            else if (strcmp(val, "fhwa13") == 0)
                *(amfi_class_scheme *)v = AMFI_CLASS_SCHEME_FHWA13;
            else {
                snprintf(why, whylen, "%s: '%.20s' is not eu or fhwa13", key, val);
                return -1;
            }
        } else if (kind == 1) {
            long x = strtol(val, &stop, 10);
            if (*stop || x < 0 || x > 1) {
                snprintf(why, whylen, "%s: '%.20s' is not 0 or 1", key, val);
                return -1;
            }
            *(int *)v = (int)x;
        } else {
            double x = strtod(val, &stop);
            if (*stop || !isfinite(x)) {
                snprintf(why, whylen, "%s: '%.20s' is not a number", key, val);
                return -1;
            }
            *(double *)v = x;
        }
        c = end;
    }
    for (int k = 0; k < N_CLASS_KEYS; k++)
        if (!seen[k]) {
            char key[48];
            int kind = 0;
            class_key(&q, k, key, sizeof key, &kind);
            snprintf(why, whylen, "%s missing", key);
            return -1;
        }
    char w[160];
    if (amfi_class_params_check(&q, &blamed, w, sizeof w) != 0) {
        snprintf(why, whylen, "%s", w);
        return -1;
    }
    *p = q;
    return 0;
}
