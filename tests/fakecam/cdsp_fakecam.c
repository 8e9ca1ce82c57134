/*
 * cdsp_fakecam - a fake GigE Vision camera that shows a pipe of known pose.
 *
 * Built on libaravis's own camera simulator (ArvGvFakeCamera: GVCP control
 * and GVSP streaming over UDP, GenICam registers for size, pixel format and
 * frame rate), with the picture drawn by libcdsp's renderer in the fake
 * camera's fill-pattern callback: frame N shows the pipe of
 * tests/fakecam/fakecam_path.h at the camera's current width, height and
 * pixel format (Mono8 or Mono16). A client that includes the same header
 * knows the ground truth of every frame, or can redraw it pixel for pixel.
 *
 * Usage: cdsp_fakecam [options]   (--help lists them)
 * It prints one line "cdsp_fakecam: ready ..." on stdout when the camera
 * answers, and runs until SIGINT/SIGTERM or --duration. With --cycle N the
 * N frames are drawn before that line, at the initial size and in every
 * format of --formats, so a test that waits for "ready" gets frames at the
 * asked rate however slow the machine draws them (issue 9: tests must not
 * depend on the machine's speed).
 * Exit status: 0 stopped by a signal or --duration, 1 the camera could not
 * start (address not local, GVCP port 3956 taken...), 2 usage error.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <arv.h>

#include "cdsp.h"
#include "cdsp_host.h"
#include "cli.h"
#include "fakecam_path.h"
#include "fakecam_pixels.h"

typedef struct {
    const char *serial;
    const char *address;
    int width, height;
    double rate;
    ArvPixelFormat pixel_format;
    double loss_per_thousand;
    const char *truth_path;
    double duration;
    unsigned cycle;
    unsigned prerender_bits;    /* bit set: 1 << 8 Mono8, 1 << 16 Mono16 */
    const char *cache;          /* --cache DIR, or NULL */
    int verbose;
} fakecam_options;

/* The pixel formats served: each is drawn from a grey render of `base`
 * bits (8 or 16: what cdsp_render writes) and turned into the format as a
 * camera would deliver it (fakecam_pixels.h): 'm' mono, 'g' GigE Vision
 * packed, 'p' PFNC packed, 'b' Bayer mosaic of cell `cell`, 'r' RGB with
 * the channel order of `cell`. Those Aravis's fake camera does not list in
 * its GenICam file are added to its PixelFormat enumeration (xml_with_formats). */
typedef struct {
    const char *name;
    guint32 code;           /* PFNC */
    int base, kind, bits;
    const char *cell;
} fakecam_format;

static const fakecam_format formats[] = {
    {"Mono8", 0x01080001u, 8, 'm', 8, NULL},       {"Mono16", 0x01100007u, 16, 'm', 16, NULL},
    {"Mono10", 0x01100003u, 16, 'm', 10, NULL},    {"Mono12", 0x01100005u, 16, 'm', 12, NULL},
    {"Mono10Packed", 0x010c0004u, 16, 'g', 10, NULL}, {"Mono12Packed", 0x010c0006u, 16, 'g', 12, NULL},
    {"Mono10p", 0x010a0046u, 16, 'p', 10, NULL},   {"Mono12p", 0x010c0047u, 16, 'p', 12, NULL},
    {"BayerRG8", 0x01080009u, 8, 'b', 8, "RGGB"},  {"BayerGR8", 0x01080008u, 8, 'b', 8, "GRBG"},
    {"BayerGB8", 0x0108000au, 8, 'b', 8, "GBRG"},  {"BayerBG8", 0x0108000bu, 8, 'b', 8, "BGGR"},
    {"BayerRG10", 0x0110000du, 16, 'b', 10, "RGGB"}, {"BayerGR10", 0x0110000cu, 16, 'b', 10, "GRBG"},
    {"BayerGB10", 0x0110000eu, 16, 'b', 10, "GBRG"}, {"BayerBG10", 0x0110000fu, 16, 'b', 10, "BGGR"},
    {"BayerRG12", 0x01100011u, 16, 'b', 12, "RGGB"}, {"BayerGR12", 0x01100010u, 16, 'b', 12, "GRBG"},
    {"BayerGB12", 0x01100012u, 16, 'b', 12, "GBRG"}, {"BayerBG12", 0x01100013u, 16, 'b', 12, "BGGR"},
    {"BayerRG16", 0x0110002fu, 16, 'b', 16, "RGGB"}, {"BayerGR16", 0x0110002eu, 16, 'b', 16, "GRBG"},
    {"BayerGB16", 0x01100030u, 16, 'b', 16, "GBRG"}, {"BayerBG16", 0x01100031u, 16, 'b', 16, "BGGR"},
    {"RGB8", 0x02180014u, 8, 'r', 8, "RGB"},       {"BGR8", 0x02180015u, 8, 'r', 8, "BGR"},
};
#define N_FORMATS (sizeof formats / sizeof formats[0])

