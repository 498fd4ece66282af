/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * mseed.c: MiniSEED records (SEED 2.4 data records, libmseed 2.19) read
 * record by record from a file, a FIFO, stdin or a file a logger is still
 * writing. Bytes are collected until ms_detect() knows the record's length
 * and the whole record is there; msr_unpack() decodes it (int16/32,
 * float32/64, Steim-1/2: whatever libmseed decodes). A record that cannot
 * be read is counted and named (FILE:record N) and skipped by the last good
 * record length (or scanned past to the next header), never fatal. The
 * record's channel NET.STA.LOC.CHA is looked up in ingest.channels; its
 * counts are multiplied by the channel's gain into m/s², its header time
 * minus the channel's offset_s is the data time of its first sample.
 *
 * Thread: amfi-ingest's main thread only.
 */
#include "ingest.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* libmseed's own diagnostics: kept (the last one) for the message naming
 * the record, and a failed Steim integrity check makes the record bad. */
static char diag_last[256];
static int diag_integrity;

static void diag_print(char *msg)
{
    snprintf(diag_last, sizeof diag_last, "%s", msg);
    size_t n = strlen(diag_last);
    while (n && (diag_last[n - 1] == '\n' || diag_last[n - 1] == ' '))
        diag_last[--n] = '\0';
    if (strstr(msg, "integrity check"))
        diag_integrity = 1;
}

static void log_print(char *msg)
{
    (void)msg;
}

