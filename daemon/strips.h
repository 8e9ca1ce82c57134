/*
 * strips.h - one frame's full search spread over several cores
 * (solver.threads, issue 17): a fixed pool of worker threads, each scanning
 * its strip of the frame (cdsp_edges_detect_strip) into its own buffer, the
 * calling thread scanning strip 0 and merging (cdsp_edges_merge_strips).
 * The result is cdsp_edges_detect's, bit for bit, so a full search through
 * cdsp_frame_prepare, cdspd_strips_detect and cdsp_frame_solve_detected
 * gives the pose cdsp_frame_solve gives on one core.
 */
#ifndef CDSPD_STRIPS_H
#define CDSPD_STRIPS_H

#include <stddef.h>
#include "cdsp.h"

typedef struct cdspd_strips cdspd_strips;

/* threads (1..CDSP_EDGE_MAX_STRIPS) strips, threads - 1 workers started;
 * 0, or -1 with err filled (out of memory, no thread). */
int cdspd_strips_start(cdspd_strips **out, int threads, char *err, size_t errlen);
/* Stops and joins the workers, frees everything (NULL: nothing). */
void cdspd_strips_stop(cdspd_strips *s);
/* cdsp_edges_detect's contract and result, in strips. One call at a time. */
cdsp_status cdspd_strips_detect(cdspd_strips *s, const cdsp_image *img, const cdsp_edge_params *p,
                                cdsp_edge *out, size_t cap, size_t *n);

#endif
