/*
 * test_edges.c - partial-area subpixel edges on rendered frames of known
 * geometry: positions on the exact contour (distortion, blur, 8/16 bit),
 * noise as the method predicts, polarity, counts per scanline, ROI,
 * capacity, and hostile images.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <limits.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

static cdsp_edge edges[20000];

typedef struct {
    double mean[2], rms[2], maxabs[2];
    int count[2], polarity_ok;
    size_t n;
} edge_stats;

/* Detect, undistort, and measure each point's distance to the nearer exact
 * contour (points farther than 2 px from both are clutter/texture). */
static void measure(const cdsp_image *img, const cdsp_camera *cam, const cdsp_edge_params *ep,
                    double l[2][3], edge_stats *st)
{
    size_t n, i;
    int k;
    memset(st, 0, sizeof *st);
    assert_int_equal(cdsp_edges_detect(img, ep, edges, 20000, &n), CDSP_OK);
    assert_int_equal(cdsp_camera_undistort_edges(cam, edges, &n), CDSP_OK);
    st->n = n;
    st->polarity_ok = 1;
    for (i = 0; i < n; i++)
        for (k = 0; k < 2; k++) {
            double d = l[k][0] * (double)edges[i].x + l[k][1] * (double)edges[i].y + l[k][2];
            if (fabs(d) < 2) {
                st->mean[k] += d;
                st->rms[k] += d * d;
                if (fabs(d) > st->maxabs[k])
                    st->maxabs[k] = fabs(d);
                st->count[k]++;
                /* pipe brighter: gradients point into the pipe, along l's normal */
                if (l[k][0] * (double)edges[i].gx + l[k][1] * (double)edges[i].gy <= 0)
                    st->polarity_ok = 0;
            }
        }
    for (k = 0; k < 2; k++)
        if (st->count[k]) {
            st->mean[k] /= st->count[k];
            st->rms[k] = sqrt(st->rms[k] / st->count[k]);
        }
}

