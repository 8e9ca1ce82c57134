/*
 * v4l2_loop - frames written to vivid's output node come back pixel-exact
 * from its capture node (run inside the VM of tests/vm/run-in-vm.sh).
 *
 * Both nodes are driven through libv4l2 with mmap streaming, 640x480 GREY.
 * The program shows N distinct pseudo-random patterns one after the other:
 * every free output buffer is refilled with the current pattern, and the
 * pattern advances as soon as it is seen on the capture node. vivid copies
 * whatever output buffer is on screen at each capture tick, so a pattern
 * repeats while the output queue drains, and before the first output frame
 * (or whenever the output queue runs dry on a loaded machine) the capture
 * node shows vivid's own test pattern instead. The check:
 *   - every pattern 0..N-1 comes back, in order, byte for byte;
 *   - a captured frame is either an exact pattern (the current one or the
 *     one before it, still queued) or unrelated to all of them (vivid's test
 *     pattern: it agrees with a random pattern on about 1/256 of the
 *     pixels); a frame that agrees with some pattern on more than half its
 *     pixels but not all is a corrupted copy and fails the test.
 *
 * Usage: v4l2_loop [-c CAPTURE] [-o OUTPUT] [-n N] [-t SECONDS] [-v]
 *   defaults: $CDSP_VIVID_CAP or /dev/video0, $CDSP_VIVID_OUT or
 *   /dev/video1, N = 12, 60 s.
 * Exit status: 0 all patterns came back exactly, 1 they did not (or the
 * devices misbehaved), 2 usage error.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <libv4l2.h>
#include <linux/videodev2.h>

#include "cdsp_host.h"

#define LOOP_W 640
#define LOOP_H 480
#define LOOP_MAX_BUFS 8
#define LOOP_MAX_PATTERNS 64

typedef struct {
    void *start;
    size_t length;
} loop_buf;

typedef struct {
    const char *path;
    int fd;
    enum v4l2_buf_type type;
    unsigned n_bufs;
    loop_buf bufs[LOOP_MAX_BUFS];
    size_t stride;      /* bytesperline */
    size_t sizeimage;
    uint32_t field;     /* negotiated field order */
    int streaming;
} loop_dev;

static int verbose;

/* ioctl through libv4l2, retried when a signal interrupts it. */
static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    do
        r = v4l2_ioctl(fd, req, arg);
    while (r == -1 && errno == EINTR);
    return r;
}

/* Pixel (x, y) of pattern k: a 32-bit integer hash (lowbias32, C. Wellons)
 * of the pixel index and the pattern number, so two patterns agree on about
 * 1/256 of their pixels and any shift, swap or stale row shows. */
static uint8_t pattern_pixel(unsigned k, unsigned x, unsigned y)
{
    uint32_t h = (uint32_t)(y * LOOP_W + x) * 0x9E3779B1u + (uint32_t)(k + 1) * 0x7FEB352Du;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return (uint8_t)h;
}

static int open_dev(loop_dev *d, const char *path, enum v4l2_buf_type type)
{
    struct v4l2_capability cap;
    uint32_t caps, want;

    d->path = path;
    d->type = type;
    d->fd = v4l2_open(path, O_RDWR | O_NONBLOCK);
    if (d->fd < 0) {
        fprintf(stderr, "v4l2_loop: %s: cannot open: %s\n", path, strerror(errno));
        return -1;
    }
    memset(&cap, 0, sizeof cap);
    if (xioctl(d->fd, VIDIOC_QUERYCAP, &cap) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_QUERYCAP: %s\n", path, strerror(errno));
        return -1;
    }
    caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    want = V4L2_CAP_STREAMING |
           (type == V4L2_BUF_TYPE_VIDEO_CAPTURE ? V4L2_CAP_VIDEO_CAPTURE : V4L2_CAP_VIDEO_OUTPUT);
    if ((caps & want) != want) {
        fprintf(stderr, "v4l2_loop: %s (%s): not a streaming video %s device\n", path,
                (const char *)cap.card,
                type == V4L2_BUF_TYPE_VIDEO_CAPTURE ? "capture" : "output");
        return -1;
    }
    if (verbose)
        printf("%s: %s, driver %s\n", path, (const char *)cap.card, (const char *)cap.driver);
    return 0;
}

