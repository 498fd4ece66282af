/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_config_live.c: amfi_config_diff and amfi_config_apply_live
 * (config/amfi_config_keys.h) against the loader's own key tables.
 *
 * Generic over the tables (config/sections.h: amfi_cfg_top_fields, each
 * row's kind saying where its value lives): every key of amfi_config_keys()
 * changed alone in a copy is named by amfi_config_diff, and nothing else is
 * (a list once for any of its items); no two keys share a byte; SIGHUP's
 * copy takes every live key and leaves every other byte. Then through
 * files, for the keys whose values a custom parser writes: a file changing
 * one key differs from the base in that key only. And the live set is the
 * one amfid's reload applies (λ policy, output channels, heartbeat, waits,
 * the intake's bounds).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amfi_config.h"
#include "amfi_config_keys.h"
#include "sections.h"

#define MAX_KEYS 512
#define ERRLEN 512

/* ---- the keys, as amfi_config_keys() gives them ---------------------------- */

typedef struct key_list {
    int n;
    char path[MAX_KEYS][PATH_LEN];
    int live[MAX_KEYS];
} key_list;

static int collect(const amfi_config_key *k, void *arg)
{
    key_list *l = arg;

    assert_true(l->n < MAX_KEYS);
    snprintf(l->path[l->n], PATH_LEN, "%s", k->path);
    l->live[l->n] = k->live;
    l->n++;
    return 0;
}

static int find(const key_list *l, const char *path)
{
    for (int i = 0; i < l->n; i++)
        if (strcmp(l->path[i], path) == 0)
            return i;
    return -1;
}

/* "bridge.supports[].at_m" -> "bridge.supports": the key diff names. */
static void list_key(const char *path, char *out)
{
    const char *br = strstr(path, "[]");

    snprintf(out, PATH_LEN, "%.*s", br ? (int)(br - path) : (int)strlen(path), path);
}

/* ---- the rows of the tables (internal: config/yaml_walk.h) ------------------ */

typedef struct row_find {
    const char *path;
    const field *f;
} row_find;

static int find_row_one(const char *path, const field *f, const void *item_default, int live,
                        void *arg)
{
    row_find *r = arg;

    (void)item_default;
    (void)live;
    if (strcmp(path, r->path) == 0) {
        r->f = f;
        return 1;
    }
    return 0;
}

static const field *find_row(const char *path)
{
    row_find r = {path, NULL};

    amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, find_row_one, &r);
    return r.f;
}

/* Change every byte of row f's value in c (^ 0x5a: each byte differs). */
static void mutate(const field *f, amfi_site_config *c)
{
    span sp[MAX_SPANS];
    const int n = f->kind->spans(f, sp);

    assert_in_range(n, 1, MAX_SPANS);
    for (int i = 0; i < n; i++) {
        assert_true(sp[i].len > 0 && sp[i].off + sp[i].len <= sizeof *c);
        for (size_t b = 0; b < sp[i].len; b++)
            ((unsigned char *)c)[sp[i].off + b] ^= 0x5a;
    }
}

static int mutate_one(const char *path, const field *f, const void *item_default, int live,
                      void *arg)
{
    (void)path;
    (void)item_default;
    (void)live;
    mutate(f, arg);
    return 0;
}

/* ---- what diff names -------------------------------------------------------- */

static int collect_diff(const amfi_config_key *k, void *arg)
{
    key_list *l = arg;

    /* a list once, never its items */
    assert_null(strstr(k->path, "[]"));
    assert_int_equal(-1, find(l, k->path));
    return collect(k, arg);
}

static void diff(const amfi_site_config *a, const amfi_site_config *b, key_list *out)
{
    out->n = 0;
    assert_int_equal(0, amfi_config_diff(a, b, collect_diff, out));
}

/* ---- tests ------------------------------------------------------------------- */

static void test_equal_configs_differ_nowhere(void **state)
{
    static amfi_site_config a, b;
    static key_list d;

    (void)state;
    amfi_config_defaults(&a);
    amfi_config_defaults(&b);
    diff(&a, &b, &d);
    assert_int_equal(0, d.n);
}

/* Every key of the key table, changed alone, is named by diff, and only it. */
static void test_diff_reaches_every_key(void **state)
{
    static amfi_site_config a, b;
    static key_list keys, d;
    char want[PATH_LEN];
    int checked = 0;

    (void)state;
    keys.n = 0;
    assert_int_equal(0, amfi_config_keys(collect, &keys));
    assert_true(keys.n > 100);
    amfi_config_defaults(&a);
    for (int i = 0; i < keys.n; i++) {
        const field *f;

        list_key(keys.path[i], want);
        f = find_row(want);
        if (!f)
            fail_msg("%s: no row of the key tables (list key %s)", keys.path[i], want);
        b = a;
        mutate(f, &b);
        diff(&a, &b, &d);
        if (d.n != 1 || strcmp(d.path[0], want) != 0)
            fail_msg("%s changed: diff named %d keys (first %s), not just %s", keys.path[i],
                     d.n, d.n ? d.path[0] : "none", want);
        /* the key's live flag, as the key table says (an item: its list's) */
        assert_int_equal(keys.live[find(&keys, want)], d.live[0]);
        assert_int_equal(keys.live[i], d.live[0]);
        checked++;
    }
    assert_int_equal(keys.n, checked);
}