static void *flat_frame(cdsp_camera *cam, double k1, double blur, double noise, int bits,
                        const double P[3], const double v[3], cdsp_image *img, double l[2][3])
{
    cdsp_scene s;
    double pin[2];
    void *buf;
    sup_camera(cam, 640, 480, 800, k1, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    s.texture = 0;
    s.blur_sigma_px = (cdsp_real)blur;
    s.noise_sigma = (cdsp_real)noise;
    buf = sup_render(&s, cam, bits, 42, img);
    assert_non_null(buf);
    assert_true(sup_contour_lines(cam, P, v, 8, l, pin));
    return buf;
}

/* Noise-free frames: the detector's error is the frame's rounding and the
 * blur that leaks across the edge to where the sides are sampled. 16 bit:
 * the window sum's rounding, sqrt(27/12) / (0.45 x 65535) = 5e-5 px rms,
 * so <= 2e-4 px at the few-sigma tail of ~100 points and 1e-4 for their mean. The second pass samples each side D = 2.25 px from the
 * edge, interpolating between the two nearest pixels; a pixel whose centre
 * is c px from a sigma-blurred edge carries ~Phi(-c/sigma) of the other
 * side, and the two sides' nearest pixels differ in c by up to 1 px with
 * the subpixel phase: at sigma 0.7 the leak differs by up to ~0.1 % of the
 * contrast, times (h + 1/2) = 4.5 px: <= 0.01 px; at sigma 1.0 ~0.6 %:
 * <= 0.035 px; near 45 degrees the outer rows move the edge by ~1 px
 * toward one sample: <= 0.02 px. The errors change sign with the phase,
 * which sweeps ~30 cycles along a contour here, so a contour's mean stays
 * within 1/30-1/10 of the largest (2e-4 at sigma 0.7, 5e-4 near 45 degrees,
 * 3.5e-3 at sigma 1.0, whose leak is not symmetric in the phase). 8 bit
 * adds the window sum's rounding, sqrt(27/12)/contrast(0.45*255) ~ 0.013 px
 * rms: a deterministic rounding of one frame, 0.03 px at most and 5e-3
 * for the mean. Each row's measured (max, |mean|) is beside it. */
static void test_exact_positions(void **state)
{
    static const struct {
        double k1, blur;
        int bits;
        double dir[3];
        double tol_max, tol_mean;
    } rows[] = {
        /* measured (max, |mean|), double and float alike: (6.2e-5, 3.3e-5) */
        {0, 0, 16, {0.2, 1, 0.2}, 2e-4, 1e-4},
        /* (4.6e-3, 4.4e-5) */
        {-0.2, 0.7, 16, {0.2, 1, 0.2}, 0.01, 2e-4},
        /* (0.027, 1.1e-3) */
        {-0.2, 1.0, 16, {1, 0.3, 0.1}, 0.035, 3.5e-3},  /* near-horizontal: column scans */
        /* (0.014, 1.5e-4) */
        {0.1, 0.7, 16, {1, 0.9, 0.3}, 0.02, 5e-4},      /* near 45 degrees: both families */
        /* (0.011, 2.0e-3) */
        {-0.2, 0.7, 8, {0.2, 1, 0.2}, 0.03, 5e-3},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        cdsp_camera cam;
        cdsp_image img;
        cdsp_edge_params ep;
        edge_stats st;
        double l[2][3], P[3] = {5, -3, 400};
        void *buf = flat_frame(&cam, rows[r].k1, rows[r].blur, 0, rows[r].bits, P, rows[r].dir,
                               &img, l);
        int k;
        cdsp_edge_params_default(&ep);
        measure(&img, &cam, &ep, l, &st);
        for (k = 0; k < 2; k++) {
            if (st.count[k] < 60)
                fail_msg("row %zu line %d: only %d points", r, k, st.count[k]);
            if (getenv("CDSP_TEST_VERBOSE"))
                print_message("row %zu line %d: mean %.2g max %.2g px\n", r, k, st.mean[k], st.maxabs[k]);
            if (st.maxabs[k] > rows[r].tol_max || fabs(st.mean[k]) > rows[r].tol_mean)
                fail_msg("row %zu line %d: mean %.2g max %.2g px", r, k, st.mean[k], st.maxabs[k]);
        }
        assert_true(st.polarity_ok);
        free(buf);
    }
}

/* Noise sigma (gray levels) -> position sd. The first pass,
 * a = (mean_k S_k - (h+1/2)(A+B)) / (A-B) with 3(2h+1) pixels in the sums
 * and 3 in each of A, B, has var(a) = [(2h+1)/3 + 2 (h+1/2)^2 / 3]
 * sigma^2 / (A-B)^2 (sd 4.06 sigma / (A-B) for h = 4); but the reported
 * point is the second pass's, whose sides are 3 samples each interpolated
 * between two pixels (weights w, 1 - w: variance (w^2 + (1-w)^2) sigma^2,
 * 2/3 sigma^2 averaged over the phase) that also lie inside the row sums:
 * var = [(2h+1)/3 + (h+1/2)^2 (4/9) - 2 (h+1/2)(2/3)] sigma^2 / (A-B)^2
 * = 6 sigma^2 / (A-B)^2 for h = 4, sd 2.45 sigma / (A-B) (1.94-3.24 over
 * the phases). The rms of n = 119 points has a relative sd of 1/sqrt(2n)
 * = 6.5 %: band 0.74-1.26 of the prediction (4 sd). Measured 0.875-1.05
 * (double), 0.875-0.92 (float); the mean, within 4 standard errors
 * (0.020 px), measured <= 0.0064 px. (It checked 0.3-1.3 of the first
 * pass's 4.06.) The frame's noise is white (added after the blur). */
static void test_noise(void **state)
{
    cdsp_camera cam;
    cdsp_image img;
    cdsp_edge_params ep;
    edge_stats st;
    double l[2][3], P[3] = {5, -3, 400}, v[3] = {0.2, 1, 0.2};
    double sigma = 0.01, contrast = 0.7 - 0.25, pred = 2.45 * sigma / contrast;
    void *buf = flat_frame(&cam, -0.2, 0.7, sigma, 16, P, v, &img, l);
    int k;
    (void)state;
    cdsp_edge_params_default(&ep);
    measure(&img, &cam, &ep, l, &st);
    for (k = 0; k < 2; k++) {
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("noise line %d: rms %.5f px (predicted %.5f), mean %.2g over %d\n", k, st.rms[k], pred,
                          st.mean[k], st.count[k]);
        if (st.rms[k] > 1.26 * pred || st.rms[k] < 0.74 * pred)
            fail_msg("line %d: rms %.4f px, predicted %.4f", k, st.rms[k], pred);
        /* unbiased: mean within 4 standard errors */
        assert_true(fabs(st.mean[k]) < 4 * pred / sqrt(st.count[k]));
    }
    free(buf);
}

/* A shaded pipe (Lambertian, 85 % ambient, light L from above left, blur
 * 0.7 px, no noise): the second pass (each side's mean over its span)
 * keeps each contour's mean offset small; the end-pixel estimate alone was
 * off by ~0.06 px on both contours (README, "Accuracy"). The residual:
 * near the limb the surface normal turns by theta = sqrt(2 delta / R) at
 * delta px inside the contour (R = f r / Z = 16.6 px here), so the pipe's
 * side is I(delta) = pipe (a + (1 - a) max(0, n0.L cos theta + t.L sin
 * theta)) (n0 the normal at the limb, t the one facing the camera). The
 * window integrates I over the side's L = h + 1/2 = 4.5 px, the second
 * pass takes I at D = L/2: offset (int_0^L I - L I(D)) / contrast.
 * - Lit contour (line 1: n0.L = 0.49, t.L = 0.62): I ~ k sqrt(delta),
 *   k = pipe (1 - a) t.L sqrt(2/R) = 0.0225 per sqrt(px), contrast 0.40:
 *   (2/3 - sqrt(1/2)) k L^1.5 / contrast = 0.022 px (numerically 0.024),
 *   inward (a concave side sampled half way is over-estimated). Measured
 *   +0.0226 px (double and float); bound 0.03 (1.3x).
 * - Shadowed contour (line 0: n0.L = -0.46): I is flat up to theta =
 *   atan(0.46/0.64), delta = 3.3 px, so only the window's outer 1.2 px see
 *   light: at most 0.021 px (the same integral), outward. Measured -0.0085
 *   px; bound 0.02 (2.4x).
 * (It was 0.03 for both.) */
static void test_shaded_pipe(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    cdsp_edge_params ep;
    edge_stats st;
    double l[2][3], pin[2], P[3] = {10, -5, 400}, v[3] = {0.3, 1, 0.2};
    void *buf;
    int k;
    (void)state;
    sup_camera(&cam, 640, 480, 800, -0.2, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = (cdsp_real)0.85;
    s.texture = 0;
    s.noise_sigma = 0;
    buf = sup_render(&s, &cam, 16, 42, &img);
    assert_non_null(buf);
    assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
    cdsp_edge_params_default(&ep);
    measure(&img, &cam, &ep, l, &st);
    for (k = 0; k < 2; k++) {
        const double bound = k ? 0.03 : 0.02; /* lit, shadowed: see above */
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("shaded line %d: mean %.4f px\n", k, st.mean[k]);
        if (fabs(st.mean[k]) > bound || st.count[k] < 60)
            fail_msg("shaded contour %d: mean offset %.4f px over %d points (bound %.2g)", k, st.mean[k],
                     st.count[k], bound);
    }
    free(buf);
}

/* One point per scanned row per near-vertical contour. */
static void test_counts_and_step(void **state)
{
    cdsp_camera cam;
    cdsp_image img;
    cdsp_edge_params ep;
    edge_stats st;
    double l[2][3], P[3] = {0, 0, 400}, v[3] = {0, 1, 0};
    void *buf = flat_frame(&cam, 0, 0.7, 0, 8, P, v, &img, l);
    int step;
    (void)state;
    for (step = 1; step <= 8; step *= 2) {
        int rows_scanned = 0, t;
        cdsp_edge_params_default(&ep);
        ep.step = step;
        for (t = 1 + step / 2; t < 479; t += step)
            rows_scanned++;
        measure(&img, &cam, &ep, l, &st);
        assert_int_equal(st.count[0], rows_scanned);
        assert_int_equal(st.count[1], rows_scanned);
        assert_int_equal(st.n, 2 * rows_scanned);
    }
    free(buf);
}

/* Whether each of pts[0, n) is, to the bit, the point of the same scan row
 * and side in ref[0, nref) (a whole-frame scan at step 1): a row's point
 * depends only on the pixels of its window, never on the roi or step that
 * chose the row. */
static int same_as_rows(const cdsp_edge *ref, size_t nref, const cdsp_edge *pts, size_t n)
{
    size_t i, j;
    for (i = 0; i < n; i++) {
        for (j = 0; j < nref; j++)
            if (ref[j].y == pts[i].y && fabs((double)(ref[j].x - pts[i].x)) < 1)
                break;
        if (j == nref || ref[j].x != pts[i].x || ref[j].gx != pts[i].gx || ref[j].gy != pts[i].gy)
            return 0;
    }
    return 1;
}

/* The roi and a full buffer choose which rows are read, not what a row
 * yields: the checks are exact (counts of the scan grid, points equal to
 * the whole frame's at step 1), no tolerance. (They were n >= 24 of the
 * roi's 25 rows, and points inside the roi's rectangle.) */
static void test_roi_capacity(void **state)
{
    static cdsp_edge ref[2048];
    cdsp_camera cam;
    cdsp_image img;
    cdsp_edge_params ep;
    double l[2][3], P[3] = {0, 0, 400}, v[3] = {0, 1, 0};
    void *buf = flat_frame(&cam, 0, 0.7, 0, 8, P, v, &img, l);
    size_t n, nref, i;
    (void)state;
    cdsp_edge_params_default(&ep);
    ep.step = 1;
    assert_int_equal(cdsp_edges_detect(&img, &ep, ref, 2048, &nref), CDSP_OK);
    assert_int_equal(nref, 2 * 478); /* rows 1 .. 478 (first_line(0, 1) = 1, t < 479), two contours */
    cdsp_edge_params_default(&ep);
    ep.roi.x = 0;
    ep.roi.y = 100;
    ep.roi.w = 320; /* the left half: only the left contour */
    ep.roi.h = 100;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 20000, &n), CDSP_OK);
    /* rows first_line(100, 4) = 102, 106, ..., 198: 25, one point each */
    assert_int_equal(n, 25);
    for (i = 0; i < n; i++) {
        assert_true(edges[i].y == (cdsp_real)(102 + 4 * i));
        assert_true(edges[i].x < 320);
    }
    assert_true(same_as_rows(ref, nref, edges, n));
    ep.roi.w = ep.roi.h = 0;
    /* 240 row points do not fit in 10: the rows are read at a coarser step,
     * 128 px (64 gives 7 rows, 14 points): rows 1 + 64 + 128 k, 4 rows of
     * both contours, 8 points */
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 10, &n), CDSP_E_CAPACITY);
    assert_int_equal(n, 8);
    for (i = 0; i < n; i++) {
        assert_true(edges[i].y == (cdsp_real)(65 + 128 * (i / 2)));
        assert_true((edges[i].x < 320) == (i % 2 == 0));
    }
    assert_true(same_as_rows(ref, nref, edges, n));
    /* a roi entirely outside the frame finds nothing, without reading outside */
    ep.roi.x = 1000;
    ep.roi.y = 1000;
    ep.roi.w = 50;
    ep.roi.h = 50;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 20000, &n), CDSP_OK);
    assert_int_equal(n, 0);
    free(buf);
}

