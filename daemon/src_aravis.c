/*
 * src_aravis.c - GigE Vision and USB3 Vision cameras through libaravis
 * (0.8): aravis:[ID] opens the camera Aravis knows as ID (its device id,
 * serial number, or IP address), or the first one found when ID is empty.
 *
 * Open: pixel format (any of daemon/pixfmt.h: mono, packed mono, Bayer,
 * RGB; "auto" takes the first the camera offers in pixfmt.h's order: Mono8,
 * since deeper pixels double the bandwidth, then the deeper mono formats,
 * packed mono, Bayer, RGB), region (the calibration's size unless aravis.region says
 * otherwise), exposure, gain, frame rate and packet size when asked and
 * available; the stream socket buffer sized to the payload (AUTO: the
 * kernel default lost most large frames on loopback, FACTS.md); the packet
 * socket disabled for loopback cameras (as root Aravis would use one, and it
 * sees nothing on lo). aravis.buffers buffers are queued once.
 *
 * Triggers (aravis.trigger_*): FrameStart's TriggerMode, TriggerSource and
 * TriggerActivation where the camera has them; with aravis.trigger_rate
 * cdspd itself sends TriggerSoftware at that rate from the grab loop.
 * Clock (aravis.ptp): PtpEnable (SFNC) or GevIEEE1588 (GigE Vision) when
 * asked; the tick frequency and PTP state are logged at open.
 *
 * Grab: pop a buffer (timeout), convert the image into the pool's buffer
 * (cdspd_pixfmt_convert: a copy for mono, unpacking, Bayer/RGB luminance;
 * its scratch is allocated at open, never per frame), give the buffer
 * back. Incomplete buffers (missing packets...) are BAD and counted.
 * t_camera_us is the buffer's timestamp: the camera's own clock (GVSP
 * leader ticks, which Aravis scales by GevTimestampTickFrequency; U3V
 * leaders are in ns), PTP time when the camera runs IEEE 1588.
 * The camera counts as lost on Aravis's "control-lost" signal (from its
 * heartbeat thread: only an atomic flag is set there) or after
 * aravis.frame_timeout seconds without any buffer; the pipeline then closes
 * it (stop may time out on a dead camera: errors are ignored) and reopens
 * with back-off. With an external trigger (trigger_mode on and no
 * trigger_rate) no frame is normal, not a loss: the camera is then only
 * lost on control-lost or when a register read fails after frame_timeout
 * without frames, so a trigger that stops gives no-frame status datagrams
 * and no reconnects.
 */
#define _POSIX_C_SOURCE 200809L
#include "source.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arv.h>

#include "log.h"
#include "pixfmt.h"

typedef struct {
    ArvCamera *camera;
    ArvStream *stream;
    gulong lost_handler;
    gint lost;              /* set by the control-lost handler (g_atomic) */
    uint64_t last_buffer_us;
    size_t payload;
    const cdspd_pixfmt *pf; /* the format set at open */
    void *scratch;          /* cdspd_pixfmt_convert's, for the region's width */
    size_t scratch_len;
    int externally_triggered; /* no frame is not a loss (see the top) */
    uint64_t trigger_period_us, next_trigger_us; /* software trigger, 0: none */
    uint64_t triggers_sent;
    uint64_t last_alive_check_us;
} arv_priv;

static void on_control_lost(ArvDevice *device, gpointer data)
{
    arv_priv *p = data;
    (void)device;
    g_atomic_int_set(&p->lost, 1);
}

/* pixfmt.c's PFNC codes are Aravis's (checked here, where both are in
 * scope: a typedef of negative size if one differs). */
#define CDSPD_SAME(a, b) typedef char cdspd_code_##a[((b) == (a##u)) ? 1 : -1]
CDSPD_SAME(0x01080001, ARV_PIXEL_FORMAT_MONO_8);
CDSPD_SAME(0x010c0004, ARV_PIXEL_FORMAT_MONO_10_PACKED);
CDSPD_SAME(0x010c0006, ARV_PIXEL_FORMAT_MONO_12_PACKED);
CDSPD_SAME(0x01080009, ARV_PIXEL_FORMAT_BAYER_RG_8);
CDSPD_SAME(0x01100031, ARV_PIXEL_FORMAT_BAYER_BG_16);
CDSPD_SAME(0x02180014, ARV_PIXEL_FORMAT_RGB_8_PACKED);
CDSPD_SAME(0x02180015, ARV_PIXEL_FORMAT_BGR_8_PACKED);

/* The names "auto" and aravis.pixel_format know, for messages. */
static void format_names(char *buf, size_t len)
{
    size_t i, n = 0;
    buf[0] = 0;
    for (i = 0; cdspd_pixfmt_at(i) && n < len; i++)
        n += (size_t)snprintf(buf + n, len - n, "%s%s", i ? ", " : "", cdspd_pixfmt_at(i)->name);
}

