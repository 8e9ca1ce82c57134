/*
 * test_frame.c - frame -> pose on rendered frames: clean frames, clutter and
 * visible end caps, a moving sequence in tracking mode (losing and finding
 * the pipe again), 16-bit frames, and hostile arguments.
 *
 * Tolerances: the solver's own 1-sigma (from the line fits' residuals),
 * times 4 (see check_pose), plus an allowance for the edge detector's
 * shading bias where the pipe is shaded: a contour shifted by delta px
 * moves the axis by about d * delta / f sideways and d * 2 delta / w in
 * depth (w the pipe's width in px), see edges.c; delta = 0.02 px, what the
 * second pass leaves at 85 % ambient (README, "Accuracy").
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <limits.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <stdio.h>
#include <cmocka.h>
#include "support.h"

static cdsp_frame_ws ws;

#define W 640
#define H 480
#define F 800.0

static void foot(const double P[3], const double v[3], double f[3])
{
    double n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    double t = (P[0] * v[0] + P[1] * v[1] + P[2] * v[2]) / n2;
    int i;
    for (i = 0; i < 3; i++)
        f[i] = P[i] - t * v[i];
}

/* |error of P_C| against 4 sigma + the shading allowance for delta px.
 * sigma = sqrt(trace of the point's covariance): the error is Gaussian with
 * that covariance (test_covariance.c), so |e| > 4 sigma has a probability
 * below 6e-5 per check whatever its shape (it was 6 sigma: 3.4 mm at 420
 * mm). Measured (CDSP_TEST_VERBOSE=1) over the ~60 poses of this file:
 * worst 2.6 sigma (double), 2.9 sigma (float); direction likewise 2.6
 * sigma. delta_px: the edge bias a shaded limb leaves (lib/edges.c's
 * second pass: 0.01-0.02 px at 85 % ambient), moving P_C by
 * d delta (1/F + 2/w). */
static void check_pose(const char *what, const cdsp_result *r, const double P[3], const double v[3],
                       double radius, double delta_px)
{
    double f[3], got[3], dir[3], err = 0, sig = 0, d, w, allow;
    int i;
    foot(P, v, f);
    sup_result_pose(r, got, dir, NULL);
    for (i = 0; i < 3; i++) {
        err += (got[i] - f[i]) * (got[i] - f[i]);
        sig += (double)(r->sigma_point[i] * r->sigma_point[i]);
    }
    err = sqrt(err);
    sig = sqrt(sig);
    d = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    w = 2 * F * radius / d;
    allow = 4 * sig + d * delta_px * (1 / F + 2 / w) + 1e-9 * d;
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("%s: P_C err %.4g = %.2f sigma (allowed %.4g), direction %.3g rad = %.2f sigma\n",
                      what, err, err / sig, allow, sup_axis_angle(dir, v),
                      sup_axis_angle(dir, v) / sqrt((double)(r->sigma_direction[0] * r->sigma_direction[0] +
                                                             r->sigma_direction[1] * r->sigma_direction[1] +
                                                             r->sigma_direction[2] * r->sigma_direction[2])));
    if (err > allow)
        fail_msg("%s: P_C off by %.4f (allowed %.4f: sigma %.4f, d %.1f)", what, err, allow, sig, d);
    /* direction: the contours' angle error, a few 1e-3 rad at worst here */
    if (sup_axis_angle(dir, v) > 4 * sqrt((double)(r->sigma_direction[0] * r->sigma_direction[0] +
                                                  r->sigma_direction[1] * r->sigma_direction[1] +
                                                  r->sigma_direction[2] * r->sigma_direction[2])) +
                                        4 * delta_px / w + 1e-7)
        fail_msg("%s: direction off by %.5f rad", what, sup_axis_angle(dir, v));
}

static cdsp_status solve(const cdsp_scene *s, const cdsp_camera *cam, int bits, uint64_t seed,
                         const cdsp_result *prior, cdsp_result *out)
{
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_status st;
    void *buf = sup_render(s, cam, bits, seed, &img);
    assert_non_null(buf);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, seed, 3);
    st = cdsp_frame_solve(&img, cam, s->radius, &prm, prior, &ws, &rng, out);
    free(buf);
    return st;
}

