/*
 * test_calib.c - checks of the real cdsp_calib binary on synthetic boards.
 *
 * Usage: test_calib PATH/TO/cdsp_calib PATH/TO/cdsp_tool WORKDIR
 *
 * Twelve views of a 9x6 board are rendered with a known camera (K, k1, k2)
 * and known poses (board_render.c: exact inverse distortion, supersampled
 * edges, seeded noise), some as 8-bit and some as 12-bit-in-16 PGM. The
 * binary calibrates them; its YAML is parsed with libyaml and compared with
 * the truth. Tolerances:
 *   - fx, fy within 0.2 %, cx, cy within 1 px, RMS under 0.1 px (the
 *     issue's requirements);
 *   - fx, fy, cx, cy, k1, k2 (and p1, p2, k3 with --full-model) within 5
 *     sigma of the
 *     Cramer-Rao bound of this very geometry: the normal matrix J^T J of
 *     the projections of every true corner with respect to the intrinsics
 *     and the 6 pose parameters of every view, at the truth, scaled by the
 *     per-coordinate corner noise that the calibration's own RMS error
 *     implies (RMS / sqrt(2): RMS is over both coordinates). That is the
 *     spread any unbiased calibration from these corners would have; 5
 *     sigma rather than 3 leaves room for the part of the corner error that
 *     is not independent noise (residual pixel locking of the subpixel
 *     refinement, ~0.01 px, correlated along an edge). The RMS is itself
 *     bounded (0.1 px), so the tolerance cannot grow without failing that.
 *     Over 8 noise draws (test_spread_over_seeds) the errors' mean and
 *     mean square in sigmas are checked against bands from the draw count;
 *   - the projection matrix: OpenCV's alpha = 0 rule recomputed from the K
 *     and D written (check_recovery).
 * Then the calibration in use: cdsp_tool solve on simulated pipe frames of
 * the same camera, with the calibration found and with the true one (see
 * test_pipe_poses_with_calibration for the margin). Then bad inputs: each
 * documented message and exit status.
 */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>
#include <json-c/json.h>
#include <yaml.h>

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>

#include "board_render.h"

static const char *g_bin;    /* the cdsp_calib under test */
static const char *g_tool;   /* cdsp_tool, which reads the calibration */
static const char *g_work;   /* scratch directory */

/* ------------------------------------------------------------------------
 * The scene: one camera, one board, twelve poses.
 * ---------------------------------------------------------------------- */

/* A 1024 x 768 camera with a moderate barrel distortion (7 % at the image
 * corners), fx != fy and the principal point off centre, so that no
 * parameter is recovered by symmetry alone. */
static const br_camera g_cam = {1100.0, 1095.0, 515.3, 380.7, -0.21, 0.09, 1024, 768};
/* 9 x 6 inner corners, 30 mm squares, a one-square white border. */
static const br_board g_board = {9, 6, 30.0, 1.0};
/* Image noise: 1 % of full scale (2.55 DN at 8 bit), a machine-vision
 * sensor at moderate gain. */
#define NOISE 0.01

#define N_VIEWS 12

/* A view: the board's centre is pushed from the optical axis toward the
 * normalized image direction (dx, dy) as far as the whole board (with its
 * border) stays 8 px inside the image, at depth z (mm), rotation rvec. The
 * set mixes a near fronto-parallel view, boards tilted 30-45 degrees in
 * the four corners and at the four edges (the corners and edges are where
 * k1, k2 show), and views rotated in plane. */
typedef struct {
    double dx, dy, z;
    double rvec[3];
} view_spec;

static const view_spec g_views[N_VIEWS] = {
    {0.00, 0.00, 750, {0.00, 0.00, 0.15}},
    {-0.50, -0.40, 1100, {-0.40, 0.40, 0.12}},
    {0.50, -0.40, 1100, {-0.40, -0.40, -0.15}},
    {-0.50, 0.40, 1100, {0.40, 0.40, -0.10}},
    {0.50, 0.40, 1100, {0.40, -0.40, 0.12}},
    {0.00, -0.40, 950, {-0.70, 0.00, 0.08}},
    {0.00, 0.40, 950, {0.70, 0.00, -0.10}},
    {-0.50, 0.00, 950, {0.00, -0.70, 0.10}},
    {0.50, 0.00, 950, {0.00, 0.70, -0.08}},
    {0.05, 0.02, 650, {0.30, -0.30, 0.60}},
    {-0.10, 0.05, 950, {0.15, 0.75, -0.35}},
    {0.10, -0.05, 950, {-0.55, -0.50, 0.30}},
};

static br_pose g_poses[N_VIEWS];

static void pose_at(const view_spec *s, double scale, br_pose *p)
{
    double R[9], c[2], dir[3];
    int i;
    c[0] = 0.5 * (g_board.cols - 1) * g_board.square;
    c[1] = 0.5 * (g_board.rows - 1) * g_board.square;
    dir[0] = scale * s->dx;
    dir[1] = scale * s->dy;
    dir[2] = 1;
    memcpy(p->rvec, s->rvec, sizeof p->rvec);
    br_rodrigues(p->rvec, R);
    for (i = 0; i < 3; i++)
        p->t[i] = s->z * dir[i] - (R[3 * i] * c[0] + R[3 * i + 1] * c[1]);
}

/* The board as far toward (dx, dy) as it stays in view (bisection when
 * the full step leaves the image). 0 if it is not even visible on the
 * optical axis (a broken view table). */
static int place_view(const view_spec *s, br_pose *p)
{
    double lo = 0, hi = 1;
    int it;
    pose_at(s, 1, p);
    if (br_visible(&g_cam, &g_board, p, 8))
        return 1;
    pose_at(s, 0, p);
    if (!br_visible(&g_cam, &g_board, p, 8))
        return 0;
    for (it = 0; it < 40; it++) {
        double mid = 0.5 * (lo + hi);
        pose_at(s, mid, p);
        if (br_visible(&g_cam, &g_board, p, 8))
            lo = mid;
        else
            hi = mid;
    }
    pose_at(s, lo, p);
    return 1;
}

/* ------------------------------------------------------------------------
 * Files and processes.
 * ---------------------------------------------------------------------- */

/* g_work/fmt..., in one of 16 rotating buffers: enough for every path of
 * one command line. */
static char *path(const char *fmt, ...)
{
    static char buf[16][1024];
    static int k;
    char *b = buf[k++ % 16];
    va_list ap;
    int n = snprintf(b, sizeof buf[0], "%s/", g_work);
    va_start(ap, fmt);
    vsnprintf(b + n, sizeof buf[0] - (size_t)n, fmt, ap);
    va_end(ap);
    return b;
}

static char *slurp(const char *p)
{
    FILE *f = fopen(p, "rb");
    char *s;
    long n;
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = 0;
    fclose(f);
    return s;
}

static int write_bytes(const char *p, const void *data, size_t n)
{
    FILE *f = fopen(p, "wb");
    int ok;
    if (!f)
        return 0;
    ok = fwrite(data, 1, n, f) == n;
    return (fclose(f) == 0) && ok;
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static int is_png(const char *p)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char b[8];
    FILE *f = fopen(p, "rb");
    int ok;
    if (!f)
        return 0;
    ok = fread(b, 1, 8, f) == 8 && memcmp(b, sig, 8) == 0;
    fclose(f);
    return ok;
}

/* What one run of the binary left behind. */
typedef struct {
    int status;    /* exit status; -1 if killed by a signal (a crash) */
    char *out;     /* its standard output */
    char *err;     /* its standard error */
} run_result;

static void run_free(run_result *r)
{
    free(r->out);
    free(r->err);
    r->out = r->err = NULL;
}

/* Runs cdsp_calib with args (a shell word list; the paths used here hold
 * no shell metacharacters, checked at setup). */
static run_result run_calib(const char *fmt, ...)
{
    char args[4096], cmd[8192], o[1024], e[1024];
    run_result r;
    va_list ap;
    int st;
    va_start(ap, fmt);
    vsnprintf(args, sizeof args, fmt, ap);
    va_end(ap);
    snprintf(o, sizeof o, "%s/run.out", g_work);
    snprintf(e, sizeof e, "%s/run.err", g_work);
    snprintf(cmd, sizeof cmd, "%s %s >%s 2>%s", g_bin, args, o, e);
    st = system(cmd);
    r.status = (st != -1 && WIFEXITED(st)) ? WEXITSTATUS(st) : -1;
    r.out = slurp(o);
    r.err = slurp(e);
    if (!r.out)
        r.out = calloc(1, 1);
    if (!r.err)
        r.err = calloc(1, 1);
    /* cmocka's print_message truncates long text: plain stdio here. */
    printf("$ cdsp_calib %s\n  -> exit %d\n", args, r.status);
    if (r.status != 0 && r.err[0])
        fputs(r.err, stdout);
    fflush(stdout);
    return r;
}

