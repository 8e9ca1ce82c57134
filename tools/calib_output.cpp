// calib_output.cpp: the files cdsp_calib writes (see calib_output.hpp).
#include "calib_output.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace calib {

bool write_camera_info(std::FILE *f, const std::string &camera_name, cv::Size size,
                       const Result &res, bool full_model, int n_given, std::string &why)
{
    // the YAML itself is the host library's writer (host/calib.c), the one
    // cdsp_tool sim and cdspd --record use; cdsp_calib adds its comment
    // lines and the projection matrix of the undistorted image
    const cv::Vec<double, 9> &s = res.sigma;
    char comment[512];
    int n = std::snprintf(comment, sizeof comment,
                          "cdsp_calib: RMS reprojection error %.4f px over %d images (of %d given)\n"
                          "model %s; 1-sigma: fx %.3g fy %.3g cx %.3g cy %.3g px, k1 %.3g k2 %.3g",
                          res.rms_px, res.n_used, n_given,
                          full_model ? "plumb_bob k1 k2 p1 p2 k3" : "k1 k2 (p1 = p2 = k3 = 0)",
                          s[0], s[1], s[2], s[3], s[4], s[5]);
    if (full_model && n > 0 && (size_t)n < sizeof comment)
        std::snprintf(comment + n, sizeof comment - (size_t)n, " p1 %.3g p2 %.3g k3 %.3g", s[6],
                      s[7], s[8]);
    cdsp_camera cam{};
    cam.fx = res.K(0, 0);
    cam.fy = res.K(1, 1);
    cam.cx = res.K(0, 2);
    cam.cy = res.K(1, 2);
    cam.k1 = res.D[0];
    cam.k2 = res.D[1];
    cam.p1 = res.D[2];
    cam.p2 = res.D[3];
    cam.k3 = res.D[4];
    cam.width = size.width;
    cam.height = size.height;
    cdsp_host_err err;
    if (cdsp_host_calib_write_stream(f, "the calibration", &cam, camera_name.c_str(), comment,
                                     res.P.val, &err) != CDSP_HOST_OK) {
        why = err.msg;
        return false;
    }
    return true;
}

static bool write_image(const std::string &path, const cv::Mat &img)
{
    try {
        return cv::imwrite(path, img);
    } catch (const cv::Exception &) {
        return false;
    }
}

// A caption legible on any background: dark outline, light text.
static void caption(cv::Mat &img, const std::string &text, int line, double scale)
{
    int thick = std::max(1, (int)std::lround(scale * 1.5));
    cv::Point at(10, (int)std::lround((line + 1) * 30 * scale));
    cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0),
                thick + 2, cv::LINE_AA);
    cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255),
                thick, cv::LINE_AA);
}

static const char *state_name(ViewState s)
{
    return s == ViewState::used ? "used" : s == ViewState::rejected ? "rejected (outlier)" : "";
}

bool write_overlay(const std::string &path, const cv::Mat &gray8, const View &v)
{
    cv::Mat img;
    cv::cvtColor(gray8, img, cv::COLOR_GRAY2BGR);
    double scale = std::max(0.6, img.cols / 1200.0);
    int thick = std::max(1, (int)std::lround(scale));
    int r = (int)std::lround(5 * scale);
    for (const cv::Point2f &p : v.corners)
        cv::circle(img, p, r, cv::Scalar(0, 200, 0), thick, cv::LINE_AA);
    for (const cv::Point2f &p : v.reprojected)
        cv::drawMarker(img, p, cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 2 * r, thick,
                       cv::LINE_AA);
    char line[160];
    std::snprintf(line, sizeof line, "rms %.3f px, max %.3f px: %s", v.rms_px, v.max_px,
                  state_name(v.state));
    caption(img, v.path, 0, scale);
    caption(img, line, 1, scale);
    caption(img, "green: detected corners, red: reprojected", 2, scale);
    return write_image(path, img);
}

bool write_coverage(const std::string &path, const std::vector<View> &views,
                    cv::Size size, const Coverage &cov)
{
    cv::Mat img(size, CV_8UC3, cv::Scalar(0, 0, 0));
    double scale = std::max(0.6, size.width / 1200.0);
    int thick = std::max(1, (int)std::lround(scale));
    for (int j = 0; j < cov.rows; j++)
        for (int i = 0; i < cov.cols; i++) {
            cv::Point a(i * size.width / cov.cols, j * size.height / cov.rows);
            cv::Point b((i + 1) * size.width / cov.cols - 1,
                        (j + 1) * size.height / cov.rows - 1);
            bool hit = cov.count[(size_t)(j * cov.cols + i)] > 0;
            cv::rectangle(img, a, b, hit ? cv::Scalar(48, 48, 48) : cv::Scalar(0, 0, 110),
                          cv::FILLED);
            cv::rectangle(img, a, b, cv::Scalar(90, 90, 90), 1);
        }

    int k = 0, n_corners = 0, n_views = 0;
    for (const View &v : views) {
        if (v.state != ViewState::used && v.state != ViewState::rejected)
            continue;
        size_t n = v.corners.size();
        cv::Scalar color(128, 128, 128);
        if (v.state == ViewState::used) {
            // One hue per view, spread by the golden angle.
            cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(std::fmod(k * 137.508, 180.0), 220, 255));
            cv::Mat bgr;
            cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
            cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
            color = cv::Scalar(c[0], c[1], c[2]);
            k++;
            n_views++;
            n_corners += (int)n;
        }
        std::vector<cv::Point> hull;
        std::vector<cv::Point2f> pts(v.corners.begin(), v.corners.end());
        std::vector<int> idx;
        cv::convexHull(pts, idx);
        for (int i : idx)
            hull.push_back(pts[(size_t)i]);
        cv::polylines(img, hull, true, color, thick, cv::LINE_AA);
        if (v.state == ViewState::used)
            for (const cv::Point2f &p : v.corners)
                cv::circle(img, p, thick + 1, color, cv::FILLED, cv::LINE_AA);
    }
    char line[200];
    std::snprintf(line, sizeof line, "%d views, %d corners: %d of %d cells covered", n_views,
                  n_corners, cov.covered, cov.cols * cov.rows);
    caption(img, line, 0, scale);
    std::snprintf(line, sizeof line, "corners reach %.0f%% of the way to the image corners",
                  100.0 * cov.reach);
    caption(img, line, 1, scale);
    caption(img, "dark red: cells without corners; gray outlines: rejected views", 2, scale);
    return write_image(path, img);
}

} // namespace calib
