#include "follower/drive_follower/object_in_base.hpp"

namespace mocap::drive {

ObjectObservation object_in_base(const Eigen::Isometry3d& base_from_camera,
                                 const Eigen::Isometry3d& camera_from_object,
                                 double min_horizontal) {
  const Eigen::Isometry3d base_from_object = base_from_camera * camera_from_object;
  const Eigen::Vector3d position = base_from_object.translation();
  Eigen::Vector3d normal = base_from_object.linear().col(2);
  if (normal.dot(base_from_camera.translation() - position) < 0) normal = -normal;

  ObjectObservation observation;
  observation.object.position = position.head<2>();
  const Eigen::Vector2d horizontal = normal.head<2>();
  if (horizontal.norm() >= min_horizontal) {
    observation.object.facing = horizontal.normalized();
    return observation;
  }
  observation.facing_from_normal = false;
  const Eigen::Vector2d toward_base = -observation.object.position;
  // An object right above the base's origin gives no direction either; any is as good.
  observation.object.facing =
      toward_base.norm() > 1e-9 ? toward_base.normalized() : Eigen::Vector2d(-1, 0);
  return observation;
}

}  // namespace mocap::drive
