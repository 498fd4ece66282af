/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * notify.c: alert notices: alerts.command run for every raised and cleared
 * alert (amfid.yaml(5), section alerts; like smartd's -M exec), with the
 * alert in its environment, never blocking the pipeline: posix_spawn without
 * a shell, at most alerts.command_max_running at once, the rest queued (256,
 * beyond: dropped and counted), children reaped from the loop with waitpid
 * (WNOHANG), SIGTERM to the child's process group at
 * alerts.command_timeout_s and SIGKILL to the group 5 s later; every failure
 * (exit status, signal, timeout, spawn error) logged and counted. The child
 * inherits nothing of amfid's but stdout and stderr: descriptors 3 and up
 * closed (the bus's sockets and pipes), every signal at its default (amfid
 * ignores SIGPIPE), an empty mask, a process group of its own. At stop,
 * notify_finish gives the notices alerts.command_stop_wait_s, then kills.
 *
 * A module (ctx.h): its tick reaps, its final is notify_finish, its stop
 * notify_free.
 *
 * Thread: the main thread only (the pipeline raises alerts there; the loop
 * calls notify_tick). Owns the queued environments and the child table.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ctx.h"

#define NOTIFY_MAX_RUNNING 64 /* alerts.command_max_running's upper bound */
#define NOTIFY_QUEUE 256      /* notices waiting; beyond: dropped, counted */

#define KILL_AFTER_S 5.0 /* SIGKILL this long after SIGTERM */
#define STOP_KILL_AFTER_S 2.0 /* at stop: SIGKILL this long after SIGTERM */

struct notice {
    char *envp[16];
    char text[2048 + 1024]; /* the strings envp points into */
};

static struct notify_state {
    int pid[NOTIFY_MAX_RUNNING];        /* running children, 0: free slot */
    double started[NOTIFY_MAX_RUNNING]; /* amfi_mono_s() at spawn */
    int term_sent[NOTIFY_MAX_RUNNING];  /* SIGTERM sent (timed out, or amfid stopping) */
    int stopping;                       /* notify_finish gave up waiting: killed at stop */
    int running;
    struct notice *queue[NOTIFY_QUEUE];
    int qhead, queued;
    int64_t started_total, ok, failed, timeouts, dropped;
} N;

/* One environment string "NAME=value" appended to n; control characters
 * of the value (a message is free text) become spaces. */
static void put_env(struct notice *n, int *k, size_t *used, const char *name, const char *val)
{
    size_t cap = sizeof n->text - *used;
    int w = snprintf(n->text + *used, cap, "%s=%s", name, val ? val : "");
    if (w < 0 || (size_t)w >= cap || *k >= 15)
        return;
    char *s = n->text + *used;
    for (char *p = s + strlen(name) + 1; *p; p++)
        if ((unsigned char)*p < 0x20)
            *p = ' ';
    n->envp[(*k)++] = s;
    n->envp[*k] = NULL;
    *used += (size_t)w + 1;
}

#if !(defined(__GLIBC__) && __GLIBC_PREREQ(2, 34))
/* Without posix_spawn_file_actions_addclosefrom_np: every descriptor from 3
 * up marked close-on-exec in amfid itself (amfid execs nothing else). */
static void cloexec_from_3(void)
{
    long max = sysconf(_SC_OPEN_MAX);
    for (int fd = 3; fd < (max > 0 && max < 65536 ? max : 65536); fd++) {
        int fl = fcntl(fd, F_GETFD);
        if (fl >= 0 && !(fl & FD_CLOEXEC))
            fcntl(fd, F_SETFD, fl | FD_CLOEXEC);
    }
}
#endif

/* Signal a notice's whole process group (it is the group's leader, not
 * reaped yet or its group still holds the id: never another process). */
static void kill_group(pid_t pid, int sig)
{
    if (kill(-pid, sig) != 0 && errno != ESRCH)
        kill(pid, sig);
}

static int start_child(amfid_ctx *d, struct notice *n)
{
    struct notify_state *ns = &N;
    char *argv[] = {(char *)d->cfg->daemon.alert_command, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    sigset_t all, none;
    pid_t pid;
    int rc;

    sigfillset(&all);
    sigemptyset(&none);
    posix_spawn_file_actions_init(&fa);
    posix_spawnattr_init(&at);
    rc = posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
#if defined(__GLIBC__) && __GLIBC_PREREQ(2, 34)
    if (rc == 0)
        rc = posix_spawn_file_actions_addclosefrom_np(&fa, 3);
#else
    cloexec_from_3();
#endif
    if (rc == 0)
        rc = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK
                                               | POSIX_SPAWN_SETPGROUP);
    if (rc == 0)
        rc = posix_spawnattr_setsigdefault(&at, &all);
    if (rc == 0)
        rc = posix_spawnattr_setsigmask(&at, &none);
    if (rc == 0)
        rc = posix_spawnattr_setpgroup(&at, 0);
    if (rc == 0)
        rc = posix_spawn(&pid, argv[0], &fa, &at, argv, n->envp);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&at);
    if (rc != 0) {
        ns->failed++;
        LOG_ERR("alert notice: cannot run %s: %s", argv[0], strerror(rc));
        return -1;
    }
    for (int i = 0; i < NOTIFY_MAX_RUNNING; i++)
        if (ns->pid[i] == 0) {
            ns->pid[i] = pid;
            ns->started[i] = amfi_mono_s();
            ns->term_sent[i] = 0;
            ns->running++;
            ns->started_total++;
            return 0;
        }
    return 0; /* not reached: callers keep running < the table's size */
}

