/*
 * tool_internal.h - private to cdsp_tool: the command-line table, shared helpers and
 * the entry point of each subcommand (tool_<name>.c).
 */
#ifndef CDSP_TOOL_H
#define CDSP_TOOL_H

#include <stddef.h>
#include <stdint.h>

#include "cdsp.h"
#include "cdsp_host.h"

/* Exit statuses, the same for every subcommand. */
enum {
    TOOL_EXIT_OK = 0,      /* everything done */
    TOOL_EXIT_PARTIAL = 1, /* some input failed (no pipe, unreadable frame, ...) */
    TOOL_EXIT_USAGE = 2    /* bad command line, calibration or input file */
};

/* ------------------------------------------------------------------------
 * The command line of a subcommand is one table: parsing, range checks,
 * defaults and the OPTIONS section of --help all come from it.
 * ---------------------------------------------------------------------- */
typedef enum {
    OPT_FLAG,   /* int, set to 1 */
    OPT_INT,    /* int in [min, max] */
    OPT_U64,    /* uint64_t */
    OPT_REAL,   /* double in [min, max] */
    OPT_STR,    /* const char * (argv string, not copied) */
    OPT_VEC3,   /* double[3], "x,y,z" */
    OPT_ROI,    /* cdsp_roi, "x,y,w,h" */
    OPT_CHOICE, /* int index into the '|'-separated `choices` */
    OPT_LIST    /* double list: tool_list, "a,b,c" */
} opt_kind;

#define TOOL_LIST_MAX 64
typedef struct {
    int n;
    double v[TOOL_LIST_MAX];
} tool_list;

typedef struct {
    const char *name;    /* long name, without "--" */
    char short_name;     /* 0: none */
    opt_kind kind;
    void *target;
    double min, max;     /* OPT_INT / OPT_REAL range, inclusive */
    const char *arg;     /* placeholder in --help ("N", "PATH"); NULL for flags */
    const char *help;    /* one or more sentences; the default is appended */
    const char *choices; /* OPT_CHOICE: "pgm|png" */
    int no_default;      /* 1: do not print a default */
} tool_opt;

typedef struct {
    const char *name;        /* "solve" */
    const char *summary;     /* one line, for NAME and `cdsp_tool --help` */
    const char *synopsis;    /* after "cdsp_tool NAME " */
    const char *description; /* paragraphs separated by blank lines */
    const char *after;       /* extra sections after OPTIONS (OUTPUT, EXAMPLES, ...) */
    const char *exit_status; /* EXIT STATUS section */
} tool_doc;

/* Parse argv[1..] (argv[0] is the subcommand name). Positional arguments
 * are collected into pos (argv pointers, *npos of them, caller array of
 * argc entries). Returns 0 to go on, or exit status + 1 to stop: --help
 * printed (1 -> exit 0) or a usage error reported (3 -> exit 2). */
int tool_parse(const tool_doc *doc, const tool_opt *opts, int argc, char **argv, char **pos,
               int *npos);
/* The same with the positional array allocated here (*pos, free it when
 * done; NULL when parsing stops); cmd names the command in messages. */
int tool_parse_alloc(const char *cmd, const tool_doc *doc, const tool_opt *opts, int argc,
                     char **argv, char ***pos, int *npos);
