/*
 * calib.c - the ROS camera_info YAML (the file ROS's camera_calibration and
 * many camera drivers write, and cdsp_calib writes) to and from cdsp_camera.
 * Parsed by libyaml's document API; every field is checked for presence,
 * shape (rows x cols = count of data) and finiteness, and a problem is
 * reported with the file name and the field's path, e.g.
 * "cam.yaml: camera_matrix.data: expected 9 numbers, got 8".
 * The library has no skew term, so a non-zero skew is refused rather than
 * silently dropped; likewise the rational model's k4..k6 (8 coefficients).
 * plumb_bob may have 4 coefficients (k3 = 0) or 5.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host_yaml.h"

/* Messages name the file, or this when no name was given. */
#define fail(err, rc, name, ...) cdsp_host__fail(err, rc, (name) ? (name) : "(calibration)", __VA_ARGS__)

typedef struct {
    yaml_document_t *doc;
    const char *name;
    cdsp_host_err *err;
} ctx;

static const char *node_kind(const yaml_node_t *n)
{
    switch (n->type) {
    case YAML_SCALAR_NODE: return "a scalar";
    case YAML_SEQUENCE_NODE: return "a list";
    case YAML_MAPPING_NODE: return "a mapping";
    default: return "nothing";
    }
}

/* The value of key in mapping m; NULL if absent. A key given twice is an
 * error (-1 in *dup). */
static yaml_node_t *map_get(ctx *c, yaml_node_t *m, const char *key, int *dup)
{
    yaml_node_pair_t *p;
    yaml_node_t *found = NULL;
    *dup = 0;
    for (p = m->data.mapping.pairs.start; p < m->data.mapping.pairs.top; p++) {
        yaml_node_t *k = yaml_document_get_node(c->doc, p->key);
        if (!k || k->type != YAML_SCALAR_NODE)
            continue;
        if (k->data.scalar.length == strlen(key) &&
            memcmp(k->data.scalar.value, key, k->data.scalar.length) == 0) {
            if (found)
                *dup = 1;
            found = yaml_document_get_node(c->doc, p->value);
        }
    }
    return found;
}

static int get_field(ctx *c, yaml_node_t *m, const char *key, const char *path, yaml_node_t **out)
{
    int dup;
    *out = map_get(c, m, key, &dup);
    if (dup)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: given more than once", path);
    if (!*out)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: missing", path);
    return CDSP_HOST_OK;
}

/* A scalar as a finite double: the whole text must be a number. */
static int scalar_real(ctx *c, yaml_node_t *n, const char *path, double *out)
{
    char buf[64], *end;
    size_t len;
    double v;
    if (n->type != YAML_SCALAR_NODE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected a number, got %s", path,
                    node_kind(n));
    len = n->data.scalar.length;
    if (len == 0 || len >= sizeof buf)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected a number, got \"%.*s\"",
                    path, (int)(len < 40 ? len : 40), (const char *)n->data.scalar.value);
    memcpy(buf, n->data.scalar.value, len);
    buf[len] = 0;
    errno = 0;
    v = strtod(buf, &end);
    /* decimal only: strtod would also take hex, "inf" and "nan" */
    if (end == buf || *end != 0 || strspn(buf, "0123456789+-.eE") != len)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected a number, got \"%s\"",
                    path, buf);
    if (!isfinite(v) || errno == ERANGE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: %s is not a finite number", path,
                    buf);
    *out = v;
    return CDSP_HOST_OK;
}

static int field_int(ctx *c, yaml_node_t *m, const char *key, const char *path, long lo, long hi,
                     long *out)
{
    yaml_node_t *n;
    double v;
    int rc = get_field(c, m, key, path, &n);
    if (!rc)
        rc = scalar_real(c, n, path, &v);
    if (rc)
        return rc;
    if (v != floor(v))
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected an integer, got %g", path,
                    v);
    if (v < (double)lo || v > (double)hi)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: %.0f outside %ld..%ld", path, v, lo,
                    hi);
    *out = (long)v;
    return CDSP_HOST_OK;
}

/* A {rows, cols, data} matrix of exactly `count` numbers (rows x cols =
 * count when rows/cols are given; ROS always writes them). */
