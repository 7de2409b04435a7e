// The turret's kinematic chain (components/follower/turret_kinematics): forward kinematics against
// hand-computed poses, aiming at targets near and far (checked by the forward chain, not by
// the aiming code's own arithmetic), limits, and the turret file's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "follower/turret_kinematics/turret_model.hpp"
#include "test/test_support.hpp"

namespace mocap::turret {
namespace {

constexpr double kDegree = M_PI / 180;

const TurretModel& shipped_turret() {
  static const TurretModel turret =
      load_turret((test::source_dir() / "config" / "turret.yaml").string());
  return turret;
}

std::string error_of(const std::string& text) {
  try {
    parse_turret(text, "turret.yaml");
  } catch (const TurretError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TurretModel, AtZeroTheCameraLooksStraightAhead) {
  const Eigen::Isometry3d camera = shipped_turret().base_from_camera({0, 0});
  // config/turret.yaml: pan joint 0.45 m up, tilt joint 0.06 m above it, camera 0.03 m in
  // front of the tilt axis and 0.05 m above it.
  EXPECT_TRUE(camera.translation().isApprox(Eigen::Vector3d(0.03, 0, 0.56), 1e-12))
      << camera.translation().transpose();
  // Optical axis forward (base +x), image x to the right (base −y), image y down (base −z).
  EXPECT_TRUE(camera.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE(camera.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE(camera.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
}

TEST(TurretModel, PanTurnsLeftAndTiltLooksUp) {
  const TurretModel& turret = shipped_turret();
  const Eigen::Isometry3d left = turret.base_from_camera({90 * kDegree, 0});
  EXPECT_TRUE(left.linear().col(2).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE(left.translation().isApprox(Eigen::Vector3d(0, 0.03, 0.56), 1e-12));
  const Eigen::Isometry3d up = turret.base_from_camera({0, 30 * kDegree});
  EXPECT_TRUE(up.linear().col(2).isApprox(
      Eigen::Vector3d(std::cos(30 * kDegree), 0, std::sin(30 * kDegree)), 1e-12));
  // The camera swings about the tilt axis, 0.51 m up: (0.03, 0.05) turned by 30 degrees.
  const double c = std::cos(30 * kDegree), s = std::sin(30 * kDegree);
  EXPECT_TRUE(up.translation().isApprox(
      Eigen::Vector3d(0.03 * c - 0.05 * s, 0, 0.51 + 0.03 * s + 0.05 * c), 1e-12))
      << up.translation().transpose();
}

TEST(TurretModel, AimCentresTargetsNearAndFar) {
  const TurretModel& turret = shipped_turret();
  std::mt19937 random(7);
  // Within the joints' reach: bearings inside ±150 degrees, elevations from the tilt joint
  // (0.51 m up) inside −45..60 degrees, with a margin for the camera's offset.
  std::uniform_real_distribution<double> bearing(-140 * kDegree, 140 * kDegree), distance(0.4, 4.0),
      elevation(-35 * kDegree, 50 * kDegree);
  for (int i = 0; i < 500; ++i) {
    const double b = bearing(random), d = distance(random);
    const Eigen::Vector3d target(d * std::cos(b), d * std::sin(b),
                                 0.51 + d * std::tan(elevation(random)));
    const Aim aim = turret.aim_at(target, {0, 0});
    ASSERT_TRUE(aim.within_limits) << target.transpose();
    // Centred, by the forward chain: in front of the camera, on its optical axis.
    const Eigen::Vector3d seen = turret.base_from_camera(aim.angles).inverse() * target;
    EXPECT_GT(seen.z(), 0) << target.transpose();
    EXPECT_LT(std::hypot(seen.x(), seen.y()), 1e-6) << target.transpose();
    EXPECT_LT(aim.residual_rad, 1e-6);
    EXPECT_NEAR(aim.angles.pan, b, 10 * kDegree) << "the camera offset changes pan only a little";
  }
}

TEST(TurretModel, AimStartsFromTheCurrentAnglesAndReportsLimits) {
  const TurretModel& turret = shipped_turret();
  // Straight behind: +180 and −180 degrees are the same direction but outside ±150.
  const Aim behind = turret.aim_at({-2, 0, 0.5}, {140 * kDegree, 0});
  EXPECT_FALSE(behind.within_limits);
  EXPECT_NEAR(behind.angles.pan, 150 * kDegree, 1e-12);  // the limit nearest the start
  EXPECT_GT(behind.residual_rad, 20 * kDegree);
  // Far overhead: beyond the tilt stop at 60 degrees.
  const Aim overhead = turret.aim_at({0.3, 0, 3.0}, {0, 0});
  EXPECT_FALSE(overhead.within_limits);
  EXPECT_NEAR(overhead.angles.tilt, 60 * kDegree, 1e-12);
  // A target on the tilt joint has no direction: the start stays.
  const Aim inside = turret.aim_at({0, 0, 0.51}, {0.2, 0.1});
  EXPECT_EQ(inside.angles.pan, 0.2);
  EXPECT_EQ(inside.angles.tilt, 0.1);
}

TEST(TurretModel, PointingErrorIsTheAngleOffTheOpticalAxis) {
  const TurretModel& turret = shipped_turret();
  const Eigen::Isometry3d camera = turret.base_from_camera({0.3, -0.1});
  const Eigen::Vector3d off_axis =
      camera * Eigen::Vector3d(std::tan(5 * kDegree) * 2.0, 0, 2.0);  // 5 degrees right
  EXPECT_NEAR(turret.pointing_error({0.3, -0.1}, off_axis), 5 * kDegree, 1e-12);
}

TEST(TurretFile, ErrorsNameTheFileLineAndField) {
  const std::string good_tilt = "tilt: {axis: [0, -1, 0]}\ncamera: {}\n";
  EXPECT_EQ(error_of("pan: {axis: [0, 0, 1]}\n" + good_tilt + "wheels: 2\n"),
            "turret.yaml:4: unknown key 'wheels' in the turret (keys: pan, tilt, camera)");
  EXPECT_EQ(error_of(good_tilt), "turret.yaml:1: the turret needs 'pan'");
  EXPECT_EQ(error_of("pan: {axis: [0, 0, 0]}\n" + good_tilt),
            "turret.yaml:1: 'axis' must not be zero");
  EXPECT_EQ(error_of("pan: {axis: [0, 0, 1], limits_deg: [30, -30]}\n" + good_tilt),
            "turret.yaml:1: 'limits_deg' must be [lowest, highest], lowest first");
  EXPECT_EQ(error_of("pan: {axis: [0, 0, 1], servo: {direction: 0}}\n" + good_tilt),
            "turret.yaml:1: 'direction' must be 1 or -1");
  EXPECT_EQ(error_of("pan: {axis: [0, 0, 1], origin: {xyz: [0, 0]}}\n" + good_tilt),
            "turret.yaml:1: 'xyz' must be a list of 3 numbers, not a list of 2");
  EXPECT_NE(error_of("pan: [").find("turret.yaml:1:"), std::string::npos);
  try {
    load_turret("/nonexistent/turret.yaml");
    ADD_FAILURE() << "no error";
  } catch (const TurretError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/turret.yaml: cannot read the turret: No such file or directory");
  }
}

}  // namespace
}  // namespace mocap::turret
