/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bus.c: amfid's LCM bus: the URL it opens (for a udpm:// bus, LCM's
 * recv_buf_size option from daemon.recv_buf_bytes, checked against the
 * kernel's cap net.core.rmem_max with a warning that says what to set), and
 * the datagrams the kernel dropped on amfid's own UDP sockets, read from
 * /proc/net/udp (and udp6): the loss nobody else can see. And the bus
 * authentication (messages/amfi_auth.h, docs/messages.md): every input is
 * subscribed through bus_subscribe, which refuses (counts per channel and
 * reason, reject.c) unsigned, wrongly signed, replayed and time-skewed
 * messages when daemon.bus.auth is required, before any decoder sees them;
 * what amfid publishes is signed.
 *
 * The modules say what they want to hear (bus_want, from their restore);
 * amfid.c subscribes it all once the bus is open (bus_subscribe_all).
 *
 * Thread: the main thread (start-up, the bus handlers, the heartbeat);
 * bus_publish also from wherever amfid publishes (the signer has a mutex).
 * Owns the LCM handle, the verifier, the signer and the subscriptions.
 */
#include <dirent.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ctx.h"

#define LCM_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"

static long read_long(const char *path)
{
    FILE *f = fopen(path, "r");
    long v = -1;
    if (f) {
        if (fscanf(f, "%ld", &v) != 1)
            v = -1;
        fclose(f);
    }
    return v;
}

void bus_url(const amfi_daemon_config *dc, char *url, size_t n)
{
    snprintf(url, n, "%s", dc->lcm_url[0] ? dc->lcm_url : LCM_DEFAULT_URL);
    if (strncmp(url, "udpm://", 7) != 0 || dc->recv_buf_bytes <= 0)
        return;
    if (!strstr(url, "recv_buf_size=")) {
        size_t len = strlen(url);
        snprintf(url + len, n - len, "%crecv_buf_size=%d", strchr(url, '?') ? '&' : '?',
                 dc->recv_buf_bytes);
    }
    long cap = read_long("/proc/sys/net/core/rmem_max");
    if (cap > 0 && cap < dc->recv_buf_bytes)
        LOG_WARN("the kernel caps UDP receive buffers at %ld bytes (net.core.rmem_max), below "
                 "daemon.recv_buf_bytes %d: bursts may be dropped (counted as "
                 "datagrams_dropped); set 'sysctl -w net.core.rmem_max=%d' and keep it in "
                 "/etc/sysctl.d/",
                 cap, dc->recv_buf_bytes, dc->recv_buf_bytes);
}

/* Is inode one of this process's sockets? (a short list, read once a call) */
static int own_socket(const unsigned long *inodes, int n, unsigned long ino)
{
    for (int i = 0; i < n; i++)
        if (inodes[i] == ino)
            return 1;
    return 0;
}

int64_t bus_udp_drops(void)
{
    unsigned long inodes[64];
    int n = 0;
    DIR *dir = opendir("/proc/self/fd");
    if (!dir)
        return -1;
    struct dirent *e;
    char path[300], target[64];
    while ((e = readdir(dir)) != NULL && n < 64) {
        snprintf(path, sizeof path, "/proc/self/fd/%s", e->d_name);
        ssize_t k = readlink(path, target, sizeof target - 1);
        if (k <= 0)
            continue;
        target[k] = '\0';
        unsigned long ino;
        if (sscanf(target, "socket:[%lu]", &ino) == 1)
            inodes[n++] = ino;
    }
    closedir(dir);
    int64_t drops = 0;
    const char *tables[] = {"/proc/net/udp", "/proc/net/udp6"};
    for (int t = 0; t < 2; t++) {
        FILE *f = fopen(tables[t], "r");
        if (!f)
            continue;
        char line[512];
        if (!fgets(line, sizeof line, f)) { /* header */
            fclose(f);
            continue;
        }
        while (fgets(line, sizeof line, f)) {
            /* sl local rem st tx:rx tr:when retr uid timeout inode ref ptr drops */
            unsigned long ino = 0;
            long long dr = 0;
            if (sscanf(line, "%*s %*s %*s %*s %*s %*s %*s %*s %*s %lu %*s %*s %lld", &ino,
                       &dr) == 2 &&
                own_socket(inodes, n, ino))
                drops += dr;
        }
        fclose(f);
    }
    return drops;
}

/* ---- the authenticated bus ---------------------------------------------- */

static struct {
    lcm_t *lcm;
    amfi_auth_verifier *auth;  /* daemon.bus.auth required; NULL: off */
    amfi_auth_signer *signer;  /* NULL: no key, amfid publishes unsigned */
    int64_t auth_refused;      /* messages refused by the authentication */
    struct bus_sub {
        amfid_ctx *c;
        lcm_msg_handler_t fn;   /* NULL: not wanted */
        const char *channel;
        int input;
    } subs[REJECT_NINPUTS];
} B;

lcm_t *bus_lcm(void)
{
    return B.lcm;
}

