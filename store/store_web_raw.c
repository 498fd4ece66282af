/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_web_raw.c: what amfi-web needs besides amfi_store_raw_get to say
 * why a passage has no raw samples (store.h, "raw samples"): the oldest raw
 * window kept. The retention deletes windows oldest first (utime, id), so a
 * window whose utime is after the oldest one kept was never deleted by it.
 */
#include <inttypes.h>

#include "store_internal.h"

int amfi_store_raw_oldest(amfi_store *s, int64_t *utime, int *found, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!utime || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "raw samples: output is NULL");
    if (rc != 0)
        return rc;
    *utime = 0;
    *found = 0;
    sqlite3_stmt *st = NULL;
    /* a store before raw samples has no raw_windows: no window, no error */
    int has = 0;
    rc = st_has_table(s, "raw_windows", &has, err, errlen);
    if (rc != 0 || !has)
        return rc;
    rc = st_prepare(s, "SELECT utime, id FROM raw_windows ORDER BY utime, id LIMIT 1", &st,
                    "raw_windows: oldest", err, errlen);
    if (rc != 0)
        return rc;
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"raw_windows", sqlite3_column_int64(st, 1)};
        rc = st_read_int(st, 0, 0, AMFI_STORE_MAX_UTIME, &o, utime, err, errlen);
        *found = rc == 0;
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "raw_windows: oldest", err, errlen);
    }
    sqlite3_finalize(st);
    return rc;
}
