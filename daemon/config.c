/*
 * config.c - see config.h. The key table below is the whole configuration:
 * name, type, where the value lives, range, default and help. Defaults are
 * applied by parsing each key's default text, so there is one place for them.
 * The file is read with libyaml (the calibration's YAML stack).
 */
#define _POSIX_C_SOURCE 200809L
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include "addr.h"
#include "cdsp_host.h"
#include "host_yaml.h"
#include "mavout.h"
#include "mount.h"
#include "source.h"

typedef enum {
    K_STR,    /* char[CDSPD_STR] */
    K_REAL,   /* double in [min, max] */
    K_INT,    /* int in [min, max] */
    K_U64,    /* uint64_t */
    K_BOOL,   /* int 0/1: true/false, yes/no, on/off, 1/0 */
    K_CHOICE, /* int: index into choices "a|b|c" */
    K_VEC3,   /* double[3] */
    K_INT4,   /* int[4], each in [min, max] */
    K_DEST,   /* the destination list */
    K_LEVEL,  /* int log level; "default" = -1 (log.level) where allowed */
    K_MAVLINK,/* the MAVLink URL list */
    K_MOUNT,  /* double[6]: PRESET | [PRESET, x, y, z] | [roll, pitch, yaw, x, y, z] */
    K_POLARITY /* int cdsp_pair_params.polarity: bright +1, dark -1, any 0 (cdsp_tool's
                * words; the numbers are accepted too) */
} key_type;

/* K_POLARITY's words and values, in cdsp_tool solve --polarity's order. */
static const struct {
    const char *word;
    int value;
} polarity_words[] = {{"any", 0}, {"bright", 1}, {"dark", -1}};

typedef struct {
    const char *name;
    key_type type;
    size_t off;
    double min, max;
    const char *choices;
    const char *def;
    const char *help;
} key_def;

#define O(f) offsetof(cdspd_config, f)

