/*
 * tool_export.c - `cdsp_tool export`: reconstructed pipes as a triangle
 * mesh, a closed cylinder of the known radius along each visible axis
 * segment, in PLY (with colours) or OBJ, for MeshLab or Blender: the 3D
 * view of the paper's figures 5 and 9. Input is what `solve` writes (JSON
 * Lines, read with json-c) or the truth.json of `sim`, so a reconstruction
 * and its ground truth can be opened side by side.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <errno.h>
#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double a[3], b[3], r;
    int camera; /* the camera marker, not a pipe */
} part;

typedef struct {
    part *p;
    size_t n, cap;
} parts;

typedef struct {
    const char *out;
    int format, sides, y_up, no_camera;
    double radius, length;
} export_opts;

static const char export_description[] =
    "    Reads the records of `cdsp_tool solve` (JSON Lines; FILE \"-\" is standard\n"
    "    input) and writes each solved pipe as a closed cylinder of its radius\n"
    "    along its visible axis segment, plus a small pyramid for the camera at\n"
    "    the origin looking along +Z. Error records are skipped. A truth.json\n"
    "    written by `cdsp_tool sim` is read as well (each simulated cylinder,\n"
    "    at its true pose), so a reconstruction and its ground truth can be\n"
    "    compared in one viewer.\n"
    "\n"
    "    Coordinates are the camera's (X right, Y down, Z forward) in the unit of\n"
    "    the radius; --y-up turns them to Y up, Z backward (a rotation of 180\n"
    "    degrees about X), as Blender and MeshLab show by default. PLY files are\n"
    "    ASCII with a colour per vertex (pipes in turn blue, orange, green, ...;\n"
    "    the camera gray); OBJ files have one object per pipe (pipe_1, ...).\n\n";

static const char export_after[] =
    "EXAMPLES\n"
    "    cdsp_tool solve --calib cam.yaml --radius 8 frames/ > poses.jsonl\n"
    "    cdsp_tool export --out pipes.ply poses.jsonl\n"
    "    cdsp_tool export --format obj --y-up poses.jsonl > pipes.obj\n"
    "    cdsp_tool export --out truth.ply sim1/truth.json\n";

static const char export_exit[] =
    "    0  the mesh was written with at least one pipe\n"
    "    1  no record held a solved pipe (a camera-only mesh was written)\n"
    "    2  usage error, an unreadable or malformed input (the message names the\n"
    "       file and line), or the output could not be written\n";

static int add_part(parts *ps, const double a[3], const double b[3], double r, int camera)
{
    part *np = tool_grow(ps->p, &ps->cap, ps->n, sizeof *np, 16);
    if (!np)
        return -1;
    ps->p = np;
    memcpy(ps->p[ps->n].a, a, sizeof ps->p[0].a);
    memcpy(ps->p[ps->n].b, b, sizeof ps->p[0].b);
    ps->p[ps->n].r = r;
    ps->p[ps->n].camera = camera;
    ps->n++;
    return 0;
}

/* A segment from a point, a direction and a length, centred. */
static void centred(const double p[3], const double d[3], double len, double a[3], double b[3])
{
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    int i;
    for (i = 0; i < 3; i++) {
        a[i] = p[i] - 0.5 * len * d[i] / n;
        b[i] = p[i] + 0.5 * len * d[i] / n;
    }
}

/* Coordinates and radii the mesh takes, unit of the radius: beyond them a
 * vertex (an end +- r along two unit vectors) or a difference of two ends
 * would overflow to Inf and print as null. 1e12 radii is far beyond any
 * pose libcdsp reports (CDSP_MAX_RADIUS is 1e9). */
#define EXPORT_MAX_COORD 1e12

/* A cylinder the mesh can be built of: 1, or 0 with *why. */
static int pipe_ok(const double a[3], const double b[3], double r, const char **why)
{
    double d2 = 0;
    int i;
    if (!(r > 0) || !(r <= EXPORT_MAX_COORD)) {
        *why = "the radius is not in (0, 1e12]";
        return 0;
    }
    for (i = 0; i < 3; i++) {
        if (!(fabs(a[i]) <= EXPORT_MAX_COORD) || !(fabs(b[i]) <= EXPORT_MAX_COORD)) {
            *why = "a coordinate beyond 1e12 (unit of the radius): cannot be meshed";
            return 0;
        }
        d2 += (b[i] - a[i]) * (b[i] - a[i]);
    }
    if (!(d2 > 0)) {
        *why = "the axis has no direction (zero vector): cannot be meshed";
        return 0;
    }
    return 1;
}

