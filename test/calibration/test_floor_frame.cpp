// A volume's world frame from a board on the floor (floor_frame.hpp): cameras calibrated
// relative to one of them come out in the room's frame, whichever way up the board lies.
#include <gtest/gtest.h>

#include <vector>

#include <mocap/calibration/floor_frame.hpp>

namespace mocap::calibration {
namespace {

// A camera 2.5 m up at `x, y`, looking down at the floor's centre.
Eigen::Isometry3d camera_from_world(double x, double y) {
  const Eigen::Vector3d position(x, y, 2.5);
  const Eigen::Vector3d z = (Eigen::Vector3d(0, 0, 0.5) - position).normalized();
  const Eigen::Vector3d right = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  world_from_camera.linear() << right, z.cross(right), z;
  world_from_camera.translation() = position;
  return world_from_camera.inverse();
}

TEST(FloorFrame, CamerasComeOutInTheRoomsFrame) {
  const std::vector<Eigen::Isometry3d> truth = {camera_from_world(-2, -2), camera_from_world(2, -2),
                                                camera_from_world(2, 2), camera_from_world(-2, 2)};
  // Calibrated relative to camera 1: camera_from_reference.
  const Eigen::Isometry3d world_from_reference = truth[1].inverse();
  std::vector<Eigen::Isometry3d> relative;
  for (const Eigen::Isometry3d& camera : truth) relative.push_back(camera * world_from_reference);
  // The board at the world's origin, its x along the world's; lying face up, then face down
  // (its z into the floor, its y along the world's -y).
  const Eigen::Isometry3d face_down(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  for (const Eigen::Isometry3d& world_from_board : {Eigen::Isometry3d::Identity(), face_down}) {
    const Eigen::Isometry3d reference_from_board = truth[1] * world_from_board;
    const std::vector<Eigen::Isometry3d> found =
        cameras_in_floor_frame(relative, reference_from_board);
    ASSERT_EQ(found.size(), truth.size());
    for (size_t c = 0; c < truth.size(); ++c) {
      EXPECT_TRUE(found[c].isApprox(truth[c], 1e-9)) << "camera " << c;
      // Up is up: every camera above the floor.
      EXPECT_GT(found[c].inverse().translation().z(), 2.4);
    }
  }
}

}  // namespace
}  // namespace mocap::calibration
