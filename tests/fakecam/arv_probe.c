/*
 * arv_probe - a minimal Aravis client that checks cdsp_fakecam end to end:
 * discovers the fake camera on a loopback address, sets size, pixel format
 * and frame rate, streams K frames over GVSP and compares each one, byte for
 * byte, with the frame libcdsp's renderer draws for that frame id
 * (tests/fakecam/fakecam_path.h).
 *
 * Loopback pitfalls (shared/FACTS.md): as root Aravis receives GVSP through
 * a packet socket, which sees nothing on lo, so the probe disables it; the
 * kernel's default socket buffer drops most of a large frame, so the probe
 * sizes it to the payload (socket-buffer AUTO). The fake camera never
 * answers resend requests, so none are sent.
 *
 * Usage: arv_probe [options]   (--help lists them)
 * Exit status: 0 K frames arrived and all were exact (and the count of
 * incomplete frames was within the given bounds), 1 otherwise, 2 usage.
 */
#define _POSIX_C_SOURCE 200809L

#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <arv.h>

#include "cdsp.h"
#include "cdsp_host.h"
#include "cli.h"
#include "fakecam_path.h"

typedef struct {
    const char *address, *serial;
    int frames;
    int width, height;      /* 0: leave the camera's */
    double rate;            /* 0: leave the camera's */
    ArvPixelFormat pixel_format;
    double timeout;
    long max_incomplete;    /* < 0: no limit */
    long min_incomplete;
    unsigned cycle;         /* the camera's --cycle */
    const char *truth;      /* the camera's --truth file, or NULL */
    int expect_wrap;
    int verbose;
} probe_options;

enum { OPT_SIZE = 256, OPT_RATE, OPT_FORMAT, OPT_TIMEOUT, OPT_MAXINC, OPT_MININC, OPT_CYCLE,
       OPT_TRUTH, OPT_WRAP };

static const cdsp_host_option option_table[] = {
    {{"address", required_argument, NULL, 'a'}, "ADDR",
     "loopback address of the camera, 127.x.y.z (default 127.0.0.1)"},
    {{"serial", required_argument, NULL, 's'}, "SERIAL", "its serial number (default CDSP01)"},
    {{"frames", required_argument, NULL, 'n'}, "K", "complete frames to check, 1..100000 (default 30)"},
    {{"size", required_argument, NULL, OPT_SIZE}, "WxH", "set this frame size first"},
    {{"rate", required_argument, NULL, OPT_RATE}, "FPS", "set this frame rate first"},
    {{"pixel-format", required_argument, NULL, OPT_FORMAT}, "FMT",
     "Mono8 or Mono16 (default Mono8)"},
    {{"timeout", required_argument, NULL, OPT_TIMEOUT}, "SECONDS",
     "give up after this long, discovery included (default 30)"},
    {{"max-incomplete", required_argument, NULL, OPT_MAXINC}, "N",
     "fail if more frames than this arrive incomplete (default: no limit)"},
    {{"min-incomplete", required_argument, NULL, OPT_MININC}, "N",
     "fail if fewer than this arrive incomplete (checks a GVSP loss ratio; default 0)"},
    {{"cycle", required_argument, NULL, OPT_CYCLE}, "N",
     "the camera runs with --cycle N (default 0)"},
    {{"truth", required_argument, NULL, OPT_TRUTH}, "FILE",
     "the camera's --truth file: every checked frame must be listed there with "
     "its pose from fakecam_path.h"},
    {{"expect-wrap", no_argument, NULL, OPT_WRAP}, NULL,
     "fail unless the 16-bit frame id wraps while streaming"},
    {{"verbose", no_argument, NULL, 'v'}, NULL, "one line per frame"},
    {{"help", no_argument, NULL, 'h'}, NULL, "this help"},
};
#define N_OPTIONS (sizeof option_table / sizeof option_table[0])

static void usage(FILE *f, int status)
{
    cli_usage(f,
              "usage: arv_probe [options]\n"
              "Stream frames from cdsp_fakecam and check them pixel for pixel.\n",
              option_table, N_OPTIONS, 28);
    exit(status);
}

static double parse_number(const char *opt, const char *s, double lo, double hi)
{
    return cli_number("arv_probe", opt, s, lo, hi);
}