/* 640x480 GREY on the device; the driver's answer is checked, not assumed. */
static int set_format(loop_dev *d, struct v4l2_format *got)
{
    struct v4l2_format f;

    memset(&f, 0, sizeof f);
    f.type = d->type;
    f.fmt.pix.width = LOOP_W;
    f.fmt.pix.height = LOOP_H;
    f.fmt.pix.pixelformat = V4L2_PIX_FMT_GREY;
    f.fmt.pix.field = V4L2_FIELD_ANY;
    if (xioctl(d->fd, VIDIOC_S_FMT, &f) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_S_FMT: %s\n", d->path, strerror(errno));
        return -1;
    }
    if (f.fmt.pix.width != LOOP_W || f.fmt.pix.height != LOOP_H ||
        f.fmt.pix.pixelformat != V4L2_PIX_FMT_GREY || f.fmt.pix.bytesperline < LOOP_W ||
        f.fmt.pix.sizeimage < (uint32_t)f.fmt.pix.bytesperline * LOOP_H) {
        fprintf(stderr, "v4l2_loop: %s: asked for %dx%d GREY, the driver set %ux%u "
                "fourcc 0x%08x, %u bytes per line, %u bytes\n", d->path, LOOP_W, LOOP_H,
                f.fmt.pix.width, f.fmt.pix.height, f.fmt.pix.pixelformat,
                f.fmt.pix.bytesperline, f.fmt.pix.sizeimage);
        return -1;
    }
    d->stride = f.fmt.pix.bytesperline;
    d->sizeimage = f.fmt.pix.sizeimage;
    d->field = f.fmt.pix.field;
    *got = f;
    return 0;
}

static int map_buffers(loop_dev *d, unsigned count)
{
    struct v4l2_requestbuffers req;
    unsigned i;

    memset(&req, 0, sizeof req);
    req.count = count;
    req.type = d->type;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(d->fd, VIDIOC_REQBUFS, &req) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_REQBUFS: %s\n", d->path, strerror(errno));
        return -1;
    }
    if (req.count < 2 || req.count > LOOP_MAX_BUFS) {
        fprintf(stderr, "v4l2_loop: %s: the driver granted %u buffers (need 2..%d)\n", d->path,
                req.count, LOOP_MAX_BUFS);
        return -1;
    }
    for (i = 0; i < req.count; i++) {
        struct v4l2_buffer b;
        memset(&b, 0, sizeof b);
        b.type = d->type;
        b.memory = V4L2_MEMORY_MMAP;
        b.index = i;
        if (xioctl(d->fd, VIDIOC_QUERYBUF, &b) < 0) {
            fprintf(stderr, "v4l2_loop: %s: VIDIOC_QUERYBUF %u: %s\n", d->path, i, strerror(errno));
            return -1;
        }
        if (b.length < d->sizeimage) {
            fprintf(stderr, "v4l2_loop: %s: buffer %u holds %u bytes, the format needs %zu\n",
                    d->path, i, b.length, d->sizeimage);
            return -1;
        }
        d->bufs[i].length = b.length;
        d->bufs[i].start = v4l2_mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, d->fd,
                                     (int64_t)b.m.offset);
        if (d->bufs[i].start == MAP_FAILED) {
            d->bufs[i].start = NULL;
            fprintf(stderr, "v4l2_loop: %s: mmap of buffer %u: %s\n", d->path, i, strerror(errno));
            return -1;
        }
        d->n_bufs = i + 1;
    }
    return 0;
}

static void close_dev(loop_dev *d)
{
    unsigned i;
    if (d->fd < 0)
        return;
    if (d->streaming) {
        int t = (int)d->type;
        xioctl(d->fd, VIDIOC_STREAMOFF, &t);
    }
    for (i = 0; i < d->n_bufs; i++)
        if (d->bufs[i].start)
            v4l2_munmap(d->bufs[i].start, d->bufs[i].length);
    v4l2_close(d->fd);
    d->fd = -1;
}

static void fill_pattern(const loop_dev *d, unsigned index, unsigned k)
{
    uint8_t *p = d->bufs[index].start;
    unsigned x, y;
    for (y = 0; y < LOOP_H; y++)
        for (x = 0; x < LOOP_W; x++)
            p[(size_t)y * d->stride + x] = pattern_pixel(k, x, y);
}

static int queue(loop_dev *d, unsigned index, uint32_t bytesused)
{
    struct v4l2_buffer b;
    memset(&b, 0, sizeof b);
    b.type = d->type;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = index;
    b.bytesused = bytesused;
    if (d->type == V4L2_BUF_TYPE_VIDEO_OUTPUT)
        b.field = d->field;
    if (xioctl(d->fd, VIDIOC_QBUF, &b) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_QBUF %u: %s\n", d->path, index, strerror(errno));
        return -1;
    }
    return 0;
}

/* 1 and the buffer in *b, 0 when none is ready, -1 on error. */
static int dequeue(loop_dev *d, struct v4l2_buffer *b)
{
    memset(b, 0, sizeof *b);
    b->type = d->type;
    b->memory = V4L2_MEMORY_MMAP;
    if (xioctl(d->fd, VIDIOC_DQBUF, b) < 0) {
        if (errno == EAGAIN)
            return 0;
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_DQBUF: %s\n", d->path, strerror(errno));
        return -1;
    }
    if (b->index >= d->n_bufs) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_DQBUF returned buffer %u of %u\n", d->path,
                b->index, d->n_bufs);
        return -1;
    }
    return 1;
}

