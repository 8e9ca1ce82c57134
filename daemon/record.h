/*
 * record.h - --record DIR: every record_every-th processed frame is saved
 * as DIR/<run>-<seq>.pgm (the run's start time, the datagram's sequence
 * number) and its result appended to DIR/<run>.jsonl (the datagram's JSON
 * record plus "file"), and the calibration is saved as DIR/<run>.yaml, so
 * `--source file:DIR/<run>-*.pgm` replays it without --calib (as does
 * `cdsp_tool solve --calib DIR/<run>.yaml`). A writer thread of its own with one preallocated
 * buffer: the processing thread only copies the frame into it, and skips
 * (counts) frames while the writer is still busy, unless the source is a
 * replay (lossless: the offer waits for the writer, as the frame pool
 * does, so a replay records every frame it should). Any write error (a
 * full disk) stops recording for the rest of the run, never the daemon.
 */
#ifndef CDSPD_RECORD_H
#define CDSPD_RECORD_H

#include <pthread.h>
#include <stdint.h>
#include <stdio.h>

#include "config.h"
#include "proto.h"
#include "source.h"
#include "stats.h"

typedef struct {
    char dir[CDSPD_STR];
    char run[32];
    int every;
    pthread_t thread;
    int have_thread;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int busy, stop;
    int lossless;           /* set before the first offer: offers wait */
    int disabled;           /* CDSPD_GET/SET: the writer sets it */
    cdspd_frame frame;      /* its own buffer */
    cdspd_record rec;
    FILE *results;
    cdspd_stats *stats;
} cdspd_recorder;

/* 0 (also when recording is off), or -1 with err. */
int cdspd_recorder_start(cdspd_recorder *r, const cdspd_config *c, size_t frame_bytes,
                         cdspd_stats *stats, char *err, size_t errlen);
/* Is frame number `processed` (0, 1, ...) one to record? */
int cdspd_recorder_wants(const cdspd_recorder *r, uint64_t processed);
/* Would a frame offered now be taken (only the offering thread makes the
 * writer busy, so the answer holds until it offers)? */
int cdspd_recorder_ready(cdspd_recorder *r);
/* Offers wait for a busy writer instead of skipping (a replay source). */
void cdspd_recorder_set_lossless(cdspd_recorder *r, int lossless);
/* Hand over a copy of the frame and its record: 1 taken, 0 skipped. */
int cdspd_recorder_offer(cdspd_recorder *r, const cdspd_frame *f, const cdspd_record *rec);
void cdspd_recorder_stop(cdspd_recorder *r);

#endif
