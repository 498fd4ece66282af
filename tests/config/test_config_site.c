/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_config_site.c: the short site file (config/site.yaml) states only
 * the site's facts and leaves every other key to the loader's defaults;
 * loaded, it must equal the annotated reference config/amfid.yaml in every
 * key. So the reference's values are the loader's defaults: a default
 * changed in the loader without amfid.yaml (or a value in amfid.yaml
 * without the loader) fails here, naming each key that differs.
 *
 *   test_config_site SITE.yaml REFERENCE.yaml
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "amfi_config.h"
#include "amfi_config_keys.h"

static const char *site_path, *ref_path;

typedef struct differ {
    int n;
    char keys[1024];
} differ;

static int note(const amfi_config_key *k, void *arg)
{
    differ *d = arg;
    size_t used = strlen(d->keys);

    d->n++;
    snprintf(d->keys + used, sizeof d->keys - used, "%s%s", used ? ", " : "", k->path);
    return 0;
}

static void test_site_file_is_the_reference(void **state)
{
    static amfi_site_config site, ref;
    char err[512];
    differ d = {0};

    (void)state;
    if (amfi_config_load(site_path, &site, err, sizeof err))
        fail_msg("%s", err);
    if (amfi_config_load(ref_path, &ref, err, sizeof err))
        fail_msg("%s", err);
    amfi_config_diff(&site, &ref, note, &d);
    if (d.n)
        fail_msg("%d key(s) of %s differ from %s (a loader default and the reference "
                 "disagree): %s", d.n, site_path, ref_path, d.keys);
    assert_memory_equal(&site, &ref, sizeof site);
}

int main(int argc, char **argv)
{
    static const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_site_file_is_the_reference),
    };

    if (argc != 3) {
        fprintf(stderr, "usage: %s SITE.yaml REFERENCE.yaml\n", argv[0]);
        return 2;
    }
    site_path = argv[1];
    ref_path = argv[2];
    return cmocka_run_group_tests_name("config_site", tests, NULL, NULL);
}
