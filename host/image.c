/*
 * image.c - frame files: PGM P5 read and written by hand (the format is a
 * short text header and a raw raster), PNG through libspng. Every size is
 * checked against CDSP_HOST_MAX_DIM before anything is allocated, and a
 * file's length against the raster it claims before the pixels are read, so
 * a hostile header cannot make us allocate more than its own file backs:
 * for PGM the raster itself, for PNG what its image data can inflate to
 * (at most 1032 times its length), decoded into at most 4 bytes a pixel
 * (RGBA) and then the gray image.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_internal.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <spng.h>

/* Messages name the file, or this when no name was given. */
#define fail(err, rc, name, ...) cdsp_host__fail(err, rc, (name) ? (name) : "(image)", __VA_ARGS__)

/* ---- images ------------------------------------------------------------ */

int cdsp_host_image_alloc(cdsp_host_image *im, int width, int height, int bits,
                          cdsp_host_err *err)
{
    size_t bpp;
    im->data = NULL;
    im->width = im->height = 0;
    im->bits = 0;
    im->stride = 0;
    if (width < 1 || height < 1 || width > CDSP_HOST_MAX_DIM || height > CDSP_HOST_MAX_DIM)
        return fail(err, CDSP_HOST_E_LIMIT, "(image)", "size %dx%d outside 1..%d", width, height,
                    CDSP_HOST_MAX_DIM);
    if (bits < 1 || bits > 16)
        return fail(err, CDSP_HOST_E_FORMAT, "(image)", "%d bits per pixel (1..16 supported)",
                    bits);
    bpp = bits <= 8 ? 1u : 2u;
    im->data = calloc((size_t)width * (size_t)height, bpp);
    if (!im->data)
        return fail(err, CDSP_HOST_E_NOMEM, "(image)", "out of memory for %dx%d pixels", width,
                    height);
    im->width = width;
    im->height = height;
    im->bits = bits <= 8 ? 8 : bits;
    im->stride = (size_t)width * bpp;
    return CDSP_HOST_OK;
}

void cdsp_host_image_free(cdsp_host_image *im)
{
    if (!im)
        return;
    free(im->data);
    im->data = NULL;
    im->width = im->height = 0;
}

cdsp_image cdsp_host_image_view(const cdsp_host_image *im)
{
    cdsp_image v;
    v.data = im->data;
    v.width = im->width;
    v.height = im->height;
    v.stride = im->stride;
    v.bits = im->bits;
    return v;
}

double cdsp_host_image_at(const cdsp_host_image *im, int x, int y)
{
    const unsigned char *row = (const unsigned char *)im->data + (size_t)y * im->stride;
    if (im->bits <= 8)
        return row[x] / 255.0;
    return ((const uint16_t *)(const void *)row)[x] / (double)((1u << im->bits) - 1u);
}

/* ---- whole files -------------------------------------------------------- */

int cdsp_host_read_file(const char *path, size_t max_bytes, void **buf, size_t *len,
                        cdsp_host_err *err)
{
    FILE *f;
    struct stat st;
    unsigned char *b = NULL;
    size_t cap = 0, n = 0;
    *buf = NULL;
    *len = 0;
    f = fopen(path, "rb");
    if (!f)
        return fail(err, CDSP_HOST_E_IO, path, "cannot open: %s", strerror(errno));
    if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
        fclose(f);
        return fail(err, CDSP_HOST_E_IO, path, "is a directory");
    }
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode)) {
        if ((uintmax_t)st.st_size > (uintmax_t)max_bytes) {
            fclose(f);
            return fail(err, CDSP_HOST_E_LIMIT, path, "file of %jd bytes exceeds the limit of %zu",
                        (intmax_t)st.st_size, max_bytes);
        }
        cap = (size_t)st.st_size + 1;
    }
    if (cap < 4096)
        cap = 4096;
    for (;;) {
        size_t got;
        if (n + 1 >= cap || !b) {
            unsigned char *nb;
            if (b) {
                if (cap > max_bytes + 1) {
                    free(b);
                    fclose(f);
                    return fail(err, CDSP_HOST_E_LIMIT, path,
                                "file exceeds the limit of %zu bytes", max_bytes);
                }
                cap = cap * 2 > max_bytes + 2 ? max_bytes + 2 : cap * 2;
            }
            nb = realloc(b, cap);
            if (!nb) {
                free(b);
                fclose(f);
                return fail(err, CDSP_HOST_E_NOMEM, path, "out of memory reading the file");
            }
            b = nb;
        }
        got = fread(b + n, 1, cap - 1 - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f)) {
                int e = errno;
                free(b);
                fclose(f);
                return fail(err, CDSP_HOST_E_IO, path, "read error: %s", strerror(e));
            }
            break;
        }
        if (n > max_bytes) {
            free(b);
            fclose(f);
            return fail(err, CDSP_HOST_E_LIMIT, path, "file exceeds the limit of %zu bytes",
                        max_bytes);
        }
    }
    fclose(f);
    b[n] = 0;
    *buf = b;
    *len = n;
    return CDSP_HOST_OK;
}