static const key_def keys[] = {
    /* ---- the command line's keys -------------------------------------- */
    {"source", K_STR, O(source), 0, 0, NULL, "sim",
     "frame source: sim | file:GLOB | aravis:[ID] | v4l2:DEVICE | libcamera:[ID] (--source)"},
    {"calib", K_STR, O(calib), 0, 0, NULL, "",
     "camera calibration, ROS camera_info YAML; required (--calib)"},
    {"radius", K_REAL, O(radius), 0, 1e9, NULL, "0",
     "pipe radius, in the unit the poses are reported in (mm); required (--radius)"},
    {"dest", K_DEST, 0, 0, 0, NULL, "",
     "UDP destinations HOST:PORT (unicast, broadcast or multicast), a list; at least one, or a "
     "mavlink link (--dest)"},
    {"format", K_CHOICE, O(format), 0, 0, "binary|json", "binary",
     "datagram format: binary (docs/protocol.md) or json (one JSON object) (--format)"},
    {"duration", K_REAL, O(duration), 0, 1e9, NULL, "0",
     "stop after this many seconds, 0 = run until stopped (--duration)"},
    {"frames", K_INT, O(frames), 0, 2e9, NULL, "0",
     "stop once this many frames have been processed, 0 = no limit (--frames); with duration, "
     "whichever comes first"},
    {"record", K_STR, O(record), 0, 0, NULL, "",
     "directory to save every record_every-th frame and its result in, empty = off (--record)"},
    {"record_every", K_INT, O(record_every), 1, 1e9, NULL, "25",
     "record every N-th processed frame"},
    /* ---- log ------------------------------------------------------------ */
    {"log.level", K_LEVEL, O(log_level), 0, 0, NULL, "info",
     "log level of every category: error | warn | info | debug (-v: debug, -q: warn)"},
    {"log.main", K_LEVEL, O(log_cat[CDSPD_LOGC_MAIN]), 0, 0, NULL, "default",
     "start, stop, signals, reload; default = log.level"},
    {"log.config", K_LEVEL, O(log_cat[CDSPD_LOGC_CONFIG]), 0, 0, NULL, "default",
     "configuration messages"},
    {"log.source", K_LEVEL, O(log_cat[CDSPD_LOGC_SOURCE]), 0, 0, NULL, "default",
     "camera / source messages (open, lost, reconnect, bad frames)"},
    {"log.proc", K_LEVEL, O(log_cat[CDSPD_LOGC_PROC]), 0, 0, NULL, "default",
     "processing thread (debug: one line per frame)"},
    {"log.net", K_LEVEL, O(log_cat[CDSPD_LOGC_NET]), 0, 0, NULL, "default",
     "UDP sender (send errors are rate-limited)"},
    {"log.stats", K_LEVEL, O(log_cat[CDSPD_LOGC_STATS]), 0, 0, NULL, "default",
     "periodic statistics (logged at info)"},
    {"log.record", K_LEVEL, O(log_cat[CDSPD_LOGC_RECORD]), 0, 0, NULL, "default",
     "--record messages"},
    {"log.mavlink", K_LEVEL, O(log_cat[CDSPD_LOGC_MAVLINK]), 0, 0, NULL, "default",
     "MAVLink links (open, lost, reopened; write errors are rate-limited)"},
    /* ---- operation ------------------------------------------------------ */
    {"stats_interval", K_REAL, O(stats_interval), 0, 1e6, NULL, "10",
     "seconds between statistics lines, 0 = only on SIGUSR1"},
    {"status_interval", K_REAL, O(status_interval), 0.01, 3600, NULL, "0.5",
     "seconds without a frame before a status datagram is sent (and then every as long)"},
    {"open_timeout", K_REAL, O(open_timeout), 0, 3600, NULL, "10",
     "seconds to keep trying to open the source at start before giving up (exit status 3)"},
    {"retry_min", K_REAL, O(retry_min), 0.01, 3600, NULL, "0.5",
     "first delay before reopening a lost source, seconds; doubles up to retry_max"},
    {"retry_max", K_REAL, O(retry_max), 0.01, 3600, NULL, "10",
     "longest delay between reopening attempts, seconds"},
    {"proc_cpu", K_INT, O(proc_cpu), -1, 1023, NULL, "-1",
     "CPU the processing thread is pinned to, -1 = any"},
    {"capture_cpu", K_INT, O(capture_cpu), -1, 1023, NULL, "-1",
     "CPU the capture thread is pinned to, -1 = any"},
    /* ---- solver ----------------------------------------------------------- */
    {"solver.step", K_INT, O(step), 1, 64, NULL, "4", "edge scanline spacing, px (cdsp_edge_params.step)"},
    {"solver.half_window", K_INT, O(half_window), 2, 8, NULL, "4",
     "partial-area window half-length, px"},
    {"solver.min_contrast", K_REAL, O(min_contrast), 0, 1, NULL, "0.06",
     "minimum edge step, fraction of full scale (0 < value < 1)"},
    {"solver.polarity", K_POLARITY, O(polarity), -1, 1, NULL, "any",
     "bright: the pipe is brighter than the background, dark: darker, any: either (as cdsp_tool "
     "solve --polarity; 1, -1, 0 also accepted)"},
    {"solver.roi", K_INT4, O(roi), 0, 65535, NULL, "[0, 0, 0, 0]",
     "region searched [x, y, w, h], px; w or h 0 = whole frame"},
    {"solver.refine_step", K_INT, O(refine_step), 0, 64, NULL, "0",
     "0 = off; K >= 3: each pose's contours read again on every Kth scanline around them and "
     "refitted (cdsp_params.refine_step, cdsp_tool solve --refine-step; 1 and 2 are refused)"},
    {"solver.point_fit", K_BOOL, O(point_fit), 0, 1, NULL, "false",
     "with refine_step: each point of that pass fitted again to its window's pixels "
     "(cdsp_params.point_fit, cdsp_tool solve --point-fit)"},
    {"solver.track_band_px", K_REAL, O(track_band_px), 1, 1000, NULL, "12",
     "tracking: half-width of the band searched around the previous contours, px"},
    {"solver.track_min_inliers", K_INT, O(track_min_inliers), 2, 100000, NULL, "30",
     "tracking: fewer inliers per contour fall back to a full search"},
    {"solver.min_distance", K_REAL, O(min_distance), 0, 1e12, NULL, "0",
     "plausible |P_C| lower bound, radius units, 0 = none"},
    {"solver.max_distance", K_REAL, O(max_distance), 0, 1e12, NULL, "0",
     "plausible |P_C| upper bound, radius units, 0 = none"},
    {"solver.seed", K_U64, O(seed), 0, 0, NULL, "1", "seed of the solver's RANSAC generator"},
    /* ---- solver: detection (issue 10) -------------------------------------- */
    {"solver.min_confidence", K_REAL, O(min_confidence), 0, 1, NULL, "0",
     "poses with a lower confidence (0..1) are sent as no-pipe"},
    /* ---- solver: one frame over several cores (issue 17) ------------------- */
    {"solver.threads", K_INT, O(threads), 1, CDSP_EDGE_MAX_STRIPS, NULL, "1",
     "cores one frame's full search is spread over (strips; the pose is the one core's, bit for bit; "
     "solver.multi_pipe solves on one core)"},
    /* ---- solver: every pipe (issue 13) ------------------------------------- */
    {"solver.multi_pipe", K_BOOL, O(multi_pipe), 0, 1, NULL, "false",
     "every pipe in view in each record (binary: the pipe list; JSON: pipes and pairs), each "
     "with a track id"},
    {"solver.full_every", K_INT, O(full_every), 0, 1000000, NULL, "10",
     "with multi_pipe: a full search every Nth frame while every track holds, so that a pipe "
     "coming into view is found within N frames (cdsp_tracker.full_every); 0 = only when a "
     "track is lost"},
    /* ---- net -------------------------------------------------------------- */
    {"net.ttl", K_INT, O(ttl), 0, 255, NULL, "1", "multicast TTL (hops)"},
    {"net.multicast_loop", K_BOOL, O(multicast_loop), 0, 1, NULL, "true",
     "deliver multicast datagrams to receivers on this host too"},
    {"net.multicast_interface", K_STR, O(multicast_if), 0, 0, NULL, "",
     "IPv4 address of the interface multicast leaves by, empty = the routing table's"},
    /* ---- sim source ------------------------------------------------------- */
    {"sim.rate", K_REAL, O(sim.rate), 0, 100000, NULL, "25", "frames per second, 0 = as fast as possible"},
    {"sim.frames", K_INT, O(sim.frames), 1, 100000, NULL, "64",
     "frames rendered at start, evenly spread over one period of the path, then shown in turn"},
    {"sim.bits", K_INT, O(sim.bits), 8, 16, NULL, "8", "pixel depth: 8, or 10, 12, 14, 16 (two bytes per pixel)"},
    {"sim.threads", K_INT, O(sim.threads), 0, 256, NULL, "0",
     "threads rendering the frames at start, 0 = one per CPU"},
    {"sim.center", K_VEC3, O(sim.center), -1e9, 1e9, NULL, "[0, 0, 450]",
     "axis point at the middle of the path, camera frame (X right, Y down, Z forward)"},
    {"sim.direction", K_VEC3, O(sim.direction), -1e9, 1e9, NULL, "[0.15, 1, 0.1]",
     "axis direction at the middle of the path (need not be unit)"},
    {"sim.sway", K_VEC3, O(sim.sway), -1e9, 1e9, NULL, "[30, 0, 60]",
     "amplitudes of the point's motion: X sin a, Y sin 2a, Z cos a over the path phase a"},
    {"sim.tilt_deg", K_REAL, O(sim.tilt_deg), -90, 90, NULL, "15",
     "amplitude of the axis's rotation about the optical axis, degrees (times sin a)"},
    {"sim.nod_deg", K_REAL, O(sim.nod_deg), -90, 90, NULL, "5",
     "amplitude of its rotation about the camera's X axis, degrees (times cos a)"},
    {"sim.away", K_REAL, O(sim.away), 0, 1, NULL, "0.1",
     "fraction of the path (its end) where the pipe is out of view (status datagrams)"},
    {"sim.ambient", K_REAL, O(sim.ambient), 0, 1, NULL, "0.85",
     "ambient share of the shading, 1 = flat (libcdsp's default look)"},
    {"sim.noise", K_REAL, O(sim.noise), 0, 1, NULL, "0.004", "sensor noise sigma, fraction of full scale"},
    {"sim.blur", K_REAL, O(sim.blur), 0, CDSP_RENDER_MAX_BLUR_PX, NULL, "0.7",
     "optical blur sigma, px (libcdsp's renderer takes up to 8)"},
    {"sim.texture", K_REAL, O(sim.texture), 0, 1, NULL, "0.03", "background texture amplitude"},
    {"sim.seed", K_U64, O(sim.seed), 0, 0, NULL, "7", "seed of the rendered noise"},
    {"sim.truth", K_BOOL, O(sim.truth), 0, 1, NULL, "false",
     "JSON datagrams carry the frame's ground truth (\"truth\": point, direction, distance)"},
    /* ---- file source ------------------------------------------------------ */
    {"file.rate", K_REAL, O(file.rate), 0, 100000, NULL, "25", "frames per second, 0 = as fast as possible"},
    {"file.loop", K_BOOL, O(file.loop), 0, 1, NULL, "false",
     "start again after the last frame (else cdspd stops, exit status 0)"},
    {"file.cache_mb", K_REAL, O(file.cache_mb), 0, 1e6, NULL, "512",
     "decode all frames at start when they fit in this many MiB, else read each in turn"},
    /* ---- aravis source ---------------------------------------------------- */
    {"aravis.pixel_format", K_STR, O(aravis.pixel_format), 0, 0, NULL, "auto",
     "Mono8|10|12|16, Mono10|12Packed, Mono10|12p, BayerRG|GR|GB|BG8|10|12|16, RGB8, BGR8 | "
     "auto (mono first, then packed mono, then Bayer, then RGB)"},
    {"aravis.exposure_us", K_REAL, O(aravis.exposure_us), 0, 1e9, NULL, "0",
     "exposure time, us, 0 = leave the camera's"},
    {"aravis.gain", K_REAL, O(aravis.gain), -1, 1e6, NULL, "-1", "gain (camera units), -1 = leave"},
    {"aravis.frame_rate", K_REAL, O(aravis.frame_rate), 0, 100000, NULL, "0",
     "frames per second, 0 = leave the camera's"},
    {"aravis.region", K_INT4, O(aravis.region), 0, 65535, NULL, "[0, 0, 0, 0]",
     "sensor region [x, y, w, h]; w, h 0 = the calibration's size at x, y"},
    {"aravis.packet_size", K_INT, O(aravis.packet_size), 0, 65535, NULL, "0",
     "GigE Vision packet size, bytes, 0 = negotiated by Aravis"},
    {"aravis.buffers", K_INT, O(aravis.buffers), 2, 256, NULL, "8", "stream buffers queued to Aravis"},
    {"aravis.packet_socket", K_CHOICE, O(aravis.packet_socket), 0, 0, "off|on|auto", "auto",
     "Aravis's packet socket (root only): auto = off for loopback cameras (it sees nothing there)"},
    {"aravis.frame_timeout", K_REAL, O(aravis.frame_timeout), 0.1, 3600, NULL, "5",
     "seconds without any frame (complete or not) before the camera counts as lost"},
    /* ---- aravis: formats, triggers, clock (issue 18) ------------------------ */
    {"aravis.bayer_gains", K_VEC3, O(aravis.bayer_gains), 0, 1e6, NULL, "[0, 0, 0]",
     "Bayer/RGB: the camera's R, G, B responses (white balance ratios); [0, 0, 0] = "
     "measured in every frame (grey world)"},
    {"aravis.bayer_phase", K_CHOICE, O(aravis.bayer_phase), 0, 0, "image|sensor", "image",
     "what the Bayer format names: the delivered image's top-left cell (SFNC), or the "
     "sensor's (then an odd region offset shifts it)"},
    {"aravis.trigger_mode", K_CHOICE, O(aravis.trigger_mode), 0, 0, "leave|off|on", "leave",
     "TriggerMode of FrameStart: on = a frame per trigger; with a hardware trigger, no frame "
     "is not a lost camera"},
    {"aravis.trigger_source", K_STR, O(aravis.trigger_source), 0, 0, NULL, "",
     "TriggerSource: Software, Line0, Line1, ... as the camera names them; empty = leave"},
    {"aravis.trigger_activation", K_STR, O(aravis.trigger_activation), 0, 0, NULL, "",
     "TriggerActivation: RisingEdge, FallingEdge, AnyEdge, LevelHigh, LevelLow; empty = leave"},
    {"aravis.trigger_rate", K_REAL, O(aravis.trigger_rate), 0, 10000, NULL, "0",
     "software triggers per second cdspd sends (trigger_source Software); 0 = none"},
    {"aravis.ptp", K_CHOICE, O(aravis.ptp), 0, 0, "leave|off|on", "leave",
     "IEEE 1588 (PTP) time on the camera (PtpEnable or GevIEEE1588): t_camera_us is then "
     "PTP time"},
    /* ---- v4l2 source -------------------------------------------------------- */
    {"v4l2.format", K_STR, O(v4l2.format), 0, 0, NULL, "auto",
     "GREY | Y16 | YUYV | YU12 (libv4l2 converts to it) | auto (GREY, Y16, YUYV if offered, else YU12)"},
    {"v4l2.buffers", K_INT, O(v4l2.buffers), 2, 32, NULL, "4", "mmap buffers"},
    {"v4l2.frame_rate", K_REAL, O(v4l2.frame_rate), 0, 100000, NULL, "0",
     "frames per second asked of the driver, 0 = leave"},
    /* ---- libcamera source ----------------------------------------------------- */
    {"libcamera.format", K_STR, O(libcamera.format), 0, 0, NULL, "auto",
     "R8 | R10 | R12 | YUYV | NV12 | YUV420 | auto (the first the camera takes)"},
    {"libcamera.buffers", K_INT, O(libcamera.buffers), 2, 32, NULL, "4", "frame buffers"},
    /* ---- MAVLink and the mounting (docs/mavlink.md) ---------------------------- */
    {"mavlink", K_MAVLINK, 0, 0, 0, NULL, "",
     "MAVLink links: udpout://HOST:PORT | serial:///dev/DEVICE:BAUD | "
     "serial_flowcontrol:///dev/DEVICE:BAUD, a list (--mavlink)"},
    {"mavlink_system_id", K_INT, O(mavlink_system_id), 1, 255, NULL, "1",
     "MAVLink system id cdspd sends as (the vehicle's, usually 1)"},
    {"mavlink_component_id", K_INT, O(mavlink_component_id), 1, 255, NULL, "191",
     "MAVLink component id cdspd sends as (191 = MAV_COMP_ID_ONBOARD_COMPUTER)"},
    {"mavlink_rate", K_REAL, O(mavlink_rate), 0, 1000, NULL, "0",
     "at most this many LANDING_TARGET per second, 0 = one per frame with a pipe"},
    {"mavlink_position", K_BOOL, O(mavlink_position_valid), 0, 1, NULL, "true",
     "LANDING_TARGET carries the body-frame position (ArduPilot); false: angles only, "
     "position_valid 0 (PX4's IRLock-style path)"},
    {"mount", K_MOUNT, O(mount), -1e9, 1e9, NULL, "forward",
     "camera on the vehicle, optical -> body FRD: forward | down | down-right | down-aft | "
     "down-left, [PRESET, x, y, z] or [roll, pitch, yaw, x, y, z] (degrees; x, y, z of the "
     "optical centre in mm)"},
};

