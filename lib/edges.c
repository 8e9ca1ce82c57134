/*
 * edges.c - subpixel edge points by the partial area effect
 * (A. Trujillo-Pino, K. Krissian, M. Aleman-Flores, D. Santana-Cedres,
 * "Accurate subpixel edge location based on partial area effect", Image and
 * Vision Computing 31(1), 2013; first-order variant).
 *
 * A pixel's value is the area-weighted mix of the intensities A and B on the
 * two sides of the edge. Across a window of 2h+1 pixels perpendicular to a
 * near-vertical edge, the sum of one row is therefore
 *     S = (h + 1/2)(A + B) + e (A - B)
 * where e is the edge's offset from the window's centre in that row, exactly,
 * for any straight edge and (because a symmetric blur only moves intensity
 * from one side of the edge to the other within the row) for a blurred edge
 * too, as long as the window spans the blur. With three rows k = -1, 0, 1:
 *     offset a = (mean S_k - (h+1/2)(A+B)) / (A - B)
 *     slope  b = (S_1 - S_-1) / (2 (A - B))
 * A and B are first taken from the window's end pixels, then (second pass,
 * see refine()) as each side's mean over its span, which removes most of the
 * bias a shaded pipe's limb causes. Near-horizontal edges are the same with
 * rows and columns exchanged.
 *
 * Only every step-th row (for near-vertical edges) and column (for
 * near-horizontal edges) is read: a frame costs about 2/step of a full
 * pass. Along a scanline, candidates are local maxima of the central
 * difference above half the minimum contrast (a step blurred with sigma
 * 1 px keeps ~0.7 of its contrast in the central difference).
 */
#include "internal.h"

void cdsp_edge_params_default(cdsp_edge_params *p)
{
    p->step = 4;
    p->half_window = 4;
    p->min_contrast = R(0.06);
    p->roi.x = p->roi.y = p->roi.w = p->roi.h = 0;
    p->coarse = 0;
}

cdsp_status cdsp_image_check(const cdsp_image *img)
{
    size_t bpp;
    if (!img || !img->data)
        return CDSP_E_ARG;
    if (img->width <= 0 || img->height <= 0)
        return CDSP_E_ARG;
    if (img->bits < 1 || img->bits > 16)
        return CDSP_E_FORMAT;
    bpp = img->bits <= 8 ? 1u : 2u;
    if (img->stride < (size_t)img->width * bpp || (bpp == 2 && img->stride % 2 != 0))
        return CDSP_E_FORMAT;
    return CDSP_OK;
}

/* The pixels around a scan's position (s, t): sample i along the scan, k
 * across it, is at element i*ds + k*dt from b (elements of the frame's
 * size). The refinement reads 3 x (2h + 3) of them; one base pointer and
 * two strides, set up once, in place of a row product and a width test per
 * read: the same integers as img_px gives, so the estimate is unchanged. */
typedef struct {
    const unsigned char *b;
    ptrdiff_t ds, dt;
    int wide; /* 16-bit samples */
} win_px;

static void win_at(const cdsp_image *img, int horizontal, int s, int t, win_px *w)
{
    size_t bpp = img->bits <= 8 ? 1u : 2u;
    ptrdiff_t row = (ptrdiff_t)(img->stride / bpp);
    int x = horizontal ? s : t, y = horizontal ? t : s;
    w->b = (const unsigned char *)img->data + (size_t)y * img->stride + (size_t)x * bpp;
    w->ds = horizontal ? 1 : row;
    w->dt = horizontal ? row : 1;
    w->wide = bpp == 2;
}

/* The integer part of the refinement: the 3x3 Sobel-like components g[0]
 * (along the scan) and g[1] (across), and for the rows k = -1, 0, 1 the
 * window sums S[k + 1] over -h .. h and the end pixels' sums AB[0] (at -h)
 * and AB[1] (at +h). wide (and h, at the default) is a constant at each
 * call below: byte and 16-bit forms, no width test per read, and the
 * default window unrolled. */
static inline void window_sums(const win_px *w, int wide, int h, int g[2], int S[3], int AB[2])
{
    int k, c;
    const uint8_t *b8 = w->b;
    const uint16_t *b16 = (const uint16_t *)(const void *)w->b;
#define WPX(i, k) (wide ? (int)b16[(ptrdiff_t)(i) * w->ds + (ptrdiff_t)(k) * w->dt] \
                        : (int)b8[(ptrdiff_t)(i) * w->ds + (ptrdiff_t)(k) * w->dt])
    g[0] = g[1] = AB[0] = AB[1] = 0;
    for (k = -1; k <= 1; k++) {
        int wk = k == 0 ? 2 : 1, sum = 0;
        g[0] += wk * (WPX(1, k) - WPX(-1, k));
        g[1] += wk * (WPX(k, 1) - WPX(k, -1));
        for (c = -h; c <= h; c++)
            sum += WPX(c, k);
        S[k + 1] = sum;
        AB[0] += WPX(-h, k);
        AB[1] += WPX(h, k);
    }
#undef WPX
}

/* window_sums for 8-bit samples at the default h = 4, in three parts
 * so that a candidate refine_core rejects early reads no more: the end
 * pixels' sums (6 pixels) first, which alone reject about half the
 * candidates of the full search's column scans (|A - B| too small: 970 of
 * 2336 on the paper frame), then the Sobel components (the 8 pixels of
 * the 3x3 around the centre), then the window sums (27 pixels, the
 * compiler keeping those already read). Offsets computed once; integer
 * sums, so the same numbers in any order. */
static inline void ends8_h4(const win_px *w, int AB[2])
{
    const uint8_t *b = w->b;
    ptrdiff_t o4 = 4 * w->ds, dt = w->dt;
    AB[0] = b[-o4 - dt] + b[-o4] + b[-o4 + dt];
    AB[1] = b[o4 - dt] + b[o4] + b[o4 + dt];
}

static inline void sobel8(const win_px *w, int g[2])
{
    const uint8_t *b = w->b;
    ptrdiff_t o1 = w->ds, dt = w->dt;
    int m0 = b[-o1 - dt], m1 = b[-o1], m2 = b[-o1 + dt];
    int p0 = b[o1 - dt], p1 = b[o1], p2 = b[o1 + dt];
    g[0] = (p0 - m0) + 2 * (p1 - m1) + (p2 - m2);
    g[1] = (m2 - m0) + 2 * (b[dt] - b[-dt]) + (p2 - p0);
}

static inline void sums8_h4(const win_px *w, int S[3])
{
    const uint8_t *b = w->b;
    ptrdiff_t o1 = w->ds, o2 = 2 * w->ds, o3 = 3 * w->ds, o4 = 4 * w->ds;
    int k;
    for (k = 0; k < 3; k++) {
        const uint8_t *q = b + (ptrdiff_t)(k - 1) * w->dt;
        S[k] = q[-o4] + q[-o3] + q[-o2] + q[-o1] + q[0] + q[o1] + q[o2] + q[o3] + q[o4];
    }
}

/* Intensity at pos along the scan from the window's centre (row k across
 * it), interpolated linearly between pixel centres: the caller guarantees
 * lim = h + 1 pixels on both sides of s (the scan keeps that margin from
 * the frame's border). The second pass samples at
 * |pos| <= |a| + |b| + (h + 1/2)/2 (|a| <= 1, |b| <= 1.05 there), i.e.
 * <= 3.3 for h = 2, one pixel past that margin: clamp (a constant at each
 * call) then clamps pos to [-lim, lim] and reads the far neighbour only
 * when its weight is non-zero, so pos = +lim never reads s + lim + 1. For
 * h >= 3 the bound (3.8 at h = 3, 4.3 at h = 4, ..., h + 1 - (h - 2.6)/2)
 * stays inside the margin with its far neighbour, so the clamp would
 * change nothing and the far neighbour is always in the window: read with
 * weight f = 0 it adds exactly 0 ((1 - 0) p0 + 0 p1 = p0), the same number
 * without the tests. */
static inline cdsp_real sample_at(const win_px *w, int wide, int clamp, int k, cdsp_real pos, int lim)
{
    int i;
    cdsp_real f;
    ptrdiff_t o;
    if (clamp) {
        if (pos < -(cdsp_real)lim)
            pos = -(cdsp_real)lim;
        if (pos > (cdsp_real)lim)
            pos = (cdsp_real)lim;
    }
    /* floor of a small finite value (|pos| <= lim): truncation, one down
     * below zero; the same integer as R_FLOOR without its call */
    i = (int)pos;
    if ((cdsp_real)i > pos)
        i--;
    f = pos - (cdsp_real)i;
    o = (ptrdiff_t)i * w->ds + (ptrdiff_t)k * w->dt;
#define SPX(o) (wide ? (cdsp_real)((const uint16_t *)(const void *)w->b)[o] : (cdsp_real)w->b[o])
    if (clamp && f <= R(0))
        return SPX(o);
    return (R(1) - f) * SPX(o) + f * SPX(o + w->ds);
#undef SPX
}

/* The second pass's side sums (refine_core): rows k = -1, 0, 1 sampled at
 * D on either side of the first pass's edge a + k b. wide and clamp are
 * constants at each call (as for window_sums): no width test per sample. */
