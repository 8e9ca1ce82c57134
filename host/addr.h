/*
 * addr.h - the UDP addresses of cdspd and its listeners, parsed in one
 * place: cdspd's dest key and --dest, the host of a MAVLink udpout:// URL,
 * `cdsp_tool listen ADDR:PORT` and the test receivers' --bind. Part of
 * libcdsp_host (host/addr.c); POSIX sockets.
 */
#ifndef CDSP_HOST_ADDR_H
#define CDSP_HOST_ADDR_H

#include <sys/socket.h>

#include "cdsp_host.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The port cdspd sends to and cdsp_tool listen listens on when none is
 * given (docs/protocol.md). */
#define CDSP_HOST_DEFAULT_PORT 23770

/*
 * Split "HOST:PORT", "[IPV6]:PORT", "HOST" (port CDSP_HOST_DEFAULT_PORT) or,
 * passive only, ":PORT" (any IPv4 address), and resolve HOST (numeric or by
 * name, getaddrinfo: the first address it returns). passive: an address to
 * bind (port 0..65535, the host may be empty) rather than one to send to
 * (port 1..65535, a host needed). The port is decimal. Returns CDSP_HOST_OK,
 * or CDSP_HOST_E_FORMAT with err naming the text and the problem, e.g.
 * "'fe80::1:9': write IPv6 addresses as [ADDR]:PORT".
 */
int cdsp_host_addr_parse(const char *text, int passive, struct sockaddr_storage *ss,
                         socklen_t *len, cdsp_host_err *err);

#ifdef __cplusplus
}
#endif

#endif
