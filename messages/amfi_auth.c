/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_auth.c: signed amfi messages (amfi_auth.h, docs/messages.md): the
 * site key file, the producer's signer, the reader's verifier.
 */
#include "amfi_auth.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <sodium.h>

#define OFF_VERSION 4
#define OFF_PRODUCER 5
#define OFF_SEQ (OFF_PRODUCER + AMFI_AUTH_PRODUCER_BYTES)
#define OFF_MAC (OFF_SEQ + 8)

static void set_err(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

static int init_sodium(char *err, size_t errlen)
{
    if (sodium_init() < 0) {
        set_err(err, errlen, "libsodium cannot be initialised");
        return -1;
    }
    return 0;
}

static int hexval(int c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

int amfi_auth_key_load(const char *path, amfi_auth_key *key, char *err, size_t errlen)
{
    if (init_sodium(err, errlen))
        return -1;
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        set_err(err, errlen, "bus key %s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        set_err(err, errlen, "bus key %s: cannot stat: %s", path, strerror(errno));
        close(fd);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        set_err(err, errlen, "bus key %s: not a regular file", path);
        close(fd);
        return -1;
    }
    if (st.st_mode & 077) {
        set_err(err, errlen,
                "bus key %s: mode %04o lets group or others read it; refused "
                "(chmod 600 %s)",
                path, (unsigned)(st.st_mode & 07777), path);
        close(fd);
        return -1;
    }
    if (st.st_uid != geteuid() && st.st_uid != 0) {
        set_err(err, errlen,
                "bus key %s: owned by uid %u, neither the running user (uid %u) nor root; "
                "refused",
                path, (unsigned)st.st_uid, (unsigned)geteuid());
        close(fd);
        return -1;
    }
    unsigned char raw[200];
    size_t n = 0;
    for (;;) {
        ssize_t k = read(fd, raw + n, sizeof raw - n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k < 0) {
            set_err(err, errlen, "bus key %s: cannot read: %s", path, strerror(errno));
            close(fd);
            sodium_memzero(raw, sizeof raw);
            return -1;
        }
        if (k == 0 || (n += (size_t)k) == sizeof raw)
            break;
    }
    close(fd);
    int rc = -1;
    if (n == AMFI_AUTH_KEY_BYTES) {
        memcpy(key->k, raw, AMFI_AUTH_KEY_BYTES);
        rc = 0;
    } else {
        size_t m = n;
        if (m > 0 && raw[m - 1] == '\n')
            m--;
        if (m > 0 && raw[m - 1] == '\r')
            m--;
        if (m == 2 * AMFI_AUTH_KEY_BYTES) {
            rc = 0;
            for (size_t i = 0; i < AMFI_AUTH_KEY_BYTES && rc == 0; i++) {
                int hi = hexval(raw[2 * i]), lo = hexval(raw[2 * i + 1]);
                if (hi < 0 || lo < 0)
                    rc = -1;
                else
                    key->k[i] = (unsigned char)(hi * 16 + lo);
            }
        }
        if (rc != 0)
            set_err(err, errlen,
                    "bus key %s: %zu bytes: neither %d raw bytes nor %d hex digits (make one "
                    "with amfid --make-bus-key FILE)",
                    path, n, AMFI_AUTH_KEY_BYTES, 2 * AMFI_AUTH_KEY_BYTES);
    }
    sodium_memzero(raw, sizeof raw);
    if (rc != 0)
        sodium_memzero(key, sizeof *key);
    return rc;
}

int amfi_auth_key_make(const char *path, char *err, size_t errlen)
{
    if (init_sodium(err, errlen))
        return -1;
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
    if (fd < 0) {
        set_err(err, errlen, "bus key %s: cannot create: %s%s", path, strerror(errno),
                errno == EEXIST ? " (an existing key is never overwritten)" : "");
        return -1;
    }
    unsigned char k[AMFI_AUTH_KEY_BYTES];
    randombytes_buf(k, sizeof k);
    /* umask may have taken bits away, never added any; be exact anyway */
    int bad = fchmod(fd, 0600) != 0;
    size_t done = 0;
    while (!bad && done < sizeof k) {
        ssize_t w = write(fd, k + done, sizeof k - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            bad = 1;
        else
            done += (size_t)w;
    }
    sodium_memzero(k, sizeof k);
    if (bad || fsync(fd) != 0) {
        set_err(err, errlen, "bus key %s: cannot write: %s", path, strerror(errno));
        close(fd);
        unlink(path);
        return -1;
    }
    if (close(fd) != 0) {
        set_err(err, errlen, "bus key %s: cannot write: %s", path, strerror(errno));
        unlink(path);
        return -1;
    }
    return 0;
}

const char *amfi_auth_key_path(const char *option, const char *config, char *buf, size_t n,
                               const char **origin)
{
    const char *o = NULL;
    if (option && option[0]) {
        snprintf(buf, n, "%s", option);
        o = "option";
    } else if (config && config[0]) {
        snprintf(buf, n, "%s", config);
        o = "configuration";
    } else {
        const char *cd = getenv("CREDENTIALS_DIRECTORY");
        if (cd && cd[0]) {
            snprintf(buf, n, "%s/%s", cd, AMFI_AUTH_CREDENTIAL);
            if (access(buf, F_OK) == 0)
                o = "credential";
        }
    }
    if (origin)
        *origin = o;
    return o ? buf : NULL;
}

/* ---- signing ------------------------------------------------------------- */

static int producer_ok(const char *p)
{
    size_t n = strlen(p);
    if (n < 1 || n > AMFI_AUTH_PRODUCER_BYTES)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = p[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '.' || c == '_' || c == '-'))
            return 0;
    }
    return 1;
}

void amfi_auth_producer_name(char out[AMFI_AUTH_PRODUCER_BYTES + 1], const char *prefix,
                             const char *suffix)
{
    char tmp[256];
    snprintf(tmp, sizeof tmp, "%s%s", prefix ? prefix : "", suffix ? suffix : "");
    size_t k = 0;
    for (size_t i = 0; tmp[i] && k < AMFI_AUTH_PRODUCER_BYTES; i++) {
        char c = tmp[i];
        int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                 c == '.' || c == '_' || c == '-';
        out[k++] = ok ? c : '_';
    }
    if (k == 0)
        out[k++] = '_';
    out[k] = '\0';
}

int amfi_auth_signer_init(amfi_auth_signer *s, const amfi_auth_key *key, const char *producer,
                          char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    if (init_sodium(err, errlen))
        return -1;
    if (!producer || !producer_ok(producer)) {
        set_err(err, errlen, "producer id '%s': 1 .. %d characters of [A-Za-z0-9._-]",
                producer ? producer : "", AMFI_AUTH_PRODUCER_BYTES);
        return -1;
    }
    s->key = *key;
    memcpy(s->producer, producer, strlen(producer));
    pthread_mutex_init(&s->mu, NULL);
    return 0;
}

void amfi_auth_signer_free(amfi_auth_signer *s)
{
    if (!s)
        return;
    free(s->buf);
    pthread_mutex_destroy(&s->mu);
    sodium_memzero(s, sizeof *s);
}

static void put_be64(unsigned char *p, uint64_t v)
{
    for (int i = 7; i >= 0; i--) {
        p[i] = (unsigned char)(v & 0xff);
        v >>= 8;
    }
}

static uint64_t get_be64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v = (v << 8) | p[i];
    return v;
}

