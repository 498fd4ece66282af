/*
 * cli.h: small helpers the command-line tools share for their arguments.
 */
#ifndef AMFI_CLI_H
#define AMFI_CLI_H

/* s for an error message: at most 40 characters, control characters as '?',
 * so that an error stays one line whatever was typed. Two rotating static
 * buffers: valid until the second call after this one; not thread-safe. */
const char *cli_shown(const char *s);

/* 0 and *v when the whole string is one finite number, −1 otherwise. */
int cli_parse_double(const char *s, double *v);

#endif
