/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * main.c: amfid's main(): the command line, then start, run and stop
 * (amfid.c). Everything else is in the library amfid_lib, which the fuzz
 * target fuzz/fuzz_intake.c drives the same way on an in-memory bus.
 */
#include "amfid.h"

int main(int argc, char **argv)
{
    amfid_options o;
    amfid_parse_options(argc, argv, &o);
    static daemon_s d; /* large; zeroed */
    int rc = amfid_start(&d, &o);
    if (rc == 0 && !o.check_only)
        rc = amfid_run(&d);
    amfid_stop(&d);
    return rc;
}
