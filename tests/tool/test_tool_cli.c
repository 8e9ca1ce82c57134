/*
 * test_tool_cli.c - the real cdsp_tool binary ($CDSP_TOOL) on frames it
 * simulated itself: poses against the ground truth, JSON read back by
 * json-c in strict mode, exit statuses, bad frames and calibrations,
 * --threads against one thread byte for byte, --track, --csv, --roi,
 * overlay pictures, meshes, bench files, and an 8192 x 8192 frame.
 *
 * Tolerances: a pose is compared with the truth through the geometry of
 * its own frame. The closed form is solved on the true contours, and the
 * derivatives of the point, its offset from the axis, the distance and the
 * direction with respect to each contour's two visible ends (moved along
 * the normal) are taken by central differences. Each component's
 * tolerance is then
 *   b x (the worse of the four sign pairs: one edge bias per contour)
 *   + 4 x the standard deviation of the random part, from each contour's
 *     fit: its ends have variance 4 s^2/n and covariance -2 s^2/n (offset
 *     s^2/n and angle 12 s^2/(n L^2) of a line through n evenly spread
 *     points, s^2 from the record's rms), exceeded with probability < 6e-5;
 * with b the contour bias of the edge detector on a rendered frame:
 *   0.002 px on flat-shaded pipes (test_edges.c measures <= 2e-3 px for a
 *   contour's mean on 8-bit flat frames),
 *   0.02 px on shaded ones (--preset paper: the shading darkens the pipe
 *   toward its contours, which the second pass leaves at 0.01-0.02 px).
 * Measured (CDSP_TEST_VERBOSE=1), worst error / tolerance over the suite:
 * flat frames 0.63 (angle), 0.58 (|dP|), 0.49 (offset, distance); the roi
 * case 0.19 (|dP|: 0.61 of 3.34 mm, where the former rule allowed 9.7 mm);
 * the paper preset 0.47 (angle), 0.44 (distance: 0.049 of 0.110 mm). The
 * former rule (+-0.03 / 0.1 px on all four ends at once, plus 3 sd each)
 * allowed 7-275 times the error.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"

#include <errno.h>
#include <float.h>
#include <fcntl.h>
#include <json-c/json.h>
#include <math.h>
#include <jpeglib.h>
#include <spng.h>
#include <tiffio.h>
#include <time.h>
#include <stdint.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>

#include "cdsp.h"
#include "cdsp_host.h"

#define EDGE_BIAS_FLAT_PX 0.002
#define EDGE_BIAS_SHADED_PX 0.02

/* ---- running the tool ------------------------------------------------------ */

typedef struct {
    int status; /* exit status, or 128 + signal */
    char *out, *err;
    size_t out_len;
} run_result;

static const char *tool_path(void)
{
    const char *p = getenv("CDSP_TOOL");
    return p && *p ? p : "build/cdsp_tool";
}

/* (the buffer pointer lives in static storage: gcc 12's -Wdangling-pointer
 * cannot see into the library and would suspect the address of a local) */
static void *slurp_buf;

static char *slurp(const char *path, size_t *len)
{
    size_t n;
    cdsp_host_err err;
    if (cdsp_host_read_file(path, (size_t)1 << 30, &slurp_buf, &n, &err) != 0)
        fail_msg("%s", err.msg);
    if (len)
        *len = n;
    return slurp_buf;
}

/* Run cdsp_tool with args (NULL-terminated), stdin from /dev/null or the
 * file `in`, and collect stdout and stderr. */
static run_result run_in(const char *in, const char *const *args)
{
    run_result r;
    const char *out_path = tt_path("run.out"), *err_path = tt_path("run.err");
    const char *argv[64];
    pid_t pid;
    int st, i, n = 0;
    argv[n++] = tool_path();
    for (i = 0; args[i]; i++)
        argv[n++] = args[i];
    argv[n] = NULL;
    pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fi = open(in ? in : "/dev/null", O_RDONLY);
        int fo = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fe = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fi < 0 || fo < 0 || fe < 0)
            _exit(120);
        dup2(fi, 0);
        dup2(fo, 1);
        dup2(fe, 2);
        execv(argv[0], (char *const *)argv);
        _exit(121);
    }
    assert_int_equal(waitpid(pid, &st, 0), pid);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    if (r.status == 121)
        fail_msg("cannot run %s (set CDSP_TOOL)", argv[0]);
    r.out = slurp(out_path, &r.out_len);
    r.err = slurp(err_path, NULL);
    return r;
}

#define RUN(...) run_in(NULL, (const char *const[]){__VA_ARGS__, NULL})

static void run_free(run_result *r)
{
    free(r->out);
    free(r->err);
}

static void expect_status(const run_result *r, int want)
{
    if (r->status != want)
        fail_msg("exit status %d, wanted %d; stderr: %s", r->status, want, r->err);
}

/* ---- JSON --------------------------------------------------------------------- */

static json_object *parse_strict(const char *text, size_t len)
{
    json_tokener *tok = json_tokener_new();
    json_object *o;
    json_tokener_set_flags(tok, JSON_TOKENER_STRICT | JSON_TOKENER_VALIDATE_UTF8);
    o = json_tokener_parse_ex(tok, text, (int)len);
    if (!o || json_tokener_get_error(tok) != json_tokener_success ||
        (size_t)json_tokener_get_parse_end(tok) != len)
        fail_msg("not one strict JSON value: %.*s", (int)len, text);
    json_tokener_free(tok);
    return o;
}

/* Every line of out as a JSON object; returns the count. */
static int parse_lines(const char *out, json_object **recs, int cap)
{
    int n = 0;
    const char *p = out;
    while (*p) {
        const char *nl = strchr(p, '\n');
        assert_non_null(nl); /* every record ends with a newline */
        assert_true(n < cap);
        recs[n] = parse_strict(p, (size_t)(nl - p));
        assert_true(json_object_is_type(recs[n], json_type_object));
        n++;
        p = nl + 1;
    }
    return n;
}

static void put_all(json_object **recs, int n)
{
    int i;
    for (i = 0; i < n; i++)
        json_object_put(recs[i]);
}

static json_object *key(json_object *o, const char *k)
{
    json_object *v = NULL;
    if (!json_object_object_get_ex(o, k, &v))
        fail_msg("no \"%s\" in %s", k, json_object_to_json_string(o));
    return v;
}

static int has(json_object *o, const char *k)
{
    return json_object_object_get_ex(o, k, NULL);
}

static double num(json_object *o)
{
    if (!json_object_is_type(o, json_type_double) && !json_object_is_type(o, json_type_int))
        fail_msg("not a number: %s", json_object_to_json_string(o));
    return json_object_get_double(o);
}

static void vec(json_object *a, double *v, int n)
{
    int i;
    assert_true(json_object_is_type(a, json_type_array));
    assert_int_equal(json_object_array_length(a), n);
    for (i = 0; i < n; i++)
        v[i] = num(json_object_array_get_idx(a, (size_t)i));
}

static const char *str(json_object *o)
{
    assert_true(json_object_is_type(o, json_type_string));
    return json_object_get_string(o);
}

/* The schema of an ok record: every field, of the right type and shape. */
static void check_ok_schema(json_object *r)
{
    double v[3], seg[3], l[3];
    int k;
    json_object *s;
    assert_string_equal(str(key(r, "status")), "ok");
    assert_false(has(r, "error"));
    vec(key(r, "point"), v, 3);
    vec(key(r, "direction"), v, 3);
    assert_true(fabs(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - 1) < 1e-9);
    assert_true(num(key(r, "distance")) > 0);
    assert_true(num(key(r, "radius")) > 0);
    for (k = 0; k < 2; k++) {
        vec(json_object_array_get_idx(key(r, "lines"), (size_t)k), l, 3);
        assert_true(fabs(l[0] * l[0] + l[1] * l[1] - 1) < 1e-9);
        vec(json_object_array_get_idx(key(r, "segment"), (size_t)k), seg, 3);
        assert_true(json_object_get_int(json_object_array_get_idx(key(r, "inliers"), (size_t)k)) >=
                    12);
    }
    assert_int_equal(json_object_array_length(key(r, "lines")), 2);
    assert_int_equal(json_object_array_length(key(r, "segment")), 2);
    s = key(r, "sigma");
    vec(key(s, "point"), v, 3);
    vec(key(s, "direction"), v, 3);
    assert_true(num(key(s, "distance")) >= 0);
    assert_true(json_object_is_type(key(r, "tracked"), json_type_boolean));
    assert_true(json_object_get_int(key(r, "edges")) > 0);
}

/* ---- the ground truth and the tolerance ----------------------------------------- */

typedef struct {
    cdsp_camera cam;
    double radius;
    json_object *doc; /* truth.json */
} truth;

static void truth_load(truth *t, const char *dir)
{
    char path[600];
    char *text;
    size_t len;
    cdsp_host_err err;
    snprintf(path, sizeof path, "%s/camera.yaml", dir);
    if (cdsp_host_calib_read(path, &t->cam, &err) != 0)
        fail_msg("%s", err.msg);
    snprintf(path, sizeof path, "%s/truth.json", dir);
    text = slurp(path, &len);
    while (len && text[len - 1] == '\n')
        len--;
    t->doc = parse_strict(text, len);
    free(text);
    t->radius = num(key(t->doc, "radius"));
}

static json_object *truth_frame(const truth *t, size_t i)
{
    return json_object_array_get_idx(key(t->doc, "frames"), i);
}

static double angle_between(const double a[3], const double b[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d);
}

typedef struct {
    double point;    /* |P_C - true P_C| */
    double offset;   /* distance of P_C from the true axis */
    double distance; /* |distance - true distance| */
    double angle;    /* angle between the directions, rad */
} tolerance;

/* Distance of X from the line through q with direction v. */
static double line_dist(const double X[3], const double q[3], const double v[3])
{
    double d[3] = {X[0] - q[0], X[1] - q[1], X[2] - q[2]};
    double c[3] = {d[1] * v[2] - d[2] * v[1], d[2] * v[0] - d[0] * v[2], d[0] * v[1] - d[1] * v[0]};
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* Foot of the perpendicular of pixel p on line l (a^2 + b^2 = 1). */
static void foot_on_line(const double l[3], const double p[2], double out[2])
{
    double s = l[0] * p[0] + l[1] * p[1] + l[2];
    out[0] = p[0] - s * l[0];
    out[1] = p[1] - s * l[1];
}

static void line_through(const double p[2], const double q[2], cdsp_real l[3])
{
    double a = q[1] - p[1], b = p[0] - q[0], n = sqrt(a * a + b * b);
    l[0] = (cdsp_real)(a / n);
    l[1] = (cdsp_real)(b / n);
    l[2] = (cdsp_real)(-(a * p[0] + b * p[1]) / n);
}

/* The closed form on the true contours with each visible end moved by
 * dn[k][e] px along its line's normal. */
static void solve_moved(const truth *t, double tl[2][3], double ends[2][2][2],
                        double dn[2][2], const cdsp_real p_in[2], cdsp_result *r)
{
    cdsp_real L[2][3];
    int k, e, i;
    for (k = 0; k < 2; k++) {
        double q[2][2];
        for (e = 0; e < 2; e++) {
            q[e][0] = ends[k][e][0] + dn[k][e] * tl[k][0];
            q[e][1] = ends[k][e][1] + dn[k][e] * tl[k][1];
        }
        line_through(q[0], q[1], L[k]);
        if (L[k][0] * tl[k][0] + L[k][1] * tl[k][1] < 0)
            for (i = 0; i < 3; i++)
                L[k][i] = -L[k][i];
    }
    assert_int_equal(cdsp_axis_solve(&t->cam, L[0], L[1], p_in, (cdsp_real)t->radius, r), CDSP_OK);
}

/* One component's tolerance from its derivatives g[i] (dimension m) with
 * respect to the four end offsets: the edge bias (one sign per contour, the
 * worse of the four sign pairs) plus 4 standard deviations of the random
 * part (end covariance C). 4 sd of a Gaussian vector's norm, whatever its
 * shape: exceeded with probability < 6e-5. */
static double tol_component(double g[4][3], int m, double C[4][4], double bias)
{
    double worst = 0, var = 0;
    int s0, s1, i, j, c;
    for (s0 = -1; s0 <= 1; s0 += 2)
        for (s1 = -1; s1 <= 1; s1 += 2) {
            double n2 = 0;
            for (c = 0; c < m; c++) {
                double x = bias * (s0 * (g[0][c] + g[1][c]) + s1 * (g[2][c] + g[3][c]));
                n2 += x * x;
            }
            worst = sqrt(n2) > worst ? sqrt(n2) : worst;
        }
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++)
            for (c = 0; c < m; c++)
                var += C[i][j] * g[i][c] * g[j][c];
    return worst + 4 * sqrt(var > 0 ? var : 0);
}

