/*
 * source.h - what every frame source (src_*.c) provides to the capture
 * thread: open, grab a frame into a caller buffer, close. One source per
 * file; cdspd_source_new() picks one by the source key's prefix.
 *
 * Threads: all calls of one source come from the capture thread, except
 * that cdspd_source_new/free run on the main thread while no capture thread
 * exists. Sources may run threads of their own (Aravis's heartbeat,
 * libcamera's event loop) and must hand their results over safely.
 */
#ifndef CDSPD_SOURCE_H
#define CDSPD_SOURCE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "config.h"

/* A frame buffer of the pool. The source writes pixels (8-bit: one byte per
 * pixel; 9..16 bits: two bytes, native order, values < 2^bits) and the
 * fields; the pipeline sets t_ready_us. */
typedef struct {
    uint8_t *data;
    size_t cap;            /* bytes of data */
    int width, height, bits;
    size_t stride;
    uint64_t frame_id;     /* the source's frame number */
    uint64_t t_camera_us;  /* the source's timestamp, us; 0 = none */
    uint64_t t_ready_us;   /* host CLOCK_MONOTONIC when it was ready */
    int bad;               /* set by the capture thread: the source said GRAB_BAD, only
                            * frame_id, t_camera_us (0 when the source did not set them)
                            * mean anything; a bad-frame datagram reports it */
} cdspd_frame;

/* grab() results */
enum {
    CDSPD_GRAB_FRAME = 1,    /* *f holds a frame */
    CDSPD_GRAB_TIMEOUT = 0,  /* nothing yet (not an error) */
    CDSPD_GRAB_LOST = -1,    /* the device is gone: close, then reopen with back-off */
    CDSPD_GRAB_END = -2,     /* no more frames ever (file source at its end) */
    CDSPD_GRAB_BAD = -3      /* a frame arrived but cannot be used (incomplete...): counted */
};

/* open() results */
enum {
    CDSPD_OPEN_OK = 0,
    CDSPD_OPEN_RETRY = -1,   /* not there (yet): camera not found, device busy */
    CDSPD_OPEN_FATAL = -2    /* will not work whatever the wait: wrong format, bad argument */
};

typedef struct cdspd_source cdspd_source;

typedef struct {
    const char *kind;
    /* err gets one line naming the source and the problem. */
    int (*open)(cdspd_source *s, char *err, size_t errlen);
    /* Waits up to timeout_ms for a frame; fills f (f->cap bytes at f->data). */
    int (*grab)(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen);
    void (*close)(cdspd_source *s);
    /* After close: releases what priv holds. cdspd_source_free() then
     * frees priv itself (free()), unless destroy did and set it NULL (a
     * C++ object). */
    void (*destroy)(cdspd_source *s);
} cdspd_source_ops;

struct cdspd_source {
    const cdspd_source_ops *ops;
    const cdspd_config *cfg;
    const char *arg;       /* after "kind:" in cfg->source */
    void *priv;
    int *stop;             /* set by the pipeline to abort long waits (CDSPD_GET) */
    int replay;            /* set by init: frames from storage, every one is processed in
                            * order (the capture thread waits for the processing thread);
                            * 0: a live camera, the latest frame wins and others drop */
};

/* A source for cfg->source (not opened), or NULL with err: kind not built
 * in (exit status 2) or out of memory. */
cdspd_source *cdspd_source_new(const cdspd_config *cfg, char *err, size_t errlen);
void cdspd_source_free(cdspd_source *s);

/* How many files the file source's GLOB matches now (0: none, or it cannot
 * be listed): --check-config refuses a replay of nothing. */
size_t cdspd_src_file_matches(const char *glob_pattern);

/* The calibration saved beside a recording, for a file: source given no
 * calib: for the first file GLOB matches, DIR/NAME.pgm, the first that
 * exists of DIR/RUN.yaml (RUN: NAME up to its last '-', as --record names
 * frames RUN-SEQ.pgm and saves RUN.yaml) and DIR/camera.yaml (cdsp_tool
 * sim's). Returns 1 with the path in out, else 0. */
int cdspd_src_file_find_calib(const char *glob_pattern, char *out, size_t cap);

/* cdspd --list-cameras: the cameras a built-in camera source sees, one line
 * each on out, "KIND:ID" (what --source takes) then a description; returns
 * how many (0: none), or -1 with one line in err when it could not look. */
int cdspd_src_aravis_list(FILE *out, char *err, size_t errlen);
int cdspd_src_v4l2_list(FILE *out, char *err, size_t errlen);
int cdspd_src_libcamera_list(FILE *out, char *err, size_t errlen);

/* Whether a kind was built in; the error text when not. */
int cdspd_source_available(int kind, const char **why);

/* The start every C source's constructor shares: s->priv a zeroed block
 * of size bytes, s->ops = ops. 0, or -1 with "KIND: out of memory". */
int cdspd_source_init_priv(cdspd_source *s, const cdspd_source_ops *ops, size_t size, char *err,
                           size_t errlen);

/* Each source's constructor: fills s->ops and s->priv. 0 or -1 with err. */
int cdspd_src_sim_init(cdspd_source *s, char *err, size_t errlen);
int cdspd_src_file_init(cdspd_source *s, char *err, size_t errlen);
int cdspd_src_aravis_init(cdspd_source *s, char *err, size_t errlen);
int cdspd_src_v4l2_init(cdspd_source *s, char *err, size_t errlen);
int cdspd_src_libcamera_init(cdspd_source *s, char *err, size_t errlen);

/* Flags shared between threads. C99 has no atomics: GCC's and Clang's
 * builtins (sequentially consistent enough for a stop flag). */
#define CDSPD_GET(x) __atomic_load_n(&(x), __ATOMIC_ACQUIRE)
#define CDSPD_SET(x, v) __atomic_store_n(&(x), (v), __ATOMIC_RELEASE)

/* Helpers for sources. */
uint64_t cdspd_now_us(void);                 /* CLOCK_MONOTONIC, us */
/* Sleep until CLOCK_MONOTONIC reaches t_us, at most max_ms, waking early if
 * *stop is set. Returns 1 when t_us was reached. */
int cdspd_sleep_until(uint64_t t_us, int max_ms, int *stop);

/* Frame pacing of the sources that make their own frames (sim, file): frame
 * n is due at t_base + n * period (us). Like a real camera, a source that
 * fell far behind (a stalled machine) does not catch up on the frames it
 * could not deliver: the schedule restarts from now. */
typedef struct {
    uint64_t t_base; /* time frame 0 was due */
    int started;     /* 0: the schedule starts at the next wait */
} cdspd_pace;
/* Wait until frame n is due (no wait when period is 0); *t is its due
 * time. Returns 0 when timeout_ms passed or *stop was set first. */
int cdspd_pace_wait(cdspd_pace *pc, uint64_t n, uint64_t period, int timeout_ms, int *stop,
                    uint64_t *t);

#endif
