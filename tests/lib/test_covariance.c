/*
 * test_covariance.c - the uncertainty cdsp_result publishes, tested as what
 * it claims (include/cdsp.h: cov is the first-order covariance of
 * (point, direction) from the edge points' random error; docs/method.md §6).
 *
 * The axis has 4 degrees of freedom: 2 of direction and 2 of position
 * perpendicular to it. cov (6 x 6) is singular along the other two: |v| = 1
 * and P_C . v = 0 (P_C is the foot of the perpendicular from the optical
 * centre), so to first order dv . v = 0 and dP . v = -P . dv. With e1, e2 an
 * orthonormal basis perpendicular to the true direction v, the observable
 * error y = (e1.dv, e2.dv, e1.dP, e2.dP) determines the whole first-order
 * error; its covariance C4 = B cov B^T (B the 4 x 6 projection) is
 * regular, and if cov is right, d^2 = y^T C4^-1 y is chi-square with 4 dof
 * over repeated noise draws: mean 4, variance 8, P(d^2 > 9.4877) = 0.05.
 *
 * Bands from the trial count N (all seeded, so each run is reproducible,
 * and the bands are 4 standard deviations of the statistic, not tuned):
 *   mean of d^2:           4 +- 4 sqrt(8 / N)
 *   sample variance:       8 +- 4 sqrt((mu4 - 64) / N), mu4 = 12 k (k + 4) = 384
 *   tail fraction > 9.4877: 0.05 +- 4 sqrt(0.05 * 0.95 / N)
 * and for the distance alone (sigma_distance), z^2 = (dd / sigma)^2 is
 * chi-square with 1 dof: mean 1 +- 4 sqrt(2 / N).
 * The covariance itself comes from estimated residuals (s^2 = RSS/(N_pts-2),
 * relative sd sqrt(2 / 1000) = 4.5 % per line) and a first-order
 * Jacobian (in closed form, lib/pair.c); both move the mean of d^2 by well
 * under a percent at these noise levels, far inside the bands.
 *
 * Poses: the paper's four pipes, random poses at 150-1500 mm, and the
 * near-degenerate ones: axis within 12-20 degrees of the line of sight
 * (contours converging toward the vanishing point), far (3-5 m: alpha ~
 * 0.004 rad, a band of 11-18 px), and seen obliquely near the frame's
 * corner (field angle ~ 17 degrees: the back-projection planes far from the
 * optical axis). A mutant that flips the sign of the point-direction
 * covariance when the contours are swapped (lib/axis.c, cdsp__axis_swap), or
 * halves the offset variance in lib/pair.c, or scales a published sigma,
 * or breaks the factor (its sign or column exchange in the swap, a sign in
 * axis_change), fails here (tests/mutants/).
 *
 * cov and cov_factor F (cov = F F^T, include/cdsp.h). Both builds score
 * every class with F; the double build scores cov too. The float build
 * does not score cov: its entries' rounding alone loses the observable dof
 * of far pipes. The position block holds (|P| sigma_v)^2 ~ 200 mm^2 along
 * v (dP.v = -P.dv) while the smallest observable variance is ~1e-5 mm^2,
 * a ratio beyond 1 / eps of float. Measured: the double build's 6 x 6
 * rounded to float is not positive definite on the observable dof at the
 * far class's first trial; the float build's cov gives d^2 more than 20 %
 * off F's (or not positive definite) in 95 of the far class's 400 trials,
 * and with seed 700 in 2 of the random class's (1.4-1.5 m; one 51.7
 * against 9.1, a variance of d^2 of 13.6, outside the band). F's columns
 * keep their relative precision (lib/pair.c, axis_change), so F carries
 * them in float; that cov is F F^T to its rounding is checked in both.
 *
 * Measured (CDSP_TEST_VERBOSE=1, seeds as committed, N = 400 each; bands
 * mean 4 +- 0.566, variance 8 +- 3.58, tail 0.05 +- 0.0436, mean z^2
 * 1 +- 0.283):
 *                          double (cov and F alike)    float (F)
 *                          mean  var   tail   z^2     mean  var   tail   z^2
 *   paper pipes, 0.1 px    3.820 7.07 0.0350 0.971    4.204 10.23 0.0575 0.944
 *   random 150-1500 mm     4.079 8.77 0.0500 1.020    3.983 7.34 0.0525 1.038
 *   12-20 deg off the view 4.023 7.30 0.0525 1.034    3.991 7.91 0.0500 0.997
 *   far, 3-5 m             4.095 9.26 0.0750 0.864    4.352 8.05 0.0525 1.047
 *   oblique, frame corner  3.904 7.05 0.0350 0.964    4.194 8.54 0.0600 1.146
 * The double figures are those of the central-difference Jacobian this
 * replaced, to the digits shown. cov - F F^T: at most 1.67 eps (double)
 * and 1.20 eps (float) of sum_k |F_ak F_bk|; bound 3 eps (the rounding of
 * 4 products and 3 sums, ~2.5 eps).
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
static cdsp_edge pts[CDSP_MAX_POINTS];

#define CHI2_4_Q95 9.4877290367811540 /* chi-square, 4 dof, 95 % quantile */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void unit3(double a[3])
{
    double n = sqrt(dot3(a, a));
    a[0] /= n;
    a[1] /= n;
    a[2] /= n;
}

