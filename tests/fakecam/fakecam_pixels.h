/*
 * fakecam_pixels.h - the camera side of pixel formats, for tests: the fake
 * GigE Vision camera (cdsp_fakecam) turns its grey renders into every
 * format cdspd reads, and tests/daemon/test_pixfmt.c packs its hand-made
 * buffers with the same code. Written from the formats' definitions (GigE
 * Vision 1.x MonoNPacked, PFNC MonoNp, SFNC Bayer cell names), bit by bit
 * and independently of daemon/pixfmt.c, whose inverse it is.
 *
 * A colour camera looking at a grey scene: sample (x, y) is the scene's
 * grey value times the gain of the filter colour over that pixel,
 * FAKECAM_GAIN_R/G/B (unequal, as an uncorrected white balance makes
 * them), so a mosaic read as grey shows the 2-px checker the converter
 * must remove.
 */
#ifndef FAKECAM_PIXELS_H
#define FAKECAM_PIXELS_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define FAKECAM_GAIN_R 0.55
#define FAKECAM_GAIN_G 1.0
#define FAKECAM_GAIN_B 0.8

/* Colour (0 R, 1 G, 2 B) at (x, y) of a mosaic whose top-left cell reads
 * cell[0] cell[1] / cell[2] cell[3], e.g. "RGGB" for BayerRG. */
static inline int fakecam_bayer_colour(const char *cell, int x, int y)
{
    char c = cell[2 * (y & 1) + (x & 1)];
    return c == 'R' ? 0 : c == 'G' ? 1 : 2;
}

/* Pack n values of `bits` bits: packing 'g' GigE Vision 1.x (2 pixels in
 * 3 bytes: high bits of pixel 0 in byte 0, of pixel 1 in byte 2, their low
 * bits in byte 1 at bit 0 and bit 4), 'p' PFNC (LSB-first bit stream).
 * out holds the packed size; returns it. */
static inline size_t fakecam_pack(const uint16_t *px, size_t n, int bits, char packing, uint8_t *out)
{
    size_t i, bytes = packing == 'g' ? (3 * n + 1) / 2 : (n * (size_t)bits + 7) / 8;
    memset(out, 0, bytes);
    for (i = 0; i < n; i++) {
        unsigned v = px[i], b;
        if (packing == 'p') {
            for (b = 0; b < (unsigned)bits; b++) {
                size_t k = i * (size_t)bits + b;
                if (v >> b & 1u)
                    out[k / 8] |= (uint8_t)(1u << (k % 8));
            }
        } else {
            unsigned lo = (unsigned)bits - 8;
            size_t g = 3 * (i / 2);
            out[g + (i & 1 ? 2 : 0)] = (uint8_t)(v >> lo);
            out[g + 1] |= (uint8_t)((v & ((1u << lo) - 1u)) << (i & 1 ? 4 : 0));
        }
    }
    return bytes;
}

#endif /* FAKECAM_PIXELS_H */
