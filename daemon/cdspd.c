/*
 * cdspd.c - the capture daemon's main: command line, configuration,
 * signals, the pipeline's life, periodic statistics and systemd
 * notification. docs/cdspd.md is the manual.
 *
 * Signals are blocked in every thread and taken by one signal thread
 * (sigwait), which only sets flags; the main thread polls them every
 * 50 ms. So nothing runs in a signal handler, and a signal during start-up
 * (a long sim render, a camera search) is seen at once.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cdsp.h"
#include "options.h"
#include "config.h"
#include "log.h"
#include "notify.h"
#include "pipeline.h"
#include "source.h"
#include "stats.h"

#define CDSPD_VERSION "0.1.0"

enum {
    EXIT_OK = 0,        /* stopped by SIGTERM/SIGINT, --duration, --frames, or the end of a file source */
    EXIT_RUNTIME = 1,   /* out of memory, no socket, a thread that would not start */
    EXIT_CONFIG = 2,    /* usage or configuration error (also --check-config) */
    EXIT_SOURCE = 3     /* the source could not be opened within open_timeout */
};

/* written by the signal thread, read and cleared by main (CDSPD_GET/SET) */
static int sig_stop, sig_reload, sig_stats, sig_last, sig_quit;

static void *signal_thread(void *arg)
{
    sigset_t *set = arg;
    for (;;) {
        int sig;
        if (sigwait(set, &sig))
            continue;
        if (CDSPD_GET(sig_quit))
            break; /* main is exiting and joins this thread */
        CDSPD_SET(sig_last, sig);
        if (sig == SIGTERM || sig == SIGINT)
            CDSPD_SET(sig_stop, 1);
        else if (sig == SIGHUP)
            CDSPD_SET(sig_reload, 1);
        else if (sig == SIGUSR1)
            CDSPD_SET(sig_stats, 1);
    }
    return NULL;
}

/* ------------------------------------------------------------------------
 * Command line.
 * ---------------------------------------------------------------------- */
enum { OPT_CALIB = 256, OPT_DURATION, OPT_FRAMES, OPT_CHECK, OPT_HELP_KEYS, OPT_VERSION, OPT_LIST,
       OPT_MAVLINK };

static const cdsp_host_option option_table[] = {
    {{"config", required_argument, NULL, 'c'}, "FILE", "read keys from this YAML file first"},
    {{"source", required_argument, NULL, 's'}, "SRC",
     "sim | file:GLOB | aravis:[ID] | v4l2:/dev/videoN | libcamera:[ID] (key source)"},
    {{"calib", required_argument, NULL, OPT_CALIB}, "CAM.yaml", "camera calibration (key calib)"},
    {{"radius", required_argument, NULL, 'r'}, "R", "pipe radius, mm (key radius)"},
    {{"dest", required_argument, NULL, 'd'}, "HOST:PORT",
     "send datagrams there; repeatable (key dest; the first --dest replaces the file's list)"},
    {{"format", required_argument, NULL, 'f'}, "binary|json", "datagram format (key format)"},
    {{"mavlink", required_argument, NULL, OPT_MAVLINK}, "URL",
     "also send MAVLink: udpout://HOST:PORT or serial:///dev/ttyX:BAUD; repeatable (key mavlink; "
     "docs/mavlink.md)"},
    {{"duration", required_argument, NULL, OPT_DURATION}, "SECONDS",
     "stop after this long, counted from the source's opening (key duration)"},
    {{"frames", required_argument, NULL, OPT_FRAMES}, "N",
     "stop once N frames have been processed (key frames): a run of a known length however "
     "fast the machine"},
    {{"record", required_argument, NULL, 'o'}, "DIR",
     "save every record_every-th frame, its result and the calibration there (key record; "
     "-o is the output directory, as in cdsp_tool)"},
    {{"set", required_argument, NULL, 'k'}, "KEY=VALUE", "set any key (repeatable)"},
    {{"verbose", no_argument, NULL, 'v'}, NULL, "log.level debug"},
    {{"quiet", no_argument, NULL, 'q'}, NULL, "log.level warn (twice: error)"},
    {{"check-config", no_argument, NULL, OPT_CHECK}, NULL,
     "check the configuration, print it as YAML, exit (0 valid, 2 not)"},
    {{"help-keys", no_argument, NULL, OPT_HELP_KEYS}, NULL, "list every configuration key"},
    {{"list-cameras", no_argument, NULL, OPT_LIST}, NULL,
     "list the cameras Aravis, V4L2 and libcamera see, as --source values, exit"},
    {{"version", no_argument, NULL, OPT_VERSION}, NULL, "print the version"},
    {{"help", no_argument, NULL, 'h'}, NULL, "this help"},
};
#define N_OPTIONS (sizeof option_table / sizeof option_table[0])
static const char short_opts[] = "+c:s:r:d:f:o:k:vqh";

