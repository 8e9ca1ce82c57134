// cdsp_calib: checkerboard calibration for cdsp. Finds the board's inner
// corners in every image, calibrates K and k1, k2 (or the full plumb_bob
// model) with Zhang's method refined by Levenberg-Marquardt, drops the
// outlier views, calibrates again, and writes the ROS camera_info YAML that
// cdsp_tool and cdspd read. The pipeline is in calib_core.cpp, the files it
// writes in calib_output.cpp; this file is the command line and the report.
#include "calib_board.hpp"
#include "calib_core.hpp"
#include "calib_output.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include <getopt.h>
#include <glob.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

using calib::View;
using calib::ViewState;

const char *const prog = "cdsp_calib";

enum Exit {
    exit_ok = 0,     // calibration written
    exit_calib = 1,  // calibration impossible: too few usable views, or it failed
    exit_usage = 2,  // usage error, an unreadable input, or an unwritable output
};

// Progress is shown on stderr only when stderr is a terminal and the run
// is long enough to wonder about.
constexpr size_t progress_min_images = 8;

// Warnings after the report (see --help, OUTPUT).
constexpr double warn_rms_px = 1.0;          // corners or model suspicious above this
constexpr double warn_focal_rel_sigma = 5e-3; // fx, fy 1-sigma relative to fx, fy
constexpr double warn_reach = 0.7;           // corners' reach toward the image corners

// ---------------------------------------------------------------------------
// The command line, one table: getopt's options and --help come from it.
// ---------------------------------------------------------------------------
enum OptKey {
    opt_board = 'b',
    opt_square = 's',
    opt_output = 'o',
    opt_help = 'h',
    opt_full_model = 256,
    opt_overlay,
    opt_coverage,
    opt_camera_name,
    opt_no_reject,
    opt_outlier_floor,
    opt_print_board,
    opt_paper,
};

struct OptSpec {
    const char *name;
    int key;
    const char *arg;   // nullptr: a flag
    const char *help;  // wrapped at 64 columns, indented by --help
};

const OptSpec opt_table[] = {
    {"board", opt_board, "COLSxROWS",
     "Inner corners of the board along its two sides, e.g. 9x6 for\n"
     "a board of 10 x 7 squares (inner corners = squares - 1).\n"
     "Each at least 3. Required."},
    {"square", opt_square, "SIZE",
     "Side of one square, in any unit (mm in the examples). K and\n"
     "the distortion do not depend on it; the board distances in\n"
     "the report are in this unit. Required."},
    {"full-model", opt_full_model, nullptr,
     "Estimate the full plumb_bob model k1, k2, p1, p2, k3. Default:\n"
     "k1, k2 only with p1 = p2 = k3 = 0, the paper's model."},
    {"output", opt_output, "FILE",
     "Write the camera_info YAML to FILE (replaced only when the\n"
     "calibration succeeds). Default, or FILE '-': standard output."},
    {"overlay", opt_overlay, "DIR",
     "Write every image with a board to DIR/NAME.png (NAME: the\n"
     "image's file name without its extension, then -N, N its place\n"
     "on the command line, if an earlier image had that name):\n"
     "detected corners in green, corners reprojected by the\n"
     "calibration in red. DIR is created if missing."},
    {"coverage", opt_coverage, "FILE",
     "Write a picture of where the corners fell in the image (a\n"
     "PNG, or any format OpenCV writes by FILE's extension)."},
    {"camera-name", opt_camera_name, "NAME",
     "camera_name written in the YAML (letters, digits and '_',\n"
     "not starting with a digit). Default: camera."},
    {"no-reject", opt_no_reject, nullptr,
     "Keep every view with a board: no outlier rejection."},
    {"outlier-floor", opt_outlier_floor, "PX",
     "A view whose RMS reprojection error is at most PX is never\n"
     "an outlier, however uniform the others are. Default: 0.1, the\n"
     "RMS a good calibration reaches as a whole (corner noise of\n"
     "0.07 px per coordinate); 0 leaves only the relative rule."},
    {"print-board", opt_print_board, "FILE",
     "Do not calibrate: write the board that --board and --square\n"
     "describe, to print, to FILE (.pdf or .svg, by the name; .png\n"
     "at 300 dpi for a screen or a test). --square is then in mm:\n"
     "the squares come out exactly that size when printed at 100 %\n"
     "(\"actual size\", no fit-to-page); a 100 mm scale bar and the\n"
     "board's description are printed under it to check. The board\n"
     "has one more square than inner corners along each side and a\n"
     "white border of half a square (at least 10 mm)."},
    {"paper", opt_paper, "a4|letter|a3|fit",
     "Page size for --print-board (portrait or landscape, whichever\n"
     "the board fits; fit: the board and its margins only). A board\n"
     "that does not fit the page is refused. Default: a4."},
    {"help", opt_help, nullptr, "Print this help and exit."},
};