static const fakecam_format *format_of(guint32 code)
{
    size_t i;
    for (i = 0; i < N_FORMATS; i++)
        if (formats[i].code == code)
            return &formats[i];
    return NULL;
}

/* Bytes of a w x h frame in format f (PFNC: bits 16..23 of the code are
 * the bits per pixel), as the fake camera's payload computes them. */
static size_t format_bytes(const fakecam_format *f, int w, int h)
{
    return (size_t)w * (size_t)h * ((f->code >> 16) & 0xFFu) / 8u;
}

/* One pose rendered for --cycle, at both depths the renderer draws (the
 * 8-bit frame is not the 16-bit one shifted: noise and rounding differ, and
 * arv_probe compares pixel for pixel with cdsp_render's own output). */
typedef struct {
    uint8_t *data[2];       /* [0]: 8 bit, [1]: 16 bit; NULL until drawn */
    int w[2], h[2];
} fakecam_slot;

/* Renderer state, owned by the fake camera's streaming thread (the callback
 * runs there, under the fake camera's fill-pattern mutex). */
typedef struct {
    ArvFakeCamera *fake;
    unsigned cycle;
    fakecam_slot *slots;    /* cycle entries, or NULL */
    float *scratch;
    size_t scratch_len;
    FILE *truth;
    const char *truth_path;
    unsigned long frames;
    uint8_t *grey;          /* a grey render turned into another format */
    uint16_t *tmp16;        /* packed formats: the shifted values */
    size_t grey_len;
    int warned_format, warned_size, warned_render, warned_slow, warned_cache;
    int verbose;
} fakecam_state;

/* Draw frame id (its pose and noise: fakecam_path.h) at w x h and bits into
 * out (w * h pixels of bits / 8 rounded up bytes). The scratch grows once per
 * larger size. */
static cdsp_status draw(fakecam_state *st, guint64 id, int w, int h, int bits, void *out)
{
    cdsp_camera cam;
    cdsp_scene scene;
    cdsp_rng rng;
    size_t len = cdsp_render_scratch_size(w, h);

    if (len > st->scratch_len) {
        float *p = realloc(st->scratch, len * sizeof *p);
        if (!p)
            return CDSP_E_CAPACITY;
        st->scratch = p;
        st->scratch_len = len;
    }
    fakecam_frame(id, st->cycle, w, h, &cam, &scene, &rng);
    return cdsp_render(&scene, &cam, out, 0, bits, st->scratch, st->scratch_len, &rng);
}

/* Keep a copy of frame id's pixels in its --cycle slot. Returns 0, or -1
 * out of memory (the frame is then drawn again next time). */
static int keep(fakecam_state *st, guint64 id, int w, int h, int bits, const void *img)
{
    fakecam_slot *sl = &st->slots[(id & 0xFFFFu) % st->cycle];
    int d = bits > 8;
    size_t need = (size_t)w * (size_t)h * (size_t)(d ? 2 : 1);
    uint8_t *p = realloc(sl->data[d], need);

    if (!p)
        return -1;
    memcpy(p, img, need);
    sl->data[d] = p;
    sl->w[d] = w;
    sl->h[d] = h;
    return 0;
}

