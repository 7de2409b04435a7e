// The drive follower's library (components/follower/drive_follower) and the simulated base
// (components/sim/mobile_base_sim): the seed's two driving rules on scripted positions, the
// object's place and facing from a camera pose and the turret, the acceleration limits and the
// lost-track stop, the base's exact arcs, and the closed loop of rules and base in simulated
// time: the base reaches the goal from several starts and follows a walking object.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "follower/drive_follower/acceleration_limiter.hpp"
#include "follower/drive_follower/drive_follower.hpp"
#include "follower/drive_follower/drive_rules.hpp"
#include "follower/drive_follower/object_in_base.hpp"
#include "follower/turret_kinematics/turret_model.hpp"
#include "sim/mobile_base_sim/mobile_base_sim.hpp"
#include "test/test_support.hpp"

namespace mocap::drive {
namespace {

constexpr double kDegree = M_PI / 180;

const turret::TurretModel& shipped_turret() {
  static const turret::TurretModel turret =
      turret::load_turret((test::source_dir() / "config" / "turret.yaml").string());
  return turret;
}

// An object at (x, y) of the base frame whose front looks along `facing_deg`.
ObjectInBase object_at(double x, double y, double facing_deg) {
  return {{x, y}, {std::cos(facing_deg * kDegree), std::sin(facing_deg * kDegree)}};
}

DriveCommand seed_rules(const ObjectInBase& object, const DriveOptions& options = {}) {
  return drive_command(object, options, options.goal_tolerance_m);
}

// ---------------------------------------------------------------------------------------------
// The rules.

TEST(DriveRules, GoalFarAheadDrivesForwardAtTopSpeed) {
  const DriveOptions options;  // 1.5 m, gains 1.0 and 2.0, top 0.6 m/s and 1.5 rad/s
  // Facing the base from 4 m: the goal is 2.5 m straight ahead.
  const DriveCommand command = seed_rules(object_at(4, 0, 180), options);
  EXPECT_EQ(command.rule, DriveRule::Forward);
  EXPECT_DOUBLE_EQ(command.linear_mps, 0.6);  // 1.0 × 2.5 m capped
  EXPECT_NEAR(command.angular_rps, 0, 1e-12);
  EXPECT_TRUE(goal_position(object_at(4, 0, 180), options).isApprox(Eigen::Vector2d(2.5, 0)));
}

TEST(DriveRules, NearerGoalsAreApproachedProportionallyAndTurnedToward) {
  // Goal 0.5 m ahead: below the cap, speed = gain × distance.
  DriveCommand command = seed_rules(object_at(2.0, 0, 180));
  EXPECT_EQ(command.rule, DriveRule::Forward);
  EXPECT_NEAR(command.linear_mps, 0.5, 1e-12);
  // Goal at (0.4, 0.3): 0.5 m away, 36.87 degrees to the left: an arc to the left.
  command = seed_rules(object_at(1.9, 0.3, 180));
  EXPECT_EQ(command.rule, DriveRule::Forward);
  EXPECT_NEAR(command.linear_mps, 0.5, 1e-12);
  EXPECT_NEAR(command.angular_rps, 2.0 * std::atan2(0.3, 0.4), 1e-12);
  EXPECT_GT(command.angular_rps, 0);
  // To the right: turns right, by the same amount.
  const DriveCommand mirrored = seed_rules(object_at(1.9, -0.3, 180));
  EXPECT_NEAR(mirrored.angular_rps, -command.angular_rps, 1e-12);
  // The gains scale the commands.
  DriveOptions soft;
  soft.linear_gain = 0.5;
  soft.angular_gain = 1.0;
  command = seed_rules(object_at(1.9, 0.3, 180), soft);
  EXPECT_NEAR(command.linear_mps, 0.25, 1e-12);
  EXPECT_NEAR(command.angular_rps, std::atan2(0.3, 0.4), 1e-12);
}

TEST(DriveRules, TurnRateSaturatesAtTheMaximum) {
  // Goal 80 degrees to the left, 2 m away: 2.0 × 1.396 rad is more than 1.5 rad/s.
  const ObjectInBase left =
      object_at(2 * std::cos(80 * kDegree) + 1.5, 2 * std::sin(80 * kDegree), 180);
  const DriveCommand command = seed_rules(left);
  EXPECT_EQ(command.rule, DriveRule::Forward);
  EXPECT_DOUBLE_EQ(command.angular_rps, 1.5);
  EXPECT_DOUBLE_EQ(command.linear_mps, 0.6);
  DriveOptions slow;
  slow.max_angular_rps = 0.4;
  slow.max_linear_mps = 0.2;
  const DriveCommand capped = seed_rules(left, slow);
  EXPECT_DOUBLE_EQ(capped.angular_rps, 0.4);
  EXPECT_DOUBLE_EQ(capped.linear_mps, 0.2);
}

TEST(DriveRules, GoalBehindDrivesBackwardSteeringByTheRear) {
  // The object 0.5 m ahead, facing the base: the goal is 1 m behind.
  DriveCommand command = seed_rules(object_at(0.5, 0, 180));
  EXPECT_EQ(command.rule, DriveRule::Backward);
  EXPECT_NEAR(command.linear_mps, -0.6, 1e-12);
  EXPECT_NEAR(command.angular_rps, 0, 1e-12);
  // Goal behind and to the left, at (-1, 0.3): the rear (pointing at 180 degrees) must turn
  // toward 163.3 degrees, clockwise: a negative turn rate.
  command = seed_rules(object_at(0.5, 0.3, 180));
  EXPECT_EQ(command.rule, DriveRule::Backward);
  EXPECT_LT(command.linear_mps, 0);
  EXPECT_NEAR(command.angular_rps, -2.0 * std::atan2(0.3, 1.0), 1e-12);
  // Just beyond 90 degrees backward, just within forward.
  EXPECT_EQ(seed_rules(object_at(-0.01 + 1.5, 1.0, 180)).rule, DriveRule::Backward);
  EXPECT_EQ(seed_rules(object_at(0.01 + 1.5, 1.0, 180)).rule, DriveRule::Forward);
  // Slowly near a goal behind.
  command = seed_rules(object_at(1.2, 0, 180));  // goal 0.3 m behind
  EXPECT_EQ(command.rule, DriveRule::Backward);
  EXPECT_NEAR(command.linear_mps, -0.3, 1e-12);
}

TEST(DriveRules, NearTheGoalTheBaseOnlyTurnsToFaceTheObject) {
  // The goal 0.2 m from the base (within 0.25), the object up and to the left at 36.9 degrees.
  const ObjectInBase object = {{1.2 + 0.12, 0.9 + 0.16}, {-0.8, -0.6}};
  const DriveCommand command = seed_rules(object);
  EXPECT_EQ(command.rule, DriveRule::Face);
  EXPECT_EQ(command.linear_mps, 0);
  EXPECT_NEAR(command.angular_rps, 2.0 * std::atan2(1.06, 1.32), 1e-12);
  // Facing it already: nothing to do.
  const DriveCommand still = seed_rules(object_at(1.5, 0, 180));
  EXPECT_EQ(still.rule, DriveRule::Face);
  EXPECT_EQ(still.linear_mps, 0);
  EXPECT_EQ(still.angular_rps, 0);
  // The object behind: a turn at the top rate.
  const DriveCommand behind = seed_rules(object_at(-1.5, 0.1, 0));
  EXPECT_EQ(behind.rule, DriveRule::Face);
  EXPECT_DOUBLE_EQ(behind.angular_rps, 1.5);
}

TEST(DriveRules, DriveOnUntilArrivedThenHoldWithinTheGoalTolerance) {
  DriveRules rules;  // arrival 0.05 m, hold 0.25 m
  // 0.2 m from the goal: the seed's rules would stop here; these drive on.
  EXPECT_EQ(rules.command(object_at(1.7, 0, 180)).rule, DriveRule::Forward);
  EXPECT_FALSE(rules.holding());
  EXPECT_EQ(rules.command(object_at(1.54, 0, 180)).rule, DriveRule::Face);
  EXPECT_TRUE(rules.holding());
  // Arrived: the object may move up to 0.25 m before the base drives again.
  EXPECT_EQ(rules.command(object_at(1.7, 0.1, 180)).rule, DriveRule::Face);
  EXPECT_EQ(rules.command(object_at(1.76, 0, 180)).rule, DriveRule::Forward);
  EXPECT_FALSE(rules.holding());
  EXPECT_EQ(rules.command(object_at(1.7, 0, 180)).rule, DriveRule::Forward);
  rules.command(object_at(1.5, 0, 180));
  EXPECT_TRUE(rules.holding());
  rules.reset();
  EXPECT_EQ(rules.command(object_at(1.7, 0, 180)).rule, DriveRule::Forward);
}

TEST(DriveRules, InvalidOptionsAreNamed) {
  EXPECT_EQ(DriveOptions{}.problem(), std::nullopt);
  DriveOptions options;
  options.arrival_tolerance_m = 0.3;
  EXPECT_EQ(options.problem(), "arrival_tolerance_m: 0.3 is above goal_tolerance_m (0.25)");
  try {
    DriveRules rules(options);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "DriveOptions::arrival_tolerance_m: 0.3 is above goal_tolerance_m (0.25)");
  }
  options = {};
  options.max_linear_mps = 0;
  EXPECT_EQ(options.problem(), "max_linear_mps: 0 is not above 0");
  options = {};
  options.angular_gain = std::nan("");
  EXPECT_EQ(options.problem(), "angular_gain: nan is not above 0");
  options = {};
  options.goal_distance_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(options.problem(), "goal_distance_m: inf is not finite");
}

// ---------------------------------------------------------------------------------------------
// The object on the floor, from the camera.

// A vertical board `distance` along the optical axis at `angles`, its z axis toward the
// camera (sign +1) or away from it (-1): what the pose estimator reports of it.
Eigen::Isometry3d board_on_axis(double distance, int sign) {
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  camera_from_object.translation() = Eigen::Vector3d(0, 0, distance);
  if (sign > 0) {  // z toward the camera: turned half round about the camera's x axis
    camera_from_object.linear() =
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  }
  return camera_from_object;
}

TEST(ObjectInBase, BoardFacingTheCameraPannedLeft) {
  // Pan 90 degrees, tilt 0: the camera is at (0, 0.03, 0.56) looking along +y
  // (config/turret.yaml). A board 2 m along the axis stands at (0, 2.03) and faces -y.
  const Eigen::Isometry3d camera = shipped_turret().base_from_camera({90 * kDegree, 0});
  for (int sign : {+1, -1}) {
    const ObjectObservation seen = object_in_base(camera, board_on_axis(2.0, sign));
    EXPECT_TRUE(seen.facing_from_normal);
    EXPECT_NEAR(seen.object.position.x(), 0, 1e-12);
    EXPECT_NEAR(seen.object.position.y(), 2.03, 1e-12);
    EXPECT_NEAR(seen.object.facing.x(), 0, 1e-12) << "z axis sign " << sign;
    EXPECT_NEAR(seen.object.facing.y(), -1, 1e-12) << "z axis sign " << sign;
  }
}

TEST(ObjectInBase, BoardLeaningBackSeenByACameraLookingUp) {
  // Tilt 30 degrees: the camera swings about the tilt axis (0.51 m up) to
  // (0.03 c - 0.05 s, 0, 0.51 + 0.03 s + 0.05 c) and looks along (c, 0, s). The board on its
  // axis faces down the axis; its horizontal part (0.87 long) points at -x.
  const double c = std::cos(30 * kDegree), s = std::sin(30 * kDegree);
  const ObjectObservation seen =
      object_in_base(shipped_turret().base_from_camera({0, 30 * kDegree}), board_on_axis(2.0, 1));
  EXPECT_TRUE(seen.facing_from_normal);
  EXPECT_NEAR(seen.object.position.x(), 0.03 * c - 0.05 * s + 2 * c, 1e-12);
  EXPECT_NEAR(seen.object.position.y(), 0, 1e-12);
  EXPECT_NEAR(seen.object.facing.x(), -1, 1e-12);
  EXPECT_NEAR(seen.object.facing.y(), 0, 1e-12);
}

TEST(ObjectInBase, TurnedBoardAtKnownTurretAngles) {
  // A vertical board standing at (3, 1, 0.8) in the base frame, its front looking along
  // 200 degrees (toward the base and a little right of it), seen with the turret at pan 20,
  // tilt 5 degrees.
  const turret::JointAngles angles{20 * kDegree, 5 * kDegree};
  const Eigen::Isometry3d base_from_camera = shipped_turret().base_from_camera(angles);
  const double facing = 200 * kDegree;
  Eigen::Isometry3d base_from_board = Eigen::Isometry3d::Identity();
  base_from_board.translation() = Eigen::Vector3d(3, 1, 0.8);
  // Board z along the facing, y up: a board standing on its edge.
  base_from_board.linear().col(2) = Eigen::Vector3d(std::cos(facing), std::sin(facing), 0);
  base_from_board.linear().col(1) = Eigen::Vector3d::UnitZ();
  base_from_board.linear().col(0) =
      base_from_board.linear().col(1).cross(base_from_board.linear().col(2));
  const ObjectObservation seen =
      object_in_base(base_from_camera, base_from_camera.inverse() * base_from_board);
  EXPECT_TRUE(seen.object.position.isApprox(Eigen::Vector2d(3, 1), 1e-12));
  EXPECT_NEAR(seen.object.facing.x(), std::cos(facing), 1e-12);
  EXPECT_NEAR(seen.object.facing.y(), std::sin(facing), 1e-12);
  // The goal 1.5 m in front of it.
  EXPECT_TRUE(goal_position(seen.object, {})
                  .isApprox(Eigen::Vector2d(3 + 1.5 * std::cos(facing), 1 + 1.5 * std::sin(facing)),
                            1e-12));
}

TEST(ObjectInBase, ANearlyFlatBoardFacesTheBase) {
  // A board lying on a table at (2, -2, 0.7), its normal 5.7 degrees off vertical (horizontal
  // part 0.1 < 0.2): no front to speak of; the facing points from the object to the base.
  const Eigen::Isometry3d base_from_camera = shipped_turret().base_from_camera({-45 * kDegree, 0});
  Eigen::Isometry3d base_from_board = Eigen::Isometry3d::Identity();
  base_from_board.translation() = Eigen::Vector3d(2, -2, 0.7);
  base_from_board.linear() =
      Eigen::AngleAxisd(std::asin(0.1), Eigen::Vector3d::UnitY()).toRotationMatrix();
  const ObjectObservation seen =
      object_in_base(base_from_camera, base_from_camera.inverse() * base_from_board);
  EXPECT_FALSE(seen.facing_from_normal);
  EXPECT_TRUE(seen.object.position.isApprox(Eigen::Vector2d(2, -2), 1e-12));
  EXPECT_TRUE(seen.object.facing.isApprox(Eigen::Vector2d(-1, 1).normalized(), 1e-12));
  // Tilted more, its top leaning toward -x (toward the camera, which is below it), it has a
  // front again: -x, whichever way its z axis points.
  for (double sign : {1.0, -1.0}) {
    base_from_board.linear() =
        Eigen::AngleAxisd(-std::asin(0.25), Eigen::Vector3d::UnitY()).toRotationMatrix() *
        Eigen::Vector3d(1, sign, sign).asDiagonal();
    const ObjectObservation tilted =
        object_in_base(base_from_camera, base_from_camera.inverse() * base_from_board);
    EXPECT_TRUE(tilted.facing_from_normal);
    EXPECT_TRUE(tilted.object.facing.isApprox(Eigen::Vector2d(-1, 0), 1e-12))
        << tilted.object.facing.transpose();
  }
}

// ---------------------------------------------------------------------------------------------
// Acceleration limits and the lost-track stop.

TEST(AccelerationLimiter, StepsTowardTheTargetAndStopsAtOnce) {
  AccelerationLimiter limiter({.max_linear_accel_mps2 = 1.0, .max_angular_accel_rps2 = 3.0});
  const Velocity target{0.6, -1.5};
  // 0.05 s periods: 0.05 m/s and 0.15 rad/s per period.
  Velocity sent = limiter.limit(target, 0.05);
  EXPECT_NEAR(sent.linear_mps, 0.05, 1e-12);
  EXPECT_NEAR(sent.angular_rps, -0.15, 1e-12);
  for (int i = 1; i < 10; ++i) sent = limiter.limit(target, 0.05);
  EXPECT_NEAR(sent.linear_mps, 0.5, 1e-12);
  EXPECT_NEAR(sent.angular_rps, -1.5, 1e-12);  // reached after 10 periods, then held
  sent = limiter.limit(target, 0.05);
  sent = limiter.limit(target, 0.05);
  EXPECT_NEAR(sent.linear_mps, 0.6, 1e-12);
  sent = limiter.limit(target, 0.05);
  EXPECT_EQ(sent, target);
  // Reversing takes as long as it must: 0.6 -> -0.6 m/s is 1.2 s.
  sent = limiter.limit({-0.6, 0}, 0.6);
  EXPECT_NEAR(sent.linear_mps, 0, 1e-12);
  EXPECT_NEAR(sent.angular_rps, 0, 1e-12);
  // No time, no change.
  EXPECT_EQ(limiter.limit({-0.6, 0}, 0), sent);
  // A stop is immediate.
  limiter.limit({-0.6, 1}, 0.3);
  EXPECT_NE(limiter.last(), Velocity{});
  EXPECT_EQ(limiter.stop(), Velocity{});
  EXPECT_EQ(limiter.last(), Velocity{});
  EXPECT_THROW(AccelerationLimiter({.max_linear_accel_mps2 = 0}), std::invalid_argument);
}

TEST(DriveFollower, StopsInThePeriodTheTrackIsLostAndStartsSmoothlyWhenItReturns) {
  DriveFollower follower;  // lost after 0.25 s
  FollowerStep step = follower.step(0);
  EXPECT_EQ(step.event, TrackEvent::None);
  EXPECT_FALSE(step.command);
  EXPECT_EQ(step.velocity, Velocity{});

  const ObjectInBase ahead = object_at(4, 0.5, 180);
  double t = 0.05;
  follower.observe(ahead, t);
  step = follower.step(t);
  EXPECT_EQ(step.event, TrackEvent::Found);
  ASSERT_TRUE(step.command);
  EXPECT_EQ(step.command->rule, DriveRule::Forward);
  EXPECT_NEAR(step.velocity.linear_mps, 0.05, 1e-12);  // limited: 1 m/s² over 0.05 s
  for (int i = 0; i < 20; ++i) {
    t += 0.05;
    follower.observe(ahead, t);
    step = follower.step(t);
    EXPECT_EQ(step.event, TrackEvent::None);
  }
  EXPECT_NEAR(step.velocity.linear_mps, 0.6, 1e-12);
  EXPECT_GT(step.velocity.angular_rps, 0);
  // No more poses: still driving until 0.25 s have passed, then a stop, at once.
  const double last_seen = t;
  for (double since : {0.05, 0.1, 0.15, 0.2}) {
    step = follower.step(last_seen + since);
    EXPECT_EQ(step.event, TrackEvent::None);
    EXPECT_GT(step.velocity.linear_mps, 0.5);
  }
  t = last_seen + 0.3;
  step = follower.step(t);
  EXPECT_EQ(step.event, TrackEvent::Lost);
  EXPECT_EQ(step.velocity.linear_mps, 0);
  EXPECT_EQ(step.velocity.angular_rps, 0);
  EXPECT_FALSE(step.command);
  EXPECT_FALSE(follower.tracking());
  t += 0.05;
  step = follower.step(t);
  EXPECT_EQ(step.event, TrackEvent::None);
  EXPECT_EQ(step.velocity, Velocity{});
  // Back: found again, and the speed ramps up from zero.
  follower.observe(ahead, t);
  t += 0.05;
  step = follower.step(t);
  EXPECT_EQ(step.event, TrackEvent::Found);
  EXPECT_NEAR(step.velocity.linear_mps, 0.05, 1e-12);
  // A loop that stalled for 0.2 s may speed up by two periods' worth only.
  t += 0.2;
  follower.observe(ahead, t);
  step = follower.step(t);
  EXPECT_NEAR(step.velocity.linear_mps, 0.15, 1e-12);
  FollowerOptions never_lost;
  never_lost.lost_after_s = 0;
  EXPECT_THROW(DriveFollower{never_lost}, std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// The simulated base.

TEST(UnicycleBase, IntegratesExactlyAlongArcs) {
  sim::UnicycleBase base({.x = 1, .y = 2, .yaw = 0});
  // Straight: 0.5 m/s for 2 s in 7 unequal steps.
  for (double dt : {0.1, 0.4, 0.2, 0.3, 0.5, 0.25, 0.25}) base.step(0.5, 0, dt);
  EXPECT_NEAR(base.pose().x, 2, 1e-12);
  EXPECT_NEAR(base.pose().y, 2, 1e-12);
  // A quarter circle of radius 1 to the left, in one step or in many: the same end.
  sim::UnicycleBase one({.x = 0, .y = 0, .yaw = 0});
  sim::UnicycleBase many({.x = 0, .y = 0, .yaw = 0});
  one.step(0.5, 0.5, M_PI);
  for (int i = 0; i < 1000; ++i) many.step(0.5, 0.5, M_PI / 1000);
  for (const sim::UnicycleBase* b : {&one, &many}) {
    EXPECT_NEAR(b->pose().x, 1, 1e-12);
    EXPECT_NEAR(b->pose().y, 1, 1e-12);
    EXPECT_NEAR(b->pose().yaw, M_PI / 2, 1e-12);
  }
  // A full turn backward and clockwise comes back to the start.
  sim::UnicycleBase circle({.x = 3, .y = -1, .yaw = 1});
  circle.step(-0.3, -0.2, 2 * M_PI / 0.2);
  EXPECT_NEAR(circle.pose().x, 3, 1e-9);
  EXPECT_NEAR(circle.pose().y, -1, 1e-9);
  EXPECT_NEAR(circle.pose().yaw, 1, 1e-9);
  EXPECT_NEAR(circle.odometer_m(), 0.3 * 2 * M_PI / 0.2, 1e-9);
  // Turning on the spot.
  sim::UnicycleBase spin;
  spin.step(0, 1, 3 * M_PI / 2);
  EXPECT_NEAR(spin.pose().yaw, -M_PI / 2, 1e-12);
  EXPECT_EQ(spin.pose().x, 0);
  const Eigen::Isometry3d pose = one.world_from_base();
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(1, 1, 0), 1e-12));
  EXPECT_TRUE((pose.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(UnicycleBase, HonoursItsTopSpeedsAndIgnoresNonsense) {
  sim::UnicycleBase base({}, {.max_linear_mps = 0.7, .max_angular_rps = 1.0});
  base.step(2.0, 0, 1.0);
  EXPECT_NEAR(base.pose().x, 0.7, 1e-12);
  base.step(0, -5, 0.5);
  EXPECT_NEAR(base.pose().yaw, -0.5, 1e-12);
  base.step(std::nan(""), INFINITY, 1.0);
  base.step(1, 1, -1);
  EXPECT_NEAR(base.pose().x, 0.7, 1e-12);
  EXPECT_NEAR(base.pose().yaw, -0.5, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The closed loop: the follower drives the simulated base; the object is placed in the world
// and converted to the base frame every control period, as the camera would see it.

constexpr double kControlPeriod = 0.05;  // 20 Hz, the plugin's default
constexpr int kSubsteps = 5;             // the simulated base integrates at 100 Hz
constexpr double kHoldTolerance = 0.1;   // metres: in front of the object at 1.5 ± 0.1 m
constexpr double kFacingTolerance = 5 * kDegree;

struct WorldObject {
  Eigen::Vector2d position;
  Eigen::Vector2d facing;  // unit
};

ObjectInBase seen_from(const sim::BasePose& base, const WorldObject& object) {
  const Eigen::Rotation2Dd base_from_world(-base.yaw);
  return {base_from_world * (object.position - Eigen::Vector2d(base.x, base.y)),
          base_from_world * object.facing};
}

// Where the base stands with respect to the object's goal: along the facing (the goal
// distance is 1.5), across it, and how far off pointing at the object it is.
struct Placement {
  double along_m = 0;
  double across_m = 0;
  double pointing_error_rad = 0;

  bool holds(double goal_distance) const {
    return std::abs(along_m - goal_distance) <= kHoldTolerance &&
           std::abs(across_m) <= kHoldTolerance && pointing_error_rad <= kFacingTolerance;
  }
};

Placement placement(const sim::BasePose& base, const WorldObject& object) {
  const Eigen::Vector2d offset = Eigen::Vector2d(base.x, base.y) - object.position;
  const Eigen::Vector2d normal(-object.facing.y(), object.facing.x());
  const ObjectInBase seen = seen_from(base, object);
  return {offset.dot(object.facing), offset.dot(normal), std::abs(bearing(seen.position))};
}

struct LoopResult {
  // The settling time: from then on the base held the goal to the end; -1 if it did not.
  double reached_s = -1;
  Placement final;
  double final_distance_error_m = 0;  // | distance to the object - 1.5 |
  double max_goal_distance_while_moving_m = 0;
};

// Runs `seconds` of the loop; `object_at(t)` places the object, which moves until
// `moving_until_s`.
template <class ObjectAt>
LoopResult run_loop(sim::BasePose start, ObjectAt object_at, double seconds,
                    double moving_until_s = 0) {
  DriveFollower follower;
  const double goal_distance = follower.options().drive.goal_distance_m;
  sim::UnicycleBase base(start, {.max_linear_mps = 0.7, .max_angular_rps = 3.14});
  LoopResult result;
  const int periods = static_cast<int>(std::lround(seconds / kControlPeriod));
  for (int k = 0; k < periods; ++k) {
    const double t = k * kControlPeriod;
    follower.observe(seen_from(base.pose(), object_at(t)), t);
    const FollowerStep step = follower.step(t);
    for (int i = 0; i < kSubsteps; ++i) {
      base.step(step.velocity.linear_mps, step.velocity.angular_rps, kControlPeriod / kSubsteps);
    }
    const double after = t + kControlPeriod;
    const Placement now = placement(base.pose(), object_at(after));
    if (after <= moving_until_s) {
      result.max_goal_distance_while_moving_m =
          std::max(result.max_goal_distance_while_moving_m,
                   std::hypot(now.along_m - goal_distance, now.across_m));
    } else if (!now.holds(goal_distance)) {
      result.reached_s = -1;
    } else if (result.reached_s < 0) {
      result.reached_s = after;
    }
  }
  result.final = placement(base.pose(), object_at(seconds));
  const ObjectInBase seen = seen_from(base.pose(), object_at(seconds));
  result.final_distance_error_m = std::abs(seen.position.norm() - goal_distance);
  return result;
}

TEST(ClosedLoop, ReachesAndHoldsTheGoalInFrontOfAStaticObjectFromSeveralStarts) {
  // The object at the origin facing +x: the goal is (1.5, 0), the base should face -x there.
  const WorldObject object{{0, 0}, {1, 0}};
  struct Start {
    sim::BasePose pose;
    const char* what;
  };
  const std::vector<Start> starts = {
      {{5, 0, 180 * kDegree}, "far, facing the object"},
      {{5, 0, 0}, "far, facing away (backs up)"},
      {{3, 3, -90 * kDegree}, "off to the left, heading across"},
      {{1.5, -2.5, 90 * kDegree}, "to the right, heading toward the goal"},
      {{0.8, 1.0, 0}, "beside the object"},
      {{4, -2, 45 * kDegree}, "far right, heading away"},
      {{1.5, 0, 90 * kDegree}, "on the goal, turned away (turns only)"},
  };
  std::printf(
      "| start (x, y, yaw) | reached after s | final distance error m | across m | "
      "pointing error deg |\n");
  for (const Start& start : starts) {
    const LoopResult result = run_loop(
        start.pose, [&](double) { return object; }, 40);
    std::printf("| %.1f, %.1f, %.0f deg (%s) | %.2f | %.4f | %.4f | %.2f |\n", start.pose.x,
                start.pose.y, start.pose.yaw / kDegree, start.what, result.reached_s,
                result.final_distance_error_m, result.final.across_m,
                result.final.pointing_error_rad / kDegree);
    EXPECT_GE(result.reached_s, 0) << start.what << ": not holding the goal at the end";
    EXPECT_LT(result.reached_s, 20) << start.what;
    EXPECT_TRUE(result.final.holds(1.5)) << start.what;
    EXPECT_LT(result.final_distance_error_m, kHoldTolerance) << start.what;
    // Arrival is within 5 cm of the goal (the arrival tolerance, plus a little braking).
    EXPECT_LT(std::hypot(result.final.along_m - 1.5, result.final.across_m), 0.06) << start.what;
  }
}

TEST(ClosedLoop, FollowsAWalkingObjectAndSettlesWhenItStops) {
  // The object walks at 0.5 m/s for 6 s (3 m), facing +x throughout, then stands still.
  struct Walk {
    Eigen::Vector2d direction;
    const char* what;
  };
  const std::vector<Walk> walks = {
      {{-1, 0}, "away from the base"},
      {{1, 0}, "toward the base (it backs up)"},
      {{0, 1}, "sideways"},
      {Eigen::Vector2d(-1, 1).normalized(), "away and sideways"},
  };
  constexpr double kWalkSeconds = 6;
  std::printf(
      "| walk | largest goal distance while walking m | reached after stop s | "
      "final distance error m |\n");
  for (const Walk& walk : walks) {
    auto object_at = [&](double t) {
      return WorldObject{0.5 * std::min(t, kWalkSeconds) * walk.direction, {1, 0}};
    };
    const LoopResult result = run_loop({1.5, 0, 180 * kDegree}, object_at, 40, kWalkSeconds);
    std::printf("| %s | %.3f | %.2f | %.4f |\n", walk.what, result.max_goal_distance_while_moving_m,
                result.reached_s - kWalkSeconds, result.final_distance_error_m);
    // Following: the base never falls more than a metre behind the moving goal.
    EXPECT_LT(result.max_goal_distance_while_moving_m, 1.0) << walk.what;
    EXPECT_GE(result.reached_s, kWalkSeconds) << walk.what;
    EXPECT_LT(result.reached_s - kWalkSeconds, 15) << walk.what;
    EXPECT_TRUE(result.final.holds(1.5)) << walk.what;
    EXPECT_LT(result.final_distance_error_m, kHoldTolerance) << walk.what;
  }
}

// The follower's options name a field of their parts by its path; the limiter's own are named
// by the limiter.
TEST(FollowerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(FollowerOptions{}.problem(), std::nullopt);
  EXPECT_EQ(AccelerationLimits{}.problem(), std::nullopt);
  // Infinite: no limit.
  EXPECT_EQ((AccelerationLimits{.max_linear_accel_mps2 = std::numeric_limits<double>::infinity(),
                                .max_angular_accel_rps2 = 3}
                 .problem()),
            std::nullopt);
  EXPECT_EQ(AccelerationLimits{.max_angular_accel_rps2 = -1}.problem(),
            "max_angular_accel_rps2: -1 is not above 0");
  FollowerOptions options;
  options.drive.linear_gain = 0;
  EXPECT_EQ(options.problem(), "drive.linear_gain: 0 is not above 0");
  options = {};
  options.acceleration.max_linear_accel_mps2 = 0;
  EXPECT_EQ(options.problem(), "acceleration.max_linear_accel_mps2: 0 is not above 0");
  options = {};
  options.control_period_s = 0;
  EXPECT_EQ(options.problem(), "control_period_s: 0 is not above 0");
  options = {};
  options.drive.linear_gain = 0;
  try {
    DriveFollower follower(options);
    ADD_FAILURE() << "a gain of 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "FollowerOptions::drive.linear_gain: 0 is not above 0");
  }
  try {
    AccelerationLimiter limiter({.max_linear_accel_mps2 = 0});
    ADD_FAILURE() << "a limit of 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "AccelerationLimits::max_linear_accel_mps2: 0 is not above 0");
  }
}

}  // namespace
}  // namespace mocap::drive
