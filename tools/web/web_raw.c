/* SPDX-License-Identifier: GPL-3.0-or-later */
/* web_raw.c: a passage's raw samples for /api/passages/ID (web.h). The store
 * of this version keeps no raw samples: "raw" is null and "raw_reason" says
 * so. When the store keeps them (a raw-sample read in store.h), this is the
 * one function to fill: {"rate_hz": R, "t0_utime": T, "sensors": [{"name":
 * N, "samples": [...]}, ...]}, which the vehicle page draws as it is
 * (tools/web/static/app.js, drawSignal). */
#include "web.h"

json_t *web_raw(amfi_store *s, int64_t id, const char **why)
{
    (void)s;
    (void)id;
    *why = "this store keeps no raw samples (store schema version "
#define STR2(x) #x
#define STR(x) STR2(x)
           STR(AMFI_STORE_SCHEMA_VERSION) " has no raw-sample table)";
    return NULL;
}
