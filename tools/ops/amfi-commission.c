/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-commission: commission a site's bridge model from calibration runs
 * and the bridge's own vibration (tools/commission/commission.h,
 * docs/commissioning.md).
 *
 *   amfi-commission --config DESIGN.yaml --runs RUNS.csv [--ambient FILE.csv ...]
 *                   --out SITE.yaml [--report DIR] [--hold NAME ...] [--segments N]
 *                   [--verbose]
 *
 * Writes SITE.yaml: DESIGN.yaml with the fitted bridge, sensors, λ and
 * detector sections and a comment block giving each value, its uncertainty,
 * what it was fitted from and the fit quality; checked by loading it back
 * before it replaces anything. One JSON line on stdout summarises.
 * Exit status: 0 commissioned; 1 bad input or runs that cannot identify the
 * model (one line on stderr saying why); 2 bad command line.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "accel_csv.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_json.h"
#include "amfi_version.h"
#include "commission.h"
#include "cost323.h"

#define PROG "amfi-commission"
#define MAX_AMBIENT 32

static const char *const hold_names[CM_P_SEG] = {"stiffness", "mass",  "bearings",
                                                    "sensor",    "clock", "speed"};

static void usage(FILE *f)
{
    fprintf(f,
            "usage: " PROG " --config DESIGN.yaml --runs RUNS.csv [--ambient FILE.csv ...]\n"
            "                       --out SITE.yaml [--report DIR] [--hold NAME ...] [--fit-lambda]\n"
            "                       [--speed-sd F] [--segments N] [--verbose]\n"
            "Commission a site's bridge model from calibration trucks of known axle loads and\n"
            "the bridge's free vibration (docs/commissioning.md).\n"
            "  --config FILE     the site file from the drawings (bridge, sensors, solver)\n"
            "  --runs FILE       RUNS.csv: file,speed_mps,axle_spacings_m,entry_time_s,axle_kg\n"
            "                    (lists ';'-separated, front to back; files relative to it)\n"
            "  --ambient FILE    a record of the bridge's free or ambient vibration (t,accel),\n"
            "                    repeatable, for the natural frequency and damping\n"
            "  --out FILE        the commissioned site file to write\n"
            "  --report DIR      also write report.md, runs.csv and accuracy.csv there\n"
            "  --hold NAME       keep a parameter at the design's value: stiffness, mass,\n"
            "                    bearings, sensor, clock or speed (repeatable)\n"
            "  --fit-lambda      choose lambda from the runs (leaving each out) instead of\n"
            "                    keeping the design's\n"
            "  --speed-sd F      the detector's speed has a random error of relative SD F per\n"
            "                    run (e.g. 0.03): each run's speed is estimated from its\n"
            "                    acceleration, the detector's mean error is its speed scale\n"
            "                    (default 0: the detector's speeds, one common scale)\n"
            "  --segments N      fit each of N equal segments' stiffness (E.I) instead of one\n"
            "                    scale for the beam, 2 .. %d; refused when the runs cannot\n"
            "                    tell them apart\n"
            "  --verbose         the search's progress on stderr\n"
            "Exit 0 commissioned, 1 bad input or runs that cannot identify the model, 2 bad\n"
            "command line.\n", CM_MAX_FIT_SEGMENTS);
}

/* ---- SITE.yaml ---------------------------------------------------------- */

typedef struct text {
    char *s;
    size_t n, cap;
} text;

static int put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int put(text *t, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(t->s ? t->s + t->n : NULL, t->s ? t->cap - t->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0)
            return -1;
        if (t->s && t->n + (size_t)k < t->cap) {
            t->n += (size_t)k;
            return 0;
        }
        size_t cap = (t->cap ? 2 * t->cap : 8192) + (size_t)k;
        char *s = realloc(t->s, cap);
        if (!s)
            return -1;
        t->s = s;
        t->cap = cap;
    }
}

