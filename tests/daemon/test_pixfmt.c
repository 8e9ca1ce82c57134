/*
 * test_pixfmt.c - the pixel-format converters (daemon/pixfmt.c) against
 * hand-made buffers:
 *  - every unpacker on bytes written out by hand from the format's
 *    definition (GigE Vision 1.x MonoNPacked, PFNC MonoNp), then on a packer
 *    of this file (bit by bit, independent of the unpacker) for widths 1..9
 *    and heights 1..3, so odd widths start rows inside a group;
 *  - Bayer, all four orders, 8 and 16 bit, origin parities 0/1: a grey
 *    scene under unequal channel gains gives a flat frame (no checker), a
 *    vertical or horizontal step edge crosses half height where the scene's
 *    edge is, whatever the phase, and a region cut at an odd offset, told
 *    its parity, converts to the same pixels as the full frame;
 *  - RGB8/BGR8 luminance by hand; argument errors.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "fakecam_pixels.h"
#include "pixfmt.h"

#define MAXW 64
#define MAXH 32

static const cdspd_pixfmt *fmt(const char *name)
{
    const cdspd_pixfmt *f = cdspd_pixfmt_find(name);
    if (!f)
        fail_msg("format %s not in the table", name);
    return f;
}

/* --- the table ------------------------------------------------------------ */

static void test_table(void **state)
{
    size_t i, j;
    int last_family = 0, seen_packed = 0;
    (void)state;
    for (i = 0; cdspd_pixfmt_at(i); i++) {
        const cdspd_pixfmt *f = cdspd_pixfmt_at(i);
        assert_ptr_equal(cdspd_pixfmt_find(f->name), f);
        assert_ptr_equal(cdspd_pixfmt_from_code(f->code), f);
        /* PFNC: bits 16..23 of the code are the bits per pixel on the wire */
        assert_int_equal((f->code >> 16) & 0xFF,
                         cdspd_pixfmt_image_bytes(f, 8, 1));
        for (j = 0; j < i; j++)
            assert_true(cdspd_pixfmt_at(j)->code != f->code);
        /* `auto` order: mono, packed mono, Bayer, RGB */
        assert_true(f->family >= last_family);
        if (f->family == CDSPD_PIX_MONO && f->packing >= CDSPD_PACK_GV)
            seen_packed = 1;
        else if (f->family == CDSPD_PIX_MONO)
            assert_false(seen_packed);
        last_family = f->family;
        assert_true(f->out_bits >= f->bits && f->out_bits <= 16);
    }
    assert_int_equal(i, 26);
    assert_null(cdspd_pixfmt_find("BayerRG12Packed"));
    assert_null(cdspd_pixfmt_find("mono8"));
    assert_null(cdspd_pixfmt_from_code(0));
    assert_string_equal(cdspd_pixfmt_at(0)->name, "Mono8");
}

/* --- unpackers: by hand --------------------------------------------------- */

typedef struct {
    const char *name;
    int w, h;
    uint8_t bytes[16];
    size_t n_bytes;
    uint16_t px[8];
} packed_case;

static const packed_case hand[] = {
    /* Mono12Packed, 3 pixels 0xABC 0x123 0x5A7: AB (C|3<<4) 12, 5A 07 */
    {"Mono12Packed", 3, 1, {0xAB, 0x3C, 0x12, 0x5A, 0x07}, 5, {0xABC, 0x123, 0x5A7}},
    /* Mono10Packed, 0x2AB 0x155: 2AB>>2 = AA, (3 | 1<<4) = 13, 155>>2 = 55 */
    {"Mono10Packed", 2, 1, {0xAA, 0x13, 0x55}, 3, {0x2AB, 0x155}},
    /* Mono12p, 0xABC 0x123: BC, (A | 3<<4) = 3A, 12 */
    {"Mono12p", 2, 1, {0xBC, 0x3A, 0x12}, 3, {0xABC, 0x123}},
    /* Mono10p, 0x3FF 0x001 0x2AA 0x155 then 0x0F0 as a 1 x 5 image:
     * FF, (3 | 1<<2) = 07, (0 | A<<4) = A0, (2A | 1<<6) = 6A, 55, F0, 00 */
    {"Mono10p", 5, 1, {0xFF, 0x07, 0xA0, 0x6A, 0x55, 0xF0, 0x00}, 7,
     {0x3FF, 0x001, 0x2AA, 0x155, 0x0F0}},
    /* the same stream as 1 pixel wide, 5 rows: rows start mid-byte */
    {"Mono10p", 1, 5, {0xFF, 0x07, 0xA0, 0x6A, 0x55, 0xF0, 0x00}, 7,
     {0x3FF, 0x001, 0x2AA, 0x155, 0x0F0}},
    /* Mono12Packed 3 x 2: row 1 starts at pixel 3, the odd half of a group */
    {"Mono12Packed", 3, 2, {0xAB, 0x3C, 0x12, 0x5A, 0x67, 0xFF, 0x00, 0x00, 0x01}, 9,
     {0xABC, 0x123, 0x5A7, 0xFF6, 0x000, 0x010}},
};

