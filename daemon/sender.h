/*
 * sender.h - the UDP sender: one datagram to every destination of the
 * dest key (unicast, broadcast or multicast, IPv4 or IPv6). Sending never
 * blocks (MSG_DONTWAIT) and never stops the daemon: a failure (no route,
 * full socket buffer...) is counted and logged, at most once per 10 s per
 * destination and reason.
 */
#ifndef CDSPD_SENDER_H
#define CDSPD_SENDER_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"

typedef struct {
    int fd4, fd6;
    int n;
    cdspd_dest dest[CDSPD_MAX_DEST];
    int last_errno[CDSPD_MAX_DEST];
    uint64_t last_log_us[CDSPD_MAX_DEST];
    uint64_t failures[CDSPD_MAX_DEST];
} cdspd_sender;

/* Sockets for c's destinations; 0, or -1 with err. */
int cdspd_sender_open(cdspd_sender *s, const cdspd_config *c, char *err, size_t errlen);
void cdspd_sender_close(cdspd_sender *s);

/* Send to all; returns the number of destinations that failed and sets
 * bit i of *failed_mask (may be NULL) when destination i did. */
int cdspd_sender_send(cdspd_sender *s, const void *buf, size_t len, uint32_t *failed_mask);

#endif
