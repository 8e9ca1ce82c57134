// calib_core.cpp: image reading, corner detection and the two-pass
// calibration of cdsp_calib (see calib_core.hpp). The calibration itself is
// OpenCV's calibrateCamera: Zhang-style closed-form initialisation from the
// board homographies, then Levenberg-Marquardt over K, the distortion
// coefficients and every board pose (the paper's section 3 step 1).
#include "calib_core.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace calib {

namespace {

// Points stderr at /dev/null while it lives. OpenCV 4.6's imread writes a
// decoder's failure ("imread_('x'): can't read data: ...") to std::cerr,
// bypassing its logger; our own message names the file and the problem.
class QuietStderr {
public:
    QuietStderr()
    {
        std::fflush(stderr);
        saved_ = dup(STDERR_FILENO);
        int null = open("/dev/null", O_WRONLY);
        if (saved_ >= 0 && null >= 0)
            dup2(null, STDERR_FILENO);
        if (null >= 0)
            close(null);
    }
    ~QuietStderr()
    {
        std::cerr.flush();
        if (saved_ >= 0) {
            dup2(saved_, STDERR_FILENO);
            close(saved_);
        }
    }
    QuietStderr(const QuietStderr &) = delete;
    QuietStderr &operator=(const QuietStderr &) = delete;

private:
    int saved_ = -1;
};

} // namespace

bool read_gray(const std::string &path, cv::Mat &gray8, cv::Mat &fine,
               std::string &problem)
{
    // OpenCV's imread says only "empty"; look at the file first so the
    // message names the real problem.
    struct stat st;
    if (stat(path.c_str(), &st) != 0) {
        problem = std::strerror(errno);
        return false;
    }
    if (S_ISDIR(st.st_mode)) {
        problem = "is a directory";
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        problem = "not a regular file";
        return false;
    }
    if (st.st_size == 0) {
        problem = "empty file";
        return false;
    }
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) {
        problem = std::strerror(errno);
        return false;
    }
    std::fclose(f);

    cv::Mat img;
    {
        QuietStderr quiet;   // imread prints decoder errors to std::cerr itself
        try {
            img = cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
        } catch (const cv::Exception &) {
            img.release();
        }
    }
    if (img.empty() || img.channels() != 1) {
        problem = "not an image OpenCV can decode (corrupt, truncated or of an unknown format)";
        return false;
    }
    if (img.depth() == CV_8U) {
        gray8 = img;
        fine = img;
        return true;
    }
    cv::Mat f32;
    img.convertTo(f32, CV_32F);
    cv::patchNaNs(f32, 0.0);
    double lo = 0, hi = 0;
    cv::minMaxLoc(f32, &lo, &hi);
    if (!std::isfinite(lo) || !std::isfinite(hi)) {
        problem = "image holds infinite values";
        return false;
    }
    double scale = hi > lo ? 255.0 / (hi - lo) : 0.0;
    f32.convertTo(gray8, CV_8U, scale, -lo * scale);
    fine = f32;   // cornerSubPix works on gradients: the scale does not matter
    return true;
}

// Smallest distance between neighbouring corners of the detected grid, px.
static double min_spacing(const std::vector<cv::Point2f> &c, cv::Size board)
{
    double d = DBL_MAX;
    for (int j = 0; j < board.height; j++)
        for (int i = 0; i < board.width; i++) {
            const cv::Point2f &p = c[(size_t)(j * board.width + i)];
            if (i + 1 < board.width)
                d = std::min(d, cv::norm(p - c[(size_t)(j * board.width + i + 1)]));
            if (j + 1 < board.height)
                d = std::min(d, cv::norm(p - c[(size_t)((j + 1) * board.width + i)]));
        }
    return d;
}