static int nonzero(const double d[3])
{
    return d[0] != 0 || d[1] != 0 || d[2] != 0;
}

/* One pipe of a record (the record itself, or an entry of its "pipes"):
 * 0 added, -1 malformed. */
static int from_pose(json_object *o, double r, const export_opts *E, parts *ps, const char **why)
{
    double seg[2][3], point[3], dir[3], len;
    if (tool_json_vec(o, "point", point, 3) || tool_json_vec(o, "direction", dir, 3)) {
        *why = "\"point\" or \"direction\" missing or not three numbers";
        return -1;
    }
    {
        json_object *sg;
        if (!json_object_object_get_ex(o, "segment", &sg) ||
            !json_object_is_type(sg, json_type_array) || json_object_array_length(sg) != 2 ||
            tool_json_array(json_object_array_get_idx(sg, 0), seg[0], 3) != 0 ||
            tool_json_array(json_object_array_get_idx(sg, 1), seg[1], 3) != 0) {
            *why = "\"segment\" is not two points";
            return -1;
        }
    }
    len = sqrt((seg[1][0] - seg[0][0]) * (seg[1][0] - seg[0][0]) +
               (seg[1][1] - seg[0][1]) * (seg[1][1] - seg[0][1]) +
               (seg[1][2] - seg[0][2]) * (seg[1][2] - seg[0][2]));
    if (!nonzero(dir)) {
        *why = "\"direction\" is the zero vector";
        return -1;
    }
    if (!(len > 1e-9 * r)) /* extent unknown: a piece of the given length */
        centred(point, dir, E->length > 0 ? E->length : 20 * r, seg[0], seg[1]);
    if (!pipe_ok(seg[0], seg[1], r, why))
        return -1;
    if (add_part(ps, seg[0], seg[1], r, 0) != 0) {
        *why = "out of memory";
        return -1;
    }
    return 0;
}

/* One solve record; the pipes added (every entry of "pipes" when the
 * record has it, from solve --all or cdspd multi_pipe; else the record's
 * own pose), 0 for an error record, -1 malformed, -2 not a record at all
 * (no "status"). */
static int from_record(json_object *o, const export_opts *E, parts *ps, const char **why)
{
    json_object *st, *pipes;
    double r = E->radius;
    size_t i, n;
    if (!json_object_object_get_ex(o, "status", &st) || !json_object_is_type(st, json_type_string)) {
        *why = "no \"status\"";
        return -2;
    }
    if (strcmp(json_object_get_string(st), "ok") != 0)
        return 0;
    if (!(r > 0) && tool_json_num(o, "radius", &r) != 0) {
        *why = "no \"radius\" (give --radius)";
        return -1;
    }
    if (!json_object_object_get_ex(o, "pipes", &pipes))
        return from_pose(o, r, E, ps, why) == 0 ? 1 : -1;
    if (!json_object_is_type(pipes, json_type_array)) {
        *why = "\"pipes\" is not a list";
        return -1;
    }
    n = json_object_array_length(pipes);
    for (i = 0; i < n; i++) {
        json_object *p = json_object_array_get_idx(pipes, i);
        if (!json_object_is_type(p, json_type_object)) {
            *why = "an entry of \"pipes\" is not an object";
            return -1;
        }
        if (from_pose(p, r, E, ps, why) != 0)
            return -1;
    }
    return (int)(n > 1000000 ? 1000000 : n);
}

/* sim's truth.json: {"radius": R, "frames": [{axis_point, axis_dir, half_length}]}. */
static int from_truth(json_object *o, const export_opts *E, parts *ps, const char **why)
{
    json_object *frames;
    double r = E->radius;
    size_t i, n;
    int added = 0;
    if (!(r > 0) && tool_json_num(o, "radius", &r) != 0) {
        *why = "no \"radius\"";
        return -1;
    }
    json_object_object_get_ex(o, "frames", &frames);
    if (!json_object_is_type(frames, json_type_array)) {
        *why = "\"frames\" is not a list";
        return -1;
    }
    n = json_object_array_length(frames);
    for (i = 0; i < n; i++) {
        json_object *f = json_object_array_get_idx(frames, i);
        double p[3], d[3], half, a[3], b[3];
        if (tool_json_vec(f, "axis_point", p, 3) || tool_json_vec(f, "axis_dir", d, 3) ||
            tool_json_num(f, "half_length", &half)) {
            *why = "a frame without axis_point, axis_dir, half_length";
            return -1;
        }
        if (!nonzero(d)) {
            *why = "a frame whose axis_dir is the zero vector";
            return -1;
        }
        centred(p, d, half > 0 ? 2 * half : (E->length > 0 ? E->length : 20 * r), a, b);
        if (!pipe_ok(a, b, r, why))
            return -1;
        if (add_part(ps, a, b, r, 0) != 0) {
            *why = "out of memory";
            return -1;
        }
        added++;
    }
    return added;
}