/* Flat-lit pipes in random poses: only noise limits the answer. */
static void test_clean_frames(void **state)
{
    cdsp_camera cam;
    cdsp_rng gen;
    int t, done = 0;
    (void)state;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    cdsp_rng_seed(&gen, 31, 1);
    for (t = 0; t < 200 && done < 10; t++) {
        double P[3], v[3], l[2][3], pin[2];
        cdsp_scene s;
        cdsp_result r;
        char what[32];
        sup_random_pipe(&gen, 250, 600, P, v);
        P[0] = 40 * ((double)cdsp_rng_uniform(&gen) - 0.5); /* through the middle of the view */
        P[1] = 40 * ((double)cdsp_rng_uniform(&gen) - 0.5);
        /* keep poses whose contours cross the middle of the frame */
        if (!sup_contour_lines(&cam, P, v, 8, l, pin) || fabs(pin[0] - W / 2.0) > 120 ||
            fabs(pin[1] - H / 2.0) > 90)
            continue;
        sup_scene(&s, P, v, 8);
        s.ambient = 1;
        assert_int_equal(solve(&s, &cam, 8, (uint64_t)t, NULL, &r), CDSP_OK);
        assert_true(r.flags & CDSP_FLAG_FULL_SEARCH);
        snprintf(what, sizeof what, "pose %d", t);
        check_pose(what, &r, P, v, 8, 0.0);
        done++;
    }
    assert_true(done >= 8);
}

/* The reported sigma at every scanline spacing (lib/edges.c
 * cdsp__edges_scan_var): at step 1 and 2 neighbouring points share
 * scanlines of their windows, and the line fits' variance, taken as of
 * independent points, was low by 3 and 5/3 (the rack engineer's
 * measurement, 2026-12-03). A flat-lit pipe, 40 noise seeds per step: the
 * errors of the distance and of the direction (its angle over the RMS of
 * its sigmas) over their reported sigmas have an RMS of 1 when the sigma
 * is right; 80 such ratios give it to about +-8 % (1 / sqrt(2 * 80)), so
 * [0.75, 1.3] holds it within 3 of those. Without the factor step 1 gives
 * about sqrt(3) = 1.73. */
static void test_sigma_step(void **state)
{
    static const int steps[] = {1, 2, 4};
    cdsp_camera cam;
    size_t si;
    (void)state;
    sup_camera(&cam, W, H, F, 0, 0);
    for (si = 0; si < sizeof steps / sizeof steps[0]; si++) {
        double P[3] = {4, -3, 420}, v[3] = {0.3, 1, 0.15}, z2 = 0, n, rms;
        int t, k, m = 0;
        n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (k = 0; k < 3; k++)
            v[k] /= n;
        for (t = 0; t < 40; t++) {
            cdsp_scene s;
            cdsp_image img;
            cdsp_params prm;
            cdsp_result r;
            cdsp_rng rng;
            double d_true = 0, foot[3], tt = P[0] * v[0] + P[1] * v[1] + P[2] * v[2], sd;
            void *buf;
            sup_scene(&s, P, v, 8);
            s.ambient = 1;
            s.noise_sigma = (cdsp_real)0.03;
            buf = sup_render(&s, &cam, 8, 500 + (uint64_t)t, &img);
            assert_non_null(buf);
            cdsp_params_default(&prm);
            prm.edge.step = steps[si];
            cdsp_rng_seed(&rng, (uint64_t)t, 3);
            assert_int_equal(cdsp_frame_solve(&img, &cam, s.radius, &prm, NULL, &ws, &rng, &r), CDSP_OK);
            free(buf);
            assert_false(r.flags & CDSP_FLAG_TRUNCATED);
            for (k = 0; k < 3; k++) {
                foot[k] = P[k] - tt * v[k];
                d_true += foot[k] * foot[k];
            }
            d_true = sqrt(d_true);
            z2 += ((double)r.distance - d_true) * ((double)r.distance - d_true) /
                  ((double)r.sigma_distance * (double)r.sigma_distance);
            sd = sqrt((double)(r.sigma_direction[0] * r.sigma_direction[0] + r.sigma_direction[1] * r.sigma_direction[1] +
                               r.sigma_direction[2] * r.sigma_direction[2]) /
                      2);
            {
                double dir[3] = {(double)r.direction[0], (double)r.direction[1], (double)r.direction[2]};
                double ang = sup_axis_angle(dir, v);
                z2 += ang * ang / (2 * sd * sd);
            }
            m += 2;
        }
        rms = sqrt(z2 / m);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("step %d: error / sigma RMS %.3f over %d ratios\n", steps[si], rms, m);
        if (rms < 0.75 || rms > 1.3)
            fail_msg("step %d: errors over their sigma have RMS %.3f (want 1: [0.75, 1.3])", steps[si], rms);
    }
}

