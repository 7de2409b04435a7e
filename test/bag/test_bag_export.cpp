// `mocap_bag export`: a bag of known poses written out and read back by a reader of each format
// written from its description (test/bag/tum_read.mjs, trc_read.mjs), values equal to the
// micrometre; a bag without poses and a body not in it are named.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include <mocap/bag/bag_writer.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <nlohmann/json.hpp>

#include "test/test_support.hpp"

namespace mocap {
namespace {

using json = nlohmann::json;

constexpr int64_t kStart = 1'700'000'000'123'456'789;
constexpr int64_t kPeriod = 8'333'333;

// Frame k: "wand" everywhere, turning; "drone" lost between frames 40 and 59; one pose that is
// no pose (frame 7, a zero quaternion).
struct Truth {
  Eigen::Vector3d position;
  Eigen::Quaterniond orientation;
};
Truth wand(int k) {
  return {Eigen::Vector3d(0.001 * k, -1.234567891, 2.0 + 1e-7 * k),
          Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d(1, 2, 3).normalized()))};
}
Truth drone(int k) {
  return {Eigen::Vector3d(-0.5, 0.25 * std::sin(0.1 * k), 1.5),
          Eigen::Quaterniond(Eigen::AngleAxisd(M_PI - 0.01 * k, Eigen::Vector3d::UnitZ()))};
}
bool drone_seen(int k) { return k < 40 || k >= 60; }

mocap_msgs::msg::ConstellationPose pose_of(const std::string& name, const Truth& truth) {
  mocap_msgs::msg::ConstellationPose pose;
  pose.name(name);
  auto& p = pose.pose().pose();
  p.position().x(truth.position.x());
  p.position().y(truth.position.y());
  p.position().z(truth.position.z());
  p.orientation().x(truth.orientation.x());
  p.orientation().y(truth.orientation.y());
  p.orientation().z(truth.orientation.z());
  p.orientation().w(truth.orientation.w());
  return pose;
}

void write_bag(const std::filesystem::path& path, int frames, bool with_poses) {
  bag::BagWriter writer(path.string());
  const MessageType& type = message_type<mocap_msgs::msg::ConstellationPoseArray>();
  const uint32_t id =
      writer.add_topic({with_poses ? "/mocap/poses" : "/other", type.name(), "cdr", {}, 0});
  for (int k = 0; k < frames; ++k) {
    mocap_msgs::msg::ConstellationPoseArray array;
    const int64_t stamp = kStart + k * kPeriod;
    array.header().stamp(
        to_time_msg(std::chrono::system_clock::time_point(std::chrono::nanoseconds(stamp))));
    array.header().frame_id("world");
    array.poses().push_back(pose_of("wand", wand(k)));
    if (drone_seen(k)) array.poses().push_back(pose_of("drone", drone(k)));
    if (k == 7)
      array.poses().push_back(
          pose_of("ghost", {Eigen::Vector3d::Zero(), Eigen::Quaterniond(0, 0, 0, 0)}));
    std::vector<uint8_t> data(type.serialized_size(&array));
    data.resize(type.serialize(&array, data));
    writer.write(id, stamp + 1'000'000, data);
  }
  writer.close();
}

std::pair<int, std::string> mocap_bag(std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), (test::bin_dir() / "mocap_bag").string());
  return test::run_command(arguments, {}, std::chrono::seconds(60));
}

TEST(BagExport, TumFilesReadBackAsTheBagsPosesToTheMicrometre) {
  test::TempDir dir;
  write_bag(dir / "bag", 100, true);
  const auto [code, output] = mocap_bag(
      {"export", (dir / "bag").string(), "--format", "tum", "-o", (dir / "tum").string()});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("wand.tum: 100 poses"), std::string::npos) << output;
  EXPECT_NE(output.find("drone.tum: 80 poses"), std::string::npos) << output;
  EXPECT_NE(output.find("1 poses that were no pose left out"), std::string::npos) << output;
  const auto [read_code, read] =
      test::run_command({"node", (test::source_dir() / "test" / "bag" / "tum_read.mjs").string(),
                         (dir / "tum" / "wand.tum").string(), (dir / "tum" / "drone.tum").string()},
                        {}, std::chrono::seconds(30));
  ASSERT_EQ(read_code, 0) << read;
  std::istringstream lines(read);
  int wand_poses = 0, drone_poses = 0;
  for (std::string line; std::getline(lines, line);) {
    const json pose = json::parse(line);
    const bool is_wand = pose["file"].get<std::string>().ends_with("wand.tum");
    const int64_t stamp = std::stoll(pose["stamp_ns"].get<std::string>());
    ASSERT_EQ((stamp - kStart) % kPeriod, 0) << line;  // the capture stamp, to the nanosecond
    const int k = static_cast<int>((stamp - kStart) / kPeriod);
    if (!is_wand) {
      EXPECT_TRUE(drone_seen(k)) << line;  // a gap where it was lost
    }
    (is_wand ? wand_poses : drone_poses)++;
    const Truth truth = is_wand ? wand(k) : drone(k);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(pose["position"][i].get<double>(), truth.position[i], 1e-6) << line;
    }
    Eigen::Quaterniond q(pose["quaternion"][3].get<double>(), pose["quaternion"][0].get<double>(),
                         pose["quaternion"][1].get<double>(), pose["quaternion"][2].get<double>());
    EXPECT_GE(q.w(), 0) << line;
    EXPECT_NEAR(std::abs(q.dot(truth.orientation)), 1.0, 1e-9) << line;
  }
  EXPECT_EQ(wand_poses, 100);
  EXPECT_EQ(drone_poses, 80);
}

