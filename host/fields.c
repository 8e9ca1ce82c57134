/*
 * fields.c - the pose fields of a record, defined once: the JSON writer
 * (cdsp_host_json_pose: cdsp_tool solve and cdspd --format json), the CSV
 * writer of cdsp_tool solve --csv and the tests that hold the manuals to
 * the code all iterate this table. A new field of cdsp_result gets one row
 * here and appears in JSON, CSV and the field-list check at once.
 *
 * CSV flattening, one convention for every field: a vector adds _x, _y,
 * _z; a per-contour pair adds _1, _2; a per-contour line adds _1_a ..
 * _2_c; the segment's two points add _1_x .. _2_z; a nested JSON key
 * "sigma.point" becomes sigma_point (then _x ...).
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "cdsp_host.h"

#define R(m) offsetof(cdsp_result, m)

/* Rows shared by the record's pose and each entry of "pipes" (solve --all,
 * cdspd's multi-pipe datagrams): defined once here. */
#define F_POINT                                                                                    \
    {"point", CDSP_HOST_FIELD_VEC3, R(point), 0,                                                   \
     "P_C, the foot of the perpendicular from the optical centre onto the axis"}
#define F_DIRECTION                                                                                \
    {"direction", CDSP_HOST_FIELD_VEC3, R(direction), 0,                                           \
     "unit axis direction, largest component positive (with a prior: following it)"}
#define F_DISTANCE {"distance", CDSP_HOST_FIELD_REAL, R(distance), 0, "|P_C|"}
#define F_LINES                                                                                    \
    {"lines", CDSP_HOST_FIELD_LINES, R(lines), 0,                                                  \
     "the two contours a u + b v + c = 0, undistorted px, a^2 + b^2 = 1"}
#define F_INLIERS {"inliers", CDSP_HOST_FIELD_COUNT2, R(inliers), 0, "contour points on each line"}
#define F_SEGMENT                                                                                  \
    {"segment", CDSP_HOST_FIELD_POINTS, R(segment), 0, "the visible part of the axis, two points"}
#define F_SIGMA_POINT                                                                              \
    {"sigma.point", CDSP_HOST_FIELD_VEC3, R(sigma_point), 0, "standard deviation of point"}
#define F_SIGMA_DIRECTION                                                                          \
    {"sigma.direction", CDSP_HOST_FIELD_VEC3, R(sigma_direction), 0,                               \
     "standard deviation of direction"}
#define F_SIGMA_DISTANCE                                                                           \
    {"sigma.distance", CDSP_HOST_FIELD_REAL, R(sigma_distance), 0,                                 \
     "standard deviation of distance"}
/* issue 12: the systematic part, a bound and not a sigma (include/cdsp.h) */
#define F_BOUND_POINT                                                                              \
    {"bound.point", CDSP_HOST_FIELD_VEC3, R(bound_point), 0,                                       \
     "systematic bound on point's error (not a sigma; 0 when not measured)"}
#define F_BOUND_DIRECTION                                                                          \
    {"bound.direction", CDSP_HOST_FIELD_VEC3, R(bound_direction), 0,                               \
     "systematic bound on direction's error (not a sigma)"}
#define F_BOUND_DISTANCE                                                                           \
    {"bound.distance", CDSP_HOST_FIELD_REAL, R(bound_distance), 0,                                 \
     "systematic bound on distance's error (not a sigma)"}
#define F_BOUND_EDGE                                                                               \
    {"bound.edge", CDSP_HOST_FIELD_PAIR, R(edge_bound), 0,                                         \
     "systematic bound on each contour line's offset from its silhouette, px"}
#define F_CONFIDENCE                                                                               \
    {"confidence", CDSP_HOST_FIELD_REAL, R(confidence), 0,                                         \
     "0..1, how sure libcdsp is that this is the pipe (include/cdsp.h, \"The pair score\")"}

static const cdsp_host_field pose_fields[] = {
    F_POINT,
    F_DIRECTION,
    F_DISTANCE,
    {"alpha", CDSP_HOST_FIELD_REAL, R(alpha), 0, "angle between the two tangent planes, rad"},
    F_LINES,
    F_INLIERS,
    {"rms", CDSP_HOST_FIELD_PAIR, R(rms), 0, "their RMS distance to the line, px"},
    F_SEGMENT,
    F_SIGMA_POINT,
    F_SIGMA_DIRECTION,
    F_SIGMA_DISTANCE,
    F_BOUND_POINT,
    F_BOUND_DIRECTION,
    F_BOUND_DISTANCE,
    F_BOUND_EDGE,
    {"edges", CDSP_HOST_FIELD_COUNT, R(n_edges), 0, "edge points considered"},
    {"tracked", CDSP_HOST_FIELD_FLAG, R(flags), CDSP_FLAG_TRACKED,
     "found in the bands around the previous frame's contours"},
    {"full_search", CDSP_HOST_FIELD_FLAG, R(flags), CDSP_FLAG_FULL_SEARCH,
     "found by searching the whole frame or ROI (no prior, or tracking lost the pipe)"},
    {"truncated", CDSP_HOST_FIELD_FLAG, R(flags), CDSP_FLAG_TRUNCATED,
     "more edge points than libcdsp keeps (CDSP_MAX_EDGES)"},
    F_CONFIDENCE,
};