/* A frame file can be as large as the largest 16-bit raster plus a header. */
static size_t max_frame_bytes(void)
{
    return (size_t)CDSP_HOST_MAX_DIM * CDSP_HOST_MAX_DIM * 2u + CDSP_HOST_PGM_MAX_HEADER;
}

/* ---- PGM ---------------------------------------------------------------- */

typedef struct {
    const unsigned char *p;
    size_t len, pos;
} cursor;

/* Next header character; a comment ('#' to the end of its line) reads as
 * the one newline that ends it. -1 at the end of the buffer, -2 past the
 * header limit. */
static int hdr_getc(cursor *c)
{
    int ch;
    if (c->pos >= CDSP_HOST_PGM_MAX_HEADER)
        return -2;
    if (c->pos >= c->len)
        return -1;
    ch = c->p[c->pos++];
    if (ch == '#') {
        while (c->pos < c->len && c->p[c->pos] != '\n' && c->p[c->pos] != '\r') {
            if (c->pos >= CDSP_HOST_PGM_MAX_HEADER)
                return -2;
            c->pos++;
        }
        if (c->pos >= c->len)
            return -1;
        c->pos++;
        return '\n';
    }
    return ch;
}

static int is_ws(int ch)
{
    return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\v' || ch == '\f' || ch == '\r';
}

static int printable(int ch)
{
    return ch >= 0x20 && ch < 0x7f;
}

/* One header number (after whitespace and comments), followed by one
 * whitespace character (consumed). */
static int hdr_uint(cursor *c, const char *name, const char *what, unsigned long max,
                    unsigned long *out, cdsp_host_err *err)
{
    unsigned long v = 0;
    int ch, digits = 0;
    do
        ch = hdr_getc(c);
    while (is_ws(ch));
    for (;;) {
        if (ch == -2)
            return fail(err, CDSP_HOST_E_LIMIT, name, "PGM header longer than %d bytes",
                        CDSP_HOST_PGM_MAX_HEADER);
        if (ch < '0' || ch > '9')
            break;
        if (++digits > 9)
            return fail(err, CDSP_HOST_E_LIMIT, name, "PGM %s has too many digits", what);
        v = v * 10u + (unsigned long)(ch - '0');
        ch = hdr_getc(c);
    }
    if (digits == 0) {
        if (ch == -1)
            return fail(err, CDSP_HOST_E_FORMAT, name, "truncated PGM header: no %s", what);
        if (printable(ch))
            return fail(err, CDSP_HOST_E_FORMAT, name, "bad PGM %s: '%c' where a number belongs",
                        what, ch);
        return fail(err, CDSP_HOST_E_FORMAT, name,
                    "bad PGM %s: byte 0x%02x where a number belongs", what, ch);
    }
    if (ch == -1)
        return fail(err, CDSP_HOST_E_FORMAT, name, "truncated PGM header after the %s", what);
    if (!is_ws(ch)) {
        if (printable(ch))
            return fail(err, CDSP_HOST_E_FORMAT, name, "bad PGM %s: unexpected '%c' after %lu",
                        what, ch, v);
        return fail(err, CDSP_HOST_E_FORMAT, name, "bad PGM %s: unexpected byte 0x%02x after %lu",
                    what, ch, v);
    }
    if (v > max)
        return fail(err, CDSP_HOST_E_LIMIT, name, "PGM %s %lu exceeds the limit %lu", what, v, max);
    *out = v;
    return CDSP_HOST_OK;
}