/* Piecewise-constant frames of random half-planes (anti-aliased), with
 * noise, or (kind 1) uniform noise: many candidates that pass the
 * estimator's checks, with every offset and slope, up to the frame's
 * border. Exactly w x h pixels on the heap, so AddressSanitizer
 * sees any read outside the frame. */
static double urand(cdsp_rng *rng)
{
    return (double)cdsp_rng_uniform(rng);
}

static void *random_planes(cdsp_rng *rng, int w, int h, int bits, int kind, cdsp_image *img)
{
    double nx[3], ny[3], c[3], amp[3];
    int full = (1 << bits) - 1, x, y, k;
    size_t bpp = bits <= 8 ? 1 : 2;
    void *buf = malloc((size_t)w * (size_t)h * bpp);
    assert_non_null(buf);
    for (k = 0; k < 3; k++) {
        double a = 2 * SUP_PI * urand(rng);
        nx[k] = cos(a);
        ny[k] = sin(a);
        c[k] = -(nx[k] * w * urand(rng) + ny[k] * h * urand(rng));
        amp[k] = (0.15 + 0.2 * urand(rng)) * full;
    }
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            /* noise of 1 % of full scale, or (kind 1) uniform over the whole
             * range: candidates with every offset and slope */
            double v = kind ? urand(rng) * full : 0.1 * full + 2 * (urand(rng) - 0.5) * 0.01 * full;
            for (k = 0; k < 3 && !kind; k++) {
                double d = nx[k] * x + ny[k] * y + c[k] + 0.5;
                v += amp[k] * (d < 0 ? 0 : d > 1 ? 1 : d);
            }
            if (v < 0)
                v = 0;
            if (v > full)
                v = full;
            if (bpp == 1)
                ((uint8_t *)buf)[(size_t)y * w + x] = (uint8_t)(v + 0.5);
            else
                ((uint16_t *)buf)[(size_t)y * w + x] = (uint16_t)(v + 0.5);
        }
    img->data = buf;
    img->width = w;
    img->height = h;
    img->stride = (size_t)w * bpp;
    img->bits = bits;
    return buf;
}

