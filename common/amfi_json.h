/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_json.h: the programs' JSON output through libjansson: one object per
 * line, keys in insertion order, numbers with 10 significant digits, NaN
 * and infinities (which JSON lacks) as null. Strings are escaped by
 * jansson, so any file name prints as valid JSON.
 */
#ifndef AMFI_COMMON_JSON_H
#define AMFI_COMMON_JSON_H

#include <jansson.h>
#include <stdio.h>

/* A real, or null when x is not finite. */
json_t *amfi_json_num(double x);

/* Writes obj compact on one line followed by '\n', then releases it
 * (json_decref). 0, or −1 when obj is NULL (out of memory while building)
 * or the write failed. */
int amfi_json_print(FILE *f, json_t *obj);

#endif
