/* SPDX-License-Identifier: GPL-3.0-or-later */
/* test_msg_check: the raw-buffer checker of the amfi bus messages
 * (messages/amfi_msg_check.h). Random valid messages of every type, encoded by
 * lcm-gen's encoder, are accepted and consume exactly their encoded size (a
 * field the checker did not know would make it refuse or read too little);
 * the 56-byte vehicle_t with a negative string length of issue 9, negative and
 * over-limit counts, every truncation, a wrong fingerprint, trailing bytes and
 * bad strings are refused with the right reason, and amfi_msg_decode_checked()
 * allocates nothing for a refused buffer (malloc is wrapped: -Wl,--wrap=malloc).
 *
 *   test_msg_check                 the cmocka tests
 *   test_msg_check --corpus DIR    write the seed corpus of the message fuzz
 *                                  targets, DIR/msg_TYPE/NAME (fuzz/make_corpus.sh)
 */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "amfi_msg_check.h"

/* --- malloc, counted while armed (the link wraps every malloc call of the
 * objects linked in, lcm-gen's decoders included) --- */
void *__real_malloc(size_t n);
void *__wrap_malloc(size_t n);
static int malloc_armed;
static long malloc_calls;
void *__wrap_malloc(size_t n)
{
    if (malloc_armed)
        malloc_calls++;
    return __real_malloc(n);
}

/* --- random valid messages --- */
static uint64_t rng_state = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
static int rnd_int(int lo, int hi) { return lo + (int)(rnd() % (uint64_t)(hi - lo + 1)); }
static double rnd_double(void)
{
    uint64_t bits = rnd();
    double d;
    memcpy(&d, &bits, sizeof d); /* any bit pattern, NaN and infinities included */
    return d;
}

/* A random valid UTF-8 string of at most max bytes (ASCII, 2-, 3- and 4-byte
 * sequences), sometimes empty, sometimes exactly max bytes long. */
static int big_strings; /* set: every string exactly its limit */
static char *rnd_string(long max)
{
    long target = big_strings || rnd() % 4 == 0 ? max : (long)(rnd() % (uint64_t)(max + 1));
    char *s = malloc((size_t)max + 1);
    long n = 0;
    static const char *const pieces[] = {"a", "Z", "_", " ", "\xc2\xb5", "\xc2\xb2", "\xe2\x82\xac",
                                         "\xf0\x9f\x9a\x9b"};
    while (n < target) {
        const char *p = pieces[rnd() % 8];
        long k = (long)strlen(p);
        if (n + k > target)
            p = "x", k = 1;
        memcpy(s + n, p, (size_t)k);
        n += k;
    }
    s[n] = 0;
    return s;
}
static double *rnd_doubles(int n)
{
    double *v = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    for (int i = 0; i < n; i++)
        v[i] = rnd_double();
    return v;
}

/* One encoded message: bytes, length. */
typedef struct {
    unsigned char *buf;
    size_t len;
} enc;

