/*
 * options.c: amfid's command line (getopt_long: long and short options,
 * `--opt=value` and `--opt value`, `--` ends the options), --help and
 * --version. Runs once on the main thread before anything else; owns
 * nothing (the strings point into argv).
 */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "amfid.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: amfid [-c FILE] [-d PATH] [-u URL] [-C] [-h] [-V]\n"
            "\n"
            "The bridge monitoring daemon: weighs every vehicle from the bridge's\n"
            "accelerations (LCM bus), stores the passages in SQLite, watches the spread\n"
            "of the weights and raises alerts (docs/daemon.md).\n"
            "\n"
            "  -c, --config FILE   configuration (default " AMFID_DEFAULT_CONFIG ")\n"
            "  -d, --db PATH       the store, over daemon.db_path of the file\n"
            "  -u, --lcm-url URL   the LCM bus, over daemon.lcm_url of the file\n"
            "                      (file://LOG?speed=0 replays a log)\n"
            "  -C, --check-config  check the configuration (bridge, solver, indicators)\n"
            "                      and exit\n"
            "  -h, --help          this help\n"
            "  -V, --version       the version\n"
            "\n"
            "Signals: SIGTERM/SIGINT drain and stop, SIGHUP reloads the configuration.\n"
            "Exit status: 0 after a signal or --check-config; 1 a runtime failure (store,\n"
            "bus); 2 bad command line or configuration.\n");
}

int amfid_parse_options(int argc, char **argv, amfid_options *o)
{
    static const struct option longopts[] = {
        {"config", required_argument, NULL, 'c'},
        {"db", required_argument, NULL, 'd'},
        {"lcm-url", required_argument, NULL, 'u'},
        {"check-config", no_argument, NULL, 'C'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };
    memset(o, 0, sizeof *o);
    o->config = AMFID_DEFAULT_CONFIG;
    opterr = 0; /* our own messages, naming the option */
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":c:d:u:ChV", longopts, NULL)) != -1) {
        const char *shown = argv[optind - 1];
        switch (c) {
        case 'c':
        case 'd':
        case 'u':
            if (!*optarg) {
                fprintf(stderr, "amfid: %s: empty value\n", shown);
                return -1;
            }
            if (c == 'c')
                o->config = optarg;
            else if (c == 'd')
                o->db = optarg;
            else
                o->lcm_url = optarg;
            break;
        case 'C':
            o->check_only = 1;
            break;
        case 'h':
            usage(stdout);
            return 1;
        case 'V':
            printf("amfid %s\n", amfi_version());
            return 1;
        case ':':
            fprintf(stderr, "amfid: %s: needs a value (see --help)\n", shown);
            return -1;
        default:
            if (strncmp(shown, "--", 2) == 0)
                fprintf(stderr, "amfid: %s: unknown option, or a value to an option that "
                        "takes none (see --help)\n", shown);
            else
                fprintf(stderr, "amfid: -%c: unknown option (see --help)\n", optopt);
            return -1;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "amfid: %s: unexpected argument (see --help)\n", argv[optind]);
        return -1;
    }
    return 0;
}