/* Solve A x = b for symmetric positive definite 4 x 4 A (Cholesky);
 * returns b^T A^-1 b, or -1 when A is not positive definite. */
static double mahalanobis4(double A[4][4], const double b[4])
{
    double L[4][4] = {{0}}, z[4], s = 0;
    int i, j, k;
    for (i = 0; i < 4; i++)
        for (j = 0; j <= i; j++) {
            double t = A[i][j];
            for (k = 0; k < j; k++)
                t -= L[i][k] * L[j][k];
            if (i == j) {
                if (!(t > 0))
                    return -1;
                L[i][i] = sqrt(t);
            } else {
                L[i][j] = t / L[j][j];
            }
        }
    for (i = 0; i < 4; i++) {
        double t = b[i];
        for (k = 0; k < i; k++)
            t -= L[i][k] * z[k];
        z[i] = t / L[i][i];
        s += z[i] * z[i];
    }
    return s;
}

/* d^2 of a result against the true axis (P, v), and z^2 of its distance;
 * from the published cov (factor 0) or from cov_factor F (factor 1: the
 * 6 x 6 is F F^T, formed in double here). */
static double observable_d2(const cdsp_result *r, int factor, const double P[3], const double v0[3],
                            double *z2_dist)
{
    double v[3], f[3], got[3], dir[3], e1[3], e2[3], y[4], B[4][6], C[6][6], C4[4][4], t, sgn;
    double ax[3] = {1, 0, 0};
    int i, j, a, b;
    memcpy(v, v0, sizeof v);
    unit3(v);
    t = dot3(P, v);
    for (i = 0; i < 3; i++)
        f[i] = P[i] - t * v[i]; /* true P_C */
    sup_result_pose(r, got, dir, NULL);
    /* the published sign of the direction is a convention; compare with the
     * truth's: flipping v flips the point-direction block of cov */
    sgn = dot3(dir, v) < 0 ? -1 : 1;
    for (a = 0; a < 6; a++)
        for (b = 0; b < 6; b++) {
            double c = 0;
            int k;
            if (!factor)
                c = (double)r->cov[a][b];
            else
                for (k = 0; k < 4; k++)
                    c += (double)r->cov_factor[a][k] * (double)r->cov_factor[b][k];
            C[a][b] = c * (((a < 3) != (b < 3)) ? sgn : 1);
        }
    if (fabs(v[0]) > 0.8) {
        ax[0] = 0;
        ax[1] = 1;
    }
    cross3(v, ax, e1);
    unit3(e1);
    cross3(v, e1, e2);
    memset(B, 0, sizeof B);
    for (i = 0; i < 3; i++) {
        B[0][3 + i] = e1[i];
        B[1][3 + i] = e2[i];
        B[2][i] = e1[i];
        B[3][i] = e2[i];
    }
    for (i = 0; i < 3; i++)
        dir[i] = sgn * dir[i] - v[i];
    for (i = 0; i < 3; i++)
        got[i] -= f[i];
    y[0] = dot3(e1, dir);
    y[1] = dot3(e2, dir);
    y[2] = dot3(e1, got);
    y[3] = dot3(e2, got);
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) {
            double s = 0;
            for (a = 0; a < 6; a++)
                for (b = 0; b < 6; b++)
                    s += B[i][a] * C[a][b] * B[j][b];
            C4[i][j] = s;
        }
    {
        double dd = (double)r->distance - sqrt(dot3(f, f));
        *z2_dist = dd * dd / ((double)r->sigma_distance * (double)r->sigma_distance);
    }
    return mahalanobis4(C4, y);
}

