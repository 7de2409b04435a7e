// What hides a marker from a camera that sends centroids: a robot's frame, or something
// standing in a swarm scene (a pillar's stretch, a person). One type for both, so the scene's
// occluders go to the camera as they are read.
#pragma once

#include <Eigen/Core>

namespace mocap::synthetic {

// An opaque sphere in the world (metres): what lies behind it, seen from the camera, is hidden.
struct OccludingSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius_m = 0;
};

}  // namespace mocap::synthetic
