/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_intake.c: libFuzzer target for amfid's own message handlers: the
 * whole daemon (amfid_lib: intake, rings, tracker, solver thread, in-order
 * pipeline, store, indicators, alerts) started from fuzz/intake.yaml on
 * LCM's in-memory bus (memq://) with a fresh store, fed the input as a
 * sequence of bus messages, drained and stopped; one daemon life per input,
 * so that an input reproduces alone.
 *
 * Input: records [u8 channel][u16 length, little-endian][length bytes]; the
 * channel byte modulo 4 picks AMFI_ACCEL, AMFI_VEHICLE, AMFI_TRUTH or
 * AMFI_ENVIRONMENT; a
 * record cut short is published as far as it goes. The bus authentication
 * (daemon.bus.auth: required, a key made here) is in the way as on a site:
 * bits 2-3 of the channel byte pick how the bytes are published: 0 signed
 * with the key (so that they reach the decoders), 1 as they are (unsigned,
 * or with a trailer of their own), 2 signed and then one bit flipped (the
 * channel byte's bits 4-7 and the length pick it), 3 the previous signed
 * message again (a replay). After each message amfid
 * does what its loop does (handle, release windows, complete results, retry).
 * Seeds: fuzz/corpus/intake/ (fuzz/make_corpus.sh: sim_publisher traffic
 * converted by tests/lcm_intake_seed, plus damaged variants).
 *
 * Findings: any sanitizer report, and the daemon's own promises broken:
 * start or drain failing; a decoded vehicle without its stored passage
 * (rows == vehicles received, nothing lost, the counter equal to the
 * table); truth rows not equal to the truth accepted.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amfid.h"

#ifndef FUZZ_INTAKE_CONFIG
#error "FUZZ_INTAKE_CONFIG (fuzz/intake.yaml) must be defined"
#endif

static char db[256], keyfile[256];
/* the site key of the fuzzed daemon and of the records it is fed */
static const unsigned char fuzz_key[AMFI_AUTH_KEY_BYTES] = "amfi fuzz_intake bus key 32 byt";

static void remove_store(void)
{
    static const char *const suffix[] = {"", "-wal", "-shm", "-journal"};
    char p[300];
    for (int i = 0; i < 4; i++) {
        snprintf(p, sizeof p, "%s%s", db, suffix[i]);
        unlink(p);
    }
}

static void remove_key(void)
{
    unlink(keyfile);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *tmp = getenv("TMPDIR");
    snprintf(db, sizeof db, "%s/fuzz_intake.%ld.db", tmp && *tmp ? tmp : "/tmp", (long)getpid());
    snprintf(keyfile, sizeof keyfile, "%s/fuzz_intake.%ld.key", tmp && *tmp ? tmp : "/tmp",
             (long)getpid());
    unlink(keyfile);
    FILE *kf = fopen(keyfile, "wx");
    if (!kf || chmod(keyfile, 0600) != 0 ||
        fwrite(fuzz_key, 1, sizeof fuzz_key, kf) != sizeof fuzz_key || fclose(kf) != 0)
        abort();
    atexit(remove_key);
    /* FUZZ_INTAKE_LOG=1: amfid's log on stderr, to study a finding */
    const char *log = getenv("FUZZ_INTAKE_LOG");
    amfid_log_stream = log && *log == '1' ? stderr : fopen("/dev/null", "w");
    if (!amfid_log_stream)
        abort();
    atexit(remove_store);
    return 0;
}

static void finding(const char *what, long long a, long long b)
{
    fprintf(stderr, "fuzz_intake: %s (%lld, %lld)\n", what, a, b);
    abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    amfid *d = NULL;
    amfid_options o = {.config = FUZZ_INTAKE_CONFIG, .db = db, .lcm_url = "memq://",
                       .bus_key = keyfile};
    static amfi_auth_signer signer;
    static int signer_ready;
    static unsigned char sb[65536 + AMFI_AUTH_TRAILER_BYTES];
    static unsigned char prev[65536 + AMFI_AUTH_TRAILER_BYTES];
    long prev_len = 0;
    int prev_c = 0;
    if (!signer_ready) {
        amfi_auth_key k;
        memcpy(k.k, fuzz_key, sizeof k.k);
        char err[256];
        if (amfi_auth_signer_init(&signer, &k, "fuzz", err, sizeof err))
            finding("signer", 0, 0);
        signer_ready = 1;
    }

    remove_store();
    if (amfid_start(&d, &o) != 0)
        finding("amfid_start failed", 0, 0);
    const amfi_daemon_config *dc = &amfid_config(d)->daemon;
    const char *ch[4] = {dc->ch_accel, dc->ch_vehicle, dc->ch_truth, dc->ch_environment};
    lcm_t *lcm = amfid_lcm(d);
    size_t at = 0;
    while (at < size) {
        int c = data[at] % 4, how = (data[at] >> 2) % 4, bit = data[at] >> 4;
        size_t len = at + 2 < size ? (size_t)data[at + 1] | (size_t)data[at + 2] << 8 : 0;
        at += 3;
        if (at > size)
            break;
        if (len > size - at)
            len = size - at;
        long n = how == 1 ? 0
                          : amfi_auth_sign_into(&signer, ch[c], data + at, len, 0, sb, sizeof sb);
        if (how == 1 || n < 0) {
            lcm_publish(lcm, ch[c], data + at, (unsigned)len);
        } else if (how == 3 && prev_len > 0) {
            lcm_publish(lcm, ch[prev_c], prev, (unsigned)prev_len);
        } else {
            if (how == 2)
                sb[((size_t)bit * 131 + len) % (size_t)n] ^= (unsigned char)(1u << (bit % 8));
            else {
                memcpy(prev, sb, (size_t)n);
                prev_len = n;
                prev_c = c;
            }
            lcm_publish(lcm, ch[c], sb, (unsigned)n);
        }
        at += len;
        amfid_turn(d); /* the messages handled, windows released, results stored */
    }
    amfid_stats st;
    if (amfid_drain(d) != 0) {
        amfid_counts(d, &st);
        finding("amfid_drain failed: passages lost", st.passages_lost, 0);
    }
    amfid_counts(d, &st);
    int64_t rows = -1, truth = -1;
    char err[256];
    if (amfi_store_count(amfid_store(d), AMFI_STORE_PASSAGES, &rows, err, sizeof err) ||
        amfi_store_count(amfid_store(d), AMFI_STORE_TRUTH, &truth, err, sizeof err))
        finding("store count failed", 0, 0);
    if (rows != st.vehicles_received)
        finding("stored passages != vehicles received", rows, st.vehicles_received);
    if (rows != st.passages_stored)
        finding("stored passages != the daemon's counter", rows, st.passages_stored);
    if (truth != st.truth_received)
        finding("truth rows != truth accepted", truth, st.truth_received);
    amfid_stop(d);
    return 0;
}