void tool_help(const tool_doc *doc, const tool_opt *opts);
/* "cdsp_tool NAME: message" on stderr and TOOL_EXIT_USAGE. */
int tool_usage_error(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void tool_warn(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Monotonic clock, microseconds. */
double tool_now_us(void);

/* mkdir -p: the directory and any missing parents; 0 or -1 with errno
 * (ENOTDIR when a file is in the way). An existing directory is fine. */
int tool_mkdir(const char *path);

/* ------------------------------------------------------------------------
 * Frame lists: paths as given; a directory stands for its frame files
 * (.pgm .png .jpg .jpeg .tif .tiff, any case) in name order; "--list FILE" adds one path per line ("-": stdin).
 * ---------------------------------------------------------------------- */
typedef struct {
    char **path;
    size_t n, cap;
} tool_frames;

int tool_frames_add(tool_frames *f, const char *cmd, const char *arg);
int tool_frames_add_list(tool_frames *f, const char *cmd, const char *listfile);
void tool_frames_free(tool_frames *f);

/* Progress on stderr, only when it is a terminal and the run has lasted
 * 2 s (a shorter one would only flash a line). */
typedef struct {
    const char *what;
    size_t total;
    int enabled, shown;
    double t0, last;
} tool_progress;

void tool_progress_start(tool_progress *p, const char *what, size_t total, int quiet);
void tool_progress_update(tool_progress *p, size_t done);
void tool_progress_end(tool_progress *p);

/* ------------------------------------------------------------------------
 * Geometry helpers shared by sim, bench and export.
 * ---------------------------------------------------------------------- */
/* The paper's simulated camera and its pipes p1..p4 (index 0..3) in camera
 * coordinates, mm: libcdsp's cdsp_render_paper_camera and
 * cdsp_render_paper_pipe (include/cdsp.h), in the tool's doubles. */
void tool_paper_camera(cdsp_camera *cam);

void tool_paper_pipe(int k, double point[3], double dir[3], double *half_length);

/* Ground truth of an axis: foot of the perpendicular from the optical
 * centre, unit direction with the library's sign rule (largest-magnitude
 * component positive), distance. */
void tool_axis_truth(const double point[3], const double dir[3], double foot[3],
                     double unit[3], double *distance);

/* Distance of X from the line through q with unit direction v. */
double tool_line_distance(const double X[3], const double q[3], const double v[3]);

/* The paper's Eq. 17-21 (docs/method.md section 8): RMS distance of `samples`
 * points evenly spaced on the segment a-b (both ends included) from the
 * line through q with direction v; the midpoint alone when samples is 1. */
double tool_segment_rmse(const double a[3], const double b[3], const double q[3],
                         const double v[3], int samples);

/* Room for element n of the array p (capacity *cap elements of elem bytes;
 * NULL and 0 at first): p itself while n < *cap, else p reallocated to
 * twice the capacity (first elements the first time) and *cap updated;
 * NULL when out of memory, p then still valid and *cap unchanged. */
void *tool_grow(void *p, size_t *cap, size_t n, size_t elem, size_t first);

/* ------------------------------------------------------------------------
 * JSON records read back (tool_common.c), the one reader of export, plot
 * and compare: the file, its JSON Lines (or, where asked, one whole JSON
 * document), the numbers and vectors of a record's fields.
 * ---------------------------------------------------------------------- */
struct json_object;

/* Whole FILE ("-": standard input) into *buf (malloc'd, NUL appended), at
 * most 1 GiB (a day of 30 Hz records is about 100 MiB); *name is what
 * messages call it ("(stdin)" for "-"). 0, or TOOL_EXIT_USAGE after a
 * message. */
int tool_read_input(const char *cmd, const char *path, void **buf, size_t *len,
                    const char **name);

/* A finite number (JSON int or double) at key of object o / an array of
 * exactly n finite numbers, a itself or at key of o. 0, else -1 (absent,
 * another type, another length, not finite; o or a NULL: absent). */
int tool_json_num(struct json_object *o, const char *key, double *v);
int tool_json_array(struct json_object *a, double *v, int n);
int tool_json_vec(struct json_object *o, const char *key, double *v, int n);

/* What a record callback returns: taken, or why not (a static string in
 * *why): NOT_RECORD says "FILE: not a cdsp_tool JSON record (line N): why"
 * (the object is no record at all), BAD "FILE:N: why" (a record with a
 * field the command cannot use). */
enum { TOOL_JSONL_OK = 0, TOOL_JSONL_NOT_RECORD = 1, TOOL_JSONL_BAD = 2 };

/* How a command reads its JSON: the callback gets each object and its
 * line (0: the whole file as one document). The differences between the
 * commands are these fields, not copies of the loop. */
typedef struct {
    int (*record)(struct json_object *o, size_t line, void *ctx, const char **why);
    int whole_document; /* a file that is one JSON object (truth.json, a
                           pretty-printed record) is one record, line 0 */
    const char *csv_hint; /* said of a line that looks like CSV (a comma,
                             no '{' first); NULL: the command reads CSV
                             elsewhere, nothing to hint */
} tool_jsonl;

/* Every non-blank line of text (len bytes, NUL-terminated, modified) as a
 * JSON object handed to how->record, in order, stopping at the first that
 * is not one or is refused. 0, or TOOL_EXIT_USAGE after the message naming
 * `name` and the line. */
int tool_jsonl_read(const char *cmd, const char *name, char *text, size_t len,
                    const tool_jsonl *how, void *ctx);

/* ------------------------------------------------------------------------
 * Records read back (tool_records.c): solve's JSON Lines or CSV, cdspd's
 * JSON, for plot and compare; sim's truth.json.
 * ---------------------------------------------------------------------- */
typedef struct {
    char *frame;        /* "file" (the path), else the "frame" number; may be NULL */
    int ok;             /* status "ok" with a pose */
    char error[40];     /* error token when not ok */
    double t_us;        /* t_camera_us, else t_host_us; NAN when absent */
    double point[3], direction[3], distance;
    double sigma_point[3], sigma_direction[3], sigma_distance; /* NAN when absent */
    double segment[2][3];
    int have_segment;
    double confidence;  /* NAN when absent */
} tool_record;

typedef struct {
    tool_record *r;
    size_t n, cap;
} tool_records;

/* All records of FILE ("-": standard input), JSON Lines or CSV by the first
 * line. 0, or TOOL_EXIT_USAGE after "FILE: not a cdsp_tool JSON record
 * (line N): why" (or another message naming the file) on stderr. */
int tool_records_read(const char *cmd, const char *path, tool_records *rs);
void tool_records_free(tool_records *rs);

typedef struct {
    char *frame;        /* file name in sim's directory; may be NULL */
    double point[3], direction[3], distance, half_length;
} tool_truth_frame;

typedef struct {
    tool_truth_frame *f;
    size_t n;
    double radius;      /* NAN when absent */
} tool_truth;

int tool_truth_read(const char *cmd, const char *path, tool_truth *t);
void tool_truth_free(tool_truth *t);
/* The truth of record r (the index-th): by the frame's file name, else by
 * position; NULL when there is none. */
const tool_truth_frame *tool_truth_match(const tool_truth *t, const tool_record *r,
                                         size_t index);
/* The errors of an ok record against its truth: the paper's axis RMSE over
 * `samples` points of the visible segment (tool_segment_rmse; the true
 * half length around P_C when the record has no extent), the angle between
 * the directions (degrees, sign-free) and the distance error (found -
 * true). */
void tool_record_errors(const tool_record *r, const tool_truth_frame *tf, int samples,
                        double *rmse, double *angle_deg, double *ddist);

/* Subcommands. */
int tool_solve_main(int argc, char **argv);   /* also "overlay" */
int tool_sim_main(int argc, char **argv);
int tool_export_main(int argc, char **argv);
int tool_bench_main(int argc, char **argv);
/* tool_rack.c: bench --rack, the paper's real experiment rendered (frames
 * per group; CSV into out_dir). */
int tool_bench_rack(const char *out_dir, int frames, int refine_step, int point_fit, double noise, uint64_t seed,
                    int quiet);
int tool_plot_main(int argc, char **argv);
int tool_compare_main(int argc, char **argv);

/* overlay drawing (tool_overlay.c): the frame in gray with the edge points
 * (distorted positions; label per point: 0 other, 2k + 1 / 2k + 2 the
 * contour inliers of r[k]), the two contours and the projected visible
 * axis of each of the nr results r[] (none when r is NULL; with nr > 1
 * each pipe's rank "#1", "#2", ... beside its axis), the ROI (when
 * roi->w > 0) and ncaption lines of caption (tool_caption.c).
 * Writes an RGB PNG. */
int tool_overlay_write(const char *path, const cdsp_host_image *img, const cdsp_camera *cam,
                       const cdsp_edge *edges, const uint8_t *label, size_t n,
                       const cdsp_result *r, size_t nr, const cdsp_roi *roi,
                       const char *const *caption, int ncaption, cdsp_host_err *err);

/* tool_caption.c: the size of the overlay's marks and text relative to a
 * 1000 px frame (1 below that), and the ROI (dashed cyan) and a caption
 * band (gray 32, white text) drawn with cairo over an RGB picture; 0, or
 * -1 when cairo cannot allocate the picture. */
double tool_overlay_scale(int width, int height);
/* Releases cairo's and fontconfig's caches once nothing is drawing any
 * more (the end of overlay and plot), so that leak checkers see only ours. */
void tool_cairo_done(void);
/* A short text drawn at (x, y) (frame px) by tool_overlay_annotate: the
 * pipes' ranks. */
typedef struct {
    double x, y;
    char text[16];
} tool_tag;
int tool_overlay_annotate(uint8_t *rgb, int w, int h, const cdsp_roi *roi,
                          const char *const *lines, int nlines, const tool_tag *tags, int ntags);

#endif
