/*
 * notify.h - systemd's service notification (sd_notify, Type=notify):
 * READY=1 once the pipeline runs, RELOADING=1 / READY=1 around SIGHUP,
 * STOPPING=1, STATUS= lines, and WATCHDOG=1 while the processing thread
 * makes progress. No-ops when built without libsystemd or when not run by
 * systemd (NOTIFY_SOCKET unset).
 */
#ifndef CDSPD_NOTIFY_H
#define CDSPD_NOTIFY_H

#include <stdint.h>

void cdspd_notify(const char *state);
/* Watchdog period asked by systemd (WatchdogSec), us; 0 = none. */
uint64_t cdspd_notify_watchdog_us(void);

#endif