static void mac_of(const amfi_auth_key *key, const char *channel, const unsigned char *msg,
                   size_t len, const unsigned char *producer_and_seq, unsigned char *mac)
{
    crypto_auth_hmacsha512256_state st;
    crypto_auth_hmacsha512256_init(&st, key->k, AMFI_AUTH_KEY_BYTES);
    crypto_auth_hmacsha512256_update(&st, (const unsigned char *)channel, strlen(channel));
    const unsigned char sep = 0;
    crypto_auth_hmacsha512256_update(&st, &sep, 1);
    crypto_auth_hmacsha512256_update(&st, msg, len);
    crypto_auth_hmacsha512256_update(&st, producer_and_seq, AMFI_AUTH_PRODUCER_BYTES + 8);
    crypto_auth_hmacsha512256_final(&st, mac);
    sodium_memzero(&st, sizeof st);
}

static int64_t now_utime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

long amfi_auth_sign_into(amfi_auth_signer *s, const char *channel, const void *data, size_t len,
                         int64_t utime, unsigned char *out, size_t cap)
{
    if (cap < len || cap - len < AMFI_AUTH_TRAILER_BYTES || len > (size_t)LONG_MAX / 2)
        return -1;
    if (utime <= 0)
        utime = now_utime();
    if (out != data)
        memmove(out, data, len);
    unsigned char *t = out + len;
    pthread_mutex_lock(&s->mu);
    uint64_t seq = (uint64_t)utime > s->last_seq ? (uint64_t)utime : s->last_seq + 1;
    s->last_seq = seq;
    pthread_mutex_unlock(&s->mu);
    memcpy(t, AMFI_AUTH_MAGIC, 4);
    t[OFF_VERSION] = AMFI_AUTH_VERSION;
    memcpy(t + OFF_PRODUCER, s->producer, AMFI_AUTH_PRODUCER_BYTES);
    put_be64(t + OFF_SEQ, seq);
    mac_of(&s->key, channel, out, len, t + OFF_PRODUCER, t + OFF_MAC);
    return (long)(len + AMFI_AUTH_TRAILER_BYTES);
}

