/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_plot.c: amfi-report --plot DIR's gnuplot helpers (report_plot.h).
 * Reads the passages, indicators, alerts and baseline once through the
 * store's typed queries, writes plain data files and one gnuplot script
 * under DIR/data/ (the plots themselves are written by their subjects'
 * files), runs gnuplot (a program, found on PATH) on the script, and checks
 * each PNG appeared. Calls no other report file.
 */
#include "report_plot.h"

#include <errno.h>
#include <math.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>

extern char **environ;

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
    report_plot_frame *a = ctx;
    (void)id;
    if (a->n_pas == a->cap_pas) {
        size_t cap = a->cap_pas ? 2 * a->cap_pas : 4096;
        report_pas *v = realloc(a->pas, cap * sizeof *v);
        if (!v)
            return AMFI_ENOMEM;
        a->pas = v;
        a->cap_pas = cap;
    }
    report_pas *p = &a->pas[a->n_pas++];
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

int report_plot_listed(const report_plot_frame *p, const char *name, const char *what, char *err,
                       size_t errlen)
{
    char path[4096];
    struct stat stt;
    snprintf(path, sizeof path, "%s/%s", p->dir, name);
    if (stat(path, &stt) != 0 || stt.st_size < 100)
        return fail(err, errlen, "%s: gnuplot wrote no image (see %s/data/gnuplot.log)", path,
                    p->dir);
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

const char *report_dat_word(const char *s, char out[64])
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

void report_hist(const double *v, size_t n, double lo, double w, int nb, double *out)
{
    for (int k = 0; k < nb; k++)
        out[k] = 0;
    for (size_t k = 0; k < n; k++) {
        int b = (int)floor((v[k] - lo) / w);
        if (b >= 0 && b < nb)
            out[b] += 1.0 / (double)n;
    }
}

int report_plot_in_range(const report_plot_frame *p, int64_t utime)
{
    return utime >= p->from && utime <= p->to;
}

int report_plot_begin(report_plot_frame *p, amfi_store *s, const char *dir, const char *site_raw,
                      const amfi_indicator_params *ip, int64_t from, int64_t to, char *err,
                      size_t errlen)
{
    int64_t total_ind = 0, total_al = 0;
    char serr[512], path[4096], t0s[32], t1s[32];
    memset(p, 0, sizeof *p);
    p->s = s;
    p->dir = dir;
    p->ip = ip;
    p->from = from;
    p->to = to;
    gp_text(site_raw, p->site, sizeof p->site);
    if (gp_dir(dir, p->gdir, sizeof p->gdir, err, errlen) != 0)
        return -1;
    snprintf(path, sizeof path, "%s/data", dir);
    if (mkdir_p(dir) != 0 || mkdir_p(path) != 0)
        return fail(err, errlen, "%s: cannot create: %s", path, strerror(errno));
    if (amfi_store_each_passage(s, from, to, NULL, collect, p, serr,
                                sizeof serr) != 0
        || amfi_store_get_baseline(s, &p->b, &p->found, serr, sizeof serr) != 0
        || amfi_store_count(s, AMFI_STORE_INDICATORS, &total_ind, serr, sizeof serr) != 0
        || amfi_store_count(s, AMFI_STORE_ALERTS, &total_al, serr, sizeof serr) != 0)
        return fail(err, errlen, "%s", serr);
    if (total_ind > 0) {
        p->ind = malloc((size_t)total_ind * sizeof *p->ind);
        if (!p->ind || amfi_store_recent_indicators(s, (int)total_ind, p->ind, &p->n_ind, serr,
                                                    sizeof serr) != 0)
            return fail(err, errlen, "%s", p->ind ? serr : "out of memory");
    }
    if (total_al > 0) {
        p->al = malloc((size_t)total_al * sizeof *p->al);
        if (!p->al
            || amfi_store_recent_alerts(s, (int)total_al, p->al, &p->n_al, serr, sizeof serr) != 0)
            return fail(err, errlen, "%s", p->al ? serr : "out of memory");
    }
    int k = 0; /* the rows in the range, newest first still */
    for (int i = 0; i < p->n_ind; i++)
        if (report_plot_in_range(p, p->ind[i].row.utime))
            p->ind[k++] = p->ind[i];
    p->n_ind = k;
    k = 0;
    for (int i = 0; i < p->n_al; i++)
        if (report_plot_in_range(p, p->al[i].utime))
            p->al[k++] = p->al[i];
    p->n_al = k;
    size_t n = p->n_pas;
    double t0 = n ? p->pas[0].t : 0, t1 = n ? p->pas[n - 1].t : 1;
    if (p->n_ind > 0) { /* newest first */
        t0 = fmin(t0, (double)p->ind[p->n_ind - 1].row.utime / 1e6);
        t1 = fmax(t1, (double)p->ind[0].row.utime / 1e6);
    }
    if (t1 <= t0)
        t1 = t0 + 60;
    p->t0 = t0;
    p->t1 = t1;
    utc_min(t0, t0s);
    utc_min(t1, t1s);
    if (n)
        snprintf(p->sub, sizeof p->sub, "%s, %s .. %s UTC, %zu passages", p->site, t0s, t1s, n);
    else
        snprintf(p->sub, sizeof p->sub, "%s, no passages in the store", p->site);
    if (!(p->gp = report_data_open(dir, "plots.gp", err, errlen)))
        return -1;
    fprintf(p->gp,
        "# written by amfi-report --plot; run from anywhere: gnuplot %s/data/plots.gp\n"
        "set terminal pngcairo size 960,540 font 'sans,10' noenhanced\n"
        "d = '%s/data/'\n"
        "o = '%s/'\n"
        "set grid\n"
        "set key outside right top box opaque\n"
        "set xdata time\nset timefmt '%%s'\nset format x \"%%H:%%M\\n%%d %%b\"\n"
        "set xlabel 'time (UTC, data time)'\n"
        "set xrange [%.3f:%.3f]\n",
        dir, p->gdir, p->gdir, t0 - 0.01 * (t1 - t0), t1 + 0.01 * (t1 - t0));
    return 0;
}

int report_plot_run(report_plot_frame *p, char *err, size_t errlen)
{
    FILE *gp = p->gp;
    p->gp = NULL;
    if (report_data_close(gp, p->dir, "plots.gp", err, errlen) != 0)
        return -1;
    return run_gnuplot(p->dir, err, errlen);
}

void report_plot_free(report_plot_frame *p)
{
    if (p->gp)
        fclose(p->gp);
    p->gp = NULL;
    free(p->pas);
    free(p->ind);
    free(p->al);
    p->pas = NULL;
    p->ind = NULL;
    p->al = NULL;
}
