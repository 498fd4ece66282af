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
} amfi_config_key;

/* Call visit for every key, depth first in the order of the loader's
 * tables (valid only during the call). Stops at and returns the first
 * non-zero return of visit; 0 when every key was visited. */
int amfi_config_keys(int (*visit)(const amfi_config_key *k, void *arg), void *arg);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_CONFIG_KEYS_H */
