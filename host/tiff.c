/*
 * tiff.c - TIFF frames through libtiff, read from memory (TIFFClientOpenExt
 * over the file's bytes). Gray 8 and 16 bit (min-is-black or min-is-white),
 * RGB/RGBA 8 and 16 bit converted to gray with Rec. 601 luma as the PNG
 * reader does, in strips or tiles, any compression libtiff decodes. Other
 * layouts (palette, 1-bit, float, separate planes, YCbCr, ...) that are
 * 8 bit deep go through TIFFReadRGBAImage; the rest are refused by name.
 * Errors and warnings come back through per-file handlers (libtiff 4.5's
 * TIFFOpenOptions: no global state), and libtiff's own allocations are
 * capped, so a hostile file is an error naming it, not a crash or a huge
 * allocation. Only the first image (directory) is read.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tiffio.h>

#define fail(err, rc, name, ...) cdsp_host__fail(err, rc, (name) ? (name) : "(image)", __VA_ARGS__)

/* Raster bytes a TIFF of `len` bytes may claim. Deflate expands at most
 * 1032:1, LZW's 12-bit codes for runs of one byte value reach about
 * 2700:1; 4096:1 is above every codec a camera writes and still refuses a
 * few hundred bytes of header claiming a 512 MiB raster. */
#define TIFF_MAX_EXPANSION 4096u

typedef struct {
    const unsigned char *p;
    tmsize_t len, pos;
    char msg[400]; /* libtiff's first error */
    int warned;    /* an error was reported */
} memfile;

static tmsize_t mem_read(thandle_t h, void *buf, tmsize_t n)
{
    memfile *m = (memfile *)h;
    tmsize_t k = m->pos >= m->len ? 0 : (m->len - m->pos < n ? m->len - m->pos : n);
    if (k > 0)
        memcpy(buf, m->p + m->pos, (size_t)k);
    m->pos += k;
    return k;
}

static tmsize_t mem_write(thandle_t h, void *buf, tmsize_t n)
{
    (void)h;
    (void)buf;
    (void)n;
    return -1;
}

static toff_t mem_seek(thandle_t h, toff_t off, int whence)
{
    memfile *m = (memfile *)h;
    uint64_t base = whence == SEEK_CUR ? (uint64_t)m->pos : whence == SEEK_END ? (uint64_t)m->len : 0;
    if (off > (uint64_t)INT64_MAX - base)
        return (toff_t)-1;
    m->pos = (tmsize_t)(base + off);
    return (toff_t)m->pos;
}

static int mem_close(thandle_t h)
{
    (void)h;
    return 0;
}

static toff_t mem_size(thandle_t h)
{
    return (toff_t)((memfile *)h)->len;
}

static int mem_map(thandle_t h, void **base, toff_t *size)
{
    memfile *m = (memfile *)h;
    *base = (void *)(uintptr_t)m->p; /* read-only use: libtiff maps for reading */
    *size = (toff_t)m->len;
    return 1;
}

static void mem_unmap(thandle_t h, void *base, toff_t size)
{
    (void)h;
    (void)base;
    (void)size;
}

/* Errors: keep the first; decoding fails on it. */
static int on_error(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap)
{
    memfile *m = user;
    (void)tif;
    if (!m->warned) {
        int k = snprintf(m->msg, sizeof m->msg, "%s: ", module ? module : "libtiff");
        if (k < 0 || (size_t)k >= sizeof m->msg)
            k = 0;
        vsnprintf(m->msg + k, sizeof m->msg - (size_t)k, fmt, ap);
        m->warned = 1;
    }
    return 1; /* handled: libtiff's global handlers are not called */
}

/* Warnings (an unknown private tag, an odd but readable directory) are
 * everyday in camera files and do not spoil the pixels: dropped. */
static int on_warning(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap)
{
    (void)tif;
    (void)user;
    (void)module;
    (void)fmt;
    (void)ap;
    return 1;
}

/* Sample (x, c) of a decoded row in `bits` bits, as 16 bit. */
static unsigned sample(const unsigned char *row, int bits, size_t i)
{
    if (bits == 8)
        return row[i];
    return ((const uint16_t *)(const void *)row)[i];
}