/* The tolerance of a record against its truth frame (see the top). */
static tolerance tolerance_for(const truth *t, json_object *tf, json_object *rec, double bias)
{
    tolerance tol = {0, 0, 0, 0};
    double tl[2][3], seg[2][3], ends[2][2][2], P[3], v[3], C[4][4] = {{0}};
    double gP[4][3], gO[4][3], gD[4][3], gV[4][3], bv[3];
    cdsp_real ap[3], ad[3], l1[3], l2[3], p_in[2];
    cdsp_result base;
    const double h = 0.05; /* px: the derivatives by central differences (linear to 1e-4 here) */
    int k, e, i, c;
    vec(key(tf, "axis_point"), P, 3);
    vec(key(tf, "axis_dir"), v, 3);
    for (i = 0; i < 3; i++) {
        ap[i] = (cdsp_real)P[i];
        ad[i] = (cdsp_real)v[i];
    }
    assert_int_equal(cdsp_cylinder_contours(&t->cam, ap, ad, (cdsp_real)t->radius, 1, l1, l2, p_in),
                     CDSP_OK);
    for (k = 0; k < 2; k++) {
        double rms = num(json_object_array_get_idx(key(rec, "rms"), (size_t)k));
        double n = num(json_object_array_get_idx(key(rec, "inliers"), (size_t)k));
        /* a TLS line's ends (points spread evenly over it): offset var s^2/n,
         * angle var s^2 / sum t^2 = 12 s^2 / (n L^2), so each end has var
         * 4 s^2/n and the two ends covariance -2 s^2/n (s^2 = RSS/(n-2)) */
        double s2 = rms * rms * n / (n > 2 ? n - 2 : 1);
        C[2 * k][2 * k] = C[2 * k + 1][2 * k + 1] = 4 * s2 / n;
        C[2 * k][2 * k + 1] = C[2 * k + 1][2 * k] = -2 * s2 / n;
        vec(json_object_array_get_idx(key(tf, "lines"), (size_t)k), tl[k], 3);
        vec(json_object_array_get_idx(key(rec, "segment"), (size_t)k), seg[k], 3);
    }
    /* the visible ends of each contour: the solved segment's ends, projected
     * (without distortion: the lines are undistorted) onto each true line */
    for (e = 0; e < 2; e++) {
        double pix[2] = {(double)t->cam.fx * seg[e][0] / seg[e][2] + (double)t->cam.cx,
                         (double)t->cam.fy * seg[e][1] / seg[e][2] + (double)t->cam.cy};
        for (k = 0; k < 2; k++)
            foot_on_line(tl[k], pix, ends[k][e]);
    }
    {
        double dn[2][2] = {{0, 0}, {0, 0}};
        solve_moved(t, tl, ends, dn, p_in, &base);
    }
    for (c = 0; c < 3; c++)
        bv[c] = (double)base.direction[c];
    for (i = 0; i < 4; i++) {
        cdsp_result rp, rm;
        double dn[2][2] = {{0, 0}, {0, 0}}, sg;
        dn[i / 2][i % 2] = h;
        solve_moved(t, tl, ends, dn, p_in, &rp);
        dn[i / 2][i % 2] = -h;
        solve_moved(t, tl, ends, dn, p_in, &rm);
        sg = (double)(rp.direction[0] * rm.direction[0] + rp.direction[1] * rm.direction[1] +
                      rp.direction[2] * rm.direction[2]) < 0 ? -1 : 1;
        for (c = 0; c < 3; c++) {
            gP[i][c] = (double)(rp.point[c] - rm.point[c]) / (2 * h);
            gV[i][c] = (double)(rp.direction[c] - sg * rm.direction[c]) / (2 * h);
            gD[i][c] = 0;
        }
        gD[i][0] = (double)(rp.distance - rm.distance) / (2 * h);
        {
            /* the offset from the axis: the point's change across it */
            double along = gP[i][0] * bv[0] + gP[i][1] * bv[1] + gP[i][2] * bv[2];
            for (c = 0; c < 3; c++)
                gO[i][c] = gP[i][c] - along * bv[c];
        }
    }
    tol.point = tol_component(gP, 3, C, bias);
    tol.offset = tol_component(gO, 3, C, bias);
    tol.distance = tol_component(gD, 1, C, bias);
    tol.angle = tol_component(gV, 3, C, bias);
    return tol;
}

/* An ok record within the tolerance of its truth frame. */
static void check_pose_b(const truth *t, json_object *tf, json_object *rec, double bias)
{
    double p[3], tp[3], dir[3], tdir[3], dist, tdist, dP, off, ang;
    tolerance tol;
    check_ok_schema(rec);
    tol = tolerance_for(t, tf, rec, bias);
    vec(key(rec, "point"), p, 3);
    vec(key(tf, "point"), tp, 3);
    vec(key(rec, "direction"), dir, 3);
    vec(key(tf, "direction"), tdir, 3);
    dist = num(key(rec, "distance"));
    tdist = num(key(tf, "distance"));
    dP = sqrt((p[0] - tp[0]) * (p[0] - tp[0]) + (p[1] - tp[1]) * (p[1] - tp[1]) +
              (p[2] - tp[2]) * (p[2] - tp[2]));
    off = line_dist(p, tp, tdir);
    ang = angle_between(dir, tdir);
    if (getenv("CDSP_TEST_VERBOSE"))
        fprintf(stderr,
                "%s: |dP| %.4f (tol %.4f), offset %.4f (tol %.4f), |dd| %.4f (tol %.4f), "
                "angle %.3g (tol %.3g)\n",
                str(key(rec, "file")), dP, tol.point, off, tol.offset, fabs(dist - tdist),
                tol.distance, ang, tol.angle);
    if (dP > tol.point || off > tol.offset || fabs(dist - tdist) > tol.distance || ang > tol.angle)
        fail_msg("%s: |dP| %.4f (tol %.4f), offset %.4f (tol %.4f), |dd| %.4f (tol %.4f), "
                 "angle %.3g (tol %.3g) rad",
                 str(key(rec, "file")), dP, tol.point, off, tol.offset, fabs(dist - tdist),
                 tol.distance, ang, tol.angle);
    /* the tolerances are not vacuous: the axis within a radius of the truth,
     * the distance within 2 %, the direction within 2 degrees */
    assert_true(tol.offset < t->radius);
    assert_true(tol.distance < 0.02 * tdist);
    assert_true(tol.angle < 2 * 3.14159265358979 / 180);
}

static void check_pose(const truth *t, json_object *tf, json_object *rec)
{
    check_pose_b(t, tf, rec, EDGE_BIAS_FLAT_PX);
}

/* ---- fixtures -------------------------------------------------------------- */

static char seq_dir[600], dist_dir[600], png_dir[600];

static void sim_or_fail(const char *const *args)
{
    run_result r = run_in(NULL, args);
    expect_status(&r, 0);
    run_free(&r);
}

static int setup(void **state)
{
    (void)state;
    snprintf(seq_dir, sizeof seq_dir, "%s", tt_path("seq"));
    snprintf(dist_dir, sizeof dist_dir, "%s", tt_path("dist"));
    snprintf(png_dir, sizeof png_dir, "%s", tt_path("png16"));
    /* a moving, turning pipe; flat shading (the method's image model) with
     * the default blur, sensor noise and background texture */
    sim_or_fail((const char *const[]){"sim", "--out", seq_dir, "--frames", "8", "--move",
                                      "1.5,0.6,-2", "--turn", "0.7", "--ambient", "1", NULL});
    /* strong lens distortion, a pipe across the frame */
    sim_or_fail((const char *const[]){"sim", "--out", dist_dir, "--frames", "3", "--k1", "-0.3",
                                      "--k2", "0.1", "--p1", "0.001", "--p2", "-0.0015",
                                      "--point", "10,20,350", "--dir", "1,0.3,0.2", "--move",
                                      "0,-8,0", "--ambient", "1", NULL});
    /* 16-bit PNG, dark pipe on a bright background */
    sim_or_fail((const char *const[]){"sim", "--out", png_dir, "--frames", "2", "--bits", "16",
                                      "--format", "png", "--pipe-level", "0.2",
                                      "--background-level", "0.7", "--ambient", "1", "--point",
                                      "-20,0,500", "--dir", "0.5,1,-0.2", NULL});
    return 0;
}

static char *calib_of(const char *dir)
{
    static char p[4][700];
    static int k;
    char *b = p[k++ & 3];
    snprintf(b, sizeof p[0], "%s/camera.yaml", dir);
    return b;
}

/* Solve dir's frames and check every pose against its truth. */
static void solve_and_check(const char *dir, const char *extra1, const char *extra2, int n_expect)
{
    truth t;
    json_object *recs[64];
    run_result r;
    int n, i;
    truth_load(&t, dir);
    if (extra2)
        r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", extra1, extra2, dir);
    else if (extra1)
        r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", extra1, dir);
    else
        r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", dir);
    expect_status(&r, 0);
    n = parse_lines(r.out, recs, 64);
    assert_int_equal(n, n_expect);
    for (i = 0; i < n; i++) {
        json_object *tf = truth_frame(&t, (size_t)i);
        char want[700];
        snprintf(want, sizeof want, "%s/%s", dir, str(key(tf, "file")));
        assert_string_equal(str(key(recs[i], "file")), want); /* input order */
        check_pose(&t, tf, recs[i]);
        assert_true(num(key(recs[i], "time_us")) >= 0);
    }
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
}

/* ---- tests: poses ------------------------------------------------------------ */

static void poses_of_a_sequence(void **state)
{
    (void)state;
    solve_and_check(seq_dir, NULL, NULL, 8);
}

static void poses_with_lens_distortion(void **state)
{
    (void)state;
    solve_and_check(dist_dir, NULL, NULL, 3);
}

static void poses_from_16bit_png(void **state)
{
    (void)state;
    solve_and_check(png_dir, "--polarity", "dark", 2);
}

static void tracking_a_sequence(void **state)
{
    truth t;
    json_object *recs[16];
    run_result r, r3;
    int n, i, tracked = 0;
    (void)state;
    truth_load(&t, seq_dir);
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--track", "--no-time",
            seq_dir);
    expect_status(&r, 0);
    n = parse_lines(r.out, recs, 16);
    assert_int_equal(n, 8);
    assert_false(json_object_get_boolean(key(recs[0], "tracked")));
    for (i = 0; i < n; i++) {
        check_pose(&t, truth_frame(&t, (size_t)i), recs[i]);
        tracked += json_object_get_boolean(key(recs[i], "tracked"));
        assert_false(has(recs[i], "time_us"));
    }
    /* the pipe moves a few px per frame, well inside the band */
    assert_int_equal(tracked, n - 1);
    /* threads only read ahead: the same bytes */
    r3 = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--track", "--no-time", "-j",
             "3", seq_dir);
    expect_status(&r3, 0);
    assert_int_equal(r3.out_len, r.out_len);
    assert_memory_equal(r3.out, r.out, r.out_len);
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
    run_free(&r3);
}

static void paper_preset(void **state)
{
    const char *dir = tt_path("paper");
    truth t;
    json_object *recs[8];
    run_result r;
    int n, i;
    (void)state;
    r = RUN("sim", "--out", dir, "--preset", "paper");
    expect_status(&r, 0);
    run_free(&r);
    truth_load(&t, dir);
    assert_int_equal(t.cam.width, 2448);
    assert_int_equal(t.cam.height, 2048);
    assert_true(fabs((double)t.cam.fx - 3478.26) < 0.01);
    /* the paper's distances from the camera to p1..p4 (docs/method.md §9 geometry) */
    {
        static const double want[4] = {360.5551, 424.2641, 335.4102, 390.5125};
        for (i = 0; i < 4; i++)
            assert_true(fabs(num(key(truth_frame(&t, (size_t)i), "distance")) - want[i]) < 1e-3);
    }
    r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", dir);
    expect_status(&r, 0);
    n = parse_lines(r.out, recs, 8);
    assert_int_equal(n, 4);
    for (i = 0; i < n; i++)
        check_pose_b(&t, truth_frame(&t, (size_t)i), recs[i], EDGE_BIAS_SHADED_PX);
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
}

/* The committed example data (docs/cdsp_tool.md's walkthrough) still
 * solves within its tolerance (flat-shaded: sim --ambient 1). */