static int has_feature(ArvCamera *camera, const char *name)
{
    GError *e = NULL;
    gboolean ok = arv_camera_is_feature_available(camera, name, &e);
    g_clear_error(&e);
    return ok ? 1 : 0;
}

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
        if (p->trigger_period_us)
            LOG_I(SOURCE, "aravis: %llu software triggers sent", (unsigned long long)p->triggers_sent);
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
    free(p->scratch);
    p->scratch = NULL;
    p->scratch_len = 0;
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

/* Set an enumeration feature when the camera has it; *missing counts the
 * ones it has not. Returns 0, or -1 with err when the camera refuses. */
static int set_enum(ArvCamera *camera, const char *feature, const char *value, int *missing, char *err,
                    size_t errlen)
{
    GError *e = NULL;
    if (!has_feature(camera, feature)) {
        (*missing)++;
        LOG_W(SOURCE, "aravis: the camera has no %s: %s ignored", feature, value);
        return 0;
    }
    arv_camera_set_string(camera, feature, value, &e);
    if (e) {
        snprintf(err, errlen, "aravis: setting %s to %s: %s", feature, value, e->message);
        g_clear_error(&e);
        return -1;
    }
    return 0;
}

/* aravis.trigger_*: FrameStart's trigger, and the software trigger's pace. */
static int set_trigger(arv_priv *p, const cdspd_config *c, char *err, size_t errlen)
{
    const char *mode = c->aravis.trigger_mode == 2 ? "On" : "Off";
    int missing = 0, software;

    p->externally_triggered = 0;
    p->trigger_period_us = 0;
    p->triggers_sent = 0;
    if (c->aravis.trigger_mode == 0 && !*c->aravis.trigger_source && !*c->aravis.trigger_activation &&
        c->aravis.trigger_rate <= 0)
        return CDSPD_OPEN_OK;
    /* the selector first: the other three are per selector */
    if (has_feature(p->camera, "TriggerSelector") &&
        set_enum(p->camera, "TriggerSelector", "FrameStart", &missing, err, errlen))
        return CDSPD_OPEN_FATAL;
    if (*c->aravis.trigger_source &&
        set_enum(p->camera, "TriggerSource", c->aravis.trigger_source, &missing, err, errlen))
        return CDSPD_OPEN_FATAL;
    if (*c->aravis.trigger_activation &&
        set_enum(p->camera, "TriggerActivation", c->aravis.trigger_activation, &missing, err, errlen))
        return CDSPD_OPEN_FATAL;
    if (c->aravis.trigger_mode && set_enum(p->camera, "TriggerMode", mode, &missing, err, errlen))
        return CDSPD_OPEN_FATAL;
    if (c->aravis.trigger_mode == 2 && missing) {
        snprintf(err, errlen, "aravis: aravis.trigger_mode on, but the camera lacks %d of the trigger "
                 "features (see the warnings)", missing);
        return CDSPD_OPEN_FATAL;
    }
    software = has_feature(p->camera, "TriggerSource") &&
               !strcmp(arv_camera_get_string(p->camera, "TriggerSource", NULL) ?
                       arv_camera_get_string(p->camera, "TriggerSource", NULL) : "", "Software");
    if (c->aravis.trigger_rate > 0) {
        if (!software || !has_feature(p->camera, "TriggerSoftware")) {
            snprintf(err, errlen, "aravis: aravis.trigger_rate needs trigger_source Software and "
                     "the camera's TriggerSoftware command");
            return CDSPD_OPEN_FATAL;
        }
        p->trigger_period_us = (uint64_t)(1e6 / c->aravis.trigger_rate + 0.5);
    }
    p->externally_triggered = c->aravis.trigger_mode == 2 && p->trigger_period_us == 0;
    {
        const char *src = has_feature(p->camera, "TriggerSource")
                              ? arv_camera_get_string(p->camera, "TriggerSource", NULL)
                              : NULL;
        char pace[64] = "";
        if (p->trigger_period_us)
            snprintf(pace, sizeof pace, ", %.4g software triggers per second", c->aravis.trigger_rate);
        LOG_I(SOURCE, "aravis: trigger %s, source %s%s%s", c->aravis.trigger_mode == 2 ? "on" : "off",
              src ? src : "(none)", pace,
              p->externally_triggered ? "; external trigger: no frame is not a lost camera" : "");
    }
    return CDSPD_OPEN_OK;
}