/* One decoded row of w pixels of spp samples into the image's row y. */
static void put_row(cdsp_host_image *out, int y, const unsigned char *src, int bits, int spp,
                    int white_is_zero)
{
    unsigned char *d8 = (unsigned char *)out->data + (size_t)y * out->stride;
    uint16_t *d16 = (uint16_t *)(void *)d8;
    unsigned full = bits == 8 ? 255u : 65535u;
    int x;
    for (x = 0; x < out->width; x++) {
        unsigned long v;
        if (spp >= 3)
            v = (299ul * sample(src, bits, (size_t)x * (size_t)spp) +
                 587ul * sample(src, bits, (size_t)x * (size_t)spp + 1) +
                 114ul * sample(src, bits, (size_t)x * (size_t)spp + 2) + 500ul) / 1000ul;
        else
            v = sample(src, bits, (size_t)x * (size_t)spp);
        if (white_is_zero)
            v = full - v;
        if (bits == 8)
            d8[x] = (unsigned char)v;
        else
            d16[x] = (uint16_t)v;
    }
}

static int read_direct(TIFF *tif, cdsp_host_image *out, int bits, int spp, int white_is_zero)
{
    int y;
    if (TIFFIsTiled(tif)) {
        uint32_t tw = 0, th = 0, tx, ty;
        tmsize_t ts = TIFFTileSize(tif);
        unsigned char *tile;
        size_t bpp = (size_t)spp * (size_t)(bits / 8);
        if (!TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tw) || !TIFFGetField(tif, TIFFTAG_TILELENGTH, &th) ||
            tw == 0 || th == 0 || ts <= 0 || (uint64_t)tw * th * bpp > (uint64_t)ts)
            return -1;
        tile = malloc((size_t)ts);
        if (!tile)
            return -2;
        for (ty = 0; ty < (uint32_t)out->height; ty += th)
            for (tx = 0; tx < (uint32_t)out->width; tx += tw) {
                uint32_t r, nx = (uint32_t)out->width - tx < tw ? (uint32_t)out->width - tx : tw;
                if (TIFFReadTile(tif, tile, tx, ty, 0, 0) < 0) {
                    free(tile);
                    return -1;
                }
                for (r = 0; r < th && ty + r < (uint32_t)out->height; r++) {
                    /* the tile's row r into the frame's columns tx.. */
                    cdsp_host_image one = *out;
                    one.width = (int)nx;
                    one.data = (unsigned char *)out->data + (size_t)tx * (bits / 8);
                    put_row(&one, (int)(ty + r), tile + (size_t)r * tw * bpp, bits, spp,
                            white_is_zero);
                }
            }
        free(tile);
        return 0;
    }
    {
        tmsize_t ss = TIFFScanlineSize(tif);
        unsigned char *line;
        if (ss <= 0 || (uint64_t)ss < (uint64_t)out->width * (uint64_t)spp * (uint64_t)(bits / 8))
            return -1;
        line = malloc((size_t)ss);
        if (!line)
            return -2;
        for (y = 0; y < out->height; y++) {
            if (TIFFReadScanline(tif, line, (uint32_t)y, 0) < 0) {
                free(line);
                return -1;
            }
            put_row(out, y, line, bits, spp, white_is_zero);
        }
        free(line);
    }
    return 0;
}

/* 8-bit layouts libtiff converts itself (palette, 1-bit, YCbCr, planar,
 * CMYK...) to ABGR, then to gray. */
static int read_rgba(TIFF *tif, cdsp_host_image *out)
{
    size_t npx = (size_t)out->width * (size_t)out->height, i;
    uint32_t *px = malloc(npx * sizeof *px);
    unsigned char *d = out->data;
    if (!px)
        return -2;
    if (!TIFFReadRGBAImageOriented(tif, (uint32_t)out->width, (uint32_t)out->height, px,
                                   ORIENTATION_TOPLEFT, 1)) {
        free(px);
        return -1;
    }
    for (i = 0; i < npx; i++)
        d[i] = (unsigned char)((299u * TIFFGetR(px[i]) + 587u * TIFFGetG(px[i]) +
                                114u * TIFFGetB(px[i]) + 500u) / 1000u);
    free(px);
    return 0;
}

