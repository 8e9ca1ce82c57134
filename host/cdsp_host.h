/*
 * cdsp_host.h - host-side code shared by cdsp_tool, cdsp_calib and cdspd:
 * frame files (PGM P5 read by hand, PNG through libspng, JPEG through
 * libjpeg-turbo, TIFF through libtiff), the ROS camera_info YAML
 * calibration (libyaml; read and written), the JSON record both programs
 * emit for a pose and its field table (fields.c: JSON, CSV and the manuals'
 * field lists), the ground truth of an axis as the solver reports it
 * (truth.c), and the monotonic clock and stop signals of the programs and
 * test peers (clock.c, stop.c). Beside it in the same library: the wire
 * protocol (proto.h) and UDP addresses (addr.h). Built as
 * build/libcdsp_host.a by host/host.mk; link it with the libraries of
 * HOSTLIB_PKGS there (-lyaml -lspng -ljson-c -ljpeg -ltiff) and libcdsp.
 *
 * Conventions:
 * - Every call that can fail returns 0 on success or a negative
 *   cdsp_host_rc, and fills a cdsp_host_err with one line of English that
 *   names the file (or the name given for an in-memory buffer) and the
 *   problem, e.g. "cam.yaml: camera_matrix.data: expected 9 numbers, got 8".
 * - Nothing here prints or exits. Images are the only allocations; the JSON
 *   writer works in a caller buffer and never allocates (the daemon calls it
 *   once per frame).
 */
#ifndef CDSP_HOST_H
#define CDSP_HOST_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "cdsp.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest width or height of a frame read or written (the issue asks for at
 * least 8192 x 8192). */
#ifndef CDSP_HOST_MAX_DIM
#define CDSP_HOST_MAX_DIM 16384
#endif

/* Largest PGM header (magic, numbers, comments), bytes. */
#ifndef CDSP_HOST_PGM_MAX_HEADER
#define CDSP_HOST_PGM_MAX_HEADER 65536
#endif

/* Largest YAML file (calibration, cdspd's config), bytes. ROS's camera_info
 * files are under 1 KiB and daemon/cdspd.yaml, every key commented, under
 * 8 KiB; libyaml loads about 3 MB/s of the worst case here (issue 16), so
 * the largest file costs ~20 ms, also in a SIGHUP reload on the daemon's
 * main loop. */
#ifndef CDSP_HOST_YAML_MAX_BYTES
#define CDSP_HOST_YAML_MAX_BYTES (64 * 1024)
#endif

typedef enum {
    CDSP_HOST_OK = 0,
    CDSP_HOST_E_IO = -1,      /* open, read or write failed (errno in the message) */
    CDSP_HOST_E_FORMAT = -2,  /* the file's content is not what it should be */
    CDSP_HOST_E_LIMIT = -3,   /* a size beyond the limits above */
    CDSP_HOST_E_NOMEM = -4,   /* allocation failed */
    CDSP_HOST_E_MISMATCH = -5 /* frame and calibration disagree (image size) */
} cdsp_host_rc;

typedef struct {
    char msg[512];
} cdsp_host_err;

/* ------------------------------------------------------------------------
 * Images: one gray channel, 8 bit (one byte per pixel) or 9..16 bit (two
 * bytes, native endianness, values in [0, 2^bits - 1]), rows tightly packed.
 * ---------------------------------------------------------------------- */
typedef struct {
    void *data;        /* malloc'd by the readers / cdsp_host_image_alloc */
    int width, height;
    int bits;          /* significant bits: 8 .. 16 */
    size_t stride;     /* bytes per row */
} cdsp_host_image;

/* bits 1..16 (<= 8 stores a byte per pixel); width, height 1..MAX_DIM.
 * The pixels are zeroed. */
int cdsp_host_image_alloc(cdsp_host_image *im, int width, int height, int bits,
                          cdsp_host_err *err);
void cdsp_host_image_free(cdsp_host_image *im);
/* A view for the library (no copy; valid while im is). */
cdsp_image cdsp_host_image_view(const cdsp_host_image *im);
/* Pixel (x, y) scaled to [0, 1]. */
double cdsp_host_image_at(const cdsp_host_image *im, int x, int y);

/*
 * PGM (P5, netpbm spec): maxval 1..65535, one byte per sample below 256,
 * else two bytes big-endian; comments anywhere in the header; a maxval of
 * 2^k - 1 is kept as bits = k (k <= 8 is stored as 8 bit scaled to 255),
 * any other maxval is rescaled (rounded) to full scale of the next such
 * depth. A sample above maxval is an error, so is a truncated raster;
 * bytes after the first image are ignored. `name` labels the messages.
 */