/* --cache DIR: the file holding pose i of --cycle n at w x h and bits. */
static void cache_name(char *buf, size_t len, const char *dir, unsigned i, unsigned n, int w, int h,
                       int bits)
{
    snprintf(buf, len, "%s/pose%u-of%u-%dx%d-%d.raw", dir, i, n, w, h, bits);
}

/* Read exactly len bytes of a cached pose into img: 0, or -1 (absent or
 * short: it is drawn again). */
static int cache_read(const char *path, void *img, size_t len)
{
    FILE *f = fopen(path, "rb");
    int ok;
    if (!f)
        return -1;
    ok = fread(img, 1, len, f) == len && fgetc(f) == EOF;
    fclose(f);
    return ok ? 0 : -1;
}

/* Write a pose to the cache through a temporary name and rename(), so a
 * camera started beside this one never reads half a file. Failure only
 * costs a redraw next time: reported, not fatal. */
static void cache_write(const char *path, const void *img, size_t len)
{
    char tmp[4200];
    FILE *f;
    snprintf(tmp, sizeof tmp, "%s.%ld.tmp", path, (long)getpid());
    f = fopen(tmp, "wb");
    if (!f || fwrite(img, 1, len, f) != len || fclose(f) || rename(tmp, path)) {
        fprintf(stderr, "cdsp_fakecam: --cache: cannot write %s: %s\n", path, strerror(errno));
        remove(tmp);
    }
}

/* --cycle N: draw the N poses at w x h in every depth of bits_mask before
 * the camera is announced, or read them from --cache (a test that starts
 * the camera again, after killing it, does not pay for the drawing twice).
 * Returns 0, or -1 with a message. */
static int prerender(fakecam_state *st, int w, int h, unsigned bits_mask, const char *cache,
                     double *seconds)
{
    static const int depths[2] = {8, 16};
    double t0 = cdsp_host_now_s();
    unsigned i;
    int d;
    uint8_t *img = malloc((size_t)w * (size_t)h * 2);

    if (!img) {
        fprintf(stderr, "cdsp_fakecam: out of memory for a %dx%d frame\n", w, h);
        return -1;
    }
    for (d = 0; d < 2; d++) {
        size_t len = (size_t)w * (size_t)h * (size_t)(d ? 2 : 1);
        if (!(bits_mask & (1u << depths[d])))
            continue;
        for (i = 0; i < st->cycle; i++) {
            char path[4096];
            cdsp_status s = CDSP_OK;
            if (cache)
                cache_name(path, sizeof path, cache, i, st->cycle, w, h, depths[d]);
            if (!cache || cache_read(path, img, len)) {
                s = draw(st, i, w, h, depths[d], img);
                if (s == CDSP_OK && cache)
                    cache_write(path, img, len);
            }
            if (s != CDSP_OK || keep(st, i, w, h, depths[d], img)) {
                fprintf(stderr, "cdsp_fakecam: drawing pose %u of --cycle %u (%dx%d, %d bit): %s\n",
                        i, st->cycle, w, h, depths[d], s != CDSP_OK ? cdsp_strerror(s) : "out of memory");
                free(img);
                return -1;
            }
        }
    }
    free(img);
    *seconds = cdsp_host_now_s() - t0;
    return 0;
}

/* A grey render (8 or 16 bit, fmt->base) as the camera delivers format fmt:
 * Bayer and RGB are the scene through the FAKECAM_GAIN_* filters. */
