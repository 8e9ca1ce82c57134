/*
 * listen.c - `cdsp_tool listen`: see listen.h. Binds a UDP socket (joining
 * the group for a multicast address), decodes every datagram with
 * host/proto.c and prints it: a readable line, or with --json the
 * record as a JSON line (binary datagrams converted). At the end it says
 * on stderr how many came, how many could not be decoded and how many
 * sequence numbers were missing.
 */
#define _GNU_SOURCE
#include "listen.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cdsp_host.h"
#include <unistd.h>

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "addr.h"
#include "cdsp_host.h"
#include "proto.h"
#include "tool_internal.h"

#define STR_(x) #x
#define STR(x) STR_(x)

static const char listen_description[] =
    "    Receives cdspd's datagrams, binary (they start with the magic CDSP)\n"
    "    or JSON (they start with '{'), see docs/protocol.md, and prints one\n"
    "    line per datagram:\n"
    "\n"
    "      #SEQ  frame N  ok  P_C (x y z) +-(sx sy sz)  v_L (x y z)  d D\n"
    "            +-S bound B  conf C  inliers n1/n2  solve T ms  latency T ms\n"
    "            [tracked]  dropped K\n"
    "\n"
    "    P_C is the foot of the perpendicular from the camera onto the pipe's\n"
    "    axis and v_L the axis direction, in the camera frame (X right, Y down,\n"
    "    Z forward), in the unit of the radius cdspd was given; +- are the\n"
    "    standard deviations; S the distance's standard deviation and B the\n"
    "    bound on its systematic error (a bound, not a sigma: the error is\n"
    "    within about S + B; 0 from a cdspd older than protocol version 4);\n"
    "    \"tracked\" marks a frame solved in the bands\n"
    "    around the previous pose. A frame without a pipe prints its status\n"
    "    token (no-pipe, few-points, bad-frame, ...) instead of a pose, and a\n"
    "    status datagram (no-frame: the source is open but silent;\n"
    "    source-down: cdspd is reopening the camera) prints \"--\" with cdspd's\n"
    "    counters. At the end a summary line counts the datagrams, the\n"
    "    undecodable ones and the gaps in the sequence numbers.\n"
    "\n"
    "    With cdspd's solver.multi_pipe on, the line goes on with every pipe:\n"
    "\n"
    "      | N pipes:  #1 id I d D conf C  #2 id I d D conf C (S from #1) ...\n"
    "\n"
    "    rank, track id (kept while the pipe is in view), distance,\n"
    "    confidence, and each pipe's axis distance from the first (the\n"
    "    paper's spacing measure); --json prints them as \"pipes\" and\n"
    "    \"pairs\" (docs/protocol.md).\n"
    "\n"
    "    ADDR:PORT is where to listen: default 0.0.0.0:" STR(CDSP_HOST_DEFAULT_PORT) " (cdspd's\n"
    "    default --dest port). A multicast ADDR joins that group; [V6ADDR]:PORT\n"
    "    for IPv6; :PORT for any address.\n";

static const char listen_after[] =
    "EXAMPLES\n"
    "    cdsp_tool listen                      # beside cdspd --dest 127.0.0.1:" STR(CDSP_HOST_DEFAULT_PORT) "\n"
    "    cdsp_tool listen 239.1.2.3:" STR(CDSP_HOST_DEFAULT_PORT) " --json  # a multicast stream, as JSON Lines\n";

static const char listen_exit[] =
    "    0  done (count or duration reached, or SIGINT/SIGTERM)\n"
    "    1  some datagram could not be decoded\n"
    "    2  usage error, or the address cannot be bound (a unicast port takes one\n"
    "       listener: a second listen on it fails; a multicast group is shared)\n";