static void test_unpack_by_hand(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < sizeof hand / sizeof hand[0]; i++) {
        const packed_case *c = &hand[i];
        const cdspd_pixfmt *f = fmt(c->name);
        uint16_t out[8];
        int k;
        assert_int_equal(cdspd_pixfmt_image_bytes(f, c->w, c->h), c->n_bytes);
        assert_int_equal(cdspd_pixfmt_convert(f, c->bytes, c->n_bytes, c->w, c->h, 0, 0, NULL, out,
                                              (size_t)c->w * 2, NULL, 0), 0);
        for (k = 0; k < c->w * c->h; k++)
            if (out[k] != c->px[k])
                fail_msg("%s %dx%d pixel %d: 0x%03x, expected 0x%03x", c->name, c->w, c->h, k,
                         out[k], c->px[k]);
    }
}

/* --- unpackers: against an independent packer ---------------------------- */

/* Write pixel values in format f's packing: the fake camera's packer
 * (tests/fakecam/fakecam_pixels.h), bit by bit from the definitions. */
static size_t pack(const cdspd_pixfmt *f, const uint16_t *px, size_t n, uint8_t *out)
{
    size_t i;
    if (f->packing == CDSPD_PACK_P || f->packing == CDSPD_PACK_GV)
        return fakecam_pack(px, n, f->bits, f->packing == CDSPD_PACK_P ? 'p' : 'g', out);
    for (i = 0; i < n; i++) {
        if (f->packing == CDSPD_PACK_16) {
            out[2 * i] = (uint8_t)px[i];
            out[2 * i + 1] = (uint8_t)(px[i] >> 8);
        } else {
            out[i] = (uint8_t)px[i];
        }
    }
    return cdspd_pixfmt_image_bytes(f, (int)n, 1);
}

static void test_unpack_all_sizes(void **state)
{
    static const char *names[] = {"Mono8", "Mono10", "Mono12", "Mono16", "Mono10Packed",
                                  "Mono12Packed", "Mono10p", "Mono12p"};
    size_t i;
    uint32_t seed = 12345u;
    (void)state;
    for (i = 0; i < sizeof names / sizeof names[0]; i++) {
        const cdspd_pixfmt *f = fmt(names[i]);
        int w, h;
        for (w = 1; w <= 9; w++)
            for (h = 1; h <= 3; h++) {
                uint16_t px[27], out[27 + 8];
                uint8_t raw[64], out8[27];
                size_t n = (size_t)(w * h), k, bytes;
                for (k = 0; k < n; k++) {
                    seed = seed * 1664525u + 1013904223u;
                    px[k] = (uint16_t)((seed >> 8) & ((1u << f->bits) - 1u));
                }
                px[0] = (uint16_t)((1u << f->bits) - 1u);   /* extremes */
                px[n - 1] = 0;
                bytes = pack(f, px, n, raw);
                assert_int_equal(cdspd_pixfmt_image_bytes(f, w, h), bytes);
                /* one byte short: refused */
                assert_int_equal(cdspd_pixfmt_convert(f, raw, bytes - 1, w, h, 0, 0, NULL, out,
                                                      (size_t)w * 2, NULL, 0), -1);
                /* a padded destination row (stride w + 3 pixels) */
                if (f->out_bits == 8) {
                    assert_int_equal(cdspd_pixfmt_convert(f, raw, bytes, w, h, 0, 0, NULL, out8,
                                                          (size_t)w, NULL, 0), 0);
                    for (k = 0; k < n; k++)
                        assert_int_equal(out8[k], px[k]);
                    continue;
                }
                {
                    uint16_t padded[3 * 12];
                    int x, y;
                    assert_int_equal(cdspd_pixfmt_convert(f, raw, bytes, w, h, 0, 0, NULL, padded,
                                                          (size_t)(w + 3) * 2, NULL, 0), 0);
                    for (y = 0; y < h; y++)
                        for (x = 0; x < w; x++)
                            if (padded[y * (w + 3) + x] != px[y * w + x])
                                fail_msg("%s %dx%d (%d, %d): %u, expected %u", f->name, w, h, x, y,
                                         padded[y * (w + 3) + x], px[y * w + x]);
                }
            }
    }
}

