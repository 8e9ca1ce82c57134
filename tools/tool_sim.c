/*
 * tool_sim.c - `cdsp_tool sim`: frames of a simulated pipe of known pose
 * (libcdsp's cdsp_render: exact area anti-aliasing, lens distortion, blur,
 * sensor noise), the matching calibration YAML and a ground-truth JSON, so
 * that anyone can try `solve` without a camera. --preset paper renders the
 * four pipes of the paper's simulation (docs/method.md).
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *out, *calib, *prefix;
    int preset, frames, width, height, bits, format;
    double fx, fy, cx, cy, k1, k2, p1, p2, k3;
    double point[3], dir[3], move[3], radius, length, turn;
    double pipe_level, background_level, noise, blur, texture, ambient;
    uint64_t seed;
    int pipes;      /* --pipes: a rack of this many parallel pipes */
    double spacing; /* --spacing: their axes' spacing (0: 3 R) */
} sim_opts;

static const char sim_description[] =
    "    Renders simulated frames of a straight pipe (a finite or infinite\n"
    "    cylinder) seen by a pinhole camera with plumb_bob distortion, and writes\n"
    "    into DIR:\n"
    "      PREFIX_0000.pgm ...   the frames (or .png with --format png)\n"
    "      camera.yaml           the calibration, ROS camera_info YAML\n"
    "      truth.json            the ground truth of every frame\n"
    "    so that `cdsp_tool solve --calib DIR/camera.yaml --radius R DIR` can be\n"
    "    compared with DIR/truth.json.\n"
    "\n"
    "    The pipe is given in camera coordinates (X right, Y down, Z forward, the\n"
    "    unit of R): a point on its axis and a direction. With --frames N > 1 the\n"
    "    pipe moves by --move per frame and its direction turns by --turn degrees\n"
    "    per frame about the optical axis, a sequence for solve --track. Each\n"
    "    frame's sensor noise comes from its own random stream, so frame k is the\n"
    "    same whatever N is.\n"
    "\n"
    "    --preset paper renders the paper's simulation instead (Yao et al. 2024,\n"
    "    docs/method.md): a 2448 x 2048 camera with 3.45 um pixels and f = 12 mm\n"
    "    (fx = fy = 3478.26 px), principal point at the centre, no distortion;\n"
    "    four pipes of radius 8 mm and length 500 mm in the world plane Z_W = 0\n"
    "    (p1 along X_W through the origin, p2 = p1 moved -100 mm along Y_W, p3\n"
    "    along Y_W, p4 = p3 moved -100 mm along X_W) seen from world (150, 200,\n"
    "    300) mm looking at the origin, one frame each. Camera, pipe and\n"
    "    --frames options are then ignored; image options still apply.\n\n";

static const char sim_after[] =
    "OUTPUT\n"
    "    truth.json is one JSON object:\n"
    "      calibration  \"camera.yaml\"\n"
    "      radius       R\n"
    "      frames       one object per frame:\n"
    "        frame        its index, from 0 (solve's \"frame\" of it)\n"
    "        file         the file name, in DIR\n"
    "        pipe         \"p1\" .. \"p4\" with --preset paper\n"
    "        axis_point, axis_dir, half_length   the simulated cylinder\n"
    "        point, direction, distance          what solve should report: the\n"
    "                     foot of the perpendicular from the optical centre, the\n"
    "                     unit direction (largest component > 0), its distance\n"
    "        lines        the exact contour lines, undistorted pixels, as solve\n"
    "                     reports them (null if the pipe is not in front)\n"
    "\n"
    "EXAMPLES\n"
    "    cdsp_tool sim --out sim1\n"
    "    cdsp_tool solve --calib sim1/camera.yaml --radius 8 sim1\n"
    "    cdsp_tool sim --out seq --frames 50 --move 0.5,0,0 --turn 0.2 --noise 0.01\n"
    "    cdsp_tool sim --out paper --preset paper --format png\n";

static const char sim_exit[] =
    "    0  all frames and files written\n"
    "    1  some frame could not be rendered (pipe behind the camera, camera\n"
    "       inside the pipe)\n"
    "    2  usage error, an unreadable --calib file, or a file that could not be\n"
    "       written\n";

static void rotate_z(double v[3], double deg)
{
    double a = deg * 3.14159265358979323846 / 180.0, c = cos(a), s = sin(a);
    double x = c * v[0] - s * v[1], y = s * v[0] + c * v[1];
    v[0] = x;
    v[1] = y;
}

