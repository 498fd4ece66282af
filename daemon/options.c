/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * options.c: amfid's command line, on common/'s getopt_long helpers
 * (amfi_cli.h: long and short options, `--opt=value` and `--opt value`,
 * `--` ends the options, --help and --version; a bad command line is one
 * line on stderr and exit 2). Runs once on the main thread before anything
 * else; owns nothing (the strings point into argv).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_cli.h"
#include "amfid.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: amfid [-c FILE] [-d PATH] [-u URL] [-k FILE] [-C [--strict]] [-h] [-V]\n"
            "       amfid --make-bus-key FILE\n"
            "\n"
            "The bridge monitoring daemon: weighs every vehicle from the bridge's\n"
            "accelerations (LCM bus), stores the passages in SQLite, watches the spread\n"
            "of the weights and raises alerts (docs/daemon.md).\n"
            "\n"
            "  -c, --config FILE   configuration (default " AMFID_DEFAULT_CONFIG ")\n"
            "  -d, --db PATH       the store, over daemon.store.path of the file\n"
            "  -u, --lcm-url URL   the LCM bus, over daemon.lcm_url of the file\n"
            "                      (file://LOG?speed=0 replays a log)\n"
            "  -k, --bus-key FILE  the site's bus key, over daemon.bus.key_file and the\n"
            "                      systemd credential amfi-bus-key\n"
            "      --make-bus-key FILE\n"
            "                      create a new site bus key (32 random bytes, mode\n"
            "                      0600; never overwrites) and exit\n"
            "  -C, --check-config  check the configuration (bridge, solver, indicators)\n"
            "                      and exit; a WARNING line for what is still the\n"
            "                      shipped example's (site.id local, the paper's bridge)\n"
            "      --strict        with --check-config: exit 2 on a warning too\n"
            "  -h, --help          this help\n"
            "  -V, --version       the version\n"
            "\n"
            "Signals: SIGTERM/SIGINT drain and stop, SIGHUP reloads the configuration.\n"
            "Exit status: 0 after a signal or --check-config; 1 a runtime failure (store,\n"
            "bus); 2 bad command line or configuration (or a warning, --strict).\n");
}

void amfid_parse_options(int argc, char **argv, amfid_options *o)
{
    static const struct option longopts[] = {
        {"config", required_argument, NULL, 'c'},
        {"db", required_argument, NULL, 'd'},
        {"lcm-url", required_argument, NULL, 'u'},
        {"check-config", no_argument, NULL, 'C'},
        {"strict", no_argument, NULL, 'S'},
        {"bus-key", required_argument, NULL, 'k'},
        {"make-bus-key", required_argument, NULL, 'K'},
        AMFI_CLI_END,
    };
    memset(o, 0, sizeof *o);
    o->config = AMFID_DEFAULT_CONFIG;
    amfi_cli c;
    amfi_cli_init(&c, "amfid", argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'c':
        case 'd':
        case 'u':
        case 'k':
        case 'K':
            if (!*optarg)
                amfi_cli_fail(&c, "empty value");
            if (k == 'k')
                o->bus_key = optarg;
            else if (k == 'K')
                o->make_bus_key = optarg;
            else if (k == 'c')
                o->config = optarg;
            else if (k == 'd')
                o->db = optarg;
            else
                o->lcm_url = optarg;
            break;
        case 'C':
            o->check_only = 1;
            break;
        case 'S':
            o->strict = 1;
            break;
        default: /* not in the table: cannot happen */
            amfi_cli_fail(&c, "unhandled option");
        }
    }
    if (o->strict && !o->check_only) {
        amfi_cli_error("amfid", "--strict", "only with --check-config");
        exit(AMFI_CLI_EXIT_USAGE);
    }
}
