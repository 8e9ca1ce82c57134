/*
 * tool_solve.c - `cdsp_tool solve` and `cdsp_tool overlay`: frames in, one
 * record per frame out (JSON Lines or CSV), in input order.
 *
 * Threads: frames are read, decoded and solved by N workers, each with its
 * own cdsp_frame_ws (large: allocated here, once per worker) and a PCG32
 * seeded from (--seed, frame index), so a frame's result does not depend on
 * which thread solved it or how many there are; the main thread prints the
 * records in input order and keeps at most 2N frames in memory. With
 * --track each frame's prior is the previous frame's result, so the solves
 * run in order on the main thread and the workers only read and decode.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct {
    /* command line */
    const char *cmd; /* "solve" or "overlay" */
    const char *calib_path, *list, *out_dir;
    double radius;
    cdsp_roi roi;
    int track, threads, csv, no_time, quiet, polarity, step, window, all, refine_step, point_fit;
    double min_contrast, inlier_px, band, min_distance, max_distance, min_confidence;
    uint64_t seed;
    /* derived */
    int overlay;
    cdsp_camera cam;
    cdsp_params params;
    tool_frames frames;
    cdsp_tracker *trk; /* --all --track: the pipes' tracks (run's, main thread only) */
} job;

typedef struct {
    size_t index;
    cdsp_host_image img;
    const char *error_token; /* NULL while the frame is fine */
    char message[600];
    cdsp_status st;
    cdsp_result res;
    cdsp_result pipes[CDSP_MAX_PIPES]; /* --all: every pipe, res = pipes[0] */
    size_t npipes;
    double time_us;
    char overlay_path[4200];
    int output_failed;
    char *text; /* the record, newline-terminated, malloc'd */
} slot;

/* ---- one frame ------------------------------------------------------------- */

static void load_frame(const job *J, slot *s)
{
    cdsp_host_err err;
    const char *path = J->frames.path[s->index];
    if (cdsp_host_image_read(path, &s->img, &err) != 0) {
        s->error_token = "bad-frame";
        snprintf(s->message, sizeof s->message, "%s", err.msg);
        return;
    }
    if (cdsp_host_calib_match(&J->cam, J->calib_path, s->img.width, s->img.height, path, &err)) {
        s->error_token = "size-mismatch";
        snprintf(s->message, sizeof s->message, "%s", err.msg);
        cdsp_host_image_free(&s->img);
    }
}

static void overlay_name(const job *J, const char *frame, char *out, size_t cap)
{
    const char *base = strrchr(frame, '/');
    const char *dot;
    size_t len;
    base = base ? base + 1 : frame;
    dot = strrchr(base, '.');
    len = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    snprintf(out, cap, "%s/%.*s_overlay.png", J->out_dir, (int)len, base);
}

static void draw(const job *J, slot *s, cdsp_frame_ws *ws)
{
    const cdsp_result *shown = J->all ? s->pipes : &s->res;
    size_t nshown = J->all ? s->npipes : 1, k;
    cdsp_host_err err;
    cdsp_image view = cdsp_host_image_view(&s->img);
    uint8_t *label = malloc(CDSP_MAX_EDGES);
    size_t n = 0, i;
    if (!label) {
        s->output_failed = 1;
        snprintf(s->message, sizeof s->message, "out of memory for the overlay");
        return;
    }
    if (s->st == CDSP_OK) {
        /* the solver's points are undistorted: back into the frame */
        n = s->res.n_edges < CDSP_MAX_EDGES ? s->res.n_edges : CDSP_MAX_EDGES;
        for (i = 0; i < n; i++) {
            cdsp_real und[2] = {ws->edge[i].x, ws->edge[i].y}, dist[2];
            if (cdsp_camera_distort(&J->cam, und, dist) == CDSP_OK) {
                ws->edge[i].x = dist[0];
                ws->edge[i].y = dist[1];
            }
            /* pipe k's contours: 2k + 1 and 2k + 2 */
            label[i] = 0;
            for (k = 0; k < nshown && !label[i]; k++)
                label[i] = ws->label[i] == shown[k].label[0]   ? (uint8_t)(2 * k + 1)
                           : ws->label[i] == shown[k].label[1] ? (uint8_t)(2 * k + 2)
                                                               : 0;
        }
    } else {
        /* no pipe: show what the edge detector saw */
        cdsp_status st = cdsp_edges_detect(&view, &J->params.edge, ws->edge, CDSP_MAX_EDGES, &n);
        if (st != CDSP_OK && st != CDSP_E_CAPACITY)
            n = 0;
        memset(label, 0, n);
    }
    overlay_name(J, J->frames.path[s->index], s->overlay_path, sizeof s->overlay_path);
    {
        /* the caption: the frame, its status and the pose in numbers, or
         * why it failed and what the detector saw */
        char l0[700], l1[400];
        const char *lines[2] = {l0, l1};
        const char *base = strrchr(J->frames.path[s->index], '/');
        const cdsp_result *r = &s->res;
        base = base ? base + 1 : J->frames.path[s->index];
        if (s->st == CDSP_OK) {
            snprintf(l0, sizeof l0,
                     "%s   ok   distance %.3f \xc2\xb1 %.3f   confidence %.2f   P_C (%.2f, %.2f, "
                     "%.2f)",
                     base, (double)r->distance, (double)r->sigma_distance, (double)r->confidence,
                     (double)r->point[0], (double)r->point[1], (double)r->point[2]);
            snprintf(l1, sizeof l1,
                     "direction (%.4f, %.4f, %.4f)   inliers %u + %u of %u edge points, "
                     "rms %.3f / %.3f px%s",
                     (double)r->direction[0], (double)r->direction[1], (double)r->direction[2],
                     (unsigned)r->inliers[0], (unsigned)r->inliers[1], (unsigned)r->n_edges,
                     (double)r->rms[0], (double)r->rms[1],
                     (r->flags & CDSP_FLAG_TRACKED) ? "   tracked" : "");
            if (J->all) {
                size_t len = strlen(l1);
                snprintf(l1 + len, sizeof l1 - len, "   %zu pipe%s (#1 described)", s->npipes,
                         s->npipes == 1 ? "" : "s");
            }
        } else {
            snprintf(l0, sizeof l0, "%s   %s: %s", base, cdsp_status_token(s->st),
                     cdsp_strerror(s->st));
            snprintf(l1, sizeof l1, "%zu edge points found (blue)%s", n,
                     J->roi.w > 0 ? " inside the region of interest (cyan)" : "");
        }
        if (tool_overlay_write(s->overlay_path, &s->img, &J->cam, ws->edge, label, n,
                               s->st == CDSP_OK ? shown : NULL, s->st == CDSP_OK ? nshown : 0,
                               &J->roi, lines, 2, &err) != 0) {
            s->output_failed = 1;
            s->overlay_path[0] = 0;
            tool_warn(J->cmd, "%s", err.msg);
        }
    }
    free(label);
}

