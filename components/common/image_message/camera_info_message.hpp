// sensor_msgs/CameraInfo from a camera model, for the cameras that publish it beside their
// images: viewers project 3-D points (a pose's axes) into the image with it.
#pragma once

#include <optional>

#include <mocap/calibration/camera_model.hpp>
#include <sensor_msgs/msg/camera_info.hpp>

namespace mocap {

// A pinhole camera as camera_info describes it: plumb_bob distortion (k1, k2, p1, p2, k3), the
// identity rectification and the projection matrix [K | 0]; the header is the caller's.
// nullopt for a model camera_info has no words for (EUCM).
std::optional<sensor_msgs::msg::CameraInfo> camera_info_message(
    const calibration::CameraModel& model);

}  // namespace mocap
