/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_plot.c: amfi-report --plot DIR: the store drawn for a bridge
 * engineer. Reads every passage, indicator and alert through the store's
 * typed queries, writes plain data files and one gnuplot script under
 * DIR/data/, runs gnuplot (a program, found on PATH) on the script, and
 * checks each PNG appeared. Plots: inferred GVW per passage over time with
 * the baseline band (mean ± 2 STD); the indicator trend (STD ratio, mean
 * ratio, p-value) with the alert thresholds and every raised and cleared
 * alert marked; the GVW histogram of the baseline against the latest
 * window; passages per hour by status; the speed distribution; and, when
 * the store has estimated speeds (issue 12), the daily median speed
 * correction with its p5-p95 band (report_speed.c); when the store has
 * them (issue 14), the scale indicator, the known-truck runs and the
 * temperature (report_scale.c).
 *
 * Single-threaded, the caller's thread. Memory: four doubles per passage
 * (a million passages: 32 MB).
 */
#include <errno.h>
#include <math.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>

#include "report_natfreq.h"
#include "report_plot.h"
#include "report_scale.h"
#include "report_speed.h"

extern char **environ;

typedef struct pas {
    double t;     /* s since 1970 */
    double gvw;   /* kg or NaN */
    double speed; /* m/s or NaN */
    int status;   /* index in amfi_store_status_name order */
} pas;

typedef struct pas_vec {
    pas *v;
    size_t n, cap;
} pas_vec;

static int fail(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

static int collect(void *ctx, int64_t id, const amfi_passage_row *r)
{
    pas_vec *a = ctx;
    (void)id;
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 4096;
        pas *v = realloc(a->v, cap * sizeof *v);
        if (!v)
            return AMFI_ENOMEM;
        a->v = v;
        a->cap = cap;
    }
    pas *p = &a->v[a->n++];
    p->t = (double)r->utime / 1e6;
    p->gvw = r->gvw_kg;
    p->speed = r->speed_mps;
    p->status = 0;
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        if (strcmp(amfi_store_status_name(k), r->status) == 0)
            p->status = k;
    return 0;
}

FILE *report_data_open(const char *dir, const char *name, char *err, size_t errlen)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/data/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f)
        fail(err, errlen, "%s: %s", path, strerror(errno));
    return f;
}

int report_data_close(FILE *f, const char *dir, const char *name, char *err, size_t errlen)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return fail(err, errlen, "%s/data/%s: write failed", dir, name);
    return 0;
}

/* A PNG gnuplot should have written: listed on stdout, or −1 with err. */
static int listed(const char *dir, const char *name, const char *what, char *err, size_t errlen)
{
    char path[4096];
    struct stat stt;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (stat(path, &stt) != 0 || stt.st_size < 100)
        return fail(err, errlen, "%s: gnuplot wrote no image (see %s/data/gnuplot.log)", path,
                    dir);
    printf("plot  %s  %s\n", path, what);
    return 0;
}

static void utc_min(double t, char buf[32])
{
    time_t tt = (time_t)t;
    struct tm tm;
    if (!gmtime_r(&tt, &tm) || strftime(buf, 32, "%Y-%m-%d %H:%M", &tm) == 0)
        snprintf(buf, 32, "%.0f s", t);
}

/* Text from the store (the site name, or the store's file name) for a
 * gnuplot string: an allow-list, never an escape. gnuplot runs `...` even
 * inside double quotes and expands @macros, so only letters, digits, the
 * space, - _ . , : ; ( ) / + # & = ! ? [ ] and whole UTF-8 sequences of two
 * to four bytes pass; every other byte (quotes, backslash, backquote, $, @,
 * control characters, a broken UTF-8 sequence) becomes '_'. At most len - 1
 * bytes, never a UTF-8 sequence cut. */
static void gp_text(const char *s, char *out, size_t len)
{
    static const char punct[] = " -_.,:;()/+#&=!?[]";
    size_t k = 0;
    const unsigned char *p = (const unsigned char *)s;
    if (len == 0)
        return;
    while (*p && k + 1 < len) {
        unsigned char c = *p;
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')
            || (c < 0x80 && strchr(punct, c))) {
            out[k++] = (char)c;
            p++;
            continue;
        }
        /* a UTF-8 sequence: lead byte, then 1..3 continuation bytes */
        int n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3
              : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
        int whole = n > 0;
        for (int j = 1; whole && j < n; j++)
            whole = (p[j] & 0xc0) == 0x80;
        if (whole) {
            if (k + (size_t)n >= len)
                break;
            memcpy(out + k, p, (size_t)n);
            k += (size_t)n;
            p += n;
        } else {
            out[k++] = '_';
            p++;
        }
    }
    out[k] = '\0';
}