/* A finite pipe whose near end cap is in view, under directional light,
 * with three support bars behind it (one crossing it): the pipe is found,
 * not a bar and not the cap's edge, and the visible segment stops at the cap. */
static void test_clutter_and_caps(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_result r;
    double P[3] = {10, 0, 420}, v[3] = {0.15, 1, 0.35}, vn, endp[3], seg_end;
    int i;
    (void)state;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    sup_scene(&s, P, v, 8);
    s.half_length = 90; /* the near end's cap sits inside the frame */
    s.n_clutter = 3;
    /* a vertical column left of the pipe, a horizontal beam crossing behind
     * it, a slanted strut: bars of the pipe's width or narrower, shorter than it */
    {
        const double bars[3][7] = {
            {-120, -60, 700, -120, 70, 700, 9},
            {-150, 40, 800, 160, 40, 800, 6},
            {80, -90, 650, 160, -10, 650, 5},
        };
        for (i = 0; i < 3; i++) {
            int k;
            for (k = 0; k < 3; k++) {
                s.clutter[i].p0[k] = (cdsp_real)bars[i][k];
                s.clutter[i].p1[k] = (cdsp_real)bars[i][3 + k];
            }
            s.clutter[i].half_width = (cdsp_real)bars[i][6];
            s.clutter[i].level = (cdsp_real)(i == 1 ? 0.55 : 0.9);
        }
    }
    assert_int_equal(solve(&s, &cam, 8, 5, NULL, &r), CDSP_OK);
    /* measured 1.49 mm (double), 1.80 (float): 1.4 / 2.9 sigma, within the
     * noise; the shaded limb's bias allowed as 0.02 px (was 0.12) */
    check_pose("clutter+caps", &r, P, v, 8, 0.02);
    /* the segment ends near the cap: the last inlier is up to one scan step
     * (4 px: 4 d / F = 2.1 mm) short of the cap, the contour's end on the
     * cap's rim is up to r |v_z| / |v| (2.6 mm) along the axis from its
     * centre, plus a px of edge position (0.5 mm): 5.2 mm; measured 2.08 mm
     * (double), 2.07 (float). It allowed 11 mm. */
    vn = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (i = 0; i < 3; i++)
        endp[i] = P[i] - 90 * v[i] / vn;
    seg_end = 1e9;
    for (i = 0; i < 2; i++) {
        double d2 = 0;
        int k;
        for (k = 0; k < 3; k++)
            d2 += pow((double)r.segment[i][k] - endp[k], 2);
        if (sqrt(d2) < seg_end)
            seg_end = sqrt(d2);
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("segment end %.3f mm from the cap's centre\n", seg_end);
    if (seg_end > 4 * 420 / F + 8 * fabs(v[2]) / vn + 420 / F)
        fail_msg("visible segment ends %.2f from the cap", seg_end);
}

/* A sequence: the pipe drifts and turns; after the first frame each frame
 * is tracked from the previous result. Then the pipe leaves the view (no
 * pipe), and comes back (found by a full search). */
static void test_tracking_sequence(void **state)
{
    cdsp_camera cam;
    cdsp_result prev, r;
    int t, tracked = 0, have = 0;
    (void)state;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    for (t = 0; t < 24; t++) {
        double P[3] = {-20 + 1.5 * t, 5 - 0.5 * t, 400 + 3 * t};
        double v[3] = {0.2 + 0.01 * t, 1, 0.2};
        cdsp_scene s;
        cdsp_status st;
        char what[32];
        if (t >= 18 && t < 20)
            P[0] = 5000; /* out of view */
        sup_scene(&s, P, v, 8);
        s.ambient = 1;
        st = solve(&s, &cam, 8, (uint64_t)(100 + t), have ? &prev : NULL, &r);
        if (t >= 18 && t < 20) {
            assert_true(st == CDSP_E_NO_PIPE || st == CDSP_E_FEW_POINTS);
            have = 0;
            continue;
        }
        assert_int_equal(st, CDSP_OK);
        snprintf(what, sizeof what, "frame %d", t);
        check_pose(what, &r, P, v, 8, 0.0);
        if (have) {
            assert_true(r.flags & CDSP_FLAG_TRACKED);
            tracked++;
            /* the direction's sign follows the prior */
            assert_true((double)(r.direction[0] * prev.direction[0] + r.direction[1] * prev.direction[1] +
                                 r.direction[2] * prev.direction[2]) > 0);
        } else {
            assert_true(r.flags & CDSP_FLAG_FULL_SEARCH);
        }
        prev = r;
        have = 1;
    }
    assert_int_equal(tracked, 17 + 3);
}

/* A jump larger than the band: tracking finds nothing where the pipe was
 * and falls back to a full search that does. */
static void test_tracking_fallback(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_result a, b;
    double P[3] = {-40, 0, 400}, v[3] = {0.1, 1, 0.1}, Q[3] = {40, 0, 400};
    (void)state;
    sup_camera(&cam, W, H, F, 0, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    assert_int_equal(solve(&s, &cam, 8, 1, NULL, &a), CDSP_OK);
    sup_scene(&s, Q, v, 8);
    s.ambient = 1;
    assert_int_equal(solve(&s, &cam, 8, 2, &a, &b), CDSP_OK);
    assert_true(b.flags & CDSP_FLAG_FULL_SEARCH);
    check_pose("after jump", &b, Q, v, 8, 0.0);
}

static void test_16bit(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_result r;
    double P[3] = {0, 10, 380}, v[3] = {1, 0.2, 0.3};
    (void)state;
    sup_camera(&cam, W, H, F, -0.1, 0);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    assert_int_equal(solve(&s, &cam, 16, 9, NULL, &r), CDSP_OK);
    check_pose("16-bit", &r, P, v, 8, 0.0);
    {
        cdsp_image img;
        uint16_t *px = sup_render(&s, &cam, 16, 9, &img);
        cdsp_params prm;
        cdsp_rng rng;
        size_t i;
        /* the same frame as Mono12 (values >> 4, bits = 12) */
        for (i = 0; i < (size_t)W * H; i++)
            px[i] >>= 4;
        img.bits = 12;
        cdsp_params_default(&prm);
        cdsp_rng_seed(&rng, 1, 1);
        assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        check_pose("12-bit", &r, P, v, 8, 0.0);
        free(px);
    }
}

/* Detection cues (issue 10), one frame each: what must be found is found
 * (within check_pose's tolerance: flat light, so noise only), what is not
 * a pipe is not reported. */
typedef struct {
    const char *what;
    int out_bits, img_bits; /* rendered significant bits, container's bits */
    double contrast;        /* pipe level - background level */
    double noise;           /* sensor noise, fraction of full scale */
    int clutter;            /* 0 none, 1 thin bar across in front, 2 rack partner,
                               3 only a thin bar (no pipe), 4 crossing bars (no pipe) */
    int expect_pipe;
} cue_case;

static void detect_cue(const cue_case *c)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_result r;
    cdsp_status st;
    double P[3] = {5, 0, 400}, v[3] = {0.1, 1, 0.05};
    void *buf;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    s.texture = 0;
    s.background_level = (cdsp_real)0.3;
    s.pipe_level = (cdsp_real)(0.3 + c->contrast);
    s.noise_sigma = (cdsp_real)c->noise;
    if (c->clutter == 1) { /* a long thin bar (4 px) across the frame, in front */
        const double a[3] = {-250, -120, 300}, b[3] = {250, 140, 300};
        sup_add_bar(&s, a, b, 0.75, 0.8);
    } else if (c->clutter == 2) { /* a parallel pipe beside it, half as long in view */
        const double a[3] = {5 + 30 - 60 * v[0], -60, 400 - 60 * v[2]}, b[3] = {5 + 30 + 60 * v[0], 60, 400 + 60 * v[2]};
        sup_add_bar(&s, a, b, 8, 0.3 + c->contrast);
    } else if (c->clutter >= 3) { /* no pipe: it is far out of view */
        const double a[3] = {-250, -120, 300}, b[3] = {250, 140, 300};
        const double a2[3] = {-200, 150, 500}, b2[3] = {200, -150, 500};
        s.axis_point[0] = (cdsp_real)1e6;
        sup_add_bar(&s, a, b, 0.75, 0.8);
        if (c->clutter == 4) {
            sup_add_bar(&s, a2, b2, 6, 0.7);
        }
    }
    buf = sup_render(&s, &cam, c->out_bits, 77, &img);
    assert_non_null(buf);
    img.bits = c->img_bits;
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 77, 3);
    st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
    if (c->expect_pipe) {
        if (st != CDSP_OK)
            fail_msg("%s: %s", c->what, cdsp_status_token(st));
        check_pose(c->what, &r, P, v, 8, 0.0);
        assert_true(r.confidence > 0 && r.confidence <= 1);
        {
            /* the frame's noise estimate (lib/frame.c) against the rendered
             * noise plus the integer rounding's (variance 1/12): the median
             * of ~1e4 |differences| has a relative sd of ~1.2 %, plus the
             * interpolation in unit bins, which dominates below 2 gray levels
             * (not checked there: +25 % at 0.51, +6-9 % at 1.06 levels).
             * Bound 6 %; measured at 2.1, 16 and 131 levels: worst +3.6 %
             * (double), -3.7 % (float). */
            double g = c->noise * (double)((1 << c->out_bits) - 1), want = sqrt(g * g + 1.0 / 12);
            double rel = (double)r.noise / want - 1;
            if (g >= 2 && getenv("CDSP_TEST_VERBOSE"))
                print_message("%s: noise %.4g, rendered %.4g gray levels (%+.2f %%)\n", c->what,
                              (double)r.noise, want, 100 * rel);
            if (g >= 2 && fabs(rel) > 0.06)
                fail_msg("%s: measured noise %.4g, rendered %.4g gray levels", c->what, (double)r.noise, want);
        }
    } else if (st == CDSP_OK) {
        fail_msg("%s: a pipe reported at %.1f (confidence %.2f)", c->what, (double)r.distance,
                 (double)r.confidence);
    }
    free(buf);
}

