/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * alert_probe.c: an alerts.command that reports what it inherited from
 * amfid, for test_daemon_children.c. Writes $AMFI_DB.probe.$AMFI_ALERT_ID:
 *   fds N N N ...      its open descriptors (/proc/self/fd, less the one
 *                      reading the folder)
 *   sigign HEX         SigIgn of /proc/self/status
 *   sigblk HEX         SigBlk
 *   pid PID pgrp PGRP
 * With AMFI_ALERT_KIND=hang, or when the file $AMFI_DB.hang exists, it then
 * starts a grandchild, writes "grandchild PID" and both sleep 600 s (the
 * grandchild ignores SIGTERM: only a SIGKILL of the group ends it);
 * otherwise it exits 0.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void status_line(FILE *out, const char *key, const char *name)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, key, strlen(key)) == 0) {
            char *v = line + strlen(key);
            while (*v == ' ' || *v == '\t')
                v++;
            fprintf(out, "%s %s", name, v);
        }
    if (f)
        fclose(f);
}

int main(void)
{
    const char *db = getenv("AMFI_DB"), *id = getenv("AMFI_ALERT_ID");
    const char *kind = getenv("AMFI_ALERT_KIND");
    if (!db || !id || !kind)
        return 2;
    /* the descriptors first, before this program opens any */
    int fds[256], n = 0;
    DIR *dir = opendir("/proc/self/fd");
    if (!dir)
        return 3;
    struct dirent *e;
    while ((e = readdir(dir)) && n < 256)
        if (e->d_name[0] != '.' && atoi(e->d_name) != dirfd(dir))
            fds[n++] = atoi(e->d_name);
    closedir(dir);
    char path[4200];
    snprintf(path, sizeof path, "%s.probe.%s", db, id);
    FILE *out = fopen(path, "w");
    if (!out)
        return 4;
    fprintf(out, "fds");
    for (int k = 0; k < n; k++)
        fprintf(out, " %d", fds[k]);
    fprintf(out, "\n");
    status_line(out, "SigIgn:", "sigign");
    status_line(out, "SigBlk:", "sigblk");
    fprintf(out, "pid %ld pgrp %ld\n", (long)getpid(), (long)getpgrp());
    char hang[4200];
    snprintf(hang, sizeof hang, "%s.hang", db);
    if (strcmp(kind, "hang") != 0 && access(hang, F_OK) != 0)
        return fclose(out) == 0 ? 0 : 5;
    fflush(out);
    pid_t g = fork();
    if (g == 0) {
        signal(SIGTERM, SIG_IGN);
        sleep(600);
        _exit(0);
    }
    fprintf(out, "grandchild %ld\n", (long)g);
    fclose(out);
    sleep(600);
    return 0;
}
