/*
 * pipeline.c - see pipeline.h.
 */
#define _GNU_SOURCE
#include "pipeline.h"

#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp.h"
#include "cdsp_host.h" /* CDSP_HOST_JSON_PIPES_MAX */
#include "log.h"
#include "mavout.h"
#include "mount.h"
#include "pool.h"
#include "proto.h"
#include "record.h"
#include "sender.h"
#include "sim_path.h"
#include "source.h"
#include "strips.h"

/* The capture thread's longest wait inside the source, ms: how quickly it
 * notices a stop. */
#define GRAB_TIMEOUT_MS 100

struct cdspd_pipeline {
    cdspd_config cfg;          /* a copy: the sources point into it */
    cdspd_stats *stats;
    uint32_t *seq;
    cdspd_source *src;
    cdspd_pool pool;
    cdspd_sender sender;
    cdspd_mavout *mav;         /* NULL without mavlink links */
    cdspd_mount mount;
    cdspd_recorder rec;
    cdsp_frame_all_ws *ws;     /* .frame is the single path's */
    cdsp_tracker trk;          /* solver.multi_pipe: every pipe's track */
    cdspd_strips *strips;      /* solver.threads > 1: the full search in strips
                                  (the single path's; multi_pipe runs on one core) */
    cdsp_params params;
    int must_open;

    pthread_t capture, proc;
    int have_capture, have_proc;
    int stop;                  /* CDSPD_GET/SET: read by every thread */

    pthread_mutex_t mu;        /* guards the fields below */
    cdspd_pipe_state state;
    int capture_done;          /* the capture thread published its last frame */
    int exit_status;
    char error[1024];
    uint64_t heartbeat;
};

static void set_state(cdspd_pipeline *p, cdspd_pipe_state s)
{
    pthread_mutex_lock(&p->mu);
    /* both are final: a reopening source must not turn an ended stream
     * (--frames reached, processing stopped) back into a running one */
    if (p->state != CDSPD_PIPE_FAILED && p->state != CDSPD_PIPE_ENDED)
        p->state = s;
    pthread_mutex_unlock(&p->mu);
}

static void pin(int cpu, const char *what)
{
    cpu_set_t set;
    if (cpu < 0)
        return;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (pthread_setaffinity_np(pthread_self(), sizeof set, &set))
        LOG_W(MAIN, "cannot pin the %s thread to CPU %d", what, cpu);
    else
        LOG_D(MAIN, "%s thread pinned to CPU %d", what, cpu);
}

/* ------------------------------------------------------------------------
 * Capture thread.
 * ---------------------------------------------------------------------- */
