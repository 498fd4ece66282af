/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ingest.h: amfi-ingest's pieces (docs/ingest.md).
 *
 *   pub.c    the publisher: per sensor, samples from any source assembled
 *            into accel blocks of ingest.block samples at their own data
 *            time (a gap starts a new block at the true time; overlapping
 *            samples are dropped; jumps of the clock counted), vehicles;
 *            every message signed (messages/amfi_auth.h) and published on
 *            the site's channels; the counters and the bad-input messages
 *   mseed.c  MiniSEED records (libmseed 2) from a file, a FIFO, stdin or a
 *            growing file, record by record, decoded and handed to pub.c
 *   line.c   the line protocol (A and V lines), from a file, a TCP peer or
 *            a serial port (termios)
 *
 * One thread: everything runs in amfi-ingest's main loop.
 */
#ifndef AMFI_INGEST_H
#define AMFI_INGEST_H

#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>
#include <libmseed.h>

#include "amfi_auth.h"
#include "amfi_config.h"
#include "amfi_vehicle_t.h"

#define INGEST_MAX_LINE 65536   /* bytes of one protocol line */
#define INGEST_MAX_VALUES 4096  /* samples on one A line */
#define INGEST_NOTES 50         /* messages printed per kind; the rest counted */

/* What went wrong with an input, for the counters and the summary. */
enum {
    BAD_RECORD,   /* a MiniSEED record refused (header, decoding, rate, values) */
    BAD_LINE,     /* a protocol line refused */
    NOTE_UNMAPPED, /* a MiniSEED channel not in ingest.channels */
    NOTE_GAP,     /* data resumed later than the next sample was due */
    NOTE_OVERLAP, /* samples already published again: dropped */
    NOTE_JUMP,    /* the data's time jumped forward by more than max_jump_s */
    NOTE_BACK,    /* the data's time went back by more than max_jump_s */
    NOTE_WALL,    /* live input whose time is more than max_jump_s from the wall clock */
    NOTE_NKINDS
};

typedef struct ingest_stream {
    int sensor_id;
    double rate_hz;  /* sensors[].rate_hz */
    int have;        /* next_us is known */
    double next_us;  /* data time the next sample is due */
    double t0_us;    /* data time of buf[0] */
    int n;
    double buf[160];
    int64_t seq;
    double last_wall; /* monotonic time of the last sample (service mode: flush idle blocks) */
} ingest_stream;

typedef struct ingest {
    const amfi_site_config *cfg;
    lcm_t *lcm;
    amfi_auth_signer *signer; /* NULL: unsigned (--unsigned) */
    int live;                 /* service mode: data time checked against the wall clock */
    int n_streams;
    ingest_stream st[AMFI_MAX_SENSORS];
    int64_t last_vehicle_us;
    unsigned char *ebuf, *sbuf;
    size_t ecap, scap;
    /* counters */
    long long records, lines, blocks, samples, vehicles, publish_failed;
    long long notes[NOTE_NKINDS];
    long long gap_samples, overlap_samples;
    char unmapped_seen[16][64]; /* channel ids already named */
    int n_unmapped_seen;
} ingest;

int ingest_init(ingest *g, const amfi_site_config *cfg, lcm_t *lcm, amfi_auth_signer *signer);
void ingest_free(ingest *g);

/* The stream index of a site sensor id, or -1. */
int ingest_sensor_index(const ingest *g, int sensor_id);

/* Count a problem of kind k and print "amfi-ingest: WHERE: FIELD: message"
 * (the first INGEST_NOTES of each kind). */
void ingest_note(ingest *g, int k, const char *where, const char *field, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* n samples (m/s²) of sensor stream idx, the first at data time start_us,
 * sample_rate rate_hz, from `where` (for messages). Checks the rate
 * against sensors[].rate_hz, every value (finite, |a| ≤ 1000 m/s²) and
 * the time; then gaps, overlaps and jumps against what the stream had
 * (docs/ingest.md "Time"). 0, or -1 when the whole record is refused
 * (counted as `bad`: BAD_RECORD or BAD_LINE). */
int ingest_samples(ingest *g, int idx, double start_us, double rate_hz, int n, const double *v,
                   const char *where, int bad);

/* One vehicle (utime already corrected by the source's offset). */
int ingest_vehicle(ingest *g, const amfi_vehicle_t *m, const char *where);

/* Publish every partial block (end of input); with idle_s > 0 only those of
 * streams that received nothing for idle_s seconds (monotonic). */
void ingest_flush(ingest *g, double idle_s);

void ingest_summary(const ingest *g, FILE *f);

/* ---- MiniSEED (mseed.c) ---- */

typedef struct mseed_src {
    char name[512];    /* for messages */
    int fd;
    int follow;        /* a regular file: EOF means "not yet" (service mode) */
    int eof;
    unsigned char *buf;
    size_t off, len, cap; /* bytes off .. len of buf wait to be read */
    long long recno;   /* records seen, 1-based in messages */
    int last_reclen;
    MSRecord *msr;     /* the record unpacked, valid after mseed_next() == 1 */
    double start_us;   /* its data time (offset applied), for the merge */
    int idx;           /* its stream, -1 unmapped */
    double gain, offset_s;
} mseed_src;

/* Open path ("-" stdin). follow: keep reading a regular file as it grows. */
int mseed_open(mseed_src *m, const char *path, int follow, char *err, size_t errlen);
void mseed_close(mseed_src *m);
/* Read what is available (one read()); 1 data read, 0 nothing now, -1 EOF/error. */
int mseed_fill(mseed_src *m);
/* The next decodable record of a mapped channel into m->msr (1), or 0 when
 * more bytes are needed (or at the end). Refused records are counted and
 * named in g; records of channels not in ingest.channels are counted and
 * skipped. */
int mseed_next(mseed_src *m, ingest *g);
/* Hand the record in m->msr to the publisher. */
void mseed_publish(mseed_src *m, ingest *g);

/* ---- the line protocol (line.c) ---- */

typedef struct line_src {
    char name[300];    /* file name or peer (ADDR:PORT) or device */
    int fd;
    long long lineno;
    char *buf;
    size_t len, cap;
    int skipping;      /* inside an over-long line */
    int eof;
} line_src;

/* One line (NUL-terminated, without the newline) from `where` ("NAME:line N"):
 * parsed, checked and published. 0 ok (or a comment), -1 refused (counted). */
int line_handle(ingest *g, char *line, const char *where);
/* The data time of a line without publishing it (for the merge of files):
 * 0 when it has none (comment, unparsable). */
double line_time_us(const char *line, double offset_s);
/* Feed bytes read from src into lines; each complete line handled. */
void line_feed(ingest *g, line_src *src, const char *data, size_t n);
/* At the end of a source: a last line without a newline. */
void line_finish(ingest *g, line_src *src);

/* Open and configure a serial port (raw, 8N1, baud). fd or -1 with err. */
int serial_open(const char *dev, int baud, char *err, size_t errlen);

#endif /* AMFI_INGEST_H */