static void convert(const fakecam_format *fmt, const uint8_t *grey, int w, int h, uint16_t *tmp,
                    void *out)
{
    static const double gain[3] = {FAKECAM_GAIN_R, FAKECAM_GAIN_G, FAKECAM_GAIN_B};
    const uint16_t *g16 = (const uint16_t *)(const void *)grey;
    uint8_t *o8 = out;
    size_t n = (size_t)w * (size_t)h, i;
    int x, y, shift = fmt->base - fmt->bits;

    switch (fmt->kind) {
    case 'm':   /* 16-bit render, the top `bits` bits, little endian */
    case 'g':
    case 'p':
        for (i = 0; i < n; i++)
            tmp[i] = (uint16_t)(g16[i] >> shift);
        if (fmt->kind != 'm') {
            fakecam_pack(tmp, n, fmt->bits, (char)fmt->kind, out);
            return;
        }
        for (i = 0; i < n; i++) {
            o8[2 * i] = (uint8_t)tmp[i];
            o8[2 * i + 1] = (uint8_t)(tmp[i] >> 8);
        }
        return;
    case 'b':
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                size_t k = (size_t)y * (size_t)w + (size_t)x;
                double gk = gain[fakecam_bayer_colour(fmt->cell, x, y)];
                if (fmt->base == 8) {
                    o8[k] = (uint8_t)(grey[k] * gk + 0.5);
                } else {
                    unsigned v = (unsigned)(g16[k] * gk + 0.5) >> shift;
                    o8[2 * k] = (uint8_t)v;
                    o8[2 * k + 1] = (uint8_t)(v >> 8);
                }
            }
        return;
    default:    /* 'r': three samples per pixel in the order of cell */
        for (i = 0; i < n; i++) {
            int c;
            for (c = 0; c < 3; c++) {
                int colour = fmt->cell[c] == 'R' ? 0 : fmt->cell[c] == 'G' ? 1 : 2;
                o8[3 * i + (size_t)c] = (uint8_t)(grey[i] * gain[colour] + 0.5);
            }
        }
        return;
    }
}

static void fill_frame(ArvBuffer *buffer, void *data, guint32 exposure_us, guint32 gain,
                       ArvPixelFormat pixel_format)
{
    fakecam_state *st = data;
    size_t size, need;
    /* The fake camera hands its own buffer to fill: the const is Aravis's
     * reader-side view. Its size: arv_buffer_get_data() reports the bytes
     * received so far (0 here); the fake camera has already checked that the
     * buffer holds its current payload. */
    void *img = (void *)arv_buffer_get_data(buffer, NULL);
    int w = arv_buffer_get_image_width(buffer), h = arv_buffer_get_image_height(buffer);
    guint64 id = arv_buffer_get_frame_id(buffer);
    const fakecam_format *fmt;
    uint8_t *grey;
    int bits;
    cdsp_status s;
    guint32 period_us;
    double t0, t_draw;

    (void)exposure_us;  /* the scene is drawn the same whatever the exposure */
    (void)gain;
    if (!img || w <= 0 || h <= 0)
        return;
    fmt = format_of((guint32)pixel_format);
    size = arv_fake_camera_get_payload(st->fake);
    if (!fmt) {
        if (!st->warned_format++)
            fprintf(stderr, "cdsp_fakecam: pixel format 0x%08x is not drawn: frames are black\n",
                    (unsigned)pixel_format);
        memset(img, 0, size);
        return;
    }
    bits = fmt->base;
    need = (size_t)w * (size_t)h * (bits > 8 ? 2 : 1);
    if (size < format_bytes(fmt, w, h)) {
        if (!st->warned_size++)
            fprintf(stderr, "cdsp_fakecam: payload of %zu bytes for a %dx%d %s frame of %zu bytes: "
                    "frame left as is\n", size, w, h, fmt->name, format_bytes(fmt, w, h));
        return;
    }
    /* Mono8 and Mono16 are drawn in place; the others from a grey render
     * kept beside (grown once per size, never per frame) */
    grey = img;
    if (!(fmt->kind == 'm' && fmt->bits == fmt->base)) {
        if (st->grey_len < need) {
            uint8_t *g = realloc(st->grey, need);
            uint16_t *t = realloc(st->tmp16, need);
            if (g)
                st->grey = g;
            if (t)
                st->tmp16 = t;
            if (!g || !t) {
                fprintf(stderr, "cdsp_fakecam: out of memory for a %dx%d frame\n", w, h);
                memset(img, 0, size);
                return;
            }
            st->grey_len = need;
        }
        grey = st->grey;
    }

    if (st->slots) {
        fakecam_slot *sl = &st->slots[(id & 0xFFFFu) % st->cycle];
        int d = bits > 8;
        if (sl->data[d] && sl->w[d] == w && sl->h[d] == h) {
            memcpy(grey, sl->data[d], need);
            goto drawn;
        }
    }

    t0 = cdsp_host_now_s();
    s = draw(st, id, w, h, bits, grey);
    if (s != CDSP_OK) {
        if (!st->warned_render++)
            fprintf(stderr, "cdsp_fakecam: cdsp_render failed for frame %lu (%dx%d, %d bit): %s\n",
                    (unsigned long)id, w, h, bits, cdsp_strerror(s));
        memset(img, 0, size);
        return;
    }
    t_draw = cdsp_host_now_s() - t0;
    if (!st->warned_slow && arv_fake_camera_read_register(st->fake,
            ARV_FAKE_CAMERA_REGISTER_ACQUISITION_FRAME_PERIOD_US, &period_us) &&
        t_draw * 1e6 > (double)period_us) {
        st->warned_slow = 1;
        fprintf(stderr, "cdsp_fakecam: drawing a %dx%d frame takes %.0f ms, longer than the frame "
                "period of %.0f ms: frames come slower than asked (--cycle N with --size and "
                "--formats of what the client sets keeps N frames drawn)\n", w, h, 1e3 * t_draw,
                1e-3 * (double)period_us);
    }
    if (st->slots && keep(st, id, w, h, bits, grey) && !st->warned_cache++)
        fprintf(stderr, "cdsp_fakecam: out of memory for the frame cache: drawing every frame\n");
drawn:
    if (grey != img)
        convert(fmt, grey, w, h, st->tmp16, img);
    /* the camera's clock (fakecam_path.h): what the GVSP leader carries */
    arv_buffer_set_timestamp(buffer, fakecam_clock_ns());
    st->frames++;
    if (st->truth) {
        double p[3], v[3];
        fakecam_pose(id, st->cycle, p, v);
        fprintf(st->truth, "%lu %.17g %.17g %.17g %.17g %.17g %.17g\n", (unsigned long)id, p[0], p[1],
                p[2], v[0], v[1], v[2]);
        fflush(st->truth);
    }
    if (st->verbose > 1)
        fprintf(stderr, "cdsp_fakecam: frame %lu %dx%d %d bit\n", (unsigned long)id, w, h, bits);
}

