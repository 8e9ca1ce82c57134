/*
 * test_render.c - the simulated camera draws what the geometry says.
 * The main check: in each row, a window's pixel sum across a contour gives
 * the contour's position exactly for an area-sampled straight edge
 * (sum = I_left (x_e - left) + I_right (right - x_e)), so it must match the
 * contour computed independently in double (distortion and all) to 1/100 px.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <stdio.h>
#include <cmocka.h>
#include "support.h"

/* Double-precision plumb_bob (k1, k2 only), independent of the library. */
static void distort_d(const cdsp_camera *c, double u, double v, double *ud, double *vd)
{
    double x = (u - (double)c->cx) / (double)c->fx, y = (v - (double)c->cy) / (double)c->fy;
    double r2 = x * x + y * y, k = 1 + (double)c->k1 * r2 + (double)c->k2 * r2 * r2;
    *ud = (double)c->fx * x * k + (double)c->cx;
    *vd = (double)c->fy * y * k + (double)c->cy;
}

/* Where undistorted line l crosses distorted row `row`: bisection along the
 * line on the distorted v coordinate. */
static double crossing_x(const cdsp_camera *c, const double l[3], double row)
{
    double lo = -2000, hi = 4000; /* v range of the undistorted line */
    int i;
    for (i = 0; i < 200; i++) {
        double mid = (lo + hi) / 2, u = -(l[1] * mid + l[2]) / l[0], ud, vd;
        distort_d(c, u, mid, &ud, &vd);
        if (vd < row)
            lo = mid;
        else
            hi = mid;
    }
    {
        double u = -(l[1] * lo + l[2]) / l[0], ud, vd;
        distort_d(c, u, lo, &ud, &vd);
        return ud;
    }
}

static void contour_positions(double k1, double blur)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    double P[3] = {-15, 10, 420}, v[3] = {0.25, 1, 0.3}, l[2][3], pin[2], worst = 0;
    uint16_t *px;
    int y, k, rows = 0;
    const double IB = 0.2, IP = 0.75; /* background, pipe: flat */
    sup_camera(&cam, 480, 400, 700, k1, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    s.texture = 0;
    s.noise_sigma = 0;
    s.blur_sigma_px = (cdsp_real)blur;
    s.background_level = (cdsp_real)IB;
    s.pipe_level = (cdsp_real)IP;
    px = sup_render(&s, &cam, 16, 1, &img);
    assert_non_null(px);
    assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
    for (y = 40; y < 360; y += 3)
        for (k = 0; k < 2; k++) {
            double xe = crossing_x(&cam, l[k], y), S = 0, IL, IR, est;
            int i0 = (int)floor(xe) - 6, i1 = (int)floor(xe) + 6, i;
            if (i0 < 2 || i1 > cam.width - 3)
                continue;
            for (i = i0; i <= i1; i++)
                S += px[(size_t)y * (size_t)cam.width + (size_t)i] / 65535.0;
            /* l points to the pipe: a > 0 means the pipe is on the right */
            IL = l[k][0] > 0 ? IB : IP;
            IR = l[k][0] > 0 ? IP : IB;
            est = (S + IL * (i0 - 0.5) - IR * (i1 + 0.5)) / (IL - IR);
            if (fabs(est - xe) > worst)
                worst = fabs(est - xe);
            rows++;
        }
    /* 16-bit rounding: 13 px * 0.5/65535 / contrast 0.55 ~ 2e-4 px, plus the
     * undistortion the renderer maps pixels with (CDSP_UNDISTORT_TOL_PX:
     * 1e-9 px double, 1e-3 px float). Measured (CDSP_TEST_VERBOSE=1): worst
     * 9.5e-5 px (double), 9.3e-4 px (float, with k1); it allowed 0.01. */
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("contours k1 %g blur %g: worst %.3g px\n", k1, blur, worst);
    if (worst > 2e-4 + CDSP_UNDISTORT_TOL_PX)
        fail_msg("k1 %g blur %g: contour off by %.4f px", k1, blur, worst);
    assert_true(rows > 150);
    free(px);
}

static void test_contours_exact(void **state)
{
    (void)state;
    contour_positions(0, 0);
    contour_positions(-0.25, 0);
    contour_positions(0, 0.8);
    contour_positions(-0.25, 1.0);
    contour_positions(0.1, 0.5);
}