static void *capture_main(void *arg)
{
    cdspd_pipeline *p = arg;
    const cdspd_config *c = &p->cfg;
    char err[1024];
    int opened = 0, first = 1, lost_before = 0, fails = 0, ended = 0;
    double backoff = c->retry_min, left = 0, wait;
    uint64_t t_first = cdspd_now_us(), last_bad_log = 0, bad_since_log = 0;

    pin(c->capture_cpu, "capture");
    while (!CDSPD_GET(p->stop)) {
        cdspd_frame *f;
        int r;
        if (!opened) {
            err[0] = 0;
            r = p->src->ops->open(p->src, err, sizeof err);
            if (r == CDSPD_OPEN_OK) {
                opened = 1;
                fails = 0;
                backoff = c->retry_min;
                if (lost_before) {
                    cdspd_stats_add(p->stats, CDSPD_STAT(reconnects), 1);
                    LOG_I(SOURCE, "%s: reopened", c->source);
                } else {
                    LOG_I(SOURCE, "%s: open", c->source);
                }
                cdspd_stats_set_down(p->stats, 0);
                if (first)
                    set_state(p, CDSPD_PIPE_RUNNING);
                first = 0;
                continue;
            }
            if (CDSPD_GET(p->stop))
                break;
            left = c->open_timeout - (double)(cdspd_now_us() - t_first) * 1e-6;
            if (first && p->must_open && (r == CDSPD_OPEN_FATAL || left <= 0)) {
                pthread_mutex_lock(&p->mu);
                snprintf(p->error, sizeof p->error, "%s%s", err,
                         r == CDSPD_OPEN_FATAL ? "" : " (gave up after open_timeout)");
                p->exit_status = 3;
                p->state = CDSPD_PIPE_FAILED;
                pthread_mutex_unlock(&p->mu);
                break;
            }
            if (first && !p->must_open) {
                set_state(p, CDSPD_PIPE_RUNNING); /* a reload runs on, reopening */
                first = 0;
            }
            cdspd_stats_set_down(p->stats, 1);
            /* the first failure and then every 10th at warning level */
            if (fails++ % 10 == 0)
                LOG_W(SOURCE, "%s; retrying in %.1f s", err, backoff);
            else
                LOG_D(SOURCE, "%s; retrying in %.1f s", err, backoff);
            wait = first && p->must_open && left < backoff ? left : backoff;
            cdspd_sleep_until(cdspd_now_us() + (uint64_t)(wait * 1e6), (int)(wait * 1000) + 1,
                              &p->stop);
            backoff *= 2;
            if (backoff > c->retry_max)
                backoff = c->retry_max;
            continue;
        }
        f = cdspd_pool_back(&p->pool);
        f->frame_id = f->t_camera_us = 0;
        f->bad = 0;
        err[0] = 0;
        r = p->src->ops->grab(p->src, f, GRAB_TIMEOUT_MS, err, sizeof err);
        switch (r) {
        case CDSPD_GRAB_FRAME:
            cdspd_stats_add(p->stats, CDSPD_STAT(frames_in), 1);
            if (cdspd_pool_publish(&p->pool))
                cdspd_stats_add(p->stats, CDSPD_STAT(frames_dropped), 1);
            break;
        case CDSPD_GRAB_TIMEOUT:
            break;
        case CDSPD_GRAB_BAD: {
            uint64_t now = cdspd_now_us();
            cdspd_stats_add(p->stats, CDSPD_STAT(frames_bad), 1);
            /* handed on as a marker: receivers get a bad-frame datagram for it
             * (docs/protocol.md), not silence */
            f->bad = 1;
            if (cdspd_pool_publish(&p->pool))
                cdspd_stats_add(p->stats, CDSPD_STAT(frames_dropped), 1);
            bad_since_log++;
            if (now - last_bad_log >= 10000000u) {
                LOG_W(SOURCE, "frame skipped: %s (%llu skipped since the last such message)",
                      *err ? err : "unusable frame", (unsigned long long)bad_since_log);
                last_bad_log = now;
                bad_since_log = 0;
            } else {
                LOG_D(SOURCE, "frame skipped: %s", *err ? err : "unusable frame");
            }
            break;
        }
        case CDSPD_GRAB_LOST:
            LOG_W(SOURCE, "%s lost: %s; reopening (back-off %.1f .. %.1f s)", c->source,
                  *err ? err : "no reason given", c->retry_min, c->retry_max);
            cdspd_stats_set_down(p->stats, 1);
            p->src->ops->close(p->src); /* may wait for a dead device's time-outs */
            opened = 0;
            lost_before = 1;
            break;
        case CDSPD_GRAB_END:
            LOG_I(SOURCE, "%s: no more frames", c->source);
            ended = 1;
            goto done;
        default:
            break;
        }
    }
done:
    if (opened)
        p->src->ops->close(p->src);
    if (ended) {
        pthread_mutex_lock(&p->mu);
        p->capture_done = 1;
        pthread_mutex_unlock(&p->mu);
    }
    return NULL;
}

/* ------------------------------------------------------------------------
 * Processing thread.
 * ---------------------------------------------------------------------- */
static void fill_counters(cdspd_pipeline *p, cdspd_record *rec)
{
    cdspd_counts n;
    cdspd_stats_get(p->stats, &n);
    rec->frames_in = (uint32_t)n.frames_in;
    rec->frames_dropped = (uint32_t)n.frames_dropped;
    rec->frames_bad = (uint32_t)n.frames_bad;
    rec->reconnects = (uint32_t)n.reconnects;
}

static void send_record(cdspd_pipeline *p, cdspd_record *rec, uint8_t *buf, size_t cap)
{
    size_t n;
    rec->seq = (*p->seq)++;
    if (p->cfg.format == CDSPD_FORMAT_JSON)
        n = cdspd_proto_encode_json(rec, (char *)buf, cap);
    else
        n = cdspd_proto_encode(rec, buf, cap);
    if (!n) {
        LOG_E(PROC, "record %lu did not fit its buffer", (unsigned long)rec->seq);
        return;
    }
    {
        uint32_t failed;
        cdspd_sender_send(&p->sender, buf, n, &failed);
        cdspd_stats_sent(p->stats, p->sender.n, failed);
    }
}