static void parse_options(int argc, char **argv, probe_options *o)
{
    struct option longopts[N_OPTIONS + 1];
    struct in_addr a;
    int c;

    cdsp_host_options_getopt(option_table, N_OPTIONS, longopts);
    memset(o, 0, sizeof *o);
    o->address = "127.0.0.1";
    o->serial = "CDSP01";
    o->frames = 30;
    o->pixel_format = ARV_PIXEL_FORMAT_MONO_8;
    o->timeout = 30.0;
    o->max_incomplete = -1;

    while ((c = getopt_long(argc, argv, "a:s:n:vh", longopts, NULL)) != -1) {
        switch (c) {
        case 'a': o->address = optarg; break;
        case 's': o->serial = optarg; break;
        case 'n': o->frames = (int)parse_number("frames", optarg, 1, 100000); break;
        case OPT_SIZE: {
            int w, h, n = 0;
            if (sscanf(optarg, "%dx%d%n", &w, &h, &n) != 2 || optarg[n] || w < 16 || h < 16 ||
                w > 2048 || h > 2048) {
                fprintf(stderr, "arv_probe: --size '%s': expected WxH, 16..2048 each\n", optarg);
                exit(2);
            }
            o->width = w;
            o->height = h;
            break;
        }
        case OPT_RATE: o->rate = parse_number("rate", optarg, 1, 1000); break;
        case OPT_FORMAT:
            if (!strcmp(optarg, "Mono8"))
                o->pixel_format = ARV_PIXEL_FORMAT_MONO_8;
            else if (!strcmp(optarg, "Mono16"))
                o->pixel_format = ARV_PIXEL_FORMAT_MONO_16;
            else {
                fprintf(stderr, "arv_probe: --pixel-format '%s': expected Mono8 or Mono16\n", optarg);
                exit(2);
            }
            break;
        case OPT_TIMEOUT: o->timeout = parse_number("timeout", optarg, 1, 3600); break;
        case OPT_MAXINC: o->max_incomplete = (long)parse_number("max-incomplete", optarg, 0, 1e9); break;
        case OPT_MININC: o->min_incomplete = (long)parse_number("min-incomplete", optarg, 0, 1e9); break;
        case OPT_CYCLE: o->cycle = (unsigned)parse_number("cycle", optarg, 0, 1000); break;
        case OPT_TRUTH: o->truth = optarg; break;
        case OPT_WRAP: o->expect_wrap = 1; break;
        case 'v': o->verbose = 1; break;
        case 'h': usage(stdout, 0); break;
        default: usage(stderr, 2);
        }
    }
    if (optind != argc) {
        fprintf(stderr, "arv_probe: unexpected argument '%s'\n", argv[optind]);
        usage(stderr, 2);
    }
    /* Tests stay on this machine: only 127.0.0.0/8. */
    if (inet_pton(AF_INET, o->address, &a) != 1 || (ntohl(a.s_addr) >> 24) != 127) {
        fprintf(stderr, "arv_probe: --address '%s': expected a loopback IPv4 address (127.x.y.z)\n",
                o->address);
        exit(2);
    }
}

/* Discovery is one UDP broadcast answered (or not) by each camera, so it is
 * repeated until the camera answers or the deadline passes: the camera may
 * still be starting, or a datagram may be lost. Returns a copy of the
 * device id, or NULL. */
static char *discover(const probe_options *o, double deadline)
{
    struct timespec pause = {0, 200000000L};
    unsigned i, n = 0;
    int attempts = 0;

    do {
        attempts++;
        arv_update_device_list();
        n = arv_get_n_devices();
        for (i = 0; i < n; i++) {
            const char *addr = arv_get_device_address(i), *serial = arv_get_device_serial_nbr(i);
            if (addr && serial && !strcmp(addr, o->address) && !strcmp(serial, o->serial)) {
                printf("arv_probe: found %s at %s (discovery attempt %d)\n", arv_get_device_id(i),
                       addr, attempts);
                return g_strdup(arv_get_device_id(i));
            }
        }
        nanosleep(&pause, NULL);
    } while (cdsp_host_now_s() < deadline);
    fprintf(stderr, "arv_probe: no camera with serial %s at %s after %d discovery attempts; "
            "seen:%s\n", o->serial, o->address, attempts, n ? "" : " none");
    for (i = 0; i < n; i++)
        fprintf(stderr, "  %s (%s, serial %s)\n", arv_get_device_id(i),
                arv_get_device_address(i) ? arv_get_device_address(i) : "?",
                arv_get_device_serial_nbr(i) ? arv_get_device_serial_nbr(i) : "?");
    return NULL;
}