static const char *support_type(const amfi_support *s)
{
    if (s->restrain_theta)
        return "fixed";
    return s->restrain_w ? "pinned" : "elastic";
}

static void put_bridge(text *t, const amfi_site_config *c, const amfi_site_config *design)
{
    const amfi_bridge_params *b = &c->bridge;
    put(t, "bridge:\n");
    put(t, "  name: \"%s\"\n", c->name);
    put(t, "  span_m: %.10g\n", b->span_m);
    put(t, "  elements: %d\n", b->n_elements);
    put(t, "  E_pa: %.10g\n", b->E_pa);
    put(t, "  A_m2: %.10g\n", b->A_m2);
    put(t, "  I_m4: %.10g\n", b->I_m4);
    put(t, "  density_kgm3: %.10g\n", b->density_kgm3);
    put(t, "  damping:\n    ratio: %.6g\n    modes: [%d, %d]\n", b->damping_ratio,
        b->rayleigh_mode_a, b->rayleigh_mode_b);
    put(t, "  supports:\n");
    for (int i = 0; i < b->n_supports; i++) {
        const amfi_support *s = &b->supports[i];
        /* a roller of the design stays a roller (the same restraints) */
        const char *type = support_type(s);
        if (!strcmp(type, "pinned") && design->bridge.n_supports == b->n_supports &&
            i == b->n_supports - 1 && i > 0)
            type = "roller";
        put(t, "    - {at_m: %.10g, type: %s", s->x_m, type);
        if (s->k_w_npm > 0)
            put(t, ", k_w_npm: %.10g", s->k_w_npm);
        if (s->k_theta_nmprad > 0)
            put(t, ", k_theta_nmprad: %.10g", s->k_theta_nmprad);
        put(t, "}\n");
    }
    if (b->n_segments > 0) {
        put(t, "  segments:\n");
        for (int i = 0; i < b->n_segments; i++) {
            const amfi_segment *g = &b->segments[i];
            put(t, "    - {from_m: %.10g, to_m: %.10g", g->x0_m, g->x1_m);
            if (g->EI_nm2 > 0)
                put(t, ", EI_nm2: %.10g", g->EI_nm2);
            if (g->mass_kgpm > 0)
                put(t, ", mass_kgpm: %.10g", g->mass_kgpm);
            put(t, "}\n");
        }
    }
    put(t, "  damage: 0\n");
}

static void put_sensors(text *t, const amfi_site_config *c)
{
    put(t, "sensors:\n");
    for (int s = 0; s < c->solver.n_sensors; s++)
        put(t, "  - {id: %d, at_m: %.10g, weight: %.10g}\n", c->sensor_id[s],
            c->solver.sensor_x_m[s], c->solver.sensor_weight[s]);
}

/* the design file's other top-level sections, verbatim, with solver.lambda
 * replaced; bridge, sensors and detector are written anew */
static int copy_design(text *t, const char *design_path, double lambda_ref, char *err,
                       size_t errlen)
{
    FILE *f = fopen(design_path, "r");
    if (!f) {
        snprintf(err, errlen, "%s: cannot read: %s", design_path, strerror(errno));
        return -1;
    }
    char line[4096];
    int skip = 0, in_solver = 0, lambda_done = 0, saw_solver = 0;
    while (fgets(line, sizeof line, f)) {
        int top = line[0] != ' ' && line[0] != '\t' && line[0] != '#' && line[0] != '\n' &&
                  line[0] != '\r';
        if (top) {
            if (in_solver && !lambda_done) {
                put(t, "  lambda: %.6g  # commissioned\n", lambda_ref);
                lambda_done = 1;
            }
            skip = !strncmp(line, "bridge:", 7) || !strncmp(line, "sensors:", 8) ||
                   !strncmp(line, "detector:", 9);
            in_solver = !strncmp(line, "solver:", 7);
            saw_solver |= in_solver;
        }
        if (skip)
            continue;
        if (in_solver && !strncmp(line, "  lambda:", 9)) {
            put(t, "  lambda: %.6g  # commissioned (the design's: %.*s)\n", lambda_ref,
                (int)strcspn(line + 9, "#\n") , line + 9);
            lambda_done = 1;
            continue;
        }
        put(t, "%s", line);
        if (line[strlen(line) - 1] != '\n')
            put(t, "\n");
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        snprintf(err, errlen, "%s: read error", design_path);
        return -1;
    }
    if (in_solver && !lambda_done)
        put(t, "  lambda: %.6g  # commissioned\n", lambda_ref);
    if (!saw_solver)
        put(t, "solver:\n  lambda: %.6g  # commissioned\n", lambda_ref);
    return 0;
}

