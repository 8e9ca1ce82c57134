/*
 * edges_simd.c - the SIMD forms of the edge scans' candidate test
 * (cdsp__edges_peaks, internal.h; the portable form, the reference, is
 * cdsp__edges_peaks_c in lib/edges.c), of the column scans' gather at
 * the default step (cdsp__edges_gather, cdsp__edges_gather_rows; the
 * portable forms in lib/edges.c) and of the frame noise's small-difference
 * counts (cdsp__noise_small; cdsp__noise_small_c in lib/frame.c). 16 positions per instruction with
 * SSE2 (every x86-64) or NEON (every AArch64), 32 with AVX2 when the
 * library is compiled for it (-mavx2: a compile-time choice, no run-time
 * dispatch). All of it is exact 8-bit integer arithmetic: |a - b| as the
 * OR of the two saturating differences (one of them is 0), the comparisons
 * as saturating differences tested against 0, so the flags (bits, 32 a
 * word) are those of the portable form bit for bit (tests/lib/test_edges_scan.c checks every
 * length, offset and threshold class, and the whole scan against a pixel
 * by pixel reference). A run's tail is the vector ending at its last
 * position (overlapping the one before it, recomputing equal flags); runs
 * shorter than a vector take the portable form. Without a SIMD target (Cortex-M, CDSP_NO_SIMD) this file is empty.
 */
#include "internal.h"

#if CDSP__SIMD

#if defined(__SSE2__)
#include <emmintrin.h>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

/* Flags of the 16 positions from i: bit j of the result is position
 * i + j's. The central difference gc alone first: where no position
 * reaches the threshold (nearly every vector: on the paper frame 95 % of
 * a row's vectors) every flag is 0 whatever gl and gr are, and they are
 * not computed (the same flags; the full search's candidate tests 0.95 ->
 * 0.66 M instructions, callgrind). */
static inline uint32_t peaks16(const uint8_t *f0, const uint8_t *f1, const uint8_t *f2, const uint8_t *f3,
                               const uint8_t *f4, const uint8_t *sel, size_t i, __m128i t)
{
    const __m128i zero = _mm_setzero_si128();
    __m128i m1 = _mm_loadu_si128((const __m128i *)(const void *)(f1 + i));
    __m128i p1 = _mm_loadu_si128((const __m128i *)(const void *)(f3 + i));
    __m128i gc = _mm_or_si128(_mm_subs_epu8(p1, m1), _mm_subs_epu8(m1, p1));
    /* gc >= t: t - gc saturates to 0 */
    __m128i tc = _mm_subs_epu8(t, gc), m2, c0, p2, gl, gr, ge, c;
    if (_mm_movemask_epi8(_mm_cmpeq_epi8(tc, zero)) == 0)
        return 0;
    m2 = _mm_loadu_si128((const __m128i *)(const void *)(f0 + i));
    c0 = _mm_loadu_si128((const __m128i *)(const void *)(f2 + i));
    p2 = _mm_loadu_si128((const __m128i *)(const void *)(f4 + i));
    gl = _mm_or_si128(_mm_subs_epu8(c0, m2), _mm_subs_epu8(m2, c0));
    gr = _mm_or_si128(_mm_subs_epu8(p2, c0), _mm_subs_epu8(c0, p2));
    /* gc >= t and gc >= gr: t - gc and gr - gc saturate to 0; gc > gl:
     * gc - gl does not */
    ge = _mm_cmpeq_epi8(_mm_or_si128(tc, _mm_subs_epu8(gr, gc)), zero);
    c = _mm_andnot_si128(_mm_cmpeq_epi8(_mm_subs_epu8(gc, gl), zero), ge);
    if (sel) /* (0/1 bytes) */
        c = _mm_andnot_si128(_mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(const void *)(sel + i)), zero), c);
    return (uint32_t)_mm_movemask_epi8(c);
}