static void solve_frame(const job *J, slot *s, cdsp_frame_all_ws *aws, const cdsp_result *prior)
{
    cdsp_frame_ws *ws = &aws->frame;
    cdsp_image view;
    cdsp_rng rng;
    double t0;
    if (s->error_token)
        return;
    view = cdsp_host_image_view(&s->img);
    cdsp_rng_seed(&rng, J->seed, (uint64_t)s->index);
    t0 = tool_now_us();
    if (J->all) {
        s->st = cdsp_frame_solve_all(&view, &J->cam, (cdsp_real)J->radius, &J->params, J->trk, aws,
                                     &rng, s->pipes, CDSP_MAX_PIPES, &s->npipes);
        if (s->st == CDSP_OK)
            s->res = s->pipes[0];
    } else {
        s->st = cdsp_frame_solve(&view, &J->cam, (cdsp_real)J->radius, &J->params, prior, ws, &rng,
                                 &s->res);
    }
    s->time_us = tool_now_us() - t0;
    if (s->st != CDSP_OK) {
        s->error_token = cdsp_status_token(s->st);
        snprintf(s->message, sizeof s->message, "%s: %s", J->frames.path[s->index],
                 cdsp_strerror(s->st));
    }
    if (J->overlay)
        draw(J, s, ws);
    cdsp_host_image_free(&s->img);
}

/* CSV: the JSON record's fields in its order, flattened as fields.c says;
 * empty cells where the JSON record has no field. */
static void csv_header(const job *J)
{
    const cdsp_host_field *f;
    size_t n, i;
    int c;
    char name[96];
    printf("frame,file,status,error,radius,message%s", J->all ? ",pipe" : "");
    f = cdsp_host_pose_fields(&n);
    for (i = 0; i < n; i++)
        for (c = 0; c < cdsp_host_field_columns(&f[i]); c++) {
            cdsp_host_field_column_name(&f[i], c, name, sizeof name);
            printf(",%s", name);
        }
    printf("%s%s,time_us\n", J->all ? ",track_id" : "", J->overlay ? ",overlay" : "");
}

/* A CSV field: quoted (RFC 4180) when it holds a comma, quote or newline. */
static size_t csv_text(char *out, size_t cap, const char *s)
{
    size_t k = 0;
    int quote = strpbrk(s, ",\"\r\n") != NULL;
    if (quote && k < cap)
        out[k++] = '"';
    for (; *s && k + 3 < cap; s++) {
        if (*s == '"')
            out[k++] = '"';
        out[k++] = *s;
    }
    if (quote && k < cap)
        out[k++] = '"';
    return k;
}

/* One CSV row: the pose r (NULL: an error row); with --all, rank the
 * pipe's place (cell "pipe") and its track_id. */