#define N_KEYS (sizeof keys / sizeof keys[0])

static void errf(char *err, size_t n, const char *fmt, ...) CDSPD_PRINTF(3, 4);
static void errf(char *err, size_t n, const char *fmt, ...)
{
    va_list ap;
    if (!err || !n)
        return;
    va_start(ap, fmt);
    vsnprintf(err, n, fmt, ap);
    va_end(ap);
}

static const key_def *find_key(const char *name)
{
    size_t i;
    for (i = 0; i < N_KEYS; i++)
        if (!strcmp(keys[i].name, name))
            return &keys[i];
    return NULL;
}

/* Is name a section ("sim", "log") of some key? */
static int is_section(const char *name)
{
    size_t i, n = strlen(name);
    for (i = 0; i < N_KEYS; i++)
        if (!strncmp(keys[i].name, name, n) && keys[i].name[n] == '.')
            return 1;
    return 0;
}

static const char *type_text(const key_def *k)
{
    switch (k->type) {
    case K_STR: return "text";
    case K_REAL: return "number";
    case K_INT: return "integer";
    case K_U64: return "integer";
    case K_BOOL: return "boolean";
    case K_CHOICE: return k->choices;
    case K_VEC3: return "[x, y, z]";
    case K_INT4: return "[x, y, w, h]";
    case K_DEST: return "list of HOST:PORT";
    case K_LEVEL: return "level";
    case K_MAVLINK: return "list of URLs";
    case K_MOUNT: return "preset or list";
    case K_POLARITY: return "any|bright|dark";
    }
    return "?";
}