static void test_detection_cues(void **state)
{
    static const cue_case cases[] = {
        /* 10 gray levels at 8 bit, noise 0.5 level: the fixed 6 % (15 levels)
         * found no edge; the measured noise gives a step of 5 levels */
        {"faint 10 levels, 8 bit", 8, 8, 10 / 255.0, 0.002, 0, 1},
        /* Mono12 data in a 16-bit container: 6 % of 65535 is above any step */
        {"Mono12 in 16 bit", 12, 16, 0.3, 0.004, 0, 1},
        {"Mono10 in 16 bit, faint", 10, 16, 12 / 255.0, 0.002, 0, 1},
        {"true 16 bit, faint", 16, 16, 10 / 255.0, 0.002, 0, 1},
        {"thin bar across in front", 8, 8, 0.3, 0.004, 1, 1},
        {"rack: the longer of two pipes", 8, 8, 0.3, 0.004, 2, 1},
        {"a thin bar alone", 8, 8, 0.3, 0.004, 3, 0},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        detect_cue(&cases[i]);
}

/* Tracking keeps the pipe it follows when a second, larger pipe and a bar
 * come into view beside it: the prior's factor in the pair score. */
static void test_tracking_newcomers(void **state)
{
    cdsp_camera cam;
    cdsp_result prev, r;
    int t;
    (void)state;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    for (t = 0; t < 10; t++) {
        double P[3] = {-30 + 1.0 * t, 0, 420}, v[3] = {0.1, 1, 0.1};
        cdsp_scene s;
        cdsp_status st;
        char what[48];
        sup_scene(&s, P, v, 8);
        s.ambient = 1;
        if (t >= 3) { /* a nearer, wider pipe slides in from the right */
            const double a[3] = {260 - 20 * t, -200, 380}, b[3] = {260 - 20 * t + 40, 200, 380};
            sup_add_bar(&s, a, b, 10, 0.75);
        }
        if (t >= 5) { /* and a bar crosses in front */
            const double a[3] = {-200, -60, 250}, b[3] = {200, 40, 250};
            sup_add_bar(&s, a, b, 3, 0.6);
        }
        st = solve(&s, &cam, 8, (uint64_t)(300 + t), t ? &prev : NULL, &r);
        assert_int_equal(st, CDSP_OK);
        snprintf(what, sizeof what, "newcomers, frame %d", t);
        check_pose(what, &r, P, v, 8, 0.0);
        if (t)
            assert_true(r.flags & CDSP_FLAG_TRACKED);
        prev = r;
    }
}

/* More edges than the workspace holds (issue 9): vertical stripes above and
 * below the pipe give ~23000 row points at step 1, the horizontal pipe
 * (its contours read by the column scan) ~1200. Filling up must
 * not decide which contours are seen: the rows are re-read at a coarser
 * step, the pipe keeps its points and is found, with the truncation
 * flagged. Before the fix the row scan filled the buffer and the columns
 * were never read: no pipe. */
static void test_edge_buffer_full(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_result r;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    double P[3] = {0, 0, 400}, v[3] = {1, 0.05, 0.1};
    uint8_t *px;
    int x, y;
    (void)state;
    sup_camera(&cam, W, H, F, -0.15, 0.02);
    sup_scene(&s, P, v, 8);
    s.ambient = 1;
    px = sup_render(&s, &cam, 8, 77, &img);
    assert_non_null(px);
    for (y = 0; y < H; y++)
        for (x = 0; x < W && abs(y - H / 2) > 60; x++) /* 10 px: wider than the window */
            px[(size_t)y * img.stride + (size_t)x] = (uint8_t)((x / 10) % 2 ? 210 : 30);
    cdsp_params_default(&prm);
    prm.edge.step = 1;
    cdsp_rng_seed(&rng, 77, 3);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    assert_true(r.flags & CDSP_FLAG_TRUNCATED);
    check_pose("stripes beside a horizontal pipe", &r, P, v, 8, 0.0);
    free(px);
}

/* A busy frame (lib/frame.c detect_busy): a 5-megapixel frame of a pipe
 * under directional light (the paper rack's light, camera and distance)
 * from a quiet sensor: 0.5 gray levels of noise, so the noise lowers the
 * threshold from the fixed 6 % (15.3 levels) to about 5.8. There the
 * pipe's own shading, about 2 levels per px across its body, passes for
 * edges on every scanline: more than half of the buffer (measured 11 082
 * of 16 384). The frame is read again at the fixed threshold, which the
 * contours (40-115 levels) pass and the shading does not: the result says
 * so (min_step 15.3, about 1 200 edges, not truncated) and the pose is
 * the pipe's. Fails without the rule (min_step 5.8). */
static void test_busy_frame(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_result r;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    double P[3] = {0, 10, 600}, v[3] = {1, 0.2, 0.15};
    uint8_t *px;
    size_t n;
    (void)state;
    sup_camera(&cam, 2448, 2048, 16 / 0.00345, 0, 0);
    sup_scene(&s, P, v, 8);
    s.pipe_level = (cdsp_real)0.75;
    s.background_level = (cdsp_real)0.2;
    s.light[0] = (cdsp_real)0.4;
    s.light[1] = (cdsp_real)-0.7;
    s.light[2] = (cdsp_real)-0.6;
    s.ambient = (cdsp_real)0.4;
    s.noise_sigma = (cdsp_real)(0.5 / 255);
    px = sup_render(&s, &cam, 8, 91, &img);
    assert_non_null(px);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 91, 3);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    /* the same frame at the lowered threshold alone: busy */
    {
        cdsp_edge_params e = prm.edge;
        e.coarse = 0;
        e.min_contrast = prm.noise_factor * r.noise / 255;
        (void)cdsp_edges_detect(&img, &e, ws.edge, CDSP_MAX_EDGES, &n);
    }
    if (getenv("FRAME_DEBUG"))
        printf("busy frame: noise %.3f, %zu edges at the lowered threshold; min_step %.2f, %u edges\n",
               (double)r.noise, n, (double)r.min_step, r.n_edges);
    assert_true(n > CDSP_MAX_EDGES / 2);
    assert_true(r.noise < 1);
    assert_true(fabs((double)r.min_step - 0.06 * 255) < 1e-3);
    assert_false(r.flags & CDSP_FLAG_TRUNCATED);
    check_pose("a pipe over a busy background", &r, P, v, 8, 0.0);
    free(px);
}