void print_help(std::FILE *f)
{
    std::fprintf(f,
        "NAME\n"
        "    cdsp_calib - calibrate a camera from checkerboard images\n"
        "\n"
        "SYNOPSIS\n"
        "    cdsp_calib --board COLSxROWS --square SIZE [--full-model]\n"
        "               [--overlay DIR] [--coverage FILE.png] [-o OUT.yaml]\n"
        "               [--camera-name NAME] [--no-reject | --outlier-floor PX]\n"
        "               IMAGE_OR_GLOB...\n"
        "    cdsp_calib --board COLSxROWS --square MM --print-board FILE.pdf|svg\n"
        "               [--paper a4|letter|a3|fit]\n"
        "\n"
        "DESCRIPTION\n"
        "    Finds the board's inner corners in each image (OpenCV's\n"
        "    findChessboardCornersSB, then cornerSubPix on a copy blurred by\n"
        "    1.5 px against pixel locking), calibrates the camera (Zhang's\n"
        "    closed form, then Levenberg-Marquardt over the intrinsics, the\n"
        "    distortion and every board pose: OpenCV's calibrateCamera),\n"
        "    drops the views whose RMS reprojection error is an outlier (above\n"
        "    both twice the median and the median plus 3 robust sigmas,\n"
        "    1.4826 x MAD, and above the absolute floor --outlier-floor) and\n"
        "    calibrates again without them (--no-reject: keeps them all).\n"
        "    The board itself can be printed with --print-board.\n"
        "\n"
        "    Images: files or glob patterns (quoted, so that cdsp_calib expands\n"
        "    them itself; a pattern must match at least one file), in any\n"
        "    format OpenCV reads (PGM, PNG, JPEG, TIFF...), 8 or 16 bit, gray\n"
        "    or colour (converted to gray), e.g. frames recorded by\n"
        "    `cdspd --record`. Deeper than 8 bit images are stretched min..max\n"
        "    for the detector; the subpixel refinement uses the full depth.\n"
        "    All images must have one size; an image of another size than\n"
        "    most is skipped with a warning. Images where the whole board is\n"
        "    not found are listed and skipped. The board must be seen whole,\n"
        "    with a white border around it; tilt it 30-45 degrees in some\n"
        "    views and bring it near every edge and corner of the image.\n"
        "\n"
        "OPTIONS\n");
    for (const OptSpec &o : opt_table) {
        char head[64];
        if (o.key < 256)
            std::snprintf(head, sizeof head, "-%c, --%s%s%s", o.key, o.name,
                          o.arg ? " " : "", o.arg ? o.arg : "");
        else
            std::snprintf(head, sizeof head, "--%s%s%s", o.name, o.arg ? " " : "",
                          o.arg ? o.arg : "");
        std::fprintf(f, "    %s\n        ", head);
        for (const char *c = o.help; *c; c++) {
            std::fputc(*c, f);
            if (*c == '\n')
                std::fputs("        ", f);
        }
        std::fputs("\n", f);
    }
    std::fprintf(f,
        "\n"
        "OUTPUT\n"
        "    The calibration, as the ROS camera_info YAML that ROS's\n"
        "    camera_calibration writes: image_width, image_height,\n"
        "    camera_name, camera_matrix (3x3, row-major), distortion_model:\n"
        "    plumb_bob, distortion_coefficients [k1, k2, p1, p2, k3],\n"
        "    rectification_matrix (identity) and projection_matrix (3x4: the\n"
        "    rectified image's camera matrix as ROS computes it,\n"
        "    getOptimalNewCameraMatrix with alpha = 0, then a zero column).\n"
        "    Numbers are written with the digits that read back exactly. Two\n"
        "    comment lines come first: the RMS reprojection error and the\n"
        "    number of images used, then the model and the 1-sigma\n"
        "    uncertainty of each estimated parameter.\n"
        "\n"
        "    The report goes to standard output (to standard error when the\n"
        "    YAML does): one line per image with its corner count, its RMS and\n"
        "    largest reprojection error (px) under the final calibration, the\n"
        "    board centre's distance from the camera (unit of --square), the\n"
        "    board's tilt from fronto-parallel (degrees) and its status (used,\n"
        "    REJECTED, no board, wrong size); then the intrinsics with their\n"
        "    1-sigma uncertainty, the grid cells (about width / 8 wide) that\n"
        "    hold corners and how far toward the image corners they reach.\n"
        "    Warnings follow when the RMS error exceeds %.1f px, fx or fy is\n"
        "    uncertain by more than %.1f%%, or the corners reach less than %.0f%%\n"
        "    of the way to the image corners (distortion there is then\n"
        "    extrapolated). Progress goes to standard error when it is a\n"
        "    terminal and there are %zu images or more.\n"
        "\n"
        "EXIT STATUS\n"
        "    0   the calibration was written.\n"
        "    1   calibration impossible: the board was found in fewer than %d\n"
        "        images (none at all usually means a wrong --board), or the\n"
        "        optimisation failed; nothing is written. The message says how\n"
        "        many views were found and how many are needed.\n"
        "    2   usage error (bad option, no images, a pattern matching\n"
        "        nothing), an input that cannot be read or decoded (every\n"
        "        such file is named; nothing is written), or an output that\n"
        "        cannot be written.\n"
        "\n"
        "EXAMPLES\n"
        "    cdsp_calib --board 9x6 --square 25 -o camera.yaml 'calib/*.png'\n"
        "    cdsp_calib -b 9x6 -s 25 --coverage cov.png --overlay check/ \\\n"
        "               -o camera.yaml rec/frame_*.pgm\n"
        "    cdsp_calib -b 9x6 -s 25 --print-board board.pdf\n",
        warn_rms_px, 100.0 * warn_focal_rel_sigma, 100.0 * warn_reach,
        progress_min_images, calib::min_views);
}