/* ------------------------------------------------------------------------
 * Command line: one table gives the options, their help and defaults.
 * ---------------------------------------------------------------------- */
enum { OPT_SIZE = 256, OPT_RATE, OPT_FORMAT, OPT_TRUTH, OPT_DURATION, OPT_CYCLE, OPT_FORMATS, OPT_CACHE };

static const cdsp_host_option option_table[] = {
    {{"serial", required_argument, NULL, 's'}, "SERIAL",
     "serial number (default CDSP01; Aravis names the camera Aravis-Fake-SERIAL)"},
    {{"interface", required_argument, NULL, 'i'}, "ADDR",
     "IPv4 address or interface to serve on (default 127.0.0.1)"},
    {{"size", required_argument, NULL, OPT_SIZE}, "WxH",
     "initial frame size, up to 2048x2048 (default 640x480; clients may change it)"},
    {{"rate", required_argument, NULL, OPT_RATE}, "FPS",
     "initial frame rate, 1..1000 (default 25)"},
    {{"pixel-format", required_argument, NULL, OPT_FORMAT}, "FMT",
     "initial pixel format (default Mono8): Mono8/10/12/16, Mono10Packed, Mono12Packed, "
     "Mono10p, Mono12p, Bayer{RG,GR,GB,BG}{8,10,12,16}, RGB8, BGR8"},
    {{"gvsp-lost-ratio", required_argument, NULL, 'r'}, "N",
     "drop N of every 1000 GVSP packets, 0..1000 (default 0; the fake camera "
     "never answers resend requests)"},
    {{"truth", required_argument, NULL, OPT_TRUTH}, "FILE",
     "append 'frame_id x y z dx dy dz' (axis point and direction, mm) per frame drawn"},
    {{"cycle", required_argument, NULL, OPT_CYCLE}, "N",
     "show only N poses in turn, each drawn once and kept (0..1000, default 0: "
     "every frame drawn; see fakecam_path.h), drawn before 'ready' at the initial "
     "size in the formats of --formats"},
    {{"formats", required_argument, NULL, OPT_FORMATS}, "FMT,...",
     "with --cycle: the pixel formats clients will set, drawn before 'ready' too "
     "(default: the initial --pixel-format)"},
    {{"cache", required_argument, NULL, OPT_CACHE}, "DIR",
     "with --cycle: read the drawn poses from DIR, or draw and write them there "
     "(a test starting the camera again draws them once)"},
    {{"duration", required_argument, NULL, OPT_DURATION}, "SECONDS",
     "stop after this long (default 0: until SIGINT/SIGTERM)"},
    {{"verbose", no_argument, NULL, 'v'}, NULL, "more messages (twice: one per frame)"},
    {{"help", no_argument, NULL, 'h'}, NULL, "this help"},
};
#define N_OPTIONS (sizeof option_table / sizeof option_table[0])

