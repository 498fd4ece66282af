/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bus.c: amfid's LCM bus: the URL it opens (for a udpm:// bus, LCM's
 * recv_buf_size option from daemon.recv_buf_bytes, checked against the
 * kernel's cap net.core.rmem_max with a warning that says what to set), and
 * the datagrams the kernel dropped on amfid's own UDP sockets, read from
 * /proc/net/udp (and udp6): the loss nobody else can see.
 *
 * Thread: the main thread only (start-up and the heartbeat). Owns nothing
 * but the URL it builds.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amfid.h"

#define LCM_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"

static long read_long(const char *path)
{
    FILE *f = fopen(path, "r");
    long v = -1;
    if (f) {
        if (fscanf(f, "%ld", &v) != 1)
            v = -1;
        fclose(f);
    }
    return v;
}

void bus_url(const amfi_daemon_config *dc, char *url, size_t n)
{
    snprintf(url, n, "%s", dc->lcm_url[0] ? dc->lcm_url : LCM_DEFAULT_URL);
    if (strncmp(url, "udpm://", 7) != 0 || dc->recv_buf_bytes <= 0)
        return;
    if (!strstr(url, "recv_buf_size=")) {
        size_t len = strlen(url);
        snprintf(url + len, n - len, "%crecv_buf_size=%d", strchr(url, '?') ? '&' : '?',
                 dc->recv_buf_bytes);
    }
    long cap = read_long("/proc/sys/net/core/rmem_max");
    if (cap > 0 && cap < dc->recv_buf_bytes)
        LOG_WARN("the kernel caps UDP receive buffers at %ld bytes (net.core.rmem_max), below "
                 "daemon.recv_buf_bytes %d: bursts may be dropped (counted as "
                 "datagrams_dropped); set 'sysctl -w net.core.rmem_max=%d' and keep it in "
                 "/etc/sysctl.d/",
                 cap, dc->recv_buf_bytes, dc->recv_buf_bytes);
}

/* Is inode one of this process's sockets? (a short list, read once a call) */
static int own_socket(const unsigned long *inodes, int n, unsigned long ino)
{
    for (int i = 0; i < n; i++)
        if (inodes[i] == ino)
            return 1;
    return 0;
}

int64_t bus_udp_drops(void)
{
    unsigned long inodes[64];
    int n = 0;
    DIR *dir = opendir("/proc/self/fd");
    if (!dir)
        return -1;
    struct dirent *e;
    char path[300], target[64];
    while ((e = readdir(dir)) != NULL && n < 64) {
        snprintf(path, sizeof path, "/proc/self/fd/%s", e->d_name);
        ssize_t k = readlink(path, target, sizeof target - 1);
        if (k <= 0)
            continue;
        target[k] = '\0';
        unsigned long ino;
        if (sscanf(target, "socket:[%lu]", &ino) == 1)
            inodes[n++] = ino;
    }
    closedir(dir);
    int64_t drops = 0;
    const char *tables[] = {"/proc/net/udp", "/proc/net/udp6"};
    for (int t = 0; t < 2; t++) {
        FILE *f = fopen(tables[t], "r");
        if (!f)
            continue;
        char line[512];
        if (!fgets(line, sizeof line, f)) { /* header */
            fclose(f);
            continue;
        }
        while (fgets(line, sizeof line, f)) {
            /* sl local rem st tx:rx tr:when retr uid timeout inode ref ptr drops */
            unsigned long ino = 0;
            long long dr = 0;
            if (sscanf(line, "%*s %*s %*s %*s %*s %*s %*s %*s %*s %lu %*s %*s %lld", &ino,
                       &dr) == 2 &&
                own_socket(inodes, n, ino))
                drops += dr;
        }
        fclose(f);
    }
    return drops;
}