struct Options {
    cv::Size board;
    double square = 0;
    bool full_model = false;
    std::string output = "-";
    std::string overlay;
    std::string coverage;
    std::string camera_name = "camera";
    calib::Rejection rejection;
    bool have_floor = false;
    std::string print_board;
    calib::Paper paper = calib::Paper::a4;
    std::vector<std::string> inputs;
};

bool usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
bool usage_error(const char *fmt, ...)
{
    std::va_list ap;
    va_start(ap, fmt);
    std::fprintf(stderr, "%s: ", prog);
    std::vfprintf(stderr, fmt, ap);
    std::fprintf(stderr, "\nTry '%s --help'.\n", prog);
    va_end(ap);
    return false;
}

bool parse_int(const char *s, const char *end, int &out)
{
    if (s == end || *s < '0' || *s > '9')
        return false;
    long v = 0;
    for (const char *c = s; c < end; c++) {
        if (*c < '0' || *c > '9')
            return false;
        v = v * 10 + (*c - '0');
        if (v > 10000)
            return false;
    }
    out = (int)v;
    return true;
}

bool parse_board(const std::string &s, cv::Size &board)
{
    size_t x = s.find_first_of("xX");
    const char *b = s.c_str();
    if (x == std::string::npos || !parse_int(b, b + x, board.width) ||
        !parse_int(b + x + 1, b + s.size(), board.height))
        return usage_error("--board wants COLSxROWS (inner corners, e.g. 9x6), not '%s'", s.c_str());
    // findChessboardCorners needs at least 3 inner corners along each side.
    if (board.width < 3 || board.height < 3 || board.width > 1000 || board.height > 1000)
        return usage_error("--board %s: each count must be 3..1000 inner corners", s.c_str());
    return true;
}