static size_t csv_row(const job *J, const slot *s, const cdsp_result *r, size_t rank, char *t,
                      size_t cap)
{
    const char *path = J->frames.path[s->index];
    const cdsp_host_field *f;
    size_t nf, i, k;
    char b[32];
    int c;
    k = (size_t)snprintf(t, cap, "%zu,", s->index);
    k += csv_text(t + k, cap - k, path);
    k += (size_t)snprintf(t + k, cap - k, ",%s,%s,", s->error_token ? "error" : "ok",
                          s->error_token ? s->error_token : "");
    k += (size_t)snprintf(t + k, cap - k, "%s,", cdsp_host_fmt_real(b, J->radius));
    if (s->error_token)
        k += csv_text(t + k, cap - k, s->message);
    if (J->all)
        k += r ? (size_t)snprintf(t + k, cap - k, ",%zu", rank) : (size_t)snprintf(t + k, cap - k, ",");
    f = cdsp_host_pose_fields(&nf);
    for (i = 0; i < nf; i++)
        for (c = 0; c < cdsp_host_field_columns(&f[i]); c++) {
            t[k++] = ',';
            if (r)
                k += cdsp_host_field_csv(&f[i], r, c, t + k, cap - k);
        }
    if (J->all) {
        t[k++] = ',';
        if (r && J->track)
            k += (size_t)snprintf(t + k, cap - k, "%u", (unsigned)r->track_id);
    }
    if (J->overlay) {
        t[k++] = ',';
        k += csv_text(t + k, cap - k, s->overlay_path);
    }
    if (J->no_time)
        k += (size_t)snprintf(t + k, cap - k, ",\n");
    else
        k += (size_t)snprintf(t + k, cap - k, ",%.0f\n", s->time_us);
    return k;
}

static void format_csv(const job *J, slot *s)
{
    const char *path = J->frames.path[s->index];
    size_t row = 6 * (strlen(path) + strlen(s->message) + strlen(s->overlay_path)) + 4096;
    size_t rows = J->all && !s->error_token ? s->npipes : 1, cap = rows * row, k = 0, p;
    char *t = malloc(cap);
    if (!t)
        return;
    if (s->error_token)
        k = csv_row(J, s, NULL, 0, t, cap);
    else if (!J->all)
        k = csv_row(J, s, &s->res, 0, t, cap);
    else
        for (p = 0; p < s->npipes; p++)
            k += csv_row(J, s, &s->pipes[p], p, t + k, cap - k);
    (void)k;
    s->text = t;
}

static void format_json(const job *J, slot *s)
{
    const char *path = J->frames.path[s->index];
    size_t cap = 6 * (strlen(path) + strlen(s->message) + strlen(s->overlay_path)) + 4096 +
                 (J->all ? CDSP_HOST_JSON_PIPES_MAX(CDSP_MAX_PIPES) : 0);
    char *t = malloc(cap);
    const char *done;
    cdsp_host_json j;
    if (!t)
        return;
    cdsp_host_json_init(&j, t, cap - 1);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "frame"); /* an index, as cdspd's frame number */
    cdsp_host_json_int(&j, (long long)s->index);
    cdsp_host_json_key(&j, "file");
    cdsp_host_json_string(&j, path);
    cdsp_host_json_pose(&j, s->error_token ? CDSP_E_NO_PIPE : CDSP_OK, s->error_token,
                        s->error_token ? NULL : &s->res, (cdsp_real)J->radius);
    if (s->error_token) {
        cdsp_host_json_key(&j, "message");
        cdsp_host_json_string(&j, s->message);
    }
    if (J->all)
        cdsp_host_json_pipes(&j, s->pipes, s->error_token ? 0 : s->npipes, J->track);
    if (J->overlay && s->overlay_path[0]) {
        cdsp_host_json_key(&j, "overlay");
        cdsp_host_json_string(&j, s->overlay_path);
    }
    if (!J->no_time) {
        cdsp_host_json_key(&j, "time_us");
        cdsp_host_json_number(&j, (double)(long long)(s->time_us + 0.5));
    }
    cdsp_host_json_end_object(&j);
    done = cdsp_host_json_finish(&j);
    if (!done) { /* cannot happen with the capacity above; never print half a record */
        free(t);
        return;
    }
    strcat(t, "\n");
    s->text = t;
}

static void format_record(const job *J, slot *s)
{
    if (J->csv)
        format_csv(J, s);
    else
        format_json(J, s);
}

/* ---- the run ----------------------------------------------------------------- */

typedef struct {
    const job *J;
    slot *slots;
    int *done; /* per slot, under mu: the worker finished it */
    size_t window, next, emitted;
    pthread_mutex_t mu;
    pthread_cond_t ready, space;
} shared;