/* Pixels of the captured frame equal to pattern k; stops counting early
 * once the frame cannot reach `need` any more. */
static long agreement(const uint8_t *img, size_t stride, unsigned k, long need)
{
    long same = 0, left = (long)LOOP_W * LOOP_H;
    unsigned x, y;
    for (y = 0; y < LOOP_H; y++) {
        for (x = 0; x < LOOP_W; x++)
            same += img[(size_t)y * stride + x] == pattern_pixel(k, x, y);
        left -= LOOP_W;
        if (same + left < need)
            return same;
    }
    return same;
}

/* Bounding box of the pixels where the frame differs from pattern k, for
 * the failure message (an OSD overlay, a shifted row... each has a shape). */
static void diff_box(const uint8_t *img, size_t stride, unsigned k, unsigned box[4])
{
    unsigned x, y;
    box[0] = LOOP_W; box[1] = LOOP_H; box[2] = 0; box[3] = 0;
    for (y = 0; y < LOOP_H; y++)
        for (x = 0; x < LOOP_W; x++)
            if (img[(size_t)y * stride + x] != pattern_pixel(k, x, y)) {
                if (x < box[0]) box[0] = x;
                if (y < box[1]) box[1] = y;
                if (x > box[2]) box[2] = x;
                if (y > box[3]) box[3] = y;
            }
}

static void usage(void)
{
    fprintf(stderr, "usage: v4l2_loop [-c CAPTURE] [-o OUTPUT] [-n N (1..%d)] [-t SECONDS] [-v]\n",
            LOOP_MAX_PATTERNS);
    exit(2);
}