static inline void side_sums(const win_px *w, int wide, int clamp, cdsp_real a, cdsp_real b, cdsp_real D,
                             int lim, cdsp_real *sa, cdsp_real *sb)
{
    int k;
    *sa = *sb = R(0);
    for (k = -1; k <= 1; k++) {
        cdsp_real ek = a + (cdsp_real)k * b;
        *sa += sample_at(w, wide, clamp, k, ek - D, lim);
        *sb += sample_at(w, wide, clamp, k, ek + D, lim);
    }
}

/* Refine candidate (s, t): returns 1 and fills e when the partial-area
 * estimate is a valid edge owned by this scan direction. Internal entry
 * (internal.h): the reference scan of tests/lib/test_edges_scan.c calls it. */
static inline int refine_core(const cdsp_image *img, int horizontal, int s, int t, int h, int min_step,
                              cdsp_edge *e, cdsp_edge *hint);

int cdsp__edges_refine(const cdsp_image *img, int horizontal, int s, int t, int h, int min_step,
                       cdsp_edge *e)
{
    return refine_core(img, horizontal, s, t, h, min_step, e, NULL);
}

/* The refinement proper. hint (the coarse pass's rows, NULL elsewhere):
 * when a row's candidate is owned by the column family and its Sobel
 * component across the row, |gt|, is at least 2 thr (the column scan's
 * candidate test needs a central difference of thr there, which a 3x3
 * Sobel weighs about 4 times), *hint = (s, t, gs, gt) and 2 is returned:
 * where a near-horizontal contour crosses the row, with its slope
 * -gs / gt (docs/method.md §2). */
static inline int refine_core(const cdsp_image *img, int horizontal, int s, int t, int h, int min_step,
                              cdsp_edge *e, cdsp_edge *hint)
{
    int S[3], g[2], AB[2], A, B, gs, gt, h4;
    cdsp_real diff, a, b, norm, gsn, gtn;
    win_px w;
    win_at(img, horizontal, s, t, &w);
    h4 = !w.wide && h == 4; /* the default: 8 bit, half window 4 */
    if (h4) {
        /* without hints a too small step rejects the candidate whichever
         * family owns it: before the rest is read */
        ends8_h4(&w, AB);
        if (!hint && iabs(AB[0] - AB[1]) < 3 * min_step)
            return 0;
        sobel8(&w, g);
    } else if (w.wide) {
        window_sums(&w, 1, h, g, S, AB);
    } else {
        window_sums(&w, 0, h, g, S, AB);
    }
    gs = g[0];
    gt = g[1];
    A = AB[0];
    B = AB[1];
    /* Which family owns the edge: compare the 3x3 Sobel-like components;
     * ties (45 degrees) go to the row family only, so no edge is reported
     * twice */
    if (horizontal ? (iabs(gs) < iabs(gt)) : (iabs(gs) <= iabs(gt))) {
        int thr = min_step / 2 > 0 ? min_step / 2 : 1;
        if (!hint || iabs(gt) < 2 * thr)
            return 0;
        hint->x = (cdsp_real)s;
        hint->y = (cdsp_real)t;
        hint->gx = (cdsp_real)gs;
        hint->gy = (cdsp_real)gt;
        return 2;
    }
    /* A, B: means of the three end pixels (kept as sums of 3 until here) */
    if (iabs(A - B) < 3 * min_step)
        return 0;
    if (h4)
        sums8_h4(&w, S);
    diff = (cdsp_real)(A - B) / R(3);
    a = ((cdsp_real)(S[0] + S[1] + S[2]) / R(3) - (R(h) + R(0.5)) * (cdsp_real)(A + B) / R(3)) / diff;
    b = (cdsp_real)(S[2] - S[0]) / (R(2) * diff);
    /* Second pass: each side's intensity as its mean over its part of the
     * window, not its value at the window's end. S = L_A mean_A + L_B mean_B
     * holds for any intensity profile; the end value stands for the mean
     * only when the side is flat, and a shaded pipe is not: toward its limb
     * a Lambertian cylinder's intensity changes like the square root of the
     * distance from it. The mean of a linear profile is its value half way
     * along the span, and that of a square-root profile nearly so (4/9), so
     * both sides of each row are sampled (linear interpolation between pixel
     * centres) at the same distance D = (h + 1/2)/2 from that row's edge:
     * the same distance, so the blur that leaks across the edge there is
     * nearly the same on both sides and cancels in A + B. Measured on
     * rendered frames: a flat-lit edge keeps a zero-mean error of 0.004 px
     * rms (sigma 0.7 blur), while the bias of a shaded pipe's contour falls
     * 3-6 fold (0.06 -> 0.01-0.02 px at 85 % ambient light, README). */
    if (R_FABS(a) <= R(1) && R_FABS(b) <= R(1.05)) {
        cdsp_real sa, sb, HH = R(h) + R(0.5), D = HH / R(2);
        if (w.wide)
            side_sums(&w, 1, 1, a, b, D, h + 1, &sa, &sb);
        else if (h >= 3) /* the default h = 4: no clamp (sample_at) */
            side_sums(&w, 0, 0, a, b, D, h + 1, &sa, &sb);
        else
            side_sums(&w, 0, 1, a, b, D, h + 1, &sa, &sb);
        if (R_FABS(sa - sb) >= R(1.5) * (cdsp_real)min_step) {
            diff = (sa - sb) / R(3);
            a = ((cdsp_real)(S[0] + S[1] + S[2]) / R(3) - HH * (sa + sb) / R(3)) / diff;
            b = (cdsp_real)(S[2] - S[0]) / (R(2) * diff);
        }
    }
    /* the edge must cross the candidate pixel's neighbourhood, at <= 45 deg;
     * the slope is let through to 1.25: at 45 degrees the outer rows'
     * windows reach into the blur, which inflates |b| (1.058 at blur 0.7,
     * more with more blur: every point of a 45-degree contour was lost);
     * which family owns the edge was decided by the gradient above */
    if (!(R_FABS(a) <= R(1)) || !(R_FABS(b) <= R(1.25)))
        return 0;
    /* gradient: from A's side to B's side, normal (1, -b) in (s, t) */
    norm = R_SQRT(R(1) + b * b);
    gsn = -diff / norm;
    gtn = diff * b / norm;
    if (horizontal) {
        e->x = (cdsp_real)s + a;
        e->y = (cdsp_real)t;
        e->gx = gsn;
        e->gy = gtn;
    } else {
        e->x = (cdsp_real)t;
        e->y = (cdsp_real)s + a;
        e->gx = gtn;
        e->gy = gsn;
    }
    return 1;
}

/*
 * The search for candidates. A candidate is a position s of a scanline
 * where |g(s)|, g(s) = f(s+1) - f(s-1) the central difference along the
 * scan, is at least thr and a local maximum: |g(s)| > |g(s-1)| and
 * |g(s)| >= |g(s+1)| (ties broken to the left). For 8-bit frames the test
 * is evaluated for many positions at once by one primitive,
 * cdsp__edges_peaks (portable below; SIMD forms in lib/edges_simd.c), on
 * five parallel runs of pixels f(s-2) .. f(s+2):
 *   - rows: SEG_RUN positions of the row, the five runs the row shifted by
 *     -2 .. +2;
 *   - columns: CHUNK columns x = xs + k*step at a time, walked row by row
 *     (memory order: a block of columns reads a few cache lines per row,
 *     where a column at a time reads a new line at every pixel); each
 *     row's samples at the block's columns are gathered once
 *     (cdsp__edges_gather) into rows of CHUNK bytes laid end to end, and
 *     the five runs are that buffer from its rows 0 .. 4: four candidate
 *     rows per call, at any step (scan_cols_block). Until issue 17's second
 *     pass the runs were the frame's rows c-2 .. c+2 over the block's whole
 *     span, every pixel between the columns included, masked to the
 *     sampled ones, one call per row, and steps above 8 (the coarse pass's
 *     columns) took the per-pixel test: every row was read by five tests,
 *     step times wider than needed;
 *   - column segments (tracking): the segment gathered, then as a row.
 * Candidates are then refined in the order of the plain definition (along
 * the scan for rows; for a block of columns row by row, left to right
 * within a row), so the edges, and their order, are those of a pixel by
 * pixel scan: tests/lib/test_edges_scan.c compares them bit for bit with
 * one. 16-bit frames take the per-pixel test.
 */
#define CHUNK 32
/* Positions a row segment's test takes at once (a multiple of 8): 128
 * with SIMD, where each call and its setup cost about as much as 3
 * vectors of the test (the full search's coarse rows, callgrind: 5.180 ->
 * 5.133 M instructions at 128 from 64; 256 gained nothing more); 64
 * without, where the flags and the run on the stack would grow by 128
 * bytes on an MCU for a smaller share. */
#if CDSP__SIMD
#define SEG_RUN 128
#else
#define SEG_RUN 64
#endif
/* A run may take up to SEG_TAIL more positions: a segment's last few (a
 * coarse row's 4 at the paper frame's width) would be a run shorter than
 * the SIMD test's vector, which takes the portable form (~220
 * instructions for 4 positions; callgrind) */
