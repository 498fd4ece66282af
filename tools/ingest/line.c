/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * line.c: amfi-ingest's line protocol (docs/ingest.md, "The line
 * protocol"): one record per line, fields separated by blanks,
 *
 *   A <sensor-id> <utime_us> <rate_hz> <v1> <v2> ...       accelerations, m/s²
 *   V <utime_us> <speed_mps> <lane> <n_axles> <spacing_m> ... [id=N] [ref=KG]
 *
 * from a file, a TCP peer or a serial port. A line that does not parse or
 * whose values are out of range is counted and named (SOURCE:line N:
 * field), never fatal; comments (#) and empty lines are skipped. The time
 * stamps are the source's clock: ingest.line.offset_s is subtracted.
 *
 * Thread: amfi-ingest's main thread only.
 */
#define _DEFAULT_SOURCE /* cfmakeraw, CRTSCTS */
#include "ingest.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#define MAX_TOKENS (INGEST_MAX_VALUES + 8)

static int to_i64(const char *s, long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno)
        return -1;
    *out = v;
    return 0;
}

static int to_dbl(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno == ERANGE || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

static int split(char *line, char **tok, int max)
{
    int n = 0;
    char *save = NULL;
    for (char *t = strtok_r(line, " \t", &save); t; t = strtok_r(NULL, " \t", &save)) {
        if (n == max)
            return -1;
        tok[n++] = t;
    }
    return n;
}

static int bad(ingest *g, const char *where, const char *field, const char *what, const char *tok)
{
    char shown[48];
    snprintf(shown, sizeof shown, "%s", tok ? tok : "");
    for (char *p = shown; *p; p++)
        if ((unsigned char)*p < 0x20 || (unsigned char)*p == 0x7f)
            *p = '?';
    if (tok)
        ingest_note(g, BAD_LINE, where, field, "%s, got '%s'%s", what, shown,
                    strlen(tok) >= sizeof shown ? "..." : "");
    else
        ingest_note(g, BAD_LINE, where, field, "%s", what);
    return -1;
}

static int accel_line(ingest *g, char **tok, int n, const char *where)
{
    long long id, ut;
    double rate;
    if (n < 5)
        return bad(g, where, "A", "expected A <sensor-id> <utime_us> <rate_hz> <v1> ...", NULL);
    if (to_i64(tok[1], &id))
        return bad(g, where, "sensor-id", "not an integer", tok[1]);
    const int idx = id >= 0 && id <= 255 ? ingest_sensor_index(g, (int)id) : -1;
    if (idx < 0)
        return bad(g, where, "sensor-id", "not a sensor of sensors:", tok[1]);
    if (to_i64(tok[2], &ut) || ut <= 0)
        return bad(g, where, "utime_us", "not a positive integer (µs since 1970)", tok[2]);
    if (to_dbl(tok[3], &rate) || !(rate > 0))
        return bad(g, where, "rate_hz", "not a positive number", tok[3]);
    const int nv = n - 4;
    double *v = malloc(sizeof(double) * (size_t)nv);
    if (!v)
        return bad(g, where, "A", "out of memory", NULL);
    for (int k = 0; k < nv; k++)
        if (to_dbl(tok[4 + k], &v[k])) {
            char field[32];
            snprintf(field, sizeof field, "v%d", k + 1);
            free(v);
            return bad(g, where, field, "not a finite number", tok[4 + k]);
        }
    const double start = (double)ut - 1e6 * g->cfg->ingest.line_offset_s;
    int rc = ingest_samples(g, idx, start, rate, nv, v, where, BAD_LINE);
    free(v);
    return rc;
}

static int vehicle_line(ingest *g, char **tok, int n, const char *where)
{
    long long ut, lane, na, id = 0;
    double speed, ref = 0.0, sp[AMFI_MAX_AXLES];
    int have_id = 0;
    if (n < 5)
        return bad(g, where, "V",
                   "expected V <utime_us> <speed_mps> <lane> <n_axles> <spacing_m> ...", NULL);
    if (to_i64(tok[1], &ut) || ut <= 0)
        return bad(g, where, "utime_us", "not a positive integer (µs since 1970)", tok[1]);
    if (to_dbl(tok[2], &speed) || !(speed > 0 && speed <= 100))
        return bad(g, where, "speed_mps", "not a number in (0, 100]", tok[2]);
    if (to_i64(tok[3], &lane) || lane < 0 || lane > 32767)
        return bad(g, where, "lane", "not an integer in 0 .. 32767", tok[3]);
    if (to_i64(tok[4], &na) || na < 1 || na > AMFI_MAX_AXLES)
        return bad(g, where, "n_axles", "not an integer in 1 .. 12", tok[4]);
    int k = 5;
    for (int a = 0; a < na - 1; a++, k++) {
        char field[32];
        snprintf(field, sizeof field, "spacing_m[%d]", a + 1);
        if (k >= n || strchr(tok[k], '='))
            return bad(g, where, field, "missing: n_axles - 1 spacings expected", NULL);
        if (to_dbl(tok[k], &sp[a]) || !(sp[a] > 0 && sp[a] <= 100))
            return bad(g, where, field, "not a number in (0, 100] m", tok[k]);
    }
    for (; k < n; k++) {
        if (strncmp(tok[k], "id=", 3) == 0) {
            if (to_i64(tok[k] + 3, &id))
                return bad(g, where, "id", "not an integer", tok[k] + 3);
            have_id = 1;
        } else if (strncmp(tok[k], "ref=", 4) == 0) {
            if (to_dbl(tok[k] + 4, &ref) || !(ref == 0.0 || (ref >= 1000 && ref <= 100000)))
                return bad(g, where, "ref", "not 0 or a GVW in [1000, 100000] kg", tok[k] + 4);
        } else {
            return bad(g, where, "V", na - 1 == k - 5 ? "more fields than n_axles - 1 spacings"
                                                      : "unexpected field", tok[k]);
        }
    }
    const double ut_c = (double)ut - 1e6 * g->cfg->ingest.line_offset_s;
    if (!(ut_c > 0))
        return bad(g, where, "utime_us", "not positive once ingest.line.offset_s applied", tok[1]);
    amfi_vehicle_t m = {(int64_t)llround(ut_c), have_id ? id : (int64_t)ut, (int16_t)lane, speed,
                        (int16_t)na, (int16_t)(na - 1), sp, (char *)g->cfg->ingest.source, ref};
    return ingest_vehicle(g, &m, where);
}

int line_handle(ingest *g, char *line, const char *where)
{
    static char *tok[MAX_TOKENS];
    size_t len = strlen(line);
    if (len && line[len - 1] == '\r')
        line[--len] = '\0';
    const char *p = line + strspn(line, " \t");
    if (*p == '\0' || *p == '#')
        return 0;
    g->lines++;
    int n = split(line, tok, MAX_TOKENS);
    if (n < 0)
        return bad(g, where, "line", "more than 4096 values", NULL);
    if (strcmp(tok[0], "A") == 0)
        return accel_line(g, tok, n, where);
    if (strcmp(tok[0], "V") == 0)
        return vehicle_line(g, tok, n, where);
    return bad(g, where, "type", "neither A nor V", tok[0]);
}

double line_time_us(const char *line, double offset_s)
{
    char t;
    long long a, b;
    if (sscanf(line, " %c %lld %lld", &t, &a, &b) == 3 && t == 'A')
        return (double)b - 1e6 * offset_s;
    if (sscanf(line, " %c %lld", &t, &a) == 2 && t == 'V')
        return (double)a - 1e6 * offset_s;
    return 0.0;
}

static void handle_one(ingest *g, line_src *src, char *line, size_t n)
{
    char where[400];
    src->lineno++;
    snprintf(where, sizeof where, "%s:line %lld", src->name, src->lineno);
    if (memchr(line, '\0', n)) {
        g->lines++;
        bad(g, where, "line", "contains a NUL byte", NULL);
        return;
    }
    line[n] = '\0';
    line_handle(g, line, where);
}

void line_feed(ingest *g, line_src *src, const char *data, size_t n)
{
    for (size_t i = 0; i < n;) {
        const char *nl = memchr(data + i, '\n', n - i);
        const size_t take = nl ? (size_t)(nl - (data + i)) : n - i;
        if (src->skipping) {
            if (nl)
                src->skipping = 0;
        } else if (src->len + take > INGEST_MAX_LINE) {
            char where[400];
            src->lineno++;
            g->lines++;
            snprintf(where, sizeof where, "%s:line %lld", src->name, src->lineno);
            bad(g, where, "line", "longer than 65536 bytes: skipped", NULL);
            src->len = 0;
            src->skipping = !nl;
        } else {
            if (src->len + take + 1 > src->cap) {
                size_t cap = src->len + take + 1 + 4096;
                char *b = realloc(src->buf, cap);
                if (!b)
                    return;
                src->buf = b;
                src->cap = cap;
            }
            memcpy(src->buf + src->len, data + i, take);
            src->len += take;
            if (nl) {
                handle_one(g, src, src->buf, src->len);
                src->len = 0;
            }
        }
        i += take + (nl ? 1 : 0);
    }
}

void line_finish(ingest *g, line_src *src)
{
    if (src->len > 0 && !src->skipping)
        handle_one(g, src, src->buf, src->len);
    src->len = 0;
    free(src->buf);
    src->buf = NULL;
    src->cap = 0;
}

static speed_t baud_code(int baud)
{
    switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return B0;
    }
}

int serial_open(const char *dev, int baud, char *err, size_t errlen)
{
    const speed_t sp = baud_code(baud);
    if (sp == B0) {
        snprintf(err, errlen, "%s: %d baud is not supported", dev, baud);
        return -1;
    }
    int fd = open(dev, O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s: %s", dev, strerror(errno));
        return -1;
    }
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        snprintf(err, errlen, "%s: not a terminal (tcgetattr: %s)", dev, strerror(errno));
        close(fd);
        return -1;
    }
    cfmakeraw(&t); /* 8 data bits, no parity, no echo, no line editing */
    t.c_cflag &= ~(tcflag_t)(CSTOPB | CRTSCTS);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, sp) || cfsetospeed(&t, sp) || tcsetattr(fd, TCSANOW, &t) != 0) {
        snprintf(err, errlen, "%s: cannot set %d baud, 8N1, raw: %s", dev, baud, strerror(errno));
        close(fd);
        return -1;
    }
    tcflush(fd, TCIFLUSH);
    return fd;
}
