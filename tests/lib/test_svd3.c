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
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <cmocka.h>
#include "support.h"

/* Backward error of one-sided Jacobi: |A - U S V^T| <= c eps |A| (Demmel &
 * Veselic), c growing with the rotations applied (a few per sweep, a few
 * sweeps for a 3x3), plus the rebuild's own rounding: c = 16. Measured
 * (CDSP_TEST_VERBOSE=1): worst 5.6 eps |A| (double), 5.1 (float). */
#define SVD_TOL(normA) (16.0 * T_EPS * (normA))
/* Singular values of a matrix built with rotations on both sides: the
 * entries' rounding (eps |A|) moves each by up to that much (Weyl), so an
 * absolute bound is all any method can promise here; test_relative checks
 * the relative accuracy where it holds. Measured: worst 2.1 eps |A|
 * (double), 1.1 (float). */
#define SV_TOL(normA) (6.0 * T_EPS * (normA))

/* Orthogonality. V is the product of the plane rotations applied, each
 * orthogonal to ~1 eps (c^2 + s^2 = 1 to eps; each entry's two products and
 * sum rounded), at most 3 per sweep over the <= 5 sweeps a 3x3 takes to
 * converge (quadratic convergence): |V'V - I| <= 15 eps, bound 16. U's
 * columns are A V's, normalized: the sweeps stop when every pair's cosine
 * is <= eps (the test in svd3.c), gamma's own rounding (three products
 * summed) adds ~2 eps and each column's normalization 1 eps to the
 * diagonal; the rank completion (a cross product, then normalized) a few
 * eps: bound 8. det V - 1 ~ tr(V'V - I) / 2 <= 1.5 x 16 = 24 eps (the
 * determinant is evaluated in double). Measured (CDSP_TEST_VERBOSE=1) over
 * test_known, test_random and test_special: U 3.0 / 2.9 eps, V 6.0 / 6.1,
 * det 8.0 / 7.8 (double / float), 2.7, 2.6 and 3x inside. (They were 100
 * eps each: a Jacobi stopping at 64 eps cosines, U orthogonal to only
 * ~64 eps, passed.) */
#define U_ORTH_TOL (8.0 * T_EPS)
#define V_ORTH_TOL (16.0 * T_EPS)
#define DET_TOL (24.0 * T_EPS)

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

/* worst |A - U S V^T| / (eps |A|) and |S - want| / (eps |A|) seen (verbose) */
static double worst_back, worst_sv, worst_uu, worst_vv, worst_det;

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
            if (fabs(uu - (i == j)) / T_EPS > worst_uu)
                worst_uu = fabs(uu - (i == j)) / T_EPS;
            if (fabs(vv - (i == j)) / T_EPS > worst_vv)
                worst_vv = fabs(vv - (i == j)) / T_EPS;
            if (fabs(uu - (i == j)) > U_ORTH_TOL || fabs(vv - (i == j)) > V_ORTH_TOL)
                fail_msg("U'U - I = %.3g, V'V - I = %.3g eps at (%d, %d)", (uu - (i == j)) / T_EPS,
                         (vv - (i == j)) / T_EPS, i, j);
        }
    if (normA > 0 && sqrt(err) / (T_EPS * normA) > worst_back)
        worst_back = sqrt(err) / (T_EPS * normA);
    if (sqrt(err) > SVD_TOL(normA) + 1e-300)
        fail_msg("|A - USV'| = %.3g > %.3g", sqrt(err), SVD_TOL(normA));
    {
        double v[9], det;
        for (i = 0; i < 9; i++)
            v[i] = (double)V[i];
        det = v[0] * (v[4] * v[8] - v[5] * v[7]) - v[1] * (v[3] * v[8] - v[5] * v[6]) +
              v[2] * (v[3] * v[7] - v[4] * v[6]);
        if (fabs(det - 1) / T_EPS > worst_det)
            worst_det = fabs(det - 1) / T_EPS;
        if (fabs(det - 1) > DET_TOL)
            fail_msg("det V - 1 = %.3g eps", (det - 1) / T_EPS);
    }
    if (want_s)
        for (i = 0; i < 3; i++) {
            if (normA > 0 && fabs((double)S[i] - want_s[i]) / (T_EPS * normA) > worst_sv)
                worst_sv = fabs((double)S[i] - want_s[i]) / (T_EPS * normA);
            if (fabs((double)S[i] - want_s[i]) > SV_TOL(normA))
                fail_msg("S[%d] = %.17g, want %.17g", i, (double)S[i], want_s[i]);
        }
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