#define ENCODE(TYPE, m)                                                                       \
    do {                                                                                      \
        int sz_ = amfi_##TYPE##_encoded_size(&(m));                                           \
        e.buf = malloc((size_t)sz_);                                                          \
        assert_int_equal(amfi_##TYPE##_encode(e.buf, 0, sz_, &(m)), sz_);                     \
        e.len = (size_t)sz_;                                                                  \
    } while (0)

/* A random valid message of type t with lcm-gen's encoder. `big` makes every
 * count and string its limit. */
static enc random_message(amfi_msg_type t, int big)
{
    enc e = {0};
    big_strings = big;
    switch (t) {
    case AMFI_MSG_ACCEL_BLOCK_T: {
        amfi_accel_block_t m = {(int64_t)rnd(), (int32_t)rnd(), (int64_t)rnd(), rnd_double(), 0,
                                NULL};
        m.n = (int16_t)(big ? AMFI_MSG_MAX_ACCEL_BLOCK_N : rnd_int(0, AMFI_MSG_MAX_ACCEL_BLOCK_N));
        m.accel = rnd_doubles(m.n);
        ENCODE(accel_block_t, m);
        free(m.accel);
        break;
    }
    case AMFI_MSG_VEHICLE_T: {
        amfi_vehicle_t m = {(int64_t)rnd(), (int64_t)rnd(), (int16_t)rnd(), rnd_double(),
                            (int16_t)rnd(), 0, NULL, NULL, rnd_double()};
        m.n_spacings = (int16_t)(big ? AMFI_MSG_MAX_VEHICLE_N_SPACINGS
                                     : rnd_int(0, AMFI_MSG_MAX_VEHICLE_N_SPACINGS));
        m.axle_spacing_m = rnd_doubles(m.n_spacings);
        m.source = rnd_string(AMFI_MSG_MAX_VEHICLE_SOURCE);
        ENCODE(vehicle_t, m);
        free(m.axle_spacing_m);
        free(m.source);
        break;
    }
    case AMFI_MSG_TRUTH_T: {
        amfi_truth_t m = {(int64_t)rnd(), (int64_t)rnd(), rnd_double(), 0, NULL, NULL,
                          rnd_double()};
        m.n_axles = (int16_t)(big ? AMFI_MSG_MAX_TRUTH_N_AXLES
                                  : rnd_int(0, AMFI_MSG_MAX_TRUTH_N_AXLES));
        m.axle_kg = rnd_doubles(m.n_axles);
        m.mean_force_N = rnd_doubles(m.n_axles);
        ENCODE(truth_t, m);
        free(m.axle_kg);
        free(m.mean_force_N);
        break;
    }
    case AMFI_MSG_PASSAGE_T: {
        amfi_passage_t m = {(int64_t)rnd(), (int64_t)rnd(), (int64_t)rnd(), (int16_t)rnd(),
                            rnd_double(), NULL, NULL, rnd_double(), 0, NULL, rnd_double(),
                            rnd_double(), NULL, rnd_double(), NULL, rnd_double(),
                            (int8_t)rnd(), (int16_t)rnd(), rnd_double(), rnd_double(),
                            rnd_double(), rnd_double(), NULL, 0, NULL, NULL, 0, rnd_double(),
                            NULL};
        m.status = rnd_string(AMFI_MSG_MAX_PASSAGE_STATUS);
        m.site_id = rnd_string(AMFI_MSG_MAX_PASSAGE_SITE_ID);
        m.reason = rnd_string(AMFI_MSG_MAX_PASSAGE_REASON);
        m.n_axles = (int16_t)(big ? AMFI_MSG_MAX_PASSAGE_N_AXLES
                                  : rnd_int(0, AMFI_MSG_MAX_PASSAGE_N_AXLES));
        m.axle_kg = rnd_doubles(m.n_axles);
        m.formulation = rnd_string(AMFI_MSG_MAX_PASSAGE_FORMULATION);
        m.vehicle_class = rnd_string(AMFI_MSG_MAX_PASSAGE_VEHICLE_CLASS);
        m.n_groups = (int8_t)(big ? AMFI_MSG_MAX_PASSAGE_N_GROUPS
                                  : rnd_int(0, AMFI_MSG_MAX_PASSAGE_N_GROUPS));
        int16_t ga[AMFI_MSG_MAX_PASSAGE_N_GROUPS];
        for (int k = 0; k < m.n_groups; k++)
            ga[k] = (int16_t)rnd();
        m.group_axles = ga;
        m.group_load_kg = rnd_doubles(m.n_groups);
        m.overload = (int8_t)rnd();
        m.loads_refused = rnd_string(AMFI_MSG_MAX_PASSAGE_LOADS_REFUSED);
        ENCODE(passage_t, m);
        free(m.site_id);
        free(m.status);
        free(m.reason);
        free(m.axle_kg);
        free(m.vehicle_class);
        free(m.loads_refused);
        free(m.group_load_kg);
        free(m.formulation);
        break;
    }
    case AMFI_MSG_INDICATOR_T: {
        amfi_indicator_t m = {(int64_t)rnd(), (int64_t)rnd(), (int32_t)rnd(), rnd_double(),
                              rnd_double(), rnd_double(), rnd_double(), rnd_double(),
                              rnd_double(), NULL, NULL};
        m.state = rnd_string(AMFI_MSG_MAX_INDICATOR_STATE);
        m.site_id = rnd_string(AMFI_MSG_MAX_INDICATOR_SITE_ID);
        ENCODE(indicator_t, m);
        free(m.state);
        free(m.site_id);
        break;
    }
    case AMFI_MSG_ALERT_T: {
        amfi_alert_t m = {(int64_t)rnd(), (int64_t)rnd(), NULL, NULL, NULL, (int64_t)rnd(),
                          (int8_t)rnd(), NULL};
        m.level = rnd_string(AMFI_MSG_MAX_ALERT_LEVEL);
        m.site_id = rnd_string(AMFI_MSG_MAX_ALERT_SITE_ID);
        m.kind = rnd_string(AMFI_MSG_MAX_ALERT_KIND);
        m.message = rnd_string(AMFI_MSG_MAX_ALERT_MESSAGE);
        ENCODE(alert_t, m);
        free(m.site_id);
        free(m.level);
        free(m.kind);
        free(m.message);
        break;
    }
    case AMFI_MSG_STATUS_T: {
        amfi_status_t m = {(int64_t)rnd(), (int64_t)rnd(), (int64_t)rnd(), (int64_t)rnd(),
                           (int64_t)rnd(), (int64_t)rnd(), (int64_t)rnd(), (int64_t)rnd(),
                           (int64_t)rnd(), (int32_t)rnd(), (int64_t)rnd(), (int64_t)rnd(),
                           (int32_t)rnd(), NULL, NULL, NULL};
        m.state = rnd_string(AMFI_MSG_MAX_STATUS_STATE);
        m.site_id = rnd_string(AMFI_MSG_MAX_STATUS_SITE_ID);
        m.last_error = rnd_string(AMFI_MSG_MAX_STATUS_LAST_ERROR);
        ENCODE(status_t, m);
        free(m.site_id);
        free(m.state);
        free(m.last_error);
        break;
    }
    case AMFI_MSG_ENVIRONMENT_T: {
        amfi_environment_t m = {(int64_t)rnd(), rnd_double(), rnd_double()};
        ENCODE(environment_t, m);
        break;
    }
    case AMFI_MSG_NTYPES:
        break;
    }
    assert_non_null(e.buf);
    return e;
}

#define SIZE_CASE(E, T) case E: return sizeof(amfi_##T);
static size_t type_size(amfi_msg_type t)
{
    switch (t) {
    AMFI_MSG_FOR_EACH(SIZE_CASE)
    case AMFI_MSG_NTYPES: break;
    }
    return 0;
}

#define FREE_CASE(E, T) case E: amfi_##T##_decode_cleanup(m); break;
static void free_message(amfi_msg_type t, void *m)
{
    switch (t) {
    AMFI_MSG_FOR_EACH(FREE_CASE)
    case AMFI_MSG_NTYPES: break;
    }
}

/* Checks `len` bytes of type t, expects `want`, and that the checked decoder
 * refuses them the same way without a single malloc and with *msg zero. */
static void expect_reason(amfi_msg_type t, const void *buf, size_t len, int want)
{
    char why[256] = "";
    int r = amfi_msg_check(t, buf, len, why, sizeof why);
    if (r != want)
        fail_msg("%s, %zu bytes: %s (%s), expected %s", amfi_msg_type_name(t), len,
                 amfi_msg_reason_name(r), why, amfi_msg_reason_name(want));
    if (want != AMFI_MSG_OK)
        assert_true(strlen(why) > 0);
    /* Large enough for every type, aligned for any of them. */
    union {
        amfi_accel_block_t a;
        amfi_vehicle_t v;
        amfi_truth_t t;
        amfi_passage_t p;
        amfi_indicator_t i;
        amfi_alert_t al;
        amfi_status_t s;
        amfi_environment_t en;
    } msg;
    const unsigned char *bytes = (const unsigned char *)&msg;
    memset(&msg, 0xA5, sizeof msg);
    malloc_armed = 1;
    malloc_calls = 0;
    r = amfi_msg_decode_checked(t, buf, len, &msg, why, sizeof why);
    malloc_armed = 0;
    assert_int_equal(r, want);
    if (want != AMFI_MSG_OK) {
        assert_int_equal(malloc_calls, 0);
        for (size_t k = 0; k < type_size(t); k++)
            assert_int_equal(bytes[k], 0);
    } else {
        free_message(t, &msg);
    }
}

/* The decoded message of a valid buffer encodes back to the same bytes. */
static void roundtrip(amfi_msg_type t, const enc *e)
{
    char why[256];
    unsigned char *again = malloc(e->len);
    int n = -1;
#define RT(TYPE)                                                                      \
    do {                                                                              \
        amfi_##TYPE m;                                                                \
        assert_int_equal(amfi_msg_decode_##TYPE(e->buf, e->len, &m, why, sizeof why), \
                         AMFI_MSG_OK);                                                \
        n = amfi_##TYPE##_encode(again, 0, (int)e->len, &m);                          \
        amfi_##TYPE##_decode_cleanup(&m);                                             \
    } while (0)
#define RT_CASE(E, T) case E: RT(T); break;
    switch (t) {
    AMFI_MSG_FOR_EACH(RT_CASE)
    case AMFI_MSG_NTYPES: break;
    }
#undef RT_CASE
#undef RT
    assert_int_equal(n, (int)e->len);
    assert_memory_equal(again, e->buf, e->len);
    free(again);
}

/* Big-endian stores into an encoded buffer. */
static void put16(unsigned char *p, int v)
{
    p[0] = (unsigned char)((unsigned)v >> 8);
    p[1] = (unsigned char)v;
}
static void put32(unsigned char *p, int32_t v)
{
    uint32_t u = (uint32_t)v;
    p[0] = (unsigned char)(u >> 24), p[1] = (unsigned char)(u >> 16);
    p[2] = (unsigned char)(u >> 8), p[3] = (unsigned char)u;
}

/* Every type: 200 random valid messages and one at every limit are accepted,
 * consumed exactly, and decode back to the same bytes. */
static void test_random_valid(void **state)
{
    (void)state;
    for (int t = 0; t < AMFI_MSG_NTYPES; t++)
        for (int i = 0; i <= 200; i++) {
            enc e = random_message((amfi_msg_type)t, i == 200);
            expect_reason((amfi_msg_type)t, e.buf, e.len, AMFI_MSG_OK);
            roundtrip((amfi_msg_type)t, &e);
            free(e.buf);
        }
}

/* Every prefix of a valid message is refused: "fingerprint" below 8 bytes,
 * "truncated" from there on; one byte more is "trailing". */
static void test_truncated_and_trailing(void **state)
{
    (void)state;
    for (int t = 0; t < AMFI_MSG_NTYPES; t++)
        for (int i = 0; i < 5; i++) {
            enc e = random_message((amfi_msg_type)t, i == 4);
            for (size_t len = 0; len < e.len; len++) {
                unsigned char *cut = malloc(len ? len : 1); /* exact size: ASan sees any overread */
                memcpy(cut, e.buf, len);
                expect_reason((amfi_msg_type)t, len ? cut : NULL, len,
                              len < 8 ? AMFI_MSG_FINGERPRINT : AMFI_MSG_TRUNCATED);
                free(cut);
            }
            unsigned char *more = malloc(e.len + 3);
            memcpy(more, e.buf, e.len);
            memset(more + e.len, 0, 3);
            expect_reason((amfi_msg_type)t, more, e.len + 1, AMFI_MSG_TRAILING);
            expect_reason((amfi_msg_type)t, more, e.len + 3, AMFI_MSG_TRAILING);
            free(more);
            free(e.buf);
        }
}

/* Another type's bytes, or one bit of the fingerprint flipped. */
static void test_fingerprint(void **state)
{
    (void)state;
    for (int t = 0; t < AMFI_MSG_NTYPES; t++) {
        enc e = random_message((amfi_msg_type)t, 0);
        for (int u = 0; u < AMFI_MSG_NTYPES; u++)
            if (u != t)
                expect_reason((amfi_msg_type)u, e.buf, e.len, AMFI_MSG_FINGERPRINT);
        for (int bit = 0; bit < 64; bit++) {
            e.buf[bit / 8] ^= (unsigned char)(1u << (bit % 8));
            expect_reason((amfi_msg_type)t, e.buf, e.len, AMFI_MSG_FINGERPRINT);
            e.buf[bit / 8] ^= (unsigned char)(1u << (bit % 8));
        }
        free(e.buf);
    }
}

/* A vehicle_t with no spacings, source "sim_publisher": 64 bytes (56 before
 * reference_gvw_kg was appended, issue 14: the source length stays at 38). */
static enc small_vehicle(void)
{
    double none[1] = {0};
    amfi_vehicle_t v = {1763800000000000, 7, 1, 20.0, 1, 0, none, (char *)"sim_publisher", 0.0};
    enc e;
    ENCODE(vehicle_t, v);
    return e;
}
#define VEHICLE_SOURCE_LEN_AT 38 /* 8 + 8 + 8 + 2 + 8 + 2 + 2 + 0 spacings */

/* Issue 9, finding 1: one 56-byte vehicle_t with the source length -16 made
 * lcm-gen's decoder malloc(-16) and memcpy (size_t)-17 bytes: amfid died. */
static void test_issue9_negative_string_length(void **state)
{
    (void)state;
    enc e = small_vehicle();
    assert_int_equal(e.len, 64);
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, -16);
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_NEGATIVE_COUNT);
    char why[256];
    amfi_vehicle_t v;
    assert_int_equal(amfi_msg_decode_vehicle_t(e.buf, e.len, &v, why, sizeof why),
                     AMFI_MSG_NEGATIVE_COUNT);
    assert_non_null(strstr(why, "vehicle_t.source"));
    assert_null(v.source);
    assert_null(v.axle_spacing_m);
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, INT32_MIN);
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_NEGATIVE_COUNT);
    free(e.buf);
}

