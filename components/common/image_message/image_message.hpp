// sensor_msgs/Image <-> cv::Mat for the image components. Only mono8 is read: cameras convert
// to it (camera_source), so each consumer handles one layout.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>
#include <sensor_msgs/msg/image.hpp>

namespace mocap {

// A mono8 view of `image`'s pixels (no copy; valid while `image` lives), or the reason it
// cannot be read: another encoding, a zero size, a step shorter than a row, or less data
// than height x step.
struct Mono8View {
  cv::Mat pixels;
  std::string problem;  // empty when pixels is valid
};
Mono8View view_mono8(const sensor_msgs::msg::Image& image);

// Copies a CV_8UC1 matrix into an Image message (encoding mono8, step = width); the header
// is the caller's.
void fill_image_message(const cv::Mat& mono8, sensor_msgs::msg::Image& message);

}  // namespace mocap
