/*
 * pixfmt.c - unpacking and Bayer/RGB-to-luminance conversion of camera
 * pixel formats (pixfmt.h says what and why). Integer arithmetic only: the
 * channel gains are Q16 fractions (k <= 1), the balanced samples carry 4
 * fractional bits, and the binomial kernel's 16 weights add 4 more bits,
 * so a 16-bit sample grows to at most 2^24 and every sum fits 32 bits.
 */
#include "pixfmt.h"

#include <string.h>

/* PFNC codes (GenICam Pixel Format Naming Convention 2.x, table of
 * values); src_aravis.c checks them against Aravis's own at compile time. */
static const cdspd_pixfmt table[] = {
    {"Mono8", 0x01080001u, CDSPD_PIX_MONO, CDSPD_PACK_8, 8, 0, 8},
    {"Mono16", 0x01100007u, CDSPD_PIX_MONO, CDSPD_PACK_16, 16, 0, 16},
    {"Mono12", 0x01100005u, CDSPD_PIX_MONO, CDSPD_PACK_16, 12, 0, 12},
    {"Mono10", 0x01100003u, CDSPD_PIX_MONO, CDSPD_PACK_16, 10, 0, 10},
    {"Mono12p", 0x010c0047u, CDSPD_PIX_MONO, CDSPD_PACK_P, 12, 0, 12},
    {"Mono12Packed", 0x010c0006u, CDSPD_PIX_MONO, CDSPD_PACK_GV, 12, 0, 12},
    {"Mono10p", 0x010a0046u, CDSPD_PIX_MONO, CDSPD_PACK_P, 10, 0, 10},
    {"Mono10Packed", 0x010c0004u, CDSPD_PIX_MONO, CDSPD_PACK_GV, 10, 0, 10},
    {"BayerRG8", 0x01080009u, CDSPD_PIX_BAYER, CDSPD_PACK_8, 8, 0, 10},
    {"BayerGR8", 0x01080008u, CDSPD_PIX_BAYER, CDSPD_PACK_8, 8, 1, 10},
    {"BayerGB8", 0x0108000au, CDSPD_PIX_BAYER, CDSPD_PACK_8, 8, 2, 10},
    {"BayerBG8", 0x0108000bu, CDSPD_PIX_BAYER, CDSPD_PACK_8, 8, 3, 10},
    {"BayerRG16", 0x0110002fu, CDSPD_PIX_BAYER, CDSPD_PACK_16, 16, 0, 16},
    {"BayerGR16", 0x0110002eu, CDSPD_PIX_BAYER, CDSPD_PACK_16, 16, 1, 16},
    {"BayerGB16", 0x01100030u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 16, 2, 16},
    {"BayerBG16", 0x01100031u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 16, 3, 16},
    {"BayerRG12", 0x01100011u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 12, 0, 14},
    {"BayerGR12", 0x01100010u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 12, 1, 14},
    {"BayerGB12", 0x01100012u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 12, 2, 14},
    {"BayerBG12", 0x01100013u, CDSPD_PIX_BAYER, CDSPD_PACK_16, 12, 3, 14},
    {"BayerRG10", 0x0110000du, CDSPD_PIX_BAYER, CDSPD_PACK_16, 10, 0, 12},
    {"BayerGR10", 0x0110000cu, CDSPD_PIX_BAYER, CDSPD_PACK_16, 10, 1, 12},
    {"BayerGB10", 0x0110000eu, CDSPD_PIX_BAYER, CDSPD_PACK_16, 10, 2, 12},
    {"BayerBG10", 0x0110000fu, CDSPD_PIX_BAYER, CDSPD_PACK_16, 10, 3, 12},
    {"RGB8", 0x02180014u, CDSPD_PIX_RGB, CDSPD_PACK_8, 8, 0, 10},
    {"BGR8", 0x02180015u, CDSPD_PIX_RGB, CDSPD_PACK_8, 8, 1, 10},
};
#define N_TABLE (sizeof table / sizeof table[0])

/* Colour (0 R, 1 G, 2 B) of the sample at (x & 1, y & 1) for each Bayer
 * order: [order][y & 1][x & 1]. */
static const uint8_t bayer_colour[4][2][2] = {
    {{0, 1}, {1, 2}},   /* RG / GB */
    {{1, 0}, {2, 1}},   /* GR / BG */
    {{1, 2}, {0, 1}},   /* GB / RG */
    {{2, 1}, {1, 0}},   /* BG / GR */
};