/* Strings: length 0 (no room for the NUL), no NUL at the end, a NUL inside,
 * not UTF-8 (a lone continuation byte, an overlong '/', a surrogate), too
 * long (over the limit although the bytes are there), longer than the rest. */
static void test_bad_strings(void **state)
{
    (void)state;
    enc e = small_vehicle();
    unsigned char *s = e.buf + VEHICLE_SOURCE_LEN_AT + 4;
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, 0);
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, VEHICLE_SOURCE_LEN_AT + 4, AMFI_MSG_BAD_STRING);
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, 14);
    s[13] = 'x';
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_BAD_STRING);
    s[13] = 0, s[3] = 0;
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_BAD_STRING);
    s[3] = 0x80;
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_BAD_STRING);
    s[3] = 0xC0, s[4] = 0xAF;
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_BAD_STRING);
    s[3] = 0xED, s[4] = 0xA0, s[5] = 0x80;
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_BAD_STRING);
    s[3] = 0xE2, s[4] = 0x82, s[5] = 0xAC; /* € is fine */
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_OK);
    /* one byte more than the message has left (the string, then the
     * 8 bytes of reference_gvw_kg) */
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, (int32_t)(e.len - VEHICLE_SOURCE_LEN_AT - 4 + 1));
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_TRUNCATED);
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, INT32_MAX);
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_OVER_LIMIT);
    free(e.buf);

    /* A source of the limit + 1 bytes, all present and NUL-terminated. */
    char *src = malloc(AMFI_MSG_MAX_VEHICLE_SOURCE + 2);
    memset(src, 's', AMFI_MSG_MAX_VEHICLE_SOURCE + 1);
    src[AMFI_MSG_MAX_VEHICLE_SOURCE + 1] = 0;
    double none[1] = {0};
    amfi_vehicle_t v = {1, 2, 1, 20.0, 1, 0, none, src, 0.0};
    ENCODE(vehicle_t, v);
    expect_reason(AMFI_MSG_VEHICLE_T, e.buf, e.len, AMFI_MSG_OVER_LIMIT);
    free(e.buf);
    free(src);
}

