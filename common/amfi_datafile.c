/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_datafile.c: the data-file lookup (see amfi_datafile.h).
 */
#include "amfi_datafile.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef AMFI_SYSCONF_DATA_DIR
#define AMFI_SYSCONF_DATA_DIR "/usr/local/etc/amfi"
#endif
#ifndef AMFI_SHARE_DATA_DIR
#define AMFI_SHARE_DATA_DIR "/usr/local/share/amfi"
#endif

/* dir[0 .. n) + "/" + name into buf when it is a regular file: 0, else −1 */
static int try_dir(const char *dir, size_t n, const char *name, char *buf, size_t len)
{
    struct stat st;
    if (n == 0)
        return -1;
    int k = snprintf(buf, len, "%.*s/%s", (int)n, dir, name);
    if (k < 0 || (size_t)k >= len)
        return -1;
    return stat(buf, &st) == 0 && S_ISREG(st.st_mode) ? 0 : -1;
}

int amfi_datafile_find(const char *name, char *buf, size_t len)
{
    const char *env = getenv("AMFI_DATA_DIR");
    if (env) {
        for (const char *p = env;;) {
            const char *colon = strchr(p, ':');
            size_t n = colon ? (size_t)(colon - p) : strlen(p);
            if (try_dir(p, n, name, buf, len) == 0)
                return 0;
            if (!colon)
                break;
            p = colon + 1;
        }
    }
    static const char *const installed[] = {AMFI_SYSCONF_DATA_DIR, AMFI_SHARE_DATA_DIR};
    for (size_t k = 0; k < sizeof installed / sizeof installed[0]; k++)
        if (try_dir(installed[k], strlen(installed[k]), name, buf, len) == 0)
            return 0;
    if (len)
        buf[0] = '\0';
    return -1;
}

const char *amfi_datafile_places(char *buf, size_t len)
{
    const char *env = getenv("AMFI_DATA_DIR");
    if (env)
        snprintf(buf, len, "$AMFI_DATA_DIR (%s), %s, %s", env, AMFI_SYSCONF_DATA_DIR,
                 AMFI_SHARE_DATA_DIR);
    else
        snprintf(buf, len, "$AMFI_DATA_DIR (unset), %s, %s", AMFI_SYSCONF_DATA_DIR,
                 AMFI_SHARE_DATA_DIR);
    return buf;
}
