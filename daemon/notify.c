/*
 * notify.c - see notify.h.
 */
#define _POSIX_C_SOURCE 200809L
#include "notify.h"

#include <stdlib.h>

#ifdef CDSPD_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

void cdspd_notify(const char *state)
{
#ifdef CDSPD_HAVE_SYSTEMD
    sd_notify(0, state);
#else
    (void)state;
#endif
}

uint64_t cdspd_notify_watchdog_us(void)
{
#ifdef CDSPD_HAVE_SYSTEMD
    uint64_t us = 0;
    if (sd_watchdog_enabled(0, &us) > 0)
        return us;
#endif
    return 0;
}
