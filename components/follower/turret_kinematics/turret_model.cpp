#include "follower/turret_kinematics/turret_model.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::turret {
namespace {

using Reader = YamlReader<TurretError>;

constexpr double kDegree = M_PI / 180;

// The signed angle about `axis` that turns `from` onto `to`, both projected onto the plane
// normal to the axis; 0 when either projection vanishes.
double angle_about(const Eigen::Vector3d& axis, const Eigen::Vector3d& from,
                   const Eigen::Vector3d& to) {
  const Eigen::Vector3d a = from - axis * axis.dot(from), b = to - axis * axis.dot(to);
  if (a.norm() < 1e-12 || b.norm() < 1e-12) return 0;
  return std::atan2(axis.dot(a.cross(b)), a.dot(b));
}

// Where the target is off the optical axis: x/z and y/z in the camera frame (0, 0 when
// centred); nothing when the target is not in front of the camera.
std::optional<Eigen::Vector2d> image_offset(const Eigen::Isometry3d& base_from_camera,
                                            const Eigen::Vector3d& target) {
  const Eigen::Vector3d p = base_from_camera.inverse() * target;
  if (p.z() <= 1e-9) return std::nullopt;
  return Eigen::Vector2d(p.x() / p.z(), p.y() / p.z());
}

Eigen::Isometry3d read_origin(const Reader& reader, const YAML::Node& joint, const char* what) {
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  YAML::Node node = joint["origin"];
  if (!node) return origin;
  reader.check_keys(node, {"xyz", "rpy_deg"}, fmt::format("the origin of {}", what));
  origin.translation() = reader.vector<3>(node, "xyz", Eigen::Vector3d::Zero());
  const Eigen::Vector3d rpy = reader.vector<3>(node, "rpy_deg", Eigen::Vector3d::Zero()) * kDegree;
  // ROS's convention (URDF): fixed axes x, y, z, i.e. R = Rz(yaw) Ry(pitch) Rx(roll).
  origin.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  return origin;
}

Joint read_joint(const Reader& reader, const YAML::Node& root, const char* name) {
  const YAML::Node node = reader.required(root, name, "the turret");
  const std::string what = fmt::format("the {} joint", name);
  reader.check_keys(node, {"origin", "axis", "limits_deg", "servo"}, what);
  Joint joint;
  joint.origin = read_origin(reader, node, what.c_str());
  const YAML::Node axis = reader.required(node, "axis", what);
  joint.axis = reader.vector<3>(axis, "axis");
  if (joint.axis.norm() < 1e-9) reader.fail(axis, "'axis' must not be zero");
  if (!std::isfinite(joint.axis.norm())) reader.fail(axis, "'axis' is too long to normalize");
  joint.axis.normalize();
  if (YAML::Node limits = node["limits_deg"]) {
    const Eigen::Vector2d range = reader.vector<2>(limits, "limits_deg", -360, 360);
    if (!(range.x() < range.y())) {
      reader.fail(limits, "'limits_deg' must be [lowest, highest], lowest first");
    }
    joint.min_rad = range.x() * kDegree;
    joint.max_rad = range.y() * kDegree;
  }
  if (YAML::Node servo = node["servo"]) {
    reader.check_keys(servo, {"zero_position", "direction"}, fmt::format("the servo of {}", what));
    joint.servo.zero_position =
        static_cast<int>(reader.integer(servo, "zero_position", 512, 0, 1023));
    joint.servo.direction = static_cast<int>(reader.integer(servo, "direction", 1, -1, 1));
    if (joint.servo.direction == 0) reader.fail(servo["direction"], "'direction' must be 1 or -1");
  }
  return joint;
}

}  // namespace

Eigen::Isometry3d Joint::parent_from_joint(double angle) const {
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  return origin * turned;
}

TurretModel::TurretModel(Joint pan, Joint tilt, Eigen::Isometry3d tilt_from_camera,
                         std::string source)
    : pan_(std::move(pan)),
      tilt_(std::move(tilt)),
      tilt_from_camera_(tilt_from_camera),
      source_(std::move(source)) {}

Eigen::Isometry3d TurretModel::base_from_camera(const JointAngles& angles) const {
  return pan_.parent_from_joint(angles.pan) * tilt_.parent_from_joint(angles.tilt) *
         tilt_from_camera_;
}

