// The poses as ROS 2 tools read them: body_frames (REP 103 frames, a body seen from another
// frame, Odometry's twist in the body frame) checked against finite differences and rotations
// worked out by hand, and the pose_outputs plugin in a graph, its messages against the pose it
// was given.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <vector>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <nav_msgs/msg/odometry.hpp>
#include <tf2_msgs/msg/tf_message.hpp>

#include "common/pose_message/pose_message.hpp"
#include "host/plugin_loader.hpp"
#include "outputs/body_frames/body_frames.hpp"
#include "test/outputs/pose_feeder.hpp"
#include "test/test_support.hpp"

namespace mocap::outputs {
namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

Isometry3d random_pose(std::mt19937& generator) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::Quaterniond q(uniform(generator), uniform(generator), uniform(generator),
                       uniform(generator));
  Isometry3d pose = Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = Vector3d(uniform(generator), uniform(generator), uniform(generator)) * 3;
  return pose;
}

Matrix3d exp_rotation(const Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0) return Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

// REP 103: the optical frame's z is the camera's x (forward), its x the camera's -y (right),
// its y the camera's -z (down); the same rotation as roll -90°, pitch 0, yaw -90°.
TEST(BodyFrames, TheOpticalFrameInTheCameraBodyFrameIsRep103s) {
  const Matrix3d body_from_optical = optical_in_body().toRotationMatrix();
  EXPECT_TRUE(body_from_optical.col(2).isApprox(Vector3d::UnitX(), 1e-15));
  EXPECT_TRUE(body_from_optical.col(0).isApprox(-Vector3d::UnitY(), 1e-15));
  EXPECT_TRUE(body_from_optical.col(1).isApprox(-Vector3d::UnitZ(), 1e-15));
  const Isometry3d rpy = from_xyz_rpy(Vector3d::Zero(), Vector3d(-M_PI / 2, 0, -M_PI / 2));
  EXPECT_TRUE(rpy.linear().isApprox(body_from_optical, 1e-15));
}

TEST(BodyFrames, RollPitchYawTurnAboutFixedXThenYThenZ) {
  // Yaw 90° alone: x goes to y.
  Isometry3d yaw = from_xyz_rpy(Vector3d(1, 2, 3), Vector3d(0, 0, M_PI / 2));
  EXPECT_TRUE((yaw.linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitY(), 1e-15));
  EXPECT_TRUE(yaw.translation().isApprox(Vector3d(1, 2, 3)));
  // Roll 90°, then yaw 90° (fixed axes): y goes to z by the roll, and z stays z.
  Isometry3d both = from_xyz_rpy(Vector3d::Zero(), Vector3d(M_PI / 2, 0, M_PI / 2));
  EXPECT_TRUE((both.linear() * Vector3d::UnitY()).isApprox(Vector3d::UnitZ(), 1e-15));
  // And x goes to y by the yaw alone.
  EXPECT_TRUE((both.linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitY(), 1e-15));
}

// A moving body seen from another fixed frame: the velocities there are the finite differences
// of its poses seen from there, and Odometry's twist (in the body frame) those of its motion
// relative to itself.
TEST(BodyFrames, VelocitiesSeenFromAnotherFrameAndInTheBodyAgreeWithFiniteDifferences) {
  std::mt19937 generator(5);
  for (int trial = 0; trial < 20; ++trial) {
    const Isometry3d new_from_parent = random_pose(generator);
    BodyState body;
    body.parent_from_body = random_pose(generator);
    std::uniform_real_distribution<double> uniform(-2, 2);
    body.linear_velocity = Vector3d(uniform(generator), uniform(generator), uniform(generator));
    body.angular_velocity = Vector3d(uniform(generator), uniform(generator), uniform(generator));

    // The body dt later, in the parent: origin moved by v dt, axes turned by exp([w] dt).
    const double dt = 1e-6;
    Isometry3d later = body.parent_from_body;
    later.translation() += body.linear_velocity * dt;
    later.linear() = exp_rotation(body.angular_velocity * dt) * later.linear();

    const BodyState seen = seen_from(new_from_parent, body);
    const Isometry3d seen_later = new_from_parent * later;
    EXPECT_TRUE(seen.parent_from_body.isApprox(new_from_parent * body.parent_from_body, 1e-12));
    EXPECT_TRUE(((seen_later.translation() - seen.parent_from_body.translation()) / dt)
                    .isApprox(seen.linear_velocity, 1e-5))
        << trial;
    const Eigen::AngleAxisd turn(seen_later.linear() * seen.parent_from_body.linear().transpose());
    EXPECT_TRUE((turn.axis() * turn.angle() / dt).isApprox(seen.angular_velocity, 1e-5)) << trial;

    // In the body frame: the motion of `later` relative to the body now.
    const BodyTwist twist = twist_in_body(body);
    const Isometry3d relative = body.parent_from_body.inverse() * later;
    EXPECT_TRUE((relative.translation() / dt).isApprox(twist.linear, 1e-5)) << trial;
    // Rotating the body's axes by [w] in the parent is rotating them by R^T w about their own.
    const Eigen::AngleAxisd own(relative.linear());
    EXPECT_TRUE((own.axis() * own.angle() / dt).isApprox(twist.angular, 1e-5)) << trial;
  }
}

