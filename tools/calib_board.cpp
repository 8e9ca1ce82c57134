// calib_board.cpp: cdsp_calib --print-board. The board cdsp_calib expects
// (the --board inner corners, so one more square along each side, with the
// white border findChessboardCornersSB needs), drawn with cairo in
// millimetres on a page of real size: a PDF or SVG page is in points
// (1/72 inch), so a square of s mm is s x 72 / 25.4 pt and prints at
// exactly s mm when printed at 100 %. A 100 mm scale bar and the board's
// description below it let the user check the print with a ruler before
// calibrating (a "fit to page" print shrinks everything by a few %, which
// would scale every distance cdsp measures).
#include "calib_board.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <strings.h>

namespace calib {

namespace {

constexpr double pt_per_mm = 72.0 / 25.4;
// White around the squares: half a square (the quiet zone the detector
// needs around the outer corners; the test boards have a whole one), but
// at least the 10 mm most printers cannot print anyway.
constexpr double margin_mm = 10.0;
constexpr double caption_mm = 12.0;  // scale bar and text under the board

bool ends_with(const std::string &s, const char *suffix)
{
    size_t n = std::char_traits<char>::length(suffix);
    return s.size() >= n && strcasecmp(s.c_str() + s.size() - n, suffix) == 0;
}

struct Layout {
    double page_w, page_h;   // mm
    double board_w, board_h; // mm, squares only
    double x0, y0;           // mm, top-left of the first square
};

} // namespace

bool parse_paper(const std::string &name, Paper &paper)
{
    if (name == "a4")
        paper = Paper::a4;
    else if (name == "letter")
        paper = Paper::letter;
    else if (name == "a3")
        paper = Paper::a3;
    else if (name == "fit")
        paper = Paper::fit;
    else
        return false;
    return true;
}

bool write_board(const std::string &path, cv::Size board, double square_mm, Paper paper,
                 std::string &problem)
{
    Layout L;
    const int nx = board.width + 1, ny = board.height + 1; // squares
    L.board_w = nx * square_mm;
    L.board_h = ny * square_mm;
    // what the page must hold: the squares, a one-square white border,
    // the margins, the caption
    const double border = std::max(margin_mm, 0.5 * square_mm);
    double need_w = L.board_w + 2 * border;
    double need_h = L.board_h + 2 * border + caption_mm;
    need_w = std::max(need_w, 100.0 + 2 * margin_mm); // room for the scale bar
    if (paper == Paper::fit) {
        L.page_w = need_w;
        L.page_h = need_h;
    } else {
        double a = paper == Paper::a4 ? 210.0 : paper == Paper::letter ? 215.9 : 297.0;
        double b = paper == Paper::a4 ? 297.0 : paper == Paper::letter ? 279.4 : 420.0;
        if (need_w <= a && need_h <= b) {
            L.page_w = a;
            L.page_h = b;
        } else if (need_w <= b && need_h <= a) {
            L.page_w = b;
            L.page_h = a;
        } else {
            char msg[200];
            std::snprintf(msg, sizeof msg,
                          "the board needs %.0f x %.0f mm with its border and margins, "
                          "more than the paper (use smaller --square, a larger --paper or "
                          "--paper fit)", need_w, need_h);
            problem = msg;
            return false;
        }
    }
    // centred across, from the top margin down
    L.x0 = 0.5 * (L.page_w - L.board_w);
    L.y0 = border + 0.5 * (L.page_h - need_h);

    cairo_surface_t *surf;
    double scale; // device units per mm
    bool png = false;
    if (ends_with(path, ".pdf")) {
        scale = pt_per_mm;
        surf = cairo_pdf_surface_create(path.c_str(), L.page_w * scale, L.page_h * scale);
    } else if (ends_with(path, ".svg")) {
        scale = pt_per_mm;
        surf = cairo_svg_surface_create(path.c_str(), L.page_w * scale, L.page_h * scale);
        cairo_svg_surface_restrict_to_version(surf, CAIRO_SVG_VERSION_1_1);
    } else if (ends_with(path, ".png")) {
        png = true;
        scale = board_png_dpi / 25.4;
        surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, (int)std::lround(L.page_w * scale),
                                          (int)std::lround(L.page_h * scale));
    } else {
        problem = "unknown format: name the file .pdf, .svg or .png";
        return false;
    }
    if (cairo_surface_status(surf) != CAIRO_STATUS_SUCCESS) {
        problem = cairo_status_to_string(cairo_surface_status(surf));
        cairo_surface_destroy(surf);
        return false;
    }
    cairo_t *cr = cairo_create(surf);
    cairo_scale(cr, scale, scale); // from here on, millimetres
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    // squares: black where (i + j) is even, the corner square black
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_antialias(cr, png ? CAIRO_ANTIALIAS_NONE : CAIRO_ANTIALIAS_DEFAULT);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++)
            if ((i + j) % 2 == 0)
                cairo_rectangle(cr, L.x0 + i * square_mm, L.y0 + j * square_mm, square_mm,
                                square_mm);
    cairo_fill(cr);
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);

    // caption: a 100 mm bar with 10 mm ticks, then the description
    double cy = L.y0 + L.board_h + border + 3.0, bx = 0.5 * (L.page_w - 100.0);
    cairo_set_line_width(cr, 0.3);
    cairo_move_to(cr, bx, cy);
    cairo_line_to(cr, bx + 100.0, cy);
    for (int t = 0; t <= 10; t++) {
        cairo_move_to(cr, bx + 10.0 * t, cy - (t % 5 ? 1.5 : 3.0));
        cairo_line_to(cr, bx + 10.0 * t, cy);
    }
    cairo_stroke(cr);
    char text[256];
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 3.2);
    std::snprintf(text, sizeof text,
                  "cdsp_calib --board %dx%d --square %g: %d x %d squares of %g mm. "
                  "Print at 100 %% (actual size); the bar must measure 100 mm.",
                  board.width, board.height, square_mm, nx, ny, square_mm);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text, &ext);
    double size = 3.2 * std::min(1.0, (L.page_w - 2 * margin_mm) / ext.width);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, text, &ext);
    cairo_move_to(cr, 0.5 * (L.page_w - ext.width), cy + 5.0);
    cairo_show_text(cr, text);
    cairo_show_page(cr);
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    if (st == CAIRO_STATUS_SUCCESS && png)
        st = cairo_surface_write_to_png(surf, path.c_str());
    cairo_surface_finish(surf);
    if (st == CAIRO_STATUS_SUCCESS)
        st = cairo_surface_status(surf);
    cairo_surface_destroy(surf);
    if (st != CAIRO_STATUS_SUCCESS) {
        problem = std::string("cannot write: ") + cairo_status_to_string(st);
        return false;
    }
    return true;
}

} // namespace calib