static int open_socket(const struct sockaddr_storage *ss, socklen_t len, const char *text)
{
    int fd = socket(ss->ss_family, SOCK_DGRAM | SOCK_CLOEXEC, 0), one = 1, rcv = 4 << 20;
    struct sockaddr_storage bind_addr = *ss;
    int multicast = 0;

    if (fd < 0) {
        fprintf(stderr, "cdsp_tool listen: socket: %s\n", strerror(errno));
        return -1;
    }
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
    if (ss->ss_family == AF_INET) {
        struct sockaddr_in *s4 = (struct sockaddr_in *)&bind_addr;
        multicast = (ntohl(s4->sin_addr.s_addr) >> 28) == 14;
    } else {
        struct sockaddr_in6 *s6 = (struct sockaddr_in6 *)&bind_addr;
        multicast = s6->sin6_addr.s6_addr[0] == 0xFF;
    }
    /* Only a multicast group is shared (every member gets every datagram).
     * Two unicast listeners on one port would split the stream unseen
     * (SO_REUSEADDR hands each datagram to one of them): the second fails. */
    if (multicast)
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (bind(fd, (struct sockaddr *)&bind_addr, len)) {
        int e = errno;
        fprintf(stderr, "cdsp_tool listen: cannot listen on %s: %s%s\n", text, strerror(e),
                e == EADDRINUSE ? " (another program, perhaps another cdsp_tool listen, has this "
                                  "port; a unicast port has one listener, use a multicast "
                                  "address to share a stream)"
                                : "");
        close(fd);
        return -1;
    }
    if (multicast && ss->ss_family == AF_INET) {
        struct ip_mreq m;
        m.imr_multiaddr = ((const struct sockaddr_in *)ss)->sin_addr;
        m.imr_interface.s_addr = htonl(INADDR_ANY);
        if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m)) {
            fprintf(stderr, "cdsp_tool listen: cannot join %s: %s\n", text, strerror(errno));
            close(fd);
            return -1;
        }
    } else if (multicast) {
        struct ipv6_mreq m;
        m.ipv6mr_multiaddr = ((const struct sockaddr_in6 *)ss)->sin6_addr;
        m.ipv6mr_interface = 0;
        if (setsockopt(fd, IPPROTO_IPV6, IPV6_JOIN_GROUP, &m, sizeof m)) {
            fprintf(stderr, "cdsp_tool listen: cannot join %s: %s\n", text, strerror(errno));
            close(fd);
            return -1;
        }
    }
    return fd;
}

static void format_human(const cdspd_record *r, char *out, size_t cap)
{
    char head[96];
    snprintf(head, sizeof head, "#%-7lu %s %-8llu", (unsigned long)r->seq,
             r->kind == CDSPD_KIND_FRAME ? "frame" : "     ",
             r->kind == CDSPD_KIND_FRAME ? (unsigned long long)r->frame_id : 0ull);
    if (r->kind == CDSPD_KIND_STATUS) {
        snprintf(out, cap, "#%-7lu --             %-11s (frames in %lu, dropped %lu, bad %lu, reconnects %lu)",
                 (unsigned long)r->seq, cdspd_status_token(r->status), (unsigned long)r->frames_in,
                 (unsigned long)r->frames_dropped, (unsigned long)r->frames_bad,
                 (unsigned long)r->reconnects);
        return;
    }
    if (r->status != 0) {
        snprintf(out, cap, "%s %-11s solve %.2f ms  latency %.2f ms", head,
                 cdspd_status_token(r->status), r->proc_us * 1e-3, r->latency_us * 1e-3);
        return;
    }
    snprintf(out, cap,
             "%s ok  P_C (%8.2f %8.2f %8.2f) +-(%.2f %.2f %.2f)  v_L (%6.3f %6.3f %6.3f)  d %7.2f  "
             "+-%.3f bound %.3f  conf %.2f  inliers %u/%u  solve %.2f ms  latency %.2f ms%s  dropped %lu",
             head, r->point[0], r->point[1], r->point[2], r->sigma_point[0], r->sigma_point[1],
             r->sigma_point[2], r->direction[0], r->direction[1], r->direction[2], r->distance,
             r->sigma_distance, r->bound_distance, r->confidence, r->inliers[0], r->inliers[1], r->proc_us * 1e-3, r->latency_us * 1e-3,
             (r->flags & CDSPD_FLAG_TRACKED) ? "  tracked" : "", (unsigned long)r->frames_dropped);
    if (r->flags & CDSPD_FLAG_MULTI) {
        /* every pipe, on the same line (a record is one line): rank,
         * track id, distance, confidence, and the spacing of each to the
         * first (the paper's axis distance) */
        size_t len = strlen(out);
        uint32_t k;
        cdsp_result first, other;
        len += (size_t)snprintf(out + len, len < cap ? cap - len : 0, "  | %u pipe%s:", r->n_pipes,
                                r->n_pipes == 1 ? "" : "s");
        if (r->n_pipes)
            cdspd_pipe_to_result(&r->pipe[0], &first);
        for (k = 0; k < r->n_pipes && len < cap; k++) {
            double ang = 0, dist = 0, rms = 0;
            const cdspd_pipe *q = &r->pipe[k];
            len += (size_t)snprintf(out + len, cap - len, "  #%u id %u d %.2f conf %.2f", k + 1, q->track_id,
                                    q->distance, q->confidence);
            cdspd_pipe_to_result(q, &other);
            if (k > 0 && len < cap && cdsp_host_pipe_pair(&first, &other, &ang, &dist, &rms) == 0)
                len += (size_t)snprintf(out + len, cap - len, " (%.3f from #1)", dist);
        }
    }
}

