/*
 * src_libcamera.cpp - cameras through libcamera's C++ API (Raspberry Pi
 * and other ISP-backed sensors, UVC webcams): libcamera:[ID] opens the
 * camera with that id, or the first one when ID is empty. Behind the C
 * interface of source.h (cdspd_src_libcamera_init); nothing else in cdspd
 * is C++.
 *
 * Open: one stream at the calibration's size in libcamera.format: R8, R10,
 * R12 (monochrome sensors; 10/12 bit in 16-bit words), YUYV, NV12 or
 * YUV420 (the luma plane is the frame); "auto" takes the first of these the
 * camera's configuration accepts unchanged. Buffers come from libcamera's
 * FrameBufferAllocator and are mapped once.
 *
 * Threads: libcamera completes requests on its own thread; the handler only
 * queues the request under a mutex and signals the capture thread, which
 * copies the frame, requeues the request and returns. The camera's
 * "disconnected" signal sets a flag: the next grab reports the camera lost
 * and the pipeline reopens it with back-off.
 */
#include <libcamera/libcamera.h>

#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

extern "C" {
#include "log.h"
#include "source.h"
}

using namespace libcamera;

namespace {

struct Mapped {
    const uint8_t *data = nullptr;
    size_t length = 0;
    void *base = MAP_FAILED;
    size_t map_length = 0;
};

struct LibcameraSource {
    std::unique_ptr<CameraManager> manager;
    std::shared_ptr<Camera> camera;
    std::unique_ptr<CameraConfiguration> config;
    std::unique_ptr<FrameBufferAllocator> allocator;
    std::vector<std::unique_ptr<Request>> requests;
    std::vector<Mapped> maps; /* per buffer, the luma plane */
    Stream *stream = nullptr;
    PixelFormat format;
    unsigned width = 0, height = 0, stride = 0;
    int bits = 8, bpp = 1;
    bool acquired = false, started = false;

    std::mutex mu;
    std::condition_variable cv;
    std::deque<Request *> done;
    bool lost = false;

    void onComplete(Request *r)
    {
        if (r->status() == Request::RequestCancelled)
            return;
        std::lock_guard<std::mutex> lock(mu);
        done.push_back(r);
        cv.notify_one();
    }

    void onDisconnected()
    {
        std::lock_guard<std::mutex> lock(mu);
        lost = true;
        cv.notify_one();
    }