/* Compare a received frame with the one the renderer draws for its id.
 * expect: expect_len bytes where the expected frame is drawn, or already
 * is when *drawn (--cycle: the same few frames come round again). */
static int check_frame(const probe_options *o, ArvBuffer *b, void *expect, size_t expect_len,
                       int *drawn, float **scratch, size_t *scratch_len)
{
    size_t size = 0, n, i, differ = 0;
    const void *img = arv_buffer_get_image_data(b, &size);
    int w = arv_buffer_get_image_width(b), h = arv_buffer_get_image_height(b);
    ArvPixelFormat pf = arv_buffer_get_image_pixel_format(b);
    guint64 id = arv_buffer_get_frame_id(b);
    int bits = pf == ARV_PIXEL_FORMAT_MONO_16 ? 16 : 8;
    unsigned maxdiff = 0;
    cdsp_camera cam;
    cdsp_scene scene;
    cdsp_rng rng;
    cdsp_status s;

    if (pf != o->pixel_format || (o->width && (w != o->width || h != o->height))) {
        fprintf(stderr, "arv_probe: frame %lu is %dx%d, pixel format 0x%08x; expected %dx%d, "
                "0x%08x\n", (unsigned long)id, w, h, (unsigned)pf, o->width, o->height,
                (unsigned)o->pixel_format);
        return -1;
    }
    n = (size_t)w * (size_t)h * (bits / 8);
    if (!img || size < n || n > expect_len) {
        fprintf(stderr, "arv_probe: frame %lu: %zu bytes of image data for %dx%d at %d bit\n",
                (unsigned long)id, size, w, h, bits);
        return -1;
    }
    if (!*drawn) {
        if (cdsp_render_scratch_size(w, h) > *scratch_len) {
            float *p = realloc(*scratch, cdsp_render_scratch_size(w, h) * sizeof *p);
            if (!p) {
                fprintf(stderr, "arv_probe: out of memory\n");
                return -1;
            }
            *scratch = p;
            *scratch_len = cdsp_render_scratch_size(w, h);
        }
        fakecam_frame(id, o->cycle, w, h, &cam, &scene, &rng);
        s = cdsp_render(&scene, &cam, expect, 0, bits, *scratch, *scratch_len, &rng);
        if (s != CDSP_OK) {
            fprintf(stderr, "arv_probe: cdsp_render failed for frame %lu: %s\n",
                    (unsigned long)id, cdsp_strerror(s));
            return -1;
        }
        *drawn = o->cycle > 0;
    }
    if (!memcmp(img, expect, n))
        return 0;
    for (i = 0; i < (size_t)w * (size_t)h; i++) {
        unsigned a, e;
        if (bits == 16) {
            uint16_t a16, e16;
            memcpy(&a16, (const uint8_t *)img + 2 * i, 2);
            memcpy(&e16, (const uint8_t *)expect + 2 * i, 2);
            a = a16;
            e = e16;
        } else {
            a = ((const uint8_t *)img)[i];
            e = ((const uint8_t *)expect)[i];
        }
        if (a != e) {
            differ++;
            if ((a > e ? a - e : e - a) > maxdiff)
                maxdiff = a > e ? a - e : e - a;
        }
    }
    fprintf(stderr, "arv_probe: frame %lu (%dx%d, %d bit) differs from the rendered frame in %zu "
            "pixels, by up to %u\n", (unsigned long)id, w, h, bits, differ, maxdiff);
    return -1;
}

/* Every id in ids[0..n) must appear in the camera's truth file with the
 * pose fakecam_pose() gives (printed with 17 digits: exact to the last
 * bit after the round trip through text). */
