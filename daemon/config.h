/*
 * config.h - cdspd's configuration: every setting is a key (the YAML
 * config file's key path, e.g. "sim.rate"), the command-line options are
 * shortcuts for keys, and --set KEY=VALUE reaches any key. One table
 * (config.c) gives each key its type, range, default and help, so the file
 * parser, --set, --check-config's dump and docs/cdspd.md agree.
 *
 * Order: defaults, then the config file, then the command line in order.
 * cdspd_config_finish() then checks what needs the whole picture (required
 * keys, the calibration file, the destinations) and loads/resolves them.
 *
 * Errors: functions return 0 or -1 and write one line into err that names
 * the key and the problem ("cam.yaml:3:7: key 'sim.rate': expected a
 * number in [0, 100000], got 'fast'"). cdspd exits with status 2 on them.
 */
#ifndef CDSPD_CONFIG_H
#define CDSPD_CONFIG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/socket.h>

#include "cdsp.h"
#include "log.h"

#define CDSPD_MAX_DEST 16
#define CDSPD_MAX_MAVLINK 8
#define CDSPD_STR 1024

typedef struct {
    char text[CDSPD_STR];          /* as given: "HOST:PORT" */
    struct sockaddr_storage addr;  /* resolved by cdspd_config_finish */
    socklen_t addr_len;
    int multicast, broadcast;      /* what the resolved address is */
} cdspd_dest;

typedef enum { CDSPD_FORMAT_BINARY = 0, CDSPD_FORMAT_JSON = 1 } cdspd_format;

typedef struct {
    /* the command line's keys */
    char source[CDSPD_STR];
    char calib[CDSPD_STR];
    double radius;
    int n_dest;
    cdspd_dest dest[CDSPD_MAX_DEST];
    int format;                    /* cdspd_format */
    double duration;               /* seconds, 0 = until stopped */
    int frames;                    /* stop once this many were processed, 0 = no limit */
    char record[CDSPD_STR];        /* directory, "" = off */
    int record_every;
    int log_level;                 /* log.level, the default of every category */
    int log_cat[CDSPD_LOGC_COUNT]; /* log.<cat>, -1 = log.level */

    /* operation */
    double stats_interval;         /* seconds, 0 = only on SIGUSR1 */
    double status_interval;        /* seconds without a frame before a status datagram */
    double open_timeout;           /* seconds to find the source at start */
    double retry_min, retry_max;   /* reopen back-off, seconds */
    int proc_cpu, capture_cpu;     /* CPU to pin the thread to, -1 = any */

    /* solver: cdsp_params */
    int step, half_window, polarity, track_min_inliers;
    double min_contrast, track_band_px, min_distance, max_distance;
    double min_confidence; /* solver.min_confidence (issue 10) */
    int multi_pipe;        /* solver.multi_pipe (issue 13): every pipe in each record */
    int full_every;        /* solver.full_every: cdsp_tracker.full_every */
    int refine_step;       /* solver.refine_step (issue 13): cdsp_params.refine_step */
    int point_fit;         /* solver.point_fit (issue 13): cdsp_params.point_fit */
    int roi[4];
    uint64_t seed;
    int threads;           /* solver.threads (issue 17): cores per frame */

    /* net */
    int ttl;
    int multicast_loop;
    char multicast_if[CDSPD_STR];

    /* sim source */
    struct {
        double rate;
        int frames, bits, threads;
        double center[3], direction[3], sway[3];
        double tilt_deg, nod_deg, away;
        double ambient, noise, blur, texture;
        uint64_t seed;
        int truth;              /* JSON datagrams carry the frame's ground truth */
    } sim;

    /* file source */
    struct {
        double rate;
        int loop;
        double cache_mb;
    } file;

    /* aravis source */
    struct {
        char pixel_format[CDSPD_STR];   /* K_STR fields hold CDSPD_STR bytes */
        double exposure_us, gain, frame_rate;
        int region[4];
        int packet_size, buffers;
        int packet_socket;      /* 0 off, 1 on, 2 auto (off on loopback) */
        double frame_timeout;   /* seconds before a missing frame counts */
        /* pixel formats, triggers, clock (issue 18; docs/cdspd.md) */
        double bayer_gains[3];  /* camera's R, G, B responses; all 0 = measure per frame */
        int bayer_phase;        /* 0 the format names the image's phase, 1 the sensor's */
        int trigger_mode;       /* 0 leave, 1 off, 2 on */
        char trigger_source[CDSPD_STR];     /* "" leave; Software, Line0, Line1, ... */
        char trigger_activation[CDSPD_STR]; /* "" leave; RisingEdge, FallingEdge, ... */
        double trigger_rate;    /* software triggers per second cdspd sends; 0 none */
        int ptp;                /* 0 leave, 1 off, 2 on (GevIEEE1588 / PtpEnable) */
    } aravis;

    /* v4l2 source */
    struct {
        char format[CDSPD_STR]; /* "auto" or a fourcc (K_STR: CDSPD_STR bytes) */
        int buffers;
        double frame_rate;
    } v4l2;

    /* libcamera source */
    struct {
        char format[CDSPD_STR]; /* "auto" or a libcamera pixel format name (K_STR) */
        int buffers;
    } libcamera;

    /* MAVLink output and the camera's mounting (docs/mavlink.md) */
    int n_mavlink;
    char mavlink[CDSPD_MAX_MAVLINK][CDSPD_STR]; /* URLs: udpout://, serial://, serial_flowcontrol:// */
    int mavlink_system_id, mavlink_component_id;
    double mavlink_rate;           /* LANDING_TARGET per second at most, 0 = every frame */
    int mavlink_position_valid;    /* LANDING_TARGET with x, y, z, q (else angles only) */
    double mount[6];               /* roll, pitch, yaw (degrees), x, y, z (pose unit): mount.h */

    /* filled by cdspd_config_finish */
    cdsp_camera cam;
    char config_file[CDSPD_STR];   /* where the file values came from ("" none) */
} cdspd_config;

