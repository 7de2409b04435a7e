#include "pixart/pixart_rig/pixart_rig.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/pinhole_camera.hpp>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::pixart {
namespace {

using Reader = YamlReader<RigError>;

}  // namespace

bool Led::is_on(double time_s) const {
  if (off_s <= 0) return true;
  double period = on_s + off_s;
  double t = std::fmod(time_s + phase_s, period);
  if (t < 0) t += period;
  return t < on_s;
}

const RigCamera* Rig::find_camera(int camera_id) const {
  for (const RigCamera& camera : cameras) {
    if (camera.camera_id == camera_id) return &camera;
  }
  return nullptr;
}

std::shared_ptr<const calibration::CameraModel> nominal_pixart_camera(double horizontal_fov_deg) {
  calibration::PinholeIntrinsics k;
  k.fx = k.fy = 512.0 / std::tan(horizontal_fov_deg * M_PI / 360.0);
  k.cx = 511.5;
  k.cy = 383.5;
  return std::make_shared<calibration::PinholeCamera>(1024, 768, k);
}

Eigen::Isometry3d downward_camera_pose(const Eigen::Vector3d& position, double yaw_deg) {
  // Looking down: camera z = world −z; camera x = world x turned by yaw; camera y = z × x.
  double yaw = yaw_deg * M_PI / 180.0;
  Eigen::Vector3d x(std::cos(yaw), std::sin(yaw), 0), z(0, 0, -1);
  Eigen::Matrix3d rotation;
  rotation.col(0) = x;
  rotation.col(1) = z.cross(x);
  rotation.col(2) = z;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = position;
  return pose;
}

std::optional<Eigen::Vector2d> pixel_to_plane(const RigCamera& camera, const Eigen::Vector2d& pixel,
                                              double height) {
  auto ray = camera.model->unproject(pixel);
  if (!ray) return std::nullopt;
  Eigen::Vector3d origin = camera.world_from_camera.translation();
  Eigen::Vector3d direction = camera.world_from_camera.linear() * *ray;
  if (std::abs(direction.z()) < 1e-12) return std::nullopt;
  double t = (height - origin.z()) / direction.z();
  if (!(t > 0)) return std::nullopt;
  return (origin + t * direction).head<2>();
}

Rig parse_rig(const std::string& text, const std::string& source,
              const std::string& base_directory) {
  Reader reader(source);
  YAML::Node root = reader.parse(text);
  reader.check_keys(root, {"led_plane_height_m", "cameras", "robots"}, "the rig");
  Rig rig;
  rig.source = source;
  rig.led_plane_height_m = reader.number(root, "led_plane_height_m", 0.45, 0, 100);
  YAML::Node cameras = reader.list(root, "cameras");
  if (cameras.size() == 0) reader.fail(root, "'cameras' must be a non-empty list");
  std::set<int> ids;
  std::set<std::string> names;
  for (const YAML::Node& node : cameras) {
    reader.check_keys(
        node, {"name", "camera_id", "position", "yaw_deg", "camera_file", "horizontal_fov_deg"},
        "a camera");
    RigCamera camera;
    camera.name = reader.text(reader.required(node, "name", "a camera"), "name");
    camera.camera_id = static_cast<int>(
        reader.to_number(reader.required(node, "camera_id", "a camera"), "camera_id", 0, 1023));
    if (!ids.insert(camera.camera_id).second || !names.insert(camera.name).second) {
      reader.fail(node, fmt::format("camera '{}' (id {}) repeats a name or id", camera.name,
                                    camera.camera_id));
    }
    std::optional<Eigen::Isometry3d> calibrated_pose;
    if (node["camera_file"]) {
      std::filesystem::path file = reader.text(node["camera_file"], "camera_file");
      if (file.is_relative()) file = std::filesystem::path(base_directory) / file;
      try {
        calibration::CameraFile camera_file = calibration::load_camera_file(file.string());
        camera.model = camera_file.model;
        calibrated_pose = camera_file.world_from_camera;
      } catch (const calibration::CameraFileError& e) {
        reader.fail(node["camera_file"], e.what());
      }
    } else {
      camera.model = nominal_pixart_camera(reader.number(node, "horizontal_fov_deg", 41, 1, 179));
    }
    if (calibrated_pose) {
      // Two poses for one camera would leave it to chance which one the rig uses.
      for (const char* key : {"position", "yaw_deg"}) {
        if (node[key]) {
          reader.fail(node[key], fmt::format("camera '{}': its camera file gives its pose, so "
                                             "'{}' must not be given too",
                                             camera.name, key));
        }
      }
      camera.world_from_camera = *calibrated_pose;
    } else {
      camera.world_from_camera = downward_camera_pose(
          reader.vector<3>(reader.required(node, "position", "a camera without a calibrated pose"),
                           "position", -1e6, 1e6),
          reader.number(node, "yaw_deg", 0, -360, 360));
    }
    rig.cameras.push_back(std::move(camera));
  }
  std::set<std::string> robot_names;
  for (const YAML::Node& node : reader.list(root, "robots")) {
    reader.check_keys(node, {"name", "leds"}, "a robot");
    RobotModel robot;
    robot.name = reader.text(reader.required(node, "name", "a robot"), "name");
    if (!robot_names.insert(robot.name).second) {
      reader.fail(node, fmt::format("robot '{}' appears twice", robot.name));
    }
    YAML::Node leds = reader.list(node, "leds");
    if (leds.size() == 0) reader.fail(node, fmt::format("robot '{}' needs 'leds'", robot.name));
    for (const YAML::Node& led_node : leds) {
      reader.check_keys(led_node, {"position", "on_s", "off_s", "phase_s"}, "an LED");
      Led led;
      led.position =
          reader.vector<2>(reader.required(led_node, "position", "an LED"), "position", -1e6, 1e6);
      led.on_s = reader.number(led_node, "on_s", led.on_s, 1e-3, 1e6);
      led.off_s = reader.number(led_node, "off_s", led.off_s, 0, 1e6);
      led.phase_s = reader.number(led_node, "phase_s", led.phase_s, -1e6, 1e6);
      robot.leds.push_back(led);
    }
    rig.robots.push_back(std::move(robot));
  }
  return rig;
}

Rig load_rig(const std::string& path) {
  std::ifstream stream(path);
  if (!stream)
    throw RigError(fmt::format("{}: cannot read the rig: {}", path, std::strerror(errno)));
  std::stringstream text;
  text << stream.rdbuf();
  return parse_rig(text.str(), path, std::filesystem::path(path).parent_path().string());
}

}  // namespace mocap::pixart
