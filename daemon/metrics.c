/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * metrics.c: amfid's health in Prometheus' text exposition format (version
 * 0.0.4), written to metrics.textfile for node-exporter's textfile collector
 * (amfid.yaml(5), section metrics; docs/daemon.md, "Health metrics"):
 * passages by status, refused messages by input and reason, messages
 * received, queue depth, held and lost passages, solve times (a histogram
 * and the quantiles of the newest 1024), the newest indicator values, open
 * alerts by kind, notices, uptime and the build. The file is written whole
 * to a new temporary file in the same folder (mkostemp: never a file or
 * symlink already there), synced and renamed over the old one, so a reader
 * never sees half of it; a failed write is logged once
 * (until a write succeeds again) and counted.
 *
 * A module (ctx.h): on_passage counts, a timer (metrics.interval_s)
 * writes the file, final writes it once more; the other modules' counters
 * come through the context's collect (amfid_stats).
 *
 * Thread: the main thread only; the counters it reads are the main thread's.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ctx.h"

#define SOLVE_BUCKETS 12
#define SOLVE_RECENT 1024
#define OPEN_KINDS 16
static struct metrics_state {
    int64_t by_status[16];        /* stored passages per amfi_store_status_name(k) */
    int64_t solve_le[SOLVE_BUCKETS]; /* solves of at most bucket_s[i] s */
    int64_t solve_count;
    double solve_sum_s;
    double recent_s[SOLVE_RECENT]; /* the newest solve times, a ring */
    int recent_n, recent_at;
    int have_indicator;
    double std_ratio, p_value, mean_ratio; /* the newest evaluation */
    char open_kind[OPEN_KINDS][32];      /* alert kinds seen, and whether open */
    int open[OPEN_KINDS];
    double start_wall;            /* time(NULL) at start */
    int64_t write_errors;
    int failing;                  /* the last write failed (logged once) */
} MS;

/* Upper bounds of the solve-time histogram, s. */
static const double bucket_s[SOLVE_BUCKETS] = {0.002, 0.005, 0.01, 0.02, 0.05, 0.1,
                                               0.2,   0.5,   1.0,  2.0,  5.0,  10.0};

static void metrics_passage(amfid_ctx *d, const amfid_passage *p)
{
    (void)d;
    const char *status = p->j->status;
    const int solved = p->j->solved;
    const double solve_ms = p->j->solve_ms;
    struct metrics_state *m = &MS;
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        if (strcmp(status, amfi_store_status_name(k)) == 0)
            m->by_status[k]++;
    if (!solved || !(solve_ms >= 0))
        return;
    double s = 1e-3 * solve_ms;
    for (int i = 0; i < SOLVE_BUCKETS; i++)
        if (s <= bucket_s[i])
            m->solve_le[i]++;
    m->solve_count++;
    m->solve_sum_s += s;
    m->recent_s[m->recent_at] = s;
    m->recent_at = (m->recent_at + 1) % SOLVE_RECENT;
    if (m->recent_n < SOLVE_RECENT)
        m->recent_n++;
}

void metrics_indicator(double std_ratio, double p_value, double mean_ratio)
{
    struct metrics_state *m = &MS;
    m->have_indicator = 1;
    m->std_ratio = std_ratio;
    m->p_value = p_value;
    m->mean_ratio = mean_ratio;
}

void metrics_alert(const char *kind, int raised)
{
    struct metrics_state *m = &MS;
    for (int i = 0; i < OPEN_KINDS; i++) {
        if (!m->open_kind[i][0])
            snprintf(m->open_kind[i], sizeof m->open_kind[i], "%s", kind);
        if (strcmp(m->open_kind[i], kind) == 0) {
            m->open[i] = raised != 0;
            return;
        }
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A label value as the format wants it: \ " and newline escaped. */
static void put_label(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '\\' || *s == '"')
            fputc('\\', f), fputc(*s, f);
        else if (*s == '\n')
            fputs("\\n", f);
        else
            fputc(*s, f);
    }
}

static void head(FILE *f, const char *name, const char *type, const char *help)
{
    fprintf(f, "# HELP %s %s\n# TYPE %s %s\n", name, help, name, type);
}

/* The value of a sample line (after its name and labels), NaN spelt as
 * the format wants it. */
static void put_value(FILE *f, double v)
{
    if (isnan(v))
        fputs("NaN\n", f);
    else
        fprintf(f, "%.17g\n", v);
}

