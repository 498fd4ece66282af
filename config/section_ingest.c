/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_ingest.c: the ingest: section of a site file, read by
 * amfi-ingest(1) (tools/ingest/, docs/ingest.md): which MiniSEED channel
 * (NET.STA.LOC.CHA) feeds which sensor, with its gain (m/s² per count) and
 * latency; the accel blocks it publishes; the bound on a jump of the
 * data's clock; the line protocol's TCP address or serial port. amfid
 * ignores the section. Runs on the loader's thread.
 */
#include "sections.h"

#include <arpa/inet.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KIND(type, parse, range, dflt, nest, spans) {type, parse, range, dflt, nest, spans}

#define IG(m) offsetof(amfi_site_config, ingest.m)
#define CH(m) offsetof(amfi_ingest_channel, m)
#define SEED_CAP sizeof(((amfi_ingest_channel *)0)->seed)

/* 1 when s is NET.STA.LOC.CHA: network 1 .. 2, station 1 .. 5, location
 * 0 .. 2, channel 3 characters of A-Z 0-9 (SEED 2.4's fixed header). */
int amfi_config_ingest_seed_valid(const char *s)
{
    const int lo[4] = {1, 1, 0, 3}, hi[4] = {2, 5, 2, 3};
    int part = 0, len = 0;

    if (!s)
        return 0;
    for (const char *p = s;; p++) {
        if (*p == '.' || *p == '\0') {
            if (part > 3 || len < lo[part] || len > hi[part])
                return 0;
            if (*p == '\0')
                return part == 3;
            part++;
            len = 0;
        } else if ((*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9')) {
            len++;
        } else {
            return 0;
        }
    }
}

/* ingest.channels[].seed */
static int p_seed(ctx *x, yaml_node_t *v, const char *path, const field *f, void *base)
{
    char shown[SHOW_LEN + 8];
    const char *s = amfi_cfg_scalar(x, v, path, "a SEED channel id NET.STA.LOC.CHA", 1);

    if (!s)
        return -1;
    if (strlen(s) >= SEED_CAP || !amfi_config_ingest_seed_valid(s))
        return amfi_cfg_fail(x, amfi_cfg_line_of(v), path,
                             "must be NET.STA.LOC.CHA (network 1-2, station 1-5, location 0-2, "
                             "channel 3 characters of A-Z 0-9), got '%s'",
                             amfi_cfg_show(shown, sizeof shown, v));
    memset((char *)base + f->off, 0, SEED_CAP);
    memcpy((char *)base + f->off, s, strlen(s));
    return 0;
}

static void d_seed(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "NET.STA.LOC.CHA");
}

static const kind K_SEED = KIND("string", p_seed, d_seed, d_seed, NEST_NONE,
                                amfi_cfg_spans_chars);

static const field channel_fields[] = {
    {.key = "seed", .kind = &K_SEED, .off = CH(seed), .hi = SEED_CAP, .flags = F_REQUIRED},
    {.key = "sensor", .kind = &amfi_cfg_k_int, .off = CH(sensor_id), .lo = 0, .hi = 255,
     .flags = F_REQUIRED},
    {.key = "gain", .kind = &amfi_cfg_k_double, .off = CH(gain), .lo = 0, .hi = 1e6,
     .flags = F_LO_OPEN | F_REQUIRED},
    {.key = "offset_s", .kind = &amfi_cfg_k_double, .off = CH(offset_s), .lo = -60, .hi = 60},
    {.key = NULL}};

static const amfi_ingest_channel channel_default = {.seed = "", .sensor_id = 0, .gain = 1.0,
                                                    .offset_s = 0.0};

/* Item i of ingest.channels: no channel twice, no sensor fed twice. */
static int check_channel(ctx *x, const char *ip, const amfi_ingest_channel *ch, int i)
{
    char kp[PATH_LEN];

    for (int j = 0; j < i; j++) {
        if (strcmp(ch[j].seed, ch[i].seed) == 0) {
            amfi_cfg_pathf(kp, "%s.seed", ip);
            return amfi_cfg_fail(x, amfi_cfg_noted(x, kp), kp,
                                 "duplicate channel %s (also ingest.channels[%d])", ch[i].seed, j);
        }
        if (ch[j].sensor_id == ch[i].sensor_id) {
            amfi_cfg_pathf(kp, "%s.sensor", ip);
            return amfi_cfg_fail(x, amfi_cfg_noted(x, kp), kp,
                                 "sensor %d is fed by ingest.channels[%d] already: one channel "
                                 "per sensor",
                                 ch[i].sensor_id, j);
        }
    }
    return 0;
}

static void store_channels(const void *items, int n, void *base)
{
    amfi_site_config *c = base;

    memset(c->ingest.ch, 0, sizeof c->ingest.ch);
    memcpy(c->ingest.ch, items, sizeof c->ingest.ch[0] * (size_t)n);
    c->ingest.n_channels = n;
}

static int check_channel_item(ctx *x, yaml_node_t *it, const char *ip, const void *items, int i,
                              const void *base)
{
    (void)it;
    (void)base;
    return check_channel(x, ip, items, i);
}

static int s_channels(const field *f, span *out)
{
    const amfi_site_config *c = NULL;

    (void)f;
    out[0] = (span){IG(ch), sizeof c->ingest.ch};
    out[1] = (span){IG(n_channels), sizeof c->ingest.n_channels};
    return 2;
}