/* A word from the store written to a data file (an alert's level and kind,
 * an indicator's state): one whitespace-free token of printable ASCII, so
 * that a line break or blank in the store cannot add rows or columns. */
static const char *dat_word(const char *s, char out[64])
{
    size_t k = 0;
    for (; s && s[k] && k < 63; k++)
        out[k] = (unsigned char)s[k] > 0x20 && (unsigned char)s[k] < 0x7f ? s[k] : '_';
    if (k == 0)
        out[k++] = '-';
    out[k] = '\0';
    return out;
}

/* The --plot directory in a gnuplot single-quoted string (no backquote or
 * macro expansion there; a quote is written twice): refused when it holds a
 * control character, which would end the script line. */
static int gp_dir(const char *dir, char *out, size_t len, char *err, size_t errlen)
{
    size_t k = 0;
    for (const char *p = dir; *p; p++) {
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            return fail(err, errlen, "the directory name holds a control character (0x%02x at "
                        "byte %zu)", (unsigned)(unsigned char)*p, (size_t)(p - dir));
        if (k + 3 >= len)
            return fail(err, errlen, "the directory name is too long (%zu bytes)", strlen(dir));
        if (*p == '\'')
            out[k++] = '\'';
        out[k++] = *p;
    }
    out[k] = '\0';
    return 0;
}

static int mkdir_p(const char *d)
{
    return mkdir(d, 0777) == 0 || errno == EEXIST ? 0 : -1;
}

static int run_gnuplot(const char *dir, char *err, size_t errlen)
{
    char script[4096], log[4096];
    snprintf(script, sizeof script, "%s/data/plots.gp", dir);
    snprintf(log, sizeof log, "%s/data/gnuplot.log", dir);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", 0, 0);
    posix_spawn_file_actions_addopen(&fa, 1, log, 01 | 0100 | 01000, 0666);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    char *argv[] = {"gnuplot", script, NULL};
    pid_t pid;
    int rc = posix_spawnp(&pid, "gnuplot", &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0)
        return fail(err, errlen, "gnuplot: cannot run: %s (install gnuplot-nox)",
                    strerror(rc));
    int st = 0;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR)
            return fail(err, errlen, "gnuplot: waitpid: %s", strerror(errno));
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
        return fail(err, errlen, "gnuplot failed on %s (see %s)", script, log);
    return 0;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Histogram of v[0..n) into nb bins from lo by w, as fractions. */
static void hist(const double *v, size_t n, double lo, double w, int nb,
                 double *out)
{
    for (int k = 0; k < nb; k++)
        out[k] = 0;
    for (size_t k = 0; k < n; k++) {
        int b = (int)floor((v[k] - lo) / w);
        if (b >= 0 && b < nb)
            out[b] += 1.0 / (double)n;
    }
}

static const char *const status_colour[AMFI_STORE_N_STATUS] = {
    "#1f77b4", "#ff7f0e", "#9467bd", "#d62728", "#8c564b", "#7f7f7f", "#000000"};