/* The offset of the count field and the type, for a message whose arrays are
 * empty (counts are rewritten in place; the arrays' bytes appended). */
struct count_case {
    amfi_msg_type t;
    size_t at;  /* byte offset of the int16 count */
    long limit; /* its AMFI_MSG_MAX_* */
    const char *field;
};

static enc empty_arrays(amfi_msg_type t)
{
    enc e = {0};
    double none[1] = {0};
    switch (t) {
    case AMFI_MSG_ACCEL_BLOCK_T: {
        amfi_accel_block_t m = {1, 0, 1, 1000.0, 0, none};
        ENCODE(accel_block_t, m);
        break;
    }
    case AMFI_MSG_VEHICLE_T: {
        amfi_vehicle_t m = {1, 2, 1, 20.0, 1, 0, none, (char *)"x", 14000.0};
        ENCODE(vehicle_t, m);
        break;
    }
    case AMFI_MSG_TRUTH_T: {
        amfi_truth_t m = {1, 2, 1e4, 0, none, none, 20.0};
        ENCODE(truth_t, m);
        break;
    }
    case AMFI_MSG_PASSAGE_T: {
        amfi_passage_t m = {1, 2, 3, 1, 20.0, (char *)"ok", (char *)"", 1e4, 0, none,
                            1e-3, 0.1, (char *)"modal", 5.0, (char *)"site-1", 20.0, 0, 1, 1.5, 0.0,
                            5.73, 5.70, (char *)"A23", 0, NULL, NULL, 0, 0.004, (char *)""};
        ENCODE(passage_t, m);
        break;
    }
    default:
        fail();
    }
    return e;
}