void notify_alert(amfid_ctx *d, int64_t utime, int64_t alert_id, const char *level,
                  const char *kind, const char *message, int64_t indicator_id, int raised)
{
    struct notify_state *ns = &N;
    if (!d->cfg->daemon.alert_command[0])
        return;
    struct notice *n = calloc(1, sizeof *n);
    if (!n) {
        ns->dropped++;
        LOG_ERR("alert notice: out of memory; %s %s not notified", kind,
                raised ? "raise" : "clear");
        return;
    }
    char num[32], iso[40];
    int k = 0;
    size_t used = 0;
    time_t sec = (time_t)(utime / 1000000);
    struct tm tm;
    gmtime_r(&sec, &tm);
    strftime(iso, sizeof iso, "%Y-%m-%dT%H:%M:%SZ", &tm);
    snprintf(num, sizeof num, "%lld", (long long)alert_id);
    put_env(n, &k, &used, "AMFI_ALERT_ID", num);
    put_env(n, &k, &used, "AMFI_ALERT_KIND", kind);
    put_env(n, &k, &used, "AMFI_ALERT_LEVEL", level);
    put_env(n, &k, &used, "AMFI_ALERT_RAISED", raised ? "1" : "0");
    put_env(n, &k, &used, "AMFI_ALERT_MESSAGE", message);
    snprintf(num, sizeof num, "%lld", (long long)utime);
    put_env(n, &k, &used, "AMFI_ALERT_UTIME", num);
    put_env(n, &k, &used, "AMFI_ALERT_TIME", iso);
    snprintf(num, sizeof num, "%lld", (long long)indicator_id);
    put_env(n, &k, &used, "AMFI_ALERT_INDICATOR_ID", num);
    put_env(n, &k, &used, "AMFI_SITE_ID", d->cfg->site.id);
    put_env(n, &k, &used, "AMFI_SITE_NAME", d->cfg->site.name);
    put_env(n, &k, &used, "AMFI_DB", d->cfg->daemon.db_path);
    const char *path = getenv("PATH");
    put_env(n, &k, &used, "PATH", path ? path : "/usr/sbin:/usr/bin:/sbin:/bin");
    if (ns->running < d->cfg->daemon.alert_max_running && ns->queued == 0) {
        start_child(d, n);
        free(n);
        return;
    }
    if (ns->queued >= NOTIFY_QUEUE) {
        ns->dropped++;
        LOG_ERR("alert notice: %d notices waiting; %s %s (alert %lld) dropped", NOTIFY_QUEUE,
                kind, raised ? "raise" : "clear", (long long)alert_id);
        free(n);
        return;
    }
    ns->queue[(ns->qhead + ns->queued) % NOTIFY_QUEUE] = n;
    ns->queued++;
}

