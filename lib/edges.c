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

/* Pixel at (s along the scan, t across it). */
static inline int at(const cdsp_image *img, int horizontal, int s, int t)
{
    return horizontal ? img_px(img, s, t) : img_px(img, t, s);
}

/* Intensity at s + pos along the scan (row t across it), interpolated
 * linearly between pixel centres, with pos clamped to [-lim, lim]: the
 * caller guarantees lim = h + 1 pixels on both sides of s (the scan keeps
 * that margin from the frame's border). The second pass samples at
 * |pos| <= |a| + |b| + (h + 1/2)/2 <= 3.3 for h = 2, one pixel past that
 * margin; for h >= 3 the bound (3.8 at h = 3, 4.3 at h = 4, ...) stays
 * inside it, so the clamp changes nothing there. The far neighbour is read
 * only when its weight is non-zero, so pos = +lim never reads s + lim + 1. */
static cdsp_real sample_at(const cdsp_image *img, int horizontal, int s, int t, cdsp_real pos, int lim)
{
    int i;
    cdsp_real f;
    if (pos < -(cdsp_real)lim)
        pos = -(cdsp_real)lim;
    if (pos > (cdsp_real)lim)
        pos = (cdsp_real)lim;
    i = (int)R_FLOOR(pos);
    f = pos - (cdsp_real)i;
    if (f <= R(0))
        return (cdsp_real)at(img, horizontal, s + i, t);
    return (R(1) - f) * (cdsp_real)at(img, horizontal, s + i, t) +
           f * (cdsp_real)at(img, horizontal, s + i + 1, t);
}

/* Refine candidate (s, t): returns 1 and fills e when the partial-area
 * estimate is a valid edge owned by this scan direction. */
