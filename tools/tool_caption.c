/*
 * tool_caption.c - what the overlay picture says in words, drawn with
 * cairo over the RGB picture tool_overlay.c made: the region of interest
 * searched (a dashed cyan rectangle) and a caption band across the top
 * (status, distance +- sigma, or why the frame failed). Sizes follow the
 * frame like the overlay's marks: text 16 px high per 1000 px of the
 * frame's larger side (at least 14 px, less only when a line would not fit
 * a small frame's width), so a 5 MP frame viewed whole still has readable
 * text and lines.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <cairo.h>
#include <fontconfig/fontconfig.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The caption band's colour, opaque so that the text reads on any frame. */
#define BAND_GRAY 32

void tool_cairo_done(void)
{
    /* cairo keeps its font faces, and through them fontconfig's patterns,
     * until told to let go: released here so that a leak checker sees
     * only real leaks; then fontconfig's own configuration */
    cairo_debug_reset_static_data();
    FcFini();
}

double tool_overlay_scale(int width, int height)
{
    int m = width > height ? width : height;
    return m > 1000 ? m / 1000.0 : 1.0;
}

int tool_overlay_annotate(uint8_t *rgb, int w, int h, const cdsp_roi *roi,
                          const char *const *lines, int nlines, const tool_tag *tags, int ntags)
{
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
    unsigned char *px;
    int stride, x, y, i;
    cairo_t *cr;
    double s = tool_overlay_scale(w, h), font = fmax(14.0, 16.0 * s), pad = 0.4 * font;
    if (cairo_surface_status(surf) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(surf);
        return -1;
    }
    /* RGB bytes <-> cairo's native-endian 0x00RRGGBB words */
    cairo_surface_flush(surf);
    px = cairo_image_surface_get_data(surf);
    stride = cairo_image_surface_get_stride(surf);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            const uint8_t *p = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
            ((uint32_t *)(void *)(px + (size_t)y * (size_t)stride))[x] =
                ((uint32_t)p[0] << 16) | ((uint32_t)p[1] << 8) | p[2];
        }
    cairo_surface_mark_dirty(surf);
    cr = cairo_create(surf);
    if (roi && roi->w > 0 && roi->h > 0) {
        double dash[2];
        dash[0] = 6 * s;
        dash[1] = 4 * s;
        cairo_set_source_rgb(cr, 0, 1, 1);
        cairo_set_line_width(cr, 1.5 * s);
        cairo_set_dash(cr, dash, 2, 0);
        /* pixel centres are integers: the ROI's outer edge is half a pixel out */
        cairo_rectangle(cr, roi->x, roi->y, roi->w, roi->h);
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
    }
    if (ntags > 0) {
        /* white on a dark box, readable on any part of the frame */
        cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
        cairo_set_font_size(cr, font);
        for (i = 0; i < ntags; i++) {
            cairo_text_extents_t e;
            cairo_text_extents(cr, tags[i].text, &e);
            cairo_set_source_rgb(cr, BAND_GRAY / 255.0, BAND_GRAY / 255.0, BAND_GRAY / 255.0);
            cairo_rectangle(cr, tags[i].x - pad / 2, tags[i].y - font - pad / 2, e.x_advance + pad,
                            font * 1.3 + pad / 2);
            cairo_fill(cr);
            cairo_set_source_rgb(cr, 1, 1, 1);
            cairo_move_to(cr, tags[i].x, tags[i].y);
            cairo_show_text(cr, tags[i].text);
        }
    }
    if (nlines > 0) {
        double widest = 0;
        cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
        cairo_set_font_size(cr, font);
        /* a small frame: the text shrinks until the longest line fits
         * (down to 8 px, then it is cut at the frame's edge) */
        for (i = 0; i < nlines; i++) {
            cairo_text_extents_t e;
            cairo_text_extents(cr, lines[i], &e);
            widest = fmax(widest, e.x_advance);
        }
        if (widest > w - 2 * pad) {
            font = fmax(8.0, font * (w - 2 * pad) / widest);
            pad = 0.4 * font;
            cairo_set_font_size(cr, font);
        }
        cairo_set_source_rgb(cr, BAND_GRAY / 255.0, BAND_GRAY / 255.0, BAND_GRAY / 255.0);
        cairo_rectangle(cr, 0, 0, w, nlines * 1.3 * font + 2 * pad);
        cairo_fill(cr);
        cairo_set_source_rgb(cr, 1, 1, 1);
        for (i = 0; i < nlines; i++) {
            cairo_move_to(cr, pad, pad + (i + 1) * 1.3 * font - 0.3 * font);
            cairo_show_text(cr, lines[i]);
        }
    }
    cairo_destroy(cr);
    cairo_surface_flush(surf);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            uint8_t *p = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
            uint32_t v = ((const uint32_t *)(const void *)(px + (size_t)y * (size_t)stride))[x];
            p[0] = (uint8_t)(v >> 16);
            p[1] = (uint8_t)(v >> 8);
            p[2] = (uint8_t)v;
        }
    cairo_surface_destroy(surf);
    return 0;
}