bool detect_board(const cv::Mat &gray8, const cv::Mat &fine, cv::Size board,
                  std::vector<cv::Point2f> &corners)
{
    // The sector-based detector (Duda & Frese 2018), not the classic
    // findChessboardCorners: on an image whose board has another size than
    // --board, the classic one spent 25-60 s per 1024x768 image here
    // (combinatorial search over quad groups), the SB one under 0.4 s. Its
    // corners are then refined below like the classic ones would be.
    corners.clear();
    if (!cv::findChessboardCornersSB(gray8, board, corners, cv::CALIB_CB_NORMALIZE_IMAGE) ||
        corners.size() != (size_t)board.area())
        return false;

    // Refinement window (half-width, px): a larger window averages the
    // gradients of more edge pixels (less noise), but must stay clear of
    // the neighbouring corners, whose gradients would pull the estimate:
    // 0.4 of the closest spacing, 2..11 px (11 is OpenCV's usual size).
    double spacing = min_spacing(corners, board);
    int half = std::clamp((int)std::floor(0.4 * spacing), 2, 11);

    // cornerSubPix "locks" onto the pixel grid: it weights each pixel by
    // its squared gradient, and an edge whose profile spans only two or
    // three pixels has a squared-gradient centroid pulled toward the
    // nearest pixel boundary. On sharp synthetic boards (tests/calib) that
    // bias reached 0.08 px RMS for boards square to the pixel grid; a
    // Gaussian blur of sigma 1.5 px spreads every edge over enough pixels
    // to bring it under 0.02 px. The blur is point-symmetric, so it does
    // not move a corner (an X-junction is point-symmetric about it); it
    // stays under spacing / 8 so that neighbouring edges do not merge.
    double sigma = std::min(1.5, spacing / 8.0);
    cv::Mat smooth;
    fine.convertTo(smooth, CV_32F);
    cv::GaussianBlur(smooth, smooth, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
    cv::cornerSubPix(smooth, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                      100, 1e-4));
    return true;
}

namespace {

struct Pass {
    cv::Mat K, D;
    std::vector<cv::Mat> rvecs, tvecs;
    cv::Mat sigma;              // stdDeviationsIntrinsics
    std::vector<double> per_view;
    double rms = 0;
};

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool finite_mat(const cv::Mat &m)
{
    return cv::checkRange(m, true, nullptr, -DBL_MAX, DBL_MAX);
}

void run_pass(const std::vector<std::vector<cv::Point3f>> &obj,
                     const std::vector<std::vector<cv::Point2f>> &img,
                     cv::Size size, bool full_model, Pass &p)
{
    // The paper's model: k1, k2 only. The full plumb_bob adds p1, p2, k3.
    int flags = full_model ? 0 : (cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3);
    cv::Mat std_ext, per_view;
    p.rms = cv::calibrateCamera(obj, img, size, p.K, p.D, p.rvecs, p.tvecs,
                                p.sigma, std_ext, per_view, flags,
                                cv::TermCriteria(cv::TermCriteria::COUNT |
                                                 cv::TermCriteria::EPS, 200, DBL_EPSILON));
    p.per_view.assign(per_view.begin<double>(), per_view.end<double>());
}

// Reprojection errors and board geometry of one view under a calibration.
void measure_view(View &v, const std::vector<cv::Point3f> &obj, const cv::Mat &K,
                  const cv::Mat &D, const cv::Mat &rvec, const cv::Mat &tvec,
                  cv::Point3d centre)
{
    cv::projectPoints(obj, rvec, tvec, K, D, v.reprojected);
    double sum = 0, mx = 0;
    for (size_t i = 0; i < obj.size(); i++) {
        double e = cv::norm(v.reprojected[i] - v.corners[i]);
        sum += e * e;
        mx = std::max(mx, e);
    }
    v.rms_px = std::sqrt(sum / (double)obj.size());
    v.max_px = mx;
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    cv::Vec3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    cv::Vec3d c = R * cv::Vec3d(centre.x, centre.y, centre.z) + t;
    v.distance = cv::norm(c);
    v.tilt_deg = std::acos(std::min(1.0, std::fabs(R(2, 2)))) * 180.0 / CV_PI;
}

} // namespace