static void *proc_main(void *arg)
{
    cdspd_pipeline *p = arg;
    const cdspd_config *c = &p->cfg;
    cdsp_rng rng;
    cdsp_result res, prev;
    cdspd_body_pose body;
    int have_prev = 0;
    uint64_t processed = 0, status_us = (uint64_t)(c->status_interval * 1e6);
    /* wake at least every 100 ms (the watchdog follows the heartbeat) */
    uint64_t wait_us = status_us < 100000u ? status_us : 100000u, last = cdspd_now_us();
    /* a JSON record with every pipe and pair needs more (binary: at most
     * CDSPD_PROTO_MAX_SIZE, below 4096) */
    const size_t cap = 4096 + (c->multi_pipe ? CDSP_HOST_JSON_PIPES_MAX(CDSP_MAX_PIPES) : 0);
    const char *src_arg;
    int sim_truth = c->sim.truth && c->format == CDSPD_FORMAT_JSON &&
                    cdspd_source_kind_parse(c->source, &src_arg) == CDSPD_SRC_SIM;
    uint8_t *buf = malloc(cap);

    if (!buf) {
        LOG_E(PROC, "out of memory");
        return NULL;
    }
    pin(c->proc_cpu, "processing");
    cdsp_rng_seed(&rng, c->seed, 1);
    while (!CDSPD_GET(p->stop)) {
        cdspd_frame *f;
        cdspd_record rec;
        int done, starting;

        pthread_mutex_lock(&p->mu);
        done = p->capture_done;
        starting = p->state == CDSPD_PIPE_STARTING;
        p->heartbeat++;
        pthread_mutex_unlock(&p->mu);
        f = cdspd_pool_take(&p->pool, done ? 1000 : wait_us);
        if (CDSPD_GET(p->stop))
            break;
        memset(&rec, 0, sizeof rec);
        rec.radius = c->radius;
        if (!f) {
            if (done) {
                set_state(p, CDSPD_PIPE_ENDED);
                break;
            }
            /* Nothing is streamed before the source's first opening (a sim
             * pre-rendering, a camera being found): cdspd's log says what it
             * waits for, and status datagrams start once it ran. */
            if (starting || cdspd_now_us() - last < status_us)
                continue;
            last = cdspd_now_us();
            rec.kind = CDSPD_KIND_STATUS;
            if (cdspd_stats_down(p->stats)) {
                rec.status = CDSPD_ST_SOURCE_DOWN;
                rec.flags = CDSPD_FLAG_SOURCE_DOWN;
            } else {
                rec.status = CDSPD_ST_NO_FRAME;
            }
            rec.t_host_us = cdspd_now_us();
            fill_counters(p, &rec);
            have_prev = 0;
            send_record(p, &rec, buf, cap);
            cdspd_stats_add(p->stats, CDSPD_STAT(status_sent), 1);
            LOG_D(PROC, "no frame for %.2f s: status %s", c->status_interval,
                  cdspd_status_token(rec.status));
            continue;
        }
        last = cdspd_now_us();
        rec.kind = CDSPD_KIND_FRAME;
        rec.frame_id = f->frame_id;
        if (sim_truth) {
            rec.has_truth = 1;
            rec.truth_in_view = cdspd_sim_truth(c, f->frame_id, rec.truth_point,
                                                rec.truth_direction, &rec.truth_distance);
        }
        rec.t_camera_us = f->t_camera_us;
        rec.t_host_us = f->t_ready_us;
        if (f->bad) { /* counted and logged by the capture thread */
            rec.status = CDSPD_ST_BAD_FRAME;
            have_prev = 0;
        } else if (f->width != c->cam.width || f->height != c->cam.height || f->bits < 1 ||
                   f->bits > 16) {
            rec.status = CDSPD_ST_BAD_FRAME;
            have_prev = 0;
            cdspd_stats_add(p->stats, CDSPD_STAT(frames_bad), 1);
            LOG_W(PROC, "frame %llu is %dx%d (%d bit) but %s is for %dx%d: not processed",
                  (unsigned long long)f->frame_id, f->width, f->height, f->bits, c->calib,
                  c->cam.width, c->cam.height);
        } else {
            cdsp_image img;
            cdsp_status st;
            uint64_t t0, t1;
            img.data = f->data;
            img.width = f->width;
            img.height = f->height;
            img.stride = f->stride;
            img.bits = f->bits;
            t0 = cdspd_now_us();
            if (c->multi_pipe) {
                /* every pipe; the record's pose is the first-ranked one */
                cdsp_result all[CDSP_MAX_PIPES];
                size_t np = 0;
                st = cdsp_frame_solve_all(&img, &c->cam, (cdsp_real)c->radius, &p->params, &p->trk,
                                          p->ws, &rng, all, CDSP_MAX_PIPES, &np);
                rec.flags |= CDSPD_FLAG_MULTI;
                if (st == CDSP_OK) {
                    res = all[0];
                    cdspd_record_set_pipes(&rec, all, np);
                }
            } else if (p->strips && !have_prev) { /* solver.threads: the full search in strips */
                cdsp_frame_edges fe;
                st = cdsp_frame_prepare(&img, &p->params, &fe);
                if (st == CDSP_OK) {
                    fe.status = cdspd_strips_detect(p->strips, &img, &fe.edge, p->ws->frame.edge,
                                                    CDSP_MAX_EDGES, &fe.n);
                    st = cdsp_frame_solve_detected(&img, &c->cam, (cdsp_real)c->radius,
                                                   &p->params, &fe, &p->ws->frame, &rng, &res);
                }
            } else {
                st = cdsp_frame_solve(&img, &c->cam, (cdsp_real)c->radius, &p->params,
                                      have_prev ? &prev : NULL, &p->ws->frame, &rng, &res);
            }
            t1 = cdspd_now_us();
            rec.status = st;
            rec.proc_us = (uint32_t)(t1 - t0);
            if (st == CDSP_OK) {
                cdspd_record_set_result(&rec, &res);
                cdspd_mount_apply(&p->mount, rec.point, rec.direction, &body);
                memcpy(rec.point_body, body.point, sizeof rec.point_body);
                memcpy(rec.direction_body, body.direction, sizeof rec.direction_body);
                prev = res;
                have_prev = 1;
            } else {
                have_prev = 0;
            }
            cdspd_stats_add(p->stats, cdspd_stats_status_field(st), 1);
        }
        cdspd_stats_add(p->stats, CDSPD_STAT(processed), 1);
        if (rec.status != CDSPD_ST_BAD_FRAME && cdspd_recorder_wants(&p->rec, processed) &&
            cdspd_recorder_ready(&p->rec))
            rec.flags |= CDSPD_FLAG_RECORDED;
        fill_counters(p, &rec);
        rec.latency_us = (uint32_t)(cdspd_now_us() - f->t_ready_us);
        send_record(p, &rec, buf, cap);
        cdspd_mavout_frame(p->mav, &rec, &body);
        cdspd_stats_latency(p->stats, rec.proc_us, (uint32_t)(cdspd_now_us() - f->t_ready_us));
        if (rec.flags & CDSPD_FLAG_RECORDED)
            cdspd_recorder_offer(&p->rec, f, &rec);
        if (cdspd_log_enabled(CDSPD_LOGC_PROC, CDSPD_LOG_DEBUG))
            LOG_D(PROC, "seq %lu frame %llu: %s, solve %u us, ready->encoded %u us",
                  (unsigned long)rec.seq, (unsigned long long)rec.frame_id,
                  cdspd_status_token(rec.status), rec.proc_us, rec.latency_us);
        processed++;
        if (c->frames > 0) {
            /* --frames: exactly that many processed (counted over reloads,
             * like --duration), then the stream ends as a file source's does */
            cdspd_counts k;
            cdspd_stats_get(p->stats, &k);
            if (k.processed >= (uint64_t)c->frames) {
                set_state(p, CDSPD_PIPE_ENDED);
                break;
            }
        }
    }
    free(buf);
    return NULL;
}

