/*
 * test_axis.c - the closed form (cdsp_axis_solve): exact contour lines of
 * known pipes in, the pose back to working precision; sign rules; the
 * degenerate cases returning their status.
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

/* Error bound of the closed form: the pose comes from n1 x n2 and
 * |n1 - n2| = 2 sin(alpha/2), so relative errors are ~ eps / alpha
 * (cancellation between two nearly parallel unit normals, each rounded to
 * ~eps), with a constant for the handful of roundings on the way: 5.
 * Measured over the 504 poses of this file (CDSP_TEST_VERBOSE=1): worst
 * 1.58 eps/alpha (P_C), 1.33 (distance), 1.51 (direction) in double, 1.02,
 * 0.64, 1.02 in float. (It was 200 eps/alpha, and never below 1e-9 in
 * double: the figure, 1e6 times what the closed form does.) */
static double rel_tol(double alpha)
{
    return 5.0 * T_EPS / alpha;
}

static void solve_known(const cdsp_camera *cam, const double P[3], const double v[3], double r)
{
    double l[2][3], pin[2], foot[3], vv[3] = {v[0], v[1], v[2]}, t, n, d, got[3], dir[3];
    cdsp_real l1[3], l2[3], pr[2];
    cdsp_result res;
    int i;
    assert_true(sup_contour_lines(cam, P, v, r, l, pin));
    for (i = 0; i < 3; i++) {
        l1[i] = (cdsp_real)l[0][i];
        l2[i] = (cdsp_real)l[1][i];
    }
    pr[0] = (cdsp_real)pin[0];
    pr[1] = (cdsp_real)pin[1];
    assert_int_equal(cdsp_axis_solve(cam, l1, l2, pr, (cdsp_real)r, &res), CDSP_OK);
    n = sqrt(vv[0] * vv[0] + vv[1] * vv[1] + vv[2] * vv[2]);
    for (i = 0; i < 3; i++)
        vv[i] /= n;
    t = P[0] * vv[0] + P[1] * vv[1] + P[2] * vv[2];
    for (i = 0; i < 3; i++)
        foot[i] = P[i] - t * vv[i];
    d = sqrt(foot[0] * foot[0] + foot[1] * foot[1] + foot[2] * foot[2]);
    sup_result_pose(&res, got, dir, NULL);
    {
        double tol = rel_tol((double)res.alpha), err = 0;
        for (i = 0; i < 3; i++)
            err += (got[i] - foot[i]) * (got[i] - foot[i]);
        err = sqrt(err);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("axis: P_C %.3g dist %.3g dir %.3g eps/alpha\n", err / d / (T_EPS / (double)res.alpha),
                          fabs((double)res.distance - d) / d / (T_EPS / (double)res.alpha),
                          sup_axis_angle(dir, vv) / (T_EPS / (double)res.alpha));
        if (err > tol * d)
            fail_msg("P_C off by %.3g (d = %.6g, rel %.3g > tol %.3g)", err, d, err / d, tol);
        if (fabs((double)res.distance - d) > tol * d)
            fail_msg("distance %.17g vs %.17g", (double)res.distance, d);
        if (sup_axis_angle(dir, vv) > tol)
            fail_msg("direction off by %.3g rad > %.3g", sup_axis_angle(dir, vv), tol);
        /* sign rules of docs/method.md §5: n1.P = +r, n2.P = -r, v = n1 x n2 */
        {
            double n1p = 0, n2p = 0;
            for (i = 0; i < 3; i++) {
                n1p += (double)res.normals[0][i] * got[i];
                n2p += (double)res.normals[1][i] * got[i];
            }
            assert_true(fabs(n1p - r) <= tol * d);
            assert_true(fabs(n2p + r) <= tol * d);
        }
        {
            const cdsp_real *a = res.normals[0], *b = res.normals[1];
            double c0 = (double)(a[1] * b[2] - a[2] * b[1]), c1 = (double)(a[2] * b[0] - a[0] * b[2]),
                   c2 = (double)(a[0] * b[1] - a[1] * b[0]), cn = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
            assert_true(fabs(c0 / cn - dir[0]) + fabs(c1 / cn - dir[1]) + fabs(c2 / cn - dir[2]) <
                        10 * tol);
        }
        /* direction sign: largest component positive */
        {
            int k = 0;
            for (i = 1; i < 3; i++)
                if (fabs(dir[i]) > fabs(dir[k]))
                    k = i;
            assert_true(dir[k] > 0);
        }
    }
    /* the same pose whichever line comes first */
    {
        cdsp_result sw;
        assert_int_equal(cdsp_axis_solve(cam, l2, l1, pr, (cdsp_real)r, &sw), CDSP_OK);
        for (i = 0; i < 3; i++) {
            assert_true(fabs((double)(sw.point[i] - res.point[i])) <= rel_tol((double)res.alpha) * d);
            assert_true(fabs((double)(sw.direction[i] - res.direction[i])) <= rel_tol((double)res.alpha));
        }
    }
}