SolveStatus calibrate(std::vector<View> &views, cv::Size image_size,
                      cv::Size board, double square, bool full_model,
                      const Rejection &rej, Result &res, std::string &problem)
{
    // Board corners in the board's plane, in the order the detector
    // returns them (row by row, board.width per row).
    std::vector<cv::Point3f> board_pts;
    for (int j = 0; j < board.height; j++)
        for (int i = 0; i < board.width; i++)
            board_pts.emplace_back((float)(i * square), (float)(j * square), 0.0f);
    cv::Point3d centre(0.5 * (board.width - 1) * square,
                       0.5 * (board.height - 1) * square, 0.0);

    std::vector<size_t> used;
    for (size_t i = 0; i < views.size(); i++)
        if (views[i].state == ViewState::used)
            used.push_back(i);
    if ((int)used.size() < min_views) {
        problem = "too few views";
        return SolveStatus::too_few_views;
    }

    auto solve = [&](const std::vector<size_t> &which, Pass &p) {
        std::vector<std::vector<cv::Point3f>> obj(which.size(), board_pts);
        std::vector<std::vector<cv::Point2f>> img;
        for (size_t i : which)
            img.push_back(views[i].corners);
        run_pass(obj, img, image_size, full_model, p);
    };

    Pass p;
    try {
        solve(used, p);

        // Outliers of the first pass: views whose RMS error exceeds both
        // twice the median and the median + 3 robust sigmas (1.4826 MAD,
        // the normal distribution's sigma). The first bound keeps views
        // that are merely a little worse than a very uniform set; the
        // second keeps the normal spread of a noisy set.
        double m = median(p.per_view);
        std::vector<double> dev;
        for (double e : p.per_view)
            dev.push_back(std::fabs(e - m));
        res.reject_above_px = std::max(2.0 * m, m + 3.0 * 1.4826 * median(dev));
        // ... and never at or below the absolute floor (calib_core.hpp).
        res.reject_above_px = std::max(res.reject_above_px, rej.floor_px);
        if (!rej.enabled)
            res.reject_above_px = HUGE_VAL;
        std::vector<size_t> keep;
        for (size_t k = 0; k < used.size(); k++)
            if (p.per_view[k] <= res.reject_above_px)
                keep.push_back(used[k]);
        res.rejection_skipped = false;
        if (keep.size() < used.size()) {
            if ((int)keep.size() < min_views) {
                res.rejection_skipped = true;
            } else {
                for (size_t k = 0; k < used.size(); k++)
                    if (p.per_view[k] > res.reject_above_px)
                        views[used[k]].state = ViewState::rejected;
                used = keep;
                solve(used, p);
            }
        }
    } catch (const cv::Exception &e) {
        problem = e.err.empty() ? e.what() : e.err;
        return SolveStatus::failed;
    }

    if (!finite_mat(p.K) || !finite_mat(p.D) || !(p.rms >= 0) ||
        !(p.K.at<double>(0, 0) > 0) || !(p.K.at<double>(1, 1) > 0)) {
        problem = "the optimisation diverged (non-finite or negative focal length)";
        return SolveStatus::failed;
    }

    res.K = cv::Matx33d(p.K);
    for (int i = 0; i < 5; i++)
        res.D[i] = i < (int)p.D.total() ? p.D.at<double>(i) : 0.0;
    for (int i = 0; i < 9; i++)
        res.sigma[i] = i < (int)p.sigma.total() ? p.sigma.at<double>(i) : 0.0;
    res.rms_px = p.rms;
    res.n_used = (int)used.size();
    res.n_rejected = 0;

    cv::Mat D5(res.D);
    try {
        cv::Mat newK = cv::getOptimalNewCameraMatrix(p.K, D5, image_size, 0.0);
        res.P = cv::Matx34d::zeros();
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                res.P(r, c) = newK.at<double>(r, c);

        for (size_t k = 0; k < used.size(); k++)
            measure_view(views[used[k]], board_pts, p.K, D5, p.rvecs[k], p.tvecs[k], centre);
        for (View &v : views) {
            if (v.state != ViewState::rejected)
                continue;
            res.n_rejected++;
            cv::Mat rvec, tvec;
            cv::solvePnP(board_pts, v.corners, p.K, D5, rvec, tvec);
            measure_view(v, board_pts, p.K, D5, rvec, tvec, centre);
        }
    } catch (const cv::Exception &e) {
        problem = e.err.empty() ? e.what() : e.err;
        return SolveStatus::failed;
    }
    return SolveStatus::ok;
}

Coverage coverage(const std::vector<View> &views, cv::Size size)
{
    Coverage c;
    c.cols = 8;
    c.rows = std::max(1, (int)std::lround(8.0 * size.height / size.width));
    c.count.assign((size_t)(c.cols * c.rows), 0);
    cv::Point2d mid(0.5 * (size.width - 1), 0.5 * (size.height - 1));
    double half_diag = cv::norm(mid);
    for (const View &v : views) {
        if (v.state != ViewState::used)
            continue;
        for (const cv::Point2f &p : v.corners) {
            int i = std::clamp((int)(p.x * c.cols / size.width), 0, c.cols - 1);
            int j = std::clamp((int)(p.y * c.rows / size.height), 0, c.rows - 1);
            c.count[(size_t)(j * c.cols + i)]++;
            c.reach = std::max(c.reach, cv::norm(cv::Point2d(p) - mid) / half_diag);
        }
    }
    c.covered = (int)std::count_if(c.count.begin(), c.count.end(),
                                   [](int n) { return n > 0; });
    return c;
}

} // namespace calib