/* Where a point of a w x hgt frame may lie (lib/edges.c): a row-scan point
 * is (s + a, t) with t a scan row, first_line = 1 + step/2 plus a multiple
 * of step, 1 <= t <= hgt - 2 (the 3-row window), s a pixel at least
 * half + 1 from the border (the window and the second pass's samples,
 * +-(half + 1), stay in the frame) and |a| <= 1 (the edge crosses the
 * candidate pixel's neighbourhood); a column-scan point is the same with
 * x and y exchanged. So each point has one coordinate exactly on its
 * family's grid and the other in [half, extent - half - 1]: no tolerance,
 * the bounds are the scan's. (The frame's extent, [-0.5, extent - 0.5],
 * allowed half + 0.5 px more at each end, where a scan whose margin is off
 * by one would put its points.) */
static int on_scan_grid(const cdsp_edge *e, int w, int hgt, int half, int step)
{
    double x = (double)e->x, y = (double)e->y;
    int k;
    for (k = 0; k < 2; k++) {
        double t = k ? x : y, sv = k ? y : x;
        int along = k ? hgt : w, across = k ? w : hgt;
        if (t == floor(t) && t >= 1 && t <= across - 2 && ((long)t - 1 - step / 2) % step == 0 &&
            sv >= half && sv <= along - half - 1)
            return 1;
    }
    return 0;
}

