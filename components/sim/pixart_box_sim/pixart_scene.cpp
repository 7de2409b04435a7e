#include "sim/pixart_box_sim/pixart_scene.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/spelling.hpp>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::pixart {
namespace {

using Keys = YamlKeys;

constexpr double kPi = 3.14159265358979323846;
// Far beyond any room, but finite: catches a misplaced exponent.
constexpr double kMaxCoordinate_m = 1000;
constexpr double kMaxTime_s = 1e6;

// Reads one scene document; every error names the source and the line of the node at fault.
class SceneReader : YamlReader<PixartSceneError> {
 public:
  SceneReader(std::string source, const Rig& rig) : YamlReader(std::move(source)), rig_(rig) {}

  PixartScene read(const YAML::Node& root) {
    if (!root.IsMap()) fail(root, "a scene is a map with 'robots' and/or 'calibration_boards'");
    check_keys(root, {"robots", "calibration_boards"}, "the scene");
    if (!root["robots"] && !root["calibration_boards"]) {
      fail(root, "a scene needs 'robots' or 'calibration_boards' (either may be an empty list)");
    }
    PixartScene scene;
    scene.source = source();
    for (const YAML::Node& node : list(root, "robots")) scene.objects.push_back(robot(node));
    for (const YAML::Node& node : list(root, "calibration_boards")) {
      scene.objects.push_back(board(node));
    }
    return scene;
  }

 private:
  SceneObject robot(const YAML::Node& map) {
    check_keys(map, {"name", "trajectory"}, "a robot");
    const YAML::Node name_node = required(map, "name", "a robot");
    SceneObject object;
    object.name = text(name_node, "name");
    object.kind = SceneObject::Kind::Robot;
    auto model = std::find_if(rig_.robots.begin(), rig_.robots.end(),
                              [&](const RobotModel& r) { return r.name == object.name; });
    if (model == rig_.robots.end()) {
      std::vector<std::string> known;
      for (const RobotModel& r : rig_.robots) known.push_back(r.name);
      fail(name_node, fmt::format("robot '{}' is not in the rig {}{}", object.name, rig_.source,
                                  did_you_mean(object.name, known, "robots")));
    }
    claim_name(name_node, object.name);
    object.leds = model->leds;
    object.height_m = rig_.led_plane_height_m;
    object.trajectory = trajectory(required(map, "trajectory", "a robot"));
    return object;
  }

  SceneObject board(const YAML::Node& map) {
    check_keys(map, {"name", "size_m", "on_s", "off_s", "pause_s", "height_m", "trajectory"},
               "a calibration board");
    const YAML::Node name_node = required(map, "name", "a calibration board");
    SceneObject object;
    object.name = text(name_node, "name");
    object.kind = SceneObject::Kind::CalibrationBoard;
    claim_name(name_node, object.name);
    const double size = positive(map, "size_m", 0.25, 10);
    const double on = positive(map, "on_s", 0.1, kMaxTime_s);
    const double off = number(map, "off_s", 0.1, 0, kMaxTime_s);
    const double pause = number(map, "pause_s", 0, 0, kMaxTime_s);
    object.leds = calibration_board_leds(size, on, off, pause);
    object.height_m = number(map, "height_m", rig_.led_plane_height_m, 0, kMaxCoordinate_m);
    object.trajectory = trajectory(required(map, "trajectory", "a calibration board"));
    return object;
  }