/* Negative array counts on accel, vehicle, truth (and passage); counts over
 * the limit (with all their bytes present), and counts within the limit
 * whose bytes are missing. */
static void test_counts(void **state)
{
    (void)state;
    static const struct count_case cases[] = {
        {AMFI_MSG_ACCEL_BLOCK_T, 36, AMFI_MSG_MAX_ACCEL_BLOCK_N, "accel_block_t.accel"},
        {AMFI_MSG_VEHICLE_T, 36, AMFI_MSG_MAX_VEHICLE_N_SPACINGS, "vehicle_t.axle_spacing_m"},
        {AMFI_MSG_TRUTH_T, 32, AMFI_MSG_MAX_TRUTH_N_AXLES, "truth_t.axle_kg"},
        {AMFI_MSG_PASSAGE_T, 0, AMFI_MSG_MAX_PASSAGE_N_AXLES, "passage_t.axle_kg"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        enc e = empty_arrays(cases[c].t);
        size_t at = cases[c].at;
        if (cases[c].t == AMFI_MSG_PASSAGE_T) /* after status "ok" and reason "" */
            at = 8 + 8 + 8 + 8 + 2 + 8 + (4 + 3) + (4 + 1) + 8;
        /* The empty message is valid and its count is where we think. */
        expect_reason(cases[c].t, e.buf, e.len, AMFI_MSG_OK);
        assert_int_equal(e.buf[at], 0);
        assert_int_equal(e.buf[at + 1], 0);
        size_t head = at + 2, tail = e.len - head;
        /* Room for limit + 1 elements (two arrays for truth_t). */
        size_t room = 2 * 8 * (size_t)(cases[c].limit + 1);
        unsigned char *b = calloc(1, e.len + room);
        memcpy(b, e.buf, head);
        static const int negatives[] = {-1, -2, -16, -32768};
        for (size_t k = 0; k < 4; k++) {
            put16(b + at, negatives[k]);
            memcpy(b + head, e.buf + head, tail);
            char why[256];
            assert_int_equal(amfi_msg_check(cases[c].t, b, e.len, why, sizeof why),
                             AMFI_MSG_NEGATIVE_COUNT);
            assert_non_null(strstr(why, cases[c].field));
            expect_reason(cases[c].t, b, e.len, AMFI_MSG_NEGATIVE_COUNT);
            expect_reason(cases[c].t, b, e.len + room, AMFI_MSG_NEGATIVE_COUNT);
        }
        int arrays = cases[c].t == AMFI_MSG_TRUTH_T ? 2 : 1;
        for (long n = cases[c].limit; n <= cases[c].limit + 1; n++) {
            size_t body = (size_t)arrays * 8 * (size_t)n;
            put16(b + at, (int)n);
            memset(b + head, 0, body);
            memcpy(b + head + body, e.buf + head, tail);
            expect_reason(cases[c].t, b, e.len + body,
                          n <= cases[c].limit ? AMFI_MSG_OK : AMFI_MSG_OVER_LIMIT);
            /* The same count without its bytes. */
            if (n <= cases[c].limit) {
                memcpy(b + head, e.buf + head, tail);
                expect_reason(cases[c].t, b, e.len, AMFI_MSG_TRUNCATED);
            }
        }
        put16(b + at, 32767);
        expect_reason(cases[c].t, b, e.len, AMFI_MSG_OVER_LIMIT);
        free(b);
        free(e.buf);
    }
}

/* passage_t's class and groups: n_groups up to its limit, one over refused
 * (over_limit, naming the array), a negative count refused, a class name
 * over its 15 bytes refused. */
static enc passage_with_refused(const char *vclass, int n_groups, const char *refused)
{
    enc e = {0};
    double none[1] = {0}, kg[AMFI_MSG_MAX_PASSAGE_N_GROUPS + 1];
    int16_t ax[AMFI_MSG_MAX_PASSAGE_N_GROUPS + 1];
    for (int k = 0; k <= AMFI_MSG_MAX_PASSAGE_N_GROUPS; k++) {
        ax[k] = 1;
        kg[k] = 1000.0 * (k + 1);
    }
    amfi_passage_t m = {1, 2, 3, 1, 20.0, (char *)"ok", (char *)"", 1e4, 0, none,
                        1e-3, 0.1, (char *)"modal", 5.0, (char *)"site-1", 20.0, 0, 1, 1.5, 0.0,
                        5.73, 5.70, (char *)vclass, (int8_t)n_groups, ax, kg, 1, 0.004,
                        (char *)refused};
    ENCODE(passage_t, m);
    return e;
}
static enc passage_with(const char *vclass, int n_groups)
{
    return passage_with_refused(vclass, n_groups, "");
}

static void test_passage_groups(void **state)
{
    (void)state;
    char why[256], big[AMFI_MSG_MAX_PASSAGE_VEHICLE_CLASS + 2];
    for (int n = 0; n <= AMFI_MSG_MAX_PASSAGE_N_GROUPS + 1; n++) {
        enc e = passage_with("A23", n);
        int want = n <= AMFI_MSG_MAX_PASSAGE_N_GROUPS ? AMFI_MSG_OK : AMFI_MSG_OVER_LIMIT;
        expect_reason(AMFI_MSG_PASSAGE_T, e.buf, e.len, want);
        if (want != AMFI_MSG_OK) {
            assert_int_equal(amfi_msg_check(AMFI_MSG_PASSAGE_T, e.buf, e.len, why, sizeof why),
                             AMFI_MSG_OVER_LIMIT);
            assert_non_null(strstr(why, "passage_t.group_axles"));
        }
        free(e.buf);
    }
    /* n_groups is the last message's fifteenth byte from the end (then
     * overload, fit_ratio and loads_refused: "" is a 4-byte length and a NUL) */
    enc e = passage_with("A23", 0);
    e.buf[e.len - 15] = 0xff; /* -1 */
    assert_int_equal(amfi_msg_check(AMFI_MSG_PASSAGE_T, e.buf, e.len, why, sizeof why),
                     AMFI_MSG_NEGATIVE_COUNT);
    assert_non_null(strstr(why, "passage_t.group_axles"));
    free(e.buf);
    memset(big, 'X', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    e = passage_with(big, 0);
    assert_int_equal(amfi_msg_check(AMFI_MSG_PASSAGE_T, e.buf, e.len, why, sizeof why),
                     AMFI_MSG_OVER_LIMIT);
    assert_non_null(strstr(why, "passage_t.vehicle_class"));
    free(e.buf);
    big[sizeof big - 2] = '\0'; /* 15 bytes: the limit */
    e = passage_with(big, 0);
    expect_reason(AMFI_MSG_PASSAGE_T, e.buf, e.len, AMFI_MSG_OK);
    free(e.buf);
    /* the refusal's reason: at most 111 bytes */
    char why_refused[AMFI_MSG_MAX_PASSAGE_LOADS_REFUSED + 2];
    memset(why_refused, 'r', sizeof why_refused - 1);
    why_refused[sizeof why_refused - 1] = '\0';
    e = passage_with_refused("A23", 0, why_refused);
    assert_int_equal(amfi_msg_check(AMFI_MSG_PASSAGE_T, e.buf, e.len, why, sizeof why),
                     AMFI_MSG_OVER_LIMIT);
    assert_non_null(strstr(why, "passage_t.loads_refused"));
    free(e.buf);
    why_refused[sizeof why_refused - 2] = '\0'; /* 111 bytes: the limit */
    e = passage_with_refused("A23", 0, why_refused);
    expect_reason(AMFI_MSG_PASSAGE_T, e.buf, e.len, AMFI_MSG_OK);
    free(e.buf);
}

/* The labels are the documented ones and every type has a name. */
static void test_names(void **state)
{
    (void)state;
    static const char *const want[] = {"ok", "fingerprint", "truncated", "negative_count",
                                       "over_limit", "bad_string", "trailing", "decode"};
    for (int r = 0; r < AMFI_MSG_NREASONS; r++)
        assert_string_equal(amfi_msg_reason_name(r), want[r]);
    assert_string_equal(amfi_msg_reason_name(-1), "unknown");
    assert_string_equal(amfi_msg_reason_name(AMFI_MSG_NREASONS), "unknown");
    assert_string_equal(amfi_msg_type_name(AMFI_MSG_VEHICLE_T), "vehicle_t");
    assert_null(amfi_msg_type_name(AMFI_MSG_NTYPES));
    char why[64];
    assert_int_equal(amfi_msg_check(AMFI_MSG_NTYPES, "", 0, why, sizeof why),
                     AMFI_MSG_FINGERPRINT);
}

/* --- seed corpus for fuzz/ --- */
static void write_file(const char *dir, const char *name, const void *buf, size_t len)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(buf, 1, len, f) != len || fclose(f) != 0) {
        fprintf(stderr, "test_msg_check: %s: %s\n", path, strerror(errno));
        exit(1);
    }
}

