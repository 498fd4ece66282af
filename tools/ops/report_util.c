/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_util.c: amfi-report's shared helpers (report.h): the failure
 * message, statistics, UTC times and their parsing. Calls no other report
 * file.
 */
#define _GNU_SOURCE
#include "report.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int report_fail(report_ctx *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err, sizeof c->err, fmt, ap);
    va_end(ap);
    return -1;
}

/* ---- time ------------------------------------------------------------------ */

const char *report_utc_fmt(int64_t utime, const char *fmt, char buf[32])
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (!gmtime_r(&t, &tm) || strftime(buf, 32, fmt, &tm) == 0)
        snprintf(buf, 32, "%lld", (long long)utime);
    return buf;
}

const char *report_iso(int64_t utime, char buf[32])
{
    return report_utc_fmt(utime, "%Y-%m-%dT%H:%M:%SZ", buf);
}

const char *report_utc(long long utime, char buf[32])
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (!gmtime_r(&t, &tm) || strftime(buf, 32, "%Y-%m-%d %H:%M:%S", &tm) == 0)
        snprintf(buf, 32, "%lld us", utime);
    return buf;
}

const char *report_duration(double s, char buf[32])
{
    if (s < 120)
        snprintf(buf, 32, "%.0f s", s);
    else if (s < 7200)
        snprintf(buf, 32, "%.1f min", s / 60);
    else if (s < 172800)
        snprintf(buf, 32, "%.1f h", s / 3600);
    else
        snprintf(buf, 32, "%.1f days", s / 86400);
    return buf;
}

const char *report_num(double x, const char *fmt, char buf[32])
{
    if (isnan(x))
        return "-";
    snprintf(buf, 32, fmt, x);
    return buf;
}

/* n digits at *p into *v; 0, or -1 when fewer digits are there */
static int digits(const char **p, int n, int *v)
{
    *v = 0;
    for (int k = 0; k < n; k++, (*p)++) {
        if (**p < '0' || **p > '9')
            return -1;
        *v = *v * 10 + (**p - '0');
    }
    return 0;
}

#define WHY(...) (snprintf(why, whylen, __VA_ARGS__), -1)

int report_parse_time(const char *s, int end_of, int64_t *utime, char *why, size_t whylen)
{
    const char *p = s;
    int y, mo, d, h = 0, mi = 0, sec = 0, us = 0, prec = 0; /* prec: 0 day, 1 min, 2 s, 3 µs */
    if (digits(&p, 4, &y) || *p != '-')
        return WHY("no year YYYY- at its start");
    p++;
    if (digits(&p, 2, &mo) || *p != '-')
        return WHY("no month MM- after the year");
    p++;
    if (digits(&p, 2, &d))
        return WHY("no day DD after the month");
    if (*p == 'T' || *p == 't' || (*p == ' ' && p[1])) {
        p++;
        if (digits(&p, 2, &h) || *p != ':' || (p++, digits(&p, 2, &mi)))
            return WHY("no time HH:MM after '%c'", s[10]);
        prec = 1;
        if (*p == ':') {
            p++;
            if (digits(&p, 2, &sec))
                return WHY("no seconds SS after HH:MM:");
            prec = 2;
            if (*p == '.' || *p == ',') {
                int n = 0;
                for (p++; *p >= '0' && *p <= '9'; p++, n++)
                    if (n < 6)
                        us = us * 10 + (*p - '0');
                if (n == 0)
                    return WHY("no digits after the decimal mark");
                for (int k = n; k < 6; k++)
                    us *= 10;
                prec = 3;
            }
        }
    }
    /* UTC only: Z, or an offset of zero */
    if (*p == 'Z' || *p == 'z')
        p++;
    else if ((*p == '+' || *p == '-') && prec > 0) {
        const char *o = p++;
        int oh = 0, om = 0;
        int bad = digits(&p, 2, &oh);
        if (!bad && *p == ':')
            p++;
        if (bad || digits(&p, 2, &om))
            return WHY("'%s' is not a UTC offset", o);
        if (oh || om)
            return WHY("offset %.6s: only UTC times (Z or +00:00)", o);
    }
    if (*p)
        return WHY("unexpected '%.20s'", p);
    if (y < 1970 || y > 9999)
        return WHY("year %d is not in 1970 .. 9999", y);
    if (mo < 1 || mo > 12)
        return WHY("month %d is not in 1 .. 12", mo);
    static const int mdays[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    if (d < 1 || d > mdays[mo - 1] || (mo == 2 && d == 29 && !leap))
        return WHY("day %d is not in %04d-%02d", d, y, mo);
    if (h > 23)
        return WHY("hour %d is not in 0 .. 23", h);
    if (mi > 59)
        return WHY("minute %d is not in 0 .. 59", mi);
    if (sec > 59)
        return WHY("second %d is not in 0 .. 59", sec);
    struct tm tm;
    memset(&tm, 0, sizeof tm);
    tm.tm_year = y - 1900;
    tm.tm_mon = mo - 1;
    tm.tm_mday = d;
    tm.tm_hour = h;
    tm.tm_min = mi;
    tm.tm_sec = sec;
    time_t t = timegm(&tm);
    if (t == (time_t)-1)
        return WHY("not a time this system can represent");
    *utime = (int64_t)t * 1000000 + us;
    if (end_of) {
        static const int64_t span[3] = {INT64_C(86400000000), 60000000, 1000000};
        if (prec < 3)
            *utime += span[prec] - 1; /* the last µs of that day, minute or second */
    }
    return 0;
}

/* ---- statistics --------------------------------------------------------------- */

void report_mean_std(const double *v, size_t n, double *mean, double *std)
{
    double s = 0, q = 0;
    for (size_t k = 0; k < n; k++)
        s += v[k];
    *mean = n ? s / (double)n : NAN;
    for (size_t k = 0; k < n; k++)
        q += (v[k] - *mean) * (v[k] - *mean);
    *std = n > 1 ? sqrt(q / (double)(n - 1)) : NAN;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void report_sort(double *v, size_t n)
{
    if (n > 1)
        qsort(v, n, sizeof *v, cmp_double);
}

double report_percentile(const double *v, size_t n, double p)
{
    if (n == 0)
        return NAN;
    size_t k = (size_t)ceil(p / 100.0 * (double)n);
    return v[k > 0 ? k - 1 : 0];
}


double report_mass_val(int units, double kg)
{
    return units == AMFI_REPORT_UNITS_ENGINEERING ? kg / 1000.0 : kg;
}

const char *report_mass_unit(int units)
{
    return units == AMFI_REPORT_UNITS_ENGINEERING ? "t" : "kg";
}

const char *report_mass(int units, double kg, char buf[32])
{
    return report_num(report_mass_val(units, kg),
                      units == AMFI_REPORT_UNITS_ENGINEERING ? "%.2f" : "%.0f", buf);
}

double report_speed_val(int units, double mps)
{
    return units == AMFI_REPORT_UNITS_ENGINEERING ? mps * 3.6 : mps;
}

const char *report_speed_unit(int units)
{
    return units == AMFI_REPORT_UNITS_ENGINEERING ? "km/h" : "m/s";
}

const char *report_speed(int units, double mps, char buf[32])
{
    return report_num(report_speed_val(units, mps),
                      units == AMFI_REPORT_UNITS_ENGINEERING ? "%.1f" : "%.2f", buf);
}
