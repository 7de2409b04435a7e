// A volume's world frame from a board on the floor (floor_frame.hpp): cameras calibrated
// relative to one of them come out in the room's frame, whichever way up the board lies, from
// the board laid once or at marks.
#include <gtest/gtest.h>

#include <optional>
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

const std::vector<Eigen::Isometry3d> kTruth = {camera_from_world(-2, -2), camera_from_world(2, -2),
                                               camera_from_world(2, 2), camera_from_world(-2, 2)};

// Calibrated relative to camera 1: camera_from_reference.
std::vector<Eigen::Isometry3d> relative_to_camera_1() {
  std::vector<Eigen::Isometry3d> relative;
  for (const Eigen::Isometry3d& camera : kTruth) relative.push_back(camera * kTruth[1].inverse());
  return relative;
}

void expect_truth(const std::vector<Eigen::Isometry3d>& found, double tolerance) {
  ASSERT_EQ(found.size(), kTruth.size());
  for (size_t c = 0; c < kTruth.size(); ++c) {
    EXPECT_TRUE(found[c].isApprox(kTruth[c], tolerance)) << "camera " << c;
    EXPECT_GT(found[c].inverse().translation().z(), 2.4);  // up is up
  }
}

TEST(FloorFrame, TheBoardLaidOnceIsTheRoom) {
  // The board at the world's origin, its x along the world's; lying face up, then face down
  // (its z into the floor, its y along the world's -y); then at the mark (1, -0.5).
  const Eigen::Isometry3d face_down(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  for (const Eigen::Isometry3d& world_from_board : {Eigen::Isometry3d::Identity(), face_down}) {
    const Eigen::Isometry3d reference_from_world =
        reference_from_world_of_board(kTruth[1] * world_from_board);
    expect_truth(cameras_in_world(relative_to_camera_1(), reference_from_world), 1e-9);
  }
  const Eigen::Isometry3d at_mark(Eigen::Translation3d(1, -0.5, 0));
  expect_truth(cameras_in_world(relative_to_camera_1(),
                                reference_from_world_of_board(kTruth[1] * at_mark, {1, -0.5})),
               1e-9);
}

TEST(FloorFrame, MarksSetTheFloorThroughTheBoardsCentres) {
  const std::vector<Eigen::Vector2d> marks = {{0, 0}, {1.5, 0}, {0, 1.5}, {-1.5, 0}, {0, -1.5}};
  std::vector<Eigen::Vector3d> centres;  // in camera 1's frame
  for (const Eigen::Vector2d& mark : marks) {
    centres.push_back(kTruth[1] * Eigen::Vector3d(mark.x(), mark.y(), 0));
  }
  const std::optional<Eigen::Isometry3d> exact = reference_from_world_of_marks(centres, marks);
  ASSERT_TRUE(exact);
  expect_truth(cameras_in_world(relative_to_camera_1(), *exact), 1e-9);

  // A centre 0.1 mm off moves the frame by about that over the marks' spread, not more.
  centres[1] += Eigen::Vector3d(0, 0, 1e-4);
  const std::optional<Eigen::Isometry3d> off = reference_from_world_of_marks(centres, marks);
  ASSERT_TRUE(off);
  const double turn = Eigen::AngleAxisd(off->linear().transpose() * exact->linear()).angle();
  EXPECT_GT(turn, 1e-5);
  EXPECT_LT(turn, 1e-4 / 1.5);

  // Too few, in a line, or mirrored (x and y swapped): nothing, not a wrong frame.
  EXPECT_FALSE(reference_from_world_of_marks({centres[0], centres[1]}, {marks[0], marks[1]}));
  EXPECT_FALSE(reference_from_world_of_marks({centres[0], centres[1], centres[3]},
                                             {marks[0], marks[1], marks[3]}));
  std::vector<Eigen::Vector2d> swapped;
  for (const Eigen::Vector2d& mark : marks) swapped.emplace_back(mark.y(), mark.x());
  EXPECT_FALSE(reference_from_world_of_marks(centres, swapped));
}

}  // namespace
}  // namespace mocap::calibration