// A position uncertainty along the parent's x is one along the new frame's image of that axis.
TEST(BodyFrames, CovariancesTurnWithTheFrame) {
  BodyState body;
  body.pose_covariance(0, 0) = 4;  // 2 m along the parent's x
  body.pose_covariance(5, 5) = 9;  // 3 rad about the parent's z
  body.velocity_covariance(1, 1) = 1;
  const Isometry3d yaw = from_xyz_rpy(Vector3d(5, 0, 0), Vector3d(0, 0, M_PI / 2));
  const BodyState seen = seen_from(yaw, body);
  Matrix6d expected = Matrix6d::Zero();
  expected(1, 1) = 4;  // the parent's x is the new y
  expected(5, 5) = 9;  // z stays z
  EXPECT_TRUE(seen.pose_covariance.isApprox(expected, 1e-12)) << seen.pose_covariance;
  EXPECT_NEAR(seen.velocity_covariance(0, 0), 1, 1e-12);  // the parent's y is the new -x

  // Odometry's twist covariance is in the body frame: a body turned by yaw 90° in its parent
  // sees the parent's y velocity uncertainty along its own -x.
  body.parent_from_body = yaw;
  EXPECT_NEAR(twist_in_body(body).covariance(0, 0), 1, 1e-12);
  EXPECT_NEAR(twist_in_body(body).covariance(1, 1), 0, 1e-12);
}

// --- the plugin in a graph --------------------------------------------------------------------

using geometry_msgs::msg::PoseStamped;
using mocap_msgs::msg::ConstellationPoseArray;
using nav_msgs::msg::Odometry;
using tf2_msgs::msg::TFMessage;

using Feeder = test::PoseFeeder;

class Collector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    // As the outputs publish (best effort), with room for every sample of a test: a collector
    // slowed by a sanitizer must not drop what it counts.
    Qos sensor_data = Qos::sensor_data();
    sensor_data.depth = 1000;
    spec.subscribes<PoseStamped>("/mocap/board_a/pose", sensor_data, "");
    spec.subscribes<Odometry>("/mocap/board_a/odom", sensor_data, "");
    spec.subscribes<TFMessage>("/tf", Qos::reliable(), "");
    spec.subscribes<TFMessage>("/tf_static", Qos::latched(), "");
  }
  explicit Collector(Context& context) : Component(context) {
    create_subscription<PoseStamped>(
        "/mocap/board_a/pose", [this](const PoseStamped& m) { add([&] { poses.push_back(m); }); });
    create_subscription<Odometry>("/mocap/board_a/odom",
                                  [this](const Odometry& m) { add([&] { odoms.push_back(m); }); });
    create_subscription<TFMessage>("/tf",
                                   [this](const TFMessage& m) { add([&] { tf.push_back(m); }); });
    create_subscription<TFMessage>(
        "/tf_static", [this](const TFMessage& m) { add([&] { tf_static.push_back(m); }); });
  }
  template <class F>
  void add(F&& f) {
    std::lock_guard lock(mutex);
    f();
    arrived.notify_all();
  }
  bool wait_for(size_t count, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return arrived.wait_for(lock, timeout, [&] {
      return poses.size() >= count && odoms.size() >= count && tf.size() >= count &&
             !tf_static.empty();
    });
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<PoseStamped> poses;
  std::vector<Odometry> odoms;
  std::vector<TFMessage> tf, tf_static;
};

Isometry3d isometry_of(const geometry_msgs::msg::Transform& t) {
  geometry_msgs::msg::Pose pose;
  pose.position().x(t.translation().x());
  pose.position().y(t.translation().y());
  pose.position().z(t.translation().z());
  pose.orientation(t.rotation());
  return *to_isometry(pose);
}

Vector3d vector_of(const geometry_msgs::msg::Vector3& v) { return {v.x(), v.y(), v.z()}; }

Matrix6d matrix_of(const std::array<double, 36>& row_major) {
  return Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(row_major.data());
}