static const char *trim(char *s)
{
    char *e;
    while (isspace((unsigned char)*s))
        s++;
    e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = 0;
    return s;
}

static int parse_real(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return end != s && !*end && !errno && isfinite(*v);
}

static int parse_long(const char *s, long long *v)
{
    char *end;
    errno = 0;
    *v = strtoll(s, &end, 0);
    return end != s && !*end && !errno;
}

/* Split a list "[a, b, c]" or "a,b,c" into at most max trimmed items in buf. */
static int split_list(const char *value, char *buf, size_t buflen, const char **items, int max)
{
    char *p, *q;
    int n = 0;
    if (strlen(value) >= buflen)
        return -1;
    strcpy(buf, value);
    p = (char *)trim(buf);
    if (*p == '[') {
        size_t l = strlen(p);
        if (l < 2 || p[l - 1] != ']')
            return -1;
        p[l - 1] = 0;
        p++;
    }
    if (!*trim(p))
        return 0;
    for (;;) {
        q = strchr(p, ',');
        if (q)
            *q = 0;
        if (n == max)
            return max + 1;
        items[n] = trim(p);
        {
            /* "a" or 'a': the quotes of a YAML flow item */
            char *it = (char *)items[n];
            size_t l = strlen(it);
            if (l >= 2 && (it[0] == '"' || it[0] == '\'') && it[l - 1] == it[0]) {
                it[l - 1] = 0;
                items[n] = it + 1;
            }
        }
        n++;
        if (!q)
            break;
        p = q + 1;
    }
    return n;
}

