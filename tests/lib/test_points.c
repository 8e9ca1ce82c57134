/*
 * test_points.c - edge points -> pipe axis (cdsp_points_solve, cdsp_line_fit):
 * exact points give the exact pose; noisy points give errors consistent with
 * the reported uncertainty (chi-square over many trials); clutter, a second
 * object's straight edges and outliers do not change the answer; hostile
 * inputs return their status.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

static cdsp_points_ws ws;
static cdsp_edge pts[CDSP_MAX_POINTS + 8];

static double vnorm(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* foot of the perpendicular from the origin onto the true axis */
static void true_foot(const double P[3], const double v[3], double f[3])
{
    double n = vnorm(v), t = (P[0] * v[0] + P[1] * v[1] + P[2] * v[2]) / (n * n);
    int i;
    for (i = 0; i < 3; i++)
        f[i] = P[i] - t * v[i];
}

static void test_line_fit(void **state)
{
    cdsp_edge e[100];
    cdsp_line ln;
    uint32_t idx[3] = {10, 50, 90};
    int i;
    (void)state;
    /* exact points on 3u - 4v + 500 = 0 (normalized: 0.6u - 0.8v + 100 = 0),
     * gradients toward +(0.6, -0.8) */
    for (i = 0; i < 100; i++) {
        double v = 10.0 * i, u = (4 * v - 500) / 3;
        e[i].x = (cdsp_real)u;
        e[i].y = (cdsp_real)v;
        e[i].gx = (cdsp_real)6;
        e[i].gy = (cdsp_real)-8;
    }
    assert_int_equal(cdsp_line_fit(e, NULL, 100, &ln), CDSP_OK);
    /* exact points, so what is left is rounding: the unit normal of a 2 x 2
     * eigenproblem a few eps (measured 1 eps double, 0.7 float: bound 3);
     * the offset c = -(a, b) . centroid, eps of the ~1e3 px coordinates
     * (measured 1.0e3 / 2.6e2 eps: bound 4e3); the residual of exact points
     * likewise eps x ~1e3 px (measured 7.9e2 / 3.1e2 eps: bound 2.5e3); the
     * extent 1650 px to eps (measured 0 / 1.0e3 eps: bound 4e3); the mean
     * gradient of identical integer gradients, sqrt(100) = 10, exactly
     * (measured 0: bound a sqrt's 4 eps x 10). They were 1e3, 1e6, 1e4,
     * 1e5 and 1e3 eps. */
    assert_true(fabs((double)ln.l[0] - 0.6) < 3 * T_EPS);
    assert_true(fabs((double)ln.l[1] + 0.8) < 3 * T_EPS);
    assert_true(fabs((double)ln.l[2] - 100) < 4e3 * T_EPS);
    assert_true((double)ln.rms < 2.5e3 * T_EPS);
    assert_int_equal(ln.count, 100);
    assert_true(fabs((double)(ln.t_max - ln.t_min) - 990 * 5.0 / 3) < 4e3 * T_EPS);
    assert_true(fabs((double)ln.strength - 10) <= 40 * T_EPS);
    assert_int_equal(cdsp_line_fit(e, idx, 3, &ln), CDSP_OK);
    assert_int_equal(ln.count, 3);
    /* flipped gradients flip the orientation */
    for (i = 0; i < 100; i++) {
        e[i].gx = -e[i].gx;
        e[i].gy = -e[i].gy;
    }
    assert_int_equal(cdsp_line_fit(e, NULL, 100, &ln), CDSP_OK);
    assert_true(fabs((double)ln.l[0] + 0.6) < 3 * T_EPS);
    /* degenerate sets */
    assert_int_equal(cdsp_line_fit(e, NULL, 1, &ln), CDSP_E_FEW_POINTS);
    e[1] = e[0];
    assert_int_equal(cdsp_line_fit(e, NULL, 2, &ln), CDSP_E_DEGENERATE);
    e[0].x = (cdsp_real)NAN;
    assert_int_equal(cdsp_line_fit(e, NULL, 2, &ln), CDSP_E_NONFINITE);
}

/* Noise-free points on both contours: the pose to the closed form's own
 * precision, scaled by the line fit's conditioning (coordinates ~1e3 px). */
