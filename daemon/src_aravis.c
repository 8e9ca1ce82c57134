/*
 * src_aravis.c - GigE Vision and USB3 Vision cameras through libaravis
 * (0.8): aravis:[ID] opens the camera Aravis knows as ID (its device id,
 * serial number, or IP address), or the first one found when ID is empty.
 *
 * Open: pixel format (Mono8, Mono10/Mono12 unpacked, Mono16; "auto" takes
 * Mono8 when offered, since deeper pixels double the bandwidth, else the
 * deepest), region (the calibration's size unless aravis.region says
 * otherwise), exposure, gain, frame rate and packet size when asked and
 * available; the stream socket buffer sized to the payload (AUTO: the
 * kernel default lost most large frames on loopback, FACTS.md); the packet
 * socket disabled for loopback cameras (as root Aravis would use one, and it
 * sees nothing on lo). aravis.buffers buffers are queued once.
 *
 * Grab: pop a buffer (timeout), copy the image into the pool's buffer, give
 * the buffer back. Incomplete buffers (missing packets...) are BAD and
 * counted. The camera counts as lost on Aravis's "control-lost" signal
 * (from its heartbeat thread: only an atomic flag is set there) or after
 * aravis.frame_timeout seconds without any buffer; the pipeline then closes
 * it (stop may time out on a dead camera: errors are ignored) and reopens
 * with back-off.
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arv.h>

#include "log.h"

typedef struct {
    ArvCamera *camera;
    ArvStream *stream;
    gulong lost_handler;
    gint lost;              /* set by the control-lost handler (g_atomic) */
    uint64_t last_buffer_us;
    size_t payload;
    int bits;
} arv_priv;

static void on_control_lost(ArvDevice *device, gpointer data)
{
    arv_priv *p = data;
    (void)device;
    g_atomic_int_set(&p->lost, 1);
}

static int bits_of(ArvPixelFormat pf)
{
    switch (pf) {
    case ARV_PIXEL_FORMAT_MONO_8: return 8;
    case ARV_PIXEL_FORMAT_MONO_10: return 10;
    case ARV_PIXEL_FORMAT_MONO_12: return 12;
    case ARV_PIXEL_FORMAT_MONO_16: return 16;
    default: return 0;
    }
}

/* Formats in the order "auto" prefers them. */
static const struct {
    const char *name;
    ArvPixelFormat pf;
} formats[] = {{"Mono8", ARV_PIXEL_FORMAT_MONO_8},
               {"Mono16", ARV_PIXEL_FORMAT_MONO_16},
               {"Mono12", ARV_PIXEL_FORMAT_MONO_12},
               {"Mono10", ARV_PIXEL_FORMAT_MONO_10}};
#define N_FORMATS (sizeof formats / sizeof formats[0])

static void close_camera(arv_priv *p)
{
    if (p->camera) {
        GError *e = NULL;
        arv_camera_stop_acquisition(p->camera, &e);
        if (e) {
            LOG_D(SOURCE, "aravis: stopping the acquisition: %s (ignored)", e->message);
            g_clear_error(&e);
        }
    }
    if (p->stream) {
        guint64 done = 0, failures = 0, underruns = 0;
        arv_stream_get_statistics(p->stream, &done, &failures, &underruns);
        /* underruns: a frame came while cdspd held every buffer (cdspd's
         * fault); failures: incomplete frames (the network's) */
        LOG_I(SOURCE, "aravis: stream statistics: %llu frames complete, %llu failed, %llu underruns",
              (unsigned long long)done, (unsigned long long)failures, (unsigned long long)underruns);
        arv_stream_set_emit_signals(p->stream, FALSE);
        g_object_unref(p->stream);
        p->stream = NULL;
    }
    if (p->camera) {
        ArvDevice *dev = arv_camera_get_device(p->camera);
        if (p->lost_handler && dev)
            g_signal_handler_disconnect(dev, p->lost_handler);
        p->lost_handler = 0;
        g_object_unref(p->camera);
        p->camera = NULL;
    }
}

static int fail(arv_priv *p, GError **e, char *err, size_t errlen, const char *what, int rc)
{
    snprintf(err, errlen, "aravis: %s: %s", what, e && *e ? (*e)->message : "failed");
    if (e)
        g_clear_error(e);
    close_camera(p);
    return rc;
}