/* Every accepted half_window (2..8) and a range of steps, on random frames
 * from 48 x 48 down to smaller than the window, 8, 12 and 16 bit: nothing is
 * read outside the frame (the ASan build of this suite checks the reads;
 * issue 9: half_window 2's second pass sampled +-4 px) and every point is
 * finite and where its scan may put it (on_scan_grid). */
static void test_every_window_safe(void **state)
{
    static const int steps[] = {1, 2, 3, 4, 7, 1000};
    static const int sizes[][2] = {{48, 48}, {47, 13}, {13, 47}, {9, 9}, {5, 40}, {40, 5}, {3, 3}};
    static const int bitss[] = {8, 12, 16};
    cdsp_rng rng;
    cdsp_edge_params ep;
    int h, si, zi, bi, rep, found = 0;
    (void)state;
    cdsp_rng_seed(&rng, 2024, 9);
    for (h = 2; h <= 8; h++)
        for (si = 0; si < (int)(sizeof steps / sizeof steps[0]); si++)
            for (zi = 0; zi < (int)(sizeof sizes / sizeof sizes[0]); zi++)
                for (bi = 0; bi < 3; bi++)
                    for (rep = 0; rep < 4; rep++) {
                        cdsp_image img;
                        size_t n, i;
                        void *buf = random_planes(&rng, sizes[zi][0], sizes[zi][1], bitss[bi],
                                                  rep % 2, &img);
                        cdsp_status st;
                        cdsp_edge_params_default(&ep);
                        ep.half_window = h;
                        ep.step = steps[si];
                        st = cdsp_edges_detect(&img, &ep, edges, 20000, &n);
                        assert_int_equal(st, CDSP_OK);
                        for (i = 0; i < n; i++) {
                            assert_true(isfinite((double)edges[i].x) && isfinite((double)edges[i].y));
                            if (!on_scan_grid(&edges[i], img.width, img.height, h, ep.step))
                                fail_msg("%d x %d, half_window %d, step %d: point (%g, %g) off its scan",
                                         img.width, img.height, h, ep.step, (double)edges[i].x,
                                         (double)edges[i].y);
                        }
                        found += (int)n;
                        free(buf);
                    }
    /* uniform noise at step 1 reaches the windows' extreme offsets and
     * slopes; with the old second pass, 48 x 48 frames read a row above the
     * frame about once in 200 frames at half_window 2 */
    for (h = 2; h <= 8; h++)
        for (rep = 0; rep < 1000; rep++) {
            cdsp_image img;
            size_t n;
            void *buf = random_planes(&rng, 48, 48, 8, 1, &img);
            cdsp_edge_params_default(&ep);
            ep.half_window = h;
            ep.step = 1;
            assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 20000, &n), CDSP_OK);
            found += (int)n;
            free(buf);
        }
    /* the frames do hold edges (else the sweep would test nothing) */
    assert_true(found > 1000);
}

