/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_bus_sign.h: the test programs that write LCM logs for amfid
 * (lcm_hostile, lcm_inject, lcm_fuzzlog, lcm_timeshift) sign what they
 * write with the test's site key, so that amfid with the shipped
 * daemon.bus.auth: required lets their hostile messages through to the
 * decoders they are meant to exercise. The key is the systemd credential
 * ($CREDENTIALS_DIRECTORY/amfi-bus-key: tests/common/bus_key.sh makes it); without
 * one the logs are written unsigned (a note on stderr).
 *
 * test_put() takes off any trailer the input message had (sim_publisher's
 * logs are signed) and signs the message again as the program's own
 * producer, the sequence from the wall clock made strictly increasing:
 * events copied out of order or twice stay acceptable to the authentication
 * and reach the intake's own checks, through file:// and, played soon after,
 * on a live bus.
 */
#ifndef TEST_BUS_SIGN_H
#define TEST_BUS_SIGN_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/eventlog.h>

#include "amfi_auth.h"

static amfi_auth_signer test_signer_s;
static amfi_auth_signer *test_signer; /* NULL: unsigned */

/* The test key from the credential; 0, or 1 (a key that cannot be used). */
static inline int test_sign_init(const char *producer)
{
    char path[4096], err[4400];
    if (!amfi_auth_key_path(NULL, NULL, path, sizeof path, NULL)) {
        fprintf(stderr, "%s: no bus key ($CREDENTIALS_DIRECTORY/%s): writing unsigned\n",
                producer, AMFI_AUTH_CREDENTIAL);
        return 0;
    }
    amfi_auth_key key;
    if (amfi_auth_key_load(path, &key, err, sizeof err) ||
        amfi_auth_signer_init(&test_signer_s, &key, producer, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", producer, err);
        return 1;
    }
    test_signer = &test_signer_s;
    return 0;
}

/* One event, its trailer (if any) replaced by this program's signature. */
static inline int test_put(lcm_eventlog_t *out, int64_t *num, int64_t ts, const char *ch,
                    const void *data, int len)
{
    size_t bare = len > 0 ? amfi_auth_bare_len(data, (size_t)len) : 0;
    return amfi_auth_log_write(out, test_signer, (*num)++, ts, ch, data, bare);
}

/* One event exactly as given (a forged or replayed trailer stays). */
static inline int test_put_raw(lcm_eventlog_t *out, int64_t *num, int64_t ts, const char *ch,
                        const void *data, int len)
{
    return amfi_auth_log_write(out, NULL, (*num)++, ts, ch, data, len > 0 ? (size_t)len : 0);
}

#endif /* TEST_BUS_SIGN_H */
