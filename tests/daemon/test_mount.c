/*
 * test_mount.c - the camera mount (daemon/mount.c) against its definition
 * in docs/mavlink.md:
 *   - each preset maps the optical axes where the table says (optical Z =
 *     where the camera looks, -Y = where the image's top points), exactly
 *     (quarter turns give exact signed permutations);
 *   - R is a rotation (R^T R = I, det +1) for arbitrary angles, and a pure
 *     yaw, pitch or roll turns the camera the documented way;
 *   - the body-frame pose: the target point on the axis and perpendicular
 *     to it, the direction's sign rule, q a unit quaternion that rotates
 *     body x onto the direction with y level, point_cam = R^T (point - t).
 * Tolerance: these are identities, off only by double rounding: a handful
 * of operations on numbers of size `scale` (1 for unit vectors, ~1e3 for
 * mm), each rounding by DBL_EPSILON / 2 relative; allowed 4 DBL_EPSILON
 * scale (9e-16 for unit vectors). The largest deviation seen is printed:
 * 0.53 DBL_EPSILON scale here, 0.13 of the tolerance.
 */
#define _GNU_SOURCE /* M_PI */
#include <float.h>
#include <stdarg.h>
#include <stdio.h>
#include <stddef.h>
#include <setjmp.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "mount.h"

static double worst; /* largest |got - want| / tolerance */

static void near(double got, double want, double scale)
{
    double tol = 4 * DBL_EPSILON * scale, r = fabs(got - want) / tol;
    if (r > worst)
        worst = r;
    if (r > 1)
        fail_msg("%.17g, expected %.17g (tolerance %.3g)", got, want, tol);
}

static void apply_R(const cdspd_mount *m, const double v[3], double out[3])
{
    int i;
    for (i = 0; i < 3; i++)
        out[i] = m->R[i][0] * v[0] + m->R[i][1] * v[1] + m->R[i][2] * v[2];
}

static void test_presets(void **state)
{
    static const struct {
        const char *name;
        double look[3], top[3];
    } t[] = {
        {"forward", {1, 0, 0}, {0, 0, -1}},
        {"down", {0, 0, 1}, {1, 0, 0}},
        {"down-right", {0, 0, 1}, {0, 1, 0}},
        {"down-aft", {0, 0, 1}, {-1, 0, 0}},
        {"down-left", {0, 0, 1}, {0, -1, 0}},
    };
    static const double z[3] = {0, 0, 1}, minus_y[3] = {0, -1, 0}, zero[3] = {0, 0, 0};
    size_t i;
    int k;
    (void)state;
    for (i = 0; i < sizeof t / sizeof t[0]; i++) {
        double rpy[3], look[3], top[3];
        cdspd_mount m;
        assert_int_equal(cdspd_mount_preset(t[i].name, rpy), 0);
        cdspd_mount_from_euler(&m, rpy, zero);
        apply_R(&m, z, look);
        apply_R(&m, minus_y, top);
        for (k = 0; k < 3; k++) {
            assert_true(look[k] == t[i].look[k]); /* exact */
            assert_true(top[k] == t[i].top[k]);
        }
    }
    {
        double rpy[3];
        assert_int_equal(cdspd_mount_preset("sideways", rpy), -1);
    }
}

