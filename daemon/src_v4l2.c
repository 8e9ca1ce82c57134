/*
 * src_v4l2.c - V4L2 capture devices through libv4l2, mmap streaming:
 * v4l2:/dev/videoN. The format is the calibration's size in v4l2.format:
 * GREY (8 bit), Y16 (16 bit little-endian), YUYV (its Y bytes are the
 * frame), or any fourcc libv4l2 can convert to YU12 (planar YUV 4:2:0,
 * whose first plane is the frame) - MJPEG webcams, Bayer sensors... "auto"
 * takes the first of GREY, Y16, YUYV the device offers natively, else YU12
 * through libv4l2's conversion.
 *
 * Grab: poll, VIDIOC_DQBUF, copy the luma into the pool's buffer, requeue.
 * A buffer flagged V4L2_BUF_FLAG_ERROR is BAD (counted). The device counts
 * as lost when an ioctl fails with ENODEV/EIO/ENXIO (unplugged), and the
 * pipeline reopens it with back-off.
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <libv4l2.h>
#include <linux/videodev2.h>

#include "log.h"

#define V4L2_MAX_BUFS 32

typedef struct {
    int fd;
    unsigned n_bufs;
    struct {
        void *start;
        size_t length;
    } bufs[V4L2_MAX_BUFS];
    uint32_t fourcc;
    int width, height;
    size_t bytesperline;
    int streaming;
} v4l2_priv;

static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    do
        r = v4l2_ioctl(fd, req, arg);
    while (r < 0 && errno == EINTR);
    return r;
}

static void fourcc_text(uint32_t f, char out[5])
{
    int i;
    for (i = 0; i < 4; i++) {
        char ch = (char)((f >> (8 * i)) & 0xFF);
        out[i] = ch >= 32 && ch < 127 ? ch : '?';
    }
    out[4] = 0;
}

static int lost_errno(int e)
{
    return e == ENODEV || e == EIO || e == ENXIO || e == EBADF;
}

static void close_dev(v4l2_priv *p)
{
    unsigned i;
    if (p->fd < 0)
        return;
    if (p->streaming) {
        enum v4l2_buf_type t = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        xioctl(p->fd, VIDIOC_STREAMOFF, &t);
        p->streaming = 0;
    }
    for (i = 0; i < p->n_bufs; i++)
        if (p->bufs[i].start && p->bufs[i].start != MAP_FAILED)
            v4l2_munmap(p->bufs[i].start, p->bufs[i].length);
    p->n_bufs = 0;
    v4l2_close(p->fd);
    p->fd = -1;
}

static int fail(v4l2_priv *p, char *err, size_t errlen, int rc, const char *fmt, const char *dev,
                const char *what)
{
    snprintf(err, errlen, fmt, dev, what);
    close_dev(p);
    return rc;
}

/* Does the device offer this format natively (not by libv4l2's conversion)? */
static int offers(int fd, uint32_t fourcc)
{
    struct v4l2_fmtdesc d;
    unsigned i;
    for (i = 0;; i++) {
        memset(&d, 0, sizeof d);
        d.index = i;
        d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(fd, VIDIOC_ENUM_FMT, &d) < 0)
            return 0;
        if (d.pixelformat == fourcc && !(d.flags & V4L2_FMT_FLAG_EMULATED))
            return 1;
    }
}

