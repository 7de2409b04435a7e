// PX4 external vision: our REP 103 state in PX4's frames (px4_frames), checked on a table of
// poses worked out by hand and against a quaternion rotation written out here; a body carried
// on a lever arm against finite differences; VehicleOdometry's bytes against the layout of
// px4_msgs' definition; and the px4_odometry plugin in a graph.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <px4_msgs/msg/vehicle_odometry.hpp>

#include "common/pose_message/pose_message.hpp"
#include "host/plugin_loader.hpp"
#include "outputs/body_frames/body_frames.hpp"
#include "outputs/px4_odometry/px4_odometry.hpp"
#include "test/outputs/pose_feeder.hpp"
#include "test/test_support.hpp"

namespace mocap::outputs {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double kExact = 1e-6;
const double kHalf = std::sqrt(0.5);

BodyState at(const Vector3d& position, const Vector3d& rpy) {
  BodyState body;
  body.parent_from_body = from_xyz_rpy(position, rpy);
  return body;
}

void expect_q(const Px4Odometry& odometry, std::array<double, 4> expected) {
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(odometry.q[i], expected[i], kExact) << i;
}

// FLU world and body to FRD: forward stays, left becomes right, up becomes down. A vehicle that
// turns left (+yaw about up) turns -90° about down; nose down (+pitch about left) is -90° about
// right; right wing down (+roll about forward) is +90° about forward.
TEST(Px4Frames, AKnownTableOfPosesInFrd) {
  {
    const Px4Odometry o = to_px4(at({1, 2, 3}, {0, 0, 0}), Px4Frame::Frd);
    EXPECT_TRUE(o.position.isApprox(Vector3d(1, -2, -3), kExact));
    expect_q(o, {1, 0, 0, 0});
    EXPECT_EQ(o.frame, Px4Frame::Frd);
  }
  expect_q(to_px4(at({0, 0, 0}, {0, 0, M_PI / 2}), Px4Frame::Frd), {kHalf, 0, 0, -kHalf});
  expect_q(to_px4(at({0, 0, 0}, {0, M_PI / 2, 0}), Px4Frame::Frd), {kHalf, 0, -kHalf, 0});
  expect_q(to_px4(at({0, 0, 0}, {M_PI / 2, 0, 0}), Px4Frame::Frd), {kHalf, kHalf, 0, 0});
}

// ENU to NED: east 1, north 2, up 3 is north 2, east 1, down -3. Heading north (yaw +90° in
// ENU) is yaw 0 in NED; heading east (yaw 0 in ENU) is yaw +90° (to the right of north).
TEST(Px4Frames, AKnownTableOfPosesInNed) {
  {
    const Px4Odometry o = to_px4(at({1, 2, 3}, {0, 0, M_PI / 2}), Px4Frame::Ned);
    EXPECT_TRUE(o.position.isApprox(Vector3d(2, 1, -3), kExact));
    expect_q(o, {1, 0, 0, 0});
  }
  expect_q(to_px4(at({0, 0, 0}, {0, 0, 0}), Px4Frame::Ned), {kHalf, 0, 0, kHalf});
  // Heading north, nose 90° up: pitch +90° in FRD terms.
  expect_q(to_px4(at({0, 0, 0}, {0, -M_PI / 2, M_PI / 2}), Px4Frame::Ned), {kHalf, 0, kHalf, 0});
}

// A robot of one marker: a position and its velocity, and NaN (PX4's "not measured") for the
// attitude, the angular velocity and their variances.
TEST(Px4Frames, ARobotOfOneMarkerHasNoAttitude) {
  BodyState robot = at({1, 2, 3}, {0, 0, 0});
  robot.pose_covariance.diagonal() << 1e-8, 1e-8, 1e-8, 1e9, 1e9, 1e9;
  robot.linear_velocity = Vector3d(0.5, 0, 0);
  const Px4Odometry o = to_px4(robot, Px4Frame::Ned);
  EXPECT_TRUE(o.position.isApprox(Vector3d(2, 1, -3), kExact));
  EXPECT_TRUE(o.velocity.isApprox(Vector3d(0, 0.5, 0), kExact));
  EXPECT_NEAR(o.position_variance.x(), 1e-8, 1e-20);
  for (double value : o.q) EXPECT_TRUE(std::isnan(value));
  EXPECT_TRUE(o.angular_velocity.array().isNaN().all());
  EXPECT_TRUE(o.orientation_variance.array().isNaN().all());
  // A measured attitude, however poor, stays.
  robot.pose_covariance.diagonal() << 1e-8, 1e-8, 1e-8, 1e9, 1e9, 1;
  EXPECT_FALSE(std::isnan(to_px4(robot, Px4Frame::Ned).q[0]));
}

// q as PX4 reads it, written out: v' = q v q*, (w, x, y, z).
Vector3d rotate(const std::array<double, 4>& q, const Vector3d& v) {
  const double w = q[0];
  const Vector3d u(q[1], q[2], q[3]);
  return 2 * u.dot(v) * u + (w * w - u.dot(u)) * v + 2 * w * u.cross(v);
}

// A general pose, velocities and covariances: a point on the vehicle (FRD body coordinates)
// lands where our pose puts it; velocities and variances turn as the frames do.
TEST(Px4Frames, AGeneralStateAgreesWithOurPoseThroughAWrittenOutRotation) {
  for (const Px4Frame frame : {Px4Frame::Frd, Px4Frame::Ned}) {
    BodyState vehicle = at({0.4, -1.2, 2.1}, {0.3, -0.7, 2.2});
    vehicle.linear_velocity = Vector3d(0.5, -0.25, 0.1);
    vehicle.angular_velocity = Vector3d(-0.2, 0.9, 0.4);
    vehicle.pose_covariance.diagonal() << 1e-4, 4e-4, 9e-4, 1e-2, 4e-2, 9e-2;
    vehicle.velocity_covariance.diagonal() << 1e-3, 2e-3, 3e-3, 1e-1, 2e-1, 3e-1;
    const Px4Odometry o = to_px4(vehicle, frame);
    const Eigen::Matrix3d world = frame == Px4Frame::Ned
                                      ? (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished()
                                      : Eigen::Matrix3d(Vector3d(1, -1, -1).asDiagonal());
    const Eigen::Matrix3d frd_from_flu = Vector3d(1, -1, -1).asDiagonal();
    const Vector3d point_frd(0.3, 0.2, -0.1);
    const Vector3d ours = world * (vehicle.parent_from_body * (frd_from_flu * point_frd));
    EXPECT_TRUE((rotate(o.q, point_frd) + o.position).isApprox(ours, kExact));
    EXPECT_NEAR(Eigen::Vector4d(o.q[0], o.q[1], o.q[2], o.q[3]).norm(), 1, kExact);
    EXPECT_GE(o.q[0], 0);
    EXPECT_TRUE(o.velocity.isApprox(world * vehicle.linear_velocity, kExact));
    // The body's angular velocity, in the body: rotating it into the world gives ours back.
    EXPECT_TRUE(rotate(o.q, o.angular_velocity).isApprox(world * vehicle.angular_velocity, kExact));
    EXPECT_TRUE(o.position_variance.isApprox(
        (world * vehicle.pose_covariance.topLeftCorner<3, 3>() * world.transpose()).diagonal(),
        kExact));
    // Variances are never negative, whatever the turn; their sum (the trace) is kept.
    EXPECT_NEAR(o.orientation_variance.sum(), 0.14, kExact);
    EXPECT_TRUE((o.orientation_variance.array() >= 0).all());
    EXPECT_NEAR(o.velocity_variance.sum(), 6e-3, kExact);
  }
}

// A vehicle 20 cm in front of the board: its origin moves with the board's turning.
TEST(BodyFrames, AnAttachedBodyMovesWithTheLeverArm) {
  BodyState board = at({1, 2, 3}, {0.2, 0.4, -0.6});
  board.linear_velocity = Vector3d(0.3, 0, -0.1);
  board.angular_velocity = Vector3d(0.5, -1.0, 2.0);
  board.pose_covariance(5, 5) = 0.01;  // 0.1 rad about the parent's z
  const Isometry3d board_from_vehicle = from_xyz_rpy({0.2, 0, 0}, {0, 0, M_PI});
  const BodyState vehicle = attached(board, board_from_vehicle);
  EXPECT_TRUE(vehicle.parent_from_body.isApprox(board.parent_from_body * board_from_vehicle));

  const double dt = 1e-6;
  Isometry3d later = board.parent_from_body;
  later.translation() += board.linear_velocity * dt;
  later.linear() =
      Eigen::AngleAxisd(board.angular_velocity.norm() * dt, board.angular_velocity.normalized()) *
      later.linear();
  const Vector3d moved =
      ((later * board_from_vehicle).translation() - vehicle.parent_from_body.translation()) / dt;
  EXPECT_TRUE(moved.isApprox(vehicle.linear_velocity, 1e-5));
  EXPECT_TRUE(vehicle.angular_velocity.isApprox(board.angular_velocity));
  // A rotation uncertainty about z swings the 20 cm arm sideways: 0.1 rad x 0.2 m = 2 cm,
  // across the arm and in the horizontal plane.
  const Vector3d arm =
      vehicle.parent_from_body.translation() - board.parent_from_body.translation();
  const Vector3d across = Vector3d::UnitZ().cross(arm).normalized();
  const double sideways =
      across.transpose() * vehicle.pose_covariance.topLeftCorner<3, 3>() * across;
  EXPECT_NEAR(std::sqrt(sideways), 0.1 * Vector3d(arm.x(), arm.y(), 0).norm(), 1e-12);
}

// The bytes on the wire, against px4_msgs' definition laid out by the XCDR1 rules (each field
// aligned to its size from the start of the payload, after the 4-byte encapsulation header).
TEST(Px4Odometry, TheBytesFollowPx4MsgsLayout) {
  px4_msgs::msg::VehicleOdometry message;
  message.timestamp(0x0102030405060708);
  message.timestamp_sample(0x1112131415161718);
  message.pose_frame(2);
  message.position({1.5f, -2.5f, 3.5f});
  message.q({0.5f, -0.5f, 0.5f, -0.5f});
  message.velocity_frame(2);
  message.velocity({0.1f, 0.2f, 0.3f});
  message.angular_velocity({-0.1f, -0.2f, -0.3f});
  message.position_variance({1e-4f, 2e-4f, 3e-4f});
  message.orientation_variance({1e-3f, 2e-3f, 3e-3f});
  message.velocity_variance({1e-2f, 2e-2f, 3e-2f});
  message.reset_counter(7);
  message.quality(-3);

  std::vector<uint8_t> expected(4 + 114, 0);
  expected[1] = 0x01;  // CDR, little endian
  auto put = [&](size_t offset, const auto& value) {
    std::memcpy(expected.data() + 4 + offset, &value, sizeof value);
  };
  put(0, uint64_t{0x0102030405060708});
  put(8, uint64_t{0x1112131415161718});
  put(16, uint8_t{2});
  put(20, std::array<float, 3>{1.5f, -2.5f, 3.5f});
  put(32, std::array<float, 4>{0.5f, -0.5f, 0.5f, -0.5f});
  put(48, uint8_t{2});
  put(52, std::array<float, 3>{0.1f, 0.2f, 0.3f});
  put(64, std::array<float, 3>{-0.1f, -0.2f, -0.3f});
  put(76, std::array<float, 3>{1e-4f, 2e-4f, 3e-4f});
  put(88, std::array<float, 3>{1e-3f, 2e-3f, 3e-3f});
  put(100, std::array<float, 3>{1e-2f, 2e-2f, 3e-2f});
  put(112, uint8_t{7});
  put(113, int8_t{-3});

  const MessageType& type = message_type<px4_msgs::msg::VehicleOdometry>();
  EXPECT_EQ(type.dds_name(), "px4_msgs::msg::dds_::VehicleOdometry_");
  std::vector<uint8_t> bytes(type.serialized_size(&message), 0);
  bytes.resize(type.serialize(&message, bytes));
  EXPECT_EQ(bytes, expected);
}

// --- the plugin in a graph --------------------------------------------------------------------

using mocap_msgs::msg::ConstellationPoseArray;
using px4_msgs::msg::VehicleOdometry;

using Feeder = test::PoseFeeder;

class Collector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<VehicleOdometry>("/fmu/in/vehicle_visual_odometry", Qos::reliable(), "");
  }
  explicit Collector(Context& context) : Component(context) {
    create_subscription<VehicleOdometry>("/fmu/in/vehicle_visual_odometry",
                                         [this](const VehicleOdometry& m) {
                                           std::lock_guard lock(mutex);
                                           received.push_back(m);
                                           arrived.notify_all();
                                         });
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<VehicleOdometry> received;
};

// A board 2 m in front of a camera looking north, level, at 1 m height in an ENU world, carried
// level and facing north by a vehicle. 100 Hz in, 50 out.
TEST(Px4Odometry, ThePluginSendsTheVehiclesStateInNedAtItsRate) {
  PluginLoader loader;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  auto& collector = static_cast<Collector&>(
      host.add(make_component_factory<Collector>("collector"), {.name = "collector"}));
  auto& feeder =
      static_cast<Feeder&>(host.add(make_component_factory<Feeder>("feeder"), {.name = "feeder"}));
  // Camera at (0, 0, 1) heading north (yaw +90° in ENU).
  host.add(*loader.load("px4_odometry").factory,
           {.name = "px4",
            .parameters = {{"board", std::string("drone")},
                           {"pose_frame", std::string("ned")},
                           {"camera_in_world", std::vector<double>{0, 0, 1, 0, 0, M_PI / 2}},
                           {"rate_hz", 50.0}}});
  host.start();

  // In the optical frame (z forward = north, x right = east, y down): 2 m ahead, its axes the
  // vehicle's FLU (vehicle_in_board is the identity): x north (optical z), y west (optical
  // -x), z up (optical -y).
  Isometry3d optical_from_board = Isometry3d::Identity();
  optical_from_board.translation() = Vector3d(0, 0, 2);
  optical_from_board.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const int64_t start_ns = 1'700'000'000'000'000'000;
  for (int k = 0; k < 10; ++k) {
    ConstellationPoseArray array;
    array.header().stamp(to_time_msg(std::chrono::system_clock::time_point(
        std::chrono::nanoseconds(start_ns + k * 10'000'000))));
    array.header().frame_id("camera_ir_optical");
    mocap_msgs::msg::ConstellationPose pose;
    pose.name("drone");
    pose.pose().header(array.header());
    pose.pose().pose(to_pose_message(optical_from_board));
    pose.velocity().linear().x(1.0);  // east, in the optical frame's x
    array.poses().push_back(pose);
    feeder.publisher.publish(array);
  }
  std::unique_lock lock(collector.mutex);
  ASSERT_TRUE(collector.arrived.wait_for(lock, std::chrono::seconds(10),
                                         [&] { return collector.received.size() >= 5; }));
  lock.unlock();
  host.stop();
  ASSERT_EQ(collector.received.size(), 5u);  // every other one of 100 Hz
  const VehicleOdometry& first = collector.received[0];
  EXPECT_EQ(first.timestamp_sample(), static_cast<uint64_t>(start_ns / 1000));
  EXPECT_EQ(collector.received[1].timestamp_sample(),
            static_cast<uint64_t>(start_ns / 1000 + 20'000));
  EXPECT_EQ(first.pose_frame(), 1);  // NED
  EXPECT_EQ(first.velocity_frame(), 1);
  // Board 2 m north of the camera, 1 m up: NED (2, 0, -1); the vehicle faces north: q = 1.
  EXPECT_NEAR(first.position()[0], 2, 1e-6);
  EXPECT_NEAR(first.position()[1], 0, 1e-6);
  EXPECT_NEAR(first.position()[2], -1, 1e-6);
  EXPECT_NEAR(first.q()[0], 1, 1e-6);
  EXPECT_NEAR(first.velocity()[0], 0, 1e-6);  // moving east: NED (0, 1, 0)
  EXPECT_NEAR(first.velocity()[1], 1, 1e-6);
  EXPECT_NEAR(first.velocity()[2], 0, 1e-6);
}

// A swarm: one px4_odometry per vehicle, each remapped into its vehicle's namespace as PX4's
// multi-vehicle uXRCE-DDS clients have them (/px4_1/fmu/in/..., /px4_2/fmu/in/...), each
// sending its own robot of the volume's poses (frame world, ENU): a quadrotor with its
// attitude, a robot of one marker with NaN there (PX4's mark of an invalid field).
TEST(Px4Odometry, OnePerVehicleEachInItsVehiclesNamespace) {
  PluginLoader loader;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  const std::vector<std::string> robots = {"cf01", "rover01"};
  std::vector<Collector*> collectors;
  for (size_t v = 0; v < robots.size(); ++v) {
    const std::string topic = fmt::format("/px4_{}/fmu/in/vehicle_visual_odometry", v + 1);
    collectors.push_back(&static_cast<Collector&>(
        host.add(make_component_factory<Collector>("collector"),
                 {.name = "collector_" + robots[v],
                  .remaps = {{"/fmu/in/vehicle_visual_odometry", topic}}})));
    host.add(*loader.load("px4_odometry").factory,
             {.name = "px4_" + robots[v],
              .parameters = {{"board", robots[v]},
                             {"pose_frame", std::string("ned")},
                             {"optical_frame", std::string("world")},
                             {"camera_in_world", std::vector<double>{}},
                             {"rate_hz", 0.0}},
              .remaps = {{"/fmu/in/vehicle_visual_odometry", topic}}});
  }
  auto& feeder =
      static_cast<Feeder&>(host.add(make_component_factory<Feeder>("feeder"), {.name = "feeder"}));
  host.start();

  Isometry3d world_from_quadrotor = Isometry3d::Identity();
  world_from_quadrotor.translation() = Vector3d(1, 2, 1.5);
  Isometry3d world_from_rover = Isometry3d::Identity();
  world_from_rover.translation() = Vector3d(-1, 0.5, 0);
  for (int k = 0; k < 3; ++k) {
    ConstellationPoseArray array;
    array.header().stamp(to_time_msg(std::chrono::system_clock::time_point(
        std::chrono::nanoseconds(1'700'000'000'000'000'000 + k * 4'166'667))));
    array.header().frame_id("world");
    auto add = [&](const std::string& name, const Isometry3d& pose, double orientation_variance) {
      mocap_msgs::msg::ConstellationPose robot;
      robot.name(name);
      robot.pose().header(array.header());
      robot.pose().pose(to_pose_message(pose));
      for (size_t i = 0; i < 6; ++i)
        robot.covariance()[7 * i] = i < 3 ? 1e-8 : orientation_variance;
      array.poses().push_back(robot);
    };
    add("cf01", world_from_quadrotor, 1e-4);
    add("rover01", world_from_rover, 1e9);
    feeder.publisher.publish(array);
  }
  for (Collector* collector : collectors) {
    std::unique_lock lock(collector->mutex);
    ASSERT_TRUE(collector->arrived.wait_for(lock, std::chrono::seconds(10),
                                            [&] { return collector->received.size() >= 3; }));
  }
  host.stop();
  ASSERT_EQ(collectors[0]->received.size(), 3u);
  ASSERT_EQ(collectors[1]->received.size(), 3u);
  // ENU (1, 2, 1.5) is NED (2, 1, -1.5); level and facing east (x east in ENU): yaw 90° in NED.
  const VehicleOdometry& quadrotor = collectors[0]->received[0];
  EXPECT_NEAR(quadrotor.position()[0], 2, 1e-6);
  EXPECT_NEAR(quadrotor.position()[1], 1, 1e-6);
  EXPECT_NEAR(quadrotor.position()[2], -1.5, 1e-6);
  EXPECT_NEAR(std::abs(quadrotor.q()[0]), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(std::abs(quadrotor.q()[3]), std::sqrt(0.5), 1e-6);
  const VehicleOdometry& rover = collectors[1]->received[0];
  EXPECT_NEAR(rover.position()[0], 0.5, 1e-6);
  EXPECT_NEAR(rover.position()[1], -1, 1e-6);
  EXPECT_NEAR(rover.position()[2], 0, 1e-6);
  for (float q : rover.q()) EXPECT_TRUE(std::isnan(q));
}

}  // namespace
}  // namespace mocap::outputs