static void examples_solve(void **state)
{
    const char *env = getenv("CDSP_EXAMPLES");
    const char *dir = env && *env ? env : "examples/sim640";
    truth t;
    json_object *recs[8];
    run_result r;
    int n, i;
    (void)state;
    truth_load(&t, dir);
    r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", "--track", dir);
    expect_status(&r, 0);
    n = parse_lines(r.out, recs, 8);
    assert_int_equal(n, 4);
    for (i = 0; i < n; i++)
        check_pose(&t, truth_frame(&t, (size_t)i), recs[i]);
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
}

/* ---- tests: output forms ---------------------------------------------------------- */

static void threads_give_identical_output(void **state)
{
    const char *const threads[] = {"2", "3", "8", "0"};
    run_result one, many, one_csv, many_csv;
    size_t i;
    (void)state;
    /* frames repeated so that the workers overtake each other */
    one = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", seq_dir,
              seq_dir, seq_dir);
    expect_status(&one, 0);
    for (i = 0; i < sizeof threads / sizeof threads[0]; i++) {
        many = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", "-j",
                   threads[i], seq_dir, seq_dir, seq_dir);
        expect_status(&many, 0);
        assert_int_equal(many.out_len, one.out_len);
        assert_memory_equal(many.out, one.out, one.out_len);
        run_free(&many);
    }
    one_csv = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--csv", "--no-time",
                  seq_dir);
    many_csv = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--csv", "--no-time",
                   "--threads=4", seq_dir);
    expect_status(&many_csv, 0);
    assert_int_equal(many_csv.out_len, one_csv.out_len);
    assert_memory_equal(many_csv.out, one_csv.out, one_csv.out_len);
    run_free(&one);
    run_free(&one_csv);
    run_free(&many_csv);
}

/* Split a CSV line without quoted fields. */
static int split(char *line, char **f, int cap)
{
    int n = 0;
    char *p = line;
    for (;;) {
        char *c = strchr(p, ',');
        assert_true(n < cap);
        f[n++] = p;
        if (!c)
            break;
        *c = 0;
        p = c + 1;
    }
    return n;
}

static void csv_matches_json(void **state)
{
    run_result j, c;
    json_object *recs[16];
    char *line, *save = NULL, *f[64], *h[64];
    int n, nh, row = 0, i;
    (void)state;
    j = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", seq_dir);
    c = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--csv", seq_dir);
    expect_status(&c, 0);
    n = parse_lines(j.out, recs, 16);
    line = strtok_r(c.out, "\n", &save);
    nh = split(line, h, 64);
    assert_string_equal(h[0], "frame");
    assert_string_equal(h[1], "file");
    assert_string_equal(h[nh - 1], "time_us");
    while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
        double p[3], l[3];
        assert_int_equal(split(line, f, 64), nh);
        assert_true(row < n);
        assert_int_equal(strtol(f[0], NULL, 10), json_object_get_int(key(recs[row], "frame")));
        assert_string_equal(f[1], str(key(recs[row], "file")));
        assert_string_equal(f[2], "ok");
        vec(key(recs[row], "point"), p, 3);
        vec(json_object_array_get_idx(key(recs[row], "lines"), 1), l, 3);
        for (i = 0; i < nh; i++) {
            if (strcmp(h[i], "point_y") == 0)
                assert_true(strtod(f[i], NULL) == p[1]);
            if (strcmp(h[i], "lines_2_c") == 0)
                assert_true(strtod(f[i], NULL) == l[2]);
            if (strcmp(h[i], "distance") == 0)
                assert_true(strtod(f[i], NULL) == num(key(recs[row], "distance")));
        }
        row++;
    }
    assert_int_equal(row, n);
    put_all(recs, n);
    run_free(&j);
    run_free(&c);
}

static void roi_and_list(void **state)
{
    truth t;
    json_object *recs[4];
    run_result r;
    const char *list = tt_path("list.txt");
    char text[1400], roi[64];
    json_object *tf;
    double foot[3], u, v;
    (void)state;
    truth_load(&t, seq_dir);
    tf = truth_frame(&t, 0);
    vec(key(tf, "point"), foot, 3);
    u = (double)t.cam.fx * foot[0] / foot[2] + (double)t.cam.cx;
    v = (double)t.cam.fy * foot[1] / foot[2] + (double)t.cam.cy;
    /* a box around the foot of the axis: found */
    snprintf(roi, sizeof roi, "%d,%d,%d,%d", (int)u - 100, (int)v - 100, 200, 200);
    snprintf(text, sizeof text, "%s/frame_0000.pgm\n\n%s/frame_0000.pgm\n", seq_dir, seq_dir);
    tt_write_str(list, text);
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--roi", roi, "--list", list);
    expect_status(&r, 0);
    assert_int_equal(parse_lines(r.out, recs, 4), 2);
    check_pose(&t, tf, recs[0]);
    put_all(recs, 2);
    run_free(&r);
    /* a box in the corner away from the pipe: no pipe, exit 1 */
    snprintf(roi, sizeof roi, "%d,0,60,60", u > t.cam.width / 2 ? 0 : t.cam.width - 60);
    r = run_in(list, (const char *const[]){"solve", "--calib", calib_of(seq_dir), "--radius", "8",
                                           "--roi", roi, "--list", "-", NULL});
    expect_status(&r, 1);
    assert_int_equal(parse_lines(r.out, recs, 4), 2);
    assert_string_equal(str(key(recs[0], "status")), "error");
    assert_true(strcmp(str(key(recs[0], "error")), "no-pipe") == 0 ||
                strcmp(str(key(recs[0], "error")), "few-points") == 0);
    put_all(recs, 2);
    run_free(&r);
    json_object_put(t.doc);
}

/* ---- tests: bad input ------------------------------------------------------------- */

static void write_bytes(const char *name, const void *data, size_t len)
{
    tt_write(tt_path(name), data, len);
}

static void bad_frames_get_error_records(void **state)
{
    const char *dir = tt_path("bad");
    char good[700], p[12][700], *text;
    size_t len;
    run_result r;
    json_object *recs[16];
    int n, i;
    static const char *const names[] = {
        "bad/truncated.pgm", "bad/empty.pgm", "bad/corrupt.png", "bad/color.ppm",
        "bad/huge.pgm", "bad/missing.pgm", "bad/small.pgm", "bad/blank.pgm", "bad/comment.pgm"};
    (void)state;
    assert_int_equal(mkdir(dir, 0777), 0);
    snprintf(good, sizeof good, "%s/frame_0000.pgm", seq_dir);
    text = slurp(good, &len);
    write_bytes("bad/truncated.pgm", text, len - 1000);
    write_bytes("bad/empty.pgm", "", 0);
    {
        /* a real PNG of the right size with a damaged data byte */
        cdsp_host_image im;
        cdsp_host_err err;
        char *png;
        size_t plen;
        assert_int_equal(cdsp_host_image_read(good, &im, &err), 0);
        assert_int_equal(cdsp_host_png_write(tt_path("bad/corrupt.png"), &im, &err), 0);
        png = slurp(tt_path("bad/corrupt.png"), &plen);
        png[plen / 2] ^= 0x40;
        write_bytes("bad/corrupt.png", png, plen);
        free(png);
        /* a blank frame of the right size: no edges at all */
        memset(im.data, 90, im.stride * (size_t)im.height);
        assert_int_equal(cdsp_host_pgm_write(tt_path("bad/blank.pgm"), &im, &err), 0);
        cdsp_host_image_free(&im);
        /* the right size, a different size */
        assert_int_equal(cdsp_host_image_alloc(&im, 320, 240, 8, &err), 0);
        assert_int_equal(cdsp_host_pgm_write(tt_path("bad/small.pgm"), &im, &err), 0);
        cdsp_host_image_free(&im);
    }
    write_bytes("bad/color.ppm", "P6\n640 480\n255\n\0\0\0", 18);
    {
        size_t hl = 70000;
        char *h = malloc(hl);
        memcpy(h, "P5\n#", 4);
        memset(h + 4, 'c', hl - 4);
        write_bytes("bad/huge.pgm", h, hl);
        free(h);
    }
    {
        /* the good frame behind a header full of comments: fine */
        char *c = malloc(len + 200);
        size_t hdr = (size_t)(strstr(text, "255\n") - text) + 4;
        size_t k = (size_t)snprintf(c, 200, "P5 # made by hand\n# another\n640\n#w\n480 255\n");
        memcpy(c + k, text + hdr, len - hdr);
        write_bytes("bad/comment.pgm", c, k + len - hdr);
        free(c);
    }
    for (i = 0; i < 9; i++)
        snprintf(p[i], sizeof p[i], "%s", tt_path(names[i]));
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", good, p[0], p[1], p[2], p[3],
            p[4], p[5], p[6], p[7], p[8], good);
    expect_status(&r, 1);
    n = parse_lines(r.out, recs, 16);
    assert_int_equal(n, 11);
    /* the run went on past every bad frame */
    check_ok_schema(recs[0]);
    check_ok_schema(recs[9]);  /* comments in the header */
    check_ok_schema(recs[10]);
    {
        static const struct {
            const char *error, *words;
        } want[8] = {
            {"bad-frame", "truncated PGM raster"}, {"bad-frame", "empty file"},
            {"bad-frame", "PNG"},                  {"bad-frame", "PPM color image"},
            {"bad-frame", "header longer than"},   {"bad-frame", "cannot open"},
            {"size-mismatch", "image is 320x240 but"}, {NULL, NULL},
        };
        for (i = 0; i < 8; i++) {
            json_object *rec = recs[i + 1];
            const char *msg;
            assert_string_equal(str(key(rec, "file")), p[i]);
            assert_string_equal(str(key(rec, "status")), "error");
            assert_false(has(rec, "point"));
            msg = str(key(rec, "message"));
            if (want[i].error) {
                assert_string_equal(str(key(rec, "error")), want[i].error);
                tt_assert_contains(msg, want[i].words);
                assert_true(strncmp(msg, p[i], strlen(p[i])) == 0); /* names the file */
            } else { /* the blank frame */
                assert_true(strcmp(str(key(rec, "error")), "few-points") == 0 ||
                            strcmp(str(key(rec, "error")), "no-pipe") == 0);
            }
        }
    }
    put_all(recs, n);
    run_free(&r);
    /* the same with threads: same records */
    {
        run_result a = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time",
                           good, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], good);
        run_result b = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time",
                           "-j", "4", good, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8],
                           good);
        expect_status(&b, 1);
        assert_int_equal(a.out_len, b.out_len);
        assert_memory_equal(a.out, b.out, a.out_len);
        run_free(&a);
        run_free(&b);
    }
    free(text);
}

static void bad_calibrations_exit_2(void **state)
{
    static const struct {
        const char *text, *msg;
    } cases[] = {
        {"image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
         "  data: [800, 0, 319.5, 0, 800, 239.5, 0, 0]\ndistortion_model: plumb_bob\n"
         "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n",
         "camera_matrix.data: expected 9 numbers, got 8"},
        {"image_width: 640\ncamera_matrix:\n  data: [800, 0, 319.5, 0, 800, 239.5, 0, 0, 1]\n"
         "distortion_model: plumb_bob\ndistortion_coefficients:\n  data: [0, 0, 0, 0, 0]\n",
         "image_height: missing"},
        {"image_width: 640\nimage_height: 480\n"
         "camera_matrix:\n  data: [800, 0, 319.5, 0, 800, 239.5, 0, 0, 1]\n"
         "distortion_model: plumb_bob\n",
         "distortion_coefficients: missing"},
        {"image_width: 640\nimage_height: [480\n", "YAML error"},
        {"", "empty calibration file"},
    };
    size_t i;
    char frame[700];
    (void)state;
    snprintf(frame, sizeof frame, "%s/frame_0000.pgm", seq_dir);
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *cal = tt_path("broken.yaml");
        char want[800];
        run_result r;
        tt_write_str(cal, cases[i].text);
        r = RUN("solve", "--calib", cal, "--radius", "8", frame);
        expect_status(&r, 2);
        assert_int_equal(r.out_len, 0); /* nothing processed */
        snprintf(want, sizeof want, "%s: %s", cal, cases[i].msg);
        tt_assert_contains(r.err, want);
        run_free(&r);
    }
    {
        run_result r = RUN("solve", "--calib", tt_path("nope.yaml"), "--radius", "8", frame);
        expect_status(&r, 2);
        tt_assert_contains(r.err, "nope.yaml: cannot open");
        run_free(&r);
    }
}

