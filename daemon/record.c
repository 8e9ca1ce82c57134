/*
 * record.c - see record.h.
 */
#define _POSIX_C_SOURCE 200809L
#include "record.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cdsp_host.h"
#include "log.h"

static void disable(cdspd_recorder *r, const char *what)
{
    LOG_E(RECORD, "%s: recording stopped for the rest of this run (the daemon keeps running)", what);
    CDSPD_SET(r->disabled, 1);
}

static void write_one(cdspd_recorder *r)
{
    char path[CDSPD_STR + 128], name[96], json[2048], where[CDSPD_STR + 128];
    cdsp_host_image im;
    cdsp_host_err herr;
    size_t n;

    snprintf(name, sizeof name, "%s-%010lu.pgm", r->run, (unsigned long)r->rec.seq);
    snprintf(path, sizeof path, "%s/%s", r->dir, name);
    im.data = r->frame.data;
    im.width = r->frame.width;
    im.height = r->frame.height;
    im.bits = r->frame.bits;
    im.stride = r->frame.stride;
    if (cdsp_host_pgm_write(path, &im, &herr)) {
        unlink(path); /* no half-written frame left behind */
        disable(r, herr.msg);
        return;
    }
    n = cdspd_proto_encode_json(&r->rec, json, sizeof json - 64);
    if (n < 2) {
        disable(r, "record: a result did not fit its buffer");
        return;
    }
    /* ...,"file":"NAME"} */
    snprintf(json + n - 1, sizeof json - (n - 1), ",\"file\":\"%s\"}\n", name);
    if (fputs(json, r->results) < 0 || fflush(r->results)) {
        snprintf(where, sizeof where, "%s/%s.jsonl: %s", r->dir, r->run, strerror(errno));
        disable(r, where);
        return;
    }
    cdspd_stats_add(r->stats, CDSPD_STAT(recorded), 1);
}

static void *writer(void *arg)
{
    cdspd_recorder *r = arg;
    pthread_mutex_lock(&r->mu);
    for (;;) {
        while (!r->busy && !r->stop)
            pthread_cond_wait(&r->cv, &r->mu);
        if (!r->busy && r->stop)
            break;
        pthread_mutex_unlock(&r->mu);
        write_one(r);
        pthread_mutex_lock(&r->mu);
        r->busy = 0;
        pthread_cond_broadcast(&r->cv); /* a lossless offer may be waiting */
    }
    pthread_mutex_unlock(&r->mu);
    return NULL;
}

int cdspd_recorder_start(cdspd_recorder *r, const cdspd_config *c, size_t frame_bytes,
                         cdspd_stats *stats, char *err, size_t errlen)
{
    char path[CDSPD_STR + 64];
    time_t now = time(NULL);
    struct tm tm;

    memset(r, 0, sizeof *r);
    CDSPD_SET(r->disabled, 1);
    if (!*c->record)
        return 0;
    strcpy(r->dir, c->record);
    r->every = c->record_every;
    r->stats = stats;
    gmtime_r(&now, &tm);
    strftime(r->run, sizeof r->run, "%Y%m%dT%H%M%SZ", &tm);
    r->frame.data = malloc(frame_bytes ? frame_bytes : 1);
    r->frame.cap = frame_bytes;
    if (!r->frame.data) {
        snprintf(err, errlen, "record: out of memory for the frame buffer");
        return -1;
    }
    snprintf(path, sizeof path, "%s/%s.jsonl", r->dir, r->run);
    r->results = fopen(path, "a");
    if (!r->results) {
        /* not fatal: the disk may be full or read-only, the daemon runs on */
        LOG_E(RECORD, "%s: %s: not recording", path, strerror(errno));
        free(r->frame.data);
        r->frame.data = NULL;
        return 0;
    }
    /* the calibration beside the frames: a replay of DIR needs nothing else
     * (cdspd --source 'file:DIR/RUN-*.pgm' finds DIR/RUN.yaml) */
    snprintf(path, sizeof path, "%s/%s.yaml", r->dir, r->run);
    {
        cdsp_host_err herr;
        if (cdsp_host_calib_write(path, &c->cam, "cdspd_record", &herr))
            LOG_E(RECORD, "%s (a replay will need --calib)", herr.msg);
    }
    pthread_mutex_init(&r->mu, NULL);
    pthread_cond_init(&r->cv, NULL);
    if (pthread_create(&r->thread, NULL, writer, r)) {
        snprintf(err, errlen, "record: cannot start the writer thread");
        fclose(r->results);
        free(r->frame.data);
        r->frame.data = NULL;
        return -1;
    }
    r->have_thread = 1;
    CDSPD_SET(r->disabled, 0);
    LOG_I(RECORD, "recording every %d%s frame into %s (%s-*.pgm, %s.jsonl, calibration %s.yaml)",
          r->every, r->every == 1 ? "" : "th", r->dir, r->run, r->run, r->run);
    return 0;
}

int cdspd_recorder_wants(const cdspd_recorder *r, uint64_t processed)
{
    return !CDSPD_GET(r->disabled) && processed % (uint64_t)r->every == 0;
}

int cdspd_recorder_ready(cdspd_recorder *r)
{
    int ready;
    if (CDSPD_GET(r->disabled) || !r->have_thread)
        return 0;
    pthread_mutex_lock(&r->mu);
    /* a lossless offer waits for the writer: ready unless recording stopped */
    ready = (r->lossless || !r->busy) && !CDSPD_GET(r->disabled);
    pthread_mutex_unlock(&r->mu);
    return ready;
}

void cdspd_recorder_set_lossless(cdspd_recorder *r, int lossless)
{
    r->lossless = lossless;
}

int cdspd_recorder_offer(cdspd_recorder *r, const cdspd_frame *f, const cdspd_record *rec)
{
    size_t bytes = f->stride * (size_t)f->height;
    uint8_t *data;
    int taken = 0;
    if (CDSPD_GET(r->disabled) || !r->have_thread)
        return 0;
    pthread_mutex_lock(&r->mu);
    while (r->lossless && r->busy && !r->stop && !CDSPD_GET(r->disabled))
        pthread_cond_wait(&r->cv, &r->mu);
    if (!r->busy && !CDSPD_GET(r->disabled) && bytes <= r->frame.cap) {
        size_t cap = r->frame.cap;
        data = r->frame.data;
        memcpy(data, f->data, bytes);
        r->frame = *f;
        r->frame.data = data;
        r->frame.cap = cap;
        r->rec = *rec;
        r->busy = 1;
        taken = 1;
        pthread_cond_signal(&r->cv);
    }
    pthread_mutex_unlock(&r->mu);
    if (!taken)
        cdspd_stats_add(r->stats, CDSPD_STAT(record_skipped), 1);
    return taken;
}

void cdspd_recorder_stop(cdspd_recorder *r)
{
    if (r->have_thread) {
        pthread_mutex_lock(&r->mu);
        r->stop = 1;
        pthread_cond_signal(&r->cv);
        pthread_mutex_unlock(&r->mu);
        pthread_join(r->thread, NULL);
        pthread_mutex_destroy(&r->mu);
        pthread_cond_destroy(&r->cv);
        r->have_thread = 0;
    }
    if (r->results)
        fclose(r->results);
    r->results = NULL;
    free(r->frame.data);
    r->frame.data = NULL;
    CDSPD_SET(r->disabled, 1);
}
