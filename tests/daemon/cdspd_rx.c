/*
 * cdspd_rx - the test receiver of cdspd's end-to-end tests: receives the
 * datagrams on loopback (or any address given), decodes them with
 * host/proto.c and checks them:
 *   - sequence numbers continuous (no datagram lost or repeated);
 *   - every pose against the ground truth of its frame: the sim source's
 *     (sim_path.h, from the same configuration the daemon read) or the fake
 *     GigE camera's (tests/fakecam/fakecam_path.h);
 *   - in-view frames give a pose, out-of-view frames give no pipe;
 *   - counts of statuses by token, bounds given on the command line;
 *   - with --validate, every datagram on its own and against the previous
 *     ones (validate() below): the soak and fault tests use it.
 *
 * Tolerance of a pose (as tests/lib/test_frame.c): |P_C - truth foot| <=
 * 6 sigma (the solver's own, from the datagram) + d delta (1/f + 2/w), with
 * delta = 0.02 px the edge detector's shading bias at libcdsp's default
 * light, 85 % ambient, which the sim source and the fake camera render
 * (lib/edges.c's second pass leaves 0.01-0.02 px there: test_frame.c's
 * figure; 0 for flat light, ambient = 1): a contour shifted by delta px
 * moves the axis by d delta / f sideways and d 2 delta / w in depth, w the
 * pipe's width in px. Direction: 6 sigma + 4 delta / w rad. 6 sigma, not
 * test_frame.c's 4: a run checks hundreds of poses and the suites together
 * ~1e5, so a per-pose tail of 6e-5 (4 sigma) would fail now and then;
 * |e| > 6 sigma has probability below 2e-9 whatever the covariance's
 * shape. Measured (the summary's lines; check-daemon-sim, 186 poses):
 * worst 0.39 of the tolerance for P_C (0.83 mm of 2.15; 3.05 sigma at
 * worst), 0.30 for the direction (2.0e-3 rad of 6.7e-3; 2.88 sigma).
 * delta was 0.12 px, an allowance of 3.7 mm and 0.015 rad that hid the
 * sigmas: 0.18 and 0.11 of the tolerance.
 *
 * Usage: cdspd_rx [options] (--help). Prints a summary; exit 0 when every
 * check passed, 1 when one failed, 2 usage.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "cdsp.h"
#include "addr.h"
#include "cdsp_host.h"
#include "config.h"
#include "fakecam_path.h"
#include "proto.h"
#include "sim_path.h"

#define MAX_SETS 32

typedef struct {
    const char *bind_text, *port_file, *config, *calib;
    const char *sets[MAX_SETS];
    int n_sets;
    enum { TRUTH_NONE, TRUTH_SIM, TRUTH_FAKECAM, TRUTH_SIM_ANY } truth;
    long min_slots;             /* sim-any: distinct poses seen */
    unsigned cycle;
    double duration, idle;
    long count, min_poses, min_status, max_status;
    const char *expect_status;  /* at least one status datagram with this token */
    long min_expect;
    double min_ok_ratio;        /* of frames whose pipe is in view */
    double delta_px;
    int allow_seq_gaps, verbose, json_expected, validate;
    long min_reconnects, min_bad, max_dropped;
    double resume_within;       /* after a source-down status: a pose within this many s */
    const char *compare;        /* --record's .jsonl: frame k of a replay = its line k */
    int compare_exact;          /* --compare-exact: P_C bit for bit, not within 6 sigma */
    const char *progress;       /* rewritten after every datagram: counts so far */
    double camera_clock_us;     /* > 0: t_camera_us - t_host_us must be about this */
    double min_interval_us;     /* > 0: frames' t_camera_us at least this far apart */
    long max_reconnects;        /* < 0: no bound */
} rx_options;

/* The records of a --record results file, in order. */
static cdspd_record *cmp_rec;
static long cmp_n;

static int load_compare(const char *path)
{
    FILE *f = fopen(path, "r");
    char line[8192];
    long cap = 0;
    if (!f) {
        fprintf(stderr, "cdspd_rx: --compare-jsonl %s: %s\n", path, strerror(errno));
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        const char *why;
        if (cmp_n == cap) {
            cdspd_record *p = realloc(cmp_rec, (size_t)(cap = cap ? 2 * cap : 64) * sizeof *p);
            if (!p)
                return -1;
            cmp_rec = p;
        }
        if (cdspd_proto_decode_json(line, strlen(line), &cmp_rec[cmp_n], &why)) {
            fprintf(stderr, "cdspd_rx: %s:%ld: %s\n", path, cmp_n + 1, why);
            fclose(f);
            return -1;
        }
        cmp_n++;
    }
    fclose(f);
    return 0;
}