static void *worker(void *arg)
{
    shared *S = arg;
    const job *J = S->J;
    cdsp_frame_all_ws *ws = J->track ? NULL : malloc(sizeof *ws);
    for (;;) {
        size_t i;
        slot *s;
        pthread_mutex_lock(&S->mu);
        while (S->next < J->frames.n && S->next >= S->emitted + S->window)
            pthread_cond_wait(&S->space, &S->mu);
        if (S->next >= J->frames.n) {
            pthread_mutex_unlock(&S->mu);
            break;
        }
        i = S->next++;
        pthread_mutex_unlock(&S->mu);
        s = &S->slots[i % S->window];
        memset(s, 0, sizeof *s);
        s->index = i;
        load_frame(J, s);
        if (!J->track) {
            if (ws) {
                solve_frame(J, s, ws, NULL);
            } else {
                s->error_token = "out-of-memory";
                snprintf(s->message, sizeof s->message, "out of memory for a workspace");
                cdsp_host_image_free(&s->img);
            }
            format_record(J, s);
        }
        pthread_mutex_lock(&S->mu);
        S->done[i % S->window] = 1;
        pthread_cond_broadcast(&S->ready);
        pthread_mutex_unlock(&S->mu);
    }
    free(ws);
    return NULL;
}

/* Emit a finished slot; returns 1 if the frame failed. */
static int emit(const job *J, slot *s)
{
    int failed = s->error_token != NULL || s->output_failed;
    if (s->text) {
        fputs(s->text, stdout);
        if (J->threads <= 1 || J->frames.n < 64)
            fflush(stdout);
    } else {
        tool_warn(J->cmd, "%s: out of memory formatting the record", J->frames.path[s->index]);
        failed = 1;
    }
    free(s->text);
    s->text = NULL;
    return failed;
}

static int run(job *J)
{
    cdsp_frame_all_ws *ws = malloc(sizeof *ws);
    cdsp_tracker trk;
    cdsp_result prior;
    int have_prior = 0, failed = 0;
    size_t n_failed = 0;
    size_t i;
    tool_progress prog;
    if (!ws)
        return tool_usage_error(J->cmd, "out of memory for the workspace");
    cdsp_tracker_init(&trk);
    trk.gate_px = (cdsp_real)(2 * J->band); /* --band: the single path's band, the gate twice it */
    J->trk = J->all && J->track ? &trk : NULL;
    if (J->csv)
        csv_header(J);
    tool_progress_start(&prog, J->cmd, J->frames.n, J->quiet);
    if (J->threads <= 1) {
        slot *s = malloc(sizeof *s);
        if (!s) {
            free(ws);
            return tool_usage_error(J->cmd, "out of memory");
        }
        for (i = 0; i < J->frames.n; i++) {
            memset(s, 0, sizeof *s);
            s->index = i;
            load_frame(J, s);
            solve_frame(J, s, ws, J->track && have_prior ? &prior : NULL);
            if (J->track) {
                have_prior = s->error_token == NULL;
                if (have_prior)
                    prior = s->res;
            }
            format_record(J, s);
            n_failed += (size_t)emit(J, s);
            tool_progress_update(&prog, i + 1);
        }
        free(s);
    } else {
        shared S;
        pthread_t *tid = calloc((size_t)J->threads, sizeof *tid);
        int t, started = 0;
        S.J = J;
        S.window = 2u * (size_t)J->threads;
        S.slots = calloc(S.window, sizeof *S.slots);
        S.done = calloc(S.window, sizeof *S.done);
        S.next = S.emitted = 0;
        if (!tid || !S.slots || !S.done) {
            free(tid);
            free(S.slots);
            free(S.done);
            free(ws);
            return tool_usage_error(J->cmd, "out of memory");
        }
        pthread_mutex_init(&S.mu, NULL);
        pthread_cond_init(&S.ready, NULL);
        pthread_cond_init(&S.space, NULL);
        for (t = 0; t < J->threads; t++)
            if (pthread_create(&tid[t], NULL, worker, &S) == 0)
                started++;
            else
                break;
        if (started == 0)
            tool_warn(J->cmd, "cannot start threads: %s; running on one", strerror(errno));
        for (i = 0; i < J->frames.n; i++) {
            slot *s = &S.slots[i % S.window];
            if (started == 0) { /* no workers: this thread does their part */
                memset(s, 0, sizeof *s);
                s->index = i;
                load_frame(J, s);
                if (!J->track) {
                    solve_frame(J, s, ws, NULL);
                    format_record(J, s);
                }
                S.done[i % S.window] = 1;
            }
            pthread_mutex_lock(&S.mu);
            while (!S.done[i % S.window])
                pthread_cond_wait(&S.ready, &S.mu);
            pthread_mutex_unlock(&S.mu);
            if (J->track) {
                solve_frame(J, s, ws, have_prior ? &prior : NULL);
                have_prior = s->error_token == NULL;
                if (have_prior)
                    prior = s->res;
                format_record(J, s);
            }
            n_failed += (size_t)emit(J, s);
            tool_progress_update(&prog, i + 1);
            pthread_mutex_lock(&S.mu);
            S.done[i % S.window] = 0;
            S.emitted++;
            pthread_cond_broadcast(&S.space);
            pthread_mutex_unlock(&S.mu);
        }
        for (t = 0; t < started; t++)
            pthread_join(tid[t], NULL);
        pthread_mutex_destroy(&S.mu);
        pthread_cond_destroy(&S.ready);
        pthread_cond_destroy(&S.space);
        free(S.slots);
        free(S.done);
        free(tid);
    }
    tool_progress_end(&prog);
    free(ws);
    failed = n_failed > 0;
    /* one line for the person at the terminal (never in a pipeline's log) */
    if (!J->quiet && isatty(STDERR_FILENO))
        fprintf(stderr, "%s: %zu frames, %zu solved, %zu failed, %.2f s\n", J->cmd, J->frames.n,
                J->frames.n - n_failed, n_failed, (tool_now_us() - prog.t0) * 1e-6);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        tool_warn(J->cmd, "writing the output failed: %s", strerror(errno));
        return TOOL_EXIT_PARTIAL;
    }
    return failed ? TOOL_EXIT_PARTIAL : TOOL_EXIT_OK;
}

