// cv_baseline.cpp - `make bench-frame`'s side-by-side (issue 17): the frame
// path of libcdsp against a plain OpenCV pipeline on the same 2448 x 2048
// frames (bench_frame's cache, DIR/frames.raw), timed in the same process,
// one core, alternately:
//   OpenCV: cv::Canny (thresholds 50/150, 3x3 Sobel, the textbook call) ->
//     the edge pixels -> sequential RANSAC (500 two-point hypotheses,
//     inliers within 1.5 px, cv::RNG seeded) for two lines, each refitted
//     with cv::fitLine (L2) on its inliers -> the same closed form as
//     libcdsp (cdsp_axis_solve, docs/method.md §5) with the midpoint of the
//     two lines' centroids as the pixel between them;
//   libcdsp: cdsp_frame_solve, default parameters (full search).
// Prints the median time of each, their ratio (target >= 50), and the
// distance each found (a sanity check that both saw the pipe; the OpenCV
// pipeline has no polarity or pair logic, so on clutter it may not).
// Figures, not pass/fail; the machine is shared: one run's ratio.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

extern "C" {
#include "cdsp.h"
}

namespace {

constexpr int W = 2448, H = 2048, NFRAMES = 6;

double now_ms()
{
    using clk = std::chrono::steady_clock;
    return std::chrono::duration<double, std::milli>(clk::now().time_since_epoch()).count();
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

// One RANSAC line over the points not yet taken; its inliers' indices.
std::vector<int> ransac_line(const std::vector<cv::Point> &pts, const std::vector<char> &taken, cv::RNG &rng)
{
    std::vector<int> best;
    const int n = (int)pts.size();
    if (n < 2)
        return best;
    for (int it = 0; it < 500; it++) {
        int i = rng.uniform(0, n), j = rng.uniform(0, n);
        if (i == j || taken[i] || taken[j])
            continue;
        double a = pts[j].y - pts[i].y, b = pts[i].x - pts[j].x, nrm = std::hypot(a, b);
        if (nrm < 20) // a short base: a poor hypothesis
            continue;
        a /= nrm;
        b /= nrm;
        double c = -(a * pts[i].x + b * pts[i].y);
        std::vector<int> in;
        for (int k = 0; k < n; k++)
            if (!taken[k] && std::fabs(a * pts[k].x + b * pts[k].y + c) < 1.5)
                in.push_back(k);
        if (in.size() > best.size())
            best.swap(in);
    }
    return best;
}

// Canny + two RANSAC lines + fitLine + the closed form; the distance found
// (NaN when there is no pair).
// noinline: a symbol of its own, for callgrind --toggle-collect
__attribute__((noinline)) double opencv_solve(const cv::Mat &img, const cdsp_camera &cam)
{
    cv::Mat edges;
    std::vector<cv::Point> pts;
    cv::Canny(img, edges, 50, 150, 3);
    cv::findNonZero(edges, pts);
    std::vector<char> taken(pts.size(), 0);
    cv::RNG rng(1);
    cdsp_real L[2][3];
    double cen[2][2];
    for (int l = 0; l < 2; l++) {
        std::vector<int> in = ransac_line(pts, taken, rng);
        if (in.size() < 10)
            return NAN;
        std::vector<cv::Point2f> sel;
        sel.reserve(in.size());
        for (int k : in) {
            taken[k] = 1;
            sel.emplace_back((float)pts[k].x, (float)pts[k].y);
        }
        cv::Vec4f f;
        cv::fitLine(sel, f, cv::DIST_L2, 0, 0.01, 0.01);
        // normal (-vy, vx) through (x0, y0)
        L[l][0] = (cdsp_real)-f[1];
        L[l][1] = (cdsp_real)f[0];
        L[l][2] = (cdsp_real)(f[1] * f[2] - f[0] * f[3]);
        cen[l][0] = f[2];
        cen[l][1] = f[3];
    }
    cdsp_real pin[2] = {(cdsp_real)((cen[0][0] + cen[1][0]) / 2), (cdsp_real)((cen[0][1] + cen[1][1]) / 2)};
    cdsp_result r;
    if (cdsp_axis_solve(&cam, L[0], L[1], pin, 8, &r) != CDSP_OK)
        return NAN;
    return (double)r.distance;
}

} // namespace

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    int reps = argc > 2 ? std::atoi(argv[2]) : 3;
    char path[4096];
    std::snprintf(path, sizeof path, "%s/frames.raw", dir);
    std::vector<unsigned char> frames((size_t)W * H * NFRAMES);
    FILE *f = std::fopen(path, "rb");
    if (!f || std::fread(frames.data(), 1, frames.size(), f) != frames.size()) {
        std::fprintf(stderr, "cv_baseline: cannot read %s (make bench-frame writes it)\n", path);
        if (f)
            std::fclose(f);
        return 2;
    }
    std::fclose(f);
    cv::setNumThreads(1); // one core, as libcdsp
    cdsp_camera cam;
    std::memset(&cam, 0, sizeof cam);
    cam.fx = cam.fy = (cdsp_real)(12.0 / 3.45e-3);
    cam.cx = (cdsp_real)((W - 1) / 2.0);
    cam.cy = (cdsp_real)((H - 1) / 2.0);
    cam.width = W;
    cam.height = H;
    cdsp_params prm;
    cdsp_params_default(&prm);
    static cdsp_frame_ws ws;
    std::vector<double> tcv, tlib;
    double dcv = NAN, dlib = NAN;
    for (int rep = 0; rep < reps; rep++)
        for (int i = 0; i < NFRAMES; i++) {
            unsigned char *px = frames.data() + (size_t)i * W * H;
            cv::Mat m(H, W, CV_8UC1, px);
            double t0 = now_ms();
            dcv = opencv_solve(m, cam);
            double t1 = now_ms();
            cdsp_image img = {px, W, H, (size_t)W, 8};
            cdsp_rng rng;
            cdsp_result r;
            cdsp_rng_seed(&rng, 1, 1);
            cdsp_status st = cdsp_frame_solve(&img, &cam, 8, &prm, nullptr, &ws, &rng, &r);
            double t2 = now_ms();
            dlib = st == CDSP_OK ? (double)r.distance : NAN;
            tcv.push_back(t1 - t0);
            tlib.push_back(t2 - t1);
        }
    double mc = median(tcv), ml = median(tlib);
    std::printf("side by side, same frames, same run, one core (%d frames x %d):\n", NFRAMES, reps);
    std::printf("  OpenCV (Canny + RANSAC pair + fitLine + closed form): %8.2f ms per frame (last distance %.1f mm)\n",
                mc, dcv);
    std::printf("  libcdsp cdsp_frame_solve, full search:                %8.2f ms per frame (last distance %.1f mm)\n",
                ml, dlib);
    std::printf("  ratio: %.1f x (target >= 50)\n", ml > 0 ? mc / ml : 0.0);
    return 0;
}