static void usage(FILE *f, int status)
{
    cli_usage(f,
              "usage: cdsp_fakecam [options]\n"
              "A fake GigE Vision camera showing the pipe of tests/fakecam/fakecam_path.h.\n",
              option_table, N_OPTIONS, 30);
    exit(status);
}

static double parse_number(const char *opt, const char *s, double lo, double hi)
{
    return cli_number("cdsp_fakecam", opt, s, lo, hi);
}

static ArvPixelFormat parse_format(const char *opt, const char *s)
{
    size_t i;
    for (i = 0; i < N_FORMATS; i++)
        if (!strcmp(s, formats[i].name))
            return (ArvPixelFormat)formats[i].code;
    fprintf(stderr, "cdsp_fakecam: %s '%s': expected one of", opt, s);
    for (i = 0; i < N_FORMATS; i++)
        fprintf(stderr, " %s", formats[i].name);
    fprintf(stderr, "\n");
    exit(2);
}

static void parse_options(int argc, char **argv, fakecam_options *o)
{
    struct option longopts[N_OPTIONS + 1];
    int c;

    cdsp_host_options_getopt(option_table, N_OPTIONS, longopts);

    o->serial = "CDSP01";
    o->address = "127.0.0.1";
    o->width = 640;
    o->height = 480;
    o->rate = 25.0;
    o->pixel_format = ARV_PIXEL_FORMAT_MONO_8;
    o->loss_per_thousand = 0.0;
    o->truth_path = NULL;
    o->duration = 0.0;
    o->cycle = 0;
    o->prerender_bits = 0;
    o->cache = NULL;
    o->verbose = 0;

    while ((c = getopt_long(argc, argv, "s:i:r:vh", longopts, NULL)) != -1) {
        switch (c) {
        case 's':
            o->serial = optarg;
            /* the GVBS serial number register holds 16 bytes with the NUL */
            if (!*optarg || strlen(optarg) > 15) {
                fprintf(stderr, "cdsp_fakecam: --serial '%s': expected 1 to 15 characters\n", optarg);
                exit(2);
            }
            break;
        case 'i': o->address = optarg; break;
        case OPT_SIZE: {
            int w, h, n = 0;
            if (sscanf(optarg, "%dx%d%n", &w, &h, &n) != 2 || optarg[n] || w < 16 || h < 16 ||
                w > 2048 || h > 2048 || w % 4) {
                fprintf(stderr, "cdsp_fakecam: --size '%s': expected WxH, 16..2048 each, "
                        "W a multiple of 4\n", optarg);
                exit(2);
            }
            o->width = w;
            o->height = h;
            break;
        }
        case OPT_RATE: o->rate = parse_number("rate", optarg, 1.0, 1000.0); break;
        case OPT_FORMAT: o->pixel_format = parse_format("--pixel-format", optarg); break;
        case OPT_FORMATS: {
            char list[256], *tok, *save = NULL;
            snprintf(list, sizeof list, "%s", optarg);
            for (tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save))
                o->prerender_bits |= 1u << format_of((guint32)parse_format("--formats", tok))->base;
            if (!o->prerender_bits) {
                fprintf(stderr, "cdsp_fakecam: --formats '%s': expected a list of formats\n", optarg);
                exit(2);
            }
            break;
        }
        case 'r':
            o->loss_per_thousand = parse_number("gvsp-lost-ratio", optarg, 0.0, 1000.0);
            break;
        case OPT_TRUTH: o->truth_path = optarg; break;
        case OPT_CACHE: o->cache = optarg; break;
        case OPT_DURATION: o->duration = parse_number("duration", optarg, 0.0, 1e7); break;
        case OPT_CYCLE: o->cycle = (unsigned)parse_number("cycle", optarg, 0.0, 1000.0); break;
        case 'v': o->verbose++; break;
        case 'h': usage(stdout, 0); break;
        default: usage(stderr, 2);
        }
    }
    if (optind != argc) {
        fprintf(stderr, "cdsp_fakecam: unexpected argument '%s'\n", argv[optind]);
        usage(stderr, 2);
    }
    if (!o->prerender_bits)
        o->prerender_bits = 1u << format_of((guint32)o->pixel_format)->base;
}