/* One key from text, within the table's type and range. */
static int set_value(cdspd_config *c, const char *key, const char *value, const char *where,
                     char *err, size_t errlen)
{
    const key_def *k = find_key(key);
    void *field;
    char buf[CDSPD_MAX_DEST * (CDSPD_STR + 2)];
    const char *items[CDSPD_MAX_DEST + 1];
    double v = 0;
    long long iv = 0;
    int n, i;

    if (!k) {
        errf(err, errlen, "%s: unknown key '%s' (cdspd --help-keys lists them)", where, key);
        return -1;
    }
    field = (char *)c + k->off;
    switch (k->type) {
    case K_STR:
        if (strlen(value) >= CDSPD_STR) {
            errf(err, errlen, "%s: key '%s': longer than %d characters", where, key, CDSPD_STR - 1);
            return -1;
        }
        strcpy(field, value);
        return 0;
    case K_REAL:
        if (!parse_real(value, &v) || v < k->min || v > k->max) {
            errf(err, errlen, "%s: key '%s': expected a number in [%g, %g], got '%s'", where, key,
                 k->min, k->max, value);
            return -1;
        }
        *(double *)field = v;
        return 0;
    case K_INT:
        if (!parse_long(value, &iv) || (double)iv < k->min || (double)iv > k->max) {
            errf(err, errlen, "%s: key '%s': expected an integer in [%g, %g], got '%s'", where, key,
                 k->min, k->max, value);
            return -1;
        }
        *(int *)field = (int)iv;
        return 0;
    case K_U64: {
        char *end;
        unsigned long long u;
        errno = 0;
        u = strtoull(value, &end, 0);
        if (end == value || *end || errno || value[0] == '-') {
            errf(err, errlen, "%s: key '%s': expected a non-negative integer, got '%s'", where, key,
                 value);
            return -1;
        }
        *(uint64_t *)field = (uint64_t)u;
        return 0;
    }
    case K_BOOL: {
        static const char *const yes[] = {"true", "yes", "on", "1"}, *const no[] = {"false", "no", "off", "0"};
        for (i = 0; i < 4; i++) {
            if (!strcmp(value, yes[i])) {
                *(int *)field = 1;
                return 0;
            }
            if (!strcmp(value, no[i])) {
                *(int *)field = 0;
                return 0;
            }
        }
        errf(err, errlen, "%s: key '%s': expected true or false, got '%s'", where, key, value);
        return -1;
    }
    case K_CHOICE: {
        const char *p = k->choices;
        int idx = 0;
        size_t l = strlen(value);
        while (p) {
            const char *bar = strchr(p, '|');
            size_t pl = bar ? (size_t)(bar - p) : strlen(p);
            if (pl == l && !strncmp(p, value, l)) {
                *(int *)field = idx;
                return 0;
            }
            idx++;
            p = bar ? bar + 1 : NULL;
        }
        errf(err, errlen, "%s: key '%s': expected one of %s, got '%s'", where, key, k->choices, value);
        return -1;
    }
    case K_POLARITY:
        for (i = 0; i < 3; i++)
            if (!strcmp(value, polarity_words[i].word)) {
                *(int *)field = polarity_words[i].value;
                return 0;
            }
        if (parse_long(value, &iv) && iv >= -1 && iv <= 1) { /* the library's numbers */
            *(int *)field = (int)iv;
            return 0;
        }
        errf(err, errlen, "%s: key '%s': expected any, bright or dark (or 0, 1, -1), got '%s'",
             where, key, value);
        return -1;
    case K_LEVEL: {
        int lv = cdspd_log_level_parse(value);
        if (lv < 0 && !strcmp(value, "default") && strcmp(key, "log.level"))
            lv = -1;
        else if (lv < 0) {
            errf(err, errlen, "%s: key '%s': expected error, warn, info or debug%s, got '%s'", where,
                 key, strcmp(key, "log.level") ? " (or default)" : "", value);
            return -1;
        }
        *(int *)field = lv;
        return 0;
    }
    case K_VEC3:
    case K_INT4: {
        int want = k->type == K_VEC3 ? 3 : 4;
        n = split_list(value, buf, sizeof buf, items, want);
        if (n != want) {
            errf(err, errlen, "%s: key '%s': expected %d numbers %s, got '%s'", where, key, want,
                 type_text(k), value);
            return -1;
        }
        for (i = 0; i < want; i++) {
            int ok = k->type == K_VEC3 ? parse_real(items[i], &v)
                                       : (parse_long(items[i], &iv) && (v = (double)iv, 1));
            if (!ok || v < k->min || v > k->max) {
                errf(err, errlen, "%s: key '%s': item %d: expected %s in [%g, %g], got '%s'", where,
                     key, i + 1, k->type == K_VEC3 ? "a number" : "an integer", k->min, k->max,
                     items[i]);
                return -1;
            }
            if (k->type == K_VEC3)
                ((double *)field)[i] = v;
            else
                ((int *)field)[i] = (int)iv;
        }
        return 0;
    }
    case K_DEST:
        n = split_list(value, buf, sizeof buf, items, CDSPD_MAX_DEST);
        if (n < 0 || n > CDSPD_MAX_DEST) {
            errf(err, errlen, "%s: key 'dest': at most %d destinations, each shorter than %d "
                 "characters", where, CDSPD_MAX_DEST, CDSPD_STR);
            return -1;
        }
        for (i = 0; i < n; i++) {
            if (!*items[i] || strlen(items[i]) >= CDSPD_STR) {
                errf(err, errlen, "%s: key 'dest': item %d: expected HOST:PORT, got '%s'", where,
                     i + 1, items[i]);
                return -1;
            }
        }
        c->n_dest = n;
        for (i = 0; i < n; i++) {
            memset(&c->dest[i], 0, sizeof c->dest[i]);
            strcpy(c->dest[i].text, items[i]);
        }
        return 0;
    case K_MAVLINK:
        n = split_list(value, buf, sizeof buf, items, CDSPD_MAX_MAVLINK);
        if (n < 0 || n > CDSPD_MAX_MAVLINK) {
            errf(err, errlen, "%s: key 'mavlink': at most %d links, each shorter than %d characters",
                 where, CDSPD_MAX_MAVLINK, CDSPD_STR);
            return -1;
        }
        for (i = 0; i < n; i++) {
            cdspd_mavlink_url u;
            char e[CDSPD_STR + 256];
            if (!*items[i] || strlen(items[i]) >= CDSPD_STR) {
                errf(err, errlen, "%s: key 'mavlink': item %d: expected a URL, got '%s'", where,
                     i + 1, items[i]);
                return -1;
            }
            /* the syntax here, with the file's line; the host in finish */
            if (cdspd_mavlink_url_parse(items[i], &u, 0, e, sizeof e)) {
                errf(err, errlen, "%s: key 'mavlink': %s", where, e);
                return -1;
            }
        }
        c->n_mavlink = n;
        for (i = 0; i < n; i++)
            strcpy(c->mavlink[i], items[i]);
        return 0;
    case K_MOUNT: {
        double m[6] = {0, 0, 0, 0, 0, 0};
        int first = 0;
        n = split_list(value, buf, sizeof buf, items, 6);
        if (n == 1 || n == 4) {
            if (cdspd_mount_preset(items[0], m)) {
                errf(err, errlen, "%s: key 'mount': unknown preset '%s' (expected %s, or "
                     "[roll, pitch, yaw, x, y, z])", where, items[0], cdspd_mount_preset_names());
                return -1;
            }
            first = 3;
        } else if (n != 6) {
            errf(err, errlen, "%s: key 'mount': expected PRESET, [PRESET, x, y, z] or "
                 "[roll, pitch, yaw, x, y, z], got '%s'", where, value);
            return -1;
        }
        for (i = n == 6 ? 0 : 1; i < n; i++) {
            if (!parse_real(items[i], &v) || v < k->min || v > k->max) {
                errf(err, errlen, "%s: key 'mount': item %d: expected a number, got '%s'", where,
                     i + 1, items[i]);
                return -1;
            }
            m[n == 6 ? i : first + i - 1] = v;
        }
        memcpy(field, m, sizeof m);
        return 0;
    }
    }
    return -1;
}

/* The solver keys' block of cdspd_config (step .. seed), saved to undo a
 * value libcdsp refuses. */
#define SOLVER_FIRST O(step)
#define SOLVER_END (O(seed) + sizeof(uint64_t))

int cdspd_config_set(cdspd_config *c, const char *key, const char *value, const char *where,
                     char *err, size_t errlen)
{
    unsigned char saved[SOLVER_END - SOLVER_FIRST];
    cdsp_params p;
    cdsp_status st;
    int solver = !strncmp(key, "solver.", 7);
    if (solver)
        memcpy(saved, (char *)c + SOLVER_FIRST, sizeof saved);
    if (set_value(c, key, value, where, err, errlen))
        return -1;
    if (!solver)
        return 0;
    /* the library's own checks, at load time: a value the table's range
     * lets through (min_contrast 0 or 1) must not turn every frame into
     * bad-argument later. The one rule between two keys, point_fit only
     * with refine_step (cdsp.h), waits for the whole configuration
     * (cdspd_config_finish): a file may set point_fit before refine_step. */
    cdspd_config_params(c, &p);
    if (p.refine_step == 0)
        p.point_fit = 0;
    st = cdsp_params_check(&p);
    if (st != CDSP_OK) {
        memcpy((char *)c + SOLVER_FIRST, saved, sizeof saved);
        errf(err, errlen, "%s: key '%s': libcdsp refuses '%s' (%s; the ranges are in cdsp.h)",
             where, key, value, cdsp_strerror(st));
        return -1;
    }
    return 0;
}

void cdspd_config_defaults(cdspd_config *c)
{
    size_t i;
    char err[256];
    cdsp_params p;
    memset(c, 0, sizeof *c);
    for (i = 0; i < N_KEYS; i++)
        if (set_value(c, keys[i].name, keys[i].def, "default", err, sizeof err))
            abort(); /* a broken table: caught by the first test run */
    cdspd_config_params(c, &p);
    if (cdsp_params_check(&p) != CDSP_OK)
        abort(); /* defaults the library refuses: the same */
}

/* ------------------------------------------------------------------------
 * YAML file.
 * ---------------------------------------------------------------------- */