static int field_matrix(ctx *c, yaml_node_t *root, const char *key, int rows, int cols,
                        double *out)
{
    yaml_node_t *m, *data;
    yaml_node_item_t *it;
    char path[96];
    long r, k;
    int rc, dup, count = rows * cols, got, i;
    rc = get_field(c, root, key, key, &m);
    if (rc)
        return rc;
    if (m->type != YAML_MAPPING_NODE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "%s: expected a mapping {rows, cols, data}, got %s", key, node_kind(m));
    if (map_get(c, m, "rows", &dup)) {
        snprintf(path, sizeof path, "%s.rows", key);
        rc = field_int(c, m, "rows", path, 0, 1000, &r);
        if (rc)
            return rc;
        if (r != rows)
            return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected %d, got %ld", path,
                        rows, r);
    }
    if (map_get(c, m, "cols", &dup)) {
        snprintf(path, sizeof path, "%s.cols", key);
        rc = field_int(c, m, "cols", path, 0, 1000, &k);
        if (rc)
            return rc;
        if (k != cols)
            return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected %d, got %ld", path,
                        cols, k);
    }
    snprintf(path, sizeof path, "%s.data", key);
    rc = get_field(c, m, "data", path, &data);
    if (rc)
        return rc;
    if (data->type != YAML_SEQUENCE_NODE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected a list of %d numbers, got %s",
                    path, count, node_kind(data));
    got = (int)(data->data.sequence.items.top - data->data.sequence.items.start);
    if (got != count)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected %d numbers, got %d", path,
                    count, got);
    for (i = 0, it = data->data.sequence.items.start; i < count; i++, it++) {
        char ipath[112];
        yaml_node_t *n = yaml_document_get_node(c->doc, *it);
        snprintf(ipath, sizeof ipath, "%s[%d]", path, i);
        if (!n)
            return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: missing", ipath);
        rc = scalar_real(c, n, ipath, &out[i]);
        if (rc)
            return rc;
    }
    return CDSP_HOST_OK;
}

static int field_string(ctx *c, yaml_node_t *m, const char *key, char *out, size_t cap)
{
    yaml_node_t *n;
    size_t len;
    int rc = get_field(c, m, key, key, &n);
    if (rc)
        return rc;
    if (n->type != YAML_SCALAR_NODE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "%s: expected a name, got %s", key,
                    node_kind(n));
    len = n->data.scalar.length < cap - 1 ? n->data.scalar.length : cap - 1;
    memcpy(out, n->data.scalar.value, len);
    out[len] = 0;
    return CDSP_HOST_OK;
}

/* How many plumb_bob coefficients the file gives: 4 (k1 k2 p1 p2, as
 * OpenCV and some ROS drivers write; k3 = 0) or 5. Eight is OpenCV's
 * rational model (k1 k2 p1 p2 k3 k4 k5 k6), which the library's
 * distortion model cannot represent: refused by name, not truncated. */
static int coeff_count(ctx *c, yaml_node_t *root, int *count)
{
    yaml_node_t *m, *data;
    int dup, n;
    m = map_get(c, root, "distortion_coefficients", &dup);
    if (!m || dup || m->type != YAML_MAPPING_NODE)
        goto plain; /* field_matrix reports it */
    data = map_get(c, m, "data", &dup);
    if (!data || dup || data->type != YAML_SEQUENCE_NODE)
        goto plain;
    n = (int)(data->data.sequence.items.top - data->data.sequence.items.start);
    if (n == 8)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "distortion_coefficients.data: 8 coefficients is OpenCV's rational model "
                    "(k4, k5, k6), which cdsp does not support: calibrate with plumb_bob "
                    "(4 or 5 coefficients, k1 k2 p1 p2 [k3])");
    if (n == 4) {
        *count = 4;
        return CDSP_HOST_OK;
    }
plain:
    *count = 5;
    return CDSP_HOST_OK;
}

static int from_document(ctx *c, cdsp_camera *cam)
{
    yaml_node_t *root = yaml_document_get_root_node(c->doc);
    double K[9], D[5];
    long w, h;
    char model[64];
    int rc, nd = 5;
    if (!root)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "empty calibration file");
    if (root->type != YAML_MAPPING_NODE)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "expected a mapping of camera_info keys at the top, got %s", node_kind(root));
    rc = field_int(c, root, "image_width", "image_width", 1, CDSP_HOST_MAX_DIM, &w);
    if (!rc)
        rc = field_int(c, root, "image_height", "image_height", 1, CDSP_HOST_MAX_DIM, &h);
    if (!rc)
        rc = field_matrix(c, root, "camera_matrix", 3, 3, K);
    if (!rc)
        rc = field_string(c, root, "distortion_model", model, sizeof model);
    if (rc)
        return rc;
    if (strcmp(model, "rational_polynomial") == 0)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "distortion_model: \"rational_polynomial\" (OpenCV's rational model, 8 "
                    "coefficients) is not supported: calibrate with plumb_bob");
    if (strcmp(model, "plumb_bob") != 0)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "distortion_model: \"%s\" is not supported (only plumb_bob)", model);
    rc = coeff_count(c, root, &nd);
    if (!rc)
        rc = field_matrix(c, root, "distortion_coefficients", 1, nd, D);
    if (rc)
        return rc;
    if (nd == 4)
        D[4] = 0; /* k1 k2 p1 p2: the r^6 term is absent, i.e. zero */
    if (!(K[0] > 0) || !(K[4] > 0))
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "camera_matrix.data: focal lengths fx = %g, fy = %g must be positive", K[0],
                    K[4]);
    if (K[1] != 0)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "camera_matrix.data[1]: skew %g is not supported (must be 0)", K[1]);
    if (K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name,
                    "camera_matrix.data: not a camera matrix [fx, 0, cx, 0, fy, cy, 0, 0, 1]");
    cam->fx = (cdsp_real)K[0];
    cam->cx = (cdsp_real)K[2];
    cam->fy = (cdsp_real)K[4];
    cam->cy = (cdsp_real)K[5];
    cam->k1 = (cdsp_real)D[0];
    cam->k2 = (cdsp_real)D[1];
    cam->p1 = (cdsp_real)D[2];
    cam->p2 = (cdsp_real)D[3];
    cam->k3 = (cdsp_real)D[4];
    cam->width = (int)w;
    cam->height = (int)h;
    if (cdsp_camera_check(cam) != CDSP_OK)
        return fail(c->err, CDSP_HOST_E_FORMAT, c->name, "not a valid camera (%s)",
                    cdsp_strerror(cdsp_camera_check(cam)));
    return CDSP_HOST_OK;
}

