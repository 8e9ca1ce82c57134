/*
 * bench_frame.c - `make bench-frame` (part of `make bench`): the frame
 * path's speed against the memory limit (issue 17), one core.
 *
 * The frames are the paper's scene at 2448 x 2048, 8 bit (pipe p1 drifting
 * and turning, as bench_lib's sequence), rendered once and cached raw in
 * DIR/frames.raw so repeated runs (and callgrind, where rendering would take
 * minutes) read them back. For each frame it times the full search and the
 * tracked path (prior: the full search's result on the same frame), medians
 * over all runs, and prints
 *   - the bytes of the frame actually read: the distinct 64-byte lines
 *     frame 0's solves read, counted by callgrind's cache model (the lines
 *     modes below, make bench-frame-lines, DIR/lines.txt); and, as an upper
 *     bound, by whole rows: the frame is mapped PROT_NONE one row per page
 *     and each first touch of a page (SIGSEGV) is counted and unprotected,
 *     one solve per mode;
 *   - the memory bandwidth measured here: memcpy of a buffer of the frame's
 *     size (5 MB, beyond this machine's caches... or near them: the ratio
 *     says what it says, on this machine), and of the bytes read;
 *   - the ratio of the achieved time to that limit (time / (bytes read /
 *     bandwidth)).
 * Each solve is timed twice, cold and warm, alternately in one run: cold
 * after evict() (the frame flushed from every cache level, then the
 * workspace and the code pushed out of L1 and L2: as a frame a camera
 * just wrote by DMA and a process doing other work between frames leave
 * them; cv_baseline's libcdsp figure is such a case, after OpenCV's pass
 * over the frame), warm right after a full search of the same frame (the
 * frame in L2 / L3, as a loop over one frame keeps it). The cold rows
 * carry the same bytes read and the same memory limit.
 * Modes for counting instructions: `bench_frame DIR full|track|load REPS
 * [FRAMES]` runs only that path REPS times on each of the first FRAMES
 * frames (track: after one full search per frame, for its prior; load:
 * nothing, the baseline of reading the frames), for valgrind
 * --tool=callgrind --toggle-collect=cdsp_frame_solve here and
 * tests/aarch64/count.sh under qemu-aarch64. `bench_frame DIR hash` prints,
 * for 3 camera models (the paper camera without distortion and with two
 * radial models) and each frame, a hash of the full search's and the
 * tracked path's result (every field): an optimisation that must not change
 * what is found leaves these lines unchanged. `bench_frame DIR poses` prints
 * the same solves' points, directions, distances, their sigmas, inliers,
 * lines, candidates and confidence in full, to compare two builds where a
 * change is not meant to be exact.
 * Figures, not pass/fail; the machine is shared: compare within one run.
 */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>
#include "support.h"
#ifdef __SSE2__
#include <emmintrin.h> /* _mm_clflush: the cold figure */
#endif

#define NFRAMES 6
#define W 2448
#define H 2048

static cdsp_frame_ws ws;

/* Cold (see the top): the frame's cache lines flushed to memory (x86:
 * clflush; elsewhere not, and the figure is the L2-cold one only), then
 * EVICT_BYTES of another buffer read: 3 x the L2 of the machine the figures
 * were taken on (2 MiB a core, L1d 48 KiB), which pushes the workspace and
 * the code out of L1 and L2 too. Reading a buffer alone left the frame in
 * this machine's L3 (480 MiB): 0.44 ms cold against 0.82 ms after reading
 * 256 MiB, cv_baseline's 0.80 ms. Read, not written: no dirty lines for the
 * solve to write back. */
#define EVICT_BYTES (12u << 20)
static unsigned char *evict_buf;
static volatile unsigned evict_sink;

