/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-accuracy: the COST 323 accuracy class of measured weights against
 * reference weights (accuracy/cost323.h).
 *
 *   amfi-accuracy --input FILE.csv [--condition r1|r2|RR1|RR2]
 *                 [--environment I|II|III] [--initial-verification]
 *
 * FILE.csv has the header criterion,measured_kg,reference_kg and one row a
 * measured value: criterion gross, group, single or group_axle. One JSON
 * line per criterion present, then one with the overall class (the worst of
 * the criteria). Exit 0 when an overall class is stated, 1 on bad input or
 * when no criterion can be classed, 2 on a bad command line.
 */
#include "amfi_cli.h"
#include "amfi_csv.h"
#include "amfi_json.h"
#include "cost323.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PROG "amfi-accuracy"
/* reference weights below this are not a vehicle, an axle or a group */
#define MIN_REFERENCE_KG 50.0
#define MAX_WEIGHT_KG 1e6

static void usage(FILE *f)
{
    fprintf(f,
            "usage: " PROG " --input FILE.csv [--condition r1|r2|RR1|RR2]\n"
            "                     [--environment I|II|III] [--initial-verification]\n"
            "The COST 323 accuracy class of weigh-in-motion results against reference\n"
            "weights. FILE.csv (plain or .gz): header criterion,measured_kg,reference_kg,\n"
            "one row a weighed value; criterion gross, group, single or group_axle.\n"
            "  --condition C        test conditions: r1 full repeatability, r2 extended\n"
            "                       repeatability, RR1 limited reproducibility, RR2 full\n"
            "                       reproducibility (default RR2)\n"
            "  --environment E      I environmental repeatability, II limited, III full\n"
            "                       environmental reproducibility (default I)\n"
            "  --initial-verification  the tolerances of an initial verification (0.8 delta)\n"
            "Prints one JSON line per criterion present (criterion, n, mean_pct, std_pct,\n"
            "pi_pct, pi0_pct, class, delta_pct, delta_min_pct) and one with the overall\n"
            "class. Exit 0 with a class, 1 on bad input or no class, 2 on a bad command line.\n");
}

typedef struct {
    double *v;
    int n, cap;
} series;

static int push(series *s, double x)
{
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        double *v = realloc(s->v, (size_t)cap * sizeof *v);
        if (!v)
            return -1;
        s->v = v;
        s->cap = cap;
    }
    s->v[s->n++] = x;
    return 0;
}

/* Reads the file into the criteria's relative errors (%). 0, or −1 with the
 * message in err. */