#define SEG_TAIL 15

/* Candidate flags as bits (cdsp__edges_peaks), 32 a word: a word of
 * zeros (nearly every word: edges are sparse along a line) is passed over
 * with one test, and a word's set bits found one by one (lowest_bit). Until
 * issue 17's third pass the flags were bytes read 8 at a time and then one
 * by one: on the paper frame's full search the column blocks' flags, in
 * which nearly every call finds a candidate (the blocks are read where the
 * hints put a contour), cost 0.22 M instructions to read. */
#define FLAG_WORDS(n) (((n) + 31) / 32)

/* The index of a non-zero word's lowest set bit: the instruction where
 * the target has one (the SIMD targets: x86-64, AArch64), else by a de
 * Bruijn sequence (no library call on any target). */
static inline int lowest_bit(uint32_t w)
{
#if CDSP__SIMD && defined(__GNUC__)
    return __builtin_ctz(w);
#else
    static const uint8_t pos[32] = {0,  1,  28, 2,  29, 14, 24, 3, 30, 22, 20, 15, 25, 17, 4,  8,
                                    31, 27, 13, 23, 21, 19, 16, 7, 26, 12, 18, 6,  11, 5,  10, 9};
    return pos[(uint32_t)((w & (0u - w)) * 0x077CB531u) >> 27];
#endif
}

/* Portable form of the primitive (internal.h). Byte-wide arithmetic (|a -
 * b| of 8-bit samples fits a byte), each word's flags then set bit by bit
 * (restrict: bits never overlaps the frame). */
uint32_t cdsp__edges_peaks_c(const uint8_t *const f[5], const uint8_t *sel, size_t n, int thr,
                             uint32_t *bits)
{
    const uint8_t *restrict m2 = f[0], *restrict m1 = f[1], *restrict z = f[2];
    const uint8_t *restrict p1 = f[3], *restrict p2 = f[4];
    uint32_t *restrict out = bits;
    size_t i, w0;
    uint8_t t = (uint8_t)thr;
    uint32_t any = 0;
    for (w0 = 0; w0 < n; w0 += 32) {
        size_t e = n - w0 < 32 ? n : w0 + 32;
        uint32_t word = 0;
        for (i = w0; i < e; i++) {
            uint8_t gl = (uint8_t)(z[i] > m2[i] ? z[i] - m2[i] : m2[i] - z[i]);
            uint8_t gc = (uint8_t)(p1[i] > m1[i] ? p1[i] - m1[i] : m1[i] - p1[i]);
            uint8_t gr = (uint8_t)(p2[i] > z[i] ? p2[i] - z[i] : z[i] - p2[i]);
            uint32_t c = (uint32_t)((gc >= t) & (gc > gl) & (gc >= gr) & (sel ? sel[i] : 1u));
            word |= c << (i - w0);
        }
        out[w0 / 32] = word;
        any |= word;
    }
    return any;
}

/* |g| at position s of a run (pixel 0 at base, element stride es, in
 * samples of the frame's size): |f(s+1) - f(s-1)|. */
static inline int absg(const cdsp_image *img, const unsigned char *base, ptrdiff_t es, int s)
{
    if (img->bits <= 8)
        return iabs((int)base[(s + 1) * es] - (int)base[(s - 1) * es]);
    return iabs((int)((const uint16_t *)(const void *)base)[(s + 1) * es] -
                (int)((const uint16_t *)(const void *)base)[(s - 1) * es]);
}

/* The per-pixel candidate test (16-bit frames, column segments). */
static inline int is_peak(const cdsp_image *img, const unsigned char *base, ptrdiff_t es, int s, int thr)
{
    int a = absg(img, base, es, s);
    return a >= thr && a > absg(img, base, es, s - 1) && a >= absg(img, base, es, s + 1);
}

/* Portable form of the gather (internal.h): n 8-bit samples src[0],
 * src[d], src[2d], ... into dst[0, n), a strided run made contiguous so
 * that the candidate test runs on it many positions at once. Each sample
 * is read once here where the per-pixel test would read it up to six
 * times (three |g| of two samples each). */
void cdsp__edges_gather_c(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst)
{
    int k;
    for (k = 0; k + 4 <= n; k += 4, src += 4 * d) {
        dst[k] = src[0];
        dst[k + 1] = src[d];
        dst[k + 2] = src[2 * d];
        dst[k + 3] = src[3 * d];
    }
    for (; k < n; k++, src += d)
        dst[k] = *src;
}

void cdsp__edges_gather_rows_c(const uint8_t *src, ptrdiff_t stride, ptrdiff_t d, int n, int rows,
                               uint8_t *dst, ptrdiff_t dstride)
{
    int r;
    for (r = 0; r < rows; r++, src += stride, dst += dstride)
        cdsp__edges_gather_c(src, d, n, dst);
}

/*
 * Scan one line: horizontal != 0 scans row `line` over x in [from, to);
 * otherwise column `line` over y in [from, to). The caller guarantees the
 * window fits: from - h - 1 >= 0, to + h + 1 <= extent, 1 <= line <= other
 * extent - 2. Returns points written (<= cap).
 */
static inline size_t scan_segment(const cdsp_image *img, const cdsp_edge_params *p, int horizontal,
                                  int line, int from, int to, cdsp_edge *out, size_t cap,
                                  cdsp_edge *htop, size_t *nh);

/* A point's position is the mean of its window's three scanlines'
 * partial-area estimates (refine_core: (S[0] + S[1] + S[2]) / 3), so points
 * d * step apart along a family share max(0, 3 - d step) of them: with
 * v the variance of one scanline's estimate a point has v / 3 and two
 * such neighbours covariance (3 - d step) v / 9. A line fitted to them as
 * if independent has its variance low by the sum of the correlations over
 * all lags, 1 + (2/3) sum_d max(0, 3 - d step): 3 at step 1, 5/3 at 2, 1
 * from 3 on (tests/lib/test_frame.c test_sigma_step measures it). */
cdsp_real cdsp__edges_scan_var(int step)
{
    int d, shared = 0;
    for (d = 1; step > 0 && d * step < 3; d++)
        shared += 3 - d * step;
    return R(1) + R(2) * (cdsp_real)shared / R(3);
}

size_t cdsp__edges_scan_segment(const cdsp_image *img, const cdsp_edge_params *p, int horizontal,
                                int line, int from, int to, cdsp_edge *out, size_t cap)
{
    return scan_segment(img, p, horizontal, line, from, to, out, cap, NULL, NULL);
}

/* The scan proper. htop (the coarse pass's rows; NULL elsewhere): the
 * hints refine_core gives are written downward from it, htop[-1 - *nh],
 * and count against cap with the edges (the scan stops when edges + new
 * hints reach cap); returns the edges written. */
static inline size_t scan_segment(const cdsp_image *img, const cdsp_edge_params *p, int horizontal,
                                  int line, int from, int to, cdsp_edge *out, size_t cap,
                                  cdsp_edge *htop, size_t *nh)
{
    int h = p->half_window, s0, m;
    int full = (1 << img->bits) - 1;
    int min_step = (int)(p->min_contrast * (cdsp_real)full + R(0.5));
    int thr = min_step / 2 > 0 ? min_step / 2 : 1;
    size_t n = 0, bpp = img->bits <= 8 ? 1u : 2u;
    const unsigned char *base = (const unsigned char *)img->data;
    ptrdiff_t es;
    uint32_t flag[FLAG_WORDS(SEG_RUN + SEG_TAIL)];
    uint8_t run[SEG_RUN + SEG_TAIL + 4];
    size_t nh0 = htop ? *nh : 0;
    if (to - from < 3 || cap == 0)
        return 0;
    /* the run's pixel s=0 and the element stride along it */
    if (horizontal) {
        base += (size_t)line * img->stride;
        es = 1;
    } else {
        base += (size_t)line * bpp;
        es = (ptrdiff_t)(img->stride / bpp);
    }
    /* candidates s in [from+1, to-1): a local maximum of |g| needs g at s-1..s+1 */
    for (s0 = from + 1; s0 < to - 1; s0 += m) {
        int i, k;
        m = (to - 1 - s0) <= SEG_RUN + SEG_TAIL ? (to - 1 - s0) : SEG_RUN;
        uint32_t wb;
        if (bpp == 1) {
            /* a column's run s0 - 2 .. s0 + m + 1 gathered first (tracking
             * reads column segments): the same samples, contiguous */
            const uint8_t *r = (const uint8_t *)base + s0;
            if (es != 1) {
                cdsp__edges_gather((const uint8_t *)base + (s0 - 2) * es, es, m + 4, run);
                r = run + 2;
            }
            {
                const uint8_t *const f[5] = {r - 2, r - 1, r, r + 1, r + 2};
                if (!cdsp__edges_peaks(f, NULL, (size_t)m, thr, flag))
                    continue;
            }
        } else {
            for (k = 0; k < FLAG_WORDS(m); k++)
                flag[k] = 0;
            for (i = 0; i < m; i++)
                flag[i / 32] |= (uint32_t)is_peak(img, base, es, s0 + i, thr) << (i % 32);
        }
        /* the words of the run's m flags (no bit at m or past it); the
         * plain scans' loop apart from the coarse rows' (one more branch
         * per candidate there cost the tracked path 2 % more
         * instructions) */
        for (k = 0; k < FLAG_WORDS(m) && !htop; k++)
            for (wb = flag[k]; wb; wb &= wb - 1)
                if (cdsp__edges_refine(img, horizontal, s0 + 32 * k + lowest_bit(wb), line, h, min_step,
                                       &out[n]) &&
                    ++n == cap)
                    return n;
        for (k = 0; k < FLAG_WORDS(m) && htop; k++)
            for (wb = flag[k]; wb; wb &= wb - 1) {
                int r = refine_core(img, horizontal, s0 + 32 * k + lowest_bit(wb), line, h, min_step, &out[n],
                                    &htop[-1 - (ptrdiff_t)*nh]);
                n += r == 1;
                *nh += r == 2;
                if (r && n + (*nh - nh0) == cap)
                    return n;
            }
    }
    return n;
}