int main(int argc, char **argv)
{
    const char *cap_path = getenv("CDSP_VIVID_CAP"), *out_path = getenv("CDSP_VIVID_OUT");
    long n_patterns = 12, timeout_s = 60;
    loop_dev cap = {0}, out = {0};
    struct v4l2_format fcap, fout;
    unsigned cur = 0, i, seen = 0;
    long captured = 0, repeats = 0, foreign = 0, foreign_after = 0;
    const long all = (long)LOOP_W * LOOP_H;
    int rc = 1, opt, t;
    double t0, deadline;

    while ((opt = getopt(argc, argv, "c:o:n:t:v")) != -1) {
        char *end;
        switch (opt) {
        case 'c': cap_path = optarg; break;
        case 'o': out_path = optarg; break;
        case 'n':
            n_patterns = strtol(optarg, &end, 10);
            if (*end || n_patterns < 1 || n_patterns > LOOP_MAX_PATTERNS)
                usage();
            break;
        case 't':
            timeout_s = strtol(optarg, &end, 10);
            if (*end || timeout_s < 1)
                usage();
            break;
        case 'v': verbose = 1; break;
        default: usage();
        }
    }
    if (optind != argc)
        usage();
    if (!cap_path)
        cap_path = "/dev/video0";
    if (!out_path)
        out_path = "/dev/video1";
    cap.fd = out.fd = -1;

    if (open_dev(&cap, cap_path, V4L2_BUF_TYPE_VIDEO_CAPTURE) < 0 ||
        open_dev(&out, out_path, V4L2_BUF_TYPE_VIDEO_OUTPUT) < 0 ||
        set_format(&cap, &fcap) < 0 || set_format(&out, &fout) < 0)
        goto done;
    if (fcap.fmt.pix.field != fout.fmt.pix.field) {
        fprintf(stderr, "v4l2_loop: field order differs: capture %u, output %u (no loop)\n",
                fcap.fmt.pix.field, fout.fmt.pix.field);
        goto done;
    }
    if (map_buffers(&cap, 4) < 0 || map_buffers(&out, 4) < 0)
        goto done;

    for (i = 0; i < cap.n_bufs; i++)
        if (queue(&cap, i, 0) < 0)
            goto done;
    for (i = 0; i < out.n_bufs; i++) {
        fill_pattern(&out, i, 0);
        if (queue(&out, i, (uint32_t)out.sizeimage) < 0)
            goto done;
    }
    t = (int)cap.type;
    if (xioctl(cap.fd, VIDIOC_STREAMON, &t) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_STREAMON: %s\n", cap.path, strerror(errno));
        goto done;
    }
    cap.streaming = 1;
    t = (int)out.type;
    if (xioctl(out.fd, VIDIOC_STREAMON, &t) < 0) {
        fprintf(stderr, "v4l2_loop: %s: VIDIOC_STREAMON: %s\n", out.path, strerror(errno));
        goto done;
    }
    out.streaming = 1;

    t0 = cdsp_host_now_s();
    deadline = t0 + (double)timeout_s;
    while (seen < (unsigned)n_patterns) {
        struct pollfd pfd[2];
        struct v4l2_buffer b;
        int r;

        if (cdsp_host_now_s() > deadline) {
            fprintf(stderr, "v4l2_loop: timeout after %ld s waiting for pattern %u of %ld\n",
                    timeout_s, cur, n_patterns);
            goto done;
        }
        pfd[0].fd = cap.fd;
        pfd[0].events = POLLIN;
        pfd[1].fd = out.fd;
        pfd[1].events = POLLOUT;
        pfd[0].revents = pfd[1].revents = 0;
        r = poll(pfd, 2, 1000);
        if (r < 0 && errno != EINTR) {
            fprintf(stderr, "v4l2_loop: poll: %s\n", strerror(errno));
            goto done;
        }
        if (r <= 0)
            continue;   /* a timeout is not an error: the deadline decides */
        if (pfd[0].revents & POLLERR || pfd[1].revents & POLLERR) {
            fprintf(stderr, "v4l2_loop: poll reports an error on %s\n",
                        pfd[0].revents & POLLERR ? cap.path : out.path);
            goto done;
        }

        /* One buffer per side and readiness: libv4l2 logs every DQBUF that
         * finds nothing ready, so never dequeue to EAGAIN. */
        /* Output side: refill the displayed buffer with the current pattern. */
        if ((pfd[1].revents & POLLOUT) && (r = dequeue(&out, &b)) != 0) {
            if (r < 0)
                goto done;
            fill_pattern(&out, b.index, cur);
            if (queue(&out, b.index, (uint32_t)out.sizeimage) < 0)
                goto done;
        }

        /* Capture side: classify the frame. */
        if ((pfd[0].revents & POLLIN) && (r = dequeue(&cap, &b)) != 0) {
            const uint8_t *img = cap.bufs[b.index].start;
            long best = 0, s;
            unsigned k, best_k = 0;
            int match = -1;

            if (r < 0)
                goto done;
            captured++;
            if (b.flags & V4L2_BUF_FLAG_ERROR) {
                fprintf(stderr, "v4l2_loop: capture frame %ld (sequence %u) flagged as an error\n",
                        captured, b.sequence);
                goto done;
            }
            if (b.bytesused != 0 && b.bytesused < cap.sizeimage) {
                fprintf(stderr, "v4l2_loop: capture frame %ld holds %u bytes, expected %zu\n",
                        captured, b.bytesused, cap.sizeimage);
                goto done;
            }
            for (k = 0; k < (unsigned)n_patterns && match < 0; k++) {
                s = agreement(img, cap.stride, k, all / 2);
                if (s == all)
                    match = (int)k;
                if (s > best) {
                    best = s;
                    best_k = k;
                }
            }
            if (match < 0) {
                if (best > all / 2) {
                    unsigned box[4];
                    diff_box(img, cap.stride, best_k, box);
                    fprintf(stderr, "v4l2_loop: capture frame %ld (sequence %u) is a corrupted copy of "
                            "pattern %u: %ld of %ld pixels differ, within x %u..%u, y %u..%u\n",
                            captured, b.sequence, best_k, all - best, all, box[0], box[2], box[1],
                            box[3]);
                    goto done;
                }
                foreign++;
                if (seen > 0)
                    foreign_after++;
                if (verbose)
                    printf("frame %ld: not looped (vivid's own pattern)\n", captured);
            } else if ((unsigned)match == cur) {
                if (verbose)
                    printf("frame %ld: pattern %d after %.3f s\n", captured, match, cdsp_host_now_s() - t0);
                seen++;
                if (cur + 1 < (unsigned)n_patterns)
                    cur++;
            } else if (cur > 0 && (unsigned)match == cur - 1) {
                repeats++;  /* still queued on the output side */
            } else {
                fprintf(stderr, "v4l2_loop: capture frame %ld is pattern %d while pattern %u was "
                        "expected (out of order)\n", captured, match, cur);
                goto done;
            }
            if (queue(&cap, b.index, 0) < 0)
                goto done;
        }
    }
    printf("v4l2_loop: %u of %ld patterns came back pixel-exact and in order through %s -> %s "
           "in %.2f s (%ld frames captured: %ld repeats, %ld not looped, %ld of them after the "
           "first looped frame)\n", seen, n_patterns, out.path, cap.path, cdsp_host_now_s() - t0, captured,
           repeats, foreign, foreign_after);
    rc = 0;
done:
    close_dev(&out);
    close_dev(&cap);
    if (rc)
        fprintf(stderr, "v4l2_loop: FAIL\n");
    return rc;
}
