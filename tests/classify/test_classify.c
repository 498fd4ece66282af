/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_classify.c: classify/amfi_classify.h. Axle groups from the spacings
 * at the threshold's edges; every European class recognised from
 * sim_publisher's own class definitions (vclass.c: the spacings at their
 * means and at the ends of their ranges, light and heavy); the FHWA 13
 * classes of typical vehicles; the legal limits of 96/53/EC by class and
 * group, overloads of the gross weight and of a group; bad parameters and
 * arguments refused with a message naming them.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "amfi_classify.h"
#include "vclass.h"

static amfi_class_params eu(void)
{
    amfi_class_params p;
    amfi_class_params_default(&p);
    return p;
}

/* Groups at the threshold: a spacing equal to it joins, one a hair above
 * it parts; loads are summed per group; axles inside a group are not
 * separable. */
static void groups_at_threshold(void **state)
{
    (void)state;
    amfi_axle_group g[AMFI_MAX_AXLES];
    const double t = 2.0;
    const double kg[5] = {6000, 10000, 7000, 7100, 7200};
    double sp[4] = {3.6, 6.0, t, t};
    assert_int_equal(amfi_axle_groups(5, sp, kg, t, g), 3);
    assert_int_equal(g[2].first, 2);
    assert_int_equal(g[2].n_axles, 3);
    assert_true(fabs(g[2].load_kg - 21300.0) < 1e-9);
    assert_true(fabs(g[2].spacing_m - t) < 1e-12);
    sp[3] = nextafter(t, 3.0); /* the last axle parts */
    assert_int_equal(amfi_axle_groups(5, sp, kg, t, g), 4);
    assert_int_equal(g[2].n_axles, 2);
    assert_int_equal(g[3].first, 4);
    assert_true(fabs(g[3].load_kg - 7200.0) < 1e-9);
    sp[2] = nextafter(t, 3.0); /* all single */
    assert_int_equal(amfi_axle_groups(5, sp, kg, t, g), 5);
    /* one axle: one group; no loads: NaN */
    assert_int_equal(amfi_axle_groups(1, NULL, NULL, t, g), 1);
    assert_int_equal(g[0].n_axles, 1);
    assert_true(isnan(g[0].load_kg));
    /* the separable flags through amfi_classify */
    amfi_class_params p = eu();
    amfi_classification c;
    const double a23[4] = {3.75, 6.0, 1.31, 1.31};
    assert_int_equal(amfi_classify(&p, 5, a23, kg, &c, NULL, 0), 0);
    const int want[5] = {1, 1, 0, 0, 0};
    for (int a = 0; a < 5; a++)
        assert_int_equal(c.separable[a], want[a]);
    /* bad input */
    const double bad[1] = {0.0};
    assert_int_equal(amfi_axle_groups(2, bad, NULL, t, g), -1);
    assert_int_equal(amfi_axle_groups(0, sp, NULL, t, g), -1);
    assert_int_equal(amfi_axle_groups(AMFI_MAX_AXLES + 1, sp, NULL, t, g), -1);
}

/* sim_publisher's class of vehicle i with spacings at `at` (0 mean, −1 the
 * low ends, +1 the high ends) and loads shared as loaded (GVW at the
 * class's loaded mean) or empty. */
static void vclass_vehicle(const amfi_vclass *vc, int at, int loaded, double *sp, double *kg)
{
    for (int i = 0; i + 1 < vc->n_axles; i++)
        sp[i] = at < 0 ? vc->sp_lo[i] : at > 0 ? vc->sp_hi[i] : vc->sp_mu[i];
    const double gvw = loaded ? vc->loaded_mu : vc->empty_mu;
    for (int a = 0; a < vc->n_axles; a++)
        kg[a] = gvw * (loaded ? vc->share_loaded[a] : vc->share_empty[a]);
}

/* Every class sim_publisher simulates is recognised under its own name,
 * with the groups of its definition (vclass.c's group[]) or, for R4's twin
 * steer wider than the threshold, its steering axles single; at the means
 * and at both ends of every spacing range, empty and loaded. */