/* Aravis's fake camera with every format of `formats` in its GenICam
 * PixelFormat enumeration: its own file (arv_fake_camera_get_genicam_xml)
 * with the missing entries added, written to a temporary file for
 * arv_gv_fake_camera_new_full, which reads it at once. The registers stay
 * Aravis's: the pixel format register takes any value, and the payload
 * formula (width x height x bits per pixel from the code) holds for all. */
static ArvGvFakeCamera *new_camera(const char *address, const char *serial)
{
    static const char anchor[] = "<pValue>PixelFormatRegister</pValue>";
    ArvFakeCamera *base = arv_fake_camera_new(serial);
    ArvGvFakeCamera *gv = NULL;
    const char *xml, *at;
    size_t len = 0, i;
    char path[] = "/tmp/cdsp-fakecam-xml-XXXXXX";
    FILE *f;
    int fd;

    xml = base ? arv_fake_camera_get_genicam_xml(base, &len) : NULL;
    at = xml ? strstr(xml, anchor) : NULL;
    fd = at ? mkstemp(path) : -1;
    if (fd < 0 || !(f = fdopen(fd, "w"))) {
        fprintf(stderr, "cdsp_fakecam: cannot extend the GenICam file (%s): only Aravis's own "
                "formats are listed\n", at ? strerror(errno) : "no PixelFormat enumeration");
        if (fd >= 0)
            close(fd);
        if (base)
            g_object_unref(base);
        return arv_gv_fake_camera_new(address, serial);
    }
    fwrite(xml, 1, (size_t)(at - xml), f);
    for (i = 0; i < N_FORMATS; i++) {
        char entry[64];
        snprintf(entry, sizeof entry, "<EnumEntry Name=\"%s\"", formats[i].name);
        if (!strstr(xml, entry))
            fprintf(f, "<EnumEntry Name=\"%s\" NameSpace=\"Standard\"><Value>%u</Value></EnumEntry>\n\t\t",
                    formats[i].name, (unsigned)formats[i].code);
    }
    fwrite(at, 1, len - (size_t)(at - xml), f);
    if (fclose(f) == 0)
        gv = arv_gv_fake_camera_new_full(address, serial, path);
    remove(path);
    g_object_unref(base);
    return gv;
}

/* GigE Vision control (GVCP) listens on UDP port 3956. Aravis binds it with
 * SO_REUSEADDR, so a second fake camera on the same address would start
 * too and the two would split the traffic between them. A plain bind
 * (without SO_REUSEADDR) fails while anyone holds the port: refuse then.
 * Returns 0 when the port is free or addr is an interface name. */