static int write_corpus(const char *top)
{
    for (int t = 0; t < AMFI_MSG_NTYPES; t++) {
        char dir[4096], name[64];
        snprintf(dir, sizeof dir, "%s/msg_%s", top, amfi_msg_type_name((amfi_msg_type)t));
        if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "test_msg_check: %s: %s\n", dir, strerror(errno));
            return 1;
        }
        for (int i = 0; i < 4; i++) {
            enc e = random_message((amfi_msg_type)t, i == 3);
            snprintf(name, sizeof name, "valid-%d", i);
            write_file(dir, name, e.buf, e.len);
            if (i == 0) {
                write_file(dir, "truncated", e.buf, e.len - 1);
                unsigned char *more = calloc(1, e.len + 1);
                memcpy(more, e.buf, e.len);
                write_file(dir, "trailing", more, e.len + 1);
                more[0] ^= 1;
                write_file(dir, "fingerprint", more, e.len);
                free(more);
            }
            free(e.buf);
        }
    }
    enc e = small_vehicle();
    put32(e.buf + VEHICLE_SOURCE_LEN_AT, -16);
    write_file(top, "msg_vehicle_t/issue9-negative-source", e.buf, e.len);
    free(e.buf);
    static const amfi_msg_type with_arrays[] = {AMFI_MSG_ACCEL_BLOCK_T, AMFI_MSG_VEHICLE_T,
                                                AMFI_MSG_TRUTH_T, AMFI_MSG_PASSAGE_T};
    for (size_t k = 0; k < 4; k++) {
        amfi_msg_type t = with_arrays[k];
        e = empty_arrays(t);
        char name[96];
        snprintf(name, sizeof name, "msg_%s/empty-arrays", amfi_msg_type_name(t));
        write_file(top, name, e.buf, e.len);
        free(e.buf);
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--corpus") == 0)
        return write_corpus(argv[2]);
    if (argc != 1) {
        fprintf(stderr, "usage: test_msg_check [--corpus DIR]\n");
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_valid),
        cmocka_unit_test(test_truncated_and_trailing),
        cmocka_unit_test(test_fingerprint),
        cmocka_unit_test(test_issue9_negative_string_length),
        cmocka_unit_test(test_bad_strings),
        cmocka_unit_test(test_counts),
        cmocka_unit_test(test_passage_groups),
        cmocka_unit_test(test_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
