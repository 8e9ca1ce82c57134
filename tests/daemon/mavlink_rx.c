/*
 * mavlink_rx - the test receiver of cdspd's MAVLink output
 * (tests/daemon/mavlink_e2e.sh). It takes cdspd's MAVLink stream (UDP on
 * loopback, or the master side of a pseudo-terminal whose slave cdspd opens
 * as a serial device) and, at the same time, its JSON datagrams, and checks:
 *   - every MAVLink frame decodes, its crc right (no junk, no bad crc), the
 *     system and component ids expected, sequence numbers continuous;
 *   - HEARTBEAT: the first message; type 18, autopilot 8, mavlink_version 3;
 *     BOOT only before the first pose, ACTIVE from then on; the rate by the
 *     arrival times (UDP: the kernel's, SO_TIMESTAMPNS). Not too many: cdspd sends on a 1 s schedule that
 *     never catches up, so N heartbeats take at least N - 1 s to send, and
 *     all were sent between this receiver's start (before cdspd's) and the
 *     last one's arrival - a bound no delay can break. Not too few: this
 *     side depends on the machine, so it is loose: a mean interval of at
 *     most 2 s and none over 10 s (cdspd under nice on this 2-core machine
 *     at 99 % CPU pressure was seen silent for 5.2 s once; idle, the
 *     intervals are 1 +- 0.05 s) - it catches a missing or half-rate
 *     heartbeat, not scheduling;
 *   - each LANDING_TARGET equals the JSON pose of the frame with the same
 *     camera timestamp transformed by the mount given here (--mount: roll,
 *     pitch, yaw in degrees, x, y, z in mm), computed here independently of
 *     daemon/mount.c (elementary rotations multiplied out, the quaternion
 *     as a product of two axis rotations); DEBUG_VECT "PIPE_DIR" the
 *     direction; the JSON body-frame fields the same;
 *   - with --pty: after --vanish-after seconds of poses the pseudo-terminal
 *     is closed and removed (the device vanishes) for --vanish-for seconds,
 *     then a new one is put at the same path; poses must come again.
 *   - with --soak (tests/daemon/soak.sh: hours of frames at full rate,
 *     reloads restarting the output): every frame still decodes with its
 *     crc and ids, each message is checked on its own as it arrives
 *     (HEARTBEAT's fields; LANDING_TARGET: BODY_FRD, type 3, valid, finite,
 *     |q| = 1, distance = |(x, y, z)|, sizes positive; DEBUG_VECT a unit
 *     vector equal to q's forward axis, right after its LANDING_TARGET),
 *     without JSON records to match; sequence gaps (a valid reload
 *     restarts the output, whose sequence starts at 0 again; loopback
 *     drops a datagram when this process falls behind) and the heartbeat's
 *     timing (a reload sends one at once) are counted and printed, not failed.
 *
 * Tolerances: the JSON numbers are exact (shortest round-trip text), so
 * the test's double computation and the daemon's differ by rounding only
 * (~1e-16 relative, 1e-13 of the mm values); the MAVLink fields are floats,
 * rounded to half an ulp, 2^-24 relative. Allowed: one float ulp, 2^-23 |x|,
 * plus 1e-9 absolute (m or rad) for values near zero: measured 0.44-0.48
 * of it (check-daemon-mavlink). The JSON body-frame fields against the
 * same transform here, in double: a few roundings of the 3x3 products,
 * 8 eps (1 + |x|) (the point in mm, the direction unit; it was 1e-9
 * relative and 1e-12); measured 0 (the same products in the same order:
 * the bound is for an order that differs). The largest errors seen are
 * printed.
 *
 * Usage: mavlink_rx --port-file F (--udp | --pty LINK) [options]; prints a
 * summary; exit 0 when every check passed, 1 when one failed, 2 usage.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <float.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <pty.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "cdsp_host.h"
#include "mavlink.h"
#include "proto.h"

#define MAX_REC 20000

typedef struct {
    uint64_t t;            /* camera timestamp */
    double point_body[3], direction_body[3];
    double point[3], direction[3], segment[2][3], radius;
    int ok;
} json_rec;

typedef struct {
    double t_rx;
    cdspd_mavlink_landing_target lt;
} lt_rec;

static json_rec *jrec;
static long n_json;
static lt_rec *lts;
static long n_lt;
static cdspd_mavlink_debug_vect *dvs;
static long n_dv;

static int failures;