/* The paper's camera (no distortion), default parameters, and the solver's
 * and the generator's streams of one seed. */
static void setup(cdsp_camera *cam, cdsp_params *prm, cdsp_rng *rng, cdsp_rng *gen, uint64_t seed)
{
    sup_paper_camera(cam, 0, 0);
    cdsp_params_default(prm);
    cdsp_rng_seed(rng, seed, 1);
    cdsp_rng_seed(gen, seed, 2);
}

/* The pose classes (see the top). */
enum { POSE_PAPER, POSE_RANDOM, POSE_ALONG_VIEW, POSE_FAR, POSE_CORNER };

static void make_pose(int kind, int t, cdsp_rng *g, double P[3], double v[3], double *s0, double *s1)
{
    double th = 2 * SUP_PI * (double)cdsp_rng_uniform(g);
    *s0 = -100;
    *s1 = 100;
    switch (kind) {
    case POSE_PAPER:
        sup_paper_pipe(t % 4, P, v);
        *s0 = -250;
        *s1 = 250;
        break;
    case POSE_RANDOM:
        sup_random_pipe(g, 150, 1500, P, v);
        break;
    case POSE_ALONG_VIEW: {
        /* 12-20 degrees off the line of sight through the axis point */
        double tilt = (12 + 8 * (double)cdsp_rng_uniform(g)) * SUP_PI / 180;
        P[0] = 20 * cos(th);
        P[1] = 20 * sin(th);
        P[2] = 500;
        v[0] = sin(tilt) * cos(th + 1);
        v[1] = sin(tilt) * sin(th + 1);
        v[2] = cos(tilt);
        *s0 = -200;
        *s1 = 400;
        break;
    }
    case POSE_FAR: {
        double z = 3000 + 2000 * (double)cdsp_rng_uniform(g);
        P[0] = 0.05 * z * cos(th);
        P[1] = 0.05 * z * sin(th);
        P[2] = z;
        v[0] = cos(th + 2);
        v[1] = sin(th + 2);
        v[2] = 0.3 * ((double)cdsp_rng_uniform(g) - 0.5);
        *s0 = -400;
        *s1 = 400;
        break;
    }
    default: { /* POSE_CORNER: centred ~ 1000 px from the principal point */
        double z = 400 + 400 * (double)cdsp_rng_uniform(g);
        double sx = (t & 1) ? 1 : -1, sy = (t & 2) ? 1 : -1;
        P[0] = sx * 0.25 * z;
        P[1] = sy * 0.2 * z;
        P[2] = z;
        /* along the frame's diagonal-ish, with some depth */
        v[0] = cos(th);
        v[1] = sin(th);
        v[2] = 0.5 * ((double)cdsp_rng_uniform(g) - 0.5);
        *s0 = -60;
        *s1 = 60;
        break;
    }
    }
}

typedef struct {
    double mean, var, tail, mean_z2;
    int n;
} chi_stats;

/* How far cov is from cov_factor F F^T: the largest |cov_ab - (F F^T)_ab|
 * over sum_k |F_ak F_bk| (the scale of the entry's rounding), in eps. */
static double factor_gap(const cdsp_result *r)
{
    double worst = 0;
    int a, b, k;
    for (a = 0; a < 6; a++)
        for (b = 0; b < 6; b++) {
            double s = 0, m = 0;
            for (k = 0; k < 4; k++) {
                double p = (double)r->cov_factor[a][k] * (double)r->cov_factor[b][k];
                s += p;
                m += fabs(p);
            }
            if (m > 0 && fabs((double)r->cov[a][b] - s) / m > worst)
                worst = fabs((double)r->cov[a][b] - s) / m;
            else if (m == 0 && r->cov[a][b] != 0)
                return 1e300;
        }
    return worst / T_EPS;
}

/* Accumulates the statistics of one d^2 series. */
static void add_d2(chi_stats *st, double d2, double z2, double *sum, double *sum2, int *tail)
{
    *sum += d2;
    *sum2 += d2 * d2;
    *tail += d2 > CHI2_4_Q95;
    st->mean_z2 += z2;
    st->n++;
}