static int gvcp_port_taken(const char *addr)
{
    struct sockaddr_in sa;
    int fd, r;

    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons(3956);
    if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1)
        return 0;
    fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0)
        return 0;
    r = bind(fd, (struct sockaddr *)&sa, sizeof sa);
    close(fd);
    return r < 0 && errno == EADDRINUSE;
}

int main(int argc, char **argv)
{
    fakecam_options o;
    fakecam_state st;
    ArvGvFakeCamera *gv;
    ArvFakeCamera *fake;
    struct timespec tick = {0, 100000000L};
    double t_end, t_prerender = 0;

    parse_options(argc, argv, &o);
    memset(&st, 0, sizeof st);
    st.verbose = o.verbose;
    st.cycle = o.cycle;
    if (o.cycle) {
        st.slots = calloc(o.cycle, sizeof *st.slots);
        if (!st.slots) {
            fprintf(stderr, "cdsp_fakecam: out of memory for --cycle %u\n", o.cycle);
            return 1;
        }
    }
    st.truth_path = o.truth_path;
    if (o.truth_path) {
        st.truth = fopen(o.truth_path, "a");
        if (!st.truth) {
            fprintf(stderr, "cdsp_fakecam: --truth %s: cannot open: %s\n", o.truth_path,
                    strerror(errno));
            return 2;
        }
    }

    cdsp_host_stop_on_signals();

    if (gvcp_port_taken(o.address)) {
        fprintf(stderr, "cdsp_fakecam: UDP port 3956 (GVCP) on %s is already taken, by another "
                "GigE Vision camera or program; only one fake camera per address can work\n",
                o.address);
        return 1;
    }
    /* Before the camera exists: no streaming thread shares st yet. */
    if (st.slots && prerender(&st, o.width, o.height, o.prerender_bits, o.cache, &t_prerender))
        return 1;
    gv = new_camera(o.address, o.serial);
    if (!gv || !arv_gv_fake_camera_is_running(gv)) {
        fprintf(stderr, "cdsp_fakecam: the fake camera did not start on '%s' (an address of this "
                "machine? GVCP port 3956 already taken by another camera?)\n", o.address);
        if (gv)
            g_object_unref(gv);
        return 1;
    }
    fake = arv_gv_fake_camera_get_fake_camera(gv);
    st.fake = fake;
    g_object_set(gv, "gvsp-lost-ratio", o.loss_per_thousand / 1000.0, NULL);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_WIDTH, (guint32)o.width);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_HEIGHT, (guint32)o.height);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT,
                                   (guint32)o.pixel_format);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_FRAME_PERIOD_US,
                                   (guint32)(1e6 / o.rate + 0.5));
    arv_fake_camera_set_fill_pattern(fake, fill_frame, &st);

    printf("cdsp_fakecam: ready: Aravis-Fake-%s on %s, %dx%d %s at %g fps, GVSP loss %g/1000",
           o.serial, o.address, o.width, o.height,
           format_of((guint32)o.pixel_format)->name, o.rate,
           o.loss_per_thousand);
    if (st.slots)
        printf(", %u poses drawn%s in %.1f s", o.cycle, o.cache ? " (or read from --cache)" : "",
               t_prerender);
    printf("\n");
    fflush(stdout);

    t_end = o.duration > 0 ? cdsp_host_now_s() + o.duration : 0;
    while (!cdsp_host_stop_requested() && (t_end == 0 || cdsp_host_now_s() < t_end))
        nanosleep(&tick, NULL);

    /* Unref joins the streaming thread: st is no longer in use after it. */
    g_object_unref(gv);
    if (st.truth)
        fclose(st.truth);
    free(st.scratch);
    free(st.grey);
    free(st.tmp16);
    if (st.slots) {
        unsigned i;
        for (i = 0; i < o.cycle; i++) {
            free(st.slots[i].data[0]);
            free(st.slots[i].data[1]);
        }
        free(st.slots);
    }
    if (o.verbose)
        fprintf(stderr, "cdsp_fakecam: stopped after drawing %lu frames\n", st.frames);
    return 0;
}