JointAngles TurretModel::clamped(const JointAngles& angles) const {
  return {std::clamp(angles.pan, pan_.min_rad, pan_.max_rad),
          std::clamp(angles.tilt, tilt_.min_rad, tilt_.max_rad)};
}

double TurretModel::pointing_error(const JointAngles& angles, const Eigen::Vector3d& target) const {
  const Eigen::Vector3d p = base_from_camera(angles).inverse() * target;
  if (p.norm() < 1e-12) return 0;
  return std::acos(std::clamp(p.normalized().z(), -1.0, 1.0));
}

Aim TurretModel::aim_at(const Eigen::Vector3d& target, const JointAngles& start) const {
  const Eigen::Vector3d tilt_joint =
      (pan_.parent_from_joint(start.pan) * tilt_.origin).translation();
  if ((target - tilt_joint).norm() < 0.01) {
    return {start, true, pointing_error(start, target)};
  }
  // First guess, as if the camera sat on both axes: turn the pan joint, then the tilt joint,
  // so the optical axis faces the target's direction.
  JointAngles angles = start;
  {
    const Eigen::Isometry3d pan_parent_from_tilt_parent = tilt_.origin;
    const Eigen::Vector3d forward_in_pan =
        pan_parent_from_tilt_parent.linear() *
        (tilt_.parent_from_joint(start.tilt).linear() * tilt_from_camera_.linear().col(2));
    const Eigen::Vector3d target_in_pan_parent = pan_.origin.inverse() * target;
    angles.pan = angle_about(pan_.axis, forward_in_pan, target_in_pan_parent);
    const Eigen::Isometry3d base_from_tilt_parent =
        pan_.parent_from_joint(angles.pan) * tilt_.origin;
    const Eigen::Vector3d target_in_tilt_parent = base_from_tilt_parent.inverse() * target;
    const Eigen::Vector3d forward_in_tilt = tilt_from_camera_.linear().col(2);
    angles.tilt = angle_about(tilt_.axis, forward_in_tilt, target_in_tilt_parent);
  }
  // Of the pan angles 2π apart, the one nearest the current angle.
  angles.pan = start.pan + std::remainder(angles.pan - start.pan, 2 * M_PI);

  // Then Newton's method on the target's offset from the optical axis, for the camera's offset
  // from the axes (a few centimetres: a near target needs it).
  for (int iteration = 0; iteration < 20; ++iteration) {
    const auto offset = image_offset(base_from_camera(angles), target);
    if (!offset || offset->norm() < 1e-12) break;
    constexpr double h = 1e-7;
    const auto d_pan = image_offset(base_from_camera({angles.pan + h, angles.tilt}), target);
    const auto d_tilt = image_offset(base_from_camera({angles.pan, angles.tilt + h}), target);
    if (!d_pan || !d_tilt) break;
    Eigen::Matrix2d jacobian;
    jacobian.col(0) = (*d_pan - *offset) / h;
    jacobian.col(1) = (*d_tilt - *offset) / h;
    if (std::abs(jacobian.determinant()) < 1e-12) break;
    const Eigen::Vector2d step = jacobian.colPivHouseholderQr().solve(-*offset);
    angles.pan += step.x();
    angles.tilt += step.y();
    if (step.norm() < 1e-12) break;
  }
  Aim aim;
  aim.angles = clamped(angles);
  aim.within_limits = std::abs(aim.angles.pan - angles.pan) < 1e-9 &&
                      std::abs(aim.angles.tilt - angles.tilt) < 1e-9;
  aim.residual_rad = pointing_error(aim.angles, target);
  return aim;
}

TurretModel parse_turret(const std::string& text, const std::string& source) {
  Reader reader(source);
  YAML::Node root = reader.parse(text);
  reader.check_keys(root, {"pan", "tilt", "camera"}, "the turret");
  Joint pan = read_joint(reader, root, "pan");
  Joint tilt = read_joint(reader, root, "tilt");
  const YAML::Node camera = reader.required(root, "camera", "the turret");
  reader.check_keys(camera, {"origin"}, "the camera");
  return TurretModel(std::move(pan), std::move(tilt), read_origin(reader, camera, "the camera"),
                     source);
}

TurretModel load_turret(const std::string& path) {
  std::ifstream stream(path);
  if (!stream) {
    throw TurretError(fmt::format("{}: cannot read the turret: {}", path, std::strerror(errno)));
  }
  std::stringstream text;
  text << stream.rdbuf();
  return parse_turret(text.str(), path);
}

}  // namespace mocap::turret
