/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_auth.c: the signed bus (messages/amfi_auth.h, docs/messages.md):
 * the trailer's bytes, every refusal reason of the verifier (unsigned,
 * bad_mac for each byte covered by the MAC, replay, skew, producers), the
 * sequence made strictly increasing, the key file's checks (size, hex, mode,
 * type), --make-bus-key's O_EXCL, and the key lookup order.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "amfi_auth.h"

#define NOW INT64_C(1790000000000000) /* µs, a fixed receive time */

static amfi_auth_key key_of(unsigned char b)
{
    amfi_auth_key k;
    memset(k.k, b, sizeof k.k);
    return k;
}

/* msg signed by s at utime into out; returns its length */
static size_t sign(amfi_auth_signer *s, const char *ch, const char *msg, int64_t utime,
                   unsigned char *out, size_t cap)
{
    long n = amfi_auth_sign_into(s, ch, msg, strlen(msg), utime, out, cap);
    assert_true(n > 0);
    return (size_t)n;
}

static void trailer_layout(void **state)
{
    (void)state;
    amfi_auth_key k = key_of(7);
    amfi_auth_signer s;
    assert_int_equal(amfi_auth_signer_init(&s, &k, "daq-1", NULL, 0), 0);
    unsigned char b[256];
    size_t n = sign(&s, "AMFI_ACCEL", "hello", NOW, b, sizeof b);
    assert_int_equal(n, 5 + AMFI_AUTH_TRAILER_BYTES);
    assert_int_equal(AMFI_AUTH_TRAILER_BYTES, 61);
    assert_memory_equal(b, "hello", 5);
    assert_memory_equal(b + 5, "AMFA\x01" "daq-1\0\0\0\0\0\0\0\0\0\0\0", 21);
    uint64_t seq = 0;
    for (int i = 0; i < 8; i++)
        seq = seq << 8 | b[5 + 21 + i];
    assert_true(seq == (uint64_t)NOW);
    assert_int_equal(amfi_auth_bare_len(b, n), 5);
    assert_int_equal(amfi_auth_bare_len(b, 5), 5); /* no trailer: all of it */
    /* the same clock again: the sequence still increases */
    n = sign(&s, "AMFI_ACCEL", "hello", NOW, b, sizeof b);
    seq = 0;
    for (int i = 0; i < 8; i++)
        seq = seq << 8 | b[5 + 21 + i];
    assert_true(seq == (uint64_t)NOW + 1);
    /* too small a buffer */
    assert_int_equal(amfi_auth_sign_into(&s, "C", "hello", 5, NOW, b, 5 + 60), -1);
    amfi_auth_signer_free(&s);
}