static void usage_errors_exit_2(void **state)
{
    char frame[700];
    const char *cal;
    (void)state;
    snprintf(frame, sizeof frame, "%s/frame_0000.pgm", seq_dir);
    cal = calib_of(seq_dir);
    {
        const struct {
            run_result r;
            const char *msg;
        } cases[] = {
            {RUN("solve", "--calib", cal, frame), "--radius R is required"},
            {RUN("solve", "--radius", "8", frame), "--calib CAM.yaml is required"},
            {RUN("solve", "--calib", cal, "--radius", "-1", frame), "--radius: -1 is outside"},
            {RUN("solve", "--calib", cal, "--radius", "eight", frame),
             "--radius: expected a number, got 'eight'"},
            {RUN("solve", "--calib", cal, "--radius", "8", "--frobnicate", frame),
             "unknown option '--frobnicate'"},
            {RUN("solve", "--calib", cal, "--radius", "8", "--roi", "1,2,3", frame),
             "--roi: expected X,Y,W,H"},
            {RUN("solve", "--calib", cal, "--radius", "8", "--roi", "600,400,100,100", frame),
             "reaches outside the 640x480 image"},
            {RUN("solve", "--calib", cal, "--radius", "8", "-j", "x", frame),
             "--threads: expected an integer"},
            {RUN("solve", "--calib", cal, "--radius", "8"), "no frames given"},
            {RUN("solve", "--calib", cal, "--radius", "8", "--polarity", "up", frame),
             "--polarity: expected one of any|bright|dark"},
            {RUN("solve", "--calib", cal, "--radius"), "--radius needs a value"},
            /* issue 16: passed, then every frame came back bad-argument */
            {RUN("solve", "--calib", cal, "--radius", "8", "--min-contrast", "1", frame),
             "libcdsp refuses these solver options"},
            /* a final-pass option without its pass: said, not ignored */
            {RUN("solve", "--calib", cal, "--radius", "8", "--point-fit", frame),
             "--point-fit needs --refine-step 3 or more"},
            {RUN("solve", "--calib", cal, "--radius", "8", "--refine-step", "2", frame),
             "libcdsp refuses these solver options"},
            {RUN("overlay", "--calib", cal, "--radius", "8", frame), "--out DIR is required"},
            {RUN("sim", "--out", tt_path("x"), "--bits", "12"), "--bits: 8 or 16"},
            {RUN("sim", "--out", tt_path("x"), "--dir", "0,0,0"), "must not be zero"},
            {RUN("sim", "--out", "/proc/no/such/dir"), "cannot create the directory"},
            {RUN("export"), "no input given"},
            {RUN("bench", "--trials", "0"), "--trials: 0 is outside"},
            {RUN("frobnicate"), "unknown command 'frobnicate'"},
        };
        size_t i;
        for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            run_result r = cases[i].r;
            if (r.status != 2 || !strstr(r.err, cases[i].msg))
                fail_msg("case %zu: status %d, stderr \"%s\", wanted \"%s\"", i, r.status, r.err,
                         cases[i].msg);
            assert_int_equal(r.out_len, 0);
            run_free(&r);
        }
    }
    {
        run_result r = run_in(NULL, (const char *const[]){NULL});
        expect_status(&r, 2);
        tt_assert_contains(r.err, "usage: cdsp_tool COMMAND");
        run_free(&r);
    }
}

static void help_pages(void **state)
{
    static const char *const cmds[] = {"solve", "overlay", "sim", "export", "bench", "plot",
                                       "compare", "listen"};
    static const char *const sections[] = {"NAME\n", "SYNOPSIS\n", "DESCRIPTION\n", "OPTIONS\n",
                                           "EXIT STATUS\n", "    -h, --help\n"};
    size_t i, k;
    (void)state;
    for (i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        run_result r = RUN(cmds[i], "--help");
        run_result h = RUN("help", cmds[i]);
        char name[64];
        expect_status(&r, 0);
        expect_status(&h, 0);
        for (k = 0; k < sizeof sections / sizeof sections[0]; k++)
            tt_assert_contains(r.out, sections[k]);
        snprintf(name, sizeof name, "cdsp_tool %s - ", cmds[i]);
        tt_assert_contains(r.out, name);
        tt_assert_contains(r.out, "    2  ");
        assert_string_equal(r.out, h.out);
        /* man-page width */
        {
            const char *p = r.out;
            while (*p) {
                const char *nl = strchr(p, '\n');
                assert_non_null(nl);
                if (nl - p > 80)
                    fail_msg("%s --help: line longer than 80: %.*s", cmds[i], (int)(nl - p), p);
                p = nl + 1;
            }
        }
        run_free(&r);
        run_free(&h);
    }
    {
        run_result r = RUN("--help");
        expect_status(&r, 0);
        for (i = 0; i < sizeof cmds / sizeof cmds[0]; i++)
            tt_assert_contains(r.out, cmds[i]);
        run_free(&r);
    }
}

/* docs/cdsp_tool.md carries every manual page exactly as --help prints it
 * (tests/tool/update_docs.sh refreshes them). */
static void docs_match_help(void **state)
{
    static const char *const cmds[] = {"solve", "overlay", "sim", "export", "bench", "plot",
                                       "compare", "listen"};
    const char *env = getenv("CDSP_DOCS");
    char *doc = slurp(env && *env ? env : "docs/cdsp_tool.md", NULL);
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        run_result r = RUN(cmds[i], "--help");
        char *block = malloc(r.out_len + 64);
        sprintf(block, "```text\n%s```\n", r.out);
        if (!strstr(doc, block))
            fail_msg("docs/cdsp_tool.md: the %s manual differs from --help "
                     "(run tests/tool/update_docs.sh)", cmds[i]);
        free(block);
        run_free(&r);
    }
    free(doc);
}

/* ---- tests: every pipe (solve --all) ---------------------------------------------- */

/* A rack of three parallel pipes 26 mm apart (gaps of 10 mm, narrower than
 * the 16 mm pipes, so each gap is itself a plausible band) moving 4 mm per
 * frame, flat light. Every frame: three pipes, each on a true one (P_C
 * within 0.5 mm, as check_pose's flat-light tolerance at this distance,
 * 400 mm), the gaps never; the neighbours' axis_distance within 0.05 mm of
 * 26 (tests/lib/test_multi.c derives the flat rack's spacing tolerance,
 * 6 sigma of the lateral spacing: 0.03-0.05 mm at this scale; measured
 * here 0.005-0.025 mm); track ids kept; CSV one line per pipe; the
 * overlay names the picture; export meshes every pipe. */
static void solve_all_rack(void **state)
{
    char dir[600], recs_path[800], single_path[800], mesh3[800], mesh1[800], ov[800], f0[800];
    truth t;
    json_object *recs[8];
    run_result r;
    unsigned ids[3] = {0, 0, 0};
    int n, i, k, q, lines = 0;
    char *text, *p;
    long nv3, nv1;
    (void)state;
    /* tt_path's buffers rotate: copies */
    snprintf(dir, sizeof dir, "%s", tt_path("rack"));
    snprintf(recs_path, sizeof recs_path, "%s", tt_path("rack.jsonl"));
    snprintf(single_path, sizeof single_path, "%s", tt_path("rack1.jsonl"));
    snprintf(mesh3, sizeof mesh3, "%s", tt_path("rack3.ply"));
    snprintf(mesh1, sizeof mesh1, "%s", tt_path("rack1.ply"));
    snprintf(ov, sizeof ov, "%s", tt_path("rack_ov"));
    snprintf(f0, sizeof f0, "%s", tt_path("rack/frame_0000.pgm"));
    sim_or_fail((const char *const[]){"sim", "--out", dir, "--frames", "4", "--pipes", "3",
                                      "--spacing", "26", "--move", "4,0,0", "--ambient", "1",
                                      NULL});
    truth_load(&t, dir);
    r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", "--all", "--track", "--no-time",
            dir);
    expect_status(&r, 0);
    tt_write(recs_path, r.out, r.out_len);
    n = parse_lines(r.out, recs, 8);
    assert_int_equal(n, 4);
    for (i = 0; i < n; i++) {
        json_object *pipes = key(recs[i], "pipes"), *pairs = key(recs[i], "pairs");
        json_object *rack = key(truth_frame(&t, (size_t)i), "rack");
        int which[3];
        check_ok_schema(recs[i]);
        assert_int_equal(json_object_array_length(pipes), 3);
        assert_int_equal(json_object_array_length(pairs), 3);
        for (k = 0; k < 3; k++) {
            json_object *pk = json_object_array_get_idx(pipes, (size_t)k);
            double P[3], best = 1e9;
            vec(key(pk, "point"), P, 3);
            which[k] = -1;
            for (q = 0; q < 3; q++) {
                double T[3], d;
                vec(key(json_object_array_get_idx(rack, (size_t)q), "point"), T, 3);
                d = sqrt((P[0] - T[0]) * (P[0] - T[0]) + (P[1] - T[1]) * (P[1] - T[1]) +
                         (P[2] - T[2]) * (P[2] - T[2]));
                if (d < best) {
                    best = d;
                    which[k] = q;
                }
            }
            if (best > 0.5)
                fail_msg("frame %d: pipe %d is %.3f mm from every true pipe", i, k, best);
            if (i == 0)
                ids[which[k]] = (unsigned)json_object_get_int64(key(pk, "track_id"));
            else
                assert_int_equal(json_object_get_int64(key(pk, "track_id")), ids[which[k]]);
        }
        assert_true(which[0] != which[1] && which[1] != which[2] && which[0] != which[2]);
        for (k = 0; k < 3; k++) {
            json_object *pr = json_object_array_get_idx(pairs, (size_t)k);
            int a = (int)json_object_get_int64(key(pr, "i")), b = (int)json_object_get_int64(key(pr, "j"));
            double want = 26.0 * abs(which[a] - which[b]);
            assert_true(a < b);
            if (fabs(num(key(pr, "axis_distance")) - want) > 0.05 * abs(which[a] - which[b]))
                fail_msg("frame %d: pipes %d-%d %.4f mm apart, truth %.1f", i, a, b,
                         num(key(pr, "axis_distance")), want);
            assert_true(num(key(pr, "angle_deg")) < 0.1);
            assert_true(num(key(pr, "axis_distance_rms")) < 0.05);
        }
    }
    assert_true(ids[0] && ids[1] && ids[2] && ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);
    put_all(recs, n);
    run_free(&r);
    /* CSV: a header and one line per pipe */
    r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", "--all", "--csv", "--no-time", dir);
    expect_status(&r, 0);
    for (p = r.out; (p = strchr(p, '\n')) != NULL; p++)
        lines++;
    assert_int_equal(lines, 1 + 4 * 3);
    assert_non_null(strstr(r.out, ",message,pipe,point_x,"));
    run_free(&r);
    /* the overlay: one picture, named in the record */
    r = RUN("overlay", "--calib", calib_of(dir), "--radius", "8", "--all", "--out", ov, f0);
    expect_status(&r, 0);
    assert_non_null(strstr(r.out, "\"overlay\":"));
    run_free(&r);
    /* export: three cylinders per record, as many vertices as three
     * single-pipe records' */
    r = RUN("solve", "--calib", calib_of(dir), "--radius", "8", "--no-time", dir);
    expect_status(&r, 0);
    tt_write(single_path, r.out, r.out_len);
    run_free(&r);
    r = RUN("export", "--no-camera", "--sides", "8", "--out", mesh3, recs_path);
    expect_status(&r, 0);
    run_free(&r);
    r = RUN("export", "--no-camera", "--sides", "8", "--out", mesh1, single_path);
    expect_status(&r, 0);
    run_free(&r);
    text = slurp(mesh3, NULL);
    nv3 = atol(strstr(text, "element vertex ") + 15);
    free(text);
    text = slurp(mesh1, NULL);
    nv1 = atol(strstr(text, "element vertex ") + 15);
    free(text);
    assert_true(nv1 > 0);
    assert_int_equal(nv3, 3 * nv1);
    json_object_put(t.doc);
}

/* ---- tests: overlay, export, bench ------------------------------------------------ */

/* A PNG read back as RGB, and the exact colour of one pixel (marks are
 * drawn in exact colours; antialiased edges are blends, never equal). */
typedef struct {
    unsigned char *rgb;
    unsigned w, h;
} picture;

static picture read_png(const char *path)
{
    picture p;
    size_t len, size;
    char *buf = slurp(path, &len);
    struct spng_ihdr ihdr;
    spng_ctx *ctx = spng_ctx_new(0);
    assert_int_equal(spng_set_png_buffer(ctx, buf, len), 0);
    assert_int_equal(spng_get_ihdr(ctx, &ihdr), 0);
    assert_int_equal(spng_decoded_image_size(ctx, SPNG_FMT_RGB8, &size), 0);
    p.rgb = malloc(size);
    p.w = ihdr.width;
    p.h = ihdr.height;
    assert_int_equal(spng_decode_image(ctx, p.rgb, size, SPNG_FMT_RGB8, 0), 0);
    spng_ctx_free(ctx);
    free(buf);
    return p;
}

