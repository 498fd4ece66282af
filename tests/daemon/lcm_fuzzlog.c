/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_fuzzlog: copy an LCM log of real traffic, adding COUNT mutated
 * messages spread evenly between its events: copies of earlier real
 * messages with random bytes changed, a random int16 or int32 made
 * negative or huge, cut short or lengthened, or random bytes, each on one of
 * amfid's input channels (AMFI_ACCEL, AMFI_VEHICLE, AMFI_TRUTH), with a fixed
 * seed. The bus fuzz run of issue 9 (tools/bench/amfi-bus-fuzz,
 * tests/daemon/daemon_busfuzz.sh). The real events are copied unchanged, so every
 * real vehicle must still be weighed.
 *
 * The bus authentication (messages/amfi_auth.h): every event is signed with
 * the test key (tests/common/test_bus_sign.h), the mutated ones after the mutation,
 * so that they reach amfid's decoders; and a sixteenth of the mutated
 * messages attack the authentication itself instead, in turn: written
 * without a new signature (the mutated bytes with whatever trailer they
 * have: unsigned or a wrong MAC), signed and then altered (bad_mac), or the
 * last real event again byte for byte (replay). The counts are printed.
 *
 *   lcm_fuzzlog IN.log OUT.log COUNT SEED
 */
#include <lcm/eventlog.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_messages.h"
#include "test_bus_sign.h"

static unsigned long long rng_state;
static unsigned rnd(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (unsigned)(rng_state >> 33);
}

/* Every event signed with the test key (test_bus_sign.h). */
#define put test_put

#define KEEP 64 /* recent real messages kept as seeds */
static unsigned char seed_buf[KEEP][4096];
static int seed_len[KEEP], seed_ch[KEEP], n_seeds;
static const char *const channels[3] = {AMFI_CHANNEL_ACCEL, AMFI_CHANNEL_VEHICLE, AMFI_CHANNEL_TRUTH};

static int mutate(unsigned char *b, int cap, int *ch)
{
    int len;
    if (n_seeds == 0 || rnd() % 8 == 0) { /* random bytes */
        len = (int)(rnd() % 200);
        for (int i = 0; i < len; i++)
            b[i] = (unsigned char)rnd();
        *ch = (int)(rnd() % 3);
        return len;
    }
    int s = (int)(rnd() % (unsigned)n_seeds);
    len = seed_len[s];
    memcpy(b, seed_buf[s], (size_t)len);
    *ch = rnd() % 16 == 0 ? (int)(rnd() % 3) : seed_ch[s]; /* sometimes the wrong channel */
    int kind = (int)(rnd() % 5);
    if (len <= 8)
        kind = 4;
    switch (kind) {
    case 0: /* flip a few bytes */
        for (int k = 1 + (int)(rnd() % 4); k > 0; k--)
            b[8 + rnd() % (unsigned)(len - 8)] ^= (unsigned char)(1u << (rnd() % 8));
        break;
    case 1: { /* an int16 or int32 made negative or huge */
        int at = 8 + (int)(rnd() % (unsigned)(len - 8 > 4 ? len - 12 : 1));
        unsigned v = rnd();
        b[at] = (unsigned char)(0x80 | (v & 0x7f));
        b[at + 1] = (unsigned char)(v >> 8);
        break;
    }
    case 2: /* cut short */
        len = (int)(rnd() % (unsigned)len);
        break;
    case 3: /* lengthened */
        for (int k = (int)(rnd() % 32) + 1; k > 0 && len < cap; k--)
            b[len++] = (unsigned char)rnd();
        break;
    default: /* the fingerprint */
        b[rnd() % 8] ^= 0xff;
        break;
    }
    return len;
}