bool valid_name(const std::string &s)
{
    if (s.empty() || s.size() > 100 || std::isdigit((unsigned char)s[0]))
        return false;
    for (char c : s)
        if (!std::isalnum((unsigned char)c) && c != '_')
            return false;
    return true;
}

// false after printing the problem (exit 2); help set if --help was given.
bool parse_args(int argc, char **argv, Options &o, bool &help)
{
    std::vector<option> longs;
    std::string shorts = ":";
    for (const OptSpec &s : opt_table) {
        longs.push_back({s.name, s.arg ? required_argument : no_argument, nullptr, s.key});
        if (s.key < 256) {
            shorts += (char)s.key;
            if (s.arg)
                shorts += ':';
        }
    }
    longs.push_back({nullptr, 0, nullptr, 0});

    bool have_board = false, have_square = false;
    help = false;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, shorts.c_str(), longs.data(), nullptr)) != -1) {
        std::string arg = optarg ? optarg : "";
        switch (c) {
        case opt_board:
            if (!parse_board(arg, o.board))
                return false;
            have_board = true;
            break;
        case opt_square: {
            char *end = nullptr;
            errno = 0;
            o.square = std::strtod(arg.c_str(), &end);
            if (arg.empty() || *end || errno || !std::isfinite(o.square) || !(o.square > 0))
                return usage_error("--square wants a positive number, not '%s'", arg.c_str());
            have_square = true;
            break;
        }
        case opt_full_model: o.full_model = true; break;
        case opt_output:
            if (arg.empty())
                return usage_error("-o wants a file name");
            o.output = arg;
            break;
        case opt_overlay:
            if (arg.empty())
                return usage_error("--overlay wants a directory");
            o.overlay = arg;
            break;
        case opt_coverage:
            if (arg.empty() || !cv::haveImageWriter(arg))
                return usage_error("--coverage %s: not a picture file name OpenCV can write "
                                   "(use .png)", arg.c_str());
            o.coverage = arg;
            break;
        case opt_camera_name:
            if (!valid_name(arg))
                return usage_error("--camera-name '%s': use letters, digits and '_', "
                                   "not starting with a digit", arg.c_str());
            o.camera_name = arg;
            break;
        case opt_no_reject: o.rejection.enabled = false; break;
        case opt_outlier_floor: {
            char *end = nullptr;
            errno = 0;
            o.rejection.floor_px = std::strtod(arg.c_str(), &end);
            if (arg.empty() || *end || errno || !std::isfinite(o.rejection.floor_px) ||
                o.rejection.floor_px < 0 || o.rejection.floor_px > 100)
                return usage_error("--outlier-floor wants a number of pixels 0..100, not '%s'",
                                   arg.c_str());
            o.have_floor = true;
            break;
        }
        case opt_print_board:
            if (arg.empty())
                return usage_error("--print-board wants a file name");
            o.print_board = arg;
            break;
        case opt_paper:
            if (!calib::parse_paper(arg, o.paper))
                return usage_error("--paper wants a4, letter, a3 or fit, not '%s'", arg.c_str());
            break;
        case opt_help: help = true; return true;
        case ':':
            return usage_error("option %s wants a value", argv[optind - 1]);
        default:
            return usage_error("unknown option '%s'", argv[optind - 1]);
        }
    }
    if (!have_board)
        return usage_error("--board COLSxROWS is required");
    if (!have_square)
        return usage_error("--square SIZE is required");
    if (!o.rejection.enabled && o.have_floor)
        return usage_error("--no-reject and --outlier-floor exclude each other");
    for (int i = optind; i < argc; i++)
        o.inputs.push_back(argv[i]);
    if (!o.print_board.empty()) {
        if (!o.inputs.empty())
            return usage_error("--print-board takes no images ('%s')", o.inputs[0].c_str());
        return true;
    }
    if (o.inputs.empty())
        return usage_error("no images given");
    return true;
}