/*
 * Near-horizontal edges over the columns x = xs + k*step, k < ncols <=
 * CHUNK, rows [from, to): candidate rows c in [from, to - 1), listed row by
 * row and left to right (see above). 8-bit frames: each row's samples at
 * the block's columns are gathered once, into rows of CHUNK bytes (zero
 * past ncols: |g| = 0 there fails every threshold) laid one after the
 * other, rows c - 2 .. c + COL_BATCH + 1 for COL_BATCH candidate rows at a
 * time. The five runs of the test are then that buffer from its rows 0 ..
 * 4, COL_BATCH * CHUNK positions long: position r * CHUNK + k is column k
 * of candidate row c + r, so one call tests COL_BATCH rows, and its flags
 * come in the order of the plain definition. 16-bit frames take the
 * per-pixel test.
 */
#define COL_BATCH 4
/* Rows the gather's prefetch runs ahead (CDSP__PREFETCH): a miss to
 * memory lasts about as long as the block's scan of this many rows. */
#define COL_PREFETCH 16

/* The cache lines of bytes [p, p + n) (1 <= n <= 129: the default
 * step's block spans 125) by three addresses no more than 64 apart, for
 * CDSP__PREFETCH; a wider block (a step doubled) only its first 129. A
 * macro, not a function: GCC 12 finds a void function whose only effect
 * is __builtin_prefetch "looping const" and drops its calls. */
#define PREFETCH_SPAN(p, n)                                                                        \
    do {                                                                                           \
        const uint8_t *pf_p = (p);                                                                 \
        int pf_n = (n) < 129 ? (n) : 129;                                                          \
        CDSP__PREFETCH(pf_p);                                                                      \
        CDSP__PREFETCH(pf_p + (pf_n - 1) / 2);                                                     \
        CDSP__PREFETCH(pf_p + pf_n - 1);                                                           \
    } while (0)

static size_t scan_cols_block(const cdsp_image *img, const cdsp_edge_params *p, int step, int xs,
                              int ncols, int from, int to, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, c, k, i;
    int full = (1 << img->bits) - 1;
    int min_step = (int)(p->min_contrast * (cdsp_real)full + R(0.5));
    int thr = min_step / 2 > 0 ? min_step / 2 : 1;
    size_t n = 0, bpp = img->bits <= 8 ? 1u : 2u;
    ptrdiff_t es = (ptrdiff_t)(img->stride / bpp);
    const uint8_t *col = (const uint8_t *)img->data + xs;
    if (bpp == 1) {
        int pf, span = (ncols - 1) * step + 1;
        uint8_t rows[(COL_BATCH + 4) * CHUNK];
        uint32_t flag[FLAG_WORDS(COL_BATCH * CHUNK)], wb;
        const uint8_t *const f[5] = {rows, rows + CHUNK, rows + 2 * CHUNK, rows + 3 * CHUNK,
                                     rows + 4 * CHUNK};
        if (from >= to - 1)
            return 0;
        for (i = 0; i < (COL_BATCH + 4) * CHUNK; i++)
            rows[i] = 0;
        /* the block's first COL_PREFETCH rows at once, then each row that
         * far ahead of the gather (rows from - 2 .. to + 1 are read) */
        for (pf = from - 2; pf < from - 2 + COL_PREFETCH && pf <= to + 1; pf++)
            PREFETCH_SPAN(col + (ptrdiff_t)pf * es, span);
        cdsp__edges_gather_rows(col + (ptrdiff_t)(from - 2) * es, es, step, ncols, 4, rows, CHUNK);
        for (c = from; c < to - 1; c += COL_BATCH) {
            int nr = to - 1 - c < COL_BATCH ? to - 1 - c : COL_BATCH, np = nr * CHUNK;
            for (; pf < c + 2 + COL_BATCH + COL_PREFETCH && pf <= to + 1; pf++)
                PREFETCH_SPAN(col + (ptrdiff_t)pf * es, span);
            cdsp__edges_gather_rows(col + (ptrdiff_t)(c + 2) * es, es, step, ncols, nr, rows + 4 * CHUNK, CHUNK);
            /* (word i: candidate row c + i, as CHUNK = 32) */
            if (cdsp__edges_peaks(f, NULL, (size_t)np, thr, flag))
                for (i = 0; i < nr; i++)
                    for (wb = flag[i]; wb; wb &= wb - 1)
                        if (cdsp__edges_refine(img, 0, c + i, xs + lowest_bit(wb) * step, h, min_step, &out[n]) &&
                            ++n == cap)
                            return n;
            /* rows c + nr - 2 .. c + nr + 1 to the front: the next batch's first four */
            for (i = 0; i < 4 * CHUNK; i++)
                rows[i] = rows[np + i];
        }
        return n;
    }
    for (c = from; c < to - 1; c++)
        for (k = 0; k < ncols; k++) {
            int x = xs + k * step;
            if (is_peak(img, (const unsigned char *)img->data + (size_t)x * bpp, es, c, thr) &&
                cdsp__edges_refine(img, 0, c, x, h, min_step, &out[n]) && ++n == cap)
                return n;
        }
    return n;
}

/*
 * Tracking's column segments, a block at a time (internal.h): column
 * x_k = xs + k*step (k < ncols <= CDSP__BAND_COLS) over [from[k], to[k]),
 * the edges of cdsp__edges_scan_segment(img, p, 0, x_k, from[k], to[k])
 * for k = 0, 1, ... in that order, with the same cap rule (the count
 * stops at cap, with the edges a column at a time gives). One segment of
 * ~25 pixels per call cost ~490 instructions besides its refinements on
 * the paper frame's tracked bands (callgrind, issue 17: ~1200 segments, a
 * quarter of a tracked frame). Here the block's segments are laid side by
 * side, each shifted to its own start: row j of the buffer holds pixel
 * j of every column's run (rows from[k] - 1 + j), so the five runs of the
 * candidate test are again the buffer's rows 0 .. 4 (vertical neighbours
 * within each column) and one call tests COL_BATCH positions of all the
 * columns. (Gathering the frame's rows over the union of the bands, as
 * scan_cols_block does, read ~4 times the pixels on the paper frame, the
 * union ~93 rows a block against 25 a segment, and cost 1.71 M
 * instructions against the segments' 1.34 M.) Each flag is kept
 * only inside its column's segment; the candidates, listed position by
 * position, are then ordered by column (a stable counting sort: within a
 * column they stay in row order) and refined in that order, the
 * per-column scans' order. Candidates and refinements are those of the
 * per-column scans (same test on the same pixels, same positions), so the
 * edges are too. A block with a segment longer than BAND_SPAN or more than
 * BAND_LIST candidates, and 16-bit frames, take the per-column scans.
 */