static void usage(FILE *f)
{
    fprintf(f,
            "usage: cdspd [--config FILE] --source SRC --calib CAM.yaml --radius R\n"
            "             --dest HOST:PORT [--dest HOST:PORT ...] [--format binary|json]\n"
            "             [--mavlink URL ...] [--duration SECONDS] [--frames N] [-o|--record DIR]\n"
            "             [-k|--set KEY=VALUE] [-v|-q]\n"
            "Capture frames, solve the pipe's axis in each (libcdsp %d.%d.%d), stream the poses "
            "over UDP.\n\n",
            CDSP_VERSION_MAJOR, CDSP_VERSION_MINOR, CDSP_VERSION_PATCH);
    cdsp_host_options_usage(f, option_table, N_OPTIONS, 30);
    fprintf(f, "\nSignals: SIGTERM/SIGINT stop, SIGHUP reloads (a broken file keeps the running\n"
               "configuration), SIGUSR1 logs statistics. Exit status: 0 stopped, 1 runtime error,\n"
               "2 usage or configuration error, 3 the source could not be opened.\n"
               "Manual: docs/cdspd.md; datagrams: docs/protocol.md.\n");
}

typedef struct {
    int argc;
    char **argv;
    const char *config_path;
    int check, help, help_keys, version, list;
} cli;

/* Pass 1: what decides the run (help, --config) and usage errors. */
static int cli_scan(cli *o, int argc, char **argv)
{
    struct option longopts[N_OPTIONS + 1];
    int c;
    memset(o, 0, sizeof *o);
    o->argc = argc;
    o->argv = argv;
    cdsp_host_options_getopt(option_table, N_OPTIONS, longopts);
    optind = 0;
    opterr = 1;
    while ((c = getopt_long(argc, argv, short_opts, longopts, NULL)) != -1) {
        switch (c) {
        case 'c': o->config_path = optarg; break;
        case OPT_CHECK: o->check = 1; break;
        case 'h': o->help = 1; break;
        case OPT_HELP_KEYS: o->help_keys = 1; break;
        case OPT_VERSION: o->version = 1; break;
        case OPT_LIST: o->list = 1; break;
        case '?': return -1;
        default: break;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "cdspd: unexpected argument '%s'\n", argv[optind]);
        return -1;
    }
    return 0;
}