/* aravis.ptp and the camera clock's description in the log. */
static int set_clock(arv_priv *p, const cdspd_config *c, char *err, size_t errlen)
{
    GError *e = NULL;
    const char *ptp = has_feature(p->camera, "PtpEnable")     ? "PtpEnable"
                      : has_feature(p->camera, "GevIEEE1588") ? "GevIEEE1588"
                                                              : NULL;
    const char *status = has_feature(p->camera, "PtpStatus")            ? "PtpStatus"
                         : has_feature(p->camera, "GevIEEE1588Status") ? "GevIEEE1588Status"
                                                                       : NULL;
    const char *tick = has_feature(p->camera, "GevTimestampTickFrequency") ? "GevTimestampTickFrequency"
                       : has_feature(p->camera, "TimestampTickFrequency") ? "TimestampTickFrequency"
                                                                          : NULL;
    if (c->aravis.ptp) {
        if (!ptp) {
            LOG_W(SOURCE, "aravis: the camera has neither PtpEnable nor GevIEEE1588: aravis.ptp "
                  "ignored, t_camera_us is its own free-running clock");
        } else {
            arv_camera_set_boolean(p->camera, ptp, c->aravis.ptp == 2, &e);
            if (e) {
                snprintf(err, errlen, "aravis: setting %s: %s", ptp, e->message);
                g_clear_error(&e);
                return CDSPD_OPEN_FATAL;
            }
        }
    }
    LOG_I(SOURCE, "aravis: camera clock: %s%llu Hz ticks%s; PTP %s%s%s", tick ? "" : "(no tick frequency "
          "feature) ", tick ? (unsigned long long)arv_camera_get_integer(p->camera, tick, NULL) : 0ull,
          tick ? "" : "", ptp ? (arv_camera_get_boolean(p->camera, ptp, NULL) ? "on" : "off") : "not offered",
          status ? ", status " : "", status ? arv_camera_get_string(p->camera, status, NULL) : "");
    return CDSPD_OPEN_OK;
}