static int is_rgb(const picture *p, unsigned x, unsigned y, int r, int g, int b)
{
    const unsigned char *q = p->rgb + 3 * ((size_t)y * p->w + x);
    return q[0] == r && q[1] == g && q[2] == b;
}

/* Distance from pixel (x, y) to the record's axis drawn through the
 * camera: the 3D segment sampled every ~0.3 px of the frame (2000 points
 * over its ~670 px), each projected with the distortion (so the bend is
 * the drawn one); *end_d is the distance to the nearer projected end. */
static double axis_px_dist(const cdsp_camera *cam, double seg[2][3], double x, double y,
                           double *end_d)
{
    double best = 1e300;
    int k, i;
    *end_d = 1e300;
    for (k = 0; k <= 2000; k++) {
        cdsp_real X[3], px[2];
        double d;
        for (i = 0; i < 3; i++)
            X[i] = (cdsp_real)(seg[0][i] + k / 2000.0 * (seg[1][i] - seg[0][i]));
        if (cdsp_camera_project(cam, X, px) != CDSP_OK)
            continue;
        d = hypot((double)px[0] - x, (double)px[1] - y);
        best = fmin(best, d);
        if (k == 0 || k == 2000)
            *end_d = fmin(*end_d, d);
    }
    return best;
}

/* The overlay of a 640 x 480 frame (marks of 1 px: rad = 640/1000 = 0,
 * tools/tool_overlay.c): every inlier a '+' of 5 px in its contour's
 * colour, the axis a 1-px curve with a disc of radius 2 at each end. The
 * inliers of a contour are 4 px apart along their scan and off the axis,
 * so no mark covers another: exactly 5 x inliers pixels of each colour
 * (measured 795 = 5 x 159 for both contours; it checked > 100). Each red
 * pixel is a sample of the projected axis rounded to the nearest pixel,
 * at most half a diagonal (0.71 px) from it, plus the samples' spacing
 * (0.33 px / 2): within 0.9 px, or within the end disc's sqrt(6) = 2.45 px
 * + 0.71 of an end (measured worst 0.63 px off the curve); and there are
 * at least as many as the columns the axis crosses (one per column:
 * |slope| < 1) and at most one per column and row crossed plus the two
 * discs (21 px each): measured 805 in [640, 872]. (It checked > 100 red
 * pixels, wherever they were.) */
static void overlay_draws_the_pipe(void **state)
{
    const char *out = tt_path("ov");
    truth t;
    run_result r;
    json_object *recs[4];
    char png[800];
    int n, green = 0, magenta = 0, red = 0, i;
    double inl[2], seg[2][3], worst = 0, cols, rows;
    (void)state;
    truth_load(&t, dist_dir);
    r = RUN("overlay", "--calib", calib_of(dist_dir), "--radius", "8", "--out", out, dist_dir);
    expect_status(&r, 0);
    n = parse_lines(r.out, recs, 4);
    assert_int_equal(n, 3);
    snprintf(png, sizeof png, "%s/frame_0000_overlay.png", out);
    assert_string_equal(str(key(recs[0], "overlay")), png);
    check_pose(&t, truth_frame(&t, 0), recs[0]);
    vec(key(recs[0], "inliers"), inl, 2);
    for (i = 0; i < 2; i++)
        vec(json_object_array_get_idx(key(recs[0], "segment"), (size_t)i), seg[i], 3);
    /* an RGB picture of the frame's size with the marks in their colours */
    {
        picture p = read_png(png);
        unsigned x, y;
        double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
        assert_int_equal(p.w, t.cam.width);
        assert_int_equal(p.h, t.cam.height);
        for (y = 0; y < p.h; y++)
            for (x = 0; x < p.w; x++) {
                green += is_rgb(&p, x, y, 0, 230, 0);
                magenta += is_rgb(&p, x, y, 255, 0, 255);
                if (is_rgb(&p, x, y, 255, 30, 30)) {
                    double end_d, d = axis_px_dist(&t.cam, seg, x, y, &end_d);
                    red++;
                    if (end_d > 2.45 + 0.71) {
                        worst = fmax(worst, d);
                        if (d > 0.9)
                            fail_msg("a red pixel at (%u, %u) is %.2f px off the axis", x, y, d);
                    } else if (end_d > 2.45 + 0.71 + 0.2) {
                        fail_msg("a red pixel at (%u, %u) is %.2f px from an end", x, y, end_d);
                    }
                    xmin = fmin(xmin, x);
                    xmax = fmax(xmax, x);
                    ymin = fmin(ymin, y);
                    ymax = fmax(ymax, y);
                }
            }
        free(p.rgb);
        cols = xmax - xmin + 1;
        rows = ymax - ymin + 1;
    }
    printf("overlay: green %d, magenta %d (inliers %g, %g); red %d over %g columns, %g rows, "
           "worst %.2f px off the axis\n", green, magenta, inl[0], inl[1], red, cols, rows, worst);
    assert_true(inl[0] > 100 && inl[1] > 100);
    assert_int_equal(green, (int)(5 * inl[0]));
    assert_int_equal(magenta, (int)(5 * inl[1]));
    assert_true(red >= cols && red <= cols + rows + 2 * 21);
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
}

static double seg_dist(const double p[3], const double a[3], const double b[3])
{
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ap[3] = {p[0] - a[0], p[1] - a[1],
                                                                       p[2] - a[2]};
    double t = (ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) /
               (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]);
    double q[3] = {a[0] + t * ab[0] - p[0], a[1] + t * ab[1] - p[1], a[2] + t * ab[2] - p[2]};
    return sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
}

static void export_meshes(void **state)
{
    const char *poses = tt_path("poses.jsonl"), *ply = tt_path("pipes.ply");
    run_result r;
    json_object *recs[16];
    char *text, *p;
    int n, nv = -1, nf = -1, i, k;
    (void)state;
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", seq_dir);
    expect_status(&r, 0);
    tt_write(poses, r.out, r.out_len);
    n = parse_lines(r.out, recs, 16);
    run_free(&r);
    r = RUN("export", "--out", ply, "--sides", "12", poses);
    expect_status(&r, 0);
    run_free(&r);
    text = slurp(ply, NULL);
    assert_true(strncmp(text, "ply\nformat ascii 1.0\n", 21) == 0);
    p = strstr(text, "element vertex ");
    assert_non_null(p);
    nv = atoi(p + 15);
    p = strstr(text, "element face ");
    assert_non_null(p);
    nf = atoi(p + 13);
    assert_int_equal(nv, 5 + n * (2 * 12 + 2));
    assert_int_equal(nf, 6 + n * 4 * 12);
    /* every ring vertex of pipe k lies at the radius from its segment */
    p = strstr(text, "end_header\n") + 11;
    for (i = 0; i < 5; i++)
        p = strchr(p, '\n') + 1;
    for (k = 0; k < n; k++) {
        double s0[3], s1[3];
        vec(json_object_array_get_idx(key(recs[k], "segment"), 0), s0, 3);
        vec(json_object_array_get_idx(key(recs[k], "segment"), 1), s1, 3);
        for (i = 0; i < 2 * 12 + 2; i++) {
            double v[3];
            char *end;
            v[0] = strtod(p, &end);
            v[1] = strtod(end, &end);
            v[2] = strtod(end, &end);
            /* vertices at r from the axis, printed to 17 digits: the
             * rounding of P + r n, eps |P| ~ 1e-13 for |P| ~ 450 mm
             * (measured <= 2.1e-14; it allowed 5e-7) */
            if (i < 24)
                assert_true(fabs(seg_dist(v, s0, s1) - 8) < 1e-13);
            else
                assert_true(seg_dist(v, s0, s1) < 1e-13);
            p = strchr(p, '\n') + 1;
        }
    }
    /* faces: 3 indices each, all in range */
    for (i = 0; i < nf; i++) {
        int a, b, c;
        assert_int_equal(sscanf(p, "3 %d %d %d", &a, &b, &c), 3);
        assert_true(a >= 0 && a < nv && b >= 0 && b < nv && c >= 0 && c < nv);
        p = strchr(p, '\n') + 1;
    }
    assert_int_equal(*p, 0);
    free(text);
    put_all(recs, n);
    /* OBJ to stdout, from the truth file too */
    {
        char truth_path[700];
        int v = 0, f = 0, o = 0;
        const char *q;
        snprintf(truth_path, sizeof truth_path, "%s/truth.json", seq_dir);
        r = RUN("export", "--format", "obj", "--no-camera", "--sides", "8", truth_path);
        expect_status(&r, 0);
        for (q = r.out; *q; q = strchr(q, '\n') + 1) {
            v += q[0] == 'v' && q[1] == ' ';
            f += q[0] == 'f' && q[1] == ' ';
            o += q[0] == 'o' && q[1] == ' ';
        }
        assert_int_equal(o, 8);
        assert_int_equal(v, 8 * (2 * 8 + 2));
        assert_int_equal(f, 8 * 4 * 8);
        run_free(&r);
    }
    /* malformed input: file and line named, exit 2; only errors: exit 1 */
    tt_write_str(tt_path("bad.jsonl"), "{\"status\":\"error\",\"error\":\"no-pipe\"}\n{oops\n");
    r = RUN("export", tt_path("bad.jsonl"));
    expect_status(&r, 2);
    tt_assert_contains(r.err, "bad.jsonl: not a cdsp_tool JSON record (line 2): ");
    run_free(&r);
    tt_write_str(tt_path("none.jsonl"), "{\"status\":\"error\",\"error\":\"no-pipe\"}\n");
    r = RUN("export", "--out", tt_path("none.ply"), tt_path("none.jsonl"));
    expect_status(&r, 1);
    run_free(&r);
    /* issue 16: a zero direction or overflowing coordinates wrote null
     * vertices and exited 0; the inputs are the fuzz target's regression
     * seeds (run from the repository's top, as make does) */
    {
        static const struct {
            const char *file, *msg;
        } cases[] = {
            {"tests/fuzz/corpus/export/regress-zero-direction.jsonl", "is the zero vector"},
            {"tests/fuzz/corpus/export/regress-overflow-segment.jsonl", "beyond 1e12"},
            {"tests/fuzz/corpus/export/regress-truth-zero-dir.json", "axis_dir is the zero vector"},
        };
        size_t c;
        for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            r = RUN("export", "--out", tt_path("hostile.ply"), cases[c].file);
            if (r.status != 2 || !strstr(r.err, cases[c].msg))
                fail_msg("%s: status %d, stderr \"%s\"", cases[c].file, r.status, r.err);
            run_free(&r);
        }
        r = RUN("export", "--out", tt_path("seed.ply"), "tests/fuzz/corpus/export/seed-records.jsonl");
        expect_status(&r, 0);
        run_free(&r);
        {
            char *mesh = slurp(tt_path("seed.ply"), NULL);
            assert_null(strstr(mesh, "null"));
            free(mesh);
        }
    }
}

static void bench_files(void **state)
{
    const char *out = tt_path("bench");
    char path[800], *text, *line, *save = NULL;
    run_result r;
    int rows = 0;
    (void)state;
    r = RUN("bench", "--out", out, "--levels", "0,0.5", "--trials", "2", "--no-frames", "-q");
    expect_status(&r, 0);
    tt_assert_contains(r.out, "Table 1.");
    tt_assert_contains(r.out, "Table 2.");
    tt_assert_contains(r.out, "Table 3.");
    run_free(&r);
    /* the radius table is exact: |dr| / r x distance (docs/method.md) */
    snprintf(path, sizeof path, "%s/bench_radius.csv", out);
    text = slurp(path, NULL);
    line = strtok_r(text, "\n", &save);
    assert_string_equal(line, "dr_mm,rmse_p1,rmse_p2,rmse_p3,rmse_p4,rmse_mean,exact,paper_rmse");
    while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
        char *f[16];
        assert_int_equal(split(line, f, 16), 8);
        /* both printed with %.6g: 5e-6 relative each (it allowed 1e-4);
         * measured: equal as printed */
        assert_true(fabs(strtod(f[5], NULL) - strtod(f[6], NULL)) < 1e-5 * strtod(f[6], NULL));
        /* and reproduces the paper's table to its 4 digits: rounds to the
         * paper's third decimal (0.944214 / 2.36053 / 4.72107 against 0.944
         * / 2.361 / 4.721: at most 4.7e-4 off; it allowed 1.5e-3) */
        assert_true(fabs(strtod(f[5], NULL) - strtod(f[7], NULL)) <= 0.0005 + 1e-5);
        rows++;
    }
    assert_int_equal(rows, 6);
    free(text);
    snprintf(path, sizeof path, "%s/bench_noise.csv", out);
    text = slurp(path, NULL);
    tt_assert_contains(text, "noise_px,rmse_p1");
    free(text);
    snprintf(path, sizeof path, "%s/bench_noise.svg", out);
    text = slurp(path, NULL);
    assert_true(strncmp(text, "<?xml", 5) == 0);
    tt_assert_contains(text, "</svg>\n");
    free(text);
}