static void test_exact_points(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, sampler;
    int t;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    cdsp_rng_seed(&sampler, 2, 2);
    for (t = 0; t < 100; t++) {
        double P[3], v[3], f[3], got[3], dir[3], err[3];
        cdsp_result r;
        size_t n;
        int i;
        sup_random_pipe(&sampler, 150, 1500, P, v);
        n = sup_contour_points(&cam, P, v, 8, -100, 100, 400, 0, 100, &sampler, pts, CDSP_MAX_POINTS, NULL);
        if (n < 600)
            continue; /* mostly outside the view */
        assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        true_foot(P, v, f);
        sup_result_pose(&r, got, dir, NULL);
        for (i = 0; i < 3; i++)
            err[i] = got[i] - f[i];
        {
            /* the points (~1e3 px) carry a rounding of eps relative; the
             * fit's normal and the plane normals K^T l keep that, a few eps,
             * and the closed form divides it by alpha (n1 x n2, |n1 - n2|
             * ~ alpha): c eps / alpha with c ~ 10 from the moments' sums.
             * Measured over the 100 poses: worst 13.3 (P_C) and 11.5
             * (angle) eps/alpha in double, 13.9 and 12.6 in float; bound
             * 40 eps / alpha (it was 3e3: 3.2 % in float at alpha 0.011). */
            double tol = 40 * T_EPS / (double)r.alpha;
            if (vnorm(err) > tol * vnorm(f))
                fail_msg("trial %d: P_C off by %.3g (rel %.3g > %.3g)", t, vnorm(err),
                         vnorm(err) / vnorm(f), tol);
            assert_true(sup_axis_angle(dir, v) < tol);
        }
        assert_true(r.inliers[0] + r.inliers[1] == n);
    }
}

/* Noise 0.1 px on 1000 points per contour over the visible part of the
 * paper's pipes: the paper's figure, 0.013 mm at one point per pixel of
 * contour (whether the reported uncertainty matches the errors is
 * test_covariance.c's Mahalanobis test: the per-axis chi-square band this
 * test had assumed x, y, z independent, which they are not): the RMSE falls as 1/sqrt(points), so ours is scaled by
 * sqrt(1000 / visible px) before the comparison (CDSP_MAX_POINTS = 2048
 * holds 1024 per contour, fewer than the ~2000-2900 px the contours span). */
static void test_noise_calibrated(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, noise;
    double rmse_sum = 0, rmse_sq = 0, mean, se;
    int t, pipe;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 3, 3);
    cdsp_rng_seed(&noise, 4, 4);
    for (pipe = 0; pipe < 4; pipe++)
        for (t = 0; t < 15; t++) {
            double P[3], v[3], got[3], dir[3], seg[2][3], s0, s1, vis[2];
            cdsp_result r;
            size_t n;
            sup_paper_pipe(pipe, P, v);
            /* the 500 mm pipe, centred on its world point; the frame clips it */
            s0 = -250;
            s1 = 250;
            n = sup_contour_points(&cam, P, v, 8, s0, s1, 1000, 0.1, 100, &noise, pts,
                                   CDSP_MAX_POINTS, vis);
            assert_int_equal(n, 2000);
            assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
            sup_result_pose(&r, got, dir, seg);
            {
                double e = sup_axis_rmse(seg[0], seg[1], P, v, 100) *
                           sqrt(1000.0 / ((vis[0] + vis[1]) / 2));
                rmse_sum += e;
                rmse_sq += e * e;
            }
        }
    /* mean (scaled) RMSE of 60 trials against the paper's 0.013 mm, allowing
     * two standard errors of the mean (the float build draws other noise) */
    mean = rmse_sum / 60;
    se = sqrt((rmse_sq / 60 - mean * mean) / 59);
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("mean RMSE %.4f +- %.4f mm\n", mean, se);
    if (mean - 2 * se > 0.013)
        fail_msg("mean RMSE %.4f +- %.4f mm > the paper's 0.013 mm", mean, se);
}

/* Outliers, a second straight object and random short segments: the pipe
 * still wins. The clutter: 40 % uniform random points with random gradients,
 * and a "support column" crossing behind the pipe (two parallel edges with
 * opposite polarity, shorter than the pipe's contours). */