static int check_truth(const probe_options *o, const guint64 *ids, long n)
{
    FILE *f = fopen(o->truth, "r");
    char *found;
    char line[512];
    long i, lineno = 0, missing = 0;

    if (!f) {
        fprintf(stderr, "arv_probe: --truth %s: cannot open: %s\n", o->truth, strerror(errno));
        return -1;
    }
    found = calloc(65536, 1);
    if (!found) {
        fclose(f);
        fprintf(stderr, "arv_probe: out of memory\n");
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        unsigned long id;
        double p[3], v[3], pe[3], ve[3];
        int k;
        lineno++;
        if (sscanf(line, "%lu %lf %lf %lf %lf %lf %lf", &id, &p[0], &p[1], &p[2], &v[0], &v[1],
                   &v[2]) != 7) {
            fprintf(stderr, "arv_probe: %s:%ld: expected 'frame_id x y z dx dy dz'\n", o->truth,
                    lineno);
            goto bad;
        }
        fakecam_pose(id, o->cycle, pe, ve);
        for (k = 0; k < 3; k++)
            if (p[k] != pe[k] || v[k] != ve[k]) {
                fprintf(stderr, "arv_probe: %s:%ld: frame %lu: pose differs from fakecam_pose()\n",
                        o->truth, lineno, id);
                goto bad;
            }
        found[id & 0xFFFFu] = 1;
    }
    fclose(f);
    for (i = 0; i < n; i++)
        if (!found[ids[i] & 0xFFFFu])
            missing++;
    free(found);
    if (missing) {
        fprintf(stderr, "arv_probe: %s: %ld of the %ld checked frames are not listed\n", o->truth,
                missing, n);
        return -1;
    }
    printf("arv_probe: all %ld checked frames are in %s with their poses\n", n, o->truth);
    return 0;
bad:
    fclose(f);
    free(found);
    return -1;
}