const cdspd_pixfmt *cdspd_pixfmt_at(size_t i)
{
    return i < N_TABLE ? &table[i] : NULL;
}

const cdspd_pixfmt *cdspd_pixfmt_find(const char *name)
{
    size_t i;
    for (i = 0; name && i < N_TABLE; i++)
        if (!strcmp(table[i].name, name))
            return &table[i];
    return NULL;
}

const cdspd_pixfmt *cdspd_pixfmt_from_code(uint32_t code)
{
    size_t i;
    for (i = 0; i < N_TABLE; i++)
        if (table[i].code == code)
            return &table[i];
    return NULL;
}

size_t cdspd_pixfmt_image_bytes(const cdspd_pixfmt *f, int w, int h)
{
    size_t n;
    if (!f || w < 1 || h < 1)
        return 0;
    n = (size_t)w * (size_t)h;
    switch (f->packing) {
    case CDSPD_PACK_8: return f->family == CDSPD_PIX_RGB ? 3 * n : n;
    case CDSPD_PACK_16: return 2 * n;
    case CDSPD_PACK_GV: return (3 * n + 1) / 2;   /* a last odd pixel takes 2 bytes */
    default: return (n * f->bits + 7) / 8;
    }
}

int cdspd_pixfmt_out_bytes(const cdspd_pixfmt *f)
{
    return f && f->out_bits > 8 ? 2 : 1;
}

size_t cdspd_pixfmt_scratch_bytes(const cdspd_pixfmt *f, int w)
{
    if (!f || f->family != CDSPD_PIX_BAYER || w < 1)
        return 0;
    return 3 * (size_t)w * sizeof(uint32_t);
}

/* Sample i (pixel index over the whole image) of a packed mono image. */
static uint32_t packed_sample(const uint8_t *s, int packing, int bits, size_t i)
{
    if (packing == CDSPD_PACK_GV) {
        /* GigE Vision 1.x: byte 0 = pixel 0's high bits, byte 2 = pixel
         * 1's; byte 1 = pixel 0's low bits in bits 0.., pixel 1's in 4.. */
        const uint8_t *b = s + 3 * (i >> 1);
        int lo_bits = bits - 8;
        uint32_t lo_mask = (1u << lo_bits) - 1u;
        if (i & 1)
            return ((uint32_t)b[2] << lo_bits) | ((uint32_t)(b[1] >> 4) & lo_mask);
        return ((uint32_t)b[0] << lo_bits) | ((uint32_t)b[1] & lo_mask);
    } else {
        /* PFNC "p": bit k of the stream is bit (k & 7) of byte k >> 3; a
         * 10- or 12-bit pixel starting at bit offset <= 6 ends within the
         * next byte, so two bytes hold it and nothing past the image is
         * read. */
        size_t off = i * (size_t)bits;
        const uint8_t *b = s + (off >> 3);
        uint32_t v = (uint32_t)b[0] | ((uint32_t)b[1] << 8);
        return (v >> (off & 7)) & ((1u << bits) - 1u);
    }
}

static uint32_t sample_at(const uint8_t *s, int packing, size_t i)
{
    if (packing == CDSPD_PACK_8)
        return s[i];
    return (uint32_t)s[2 * i] | ((uint32_t)s[2 * i + 1] << 8);   /* little endian on the wire */
}

static int reflect(int i, int n)
{
    if (n == 1)
        return 0;
    if (i < 0)
        return -i;
    if (i >= n)
        return 2 * (n - 1) - i;
    return i;
}

