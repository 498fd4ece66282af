/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_config_man.c: the manual amfid.yaml(5) against the loader. For every
 * key the loader reads (amfi_config_keys(): its own tables and defaults)
 * the page must hold the entry line
 *
 *   *PATH* (TYPE; RANGE; default DEFAULT)     or, for a required item key,
 *   *PATH* (TYPE; RANGE; required)
 *
 * exactly, every entry line of the page must name a key the loader reads,
 * and the page must state the solver's step and workspace bounds, so
 * neither can change without the other. With --print, write the
 * entry lines the page needs (to write or mend the page).
 *
 * Usage: test_config_man PAGE.scd | test_config_man --print
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_config_keys.h"
#include "sections.h" /* the workspace bounds */

#define MAX_LINES 4000
#define LINE_LEN 512

typedef struct page {
    char *line[MAX_LINES];
    int n;
    int failures;
    int keys; /* keys the loader reads */
} page;

/* "*path* (type; range; default D; applies ...)": when a change applies,
 * from the key's live flag (amfi_config_apply_live is what SIGHUP copies). */
static void entry(const amfi_config_key *k, char *buf, size_t len)
{
    const char *when = k->live ? "applies at once on SIGHUP" : "applies at the next start";

    if (k->required)
        snprintf(buf, len, "*%s* (%s; %s; required; %s)", k->path, k->type, k->range, when);
    else
        snprintf(buf, len, "*%s* (%s; %s; default %s; %s)", k->path, k->type, k->range,
                 k->dflt, when);
}

static int print_key(const amfi_config_key *k, void *arg)
{
    char buf[LINE_LEN];

    (void)arg;
    entry(k, buf, sizeof buf);
    printf("%s\n", buf);
    return 0;
}

/* An entry line: "*" a path (no blanks) "* (" ... "; default ...)" or
 * "; required; ...)". */
static int is_entry(const char *l)
{
    size_t n = strlen(l), p;

    if (l[0] != '*')
        return 0;
    p = strcspn(l + 1, "* \t") + 1;
    return p > 1 && strncmp(l + p, "* (", 3) == 0 && n && l[n - 1] == ')' &&
           (strstr(l, "; default ") || strstr(l, "; required"));
}

/* The page states the bounds the loader applies (sections.h). */
static void check_limits(page *pg)
{
    char steps[64], bytes[64];
    int have_steps = 0, have_bytes = 0;

    snprintf(steps, sizeof steps, "exceed %.0f steps", AMFI_CONFIG_MAX_STEPS);
    snprintf(bytes, sizeof bytes, "exceeds %.0f GiB",
             AMFI_CONFIG_MAX_WORKSPACE_BYTES / (1024.0 * 1024.0 * 1024.0));
    for (int i = 0; i < pg->n; i++) {
        have_steps |= strstr(pg->line[i], steps) != NULL;
        have_bytes |= strstr(pg->line[i], bytes) != NULL;
    }
    if (!have_steps || !have_bytes) {
        fprintf(stderr, "the page must state the limits: '%s', '%s'\n", steps, bytes);
        pg->failures++;
    }
}

static int check_key(const amfi_config_key *k, void *arg)
{
    page *pg = arg;
    char want[LINE_LEN], head[LINE_LEN];
    int found = 0;

    pg->keys++;
    entry(k, want, sizeof want);
    snprintf(head, sizeof head, "*%s* (", k->path);
    for (int i = 0; i < pg->n; i++) {
        if (strncmp(pg->line[i], head, strlen(head)) != 0)
            continue;
        found++;
        if (strcmp(pg->line[i], want) != 0) {
            fprintf(stderr, "line %d: %s\n  the loader has: %s\n", i + 1, pg->line[i], want);
            pg->failures++;
        }
        pg->line[i][0] = '\0'; /* seen */
    }
    if (found != 1) {
        fprintf(stderr, "%s: %d entries in the page, want 1: %s\n", k->path, found, want);
        pg->failures++;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static page pg;
    char buf[LINE_LEN];
    FILE *f;

    if (argc == 2 && strcmp(argv[1], "--print") == 0)
        return amfi_config_keys(print_key, NULL);
    if (argc != 2) {
        fprintf(stderr, "usage: test_config_man PAGE.scd | --print\n");
        return 2;
    }
    f = fopen(argv[1], "r");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    while (fgets(buf, sizeof buf, f)) {
        buf[strcspn(buf, "\n")] = '\0';
        if (pg.n == MAX_LINES) {
            fprintf(stderr, "%s: more than %d lines\n", argv[1], MAX_LINES);
            return 2;
        }
        pg.line[pg.n] = strdup(buf);
        if (!pg.line[pg.n++])
            return 2;
    }
    fclose(f);
    amfi_config_keys(check_key, &pg);
    check_limits(&pg);
    for (int i = 0; i < pg.n; i++)
        if (is_entry(pg.line[i])) {
            fprintf(stderr, "line %d: %s\n  is not a key the loader reads\n", i + 1,
                    pg.line[i]);
            pg.failures++;
        }
    for (int i = 0; i < pg.n; i++)
        free(pg.line[i]);
    printf("%s: %d keys checked, %d problem(s)\n", argv[1], pg.keys, pg.failures);
    if (pg.failures)
        fprintf(stderr, "%s: %d problem(s); `test_config_man --print` lists the entries\n",
                argv[1], pg.failures);
    return pg.failures ? 1 : 0;
}