/* Each entry of "pipes", in this order; track_id only when tracking. */
static const cdsp_host_field pipe_fields[] = {
    F_POINT,
    F_DIRECTION,
    F_DISTANCE,
    F_SEGMENT,
    F_SIGMA_POINT,
    F_SIGMA_DIRECTION,
    F_SIGMA_DISTANCE,
    F_BOUND_POINT,
    F_BOUND_DIRECTION,
    F_BOUND_DISTANCE,
    F_BOUND_EDGE,
    {"confidence", CDSP_HOST_FIELD_REAL, R(confidence), 0,
     "0..1, how sure libcdsp is that this band is a pipe (its evidence)"},
    F_LINES,
    F_INLIERS,
    {"track_id", CDSP_HOST_FIELD_COUNT, R(track_id), 0,
     "(when tracking) the pipe's id, the same while it stays in view"},
};

const cdsp_host_field *cdsp_host_pipe_fields(size_t *n)
{
    *n = sizeof pipe_fields / sizeof pipe_fields[0];
    return pipe_fields;
}

/* Samples along pipe i's visible segment for the spacing (Eq. 17-21):
 * the mean converges as 1/N^2 for the smooth distance profile, so 100 is
 * exact to printing precision. */
#define PAIR_SAMPLES 100

int cdsp_host_pipe_pair(const cdsp_result *a, const cdsp_result *b, double *angle_deg,
                        double *axis_distance, double *axis_distance_rms)
{
    double dot = 0, cr[3], c;
    cdsp_real mean, spread;
    int k;
    for (k = 0; k < 3; k++)
        dot += (double)a->direction[k] * (double)b->direction[k];
    cr[0] = (double)a->direction[1] * (double)b->direction[2] - (double)a->direction[2] * (double)b->direction[1];
    cr[1] = (double)a->direction[2] * (double)b->direction[0] - (double)a->direction[0] * (double)b->direction[2];
    cr[2] = (double)a->direction[0] * (double)b->direction[1] - (double)a->direction[1] * (double)b->direction[0];
    c = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    /* sign-insensitive: axes, not vectors; atan2 keeps small angles exact */
    *angle_deg = atan2(c, fabs(dot)) * 180.0 / 3.14159265358979323846;
    if (cdsp_result_axis_spacing(a, b, PAIR_SAMPLES, &mean, &spread) != CDSP_OK)
        return -1;
    *axis_distance = (double)mean;
    *axis_distance_rms = (double)spread;
    return 0;
}

const cdsp_host_field *cdsp_host_pose_fields(size_t *n)
{
    *n = sizeof pose_fields / sizeof pose_fields[0];
    return pose_fields;
}

static const char *const xyz[] = {"x", "y", "z"}, *const abc[] = {"a", "b", "c"};

int cdsp_host_field_columns(const cdsp_host_field *f)
{
    switch (f->kind) {
    case CDSP_HOST_FIELD_VEC3: return 3;
    case CDSP_HOST_FIELD_PAIR:
    case CDSP_HOST_FIELD_COUNT2: return 2;
    case CDSP_HOST_FIELD_LINES:
    case CDSP_HOST_FIELD_POINTS: return 6;
    default: return 1;
    }
}

size_t cdsp_host_field_column_name(const cdsp_host_field *f, int col, char *buf, size_t cap)
{
    char base[64];
    size_t i;
    int n;
    /* "sigma.point" -> "sigma_point" */
    snprintf(base, sizeof base, "%s", f->name);
    for (i = 0; base[i]; i++)
        if (base[i] == '.')
            base[i] = '_';
    switch (f->kind) {
    case CDSP_HOST_FIELD_VEC3: n = snprintf(buf, cap, "%s_%s", base, xyz[col % 3]); break;
    case CDSP_HOST_FIELD_PAIR:
    case CDSP_HOST_FIELD_COUNT2: n = snprintf(buf, cap, "%s_%d", base, col % 2 + 1); break;
    case CDSP_HOST_FIELD_LINES:
        n = snprintf(buf, cap, "%s_%d_%s", base, col / 3 % 2 + 1, abc[col % 3]);
        break;
    case CDSP_HOST_FIELD_POINTS:
        n = snprintf(buf, cap, "%s_%d_%s", base, col / 3 % 2 + 1, xyz[col % 3]);
        break;
    default: n = snprintf(buf, cap, "%s", base); break;
    }
    return n < 0 ? 0 : (size_t)n;
}

size_t cdsp_host_field_csv(const cdsp_host_field *f, const cdsp_result *r, int col, char *buf,
                           size_t cap)
{
    const char *base = (const char *)r + f->offset;
    const cdsp_real *v = (const cdsp_real *)(const void *)base;
    const uint32_t *u = (const uint32_t *)(const void *)base;
    char b[32];
    int n;
    switch (f->kind) {
    case CDSP_HOST_FIELD_COUNT: n = snprintf(buf, cap, "%u", (unsigned)u[0]); break;
    case CDSP_HOST_FIELD_COUNT2: n = snprintf(buf, cap, "%u", (unsigned)u[col % 2]); break;
    case CDSP_HOST_FIELD_FLAG: n = snprintf(buf, cap, "%s", (u[0] & f->mask) ? "true" : "false"); break;
    case CDSP_HOST_FIELD_REAL: n = snprintf(buf, cap, "%s", cdsp_host_fmt_real(b, (double)v[0])); break;
    default: /* VEC3, PAIR, LINES, POINTS: consecutive reals */
        n = snprintf(buf, cap, "%s", cdsp_host_fmt_real(b, (double)v[col]));
        break;
    }
    return n < 0 ? 0 : (size_t)n;
}
