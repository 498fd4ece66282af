/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * main.c: amfid's main(): the command line, then start, run and stop
 * (amfid.c). Everything else is in the library amfid_lib, which the fuzz
 * target fuzz/fuzz_intake.c drives the same way on an in-memory bus.
 */
#include <gsl/gsl_errno.h>

#include "amfid.h"

int main(int argc, char **argv)
{
    /* GSL's default error handler aborts the process. Every GSL call in
     * libamfi and the indicators checks its status or its result (a NaN
     * p-value is no alert), so a domain error must not take the daemon
     * down: errors are returned, not fatal. */
    gsl_set_error_handler_off();
    amfid_options o;
    amfid_parse_options(argc, argv, &o);
    amfid *d = NULL;
    int rc = amfid_start(&d, &o);
    if (rc == 0 && !o.check_only && !o.make_bus_key)
        rc = amfid_run(d);
    amfid_stop(d);
    return rc;
}
