/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcm_forge: an attacker on the site's LAN without the site key, for
 * tests/daemon_forged.sh. Reads CAPTURE (an LCM log of the bus as a sniffer
 * on the LAN records it: signed messages) and sends LCM datagrams (LCM's
 * small-message format: magic "LC02", sequence number, channel, NUL,
 * payload) with plain UDP to ADDR:7667, a unicast address of amfid's host or
 * LCM's multicast group (TTL 1, out of the interface the route names):
 *
 *   lcm_forge unsigned ADDR CAPTURE   for each captured vehicle_t, a forged
 *                                     one (id 991000 + k, 1.5 s later),
 *                                     without a trailer
 *   lcm_forge wrongkey ADDR CAPTURE   the same (ids 992000 + k) signed with a
 *                                     random key as the captured producer
 *   lcm_forge replay ADDR CAPTURE     every captured AMFI_ACCEL and
 *                                     AMFI_VEHICLE message again, byte for
 *                                     byte (a valid signature, an old
 *                                     sequence)
 *
 * Prints "sent N" (the datagrams). Paced at 1 ms a datagram.
 *
 *   lcm_forge count - CAPTURE          prints the vehicle_t messages captured
 * Exit status: 0, 1 (a file or socket error), 2 (bad command line).
 */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "amfi_auth.h"
#include "amfi_messages.h"

#define PORT 7667

static int send_lcm(int fd, const struct sockaddr_in *to, const char *channel, const void *data,
                    size_t len)
{
    static uint32_t seqno;
    unsigned char pkt[65000];
    size_t cl = strlen(channel) + 1;
    if (8 + cl + len > sizeof pkt)
        return -1;
    const uint32_t magic = htonl(0x4c433032), seq = htonl(seqno++);
    memcpy(pkt, &magic, 4);
    memcpy(pkt + 4, &seq, 4);
    memcpy(pkt + 8, channel, cl);
    memcpy(pkt + 8 + cl, data, len);
    ssize_t n = sendto(fd, pkt, 8 + cl + len, 0, (const struct sockaddr *)to, sizeof *to);
    struct timespec ts = {0, 1000000};
    nanosleep(&ts, NULL);
    return n == (ssize_t)(8 + cl + len) ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc != 4 || (strcmp(argv[1], "unsigned") && strcmp(argv[1], "wrongkey") &&
                      strcmp(argv[1], "replay") && strcmp(argv[1], "count"))) {
        fprintf(stderr, "usage: lcm_forge unsigned|wrongkey|replay|count ADDR CAPTURE.log\n");
        return 2;
    }
    const char *mode = argv[1];
    if (strcmp(mode, "count") == 0) {
        lcm_eventlog_t *in = lcm_eventlog_create(argv[3], "r");
        long n = 0;
        lcm_eventlog_event_t *e;
        while (in && (e = lcm_eventlog_read_next_event(in)) != NULL) {
            n += strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0;
            lcm_eventlog_free_event(e);
        }
        if (in)
            lcm_eventlog_destroy(in);
        printf("%ld\n", n);
        return in ? 0 : 1;
    }
    struct sockaddr_in to;
    memset(&to, 0, sizeof to);
    to.sin_family = AF_INET;
    to.sin_port = htons(PORT);
    if (inet_pton(AF_INET, argv[2], &to.sin_addr) != 1) {
        fprintf(stderr, "lcm_forge: %s: not an IPv4 address\n", argv[2]);
        return 2;
    }
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char ttl = 1;
    if (fd < 0 || setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0) {
        perror("lcm_forge: socket");
        return 1;
    }
    lcm_eventlog_t *in = lcm_eventlog_create(argv[3], "r");
    if (!in) {
        fprintf(stderr, "lcm_forge: cannot read %s\n", argv[3]);
        return 1;
    }
    amfi_auth_signer wrong;
    if (strcmp(mode, "wrongkey") == 0) {
        amfi_auth_key k;
        FILE *r = fopen("/dev/urandom", "rb");
        if (!r || fread(k.k, 1, sizeof k.k, r) != sizeof k.k) {
            fprintf(stderr, "lcm_forge: no random key\n");
            return 1;
        }
        fclose(r);
        /* impersonating the first captured producer, set below */
        char err[200];
        if (amfi_auth_signer_init(&wrong, &k, "sim.1", err, sizeof err)) {
            fprintf(stderr, "lcm_forge: %s\n", err);
            return 1;
        }
    }
    long sent = 0, k = 0;
    int rc = 0, producer_set = 0;
    lcm_eventlog_event_t *e;
    while ((e = lcm_eventlog_read_next_event(in)) != NULL) {
        const int is_vehicle = strcmp(e->channel, AMFI_CHANNEL_VEHICLE) == 0;
        const int is_accel = strcmp(e->channel, AMFI_CHANNEL_ACCEL) == 0;
        if (strcmp(mode, "replay") == 0) {
            if (is_vehicle || is_accel) {
                rc |= send_lcm(fd, &to, e->channel, e->data, (size_t)e->datalen);
                sent++;
            }
        } else if (is_vehicle) {
            size_t bare = amfi_auth_bare_len(e->data, (size_t)e->datalen);
            if (!producer_set && bare < (size_t)e->datalen && strcmp(mode, "wrongkey") == 0) {
                /* the real producer's id, from the captured trailer */
                memcpy(wrong.producer, (const unsigned char *)e->data + bare + 5,
                       AMFI_AUTH_PRODUCER_BYTES);
                producer_set = 1;
            }
            amfi_vehicle_t v;
            if (amfi_vehicle_t_decode(e->data, 0, (int)bare, &v) < 0)
                continue;
            v.vehicle_id = (strcmp(mode, "unsigned") == 0 ? 991000 : 992000) + k++;
            v.utime += 1500000;
            unsigned char buf[1024 + AMFI_AUTH_TRAILER_BYTES];
            int n = amfi_vehicle_t_encode(buf, 0, 1024, &v);
            amfi_vehicle_t_decode_cleanup(&v);
            if (n < 0)
                continue;
            long len = n;
            if (strcmp(mode, "wrongkey") == 0)
                len = amfi_auth_sign_into(&wrong, AMFI_CHANNEL_VEHICLE, buf, (size_t)n, 0, buf,
                                          sizeof buf);
            rc |= len < 0 || send_lcm(fd, &to, AMFI_CHANNEL_VEHICLE, buf, (size_t)len);
            sent++;
        }
        lcm_eventlog_free_event(e);
    }
    lcm_eventlog_destroy(in);
    close(fd);
    if (rc) {
        fprintf(stderr, "lcm_forge: a send failed\n");
        return 1;
    }
    printf("sent %ld\n", sent);
    return 0;
}