/* ---- tests: size limits ------------------------------------------------------------ */

/* An 8192 x 8192 frame: a bright vertical band of a known width, its edges
 * exactly between two pixel columns. */
/* ---- tests: issue 15 (directories, export's messages, JPEG/TIFF, plot,
 * compare, overlay caption, terminal lines, the manual's examples) ------------ */

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* --out A/B/C: created with its parents, as the help says. */
static void out_dirs_created_with_parents(void **state)
{
    char d[800], f[900];
    run_result r;
    (void)state;
    snprintf(d, sizeof d, "%s/sim/a/b", tt_tmpdir());
    r = RUN("sim", "--out", d, "--width", "64", "--height", "48", "--point", "0,0,200");
    expect_status(&r, 0);
    snprintf(f, sizeof f, "%s/frame_0000.pgm", d);
    assert_true(access(f, R_OK) == 0);
    run_free(&r);
    snprintf(f, sizeof f, "%s/ov/x/y/", tt_tmpdir());
    r = RUN("overlay", "--calib", calib_of(dist_dir), "--radius", "8", "--out", f, dist_dir);
    expect_status(&r, 0);
    assert_true(is_dir(f));
    run_free(&r);
    snprintf(f, sizeof f, "%s/bench/p/q", tt_tmpdir());
    r = RUN("bench", "--out", f, "--levels", "0", "--trials", "1", "--no-frames", "-q");
    expect_status(&r, 0);
    assert_true(is_dir(f));
    run_free(&r);
    /* a file in the way: exit 2 naming it */
    snprintf(f, sizeof f, "%s/frame_0000.pgm/sub", d);
    r = RUN("sim", "--out", f);
    expect_status(&r, 2);
    tt_assert_contains(r.err, "cannot create the directory");
    run_free(&r);
}

/* Input that is not solve's records: "FILE: not a cdsp_tool JSON record
 * (line N)", exit 2, for export, plot and compare alike. */
static void not_a_record_named(void **state)
{
    static const struct {
        const char *name, *text, *line;
    } cases[] = {
        {"p.csv", "frame,status,error\nf.pgm,ok,\n", "(line 1)"},
        {"other.jsonl", "{\"a\": 1}\n", "(line 1)"},
        {"cut.jsonl", "{\"frame\":\"a\",\"status\":\"ok\"", "(line 1)"},
        {"third.jsonl", "{\"frame\":\"a\",\"status\":\"error\",\"error\":\"no-pipe\"}\n\n"
                        "[1, 2]\n", "(line 3)"},
    };
    static const char *const cmds[] = {"export", "plot", "compare"};
    size_t i, c;
    char seq_truth[800];
    (void)state;
    snprintf(seq_truth, sizeof seq_truth, "%s/truth.json", seq_dir);
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[800], want[900];
        /* (tt_path's buffers rotate: a path kept across runs is copied) */
        snprintf(path, sizeof path, "%s", tt_path(cases[i].name));
        tt_write_str(path, cases[i].text);
        snprintf(want, sizeof want, "%s: not a cdsp_tool JSON record %s", path, cases[i].line);
        for (c = 0; c < 3; c++) {
            run_result r;
            if (c == 0)
                r = RUN("export", "--out", tt_path("x.ply"), path);
            else if (c == 1)
                r = RUN("plot", "--out", tt_path("x.png"), path);
            else
                r = RUN("compare", path, seq_truth);
            /* plot and compare read solve's CSV too: a CSV without the pose
             * columns is refused with its own wording */
            if (c > 0 && i == 0) {
                expect_status(&r, 2);
                tt_assert_contains(r.err, "p.csv: not a cdsp_tool CSV record file (line 1)");
            } else {
                if (r.status != 2 || !strstr(r.err, want))
                    fail_msg("%s %s: status %d, \"%s\", wanted \"%s\"", cmds[c], cases[i].name,
                             r.status, r.err, want);
            }
            run_free(&r);
        }
    }
}

/* JPEG and TIFF frames through solve: a 16-bit TIFF and an 8-bit TIFF of a
 * PGM frame solve to the very same pose (lossless), a JPEG (quality 100)
 * within its tolerance of the truth. */
static void write_tiff(const char *path, const cdsp_host_image *im)
{
    TIFF *t = TIFFOpen(path, "w");
    int y;
    assert_non_null(t);
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, (uint32_t)im->width);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, (uint32_t)im->height);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, (uint16_t)(im->bits > 8 ? 16 : 8));
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, (uint16_t)1);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, (uint16_t)PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_COMPRESSION, (uint16_t)COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 16u);
    for (y = 0; y < im->height; y++)
        assert_int_equal(TIFFWriteScanline(t, (unsigned char *)im->data + (size_t)y * im->stride,
                                           (uint32_t)y, 0), 1);
    TIFFClose(t);
}

static void write_jpeg(const char *path, const cdsp_host_image *im)
{
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr e;
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    c.err = jpeg_std_error(&e);
    jpeg_create_compress(&c);
    jpeg_stdio_dest(&c, f);
    c.image_width = (JDIMENSION)im->width;
    c.image_height = (JDIMENSION)im->height;
    c.input_components = 1;
    c.in_color_space = JCS_GRAYSCALE;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = (unsigned char *)im->data + (size_t)c.next_scanline * im->stride;
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    fclose(f);
}

static void jpeg_and_tiff_frames(void **state)
{
    char dir[600], pgm[800], tif[800], tif16[800], jpg[800];
    cdsp_host_image im;
    cdsp_host_err err;
    run_result a, b;
    json_object *ra[2], *rb[2];
    truth t;
    (void)state;
    snprintf(dir, sizeof dir, "%s", tt_path("jt"));
    assert_int_equal(mkdir(dir, 0777), 0);
    snprintf(pgm, sizeof pgm, "%s/frame_0000.pgm", seq_dir);
    snprintf(tif, sizeof tif, "%s/frame_0000.tif", dir);
    snprintf(tif16, sizeof tif16, "%s/frame_0000.tiff", png_dir);
    snprintf(jpg, sizeof jpg, "%s/frame_0000.jpg", dir);
    if (cdsp_host_image_read(pgm, &im, &err) != 0)
        fail_msg("%s", err.msg);
    write_tiff(tif, &im);
    write_jpeg(jpg, &im);
    cdsp_host_image_free(&im);
    /* lossless: the same record as the PGM's, but for the frame's name */
    a = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", pgm);
    b = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", tif);
    expect_status(&a, 0);
    expect_status(&b, 0);
    assert_string_equal(strstr(a.out, "\"status\""), strstr(b.out, "\"status\""));
    run_free(&a);
    run_free(&b);
    /* 16 bit */
    snprintf(pgm, sizeof pgm, "%s/frame_0000.png", png_dir);
    if (cdsp_host_image_read(pgm, &im, &err) != 0)
        fail_msg("%s", err.msg);
    assert_int_equal(im.bits, 16);
    write_tiff(tif16, &im);
    cdsp_host_image_free(&im);
    a = RUN("solve", "--calib", calib_of(png_dir), "--radius", "8", "--no-time", pgm);
    b = RUN("solve", "--calib", calib_of(png_dir), "--radius", "8", "--no-time", tif16);
    expect_status(&a, 0);
    expect_status(&b, 0);
    assert_string_equal(strstr(a.out, "\"status\""), strstr(b.out, "\"status\""));
    run_free(&a);
    run_free(&b);
    /* the directory lists the .jpg and the .tif; the JPEG's pose is within
     * the usual tolerance of the truth (quality 100: at most 1 grey level
     * off per pixel, test_host_jpeg_tiff) */
    truth_load(&t, seq_dir);
    a = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", dir);
    expect_status(&a, 0);
    assert_int_equal(parse_lines(a.out, ra, 2), 2);
    assert_non_null(strstr(str(key(ra[0], "file")), "frame_0000.jpg"));
    check_pose(&t, truth_frame(&t, 0), ra[0]);
    check_pose(&t, truth_frame(&t, 0), ra[1]);
    put_all(ra, 2);
    run_free(&a);
    /* a truncated TIFF is a bad-frame record naming the file */
    {
        size_t len;
        char *data = slurp(tif, &len), cut[800];
        snprintf(cut, sizeof cut, "%s/cut.tif", tt_tmpdir());
        tt_write(cut, data, len / 3);
        free(data);
        b = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", cut);
        expect_status(&b, 1);
        assert_int_equal(parse_lines(b.out, rb, 2), 1);
        assert_string_equal(str(key(rb[0], "error")), "bad-frame");
        tt_assert_contains(str(key(rb[0], "message")), cut);
        put_all(rb, 1);
        run_free(&b);
    }
    json_object_put(t.doc);
}

/* compare against sim's truth: every frame of the sequence solved, the
 * table's errors equal to the ones recomputed here from the records and
 * the truth, and within the pose tolerance of each frame (check_pose);
 * a failed record and a missing truth give status 1. */
static void compare_against_sim(void **state)
{
    char recs_path[800], truth_path[800];
    truth t;
    run_result r, c;
    json_object *recs[8], *rows[10];
    int n, i;
    (void)state;
    snprintf(recs_path, sizeof recs_path, "%s", tt_path("cmp.jsonl"));
    snprintf(truth_path, sizeof truth_path, "%s/truth.json", seq_dir);
    truth_load(&t, seq_dir);
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--track", seq_dir);
    expect_status(&r, 0);
    tt_write_str(recs_path, r.out);
    n = parse_lines(r.out, recs, 8);
    assert_int_equal(n, 8);
    c = RUN("compare", "--json", recs_path, truth_path);
    expect_status(&c, 0);
    assert_int_equal(parse_lines(c.out, rows, 10), 9);
    for (i = 0; i < n; i++) {
        json_object *tf = truth_frame(&t, (size_t)i);
        double seg[2][3], P[3], v[3], tv[3], s2 = 0, d;
        int k, j;
        check_pose(&t, tf, recs[i]);
        assert_string_equal(str(key(rows[i], "status")), "ok");
        for (j = 0; j < 2; j++)
            vec(json_object_array_get_idx(key(recs[i], "segment"), (size_t)j), seg[j], 3);
        vec(key(tf, "point"), P, 3);
        vec(key(tf, "direction"), tv, 3);
        for (k = 0; k < 100; k++) { /* the paper's metric, 100 points */
            double X[3], f = k / 99.0;
            for (j = 0; j < 3; j++)
                X[j] = seg[0][j] + f * (seg[1][j] - seg[0][j]);
            d = line_dist(X, P, tv);
            s2 += d * d;
        }
        assert_true(fabs(num(key(rows[i], "rmse")) - sqrt(s2 / 100)) <= 1e-12 * (1 + sqrt(s2)));
        vec(key(recs[i], "direction"), v, 3);
        assert_true(fabs(num(key(rows[i], "angle_deg")) - angle_between(v, tv) * 180 /
                                                                3.14159265358979323846) < 1e-6);
        assert_true(fabs(num(key(rows[i], "d_error")) -
                         (num(key(recs[i], "distance")) - num(key(tf, "distance")))) < 1e-9);
    }
    {
        json_object *sum = key(rows[8], "summary");
        assert_int_equal((int)num(key(sum, "frames")), 8);
        assert_int_equal((int)num(key(sum, "solved")), 8);
        assert_int_equal((int)num(key(sum, "failed")), 0);
    }
    put_all(rows, 9);
    run_free(&c);
    /* the table form, and --max-rmse below the largest error: status 1 */
    c = RUN("compare", recs_path, truth_path);
    expect_status(&c, 0);
    tt_assert_contains(c.out, "summary: 8 frames, 8 solved, 0 failed; axis RMSE ");
    run_free(&c);
    c = RUN("compare", "--max-rmse", "1e-9", recs_path, truth_path);
    expect_status(&c, 1);
    run_free(&c);
    /* an error record and a record without truth */
    {
        char *more = malloc(strlen(r.out) + 400);
        sprintf(more, "%s{\"frame\":\"x/frame_0003.pgm\",\"status\":\"error\",\"error\":\"no-pipe\"}\n"
                      "{\"frame\":\"x/other.pgm\",\"status\":\"error\",\"error\":\"no-pipe\"}\n",
                r.out);
        /* (the second: no truth by name, and none at its position 9 of 8) */
        tt_write_str(recs_path, more);
        free(more);
        c = RUN("compare", recs_path, truth_path);
        expect_status(&c, 1);
        /* (the frame column is as wide as the longest name) */
        {
            const char *l3 = strstr(c.out, "\nx/frame_0003.pgm "), *lo = strstr(c.out, "\nx/other.pgm ");
            assert_non_null(l3);
            assert_non_null(lo);
            assert_true(strncmp(l3 + strspn(l3 + 17, " ") + 17, "no-pipe ", 8) == 0);
            assert_true(strncmp(lo + strspn(lo + 12, " ") + 12, "no-truth ", 9) == 0);
        }
        tt_assert_contains(c.out, "summary: 10 frames, 8 solved, 1 failed, 1 without truth");
        run_free(&c);
    }
    c = RUN("compare", recs_path);
    expect_status(&c, 2);
    run_free(&c);
    c = RUN("compare", recs_path, tt_path("nothere.json"));
    expect_status(&c, 2);
    tt_assert_contains(c.err, "nothere.json");
    run_free(&c);
    put_all(recs, n);
    json_object_put(t.doc);
    run_free(&r);
}