#define BAND_SPAN 256
#define BAND_LIST 256
typedef char cdsp__band_cols_is_chunk[CDSP__BAND_COLS == CHUNK ? 1 : -1];
/* a candidate row's flags are one word of them (scan_cols_block too) */
typedef char cdsp__chunk_is_a_word[CHUNK == 32 ? 1 : -1];
size_t cdsp__edges_scan_col_bands(const cdsp_image *img, const cdsp_edge_params *p, int step, int xs,
                                  int ncols, const int *from, const int *to, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, full = (1 << img->bits) - 1, c, k, i, L = 0, nl = 0;
    int min_step = (int)(p->min_contrast * (cdsp_real)full + R(0.5));
    int thr = min_step / 2 > 0 ? min_step / 2 : 1;
    size_t n = 0;
    if (cap == 0)
        return 0;
    /* candidates of column k: rows from[k] + 1 + c, c < len[k] (scan_segment's
     * [from + 1, to - 1)); its run: rows from[k] - 1 .. to[k] */
    if (img->bits <= 8) {
        const uint8_t *src[CHUNK];
        int len[CHUNK];
        ptrdiff_t es = (ptrdiff_t)img->stride;
        uint8_t rows[(COL_BATCH + 4) * CHUNK];
        uint32_t flag[FLAG_WORDS(COL_BATCH * CHUNK)], wb;
        const uint8_t *const f[5] = {rows, rows + CHUNK, rows + 2 * CHUNK, rows + 3 * CHUNK,
                                     rows + 4 * CHUNK};
        uint16_t list[BAND_LIST], sorted[BAND_LIST]; /* c * CHUNK + k */
        int cnt[CHUNK + 1], j, even;
        for (k = 0; k < ncols; k++) {
            len[k] = to[k] - from[k] - 2;
            if (len[k] < 1) {
                len[k] = -4; /* no run: never read, zeros */
                src[k] = NULL;
                continue;
            }
            src[k] = (const uint8_t *)img->data + (size_t)(from[k] - 1) * img->stride + (size_t)(xs + k * step);
            L = len[k] > L ? len[k] : L;
        }
        if (L == 0)
            return 0;
        for (k = 0; k < ncols && (len[k] == L || len[k] == -4); k++)
            ;
        even = k == ncols;
        if (L <= BAND_SPAN) {
            for (i = 0; i < (COL_BATCH + 4) * CHUNK; i++)
                rows[i] = 0;
            /* buffer row j: pixel j of each run, 0 past its end (a column
             * without a run is never written: zeros) */
            for (k = 0; k < ncols; k++)
                if (src[k]) { /* every run has >= 5 pixels */
                    const uint8_t *sp = src[k];
                    rows[k] = sp[0];
                    rows[CHUNK + k] = sp[es];
                    rows[2 * CHUNK + k] = sp[2 * es];
                    rows[3 * CHUNK + k] = sp[3 * es];
                    src[k] = sp + 4 * es;
                }
            for (c = 0; c < L && nl >= 0; c += COL_BATCH) {
                int nr = L - c < COL_BATCH ? L - c : COL_BATCH, np = nr * CHUNK;
                if (even) { /* every run this long (no segment clipped): no test per pixel */
                    for (k = 0; k < ncols; k++) {
                        const uint8_t *sp = src[k];
                        if (!sp)
                            continue;
                        if (nr == COL_BATCH) { /* four loads, no loop */
                            rows[4 * CHUNK + k] = sp[0];
                            rows[5 * CHUNK + k] = sp[es];
                            rows[6 * CHUNK + k] = sp[2 * es];
                            rows[7 * CHUNK + k] = sp[3 * es];
                            sp += 4 * es;
                        } else {
                            for (i = 0; i < nr; i++, sp += es)
                                rows[(4 + i) * CHUNK + k] = *sp;
                        }
                        src[k] = sp;
                    }
                } else {
                    for (i = 0; i < nr; i++)
                        for (j = c + 4 + i, k = 0; k < ncols; k++) {
                            uint8_t v = 0;
                            if (j < len[k] + 4) {
                                v = *src[k];
                                src[k] += es;
                            }
                            rows[(4 + i) * CHUNK + k] = v;
                        }
                }
                /* (word i: position c + i of every run, as CHUNK = 32) */
                if (cdsp__edges_peaks(f, NULL, (size_t)np, thr, flag))
                    for (i = 0; i < nr && nl >= 0; i++)
                        for (wb = flag[i]; wb; wb &= wb - 1) {
                            int q = lowest_bit(wb), cc = c + i;
                            if (cc >= len[q])
                                continue;
                            if (nl == BAND_LIST) {
                                nl = -1; /* too many: the per-column scans */
                                break;
                            }
                            list[nl++] = (uint16_t)(cc * CHUNK + q);
                        }
                for (i = 0; i < 4 * CHUNK; i++)
                    rows[i] = rows[np + i];
            }
            if (nl >= 0) {
                for (k = 0; k <= CHUNK; k++)
                    cnt[k] = 0;
                for (i = 0; i < nl; i++)
                    cnt[list[i] % CHUNK + 1]++;
                for (k = 0; k < CHUNK; k++)
                    cnt[k + 1] += cnt[k];
                for (i = 0; i < nl; i++)
                    sorted[cnt[list[i] % CHUNK]++] = list[i];
                for (i = 0; i < nl; i++) {
                    int q = sorted[i] % CHUNK, r = from[q] + 1 + sorted[i] / CHUNK;
                    if (cdsp__edges_refine(img, 0, r, xs + q * step, h, min_step, &out[n]) && ++n == cap)
                        return n;
                }
                return n;
            }
        }
    }
    for (k = 0; k < ncols; k++) {
        n += cdsp__edges_scan_segment(img, p, 0, xs + k * step, from[k], to[k], out + n, cap - n);
        if (n == cap)
            return n;
    }
    return n;
}

/* The roi clipped to the frame (w or h == 0: whole frame). */
void cdsp__edges_clip_roi(const cdsp_image *img, const cdsp_roi *roi, int *x0, int *y0, int *x1,
                          int *y1)
{
    if (roi->w <= 0 || roi->h <= 0) {
        *x0 = 0;
        *y0 = 0;
        *x1 = img->width;
        *y1 = img->height;
        return;
    }
    /* the end in 64 bits: roi.x + roi.w may exceed INT_MAX; a start beyond
     * the frame is its edge (the scans add a step to it) */
    *x0 = roi->x < 0 ? 0 : (roi->x > img->width ? img->width : roi->x);
    *y0 = roi->y < 0 ? 0 : (roi->y > img->height ? img->height : roi->y);
    *x1 = (int64_t)roi->x + roi->w > img->width ? img->width : roi->x + roi->w;
    *y1 = (int64_t)roi->y + roi->h > img->height ? img->height : roi->y + roi->h;
}

cdsp_status cdsp__edge_params_check(const cdsp_edge_params *p)
{
    if (!p || p->step < 1 || p->step > CDSP_EDGE_MAX_STEP || p->half_window < 2 || p->half_window > 8 ||
        !(p->min_contrast > R(0)) || !(p->min_contrast < R(1)) || p->coarse < 0 ||
        p->coarse > CDSP_EDGE_MAX_COARSE)
        return CDSP_E_ARG;
    return CDSP_OK;
}

/* The first row (column) the family scans at `step` in [y0, ...) */
static int first_line(int y0, int step)
{
    return (y0 > 1 ? y0 : 1) + step / 2;
}

/* Near-vertical edges: rows first + k*step of the clipped roi (the full
 * search: first = first_line(y0, step)). */
static size_t scan_rows(const cdsp_image *img, const cdsp_edge_params *p, int first, int step, int x0,
                        int x1, int y1, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, t;
    int from = x0 > h + 1 ? x0 : h + 1, to = x1 < img->width - h - 1 ? x1 : img->width - h - 1;
    size_t count = 0;
    for (t = first; t < y1 - 1 && t < img->height - 1; t += step) {
        count += cdsp__edges_scan_segment(img, p, 1, t, from, to, out + count, cap - count);
        if (count == cap)
            break;
    }
    return count;
}

/* Near-horizontal edges: the same over columns first + k*step, CHUNK
 * columns at a time (the full search: first = first_line(x0, step)). */
static size_t scan_cols_at(const cdsp_image *img, const cdsp_edge_params *p, int first, int step,
                           int y0, int x1, int y1, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, t;
    int last = (x1 - 1 < img->width - 1 ? x1 - 1 : img->width - 1); /* exclusive */
    int from = y0 > h + 1 ? y0 : h + 1, to = y1 < img->height - h - 1 ? y1 : img->height - h - 1;
    size_t count = 0;
    if (cap == 0)
        return 0;
    for (t = first; t < last && from < to; t += CHUNK * step) {
        int ncols = (last - 1 - t) / step + 1;
        if (ncols > CHUNK)
            ncols = CHUNK;
        count += scan_cols_block(img, p, step, t, ncols, from, to, out + count, cap - count);
        if (count == cap)
            break;
    }
    return count;
}

/*
 * When more edges are found than `cap` holds, the family that does not fit
 * is scanned again at twice its step (and again, until it fits), so that the
 * buffer filling up never decides which contours are seen: each family is
 * scanned over the whole roi at one uniform step, and the family with fewer
 * edges keeps its resolution. Rows go first; if rows alone overflow, their
 * step doubles. If rows fit but rows + columns do not, the family with more
 * points (the columns' count is at least what they wrote) is coarsened. A
 * step that has passed the frame's extent reads one line only; if even that
 * overflows (cap smaller than one line's edges) the points found are kept.
 */
static cdsp_status detect_full(const cdsp_image *img, const cdsp_edge_params *p, cdsp_edge *out,
                               size_t cap, size_t *n)
{
    int x0, y0, x1, y1, srow, scol, extent, rows_at = 0;
    size_t nr = 0, nc;
    cdsp_status result = CDSP_OK;
    cdsp__edges_clip_roi(img, &p->roi, &x0, &y0, &x1, &y1);
    extent = img->width > img->height ? img->width : img->height;
    srow = scol = p->step;
    for (;;) {
        /* a step may double while it stays within the frame (no overflow) */
        int can_r = srow <= extent / 2, can_c = scol <= extent / 2;
        if (rows_at != srow) /* rows already in out[0, nr) at this step are kept */
            nr = scan_rows(img, p, first_line(y0, srow), srow, x0, x1, y1, out, cap);
        rows_at = srow;
        if (nr == cap && can_r) {
            srow *= 2;
            result = CDSP_E_CAPACITY;
            continue;
        }
        nc = scan_cols_at(img, p, first_line(x0, scol), scol, y0, x1, y1, out + nr, cap - nr);
        if (nr + nc < cap)
            break;
        result = CDSP_E_CAPACITY;
        if (can_c && (nc >= nr || !can_r))
            scol *= 2;
        else if (can_r)
            srow *= 2;
        else
            break;
    }
    *n = nr + nc;
    return result;
}

