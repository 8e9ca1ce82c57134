/*
 * mavout.h - cdspd's MAVLink output (docs/mavlink.md): the links of the
 * mavlink key (udpout://HOST:PORT, serial:///dev/ttyX:BAUD,
 * serial_flowcontrol:///dev/ttyX:BAUD) and a thread that writes to them
 *   - HEARTBEAT every second from the start (BOOT until the source first
 *     opens, then ACTIVE while it is up and CRITICAL while it is lost);
 *   - for each frame with a pipe (at most mavlink_rate per second),
 *     LANDING_TARGET and DEBUG_VECT "PIPE_DIR" from the body-frame pose.
 * The processing thread only hands over the latest pose (never blocks, never
 * allocates); the thread encodes and writes. A write error on a serial link
 * closes it and reopens it with back-off (retry_min doubling to retry_max)
 * while the daemon runs; a UDP link only counts and logs (rate-limited).
 */
#ifndef CDSPD_MAVOUT_H
#define CDSPD_MAVOUT_H

#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>

#include "config.h"
#include "mount.h"
#include "proto.h"
#include "stats.h"

typedef enum { CDSPD_MAVLINK_UDPOUT = 0, CDSPD_MAVLINK_SERIAL = 1 } cdspd_mavlink_kind;

typedef struct {
    cdspd_mavlink_kind kind;
    /* udpout */
    struct sockaddr_storage addr;
    socklen_t addr_len;
    /* serial */
    char path[CDSPD_STR];
    long baud;
    int flow_control;  /* RTS/CTS (serial_flowcontrol://) */
} cdspd_mavlink_url;

/* Parse one URL of the mavlink key (resolve: also look the udpout host
 * up): 0, or -1 with err naming the problem. */
int cdspd_mavlink_url_parse(const char *text, cdspd_mavlink_url *u, int resolve, char *err,
                            size_t errlen);

typedef struct cdspd_mavout cdspd_mavout;

/* Start the thread when c has links (*out NULL when it has none): 0, or -1
 * with err. stats: read for the heartbeat's state. */
int cdspd_mavout_start(cdspd_mavout **out, const cdspd_config *c, cdspd_stats *stats, char *err,
                       size_t errlen);

/* A processed frame (status 0: with a pipe; its body-frame pose in b). */
void cdspd_mavout_frame(cdspd_mavout *m, const cdspd_record *r, const cdspd_body_pose *b);

void cdspd_mavout_stop(cdspd_mavout *m);

#endif