/* No byte of the config belongs to two keys (else changing one would show
 * as the other, and SIGHUP would copy a restart-only key with a live one). */
typedef struct owner_map {
    short owner[sizeof(amfi_site_config)];
    int row;
    char names[MAX_KEYS][PATH_LEN];
} owner_map;

static int own_one(const char *path, const field *f, const void *item_default, int live,
                   void *arg)
{
    owner_map *m = arg;
    span sp[MAX_SPANS];
    const int n = f->kind->spans(f, sp);

    (void)item_default;
    (void)live;
    assert_true(m->row < MAX_KEYS);
    snprintf(m->names[m->row], PATH_LEN, "%s", path);
    m->row++;
    for (int i = 0; i < n; i++)
        for (size_t b = sp[i].off; b < sp[i].off + sp[i].len; b++) {
            if (m->owner[b])
                fail_msg("byte %zu belongs to %s and %s", b, m->names[m->owner[b] - 1], path);
            m->owner[b] = (short)m->row;
        }
    return 0;
}

static void test_keys_share_no_byte(void **state)
{
    static owner_map m;

    (void)state;
    memset(&m, 0, sizeof m);
    assert_int_equal(0, amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, own_one, &m));
    assert_true(m.row > 100);
}

/* SIGHUP's copy: every live key from the new file, every other byte kept. */
static void test_apply_live_copies_exactly_the_live_keys(void **state)
{
    static amfi_site_config a, b, run;
    static key_list keys, d;
    static owner_map m;
    char want[PATH_LEN];
    int n_live = 0, n_restart = 0;

    (void)state;
    keys.n = 0;
    assert_int_equal(0, amfi_config_keys(collect, &keys));
    amfi_config_defaults(&a);
    b = a;
    assert_int_equal(0, amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, mutate_one, &b));
    run = a;
    amfi_config_apply_live(&run, &b);

    /* run now differs from the new config in the restart-only keys ... */
    diff(&run, &b, &d);
    for (int i = 0; i < d.n; i++)
        if (d.live[i])
            fail_msg("%s is live but apply_live did not copy it", d.path[i]);
    /* ... and from the running one in the live keys, each of them */
    diff(&a, &run, &d);
    for (int i = 0; i < d.n; i++)
        if (!d.live[i])
            fail_msg("%s needs a restart but apply_live copied it", d.path[i]);
    for (int i = 0; i < keys.n; i++) {
        if (strstr(keys.path[i], "[]"))
            continue;
        list_key(keys.path[i], want);
        if (keys.live[i]) {
            n_live++;
            if (find(&d, want) < 0)
                fail_msg("%s is live but apply_live did not copy it", want);
        } else {
            n_restart++;
        }
    }
    assert_int_equal(n_live, d.n);
    assert_true(n_live > 0 && n_restart > 0);

    /* every byte outside the live keys' values is the running config's */
    memset(&m, 0, sizeof m);
    assert_int_equal(0, amfi_cfg_walk_rows(amfi_cfg_top_fields, "", 0, own_one, &m));
    for (size_t i = 0; i < sizeof run; i++) {
        const int o = m.owner[i];
        const int live = o && keys.live[find(&keys, m.names[o - 1])];
        if (!live && ((unsigned char *)&run)[i] != ((unsigned char *)&a)[i])
            fail_msg("byte %zu (%s) changed by apply_live", i, o ? m.names[o - 1] : "no key");
    }

    /* NULL and self are no-ops */
    amfi_config_apply_live(NULL, &b);
    amfi_config_apply_live(&run, NULL);
    amfi_config_apply_live(&run, &run);
    assert_int_equal(0, amfi_config_diff(NULL, &b, collect_diff, &d));
}

/* The keys amfid's reload applies at once (daemon/control.c reload()):
 * the λ policy, the output channels, the heartbeat, the waits, the
 * intake's bounds and the detector's corrections. A flag flipped by
 * mistake in a table shows here. */
static int expected_live(const char *p)
{
    static const char *const exact[] = {
        "solver.lambda", "solver.lambda_ref_rate_hz", "daemon.channels.passage",
        "daemon.channels.indicator", "daemon.channels.alert", "daemon.channels.status",
        "daemon.status_period_s", "daemon.max_wait_s", "daemon.environment_max_skew_s", NULL};

    for (int i = 0; exact[i]; i++)
        if (strcmp(p, exact[i]) == 0)
            return 1;
    return strncmp(p, "solver.lcurve.", 14) == 0 || strncmp(p, "daemon.intake.", 14) == 0 ||
           strncmp(p, "detector.", 9) == 0;
}