static void every_eu_class_from_vclass(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    assert_true(amfi_vclass_count() == 7);
    for (int i = 0; i < amfi_vclass_count(); i++) {
        const amfi_vclass *vc = amfi_vclass_get(i);
        for (int at = -1; at <= 1; at++)
            for (int loaded = 0; loaded <= 1; loaded++) {
                double sp[AMFI_MAX_AXLES], kg[AMFI_MAX_AXLES];
                vclass_vehicle(vc, at, loaded, sp, kg);
                amfi_classification c;
                char err[128];
                assert_int_equal(amfi_classify(&p, vc->n_axles, sp, kg, &c, err, sizeof err),
                                 0);
                if (strcmp(c.name, vc->name) != 0)
                    fail_msg("%s (spacings %s, %s): classed %s", vc->name,
                             at < 0 ? "low" : at > 0 ? "high" : "mean",
                             loaded ? "loaded" : "empty", c.name);
                assert_true(c.known);
                /* the definition's groups, but a twin steer beyond the threshold */
                int gid[AMFI_MAX_AXLES];
                for (int k = 0; k < c.n_groups; k++)
                    for (int a = 0; a < c.group[k].n_axles; a++)
                        gid[c.group[k].first + a] = k;
                for (int a = 0; a + 1 < vc->n_axles; a++) {
                    const int same = gid[a] == gid[a + 1];
                    const int def = vc->group[a] == vc->group[a + 1];
                    if (def != same && !(vc->n_axles == 4 && vc->tractor_axles == 0 && a == 0 &&
                                         sp[0] > p.group_spacing_m))
                        fail_msg("%s: axles %d and %d grouped %d, defined %d", vc->name, a + 1,
                                 a + 2, same, def);
                }
                assert_true(isfinite(c.gvw_limit_kg) && c.gvw_limit_kg >= 18000.0);
                for (int k = 0; k < c.n_groups; k++)
                    assert_true(isfinite(c.group[k].limit_kg));
            }
    }
}

/* Two axles: a car or van up to light_max_kg, a truck above; 96/53/EC's
 * gross-weight limits by class; the container option. */
static void eu_limits(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    amfi_classification c;
    const double sp2[1] = {2.7}, car[2] = {900, 800}, truck[2] = {7000, 11000};
    assert_int_equal(amfi_classify(&p, 2, sp2, car, &c, NULL, 0), 0);
    assert_string_equal(c.name, "CAR");
    assert_true(isnan(c.gvw_limit_kg) && c.over == 0);
    const double sp2t[1] = {4.8};
    assert_int_equal(amfi_classify(&p, 2, sp2t, truck, &c, NULL, 0), 0);
    assert_string_equal(c.name, "R2");
    assert_true(c.gvw_limit_kg == 18000.0);
    assert_int_equal(c.group[1].kind, AMFI_GROUP_DRIVING);
    assert_true(c.group[1].limit_kg == 11500.0);
    assert_int_equal(c.over, 0);
    const double heavy[2] = {7000, 11600}; /* GVW 18.6 t, driving axle 11.6 t */
    assert_int_equal(amfi_classify(&p, 2, sp2t, heavy, &c, NULL, 0), 0);
    assert_int_equal(c.over, AMFI_OVER_GVW | AMFI_OVER_GROUP);
    /* A33 at 43 t: over 40 t, not over 44 t with the container option */
    const double sp6[5] = {3.3, 1.35, 5.3, 1.31, 1.31};
    const double kg6[6] = {7500, 9000, 9000, 5833, 5833, 5834};
    assert_int_equal(amfi_classify(&p, 6, sp6, kg6, &c, NULL, 0), 0);
    assert_string_equal(c.name, "A33");
    assert_int_equal(c.over, AMFI_OVER_GVW);
    assert_int_equal(c.group[1].kind, AMFI_GROUP_MOTOR_TANDEM);
    assert_true(c.group[1].limit_kg == 19000.0); /* 1.35 m, air suspension */
    assert_int_equal(c.group[2].kind, AMFI_GROUP_TRIDEM);
    assert_true(c.group[2].limit_kg == 24000.0); /* 1.31 m: 1.3 < d <= 1.4 */
    p.container_44t = 1;
    assert_int_equal(amfi_classify(&p, 6, sp6, kg6, &c, NULL, 0), 0);
    assert_true(c.gvw_limit_kg == 44000.0 && c.over == 0);
    p.motor_tandem_air = 0;
    assert_int_equal(amfi_classify(&p, 6, sp6, kg6, &c, NULL, 0), 0);
    assert_true(c.group[1].limit_kg == 18000.0);
    /* a trailer's tandem by spacing (A22): 1.0 / 1.3 / 1.8 m edges */
    p = eu();
    const double kg4[4] = {6000, 10000, 8000, 8000};
    const struct {
        double d, limit;
    } tandem[] = {{0.99, 11000}, {1.0, 16000}, {1.29, 16000}, {1.3, 18000}, {1.79, 18000},
                  {1.8, 20000}, {2.0, 20000}};
    for (size_t k = 0; k < sizeof tandem / sizeof tandem[0]; k++) {
        const double sp4[3] = {3.7, 6.6, tandem[k].d};
        assert_int_equal(amfi_classify(&p, 4, sp4, kg4, &c, NULL, 0), 0);
        assert_string_equal(c.name, "A22");
        assert_int_equal(c.group[2].kind, AMFI_GROUP_TANDEM);
        if (c.group[2].limit_kg != tandem[k].limit)
            fail_msg("tandem %.2f m: limit %g, want %g", tandem[k].d, c.group[2].limit_kg,
                     tandem[k].limit);
    }
    /* a tridem of 1.3 m: 21 t, over it at 22 t (A23) */
    const double sp5[4] = {3.75, 6.0, 1.3, 1.3}, kg5[5] = {6000, 10000, 7400, 7300, 7300};
    assert_int_equal(amfi_classify(&p, 5, sp5, kg5, &c, NULL, 0), 0);
    assert_string_equal(c.name, "A23");
    assert_true(c.group[2].limit_kg == 21000.0);
    assert_int_equal(c.over, AMFI_OVER_GROUP);
    /* an R4 with its twin steer within the threshold: one steer pair, 20 t */
    const double sp4r[3] = {1.9, 3.4, 1.35}, kg4r[4] = {7000, 7000, 8000, 8000};
    assert_int_equal(amfi_classify(&p, 4, sp4r, kg4r, &c, NULL, 0), 0);
    assert_string_equal(c.name, "R4");
    assert_int_equal(c.n_groups, 2);
    assert_int_equal(c.group[0].kind, AMFI_GROUP_STEER_PAIR);
    assert_true(c.group[0].limit_kg == 20000.0);
    /* what the scheme does not know: a three-axle car and trailer, a 7-axle */
    const double sp3[2] = {2.7, 3.5}, sp7[6] = {3, 1.3, 5, 1.3, 1.3, 1.3};
    assert_int_equal(amfi_classify(&p, 3, sp3, NULL, &c, NULL, 0), 0);
    assert_false(c.known);
    assert_string_equal(c.name, "unknown");
    assert_int_equal(c.n_groups, 3);
    assert_int_equal(amfi_classify(&p, 7, sp7, NULL, &c, NULL, 0), 0);
    assert_false(c.known);
}