static void end_stats(chi_stats *st, double sum, double sum2, int tail)
{
    st->mean = sum / st->n;
    st->var = (sum2 - st->n * st->mean * st->mean) / (st->n - 1);
    st->tail = (double)tail / st->n;
    st->mean_z2 /= st->n;
}

/* The same seeded trials scored with cov (st[0], when use_cov) and with
 * cov_factor (st[1]). */
static void run_trials(int kind, int trials, double sigma_px, uint64_t seed, int use_cov,
                       chi_stats st[2], double *gap)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, gen;
    double sum[2] = {0, 0}, sum2[2] = {0, 0};
    int t, f, tail[2] = {0, 0}, tries = 0;
    memset(st, 0, 2 * sizeof *st);
    setup(&cam, &prm, &rng, &gen, seed);
    for (t = 0; st[1].n < trials; t++) {
        double P[3], v[3], s0, s1;
        cdsp_result r;
        size_t n;
        cdsp_status s;
        assert_true(++tries < 4 * trials); /* the pose generator keeps most poses in view */
        make_pose(kind, t, &gen, P, v, &s0, &s1);
        n = sup_contour_points(&cam, P, v, 8, s0, s1, CDSP_MAX_POINTS / 2, sigma_px, 100, &gen, pts,
                               CDSP_MAX_POINTS, NULL);
        if (n < CDSP_MAX_POINTS)
            continue; /* a contour out of view */
        s = cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r);
        if (s != CDSP_OK)
            fail_msg("pose class %d trial %d: %s", kind, t, cdsp_strerror(s));
        {
            double e = factor_gap(&r);
            if (e > *gap)
                *gap = e;
        }
        for (f = use_cov ? 0 : 1; f < 2; f++) {
            double z2, d2 = observable_d2(&r, f, P, v, &z2);
            if (d2 < 0)
                fail_msg("pose class %d trial %d: %s not positive definite on the 4 "
                         "observable dof", kind, t, f ? "cov_factor F F^T" : "cov");
            add_d2(&st[f], d2, z2, &sum[f], &sum2[f], &tail[f]);
        }
    }
    for (f = use_cov ? 0 : 1; f < 2; f++)
        end_stats(&st[f], sum[f], sum2[f], tail[f]);
}

static void check_stats(const char *what, const char *from, chi_stats st)
{
    double n = st.n;
    double mean_band = 4 * sqrt(8 / n), var_band = 4 * sqrt((384.0 - 64.0) / n),
           tail_band = 4 * sqrt(0.05 * 0.95 / n), z2_band = 4 * sqrt(2 / n);
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("%-24s %-6s N=%d mean d2 %.3f (4 +- %.3f) var %.2f (8 +- %.2f) tail %.4f "
                      "(0.05 +- %.4f) mean z2(dist) %.3f (1 +- %.3f)\n",
                      what, from, st.n, st.mean, mean_band, st.var, var_band, st.tail, tail_band,
                      st.mean_z2, z2_band);
    if (fabs(st.mean - 4) > mean_band)
        fail_msg("%s (%s): mean Mahalanobis d^2 %.3f over %d trials, want 4 +- %.3f", what, from,
                 st.mean, st.n, mean_band);
    if (fabs(st.var - 8) > var_band)
        fail_msg("%s (%s): variance of d^2 %.3f, want 8 +- %.3f", what, from, st.var, var_band);
    if (fabs(st.tail - 0.05) > tail_band)
        fail_msg("%s (%s): fraction of d^2 > %.3f is %.4f, want 0.05 +- %.4f", what, from,
                 CHI2_4_Q95, st.tail, tail_band);
    if (fabs(st.mean_z2 - 1) > z2_band)
        fail_msg("%s (%s): mean (distance error / sigma_distance)^2 %.3f, want 1 +- %.3f", what,
                 from, st.mean_z2, z2_band);
}

/* Table: each pose class, 400 seeded trials of 1024 points per contour,
 * scored with the factor in both builds and with cov wherever its entries'
 * precision resolves the observable dof (see the top: not the far class in
 * float). The measured figures are at the top. */
