// The two poses of a plane from its image (IPPE: Collins and Bartoli, "Infinitesimal Plane-Based
// Pose Estimation", IJCV 2014). A plane seen through a camera has up to two poses that image it
// nearly alike (one tilted towards the camera, one away); IPPE finds both in closed form from the
// homography's first-order behaviour at one point of the plane.
#pragma once

#include <array>
#include <optional>
#include <span>

#include <Eigen/Geometry>

namespace mocap::pose {

// Both poses camera_from_plane of the plane z = 0 whose points `plane` (x, y; centred on their
// mean, which IPPE expands about) are seen at the normalised image points `rays` (x/z, y/z),
// four pairs or more, not all on one line; nullopt otherwise. The first pose is not
// necessarily the better: the caller compares their reprojection errors.
std::optional<std::array<Eigen::Isometry3d, 2>> plane_poses(std::span<const Eigen::Vector2d> plane,
                                                            std::span<const Eigen::Vector2d> rays);

}  // namespace mocap::pose