/* The FHWA 13 classes of typical vehicles (US spacings, feet). */
static void fhwa_typical(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    p.scheme = AMFI_CLASS_SCHEME_FHWA13;
    p.group_spacing_m = 2.44; /* 96 in, the US tandem */
    const double ft = 0.3048;
    const struct {
        const char *what, *want;
        int n;
        double sp_ft[8];
    } v[] = {
        {"motorcycle", "FHWA1", 2, {4.8}},
        {"passenger car", "FHWA2", 2, {9.0}},
        {"pickup", "FHWA3", 2, {11.5}},
        {"two-axle bus", "FHWA4", 2, {24.0}},
        {"two-axle six-tyre single unit", "FHWA5", 2, {15.0}},
        {"three-axle bus", "FHWA4", 3, {25.0, 4.0}},
        {"three-axle single unit (dump truck)", "FHWA6", 3, {15.0, 4.3}},
        {"four-axle single unit (concrete mixer)", "FHWA7", 4, {12.0, 4.3, 4.3}},
        {"three-axle tractor semi-trailer", "FHWA8", 3, {11.0, 25.0}},
        {"four-axle tractor semi-trailer", "FHWA8", 4, {12.0, 4.3, 30.0}},
        {"five-axle tractor semi-trailer (3-S2)", "FHWA9", 5, {14.0, 4.3, 33.0, 4.2}},
        {"six-axle tractor semi-trailer (3-S3)", "FHWA10", 6, {14.0, 4.3, 33.0, 4.2, 4.2}},
        {"five-axle double (2-S1-2)", "FHWA11", 5, {12.0, 22.0, 9.0, 21.0}},
        {"six-axle double (3-S1-2)", "FHWA12", 6, {12.0, 4.3, 21.0, 9.0, 21.0}},
        {"seven-axle triple", "FHWA13", 7, {12.0, 21.0, 9.0, 21.0, 9.0, 21.0}},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        double sp[8];
        for (int i = 0; i + 1 < v[k].n; i++)
            sp[i] = v[k].sp_ft[i] * ft;
        amfi_classification c;
        assert_int_equal(amfi_classify(&p, v[k].n, sp, NULL, &c, NULL, 0), 0);
        if (strcmp(c.name, v[k].want) != 0)
            fail_msg("%s: %s, want %s", v[k].what, c.name, v[k].want);
        assert_true(isnan(c.gvw_limit_kg)); /* no US limits here */
    }
}