/* The accuracy svd3.c claims for small singular values (Demmel & Veselic
 * 1992): one-sided Jacobi computes every singular value of A = B D (D a
 * column scaling, B's columns well conditioned) to a relative error of
 * O(eps kappa(B)), however graded D is; an absolute bound, eps |A|, would
 * let a singular value of 1e-12 fall anywhere in [0, 6e-6] in float. So:
 * A = U diag(s) P with U a rotation and P a column permutation (B = U P,
 * kappa = 1), the columns graded down to 1e-12 (1e-30 in double, where the
 * range allows), each S[i] within 6 eps of s[i] relative (the reference
 * is the rounded matrix's column norms, exact to eps / 2: its columns are
 * orthogonal to eps), and the left singular vectors of simple singular
 * values within 6 eps of A's columns over their norms. Measured: worst 1.9
 * eps (double) and 1.6 eps (float) for the values, 1.75 and 1.4 eps for
 * the vectors, over 2000 random rotations and column orders. */
static void test_relative(void **state)
{
    static const double grades[][3] = {
        {1, 1e-6, 1e-12},
        {1e-12, 1, 1e-6},
        {1, 1, 1e-9},
        {3, 1e-4, 1e-8},
#ifndef CDSP_SINGLE
        {1, 1e-15, 1e-30},
#endif
    };
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    cdsp_rng rng;
    double worst = 0, worst_u = 0;
    int t;
    (void)state;
    cdsp_rng_seed(&rng, 5, 8);
    for (t = 0; t < 2000; t++) {
        const double *g = grades[t % (int)(sizeof grades / sizeof grades[0])];
        const int *p = perm[(t / 7) % 6];
        double Ua[9], want[3], sorted[3], tmp;
        cdsp_real a[9], U[9], S[3], V[9];
        int i, j;
        rot(2 * SUP_PI * (double)cdsp_rng_uniform(&rng), 2 * SUP_PI * (double)cdsp_rng_uniform(&rng),
            2 * SUP_PI * (double)cdsp_rng_uniform(&rng), Ua);
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                a[i * 3 + j] = (cdsp_real)(Ua[i * 3 + p[j]] * g[p[j]]);
        /* the singular values of the rounded matrix are the columns' norms
         * to eps / 2 (columns orthogonal to eps): take them in double */
        for (j = 0; j < 3; j++) {
            double nn = 0;
            for (i = 0; i < 3; i++)
                nn += (double)a[i * 3 + j] * (double)a[i * 3 + j];
            want[j] = sqrt(nn);
        }
        for (i = 0; i < 3; i++)
            sorted[i] = want[i];
        for (i = 0; i < 2; i++)
            for (j = 0; j < 2 - i; j++)
                if (sorted[j] < sorted[j + 1]) {
                    tmp = sorted[j];
                    sorted[j] = sorted[j + 1];
                    sorted[j + 1] = tmp;
                }
        assert_int_equal(cdsp_svd3(a, U, S, V), CDSP_OK);
        for (i = 0; i < 3; i++) {
            double rel = fabs((double)S[i] - sorted[i]) / sorted[i];
            if (rel > worst)
                worst = rel;
            if (rel > 6 * T_EPS)
                fail_msg("trial %d: S[%d] = %.9g, want %.9g (relative %.3g > 6 eps)", t, i,
                         (double)S[i], sorted[i], rel);
        }
        /* the left singular vectors too, where the singular value is
         * simple: column j of A over its norm (the grades are 1e3 or more
         * apart, so the vectors' error is eps over that relative gap) */
        for (i = 0; i < 3; i++) {
            double dot = 0, dif = 0;
            int simple = 1;
            for (j = 0; j < 3; j++)
                if (j != i && fabs(sorted[j] / sorted[i] - 1) < 1e-3)
                    simple = 0;
            for (j = 0; j < 3 && simple; j++)
                if (want[j] == sorted[i])
                    break;
            if (!simple || j == 3)
                continue;
            {
                int c = j, r;
                for (r = 0; r < 3; r++)
                    dot += (double)U[r * 3 + i] * (double)a[r * 3 + c] / want[c];
                for (r = 0; r < 3; r++) {
                    double d = (double)U[r * 3 + i] - (dot < 0 ? -1 : 1) * (double)a[r * 3 + c] / want[c];
                    dif += d * d;
                }
            }
            dif = sqrt(dif);
            if (dif > worst_u)
                worst_u = dif;
            if (dif > 6 * T_EPS)
                fail_msg("trial %d: U column %d off by %.3g (> 6 eps)", t, i, dif);
        }
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("relative accuracy: worst %.3g eps; left vectors: worst %.3g eps\n", worst / T_EPS,
                      worst_u / T_EPS);
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
        cmocka_unit_test(test_relative),
        cmocka_unit_test(test_special),
    };
    int rc;
    rc = cmocka_run_group_tests_name("svd3", tests, NULL, NULL);
    if (getenv("CDSP_TEST_VERBOSE"))
        printf("backward error: worst %.3g eps |A|; known singular values: worst %.3g eps |A|; "
               "orthogonality: U %.3g, V %.3g, det V %.3g eps\n",
               worst_back, worst_sv, worst_uu, worst_vv, worst_det);
    return rc;
}