/* Lines of a report that mention name and also the word what. */
static int count_lines_with(const char *text, const char *name, const char *what)
{
    int n = 0;
    const char *line = text;
    while (line && *line) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        char buf[1024];
        if (len >= sizeof buf)
            len = sizeof buf - 1;
        memcpy(buf, line, len);
        buf[len] = 0;
        if ((!name || strstr(buf, name)) && strstr(buf, what))
            n++;
        line = end ? end + 1 : NULL;
    }
    return n;
}

/* ------------------------------------------------------------------------
 * The camera_info YAML, read with libyaml.
 * ---------------------------------------------------------------------- */

typedef struct {
    int width, height;
    char name[128];
    char model[64];
    double K[9], D[5], R[9], P[12];
    double rms;              /* from the first comment line */
    int n_used, n_given;
} camera_info;

static yaml_node_t *map_get(yaml_document_t *doc, yaml_node_t *map, const char *key)
{
    yaml_node_pair_t *p;
    if (!map || map->type != YAML_MAPPING_NODE)
        return NULL;
    for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; p++) {
        yaml_node_t *k = yaml_document_get_node(doc, p->key);
        if (k && k->type == YAML_SCALAR_NODE && strcmp((char *)k->data.scalar.value, key) == 0)
            return yaml_document_get_node(doc, p->value);
    }
    return NULL;
}

static int scalar_double(yaml_node_t *n, double *x)
{
    char *end;
    if (!n || n->type != YAML_SCALAR_NODE || n->data.scalar.length == 0)
        return 0;
    errno = 0;
    *x = strtod((char *)n->data.scalar.value, &end);
    return *end == 0 && errno == 0 && isfinite(*x);
}

static int scalar_int(yaml_node_t *n, int *v)
{
    double x;
    if (!scalar_double(n, &x) || x != floor(x) || fabs(x) > 1e6)
        return 0;
    *v = (int)x;
    return 1;
}

static int scalar_str(yaml_node_t *n, char *out, size_t cap)
{
    if (!n || n->type != YAML_SCALAR_NODE || n->data.scalar.length >= cap)
        return 0;
    memcpy(out, n->data.scalar.value, n->data.scalar.length + 1);
    return 1;
}

/* {rows: r, cols: c, data: [r*c numbers]} */
static int get_matrix(yaml_document_t *doc, yaml_node_t *root, const char *key, int rows,
                      int cols, double *out)
{
    yaml_node_t *m = map_get(doc, root, key), *data;
    yaml_node_item_t *it;
    int r, c, i = 0;
    if (!scalar_int(map_get(doc, m, "rows"), &r) || !scalar_int(map_get(doc, m, "cols"), &c) ||
        r != rows || c != cols) {
        print_error("%s: rows/cols missing or not %d x %d\n", key, rows, cols);
        return 0;
    }
    data = map_get(doc, m, "data");
    if (!data || data->type != YAML_SEQUENCE_NODE) {
        print_error("%s: no data sequence\n", key);
        return 0;
    }
    for (it = data->data.sequence.items.start; it < data->data.sequence.items.top; it++) {
        if (i >= rows * cols || !scalar_double(yaml_document_get_node(doc, *it), &out[i])) {
            print_error("%s: data item %d is not a number or one too many\n", key, i);
            return 0;
        }
        i++;
    }
    if (i != rows * cols) {
        print_error("%s: %d numbers, not %d\n", key, i, rows * cols);
        return 0;
    }
    return 1;
}

/* Parses the YAML text; 1 if every field is there and well formed. */
static int parse_camera_info(const char *text, camera_info *ci)
{
    yaml_parser_t parser;
    yaml_document_t doc;
    yaml_node_t *root;
    int ok = 0;

    memset(ci, 0, sizeof *ci);
    if (sscanf(text, "# cdsp_calib: RMS reprojection error %lf px over %d images (of %d given)",
               &ci->rms, &ci->n_used, &ci->n_given) != 3) {
        print_error("first line is not the RMS comment: %.80s\n", text);
        return 0;
    }
    if (!yaml_parser_initialize(&parser))
        return 0;
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, strlen(text));
    if (!yaml_parser_load(&parser, &doc)) {
        print_error("YAML error: %s at line %lu\n", parser.problem ? parser.problem : "?",
                    (unsigned long)parser.problem_mark.line + 1);
        yaml_parser_delete(&parser);
        return 0;
    }
    root = yaml_document_get_root_node(&doc);
    if (root && root->type == YAML_MAPPING_NODE &&
        scalar_int(map_get(&doc, root, "image_width"), &ci->width) &&
        scalar_int(map_get(&doc, root, "image_height"), &ci->height) &&
        scalar_str(map_get(&doc, root, "camera_name"), ci->name, sizeof ci->name) &&
        scalar_str(map_get(&doc, root, "distortion_model"), ci->model, sizeof ci->model) &&
        get_matrix(&doc, root, "camera_matrix", 3, 3, ci->K) &&
        get_matrix(&doc, root, "distortion_coefficients", 1, 5, ci->D) &&
        get_matrix(&doc, root, "rectification_matrix", 3, 3, ci->R) &&
        get_matrix(&doc, root, "projection_matrix", 3, 4, ci->P))
        ok = 1;
    else
        print_error("camera_info: a field is missing or malformed\n");
    yaml_document_delete(&doc);
    yaml_parser_delete(&parser);
    return ok;
}

/* ------------------------------------------------------------------------
 * The Cramer-Rao bound of the calibration of the scene above.
 * ---------------------------------------------------------------------- */

/* Intrinsics: fx fy cx cy k1 k2 p1 p2 k3 (plumb_bob, the tool's model). */
#define N_INTR 9

static void project_full(const double in[N_INTR], const double pose[6], double X, double Y,
                         double pix[2])
{
    double R[9], P[3], x, y, r2, rad, xd, yd;
    int i;
    br_rodrigues(pose, R);
    for (i = 0; i < 3; i++)
        P[i] = R[3 * i] * X + R[3 * i + 1] * Y + pose[3 + i];
    x = P[0] / P[2];
    y = P[1] / P[2];
    r2 = x * x + y * y;
    rad = 1 + in[4] * r2 + in[5] * r2 * r2 + in[8] * r2 * r2 * r2;
    xd = x * rad + 2 * in[6] * x * y + in[7] * (r2 + 2 * x * x);
    yd = y * rad + in[6] * (r2 + 2 * y * y) + 2 * in[7] * x * y;
    pix[0] = in[0] * xd + in[2];
    pix[1] = in[1] * yd + in[3];
}

/* In place Cholesky of the n x n SPD matrix A (lower triangle); 0 if not
 * positive definite. */
static int cholesky(double *A, int n)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double d = A[j * n + j];
        for (k = 0; k < j; k++)
            d -= A[j * n + k] * A[j * n + k];
        if (!(d > 0))
            return 0;
        A[j * n + j] = sqrt(d);
        for (i = j + 1; i < n; i++) {
            double s = A[i * n + j];
            for (k = 0; k < j; k++)
                s -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = s / A[j * n + j];
        }
    }
    return 1;
}

/* 1-sigma of each of the first n_est intrinsics for unit corner noise
 * (per coordinate), the other intrinsics held at zero as the tool holds
 * them. Views: the first n_views poses of g_poses. */
