/*
 * stats.c - see stats.h. Percentiles by sorting the window's samples
 * (at most CDSPD_STATS_SAMPLES) when the window closes, on the main thread,
 * into a preallocated array: nearest-rank definition.
 */
#define _POSIX_C_SOURCE 200809L
#include "stats.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp.h"
#include "log.h"
#include "source.h"

void cdspd_stats_init(cdspd_stats *s)
{
    memset(s, 0, sizeof *s);
    pthread_mutex_init(&s->mu, NULL);
    s->t0_us = s->w_t0_us = cdspd_now_us();
}

void cdspd_stats_destroy(cdspd_stats *s)
{
    pthread_mutex_destroy(&s->mu);
}

void cdspd_stats_add(cdspd_stats *s, size_t field, uint64_t n)
{
    pthread_mutex_lock(&s->mu);
    ((uint64_t *)&s->c)[field] += n;
    pthread_mutex_unlock(&s->mu);
}

void cdspd_stats_latency(cdspd_stats *s, uint32_t proc_us, uint32_t e2e_us)
{
    pthread_mutex_lock(&s->mu);
    s->proc[s->n % CDSPD_STATS_SAMPLES] = proc_us;
    s->e2e[s->n % CDSPD_STATS_SAMPLES] = e2e_us;
    s->n++;
    pthread_mutex_unlock(&s->mu);
}

void cdspd_stats_get(cdspd_stats *s, cdspd_counts *c)
{
    pthread_mutex_lock(&s->mu);
    *c = s->c;
    pthread_mutex_unlock(&s->mu);
}

void cdspd_stats_set_down(cdspd_stats *s, int down)
{
    pthread_mutex_lock(&s->mu);
    s->source_down = down;
    pthread_mutex_unlock(&s->mu);
}

void cdspd_stats_set_dests(cdspd_stats *s, const cdspd_config *c)
{
    int i, same;
    pthread_mutex_lock(&s->mu);
    same = s->n_dest == c->n_dest;
    for (i = 0; same && i < c->n_dest; i++)
        same = !strcmp(s->dest_name[i], c->dest[i].text);
    if (!same) {
        memset(s->c.dest_sent, 0, sizeof s->c.dest_sent);
        memset(s->c.dest_errors, 0, sizeof s->c.dest_errors);
        memset(s->w0.dest_sent, 0, sizeof s->w0.dest_sent);
        memset(s->w0.dest_errors, 0, sizeof s->w0.dest_errors);
        s->n_dest = c->n_dest;
        for (i = 0; i < c->n_dest; i++)
            snprintf(s->dest_name[i], sizeof s->dest_name[i], "%s", c->dest[i].text);
    }
    pthread_mutex_unlock(&s->mu);
}

void cdspd_stats_sent(cdspd_stats *s, int n_dest, uint32_t failed_mask)
{
    int i, failed = 0;
    pthread_mutex_lock(&s->mu);
    for (i = 0; i < n_dest && i < CDSPD_MAX_DEST; i++) {
        if (failed_mask >> i & 1u) {
            s->c.dest_errors[i]++;
            failed++;
        } else {
            s->c.dest_sent[i]++;
        }
    }
    s->c.send_errors += (uint64_t)failed;
    if (failed < n_dest)
        s->c.sent++;
    pthread_mutex_unlock(&s->mu);
}