/* Shaded pipes: a contour pixel's pipe part must carry the mean of the
 * shading over that part (it changes like sqrt(distance) near the limb),
 * not the limb's value. Reference: the same scene rendered 4x finer and
 * box-filtered, whose own error is 4x smaller. A window-sum difference d
 * (intensity x px) moves the edge by d / contrast; required < 0.01 px (the
 * limb-value shortcut this replaced was off by 0.04-0.13 px). */
static void test_shaded_coverage(void **state)
{
    const int SS = 4, Wd = 320, Hd = 240;
    double ambient;
    (void)state;
    for (ambient = 0.5; ambient < 0.9; ambient += 0.35) {
        cdsp_camera cam, big;
        cdsp_scene s;
        cdsp_image a, b;
        double P[3] = {0, 0, 300}, v[3] = {0.1, 1, 0.1}, l[2][3], pin[2];
        uint16_t *pa, *pb;
        int k;
        sup_camera(&cam, Wd, Hd, 400, 0, 0);
        sup_camera(&big, Wd * SS, Hd * SS, 400.0 * SS, 0, 0);
        big.cx = (cdsp_real)(((double)cam.cx + 0.5) * SS - 0.5);
        big.cy = (cdsp_real)(((double)cam.cy + 0.5) * SS - 0.5);
        sup_scene(&s, P, v, 8);
        s.ambient = (cdsp_real)ambient;
        s.texture = 0;
        s.blur_sigma_px = 0;
        s.noise_sigma = 0;
        pa = sup_render(&s, &cam, 16, 1, &a);
        pb = sup_render(&s, &big, 16, 1, &b);
        assert_non_null(pa);
        assert_non_null(pb);
        assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
        for (k = 0; k < 2; k++) {
            double sum = 0;
            int y, rows = 0;
            for (y = 20; y < Hd - 20; y += 2) {
                double xe = -(l[k][1] * y + l[k][2]) / l[k][0], d = 0;
                int x, i0 = (int)floor(xe) - 5, i1 = (int)floor(xe) + 5;
                for (x = i0; x <= i1; x++) {
                    double ref = 0;
                    int yy, xx;
                    for (yy = 0; yy < SS; yy++)
                        for (xx = 0; xx < SS; xx++)
                            ref += pb[(size_t)(y * SS + yy) * (size_t)(Wd * SS) + (size_t)(x * SS + xx)];
                    d += pa[(size_t)y * (size_t)Wd + (size_t)x] / 65535.0 - ref / (SS * SS * 65535.0);
                }
                sum += d;
                rows++;
            }
            sum /= rows;
            if (getenv("CDSP_TEST_VERBOSE"))
                print_message("supersampled ambient %.2f contour %d: %.3g px\n", ambient, k,
                              sum / (double)(s.pipe_level - s.background_level));
            /* measured 4.2e-3 px at most (ambient 0.5), double and float */
            if (fabs(sum / (double)(s.pipe_level - s.background_level)) > 0.01)
                fail_msg("ambient %.2f contour %d: edge moved %.4f px from the supersampled one",
                         ambient, k, sum / (double)(s.pipe_level - s.background_level));
        }
        free(pa);
        free(pb);
    }
}

/* A finite pipe: the cap faces the camera where the axis runs away from it;
 * beyond the end is background; clutter bars are drawn at their level. */