static void test_rotation(void **state)
{
    static const double angles[][3] = {{10, -60, 30}, {-170, 85, 200}, {0.5, 0, -0.25}, {33, 44, 55}};
    static const double zero[3] = {0, 0, 0};
    size_t a;
    int i, j, k;
    (void)state;
    for (a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        cdspd_mount m;
        double det;
        cdspd_mount_from_euler(&m, angles[a], zero);
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                double s = 0;
                for (k = 0; k < 3; k++)
                    s += m.R[k][i] * m.R[k][j];
                near(s, i == j, 1);
            }
        det = m.R[0][0] * (m.R[1][1] * m.R[2][2] - m.R[1][2] * m.R[2][1]) -
              m.R[0][1] * (m.R[1][0] * m.R[2][2] - m.R[1][2] * m.R[2][0]) +
              m.R[0][2] * (m.R[1][0] * m.R[2][1] - m.R[1][1] * m.R[2][0]);
        near(det, 1, 1);
    }
    /* yaw +30: the camera looks 30 degrees to the right (body y > 0);
     * pitch +30: up (body z < 0); roll +30: the image's top toward the right */
    {
        static const double yaw[3] = {0, 0, 30}, pitch[3] = {0, 30, 0}, roll[3] = {30, 0, 0};
        static const double z[3] = {0, 0, 1}, minus_y[3] = {0, -1, 0};
        cdspd_mount m;
        double v[3];
        cdspd_mount_from_euler(&m, yaw, zero);
        apply_R(&m, z, v);
        near(v[0], cos(M_PI / 6), 1), near(v[1], 0.5, 1), near(v[2], 0, 1);
        cdspd_mount_from_euler(&m, pitch, zero);
        apply_R(&m, z, v);
        near(v[0], cos(M_PI / 6), 1), near(v[2], -0.5, 1);
        cdspd_mount_from_euler(&m, roll, zero);
        apply_R(&m, minus_y, v);
        near(v[1], 0.5, 1), near(v[2], -cos(M_PI / 6), 1);
    }
}

static void test_body_pose(void **state)
{
    static const double rpy[3] = {10, -60, 30}, t[3] = {5, 0, -40};
    static const double p[][3] = {{30, -70, 480}, {0, 0, 450}, {-200, 10, 900}};
    static const double v[][3] = {{-0.067, 0.987, 0.148}, {0, 0, -1}, {1, 0, 0}};
    cdspd_mount m;
    size_t c;
    int i;
    (void)state;
    cdspd_mount_from_euler(&m, rpy, t);
    for (c = 0; c < sizeof p / sizeof p[0]; c++) {
        cdspd_body_pose b;
        double pb[3], vb[3], dot = 0, nd = 0, off[3], ex[3], w, x, y, zq, len = 0;
        cdspd_mount_apply(&m, p[c], v[c], &b);
        apply_R(&m, p[c], pb);
        apply_R(&m, v[c], vb);
        for (i = 0; i < 3; i++) {
            pb[i] += t[i];
            len += vb[i] * vb[i];
            nd += b.point[i] * b.direction[i];
        }
        len = sqrt(len);
        /* d is +-R v / |R v|, first nonzero component positive */
        for (i = 0; i < 3; i++)
            dot += b.direction[i] * vb[i] / len;
        near(fabs(dot), 1, 1);
        assert_true(b.direction[0] > 0 || (b.direction[0] == 0 && b.direction[1] >= 0));
        /* on the axis (point - pb parallel to d) and nearest the origin */
        near(nd, 0, 1e3);
        for (i = 0; i < 3; i++)
            off[i] = b.point[i] - pb[i];
        near(off[1] * b.direction[2], off[2] * b.direction[1], 1e3);
        near(off[2] * b.direction[0], off[0] * b.direction[2], 1e3);
        /* q unit; it rotates body x onto d; its y axis is level */
        w = b.q[0], x = b.q[1], y = b.q[2], zq = b.q[3];
        near(w * w + x * x + y * y + zq * zq, 1, 1);
        ex[0] = 1 - 2 * (y * y + zq * zq);
        ex[1] = 2 * (x * y + w * zq);
        ex[2] = 2 * (x * zq - w * y);
        for (i = 0; i < 3; i++)
            near(ex[i], b.direction[i], 1);
        near(2 * (y * zq + w * x), 0, 1); /* z of the rotated y axis */
        /* back in the optical frame */
        {
            double back[3];
            apply_R(&m, b.point_cam, back);
            for (i = 0; i < 3; i++)
                near(back[i] + t[i], b.point[i], 1e3);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_presets),
        cmocka_unit_test(test_rotation),
        cmocka_unit_test(test_body_pose),
    };
    int r = cmocka_run_group_tests_name("daemon-mount", tests, NULL, NULL);
    printf("test_mount: largest deviation %.3g of its tolerance\n", worst);
    return r;
}