// An argument that names no file but holds glob characters is expanded
// (sorted); a pattern that matches nothing is a usage error. Anything else
// is kept as given and judged when read.
bool expand_inputs(const std::vector<std::string> &args, std::vector<std::string> &paths)
{
    for (const std::string &a : args) {
        struct stat st;
        if (stat(a.c_str(), &st) == 0 || a.find_first_of("*?[") == std::string::npos) {
            paths.push_back(a);
            continue;
        }
        glob_t g;
        int rc = glob(a.c_str(), 0, nullptr, &g);
        if (rc == GLOB_NOMATCH) {
            std::fprintf(stderr, "%s: no file matches '%s'\n", prog, a.c_str());
            return false;
        }
        if (rc != 0) {
            std::fprintf(stderr, "%s: cannot expand '%s': %s\n", prog, a.c_str(),
                         rc == GLOB_NOSPACE ? "out of memory" : "read error");
            globfree(&g);
            return false;
        }
        for (size_t i = 0; i < g.gl_pathc; i++)
            paths.push_back(g.gl_pathv[i]);
        globfree(&g);
    }
    return true;
}

std::string dir_of(const std::string &path)
{
    size_t s = path.find_last_of('/');
    return s == std::string::npos ? "." : s == 0 ? "/" : path.substr(0, s);
}

