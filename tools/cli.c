/*
 * cli.c: argument helpers shared by the tools (see cli.h).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char *cli_shown(const char *s)
{
    static char buf[2][48];
    static int which;
    char *out = buf[which];
    which ^= 1;
    size_t k = 0;
    for (; s[k] && k < 40; k++)
        out[k] = ((unsigned char)s[k] < 0x20 || s[k] == 0x7f) ? '?' : s[k];
    if (s[k]) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = '\0';
    return out;
}

int cli_parse_double(const char *s, double *v)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(s, &end);
    if (end == s || *end != '\0' || !isfinite(x))
        return -1;
    *v = x;
    return 0;
}
