/*
 * test_pointfit.c - cdsp_params.point_fit (lib/rescan.c, docs/method.md
 * §3a): with the rescan pass on (refine_step 3), each point's position is
 * fitted again to its window's pixels (a blurred step with the contour's
 * own spread and side slopes, its levels and offset free), in place of the
 * partial-area estimate, which weighs the window's 9 pixels of a scanline
 * alike. Rendered pipes (blur 0.8 px, flat light, no texture: no shading
 * bias) with exact contour lines (sup_contour_lines), NFRAMES noise seeds
 * each, every frame solved with the fit off and on on the same pixels; per
 * case, over its contours' offset errors at the pipe's middle:
 *  - the noise ratio (RMS about the mean, off / on) within RATIO_LO ..
 *    RATIO_HI. Derived: both estimates are linear in the pixels' noise to
 *    first order, so the ratio does not depend on the contrast or the
 *    noise level; per point it is 2.23 / 1.20 sigma/C (detector / fit,
 *    tests/bench/probe_point_fit.c on 4743 points of a flat-lit pipe and
 *    11075 of the rack's shadowed limbs: 1.85 on both), and a line's
 *    offset error is the mean of its independent points' (refine_step 3),
 *    so the line's ratio is the points' 1.85. Each RMS over NFRAMES x 2
 *    lines is uncertain by 1 / sqrt(2 * 48) = 10 %, the two share the
 *    pixels' noise (correlated, so the ratio scatters less): 1.85 within
 *    -20 % / +25 %, about 2 sd of two independent RMS;
 *  - the bias not worse: |mean| on <= |mean| off + 3 standard errors;
 *  - the poses with the fit within their own (smaller) sigma: RMS of
 *    distance error / sigma_distance over the frames at most 1.6 (as
 *    tests/lib/test_rescan.c: chi-square of NFRAMES terms at 99.9 %, 1.46,
 *    with the renderer's flat-light bias on top).
 * Without the fit the ratio is 1 and every case fails.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <stdio.h>
#include <cmocka.h>
#include "support.h"

#define W 1024
#define H 768
#define FOC 1000.0
#define NFRAMES 24
#define RATIO 1.85
/* the pooled line offset ratio (geometric mean over the cases): 2 sd of
 * its scatter, the per-case ratios' ~0.4 (measured 1.40-2.41) over 4 */
#define RATIO_LO (RATIO - 0.4)
#define RATIO_HI (RATIO + 0.4)
/* each case's: at least 1.85 - 0.4 x 1.2 (3 sd of one case) */
#define CASE_LO 1.25
/* the points' residual RMS about their line, pooled over 2 x NFRAMES x
 * pipes lines of ~300 points: its ratio is the points' noise ratio itself,
 * within 10 % (the probe's per-contour ratios 1.7-2.0) */
#define RES_LO (0.9 * RATIO)
#define RES_HI (1.1 * RATIO)

static cdsp_frame_ws ws;
static cdsp_frame_all_ws aws;

typedef struct {
    const char *name;
    int pipes;       /* 1: cdsp_frame_solve; 2: a rack, cdsp_frame_solve_all */
    double k1;       /* radial distortion */
    double roll_deg; /* the axes' angle in the image from the x axis */
    double contrast; /* pipe level above the background, gray levels */
    double noise;    /* gray levels */
} pf_case;

static const pf_case cases[] = {
    {"single, near horizontal, contrast 110, noise 2", 1, 0, 8, 110, 2},
    {"single, near vertical, contrast 40, noise 3", 1, 0, 80, 40, 3},
    {"single, near vertical, distorted, contrast 60, noise 3", 1, -0.15, 80, 60, 3},
    {"rack of two, contrast 60, noise 3", 2, 0, -5, 60, 3},
};

static int verbose(void)
{
    const char *v = getenv("CDSP_TEST_VERBOSE");
    return v && *v && strcmp(v, "0") != 0;
}