static void test_args(void **state)
{
    cdsp_camera cam, other;
    cdsp_scene s;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_result r;
    double P[3] = {0, 0, 400}, v[3] = {0, 1, 0};
    void *buf;
    (void)state;
    sup_camera(&cam, W, H, F, 0, 0);
    sup_scene(&s, P, v, 8);
    buf = sup_render(&s, &cam, 8, 1, &img);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    other = cam;
    other.width = 641;
    assert_int_equal(cdsp_frame_solve(&img, &other, 8, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve(&img, &cam, -8, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve(NULL, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, NULL, &rng, &r), CDSP_E_ARG);
    prm.edge.step = 0;
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    cdsp_params_default(&prm);
    /* a region of interest without the pipe */
    prm.edge.roi.x = 0;
    prm.edge.roi.y = 0;
    prm.edge.roi.w = 200;
    prm.edge.roi.h = 480;
    {
        cdsp_status st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
        assert_true(st == CDSP_E_NO_PIPE || st == CDSP_E_FEW_POINTS);
    }
    /* a prior full of NaN is ignored (full search) */
    cdsp_params_default(&prm);
    memset(&r, 0, sizeof r);
    r.lines[0][0] = (cdsp_real)NAN;
    {
        cdsp_result out;
        assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, &r, &ws, &rng, &out), CDSP_OK);
        assert_true(out.flags & CDSP_FLAG_FULL_SEARCH);
    }
    /* a flat frame: nothing to find */
    memset(buf, 100, (size_t)W * H);
    {
        cdsp_status st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
        assert_true(st == CDSP_E_FEW_POINTS || st == CDSP_E_NO_PIPE);
    }
    free(buf);
}

