/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_version.c: amfi_version() from the header common/version.cmake
 * generates at build time.
 */
#include "amfi_version.h"

#include "amfi_version_gen.h"

const char *amfi_version(void) { return AMFI_VERSION_STRING; }