int cdsp_host_calib_parse(const char *text, size_t len, const char *name, cdsp_camera *cam,
                          cdsp_host_err *err)
{
    yaml_document_t doc;
    ctx c;
    int rc;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty calibration file");
    if (len > CDSP_HOST_YAML_MAX_BYTES)
        return fail(err, CDSP_HOST_E_LIMIT, name, "calibration file larger than %d bytes",
                    CDSP_HOST_YAML_MAX_BYTES);
    rc = cdsp_host_yaml_load(text, len, name ? name : "(calibration)", &doc, err);
    if (rc)
        return rc;
    c.doc = &doc;
    c.name = name;
    c.err = err;
    rc = from_document(&c, cam);
    yaml_document_delete(&doc);
    return rc;
}

int cdsp_host_calib_read(const char *path, cdsp_camera *cam, cdsp_host_err *err)
{
    void *buf;
    size_t len;
    int rc = cdsp_host_read_file(path, CDSP_HOST_YAML_MAX_BYTES, &buf, &len, err);
    if (rc)
        return rc;
    rc = cdsp_host_calib_parse(buf, len, path, cam, err);
    free(buf);
    return rc;
}

int cdsp_host_calib_write(const char *path, const cdsp_camera *cam, const char *camera_name,
                          cdsp_host_err *err)
{
    char nm[64], b[12][32];
    size_t i, k = 0;
    FILE *f;
    int bad;
    const char *src = camera_name ? camera_name : "cdsp";
    for (i = 0; src[i] && k < sizeof nm - 1; i++) {
        char ch = src[i];
        if ((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
            ch == '_' || ch == '-' || ch == '.')
            nm[k++] = ch;
    }
    nm[k] = 0;
    if (k == 0)
        strcpy(nm, "cdsp");
    if (cdsp_camera_check(cam) != CDSP_OK)
        return fail(err, CDSP_HOST_E_FORMAT, path, "refusing to write an invalid camera");
    f = fopen(path, "w");
    if (!f)
        return fail(err, CDSP_HOST_E_IO, path, "cannot create: %s", strerror(errno));
    cdsp_host_fmt_real(b[0], cam->fx);
    cdsp_host_fmt_real(b[1], cam->fy);
    cdsp_host_fmt_real(b[2], cam->cx);
    cdsp_host_fmt_real(b[3], cam->cy);
    cdsp_host_fmt_real(b[4], cam->k1);
    cdsp_host_fmt_real(b[5], cam->k2);
    cdsp_host_fmt_real(b[6], cam->p1);
    cdsp_host_fmt_real(b[7], cam->p2);
    cdsp_host_fmt_real(b[8], cam->k3);
    fprintf(f,
            "image_width: %d\n"
            "image_height: %d\n"
            "camera_name: %s\n"
            "camera_matrix:\n"
            "  rows: 3\n"
            "  cols: 3\n"
            "  data: [%s, 0, %s, 0, %s, %s, 0, 0, 1]\n"
            "distortion_model: plumb_bob\n"
            "distortion_coefficients:\n"
            "  rows: 1\n"
            "  cols: 5\n"
            "  data: [%s, %s, %s, %s, %s]\n"
            "rectification_matrix:\n"
            "  rows: 3\n"
            "  cols: 3\n"
            "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
            "projection_matrix:\n"
            "  rows: 3\n"
            "  cols: 4\n"
            "  data: [%s, 0, %s, 0, 0, %s, %s, 0, 0, 0, 1, 0]\n",
            cam->width, cam->height, nm, b[0], b[2], b[1], b[3], b[4], b[5], b[6], b[7], b[8],
            b[0], b[2], b[1], b[3]);
    bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return fail(err, CDSP_HOST_E_IO, path, "write failed: %s", strerror(errno));
    return CDSP_HOST_OK;
}

int cdsp_host_calib_match(const cdsp_camera *cam, const char *calib_name, int width, int height,
                          const char *frame_name, cdsp_host_err *err)
{
    if (cam->width == width && cam->height == height)
        return CDSP_HOST_OK;
    return fail(err, CDSP_HOST_E_MISMATCH, frame_name, "image is %dx%d but %s is for %dx%d", width,
                height, calib_name ? calib_name : "the calibration", cam->width, cam->height);
}