static int crb_sigma(int n_est, int n_views, double sigma[N_INTR])
{
    const double truth[N_INTR] = {g_cam.fx, g_cam.fy, g_cam.cx, g_cam.cy, g_cam.k1, g_cam.k2,
                                  0, 0, 0};
    int n = n_est + 6 * n_views, v, i, j, k, q;
    double *N = calloc((size_t)n * (size_t)n, sizeof *N), *x = malloc(sizeof *x * (size_t)n);
    int ok = N && x;

    for (v = 0; ok && v < n_views; v++) {
        double pose[6];
        memcpy(pose, g_poses[v].rvec, sizeof g_poses[v].rvec);
        memcpy(pose + 3, g_poses[v].t, sizeof g_poses[v].t);
        for (j = 0; j < g_board.rows; j++)
            for (i = 0; i < g_board.cols; i++) {
                double X = i * g_board.square, Y = j * g_board.square;
                double J[2][N_INTR + 6];   /* d(u, v) / d(intrinsics, pose) */
                int idx[N_INTR + 6], m = 0;
                /* Central differences; steps ~1e-6 of each parameter's
                 * scale keep truncation (h^2) and rounding (eps / h) far
                 * below the 1e-3 relative accuracy a tolerance needs. */
                for (k = 0; k < n_est + 6; k++) {
                    double in[N_INTR], ps[6], a[2], b[2], h;
                    double *p;
                    memcpy(in, truth, sizeof in);
                    memcpy(ps, pose, sizeof ps);
                    p = k < n_est ? &in[k] : &ps[k - n_est];
                    h = 1e-6 * (fabs(*p) > 1 ? fabs(*p) : 1);
                    *p += h;
                    project_full(in, ps, X, Y, a);
                    *p -= 2 * h;
                    project_full(in, ps, X, Y, b);
                    J[0][m] = (a[0] - b[0]) / (2 * h);
                    J[1][m] = (a[1] - b[1]) / (2 * h);
                    idx[m++] = k < n_est ? k : n_est + 6 * v + (k - n_est);
                }
                for (q = 0; q < 2; q++) {
                    int a, b;
                    for (a = 0; a < m; a++)
                        for (b = 0; b < m; b++)
                            N[idx[a] * n + idx[b]] += J[q][a] * J[q][b];
                }
            }
    }
    ok = ok && cholesky(N, n);
    /* Cov = N^-1: its diagonal entry k is |L^-1 e_k|^2 only for k = n-1,
     * so solve L L^T x = e_k for each wanted k. */
    for (k = 0; ok && k < n_est; k++) {
        for (i = 0; i < n; i++) {               /* L y = e_k */
            double s = i == k ? 1.0 : 0.0;
            for (j = 0; j < i; j++)
                s -= N[i * n + j] * x[j];
            x[i] = s / N[i * n + i];
        }
        for (i = n - 1; i >= 0; i--) {          /* L^T x = y */
            double s = x[i];
            for (j = i + 1; j < n; j++)
                s -= N[j * n + i] * x[j];
            x[i] = s / N[i * n + i];
        }
        sigma[k] = sqrt(x[k]);
    }
    free(N);
    free(x);
    return ok;
}

/* ------------------------------------------------------------------------
 * Fixture: every input file, rendered once.
 * ---------------------------------------------------------------------- */

static int render_view_noise(const br_camera *cam, const br_pose *p, const char *file,
                             int maxval, uint64_t seed, double noise)
{
    double *img = malloc(sizeof *img * (size_t)cam->width * (size_t)cam->height);
    br_rng rng;
    int ok;
    if (!img)
        return 0;
    br_rng_seed(&rng, seed);
    ok = br_render(cam, &g_board, p, img) &&
         br_write_pgm(file, img, cam->width, cam->height, noise, &rng, maxval);
    free(img);
    return ok;
}

static int render_view(const br_camera *cam, const br_pose *p, const char *file, int maxval,
                       uint64_t seed)
{
    return render_view_noise(cam, p, file, maxval, seed, NOISE);
}

/* Noise draws of the 12 views for test_spread_over_seeds: draw 0 is
 * views/ (seeds 1000 + v), draw s > 0 is seeds/sS/ (seeds 1000 + 100 s +
 * v). Eight draws: the bands on a mean over them are derived there. */
#define N_DRAWS 8

/* View v of the true camera, rendered once and written with every draw's
 * noise. */
static int render_view_draws(int v, int maxval)
{
    double *img = malloc(sizeof *img * (size_t)g_cam.width * (size_t)g_cam.height);
    br_rng rng;
    int ok, s;
    if (!img)
        return 0;
    ok = br_render(&g_cam, &g_board, &g_poses[v], img);
    for (s = 0; ok && s < N_DRAWS; s++) {
        br_rng_seed(&rng, 1000 + 100 * (uint64_t)s + (uint64_t)v);
        ok = br_write_pgm(s ? path("seeds/s%d/v%02d.pgm", s, v) : path("views/v%02d.pgm", v), img,
                          g_cam.width, g_cam.height, NOISE, &rng, maxval);
    }
    free(img);
    return ok;
}

/* Views 12 and 13 of the outlier-floor test: good views of the true camera
 * (poses of views 5 and 7) through three times the noise, as from a
 * darker part of the room: their corners are noisier (0.05-0.07 px RMS
 * against the others' 0.02, the case), but they fit the true
 * camera. */
#define NOISY_FACTOR 4.0

static int make_dir(const char *p)
{
    return mkdir(p, 0777) == 0 || errno == EEXIST;
}

static int setup_failed(const char *what)
{
    fprintf(stderr, "test_calib: setup: cannot make %s in %s (%s)\n", what, g_work,
            errno ? strerror(errno) : "view out of the image");
    return -1;
}

static int setup(void **state)
{
    int v;
    (void)state;
    const char *meta = " \t'\"\\$`*?[;&|<>()";
    if (strpbrk(g_work, meta) || strpbrk(g_bin, meta) || strpbrk(g_tool, meta)) {
        fprintf(stderr, "test_calib: paths with shell metacharacters are not supported\n");
        return -1;
    }
    if (!make_dir(g_work) || !make_dir(path("views")) || !make_dir(path("extra")) ||
        !make_dir(path("bad")) || !make_dir(path("bad/adir")) || !make_dir(path("out")))
        return setup_failed("the work directories");
    if (!make_dir(path("seeds")))
        return setup_failed("the work directories");
    for (v = 1; v < N_DRAWS; v++)
        if (!make_dir(path("seeds/s%d", v)))
            return setup_failed("the work directories");

    for (v = 0; v < N_VIEWS; v++) {
        if (!place_view(&g_views[v], &g_poses[v])) {
            fprintf(stderr, "test_calib: view %d of the table is not visible\n", v);
            return -1;
        }
        /* Every third view as 12-bit data in 16-bit words, like Mono12
         * frames recorded by cdspd. */
        if (!render_view_draws(v, v % 3 == 2 ? 4095 : 255))
            return setup_failed("a view");
    }

    {
        /* An outlier: view 0's pose seen by another camera (focal 4 %
         * longer, half the distortion): its corners fit no calibration of
         * the others. */
        br_camera other = g_cam;
        other.fx *= 1.04;
        other.fy *= 1.04;
        other.k1 *= 0.5;
        if (!br_visible(&other, &g_board, &g_poses[0], 8) ||
            !render_view(&other, &g_poses[0], path("extra/outlier.pgm"), 255, 77))
            return setup_failed("the outlier view");
    }
    if (!make_dir(path("noisy")) ||
        !render_view_noise(&g_cam, &g_poses[5], path("noisy/v12.pgm"), 255, 2012,
                           NOISY_FACTOR * NOISE) ||
        !render_view_noise(&g_cam, &g_poses[7], path("noisy/v13.pgm"), 255, 2013,
                           NOISY_FACTOR * NOISE))
        return setup_failed("the noisy views");
    {
        /* A board at another image size. */
        br_camera small = g_cam;
        br_pose p;
        small.width = 800;
        small.height = 600;
        small.cx = 399.5;
        small.cy = 299.5;
        small.fx = small.fy = 900;
        pose_at(&g_views[0], 0, &p);
        if (!br_visible(&small, &g_board, &p, 8) ||
            !render_view(&small, &p, path("extra/small.pgm"), 255, 78))
            return setup_failed("the 800x600 view");
    }
    {
        /* Boards out of view: background and noise only. */
        br_pose away = {{0, 0, 0}, {0, 0, -1000}};
        for (v = 0; v < 3; v++)
            if (!render_view(&g_cam, &away, path("extra/blank%d.pgm", v), 255, 90 + (uint64_t)v))
                return setup_failed("a blank view");
    }
    {
        /* Unreadable files. */
        unsigned char junk[4096];
        char *pgm = slurp(path("views/v00.pgm"));
        size_t i;
        uint64_t s = 5;
        for (i = 0; i < sizeof junk; i++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            junk[i] = (unsigned char)(s >> 56);
        }
        if (!pgm || !write_bytes(path("bad/garbage.png"), junk, sizeof junk) ||
            !write_bytes(path("bad/truncated.pgm"), pgm, 1024 * 300) ||
            !write_bytes(path("bad/empty.pgm"), "", 0)) {
            free(pgm);
            return setup_failed("the unreadable files");
        }
        free(pgm);
    }
    return 0;
}

/* ------------------------------------------------------------------------
 * Recovery.
 * ---------------------------------------------------------------------- */

/* The projection matrix getOptimalNewCameraMatrix(K, D, size, alpha = 0)
 * returns, recomputed here the way OpenCV 4 does it (calib3d
 * getUndistortRectangles): a 9 x 9 grid of float points x w / 8, y h / 8
 * (0 to w, not w - 1), undistorted by undistortPoints' default 5
 * fixed-point iterations into normalized coordinates, rounded to float;
 * the inner rectangle is the largest x of the left column, the smallest of
 * the right one, likewise in y; P maps that rectangle onto the image:
 * f' = (w - 1) / its width (a float), c' = -f' x0. out: fx', cx', fy',
 * cy'. (The other three combinations of grid span and numerator miss by
 * 0.5-2.9 px, measured.) */
