/*
 * stats.h - counters and latency percentiles of a cdspd run: frames in,
 * processed, dropped, bad; datagrams sent and failed; reconnects; solve
 * time and end-to-end latency (frame ready -> datagram sent) p50/p99 over
 * the last reporting window. Kept across SIGHUP reloads. Fixed arrays:
 * recording a sample never allocates. Thread-safe (one mutex).
 */
#ifndef CDSPD_STATS_H
#define CDSPD_STATS_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"

/* Latency samples kept per window (the most recent ones when more came). */
#define CDSPD_STATS_SAMPLES 16384

/* sent: datagrams that went out to at least one destination; send_errors:
 * failed sends summed over the destinations; dest_*: per destination, in
 * the order of the dest key (dest_name). */
typedef struct {
    uint64_t frames_in, frames_bad, frames_dropped, reconnects;
    uint64_t processed, ok, not_found, status_sent, sent, send_errors;
    uint64_t recorded, record_skipped;
    uint64_t dest_sent[CDSPD_MAX_DEST], dest_errors[CDSPD_MAX_DEST];
    uint64_t arg_errors;   /* frames the library refused as bad arguments */
} cdspd_counts;

typedef struct {
    pthread_mutex_t mu;
    cdspd_counts c;        /* since start */
    cdspd_counts w0;       /* at the start of the window */
    uint64_t t0_us, w_t0_us;
    uint32_t proc[CDSPD_STATS_SAMPLES], e2e[CDSPD_STATS_SAMPLES];
    uint32_t sorted[CDSPD_STATS_SAMPLES];
    uint64_t n;            /* samples in the window (may exceed the array) */
    int source_down;       /* the source is being reopened */
    int n_dest;
    char dest_name[CDSPD_MAX_DEST][CDSPD_STR]; /* the dest key's texts */
} cdspd_stats;

typedef struct {
    double seconds;
    cdspd_counts d;        /* counts in the window */
    cdspd_counts total;
    double proc_p50_us, proc_p99_us, e2e_p50_us, e2e_p99_us, e2e_max_us;
    uint64_t samples;
    int n_dest;
    char dest_name[CDSPD_MAX_DEST][CDSPD_STR];
} cdspd_stats_window;

void cdspd_stats_init(cdspd_stats *s);
void cdspd_stats_destroy(cdspd_stats *s);

/* Add to a counter: field is offsetof(cdspd_counts, x) / sizeof(uint64_t). */
#define CDSPD_STAT(name) (offsetof(cdspd_counts, name) / sizeof(uint64_t))
void cdspd_stats_add(cdspd_stats *s, size_t field, uint64_t n);
/* The counter a processed frame's libcdsp status goes to: ok; arg_errors
 * for CDSP_E_ARG, CDSP_E_NONFINITE, CDSP_E_FORMAT (what the daemon passed
 * is wrong: a configuration problem, not an empty view); not_found for the
 * rest (no pipe, few points, degenerate, ...). */
size_t cdspd_stats_status_field(int status);
void cdspd_stats_latency(cdspd_stats *s, uint32_t proc_us, uint32_t e2e_us);
void cdspd_stats_get(cdspd_stats *s, cdspd_counts *c);
void cdspd_stats_set_down(cdspd_stats *s, int down);
/* The destinations of the running configuration: a list that differs from
 * the previous one (a reload) restarts the per-destination counts. */
void cdspd_stats_set_dests(cdspd_stats *s, const cdspd_config *c);
/* One datagram's fate: failed_mask bit i set when destination i failed. */
void cdspd_stats_sent(cdspd_stats *s, int n_dest, uint32_t failed_mask);
int cdspd_stats_down(cdspd_stats *s);

/* Close the window: its figures, then start a new one. */
void cdspd_stats_window_take(cdspd_stats *s, cdspd_stats_window *w);
/* One log line (category stats, info) for a window; why prefixes it
 * ("", "SIGUSR1: ", "final: "). */
void cdspd_stats_log(const cdspd_stats_window *w, const char *why);

#endif
