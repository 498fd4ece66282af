/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_version.h: the one version string of every amfi program: the CMake
 * project version, plus "+" and `git describe --always --dirty` when the
 * program was built from a git checkout (e.g. "0.1.0+deaaffa-dirty").
 */
#ifndef AMFI_COMMON_VERSION_H
#define AMFI_COMMON_VERSION_H

const char *amfi_version(void);

#endif