int cdsp_host_tiff_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                          cdsp_host_err *err)
{
    memfile m;
    TIFFOpenOptions *opts;
    TIFF *tif;
    uint32_t w = 0, h = 0;
    uint16_t bits = 1, spp = 1, fmt = SAMPLEFORMAT_UINT, photo = PHOTOMETRIC_MINISBLACK,
             planar = PLANARCONFIG_CONTIG;
    int rc = CDSP_HOST_OK, direct, k;
    out->data = NULL;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty file");
    memset(&m, 0, sizeof m);
    m.p = buf;
    m.len = (tmsize_t)len;
    opts = TIFFOpenOptionsAlloc();
    if (!opts)
        return fail(err, CDSP_HOST_E_NOMEM, name, "out of memory (TIFF decoder)");
    TIFFOpenOptionsSetErrorHandlerExtR(opts, on_error, &m);
    TIFFOpenOptionsSetWarningHandlerExtR(opts, on_warning, &m);
    /* no single libtiff buffer beyond the largest 16-bit RGBA row band a
     * frame needs; a strip claiming more is refused by libtiff itself */
    TIFFOpenOptionsSetMaxSingleMemAlloc(opts, (tmsize_t)CDSP_HOST_MAX_DIM * CDSP_HOST_MAX_DIM * 2);
    tif = TIFFClientOpenExt(name ? name : "(image)", "r", (thandle_t)&m, mem_read, mem_write,
                            mem_seek, mem_close, mem_size, mem_map, mem_unmap, opts);
    TIFFOpenOptionsFree(opts);
    if (!tif)
        return fail(err, CDSP_HOST_E_FORMAT, name, "not a readable TIFF: %s",
                    m.warned ? m.msg : "unknown error");
    TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &h);
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &spp);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &fmt);
    TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
    if (!TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photo))
        photo = spp >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;
    if (w < 1 || h < 1 || w > CDSP_HOST_MAX_DIM || h > CDSP_HOST_MAX_DIM) {
        rc = fail(err, CDSP_HOST_E_LIMIT, name, "TIFF size %ux%u outside 1..%d", (unsigned)w,
                  (unsigned)h, CDSP_HOST_MAX_DIM);
        goto done;
    }
    if (fmt != SAMPLEFORMAT_UINT || (bits != 8 && bits != 16 && bits > 8)) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name,
                  "TIFF of %u-bit %s samples (8 or 16-bit unsigned integers supported)",
                  (unsigned)bits, fmt == SAMPLEFORMAT_IEEEFP ? "floating-point"
                                  : fmt == SAMPLEFORMAT_INT  ? "signed" : "unsigned");
        goto done;
    }
    if ((double)w * h * spp * (bits > 8 ? 2 : 1) > (double)TIFF_MAX_EXPANSION * len) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name,
                  "TIFF claims %ux%u pixels, more than its %zu bytes can hold", (unsigned)w,
                  (unsigned)h, len);
        goto done;
    }
    /* read directly: 8/16-bit gray or RGB(A), samples interleaved */
    direct = (bits == 8 || bits == 16) && planar == PLANARCONFIG_CONTIG &&
             (((photo == PHOTOMETRIC_MINISBLACK || photo == PHOTOMETRIC_MINISWHITE) && spp >= 1 &&
               spp <= 2) ||
              (photo == PHOTOMETRIC_RGB && spp >= 3 && spp <= 4));
    if (!direct && bits == 16) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name,
                  "16-bit TIFF with photometric %u, %u samples per pixel%s: only gray and RGB "
                  "are supported at 16 bits", (unsigned)photo, (unsigned)spp,
                  planar == PLANARCONFIG_SEPARATE ? " in separate planes" : "");
        goto done;
    }
    rc = cdsp_host_image_alloc(out, (int)w, (int)h, bits == 16 ? 16 : 8, NULL);
    if (rc) {
        rc = fail(err, rc, name, "out of memory for %ux%u pixels", (unsigned)w, (unsigned)h);
        goto done;
    }
    k = direct ? read_direct(tif, out, bits, spp, photo == PHOTOMETRIC_MINISWHITE)
               : read_rgba(tif, out);
    if (k == -2)
        rc = fail(err, CDSP_HOST_E_NOMEM, name, "out of memory decoding the TIFF");
    else if (k != 0 || m.warned)
        rc = fail(err, CDSP_HOST_E_FORMAT, name, "corrupt TIFF: %s",
                  m.warned ? m.msg : "cannot decode the image data");
    if (rc)
        cdsp_host_image_free(out);
done:
    TIFFClose(tif);
    return rc;
}
