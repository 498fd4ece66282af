/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi_csv.h: the one CSV line reader of amfi (passage files, WIM traffic
 * lists, per-vehicle results), plain or gzip, with errors as one line
 * "FILE:LINE: [COLUMN: ]problem".
 *
 * It cuts lines (LF or CRLF) of at most max_line characters, counts them
 * (1-based), refuses a NUL byte inside a line (binary data), reports a
 * truncated or corrupt gzip stream, and splits a line at commas into trimmed
 * fields. What the fields mean is the caller's: it reads the header and the
 * rows and reports its own problems through amfi_csv_fail().
 *
 * Lines are cut from gzread() chunks by hand rather than with gzgets(): that
 * way a NUL byte inside a line is seen and the length limit is exact. zlib
 * reads plain files transparently; a name ending in ".gz" must hold gzip
 * data. Cost: one pass, O(bytes); the reader holds one 64 KiB chunk and one
 * line. One reader belongs to one thread.
 */
#ifndef AMFI_COMMON_CSV_H
#define AMFI_COMMON_CSV_H

#include <stddef.h>

#define AMFI_CSV_MAX_LINE 4096 /* the largest max_line, characters */

typedef struct amfi_csv amfi_csv;

/* Opens path for reading lines of at most max_line (1 .. AMFI_CSV_MAX_LINE)
 * characters without the line end. err (errlen bytes, may be NULL when
 * errlen is 0) receives every message of this reader. NULL with a message
 * ("FILE: cannot open: ...") when the file cannot be read. */
amfi_csv *amfi_csv_open(const char *path, size_t max_line, char *err, size_t errlen);

/* The next line, NUL-terminated, without CR/LF: 1 and *line, *len; 0 at the
 * end of the file; −1 on an error (message written). The line stays valid
 * until the next call. */
int amfi_csv_next(amfi_csv *r, const char **line, size_t *len);

/* The next line that is not blank (spaces and tabs only), like
 * amfi_csv_next; blank lines are allowed only at the end of the file: one
 * followed by data is an error "FILE:LINE: BLANK_MSG". */
int amfi_csv_next_row(amfi_csv *r, const char **line, size_t *len, const char *blank_msg);

/* The line number of the last line returned (1-based; 0 before the first). */
long amfi_csv_lineno(const amfi_csv *r);

/* The path the reader was opened with. */
const char *amfi_csv_path(const amfi_csv *r);

/* Writes "FILE:LINE: COLUMN: message" (without "LINE: " when line <= 0,
 * without "COLUMN: " when column is NULL) into the reader's err. Returns −1. */
int amfi_csv_fail(amfi_csv *r, long line, const char *column, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Closes the file: 0, or −1 with a message when the gzip stream turns out
 * truncated or corrupt at the end (only checked when check is nonzero).
 * NULL-safe. */
int amfi_csv_close(amfi_csv *r, int check);

/* Splits s[0 .. n) at commas into trimmed fields (spaces and tabs around a
 * field removed); stores at most max (start, length), returns how many
 * fields there are (which may exceed max). */
int amfi_csv_split(const char *s, size_t n, const char *start[], size_t flen[], int max);

/* Removes a UTF-8 byte-order mark from the start of *s. */
void amfi_csv_strip_bom(const char **s, size_t *n);

/* Parses field s[0 .. n) as a number: 0 and *v; otherwise one of
 * AMFI_CSV_EMPTY, AMFI_CSV_NOT_NUMBER, AMFI_CSV_NAN, AMFI_CSV_INF (the
 * caller words the message). */
enum { AMFI_CSV_EMPTY = 1, AMFI_CSV_NOT_NUMBER, AMFI_CSV_NAN, AMFI_CSV_INF };
int amfi_csv_field_double(const char *s, size_t n, double *v);

/* At most 24 characters of s[0 .. n), anything but printable ASCII (and the
 * quote) as '?', "..." when cut: a field shown in a one-line message. */
const char *amfi_csv_quote(const char *s, size_t n, char out[32]);

#endif