/* Issue 16: track_band_px >= 2^31 (or +Inf) used to overflow its
 * conversion to int; a band wider than the frame is the whole frame, and
 * an roi ending beyond INT_MAX is clipped like the full search's. */
static void test_huge_band(void **state)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_result prior, r;
    double P[3] = {0, 0, 400}, v[3] = {0, 1, 0};
    const double bands[] = {3e9, 1e300, (double)INFINITY};
    void *buf;
    int i;
    (void)state;
    sup_camera(&cam, W, H, F, 0, 0);
    sup_scene(&s, P, v, 8);
    buf = sup_render(&s, &cam, 8, 1, &img);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &prior), CDSP_OK);
    for (i = 0; i < (int)(sizeof bands / sizeof bands[0]); i++) {
        prm.track_band_px = (cdsp_real)bands[i];
        prm.edge.roi.x = 1;
        prm.edge.roi.y = 1;
        prm.edge.roi.w = INT_MAX;
        prm.edge.roi.h = INT_MAX;
        assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, &prior, &ws, &rng, &r), CDSP_OK);
        assert_true(r.flags & CDSP_FLAG_TRACKED);
    }
    free(buf);
}

/*
 * Issue 12: the systematic bound and the scattered-contour rule on the
 * paper's scene (2448 x 2048, 8 bit, noise 0.5 gray level, pipes p1..p4,
 * radius 8 mm, as make bench-accuracy renders it). At ambient 0.4 (the
 * paper's experiment) the shadowed limb is nearly the background's level
 * and its line, fitted to scattered points, put poses 13-170 mm off with
 * confidence 0.97-0.999, beyond sigma plus the bound on p4 (170 mm, bound
 * 31): every pose reported with CDSP_FLAG_BOUND must now hold its error
 * within 3 sigma plus the bound, per coordinate of P_C and on the distance;
 * a pose the scatter rule marks (lib/frame.c cdsp__frame_scatter_mark)
 * claims no bound (flag clear, bound fields 0), so its error is not
 * checked, and its confidence is capped at 0.78 (measured: all four are
 * marked, 20-106 mm off; without the rule they carry a bound and fail).
 * At ambient 0.85 (the renderer's default)
 * every pose is reported with its bound (the rule spares clean contours) with
 * the same coverage; measured errors 0.018-0.051 mm on the distance, bounds
 * 0.15-0.19 mm on p2 and p4 and 4.2 / 3.8 mm on p1 / p3 (one contour's
 * model misfits there: the bound falls back to its blur zone), so the
 * bound stays below 1.5 % of the distance (measured at most 1.16 %).
 */