/* Count of the points within 0.5 px of the horizontal line y = yh with
 * x >= x0, and the distinct scan rows of the other points. */
static void split_counts(size_t n, double yh, double x0, int *nh, int *rows, int *row_min,
                         int *row_max, int *row_gap)
{
    int seen[512] = {0}, y, last = -1;
    size_t i;
    *nh = 0;
    for (i = 0; i < n; i++) {
        if (fabs((double)edges[i].y - yh) < 0.5 && (double)edges[i].x >= x0)
            (*nh)++;
        else if (edges[i].y >= 0 && edges[i].y < 512)
            seen[(int)((double)edges[i].y + 0.5)] = 1;
    }
    *rows = 0;
    *row_gap = -1;
    *row_min = *row_max = -1;
    for (y = 0; y < 512; y++)
        if (seen[y]) {
            if (last >= 0) {
                if (*row_gap >= 0 && y - last != *row_gap)
                    *row_gap = -2; /* not uniform */
                else if (*row_gap != -2)
                    *row_gap = y - last;
            }
            if (*row_min < 0)
                *row_min = y;
            *row_max = y;
            last = y;
            (*rows)++;
        }
}

/* The buffer filling up must not decide which contours are seen (issue 9):
 * vertical stripes over the left half (near-vertical edges, ~640 row
 * points at step 4) and one horizontal step edge over the right half (32
 * column points). With room for 200, the rows are re-read at a coarser
 * uniform step spanning the whole frame, and the horizontal edge keeps
 * every point it has at full resolution. The same with the families
 * exchanged (the image transposed). */
static void test_capacity_fair(void **state)
{
    enum { S = 256 };
    static uint8_t px[S * S], tp[S * S];
    cdsp_image img = {px, S, S, S, 8}, timg = {tp, S, S, S, 8};
    cdsp_edge_params ep;
    size_t n_all, n;
    int x, y, nh_all, nh, rows, rmin, rmax, gap, pass;
    const double yh = 128.3;
    (void)state;
    for (y = 0; y < S; y++)
        for (x = 0; x < S; x++) {
            double v;
            if (x < S / 2)
                v = (x / 12) % 2 ? 200 : 40; /* 12 px: wider than the 9 px window */
            else {
                double d = y + 0.5 - yh; /* covered fraction of the pixel below the edge */
                v = 40 + 160 * (d < 0 ? 0 : d > 1 ? 1 : d);
            }
            px[y * S + x] = (uint8_t)(v + 0.5);
        }
    for (y = 0; y < S; y++)
        for (x = 0; x < S; x++)
            tp[x * S + y] = px[y * S + x];
    cdsp_edge_params_default(&ep);
    for (pass = 0; pass < 2; pass++) {
        const cdsp_image *im = pass ? &timg : &img;
        size_t i;
        assert_int_equal(cdsp_edges_detect(im, &ep, edges, 20000, &n_all), CDSP_OK);
        if (pass) /* transpose the points back: the checks below are for img */
            for (i = 0; i < n_all; i++) {
                cdsp_real t = edges[i].x;
                edges[i].x = edges[i].y;
                edges[i].y = t;
            }
        split_counts(n_all, yh, S / 2, &nh_all, &rows, &rmin, &rmax, &gap);
        assert_true(n_all > 600);
        assert_true(nh_all >= 28);
        assert_int_equal(cdsp_edges_detect(im, &ep, edges, 200, &n), CDSP_E_CAPACITY);
        assert_true(n <= 200);
        if (pass)
            for (i = 0; i < n; i++) {
                cdsp_real t = edges[i].x;
                edges[i].x = edges[i].y;
                edges[i].y = t;
            }
        split_counts(n, yh, S / 2, &nh, &rows, &rmin, &rmax, &gap);
        /* the small family at full resolution */
        assert_int_equal(nh, nh_all);
        /* the large one thinned evenly: scan lines a power-of-two multiple
         * of the step apart, from the top of the frame to the bottom */
        assert_true(gap == 8 || gap == 16 || gap == 32 || gap == 64);
        assert_true(rmin <= gap && rmax >= S - 1 - gap);
        assert_true(rows >= S / gap - 1);
    }
}

