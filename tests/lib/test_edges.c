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
 * rounding < 1e-4 px. The second pass samples each side D = 2.25 px from the
 * edge, interpolating between the two nearest pixels; a pixel whose centre
 * is c px from a sigma-blurred edge carries ~Phi(-c/sigma) of the other
 * side, and the two sides' nearest pixels differ in c by up to 1 px with
 * the subpixel phase: at sigma 0.7 the leak differs by up to ~0.1 % of the
 * contrast, times (h + 1/2) = 4.5 px: <= 0.01 px; at sigma 1.0 ~0.6 %:
 * <= 0.035 px; near 45 degrees the outer rows move the edge by ~1 px
 * toward one sample: <= 0.02 px. The errors change sign with the phase, so
 * a contour's mean stays within a tenth of that. 8 bit adds the window
 * sum's rounding, sqrt(27/12)/contrast(0.45*255) ~ 0.013 px rms. */
static void test_exact_positions(void **state)
{
    static const struct {
        double k1, blur;
        int bits;
        double dir[3];
        double tol_max, tol_mean;
    } rows[] = {
        {0, 0, 16, {0.2, 1, 0.2}, 1e-3, 2e-4},
        {-0.2, 0.7, 16, {0.2, 1, 0.2}, 0.01, 1e-3},
        {-0.2, 1.0, 16, {1, 0.3, 0.1}, 0.035, 3.5e-3},  /* near-horizontal: column scans */
        {0.1, 0.7, 16, {1, 0.9, 0.3}, 0.02, 2e-3},      /* near 45 degrees: both families */
        {-0.2, 0.7, 8, {0.2, 1, 0.2}, 0.06, 0.01},
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

/* Noise sigma (gray levels) -> position sd of the first-order estimate:
 * a = (mean_k S_k - (h+1/2)(A+B)) / (A-B) with 3(2h+1) pixels in the sums
 * and 3 in each of A, B: var(a) = [(2h+1)/3 + 2 (h+1/2)^2 / 3] sigma^2 / (A-B)^2,
 * i.e. sd = 4.06 sigma / (A-B) for h = 4 (blur correlates neighbours, so
 * the measured value may be lower, never much higher). */
static void test_noise(void **state)
{
    cdsp_camera cam;
    cdsp_image img;
    cdsp_edge_params ep;
    edge_stats st;
    double l[2][3], P[3] = {5, -3, 400}, v[3] = {0.2, 1, 0.2};
    double sigma = 0.01, contrast = 0.7 - 0.25, pred = 4.06 * sigma / contrast;
    void *buf = flat_frame(&cam, -0.2, 0.7, sigma, 16, P, v, &img, l);
    int k;
    (void)state;
    cdsp_edge_params_default(&ep);
    measure(&img, &cam, &ep, l, &st);
    for (k = 0; k < 2; k++) {
        if (st.rms[k] > 1.3 * pred || st.rms[k] < 0.3 * pred)
            fail_msg("line %d: rms %.4f px, predicted %.4f", k, st.rms[k], pred);
        /* unbiased: mean within 4 standard errors */
        assert_true(fabs(st.mean[k]) < 4 * pred / sqrt(st.count[k]));
    }
    free(buf);
}

/* A shaded pipe (Lambertian, 85 % ambient, light from above left): the
 * second pass (each side's mean over its span) keeps each contour's mean
 * offset under 0.03 px; the end-pixel estimate alone was off by ~0.06 px
 * on both contours (README, "Accuracy"). The residual is the midpoint rule's
 * error for a square-root profile, 0.04 k L^1.5 / contrast for a limb
 * profile k sqrt(delta) over the span L ~ 4.5 px. */
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
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("shaded line %d: mean %.4f px\n", k, st.mean[k]);
        if (fabs(st.mean[k]) > 0.03 || st.count[k] < 60)
            fail_msg("shaded contour %d: mean offset %.4f px over %d points", k, st.mean[k], st.count[k]);
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

static void test_roi_capacity(void **state)
{
    cdsp_camera cam;
    cdsp_image img;
    cdsp_edge_params ep;
    double l[2][3], P[3] = {0, 0, 400}, v[3] = {0, 1, 0};
    void *buf = flat_frame(&cam, 0, 0.7, 0, 8, P, v, &img, l);
    size_t n, i;
    (void)state;
    cdsp_edge_params_default(&ep);
    ep.roi.x = 0;
    ep.roi.y = 100;
    ep.roi.w = 320; /* the left half: only the left contour */
    ep.roi.h = 100;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 20000, &n), CDSP_OK);
    assert_true(n >= 24);
    for (i = 0; i < n; i++) {
        assert_true(edges[i].x >= 0 && edges[i].x < 320);
        assert_true(edges[i].y >= 100 && edges[i].y < 200);
    }
    ep.roi.w = ep.roi.h = 0;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 10, &n), CDSP_E_CAPACITY);
    assert_int_equal(n, 10);
    /* a roi entirely outside the frame finds nothing, without reading outside */
    ep.roi.x = 1000;
    ep.roi.y = 1000;
    ep.roi.w = 50;
    ep.roi.h = 50;
    assert_int_equal(cdsp_edges_detect(&img, &ep, edges, 20000, &n), CDSP_OK);
    assert_int_equal(n, 0);
    free(buf);
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
        cmocka_unit_test(test_roi_overflow),
    };
    return cmocka_run_group_tests_name("edges", tests, NULL, NULL);
}