struct Graph {
  explicit Graph(std::map<std::string, ParameterValue> parameters)
      : host({.name = "test", .threads = 2, .dds = {.enabled = false}}) {
    collector = &static_cast<Collector&>(
        host.add(make_component_factory<Collector>("collector"), {.name = "collector"}));
    feeder = &static_cast<Feeder&>(
        host.add(make_component_factory<Feeder>("feeder"), {.name = "feeder"}));
    host.add(*loader.load("pose_outputs").factory,
             {.name = "outputs", .parameters = std::move(parameters)});
    host.start();
  }
  PluginLoader loader;
  ComponentHost host;
  Collector* collector = nullptr;
  Feeder* feeder = nullptr;
};

// One board with a pose, a velocity and covariances in the camera's optical frame, at 30 Hz.
ConstellationPoseArray board_a(const Isometry3d& optical_from_board, int64_t stamp_ns) {
  ConstellationPoseArray array;
  array.header().stamp(
      to_time_msg(std::chrono::system_clock::time_point(std::chrono::nanoseconds(stamp_ns))));
  array.header().frame_id("camera_ir_optical");
  mocap_msgs::msg::ConstellationPose pose;
  pose.name("board_a");
  pose.pose().header(array.header());
  pose.pose().pose(to_pose_message(optical_from_board));
  for (int i = 0; i < 6; ++i) {
    pose.covariance()[static_cast<size_t>(7 * i)] = 1e-6 * (i + 1);
    pose.velocity_covariance()[static_cast<size_t>(7 * i)] = 1e-4 * (i + 1);
  }
  pose.covariance()[1] = pose.covariance()[6] = 2e-7;  // x-y correlation
  pose.velocity().linear().x(0.5);
  pose.velocity().linear().z(-0.25);
  pose.velocity().angular().y(1.5);
  array.poses().push_back(pose);
  return array;
}

TEST(PoseOutputs, InTheWorldFramePoseOdometryAndTfAgreeWithTheTrackedPose) {
  const std::vector<double> mounting = {1.0, 2.0, 0.5, 0.1, -0.2, 0.3};
  Graph graph({{"parent", std::string("world")}, {"camera_in_world", mounting}});
  std::mt19937 generator(9);
  const Isometry3d optical_from_board = random_pose(generator);
  const int64_t stamp_ns = 1'700'000'000'123'456'789;
  graph.feeder->publisher.publish(board_a(optical_from_board, stamp_ns));
  ASSERT_TRUE(graph.collector->wait_for(1, std::chrono::seconds(10)));
  std::lock_guard lock(graph.collector->mutex);
  const Collector& got = *graph.collector;

  // /tf_static: world -> camera_ir (the mounting) -> camera_ir_optical (REP 103).
  ASSERT_EQ(got.tf_static[0].transforms().size(), 2u);
  const auto& mounted = got.tf_static[0].transforms()[0];
  EXPECT_EQ(mounted.header().frame_id(), "world");
  EXPECT_EQ(mounted.child_frame_id(), "camera_ir");
  const Isometry3d world_from_camera =
      from_xyz_rpy(Vector3d(1.0, 2.0, 0.5), Vector3d(0.1, -0.2, 0.3));
  EXPECT_TRUE(isometry_of(mounted.transform()).isApprox(world_from_camera, 1e-12));
  const auto& optical = got.tf_static[0].transforms()[1];
  EXPECT_EQ(optical.header().frame_id(), "camera_ir");
  EXPECT_EQ(optical.child_frame_id(), "camera_ir_optical");
  EXPECT_NEAR(optical.transform().rotation().x(), -0.5, 1e-15);
  EXPECT_NEAR(optical.transform().rotation().y(), 0.5, 1e-15);
  EXPECT_NEAR(optical.transform().rotation().z(), -0.5, 1e-15);
  EXPECT_NEAR(optical.transform().rotation().w(), 0.5, 1e-15);

  // The board through the tree equals the board on /tf, in the pose and in the odometry.
  const Isometry3d world_from_board =
      world_from_camera * isometry_of(optical.transform()) * optical_from_board;
  ASSERT_EQ(got.tf[0].transforms().size(), 1u);
  const auto& board = got.tf[0].transforms()[0];
  EXPECT_EQ(board.header().frame_id(), "world");
  EXPECT_EQ(board.child_frame_id(), "board_a");
  EXPECT_EQ(to_nanoseconds(board.header().stamp()), stamp_ns);
  EXPECT_TRUE(isometry_of(board.transform()).isApprox(world_from_board, 1e-12));
  EXPECT_EQ(got.poses[0].header().frame_id(), "world");
  EXPECT_EQ(to_nanoseconds(got.poses[0].header().stamp()), stamp_ns);
  EXPECT_TRUE(to_isometry(got.poses[0].pose())->isApprox(world_from_board, 1e-12));
  const Odometry& odom = got.odoms[0];
  EXPECT_EQ(odom.header().frame_id(), "world");
  EXPECT_EQ(odom.child_frame_id(), "board_a");
  EXPECT_EQ(to_nanoseconds(odom.header().stamp()), stamp_ns);
  EXPECT_TRUE(to_isometry(odom.pose().pose())->isApprox(world_from_board, 1e-12));

  // Velocities: given in the optical frame; Odometry's twist is in the board's frame.
  const Matrix3d board_from_optical = optical_from_board.linear().transpose();
  EXPECT_TRUE(vector_of(odom.twist().twist().linear())
                  .isApprox(board_from_optical * Vector3d(0.5, 0, -0.25), 1e-12));
  EXPECT_TRUE(vector_of(odom.twist().twist().angular())
                  .isApprox(board_from_optical * Vector3d(0, 1.5, 0), 1e-12));
  // Covariances: the pose's turned into the world, the twist's into the board's frame.
  const Matrix3d world_from_optical = world_from_board.linear() * board_from_optical;
  Matrix6d turn = Matrix6d::Zero();
  turn.topLeftCorner<3, 3>() = turn.bottomRightCorner<3, 3>() = world_from_optical;
  const ConstellationPoseArray given = board_a(optical_from_board, stamp_ns);
  EXPECT_TRUE(
      matrix_of(odom.pose().covariance())
          .isApprox(turn * matrix_of(given.poses()[0].covariance()) * turn.transpose(), 1e-12));
  turn.topLeftCorner<3, 3>() = turn.bottomRightCorner<3, 3>() = board_from_optical;
  EXPECT_TRUE(
      matrix_of(odom.twist().covariance())
          .isApprox(turn * matrix_of(given.poses()[0].velocity_covariance()) * turn.transpose(),
                    1e-12));
}

