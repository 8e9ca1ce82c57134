/*
 * pool.h - the fixed pool of frame buffers between the capture thread and
 * the processing thread: three buffers (triple buffering). The capture
 * thread fills its back buffer and publishes it as the latest; the
 * processing thread takes the latest. A frame published while the previous
 * one was still waiting replaces it (latest wins) and counts as dropped:
 * frames never queue up into latency. That is right for a live camera;
 * a replay (file:) must process every frame in order, so a pool made
 * lossless makes publish wait until the previous frame was taken instead.
 * Buffers are allocated once.
 */
#ifndef CDSPD_POOL_H
#define CDSPD_POOL_H

#include <pthread.h>
#include <stdint.h>

#include "source.h"

typedef struct {
    cdspd_frame slot[3];
    int back, ready, front;   /* which slot each party holds */
    int fresh;                /* ready holds a frame not taken yet */
    int lossless;             /* publish waits for the taker instead of replacing */
    uint64_t dropped;
    int stop, inited;
    pthread_mutex_t mu;
    pthread_cond_t cv;        /* a frame became fresh, or stop */
    pthread_cond_t taken;     /* lossless: the fresh frame was taken, or stop */
} cdspd_pool;

/* bytes per buffer; 0 or -1 (out of memory). */
int cdspd_pool_init(cdspd_pool *p, size_t bytes);
void cdspd_pool_destroy(cdspd_pool *p);

/* Make publish wait for the taker (never drop); call before any publish. */
void cdspd_pool_set_lossless(cdspd_pool *p, int lossless);

/* Capture side: the buffer to fill, then publish it (sets t_ready_us).
 * Returns 1 when it replaced a frame nobody took (a drop), else 0. A
 * lossless pool waits until the previous frame was taken (or a wake) and
 * never drops; after a wake it returns at once without publishing. */
cdspd_frame *cdspd_pool_back(cdspd_pool *p);
int cdspd_pool_publish(cdspd_pool *p);

/* Processing side: the latest frame (now owned until the next take), or
 * NULL after timeout_us without one. */
cdspd_frame *cdspd_pool_take(cdspd_pool *p, uint64_t timeout_us);

/* Wake a waiting taker (and a waiting lossless publisher) and make every
 * later take and lossless publish return at once. */
void cdspd_pool_wake(cdspd_pool *p);

uint64_t cdspd_pool_dropped(cdspd_pool *p);

#endif