static void test_caps_and_clutter(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    double P[3] = {0, 0, 300}, v[3] = {0, 0.6, 0.8};
    uint8_t *px;
    cdsp_real end[3], pix[2], beyond[3], mid[3];
    int i;
    (void)state;
    sup_camera(&cam, 320, 240, 300, 0, 0);
    sup_scene(&s, P, v, 10);
    s.half_length = 60;
    s.ambient = 1;
    s.texture = 0;
    s.noise_sigma = 0;
    s.blur_sigma_px = 0;
    s.n_clutter = 1;
    s.clutter[0].p0[0] = -200;
    s.clutter[0].p0[1] = -60;
    s.clutter[0].p0[2] = 600;
    s.clutter[0].p1[0] = 200;
    s.clutter[0].p1[1] = -60;
    s.clutter[0].p1[2] = 600;
    s.clutter[0].half_width = 8;
    s.clutter[0].level = (cdsp_real)0.95;
    px = sup_render(&s, &cam, 8, 1, &img);
    assert_non_null(px);
    /* the near end (axis - half_length): its cap faces the camera */
    for (i = 0; i < 3; i++) {
        end[i] = (cdsp_real)(P[i] - 60 * v[i]);
        beyond[i] = (cdsp_real)(P[i] + 100 * v[i]); /* past the far end */
        mid[i] = (cdsp_real)(P[i] + 0 * v[i]);
    }
    assert_int_equal(cdsp_camera_project(&cam, end, pix), CDSP_OK);
    /* float builds may round the last gray level the other way */
    assert_true(abs(px[(int)lround((double)pix[1]) * 320 + (int)lround((double)pix[0])] -
                    (int)lround((double)s.cap_level * 255)) <= 1);
    assert_int_equal(cdsp_camera_project(&cam, mid, pix), CDSP_OK);
    assert_true(abs(px[(int)lround((double)pix[1]) * 320 + (int)lround((double)pix[0])] -
                    (int)lround((double)s.pipe_level * 255)) <= 1);
    /* the bar crosses the frame at v = 300 * -60/600 + cy; at u = 100 it is
     * at X = (100 - cx) * 600/300 = -119, inside its +-200 span, and its
     * half-width 8 at 600 mm is 4 px: that pixel is all bar, its level */
    assert_int_equal(px[(int)lround(-0.1 * 300 + (double)cam.cy) * 320 + 100],
                     (int)lround((double)s.clutter[0].level * 255));
    assert_int_equal(cdsp_camera_project(&cam, beyond, pix), CDSP_OK);
    assert_int_equal(px[(int)lround((double)pix[1]) * 320 + (int)lround((double)pix[0])],
                     (int)lround((double)s.background_level * 255));
    /* top-left corner: background */
    assert_int_equal(px[5 * 320 + 5], (int)lround((double)s.background_level * 255));
    free(px);
}

static void test_noise_and_depth(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image i8, i16;
    double P[3] = {0, 0, 5000}, v[3] = {1, 0, 0}, sum = 0, sum2 = 0;
    uint8_t *a;
    uint16_t *b;
    int n = 0, x, y;
    (void)state;
    sup_camera(&cam, 200, 150, 300, 0, 0);
    sup_scene(&s, P, v, 1);
    s.texture = 0;
    s.blur_sigma_px = 0;
    s.noise_sigma = (cdsp_real)0.01;
    b = sup_render(&s, &cam, 16, 3, &i16);
    s.noise_sigma = 0;
    a = sup_render(&s, &cam, 8, 3, &i8);
    assert_non_null(a);
    assert_non_null(b);
    /* rows 0..40: background only; the noise sd comes back (n = 8000:
     * sd of the sd estimate ~ 0.8 %) */
    for (y = 0; y < 40; y++)
        for (x = 0; x < 200; x++) {
            double d = b[y * 200 + x] / 65535.0 - (double)s.background_level;
            sum += d;
            sum2 += d * d;
            n++;
            assert_int_equal(a[y * 200 + x], (int)lround((double)s.background_level * 255));
        }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("noise: mean %.3g (se %.3g), sd/0.01 - 1 = %.4f\n", sum / n, 0.01 / sqrt(n),
                      sqrt(sum2 / n) / 0.01 - 1);
    assert_true(fabs(sum / n) < 5 * 0.01 / sqrt(n));
    /* 4 sd of the sd estimate (1/sqrt(2n) = 0.8 %); measured +0.25 %
     * (double), -2.1 % (float: other draws) */
    assert_true(fabs(sqrt(sum2 / n) / 0.01 - 1) < 4 / sqrt(2.0 * n));
    free(a);
    free(b);
}

