/*
 * clockshim.so - LD_PRELOAD shim of tests/daemon/faults.sh: steps the wall
 * clock of one process without touching the machine's (setting the real
 * clock would disturb every other process here, and a time namespace
 * offsets only CLOCK_MONOTONIC and CLOCK_BOOTTIME, never CLOCK_REALTIME).
 *
 * CLOCKSHIM_STEPS="T1:D1,T2:D2,...": T seconds after the process started
 * (counted on the real CLOCK_MONOTONIC), CLOCK_REALTIME (and its coarse
 * variant, gettimeofday, time) jumps by D seconds, negative = back; the
 * steps add up. CLOCK_MONOTONIC is left alone: no clock the kernel keeps
 * for a process can step it, and the daemon's timestamps rely on it.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/time.h>
#include <time.h>

#define MAX_STEPS 16

static int (*real_clock_gettime)(clockid_t, struct timespec *);
static int n_steps;
static double step_at[MAX_STEPS], step_by[MAX_STEPS], t_start;

static void shim_init(void);

static double mono_now(void)
{
    struct timespec ts;
    real_clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Run by the first call, whichever comes first: the constructor or a call
 * from another library's constructor (GLib and lttng-ust read the clock
 * before this library's constructor may have run). */
__attribute__((constructor)) static void shim_init(void)
{
    const char *s = getenv("CLOCKSHIM_STEPS");
    if (real_clock_gettime)
        return;
    /* POSIX's sanctioned way from dlsym's void * to a function pointer */
    *(void **)&real_clock_gettime = dlsym(RTLD_NEXT, "clock_gettime");
    t_start = mono_now();
    while (s && *s && n_steps < MAX_STEPS) {
        char *end;
        step_at[n_steps] = strtod(s, &end);
        if (*end != ':')
            break;
        step_by[n_steps] = strtod(end + 1, &end);
        n_steps++;
        s = *end == ',' ? end + 1 : end;
    }
}

/* The sum of the steps whose time has come, seconds. */
static double offset_now(void)
{
    double t = mono_now() - t_start, off = 0;
    int i;
    for (i = 0; i < n_steps; i++)
        if (t >= step_at[i])
            off += step_by[i];
    return off;
}

int clock_gettime(clockid_t id, struct timespec *ts)
{
    int r;
    if (!real_clock_gettime)
        shim_init();
    r = real_clock_gettime(id, ts);
    if (r == 0 && (id == CLOCK_REALTIME || id == CLOCK_REALTIME_COARSE)) {
        long long ns = (long long)ts->tv_sec * 1000000000LL + ts->tv_nsec +
                       (long long)(offset_now() * 1e9);
        ts->tv_sec = (time_t)(ns / 1000000000LL);
        ts->tv_nsec = (long)(ns % 1000000000LL);
    }
    return r;
}

int gettimeofday(struct timeval *tv, void *tz)
{
    struct timespec ts;
    (void)tz;
    clock_gettime(CLOCK_REALTIME, &ts);
    tv->tv_sec = ts.tv_sec;
    tv->tv_usec = ts.tv_nsec / 1000;
    return 0;
}

time_t time(time_t *t)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    if (t)
        *t = ts.tv_sec;
    return ts.tv_sec;
}
