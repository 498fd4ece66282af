/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * record.c: a parameter struct as one line of "key=value" pairs and back
 * (ind_internal.h), from a table of its int and double fields: what amfid
 * records in the store's meta table for the STD and mean rules
 * (amfi_indicator_params_format/parse) and for the median level rules
 * (amfi_level_params_format/parse). Doubles are written with 17 digits, so
 * a record read back is the struct written.
 */
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "ind_internal.h"

int ind_record_format(const ind_field *fields, size_t n, const void *obj, char *buf, size_t len)
{
    size_t at = 0;
    if (!obj || !buf || len == 0)
        return AMFI_IND_EINVAL;
    buf[0] = '\0';
    for (size_t i = 0; i < n; i++) {
        const char *f = (const char *)obj + fields[i].off;
        int k = fields[i].is_int
                    ? snprintf(buf + at, len - at, "%s%s=%d", i ? " " : "", fields[i].key,
                               *(const int *)(const void *)f)
                    : snprintf(buf + at, len - at, "%s%s=%.17g", i ? " " : "", fields[i].key,
                               *(const double *)(const void *)f);
        if (k < 0 || (size_t)k >= len - at) {
            buf[0] = '\0';
            return AMFI_IND_EINVAL;
        }
        at += (size_t)k;
    }
    return AMFI_IND_OK;
}

#define PARSE_FAIL(...)                                                                       \
    do {                                                                                      \
        if (err && errlen)                                                                    \
            snprintf(err, errlen, __VA_ARGS__);                                               \
        return AMFI_IND_EINVAL;                                                               \
    } while (0)

int ind_record_parse(const ind_field *fields, size_t n, const char *s, void *obj, char *err,
                     size_t errlen)
{
    int seen[IND_RECORD_MAX_FIELDS] = {0};
    if (!s || !obj)
        PARSE_FAIL("NULL argument");
    if (n > IND_RECORD_MAX_FIELDS)
        PARSE_FAIL("%zu fields: at most %d", n, IND_RECORD_MAX_FIELDS);
    const char *c = s;
    while (*c) {
        while (*c == ' ')
            c++;
        if (!*c)
            break;
        const char *eq = strchr(c, '=');
        size_t i = 0, kl = eq ? (size_t)(eq - c) : 0;
        for (; eq && i < n; i++)
            if (strlen(fields[i].key) == kl && strncmp(c, fields[i].key, kl) == 0)
                break;
        if (!eq || i == n)
            PARSE_FAIL("unknown field at '%.40s'", c);
        if (seen[i]++)
            PARSE_FAIL("%s given twice", fields[i].key);
        char *end = NULL;
        errno = 0;
        void *f = (char *)obj + fields[i].off;
        if (fields[i].is_int) {
            long v = strtol(eq + 1, &end, 10);
            if (end == eq + 1 || errno || v < INT_MIN || v > INT_MAX)
                PARSE_FAIL("%s: not an integer", fields[i].key);
            *(int *)f = (int)v;
        } else {
            double v = strtod(eq + 1, &end);
            if (end == eq + 1 || errno)
                PARSE_FAIL("%s: not a number", fields[i].key);
            *(double *)f = v;
        }
        if (*end != ' ' && *end != '\0')
            PARSE_FAIL("%s: trailing text '%.20s'", fields[i].key, end);
        c = end;
    }
    for (size_t i = 0; i < n; i++)
        if (!seen[i])
            PARSE_FAIL("%s missing", fields[i].key);
    return AMFI_IND_OK;
}
