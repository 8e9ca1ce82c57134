/*
 * pool.c - see pool.h. Swapping indices under one mutex: the capture
 * thread never waits for the processing thread and vice versa, except for
 * the few instructions of a swap (and a lossless pool's publish, which
 * waits on purpose).
 */
#define _POSIX_C_SOURCE 200809L
#include "pool.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int cdspd_pool_init(cdspd_pool *p, size_t bytes)
{
    pthread_condattr_t ca;
    int i;
    memset(p, 0, sizeof *p);
    pthread_mutex_init(&p->mu, NULL);
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&p->cv, &ca);
    pthread_cond_init(&p->taken, NULL);
    pthread_condattr_destroy(&ca);
    p->inited = 1;
    for (i = 0; i < 3; i++) {
        /* 64-byte aligned rows help the edge detector's vector loads */
        if (posix_memalign((void **)&p->slot[i].data, 64, bytes ? bytes : 1)) {
            p->slot[i].data = NULL;
            cdspd_pool_destroy(p);
            return -1;
        }
        memset(p->slot[i].data, 0, bytes ? bytes : 1);
        p->slot[i].cap = bytes;
    }
    p->back = 0;
    p->ready = 1;
    p->front = 2;
    return 0;
}

void cdspd_pool_destroy(cdspd_pool *p)
{
    int i;
    for (i = 0; i < 3; i++) {
        free(p->slot[i].data);
        p->slot[i].data = NULL;
    }
    if (p->inited) {
        pthread_mutex_destroy(&p->mu);
        pthread_cond_destroy(&p->cv);
        pthread_cond_destroy(&p->taken);
    }
    memset(p, 0, sizeof *p);
}

cdspd_frame *cdspd_pool_back(cdspd_pool *p)
{
    return &p->slot[p->back]; /* only the capture thread changes back */
}

void cdspd_pool_set_lossless(cdspd_pool *p, int lossless)
{
    pthread_mutex_lock(&p->mu);
    p->lossless = lossless;
    pthread_mutex_unlock(&p->mu);
}

int cdspd_pool_publish(cdspd_pool *p)
{
    int t, dropped;
    pthread_mutex_lock(&p->mu);
    while (p->lossless && p->fresh && !p->stop)
        pthread_cond_wait(&p->taken, &p->mu);
    if (p->lossless && p->stop) {
        pthread_mutex_unlock(&p->mu);
        return 0;
    }
    /* ready when it enters the pool: a lossless wait is not latency */
    p->slot[p->back].t_ready_us = cdspd_now_us();
    t = p->ready;
    p->ready = p->back;
    p->back = t;
    dropped = p->fresh;
    if (dropped)
        p->dropped++;
    p->fresh = 1;
    pthread_cond_signal(&p->cv);
    pthread_mutex_unlock(&p->mu);
    return dropped;
}

cdspd_frame *cdspd_pool_take(cdspd_pool *p, uint64_t timeout_us)
{
    struct timespec ts;
    cdspd_frame *f = NULL;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    ts.tv_sec += (time_t)(timeout_us / 1000000u);
    ts.tv_nsec += (long)(timeout_us % 1000000u) * 1000L;
    if (ts.tv_nsec >= 1000000000L) {
        ts.tv_sec++;
        ts.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&p->mu);
    while (!p->fresh && !p->stop) {
        if (pthread_cond_timedwait(&p->cv, &p->mu, &ts) == ETIMEDOUT)
            break;
    }
    if (p->fresh && !p->stop) {
        int t = p->front;
        p->front = p->ready;
        p->ready = t;
        p->fresh = 0;
        f = &p->slot[p->front];
        pthread_cond_signal(&p->taken);
    }
    pthread_mutex_unlock(&p->mu);
    return f;
}

void cdspd_pool_wake(cdspd_pool *p)
{
    pthread_mutex_lock(&p->mu);
    p->stop = 1;
    pthread_cond_broadcast(&p->cv);
    pthread_cond_broadcast(&p->taken);
    pthread_mutex_unlock(&p->mu);
}

uint64_t cdspd_pool_dropped(cdspd_pool *p)
{
    uint64_t d;
    pthread_mutex_lock(&p->mu);
    d = p->dropped;
    pthread_mutex_unlock(&p->mu);
    return d;
}
