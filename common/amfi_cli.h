/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_cli.h: command-line parsing shared by every amfi program, on
 * getopt_long: long and short options, "--opt=value" and "--opt value",
 * "--" ends the options, --help and --version handled alike everywhere.
 *
 * A program lists its options once:
 *
 *     static const struct option opts[] = {
 *         {"speed", required_argument, NULL, 's'},
 *         {"lcurve", required_argument, NULL, 256},  (no short form: >= 256)
 *         AMFI_CLI_END};                              (--help/-h, --version/-V)
 *     amfi_cli c;
 *     amfi_cli_init(&c, "amfi-solve", argc, argv, opts, usage);
 *     for (int k; (k = amfi_cli_next(&c)) != -1;)
 *         switch (k) { case 's': speed = amfi_cli_num(&c, optarg, 0, 60); ... }
 *
 * Every message is one line on stderr, "PROG: --option: problem", naming
 * the option by its long name (also when the short one was typed); a bad
 * command line exits with status 2. Not thread-safe (getopt's globals).
 */
#ifndef AMFI_COMMON_CLI_H
#define AMFI_COMMON_CLI_H

#include <getopt.h>
#include <stdio.h>

#define AMFI_CLI_EXIT_USAGE 2

/* The end of every option table: --help (-h) prints the usage on stdout
 * and exits 0; --version (-V) prints "PROG VERSION" and exits 0; then the
 * terminating entry. */
#define AMFI_CLI_END                                                         \
    {"help", no_argument, NULL, 'h'}, {"version", no_argument, NULL, 'V'}, { NULL, 0, NULL, 0 }

typedef struct amfi_cli {
    const char *prog;
    int argc;
    char **argv;
    const struct option *longopts;
    void (*usage)(FILE *);
    char shortopts[192];
    const char *opt;  /* "--name" of the option amfi_cli_next returned last */
    char optbuf[64];
    int operands;     /* amfi_cli_allow_operands() was called */
} amfi_cli;

/* Prepares parsing of argv (resets getopt). usage(f) prints the help. */
void amfi_cli_init(amfi_cli *c, const char *prog, int argc, char **argv,
                   const struct option *longopts, void (*usage)(FILE *));

/* The next option's val (its value in optarg), or −1 after the last one.
 * Handles --help and --version (exit 0), an unknown option, a missing value
 * and a stray argument after the options (message, exit 2). */
int amfi_cli_next(amfi_cli *c);

/* Lets arguments that are not options through (argv[optind ..] after the
 * last option); without this call amfi_cli_next refuses them. */
void amfi_cli_allow_operands(amfi_cli *c);

/* "PROG: OPT: message" on stderr (OPT omitted when NULL). */
void amfi_cli_error(const char *prog, const char *opt, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* The same for the current option, then exit(2). */
void amfi_cli_fail(const amfi_cli *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3), noreturn));

/* s as one finite number in [lo, hi], else "PROG: --opt: 's' is not a
 * number in [lo, hi]" and exit(2). */
double amfi_cli_num(const amfi_cli *c, const char *s, double lo, double hi);

/* The same, and s must be a whole number ("... 's' is not an integer"). */
long amfi_cli_integer(const amfi_cli *c, const char *s, double lo, double hi);

/* A comma-separated list of numbers in [lo, hi], at most max of them and at
 * least one; returns the count (exit(2) with a message otherwise). */
int amfi_cli_list(const amfi_cli *c, const char *s, double *out, int max, double lo,
                  double hi);

/* 0 and *v when the whole string is one finite number, −1 otherwise. */
int amfi_cli_double(const char *s, double *v);

/* s for an error message: at most 40 characters, control characters as '?',
 * so that an error stays one line whatever was typed. Two rotating static
 * buffers: valid until the second call after this one; not thread-safe. */
const char *amfi_cli_shown(const char *s);

#endif