/* --- Bayer ---------------------------------------------------------------- */

/* The mosaic of a grey scene through channel gains g (R, G, B) in format f
 * with the sensor's origin at parity (xp, yp): scene(x, y) in [0, 1]. */
typedef double (*scene_fn)(double x, double y);

static const double gains_unequal[3] = {0.55, 1.0, 0.8};

static uint8_t colour_of(const cdspd_pixfmt *f, int x, int y)
{
    /* from the name: the top-left 2 x 2 cell as two letters per row */
    static const char *cells[4] = {"RGGB", "GRBG", "GBRG", "BGGR"};
    char c = cells[f->order][2 * (y & 1) + (x & 1)];
    return (uint8_t)(c == 'R' ? 0 : c == 'G' ? 1 : 2);
}

static size_t mosaic(const cdspd_pixfmt *f, int w, int h, int xp, int yp, scene_fn scene,
                     const double g[3], uint8_t *out)
{
    double full = (double)((1u << f->bits) - 1u);
    int x, y;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double v = scene(x, y) * g[colour_of(f, x + xp, y + yp)] * full;
            unsigned q = (unsigned)(v + 0.5);
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            if (f->packing == CDSPD_PACK_8) {
                out[i] = (uint8_t)q;
            } else {
                out[2 * i] = (uint8_t)q;
                out[2 * i + 1] = (uint8_t)(q >> 8);
            }
        }
    return cdspd_pixfmt_image_bytes(f, w, h);
}

static double flat(double x, double y)
{
    (void)x;
    (void)y;
    return 0.6;
}

/* Step edges between pixel 9 and 10 (at 9.5): every channel sees both
 * sides equally often over an even width, so grey-world means are exact. */
static double step_x(double x, double y)
{
    (void)y;
    return x < 9.5 ? 0.2 : 0.8;
}

static double step_y(double x, double y)
{
    (void)x;
    return y < 9.5 ? 0.8 : 0.2;
}

static const char *bayer_names[] = {"BayerRG8", "BayerGR8", "BayerGB8", "BayerBG8",
                                    "BayerRG10", "BayerGR12", "BayerGB16", "BayerBG16"};

static void convert_bayer(const cdspd_pixfmt *f, const uint8_t *raw, size_t n, int w, int h, int xp,
                          int yp, const double *gains, uint16_t *out)
{
    uint32_t scratch[3 * MAXW];
    assert_true(cdspd_pixfmt_scratch_bytes(f, w) <= sizeof scratch);
    assert_int_equal(cdspd_pixfmt_convert(f, raw, n, w, h, xp, yp, gains, out, (size_t)w * 2, scratch,
                                          cdspd_pixfmt_scratch_bytes(f, w)), 0);
}

