// calib_output.hpp: what cdsp_calib writes: the ROS camera_info YAML, the
// per-image overlays and the corner-coverage picture.
#ifndef CDSP_CALIB_OUTPUT_HPP
#define CDSP_CALIB_OUTPUT_HPP

#include "calib_core.hpp"
#include "cdsp_host.h"

#include <cstdio>
#include <string>
#include <vector>

namespace calib {

// The ROS camera_info YAML (the layout ROS's camera_calibration writes,
// host/calib.c's writer), preceded by comment lines with the RMS error, the
// image count and the 1-sigma uncertainties. false, with why, when the
// camera is unusable or the stream's error flag is set (a failed write).
bool write_camera_info(std::FILE *f, const std::string &camera_name, cv::Size size,
                       const Result &res, bool full_model, int n_given, std::string &why);

// The image with its detected corners (green circles), the corners
// reprojected by the final calibration (red crosses) and a caption.
// false if the file could not be written.
bool write_overlay(const std::string &path, const cv::Mat &gray8, const View &v);

// Where the corners of the used views fell: grid cells with corners (gray)
// and without (dark red), every view's board outline and corners, and a
// caption with the coverage figures. false if the file could not be written.
bool write_coverage(const std::string &path, const std::vector<View> &views,
                    cv::Size size, const Coverage &cov);

} // namespace calib

#endif
