/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_classify.h: vehicle classes, axle groups and legal limits from what
 * a passage gives (axle count, spacings, axle loads); docs/classes.md has
 * the rules and their sources.
 *
 *   axle groups  adjacent axles at most group_spacing_m apart form a group
 *                (tandem, tridem, ...); its load is the sum of its axles'.
 *                An axle inside a group is not separable: one sensor under
 *                the span gives the group's sum, not how it splits.
 *   classes      the European default (scheme eu): CAR (two axles, up to
 *                light_max_kg), R2, R3, R4 (rigid), A22, A23, A32, A33
 *                (tractor + semi-trailer, the digits the tractor's and the
 *                trailer's axles), as sim_publisher simulates them; or the
 *                FHWA 13 classes (scheme fhwa13: FHWA1 .. FHWA13).
 *   limits       EU Directive 96/53/EC, Annex I: the gross weight of each
 *                European class and each group's limit by its kind
 *                (single, driving, tandem and tridem by spacing).
 *
 * Pure computation on the caller's data: no allocation, no I/O, no global
 * state; any thread.
 */
#ifndef AMFI_CLASSIFY_H
#define AMFI_CLASSIFY_H

#include <stddef.h>

#include "amfi/amfi.h" /* AMFI_MAX_AXLES */

#ifdef __cplusplus
extern "C" {
#endif

#define AMFI_CLASS_NAME_LEN 16

typedef enum amfi_class_scheme {
    AMFI_CLASS_SCHEME_EU = 0,     /* CAR, R2 .. A33 (default) */
    AMFI_CLASS_SCHEME_FHWA13 = 1  /* FHWA1 .. FHWA13 */
} amfi_class_scheme;

/* The European classes, in the order of the gvw_limit_kg array. */
typedef enum amfi_eu_class {
    AMFI_EU_CAR,
    AMFI_EU_R2,
    AMFI_EU_R3,
    AMFI_EU_R4,
    AMFI_EU_A22,
    AMFI_EU_A23,
    AMFI_EU_A32,
    AMFI_EU_A33,
    AMFI_EU_N
} amfi_eu_class;

typedef struct amfi_class_params {
    amfi_class_scheme scheme;
    double group_spacing_m;  /* axles at most this far apart are one group; 2.0 */
    double light_max_kg;     /* a two-axle vehicle up to this GVW is a CAR; 3500 */
    int container_44t;       /* 1: A33 may weigh 44 t (a 40-ft ISO container in
                                combined transport), else 40 t; 0 */
    double gvw_limit_kg[AMFI_EU_N]; /* per European class; 0: none (CAR) */
    double single_axle_kg;   /* a single non-driving axle; 10000 */
    double driving_axle_kg;  /* a single driving axle; 11500 */
    int motor_tandem_air;    /* 1: a motor vehicle's tandem of 1.3 .. 1.8 m may
                                carry 19 t (air suspension, twin tyres), else 18 t; 1 */
} amfi_class_params;

/* The defaults above, the GVW limits of 96/53/EC (docs/classes.md). */
void amfi_class_params_default(amfi_class_params *p);

/* Check p: 0, or −1 with *blamed the offending field's name (as in the site
 * file's classes: section) and a message. */
int amfi_class_params_check(const amfi_class_params *p, const char **blamed, char *why,
                            size_t whylen);

/* p as one line of "key=value" words ("scheme=eu group_spacing_m=2 ...
 * gvw_limit_kg.A23=40000 ..."; doubles with 17 significant digits): what
 * amfid ran with, recorded in the store's meta (daemon.classes) for the
 * reports. 0, or −1 when buf is too small. */
int amfi_class_params_format(const amfi_class_params *p, char *buf, size_t len);
/* The line back: every key once, and amfi_class_params_check passed. 0, or
 * −1 with why naming the key or the text at fault (*p untouched). */
int amfi_class_params_parse(const char *s, amfi_class_params *p, char *why, size_t whylen);

/* The kind of a group, for its legal limit. */
typedef enum amfi_group_kind {
    AMFI_GROUP_SINGLE,       /* a single non-driving axle (steer, trailer) */
    AMFI_GROUP_DRIVING,      /* a single driving axle */
    AMFI_GROUP_STEER_PAIR,   /* two steering axles (twin steer) */
    AMFI_GROUP_MOTOR_TANDEM, /* a tandem of a motor vehicle (rigid, tractor) */
    AMFI_GROUP_TANDEM,       /* a tandem of a trailer or semi-trailer */
    AMFI_GROUP_TRIDEM,       /* a tridem of a trailer or semi-trailer */
    AMFI_GROUP_OTHER         /* unknown class, or four axles and more */
} amfi_group_kind;

typedef struct amfi_axle_group {
    int first, n_axles;      /* axles first .. first + n_axles − 1 (0-based) */
    double load_kg;          /* sum of its axles' loads; NaN without loads */
    double spacing_m;        /* mean spacing inside the group; 0 for one axle */
    amfi_group_kind kind;
    double limit_kg;         /* its legal limit; NaN when none is known */
} amfi_axle_group;

/* A group (or single axle) whose load is more than this many times the
 * largest legal load of any group of its axle count (under the limits of
 * amfi_class_params, whatever the class) is not an overload but a load no
 * vehicle carries: the loads are refused (loads_why). */
#define AMFI_CLASS_IMPLAUSIBLE_FACTOR 10.0

#define AMFI_OVER_GVW 1u   /* gross weight above its class's limit */
#define AMFI_OVER_GROUP 2u /* a group (or single axle outside groups) above its limit */

typedef struct amfi_classification {
    char name[AMFI_CLASS_NAME_LEN]; /* "A23", "FHWA9", or "unknown" */
    int known;                      /* 0: no class of the scheme fits */
    int n_axles;
    int n_groups;
    amfi_axle_group group[AMFI_MAX_AXLES];
    int separable[AMFI_MAX_AXLES];  /* 0: the axle is inside a group */
    double gvw_kg;                  /* sum of the loads; NaN without loads */
    double gvw_limit_kg;            /* NaN when none */
    unsigned over;                  /* AMFI_OVER_*; 0 unless loads_ok */
    int loads_ok;                   /* 1: loads given and judged against the limits;
                                       0: none given, or refused (loads_why) */
    char loads_why[112];            /* why the loads were refused: a single axle or a
                                       group below zero, or above
                                       AMFI_CLASS_IMPLAUSIBLE_FACTOR x any legal load
                                       of its axle count; "" otherwise */
} amfi_classification;

/* Group n_axles axles (1 .. AMFI_MAX_AXLES) with n_axles − 1 spacings (m,
 * finite, > 0) at threshold group_spacing_m (a spacing equal to it joins):
 * fills g[] (first, n_axles, spacing_m, load_kg from axle_kg, or NaN when
 * axle_kg is NULL; kind OTHER, limit NaN) and returns the number of groups,
 * or −1 for bad arguments. */
int amfi_axle_groups(int n_axles, const double *spacing_m, const double *axle_kg,
                     double group_spacing_m, amfi_axle_group *g);

/* Classify a vehicle: its groups, class, limits and overloads under p.
 * axle_kg may be NULL (no loads: the CAR / R2 split then goes by R2, no
 * overload is decided). Loads are judged per group (a single axle is a
 * group of one): an axle inside a group is not separable, so it may be
 * negative as long as its group's sum is not (the group's sum is what is
 * classified and checked against the limits; separable[] flags such axles).
 * A single axle or a group below zero, or a group above
 * AMFI_CLASS_IMPLAUSIBLE_FACTOR x the largest legal load of any group of
 * its axle count, is a result the solve could not
 * give: the class and groups are still filled (loads reported as they are)
 * but the loads are refused: loads_ok 0, loads_why says which axle or group,
 * the class decided as without loads and no overload. 0, or −1 with a
 * message for bad arguments (axle count, a spacing that is not finite and
 * positive, a load that is not finite). An unknown class is not an error:
 * out->known = 0, name "unknown", the groups still filled. */
int amfi_classify(const amfi_class_params *p, int n_axles, const double *spacing_m,
                  const double *axle_kg, amfi_classification *out, char *err,
                  size_t errlen);

const char *amfi_class_scheme_name(amfi_class_scheme s); /* "eu", "fhwa13" */
/* The number of classes of scheme s (eu: 8, fhwa13: 13) and a class's
 * index from its name ("A23": AMFI_EU_A23; "FHWA9": 8), −1 when the name is
 * not a class of s ("unknown" is none). */
int amfi_class_count(amfi_class_scheme s);
int amfi_class_index(amfi_class_scheme s, const char *name);
const char *amfi_eu_class_name(amfi_eu_class c);          /* "CAR" .. "A33" */
const char *amfi_group_kind_name(amfi_group_kind k);      /* "single", "tandem", ... */

#ifdef __cplusplus
}
#endif

#endif /* AMFI_CLASSIFY_H */
