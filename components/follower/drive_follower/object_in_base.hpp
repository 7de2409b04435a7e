// Where the tracked object stands and which way it faces, on the floor plane of the base, from
// its pose in the tracking camera's optical frame and the turret's chain (the camera in the
// base frame at the current joint angles).
//
//   ObjectInBase object =
//       object_in_base(turret.base_from_camera({pan, tilt}), camera_from_object);
//
// Position: the object's origin dropped onto the floor plane (its height is irrelevant to the
// base). Facing: the board's normal (its z axis) turned toward the camera, since the side the
// camera sees is the front whichever way the board's z axis points, then dropped onto the
// floor and normalised. A board lying nearly flat has no meaningful front: when the horizontal
// part of its normal is shorter than `min_horizontal` (0.2: tilted less than about 12 degrees
// from horizontal), the facing is taken from the object toward the base, so the goal lies on
// the line between them and the base only closes or opens the distance.
#pragma once

#include <Eigen/Geometry>

#include "follower/drive_follower/drive_rules.hpp"

namespace mocap::drive {

struct ObjectObservation {
  ObjectInBase object;
  // false: the board was nearly horizontal and the facing points from the object to the base.
  bool facing_from_normal = true;
};

ObjectObservation object_in_base(const Eigen::Isometry3d& base_from_camera,
                                 const Eigen::Isometry3d& camera_from_object,
                                 double min_horizontal = 0.2);

}  // namespace mocap::drive