int cdsp_host_pgm_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                         cdsp_host_err *err);
int cdsp_host_pgm_read(const char *path, cdsp_host_image *out, cdsp_host_err *err);
/* maxval = 2^bits - 1 (bits 8 gives 255, 12 gives 4095, 16 gives 65535). */
int cdsp_host_pgm_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err);

/* PNG through libspng: gray 1/2/4/8/16 bit kept gray (low depths scaled
 * to 8 bit); gray+alpha, RGB, RGBA and palette converted to gray with
 * Rec. 601 luma (0.299 R + 0.587 G + 0.114 B, the weights OpenCV uses),
 * alpha ignored; no gamma applied. 16-bit files give bits = 16. */
int cdsp_host_png_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                         cdsp_host_err *err);
int cdsp_host_png_read(const char *path, cdsp_host_image *out, cdsp_host_err *err);
/* Gray, 8 bit, or 16 bit when bits > 8 (values scaled to 65535). */
int cdsp_host_png_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err);
/* Interleaved 8-bit RGB, width * 3 bytes per row. */
int cdsp_host_png_write_rgb(const char *path, const uint8_t *rgb, int width, int height,
                            cdsp_host_err *err);

/* JPEG through libjpeg-turbo: baseline or progressive, 8 bit, gray or
 * colour (converted to gray: libjpeg keeps Y, Rec. 601 luma). Corrupt or
 * truncated data is an error, not gray filler; a header claiming more
 * pixels than the file can encode is refused before allocating. */
int cdsp_host_jpeg_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                          cdsp_host_err *err);
/* TIFF through libtiff (first image only): gray 8/16 bit (min-is-black or
 * min-is-white), RGB(A) 8/16 bit converted to gray with Rec. 601 luma, in
 * strips or tiles, any compression libtiff decodes; other 8-bit layouts
 * (palette, bilevel, separate planes, YCbCr) through libtiff's RGBA
 * conversion. 16-bit files give bits = 16. Float and signed samples are
 * refused by name. */
int cdsp_host_tiff_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                          cdsp_host_err *err);

/* Any supported frame (PGM, PNG, JPEG, TIFF), chosen by its first bytes
 * (not its name). */
int cdsp_host_image_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                           cdsp_host_err *err);
int cdsp_host_image_read(const char *path, cdsp_host_image *out, cdsp_host_err *err);
/* By extension: ".png" -> PNG, ".pgm" -> PGM; anything else is an error. */
int cdsp_host_image_write(const char *path, const cdsp_host_image *im, cdsp_host_err *err);

/* Whole file into a malloc'd buffer (NUL appended, not counted), at most
 * max_bytes; a bigger file is CDSP_HOST_E_LIMIT. */
int cdsp_host_read_file(const char *path, size_t max_bytes, void **buf, size_t *len,
                        cdsp_host_err *err);

/* ------------------------------------------------------------------------
 * Calibration: ROS camera_info YAML (camera_calibration, camera drivers,
 * cdsp_calib). Required keys: image_width, image_height, camera_matrix
 * {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]},
 * distortion_model: plumb_bob, distortion_coefficients {rows: 1, cols: 5,
 * data: [k1, k2, p1, p2, k3]} (or cols: 4, data: [k1, k2, p1, p2], k3 = 0;
 * 8 coefficients, OpenCV's rational model, are refused by name). Other keys (camera_name,
 * rectification_matrix, projection_matrix) are accepted and ignored.
 * ---------------------------------------------------------------------- */
int cdsp_host_calib_parse(const char *text, size_t len, const char *name, cdsp_camera *cam,
                          cdsp_host_err *err);
int cdsp_host_calib_read(const char *path, cdsp_camera *cam, cdsp_host_err *err);
/* The layout ROS's camera_calibration writes (rectification identity;
 * projection [K | 0]). camera_name may be NULL ("cdsp"); only
 * [A-Za-z0-9_.-] are kept. Numbers carry the fewest of 15-17 significant
 * digits that read back to the same double, and always a '.' ("0.0",
 * "1.5e-05") so YAML 1.1 readers (PyYAML) see floats. An invalid camera
 * (cdsp_camera_check) is refused before anything is written. */