// In the camera frame (the default) the numbers are /mocap/poses' own; rates are kept by the
// poses' stamps: at 30 Hz in, 10 Hz out, every third.
TEST(PoseOutputs, InTheCameraFrameAtTheRatesAskedByTheStamps) {
  Graph graph({{"pose_rate_hz", 10.0}, {"odom_rate_hz", 15.0}});
  std::mt19937 generator(4);
  const Isometry3d optical_from_board = random_pose(generator);
  const int64_t start_ns = 1'700'000'000'000'000'000;
  const int64_t frame_ns = 33'333'333;
  for (int k = 0; k < 30; ++k) {
    // One at a time: the best-effort outputs keep a short queue.
    graph.feeder->publisher.publish(board_a(optical_from_board, start_ns + k * frame_ns));
    std::unique_lock lock(graph.collector->mutex);
    ASSERT_TRUE(graph.collector->arrived.wait_for(lock, std::chrono::seconds(10), [&] {
      return graph.collector->tf.size() > static_cast<size_t>(k);
    }));
  }
  {
    // The best-effort outputs' callbacks may still be on their way after the last /tf.
    std::unique_lock lock(graph.collector->mutex);
    graph.collector->arrived.wait_for(lock, std::chrono::seconds(10), [&] {
      return graph.collector->poses.size() >= 10 && graph.collector->odoms.size() >= 15;
    });
  }
  graph.host.stop();
  const Collector& got = *graph.collector;
  EXPECT_EQ(got.tf.size(), 30u);
  ASSERT_EQ(got.poses.size(), 10u);
  EXPECT_EQ(got.odoms.size(), 15u);
  for (size_t i = 0; i < got.poses.size(); ++i) {
    EXPECT_EQ(to_nanoseconds(got.poses[i].header().stamp()),
              start_ns + 3 * static_cast<int64_t>(i) * frame_ns);
    EXPECT_EQ(got.poses[i].header().frame_id(), "camera_ir_optical");
    EXPECT_TRUE(to_isometry(got.poses[i].pose())->isApprox(optical_from_board, 1e-12));
  }
  EXPECT_EQ(got.tf[0].transforms()[0].header().frame_id(), "camera_ir_optical");
}

TEST(PoseOutputs, BadParametersAreNamed) {
  PluginLoader loader;
  for (const auto& [parameters, message] :
       std::vector<std::pair<std::map<std::string, ParameterValue>, std::string>>{
           {{{"parent", std::string("map")}}, "parent: 'map'; expected camera or world"},
           {{{"camera_in_world", std::vector<double>{1, 2, 3}}},
            "camera_in_world: expected 6 numbers (x, y, z, roll, pitch, yaw), got 3"},
           {{{"camera_frame", std::string()}}, "camera_frame is empty"}}) {
    ComponentHost host({.name = "test", .threads = 1, .dds = {.enabled = false}});
    try {
      host.add(*loader.load("pose_outputs").factory, {.name = "outputs", .parameters = parameters});
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mocap::outputs
