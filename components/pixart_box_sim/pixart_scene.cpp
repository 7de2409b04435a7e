#include "pixart_scene.hpp"

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

namespace mocap::pixart {
namespace {

using Keys = std::initializer_list<std::string_view>;

constexpr double kPi = 3.14159265358979323846;
// Far beyond any room, but finite: catches a misplaced exponent.
constexpr double kMaxCoordinate_m = 1000;
constexpr double kMaxTime_s = 1e6;

// Reads one scene document; every error names the source and the line of the node at fault.
class SceneReader {
 public:
  SceneReader(std::string source, const Rig& rig) : source_(std::move(source)), rig_(rig) {}

  PixartScene read(const YAML::Node& root) {
    if (!root.IsMap()) fail(root, "a scene is a map with 'robots' and/or 'calibration_boards'");
    check_keys(root, {"robots", "calibration_boards"}, "the scene");
    if (!root["robots"] && !root["calibration_boards"]) {
      fail(root, "a scene needs 'robots' or 'calibration_boards' (either may be an empty list)");
    }
    PixartScene scene;
    scene.source = source_;
    for (const YAML::Node& node : list(root, "robots")) scene.objects.push_back(robot(node));
    for (const YAML::Node& node : list(root, "calibration_boards")) {
      scene.objects.push_back(board(node));
    }
    return scene;
  }

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    std::string where = source_;
    if (node.IsDefined() && node.Mark().line >= 0) {
      where += ":" + std::to_string(node.Mark().line + 1);
    }
    throw PixartSceneError(where + ": " + what);
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
    check_keys(map, {"name", "size_m", "on_s", "off_s", "height_m", "trajectory"},
               "a calibration board");
    const YAML::Node name_node = required(map, "name", "a calibration board");
    SceneObject object;
    object.name = text(name_node, "name");
    object.kind = SceneObject::Kind::CalibrationBoard;
    claim_name(name_node, object.name);
    const double size = positive(map, "size_m", 0.25, 10);
    const double on = positive(map, "on_s", 0.1, kMaxTime_s);
    const double off = number(map, "off_s", 0.1, 0, kMaxTime_s);
    object.leds = calibration_board_leds(size, on, off);
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

  // The list under `key`, or an empty one when the key is absent.
  YAML::Node list(const YAML::Node& map, const char* key) const {
    YAML::Node node = map[key];
    if (!node) return YAML::Node(YAML::NodeType::Sequence);
    if (!node.IsSequence())
      fail(node, fmt::format("'{}' must be a list, not {}", key, describe(node)));
    return node;
  }

  // Rejects keys outside `allowed` and repeated keys, suggesting the nearest allowed key.
  void check_keys(const YAML::Node& map, Keys allowed, std::string_view what) const {
    if (!map.IsMap()) fail(map, fmt::format("{} must be a map, not {}", what, describe(map)));
    std::set<std::string> seen;
    for (const auto& entry : map) {
      const YAML::Node& key = entry.first;
      std::string name = key.IsScalar() ? key.Scalar() : std::string("(not a word)");
      if (!seen.insert(name).second) fail(key, fmt::format("'{}' appears twice in {}", name, what));
      if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
      fail(key, fmt::format("unknown key '{}' in {}{}", name, what,
                            did_you_mean(name, {allowed.begin(), allowed.end()}, "keys")));
    }
  }

  YAML::Node required(const YAML::Node& map, const char* key, std::string_view what) const {
    YAML::Node node = map[key];
    if (!node) fail(map, fmt::format("{} needs '{}'", what, key));
    return node;
  }

  std::string text(const YAML::Node& node, const char* key) const {
    if (!node.IsScalar() || node.Scalar().empty()) {
      fail(node, fmt::format("'{}' must be a non-empty name, not {}", key, describe(node)));
    }
    return node.Scalar();
  }

  double to_number(const YAML::Node& node, const char* key, double min, double max) const {
    double value = 0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
      fail(node, fmt::format("'{}' must be a number, not {}", key, describe(node)));
    }
    if (value < min || value > max) {
      fail(node, fmt::format("'{}' is {}, must be in [{}, {}]", key, value, min, max));
    }
    return value;
  }

  double number(const YAML::Node& map, const char* key, double fallback, double min,
                double max) const {
    YAML::Node node = map[key];
    return node ? to_number(node, key, min, max) : fallback;
  }

  // A number above 0 and up to `max` (periods, speeds, sizes).
  double positive(const YAML::Node& map, const char* key, double fallback, double max) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    double value = to_number(node, key, -max, max);
    if (!(value > 0)) fail(node, fmt::format("'{}' is {}, must be positive", key, value));
    return value;
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

  bool boolean(const YAML::Node& map, const char* key, bool fallback) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
      fail(node, fmt::format("'{}' must be true or false, not {}", key, describe(node)));
    }
    return value;
  }

  static std::string describe(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + node.Scalar() + "'";
    if (node.IsSequence()) return fmt::format("a list of {}", node.size());
    if (node.IsMap()) return "a map";
    return "nothing";
  }

  std::string source_;
  const Rig& rig_;
  std::set<std::string> names_;
};

}  // namespace

std::vector<Led> calibration_board_leds(double size_m, double on_s, double off_s) {
  const double half = size_m / 2;
  const Eigen::Vector2d corners[] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  const double slot = on_s + off_s;  // one LED's turn: lit, then dark before the next
  const double cycle = 4 * slot;
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
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw PixartSceneError(fmt::format("{}:{}: {}", source, e.mark.line + 1, e.msg));
  }
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