static void test_hostile(void **state)
{
    uint8_t px[16 * 16];
    cdsp_image img = {px, 16, 16, 16, 8};
    cdsp_edge_params ep;
    size_t n = 99;
    int i;
    (void)state;
    for (i = 0; i < 256; i++)
        px[i] = (uint8_t)((i % 16) < 8 ? 10 : 200);
    cdsp_edge_params_default(&ep);
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    assert_true(n > 0);
    img.bits = 0;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_FORMAT);
    img.bits = 17;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_FORMAT);
    img.bits = 8;
    img.stride = 15;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_FORMAT);
    img.stride = 16;
    img.bits = 16; /* two bytes per pixel need stride >= 32 */
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_FORMAT);
    img.bits = 8;
    img.data = NULL;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_ARG);
    img.data = px;
    img.width = 0;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_ARG);
    img.width = 16;
    ep.step = 0;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_ARG);
    ep.step = 4;
    ep.half_window = 9;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_ARG);
    ep.half_window = 4;
    /* frames smaller than the window: nothing found, nothing read outside */
    img.width = 5;
    img.height = 5;
    img.stride = 16;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    assert_int_equal(n, 0);
}

/* Issue 16: roi.x + roi.w beyond INT_MAX used to overflow (a wrapped end
 * found nothing, UBSan stops the sanitizer build); the end is clipped to
 * the frame instead. A step beyond CDSP_EDGE_MAX_STEP is refused. */
static void test_roi_overflow(void **state)
{
    uint8_t px[32 * 32];
    cdsp_image img = {px, 32, 32, 32, 8};
    cdsp_edge_params ep;
    size_t n = 0, n_all = 0;
    int i;
    (void)state;
    for (i = 0; i < 32 * 32; i++)
        px[i] = (uint8_t)((i % 32) < 16 ? 10 : 200);
    cdsp_edge_params_default(&ep);
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n_all), CDSP_OK);
    assert_true(n_all > 0);
    ep.roi.x = 0;
    ep.roi.y = 0;
    ep.roi.w = INT_MAX;
    ep.roi.h = INT_MAX;
    ep.roi.x = 1; /* 1 + INT_MAX overflows an int */
    ep.roi.y = 1;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    assert_true(n > 0 && n <= n_all);
    ep.roi.x = INT_MAX;
    ep.roi.y = INT_MAX; /* starts beyond the frame: nothing, no overflow */
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    assert_int_equal(n, 0);
    ep.roi.x = INT_MIN;
    ep.roi.y = INT_MIN;
    ep.roi.w = 1;
    ep.roi.h = 1; /* ends before the frame */
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    assert_int_equal(n, 0);
    cdsp_edge_params_default(&ep);
    ep.step = CDSP_EDGE_MAX_STEP;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_OK);
    ep.step = CDSP_EDGE_MAX_STEP + 1;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 100, &n), CDSP_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_positions),
        cmocka_unit_test(test_noise),
        cmocka_unit_test(test_shaded_pipe),
        cmocka_unit_test(test_counts_and_step),
        cmocka_unit_test(test_roi_capacity),
        cmocka_unit_test(test_hostile),
        cmocka_unit_test(test_every_window_safe),
        cmocka_unit_test(test_capacity_fair),
        cmocka_unit_test(test_roi_overflow),
    };
    return cmocka_run_group_tests_name("edges", tests, NULL, NULL);
}
