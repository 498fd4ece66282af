/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi_msg_check.c: the raw-buffer checker of the amfi bus messages
 * (amfi_msg_check.h). Walks an LCM buffer field by field with the tables
 * generated from messages/ *.lcm (amfi_msg_fields.c) before lcm-gen's
 * decoder is allowed to see it. No allocation, no global state: any thread.
 */
#include "amfi_msg_check_impl.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const char *const reason_names[AMFI_MSG_NREASONS] = {
    [AMFI_MSG_OK] = "ok",
    [AMFI_MSG_FINGERPRINT] = "fingerprint",
    [AMFI_MSG_TRUNCATED] = "truncated",
    [AMFI_MSG_NEGATIVE_COUNT] = "negative_count",
    [AMFI_MSG_OVER_LIMIT] = "over_limit",
    [AMFI_MSG_BAD_STRING] = "bad_string",
    [AMFI_MSG_TRAILING] = "trailing",
    [AMFI_MSG_DECODE] = "decode",
};

const char *amfi_msg_reason_name(int reason)
{
    if (reason < 0 || reason >= AMFI_MSG_NREASONS)
        return "unknown";
    return reason_names[reason];
}

const char *amfi_msg_type_name(amfi_msg_type t)
{
    if ((int)t < 0 || t >= AMFI_MSG_NTYPES)
        return NULL;
    return amfi_msg_descs[t].name;
}

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static int refuse(int reason, char *why, size_t whylen, const char *fmt, ...)
{
    if (why && whylen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(why, whylen, fmt, ap);
        va_end(ap);
    }
    return reason;
}

/* Big-endian signed integer of `size` bytes (1, 2, 4, 8) at p. */
static int64_t read_be(const unsigned char *p, size_t size)
{
    uint64_t v = 0;
    for (size_t i = 0; i < size; i++)
        v = v << 8 | p[i];
    switch (size) {
    case 1: return (int8_t)(uint8_t)v;
    case 2: return (int16_t)(uint16_t)v;
    case 4: return (int32_t)(uint32_t)v;
    default: return (int64_t)v;
    }
}

static size_t kind_size(amfi_msg_kind k)
{
    switch (k) {
    case AMFI_MSG_F_INT8: case AMFI_MSG_F_BOOLEAN: case AMFI_MSG_F_BYTE: return 1;
    case AMFI_MSG_F_INT16: return 2;
    case AMFI_MSG_F_INT32: case AMFI_MSG_F_FLOAT: return 4;
    case AMFI_MSG_F_INT64: case AMFI_MSG_F_DOUBLE: return 8;
    case AMFI_MSG_F_STRING: return 0;
    }
    return 0;
}

/* Well-formed UTF-8 (Unicode 15, table 3-7: no overlong forms, no
 * surrogates, nothing above U+10FFFF). */
static int utf8_ok(const unsigned char *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        unsigned c = s[i];
        size_t k;
        unsigned lo = 0x80, hi = 0xBF;
        if (c < 0x80) { i++; continue; }
        else if (c >= 0xC2 && c <= 0xDF) k = 1;
        else if (c == 0xE0) { k = 2; lo = 0xA0; }
        else if (c >= 0xE1 && c <= 0xEC) k = 2;
        else if (c == 0xED) { k = 2; hi = 0x9F; }
        else if (c >= 0xEE && c <= 0xEF) k = 2;
        else if (c == 0xF0) { k = 3; lo = 0x90; }
        else if (c >= 0xF1 && c <= 0xF3) k = 3;
        else if (c == 0xF4) { k = 3; hi = 0x8F; }
        else return 0;
        if (n - i - 1 < k)
            return 0;
        if (s[i + 1] < lo || s[i + 1] > hi)
            return 0;
        for (size_t j = 2; j <= k; j++)
            if (s[i + j] < 0x80 || s[i + j] > 0xBF)
                return 0;
        i += k + 1;
    }
    return 1;
}

