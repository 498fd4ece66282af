/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_cli.c: getopt_long-based command-line parsing for every amfi
 * program (see amfi_cli.h). Runs on the main thread before anything else.
 */
#include "amfi_cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_version.h"

void amfi_cli_init(amfi_cli *c, const char *prog, int argc, char **argv,
                   const struct option *longopts, void (*usage)(FILE *))
{
    memset(c, 0, sizeof *c);
    c->prog = prog;
    c->argc = argc;
    c->argv = argv;
    c->longopts = longopts;
    c->usage = usage;
    /* ':' first: a missing value is ':', not '?'; then every short form */
    size_t k = 0;
    c->shortopts[k++] = ':';
    for (const struct option *o = longopts; o->name; o++) {
        if (o->flag || o->val <= 0 || o->val > 127 || k + 3 >= sizeof c->shortopts)
            continue;
        c->shortopts[k++] = (char)o->val;
        if (o->has_arg == required_argument)
            c->shortopts[k++] = ':';
        else if (o->has_arg == optional_argument) {
            c->shortopts[k++] = ':';
            c->shortopts[k++] = ':';
        }
    }
    c->shortopts[k] = '\0';
    opterr = 0;
    optind = 0; /* glibc: 0 also resets its internal state */
}

void amfi_cli_allow_operands(amfi_cli *c)
{
    c->operands = 1;
}

void amfi_cli_error(const char *prog, const char *opt, const char *fmt, ...)
{
    va_list ap;
    if (opt)
        fprintf(stderr, "%s: %s: ", prog, opt);
    else
        fprintf(stderr, "%s: ", prog);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

void amfi_cli_fail(const amfi_cli *c, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: %s: ", c->prog, c->opt ? c->opt : "?");
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    exit(AMFI_CLI_EXIT_USAGE);
}

/* "--name" of the long option with this val, else "-v" */
static const char *name_of(amfi_cli *c, int val, int longindex)
{
    const struct option *o = NULL;
    if (longindex >= 0)
        o = &c->longopts[longindex];
    else
        for (const struct option *p = c->longopts; p->name; p++)
            if (!p->flag && p->val == val) {
                o = p;
                break;
            }
    if (o)
        snprintf(c->optbuf, sizeof c->optbuf, "--%s", o->name);
    else
        snprintf(c->optbuf, sizeof c->optbuf, "-%c", val > 32 && val < 127 ? val : '?');
    return c->optbuf;
}

/* The option as typed (argv[optind − 1] up to any '='), for messages about
 * options that do not exist. */
static const char *as_typed(amfi_cli *c)
{
    const char *a = optind >= 1 && optind <= c->argc ? c->argv[optind - 1] : "?";
    if (strncmp(a, "--", 2) != 0) {
        snprintf(c->optbuf, sizeof c->optbuf, "-%c",
                 optopt > 32 && optopt < 127 ? optopt : '?');
        return c->optbuf;
    }
    size_t n = strcspn(a, "=");
    snprintf(c->optbuf, sizeof c->optbuf, "%.*s", (int)(n < 40 ? n : 40), a);
    for (char *p = c->optbuf; *p; p++)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            *p = '?';
    return c->optbuf;
}

int amfi_cli_next(amfi_cli *c)
{
    int longindex = -1;
    int k = getopt_long(c->argc, c->argv, c->shortopts, c->longopts, &longindex);
    if (k == -1) {
        c->opt = NULL;
        if (optind < c->argc && !c->operands) {
            amfi_cli_error(c->prog, amfi_cli_shown(c->argv[optind]),
                           "unexpected argument (see --help)");
            exit(AMFI_CLI_EXIT_USAGE);
        }
        return -1;
    }
    if (k == '?') {
        amfi_cli_error(c->prog, as_typed(c), "unknown option (see --help)");
        exit(AMFI_CLI_EXIT_USAGE);
    }
    if (k == ':') {
        amfi_cli_error(c->prog, name_of(c, optopt, -1), "needs a value");
        exit(AMFI_CLI_EXIT_USAGE);
    }
    c->opt = name_of(c, k, longindex);
    if (k == 'h' && !strcmp(c->opt, "--help")) {
        c->usage(stdout);
        exit(fflush(stdout) == 0 ? 0 : 1);
    }
    if (k == 'V' && !strcmp(c->opt, "--version")) {
        printf("%s %s\n", c->prog, amfi_version());
        exit(fflush(stdout) == 0 ? 0 : 1);
    }
    return k;
}

int amfi_cli_double(const char *s, double *v)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(s, &end);
    if (end == s || *end != '\0' || !isfinite(x))
        return -1;
    *v = x;
    return 0;
}

double amfi_cli_num(const amfi_cli *c, const char *s, double lo, double hi)
{
    double v;
    if (amfi_cli_double(s, &v) != 0 || v < lo || v > hi)
        amfi_cli_fail(c, "'%s' is not a number in [%g, %g]", amfi_cli_shown(s), lo, hi);
    return v;
}

long amfi_cli_integer(const amfi_cli *c, const char *s, double lo, double hi)
{
    double v = amfi_cli_num(c, s, lo, hi);
    if (v != floor(v))
        amfi_cli_fail(c, "'%s' is not an integer", amfi_cli_shown(s));
    return (long)v;
}

int amfi_cli_list(const amfi_cli *c, const char *s, double *out, int max, double lo,
                  double hi)
{
    char buf[512];
    if (strlen(s) >= sizeof buf)
        amfi_cli_fail(c, "list too long");
    strcpy(buf, s);
    int n = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        if (n == max)
            amfi_cli_fail(c, "at most %d values", max);
        out[n++] = amfi_cli_num(c, tok, lo, hi);
    }
    if (n == 0)
        amfi_cli_fail(c, "no value");
    return n;
}

const char *amfi_cli_shown(const char *s)
{
    static char buf[2][48];
    static int which;
    char *out = buf[which];
    which ^= 1;
    size_t k = 0;
    for (; s[k] && k < 40; k++)
        out[k] = ((unsigned char)s[k] < 0x20 || s[k] == 0x7f) ? '?' : s[k];
    if (s[k]) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = '\0';
    return out;
}