int mseed_open(mseed_src *m, const char *path, int follow, char *err, size_t errlen)
{
    static int log_set;
    if (!log_set) {
        ms_loginit(log_print, NULL, diag_print, NULL);
        log_set = 1;
    }
    memset(m, 0, sizeof *m);
    m->idx = -1;
    snprintf(m->name, sizeof m->name, "%s", strcmp(path, "-") ? path : "stdin");
    /* files: blocking reads; a service's streams: non-blocking, read when
     * poll() says so (a followed regular file every turn) */
    const int nb = follow ? O_NONBLOCK : 0;
    m->fd = strcmp(path, "-") ? open(path, O_RDONLY | O_CLOEXEC | nb) : 0;
    if (m->fd < 0) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    struct stat sb;
    if (fstat(m->fd, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        snprintf(err, errlen, "%s: is a directory", path);
        if (m->fd > 0)
            close(m->fd);
        return -1;
    }
    if (follow && S_ISFIFO(sb.st_mode) && m->fd > 0) {
        /* A named FIFO of the service is held open for writing too: no end
         * of file when its writer closes or has not opened it yet (a logger
         * that restarts reopens it and the stream goes on). */
        int rw = open(path, O_RDWR | O_CLOEXEC | O_NONBLOCK);
        if (rw < 0) {
            snprintf(err, errlen, "%s: %s", path, strerror(errno));
            close(m->fd);
            return -1;
        }
        close(m->fd);
        m->fd = rw;
    }
    if (follow && m->fd == 0) {
        int fl = fcntl(0, F_GETFL);
        if (fl >= 0)
            fcntl(0, F_SETFL, fl | O_NONBLOCK);
    }
    m->follow = follow && S_ISREG(sb.st_mode);
    return 0;
}

void mseed_close(mseed_src *m)
{
    if (m->fd > 0)
        close(m->fd);
    m->fd = -1;
    if (m->msr)
        msr_free(&m->msr);
    free(m->buf);
    m->buf = NULL;
}

int mseed_fill(mseed_src *m)
{
    if (m->eof)
        return -1;
    if (m->off > 0) { /* what was consumed leaves the buffer once per read */
        memmove(m->buf, m->buf + m->off, m->len - m->off);
        m->len -= m->off;
        m->off = 0;
    }
    if (m->cap - m->len < 65536) {
        size_t cap = m->cap ? 2 * m->cap : 262144;
        unsigned char *b = realloc(m->buf, cap);
        if (!b)
            return -1;
        m->buf = b;
        m->cap = cap;
    }
    ssize_t r = read(m->fd, m->buf + m->len, m->cap - m->len);
    if (r > 0) {
        m->len += (size_t)r;
        return 1;
    }
    if (r < 0 && (errno == EAGAIN || errno == EINTR))
        return 0;
    if (r == 0 && m->follow)
        return 0; /* a growing file: more may come */
    m->eof = 1;
    return -1;
}

/* Bytes waiting, and where they start. */
#define AVAIL(m) ((m)->len - (m)->off)
#define DATA(m) ((m)->buf + (m)->off)

static void consume(mseed_src *m, size_t n)
{
    if (n > AVAIL(m))
        n = AVAIL(m);
    m->off += n;
}

/* The record's channel as NET.STA.LOC.CHA. */
static void seed_id(const MSRecord *r, char *out, size_t n)
{
    snprintf(out, n, "%s.%s.%s.%s", r->network, r->station, r->location, r->channel);
}

/* Whether the record's header promises no more data than the record
 * holds. libmseed 2.19 bounds its Steim decoders by the record, but not the
 * int16, int32, float32 and float64 ones: a header claiming more samples
 * than fit made them read past the record (a crash found by the hostile-
 * input test). Only the encodings below are accepted; NULL when it fits,
 * else why not. */
static const char *data_fits(const MSRecord *r, int reclen, char *buf, size_t n)
{
    const int off = r->fsdh ? r->fsdh->data_offset : 0;
    if (off < 48 || off >= reclen) {
        snprintf(buf, n, "the data offset %d is outside the %d-byte record", off, reclen);
        return buf;
    }
    const long long avail = reclen - off, cnt = r->samplecnt;
    long long max;
    switch (r->encoding) {
    case DE_INT16: max = avail / 2; break;
    case DE_INT32:
    case DE_FLOAT32: max = avail / 4; break;
    case DE_FLOAT64: max = avail / 8; break;
    case DE_STEIM1: max = avail / 64 * 15 * 4; break; /* 4 differences a word at most */
    case DE_STEIM2: max = avail / 64 * 15 * 7; break; /* 7 differences a word at most */
    default:
        snprintf(buf, n, "encoding %d (%s) is not int16, int32, float32, float64, Steim-1 or Steim-2",
                 r->encoding, ms_encodingstr(r->encoding));
        return buf;
    }
    if (cnt > max) {
        snprintf(buf, n, "%lld samples cannot fit in the record's %lld data bytes (%s)", cnt, avail,
                 ms_encodingstr(r->encoding));
        return buf;
    }
    return NULL;
}

int mseed_next(mseed_src *m, ingest *g)
{
    char where[600];
    if (m->msr)
        msr_free(&m->msr);
    for (;;) {
        if (AVAIL(m) < 48) {
            if (m->eof && AVAIL(m) > 0) {
                snprintf(where, sizeof where, "%s:record %lld", m->name, m->recno + 1);
                ingest_note(g, BAD_RECORD, where, "header",
                            "%zu bytes at the end are not a record", AVAIL(m));
                m->recno++;
                consume(m, AVAIL(m));
            }
            return 0;
        }
        int reclen = ms_detect((const char *)DATA(m), (int)(AVAIL(m) < MAXRECLEN ? AVAIL(m) : MAXRECLEN));
        snprintf(where, sizeof where, "%s:record %lld", m->name, m->recno + 1);
        if (reclen == 0 && !m->eof && AVAIL(m) < MAXRECLEN)
            return 0; /* a header, its length not known yet */
        if (reclen == 0)
            reclen = m->last_reclen > 0 ? m->last_reclen : (int)AVAIL(m);
        if (reclen < 0) {
            /* not a record header: skip one record of the last good length,
             * or scan to the next place where a header begins */
            m->recno++;
            size_t skip = m->last_reclen > 0 ? (size_t)m->last_reclen : 0;
            if (!skip) {
                for (skip = 64; skip + 48 <= AVAIL(m); skip += 64)
                    if (MS_ISVALIDHEADER((char *)DATA(m) + skip))
                        break;
            }
            if (skip > AVAIL(m) && !m->eof)
                return 0;
            ingest_note(g, BAD_RECORD, where, "header",
                        "not a MiniSEED data record header: %zu bytes skipped", skip);
            consume(m, skip);
            continue;
        }
        if ((size_t)reclen > AVAIL(m)) {
            if (!m->eof)
                return 0;
            m->recno++;
            ingest_note(g, BAD_RECORD, where, "length",
                        "the record's length is %d bytes, only %zu remain: truncated", reclen,
                        AVAIL(m));
            consume(m, AVAIL(m));
            return 0;
        }
        m->recno++;
        g->records++;
        diag_last[0] = '\0';
        diag_integrity = 0;
        MSRecord *r = NULL;
        /* the header first: the data decoded only when they fit */
        int rc = msr_unpack((char *)DATA(m), reclen, &r, 0, 0);
        char fits[200];
        const char *nofit = rc == MS_NOERROR && r ? data_fits(r, reclen, fits, sizeof fits) : NULL;
        if (nofit) {
            consume(m, (size_t)reclen);
            ingest_note(g, BAD_RECORD, where, "data", "%s", nofit);
            msr_free(&r);
            continue;
        }
        if (rc == MS_NOERROR)
            rc = msr_unpack((char *)DATA(m), reclen, &r, 1, 0);
        consume(m, (size_t)reclen);
        if (rc != MS_NOERROR || !r) {
            ingest_note(g, BAD_RECORD, where, "data", "cannot decode: %s%s%s", ms_errorstr(rc),
                        diag_last[0] ? ": " : "", diag_last);
            if (r)
                msr_free(&r);
            continue;
        }
        m->last_reclen = reclen;
        if (diag_integrity) {
            ingest_note(g, BAD_RECORD, where, "data",
                        "%s: the decoded samples are not trusted, record refused", diag_last);
            msr_free(&r);
            continue;
        }
        char id[64];
        seed_id(r, id, sizeof id);
        snprintf(where, sizeof where, "%s:record %lld (%s)", m->name, m->recno, id);
        if (r->samplecnt == 0 || r->numsamples == 0) {
            msr_free(&r); /* a record without samples (e.g. only blockettes): nothing to do */
            continue;
        }
        if (r->numsamples != r->samplecnt) {
            ingest_note(g, BAD_RECORD, where, "data", "decoded %lld of %lld samples",
                        (long long)r->numsamples, (long long)r->samplecnt);
            msr_free(&r);
            continue;
        }
        if (r->sampletype != 'i' && r->sampletype != 'f' && r->sampletype != 'd') {
            ingest_note(g, BAD_RECORD, where, "encoding",
                        "sample type '%c' is not numeric", r->sampletype ? r->sampletype : '?');
            msr_free(&r);
            continue;
        }
        const amfi_ingest_config *ic = &g->cfg->ingest;
        int c = -1;
        for (int i = 0; i < ic->n_channels; i++)
            if (strcmp(ic->ch[i].seed, id) == 0)
                c = i;
        if (c < 0) {
            g->notes[NOTE_UNMAPPED]++;
            int seen = 0;
            for (int i = 0; i < g->n_unmapped_seen; i++)
                seen |= strcmp(g->unmapped_seen[i], id) == 0;
            if (!seen && g->n_unmapped_seen < 16) {
                snprintf(g->unmapped_seen[g->n_unmapped_seen++], sizeof g->unmapped_seen[0],
                         "%s", id);
                fprintf(stderr,
                        "amfi-ingest: %s: channel %s is not in ingest.channels: its records "
                        "are counted and skipped\n",
                        where, id);
            }
            msr_free(&r);
            continue;
        }
        m->idx = ingest_sensor_index(g, ic->ch[c].sensor_id);
        m->gain = ic->ch[c].gain;
        m->offset_s = ic->ch[c].offset_s;
        m->start_us = (double)r->starttime * (1e6 / HPTMODULUS) - 1e6 * m->offset_s;
        m->msr = r;
        return 1;
    }
}

void mseed_publish(mseed_src *m, ingest *g)
{
    MSRecord *r = m->msr;
    char where[600], id[64];
    seed_id(r, id, sizeof id);
    snprintf(where, sizeof where, "%s:record %lld (%s)", m->name, m->recno, id);
    const int n = (int)r->numsamples;
    double *v = malloc(sizeof(double) * (size_t)n);
    if (!v) {
        ingest_note(g, BAD_RECORD, where, "data", "out of memory for %d samples", n);
        return;
    }
    for (int k = 0; k < n; k++) {
        double x = r->sampletype == 'i'   ? (double)((const int32_t *)r->datasamples)[k]
                   : r->sampletype == 'f' ? (double)((const float *)r->datasamples)[k]
                                          : ((const double *)r->datasamples)[k];
        v[k] = x * m->gain;
    }
    /* the nominal rate (the header's factor and multiplier), not blockette
     * 100's measured one: the samples are placed by each record's own start
     * time, so a logger whose clock runs a few ppm off is followed record by
     * record, and the rate on the bus stays the sensor's rate_hz */
    const double rate = msr_nomsamprate(r);
    if (!(rate > 0)) {
        ingest_note(g, BAD_RECORD, where, "sample rate", "%g Hz in the header", rate);
    } else {
        ingest_samples(g, m->idx, m->start_us, rate, n, v, where, BAD_RECORD);
    }
    free(v);
    msr_free(&m->msr);
}
