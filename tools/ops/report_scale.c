/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_scale.c: amfi-report's scale-indicator and known-truck lines and
 * plots (report_scale.h). Single-threaded; reads the store only.
 */
#include "report_scale.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *utc_of(int64_t utime, char *buf, size_t n)
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(buf, n, "%Y-%m-%d %H:%M", &tm);
    return buf;
}

/* Range of the finite values of one column over the non-baseline rows. */
static void range_of(const amfi_scale_eval_rec *r, size_t n, int raw, double *lo, double *hi,
                     size_t *k)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    *k = 0;
    for (size_t i = 0; i < n; i++) {
        double v = raw ? r[i].raw : r[i].value;
        if (strcmp(r[i].state, "baseline") == 0 || !isfinite(v))
            continue;
        if (v < *lo) *lo = v;
        if (v > *hi) *hi = v;
        (*k)++;
    }
}

int report_scale_summary(amfi_store *s, FILE *f, char *err, size_t errlen)
{
    amfi_scale_eval_rec *r = NULL;
    size_t n = 0, k = 0;
    char a[32];
    double lo, hi, rlo, rhi;
    if (amfi_store_scale_evals(s, "scale_shift", &r, &n, err, errlen) != 0)
        return -1;
    if (n > 0) {
        range_of(r, n, 0, &lo, &hi, &k);
        range_of(r, n, 1, &rlo, &rhi, &k);
        const amfi_scale_eval_rec *e = &r[n - 1];
        if (k == 0)
            fprintf(f, "scale        baseline fitted %s UTC (%d vehicles); no block since\n",
                    utc_of(e->utime, a, sizeof a), e->n);
        else
            fprintf(f,
                    "scale        %zu blocks, newest %s UTC: %.4f compensated (raw %.4f, deck "
                    "%.1f °C), CUSUM %.2f of %.2f, %s; all blocks %.4f .. %.4f (raw %.4f .. "
                    "%.4f)\n",
                    k, utc_of(e->utime, a, sizeof a), e->value, e->raw, e->deck_c, e->cusum,
                    e->h, e->state, lo, hi, rlo, rhi);
    }
    free(r);
    r = NULL;
    if (amfi_store_scale_evals(s, "known_truck", &r, &n, err, errlen) != 0)
        return -1;
    if (n > 0) {
        range_of(r, n, 0, &lo, &hi, &k);
        const amfi_scale_eval_rec *e = &r[n - 1];
        double sum = 0;
        size_t m = 0;
        for (size_t i = 0; i < n; i++)
            if (isfinite(r[i].value)) {
                sum += r[i].value;
                m++;
            }
        fprintf(f,
                "known truck  %zu runs, ratio inferred/reference (compensated) mean %.4f, %.4f "
                ".. %.4f; newest %s UTC: %.4f (raw %.4f, deck %.1f °C), %s",
                n, m ? sum / (double)m : NAN, m ? lo : NAN, m ? hi : NAN,
                utc_of(e->utime, a, sizeof a), e->value, e->raw, e->deck_c, e->state);
        if (isfinite(e->cusum))
            fprintf(f, ", CUSUM %.2f of %.2f", e->cusum, e->h);
        fputc('\n', f);
    }
    free(r);
    return 0;
}

/* scale.dat or known_truck.dat: t value raw deck z cusum h state(0 baseline,
 * 1 normal, 2 watch, 3 alert); NaN where unknown. */
static int write_evals(const char *dir, const char *name, const amfi_scale_eval_rec *r, size_t n,
                       char *err, size_t errlen)
{
    FILE *f = report_data_open(dir, name, err, errlen);
    if (!f)
        return -1;
    fprintf(f, "# time_s value raw deck_c z cusum h state(0 baseline,1 normal,2 watch,3 alert)\n");
    for (size_t i = 0; i < n; i++) {
        int st = !strcmp(r[i].state, "normal") ? 1 : !strcmp(r[i].state, "watch") ? 2
                 : !strcmp(r[i].state, "alert") ? 3 : 0;
        fprintf(f, "%.3f %.6g %.6g %.4g %.4g %.4g %.4g %d\n", (double)r[i].utime / 1e6,
                r[i].value, r[i].raw, r[i].deck_c, r[i].z, r[i].cusum, r[i].h, st);
    }
    return report_data_close(f, dir, name, err, errlen);
}

/* Keep the rows of the plots' range, in order. */
static void keep_range(const report_plot_frame *p, amfi_scale_eval_rec *r, size_t *n)
{
    size_t k = 0;
    for (size_t i = 0; i < *n; i++)
        if (report_plot_in_range(p, r[i].utime))
            r[k++] = r[i];
    *n = k;
}

/* A time axis in data time, y autoscaled, no leftover label. */
static void time_axis(FILE *gp)
{
    fputs("unset label 99\nset autoscale y\nset xdata time\nset timefmt '%s'\n"
          "set format x \"%H:%M\\n%d %b\"\nset autoscale x\nset xlabel 'time (UTC, data time)'\n",
          gp);
}