static void test_reproducible_and_args(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image i1, i2;
    double P[3] = {0, 0, 300}, v[3] = {0.1, 1, 0};
    uint8_t *a, *b, buf[64 * 48];
    float scr[10];
    cdsp_rng rng;
    (void)state;
    sup_camera(&cam, 64, 48, 80, -0.1, 0);
    sup_scene(&s, P, v, 8);
    a = sup_render(&s, &cam, 8, 11, &i1);
    b = sup_render(&s, &cam, 8, 11, &i2);
    assert_memory_equal(a, b, 64 * 48);
    free(a);
    free(b);
    cdsp_rng_seed(&rng, 1, 1);
    assert_int_equal(cdsp_render(&s, &cam, buf, 10, 8, NULL, 0, &rng), CDSP_E_FORMAT);
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 0, NULL, 0, &rng), CDSP_E_FORMAT);
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, scr, 10, &rng), CDSP_E_CAPACITY);
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, &rng), CDSP_E_CAPACITY);
    s.blur_sigma_px = 0;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_ARG); /* noise, no rng */
    s.noise_sigma = 0;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_OK);
    s.radius = (cdsp_real)NAN;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_NONFINITE);
    s.radius = -1;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_ARG);
    s.radius = 8;
    s.n_clutter = CDSP_RENDER_MAX_CLUTTER + 1;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_ARG);
    s.n_clutter = 0;
    /* camera inside the pipe: everything is pipe, no crash */
    s.radius = 400;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_OK);
}

/* The scene options the detection tests need (background ramp, specular
 * highlight, linear motion blur), each against its own formula on a flat,
 * noise-free 16-bit frame of a vertical pipe (no distortion: pixel = ray).
 * 16-bit rounding is 0.5/65535 = 7.6e-6 of full scale. */
typedef struct {
    const char *what;
    double ramp_u, ramp_v, specular, motion;
} option_case;

