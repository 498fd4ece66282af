/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_fixture.h: the cmocka fixture the store tests share: a new store in
 * a private temporary directory (setup), closed and removed with the
 * directory (teardown; a test's extra files are its own to remove first, or
 * listed in STORE_FIXTURE_EXTRA). Single-threaded tests only.
 */
#ifndef AMFI_STORE_FIXTURE_H
#define AMFI_STORE_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "store.h"

typedef struct fixture {
    char dir[64];
    char path[96];
    amfi_store *s;
} fixture;

/* A new store at DIR/amfi.db, DIR = /tmp/PREFIX_XXXXXX. */
static inline int store_fixture_setup(void **state, const char *prefix)
{
    fixture *f = calloc(1, sizeof *f);
    char err[512];
    if (!f)
        return -1;
    snprintf(f->dir, sizeof f->dir, "/tmp/%s_XXXXXX", prefix);
    if (!mkdtemp(f->dir))
        return -1;
    snprintf(f->path, sizeof f->path, "%s/amfi.db", f->dir);
    if (amfi_store_open(f->path, 0, &f->s, err, sizeof err) != 0) {
        fprintf(stderr, "setup: %s\n", err);
        return -1;
    }
    *state = f;
    return 0;
}

/* Close and remove the store, the stores named in `extra` (file names in
 * the fixture's directory, NULL-terminated; may be NULL) and the directory. */
static inline int store_fixture_teardown(void **state, const char *const *extra)
{
    fixture *f = *state;
    char p[128];
    amfi_store_close(f->s);
    amfi_store_remove(f->path);
    for (int i = 0; extra && extra[i]; i++) {
        snprintf(p, sizeof p, "%s/%s", f->dir, extra[i]);
        amfi_store_remove(p);
        unlink(p);
    }
    rmdir(f->dir);
    free(f);
    return 0;
}

#endif
