/*
 * v4l2_feed - writes simulated pipe frames into a V4L2 output device (the
 * vivid driver's output node, looped back to its capture node) for the
 * daemon's V4L2 test in the VM (tests/daemon/vm_v4l2.sh). The frames are
 * cdspd's own simulated ones (daemon/sim_path.h: the sim.* keys given with
 * --set), rendered once at start; each is shown for --hold output frames,
 * then the next, in a loop. The output queue is kept full, so vivid never
 * falls back to its own test pattern while this runs.
 *
 * Usage: v4l2_feed -o DEVICE --calib CAM.yaml [--set KEY=VALUE ...]
 *        [--fourcc GREY|YUYV] [--hold N] [--duration S]
 * Prints "v4l2_feed: streaming" once the first frames are queued. Exit
 * status 0, 1 on a device error, 2 usage.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
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

#include "cdsp.h"
#include "cdsp_host.h"
#include "config.h"
#include "sim_path.h"

static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    do
        r = v4l2_ioctl(fd, req, arg);
    while (r < 0 && errno == EINTR);
    return r;
}

int main(int argc, char **argv)
{
    static const struct option lo[] = {{"output", 1, NULL, 'o'}, {"calib", 1, NULL, 'c'},
                                       {"set", 1, NULL, 's'},    {"fourcc", 1, NULL, 'f'},
                                       {"hold", 1, NULL, 'H'},   {"duration", 1, NULL, 'd'},
                                       {NULL, 0, NULL, 0}};
    static cdspd_config cfg;
    const char *dev = NULL, *calib = NULL;
    char err[1024];
    uint32_t fourcc = V4L2_PIX_FMT_GREY;
    int hold = 10, ch, fd, k, nbufs, frames, w, h;
    double duration = 60;
    struct v4l2_format f;
    struct v4l2_requestbuffers req;
    enum v4l2_buf_type t = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    struct {
        void *start;
        size_t length;
    } bufs[8];
    uint8_t *ring;
    size_t bpl, sizeimage;
    unsigned long shown = 0;
    double t0;

    cdspd_config_defaults(&cfg);
    while ((ch = getopt_long(argc, argv, "o:", lo, NULL)) != -1) {
        switch (ch) {
        case 'o': dev = optarg; break;
        case 'c': calib = optarg; break;
        case 's': {
            char kv[1200], *eq;
            snprintf(kv, sizeof kv, "%s", optarg);
            eq = strchr(kv, '=');
            if (!eq || (*eq = 0, cdspd_config_set(&cfg, kv, eq + 1, "--set", err, sizeof err))) {
                fprintf(stderr, "v4l2_feed: --set %s: %s\n", optarg, eq ? err : "expected K=V");
                return 2;
            }
            break;
        }
        case 'f':
            if (!strcmp(optarg, "GREY"))
                fourcc = V4L2_PIX_FMT_GREY;
            else if (!strcmp(optarg, "YUYV"))
                fourcc = V4L2_PIX_FMT_YUYV;
            else
                return 2;
            break;
        case 'H': hold = atoi(optarg); break;
        case 'd': duration = atof(optarg); break;
        default: return 2;
        }
    }
    if (!dev || !calib || hold < 1) {
        fprintf(stderr, "usage: v4l2_feed -o DEVICE --calib CAM.yaml [--set K=V] [--fourcc GREY|YUYV] "
                "[--hold N] [--duration S]\n");
        return 2;
    }
    {
        cdsp_host_err herr;
        if (cdsp_host_calib_read(calib, &cfg.cam, &herr)) {
            fprintf(stderr, "v4l2_feed: %s\n", herr.msg);
            return 2;
        }
    }
    if (!(cfg.radius > 0))
        cfg.radius = 10;
    w = cfg.cam.width;
    h = cfg.cam.height;
    frames = cfg.sim.frames;
    ring = malloc((size_t)frames * (size_t)w * (size_t)h);
    if (!ring)
        return 1;
    {
        size_t nscr = cdsp_render_scratch_size(w, h);
        float *scr = malloc(nscr * sizeof *scr);
        for (k = 0; k < frames; k++) {
            cdsp_scene sc;
            cdsp_rng rng;
            cdspd_sim_scene(&cfg, k, &sc);
            cdsp_rng_seed(&rng, cfg.sim.seed, (uint64_t)k);
            if (!scr || cdsp_render(&sc, &cfg.cam, ring + (size_t)k * w * h, 0, 8, scr, nscr, &rng)) {
                fprintf(stderr, "v4l2_feed: rendering failed\n");
                return 1;
            }
        }
        free(scr);
    }
    fd = v4l2_open(dev, O_RDWR | O_NONBLOCK);
    if (fd < 0) {
        fprintf(stderr, "v4l2_feed: %s: %s\n", dev, strerror(errno));
        return 1;
    }
    memset(&f, 0, sizeof f);
    f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    f.fmt.pix.width = (unsigned)w;
    f.fmt.pix.height = (unsigned)h;
    f.fmt.pix.pixelformat = fourcc;
    f.fmt.pix.field = V4L2_FIELD_ANY;
    if (xioctl(fd, VIDIOC_S_FMT, &f) < 0 || (int)f.fmt.pix.width != w || (int)f.fmt.pix.height != h ||
        f.fmt.pix.pixelformat != fourcc) {
        fprintf(stderr, "v4l2_feed: %s: cannot set %dx%d: %s\n", dev, w, h, strerror(errno));
        return 1;
    }
    bpl = f.fmt.pix.bytesperline;
    sizeimage = f.fmt.pix.sizeimage;
    memset(&req, 0, sizeof req);
    req.count = 4;
    req.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd, VIDIOC_REQBUFS, &req) < 0 || req.count < 2) {
        fprintf(stderr, "v4l2_feed: REQBUFS: %s\n", strerror(errno));
        return 1;
    }
    nbufs = req.count > 8 ? 8 : (int)req.count;
    t0 = cdsp_host_now_s();
    for (k = 0; k < nbufs; k++) {
        struct v4l2_buffer b;
        memset(&b, 0, sizeof b);
        b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        b.memory = V4L2_MEMORY_MMAP;
        b.index = (unsigned)k;
        if (xioctl(fd, VIDIOC_QUERYBUF, &b) < 0)
            return 1;
        bufs[k].length = b.length;
        bufs[k].start = v4l2_mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
        if (bufs[k].start == MAP_FAILED)
            return 1;
    }
    for (;;) {
        struct v4l2_buffer b;
        const uint8_t *img = ring + (size_t)((shown / (unsigned long)hold) % (unsigned long)frames) * w * h;
        int y, x;
        memset(&b, 0, sizeof b);
        b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        b.memory = V4L2_MEMORY_MMAP;
        if (shown < (unsigned long)nbufs) {
            b.index = (unsigned)shown; /* the first round: every buffer once */
        } else {
            struct pollfd p = {fd, POLLOUT, 0};
            if (cdsp_host_now_s() - t0 > duration)
                break;
            if (poll(&p, 1, 200) <= 0)
                continue;
            if (xioctl(fd, VIDIOC_DQBUF, &b) < 0) {
                if (errno == EAGAIN)
                    continue;
                fprintf(stderr, "v4l2_feed: DQBUF: %s\n", strerror(errno));
                return 1;
            }
        }
        for (y = 0; y < h; y++) {
            uint8_t *o = (uint8_t *)bufs[b.index].start + (size_t)y * bpl;
            const uint8_t *in = img + (size_t)y * w;
            if (fourcc == V4L2_PIX_FMT_GREY) {
                memcpy(o, in, (size_t)w);
            } else {
                for (x = 0; x < w; x++) {
                    o[2 * x] = in[x];
                    o[2 * x + 1] = 128;
                }
            }
        }
        b.bytesused = (unsigned)sizeimage;
        b.field = V4L2_FIELD_NONE;
        if (xioctl(fd, VIDIOC_QBUF, &b) < 0) {
            fprintf(stderr, "v4l2_feed: QBUF: %s\n", strerror(errno));
            return 1;
        }
        shown++;
        if (shown == (unsigned long)nbufs) {
            if (xioctl(fd, VIDIOC_STREAMON, &t) < 0) {
                fprintf(stderr, "v4l2_feed: STREAMON: %s\n", strerror(errno));
                return 1;
            }
            printf("v4l2_feed: streaming %d frames of %dx%d, each for %d output frames\n", frames,
                   w, h, hold);
            fflush(stdout);
        }
    }
    xioctl(fd, VIDIOC_STREAMOFF, &t);
    v4l2_close(fd);
    free(ring);
    return 0;
}