typedef struct {
    yaml_document_t *doc;
    const char *path;
    cdspd_config *c;
    char *err;
    size_t errlen;
    unsigned long line[N_KEYS]; /* where each key was set, 1-based; 0 = not yet */
} yaml_walk;

/* The same key or section twice in one mapping (libyaml keeps both; the
 * last would silently win): the line of the first, or 0. */
static unsigned long earlier_twin(const yaml_walk *w, const yaml_node_t *map,
                                  const yaml_node_pair_t *pair, const yaml_node_t *kn)
{
    const yaml_node_pair_t *q;
    for (q = map->data.mapping.pairs.start; q < pair; q++) {
        const yaml_node_t *qk = yaml_document_get_node(w->doc, q->key);
        if (qk && qk->type == YAML_SCALAR_NODE && qk->data.scalar.length == kn->data.scalar.length &&
            !memcmp(qk->data.scalar.value, kn->data.scalar.value, kn->data.scalar.length))
            return (unsigned long)qk->start_mark.line + 1;
    }
    return 0;
}

/* A key set twice (also "sim.rate" beside "sim: {rate}"): 0, or -1 with err. */
static int first_time(yaml_walk *w, const char *name, const yaml_node_t *kn, const char *where)
{
    const key_def *k = find_key(name);
    size_t i;
    if (!k)
        return 0;
    i = (size_t)(k - keys);
    if (w->line[i]) {
        errf(w->err, w->errlen, "%s: key '%s' given twice (first at line %lu)", where, name,
             w->line[i]);
        return -1;
    }
    w->line[i] = (unsigned long)kn->start_mark.line + 1;
    return 0;
}

static void where_of(const yaml_walk *w, const yaml_node_t *n, char *buf, size_t len)
{
    snprintf(buf, len, "%s:%lu:%lu", w->path, (unsigned long)n->start_mark.line + 1,
             (unsigned long)n->start_mark.column + 1);
}

static int walk_mapping(yaml_walk *w, yaml_node_t *map, const char *prefix)
{
    yaml_node_pair_t *pair;
    char where[CDSPD_STR + 32];
    for (pair = map->data.mapping.pairs.start; pair < map->data.mapping.pairs.top; pair++) {
        yaml_node_t *kn = yaml_document_get_node(w->doc, pair->key);
        yaml_node_t *vn = yaml_document_get_node(w->doc, pair->value);
        char name[256];
        if (!kn || !vn)
            continue;
        where_of(w, kn, where, sizeof where);
        if (kn->type != YAML_SCALAR_NODE) {
            errf(w->err, w->errlen, "%s: a key must be a plain name", where);
            return -1;
        }
        if ((size_t)snprintf(name, sizeof name, "%s%s%s", prefix, *prefix ? "." : "",
                             (const char *)kn->data.scalar.value) >= sizeof name) {
            errf(w->err, w->errlen, "%s: key too long", where);
            return -1;
        }
        {
            unsigned long twin = earlier_twin(w, map, pair, kn);
            if (twin) {
                errf(w->err, w->errlen, "%s: %s '%s' given twice (first at line %lu)", where,
                     vn->type == YAML_MAPPING_NODE ? "section" : "key", name, twin);
                return -1;
            }
        }
        if (vn->type != YAML_MAPPING_NODE && first_time(w, name, kn, where))
            return -1;
        if (vn->type == YAML_MAPPING_NODE) {
            if (!is_section(name)) {
                errf(w->err, w->errlen, "%s: key '%s' %s", where, name,
                     find_key(name) ? "takes a value, not a mapping"
                                    : "is not a section (cdspd --help-keys lists the keys)");
                return -1;
            }
            if (walk_mapping(w, vn, name))
                return -1;
        } else if (vn->type == YAML_SEQUENCE_NODE) {
            const key_def *k = find_key(name);
            char list[CDSPD_MAX_DEST * (CDSPD_STR + 2)];
            size_t used = 0;
            yaml_node_item_t *it;
            if (!k) {
                errf(w->err, w->errlen, "%s: unknown key '%s' (cdspd --help-keys lists them)", where,
                     name);
                return -1;
            }
            if (k->type != K_VEC3 && k->type != K_INT4 && k->type != K_DEST &&
                k->type != K_MAVLINK && k->type != K_MOUNT) {
                errf(w->err, w->errlen, "%s: key '%s': expected %s, got a list", where, name,
                     type_text(k));
                return -1;
            }
            list[0] = 0;
            for (it = vn->data.sequence.items.start; it < vn->data.sequence.items.top; it++) {
                yaml_node_t *in = yaml_document_get_node(w->doc, *it);
                size_t l;
                if (!in || in->type != YAML_SCALAR_NODE) {
                    where_of(w, in ? in : vn, where, sizeof where);
                    errf(w->err, w->errlen, "%s: key '%s': list items must be plain values", where,
                         name);
                    return -1;
                }
                l = strlen((const char *)in->data.scalar.value);
                if (strchr((const char *)in->data.scalar.value, ',') || used + l + 2 > sizeof list) {
                    errf(w->err, w->errlen, "%s: key '%s': bad list item '%s'", where, name,
                         (const char *)in->data.scalar.value);
                    return -1;
                }
                if (used)
                    list[used++] = ',';
                memcpy(list + used, in->data.scalar.value, l + 1);
                used += l;
            }
            if (cdspd_config_set(w->c, name, list, where, w->err, w->errlen))
                return -1;
        } else {
            if (!find_key(name) && !is_section(name)) {
                errf(w->err, w->errlen, "%s: unknown key '%s' (cdspd --help-keys lists them)", where,
                     name);
                return -1;
            }
            where_of(w, vn, where, sizeof where);
            if (!find_key(name) && is_section(name)) {
                errf(w->err, w->errlen, "%s: key '%s' is a section: expected a mapping", where, name);
                return -1;
            }
            if (cdspd_config_set(w->c, name, (const char *)vn->data.scalar.value, where, w->err,
                                 w->errlen))
                return -1;
        }
    }
    return 0;
}

