/* SPDX-License-Identifier: GPL-3.0-or-later */
/* web_time.c: amfi-web's times: ISO-8601 UTC or seconds since 1970 in,
 * ISO-8601 UTC with microseconds out (web.h). */
#define _DEFAULT_SOURCE /* timegm */
#include <ctype.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "web.h"

/* n digits at s into *v; 0 or −1 */
static int digits(const char *s, int n, int *v)
{
    int x = 0;
    for (int k = 0; k < n; k++) {
        if (!isdigit((unsigned char)s[k]))
            return -1;
        x = 10 * x + (s[k] - '0');
    }
    *v = x;
    return 0;
}

/* ".ffffff" (1 .. 6 digits) at *s: µs, *s moved past it */
static int fraction(const char **s, int64_t *us)
{
    *us = 0;
    if (**s != '.')
        return 0;
    (*s)++;
    int n = 0;
    int64_t scale = 100000;
    while (isdigit((unsigned char)**s)) {
        if (++n > 6)
            return -1;
        *us += (**s - '0') * scale;
        scale /= 10;
        (*s)++;
    }
    return n == 0 ? -1 : 0;
}

int web_parse_time(const char *s, int64_t *utime)
{
    if (!s || !*s || strlen(s) > 40)
        return -1;
    int64_t us = 0;
    if (!strchr(s, '-')) {
        /* seconds since 1970 */
        size_t nd = strspn(s, "0123456789");
        if (nd < 1 || nd > 12)
            return -1;
        int64_t sec = 0;
        for (size_t k = 0; k < nd; k++)
            sec = 10 * sec + (s[k] - '0');
        const char *p = s + nd;
        if (fraction(&p, &us) != 0 || *p)
            return -1;
        if (sec > AMFI_STORE_MAX_UTIME / 1000000)
            return -1;
        *utime = sec * 1000000 + us;
        return 0;
    }
    int y, mo, d, h = 0, mi = 0, se = 0;
    if (strlen(s) < 10 || digits(s, 4, &y) || s[4] != '-' || digits(s + 5, 2, &mo) || s[7] != '-'
        || digits(s + 8, 2, &d))
        return -1;
    const char *p = s + 10;
    if (*p == 'T' || *p == ' ') {
        if (digits(p + 1, 2, &h) || p[3] != ':' || digits(p + 4, 2, &mi))
            return -1;
        p += 6;
        if (*p == ':') {
            if (digits(p + 1, 2, &se))
                return -1;
            p += 3;
            if (fraction(&p, &us) != 0)
                return -1;
        }
        if (*p == 'Z')
            p++;
    }
    if (*p)
        return -1;
    if (y < 1970 || mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || se > 59)
        return -1;
    struct tm tm = {.tm_year = y - 1900, .tm_mon = mo - 1, .tm_mday = d, .tm_hour = h,
                    .tm_min = mi, .tm_sec = se};
    time_t t = timegm(&tm);
    if (t == (time_t)-1 || tm.tm_mday != d || tm.tm_mon != mo - 1) /* 2026-02-30 */
        return -1;
    *utime = (int64_t)t * 1000000 + us;
    return *utime <= AMFI_STORE_MAX_UTIME ? 0 : -1;
}

const char *web_format_time(int64_t utime, char *buf, size_t len)
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (utime < 0 || !gmtime_r(&t, &tm)) {
        snprintf(buf, len, "?");
        return buf;
    }
    char day[24];
    strftime(day, sizeof day, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(buf, len, "%s.%06dZ", day, (int)(utime % 1000000));
    return buf;
}

int64_t web_now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}