static int read_input(const char *path, series err[AMFI_COST323_N_CRITERIA], char *msg,
                      size_t msglen)
{
    amfi_csv *r = amfi_csv_open(path, 256, msg, msglen);
    if (!r)
        return -1;
    const char *line, *f[4];
    size_t len, fl[4];
    int got = amfi_csv_next(r, &line, &len);
    if (got <= 0) {
        if (got == 0)
            amfi_csv_fail(r, 0, NULL, "empty file: expected the header "
                                      "criterion,measured_kg,reference_kg");
        amfi_csv_close(r, 0);
        return -1;
    }
    amfi_csv_strip_bom(&line, &len);
    static const char *const header[3] = {"criterion", "measured_kg", "reference_kg"};
    int nf = amfi_csv_split(line, len, f, fl, 4);
    int ok = nf == 3;
    for (int i = 0; ok && i < 3; i++)
        ok = fl[i] == strlen(header[i]) && memcmp(f[i], header[i], fl[i]) == 0;
    if (!ok) {
        amfi_csv_fail(r, 1, NULL, "the header must be criterion,measured_kg,reference_kg");
        amfi_csv_close(r, 0);
        return -1;
    }
    int rows = 0;
    for (;;) {
        got = amfi_csv_next_row(r, &line, &len, "empty line before the end of the data");
        if (got < 0) {
            amfi_csv_close(r, 0);
            return -1;
        }
        if (got == 0)
            break;
        long ln = amfi_csv_lineno(r);
        nf = amfi_csv_split(line, len, f, fl, 4);
        if (nf != 3) {
            amfi_csv_fail(r, ln, NULL, "%d fields, expected 3 (criterion,measured_kg,reference_kg)",
                          nf);
            amfi_csv_close(r, 0);
            return -1;
        }
        char name[24], q[32];
        amfi_cost323_criterion c;
        if (fl[0] >= sizeof name || (memcpy(name, f[0], fl[0]), name[fl[0]] = 0,
                                     amfi_cost323_criterion_parse(name, &c) != 0)) {
            amfi_csv_fail(r, ln, "criterion", "'%s' is not gross, group, single or group_axle",
                          amfi_csv_quote(f[0], fl[0], q));
            amfi_csv_close(r, 0);
            return -1;
        }
        double w[2];
        for (int k = 0; k < 2; k++) {
            int e = amfi_csv_field_double(f[k + 1], fl[k + 1], &w[k]);
            const char *col = header[k + 1];
            if (e) {
                amfi_csv_fail(r, ln, col, "'%s' is not a number",
                              amfi_csv_quote(f[k + 1], fl[k + 1], q));
                amfi_csv_close(r, 0);
                return -1;
            }
            /* a measured value may be below zero: a solver reports the axles
             * of a group it cannot separate as it split them (docs/classes.md),
             * and that error counts like any other */
            double lo = k == 0 ? -MAX_WEIGHT_KG : MIN_REFERENCE_KG;
            if (!(w[k] >= lo && w[k] <= MAX_WEIGHT_KG)) {
                amfi_csv_fail(r, ln, col, "%g kg is outside [%g, %g]", w[k], lo, MAX_WEIGHT_KG);
                amfi_csv_close(r, 0);
                return -1;
            }
        }
        if (push(&err[c], 100.0 * (w[0] - w[1]) / w[1]) != 0) {
            amfi_csv_fail(r, ln, NULL, "out of memory");
            amfi_csv_close(r, 0);
            return -1;
        }
        rows++;
    }
    if (amfi_csv_close(r, 1) != 0)
        return -1;
    if (rows == 0) {
        snprintf(msg, msglen, "%s: no data rows after the header", path);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static const struct option opts[] = {{"input", required_argument, NULL, 'i'},
                                         {"condition", required_argument, NULL, 'c'},
                                         {"environment", required_argument, NULL, 'e'},
                                         {"initial-verification", no_argument, NULL, 256},
                                         AMFI_CLI_END};
    amfi_cli cli;
    amfi_cli_init(&cli, PROG, argc, argv, opts, usage);
    const char *input = NULL;
    amfi_cost323_condition cond = AMFI_COST323_RR2;
    amfi_cost323_environment env = AMFI_COST323_ENV_I;
    int initial = 0;
    for (int k; (k = amfi_cli_next(&cli)) != -1;) {
        switch (k) {
        case 'i': input = optarg; break;
        case 'c':
            if (amfi_cost323_condition_parse(optarg, &cond) != 0)
                amfi_cli_fail(&cli, "'%s' is not r1, r2, RR1 or RR2", optarg);
            break;
        case 'e':
            if (amfi_cost323_environment_parse(optarg, &env) != 0)
                amfi_cli_fail(&cli, "'%s' is not I, II or III", optarg);
            break;
        case 256: initial = 1; break;
        default: break;
        }
    }
    if (!input) {
        amfi_cli_error(PROG, "--input", "required (FILE.csv)");
        return AMFI_CLI_EXIT_USAGE;
    }
    series err[AMFI_COST323_N_CRITERIA] = {{0}};
    char msg[512] = "";
    if (read_input(input, err, msg, sizeof msg) != 0) {
        fprintf(stderr, PROG ": %s\n", msg);
        for (int c = 0; c < AMFI_COST323_N_CRITERIA; c++)
            free(err[c].v);
        return 1;
    }
    int worst = -1, classed = 0, failed = 0;
    const char *worst_criterion = NULL;
    for (int c = 0; c < AMFI_COST323_N_CRITERIA; c++) {
        if (err[c].n == 0)
            continue;
        amfi_cost323_result res;
        char why[200];
        json_t *o = json_object();
        json_object_set_new(o, "criterion", json_string(amfi_cost323_criterion_name(c)));
        json_object_set_new(o, "n", json_integer(err[c].n));
        json_object_set_new(o, "condition", json_string(amfi_cost323_condition_name(cond)));
        json_object_set_new(o, "environment", json_string(amfi_cost323_environment_name(env)));
        if (amfi_cost323_evaluate(c, err[c].v, err[c].n, cond, env, initial, &res, why,
                                  sizeof why) != 0) {
            json_object_set_new(o, "class", json_null());
            json_object_set_new(o, "reason", json_string(why));
            fprintf(stderr, PROG ": %s: no class: %s\n", amfi_cost323_criterion_name(c), why);
            failed++;
        } else {
            json_object_set_new(o, "mean_pct", amfi_json_num(res.mean_pct));
            json_object_set_new(o, "std_pct", amfi_json_num(res.std_pct));
            json_object_set_new(o, "pi_pct", amfi_json_num(res.pi_pct));
            json_object_set_new(o, "pi0_pct", amfi_json_num(res.pi0_pct));
            json_object_set_new(o, "class", res.class_value ? json_string(res.class_name)
                                                            : json_null());
            json_object_set_new(o, "delta_pct", amfi_json_num(res.delta_pct));
            json_object_set_new(o, "delta_min_pct", amfi_json_num(res.delta_min_pct));
            if (!res.class_value) {
                json_object_set_new(o, "reason", json_string("worse than E(100)"));
                failed++;
            } else {
                classed++;
                if (res.class_value > worst) {
                    worst = res.class_value;
                    worst_criterion = amfi_cost323_criterion_name(c);
                }
            }
        }
        if (amfi_json_print(stdout, o) != 0) {
            for (int k = 0; k < AMFI_COST323_N_CRITERIA; k++)
                free(err[k].v);
            return 1;
        }
    }
    json_t *o = json_object();
    json_object_set_new(o, "criterion", json_string("overall"));
    json_object_set_new(o, "condition", json_string(amfi_cost323_condition_name(cond)));
    json_object_set_new(o, "environment", json_string(amfi_cost323_environment_name(env)));
    json_object_set_new(o, "initial_verification", json_boolean(initial));
    char name[16];
    if (classed && !failed) {
        amfi_cost323_class_name(worst, name, sizeof name);
        json_object_set_new(o, "class", json_string(name));
        json_object_set_new(o, "set_by", json_string(worst_criterion));
    } else {
        json_object_set_new(o, "class", json_null());
        json_object_set_new(o, "reason",
                            json_string(classed ? "a criterion present has no class"
                                                : "no criterion could be classed"));
    }
    int rc = amfi_json_print(stdout, o) != 0 || fflush(stdout) != 0 ? 1 : 0;
    for (int c = 0; c < AMFI_COST323_N_CRITERIA; c++)
        free(err[c].v);
    return rc ? 1 : (classed && !failed) ? 0 : 1;
}
