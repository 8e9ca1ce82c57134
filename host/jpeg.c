/*
 * jpeg.c - JPEG frames through libjpeg-turbo (Debian's libjpeg62-turbo, the
 * libjpeg 6b API). Baseline and progressive, gray or colour (libjpeg turns
 * YCbCr into gray by keeping Y, which is Rec. 601 luma, as the PNG reader
 * computes it). libjpeg reports errors by calling error_exit, which must not
 * return: ours longjmps back here with the message, so a corrupt file is an
 * error naming it, never an exit. Its warnings (a truncated file, corrupt
 * entropy data it papered over with gray) are errors too: a frame with made
 * up pixels would give a made up pose.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_internal.h"

#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include <jpeglib.h>

#define fail(err, rc, name, ...) cdsp_host__fail(err, rc, (name) ? (name) : "(image)", __VA_ARGS__)

/* Pixels a JPEG of `len` bytes can decode to at most. The leanest baseline
 * encoding of an 8 x 8 block is a 2-bit DC difference code and a 2-bit
 * end-of-block code: 4 bits for 64 pixels, 128 pixels per byte; progressive
 * scans with end-of-band runs halve that again. 1024 per byte leaves a
 * factor of 4 above the densest real file and still stops a 100-byte header
 * that claims 16384 x 16384 before the 256 MiB raster is allocated. */
#define JPEG_MAX_PIXELS_PER_BYTE 1024u

typedef struct {
    struct jpeg_error_mgr pub;
    jmp_buf jump;
    int warned;
    char msg[JMSG_LENGTH_MAX];
} jerr;

static void on_error(j_common_ptr cinfo)
{
    jerr *e = (jerr *)(void *)cinfo->err;
    (*cinfo->err->format_message)(cinfo, e->msg);
    longjmp(e->jump, 1);
}

/* level -1: a warning (corrupt data); 0.. trace messages, ignored. The
 * first warning is kept and decoding goes on to its end; the caller then
 * refuses the frame. */
static void on_message(j_common_ptr cinfo, int level)
{
    jerr *e = (jerr *)(void *)cinfo->err;
    if (level >= 0 || e->warned)
        return;
    e->warned = 1;
    (*cinfo->err->format_message)(cinfo, e->msg);
}

int cdsp_host_jpeg_decode(const void *buf, size_t len, const char *name, cdsp_host_image *out,
                          cdsp_host_err *err)
{
    struct jpeg_decompress_struct cinfo;
    jerr je;
    /* volatile: changed between setjmp and a longjmp back to it */
    volatile int rc = CDSP_HOST_OK;
    out->data = NULL;
    if (len == 0)
        return fail(err, CDSP_HOST_E_FORMAT, name, "empty file");
    if (len > (unsigned long)-1)
        return fail(err, CDSP_HOST_E_LIMIT, name, "JPEG file too large");
    memset(&je, 0, sizeof je);
    cinfo.err = jpeg_std_error(&je.pub);
    je.pub.error_exit = on_error;
    je.pub.emit_message = on_message;
    if (setjmp(je.jump)) {
        cdsp_host_image_free(out);
        jpeg_destroy_decompress(&cinfo);
        return fail(err, rc ? rc : CDSP_HOST_E_FORMAT, name, "JPEG: %s", je.msg);
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, (const unsigned char *)buf, (unsigned long)len);
    jpeg_read_header(&cinfo, TRUE);
    if (cinfo.image_width < 1 || cinfo.image_height < 1 ||
        cinfo.image_width > CDSP_HOST_MAX_DIM || cinfo.image_height > CDSP_HOST_MAX_DIM) {
        rc = fail(err, CDSP_HOST_E_LIMIT, name, "JPEG size %ux%u outside 1..%d",
                  (unsigned)cinfo.image_width, (unsigned)cinfo.image_height, CDSP_HOST_MAX_DIM);
        goto done;
    }
    if ((double)cinfo.image_width * cinfo.image_height > (double)JPEG_MAX_PIXELS_PER_BYTE * len) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name,
                  "JPEG claims %ux%u pixels, more than its %zu bytes can hold",
                  (unsigned)cinfo.image_width, (unsigned)cinfo.image_height, len);
        goto done;
    }
    if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
        rc = fail(err, CDSP_HOST_E_FORMAT, name,
                  "a CMYK JPEG, not a camera frame (convert it to gray or RGB)");
        goto done;
    }
    cinfo.out_color_space = JCS_GRAYSCALE;
    jpeg_start_decompress(&cinfo);
    rc = cdsp_host_image_alloc(out, (int)cinfo.output_width, (int)cinfo.output_height, 8, NULL);
    if (rc) {
        rc = fail(err, rc, name, "out of memory for %ux%u pixels", (unsigned)cinfo.output_width,
                  (unsigned)cinfo.output_height);
        goto done;
    }
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = (unsigned char *)out->data + (size_t)cinfo.output_scanline * out->stride;
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    if (je.warned) {
        cdsp_host_image_free(out);
        rc = fail(err, CDSP_HOST_E_FORMAT, name, "corrupt JPEG: %s", je.msg);
    }
done:
    jpeg_destroy_decompress(&cinfo);
    return rc;
}
