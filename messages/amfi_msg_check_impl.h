/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi_msg_check_impl.h: internal to messages/: the per-type wire layout
 * tables that messages/gen_msg_check.cmake generates (amfi_msg_fields.c) and
 * messages/amfi_msg_check.c walks. Not for other folders. */
#ifndef AMFI_MSG_CHECK_IMPL_H
#define AMFI_MSG_CHECK_IMPL_H

#include <stdint.h>

#include "amfi_msg_check.h"

typedef enum {
    AMFI_MSG_F_INT8,
    AMFI_MSG_F_INT16,
    AMFI_MSG_F_INT32,
    AMFI_MSG_F_INT64,
    AMFI_MSG_F_FLOAT,
    AMFI_MSG_F_DOUBLE,
    AMFI_MSG_F_BOOLEAN,
    AMFI_MSG_F_BYTE,
    AMFI_MSG_F_STRING
} amfi_msg_kind;

/* Fields per type at most (gen_msg_check.cmake refuses more). */
#define AMFI_MSG_MAX_FIELDS 64

typedef struct {
    const char *name;   /* field name as in the .lcm file */
    amfi_msg_kind kind;
    int dim_field;      /* array with a field dimension: index of the count
                           field (an earlier integer field); else -1 */
    int dim_const;      /* array with a constant dimension: the count; else 0 */
    long count_max;     /* dim_field >= 0: the count's limit (AMFI_MSG_MAX_*) */
    long string_max;    /* strings: bytes without the NUL (AMFI_MSG_MAX_*) */
} amfi_msg_field;

typedef struct {
    const char *name;              /* "vehicle_t" */
    const amfi_msg_field *fields;  /* in wire order */
    int n_fields;
    int64_t (*hash)(void);         /* lcm-gen's fingerprint */
    size_t size;                   /* sizeof the C struct */
    int (*decode)(const void *buf, int len, void *msg); /* lcm-gen's TYPE_decode */
    void (*cleanup)(void *msg);                         /* TYPE_decode_cleanup */
} amfi_msg_desc;

extern const amfi_msg_desc amfi_msg_descs[AMFI_MSG_NTYPES];

#endif /* AMFI_MSG_CHECK_IMPL_H */