/* Defaults, the file, the command line in order, then the checks. */
static int load_config(const cli *o, cdspd_config *c, char *err, size_t errlen)
{
    struct option longopts[N_OPTIONS + 1];
    int ch, ndest_cli = 0, nmav_cli = 0, quiet = 0;
    char where[64];

    cdspd_config_defaults(c);
    if (o->config_path && cdspd_config_load_file(c, o->config_path, err, errlen))
        return -1;
    cdsp_host_options_getopt(option_table, N_OPTIONS, longopts);
    optind = 0;
    opterr = 0;
    while ((ch = getopt_long(o->argc, o->argv, short_opts, longopts, NULL)) != -1) {
        const char *key = NULL;
        int r = 0;
        switch (ch) {
        case 's': key = "source"; break;
        case OPT_CALIB: key = "calib"; break;
        case 'r': key = "radius"; break;
        case 'f': key = "format"; break;
        case OPT_DURATION: key = "duration"; break;
        case OPT_FRAMES: key = "frames"; break;
        case 'o':
            if (strchr(optarg, '=')) { /* -o KEY=VALUE was --set before 0.2: say so, do it */
                fprintf(stderr, "cdspd: warning: -o %s: -o is --record DIR now (as cdsp_tool's "
                        "--out); use -k/--set KEY=VALUE\n", optarg);
                goto set;
            }
            key = "record";
            break;
        case 'v': r = cdspd_config_set(c, "log.level", "debug", "-v", err, errlen); break;
        case 'q':
            quiet++;
            r = cdspd_config_set(c, "log.level", quiet > 1 ? "error" : "warn", "-q", err, errlen);
            break;
        case 'd':
            if (ndest_cli == 0)
                c->n_dest = 0;
            if (c->n_dest >= CDSPD_MAX_DEST) {
                snprintf(err, errlen, "--dest: at most %d destinations", CDSPD_MAX_DEST);
                return -1;
            }
            if (strlen(optarg) >= CDSPD_STR || !*optarg || strchr(optarg, ',')) {
                snprintf(err, errlen, "--dest '%s': expected HOST:PORT", optarg);
                return -1;
            }
            memset(&c->dest[c->n_dest], 0, sizeof c->dest[0]);
            strcpy(c->dest[c->n_dest++].text, optarg);
            ndest_cli++;
            break;
        case OPT_MAVLINK:
            if (nmav_cli++ == 0)
                c->n_mavlink = 0;
            if (c->n_mavlink >= CDSPD_MAX_MAVLINK) {
                snprintf(err, errlen, "--mavlink: at most %d links", CDSPD_MAX_MAVLINK);
                return -1;
            }
            if (strlen(optarg) >= CDSPD_STR || !*optarg || strchr(optarg, ',')) {
                snprintf(err, errlen, "--mavlink '%s': expected udpout://HOST:PORT or "
                         "serial:///dev/DEVICE:BAUD", optarg);
                return -1;
            }
            strcpy(c->mavlink[c->n_mavlink++], optarg);
            break;
        case 'k':
        set: {
            char kv[CDSPD_STR + 256], *eq;
            snprintf(kv, sizeof kv, "%s", optarg);
            eq = strchr(kv, '=');
            if (!eq || eq == kv) {
                snprintf(err, errlen, "--set '%s': expected KEY=VALUE", optarg);
                return -1;
            }
            *eq = 0;
            r = cdspd_config_set(c, kv, eq + 1, "--set", err, errlen);
            break;
        }
        default: break;
        }
        if (key) {
            snprintf(where, sizeof where, "--%s", key);
            r = cdspd_config_set(c, key, optarg, where, err, errlen);
        }
        if (r)
            return -1;
    }
    if (cdspd_config_finish(c, err, errlen))
        return -1;
    {
        const char *arg, *why;
        if (!cdspd_source_available(cdspd_source_kind_parse(c->source, &arg), &why)) {
            snprintf(err, errlen, "key 'source': '%s': %s", c->source, why);
            return -1;
        }
    }
    return 0;
}

/* --list-cameras: one line per camera, "KIND:ID  description", to paste
 * into --source; a comment line per source kind that found none or is not
 * built in. Exit status 0 (none found is an answer, not an error). */
static int list_cameras(void)
{
    static const struct {
        int kind;
        const char *name;
        int (*list)(FILE *, char *, size_t);
    } kinds[] = {
#ifdef CDSPD_HAVE_ARAVIS
        {CDSPD_SRC_ARAVIS, "aravis", cdspd_src_aravis_list},
#else
        {CDSPD_SRC_ARAVIS, "aravis", NULL},
#endif
#ifdef CDSPD_HAVE_V4L2
        {CDSPD_SRC_V4L2, "v4l2", cdspd_src_v4l2_list},
#else
        {CDSPD_SRC_V4L2, "v4l2", NULL},
#endif
#ifdef CDSPD_HAVE_LIBCAMERA
        {CDSPD_SRC_LIBCAMERA, "libcamera", cdspd_src_libcamera_list},
#else
        {CDSPD_SRC_LIBCAMERA, "libcamera", NULL},
#endif
    };
    size_t i;
    for (i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        char err[512] = "";
        const char *why;
        int n;
        if (!kinds[i].list || !cdspd_source_available(kinds[i].kind, &why)) {
            printf("# %s: %s\n", kinds[i].name,
                   kinds[i].list ? why : "not built in (cdspd --version lists the sources)");
            continue;
        }
        fflush(stdout);
        n = kinds[i].list(stdout, err, sizeof err);
        if (n < 0)
            printf("# %s: %s\n", kinds[i].name, err);
        else if (n == 0)
            printf("# %s: no camera found\n", kinds[i].name);
    }
    return fflush(stdout) ? EXIT_RUNTIME : EXIT_OK;
}

static void apply_log_levels(const cdspd_config *c)
{
    int i;
    for (i = 0; i < CDSPD_LOGC_COUNT; i++)
        cdspd_log_set_level((cdspd_log_cat)i, (cdspd_log_level)cdspd_config_log_level(c, i));
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) && errno == EINTR) {
    }
}

