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
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

/* The round trip is bounded by the undistortion tolerance (stated in
 * distorted px: the Newton iteration stops once the residual is below it,
 * and the last step's residual may be just under it, in either sign, with
 * the distortion's own rounding on top: 2 TOL) plus the rounding of
 * coordinates ~ 1e3 px (4096 eps). Measured (CDSP_TEST_VERBOSE=1) over the
 * 5 lenses x 1353 points: worst 1.0e-9 px of a bound 2.0e-9 (double),
 * 1.1e-3 of 2.5e-3 (float). */
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
    double worst = 0;
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
                worst = fmax(worst, fmax(fabs((double)(back[0] - d[0])), fabs((double)(back[1] - d[1]))));
                if (fabs((double)(back[0] - d[0])) > RT_TOL || fabs((double)(back[1] - d[1])) > RT_TOL)
                    fail_msg("%s: (%d,%d) -> (%.12g,%.12g)", lenses[li].name, x, y,
                             (double)back[0], (double)back[1]);
            }
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("round trip: worst %.3g px (bound %.3g)\n", worst, RT_TOL);
}

/* The distortion is the plumb_bob model (docs/method.md §1), computed here
 * in double, independently of the library: a consistent error in both
 * directions (a wrong k1 in distort and undistort alike) passes the round
 * trip and the projection, not this. Rounding: the model's few products of
 * normalized coordinates times fx ~ 1e3: ~1e3 eps px. Measured worst 0 px
 * in double (the same operations in the same order) and 1.35e-4 px in float
 * (1.1e3 eps); bound 2e3 eps. */
