/*
 * test_host_jpeg_tiff.c - JPEG (libjpeg-turbo) and TIFF (libtiff) frames of
 * host/: files written here with the same libraries in the layouts
 * cameras and image tools produce (gray and colour, 8 and 16 bit, strips
 * and tiles, compressed), read back through cdsp_host_image_decode, and
 * hostile files (truncated, corrupt, huge claimed sizes, float samples,
 * random damage) refused with a message that names the file.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"

#include <jpeglib.h>
#include <stdint.h>
#include <tiffio.h>

#include "cdsp_host.h"

#define W 48
#define H 32

/* A test pattern with both gradients and a sharp edge (what a frame has). */
static unsigned pattern(int x, int y, unsigned full)
{
    unsigned v = (unsigned)(x * 5 + y * 3) % 200u + (x > W / 2 ? 40u : 0u);
    return (unsigned)((unsigned long)v * full / 255ul);
}

static unsigned char *slurp_file(const char *path, size_t *len)
{
    void *buf;
    cdsp_host_err err;
    if (cdsp_host_read_file(path, 1u << 26, &buf, len, &err) != 0)
        fail_msg("%s", err.msg);
    return buf;
}

static void expect_fail(const void *buf, size_t len, const char *name, const char *what)
{
    cdsp_host_image im;
    cdsp_host_err err;
    int rc = cdsp_host_image_decode(buf, len, name, &im, &err);
    if (rc == 0) {
        cdsp_host_image_free(&im);
        fail_msg("%s decoded, wanted an error with \"%s\"", name, what);
    }
    if (strncmp(err.msg, name, strlen(name)) != 0 || !strstr(err.msg, what))
        fail_msg("%s: \"%s\", wanted \"%s\"", name, err.msg, what);
}

/* ---- JPEG ------------------------------------------------------------------ */

static unsigned char *jpeg_encode(int components, int quality, int progressive, size_t *len)
{
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr e;
    unsigned char *out = NULL, row[W * 3];
    unsigned long size = 0;
    c.err = jpeg_std_error(&e);
    jpeg_create_compress(&c);
    jpeg_mem_dest(&c, &out, &size);
    c.image_width = W;
    c.image_height = H;
    c.input_components = components;
    c.in_color_space = components == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, quality, TRUE);
    if (progressive)
        jpeg_simple_progression(&c);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < H) {
        int x, y = (int)c.next_scanline;
        JSAMPROW r = row;
        for (x = 0; x < W; x++) {
            unsigned g = pattern(x, y, 255);
            if (components == 1) {
                row[x] = (unsigned char)g;
            } else { /* a colour whose luma is g: equal channels */
                row[3 * x] = row[3 * x + 1] = row[3 * x + 2] = (unsigned char)g;
            }
        }
        jpeg_write_scanlines(&c, &r, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    *len = size;
    return out;
}

/* Quality 100 has quantisation steps of 1: what is left is the rounding of
 * the integer DCT (+-0.5 level each way) and, in colour, of YCbCr: at most
 * 1 grey level measured on this pattern in all four cases; 2 allowed. */
#define JPEG_Q100_TOL 2

static void jpeg_gray_and_colour(void **state)
{
    static const struct {
        int components, progressive;
    } cases[] = {{1, 0}, {1, 1}, {3, 0}, {3, 1}};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t len;
        unsigned char *buf = jpeg_encode(cases[i].components, 100, cases[i].progressive, &len);
        cdsp_host_image im;
        cdsp_host_err err;
        int x, y, worst = 0;
        if (cdsp_host_image_decode(buf, len, "f.jpg", &im, &err) != 0)
            fail_msg("case %zu: %s", i, err.msg);
        assert_int_equal(im.width, W);
        assert_int_equal(im.height, H);
        assert_int_equal(im.bits, 8);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                int d = (int)((const unsigned char *)im.data)[(size_t)y * im.stride + (size_t)x] -
                        (int)pattern(x, y, 255);
                worst = d < 0 ? (-d > worst ? -d : worst) : (d > worst ? d : worst);
            }
        if (worst > JPEG_Q100_TOL)
            fail_msg("case %zu: a pixel is %d grey levels off", i, worst);
        cdsp_host_image_free(&im);
        free(buf);
    }
}

