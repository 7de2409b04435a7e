// geometry_msgs/Pose <-> Eigen (components/common/pose_message): a round trip, and messages no
// transform describes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/pose_message/pose_message.hpp"

namespace mocap {
namespace {

TEST(PoseMessage, RoundTripsATransform) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.3, -1.2, 2.5);
  pose.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const geometry_msgs::msg::Pose message = to_pose_message(pose);
  EXPECT_DOUBLE_EQ(message.position().y(), -1.2);
  const std::optional<Eigen::Isometry3d> back = to_isometry(message);
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->isApprox(pose, 1e-12));
}

TEST(PoseMessage, NormalisesTheQuaternionAndRefusesWhatIsNoRotation) {
  geometry_msgs::msg::Pose message;
  message.orientation().w(2.0);  // not unit length: the same rotation
  ASSERT_TRUE(to_isometry(message));
  EXPECT_TRUE(to_isometry(message)->linear().isApprox(Eigen::Matrix3d::Identity()));
  message.orientation().w(0.0);  // all zero
  EXPECT_FALSE(to_isometry(message));
  message.orientation().w(1.0);
  message.position().x(std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(to_isometry(message));
}

}  // namespace
}  // namespace mocap
