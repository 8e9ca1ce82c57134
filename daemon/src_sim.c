/*
 * src_sim.c - the built-in simulated camera: libcdsp's renderer draws the
 * pipe of sim_path.h as the calibrated camera sees it (size and distortion
 * from --calib). Rendering a 2448 x 2048 frame takes about 2 s here, so all
 * sim.frames frames are drawn once at open (by sim.threads threads) and then
 * served in turn at sim.rate: the renderer never limits the frame rate.
 * Frame n shows slot n mod sim.frames; its timestamp is the time it was
 * scheduled for.
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "log.h"
#include "sim_path.h"

typedef struct {
    uint8_t *ring;          /* frames * frame_bytes */
    size_t frame_bytes;
    int frames, width, height, bits;
    uint64_t n;             /* next frame number */
    cdspd_pace pace;
    /* rendering */
    pthread_mutex_t mu;
    int next_slot, failed;
    cdsp_status fail_status;
    int *stop;
    const cdspd_config *cfg;
} sim_priv;

static void *render_worker(void *arg)
{
    sim_priv *p = arg;
    size_t nscr = cdsp_render_scratch_size(p->width, p->height);
    float *scratch = malloc(nscr * sizeof *scratch);

    for (;;) {
        int slot;
        cdsp_scene scene;
        cdsp_rng rng;
        cdsp_status st;

        pthread_mutex_lock(&p->mu);
        if (!scratch && !p->failed) {
            p->failed = 1;
            p->fail_status = CDSP_E_CAPACITY;
        }
        slot = p->failed || (p->stop && CDSPD_GET(*p->stop)) || p->next_slot >= p->frames ? -1 : p->next_slot++;
        pthread_mutex_unlock(&p->mu);
        if (slot < 0)
            break;
        cdspd_sim_scene(p->cfg, slot, &scene);
        cdsp_rng_seed(&rng, p->cfg->sim.seed, (uint64_t)slot);
        st = cdsp_render(&scene, &p->cfg->cam, p->ring + (size_t)slot * p->frame_bytes, 0, p->bits,
                         scratch, nscr, &rng);
        if (st != CDSP_OK) {
            pthread_mutex_lock(&p->mu);
            p->failed = 1;
            p->fail_status = st;
            pthread_mutex_unlock(&p->mu);
        }
    }
    free(scratch);
    return NULL;
}

static int sim_open(cdspd_source *s, char *err, size_t errlen)
{
    sim_priv *p = s->priv;
    const cdspd_config *c = s->cfg;
    size_t bpp = c->sim.bits > 8 ? 2 : 1;
    double total;
    int nthreads, i, started = 0;
    pthread_t th[64];
    uint64_t t0;

    if (p->ring) { /* rendered already (reopen) */
        p->pace.started = 0;
        return CDSPD_OPEN_OK;
    }
    p->width = c->cam.width;
    p->height = c->cam.height;
    p->bits = c->sim.bits;
    p->frames = c->sim.frames;
    p->frame_bytes = (size_t)p->width * (size_t)p->height * bpp;
    total = (double)p->frame_bytes * p->frames;
    if (total > 4.0 * 1024 * 1024 * 1024) {
        snprintf(err, errlen, "sim: %d frames of %dx%d need %.1f GiB: lower sim.frames", p->frames,
                 p->width, p->height, total / (1024.0 * 1024 * 1024));
        return CDSPD_OPEN_FATAL;
    }
    p->ring = malloc((size_t)total);
    if (!p->ring) {
        snprintf(err, errlen, "sim: out of memory for %d frames of %dx%d (%.0f MiB)", p->frames,
                 p->width, p->height, total / (1024.0 * 1024));
        return CDSPD_OPEN_FATAL;
    }
    nthreads = c->sim.threads;
    if (nthreads <= 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        nthreads = n > 0 ? (int)n : 1;
    }
    if (nthreads > 64)
        nthreads = 64;
    if (nthreads > p->frames)
        nthreads = p->frames;
    LOG_I(SOURCE, "sim: rendering %d frames of %dx%d, %d bit, with %d thread%s", p->frames,
          p->width, p->height, p->bits, nthreads, nthreads > 1 ? "s" : "");
    t0 = cdspd_now_us();
    p->stop = s->stop;
    p->next_slot = 0;
    p->failed = 0;
    for (i = 1; i < nthreads; i++) {
        if (pthread_create(&th[i], NULL, render_worker, p))
            break;
        started++;
    }
    render_worker(p);
    for (i = 1; i <= started; i++)
        pthread_join(th[i], NULL);
    if (p->failed || p->next_slot < p->frames) {
        if (p->failed)
            snprintf(err, errlen, "sim: rendering failed: %s", cdsp_strerror(p->fail_status));
        else
            snprintf(err, errlen, "sim: rendering interrupted");
        free(p->ring);
        p->ring = NULL;
        return CDSPD_OPEN_FATAL;
    }
    LOG_I(SOURCE, "sim: %d frames rendered in %.1f s", p->frames, (double)(cdspd_now_us() - t0) * 1e-6);
    p->pace.started = 0;
    return CDSPD_OPEN_OK;
}

static int sim_grab(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen)
{
    sim_priv *p = s->priv;
    const cdspd_config *c = s->cfg;
    uint64_t t, period = c->sim.rate > 0 ? (uint64_t)(1e6 / c->sim.rate + 0.5) : 0;

    if (!cdspd_pace_wait(&p->pace, p->n, period, timeout_ms, s->stop, &t))
        return CDSPD_GRAB_TIMEOUT;
    if (f->cap < p->frame_bytes) {
        snprintf(err, errlen, "sim: frame buffer of %zu bytes for a %zu-byte frame", f->cap,
                 p->frame_bytes);
        return CDSPD_GRAB_BAD;
    }
    memcpy(f->data, p->ring + (size_t)cdspd_sim_slot(c, p->n) * p->frame_bytes, p->frame_bytes);
    f->width = p->width;
    f->height = p->height;
    f->bits = p->bits;
    f->stride = p->frame_bytes / (size_t)p->height;
    f->frame_id = p->n;
    f->t_camera_us = period ? t : cdspd_now_us();
    p->n++;
    return CDSPD_GRAB_FRAME;
}

static void sim_close(cdspd_source *s)
{
    (void)s; /* the ring stays for a reopen */
}

static void sim_destroy(cdspd_source *s)
{
    sim_priv *p = s->priv;
    free(p->ring);
    pthread_mutex_destroy(&p->mu);
}

static const cdspd_source_ops sim_ops = {"sim", sim_open, sim_grab, sim_close, sim_destroy};

int cdspd_src_sim_init(cdspd_source *s, char *err, size_t errlen)
{
    sim_priv *p;
    if (cdspd_source_init_priv(s, &sim_ops, sizeof *p, err, errlen))
        return -1;
    p = s->priv;
    pthread_mutex_init(&p->mu, NULL);
    p->cfg = s->cfg;
    return 0;
}