static int v4l2src_open(cdspd_source *s, char *err, size_t errlen)
{
    v4l2_priv *p = s->priv;
    const cdspd_config *c = s->cfg;
    const char *dev = s->arg;
    struct v4l2_capability cap;
    struct v4l2_format f;
    struct v4l2_requestbuffers req;
    enum v4l2_buf_type t = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    uint32_t want = 0, caps;
    char fc[5], got[5];
    unsigned i;

    p->fd = v4l2_open(dev, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (p->fd < 0)
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: cannot open %s: %s", dev, strerror(errno));
    memset(&cap, 0, sizeof cap);
    if (xioctl(p->fd, VIDIOC_QUERYCAP, &cap) < 0)
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: VIDIOC_QUERYCAP: %s", dev,
                    strerror(errno));
    caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING))
        return fail(p, err, errlen, CDSPD_OPEN_FATAL, "v4l2: %s: %s", dev,
                    "not a video capture device with streaming I/O");

    if (!strcmp(c->v4l2.format, "auto")) {
        static const uint32_t pref[] = {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_Y16, V4L2_PIX_FMT_YUYV};
        for (i = 0; i < 3 && !want; i++)
            if (offers(p->fd, pref[i]))
                want = pref[i];
        if (!want)
            want = V4L2_PIX_FMT_YUV420; /* libv4l2 converts into it */
    } else {
        const char *k = c->v4l2.format;
        size_t l = strlen(k);
        if (l < 1 || l > 4)
            return fail(p, err, errlen, CDSPD_OPEN_FATAL, "key 'v4l2.format': '%s' %s", k,
                        "is not a fourcc (GREY, Y16, YUYV, YU12, ...) or auto");
        want = v4l2_fourcc(k[0], l > 1 ? k[1] : ' ', l > 2 ? k[2] : ' ', l > 3 ? k[3] : ' ');
    }
    fourcc_text(want, fc);
    memset(&f, 0, sizeof f);
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = (unsigned)c->cam.width;
    f.fmt.pix.height = (unsigned)c->cam.height;
    f.fmt.pix.pixelformat = want;
    f.fmt.pix.field = V4L2_FIELD_ANY;
    if (xioctl(p->fd, VIDIOC_S_FMT, &f) < 0)
        return fail(p, err, errlen, CDSPD_OPEN_FATAL, "v4l2: %s: VIDIOC_S_FMT: %s", dev, strerror(errno));
    fourcc_text(f.fmt.pix.pixelformat, got);
    if (f.fmt.pix.pixelformat != want || (int)f.fmt.pix.width != c->cam.width ||
        (int)f.fmt.pix.height != c->cam.height) {
        snprintf(err, errlen, "v4l2: %s delivers %ux%u '%s' when asked for %dx%d '%s' (the "
                 "calibration's size; key v4l2.format)", dev, f.fmt.pix.width, f.fmt.pix.height, got,
                 c->cam.width, c->cam.height, fc);
        close_dev(p);
        return CDSPD_OPEN_FATAL;
    }
    if (want != V4L2_PIX_FMT_GREY && want != V4L2_PIX_FMT_Y16 && want != V4L2_PIX_FMT_YUYV &&
        want != V4L2_PIX_FMT_YUV420) {
        snprintf(err, errlen, "key 'v4l2.format': '%s' is not read by cdspd (GREY, Y16, YUYV, YU12)", fc);
        close_dev(p);
        return CDSPD_OPEN_FATAL;
    }
    p->fourcc = want;
    p->width = c->cam.width;
    p->height = c->cam.height;
    p->bytesperline = f.fmt.pix.bytesperline;
    if (!p->bytesperline)
        p->bytesperline = (size_t)p->width * (want == V4L2_PIX_FMT_GREY || want == V4L2_PIX_FMT_YUV420 ? 1 : 2);

    if (c->v4l2.frame_rate > 0) {
        struct v4l2_streamparm sp;
        memset(&sp, 0, sizeof sp);
        sp.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        sp.parm.capture.timeperframe.numerator = 1000;
        sp.parm.capture.timeperframe.denominator = (unsigned)(c->v4l2.frame_rate * 1000 + 0.5);
        if (xioctl(p->fd, VIDIOC_S_PARM, &sp) < 0)
            LOG_W(SOURCE, "v4l2: %s: cannot set %g fps: %s", dev, c->v4l2.frame_rate, strerror(errno));
    }

    memset(&req, 0, sizeof req);
    req.count = (unsigned)c->v4l2.buffers;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(p->fd, VIDIOC_REQBUFS, &req) < 0 || req.count < 2)
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: VIDIOC_REQBUFS: %s", dev,
                    req.count < 2 ? "fewer than 2 buffers" : strerror(errno));
    if (req.count > V4L2_MAX_BUFS)
        req.count = V4L2_MAX_BUFS;
    for (i = 0; i < req.count; i++) {
        struct v4l2_buffer b;
        memset(&b, 0, sizeof b);
        b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        b.memory = V4L2_MEMORY_MMAP;
        b.index = i;
        if (xioctl(p->fd, VIDIOC_QUERYBUF, &b) < 0)
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: VIDIOC_QUERYBUF: %s", dev,
                        strerror(errno));
        p->bufs[i].length = b.length;
        p->bufs[i].start = v4l2_mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, p->fd, b.m.offset);
        p->n_bufs = i + 1;
        if (p->bufs[i].start == MAP_FAILED)
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: mmap: %s", dev, strerror(errno));
        if (xioctl(p->fd, VIDIOC_QBUF, &b) < 0)
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: VIDIOC_QBUF: %s", dev,
                        strerror(errno));
    }
    if (xioctl(p->fd, VIDIOC_STREAMON, &t) < 0)
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "v4l2: %s: VIDIOC_STREAMON: %s", dev,
                    strerror(errno));
    p->streaming = 1;
    LOG_I(SOURCE, "v4l2: %s (%s, driver %s): %dx%d '%s'%s, %u buffers", dev, (const char *)cap.card,
          (const char *)cap.driver, p->width, p->height, fc,
          offers(p->fd, want) ? "" : " converted by libv4l2", p->n_bufs);
    return CDSPD_OPEN_OK;
}