/* What export reads: each line of solve's JSON Lines (from_record), or a
 * file that is one JSON document: sim's truth.json (it has "frames") or a
 * single record, pretty-printed or not. */
typedef struct {
    const export_opts *E;
    parts *ps;
    int pipes;
} export_input;

static int export_record(json_object *o, size_t line, void *ctx, const char **why)
{
    export_input *in = ctx;
    int k = line == 0 && json_object_object_get_ex(o, "frames", NULL)
                ? from_truth(o, in->E, in->ps, why)
                : from_record(o, in->E, in->ps, why);
    if (k < 0)
        return k == -2 ? TOOL_JSONL_NOT_RECORD : TOOL_JSONL_BAD;
    in->pipes += k;
    return TOOL_JSONL_OK;
}

static const tool_jsonl export_jsonl = {
    export_record, 1, "it looks like CSV; export reads JSON Lines (solve without --csv)"};

static int read_input(const char *path, const export_opts *E, parts *ps, int *pipes)
{
    void *buf;
    size_t len;
    const char *name;
    export_input in;
    int rc;
    if (tool_read_input("export", path, &buf, &len, &name) != 0)
        return TOOL_EXIT_USAGE;
    in.E = E;
    in.ps = ps;
    in.pipes = 0;
    rc = tool_jsonl_read("export", name, buf, len, &export_jsonl, &in);
    free(buf);
    *pipes += in.pipes;
    return rc;
}

/* ---- mesh --------------------------------------------------------------------- */

typedef struct {
    double (*v)[3];
    uint8_t (*c)[3];
    int (*f)[3];
    size_t nv, nf;
    int *first_face; /* per part: index of its first face (OBJ objects) */
} mesh;

static void orient(const export_opts *E, const double in[3], double out[3])
{
    out[0] = in[0];
    out[1] = E->y_up ? -in[1] : in[1];
    out[2] = E->y_up ? -in[2] : in[2];
}

static void vert(mesh *m, const export_opts *E, const double p[3], const uint8_t col[3])
{
    orient(E, p, m->v[m->nv]);
    memcpy(m->c[m->nv], col, 3);
    m->nv++;
}

static void face(mesh *m, size_t a, size_t b, size_t c)
{
    m->f[m->nf][0] = (int)a;
    m->f[m->nf][1] = (int)b;
    m->f[m->nf][2] = (int)c;
    m->nf++;
}

static void cylinder(mesh *m, const export_opts *E, const part *p, const uint8_t col[3])
{
    double u[3], e1[3], e2[3], h[3] = {1, 0, 0}, n;
    size_t base = m->nv, i, k = (size_t)E->sides;
    int j;
    for (j = 0; j < 3; j++)
        u[j] = p->b[j] - p->a[j];
    n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (j = 0; j < 3; j++)
        u[j] /= n;
    if (fabs(u[0]) > 0.9)
        h[0] = 0, h[1] = 1;
    /* e1 = u x h normalized, e2 = u x e1: e1 x e2 = u */
    e1[0] = u[1] * h[2] - u[2] * h[1];
    e1[1] = u[2] * h[0] - u[0] * h[2];
    e1[2] = u[0] * h[1] - u[1] * h[0];
    n = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (j = 0; j < 3; j++)
        e1[j] /= n;
    e2[0] = u[1] * e1[2] - u[2] * e1[1];
    e2[1] = u[2] * e1[0] - u[0] * e1[2];
    e2[2] = u[0] * e1[1] - u[1] * e1[0];
    for (i = 0; i < k; i++) {
        double t = 2 * 3.14159265358979323846 * (double)i / (double)k, q[3];
        for (j = 0; j < 3; j++)
            q[j] = p->a[j] + p->r * (cos(t) * e1[j] + sin(t) * e2[j]);
        vert(m, E, q, col);
        for (j = 0; j < 3; j++)
            q[j] = p->b[j] + p->r * (cos(t) * e1[j] + sin(t) * e2[j]);
        vert(m, E, q, col);
    }
    vert(m, E, p->a, col);
    vert(m, E, p->b, col);
    /* vertex 2i: ring at a, 2i+1: ring at b; outward-facing windings */
    for (i = 0; i < k; i++) {
        size_t a0 = base + 2 * i, b0 = a0 + 1, a1 = base + 2 * ((i + 1) % k), b1 = a1 + 1;
        face(m, a0, a1, b1);
        face(m, a0, b1, b0);
        face(m, base + 2 * k, a1, a0);
        face(m, base + 2 * k + 1, b0, b1);
    }
}