static void test_the_live_set(void **state)
{
    static key_list keys;
    int n = 0;

    (void)state;
    keys.n = 0;
    assert_int_equal(0, amfi_config_keys(collect, &keys));
    for (int i = 0; i < keys.n; i++) {
        if (keys.live[i] != expected_live(keys.path[i]))
            fail_msg("%s: live %d, amfid's reload applies it %s", keys.path[i], keys.live[i],
                     expected_live(keys.path[i]) ? "at once" : "at the next start");
        n += keys.live[i];
    }
    assert_int_equal(9 + 4 + 14 + 2, n);
}

/* ---- through files: the keys a custom parser writes -------------------------- */

static int load_text(const char *text, amfi_site_config *c)
{
    char path[64], err[ERRLEN];
    int fd, rc;

    snprintf(path, sizeof path, "/tmp/amfi_test_config_live_XXXXXX");
    fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal((ssize_t)strlen(text), write(fd, text, strlen(text)));
    assert_int_equal(0, close(fd));
    rc = amfi_config_load(path, c, err, sizeof err);
    unlink(path);
    if (rc)
        fail_msg("%s", err);
    return rc;
}

static void test_diff_of_files(void **state)
{
    static const struct {
        const char *text; /* a site file changing one key from the defaults */
        const char *key;  /* the keys diff names, in table order, ", " between */
        int live;
    } cases[] = {
        /* site.name follows bridge.name unless given */
        {"bridge:\n  name: other\n", "site.name, bridge.name", 0},
        {"site:\n  name: other\n", "site.name", 0},
        /* the default roller and sensor follow the span */
        {"bridge:\n  span_m: 21\n", "bridge.span_m, bridge.supports, sensors", 0},
        {"bridge:\n  damping:\n    modes: [1, 3]\n", "bridge.damping.modes", 0},
        {"bridge:\n  supports:\n    - {at_m: 0, type: fixed}\n    - {at_m: 20, type: roller}\n",
         "bridge.supports", 0},
        {"bridge:\n  segments:\n    - {from_m: 0, to_m: 5, EI_nm2: 1e10}\n",
         "bridge.segments", 0},
        {"sensors:\n  - {id: 0, at_m: 9}\n", "sensors", 0},
        {"solver:\n  modes: 5\n", "solver.modes", 0},
        {"solver:\n  lambda: auto\n", "solver.lambda", 1},
        {"solver:\n  lambda: 1e-8\n", "solver.lambda", 1},
        {"solver:\n  lcurve:\n    per_decade: 3\n", "solver.lcurve.per_decade", 1},
        {"site:\n  id: b-1\n", "site.id", 0},
        {"site:\n  latitude: 47.5\n  longitude: 8.5\n", "site.latitude, site.longitude", 0},
        {"simulation:\n  preceding_gap: [1, 2]\n", "simulation.preceding_gap", 0},
        {"simulation:\n  damage_step_at: 3\n", "simulation.damage_step_at", 0},
        {"simulation:\n  stream:\n    speedup: max\n", "simulation.stream.speedup", 0},
        {"daemon:\n  channels:\n    passage: P2\n", "daemon.channels.passage", 1},
        {"daemon:\n  channels:\n    accel: A2\n", "daemon.channels.accel", 0},
        {"daemon:\n  max_wait_s: 7\n", "daemon.max_wait_s", 1},
        {"daemon:\n  intake:\n    calibration_sources: a,b\n",
         "daemon.intake.calibration_sources", 1},
        {"daemon:\n  workers: 3\n", "daemon.workers", 0},
    };
    static amfi_site_config base, c;
    static key_list d;
    char got[1024];

    (void)state;
    amfi_config_defaults(&base);
    assert_int_equal(0, load_text("bridge:\n  span_m: 20\n", &c));
    diff(&base, &c, &d);
    assert_int_equal(0, d.n); /* the default written out is no change */
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        assert_int_equal(0, load_text(cases[i].text, &c));
        diff(&base, &c, &d);
        got[0] = '\0';
        for (int k = 0; k < d.n; k++)
            snprintf(got + strlen(got), sizeof got - strlen(got), "%s%s", k ? ", " : "",
                     d.path[k]);
        if (strcmp(got, cases[i].key) != 0)
            fail_msg("%s: diff named '%s', not '%s'", cases[i].text, got, cases[i].key);
        assert_int_equal(cases[i].live, d.live[0]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_equal_configs_differ_nowhere),
        cmocka_unit_test(test_diff_reaches_every_key),
        cmocka_unit_test(test_keys_share_no_byte),
        cmocka_unit_test(test_apply_live_copies_exactly_the_live_keys),
        cmocka_unit_test(test_the_live_set),
        cmocka_unit_test(test_diff_of_files),
    };

    return cmocka_run_group_tests(tests, NULL, NULL);
}