int cdspd_pixfmt_channel_means(const cdspd_pixfmt *f, const void *src, size_t src_len, int w, int h,
                               int x_parity, int y_parity, double m[3])
{
    const uint8_t *s = src;
    uint64_t sum[3] = {0, 0, 0}, cnt[3] = {0, 0, 0};
    int x, y, c;

    if (!f || f->family == CDSPD_PIX_MONO || !src || !m || w < 1 || h < 1 ||
        src_len < cdspd_pixfmt_image_bytes(f, w, h))
        return -1;
    for (y = 0; y < h; y++) {
        size_t row = (size_t)y * (size_t)w;
        if (f->family == CDSPD_PIX_RGB) {
            const uint8_t *p = s + 3 * row;
            for (x = 0; x < w; x++, p += 3) {
                sum[0] += p[f->order ? 2 : 0];
                sum[1] += p[1];
                sum[2] += p[f->order ? 0 : 2];
            }
            cnt[0] += (uint64_t)w;
        } else {
            /* even and odd columns apart: each is one colour */
            const uint8_t *col = bayer_colour[f->order][(y + y_parity) & 1];
            uint64_t se = 0, so = 0;
            if (f->packing == CDSPD_PACK_8) {
                const uint8_t *p = s + row;
                for (x = 0; x + 1 < w; x += 2) {
                    se += p[x];
                    so += p[x + 1];
                }
                if (x < w)
                    se += p[x];
            } else {
                for (x = 0; x + 1 < w; x += 2) {
                    se += sample_at(s, f->packing, row + (size_t)x);
                    so += sample_at(s, f->packing, row + (size_t)x + 1);
                }
                if (x < w)
                    se += sample_at(s, f->packing, row + (size_t)x);
            }
            c = col[x_parity & 1];
            sum[c] += se;
            cnt[c] += (uint64_t)(w + 1) / 2;
            c = col[(x_parity + 1) & 1];
            sum[c] += so;
            cnt[c] += (uint64_t)w / 2;
        }
    }
    if (f->family == CDSPD_PIX_RGB)
        cnt[1] = cnt[2] = cnt[0];
    for (c = 0; c < 3; c++)
        m[c] = cnt[c] ? (double)sum[c] / (double)cnt[c] : 0.0;
    return 0;
}

/* Q16 channel factors k_c = r_min / r_c <= 1 (pixfmt.h, step 1), r the
 * channels' responses: the caller's gains (only their ratios matter) or
 * the frame's channel means; the dimmest channel keeps its scale. A
 * channel with no light (mean 0) or a gain that is not positive leaves all
 * factors 1. */
static void channel_factors(const cdspd_pixfmt *f, const void *src, size_t src_len, int w, int h,
                            int xp, int yp, const double *gains, uint32_t k[3])
{
    double m[3], ref;
    int c;

    k[0] = k[1] = k[2] = 65536u;
    if (gains) {
        for (c = 0; c < 3; c++)
            m[c] = gains[c];
    } else if (cdspd_pixfmt_channel_means(f, src, src_len, w, h, xp, yp, m)) {
        return;
    }
    ref = m[0];
    for (c = 0; c < 3; c++) {
        if (!(m[c] > 0))
            return;
        if (m[c] < ref)
            ref = m[c];
    }
    for (c = 0; c < 3; c++)
        k[c] = (uint32_t)(65536.0 * ref / m[c] + 0.5);
}

/* Row r of a Bayer image, balanced (4 fractional bits) and filtered with
 * [1 2 1] along x (reflected borders), into out[0..w). Two passes over
 * the row, each a plain loop the compiler vectorises: balance (the gain
 * alternates with x), then the filter in place. */
static void bayer_hrow(const cdspd_pixfmt *f, const uint8_t *s, int w, int r, int xp, int yp,
                       const uint32_t k[3], uint32_t *out)
{
    const uint8_t *col = bayer_colour[f->order][(r + yp) & 1];
    const uint8_t *row8 = s + (size_t)r * (size_t)w * (f->packing == CDSPD_PACK_8 ? 1u : 2u);
    /* balanced sample: (v * k_c) >> 12 keeps 4 fractional bits; v * k_c
     * < 2^16 * 2^16 + 1 fits 32 bits only just, so 64-bit products */
    uint64_t kk[2];
    uint32_t prev, cur;
    int x;

    kk[0] = k[col[xp & 1]];
    kk[1] = k[col[(xp + 1) & 1]];
    if (f->packing == CDSPD_PACK_8)
        for (x = 0; x < w; x++)
            out[x] = (uint32_t)(((uint64_t)row8[x] * kk[x & 1]) >> 12);
    else
        for (x = 0; x < w; x++)
            out[x] = (uint32_t)((((uint64_t)row8[2 * x] | (uint64_t)row8[2 * x + 1] << 8) * kk[x & 1]) >> 12);
    if (w == 1) {
        out[0] *= 4;
        return;
    }
    /* in place: out[x] = b[x-1] + 2 b[x] + b[x+1], b[-1] = b[1], b[w] = b[w-2] */
    prev = out[1];
    for (x = 0; x < w - 1; x++) {
        cur = out[x];
        out[x] = prev + 2 * cur + out[x + 1];
        prev = cur;
    }
    out[w - 1] = 2 * prev + 2 * out[w - 1];
}