static void d_channels(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "1 .. %d channels", AMFI_INGEST_MAX_CHANNELS);
}

static void v_channels(const field *f, const void *base, char *buf)
{
    (void)f;
    (void)base;
    snprintf(buf, DOC_LEN, "none");
}

static const list_schema channels_list = {channel_fields,     &channel_default,
                                          sizeof channel_default, AMFI_INGEST_MAX_CHANNELS,
                                          "channels",         check_channel_item,
                                          store_channels};
static const kind K_CHANNELS = KIND("list", amfi_cfg_parse_list, d_channels, v_channels,
                                    NEST_LIST, s_channels);

static const enum_name baud_names[] = {
    {"1200", 1200},     {"2400", 2400},     {"4800", 4800},     {"9600", 9600},
    {"19200", 19200},   {"38400", 38400},   {"57600", 57600},   {"115200", 115200},
    {"230400", 230400}, {"460800", 460800}, {"921600", 921600}, {NULL, 0}};

static const field line_fields[] = {
    {.key = "listen", .kind = &amfi_cfg_k_string, .off = IG(listen), .lo = 0,
     .hi = sizeof(((amfi_ingest_config *)0)->listen)},
    {.key = "serial", .kind = &amfi_cfg_k_path, .off = IG(serial),
     .hi = sizeof(((amfi_ingest_config *)0)->serial)},
    {.key = "baud", .kind = &amfi_cfg_k_enum, .off = IG(baud), .aux = baud_names},
    {.key = "offset_s", .kind = &amfi_cfg_k_double, .off = IG(line_offset_s), .lo = -60,
     .hi = 60},
    {.key = "source", .kind = &amfi_cfg_k_string, .off = IG(source), .lo = 1,
     .hi = sizeof(((amfi_ingest_config *)0)->source)},
    {.key = "max_clients", .kind = &amfi_cfg_k_int, .off = IG(max_clients), .lo = 1, .hi = 64},
    {.key = NULL}};

const field amfi_cfg_ingest_fields[] = {
    {.key = "producer", .kind = &amfi_cfg_k_string, .off = IG(producer), .lo = 1,
     .hi = sizeof(((amfi_ingest_config *)0)->producer)},
    {.key = "block", .kind = &amfi_cfg_k_int, .off = IG(block), .lo = 1, .hi = 160},
    {.key = "max_jump_s", .kind = &amfi_cfg_k_double, .off = IG(max_jump_s), .lo = 0,
     .hi = 86400, .flags = F_LO_OPEN},
    {.key = "channels", .kind = &K_CHANNELS, .aux = &channels_list},
    {.key = "line", .kind = &amfi_cfg_k_map, .aux = line_fields},
    {.key = NULL}};

void amfi_config_ingest_defaults(amfi_ingest_config *g)
{
    memset(g, 0, sizeof *g);
    strcpy(g->producer, "ingest");
    g->block = 100;
    g->max_jump_s = 10.0;
    strcpy(g->listen, "127.0.0.1:7670");
    g->baud = 9600;
    g->line_offset_s = 0.0;
    strcpy(g->source, "amfi-ingest");
    g->max_clients = 8;
}

int amfi_config_ingest_listen_parse(const char *s, char host[64], int *port)
{
    const char *colon = s ? strrchr(s, ':') : NULL;
    struct in_addr a;
    char *end;
    long p;

    if (!colon || colon == s || (size_t)(colon - s) >= 64)
        return -1;
    memcpy(host, s, (size_t)(colon - s));
    host[colon - s] = '\0';
    if (inet_pton(AF_INET, host, &a) != 1)
        return -1;
    p = strtol(colon + 1, &end, 10);
    if (end == colon + 1 || *end || p < 1 || p > 65535)
        return -1;
    *port = (int)p;
    return 0;
}

/* Each channel feeds a sensor of sensors:; the producer id is the bus's
 * (1 .. 16 of A-Z a-z 0-9 . _ -); the address is IPv4:PORT or empty. */
int amfi_cfg_ingest_check(ctx *x, amfi_site_config *c)
{
    amfi_ingest_config *g = &c->ingest;
    char kp[PATH_LEN], host[64];
    int port;

    for (int i = 0; i < g->n_channels; i++) {
        int found = 0;
        for (int s = 0; s < c->solver.n_sensors; s++)
            found |= c->sensor_id[s] == g->ch[i].sensor_id;
        if (!found) {
            amfi_cfg_pathf(kp, "ingest.channels[%d].sensor", i);
            return amfi_cfg_fail(x, amfi_cfg_noted(x, kp), kp, "sensor %d is not in sensors:",
                                 g->ch[i].sensor_id);
        }
    }
    for (const char *p = g->producer; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
              *p == '.' || *p == '_' || *p == '-'))
            return amfi_cfg_fail(x, amfi_cfg_noted(x, "ingest.producer"), "ingest.producer",
                                 "must be 1 .. 16 characters of A-Z a-z 0-9 . _ -, got '%s'",
                                 g->producer);
    if (g->listen[0] && amfi_config_ingest_listen_parse(g->listen, host, &port))
        return amfi_cfg_fail(x, amfi_cfg_noted(x, "ingest.line.listen"), "ingest.line.listen",
                             "must be IPV4-ADDRESS:PORT (port 1 .. 65535) or empty, got '%s'",
                             g->listen);
    return 0;
}
