/*
 * proto.h - the datagrams cdspd sends (docs/protocol.md is the reference):
 * one record per processed frame, or a status record when no frame came.
 * Binary: a fixed little-endian layout of CDSPD_PROTO_SIZE bytes starting
 * with the magic "CDSP" and a version byte. JSON: one object with the field
 * names of `cdsp_tool solve` plus the daemon's (seq, t_camera_us, ...).
 *
 * Encoding never allocates (the daemon encodes every frame); the decoders
 * are for receivers (cdsp_tool listen, the tests). The JSON decoder uses
 * json-c.
 */
#ifndef CDSPD_PROTO_H
#define CDSPD_PROTO_H

#include <stddef.h>
#include <stdint.h>

#include "cdsp.h"

#define CDSPD_PROTO_MAGIC "CDSP"
#define CDSPD_PROTO_VERSION 4
#define CDSPD_PROTO_SIZE 452     /* bytes of a version-4 record without pipes */
#define CDSPD_PROTO_SIZE_V3 380  /* bytes of a version-3 record without pipes (still decoded) */
#define CDSPD_PROTO_SIZE_V2 376  /* bytes of a version-2 record (still decoded) */
#define CDSPD_PROTO_SIZE_V1 320  /* bytes of a version-1 record (still decoded) */
/* Version 3 (issue 13): after the version-2 fields, a pipe count and the
 * size of one pipe entry, then that many entries (docs/protocol.md).
 * Version 4 (issue 12): the systematic bounds appended to the fixed part
 * (so the entries start at 452) and to each entry. */
#define CDSPD_PROTO_PIPE_SIZE 304
#define CDSPD_PROTO_PIPE_SIZE_V3 232
#define CDSPD_PROTO_MAX_SIZE (CDSPD_PROTO_SIZE + CDSP_MAX_PIPES * CDSPD_PROTO_PIPE_SIZE)

/* kind */
#define CDSPD_KIND_FRAME 1       /* the result of one frame */
#define CDSPD_KIND_STATUS 2      /* no frame: the source is quiet or lost */

/* Statuses beyond cdsp_status (which are 0 .. -8). */
#define CDSPD_ST_NO_FRAME (-100)    /* no frame for status_interval, source open */
#define CDSPD_ST_SOURCE_DOWN (-101) /* the source is lost; cdspd is reopening it */
#define CDSPD_ST_BAD_FRAME (-102)   /* a frame cdspd cannot use (size, format) */

/* flags */
#define CDSPD_FLAG_TRACKED 0x0001u     /* found in the bands around the previous result */
#define CDSPD_FLAG_FULL_SEARCH 0x0002u /* searched the whole frame / ROI */
#define CDSPD_FLAG_TRUNCATED 0x0004u   /* more edges than the library keeps */
#define CDSPD_FLAG_SOURCE_DOWN 0x0008u /* the source is being reopened */
#define CDSPD_FLAG_RECORDED 0x0010u    /* this frame was saved by --record */
#define CDSPD_FLAG_MULTI 0x0020u       /* multi_pipe: the record lists every pipe */

/* One pipe of a multi-pipe record (version 3; cdsp_tool solve --all's
 * "pipes" entry). */
typedef struct {
    double point[3], direction[3], distance;
    double segment[2][3];
    double sigma_point[3], sigma_direction[3], sigma_distance;
    double confidence;
    double lines[2][3];
    uint32_t inliers[2];
    uint32_t track_id;         /* kept from frame to frame while the pipe is in view */
    /* version 4: cdsp_result's systematic bounds (not sigmas; 0 from older versions) */
    double bound_point[3], bound_direction[3], bound_distance, edge_bound[2];
} cdspd_pipe;