static void put_header(text *t, const char *design, const char *runs_path, int n_amb,
                       const cm_runs *runs, const cm_result *r)
{
    time_t now = time(NULL);
    char when[32];
    strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    put(t, "# Commissioned by %s %s on %s\n", PROG, amfi_version(), when);
    put(t, "# from the design %s, %d calibration runs in %s", design, runs->n, runs_path);
    put(t, " and %d ambient record%s.\n", n_amb, n_amb == 1 ? "" : "s");
    put(t, "# Measured (free vibration of %d records): f1 = %.4f Hz (+- %.4f), damping "
           "ratio %.4f (+- %.4f).\n",
        r->n_modal, r->f1_meas_hz, r->f1_meas_sd_hz, r->zeta_meas, r->zeta_meas_sd);
    put(t, "# Model f1: design %.4f Hz, commissioned %.4f Hz.\n", r->before.f1_hz, r->after.f1_hz);
    if (r->speeds_estimated)
        put(t, "# Each run's speed estimated from its acceleration (the detector's random error\n"
               "# per run: SD %.2f %% over the runs); the speed scale is the mean of its error.\n",
            r->run_speed_sd_pct);
    put(t, "# Fitted (value +- standard uncertainty; from f1, the runs' known axle loads\n"
           "# and their fit with the free vibration after the last axle):\n");
    for (int k = 0; k < CM_P_SEG; k++) {
        double v = r->p[k], sd = r->sd[k];
        if (k == CM_P_EI && r->n_segments > 0) {
            put(t, "#   flexural stiffness per segment (E.I over the design's):\n");
            for (int i = 0; i < r->n_segments; i++)
                put(t, "#     %5.2f .. %5.2f m  x%.5f +- %.5f%s\n", r->seg_x0_m[i],
                    r->seg_x1_m[i], r->seg_scale[i], r->seg_scale[i] * r->seg_sd_rel[i],
                    i == r->seg_ref ? " (the reference: the first sensor's segment)" : "");
            continue;
        }
        if (k == CM_P_SPEED)
            v = r->speed_scale_log, sd = r->speed_scale_sd;
        switch (k) {
        case CM_P_EI: { /* reported as the stiffness scale c·r */
            double ls = r->p[CM_P_EI] + r->p[CM_P_MASS];
            double var = r->cov[CM_P_EI][CM_P_EI] + r->cov[CM_P_MASS][CM_P_MASS] +
                         2 * r->cov[CM_P_EI][CM_P_MASS];
            sd = isfinite(r->sd[CM_P_EI]) || isfinite(r->sd[CM_P_MASS]) ? sqrt(var) : NAN;
            put(t, "#   %-30s x%.5f", "flexural stiffness scale", exp(ls));
            if (isfinite(sd))
                put(t, " +- %.5f", exp(ls) * sd);
            break;
        }
        case CM_P_MASS:
        case CM_P_SPEED:
            put(t, "#   %-30s x%.5f", k == CM_P_MASS ? "mass scale" : cm_param_names[k], exp(v));
            if (isfinite(sd))
                put(t, " +- %.5f", exp(v) * sd);
            break;
        case CM_P_KAPPA:
            if (exp(v) <= 1e-3)
                put(t, "#   %-30s none: pinned (the scan's best)", cm_param_names[k]);
            else
                put(t, "#   %-30s kL/EI = %.4f", cm_param_names[k], exp(v));
            if (isfinite(sd))
                put(t, " +- %.4f", exp(v) * sd);
            break;
        case CM_P_SENSOR:
            put(t, "#   %-30s %+.4f m", cm_param_names[k], v);
            if (isfinite(sd))
                put(t, " +- %.4f", sd);
            break;
        default:
            put(t, "#   %-30s %+.5f s", cm_param_names[k], v);
            if (isfinite(sd))
                put(t, " +- %.5f", sd);
            break;
        }
        put(t, "%s\n", isfinite(sd) ? "" : " (held at the design's)");
    }
    if (r->lambda_fitted)
        put(t, "#   lambda %.3g (the runs' best, chosen leaving each run out in turn)\n",
            r->lambda_ref);
    else
        put(t, "#   lambda %.3g (the design's; --fit-lambda chooses it from the runs)\n",
            r->lambda_ref);
    put(t, "# Fit quality: residual/signal with the free vibration %.4f (design %.4f);\n",
        r->after.mean_resid_rel, r->before.mean_resid_rel);
    put(t, "# calibration GVW error mean %+.2f %%, mean |.| %.2f %%, worst %+.2f %% "
           "(design: %+.2f, %.2f, %+.2f %%).\n",
        r->after.mean_gvw_pct, r->after.mean_abs_gvw_pct, r->after.worst_gvw_pct,
        r->before.mean_gvw_pct, r->before.mean_abs_gvw_pct, r->before.worst_gvw_pct);
    put(t, "# Largest correlation between fitted parameters %.3f", r->corr_max);
    if (r->n_segments > 0)
        put(t, "; between a segment's stiffness and\n# another's or another parameter %.3f (%s)",
            r->seg_corr_max, r->seg_corr_what[0] ? r->seg_corr_what : "none");
    put(t, ".\n\n");
}

