/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * intake_seed_dump: a fuzz_intake seed (tests/lcm_intake_seed: records
 * [u8 channel][u16 length LE][bytes]) as text, one line per record, every
 * message decoded with the raw-buffer checker (amfi_msg_decode_checked) and
 * every field written (doubles with %.17g). Exit 1, naming the file and
 * the record, when a record is cut short, has an unknown channel or does
 * not decode as today's type (a stale fingerprint). Used by
 * tests/fuzz/fuzz_corpus.sh, which compares a committed seed with one written
 * again numerically (tests/common/num_cmp.sh), not byte for byte: the samples
 * are simulator output, whose last bits differ between CPUs.
 *
 *   intake_seed_dump SEED
 */
#include <stdio.h>
#include <stdlib.h>

#include "amfi_msg_check.h"

static void doubles(const char *name, const double *v, int n)
{
    printf(" %s=[", name);
    for (int i = 0; i < n; i++)
        printf("%s%.17g", i ? " " : "", v[i]);
    printf("]");
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: intake_seed_dump SEED\n");
        return 2;
    }
    const char *path = argv[1];
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return 1;
    }
    static unsigned char buf[65536];
    char why[256];
    long k = 0;
    int rc = 0;
    for (;; k++) {
        unsigned char h[3];
        size_t got = fread(h, 1, 3, f);
        if (got == 0)
            break;
        if (got != 3) {
            fprintf(stderr, "%s: record %ld: header cut short\n", path, k);
            rc = 1;
            break;
        }
        size_t len = (size_t)h[1] | (size_t)h[2] << 8;
        if (fread(buf, 1, len, f) != len) {
            fprintf(stderr, "%s: record %ld: %zu bytes announced, fewer there\n", path, k, len);
            rc = 1;
            break;
        }
        int st = 0;
        switch (h[0]) {
        case 0: {
            amfi_accel_block_t m;
            if ((st = amfi_msg_decode_accel_block_t(buf, len, &m, why, sizeof why)) != 0)
                break;
            printf("%ld accel utime=%lld sensor_id=%d seq=%lld sample_rate_hz=%.17g n=%d", k,
                   (long long)m.utime, (int)m.sensor_id, (long long)m.seq, m.sample_rate_hz,
                   (int)m.n);
            doubles("accel", m.accel, m.n);
            amfi_accel_block_t_decode_cleanup(&m);
            break;
        }
        case 1: {
            amfi_vehicle_t m;
            if ((st = amfi_msg_decode_vehicle_t(buf, len, &m, why, sizeof why)) != 0)
                break;
            printf("%ld vehicle utime=%lld vehicle_id=%lld lane=%d speed_mps=%.17g n_axles=%d "
                   "n_spacings=%d",
                   k, (long long)m.utime, (long long)m.vehicle_id, (int)m.lane, m.speed_mps,
                   (int)m.n_axles, (int)m.n_spacings);
            doubles("axle_spacing_m", m.axle_spacing_m, m.n_spacings);
            printf(" source=%s reference_gvw_kg=%.17g", m.source, m.reference_gvw_kg);
            amfi_vehicle_t_decode_cleanup(&m);
            break;
        }
        case 2: {
            amfi_truth_t m;
            if ((st = amfi_msg_decode_truth_t(buf, len, &m, why, sizeof why)) != 0)
                break;
            printf("%ld truth utime=%lld vehicle_id=%lld gvw_kg=%.17g n_axles=%d", k,
                   (long long)m.utime, (long long)m.vehicle_id, m.gvw_kg, (int)m.n_axles);
            doubles("axle_kg", m.axle_kg, m.n_axles);
            doubles("mean_force_N", m.mean_force_N, m.n_axles);
            printf(" speed_true_mps=%.17g", m.speed_true_mps);
            amfi_truth_t_decode_cleanup(&m);
            break;
        }
        case 3: {
            amfi_environment_t m;
            if ((st = amfi_msg_decode_environment_t(buf, len, &m, why, sizeof why)) != 0)
                break;
            printf("%ld environment utime=%lld air_c=%.17g deck_c=%.17g", k, (long long)m.utime,
                   m.air_c, m.deck_c);
            amfi_environment_t_decode_cleanup(&m);
            break;
        }
        default:
            fprintf(stderr,
                    "%s: record %ld: channel %d (0..3: accel, vehicle, truth, environment)\n",
                    path, k, h[0]);
            rc = 1;
            break;
        }
        if (rc)
            break;
        if (st != 0) {
            fprintf(stderr, "%s: record %ld (channel %d): refused, %s: %s\n", path, k, h[0],
                    amfi_msg_reason_name(st), why);
            rc = 1;
            break;
        }
        printf("\n");
    }
    fclose(f);
    return rc;
}
