/*
 * pixfmt.h - camera pixel formats turned into the frames libcdsp reads
 * (one sample per pixel: 8 bit, or 9..16 bit in native 16-bit words), for
 * the capture sources (src_aravis.c, src_v4l2.c). Dependency-free C99: no
 * allocation, no I/O; the caller owns every buffer.
 *
 * Formats (GenICam SFNC / PFNC names and codes, GigE Vision 2.x §4.3):
 * - Mono8, Mono10, Mono12, Mono16: copied (10/12/16: little-endian 16-bit
 *   words, value in the low bits);
 * - Mono10Packed, Mono12Packed (GigE Vision 1.x): two pixels in three
 *   bytes, the high bits of each pixel in its own byte, the low bits of
 *   both shared in the middle byte; Mono10p, Mono12p (PFNC): the pixels as
 *   one little-endian bit stream, 4 pixels in 5 bytes / 2 in 3 bytes.
 *   Both are unpacked into 16-bit words with bits = 10 or 12;
 * - Bayer RG/GR/GB/BG in 8, 10, 12, 16 bit (the name gives the colours of
 *   the top-left 2 x 2 cell): a luminance frame, see cdspd_pixfmt_convert;
 * - RGB8, BGR8: luminance (R + 2G + B)/4 after the same channel balance.
 *
 * Packed formats are one continuous pixel stream over the whole image
 * (GigE Vision and USB3 Vision send no row padding), so with an odd width
 * a row can start in the middle of a group: rows are located by pixel
 * index, not by byte.
 */
#ifndef CDSPD_PIXFMT_H
#define CDSPD_PIXFMT_H

#include <stddef.h>
#include <stdint.h>

enum {
    CDSPD_PIX_MONO = 0,     /* one grey sample per pixel */
    CDSPD_PIX_BAYER = 1,    /* a colour filter mosaic, one sample per pixel */
    CDSPD_PIX_RGB = 2       /* three samples per pixel */
};

enum {
    CDSPD_PACK_8 = 0,       /* one byte per sample */
    CDSPD_PACK_16 = 1,      /* little-endian 16-bit word per sample */
    CDSPD_PACK_GV = 2,      /* GigE Vision 1.x MonoNPacked: 2 pixels in 3 bytes */
    CDSPD_PACK_P = 3        /* PFNC MonoNp: LSB-first bit stream of N-bit pixels */
};

typedef struct {
    const char *name;       /* SFNC name, e.g. "BayerRG12" */
    uint32_t code;          /* PFNC value (what the camera's PixelFormat register holds) */
    uint8_t family;         /* CDSPD_PIX_* */
    uint8_t packing;        /* CDSPD_PACK_* */
    uint8_t bits;           /* significant bits per sample */
    uint8_t order;          /* Bayer: colour of the top-left pixel and its right
                             * neighbour: 0 RG, 1 GR, 2 GB, 3 BG. RGB: 0 RGB, 1 BGR */
    uint8_t out_bits;       /* bits of the frame cdspd_pixfmt_convert writes */
} cdspd_pixfmt;

/* The formats in the order `auto` prefers them: mono (Mono8 first: the
 * least bandwidth, then the deeper ones), packed mono, Bayer (8 bit first),
 * then RGB. i from 0; NULL past the end. */
const cdspd_pixfmt *cdspd_pixfmt_at(size_t i);
/* By SFNC name (exact, case-sensitive as GenICam) or by PFNC code; NULL
 * when not known. */
const cdspd_pixfmt *cdspd_pixfmt_find(const char *name);
const cdspd_pixfmt *cdspd_pixfmt_from_code(uint32_t code);

/* Bytes of a w x h image in format f, rows not padded; 0 for w or h < 1. */
size_t cdspd_pixfmt_image_bytes(const cdspd_pixfmt *f, int w, int h);
/* Bytes per pixel of the converted frame: 1 when out_bits is 8, else 2. */
int cdspd_pixfmt_out_bytes(const cdspd_pixfmt *f);
/* Scratch cdspd_pixfmt_convert needs for width w (three filtered rows of
 * a Bayer image; 0 for other families). Allocate it once per size. */
size_t cdspd_pixfmt_scratch_bytes(const cdspd_pixfmt *f, int w);

/* Convert one w x h image (src_len bytes at src, cdspd_pixfmt_image_bytes
 * of them used) into dst: h rows of dst_stride bytes, each w pixels of
 * cdspd_pixfmt_out_bytes(f) bytes, values < 2^out_bits.
 *
 * Bayer (and RGB): libcdsp's edge detector needs one grey value per pixel
 * whose edges lie where the scene's do. A mosaic read as grey has a 2-px
 * checker pattern wherever the channels' gains differ (a white balance, or
 * a coloured light), and the pattern moves with every edge. So:
 *  1. channel balance: each channel c is scaled by k_c = m_min / m_c, m_c
 *     the mean of its samples over the frame (grey world: in a grey scene
 *     m_c is the channel's gain times the scene's mean, so the balanced
 *     mosaic is the grey scene itself; k_c <= 1, so nothing clips); or
 *     k_c = g_min / g_c from the caller's gains (gains[3]: the camera's
 *     R, G, B responses, e.g. its white balance ratios; only their ratios
 *     matter; NULL: measured);
 *  2. the 3 x 3 binomial kernel [1 2 1]^T [1 2 1] / 16, centred on every
 *     pixel. Whatever the pixel's colour, its 3 x 3 window weighs R, G, B
 *     samples 4 : 8 : 4 (centre 4, the 4 edge neighbours 2 each, the 4
 *     corners 1 each; the same colours sit at the centre, at the edge pair
 *     of one axis, ...), so the response to a grey scene is the same at all
 *     four phases: Y = (R + 2G + B)/4. The kernel is symmetric, so a
 *     straight edge keeps its position (no half-pixel shift, unlike a 2 x 2
 *     box), and its transfer function cos^2(wx/2) cos^2(wy/2) is 0 at the
 *     mosaic's frequencies (pi, 0), (0, pi), (pi, pi): whatever imbalance
 *     is left is removed too. It blurs by sigma = 0.71 px per axis, which
 *     the edge detector's own smoothing (its window) absorbs.
 *  Borders: reflected about the border pixel (x = -1 reads x = 1), which
 *  keeps the mosaic's phase. Output: out_bits = bits + 2 (the 16 weights
 *  carry 2 bits more than one sample), at most 16.
 * (x_parity, y_parity): the parity of the image's origin on the sensor
 * when the camera's format names the sensor's phase rather than the
 * image's (a region offset by an odd number of pixels shifts it); 0, 0 when
 * the format names the delivered image's phase, as SFNC says it should.
 *
 * Returns 0, or -1 (f NULL, w or h < 1, src_len short, dst_stride short,
 * scratch short for a Bayer format). No allocation; the time is linear in
 * the pixels (make bench: bench-pixfmt). */
int cdspd_pixfmt_convert(const cdspd_pixfmt *f, const void *src, size_t src_len, int w, int h,
                         int x_parity, int y_parity, const double *gains, void *dst,
                         size_t dst_stride, void *scratch, size_t scratch_len);

/* The channel means of a Bayer or RGB image (m[0] R, m[1] G, m[2] B, in
 * sample units), as step 1 above measures them. 0, or -1 as convert. */
int cdspd_pixfmt_channel_means(const cdspd_pixfmt *f, const void *src, size_t src_len, int w, int h,
                               int x_parity, int y_parity, double m[3]);

#endif