typedef struct {
    uint8_t version;
    uint8_t kind;
    uint32_t seq;              /* datagrams sent by this daemon run, from 0, +1 each */
    int32_t status;            /* 0 ok, cdsp_status < 0, or CDSPD_ST_* */
    uint32_t flags;
    uint64_t frame_id;         /* the source's frame number (GVSP block id, V4L2 sequence, ...) */
    uint64_t t_camera_us;      /* the source's timestamp, us (its own clock; 0 = none) */
    uint64_t t_host_us;        /* host CLOCK_MONOTONIC, us, when the frame was ready */
    double radius;
    /* meaningful when status == 0, zero otherwise */
    double point[3];           /* P_C, camera frame */
    double direction[3];       /* v_L, unit */
    double distance;           /* |P_C| */
    double alpha;              /* angle between the tangent planes, rad */
    double lines[2][3];        /* the contours, undistorted px */
    double segment[2][3];      /* visible axis segment */
    double sigma_point[3], sigma_direction[3], sigma_distance;
    double rms[2];
    uint32_t inliers[2];
    uint32_t n_edges;
    /* always */
    uint32_t proc_us;          /* solve time */
    uint32_t latency_us;       /* frame ready -> this datagram encoded */
    uint32_t frames_in;        /* frames captured (complete) since start */
    uint32_t frames_dropped;   /* frames replaced in the pool before processing */
    uint32_t frames_bad;       /* incomplete or unusable frames skipped */
    uint32_t reconnects;       /* times the source was reopened */
    /* the pose in the vehicle's body frame FRD through the mount key
     * (daemon/mount.h), meaningful when status == 0, zero otherwise */
    double point_body[3];      /* axis point nearest the body origin, pose unit (mm) */
    double direction_body[3];  /* unit, signed to point forward */
    /* JSON only (not in the binary layout): the sim source's ground truth
     * with sim.truth, as cdspd_sim_truth gives it */
    int has_truth, truth_in_view;
    double truth_point[3], truth_direction[3], truth_distance;
    double confidence;         /* version 2: cdsp_result.confidence, 0..1 (0 unless status == 0) */
    /* version 3: every pipe, best first, when flags has CDSPD_FLAG_MULTI
     * (pipe[0] is the pose above); 0 pipes otherwise or without a pose */
    uint32_t n_pipes;
    cdspd_pipe pipe[CDSP_MAX_PIPES];
    /* version 4: the systematic part of the error, a bound and not a sigma
     * (cdsp_result.bound_*, edge_bound px); meaningful when status == 0,
     * zero otherwise and from older versions */
    double bound_point[3], bound_direction[3], bound_distance, edge_bound[2];
} cdspd_record;

/* Short stable token of a status: the library's (cdsp_status_token) or
 * "no-frame", "source-down", "bad-frame"; "unknown" otherwise. */
const char *cdspd_status_token(int status);
/* Inverse; returns 1 and sets *status when known. */
int cdspd_status_from_token(const char *token, int *status);

/* Fill a record's pose fields from a library result (status OK). */
void cdspd_record_set_result(cdspd_record *r, const cdsp_result *res);
/* The inverse, for cdsp_host_json_pose: a cdsp_result with the fields the
 * record carries (covariance and labels zero). */
void cdspd_record_to_result(const cdspd_record *r, cdsp_result *res);

/* Every pipe of a frame into r->pipe[] (at most CDSP_MAX_PIPES); sets
 * CDSPD_FLAG_MULTI. */
void cdspd_record_set_pipes(cdspd_record *r, const cdsp_result *res, size_t n);
/* One pipe of a record as a cdsp_result (the fields it carries). */
void cdspd_pipe_to_result(const cdspd_pipe *p, cdsp_result *res);

/* Binary: writes CDSPD_PROTO_SIZE + n_pipes * CDSPD_PROTO_PIPE_SIZE bytes;
 * returns that, or 0 if cap is smaller. */
size_t cdspd_proto_encode(const cdspd_record *r, uint8_t *buf, size_t cap);

/* Binary: 0 and *r filled, or -1 with *why set ("bad magic", ...).
 * Accepts version 4 and 3 records (their length covering the pipe
 * entries; a larger entry size than the version's is a later addition and
 * its tail is skipped; version 3 has no bounds), version 2 records of CDSPD_PROTO_SIZE_V2 bytes or
 * longer (no pipes), and version 1 records of CDSPD_PROTO_SIZE_V1 bytes or
 * longer (the body-frame fields then zero). */
int cdspd_proto_decode(const uint8_t *buf, size_t len, cdspd_record *r, const char **why);

/* JSON (no trailing newline, NUL-terminated): returns the length, or 0 if
 * cap is too small. */
size_t cdspd_proto_encode_json(const cdspd_record *r, char *buf, size_t cap);

/* JSON decoder (json-c): 0 or -1 with *why. */
int cdspd_proto_decode_json(const char *text, size_t len, cdspd_record *r, const char **why);

/* Either: binary if it starts with the magic, JSON if with '{'. */
int cdspd_proto_decode_any(const uint8_t *buf, size_t len, cdspd_record *r, int *is_json,
                           const char **why);

#endif