static int refine(const cdsp_image *img, int horizontal, int s, int t, int h, int min_step,
                  cdsp_edge *e)
{
    int k, c, S[3], A = 0, B = 0, gs = 0, gt = 0;
    cdsp_real diff, a, b, norm, gsn, gtn;
    /* Which family owns the edge: compare the 3x3 Sobel-like components. */
    for (k = -1; k <= 1; k++) {
        int w = k == 0 ? 2 : 1;
        gs += w * (at(img, horizontal, s + 1, t + k) - at(img, horizontal, s - 1, t + k));
        gt += w * (at(img, horizontal, s + k, t + 1) - at(img, horizontal, s + k, t - 1));
    }
    /* ties (45 degrees) go to the row family only, so no edge is reported twice */
    if (horizontal ? (iabs(gs) < iabs(gt)) : (iabs(gs) <= iabs(gt)))
        return 0;
    for (k = -1; k <= 1; k++) {
        int sum = 0;
        for (c = -h; c <= h; c++)
            sum += at(img, horizontal, s + c, t + k);
        S[k + 1] = sum;
        A += at(img, horizontal, s - h, t + k);
        B += at(img, horizontal, s + h, t + k);
    }
    /* A, B: means of the three end pixels (kept as sums of 3 until here) */
    if (iabs(A - B) < 3 * min_step)
        return 0;
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
        cdsp_real sa = R(0), sb = R(0), HH = R(h) + R(0.5), D = HH / R(2);
        for (k = -1; k <= 1; k++) {
            cdsp_real ek = a + (cdsp_real)k * b;
            sa += sample_at(img, horizontal, s, t + k, ek - D, h + 1);
            sb += sample_at(img, horizontal, s, t + k, ek + D, h + 1);
        }
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

/* Candidates along a run are searched CHUNK pixels at a time: the central
 * differences of a chunk go into a small array (a loop compilers vectorize)
 * and a chunk whose largest |difference| is below the threshold, nearly all
 * of them in a frame, is skipped without further work. */
#define CHUNK 32

/* Central differences g[i] = f(s0+i+1) - f(s0+i-1), i in [0, m), along a
 * run through `base` with element stride es (1 for a row, stride/bpp for a
 * column); returns max |g|. Rows get a copy with unit stride and a fixed
 * trip count, which compilers turn into SIMD code at -O2. */
#define DEFINE_DIFFS(NAME, T)                                                                  \
    static int NAME(const T *base, ptrdiff_t es, int s0, int m, int *g)                        \
    {                                                                                          \
        int i, mx = 0;                                                                         \
        for (i = 0; i < m; i++) {                                                              \
            int d = (int)base[(ptrdiff_t)(s0 + i + 1) * es] - (int)base[(ptrdiff_t)(s0 + i - 1) * es]; \
            int ad = d < 0 ? -d : d;                                                           \
            g[i] = d;                                                                          \
            mx = ad > mx ? ad : mx;                                                            \
        }                                                                                      \
        return mx;                                                                             \
    }                                                                                          \
    static int NAME##_row(const T *row, int s0, int *g)                                        \
    {                                                                                          \
        int i, mx = 0;                                                                         \
        const T *a = row + s0 + 1, *b = row + s0 - 1;                                          \
        for (i = 0; i < CHUNK + 2; i++) {                                                      \
            int d = (int)a[i] - (int)b[i];                                                     \
            int ad = d < 0 ? -d : d;                                                           \
            g[i] = d;                                                                          \
            mx = ad > mx ? ad : mx;                                                            \
        }                                                                                      \
        return mx;                                                                             \
    }
DEFINE_DIFFS(diffs_u8, uint8_t)
DEFINE_DIFFS(diffs_u16, uint16_t)

/*
 * Scan one line: horizontal != 0 scans row `line` over x in [from, to);
 * otherwise column `line` over y in [from, to). The caller guarantees the
 * window fits: from - h - 1 >= 0, to + h + 1 <= extent, 1 <= line <= other
 * extent - 2. Returns points written (<= cap).
 */
size_t cdsp__edges_scan_segment(const cdsp_image *img, const cdsp_edge_params *p, int horizontal,
                                int line, int from, int to, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, s0;
    int full = (1 << img->bits) - 1;
    int min_step = (int)(p->min_contrast * (cdsp_real)full + R(0.5));
    int thr = min_step / 2 > 0 ? min_step / 2 : 1;
    int g[CHUNK + 2];
    size_t n = 0, bpp = img->bits <= 8 ? 1u : 2u;
    const unsigned char *base = (const unsigned char *)img->data;
    ptrdiff_t es;
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
    for (s0 = from + 1; s0 < to - 1; s0 += CHUNK) {
        int m = (to - 1 - s0) < CHUNK ? (to - 1 - s0) : CHUNK, mx, i;
        /* g[0] is at s0 - 1, g[i + 1] at s0 + i */
        if (es == 1 && m == CHUNK)
            mx = bpp == 1 ? diffs_u8_row((const uint8_t *)(const void *)base, s0 - 1, g)
                          : diffs_u16_row((const uint16_t *)(const void *)base, s0 - 1, g);
        else
            mx = bpp == 1 ? diffs_u8((const uint8_t *)(const void *)base, es, s0 - 1, m + 2, g)
                          : diffs_u16((const uint16_t *)(const void *)base, es, s0 - 1, m + 2, g);
        if (mx < thr)
            continue;
        for (i = 1; i <= m; i++) {
            int a = iabs(g[i]);
            /* local maximum of |central difference| (ties broken to the left) */
            if (a >= thr && a > iabs(g[i - 1]) && a >= iabs(g[i + 1]) &&
                refine(img, horizontal, s0 + i - 1, line, h, min_step, &out[n])) {
                if (++n == cap)
                    return n;
            }
        }
    }
    return n;
}

/*
 * Near-horizontal edges over the columns x = xs + k*step, k < ncols <=
 * CHUNK, rows [from, to): the same search as cdsp__edges_scan_segment on
 * each column, but walking the frame row by row so memory is read in order
 * (a column-at-a-time walk touches a new cache line at every pixel).
 */
static size_t scan_cols_block(const cdsp_image *img, const cdsp_edge_params *p, int step, int xs,
                              int ncols, int from, int to, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, y, k;
    int full = (1 << img->bits) - 1;
    int min_step = (int)(p->min_contrast * (cdsp_real)full + R(0.5));
    int thr = min_step / 2 > 0 ? min_step / 2 : 1;
    int g0[CHUNK], g1[CHUNK], *gprev = g0, *gcur = g1, prev_hot = 0;
    size_t n = 0, bpp = img->bits <= 8 ? 1u : 2u;
    /* g at row y - 1 (gprev) and y (gcur); a candidate at row y needs g(y+1) */
    for (y = from - 1; y < to; y++) {
        const unsigned char *up = (const unsigned char *)img->data + (size_t)(y - 1) * img->stride;
        const unsigned char *dn = up + 2 * img->stride;
        int hot = 0, *gnext = gprev; /* gprev's storage is free once gnext is computed */
        int tmp[CHUNK];
        for (k = 0; k < ncols; k++) {
            size_t x = (size_t)(xs + k * step);
            int d = bpp == 1 ? (int)dn[x] - (int)up[x]
                             : (int)((const uint16_t *)(const void *)dn)[x] -
                                   (int)((const uint16_t *)(const void *)up)[x];
            tmp[k] = d;
            hot |= iabs(d) >= thr;
        }
        /* candidates at row y - 1 use gprev (y - 2), gcur (y - 1), tmp (y) */
        if (prev_hot && y - 1 > from - 1) {
            for (k = 0; k < ncols; k++) {
                int a = iabs(gcur[k]);
                if (a >= thr && a > iabs(gprev[k]) && a >= iabs(tmp[k]) &&
                    refine(img, 0, y - 1, xs + k * step, h, min_step, &out[n])) {
                    if (++n == cap)
                        return n;
                }
            }
        }
        for (k = 0; k < ncols; k++)
            gnext[k] = tmp[k];
        gprev = gcur;
        gcur = gnext;
        prev_hot = hot;
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
        !(p->min_contrast > R(0)) || !(p->min_contrast < R(1)))
        return CDSP_E_ARG;
    return CDSP_OK;
}

/* Near-vertical edges: rows y0 + 1 + step/2 + k*step of the clipped roi. */
static size_t scan_rows(const cdsp_image *img, const cdsp_edge_params *p, int step, int x0, int y0,
                        int x1, int y1, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, t;
    int from = x0 > h + 1 ? x0 : h + 1, to = x1 < img->width - h - 1 ? x1 : img->width - h - 1;
    size_t count = 0;
    for (t = (y0 > 1 ? y0 : 1) + step / 2; t < y1 - 1 && t < img->height - 1; t += step) {
        count += cdsp__edges_scan_segment(img, p, 1, t, from, to, out + count, cap - count);
        if (count == cap)
            break;
    }
    return count;
}

/* Near-horizontal edges: the same over columns, CHUNK columns at a time. */
static size_t scan_cols(const cdsp_image *img, const cdsp_edge_params *p, int step, int x0, int y0,
                        int x1, int y1, cdsp_edge *out, size_t cap)
{
    int h = p->half_window, t;
    int first = (x0 > 1 ? x0 : 1) + step / 2;
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
cdsp_status cdsp_edges_detect(const cdsp_image *img, const cdsp_edge_params *p, cdsp_edge *out,
                              size_t cap, size_t *n)
{
    int x0, y0, x1, y1, srow, scol, extent, rows_at = 0;
    size_t nr = 0, nc;
    cdsp_status st, result = CDSP_OK;
    if (!p || !out || !n)
        return CDSP_E_ARG;
    *n = 0;
    st = cdsp_image_check(img);
    if (st != CDSP_OK)
        return st;
    st = cdsp__edge_params_check(p);
    if (st != CDSP_OK)
        return st;
    cdsp__edges_clip_roi(img, &p->roi, &x0, &y0, &x1, &y1);
    extent = img->width > img->height ? img->width : img->height;
    srow = scol = p->step;
    for (;;) {
        /* a step may double while it stays within the frame (no overflow) */
        int can_r = srow <= extent / 2, can_c = scol <= extent / 2;
        if (rows_at != srow) /* rows already in out[0, nr) at this step are kept */
            nr = scan_rows(img, p, srow, x0, y0, x1, y1, out, cap);
        rows_at = srow;
        if (nr == cap && can_r) {
            srow *= 2;
            result = CDSP_E_CAPACITY;
            continue;
        }
        nc = scan_cols(img, p, scol, x0, y0, x1, y1, out + nr, cap - nr);
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