/* ---- plot -------------------------------------------------------------------- */

/* A known record set drawn and measured back from the pixels: distance
 * 400 + k mm for record k = 0..20 (a straight line), sigma 0.5 mm, record
 * 10 without a pipe. In the top panel the curve's pixels (its exact colour)
 * must lie on one straight line, be absent between records 9 and 11 (the
 * break), the red band must be centred on record 10 and one record wide,
 * and the sigma band must span +-0.5 mm at the curve's own scale (px per mm
 * from its slope). Then the other forms: CSV, --truth, error cases.
 * The bounds, from how cairo fills (tools/tool_plot.c): a pixel has the
 * exact colour only when the shape covers all of its antialiasing samples
 * (inset <= 1/15 px from its edges: cairo's scan converter samples 15 rows
 * per pixel); the rest are blends, never equal to it.
 * - The curve, a 2 px stroke of slope m = 0.22 px/px: its edges move by m
 *   across a column, so a covered pixel's centre is within (2 sqrt(1 + m^2)
 *   - 1 - m)/2 + 1/15 = 0.48 px of the stroke's centre, at most one per
 *   column; the fitted line is off the true one by ~0.48/sqrt(600) = 0.02:
 *   0.5, bound 0.55 (measured worst 0.47; it was 1).
 * - Records 0 and 20 are the curve's end columns to within the butt cap's
 *   slant and the first covered column (<= 1.2 px each, inward at both
 *   ends): per_rec = (last - first)/20 to 0.12 px, their midpoint to 0.6.
 * - A band of width W px covers between W - 2 and W whole columns (rows),
 *   whichever its edges' phase; tilted by m, the sigma band's top and
 *   bottom lose up to m/2 more each: the red band's width minus per_rec in
 *   (-2.12, 0.12] (measured -1.1; it allowed +-2), its centre within 0.5
 *   (the columns lost on either side) + 0.6 of record 10's (measured 0.5:
 *   bound 1.1, it was 1.5); the sigma band's height minus 2 x 0.5 mm in
 *   (-2.25, 0.05] px (measured 7 rows for 7.68 px; it allowed +-2). */
static void plot_pixels_where_they_belong(void **state)
{
    char recs[800], png[800], truth_path[800];
    char *text = malloc(21 * 400), *t = text;
    run_result r;
    picture p;
    unsigned x, y, top, bottom;
    int k, first_x = -1, last_x = -1, n_col = 0, gap_lo = -1, gap_hi = -1, curve_in_gap = 0;
    double sx = 0, sy = 0, sxx = 0, sxy = 0, slope, icpt, worst = 0;
    (void)state;
    snprintf(recs, sizeof recs, "%s", tt_path("plot.jsonl"));
    snprintf(png, sizeof png, "%s", tt_path("plot.png"));
    snprintf(truth_path, sizeof truth_path, "%s/truth.json", seq_dir);
    for (k = 0; k <= 20; k++) {
        if (k == 10)
            t += sprintf(t, "{\"frame\":\"f%02d.pgm\",\"status\":\"error\",\"error\":\"no-pipe\"}\n", k);
        else
            t += sprintf(t, "{\"frame\":\"f%02d.pgm\",\"status\":\"ok\",\"point\":[%d,%d,400],"
                            "\"direction\":[1,0.5,0.1],\"distance\":%d,"
                            "\"sigma\":{\"point\":[0.2,0.2,0.2],\"direction\":[0.001,0.001,0.001],"
                            "\"distance\":0.5}}\n", k, k, -k, 400 + k);
    }
    tt_write_str(recs, text);
    free(text);
    r = RUN("plot", "--out", png, "--width", "800", "--height", "700", recs);
    expect_status(&r, 0);
    run_free(&r);
    p = read_png(png);
    assert_int_equal(p.w, 800);
    assert_int_equal(p.h, 700);
    /* the top panel's plot area: between the black top and bottom lines of
     * its frame, found in a column just inside its right side (the title
     * and the legend do not reach there) */
    for (top = 0; top < p.h && !is_rgb(&p, p.w - 18, top, 0, 0, 0); top++)
        ;
    for (bottom = top + 1; bottom < p.h && !is_rgb(&p, p.w - 18, bottom, 0, 0, 0); bottom++)
        ;
    assert_true(bottom < p.h / 2 && bottom > top + 100);
    for (x = 0; x < p.w; x++) {
        int n = 0, gapc = 0;
        double ysum = 0;
        for (y = top; y < bottom; y++) {
            if (is_rgb(&p, x, y, 0, 90, 200)) {
                ysum += y;
                n++;
            }
            gapc += is_rgb(&p, x, y, 255, 215, 215);
        }
        if (gapc > 50) {
            if (gap_lo < 0)
                gap_lo = (int)x;
            gap_hi = (int)x;
            curve_in_gap += n > 0;
        }
        if (n == 0 || gapc > 50)
            continue;
        if (n > 1)
            fail_msg("plot: column %u has %d curve pixels (at most one is covered)", x, n);
        if (first_x < 0)
            first_x = (int)x;
        last_x = (int)x;
        ysum /= n;
        sx += x;
        sy += ysum;
        sxx += (double)x * x;
        sxy += x * ysum;
        n_col++;
    }
    assert_true(n_col > 300);
    slope = (n_col * sxy - sx * sy) / (n_col * sxx - sx * sx);
    icpt = (sy - slope * sx) / n_col;
    for (x = (unsigned)first_x; x <= (unsigned)last_x; x++) {
        int n = 0;
        double ysum = 0;
        if ((int)x >= gap_lo && (int)x <= gap_hi)
            continue;
        for (y = top; y < bottom; y++)
            if (is_rgb(&p, x, y, 0, 90, 200)) {
                ysum += y;
                n++;
            }
        if (n)
            worst = fmax(worst, fabs(ysum / n - (slope * x + icpt)));
    }
    printf("plot: curve from x %d to %d, slope %.4f px/px, worst %.2f px off the line; "
           "gap %d..%d\n", first_x, last_x, slope, worst, gap_lo, gap_hi);
    assert_true(worst <= 0.55);
    assert_true(slope < 0); /* distance grows upward */
    assert_int_equal(curve_in_gap, 0);
    {
        /* records 0 and 20 at first_x and last_x: record 10 at the middle,
         * the band one record (1/20 of the run) wide */
        double per_rec = (last_x - first_x) / 20.0, mid = first_x + 10 * per_rec;
        printf("plot: gap centre %.2f px off record 10's, width %d px for %.2f\n",
               0.5 * (gap_lo + gap_hi) - mid, gap_hi - gap_lo + 1, per_rec);
        assert_true(fabs(0.5 * (gap_lo + gap_hi) - mid) <= 1.1);
        assert_true((gap_hi - gap_lo + 1) - per_rec > -2.12 && (gap_hi - gap_lo + 1) - per_rec <= 0.12);
        /* px per mm: the curve rises 20 mm over the run */
        {
            double px_mm = -slope * (last_x - first_x) / 20.0;
            unsigned cx = (unsigned)(first_x + 3 * per_rec); /* record 3 */
            int lo = -1, hi = -1;
            for (y = top; y < bottom; y++)
                if (is_rgb(&p, cx, y, 200, 220, 245) || is_rgb(&p, cx, y, 0, 90, 200)) {
                    if (lo < 0)
                        lo = (int)y;
                    hi = (int)y;
                }
            printf("plot: %.2f px per mm, sigma band %d px tall (expected %.2f)\n", px_mm,
                   hi - lo + 1, 2 * 0.5 * px_mm);
            assert_true((hi - lo + 1) - 2 * 0.5 * px_mm > -2.25 && (hi - lo + 1) - 2 * 0.5 * px_mm <= 0.05);
        }
    }
    free(p.rgb);

    /* solve's CSV plots the same picture as its JSON */
    {
        run_result j, c;
        char pj[800], pc[800], sj[800], scsv[800];
        char *a, *b;
        size_t la, lb;
        snprintf(pj, sizeof pj, "%s", tt_path("pj.png"));
        snprintf(pc, sizeof pc, "%s", tt_path("pc.png"));
        snprintf(sj, sizeof sj, "%s", tt_path("s.jsonl"));
        snprintf(scsv, sizeof scsv, "%s", tt_path("s.csv"));
        j = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", seq_dir);
        c = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", "--no-time", "--csv",
                seq_dir);
        tt_write_str(sj, j.out);
        tt_write_str(scsv, c.out);
        run_free(&j);
        run_free(&c);
        j = RUN("plot", "--out", pj, "--title", "t", "--truth", truth_path, sj);
        c = RUN("plot", "--out", pc, "--title", "t", "--truth", truth_path, scsv);
        expect_status(&j, 0);
        expect_status(&c, 0);
        a = slurp(pj, &la);
        b = slurp(pc, &lb);
        /* (the CSV rounds nothing: its numbers read back exactly) */
        assert_int_equal(la, lb);
        assert_memory_equal(a, b, la);
        free(a);
        free(b);
        p = read_png(pj);
        assert_int_equal(p.h, 240 * 5 + 70); /* five panels with --truth */
        free(p.rgb);
        run_free(&j);
        run_free(&c);
    }
    /* error cases */
    r = RUN("plot", recs);
    expect_status(&r, 2);
    tt_assert_contains(r.err, "--out FILE.png is required");
    run_free(&r);
    r = RUN("plot", "--out", png, "--x", "time", recs);
    expect_status(&r, 2);
    tt_assert_contains(r.err, "has no time");
    run_free(&r);
    r = RUN("plot", "--out", tt_path("nodir/x.png"), recs);
    expect_status(&r, 2);
    tt_assert_contains(r.err, "cannot write the picture");
    run_free(&r);
    tt_write_str(tt_path("allbad.jsonl"), "{\"frame\":\"a\",\"status\":\"error\",\"error\":\"no-pipe\"}\n");
    r = RUN("plot", "--out", png, tt_path("allbad.jsonl"));
    expect_status(&r, 1);
    run_free(&r);
}

/* The overlay of a 5 MP frame (the paper's camera) says what it found:
 * a caption band across the top whose height follows the frame (two lines
 * of 16 px text per 1000 px: 2448 px wide gives 39 px text), white text in
 * it, and the --roi rectangle in cyan where it was asked. Exact counts,
 * from how cairo fills (tools/tool_caption.c; a pixel has the exact colour
 * only when covered whole, see plot_pixels_where_they_belong):
 * - the band is the rectangle [0, want) with want = 2 x 1.3 font + 2 x 0.4
 *   font = 133.2 px: rows 0 .. floor(want) - 1 covered, the next one only
 *   in part: floor(want) = 133 rows (measured 133; it allowed +-1).
 * - the ROI's left side is a stroke of width 1.5 s = 3.67 px centred on
 *   cairo's x = 200 (the outer edge of column 200: cairo's pixel i spans
 *   [i, i + 1]): it covers [198.16, 201.84], columns 199 and 200 whole and
 *   no other; dashed 6 s on, 4 s off (s = 2.448) along the path, which
 *   reaches the left side at arc length 5500 and runs up it, so row y is
 *   covered when [7300 - (y + 1), 7300 - y] lies in an on-dash. Rows whose
 *   dash end falls within 1/15 px of their edge may go either way: the
 *   count is between 2 x the sure rows and 2 x the possible ones (measured
 *   564 in [560, 566]; it checked > 100 in columns 195 .. 205). */