int cdsp_host_pgm_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                         cdsp_host_err *err)
{
    cursor c;
    unsigned long w, h, maxval, v, full;
    size_t bps, need, i, npx;
    const unsigned char *raster;
    int rc, bits;
    out->data = NULL;
    c.p = buf;
    c.len = len;
    c.pos = 0;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty file");
    if (len < 2 || c.p[0] != 'P')
        return fail(err, CDSP_HOST_E_FORMAT, name, "not a PGM file (no P5 magic)");
    switch (c.p[1]) {
    case '5':
        break;
    case '2':
        return fail(err, CDSP_HOST_E_FORMAT, name,
                    "plain (ASCII) PGM P2 is not supported, only binary P5");
    case '1': case '4':
        return fail(err, CDSP_HOST_E_FORMAT, name, "a PBM bitmap (P%c), not a PGM gray image",
                    c.p[1]);
    case '3': case '6':
        return fail(err, CDSP_HOST_E_FORMAT, name,
                    "a PPM color image (P%c), not a PGM gray image (convert with ppmtopgm)",
                    c.p[1]);
    case '7':
        return fail(err, CDSP_HOST_E_FORMAT, name, "a PAM image (P7), not a PGM (P5)");
    default:
        return fail(err, CDSP_HOST_E_FORMAT, name, "not a PGM file (no P5 magic)");
    }
    c.pos = 2;
    if (c.pos < c.len && !is_ws(c.p[c.pos]) && c.p[c.pos] != '#')
        return fail(err, CDSP_HOST_E_FORMAT, name, "not a PGM file (no whitespace after P5)");
    rc = hdr_uint(&c, name, "width", CDSP_HOST_MAX_DIM, &w, err);
    if (rc)
        return rc;
    rc = hdr_uint(&c, name, "height", CDSP_HOST_MAX_DIM, &h, err);
    if (rc)
        return rc;
    rc = hdr_uint(&c, name, "maxval", 65535, &maxval, err);
    if (rc)
        return rc;
    if (w == 0 || h == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "PGM image has zero size (%lux%lu)", w, h);
    if (maxval == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "PGM maxval 0 (must be 1..65535)");

    bps = maxval < 256 ? 1u : 2u;
    npx = (size_t)w * (size_t)h;
    need = npx * bps;
    if (c.len - c.pos < need)
        return fail(err, CDSP_HOST_E_FORMAT, name,
                    "truncated PGM raster: %lux%lu at %zu byte%s per pixel needs %zu bytes, "
                    "the file has %zu",
                    w, h, bps, bps == 1 ? "" : "s", need, c.len - c.pos);
    raster = c.p + c.pos;

    /* depth kept: 2^bits - 1 >= maxval, bits 8 for one-byte samples */
    bits = 8;
    if (bps == 2)
        while (bits < 16 && ((1ul << bits) - 1ul) < maxval)
            bits++;
    full = (1ul << bits) - 1ul;
    rc = cdsp_host_image_alloc(out, (int)w, (int)h, bits, NULL);
    if (rc)
        return fail(err, rc, name, "out of memory for %lux%lu pixels", w, h);
    if (bps == 1) {
        unsigned char *d = out->data;
        for (i = 0; i < npx; i++) {
            v = raster[i];
            if (v > maxval)
                goto above;
            d[i] = (unsigned char)(maxval == full ? v : (v * full + maxval / 2) / maxval);
        }
    } else {
        uint16_t *d = out->data;
        for (i = 0; i < npx; i++) {
            v = ((unsigned long)raster[2 * i] << 8) | raster[2 * i + 1];
            if (v > maxval)
                goto above;
            d[i] = (uint16_t)(maxval == full ? v : (v * full + maxval / 2) / maxval);
        }
    }
    return CDSP_HOST_OK;
above:
    cdsp_host_image_free(out);
    return fail(err, CDSP_HOST_E_FORMAT, name, "PGM pixel (%zu, %zu) is %lu, above maxval %lu",
                i % w, i / w, v, maxval);
}

