/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_columns.h: the one description of the store's stored columns
 * (store_columns.c), table by table, in each table's column order (the
 * order PRAGMA table_info gives: the columns of the table's first
 * migration, then those each later ALTER TABLE added). From it come the
 * store's INSERT text and binding loop for the tables written from a row
 * struct, their argument checks, the reads of values for other programs,
 * the fleet's column rules (fleet/fleet_schema.c) and the column table of
 * docs/schema.md (amfi-store-schema --markdown; test store_schema_doc).
 *
 * The DDL stays in the migrations (store_schema.c): it is history. The
 * newest DDL's columns agree with this table (test store_columns: a fresh
 * store's PRAGMA table_info against it). Adding a column: one row here (at
 * the end of its table, `since` the new version) and one migration; the
 * field in the row struct when programs write it (docs/schema.md, "Adding
 * a column").
 *
 * Static data only; any thread.
 */
#ifndef AMFI_STORE_COLUMNS_H
#define AMFI_STORE_COLUMNS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* SQL type of a column (STRICT tables: exactly these). */
enum amfi_store_sqltype {
    AMFI_SQL_INTEGER = 'i',
    AMFI_SQL_REAL = 'r',
    AMFI_SQL_TEXT = 't',
    AMFI_SQL_BLOB = 'b' /* raw_windows.samples only (written and read by store_raw.c) */
};

/* C type of the column's field in its table's row struct. */
enum amfi_store_ctype {
    AMFI_C_NONE = 0,     /* not in the row struct: SQLite fills it (id, a
                            DEFAULT), or a table written otherwise */
    AMFI_C_I64 = 'l',    /* int64_t */
    AMFI_C_INT = 'i',    /* int */
    AMFI_C_DOUBLE = 'd', /* double */
    AMFI_C_STR = 's',    /* const char * (NUL-terminated) */
    AMFI_C_CHARS = 'c'   /* char[] inside the struct (NUL-terminated) */
};

/* When the column is NULL. */
enum amfi_store_null {
    AMFI_NULL_NEVER = 0, /* NOT NULL: the row struct must give a value (a
                            double NaN, a NULL pointer is refused) */
    AMFI_NULL_NAN,       /* double: NaN is NULL */
    AMFI_NULL_ZERO,      /* double: NaN or 0 is NULL */
    AMFI_NULL_PTR,       /* text: a NULL pointer is NULL */
    AMFI_NULL_EMPTY,     /* NOT NULL text: a NULL pointer is stored as '' */
    AMFI_NULL_FLAG,      /* double or int: NULL when the int field at flag_off is 0,
                            else a value is needed */
    AMFI_NULL_ZERO_AS,   /* NOT NULL int: 0 is stored as `zero_as` */
    AMFI_NULL_OPTIONAL,  /* integer: NULL when the value is <= 0 */
    AMFI_NULL_DB         /* filled by SQLite (AMFI_C_NONE); NULL per `null_ok` */
};

/* How a text column is checked. */
enum amfi_store_textkind {
    AMFI_TEXT_UTF8 = 0,  /* valid UTF-8 without control characters */
    AMFI_TEXT_ENUM,      /* one of `words` */
    AMFI_TEXT_TOKEN,     /* [a-z0-9_] */
    AMFI_TEXT_BYTES      /* any bytes (only the length is checked) */
};

typedef struct amfi_store_coldef {
    const char *name;
    char sql_type;       /* enum amfi_store_sqltype */
    char ctype;          /* enum amfi_store_ctype */
    char null_rule;      /* enum amfi_store_null */
    char null_ok;        /* 1: the column may hold NULL */
    size_t off;          /* offsetof the field in the row struct */
    const char *unit;    /* "kg", "m/s", "µs", "" */
    int64_t ilo, ihi;    /* INTEGER: the range */
    double lo, hi;       /* REAL: the range (hi may be HUGE_VAL) */
    char open;           /* REAL: bit 1 lo excluded, bit 2 hi excluded */
    char text_kind;      /* TEXT: enum amfi_store_textkind */
    int min_len, max_len;/* TEXT, BLOB: bytes the table holds (max_len 0: no limit) */
    int wmin, wmax;      /* TEXT: bytes the store writes, when stricter
                            (wmax 0: min_len .. max_len) */
    int cut;             /* TEXT: stored cut to this many characters (0: not) */
    const char *const *words; /* TEXT enum: the words allowed, NULL-terminated */
    const char *with;    /* NULL whenever this column (of the same row) is */
    size_t flag_off;     /* AMFI_NULL_FLAG: offsetof the int flag */
    int zero_as;         /* AMFI_NULL_ZERO_AS: what 0 is stored as */
    int since;           /* store schema version that added the column */
    int shipped;         /* central (fleet) version that added it; 0: not shipped */
    const char *meaning; /* one line, for docs/schema.md */
} amfi_store_coldef;

typedef struct amfi_store_tabledef {
    const char *name;
    const amfi_store_coldef *cols;
    int ncols;
    const char *key;     /* the column rows are ranged by (id, passage_id) */
    size_t row_size;     /* sizeof the row struct; 0: none */
} amfi_store_tabledef;

extern const amfi_store_tabledef amfi_store_tabledefs[];
extern const int amfi_store_n_tabledefs;

/* The table's description, NULL if the store has no such table. */
const amfi_store_tabledef *amfi_store_tabledef_find(const char *name);
/* Index of the column in t, or -1. */
int amfi_store_coldef_index(const amfi_store_tabledef *t, const char *name);

/* One value of a stored column, as SQLite holds it. */
typedef struct amfi_store_value {
    int type;            /* AMFI_SQL_INTEGER, AMFI_SQL_REAL, AMFI_SQL_TEXT,
                            0 NULL, AMFI_SQL_BLOB a blob (raw_windows.samples) */
    int64_t i;
    double r;
    const char *text;    /* TEXT: its bytes (NUL-terminated), len of them */
    int len;
} amfi_store_value;

/* What is wrong with v as a value of column c under the store's rules
 * (type, NULL, range, length, UTF-8, the words allowed), NULL if nothing;
 * msg (at least 160 bytes) receives the explanation returned. */
const char *amfi_store_value_problem(const amfi_store_coldef *c, const amfi_store_value *v,
                                     char *msg, size_t msglen);

/* The enum's words joined by sep ("ok|gap|..."), into buf. */
const char *amfi_store_coldef_words(const amfi_store_coldef *c, const char *sep, char *buf,
                                    size_t len);

/* The value's text as SQLite gives it (an integer in decimal, a real as
 * %.17g, text as is); buf (at least 40 bytes) holds a number's text.
 * NULL for a NULL value. */
const char *amfi_store_value_text(const amfi_store_value *v, char *buf, size_t len);

/* Writes the column table of docs/schema.md (Markdown, between its markers)
 * to f. 0, or -1 on a write error. */
#include <stdio.h>
int amfi_store_columns_markdown(FILE *f);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_STORE_COLUMNS_H */
