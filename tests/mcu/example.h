/*
 * example.h - the firmware example's interface (example.c): what it calls
 * in the application and what the application calls in it.
 */
#ifndef CDSP_TESTS_MCU_EXAMPLE_H
#define CDSP_TESTS_MCU_EXAMPLE_H

#include "cdsp.h"

/* Provided by the application. */
size_t app_read_edges(cdsp_edge *buf, size_t cap);  /* undistorted edge points */
const void *app_frame(int *width, int *height);     /* latest 8-bit frame */
void app_publish_pose(const cdsp_result *pose);
void app_no_pipe(const char *why);
void app_fault(const char *what);

/* Provided by example.c. */
void pipe_init(const cdsp_camera *calibration);
void pipe_points_step(void);
void pipe_frame_step(void);

#endif
