/*
 * strips.c - see strips.h. The workers wait on one condition variable for
 * the job's generation number to change, scan their strip, and count
 * themselves done; the caller scans strip 0, waits for the count, and
 * merges in strip order, so the threads' timing never reaches the result.
 * A strip or the merge that does not fit (CDSP_E_CAPACITY) hands the frame
 * to cdsp_edges_detect on the calling thread, whose rule for a full buffer
 * needs the whole frame: the same result again.
 */
#define _POSIX_C_SOURCE 200809L
#include "strips.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct {
    cdspd_strips *s;
    int k;
    pthread_t tid;
} worker;

struct cdspd_strips {
    int n, started;
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    unsigned long gen;  /* job number: a change starts the workers */
    int pending, stop;  /* workers still scanning; stop: exit */
    /* the job */
    const cdsp_image *img;
    const cdsp_edge_params *p;
    cdsp_edge *buf[CDSP_EDGE_MAX_STRIPS];
    size_t nr[CDSP_EDGE_MAX_STRIPS], nc[CDSP_EDGE_MAX_STRIPS];
    cdsp_status st[CDSP_EDGE_MAX_STRIPS];
    worker w[CDSP_EDGE_MAX_STRIPS];
};

static void scan(cdspd_strips *s, int k)
{
    s->st[k] = cdsp_edges_detect_strip(s->img, s->p, k, s->n, s->buf[k], CDSP_MAX_EDGES, &s->nr[k],
                                       &s->nc[k]);
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    cdspd_strips *s = w->s;
    unsigned long seen = 0;
    pthread_mutex_lock(&s->mu);
    for (;;) {
        while (!s->stop && s->gen == seen)
            pthread_cond_wait(&s->go, &s->mu);
        if (s->stop)
            break;
        seen = s->gen;
        pthread_mutex_unlock(&s->mu);
        scan(s, w->k);
        pthread_mutex_lock(&s->mu);
        if (--s->pending == 0)
            pthread_cond_signal(&s->done);
    }
    pthread_mutex_unlock(&s->mu);
    return NULL;
}

int cdspd_strips_start(cdspd_strips **out, int threads, char *err, size_t errlen)
{
    cdspd_strips *s;
    int k;
    *out = NULL;
    if (threads < 1 || threads > CDSP_EDGE_MAX_STRIPS) {
        snprintf(err, errlen, "solver.threads %d is outside 1..%d", threads, CDSP_EDGE_MAX_STRIPS);
        return -1;
    }
    s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory for the strips");
        return -1;
    }
    s->n = threads;
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->go, NULL);
    pthread_cond_init(&s->done, NULL);
    for (k = 0; k < threads; k++) {
        s->buf[k] = malloc(sizeof(cdsp_edge) * CDSP_MAX_EDGES);
        if (!s->buf[k]) {
            snprintf(err, errlen, "out of memory for %d strip buffers (%zu bytes each)", threads,
                     sizeof(cdsp_edge) * CDSP_MAX_EDGES);
            cdspd_strips_stop(s);
            return -1;
        }
    }
    for (k = 1; k < threads; k++) {
        s->w[k].s = s;
        s->w[k].k = k;
        if (pthread_create(&s->w[k].tid, NULL, worker_main, &s->w[k])) {
            snprintf(err, errlen, "cannot start strip worker %d of %d", k, threads - 1);
            cdspd_strips_stop(s);
            return -1;
        }
        s->started = k;
    }
    *out = s;
    return 0;
}

void cdspd_strips_stop(cdspd_strips *s)
{
    int k;
    if (!s)
        return;
    pthread_mutex_lock(&s->mu);
    s->stop = 1;
    pthread_cond_broadcast(&s->go);
    pthread_mutex_unlock(&s->mu);
    for (k = 1; k <= s->started; k++)
        pthread_join(s->w[k].tid, NULL);
    for (k = 0; k < s->n; k++)
        free(s->buf[k]);
    pthread_cond_destroy(&s->go);
    pthread_cond_destroy(&s->done);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

cdsp_status cdspd_strips_detect(cdspd_strips *s, const cdsp_image *img, const cdsp_edge_params *p,
                                cdsp_edge *out, size_t cap, size_t *n)
{
    const cdsp_edge *parts[CDSP_EDGE_MAX_STRIPS];
    int k;
    if (s->n == 1)
        return cdsp_edges_detect(img, p, out, cap, n);
    pthread_mutex_lock(&s->mu);
    s->img = img;
    s->p = p;
    s->pending = s->n - 1;
    s->gen++;
    pthread_cond_broadcast(&s->go);
    pthread_mutex_unlock(&s->mu);
    scan(s, 0);
    pthread_mutex_lock(&s->mu);
    while (s->pending > 0)
        pthread_cond_wait(&s->done, &s->mu);
    pthread_mutex_unlock(&s->mu);
    for (k = 0; k < s->n; k++) {
        if (s->st[k] != CDSP_OK)
            return s->st[k] == CDSP_E_CAPACITY ? cdsp_edges_detect(img, p, out, cap, n) : s->st[k];
        parts[k] = s->buf[k];
    }
    if (cdsp_edges_merge_strips(p, parts, s->nr, s->nc, s->n, out, cap, n) != CDSP_OK)
        return cdsp_edges_detect(img, p, out, cap, n);
    return CDSP_OK;
}
