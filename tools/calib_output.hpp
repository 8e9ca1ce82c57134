// calib_output.hpp: what cdsp_calib writes: the ROS camera_info YAML, the
// per-image overlays and the corner-coverage picture.
#ifndef CDSP_CALIB_OUTPUT_HPP
#define CDSP_CALIB_OUTPUT_HPP

#include "calib_core.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace calib {

// A double in the shortest "%.{15,16,17}g" form that reads back to the same
// value, always with a '.' in the mantissa so YAML 1.1 readers (PyYAML,
// ROS's camera_info_manager_py) see a float: "0.0", "1.5e-05".
std::string format_real(double x);

// The ROS camera_info YAML (the layout ROS's camera_calibration writes),
// preceded by comment lines with the RMS error and the image count.
// A failed write shows in ferror(f).
void write_camera_info(std::FILE *f, const std::string &camera_name,
                       cv::Size size, const Result &res, bool full_model,
                       int n_given);

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
