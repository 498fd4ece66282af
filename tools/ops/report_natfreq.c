/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_natfreq.c: amfi-report's natural-frequency summary and plot
 * (report_natfreq.h). Single-threaded, the caller's thread.
 */
#include "report_natfreq.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* n, mean and SD (n − 1) of the finite raw (comp 0) or compensated f1 */
static void stats(const amfi_f1_rec *a, size_t n, int comp, size_t *m, double *mean, double *sd)
{
    double s1 = 0, s2 = 0;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        const double v = comp ? a[i].f1_comp_hz : a[i].f1_hz;
        if (!isfinite(v))
            continue;
        s1 += v;
        s2 += v * v;
        k++;
    }
    *m = k;
    *mean = k ? s1 / k : NAN;
    *sd = k > 1 ? sqrt(fmax(0.0, (s2 - k * (*mean) * (*mean)) / (k - 1))) : NAN;
}

int natfreq_read_stats(amfi_store *s, natfreq_stats *st, char *err, size_t errlen)
{
    amfi_f1_rec *a = NULL;
    size_t n = 0;
    if (amfi_store_f1_series(s, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err, errlen) != 0)
        return -1;
    stats(a, n, 0, &st->n, &st->mean_hz, &st->sd_hz);
    stats(a, n, 1, &st->n_comp, &st->comp_mean_hz, &st->comp_sd_hz);
    free(a);
    return 0;
}

int natfreq_summary(amfi_store *s, char *line, size_t len, char *err, size_t errlen)
{
    amfi_f1_rec *a = NULL;
    size_t n = 0, nr, nc;
    double mr, sr, mc, sc;
    line[0] = '\0';
    if (amfi_store_f1_series(s, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err, errlen) != 0)
        return -1;
    size_t at = 0;
    if (n > 0) {
        stats(a, n, 0, &nr, &mr, &sr);
        stats(a, n, 1, &nc, &mc, &sc);
        /* the newest 50 of each, for the drift at a glance */
        size_t from = n > 50 ? n - 50 : 0, lr, lc;
        double lmr, lsr, lmc, lsc;
        stats(a + from, n - from, 0, &lr, &lmr, &lsr);
        stats(a + from, n - from, 1, &lc, &lmc, &lsc);
        at += (size_t)snprintf(line + at, len - at,
                               "natural f1   n %zu, raw mean %.4f Hz (SD %.2f %%), compensated "
                               "n %zu",
                               nr, mr, nr > 1 ? 100 * sr / mr : 0.0, nc);
        if (nc > 0 && at < len)
            at += (size_t)snprintf(line + at, len - at, ", mean %.4f Hz (SD %.2f %%)", mc,
                                   nc > 1 ? 100 * sc / mc : 0.0);
        if (at < len)
            at += (size_t)snprintf(line + at, len - at, "; newest %zu: raw %.4f Hz", lr, lmr);
        if (lc > 0 && at < len)
            at += (size_t)snprintf(line + at, len - at, ", compensated %.4f Hz (%+.2f %%)", lmc,
                                   nc > 0 ? 100 * (lmc / mc - 1) : 0.0);
        if (at < len)
            at += (size_t)snprintf(line + at, len - at, "\n");
    }
    free(a);
    /* amfid's counters of this run (natfreq.*, daemon/freevib.c) */
    static const char *const names[] = {"no_free_vibration", "short", "no_peak", "no_fit",
                                        "damping", "noisy", "invalid"};
    char key[64], val[64], part[512] = "";
    size_t pat = 0;
    long long total = 0;
    for (size_t k = 0; k < sizeof names / sizeof *names; k++) {
        int found = 0;
        snprintf(key, sizeof key, "natfreq.%s", names[k]);
        if (amfi_store_meta_get(s, key, val, sizeof val, &found, err, errlen) != 0)
            return -1;
        const long long v = found ? atoll(val) : 0;
        if (v > 0 && pat < sizeof part) {
            pat += (size_t)snprintf(part + pat, sizeof part - pat, "%s%s %lld",
                                    total ? ", " : "", names[k], v);
            total += v;
        }
    }
    if (total > 0 && at < len)
        snprintf(line + at, len - at, "  not estimated (amfid's last run): %s\n", part);
    return 0;
}

int natfreq_plot(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_store *s = p->s;
    const char *dir = p->dir, *sub = p->sub;
    FILE *gp = p->gp;
    amfi_f1_rec *a = NULL;
    size_t n = 0;
    if (amfi_store_f1_series(s, p->from, p->to, 0, &a, &n, err, errlen) != 0)
        return -1;
    if (n == 0) {
        free(a);
        return 0;
    }
    size_t n_comp = 0; /* no legend entry for a series without a point */
    for (size_t k = 0; k < n; k++)
        n_comp += isfinite(a[k].f1_comp_hz) != 0;
    FILE *f = report_data_open(dir, "natfreq.dat", err, errlen);
    if (!f) {
        free(a);
        return -1;
    }
    fprintf(f, "# time_s f1_hz f1_comp_hz zeta_pct (nan: none)\n");
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%.3f %.6f %.6f %.4f\n", (double)a[k].utime / 1e6, a[k].f1_hz,
                isfinite(a[k].f1_comp_hz) ? a[k].f1_comp_hz : NAN,
                isfinite(a[k].f1_zeta) ? 100 * a[k].f1_zeta : NAN);
    free(a);
    if (report_data_close(f, dir, "natfreq.dat", err, errlen) != 0)
        return -1;
    fprintf(gp,
            "unset label 99\nset output o.'natfreq.png'\n"
            "set xdata time\nset timefmt '%%s'\nset format x \"%%H:%%M\\n%%d %%b\"\n"
            "set autoscale x\nset autoscale y\nunset xtics\nset xtics\n"
            "set title \"Natural frequency f1 from each passage's free vibration: raw and "
            "temperature-compensated\\n%s\"\n"
            "set xlabel 'time (UTC, data time)'\nset ylabel 'f1 (Hz)'\n"
            "plot d.'natfreq.dat' using 1:2 with points pt 7 ps 0.4 lc rgb '#aaaaaa' title 'raw'%s\n"
            "set output\n",
            sub, n_comp ? ", \\\n     d.'natfreq.dat' using 1:3 with points pt 7 ps 0.4 "
                          "lc rgb '#1f77b4' title 'compensated'" : "");
    *made = 1;
    return 0;
}