static void check(int cond, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void check(int cond, const char *fmt, ...)
{
    va_list ap;
    if (cond)
        return;
    if (failures++ < 20) {
        va_start(ap, fmt);
        fputs("mavlink_rx: FAIL: ", stderr);
        vfprintf(stderr, fmt, ap);
        fputc('\n', stderr);
        va_end(ap);
    }
}

/* One UDP datagram and the kernel's arrival time (SO_TIMESTAMPNS, the
 * realtime clock, moved onto cdsp_host_now_s's by the offset measured at start): the
 * heartbeat's timing is then the sender's, not this process's scheduling. */
static double real_minus_mono;

static ssize_t recv_stamped(int fd, void *buf, size_t cap, double *t)
{
    char ctl[CMSG_SPACE(sizeof(struct timespec))];
    struct iovec io = {buf, cap};
    struct msghdr mh;
    struct cmsghdr *c;
    ssize_t n;
    memset(&mh, 0, sizeof mh);
    mh.msg_iov = &io;
    mh.msg_iovlen = 1;
    mh.msg_control = ctl;
    mh.msg_controllen = sizeof ctl;
    n = recvmsg(fd, &mh, 0);
    for (c = CMSG_FIRSTHDR(&mh); n > 0 && c; c = CMSG_NXTHDR(&mh, c))
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
            struct timespec ts;
            memcpy(&ts, CMSG_DATA(c), sizeof ts);
            *t = (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec - real_minus_mono;
        }
    return n;
}

/* ---- the expected pose, independently of daemon/mount.c ------------------ */
static void matmul(double a[3][3], double b[3][3], double c[3][3])
{
    int i, j, k;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            c[i][j] = 0;
            for (k = 0; k < 3; k++)
                c[i][j] += a[i][k] * b[k][j];
        }
}

/* Rotation about body axis `axis` (0 x, 1 y, 2 z) by deg, right-handed. */
static void rot(int axis, double deg, double r[3][3])
{
    double a = deg * M_PI / 180, c = cos(a), s = sin(a);
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    memset(r, 0, 9 * sizeof(double));
    r[axis][axis] = 1;
    r[i][i] = c;
    r[i][j] = -s;
    r[j][i] = s;
    r[j][j] = c;
    /* quarter turns exactly, as a rotated camera mount is meant */
    if (fabs(fmod(deg, 90)) < 1e-12)
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                r[i][j] = round(r[i][j]);
}

static double mount_R[3][3], mount_t[3];

