/*
 * mount.h - the camera's mounting on the vehicle, and the pose of the pipe
 * in the vehicle's body frame (FRD: x forward, y right, z down, origin the
 * vehicle's reference point), as the MAVLink output and the datagrams'
 * body-frame fields give it (docs/mavlink.md).
 *
 * The mount is the camera's attitude and position in the body frame:
 *   p_body = R p_optical + t
 * with the optical frame the library's (X right, Y down, Z forward along
 * the optical axis) and t the optical centre in body coordinates, in the
 * pose unit (that of the radius: mm). R is given by the Euler angles of the
 * camera's own FRD frame (forward = optical Z, right = optical X, down =
 * optical Y) in the body, aerospace order (yaw about z, then pitch about the
 * new y, then roll about the new x: R_frd = Rz(yaw) Ry(pitch) Rx(roll)), so
 * all zero is a camera looking forward with the image's top up, and
 *   R = R_frd P,   P = [0 0 1; 1 0 0; 0 1 0] (optical -> camera FRD).
 * Presets: forward (0, 0, 0); down (pitch -90: looking down, the image's
 * top toward the nose); down-right, down-aft, down-left (down, the image's
 * top toward that side: yaw 90, 180, -90 after the pitch).
 *
 * The pipe's pose in the body frame: its direction d = R v_L, signed so
 * that it points forward (d_x > 0; for a pipe across the vehicle, d_y > 0;
 * vertical, d_z > 0); the target point the axis point nearest the body
 * origin (p - (p . d) d for any axis point p); and its orientation the
 * rotation Rz(yaw) Ry(pitch) taking body axes to the pipe's (x along the
 * axis, y level, z in the vertical plane through the axis, downward), with
 * yaw = atan2(d_y, d_x), pitch = atan2(-d_z, hypot(d_x, d_y)): the roll
 * about the axis is unobservable for a cylinder and set to 0.
 */
#ifndef CDSPD_MOUNT_H
#define CDSPD_MOUNT_H

#include <stddef.h>

typedef struct {
    double R[3][3];   /* optical -> body */
    double t[3];      /* optical centre in the body frame, pose unit */
} cdspd_mount;

typedef struct {
    double point[3];      /* axis point nearest the body origin, body frame, pose unit */
    double direction[3];  /* unit, body frame, signed as above */
    double yaw, pitch;    /* rad */
    double q[4];          /* w, x, y, z of Rz(yaw) Ry(pitch) */
    double point_cam[3];  /* point in the optical frame */
} cdspd_body_pose;

/* The mount of [roll, pitch, yaw] (degrees) and t. */
void cdspd_mount_from_euler(cdspd_mount *m, const double rpy_deg[3], const double t[3]);

/* A preset's [roll, pitch, yaw] in degrees; 0, or -1 for an unknown name. */
int cdspd_mount_preset(const char *name, double rpy_deg[3]);
/* "forward, down, down-right, down-aft, down-left" */
const char *cdspd_mount_preset_names(void);

/* The body-frame pose of the axis through p (optical frame) along v (need
 * not be unit, not zero). */
void cdspd_mount_apply(const cdspd_mount *m, const double p[3], const double v[3],
                       cdspd_body_pose *out);

#endif
