/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_config_keys.h: every key a site file may hold, as the loader itself
 * reads it, for the manual amfid.yaml(5) and its test (tests/config/test_config_man.c
 * holds each key's type, range and default against man/amfid.yaml.5.scd, so
 * the page cannot drift from the loader).
 *
 * The strings come from the loader's own key tables and from
 * amfi_config_defaults(): ranges are written as the loader's messages write
 * them ("(0, 1e+06]", "> 0", "1 .. 64", "pinned, roller, fixed"). No state;
 * any thread.
 */
#ifndef AMFI_CONFIG_KEYS_H
#define AMFI_CONFIG_KEYS_H

#include "amfi_config.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct amfi_config_key {
    const char *path;  /* "solver.calc_rate_hz"; items of a list: "sensors[].at_m" */
    const char *type;  /* "number", "integer", "name", "string", "file path", "list", ... */
    const char *range; /* the values allowed */
    const char *dflt;  /* the default ("required" for a required list-item key) */
    int required;      /* 1: a required key (dflt "required"), 0: dflt is the default
                          (which may be the name "required", daemon.bus.auth) */
    int live;          /* 1: SIGHUP applies a change at once (amfid.yaml(5): "applies
                          at once on SIGHUP"); 0: at the next start. Items of a
                          list: their list's flag. */
} amfi_config_key;

/* Call visit for every key, depth first in the order of the loader's
 * tables (valid only during the call). Stops at and returns the first
 * non-zero return of visit; 0 when every key was visited. */
int amfi_config_keys(int (*visit)(const amfi_config_key *k, void *arg), void *arg);

/* Call visit for every key whose value differs between a and b, in the
 * order of amfi_config_keys() (k as there, valid only during the call). A
 * list (bridge.supports, bridge.segments, sensors) is one key: visited once
 * when any of its items differs, its item keys never. Derived from the key
 * tables (where each key's value lives), so a new key is compared without
 * being named here. Values compare by their bytes: two configurations loaded
 * from equal files compare equal. Stops at and returns the first non-zero
 * return of visit; 0 when every differing key was visited. No state; any
 * thread. */
int amfi_config_diff(const amfi_site_config *a, const amfi_site_config *b,
                     int (*visit)(const amfi_config_key *k, void *arg), void *arg);

/* Copy into run the value of every live key (live = 1) from n, and nothing
 * else: after it amfi_config_diff(run, n) visits only keys with live = 0.
 * This is what SIGHUP applies; the daemon logs the rest (restart-only) as
 * taking effect at the next start. No state; any thread. */
void amfi_config_apply_live(amfi_site_config *run, const amfi_site_config *n);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_CONFIG_KEYS_H */