int main(int argc, char **argv)
{
    probe_options o;
    GError *err = NULL;
    ArvCamera *camera = NULL;
    ArvStream *stream = NULL;
    char *device_id = NULL;
    uint8_t *expect = NULL;     /* max(1, cycle) frames of payload bytes */
    int *drawn = NULL;
    unsigned n_slots;
    float *scratch = NULL;
    size_t scratch_len = 0, payload;
    long verified = 0, incomplete = 0, received = 0;
    guint64 *ids = NULL;
    int wrapped = 0;
    guint64 last_id = 0;
    int have_last = 0, rc = 1, i, x, y, w, h;
    double t0, deadline;

    parse_options(argc, argv, &o);
    ids = malloc((size_t)o.frames * sizeof *ids);
    if (!ids) {
        fprintf(stderr, "arv_probe: out of memory\n");
        return 1;
    }
    t0 = cdsp_host_now_s();
    deadline = t0 + o.timeout;

    /* discovery gets most of the time-out: a loaded machine answers late */
    device_id = discover(&o, t0 + (o.timeout < 60 ? o.timeout : 60));
    if (!device_id)
        goto done;
    camera = arv_camera_new(device_id, &err);
    if (!camera)
        goto fail;
    arv_camera_set_pixel_format(camera, o.pixel_format, &err);
    if (err)
        goto fail;
    if (o.width) {
        arv_camera_set_region(camera, 0, 0, o.width, o.height, &err);
        if (err)
            goto fail;
    }
    if (o.rate > 0) {
        arv_camera_set_frame_rate(camera, o.rate, &err);
        if (err)
            goto fail;
    }
    arv_camera_get_region(camera, &x, &y, &w, &h, &err);
    if (err)
        goto fail;
    if (o.width && (w != o.width || h != o.height)) {
        fprintf(stderr, "arv_probe: asked for %dx%d, the camera set %dx%d\n", o.width, o.height, w, h);
        goto done;
    }
    payload = arv_camera_get_payload(camera, &err);
    if (err)
        goto fail;
    printf("arv_probe: %dx%d %s, payload %zu bytes, %.3g fps\n", w, h,
           o.pixel_format == ARV_PIXEL_FORMAT_MONO_16 ? "Mono16" : "Mono8", payload,
           arv_camera_get_frame_rate(camera, NULL));
    n_slots = o.cycle ? o.cycle : 1;
    expect = malloc(n_slots * (payload ? payload : 1));
    drawn = calloc(n_slots, sizeof *drawn);
    if (!expect || !drawn) {
        fprintf(stderr, "arv_probe: out of memory for %u frames of %zu bytes\n", n_slots, payload);
        goto done;
    }

    arv_camera_gv_set_stream_options(camera, ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    stream = arv_camera_create_stream(camera, NULL, NULL, &err);
    if (!stream)
        goto fail;
    /* frame-retention: how long Aravis waits for the rest of a started
     * frame before it gives the frame up as incomplete (default 100 ms).
     * On a loaded machine the camera's sending thread can be off the CPU
     * longer than that in the middle of a frame: a frame given up then is
     * the machine's speed, not the camera's loss, so wait 5 s. */
    g_object_set(stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_AUTO, "packet-resend",
                 ARV_GV_STREAM_PACKET_RESEND_NEVER, "frame-retention", (guint)5000000, NULL);
    for (i = 0; i < 8; i++)
        arv_stream_push_buffer(stream, arv_buffer_new(payload, NULL));
    arv_camera_start_acquisition(camera, &err);
    if (err)
        goto fail;

    while (verified < o.frames) {
        ArvBuffer *b;
        if (cdsp_host_now_s() > deadline) {
            fprintf(stderr, "arv_probe: timeout after %g s: %ld of %d frames checked (%ld received, "
                    "%ld incomplete)\n", o.timeout, verified, o.frames, received, incomplete);
            goto stop;
        }
        b = arv_stream_timeout_pop_buffer(stream, 1000000);
        if (!b)
            continue;   /* a timeout is not an error: the deadline decides */
        received++;
        if (arv_buffer_get_status(b) != ARV_BUFFER_STATUS_SUCCESS) {
            incomplete++;
            if (o.verbose)
                printf("frame %lu: status %d (incomplete)\n", (unsigned long)arv_buffer_get_frame_id(b),
                       (int)arv_buffer_get_status(b));
        } else {
            guint64 id = arv_buffer_get_frame_id(b);
            /* ids increase (16-bit wrap allowed); frames may be missing */
            if (have_last && (((id - last_id) & 0xFFFFu) == 0 || ((id - last_id) & 0xFFFFu) > 0x8000u)) {
                fprintf(stderr, "arv_probe: frame id %lu after %lu\n", (unsigned long)id,
                        (unsigned long)last_id);
                arv_stream_push_buffer(stream, b);
                goto stop;
            }
            if (have_last && id < last_id)
                wrapped = 1;
            last_id = id;
            have_last = 1;
            unsigned slot = o.cycle ? (unsigned)((id & 0xFFFFu) % o.cycle) : 0;
            if (check_frame(&o, b, expect + (size_t)slot * payload, payload, &drawn[slot],
                            &scratch, &scratch_len) < 0) {
                arv_stream_push_buffer(stream, b);
                goto stop;
            }
            ids[verified++] = id;
            if (o.verbose)
                printf("frame %lu: exact\n", (unsigned long)id);
        }
        arv_stream_push_buffer(stream, b);
        if (o.max_incomplete >= 0 && incomplete > o.max_incomplete) {
            fprintf(stderr, "arv_probe: %ld incomplete frames, more than the %ld allowed\n",
                    incomplete, o.max_incomplete);
            goto stop;
        }
    }
    if (incomplete < o.min_incomplete) {
        fprintf(stderr, "arv_probe: %ld incomplete frames, fewer than the %ld expected (is the "
                "GVSP loss ratio applied?)\n", incomplete, o.min_incomplete);
        goto stop;
    }
    if (o.expect_wrap && !wrapped) {
        fprintf(stderr, "arv_probe: the frame id did not wrap (first %lu, last %lu)\n",
                (unsigned long)ids[0], (unsigned long)last_id);
        goto stop;
    }
    printf("arv_probe: %ld frames pixel-exact (ids %lu..%lu%s), %ld incomplete, %ld received in "
           "%.2f s\n", verified, (unsigned long)ids[0], (unsigned long)last_id,
           wrapped ? ", across the 16-bit wrap" : "", incomplete, received, cdsp_host_now_s() - t0);
    if (o.truth && check_truth(&o, ids, verified) < 0)
        goto stop;
    rc = 0;
stop:
    arv_camera_stop_acquisition(camera, &err);
    if (err) {
        fprintf(stderr, "arv_probe: stop_acquisition: %s\n", err->message);
        g_clear_error(&err);
    }
    goto done;
fail:
    fprintf(stderr, "arv_probe: %s: %s\n", device_id ? device_id : o.address,
            err ? err->message : "failed");
    g_clear_error(&err);
done:
    if (stream)
        g_object_unref(stream);
    if (camera)
        g_object_unref(camera);
    g_free(device_id);
    free(expect);
    free(drawn);
    free(scratch);
    free(ids);
    arv_shutdown();
    if (rc)
        fprintf(stderr, "arv_probe: FAIL\n");
    return rc;
}
