/*
 * pool.h - the fixed pool of frame buffers between the capture thread and
 * the processing thread: three buffers (triple buffering). The capture
 * thread fills its back buffer and publishes it as the latest; the
 * processing thread takes the latest. A frame published while the previous
 * one was still waiting replaces it (latest wins) and counts as dropped:
 * frames never queue up into latency. Buffers are allocated once.
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
    uint64_t dropped;
    int stop, inited;
    pthread_mutex_t mu;
    pthread_cond_t cv;
} cdspd_pool;

/* bytes per buffer; 0 or -1 (out of memory). */
int cdspd_pool_init(cdspd_pool *p, size_t bytes);
void cdspd_pool_destroy(cdspd_pool *p);

/* Capture side: the buffer to fill, then publish it (sets t_ready_us).
 * Returns 1 when it replaced a frame nobody took (a drop), else 0. */
cdspd_frame *cdspd_pool_back(cdspd_pool *p);
int cdspd_pool_publish(cdspd_pool *p);

/* Processing side: the latest frame (now owned until the next take), or
 * NULL after timeout_us without one. */
cdspd_frame *cdspd_pool_take(cdspd_pool *p, uint64_t timeout_us);

/* Wake a waiting taker and make every later take return NULL at once. */
void cdspd_pool_wake(cdspd_pool *p);

uint64_t cdspd_pool_dropped(cdspd_pool *p);

#endif