static int v4l2src_grab(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen)
{
    v4l2_priv *p = s->priv;
    struct pollfd pfd;
    struct v4l2_buffer b;
    const uint8_t *src;
    size_t need;
    int r = CDSPD_GRAB_FRAME, y, x;

    pfd.fd = p->fd;
    pfd.events = POLLIN;
    pfd.revents = 0;
    r = poll(&pfd, 1, timeout_ms);
    if (r < 0 && errno != EINTR) {
        snprintf(err, errlen, "v4l2: %s: poll: %s", s->arg, strerror(errno));
        return CDSPD_GRAB_LOST;
    }
    if (r <= 0)
        return CDSPD_GRAB_TIMEOUT;
    if (pfd.revents & (POLLERR | POLLHUP | POLLNVAL)) {
        /* vivid and USB devices report a removal this way; a plain POLLERR
         * without data can also be a stream that is not running */
        if (!(pfd.revents & POLLIN)) {
            snprintf(err, errlen, "v4l2: %s: the device reports an error (unplugged?)", s->arg);
            return CDSPD_GRAB_LOST;
        }
    }
    memset(&b, 0, sizeof b);
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(p->fd, VIDIOC_DQBUF, &b) < 0) {
        if (errno == EAGAIN)
            return CDSPD_GRAB_TIMEOUT;
        snprintf(err, errlen, "v4l2: %s: VIDIOC_DQBUF: %s", s->arg, strerror(errno));
        return lost_errno(errno) ? CDSPD_GRAB_LOST : CDSPD_GRAB_BAD;
    }
    r = CDSPD_GRAB_FRAME;
    src = p->bufs[b.index].start;
    need = p->bytesperline * (size_t)(p->height - 1) +
           (size_t)p->width * (p->fourcc == V4L2_PIX_FMT_GREY || p->fourcc == V4L2_PIX_FMT_YUV420 ? 1 : 2);
    if (b.flags & V4L2_BUF_FLAG_ERROR) {
        snprintf(err, errlen, "v4l2: %s: frame %u flagged as corrupted by the driver", s->arg, b.sequence);
        r = CDSPD_GRAB_BAD;
    } else if (b.index >= p->n_bufs || b.bytesused < need || b.bytesused > p->bufs[b.index].length) {
        snprintf(err, errlen, "v4l2: %s: frame %u has %u bytes, %zu expected", s->arg, b.sequence,
                 b.bytesused, need);
        r = CDSPD_GRAB_BAD;
    } else {
        int bits = p->fourcc == V4L2_PIX_FMT_Y16 ? 16 : 8;
        size_t row = (size_t)p->width * (bits > 8 ? 2 : 1);
        if (row * (size_t)p->height > f->cap) {
            snprintf(err, errlen, "v4l2: %s: frame larger than the pool's buffers", s->arg);
            r = CDSPD_GRAB_BAD;
        } else {
            for (y = 0; y < p->height; y++) {
                const uint8_t *in = src + (size_t)y * p->bytesperline;
                uint8_t *out = f->data + (size_t)y * row;
                if (p->fourcc == V4L2_PIX_FMT_YUYV) {
                    for (x = 0; x < p->width; x++)
                        out[x] = in[2 * x];
                } else if (p->fourcc == V4L2_PIX_FMT_Y16) {
                    /* little-endian samples to native order */
                    uint16_t *o16 = (uint16_t *)(void *)out;
                    for (x = 0; x < p->width; x++)
                        o16[x] = (uint16_t)(in[2 * x] | in[2 * x + 1] << 8);
                } else {
                    memcpy(out, in, row);
                }
            }
            f->width = p->width;
            f->height = p->height;
            f->bits = bits;
            f->stride = row;
            f->frame_id = b.sequence;
            f->t_camera_us = (uint64_t)b.timestamp.tv_sec * 1000000u + (uint64_t)b.timestamp.tv_usec;
        }
    }
    if (xioctl(p->fd, VIDIOC_QBUF, &b) < 0) {
        snprintf(err, errlen, "v4l2: %s: VIDIOC_QBUF: %s", s->arg, strerror(errno));
        return CDSPD_GRAB_LOST;
    }
    return r;
}

static void v4l2src_close(cdspd_source *s)
{
    close_dev(s->priv);
}

static void v4l2src_destroy(cdspd_source *s)
{
    close_dev(s->priv);
}

static const cdspd_source_ops v4l2_ops = {"v4l2", v4l2src_open, v4l2src_grab, v4l2src_close,
                                          v4l2src_destroy};

int cdspd_src_v4l2_init(cdspd_source *s, char *err, size_t errlen)
{
    if (cdspd_source_init_priv(s, &v4l2_ops, sizeof(v4l2_priv), err, errlen))
        return -1;
    ((v4l2_priv *)s->priv)->fd = -1;
    return 0;
}

int cdspd_src_v4l2_list(FILE *out, char *err, size_t errlen)
{
    glob_t g;
    size_t i;
    int n = 0;
    (void)err;
    (void)errlen;
    memset(&g, 0, sizeof g);
    if (glob("/dev/video*", 0, NULL, &g) != 0) {
        globfree(&g);
        return 0;
    }
    for (i = 0; i < g.gl_pathc; i++) {
        struct v4l2_capability cap;
        int fd = open(g.gl_pathv[i], O_RDWR | O_NONBLOCK | O_CLOEXEC);
        uint32_t caps;
        if (fd < 0)
            continue;
        memset(&cap, 0, sizeof cap);
        if (xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0) {
            caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
            /* a metadata or output node of the same camera is not a source */
            if ((caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING)) {
                fprintf(out, "v4l2:%-32s %s (driver %s, %s)\n", g.gl_pathv[i], (const char *)cap.card,
                        (const char *)cap.driver, (const char *)cap.bus_info);
                n++;
            }
        }
        close(fd);
    }
    globfree(&g);
    return n;
}