/* s->buf large enough for len + trailer; locked by the caller */
static unsigned char *room(amfi_auth_signer *s, size_t len)
{
    size_t need = len + AMFI_AUTH_TRAILER_BYTES;
    if (need > s->cap) {
        unsigned char *n = realloc(s->buf, need);
        if (!n)
            return NULL;
        s->buf = n;
        s->cap = need;
    }
    return s->buf;
}

int amfi_auth_publish(lcm_t *lcm, amfi_auth_signer *s, const char *channel, const void *data,
                      size_t len)
{
    if (!s)
        return lcm_publish(lcm, channel, data, (unsigned)len);
    /* a private buffer: the signer may be shared by threads */
    unsigned char stackbuf[2048];
    unsigned char *buf = len + AMFI_AUTH_TRAILER_BYTES <= sizeof stackbuf
                             ? stackbuf
                             : malloc(len + AMFI_AUTH_TRAILER_BYTES);
    if (!buf)
        return -1;
    long n = amfi_auth_sign_into(s, channel, data, len, 0, buf, len + AMFI_AUTH_TRAILER_BYTES);
    int rc = n < 0 ? -1 : lcm_publish(lcm, channel, buf, (unsigned)n);
    if (buf != stackbuf)
        free(buf);
    return rc;
}

int amfi_auth_log_write(lcm_eventlog_t *log, amfi_auth_signer *s, int64_t eventnum, int64_t ts,
                        const char *channel, const void *data, size_t len)
{
    lcm_eventlog_event_t ev = {eventnum, ts, (int32_t)strlen(channel), (int32_t)len,
                               (char *)channel, (void *)data};
    if (!s)
        return lcm_eventlog_write_event(log, &ev);
    pthread_mutex_lock(&s->mu);
    unsigned char *buf = room(s, len);
    pthread_mutex_unlock(&s->mu);
    if (!buf)
        return -1;
    long n = amfi_auth_sign_into(s, channel, data, len, 0, buf, s->cap);
    if (n < 0)
        return -1;
    ev.datalen = (int32_t)n;
    ev.data = buf;
    return lcm_eventlog_write_event(log, &ev);
}

size_t amfi_auth_bare_len(const void *buf, size_t len)
{
    const unsigned char *b = buf;
    if (len < AMFI_AUTH_TRAILER_BYTES)
        return len;
    const unsigned char *t = b + len - AMFI_AUTH_TRAILER_BYTES;
    if (memcmp(t, AMFI_AUTH_MAGIC, 4) != 0 || t[OFF_VERSION] != AMFI_AUTH_VERSION)
        return len;
    return len - AMFI_AUTH_TRAILER_BYTES;
}

/* ---- verifying ----------------------------------------------------------- */

static const char *const reason_names[AMFI_AUTH_NREASONS] = {
    [AMFI_AUTH_OK] = "ok",           [AMFI_AUTH_UNSIGNED] = "unsigned",
    [AMFI_AUTH_BAD_MAC] = "bad_mac", [AMFI_AUTH_REPLAY] = "replay",
    [AMFI_AUTH_SKEW] = "skew",       [AMFI_AUTH_PRODUCERS] = "producers",
};

const char *amfi_auth_reason_name(int reason)
{
    return reason >= 0 && reason < AMFI_AUTH_NREASONS ? reason_names[reason] : "unknown";
}

int amfi_auth_verifier_init(amfi_auth_verifier *v, const amfi_auth_key *key, double max_skew_s)
{
    memset(v, 0, sizeof *v);
    if (sodium_init() < 0)
        return -1;
    v->key = *key;
    v->max_skew_us = (int64_t)(max_skew_s * 1e6);
    return 0;
}