/* Is the camera on a loopback address (then its packet socket sees nothing)? */
static int camera_on_loopback(ArvCamera *camera)
{
    ArvDevice *dev = arv_camera_get_device(camera);
    GSocketAddress *sa;
    int lo = 0;
    if (!arv_camera_is_gv_device(camera) || !ARV_IS_GV_DEVICE(dev))
        return 0;
    sa = arv_gv_device_get_device_address(ARV_GV_DEVICE(dev));
    if (sa && G_IS_INET_SOCKET_ADDRESS(sa))
        lo = g_inet_address_get_is_loopback(g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(sa)));
    return lo;
}

static int aravis_open(cdspd_source *s, char *err, size_t errlen)
{
    arv_priv *p = s->priv;
    const cdspd_config *c = s->cfg;
    GError *e = NULL;
    ArvPixelFormat pf = 0;
    gint x, y, w, h;
    int i;
    const char *id = *s->arg ? s->arg : NULL;

    g_atomic_int_set(&p->lost, 0);
    p->camera = arv_camera_new(id, &e);
    if (!p->camera) {
        char what[256];
        snprintf(what, sizeof what, "no camera %s%s%s", id ? "'" : "", id ? id : "found", id ? "'" : "");
        return fail(p, &e, err, errlen, what, CDSPD_OPEN_RETRY);
    }
    p->lost_handler = g_signal_connect(arv_camera_get_device(p->camera), "control-lost",
                                       G_CALLBACK(on_control_lost), p);

    /* pixel format */
    if (!strcmp(c->aravis.pixel_format, "auto")) {
        guint n = 0, k;
        gint64 *avail = arv_camera_dup_available_pixel_formats(p->camera, &n, &e);
        if (!avail)
            return fail(p, &e, err, errlen, "reading the pixel formats", CDSPD_OPEN_RETRY);
        for (i = 0; i < (int)N_FORMATS && !pf; i++)
            for (k = 0; k < n; k++)
                if ((ArvPixelFormat)avail[k] == formats[i].pf) {
                    pf = formats[i].pf;
                    break;
                }
        g_free(avail);
        if (!pf) {
            snprintf(err, errlen, "aravis: %s offers none of Mono8, Mono16, Mono12, Mono10 "
                     "(packed and colour formats are not read)", arv_camera_get_model_name(p->camera, NULL));
            close_camera(p);
            return CDSPD_OPEN_FATAL;
        }
    } else {
        for (i = 0; i < (int)N_FORMATS; i++)
            if (!strcmp(c->aravis.pixel_format, formats[i].name))
                pf = formats[i].pf;
        if (!pf) {
            snprintf(err, errlen, "key 'aravis.pixel_format': '%s' is not Mono8, Mono10, Mono12, "
                     "Mono16 or auto", c->aravis.pixel_format);
            close_camera(p);
            return CDSPD_OPEN_FATAL;
        }
    }
    arv_camera_set_pixel_format(p->camera, pf, &e);
    if (e)
        return fail(p, &e, err, errlen, "setting the pixel format", CDSPD_OPEN_FATAL);
    p->bits = bits_of(arv_camera_get_pixel_format(p->camera, NULL));
    if (!p->bits) {
        snprintf(err, errlen, "aravis: the camera did not take pixel format %s", c->aravis.pixel_format);
        close_camera(p);
        return CDSPD_OPEN_FATAL;
    }

    /* region: the calibration's size */
    x = c->aravis.region[0];
    y = c->aravis.region[1];
    w = c->aravis.region[2] ? c->aravis.region[2] : c->cam.width;
    h = c->aravis.region[3] ? c->aravis.region[3] : c->cam.height;
    arv_camera_set_region(p->camera, x, y, w, h, &e);
    if (e)
        return fail(p, &e, err, errlen, "setting the region", CDSPD_OPEN_FATAL);
    arv_camera_get_region(p->camera, &x, &y, &w, &h, &e);
    if (e)
        return fail(p, &e, err, errlen, "reading the region", CDSPD_OPEN_RETRY);
    if (w != c->cam.width || h != c->cam.height) {
        snprintf(err, errlen, "aravis: the camera delivers %dx%d, the calibration %s is for %dx%d "
                 "(aravis.region)", w, h, c->calib, c->cam.width, c->cam.height);
        close_camera(p);
        return CDSPD_OPEN_FATAL;
    }

    if (c->aravis.exposure_us > 0) {
        if (arv_camera_is_exposure_time_available(p->camera, NULL))
            arv_camera_set_exposure_time(p->camera, c->aravis.exposure_us, &e);
        else
            LOG_W(SOURCE, "aravis: the camera has no exposure time setting: aravis.exposure_us ignored");
        if (e)
            return fail(p, &e, err, errlen, "setting the exposure", CDSPD_OPEN_FATAL);
    }
    if (c->aravis.gain >= 0) {
        if (arv_camera_is_gain_available(p->camera, NULL))
            arv_camera_set_gain(p->camera, c->aravis.gain, &e);
        else
            LOG_W(SOURCE, "aravis: the camera has no gain setting: aravis.gain ignored");
        if (e)
            return fail(p, &e, err, errlen, "setting the gain", CDSPD_OPEN_FATAL);
    }
    if (c->aravis.frame_rate > 0) {
        if (arv_camera_is_frame_rate_available(p->camera, NULL))
            arv_camera_set_frame_rate(p->camera, c->aravis.frame_rate, &e);
        else
            LOG_W(SOURCE, "aravis: the camera has no frame rate setting: aravis.frame_rate ignored");
        if (e)
            return fail(p, &e, err, errlen, "setting the frame rate", CDSPD_OPEN_FATAL);
    }
    if (arv_camera_is_gv_device(p->camera)) {
        int use_socket = c->aravis.packet_socket == 1 ||
                         (c->aravis.packet_socket == 2 && !camera_on_loopback(p->camera));
        if (c->aravis.packet_size > 0) {
            arv_camera_gv_set_packet_size(p->camera, c->aravis.packet_size, &e);
            if (e)
                return fail(p, &e, err, errlen, "setting the packet size", CDSPD_OPEN_FATAL);
        }
        arv_camera_gv_set_stream_options(p->camera, use_socket ? ARV_GV_STREAM_OPTION_NONE
                                                               : ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    }

    p->payload = arv_camera_get_payload(p->camera, &e);
    if (e)
        return fail(p, &e, err, errlen, "reading the payload size", CDSPD_OPEN_RETRY);
    p->stream = arv_camera_create_stream(p->camera, NULL, NULL, &e);
    if (!p->stream)
        return fail(p, &e, err, errlen, "creating the stream", CDSPD_OPEN_RETRY);
    if (ARV_IS_GV_STREAM(p->stream))
        g_object_set(p->stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_AUTO, NULL);
    for (i = 0; i < c->aravis.buffers; i++)
        arv_stream_push_buffer(p->stream, arv_buffer_new(p->payload, NULL));
    arv_camera_start_acquisition(p->camera, &e);
    if (e)
        return fail(p, &e, err, errlen, "starting the acquisition", CDSPD_OPEN_RETRY);
    p->last_buffer_us = cdspd_now_us();
    LOG_I(SOURCE, "aravis: %s %s (%s): %dx%d at (%d, %d), %d bit, %.3g fps, payload %zu bytes, "
          "packet socket %s",
          arv_camera_get_vendor_name(p->camera, NULL), arv_camera_get_model_name(p->camera, NULL),
          arv_camera_get_device_id(p->camera, NULL), w, h, x, y, p->bits,
          arv_camera_is_frame_rate_available(p->camera, NULL) ? arv_camera_get_frame_rate(p->camera, NULL)
                                                              : 0.0,
          p->payload,
          arv_camera_is_gv_device(p->camera)
              ? (c->aravis.packet_socket == 1 ||
                         (c->aravis.packet_socket == 2 && !camera_on_loopback(p->camera))
                     ? "on"
                     : "off")
              : "n/a");
    return CDSPD_OPEN_OK;
}

static int aravis_grab(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen)
{
    arv_priv *p = s->priv;
    ArvBuffer *b;
    ArvBufferStatus st;
    int r = CDSPD_GRAB_FRAME;

    if (g_atomic_int_get(&p->lost)) {
        snprintf(err, errlen, "aravis: control of the camera lost (no heartbeat answer)");
        return CDSPD_GRAB_LOST;
    }
    b = arv_stream_timeout_pop_buffer(p->stream, (guint64)timeout_ms * 1000u);
    if (!b) {
        if ((double)(cdspd_now_us() - p->last_buffer_us) * 1e-6 > s->cfg->aravis.frame_timeout) {
            snprintf(err, errlen, "aravis: no frame for %.1f s (aravis.frame_timeout)",
                     s->cfg->aravis.frame_timeout);
            return CDSPD_GRAB_LOST;
        }
        return CDSPD_GRAB_TIMEOUT;
    }
    p->last_buffer_us = cdspd_now_us();
    st = arv_buffer_get_status(b);
    /* also for a bad frame: its bad-frame datagram carries the camera's number */
    f->frame_id = arv_buffer_get_frame_id(b);
    f->t_camera_us = arv_buffer_get_timestamp(b) / 1000u;
    if (st != ARV_BUFFER_STATUS_SUCCESS) {
        snprintf(err, errlen, "aravis: frame %llu incomplete (buffer status %d%s)",
                 (unsigned long long)arv_buffer_get_frame_id(b), (int)st,
                 st == ARV_BUFFER_STATUS_MISSING_PACKETS ? ": missing packets" : "");
        r = CDSPD_GRAB_BAD;
    } else {
        size_t size = 0, bpp, row;
        const uint8_t *img = arv_buffer_get_image_data(b, &size);
        int w = arv_buffer_get_image_width(b), h = arv_buffer_get_image_height(b), y;
        int bits = bits_of(arv_buffer_get_image_pixel_format(b));
        bpp = bits > 8 ? 2 : 1;
        row = (size_t)w * bpp;
        if (!bits || !img || w <= 0 || h <= 0 || size < row * (size_t)h || row * (size_t)h > f->cap) {
            snprintf(err, errlen, "aravis: frame %llu: %dx%d, pixel format 0x%08x, %zu bytes: not usable",
                     (unsigned long long)arv_buffer_get_frame_id(b), w, h,
                     (unsigned)arv_buffer_get_image_pixel_format(b), size);
            r = CDSPD_GRAB_BAD;
        } else {
            for (y = 0; y < h; y++)
                memcpy(f->data + (size_t)y * row, img + (size_t)y * row, row);
            f->width = w;
            f->height = h;
            f->bits = bits;
            f->stride = row;
        }
    }
    arv_stream_push_buffer(p->stream, b);
    return r;
}

static void aravis_close(cdspd_source *s)
{
    close_camera(s->priv);
}

static void aravis_destroy(cdspd_source *s)
{
    arv_priv *p = s->priv;
    if (!p)
        return;
    close_camera(p);
    free(p);
    s->priv = NULL;
}

static const cdspd_source_ops aravis_ops = {"aravis", aravis_open, aravis_grab, aravis_close,
                                            aravis_destroy};

int cdspd_src_aravis_init(cdspd_source *s, char *err, size_t errlen)
{
    arv_priv *p = calloc(1, sizeof *p);
    if (!p) {
        snprintf(err, errlen, "aravis: out of memory");
        return -1;
    }
    s->priv = p;
    s->ops = &aravis_ops;
    return 0;
}

int cdspd_src_aravis_list(FILE *out, char *err, size_t errlen)
{
    unsigned i, n;
    (void)err;
    (void)errlen;
    /* GigE Vision discovery (a broadcast on every interface) and USB3 Vision */
    arv_update_device_list();
    n = arv_get_n_devices();
    for (i = 0; i < n; i++) {
        const char *id = arv_get_device_id(i), *vendor = arv_get_device_vendor(i),
                   *model = arv_get_device_model(i), *serial = arv_get_device_serial_nbr(i),
                   *addr = arv_get_device_address(i), *proto = arv_get_device_protocol(i);
        fprintf(out, "aravis:%-30s %s %s, serial %s, %s %s\n", id ? id : "?", vendor ? vendor : "?",
                model ? model : "?", serial ? serial : "?", proto ? proto : "?", addr ? addr : "");
    }
    return (int)n;
}