int main(int argc, char **argv)
{
    if (test_sign_init("test.fuzzlog"))
        return 1;
    if (argc != 5) {
        fprintf(stderr, "usage: lcm_fuzzlog IN.log OUT.log COUNT SEED\n");
        return 2;
    }
    long long count = atoll(argv[3]);
    rng_state = (unsigned long long)atoll(argv[4]) * 2654435761ULL + 1;
    lcm_eventlog_t *in = lcm_eventlog_create(argv[1], "r");
    if (!in || count < 0) {
        fprintf(stderr, "lcm_fuzzlog: cannot read %s\n", argv[1]);
        return 1;
    }
    /* count the real events first, to spread the mutations evenly */
    long long events = 0;
    lcm_eventlog_event_t *e;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        events++;
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    in = lcm_eventlog_create(argv[1], "r");
    lcm_eventlog_t *out = lcm_eventlog_create(argv[2], "w");
    if (!in || !out || events == 0) {
        fprintf(stderr, "lcm_fuzzlog: cannot copy %s\n", argv[1]);
        return 1;
    }
    int64_t num = 0;
    long long done = 0, k = 0;
    int rc = 0;
    static unsigned char b[8192], last[8192 + AMFI_AUTH_TRAILER_BYTES];
    long long auth_raw = 0, auth_altered = 0, auth_replayed = 0;
    int last_len = 0;
    const char *last_ch = NULL;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        rc |= put(out, &num, e->timestamp, e->channel, e->data, e->datalen);
        /* what was just written, signed: replayed later */
        size_t bare = amfi_auth_bare_len(e->data, (size_t)e->datalen);
        if (test_signer && bare + AMFI_AUTH_TRAILER_BYTES <= sizeof last) {
            last_len = (int)(bare + AMFI_AUTH_TRAILER_BYTES);
            memcpy(last, test_signer->buf, (size_t)last_len);
            last_ch = channels[0];
            for (int c = 0; c < 3; c++)
                if (strcmp(e->channel, channels[c]) == 0)
                    last_ch = channels[c];
            if (strcmp(e->channel, last_ch) != 0)
                last_len = 0; /* not an input channel: not replayed */
        }
        for (int c = 0; c < 3; c++)
            if (strcmp(e->channel, channels[c]) == 0 && e->datalen <= 4096) {
                int s = n_seeds < KEEP ? n_seeds++ : (int)(rnd() % KEEP);
                memcpy(seed_buf[s], e->data, (size_t)e->datalen);
                seed_len[s] = (int)amfi_auth_bare_len(e->data, (size_t)e->datalen);
                seed_ch[s] = c;
            }
        k++;
        long long due = count * k / events;
        for (; done < due; done++) {
            int ch, len = mutate(b, sizeof b, &ch);
            unsigned attack = test_signer && rnd() % 16 == 0 ? 1 + rnd() % 3 : 0;
            if (attack == 1) { /* as mutated, no new signature */
                rc |= test_put_raw(out, &num, e->timestamp, channels[ch], b, len);
                auth_raw++;
            } else if (attack == 2) { /* signed, then one bit changed */
                static unsigned char sb[8192 + AMFI_AUTH_TRAILER_BYTES];
                long n = amfi_auth_sign_into(test_signer, channels[ch], b, (size_t)len, 0,
                                             sb, sizeof sb);
                if (n > 0) {
                    sb[rnd() % (unsigned)n] ^= (unsigned char)(1u << (rnd() % 8));
                    rc |= test_put_raw(out, &num, e->timestamp, channels[ch], sb, (int)n);
                }
                auth_altered++;
            } else if (attack == 3 && last_len > 0) { /* the last real event again */
                rc |= test_put_raw(out, &num, e->timestamp, last_ch, last, last_len);
                auth_replayed++;
            } else {
                rc |= put(out, &num, e->timestamp, channels[ch], b, len);
            }
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    lcm_eventlog_destroy(out);
    if (rc) {
        fprintf(stderr, "lcm_fuzzlog: write failed\n");
        return 1;
    }
    printf("%lld real events, %lld mutated messages (of which against the bus "
           "authentication: %lld unsigned or with a stale trailer, %lld signed then altered, "
           "%lld replays)\n",
           events, done, auth_raw, auth_altered, auth_replayed);
    return 0;
}
