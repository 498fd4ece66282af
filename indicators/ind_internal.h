/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ind_internal.h: helpers shared by the parameter checks of the
 * indicators (scale.c, known_truck.c, level_rule.c, speed_drift.c) and
 * their one-line records (record.c); not installed, not part of the API.
 * Pure functions.
 */
#ifndef AMFI_INDICATORS_INTERNAL_H
#define AMFI_INDICATORS_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "indicators.h"

/* 1 when v is finite and in [lo, hi]. */
static inline int ind_in(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

/* Blame parameter `name` of indicator `who`: *field (may be NULL) = name,
 * err (may be NULL) = "who: name why"; returns AMFI_IND_EINVAL. */
static inline int ind_bad(const char *who, const char *name, const char **field, char *err,
                          size_t errlen, const char *why)
{
    if (field)
        *field = name;
    if (err && errlen)
        snprintf(err, errlen, "%s: %s %s", who, name, why);
    return AMFI_IND_EINVAL;
}

/* In a parameter check with `field` and `err`, `errlen` in scope: *field
 * (may be NULL) = name, err (may be NULL) = the printf message; returns
 * AMFI_IND_EINVAL from the function. */
#define IND_BLAME(name, ...)                                                                  \
    do {                                                                                      \
        if (field)                                                                            \
            *field = name;                                                                    \
        if (err && errlen)                                                                    \
            snprintf(err, errlen, __VA_ARGS__);                                               \
        return AMFI_IND_EINVAL;                                                               \
    } while (0)

/* A parameter struct's int and double fields, for its one-line record
 * "key=value key=value ..." (record.c). */
typedef struct ind_field {
    const char *key;
    size_t off;  /* offsetof in the struct */
    int is_int;  /* 1: int, 0: double */
} ind_field;
#define IND_RECORD_MAX_FIELDS 32

/* The record of obj's fields in table order, doubles with 17 digits;
 * AMFI_IND_EINVAL (buf "") when it does not fit in len. */
int ind_record_format(const ind_field *fields, size_t n, const void *obj, char *buf, size_t len);

/* Fill obj's fields from a record: every field exactly once, in any order;
 * AMFI_IND_EINVAL naming the field (unknown, twice, not a number, trailing
 * text, missing). obj is written field by field: parse into a scratch copy. */
int ind_record_parse(const ind_field *fields, size_t n, const char *s, void *obj, char *err,
                     size_t errlen);

#endif
