/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * top_inject: what a hostile or broken producer puts on the bus, for
 * amfi-top's test (tests/tools/amfi_top.sh), on LCM's default URL:
 *   1. an alert_t signed with the site key whose message and kind hold
 *      terminal escapes and control characters ("\033[2J", "\a", "\r");
 *   2. a passage_t without a signature;
 *   3. a passage_t signed with another key;
 *   4. a passage_t signed with the site key whose lengths lie (a string
 *      length past the end): refused by the checker, never decoded.
 * The site key: $CREDENTIALS_DIRECTORY/amfi-bus-key (tests/common/bus_key.sh).
 *
 *   top_inject
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_auth.h"
#include "amfi_messages.h"

static int die(const char *what)
{
    fprintf(stderr, "top_inject: %s\n", what);
    return 1;
}

int main(void)
{
    char kpath[4096], err[4400];
    amfi_auth_key key, other;
    if (!amfi_auth_key_path(NULL, NULL, kpath, sizeof kpath, NULL))
        return die("no $CREDENTIALS_DIRECTORY/amfi-bus-key");
    if (amfi_auth_key_load(kpath, &key, err, sizeof err))
        return die(err);
    for (int i = 0; i < AMFI_AUTH_KEY_BYTES; i++)
        other.k[i] = (unsigned char)(key.k[i] ^ 0x5a);
    static amfi_auth_signer good, bad;
    if (amfi_auth_signer_init(&good, &key, "test.inject", err, sizeof err) ||
        amfi_auth_signer_init(&bad, &other, "test.forger", err, sizeof err))
        return die(err);
    lcm_t *lcm = lcm_create(NULL);
    if (!lcm)
        return die("cannot open the bus");
    static unsigned char buf[65536];

    amfi_alert_t a = {.utime = 1767225600000000LL, .alert_id = 7, .level = "warning",
                      .kind = "std_\033]0;owned\a", .message = "evil\033[2J\r\nmore", .indicator_id = 3,
                      .raised = 1, .site_id = "top-1"};
    int n = amfi_alert_t_encode(buf, 0, sizeof buf, &a);
    if (n < 0 || amfi_auth_publish(lcm, &good, AMFI_CHANNEL_ALERT, buf, (size_t)n) != 0)
        return die("alert");

    double axle[2] = {4000, 6000};
    int16_t groups[2] = {1, 1};
    double gload[2] = {4000, 6000};
    amfi_passage_t p = {.utime = 1767225600000000LL, .passage_id = 900, .vehicle_id = 900, .lane = 1,
                        .speed_mps = 20, .status = "ok", .reason = "", .gvw_kg = 10000,
                        .n_axles = 2, .axle_kg = axle, .lambda = 1e-8, .residual_rms = 0.001,
                        .formulation = "modal", .solve_ms = 1, .site_id = "top-1",
                        .speed_given_mps = 20, .n_vehicles = 1, .quality = 1,
                        .reference_gvw_kg = 0, .f1_hz = 0, .f1_comp_hz = 0,
                        .vehicle_class = "R2", .n_groups = 2, .group_axles = groups,
                        .group_load_kg = gload, .overload = 0, .loads_refused = ""};
    n = amfi_passage_t_encode(buf, 0, sizeof buf, &p);
    if (n < 0 || amfi_auth_publish(lcm, NULL, AMFI_CHANNEL_PASSAGE, buf, (size_t)n) != 0 ||
        amfi_auth_publish(lcm, &bad, AMFI_CHANNEL_PASSAGE, buf, (size_t)n) != 0)
        return die("passage");
    /* the status string's length (after the 8-byte fingerprint and the
     * fields before it) made huge: signed, so only the checker stops it */
    size_t at = 8 + 8 + 8 + 8 + 2 + 8; /* utime, passage_id, vehicle_id, lane, speed_mps */
    buf[at] = 0x7f;
    if (amfi_auth_publish(lcm, &good, AMFI_CHANNEL_PASSAGE, buf, (size_t)n) != 0)
        return die("lying passage");
    /* a good passage whose loads were refused, the reason with an escape */
    p.passage_id = p.vehicle_id = 901;
    p.overload = -1;
    p.loads_refused = "group 2: 276000 kg, over ten times any legal load\033[2J";
    n = amfi_passage_t_encode(buf, 0, sizeof buf, &p);
    if (n < 0 || amfi_auth_publish(lcm, &good, AMFI_CHANNEL_PASSAGE, buf, (size_t)n) != 0)
        return die("refused passage");
    lcm_destroy(lcm);
    amfi_auth_signer_free(&good);
    amfi_auth_signer_free(&bad);
    printf("top_inject: 1 alert, 3 bad passages, 1 with its loads refused\n");
    return 0;
}