static void json_vec(cdsp_host_json *j, const char *key, const double *v, int n)
{
    int i;
    cdsp_host_json_key(j, key);
    cdsp_host_json_begin_array(j);
    for (i = 0; i < n; i++)
        cdsp_host_json_number(j, v[i]);
    cdsp_host_json_end_array(j);
}

/* The rack's further pipes: copies of the first moved by k * spacing along
 * s = dir x point (perpendicular to the axis and the line of sight). */
static void rack_place(cdsp_scene *sc, const double point[3], const double dir[3], double spacing)
{
    double s[3], n;
    int i, q;
    s[0] = dir[1] * point[2] - dir[2] * point[1];
    s[1] = dir[2] * point[0] - dir[0] * point[2];
    s[2] = dir[0] * point[1] - dir[1] * point[0];
    n = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(n > 0)) {
        s[0] = 1; /* looking along the axis: any side will do */
        s[1] = s[2] = 0;
        n = 1;
    }
    for (i = 0; i < sc->n_extra_pipes; i++) {
        for (q = 0; q < 3; q++) {
            sc->extra_pipe[i].axis_point[q] = (cdsp_real)(point[q] + (i + 1) * spacing * s[q] / n);
            sc->extra_pipe[i].axis_dir[q] = (cdsp_real)dir[q];
        }
        sc->extra_pipe[i].radius = sc->radius;
        sc->extra_pipe[i].half_length = sc->half_length;
    }
}

