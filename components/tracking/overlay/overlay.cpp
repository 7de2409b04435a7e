#include "tracking/overlay/overlay.hpp"

#include <opencv2/imgproc.hpp>

namespace mocap::overlay {
namespace {

cv::Point2f to_cv(const Eigen::Vector2d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y())};
}

// Sub-pixel drawing: OpenCV takes fixed-point coordinates with `shift` fractional bits.
constexpr int kShift = 4;
cv::Point fixed(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * (1 << kShift))),
          static_cast<int>(std::lround(p.y() * (1 << kShift)))};
}

}  // namespace

cv::Mat draw_overlay(const cv::Mat& mono8, const OverlayFrame& frame,
                     const calibration::CameraModel* camera, double axis_length_m) {
  cv::Mat image;
  cv::cvtColor(mono8, image, cv::COLOR_GRAY2BGR);
  const cv::Scalar yellow(0, 220, 255), green(0, 200, 0), white(255, 255, 255);
  for (const auto& p : frame.fiducials) {
    if (!p.allFinite()) continue;
    cv::circle(image, fixed(p), 6 << kShift, yellow, 1, cv::LINE_AA, kShift);
  }
  for (const auto& constellation : frame.constellations) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    int count = 0;
    for (const auto& line : constellation.lines) {
      // From its first marker seen to its last: a marker not seen (hidden, out of the
      // picture) is NaN.
      const Eigen::Vector2d* first = nullptr;
      const Eigen::Vector2d* last = nullptr;
      for (const auto& p : line.pixels) {
        if (!p.allFinite()) continue;
        if (first == nullptr) first = &p;
        last = &p;
        centre += p;
        ++count;
      }
      if (first == nullptr || first == last) continue;
      cv::line(image, fixed(*first), fixed(*last), green, 1, cv::LINE_AA, kShift);
      const Eigen::Vector2d middle = (*first + *last) / 2;
      cv::putText(image, line.name, to_cv(middle + Eigen::Vector2d(4, -4)),
                  cv::FONT_HERSHEY_SIMPLEX, 0.4, green, 1, cv::LINE_AA);
    }
    if (count > 0) {
      cv::putText(image, constellation.name, to_cv(centre / count), cv::FONT_HERSHEY_SIMPLEX, 0.6,
                  white, 1, cv::LINE_AA);
    }
  }
  if (camera == nullptr) return image;
  const std::array<cv::Scalar, 3> colours = {cv::Scalar(0, 0, 255), cv::Scalar(0, 255, 0),
                                             cv::Scalar(255, 0, 0)};
  for (const auto& pose : frame.poses) {
    auto origin = camera->project(pose.camera_from_object.translation());
    if (!origin) continue;
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d tip = pose.camera_from_object * (axis_length_m * Eigen::Vector3d::Unit(axis));
      if (auto end = camera->project(tip)) {
        cv::line(image, fixed(*origin), fixed(*end), colours[axis], 2, cv::LINE_AA, kShift);
      }
    }
  }
  return image;
}

}  // namespace mocap::overlay