static void camera_marker(mesh *m, const export_opts *E, double s)
{
    static const uint8_t gray[3] = {160, 160, 160};
    static const double corner[4][2] = {{-0.6, -0.45}, {0.6, -0.45}, {0.6, 0.45}, {-0.6, 0.45}};
    double o[3] = {0, 0, 0};
    size_t base = m->nv;
    int i;
    vert(m, E, o, gray);
    for (i = 0; i < 4; i++) {
        double q[3] = {corner[i][0] * s, corner[i][1] * s, s};
        vert(m, E, q, gray);
    }
    for (i = 0; i < 4; i++)
        face(m, base, base + 1 + (size_t)((i + 1) % 4), base + 1 + (size_t)i);
    face(m, base + 1, base + 2, base + 3);
    face(m, base + 1, base + 3, base + 4);
}

static int write_mesh(const char *path, int obj, const mesh *m, const parts *ps)
{
    FILE *f = path ? fopen(path, "w") : stdout;
    size_t i, part_i = 0;
    int bad;
    char b[3][32];
    if (!f)
        return tool_usage_error("export", "%s: cannot create: %s", path, strerror(errno));
    if (obj) {
        size_t pipes = 0;
        for (i = 0; i < ps->n; i++)
            pipes += !ps->p[i].camera;
        fprintf(f, "# cdsp_tool export: %zu pipe(s), camera frame, units of the radius\n",
                pipes);
        for (i = 0; i < m->nv; i++)
            fprintf(f, "v %s %s %s\n", cdsp_host_fmt_real(b[0], m->v[i][0]),
                    cdsp_host_fmt_real(b[1], m->v[i][1]), cdsp_host_fmt_real(b[2], m->v[i][2]));
        for (i = 0; i < m->nf; i++) {
            while (part_i < ps->n && (size_t)m->first_face[part_i] == i) {
                if (ps->p[part_i].camera)
                    fprintf(f, "o camera\n");
                else
                    fprintf(f, "o pipe_%zu\n", part_i + 1 - (ps->p[0].camera ? 1u : 0u));
                part_i++;
            }
            fprintf(f, "f %d %d %d\n", m->f[i][0] + 1, m->f[i][1] + 1, m->f[i][2] + 1);
        }
    } else {
        fprintf(f,
                "ply\nformat ascii 1.0\ncomment cdsp_tool export: camera frame, units of the "
                "radius\nelement vertex %zu\nproperty double x\nproperty double y\nproperty "
                "double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
                m->nv, m->nf);
        for (i = 0; i < m->nv; i++)
            fprintf(f, "%s %s %s %u %u %u\n", cdsp_host_fmt_real(b[0], m->v[i][0]),
                    cdsp_host_fmt_real(b[1], m->v[i][1]), cdsp_host_fmt_real(b[2], m->v[i][2]),
                    m->c[i][0], m->c[i][1], m->c[i][2]);
        for (i = 0; i < m->nf; i++)
            fprintf(f, "3 %d %d %d\n", m->f[i][0], m->f[i][1], m->f[i][2]);
    }
    bad = ferror(f);
    if (path)
        bad |= fclose(f) != 0;
    else
        bad |= fflush(f) != 0;
    if (bad)
        return tool_usage_error("export", "%s: write failed: %s", path ? path : "(stdout)",
                                strerror(errno));
    return 0;
}

static int ends_with(const char *s, const char *suf)
{
    size_t n = strlen(s), k = strlen(suf);
    return n >= k && strcmp(s + n - k, suf) == 0;
}