/* Read the whole file (bounded by the largest frame), then decode it; the
 * file's path names it in messages. */
typedef int (*decode_fn)(const void *, size_t, const char *, cdsp_host_image *, cdsp_host_err *);
static int read_and_decode(const char *path, decode_fn decode, cdsp_host_image *out,
                           cdsp_host_err *err)
{
    void *buf;
    size_t len;
    int rc = cdsp_host_read_file(path, max_frame_bytes(), &buf, &len, err);
    out->data = NULL;
    if (rc)
        return rc;
    rc = decode(buf, len, path, out, err);
    free(buf);
    return rc;
}

int cdsp_host_pgm_read(const char *path, cdsp_host_image *out, cdsp_host_err *err)
{
    return read_and_decode(path, cdsp_host_pgm_decode, out, err);
}

static FILE *open_out(const char *path, cdsp_host_err *err)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        fail(err, CDSP_HOST_E_IO, path, "cannot create: %s", strerror(errno));
    return f;
}

static int close_out(FILE *f, const char *path, cdsp_host_err *err)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return fail(err, CDSP_HOST_E_IO, path, "write failed: %s", strerror(errno));
    return CDSP_HOST_OK;
}

int cdsp_host_pgm_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err)
{
    FILE *f;
    int y, x;
    unsigned long maxval;
    unsigned char *row;
    if (!im->data || im->bits < 1 || im->bits > 16)
        return fail(err, CDSP_HOST_E_FORMAT, path, "no image to write");
    maxval = im->bits <= 8 ? 255ul : (1ul << im->bits) - 1ul;
    row = malloc((size_t)im->width * 2u);
    if (!row)
        return fail(err, CDSP_HOST_E_NOMEM, path, "out of memory");
    f = open_out(path, err);
    if (!f) {
        free(row);
        return CDSP_HOST_E_IO;
    }
    fprintf(f, "P5\n%d %d\n%lu\n", im->width, im->height, maxval);
    for (y = 0; y < im->height; y++) {
        const unsigned char *src = (const unsigned char *)im->data + (size_t)y * im->stride;
        if (im->bits <= 8) {
            fwrite(src, 1, (size_t)im->width, f);
        } else {
            const uint16_t *s16 = (const uint16_t *)(const void *)src;
            for (x = 0; x < im->width; x++) {
                row[2 * x] = (unsigned char)(s16[x] >> 8);
                row[2 * x + 1] = (unsigned char)(s16[x] & 0xffu);
            }
            fwrite(row, 2, (size_t)im->width, f);
        }
    }
    free(row);
    return close_out(f, path, err);
}

/* ---- PNG ---------------------------------------------------------------- */

static int spng_fail(cdsp_host_err *err, const char *name, const char *what, int e)
{
    return fail(err, CDSP_HOST_E_FORMAT, name, "PNG %s: %s", what, spng_strerror(e));
}

/* libspng stops reading once the image data is complete, so a file cut
 * after its last IDAT byte decodes; walk the chunk lengths to the IEND
 * chunk to refuse such a truncated file too. */
static int png_has_iend(const unsigned char *p, size_t len)
{
    size_t pos = 8;
    while (len >= 12 && pos <= len - 12) {
        uint32_t n = ((uint32_t)p[pos] << 24) | ((uint32_t)p[pos + 1] << 16) |
                     ((uint32_t)p[pos + 2] << 8) | p[pos + 3];
        if (n > 0x7fffffffu || n > len - 12 - pos)
            return 0;
        if (memcmp(p + pos + 4, "IEND", 4) == 0)
            return 1;
        pos += 12u + n;
    }
    return 0;
}

