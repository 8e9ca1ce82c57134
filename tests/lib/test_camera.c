/*
 * test_camera.c - plumb_bob distortion and its inverse: round trips over
 * the whole frame for a table of lens models, the documented tolerance,
 * non-convergence where the model folds over, gradients carried through
 * undistortion, hostile inputs.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

/* The round trip is bounded by the undistortion tolerance (stated in
 * distorted px) plus the rounding of coordinates ~ 1e3 px. */
#define RT_TOL (2.0 * CDSP_UNDISTORT_TOL_PX + 4096.0 * T_EPS)

typedef struct {
    const char *name;
    double k1, k2, p1, p2, k3;
} lens;

static const lens lenses[] = {
    {"pinhole", 0, 0, 0, 0, 0},
    {"paper-like barrel", -0.12, 0.05, 0, 0, 0},
    {"pincushion", 0.15, -0.02, 0, 0, 0},
    {"full plumb_bob", -0.25, 0.08, 1e-3, -6e-4, -0.01},
    {"strong barrel", -0.35, 0.12, 0, 0, 0},
};

static void cam_for(const lens *L, cdsp_camera *cam)
{
    sup_camera(cam, 1280, 1024, 1100, L->k1, L->k2);
    cam->p1 = (cdsp_real)L->p1;
    cam->p2 = (cdsp_real)L->p2;
    cam->k3 = (cdsp_real)L->k3;
}

static void test_round_trip(void **state)
{
    size_t li;
    (void)state;
    for (li = 0; li < sizeof lenses / sizeof lenses[0]; li++) {
        cdsp_camera cam;
        int x, y;
        cam_for(&lenses[li], &cam);
        assert_int_equal(cdsp_camera_check(&cam), CDSP_OK);
        for (y = 0; y <= 1024; y += 32)
            for (x = 0; x <= 1280; x += 32) {
                cdsp_real d[2] = {(cdsp_real)x, (cdsp_real)y}, u[2], back[2];
                cdsp_status st = cdsp_camera_undistort(&cam, d, u);
                if (st != CDSP_OK)
                    fail_msg("%s: (%d,%d) did not converge", lenses[li].name, x, y);
                assert_int_equal(cdsp_camera_distort(&cam, u, back), CDSP_OK);
                if (fabs((double)(back[0] - d[0])) > RT_TOL || fabs((double)(back[1] - d[1])) > RT_TOL)
                    fail_msg("%s: (%d,%d) -> (%.12g,%.12g)", lenses[li].name, x, y,
                             (double)back[0], (double)back[1]);
            }
    }
}

/* Project a 3D point, then undistort: must equal the pinhole projection. */
static void test_project(void **state)
{
    cdsp_camera cam;
    cdsp_real X[3] = {120, -80, 900}, pix[2], und[2], behind[3] = {1, 1, -5};
    (void)state;
    cam_for(&lenses[3], &cam);
    assert_int_equal(cdsp_camera_project(&cam, X, pix), CDSP_OK);
    assert_int_equal(cdsp_camera_undistort(&cam, pix, und), CDSP_OK);
    assert_true(fabs((double)und[0] - ((double)cam.fx * 120.0 / 900.0 + (double)cam.cx)) < RT_TOL);
    assert_true(fabs((double)und[1] - ((double)cam.fy * -80.0 / 900.0 + (double)cam.cy)) < RT_TOL);
    assert_int_equal(cdsp_camera_project(&cam, behind, pix), CDSP_E_DEGENERATE);
}

/* Barrel distortion r_d = r (1 + k1 r^2) peaks at r = 1/sqrt(-3 k1); a
 * distorted point beyond the peak has no preimage. */
static void test_no_convergence(void **state)
{
    cdsp_camera cam;
    cdsp_real d[2], u[2];
    double rmax;
    (void)state;
    sup_camera(&cam, 1000, 1000, 500, -0.5, 0);
    rmax = (1 / sqrt(1.5)) * (1 - 0.5 / 1.5);
    d[0] = (cdsp_real)((double)cam.cx + 500 * (rmax * 1.2));
    d[1] = cam.cy;
    assert_int_equal(cdsp_camera_undistort(&cam, d, u), CDSP_E_NOCONVERGE);
    d[0] = (cdsp_real)((double)cam.cx + 500 * (rmax * 0.9));
    assert_int_equal(cdsp_camera_undistort(&cam, d, u), CDSP_OK);
}

/* Edge gradients follow the local Jacobian: a straight undistorted line
 * sampled after distortion comes back with normals matching the line. */
