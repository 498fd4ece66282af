/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * web.h: amfi-web, the read-only web dashboard and JSON API over a site's
 * store or one site of the central PostgreSQL (docs/web.md). Files:
 * amfi-web.c (options, the HTTP server on libmicrohttpd, routing, headers,
 * the central database's copy), web_api.c (the JSON API: parameters checked
 * and answered from store.h's reads), web_time.c (times in and out),
 * web_raw.c (a passage's raw samples, bounded for a browser) and
 * web_assets.c (generated at build time: the pages, the script and the
 * style sheet, embedded). One thread serves every request, so the store
 * handle is used by one thread at a time (store.h).
 */
#ifndef AMFI_WEB_H
#define AMFI_WEB_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "store.h"

/* What the API answers from. */
typedef struct web_source {
    amfi_store *store;   /* read-only handle */
    const char *kind;    /* "store" or "central" */
    const char *name;    /* the store's path, or the site (central) */
    int64_t as_of_us;    /* central: when the copy was fetched (wall clock); 0 store */
} web_source;

/* One query parameter (name=value, both unescaped by libmicrohttpd). */
typedef struct web_param {
    const char *name, *value;
} web_param;

/* An answer: HTTP status and a JSON body (owned). */
typedef struct web_reply {
    unsigned status;
    json_t *body;
} web_reply;

/* Answers GET path (starting "/api/") with the parameters p[0 .. np − 1].
 * A parameter that is unknown, repeated or invalid gives 400 with
 * {"error": ..., "parameter": NAME}; an unknown path 404; a store error
 * 500. */
web_reply web_api(const web_source *src, const char *path, const web_param *p, int np);

/* {"error": msg, "parameter": name (when not NULL)} */
json_t *web_error(const char *msg, const char *name);

/* ---- times (web_time.c) -------------------------------------------------- */

/* s: ISO-8601 UTC (YYYY-MM-DD, YYYY-MM-DDTHH:MM[:SS[.ffffff]][Z]) or
 * seconds since 1970 (digits, optional fraction) into µs. 0, or −1. */
int web_parse_time(const char *s, int64_t *utime);
/* µs since 1970 as "YYYY-MM-DDTHH:MM:SS.ffffffZ" (buf >= 32 bytes). */
const char *web_format_time(int64_t utime, char *buf, size_t len);
/* Wall clock, µs since 1970. */
int64_t web_now_us(void);

/* ---- raw samples (web_raw.c) --------------------------------------------- */

/* The raw samples of passage p, at most 4000 points per sensor (min/max per
 * bucket beyond), or NULL with why (whylen bytes) saying why there are none:
 * the central database, never weighed, not kept, not kept or deleted by the
 * retention, damaged (named). */
json_t *web_raw(const web_source *src, const amfi_web_passage *p, char *why, size_t whylen);

/* ---- embedded files (web_assets.c, generated) ---------------------------- */

typedef struct web_asset {
    const char *path;           /* URL path, "/", "/static/app.js", ... */
    const char *content_type;
    const unsigned char *data;
    size_t len;
} web_asset;

extern const web_asset web_assets[];
extern const int web_n_assets;

#endif