/* ------------------------------------------------------------------------
 * Start and stop.
 * ---------------------------------------------------------------------- */
int cdspd_pipeline_start(cdspd_pipeline **out, const cdspd_config *cfg, cdspd_stats *stats,
                         uint32_t *seq, int must_open, char *err, size_t errlen)
{
    cdspd_pipeline *p = calloc(1, sizeof *p);
    size_t bytes;

    *out = NULL;
    if (!p) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    p->cfg = *cfg;
    p->stats = stats;
    p->seq = seq;
    p->must_open = must_open;
    pthread_mutex_init(&p->mu, NULL);
    cdspd_config_params(&p->cfg, &p->params);
    p->src = cdspd_source_new(&p->cfg, err, errlen);
    if (!p->src) {
        pthread_mutex_destroy(&p->mu);
        free(p);
        return 2;
    }
    p->src->stop = &p->stop;
    bytes = (size_t)p->cfg.cam.width * (size_t)p->cfg.cam.height * 2;
    p->ws = malloc(sizeof *p->ws);
    cdsp_tracker_init(&p->trk);
    p->trk.gate_px = (cdsp_real)(2 * p->cfg.track_band_px); /* as cdsp_tool solve --all --track */
    p->trk.full_every = p->cfg.full_every;
    if (!p->ws || cdspd_pool_init(&p->pool, bytes)) {
        snprintf(err, errlen, "out of memory for the frame buffers (3 x %zu bytes)", bytes);
        goto fail;
    }
    if (p->cfg.threads > 1 && cdspd_strips_start(&p->strips, p->cfg.threads, err, errlen))
        goto fail;
    cdspd_pool_set_lossless(&p->pool, p->src->replay);
    if (cdspd_sender_open(&p->sender, &p->cfg, err, errlen))
        goto fail;
    cdspd_stats_set_dests(stats, &p->cfg);
    cdspd_mount_from_euler(&p->mount, p->cfg.mount, p->cfg.mount + 3);
    if (cdspd_mavout_start(&p->mav, &p->cfg, stats, err, errlen)) {
        cdspd_sender_close(&p->sender);
        goto fail;
    }
    if (cdspd_recorder_start(&p->rec, &p->cfg, bytes, stats, err, errlen)) {
        cdspd_mavout_stop(p->mav);
        cdspd_sender_close(&p->sender);
        goto fail;
    }
    cdspd_recorder_set_lossless(&p->rec, p->src->replay);
    if (pthread_create(&p->proc, NULL, proc_main, p)) {
        snprintf(err, errlen, "cannot start the processing thread");
        goto fail_rec;
    }
    p->have_proc = 1;
    if (pthread_create(&p->capture, NULL, capture_main, p)) {
        snprintf(err, errlen, "cannot start the capture thread");
        goto fail_rec;
    }
    p->have_capture = 1;
    *out = p;
    return 0;

fail_rec:
    cdspd_pipeline_stop(p);
    return 1;
fail:
    cdspd_strips_stop(p->strips);
    cdspd_pool_destroy(&p->pool);
    free(p->ws);
    cdspd_source_free(p->src);
    pthread_mutex_destroy(&p->mu);
    free(p);
    return 1;
}