static void test_undistort_edges(void **state)
{
    cdsp_camera cam;
    cdsp_edge e[64];
    size_t n = 0, i;
    const double a = 0.8, b = 0.6, c = -700; /* a u + b v + c = 0 */
    (void)state;
    cam_for(&lenses[4], &cam);
    for (i = 0; i < 40; i++) {
        /* a point on the undistorted line, then its distorted position and
         * the distorted curve's normal by finite differences */
        double t = -300 + 15.0 * (double)i, u0 = -a * c + t * -b, v0 = -b * c + t * a, h = 0.5;
        cdsp_real p0[2] = {(cdsp_real)u0, (cdsp_real)v0}, p1[2] = {(cdsp_real)(u0 - h * b), (cdsp_real)(v0 + h * a)};
        cdsp_real d0[2], d1[2];
        double tx, ty, tl;
        assert_int_equal(cdsp_camera_distort(&cam, p0, d0), CDSP_OK);
        assert_int_equal(cdsp_camera_distort(&cam, p1, d1), CDSP_OK);
        tx = (double)(d1[0] - d0[0]);
        ty = (double)(d1[1] - d0[1]);
        tl = sqrt(tx * tx + ty * ty);
        e[n].x = d0[0];
        e[n].y = d0[1];
        e[n].gx = (cdsp_real)(50 * ty / tl); /* normal of the distorted curve, length 50 */
        e[n].gy = (cdsp_real)(-50 * tx / tl);
        n++;
    }
    /* one point that cannot be undistorted is dropped */
    e[n].x = (cdsp_real)1e6;
    e[n].y = (cdsp_real)1e6;
    e[n].gx = 1;
    e[n].gy = 0;
    n++;
    assert_int_equal(cdsp_camera_undistort_edges(&cam, e, &n), CDSP_OK);
    assert_int_equal(n, 40);
    for (i = 0; i < n; i++) {
        double d = a * (double)e[i].x + b * (double)e[i].y + c;
        double gl = sqrt((double)(e[i].gx * e[i].gx + e[i].gy * e[i].gy));
        double cosang = fabs(a * (double)e[i].gx + b * (double)e[i].gy) / gl;
        assert_true(fabs(d) < 4 * RT_TOL);
        assert_true(fabs(gl - 50) < 1e-3);
        /* finite-difference normal over h = 0.5 px: angle error ~ h * curvature / 2 < 1e-4 */
        assert_true(cosang > 1 - 1e-6);
    }
}

static void test_check(void **state)
{
    struct {
        const char *what;
        double fx, fy, k1;
        int w, h;
        cdsp_status want;
    } rows[] = {
        {"good", 1000, 1000, 0, 640, 480, CDSP_OK},
        {"fx 0", 0, 1000, 0, 640, 480, CDSP_E_ARG},
        {"fy < 0", 1000, -5, 0, 640, 480, CDSP_E_ARG},
        {"width 0", 1000, 1000, 0, 0, 480, CDSP_E_ARG},
        {"k1 NaN", 1000, 1000, NAN, 640, 480, CDSP_E_NONFINITE},
        {"fx Inf", INFINITY, 1000, 0, 640, 480, CDSP_E_NONFINITE},
    };
    size_t i;
    cdsp_real p[2] = {1, 2}, q[2], nanp[2] = {0, 0};
    cdsp_camera cam;
    (void)state;
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        sup_camera(&cam, rows[i].w, rows[i].h, 1000, rows[i].k1, 0);
        cam.fx = (cdsp_real)rows[i].fx;
        cam.fy = (cdsp_real)rows[i].fy;
        if (cdsp_camera_check(&cam) != rows[i].want)
            fail_msg("%s", rows[i].what);
    }
    assert_int_equal(cdsp_camera_check(NULL), CDSP_E_ARG);
    sup_camera(&cam, 640, 480, 1000, 0, 0);
    nanp[0] = (cdsp_real)NAN;
    assert_int_equal(cdsp_camera_undistort(&cam, nanp, q), CDSP_E_NONFINITE);
    assert_int_equal(cdsp_camera_distort(&cam, nanp, q), CDSP_E_NONFINITE);
    assert_int_equal(cdsp_camera_undistort(NULL, p, q), CDSP_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_project),
        cmocka_unit_test(test_no_convergence),
        cmocka_unit_test(test_undistort_edges),
        cmocka_unit_test(test_check),
    };
    return cmocka_run_group_tests_name("camera", tests, NULL, NULL);
}
