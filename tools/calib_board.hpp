// calib_board.hpp: the printable checkerboard of cdsp_calib --print-board,
// drawn with cairo at exact scale (PDF, SVG, or PNG at 300 dpi).
#ifndef CDSP_CALIB_BOARD_HPP
#define CDSP_CALIB_BOARD_HPP

#include <opencv2/core.hpp>

#include <string>

namespace calib {

enum class Paper { a4, letter, a3, fit };

// "a4", "letter", "a3", "fit"; false for anything else.
bool parse_paper(const std::string &name, Paper &paper);

// Resolution of a PNG board, dots per inch (a PDF or SVG is vector).
constexpr double board_png_dpi = 300.0;

// Writes the board of board.width x board.height inner corners (one more
// square along each side), squares of square_mm millimetres, a white
// border of one square, on a page of the given paper (portrait or
// landscape, whichever fits) with its description and a scale bar under
// it. The format follows the file name: .pdf, .svg or .png. false and
// problem when the board does not fit the paper or the file cannot be
// written.
bool write_board(const std::string &path, cv::Size board, double square_mm, Paper paper,
                 std::string &problem);

} // namespace calib

#endif