/* ---- command line -------------------------------------------------------------- */

static const char solve_description[] =
    "    Reads each FRAME (PGM P5, PNG or TIFF, 8 or 16 bit, or JPEG; colour\n"
    "    frames are converted to gray), finds the two straight contours of the\n"
    "    pipe in it and recovers the pipe's 3D axis in closed form from the\n"
    "    contours and the known radius R (Yao et al. 2024). The calibration is the\n"
    "    ROS camera_info YAML that ROS's camera_calibration, many camera drivers\n"
    "    and cdsp_tool sim write; its image size must equal every frame's.\n"
    "\n"
    "    A FRAME that is a directory stands for the .pgm, .png, .jpg, .jpeg, .tif\n"
    "    and .tiff files in it, in name order. One record per frame is written to\n"
    "    standard output, in input order, whatever --threads is; a frame that\n"
    "    cannot be read or holds no pipe gets an error record and the run goes on.\n"
    "\n"
    "    Lengths are in the unit of R (mm in all examples); coordinates are the\n"
    "    camera's: origin at the optical centre, X right, Y down, Z forward.\n\n";

static const char overlay_description[] =
    "    Solves each FRAME as `cdsp_tool solve` does (same options, same records on\n"
    "    standard output, with an \"overlay\" field naming the picture) and writes\n"
    "    DIR/NAME_overlay.png for FRAME NAME.pgm or NAME.png: the frame in gray,\n"
    "    the detected edge points (blue), the inliers of the two contours (green\n"
    "    and magenta), the two fitted contour lines (yellow, curved as the lens\n"
    "    distortion bends them) and the visible axis segment projected into the\n"
    "    frame (red); the --roi rectangle (dashed cyan) and a caption across the\n"
    "    top: the frame, its status, the distance +- sigma, the confidence, P_C,\n"
    "    the direction and the inliers, or the error and why. Lines, marks and\n"
    "    text grow with the frame (text 16 px high per 1000 px), so a 5 MP frame\n"
    "    viewed whole reads.\n"
    "    When no pipe is found the picture shows all edge points the detector\n"
    "    found, which usually tells why.\n\n";