static void jpeg_hostile(void **state)
{
    size_t len, i;
    unsigned char *buf = jpeg_encode(1, 90, 0, &len), *cut;
    cdsp_rng rng;
    int trial, ok = 0, bad = 0;
    (void)state;
    /* cut in the entropy-coded data: libjpeg would pad with grey and warn */
    expect_fail(buf, len / 2, "cut.jpg", "corrupt JPEG");
    expect_fail(buf, 20, "hdr.jpg", "JPEG");
    /* a header claiming 16000 x 16000 in a few hundred bytes */
    cut = malloc(len);
    memcpy(cut, buf, len);
    for (i = 0; i + 8 < len; i++)
        if (cut[i] == 0xff && cut[i + 1] == 0xc0) { /* SOF0: length, precision, H, W */
            cut[i + 5] = 0x3e, cut[i + 6] = 0x80, cut[i + 7] = 0x3e, cut[i + 8] = 0x80;
            break;
        }
    expect_fail(cut, len, "big.jpg", "more than its");
    /* random damage: an error naming the file, or a frame of the right size */
    cdsp_rng_seed(&rng, 7, 3);
    for (trial = 0; trial < 1500; trial++) {
        cdsp_host_image im;
        cdsp_host_err err;
        size_t k, flips = 1 + cdsp_rng_below(&rng, 3), n = len;
        memcpy(cut, buf, len);
        for (k = 0; k < flips; k++)
            cut[3 + cdsp_rng_below(&rng, (uint32_t)len - 3)] = (unsigned char)cdsp_rng_u32(&rng);
        if (trial % 4 == 0)
            n = 3 + cdsp_rng_below(&rng, (uint32_t)len - 3);
        if (cdsp_host_image_decode(cut, n, "m.jpg", &im, &err) == 0) {
            assert_true(im.width >= 1 && im.width <= CDSP_HOST_MAX_DIM);
            cdsp_host_image_free(&im);
            ok++;
        } else {
            assert_true(strncmp(err.msg, "m.jpg: ", 7) == 0);
            bad++;
        }
    }
    assert_true(ok > 50);
    assert_true(bad > 50);
    free(cut);
    free(buf);
}

/* ---- TIFF ------------------------------------------------------------------ */

typedef struct {
    int bits, spp, photometric, tiled, compression, sampleformat;
} tiff_kind;

static void tiff_write(const char *path, const tiff_kind *k)
{
    TIFF *t = TIFFOpen(path, "w");
    size_t bps = (size_t)k->bits / 8, rowbytes = (size_t)W * (size_t)k->spp * bps;
    unsigned char *rows = malloc(rowbytes * H);
    unsigned full = k->bits == 16 ? 65535u : 255u;
    int x, y, c;
    assert_non_null(t);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            for (c = 0; c < k->spp; c++) {
                unsigned v = pattern(x, y, full);
                size_t at = ((size_t)y * W + (size_t)x) * (size_t)k->spp + (size_t)c;
                if (k->photometric == PHOTOMETRIC_MINISWHITE)
                    v = full - v;
                if (c == 3)
                    v = full; /* opaque alpha */
                if (bps == 1)
                    rows[at] = (unsigned char)v;
                else
                    ((uint16_t *)(void *)rows)[at] = (uint16_t)v;
            }
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, (uint32_t)W);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, (uint32_t)H);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, (uint16_t)k->bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, (uint16_t)k->spp);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, (uint16_t)k->photometric);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, (uint16_t)PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, (uint16_t)k->compression);
    if (k->sampleformat)
        TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, (uint16_t)k->sampleformat);
    if (k->spp == 4) {
        uint16_t extra = EXTRASAMPLE_UNASSALPHA;
        TIFFSetField(t, TIFFTAG_EXTRASAMPLES, 1, &extra);
    }
    if (k->tiled) {
        uint32_t tx, ty, r;
        unsigned char *tile = calloc(16 * 16, (size_t)k->spp * bps);
        TIFFSetField(t, TIFFTAG_TILEWIDTH, 16u);
        TIFFSetField(t, TIFFTAG_TILELENGTH, 16u);
        for (ty = 0; ty < H; ty += 16)
            for (tx = 0; tx < W; tx += 16) {
                for (r = 0; r < 16; r++)
                    memcpy(tile + r * 16 * k->spp * bps,
                           rows + (ty + r) * rowbytes + tx * k->spp * bps, 16 * k->spp * bps);
                assert_true(TIFFWriteTile(t, tile, tx, ty, 0, 0) >= 0);
            }
        free(tile);
    } else {
        TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 8u);
        for (y = 0; y < H; y++)
            assert_int_equal(TIFFWriteScanline(t, rows + (size_t)y * rowbytes, (uint32_t)y, 0), 1);
    }
    TIFFClose(t);
    free(rows);
}

