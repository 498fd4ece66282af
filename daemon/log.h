/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * log.h: amfid's log: lines on stderr with the <N> priority prefixes that
 * journald reads. log.c calls nothing of amfid's: every daemon file may
 * log without making a circle of calls (tests/common/call_graph.sh).
 */
#ifndef AMFID_LOG_H
#define AMFID_LOG_H

#include <stdio.h>
#include <systemd/sd-daemon.h>

void amfid_log(const char *prefix, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Where amfid_log writes: NULL (the default) is stderr; the fuzz target
 * points it at /dev/null so that only sanitizer reports reach stderr. */
extern FILE *amfid_log_stream;
#define LOG_INFO(...) amfid_log(SD_INFO "amfid: ", __VA_ARGS__)
#define LOG_WARN(...) amfid_log(SD_WARNING "amfid: ", __VA_ARGS__)
#define LOG_ERR(...) amfid_log(SD_ERR "amfid: ", __VA_ARGS__)

/* The error service: the formatted line into last_error (n bytes: the
 * status message's last_error) and the log as a warning. */
void amfid_error(char *last_error, size_t n, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#endif /* AMFID_LOG_H */