static int write_site(const char *out, const char *design_path, const char *runs_path,
                      int n_amb, const cm_runs *runs, const cm_result *r,
                      const amfi_site_config *design, char *err, size_t errlen)
{
    text t = {0};
    put_header(&t, design_path, runs_path, n_amb, runs, r);
    if (copy_design(&t, design_path, r->lambda_ref, err, errlen) != 0) {
        free(t.s);
        return -1;
    }
    put(&t, "\n");
    put_bridge(&t, &r->site, design);
    put_sensors(&t, &r->site);
    put(&t, "detector:\n  clock_offset_s: %.6f\n  speed_scale: %.6f\n",
        r->site.detector.clock_offset_s, r->site.detector.speed_scale);
    if (!t.s) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", out, (long)getpid());
    FILE *f = fopen(tmp, "wx");
    if (!f) {
        snprintf(err, errlen, "%.900s: cannot write: %s", tmp, strerror(errno));
        free(t.s);
        return -1;
    }
    int bad = fwrite(t.s, 1, t.n, f) != t.n;
    bad |= fclose(f) != 0;
    free(t.s);
    /* what was written loads back as the commissioned model */
    amfi_site_config back;
    char lerr[512];
    if (bad || amfi_config_load(tmp, &back, lerr, sizeof lerr) != 0) {
        snprintf(err, errlen, "%s: the written site file does not load back: %s", out,
                 bad ? strerror(errno) : lerr);
        unlink(tmp);
        return -1;
    }
    const amfi_bridge_params *a = &back.bridge, *b = &r->site.bridge;
    int same = fabs(a->E_pa / b->E_pa - 1) < 1e-8 &&
               fabs(a->density_kgm3 / b->density_kgm3 - 1) < 1e-8 &&
               fabs(back.solver.sensor_x_m[0] - r->site.solver.sensor_x_m[0]) < 1e-8 &&
               fabs(back.lambda.lambda_ref / r->lambda_ref - 1) < 1e-5 && !back.lambda.automatic;
    same = same && a->n_segments == b->n_segments;
    for (int i = 0; same && i < a->n_segments; i++)
        same = fabs(a->segments[i].EI_nm2 - b->segments[i].EI_nm2) <=
                   1e-8 * (1 + b->segments[i].EI_nm2) &&
               fabs(a->segments[i].mass_kgpm - b->segments[i].mass_kgpm) <=
                   1e-8 * (1 + b->segments[i].mass_kgpm);
    for (int i = 0; same && i < a->n_supports; i++)
        same = fabs(a->supports[i].k_theta_nmprad - b->supports[i].k_theta_nmprad) <=
               1e-8 * (1 + b->supports[i].k_theta_nmprad);
    if (!same) {
        snprintf(err, errlen, "%s: the written site file does not load back as the "
                 "commissioned model", out);
        unlink(tmp);
        return -1;
    }
    if (rename(tmp, out) != 0) {
        snprintf(err, errlen, "%s: %s", out, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* ---- report ------------------------------------------------------------- */

static int class_of(const double *err_pct, int n, amfi_cost323_condition cond,
                    amfi_cost323_result *out)
{
    char why[200];
    return amfi_cost323_evaluate(AMFI_COST323_GROSS, err_pct, n, cond, AMFI_COST323_ENV_I, 0,
                                 out, why, sizeof why);
}

static int write_report(const char *dir, const cm_runs *runs, const cm_result *r, char *err,
                        size_t errlen)
{
    if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
        snprintf(err, errlen, "%s: %s", dir, strerror(errno));
        return -1;
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/runs.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        goto io;
    fprintf(f, "file,speed_mps,speed_found_mps,gvw_kg,gvw_err_before_pct,gvw_err_after_pct,"
               "gvw_err_loo_pct,fit_before,fit_after\n");
    for (int i = 0; i < runs->n; i++)
        fprintf(f, "%s,%.3f,%.4f,%.1f,%.3f,%.3f,%.3f,%.5f,%.5f\n", runs->run[i].file,
                runs->run[i].speed_mps, r->run_speed_mps[i], runs->run[i].gvw_kg,
                r->before.gvw_err_pct[i],
                r->after.gvw_err_pct[i], r->loo_gvw_err_pct[i], r->before.resid_rel[i],
                r->after.resid_rel[i]);
    if (fclose(f) != 0)
        goto io;
    snprintf(path, sizeof path, "%s/accuracy.csv", dir);
    if (!(f = fopen(path, "w")))
        goto io;
    fprintf(f, "criterion,measured_kg,reference_kg\n");
    for (int i = 0; i < runs->n; i++)
        fprintf(f, "gross,%.2f,%.2f\n", runs->run[i].gvw_kg * (1 + r->after.gvw_err_pct[i] / 100),
                runs->run[i].gvw_kg);
    if (fclose(f) != 0)
        goto io;
    snprintf(path, sizeof path, "%s/report.md", dir);
    if (!(f = fopen(path, "w")))
        goto io;
    fprintf(f, "# Commissioning report\n\n");
    fprintf(f, "## Natural frequency\n\n| | f1, Hz |\n|---|---|\n");
    fprintf(f, "| measured (%d records) | %.4f ± %.4f |\n", r->n_modal, r->f1_meas_hz,
            r->f1_meas_sd_hz);
    fprintf(f, "| design model | %.4f (%+.2f %%) |\n", r->before.f1_hz,
            100 * (r->before.f1_hz / r->f1_meas_hz - 1));
    fprintf(f, "| commissioned model | %.4f (%+.2f %%) |\n\n", r->after.f1_hz,
            100 * (r->after.f1_hz / r->f1_meas_hz - 1));
    fprintf(f, "Damping ratio measured %.4f ± %.4f.\n\n", r->zeta_meas, r->zeta_meas_sd);
    if (r->n_segments > 0) {
        fprintf(f, "## Stiffness per segment\n\nE·I over the design's, with its standard "
                   "uncertainty; the reference segment (the first sensor's) carries the "
                   "common level that f1 fixes.\n\n| segment | from m | to m | E·I scale | "
                   "± | ± %% |\n|---|---|---|---|---|---|\n");
        for (int i = 0; i < r->n_segments; i++)
            fprintf(f, "| %d%s | %.2f | %.2f | %.5f | %.5f | %.2f |\n", i + 1,
                    i == r->seg_ref ? " (reference)" : "", r->seg_x0_m[i], r->seg_x1_m[i],
                    r->seg_scale[i], r->seg_scale[i] * r->seg_sd_rel[i],
                    100 * r->seg_sd_rel[i]);
        fprintf(f, "\nLargest correlation: %s, %.3f.\n\n",
                r->seg_corr_what[0] ? r->seg_corr_what : "none", r->seg_corr_max);
    }
    fprintf(f, "## Runs\n\nGVW errors in %%; fit = residual/signal with the free vibration "
               "after the last axle in the window.\n\n");
    if (r->speeds_estimated)
        fprintf(f, "Each run's speed was estimated from its acceleration (runs.csv: "
                   "speed_found_mps); the detector's random error per run has an SD of "
                   "%.2f %% over the runs.\n\n", r->run_speed_sd_pct);
    fprintf(f, "| run | speed m/s | GVW kg | design | commissioned | left out | fit design | "
               "fit commissioned |\n|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < runs->n; i++)
        fprintf(f, "| %s | %.2f | %.0f | %+.2f | %+.2f | %+.2f | %.4f | %.4f |\n",
                runs->run[i].file, runs->run[i].speed_mps, runs->run[i].gvw_kg,
                r->before.gvw_err_pct[i], r->after.gvw_err_pct[i], r->loo_gvw_err_pct[i],
                r->before.resid_rel[i], r->after.resid_rel[i]);
    amfi_cost323_result cb, ca, cl;
    int okb = class_of(r->before.gvw_err_pct, runs->n, AMFI_COST323_R2, &cb) == 0;
    int oka = class_of(r->after.gvw_err_pct, runs->n, AMFI_COST323_R2, &ca) == 0;
    int okl = class_of(r->loo_gvw_err_pct, runs->n, AMFI_COST323_R2, &cl) == 0;
    fprintf(f, "\n## COST 323 class of the runs (gross weight, r2, environment I)\n\n");
    fprintf(f, "| model | mean %% | SD %% | class |\n|---|---|---|---|\n");
    if (okb)
        fprintf(f, "| design | %+.2f | %.2f | %s |\n", cb.mean_pct, cb.std_pct, cb.class_name);
    if (oka)
        fprintf(f, "| commissioned | %+.2f | %.2f | %s |\n", ca.mean_pct, ca.std_pct,
                ca.class_name);
    if (okl)
        fprintf(f, "| commissioned, λ chosen without the run | %+.2f | %.2f | %s |\n",
                cl.mean_pct, cl.std_pct, cl.class_name);
    fprintf(f, "\nThe runs fitted the model: their class is optimistic. The class a site "
               "states comes from vehicles not used for commissioning "
               "(amfi-accuracy on reference weights).\n");
    if (fclose(f) != 0)
        goto io;
    return 0;
io:
    snprintf(err, errlen, "%.900s: %s", path, strerror(errno));
    return -1;
}

int main(int argc, char **argv)
{
    static const struct option opts[] = {{"config", required_argument, NULL, 'c'},
                                         {"runs", required_argument, NULL, 'r'},
                                         {"ambient", required_argument, NULL, 'a'},
                                         {"out", required_argument, NULL, 'o'},
                                         {"report", required_argument, NULL, 256},
                                         {"hold", required_argument, NULL, 257},
                                         {"verbose", no_argument, NULL, 'v'},
                                         {"fit-lambda", no_argument, NULL, 258},
                                         {"speed-sd", required_argument, NULL, 259},
                                         {"segments", required_argument, NULL, 260},
                                         AMFI_CLI_END};
    amfi_cli cli;
    amfi_cli_init(&cli, PROG, argc, argv, opts, usage);
    const char *config = NULL, *runs_path = NULL, *out = NULL, *report = NULL;
    const char *amb_path[MAX_AMBIENT];
    int n_amb = 0;
    cm_options o;
    cm_options_default(&o);
    for (int k; (k = amfi_cli_next(&cli)) != -1;) {
        switch (k) {
        case 'c': config = optarg; break;
        case 'r': runs_path = optarg; break;
        case 'o': out = optarg; break;
        case 'v': o.verbose = 1; break;
        case 256: report = optarg; break;
        case 258: o.fit_lambda = 1; break;
        case 259: o.speed_sd = amfi_cli_num(&cli, optarg, 0, 0.15); break;
        case 260: o.n_segments = (int)amfi_cli_integer(&cli, optarg, 2, CM_MAX_FIT_SEGMENTS); break;
        case 'a':
            if (n_amb == MAX_AMBIENT)
                amfi_cli_fail(&cli, "at most %d records", MAX_AMBIENT);
            amb_path[n_amb++] = optarg;
            break;
        case 257: {
            int found = 0;
            for (int p = 0; p < CM_P_SEG; p++)
                if (!strcmp(optarg, hold_names[p]))
                    o.fit[p] = 0, found = 1;
            if (!found)
                amfi_cli_fail(&cli, "'%s' is not stiffness, mass, bearings, sensor, clock or "
                                    "speed", optarg);
            break;
        }
        default: break;
        }
    }
    if (!config || !runs_path || !out) {
        amfi_cli_error(PROG, !config ? "--config" : !runs_path ? "--runs" : "--out",
                       "required");
        return AMFI_CLI_EXIT_USAGE;
    }
    static amfi_site_config design;
    char err[1024];
    if (amfi_config_load(config, &design, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    static cm_runs runs;
    if (cm_runs_read(runs_path, &design, &runs, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    accel_csv amb[MAX_AMBIENT];
    const double *amb_y[MAX_AMBIENT];
    int amb_n[MAX_AMBIENT];
    double amb_rate[MAX_AMBIENT];
    int rc = 1;
    for (int i = 0; i < n_amb; i++) {
        memset(&amb[i], 0, sizeof amb[i]);
        if (accel_csv_read(amb_path[i], &amb[i], err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            for (int j = 0; j < i; j++)
                accel_csv_free(&amb[j]);
            cm_runs_free(&runs);
            return 1;
        }
        amb_y[i] = amb[i].accel;
        amb_n[i] = amb[i].n;
        amb_rate[i] = amb[i].rate_hz;
    }
    static cm_result res;
    if (cm_identify(&design, &runs, amb_y, amb_n, amb_rate, n_amb, &o, &res, err, sizeof err) !=
        0) {
        fprintf(stderr, PROG ": %s: %s\n", runs_path, err);
        goto done;
    }
    res.site.detector.clock_offset_s = design.detector.clock_offset_s + res.p[CM_P_CLOCK];
    res.site.detector.speed_scale = design.detector.speed_scale * exp(res.speed_scale_log);
    if (write_site(out, config, runs_path, n_amb, &runs, &res, &design, err, sizeof err) != 0 ||
        (report && write_report(report, &runs, &res, err, sizeof err) != 0)) {
        fprintf(stderr, PROG ": %s\n", err);
        goto done;
    }
    amfi_cost323_result cls;
    int have_class = class_of(res.after.gvw_err_pct, runs.n, AMFI_COST323_R2, &cls) == 0;
    json_t *j = json_object();
    json_object_set_new(j, "site", json_string(out));
    json_object_set_new(j, "runs", json_integer(runs.n));
    json_object_set_new(j, "modal_records", json_integer(res.n_modal));
    json_object_set_new(j, "f1_measured_hz", amfi_json_num(res.f1_meas_hz));
    json_object_set_new(j, "f1_design_hz", amfi_json_num(res.before.f1_hz));
    json_object_set_new(j, "f1_commissioned_hz", amfi_json_num(res.after.f1_hz));
    json_object_set_new(j, "damping_ratio", amfi_json_num(res.zeta_meas));
    json_object_set_new(j, "stiffness_scale",
                        amfi_json_num(exp(res.p[CM_P_EI] + res.p[CM_P_MASS])));
    json_object_set_new(j, "mass_scale", amfi_json_num(exp(res.p[CM_P_MASS])));
    if (res.n_segments > 0) {
        json_t *sg = json_array();
        for (int i = 0; i < res.n_segments; i++) {
            json_t *e = json_object();
            json_object_set_new(e, "from_m", amfi_json_num(res.seg_x0_m[i]));
            json_object_set_new(e, "to_m", amfi_json_num(res.seg_x1_m[i]));
            json_object_set_new(e, "stiffness_scale", amfi_json_num(res.seg_scale[i]));
            json_object_set_new(e, "sd_rel", amfi_json_num(res.seg_sd_rel[i]));
            json_array_append_new(sg, e);
        }
        json_object_set_new(j, "segments", sg);
        json_object_set_new(j, "segments_corr_max", amfi_json_num(res.seg_corr_max));
    }
    json_object_set_new(j, "bearing_kL_EI",
                        amfi_json_num(exp(res.p[CM_P_KAPPA]) > 1e-3 ? exp(res.p[CM_P_KAPPA]) : 0));
    json_object_set_new(j, "sensor_offset_m", amfi_json_num(res.p[CM_P_SENSOR]));
    json_object_set_new(j, "clock_offset_s", amfi_json_num(res.site.detector.clock_offset_s));
    json_object_set_new(j, "speed_scale", amfi_json_num(res.site.detector.speed_scale));
    json_object_set_new(j, "lambda", amfi_json_num(res.lambda_ref));
    json_object_set_new(j, "gvw_mean_abs_err_design_pct", amfi_json_num(res.before.mean_abs_gvw_pct));
    json_object_set_new(j, "gvw_mean_abs_err_pct", amfi_json_num(res.after.mean_abs_gvw_pct));
    json_object_set_new(j, "gvw_worst_err_pct", amfi_json_num(res.after.worst_gvw_pct));
    json_object_set_new(j, "fit_design", amfi_json_num(res.before.mean_resid_rel));
    json_object_set_new(j, "fit", amfi_json_num(res.after.mean_resid_rel));
    json_object_set_new(j, "class_runs", have_class ? json_string(cls.class_name) : json_null());
    json_object_set_new(j, "run_speeds", json_string(res.speeds_estimated ? "estimated" : "detector"));
    if (res.speeds_estimated)
        json_object_set_new(j, "run_speed_sd_pct", amfi_json_num(res.run_speed_sd_pct));
    json_object_set_new(j, "iterations", json_integer(res.iterations));
    json_object_set_new(j, "evaluations", json_integer(res.evaluations));
    json_object_set_new(j, "scan_evaluations", json_integer(res.scan_evaluations));
    json_object_set_new(j, "seconds", amfi_json_num(res.seconds));
    json_t *cpu = json_object();
    json_object_set_new(cpu, "modal_and_design", amfi_json_num(res.cpu_modal_s));
    json_object_set_new(cpu, "run_speeds", amfi_json_num(res.cpu_speed_s));
    json_object_set_new(cpu, "scans", amfi_json_num(res.cpu_scan_s));
    json_object_set_new(cpu, "search", amfi_json_num(res.cpu_search_s));
    json_object_set_new(cpu, "final", amfi_json_num(res.cpu_final_s));
    json_object_set_new(j, "cpu_s", cpu);
    rc = amfi_json_print(stdout, j) != 0;
done:
    for (int i = 0; i < n_amb; i++)
        accel_csv_free(&amb[i]);
    cm_runs_free(&runs);
    return rc;
}
