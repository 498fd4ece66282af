/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fuzz_msg.c: libFuzzer target for one bus message type, compiled once per
 * type (fuzz/CMakeLists.txt: -DFUZZ_MSG=vehicle_t -DFUZZ_MSG_ENUM=
 * AMFI_MSG_VEHICLE_T gives fuzz_msg_vehicle_t): the raw-buffer check, lcm-gen's
 * decoder on what passes, and the decoded message encoded back, which must
 * give the input's bytes (the encoding is canonical for what the checker
 * accepts). Findings: any sanitizer report (the decoder on a buffer the
 * checker let through), a refusal with an unknown reason or without a
 * message, a checked decode that fails, a re-encoding that differs. Seeds:
 * fuzz/corpus/msg_TYPE/ (fuzz/make_corpus.sh). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_msg_check.h"

#define CAT3_(a, b, c) a##b##c
#define CAT3(a, b, c) CAT3_(a, b, c)
#define MSG_T CAT3(amfi_, FUZZ_MSG, )
#define MSG_FN(suffix) CAT3(amfi_, FUZZ_MSG, suffix)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    MSG_T m;
    char why[256] = "";
    int r = amfi_msg_decode_checked(FUZZ_MSG_ENUM, data, size, &m, why, sizeof why);
    if (r != AMFI_MSG_OK) {
        if (r == AMFI_MSG_DECODE || r < 0 || r >= AMFI_MSG_NREASONS || why[0] == 0) {
            fprintf(stderr, "fuzz_msg: reason %d (%s): %s\n", r, amfi_msg_reason_name(r), why);
            abort();
        }
        return 0;
    }
    int n = MSG_FN(_encoded_size)(&m);
    if (n != (int)size) {
        fprintf(stderr, "fuzz_msg: %zu bytes decode to a message of %d bytes\n", size, n);
        abort();
    }
    uint8_t *again = malloc(size);
    if (!again || MSG_FN(_encode)(again, 0, n, &m) != n || memcmp(again, data, size) != 0) {
        fprintf(stderr, "fuzz_msg: the decoded message does not encode back to its bytes\n");
        abort();
    }
    free(again);
    MSG_FN(_decode_cleanup)(&m);
    return 0;
}