static void test_clutter(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, gen;
    int t;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 5, 5);
    cdsp_rng_seed(&gen, 6, 6);
    for (t = 0; t < 30; t++) {
        double P[3], v[3], f[3], got[3], dir[3];
        cdsp_result r;
        size_t n, m, i;
        sup_paper_pipe(t % 4, P, v);
        n = sup_contour_points(&cam, P, v, 8, -250, 250, 500, 0.1, 100, &gen, pts, CDSP_MAX_POINTS, NULL);
        /* the column: vertical edges at u = 300 and 340, v in [700, 1300] */
        for (m = 0; m < 150; m++) {
            double vv = 700 + 4.0 * (double)m;
            pts[n].x = (cdsp_real)300;
            pts[n].y = (cdsp_real)vv;
            pts[n].gx = (cdsp_real)80;
            pts[n].gy = 0;
            pts[n + 1].x = (cdsp_real)340;
            pts[n + 1].y = (cdsp_real)vv;
            pts[n + 1].gx = (cdsp_real)-80;
            pts[n + 1].gy = 0;
            n += 2;
        }
        for (i = 0; i < 500 && n < CDSP_MAX_POINTS; i++, n++) {
            double a = 2 * SUP_PI * (double)cdsp_rng_uniform(&gen);
            pts[n].x = (cdsp_real)(2448 * (double)cdsp_rng_uniform(&gen));
            pts[n].y = (cdsp_real)(2048 * (double)cdsp_rng_uniform(&gen));
            pts[n].gx = (cdsp_real)(50 * cos(a));
            pts[n].gy = (cdsp_real)(50 * sin(a));
        }
        assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        true_foot(P, v, f);
        sup_result_pose(&r, got, dir, NULL);
        for (i = 0; i < 3; i++) {
            /* Gaussian errors of the reported sigma (test_covariance.c):
             * |z| > 5 has probability 5.7e-7 per check, 90 checks; measured
             * worst 1.9 sigma (double), 2.8 (float); it allowed 6 */
            if (fabs(got[i] - f[i]) > 5 * (double)r.sigma_point[i])
                fail_msg("trial %d axis %zu: error %.4f > 5 sigma (%.4f)", t, i, fabs(got[i] - f[i]),
                         (double)r.sigma_point[i]);
        }
        assert_true(r.inliers[0] >= 480 && r.inliers[1] >= 480);
    }
}

/* A halo beside each contour (a shadow or a chamfer's edge: 1.5-2.5 px
 * outside the silhouette, same gradient, ~30 % as many points): RANSAC's
 * threshold (inlier_px = 1) and the refinement's re-selection of inliers
 * about the fitted line keep it out, so the pose stays within the noise's
 * uncertainty. Included, it would move each contour by ~0.4 x 2 px = 0.8 px
 * outward, hundreds of sigma (sigma_offset ~ 0.004 px). Bound: every
 * coordinate of P_C within 5 sigma (a normal's |z| over 60 draws exceeds 5
 * with probability 3e-5; measured worst 2.97 sigma double, 3.06 float). */