static void alpha0_projection(const camera_info *ci, double out[4])
{
    const int n = 9;
    const double *K = ci->K, *k = ci->D;   /* k1 k2 p1 p2 k3 */
    float ix0 = -FLT_MAX, ix1 = FLT_MAX, iy0 = -FLT_MAX, iy1 = FLT_MAX;
    int i, j, it;
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            double u = (float)((double)i * ci->width / (n - 1));
            double v = (float)((double)j * ci->height / (n - 1));
            double x0 = (u - K[2]) / K[0], y0 = (v - K[5]) / K[4], x = x0, y = y0;
            for (it = 0; it < 5; it++) {
                double r2 = x * x + y * y;
                double icd = 1 / (1 + ((k[4] * r2 + k[1]) * r2 + k[0]) * r2);
                double dx = 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x);
                double dy = k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y;
                x = (x0 - dx) * icd;
                y = (y0 - dy) * icd;
            }
            if (i == 0)
                ix0 = fmaxf(ix0, (float)x);
            if (i == n - 1)
                ix1 = fminf(ix1, (float)x);
            if (j == 0)
                iy0 = fmaxf(iy0, (float)y);
            if (j == n - 1)
                iy1 = fminf(iy1, (float)y);
        }
    out[0] = (ci->width - 1) / (double)(float)(ix1 - ix0);
    out[1] = -out[0] * ix0;
    out[2] = (ci->height - 1) / (double)(float)(iy1 - iy0);
    out[3] = -out[2] * iy0;
}

/* The checks every successful calibration of the 12 views must pass.
 * Intrinsics: within 5 Cramer-Rao sigmas (crb_sigma, scaled by the corner
 * noise the RMS implies), like the distortion; fx, fy, cx, cy also within
 * the figures (0.2 %, 1 px), which are requirements on the
 * product, not tolerances. A 5-sigma band on one sample is derived from
 * the distribution (probability 6e-7 per parameter), and is wide for the
 * sample at hand: measured 0.38 / 0.48 / 0.02 / 0.11 sigma (fx fy cx cy,
 * paper model), 0.14 / 0.07 / 0.58 / 0.15 (full model), k1 k2 0.2-0.4
 * sigma. That the sigmas themselves are right, and that no systematic
 * error hides under them, is test_spread_over_seeds's check over eight
 * noise draws. RMS under 0.1 px: the figure, measured 0.0204 px
 * (5x). */
static void check_recovery(const camera_info *ci, int full_model)
{
    double sig[N_INTR], sc = ci->rms / sqrt(2.0), Pw[4];
    const double truth[9] = {g_cam.fx, g_cam.fy, g_cam.cx, g_cam.cy, g_cam.k1, g_cam.k2, 0, 0, 0};
    const double got[9] = {ci->K[0], ci->K[4], ci->K[2], ci->K[5], ci->D[0], ci->D[1],
                           ci->D[2], ci->D[3], ci->D[4]};
    const char *name[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
    int n_est = full_model ? 9 : 6, i;

    assert_int_equal(ci->width, g_cam.width);
    assert_int_equal(ci->height, g_cam.height);
    assert_string_equal(ci->model, "plumb_bob");
    assert_true(ci->rms > 0);
    assert_true(ci->rms < 0.1);

    /* K: [fx 0 cx; 0 fy cy; 0 0 1], zero skew. */
    assert_true(ci->K[1] == 0 && ci->K[3] == 0 && ci->K[6] == 0 && ci->K[7] == 0 &&
                ci->K[8] == 1);
    print_message("fx %.4f (true %.4f, %.4f %%), fy %.4f (true %.4f, %.4f %%)\n", ci->K[0],
                  g_cam.fx, 100 * fabs(ci->K[0] / g_cam.fx - 1), ci->K[4], g_cam.fy,
                  100 * fabs(ci->K[4] / g_cam.fy - 1));
    assert_true(fabs(ci->K[0] / g_cam.fx - 1) < 0.002 && fabs(ci->K[4] / g_cam.fy - 1) < 0.002);
    assert_true(fabs(ci->K[2] - g_cam.cx) < 1.0 && fabs(ci->K[5] - g_cam.cy) < 1.0);

    assert_true(crb_sigma(n_est, N_VIEWS, sig));
    print_message("Cramer-Rao 1-sigma at corner noise %.4f px: fx %.3g fy %.3g cx %.3g cy %.3g\n",
                  sc, sc * sig[0], sc * sig[1], sc * sig[2], sc * sig[3]);
    for (i = 0; i < 9; i++) {
        double e = fabs(got[i] - truth[i]);
        if (i >= 6 && !full_model) {
            /* The paper's model: p1, p2, k3 fixed at exactly zero. */
            assert_true(got[i] == 0.0);
            continue;
        }
        print_message("%s %.6f (true %.6f): error %.3g = %.2f sigma, tolerance 5 sigma = %.3g\n",
                      name[i], got[i], truth[i], e, e / (sc * sig[i]), 5 * sc * sig[i]);
        assert_true(e < 5 * sc * sig[i]);
    }

    /* rectification: identity; projection: OpenCV's alpha = 0 camera
     * matrix of the K and D written beside it, and a zero fourth column.
     * Recomputed by alpha0_projection from the YAML's own 17-digit K and D
     * with OpenCV's float roundings, so what is left is a float rounding
     * that falls the other way (OpenCV's order of operations): one ulp of
     * an edge of the ~0.97 x 0.73 inner rectangle (6e-8) moves f' by
     * 6.5e-5 px and c' by 3.3e-5 px; bound 2 ulps of both edges, 3e-4 px;
     * measured 9.3e-6 / 4.1e-5 px (paper / full model: no ulp flipped).
     * It was |P / K - 1| < 0.2, which any focal in 0.8-1.2 f passed. */
    for (i = 0; i < 9; i++)
        assert_true(ci->R[i] == (i % 4 == 0 ? 1.0 : 0.0));
    assert_true(ci->P[3] == 0 && ci->P[7] == 0 && ci->P[11] == 0);
    assert_true(ci->P[8] == 0 && ci->P[9] == 0 && ci->P[10] == 1);
    assert_true(ci->P[1] == 0 && ci->P[4] == 0);
    alpha0_projection(ci, Pw);
    print_message("projection fx' %.6f cx' %.6f fy' %.6f cy' %.6f; alpha = 0 rule: %.6f %.6f %.6f %.6f; "
                  "worst difference %.3g px\n", ci->P[0], ci->P[2], ci->P[5], ci->P[6], Pw[0], Pw[1],
                  Pw[2], Pw[3],
                  fmax(fmax(fabs(ci->P[0] - Pw[0]), fabs(ci->P[2] - Pw[1])),
                       fmax(fabs(ci->P[5] - Pw[2]), fabs(ci->P[6] - Pw[3]))));
    assert_true(fabs(ci->P[0] - Pw[0]) < 3e-4 && fabs(ci->P[2] - Pw[1]) < 3e-4 &&
                fabs(ci->P[5] - Pw[2]) < 3e-4 && fabs(ci->P[6] - Pw[3]) < 3e-4);
}

static void test_recovers_paper_model(void **state)
{
    run_result r;
    camera_info ci;
    char *yaml;
    int v;
    (void)state;
    remove(path("out/k1k2.yaml"));
    r = run_calib("--board 9x6 --square 30 --camera-name bench_cam -o %s --overlay %s "
                  "--coverage %s '%s'",
                  path("out/k1k2.yaml"), path("out/overlay"), path("out/coverage.png"),
                  path("views/*.pgm"));
    fputs(r.out, stdout);
    assert_int_equal(r.status, 0);
    /* A clean run says nothing on stderr: no warning, no OpenCV chatter. */
    assert_string_equal(r.err, "");
    assert_int_equal(count_lines_with(r.out, ".pgm", " used"), N_VIEWS);
    assert_non_null(strstr(r.out, "RMS reprojection error"));

    yaml = slurp(path("out/k1k2.yaml"));
    assert_non_null(yaml);
    assert_true(parse_camera_info(yaml, &ci));
    free(yaml);
    assert_string_equal(ci.name, "bench_cam");
    assert_int_equal(ci.n_used, N_VIEWS);
    assert_int_equal(ci.n_given, N_VIEWS);
    check_recovery(&ci, 0);

    for (v = 0; v < N_VIEWS; v++)
        assert_true(is_png(path("out/overlay/v%02d.png", v)));
    assert_true(is_png(path("out/coverage.png")));
    run_free(&r);
}

static void test_recovers_full_model_to_stdout(void **state)
{
    run_result r;
    camera_info ci;
    (void)state;
    /* No -o: the YAML on stdout, the report on stderr. */
    r = run_calib("--full-model -b 9x6 -s 30 %s", path("views/v*.pgm"));
    assert_int_equal(r.status, 0);
    assert_true(parse_camera_info(r.out, &ci));
    assert_string_equal(ci.name, "camera");
    assert_int_equal(ci.n_used, N_VIEWS);
    assert_int_equal(count_lines_with(r.err, ".pgm", " used"), N_VIEWS);
    check_recovery(&ci, 1);
    run_free(&r);
}

static void test_rejects_outlier_and_skips(void **state)
{
    run_result r;
    camera_info ci;
    char *yaml;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s %s %s %s '%s'", path("out/outlier.yaml"),
                  path("extra/outlier.pgm"), path("extra/small.pgm"), path("extra/blank0.pgm"),
                  path("views/*.pgm"));
    fputs(r.out, stdout);
    assert_int_equal(r.status, 0);
    assert_int_equal(count_lines_with(r.out, "outlier.pgm", "REJECTED"), 1);
    assert_int_equal(count_lines_with(r.out, "small.pgm", "wrong size"), 1);
    assert_int_equal(count_lines_with(r.out, "blank0.pgm", "no board"), 1);
    assert_int_equal(count_lines_with(r.out, ".pgm", " used"), N_VIEWS);
    assert_int_equal(count_lines_with(r.out, NULL, "1 rejected"), 1);
    assert_int_equal(count_lines_with(r.err, "small.pgm", "800x600, unlike the other images (1024x768)"), 1);

    yaml = slurp(path("out/outlier.yaml"));
    assert_non_null(yaml);
    assert_true(parse_camera_info(yaml, &ci));
    free(yaml);
    assert_int_equal(ci.n_used, N_VIEWS);
    assert_int_equal(ci.n_given, N_VIEWS + 3);
    check_recovery(&ci, 0);
    run_free(&r);
}

