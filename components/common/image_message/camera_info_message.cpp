#include "common/image_message/camera_info_message.hpp"

#include <mocap/calibration/pinhole_camera.hpp>

namespace mocap {

std::optional<sensor_msgs::msg::CameraInfo> camera_info_message(
    const calibration::CameraModel& model) {
  const auto* pinhole = dynamic_cast<const calibration::PinholeCamera*>(&model);
  if (pinhole == nullptr) return std::nullopt;
  const calibration::PinholeIntrinsics& in = pinhole->intrinsics();
  sensor_msgs::msg::CameraInfo info;
  info.width(static_cast<uint32_t>(model.width()));
  info.height(static_cast<uint32_t>(model.height()));
  info.distortion_model("plumb_bob");
  info.d(std::vector<double>(in.distortion.begin(), in.distortion.end()));
  info.k({in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1});
  info.r({1, 0, 0, 0, 1, 0, 0, 0, 1});
  info.p({in.fx, 0, in.cx, 0, 0, in.fy, in.cy, 0, 0, 0, 1, 0});
  return info;
}

}  // namespace mocap