static void test_bayer_flat(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < sizeof bayer_names / sizeof bayer_names[0]; i++) {
        const cdspd_pixfmt *f = fmt(bayer_names[i]);
        int w, par;
        for (w = 5; w <= 8; w++)   /* odd and even widths */
            for (par = 0; par < 4; par++) {
                uint8_t raw[2 * MAXW * 7];
                uint16_t out[MAXW * 7];
                int h = 7, k, lo = 1 << 20, hi = 0, raw_lo = 1 << 20, raw_hi = 0;
                size_t n = mosaic(f, w, h, par & 1, par >> 1, flat, gains_unequal, raw);
                convert_bayer(f, raw, n, w, h, par & 1, par >> 1, NULL, out);
                for (k = 0; k < w * h; k++) {
                    int v = out[k];
                    int r = f->packing == CDSPD_PACK_8 ? raw[k] : raw[2 * k] | raw[2 * k + 1] << 8;
                    lo = v < lo ? v : lo;
                    hi = v > hi ? v : hi;
                    raw_lo = r < raw_lo ? r : raw_lo;
                    raw_hi = r > raw_hi ? r : raw_hi;
                    assert_true(v < 1 << f->out_bits);
                }
                /* the mosaic itself is a checker of (1 - 0.55) of its level;
                 * converted: flat within the rounding of the samples (half an
                 * input LSB each, times the 4 LSB of out_bits - bits = 2;
                 * measured: 0 or 1 output LSB) */
                assert_true(raw_hi - raw_lo > (raw_hi * 4) / 10);
                if (hi - lo > 1)
                    fail_msg("%s w %d parity %d: output spans %d..%d", f->name, w, par, lo, hi);
            }
    }
}

/* Half-height crossing along a row (x) or column: the linear interpolation
 * between the two samples around (lo + hi) / 2. */
static double crossing(const uint16_t *v, int n, int step)
{
    double lo = v[0], hi = v[0], mid;
    int i;
    for (i = 0; i < n; i++) {
        lo = v[i * step] < lo ? v[i * step] : lo;
        hi = v[i * step] > hi ? v[i * step] : hi;
    }
    mid = 0.5 * (lo + hi);
    for (i = 0; i + 1 < n; i++) {
        double a = v[i * step], b = v[(i + 1) * step];
        if ((a - mid) * (b - mid) <= 0 && a != b)
            return i + (mid - a) / (b - a);
    }
    return -1;
}

static void test_bayer_edges_stay(void **state)
{
    size_t i;
    double worst = 0;
    (void)state;
    for (i = 0; i < sizeof bayer_names / sizeof bayer_names[0]; i++) {
        const cdspd_pixfmt *f = fmt(bayer_names[i]);
        int par, g;
        for (par = 0; par < 4; par++)
            for (g = 0; g < 2; g++) {
                /* 20 x 20: 10 columns/rows each side of the edge */
                enum { W = 20, H = 20 };
                uint8_t raw[2 * W * H];
                uint16_t out[W * H];
                const double *gains = g ? gains_unequal : NULL; /* told, or measured */
                int k;
                size_t n = mosaic(f, W, H, par & 1, par >> 1, step_x, gains_unequal, raw);
                convert_bayer(f, raw, n, W, H, par & 1, par >> 1, gains, out);
                /* The binomial kernel is symmetric: the crossing of a step
                 * stays at 9.5. Error budget: sample rounding (0.5 LSB of
                 * 255 on a 0.6 step: 0.003 of the step, moving the crossing
                 * by 0.003 / slope 0.5 per px = 0.007 px; measured: 0.0007
                 * px at worst). The mosaic read as grey is off by 0.54 px
                 * with these gains (test_bayer_raw_would_fail). */
                for (k = 0; k < H; k++) {
                    double c = crossing(out + k * W, W, 1);
                    worst = fabs(c - 9.5) > worst ? fabs(c - 9.5) : worst;
                    if (c < 9.5 - 0.01 || c > 9.5 + 0.01)
                        fail_msg("%s parity %d gains %s row %d: edge at %.4f, not 9.5", f->name, par,
                                 g ? "given" : "measured", k, c);
                }
                n = mosaic(f, W, H, par & 1, par >> 1, step_y, gains_unequal, raw);
                convert_bayer(f, raw, n, W, H, par & 1, par >> 1, gains, out);
                for (k = 0; k < W; k++) {
                    double c = crossing(out + k, H, W);
                    worst = fabs(c - 9.5) > worst ? fabs(c - 9.5) : worst;
                    if (c < 9.5 - 0.01 || c > 9.5 + 0.01)
                        fail_msg("%s parity %d column %d: edge at %.4f, not 9.5", f->name, par, k, c);
                }
            }
    }
    print_message("Bayer step edges: worst crossing error %.4f px (tolerance 0.01)\n", worst);
}

