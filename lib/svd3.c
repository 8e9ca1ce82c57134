/*
 * svd3.c - singular value decomposition of a 3x3 matrix by one-sided Jacobi
 * (Hestenes 1958; Demmel & Veselic 1992 for its accuracy): plane rotations
 * applied to pairs of columns until every pair is orthogonal to working
 * precision. The column norms are then the singular values. One-sided
 * Jacobi is accurate for small singular values (it never forms A^T A), which
 * is what a total-least-squares line fit asks for.
 */
#include "internal.h"

#define SVD3_MAX_SWEEPS 40

static void swap_cols(cdsp_real M[9], int a, int b)
{
    int r;
    for (r = 0; r < 3; r++) {
        cdsp_real t = M[r * 3 + a];
        M[r * 3 + a] = M[r * 3 + b];
        M[r * 3 + b] = t;
    }
}

static void col(const cdsp_real M[9], int c, cdsp_real out[3])
{
    out[0] = M[c];
    out[1] = M[3 + c];
    out[2] = M[6 + c];
}

static void set_col(cdsp_real M[9], int c, const cdsp_real v[3])
{
    M[c] = v[0];
    M[3 + c] = v[1];
    M[6 + c] = v[2];
}

/* A unit vector orthogonal to unit a. */
static void any_orthogonal(const cdsp_real a[3], cdsp_real out[3])
{
    cdsp_real e[3] = {R(0), R(0), R(0)};
    int k = 0;
    if (R_FABS(a[1]) < R_FABS(a[k]))
        k = 1;
    if (R_FABS(a[2]) < R_FABS(a[k]))
        k = 2;
    e[k] = R(1); /* the axis least aligned with a */
    v3_cross(a, e, out);
    v3_normalize(out);
}

cdsp_status cdsp_svd3(const cdsp_real A[9], cdsp_real U[9], cdsp_real S[3], cdsp_real V[9])
{
    int i, sweep, p, q, converged = 0;
    cdsp_real scale = R(0);
    if (!A || !U || !S || !V)
        return CDSP_E_ARG;
    for (i = 0; i < 9; i++) {
        if (!R_FINITE(A[i]))
            return CDSP_E_NONFINITE;
        U[i] = A[i];
        V[i] = (i % 4 == 0) ? R(1) : R(0);
        if (R_FABS(A[i]) > scale)
            scale = R_FABS(A[i]);
    }
    if (scale == R(0)) { /* the zero matrix: U = V = I, S = 0 */
        for (i = 0; i < 9; i++)
            U[i] = V[i];
        S[0] = S[1] = S[2] = R(0);
        return CDSP_OK;
    }
    /* Work on A / scale so squared norms cannot overflow or underflow. */
    for (i = 0; i < 9; i++)
        U[i] /= scale;

    for (sweep = 0; sweep < SVD3_MAX_SWEEPS && !converged; sweep++) {
        converged = 1;
        for (p = 0; p < 2; p++) {
            for (q = p + 1; q < 3; q++) {
                cdsp_real alpha = R(0), beta = R(0), gamma = R(0), zeta, t, c, s;
                int r;
                for (r = 0; r < 3; r++) {
                    alpha += U[r * 3 + p] * U[r * 3 + p];
                    beta += U[r * 3 + q] * U[r * 3 + q];
                    gamma += U[r * 3 + p] * U[r * 3 + q];
                }
                /* Columns orthogonal to working precision: no rotation. */
                if (gamma == R(0) || R_FABS(gamma) <= R_EPS * R_SQRT(alpha * beta))
                    continue;
                converged = 0;
                /* Rotation that zeroes the (p,q) entry of U^T U (Rutishauser's
                 * stable tangent). */
                zeta = (beta - alpha) / (R(2) * gamma);
                t = (zeta >= R(0) ? R(1) : R(-1)) / (R_FABS(zeta) + R_SQRT(R(1) + zeta * zeta));
                c = R(1) / R_SQRT(R(1) + t * t);
                s = c * t;
                for (r = 0; r < 3; r++) {
                    cdsp_real up = U[r * 3 + p], uq = U[r * 3 + q];
                    cdsp_real vp = V[r * 3 + p], vq = V[r * 3 + q];
                    U[r * 3 + p] = c * up - s * uq;
                    U[r * 3 + q] = s * up + c * uq;
                    V[r * 3 + p] = c * vp - s * vq;
                    V[r * 3 + q] = s * vp + c * vq;
                }
            }
        }
    }
    if (!converged)
        return CDSP_E_NOCONVERGE;

    for (i = 0; i < 3; i++) {
        cdsp_real c3[3];
        col(U, i, c3);
        S[i] = v3_norm(c3);
    }
    /* sort descending (three elements: a tiny bubble sort) */
    for (p = 0; p < 2; p++)
        for (q = 0; q < 2 - p; q++)
            if (S[q] < S[q + 1]) {
                cdsp_real t = S[q];
                S[q] = S[q + 1];
                S[q + 1] = t;
                swap_cols(U, q, q + 1);
                swap_cols(V, q, q + 1);
            }
    /* Normalize U's columns; complete the basis where a singular value is
     * zero relative to the largest (rank-deficient A). */
    {
        cdsp_real u0[3], u1[3], u2[3];
        cdsp_real tiny = S[0] * R_EPS * R(4);
        col(U, 0, u0);
        col(U, 1, u1);
        col(U, 2, u2);
        v3_scale(u0, R(1) / S[0]);
        if (S[1] > tiny) {
            v3_scale(u1, R(1) / S[1]);
        } else {
            any_orthogonal(u0, u1);
        }
        if (S[2] > tiny) {
            v3_scale(u2, R(1) / S[2]);
        } else {
            v3_cross(u0, u1, u2);
            v3_normalize(u2);
        }
        set_col(U, 0, u0);
        set_col(U, 1, u1);
        set_col(U, 2, u2);
    }
    /* det V = +1: flipping column 2 of both U and V keeps A = U S V^T. */
    {
        cdsp_real v0[3], v1[3], v2[3], x[3];
        col(V, 0, v0);
        col(V, 1, v1);
        col(V, 2, v2);
        v3_cross(v0, v1, x);
        if (v3_dot(x, v2) < R(0)) {
            for (i = 0; i < 3; i++) {
                V[i * 3 + 2] = -V[i * 3 + 2];
                U[i * 3 + 2] = -U[i * 3 + 2];
            }
        }
    }
    for (i = 0; i < 3; i++)
        S[i] *= scale;
    return CDSP_OK;
}