/* The spread of the calibration over N_DRAWS noise draws of the same 12
 * views (the same poses, the same rendering: only the noise differs), the
 * paper's model. For each parameter, z = error / its Cramer-Rao sigma at
 * the run's own corner noise. If the sigmas are right and the errors are
 * noise alone, z ~ N(0, 1) in every draw, the draws independent, so over
 * 8 draws:
 *   mean z ~ N(0, 1/8): |mean z| < 3.9 / sqrt(8) = 1.38 (two-sided 1e-4):
 *     a systematic error (pixel locking, a biased corner refinement, a
 *     wrong truth) that each single 5-sigma check hides shows here;
 *   mean z^2 ~ chi2(8) / 8: within [0.058, 3.98] (1e-4 each side): the
 *     sigmas are neither 2x too small (mean z^2 4) nor 4x too large.
 * Six parameters, 12 bounds: 1.2e-3 false alarms in all for a correct
 * bound; the seeds are fixed, so the verdict is repeatable. Measured:
 * mean z +0.40 +0.36 +0.65 +0.04 -0.21 +0.62 (fx fy cx cy k1 k2), mean
 * z^2 0.44 0.43 0.97 0.32 0.26 0.52: no bias beyond the noise's, and the
 * bound a little pessimistic (RMS z 0.5-1.0: the RMS the noise is read
 * from holds some error that is not independent per corner). */