/* The test above can fail: the same mosaic read as grey (no balance, no
 * kernel) puts the edge elsewhere in some rows. */
static void test_bayer_raw_would_fail(void **state)
{
    const cdspd_pixfmt *f = fmt("BayerRG8");
    enum { W = 20, H = 4 };
    uint8_t raw[W * H];
    uint16_t row[W];
    double worst = 0;
    int y, x;
    (void)state;
    mosaic(f, W, H, 0, 0, step_x, gains_unequal, raw);
    for (y = 0; y < H; y++) {
        double c;
        for (x = 0; x < W; x++)
            row[x] = raw[y * W + x];
        c = crossing(row, W, 1);
        if (c < 0 || (c - 9.5 > worst || 9.5 - c > worst))
            worst = c < 0 ? 99 : (c > 9.5 ? c - 9.5 : 9.5 - c);
    }
    print_message("mosaic read as grey: edge off by %.2f px\n", worst);
    assert_true(worst > 0.1);
}

/* A region cut from the sensor at an odd offset, converted with its
 * parity, gives the full frame's pixels away from the region's border
 * (the border is reflected inside the region, the full frame's is not). */
static void test_bayer_region_parity(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < sizeof bayer_names / sizeof bayer_names[0]; i++) {
        const cdspd_pixfmt *f = fmt(bayer_names[i]);
        enum { W = 20, H = 20 };
        uint8_t raw[2 * W * H], sub[2 * W * H];
        uint16_t full[W * H], part[W * H];
        double g[3] = {0.55, 1.0, 0.8};
        int ox, oy;
        size_t bpp = f->packing == CDSPD_PACK_8 ? 1 : 2;
        size_t n = mosaic(f, W, H, 0, 0, step_x, gains_unequal, raw);
        convert_bayer(f, raw, n, W, H, 0, 0, g, full);
        for (oy = 0; oy < 2; oy++)
            for (ox = 0; ox < 2; ox++) {
                int w = 13, h = 11, x, y;
                for (y = 0; y < h; y++)
                    memcpy(sub + (size_t)y * w * bpp, raw + ((size_t)(y + oy) * W + (size_t)(3 + ox)) * bpp,
                           (size_t)w * bpp);
                /* the camera names the sensor's phase; the region starts at
                 * (3 + ox, oy) */
                convert_bayer(f, sub, (size_t)w * h * bpp, w, h, 3 + ox, oy, g, part);
                for (y = 1; y < h - 1; y++)
                    for (x = 1; x < w - 1; x++)
                        if (part[y * w + x] != full[(y + oy) * W + x + 3 + ox])
                            fail_msg("%s offset (%d, %d) pixel (%d, %d): %u, full frame %u", f->name,
                                     3 + ox, oy, x, y, part[y * w + x], full[(y + oy) * W + x + 3 + ox]);
            }
    }
}