// OpenSim's Y up: our (x, y, z) as (x, z, -y).
Eigen::Vector3d y_up(const Eigen::Vector3d& p) { return {p.x(), p.z(), -p.y()}; }

TEST(BagExport, TrcReadsBackAsEachBodysOriginAndAxesToTheMicrometre) {
  test::TempDir dir;
  write_bag(dir / "bag", 100, true);
  const auto [code, output] = mocap_bag(
      {"export", (dir / "bag").string(), "--format", "trc", "-o", (dir / "bag.trc").string()});
  ASSERT_EQ(code, 0) << output;
  const auto [read_code, read] =
      test::run_command({"node", (test::source_dir() / "test" / "bag" / "trc_read.mjs").string(),
                         (dir / "bag.trc").string()},
                        {}, std::chrono::seconds(30));
  ASSERT_EQ(read_code, 0) << read;
  const json trc = json::parse(read);
  EXPECT_EQ(trc["header"]["Units"], "m");
  EXPECT_EQ(trc["header"]["NumFrames"], "100");
  EXPECT_NEAR(std::stod(trc["header"]["DataRate"].get<std::string>()), 1e9 / kPeriod, 1e-5);
  EXPECT_EQ(trc["markers"], (json{"drone_origin", "drone_x", "drone_y", "drone_z", "wand_origin",
                                  "wand_x", "wand_y", "wand_z"}));
  ASSERT_EQ(trc["rows"].size(), 100u);
  for (int k = 0; k < 100; ++k) {
    const json& row = trc["rows"][static_cast<size_t>(k)];
    EXPECT_EQ(row["frame"], k + 1);
    EXPECT_NEAR(std::stod(row["time"].get<std::string>()), k * kPeriod * 1e-9, 1e-9);
    for (const auto& [name, truth] : {std::pair{"wand", wand(k)}, {"drone", drone(k)}}) {
      const std::string body = name;
      if (body == "drone" && !drone_seen(k)) {
        EXPECT_TRUE(row["points"][body + "_origin"].is_null()) << row;  // a gap where it was lost
        continue;
      }
      const Eigen::Isometry3d pose =
          Eigen::Translation3d(truth.position) * truth.orientation.normalized();
      const std::pair<const char*, Eigen::Vector3d> points[] = {
          {"_origin", Eigen::Vector3d::Zero()},
          {"_x", Eigen::Vector3d(0.1, 0, 0)},
          {"_y", Eigen::Vector3d(0, 0.1, 0)},
          {"_z", Eigen::Vector3d(0, 0, 0.1)}};
      for (const auto& [suffix, in_body] : points) {
        const Eigen::Vector3d expected = y_up(pose * in_body);
        const json& got = row["points"][body + suffix];
        ASSERT_FALSE(got.is_null()) << body << suffix << " at frame " << k;
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i].get<double>(), expected[i], 1e-6) << row;
      }
    }
  }
}

TEST(BagExport, ABagWithoutPosesOrABodyNotInItIsNamed) {
  test::TempDir dir;
  write_bag(dir / "no_poses", 3, false);
  auto [code, output] = mocap_bag({"export", (dir / "no_poses").string(), "--format", "tum"});
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("no /mocap/poses messages in the bag (its topics: /other)"),
            std::string::npos)
      << output;
  write_bag(dir / "bag", 3, true);
  std::tie(code, output) = mocap_bag({"export", (dir / "bag").string(), "--format", "tum", "-o",
                                      (dir / "tum").string(), "--bodies", "wand", "boat"});
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("--bodies boat: not in"), std::string::npos) << output;
  EXPECT_NE(output.find("(its bodies: drone, wand)"), std::string::npos) << output;
  std::tie(code, output) = mocap_bag({"export", (dir / "bag").string(), "--format", "bvh"});
  EXPECT_EQ(code, 2);
  EXPECT_NE(output.find("--format bvh"), std::string::npos) << output;
}

}  // namespace
}  // namespace mocap