static const char solve_after[] =
    "OUTPUT\n"
    "    JSON Lines (default): one object per frame, in input order:\n"
    "      frame      its index in the input, from 0 (as cdspd's frame number)\n"
    "      file       the path as given\n"
    "      status     \"ok\" or \"error\"\n"
    "      error      (errors only) a short reason: bad-frame (unreadable, corrupt\n"
    "                 or unsupported file), size-mismatch (frame size differs from\n"
    "                 the calibration's), no-pipe, few-points, degenerate, ...\n"
    "      radius     R as given\n"
    "      message    (errors only) the same in words, naming the file\n"
    "      point      [x, y, z]: P_C, the foot of the perpendicular from the\n"
    "                 optical centre onto the axis\n"
    "      direction  [x, y, z]: unit axis direction (largest component > 0, or\n"
    "                 following the previous frame with --track)\n"
    "      distance   |P_C|\n"
    "      alpha      angle between the two tangent planes, radians\n"
    "      lines      [[a, b, c], [a, b, c]]: the contours a u + b v + c = 0 in\n"
    "                 undistorted pixels, a^2 + b^2 = 1, (a, b) toward the\n"
    "                 brighter side\n"
    "      inliers    [n1, n2]: contour points on each line\n"
    "      rms        [r1, r2]: their RMS distance to the line, px\n"
    "      segment    [[x, y, z], [x, y, z]]: the visible part of the axis\n"
    "      sigma      {\"point\": [..], \"direction\": [..], \"distance\": s}: standard\n"
    "                 deviations propagated from the line fits\n"
    "      bound      {\"point\", \"direction\", \"distance\", \"edge\": [e1, e2]}: the\n"
    "                 systematic part, a bound and not a sigma (the error is\n"
    "                 within sigma + bound); edge in px, per contour\n"
    "      edges      edge points considered\n"
    "      tracked    true when found near the previous frame's pipe (--track)\n"
    "      full_search  true when found by searching the whole frame or ROI\n"
    "      truncated  true when the frame had more edges than the solver keeps\n"
    "      confidence 0..1: how sure the solver is that this is the pipe (its\n"
    "                 evidence and margin over the next candidate; see\n"
    "                 --min-confidence)\n"
    "      pipes      (--all) every pipe, best first: objects with point,\n"
    "                 direction, distance, segment, sigma, bound, confidence\n"
    "                 (how sure this band is a pipe), lines, inliers, and with\n"
    "                 --track track_id (kept from frame to frame while the\n"
    "                 pipe is in view); the fields above describe pipes[0]\n"
    "      pairs      (--all) for every two pipes i < j: {\"i\", \"j\",\n"
    "                 \"angle_deg\" between their axes, \"axis_distance\": the\n"
    "                 mean distance from 100 points of pipe i's visible axis\n"
    "                 segment to pipe j's axis (the paper's Eq. 17-21: the\n"
    "                 spacing of parallel pipes), \"axis_distance_rms\": its\n"
    "                 spread along the segment}\n"
    "      overlay    (overlay only) the picture written\n"
    "      time_us    processing time of the frame in the library, microseconds\n"
    "                 (omitted with --no-time)\n"
    "    With --csv: a header line, then one line per frame with every field of\n"
    "    the JSON record, in its order, flattened: vectors _x _y _z, one per\n"
    "    contour _1 _2 (lines_1_a .. lines_2_c, segment_1_x .. segment_2_z),\n"
    "    sigma.point as sigma_point_x ...; booleans true/false; cells empty\n"
    "    where the JSON record has no field (the pose of an error). With --all:\n"
    "    one line per pipe, the pose columns that pipe's, with a column \"pipe\"\n"
    "    (its rank, 0 first) after message and \"track_id\" (with --track) after\n"
    "    the pose; \"pairs\" is in the JSON output only.\n"
    "\n"
    "EXAMPLES\n"
    "    cdsp_tool solve --calib cam.yaml --radius 8 frames/ > poses.jsonl\n"
    "    cdsp_tool solve --calib cam.yaml --radius 8 --track -j 4 run1/*.png\n"
    "    cdsp_tool overlay --calib cam.yaml --radius 8 --out check/ f0001.pgm\n"
    "    cdsp_tool solve --calib cam.yaml --radius 8 --all --track rack/ > rack.jsonl\n"
    "    find data -name '*.pgm' | cdsp_tool solve --calib cam.yaml --radius 8 \\\n"
    "        --list - --csv > poses.csv\n";

static const char solve_exit[] =
    "    0  every frame was solved\n"
    "    1  some frame had no pipe, could not be read or its overlay could not be\n"
    "       written (its record says which); the other frames were processed\n"
    "    2  usage error, or the calibration file is missing or invalid (the\n"
    "       message names the file and the field); no frame was processed\n";