#if defined(__AVX2__)
/* The same for 32 positions (without the threshold's shortcut). */
static inline uint32_t peaks32(const uint8_t *const f[5], const uint8_t *sel, size_t i, __m256i t)
{
    const __m256i zero = _mm256_setzero_si256();
    __m256i m2 = _mm256_loadu_si256((const __m256i *)(const void *)(f[0] + i));
    __m256i m1 = _mm256_loadu_si256((const __m256i *)(const void *)(f[1] + i));
    __m256i c0 = _mm256_loadu_si256((const __m256i *)(const void *)(f[2] + i));
    __m256i p1 = _mm256_loadu_si256((const __m256i *)(const void *)(f[3] + i));
    __m256i p2 = _mm256_loadu_si256((const __m256i *)(const void *)(f[4] + i));
    __m256i gl = _mm256_or_si256(_mm256_subs_epu8(c0, m2), _mm256_subs_epu8(m2, c0));
    __m256i gc = _mm256_or_si256(_mm256_subs_epu8(p1, m1), _mm256_subs_epu8(m1, p1));
    __m256i gr = _mm256_or_si256(_mm256_subs_epu8(p2, c0), _mm256_subs_epu8(c0, p2));
    __m256i ge = _mm256_cmpeq_epi8(_mm256_or_si256(_mm256_subs_epu8(t, gc), _mm256_subs_epu8(gr, gc)), zero);
    __m256i c = _mm256_andnot_si256(_mm256_cmpeq_epi8(_mm256_subs_epu8(gc, gl), zero), ge);
    if (sel)
        c = _mm256_andnot_si256(
            _mm256_cmpeq_epi8(_mm256_loadu_si256((const __m256i *)(const void *)(sel + i)), zero), c);
    return (uint32_t)_mm256_movemask_epi8(c);
}
#endif

uint32_t cdsp__edges_peaks_simd(const uint8_t *const f[5], const uint8_t *sel, size_t n, int thr,
                                uint32_t *bits)
{
    size_t i = 0, j;
    const uint8_t *f0 = f[0], *f1 = f[1], *f2 = f[2], *f3 = f[3], *f4 = f[4];
    const __m128i t = _mm_set1_epi8((char)thr);
    uint32_t any = 0, w;
    if (n < 16)
        return cdsp__edges_peaks_c(f, sel, n, thr, bits);
#if defined(__AVX2__)
    {
        const __m256i t8 = _mm256_set1_epi8((char)thr);
        for (; i + 32 <= n; i += 32) {
            w = peaks32(f, sel, i, t8);
            bits[i / 32] = w;
            any |= w;
        }
    }
#endif
    /* a word from two vectors */
    for (; i + 32 <= n; i += 32) {
        w = peaks16(f0, f1, f2, f3, f4, sel, i, t) | peaks16(f0, f1, f2, f3, f4, sel, i + 16, t) << 16;
        bits[i / 32] = w;
        any |= w;
    }
    if (i == n)
        return any;
    /* the last word: a vector if 16 positions are left, then the tail,
     * the 16 positions ending at n (overlapping those before; its lanes
     * from j - (n - 16) on are positions j .. n - 1) */
    j = i + 16 <= n ? i + 16 : i;
    w = j > i ? peaks16(f0, f1, f2, f3, f4, sel, i, t) : 0;
    if (j < n)
        w |= peaks16(f0, f1, f2, f3, f4, sel, n - 16, t) >> (j + 16 - n) << (j - i);
    bits[i / 32] = w;
    return any | w;
}

/* The gather at d = 4 (internal.h), 16 samples from 64 bytes: each 32-bit
 * lane holds one sample in its low byte; masked and packed (the signed and
 * unsigned saturating packs keep 0..255 as they are). A block of 16 that
 * ends 3 or more bytes before the run's last sample is loaded from its
 * first sample; the others from 3 bytes before it, the sample then in each
 * lane's top byte, so that no byte past the last sample and none before
 * the first is read. Other steps, and what no block of 16 covers, are
 * the portable form's. */