/* the case's scene: sup_row_scene's, at the case's contrast and noise */
static void scene(const pf_case *pc, const double c[2][3], const double v[3], cdsp_scene *s)
{
    sup_row_scene(pc->pipes, c, v, s);
    s->blur_sigma_px = (cdsp_real)0.8;
    s->background_level = (cdsp_real)0.25;
    s->pipe_level = (cdsp_real)(0.25 + pc->contrast / 255);
    s->noise_sigma = (cdsp_real)(pc->noise / 255);
}

typedef struct {
    double s1, s2, z2, r2;
    int n, nz;
} tally;

/* r's contours' offset errors (px, toward the pipe) at the foot on each
 * true line of the image of the axis point c; and its distance error over
 * its sigma */
static void add(tally *t, const cdsp_camera *cam, const cdsp_result *r, const double c[3], const double v[3])
{
    double l[2][3], p_in[2], q[2];
    int k, j;
    assert_true(sup_contour_lines(cam, c, v, 8, l, p_in));
    q[0] = (double)cam->fx * c[0] / c[2] + (double)cam->cx;
    q[1] = (double)cam->fy * c[1] / c[2] + (double)cam->cy;
    for (k = 0; k < 2; k++) {
        double dq = l[k][0] * q[0] + l[k][1] * q[1] + l[k][2], f[2], best = 1e9;
        f[0] = q[0] - dq * l[k][0];
        f[1] = q[1] - dq * l[k][1];
        for (j = 0; j < 2; j++) {
            double a = (double)r->lines[j][0], b = (double)r->lines[j][1], cc = (double)r->lines[j][2], nn = sqrt(a * a + b * b), e;
            if (a * l[k][0] + b * l[k][1] < 0)
                nn = -nn;
            if (fabs(a * l[k][0] + b * l[k][1]) < 0.999 * fabs(nn))
                continue;
            e = (a * f[0] + b * f[1] + cc) / nn; /* the true line's foot, from the result's line */
            if (fabs(e) < fabs(best))
                best = e;
        }
        if (!(fabs(best) < 2))
            fail_msg("no result line within 2 px of true contour %d", k);
        /* the result's line is at -best along the true normal */
        t->s1 -= best;
        t->s2 += best * best;
        t->n++;
    }
    {
        double e = ((double)r->distance - sup_true_distance(c, v)) / (double)r->sigma_distance;
        t->z2 += e * e;
        t->nz++;
        t->r2 += (double)r->rms[0] * (double)r->rms[0] + (double)r->rms[1] * (double)r->rms[1];
    }
}

