#include "sim/swarm_scene/swarm_scene_file.hpp"

#include <algorithm>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::synthetic {
namespace {

using Reader = YamlReader<SwarmSceneError>;

std::vector<Eigen::Vector3d> read_markers(const Reader& reader, const YAML::Node& node,
                                          const std::string& name) {
  const YAML::Node markers = reader.required(node, "markers", fmt::format("layout '{}'", name));
  if (!markers.IsSequence() || markers.size() == 0) {
    reader.fail(markers,
                fmt::format("layout '{}' needs markers, not {}", name, Reader::describe(markers)));
  }
  std::vector<Eigen::Vector3d> points;
  for (const YAML::Node& marker : markers) {
    points.push_back(reader.vector<3>(marker, "markers", -100, 100));
  }
  return points;
}

SwarmScene read_group(const Reader& reader, const YAML::Node& node,
                      const std::map<std::string, std::vector<Eigen::Vector3d>>& layouts,
                      double duration_s) {
  const std::string flight = reader.text(reader.required(node, "flight", "a group"), "flight");
  const std::string layout_name = reader.text(reader.required(node, "layout", "a group"), "layout");
  const auto layout = layouts.find(layout_name);
  if (layout == layouts.end()) {
    reader.fail(node["layout"], fmt::format("no layout '{}' in the file", layout_name));
  }
  const std::string prefix = node["prefix"] ? reader.text(node["prefix"], "prefix") : "robot_";
  const std::vector<Eigen::Vector3d>& markers = layout->second;
  auto count = [&](const char* key) {
    reader.required(node, key, flight);
    return static_cast<int>(reader.integer(node, key, 1, 1, 10000));
  };
  auto positive = [&](const char* key) {
    reader.required(node, key, flight);
    return reader.positive(node, key, 1, 1000);
  };
  auto number = [&](const char* key) {
    reader.required(node, key, flight);
    return reader.number(node, key, 0, -1000, 1000);
  };
  SwarmScene scene;
  try {
    if (flight == "takeoff_grid") {
      reader.check_keys(node,
                        {"flight", "layout", "prefix", "offset", "rows", "columns", "spacing_m",
                         "height_m", "climb_s"},
                        "a takeoff_grid group");
      scene = takeoff_grid(markers, count("rows"), count("columns"), positive("spacing_m"),
                           positive("height_m"), positive("climb_s"), duration_s, prefix);
    } else if (flight == "formation_circle") {
      reader.check_keys(
          node,
          {"flight", "layout", "prefix", "offset", "count", "radius_m", "height_m", "rate_rad_s"},
          "a formation_circle group");
      scene = formation_circle(markers, count("count"), positive("radius_m"), positive("height_m"),
                               number("rate_rad_s"), duration_s, prefix);
    } else if (flight == "crossing_pairs") {
      reader.check_keys(node,
                        {"flight", "layout", "prefix", "offset", "pairs", "separation_m",
                         "speed_mps", "pair_spacing_m", "height_m"},
                        "a crossing_pairs group");
      scene =
          crossing_pairs(markers, count("pairs"), positive("separation_m"), positive("speed_mps"),
                         positive("pair_spacing_m"), positive("height_m"), duration_s, prefix);
    } else if (flight == "place_exchange") {
      reader.check_keys(node,
                        {"flight", "layout", "prefix", "offset", "centre", "distance_m",
                         "separation_m", "over_s", "period_s"},
                        "a place_exchange group");
      const double over_s = positive("over_s"), period_s = positive("period_s");
      if (over_s > period_s) {
        reader.fail(node["over_s"],
                    fmt::format("over_s {} is longer than period_s {}", over_s, period_s));
      }
      scene = place_exchange(
          markers, reader.vector<3>(reader.required(node, "centre", flight), "centre", -1000, 1000),
          positive("distance_m"), positive("separation_m"), over_s, period_s, duration_s, prefix);
    } else if (flight == "random_flight") {
      reader.check_keys(node,
                        {"flight", "layout", "prefix", "offset", "count", "extent_m", "height_m",
                         "min_separation_m", "seed"},
                        "a random_flight group");
      scene = random_flight(markers, count("count"), positive("extent_m"), positive("height_m"),
                            positive("min_separation_m"), duration_s,
                            static_cast<uint64_t>(reader.integer(node, "seed", 1, 0, INT64_MAX)),
                            prefix);
    } else {
      reader.fail(node["flight"],
                  fmt::format("unknown flight '{}': one of takeoff_grid, formation_circle, "
                              "crossing_pairs, place_exchange, random_flight",
                              flight));
    }
  } catch (const std::invalid_argument& e) {
    reader.fail(node, e.what());  // a builder's own check (random_flight's room)
  }
  if (node["offset"]) {
    scene = scene.shifted(reader.vector<3>(node["offset"], "offset", -1000, 1000));
  }
  for (SwarmSceneRobot& robot : scene.robots) robot.layout = layout_name;
  return scene;
}

SwarmScene read_scene(const Reader& reader, const YAML::Node& root) {
  reader.check_keys(root, {"duration_s", "hold_s", "layouts", "groups", "occluders"}, "the file");
  const double duration_s = reader.positive(root, "duration_s", 60, 1e6);
  std::map<std::string, std::vector<Eigen::Vector3d>> layouts;
  for (const YAML::Node& node : reader.list(root, "layouts")) {
    reader.check_keys(node, {"name", "markers"}, "a layout");
    const std::string name = reader.text(reader.required(node, "name", "a layout"), "name");
    if (layouts.count(name) > 0) {
      reader.fail(node["name"], fmt::format("layout '{}' is declared twice", name));
    }
    layouts[name] = read_markers(reader, node, name);
  }
  SwarmScene scene;
  scene.duration_s = duration_s;
  const YAML::Node groups = reader.list(root, "groups");
  if (groups.size() == 0) reader.fail(root, "the file needs 'groups' of robots");
  for (const YAML::Node& node : groups) {
    const SwarmScene group = read_group(reader, node, layouts, duration_s);
    for (const SwarmSceneRobot& robot : group.robots) {
      if (std::any_of(scene.robots.begin(), scene.robots.end(),
                      [&](const SwarmSceneRobot& r) { return r.name == robot.name; })) {
        reader.fail(node, fmt::format("robot '{}' is named twice: give the group its own prefix",
                                      robot.name));
      }
    }
    scene = scene.with(group);
  }
  scene.hold_s = reader.number(root, "hold_s", 0, 0, 3600);
  if (root["occluders"]) {
    for (const YAML::Node& node : reader.list(root, "occluders")) {
      reader.check_keys(node, {"centre", "radius_m"}, "an occluder");
      OccludingSphere occluder;
      occluder.centre =
          reader.vector<3>(reader.required(node, "centre", "an occluder"), "centre", -1000, 1000);
      reader.required(node, "radius_m", "an occluder");
      occluder.radius_m = reader.positive(node, "radius_m", 0, 100);
      scene.occluders.push_back(occluder);
    }
  }
  return scene;
}

}  // namespace

