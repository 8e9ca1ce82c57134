/*
 * sim_path.h - the pose the simulated camera (src_sim.c) shows in each
 * frame: a pure function of the sim.* keys and the frame number, so a
 * receiver that reads the same configuration knows the ground truth of
 * every datagram (tests/daemon).
 *
 * The path: sim.frames poses at phases a_k = 2 pi k / frames, k = 0 ..
 * frames-1; frame n shows pose k = n mod frames. At phase a:
 *   point     = center + (sway_x sin a, sway_y sin 2a, sway_z cos a)
 *   direction = Rz(tilt_deg sin a) Rx(nod_deg cos a) direction0 (unit)
 * and for k >= frames (1 - away) the pipe is out of view (no pipe).
 */
#ifndef CDSPD_SIM_PATH_H
#define CDSPD_SIM_PATH_H

#include <stdint.h>

#include "config.h"

/* Ring slot of frame n. */
int cdspd_sim_slot(const cdspd_config *c, uint64_t frame);

/* Pose of slot k: returns 1 and fills point (on the axis) and unit dir when
 * the pipe is in view, 0 when the slot is in the away part of the path. */
int cdspd_sim_pose(const cdspd_config *c, int slot, double point[3], double dir[3]);

/* Ground truth of frame n as the solver reports it: returns 1 and the foot
 * of the perpendicular from the optical centre (P_C), the unit direction
 * with the library's sign rule and |P_C| when the pipe is in view, else 0
 * (nothing filled). cdsp_host_axis_truth does the geometry. */
int cdspd_sim_truth(const cdspd_config *c, uint64_t frame, double foot[3], double dir[3],
                    double *distance);

/* The scene of slot k as cdsp_render draws it: the pose above (out of
 * view: the pipe lies behind the camera), radius, and the sim.* look
 * (ambient, noise, blur, texture); libcdsp's defaults otherwise. */
void cdspd_sim_scene(const cdspd_config *c, int slot, cdsp_scene *s);

#endif
