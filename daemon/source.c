/*
 * source.c - picks the source by the source key (see source.h), and small
 * helpers shared by the sources. Which optional sources exist is decided at
 * build time (daemon.mk defines CDSPD_HAVE_ARAVIS, _V4L2, _LIBCAMERA when
 * their development packages are present).
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

uint64_t cdspd_now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

int cdspd_sleep_until(uint64_t t_us, int max_ms, int *stop)
{
    uint64_t limit = cdspd_now_us() + (uint64_t)max_ms * 1000u;
    for (;;) {
        uint64_t now = cdspd_now_us(), until = t_us < limit ? t_us : limit, d;
        struct timespec ts;
        if (now >= t_us)
            return 1;
        if (now >= limit || (stop && CDSPD_GET(*stop)))
            return 0;
        /* wake at least every 50 ms to notice a stop */
        d = until - now;
        if (d > 50000)
            d = 50000;
        ts.tv_sec = (time_t)(d / 1000000u);
        ts.tv_nsec = (long)(d % 1000000u) * 1000L;
        nanosleep(&ts, NULL);
    }
}

int cdspd_pace_wait(cdspd_pace *pc, uint64_t n, uint64_t period, int timeout_ms, int *stop,
                    uint64_t *t)
{
    if (!pc->started) {
        pc->t_base = cdspd_now_us();
        pc->started = 1;
    }
    *t = pc->t_base + n * period;
    if (!period)
        return 1;
    {
        uint64_t now = cdspd_now_us();
        if (now > *t + 2 * period) {
            pc->t_base = now - n * period;
            *t = now;
        }
    }
    return cdspd_sleep_until(*t, timeout_ms, stop);
}

int cdspd_source_available(int kind, const char **why)
{
    *why = NULL;
    switch (kind) {
    case CDSPD_SRC_SIM:
    case CDSPD_SRC_FILE:
        return 1;
    case CDSPD_SRC_ARAVIS:
#ifdef CDSPD_HAVE_ARAVIS
        return 1;
#else
        *why = "the aravis source is not built in (install libaravis-dev and rebuild)";
        return 0;
#endif
    case CDSPD_SRC_V4L2:
#ifdef CDSPD_HAVE_V4L2
        return 1;
#else
        *why = "the v4l2 source is not built in (install libv4l-dev and rebuild)";
        return 0;
#endif
    case CDSPD_SRC_LIBCAMERA:
#ifdef CDSPD_HAVE_LIBCAMERA
        return 1;
#else
        *why = "the libcamera source is not built in (install libcamera-dev and rebuild)";
        return 0;
#endif
    }
    *why = "unknown source kind";
    return 0;
}

cdspd_source *cdspd_source_new(const cdspd_config *cfg, char *err, size_t errlen)
{
    cdspd_source *s;
    const char *arg, *why;
    int kind = cdspd_source_kind_parse(cfg->source, &arg), r = -1;

    if (!cdspd_source_available(kind, &why)) {
        snprintf(err, errlen, "key 'source': '%s': %s", cfg->source, why);
        return NULL;
    }
    s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->cfg = cfg;
    s->arg = arg;
    switch (kind) {
    case CDSPD_SRC_SIM: r = cdspd_src_sim_init(s, err, errlen); break;
    case CDSPD_SRC_FILE: r = cdspd_src_file_init(s, err, errlen); break;
#ifdef CDSPD_HAVE_ARAVIS
    case CDSPD_SRC_ARAVIS: r = cdspd_src_aravis_init(s, err, errlen); break;
#endif
#ifdef CDSPD_HAVE_V4L2
    case CDSPD_SRC_V4L2: r = cdspd_src_v4l2_init(s, err, errlen); break;
#endif
#ifdef CDSPD_HAVE_LIBCAMERA
    case CDSPD_SRC_LIBCAMERA: r = cdspd_src_libcamera_init(s, err, errlen); break;
#endif
    default: break;
    }
    if (r) {
        free(s->priv);
        free(s);
        return NULL;
    }
    return s;
}

int cdspd_source_init_priv(cdspd_source *s, const cdspd_source_ops *ops, size_t size, char *err,
                           size_t errlen)
{
    s->priv = calloc(1, size);
    if (!s->priv) {
        snprintf(err, errlen, "%s: out of memory", ops->kind);
        return -1;
    }
    s->ops = ops;
    return 0;
}

void cdspd_source_free(cdspd_source *s)
{
    if (!s)
        return;
    if (s->priv && s->ops && s->ops->destroy)
        s->ops->destroy(s);
    free(s->priv);
    free(s);
}