static void scene_option(const option_case *c)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    double P[3] = {0, 0, 300}, v[3] = {0, 1, 0}, l[2][3], pin[2];
    const double IB = 0.2, IP = 0.6;
    uint16_t *px;
    int W = 320, Hh = 240;
    sup_camera(&cam, W, Hh, 300, 0, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    s.texture = 0;
    s.noise_sigma = 0;
    s.blur_sigma_px = 0;
    s.background_level = (cdsp_real)IB;
    s.pipe_level = (cdsp_real)IP;
    s.background_ramp[0] = (cdsp_real)c->ramp_u;
    s.background_ramp[1] = (cdsp_real)c->ramp_v;
    s.specular = (cdsp_real)c->specular;
    s.specular_exp = 20;
    s.light[0] = 0;
    s.light[1] = 0;
    s.light[2] = -1;
    s.motion_px[0] = (cdsp_real)c->motion;
    px = sup_render(&s, &cam, 16, 1, &img);
    assert_non_null(px);
    assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
    if (c->ramp_u != 0 || c->ramp_v != 0) {
        /* background corners: level + ramp . (pixel - principal point) */
        static const int at[4][2] = {{5, 5}, {300, 10}, {20, 230}, {310, 200}};
        int i;
        for (i = 0; i < 4; i++) {
            double want = IB + c->ramp_u * (at[i][0] - (double)cam.cx) + c->ramp_v * (at[i][1] - (double)cam.cy);
            double got = px[at[i][1] * W + at[i][0]] / 65535.0;
            if (fabs(got - want) > 1e-5)
                fail_msg("%s: background at (%d, %d) is %.6f, want %.6f", c->what, at[i][0], at[i][1], got, want);
        }
    }
    if (c->specular > 0) {
        /* Light and view both along -Z at the row through the principal
         * point: h = (0, 0, -1), so n.h = cos(theta) for a surface normal
         * theta from the view; pixel centres are at most half a pixel
         * (1 mm at 300 mm, theta <= 0.5/8 rad) from the crest, so the peak
         * is specular * cos(1/16)^20 >= 0.961 specular. Near the limb
         * (theta ~ 60 deg) the highlight is below 1e-6. */
        int y = (int)lround((double)cam.cy), x, xl = (int)floor(-l[0][2] / l[0][0]), xr = (int)ceil(-l[1][2] / l[1][0]);
        double peak = 0, lo = xl < xr ? xl : xr, hi = xl < xr ? xr : xl, limb;
        for (x = (int)lo + 2; x <= (int)hi - 2; x++)
            if (px[y * W + x] / 65535.0 > peak)
                peak = px[y * W + x] / 65535.0;
        if (peak < IP + 0.961 * c->specular || peak > IP + c->specular + 1e-5)
            fail_msg("%s: highlight peak %.5f, want %.5f..%.5f", c->what, peak, IP + 0.961 * c->specular,
                     IP + c->specular);
        /* a pixel whose centre sees the surface at ~60 degrees: x = 7 mm of 8 */
        limb = px[y * W + (int)lround((double)cam.cx + 7.0 * 300 / 292)] / 65535.0;
        if (fabs(limb - IP) > 1e-5)
            fail_msg("%s: off the stripe %.6f, want %.6f", c->what, limb, IP);
    }
    if (c->motion > 0) {
        /* A horizontal box of length L over an area-sampled vertical edge:
         * the pixel at offset e from it becomes IB + (IP - IB)(1/2 + e/L)
         * for |e| <= (L - 1)/2 (a box of L convolved with the pixel's box);
         * linear interpolation between pixel centres is exact on that
         * linear stretch, so only 16-bit rounding remains: 7.6e-6 / 0.4
         * contrast = 1.9e-5 (measured 1.5e-5; allowed 5e-5). The window
         * sum, and so the edge position from it, is kept exactly:
         * interpolated shifts of a sampled profile keep its sum
         * (telescoping); 19 rounded pixels give <= 3.6e-4 px (measured
         * 2.3e-5; allowed 4e-4). */
        double L = c->motion, worst_ramp = 0, worst_pos = 0;
        int y, k;
        for (y = 60; y < 180; y += 7)
            for (k = 0; k < 2; k++) {
                double xe = -(l[k][1] * y + l[k][2]) / l[k][0], S = 0, IL, IR, est;
                int i0 = (int)floor(xe) - 9, i1 = (int)floor(xe) + 9, i;
                IL = l[k][0] > 0 ? IB : IP;
                IR = l[k][0] > 0 ? IP : IB;
                for (i = i0; i <= i1; i++) {
                    double val = px[y * W + i] / 65535.0, e = i - xe;
                    S += val;
                    if (fabs(e) <= (L - 1) / 2) {
                        double frac = (val - IL) / (IR - IL), want = 0.5 + e / L;
                        if (fabs(frac - want) > worst_ramp)
                            worst_ramp = fabs(frac - want);
                    }
                }
                est = (S + IL * (i0 - 0.5) - IR * (i1 + 0.5)) / (IL - IR);
                if (fabs(est - xe) > worst_pos)
                    worst_pos = fabs(est - xe);
            }
        if (worst_ramp > 5e-5 || worst_pos > 4e-4)
            fail_msg("%s: ramp off by %.4f of the contrast, edge moved %.4f px", c->what, worst_ramp, worst_pos);
    }
    free(px);
}

