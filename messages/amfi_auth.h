/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_auth.h: the authenticated amfi bus (docs/messages.md, "Signed
 * messages"). Every message stays the LCM-encoded struct, followed by a
 * trailer of AMFI_AUTH_TRAILER_BYTES bytes:
 *
 *   offset  size  field
 *   0       4     magic "AMFA"
 *   4       1     version, 1
 *   5       16    producer id: 1 .. 16 bytes of [A-Za-z0-9._-], NUL-padded
 *   21      8     sequence, unsigned big-endian: the producer's wall clock
 *                 in µs since 1970 when it signs, made strictly increasing
 *                 per producer (on the bus and in the LCM logs it writes)
 *   29      32    MAC: HMAC-SHA-512-256 (libsodium crypto_auth) keyed by the
 *                 site key, over channel name, one 0 byte, the encoded
 *                 message, the 16 producer bytes and the 8 sequence bytes
 *
 * LCM's generated decoders (C and Java) ignore bytes after the last field, so
 * lcm-spy and the logs stay readable; amfi's raw-buffer checker does not, so
 * a reader strips the trailer first (amfi_auth_verify, amfi_auth_bare_len).
 *
 * The site key: 32 bytes, in a file of exactly 32 raw bytes or of 64 hex
 * digits (one final newline allowed), mode 0600 or stricter, owned by the
 * running user or root (amfi_auth_key_load).
 *
 * Thread: a signer may be shared by threads (it has a mutex); a verifier is
 * one thread's. No global state but libsodium's one-time initialisation.
 */
#ifndef AMFI_AUTH_H
#define AMFI_AUTH_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#define AMFI_AUTH_MAGIC "AMFA"
#define AMFI_AUTH_VERSION 1
#define AMFI_AUTH_KEY_BYTES 32
#define AMFI_AUTH_PRODUCER_BYTES 16
#define AMFI_AUTH_MAC_BYTES 32
#define AMFI_AUTH_TRAILER_BYTES (4 + 1 + AMFI_AUTH_PRODUCER_BYTES + 8 + AMFI_AUTH_MAC_BYTES)
/* The systemd credential's name ($CREDENTIALS_DIRECTORY/amfi-bus-key). */
#define AMFI_AUTH_CREDENTIAL "amfi-bus-key"
/* Producers a verifier remembers at once (each with its last sequence). */
#define AMFI_AUTH_MAX_PRODUCERS 256

typedef struct amfi_auth_key {
    unsigned char k[AMFI_AUTH_KEY_BYTES];
} amfi_auth_key;

/* Read the key file at path into *key. Refused, with one line in err naming
 * the file: not a regular file, group or other may read or write it (mode
 * not 0600 or stricter), owned by neither the running user nor root, neither
 * 32 raw bytes nor 64 hex digits. 0 or -1. */
int amfi_auth_key_load(const char *path, amfi_auth_key *key, char *err, size_t errlen);

/* Create a new key file at path: 32 random bytes, O_CREAT|O_EXCL, mode 0600
 * (an existing file is never overwritten). 0 or -1 with err. */
int amfi_auth_key_make(const char *path, char *err, size_t errlen);

/* Which key file: option (a command-line option) if non-empty, else config
 * (a configuration key) if non-empty, else $CREDENTIALS_DIRECTORY/amfi-bus-key
 * if that variable is set and the file exists. The path is written to buf;
 * *origin (if not NULL) says where it came from ("option", "configuration",
 * "credential"). Returns buf, or NULL when there is none. */
const char *amfi_auth_key_path(const char *option, const char *config, char *buf, size_t n,
                               const char **origin);

/* A producer's signer. */
typedef struct amfi_auth_signer {
    amfi_auth_key key;
    unsigned char producer[AMFI_AUTH_PRODUCER_BYTES];
    uint64_t last_seq;
    unsigned char *buf;
    size_t cap;
    pthread_mutex_t mu;
} amfi_auth_signer;

/* producer: 1 .. 16 characters of [A-Za-z0-9._-]. 0 or -1 with err. */
int amfi_auth_signer_init(amfi_auth_signer *s, const amfi_auth_key *key, const char *producer,
                          char *err, size_t errlen);
void amfi_auth_signer_free(amfi_auth_signer *s);

/* A producer id made of prefix and suffix, characters outside
 * [A-Za-z0-9._-] replaced by '_', cut at 16 characters. */
void amfi_auth_producer_name(char out[AMFI_AUTH_PRODUCER_BYTES + 1], const char *prefix,
                             const char *suffix);

/* Sign len bytes of an encoded message for channel into out (cap bytes,
 * at least len + AMFI_AUTH_TRAILER_BYTES; out may be data itself when the
 * buffer has room behind the message). The sequence is max(last + 1, utime)
 * (utime: µs since 1970; <= 0: the wall clock now). Returns the signed
 * length, or -1 (out too small). */
long amfi_auth_sign_into(amfi_auth_signer *s, const char *channel, const void *data, size_t len,
                         int64_t utime, unsigned char *out, size_t cap);

/* Publish on lcm: signed when s is not NULL (sequence from the wall clock),
 * else the bare message. lcm_publish's result, or -1. */
int amfi_auth_publish(lcm_t *lcm, amfi_auth_signer *s, const char *channel, const void *data,
                      size_t len);

/* Write one event (timestamp ts) to an LCM log: signed when s is not NULL,
 * the sequence from the wall clock as on the bus (a log played onto a live
 * bus soon after is accepted; the same log played later is a replay and
 * refused as skew). lcm_eventlog_write_event's result, or -1. */
int amfi_auth_log_write(lcm_eventlog_t *log, amfi_auth_signer *s, int64_t eventnum, int64_t ts,
                        const char *channel, const void *data, size_t len);

/* The length of the message without its trailer when buf ends in something
 * shaped like one (the magic and version at len - 61), else len. Nothing is
 * verified: for readers of trusted logs and for tests. */
size_t amfi_auth_bare_len(const void *buf, size_t len);

/* Why a message was refused; the names are counter labels. */
typedef enum {
    AMFI_AUTH_OK = 0,
    AMFI_AUTH_UNSIGNED,  /* "unsigned": no trailer (no magic, another version) */
    AMFI_AUTH_BAD_MAC,   /* "bad_mac": the MAC does not match (another key, altered) */
    AMFI_AUTH_REPLAY,    /* "replay": sequence not above the producer's last one */
    AMFI_AUTH_SKEW,      /* "skew": sequence further than the maximum skew from the
                            receive time */
    AMFI_AUTH_PRODUCERS, /* "producers": too many producers within the skew */
    AMFI_AUTH_NREASONS
} amfi_auth_reason;

const char *amfi_auth_reason_name(int reason);

typedef struct amfi_auth_producer_state {
    unsigned char id[AMFI_AUTH_PRODUCER_BYTES];
    uint64_t last_seq;
} amfi_auth_producer_state;

typedef struct amfi_auth_verifier {
    amfi_auth_key key;
    int64_t max_skew_us;
    int n;
    amfi_auth_producer_state p[AMFI_AUTH_MAX_PRODUCERS];
} amfi_auth_verifier;

/* max_skew_s <= 0: the time is not checked (a log replayed through LCM's
 * file:// provider, whose receive time is the wall clock of the replay, not
 * the log's); signatures and each producer's order still are. 0, or -1
 * when libsodium cannot be initialised. */
int amfi_auth_verifier_init(amfi_auth_verifier *v, const amfi_auth_key *key, double max_skew_s);

/* Verify a received message (len bytes at buf, as LCM hands it to a
 * subscriber) on channel, received at recv_utime (µs since 1970:
 * lcm_recv_buf_t.recv_utime). AMFI_AUTH_OK with *bare_len the length of the
 * encoded message (the trailer excluded) and the producer's sequence
 * advanced; else the reason, with one line in why (the producer and
 * sequence when known). A refused message changes no state. */
int amfi_auth_verify(amfi_auth_verifier *v, const char *channel, const void *buf, size_t len,
                     int64_t recv_utime, size_t *bare_len, char *why, size_t whylen);

#endif /* AMFI_AUTH_H */