static void tiff_layouts(void **state)
{
    static const tiff_kind kinds[] = {
        {8, 1, PHOTOMETRIC_MINISBLACK, 0, COMPRESSION_NONE, 0},
        {16, 1, PHOTOMETRIC_MINISBLACK, 0, COMPRESSION_NONE, 0},
        {8, 1, PHOTOMETRIC_MINISWHITE, 0, COMPRESSION_LZW, 0},
        {16, 1, PHOTOMETRIC_MINISBLACK, 1, COMPRESSION_ADOBE_DEFLATE, 0},
        {8, 3, PHOTOMETRIC_RGB, 0, COMPRESSION_PACKBITS, 0},
        {16, 3, PHOTOMETRIC_RGB, 1, COMPRESSION_NONE, 0},
        {8, 4, PHOTOMETRIC_RGB, 0, COMPRESSION_LZW, 0},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        const char *path = tt_path("f.tif");
        cdsp_host_image im;
        cdsp_host_err err;
        unsigned full = kinds[i].bits == 16 ? 65535u : 255u;
        int x, y;
        tiff_write(path, &kinds[i]);
        if (cdsp_host_image_read(path, &im, &err) != 0)
            fail_msg("kind %zu: %s", i, err.msg);
        assert_int_equal(im.width, W);
        assert_int_equal(im.height, H);
        assert_int_equal(im.bits, kinds[i].bits);
        /* lossless codecs and equal channels: exact */
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                const unsigned char *row = (const unsigned char *)im.data + (size_t)y * im.stride;
                unsigned got = im.bits == 16 ? ((const uint16_t *)(const void *)row)[x] : row[x];
                if (got != pattern(x, y, full))
                    fail_msg("kind %zu: pixel (%d, %d) is %u, wanted %u", i, x, y, got,
                             pattern(x, y, full));
            }
        cdsp_host_image_free(&im);
    }
}

static void tiff_hostile(void **state)
{
    static const tiff_kind gray8 = {8, 1, PHOTOMETRIC_MINISBLACK, 0, COMPRESSION_NONE, 0};
    static const tiff_kind floats = {16, 1, PHOTOMETRIC_MINISBLACK, 0, COMPRESSION_NONE,
                                     SAMPLEFORMAT_IEEEFP};
    const char *path = tt_path("h.tif");
    unsigned char *buf, *cut;
    size_t len, i;
    cdsp_rng rng;
    int trial, ok = 0, bad = 0;
    (void)state;
    tiff_write(path, &floats);
    buf = slurp_file(path, &len);
    expect_fail(buf, len, "f.tif", "floating-point");
    free(buf);

    tiff_write(path, &gray8);
    buf = slurp_file(path, &len);
    expect_fail(buf, 8, "short.tif", "TIFF");
    /* the raster cut off: a strip cannot be read */
    expect_fail(buf, len - (size_t)W * H / 2, "cut.tif", "TIFF");
    /* width 16000 claimed in a small file: the IFD's ImageWidth (tag 256) */
    cut = malloc(len);
    memcpy(cut, buf, len);
    for (i = 8; i + 12 <= len; i += 2)
        if (cut[i] == 0 && cut[i + 1] == 1 && cut[i + 2] == 3 && cut[i + 3] == 0) {
            /* little-endian tag 256, type SHORT (3) or LONG (4): value at +8 */
            cut[i + 8] = 0x80, cut[i + 9] = 0x3e;
            break;
        }
    /* (the IFD may store the width as LONG: tag 256 = 00 01 04 00) */
    if (i + 12 > len)
        for (i = 8; i + 12 <= len; i += 2)
            if (cut[i] == 0 && cut[i + 1] == 1 && cut[i + 2] == 4 && cut[i + 3] == 0) {
                cut[i + 8] = 0x80, cut[i + 9] = 0x3e;
                break;
            }
    assert_true(i + 12 <= len);
    {
        cdsp_host_image im;
        cdsp_host_err err;
        assert_true(cdsp_host_image_decode(cut, len, "wide.tif", &im, &err) != 0);
        assert_true(strncmp(err.msg, "wide.tif: ", 10) == 0);
    }
    cdsp_rng_seed(&rng, 11, 5);
    for (trial = 0; trial < 1500; trial++) {
        cdsp_host_image im;
        cdsp_host_err err;
        size_t k, flips = 1 + cdsp_rng_below(&rng, 3), n = len;
        memcpy(cut, buf, len);
        for (k = 0; k < flips; k++) /* the header and the IFD, mostly */
            cut[4 + cdsp_rng_below(&rng, (uint32_t)(trial % 2 ? len - 4 : 200))] =
                (unsigned char)cdsp_rng_u32(&rng);
        if (trial % 4 == 0)
            n = 4 + cdsp_rng_below(&rng, (uint32_t)len - 4);
        if (cdsp_host_image_decode(cut, n, "m.tif", &im, &err) == 0) {
            assert_true(im.width >= 1 && im.width <= CDSP_HOST_MAX_DIM);
            cdsp_host_image_free(&im);
            ok++;
        } else {
            assert_true(strncmp(err.msg, "m.tif: ", 7) == 0);
            bad++;
        }
    }
    assert_true(ok > 50);
    assert_true(bad > 50);
    free(cut);
    free(buf);
}

static int teardown(void **state)
{
    char cmd[700];
    (void)state;
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tt_tmpdir());
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(jpeg_gray_and_colour),
        cmocka_unit_test(jpeg_hostile),
        cmocka_unit_test(tiff_layouts),
        cmocka_unit_test(tiff_hostile),
    };
    return cmocka_run_group_tests_name("host_jpeg_tiff", tests, NULL, teardown);
}
