/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi_msg_check.h: check a raw LCM buffer against an amfi message type
 * before lcm-gen's _decode() runs on it (docs/messages.md, "Checking raw
 * buffers"). lcm-gen's decoder trusts the counts and string lengths: a
 * negative one makes it malloc() a huge size and memcpy() past the buffer,
 * so one datagram could crash the reader. The checker walks the LCM wire
 * encoding (8-byte fingerprint, big-endian fields, counts, strings as an
 * int32 length including the NUL and then the bytes) with the field lists
 * generated from messages/ *.lcm at build time and the limits of
 * amfi_msg_limits.h. Pure functions of their arguments: no allocation, no
 * global state written; callable from any thread.
 */
#ifndef AMFI_MSG_CHECK_H
#define AMFI_MSG_CHECK_H

#include <stddef.h>

#include "amfi_msg_types.h" /* amfi_msg_type, amfi_msg_decode_TYPE() */

/* Why a buffer was refused. The names (amfi_msg_reason_name) are short
 * lower-case words, usable as counter or metric labels. */
typedef enum {
    AMFI_MSG_OK = 0,
    AMFI_MSG_FINGERPRINT,    /* "fingerprint": shorter than 8 bytes or another type's */
    AMFI_MSG_TRUNCATED,      /* "truncated": a field, array or string runs past the end */
    AMFI_MSG_NEGATIVE_COUNT, /* "negative_count": an array count or string length < 0 */
    AMFI_MSG_OVER_LIMIT,     /* "over_limit": a count or string longer than its limit */
    AMFI_MSG_BAD_STRING,     /* "bad_string": length 0, no final NUL, a NUL inside, not UTF-8 */
    AMFI_MSG_TRAILING,       /* "trailing": bytes after the last field */
    AMFI_MSG_DECODE,         /* "decode": lcm-gen's decoder refused what the checker
                                accepted (a checker bug; never expected) */
    AMFI_MSG_NREASONS
} amfi_msg_reason;

/* The label of a reason ("ok", "fingerprint", ...); "unknown" out of range. */
const char *amfi_msg_reason_name(int reason);

/* The type's name as in its .lcm file ("vehicle_t"); NULL out of range. */
const char *amfi_msg_type_name(amfi_msg_type t);

/* Check `len` bytes at `buf` (the whole LCM payload, as a subscriber's
 * handler receives it in lcm_recv_buf_t) against type `t`. Returns AMFI_MSG_OK
 * or the reason; on refusal writes one line into why (when whylen > 0) naming
 * the field and the byte offset, e.g.
 *   "vehicle_t.source: string length -16 at byte 42 is negative".
 * Never reads outside buf[0 .. len). */
int amfi_msg_check(amfi_msg_type t, const void *buf, size_t len, char *why, size_t whylen);

/* amfi_msg_check() and, when it passes, lcm-gen's TYPE_decode() into `msg`
 * (a struct of type t, e.g. amfi_vehicle_t *). Returns AMFI_MSG_OK with *msg
 * decoded (free it with TYPE_decode_cleanup()), or the reason with *msg all
 * zero and nothing allocated (no cleanup needed). The typed wrappers
 * amfi_msg_decode_accel_block_t() ... (amfi_msg_types.h) do the same. */
int amfi_msg_decode_checked(amfi_msg_type t, const void *buf, size_t len, void *msg, char *why,
                            size_t whylen);

#endif /* AMFI_MSG_CHECK_H */