static void mount_setup(const double m[6])
{
    double rz[3][3], ry[3][3], rx[3][3], t1[3][3], frd[3][3];
    /* optical -> camera FRD: forward = Z, right = X, down = Y */
    double P[3][3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    rot(2, m[2], rz);
    rot(1, m[1], ry);
    rot(0, m[0], rx);
    matmul(rz, ry, t1);
    matmul(t1, rx, frd);
    matmul(frd, P, mount_R);
    mount_t[0] = m[3];
    mount_t[1] = m[4];
    mount_t[2] = m[5];
}

typedef struct {
    double n[3], d[3], q[4], pc[3];
} expect;

static void qmul(const double a[4], const double b[4], double c[4])
{
    c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

static void expected(const json_rec *j, expect *e)
{
    double pb[3], len = 0, s = 0, yaw, pitch, qz[4], qy[4];
    int i, k;
    for (i = 0; i < 3; i++) {
        pb[i] = mount_t[i];
        e->d[i] = 0;
        for (k = 0; k < 3; k++) {
            pb[i] += mount_R[i][k] * j->point[k];
            e->d[i] += mount_R[i][k] * j->direction[k];
        }
        len += e->d[i] * e->d[i];
    }
    len = sqrt(len);
    for (i = 0; i < 3; i++)
        e->d[i] /= len;
    /* forward first, then right, then down (docs/mavlink.md) */
    for (i = 0; i < 3; i++)
        if (fabs(e->d[i]) > 1e-12) {
            if (e->d[i] < 0)
                for (k = 0; k < 3; k++)
                    e->d[k] = -e->d[k];
            break;
        }
    for (i = 0; i < 3; i++)
        s += pb[i] * e->d[i];
    for (i = 0; i < 3; i++)
        e->n[i] = pb[i] - s * e->d[i];
    yaw = atan2(e->d[1], e->d[0]);
    pitch = atan2(-e->d[2], hypot(e->d[0], e->d[1]));
    qz[0] = cos(yaw / 2), qz[1] = 0, qz[2] = 0, qz[3] = sin(yaw / 2);
    qy[0] = cos(pitch / 2), qy[1] = 0, qy[2] = sin(pitch / 2), qy[3] = 0;
    qmul(qz, qy, e->q);
    for (k = 0; k < 3; k++) {
        e->pc[k] = 0;
        for (i = 0; i < 3; i++)
            e->pc[k] += mount_R[i][k] * (e->n[i] - mount_t[i]);
    }
}

static double worst_body; /* largest JSON body-frame error / its bound */
static double worst_rel; /* largest |got - want| / (2^-23 |want| + 1e-9) */

static void near(double got, double want, const char *what, uint64_t t)
{
    double tol = ldexp(fabs(want), -23) + 1e-9, r = fabs(got - want) / tol;
    if (r > worst_rel)
        worst_rel = r;
    check(r <= 1, "frame t=%llu: %s = %.9g, expected %.9g (tolerance %.3g)", (unsigned long long)t,
          what, got, want, tol);
}

/* ---- options ------------------------------------------------------------- */
typedef struct {
    const char *port_file, *pty_link;
    double mount[6];
    double duration, idle, vanish_after, vanish_for, max_rate;
    long min_targets, min_after_reopen;
    int sysid, compid, no_position, soak;
} options;

static void usage(FILE *f)
{
    fprintf(f, "usage: mavlink_rx --port-file F [--pty LINK] [--mount r,p,y,x,y,z]\n"
               "       [--sysid N] [--compid N] [--duration S] [--idle S] [--min-targets N]\n"
               "       [--no-position (cdspd's mavlink_position false)] [--max-rate HZ]\n"
               "       [--vanish-after S --vanish-for S --min-after-reopen N] [--soak]\n"
               "Port file: 'MAVPORT JSONPORT' (MAVPORT 0 with --pty).\n");
}

static int parse(options *o, int argc, char **argv)
{
    static const struct option lo[] = {
        {"port-file", 1, 0, 'p'}, {"pty", 1, 0, 't'}, {"mount", 1, 0, 'm'},
        {"sysid", 1, 0, 's'}, {"compid", 1, 0, 'c'}, {"duration", 1, 0, 'd'},
        {"idle", 1, 0, 'i'}, {"min-targets", 1, 0, 'n'}, {"no-position", 0, 0, 'o'}, {"max-rate", 1, 0, 'R'},
        {"vanish-after", 1, 0, 'v'}, {"vanish-for", 1, 0, 'w'}, {"min-after-reopen", 1, 0, 'r'},
        {"soak", 0, 0, 'S'}, {"help", 0, 0, 'h'}, {0, 0, 0, 0}};
    int ch;
    memset(o, 0, sizeof *o);
    o->duration = 600; /* a bound only: it stops --idle s after the last datagram */
    o->idle = 3;
    o->sysid = 1;
    o->compid = 191;
    while ((ch = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        switch (ch) {
        case 'p': o->port_file = optarg; break;
        case 't': o->pty_link = optarg; break;
        case 'm':
            if (sscanf(optarg, "%lf,%lf,%lf,%lf,%lf,%lf", &o->mount[0], &o->mount[1], &o->mount[2],
                       &o->mount[3], &o->mount[4], &o->mount[5]) != 6) {
                fprintf(stderr, "mavlink_rx: --mount: six numbers r,p,y,x,y,z\n");
                return -1;
            }
            break;
        case 's': o->sysid = atoi(optarg); break;
        case 'c': o->compid = atoi(optarg); break;
        case 'd': o->duration = atof(optarg); break;
        case 'i': o->idle = atof(optarg); break;
        case 'n': o->min_targets = atol(optarg); break;
        case 'o': o->no_position = 1; break;
        case 'R': o->max_rate = atof(optarg); break;
        case 'v': o->vanish_after = atof(optarg); break;
        case 'w': o->vanish_for = atof(optarg); break;
        case 'r': o->min_after_reopen = atol(optarg); break;
        case 'S': o->soak = 1; break;
        case 'h': usage(stdout); exit(0);
        default: return -1;
        }
    }
    if (!o->port_file || optind < argc)
        return -1;
    return 0;
}

/* ---- the pseudo-terminal ------------------------------------------------- */
static int pty_master = -1, pty_slave = -1;

static int pty_open(const char *link_path)
{
    char name[256], tmp[1100];
    struct termios t;
    if (openpty(&pty_master, &pty_slave, name, NULL, NULL)) {
        fprintf(stderr, "mavlink_rx: openpty: %s\n", strerror(errno));
        return -1;
    }
    /* raw from the start: cdspd sets it too, this only covers the time
     * before it opens; the slave stays open here so that the master never
     * reads as hung up while cdspd has it closed */
    tcgetattr(pty_slave, &t);
    cfmakeraw(&t);
    tcsetattr(pty_slave, TCSANOW, &t);
    fcntl(pty_master, F_SETFL, fcntl(pty_master, F_GETFL) | O_NONBLOCK);
    snprintf(tmp, sizeof tmp, "%s.new", link_path);
    unlink(tmp);
    if (symlink(name, tmp) || rename(tmp, link_path)) {
        fprintf(stderr, "mavlink_rx: %s -> %s: %s\n", link_path, name, strerror(errno));
        return -1;
    }
    return 0;
}

static void pty_vanish(const char *link_path)
{
    unlink(link_path);
    close(pty_master);
    close(pty_slave);
    pty_master = pty_slave = -1;
}

/* ---- the MAVLink stream --------------------------------------------------- */
typedef struct {
    long frames, junk_bytes, bad_crc, unknown, seq_gaps, hb, bad_ids;
    int have_seq;
    uint8_t last_seq;
    double hb_last, hb_min_gap, hb_max_gap, hb_sum;
    long hb_gaps;
    int skip_gap;          /* the device vanished since the last heartbeat */
    long hb_boot_after_pose, hb_not_active_after_pose, dv;
    double t_first_lt, t_reopen;
    long lt_after_reopen;
    uint64_t out0, out1;   /* camera times of the last pose before the outage, the first after */
    int first_was_hb, got_any;
    uint64_t last_lt_time;
    uint64_t last_dv_time;
    int cut_pair;          /* the vanish fell between a LANDING_TARGET and its DEBUG_VECT */
} stream;

/* --soak: a LANDING_TARGET on its own. Tolerances: the fields are floats
 * computed in double and rounded once (u = 2^-24 = 6e-8 relative each):
 * |q|^2 - 1 moves by 2 sum q_i dq_i <= 2u |q|^2 = 1.2e-7, distance /
 * |(x, y, z)| - 1 by u for distance and u for the norm: 1.2e-7; both
 * bounded by 2.5e-7 (2x). DEBUG_VECT: (1, 0, 0) rotated by the float q
 * (each component quadratic in q: an error <= 4u per component from q's
 * rounding) against the float vector (u each): 3 (4u + u) = 9e-7, bounded
 * by 1e-6. Angles within [-pi, pi]. Measured (the summary's "worst" line,
 * check-daemon-soak, 25 s): 6.9e-8, 4.7e-8, 1.9e-7 (3.6x, 5.3x, 5.2x
 * below; they were 1e-6, 1e-6, 3e-6). */
#define SOAK_NORM_TOL 2.5e-7
#define SOAK_DV_TOL 1e-6
static double soak_worst_q, soak_worst_dist, soak_worst_dv;
static long soak_lt, soak_dv, soak_lt_bad, soak_dv_bad;
static float soak_q[4];
static uint64_t soak_t;

static void soak_landing_target(const cdspd_mavlink_landing_target *lt)
{
    double qn = 0, r;
    int i, ok = 1;
    soak_lt++;
    for (i = 0; i < 4; i++) {
        ok = ok && isfinite(lt->q[i]);
        qn += (double)lt->q[i] * lt->q[i];
    }
    r = sqrt((double)lt->x * lt->x + (double)lt->y * lt->y + (double)lt->z * lt->z);
    ok = ok && isfinite(lt->x) && isfinite(lt->y) && isfinite(lt->z) && isfinite(lt->distance) &&
         isfinite(lt->angle_x) && isfinite(lt->angle_y) && isfinite(lt->size_x) && isfinite(lt->size_y);
    check(ok, "LANDING_TARGET t=%llu: a field not finite", (unsigned long long)lt->time_usec);
    check(lt->frame == CDSPD_MAV_FRAME_BODY_FRD && lt->type == 3 && lt->position_valid == 1 &&
              lt->target_num == 0,
          "LANDING_TARGET t=%llu: frame %u type %u position_valid %u target_num %u",
          (unsigned long long)lt->time_usec, lt->frame, lt->type, lt->position_valid,
          lt->target_num);
    if (ok) {
        soak_worst_q = fmax(soak_worst_q, fabs(qn - 1));
        if (r > 0)
            soak_worst_dist = fmax(soak_worst_dist, fabs(lt->distance / r - 1));
    }
    check(fabs(qn - 1) <= SOAK_NORM_TOL, "LANDING_TARGET t=%llu: |q|^2 = %.9g",
          (unsigned long long)lt->time_usec, qn);
    check(r > 0 && fabs(lt->distance / r - 1) <= SOAK_NORM_TOL, "LANDING_TARGET t=%llu: distance %.9g, |(x, y, z)| %.9g",
          (unsigned long long)lt->time_usec, lt->distance, r);
    check(fabs(lt->angle_x) <= M_PI && fabs(lt->angle_y) <= M_PI && lt->size_x > 0 &&
              lt->size_y > 0,
          "LANDING_TARGET t=%llu: angles %.6g %.6g, sizes %.6g %.6g", (unsigned long long)lt->time_usec,
          lt->angle_x, lt->angle_y, lt->size_x, lt->size_y);
    if (!ok || fabs(qn - 1) > SOAK_NORM_TOL || !(r > 0 && fabs(lt->distance / r - 1) <= SOAK_NORM_TOL))
        soak_lt_bad++;
    memcpy(soak_q, lt->q, sizeof soak_q);
    soak_t = lt->time_usec;
}

/* DEBUG_VECT PIPE_DIR: the forward axis (1, 0, 0) rotated by q (the body
 * frame's rotation matrix's first column), within 1e-6 per component. */
static void soak_debug_vect(const cdspd_mavlink_debug_vect *d)
{
    double w = soak_q[0], x = soak_q[1], y = soak_q[2], z = soak_q[3];
    double f[3] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
    double e = fabs(d->x - f[0]) + fabs(d->y - f[1]) + fabs(d->z - f[2]);
    soak_dv++;
    if (soak_t == d->time_usec)
        soak_worst_dv = fmax(soak_worst_dv, e);
    check(soak_t == d->time_usec && e <= SOAK_DV_TOL,
          "DEBUG_VECT t=%llu (%.7g %.7g %.7g): not q's forward axis (%.7g %.7g %.7g) of "
          "LANDING_TARGET t=%llu",
          (unsigned long long)d->time_usec, d->x, d->y, d->z, f[0], f[1], f[2],
          (unsigned long long)soak_t);
    if (soak_t != d->time_usec || e > SOAK_DV_TOL)
        soak_dv_bad++;
}

static void on_frame(stream *s, const options *o, const cdspd_mavlink_frame *f, double t)
{
    if (!s->got_any) {
        s->got_any = 1;
        s->first_was_hb = f->msgid == CDSPD_MAVLINK_ID_HEARTBEAT;
    }
    s->frames++;
    if (f->sysid != o->sysid || f->compid != o->compid)
        s->bad_ids++;
    if (s->have_seq && (uint8_t)(s->last_seq + 1) != f->seq)
        s->seq_gaps++;
    s->have_seq = 1;
    s->last_seq = f->seq;
    if (f->msgid == CDSPD_MAVLINK_ID_HEARTBEAT) {
        cdspd_mavlink_heartbeat h;
        cdspd_mavlink_unpack_heartbeat(f, &h);
        check(h.type == 18 && h.autopilot == 8 && h.mavlink_version == 3 && h.base_mode == 0 &&
                  h.custom_mode == 0,
              "heartbeat type %u autopilot %u version %u base_mode %u", h.type, h.autopilot,
              h.mavlink_version, h.base_mode);
        check(h.system_status == CDSPD_MAV_STATE_BOOT || h.system_status == CDSPD_MAV_STATE_ACTIVE ||
                  h.system_status == CDSPD_MAV_STATE_CRITICAL,
              "heartbeat system_status %u", h.system_status);
        if (n_lt && h.system_status != CDSPD_MAV_STATE_ACTIVE)
            s->hb_not_active_after_pose++;
        if (s->hb && !s->skip_gap) {
            double gap = t - s->hb_last;
            if (!s->hb_gaps || gap < s->hb_min_gap)
                s->hb_min_gap = gap;
            if (gap > s->hb_max_gap)
                s->hb_max_gap = gap;
            s->hb_sum += gap;
            s->hb_gaps++;
        }
        s->skip_gap = 0;
        s->hb_last = t;
        s->hb++;
    } else if (f->msgid == CDSPD_MAVLINK_ID_LANDING_TARGET && o->soak) {
        cdspd_mavlink_landing_target lt;
        cdspd_mavlink_unpack_landing_target(f, &lt);
        soak_landing_target(&lt);
        n_lt++;
        s->last_lt_time = lt.time_usec;
    } else if (f->msgid == CDSPD_MAVLINK_ID_DEBUG_VECT && o->soak) {
        cdspd_mavlink_debug_vect d;
        cdspd_mavlink_unpack_debug_vect(f, &d);
        s->dv++;
        check(!memcmp(d.name, "PIPE_DIR\0\0", 10), "DEBUG_VECT named '%.10s'", d.name);
        soak_debug_vect(&d);
    } else if (f->msgid == CDSPD_MAVLINK_ID_LANDING_TARGET) {
        if (n_lt < MAX_REC) {
            lts[n_lt].t_rx = t;
            cdspd_mavlink_unpack_landing_target(f, &lts[n_lt].lt);
            s->last_lt_time = lts[n_lt].lt.time_usec;
            n_lt++;
        }
        if (!s->t_first_lt)
            s->t_first_lt = t;
        if (s->t_reopen > 0 && !s->lt_after_reopen++)
            s->out1 = s->last_lt_time;
    } else if (f->msgid == CDSPD_MAVLINK_ID_DEBUG_VECT) {
        cdspd_mavlink_debug_vect d;
        cdspd_mavlink_unpack_debug_vect(f, &d);
        s->dv++;
        check(!memcmp(d.name, "PIPE_DIR\0\0", 10), "DEBUG_VECT named '%.10s'", d.name);
        check(n_lt > 0 && d.time_usec == s->last_lt_time,
              "DEBUG_VECT t=%llu does not follow its LANDING_TARGET", (unsigned long long)d.time_usec);
        s->last_dv_time = d.time_usec;
        if (n_dv < MAX_REC)
            dvs[n_dv++] = d; /* checked against the JSON at the end */
    }
}

static void feed(stream *s, const options *o, uint8_t *buf, size_t *have, double t)
{
    size_t off = 0, used;
    cdspd_mavlink_frame f;
    for (;;) {
        cdspd_mavlink_result r = cdspd_mavlink_frame_decode(buf + off, *have - off, &f, &used);
        if (r == CDSPD_MAVLINK_MORE || off == *have)
            break;
        off += used;
        switch (r) {
        case CDSPD_MAVLINK_OK: on_frame(s, o, &f, t); break;
        case CDSPD_MAVLINK_JUNK: s->junk_bytes += (long)used; break;
        case CDSPD_MAVLINK_BAD_CRC: s->bad_crc++; break;
        case CDSPD_MAVLINK_UNKNOWN: s->unknown++; break;
        default: break;
        }
    }
    memmove(buf, buf + off, *have - off);
    *have -= off;
}

static int bind_udp(int *port)
{
    struct sockaddr_in a;
    socklen_t l = sizeof a;
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int big = 8 << 20;
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) ||
        getsockname(fd, (struct sockaddr *)&a, &l)) {
        fprintf(stderr, "mavlink_rx: UDP socket: %s\n", strerror(errno));
        return -1;
    }
    /* room for seconds of datagrams while this process waits for a CPU on
     * a loaded machine (FORCE: beyond rmem_max when root; else the cap) */
    if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &big, sizeof big))
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    *port = ntohs(a.sin_port);
    return fd;
}

