/*
 * mavout.c - see mavout.h; the message fields are defined in
 * docs/mavlink.md ("What cdspd sends").
 */
#define _GNU_SOURCE
#include "mavout.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "addr.h"
#include "log.h"
#include "mavlink.h"
#include "source.h"

/* How long a serial write may wait for room in the driver's buffer before
 * the rest of the frame is dropped, ms: a few frames' time at 57600 baud. */
#define SERIAL_WRITE_WAIT_MS 100

/* ------------------------------------------------------------------------
 * URLs.
 * ---------------------------------------------------------------------- */
static const struct {
    long baud;
    speed_t code;
} bauds[] = {{9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
             {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
             {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1500000, B1500000},
             {2000000, B2000000}, {3000000, B3000000}, {4000000, B4000000}};
#define N_BAUDS (sizeof bauds / sizeof bauds[0])

static int baud_code(long baud, speed_t *code)
{
    size_t i;
    for (i = 0; i < N_BAUDS; i++)
        if (bauds[i].baud == baud) {
            *code = bauds[i].code;
            return 0;
        }
    return -1;
}

int cdspd_mavlink_url_parse(const char *text, cdspd_mavlink_url *u, int resolve, char *err,
                            size_t errlen)
{
    static const char udp[] = "udpout://", ser[] = "serial://", serfc[] = "serial_flowcontrol://";
    memset(u, 0, sizeof *u);
    if (!strncmp(text, udp, sizeof udp - 1)) {
        const char *hp = text + sizeof udp - 1, *colon = strrchr(hp, ':');
        cdsp_host_err e;
        char *end;
        long port;
        u->kind = CDSPD_MAVLINK_UDPOUT;
        errno = 0;
        port = colon ? strtol(colon + 1, &end, 10) : 0;
        if (!colon || colon == hp || !colon[1] || *end || errno || port < 1 || port > 65535) {
            snprintf(err, errlen, "'%s': expected udpout://HOST:PORT (PORT 1..65535)", text);
            return -1;
        }
        if (resolve && cdsp_host_addr_parse(hp, 0, &u->addr, &u->addr_len, &e)) {
            snprintf(err, errlen, "'%s': %s", text, e.msg);
            return -1;
        }
        return 0;
    }
    if (!strncmp(text, ser, sizeof ser - 1) || !strncmp(text, serfc, sizeof serfc - 1)) {
        int fc = !strncmp(text, serfc, sizeof serfc - 1);
        const char *path = text + (fc ? sizeof serfc - 1 : sizeof ser - 1);
        const char *colon = strrchr(path, ':');
        char *end;
        speed_t code;
        u->kind = CDSPD_MAVLINK_SERIAL;
        u->flow_control = fc;
        if (path[0] != '/' || !colon || colon == path + 1 || !colon[1]) {
            snprintf(err, errlen, "'%s': expected %s/dev/DEVICE:BAUD", text, fc ? serfc : ser);
            return -1;
        }
        errno = 0;
        u->baud = strtol(colon + 1, &end, 10);
        if (*end || errno || baud_code(u->baud, &code)) {
            snprintf(err, errlen, "'%s': baud rate '%s': expected one of 9600, 19200, 38400, 57600, "
                     "115200, 230400, 460800, 500000, 576000, 921600, 1000000, 1500000, 2000000, "
                     "3000000, 4000000", text, colon + 1);
            return -1;
        }
        if ((size_t)(colon - path) >= sizeof u->path) {
            snprintf(err, errlen, "'%s': device path too long", text);
            return -1;
        }
        memcpy(u->path, path, (size_t)(colon - path));
        u->path[colon - path] = 0;
        return 0;
    }
    snprintf(err, errlen, "'%s': expected udpout://HOST:PORT, serial:///dev/DEVICE:BAUD or "
             "serial_flowcontrol:///dev/DEVICE:BAUD", text);
    return -1;
}

/* ------------------------------------------------------------------------
 * Links.
 * ---------------------------------------------------------------------- */
typedef struct {
    cdspd_mavlink_url u;
    const char *text;
    int fd;                  /* -1: closed */
    uint8_t seq;             /* MAVLink sequence of this link */
    double backoff;          /* s, next reopening delay */
    uint64_t retry_at_us;    /* closed: when to try again */
    int opened_before, open_fails;
    uint64_t failures, last_log_us;
    int last_errno;
} mav_link;

typedef struct {
    uint64_t time_usec;
    double radius;
    double segment[2][3];
    cdspd_body_pose b;
} target;

struct cdspd_mavout {
    mav_link links[CDSPD_MAX_MAVLINK];
    int n;
    uint8_t sysid, compid;
    double min_interval_us;  /* 1e6 / mavlink_rate, 0 = every frame */
    double retry_min, retry_max;
    int position_valid;
    cdspd_stats *stats;

    pthread_t th;
    int have_th;
    pthread_mutex_t mu;      /* guards what follows */
    pthread_cond_t cv;
    int stop;
    int seen_up;             /* the source has been open: BOOT before */
    int pending;
    target tgt;
    uint64_t last_accept_us;
    uint64_t n_sent, n_replaced, n_limited; /* poses: sent, replaced unsent, over the rate */
};

static int open_serial(mav_link *l, char *err, size_t errlen)
{
    struct termios t;
    speed_t code = B57600;
    int fd = open(l->u.path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s: %s", l->u.path, strerror(errno));
        return -1;
    }
    if (tcgetattr(fd, &t)) {
        snprintf(err, errlen, "%s: not a serial device: %s", l->u.path, strerror(errno));
        close(fd);
        return -1;
    }
    /* raw 8N1: no line discipline, no translation of 0x0A or 0x0D, no
     * echo, no signals, receiver on, modem lines ignored */
    cfmakeraw(&t);
    t.c_cflag &= ~(tcflag_t)(CSTOPB | PARENB | CSIZE | CRTSCTS);
    t.c_cflag |= CS8 | CREAD | CLOCAL;
    if (l->u.flow_control)
        t.c_cflag |= CRTSCTS;
    t.c_iflag &= ~(tcflag_t)(IXON | IXOFF | IXANY);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    baud_code(l->u.baud, &code);
    if (cfsetispeed(&t, code) || cfsetospeed(&t, code) || tcsetattr(fd, TCSANOW, &t)) {
        snprintf(err, errlen, "%s: cannot set %ld baud 8N1: %s", l->u.path, l->u.baud,
                 strerror(errno));
        close(fd);
        return -1;
    }
    tcflush(fd, TCIOFLUSH);
    l->fd = fd;
    return 0;
}

static int open_link(mav_link *l, char *err, size_t errlen)
{
    if (l->u.kind == CDSPD_MAVLINK_SERIAL)
        return open_serial(l, err, errlen);
    l->fd = socket(l->u.addr.ss_family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (l->fd < 0) {
        snprintf(err, errlen, "cannot create a UDP socket: %s", strerror(errno));
        return -1;
    }
    return 0;
}

static void close_link(mav_link *l)
{
    if (l->fd >= 0)
        close(l->fd);
    l->fd = -1;
}

/* Try to open a closed link whose time has come. */
static void try_open(cdspd_mavout *m, mav_link *l, uint64_t now)
{
    char err[CDSPD_STR + 256];
    if (!open_link(l, err, sizeof err)) {
        if (l->opened_before)
            LOG_I(MAVLINK, "%s: reopened", l->text);
        else
            LOG_I(MAVLINK, "sending MAVLink (system %u, component %u) to %s", m->sysid, m->compid,
                  l->text);
        l->opened_before = 1;
        l->open_fails = 0;
        l->backoff = m->retry_min;
        return;
    }
    /* the first failure and then every 10th at warning level */
    if (l->open_fails++ % 10 == 0)
        LOG_W(MAVLINK, "%s: cannot open %s; retrying in %.1f s (the daemon keeps running)", l->text,
              err, l->backoff);
    else
        LOG_D(MAVLINK, "%s: cannot open %s; retrying in %.1f s", l->text, err, l->backoff);
    l->retry_at_us = now + (uint64_t)(l->backoff * 1e6);
    l->backoff = l->backoff * 2 > m->retry_max ? m->retry_max : l->backoff * 2;
}

static void count_failure(mav_link *l, int e, const char *what)
{
    uint64_t now = cdspd_now_us();
    l->failures++;
    if (e != l->last_errno || now - l->last_log_us >= 10000000u) {
        LOG_W(MAVLINK, "%s: %s: %s (%llu failed so far; the daemon keeps running)", l->text, what,
              strerror(e), (unsigned long long)l->failures);
        l->last_errno = e;
        l->last_log_us = now;
    }
}

/* All of buf to a serial link, waiting at most SERIAL_WRITE_WAIT_MS for
 * room: 0; 1 (dropped, link kept); -1 (device gone: closed). */
static int write_serial(cdspd_mavout *m, mav_link *l, const uint8_t *buf, size_t n)
{
    size_t done = 0;
    uint64_t give_up = cdspd_now_us() + SERIAL_WRITE_WAIT_MS * 1000u;
    while (done < n) {
        ssize_t w = write(l->fd, buf + done, n - done);
        if (w > 0) {
            done += (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && errno == EAGAIN) {
            struct pollfd p = {l->fd, POLLOUT, 0};
            uint64_t now = cdspd_now_us();
            if (now >= give_up) {
                count_failure(l, EAGAIN, "the link is too slow, frame dropped");
                return 1;
            }
            poll(&p, 1, (int)((give_up - now) / 1000u) + 1);
            if (!(p.revents & (POLLERR | POLLHUP | POLLNVAL)))
                continue;
            errno = EIO;
        }
        LOG_W(MAVLINK, "%s: write: %s; closed, reopening in %.1f s (the daemon keeps running)",
              l->text, w < 0 ? strerror(errno) : "nothing written", l->backoff);
        close_link(l);
        l->retry_at_us = cdspd_now_us() + (uint64_t)(l->backoff * 1e6);
        l->backoff = l->backoff * 2 > m->retry_max ? m->retry_max : l->backoff * 2;
        return -1;
    }
    if (l->failures && l->last_errno) {
        LOG_I(MAVLINK, "%s: sending works again (after %llu failures)", l->text,
              (unsigned long long)l->failures);
        l->failures = 0;
        l->last_errno = 0;
    }
    return 0;
}

/* Frame one message and write it to every open link (each its own seq). */
static void send_all(cdspd_mavout *m, uint32_t msgid, const uint8_t *payload, size_t len)
{
    uint8_t buf[CDSPD_MAVLINK_MAX_FRAME];
    int i;
    for (i = 0; i < m->n; i++) {
        mav_link *l = &m->links[i];
        size_t n;
        if (l->fd < 0)
            continue;
        n = cdspd_mavlink_frame_encode(buf, sizeof buf, l->seq++, m->sysid, m->compid, msgid, payload,
                                       len);
        if (!n)
            continue; /* an unknown id: a programming error caught by the tests */
        if (l->u.kind == CDSPD_MAVLINK_SERIAL) {
            write_serial(m, l, buf, n);
        } else {
            ssize_t r;
            do
                r = sendto(l->fd, buf, n, MSG_DONTWAIT | MSG_NOSIGNAL,
                           (const struct sockaddr *)&l->u.addr, l->u.addr_len);
            while (r < 0 && errno == EINTR);
            if (r != (ssize_t)n) {
                count_failure(l, r < 0 ? errno : EMSGSIZE, "cannot send");
            } else if (l->failures && l->last_errno) {
                LOG_I(MAVLINK, "%s: sending works again (after %llu failures)", l->text,
                      (unsigned long long)l->failures);
                l->failures = 0;
                l->last_errno = 0;
            }
        }
    }
}

static void send_heartbeat(cdspd_mavout *m)
{
    cdspd_mavlink_heartbeat h;
    uint8_t p[CDSPD_MAVLINK_LEN_HEARTBEAT];
    memset(&h, 0, sizeof h);
    h.type = CDSPD_MAV_TYPE_ONBOARD_CONTROLLER;
    h.autopilot = CDSPD_MAV_AUTOPILOT_INVALID;
    if (!cdspd_stats_down(m->stats))
        m->seen_up = 1; /* only this thread reads or writes it */
    h.system_status = !m->seen_up                   ? CDSPD_MAV_STATE_BOOT
                      : cdspd_stats_down(m->stats) ? CDSPD_MAV_STATE_CRITICAL
                                                   : CDSPD_MAV_STATE_ACTIVE;
    h.mavlink_version = CDSPD_MAVLINK_VERSION;
    send_all(m, CDSPD_MAVLINK_ID_HEARTBEAT, p, cdspd_mavlink_pack_heartbeat(p, &h));
}

/* The angle of an optical-frame point off the optical axis along image x
 * and y (docs/mavlink.md: angle_x, angle_y). */
static double angle_x(const double p[3])
{
    return atan2(p[0], p[2]);
}

static double angle_y(const double p[3])
{
    return atan2(p[1], p[2]);
}

static void send_target(cdspd_mavout *m, const target *t)
{
    cdspd_mavlink_landing_target lt;
    cdspd_mavlink_debug_vect dv;
    uint8_t p[CDSPD_MAVLINK_LEN_LANDING_TARGET];
    const double *pc = t->b.point_cam;
    double range = sqrt(pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2]);
    double width = range > t->radius ? 2 * asin(t->radius / range) : M_PI;
    int i;

    memset(&lt, 0, sizeof lt);
    lt.time_usec = t->time_usec;
    lt.angle_x = (float)angle_x(pc);
    lt.angle_y = (float)angle_y(pc);
    lt.distance = (float)(1e-3 * sqrt(t->b.point[0] * t->b.point[0] + t->b.point[1] * t->b.point[1] +
                                      t->b.point[2] * t->b.point[2]));
    /* the visible pipe's angular extent: its axis segment's plus the
     * pipe's angular width 2 asin(r / range) at the target point */
    lt.size_x = (float)(fabs(angle_x(t->segment[1]) - angle_x(t->segment[0])) + width);
    lt.size_y = (float)(fabs(angle_y(t->segment[1]) - angle_y(t->segment[0])) + width);
    lt.target_num = 0;
    lt.frame = CDSPD_MAV_FRAME_BODY_FRD;
    if (m->position_valid) {
        /* else the position fields (x, y, z, q, type) stay zero, as the
         * message defines them when position_valid is 0 */
        lt.x = (float)(1e-3 * t->b.point[0]);
        lt.y = (float)(1e-3 * t->b.point[1]);
        lt.z = (float)(1e-3 * t->b.point[2]);
        for (i = 0; i < 4; i++)
            lt.q[i] = (float)t->b.q[i];
        lt.type = CDSPD_LANDING_TARGET_TYPE_VISION_OTHER;
        lt.position_valid = 1;
    }
    send_all(m, CDSPD_MAVLINK_ID_LANDING_TARGET, p, cdspd_mavlink_pack_landing_target(p, &lt));

    memset(&dv, 0, sizeof dv);
    dv.time_usec = t->time_usec;
    dv.x = (float)t->b.direction[0];
    dv.y = (float)t->b.direction[1];
    dv.z = (float)t->b.direction[2];
    memcpy(dv.name, "PIPE_DIR", 8);
    send_all(m, CDSPD_MAVLINK_ID_DEBUG_VECT, p, cdspd_mavlink_pack_debug_vect(p, &dv));
}

static void abs_time(struct timespec *ts, uint64_t t_us)
{
    ts->tv_sec = (time_t)(t_us / 1000000u);
    ts->tv_nsec = (long)(t_us % 1000000u) * 1000L;
}

static void *mavout_main(void *arg)
{
    cdspd_mavout *m = arg;
    uint64_t next_hb = cdspd_now_us();
    target t;

    pthread_mutex_lock(&m->mu);
    for (;;) {
        uint64_t now = cdspd_now_us(), wake = next_hb;
        int i, acted = 0;
        /* links due to be (re)opened first: the first heartbeat finds them open */
        for (i = 0; i < m->n; i++) {
            mav_link *l = &m->links[i];
            if (l->fd < 0 && now >= l->retry_at_us && !m->stop) {
                pthread_mutex_unlock(&m->mu);
                try_open(m, l, now);
                pthread_mutex_lock(&m->mu);
                acted = 1;
            }
        }
        if (acted)
            continue;
        if (now >= next_hb && !m->stop) {
            /* before the pose: a slow link busy with poses must not starve it */
            pthread_mutex_unlock(&m->mu);
            send_heartbeat(m);
            pthread_mutex_lock(&m->mu);
            /* 1 Hz on the clock, without catching up after a stall */
            next_hb += 1000000u;
            if (next_hb <= now)
                next_hb = now + 1000000u;
            continue;
        }
        if (m->pending) {
            /* first, and once more after the stop: the last pose goes out */
            t = m->tgt;
            m->pending = 0;
            m->n_sent++;
            pthread_mutex_unlock(&m->mu);
            send_target(m, &t);
            pthread_mutex_lock(&m->mu);
            continue;
        }
        if (m->stop)
            break;
        for (i = 0; i < m->n; i++)
            if (m->links[i].fd < 0 && m->links[i].retry_at_us < wake)
                wake = m->links[i].retry_at_us;
        {
            struct timespec ts;
            abs_time(&ts, wake);
            pthread_cond_timedwait(&m->cv, &m->mu, &ts);
        }
    }
    pthread_mutex_unlock(&m->mu);
    return NULL;
}

/* ------------------------------------------------------------------------
 * Start, frames, stop.
 * ---------------------------------------------------------------------- */
int cdspd_mavout_start(cdspd_mavout **out, const cdspd_config *c, cdspd_stats *stats, char *err,
                       size_t errlen)
{
    cdspd_mavout *m;
    pthread_condattr_t ca;
    int i;

    *out = NULL;
    if (c->n_mavlink == 0)
        return 0;
    m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    m->n = c->n_mavlink;
    m->sysid = (uint8_t)c->mavlink_system_id;
    m->compid = (uint8_t)c->mavlink_component_id;
    m->min_interval_us = c->mavlink_rate > 0 ? 1e6 / c->mavlink_rate : 0;
    m->retry_min = c->retry_min;
    m->retry_max = c->retry_max;
    m->position_valid = c->mavlink_position_valid;
    m->stats = stats;
    for (i = 0; i < m->n; i++) {
        mav_link *l = &m->links[i];
        char e[CDSPD_STR + 256];
        if (cdspd_mavlink_url_parse(c->mavlink[i], &l->u, 1, e, sizeof e)) {
            snprintf(err, errlen, "key 'mavlink': %s", e);
            free(m);
            return -1;
        }
        l->text = c->mavlink[i];
        l->fd = -1;
        l->backoff = c->retry_min;
    }
    pthread_mutex_init(&m->mu, NULL);
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC); /* cdspd_now_us's clock */
    pthread_cond_init(&m->cv, &ca);
    pthread_condattr_destroy(&ca);
    if (pthread_create(&m->th, NULL, mavout_main, m)) {
        snprintf(err, errlen, "cannot start the MAVLink thread");
        cdspd_mavout_stop(m);
        return -1;
    }
    m->have_th = 1;
    *out = m;
    return 0;
}

void cdspd_mavout_frame(cdspd_mavout *m, const cdspd_record *r, const cdspd_body_pose *b)
{
    uint64_t now;
    if (!m || r->status != 0 || r->kind != CDSPD_KIND_FRAME)
        return; /* no pipe: the heartbeat only */
    now = cdspd_now_us();
    pthread_mutex_lock(&m->mu);
    if (m->min_interval_us <= 0 || m->last_accept_us == 0 ||
        (double)(now - m->last_accept_us) >= m->min_interval_us) {
        m->last_accept_us = now;
        m->tgt.time_usec = r->t_camera_us ? r->t_camera_us : r->t_host_us;
        m->tgt.radius = r->radius;
        memcpy(m->tgt.segment, r->segment, sizeof m->tgt.segment);
        m->tgt.b = *b;
        m->n_replaced += m->pending;
        m->pending = 1; /* latest wins: an unsent older pose is replaced */
        pthread_cond_signal(&m->cv);
    } else {
        m->n_limited++;
    }
    pthread_mutex_unlock(&m->mu);
}

void cdspd_mavout_stop(cdspd_mavout *m)
{
    int i;
    if (!m)
        return;
    pthread_mutex_lock(&m->mu);
    m->stop = 1;
    pthread_cond_signal(&m->cv);
    pthread_mutex_unlock(&m->mu);
    if (m->have_th)
        pthread_join(m->th, NULL);
    LOG_I(MAVLINK, "poses: %llu sent, %llu replaced by a newer one before sending, %llu over "
          "mavlink_rate", (unsigned long long)m->n_sent, (unsigned long long)m->n_replaced,
          (unsigned long long)m->n_limited);
    for (i = 0; i < m->n; i++)
        close_link(&m->links[i]);
    pthread_cond_destroy(&m->cv);
    pthread_mutex_destroy(&m->mu);
    free(m);
}