static void sample(FILE *f, const char *name, double v)
{
    fprintf(f, "%s ", name);
    put_value(f, v);
}

static void write_all(amfid_ctx *d, const amfid_stats *st, FILE *f)
{
    const struct metrics_state *m = &MS;
    head(f, "amfi_build_info", "gauge", "amfid's version and site (value 1).");
    fputs("amfi_build_info{version=\"", f);
    put_label(f, amfi_version());
    fputs("\",site=\"", f);
    put_label(f, d->cfg->site.id);
    fputs("\"} 1\n", f);
    head(f, "amfi_start_time_seconds", "gauge", "Start of this amfid, Unix time.");
    sample(f, "amfi_start_time_seconds", m->start_wall);
    head(f, "amfi_uptime_seconds", "gauge", "Seconds since this amfid started.");
    sample(f, "amfi_uptime_seconds", (double)time(NULL) - m->start_wall);
    head(f, "amfi_state", "gauge", "amfid's state (the status message's), 1 for the current one.");
    static const char *const states[] = {"starting", "running", "degraded", "draining"};
    for (int i = 0; i < 4; i++)
        fprintf(f, "amfi_state{state=\"%s\"} %d\n", states[i],
                d->state && strcmp(d->state, states[i]) == 0);

    head(f, "amfi_passages_total", "counter", "Passages stored since start, by status.");
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        fprintf(f, "amfi_passages_total{status=\"%s\"} %lld\n", amfi_store_status_name(k),
                (long long)m->by_status[k]);
    head(f, "amfi_passages_lost_total", "counter",
         "Passages not stored (held queue full, or the store refused at shutdown).");
    fprintf(f, "amfi_passages_lost_total %lld\n", (long long)st->passages_lost);
    head(f, "amfi_passages_held", "gauge", "Passages held because the store cannot write.");
    fprintf(f, "amfi_passages_held %d\n", st->passages_held);
    head(f, "amfi_queue_depth", "gauge", "Passages waiting for a solver thread.");
    fprintf(f, "amfi_queue_depth %d\n", st->queue_depth);

    head(f, "amfi_raw_windows_total", "counter",
         "Raw sample windows written since start (daemon.store.raw.keep), and passages linked "
         "to the window of their event.");
    fprintf(f, "amfi_raw_windows_total{kind=\"window\"} %lld\n", (long long)st->raw_windows);
    fprintf(f, "amfi_raw_windows_total{kind=\"link\"} %lld\n", (long long)st->raw_links);
    fprintf(f, "amfi_raw_windows_total{kind=\"failed\"} %lld\n", (long long)st->raw_failed);
    head(f, "amfi_raw_bytes_total", "counter",
         "Bytes of the raw windows written since start, compressed and as float64.");
    fprintf(f, "amfi_raw_bytes_total{form=\"compressed\"} %lld\n", (long long)st->raw_bytes);
    fprintf(f, "amfi_raw_bytes_total{form=\"float64\"} %lld\n", (long long)st->raw_bytes_in);
    head(f, "amfi_raw_deleted_total", "counter",
         "Raw sample windows deleted by retention since start, by rule.");
    fprintf(f, "amfi_raw_deleted_total{rule=\"age\"} %lld\n", (long long)st->raw_pruned_age);
    fprintf(f, "amfi_raw_deleted_total{rule=\"size\"} %lld\n", (long long)st->raw_pruned_size);
    head(f, "amfi_raw_deleted_bytes_total", "counter",
         "Compressed bytes of the raw windows deleted by retention since start.");
    fprintf(f, "amfi_raw_deleted_bytes_total %lld\n", (long long)st->raw_pruned_bytes);
    head(f, "amfi_raw_stored_windows", "gauge", "Raw sample windows in the store.");
    fprintf(f, "amfi_raw_stored_windows %lld\n", (long long)st->raw_kept_windows);
    head(f, "amfi_raw_stored_bytes", "gauge", "Compressed bytes of the raw windows in the store.");
    fprintf(f, "amfi_raw_stored_bytes %lld\n", (long long)st->raw_kept_bytes);

    head(f, "amfi_messages_received_total", "counter",
         "Bus messages the input channels handed to amfid.");
    fprintf(f, "amfi_messages_received_total %lld\n", (long long)st->messages_in);
    head(f, "amfi_messages_refused_total", "counter",
         "Bus messages refused, by input and reason.");
    static const char *const inputs[REJECT_NINPUTS] = {"accel", "vehicle", "truth",
                                                         "environment"};
    for (int i = 0; i < REJECT_NINPUTS; i++)
        for (int k = 0; k < REJECT_NREASONS; k++)
            if (st->refused[i][k] > 0)
                fprintf(f, "amfi_messages_refused_total{input=\"%s\",reason=\"%s\"} %lld\n",
                        inputs[i], reject_reason_name(k), (long long)st->refused[i][k]);
    head(f, "amfi_intake_bounded_total", "counter",
         "What the intake's bounds did (daemon.intake): waiting vehicles evicted from a full "
         "tracker, calibration references not taken, environment readings accepted but not "
         "stored, refusal summary rows lost.");
    fprintf(f, "amfi_intake_bounded_total{what=\"vehicles_evicted\"} %lld\n",
            (long long)st->vehicles_evicted);
    fprintf(f, "amfi_intake_bounded_total{what=\"references_refused\"} %lld\n",
            (long long)st->references_refused);
    fprintf(f, "amfi_intake_bounded_total{what=\"environment_thinned\"} %lld\n",
            (long long)st->env_thinned);
    fprintf(f, "amfi_intake_bounded_total{what=\"summaries_lost\"} %lld\n",
            (long long)st->summaries_lost);
    head(f, "amfi_datagrams_dropped_total", "counter",
         "UDP datagrams the kernel dropped on amfid's sockets.");
    fprintf(f, "amfi_datagrams_dropped_total %lld\n",
            (long long)(st->udp_drops > 0 ? st->udp_drops : 0));

    head(f, "amfi_solve_seconds", "histogram", "Wall time of the solves since start.");
    for (int i = 0; i < SOLVE_BUCKETS; i++)
        fprintf(f, "amfi_solve_seconds_bucket{le=\"%g\"} %lld\n", bucket_s[i],
                (long long)m->solve_le[i]);
    fprintf(f, "amfi_solve_seconds_bucket{le=\"+Inf\"} %lld\n", (long long)m->solve_count);
    fprintf(f, "amfi_solve_seconds_sum %.9g\n", m->solve_sum_s);
    fprintf(f, "amfi_solve_seconds_count %lld\n", (long long)m->solve_count);
    head(f, "amfi_solve_recent_seconds", "summary",
         "Quantiles of the newest 1024 solve times.");
    double q[SOLVE_RECENT];
    double sum = 0;
    for (int i = 0; i < m->recent_n; i++)
        sum += (q[i] = m->recent_s[i]);
    qsort(q, (size_t)m->recent_n, sizeof q[0], cmp_double);
    static const double qs[] = {0.5, 0.9, 0.99};
    for (int i = 0; i < 3; i++) {
        fprintf(f, "amfi_solve_recent_seconds{quantile=\"%g\"} ", qs[i]);
        put_value(f, m->recent_n ? q[(int)floor(qs[i] * (m->recent_n - 1) + 0.5)] : NAN);
    }
    fprintf(f, "amfi_solve_recent_seconds_sum %.9g\n", sum);
    fprintf(f, "amfi_solve_recent_seconds_count %d\n", m->recent_n);

    head(f, "amfi_indicator_std_ratio", "gauge",
         "Window STD over baseline STD at the newest evaluation (NaN: none yet).");
    sample(f, "amfi_indicator_std_ratio", m->have_indicator ? m->std_ratio : NAN);
    head(f, "amfi_indicator_p_value", "gauge",
         "Variance-ratio test p-value at the newest evaluation (NaN: none yet).");
    sample(f, "amfi_indicator_p_value", m->have_indicator ? m->p_value : NAN);
    head(f, "amfi_indicator_mean_ratio", "gauge",
         "Window mean over baseline mean at the newest evaluation (NaN: none yet).");
    sample(f, "amfi_indicator_mean_ratio", m->have_indicator ? m->mean_ratio : NAN);
    head(f, "amfi_scale", "gauge",
         "The scale indicator's newest block: temperature-compensated scale of the inferred "
         "GVW (NaN: none yet).");
    sample(f, "amfi_scale", st->last_scale);
    head(f, "amfi_scale_cusum", "gauge", "The scale indicator's CUSUM after the newest block.");
    sample(f, "amfi_scale_cusum", st->last_cusum);
    head(f, "amfi_scale_passages_total", "counter",
         "Solved passages since start by what the scale indicator did with them (fed, or "
         "skipped without a deck temperature).");
    fprintf(f, "amfi_scale_passages_total{use=\"fed\"} %lld\n", (long long)st->scale_fed);
    fprintf(f, "amfi_scale_passages_total{use=\"no_temperature\"} %lld\n",
            (long long)st->scale_no_temp);
    head(f, "amfi_alert_open", "gauge", "1 while an alert of this kind is raised.");
    for (int i = 0; i < OPEN_KINDS && m->open_kind[i][0]; i++) {
        fputs("amfi_alert_open{kind=\"", f);
        put_label(f, m->open_kind[i]);
        fprintf(f, "\"} %d\n", m->open[i]);
    }

    head(f, "amfi_notices_total", "counter", "Alert notices (alerts.command) by result.");
    fprintf(f, "amfi_notices_total{result=\"ok\"} %lld\n", (long long)st->notices_ok);
    fprintf(f, "amfi_notices_total{result=\"failed\"} %lld\n", (long long)st->notices_failed);
    fprintf(f, "amfi_notices_total{result=\"timeout\"} %lld\n",
            (long long)st->notices_timeouts);
    fprintf(f, "amfi_notices_total{result=\"dropped\"} %lld\n",
            (long long)st->notices_dropped);
    head(f, "amfi_notices_running", "gauge", "Alert notices running now.");
    fprintf(f, "amfi_notices_running %d\n", st->notices_running);
    head(f, "amfi_metrics_write_errors_total", "counter",
         "Failed writes of this file (the previous file stays).");
    fprintf(f, "amfi_metrics_write_errors_total %lld\n", (long long)m->write_errors);
}

