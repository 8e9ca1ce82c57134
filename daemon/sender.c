/*
 * sender.c - see sender.h.
 */
#define _GNU_SOURCE
#include "sender.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <linux/filter.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "log.h"
#include "source.h"

static int open_socket(int family, const cdspd_config *c, char *err, size_t errlen)
{
    int fd = socket(family, SOCK_DGRAM | SOCK_CLOEXEC, 0), one = 1;
    unsigned char ttl = (unsigned char)c->ttl, loop = (unsigned char)(c->multicast_loop != 0);
    if (fd < 0) {
        snprintf(err, errlen, "cannot create a UDP%s socket: %s", family == AF_INET6 ? "/IPv6" : "",
                 strerror(errno));
        return -1;
    }
    {
        /* The socket only sends, but its first sendto binds it to an
         * ephemeral port on every address: a filter that accepts no packet
         * (classic BPF "return 0") makes the kernel drop whatever arrives
         * there before it is queued, so nothing from the network ever
         * reaches cdspd through it (docs/security.md). */
        static struct sock_filter drop_all[] = {BPF_STMT(BPF_RET | BPF_K, 0)};
        struct sock_fprog prog = {1, drop_all};
        if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &prog, sizeof prog))
            LOG_W(NET, "cannot attach the drop-all receive filter: %s", strerror(errno));
    }
    if (family == AF_INET) {
        /* broadcast destinations need it; harmless for the others */
        setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &one, sizeof one);
        setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
        setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop);
        if (*c->multicast_if) {
            struct in_addr a;
            inet_pton(AF_INET, c->multicast_if, &a);
            if (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &a, sizeof a)) {
                snprintf(err, errlen, "key 'net.multicast_interface': %s: %s", c->multicast_if,
                         strerror(errno));
                close(fd);
                return -1;
            }
        }
    } else {
        int hops = c->ttl, l = c->multicast_loop != 0;
        setsockopt(fd, IPPROTO_IPV6, IPV6_MULTICAST_HOPS, &hops, sizeof hops);
        setsockopt(fd, IPPROTO_IPV6, IPV6_MULTICAST_LOOP, &l, sizeof l);
    }
    return fd;
}

int cdspd_sender_open(cdspd_sender *s, const cdspd_config *c, char *err, size_t errlen)
{
    int i, need4 = 0, need6 = 0;
    memset(s, 0, sizeof *s);
    s->fd4 = s->fd6 = -1;
    s->n = c->n_dest;
    memcpy(s->dest, c->dest, sizeof s->dest);
    for (i = 0; i < s->n; i++) {
        if (s->dest[i].addr.ss_family == AF_INET6)
            need6 = 1;
        else
            need4 = 1;
    }
    if (need4 && (s->fd4 = open_socket(AF_INET, c, err, errlen)) < 0)
        return -1;
    if (need6 && (s->fd6 = open_socket(AF_INET6, c, err, errlen)) < 0) {
        cdspd_sender_close(s);
        return -1;
    }
    for (i = 0; i < s->n; i++)
        LOG_I(NET, "sending %s datagrams to %s%s", c->format == CDSPD_FORMAT_JSON ? "JSON" : "binary",
              s->dest[i].text,
              s->dest[i].multicast ? " (multicast)" : s->dest[i].broadcast ? " (broadcast?)" : "");
    return 0;
}

void cdspd_sender_close(cdspd_sender *s)
{
    if (s->fd4 >= 0)
        close(s->fd4);
    if (s->fd6 >= 0)
        close(s->fd6);
    s->fd4 = s->fd6 = -1;
}

int cdspd_sender_send(cdspd_sender *s, const void *buf, size_t len, uint32_t *failed_mask)
{
    int i, failed = 0;
    uint32_t mask = 0;
    for (i = 0; i < s->n; i++) {
        const cdspd_dest *d = &s->dest[i];
        int fd = d->addr.ss_family == AF_INET6 ? s->fd6 : s->fd4;
        ssize_t r;
        do
            r = sendto(fd, buf, len, MSG_DONTWAIT | MSG_NOSIGNAL, (const struct sockaddr *)&d->addr,
                       d->addr_len);
        while (r < 0 && errno == EINTR);
        if (r == (ssize_t)len) {
            if (s->failures[i] && s->last_errno[i]) {
                LOG_I(NET, "%s: sending works again (after %llu failures)", d->text,
                      (unsigned long long)s->failures[i]);
                s->last_errno[i] = 0;
                s->failures[i] = 0;
            }
            continue;
        }
        {
            int e = r < 0 ? errno : EMSGSIZE;
            uint64_t now = cdspd_now_us();
            failed++;
            mask |= 1u << i;
            s->failures[i]++;
            if (e != s->last_errno[i] || now - s->last_log_us[i] >= 10000000u) {
                LOG_W(NET, "%s: cannot send: %s (%llu failed so far; the daemon keeps running)",
                      d->text, strerror(e), (unsigned long long)s->failures[i]);
                s->last_errno[i] = e;
                s->last_log_us[i] = now;
            }
        }
    }
    if (failed_mask)
        *failed_mask = mask;
    return failed;
}
