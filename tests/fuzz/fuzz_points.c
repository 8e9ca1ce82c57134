/*
 * fuzz_points.c - libcdsp's geometric entry points fed arbitrary numbers
 * (NaN, Inf, huge, tiny, duplicates): edge points for cdsp_line_fit and
 * cdsp_points_solve (a pool of fuzzed values, some points repeated), two
 * lines and a pixel for cdsp_axis_solve, a camera for distort / undistort
 * / project / undistort_edges, a 3x3 matrix for cdsp_svd3, a cylinder for
 * cdsp_cylinder_contours, and a small scene for cdsp_render. Whatever
 * returns CDSP_OK must have written finite numbers.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp.h"
#include "fuzz_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static cdsp_points_ws pws;
static cdsp_edge pts[CDSP_MAX_POINTS];
static float scratch[24 * 16 * 2];

static int fin(const cdsp_real *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite((double)v[i]))
            return 0;
    return 1;
}

static void take_camera(fz_in *in, cdsp_camera *cam)
{
    memset(cam, 0, sizeof *cam);
    cam->width = (int)fz_range(in, -1, 40);
    cam->height = (int)fz_range(in, -1, 40);
    cam->fx = (cdsp_real)fz_real(in, 1, 1000);
    cam->fy = (cdsp_real)fz_real(in, 1, 1000);
    cam->cx = (cdsp_real)fz_real(in, -100, 100);
    cam->cy = (cdsp_real)fz_real(in, -100, 100);
    cam->k1 = (cdsp_real)fz_real(in, -1, 1);
    cam->k2 = (cdsp_real)fz_real(in, -1, 1);
    cam->p1 = (cdsp_real)fz_real(in, -0.1, 0.1);
    cam->p2 = (cdsp_real)fz_real(in, -0.1, 0.1);
    cam->k3 = (cdsp_real)fz_real(in, -1, 1);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    cdsp_camera cam;
    cdsp_params p;
    cdsp_result r;
    cdsp_line line;
    cdsp_rng rng;
    cdsp_real pool[16], l1[3], l2[3], pin[2], X[3], a[2], b[2];
    size_t n, i;
    double radius;
    int k;

    take_camera(&in, &cam);
    if (cam.width < 1 || cam.height < 1) { /* a sane camera half the time */
        cam.width = 640;
        cam.height = 480;
        cam.fx = cam.fy = 500;
        cam.cx = 320;
        cam.cy = 240;
        cam.k1 = cam.k2 = cam.p1 = cam.p2 = cam.k3 = 0;
    }
    radius = fz_real(&in, 0, 50);
    for (k = 0; k < 16; k++)
        pool[k] = (cdsp_real)fz_real(&in, -1000, 1000);
    /* points from the pool (duplicates by construction), or from the
     * bytes as raw doubles */
    n = (size_t)fz_range(&in, 0, CDSP_MAX_POINTS + 2);
    for (i = 0; i < n && i < CDSP_MAX_POINTS; i++) {
        uint8_t s = fz_u8(&in);
        if (in.n == 0 && i > 0) {
            pts[i] = pts[i % (i > 8 ? 8 : i)];
            continue;
        }
        pts[i].x = pool[s & 15];
        pts[i].y = pool[(s >> 4) & 15];
        pts[i].gx = (cdsp_real)fz_real(&in, -100, 100);
        pts[i].gy = (cdsp_real)fz_real(&in, -100, 100);
    }
    cdsp_params_default(&p);
    cdsp_rng_seed(&rng, 1, 1);
    if (cdsp_line_fit(pts, NULL, n < CDSP_MAX_POINTS ? n : CDSP_MAX_POINTS, &line) == CDSP_OK &&
        !fin(line.l, 3))
        abort();
    if (cdsp_points_solve(&cam, (cdsp_real)radius, pts, n, &p, NULL, &pws, &rng, &r) == CDSP_OK &&
        (!fin(r.point, 3) || !fin(r.direction, 3) || !fin(r.sigma_point, 3)))
        abort();
    for (k = 0; k < 3; k++) {
        l1[k] = (cdsp_real)fz_real(&in, -1, 1);
        l2[k] = (cdsp_real)fz_real(&in, -1, 1);
        X[k] = (cdsp_real)fz_real(&in, -1000, 1000);
    }
    pin[0] = (cdsp_real)fz_real(&in, -100, 800);
    pin[1] = (cdsp_real)fz_real(&in, -100, 600);
    if (cdsp_axis_solve(&cam, l1, l2, pin, (cdsp_real)radius, &r) == CDSP_OK) {
        if (!fin(r.point, 3) || !fin(r.direction, 3) || !isfinite((double)r.distance))
            abort();
        (void)cdsp_result_point_distance(&r, X);
    }
    a[0] = (cdsp_real)fz_real(&in, -100, 800);
    a[1] = (cdsp_real)fz_real(&in, -100, 600);
    if (cdsp_camera_distort(&cam, a, b) == CDSP_OK && !fin(b, 2))
        abort();
    (void)cdsp_camera_undistort(&cam, a, b);
    if (cdsp_camera_project(&cam, X, b) == CDSP_OK && !fin(b, 2))
        abort();
    n = n < CDSP_MAX_POINTS ? n : CDSP_MAX_POINTS;
    (void)cdsp_camera_undistort_edges(&cam, pts, &n);
    {
        cdsp_real A[9], U[9], S[3], V[9];
        for (k = 0; k < 9; k++)
            A[k] = pool[(size_t)fz_u8(&in) & 15];
        if (cdsp_svd3(A, U, S, V) == CDSP_OK && (!fin(U, 9) || !fin(S, 3) || !fin(V, 9)))
            abort();
    }
    {
        cdsp_real dir[3], c1[3], c2[3], cin[2];
        memcpy(dir, l1, sizeof dir);
        if (cdsp_cylinder_contours(&cam, X, dir, (cdsp_real)radius, fz_u8(&in) & 1, c1, c2, cin) ==
                CDSP_OK &&
            (!fin(c1, 3) || !fin(c2, 3) || !fin(cin, 2)))
            abort();
    }
    {
        /* a small frame of a fuzzed scene */
        static uint8_t out[24 * 16 * 2];
        cdsp_scene s;
        cdsp_camera small = cam;
        int bits = (int)fz_range(&in, 0, 17);
        small.width = 24;
        small.height = 16;
        if (cdsp_camera_check(&small) != CDSP_OK) { /* else the render stops at the camera */
            small.fx = small.fy = 20;
            small.cx = 12;
            small.cy = 8;
            small.k1 = small.k2 = small.p1 = small.p2 = small.k3 = 0;
        }
        cdsp_scene_default(&s);
        for (k = 0; k < 3; k++) {
            s.axis_point[k] = pool[(size_t)fz_u8(&in) & 15];
            s.axis_dir[k] = (cdsp_real)fz_real(&in, -1, 1);
            s.light[k] = (cdsp_real)fz_real(&in, -1, 1);
        }
        s.radius = (cdsp_real)radius;
        s.half_length = (cdsp_real)fz_real(&in, 0, 100);
        s.pipe_level = (cdsp_real)fz_real(&in, 0, 1);
        s.background_level = (cdsp_real)fz_real(&in, 0, 1);
        s.texture = (cdsp_real)fz_real(&in, 0, 1);
        s.texture_scale_px = (cdsp_real)fz_real(&in, 0, 100);
        s.blur_sigma_px = (cdsp_real)fz_real(&in, 0, 9);
        s.noise_sigma = (cdsp_real)fz_real(&in, 0, 0.1);
        s.n_clutter = (int)fz_range(&in, -1, CDSP_RENDER_MAX_CLUTTER + 1);
        for (k = 0; k < CDSP_RENDER_MAX_CLUTTER; k++) {
            s.clutter[k].p0[0] = pool[(size_t)fz_u8(&in) & 15];
            s.clutter[k].p1[2] = pool[(size_t)fz_u8(&in) & 15];
            s.clutter[k].half_width = (cdsp_real)fz_real(&in, 0, 10);
            s.clutter[k].level = (cdsp_real)fz_real(&in, 0, 1);
        }
        cdsp_rng_seed(&rng, 2, 1);
        (void)cdsp_render(&s, &small, out, 0, bits, scratch, sizeof scratch / sizeof scratch[0],
                          &rng);
    }
    return 0;
}