static void overlay_caption_and_roi(void **state)
{
    char dir[600], pdir[600], png[800], calib[800], frame[800];
    run_result r;
    picture p;
    unsigned x, y, band = 0, white = 0, cyan_left = 0;
    double font = 16.0 * 2448 / 1000, want;
    (void)state;
    snprintf(dir, sizeof dir, "%s", tt_path("ov5"));
    snprintf(pdir, sizeof pdir, "%s", tt_path("paper5"));
    snprintf(calib, sizeof calib, "%s/camera.yaml", pdir);
    snprintf(frame, sizeof frame, "%s/frame_0000.pgm", pdir);
    /* one frame of a 5 MP camera (the paper's: 2448 x 2048, f = 3478 px) */
    r = RUN("sim", "--out", pdir, "--width", "2448", "--height", "2048", "--fx", "3478.26",
            "--fy", "3478.26", "--ambient", "1");
    expect_status(&r, 0);
    run_free(&r);
    r = RUN("overlay", "--calib", calib, "--radius", "8", "--out", dir,
            "--roi", "200,300,2000,1500", frame);
    expect_status(&r, 0);
    run_free(&r);
    snprintf(png, sizeof png, "%s/frame_0000_overlay.png", dir);
    p = read_png(png);
    assert_int_equal(p.w, 2448);
    assert_int_equal(p.h, 2048);
    /* the band: rows of gray 32 at the right edge (no text reaches it) */
    for (y = 0; y < 400 && is_rgb(&p, p.w - 1, y, 32, 32, 32); y++)
        band++;
    for (y = 0; y < band; y++)
        for (x = 0; x < p.w; x++)
            white += is_rgb(&p, x, y, 255, 255, 255);
    want = 2 * 1.3 * font + 2 * 0.4 * font;
    printf("overlay: caption band %u px (expected %.1f), %u white text pixels\n", band, want,
           white);
    assert_int_equal(band, (unsigned)floor(want));
    assert_true(white > 2000);
    /* the ROI's left side */
    {
        const double sc = 2448 / 1000.0, on = 6 * sc, period = 10 * sc, slop = 1.0 / 15;
        unsigned sure = 0, maybe = 0;
        for (y = 1000; y < 1500; y++) {
            double a = fmod(7300.0 - (y + 1), period), b;
            if (a > period - slop) /* a dash starting at the row's edge */
                a -= period;
            b = a + 1; /* the row's arc, in one period */
            sure += a >= slop && b <= on - slop;
            maybe += a >= -slop && b <= on + slop;
            for (x = 195; x <= 205; x++)
                if (is_rgb(&p, x, y, 0, 255, 255)) {
                    if (x != 199 && x != 200)
                        fail_msg("a cyan pixel at (%u, %u): the ROI's side covers columns 199, 200", x, y);
                    cyan_left++;
                }
        }
        printf("overlay: roi side %u cyan pixels (expected %u .. %u)\n", cyan_left, 2 * sure,
               2 * maybe);
        assert_true(cyan_left >= 2 * sure && cyan_left <= 2 * maybe);
    }
    for (y = 1000; y < 1500; y++)
        for (x = 600; x <= 610; x++)
            assert_false(is_rgb(&p, x, y, 0, 255, 255));
    free(p.rgb);
}

/* On a terminal (script(1) gives the tool one), solve ends with a summary
 * line; in a pipe, neither it nor any progress appears. Progress shows only
 * after 2 s: a run that took longer shows it, a quicker one must not (the
 * test times the run rather than assume the machine's speed). */
static void terminal_lines(void **state)
{
    char cmd[3000], *tty;
    double t0, secs;
    struct timespec ts;
    run_result r;
    (void)state;
    snprintf(cmd, sizeof cmd,
             "script -qec \"%s solve --calib %s --radius 8 %s >/dev/null\" /dev/null >%s 2>&1",
             tool_path(), calib_of(seq_dir), seq_dir, tt_path("tty.txt"));
    assert_int_equal(system(cmd), 0);
    tty = slurp(tt_path("tty.txt"), NULL);
    tt_assert_contains(tty, "solve: 8 frames, 8 solved, 0 failed, ");
    free(tty);
    r = RUN("solve", "--calib", calib_of(seq_dir), "--radius", "8", seq_dir);
    expect_status(&r, 0);
    assert_string_equal(r.err, "");
    run_free(&r);
    clock_gettime(CLOCK_MONOTONIC, &ts);
    t0 = ts.tv_sec + 1e-9 * ts.tv_nsec;
    snprintf(cmd, sizeof cmd,
             "script -qec \"%s sim --out %s --frames 20 --width 320 --height 240 >/dev/null\" "
             "/dev/null >%s 2>&1", tool_path(), tt_path("ttysim"), tt_path("ttysim.txt"));
    assert_int_equal(system(cmd), 0);
    clock_gettime(CLOCK_MONOTONIC, &ts);
    secs = ts.tv_sec + 1e-9 * ts.tv_nsec - t0;
    tty = slurp(tt_path("ttysim.txt"), NULL);
    printf("sim on a terminal: %.2f s, progress %s\n", secs, strstr(tty, "/20 frames") ? "shown" : "not shown");
    if (secs > 3.0) /* 2 s plus the terminal's start */
        tt_assert_contains(tty, "sim: ");
    else if (secs < 2.0)
        assert_null(strstr(tty, "/20 frames"));
    free(tty);
}

/* Every fenced block after a "<!-- checked -->" line in the manual is run:
 * "$ " lines are commands (build/cdsp_tool meaning the tool under test,
 * /tmp/ this suite's scratch directory), the lines up to the next command
 * their output (standard output and error), compared with what they print
 * with all white space removed (the manual wraps long JSON lines). */
static char *squeeze(const char *s)
{
    char *o = malloc(strlen(s) + 1), *q = o;
    for (; *s; s++)
        if (*s != ' ' && *s != '\n' && *s != '\t' && *s != '\r')
            *q++ = *s;
    *q = 0;
    return o;
}

static char *replace_all(const char *s, const char *from, const char *to)
{
    size_t n = 0, lf = strlen(from), lt = strlen(to);
    const char *p;
    char *o, *q;
    for (p = s; (p = strstr(p, from)); p += lf)
        n++;
    o = malloc(strlen(s) + n * lt + 1);
    for (q = o, p = s;;) {
        const char *h = strstr(p, from);
        if (!h) {
            strcpy(q, p);
            break;
        }
        memcpy(q, p, (size_t)(h - p));
        q += h - p;
        memcpy(q, to, lt);
        q += lt;
        p = h + lf;
    }
    return o;
}

static void check_example(const char *cmd, const char *expected, int block)
{
    char tmp[700], sh[8192], *c1, *c2, *e1, *got, *a, *b;
    int st;
    snprintf(tmp, sizeof tmp, "%s/", tt_tmpdir());
    c1 = replace_all(cmd, "build/cdsp_tool", tool_path());
    c2 = replace_all(c1, "/tmp/", tmp);
    e1 = replace_all(expected, "/tmp/", tmp);
    snprintf(sh, sizeof sh, "(%s) >%s 2>&1", c2, tt_path("example.out"));
    st = system(sh);
    assert_true(st != -1);
    got = slurp(tt_path("example.out"), NULL);
    a = squeeze(got);
    b = squeeze(e1);
    if (strcmp(a, b) != 0)
        fail_msg("docs/cdsp_tool.md, checked example %d:\n$ %s\nprints:\n%swhere the manual "
                 "says:\n%s", block, cmd, got, expected);
    free(a);
    free(b);
    free(got);
    free(c1);
    free(c2);
    free(e1);
}

static void docs_examples_run(void **state)
{
    const char *env = getenv("CDSP_DOCS");
    char *doc = slurp(env && *env ? env : "docs/cdsp_tool.md", NULL), *p = doc;
    int blocks = 0;
    (void)state;
    while ((p = strstr(p, "<!-- checked -->\n```sh\n")) != NULL) {
        char *end, *line, cmd[4096] = "", out[16384] = "";
        p += strlen("<!-- checked -->\n```sh\n");
        end = strstr(p, "\n```\n");
        assert_non_null(end);
        *end = 0;
        blocks++;
        for (line = p; line && *line;) {
            char *nl = strchr(line, '\n');
            if (nl)
                *nl = 0;
            if (strncmp(line, "$ ", 2) == 0) {
                if (cmd[0])
                    check_example(cmd, out, blocks);
                snprintf(cmd, sizeof cmd, "%s", line + 2);
                out[0] = 0;
            } else {
                size_t k = strlen(out);
                snprintf(out + k, sizeof out - k, "%s\n", line);
            }
            line = nl ? nl + 1 : NULL;
        }
        if (cmd[0])
            check_example(cmd, out, blocks);
        p = end + 1;
    }
    /* the walkthrough's solve, compare and bad-frame examples */
    assert_true(blocks >= 3);
    free(doc);
}

static void frame_of_8192_squared(void **state)
{
    const int W = 8192, H = 8192, u0 = 4000, u1 = 4120;
    cdsp_host_image im;
    cdsp_host_err err;
    cdsp_camera cam;
    const char *frame = tt_path("big.pgm"), *cal = tt_path("big.yaml");
    run_result r;
    json_object *recs[2];
    int y;
    double l[3];
    (void)state;
    assert_int_equal(cdsp_host_image_alloc(&im, W, H, 8, &err), 0);
    for (y = 0; y < H; y++) {
        unsigned char *row = (unsigned char *)im.data + (size_t)y * im.stride;
        memset(row, 60, (size_t)W);
        memset(row + u0, 200, (size_t)(u1 - u0));
    }
    assert_int_equal(cdsp_host_pgm_write(frame, &im, &err), 0);
    cdsp_host_image_free(&im);
    memset(&cam, 0, sizeof cam);
    cam.width = W;
    cam.height = H;
    cam.fx = cam.fy = 10000;
    cam.cx = cam.cy = (W - 1) / 2.0;
    assert_int_equal(cdsp_host_calib_write(cal, &cam, "big", &err), 0);
    r = RUN("solve", "--calib", cal, "--radius", "8", frame);
    expect_status(&r, 0);
    assert_int_equal(parse_lines(r.out, recs, 2), 1);
    check_ok_schema(recs[0]);
    /* the contours are the columns u = 3999.5 and u = 4119.5 */
    vec(json_object_array_get_idx(key(recs[0], "lines"), 0), l, 3);
    /* a sharp step between integer levels: the partial-area sums are exact
     * integers, so the line is exact but for the fit's rounding, eps x 4e3
     * px (measured: exactly 1 and 3999.5; they allowed 1e-6 and 0.05 px) */
    assert_true(fabs(fabs(l[0]) - 1) <= 4 * DBL_EPSILON);
    assert_true(fabs(fabs(l[2] / l[0]) - 3999.5) < 1e-9 || fabs(fabs(l[2] / l[0]) - 4119.5) < 1e-9);
    json_object_put(recs[0]);
    run_free(&r);
    remove(frame);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(poses_of_a_sequence),
        cmocka_unit_test(poses_with_lens_distortion),
        cmocka_unit_test(poses_from_16bit_png),
        cmocka_unit_test(tracking_a_sequence),
        cmocka_unit_test(paper_preset),
        cmocka_unit_test(examples_solve),
        cmocka_unit_test(threads_give_identical_output),
        cmocka_unit_test(csv_matches_json),
        cmocka_unit_test(roi_and_list),
        cmocka_unit_test(bad_frames_get_error_records),
        cmocka_unit_test(bad_calibrations_exit_2),
        cmocka_unit_test(usage_errors_exit_2),
        cmocka_unit_test(help_pages),
        cmocka_unit_test(docs_match_help),
        cmocka_unit_test(overlay_draws_the_pipe),
        cmocka_unit_test(export_meshes),
        cmocka_unit_test(solve_all_rack),
        cmocka_unit_test(bench_files),
        cmocka_unit_test(out_dirs_created_with_parents),
        cmocka_unit_test(not_a_record_named),
        cmocka_unit_test(jpeg_and_tiff_frames),
        cmocka_unit_test(compare_against_sim),
        cmocka_unit_test(plot_pixels_where_they_belong),
        cmocka_unit_test(overlay_caption_and_roi),
        cmocka_unit_test(terminal_lines),
        cmocka_unit_test(docs_examples_run),
        cmocka_unit_test(frame_of_8192_squared),
    };
    /* CDSP_TEST_FILTER=pattern (cmocka's wildcards) runs only matching tests */
    if (getenv("CDSP_TEST_FILTER"))
        cmocka_set_test_filter(getenv("CDSP_TEST_FILTER"));
    return cmocka_run_group_tests_name("tool_cli", tests, setup, tt_teardown);
}