/*
 * The coarse pass (p->coarse = F >= 2; docs/method.md §2). The full
 * search's rows are t_j = first + j*step; the coarse rows are those with
 * j % F == 0, scanned exactly as the full search scans them, so their
 * edges are full-search edges. Then only the bands around what they saw
 * are read at full resolution, with the full search's own scans on
 * sub-ranges of its lines, so every edge reported is one the full search
 * reports, in the full search's order.
 * - Rows: an edge owned by the row family lies within 45 degrees of
 *   vertical (refine's ownership test), so a straight contour through an
 *   edge q on coarse row t_k stays within |t - t_k| px of q along row t.
 *   Each fine row between coarse rows k and k + 1 is read around the edges
 *   of both, +- (that distance + BAND_MARGIN px); a coarse row itself is
 *   taken as it was scanned.
 * - Columns: no coarse columns. A column every F*step px read over every
 *   row touches every 64-byte line of the frame at the default 32 px (the
 *   coarse pass alone read 99.7 % of the paper frame, issue 17). A coarse
 *   row's candidate owned by the column family is a hint (refine_core):
 *   where a near-horizontal contour crosses that row, with its slope. A
 *   block of CHUNK columns, whose order must be kept, reads the rows
 *   within F*step of each coarse row where the lines through its hints
 *   (slope within a tolerance) cross the block (band_cols). A contour too
 *   near the rows to make a candidate is seen between two coarse rows
 *   instead: where they differ along a block (gap_hints), the block reads
 *   the gap.
 * The guarantee: every row edge of the full search whose contour (straight,
 * of that family) reaches a coarse row within F rows of it, every column
 * edge within F*step rows of a hint on the line through it, and every
 * column edge inside a gap whose block's samples show a step (gap_hints)
 * is reported; tests/lib/test_edges_scan.c checks exactly that on its
 * table of frames. What can be missed is a short contour lying wholly
 * between two coarse rows, or a contour of less contrast than the gap
 * test's (3/4 of min_step) or shorter along the rows than its samples
 * span; the frame path falls back to the full search when the band edges
 * do not give it a pipe (lib/frame.c).
 * The coarse rows' edges and hints are kept at the end of out while the
 * bands are read into its start; if the two would meet, or the coarse
 * pass overflows, the full search runs instead (its rule for a full
 * buffer applies).
 */
#define BAND_MARGIN 2

/* Backward element copy: dst > src, overlapping (no memmove in the lib). */
static void move_up(cdsp_edge *dst, const cdsp_edge *src, size_t n)
{
    while (n--)
        dst[n] = src[n];
}

/* Candidate range [lo, hi] of a band around coordinate c (+-d px) */
static void band_of(cdsp_real c, int d, int *lo, int *hi)
{
    int ci = (int)R_FLOOR(c);
    *lo = ci - d - BAND_MARGIN;
    *hi = ci + 1 + d + BAND_MARGIN;
}

/* Fine rows j in [j0, j1) in bands; coarse row edges in rc[0, nrc),
 * sorted by row (those of the coarse rows j0/F .. (j1-1)/F + 1 at least). */
static size_t band_rows(const cdsp_image *img, const cdsp_edge_params *p, int F, int j0, int j1, int x0,
                        int y0, int x1, int y1, const cdsp_edge *rc, size_t nrc, cdsp_edge *out,
                        size_t cap, int *full)
{
    int h = p->half_window, step = p->step, t, j;
    int from = x0 > h + 1 ? x0 : h + 1, to = x1 < img->width - h - 1 ? x1 : img->width - h - 1;
    int first = first_line(y0, step), lim = y1 - 1 < img->height - 1 ? y1 - 1 : img->height - 1;
    size_t n = 0, ia = 0, ib = 0, ic = 0; /* coarse row ka: [ia, ib), ka + 1: [ib, ic) */
    int ka = -2;
    for (j = j0, t = first + j0 * step; t < lim && j < j1; j++, t += step) {
        int k = j / F, ta = first + k * F * step, tb = ta + F * step;
        size_t u, v;
        int cur_lo = 0, cur_hi = -1;
        if (k != ka) { /* advance the two coarse rows around t */
            ia = k == ka + 1 ? ib : ia;
            while (ia < nrc && rc[ia].y < (cdsp_real)ta)
                ia++;
            for (ib = ia; ib < nrc && rc[ib].y == (cdsp_real)ta; ib++)
                ;
            for (ic = ib; ic < nrc && rc[ic].y == (cdsp_real)tb; ic++)
                ;
            ka = k;
        }
        if (j % F == 0) { /* a coarse row: as it was scanned */
            if (n + (ib - ia) > cap) {
                *full = 1;
                return n;
            }
            for (u = ia; u < ib; u++)
                out[n++] = rc[u];
            continue;
        }
        /* merge the bands of both coarse rows (each sorted along x) */
        for (u = ia, v = ib; u < ib || v < ic;) {
            int lo, hi;
            if (v >= ic || (u < ib && rc[u].x - (cdsp_real)(t - ta) <= rc[v].x - (cdsp_real)(tb - t))) {
                band_of(rc[u].x, t - ta, &lo, &hi);
                u++;
            } else {
                band_of(rc[v].x, tb - t, &lo, &hi);
                v++;
            }
            if (cur_hi >= cur_lo && lo <= cur_hi + 1) {
                cur_hi = hi > cur_hi ? hi : cur_hi;
                continue;
            }
            if (cur_hi >= cur_lo) {
                int f = cur_lo - 1 < from ? from : cur_lo - 1, e = cur_hi + 2 > to ? to : cur_hi + 2;
                n += cdsp__edges_scan_segment(img, p, 1, t, f, e, out + n, cap - n);
                if (n == cap) {
                    *full = 1;
                    return n;
                }
            }
            cur_lo = lo;
            cur_hi = hi;
        }
        if (cur_hi >= cur_lo) {
            int f = cur_lo - 1 < from ? from : cur_lo - 1, e = cur_hi + 2 > to ? to : cur_hi + 2;
            n += cdsp__edges_scan_segment(img, p, 1, t, f, e, out + n, cap - n);
            if (n == cap) {
                *full = 1;
                return n;
            }
        }
    }
    return n;
}

/* The slope tolerance of a hint (the Sobel components' ratio): +-(ABS +
 * REL |m|) on m = -gs / gt; the ratio's error is rms 0.02-0.06 on the
 * paper frames. A tighter 0.05 + 0.15 |m| (session 6) cut a full search
 * on the paper frame from 5.81 to 5.53 M instructions (callgrind,
 * bench_frame full 1 1) and passed make check-coarse, but lost pipes of
 * the paper's rack (cdsp_tool bench --rack --rack-frames 1: both pipes
 * found in 7 of 10 frames instead of 9, gaps taken for pipes 4 instead of
 * 2): the rack's near-horizontal contours' hints are off by more. */
#define HINT_SLOPE_ABS 0.1
#define HINT_SLOPE_REL 0.25
/* Rows beyond a hint's predicted band: the crossing's own +-1 px, the
 * candidate row within 1 of the contour, and BAND_MARGIN. */
#define HINT_MARGIN 3

/* The rows, relative to the hint's row, where the contour through hint q
 * (slope m = -gs / gt, within its tolerance) crosses the columns [xa, xb]:
 * [*dlo, *dhi] (unclipped). */
static void hint_reach(const cdsp_edge *q, cdsp_real xa, cdsp_real xb, cdsp_real *dlo, cdsp_real *dhi)
{
    cdsp_real m, am, d, ua = xa - q->x - R(1.5), ub = xb - q->x + R(1.5), c[4];
    int i;
    if (q->gy == R(0)) { /* a gap hint (gap_hints): its block's rows toward gx */
        int mine = q->x >= xa && q->x <= xb;
        *dlo = mine ? (q->gx < R(0) ? q->gx : R(0)) : R(1e30);
        *dhi = mine ? (q->gx > R(0) ? q->gx : R(0)) : R(1e30);
        return;
    }
    m = -q->gx / q->gy;
    am = R_FABS(m);
    d = R(HINT_SLOPE_ABS) + R(HINT_SLOPE_REL) * am;
    c[0] = (m - d) * ua;
    c[1] = (m - d) * ub;
    c[2] = (m + d) * ua;
    c[3] = (m + d) * ub;
    *dlo = *dhi = c[0];
    for (i = 1; i < 4; i++) {
        *dlo = c[i] < *dlo ? c[i] : *dlo;
        *dhi = c[i] > *dhi ? c[i] : *dhi;
    }
}

