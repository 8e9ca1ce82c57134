/*
 * example.c - libcdsp linked into firmware: the example docs/mcu.md shows,
 * compiled for every Cortex-M target by `make mcu` and linked by the size
 * probes (`make size`), so the example is known to build and what it costs
 * is what the table says.
 *
 * Everything lives in static memory, sized by the CDSP_MAX_* capacities the
 * library was built with; nothing is allocated. The application supplies
 * the app_* functions (edge points from its front end, a frame from its
 * camera, where the pose goes).
 */
#include "cdsp.h"
#include "example.h"

#define PIPE_RADIUS_MM ((cdsp_real)8)

static cdsp_camera cam;            /* the calibration, loaded once */
static cdsp_params params;
static cdsp_rng rng;               /* seeded once: runs are reproducible */
static cdsp_result pose, prior;
static int have_prior;

void pipe_init(const cdsp_camera *calibration)
{
    cam = *calibration;
    cdsp_params_default(&params);
    params.pair.polarity = +1;     /* the pipe is brighter than the background */
    cdsp_rng_seed(&rng, 0x2024u, 1u);
    have_prior = 0;
}

/* Shared status handling: a pose, no pipe in view (normal), or a fault. */
static void pipe_handle(cdsp_status st)
{
    switch (st) {
    case CDSP_OK:
        app_publish_pose(&pose);
        prior = pose;              /* the next frame tracks from here */
        have_prior = 1;
        break;
    case CDSP_E_FEW_POINTS:        /* nothing pipe-like in view: not an error */
    case CDSP_E_NO_PIPE:
    case CDSP_E_DEGENERATE:        /* looking along the pipe */
        have_prior = 0;
        app_no_pipe(cdsp_status_token(st));
        break;
    default:                       /* bad calibration/parameters, NaN input */
        have_prior = 0;
        app_fault(cdsp_strerror(st));
        break;
    }
}

#ifndef EXAMPLE_NO_POINTS
/* Points -> pose: edge points from an FPGA/ISP front end, undistorted. */
static cdsp_edge edges[CDSP_MAX_POINTS];
static cdsp_points_ws points_ws;

void pipe_points_step(void)
{
    size_t n = app_read_edges(edges, CDSP_MAX_POINTS);
    pipe_handle(cdsp_points_solve(&cam, PIPE_RADIUS_MM, edges, n, &params,
                                  have_prior ? &prior : NULL, &points_ws, &rng, &pose));
}
#endif

#ifndef EXAMPLE_NO_FRAME
/* Frame -> pose: the whole pipeline on a camera frame (8-bit here). */
static cdsp_frame_ws frame_ws;     /* CDSP_MAX_EDGES edge points + labels */

void pipe_frame_step(void)
{
    cdsp_image img;
    img.data = app_frame(&img.width, &img.height);
    img.stride = (size_t)img.width;
    img.bits = 8;
    pipe_handle(cdsp_frame_solve(&img, &cam, PIPE_RADIUS_MM, &params,
                                 have_prior ? &prior : NULL, &frame_ws, &rng, &pose));
}
#endif
