// The volume's marker cloud as ROS 2's sensor_msgs/PointCloud2 (/mocap/markers), and back: one
// row of markers, each point 32 bytes, little-endian, with the fields
//
//   x, y, z    float32  world frame, metres
//   body       int32    the index of the body or robot it belongs to (the order of the poses'
//                       names: the volume's bodies, then its robots), -1 when unlabeled
//   marker     uint16   its index in that body's markers (0 when unlabeled)
//   id         uint32   its track's id: the same marker from frame to frame
//   residual   float32  its reprojection error over the cameras that saw it (pixels)
//   cameras    uint32   a bit per camera that saw it (bit c: the fusion's camera c)
//
// so that RViz, Foxglove and any PointCloud2 reader draw it (x, y, z), and a tracker of its own
// reads the rest.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <std_msgs/msg/header.hpp>

namespace mocap {

struct LabeledMarker {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  int32_t body = -1;
  uint16_t marker = 0;
  uint32_t id = 0;
  float residual_px = 0;
  uint32_t cameras = 0;
};

// The cloud with `header` (frame 'world', the capture stamp).
sensor_msgs::msg::PointCloud2 to_point_cloud(const std_msgs::msg::Header& header,
                                             const std::vector<LabeledMarker>& markers);

// The markers of a cloud of these fields (any order, any point_step that holds them); nullopt
// and `problem` (naming the field) for a cloud without them or with data of the wrong size.
std::optional<std::vector<LabeledMarker>> markers_from_point_cloud(
    const sensor_msgs::msg::PointCloud2& cloud, std::string* problem = nullptr);

}  // namespace mocap
