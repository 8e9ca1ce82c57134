/*
 * fakecam_path.h - what the fake GigE Vision camera (cdsp_fakecam) shows in
 * frame N: the camera model, the scene and the pipe's pose, all a pure
 * function of the frame id. The fake camera renders with it, and a test on
 * the receiving side (tests/fakecam/arv_probe.c, the daemon's end-to-end
 * test) includes the same header to know the ground truth of every frame it
 * receives, or to redraw the frame and compare pixels. Sender and receiver
 * must agree on the camera's --cycle (0 unless the test says otherwise).
 *
 * Frame ids: GVSP (GigE Vision 1.x) carries a 16-bit block id, and the fake
 * camera's counter starts at 65401, so it wraps within the first 6 s at
 * 25 fps. Everything here depends on (frame_id & 0xFFFF) only, so the id the
 * camera drew with and the one a client reads from ArvBuffer agree across the
 * wrap whether the client sees 16 or 64 bits. (Aravis 0.8's fake camera
 * counts 65401, 65402, ..., 65535, 1, 2, ...: 0 is not a valid block id.)
 *
 * Geometry (camera frame of cdsp.h: X right, Y down, Z forward, mm):
 * a pipe of radius FAKECAM_RADIUS, infinite, seen at 350..550 mm, drifting
 * sideways by +-40 mm and tilting by +-20 degrees in the image plane and
 * +-8.5 degrees towards the camera, with a period of FAKECAM_PERIOD frames.
 * It stays in view at every size (the focal length scales with the width).
 *
 * Requires cdsp.h (cdsp_camera, cdsp_scene, cdsp_rng) and -lm.
 */
#ifndef FAKECAM_PATH_H
#define FAKECAM_PATH_H

#include <math.h>
#include <stdint.h>
#include <time.h>

#include "cdsp.h"

/* Pipe radius, mm: what a receiver passes as --radius. */
#define FAKECAM_RADIUS 10.0

/* Frames per period of the path. */
#define FAKECAM_PERIOD 250

/* Seed of the per-frame sensor-noise generator (stream = frame id). */
#define FAKECAM_NOISE_SEED 0x6364737066616b65ull /* "cdspfake" */

/* Camera model for a w x h frame: fx = fy = 1.25 w (about 44 degrees
 * horizontal field of view), principal point at the image centre (pixel
 * centres are integers, cdsp.h), mild barrel distortion so receivers
 * exercise their undistortion. A receiver's calibration file must hold
 * exactly these numbers. */
static inline void fakecam_camera(int w, int h, cdsp_camera *cam)
{
    cam->fx = (cdsp_real)(1.25 * w);
    cam->fy = (cdsp_real)(1.25 * w);
    cam->cx = (cdsp_real)(0.5 * (w - 1));
    cam->cy = (cdsp_real)(0.5 * (h - 1));
    cam->k1 = (cdsp_real)-0.05;
    cam->k2 = (cdsp_real)0.01;
    cam->p1 = cam->p2 = cam->k3 = (cdsp_real)0;
    cam->width = w;
    cam->height = h;
}

/* The path position frame frame_id shows, 0..65535. cycle = 0: every frame
 * id its own position (the pose repeats every FAKECAM_PERIOD ids, the noise
 * never within the 16-bit id range). cycle = N > 0 (cdsp_fakecam --cycle N):
 * only N frames, evenly spread over one period, shown in turn, so the
 * camera can keep them rendered and serve at full rate at any size. */
static inline uint32_t fakecam_phase(uint64_t frame_id, unsigned cycle)
{
    uint32_t id = (uint32_t)(frame_id & 0xFFFFu);
    if (cycle == 0)
        return id;
    return (uint32_t)((uint64_t)(id % cycle) * FAKECAM_PERIOD / cycle);
}

/* Ground truth of frame frame_id (with the camera's --cycle): a point on
 * the axis and the axis's unit direction, camera frame, mm. The point is
 * the axis's crossing with the plane Y = 0. */
static inline void fakecam_pose(uint64_t frame_id, unsigned cycle, double point[3], double dir[3])
{
    const double two_pi = 6.283185307179586;
    double a = two_pi * (double)(fakecam_phase(frame_id, cycle) % FAKECAM_PERIOD) / FAKECAM_PERIOD;
    double tilt = 0.35 * sin(a);        /* in the image plane, rad */
    double d[3], n;

    point[0] = 40.0 * sin(2.0 * a);
    point[1] = 0.0;
    point[2] = 450.0 + 100.0 * sin(a);
    d[0] = sin(tilt);
    d[1] = cos(tilt);
    d[2] = 0.15 * cos(a);
    n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    dir[0] = d[0] / n;
    dir[1] = d[1] / n;
    dir[2] = d[2] / n;
}

/* Everything cdsp_render needs to draw frame frame_id at w x h:
 * the camera, the scene (libcdsp's defaults: shading, background texture,
 * 0.7 px blur, 0.4 % noise; the pose above) and the noise generator seeded
 * for this frame. Render with
 *   cdsp_render(&scene, &cam, out, stride, bits, scratch,
 *               cdsp_render_scratch_size(w, h), &rng)
 * bits 8 (Mono8) or 16 (Mono16, full 16-bit range, little-endian host). */
static inline void fakecam_frame(uint64_t frame_id, unsigned cycle, int w, int h,
                                 cdsp_camera *cam, cdsp_scene *scene, cdsp_rng *rng)
{
    double p[3], v[3];
    int i;

    fakecam_camera(w, h, cam);
    cdsp_scene_default(scene);
    fakecam_pose(frame_id, cycle, p, v);
    for (i = 0; i < 3; i++) {
        scene->axis_point[i] = (cdsp_real)p[i];
        scene->axis_dir[i] = (cdsp_real)v[i];
    }
    scene->radius = (cdsp_real)FAKECAM_RADIUS;
    scene->half_length = (cdsp_real)0;
    cdsp_rng_seed(rng, FAKECAM_NOISE_SEED, (uint64_t)fakecam_phase(frame_id, cycle));
}

/* The fake camera's own clock, stamped into every frame (the GVSP
 * leader's timestamp): the host's CLOCK_MONOTONIC plus
 * FAKECAM_CLOCK_OFFSET_US, so a receiver can tell the camera's time
 * (t_camera_us - t_host_us = the offset, less the transfer time) from the
 * host's arrival time (t_host_us). Needs clock_gettime (POSIX). */
#define FAKECAM_CLOCK_OFFSET_US 1000000000000ull /* 11.6 days */

static inline uint64_t fakecam_clock_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec + FAKECAM_CLOCK_OFFSET_US * 1000u;
}

#endif /* FAKECAM_PATH_H */