int report_plot(amfi_store *s, const char *dir, const char *site_raw,
                const amfi_indicator_params *ip, char *err, size_t errlen)
{
    pas_vec pv = {0};
    amfi_indicator_rec *ind = NULL;
    amfi_alert_rec *al = NULL;
    double *ok = NULL, *bl = NULL, *la = NULL, *sp = NULL;
    FILE *f = NULL;
    speed_day *sdays = NULL;
    size_t n_sdays = 0;
    int rc = -1, n_ind = 0, n_al = 0, found = 0;
    int64_t total_ind = 0, total_al = 0;
    char serr[512], site[128], t0s[32], t1s[32], sub[256], path[4096], gdir[8200];
    char w1[64], w2[64];
    amfi_baseline b;

    gp_text(site_raw, site, sizeof site);
    if (gp_dir(dir, gdir, sizeof gdir, err, errlen) != 0)
        goto out;
    snprintf(path, sizeof path, "%s/data", dir);
    if (mkdir_p(dir) != 0 || mkdir_p(path) != 0) {
        fail(err, errlen, "%s: cannot create: %s", path, strerror(errno));
        goto out;
    }
    if (amfi_store_each_passage(s, 0, AMFI_STORE_MAX_UTIME, NULL, collect, &pv,
                                serr, sizeof serr) != 0
        || amfi_store_get_baseline(s, &b, &found, serr, sizeof serr) != 0
        || amfi_store_count(s, AMFI_STORE_INDICATORS, &total_ind, serr, sizeof serr) != 0
        || amfi_store_count(s, AMFI_STORE_ALERTS, &total_al, serr, sizeof serr) != 0) {
        fail(err, errlen, "%s", serr);
        goto out;
    }
    if (total_ind > 0) {
        ind = malloc((size_t)total_ind * sizeof *ind);
        if (!ind || amfi_store_recent_indicators(s, (int)total_ind, ind, &n_ind,
                                                 serr, sizeof serr) != 0) {
            fail(err, errlen, "%s", ind ? serr : "out of memory");
            goto out;
        }
    }
    if (total_al > 0) {
        al = malloc((size_t)total_al * sizeof *al);
        if (!al || amfi_store_recent_alerts(s, (int)total_al, al, &n_al, serr,
                                            sizeof serr) != 0) {
            fail(err, errlen, "%s", al ? serr : "out of memory");
            goto out;
        }
    }
    size_t n = pv.n;
    double t0 = n ? pv.v[0].t : 0, t1 = n ? pv.v[n - 1].t : 1;
    if (n_ind > 0) { /* newest first */
        t0 = fmin(t0, (double)ind[n_ind - 1].row.utime / 1e6);
        t1 = fmax(t1, (double)ind[0].row.utime / 1e6);
    }
    if (t1 <= t0)
        t1 = t0 + 60;
    utc_min(t0, t0s);
    utc_min(t1, t1s);
    if (n)
        snprintf(sub, sizeof sub, "%s, %s .. %s UTC, %zu passages", site, t0s, t1s, n);
    else
        snprintf(sub, sizeof sub, "%s, no passages in the store", site);

    /* passages.dat: t gvw_t status speed_kmh */
    if (!(f = report_data_open(dir, "passages.dat", err, errlen)))
        goto out;
    fprintf(f, "# time_s gvw_t status(0 ok,1 gap,2 late,3 overload,4 multiple,5 invalid,6 error) speed_kmh\n");
    size_t n_ok = 0, n_sp = 0, n_gvw = 0;
    ok = malloc((n + 1) * sizeof *ok);
    sp = malloc((n + 1) * sizeof *sp);
    if (!ok || !sp) {
        fclose(f);
        fail(err, errlen, "out of memory");
        goto out;
    }
    for (size_t k = 0; k < n; k++) {
        const pas *p = &pv.v[k];
        fprintf(f, "%.3f %.4f %d %.3f\n", p->t, isnan(p->gvw) ? NAN : p->gvw / 1000,
                p->status, isnan(p->speed) ? NAN : p->speed * 3.6);
        if (!isnan(p->gvw))
            n_gvw++;
        if (p->status == 0 && !isnan(p->gvw))
            ok[n_ok++] = p->gvw / 1000;
        if (!isnan(p->speed))
            sp[n_sp++] = p->speed * 3.6;
    }
    if (report_data_close(f, dir, "passages.dat", err, errlen) != 0)
        goto out;

    /* band.dat: baseline mean ± 2 STD from when it applies */
    if (!(f = report_data_open(dir, "band.dat", err, errlen)))
        goto out;
    if (found) {
        double tb = fmax(t0, (double)b.utime_set / 1e6);
        for (int k = 0; k < 2; k++)
            fprintf(f, "%.3f %.4f %.4f %.4f\n", k ? t1 : tb,
                    (b.mean_kg - 2 * b.std_kg) / 1000,
                    (b.mean_kg + 2 * b.std_kg) / 1000, b.mean_kg / 1000);
    } else {
        fprintf(f, "%.3f NaN NaN NaN\n", t0);
    }
    if (report_data_close(f, dir, "band.dat", err, errlen) != 0)
        goto out;

    /* indicators.dat, oldest first */
    if (!(f = report_data_open(dir, "indicators.dat", err, errlen)))
        goto out;
    fprintf(f, "# time_s std_ratio p_value mean_ratio n state\n");
    for (int k = n_ind - 1; k >= 0; k--) {
        const amfi_indicator_row *r = &ind[k].row;
        double mr = r->mean_kg / r->baseline_mean_kg;
        fprintf(f, "%.3f %.5g %.5g %.5g %d %s\n", (double)r->utime / 1e6,
                r->std_ratio, r->p_value, isfinite(mr) ? mr : NAN, r->n, dat_word(r->state, w1));
    }
    if (report_data_close(f, dir, "indicators.dat", err, errlen) != 0)
        goto out;

    /* alerts.dat: one line per alert row, oldest first */
    if (!(f = report_data_open(dir, "alerts.dat", err, errlen)))
        goto out;
    fprintf(f, "# alert_id time_s raised(1)/cleared(0) level kind\n");
    for (int k = n_al - 1; k >= 0; k--)
        fprintf(f, "%lld %.3f %d %s %s\n", (long long)al[k].id,
                (double)al[k].utime / 1e6, al[k].raised, dat_word(al[k].level, w1),
                dat_word(al[k].kind, w2));
    if (report_data_close(f, dir, "alerts.dat", err, errlen) != 0)
        goto out;

    /* histogram.dat: baseline sample (the b.n ok passages up to the
       baseline's time, else the first window) against the latest window */
    int win = n_ind > 0 && ind[0].row.n > 0 ? ind[0].row.n : 500;
    size_t nb_end = 0, nb = 0, nla = n_ok < (size_t)win ? n_ok : (size_t)win;
    if (found) {
        for (size_t k = 0, j = 0; k < n; k++)
            if (pv.v[k].status == 0 && !isnan(pv.v[k].gvw)) {
                j++;
                if (pv.v[k].t <= (double)b.utime_set / 1e6)
                    nb_end = j;
            }
        nb = nb_end < (size_t)b.n ? nb_end : (size_t)b.n;
    } else {
        nb_end = nb = nla;
    }
    bl = ok + (nb_end - nb);
    la = ok + (n_ok - nla);
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t k = 0; k < n_ok; k++) {
        lo = fmin(lo, ok[k]);
        hi = fmax(hi, ok[k]);
    }
    if (!(hi > lo)) {
        lo = 0;
        hi = 60;
    }
    int nbins = 30;
    double w = (hi - lo) / nbins, hb[64], hl[64];
    hist(bl, nb, lo, w, nbins, hb);
    hist(la, nla, lo, w * (1 + 1e-12), nbins, hl);
    if (!(f = report_data_open(dir, "histogram.dat", err, errlen)))
        goto out;
    fprintf(f, "# gvw_t_bin_centre baseline_fraction latest_fraction (bin %.3f t; baseline n %zu, latest n %zu)\n",
            w, nb, nla);
    for (int k = 0; k < nbins; k++)
        fprintf(f, "%.4f %.5f %.5f\n", lo + (k + 0.5) * w, hb[k], hl[k]);
    if (report_data_close(f, dir, "histogram.dat", err, errlen) != 0)
        goto out;

    /* hourly.dat: passages per hour by status, cumulative columns so the
       boxes stack; the bucket adapts to the span */
    static const double buckets[] = {60, 300, 900, 3600, 86400};
    double bw = 86400;
    for (int k = 0; k < 5; k++)
        if ((t1 - t0) / buckets[k] <= 200) {
            bw = buckets[k];
            break;
        }
    int nbk = (int)floor((t1 - t0) / bw) + 1;
    if (nbk > 100000)
        nbk = 100000;
    double *cnt = calloc((size_t)nbk * AMFI_STORE_N_STATUS, sizeof *cnt);
    if (!cnt) {
        fail(err, errlen, "out of memory");
        goto out;
    }
    double tb0 = floor(t0 / bw) * bw;
    for (size_t k = 0; k < n; k++) {
        int i = (int)floor((pv.v[k].t - tb0) / bw);
        if (i >= 0 && i < nbk)
            cnt[(size_t)i * AMFI_STORE_N_STATUS + (size_t)pv.v[k].status] += 3600.0 / bw;
    }
    if (!(f = report_data_open(dir, "hourly.dat", err, errlen))) {
        free(cnt);
        goto out;
    }
    fprintf(f, "# bucket_centre_s then per hour, cumulative: ok +gap +late +overload +multiple +invalid +error (bucket %.0f s)\n", bw);
    for (int i = 0; i < nbk; i++) {
        double c = 0;
        fprintf(f, "%.0f", tb0 + (i + 0.5) * bw);
        for (int k = 0; k < AMFI_STORE_N_STATUS; k++) {
            c += cnt[(size_t)i * AMFI_STORE_N_STATUS + (size_t)k];
            fprintf(f, " %.2f", c);
        }
        fputc('\n', f);
    }
    free(cnt);
    if (report_data_close(f, dir, "hourly.dat", err, errlen) != 0)
        goto out;

    /* speed.dat: 2 km/h bins */
    if (!(f = report_data_open(dir, "speed.dat", err, errlen)))
        goto out;
    fprintf(f, "# speed_kmh_bin_centre passages (bin 2 km/h)\n");
    qsort(sp, n_sp, sizeof *sp, cmp_d);
    for (size_t k = 0; k < n_sp;) {
        double b0 = floor(sp[k] / 2) * 2;
        size_t c = 0;
        while (k < n_sp && sp[k] < b0 + 2) {
            c++;
            k++;
        }
        fprintf(f, "%.1f %zu\n", b0 + 1, c);
    }
    if (n_sp == 0)
        fprintf(f, "NaN 0\n");
    if (report_data_close(f, dir, "speed.dat", err, errlen) != 0)
        goto out;

    /* speed_correction.dat: one line per UTC day with estimated speeds */
    {
        export_opts every = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
        speed_stats sall;
        if (speed_corrections(s, &every, &sall, &sdays, &n_sdays, err, errlen) != 0)
            goto out;
    }
    if (n_sdays > 0) {
        if (!(f = report_data_open(dir, "speed_correction.dat", err, errlen)))
            goto out;
        fprintf(f, "# day_utc_s n median_pct p5_pct p95_pct (c = speed used / detector's - 1)\n");
        for (size_t k = 0; k < n_sdays; k++)
            fprintf(f, "%.0f %zu %.4f %.4f %.4f\n", (double)sdays[k].day_utime / 1e6,
                    sdays[k].st.n, sdays[k].st.median, sdays[k].st.p5, sdays[k].st.p95);
        if (report_data_close(f, dir, "speed_correction.dat", err, errlen) != 0)
            goto out;
    }

    /* the script */
    if (!(f = report_data_open(dir, "plots.gp", err, errlen)))
        goto out;
    fprintf(f,
        "# written by amfi-report --plot; run from anywhere: gnuplot %s/data/plots.gp\n"
        "set terminal pngcairo size 960,540 font 'sans,10' noenhanced\n"
        "d = '%s/data/'\n"
        "o = '%s/'\n"
        "set grid\n"
        "set key outside right top box opaque\n"
        "set xdata time\nset timefmt '%%s'\nset format x \"%%H:%%M\\n%%d %%b\"\n"
        "set xlabel 'time (UTC, data time)'\n"
        "set xrange [%.3f:%.3f]\n",
        dir, gdir, gdir, t0 - 0.01 * (t1 - t0), t1 + 0.01 * (t1 - t0));
    /* 1: GVW over time */
    fprintf(f,
        "set output o.'gvw.png'\n"
        "set title \"Inferred gross vehicle weight per passage\\n%s\"\n"
        "set ylabel 'GVW (t)'\n"
        "%s"
        "plot d.'band.dat' using 1:2:3 with filledcurves fc rgb '#b0d0b0' fs transparent solid 0.5 title 'baseline mean +/- 2 STD', \\\n"
        "     d.'band.dat' using 1:4 with lines lw 2 lc rgb '#2ca02c' title 'baseline mean', \\\n"
        "     d.'passages.dat' using 1:($3==0?$2:NaN) with points pt 7 ps 0.4 lc rgb '#1f77b4' title 'ok', \\\n"
        "     d.'passages.dat' using 1:($3!=0?$2:NaN) with points pt 2 ps 0.6 lc rgb '#d62728' title 'not ok (solved)'\n"
        "unset label 99\nset autoscale y\n",
        sub,
        /* gnuplot refuses a plot without one valid point: a fixed range and a word */
        n_gvw ? "" : "set yrange [0:60]\nset label 99 'no passage with an inferred GVW in this store' at graph 0.5, graph 0.5 center\n");
    /* 2: trend, three panels with the alerts as vertical lines */
    fprintf(f, "set terminal pngcairo size 960,800\nset output o.'trend.png'\n"
               "unset arrow\n");
    for (int k = n_al - 1; k >= 0; k--)
        fprintf(f, "set arrow from %.3f, graph 0 to %.3f, graph 1 nohead lw 1.5 lc rgb '%s' dt %d\n",
                (double)al[k].utime / 1e6, (double)al[k].utime / 1e6,
                al[k].raised ? "#d62728" : "#2ca02c", al[k].raised ? 1 : 2);
    fprintf(f,
        "set multiplot layout 3,1 title \"Damage indicator trend (%s)\\n%d indicator rows, %d alerts: red solid = raised, green dashed = cleared\"\n"
        "unset title\nset format x ''\nunset xlabel\n"
        "set lmargin at screen 0.09\nset rmargin at screen 0.72\n"
        "set ylabel 'STD ratio (window / baseline)'\n"
        "plot d.'indicators.dat' using 1:2 with linespoints pt 7 ps 0.3 lc rgb '#1f77b4' title 'STD ratio', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'raise at >= %.4g', %.4g with lines dt 2 lc rgb '#2ca02c' title 'clear below %.4g', \\\n"
        "     NaN with lines lc rgb '#d62728' title 'alert raised', NaN with lines dt 2 lc rgb '#2ca02c' title 'alert cleared'\n"
        "set ylabel 'p-value (variance ratio)'\nset logscale y\nset format y '%%.0e'\n"
        "plot d.'indicators.dat' using 1:($3>0?$3:NaN) with linespoints pt 7 ps 0.3 lc rgb '#9467bd' title 'p (STD test)', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'raise at p <= %.4g'\n"
        "unset logscale y\nset format y '%%g'\n"
        "set format x \"%%H:%%M\\n%%d %%b\"\nset xlabel 'time (UTC, data time)'\n"
        "set ylabel 'mean ratio (window / baseline)'\n"
        "plot d.'indicators.dat' using 1:4 with linespoints pt 7 ps 0.3 lc rgb '#ff7f0e' title 'mean ratio', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'mean alert %.4g and 1/%.4g', %.4g with lines dt 1 lc rgb '#d62728' notitle\n"
        "unset multiplot\nunset arrow\nset lmargin\nset rmargin\nset terminal pngcairo size 960,540\n",
        sub, n_ind, n_al, ip->std_alert_ratio, ip->std_alert_ratio,
        ip->std_clear_ratio, ip->std_clear_ratio, ip->std_alert_p, ip->std_alert_p,
        ip->mean_alert_ratio, ip->mean_alert_ratio, ip->mean_alert_ratio,
        1.0 / ip->mean_alert_ratio);
    /* 3: histogram */
    fprintf(f,
        "set output o.'gvw_histogram.png'\n"
        "set xdata\nset format x '%%g'\nset autoscale x\n"
        "set title \"GVW distribution: baseline (%zu ok passages) against the latest window (%zu)\\n%s\"\n"
        "set xlabel 'GVW (t), bins of %.2f t'\nset ylabel 'fraction of passages'\n"
        "set style fill transparent solid 0.45 noborder\nset boxwidth %.4f\n"
        "plot d.'histogram.dat' using 1:2 with boxes lc rgb '#2ca02c' title 'baseline', \\\n"
        "     d.'histogram.dat' using 1:3 with boxes lc rgb '#d62728' title 'latest window'\n",
        nb, nla, sub, w, w);
    /* 4: passages per hour by status */
    fprintf(f,
        "set output o.'passages_per_hour.png'\n"
        "set xdata time\nset format x \"%%H:%%M\\n%%d %%b\"\nset xrange [%.3f:%.3f]\n"
        "set title \"Passages per hour by status (buckets of %.0f min)\\n%s\"\n"
        "set xlabel 'time (UTC, data time)'\nset ylabel 'passages per hour'\n"
        "set style fill solid 0.8 border lc rgb 'black'\nset boxwidth %.0f\nset yrange [0:*]\n"
        "plot ",
        tb0, tb0 + nbk * bw, bw / 60, sub, bw * 0.9);
    for (int k = AMFI_STORE_N_STATUS - 1; k >= 0; k--)
        fprintf(f, "d.'hourly.dat' using 1:%d with boxes lc rgb '%s' title '%s'%s", k + 2,
                status_colour[k], amfi_store_status_name(k), k ? ", \\\n     " : "\n");
    /* 5: speed */
    fprintf(f,
        "set output o.'speed.png'\n"
        "set xdata\nset format x '%%g'\nset autoscale x\nset yrange [0:*]\n"
        "set title \"Speed distribution (%zu passages with a speed)\\n%s\"\n"
        "set xlabel 'speed (km/h), bins of 2 km/h'\nset ylabel 'passages'\n"
        "set style fill solid 0.7 border lc rgb 'black'\nset boxwidth 1.8\n"
        "%s"
        "plot d.'speed.dat' using 1:2 with boxes lc rgb '#1f77b4' title 'passages'\n"
        "set output\n",
        n_sp, sub,
        n_sp ? "" : "set xrange [0:150]\nset yrange [0:1]\nset label 99 'no passage with a speed in this store' at graph 0.5, graph 0.5 center\n");
    /* 6: speed corrections per day, when there are any */
    if (n_sdays > 0)
        fprintf(f,
            "unset label 99\nset output o.'speed_correction.png'\n"
            "set xdata time\nset timefmt '%%s'\nset format x \"%%d %%b\\n%%Y\"\nset autoscale x\n"
            "set xrange [%.0f:%.0f]\nset xtics 86400\nset autoscale y\n"
            "set title \"Speed correction of the estimated passages per day (c = speed used / detector's - 1)\\n%s\"\n"
            "set xlabel 'day (UTC, data time)'\nset ylabel 'c (%%)'\n"
            "plot d.'speed_correction.dat' using 1:4:5 with filledcurves fc rgb '#aec7e8' fs transparent solid 0.5 title 'p5 .. p95', \\\n"
            "     d.'speed_correction.dat' using 1:3 with linespoints pt 7 ps 0.6 lw 2 lc rgb '#1f77b4' title 'daily median', \\\n"
            "     0 with lines dt 2 lc rgb 'black' notitle\n"
            "set output\nset xtics autofreq\n",
            (double)sdays[0].day_utime / 1e6 - 43200,
            (double)sdays[n_sdays - 1].day_utime / 1e6 + 43200, sub);
    /* 7-9: the scale indicator, the known-truck runs, the temperature,
     * when there are any (report_scale.c); 10: the natural frequency
     * (report_natfreq.c) */
    int more = 0, n_f1 = 0;
    if (report_scale_plots(s, dir, f, site, &more, err, errlen) != 0 ||
        natfreq_plot(s, dir, f, sub, &n_f1, err, errlen) != 0) {
        fclose(f);
        goto out;
    }
    if (report_data_close(f, dir, "plots.gp", err, errlen) != 0)
        goto out;
    f = NULL;
    if (run_gnuplot(dir, err, errlen) != 0)
        goto out;
    static const char *const png[][2] = {
        {"gvw.png", "inferred GVW per passage over time, baseline band"},
        {"trend.png", "indicator trend, thresholds, alerts raised and cleared"},
        {"gvw_histogram.png", "GVW histogram, baseline against the latest window"},
        {"passages_per_hour.png", "passages per hour by status"},
        {"speed.png", "speed distribution"},
        {"speed_correction.png", "daily median speed correction, p5 .. p95"}};
    for (int k = 0; k < (n_sdays > 0 ? 6 : 5); k++)
        if (listed(dir, png[k][0], png[k][1], err, errlen) != 0)
            goto out;
    static const char *const png2[][2] = {
        {"scale.png", "scale indicator: raw and temperature-compensated scale, CUSUM and threshold"},
        {"known_truck.png", "known-truck runs: ratio inferred / reference, raw and compensated"},
        {"temperature.png", "deck and air temperature"},
        {"natfreq.png", "natural frequency per passage, raw and temperature-compensated"}};
    more |= n_f1 ? 1 << 3 : 0;
    for (int k = 0; k < 4; k++)
        if ((more & (1 << k)) && listed(dir, png2[k][0], png2[k][1], err, errlen) != 0)
            goto out;
    rc = 0;
out:
    free(pv.v);
    free(ind);
    free(al);
    free(ok);
    free(sp);
    free(sdays);
    return rc;
}
