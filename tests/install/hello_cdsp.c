/*
 * hello_cdsp.c - the smallest program against an installed libcdsp
 * (tests/install/check.sh builds it with `pkg-config --cflags --libs cdsp`):
 * render a pipe with flat light, solve it, compare with the truth.
 * Tolerance: with flat light the edge detector has no shading bias, so the
 * distance lies within 6 of its own sigmas of the truth (the bound of
 * tests/daemon/cdspd_rx.c with delta = 0; measured: 0.009 mm off, 0.3
 * sigma). Exit 0 when it does.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <cdsp.h>

int main(void)
{
    static cdsp_frame_ws ws; /* large: static, as cdsp.h advises */
    static unsigned char px[480][640];
    cdsp_camera cam = {800, 800, 319.5, 239.5, 0, 0, 0, 0, 0, 640, 480};
    cdsp_scene s;
    cdsp_params p;
    cdsp_rng rng;
    cdsp_image img = {px, 640, 480, 640, 8};
    cdsp_result r;
    cdsp_status st;
    /* the axis through (0, 0, 400) along (0.1, 1, 0.05): |P_C| = 400 sin of
     * the angle between the axis and the line of sight to that point */
    const double v[3] = {0.1, 1, 0.05}, n = sqrt(0.01 + 1 + 0.0025);
    const double t = 400 * v[2] / n, truth = sqrt(400.0 * 400.0 - t * t);

    cdsp_scene_default(&s);
    s.axis_point[2] = 400;
    s.axis_dir[0] = 0.1;
    s.axis_dir[1] = 1;
    s.axis_dir[2] = 0.05;
    s.radius = 10;
    s.ambient = 1;
    s.blur_sigma_px = 0; /* no scratch needed */
    cdsp_rng_seed(&rng, 1, 0);
    st = cdsp_render(&s, &cam, px, 640, 8, NULL, 0, &rng);
    if (st != CDSP_OK) {
        fprintf(stderr, "render: %s\n", cdsp_strerror(st));
        return 1;
    }
    cdsp_params_default(&p);
    st = cdsp_frame_solve(&img, &cam, 10, &p, NULL, &ws, &rng, &r);
    if (st != CDSP_OK) {
        fprintf(stderr, "solve: %s\n", cdsp_strerror(st));
        return 1;
    }
    printf("libcdsp %d.%d.%d: distance %.3f (truth %.3f, sigma %.3f)\n", CDSP_VERSION_MAJOR,
           CDSP_VERSION_MINOR, CDSP_VERSION_PATCH, (double)r.distance, truth,
           (double)r.sigma_distance);
    return fabs((double)r.distance - truth) <= 6 * (double)r.sigma_distance ? 0 : 1;
}
