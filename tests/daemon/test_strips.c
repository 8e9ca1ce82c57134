/*
 * test_strips.c - solver.threads (daemon/strips.c, issue 17): the pose of a
 * frame whose full search ran in strips on 2..5 threads is the one core's,
 * every byte of the cdsp_result, on rendered frames (a pipe with clutter
 * bars and texture at 1280 x 960, 8 and 12 bit), with the pool reused from
 * frame to frame (tracked frames stay on one core: nothing to compare).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "strips.h"

static cdsp_frame_ws ws;

static void *render(int bits, double tilt, cdsp_camera *cam, cdsp_image *img)
{
    cdsp_scene s;
    cdsp_rng rng;
    size_t nscr, bpp = bits <= 8 ? 1 : 2;
    float *scr;
    void *buf;
    int k;
    memset(cam, 0, sizeof *cam);
    cam->fx = cam->fy = 1100;
    cam->cx = (1280 - 1) / 2.0;
    cam->cy = (960 - 1) / 2.0;
    cam->k1 = (cdsp_real)-0.05;
    cam->width = 1280;
    cam->height = 960;
    cdsp_scene_default(&s);
    s.axis_point[0] = 5;
    s.axis_point[1] = -3;
    s.axis_point[2] = 400;
    s.axis_dir[0] = (cdsp_real)tilt;
    s.axis_dir[1] = 1;
    s.axis_dir[2] = (cdsp_real)0.2;
    s.radius = 8;
    s.texture = (cdsp_real)0.15;
    s.noise_sigma = (cdsp_real)0.003;
    s.n_clutter = 2;
    for (k = 0; k < 2; k++) {
        s.clutter[k].p0[0] = (cdsp_real)(-150 + 90 * k);
        s.clutter[k].p0[1] = (cdsp_real)(-100 + 40 * k);
        s.clutter[k].p0[2] = 450;
        s.clutter[k].p1[0] = (cdsp_real)(140 - 30 * k);
        s.clutter[k].p1[1] = (cdsp_real)(90 - 120 * k);
        s.clutter[k].p1[2] = 450;
        s.clutter[k].half_width = 5;
        s.clutter[k].level = (cdsp_real)(0.25 + 0.4 * k);
    }
    nscr = cdsp_render_scratch_size(cam->width, cam->height);
    scr = malloc(nscr * sizeof *scr);
    buf = malloc((size_t)cam->width * (size_t)cam->height * bpp);
    assert_non_null(scr);
    assert_non_null(buf);
    cdsp_rng_seed(&rng, 11, 7);
    assert_int_equal(cdsp_render(&s, cam, buf, 0, bits, scr, nscr, &rng), CDSP_OK);
    free(scr);
    img->data = buf;
    img->width = cam->width;
    img->height = cam->height;
    img->stride = (size_t)cam->width * bpp;
    img->bits = bits;
    return buf;
}

static void test_threads_equal_one_core(void **state)
{
    static const struct {
        int bits;
        double tilt;
    } frames[] = {{8, 0.3}, {12, 1.2}, {8, -0.6}};
    int threads, ok = 0;
    size_t f;
    (void)state;
    for (threads = 2; threads <= 5; threads++) {
        cdspd_strips *s;
        char err[256];
        assert_int_equal(cdspd_strips_start(&s, threads, err, sizeof err), 0);
        for (f = 0; f < sizeof frames / sizeof frames[0]; f++) {
            cdsp_camera cam;
            cdsp_image img;
            cdsp_params prm;
            cdsp_result a, b;
            cdsp_rng ra, rb;
            cdsp_frame_edges fe;
            cdsp_status sa, sb;
            void *buf = render(frames[f].bits, frames[f].tilt, &cam, &img);
            cdsp_params_default(&prm);
            memset(&a, 0, sizeof a);
            memset(&b, 0, sizeof b);
            cdsp_rng_seed(&ra, 1, 1);
            cdsp_rng_seed(&rb, 1, 1);
            sa = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &ra, &a);
            assert_int_equal(cdsp_frame_prepare(&img, &prm, &fe), CDSP_OK);
            fe.status = cdspd_strips_detect(s, &img, &fe.edge, ws.edge, CDSP_MAX_EDGES, &fe.n);
            sb = cdsp_frame_solve_detected(&img, &cam, 8, &prm, &fe, &ws, &rb, &b);
            assert_int_equal(sa, sb);
            assert_memory_equal(&a, &b, sizeof a);
            ok += sa == CDSP_OK;
            free(buf);
        }
        cdspd_strips_stop(s);
    }
    /* the frames hold a pipe the full search finds: poses were compared */
    assert_true(ok >= 8);
}

static void test_bad_thread_count(void **state)
{
    cdspd_strips *s = (cdspd_strips *)1;
    char err[256];
    (void)state;
    assert_int_equal(cdspd_strips_start(&s, 0, err, sizeof err), -1);
    assert_null(s);
    assert_int_equal(cdspd_strips_start(&s, CDSP_EDGE_MAX_STRIPS + 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "solver.threads"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threads_equal_one_core),
        cmocka_unit_test(test_bad_thread_count),
    };
    return cmocka_run_group_tests_name("strips", tests, NULL, NULL);
}
