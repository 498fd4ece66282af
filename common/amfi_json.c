/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_json.c: JSON output helpers on libjansson (see amfi_json.h).
 */
#include "amfi_json.h"

#include <math.h>

json_t *amfi_json_num(double x) { return isfinite(x) ? json_real(x) : json_null(); }

int amfi_json_print(FILE *f, json_t *obj)
{
    if (!obj)
        return -1;
    int rc = json_dumpf(obj, f, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(obj);
    if (rc != 0 || fputc('\n', f) == EOF)
        return -1;
    return 0;
}