SwarmScene parse_swarm_scene(const std::string& text, const std::string& source) {
  const Reader reader(source);
  return read_scene(reader, reader.parse(text));
}

SwarmScene load_swarm_scene(const std::string& path) {
  const Reader reader(path);
  return read_scene(reader, reader.load());
}

std::string robots_file_of(const SwarmScene& scene, double top_speed_mps) {
  std::string text = "layouts:\n";
  std::vector<std::string> written;
  for (const SwarmSceneRobot& robot : scene.robots) {
    if (std::find(written.begin(), written.end(), robot.layout) != written.end()) continue;
    written.push_back(robot.layout);
    text += fmt::format("  - name: {}\n    markers: [", robot.layout);
    for (size_t m = 0; m < robot.markers.size(); ++m) {
      const Eigen::Vector3d& p = robot.markers[m];
      text += fmt::format("{}[{}, {}, {}]", m == 0 ? "" : ", ", p.x(), p.y(), p.z());
    }
    text += fmt::format("]\n    top_speed_mps: {}\n", top_speed_mps);
  }
  text += "robots:\n";
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    const Eigen::Vector3d at = scene.pose(r, 0).translation();
    text +=
        fmt::format("  - {{name: {}, layout: {}, initial_position: [{:.6f}, {:.6f}, {:.6f}]}}\n",
                    scene.robots[r].name, scene.robots[r].layout, at.x(), at.y(), at.z());
  }
  return text;
}

}  // namespace mocap::synthetic
