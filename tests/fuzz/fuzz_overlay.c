/*
 * fuzz_overlay.c - `cdsp_tool overlay`'s drawing (tools/tool_overlay.c)
 * fed edge points, contour lines and an axis segment anywhere (NaN, Inf,
 * far beyond the frame: a projection more than 2^31 px away was converted
 * to int, issue 16), over a small frame, with a ROI and caption lines, written as a PNG to a memory file.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "tool_internal.h"
#include "fuzz_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int fd = -1;
static char path[64];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    static uint8_t px[32 * 24];
    static cdsp_edge edges[64];
    static uint8_t label[64];
    cdsp_host_image img;
    cdsp_camera cam = {40, 40, 16, 12, 0, 0, 0, 0, 0, 32, 24};
    cdsp_result r;
    cdsp_host_err err;
    cdsp_roi roi;
    static const char *const caption[2] = {"frame 1  distance 123.4 mm", "conf 0.93 \xc3\xa9"};
    size_t n, i;
    int k, with_result, ncaption;
    if (fd < 0) {
        fd = memfd_create("cdsp-fuzz-overlay", 0);
        if (fd < 0)
            abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    if (ftruncate(fd, 0))
        abort();
    cam.k1 = (cdsp_real)fz_real(&in, -0.5, 0.5);
    n = (size_t)fz_range(&in, 0, 64);
    for (i = 0; i < n; i++) {
        edges[i].x = (cdsp_real)fz_real(&in, -10, 40);
        edges[i].y = (cdsp_real)fz_real(&in, -10, 30);
        label[i] = (uint8_t)fz_range(&in, 0, 2);
    }
    with_result = fz_u8(&in) & 1;
    memset(&r, 0, sizeof r);
    for (k = 0; k < 3; k++) {
        r.lines[0][k] = (cdsp_real)fz_real(&in, -1, 1);
        r.lines[1][k] = (cdsp_real)fz_real(&in, -1, 1);
        r.segment[0][k] = (cdsp_real)fz_real(&in, -1e3, 1e3);
        r.segment[1][k] = (cdsp_real)fz_real(&in, -1e3, 1e3);
        r.point[k] = (cdsp_real)fz_real(&in, -1e3, 1e3);
    }
    memcpy(px, in.p, in.n < sizeof px ? in.n : sizeof px);
    img.data = px;
    img.width = 32;
    img.height = 24;
    img.bits = 8;
    img.stride = 32;
    roi.x = (int)fz_range(&in, -40, 40);
    roi.y = (int)fz_range(&in, -40, 40);
    roi.w = (int)fz_range(&in, -1, 60);
    roi.h = (int)fz_range(&in, -1, 60);
    ncaption = (int)fz_range(&in, 0, 2);
    (void)tool_overlay_write(path, &img, &cam, edges, label, n, with_result ? &r : NULL, 1,
                             &roi, caption, ncaption, &err);
    /* cairo's and fontconfig's caches live until this (as at the end of
     * `cdsp_tool overlay`): what is left after it is ours, and leaks */
    tool_cairo_done();
    return 0;
}