static void evict(const unsigned char *frame)
{
    unsigned s = 0;
    size_t i;
#ifdef __SSE2__
    for (i = 0; i < (size_t)W * H; i += 64)
        _mm_clflush(frame + i);
    _mm_mfence();
#else
    (void)frame;
#endif
    for (i = 0; i < EVICT_BYTES; i += 64)
        s += evict_buf[i];
    evict_sink = s;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* One row of the frame path's table: time (ms), the frame's bytes read,
 * the memory limit for them (ms) and the ratio of the two. */
static void print_row(const char *path, double ms, size_t bytes, size_t frame_bytes, double lim)
{
    printf("| %-28s | %7.3f ms | %9zu (%5.1f %%)     | %9.3f ms | %6.1f x |\n", path, ms, bytes,
           100.0 * (double)bytes / (double)frame_bytes, lim, lim > 0 ? ms / lim : 0);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return n ? v[n / 2] : 0;
}

/* Frame i of the sequence (bench_lib.c's moving pipe). */
static int render_frame(const cdsp_camera *cam, int i, unsigned char *dst)
{
    cdsp_scene s;
    cdsp_image img;
    double P[3], v[3];
    void *px;
    sup_paper_pipe(0, P, v);
    P[0] += 0.8 * i;
    P[1] -= 0.5 * i;
    v[1] += 0.004 * i;
    sup_scene(&s, P, v, 8);
    s.half_length = 250;
    s.noise_sigma = (cdsp_real)0.002;
    px = sup_render(&s, cam, 8, (uint64_t)i, &img);
    if (!px)
        return -1;
    memcpy(dst, px, (size_t)W * H);
    free(px);
    return 0;
}

/* The cached frames, rendered when the cache is missing or short. */
static int load_frames(const cdsp_camera *cam, const char *dir, unsigned char *frames)
{
    char path[4096];
    size_t sz = (size_t)W * H * NFRAMES;
    FILE *f;
    int i;
    snprintf(path, sizeof path, "%s/frames.raw", dir);
    f = fopen(path, "rb");
    if (f) {
        size_t got = fread(frames, 1, sz, f);
        fclose(f);
        if (got == sz)
            return 0;
    }
    fprintf(stderr, "bench_frame: rendering %d frames at %d x %d into %s...\n", NFRAMES, W, H, path);
    for (i = 0; i < NFRAMES; i++)
        if (render_frame(cam, i, frames + (size_t)i * W * H) != 0) {
            fprintf(stderr, "bench_frame: rendering frame %d failed\n", i);
            return -1;
        }
    f = fopen(path, "wb");
    if (!f || fwrite(frames, 1, sz, f) != sz) {
        fprintf(stderr, "bench_frame: cannot write %s: %s\n", path, strerror(errno));
        if (f)
            fclose(f);
        return -1;
    }
    return fclose(f) == 0 ? 0 : -1;
}

/* ---- bytes read: first touches of a PROT_NONE mapping ---------------------- */

static unsigned char *trap_base;
static size_t trap_len, page;
static volatile sig_atomic_t pages_touched;

static void on_segv(int sig, siginfo_t *si, void *ctx)
{
    unsigned char *a = (unsigned char *)si->si_addr;
    (void)ctx;
    if (a < trap_base || a >= trap_base + trap_len) {
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    a = trap_base + (size_t)(a - trap_base) / page * page;
    mprotect(a, page, PROT_READ);
    pages_touched++;
}

/* Bytes of the frame one call of solve reads, at row granularity: the
 * frame is laid out one row per page (stride = a whole number of pages),
 * so a page first touched is a row read; the figure is rows touched times
 * the row's W bytes. An upper bound: a band search reads only its segment
 * of each row (a few cache lines), and is counted a whole row here. */
static size_t bytes_read(const unsigned char *frame, const cdsp_camera *cam, const cdsp_params *prm,
                         const cdsp_result *prior, size_t *rows)
{
    struct sigaction sa, old;
    cdsp_image img;
    cdsp_result r;
    cdsp_rng rng;
    size_t stride;
    int y;
    page = (size_t)sysconf(_SC_PAGESIZE);
    stride = (W + page - 1) / page * page;
    trap_len = stride * H;
    trap_base = mmap(NULL, trap_len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (trap_base == MAP_FAILED)
        return 0;
    for (y = 0; y < H; y++)
        memcpy(trap_base + (size_t)y * stride, frame + (size_t)y * W, W);
    mprotect(trap_base, trap_len, PROT_NONE);
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = on_segv;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGSEGV, &sa, &old);
    pages_touched = 0;
    img.data = trap_base;
    img.width = W;
    img.height = H;
    img.stride = stride;
    img.bits = 8;
    cdsp_rng_seed(&rng, 1, 1);
    cdsp_frame_solve(&img, cam, 8, prm, prior, &ws, &rng, &r);
    sigaction(SIGSEGV, &old, NULL);
    munmap(trap_base, trap_len);
    /* a row of W <= page bytes spans one page, or two when stride > page */
    *rows = (size_t)pages_touched * page / stride;
    return *rows * W;
}

/* Memory bandwidth, bytes/s: the best of several memcpy of n bytes between
 * two buffers that together exceed the frame (the copy reads n and writes
 * n; the figure is bytes read per second, which is what the scan does). */
static double bandwidth(size_t n)
{
    unsigned char *a = malloc(n), *b = malloc(n);
    double best = 1e30;
    int i;
    if (!a || !b) {
        free(a);
        free(b);
        return 0;
    }
    memset(a, 1, n);
    memset(b, 2, n);
    for (i = 0; i < 15; i++) {
        double t0 = sup_now();
        memcpy(i & 1 ? a : b, i & 1 ? b : a, n);
        t0 = sup_now() - t0;
        best = t0 < best ? t0 : best;
    }
    free(a);
    free(b);
    return (double)n / best;
}

/* FNV-1a of the result's fields, one at a time (the struct's padding is
 * not part of the result). */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    while (n--)
        h = (h ^ *b++) * 1099511628211u;
    return h;
}

static uint64_t result_hash(cdsp_status st, const cdsp_result *r)
{
    uint64_t h = fnv(14695981039346656037u, &st, sizeof st);
#define F(x) h = fnv(h, &r->x, sizeof r->x)
    F(point); F(direction); F(distance); F(alpha); F(normals); F(lines); F(segment); F(cov);
    F(cov_factor); F(sigma_point); F(sigma_direction); F(sigma_distance); F(rms); F(inliers);
    F(n_edges); F(label); F(flags); F(edge_offset); F(edge_blur); F(confidence); F(score);
    F(noise); F(min_step); F(n_lines); F(n_candidates); F(track_id); F(edge_bound);
    F(bound_point); F(bound_direction); F(bound_distance);
#undef F
    return h;
}

/* The poses mode: the fields a pose is judged by, full precision, for each
 * camera model and frame, full search then tracked (the same solves as the
 * hash mode): to compare two builds within the poses' sigmas where a change
 * is not meant to be exact. */
static void print_pose(const char *what, cdsp_status st, const cdsp_result *r)
{
    int k;
    printf(" %s %d", what, (int)st);
    for (k = 0; k < 3; k++)
        printf(" %.17g", (double)r->point[k]);
    for (k = 0; k < 3; k++)
        printf(" %.17g", (double)r->direction[k]);
    printf(" %.17g", (double)r->distance);
    for (k = 0; k < 3; k++)
        printf(" %.17g", (double)r->sigma_point[k]);
    for (k = 0; k < 3; k++)
        printf(" %.17g", (double)r->sigma_direction[k]);
    printf(" %.17g %u %u %u %u %.17g", (double)r->sigma_distance, (unsigned)r->inliers[0],
           (unsigned)r->inliers[1], (unsigned)r->n_lines, (unsigned)r->n_candidates, (double)r->confidence);
}

/* The hash mode (see the top); poses: the poses mode instead. */
static int hash_poses(const unsigned char *frames, int nuse, int poses)
{
    static const double model[3][2] = {{0, 0}, {-0.05, 0}, {0.03, -0.01}};
    int m, i;
    for (m = 0; m < 3; m++) {
        cdsp_camera cam;
        cdsp_params prm;
        sup_paper_camera(&cam, model[m][0], model[m][1]);
        cdsp_params_default(&prm);
        for (i = 0; i < nuse; i++) {
            cdsp_image img = {(void *)(frames + (size_t)i * W * H), W, H, W, 8};
            cdsp_result r, t;
            cdsp_rng rng;
            cdsp_status sf, stk = CDSP_E_NO_PIPE;
            memset(&r, 0, sizeof r);
            memset(&t, 0, sizeof t);
            cdsp_rng_seed(&rng, 1, 1);
            sf = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
            if (sf == CDSP_OK) {
                cdsp_rng_seed(&rng, 1, 1);
                stk = cdsp_frame_solve(&img, &cam, 8, &prm, &r, &ws, &rng, &t);
            }
            if (poses) {
                printf("model %d frame %d", m, i);
                print_pose("full", sf, &r);
                print_pose("track", stk, &t);
                printf("\n");
            } else {
                printf("model %d frame %d full %016llx track %016llx\n", m, i,
                       (unsigned long long)result_hash(sf, &r), (unsigned long long)result_hash(stk, &t));
            }
        }
    }
    return 0;
}

/* ---- bytes read: distinct cache lines, callgrind's cache model ----------- */

/* The lines modes (`lines-full`, `lines-track`), run under callgrind with a
 * last-level cache larger than the frame (tests/bench/frame_lines.sh): a
 * solve on one copy of frame 0 (for the tracked path: a full search, then
 * the tracked solve, on it) warms the workspace, the stack and the code;
 * the measured solve (measured_full / measured_track, the functions
 * callgrind collects in) then runs on a second copy nothing has read, on
 * the same path (the same pixels), so its last-level read misses are the
 * frame's distinct 64-byte lines it reads, each once. The copies are
 * written first, and those writes pushed out of the model's caches. */
__attribute__((noinline)) static cdsp_status measured_full(const cdsp_image *img, const cdsp_camera *cam,
                                                           const cdsp_params *prm, cdsp_result *r)
{
    cdsp_rng rng;
    cdsp_rng_seed(&rng, 1, 1);
    return cdsp_frame_solve(img, cam, 8, prm, NULL, &ws, &rng, r);
}

__attribute__((noinline)) static cdsp_status measured_track(const cdsp_image *img, const cdsp_camera *cam,
                                                            const cdsp_params *prm, const cdsp_result *prior,
                                                            cdsp_result *r)
{
    cdsp_rng rng;
    cdsp_rng_seed(&rng, 1, 1);
    return cdsp_frame_solve(img, cam, 8, prm, prior, &ws, &rng, r);
}

/* frame_lines.sh's --LL size: holds the frame, the workspace and the code
 * (no capacity misses), which 3 times its size read clears */
#define LINES_LL_BYTES (16u << 20)
static int lines_mode(const unsigned char *frame, const cdsp_camera *cam, const cdsp_params *prm, int track)
{
    unsigned char *a = malloc((size_t)W * H), *b = malloc((size_t)W * H);
    cdsp_image ia = {a, W, H, W, 8}, ib = {b, W, H, W, 8};
    cdsp_result r, t;
    cdsp_rng rng;
    cdsp_status st;
    if (!a || !b) {
        free(a);
        free(b);
        return 1;
    }
    memcpy(a, frame, (size_t)W * H);
    memcpy(b, frame, (size_t)W * H);
    /* the copies' writes out of the model's caches (LINES_LL_BYTES, the
     * script's --LL): 3 times that read, then the warm-up */
    {
        size_t i, nj = (size_t)3 * LINES_LL_BYTES;
        unsigned char *junk = malloc(nj);
        unsigned sum = 0;
        if (!junk) {
            free(a);
            free(b);
            return 1;
        }
        memset(junk, 1, nj);
        for (i = 0; i < nj; i += 64)
            sum += junk[i];
        evict_sink = sum;
        free(junk);
    }
    cdsp_rng_seed(&rng, 1, 1);
    st = cdsp_frame_solve(&ia, cam, 8, prm, NULL, &ws, &rng, &r);
    if (track && st == CDSP_OK) {
        cdsp_rng_seed(&rng, 1, 1);
        (void)cdsp_frame_solve(&ia, cam, 8, prm, &r, &ws, &rng, &t);
        st = measured_track(&ib, cam, prm, &r, &t);
    } else if (!track) {
        st = measured_full(&ib, cam, prm, &r);
    }
    free(a);
    free(b);
    return st == CDSP_OK ? 0 : 1;
}

/* DIR/lines.txt (frame_lines.sh): the bytes of the frame's distinct lines
 * a full search and a tracked solve read; 0 each when not counted. */
static void read_lines(const char *dir, size_t *full, size_t *track)
{
    char path[4096], key[16];
    unsigned long long v;
    FILE *f;
    *full = *track = 0;
    snprintf(path, sizeof path, "%s/lines.txt", dir);
    f = fopen(path, "r");
    if (!f)
        return;
    while (fscanf(f, "%15s %llu", key, &v) == 2) {
        if (strcmp(key, "full") == 0)
            *full = (size_t)v;
        else if (strcmp(key, "track") == 0)
            *track = (size_t)v;
    }
    fclose(f);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    const char *mode = argc > 2 ? argv[2] : "time";
    int reps = argc > 3 ? atoi(argv[3]) : 9;
    int nuse = argc > 4 ? atoi(argv[4]) : NFRAMES;
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_result prior[NFRAMES];
    unsigned char *frames = malloc((size_t)W * H * NFRAMES);
    double tf[NFRAMES * 64], tt[NFRAMES * 64], cf[NFRAMES * 64], ct[NFRAMES * 64];
    int i, k, nf = 0, nt = 0, ncf = 0, nct = 0, ok[NFRAMES];
    evict_buf = malloc(EVICT_BYTES);
    if (!frames || !evict_buf || reps < 1 || reps > 64 || nuse < 1 || nuse > NFRAMES) {
        fprintf(stderr, "usage: bench_frame DIR [time|full|track|load|hash|poses|lines-full|lines-track] [REPS 1..64] "
                        "[FRAMES 1..%d]\n",
                NFRAMES);
        return 2;
    }
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    if (load_frames(&cam, dir, frames) != 0)
        return 1;
    if (strcmp(mode, "load") == 0)
        return 0;
    if (strcmp(mode, "lines-full") == 0 || strcmp(mode, "lines-track") == 0) {
        int rc = lines_mode(frames, &cam, &prm, strcmp(mode, "lines-track") == 0);
        free(frames);
        free(evict_buf);
        return rc;
    }
    if (strcmp(mode, "hash") == 0 || strcmp(mode, "poses") == 0) {
        hash_poses(frames, nuse, strcmp(mode, "poses") == 0);
        free(frames);
        return 0;
    }
    memset(evict_buf, 1, EVICT_BYTES);
    cdsp_rng_seed(&rng, 1, 1);
    /* priors: the full search on each frame (outside any timing; not in
     * mode full, so that callgrind's count there is full searches only) */
    for (i = 0; i < nuse; i++) {
        ok[i] = 0;
        if (strcmp(mode, "full") == 0)
            continue;
        cdsp_image img = {frames + (size_t)i * W * H, W, H, W, 8};
        ok[i] = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &prior[i]) == CDSP_OK;
    }
    for (i = 0; i < nuse; i++) {
        cdsp_image img = {frames + (size_t)i * W * H, W, H, W, 8};
        for (k = 0; k < reps; k++) {
            /* cold then warm: warm after an untimed full search of the
             * same frame, as a loop over one frame keeps it (a solve right
             * after a cold one finds only part of the frame in the caches:
             * 0.63 against 0.38 ms). Cold only in mode time: callgrind's
             * counts in modes full and track stay one solve per rep. */
            int c, cold = strcmp(mode, "time") == 0;
            for (c = !cold; c < 2; c++) {
                const unsigned char *fp = img.data;
                cdsp_result r;
                double t0;
                if (c == 1 && cold) {
                    cdsp_rng_seed(&rng, 1, 1);
                    cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
                }
                if (strcmp(mode, "track") != 0) {
                    if (c == 0)
                        evict(fp);
                    cdsp_rng_seed(&rng, 1, 1);
                    t0 = sup_now();
                    cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
                    t0 = (sup_now() - t0) * 1e3;
                    if (c == 0)
                        cf[ncf++] = t0;
                    else
                        tf[nf++] = t0;
                }
                if (strcmp(mode, "full") != 0 && ok[i]) {
                    if (c == 0)
                        evict(fp);
                    cdsp_rng_seed(&rng, 1, 1);
                    t0 = sup_now();
                    cdsp_frame_solve(&img, &cam, 8, &prm, &prior[i], &ws, &rng, &r);
                    t0 = (sup_now() - t0) * 1e3;
                    if (c == 0)
                        ct[nct++] = t0;
                    else
                        tt[nt++] = t0;
                }
            }
        }
    }
    if (strcmp(mode, "time") != 0)
        return 0;
    {
        size_t frame_bytes = (size_t)W * H, lf, lt;
        size_t rf = 0, rt = 0, bf = bytes_read(frames, &cam, &prm, NULL, &rf);
        size_t bt = ok[0] ? bytes_read(frames, &cam, &prm, &prior[0], &rt) : 0;
        size_t pf = bf, pt = bt; /* by whole rows */
        double bw = bandwidth(frame_bytes);
        /* the distinct lines where counted (make bench-frame-lines) */
        read_lines(dir, &lf, &lt);
        if (lf && lt) {
            bf = lf;
            bt = lt;
        }
        double mf = median(tf, nf), mt = median(tt, nt), mcf = median(cf, ncf), mct = median(ct, nct);
        double limf = (double)bf / bw * 1e3, limt = (double)bt / bw * 1e3;
        printf("frame path, %d x %d 8 bit, %d frames x %d runs, one core (issue 17)\n", W, H,
               nuse, reps);
        printf("| %-28s | %-10s | %-22s | %-12s | %-8s |\n", "path", "time", "frame bytes read",
               "memory limit", "ratio");
        printf("|%s|%s|%s|%s|%s|\n", "------------------------------", "------------",
               "------------------------", "--------------", "----------");
        print_row("full search (target <= 1 ms)", mf, bf, frame_bytes, limf);
        print_row("tracked (target <= 0.2 ms)", mt, bt, frame_bytes, limt);
        print_row("full search, cold", mcf, bf, frame_bytes, limf);
        print_row("tracked, cold", mct, bt, frame_bytes, limt);
        printf("memory bandwidth (memcpy of %zu bytes, best of 15): %.2f GB/s; ", frame_bytes, bw / 1e9);
        if (lf && lt)
            printf("bytes read: the frame's distinct 64-byte lines frame 0's solves read (callgrind's cache "
                   "model, make bench-frame-lines); by whole rows %zu full and %zu tracked (%zu of %d rows "
                   "full, %zu tracked: an upper bound); ",
                   pf, pt, rf, H, rt);
        else
            printf("bytes read counted by whole rows (%zu of %d rows full, %zu tracked; an upper bound: the "
                   "lines are counted by make bench-frame-lines, which needs valgrind); ",
                   rf, H, rt);
        printf("ratio = time / (bytes read / bandwidth), target <= 3; cold: the frame flushed "
               "from the caches, then %u MiB of another buffer read\n",
               (unsigned)(EVICT_BYTES >> 20));
    }
    free(evict_buf);
    free(frames);
    return 0;
}