int main(int argc, char **argv)
{
    cli o;
    cdspd_config *cfg = malloc(sizeof *cfg), *next = malloc(sizeof *next);
    cdspd_stats *stats = malloc(sizeof *stats);
    cdspd_pipeline *pipe = NULL;
    char err[2048], status[CDSPD_STR + 64];
    sigset_t set;
    pthread_t sig_th;
    int sig_started = 0;
    uint32_t seq = 0;
    uint64_t t_running = 0, t_stats, wd_us, t_wd = 0, hb_wd = (uint64_t)-1;
    int rc = EXIT_OK, ready = 0;
    cdspd_stats_window w;

    /* SIGHUP and SIGUSR1 kill a process by default: one sent while the
     * configuration is still loading (systemd's ExecReload, a script that
     * does not wait for READY=1) is held pending instead, and the signal
     * thread takes it once it runs (a reload, a report). SIGINT and SIGTERM
     * keep their default until then: stopping a start-up is what they ask. */
    sigemptyset(&set);
    sigaddset(&set, SIGHUP);
    sigaddset(&set, SIGUSR1);
    pthread_sigmask(SIG_BLOCK, &set, NULL);

    if (!cfg || !next || !stats) {
        fprintf(stderr, "cdspd: out of memory\n");
        rc = EXIT_RUNTIME;
        goto out;
    }
    if (cli_scan(&o, argc, argv)) {
        usage(stderr);
        rc = EXIT_CONFIG;
        goto out;
    }
    if (o.help) {
        usage(stdout);
        goto out;
    }
    if (o.version) {
        static const char *const kinds[] = {"sim", "file", "aravis", "v4l2", "libcamera"};
        const char *why;
        int k;
        printf("cdspd %s (libcdsp %d.%d.%d)\nsources:", CDSPD_VERSION, CDSP_VERSION_MAJOR,
               CDSP_VERSION_MINOR, CDSP_VERSION_PATCH);
        for (k = 0; k < 5; k++)
            if (cdspd_source_available(k, &why))
                printf(" %s", kinds[k]);
        printf("\nsd_notify: %s\n",
#ifdef CDSPD_HAVE_SYSTEMD
               "yes"
#else
               "no"
#endif
        );
        goto out;
    }
    if (o.list) {
        rc = list_cameras();
        goto out;
    }
    if (o.help_keys) {
        printf("Configuration keys (YAML: nested mappings give the dotted names; "
               "--set KEY=VALUE):\n");
        cdspd_config_help(stdout);
        goto out;
    }
    if (load_config(&o, cfg, err, sizeof err)) {
        fprintf(stderr, "cdspd: %s\n", err);
        rc = EXIT_CONFIG;
        goto out;
    }
    if (o.check) {
        const char *arg;
        if (cdspd_source_kind_parse(cfg->source, &arg) == CDSPD_SRC_FILE &&
            cdspd_src_file_matches(arg) == 0) {
            /* a run would retry for open_timeout and exit 3: say it now */
            fprintf(stderr, "cdspd: key 'source': '%s': no file matches '%s'\n", cfg->source, arg);
            rc = EXIT_CONFIG;
            goto out;
        }
        printf("# cdspd: configuration OK: source %s, calibration %s (%dx%d), %d destination%s, "
               "%d MAVLink link%s\n",
               cfg->source, cfg->calib, cfg->cam.width, cfg->cam.height, cfg->n_dest,
               cfg->n_dest == 1 ? "" : "s", cfg->n_mavlink, cfg->n_mavlink == 1 ? "" : "s");
        cdspd_config_dump(cfg, stdout);
        goto out;
    }
    apply_log_levels(cfg);

    /* every thread inherits this mask; only the signal thread takes them */
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    sigaddset(&set, SIGUSR1);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    signal(SIGPIPE, SIG_IGN);
    signal(SIGXFSZ, SIG_IGN); /* a file size limit is a write error for --record, not death */
    if (pthread_create(&sig_th, NULL, signal_thread, &set)) {
        fprintf(stderr, "cdspd: cannot start the signal thread\n");
        rc = EXIT_RUNTIME;
        goto out;
    }
    sig_started = 1;

    cdspd_stats_init(stats);
    LOG_I(MAIN, "cdspd %s starting: source %s, calibration %s (%dx%d), radius %g, %d destination%s%s%s",
          CDSPD_VERSION, cfg->source, cfg->calib, cfg->cam.width, cfg->cam.height, cfg->radius,
          cfg->n_dest, cfg->n_dest > 1 ? "s" : "", *cfg->config_file ? ", config " : "",
          cfg->config_file);
    cdspd_stats_set_down(stats, 1);
    rc = cdspd_pipeline_start(&pipe, cfg, stats, &seq, 1, err, sizeof err);
    if (rc) {
        LOG_E(MAIN, "%s", err);
        cdspd_stats_destroy(stats);
        goto out;
    }
    t_stats = cdspd_now_us();
    wd_us = cdspd_notify_watchdog_us();
    for (;;) {
        cdspd_pipe_state st;
        uint64_t now;
        sleep_ms(50);
        now = cdspd_now_us();
        if (CDSPD_GET(sig_stop)) {
            LOG_I(MAIN, "%s: stopping", CDSPD_GET(sig_last) == SIGINT ? "SIGINT" : "SIGTERM");
            break;
        }
        st = cdspd_pipeline_state(pipe);
        if (st == CDSPD_PIPE_FAILED) {
            rc = cdspd_pipeline_error(pipe, err, sizeof err);
            LOG_E(MAIN, "cannot open the source: %s", err);
            break;
        }
        if (st == CDSPD_PIPE_ENDED) {
            cdspd_counts k;
            cdspd_stats_get(stats, &k);
            if (cfg->frames > 0 && k.processed >= (uint64_t)cfg->frames)
                LOG_I(MAIN, "--frames %d reached: stopping", cfg->frames);
            else
                LOG_I(MAIN, "the source has ended: stopping");
            break;
        }
        if (st == CDSPD_PIPE_RUNNING && !ready) {
            ready = 1;
            t_stats = now; /* the first window starts with the stream */
            if (!t_running)
                t_running = now; /* a reload does not restart --duration */
            snprintf(status, sizeof status, "READY=1\nSTATUS=streaming poses from %s", cfg->source);
            cdspd_notify(status);
        }
        if (ready && cfg->duration > 0 && (double)(now - t_running) * 1e-6 >= cfg->duration) {
            LOG_I(MAIN, "--duration %g s reached: stopping", cfg->duration);
            break;
        }
        if (CDSPD_GET(sig_reload)) {
            CDSPD_SET(sig_reload, 0);
            LOG_I(MAIN, "SIGHUP: reloading the configuration");
            if (load_config(&o, next, err, sizeof err)) {
                LOG_E(CONFIG, "reload: %s; keeping the running configuration", err);
            } else {
                cdspd_config *t;
                int r;
                cdspd_notify("RELOADING=1");
                cdspd_pipeline_stop(pipe);
                pipe = NULL;
                apply_log_levels(next);
                r = cdspd_pipeline_start(&pipe, next, stats, &seq, 0, err, sizeof err);
                if (r) {
                    LOG_E(MAIN, "reload: %s: stopping", err);
                    rc = r;
                    break;
                }
                t = cfg;
                cfg = next;
                next = t;
                ready = 0;
                LOG_I(MAIN, "reloaded: source %s, %d destination%s", cfg->source, cfg->n_dest,
                      cfg->n_dest > 1 ? "s" : "");
            }
        }
        if (CDSPD_GET(sig_stats)) {
            CDSPD_SET(sig_stats, 0);
            cdspd_stats_window_take(stats, &w);
            cdspd_stats_log(&w, "SIGUSR1: ");
            t_stats = now;
        }
        if (ready && cfg->stats_interval > 0 &&
            (double)(now - t_stats) * 1e-6 >= cfg->stats_interval) {
            cdspd_stats_window_take(stats, &w);
            cdspd_stats_log(&w, "");
            t_stats = now;
        }
        /* The watchdog is fed only while the processing thread goes round
         * its loop (it does so at least every status_interval). */
        if (wd_us && now - t_wd >= wd_us / 2) {
            uint64_t hb = cdspd_pipeline_heartbeat(pipe);
            if (hb != hb_wd)
                cdspd_notify("WATCHDOG=1");
            else
                LOG_W(MAIN, "the processing thread made no progress for %.1f s: not feeding the "
                      "watchdog", (double)(now - t_wd) * 1e-6);
            hb_wd = hb;
            t_wd = now;
        }
    }
    cdspd_notify("STOPPING=1");
    cdspd_pipeline_stop(pipe);
    cdspd_stats_window_take(stats, &w);
    cdspd_stats_log(&w, "final: ");
    LOG_I(MAIN, "stopped (exit status %d)", rc);
    cdspd_stats_destroy(stats);
out:
    if (sig_started) {
        /* Joined, not detached: at exit no thread is left in sigwait (its
         * stack would count as lost under valgrind, tests/daemon/valgrind.sh).
         * The signal is one it waits for, directed at it. */
        CDSPD_SET(sig_quit, 1);
        pthread_kill(sig_th, SIGUSR1);
        pthread_join(sig_th, NULL);
    }
    free(stats);
    free(cfg);
    free(next);
    return rc;
}