/* A child ended: count and log how. */
static void ended(amfid_ctx *d, int i, int status)
{
    struct notify_state *ns = &N;
    const char *cmd = d->cfg->daemon.alert_command;
    if (ns->term_sent[i]) {
        ns->timeouts++;
        if (ns->stopping)
            LOG_ERR("alert notice: %s killed at stop after %.0f s "
                    "(alerts.command_stop_wait_s)", cmd, d->cfg->daemon.alert_stop_wait_s);
        else
            LOG_ERR("alert notice: %s killed after %.0f s (alerts.command_timeout_s)", cmd,
                    d->cfg->daemon.alert_timeout_s);
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        ns->ok++;
    } else {
        ns->failed++;
        if (WIFEXITED(status))
            LOG_ERR("alert notice: %s exited %d", cmd, WEXITSTATUS(status));
        else
            LOG_ERR("alert notice: %s ended by signal %d", cmd,
                    WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    }
    ns->pid[i] = 0;
    ns->running--;
}

static void notify_tick(amfid_ctx *d)
{
    struct notify_state *ns = &N;
    if (ns->running == 0 && ns->queued == 0)
        return;
    double now = amfi_mono_s();
    for (int i = 0; i < NOTIFY_MAX_RUNNING; i++) {
        if (ns->pid[i] == 0)
            continue;
        int status = 0;
        pid_t r = waitpid(ns->pid[i], &status, WNOHANG);
        if (r == ns->pid[i] || (r < 0 && errno == ECHILD)) {
            /* a notice killed at its timeout: what it started goes too,
             * had it caught or ignored the SIGTERM */
            if (ns->term_sent[i])
                kill_group(ns->pid[i], SIGKILL);
            ended(d, i, status);
            continue;
        }
        double age = now - ns->started[i];
        if (!ns->term_sent[i] && age > d->cfg->daemon.alert_timeout_s) {
            kill_group(ns->pid[i], SIGTERM);
            ns->term_sent[i] = 1;
        } else if (ns->term_sent[i] && age > d->cfg->daemon.alert_timeout_s + KILL_AFTER_S) {
            kill_group(ns->pid[i], SIGKILL);
        }
    }
    while (ns->queued > 0 && ns->running < d->cfg->daemon.alert_max_running) {
        struct notice *n = ns->queue[ns->qhead];
        ns->queue[ns->qhead] = NULL;
        ns->qhead = (ns->qhead + 1) % NOTIFY_QUEUE;
        ns->queued--;
        start_child(d, n);
        free(n);
    }
}

/* At stop: the notices running, and the queued ones as slots free up, get
 * alerts.command_stop_wait_s; then SIGTERM to every group still running,
 * SIGKILL STOP_KILL_AFTER_S later, and the notices never started are
 * dropped and counted. Bounded: stop_wait + STOP_KILL_AFTER_S + 1 s. */
static void notify_finish(amfid_ctx *d)
{
    struct notify_state *ns = &N;
    if (ns->running == 0 && ns->queued == 0)
        return;
    double wait = d->cfg->daemon.alert_stop_wait_s, t0 = amfi_mono_s();
    LOG_INFO("waiting for %d alert notice(s) (%d queued), at most %.0f s "
             "(alerts.command_stop_wait_s)", ns->running, ns->queued, wait);
    struct timespec ts = {0, 20000000};
    while ((ns->running > 0 || ns->queued > 0) && amfi_mono_s() - t0 < wait) {
        notify_tick(d);
        nanosleep(&ts, NULL);
    }
    if (ns->queued > 0) {
        LOG_ERR("alert notice: stopping: %d notice(s) not started, dropped", ns->queued);
        ns->dropped += ns->queued;
        for (; ns->queued > 0; ns->queued--) {
            free(ns->queue[ns->qhead]);
            ns->queue[ns->qhead] = NULL;
            ns->qhead = (ns->qhead + 1) % NOTIFY_QUEUE;
        }
    }
    if (ns->running == 0)
        return;
    LOG_ERR("alert notice: stopping: %d notice(s) still running after %.0f s "
            "(alerts.command_stop_wait_s), killed", ns->running, wait);
    ns->stopping = 1;
    for (int i = 0; i < NOTIFY_MAX_RUNNING; i++)
        if (ns->pid[i] > 0 && !ns->term_sent[i]) {
            kill_group(ns->pid[i], SIGTERM);
            ns->term_sent[i] = 1;
        }
    double t1 = amfi_mono_s();
    int killed = 0;
    while (ns->running > 0 && amfi_mono_s() - t1 < STOP_KILL_AFTER_S + 1.0) {
        if (!killed && amfi_mono_s() - t1 >= STOP_KILL_AFTER_S) {
            for (int i = 0; i < NOTIFY_MAX_RUNNING; i++)
                if (ns->pid[i] > 0)
                    kill_group(ns->pid[i], SIGKILL);
            killed = 1;
        }
        notify_tick(d);
        nanosleep(&ts, NULL);
    }
}

static void notify_free(amfid_ctx *d)
{
    (void)d;
    struct notify_state *ns = &N;
    for (; ns->queued > 0; ns->queued--) {
        free(ns->queue[ns->qhead]);
        ns->queue[ns->qhead] = NULL;
        ns->qhead = (ns->qhead + 1) % NOTIFY_QUEUE;
    }
    for (int i = 0; i < NOTIFY_MAX_RUNNING; i++)
        if (ns->pid[i] > 0) {
            kill_group(ns->pid[i], SIGKILL);
            waitpid(ns->pid[i], NULL, WNOHANG); /* never blocks: init reaps it */
            ns->pid[i] = 0;
        }
    ns->running = 0;
}

static int notify_start(amfid_ctx *d, char *err, size_t errlen)
{
    (void)d, (void)err, (void)errlen;
    memset(&N, 0, sizeof N);
    return 0;
}

static void notify_metrics(amfid_ctx *d, amfid_stats *s)
{
    (void)d;
    s->notices_ok = N.ok;
    s->notices_failed = N.failed;
    s->notices_timeouts = N.timeouts;
    s->notices_dropped = N.dropped;
    s->notices_running = N.running;
    s->notices_queued = N.queued;
}

const amfid_module notify_module = {
    .name = "notify",
    .start = notify_start,
    .tick = notify_tick,
    .metrics = notify_metrics,
    .final = notify_finish,
    .stop = notify_free,
};