int cdsp_tool_listen_format(const uint8_t *buf, size_t len, int json, char *out, size_t cap,
                            uint32_t *seq, const char **why)
{
    cdspd_record rec, *r = &rec;
    if (cap)
        out[0] = 0;
    if (cdspd_proto_decode_any(buf, len, r, NULL, why))
        return -1;
    *seq = r->seq;
    /* what was decoded, re-encoded: never the datagram's own bytes, so
     * nothing a sender appends or embeds reaches the consumer's stream */
    if (json) {
        if (!cdspd_proto_encode_json(r, out, cap)) {
            *why = "record too long to re-encode";
            return -1;
        }
    } else {
        format_human(r, out, cap);
    }
    return 0;
}

int cdsp_tool_listen(int argc, char **argv)
{
    static const tool_doc doc = {
        "listen", "decode and print the poses cdspd streams over UDP", "[OPTIONS] [ADDR:PORT]",
        listen_description, listen_after, listen_exit};
    const char *addr_text = "0.0.0.0";
    struct sockaddr_storage ss;
    socklen_t sslen;
    int json = 0, quiet = 0, fd, rc, npos = 0, count = 0;
    double duration = 0, t_end = 0;
    unsigned long received = 0, bad = 0, missing = 0;
    uint32_t last_seq = 0;
    int have_seq = 0;
    static uint8_t buf[65536];
    static char out[65536]; /* a record with every pipe and pair */
    char **pos = NULL;
    const tool_opt opts[] = {
        {"json", 0, OPT_FLAG, &json, 0, 0, NULL,
         "Print each record as one JSON line, with the field names of `cdsp_tool solve` plus "
         "seq, t_camera_us and t_host_us, for scripts. The line is the decoded record encoded "
         "again (binary and JSON datagrams alike), never the datagram's own bytes: a JSON "
         "datagram with anything but white space after its object is undecodable.", NULL, 0},
        {"count", 0, OPT_INT, &count, 1, 2147483647.0, "N", "Stop after N datagrams.", NULL, 1},
        {"duration", 0, OPT_REAL, &duration, 1e-6, 1e12, "SECONDS",
         "Stop after this long. Without --count or --duration, listen runs until SIGINT or "
         "SIGTERM (Ctrl-C).", NULL, 1},
        {"quiet", 0, OPT_FLAG, &quiet, 0, 0, NULL, "Print only the summary.", NULL, 0},
        {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
    };

    rc = tool_parse_alloc("listen", &doc, opts, argc, argv, &pos, &npos);
    if (rc)
        return rc - 1;
    if (npos > 1) {
        rc = tool_usage_error("listen", "unexpected argument '%s' (see --help)", pos[1]);
        free(pos);
        return rc;
    }
    if (npos == 1)
        addr_text = pos[0];
    free(pos);
    {
        cdsp_host_err herr;
        if (cdsp_host_addr_parse(addr_text, 1, &ss, &sslen, &herr)) {
            fprintf(stderr, "cdsp_tool listen: %s (expected ADDR:PORT, :PORT or [V6ADDR]:PORT)\n",
                    herr.msg);
            return 2;
        }
    }
    fd = open_socket(&ss, sslen, addr_text);
    if (fd < 0)
        return 2;
    cdsp_host_stop_on_signals();
    if (duration > 0)
        t_end = cdsp_host_now_s() + duration;
    if (!quiet && !json) {
        struct sockaddr_storage got;
        socklen_t gl = sizeof got;
        unsigned port = 0;
        if (!getsockname(fd, (struct sockaddr *)&got, &gl))
            port = ntohs(got.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&got)->sin6_port
                                                   : ((struct sockaddr_in *)&got)->sin_port);
        fprintf(stderr, "cdsp_tool listen: listening on %s (port %u)\n", addr_text, port);
    }
    while (!cdsp_host_stop_requested() && (count == 0 || (long)received < count)) {
        struct pollfd pfd = {fd, POLLIN, 0};
        int wait_ms = 200, pr;
        ssize_t n;
        uint32_t seq;
        const char *why;
        if (t_end > 0) {
            double left = t_end - cdsp_host_now_s();
            if (left <= 0)
                break;
            if (left * 1000 < wait_ms)
                wait_ms = (int)(left * 1000) + 1;
        }
        pr = poll(&pfd, 1, wait_ms);
        if (pr <= 0)
            continue;
        n = recv(fd, buf, sizeof buf, 0);
        if (n < 0)
            continue;
        received++;
        if (cdsp_tool_listen_format(buf, (size_t)n, json, out, sizeof out, &seq, &why)) {
            bad++;
            fprintf(stderr, "cdsp_tool listen: datagram of %zd bytes: %s\n", n, why);
            continue;
        }
        if (have_seq && seq != last_seq + 1u && seq > last_seq)
            missing += seq - last_seq - 1u;
        last_seq = seq;
        have_seq = 1;
        if (quiet)
            continue;
        printf("%s\n", out);
        fflush(stdout);
    }
    close(fd);
    fprintf(stderr, "cdsp_tool listen: %lu datagrams, %lu undecodable, %lu sequence numbers missing\n",
            received, bad, missing);
    return bad ? 1 : 0;
}