/* Gap hints (issue 10). A near-horizontal contour (under about 14 degrees
 * from the rows) makes no candidate on a row it crosses (the row's own
 * gradient, the step times the slope per px, stays below thr), and none at
 * all where it lies wholly between two coarse rows: issue 10's bench lost
 * such pipes to the bands (seed 1, frames 229, 270, 279, at 13.5 and 1.6
 * degrees: a contour read 0 of its 107 edges, another 54 of 156). So the
 * two coarse rows ta < tb around each gap (and the last coarse row against
 * the last row a column block reads) are compared in every block of CHUNK
 * columns, at its columns c = 0, GAP_SAMPLE, 2 GAP_SAMPLE, ... (two pixels,
 * x and x + 1, each side): three consecutive samples with one sign whose
 * difference of sums reaches GAP_T thr (a mean step of 3/4 min_step) say
 * that an edge runs between the rows along at least 2 GAP_SAMPLE lines of
 * the block, and a gap hint (gy = 0; x = the block's
 * first column; gx = the rows it reaches from y, -(tb - ta) from the lower
 * row, + from the last row) makes band_cols read that gap in that block.
 * A near-vertical contour changes the difference over fewer columns (a
 * 45-degree one over D px) and is the rows' business; a ramp of shading or
 * texture that steep is read for nothing. Measured (make bench-detect
 * with BENCH_DETECT_COARSE=1, seeds 1-3): found 87.3 -> 88.7, 85.3 ->
 * 87.3, 89.3 -> 89.7 % (radius only); the paper frame's full search 5.88
 * -> 6.15 M instructions (callgrind, bench_frame full 1 1). Written below
 * htop[-1 - *nh] in row order like the rows' hints; returns 0 if room ran
 * out. */
#define GAP_SAMPLE 8
#define GAP_T 3
/* the sign of the gap difference at column x (-1, 0, 1) */
static inline int gap_sign(const unsigned char *ra, const unsigned char *rb, int x, int wide, int lim)
{
    int dv;
    if (wide) {
        const uint16_t *a16 = (const uint16_t *)(const void *)ra, *b16 = (const uint16_t *)(const void *)rb;
        dv = (int)b16[x] + (int)b16[x + 1] - (int)a16[x] - (int)a16[x + 1];
    } else {
        dv = (int)rb[x] + (int)rb[x + 1] - (int)ra[x] - (int)ra[x + 1];
    }
    return (dv >= lim) - (dv <= -lim);
}

/* Three consecutive samples of one sign among a block's four (CHUNK /
 * GAP_SAMPLE): both runs hold samples 1 and 2, so a block whose sample 1
 * shows nothing is done after one test (most blocks, on the paper frame). */
static int gap_hints(const cdsp_image *img, int thr, int step, int fc, int b0, int b1, int last, int ta,
                     int tb, int y, cdsp_edge *htop, size_t *nh, size_t room)
{
    const unsigned char *ra = (const unsigned char *)img->data + (size_t)ta * img->stride;
    const unsigned char *rb = (const unsigned char *)img->data + (size_t)tb * img->stride;
    int b, lim = GAP_T * thr, ds = GAP_SAMPLE * step, wide = img->bits > 8;
    for (b = b0; b < b1; b++) {
        int xa = fc + b * CHUNK * step, s1, hit;
        if (xa + 2 * ds + 1 > last) /* fewer than three samples x, x + 1 <= last */
            break;
        s1 = gap_sign(ra, rb, xa + ds, wide, lim);
        hit = s1 != 0 && gap_sign(ra, rb, xa + 2 * ds, wide, lim) == s1 &&
              (gap_sign(ra, rb, xa, wide, lim) == s1 ||
               (xa + 3 * ds + 1 <= last && gap_sign(ra, rb, xa + 3 * ds, wide, lim) == s1));
        if (hit) {
            cdsp_edge *q;
            if (*nh >= room)
                return 0;
            q = &htop[-1 - (ptrdiff_t)*nh];
            q->x = (cdsp_real)xa;
            q->y = (cdsp_real)y;
            q->gx = (cdsp_real)(y == tb ? ta - tb : tb - ta);
            q->gy = R(0);
            ++*nh;
        }
    }
    return 1;
}

/* Fine column blocks b in [b0, b1), read only where the coarse rows' hints
 * (hint[-1 - i], i < nh, in row order; see detect_range) put a
 * near-horizontal contour: for each coarse row t_k with hints, the hull
 * of the rows within D = F*step of t_k where the contours through its
 * hints (within their slope tolerance) cross the block's columns,
 * HINT_MARGIN rows wider. Coarse rows in order, merged, rows already read
 * never again: a block's rows ascending, the full search's order. */
static size_t band_cols(const cdsp_image *img, const cdsp_edge_params *p, int F, int b0, int b1, int x0,
                        int y0, int x1, int y1, const cdsp_edge *hint, size_t nh, cdsp_edge *out,
                        size_t cap, int *full)
{
    int h = p->half_window, step = p->step, t, b;
    int first = first_line(x0, step);
    int last = (x1 - 1 < img->width - 1 ? x1 - 1 : img->width - 1);
    int from = y0 > h + 1 ? y0 : h + 1, to = y1 < img->height - h - 1 ? y1 : img->height - h - 1;
    cdsp_real D = (cdsp_real)(F * step);
    size_t n = 0;
    for (b = b0, t = first + b0 * CHUNK * step; t < last && from < to && b < b1; b++, t += CHUNK * step) {
        int ncols = (last - 1 - t) / step + 1, cur_lo = 0, cur_hi = -1, done = from - 1;
        size_t ia = 0;
        cdsp_real xa = (cdsp_real)t, xb;
        if (ncols > CHUNK)
            ncols = CHUNK;
        xb = (cdsp_real)(t + (ncols - 1) * step);
        for (;;) {
            int have = 0, lo = 0, hi = -1;
            while (ia < nh && !have) { /* the next coarse row reaching the block */
                cdsp_real yk = hint[-1 - (ptrdiff_t)ia].y, hl = D, hh = -D;
                size_t u;
                for (u = ia; u < nh && hint[-1 - (ptrdiff_t)u].y == yk; u++) {
                    cdsp_real dl, dh;
                    hint_reach(&hint[-1 - (ptrdiff_t)u], xa, xb, &dl, &dh);
                    if (dh < -D || dl > D)
                        continue;
                    hl = dl < hl ? (dl < -D ? -D : dl) : hl;
                    hh = dh > hh ? (dh > D ? D : dh) : hh;
                    have = 1;
                }
                ia = u;
                if (have) {
                    lo = (int)R_FLOOR(yk + hl) - HINT_MARGIN;
                    hi = (int)R_CEIL(yk + hh) + HINT_MARGIN;
                    lo = lo <= done ? done + 1 : lo;
                    have = hi >= lo;
                }
            }
            if (have && cur_hi >= cur_lo && lo <= cur_hi + 1) {
                cur_lo = lo < cur_lo ? lo : cur_lo;
                cur_hi = hi > cur_hi ? hi : cur_hi;
                continue;
            }
            if (cur_hi >= cur_lo) {
                /* candidate rows [cur_lo, cur_hi]: scan_cols_block takes
                 * candidates in [f, e - 1) */
                int f = cur_lo < from ? from : cur_lo, e = cur_hi + 2 > to ? to : cur_hi + 2;
                if (f < e) {
                    n += scan_cols_block(img, p, step, t, ncols, f, e, out + n, cap - n);
                    if (n == cap) {
                        *full = 1;
                        return n;
                    }
                }
                done = cur_hi;
            }
            if (!have)
                break;
            cur_lo = lo;
            cur_hi = hi;
        }
    }
    return n;
}

/* The number of the full search's rows (jn) and column blocks (bn). */
static void family_extents(const cdsp_image *img, const cdsp_edge_params *p, int x0, int y0, int x1,
                           int y1, int *jn, int *bn)
{
    int h = p->half_window, step = p->step;
    int fr = first_line(y0, step), lim = y1 - 1 < img->height - 1 ? y1 - 1 : img->height - 1;
    int fc = first_line(x0, step), last = x1 - 1 < img->width - 1 ? x1 - 1 : img->width - 1;
    int from = y0 > h + 1 ? y0 : h + 1, to = y1 < img->height - h - 1 ? y1 : img->height - h - 1;
    *jn = lim > fr ? (lim - fr + step - 1) / step : 0;
    *bn = last > fc && from < to ? ((last - fc + step - 1) / step + CHUNK - 1) / CHUNK : 0;
}

/*
 * The full search (p->coarse < 2) or the coarse pass over the rows j in
 * [j0, j1) and the column blocks b in [b0, b1) of the full search: rows'
 * edges to out[0, *nr), the columns' after them (*nc). CDSP_E_CAPACITY
 * when they do not fit in cap (nothing is coarsened here).
 */