int cdspd_stats_down(cdspd_stats *s)
{
    int d;
    pthread_mutex_lock(&s->mu);
    d = s->source_down;
    pthread_mutex_unlock(&s->mu);
    return d;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* nearest rank: the smallest sample with at least q of them at or below it */
static double percentile(const uint32_t *sorted, size_t n, double q)
{
    size_t k;
    if (!n)
        return 0;
    k = (size_t)(q * (double)n + 0.999999);
    if (k < 1)
        k = 1;
    if (k > n)
        k = n;
    return sorted[k - 1];
}

void cdspd_stats_window_take(cdspd_stats *s, cdspd_stats_window *w)
{
    size_t n, i;
    uint64_t now = cdspd_now_us();
    memset(w, 0, sizeof *w);
    pthread_mutex_lock(&s->mu);
    w->seconds = (double)(now - s->w_t0_us) * 1e-6;
    w->total = s->c;
    for (i = 0; i < sizeof s->c / sizeof(uint64_t); i++)
        ((uint64_t *)&w->d)[i] = ((uint64_t *)&s->c)[i] - ((uint64_t *)&s->w0)[i];
    w->samples = s->n;
    n = s->n < CDSPD_STATS_SAMPLES ? (size_t)s->n : CDSPD_STATS_SAMPLES;
    memcpy(s->sorted, s->proc, n * sizeof *s->sorted);
    qsort(s->sorted, n, sizeof *s->sorted, cmp_u32);
    w->proc_p50_us = percentile(s->sorted, n, 0.5);
    w->proc_p99_us = percentile(s->sorted, n, 0.99);
    memcpy(s->sorted, s->e2e, n * sizeof *s->sorted);
    qsort(s->sorted, n, sizeof *s->sorted, cmp_u32);
    w->e2e_p50_us = percentile(s->sorted, n, 0.5);
    w->e2e_p99_us = percentile(s->sorted, n, 0.99);
    w->e2e_max_us = n ? s->sorted[n - 1] : 0;
    w->n_dest = s->n_dest;
    memcpy(w->dest_name, s->dest_name, sizeof w->dest_name);
    s->w0 = s->c;
    s->w_t0_us = now;
    s->n = 0;
    pthread_mutex_unlock(&s->mu);
}

size_t cdspd_stats_status_field(int status)
{
    switch (status) {
    case CDSP_OK: return CDSPD_STAT(ok);
    case CDSP_E_ARG:
    case CDSP_E_NONFINITE:
    case CDSP_E_FORMAT: return CDSPD_STAT(arg_errors);
    default: return CDSPD_STAT(not_found);
    }
}

void cdspd_stats_log(const cdspd_stats_window *w, const char *why)
{
    int i;
    double t = w->seconds > 0 ? w->seconds : 1e-9;
    LOG_I(STATS,
          "%s%.1f s: frames in %llu (%.1f/s), processed %llu (%.1f/s), pose %llu, no pipe %llu, "
          "argument errors %llu, "
          "dropped %llu, bad %llu, status %llu, sent %llu, send errors %llu, reconnects %llu, "
          "recorded %llu; solve p50 %.2f ms p99 %.2f ms; ready->sent p50 %.2f ms p99 %.2f ms "
          "(%llu samples); total: in %llu, processed %llu, dropped %llu, reconnects %llu",
          why, w->seconds, (unsigned long long)w->d.frames_in, (double)w->d.frames_in / t,
          (unsigned long long)w->d.processed, (double)w->d.processed / t,
          (unsigned long long)w->d.ok, (unsigned long long)w->d.not_found,
          (unsigned long long)w->d.arg_errors,
          (unsigned long long)w->d.frames_dropped, (unsigned long long)w->d.frames_bad,
          (unsigned long long)w->d.status_sent, (unsigned long long)w->d.sent,
          (unsigned long long)w->d.send_errors, (unsigned long long)w->d.reconnects,
          (unsigned long long)w->d.recorded, w->proc_p50_us * 1e-3, w->proc_p99_us * 1e-3,
          w->e2e_p50_us * 1e-3, w->e2e_p99_us * 1e-3, (unsigned long long)w->samples,
          (unsigned long long)w->total.frames_in, (unsigned long long)w->total.processed,
          (unsigned long long)w->total.frames_dropped, (unsigned long long)w->total.reconnects);
    /* One line per destination: a dead one is seen beside the live ones. */
    for (i = 0; i < w->n_dest; i++)
        LOG_I(STATS, "%sdestination %s: sent %llu, send errors %llu (total: sent %llu, send "
              "errors %llu)", why, w->dest_name[i], (unsigned long long)w->d.dest_sent[i],
              (unsigned long long)w->d.dest_errors[i], (unsigned long long)w->total.dest_sent[i],
              (unsigned long long)w->total.dest_errors[i]);
}