/* The authentication: 0, or 2 (reported). */
static int auth_start(amfid_ctx *c, const char *key_option)
{
    const amfi_daemon_config *dc = &c->cfg->daemon;
    char path[PATH_MAX], err[PATH_MAX + 200];
    const char *origin = NULL;
    const char *kp = amfi_auth_key_path(key_option, dc->bus_key_file, path, sizeof path, &origin);
    if (!kp && dc->bus_auth) {
        LOG_ERR("daemon.bus.auth is required but there is no bus key: give --bus-key FILE, "
                "daemon.bus.key_file in %s, or the systemd credential %s "
                "(LoadCredential=%s:/etc/amfid/bus.key); make one with amfid --make-bus-key "
                "FILE",
                c->config_path, AMFI_AUTH_CREDENTIAL, AMFI_AUTH_CREDENTIAL);
        return 2;
    }
    if (!dc->bus_auth)
        LOG_WARN("daemon.bus.auth is off: every message on the bus is accepted unchecked, "
                 "forged ones too; only for a lab bus (docs/messages.md)");
    if (!kp)
        return 0; /* auth off and no key: amfid publishes unsigned */
    /* LCM's file:// provider hands a replayed log's messages over with the
     * wall clock of the replay as receive time, not the log's: the time
     * cannot be checked there (the signatures and the order can) */
    const int replay = strncmp(dc->lcm_url, "file://", 7) == 0;
    amfi_auth_key key;
    if (amfi_auth_key_load(kp, &key, err, sizeof err)) {
        LOG_ERR("%s (from the %s)", err, origin);
        return 2;
    }
    char producer[AMFI_AUTH_PRODUCER_BYTES + 1];
    amfi_auth_producer_name(producer, "amfid.", c->cfg->site.id);
    B.signer = calloc(1, sizeof *B.signer);
    if (!B.signer || amfi_auth_signer_init(B.signer, &key, producer, err, sizeof err)) {
        LOG_ERR("bus key: %s", B.signer ? err : "out of memory");
        free(B.signer);
        B.signer = NULL;
        return 2;
    }
    if (dc->bus_auth) {
        B.auth = malloc(sizeof *B.auth);
        if (!B.auth ||
            amfi_auth_verifier_init(B.auth, &key, replay ? 0.0 : dc->bus_max_skew_s)) {
            LOG_ERR("bus key: %s", B.auth ? "libsodium cannot be initialised" : "out of memory");
            return 2;
        }
    }
    memset(&key, 0, sizeof key);
    LOG_INFO("bus authentication %s, key %s (from the %s), amfid signs as '%s'%s",
             dc->bus_auth ? "required" : "off (outgoing messages signed)", kp, origin, producer,
             dc->bus_auth && replay
                 ? "; replaying a log: signatures and each producer's order checked, not the "
                   "time (file:// gives no receive time of the log)"
                 : "");
    return 0;
}

int bus_open(amfid_ctx *c, const char *key_option)
{
    char url[512];
    bus_url(&c->cfg->daemon, url, sizeof url);
    B.lcm = lcm_create(url);
    if (!B.lcm) {
        LOG_ERR("cannot open the LCM bus '%s'", url);
        return 1;
    }
    return auth_start(c, key_option);
}

void bus_close(void)
{
    if (B.lcm)
        lcm_destroy(B.lcm);
    if (B.signer)
        amfi_auth_signer_free(B.signer);
    free(B.signer);
    if (B.auth)
        memset(B.auth, 0, sizeof *B.auth);
    free(B.auth);
    memset(&B, 0, sizeof B);
}

static void on_bus_message(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    struct bus_sub *s = user;
    lcm_recv_buf_t bare = *rb;
    if (!B.auth) {
        bare.data_size = (uint32_t)amfi_auth_bare_len(rb->data, rb->data_size);
        s->fn(&bare, ch, s->c);
        return;
    }
    size_t len = rb->data_size;
    char why[256];
    int r = amfi_auth_verify(B.auth, ch, rb->data, rb->data_size, rb->recv_utime, &len, why,
                             sizeof why);
    if (r != AMFI_AUTH_OK) {
        admit_count_in();
        B.auth_refused++;
        reject_note(s->c, s->input, REJECT_AUTH + r, "%s: message of %u bytes refused: %s", ch,
                    rb->data_size, why);
        return;
    }
    bare.data_size = (uint32_t)len;
    s->fn(&bare, ch, s->c);
}

void bus_want(int input, const char *channel, lcm_msg_handler_t fn)
{
    if (input < 0 || input >= REJECT_NINPUTS)
        return;
    B.subs[input].fn = fn;
    B.subs[input].channel = channel;
    B.subs[input].input = input;
}

/* Each input channel keeps up to daemon.bus_queue messages between LCM's
 * receive thread and the loop: LCM's default, 30, drops everything beyond
 * without a trace as soon as the loop is busy for a moment (measured: more
 * than half of a 2 500 messages/s stream lost, docs/daemon.md). */
int bus_subscribe_all(amfid_ctx *c)
{
    for (int i = 0; i < REJECT_NINPUTS; i++) {
        struct bus_sub *s = &B.subs[i];
        if (!s->fn)
            continue;
        s->c = c;
        lcm_subscription_t *sub = lcm_subscribe(B.lcm, s->channel, on_bus_message, s);
        if (!sub || lcm_subscription_set_queue_capacity(sub, c->cfg->daemon.bus_queue) != 0) {
            LOG_ERR("cannot subscribe to '%s' with a queue of %d messages", s->channel,
                    c->cfg->daemon.bus_queue);
            return -1;
        }
    }
    return 0;
}

int bus_publish(amfid_ctx *c, const char *channel, const void *data, size_t len)
{
    (void)c;
    return amfi_auth_publish(B.lcm, B.signer, channel, data, len);
}

void bus_stats(amfid_stats *s)
{
    s->auth_refused = B.auth_refused;
}