static void test_random_poses(void **state)
{
    cdsp_camera cam;
    cdsp_rng rng;
    int i;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_rng_seed(&rng, 1234, 1);
    for (i = 0; i < 500; i++) {
        double P[3], v[3], r = 1 + 20 * (double)cdsp_rng_uniform(&rng);
        sup_random_pipe(&rng, 100, 5000, P, v);
        solve_known(&cam, P, v, r);
    }
}

static void test_paper_pipes(void **state)
{
    cdsp_camera cam;
    int i;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    for (i = 0; i < 4; i++) {
        double P[3], v[3];
        sup_paper_pipe(i, P, v);
        solve_known(&cam, P, v, 8.0);
    }
}

/* Table of hostile inputs and the status each must give. */
static void test_degenerate(void **state)
{
    cdsp_camera cam;
    cdsp_result res;
    const cdsp_real good1[3] = {1, 0, -1000}, good2[3] = {-1, 0, 1400};
    const cdsp_real pin[2] = {1200, 1000}, pin_on_line[2] = {1000, 500};
    const cdsp_real far1[3] = {1, 0, 1e7}, far2[3] = {-1, 0, 1e7};
    const cdsp_real zero[3] = {0, 0, 0};
    cdsp_real nanl[3] = {1, 0, 0};
    struct {
        const char *what;
        const cdsp_real *l1, *l2, *p;
        double r;
        cdsp_status want;
    } rows[] = {
        {"ok", good1, good2, pin, 8, CDSP_OK},
        {"same line twice (parallel planes)", good1, good1, pin, 8, CDSP_E_DEGENERATE},
        {"p_in on a contour", good1, good2, pin_on_line, 8, CDSP_E_DEGENERATE},
        {"lines a world apart: camera inside the pipe", far1, far2, pin, 8, CDSP_E_DEGENERATE},
        {"zero line", zero, good2, pin, 8, CDSP_E_DEGENERATE},
        {"NaN line", nanl, good2, pin, 8, CDSP_E_NONFINITE},
        {"radius 0", good1, good2, pin, 0, CDSP_E_ARG},
        {"radius < 0", good1, good2, pin, -1, CDSP_E_ARG},
        {"radius NaN", good1, good2, pin, NAN, CDSP_E_NONFINITE},
    };
    size_t i;
    (void)state;
    nanl[2] = (cdsp_real)NAN;
    sup_paper_camera(&cam, 0, 0);
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        cdsp_status st = cdsp_axis_solve(&cam, rows[i].l1, rows[i].l2, rows[i].p,
                                         (cdsp_real)rows[i].r, &res);
        if (st != rows[i].want)
            fail_msg("%s: got %s, want %s", rows[i].what, cdsp_strerror(st),
                     cdsp_strerror(rows[i].want));
    }
    assert_int_equal(cdsp_axis_solve(NULL, good1, good2, pin, 8, &res), CDSP_E_ARG);
    assert_int_equal(cdsp_axis_solve(&cam, good1, good2, pin, 8, NULL), CDSP_E_ARG);
    cam.fx = 0;
    assert_int_equal(cdsp_axis_solve(&cam, good1, good2, pin, 8, &res), CDSP_E_ARG);
    cam.fx = (cdsp_real)NAN;
    assert_int_equal(cdsp_axis_solve(&cam, good1, good2, pin, 8, &res), CDSP_E_NONFINITE);
}

static void test_point_distance(void **state)
{
    cdsp_result r;
    cdsp_real X[3] = {3, 4, 100};
    (void)state;
    memset(&r, 0, sizeof r);
    r.point[2] = 100;
    r.direction[2] = 1;
    /* small integers: the cross product is exact and sqrt(25) correctly
     * rounded, so 5 to the last bit (measured 0; bound a sqrt's 4 eps) */
    assert_true(fabs((double)cdsp_result_point_distance(&r, X) - 5.0) <= 4 * T_EPS * 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_poses),
        cmocka_unit_test(test_paper_pipes),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_point_distance),
    };
    return cmocka_run_group_tests_name("axis", tests, NULL, NULL);
}