int tool_sim_main(int argc, char **argv)
{
    sim_opts o;
    cdsp_scene scene;
    cdsp_camera cam;
    cdsp_host_err err;
    cdsp_host_image img;
    char **pos, path[4200];
    char *truth = NULL;
    size_t truth_cap;
    float *scratch = NULL;
    size_t scratch_len;
    int npos = 0, rc, k, n_frames, failed = 0;
    cdsp_host_json j;
    tool_progress prog;
    FILE *f;
    static const tool_doc doc = {
        "sim", "simulated frames of a known pipe, calibration, ground truth",
        "--out DIR [OPTIONS]", sim_description, sim_after, sim_exit};

    memset(&o, 0, sizeof o);
    o.pipes = 1;
    cdsp_scene_default(&scene);
    o.prefix = "frame";
    o.frames = 1;
    o.width = 640;
    o.height = 480;
    o.fx = o.fy = 800;
    o.cx = o.cy = NAN;
    for (k = 0; k < 3; k++) {
        o.point[k] = (double)scene.axis_point[k];
        o.dir[k] = (double)scene.axis_dir[k];
    }
    o.radius = (double)scene.radius;
    o.length = 0;
    o.pipe_level = (double)scene.pipe_level;
    o.background_level = (double)scene.background_level;
    o.noise = (double)scene.noise_sigma;
    o.blur = (double)scene.blur_sigma_px;
    o.texture = (double)scene.texture;
    o.ambient = (double)scene.ambient;
    o.seed = 1;
    {
        const tool_opt opts[] = {
            {"out", 'o', OPT_STR, &o.out, 0, 0, "DIR", "Where to write (created if missing; "
             "required).", NULL, 1},
            {"preset", 0, OPT_CHOICE, &o.preset, 0, 0, NULL,
             "paper: the paper's four simulated pipes (see DESCRIPTION).", "none|paper", 0},
            {"frames", 'n', OPT_INT, &o.frames, 1, 100000, "N", "Number of frames.", NULL, 0},
            {"calib", 'c', OPT_STR, &o.calib, 0, 0, "CAM.yaml",
             "Take the camera from this calibration instead of the options below.", NULL, 1},
            {"width", 0, OPT_INT, &o.width, 16, CDSP_HOST_MAX_DIM, "W", "Image width, px.", NULL, 0},
            {"height", 0, OPT_INT, &o.height, 16, CDSP_HOST_MAX_DIM, "H", "Image height, px.",
             NULL, 0},
            {"fx", 0, OPT_REAL, &o.fx, 1, 1e6, "F", "Focal length along u, px.", NULL, 0},
            {"fy", 0, OPT_REAL, &o.fy, 1, 1e6, "F", "Focal length along v, px.", NULL, 0},
            {"cx", 0, OPT_REAL, &o.cx, -1e6, 1e6, "U",
             "Principal point u, px. Default: the image centre, (W - 1) / 2.", NULL, 1},
            {"cy", 0, OPT_REAL, &o.cy, -1e6, 1e6, "V",
             "Principal point v, px. Default: the image centre, (H - 1) / 2.", NULL, 1},
            {"k1", 0, OPT_REAL, &o.k1, -10, 10, "K", "Radial distortion r^2 coefficient.", NULL, 0},
            {"k2", 0, OPT_REAL, &o.k2, -10, 10, "K", "Radial distortion r^4 coefficient.", NULL, 0},
            {"p1", 0, OPT_REAL, &o.p1, -1, 1, "P", "Tangential distortion p1.", NULL, 0},
            {"p2", 0, OPT_REAL, &o.p2, -1, 1, "P", "Tangential distortion p2.", NULL, 0},
            {"k3", 0, OPT_REAL, &o.k3, -10, 10, "K", "Radial distortion r^6 coefficient.", NULL, 0},
            {"point", 'p', OPT_VEC3, o.point, 0, 0, "X,Y,Z",
             "A point on the pipe's axis, camera frame, unit of R.", NULL, 0},
            {"dir", 'd', OPT_VEC3, o.dir, 0, 0, "X,Y,Z",
             "The axis direction (any length but 0).", NULL, 0},
            {"radius", 'r', OPT_REAL, &o.radius, 1e-6, 1e9, "R", "The pipe's radius.", NULL, 0},
            {"length", 0, OPT_REAL, &o.length, 0, 1e12, "L",
             "The pipe's length, centred on --point; 0: infinite.", NULL, 0},
            {"move", 0, OPT_VEC3, o.move, 0, 0, "DX,DY,DZ",
             "Translation of the pipe per frame, camera frame.", NULL, 0},
            {"pipes", 0, OPT_INT, &o.pipes, 1, CDSP_RENDER_MAX_PIPES, "N",
             "A rack: N parallel pipes of the same radius and length, the first as "
             "--point and --dir say, the others beside it at multiples of --spacing "
             "(along the direction perpendicular to the axis and to the line of sight "
             "to --point); truth.json lists them as \"rack\".", NULL, 0},
            {"spacing", 0, OPT_REAL, &o.spacing, 0, 1e12, "S",
             "The rack's axis spacing (unit of R); 0: 3 R, a gap of one radius.", NULL, 0},
            {"turn", 0, OPT_REAL, &o.turn, -180, 180, "DEG",
             "Rotation of the axis direction per frame about the optical axis, degrees.",
             NULL, 0},
            {"pipe-level", 0, OPT_REAL, &o.pipe_level, 0, 1, "F",
             "Brightness of the pipe, fraction of full scale.", NULL, 0},
            {"background-level", 0, OPT_REAL, &o.background_level, 0, 1, "F",
             "Brightness of the background.", NULL, 0},
            {"ambient", 0, OPT_REAL, &o.ambient, 0, 1, "F",
             "Ambient share of the pipe's shading (1: flat).", NULL, 0},
            {"texture", 0, OPT_REAL, &o.texture, 0, 1, "F",
             "Amplitude of the background texture.", NULL, 0},
            {"blur", 0, OPT_REAL, &o.blur, 0, 20, "PX", "Gaussian optical blur sigma, px.", NULL, 0},
            {"noise", 0, OPT_REAL, &o.noise, 0, 1, "F",
             "Gaussian sensor noise sigma, fraction of full scale.", NULL, 0},
            {"bits", 0, OPT_INT, &o.bits, 8, 16, "8|16", "Bits per pixel of the frames.", NULL, 0},
            {"format", 'f', OPT_CHOICE, &o.format, 0, 0, NULL, "File format of the frames.",
             "pgm|png", 0},
            {"prefix", 0, OPT_STR, &o.prefix, 0, 0, "NAME", "Frame file names: NAME_0000.pgm ...",
             NULL, 0},
            {"seed", 0, OPT_U64, &o.seed, 0, 0, "S", "Seed of the noise and the texture.", NULL, 0},
            {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
        };
        o.bits = 8;
        rc = tool_parse_alloc("sim", &doc, opts, argc, argv, &pos, &npos);
        if (rc)
            return rc - 1;
    }
    rc = TOOL_EXIT_USAGE;
    if (npos > 0) {
        tool_usage_error("sim", "unexpected argument '%s' (see --help)", pos[0]);
        goto out;
    }
    if (!o.out) {
        tool_usage_error("sim", "--out DIR is required (see --help)");
        goto out;
    }
    if (o.bits != 8 && o.bits != 16) {
        tool_usage_error("sim", "--bits: 8 or 16");
        goto out;
    }
    if (strchr(o.prefix, '/') || !o.prefix[0]) {
        tool_usage_error("sim", "--prefix: a file name without '/'");
        goto out;
    }
    if (!(o.dir[0] != 0 || o.dir[1] != 0 || o.dir[2] != 0)) {
        tool_usage_error("sim", "--dir: the direction must not be zero");
        goto out;
    }

    /* the camera */
    if (o.preset == 1) {
        tool_paper_camera(&cam);
    } else if (o.calib) {
        if (cdsp_host_calib_read(o.calib, &cam, &err) != 0) {
            tool_usage_error("sim", "%s", err.msg);
            goto out;
        }
    } else {
        cam.width = o.width;
        cam.height = o.height;
        cam.fx = (cdsp_real)o.fx;
        cam.fy = (cdsp_real)o.fy;
        cam.cx = (cdsp_real)(isnan(o.cx) ? (o.width - 1) / 2.0 : o.cx);
        cam.cy = (cdsp_real)(isnan(o.cy) ? (o.height - 1) / 2.0 : o.cy);
        cam.k1 = (cdsp_real)o.k1;
        cam.k2 = (cdsp_real)o.k2;
        cam.p1 = (cdsp_real)o.p1;
        cam.p2 = (cdsp_real)o.p2;
        cam.k3 = (cdsp_real)o.k3;
    }
    if (cdsp_camera_check(&cam) != CDSP_OK) {
        tool_usage_error("sim", "invalid camera");
        goto out;
    }
    n_frames = o.preset == 1 ? 4 : o.frames;

    if (tool_mkdir(o.out) != 0) {
        tool_usage_error("sim", "%s: cannot create the directory: %s", o.out, strerror(errno));
        goto out;
    }
    snprintf(path, sizeof path, "%s/camera.yaml", o.out);
    if (cdsp_host_calib_write(path, &cam, o.preset == 1 ? "paper_sim" : "cdsp_sim", &err) != 0) {
        tool_usage_error("sim", "%s", err.msg);
        goto out;
    }
    if (cdsp_host_image_alloc(&img, cam.width, cam.height, o.bits, &err) != 0) {
        tool_usage_error("sim", "%s", err.msg);
        goto out;
    }
    scratch_len = cdsp_render_scratch_size(cam.width, cam.height);
    scratch = malloc((scratch_len ? scratch_len : 1) * sizeof *scratch);
    truth_cap = 4096 + (size_t)n_frames * (1600 + 400 * (size_t)o.pipes);
    truth = malloc(truth_cap);
    if (!scratch || !truth) {
        cdsp_host_image_free(&img);
        tool_usage_error("sim", "out of memory");
        goto out;
    }
    cdsp_host_json_init(&j, truth, truth_cap);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "calibration");
    cdsp_host_json_string(&j, "camera.yaml");
    cdsp_host_json_key(&j, "radius");
    cdsp_host_json_number(&j, o.preset == 1 ? 8.0 : o.radius);
    cdsp_host_json_key(&j, "frames");
    cdsp_host_json_begin_array(&j);

    scene.pipe_level = (cdsp_real)o.pipe_level;
    scene.background_level = (cdsp_real)o.background_level;
    scene.noise_sigma = (cdsp_real)o.noise;
    scene.blur_sigma_px = (cdsp_real)o.blur;
    scene.texture = (cdsp_real)o.texture;
    scene.ambient = (cdsp_real)o.ambient;
    scene.texture_seed = (uint32_t)(o.seed * 2654435761u + 1u);

    tool_progress_start(&prog, "sim", (size_t)n_frames, 0);
    for (k = 0; k < n_frames; k++) {
        double point[3], dir[3], half, foot[3], unit[3], dist;
        cdsp_real l[2][3], p_in[2];
        cdsp_rng rng;
        cdsp_status st;
        char name[300];
        int i;
        if (o.preset == 1) {
            tool_paper_pipe(k, point, dir, &half);
            scene.radius = 8;
        } else {
            for (i = 0; i < 3; i++) {
                point[i] = o.point[i] + k * o.move[i];
                dir[i] = o.dir[i];
            }
            rotate_z(dir, k * o.turn);
            half = o.length / 2;
            scene.radius = (cdsp_real)o.radius;
        }
        for (i = 0; i < 3; i++) {
            scene.axis_point[i] = (cdsp_real)point[i];
            scene.axis_dir[i] = (cdsp_real)dir[i];
        }
        scene.half_length = (cdsp_real)half;
        scene.n_extra_pipes = o.preset == 1 ? 0 : o.pipes - 1;
        rack_place(&scene, point, dir, o.spacing > 0 ? o.spacing : 3 * (double)scene.radius);
        cdsp_rng_seed(&rng, o.seed, (uint64_t)k);
        st = cdsp_render(&scene, &cam, img.data, img.stride, o.bits, scratch, scratch_len, &rng);
        snprintf(name, sizeof name, "%s_%04d.%s", o.prefix, k, o.format == 1 ? "png" : "pgm");
        if (st != CDSP_OK) {
            tool_warn("sim", "frame %d: cannot render: %s", k, cdsp_strerror(st));
            failed = 1;
            continue;
        }
        snprintf(path, sizeof path, "%s/%s", o.out, name);
        if (cdsp_host_image_write(path, &img, &err) != 0) {
            tool_progress_end(&prog);
            tool_usage_error("sim", "%s", err.msg);
            cdsp_host_image_free(&img);
            goto out;
        }
        tool_axis_truth(point, dir, foot, unit, &dist);
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "frame"); /* the index, as in solve's records */
        cdsp_host_json_int(&j, (long long)k);
        cdsp_host_json_key(&j, "file");
        cdsp_host_json_string(&j, name);
        if (o.preset == 1) {
            char pn[4] = {'p', (char)('1' + k), 0, 0};
            cdsp_host_json_key(&j, "pipe");
            cdsp_host_json_string(&j, pn);
        }
        if (scene.n_extra_pipes > 0) {
            cdsp_host_json_key(&j, "rack");
            cdsp_host_json_begin_array(&j);
            for (i = 0; i <= scene.n_extra_pipes; i++) {
                double pp[3], pf[3], pu[3], pd;
                int q;
                for (q = 0; q < 3; q++)
                    pp[q] = i ? (double)scene.extra_pipe[i - 1].axis_point[q] : point[q];
                tool_axis_truth(pp, dir, pf, pu, &pd);
                cdsp_host_json_begin_object(&j);
                json_vec(&j, "axis_point", pp, 3);
                json_vec(&j, "point", pf, 3);
                json_vec(&j, "direction", pu, 3);
                cdsp_host_json_key(&j, "distance");
                cdsp_host_json_number(&j, pd);
                cdsp_host_json_end_object(&j);
            }
            cdsp_host_json_end_array(&j);
        }
        json_vec(&j, "axis_point", point, 3);
        json_vec(&j, "axis_dir", dir, 3);
        cdsp_host_json_key(&j, "half_length");
        cdsp_host_json_number(&j, half);
        json_vec(&j, "point", foot, 3);
        json_vec(&j, "direction", unit, 3);
        cdsp_host_json_key(&j, "distance");
        cdsp_host_json_number(&j, dist);
        cdsp_host_json_key(&j, "lines");
        if (cdsp_cylinder_contours(&cam, scene.axis_point, scene.axis_dir, scene.radius,
                                   scene.pipe_level > scene.background_level, l[0], l[1],
                                   p_in) == CDSP_OK) {
            cdsp_host_json_begin_array(&j);
            cdsp_host_json_reals(&j, l[0], 3);
            cdsp_host_json_reals(&j, l[1], 3);
            cdsp_host_json_end_array(&j);
        } else {
            cdsp_host_json_null(&j);
            tool_warn("sim", "frame %d: the pipe is not in front of the camera", k);
            failed = 1;
        }
        cdsp_host_json_end_object(&j);
        tool_progress_update(&prog, (size_t)k + 1);
    }
    tool_progress_end(&prog);
    cdsp_host_image_free(&img);
    cdsp_host_json_end_array(&j);
    cdsp_host_json_end_object(&j);
    snprintf(path, sizeof path, "%s/truth.json", o.out);
    if (!cdsp_host_json_finish(&j)) {
        tool_usage_error("sim", "%s: ground truth too large", path);
        goto out;
    }
    f = fopen(path, "w");
    if (!f) {
        tool_usage_error("sim", "%s: cannot create: %s", path, strerror(errno));
        goto out;
    }
    fprintf(f, "%s\n", truth);
    if (ferror(f) | (fclose(f) != 0)) {
        tool_usage_error("sim", "%s: write failed: %s", path, strerror(errno));
        goto out;
    }
    rc = failed ? TOOL_EXIT_PARTIAL : TOOL_EXIT_OK;
out:
    free(truth);
    free(scratch);
    free(pos);
    return rc;
}