static void test_paper_bound(void **state)
{
    static const double ambients[] = {0.4, 0.85};
    cdsp_camera cam;
    cdsp_rng rng;
    int a, i, k, unbounded = 0;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_rng_seed(&rng, 3, 3);
    for (a = 0; a < 2; a++)
        for (i = 0; i < 4; i++) {
            cdsp_scene s;
            cdsp_image img;
            cdsp_result r;
            cdsp_params prm;
            cdsp_status st;
            double P[3], v[3], f[3], got[3], dir[3], dtrue;
            void *px;
            sup_paper_bound_scene(&s, i, ambients[a], P, v);
            px = sup_render(&s, &cam, 8, (uint64_t)(50 + i), &img);
            assert_non_null(px);
            cdsp_params_default(&prm);
            st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
            if (st == CDSP_OK && (r.flags & CDSP_FLAG_BOUND)) {
                /* the same frame tracked from this pose: the bounds are
                 * carried (the larger for both contours), not fitted */
                cdsp_result t;
                double bmax = r.edge_bound[0] > r.edge_bound[1] ? r.edge_bound[0] : r.edge_bound[1];
                assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, &r, &ws, &rng, &t), CDSP_OK);
                assert_true(t.flags & CDSP_FLAG_TRACKED);
                assert_true(t.flags & CDSP_FLAG_BOUND);
                for (k = 0; k < 2; k++)
                    assert_true((double)t.edge_bound[k] == bmax);
                foot(P, v, f);
                dtrue = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
                assert_true(fabs((double)t.distance - dtrue) <= 3 * (double)t.sigma_distance + (double)t.bound_distance);
            }
            free(px);
            foot(P, v, f);
            dtrue = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            if (getenv("CDSP_TEST_VERBOSE"))
                print_message("ambient %.2f p%d: status %d d_err %+.4f sigma %.4f bound %.4f edge bounds %.3f %.3f\n",
                              ambients[a], i + 1, st, st == CDSP_OK ? (double)r.distance - dtrue : 0,
                              (double)r.sigma_distance, (double)r.bound_distance, (double)r.edge_bound[0],
                              (double)r.edge_bound[1]);
            if (a == 1)
                assert_int_equal(st, CDSP_OK);
            if (st != CDSP_OK) {
                assert_int_equal(st, CDSP_E_NO_PIPE);
                continue;
            }
            if (!(r.flags & CDSP_FLAG_BOUND)) {
                /* scattered: no bound claimed, so no error asserted; the
                 * bound fields say "not measured" and the confidence is
                 * capped (lib/frame.c SCATTER_CONF) */
                assert_true(a == 0);
                assert_true((double)r.confidence <= 0.78);
                assert_true(ws.cand[0].confidence == r.confidence); /* cand[0] is the pose */
                assert_true(r.bound_distance == 0 && r.edge_bound[0] == 0 && r.edge_bound[1] == 0);
                for (k = 0; k < 3; k++)
                    assert_true(r.bound_point[k] == 0 && r.bound_direction[k] == 0);
                unbounded++;
                continue;
            }
            sup_result_pose(&r, got, dir, NULL);
            if (!(fabs((double)r.distance - dtrue) <= 3 * (double)r.sigma_distance + (double)r.bound_distance))
                fail_msg("ambient %.2f p%d: distance error %.4f beyond 3 sigma %.4f + bound %.4f", ambients[a], i + 1,
                         (double)r.distance - dtrue, 3 * (double)r.sigma_distance, (double)r.bound_distance);
            for (k = 0; k < 3; k++)
                if (!(fabs(got[k] - f[k]) <= 3 * (double)r.sigma_point[k] + (double)r.bound_point[k]))
                    fail_msg("ambient %.2f p%d: P_C[%d] error %.4f beyond 3 sigma %.4f + bound %.4f", ambients[a],
                             i + 1, k, got[k] - f[k], 3 * (double)r.sigma_point[k], (double)r.bound_point[k]);
            if (a == 1)
                assert_true((double)r.bound_distance <= 0.015 * dtrue);
        }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("scattered (no bound): %d of 4 at ambient 0.4\n", unbounded);
    assert_true(unbounded >= 1); /* the rule is exercised: the checks above are not vacuous */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean_frames),
        cmocka_unit_test(test_clutter_and_caps),
        cmocka_unit_test(test_sigma_step),
        cmocka_unit_test(test_tracking_sequence),
        cmocka_unit_test(test_tracking_fallback),
        cmocka_unit_test(test_16bit),
        cmocka_unit_test(test_detection_cues),
        cmocka_unit_test(test_tracking_newcomers),
        cmocka_unit_test(test_edge_buffer_full),
        cmocka_unit_test(test_busy_frame),
        cmocka_unit_test(test_args),
        cmocka_unit_test(test_huge_band),
        cmocka_unit_test(test_paper_bound),
    };
    return cmocka_run_group_tests_name("frame", tests, NULL, NULL);
}