  FloorTrajectory trajectory(const YAML::Node& map) const {
    if (!map.IsMap()) fail(map, "'trajectory' must be a map with a 'type'");
    const YAML::Node type = required(map, "type", "a trajectory");
    const std::string name = type.IsScalar() ? type.Scalar() : std::string();
    if (name == "static") {
      check_keys(map, {"type", "x", "y", "theta_deg"}, "a static trajectory");
      StaticFloorTrajectory still;
      still.pose.x = coordinate(required(map, "x", "a static trajectory"), "x");
      still.pose.y = coordinate(required(map, "y", "a static trajectory"), "y");
      still.pose.theta = number(map, "theta_deg", 0, -360, 360) * kPi / 180;
      return still;
    }
    if (name == "circle") {
      check_keys(map, {"type", "centre", "radius_m", "period_s", "phase_deg", "clockwise"},
                 "a circle trajectory");
      CircleFloorTrajectory circle;
      circle.centre = point(required(map, "centre", "a circle trajectory"), "centre");
      circle.radius_m = number(map, "radius_m", circle.radius_m, 0, kMaxCoordinate_m);
      circle.period_s = positive(map, "period_s", circle.period_s, kMaxTime_s);
      circle.phase_deg = number(map, "phase_deg", circle.phase_deg, -360, 360);
      circle.clockwise = boolean(map, "clockwise", circle.clockwise);
      return circle;
    }
    if (name == "waypoints") {
      check_keys(map, {"type", "points", "speed_mps", "loop"}, "a waypoints trajectory");
      WaypointFloorTrajectory path;
      const YAML::Node points = required(map, "points", "a waypoints trajectory");
      if (!points.IsSequence() || points.size() < 2) {
        fail(points, fmt::format("'points' must be a list of at least two [x, y], not {}",
                                 describe(points)));
      }
      for (const YAML::Node& p : points) path.points.push_back(point(p, "points"));
      const bool moves = std::any_of(path.points.begin(), path.points.end(),
                                     [&](const Eigen::Vector2d& p) { return p != path.points[0]; });
      if (!moves) fail(points, "'points' are all the same point: the path has no length");
      path.speed_mps = positive(map, "speed_mps", path.speed_mps, 100);
      path.loop = boolean(map, "loop", path.loop);
      return path;
    }
    fail(type, fmt::format("trajectory type is {}, must be one of: static, circle, waypoints",
                           describe(type)));
  }

  // Every object's name is unique, so that ground truth and logs can name it.
  void claim_name(const YAML::Node& node, const std::string& name) {
    if (!names_.insert(name).second) fail(node, fmt::format("'{}' appears twice", name));
  }

  double coordinate(const YAML::Node& node, const char* key) const {
    return to_number(node, key, -kMaxCoordinate_m, kMaxCoordinate_m);
  }

  Eigen::Vector2d point(const YAML::Node& node, const char* key) const {
    if (!node.IsSequence() || node.size() != 2) {
      fail(node, fmt::format("'{}' needs [x, y] in metres, not {}", key, describe(node)));
    }
    return {coordinate(node[0], key), coordinate(node[1], key)};
  }

  const Rig& rig_;
  std::set<std::string> names_;
};

}  // namespace

std::vector<Led> calibration_board_leds(double size_m, double on_s, double off_s, double pause_s) {
  const double half = size_m / 2;
  const Eigen::Vector2d corners[] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  const double slot = on_s + off_s;  // one LED's turn: lit, then dark before the next
  const double cycle = 4 * slot + pause_s;
  std::vector<Led> leds;
  for (int i = 0; i < 4; ++i) {
    Led led;
    led.position = corners[i];
    led.on_s = on_s;
    led.off_s = cycle - on_s;
    // Led::is_on lights an LED while (t + phase) mod cycle < on_s: LED i starts at i·slot.
    led.phase_s = std::fmod(cycle - i * slot, cycle);
    leds.push_back(led);
  }
  return leds;
}

PixartScene parse_pixart_scene(const std::string& text, const std::string& source, const Rig& rig) {
  YAML::Node root = YamlReader<PixartSceneError>(source).parse(text);
  return SceneReader(source, rig).read(root);
}

PixartScene load_pixart_scene(const std::string& path, const Rig& rig) {
  std::ifstream stream(path);
  if (!stream) {
    throw PixartSceneError(
        fmt::format("{}: cannot read the scene: {}", path, std::strerror(errno)));
  }
  std::stringstream text;
  text << stream.rdbuf();
  return parse_pixart_scene(text.str(), path, rig);
}

}  // namespace mocap::pixart