static void test_mahalanobis(void **state)
{
    static const struct {
        const char *what;
        int kind;
        double sigma_px;
    } rows[] = {
        {"paper pipes, 0.1 px", POSE_PAPER, 0.1},
        {"random 150-1500 mm", POSE_RANDOM, 0.2},
        {"12-20 deg off the view", POSE_ALONG_VIEW, 0.2},
        {"far, 3-5 m", POSE_FAR, 0.1},
        {"oblique, frame corner", POSE_CORNER, 0.2},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        chi_stats st[2];
        double gap = 0;
#ifdef CDSP_SINGLE
        int use_cov = 0;
#else
        int use_cov = 1;
#endif
        run_trials(rows[i].kind, 400, rows[i].sigma_px, 100 + i, use_cov, st, &gap);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("%-24s cov - F F^T: %.2f eps of the entries' scale\n", rows[i].what, gap);
        /* cov is F F^T summed in the precision in use: 4 products and 3
         * additions, at most ~2.5 eps of sum |F_ak F_bk| (the unit roundoff
         * is eps / 2); measured at the top */
        if (gap > 3)
            fail_msg("%s: cov is %.3g eps of its scale from cov_factor F F^T, want <= 3", rows[i].what, gap);
        if (use_cov)
            check_stats(rows[i].what, "cov", st[0]);
        check_stats(rows[i].what, "factor", st[1]);
    }
}

/* The published sigmas are the covariance's diagonal (not a second
 * computation that could drift from it): equal to rounding. */
static void test_sigmas_are_cov_diagonal(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, gen;
    cdsp_result r;
    double P[3], v[3];
    size_t n;
    int i;
    (void)state;
    setup(&cam, &prm, &rng, &gen, 7);
    sup_paper_pipe(1, P, v);
    n = sup_contour_points(&cam, P, v, 8, -250, 250, 1000, 0.1, 100, &gen, pts, CDSP_MAX_POINTS, NULL);
    assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    {
        /* singular along the two unobservable dof: |v| = 1 (dv . v = 0) and
         * P_C . v = 0 (dP . v + P . dv = 0), i.e. n^T cov n = 0 for n = (0, v)
         * and n = (v, P). Each column of F meets both to first order by
         * construction (lib/pair.c, axis_change), so only rounding is left:
         * ~eps of the block's variance. Measured (CDSP_TEST_VERBOSE=1)
         * 3.4e-17 (double, 0.15 eps) and 2.8e-8 (float, 0.23 eps); bound
         * 1 eps, 4.3 times the larger. */
        double n1[6] = {0, 0, 0, 0, 0, 0}, n2[6], q1 = 0, q2 = 0, tv = 0, tp = 0;
        int a, b;
        for (i = 0; i < 3; i++) {
            n1[3 + i] = (double)r.direction[i];
            n2[i] = (double)r.direction[i];
            n2[3 + i] = (double)r.point[i];
            tp += (double)r.cov[i][i];
            tv += (double)r.cov[3 + i][3 + i];
        }
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) {
                q1 += n1[a] * (double)r.cov[a][b] * n1[b];
                q2 += n2[a] * (double)r.cov[a][b] * n2[b];
            }
        /* n2's scale: |P|^2 tv + tp */
        q2 /= (double)r.distance * (double)r.distance * tv + tp;
        q1 /= tv;
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("null directions: %.3g %.3g of the variance\n", q1, q2);
        assert_true(fabs(q1) < T_EPS && fabs(q2) < T_EPS);
    }
    for (i = 0; i < 3; i++) {
        /* a square root's rounding: a few eps relative */
        double sp = (double)r.sigma_point[i], sd = (double)r.sigma_direction[i];
        assert_true(fabs(sp * sp - (double)r.cov[i][i]) <= 8 * T_EPS * (double)r.cov[i][i]);
        assert_true(fabs(sd * sd - (double)r.cov[3 + i][3 + i]) <= 8 * T_EPS * (double)r.cov[3 + i][3 + i]);
    }
}

