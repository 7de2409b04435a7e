// The PixArt ceiling rig and the robots it localizes (seed 002 §1, §11.2.1): where each camera
// hangs and how it images, the height of the robots' LED plane, and each robot's LED layout.
// Shared by the simulated box (which renders it) and the localizer (which inverts it).
//
// World frame: x, y on the floor, z up, metres. A camera's pose is its optical frame (x right,
// y down, z forward along the optical axis) in the world frame; a camera looking straight down
// has its z axis along world −z.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::pixart {

struct RigCamera {
  std::string name;   // topic segment and frame id: /pixart/<name>/fiducials
  int camera_id = 0;  // on the CAN bus: 4·box + camera
  std::shared_ptr<const calibration::CameraModel> model;  // 1024x768 pixels
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
};

// One infrared LED on a robot, in the robot's frame (x forward, y left, metres).
struct Led {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  // Blinking: on for `on_s`, then off for `off_s`, starting `phase_s` into the cycle at time
  // 0. off_s = 0: always on.
  double on_s = 1;
  double off_s = 0;
  double phase_s = 0;
  bool is_on(double time_s) const;
};

struct RobotModel {
  std::string name;
  std::vector<Led> leds;
};

struct Rig {
  std::string source;  // the file it came from
  std::vector<RigCamera> cameras;
  double led_plane_height_m = 0.45;  // LEDs' height above the floor (seed 002: 0.45 m)
  std::vector<RobotModel> robots;

  const RigCamera* find_camera(int camera_id) const;
};

// Why a rig file cannot be used: "FILE:LINE: what".
class RigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a rig file (config/pixart/README.md documents the keys). Camera files named in it are
// relative to the rig file; a camera file's `pose` is the camera's world_from_camera, and the
// rig then must not give the camera a `position` or `yaw_deg` of its own.
Rig load_rig(const std::string& path);
Rig parse_rig(const std::string& text, const std::string& source,
              const std::string& base_directory = ".");

// The nominal PixArt camera: 1024x768 pixels, `horizontal_fov_deg` (41 in the seed), no
// distortion; what the rig uses until a calibrated camera file is given.
std::shared_ptr<const calibration::CameraModel> nominal_pixart_camera(
    double horizontal_fov_deg = 41.0);

// The pose of a camera hanging at `position` looking straight down, its image x axis turned
// `yaw_deg` counter-clockwise from world x (seed: each camera 90 degrees from the last).
Eigen::Isometry3d downward_camera_pose(const Eigen::Vector3d& position, double yaw_deg);

// Where the ray through `pixel` meets the horizontal plane z = height (world frame), or
// nothing when it does not (unprojectable pixel, ray parallel to or away from the plane).
std::optional<Eigen::Vector2d> pixel_to_plane(const RigCamera& camera, const Eigen::Vector2d& pixel,
                                              double height);

}  // namespace mocap::pixart