int tool_solve_main(int argc, char **argv)
{
    job J;
    cdsp_params def;
    cdsp_host_err err;
    char **pos = NULL;
    int npos = 0, rc, i;
    static const tool_doc solve_doc = {
        "solve", "pipe axes from saved frames, one JSON object per frame",
        "--calib CAM.yaml --radius R [OPTIONS] FRAME|DIR...", solve_description, solve_after,
        solve_exit};
    static const tool_doc overlay_doc = {
        "overlay", "solve, and draw edges, contours and axis over each frame",
        "--calib CAM.yaml --radius R --out DIR [OPTIONS] FRAME...", overlay_description,
        solve_after, solve_exit};
    memset(&J, 0, sizeof J);
    J.overlay = strcmp(argv[0], "overlay") == 0;
    J.cmd = J.overlay ? "overlay" : "solve";
    cdsp_params_default(&def);
    J.threads = 1;
    J.step = def.edge.step;
    J.refine_step = def.refine_step;
    J.window = def.edge.half_window;
    J.min_contrast = (double)def.edge.min_contrast;
    J.inlier_px = (double)def.pair.inlier_px;
    J.band = (double)def.track_band_px;
    J.min_distance = (double)def.pair.min_distance;
    J.max_distance = (double)def.pair.max_distance;
    J.min_confidence = (double)def.min_confidence;
    J.polarity = def.pair.polarity == 0 ? 0 : def.pair.polarity > 0 ? 1 : 2;
    J.seed = 1;
    {
        const tool_opt opts[] = {
            {"calib", 'c', OPT_STR, &J.calib_path, 0, 0, "CAM.yaml",
             "The camera calibration, ROS camera_info YAML (required).", NULL, 1},
            {"radius", 'r', OPT_REAL, &J.radius, 1e-9, CDSP_MAX_RADIUS, "R",
             "The pipe's radius in the unit wanted for the output, e.g. 8 for a 16 mm "
             "pipe in mm (required).", NULL, 1},
            {"out", 'o', OPT_STR, &J.out_dir, 0, 0, "DIR",
             J.overlay ? "Where the pictures go (created if missing; required)."
                       : "Only with cdsp_tool overlay.", NULL, 1},
            {"roi", 0, OPT_ROI, &J.roi, 0, 0, "X,Y,W,H",
             "Look for the pipe only in this rectangle of the frame (pixels, X,Y its "
             "top-left corner). Must lie inside the calibrated image.", NULL, 0},
            {"track", 't', OPT_FLAG, &J.track, 0, 0, NULL,
             "Frames are a sequence: use each frame's result as the prior for the next "
             "(search near the previous contours first, full search when that fails; "
             "an error record resets the prior). Solves run in input order; --threads "
             "then only parallelizes reading and decoding.", NULL, 0},
            {"all", 'a', OPT_FLAG, &J.all, 0, 0, NULL,
             "Every pipe in view (a rack): the record's usual fields describe the "
             "first-ranked pipe, and \"pipes\" and \"pairs\" (see OUTPUT) list every pipe "
             "and the spacing of every two; with --csv one line per pipe; the overlay "
             "draws every pipe with its rank. No contour is shared by two pipes, so the "
             "gap between two pipes is never one. With --track each pipe keeps a "
             "track_id while it stays in view (a pipe continues a track when its "
             "contours lie within twice --band of it); while every track is found "
             "there, only the bands around the tracks are read, and a full search runs "
             "when one is lost and every 10th frame (a pipe coming into view is found "
             "then).",
             NULL, 0},
            {"threads", 'j', OPT_INT, &J.threads, 0, 256, "N",
             "Solve N frames at a time on N threads (0: one per core). The output is "
             "the same, byte for byte, whatever N is.", NULL, 0},
            {"csv", 0, OPT_FLAG, &J.csv, 0, 0, NULL, "Write CSV instead of JSON Lines.", NULL, 0},
            {"no-time", 0, OPT_FLAG, &J.no_time, 0, 0, NULL,
             "Leave out time_us, so that runs can be compared byte for byte.", NULL, 0},
            {"list", 'l', OPT_STR, &J.list, 0, 0, "FILE",
             "Also read frame paths from FILE, one per line (\"-\": standard input).", NULL, 1},
            {"seed", 0, OPT_U64, &J.seed, 0, 0, "S",
             "Seed of RANSAC's random numbers; frame k uses stream k, so results are "
             "reproducible and independent of --threads.", NULL, 0},
            {"polarity", 0, OPT_CHOICE, &J.polarity, 0, 0, NULL,
             "Whether the pipe is brighter (bright) or darker (dark) than the "
             "background; any accepts both.", "any|bright|dark", 0},
            {"step", 0, OPT_INT, &J.step, 1, 64, "N",
             "Scan every Nth row and column for edge points.", NULL, 0},
            {"refine-step", 0, OPT_INT, &J.refine_step, 0, 64, "K",
             "A final pass once each pose's two contours are found: only short segments "
             "(+-(--inlier-px + 2) px) of the scanlines around them are read again, on "
             "every Kth scanline, and the contour lines refitted to the edge points there "
             "(the search, its edge budget and the confidences stay as they are). 0: off; "
             "else at least 3: an edge point's position is the mean over 3 scanlines, so 3 "
             "reads every pixel near the contours once. The lines' random error falls by "
             "sqrt(--step / K) at most: 1.15 at the default --step 4 (cdsp_tool bench "
             "--rack measures what it does to a rack's spacing).", NULL, 0},
            {"point-fit", 0, OPT_FLAG, &J.point_fit, 0, 0, NULL,
             "With --refine-step: each point of the final pass fitted again to its "
             "window's pixels (a blurred step with the contour's own spread): about 1.8 "
             "times less noise per point on a rendered rack, but a shaded limb's bias "
             "grows (docs/method.md 3a).", NULL, 0},
            {"window", 0, OPT_INT, &J.window, 2, 8, "H",
             "Half-length of the subpixel edge window, px (covers blur up to about "
             "H/3 px sigma).", NULL, 0},
            {"min-contrast", 0, OPT_REAL, &J.min_contrast, 0.001, 1, "F",
             "Smallest intensity step across an edge, as a fraction of full scale "
             "(below 1).", NULL, 0},
            {"inlier-px", 0, OPT_REAL, &J.inlier_px, 0.01, 100, "PX",
             "RANSAC inlier distance to a contour line, px.", NULL, 0},
            {"band", 0, OPT_REAL, &J.band, 1, 1000, "PX",
             "With --track: half-width of the search band around the previous contours, "
             "px.", NULL, 0},
            {"min-confidence", 0, OPT_REAL, &J.min_confidence, 0, 1, "C",
             "Report a pose whose confidence (0..1, in the output) is below C as "
             "no-pipe. How often poses of each confidence were the true pipe is "
             "measured by make bench-detect (its calibration table).", NULL, 0},
            {"min-distance", 0, OPT_REAL, &J.min_distance, 0, 1e12, "D",
             "Reject pipes nearer than D (unit of R); 0: no bound.", NULL, 0},
            {"max-distance", 0, OPT_REAL, &J.max_distance, 0, 1e12, "D",
             "Reject pipes farther than D (unit of R); 0: no bound.", NULL, 0},
            {"quiet", 'q', OPT_FLAG, &J.quiet, 0, 0, NULL,
             "No progress line and no closing summary (frames, solved, failed, time) on "
             "standard error; both only appear when it is a terminal, the progress line "
             "once the run has lasted 2 s.", NULL, 0},
            {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
        };
        rc = tool_parse_alloc(J.cmd, J.overlay ? &overlay_doc : &solve_doc, opts, argc, argv, &pos, &npos);
        if (rc)
            return rc - 1;
    }
    rc = TOOL_EXIT_USAGE;
    if (!J.calib_path) {
        tool_usage_error(J.cmd, "--calib CAM.yaml is required (see --help)");
        goto out;
    }
    if (!(J.radius > 0)) {
        tool_usage_error(J.cmd, "--radius R is required (see --help)");
        goto out;
    }
    if (!J.overlay && J.out_dir) {
        tool_usage_error(J.cmd, "--out is an option of cdsp_tool overlay");
        goto out;
    }
    if (J.overlay && !J.out_dir) {
        tool_usage_error(J.cmd, "--out DIR is required (see --help)");
        goto out;
    }
    if (cdsp_host_calib_read(J.calib_path, &J.cam, &err) != 0) {
        tool_usage_error(J.cmd, "%s", err.msg);
        goto out;
    }
    if (J.roi.w > 0 && (J.roi.x + J.roi.w > J.cam.width || J.roi.y + J.roi.h > J.cam.height)) {
        tool_usage_error(J.cmd, "--roi %d,%d,%d,%d reaches outside the %dx%d image of %s",
                         J.roi.x, J.roi.y, J.roi.w, J.roi.h, J.cam.width, J.cam.height,
                         J.calib_path);
        goto out;
    }
    if (J.min_distance > 0 && J.max_distance > 0 && J.min_distance >= J.max_distance) {
        tool_usage_error(J.cmd, "--min-distance must be below --max-distance");
        goto out;
    }
    for (i = 0; i < npos; i++)
        if (tool_frames_add(&J.frames, J.cmd, pos[i]) != 0)
            goto out;
    if (J.list && tool_frames_add_list(&J.frames, J.cmd, J.list) != 0)
        goto out;
    if (J.frames.n == 0) {
        tool_usage_error(J.cmd, "no frames given (see --help)");
        goto out;
    }
    if (J.overlay && tool_mkdir(J.out_dir) != 0) {
        tool_usage_error(J.cmd, "%s: cannot create the directory: %s", J.out_dir,
                         strerror(errno));
        goto out;
    }
    if (J.threads == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        J.threads = n > 0 ? (n > 256 ? 256 : (int)n) : 1;
    }
    if ((size_t)J.threads > J.frames.n)
        J.threads = (int)J.frames.n;

    J.params = def;
    J.params.edge.roi = J.roi;
    J.params.edge.step = J.step;
    J.params.edge.half_window = J.window;
    J.params.edge.min_contrast = (cdsp_real)J.min_contrast;
    J.params.pair.inlier_px = (cdsp_real)J.inlier_px;
    J.params.pair.polarity = J.polarity == 0 ? 0 : J.polarity == 1 ? 1 : -1;
    J.params.pair.min_distance = (cdsp_real)J.min_distance;
    J.params.pair.max_distance = (cdsp_real)J.max_distance;
    J.params.min_confidence = (cdsp_real)J.min_confidence;
    J.params.track_band_px = (cdsp_real)J.band;
    J.params.refine_step = J.refine_step;
    J.params.point_fit = J.point_fit;
    /* libcdsp refuses the point fit without the final pass it refits
     * (cdsp_params_check): said first with the options' names */
    if (J.point_fit && J.refine_step < 3) {
        tool_usage_error(J.cmd, "--point-fit needs --refine-step 3 or more (the final pass it refits)");
        goto out;
    }
    /* the library's own parameter checks before any frame: the options'
     * ranges are inclusive, libcdsp's are not all (0 < min_contrast < 1) */
    if (cdsp_params_check(&J.params) != CDSP_OK) {
        tool_usage_error(J.cmd, "libcdsp refuses these solver options (--step %d --window %d "
                         "--min-contrast %g --inlier-px %g --band %g --refine-step %d): "
                         "--min-contrast must be below 1, --refine-step 0 or at least 3, the "
                         "other ranges are in --help",
                         J.step, J.window, J.min_contrast, J.inlier_px, J.band, J.refine_step);
        goto out;
    }
    rc = run(&J);
    if (J.overlay)
        tool_cairo_done(); /* every worker has finished drawing */
out:
    tool_frames_free(&J.frames);
    free(pos);
    return rc;
}
