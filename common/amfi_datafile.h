/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_datafile.h: where the programs find their shipped data files
 * (paper-20m.yaml, sim_publisher.yaml, population.csv) when none is named on
 * the command line.
 *
 * The places, in order:
 *   1. each directory of the environment variable AMFI_DATA_DIR (a list
 *      separated by ':', like PATH), for development builds, e.g.
 *      AMFI_DATA_DIR=$PWD/config:$PWD/sim_publisher/data
 *   2. SYSCONFDIR/amfi (the site's copy, e.g. /usr/local/etc/amfi)
 *   3. DATADIR/amfi (the installed copy, e.g. /usr/local/share/amfi)
 * The last two come from CMake's GNUInstallDirs at build time; no program
 * knows the source tree it was built from.
 */
#ifndef AMFI_COMMON_DATAFILE_H
#define AMFI_COMMON_DATAFILE_H

#include <stddef.h>

/* The first existing file `name` in the places above: 0 and its path in
 * buf, or −1 (buf holds "") when there is none. */
int amfi_datafile_find(const char *name, char *buf, size_t len);

/* The places searched, for --help: "$AMFI_DATA_DIR (A:B), SYSCONF, DATA"
 * (the variable shown as unset when it is). */
const char *amfi_datafile_places(char *buf, size_t len);

#endif
