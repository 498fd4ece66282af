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