/* Bytes of image data (IDAT chunks) in the file; chunk lengths walked as
 * in png_has_iend. */
static size_t png_idat_bytes(const unsigned char *p, size_t len)
{
    size_t pos = 8, sum = 0;
    while (len >= 12 && pos <= len - 12) {
        uint32_t n = ((uint32_t)p[pos] << 24) | ((uint32_t)p[pos + 1] << 16) |
                     ((uint32_t)p[pos + 2] << 8) | p[pos + 3];
        if (n > 0x7fffffffu || n > len - 12 - pos)
            break;
        if (memcmp(p + pos + 4, "IDAT", 4) == 0)
            sum += n;
        pos += 12u + n;
    }
    return sum;
}

/* Deflate expands at most 1032:1 (zlib's FAQ: 258-byte matches at one bit
 * each, plus block overhead). */
#define PNG_MAX_INFLATE 1032u

int cdsp_host_png_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                         cdsp_host_err *err)
{
    spng_ctx *ctx;
    struct spng_ihdr ihdr;
    size_t size, i, npx;
    void *tmp = NULL;
    int e, rc = CDSP_HOST_OK, fmt;
    out->data = NULL;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty file");
    ctx = spng_ctx_new(0);
    if (!ctx)
        return fail(err, CDSP_HOST_E_NOMEM, name, "out of memory (PNG decoder)");
    /* bounds before anything is inflated: image size, and ancillary chunks
     * (text, ICC profiles) at most 1 MiB each / 4 MiB in all */
    spng_set_image_limits(ctx, CDSP_HOST_MAX_DIM, CDSP_HOST_MAX_DIM);
    spng_set_chunk_limits(ctx, 1u << 20, 4u << 20);
    spng_set_crc_action(ctx, SPNG_CRC_ERROR, SPNG_CRC_ERROR);
    e = spng_set_png_buffer(ctx, buf, len);
    if (!e)
        e = spng_get_ihdr(ctx, &ihdr);
    if (e) {
        if (e == SPNG_EWIDTH || e == SPNG_EHEIGHT || e == SPNG_EUSER_WIDTH ||
            e == SPNG_EUSER_HEIGHT)
            rc = fail(err, CDSP_HOST_E_LIMIT, name, "PNG size outside 1..%d: %s",
                      CDSP_HOST_MAX_DIM, spng_strerror(e));
        else
            rc = spng_fail(err, name, "header", e);
        goto done;
    }
    {
        /* what the header claims against what the file can back, before
         * anything is allocated: the filtered raster is height x (1 + row
         * bytes), and inflating the IDAT bytes yields at most 1032 times
         * their length (a 69-byte file used to reserve 2 GiB) */
        static const unsigned channels[7] = {1, 0, 3, 1, 2, 0, 4};
        unsigned ch = ihdr.color_type < 7 ? channels[ihdr.color_type] : 0;
        double row = ceil((double)ihdr.width * ch * ihdr.bit_depth / 8.0) + 1.0;
        double need = row * (double)ihdr.height;
        size_t idat = png_idat_bytes(buf, len);
        if (ch == 0 || need > (double)PNG_MAX_INFLATE * (double)idat) {
            rc = fail(err, CDSP_HOST_E_FORMAT, name,
                      "PNG header claims %ux%u pixels (%.0f bytes of raster) but its %zu bytes "
                      "of image data cannot inflate to that",
                      ihdr.width, ihdr.height, need, idat);
            goto done;
        }
    }
    if (ihdr.color_type == SPNG_COLOR_TYPE_GRAYSCALE)
        fmt = ihdr.bit_depth == 16 ? SPNG_FMT_RAW : SPNG_FMT_G8;
    else
        fmt = ihdr.bit_depth == 16 ? SPNG_FMT_RGBA16 : SPNG_FMT_RGBA8;
    e = spng_decoded_image_size(ctx, fmt, &size);
    if (e) {
        rc = spng_fail(err, name, "decoded size", e);
        goto done;
    }
    tmp = malloc(size);
    if (!tmp) {
        rc = fail(err, CDSP_HOST_E_NOMEM, name, "out of memory for a %ux%u PNG", ihdr.width,
                  ihdr.height);
        goto done;
    }
    e = spng_decode_image(ctx, tmp, size, fmt, 0);
    if (e) {
        rc = spng_fail(err, name, "data", e);
        goto done;
    }
    if (!png_has_iend(buf, len)) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name, "truncated PNG: the file ends before IEND");
        goto done;
    }
    rc = cdsp_host_image_alloc(out, (int)ihdr.width, (int)ihdr.height,
                               ihdr.bit_depth == 16 ? 16 : 8, NULL);
    if (rc) {
        rc = fail(err, rc, name, "out of memory for %ux%u pixels", ihdr.width, ihdr.height);
        goto done;
    }
    npx = (size_t)ihdr.width * ihdr.height;
    if (fmt == SPNG_FMT_G8) {
        memcpy(out->data, tmp, npx);
    } else if (fmt == SPNG_FMT_RAW) {
        const unsigned char *s = tmp;
        uint16_t *d = out->data;
        for (i = 0; i < npx; i++)
            d[i] = (uint16_t)((s[2 * i] << 8) | s[2 * i + 1]);
    } else if (fmt == SPNG_FMT_RGBA8) {
        const unsigned char *s = tmp;
        unsigned char *d = out->data;
        for (i = 0; i < npx; i++)
            d[i] = (unsigned char)((299u * s[4 * i] + 587u * s[4 * i + 1] +
                                    114u * s[4 * i + 2] + 500u) / 1000u);
    } else {
        const uint16_t *s = tmp;
        uint16_t *d = out->data;
        for (i = 0; i < npx; i++)
            d[i] = (uint16_t)((299ul * s[4 * i] + 587ul * s[4 * i + 1] +
                               114ul * s[4 * i + 2] + 500ul) / 1000ul);
    }
