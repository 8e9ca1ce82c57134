/*
 * proto.c - see proto.h; the byte layout is the table in docs/protocol.md.
 * Bytes are written one by one (shifts), so the encoding is little-endian
 * whatever the host's order; doubles are IEEE 754 binary64 moved through a
 * uint64_t.
 */
#define _POSIX_C_SOURCE 200809L
#include "proto.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <string.h>

#include <json-c/json.h>

#include "cdsp_host.h"

/* Offsets of the version-1 layout (docs/protocol.md). */
enum {
    OFF_MAGIC = 0, OFF_VERSION = 4, OFF_KIND = 5, OFF_LENGTH = 6, OFF_SEQ = 8, OFF_STATUS = 12,
    OFF_FLAGS = 16, OFF_EDGES = 20, OFF_FRAME = 24, OFF_TCAM = 32, OFF_THOST = 40, OFF_RADIUS = 48,
    OFF_POINT = 56, OFF_DIR = 80, OFF_DIST = 104, OFF_ALPHA = 112, OFF_LINES = 120,
    OFF_SEGMENT = 168, OFF_SIG_P = 216, OFF_SIG_D = 240, OFF_SIG_DIST = 264, OFF_RMS = 272,
    OFF_INLIERS = 288, OFF_PROC = 296, OFF_LAT = 300, OFF_IN = 304, OFF_DROP = 308, OFF_BAD = 312,
    OFF_RECON = 316, OFF_END_V1 = 320,
    /* version 2 */
    OFF_POINT_BODY = 320, OFF_DIR_BODY = 344, OFF_CONF = 368, OFF_END_V2 = 376,
    /* version 3: the pipe list's header, then the entries */
    OFF_NPIPES = 376, OFF_PIPE_SIZE = 378, OFF_END_V3 = 380,
    /* version 4: the systematic bounds (issue 12), then the entries */
    OFF_BOUND_P = 380, OFF_BOUND_D = 404, OFF_BOUND_DIST = 428, OFF_EDGE_BOUND = 436, OFF_END = 452
};

/* Offsets inside one pipe entry. */
enum {
    PIPE_POINT = 0, PIPE_DIR = 24, PIPE_DIST = 48, PIPE_SEGMENT = 56, PIPE_SIG_P = 104,
    PIPE_SIG_D = 128, PIPE_SIG_DIST = 152, PIPE_CONF = 160, PIPE_LINES = 168, PIPE_INLIERS = 216,
    PIPE_TRACK = 224, PIPE_RESERVED = 228, PIPE_END_V3 = 232,
    /* version 4 */
    PIPE_BOUND_P = 232, PIPE_BOUND_D = 256, PIPE_BOUND_DIST = 280, PIPE_EDGE_BOUND = 288, PIPE_END = 304
};

typedef char proto_size_check[OFF_END == CDSPD_PROTO_SIZE ? 1 : -1];
typedef char proto_size_v2_check[OFF_END_V2 == CDSPD_PROTO_SIZE_V2 ? 1 : -1];
typedef char proto_pipe_check[PIPE_END == CDSPD_PROTO_PIPE_SIZE ? 1 : -1];
typedef char proto_size_v1_check[OFF_END_V1 == CDSPD_PROTO_SIZE_V1 ? 1 : -1];
typedef char proto_size_v3_check[OFF_END_V3 == CDSPD_PROTO_SIZE_V3 ? 1 : -1];
typedef char proto_pipe_v3_check[PIPE_END_V3 == CDSPD_PROTO_PIPE_SIZE_V3 ? 1 : -1];

const char *cdspd_status_token(int status)
{
    switch (status) {
    case CDSPD_ST_NO_FRAME: return "no-frame";
    case CDSPD_ST_SOURCE_DOWN: return "source-down";
    case CDSPD_ST_BAD_FRAME: return "bad-frame";
    default:
        if (status <= 0 && status >= CDSP_E_FORMAT)
            return cdsp_status_token((cdsp_status)status);
        return "unknown";
    }
}

int cdspd_status_from_token(const char *token, int *status)
{
    int s;
    for (s = 0; s >= CDSP_E_FORMAT; s--)
        if (!strcmp(token, cdsp_status_token((cdsp_status)s))) {
            *status = s;
            return 1;
        }
    for (s = CDSPD_ST_NO_FRAME; s >= CDSPD_ST_BAD_FRAME; s--)
        if (!strcmp(token, cdspd_status_token(s))) {
            *status = s;
            return 1;
        }
    return 0;
}

/* The fields cdspd_record and cdspd_pipe share with cdsp_result, with the
 * number of values of each: the conversions and the finiteness checks
 * below all walk this one list (X(field, count); an array field is read
 * through its first element). */
