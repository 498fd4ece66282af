/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_daemon_children.c: what amfid's files and children can be made to
 * do by someone else on the host.
 *  - metrics.textfile: a symlink planted where the temporary file used to
 *    be (FILE.tmp.PID, a name anyone could guess) to a 0600 file: the file
 *    is neither followed, truncated nor made 0644; the metrics file is
 *    written (0644, a regular file) and no temporary file is left.
 *  - alerts.command (tests/daemon/alert_probe.c as the command), run from a process
 *    that, as amfid does, ignores SIGPIPE, has a signal blocked and holds a
 *    pipe and two UDP sockets without close-on-exec (liblcm's): the command
 *    sees only descriptors 0, 1 and 2, no ignored and no blocked signal, and
 *    leads a process group of its own; at its timeout the grandchild it
 *    started (which ignores SIGTERM) is killed too; at stop notify_finish
 *    returns within alerts.command_stop_wait_s + 3 s though the command's
 *    timeout is 600 s, the notice never started dropped and counted.
 * The modules are driven through their interface (ctx.h) with a context
 * of the test's own.
 * usage: test_daemon_children PATH/TO/alert_probe
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "ctx.h"

static const char *probe;

typedef struct fixture {
    char dir[256];
    amfid_ctx *d;
    amfi_site_config *cfg;
} fixture;

/* The counters of the two modules under test (the context's collect). */
static void collect(amfid_ctx *c, amfid_stats *s)
{
    memset(s, 0, sizeof *s);
    notify_module.metrics(c, s);
}

static int no_publish(amfid_ctx *c, const char *ch, const void *data, size_t len)
{
    (void)c, (void)ch, (void)data, (void)len;
    return 0;
}

static amfid_stats counts(fixture *f)
{
    amfid_stats s;
    collect(f->d, &s);
    return s;
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    assert_non_null(f);
    snprintf(f->dir, sizeof f->dir, "%s/amfi_children.XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    assert_non_null(mkdtemp(f->dir));
    f->d = calloc(1, sizeof *f->d);
    f->cfg = calloc(1, sizeof *f->cfg);
    assert_non_null(f->d);
    assert_non_null(f->cfg);
    amfi_config_defaults(f->cfg);
    f->d->cfg = f->cfg;
    f->d->collect = collect;
    f->d->publish = no_publish;
    f->d->state = "running";
    snprintf(f->cfg->daemon.alert_command, sizeof f->cfg->daemon.alert_command, "%s", probe);
    snprintf(f->cfg->daemon.db_path, sizeof f->cfg->daemon.db_path, "%s/a.db", f->dir);
    f->cfg->daemon.alert_timeout_s = 30;
    f->cfg->daemon.alert_max_running = 4;
    f->cfg->daemon.alert_stop_wait_s = 10;
    f->cfg->daemon.metrics_interval_s = 15;
    char err[64];
    assert_int_equal(0, notify_module.start(f->d, err, sizeof err));
    assert_int_equal(0, metrics_module.start(f->d, err, sizeof err));
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    notify_module.stop(f->d);
    free(f->cfg);
    free(f->d);
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    if (system(cmd) != 0)
        fprintf(stderr, "cannot remove %s\n", f->dir);
    free(f);
    return 0;
}

static char *slurp(const char *path)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return NULL;
    static char buf[8192];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    buf[n] = '\0';
    fclose(fp);
    return buf;
}

/* ---- metrics.textfile ------------------------------------------------------ */

static void metrics_symlink_not_followed(void **state)
{
    fixture *f = *state;
    char victim[512], link[600], prom[512];
    snprintf(victim, sizeof victim, "%s/victim", f->dir);
    snprintf(prom, sizeof prom, "%s/amfid.prom", f->dir);
    snprintf(f->cfg->daemon.metrics_path, sizeof f->cfg->daemon.metrics_path, "%s", prom);
    FILE *v = fopen(victim, "w");
    assert_non_null(v);
    fputs("secret\n", v);
    assert_int_equal(0, fclose(v));
    assert_int_equal(0, chmod(victim, 0600));
    /* the name the temporary file had: FILE.tmp.PID */
    snprintf(link, sizeof link, "%s.tmp.%ld", prom, (long)getpid());
    assert_int_equal(0, symlink(victim, link));

    for (int k = 0; k < 2; k++) /* a first file, then one renamed over it */
        metrics_module.final(f->d); /* the forced write */
    struct stat st;
    assert_int_equal(0, stat(victim, &st));
    if ((st.st_mode & 07777) != 0600)
        fail_msg("the planted file was made %04o", (unsigned)(st.st_mode & 07777));
    assert_string_equal("secret\n", slurp(victim));
    assert_int_equal(0, lstat(link, &st));
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(0, lstat(prom, &st));
    assert_true(S_ISREG(st.st_mode));
    assert_int_equal(0644, st.st_mode & 07777);
    const char *m = slurp(prom);
    assert_non_null(m);
    assert_non_null(strstr(m, "\namfi_metrics_write_errors_total 0\n"));
    /* nothing else in the folder: no temporary file left */
    DIR *dir = opendir(f->dir);
    assert_non_null(dir);
    struct dirent *e;
    int n = 0;
    while ((e = readdir(dir)))
        if (e->d_name[0] != '.') {
            n++;
            if (strcmp(e->d_name, "victim") && strcmp(e->d_name, "amfid.prom")
                && strcmp(e->d_name, strrchr(link, '/') + 1))
                fail_msg("left in the folder: %s", e->d_name);
        }
    closedir(dir);
    assert_int_equal(3, n);
}

/* ---- alerts.command ------------------------------------------------------- */

/* Tick until no notice runs or waits, at most limit_s; the seconds taken. */
static double run_out(amfid_ctx *d, double limit_s)
{
    double t0 = amfi_mono_s();
    struct timespec ts = {0, 20000000};
    amfid_stats s;
    for (collect(d, &s); (s.notices_running > 0 || s.notices_queued > 0) &&
                         amfi_mono_s() - t0 < limit_s;
         collect(d, &s)) {
        notify_module.tick(d);
        nanosleep(&ts, NULL);
    }
    if (s.notices_running > 0 || s.notices_queued > 0)
        fail_msg("notices still running after %.0f s", limit_s);
    return amfi_mono_s() - t0;
}

/* The probe's report for alert id, waiting (10 s at most) for `want`. */
static const char *report(fixture *f, int id, const char *want)
{
    char path[sizeof f->cfg->daemon.db_path + 32];
    snprintf(path, sizeof path, "%s.probe.%d", f->cfg->daemon.db_path, id);
    for (int k = 0; k < 500; k++) {
        const char *r = slurp(path);
        if (r && strstr(r, want))
            return r;
        usleep(20000);
    }
    fail_msg("%s: no '%s' in it: %s", path, want, slurp(path) ? slurp(path) : "(missing)");
    return NULL;
}

static unsigned long long field_hex(const char *r, const char *key)
{
    const char *p = strstr(r, key);
    if (!p)
        fail_msg("no %s in the report: %s", key, r);
    return strtoull(p + strlen(key), NULL, 16);
}

/* Is pid gone (or a zombie nobody reaps yet)? Waits up to 5 s. */
static int gone(long pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%ld/stat", pid);
    for (int k = 0; k < 250; k++) {
        if (kill((pid_t)pid, 0) != 0 && errno == ESRCH)
            return 1;
        char *s = slurp(path), *rp = s ? strrchr(s, ')') : NULL;
        if (rp && (rp[2] == 'Z' || rp[2] == 'X'))
            return 1;
        usleep(20000);
    }
    return 0;
}

static long grandchild_of(fixture *f, int id)
{
    const char *r = report(f, id, "grandchild ");
    return strtol(strstr(r, "grandchild ") + 11, NULL, 10);
}

static void notify_inherits_nothing(void **state)
{
    fixture *f = *state;
    /* amfid's state when it spawns: SIGPIPE ignored, the bus's descriptors */
    struct sigaction ign = {.sa_handler = SIG_IGN}, old_pipe;
    sigaction(SIGPIPE, &ign, &old_pipe);
    sigset_t usr1, old_mask;
    sigemptyset(&usr1);
    sigaddset(&usr1, SIGUSR1);
    sigprocmask(SIG_BLOCK, &usr1, &old_mask);
    int p[2];
    assert_int_equal(0, pipe(p));
    int u1 = socket(AF_INET, SOCK_DGRAM, 0), u2 = socket(AF_INET, SOCK_DGRAM, 0);
    assert_true(u1 >= 0 && u2 >= 0);

    notify_alert(f->d, 1764547200000000LL, 1, "warning", "probe", "inherited?", 0, 1);
    run_out(f->d, 20);
    assert_int_equal(1, counts(f).notices_ok);
    const char *r = report(f, 1, "pgrp ");
    if (!strstr(r, "fds 0 1 2\n"))
        fail_msg("the alert command inherited descriptors: %s", r);
    /* signals 32 and 33 are glibc's own (below SIGRTMIN): posix_spawn leaves
     * them ignored, and the program's libc sets them up again */
    const unsigned long long glibc = 3ULL << 31;
    if ((field_hex(r, "sigign ") & ~glibc) != 0)
        fail_msg("the alert command starts with signals ignored (SIGPIPE is bit %d): %s",
                 SIGPIPE - 1, r);
    if (field_hex(r, "sigblk ") != 0)
        fail_msg("the alert command starts with signals blocked: %s", r);
    long pid = 0, pgrp = 0;
    assert_int_equal(2, sscanf(strstr(r, "pid "), "pid %ld pgrp %ld", &pid, &pgrp));
    if (pid != pgrp)
        fail_msg("the alert command is not its group's leader (pid %ld, group %ld)", pid, pgrp);

    close(p[0]);
    close(p[1]);
    close(u1);
    close(u2);
    sigprocmask(SIG_SETMASK, &old_mask, NULL);
    sigaction(SIGPIPE, &old_pipe, NULL);
}

static void notify_timeout_kills_the_group(void **state)
{
    fixture *f = *state;
    f->cfg->daemon.alert_timeout_s = 1;
    notify_alert(f->d, 1764547200000000LL, 2, "warning", "hang", "sleeps", 0, 1);
    long g = grandchild_of(f, 2);
    run_out(f->d, 20);
    assert_int_equal(1, counts(f).notices_timeouts);
    if (!gone(g)) {
        kill((pid_t)g, SIGKILL);
        fail_msg("the grandchild %ld outlived the alert command's timeout", g);
    }
}

static void on_alarm(int sig)
{
    (void)sig;
    static const char m[] = "FAIL: notify_finish still waiting after 30 s\n";
    if (write(2, m, sizeof m - 1) < 0)
        _exit(1);
    _exit(1);
}

static void notify_stop_is_bounded(void **state)
{
    fixture *f = *state;
    f->cfg->daemon.alert_timeout_s = 600;
    f->cfg->daemon.alert_stop_wait_s = 1;
    f->cfg->daemon.alert_max_running = 1;
    notify_alert(f->d, 1764547200000000LL, 3, "warning", "hang", "sleeps", 0, 1);
    notify_alert(f->d, 1764547200000000LL, 4, "warning", "probe", "waits its turn", 0, 1);
    assert_int_equal(1, counts(f).notices_running);
    assert_int_equal(1, counts(f).notices_queued);
    long g = grandchild_of(f, 3);
    signal(SIGALRM, on_alarm);
    alarm(30);
    double t0 = amfi_mono_s();
    notify_module.final(f->d); /* notify_finish */
    double took = amfi_mono_s() - t0;
    alarm(0);
    signal(SIGALRM, SIG_DFL);
    if (took > 1 + 2 + 1 + 0.5)
        fail_msg("notify_finish took %.1f s with command_stop_wait_s 1", took);
    amfid_stats s = counts(f);
    assert_int_equal(0, s.notices_running);
    assert_int_equal(0, s.notices_queued);
    assert_int_equal(1, s.notices_dropped);
    assert_int_equal(1, s.notices_timeouts);
    if (!gone(g)) {
        kill((pid_t)g, SIGKILL);
        fail_msg("the grandchild %ld outlived amfid's stop", g);
    }
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_daemon_children PATH/TO/alert_probe\n");
        return 2;
    }
    probe = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(metrics_symlink_not_followed, setup, teardown),
        cmocka_unit_test_setup_teardown(notify_inherits_nothing, setup, teardown),
        cmocka_unit_test_setup_teardown(notify_timeout_kills_the_group, setup, teardown),
        cmocka_unit_test_setup_teardown(notify_stop_is_bounded, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