int cdsp_host_calib_write(const char *path, const cdsp_camera *cam, const char *camera_name,
                          cdsp_host_err *err);
/* The same to an open stream (name for messages), after comment (NULL, or
 * lines written as "# LINE"), with the 3x4 row-major projection matrix
 * given (NULL: [K | 0]; cdsp_calib's is the undistorted image's camera
 * matrix). CDSP_HOST_E_IO when the stream's error flag is set after it. */
int cdsp_host_calib_write_stream(FILE *f, const char *name, const cdsp_camera *cam,
                                 const char *camera_name, const char *comment,
                                 const double projection[12], cdsp_host_err *err);
/* CDSP_HOST_E_MISMATCH with "FRAME: image is WxH but CALIB is for WxH". */
int cdsp_host_calib_match(const cdsp_camera *cam, const char *calib_name, int width, int height,
                          const char *frame_name, cdsp_host_err *err);

/* ------------------------------------------------------------------------
 * JSON writer into a caller buffer: no allocation, output always valid
 * UTF-8 JSON. Strings are escaped; bytes that are not valid UTF-8 become
 * U+FFFD; non-finite numbers become null. Once the buffer is full the
 * writer stops and cdsp_host_json_finish() returns NULL.
 * ---------------------------------------------------------------------- */
#define CDSP_HOST_JSON_DEPTH 16

typedef struct {
    char *buf;
    size_t cap, len;
    int overflow;      /* buffer too small, or nesting beyond DEPTH */
    int depth;
    unsigned char count[CDSP_HOST_JSON_DEPTH]; /* items so far at each level (saturates) */
    int after_key;
} cdsp_host_json;

void cdsp_host_json_init(cdsp_host_json *j, char *buf, size_t cap);
void cdsp_host_json_begin_object(cdsp_host_json *j);
void cdsp_host_json_end_object(cdsp_host_json *j);
void cdsp_host_json_begin_array(cdsp_host_json *j);
void cdsp_host_json_end_array(cdsp_host_json *j);
void cdsp_host_json_key(cdsp_host_json *j, const char *key);
void cdsp_host_json_string(cdsp_host_json *j, const char *s);
void cdsp_host_json_number(cdsp_host_json *j, double v);
void cdsp_host_json_int(cdsp_host_json *j, long long v);
void cdsp_host_json_bool(cdsp_host_json *j, int v);
void cdsp_host_json_null(cdsp_host_json *j);
void cdsp_host_json_reals(cdsp_host_json *j, const cdsp_real *v, int n);
/* The NUL-terminated text, or NULL on overflow or unbalanced nesting. */
const char *cdsp_host_json_finish(cdsp_host_json *j);

/* Shortest "%.*g" text (15 or 17 digits) that reads back as v exactly;
 * "null" for NaN/Inf. buf needs 32 bytes. */
const char *cdsp_host_fmt_real(char buf[32], double v);

/*
 * The pose fields of a record (fields.c): one table, iterated by the JSON
 * writer below, cdsp_tool solve's CSV writer and the tests comparing the
 * manuals with the code. A name "group.key" is key inside the JSON object
 * "group" (consecutive rows share it).
 */
typedef enum {
    CDSP_HOST_FIELD_REAL,   /* cdsp_real */
    CDSP_HOST_FIELD_VEC3,   /* cdsp_real[3]: [x, y, z]; CSV _x _y _z */
    CDSP_HOST_FIELD_PAIR,   /* cdsp_real[2], one per contour: [r1, r2]; CSV _1 _2 */
    CDSP_HOST_FIELD_COUNT,  /* uint32_t */
    CDSP_HOST_FIELD_COUNT2, /* uint32_t[2], one per contour; CSV _1 _2 */
    CDSP_HOST_FIELD_LINES,  /* cdsp_real[2][3] lines: [[a,b,c],[a,b,c]]; CSV _1_a .. _2_c */
    CDSP_HOST_FIELD_POINTS, /* cdsp_real[2][3] points: [[x,y,z],[x,y,z]]; CSV _1_x .. _2_z */
    CDSP_HOST_FIELD_FLAG    /* bool: the uint32_t at offset has mask set */
} cdsp_host_field_kind;

typedef struct {
    const char *name;           /* JSON key ("sigma.point": nested) */
    cdsp_host_field_kind kind;
    size_t offset;              /* in cdsp_result */
    uint32_t mask;              /* FLAG: the CDSP_FLAG_* bit */
    const char *doc;            /* one line for the manuals */
} cdsp_host_field;

