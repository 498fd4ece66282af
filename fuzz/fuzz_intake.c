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
 * record cut short is published as far as it goes. After each message amfid
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
#include <unistd.h>

#include "amfid.h"

#ifndef FUZZ_INTAKE_CONFIG
#error "FUZZ_INTAKE_CONFIG (fuzz/intake.yaml) must be defined"
#endif

static char db[256];

static void remove_store(void)
{
    static const char *const suffix[] = {"", "-wal", "-shm", "-journal"};
    char p[300];
    for (int i = 0; i < 4; i++) {
        snprintf(p, sizeof p, "%s%s", db, suffix[i]);
        unlink(p);
    }
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *tmp = getenv("TMPDIR");
    snprintf(db, sizeof db, "%s/fuzz_intake.%ld.db", tmp && *tmp ? tmp : "/tmp", (long)getpid());
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
    static daemon_s d;
    amfid_options o = {FUZZ_INTAKE_CONFIG, db, "memq://", 0};

    memset(&d, 0, sizeof d);
    remove_store();
    if (amfid_start(&d, &o) != 0)
        finding("amfid_start failed", 0, 0);
    const char *ch[4] = {d.cfg.daemon.ch_accel, d.cfg.daemon.ch_vehicle, d.cfg.daemon.ch_truth,
                         d.cfg.daemon.ch_environment};
    size_t at = 0;
    while (at < size) {
        int c = data[at] % 4;
        size_t len = at + 2 < size ? (size_t)data[at + 1] | (size_t)data[at + 2] << 8 : 0;
        at += 3;
        if (at > size)
            break;
        if (len > size - at)
            len = size - at;
        lcm_publish(d.lcm, ch[c], data + at, (unsigned)len);
        at += len;
        while (lcm_handle_timeout(d.lcm, 0) > 0)
            ;
        release_windows(&d, 0);
        pipeline_drain_results(&d);
        if (d.held_n > 0)
            pipeline_retry(&d, 0);
    }
    if (amfid_drain(&d) != 0)
        finding("amfid_drain failed: passages lost", d.passages_lost, 0);
    int64_t rows = -1, truth = -1;
    char err[256];
    if (amfi_store_count(d.store, AMFI_STORE_PASSAGES, &rows, err, sizeof err) ||
        amfi_store_count(d.store, AMFI_STORE_TRUTH, &truth, err, sizeof err))
        finding("store count failed", 0, 0);
    if (rows != d.vehicles_received)
        finding("stored passages != vehicles received", rows, d.vehicles_received);
    if (rows != d.passages_stored)
        finding("stored passages != the daemon's counter", rows, d.passages_stored);
    if (truth != d.truth_received)
        finding("truth rows != truth accepted", truth, d.truth_received);
    amfid_stop(&d);
    return 0;
}
