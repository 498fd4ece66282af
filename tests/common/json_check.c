/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * json_check: reads one JSON document on stdin with libjansson and checks
 * that it parses and, for each KEY=VALUE argument, that the object's
 * string member KEY equals VALUE. Exit 0 ok, 1 with a message otherwise.
 * Used by mkcase_json.sh (the tools' JSON must survive any file name).
 */
#include <jansson.h>
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    json_error_t e;
    json_t *doc = json_loadf(stdin, 0, &e);
    if (!doc) {
        fprintf(stderr, "json_check: line %d column %d: %s\n", e.line, e.column, e.text);
        return 1;
    }
    int rc = 0;
    for (int i = 1; i < argc; i++) {
        const char *eq = strchr(argv[i], '=');
        if (!eq) {
            fprintf(stderr, "json_check: %s: expected KEY=VALUE\n", argv[i]);
            rc = 1;
            continue;
        }
        char key[128];
        snprintf(key, sizeof key, "%.*s", (int)(eq - argv[i]), argv[i]);
        const char *got = json_string_value(json_object_get(doc, key));
        if (!got || strcmp(got, eq + 1) != 0) {
            fprintf(stderr, "json_check: %s is '%s', expected '%s'\n", key, got ? got : "(none)",
                    eq + 1);
            rc = 1;
        }
    }
    json_decref(doc);
    return rc;
}
