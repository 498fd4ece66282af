/* SPDX-License-Identifier: GPL-3.0-or-later */
/* notify_listen: stands in for systemd's notification socket in tests.
 * Binds a Unix datagram socket at PATH and prints every datagram received
 * (sd_notify's "READY=1", "WATCHDOG=1", ...) as one line with the seconds
 * since start, for SECONDS seconds; then exits 0. Single-threaded. */
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: notify_listen PATH SECONDS\n");
        return 2;
    }
    struct sockaddr_un a = {.sun_family = AF_UNIX};
    if (strlen(argv[1]) >= sizeof a.sun_path) {
        fprintf(stderr, "notify_listen: %s: path too long\n", argv[1]);
        return 2;
    }
    strcpy(a.sun_path, argv[1]);
    double secs = atof(argv[2]);
    int fd = socket(AF_UNIX, SOCK_DGRAM, 0);
    unlink(argv[1]);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        fprintf(stderr, "notify_listen: %s: %s\n", argv[1], strerror(errno));
        return 1;
    }
    double t0 = now_s();
    setvbuf(stdout, NULL, _IOLBF, 0);
    for (;;) {
        double left = secs - (now_s() - t0);
        if (left <= 0) break;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        if (poll(&p, 1, (int)(left * 1000) + 1) > 0) {
            char buf[4096];
            ssize_t n = recv(fd, buf, sizeof buf - 1, 0);
            if (n > 0) {
                buf[n] = 0;
                for (char *line = strtok(buf, "\n"); line; line = strtok(NULL, "\n"))
                    printf("%.3f %s\n", now_s() - t0, line);
            }
        }
    }
    close(fd);
    unlink(argv[1]);
    return 0;
}
