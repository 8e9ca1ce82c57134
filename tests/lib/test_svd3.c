/*
 * test_svd3.c - cdsp_svd3 against known decompositions: A = U S V^T is
 * rebuilt, U and V are orthogonal with det V = +1, S descending; matrices
 * built from chosen rotations and singular values come back with those
 * singular values.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>
#include "support.h"

/* Backward error of one-sided Jacobi: |A - U S V^T| <= c eps |A| (Demmel &
 * Veselic); c = 50 covers the few dozen rotations of a 3x3. */
#define SVD_TOL(normA) (50.0 * T_EPS * (normA))

static void rot(double ax, double ay, double az, double Rm[9])
{
    double cx = cos(ax), sx = sin(ax), cy = cos(ay), sy = sin(ay), cz = cos(az), sz = sin(az);
    Rm[0] = cy * cz;
    Rm[1] = -cy * sz;
    Rm[2] = sy;
    Rm[3] = sx * sy * cz + cx * sz;
    Rm[4] = -sx * sy * sz + cx * cz;
    Rm[5] = -sx * cy;
    Rm[6] = -cx * sy * cz + sx * sz;
    Rm[7] = cx * sy * sz + sx * cz;
    Rm[8] = cx * cy;
}

static void check_svd(const double A[9], const double *want_s)
{
    cdsp_real a[9], U[9], S[3], V[9];
    double normA = 0, err = 0;
    int i, j, k;
    for (i = 0; i < 9; i++) {
        a[i] = (cdsp_real)A[i];
        normA += A[i] * A[i];
    }
    normA = sqrt(normA);
    assert_int_equal(cdsp_svd3(a, U, S, V), CDSP_OK);
    assert_true(S[0] >= S[1] && S[1] >= S[2] && S[2] >= 0);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            double us = 0, uu = 0, vv = 0;
            for (k = 0; k < 3; k++) {
                us += (double)U[i * 3 + k] * (double)S[k] * (double)V[j * 3 + k];
                uu += (double)U[k * 3 + i] * (double)U[k * 3 + j];
                vv += (double)V[k * 3 + i] * (double)V[k * 3 + j];
            }
            err += (us - (double)a[i * 3 + j]) * (us - (double)a[i * 3 + j]);
            assert_true(fabs(uu - (i == j)) < 100 * T_EPS);
            assert_true(fabs(vv - (i == j)) < 100 * T_EPS);
        }
    if (sqrt(err) > SVD_TOL(normA) + 1e-300)
        fail_msg("|A - USV'| = %.3g > %.3g", sqrt(err), SVD_TOL(normA));
    {
        double det = (double)(V[0] * (V[4] * V[8] - V[5] * V[7]) - V[1] * (V[3] * V[8] - V[5] * V[6]) +
                              V[2] * (V[3] * V[7] - V[4] * V[6]));
        assert_true(fabs(det - 1) < 100 * T_EPS);
    }
    if (want_s)
        for (i = 0; i < 3; i++)
            if (fabs((double)S[i] - want_s[i]) > SVD_TOL(normA))
                fail_msg("S[%d] = %.17g, want %.17g", i, (double)S[i], want_s[i]);
}

static void test_known(void **state)
{
    /* rows: singular values and the rotations U, V are built from */
    static const double table[][9] = {
        /* s0, s1, s2, U angles, V angles */
        {3, 2, 1, 0, 0, 0, 0, 0, 0},
        {3, 2, 1, 0.3, -1.1, 2.0, 0.7, 0.2, -0.4},
        {1e3, 1, 1e-3, 1.0, 0.5, -0.25, -2.0, 1.5, 0.1},
        {5, 5, 5, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6},   /* repeated singular values */
        {2, 1, 0, 0.9, -0.3, 0.4, 0.2, 0.8, -1.2},  /* rank 2 */
        {7, 0, 0, -0.5, 0.1, 1.3, 0.6, -0.7, 0.9},  /* rank 1 */
        {1, 1e-6, 1e-12, 0.2, 0.4, 0.6, -0.3, 0.5, 1.1}, /* ill conditioned */
    };
    size_t t;
    (void)state;
    for (t = 0; t < sizeof table / sizeof table[0]; t++) {
        double Ua[9], Va[9], A[9];
        int i, j, k;
        rot(table[t][3], table[t][4], table[t][5], Ua);
        rot(table[t][6], table[t][7], table[t][8], Va);
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                A[i * 3 + j] = 0;
                for (k = 0; k < 3; k++)
                    A[i * 3 + j] += Ua[i * 3 + k] * table[t][k] * Va[j * 3 + k];
            }
        check_svd(A, table[t]);
    }
}

static void test_random(void **state)
{
    cdsp_rng rng;
    int t, i;
    (void)state;
    cdsp_rng_seed(&rng, 99, 3);
    for (t = 0; t < 2000; t++) {
        double A[9], scale = pow(10.0, (double)(cdsp_rng_below(&rng, 13)) - 6.0);
        for (i = 0; i < 9; i++)
            A[i] = scale * (double)cdsp_rng_normal(&rng);
        check_svd(A, NULL);
    }
}

static void test_special(void **state)
{
    const double zero[9] = {0};
    const double diag_neg[9] = {-2, 0, 0, 0, 3, 0, 0, 0, -1};
    const double want[3] = {3, 2, 1};
    cdsp_real a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, U[9], S[3], V[9];
    (void)state;
    check_svd(zero, zero);
    check_svd(diag_neg, want);
    a[4] = (cdsp_real)NAN;
    assert_int_equal(cdsp_svd3(a, U, S, V), CDSP_E_NONFINITE);
    a[4] = (cdsp_real)INFINITY;
    assert_int_equal(cdsp_svd3(a, U, S, V), CDSP_E_NONFINITE);
    assert_int_equal(cdsp_svd3(NULL, U, S, V), CDSP_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known),
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_special),
    };
    return cmocka_run_group_tests_name("svd3", tests, NULL, NULL);
}