static void test_spread_over_seeds(void **state)
{
    const double truth[6] = {g_cam.fx, g_cam.fy, g_cam.cx, g_cam.cy, g_cam.k1, g_cam.k2};
    const char *name[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
    double sig[N_INTR], sz[6] = {0}, sz2[6] = {0};
    int s, i;
    (void)state;
    assert_true(crb_sigma(6, N_VIEWS, sig));
    for (s = 0; s < N_DRAWS; s++) {
        camera_info ci;
        char *yaml;
        double got[6], sc;
        if (s > 0) {
            run_result r = run_calib("-b 9x6 -s 30 -o %s '%s'", path("out/draw.yaml"),
                                     path("seeds/s%d/*.pgm", s));
            assert_int_equal(r.status, 0);
            run_free(&r);
        }
        /* draw 0: test_recovers_paper_model's calibration of views/ */
        yaml = slurp(s ? path("out/draw.yaml") : path("out/k1k2.yaml"));
        assert_non_null(yaml);
        assert_true(parse_camera_info(yaml, &ci));
        free(yaml);
        assert_int_equal(ci.n_used, N_VIEWS);
        sc = ci.rms / sqrt(2.0);
        got[0] = ci.K[0];
        got[1] = ci.K[4];
        got[2] = ci.K[2];
        got[3] = ci.K[5];
        got[4] = ci.D[0];
        got[5] = ci.D[1];
        print_message("draw %d: RMS %.4f px; z =", s, ci.rms);
        for (i = 0; i < 6; i++) {
            double z = (got[i] - truth[i]) / (sc * sig[i]);
            sz[i] += z;
            sz2[i] += z * z;
            print_message(" %s %+.2f", name[i], z);
        }
        print_message("\n");
    }
    for (i = 0; i < 6; i++) {
        double m = sz[i] / N_DRAWS, m2 = sz2[i] / N_DRAWS;
        print_message("%s over %d draws: mean z %+.3f (bound 1.38), mean z^2 %.3f (band 0.058-3.98)\n",
                      name[i], N_DRAWS, m, m2);
        assert_true(fabs(m) < 3.9 / sqrt((double)N_DRAWS));
        assert_true(m2 > 0.058 && m2 < 3.98);
    }
}

/* ------------------------------------------------------------------------
 * The calibration in use: cdsp_tool solve on simulated pipes.
 * ---------------------------------------------------------------------- */

/* Undistorted normalized radius of the image corner farthest from the
 * principal point: the largest field angle a contour point can have. */
static double max_field_radius(void)
{
    double r_max = 0;
    int c;
    for (c = 0; c < 4; c++) {
        double u = (c & 1) ? g_cam.width - 1 : 0, v = (c & 2) ? g_cam.height - 1 : 0;
        double xd = (u - g_cam.cx) / g_cam.fx, yd = (v - g_cam.cy) / g_cam.fy;
        double rd = sqrt(xd * xd + yd * yd), r = rd;
        int it;
        for (it = 0; it < 50; it++) {   /* r (1 + k1 r^2 + k2 r^4) = rd */
            double r2 = r * r;
            r -= (r * (1 + g_cam.k1 * r2 + g_cam.k2 * r2 * r2) - rd) /
                 (1 + 3 * g_cam.k1 * r2 + 5 * g_cam.k2 * r2 * r2);
        }
        if (r > r_max)
            r_max = r;
    }
    return r_max;
}

typedef struct {
    int ok;
    double point[3], dir[3], seg[2][3];
} pipe_pose;

static int json_vec3(json_object *o, const char *key, double v[3])
{
    json_object *a;
    int i;
    if (!json_object_object_get_ex(o, key, &a) || !json_object_is_type(a, json_type_array) ||
        json_object_array_length(a) != 3)
        return 0;
    for (i = 0; i < 3; i++) {
        json_object *x = json_object_array_get_idx(a, (size_t)i);
        if (!json_object_is_type(x, json_type_double) && !json_object_is_type(x, json_type_int))
            return 0;
        v[i] = json_object_get_double(x);
    }
    return 1;
}

/* n JSON Lines records of cdsp_tool solve. */
static int read_solves(const char *text, pipe_pose *p, int n)
{
    const char *line = text;
    int k = 0;
    while (line && *line && k < n) {
        json_object *o = json_tokener_parse(line), *st, *seg;
        const char *end = strchr(line, '\n');
        memset(&p[k], 0, sizeof p[k]);
        if (!o)
            return 0;
        p[k].ok = json_object_object_get_ex(o, "status", &st) &&
                  strcmp(json_object_get_string(st), "ok") == 0 &&
                  json_vec3(o, "point", p[k].point) && json_vec3(o, "direction", p[k].dir) &&
                  json_object_object_get_ex(o, "segment", &seg) &&
                  json_object_array_length(seg) == 2;
        if (p[k].ok) {
            json_object *pair = json_object_new_object();
            json_object_object_add(pair, "a", json_object_get(json_object_array_get_idx(seg, 0)));
            json_object_object_add(pair, "b", json_object_get(json_object_array_get_idx(seg, 1)));
            p[k].ok = json_vec3(pair, "a", p[k].seg[0]) && json_vec3(pair, "b", p[k].seg[1]);
            json_object_put(pair);
        }
        json_object_put(o);
        k++;
        line = end ? end + 1 : NULL;
    }
    return k == n;
}

/* The paper's accuracy metric (docs/method.md §8, Eq. 17-21): RMS distance from
 * 100 points of the segment to the line (P, v). */
static double segment_rmse(const double a[3], const double b[3], const double P[3],
                           const double v[3])
{
    double s = 0, nv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    int i, k;
    for (i = 0; i < 100; i++) {
        double t = i / 99.0, d[3], c[3];
        for (k = 0; k < 3; k++)
            d[k] = a[k] + t * (b[k] - a[k]) - P[k];
        c[0] = d[1] * v[2] - d[2] * v[1];
        c[1] = d[2] * v[0] - d[0] * v[2];
        c[2] = d[0] * v[1] - d[1] * v[0];
        s += (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / (nv * nv);
    }
    return sqrt(s / 100);
}

#define N_PIPES 6

/* Six frames of an infinite pipe (radius 8 mm, 380-490 mm away) crossing
 * the image at several angles, contours reaching the image corners where
 * the distortion is largest, rendered by cdsp_tool sim with the true
 * camera. cdsp_tool solve runs on them with the true calibration and with
 * the one cdsp_calib found (test_recovers_paper_model's). Margin: the pose
 * change the calibration's actual errors (found - true, each bounded by
 * check_recovery's 5 sigma) can cause, to first order, at distance d (the
 * far end of the visible axis):
 *   a focal error df scales the recovered distance (d = r / sin(alpha/2),
 *   alpha ~ the band's width / f): d |df| / f;
 *   a principal point error dc turns every ray by dc / f: d |dc| / f;
 *   a distortion error moves a point at undistorted field radius r by
 *   e(r) = dk1 r^3 + dk2 r^5 (normalized units, an angle): the axis
 *   sideways by d |e(r)|, and it widens a band by e'(r) = 3 dk1 r^2 +
 *   5 dk2 r^4 times its width (e(r) / r for a band across the radius),
 *   which scales the distance like a focal error: d max(|e'|, |e / r|);
 *   r up to the pipe's own largest field radius (its segment's ends plus
 *   its angular radius), where |e| and |e'| are largest.
 * The sum is a first-order upper bound, the terms' signs ignored (they
 * partly cancel: a shorter focal against a larger k2): margins 0.13-0.42
 * mm for axes measured 0.023-0.034 mm apart (4.9-13x; the widest for the
 * pipes reaching the corners, where the bound takes e' at its largest r).
 * It was the same sum with 5 sigmas for the actual errors, the image
 * corner's r for every pipe and no widening term: 1.4-1.9 mm, 40-60x.
 * Each frame: the axis found with the calibration lies within that margin
 * of the axis found with the true one, and its RMSE against the truth
 * exceeds the true calibration's by less than the margin. */
static double distortion_error_bound(double dk1, double dk2, double r_max)
{
    double worst = 0, r;
    int i;
    for (i = 1; i <= 100; i++) {   /* the terms are monotonic but for sign changes: sample */
        double e, de;
        r = r_max * i / 100;
        e = dk1 * r * r * r + dk2 * r * r * r * r * r;
        de = 3 * dk1 * r * r + 5 * dk2 * r * r * r * r;
        worst = fmax(worst, fabs(e) + fmax(fabs(de), fabs(e / r)));
    }
    return worst;
}

static void test_pipe_poses_with_calibration(void **state)
{
    const char *calibrated = path("out/k1k2.yaml");
    char cmd[8192], *text, *truth_text;
    pipe_pose with_true[N_PIPES], with_cal[N_PIPES];
    camera_info ci;
    double r, per_mm;
    json_object *truth, *frames;
    int k;
    (void)state;

    text = slurp(calibrated);
    assert_non_null(text);   /* written by test_recovers_paper_model */
    assert_true(parse_camera_info(text, &ci));
    free(text);
    r = max_field_radius();
    per_mm = fmax(fabs(ci.K[0] - g_cam.fx) / g_cam.fx, fabs(ci.K[4] - g_cam.fy) / g_cam.fy) +
             fmax(fabs(ci.K[2] - g_cam.cx), fabs(ci.K[5] - g_cam.cy)) / fmin(g_cam.fx, g_cam.fy);
    print_message("margin: %.3g mm per mm of distance from K, plus the distortion's (%.3g at the "
                  "image corner, field radius %.3f)\n", per_mm,
                  distortion_error_bound(ci.D[0] - g_cam.k1, ci.D[1] - g_cam.k2, r), r);

    snprintf(cmd, sizeof cmd,
             "%s sim --out %s --width %d --height %d --fx %.17g --fy %.17g --cx %.17g "
             "--cy %.17g --k1 %.17g --k2 %.17g --frames %d --radius 8 --point -60,-20,380 "
             "--dir 0.3,1,0.15 --turn 30 --move 25,8,20 >%s 2>&1",
             g_tool, path("pipes"), g_cam.width, g_cam.height, g_cam.fx, g_cam.fy, g_cam.cx,
             g_cam.cy, g_cam.k1, g_cam.k2, N_PIPES, path("pipes.log"));
    assert_int_equal(system(cmd), 0);

    snprintf(cmd, sizeof cmd, "%s solve --no-time --calib %s --radius 8 %s >%s 2>>%s", g_tool,
             path("pipes/camera.yaml"), path("pipes"), path("solve_true.jsonl"),
             path("pipes.log"));
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "%s solve --no-time --calib %s --radius 8 %s >%s 2>>%s", g_tool,
             calibrated, path("pipes"), path("solve_cal.jsonl"), path("pipes.log"));
    assert_int_equal(system(cmd), 0);

    text = slurp(path("solve_true.jsonl"));
    assert_non_null(text);
    assert_true(read_solves(text, with_true, N_PIPES));
    free(text);
    text = slurp(path("solve_cal.jsonl"));
    assert_non_null(text);
    assert_true(read_solves(text, with_cal, N_PIPES));
    free(text);

    truth_text = slurp(path("pipes/truth.json"));
    assert_non_null(truth_text);
    truth = json_tokener_parse(truth_text);
    free(truth_text);
    assert_non_null(truth);
    assert_true(json_object_object_get_ex(truth, "frames", &frames));
    assert_int_equal((int)json_object_array_length(frames), N_PIPES);

    for (k = 0; k < N_PIPES; k++) {
        json_object *f = json_object_array_get_idx(frames, (size_t)k);
        double P[3], v[3], far, margin, e_true, e_cal, e_diff;
        assert_true(with_true[k].ok && with_cal[k].ok);
        assert_true(json_vec3(f, "axis_point", P) && json_vec3(f, "axis_dir", v));
        far = fmax(sqrt(with_true[k].seg[0][0] * with_true[k].seg[0][0] +
                        with_true[k].seg[0][1] * with_true[k].seg[0][1] +
                        with_true[k].seg[0][2] * with_true[k].seg[0][2]),
                   sqrt(with_true[k].seg[1][0] * with_true[k].seg[1][0] +
                        with_true[k].seg[1][1] * with_true[k].seg[1][1] +
                        with_true[k].seg[1][2] * with_true[k].seg[1][2]));
        {
            /* the pipe's largest undistorted field radius: its segment's
             * ends (true pose), widened by its angular radius */
            double rk = 0;
            int e;
            for (e = 0; e < 2; e++) {
                const double *q = with_true[k].seg[e];
                rk = fmax(rk, (sqrt(q[0] * q[0] + q[1] * q[1]) + 8) / q[2]);
            }
            rk = fmin(rk, r);
            margin = far * (per_mm + distortion_error_bound(ci.D[0] - g_cam.k1, ci.D[1] - g_cam.k2, rk));
        }
        e_true = segment_rmse(with_true[k].seg[0], with_true[k].seg[1], P, v);
        e_cal = segment_rmse(with_cal[k].seg[0], with_cal[k].seg[1], P, v);
        e_diff = segment_rmse(with_cal[k].seg[0], with_cal[k].seg[1], with_true[k].point,
                              with_true[k].dir);
        print_message("pipe %d (far end %.0f mm): RMSE %.4f mm with the true calibration, "
                      "%.4f mm with cdsp_calib's; axes %.4f mm apart; margin %.3f mm\n",
                      k, far, e_true, e_cal, e_diff, margin);
        assert_true(e_diff < margin);
        assert_true(e_cal < e_true + margin);
    }
    json_object_put(truth);
}

/* Progress goes to stderr only when it is a terminal (script(1) gives the
 * run one) and there are 8 images or more. */
static void test_progress_on_terminal(void **state)
{
    char cmd[8192], *tty;
    (void)state;
    snprintf(cmd, sizeof cmd,
             "script -qec \"%s -b 9x6 -s 30 -o %s '%s' >/dev/null\" /dev/null >%s 2>&1", g_bin,
             path("out/tty.yaml"), path("views/*.pgm"), path("tty12.txt"));
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "script -qec \"%s -b 9x6 -s 30 -o %s %s %s %s >/dev/null\" /dev/null >%s 2>&1",
             g_bin, path("out/tty.yaml"), path("views/v00.pgm"), path("views/v01.pgm"),
             path("views/v02.pgm"), path("tty3.txt"));
    assert_int_equal(system(cmd), 0);
    tty = slurp(path("tty12.txt"));
    assert_non_null(tty);
    assert_non_null(strstr(tty, "corners 12/12"));
    free(tty);
    tty = slurp(path("tty3.txt"));
    assert_non_null(tty);
    assert_null(strstr(tty, "corners"));
    free(tty);
}