done:
    free(tmp);
    spng_ctx_free(ctx);
    return rc;
}

int cdsp_host_png_read(const char *path, cdsp_host_image *out, cdsp_host_err *err)
{
    return read_and_decode(path, cdsp_host_png_decode, out, err);
}

static int png_encode(const char *path, const void *px, size_t len, int width, int height,
                      int color_type, int depth, cdsp_host_err *err)
{
    spng_ctx *ctx;
    struct spng_ihdr ihdr;
    FILE *f;
    int e, rc;
    if (width < 1 || height < 1 || width > CDSP_HOST_MAX_DIM || height > CDSP_HOST_MAX_DIM)
        return fail(err, CDSP_HOST_E_LIMIT, path, "size %dx%d outside 1..%d", width, height,
                    CDSP_HOST_MAX_DIM);
    f = open_out(path, err);
    if (!f)
        return CDSP_HOST_E_IO;
    ctx = spng_ctx_new(SPNG_CTX_ENCODER);
    if (!ctx) {
        fclose(f);
        return fail(err, CDSP_HOST_E_NOMEM, path, "out of memory (PNG encoder)");
    }
    memset(&ihdr, 0, sizeof ihdr);
    ihdr.width = (uint32_t)width;
    ihdr.height = (uint32_t)height;
    ihdr.color_type = (uint8_t)color_type;
    ihdr.bit_depth = (uint8_t)depth;
    e = spng_set_png_file(ctx, f);
    if (!e)
        e = spng_set_ihdr(ctx, &ihdr);
    if (!e)
        e = spng_encode_image(ctx, px, len, SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
    spng_ctx_free(ctx);
    rc = close_out(f, path, err);
    if (e)
        return fail(err, CDSP_HOST_E_IO, path, "PNG encoding failed: %s", spng_strerror(e));
    return rc;
}

int cdsp_host_png_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err)
{
    size_t npx, i;
    int y, x, rc;
    unsigned char *px;
    if (!im->data || im->bits < 1 || im->bits > 16)
        return fail(err, CDSP_HOST_E_FORMAT, path, "no image to write");
    npx = (size_t)im->width * (size_t)im->height;
    if (im->bits <= 8) {
        px = malloc(npx);
        if (!px)
            return fail(err, CDSP_HOST_E_NOMEM, path, "out of memory");
        for (y = 0; y < im->height; y++)
            memcpy(px + (size_t)y * im->width, (const unsigned char *)im->data + y * im->stride,
                   (size_t)im->width);
        rc = png_encode(path, px, npx, im->width, im->height, SPNG_COLOR_TYPE_GRAYSCALE, 8, err);
    } else {
        /* libspng takes 16-bit samples host-endian (SPNG_FMT_PNG) and
         * stores them big-endian; they span the full 16 bits (sBIT could
         * record fewer, but scaling is what every viewer expects) */
        unsigned long full = (1ul << im->bits) - 1ul;
        px = malloc(npx * 2u);
        if (!px)
            return fail(err, CDSP_HOST_E_NOMEM, path, "out of memory");
        i = 0;
        for (y = 0; y < im->height; y++) {
            const uint16_t *s = (const uint16_t *)(const void *)((const unsigned char *)im->data +
                                                                 (size_t)y * im->stride);
            for (x = 0; x < im->width; x++, i++) {
                unsigned long v = s[x] > full ? full : s[x];
                ((uint16_t *)(void *)px)[i] = (uint16_t)((v * 65535ul + full / 2) / full);
            }
        }
        rc = png_encode(path, px, npx * 2u, im->width, im->height, SPNG_COLOR_TYPE_GRAYSCALE, 16,
                        err);
    }
    free(px);
    return rc;
}