static void test_halo(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, gen;
    double worst = 0;
    int t;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 15, 5);
    cdsp_rng_seed(&gen, 16, 6);
    for (t = 0; t < 20; t++) {
        double P[3], v[3], f[3], got[3], dir[3], l[2][3], pin[2];
        cdsp_result r;
        size_t n, m, i;
        sup_paper_pipe(t % 4, P, v);
        n = sup_contour_points(&cam, P, v, 8, -250, 250, 700, 0.1, 100, &gen, pts, CDSP_MAX_POINTS, NULL);
        assert_true(sup_contour_lines(&cam, P, v, 8, l, pin));
        /* the halo: every 5th point copied 1.5-2.5 px away from the pipe
         * (l's normal points into it), every other copy twice (1 px apart
         * along v) */
        for (i = 0, m = n; i < n && m < CDSP_MAX_POINTS; i += 5) {
            int k = fabs(l[0][0] * (double)pts[i].x + l[0][1] * (double)pts[i].y + l[0][2]) <
                            fabs(l[1][0] * (double)pts[i].x + l[1][1] * (double)pts[i].y + l[1][2])
                        ? 0 : 1;
            double off = 1.5 + (double)cdsp_rng_uniform(&gen);
            pts[m] = pts[i];
            pts[m].x = (cdsp_real)((double)pts[i].x - off * l[k][0]);
            pts[m].y = (cdsp_real)((double)pts[i].y - off * l[k][1]);
            m++;
            if (i % 2 == 0 && m < CDSP_MAX_POINTS) {
                pts[m] = pts[m - 1];
                pts[m].y = (cdsp_real)((double)pts[m].y + 1.0);
                m++;
            }
        }
        assert_int_equal(cdsp_points_solve(&cam, 8, pts, m, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        true_foot(P, v, f);
        sup_result_pose(&r, got, dir, NULL);
        for (i = 0; i < 3; i++) {
            double z = fabs(got[i] - f[i]) / (double)r.sigma_point[i];
            worst = z > worst ? z : worst;
            if (z > 5)
                fail_msg("trial %d axis %zu: error %.4f = %.1f sigma (halo let in?)", t, i,
                         fabs(got[i] - f[i]), z);
        }
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("halo: worst %.2f sigma\n", worst);
}

/* The same seed gives the same answer; the prior sets the direction's sign. */
static void test_reproducible_and_prior(void **state)
{
    cdsp_camera cam;
    cdsp_params prm, strict;
    cdsp_rng a, b, c, gen;
    cdsp_result ra, rb, rc, rd, prior;
    double P[3], v[3];
    size_t n;
    (void)state;
    /* the workspace the library was built with is the one compiled here */
    assert_true(cdsp_points_ws_size() == sizeof(cdsp_points_ws));
    assert_true(cdsp_frame_ws_size() == sizeof(cdsp_frame_ws));
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&gen, 9, 9);
    sup_paper_pipe(2, P, v);
    n = sup_contour_points(&cam, P, v, 8, -200, 200, 500, 0.2, 100, &gen, pts, CDSP_MAX_POINTS, NULL);
    cdsp_rng_seed(&a, 77, 1);
    cdsp_rng_seed(&b, 77, 1);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &a, &ra), CDSP_OK);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &b, &rb), CDSP_OK);
    assert_memory_equal(&ra, &rb, sizeof ra);
    prior = ra;
    prior.direction[0] = -ra.direction[0];
    prior.direction[1] = -ra.direction[1];
    prior.direction[2] = -ra.direction[2];
    c = a;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, &prior, &ws, &a, &rb), CDSP_OK);
    assert_true((double)(rb.direction[0] * ra.direction[0] + rb.direction[1] * ra.direction[1] +
                         rb.direction[2] * ra.direction[2]) < -0.999);
    /* the pose is built in out itself (lib/pair.c, cdsp__pair_pose): with
     * out the prior itself, the same bytes as with two objects */
    rc = prior;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, &rc, &ws, &c, &rc), CDSP_OK);
    assert_memory_equal(&rc, &rb, sizeof rc);
    /* and out is written only on success: a pose refused for its confidence
     * (min_confidence 1 above this one's) leaves every byte of out as it was */
    assert_true(ra.confidence < (cdsp_real)1);
    strict = prm;
    strict.min_confidence = (cdsp_real)1;
    memset(&rc, 0x5a, sizeof rc);
    rd = rc;
    cdsp_rng_seed(&c, 77, 1);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &strict, NULL, &ws, &c, &rc), CDSP_E_NO_PIPE);
    assert_memory_equal(&rc, &rd, sizeof rc);
    /* swapping the contours keeps n1.P = r, n2.P = -r */
    {
        double n1p = 0, n2p = 0;
        int i;
        for (i = 0; i < 3; i++) {
            n1p += (double)(rb.normals[0][i] * rb.point[i]);
            n2p += (double)(rb.normals[1][i] * rb.point[i]);
        }
        /* unit normals and P_C to eps each, a dot of three products: ~eps
         * |P| (measured 0.29 eps |P| double, 0.12 float; it allowed 1e-3) */
        double tol = T_EPS * (double)rb.distance;
        assert_true(fabs(n1p - 8) < tol && fabs(n2p + 8) < tol);
    }
}