/* ------------------------------------------------------------------------
 * Calibration impossible: exit 1, nothing written.
 * ---------------------------------------------------------------------- */

static void test_wrong_board_size(void **state)
{
    /* One inner corner fewer, and one more, than the board has. */
    const char *sizes[] = {"8x6", "10x6", "9x5"};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        run_result r;
        remove(path("out/never.yaml"));
        r = run_calib("-b %s -s 30 -o %s '%s'", sizes[i], path("out/never.yaml"),
                      path("views/*.pgm"));
        assert_int_equal(r.status, 1);
        assert_non_null(strstr(r.err, "board was found in none of the 12 images"));
        assert_non_null(strstr(r.err, "check --board"));
        assert_int_equal(count_lines_with(r.out, ".pgm", "no board"), N_VIEWS);
        assert_false(file_exists(path("out/never.yaml")));
        run_free(&r);
    }
}

static void test_no_board_anywhere(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s '%s'", path("out/never.yaml"), path("extra/blank*.pgm"));
    assert_int_equal(r.status, 1);
    assert_non_null(strstr(r.err, "the 9x6 board was found in none of the 3 images"));
    assert_false(file_exists(path("out/never.yaml")));
    run_free(&r);
}

static void test_too_few_views(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s %s %s %s", path("out/never.yaml"),
                  path("views/v00.pgm"), path("views/v01.pgm"), path("extra/blank0.pgm"));
    assert_int_equal(r.status, 1);
    assert_non_null(strstr(r.err, "found in only 2 of the 3 images; at least 3 usable views"));
    assert_non_null(strstr(r.err, "nothing written"));
    /* the boards found are listed as found, not with errors never measured */
    assert_int_equal(count_lines_with(r.out, "v00.pgm", "board found"), 1);
    assert_int_equal(count_lines_with(r.out, "v01.pgm", "board found"), 1);
    assert_int_equal(count_lines_with(r.out, NULL, " used"), 0);
    assert_null(strstr(r.out, "0.0000"));
    assert_false(file_exists(path("out/never.yaml")));
    run_free(&r);
}

/* The numbers in column `col` (0-based, blank-separated) of the table
 * lines (naming a .pgm) that contain `what`, into v (at most 64); their
 * count in *n; the largest returned. */
static double column_values(const char *text, const char *what, int col, double *v, int *n)
{
    const char *line = text;
    double mx = 0;
    *n = 0;
    while (line && *line) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        char buf[1024];
        if (len < sizeof buf) {
            memcpy(buf, line, len);
            buf[len] = 0;
            if (strstr(buf, ".pgm") && strstr(buf, what)) {
                char *tok = strtok(buf, " ");
                int c;
                for (c = 0; tok && c < col; c++)
                    tok = strtok(NULL, " ");
                if (tok && *n < 64) {
                    v[*n] = atof(tok);
                    mx = v[*n] > mx ? v[*n] : mx;
                    (*n)++;
                }
            }
        }
        line = end ? end + 1 : NULL;
    }
    return mx;
}

/* Fourteen good views of the true camera, two of them noisier (about 3 x
 * the others' RMS error): none may be rejected. The relative rule alone
 * (--outlier-floor 0) rejects the noisy two, which shows the check can
 * fail; the floor (0.1 px, calib_core.hpp) keeps them. And --no-reject
 * keeps even the real outlier (a view from another camera). */
static void test_outlier_floor_and_no_reject(void **state)
{
    run_result r;
    int n, i, below;
    double worst, v[64], good[64], median;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s '%s' '%s'", path("out/floor.yaml"), path("views/*.pgm"),
                  path("noisy/*.pgm"));
    fputs(r.out, stdout);
    assert_int_equal(r.status, 0);
    assert_int_equal(count_lines_with(r.out, ".pgm", " used"), N_VIEWS + 2);
    assert_int_equal(count_lines_with(r.out, ".pgm", "REJECTED"), 0);
    /* the noisy views are what the issue saw: above twice the others'
     * median (the relative threshold's lower bound), below the floor */
    column_values(r.out, "views/", 3, good, &n);
    assert_int_equal(n, N_VIEWS);
    for (i = 0, median = 0; i < n; i++) { /* the median: as many below as above */
        int j;
        for (j = 0, below = 0; j < n; j++)
            below += good[j] < good[i];
        if (below == n / 2 - 1 || below == n / 2)
            median += good[i] / 2;
    }
    worst = column_values(r.out, "noisy/", 3, v, &n);
    assert_int_equal(n, 2);
    printf("good views' median RMS %.4f px; noisy views %.4f and %.4f px (floor 0.1 px)\n",
           median, v[0], v[1]);
    assert_true(v[0] > 2 * median && v[1] > 2 * median && worst < 0.1);
    run_free(&r);

    r = run_calib("-b 9x6 -s 30 --outlier-floor 0 -o %s '%s' '%s'", path("out/nofloor.yaml"),
                  path("views/*.pgm"), path("noisy/*.pgm"));
    assert_int_equal(r.status, 0);
    assert_int_equal(count_lines_with(r.out, "noisy/", "REJECTED"), 2);
    run_free(&r);

    r = run_calib("-b 9x6 -s 30 --no-reject -o %s %s '%s'", path("out/noreject.yaml"),
                  path("extra/outlier.pgm"), path("views/*.pgm"));
    assert_int_equal(r.status, 0);
    assert_int_equal(count_lines_with(r.out, "outlier.pgm", " used"), 1);
    assert_int_equal(count_lines_with(r.out, ".pgm", "REJECTED"), 0);
    run_free(&r);

    r = run_calib("-b 9x6 -s 30 --no-reject --outlier-floor 0.2 %s", path("views/v00.pgm"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "exclude each other"));
    run_free(&r);
    r = run_calib("-b 9x6 -s 30 --outlier-floor -1 %s", path("views/v00.pgm"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "--outlier-floor wants a number of pixels"));
    run_free(&r);
}

/* cdsp_calib --print-board: the board it expects, at exact scale. The
 * reader of the PNG print is cdsp_calib itself: it must find the board it
 * printed, and not a board of other corners. */
