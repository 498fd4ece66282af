/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * log.c: amfid's log (log.h). A leaf: it calls nothing of amfid's.
 *
 * Thread: any (one fputs sequence per line; the solver threads do not log).
 */
#include <stdarg.h>
#include <stdio.h>

#include "log.h"

FILE *amfid_log_stream;

void amfid_log(const char *prefix, const char *fmt, ...)
{
    FILE *f = amfid_log_stream ? amfid_log_stream : stderr;
    va_list ap;
    va_start(ap, fmt);
    fputs(prefix, f);
    vfprintf(f, fmt, ap);
    fputc('\n', f);
    va_end(ap);
}

void amfid_error(char *last_error, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(last_error, n, fmt, ap);
    va_end(ap);
    LOG_WARN("%s", last_error);
}
