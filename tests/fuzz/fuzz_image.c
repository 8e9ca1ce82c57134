/*
 * fuzz_image.c - the frame readers (host/image.c): PGM by hand,
 * PNG through libspng, and the dispatcher that picks one by magic. A frame
 * that decodes must be one the library accepts (cdsp_image_check), and is
 * then scanned for edges, so what a reader lets through reaches libcdsp.
 * FUZZ_FORMAT selects the reader: 1 PGM, 2 PNG (two binaries, two corpora).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "cdsp_host.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static cdsp_edge edges[4096];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    cdsp_host_image im;
    cdsp_host_err err;
    int rc;
#if FUZZ_FORMAT == 1
    rc = cdsp_host_pgm_decode(data, size, "fuzz.pgm", &im, &err);
#else
    rc = cdsp_host_png_decode(data, size, "fuzz.png", &im, &err);
#endif
    if (rc == CDSP_HOST_OK) {
        cdsp_image v = cdsp_host_image_view(&im);
        cdsp_edge_params ep;
        size_t n;
        if (cdsp_image_check(&v) != CDSP_OK)
            abort(); /* a reader handed on a frame the library refuses */
        cdsp_edge_params_default(&ep);
        if (im.width <= 512 && im.height <= 512)
            (void)cdsp_edges_detect(&v, &ep, edges, sizeof edges / sizeof edges[0], &n);
        cdsp_host_image_free(&im);
    } else if (im.data) {
        abort(); /* an error must leave nothing allocated */
    }
    /* the dispatcher on the same bytes */
    rc = cdsp_host_image_decode(data, size, "fuzz", &im, &err);
    if (rc == CDSP_HOST_OK)
        cdsp_host_image_free(&im);
    return 0;
}