int cdspd_config_load_file(cdspd_config *c, const char *path, char *err, size_t errlen)
{
    yaml_document_t doc;
    yaml_node_t *root;
    yaml_walk w;
    void *text = NULL;
    size_t len = 0;
    cdsp_host_err herr;
    int rc = -1;

    if (strlen(path) >= CDSPD_STR) {
        errf(err, errlen, "%s: path too long", path);
        return -1;
    }
    if (cdsp_host_read_file(path, CDSP_HOST_YAML_MAX_BYTES, &text, &len, &herr)) {
        errf(err, errlen, "%s", herr.msg);
        return -1;
    }
    /* bounded (depth, aliases) before libyaml builds the document: a
     * SIGHUP reload of a hostile file must not stall the main loop */
    if (cdsp_host_yaml_load(text, len, path, &doc, &herr)) {
        errf(err, errlen, "%s", herr.msg);
        free(text);
        return -1;
    }
    root = yaml_document_get_root_node(&doc);
    memset(&w, 0, sizeof w);
    w.doc = &doc;
    w.path = path;
    w.c = c;
    w.err = err;
    w.errlen = errlen;
    if (!root) {
        rc = 0; /* an empty file: all defaults */
    } else if (root->type != YAML_MAPPING_NODE) {
        errf(err, errlen, "%s:%lu:%lu: expected a mapping of keys (key: value)", path,
             (unsigned long)root->start_mark.line + 1, (unsigned long)root->start_mark.column + 1);
    } else {
        rc = walk_mapping(&w, root, "");
    }
    if (rc == 0)
        strcpy(c->config_file, path);
    yaml_document_delete(&doc);
    free(text);
    return rc;
}

int cdspd_source_kind_parse(const char *spec, const char **arg)
{
    static const struct {
        const char *name;
        int kind;
    } kinds[] = {{"sim", CDSPD_SRC_SIM},
                 {"file", CDSPD_SRC_FILE},
                 {"aravis", CDSPD_SRC_ARAVIS},
                 {"v4l2", CDSPD_SRC_V4L2},
                 {"libcamera", CDSPD_SRC_LIBCAMERA}};
    size_t i;
    for (i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        size_t l = strlen(kinds[i].name);
        if (!strncmp(spec, kinds[i].name, l) && (spec[l] == ':' || !spec[l])) {
            *arg = spec[l] ? spec + l + 1 : spec + l;
            return kinds[i].kind;
        }
    }
    *arg = NULL;
    return -1;
}