static void test_bayer_tiny_and_errors(void **state)
{
    const cdspd_pixfmt *f = fmt("BayerGB8");
    uint8_t raw[4] = {10, 20, 30, 40};
    uint16_t out[4];
    uint32_t scratch[6];
    double g1[3] = {1, 1, 1}, gbad[3] = {1, 0, 1};
    (void)state;
    /* 1 x 1 and 2 x 1 and 1 x 2: reflection onto itself, no read outside */
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 1, 1, 1, 0, 0, g1, out, 2, scratch, 12), 0);
    assert_int_equal(out[0], 40);   /* 16 weights on the one sample, 2 bits kept */
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 2, 2, 1, 0, 0, g1, out, 4, scratch, 24), 0);
    /* G B row: x0 = (2*10 + 2*20) * 4 / 16... = (20 + 2*10 + 20) * 4 / 4 = 60 */
    assert_int_equal(out[0], (20 + 2 * 10 + 20) * 4 / 4);
    assert_int_equal(out[1], (10 + 2 * 20 + 10) * 4 / 4);
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 2, 1, 2, 0, 0, g1, out, 2, scratch, 12), 0);
    /* a non-positive gain: no balance, as all 1 */
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 4, 2, 2, 0, 0, gbad, out, 4, scratch, 24), 0);
    /* scratch short, stride short, no scratch, no format */
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 4, 2, 2, 0, 0, NULL, out, 4, scratch, 23), -1);
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 4, 2, 2, 0, 0, NULL, out, 3, scratch, 24), -1);
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 4, 2, 2, 0, 0, NULL, out, 4, NULL, 0), -1);
    assert_int_equal(cdspd_pixfmt_convert(NULL, raw, 4, 2, 2, 0, 0, NULL, out, 4, scratch, 24), -1);
    assert_int_equal(cdspd_pixfmt_convert(f, raw, 4, 0, 2, 0, 0, NULL, out, 4, scratch, 24), -1);
    assert_int_equal(cdspd_pixfmt_scratch_bytes(fmt("Mono12p"), 100), 0);
    assert_int_equal(cdspd_pixfmt_scratch_bytes(f, 100), 1200);
}

/* --- RGB ------------------------------------------------------------------ */

static void test_rgb(void **state)
{
    /* two pixels: (R, G, B) = (100, 50, 20) and (200, 100, 40): the second
     * is twice the first, so a grey scene under gains 1 : 0.5 : 0.2 */
    static const uint8_t rgb[6] = {100, 50, 20, 200, 100, 40}, bgr[6] = {20, 50, 100, 40, 100, 200};
    const double g1[3] = {1, 1, 1};
    uint16_t out[2];
    double m[3];
    (void)state;
    assert_int_equal(cdspd_pixfmt_convert(fmt("RGB8"), rgb, 6, 2, 1, 0, 0, g1, out, 4, NULL, 0), 0);
    assert_int_equal(out[0], 100 + 2 * 50 + 20);     /* (R + 2G + B) / 4, 2 bits kept */
    assert_int_equal(out[1], 200 + 2 * 100 + 40);
    assert_int_equal(cdspd_pixfmt_convert(fmt("BGR8"), bgr, 6, 2, 1, 0, 0, g1, out, 4, NULL, 0), 0);
    assert_int_equal(out[0], 220);
    assert_int_equal(out[1], 440);
    /* measured balance: every channel scaled to the dimmest (B): R*0.2,
     * G*0.4 -> each pixel 4 B: 80 and 160 */
    assert_int_equal(cdspd_pixfmt_channel_means(fmt("RGB8"), rgb, 6, 2, 1, 0, 0, m), 0);
    assert_true(m[0] == 150 && m[1] == 75 && m[2] == 30);
    assert_int_equal(cdspd_pixfmt_convert(fmt("RGB8"), rgb, 6, 2, 1, 0, 0, NULL, out, 4, NULL, 0), 0);
    assert_int_equal(out[0], 80);
    assert_int_equal(out[1], 160);
    assert_int_equal(cdspd_pixfmt_convert(fmt("RGB8"), rgb, 5, 2, 1, 0, 0, NULL, out, 4, NULL, 0), -1);
    assert_int_equal(cdspd_pixfmt_channel_means(fmt("Mono8"), rgb, 6, 2, 1, 0, 0, m), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table),
        cmocka_unit_test(test_unpack_by_hand),
        cmocka_unit_test(test_unpack_all_sizes),
        cmocka_unit_test(test_bayer_flat),
        cmocka_unit_test(test_bayer_edges_stay),
        cmocka_unit_test(test_bayer_raw_would_fail),
        cmocka_unit_test(test_bayer_region_parity),
        cmocka_unit_test(test_bayer_tiny_and_errors),
        cmocka_unit_test(test_rgb),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