cdspd_pipe_state cdspd_pipeline_state(cdspd_pipeline *p)
{
    cdspd_pipe_state s;
    pthread_mutex_lock(&p->mu);
    s = p->state;
    pthread_mutex_unlock(&p->mu);
    return s;
}

int cdspd_pipeline_error(cdspd_pipeline *p, char *err, size_t errlen)
{
    int st;
    pthread_mutex_lock(&p->mu);
    snprintf(err, errlen, "%s", p->error);
    st = p->exit_status;
    pthread_mutex_unlock(&p->mu);
    return st;
}

uint64_t cdspd_pipeline_heartbeat(cdspd_pipeline *p)
{
    uint64_t h;
    pthread_mutex_lock(&p->mu);
    h = p->heartbeat;
    pthread_mutex_unlock(&p->mu);
    return h;
}

void cdspd_pipeline_stop(cdspd_pipeline *p)
{
    if (!p)
        return;
    CDSPD_SET(p->stop, 1);
    cdspd_pool_wake(&p->pool); /* first: a replay's capture thread may wait in publish */
    if (p->have_capture)
        pthread_join(p->capture, NULL);
    if (p->have_proc)
        pthread_join(p->proc, NULL);
    cdspd_recorder_stop(&p->rec);
    cdspd_mavout_stop(p->mav);
    cdspd_sender_close(&p->sender);
    cdspd_source_free(p->src);
    cdspd_strips_stop(p->strips);
    cdspd_pool_destroy(&p->pool);
    free(p->ws);
    pthread_mutex_destroy(&p->mu);
    free(p);
}
