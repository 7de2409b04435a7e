#include "common/marker_cloud_message/marker_cloud_message.hpp"

#include <array>
#include <cstring>

#include <fmt/format.h>

namespace mocap {
namespace {

using sensor_msgs::msg::PointField;

constexpr uint8_t kInt32 = 5, kUint16 = 4, kUint32 = 6, kFloat32 = 7;
constexpr uint32_t kPointStep = 32;

struct Field {
  const char* name;
  uint32_t offset;
  uint8_t datatype;
  uint32_t size;
};
constexpr std::array<Field, 8> kFields = {{{"x", 0, kFloat32, 4},
                                           {"y", 4, kFloat32, 4},
                                           {"z", 8, kFloat32, 4},
                                           {"body", 12, kInt32, 4},
                                           {"marker", 16, kUint16, 2},
                                           {"id", 20, kUint32, 4},
                                           {"residual", 24, kFloat32, 4},
                                           {"cameras", 28, kUint32, 4}}};

// The machine is little-endian (as the cloud says it is): values are copied byte for byte.
template <class T>
void put(std::vector<uint8_t>& data, size_t at, T value) {
  std::memcpy(data.data() + at, &value, sizeof(T));
}
template <class T>
T get(const std::vector<uint8_t>& data, size_t at) {
  T value;
  std::memcpy(&value, data.data() + at, sizeof(T));
  return value;
}

}  // namespace

sensor_msgs::msg::PointCloud2 to_point_cloud(const std_msgs::msg::Header& header,
                                             const std::vector<LabeledMarker>& markers) {
  sensor_msgs::msg::PointCloud2 cloud;
  cloud.header(header);
  cloud.height(1);
  cloud.width(static_cast<uint32_t>(markers.size()));
  for (const Field& field : kFields) {
    PointField point_field;
    point_field.name(field.name);
    point_field.offset(field.offset);
    point_field.datatype(field.datatype);
    point_field.count(1);
    cloud.fields().push_back(point_field);
  }
  cloud.is_bigendian(false);
  cloud.point_step(kPointStep);
  cloud.row_step(kPointStep * static_cast<uint32_t>(markers.size()));
  cloud.is_dense(true);
  std::vector<uint8_t>& data = cloud.data();
  data.assign(markers.size() * kPointStep, 0);
  for (size_t i = 0; i < markers.size(); ++i) {
    const LabeledMarker& marker = markers[i];
    const size_t at = i * kPointStep;
    put(data, at + 0, marker.position.x());
    put(data, at + 4, marker.position.y());
    put(data, at + 8, marker.position.z());
    put(data, at + 12, marker.body);
    put(data, at + 16, marker.marker);
    put(data, at + 20, marker.id);
    put(data, at + 24, marker.residual_px);
    put(data, at + 28, marker.cameras);
  }
  return cloud;
}

std::optional<std::vector<LabeledMarker>> markers_from_point_cloud(
    const sensor_msgs::msg::PointCloud2& cloud, std::string* problem) {
  auto fail = [&](std::string why) -> std::optional<std::vector<LabeledMarker>> {
    if (problem) *problem = std::move(why);
    return std::nullopt;
  };
  if (cloud.is_bigendian()) return fail("is_bigendian: a big-endian cloud");
  std::array<uint32_t, kFields.size()> offsets{};
  for (size_t f = 0; f < kFields.size(); ++f) {
    const Field& wanted = kFields[f];
    bool found = false;
    for (const PointField& field : cloud.fields()) {
      if (field.name() != wanted.name) continue;
      if (field.datatype() != wanted.datatype || field.count() != 1) {
        return fail(fmt::format("fields: '{}' has datatype {} x {}, not {} x 1", wanted.name,
                                field.datatype(), field.count(), wanted.datatype));
      }
      if (field.offset() + wanted.size > cloud.point_step()) {
        return fail(fmt::format("fields: '{}' at offset {} does not fit point_step {}", wanted.name,
                                field.offset(), cloud.point_step()));
      }
      offsets[f] = field.offset();
      found = true;
    }
    if (!found) return fail(fmt::format("fields: no '{}'", wanted.name));
  }
  const size_t points = static_cast<size_t>(cloud.width()) * cloud.height();
  if (cloud.row_step() != cloud.point_step() * cloud.width() ||
      cloud.data().size() != static_cast<size_t>(cloud.row_step()) * cloud.height()) {
    return fail(fmt::format("data: {} bytes, not {} points of {} bytes", cloud.data().size(),
                            points, cloud.point_step()));
  }
  std::vector<LabeledMarker> markers(points);
  const std::vector<uint8_t>& data = cloud.data();
  for (size_t i = 0; i < points; ++i) {
    const size_t at = i * cloud.point_step();
    LabeledMarker& marker = markers[i];
    marker.position = {get<float>(data, at + offsets[0]), get<float>(data, at + offsets[1]),
                       get<float>(data, at + offsets[2])};
    marker.body = get<int32_t>(data, at + offsets[3]);
    marker.marker = get<uint16_t>(data, at + offsets[4]);
    marker.id = get<uint32_t>(data, at + offsets[5]);
    marker.residual_px = get<float>(data, at + offsets[6]);
    marker.cameras = get<uint32_t>(data, at + offsets[7]);
  }
  return markers;
}

}  // namespace mocap
