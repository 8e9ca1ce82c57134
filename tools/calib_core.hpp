// calib_core.hpp: the calibration pipeline of cdsp_calib without its command
// line: read an image, find the checkerboard's inner corners, calibrate
// (Zhang initialisation + Levenberg-Marquardt, OpenCV's calibrateCamera),
// drop the outlier views and calibrate again. Nothing here prints or exits;
// problems come back as a status and a message.
#ifndef CDSP_CALIB_CORE_HPP
#define CDSP_CALIB_CORE_HPP

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace calib {

// Fewest views the calibration accepts. Zhang's method needs two
// homographies for fx, fy, cx, cy (skew fixed at zero); a third makes the
// result checkable (a residual) and the LM refinement of k1, k2 well posed.
// Real calibrations want 10-20 views; the report says how well constrained
// the result is.
constexpr int min_views = 3;

enum class ViewState {
    unreadable,  // the file could not be read or decoded (problem says why)
    wrong_size,  // readable, but not the size of the other images
    no_board,    // the board was not found
    used,        // in the final calibration
    rejected,    // board found, dropped as a reprojection-error outlier
};

struct View {
    std::string path;                     // as given on the command line
    ViewState state = ViewState::no_board;
    std::string problem;                  // why unreadable
    cv::Size size;                        // image size, px
    std::vector<cv::Point2f> corners;     // detected, distorted px, board order
    // Filled by calibrate() for views with a board (used or rejected):
    std::vector<cv::Point2f> reprojected; // corners reprojected, final calibration
    double rms_px = 0, max_px = 0;        // reprojection error, final calibration
    double distance = 0;                  // board centre from the camera, unit of --square
    double tilt_deg = 0;                  // board normal vs the optical axis
};

// Reads an image as 8-bit gray (for the detector) and, for deeper images,
// also the full-precision gray as CV_32F (for the subpixel refinement);
// fine is gray8 itself for 8-bit images. Deeper images are stretched
// min..max onto 0..255 for the detector, so 10/12-bit data stored in 16-bit
// words (cdspd --record) is not left dark. false and problem on failure.
bool read_gray(const std::string &path, cv::Mat &gray8, cv::Mat &fine,
               std::string &problem);

// Inner corners of a board of board.width x board.height inner corners,
// refined to subpixel precision. false if the board is not found whole.
bool detect_board(const cv::Mat &gray8, const cv::Mat &fine, cv::Size board,
                  std::vector<cv::Point2f> &corners);

struct Result {
    cv::Matx33d K;                   // camera matrix, px
    cv::Vec<double, 5> D;            // k1, k2, p1, p2, k3
    cv::Matx34d P;                   // ROS projection matrix (see calibrate)
    double rms_px = 0;               // RMS reprojection error, used views
    cv::Vec<double, 9> sigma;        // 1-sigma of fx fy cx cy k1 k2 p1 p2 k3
    int n_used = 0, n_rejected = 0;
    double reject_above_px = 0;      // outlier threshold of the first pass
    bool rejection_skipped = false;  // outliers kept: too few views would remain
};

// The absolute floor of outlier rejection: a view whose first-pass RMS
// reprojection error is at most this is never an outlier, however uniform
// the other views are. 0.1 px is the RMS a good calibration must reach as a
// whole (the bar cdsp_calib's tests hold it to, and what ROS's and
// OpenCV's guides call a good calibration); it is what corner noise of
// 0.07 px per coordinate gives (RMS over both coordinates: sqrt(2) x 0.07).
// A view that meets the bar set for the whole calibration fits the model
// as well as corner noise allows, and dropping it only loses information:
// the relative rule below alone rejected views at 0.05 px from sets whose
// median was 0.02 px.
constexpr double default_outlier_floor_px = 0.1;

// How outliers are rejected (see calibrate).
struct Rejection {
    bool enabled = true;                           // false: --no-reject
    double floor_px = default_outlier_floor_px;    // --outlier-floor
};

enum class SolveStatus { ok, too_few_views, failed };

// Calibrates from the views in state used (all others are left alone),
// with k1, k2 only (p1 = p2 = k3 = 0) unless full_model. Views whose
// first-pass RMS error is an outlier (above reject_above_px, see the .cpp,
// and never at or below rej.floor_px) become rejected and the calibration
// runs again without them; with rej.enabled false every view is kept. Fills the
// per-view fields of every view with a board. P is what ROS's
// camera_calibration writes for a monocular camera: the camera matrix of
// the rectified image, getOptimalNewCameraMatrix with alpha = 0 (every
// pixel of the rectified image valid), with a zero fourth column.
SolveStatus calibrate(std::vector<View> &views, cv::Size image_size,
                      cv::Size board, double square, bool full_model,
                      const Rejection &rej, Result &res, std::string &problem);

// Corners of the views in state used, counted on a grid of cells about
// image_size.width / 8 wide: how much of the field of view they cover.
struct Coverage {
    int cols = 0, rows = 0;          // grid cells
    std::vector<int> count;          // corners per cell, row-major
    int covered = 0;                 // cells with at least one corner
    double reach = 0;                // farthest corner from the image centre,
                                     // as a fraction of the centre-to-corner distance
};
Coverage coverage(const std::vector<View> &views, cv::Size image_size);

} // namespace calib

#endif