static int aravis_open(cdspd_source *s, char *err, size_t errlen)
{
    arv_priv *p = s->priv;
    const cdspd_config *c = s->cfg;
    GError *e = NULL;
    ArvPixelFormat pf = 0;
    gint x, y, w, h;
    int i, r;
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
        size_t j;
        gint64 *avail = arv_camera_dup_available_pixel_formats(p->camera, &n, &e);
        if (!avail)
            return fail(p, &e, err, errlen, "reading the pixel formats", CDSPD_OPEN_RETRY);
        for (j = 0; cdspd_pixfmt_at(j) && !pf; j++)
            for (k = 0; k < n; k++)
                if ((uint32_t)avail[k] == cdspd_pixfmt_at(j)->code) {
                    pf = (ArvPixelFormat)avail[k];
                    break;
                }
        g_free(avail);
        if (!pf) {
            char names[1024];
            format_names(names, sizeof names);
            snprintf(err, errlen, "aravis: %s offers none of %s", arv_camera_get_model_name(p->camera, NULL),
                     names);
            close_camera(p);
            return CDSPD_OPEN_FATAL;
        }
    } else {
        const cdspd_pixfmt *want = cdspd_pixfmt_find(c->aravis.pixel_format);
        if (!want) {
            char names[1024];
            format_names(names, sizeof names);
            snprintf(err, errlen, "key 'aravis.pixel_format': '%s' is not one of %s or auto",
                     c->aravis.pixel_format, names);
            close_camera(p);
            return CDSPD_OPEN_FATAL;
        }
        pf = (ArvPixelFormat)want->code;
    }
    arv_camera_set_pixel_format(p->camera, pf, &e);
    if (e)
        return fail(p, &e, err, errlen, "setting the pixel format", CDSPD_OPEN_FATAL);
    p->pf = cdspd_pixfmt_from_code((uint32_t)arv_camera_get_pixel_format(p->camera, NULL));
    if (!p->pf || p->pf->code != (uint32_t)pf) {
        snprintf(err, errlen, "aravis: the camera did not take pixel format %s (it reports 0x%08x)",
                 cdspd_pixfmt_from_code((uint32_t)pf)->name,
                 (unsigned)arv_camera_get_pixel_format(p->camera, NULL));
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
    /* the converter's rows, for every format at this width: once per open */
    p->scratch_len = 3 * (size_t)w * sizeof(uint32_t);
    p->scratch = malloc(p->scratch_len);
    if (!p->scratch) {
        snprintf(err, errlen, "aravis: out of memory for a %d-pixel row", w);
        close_camera(p);
        return CDSPD_OPEN_RETRY;
    }
    if ((r = set_trigger(p, c, err, errlen)) != CDSPD_OPEN_OK ||
        (r = set_clock(p, c, err, errlen)) != CDSPD_OPEN_OK) {
        close_camera(p);
        return r;
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
    p->next_trigger_us = p->last_buffer_us;
    LOG_I(SOURCE, "aravis: %s %s (%s): %dx%d at (%d, %d), %s (%d bit), %.3g fps, payload %zu bytes, "
          "packet socket %s",
          arv_camera_get_vendor_name(p->camera, NULL), arv_camera_get_model_name(p->camera, NULL),
          arv_camera_get_device_id(p->camera, NULL), w, h, x, y, p->pf->name, p->pf->out_bits,
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

    uint64_t now, wait_us = (uint64_t)timeout_ms * 1000u;

    if (g_atomic_int_get(&p->lost)) {
        snprintf(err, errlen, "aravis: control of the camera lost (no heartbeat answer)");
        return CDSPD_GRAB_LOST;
    }
    now = cdspd_now_us();
    if (p->trigger_period_us) {
        /* one trigger per period; a late loop does not send a burst to
         * catch up (the camera would only drop frames) */
        if (now >= p->next_trigger_us) {
            GError *e = NULL;
            arv_camera_software_trigger(p->camera, &e);
            p->triggers_sent++;
            if (e) {
                LOG_D(SOURCE, "aravis: software trigger: %s", e->message);
                g_clear_error(&e);
            }
            p->next_trigger_us += p->trigger_period_us;
            if (p->next_trigger_us <= now)
                p->next_trigger_us = now + p->trigger_period_us;
        }
        if (p->next_trigger_us - now < wait_us)
            wait_us = p->next_trigger_us - now;
    }
    b = arv_stream_timeout_pop_buffer(p->stream, wait_us);
    if (!b) {
        now = cdspd_now_us();
        if ((double)(now - p->last_buffer_us) * 1e-6 <= s->cfg->aravis.frame_timeout)
            return CDSPD_GRAB_TIMEOUT;
        if (p->externally_triggered) {
            /* no trigger, no frame: ask the camera whether it is there,
             * once per frame_timeout (a read takes a round trip) */
            GError *e = NULL;
            if ((double)(now - p->last_alive_check_us) * 1e-6 < s->cfg->aravis.frame_timeout)
                return CDSPD_GRAB_TIMEOUT;
            p->last_alive_check_us = now;
            arv_camera_get_string(p->camera, "TriggerMode", &e);
            if (!e) {
                LOG_D(SOURCE, "aravis: no trigger for %.1f s; the camera answers",
                      (double)(now - p->last_buffer_us) * 1e-6);
                return CDSPD_GRAB_TIMEOUT;
            }
            snprintf(err, errlen, "aravis: no frame for %.1f s and the camera does not answer (%s)",
                     (double)(now - p->last_buffer_us) * 1e-6, e->message);
            g_clear_error(&e);
            return CDSPD_GRAB_LOST;
        }
        snprintf(err, errlen, "aravis: no frame for %.1f s (aravis.frame_timeout)",
                 s->cfg->aravis.frame_timeout);
        return CDSPD_GRAB_LOST;
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
        size_t size = 0, row;
        const uint8_t *img = arv_buffer_get_image_data(b, &size);
        int w = arv_buffer_get_image_width(b), h = arv_buffer_get_image_height(b);
        const cdspd_pixfmt *pf = cdspd_pixfmt_from_code((uint32_t)arv_buffer_get_image_pixel_format(b));
        /* aravis.bayer_phase sensor: the region's offset moves the phase */
        int sensor = s->cfg->aravis.bayer_phase == 1;
        int xp = sensor ? arv_buffer_get_image_x(b) & 1 : 0, yp = sensor ? arv_buffer_get_image_y(b) & 1 : 0;
        const double *g = s->cfg->aravis.bayer_gains;
        row = (size_t)w * (size_t)cdspd_pixfmt_out_bytes(pf);
        if (!pf || !img || w <= 0 || h <= 0 || row * (size_t)h > f->cap ||
            cdspd_pixfmt_scratch_bytes(pf, w) > p->scratch_len ||
            cdspd_pixfmt_convert(pf, img, size, w, h, xp, yp, g[0] > 0 || g[1] > 0 || g[2] > 0 ? g : NULL,
                                 f->data, row, p->scratch, p->scratch_len)) {
            snprintf(err, errlen, "aravis: frame %llu: %dx%d, pixel format 0x%08x (%s), %zu bytes: not usable",
                     (unsigned long long)arv_buffer_get_frame_id(b), w, h,
                     (unsigned)arv_buffer_get_image_pixel_format(b), pf ? pf->name : "not known", size);
            r = CDSPD_GRAB_BAD;
        } else {
            f->width = w;
            f->height = h;
            f->bits = pf->out_bits;
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
    close_camera(s->priv);
}

static const cdspd_source_ops aravis_ops = {"aravis", aravis_open, aravis_grab, aravis_close,
                                            aravis_destroy};

int cdspd_src_aravis_init(cdspd_source *s, char *err, size_t errlen)
{
    return cdspd_source_init_priv(s, &aravis_ops, sizeof(arv_priv), err, errlen);
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