    void close()
    {
        if (camera) {
            if (started)
                camera->stop();
            started = false;
            camera->requestCompleted.disconnect(this);
            camera->disconnected.disconnect(this);
        }
        for (Mapped &m : maps)
            if (m.base != MAP_FAILED)
                munmap(m.base, m.map_length);
        maps.clear();
        requests.clear();
        allocator.reset();
        config.reset();
        if (camera && acquired)
            camera->release();
        acquired = false;
        camera.reset();
        if (manager)
            manager->stop();
        manager.reset();
        std::lock_guard<std::mutex> lock(mu);
        done.clear();
        lost = false;
    }
};

struct Candidate {
    const char *name;
    PixelFormat format;
    int bits, bpp;
};

const Candidate candidates[] = {
    {"R8", formats::R8, 8, 1},        {"R12", formats::R12, 12, 2}, {"R10", formats::R10, 10, 2},
    {"YUYV", formats::YUYV, 8, 2},    {"NV12", formats::NV12, 8, 1}, {"YUV420", formats::YUV420, 8, 1},
};

int fail(LibcameraSource *p, char *err, size_t errlen, int rc, const std::string &msg)
{
    std::snprintf(err, errlen, "libcamera: %s", msg.c_str());
    p->close();
    return rc;
}

int lc_open(cdspd_source *s, char *err, size_t errlen)
{
    LibcameraSource *p = static_cast<LibcameraSource *>(s->priv);
    const cdspd_config *c = s->cfg;
    std::string id = s->arg ? s->arg : "";

    /* libcamera logs INFO and WARN lines of its own on stderr: keep its
     * errors only, unless the source is debugged or LIBCAMERA_LOG_LEVELS
     * says otherwise */
    if (!std::getenv("LIBCAMERA_LOG_LEVELS") && !cdspd_log_enabled(CDSPD_LOGC_SOURCE, CDSPD_LOG_DEBUG))
        setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0); /* read when libcamera's logger starts */
    p->manager = std::make_unique<CameraManager>();
    if (p->manager->start())
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "the camera manager did not start");
    if (p->manager->cameras().empty())
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "no camera found");
    p->camera = id.empty() ? p->manager->cameras()[0] : p->manager->get(id);
    if (!p->camera) {
        std::string names;
        for (const auto &cam : p->manager->cameras())
            names += " " + cam->id();
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "no camera '" + id + "' (found:" + names + ")");
    }
    if (p->camera->acquire())
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "camera '" + p->camera->id() + "' is in use");
    p->acquired = true;

    /* the format: the one asked for, or the first the camera takes as is */
    bool found = false;
    for (const Candidate &cand : candidates) {
        if (std::strcmp(c->libcamera.format, "auto") && std::strcmp(c->libcamera.format, cand.name))
            continue;
        p->config = p->camera->generateConfiguration({StreamRole::Raw});
        if (!p->config || p->config->empty())
            p->config = p->camera->generateConfiguration({StreamRole::Viewfinder});
        if (!p->config || p->config->empty())
            return fail(p, err, errlen, CDSPD_OPEN_FATAL, "the camera offers no stream configuration");
        StreamConfiguration &sc = p->config->at(0);
        sc.pixelFormat = cand.format;
        sc.size = Size(static_cast<unsigned>(c->cam.width), static_cast<unsigned>(c->cam.height));
        sc.bufferCount = static_cast<unsigned>(c->libcamera.buffers);
        if (p->config->validate() == CameraConfiguration::Invalid)
            continue;
        if (sc.pixelFormat != cand.format ||
            sc.size != Size(static_cast<unsigned>(c->cam.width), static_cast<unsigned>(c->cam.height)))
            continue;
        p->format = cand.format;
        p->bits = cand.bits;
        p->bpp = cand.bpp;
        found = true;
        break;
    }
    if (!found)
        return fail(p, err, errlen, CDSPD_OPEN_FATAL,
                    "camera '" + p->camera->id() + "' takes none of the formats asked (" +
                        c->libcamera.format + ") at " + std::to_string(c->cam.width) + "x" +
                        std::to_string(c->cam.height) + ", the calibration's size");
    if (p->camera->configure(p->config.get()))
        return fail(p, err, errlen, CDSPD_OPEN_FATAL, "configuring the camera failed");
    StreamConfiguration &sc = p->config->at(0);
    p->stream = sc.stream();
    p->width = sc.size.width;
    p->height = sc.size.height;
    p->stride = sc.stride ? sc.stride : p->width * static_cast<unsigned>(p->bpp);

    p->allocator = std::make_unique<FrameBufferAllocator>(p->camera);
    if (p->allocator->allocate(p->stream) < 0)
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "cannot allocate frame buffers");
    for (const std::unique_ptr<FrameBuffer> &fb : p->allocator->buffers(p->stream)) {
        const FrameBuffer::Plane &plane = fb->planes()[0];
        Mapped m;
        size_t off = plane.offset == FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
        m.map_length = off + plane.length;
        m.base = mmap(nullptr, m.map_length, PROT_READ, MAP_SHARED, plane.fd.get(), 0);
        if (m.base == MAP_FAILED)
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "cannot map a frame buffer");
        m.data = static_cast<const uint8_t *>(m.base) + off;
        m.length = plane.length;
        std::unique_ptr<Request> r = p->camera->createRequest(p->maps.size());
        if (!r || r->addBuffer(p->stream, fb.get()))
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "cannot create a request");
        p->maps.push_back(m);
        p->requests.push_back(std::move(r));
    }
    p->camera->requestCompleted.connect(p, &LibcameraSource::onComplete);
    p->camera->disconnected.connect(p, &LibcameraSource::onDisconnected);
    if (p->camera->start())
        return fail(p, err, errlen, CDSPD_OPEN_RETRY, "starting the camera failed");
    p->started = true;
    for (std::unique_ptr<Request> &r : p->requests)
        if (p->camera->queueRequest(r.get()))
            return fail(p, err, errlen, CDSPD_OPEN_RETRY, "queueing a request failed");
    LOG_I(SOURCE, "libcamera: %s: %ux%u %s, stride %u, %zu buffers", p->camera->id().c_str(), p->width,
          p->height, p->format.toString().c_str(), p->stride, p->requests.size());
    return CDSPD_OPEN_OK;
}