static void test_scene_options(void **state)
{
    static const option_case cases[] = {
        {"ramp along u", 4e-4, 0, 0, 0},
        {"ramp along u and v", -3e-4, 5e-4, 0, 0},
        {"specular stripe", 0, 0, 0.3, 0},
        {"motion blur 6 px", 0, 0, 0, 6},
        {"motion blur 4 px", 0, 0, 0, 4},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        scene_option(&cases[i]);
}

/* The library's exact contours agree with the test's own. */
static void test_cylinder_contours(void **state)
{
    cdsp_camera cam;
    cdsp_rng rng;
    int t, k, j;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_rng_seed(&rng, 8, 8);
    for (t = 0; t < 100; t++) {
        double P[3], v[3], l[2][3], pin[2];
        cdsp_real Pr[3], vr[3], l1[3], l2[3], pr[2];
        sup_random_pipe(&rng, 200, 2000, P, v);
        for (j = 0; j < 3; j++) {
            Pr[j] = (cdsp_real)P[j];
            vr[j] = (cdsp_real)v[j];
        }
        assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
        assert_int_equal(cdsp_cylinder_contours(&cam, Pr, vr, 8, 1, l1, l2, pr), CDSP_OK);
        for (k = 0; k < 3; k++) {
            /* the same formulas in the build's precision: a few roundings of
             * eps (c: of its ~3000 px); measured 0 in double (identical
             * arithmetic) and 0.97 eps in float; it allowed 1e4 eps */
            assert_true(fabs((double)l1[k] - l[0][k]) < 4 * T_EPS * (k == 2 ? 3000 : 1));
            assert_true(fabs((double)l2[k] - l[1][k]) < 4 * T_EPS * (k == 2 ? 3000 : 1));
        }
        assert_int_equal(cdsp_cylinder_contours(&cam, Pr, vr, 8, 0, l1, l2, pr), CDSP_OK);
        assert_true(fabs((double)l1[0] + l[0][0]) < 4 * T_EPS);
    }
    {
        cdsp_real Pr[3] = {0, 0, 5}, vr[3] = {0, 1, 0}, l1[3], l2[3], pr[2];
        assert_int_equal(cdsp_cylinder_contours(&cam, Pr, vr, 8, 1, l1, l2, pr), CDSP_E_DEGENERATE);
    }
}

/* Issue 16: every real of the scene is checked (a NaN level or light used
 * to reach a conversion to long), and out-of-range but finite values are
 * clamped, not converted out of range. */
static void test_nonfinite_scene(void **state)
{
    cdsp_camera cam;
    cdsp_scene s, base;
    uint8_t buf[64 * 48];
    double P[3] = {0, 0, 300}, v[3] = {0.1, 1, 0};
    cdsp_real *fields[8];
    int i;
    (void)state;
    sup_camera(&cam, 64, 48, 80, -0.1, 0);
    sup_scene(&base, P, v, 8);
    base.blur_sigma_px = 0;
    base.noise_sigma = 0;
    for (i = 0; i < 8; i++) {
        s = base;
        fields[0] = &s.pipe_level;
        fields[1] = &s.cap_level;
        fields[2] = &s.background_level;
        fields[3] = &s.light[1];
        fields[4] = &s.ambient;
        fields[5] = &s.texture;
        fields[6] = &s.texture_scale_px;
        fields[7] = &s.half_length;
        *fields[i] = (cdsp_real)NAN;
        assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_NONFINITE);
        *fields[i] = (cdsp_real)INFINITY;
        assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_NONFINITE);
    }
    s = base;
    s.n_clutter = 1;
    s.clutter[0].p0[0] = -50;
    s.clutter[0].p1[0] = 50;
    s.clutter[0].p0[2] = s.clutter[0].p1[2] = 500;
    s.clutter[0].half_width = 5;
    s.clutter[0].level = (cdsp_real)NAN;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_NONFINITE);
    /* finite extremes: clamped to the output's range */
    s = base;
    s.pipe_level = (cdsp_real)1e30;
    s.background_level = (cdsp_real)-1e30;
    s.texture = 1;
    s.texture_scale_px = (cdsp_real)1e-30;
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_OK);
    assert_int_equal(buf[0], 0);            /* corner: background */
    assert_int_equal(buf[24 * 64 + 32], 255); /* centre: the pipe */
    s = base;
    s.blur_sigma_px = (cdsp_real)(CDSP_RENDER_MAX_BLUR_PX + 0.5);
    assert_int_equal(cdsp_render(&s, &cam, buf, 0, 8, NULL, 0, NULL), CDSP_E_ARG);
    /* found by fuzzing (tests/fuzz/corpus/points/regress-contours-infinite-fx.bin):
     * the contours of a camera with fx = -Inf came back CDSP_OK and infinite */
    {
        cdsp_camera bad = cam;
        cdsp_real l1[3], l2[3], pin[2];
        bad.fx = (cdsp_real)-INFINITY;
        assert_int_equal(cdsp_cylinder_contours(&bad, base.axis_point, base.axis_dir, 8, 1, l1, l2,
                                                pin), CDSP_E_NONFINITE);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contours_exact),
        cmocka_unit_test(test_shaded_coverage),
        cmocka_unit_test(test_caps_and_clutter),
        cmocka_unit_test(test_noise_and_depth),
        cmocka_unit_test(test_reproducible_and_args),
        cmocka_unit_test(test_cylinder_contours),
        cmocka_unit_test(test_scene_options),
        cmocka_unit_test(test_nonfinite_scene),
    };
    return cmocka_run_group_tests_name("render", tests, NULL, NULL);
}