static void usage(FILE *f, int st)
{
    fprintf(f,
            "usage: cdspd_rx [options]\n"
            "  --bind ADDR:PORT       where to listen (default 127.0.0.1:0)\n"
            "  --port-file FILE       write the bound port there once listening\n"
            "  --truth sim|fakecam|sim-any|none  ground truth of the frames (default none);\n"
            "                         sim-any: frames do not carry the sim's frame numbers (V4L2\n"
            "                         loop-back): each pose must match one of the path's poses\n"
            "  --min-slots N          sim-any: at least N different poses seen\n"
            "  --config FILE --set K=V --calib FILE  the daemon's configuration (truth sim)\n"
            "  --cycle N              the fake camera's --cycle\n"
            "  --duration S           stop after S seconds (default 10)\n"
            "  --idle S               stop after S seconds without a datagram once some came\n"
            "  --count N              stop after N datagrams\n"
            "  --min-poses N          at least N poses checked (default 1)\n"
            "  --min-ok-ratio R       of in-view frames at least R gave a pose (default 1)\n"
            "  --expect-status TOKEN  at least --min-expect (default 1) status datagrams with TOKEN\n"
            "  --min-status N / --max-status N  bounds on all non-pose datagrams\n"
            "  --min-reconnects N --min-bad N --max-dropped N  bounds on the daemon's counters\n"
            "  --resume-within S      after a source-down, poses must resume within S seconds\n"
            "  --delta PX             shading allowance (default 0.02)\n"
            "  --allow-seq-gaps       do not fail on missing sequence numbers\n"
            "  --compare-jsonl FILE   a replay of --record's frames: frame k must give the\n"
            "                         result of line k (status equal, pose within 6 sigma)\n"
            "  --compare-exact        ... and P_C equal bit for bit (a replay of every frame:\n"
            "                         the same frames tracked from the same ones)\n"
            "  --progress FILE        after every datagram, replace FILE by one line of counts\n"
            "                         'received N poses N statuses N source-down N bad N\n"
            "                         reconnects N', for a test that waits for counts, not time\n"
            "  --camera-clock US      frames carry the fake camera's clock: t_camera_us increases\n"
            "                         and t_camera_us - t_host_us is US less at most 10 s\n"
            "  --min-interval US      frames' t_camera_us at least US apart on average (first\n"
            "                         to last: a late frame may follow an early one closely)\n"
            "  --max-reconnects N     the daemon's reconnect counter at most N\n"
            "  --json                 datagrams must be JSON\n"
            "  --validate             check every datagram: known kind and status, pose fields\n"
            "                         finite and consistent (unit direction, distance = |P_C|)\n"
            "                         when ok and zero otherwise; seq, frame t_host_us and the\n"
            "                         daemon's counters never go backwards (gaps are counted)\n"
            "  -v                     one line per datagram\n");
    exit(st);
}

static double num(const char *opt, const char *s)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v)) {
        fprintf(stderr, "cdspd_rx: %s '%s': expected a number\n", opt, s);
        exit(2);
    }
    return v;
}