#ifndef CDSP_SINGLE
/* What each column of cov_factor means (include/cdsp.h): column 2k is the
 * change of (point, direction) when contour k's published line moves by one
 * standard deviation of its offset, s / sqrt(N - 2) with s = rms (the
 * angle columns turn about the fit's centroid, which the result does not
 * carry, so they are left to the Mahalanobis test). Checked against central
 * differences of cdsp_axis_solve on the published lines, in double only:
 * in float the differences' rounding is what the closed form is there to
 * avoid. The differences' truncation is (h / band)^2 relative: h = 0.1 /
 * sqrt(1000) = 3.2e-3 px, the far pose's band 15 px, 4.4e-8; their
 * rounding, eps |P| / h ~ 3e-10 mm, is negligible. Measured 4.5e-8 of the
 * column's norm (the far pose); bound 2e-7, 4.5 times it. Poses: the
 * paper's four, one far, one at the corner; the contours come out in both
 * orders (3 and 3: the direction's sign rule swaps them), so the swap's
 * column exchange is exercised. */
static void test_factor_columns(void **state)
{
    static const double far_P[3] = {185, 0, 3700}, far_v[3] = {-0.41, 0.91, 0.1};
    static const double cor_P[3] = {150, 120, 600}, cor_v[3] = {0.6, -0.78, 0.2};
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng, gen;
    double worst = 0;
    int pose, k, swapped = 0, straight = 0;
    (void)state;
    setup(&cam, &prm, &rng, &gen, 9);
    for (pose = 0; pose < 6; pose++) {
        double P[3], v[3];
        cdsp_result r;
        cdsp_real pin[2];
        size_t n;
        if (pose < 4)
            sup_paper_pipe(pose, P, v);
        memcpy(P, pose == 4 ? far_P : pose == 5 ? cor_P : P, sizeof P);
        memcpy(v, pose == 4 ? far_v : pose == 5 ? cor_v : v, sizeof v);
        n = sup_contour_points(&cam, P, v, 8, pose == 4 ? -400 : -100, pose == 4 ? 400 : 100, 1000,
                               0.1, 100, &gen, pts, CDSP_MAX_POINTS, NULL);
        assert_int_equal(cdsp_points_solve(&cam, 8, pts, n, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        assert_int_equal(cdsp_camera_project(&cam, r.point, pin), CDSP_OK); /* between the contours */
        /* lib/pair.c solves with the lines in the order of their labels
         * (pairs i < j) and swaps them for the direction's sign rule */
        if (r.label[0] > r.label[1])
            swapped++;
        else
            straight++;
        for (k = 0; k < 2; k++) {
            double h = (double)r.rms[k] / sqrt((double)r.inliers[k] - 2), fd[6], e2 = 0, c2 = 0;
            cdsp_real lp[2][3], lm[2][3];
            cdsp_result rp, rm;
            int i;
            memcpy(lp, r.lines, sizeof lp);
            memcpy(lm, r.lines, sizeof lm);
            lp[k][2] -= h; /* + one sigma: l[2] - h moves the line by h along its normal */
            lm[k][2] += h;
            assert_int_equal(cdsp_axis_solve(&cam, lp[0], lp[1], pin, 8, &rp), CDSP_OK);
            assert_int_equal(cdsp_axis_solve(&cam, lm[0], lm[1], pin, 8, &rm), CDSP_OK);
            for (i = 0; i < 3; i++) {
                double sp = (double)(rp.direction[0] * r.direction[0] + rp.direction[1] * r.direction[1] +
                                     rp.direction[2] * r.direction[2]) < 0 ? -1 : 1;
                double sm = (double)(rm.direction[0] * r.direction[0] + rm.direction[1] * r.direction[1] +
                                     rm.direction[2] * r.direction[2]) < 0 ? -1 : 1;
                fd[i] = ((double)rp.point[i] - (double)rm.point[i]) / 2;
                fd[3 + i] = (sp * (double)rp.direction[i] - sm * (double)rm.direction[i]) / 2;
            }
            for (i = 0; i < 6; i++) {
                double c = (double)r.cov_factor[i][2 * k];
                e2 += (c - fd[i]) * (c - fd[i]);
                c2 += c * c;
            }
            if (sqrt(e2 / c2) > worst)
                worst = sqrt(e2 / c2);
        }
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("offset columns against central differences: %.3g of the column "
                      "(%d poses with the contours swapped, %d not)\n", worst, swapped, straight);
    assert_true(swapped > 0 && straight > 0);
    assert_true(worst < 2e-7);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mahalanobis),
        cmocka_unit_test(test_sigmas_are_cov_diagonal),
#ifndef CDSP_SINGLE
        cmocka_unit_test(test_factor_columns),
#endif
    };
    return cmocka_run_group_tests_name("covariance", tests, NULL, NULL);
}