int tool_export_main(int argc, char **argv)
{
    static const uint8_t palette[6][3] = {{40, 110, 230}, {240, 140, 20}, {40, 170, 60},
                                          {200, 40, 40}, {140, 80, 200}, {20, 170, 170}};
    export_opts E;
    parts ps = {NULL, 0, 0};
    mesh m;
    char **pos;
    int npos = 0, rc, i, pipes = 0, fmt_given;
    size_t k, nv, nf;
    double mean_dist = 0;
    static const tool_doc doc = {"export", "solved pipes as a PLY or OBJ mesh of cylinders",
                                 "[OPTIONS] [--out FILE] RECORDS.jsonl|truth.json|-...",
                                 export_description, export_after, export_exit};
    memset(&E, 0, sizeof E);
    memset(&m, 0, sizeof m);
    E.sides = 32;
    E.format = -1;
    {
        const tool_opt opts[] = {
            {"out", 'o', OPT_STR, &E.out, 0, 0, "FILE",
             "Write the mesh here (default: standard output).", NULL, 1},
            {"format", 'f', OPT_CHOICE, &E.format, 0, 0, NULL,
             "Mesh format. Default: from the --out extension, else ply.", "ply|obj", 1},
            {"sides", 0, OPT_INT, &E.sides, 3, 1024, "N", "Facets around each cylinder.", NULL, 0},
            {"radius", 'r', OPT_REAL, &E.radius, 1e-9, 1e12, "R",
             "Use this radius instead of each record's.", NULL, 1},
            {"length", 0, OPT_REAL, &E.length, 1e-9, 1e12, "L",
             "Length of a cylinder whose visible extent is unknown (a record whose "
             "segment is a single point, an infinite simulated pipe). Default: 20 radii.",
             NULL, 1},
            {"y-up", 0, OPT_FLAG, &E.y_up, 0, 0, NULL,
             "Y up, Z backward instead of the camera's Y down, Z forward.", NULL, 0},
            {"no-camera", 0, OPT_FLAG, &E.no_camera, 0, 0, NULL, "Leave out the camera marker.",
             NULL, 0},
            {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
        };
        rc = tool_parse_alloc("export", &doc, opts, argc, argv, &pos, &npos);
        if (rc)
            return rc - 1;
    }
    rc = TOOL_EXIT_USAGE;
    if (npos == 0) {
        tool_usage_error("export", "no input given (see --help)");
        goto out;
    }
    fmt_given = E.format >= 0;
    if (!fmt_given)
        E.format = E.out && (ends_with(E.out, ".obj") || ends_with(E.out, ".OBJ")) ? 1 : 0;
    if (!fmt_given && E.out && !ends_with(E.out, ".obj") && !ends_with(E.out, ".OBJ") &&
        !ends_with(E.out, ".ply") && !ends_with(E.out, ".PLY")) {
        tool_usage_error("export", "%s: give --format ply|obj or a .ply/.obj name", E.out);
        goto out;
    }
    if (!E.no_camera) {
        double z[3] = {0, 0, 0};
        if (add_part(&ps, z, z, 0, 1) != 0) {
            tool_usage_error("export", "out of memory");
            goto out;
        }
    }
    for (i = 0; i < npos; i++)
        if (read_input(pos[i], &E, &ps, &pipes) != 0)
            goto out;

    /* camera marker scaled to the scene: 15% of the pipes' mean distance */
    for (k = 0; k < ps.n; k++)
        if (!ps.p[k].camera) {
            double mid[3], d;
            int j;
            for (j = 0; j < 3; j++)
                mid[j] = 0.5 * (ps.p[k].a[j] + ps.p[k].b[j]);
            d = sqrt(mid[0] * mid[0] + mid[1] * mid[1] + mid[2] * mid[2]);
            mean_dist += d / pipes;
        }
    nv = nf = 0;
    for (k = 0; k < ps.n; k++) {
        nv += ps.p[k].camera ? 5 : 2 * (size_t)E.sides + 2;
        nf += ps.p[k].camera ? 6 : 4 * (size_t)E.sides;
    }
    m.v = malloc((nv ? nv : 1) * sizeof *m.v);
    m.c = malloc((nv ? nv : 1) * sizeof *m.c);
    m.f = malloc((nf ? nf : 1) * sizeof *m.f);
    m.first_face = malloc((ps.n ? ps.n : 1) * sizeof *m.first_face);
    if (!m.v || !m.c || !m.f || !m.first_face) {
        tool_usage_error("export", "out of memory");
        goto out;
    }
    for (k = 0; k < ps.n; k++) {
        m.first_face[k] = (int)m.nf;
        if (ps.p[k].camera)
            camera_marker(&m, &E, mean_dist > 0 ? 0.15 * mean_dist : 10);
        else
            cylinder(&m, &E, &ps.p[k], palette[(k - (E.no_camera ? 0 : 1)) % 6]);
    }
    if (write_mesh(E.out, E.format == 1, &m, &ps) != 0)
        goto out;
    if (pipes == 0)
        tool_warn("export", "no solved pipe in the input");
    rc = pipes > 0 ? TOOL_EXIT_OK : TOOL_EXIT_PARTIAL;
out:
    free(m.v);
    free(m.c);
    free(m.f);
    free(m.first_face);
    free(ps.p);
    free(pos);
    return rc;
}