/* Bad parameters name their field; bad arguments their axle or spacing. */
static void refusals(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    const char *blamed = NULL;
    char why[256];
    assert_int_equal(amfi_class_params_check(&p, &blamed, why, sizeof why), 0);
    p.group_spacing_m = 0.9;
    assert_int_equal(amfi_class_params_check(&p, &blamed, why, sizeof why), -1);
    assert_string_equal(blamed, "group_spacing_m");
    p = eu();
    p.gvw_limit_kg[AMFI_EU_A32] = 900;
    assert_int_equal(amfi_class_params_check(&p, &blamed, why, sizeof why), -1);
    assert_string_equal(blamed, "A32");
    p = eu();
    p.scheme = (amfi_class_scheme)7;
    assert_int_equal(amfi_class_params_check(&p, &blamed, why, sizeof why), -1);
    assert_string_equal(blamed, "scheme");
    p = eu();
    amfi_classification c;
    char err[128];
    const double sp[2] = {3.0, NAN}, kg[3] = {1000, INFINITY, 1000};
    assert_int_equal(amfi_classify(&p, 3, sp, NULL, &c, err, sizeof err), -1);
    assert_non_null(strstr(err, "spacing 2"));
    const double sp2[2] = {3.0, 1.3};
    assert_int_equal(amfi_classify(&p, 3, sp2, kg, &c, err, sizeof err), -1);
    assert_non_null(strstr(err, "axle 2"));
    assert_int_equal(amfi_classify(&p, 0, sp2, NULL, &c, err, sizeof err), -1);
    assert_int_equal(amfi_classify(&p, AMFI_MAX_AXLES + 1, sp2, NULL, &c, err, sizeof err), -1);
}

/* Negative loads as a solve gives them: an axle inside a group is not
 * separable, so a negative one in a tridem whose sum is positive is
 * accepted (the class, the group's sum against its limit, the axle flagged
 * not separable and reported as it is); a negative single axle, or a group
 * below zero, refuses the loads with the axle or group named, the class
 * and groups still given, no overload decided. */
static void negative_loads(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    amfi_classification c;
    char err[128] = "";
    const double a23[4] = {3.75, 6.0, 1.31, 1.31};
    /* A23 with a tridem of 25 t split 14 / −3.4 / 14.4: the tridem's 25 t is
     * above its 24 t limit, the gross 42 t above 40 t */
    const double in_group[5] = {7000, 10000, 14000, -3426, 14426};
    assert_int_equal(amfi_classify(&p, 5, a23, in_group, &c, err, sizeof err), 0);
    assert_string_equal(c.name, "A23");
    assert_int_equal(c.loads_ok, 1);
    assert_string_equal(c.loads_why, "");
    assert_int_equal(c.n_groups, 3);
    assert_int_equal(c.group[2].kind, AMFI_GROUP_TRIDEM);
    assert_float_equal(c.group[2].load_kg, 25000.0, 1e-6);
    assert_int_equal(c.separable[3], 0);
    assert_true(c.over & AMFI_OVER_GROUP);
    assert_true(c.over & AMFI_OVER_GVW);
    /* within its limits: no overload although one axle is below zero */
    const double light[5] = {6000, 9000, 9000, -2000, 9000};
    assert_int_equal(amfi_classify(&p, 5, a23, light, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 1);
    assert_int_equal(c.over, 0);
    /* a single axle below zero (the driving axle, axle 2): refused, named */
    const double single[5] = {7000, -1200, 8000, 8000, 8000};
    assert_int_equal(amfi_classify(&p, 5, a23, single, &c, err, sizeof err), 0);
    assert_string_equal(c.name, "A23");
    assert_int_equal(c.n_groups, 3);
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "axle 2"));
    assert_non_null(strstr(c.loads_why, "single axle"));
    assert_int_equal(c.over, 0);
    assert_float_equal(c.group[1].load_kg, -1200.0, 1e-9); /* reported as it is */
    /* a group below zero: refused, named */
    const double group[5] = {7000, 9000, 3000, -6000, 1000};
    assert_int_equal(amfi_classify(&p, 5, a23, group, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "group 3 (axles 3-5)"));
    assert_int_equal(c.over, 0);
    /* two axles, one below zero: not a CAR by its (negative) gross weight */
    const double sp2[1] = {2.7}, car[2] = {2500, -900};
    assert_int_equal(amfi_classify(&p, 2, sp2, car, &c, err, sizeof err), 0);
    assert_string_equal(c.name, "R2");
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "axle 2"));
}