static void write_file(amfid_ctx *d)
{
    struct metrics_state *m = &MS;
    const char *path = d->cfg->daemon.metrics_path;
    if (!path[0])
        return;
    /* A new file of a name nobody can guess, in the same folder (the
     * rename stays atomic): mkostemp opens it O_CREAT|O_EXCL, mode 0600, so a
     * file or symlink planted there is never followed nor truncated. */
    char tmp[sizeof d->cfg->daemon.metrics_path + 32];
    snprintf(tmp, sizeof tmp, "%s.tmp.XXXXXX", path);
    int fd = mkostemp(tmp, O_CLOEXEC);
    FILE *f = NULL;
    int e = 0; /* the first failure's errno */
    if (fd < 0) {
        e = errno ? errno : EIO;
    } else if (!(f = fdopen(fd, "w"))) {
        e = errno ? errno : EIO;
        close(fd);
        unlink(tmp);
    }
    if (f) {
        /* node-exporter runs as another user (prometheus); the unit's
         * UMask=0027 would hide the file from it */
        if (fchmod(fd, 0644) != 0)
            e = errno ? errno : EIO;
        amfid_stats st;
        d->collect(d, &st);
        write_all(d, &st, f);
        if ((fflush(f) != 0 || fsync(fileno(f)) != 0) && !e)
            e = errno ? errno : EIO;
        if (fclose(f) != 0 && !e)
            e = errno ? errno : EIO;
        if (!e && rename(tmp, path) != 0)
            e = errno ? errno : EIO;
    }
    if (!e) {
        if (m->failing)
            LOG_INFO("metrics: %s written again", path);
        m->failing = 0;
        return;
    }
    if (f)
        unlink(tmp);
    m->write_errors++;
    if (!m->failing)
        LOG_ERR("metrics: cannot write %s: %s (retried every %.0f s; logged once)", path,
                strerror(e), d->cfg->daemon.metrics_interval_s);
    m->failing = 1;
}

static int metrics_tick(amfid_ctx *d)
{
    write_file(d);
    return 0;
}

static int metrics_start(amfid_ctx *d, char *err, size_t errlen)
{
    (void)d, (void)err, (void)errlen;
    memset(&MS, 0, sizeof MS);
    return 0;
}

static int metrics_restore(amfid_ctx *d)
{
    MS.start_wall = (double)time(NULL);
    return timer_add(d->timers, &d->cfg->daemon.metrics_interval_s, metrics_tick) ? 1 : 0;
}

const amfid_module metrics_module = {
    .name = "metrics",
    .start = metrics_start,
    .restore = metrics_restore,
    .on_passage = metrics_passage,
    .final = write_file,
};
