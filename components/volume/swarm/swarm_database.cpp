#include "volume/swarm/swarm_database.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::volume {
namespace {

using Reader = YamlReader<RigidBodyError>;

MarkerLayout read_layout(const Reader& reader, const YAML::Node& node,
                         const std::vector<MarkerLayout>& earlier, double tolerance) {
  reader.check_keys(node, {"name", "markers", "top_speed_mps"}, "a layout");
  MarkerLayout layout;
  layout.name = reader.text(reader.required(node, "name", "a layout"), "name");
  for (const MarkerLayout& other : earlier) {
    if (other.name == layout.name) {
      reader.fail(node["name"], fmt::format("layout '{}' is declared twice", layout.name));
    }
  }
  const YAML::Node markers =
      reader.required(node, "markers", fmt::format("layout '{}'", layout.name));
  if (!markers.IsSequence() || markers.size() == 0 || markers.size() == 2) {
    reader.fail(markers, fmt::format("layout '{}' needs 1 marker, or 3 or more, not {}: two "
                                     "markers leave the turn about their line unknown",
                                     layout.name, Reader::describe(markers)));
  }
  for (const YAML::Node& marker : markers) {
    const Eigen::Vector3d position = reader.vector<3>(marker, "markers", -100, 100);
    for (size_t i = 0; i < layout.markers.size(); ++i) {
      if ((layout.markers[i] - position).norm() < kMinMarkerSeparation) {
        reader.fail(marker,
                    fmt::format("layout '{}': marker {} is within {} m of marker {}", layout.name,
                                layout.markers.size(), kMinMarkerSeparation, i));
      }
    }
    layout.markers.push_back(position);
  }
  layout.top_speed_mps = reader.positive(node, "top_speed_mps", layout.top_speed_mps, 1000);
  if (layout.markers.size() >= 3) {
    const RigidBody body{layout.name, layout.markers};
    if (auto turned = marker_confusion(body, body, body.markers.size(), tolerance, true)) {
      reader.fail(markers,
                  fmt::format("layout '{}' is symmetric: a rotation takes its markers {} to "
                              "its markers {} (within {} m), so its orientation is ambiguous; "
                              "move a marker",
                              layout.name, fmt::join(turned->first, ", "),
                              fmt::join(turned->second, ", "), 2 * tolerance));
    }
  }
  return layout;
}

SwarmDatabase read_swarm(const Reader& reader, const YAML::Node& root, double tolerance) {
  reader.check_keys(root, {"layouts", "robots"}, "the file");
  SwarmDatabase swarm;
  for (const YAML::Node& node : reader.list(root, "layouts")) {
    swarm.layouts.push_back(read_layout(reader, node, swarm.layouts, tolerance));
  }
  const YAML::Node robots = reader.list(root, "robots");
  for (const YAML::Node& node : robots) {
    reader.check_keys(node, {"name", "layout", "initial_position", "streaming_id"}, "a robot");
    SwarmRobot robot;
    robot.name = reader.text(reader.required(node, "name", "a robot"), "name");
    const std::string what = fmt::format("robot '{}'", robot.name);
    const std::string layout = reader.text(reader.required(node, "layout", what), "layout");
    const auto found =
        std::find_if(swarm.layouts.begin(), swarm.layouts.end(),
                     [&](const MarkerLayout& candidate) { return candidate.name == layout; });
    if (found == swarm.layouts.end()) {
      reader.fail(node["layout"], fmt::format("{}: no layout '{}' in the file", what, layout));
    }
    robot.layout = static_cast<size_t>(found - swarm.layouts.begin());
    robot.initial_position = reader.vector<3>(reader.required(node, "initial_position", what),
                                              "initial_position", -1000, 1000);
    if (node["streaming_id"]) {
      robot.streaming_id = static_cast<int32_t>(
          reader.to_integer(node["streaming_id"], "streaming_id", 1, kMaxStreamingId));
    }
    for (size_t other = 0; other < swarm.robots.size(); ++other) {
      const SwarmRobot& earlier = swarm.robots[other];
      if (earlier.name == robot.name) {
        reader.fail(node["name"], fmt::format("robot '{}' is declared twice", robot.name));
      }
      if (robot.streaming_id && earlier.streaming_id == robot.streaming_id) {
        reader.fail(node["streaming_id"],
                    fmt::format("robots '{}' and '{}' have streaming_id {}", earlier.name,
                                robot.name, *robot.streaming_id));
      }
      const double apart = (earlier.initial_position - robot.initial_position).norm();
      if (earlier.layout == robot.layout && apart < found->size_m()) {
        reader.fail(node["initial_position"],
                    fmt::format("robots '{}' and '{}' (line {}) of layout '{}' start {:.3f} m "
                                "apart, closer than the layout's size ({:.3f} m): which is "
                                "which could not be told",
                                earlier.name, robot.name, Reader::line_of(robots[other]), layout,
                                apart, found->size_m()));
      }
    }
    swarm.robots.push_back(robot);
  }
  return swarm;
}

}  // namespace

double MarkerLayout::size_m() const {
  double widest = 0;
  for (size_t a = 0; a < markers.size(); ++a) {
    for (size_t b = a + 1; b < markers.size(); ++b) {
      widest = std::max(widest, (markers[a] - markers[b]).norm());
    }
  }
  return markers.size() < 2 ? kMinMarkerSeparation : widest;
}

SwarmDatabase parse_swarm(const std::string& text, const std::string& source, double tolerance) {
  const Reader reader(source);
  return read_swarm(reader, reader.parse(text), tolerance);
}

SwarmDatabase load_swarm(const std::string& path, double tolerance) {
  const Reader reader(path);
  return read_swarm(reader, reader.load(), tolerance);
}

}  // namespace mocap::volume