/* The producer id as printable text (it is authenticated before it is
 * printed, but print it safely anyway). */
static void producer_text(const unsigned char *id, char out[AMFI_AUTH_PRODUCER_BYTES + 1])
{
    int k = 0;
    for (int i = 0; i < AMFI_AUTH_PRODUCER_BYTES && id[i]; i++)
        out[k++] = (id[i] >= 0x21 && id[i] < 0x7f) ? (char)id[i] : '?';
    out[k] = '\0';
}

int amfi_auth_verify(amfi_auth_verifier *v, const char *channel, const void *buf, size_t len,
                     int64_t recv_utime, size_t *bare_len, char *why, size_t whylen)
{
    const unsigned char *b = buf;
    *bare_len = len;
    if (len < AMFI_AUTH_TRAILER_BYTES) {
        set_err(why, whylen, "unsigned: %zu bytes, shorter than the %d-byte trailer", len,
                AMFI_AUTH_TRAILER_BYTES);
        return AMFI_AUTH_UNSIGNED;
    }
    const size_t mlen = len - AMFI_AUTH_TRAILER_BYTES;
    const unsigned char *t = b + mlen;
    if (memcmp(t, AMFI_AUTH_MAGIC, 4) != 0) {
        set_err(why, whylen, "unsigned: no trailer (no \"AMFA\" at byte %zu of %zu)", mlen, len);
        return AMFI_AUTH_UNSIGNED;
    }
    if (t[OFF_VERSION] != AMFI_AUTH_VERSION) {
        set_err(why, whylen, "unsigned: trailer version %u, this reader knows %d",
                (unsigned)t[OFF_VERSION], AMFI_AUTH_VERSION);
        return AMFI_AUTH_UNSIGNED;
    }
    unsigned char mac[AMFI_AUTH_MAC_BYTES];
    mac_of(&v->key, channel, b, mlen, t + OFF_PRODUCER, mac);
    if (sodium_memcmp(mac, t + OFF_MAC, AMFI_AUTH_MAC_BYTES) != 0) {
        set_err(why, whylen, "bad_mac: the MAC does not match (another key, or altered)");
        return AMFI_AUTH_BAD_MAC;
    }
    char pname[AMFI_AUTH_PRODUCER_BYTES + 1];
    producer_text(t + OFF_PRODUCER, pname);
    const uint64_t seq = get_be64(t + OFF_SEQ);
    const int64_t dt = (int64_t)(seq > (uint64_t)INT64_MAX ? INT64_MAX : seq) - recv_utime;
    if (v->max_skew_us > 0 && (dt > v->max_skew_us || dt < -v->max_skew_us)) {
        set_err(why, whylen,
                "skew: producer %s sequence %llu is %+.3f s from the receive time (at most "
                "%.3f s)",
                pname, (unsigned long long)seq, 1e-6 * (double)dt, 1e-6 * (double)v->max_skew_us);
        return AMFI_AUTH_SKEW;
    }
    int slot = -1;
    for (int i = 0; i < v->n; i++)
        if (memcmp(v->p[i].id, t + OFF_PRODUCER, AMFI_AUTH_PRODUCER_BYTES) == 0) {
            slot = i;
            break;
        }
    if (slot >= 0 && seq <= v->p[slot].last_seq) {
        set_err(why, whylen,
                "replay: producer %s sequence %llu is not above its last accepted one %llu",
                pname, (unsigned long long)seq, (unsigned long long)v->p[slot].last_seq);
        return AMFI_AUTH_REPLAY;
    }
    if (slot < 0) {
        if (v->n < AMFI_AUTH_MAX_PRODUCERS) {
            slot = v->n++;
        } else {
            /* forget a producer whose last message is beyond the skew: any
             * replay of its messages is refused as skew anyway */
            for (int i = 0; i < v->n && slot < 0 && v->max_skew_us > 0; i++)
                if ((int64_t)v->p[i].last_seq < recv_utime - v->max_skew_us)
                    slot = i;
            if (slot < 0) {
                set_err(why, whylen,
                        "producers: producer %s is new and %d others sent within the skew",
                        pname, AMFI_AUTH_MAX_PRODUCERS);
                return AMFI_AUTH_PRODUCERS;
            }
        }
        memcpy(v->p[slot].id, t + OFF_PRODUCER, AMFI_AUTH_PRODUCER_BYTES);
    }
    v->p[slot].last_seq = seq;
    *bare_len = mlen;
    return AMFI_AUTH_OK;
}