int lc_grab(cdspd_source *s, cdspd_frame *f, int timeout_ms, char *err, size_t errlen)
{
    LibcameraSource *p = static_cast<LibcameraSource *>(s->priv);
    Request *r = nullptr;
    {
        std::unique_lock<std::mutex> lock(p->mu);
        p->cv.wait_for(lock, std::chrono::milliseconds(timeout_ms), [p] { return p->lost || !p->done.empty(); });
        if (p->lost) {
            std::snprintf(err, errlen, "libcamera: the camera was disconnected");
            return CDSPD_GRAB_LOST;
        }
        if (p->done.empty())
            return CDSPD_GRAB_TIMEOUT;
        r = p->done.front();
        p->done.pop_front();
    }
    int rc = CDSPD_GRAB_FRAME;
    FrameBuffer *fb = r->buffers().begin()->second;
    const FrameMetadata &md = fb->metadata();
    const Mapped &m = p->maps[r->cookie()];
    size_t row = static_cast<size_t>(p->width) * (p->bits > 8 ? 2 : 1);
    if (r->status() != Request::RequestComplete || md.status != FrameMetadata::FrameSuccess) {
        std::snprintf(err, errlen, "libcamera: frame %u failed", md.sequence);
        rc = CDSPD_GRAB_BAD;
    } else if (static_cast<size_t>(p->stride) * (p->height - 1) + row * (p->format == formats::YUYV ? 2 : 1) >
                   m.length ||
               row * p->height > f->cap) {
        std::snprintf(err, errlen, "libcamera: frame %u is smaller than its format says", md.sequence);
        rc = CDSPD_GRAB_BAD;
    } else {
        for (unsigned y = 0; y < p->height; y++) {
            const uint8_t *in = m.data + static_cast<size_t>(y) * p->stride;
            uint8_t *out = f->data + y * row;
            if (p->format == formats::YUYV) {
                for (unsigned x = 0; x < p->width; x++)
                    out[x] = in[2 * x];
            } else {
                std::memcpy(out, in, row); /* R8, the luma plane, or 16-bit LE words */
            }
        }
        f->width = static_cast<int>(p->width);
        f->height = static_cast<int>(p->height);
        f->bits = p->bits;
        f->stride = row;
        f->frame_id = md.sequence;
        f->t_camera_us = md.timestamp / 1000u;
    }
    r->reuse(Request::ReuseBuffers);
    if (p->camera->queueRequest(r)) {
        std::snprintf(err, errlen, "libcamera: requeueing a request failed");
        return CDSPD_GRAB_LOST;
    }
    return rc;
}

void lc_close(cdspd_source *s)
{
    static_cast<LibcameraSource *>(s->priv)->close();
}

void lc_destroy(cdspd_source *s)
{
    LibcameraSource *p = static_cast<LibcameraSource *>(s->priv);
    if (!p)
        return;
    p->close();
    delete p;
    s->priv = nullptr;
}

const cdspd_source_ops lc_ops = {"libcamera", lc_open, lc_grab, lc_close, lc_destroy};

} // namespace

extern "C" int cdspd_src_libcamera_init(cdspd_source *s, char *err, size_t errlen)
{
    try {
        s->priv = new LibcameraSource();
    } catch (...) {
        std::snprintf(err, errlen, "libcamera: out of memory");
        return -1;
    }
    s->ops = &lc_ops;
    return 0;
}

extern "C" int cdspd_src_libcamera_list(FILE *out, char *err, size_t errlen)
{
    if (!std::getenv("LIBCAMERA_LOG_LEVELS"))
        setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0); /* as at open: errors only */
    CameraManager cm;
    if (cm.start()) {
        snprintf(err, errlen, "libcamera: the camera manager did not start");
        return -1;
    }
    int n = 0;
    for (const auto &cam : cm.cameras()) {
        fprintf(out, "libcamera:%-29s a libcamera camera\n", cam->id().c_str());
        n++;
    }
    cm.stop();
    return n;
}
