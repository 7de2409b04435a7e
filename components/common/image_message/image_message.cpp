#include "common/image_message/image_message.hpp"

#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {

Mono8View view_mono8(const sensor_msgs::msg::Image& image) {
  Mono8View view;
  if (image.encoding() != "mono8" && image.encoding() != "8UC1") {
    view.problem = fmt::format("encoding '{}' is not supported (mono8)", image.encoding());
  } else if (image.width() == 0 || image.height() == 0) {
    view.problem = fmt::format("the image is empty ({}x{})", image.width(), image.height());
  } else if (image.step() < image.width()) {
    view.problem =
        fmt::format("step {} is shorter than a row of {} pixels", image.step(), image.width());
  } else if (image.data().size() < static_cast<size_t>(image.step()) * image.height()) {
    view.problem = fmt::format("{} bytes of data, a {}x{} image with step {} needs {}",
                               image.data().size(), image.width(), image.height(), image.step(),
                               static_cast<size_t>(image.step()) * image.height());
  } else if (image.width() > 1u << 16 || image.height() > 1u << 16) {
    view.problem =
        fmt::format("{}x{} is larger than 65536 pixels a side", image.width(), image.height());
  } else {
    // cv::Mat does not write through a const view, but its constructor takes void*.
    view.pixels = cv::Mat(static_cast<int>(image.height()), static_cast<int>(image.width()),
                          CV_8UC1, const_cast<uint8_t*>(image.data().data()), image.step());
  }
  return view;
}

void fill_image_message(const cv::Mat& mono8, sensor_msgs::msg::Image& message) {
  if (mono8.type() != CV_8UC1) throw std::invalid_argument("fill_image_message: not CV_8UC1");
  message.width(static_cast<uint32_t>(mono8.cols));
  message.height(static_cast<uint32_t>(mono8.rows));
  message.encoding("mono8");
  message.is_bigendian(0);
  message.step(static_cast<uint32_t>(mono8.cols));
  std::vector<uint8_t>& data = message.data();
  data.resize(static_cast<size_t>(mono8.cols) * mono8.rows);
  for (int row = 0; row < mono8.rows; ++row) {
    std::memcpy(data.data() + static_cast<size_t>(row) * mono8.cols, mono8.ptr(row),
                static_cast<size_t>(mono8.cols));
  }
}

}  // namespace mocap