/* A load an order of magnitude above any legal configuration (a broken
 * solve, a wrong detector record) is refused, not an overload: the trailer
 * tandem of an A22 at 250 t (the largest legal tandem 20 t), a single axle
 * at 130 t (11.5 t); the class and groups still given, no overload. A heavy
 * but possible overload (a 40 t tandem) is still an overload. */
static void implausible_loads(void **state)
{
    (void)state;
    amfi_class_params p = eu();
    amfi_classification c;
    char err[128] = "";
    const double a22[3] = {3.7, 6.6, 1.31};
    const double tandem[4] = {7000, 11000, 125000, 125000};
    assert_int_equal(amfi_classify(&p, 4, a22, tandem, &c, err, sizeof err), 0);
    assert_string_equal(c.name, "A22");
    assert_int_equal(c.n_groups, 3);
    assert_int_equal(c.loads_ok, 0);
    assert_int_equal(c.over, 0);
    assert_non_null(strstr(c.loads_why, "group 3: load 250000 kg"));
    assert_non_null(strstr(c.loads_why, "(20000 kg)"));
    assert_float_equal(c.group[2].load_kg, 250000.0, 1e-6); /* reported as it is */
    const double single[4] = {130000, 11000, 9000, 9000};
    assert_int_equal(amfi_classify(&p, 4, a22, single, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "single axle 1: load 130000 kg"));
    assert_int_equal(c.over, 0);
    const double heavy[4] = {7000, 11000, 20000, 20000};
    assert_int_equal(amfi_classify(&p, 4, a22, heavy, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 1);
    assert_true(c.over & AMFI_OVER_GROUP);
    /* a tridem: over 10 x 24 t refused, just under it an overload */
    const double a23[4] = {3.75, 6.0, 1.31, 1.31};
    const double tridem[5] = {7000, 11000, 81000, 81000, 81000};
    assert_int_equal(amfi_classify(&p, 5, a23, tridem, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "group 3: load 243000 kg, over 10 x any legal load "
                                        "of 3 axles (24000 kg)"));
    const double tridem_less[5] = {7000, 11000, 79000, 79000, 79000};
    assert_int_equal(amfi_classify(&p, 5, a23, tridem_less, &c, err, sizeof err), 0);
    assert_int_equal(c.loads_ok, 1);
    assert_true(c.over & AMFI_OVER_GROUP);
    /* an unknown class (a road train of seven single axles) is judged too */
    const double sp7[6] = {3.0, 4.0, 4.0, 4.0, 4.0, 4.0};
    const double train[7] = {7000, 9000, 9000, 9000, 9000, 200000, 9000};
    assert_int_equal(amfi_classify(&p, 7, sp7, train, &c, err, sizeof err), 0);
    assert_string_equal(c.name, "unknown");
    assert_int_equal(c.loads_ok, 0);
    assert_non_null(strstr(c.loads_why, "single axle 6"));
}

/* The reason amfid stores (passages.loads_refused, 1 .. 111 bytes of text
 * without control characters) and publishes (passage_t.loads_refused, at
 * most 111 bytes): the longest refusals of the loads the store holds
 * (|load| <= 1e6 kg, 12 axles, limits raised to the checks' largest) fit
 * whole, printable. */
static void refusal_fits_the_store(void **state)
{
    (void)state;
    assert_int_equal(sizeof(((amfi_classification *)0)->loads_why) - 1, 111);
    amfi_class_params p = eu();
    p.single_axle_kg = p.driving_axle_kg = 99999.0; /* the widest legal figure */
    amfi_classification c;
    char err[128] = "";
    /* 12 axles: singles, one group of 12, 10 singles and a tandem, 9 singles
     * and a tridem; the last axle (or every axle) at the store's extremes */
    static const struct {
        int last_group;  /* axles in the last group (the others single), 12: one group */
        double last_kg, other_kg;
        const char *want; /* the reason's start */
    } cases[] = {
        {1, -999999.0, 1000.0, "axle 12: load -999999 kg < 0"},
        {1, 999999.0, 1000.0, "single axle 12: load 999999 kg, over 10 x"},
        {12, -83333.0, -83333.0, "group 1 (axles 1-12): load -999996 kg < 0"},
        {2, -999999.0, 1000.0, "group 11 (axles 11-12): load -998999 kg < 0"},
        {3, 997999.0, 1000.0, "group 10: load 999999 kg, over 10 x any legal load of 3 axles"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double sp[11], kg[12];
        for (int a = 0; a < 11; a++)
            sp[a] = a >= 11 - (cases[k].last_group - 1) ? 1.3 : 3.0;
        for (int a = 0; a < 12; a++)
            kg[a] = cases[k].other_kg;
        kg[11] = cases[k].last_kg;
        assert_int_equal(amfi_classify(&p, 12, sp, kg, &c, err, sizeof err), 0);
        assert_int_equal(c.loads_ok, 0);
        size_t n = strlen(c.loads_why);
        assert_true(strncmp(c.loads_why, cases[k].want, strlen(cases[k].want)) == 0);
        assert_true(n >= 1 && n < sizeof c.loads_why - 1); /* whole, not cut */
        for (size_t i = 0; i < n; i++)
            assert_true(c.loads_why[i] >= 0x20 && c.loads_why[i] < 0x7f);
    }
}

/* The text form amfid records in the store (meta daemon.classes): every
 * field round-trips exactly; a damaged text is refused naming the field,
 * *p untouched. */
static void params_text(void **state)
{
    (void)state;
    amfi_class_params a, b;
    char buf[1024], why[256];
    amfi_class_params_default(&a);
    a.scheme = AMFI_CLASS_SCHEME_FHWA13;
    a.group_spacing_m = 1.0 + 1.0 / 3.0;
    a.gvw_limit_kg[AMFI_EU_A33] = 44000;
    a.container_44t = 1;
    assert_int_equal(amfi_class_params_format(&a, buf, sizeof buf), 0);
    assert_non_null(strstr(buf, "scheme=fhwa13 group_spacing_m="));
    assert_non_null(strstr(buf, " gvw_limit_kg.A33=44000 "));
    amfi_class_params_default(&b);
    assert_int_equal(amfi_class_params_parse(buf, &b, why, sizeof why), 0);
    assert_memory_equal(&a.gvw_limit_kg, &b.gvw_limit_kg, sizeof a.gvw_limit_kg);
    assert_true(a.scheme == b.scheme && a.group_spacing_m == b.group_spacing_m &&
                a.light_max_kg == b.light_max_kg && a.container_44t == b.container_44t &&
                a.single_axle_kg == b.single_axle_kg && a.driving_axle_kg == b.driving_axle_kg &&
                a.motor_tandem_air == b.motor_tandem_air);
    assert_int_equal(amfi_class_params_format(&a, buf, 30), -1);
    static const struct {
        const char *text, *why;
    } bad[] = {
        {"scheme=eu", "group_spacing_m missing"},
        {"scheme=eu scheme=eu", "scheme given twice"},
        {"scheme=mars", "scheme: 'mars' is not eu or fhwa13"},
        {"gvw_limit_kg.B9=1", "unknown field"},
        {"container_44t=2", "container_44t: '2' is not 0 or 1"},
        {"light_max_kg=heavy", "light_max_kg: 'heavy' is not a number"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        amfi_class_params_default(&b);
        assert_int_equal(amfi_class_params_parse(bad[k].text, &b, why, sizeof why), -1);
        if (!strstr(why, bad[k].why))
            fail_msg("'%s': '%s', expected '%s'", bad[k].text, why, bad[k].why);
        assert_true(b.scheme == AMFI_CLASS_SCHEME_EU && b.group_spacing_m == 2.0);
    }
    /* every key there but a value amfi_class_params_check refuses */
    amfi_class_params_default(&a);
    assert_int_equal(amfi_class_params_format(&a, buf, sizeof buf), 0);
    char *gs = strstr(buf, "group_spacing_m=2");
    assert_non_null(gs);
    gs[strlen("group_spacing_m=")] = '9';
    assert_int_equal(amfi_class_params_parse(buf, &b, why, sizeof why), -1);
    assert_non_null(strstr(why, "group_spacing"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(groups_at_threshold),  cmocka_unit_test(every_eu_class_from_vclass),
        cmocka_unit_test(eu_limits),            cmocka_unit_test(fhwa_typical),
        cmocka_unit_test(refusals),             cmocka_unit_test(params_text),
        cmocka_unit_test(negative_loads),       cmocka_unit_test(implausible_loads),
        cmocka_unit_test(refusal_fits_the_store),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