static cdsp_status detect_range(const cdsp_image *img, const cdsp_edge_params *p, int j0, int j1, int b0,
                                int b1, cdsp_edge *out, size_t cap, size_t *nr, size_t *nc)
{
    int x0, y0, x1, y1, F = p->coarse, step = p->step, full = 0, fr, fc;
    size_t nrc = 0, nh = 0;
    cdsp__edges_clip_roi(img, &p->roi, &x0, &y0, &x1, &y1);
    fr = first_line(y0, step);
    fc = first_line(x0, step);
    *nr = *nc = 0;
    if (F < 2) {
        /* rows fr + j*step, j < j1: scan_rows stops below y1' - 1 */
        *nr = j1 > j0 ? scan_rows(img, p, fr + j0 * step, step, x0, x1,
                                  y1 < fr + (j1 - 1) * step + 2 ? y1 : fr + (j1 - 1) * step + 2, out, cap)
                      : 0;
        if (*nr == cap)
            return CDSP_E_CAPACITY;
        /* column blocks: scan_cols_at stops before column x1' - 1 */
        if (b1 > b0) {
            int xe = fc + b1 * CHUNK * step + 1;
            *nc = scan_cols_at(img, p, fc + b0 * CHUNK * step, step, y0, x1 < xe ? x1 : xe, y1, out + *nr,
                               cap - *nr);
        }
        return *nr + *nc == cap ? CDSP_E_CAPACITY : CDSP_OK;
    }
    /* coarse rows (every F-th): their edges into out[0, nrc), the hints
     * for the column blocks downward from out + cap (nh); every coarse
     * row of the roi when there are column blocks (a block spans all the
     * rows), else those around [j0, j1) */
    {
        int h = p->half_window, D = F * step, ka = 0, t, tend = y1 - 1 < img->height - 1 ? y1 - 1 : img->height - 1;
        int from = x0 > h + 1 ? x0 : h + 1, to = x1 < img->width - h - 1 ? x1 : img->width - h - 1;
        if (b1 <= b0) {
            int kb = (j1 - 1) / F + 1;
            ka = j0 / F;
            tend = j1 > j0 && fr + kb * D + 1 < tend ? fr + kb * D + 1 : (j1 > j0 ? tend : fr);
        }
        int full_px = (1 << img->bits) - 1, thr = (int)(p->min_contrast * (cdsp_real)full_px + R(0.5)) / 2;
        int lastc = x1 - 1 < img->width - 1 ? x1 - 1 : img->width - 1;
        int bottom = (y1 < img->height - h - 1 ? y1 : img->height - h - 1) - 1;
        thr = thr > 0 ? thr : 1;
        for (t = fr + ka * D; t < tend; t += D) {
            /* the next coarse row while this one is read (it reads
             * [from - 2, to + 2)), and the rows above and below it, which
             * its candidates' refinement reads: each starts in other pages,
             * where the hardware's streams start over (the rows beside:
             * cold full search 0.51 -> 0.495 ms, bench_frame) */
            if (t + D < tend) {
                int r;
                for (r = -1; r <= 1; r++)
                    CDSP__PREFETCH_RANGE((const unsigned char *)img->data + (size_t)(t + D + r) * img->stride +
                                             (size_t)(from - 2) * (img->bits > 8 ? 2u : 1u),
                                         (size_t)(to - from + 4) * (img->bits > 8 ? 2u : 1u));
            }
            nrc += scan_segment(img, p, 1, t, from, to, out + nrc, cap / 2 - nrc - nh, out + cap, &nh);
            if (nrc + nh >= cap / 2)
                return CDSP_E_CAPACITY;
            /* the gap above this row, and below the last one */
            if (b1 > b0 && t > fr + ka * D &&
                !gap_hints(img, thr, step, fc, b0, b1, lastc, t - D, t, t, out + cap, &nh, cap / 2 - nrc))
                return CDSP_E_CAPACITY;
            if (b1 > b0 && t + D >= tend && bottom > t + 1 &&
                !gap_hints(img, thr, step, fc, b0, b1, lastc, t, bottom < t + D ? bottom : t + D, t, out + cap,
                           &nh, cap / 2 - nrc))
                return CDSP_E_CAPACITY;
        }
    }
    /* the coarse edges below the hints; the bands into out's start */
    move_up(out + cap - nh - nrc, out, nrc);
    {
        const cdsp_edge *rc = out + cap - nh - nrc;
        size_t room = cap - (nrc + nh);
        *nr = band_rows(img, p, F, j0, j1, x0, y0, x1, y1, rc, nrc, out, room, &full);
        *nc = full ? 0
                   : band_cols(img, p, F, b0, b1, x0, y0, x1, y1, out + cap, nh, out + *nr, room - *nr,
                               &full);
        if (full || *nr + *nc >= room)
            return CDSP_E_CAPACITY;
    }
    return CDSP_OK;
}

static cdsp_status detect_coarse(const cdsp_image *img, const cdsp_edge_params *p, cdsp_edge *out,
                                 size_t cap, size_t *n)
{
    int x0, y0, x1, y1, jn, bn;
    size_t nr, nc;
    cdsp__edges_clip_roi(img, &p->roi, &x0, &y0, &x1, &y1);
    family_extents(img, p, x0, y0, x1, y1, &jn, &bn);
    if (detect_range(img, p, 0, jn, 0, bn, out, cap, &nr, &nc) != CDSP_OK)
        return detect_full(img, p, out, cap, n);
    *n = nr + nc;
    return CDSP_OK;
}

/* Where strip k of n starts among m lines (or blocks): the first m % n
 * strips one longer. No product that could overflow (and no 64-bit
 * division, which 32-bit targets would call a helper for). */
static int strip_start(int m, int k, int n)
{
    return (m / n) * k + (k < m % n ? k : m % n);
}

/* The image and parameter checks of the detect entry points. */
static cdsp_status detect_args_check(const cdsp_image *img, const cdsp_edge_params *p)
{
    cdsp_status st = cdsp_image_check(img);
    return st != CDSP_OK ? st : cdsp__edge_params_check(p);
}

/*
 * Strips (docs/method.md §2): strip k of n is the full search's (or the
 * coarse pass's) rows j in [strip_start(jn, k, n), strip_start(jn, k+1, n))
 * and column blocks likewise; rows, then columns, in the full search's order
 * within each. Every strip's rows before every strip's columns, in strip
 * order, is therefore cdsp_edges_detect's list, bit for bit, whenever that
 * fits (cdsp_edges_merge_strips).
 */
cdsp_status cdsp_edges_detect_strip(const cdsp_image *img, const cdsp_edge_params *p, int k, int n,
                                    cdsp_edge *out, size_t cap, size_t *n_rows, size_t *n_cols)
{
    int x0, y0, x1, y1, jn, bn;
    cdsp_status st;
    if (!p || !out || !n_rows || !n_cols)
        return CDSP_E_ARG;
    *n_rows = *n_cols = 0;
    if (n < 1 || n > CDSP_EDGE_MAX_STRIPS || k < 0 || k >= n)
        return CDSP_E_ARG;
    st = detect_args_check(img, p);
    if (st != CDSP_OK)
        return st;
    cdsp__edges_clip_roi(img, &p->roi, &x0, &y0, &x1, &y1);
    family_extents(img, p, x0, y0, x1, y1, &jn, &bn);
    return detect_range(img, p, strip_start(jn, k, n), strip_start(jn, k + 1, n), strip_start(bn, k, n),
                        strip_start(bn, k + 1, n), out, cap, n_rows, n_cols);
}

/* The merge fits when cdsp_edges_detect's own list surely fits: fewer
 * than cap edges, or with the coarse pass fewer than cap / 2 (there the
 * coarse lines' edges, each also in the result, share the buffer: with
 * fewer than cap / 2 results both fit; above, the caller's fallback to
 * cdsp_edges_detect gives the same list anyway). */
cdsp_status cdsp_edges_merge_strips(const cdsp_edge_params *p, const cdsp_edge *const *strip,
                                    const size_t *n_rows, const size_t *n_cols, int n, cdsp_edge *out,
                                    size_t cap, size_t *count)
{
    int k, f;
    size_t m = 0, i;
    if (!p || !strip || !n_rows || !n_cols || !out || !count || n < 1 || n > CDSP_EDGE_MAX_STRIPS)
        return CDSP_E_ARG;
    *count = 0;
    if (p->coarse >= 2)
        cap /= 2;
    for (f = 0; f < 2; f++)
        for (k = 0; k < n; k++) {
            size_t c = f == 0 ? n_rows[k] : n_cols[k];
            const cdsp_edge *src = strip[k] + (f == 0 ? 0 : n_rows[k]);
            if (!strip[k] && c)
                return CDSP_E_ARG;
            if (c >= cap - m) /* the whole frame's list would not fit either */
                return CDSP_E_CAPACITY;
            for (i = 0; i < c; i++)
                out[m++] = src[i];
        }
    *count = m;
    return CDSP_OK;
}

cdsp_status cdsp_edges_detect(const cdsp_image *img, const cdsp_edge_params *p, cdsp_edge *out,
                              size_t cap, size_t *n)
{
    cdsp_status st;
    if (!p || !out || !n)
        return CDSP_E_ARG;
    *n = 0;
    st = detect_args_check(img, p);
    if (st != CDSP_OK)
        return st;
    return p->coarse >= 2 ? detect_coarse(img, p, out, cap, n) : detect_full(img, p, out, cap, n);
}
