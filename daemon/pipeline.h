/*
 * pipeline.h - one running configuration: the source, the capture thread,
 * the frame pool, the processing thread (solve, encode, send) and the
 * recorder. A SIGHUP reload stops one pipeline and starts another; the
 * statistics and the datagram sequence number live outside and carry on.
 *
 * Capture thread: opens the source (at start: retrying for open_timeout,
 * then giving up; later: forever, with back-off retry_min .. retry_max),
 * grabs frames into the pool's back buffer and publishes them. A lost
 * source is closed and reopened; meanwhile the processing thread sends a
 * status datagram every status_interval.
 *
 * Processing thread: takes the latest frame, solves it (tracking from the
 * previous result, the library falls back to a full search), sends one
 * datagram per frame. Its workspace, generator and buffers are allocated
 * once at start: nothing is allocated per frame.
 */
#ifndef CDSPD_PIPELINE_H
#define CDSPD_PIPELINE_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "stats.h"

typedef struct cdspd_pipeline cdspd_pipeline;

typedef enum {
    CDSPD_PIPE_STARTING = 0, /* the source is being opened for the first time */
    CDSPD_PIPE_RUNNING = 1,  /* frames flow (or the source is being reopened) */
    CDSPD_PIPE_FAILED = 2,   /* the first open gave up: see cdspd_pipeline_error */
    CDSPD_PIPE_ENDED = 3     /* the source has no more frames, all were sent */
} cdspd_pipe_state;

/* Starts the threads. must_open: the first open may fail (state FAILED)
 * rather than retry forever. Returns 0, or an exit status with err
 * (2: the source kind is not built in; 1: out of memory, no socket...). */
int cdspd_pipeline_start(cdspd_pipeline **out, const cdspd_config *cfg, cdspd_stats *stats,
                         uint32_t *seq, int must_open, char *err, size_t errlen);

cdspd_pipe_state cdspd_pipeline_state(cdspd_pipeline *p);
/* FAILED: the exit status (3) and the message. */
int cdspd_pipeline_error(cdspd_pipeline *p, char *err, size_t errlen);
/* Increases while the processing thread runs (watchdog). */
uint64_t cdspd_pipeline_heartbeat(cdspd_pipeline *p);

/* Stops the threads, closes the source, frees everything. */
void cdspd_pipeline_stop(cdspd_pipeline *p);

#endif