static inline void gather1(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst)
{
    int k = 0;
    if (d == 4) {
        const __m128i lo = _mm_set1_epi32(0xFF);
        for (; k + 16 <= n; k += 16) {
            const uint8_t *s = src + 4 * k;
            __m128i a, b, c, e;
            if (k + 17 <= n) {
                a = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)s), lo);
                b = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(s + 16)), lo);
                c = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(s + 32)), lo);
                e = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(s + 48)), lo);
            } else if (k > 0) {
                a = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(s - 3)), 24);
                b = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(s + 13)), 24);
                c = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(s + 29)), 24);
                e = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(s + 45)), 24);
            } else {
                break; /* n = 16 exactly: 61 bytes, no whole vector load fits */
            }
            _mm_storeu_si128((__m128i *)(void *)(dst + k),
                             _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_packs_epi32(c, e)));
        }
    }
    if (k < n) /* (a whole number of blocks, the column scans' 32: no call) */
        cdsp__edges_gather_c(src + (ptrdiff_t)k * d, d, n - k, dst + k);
}

void cdsp__edges_gather_simd(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst)
{
    gather1(src, d, n, dst);
}

/* (internal.h) the rows in one call: the column scans gather 4 rows of
 * 32 samples at a time, and a call and its tests were about half of a
 * row's cost; their whole blocks (32 samples at d = 4) without the
 * tests: gather1's two blocks, from the first sample and from 3 bytes
 * before the 17th */
void cdsp__edges_gather_rows_simd(const uint8_t *src, ptrdiff_t stride, ptrdiff_t d, int n, int rows,
                                  uint8_t *dst, ptrdiff_t dstride)
{
    int r;
    if (d == 4 && n == 32) {
        const __m128i lo = _mm_set1_epi32(0xFF);
        for (r = 0; r < rows; r++, src += stride, dst += dstride) {
            __m128i a = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)src), lo);
            __m128i b = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(src + 16)), lo);
            __m128i c = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(src + 32)), lo);
            __m128i e = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(src + 48)), lo);
            _mm_storeu_si128((__m128i *)(void *)dst, _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_packs_epi32(c, e)));
            a = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(src + 61)), 24);
            b = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(src + 77)), 24);
            c = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(src + 93)), 24);
            e = _mm_srli_epi32(_mm_loadu_si128((const __m128i *)(const void *)(src + 109)), 24);
            _mm_storeu_si128((__m128i *)(void *)(dst + 16),
                             _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_packs_epi32(c, e)));
        }
        return;
    }
    for (r = 0; r < rows; r++, src += stride, dst += dstride)
        gather1(src, d, n, dst);
}

/* cdsp__noise_small (internal.h): 16 pairs a round, their even and odd
 * bytes split (mask / shift of the 16-bit lanes, then packed), |d| as for
 * the candidate test, each count a byte per lane (cmpeq's -1 subtracted),
 * summed into cnt before a lane could wrap (255 rounds) */