std::string stem_of(const std::string &path)
{
    size_t s = path.find_last_of('/');
    std::string name = s == std::string::npos ? path : path.substr(s + 1);
    size_t dot = name.find_last_of('.');
    return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

bool writable_dir(const std::string &dir, const char *what)
{
    struct stat st;
    if (stat(dir.c_str(), &st) != 0) {
        std::fprintf(stderr, "%s: %s: directory %s: %s\n", prog, what, dir.c_str(),
                     std::strerror(errno));
        return false;
    }
    if (!S_ISDIR(st.st_mode)) {
        std::fprintf(stderr, "%s: %s: %s is not a directory\n", prog, what, dir.c_str());
        return false;
    }
    if (access(dir.c_str(), W_OK | X_OK) != 0) {
        std::fprintf(stderr, "%s: %s: cannot write in %s: %s\n", prog, what, dir.c_str(),
                     std::strerror(errno));
        return false;
    }
    return true;
}

// The YAML goes to a temporary file beside its destination, renamed into
// place only once complete: a failed run never leaves half a calibration.
struct Output {
    std::string path, tmp;
    std::FILE *f = nullptr;

    bool open(const std::string &p)
    {
        path = p;
        if (p == "-") {
            f = stdout;
            return true;
        }
        tmp = p + ".tmp" + std::to_string((long)getpid());
        f = std::fopen(tmp.c_str(), "w");
        if (!f) {
            std::fprintf(stderr, "%s: cannot write %s: %s\n", prog, p.c_str(),
                         std::strerror(errno));
            return false;
        }
        return true;
    }
    // the temporary file removed, the destination left as it was
    void abandon()
    {
        if (f && f != stdout) {
            std::fclose(f);
            std::remove(tmp.c_str());
        }
        f = nullptr;
    }
    bool commit()
    {
        if (f == stdout) {
            if (std::fflush(stdout) == 0 && !std::ferror(stdout))
                return true;
            std::fprintf(stderr, "%s: cannot write the calibration to standard output: %s\n",
                         prog, std::strerror(errno));
            return false;
        }
        bool ok = !std::ferror(f);
        ok = (std::fclose(f) == 0) && ok;
        f = nullptr;
        if (ok && std::rename(tmp.c_str(), path.c_str()) != 0)
            ok = false;
        if (!ok) {
            std::fprintf(stderr, "%s: cannot write %s: %s\n", prog, path.c_str(),
                         std::strerror(errno));
            std::remove(tmp.c_str());
        }
        return ok;
    }
    ~Output()
    {
        if (f && f != stdout) {
            std::fclose(f);
            std::remove(tmp.c_str());
        }
    }
};

struct Progress {
    bool on = false;
    size_t width = 0;

    void show(const char *what, size_t i, size_t n, const std::string &name)
    {
        if (!on)
            return;
        char line[256];
        int len = std::snprintf(line, sizeof line, "%s %zu/%zu %s", what, i, n, name.c_str());
        size_t w = (size_t)std::max(0, std::min(len, (int)sizeof line - 1));
        std::fprintf(stderr, "\r%s%*s", line, (int)(width > w ? width - w : 0), "");
        width = w;
    }
    void clear()
    {
        if (on && width) {
            std::fprintf(stderr, "\r%*s\r", (int)width, "");
            width = 0;
        }
    }
};

const char *status_text(const View &v)
{
    switch (v.state) {
    case ViewState::used: return "used";
    case ViewState::rejected: return "REJECTED";
    case ViewState::no_board: return "no board";
    case ViewState::wrong_size: return "wrong size";
    case ViewState::unreadable: return "unreadable";
    }
    return "";
}

// calibrated: the views' errors and poses were measured (false when there
// were too few views to calibrate: boards found are shown as "board found").
void print_table(std::FILE *f, const std::vector<View> &views, bool calibrated = true)
{
    int w = 5;
    for (const View &v : views)
        w = std::max(w, (int)v.path.size());
    std::fprintf(f, "%4s  %-*s %7s %8s %8s %9s %6s  %s\n", "#", w, "image", "corners",
                 "rms px", "max px", "distance", "tilt", "status");
    int i = 0;
    for (const View &v : views) {
        i++;
        if (!calibrated && v.state == ViewState::used)
            std::fprintf(f, "%4d  %-*s %7zu %8s %8s %9s %6s  %s\n", i, w, v.path.c_str(),
                         v.corners.size(), "-", "-", "-", "-", "board found");
        else if (v.state == ViewState::used || v.state == ViewState::rejected)
            std::fprintf(f, "%4d  %-*s %7zu %8.4f %8.4f %9.4g %6.1f  %s\n", i, w,
                         v.path.c_str(), v.corners.size(), v.rms_px, v.max_px, v.distance,
                         v.tilt_deg, status_text(v));
        else
            std::fprintf(f, "%4d  %-*s %7s %8s %8s %9s %6s  %s\n", i, w, v.path.c_str(),
                         v.corners.empty() ? "-" : std::to_string(v.corners.size()).c_str(),
                         "-", "-", "-", "-", status_text(v));
    }
}

void print_result(std::FILE *f, const calib::Result &r, const calib::Coverage &cov,
                  bool full_model, size_t n_views)
{
    const cv::Vec<double, 9> &s = r.sigma;
    std::fprintf(f, "\nviews used: %d of %zu", r.n_used, n_views);
    if (r.n_rejected)
        std::fprintf(f, " (%d rejected: RMS error above %.4f px)", r.n_rejected,
                     r.reject_above_px);
    std::fprintf(f, "\nRMS reprojection error: %.4f px\n", r.rms_px);
    std::fprintf(f, "model: %s\n", full_model ? "plumb_bob (k1 k2 p1 p2 k3)"
                                              : "k1 k2 (p1 = p2 = k3 = 0)");
    std::fprintf(f, "  fx = %.4f +- %.3g px\n  fy = %.4f +- %.3g px\n", r.K(0, 0), s[0],
                 r.K(1, 1), s[1]);
    std::fprintf(f, "  cx = %.4f +- %.3g px\n  cy = %.4f +- %.3g px\n", r.K(0, 2), s[2],
                 r.K(1, 2), s[3]);
    const char *dn[5] = {"k1", "k2", "p1", "p2", "k3"};
    for (int i = 0; i < 5; i++)
        if (full_model || i < 2)
            std::fprintf(f, "  %s = %.6g +- %.3g\n", dn[i], r.D[i], s[4 + i]);
    std::fprintf(f, "corner coverage: %d of %d grid cells; corners reach %.0f%% of the way "
                    "to the image corners\n",
                 cov.covered, cov.cols * cov.rows, 100.0 * cov.reach);
}

void print_warnings(const calib::Result &r, const calib::Coverage &cov)
{
    if (r.rejection_skipped)
        std::fprintf(stderr, "%s: warning: some views look like outliers (RMS error above "
                     "%.4f px) but were kept: fewer than %d views would remain\n",
                     prog, r.reject_above_px, calib::min_views);
    if (r.rms_px > warn_rms_px)
        std::fprintf(stderr, "%s: warning: RMS reprojection error %.3f px is high: check "
                     "focus, motion blur and the board's flatness, or try --full-model\n",
                     prog, r.rms_px);
    double rel = std::max(r.sigma[0] / r.K(0, 0), r.sigma[1] / r.K(1, 1));
    if (rel > warn_focal_rel_sigma)
        std::fprintf(stderr, "%s: warning: fx, fy are uncertain by %.2g%%: add views with "
                     "the board tilted 30-45 degrees\n", prog, 100.0 * rel);
    if (cov.reach < warn_reach)
        std::fprintf(stderr, "%s: warning: the corners reach only %.0f%% of the way to the "
                     "image corners, where the distortion is extrapolated: add views with "
                     "the board near the image's corners\n", prog, 100.0 * cov.reach);
}

int run(const Options &o)
{
    std::vector<std::string> paths;
    if (!expand_inputs(o.inputs, paths))
        return exit_usage;

    // Outputs are checked before the long corner search; the YAML's
    // temporary file is created only once there is something to write.
    if (o.output != "-" && !writable_dir(dir_of(o.output), "-o"))
        return exit_usage;
    if (!o.overlay.empty()) {
        if (mkdir(o.overlay.c_str(), 0777) != 0 && errno != EEXIST) {
            std::fprintf(stderr, "%s: --overlay: cannot create %s: %s\n", prog,
                         o.overlay.c_str(), std::strerror(errno));
            return exit_usage;
        }
        if (!writable_dir(o.overlay, "--overlay"))
            return exit_usage;
    }
    if (!o.coverage.empty() && !writable_dir(dir_of(o.coverage), "--coverage"))
        return exit_usage;
    std::FILE *rep = o.output == "-" ? stderr : stdout;

    // Corners. After the first unreadable file, the rest are only read,
    // so that every bad file is named without a long wait.
    Progress progress;
    progress.on = isatty(fileno(stderr)) && paths.size() >= progress_min_images;
    std::vector<View> views(paths.size());
    size_t n_bad = 0;
    std::map<std::pair<int, int>, int> sizes;
    for (size_t i = 0; i < paths.size(); i++) {
        View &v = views[i];
        v.path = paths[i];
        progress.show("corners", i + 1, paths.size(), v.path);
        cv::Mat gray8, fine;
        if (!calib::read_gray(v.path, gray8, fine, v.problem)) {
            progress.clear();
            std::fprintf(stderr, "%s: %s: %s\n", prog, v.path.c_str(), v.problem.c_str());
            v.state = ViewState::unreadable;
            n_bad++;
            continue;
        }
        v.size = gray8.size();
        sizes[{v.size.width, v.size.height}]++;
        if (n_bad == 0)
            v.state = calib::detect_board(gray8, fine, o.board, v.corners) ? ViewState::used
                                                                           : ViewState::no_board;
    }
    progress.clear();
    if (n_bad) {
        std::fprintf(stderr, "%s: %zu of %zu images could not be read; nothing written\n",
                     prog, n_bad, paths.size());
        return exit_usage;
    }

    // The image size: the one most images have.
    auto most = std::max_element(sizes.begin(), sizes.end(),
                                 [](const auto &a, const auto &b) { return a.second < b.second; });
    cv::Size size(most->first.first, most->first.second);
    for (View &v : views)
        if (v.size != size) {
            std::fprintf(stderr, "%s: %s: %dx%d, unlike the other images (%dx%d): skipped\n",
                         prog, v.path.c_str(), v.size.width, v.size.height, size.width,
                         size.height);
            v.state = ViewState::wrong_size;
        }

    int n_board = (int)std::count_if(views.begin(), views.end(),
                                     [](const View &v) { return v.state == ViewState::used; });
    if (n_board < calib::min_views) {
        print_table(rep, views, false);
        if (n_board == 0)
            std::fprintf(stderr, "%s: the %dx%d board was found in none of the %zu images: "
                         "check --board (it counts inner corners: squares - 1 along each "
                         "side) and that the whole board, with a white border, is in view\n",
                         prog, o.board.width, o.board.height, views.size());
        else
            std::fprintf(stderr, "%s: the %dx%d board was found in only %d of the %zu "
                         "images; at least %d usable views are needed (10-20 give a good "
                         "calibration): nothing calibrated, nothing written\n", prog,
                         o.board.width, o.board.height, n_board, views.size(),
                         calib::min_views);
        return exit_calib;
    }

    calib::Result res;
    std::string problem;
    calib::SolveStatus st = calib::calibrate(views, size, o.board, o.square, o.full_model,
                                             o.rejection, res, problem);
    if (st != calib::SolveStatus::ok) {
        print_table(rep, views);
        std::fprintf(stderr, "%s: calibration failed: %s\n", prog, problem.c_str());
        return exit_calib;
    }
    calib::Coverage cov = calib::coverage(views, size);
    print_table(rep, views);
    print_result(rep, res, cov, o.full_model, views.size());
    std::fflush(rep);
    print_warnings(res, cov);

    // commit() checks the stream's error flag: a failed write is caught there.
    int rc = exit_ok;
    Output out;
    if (!out.open(o.output)) {
        rc = exit_usage;
    } else {
        std::string why;
        if (!calib::write_camera_info(out.f, o.camera_name, size, res, o.full_model,
                                      (int)views.size(), why) &&
            !std::ferror(out.f)) {
            // a camera the rest would refuse: nothing is written
            std::fprintf(stderr, "%s: %s\n", prog, why.c_str());
            out.abandon();
            rc = exit_calib;
        } else if (!out.commit())
            rc = exit_usage;
        else if (o.output != "-")
            std::fprintf(rep, "wrote %s\n", o.output.c_str());
    }

    if (!o.overlay.empty()) {
        std::set<std::string> names;
        size_t n = 0, i = 0;
        for (const View &v : views)
            n += v.state == ViewState::used || v.state == ViewState::rejected;
        for (size_t k = 0; k < views.size(); k++) {
            const View &v = views[k];
            if (v.state != ViewState::used && v.state != ViewState::rejected)
                continue;
            progress.show("overlays", ++i, n, v.path);
            std::string name = stem_of(v.path);
            if (!names.insert(name).second)
                name += "-" + std::to_string(k + 1);   // same name, other directory
            names.insert(name);
            std::string path = o.overlay + "/" + name + ".png";
            cv::Mat gray8, fine;
            if (!calib::read_gray(v.path, gray8, fine, problem) ||
                !calib::write_overlay(path, gray8, v)) {
                progress.clear();
                std::fprintf(stderr, "%s: cannot write overlay %s\n", prog, path.c_str());
                rc = exit_usage;
            }
        }
        progress.clear();
    }
    if (!o.coverage.empty() && !calib::write_coverage(o.coverage, views, size, cov)) {
        std::fprintf(stderr, "%s: cannot write %s\n", prog, o.coverage.c_str());
        rc = exit_usage;
    }
    return rc;
}

} // namespace

int main(int argc, char **argv)
{
    // OpenCV's own warnings (a decoder's complaint, say) would duplicate
    // our messages, which name the file and the problem.
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    Options o;
    bool help = false;
    if (!parse_args(argc, argv, o, help))
        return exit_usage;
    if (help) {
        print_help(stdout);
        return std::fflush(stdout) == 0 ? exit_ok : exit_usage;
    }
    try {
        if (!o.print_board.empty()) {
            std::string problem;
            if (!writable_dir(dir_of(o.print_board), "--print-board"))
                return exit_usage;
            if (!calib::write_board(o.print_board, o.board, o.square, o.paper, problem)) {
                std::fprintf(stderr, "%s: --print-board %s: %s\n", prog,
                             o.print_board.c_str(), problem.c_str());
                return exit_usage;
            }
            std::printf("wrote %s: %dx%d inner corners, %g mm squares (print at 100 %%)\n",
                        o.print_board.c_str(), o.board.width, o.board.height, o.square);
            return exit_ok;
        }
        return run(o);
    } catch (const cv::Exception &e) {
        std::fprintf(stderr, "%s: OpenCV error: %s\n", prog, e.what());
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    }
    return exit_calib;
}
