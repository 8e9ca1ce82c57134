/*
 * src_file.c - replays saved frames (PGM or PNG, anything
 * cdsp_host_image_read reads) matching file:GLOB, in name order, at
 * file.rate, optionally looped: for reproducing a field recording (--record
 * writes frames this reads). When all frames fit in file.cache_mb they are
 * decoded once at open, so replay does not allocate; otherwise each is read
 * (and allocated by the decoder) in turn. A frame that cannot be read is
 * reported and skipped (GRAB_BAD). A replay drops nothing: the capture
 * thread waits for the processing thread (source.h, replay), so file.rate=0
 * replays as fast as frames are solved.
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp_host.h"
#include "log.h"

typedef struct {
    glob_t g;
    int have_glob;
    cdsp_host_image *cache; /* g.gl_pathc images, or NULL */
    size_t next;            /* index of the next file */
    uint64_t n;             /* frames delivered */
    cdspd_pace pace;
} file_priv;

static void free_cache(file_priv *p)
{
    size_t i;
    if (!p->cache)
        return;
    for (i = 0; i < p->g.gl_pathc; i++)
        cdsp_host_image_free(&p->cache[i]);
    free(p->cache);
    p->cache = NULL;
}

static int file_open(cdspd_source *s, char *err, size_t errlen)
{
    file_priv *p = s->priv;
    int r;
    size_t i;
    double bytes = 0;

    if (p->have_glob) { /* reopen: keep the list and the cache */
        p->pace.started = 0;
        return CDSPD_OPEN_OK;
    }
    r = glob(s->arg, 0, NULL, &p->g);
    if (r == GLOB_NOMATCH || (r == 0 && p->g.gl_pathc == 0)) {
        if (r == 0)
            globfree(&p->g);
        snprintf(err, errlen, "file: no file matches '%s'", s->arg);
        return CDSPD_OPEN_RETRY;
    }
    if (r) {
        snprintf(err, errlen, "file: cannot list '%s' (%s)", s->arg,
                 r == GLOB_NOSPACE ? "out of memory" : "read error");
        return CDSPD_OPEN_RETRY;
    }
    p->have_glob = 1;
    p->next = 0;
    p->pace.started = 0;
    LOG_I(SOURCE, "file: %zu frame%s match '%s'", p->g.gl_pathc, p->g.gl_pathc > 1 ? "s" : "", s->arg);
    /* Decode everything now if it fits the cache budget (the frames'
     * calibrated size at 2 bytes per pixel is the estimate). */
    bytes = (double)p->g.gl_pathc * s->cfg->cam.width * s->cfg->cam.height * 2;
    if (bytes <= s->cfg->file.cache_mb * 1024 * 1024) {
        p->cache = calloc(p->g.gl_pathc, sizeof *p->cache);
        for (i = 0; p->cache && i < p->g.gl_pathc; i++) {
            cdsp_host_err herr;
            if (cdsp_host_image_read(p->g.gl_pathv[i], &p->cache[i], &herr)) {
                LOG_W(SOURCE, "file: %s (skipped on replay)", herr.msg);
                memset(&p->cache[i], 0, sizeof p->cache[i]);
            }
        }
        if (p->cache)
            LOG_I(SOURCE, "file: all frames decoded into memory");
    }
    return CDSPD_OPEN_OK;
}

static int copy_frame(cdspd_source *s, const cdsp_host_image *im, const char *name, cdspd_frame *f,
                      char *err, size_t errlen)
{
    size_t bpp = im->bits > 8 ? 2 : 1, row = (size_t)im->width * bpp;
    int y;
    (void)s;
    if (row * (size_t)im->height > f->cap) {
        snprintf(err, errlen, "file: %s: %dx%d is larger than the calibration's frame", name,
                 im->width, im->height);
        return CDSPD_GRAB_BAD;
    }
    for (y = 0; y < im->height; y++)
        memcpy(f->data + (size_t)y * row, (const uint8_t *)im->data + (size_t)y * im->stride, row);
    f->width = im->width;
    f->height = im->height;
    f->bits = im->bits;
    f->stride = row;
    return CDSPD_GRAB_FRAME;
}

static int file_grab(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen)
{
    file_priv *p = s->priv;
    double rate = s->cfg->file.rate;
    uint64_t period = rate > 0 ? (uint64_t)(1e6 / rate + 0.5) : 0, t;
    const char *name;
    int r;

    if (p->next >= p->g.gl_pathc) {
        if (!s->cfg->file.loop)
            return CDSPD_GRAB_END;
        p->next = 0;
    }
    if (!cdspd_pace_wait(&p->pace, p->n, period, timeout_ms, s->stop, &t))
        return CDSPD_GRAB_TIMEOUT;
    name = p->g.gl_pathv[p->next];
    if (p->cache) {
        if (!p->cache[p->next].data) {
            snprintf(err, errlen, "file: %s could not be read at start", name);
            r = CDSPD_GRAB_BAD;
        } else {
            r = copy_frame(s, &p->cache[p->next], name, f, err, errlen);
        }
    } else {
        cdsp_host_image im;
        cdsp_host_err herr;
        if (cdsp_host_image_read(name, &im, &herr)) {
            snprintf(err, errlen, "%s", herr.msg);
            r = CDSPD_GRAB_BAD;
        } else {
            r = copy_frame(s, &im, name, f, err, errlen);
            cdsp_host_image_free(&im);
        }
    }
    f->frame_id = p->n;
    f->t_camera_us = period ? t : cdspd_now_us();
    p->n++;
    p->next++;
    return r;
}

static void file_close(cdspd_source *s)
{
    (void)s;
}

static void file_destroy(cdspd_source *s)
{
    file_priv *p = s->priv;
    free_cache(p);
    if (p->have_glob)
        globfree(&p->g);
}

static const cdspd_source_ops file_ops = {"file", file_open, file_grab, file_close, file_destroy};

size_t cdspd_src_file_matches(const char *glob_pattern)
{
    glob_t g;
    size_t n = 0;
    memset(&g, 0, sizeof g); /* globfree is safe whatever glob returned */
    if (glob(glob_pattern, 0, NULL, &g) == 0)
        n = g.gl_pathc;
    globfree(&g);
    return n;
}

static int readable(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    fclose(f);
    return 1;
}

int cdspd_src_file_find_calib(const char *glob_pattern, char *out, size_t cap)
{
    glob_t g;
    char dir[4096], name[4096], *slash, *dash;
    int found = 0;
    memset(&g, 0, sizeof g);
    if (glob(glob_pattern, 0, NULL, &g) != 0 || g.gl_pathc == 0) {
        globfree(&g);
        return 0;
    }
    snprintf(dir, sizeof dir, "%s", g.gl_pathv[0]);
    globfree(&g);
    slash = strrchr(dir, '/');
    snprintf(name, sizeof name, "%s", slash ? slash + 1 : dir);
    if (slash)
        slash[1] = 0;
    else
        dir[0] = 0;
    dash = strrchr(name, '-');
    if (dash) {
        *dash = 0;
        if ((size_t)snprintf(out, cap, "%s%s.yaml", dir, name) < cap && readable(out))
            found = 1;
    }
    if (!found && (size_t)snprintf(out, cap, "%scamera.yaml", dir) < cap && readable(out))
        found = 1;
    if (!found && cap)
        out[0] = 0;
    return found;
}

int cdspd_src_file_init(cdspd_source *s, char *err, size_t errlen)
{
    if (cdspd_source_init_priv(s, &file_ops, sizeof(file_priv), err, errlen))
        return -1;
    s->replay = 1; /* a recording is replayed whole, in order, whatever file.rate is */
    return 0;
}
