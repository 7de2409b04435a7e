// The debug picture of one frame: fiducials, identified lines with their names, pose axes.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::overlay {

struct OverlayLine {
  std::string name;
  std::array<Eigen::Vector2d, 4> pixels;
};

struct OverlayConstellation {
  std::string name;
  std::vector<OverlayLine> lines;
};

struct OverlayPose {
  std::string name;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
};

struct OverlayFrame {
  std::vector<Eigen::Vector2d> fiducials;
  std::vector<OverlayConstellation> constellations;
  std::vector<OverlayPose> poses;
};

// A BGR copy of `mono8` with the frame drawn on it: fiducials as yellow circles, identified
// lines in green with their names, constellation names, and each pose's axes (x red, y green,
// z blue, `axis_length_m` long) projected through `camera` (axes are skipped without one).
cv::Mat draw_overlay(const cv::Mat& mono8, const OverlayFrame& frame,
                     const calibration::CameraModel* camera, double axis_length_m = 0.1);

}  // namespace mocap::overlay