static void test_pointfit_noise(void **state)
{
    size_t ci;
    int bad = 0, nlog = 0;
    double logsum = 0;
    (void)state;
    for (ci = 0; ci < sizeof cases / sizeof cases[0]; ci++) {
        const pf_case *pc = &cases[ci];
        tally t[2]; /* [mode] over the case's pipes */
        cdsp_camera cam;
        double c[2][3], v[3], mean[2], sd[2], ratio, z, rr;
        int f, k, m;
        memset(t, 0, sizeof t);
        sup_camera(&cam, W, H, FOC, pc->k1, 0);
        sup_row_pipes(pc->pipes, pc->roll_deg, c, v);
        for (f = 0; f < NFRAMES; f++) {
            cdsp_scene s;
            cdsp_image img;
            void *buf;
            scene(pc, (const double(*)[3])c, v, &s);
            buf = sup_render(&s, &cam, 8, 1300 + (uint64_t)f, &img);
            assert_non_null(buf);
            for (m = 0; m < 2; m++) {
                cdsp_params p;
                cdsp_result out[CDSP_MAX_PIPES];
                cdsp_rng rng;
                size_t n = 0;
                cdsp_params_default(&p);
                p.refine_step = 3;
                p.point_fit = m;
                cdsp_rng_seed(&rng, 5, (uint64_t)f);
                if (pc->pipes == 1) {
                    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &p, NULL, &ws, &rng, &out[0]), CDSP_OK);
                    n = 1;
                } else {
                    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &p, NULL, &aws, &rng, out,
                                                          CDSP_MAX_PIPES, &n),
                                     CDSP_OK);
                }
                for (k = 0; k < pc->pipes; k++) {
                    int i = sup_find_axis(out, n, c[k], v, 5);
                    if (i < 0)
                        fail_msg("%s, frame %d, point_fit %d: pipe %d not found", pc->name, f, m, k);
                    add(&t[m], &cam, &out[i], c[k], v);
                }
            }
            free(buf);
        }
        for (m = 0; m < 2; m++) {
            mean[m] = t[m].s1 / t[m].n;
            sd[m] = sqrt(t[m].s2 / t[m].n - mean[m] * mean[m]);
        }
        ratio = sd[0] / sd[1];
        rr = sqrt(t[0].r2 / t[1].r2);
        z = sqrt(t[1].z2 / t[1].nz);
        logsum += log(ratio);
        nlog++;
        if (verbose())
            printf("%s: points' residual / %.2f (derived %.2f); line offset noise %.4f -> %.4f px (/ %.2f), "
                   "bias %+.4f -> %+.4f px; distance error / sigma RMS %.2f -> %.2f\n",
                   pc->name, rr, RATIO, sd[0], sd[1], ratio, mean[0], mean[1], sqrt(t[0].z2 / t[0].nz), z);
        if (!(rr >= RES_LO && rr <= RES_HI))
            bad++, print_error("%s: points' residual RMS / %.2f with the point fit, not %.2f (%.2f .. %.2f)\n",
                               pc->name, rr, RATIO, RES_LO, RES_HI);
        if (!(ratio >= CASE_LO))
            bad++, print_error("%s: line offset noise / %.2f with the point fit, below %.2f\n", pc->name, ratio,
                               CASE_LO);
        if (!(fabs(mean[1]) <= fabs(mean[0]) + 3 * sd[1] / sqrt((double)t[1].n)))
            bad++, print_error("%s: offset bias %+.4f px with the point fit, %+.4f without\n", pc->name, mean[1], mean[0]);
        if (!(z <= 1.6))
            bad++, print_error("%s: with the point fit distance error / sigma RMS %.2f, above 1.6\n", pc->name, z);
    }
    {
        double g = exp(logsum / nlog);
        if (verbose())
            printf("pooled: line offset noise / %.2f with the point fit (derived %.2f)\n", g, RATIO);
        if (!(g >= RATIO_LO && g <= RATIO_HI))
            bad++, print_error("pooled line offset noise / %.2f with the point fit, not %.2f (%.2f .. %.2f)\n", g,
                               RATIO, RATIO_LO, RATIO_HI);
    }
    assert_int_equal(bad, 0);
}

/* point_fit's range (include/cdsp.h): 0 or 1, 0 by default, 1 only with
 * refine_step on (without the final pass it would refit nothing) */
static void test_pointfit_params(void **state)
{
    cdsp_params p;
    cdsp_camera cam;
    cdsp_image img;
    cdsp_result r;
    cdsp_rng rng;
    static uint8_t px[64 * 48];
    (void)state;
    cdsp_params_default(&p);
    assert_int_equal(p.point_fit, 0);
    sup_camera(&cam, 64, 48, 60, 0, 0);
    img.data = px;
    img.width = 64;
    img.height = 48;
    img.stride = 64;
    img.bits = 8;
    cdsp_rng_seed(&rng, 1, 1);
    p.point_fit = 1;
    assert_int_equal(cdsp_params_check(&p), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &p, NULL, &ws, &rng, &r), CDSP_E_ARG);
    p.refine_step = 3;
    assert_int_equal(cdsp_params_check(&p), CDSP_OK);
    p.point_fit = 2;
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &p, NULL, &ws, &rng, &r), CDSP_E_ARG);
    p.point_fit = -1;
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &p, NULL, &ws, &rng, &r), CDSP_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pointfit_params),
        cmocka_unit_test(test_pointfit_noise),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
