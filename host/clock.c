/*
 * clock.c - the monotonic clock in seconds, as the programs and the test
 * peers time their runs (cdsp_host.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "cdsp_host.h"

#include <time.h>

double cdsp_host_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