static void verify_reasons(void **state)
{
    (void)state;
    amfi_auth_key k = key_of(1), other = key_of(2);
    amfi_auth_signer s, w;
    amfi_auth_verifier v;
    assert_int_equal(amfi_auth_signer_init(&s, &k, "sim.1", NULL, 0), 0);
    assert_int_equal(amfi_auth_signer_init(&w, &other, "sim.1", NULL, 0), 0);
    assert_int_equal(amfi_auth_verifier_init(&v, &k, 300.0), 0);
    unsigned char b[256], c[256];
    char why[256];
    size_t bare = 0;
    size_t n = sign(&s, "AMFI_VEHICLE", "vehicle bytes", NOW, b, sizeof b);
    /* every covered byte matters: struct, producer, sequence, MAC; and the channel */
    for (size_t i = 0; i < n; i++) {
        if (i >= 13 && i < 13 + 5)
            continue; /* magic and version: unsigned, below */
        memcpy(c, b, n);
        c[i] ^= 0x10;
        assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", c, n, NOW, &bare, why, sizeof why),
                         AMFI_AUTH_BAD_MAC);
    }
    assert_int_equal(amfi_auth_verify(&v, "AMFI_ACCEL", b, n, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_BAD_MAC);
    /* another key, as the same producer */
    size_t m = sign(&w, "AMFI_VEHICLE", "vehicle bytes", NOW, c, sizeof c);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", c, m, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_BAD_MAC);
    assert_non_null(strstr(why, "bad_mac"));
    /* no trailer, too short, another version */
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", b, 13, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_UNSIGNED);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", "x", 1, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_UNSIGNED);
    memcpy(c, b, n);
    c[13 + 4] = 2;
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", c, n, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_UNSIGNED);
    /* none of the refusals changed the producer's state: the original passes */
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", b, n, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_OK);
    assert_int_equal(bare, 13);
    /* again: a replay; an older one too; a newer one passes */
    assert_int_equal(amfi_auth_verify(&v, "AMFI_VEHICLE", b, n, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_REPLAY);
    assert_non_null(strstr(why, "producer sim.1"));
    size_t o = sign(&s, "AMFI_ACCEL", "a", NOW + 1000, c, sizeof c);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_ACCEL", c, o, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_OK);
    /* skew: 300 s is the limit either way */
    o = sign(&s, "AMFI_ACCEL", "a", NOW + 301000000, c, sizeof c);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_ACCEL", c, o, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_SKEW);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_ACCEL", c, o, NOW + 2000000, &bare, why,
                                      sizeof why),
                     AMFI_AUTH_OK);
    amfi_auth_signer s2;
    assert_int_equal(amfi_auth_signer_init(&s2, &k, "old", NULL, 0), 0);
    o = sign(&s2, "AMFI_ACCEL", "a", NOW - 301000000, c, sizeof c);
    assert_int_equal(amfi_auth_verify(&v, "AMFI_ACCEL", c, o, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_SKEW);
    /* without a time check (a file:// replay) the old one passes, once */
    amfi_auth_verifier nv;
    assert_int_equal(amfi_auth_verifier_init(&nv, &k, 0.0), 0);
    assert_int_equal(amfi_auth_verify(&nv, "AMFI_ACCEL", c, o, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_OK);
    assert_int_equal(amfi_auth_verify(&nv, "AMFI_ACCEL", c, o, NOW, &bare, why, sizeof why),
                     AMFI_AUTH_REPLAY);
    amfi_auth_signer_free(&s);
    amfi_auth_signer_free(&w);
    amfi_auth_signer_free(&s2);
}

static void producer_table(void **state)
{
    (void)state;
    amfi_auth_key k = key_of(3);
    amfi_auth_verifier *v = malloc(sizeof *v);
    assert_non_null(v);
    assert_int_equal(amfi_auth_verifier_init(v, &k, 10.0), 0);
    unsigned char b[256];
    char why[256], name[32];
    size_t bare;
    for (int i = 0; i <= AMFI_AUTH_MAX_PRODUCERS; i++) {
        amfi_auth_signer s;
        snprintf(name, sizeof name, "p%d", i);
        assert_int_equal(amfi_auth_signer_init(&s, &k, name, NULL, 0), 0);
        size_t n = sign(&s, "C", "m", NOW, b, sizeof b);
        int r = amfi_auth_verify(v, "C", b, n, NOW, &bare, why, sizeof why);
        assert_int_equal(r, i < AMFI_AUTH_MAX_PRODUCERS ? AMFI_AUTH_OK : AMFI_AUTH_PRODUCERS);
        /* 11 s later the stalest producer is past the skew: its slot is reused */
        if (i == AMFI_AUTH_MAX_PRODUCERS) {
            n = sign(&s, "C", "m", NOW + 11000000, b, sizeof b);
            assert_int_equal(amfi_auth_verify(v, "C", b, n, NOW + 11000000, &bare, why,
                                              sizeof why),
                             AMFI_AUTH_OK);
        }
        amfi_auth_signer_free(&s);
    }
    free(v);
}

static void producer_names(void **state)
{
    (void)state;
    amfi_auth_key k = key_of(4);
    amfi_auth_signer s;
    char err[200];
    assert_int_equal(amfi_auth_signer_init(&s, &k, "", err, sizeof err), -1);
    assert_int_equal(amfi_auth_signer_init(&s, &k, "a b", err, sizeof err), -1);
    assert_int_equal(amfi_auth_signer_init(&s, &k, "12345678901234567", err, sizeof err), -1);
    assert_non_null(strstr(err, "[A-Za-z0-9._-]"));
    char out[AMFI_AUTH_PRODUCER_BYTES + 1];
    amfi_auth_producer_name(out, "amfid.", "site with a very long name");
    assert_string_equal(out, "amfid.site_with_");
    assert_int_equal(amfi_auth_signer_init(&s, &k, out, err, sizeof err), 0);
    amfi_auth_signer_free(&s);
}

static char dir[] = "/tmp/amfi_test_auth_XXXXXX";

static const char *path_in(const char *name)
{
    static char p[4][300];
    static int i;
    i = (i + 1) % 4;
    snprintf(p[i], sizeof p[i], "%s/%s", dir, name);
    return p[i];
}

static void write_file(const char *path, const void *data, size_t n, mode_t mode)
{
    unlink(path);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
    assert_int_equal(chmod(path, mode), 0);
}

static void key_files(void **state)
{
    (void)state;
    amfi_auth_key k;
    char err[600];
    unsigned char raw[32];
    for (int i = 0; i < 32; i++)
        raw[i] = (unsigned char)(i * 7 + 1);
    write_file(path_in("raw"), raw, 32, 0600);
    assert_int_equal(amfi_auth_key_load(path_in("raw"), &k, err, sizeof err), 0);
    assert_memory_equal(k.k, raw, 32);
    char hex[80];
    for (int i = 0; i < 32; i++)
        snprintf(hex + 2 * i, 3, "%02X", raw[i]);
    strcat(hex, "\n");
    write_file(path_in("hex"), hex, 65, 0400);
    memset(&k, 0, sizeof k);
    assert_int_equal(amfi_auth_key_load(path_in("hex"), &k, err, sizeof err), 0);
    assert_memory_equal(k.k, raw, 32);
    hex[10] = 'g';
    write_file(path_in("badhex"), hex, 65, 0600);
    assert_int_equal(amfi_auth_key_load(path_in("badhex"), &k, err, sizeof err), -1);
    assert_non_null(strstr(err, "neither 32 raw bytes nor 64 hex digits"));
    assert_non_null(strstr(err, path_in("badhex")));
    write_file(path_in("short"), raw, 31, 0600);
    assert_int_equal(amfi_auth_key_load(path_in("short"), &k, err, sizeof err), -1);
    assert_non_null(strstr(err, "31 bytes"));
    write_file(path_in("open"), raw, 32, 0640);
    assert_int_equal(amfi_auth_key_load(path_in("open"), &k, err, sizeof err), -1);
    assert_non_null(strstr(err, "mode 0640"));
    write_file(path_in("world"), raw, 32, 0604);
    assert_int_equal(amfi_auth_key_load(path_in("world"), &k, err, sizeof err), -1);
    assert_int_equal(amfi_auth_key_load(dir, &k, err, sizeof err), -1);
    assert_non_null(strstr(err, "not a regular file"));
    assert_int_equal(amfi_auth_key_load(path_in("none"), &k, err, sizeof err), -1);
    assert_non_null(strstr(err, "cannot open"));
    /* make: 0600, 32 bytes, loadable, never over an existing file */
    assert_int_equal(amfi_auth_key_make(path_in("made"), err, sizeof err), 0);
    struct stat st;
    assert_int_equal(stat(path_in("made"), &st), 0);
    assert_int_equal(st.st_mode & 07777, 0600);
    assert_int_equal(st.st_size, 32);
    assert_int_equal(amfi_auth_key_load(path_in("made"), &k, err, sizeof err), 0);
    assert_int_equal(amfi_auth_key_make(path_in("made"), err, sizeof err), -1);
    assert_non_null(strstr(err, "never overwritten"));
    assert_int_equal(amfi_auth_key_make(path_in("raw"), err, sizeof err), -1);
    assert_int_equal(amfi_auth_key_load(path_in("raw"), &k, err, sizeof err), 0);
    assert_memory_equal(k.k, raw, 32); /* untouched */
}

static void key_lookup(void **state)
{
    (void)state;
    char buf[400];
    const char *origin = NULL;
    setenv("CREDENTIALS_DIRECTORY", dir, 1);
    assert_string_equal(amfi_auth_key_path("/a", "/b", buf, sizeof buf, &origin), "/a");
    assert_string_equal(origin, "option");
    assert_string_equal(amfi_auth_key_path(NULL, "/b", buf, sizeof buf, &origin), "/b");
    assert_string_equal(origin, "configuration");
    /* the credential only when the file exists */
    unlink(path_in(AMFI_AUTH_CREDENTIAL));
    assert_null(amfi_auth_key_path("", "", buf, sizeof buf, &origin));
    assert_null(origin);
    unsigned char raw[32] = {0};
    write_file(path_in(AMFI_AUTH_CREDENTIAL), raw, 32, 0600);
    assert_string_equal(amfi_auth_key_path(NULL, NULL, buf, sizeof buf, &origin),
                        path_in(AMFI_AUTH_CREDENTIAL));
    assert_string_equal(origin, "credential");
    unsetenv("CREDENTIALS_DIRECTORY");
    assert_null(amfi_auth_key_path(NULL, NULL, buf, sizeof buf, &origin));
}

static int setup(void **state)
{
    (void)state;
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(trailer_layout), cmocka_unit_test(verify_reasons),
        cmocka_unit_test(producer_table), cmocka_unit_test(producer_names),
        cmocka_unit_test(key_files),      cmocka_unit_test(key_lookup),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