#define POSE_FIELDS(X)                                                                             \
    X(point, 3) X(direction, 3) X(distance, 1) X(segment, 6) X(lines, 6) X(sigma_point, 3)         \
    X(sigma_direction, 3) X(sigma_distance, 1) X(confidence, 1) X(bound_point, 3)                  \
    X(bound_direction, 3) X(bound_distance, 1) X(edge_bound, 2)
#define POSE_TO_DOUBLES(f, n) to_doubles((double *)&d->f, (const cdsp_real *)&s->f, n);
#define POSE_TO_REALS(f, n) to_reals((cdsp_real *)&d->f, (const double *)&s->f, n);
#define POSE_FINITE(f, n) &&finite_n((const double *)&x->f, n)

static void to_doubles(double *d, const cdsp_real *s, int n)
{
    int i;
    for (i = 0; i < n; i++)
        d[i] = (double)s[i];
}

static void to_reals(cdsp_real *d, const double *s, int n)
{
    int i;
    for (i = 0; i < n; i++)
        d[i] = (cdsp_real)s[i];
}

static int finite_n(const double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

void cdspd_record_set_result(cdspd_record *d, const cdsp_result *s)
{
    POSE_FIELDS(POSE_TO_DOUBLES)
    d->alpha = (double)s->alpha;
    to_doubles(d->rms, s->rms, 2);
    d->inliers[0] = s->inliers[0];
    d->inliers[1] = s->inliers[1];
    d->n_edges = s->n_edges;
    d->flags &= ~(CDSPD_FLAG_TRACKED | CDSPD_FLAG_FULL_SEARCH | CDSPD_FLAG_TRUNCATED);
    if (s->flags & CDSP_FLAG_TRACKED)
        d->flags |= CDSPD_FLAG_TRACKED;
    if (s->flags & CDSP_FLAG_FULL_SEARCH)
        d->flags |= CDSPD_FLAG_FULL_SEARCH;
    if (s->flags & CDSP_FLAG_TRUNCATED)
        d->flags |= CDSPD_FLAG_TRUNCATED;
}

void cdspd_record_to_result(const cdspd_record *s, cdsp_result *d)
{
    memset(d, 0, sizeof *d);
    POSE_FIELDS(POSE_TO_REALS)
    d->alpha = (cdsp_real)s->alpha;
    to_reals(d->rms, s->rms, 2);
    d->inliers[0] = s->inliers[0];
    d->inliers[1] = s->inliers[1];
    d->n_edges = s->n_edges;
    if (s->flags & CDSPD_FLAG_TRACKED)
        d->flags |= CDSP_FLAG_TRACKED;
    if (s->flags & CDSPD_FLAG_FULL_SEARCH)
        d->flags |= CDSP_FLAG_FULL_SEARCH;
    if (s->flags & CDSPD_FLAG_TRUNCATED)
        d->flags |= CDSP_FLAG_TRUNCATED;
}

/* ------------------------------------------------------------------------
 * Binary.
 * ---------------------------------------------------------------------- */
static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    int i;
    for (i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_u64(uint8_t *p, uint64_t v)
{
    int i;
    for (i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_f64(uint8_t *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    put_u64(p, u);
}

static void put_f64s(uint8_t *p, const double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        put_f64(p + 8 * i, v[i]);
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

static double get_f64(const uint8_t *p)
{
    uint64_t u = get_u64(p);
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}

static void get_f64s(const uint8_t *p, double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        v[i] = get_f64(p + 8 * i);
}

void cdspd_record_set_pipes(cdspd_record *r, const cdsp_result *res, size_t n)
{
    size_t k;
    r->flags |= CDSPD_FLAG_MULTI;
    r->n_pipes = (uint32_t)(n < CDSP_MAX_PIPES ? n : CDSP_MAX_PIPES);
    for (k = 0; k < r->n_pipes; k++) {
        cdspd_pipe *d = &r->pipe[k];
        const cdsp_result *s = &res[k];
        memset(d, 0, sizeof *d);
        POSE_FIELDS(POSE_TO_DOUBLES)
        d->inliers[0] = s->inliers[0];
        d->inliers[1] = s->inliers[1];
        d->track_id = s->track_id;
    }
}

void cdspd_pipe_to_result(const cdspd_pipe *s, cdsp_result *d)
{
    memset(d, 0, sizeof *d);
    POSE_FIELDS(POSE_TO_REALS)
    d->inliers[0] = s->inliers[0];
    d->inliers[1] = s->inliers[1];
    d->track_id = s->track_id;
}

size_t cdspd_proto_encode(const cdspd_record *r, uint8_t *b, size_t cap)
{
    uint32_t np = r->n_pipes < CDSP_MAX_PIPES ? r->n_pipes : CDSP_MAX_PIPES, k;
    size_t total = CDSPD_PROTO_SIZE + (size_t)np * CDSPD_PROTO_PIPE_SIZE;
    if (cap < total)
        return 0;
    memcpy(b + OFF_MAGIC, CDSPD_PROTO_MAGIC, 4);
    b[OFF_VERSION] = CDSPD_PROTO_VERSION;
    b[OFF_KIND] = r->kind;
    put_u16(b + OFF_LENGTH, (uint16_t)total);
    put_u32(b + OFF_SEQ, r->seq);
    put_u32(b + OFF_STATUS, (uint32_t)r->status);
    put_u32(b + OFF_FLAGS, r->flags);
    put_u32(b + OFF_EDGES, r->n_edges);
    put_u64(b + OFF_FRAME, r->frame_id);
    put_u64(b + OFF_TCAM, r->t_camera_us);
    put_u64(b + OFF_THOST, r->t_host_us);
    put_f64(b + OFF_RADIUS, r->radius);
    put_f64s(b + OFF_POINT, r->point, 3);
    put_f64s(b + OFF_DIR, r->direction, 3);
    put_f64(b + OFF_DIST, r->distance);
    put_f64(b + OFF_ALPHA, r->alpha);
    put_f64s(b + OFF_LINES, &r->lines[0][0], 6);
    put_f64s(b + OFF_SEGMENT, &r->segment[0][0], 6);
    put_f64s(b + OFF_SIG_P, r->sigma_point, 3);
    put_f64s(b + OFF_SIG_D, r->sigma_direction, 3);
    put_f64(b + OFF_SIG_DIST, r->sigma_distance);
    put_f64s(b + OFF_RMS, r->rms, 2);
    put_u32(b + OFF_INLIERS, r->inliers[0]);
    put_u32(b + OFF_INLIERS + 4, r->inliers[1]);
    put_u32(b + OFF_PROC, r->proc_us);
    put_u32(b + OFF_LAT, r->latency_us);
    put_u32(b + OFF_IN, r->frames_in);
    put_u32(b + OFF_DROP, r->frames_dropped);
    put_u32(b + OFF_BAD, r->frames_bad);
    put_u32(b + OFF_RECON, r->reconnects);
    put_f64s(b + OFF_POINT_BODY, r->point_body, 3);
    put_f64s(b + OFF_DIR_BODY, r->direction_body, 3);
    put_f64(b + OFF_CONF, r->confidence);
    put_u16(b + OFF_NPIPES, (uint16_t)np);
    put_u16(b + OFF_PIPE_SIZE, CDSPD_PROTO_PIPE_SIZE);
    put_f64s(b + OFF_BOUND_P, r->bound_point, 3);
    put_f64s(b + OFF_BOUND_D, r->bound_direction, 3);
    put_f64(b + OFF_BOUND_DIST, r->bound_distance);
    put_f64s(b + OFF_EDGE_BOUND, r->edge_bound, 2);
    for (k = 0; k < np; k++) {
        uint8_t *e = b + CDSPD_PROTO_SIZE + (size_t)k * CDSPD_PROTO_PIPE_SIZE;
        const cdspd_pipe *p = &r->pipe[k];
        put_f64s(e + PIPE_POINT, p->point, 3);
        put_f64s(e + PIPE_DIR, p->direction, 3);
        put_f64(e + PIPE_DIST, p->distance);
        put_f64s(e + PIPE_SEGMENT, &p->segment[0][0], 6);
        put_f64s(e + PIPE_SIG_P, p->sigma_point, 3);
        put_f64s(e + PIPE_SIG_D, p->sigma_direction, 3);
        put_f64(e + PIPE_SIG_DIST, p->sigma_distance);
        put_f64(e + PIPE_CONF, p->confidence);
        put_f64s(e + PIPE_LINES, &p->lines[0][0], 6);
        put_u32(e + PIPE_INLIERS, p->inliers[0]);
        put_u32(e + PIPE_INLIERS + 4, p->inliers[1]);
        put_u32(e + PIPE_TRACK, p->track_id);
        put_u32(e + PIPE_RESERVED, 0);
        put_f64s(e + PIPE_BOUND_P, p->bound_point, 3);
        put_f64s(e + PIPE_BOUND_D, p->bound_direction, 3);
        put_f64(e + PIPE_BOUND_DIST, p->bound_distance);
        put_f64s(e + PIPE_EDGE_BOUND, p->edge_bound, 2);
    }
    return total;
}

/* cdspd sends finite numbers only (zeros without a pose); a NaN or Inf
 * would reach the consumer as JSON null, which no decoder takes back
 * (found by tests/fuzz listen). */
static int pipe_finite(const cdspd_pipe *x)
{
    return 1 POSE_FIELDS(POSE_FINITE);
}

static int record_finite(const cdspd_record *x)
{
    return finite_n(&x->radius, 1) && finite_n(&x->alpha, 1) && finite_n(x->rms, 2) &&
           finite_n(x->point_body, 3) && finite_n(x->direction_body, 3) POSE_FIELDS(POSE_FINITE);
}

int cdspd_proto_decode(const uint8_t *b, size_t len, cdspd_record *r, const char **why)
{
    const char *dummy;
    uint16_t length;
    if (!why)
        why = &dummy;
    if (len < 8 || memcmp(b, CDSPD_PROTO_MAGIC, 4)) {
        *why = "not a cdspd datagram (no CDSP magic)";
        return -1;
    }
    if (b[OFF_VERSION] != CDSPD_PROTO_VERSION && b[OFF_VERSION] != 3 && b[OFF_VERSION] != 2 &&
        b[OFF_VERSION] != 1) {
        *why = "unsupported protocol version";
        return -1;
    }
    length = get_u16(b + OFF_LENGTH);
    if (length < (b[OFF_VERSION] == 1   ? CDSPD_PROTO_SIZE_V1
                  : b[OFF_VERSION] == 2 ? CDSPD_PROTO_SIZE_V2
                  : b[OFF_VERSION] == 3 ? CDSPD_PROTO_SIZE_V3
                                        : CDSPD_PROTO_SIZE) ||
        len < length) {
        *why = "truncated datagram";
        return -1;
    }
    if (b[OFF_KIND] != CDSPD_KIND_FRAME && b[OFF_KIND] != CDSPD_KIND_STATUS) {
        *why = "unknown record kind";
        return -1;
    }
    memset(r, 0, sizeof *r);
    r->version = b[OFF_VERSION];
    r->kind = b[OFF_KIND];
    r->seq = get_u32(b + OFF_SEQ);
    r->status = (int32_t)get_u32(b + OFF_STATUS);
    r->flags = get_u32(b + OFF_FLAGS);
    r->n_edges = get_u32(b + OFF_EDGES);
    r->frame_id = get_u64(b + OFF_FRAME);
    r->t_camera_us = get_u64(b + OFF_TCAM);
    r->t_host_us = get_u64(b + OFF_THOST);
    r->radius = get_f64(b + OFF_RADIUS);
    get_f64s(b + OFF_POINT, r->point, 3);
    get_f64s(b + OFF_DIR, r->direction, 3);
    r->distance = get_f64(b + OFF_DIST);
    r->alpha = get_f64(b + OFF_ALPHA);
    get_f64s(b + OFF_LINES, &r->lines[0][0], 6);
    get_f64s(b + OFF_SEGMENT, &r->segment[0][0], 6);
    get_f64s(b + OFF_SIG_P, r->sigma_point, 3);
    get_f64s(b + OFF_SIG_D, r->sigma_direction, 3);
    r->sigma_distance = get_f64(b + OFF_SIG_DIST);
    get_f64s(b + OFF_RMS, r->rms, 2);
    r->inliers[0] = get_u32(b + OFF_INLIERS);
    r->inliers[1] = get_u32(b + OFF_INLIERS + 4);
    r->proc_us = get_u32(b + OFF_PROC);
    r->latency_us = get_u32(b + OFF_LAT);
    r->frames_in = get_u32(b + OFF_IN);
    r->frames_dropped = get_u32(b + OFF_DROP);
    r->frames_bad = get_u32(b + OFF_BAD);
    r->reconnects = get_u32(b + OFF_RECON);
    if (r->version >= 2) {
        get_f64s(b + OFF_POINT_BODY, r->point_body, 3);
        get_f64s(b + OFF_DIR_BODY, r->direction_body, 3);
        r->confidence = get_f64(b + OFF_CONF);
    }
    if (r->version >= 4) {
        get_f64s(b + OFF_BOUND_P, r->bound_point, 3);
        get_f64s(b + OFF_BOUND_D, r->bound_direction, 3);
        r->bound_distance = get_f64(b + OFF_BOUND_DIST);
        get_f64s(b + OFF_EDGE_BOUND, r->edge_bound, 2);
    }
    if (r->version >= 3) {
        uint16_t np = get_u16(b + OFF_NPIPES), esz = get_u16(b + OFF_PIPE_SIZE), k;
        /* version 3's entries follow its 380 bytes and are 232 long */
        size_t fixed = r->version >= 4 ? CDSPD_PROTO_SIZE : CDSPD_PROTO_SIZE_V3;
        uint16_t esz_min = r->version >= 4 ? CDSPD_PROTO_PIPE_SIZE : CDSPD_PROTO_PIPE_SIZE_V3;
        if (np > CDSP_MAX_PIPES || esz < esz_min || (size_t)length < fixed + (size_t)np * esz) {
            *why = np > CDSP_MAX_PIPES ? "more pipes than a record holds" : "truncated pipe list";
            return -1;
        }
        r->n_pipes = np;
        for (k = 0; k < np; k++) {
            const uint8_t *e = b + fixed + (size_t)k * esz;
            cdspd_pipe *p = &r->pipe[k];
            get_f64s(e + PIPE_POINT, p->point, 3);
            get_f64s(e + PIPE_DIR, p->direction, 3);
            p->distance = get_f64(e + PIPE_DIST);
            get_f64s(e + PIPE_SEGMENT, &p->segment[0][0], 6);
            get_f64s(e + PIPE_SIG_P, p->sigma_point, 3);
            get_f64s(e + PIPE_SIG_D, p->sigma_direction, 3);
            p->sigma_distance = get_f64(e + PIPE_SIG_DIST);
            p->confidence = get_f64(e + PIPE_CONF);
            get_f64s(e + PIPE_LINES, &p->lines[0][0], 6);
            p->inliers[0] = get_u32(e + PIPE_INLIERS);
            p->inliers[1] = get_u32(e + PIPE_INLIERS + 4);
            p->track_id = get_u32(e + PIPE_TRACK);
            if (r->version >= 4) {
                get_f64s(e + PIPE_BOUND_P, p->bound_point, 3);
                get_f64s(e + PIPE_BOUND_D, p->bound_direction, 3);
                p->bound_distance = get_f64(e + PIPE_BOUND_DIST);
                get_f64s(e + PIPE_EDGE_BOUND, p->edge_bound, 2);
            }
            if (!pipe_finite(p)) {
                *why = "a number in the pipe list is not finite";
                return -1;
            }
        }
    }
    /* a status without a token would go out of listen --json as "unknown",
     * which the JSON decoder refuses (tests/fuzz listen): both refuse it */
    if (!strcmp(cdspd_status_token(r->status), "unknown")) {
        *why = "unknown status";
        return -1;
    }
    /* likewise a status record saying "ok" (JSON: "error":"ok") */
    if (r->kind == CDSPD_KIND_STATUS && r->status == 0) {
        *why = "a status record without a status";
        return -1;
    }
    if (!record_finite(r)) {
        *why = "a number in the record is not finite";
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------------------
 * JSON.
 * ---------------------------------------------------------------------- */
/* An array of doubles at full precision (cdsp_host_json_reals takes
 * cdsp_real, which may be float). */
static void json_doubles(cdsp_host_json *j, const double *v, int n)
{
    int i;
    cdsp_host_json_begin_array(j);
    for (i = 0; i < n; i++)
        cdsp_host_json_number(j, v[i]);
    cdsp_host_json_end_array(j);
}

size_t cdspd_proto_encode_json(const cdspd_record *r, char *buf, size_t cap)
{
    cdsp_host_json j;
    cdsp_result res;
    const char *text;
    int ok = r->status == 0 && r->kind == CDSPD_KIND_FRAME;

    cdsp_host_json_init(&j, buf, cap);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "seq");
    cdsp_host_json_int(&j, r->seq);
    cdsp_host_json_key(&j, "kind");
    cdsp_host_json_string(&j, r->kind == CDSPD_KIND_FRAME ? "frame" : "status");
    cdsp_host_json_key(&j, "frame");
    cdsp_host_json_int(&j, (long long)r->frame_id);
    cdsp_host_json_key(&j, "t_camera_us");
    cdsp_host_json_int(&j, (long long)r->t_camera_us);
    cdsp_host_json_key(&j, "t_host_us");
    cdsp_host_json_int(&j, (long long)r->t_host_us);
    if (ok) {
        cdspd_record_to_result(r, &res);
        cdsp_host_json_pose(&j, CDSP_OK, NULL, &res, (cdsp_real)r->radius);
    } else {
        /* the token names the status; st only has to be an error */
        cdsp_host_json_pose(&j, CDSP_E_ARG, cdspd_status_token(r->status), NULL,
                            (cdsp_real)r->radius);
    }
    cdsp_host_json_key(&j, "source_down");
    cdsp_host_json_bool(&j, (r->flags & CDSPD_FLAG_SOURCE_DOWN) != 0);
    cdsp_host_json_key(&j, "recorded");
    cdsp_host_json_bool(&j, (r->flags & CDSPD_FLAG_RECORDED) != 0);
    cdsp_host_json_key(&j, "proc_us");
    cdsp_host_json_int(&j, r->proc_us);
    cdsp_host_json_key(&j, "latency_us");
    cdsp_host_json_int(&j, r->latency_us);
    cdsp_host_json_key(&j, "frames_in");
    cdsp_host_json_int(&j, r->frames_in);
    cdsp_host_json_key(&j, "frames_dropped");
    cdsp_host_json_int(&j, r->frames_dropped);
    cdsp_host_json_key(&j, "frames_bad");
    cdsp_host_json_int(&j, r->frames_bad);
    cdsp_host_json_key(&j, "reconnects");
    cdsp_host_json_int(&j, r->reconnects);
    /* the pose in the body frame (mount key), null without a pose */
    cdsp_host_json_key(&j, "body");
    if (ok) {
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "point");
        json_doubles(&j, r->point_body, 3);
        cdsp_host_json_key(&j, "direction");
        json_doubles(&j, r->direction_body, 3);
        cdsp_host_json_end_object(&j);
    } else {
        cdsp_host_json_null(&j);
    }
    if (r->flags & CDSPD_FLAG_MULTI) {
        /* every pipe, as cdsp_tool solve --all writes them (track ids:
         * cdspd tracks every pipe) */
        cdsp_result res_all[CDSP_MAX_PIPES];
        uint32_t k, np = ok ? (r->n_pipes < CDSP_MAX_PIPES ? r->n_pipes : CDSP_MAX_PIPES) : 0;
        for (k = 0; k < np; k++)
            cdspd_pipe_to_result(&r->pipe[k], &res_all[k]);
        cdsp_host_json_pipes(&j, res_all, np, 1);
    }
    if (r->has_truth) {
        cdsp_host_json_key(&j, "truth");
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "in_view");
        cdsp_host_json_bool(&j, r->truth_in_view);
        if (r->truth_in_view) {
            cdsp_host_json_key(&j, "point");
            json_doubles(&j, r->truth_point, 3);
            cdsp_host_json_key(&j, "direction");
            json_doubles(&j, r->truth_direction, 3);
            cdsp_host_json_key(&j, "distance");
            cdsp_host_json_number(&j, r->truth_distance);
        }
        cdsp_host_json_end_object(&j);
    }
    cdsp_host_json_end_object(&j);
    text = cdsp_host_json_finish(&j);
    return text ? strlen(text) : 0;
}

/* A finite number (json-c also parses NaN and Infinity, which no record
 * carries: the encoder writes them as null). */
static int jnum_of(json_object *x, double *v)
{
    if (!json_object_is_type(x, json_type_double) && !json_object_is_type(x, json_type_int))
        return 0;
    *v = json_object_get_double(x);
    return isfinite(*v);
}

static int jnum(json_object *o, const char *key, double *v)
{
    json_object *x;
    return json_object_object_get_ex(o, key, &x) && jnum_of(x, v);
}

/* A count: an integer in 0 .. UINT32_MAX (anything else would be an
 * undefined conversion). */
static int ju32_of(json_object *x, uint32_t *v)
{
    int64_t i;
    if (!json_object_is_type(x, json_type_int))
        return 0;
    errno = 0;
    i = json_object_get_int64(x);
    if (errno || i < 0 || i > (int64_t)UINT32_MAX)
        return 0;
    *v = (uint32_t)i;
    return 1;
}

/* A string member (NULL when absent or of another type: json-c returns
 * NULL for null, and strcmp must never see it). */
static const char *jstr(json_object *o, const char *key)
{
    json_object *x;
    if (!json_object_object_get_ex(o, key, &x) || !json_object_is_type(x, json_type_string))
        return NULL;
    return json_object_get_string(x);
}

static int jvec(json_object *o, double *v, int n)
{
    int i;
    if (!o || !json_object_is_type(o, json_type_array) || (int)json_object_array_length(o) != n)
        return 0;
    for (i = 0; i < n; i++)
        if (!jnum_of(json_object_array_get_idx(o, (size_t)i), &v[i]))
            return 0;
    return 1;
}

static int jkvec(json_object *o, const char *key, double *v, int n)
{
    json_object *x;
    return json_object_object_get_ex(o, key, &x) && jvec(x, v, n);
}

static int jmat(json_object *o, const char *key, double m[2][3])
{
    json_object *x;
    if (!json_object_object_get_ex(o, key, &x) || !json_object_is_type(x, json_type_array) ||
        json_object_array_length(x) != 2)
        return 0;
    return jvec(json_object_array_get_idx(x, 0), m[0], 3) && jvec(json_object_array_get_idx(x, 1), m[1], 3);
}

static int jbool(json_object *o, const char *key)
{
    json_object *x;
    return json_object_object_get_ex(o, key, &x) && json_object_get_boolean(x);
}

static uint64_t ju64(json_object *o, const char *key, int *ok)
{
    json_object *x;
    if (!json_object_object_get_ex(o, key, &x) || !json_object_is_type(x, json_type_int)) {
        *ok = 0;
        return 0;
    }
    return (uint64_t)json_object_get_int64(x);
}

/* inliers [n1, n2] and edges: counts */
static int jcounts(json_object *o, cdspd_record *r)
{
    json_object *x;
    if (!json_object_object_get_ex(o, "inliers", &x) || !json_object_is_type(x, json_type_array) ||
        json_object_array_length(x) != 2 || !ju32_of(json_object_array_get_idx(x, 0), &r->inliers[0]) ||
        !ju32_of(json_object_array_get_idx(x, 1), &r->inliers[1]))
        return 0;
    return json_object_object_get_ex(o, "edges", &x) && ju32_of(x, &r->n_edges);
}

/* "bound" (version 4, issue 12): absent from an older cdspd's datagram
 * (then zero); when present, every member a finite number. */
static int jbound(json_object *o, double point[3], double direction[3], double *distance, double edge[2])
{
    json_object *x;
    if (!json_object_object_get_ex(o, "bound", &x))
        return 1;
    return json_object_is_type(x, json_type_object) && jkvec(x, "point", point, 3) &&
           jkvec(x, "direction", direction, 3) && jnum(x, "distance", distance) && jkvec(x, "edge", edge, 2);
}

/* One entry of "pipes" (cdsp_host_pipe_fields' names). */
static int jpipe(json_object *o, cdspd_pipe *p)
{
    json_object *x;
    int ok = json_object_is_type(o, json_type_object) && jkvec(o, "point", p->point, 3) &&
             jkvec(o, "direction", p->direction, 3) && jnum(o, "distance", &p->distance) &&
             jmat(o, "segment", p->segment) && jmat(o, "lines", p->lines) &&
             jnum(o, "confidence", &p->confidence);
    if (!ok || !json_object_object_get_ex(o, "sigma", &x) ||
        !jkvec(x, "point", p->sigma_point, 3) || !jkvec(x, "direction", p->sigma_direction, 3) ||
        !jnum(x, "distance", &p->sigma_distance))
        return 0;
    if (!jbound(o, p->bound_point, p->bound_direction, &p->bound_distance, p->edge_bound))
        return 0;
    if (!json_object_object_get_ex(o, "inliers", &x) || !json_object_is_type(x, json_type_array) ||
        json_object_array_length(x) != 2 || !ju32_of(json_object_array_get_idx(x, 0), &p->inliers[0]) ||
        !ju32_of(json_object_array_get_idx(x, 1), &p->inliers[1]))
        return 0;
    /* track_id: absent when the writer did not track */
    return !json_object_object_get_ex(o, "track_id", &x) || ju32_of(x, &p->track_id);
}

int cdspd_proto_decode_json(const char *text, size_t len, cdspd_record *r, const char **why)
{
    json_tokener *tok;
    json_object *o, *x;
    const char *dummy, *kind, *status, *error;
    double v;
    size_t end;
    int ok = 1;

    if (!why)
        why = &dummy;
    tok = json_tokener_new();
    if (!tok) {
        *why = "out of memory";
        return -1;
    }
    if (len > INT_MAX)
        len = INT_MAX; /* json-c takes an int; a datagram is far shorter */
    o = json_tokener_parse_ex(tok, text, (int)len);
    end = json_tokener_get_parse_end(tok);
    json_tokener_free(tok);
    if (!o || !json_object_is_type(o, json_type_object)) {
        if (o)
            json_object_put(o);
        *why = "not a JSON object";
        return -1;
    }
    /* one object per datagram: bytes after it (but white space) would be
     * another message smuggled behind this one */
    while (end < len && (text[end] == ' ' || text[end] == '\t' || text[end] == '\n' ||
                         text[end] == '\r'))
        end++;
    if (end < len) {
        json_object_put(o);
        *why = "bytes after the JSON object";
        return -1;
    }
    memset(r, 0, sizeof *r);
    r->version = CDSPD_PROTO_VERSION;
    r->seq = (uint32_t)ju64(o, "seq", &ok);
    r->frame_id = ju64(o, "frame", &ok);
    r->t_camera_us = ju64(o, "t_camera_us", &ok);
    r->t_host_us = ju64(o, "t_host_us", &ok);
    r->kind = CDSPD_KIND_FRAME;
    kind = jstr(o, "kind");
    status = jstr(o, "status");
    error = jstr(o, "error");
    if (kind && !strcmp(kind, "status"))
        r->kind = CDSPD_KIND_STATUS;
    else if (kind ? strcmp(kind, "frame") != 0 : json_object_object_get_ex(o, "kind", NULL))
        ok = 0; /* a kind that is not "frame" or "status", or not a string */
    if (!status) {
        ok = 0;
    } else if (!strcmp(status, "ok")) {
        r->status = 0;
        ok = ok && jkvec(o, "point", r->point, 3) && jkvec(o, "direction", r->direction, 3) &&
             jnum(o, "distance", &r->distance) && jnum(o, "alpha", &r->alpha) &&
             jmat(o, "lines", r->lines) && jmat(o, "segment", r->segment) &&
             jkvec(o, "rms", r->rms, 2) && jcounts(o, r);
        if (ok && json_object_object_get_ex(o, "sigma", &x)) {
            ok = jkvec(x, "point", r->sigma_point, 3) && jkvec(x, "direction", r->sigma_direction, 3) &&
                 jnum(x, "distance", &r->sigma_distance);
        } else {
            ok = 0;
        }
        if (jbool(o, "tracked"))
            r->flags |= CDSPD_FLAG_TRACKED;
        if (jbool(o, "full_search"))
            r->flags |= CDSPD_FLAG_FULL_SEARCH;
        if (jbool(o, "truncated"))
            r->flags |= CDSPD_FLAG_TRUNCATED;
        ok = ok && jnum(o, "confidence", &r->confidence) &&
             jbound(o, r->bound_point, r->bound_direction, &r->bound_distance, r->edge_bound);
    } else {
        int st = 0;
        if (strcmp(status, "error") || !error || !cdspd_status_from_token(error, &st) || st == 0)
            ok = 0;
        r->status = st;
    }
    if (json_object_object_get_ex(o, "radius", &x)) {
        if (jnum_of(x, &v))
            r->radius = v;
        else
            ok = 0; /* given, but not a finite number */
    }
    if (jbool(o, "source_down"))
        r->flags |= CDSPD_FLAG_SOURCE_DOWN;
    if (jbool(o, "recorded"))
        r->flags |= CDSPD_FLAG_RECORDED;
    r->proc_us = (uint32_t)ju64(o, "proc_us", &ok);
    r->latency_us = (uint32_t)ju64(o, "latency_us", &ok);
    r->frames_in = (uint32_t)ju64(o, "frames_in", &ok);
    r->frames_dropped = (uint32_t)ju64(o, "frames_dropped", &ok);
    r->frames_bad = (uint32_t)ju64(o, "frames_bad", &ok);
    r->reconnects = (uint32_t)ju64(o, "reconnects", &ok);
    /* the body-frame pose: absent from a datagram of an older cdspd */
    if (r->status == 0 && json_object_object_get_ex(o, "body", &x) &&
        json_object_is_type(x, json_type_object))
        ok = ok && jkvec(x, "point", r->point_body, 3) && jkvec(x, "direction", r->direction_body, 3);
    if (json_object_object_get_ex(o, "pipes", &x)) {
        size_t k, np;
        r->flags |= CDSPD_FLAG_MULTI;
        if (!json_object_is_type(x, json_type_array) ||
            (np = json_object_array_length(x)) > CDSP_MAX_PIPES || (np > 0 && r->status != 0)) {
            ok = 0;
        } else {
            r->n_pipes = (uint32_t)np;
            for (k = 0; k < np && ok; k++)
                ok = jpipe(json_object_array_get_idx(x, k), &r->pipe[k]);
        }
    }
    if (json_object_object_get_ex(o, "truth", &x) && json_object_is_type(x, json_type_object)) {
        r->has_truth = 1;
        r->truth_in_view = jbool(x, "in_view");
        if (r->truth_in_view)
            ok = ok && jkvec(x, "point", r->truth_point, 3) &&
                 jkvec(x, "direction", r->truth_direction, 3) &&
                 jnum(x, "distance", &r->truth_distance);
    }
    json_object_put(o);
    if (!ok) {
        *why = "JSON record lacks a field or has one of the wrong type";
        return -1;
    }
    return 0;
}

int cdspd_proto_decode_any(const uint8_t *buf, size_t len, cdspd_record *r, int *is_json,
                           const char **why)
{
    if (len > 0 && buf[0] == '{') {
        if (is_json)
            *is_json = 1;
        return cdspd_proto_decode_json((const char *)buf, len, r, why);
    }
    if (is_json)
        *is_json = 0;
    return cdspd_proto_decode(buf, len, r, why);
}
