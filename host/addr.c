/*
 * addr.c - see addr.h: "HOST:PORT" split and resolved, for senders and
 * listeners alike.
 */
#define _POSIX_C_SOURCE 200809L
#include "addr.h"

#include <errno.h>
#include <netdb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "'TEXT': WHAT" */
static int fail(cdsp_host_err *err, const char *text, const char *what)
{
    if (err)
        snprintf(err->msg, sizeof err->msg, "'%s': %s", text, what);
    return CDSP_HOST_E_FORMAT;
}

int cdsp_host_addr_parse(const char *text, int passive, struct sockaddr_storage *ss,
                         socklen_t *len, cdsp_host_err *err)
{
    char host[256], port[16];
    const char *colon;
    struct addrinfo hints, *res = NULL;
    long p = CDSP_HOST_DEFAULT_PORT;
    int r;

    if (text[0] == '[') {
        const char *close = strchr(text, ']');
        if (!close || (close[1] && close[1] != ':') || close - text - 1 <= 0 ||
            (size_t)(close - text - 1) >= sizeof host)
            return fail(err, text, "expected [IPV6]:PORT");
        memcpy(host, text + 1, (size_t)(close - text - 1));
        host[close - text - 1] = 0;
        colon = close[1] ? close + 1 : NULL;
    } else {
        colon = strrchr(text, ':');
        if (colon && strchr(text, ':') != colon)
            return fail(err, text, "write IPv6 addresses as [ADDR]:PORT");
        if (strlen(text) >= sizeof host)
            return fail(err, text, "too long");
        strcpy(host, text);
        if (colon)
            host[colon - text] = 0;
    }
    if (colon) {
        char *end;
        errno = 0;
        p = strtol(colon + 1, &end, 10);
        if (end == colon + 1 || *end || errno || p < (passive ? 0 : 1) || p > 65535) {
            if (err)
                snprintf(err->msg, sizeof err->msg, "'%s': port '%s': expected %d..65535", text,
                         colon + 1, passive ? 0 : 1);
            return CDSP_HOST_E_FORMAT;
        }
    }
    if (!*host && !passive)
        return fail(err, text, "no host");
    snprintf(port, sizeof port, "%ld", p);
    memset(&hints, 0, sizeof hints);
    /* ":PORT" binds IPv4's any address (0.0.0.0), whatever order
     * getaddrinfo's configuration would give the families */
    hints.ai_family = *host ? AF_UNSPEC : AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    hints.ai_flags = passive ? AI_PASSIVE : 0;
    r = getaddrinfo(*host ? host : NULL, port, &hints, &res);
    if (r || !res) {
        if (err)
            snprintf(err->msg, sizeof err->msg, "'%s': cannot resolve '%s': %s", text, host,
                     r ? gai_strerror(r) : "no address");
        if (res)
            freeaddrinfo(res);
        return CDSP_HOST_E_FORMAT;
    }
    memcpy(ss, res->ai_addr, res->ai_addrlen);
    *len = res->ai_addrlen;
    freeaddrinfo(res);
    return CDSP_HOST_OK;
}