static void test_print_board(void **state)
{
    run_result r;
    char *pdf, *svg;
    (void)state;
    /* a PNG page of exactly the board: cdsp_calib finds the 9x6 board in
     * its own print (one view: "found in only 1", not "found in none") */
    r = run_calib("-b 9x6 -s 20 --print-board %s --paper fit", path("out/board.png"));
    assert_int_equal(r.status, 0);
    assert_true(is_png(path("out/board.png")));
    run_free(&r);
    r = run_calib("-b 9x6 -s 20 %s", path("out/board.png"));
    assert_int_equal(r.status, 1);
    assert_non_null(strstr(r.err, "found in only 1 of the 1 images"));
    run_free(&r);
    /* a board of other corners is not found in it */
    r = run_calib("-b 8x6 -s 20 %s", path("out/board.png"));
    assert_int_equal(r.status, 1);
    assert_non_null(strstr(r.err, "found in none"));
    run_free(&r);

    /* PDF and SVG pages in points: A4 landscape (841.89 x 595.28 pt) for a
     * 9x6 board of 24 mm squares (275 x 204 mm with its border) */
    r = run_calib("-b 9x6 -s 24 --print-board %s", path("out/board.pdf"));
    assert_int_equal(r.status, 0);
    run_free(&r);
    pdf = slurp(path("out/board.pdf"));
    assert_non_null(pdf);
    assert_int_equal(memcmp(pdf, "%PDF-", 5), 0);
    {
        /* binary streams hold NUL bytes: search the whole file */
        static const char box[] = "/MediaBox [ 0 0 841.889764 595.275591 ]";
        struct stat st;
        size_t k, found = 0;
        assert_int_equal(stat(path("out/board.pdf"), &st), 0);
        for (k = 0; k + sizeof box - 1 <= (size_t)st.st_size && !found; k++)
            found = memcmp(pdf + k, box, sizeof box - 1) == 0;
        assert_true(found);
    }
    free(pdf);
    r = run_calib("-b 9x6 -s 24 --print-board %s --paper letter", path("out/board.svg"));
    assert_int_equal(r.status, 0);
    run_free(&r);
    svg = slurp(path("out/board.svg"));
    assert_non_null(svg);
    assert_non_null(strstr(svg, "width=\"792pt\" height=\"612pt\""));
    /* 10 x 7 squares, 35 of them black: cairo writes the fill as one path
     * of closed subpaths "M x0 y0 L x1 y0 L x1 y1 L x0 y1 Z" in points,
     * each coordinate rounded to cairo's 1/256 pt fixed point. Every side
     * is 24 mm = 68.0315 pt within 2/256 pt (two roundings), and every
     * square sits on the grid of the first one. */
    {
        /* the squares' path among the glyphs' (each path tried in turn) */
        const char *d = svg;
        int found = 0;
        double side = 24.0 * 72.0 / 25.4;
        while (!found && (d = strstr(d, "d=\"")) != NULL) {
            double first[2] = {0, 0};
            int n = 0, bad = 0;
            d += 3;
            for (;;) {
                double x0, y0, x1, y1, x2, y2, x3, y3, gx, gy;
                int used = 0;
                if (sscanf(d, " M %lf %lf L %lf %lf L %lf %lf L %lf %lf Z%n", &x0, &y0, &x1,
                           &y1, &x2, &y2, &x3, &y3, &used) != 8 || used == 0)
                    break;
                d += used;
                if (n == 0) {
                    first[0] = x0;
                    first[1] = y0;
                }
                gx = (x0 - first[0]) / side;
                gy = (y0 - first[1]) / side;
                bad |= fabs(x1 - x0 - side) > 2.0 / 256 || fabs(y2 - y1 - side) > 2.0 / 256 ||
                       y1 != y0 || x2 != x1 || x3 != x0 || y3 != y2 ||
                       fabs(gx - floor(gx + 0.5)) * side > 2.0 / 256 ||
                       fabs(gy - floor(gy + 0.5)) * side > 2.0 / 256 ||
                       /* black squares alternate: (i + j) even from the first */
                       ((long)floor(gx + 0.5) + (long)floor(gy + 0.5)) % 2 != 0;
                n++;
            }
            found = n == 35 && !bad;
        }
        assert_true(found);
    }
    free(svg);

    /* errors: too big for the paper, unknown format, no directory */
    r = run_calib("-b 9x6 -s 25 --print-board %s", path("out/big.pdf"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "more than the paper"));
    assert_false(file_exists(path("out/big.pdf")));
    run_free(&r);
    r = run_calib("-b 9x6 -s 20 --print-board %s", path("out/board.txt"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "unknown format"));
    run_free(&r);
    r = run_calib("-b 9x6 -s 20 --print-board %s", path("nodir/board.pdf"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "--print-board"));
    run_free(&r);
    r = run_calib("-b 9x6 -s 20 --print-board %s %s", path("out/b2.pdf"), path("views/v00.pgm"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "takes no images"));
    run_free(&r);
}

/* ------------------------------------------------------------------------
 * Usage and unreadable inputs: exit 2.
 * ---------------------------------------------------------------------- */

static void test_unreadable_inputs(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s %s %s %s %s %s %s", path("out/never.yaml"),
                  path("views/v00.pgm"), path("bad/missing.pgm"), path("bad/garbage.png"),
                  path("bad/truncated.pgm"), path("bad/empty.pgm"), path("bad/adir"));
    assert_int_equal(r.status, 2);
    assert_int_equal(count_lines_with(r.err, "missing.pgm", "No such file or directory"), 1);
    assert_int_equal(count_lines_with(r.err, "garbage.png", "not an image OpenCV can decode"), 1);
    assert_int_equal(count_lines_with(r.err, "truncated.pgm", "not an image OpenCV can decode"), 1);
    assert_int_equal(count_lines_with(r.err, "empty.pgm", "empty file"), 1);
    assert_int_equal(count_lines_with(r.err, "adir", "is a directory"), 1);
    assert_non_null(strstr(r.err, "5 of 6 images could not be read; nothing written"));
    assert_false(file_exists(path("out/never.yaml")));
    run_free(&r);
}

static void test_no_images(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("-b 9x6 -s 30");
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "no images given"));
    run_free(&r);

    r = run_calib("-b 9x6 -s 30 '%s'", path("views/*.png"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "no file matches"));
    assert_non_null(strstr(r.err, "views/*.png"));
    run_free(&r);
}

static void test_usage_errors(void **state)
{
    static const struct {
        const char *args;
        const char *says;
    } cases[] = {
        {"-s 30 x.pgm", "--board COLSxROWS is required"},
        {"-b 9x6 x.pgm", "--square SIZE is required"},
        {"-b 9 -s 30 x.pgm", "--board wants COLSxROWS"},
        {"-b 9x6x -s 30 x.pgm", "--board wants COLSxROWS"},
        {"-b 9x-6 -s 30 x.pgm", "--board wants COLSxROWS"},
        {"-b 2x6 -s 30 x.pgm", "each count must be 3..1000"},
        {"-b 9x6 -s 0 x.pgm", "--square wants a positive number"},
        {"-b 9x6 -s -3 x.pgm", "--square wants a positive number"},
        {"-b 9x6 -s 3mm x.pgm", "--square wants a positive number"},
        {"-b 9x6 -s nan x.pgm", "--square wants a positive number"},
        {"-b 9x6 -s 30 --camera-name 9cam x.pgm", "--camera-name '9cam'"},
        {"-b 9x6 -s 30 --camera-name 'a b' x.pgm", "--camera-name 'a b'"},
        {"-b 9x6 -s 30 --coverage cov.txt x.pgm", "--coverage cov.txt"},
        {"-b 9x6 -s 30 --bogus x.pgm", "unknown option '--bogus'"},
        {"-b 9x6 -s 30 -o", "wants a value"},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run_result r = run_calib("%s", cases[i].args);
        assert_int_equal(r.status, 2);
        if (!strstr(r.err, cases[i].says))
            fail_msg("'%s': stderr lacks \"%s\": %s", cases[i].args, cases[i].says, r.err);
        assert_non_null(strstr(r.err, "Try 'cdsp_calib --help'"));
        run_free(&r);
    }
}

static void test_unwritable_outputs(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("-b 9x6 -s 30 -o %s %s", path("nowhere/c.yaml"), path("views/v00.pgm"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "nowhere: No such file or directory"));
    run_free(&r);

    /* The YAML on a full standard output. */
    {
        char cmd[8192], *err;
        snprintf(cmd, sizeof cmd, "%s -b 9x6 -s 30 %s %s %s >/dev/full 2>%s", g_bin,
                 path("views/v00.pgm"), path("views/v01.pgm"), path("views/v02.pgm"),
                 path("full.err"));
        r.status = system(cmd);
        assert_true(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 2);
        err = slurp(path("full.err"));
        assert_non_null(err);
        assert_non_null(strstr(err, "cannot write the calibration to standard output"));
        free(err);
    }

    /* --overlay on an existing file, not a directory. */
    r = run_calib("-b 9x6 -s 30 --overlay %s %s", path("views/v00.pgm"), path("views/v01.pgm"));
    assert_int_equal(r.status, 2);
    assert_non_null(strstr(r.err, "--overlay"));
    assert_non_null(strstr(r.err, "v00.pgm is not a directory"));
    run_free(&r);
}

static void test_help(void **state)
{
    run_result r;
    (void)state;
    r = run_calib("--help");
    assert_int_equal(r.status, 0);
    assert_string_equal(r.err, "");
    assert_non_null(strstr(r.out, "SYNOPSIS"));
    assert_non_null(strstr(r.out, "EXIT STATUS"));
    assert_non_null(strstr(r.out, "--full-model"));
    run_free(&r);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_help),
        cmocka_unit_test(test_recovers_paper_model),
        cmocka_unit_test(test_recovers_full_model_to_stdout),
        cmocka_unit_test(test_spread_over_seeds),
        cmocka_unit_test(test_pipe_poses_with_calibration),
        cmocka_unit_test(test_rejects_outlier_and_skips),
        cmocka_unit_test(test_progress_on_terminal),
        cmocka_unit_test(test_wrong_board_size),
        cmocka_unit_test(test_no_board_anywhere),
        cmocka_unit_test(test_too_few_views),
        cmocka_unit_test(test_outlier_floor_and_no_reject),
        cmocka_unit_test(test_print_board),
        cmocka_unit_test(test_unreadable_inputs),
        cmocka_unit_test(test_no_images),
        cmocka_unit_test(test_usage_errors),
        cmocka_unit_test(test_unwritable_outputs),
    };
    if (argc != 4) {
        fprintf(stderr, "usage: test_calib PATH/TO/cdsp_calib PATH/TO/cdsp_tool WORKDIR\n");
        return 2;
    }
    g_bin = argv[1];
    g_tool = argv[2];
    g_work = argv[3];
    return cmocka_run_group_tests_name("calib", tests, setup, NULL);
}