/* The table, in output order; *n rows. */
const cdsp_host_field *cdsp_host_pose_fields(size_t *n);
/* The fields of each entry of a record's "pipes" (cdsp_tool solve --all,
 * cdspd multi_pipe), in output order: point, direction, distance,
 * segment, sigma, confidence, lines, inliers, track_id (written only when
 * tracking). */
const cdsp_host_field *cdsp_host_pipe_fields(size_t *n);
/* One entry of "pairs" for pipes a (i) and b (j): the angle between their
 * axes (degrees, 0..90), and the mean distance from 100 points of a's
 * visible axis segment to b's axis with its RMS spread along the segment
 * (the paper's Eq. 17-21; cdsp_result_axis_spacing). 0, or -1 when a
 * result holds no finite segment. */
int cdsp_host_pipe_pair(const cdsp_result *a, const cdsp_result *b, double *angle_deg,
                        double *axis_distance, double *axis_distance_rms);
/* CSV columns a field flattens to, the name of column col (0-based) and
 * its value for r (text as in JSON: shortest round-trip numbers, true and
 * false); both return the length written (snprintf's). */
int cdsp_host_field_columns(const cdsp_host_field *f);
size_t cdsp_host_field_column_name(const cdsp_host_field *f, int col, char *buf, size_t cap);
size_t cdsp_host_field_csv(const cdsp_host_field *f, const cdsp_result *r, int col, char *buf,
                           size_t cap);

/*
 * The pose part of a record, written into an open object; the same names
 * in cdsp_tool solve and cdspd --format json:
 *   "status": "ok" | "error"
 *   "error": token (only when status is "error"): error_token if not NULL,
 *            else cdsp_status_token(st)
 *   "radius": always
 *   and only when st == CDSP_OK (r != NULL) the fields of
 *   cdsp_host_pose_fields() in order ("point", "direction", ..., "sigma"
 *   {"point", "direction", "distance"}, "edges", "tracked", "full_search",
 *   "truncated").
 */
void cdsp_host_json_pose(cdsp_host_json *j, cdsp_status st, const char *error_token,
                         const cdsp_result *r, cdsp_real radius);

/*
 * Every pipe of a frame (issue 13), written into an open object after the
 * pose: "pipes": [{the fields of cdsp_host_pipe_fields()}, ...] (best
 * first; "track_id" only when tracking != 0) and "pairs": [{"i", "j",
 * "angle_deg", "axis_distance", "axis_distance_rms"}, ...] for every i < j
 * (cdsp_host_pipe_pair; a pair without a finite segment is left out).
 * n may be 0 (two empty lists).
 */
void cdsp_host_json_pipes(cdsp_host_json *j, const cdsp_result *pipes, size_t n, int tracking);

/* Bytes one entry of "pipes" and of "pairs" take at most. */
#define CDSP_HOST_JSON_PIPE_MAX 1536
#define CDSP_HOST_JSON_PAIR_MAX 192
/* ... and the two lists for n pipes. */
#define CDSP_HOST_JSON_PIPES_MAX(n) (64 + (n) * CDSP_HOST_JSON_PIPE_MAX + (n) * (n) / 2 * CDSP_HOST_JSON_PAIR_MAX)

/* Ground truth of an axis through point with direction dir (any length):
 * the foot of the perpendicular from the optical centre (P_C), the unit
 * direction with cdsp_result's sign rule (largest-magnitude component
 * positive) and |P_C|. */
void cdsp_host_axis_truth(const double point[3], const double dir[3], double foot[3],
                          double unit[3], double *distance);

/* Bytes the pose fields take at most (every number at its longest); size
 * a record buffer as this plus the caller's own fields. */
#define CDSP_HOST_JSON_POSE_MAX 2048

/* ------------------------------------------------------------------------
 * Running until told to stop (clock.c, stop.c): what cdsp_tool listen and
 * the test peers (receivers, fake camera, feeders) share.
 * ---------------------------------------------------------------------- */
/* CLOCK_MONOTONIC, seconds. */
double cdsp_host_now_s(void);
/* SIGINT and SIGTERM set the process's stop flag (cleared here) and
 * interrupt blocking calls (no SA_RESTART); cdsp_host_stop_requested()
 * reads it. */
void cdsp_host_stop_on_signals(void);
int cdsp_host_stop_requested(void);

#ifdef __cplusplus
}
#endif

#endif /* CDSP_HOST_H */