static void on_json(const uint8_t *buf, size_t n)
{
    cdspd_record r;
    const char *why;
    int is_json;
    json_rec *j;
    if (n_json >= MAX_REC)
        return;
    if (cdspd_proto_decode_any(buf, n, &r, &is_json, &why)) {
        check(0, "undecodable datagram: %s", why);
        return;
    }
    check(is_json, "a binary datagram (the test runs --format json)");
    if (r.kind != CDSPD_KIND_FRAME)
        return;
    j = &jrec[n_json++];
    j->t = r.t_camera_us;
    j->ok = r.status == 0;
    j->radius = r.radius;
    memcpy(j->point, r.point, sizeof j->point);
    memcpy(j->direction, r.direction, sizeof j->direction);
    memcpy(j->segment, r.segment, sizeof j->segment);
    memcpy(j->point_body, r.point_body, sizeof j->point_body);
    memcpy(j->direction_body, r.direction_body, sizeof j->direction_body);
}

int main(int argc, char **argv)
{
    options o;
    stream s;
    int mav_fd = -1, json_fd, mav_port = 0, json_port, i, vanished = 0;
    uint8_t buf[1 << 16];
    size_t have = 0;
    double t0, t_last = 0, t_vanish = 0;
    long matched = 0, json_ok = 0, k;
    FILE *pf;

    if (parse(&o, argc, argv)) {
        usage(stderr);
        return 2;
    }
    jrec = calloc(MAX_REC, sizeof *jrec);
    lts = calloc(MAX_REC, sizeof *lts);
    dvs = calloc(MAX_REC, sizeof *dvs);
    if (!jrec || !lts || !dvs)
        return 1;
    mount_setup(o.mount);
    memset(&s, 0, sizeof s);
    if ((json_fd = bind_udp(&json_port)) < 0)
        return 1;
    if (o.pty_link) {
        if (pty_open(o.pty_link))
            return 1;
    } else {
        int one = 1;
        struct timespec rt;
        if ((mav_fd = bind_udp(&mav_port)) < 0)
            return 1;
        setsockopt(mav_fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);
        clock_gettime(CLOCK_REALTIME, &rt);
        real_minus_mono = (double)rt.tv_sec + 1e-9 * (double)rt.tv_nsec - cdsp_host_now_s();
    }
    pf = fopen(o.port_file, "w");
    if (!pf)
        return 1;
    fprintf(pf, "%d %d\n", mav_port, json_port);
    fclose(pf);

    /* SIGTERM (or SIGINT): stop receiving and check what came (the soak
     * ends it so) */
    cdsp_host_stop_on_signals();
    t0 = cdsp_host_now_s();
    for (;;) {
        struct pollfd p[2];
        double t = cdsp_host_now_s();
        int np = 1;
        if (t - t0 > o.duration || cdsp_host_stop_requested())
            break;
        if (t_last > 0 && t - t_last > o.idle)
            break;
        if (o.pty_link && o.vanish_after > 0 && !vanished && s.t_first_lt > 0 &&
            t - s.t_first_lt > o.vanish_after) {
            pty_vanish(o.pty_link);
            have = 0;
            s.skip_gap = 1;
            s.out0 = s.last_lt_time;
            /* the pty's unread bytes (and the partial frame in buf) go
             * with it: the pose's DEBUG_VECT can be among them, after its
             * LANDING_TARGET was read (seen in CI: 125 for 126) */
            s.cut_pair = s.last_lt_time && s.last_dv_time != s.last_lt_time;
            vanished = 1;
            t_vanish = t;
            printf("pty closed and removed at %.2f s\n", t - t0);
        }
        if (vanished == 1 && t - t_vanish > o.vanish_for) {
            if (pty_open(o.pty_link))
                return 1;
            vanished = 2;
            s.t_reopen = t;
            t_last = t; /* idle counts from here */
            printf("new pty at %.2f s\n", t - t0);
        }
        p[0].fd = json_fd;
        p[0].events = POLLIN;
        p[1].fd = o.pty_link ? pty_master : mav_fd;
        p[1].events = POLLIN;
        if (p[1].fd >= 0)
            np = 2;
        if (poll(p, (nfds_t)np, 50) <= 0)
            continue;
        t = cdsp_host_now_s();
        /* everything that is there (non-blocking reads until EAGAIN) */
        if (p[0].revents & POLLIN) {
            static uint8_t jbuf[1 << 16];
            ssize_t n;
            while ((n = recv(json_fd, jbuf, sizeof jbuf, 0)) > 0) {
                on_json(jbuf, (size_t)n);
                t_last = t;
            }
        }
        if (np == 2 && (p[1].revents & POLLIN)) {
            uint8_t tmp[4096];
            ssize_t n;
            double ta = t;
            while ((n = o.pty_link ? read(pty_master, tmp, sizeof tmp)
                                   : recv_stamped(mav_fd, tmp, sizeof tmp, &ta)) > 0) {
                if (have + (size_t)n > sizeof buf) {
                    check(0, "more than %zu bytes without a whole frame", sizeof buf);
                    have = 0;
                }
                memcpy(buf + have, tmp, (size_t)n);
                have += (size_t)n;
                feed(&s, &o, buf, &have, ta);
                t_last = t;
                if (!o.pty_link) /* one datagram is whole frames */
                    check(have == 0, "a UDP datagram with a partial frame (%zu bytes left)", have);
                ta = cdsp_host_now_s(); /* the pty's bytes: when read */
            }
        }
    }
    if (o.pty_link && pty_master >= 0)
        pty_vanish(o.pty_link);

    if (o.soak) {
        printf("mavlink_rx --soak: %ld frames (%ld heartbeats, %ld LANDING_TARGET, %ld DEBUG_VECT), "
               "%ld junk bytes, %ld bad crc, %ld unknown, %ld sequence gaps (reloads, loopback "
               "losses: counted), %ld LANDING_TARGET and %ld DEBUG_VECT failed their checks\n",
               s.frames, s.hb, soak_lt, soak_dv, s.junk_bytes, s.bad_crc, s.unknown, s.seq_gaps,
               soak_lt_bad, soak_dv_bad);
        printf("mavlink_rx --soak: worst | |q|^2 - 1 | %.3g, | distance / |(x, y, z)| - 1 | %.3g "
               "(tolerance %.3g), DEBUG_VECT %.3g (tolerance %.3g)\n", soak_worst_q, soak_worst_dist,
               SOAK_NORM_TOL, soak_worst_dv, SOAK_DV_TOL);
        check(s.got_any && s.first_was_hb, "the first MAVLink message was not a HEARTBEAT");
        check(s.junk_bytes == 0 && s.bad_crc == 0 && s.unknown == 0,
              "%ld junk bytes, %ld bad crc, %ld unknown ids", s.junk_bytes, s.bad_crc, s.unknown);
        check(s.bad_ids == 0, "%ld frames not from system %d component %d", s.bad_ids, o.sysid,
              o.compid);
        check(n_lt >= o.min_targets, "%ld LANDING_TARGET, at least %ld expected", n_lt,
              o.min_targets);
        if (failures)
            fprintf(stderr, "mavlink_rx: %d check(s) failed\n", failures);
        else
            printf("mavlink_rx: PASS\n");
        free(jrec);
        free(lts);
        free(dvs);
        return failures ? 1 : 0;
    }

    /* every LANDING_TARGET against its frame's JSON record */
    for (k = 0; k < n_lt; k++) {
        const cdspd_mavlink_landing_target *lt = &lts[k].lt;
        const json_rec *j = NULL;
        expect e;
        double w, range, sx, sy;
        for (i = 0; i < n_json; i++)
            if (jrec[i].t == lt->time_usec) {
                j = &jrec[i];
                break;
            }
        check(j != NULL, "LANDING_TARGET t=%llu: no JSON record of that frame",
              (unsigned long long)lt->time_usec);
        if (!j)
            continue;
        check(j->ok, "LANDING_TARGET t=%llu for a frame without a pipe", (unsigned long long)j->t);
        if (!j->ok)
            continue;
        matched++;
        expected(j, &e);
        check(lt->frame == CDSPD_MAV_FRAME_BODY_FRD && lt->type == (o.no_position ? 0 : 3) &&
                  lt->position_valid == !o.no_position && lt->target_num == 0,
              "LANDING_TARGET frame %u type %u position_valid %u target_num %u", lt->frame, lt->type,
              lt->position_valid, lt->target_num);
        if (o.no_position) {
            /* the position fields zero (and not sent: trailing zeros) */
            check(lt->x == 0 && lt->y == 0 && lt->z == 0 && lt->q[0] == 0 && lt->q[1] == 0 &&
                      lt->q[2] == 0 && lt->q[3] == 0,
                  "LANDING_TARGET t=%llu: position fields without position_valid",
                  (unsigned long long)j->t);
        } else {
            near(lt->x, 1e-3 * e.n[0], "x", j->t);
            near(lt->y, 1e-3 * e.n[1], "y", j->t);
            near(lt->z, 1e-3 * e.n[2], "z", j->t);
            for (i = 0; i < 4; i++)
                near(lt->q[i], e.q[i], "q", j->t);
        }
        near(lt->distance, 1e-3 * sqrt(e.n[0] * e.n[0] + e.n[1] * e.n[1] + e.n[2] * e.n[2]),
             "distance", j->t);
        near(lt->angle_x, atan2(e.pc[0], e.pc[2]), "angle_x", j->t);
        near(lt->angle_y, atan2(e.pc[1], e.pc[2]), "angle_y", j->t);
        range = sqrt(e.pc[0] * e.pc[0] + e.pc[1] * e.pc[1] + e.pc[2] * e.pc[2]);
        w = 2 * asin(j->radius / range);
        sx = fabs(atan2(j->segment[1][0], j->segment[1][2]) - atan2(j->segment[0][0], j->segment[0][2]));
        sy = fabs(atan2(j->segment[1][1], j->segment[1][2]) - atan2(j->segment[0][1], j->segment[0][2]));
        near(lt->size_x, sx + w, "size_x", j->t);
        near(lt->size_y, sy + w, "size_y", j->t);
        /* the JSON body-frame fields: the same transform, in mm, doubles */
        for (i = 0; i < 3; i++) {
            double bp = 8 * DBL_EPSILON * (1 + fabs(e.n[i])), bd = 8 * DBL_EPSILON * (1 + fabs(e.d[i]));
            worst_body = fmax(worst_body, fmax(fabs(j->point_body[i] - e.n[i]) / bp,
                                               fabs(j->direction_body[i] - e.d[i]) / bd));
            check(fabs(j->point_body[i] - e.n[i]) <= bp,
                  "JSON point_body[%d] %.17g, expected %.17g", i, j->point_body[i], e.n[i]);
            check(fabs(j->direction_body[i] - e.d[i]) <= bd,
                  "JSON direction_body[%d] %.17g, expected %.17g", i, j->direction_body[i], e.d[i]);
        }
    }
    for (k = 0; k < n_dv; k++) {
        const cdspd_mavlink_debug_vect *d = &dvs[k];
        for (i = 0; i < n_json; i++)
            if (jrec[i].t == d->time_usec && jrec[i].ok) {
                expect e;
                expected(&jrec[i], &e);
                near(d->x, e.d[0], "PIPE_DIR.x", d->time_usec);
                near(d->y, e.d[1], "PIPE_DIR.y", d->time_usec);
                near(d->z, e.d[2], "PIPE_DIR.z", d->time_usec);
                break;
            }
        check(i < n_json, "DEBUG_VECT t=%llu: no JSON record with a pipe of that frame",
              (unsigned long long)d->time_usec);
    }
    /* poses without their LANDING_TARGET, those of the outage excepted */
    for (i = 0; i < n_json; i++) {
        int outage = s.out0 && jrec[i].t > s.out0 && (!s.out1 || jrec[i].t < s.out1);
        json_ok += jrec[i].ok && !outage;
    }

    printf("mavlink_rx: %ld frames (%ld heartbeats, %ld LANDING_TARGET, %ld DEBUG_VECT), %ld junk "
           "bytes, %ld bad crc, %ld unknown, %ld sequence gaps; %ld JSON frame records (%ld with a "
           "pipe), %ld targets matched; worst error %.3f of its tolerance\n",
           s.frames, s.hb, n_lt, s.dv, s.junk_bytes, s.bad_crc, s.unknown, s.seq_gaps, n_json,
           json_ok, matched, worst_rel);
    printf("mavlink_rx: JSON body frame: worst error %.3g of its bound (8 eps (1 + |x|))\n", worst_body);
    if (s.hb_gaps)
        printf("heartbeat: mean interval %.3f s, shortest %.3f s, longest %.3f s%s\n",
               s.hb_sum / (double)s.hb_gaps, s.hb_min_gap, s.hb_max_gap,
               s.out0 ? " (the outage's interval left out)" : "");
    if (o.pty_link && o.vanish_after > 0)
        printf("after the new pty: %ld LANDING_TARGET\n", s.lt_after_reopen);

    check(s.got_any && s.first_was_hb, "the first MAVLink message was not a HEARTBEAT");
    check(s.junk_bytes == 0 && s.bad_crc == 0 && s.unknown == 0,
          "%ld junk bytes, %ld bad crc, %ld unknown ids", s.junk_bytes, s.bad_crc, s.unknown);
    check(s.bad_ids == 0, "%ld frames not from system %d component %d", s.bad_ids, o.sysid,
          o.compid);
    /* the bytes still in the vanished pty are lost with it: one gap */
    check(s.seq_gaps <= (o.pty_link && o.vanish_after > 0 ? 1 : 0), "%ld sequence gaps", s.seq_gaps);
    check(s.hb >= 3, "%ld heartbeats (at least 3 expected)", s.hb);
    if (s.hb_gaps) {
        double mean = s.hb_sum / (double)s.hb_gaps;
        check(mean <= 2, "heartbeat mean interval %.3f s", mean);
        check(s.hb_max_gap <= 10, "heartbeats %.3f s apart", s.hb_max_gap);
        check((double)(s.hb - 1) <= s.hb_last - t0,
              "%ld heartbeats within %.2f s of the receiver's start: more than one per second",
              s.hb, s.hb_last - t0);
    }
    check(s.hb_not_active_after_pose == 0, "%ld heartbeats not ACTIVE after the first pose",
          s.hb_not_active_after_pose);
    check(n_lt >= o.min_targets, "%ld LANDING_TARGET, at least %ld expected", n_lt, o.min_targets);
    check(s.dv + s.cut_pair == n_lt, "%ld DEBUG_VECT for %ld LANDING_TARGET%s", s.dv, n_lt,
          s.cut_pair ? " (one cut by the vanish)" : "");
    /* no LANDING_TARGET lies in the outage (out0, out1 are the last and
     * first around it): the difference is what went missing outside it */
    printf("poses without a LANDING_TARGET: %ld\n", json_ok - matched);
    if (o.pty_link && o.vanish_after > 0)
        check(vanished == 2 && s.lt_after_reopen >= o.min_after_reopen,
              "%ld LANDING_TARGET after the device came back, at least %ld expected",
              s.lt_after_reopen, o.min_after_reopen);
    if (o.max_rate > 0 && n_lt > 1) {
        /* cdspd's limit is on its clock when it takes the pose; the camera
         * times of the first and last differ from that span by their
         * latencies' difference: allowed 0.2 s, ten times the p99 latency
         * measured on a loaded machine (20 ms). That none went missing
         * beyond what cdspd counts as held back: mavlink_e2e.sh. */
        double span = 1e-6 * (double)(lts[n_lt - 1].lt.time_usec - lts[0].lt.time_usec);
        printf("mavlink_rate: %ld LANDING_TARGET over %.2f s of camera time (%.2f per second)\n",
               n_lt, span, span > 0 ? (double)(n_lt - 1) / span : 0.0);
        check((double)(n_lt - 1) <= o.max_rate * (span + 0.2),
              "%ld LANDING_TARGET in %.2f s: more than mavlink_rate %g", n_lt, span, o.max_rate);
    }
    if (failures)
        fprintf(stderr, "mavlink_rx: %d check(s) failed\n", failures);
    else
        printf("mavlink_rx: PASS\n");
    free(jrec);
    free(lts);
    free(dvs);
    return failures ? 1 : 0;
}