int scale_plot_scale(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_scale_eval_rec *sc = NULL;
    size_t nsc = 0;
    if (amfi_store_scale_evals(p->s, "scale_shift", &sc, &nsc, err, errlen) != 0)
        return -1;
    keep_range(p, sc, &nsc);
    size_t blocks = 0; /* gnuplot refuses a plot without one valid point */
    for (size_t i = 0; i < nsc; i++)
        blocks += strcmp(sc[i].state, "baseline") != 0;
    int rc = 0;
    if (blocks > 0) {
        rc = write_evals(p->dir, "scale.dat", sc, nsc, err, errlen);
        if (rc == 0) {
            fprintf(p->gp,
                "unset label 99\nset autoscale y\nset xdata time\nset timefmt '%%s'\n"
                "set format x \"%%H:%%M\\n%%d %%b\"\nset autoscale x\n"
                "set terminal pngcairo size 960,700 noenhanced\nset output o.'scale.png'\n"
                "set multiplot layout 2,1 title \"Scale indicator (scale_shift): %zu blocks after the baseline\\n%s\"\n"
                "unset title\nset lmargin at screen 0.09\nset rmargin at screen 0.72\n"
                "set format x ''\nunset xlabel\nset ylabel 'scale of inferred GVW'\n"
                "plot d.'scale.dat' using 1:($8>0?$3:NaN) with linespoints pt 6 ps 0.5 lc rgb '#aaaaaa' title 'raw', \\\n"
                "     d.'scale.dat' using 1:($8>0?$2:NaN) with linespoints pt 7 ps 0.5 lc rgb '#1f77b4' title 'temperature-compensated', \\\n"
                "     1 with lines dt 2 lc rgb 'black' notitle\n"
                "set format x \"%%H:%%M\\n%%d %%b\"\nset xlabel 'time (UTC, data time)'\n"
                "set ylabel 'CUSUM (block SDs)'\n"
                "plot d.'scale.dat' using 1:($8>0?$6:NaN) with steps lw 2 lc rgb '#ff7f0e' title 'CUSUM', \\\n"
                "     d.'scale.dat' using 1:7 with lines dt 1 lc rgb '#d62728' title 'threshold h'\n"
                "unset multiplot\nset lmargin\nset rmargin\nset terminal pngcairo size 960,540 noenhanced\nset output\n",
                blocks, p->site);
            *made = 1;
        }
    }
    free(sc);
    return rc;
}

int scale_plot_known_truck(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_scale_eval_rec *kt = NULL;
    size_t nkt = 0;
    if (amfi_store_scale_evals(p->s, "known_truck", &kt, &nkt, err, errlen) != 0)
        return -1;
    keep_range(p, kt, &nkt);
    int rc = 0;
    if (nkt > 0) {
        rc = write_evals(p->dir, "known_truck.dat", kt, nkt, err, errlen);
        if (rc == 0) {
            time_axis(p->gp);
            fprintf(p->gp,
                "set output o.'known_truck.png'\n"
                "set title \"Known-truck runs (known_truck): %zu runs, inferred / reference GVW\\n%s\"\n"
                "set ylabel 'ratio inferred / reference'\n"
                "plot d.'known_truck.dat' using 1:3 with points pt 6 ps 0.8 lc rgb '#aaaaaa' title 'raw', \\\n"
                "     d.'known_truck.dat' using 1:2 with linespoints pt 7 ps 0.8 lc rgb '#2ca02c' title 'temperature-compensated', \\\n"
                "     d.'known_truck.dat' using 1:($8==3?$2:NaN) with points pt 7 ps 1.2 lc rgb '#d62728' title 'in alert', \\\n"
                "     1 with lines dt 2 lc rgb 'black' notitle\nset output\n",
                nkt, p->site);
            *made = 1;
        }
    }
    free(kt);
    return rc;
}

int scale_plot_temperature(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_environment_row *env = NULL;
    size_t nenv = 0;
    if (amfi_store_environment_rows(p->s, &env, &nenv, err, errlen) != 0)
        return -1;
    size_t kept = 0;
    for (size_t i = 0; i < nenv; i++)
        if (report_plot_in_range(p, env[i].utime))
            env[kept++] = env[i];
    nenv = kept;
    if (nenv == 0) {
        free(env);
        return 0;
    }
    FILE *f = report_data_open(p->dir, "temperature.dat", err, errlen);
    if (!f) {
        free(env);
        return -1;
    }
    /* at most about 20 000 points: a year of minute readings is thinned */
    size_t step = nenv / 20000 + 1;
    fprintf(f, "# time_s deck_c air_c (every %zu-th reading)\n", step);
    for (size_t i = 0; i < nenv; i += step)
        fprintf(f, "%.3f %.2f %.2f\n", (double)env[i].utime / 1e6, env[i].deck_c, env[i].air_c);
    free(env);
    if (report_data_close(f, p->dir, "temperature.dat", err, errlen) != 0)
        return -1;
    time_axis(p->gp);
    fprintf(p->gp,
        "set output o.'temperature.png'\n"
        "set title \"Deck and air temperature (environment_t, %zu readings)\\n%s\"\n"
        "set ylabel 'temperature (°C)'\n"
        "plot d.'temperature.dat' using 1:2 with lines lw 1.5 lc rgb '#d62728' title 'deck', \\\n"
        "     d.'temperature.dat' using 1:3 with lines lc rgb '#1f77b4' title 'air', \\\n"
        "     0 with lines dt 2 lc rgb 'black' notitle\nset output\n",
        nenv, p->site);
    *made = 1;
    return 0;
}