/* Defaults for every key. */
void cdspd_config_defaults(cdspd_config *c);

/* Set one key from its text form (a scalar, or a comma-separated list for
 * list keys, with optional [ ]). `where` prefixes messages ("--set",
 * "cdspd.yaml:4:3"). */
int cdspd_config_set(cdspd_config *c, const char *key, const char *value, const char *where,
                     char *err, size_t errlen);

/* Read a YAML config file (a mapping; nested mappings give dotted keys).
 * Unknown keys are errors (a typo must not be silently ignored). */
int cdspd_config_load_file(cdspd_config *c, const char *path, char *err, size_t errlen);

/* Check and complete: required keys, cross-key rules, source syntax, the
 * calibration (read into c->cam), destinations (resolved). */
int cdspd_config_finish(cdspd_config *c, char *err, size_t errlen);

/* The cdsp_params the solver keys describe. */
void cdspd_config_params(const cdspd_config *c, cdsp_params *p);

/* Effective log level of a category. */
int cdspd_config_log_level(const cdspd_config *c, int cat);

/* The effective configuration as YAML (the config file format). */
void cdspd_config_dump(const cdspd_config *c, FILE *f);

/* Key reference for --help-keys / docs: "key  type  default  help". */
void cdspd_config_help(FILE *f);

/* Source kinds as named in the source key. */
typedef enum {
    CDSPD_SRC_SIM, CDSPD_SRC_FILE, CDSPD_SRC_ARAVIS, CDSPD_SRC_V4L2, CDSPD_SRC_LIBCAMERA
} cdspd_source_kind;

/* Splits "kind:arg"; arg points into spec. -1 for an unknown kind. */
int cdspd_source_kind_parse(const char *spec, const char **arg);

#endif