static int mkdir_p(const char *path)
{
    char buf[CDSPD_STR];
    char *p;
    struct stat st;
    if (strlen(path) >= sizeof buf)
        return -1;
    strcpy(buf, path);
    for (p = buf + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = 0;
        if (mkdir(buf, 0755) && errno != EEXIST)
            return -1;
        *p = '/';
    }
    if (mkdir(buf, 0755) && errno != EEXIST)
        return -1;
    if (stat(buf, &st) || !S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

int cdspd_config_finish(cdspd_config *c, char *err, size_t errlen)
{
    cdsp_host_err herr;
    const char *arg;
    int kind, i;
    double n2;

    kind = cdspd_source_kind_parse(c->source, &arg);
    if (kind < 0) {
        errf(err, errlen, "key 'source': unknown source '%s' (expected sim, file:GLOB, "
             "aravis:[ID], v4l2:DEVICE or libcamera:[ID])", c->source);
        return -1;
    }
    if ((kind == CDSPD_SRC_FILE || kind == CDSPD_SRC_V4L2) && !*arg) {
        errf(err, errlen, "key 'source': '%s' needs %s after the colon", c->source,
             kind == CDSPD_SRC_FILE ? "a file name or pattern" : "a device (/dev/videoN)");
        return -1;
    }
    if (kind == CDSPD_SRC_SIM && *arg) {
        errf(err, errlen, "key 'source': 'sim' takes no argument (got '%s'; the sim.* keys set it up)",
             c->source);
        return -1;
    }
    /* a replay of a recording needs no --calib: --record saved it beside */
    if (!*c->calib && kind == CDSPD_SRC_FILE)
        cdspd_src_file_find_calib(arg, c->calib, sizeof c->calib);
    if (!*c->calib) {
        errf(err, errlen, "key 'calib': required: the camera calibration (--calib CAM.yaml%s)",
             kind == CDSPD_SRC_FILE ? "; none beside the frames either: DIR/RUN.yaml as --record "
                                      "saves it, or DIR/camera.yaml" : "");
        return -1;
    }
    if (!(c->radius > 0)) {
        errf(err, errlen, "key 'radius': required: the pipe radius, a positive number (--radius R)");
        return -1;
    }
    if (c->n_dest < 1 && c->n_mavlink < 1) {
        errf(err, errlen, "key 'dest': required: at least one HOST:PORT to send poses to (--dest), "
             "or a MAVLink link (--mavlink)");
        return -1;
    }
    for (i = 0; i < c->n_mavlink; i++) {
        cdspd_mavlink_url u;
        char e[CDSPD_STR + 256];
        if (cdspd_mavlink_url_parse(c->mavlink[i], &u, 1, e, sizeof e)) {
            errf(err, errlen, "key 'mavlink': %s", e);
            return -1;
        }
    }
    if (c->retry_min > c->retry_max) {
        errf(err, errlen, "key 'retry_min': %g is more than retry_max (%g)", c->retry_min, c->retry_max);
        return -1;
    }
    /* the point fit refits the final pass's points: libcdsp refuses it
     * without that pass (cdsp_params_check); said here with the keys' names */
    if (c->point_fit && c->refine_step < 3) {
        errf(err, errlen, "key 'solver.point_fit': needs solver.refine_step 3 or more (the final "
             "pass it refits), got refine_step %d", c->refine_step);
        return -1;
    }
    if (c->min_distance > 0 && c->max_distance > 0 && c->min_distance >= c->max_distance) {
        errf(err, errlen, "key 'solver.min_distance': %g is not below solver.max_distance (%g)",
             c->min_distance, c->max_distance);
        return -1;
    }
    n2 = c->sim.direction[0] * c->sim.direction[0] + c->sim.direction[1] * c->sim.direction[1] +
         c->sim.direction[2] * c->sim.direction[2];
    if (!(n2 > 1e-18)) {
        errf(err, errlen, "key 'sim.direction': must not be zero");
        return -1;
    }
    if (c->sim.bits % 2) {
        errf(err, errlen, "key 'sim.bits': expected 8, 10, 12, 14 or 16, got %d", c->sim.bits);
        return -1;
    }
    if (*c->multicast_if) {
        struct in_addr a;
        if (inet_pton(AF_INET, c->multicast_if, &a) != 1) {
            errf(err, errlen, "key 'net.multicast_interface': expected an IPv4 address, got '%s'",
                 c->multicast_if);
            return -1;
        }
    }
    if (cdsp_host_calib_read(c->calib, &c->cam, &herr)) {
        errf(err, errlen, "key 'calib': %s", herr.msg);
        return -1;
    }
    if (c->roi[2] || c->roi[3]) {
        if (c->roi[0] + c->roi[2] > c->cam.width || c->roi[1] + c->roi[3] > c->cam.height ||
            !c->roi[2] || !c->roi[3]) {
            errf(err, errlen, "key 'solver.roi': [%d, %d, %d, %d] is not inside the %dx%d frame of %s",
                 c->roi[0], c->roi[1], c->roi[2], c->roi[3], c->cam.width, c->cam.height, c->calib);
            return -1;
        }
    }
    for (i = 0; i < c->n_dest; i++) {
        cdspd_dest *d = &c->dest[i];
        cdsp_host_err e;
        if (cdsp_host_addr_parse(d->text, 0, &d->addr, &d->addr_len, &e)) {
            errf(err, errlen, "key 'dest': %s", e.msg);
            return -1;
        }
        if (d->addr.ss_family == AF_INET) {
            uint32_t a = ntohl(((struct sockaddr_in *)&d->addr)->sin_addr.s_addr);
            d->multicast = (a >> 28) == 14;
            /* the limited broadcast, or a host part of all ones is a guess:
             * SO_BROADCAST is set anyway, this only labels the log */
            d->broadcast = a == 0xFFFFFFFFu || (a & 0xFF) == 0xFF;
        } else {
            const struct sockaddr_in6 *s6 = (const struct sockaddr_in6 *)&d->addr;
            d->multicast = s6->sin6_addr.s6_addr[0] == 0xFF;
        }
    }
    if (*c->record && mkdir_p(c->record)) {
        errf(err, errlen, "key 'record': cannot create the directory '%s': %s", c->record,
             strerror(errno));
        return -1;
    }
    if (*c->record && access(c->record, W_OK | X_OK)) {
        errf(err, errlen, "key 'record': cannot write into '%s': %s", c->record, strerror(errno));
        return -1;
    }
    return 0;
}

void cdspd_config_params(const cdspd_config *c, cdsp_params *p)
{
    cdsp_params_default(p);
    p->edge.step = c->step;
    p->edge.half_window = c->half_window;
    p->edge.min_contrast = (cdsp_real)c->min_contrast;
    p->min_confidence = (cdsp_real)c->min_confidence;
    p->edge.roi.x = c->roi[0];
    p->edge.roi.y = c->roi[1];
    p->edge.roi.w = c->roi[2];
    p->edge.roi.h = c->roi[3];
    p->pair.polarity = c->polarity;
    p->pair.min_distance = (cdsp_real)c->min_distance;
    p->pair.max_distance = (cdsp_real)c->max_distance;
    p->track_band_px = (cdsp_real)c->track_band_px;
    p->track_min_inliers = c->track_min_inliers;
    p->refine_step = c->refine_step;
    p->point_fit = c->point_fit;
}

int cdspd_config_log_level(const cdspd_config *c, int cat)
{
    return c->log_cat[cat] >= 0 ? c->log_cat[cat] : c->log_level;
}

/* ------------------------------------------------------------------------
 * Dump and help.
 * ---------------------------------------------------------------------- */
static void fmt_real(char *buf, size_t n, double v)
{
    char tmp[32];
    cdsp_host_fmt_real(tmp, v);
    snprintf(buf, n, "%s", tmp);
}

static void yaml_quote(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            fputc('\\', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* A YAML flow list of n quoted texts, stride bytes apart from first. */
static void dump_texts(FILE *f, const char *first, size_t stride, int n)
{
    int i;
    fputc('[', f);
    for (i = 0; i < n; i++) {
        if (i)
            fputs(", ", f);
        yaml_quote(f, first + (size_t)i * stride);
    }
    fputc(']', f);
}

/* A YAML flow list of n numbers. */
static void dump_reals(FILE *f, const double *v, int n)
{
    char b[32];
    int i;
    fputc('[', f);
    for (i = 0; i < n; i++) {
        fmt_real(b, sizeof b, v[i]);
        fprintf(f, "%s%s", i ? ", " : "", b);
    }
    fputc(']', f);
}

static void dump_value(const cdspd_config *c, const key_def *k, FILE *f)
{
    const void *field = (const char *)c + k->off;
    char b[32];
    int i;
    switch (k->type) {
    case K_STR: yaml_quote(f, field); break;
    case K_REAL: fmt_real(b, sizeof b, *(const double *)field); fputs(b, f); break;
    case K_INT: fprintf(f, "%d", *(const int *)field); break;
    case K_U64: fprintf(f, "%llu", (unsigned long long)*(const uint64_t *)field); break;
    case K_BOOL: fputs(*(const int *)field ? "true" : "false", f); break;
    case K_CHOICE: {
        const char *p = k->choices;
        int idx = *(const int *)field;
        for (i = 0; i < idx && p; i++) {
            p = strchr(p, '|');
            if (p)
                p++;
        }
        if (p)
            fprintf(f, "%.*s", (int)(strchr(p, '|') ? (size_t)(strchr(p, '|') - p) : strlen(p)), p);
        break;
    }
    case K_LEVEL: {
        int lv = *(const int *)field;
        fputs(lv < 0 ? "default" : cdspd_log_level_name(lv), f);
        break;
    }
    case K_POLARITY:
        for (i = 0; i < 3; i++)
            if (*(const int *)field == polarity_words[i].value)
                fputs(polarity_words[i].word, f);
        break;
    case K_VEC3:
        dump_reals(f, field, 3);
        break;
    case K_INT4:
        fprintf(f, "[%d, %d, %d, %d]", ((const int *)field)[0], ((const int *)field)[1],
                ((const int *)field)[2], ((const int *)field)[3]);
        break;
    case K_DEST:
        dump_texts(f, c->dest[0].text, sizeof c->dest[0], c->n_dest);
        break;
    case K_MAVLINK:
        dump_texts(f, c->mavlink[0], sizeof c->mavlink[0], c->n_mavlink);
        break;
    case K_MOUNT:
        dump_reals(f, field, 6);
        break;
    }
}

void cdspd_config_dump(const cdspd_config *c, FILE *f)
{
    size_t i;
    char section[64] = "";
    for (i = 0; i < N_KEYS; i++) {
        const char *dot = strchr(keys[i].name, '.');
        const char *leaf = keys[i].name;
        if (dot) {
            size_t l = (size_t)(dot - keys[i].name);
            if (strlen(section) != l || strncmp(section, keys[i].name, l)) {
                snprintf(section, sizeof section, "%.*s", (int)l, keys[i].name);
                fprintf(f, "%s:\n", section);
            }
            leaf = dot + 1;
        } else {
            section[0] = 0;
        }
        fprintf(f, "%s%s: ", dot ? "  " : "", leaf);
        dump_value(c, &keys[i], f);
        fputc('\n', f);
    }
}

void cdspd_config_help(FILE *f)
{
    size_t i;
    for (i = 0; i < N_KEYS; i++)
        fprintf(f, "  %-26s %-16s default %-16s\n      %s\n", keys[i].name, type_text(&keys[i]),
                *keys[i].def ? keys[i].def : "(none)", keys[i].help);
}
