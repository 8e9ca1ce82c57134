/*
 * stop.c - SIGINT and SIGTERM as a request to stop (cdsp_host.h): the
 * handler only sets a volatile sig_atomic_t, the one thing a handler may
 * safely write (C99 7.14.1.1); the program's loop polls it. No SA_RESTART:
 * a poll() or recv() the signal interrupts returns EINTR, so the loop sees
 * the request at once rather than at its next time-out.
 */
#define _POSIX_C_SOURCE 200809L
#include "cdsp_host.h"

#include <signal.h>
#include <string.h>

/* a process has one set of signal dispositions: one flag for it */
static volatile sig_atomic_t stop_flag;

static void on_stop(int sig)
{
    (void)sig;
    stop_flag = 1;
}

void cdsp_host_stop_on_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    stop_flag = 0;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

int cdsp_host_stop_requested(void)
{
    return stop_flag != 0;
}