void cdsp__noise_small_simd(const uint8_t *q, size_t n, uint32_t cnt[4])
{
    const __m128i lo = _mm_set1_epi16(0xFF), zero = _mm_setzero_si128();
    const __m128i v1 = _mm_set1_epi8(1), v2 = _mm_set1_epi8(2), v3 = _mm_set1_epi8(3);
    size_t i = 0;
    while (i + 16 <= n) {
        __m128i c0 = zero, c1 = zero, c2 = zero, c3 = zero;
        size_t end = n - i > 255 * 16 ? i + 255 * 16 : n;
        for (; i + 16 <= end; i += 16) {
            __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(q + 2 * i));
            __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(q + 2 * i + 16));
            __m128i ev = _mm_packus_epi16(_mm_and_si128(a, lo), _mm_and_si128(b, lo));
            __m128i od = _mm_packus_epi16(_mm_srli_epi16(a, 8), _mm_srli_epi16(b, 8));
            __m128i d = _mm_or_si128(_mm_subs_epu8(od, ev), _mm_subs_epu8(ev, od));
            c0 = _mm_sub_epi8(c0, _mm_cmpeq_epi8(d, zero));
            c1 = _mm_sub_epi8(c1, _mm_cmpeq_epi8(d, v1));
            c2 = _mm_sub_epi8(c2, _mm_cmpeq_epi8(d, v2));
            c3 = _mm_sub_epi8(c3, _mm_cmpeq_epi8(d, v3));
        }
        /* the lanes' bytes summed (psadbw: two 64-bit halves) */
        c0 = _mm_sad_epu8(c0, zero);
        c1 = _mm_sad_epu8(c1, zero);
        c2 = _mm_sad_epu8(c2, zero);
        c3 = _mm_sad_epu8(c3, zero);
        cnt[0] += (uint32_t)_mm_cvtsi128_si32(c0) + (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(c0, 8));
        cnt[1] += (uint32_t)_mm_cvtsi128_si32(c1) + (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(c1, 8));
        cnt[2] += (uint32_t)_mm_cvtsi128_si32(c2) + (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(c2, 8));
        cnt[3] += (uint32_t)_mm_cvtsi128_si32(c3) + (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(c3, 8));
    }
    cdsp__noise_small_c(q + 2 * i, n - i, cnt);
}

#else /* AArch64 NEON */
#include <arm_neon.h>

/* Flags of the 16 positions from i as the bits of the result (see the
 * SSE2 form; gc alone first). */
static inline uint32_t peaks16(const uint8_t *f0, const uint8_t *f1, const uint8_t *f2, const uint8_t *f3,
                               const uint8_t *f4, const uint8_t *sel, size_t i, uint8x16_t t)
{
    /* each lane's bit weight within its half: the mask as two sums (NEON
     * has no movemask) */
    static const uint8_t wgt[16] = {1, 2, 4, 8, 16, 32, 64, 128, 1, 2, 4, 8, 16, 32, 64, 128};
    uint8x16_t m1 = vld1q_u8(f1 + i), p1 = vld1q_u8(f3 + i), gc = vabdq_u8(p1, m1);
    uint8x16_t m2, c0, p2, gl, gr, c;
    if (vmaxvq_u8(vcgeq_u8(gc, t)) == 0)
        return 0;
    m2 = vld1q_u8(f0 + i);
    c0 = vld1q_u8(f2 + i);
    p2 = vld1q_u8(f4 + i);
    gl = vabdq_u8(c0, m2);
    gr = vabdq_u8(p2, c0);
    c = vandq_u8(vandq_u8(vcgeq_u8(gc, t), vcgtq_u8(gc, gl)), vcgeq_u8(gc, gr));
    if (sel) /* (0/1 bytes) */
        c = vandq_u8(c, vtstq_u8(vld1q_u8(sel + i), vld1q_u8(sel + i)));
    c = vandq_u8(c, vld1q_u8(wgt));
    return (uint32_t)vaddv_u8(vget_low_u8(c)) | (uint32_t)vaddv_u8(vget_high_u8(c)) << 8;
}

uint32_t cdsp__edges_peaks_simd(const uint8_t *const f[5], const uint8_t *sel, size_t n, int thr,
                                uint32_t *bits)
{
    size_t i = 0, j;
    const uint8_t *f0 = f[0], *f1 = f[1], *f2 = f[2], *f3 = f[3], *f4 = f[4];
    const uint8x16_t t = vdupq_n_u8((uint8_t)thr);
    uint32_t any = 0, w;
    if (n < 16)
        return cdsp__edges_peaks_c(f, sel, n, thr, bits);
    for (; i + 32 <= n; i += 32) {
        w = peaks16(f0, f1, f2, f3, f4, sel, i, t) | peaks16(f0, f1, f2, f3, f4, sel, i + 16, t) << 16;
        bits[i / 32] = w;
        any |= w;
    }
    if (i == n)
        return any;
    /* the last word (see the SSE2 form) */
    j = i + 16 <= n ? i + 16 : i;
    w = j > i ? peaks16(f0, f1, f2, f3, f4, sel, i, t) : 0;
    if (j < n)
        w |= peaks16(f0, f1, f2, f3, f4, sel, n - 16, t) >> (j + 16 - n) << (j - i);
    bits[i / 32] = w;
    return any | w;
}