int amfi_msg_check(amfi_msg_type t, const void *buf, size_t len, char *why, size_t whylen)
{
    if ((int)t < 0 || t >= AMFI_MSG_NTYPES)
        return refuse(AMFI_MSG_FINGERPRINT, why, whylen, "message type %d unknown", (int)t);
    const amfi_msg_desc *d = &amfi_msg_descs[t];
    const unsigned char *b = buf;
    if (!b && len > 0)
        return refuse(AMFI_MSG_TRUNCATED, why, whylen, "%s: no buffer", d->name);
    if (len < 8)
        return refuse(AMFI_MSG_FINGERPRINT, why, whylen,
                      "%s: %zu bytes, shorter than the 8-byte fingerprint", d->name, len);
    int64_t fp = read_be(b, 8), want = d->hash();
    if (fp != want)
        return refuse(AMFI_MSG_FINGERPRINT, why, whylen,
                      "%s: fingerprint 0x%016" PRIx64 ", not the type's 0x%016" PRIx64, d->name,
                      (uint64_t)fp, (uint64_t)want);
    size_t pos = 8;
    int64_t value[AMFI_MSG_MAX_FIELDS]; /* integer fields' values: later arrays' counts */
    for (int f = 0; f < d->n_fields; f++) {
        const amfi_msg_field *fl = &d->fields[f];
        int64_t count = 1;
        if (fl->dim_field >= 0) {
            count = value[fl->dim_field];
            if (count < 0)
                return refuse(AMFI_MSG_NEGATIVE_COUNT, why, whylen,
                              "%s.%s: count %s = %" PRId64 " is negative", d->name, fl->name,
                              d->fields[fl->dim_field].name, count);
            if (count > fl->count_max)
                return refuse(AMFI_MSG_OVER_LIMIT, why, whylen,
                              "%s.%s: count %s = %" PRId64 " is over the limit %ld", d->name,
                              fl->name, d->fields[fl->dim_field].name, count, fl->count_max);
        } else if (fl->dim_const > 0) {
            count = fl->dim_const;
        }
        if (fl->kind != AMFI_MSG_F_STRING) {
            size_t size = kind_size(fl->kind);
            if ((uint64_t)count > (len - pos) / size)
                return refuse(AMFI_MSG_TRUNCATED, why, whylen,
                              "%s.%s: %" PRId64 " x %zu bytes at byte %zu, past the end (%zu bytes)",
                              d->name, fl->name, count, size, pos, len);
            value[f] = (fl->kind <= AMFI_MSG_F_INT64 && fl->dim_field < 0 && fl->dim_const == 0)
                           ? read_be(b + pos, size)
                           : 0;
            pos += (size_t)count * size;
            continue;
        }
        value[f] = 0;
        for (int64_t i = 0; i < count; i++) {
            if (len - pos < 4)
                return refuse(AMFI_MSG_TRUNCATED, why, whylen,
                              "%s.%s: string length at byte %zu, past the end (%zu bytes)",
                              d->name, fl->name, pos, len);
            int64_t slen = read_be(b + pos, 4);
            if (slen < 0)
                return refuse(AMFI_MSG_NEGATIVE_COUNT, why, whylen,
                              "%s.%s: string length %" PRId64 " at byte %zu is negative", d->name,
                              fl->name, slen, pos);
            if (slen == 0)
                return refuse(AMFI_MSG_BAD_STRING, why, whylen,
                              "%s.%s: string length 0 at byte %zu (it counts the NUL)", d->name,
                              fl->name, pos);
            if (slen - 1 > fl->string_max)
                return refuse(AMFI_MSG_OVER_LIMIT, why, whylen,
                              "%s.%s: string of %" PRId64 " bytes at byte %zu is over the limit %ld",
                              d->name, fl->name, slen - 1, pos, fl->string_max);
            pos += 4;
            if ((uint64_t)slen > len - pos)
                return refuse(AMFI_MSG_TRUNCATED, why, whylen,
                              "%s.%s: string of %" PRId64 " bytes at byte %zu, past the end (%zu bytes)",
                              d->name, fl->name, slen, pos, len);
            const unsigned char *s = b + pos;
            size_t n = (size_t)slen - 1;
            if (s[n] != 0)
                return refuse(AMFI_MSG_BAD_STRING, why, whylen,
                              "%s.%s: string at byte %zu not NUL-terminated", d->name, fl->name, pos);
            const void *nul = memchr(s, 0, n);
            if (nul)
                return refuse(AMFI_MSG_BAD_STRING, why, whylen,
                              "%s.%s: string at byte %zu has a NUL at byte %zu", d->name, fl->name,
                              pos, pos + (size_t)((const unsigned char *)nul - s));
            if (!utf8_ok(s, n))
                return refuse(AMFI_MSG_BAD_STRING, why, whylen,
                              "%s.%s: string at byte %zu is not UTF-8", d->name, fl->name, pos);
            pos += (size_t)slen;
        }
    }
    if (pos != len)
        return refuse(AMFI_MSG_TRAILING, why, whylen, "%s: %zu bytes after the last field (byte %zu)",
                      d->name, len - pos, pos);
    return AMFI_MSG_OK;
}

int amfi_msg_decode_checked(amfi_msg_type t, const void *buf, size_t len, void *msg, char *why,
                            size_t whylen)
{
    int r = amfi_msg_check(t, buf, len, why, whylen);
    if (r != AMFI_MSG_OK) {
        if ((int)t >= 0 && t < AMFI_MSG_NTYPES)
            memset(msg, 0, amfi_msg_descs[t].size);
        return r;
    }
    const amfi_msg_desc *d = &amfi_msg_descs[t];
    memset(msg, 0, d->size);
    /* The checker bounds len: at most the fields' limits, far below INT_MAX. */
    if (len > (size_t)INT32_MAX || d->decode(buf, (int)len, msg) != (int)len) {
        d->cleanup(msg);
        memset(msg, 0, d->size);
        return refuse(AMFI_MSG_DECODE, why, whylen, "%s: lcm decode refused %zu checked bytes",
                      d->name, len);
    }
    return AMFI_MSG_OK;
}