int cdspd_pixfmt_convert(const cdspd_pixfmt *f, const void *src, size_t src_len, int w, int h,
                         int x_parity, int y_parity, const double *gains, void *dst,
                         size_t dst_stride, void *scratch, size_t scratch_len)
{
    const uint8_t *s = src;
    uint8_t *d = dst;
    int x, y, xp = x_parity & 1, yp = y_parity & 1;
    uint32_t mask;

    if (!f || !src || !dst || w < 1 || h < 1 || src_len < cdspd_pixfmt_image_bytes(f, w, h) ||
        dst_stride < (size_t)w * (size_t)cdspd_pixfmt_out_bytes(f))
        return -1;
    mask = (1u << f->out_bits) - 1u;

    if (f->family == CDSPD_PIX_MONO) {
        for (y = 0; y < h; y++) {
            size_t row = (size_t)y * (size_t)w;
            if (f->packing == CDSPD_PACK_8) {
                memcpy(d + (size_t)y * dst_stride, s + row, (size_t)w);
                continue;
            }
            {
                uint16_t *o = (uint16_t *)(void *)(d + (size_t)y * dst_stride);
                if (f->packing == CDSPD_PACK_16)
                    for (x = 0; x < w; x++)
                        o[x] = (uint16_t)(sample_at(s, CDSPD_PACK_16, row + (size_t)x) & mask);
                else
                    for (x = 0; x < w; x++)
                        o[x] = (uint16_t)packed_sample(s, f->packing, f->bits, row + (size_t)x);
            }
        }
        return 0;
    }

    if (f->family == CDSPD_PIX_RGB) {
        uint32_t k[3];
        /* Y = (kR R + 2 kG G + kB B) / 4: Q16 factors, >> 12 leaves 4
         * fractional bits and the weights 4 = 2 bits: (v << 6) at most,
         * out_bits = bits + 2, so >> 4 with rounding. */
        int ri = f->order ? 2 : 0, bi = f->order ? 0 : 2;
        channel_factors(f, src, src_len, w, h, 0, 0, gains, k);
        for (y = 0; y < h; y++) {
            const uint8_t *p = s + 3 * (size_t)y * (size_t)w;
            uint16_t *o = (uint16_t *)(void *)(d + (size_t)y * dst_stride);
            for (x = 0; x < w; x++, p += 3) {
                uint32_t v = ((uint32_t)p[ri] * k[0] + 2u * (uint32_t)p[1] * k[1] +
                              (uint32_t)p[bi] * k[2]) >> 12;
                v = (v + 8u) >> 4;
                o[x] = (uint16_t)(v > mask ? mask : v);
            }
        }
        return 0;
    }

    /* Bayer: balance, then [1 2 1] along x into three cached rows, then
     * [1 2 1] down the column (pixfmt.h, step 2). Sums are v << 8 at most
     * (4 fractional bits, 16 weights); out_bits - bits = 2 (or 0 for
     * 16-bit samples) of them stay. */
    {
        uint32_t k[3], *rows = scratch;
        int cached[3] = {-1, -1, -1};
        int shift = 8 - (f->out_bits - f->bits);
        uint32_t half = 1u << (shift - 1);

        if (!scratch || scratch_len < cdspd_pixfmt_scratch_bytes(f, w))
            return -1;
        channel_factors(f, src, src_len, w, h, xp, yp, gains, k);
        for (y = 0; y < h; y++) {
            const uint32_t *r3[3];
            int j;
            for (j = 0; j < 3; j++) {
                int r = reflect(y - 1 + j, h), slot = r % 3;
                if (cached[slot] != r) {
                    bayer_hrow(f, s, w, r, xp, yp, k, rows + (size_t)slot * (size_t)w);
                    cached[slot] = r;
                }
                r3[j] = rows + (size_t)slot * (size_t)w;
            }
            {
                /* out_bits >= 10: 16-bit words */
                uint16_t *o = (uint16_t *)(void *)(d + (size_t)y * dst_stride);
                for (x = 0; x < w; x++) {
                    uint32_t v = (r3[0][x] + 2u * r3[1][x] + r3[2][x] + half) >> shift;
                    o[x] = (uint16_t)(v > mask ? mask : v);
                }
            }
        }
    }
    return 0;
}