static void parse(int argc, char **argv, rx_options *o)
{
    enum { B = 256, PF, TR, CF, ST, CA, CY, DU, ID, CO, MP, MR, ES, ME, MS, XS, MRC, MB, MD, RW, DL, SG, JS, CJ, MSL, VA, PG, CC, MI, XR, CX };
    static const struct option lo[] = {
        {"bind", 1, NULL, B}, {"port-file", 1, NULL, PF}, {"truth", 1, NULL, TR},
        {"config", 1, NULL, CF}, {"set", 1, NULL, ST}, {"calib", 1, NULL, CA},
        {"cycle", 1, NULL, CY}, {"duration", 1, NULL, DU}, {"idle", 1, NULL, ID},
        {"count", 1, NULL, CO}, {"min-poses", 1, NULL, MP}, {"min-ok-ratio", 1, NULL, MR},
        {"expect-status", 1, NULL, ES}, {"min-expect", 1, NULL, ME}, {"min-status", 1, NULL, MS},
        {"max-status", 1, NULL, XS}, {"min-reconnects", 1, NULL, MRC}, {"min-bad", 1, NULL, MB},
        {"max-dropped", 1, NULL, MD}, {"resume-within", 1, NULL, RW}, {"delta", 1, NULL, DL},
        {"allow-seq-gaps", 0, NULL, SG}, {"compare-jsonl", 1, NULL, CJ}, {"min-slots", 1, NULL, MSL}, {"json", 0, NULL, JS},
        {"validate", 0, NULL, VA}, {"progress", 1, NULL, PG}, {"camera-clock", 1, NULL, CC},
        {"min-interval", 1, NULL, MI}, {"max-reconnects", 1, NULL, XR}, {"compare-exact", 0, NULL, CX}, {"help", 0, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    int c;
    memset(o, 0, sizeof *o);
    o->bind_text = "127.0.0.1:0";
    o->duration = 10;
    o->min_poses = 1;
    o->min_ok_ratio = 1;
    o->max_status = -1;
    o->max_dropped = -1;
    o->max_reconnects = -1;
    o->min_expect = 1;
    o->delta_px = 0.02;
    while ((c = getopt_long(argc, argv, "vh", lo, NULL)) != -1) {
        switch (c) {
        case B: o->bind_text = optarg; break;
        case PF: o->port_file = optarg; break;
        case TR:
            if (!strcmp(optarg, "sim"))
                o->truth = TRUTH_SIM;
            else if (!strcmp(optarg, "fakecam"))
                o->truth = TRUTH_FAKECAM;
            else if (!strcmp(optarg, "sim-any"))
                o->truth = TRUTH_SIM_ANY;
            else if (!strcmp(optarg, "none"))
                o->truth = TRUTH_NONE;
            else
                usage(stderr, 2);
            break;
        case CF: o->config = optarg; break;
        case ST:
            if (o->n_sets == MAX_SETS)
                usage(stderr, 2);
            o->sets[o->n_sets++] = optarg;
            break;
        case CA: o->calib = optarg; break;
        case CY: o->cycle = (unsigned)num("--cycle", optarg); break;
        case DU: o->duration = num("--duration", optarg); break;
        case ID: o->idle = num("--idle", optarg); break;
        case CO: o->count = (long)num("--count", optarg); break;
        case MP: o->min_poses = (long)num("--min-poses", optarg); break;
        case MR: o->min_ok_ratio = num("--min-ok-ratio", optarg); break;
        case ES: o->expect_status = optarg; break;
        case ME: o->min_expect = (long)num("--min-expect", optarg); break;
        case MS: o->min_status = (long)num("--min-status", optarg); break;
        case XS: o->max_status = (long)num("--max-status", optarg); break;
        case MRC: o->min_reconnects = (long)num("--min-reconnects", optarg); break;
        case MB: o->min_bad = (long)num("--min-bad", optarg); break;
        case MD: o->max_dropped = (long)num("--max-dropped", optarg); break;
        case RW: o->resume_within = num("--resume-within", optarg); break;
        case DL: o->delta_px = num("--delta", optarg); break;
        case SG: o->allow_seq_gaps = 1; break;
        case JS: o->json_expected = 1; break;
        case VA: o->validate = 1; break;
        case CJ: o->compare = optarg; break;
        case CX: o->compare_exact = 1; break;
        case MSL: o->min_slots = (long)num("--min-slots", optarg); break;
        case PG: o->progress = optarg; break;
        case CC: o->camera_clock_us = num("--camera-clock", optarg); break;
        case MI: o->min_interval_us = num("--min-interval", optarg); break;
        case XR: o->max_reconnects = (long)num("--max-reconnects", optarg); break;
        case 'v': o->verbose = 1; break;
        case 'h': usage(stdout, 0); break;
        default: usage(stderr, 2);
        }
    }
    if (optind < argc)
        usage(stderr, 2);
}

/* Ground truth of a frame: 1 and the foot of the perpendicular + unit
 * direction when the pipe is in view, 0 when not. */
static int truth_of(const rx_options *o, const cdspd_config *c, uint64_t frame, double foot[3],
                    double dir[3])
{
    double p[3], t;
    int i, in_view = 1;
    if (o->truth == TRUTH_SIM || o->truth == TRUTH_SIM_ANY)
        in_view = cdspd_sim_pose(c, cdspd_sim_slot(c, frame), p, dir);
    else
        fakecam_pose(frame, o->cycle, p, dir);
    t = p[0] * dir[0] + p[1] * dir[1] + p[2] * dir[2];
    for (i = 0; i < 3; i++)
        foot[i] = p[i] - t * dir[i];
    return in_view;
}

/* --progress: the counts so far, written to a temporary name and renamed
 * over FILE so a reader never sees half a line. */
static void write_progress(const char *path, long received, long poses, long statuses, long down,
                           uint32_t bad, uint32_t reconnects)
{
    char tmp[4200];
    FILE *f;
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    f = fopen(tmp, "w");
    if (!f)
        return;
    fprintf(f, "received %ld poses %ld statuses %ld source-down %ld bad %lu reconnects %lu\n", received,
            poses, statuses, down, (unsigned long)bad, (unsigned long)reconnects);
    if (fclose(f) == 0)
        rename(tmp, path);
}

static double norm3(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* The parts of the worst pose seen, for the summary: the error, the
 * solver's sigma and the shading allowance, for P_C (mm) and direction
 * (rad). */
typedef struct {
    double err, sigma, bias;
} rx_part;

static rx_part g_last_point, g_last_dir;   /* of the last pose_ratios call */

/* Error / tolerance of a pose (see the top of this file): P_C and direction. */
static void pose_ratios(const rx_options *o, const cdspd_record *r, double f_px, const double foot[3],
                        const double dir[3], double *rp, double *rd)
{
    double e[3], sig = 0, sigd = 0, d, w, allow, c[3], ang, allow_d;
    int k;
    for (k = 0; k < 3; k++) {
        e[k] = r->point[k] - foot[k];
        sig += r->sigma_point[k] * r->sigma_point[k];
        sigd += r->sigma_direction[k] * r->sigma_direction[k];
    }
    d = norm3(foot);
    w = 2 * f_px * r->radius / d;
    allow = 6 * sqrt(sig) + d * o->delta_px * (1 / f_px + 2 / w) + 1e-9 * d;
    c[0] = r->direction[1] * dir[2] - r->direction[2] * dir[1];
    c[1] = r->direction[2] * dir[0] - r->direction[0] * dir[2];
    c[2] = r->direction[0] * dir[1] - r->direction[1] * dir[0];
    ang = atan2(norm3(c), fabs(r->direction[0] * dir[0] + r->direction[1] * dir[1] +
                               r->direction[2] * dir[2]));
    allow_d = 6 * sqrt(sigd) + 4 * o->delta_px / w + 1e-7;
    *rp = norm3(e) / allow;
    *rd = ang / allow_d;
    g_last_point.err = norm3(e);
    g_last_point.sigma = sqrt(sig);
    g_last_point.bias = d * o->delta_px * (1 / f_px + 2 / w);
    g_last_dir.err = ang;
    g_last_dir.sigma = sqrt(sigd);
    g_last_dir.bias = 4 * o->delta_px / w;
}

/* What --validate remembers of the datagrams before. */
typedef struct {
    int have, have_frame;
    cdspd_record prev;            /* the previous datagram */
    uint64_t last_frame_t_host;   /* t_host_us of the previous frame record */
} rx_history;

static int finite_all(const double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* --validate: NULL when the record is well formed and consistent with the
 * ones before, else what is wrong. A pose must be finite with a unit
 * direction (1e-9: the daemon normalizes in double precision) and
 * distance = |P_C| (1e-9 relative: the same computation, rounded once);
 * every pose field of a record without a pose is zero (docs/protocol.md).
 * seq, the frames' t_host_us (CLOCK_MONOTONIC, frames are processed in the
 * order they became ready) and the counters (since the daemon started,
 * across reloads) never decrease; seq gaps are the caller's business. */
static const char *validate(rx_history *h, const cdspd_record *r)
{
    const char *why = NULL;
    if (r->version != CDSPD_PROTO_VERSION)
        why = "unknown version";
    else if (r->kind != CDSPD_KIND_FRAME && r->kind != CDSPD_KIND_STATUS)
        why = "unknown kind";
    else if (!strcmp(cdspd_status_token(r->status), "unknown"))
        why = "unknown status";
    else if (r->kind == CDSPD_KIND_STATUS &&
             (r->status == 0 || r->frame_id != 0))
        why = "a status record with a pose status or a frame id";
    else if (!(r->radius > 0) || !isfinite(r->radius))
        why = "radius not positive";
    else if (r->status == 0) {
        double dn = norm3(r->direction), pn = norm3(r->point);
        if (!finite_all(r->point, 3) || !finite_all(r->direction, 3) || !isfinite(r->distance) ||
            !isfinite(r->alpha) || !finite_all(&r->lines[0][0], 6) ||
            !finite_all(&r->segment[0][0], 6) || !finite_all(r->sigma_point, 3) ||
            !finite_all(r->sigma_direction, 3) || !isfinite(r->sigma_distance) ||
            !finite_all(r->rms, 2))
            why = "a pose with a non-finite field";
        else if (fabs(dn - 1) > 1e-9)
            why = "a pose whose direction is not a unit vector";
        else if (fabs(r->distance - pn) > 1e-9 * pn)
            why = "a pose whose distance is not |P_C|";
        else if (r->inliers[0] == 0 || r->inliers[1] == 0 || r->n_edges < r->inliers[0] + r->inliers[1])
            why = "a pose with inconsistent inlier and edge counts";
    } else {
        static const cdspd_record zero;
        if (memcmp(r->point, zero.point, sizeof r->point) ||
            memcmp(r->direction, zero.direction, sizeof r->direction) || r->distance != 0 ||
            r->alpha != 0 || memcmp(r->sigma_point, zero.sigma_point, sizeof r->sigma_point) ||
            r->inliers[0] || r->inliers[1])
            why = "pose fields set in a record without a pose";
    }
    if (!why && h->have) {
        const cdspd_record *p = &h->prev;
        if (r->seq <= p->seq)
            why = "seq went backwards";
        else if (r->frames_in < p->frames_in || r->frames_dropped < p->frames_dropped ||
                 r->frames_bad < p->frames_bad || r->reconnects < p->reconnects)
            why = "a counter (frames_in, dropped, bad, reconnects) went backwards";
    }
    if (!why && r->kind == CDSPD_KIND_FRAME && h->have_frame && r->t_host_us < h->last_frame_t_host)
        why = "t_host_us went backwards";
    if (r->kind == CDSPD_KIND_FRAME) {
        h->last_frame_t_host = r->t_host_us;
        h->have_frame = 1;
    }
    h->prev = *r;
    h->have = 1;
    return why;
}

int main(int argc, char **argv)
{
    rx_options o;
    static cdspd_config cfg;
    cdsp_camera cam;
    char err[2048];
    int fd, i, fails = 0;
    struct sockaddr_storage ss;
    socklen_t sl;
    static uint8_t buf[65536];
    double t0, t_last = 0, worst_ratio = 0, worst_dir_ratio = 0, t_down = -1, worst_resume = 0;
    double worst_point_sig = 0, worst_dir_sig = 0, cmp_worst = 0;
    rx_part worst_point = {0, 0, 0}, worst_dir = {0, 0, 0};
    long received = 0, poses = 0, statuses = 0, expect_hits = 0, in_view = 0, in_view_ok = 0;
    long gaps = 0, seq_errors = 0, away_poses = 0, bad_decode = 0, tracked = 0;
    long compared = 0, cmp_fail = 0, slots_seen = 0, invalid = 0, progress_at = -1, clock_fail = 0;
    static rx_history hist;
    uint64_t last_tcam = 0, first_tcam = 0;
    long n_tcam = 0;
    double min_dt_us = -1, mean_dt_us = -1;
    static unsigned char slot_seen[4096];
    long status_by[8] = {0};
    const char *status_names[8] = {"no-pipe", "few-points", "no-frame", "source-down", "bad-frame",
                                   "degenerate", "other", "json-mismatch"};
    uint32_t last_seq = 0, max_reconnects = 0, max_bad = 0, max_dropped = 0;
    uint64_t first_frame = 0, last_frame = 0;
    int have_seq = 0, have_frame = 0;
    double f_px;

    parse(argc, argv, &o);
    cdspd_config_defaults(&cfg);
    if (o.config && cdspd_config_load_file(&cfg, o.config, err, sizeof err)) {
        fprintf(stderr, "cdspd_rx: %s\n", err);
        return 2;
    }
    for (i = 0; i < o.n_sets; i++) {
        char kv[1200], *eq;
        snprintf(kv, sizeof kv, "%s", o.sets[i]);
        eq = strchr(kv, '=');
        if (!eq || (*eq = 0, cdspd_config_set(&cfg, kv, eq + 1, "--set", err, sizeof err))) {
            fprintf(stderr, "cdspd_rx: --set %s: %s\n", o.sets[i], eq ? err : "expected K=V");
            return 2;
        }
    }
    if (o.calib)
        snprintf(cfg.calib, sizeof cfg.calib, "%s", o.calib);
    memset(&cam, 0, sizeof cam);
    if (o.truth == TRUTH_FAKECAM) {
        cam.fx = 0; /* read from the datagrams' frames: the test passes --calib */
    }
    if (*cfg.calib) {
        cdsp_host_err herr;
        if (cdsp_host_calib_read(cfg.calib, &cam, &herr)) {
            fprintf(stderr, "cdspd_rx: %s\n", herr.msg);
            return 2;
        }
    } else if (o.truth != TRUTH_NONE) {
        fprintf(stderr, "cdspd_rx: a truth needs the calibration (--calib or the config's calib)\n");
        return 2;
    }
    f_px = (double)cam.fx;
    if (o.compare && load_compare(o.compare))
        return 2;

    {
        cdsp_host_err herr;
        if (cdsp_host_addr_parse(o.bind_text, 1, &ss, &sl, &herr)) {
            fprintf(stderr, "cdspd_rx: --bind %s\n", herr.msg);
            return 2;
        }
    }
    fd = socket(ss.ss_family, SOCK_DGRAM, 0);
    {
        int one = 1, rcv = 8 << 20;
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
    }
    if (fd < 0 || bind(fd, (struct sockaddr *)&ss, sl)) {
        fprintf(stderr, "cdspd_rx: cannot bind %s: %s\n", o.bind_text, strerror(errno));
        return 2;
    }
    if (ss.ss_family == AF_INET && (ntohl(((struct sockaddr_in *)&ss)->sin_addr.s_addr) >> 28) == 14) {
        struct ip_mreq m;
        m.imr_multiaddr = ((struct sockaddr_in *)&ss)->sin_addr;
        m.imr_interface.s_addr = htonl(INADDR_LOOPBACK);
        if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m)) {
            fprintf(stderr, "cdspd_rx: cannot join %s: %s\n", o.bind_text, strerror(errno));
            return 2;
        }
    }
    if (o.port_file) {
        struct sockaddr_storage got;
        socklen_t gl = sizeof got;
        FILE *pf;
        getsockname(fd, (struct sockaddr *)&got, &gl);
        pf = fopen(o.port_file, "w");
        if (!pf) {
            fprintf(stderr, "cdspd_rx: --port-file %s: %s\n", o.port_file, strerror(errno));
            return 2;
        }
        fprintf(pf, "%u\n", (unsigned)ntohs(((struct sockaddr_in *)&got)->sin_port));
        fclose(pf);
    }
    cdsp_host_stop_on_signals();

    t0 = cdsp_host_now_s();
    while (!cdsp_host_stop_requested() && cdsp_host_now_s() - t0 < o.duration && (o.count == 0 || received < o.count)) {
        struct pollfd pfd = {fd, POLLIN, 0};
        cdspd_record r;
        const char *why;
        int is_json;
        ssize_t n;
        double t;
        if (o.idle > 0 && received && cdsp_host_now_s() - t_last > o.idle)
            break;
        if (o.progress && received != progress_at) {
            write_progress(o.progress, received, poses, statuses, status_by[3], max_bad, max_reconnects);
            progress_at = received;
        }
        if (poll(&pfd, 1, 100) <= 0)
            continue;
        n = recv(fd, buf, sizeof buf - 1, 0);
        if (n <= 0)
            continue;
        buf[n] = 0;
        t = cdsp_host_now_s();
        t_last = t;
        received++;
        if (cdspd_proto_decode_any(buf, (size_t)n, &r, &is_json, &why)) {
            fprintf(stderr, "cdspd_rx: FAIL: datagram %ld (%zd bytes): %s\n", received, n, why);
            bad_decode++;
            continue;
        }
        if (o.validate) {
            const char *bad = validate(&hist, &r);
            if (bad) {
                if (invalid++ < 20)
                    fprintf(stderr, "cdspd_rx: FAIL: datagram seq %lu (frame %llu): %s\n",
                            (unsigned long)r.seq, (unsigned long long)r.frame_id, bad);
            }
        }
        if (is_json != o.json_expected) {
            fprintf(stderr, "cdspd_rx: FAIL: datagram seq %lu is %s\n", (unsigned long)r.seq,
                    is_json ? "JSON" : "binary");
            status_by[7]++;
        }
        if (have_seq && r.seq != last_seq + 1u) {
            if (r.seq > last_seq + 1u)
                gaps += r.seq - last_seq - 1u;
            else
                seq_errors++;
            if (!o.allow_seq_gaps)
                fprintf(stderr, "cdspd_rx: FAIL: seq %lu after %lu\n", (unsigned long)r.seq,
                        (unsigned long)last_seq);
        }
        last_seq = r.seq;
        have_seq = 1;
        if (r.reconnects > max_reconnects)
            max_reconnects = r.reconnects;
        if (r.frames_bad > max_bad)
            max_bad = r.frames_bad;
        if (r.frames_dropped > max_dropped)
            max_dropped = r.frames_dropped;
        if (r.kind == CDSPD_KIND_STATUS || r.status != 0) {
            const char *tok = cdspd_status_token(r.status);
            int k;
            statuses++;
            for (k = 0; k < 6; k++)
                if (!strcmp(tok, status_names[k]))
                    break;
            status_by[k]++;
            if (o.expect_status) {
                /* "a|b": any of them */
                const char *p = o.expect_status;
                size_t l = strlen(tok);
                while (p && *p) {
                    const char *bar = strchr(p, '|');
                    size_t pl = bar ? (size_t)(bar - p) : strlen(p);
                    if (pl == l && !strncmp(p, tok, l)) {
                        expect_hits++;
                        break;
                    }
                    p = bar ? bar + 1 : NULL;
                }
            }
            if (r.status == CDSPD_ST_SOURCE_DOWN && t_down < 0)
                t_down = t;
        }
        if (r.kind == CDSPD_KIND_FRAME && r.status != CDSPD_ST_BAD_FRAME &&
            (o.camera_clock_us > 0 || o.min_interval_us > 0)) {
            /* the camera's clock: ahead of the host's by the offset, less
             * the transfer (the camera stamps first); increasing. Not for
             * bad-frame datagrams: an incomplete frame may lack its stamp */
            double lead = (double)r.t_camera_us - (double)r.t_host_us;
            if (o.camera_clock_us > 0 && (lead > o.camera_clock_us || lead < o.camera_clock_us - 10e6)) {
                fprintf(stderr, "cdspd_rx: FAIL: frame %llu: t_camera_us - t_host_us = %.0f us, not "
                        "the camera's clock (%.0f us less the transfer)\n",
                        (unsigned long long)r.frame_id, lead, o.camera_clock_us);
                clock_fail++;
            }
            if (have_frame && r.t_camera_us <= last_tcam) {
                fprintf(stderr, "cdspd_rx: FAIL: frame %llu: t_camera_us %llu after %llu\n",
                        (unsigned long long)r.frame_id, (unsigned long long)r.t_camera_us,
                        (unsigned long long)last_tcam);
                clock_fail++;
            } else if (have_frame && (min_dt_us < 0 || (double)(r.t_camera_us - last_tcam) < min_dt_us)) {
                min_dt_us = (double)(r.t_camera_us - last_tcam);
            }
            if (!n_tcam++)
                first_tcam = r.t_camera_us;
            last_tcam = r.t_camera_us;
        }
        if (r.kind == CDSPD_KIND_FRAME) {
            if (!have_frame)
                first_frame = r.frame_id;
            have_frame = 1;
            last_frame = r.frame_id;
        }
        if (r.kind == CDSPD_KIND_FRAME && r.status == 0 && t_down >= 0) {
            if (t - t_down > worst_resume)
                worst_resume = t - t_down;
            t_down = -1;
        }
        if (o.verbose)
            printf("seq %lu kind %d frame %llu status %s flags %x P_C %.3f %.3f %.3f\n",
                   (unsigned long)r.seq, r.kind, (unsigned long long)r.frame_id,
                   cdspd_status_token(r.status), (unsigned)r.flags, r.point[0], r.point[1], r.point[2]);
        if (o.compare && r.kind == CDSPD_KIND_FRAME) {
            const cdspd_record *e = (long)r.frame_id < cmp_n ? &cmp_rec[r.frame_id] : NULL;
            compared++;
            if (!e) {
                fprintf(stderr, "cdspd_rx: FAIL: replayed frame %llu is not in %s\n",
                        (unsigned long long)r.frame_id, o.compare);
                cmp_fail++;
            } else if ((e->status == 0) != (r.status == 0)) {
                fprintf(stderr, "cdspd_rx: FAIL: replayed frame %llu: %s, recorded: %s\n",
                        (unsigned long long)r.frame_id, cdspd_status_token(r.status),
                        cdspd_status_token(e->status));
                cmp_fail++;
            } else if (r.status == 0) {
                double d2 = 0, s2 = 0;
                int k;
                for (k = 0; k < 3; k++) {
                    d2 += (r.point[k] - e->point[k]) * (r.point[k] - e->point[k]);
                    s2 += e->sigma_point[k] * e->sigma_point[k];
                }
                cmp_worst = fmax(cmp_worst, sqrt(d2) / (6 * sqrt(s2) + 1e-9));
                if (o.compare_exact ? d2 != 0 : sqrt(d2) > 6 * sqrt(s2) + 1e-9) {
                    fprintf(stderr, "cdspd_rx: FAIL: replayed frame %llu: P_C %.4f from the recorded "
                            "one (6 sigma: %.4f)\n", (unsigned long long)r.frame_id, sqrt(d2),
                            6 * sqrt(s2));
                    cmp_fail++;
                }
            }
        }
        if (r.kind != CDSPD_KIND_FRAME || o.truth == TRUTH_NONE || r.status == CDSPD_ST_BAD_FRAME)
            continue;
        if (o.truth == TRUTH_SIM_ANY) {
            double foot[3], dir[3], best = 1e300, rp, rd;
            int slot, best_slot = -1;
            if (r.status != 0)
                continue;
            poses++;
            for (slot = 0; slot < cfg.sim.frames; slot++) {
                if (!truth_of(&o, &cfg, (uint64_t)slot, foot, dir))
                    continue;
                pose_ratios(&o, &r, f_px, foot, dir, &rp, &rd);
                if ((rp > rd ? rp : rd) < best) {
                    best = rp > rd ? rp : rd;
                    best_slot = slot;
                }
            }
            if (best_slot >= 0 && best <= 1) {
                if (!slot_seen[best_slot % 4096]++)
                    slots_seen++;
            } else {
                fprintf(stderr, "cdspd_rx: FAIL: frame %llu: P_C (%.2f %.2f %.2f) matches none of the "
                        "path's poses (best: slot %d at %.2f times its tolerance)\n",
                        (unsigned long long)r.frame_id, r.point[0], r.point[1], r.point[2], best_slot,
                        best);
            }
            if (best > worst_ratio)
                worst_ratio = best;
            continue;
        }
        {
            double foot[3], dir[3], rp, rd;
            int view = truth_of(&o, &cfg, r.frame_id, foot, dir);
            if (!view) {
                if (r.status == 0) {
                    away_poses++;
                    fprintf(stderr, "cdspd_rx: FAIL: frame %llu: a pose, but the pipe is out of view\n",
                            (unsigned long long)r.frame_id);
                }
                continue;
            }
            in_view++;
            if (r.status != 0)
                continue;
            in_view_ok++;
            poses++;
            if (r.flags & CDSPD_FLAG_TRACKED)
                tracked++;
            pose_ratios(&o, &r, f_px, foot, dir, &rp, &rd);
            if (rp > worst_ratio) {
                worst_ratio = rp;
                worst_point = g_last_point;
            }
            if (rd > worst_dir_ratio) {
                worst_dir_ratio = rd;
                worst_dir = g_last_dir;
            }
            worst_point_sig = fmax(worst_point_sig, g_last_point.err / g_last_point.sigma);
            worst_dir_sig = fmax(worst_dir_sig, g_last_dir.err / g_last_dir.sigma);
            if (rp > 1 || rd > 1)
                fprintf(stderr, "cdspd_rx: FAIL: frame %llu: P_C off by %.2f times its tolerance, "
                        "direction by %.2f times\n", (unsigned long long)r.frame_id, rp, rd);
        }
    }

    printf("cdspd_rx: %ld datagrams (%ld undecodable), seq gaps %ld, seq out of order %ld; frames "
           "%llu..%llu; poses %ld (%ld tracked), statuses %ld:", received, bad_decode, gaps, seq_errors,
           (unsigned long long)first_frame, (unsigned long long)last_frame, poses, tracked, statuses);
    for (i = 0; i < 8; i++)
        if (status_by[i])
            printf(" %s %ld", status_names[i], status_by[i]);
    printf("; daemon counters: reconnects %lu, bad %lu, dropped %lu\n", (unsigned long)max_reconnects,
           (unsigned long)max_bad, (unsigned long)max_dropped);
    if (o.validate)
        printf("cdspd_rx: validated %ld datagrams: %ld invalid\n", received - bad_decode, invalid);
    if (o.compare)
        printf("cdspd_rx: replay: %ld frames compared with %ld recorded results, %ld differ; worst "
               "P_C difference %.3g of its tolerance (6 sigma)\n", compared, cmp_n, cmp_fail, cmp_worst);
    if (o.truth == TRUTH_SIM_ANY)
        printf("cdspd_rx: poses %ld, each matching one of the path's; %ld different ones seen\n", poses,
               slots_seen);
    else if (o.truth != TRUTH_NONE)
        printf("cdspd_rx: in-view frames %ld, with a pose %ld; worst error / tolerance: point %.3f, "
               "direction %.3f\n", in_view, in_view_ok, worst_ratio, worst_dir_ratio);
    if (o.truth != TRUTH_NONE && o.truth != TRUTH_SIM_ANY && in_view_ok)
        printf("cdspd_rx: worst point %.4f mm (sigma %.4f, shading allowance %.4f), direction "
               "%.3g rad (sigma %.3g, allowance %.3g); worst in sigmas: point %.2f, direction %.2f\n",
               worst_point.err, worst_point.sigma, worst_point.bias, worst_dir.err, worst_dir.sigma,
               worst_dir.bias, worst_point_sig, worst_dir_sig);

#define CHECK(cond, ...)                                                                          \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            fprintf(stderr, "cdspd_rx: FAIL: " __VA_ARGS__);                                      \
            fputc('\n', stderr);                                                                  \
            fails++;                                                                              \
        }                                                                                         \
    } while (0)
    CHECK(received > 0, "no datagram received");
    if (n_tcam > 1)
        mean_dt_us = (double)(last_tcam - first_tcam) / (double)(n_tcam - 1);
    if (o.camera_clock_us > 0 || o.min_interval_us > 0)
        printf("cdspd_rx: camera clock: %s; interval between frames: mean %.0f us, shortest %.0f us\n",
               clock_fail ? "FAILED" : "t_camera_us increasing, from the camera", mean_dt_us, min_dt_us);
    CHECK(clock_fail == 0, "%ld frames with a t_camera_us not from the camera's clock", clock_fail);
    CHECK(o.min_interval_us <= 0 || mean_dt_us >= o.min_interval_us,
          "frames %.0f us apart on average, closer than %.0f us", mean_dt_us, o.min_interval_us);
    CHECK(o.max_reconnects < 0 || (long)max_reconnects <= o.max_reconnects,
          "the daemon reports %lu reconnects, expected <= %ld", (unsigned long)max_reconnects,
          o.max_reconnects);
    CHECK(o.truth != TRUTH_SIM_ANY || slots_seen >= o.min_slots,
          "%ld different poses of the path seen, expected at least %ld", slots_seen, o.min_slots);
    CHECK(!o.compare || (compared == cmp_n && cmp_fail == 0),
          "replay: %ld frames compared with the %ld recorded, %ld differ", compared, cmp_n, cmp_fail);
    CHECK(bad_decode == 0, "%ld datagrams could not be decoded", bad_decode);
    CHECK(invalid == 0, "%ld datagrams invalid or inconsistent with the ones before", invalid);
    CHECK(status_by[7] == 0, "datagrams in the wrong format");
    CHECK(o.allow_seq_gaps || (gaps == 0 && seq_errors == 0), "sequence numbers not continuous "
          "(%ld missing, %ld out of order)", gaps, seq_errors);
    CHECK(worst_ratio <= 1 && worst_dir_ratio <= 1, "poses outside their tolerance");
    CHECK(away_poses == 0, "%ld poses for frames without a pipe in view", away_poses);
    CHECK(o.truth == TRUTH_NONE || poses >= o.min_poses, "%ld poses checked, fewer than %ld", poses,
          o.min_poses);
    CHECK(o.truth == TRUTH_NONE || in_view == 0 || (double)in_view_ok >= o.min_ok_ratio * (double)in_view,
          "%ld of %ld in-view frames gave a pose (ratio below %g)", in_view_ok, in_view, o.min_ok_ratio);
    CHECK(!o.expect_status || expect_hits >= o.min_expect, "%ld '%s' statuses, expected at least %ld",
          expect_hits, o.expect_status ? o.expect_status : "", o.min_expect);
    CHECK(statuses >= o.min_status, "%ld statuses, expected at least %ld", statuses, o.min_status);
    CHECK(o.max_status < 0 || statuses <= o.max_status, "%ld statuses, expected at most %ld", statuses,
          o.max_status);
    CHECK((long)max_reconnects >= o.min_reconnects, "the daemon reports %lu reconnects, expected >= %ld",
          (unsigned long)max_reconnects, o.min_reconnects);
    CHECK((long)max_bad >= o.min_bad, "the daemon reports %lu bad frames, expected >= %ld",
          (unsigned long)max_bad, o.min_bad);
    CHECK(o.max_dropped < 0 || (long)max_dropped <= o.max_dropped,
          "the daemon reports %lu dropped frames, expected <= %ld", (unsigned long)max_dropped,
          o.max_dropped);
    CHECK(o.resume_within <= 0 || (t_down < 0 && worst_resume <= o.resume_within),
          "poses did not resume within %g s after the source went down (%s)", o.resume_within,
          t_down >= 0 ? "still down at the end" : "took longer");
    printf("cdspd_rx: %s\n", fails ? "FAIL" : "PASS");
    return fails ? 1 : 0;
}
