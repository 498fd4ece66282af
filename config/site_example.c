/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * site_example.c: what of a site file is still the shipped example's
 * (amfi_config_example_warnings, amfid --check-config): config/amfid.yaml
 * is installed as /etc/amfid/amfid.yaml with the example site id 'local'
 * and the paper's 20 m bridge, and it loads without error, so an
 * unconfigured site would otherwise start weighing with another bridge's
 * model and claim a fleet id every untouched site shares. The file is
 * walked again for the lines of the keys blamed (the loader's record of
 * where each key path was seen). Runs on the caller's thread; no global
 * state.
 */
#include "amfi_config.h"
#include "sections.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The example's site id (config/amfid.yaml, the built-in default). */
#define EXAMPLE_SITE_ID "local"
#define EXAMPLE_BRIDGE_NAME "paper-20m"

static int same(double a, double b) { return fabs(a - b) <= 1e-9 * fabs(b); }

/* FILE:LINE: (or FILE: when the key is not in the file) */
static void say(void (*warn)(const char *, void *), void *arg, const char *file, int line,
                const char *key, const char *what)
{
    char buf[1024], at[32] = "";
    if (line > 0)
        snprintf(at, sizeof at, ":%d", line);
    snprintf(buf, sizeof buf, "%s%s: %s: WARNING: %s", file, at, key, what);
    warn(buf, arg);
}

int amfi_config_example_warnings(const char *path, void (*warn)(const char *line, void *arg),
                                 void *arg)
{
    static const char *const keys[] = {"bridge.span_m", "bridge.E_pa", "bridge.A_m2",
                                       "bridge.I_m4", "bridge.density_kgm3"};
    amfi_site_config *c = malloc(sizeof *c), *tmp = malloc(sizeof *tmp);
    ctx *x = calloc(1, sizeof *x);
    char err[512], what[600];
    int n = -1;

    if (!c || !tmp || !x) {
        say(warn, arg, path, 0, "(file)", "out of memory");
        goto out;
    }
    if (amfi_config_load(path, c, err, sizeof err)) {
        snprintf(what, sizeof what, "cannot be read again: %s", err);
        say(warn, arg, path, 0, "(file)", what);
        goto out;
    }
    x->file = path;
    x->err = err;
    x->errlen = sizeof err;
    amfi_config_defaults(tmp);
    if (amfi_cfg_walk_file(x, amfi_cfg_top_fields, tmp, NULL)) {
        snprintf(what, sizeof what, "cannot be read again: %s", err);
        say(warn, arg, path, 0, "(file)", what);
        goto out;
    }
    n = 0;
    if (!strcmp(c->site.id, EXAMPLE_SITE_ID)) {
        say(warn, arg, path, amfi_cfg_noted(x, "site.id"), "site.id",
            "'" EXAMPLE_SITE_ID "' is the shipped example's site id: give this bridge its own, "
            "unique in the fleet (amfid writes it into the store at the first start and the "
            "central database keys every row by it; change it before that)");
        n++;
    }
    amfi_bridge_params paper;
    amfi_bridge_params_paper20(&paper);
    const amfi_bridge_params *b = &c->bridge;
    int paper_model = same(b->span_m, paper.span_m) && same(b->E_pa, paper.E_pa) &&
                      same(b->A_m2, paper.A_m2) && same(b->I_m4, paper.I_m4) &&
                      same(b->density_kgm3, paper.density_kgm3) && b->n_segments == 0;
    if (paper_model || !strcmp(c->name, EXAMPLE_BRIDGE_NAME)) {
        int line = amfi_cfg_noted(x, "bridge.name");
        for (size_t i = 0; !line && i < sizeof keys / sizeof keys[0]; i++)
            line = amfi_cfg_noted(x, keys[i]);
        snprintf(what, sizeof what, "%s: describe this site's bridge (bridge.*: its span, "
                 "stiffness, section and density as built, and its name; amfid.yaml(5)), or "
                 "every vehicle is weighed with another bridge's model",
                 paper_model ? "the bridge is the paper's 20 m example (span 20 m, E 3.5e10 Pa, "
                               "A 2.046 m², I 0.2991 m⁴, density 2400 kg/m³)"
                             : "bridge.name is the shipped example's 'paper-20m'");
        say(warn, arg, path, line, paper_model ? "bridge" : "bridge.name", what);
        n++;
    }
    if (!amfi_cfg_noted(x, "site.name") && !strcmp(c->site.name, EXAMPLE_BRIDGE_NAME)) {
        say(warn, arg, path, amfi_cfg_noted(x, "site"), "site.name",
            "not given, so reports, plots, notices and the fleet call this site 'paper-20m': "
            "name it");
        n++;
    }
out:
    free(c);
    free(tmp);
    free(x);
    return n;
}