static void two_lines(cdsp_edge *e, size_t per, double u1, double u2, double g1, double g2,
                      double slope2)
{
    size_t i;
    for (i = 0; i < per; i++) {
        double v = 100 + 4.0 * (double)i;
        e[2 * i].x = (cdsp_real)u1;
        e[2 * i].y = (cdsp_real)v;
        e[2 * i].gx = (cdsp_real)g1;
        e[2 * i].gy = 0;
        e[2 * i + 1].x = (cdsp_real)(u2 + slope2 * (v - 500));
        e[2 * i + 1].y = (cdsp_real)v;
        e[2 * i + 1].gx = (cdsp_real)g2;
        e[2 * i + 1].gy = (cdsp_real)(-g2 * slope2);
    }
}

/* Table: point sets that are not a pipe, and arguments that are not valid. */
static void test_not_a_pipe(void **state)
{
    cdsp_camera cam;
    cdsp_params prm, bad;
    cdsp_rng rng;
    cdsp_result r;
    static const struct {
        const char *what;
        double u1, u2, g1, g2, slope2;
        size_t per;
        cdsp_status want;
    } rows[] = {
        {"a pipe: stripe, opposite gradients", 1000, 1100, 60, -60, 0, 200, CDSP_OK},
        {"dark pipe: gradients point out", 1000, 1100, -60, 60, 0, 200, CDSP_OK},
        {"staircase: same gradients", 1000, 1100, 60, 60, 0, 200, CDSP_E_NO_PIPE},
        {"X: lines cross in the middle", 1000, 1000, 60, -60, 0.5, 200, CDSP_E_NO_PIPE},
        {"two contours 1 px apart", 1000, 1001, 60, -60, 0, 200, CDSP_E_NO_PIPE},
        /* the band must be as wide as the edge window, 2 half_window + 1 = 9 px */
        {"band 8.5 px: narrower than the edge window", 1000, 1008.5, 60, -60, 0, 200, CDSP_E_NO_PIPE},
        {"band 9.5 px: as wide as the edge window", 1000, 1009.5, 60, -60, 0, 200, CDSP_OK},
        {"too few points", 1000, 1100, 60, -60, 0, 1, CDSP_E_FEW_POINTS},
    };
    size_t i;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        cdsp_status st;
        two_lines(pts, rows[i].per, rows[i].u1, rows[i].u2, rows[i].g1, rows[i].g2, rows[i].slope2);
        st = cdsp_points_solve(&cam, 8, pts, 2 * rows[i].per, &prm, NULL, &ws, &rng, &r);
        if (st != rows[i].want)
            fail_msg("%s: got %s, want %s", rows[i].what, cdsp_strerror(st), cdsp_strerror(rows[i].want));
    }
    /* polarity and distance constraints */
    two_lines(pts, 200, 1000, 1100, 60, -60, 0);
    prm.pair.polarity = -1;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_NO_PIPE);
    prm.pair.polarity = 1;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    prm.pair.max_distance = r.distance / 2;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_NO_PIPE);
    cdsp_params_default(&prm);
    /* arguments */
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, CDSP_MAX_POINTS + 1, &prm, NULL, &ws, &rng, &r),
                     CDSP_E_CAPACITY);
    assert_int_equal(cdsp_points_solve(&cam, 0, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_points_solve(&cam, (cdsp_real)NAN, pts, 400, &prm, NULL, &ws, &rng, &r),
                     CDSP_E_NONFINITE);
    assert_int_equal(cdsp_points_solve(NULL, 8, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_points_solve(&cam, 8, NULL, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 0, &prm, NULL, &ws, &rng, &r), CDSP_E_FEW_POINTS);
    bad = prm;
    bad.pair.max_lines = 1;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &bad, NULL, &ws, &rng, &r), CDSP_E_ARG);
    bad = prm;
    bad.pair.confidence = 1;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &bad, NULL, &ws, &rng, &r), CDSP_E_ARG);
    bad = prm;
    bad.pair.inlier_px = (cdsp_real)NAN;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &bad, NULL, &ws, &rng, &r), CDSP_E_ARG);
    pts[7].y = (cdsp_real)INFINITY;
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, 400, &prm, NULL, &ws, &rng, &r), CDSP_E_NONFINITE);
}