int cdsp_host_png_write_rgb(const char *path, const uint8_t *rgb, int width, int height,
                            cdsp_host_err *err)
{
    return png_encode(path, rgb, (size_t)width * (size_t)height * 3u, width, height,
                      SPNG_COLOR_TYPE_TRUECOLOR, 8, err);
}

/* ---- by content / by name ---------------------------------------------- */

static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

int cdsp_host_image_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                           cdsp_host_err *err)
{
    const unsigned char *p = buf;
    out->data = NULL;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty file");
    if (len >= 4 && memcmp(p, png_sig, 4) == 0)
        return cdsp_host_png_decode(buf, len, name, out, err);
    if (p[0] == 'P')
        return cdsp_host_pgm_decode(buf, len, name, out, err);
    /* JPEG: SOI then a marker; TIFF: byte order "II" or "MM", then 42 */
    if (len >= 3 && p[0] == 0xff && p[1] == 0xd8 && p[2] == 0xff)
        return cdsp_host_jpeg_decode(buf, len, name, out, err);
    if (len >= 4 && ((p[0] == 'I' && p[1] == 'I' && p[2] == 42 && p[3] == 0) ||
                     (p[0] == 'M' && p[1] == 'M' && p[2] == 0 && p[3] == 42)))
        return cdsp_host_tiff_decode(buf, len, name, out, err);
    return fail(err, CDSP_HOST_E_FORMAT, name, "not a PGM (P5), PNG, JPEG or TIFF file");
}

int cdsp_host_image_read(const char *path, cdsp_host_image *out, cdsp_host_err *err)
{
    return read_and_decode(path, cdsp_host_image_decode, out, err);
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix), i;
    if (n < k)
        return 0;
    for (i = 0; i < k; i++) {
        char a = s[n - k + i];
        if (a >= 'A' && a <= 'Z')
            a = (char)(a - 'A' + 'a');
        if (a != suffix[i])
            return 0;
    }
    return 1;
}

int cdsp_host_image_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err)
{
    if (ends_with(path, ".png"))
        return cdsp_host_png_write(path, im, err);
    if (ends_with(path, ".pgm"))
        return cdsp_host_pgm_write(path, im, err);
    return fail(err, CDSP_HOST_E_FORMAT, path, "unknown image type (use .pgm or .png)");
}