/* The gather at d = 4 (see the SSE2 form): vld4q_u8 deinterleaves 64 bytes
 * into the four byte lanes of 16 words; the same blocks, loaded from their
 * first sample (lane 0) or from 3 bytes before it (lane 3). */
static inline void gather1(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst)
{
    int k = 0;
    if (d == 4) {
        for (; k + 16 <= n; k += 16) {
            const uint8_t *s = src + 4 * k;
            if (k + 17 <= n)
                vst1q_u8(dst + k, vld4q_u8(s).val[0]);
            else if (k > 0)
                vst1q_u8(dst + k, vld4q_u8(s - 3).val[3]);
            else
                break; /* n = 16 exactly: 61 bytes, no whole load fits */
        }
    }
    if (k < n) /* (a whole number of blocks, the column scans' 32: no call) */
        cdsp__edges_gather_c(src + (ptrdiff_t)k * d, d, n - k, dst + k);
}

void cdsp__edges_gather_simd(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst)
{
    gather1(src, d, n, dst);
}

/* (internal.h) the rows in one call; 32 samples at d = 4 without the
 * tests (see the SSE2 form) */
void cdsp__edges_gather_rows_simd(const uint8_t *src, ptrdiff_t stride, ptrdiff_t d, int n, int rows,
                                  uint8_t *dst, ptrdiff_t dstride)
{
    int r;
    if (d == 4 && n == 32) {
        for (r = 0; r < rows; r++, src += stride, dst += dstride) {
            vst1q_u8(dst, vld4q_u8(src).val[0]);
            vst1q_u8(dst + 16, vld4q_u8(src + 61).val[3]);
        }
        return;
    }
    for (r = 0; r < rows; r++, src += stride, dst += dstride)
        gather1(src, d, n, dst);
}
/* cdsp__noise_small (see the SSE2 form): vld2q_u8 splits the pairs */
void cdsp__noise_small_simd(const uint8_t *q, size_t n, uint32_t cnt[4])
{
    size_t i = 0;
    while (i + 16 <= n) {
        uint8x16_t c0 = vdupq_n_u8(0), c1 = c0, c2 = c0, c3 = c0;
        size_t end = n - i > 255 * 16 ? i + 255 * 16 : n;
        for (; i + 16 <= end; i += 16) {
            uint8x16x2_t p = vld2q_u8(q + 2 * i);
            uint8x16_t d = vabdq_u8(p.val[1], p.val[0]);
            c0 = vsubq_u8(c0, vceqq_u8(d, vdupq_n_u8(0)));
            c1 = vsubq_u8(c1, vceqq_u8(d, vdupq_n_u8(1)));
            c2 = vsubq_u8(c2, vceqq_u8(d, vdupq_n_u8(2)));
            c3 = vsubq_u8(c3, vceqq_u8(d, vdupq_n_u8(3)));
        }
        cnt[0] += vaddlvq_u8(c0);
        cnt[1] += vaddlvq_u8(c1);
        cnt[2] += vaddlvq_u8(c2);
        cnt[3] += vaddlvq_u8(c3);
    }
    cdsp__noise_small_c(q + 2 * i, n - i, cnt);
}

#endif

#else
/* ISO C forbids an empty translation unit */
typedef int cdsp__edges_simd_unused;
#endif
