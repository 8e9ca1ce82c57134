/*
 * fuzz_frame.c - libcdsp's frame entry points fed arbitrary frames: size
 * (1..96 px each way), stride (padding 0..7 bytes, sometimes too short),
 * bit depth (0..17: every accepted one and the refused ones around them),
 * every accepted parameter value and some refused ones (step, half_window,
 * min_contrast, roi with extreme ints, track_band_px, polarity, distance
 * bounds), a camera with fuzzed intrinsics and distortion, a radius, and
 * a fuzzed prior for the tracking path. Pixels are the rest of the input.
 * A call that returns CDSP_OK must give finite poses.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp.h"
#include "fuzz_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static cdsp_frame_ws ws;
static uint8_t pixels[96 * (96 * 2 + 8)];

static int result_finite(const cdsp_result *r)
{
    int i;
    for (i = 0; i < 3; i++)
        if (!isfinite((double)r->point[i]) || !isfinite((double)r->direction[i]) ||
            !isfinite((double)r->sigma_point[i]) || !isfinite((double)r->sigma_direction[i]))
            return 0;
    return isfinite((double)r->distance) && isfinite((double)r->sigma_distance);
}

static int fz_roi_int(fz_in *in)
{
    static const int special[] = {0, 1, -1, 2147483647, -2147483647 - 1, 48, 96};
    uint8_t s = fz_u8(in);
    return s < 7 ? special[s] : (int)fz_range(in, -200, 200);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    cdsp_image img;
    cdsp_camera cam;
    cdsp_params p;
    cdsp_result prior, r;
    cdsp_rng rng;
    cdsp_status st;
    int w = (int)fz_range(&in, 1, 96), h = (int)fz_range(&in, 1, 96);
    int bits = (int)fz_range(&in, 0, 17), bpp = bits <= 8 ? 1 : 2, pad = (int)fz_range(&in, -1, 7);
    size_t stride = (size_t)w * (size_t)bpp + (size_t)(pad < 0 ? 0 : pad), need, k;
    uint8_t flags = fz_u8(&in);
    double radius;

    if (pad < 0 && stride > 0)
        stride--; /* one byte short: refused with CDSP_E_FORMAT */
    cdsp_params_default(&p);
    p.edge.step = (int)fz_range(&in, 0, 70);
    p.edge.half_window = (int)fz_range(&in, 1, 9);
    p.edge.min_contrast = (cdsp_real)fz_real(&in, 0, 1);
    if (flags & 1) {
        p.edge.roi.x = fz_roi_int(&in);
        p.edge.roi.y = fz_roi_int(&in);
        p.edge.roi.w = fz_roi_int(&in);
        p.edge.roi.h = fz_roi_int(&in);
    }
    p.track_band_px = (cdsp_real)fz_real(&in, 0, 100);
    p.track_min_inliers = (int)fz_range(&in, 0, 60);
    p.pair.polarity = (int)fz_range(&in, -1, 1);
    if (flags & 2) {
        p.pair.min_distance = (cdsp_real)fz_real(&in, 0, 1000);
        p.pair.max_distance = (cdsp_real)fz_real(&in, 0, 5000);
        p.pair.min_inliers = (int)fz_range(&in, 0, 40);
        p.pair.inlier_px = (cdsp_real)fz_real(&in, 0, 4);
    }
    /* the final pass (lib/rescan.c) and its point fit: 0..8 and 0..2, so
     * the refused values (1, 2; point_fit 2) are tried too */
    p.refine_step = (int)fz_range(&in, 0, 8);
    p.point_fit = (int)fz_range(&in, 0, 2);
    memset(&cam, 0, sizeof cam);
    cam.width = w;
    cam.height = h;
    cam.fx = (cdsp_real)(flags & 4 ? fz_real(&in, 1, 500) : 60);
    cam.fy = (cdsp_real)(flags & 4 ? fz_real(&in, 1, 500) : 60);
    cam.cx = (cdsp_real)(flags & 8 ? fz_real(&in, -10, 100) : w / 2.0);
    cam.cy = (cdsp_real)(flags & 8 ? fz_real(&in, -10, 100) : h / 2.0);
    if (flags & 16) {
        cam.k1 = (cdsp_real)fz_real(&in, -1, 1);
        cam.k2 = (cdsp_real)fz_real(&in, -1, 1);
        cam.p1 = (cdsp_real)fz_real(&in, -0.1, 0.1);
        cam.p2 = (cdsp_real)fz_real(&in, -0.1, 0.1);
        cam.k3 = (cdsp_real)fz_real(&in, -1, 1);
    }
    radius = flags & 32 ? fz_real(&in, 0, 100) : 5;
    memset(&prior, 0, sizeof prior);
    for (k = 0; k < 3; k++) {
        prior.lines[0][k] = (cdsp_real)fz_real(&in, -100, 100);
        prior.lines[1][k] = (cdsp_real)fz_real(&in, -100, 100);
        prior.direction[k] = (cdsp_real)fz_real(&in, -1, 1);
    }
    need = stride * (size_t)h;
    memset(pixels, 0, need);
    memcpy(pixels, in.p, in.n < need ? in.n : need);
    if (bpp == 2 && bits >= 1) /* values beyond 2^bits - 1 too: the frame is the sensor's */
        for (k = 0; k + 1 < need; k += 2)
            if (flags & 64)
                pixels[k + 1] &= (uint8_t)((1u << (bits - 8)) - 1u);
    img.data = pixels;
    img.width = w;
    img.height = h;
    img.stride = stride;
    img.bits = bits;

    {
        size_t n;
        static cdsp_edge edges[CDSP_MAX_EDGES];
        st = cdsp_edges_detect(&img, &p.edge, edges, (flags & 128) ? 7 : CDSP_MAX_EDGES, &n);
        if (st == CDSP_OK || st == CDSP_E_CAPACITY) {
            for (k = 0; k < n; k++)
                if (!isfinite((double)edges[k].x) || !isfinite((double)edges[k].y) ||
                    edges[k].x < -1 || edges[k].x > w || edges[k].y < -1 || edges[k].y > h)
                    abort(); /* an edge outside the frame it was found in */
            if (cdsp_camera_check(&cam) == CDSP_OK)
                (void)cdsp_camera_undistort_edges(&cam, edges, &n);
        }
    }
    cdsp_rng_seed(&rng, 1, 1);
    st = cdsp_frame_solve(&img, &cam, (cdsp_real)radius, &p, NULL, &ws, &rng, &r);
    if (st == CDSP_OK && !result_finite(&r))
        abort();
    st = cdsp_frame_solve(&img, &cam, (cdsp_real)radius, &p, &prior, &ws, &rng, &r);
    if (st == CDSP_OK && !result_finite(&r))
        abort();
    return 0;
}