/* Issue 16: the radius has a documented bound (CDSP_MAX_RADIUS). At the
 * bound the same image (the geometry scaled by s = r / 8) solves with a finite
 * uncertainty; far beyond it (1e256 used to return CDSP_OK with infinite
 * sigma) it is refused. */
static void test_radius_bound(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, sampler;
    cdsp_result r;
    double P[3] = {10, -20, 400}, v[3] = {0.2, 1, 0.1}, s = CDSP_MAX_RADIUS / 8.0;
    double d8;
    size_t n;
    int i;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&sampler, 3, 1);
    n = sup_contour_points(&cam, P, v, 8, -100, 100, 400, 0.1, 100, &sampler, pts, CDSP_MAX_POINTS,
                           NULL);
    assert_true(n > 600);
    cdsp_rng_seed(&rng, 1, 1);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    d8 = (double)r.distance;
    cdsp_rng_seed(&rng, 1, 1);
    assert_int_equal(cdsp_points_solve(&cam, (cdsp_real)CDSP_MAX_RADIUS, pts, n, &prm, NULL, &ws,
                                       &rng, &r), CDSP_OK);
    for (i = 0; i < 3; i++) {
        assert_true(isfinite((double)r.sigma_point[i]) && isfinite((double)r.sigma_direction[i]));
        assert_true(isfinite((double)r.point[i]));
    }
    assert_true(isfinite((double)r.sigma_distance));
    /* the same points and RANSAC draws: the closed form is linear in r, so
     * the distance scales exactly but for rounding (measured 0 to 2e-16
     * relative in double, 0.1 eps in float; bound 8 eps: a few roundings
     * of the scale; it was 1e3 eps) */
    assert_true(fabs((double)r.distance / s - d8) < T_EPS * 8 * d8);
    assert_int_equal(cdsp_points_solve(&cam, (cdsp_real)(2 * CDSP_MAX_RADIUS), pts, n, &prm, NULL,
                                       &ws, &rng, &r), CDSP_E_ARG);
#ifndef CDSP_SINGLE
    assert_int_equal(cdsp_points_solve(&cam, 1e256, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
#endif
    {
        cdsp_real l1[3], l2[3], pin[2];
        cdsp_real Pr[3] = {(cdsp_real)P[0], (cdsp_real)P[1], (cdsp_real)P[2]};
        cdsp_real vr[3] = {(cdsp_real)v[0], (cdsp_real)v[1], (cdsp_real)v[2]};
        assert_int_equal(cdsp_cylinder_contours(&cam, Pr, vr, 8, 1, l1, l2, pin), CDSP_OK);
        assert_int_equal(cdsp_axis_solve(&cam, l1, l2, pin, (cdsp_real)CDSP_MAX_RADIUS, &r), CDSP_OK);
        assert_true(isfinite((double)r.distance));
        assert_int_equal(cdsp_axis_solve(&cam, l1, l2, pin, (cdsp_real)(2 * CDSP_MAX_RADIUS), &r),
                         CDSP_E_ARG);
    }
    /* the parameter check callers run before any frame */
    assert_int_equal(cdsp_params_check(&prm), CDSP_OK);
    assert_int_equal(cdsp_params_check(NULL), CDSP_E_ARG);
    prm.edge.min_contrast = 1;
    assert_int_equal(cdsp_params_check(&prm), CDSP_E_ARG);
    prm.edge.min_contrast = 0;
    assert_int_equal(cdsp_params_check(&prm), CDSP_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_line_fit),
        cmocka_unit_test(test_exact_points),
        cmocka_unit_test(test_noise_calibrated),
        cmocka_unit_test(test_clutter),
        cmocka_unit_test(test_halo),
        cmocka_unit_test(test_reproducible_and_prior),
        cmocka_unit_test(test_not_a_pipe),
        cmocka_unit_test(test_radius_bound),
    };
    return cmocka_run_group_tests_name("points", tests, NULL, NULL);
}