static void test_model(void **state)
{
    size_t li;
    double worst = 0;
    (void)state;
    for (li = 0; li < sizeof lenses / sizeof lenses[0]; li++) {
        const lens *L = &lenses[li];
        cdsp_camera cam;
        int x, y;
        cam_for(L, &cam);
        for (y = 0; y <= 1024; y += 64)
            for (x = 0; x <= 1280; x += 64) {
                cdsp_real u[2] = {(cdsp_real)x, (cdsp_real)y}, d[2];
                double xn = (x - (double)cam.cx) / (double)cam.fx, yn = (y - (double)cam.cy) / (double)cam.fy;
                double r2 = xn * xn + yn * yn, rad = 1 + r2 * (L->k1 + r2 * (L->k2 + r2 * L->k3));
                double xd = xn * rad + 2 * L->p1 * xn * yn + L->p2 * (r2 + 2 * xn * xn);
                double yd = yn * rad + L->p1 * (r2 + 2 * yn * yn) + 2 * L->p2 * xn * yn;
                double ud = (double)cam.fx * xd + (double)cam.cx, vd = (double)cam.fy * yd + (double)cam.cy;
                double e;
                assert_int_equal(cdsp_camera_distort(&cam, u, d), CDSP_OK);
                e = fmax(fabs((double)d[0] - ud), fabs((double)d[1] - vd));
                worst = e > worst ? e : worst;
                if (e > 2e3 * T_EPS)
                    fail_msg("%s: (%d,%d) distorted to (%.9g, %.9g), the model gives (%.9g, %.9g)", L->name,
                             x, y, (double)d[0], (double)d[1], ud, vd);
            }
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("model: worst %.3g px = %.3g eps\n", worst, worst / T_EPS);
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
        cdsp_real p0[2] = {(cdsp_real)u0, (cdsp_real)v0};
        cdsp_real pm[2] = {(cdsp_real)(u0 + h * b), (cdsp_real)(v0 - h * a)};
        cdsp_real p1[2] = {(cdsp_real)(u0 - h * b), (cdsp_real)(v0 + h * a)};
        cdsp_real d0[2], d1[2], dm[2];
        double tx, ty, tl;
        assert_int_equal(cdsp_camera_distort(&cam, p0, d0), CDSP_OK);
        assert_int_equal(cdsp_camera_distort(&cam, p1, d1), CDSP_OK);
        assert_int_equal(cdsp_camera_distort(&cam, pm, dm), CDSP_OK);
        /* central difference: the tangent at d0 to O(h^2) */
        tx = (double)(d1[0] - dm[0]);
        ty = (double)(d1[1] - dm[1]);
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
    {
        double dmax = 0, glmax = 0, angmax = 0;
        for (i = 0; i < n; i++) {
            double d = a * (double)e[i].x + b * (double)e[i].y + c;
            double gl = sqrt((double)(e[i].gx * e[i].gx + e[i].gy * e[i].gy));
            double ang = fabs(a * (double)e[i].gy - b * (double)e[i].gx) / gl;
            dmax = fabs(d) > dmax ? fabs(d) : dmax;
            glmax = fabs(gl - 50) > glmax ? fabs(gl - 50) : glmax;
            angmax = ang > angmax ? ang : angmax;
        }
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("undistort_edges: line %.3g px, |g| - 50 %.3g, angle %.3g rad\n", dmax,
                          glmax, angmax);
        /* the position: Newton stops once the distorted residual is below
         * CDSP_UNDISTORT_TOL_PX, and the undistortion's local scale here is
         * ~1 (|J^-1| <= 1.3 for this lens), plus the coordinates' rounding
         * (~1e3 px x eps): 1.5 TOL + 4096 eps = 1.5e-9 / 2.0e-3 px; measured
         * 4.0e-10 (double), 5.1e-4 (float) */
        assert_true(dmax < 1.5 * CDSP_UNDISTORT_TOL_PX + 4096 * T_EPS);
        /* the length is kept by construction (rescaled to the input's): only
         * the rounding of a norm, a few eps of 50: 4 eps x 50 = 4.4e-14 /
         * 2.4e-5; measured 2.1e-14 (double), 7.3e-6 (float) */
        assert_true(glmax < 4 * T_EPS * 50);
        /* the normal (J^T n) against the central-difference tangent over
         * +-0.5 px: its truncation error h^2/6 |x'''|/|x'| is ~2e-9 rad on this
         * lens (measured 2.1e-9 in double, where rounding is 1e-13), and in
         * float the coordinates' rounding (~1e3 px x eps over the 1 px
         * baseline: ~1e3 eps = 1.2e-4 rad; measured 1.0e-4). Bound: 6e-9 +
         * 2e3 eps = 6.4e-9 (double, 3x) / 2.4e-4 (float, 2.4x) */
        assert_true(angmax < 6e-9 + 2e3 * T_EPS);
    }
}

/* A camera without distortion (every coefficient 0) takes the fast form
 * of cdsp_camera_undistort_edges (lib/camera.c): each edge exactly where
 * cdsp_camera_undistort (Newton, the general form) puts it, bit for bit,
 * with its gradient unchanged, and the points the general form cannot
 * undistort (non-finite, r^2 overflowing) dropped. A table of positions
 * over and far beyond a frame, with non-zero principal points. */
static void test_undistort_edges_no_distortion(void **state)
{
    static const double pos[][2] = {
        {0, 0}, {640, 512}, {639.5, 511.25}, {1279, 1023}, {-3.75, 2000.125}, {1e5, -1e5},
        {1e-300, 7}, {640.0000000001, 512}, {1e160, 0}, {0, -1e160}, {1e200, 1e200},
    };
    cdsp_camera cam;
    cdsp_edge e[32], in[32];
    size_t n = 0, i, k = 0, np = sizeof pos / sizeof pos[0];
    (void)state;
    cam_for(&lenses[0], &cam);
    cam.cx = (cdsp_real)641.3;
    cam.cy = (cdsp_real)509.7;
    cam.fy = (cdsp_real)1093.5;
    for (i = 0; i < np; i++, n++) {
        e[n].x = (cdsp_real)pos[i][0];
        e[n].y = (cdsp_real)pos[i][1];
        e[n].gx = (cdsp_real)(3 + (double)i);
        e[n].gy = (cdsp_real)(-2 * (double)i);
    }
    e[n].x = (cdsp_real)NAN;
    e[n].y = 1;
    e[n].gx = e[n].gy = 1;
    n++;
    e[n].x = 1;
    e[n].y = (cdsp_real)INFINITY;
    e[n].gx = e[n].gy = 1;
    n++;
    memcpy(in, e, sizeof e);
    assert_int_equal(cdsp_camera_undistort_edges(&cam, e, &n), CDSP_OK);
    for (i = 0; i < np + 2; i++) {
        cdsp_real d[2] = {in[i].x, in[i].y}, u[2];
        if (cdsp_camera_undistort(&cam, d, u) != CDSP_OK)
            continue; /* dropped by the general form: by the fast one too */
        assert_true(k < n);
        assert_memory_equal(&e[k].x, &u[0], sizeof u[0]);
        assert_memory_equal(&e[k].y, &u[1], sizeof u[1]);
        assert_memory_equal(&e[k].gx, &in[i].gx, sizeof in[i].gx);
        assert_memory_equal(&e[k].gy, &in[i].gy, sizeof in[i].gy);
        k++;
    }
    assert_int_equal(k, n);
    /* the table holds points of both kinds */
    assert_true(n >= 8 && n < np);
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
        cmocka_unit_test(test_model),
        cmocka_unit_test(test_project),
        cmocka_unit_test(test_no_convergence),
        cmocka_unit_test(test_undistort_edges),
        cmocka_unit_test(test_undistort_edges_no_distortion),
        cmocka_unit_test(test_check),
    };
    return cmocka_run_group_tests_name("camera", tests, NULL, NULL);
}
