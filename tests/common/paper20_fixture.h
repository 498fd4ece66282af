/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * paper20_fixture.h: the cmocka group fixture of the libamfi unit tests
 * (test_libamfi.c, test_speed.c): one paper-20m bridge model, built before
 * the group and shared read-only by its tests (single-threaded).
 */
#ifndef AMFI_PAPER20_FIXTURE_H
#define AMFI_PAPER20_FIXTURE_H

#include "amfi/amfi.h"

static amfi_bridge *bridge; /* paper-20m, shared by all tests */

static int setup(void **state)
{
    (void)state;
    amfi_bridge_params p;
    char err[256];
    amfi_bridge_params_paper20(&p);
    return amfi_bridge_create(&p, &bridge, err, sizeof err);
}

static int teardown(void **state)
{
    (void)state;
    amfi_bridge_destroy(bridge);
    return 0;
}

#endif
