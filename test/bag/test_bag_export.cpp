// `mocap_bag export` (and motion_export's C3D writer alone, past 65535 frames): a bag of known
// poses and markers written out and read back by a reader of each format written from its
// description (test/bag/tum_read.mjs, trc_read.mjs, c3d_read.mjs, motive_csv_read.mjs), values
// equal to the micrometre (text) or to the float (C3D); a bag without poses and a body not in
// it are named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <tuple>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include <mocap/bag/bag_writer.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <nlohmann/json.hpp>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "recording/motion_export/c3d_writer.hpp"
#include "recording/motion_export/point_table.hpp"

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

// Their markers, in their own frames, as the bodies file of kBodiesFile lists them (wand first:
// the cloud's body 0).
const std::vector<Eigen::Vector3d> kWandMarkers = {{0.1, 0, 0}, {0, 0.15, 0}, {-0.05, -0.02, 0.03}};
const std::vector<Eigen::Vector3d> kDroneMarkers = {{0.2, 0, 0}, {-0.1, 0.1, 0}, {-0.1, -0.1, 0}};
constexpr const char* kBodiesFile = R"(bodies:
  - name: wand
    markers: [[0.1, 0, 0], [0, 0.15, 0], [-0.05, -0.02, 0.03]]
  - name: drone
    markers: [[0.2, 0, 0], [-0.1, 0.1, 0], [-0.1, -0.1, 0]]
)";

// Two markers no body claims: track 77 in frames 10 to 29, track 5 from frame 50, each moving.
std::optional<Eigen::Vector3d> unlabeled(uint32_t track, int k) {
  if (track == 77 && k >= 10 && k < 30) return Eigen::Vector3d(1.5, 0.01 * k, 0.02);
  if (track == 5 && k >= 50) return Eigen::Vector3d(-2.0 + 0.003 * k, 0.5, 1.0);
  return std::nullopt;
}

// Frame k's cloud: the markers of each body seen (wand's marker 2 hidden in frames 70 to 74),
// then the unlabeled ones; `extra_unlabeled` more at fixed places (tracks 1000 and up).
std::vector<LabeledMarker> cloud(int k, int extra_unlabeled = 0) {
  std::vector<LabeledMarker> markers;
  auto add_body = [&](int32_t body, const Truth& truth,
                      const std::vector<Eigen::Vector3d>& layout) {
    for (size_t m = 0; m < layout.size(); ++m) {
      if (body == 0 && m == 1 && k >= 70 && k < 75) continue;
      const Eigen::Vector3d world = truth.position + truth.orientation * layout[m];
      markers.push_back({world.cast<float>(), body, static_cast<uint16_t>(m),
                         static_cast<uint32_t>(10 * body + m + 1), 0.2f, 0b101});
    }
  };
  add_body(0, wand(k), kWandMarkers);
  if (drone_seen(k)) add_body(1, drone(k), kDroneMarkers);
  for (uint32_t track : {77u, 5u}) {
    if (const auto p = unlabeled(track, k))
      markers.push_back({p->cast<float>(), -1, 0, track, 0.3f, 0b11});
  }
  for (int e = 0; e < extra_unlabeled; ++e) {
    markers.push_back(
        {Eigen::Vector3f(0.01f * e, 0.5f, 0.25f), -1, 0, static_cast<uint32_t>(1000 + e), 0.1f, 1});
  }
  return markers;
}

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

template <typename Message>
std::vector<uint8_t> serialized(const Message& message) {
  const MessageType& type = message_type<Message>();
  std::vector<uint8_t> data(type.serialized_size(&message));
  data.resize(type.serialize(&message, data));
  return data;
}

// `frames` pose arrays (on /other without poses) and, with `markers`, the cloud of each frame
// (with `extra_unlabeled` more markers).
void write_bag(const std::filesystem::path& path, int frames, bool with_poses, bool markers = false,
               int extra_unlabeled = 0) {
  bag::BagWriter writer(path.string());
  const uint32_t poses_id =
      writer.add_topic({with_poses ? "/mocap/poses" : "/other",
                        message_type<mocap_msgs::msg::ConstellationPoseArray>().name(),
                        "cdr",
                        {},
                        0});
  const uint32_t cloud_id =
      markers ? writer.add_topic({"/mocap/markers",
                                  message_type<sensor_msgs::msg::PointCloud2>().name(),
                                  "cdr",
                                  {},
                                  0})
              : 0;
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
    writer.write(poses_id, stamp + 1'000'000, serialized(array));
    if (markers) {
      writer.write(cloud_id, stamp + 1'100'000,
                   serialized(to_point_cloud(array.header(), cloud(k, extra_unlabeled))));
    }
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

// Every point of frame k in the world frame (z up, metres), by name, in the order the exports
// write them: the labeled markers by body and index, the unlabeled by track, then each body's
// origin and axis ends 0.1 m out; nullopt where the point is missing (a gap).
std::vector<std::pair<std::string, std::optional<Eigen::Vector3d>>> points_of_frame(int k) {
  std::vector<std::pair<std::string, std::optional<Eigen::Vector3d>>> points;
  const std::vector<LabeledMarker> markers = cloud(k);
  auto marker = [&](int32_t body, uint16_t index) -> std::optional<Eigen::Vector3d> {
    for (const LabeledMarker& m : markers) {
      if (m.body == body && m.marker == index) return m.position.cast<double>();
    }
    return std::nullopt;
  };
  for (uint16_t m = 0; m < 3; ++m)
    points.emplace_back(fmt::format("drone_{}", m + 1), marker(1, m));
  for (uint16_t m = 0; m < 3; ++m) points.emplace_back(fmt::format("wand_{}", m + 1), marker(0, m));
  points.emplace_back("unlabeled_5", unlabeled(5, k));
  points.emplace_back("unlabeled_77", unlabeled(77, k));
  for (const auto& [body, truth, seen] :
       {std::tuple{"drone", drone(k), drone_seen(k)}, {"wand", wand(k), true}}) {
    const Eigen::Isometry3d pose =
        Eigen::Translation3d(truth.position) * truth.orientation.normalized();
    const std::pair<const char*, Eigen::Vector3d> ends[] = {{"origin", Eigen::Vector3d::Zero()},
                                                            {"x", Eigen::Vector3d(0.1, 0, 0)},
                                                            {"y", Eigen::Vector3d(0, 0.1, 0)},
                                                            {"z", Eigen::Vector3d(0, 0, 0.1)}};
    for (const auto& [suffix, in_body] : ends) {
      points.emplace_back(fmt::format("{}_{}", body, suffix),
                          seen ? std::optional(pose * in_body) : std::nullopt);
    }
  }
  return points;
}

std::vector<std::string> point_names() {
  std::vector<std::string> names;
  for (const auto& [name, point] : points_of_frame(0)) names.push_back(name);
  return names;
}

json read_back(const char* reader, const std::filesystem::path& file,
               const std::vector<std::string>& options = {}) {
  std::vector<std::string> arguments = {
      "node", (test::source_dir() / "test" / "bag" / reader).string(), file.string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  const auto [code, output] = test::run_command(arguments, {}, std::chrono::seconds(60));
  EXPECT_EQ(code, 0) << output;
  return code == 0 ? json::parse(output) : json();
}

// OpenSim's Y up: our (x, y, z) as (x, z, -y).
Eigen::Vector3d y_up(const Eigen::Vector3d& p) { return {p.x(), p.z(), -p.y()}; }

TEST(BagExport, TrcReadsBackAsTheMarkersAndEachBodysOriginAndAxesToTheMicrometre) {
  test::TempDir dir;
  write_bag(dir / "bag", 100, true, true);
  test::write_file(dir / "bodies.yaml", kBodiesFile);
  const auto [code, output] = mocap_bag({"export", (dir / "bag").string(), "--format", "trc", "-o",
                                         (dir / "bag.trc").string(), "--markers", "--bodies-file",
                                         (dir / "bodies.yaml").string()});
  ASSERT_EQ(code, 0) << output;
  const json trc = read_back("trc_read.mjs", dir / "bag.trc");
  ASSERT_TRUE(trc.is_object());
  EXPECT_EQ(trc["header"]["Units"], "m");
  EXPECT_EQ(trc["header"]["NumFrames"], "100");
  EXPECT_NEAR(std::stod(trc["header"]["DataRate"].get<std::string>()), 1e9 / kPeriod, 1e-5);
  EXPECT_EQ(trc["markers"], json(point_names()));
  ASSERT_EQ(trc["rows"].size(), 100u);
  for (int k = 0; k < 100; ++k) {
    const json& row = trc["rows"][static_cast<size_t>(k)];
    EXPECT_EQ(row["frame"], k + 1);
    EXPECT_NEAR(std::stod(row["time"].get<std::string>()), k * kPeriod * 1e-9, 1e-9);
    for (const auto& [name, point] : points_of_frame(k)) {
      const json& got = row["points"][name];
      if (!point) {
        EXPECT_TRUE(got.is_null()) << name << " at frame " << k;  // a gap where it was missing
        continue;
      }
      ASSERT_FALSE(got.is_null()) << name << " at frame " << k;
      const Eigen::Vector3d expected = y_up(*point);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i].get<double>(), expected[i], 1e-6) << row;
    }
  }
}

// Within one unit in the last place of the float that holds `expected`.
::testing::AssertionResult same_float(double got, double expected) {
  const double ulp = std::nextafter(static_cast<float>(std::abs(expected)), INFINITY) -
                     static_cast<float>(std::abs(expected));
  if (std::abs(got - expected) <= ulp) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << got << " is not " << expected << " to the float (ulp " << ulp << ")";
}

TEST(BagExport, C3dReadsBackAsTheMarkersAndEachBodysOriginAndAxesToTheFloat) {
  test::TempDir dir;
  write_bag(dir / "bag", 100, true, true);
  test::write_file(dir / "bodies.yaml", kBodiesFile);
  const auto [code, output] = mocap_bag({"export", (dir / "bag").string(), "--format", "c3d", "-o",
                                         (dir / "bag.c3d").string(), "--markers", "--bodies-file",
                                         (dir / "bodies.yaml").string()});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("100 frames at 120.000 Hz, 8 markers, 2 bodies as 8 points"),
            std::string::npos)
      << output;
  const json c3d = read_back("c3d_read.mjs", dir / "bag.c3d");
  ASSERT_TRUE(c3d.is_object());
  EXPECT_EQ(c3d["processor"], "intel");
  EXPECT_EQ(c3d["header"]["point_count"], 16);
  EXPECT_EQ(c3d["header"]["first_frame"], 1);
  EXPECT_EQ(c3d["header"]["last_frame"], 100);
  EXPECT_LT(c3d["header"]["scale"].get<double>(), 0);  // real numbers
  EXPECT_TRUE(same_float(c3d["rate"].get<double>(), 1e9 / kPeriod)) << c3d["rate"];
  EXPECT_EQ(c3d["units"], "mm");
  EXPECT_EQ(c3d["labels"], json(point_names()));
  EXPECT_EQ(c3d["descriptions"][0], "marker 1 of drone");
  EXPECT_EQ(c3d["descriptions"][6], "unlabeled, track 5");
  EXPECT_EQ(c3d["descriptions"][8], "origin of drone");
  ASSERT_EQ(c3d["frames"].size(), 100u);
  for (int k = 0; k < 100; ++k) {
    const json& frame = c3d["frames"][static_cast<size_t>(k)];
    const auto points = points_of_frame(k);
    ASSERT_EQ(frame.size(), points.size());
    for (size_t p = 0; p < points.size(); ++p) {
      const auto& [name, point] = points[p];
      if (!point) {
        EXPECT_TRUE(frame[p].is_null()) << name << " at frame " << k;  // C3D's invalid point
        EXPECT_TRUE(c3d["residuals"][static_cast<size_t>(k)][p].is_null());
        continue;
      }
      ASSERT_FALSE(frame[p].is_null()) << name << " at frame " << k;
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(same_float(frame[p][i].get<double>(), 1000 * (*point)[i]))
            << name << " at frame " << k << " axis " << i;
      }
    }
  }
}

// Past 255 points C3D continues the labels in POINT:LABELS2: 300 more unlabeled markers.
TEST(BagExport, C3dLabelsPast255PointsContinueInLabels2) {
  test::TempDir dir;
  write_bag(dir / "bag", 3, true, true, 300);
  const auto [code, output] =
      mocap_bag({"export", (dir / "bag").string(), "--format", "c3d", "-o",
                 (dir / "bag.c3d").string(), "--markers", "--bodies", "wand"});
  ASSERT_EQ(code, 0) << output;
  // The cloud's bodies without a bodies file: named by their index, and said.
  EXPECT_NE(output.find("the markers of 2 bodies named by their index"), std::string::npos)
      << output;
  const json c3d = read_back("c3d_read.mjs", dir / "bag.c3d");
  ASSERT_TRUE(c3d.is_object());
  const size_t points = 3 + 3 + 300 + 4;  // body0 and body1's markers, the extra, wand's four
  EXPECT_EQ(c3d["parameters"]["POINT"]["USED"], points);
  EXPECT_EQ(c3d["parameters"]["POINT"]["LABELS"].size(), 255u);
  EXPECT_EQ(c3d["parameters"]["POINT"]["LABELS2"].size(), points - 255);
  ASSERT_EQ(c3d["labels"].size(), points);
  EXPECT_EQ(c3d["labels"][0], "body0_1");
  EXPECT_EQ(c3d["labels"][6], "unlabeled_1000");
  EXPECT_EQ(c3d["labels"][points - 4], "wand_origin");
  for (int e = 0; e < 300; ++e) {
    const json& point = c3d["frames"][2][static_cast<size_t>(6 + e)];
    ASSERT_FALSE(point.is_null()) << e;
    EXPECT_TRUE(same_float(point[0].get<double>(), 1000.0 * static_cast<double>(0.01f * e)));
  }
}

// Past 65535 frames the header's last frame stays 65535 and TRIAL:ACTUAL_END_FIELD (two 16-bit
// words) counts them, as the C3D User Guide says; a reader that follows it reads every frame.
// The writer alone, and four frames printed (through a bag, or all 70,000 frames parsed, it took
// half a minute under AddressSanitizer).
TEST(BagExport, C3dPast65535FramesCountsThemInTrialActualEndField) {
  test::TempDir dir;
  constexpr int kFrames = 70'000;
  std::vector<int64_t> stamps;
  std::vector<motion_export::StampedPose> poses;
  for (int k = 0; k < kFrames; ++k) {
    stamps.push_back(kStart + k * kPeriod);
    poses.push_back({stamps.back(), Eigen::Translation3d(wand(k).position) * wand(k).orientation});
  }
  motion_export::PointTable table = motion_export::make_point_table(stamps);
  motion_export::add_body_points(table, "wand", poses);
  {
    std::ofstream out(dir / "long.c3d", std::ios::binary);
    motion_export::write_c3d(out, table);
  }
  // Every frame read, four printed.
  const int printed[] = {0, 65534, 65535, kFrames - 1};
  const json c3d = read_back("c3d_read.mjs", dir / "long.c3d", {"--frames", "0,65534,65535,69999"});
  ASSERT_TRUE(c3d.is_object());
  EXPECT_EQ(c3d["header"]["last_frame"], 65535);
  EXPECT_EQ(c3d["parameters"]["TRIAL"]["ACTUAL_END_FIELD"],
            (json{kFrames & 0xffff, kFrames >> 16}));
  EXPECT_EQ(c3d["frame_count"], kFrames);
  ASSERT_EQ(c3d["frames"].size(), 4u);
  for (size_t f = 0; f < 4; ++f) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(
          same_float(c3d["frames"][f][0][i].get<double>(), 1000 * wand(printed[f]).position[i]))
          << "frame " << printed[f];
    }
  }
}

// Motive's default CSV: Y up, metres; rigid bodies as rotation and position, markers as
// "<body>:Marker<n>" and "Unlabeled <track>", gaps as empty cells.
TEST(BagExport, MotiveCsvReadsBackAsTheBodiesAndMarkersToTheMicrometre) {
  test::TempDir dir;
  write_bag(dir / "bag", 100, true, true);
  test::write_file(dir / "bodies.yaml", kBodiesFile);
  const auto [code, output] = mocap_bag({"export", (dir / "bag").string(), "--format", "csv", "-o",
                                         (dir / "bag.csv").string(), "--markers", "--bodies-file",
                                         (dir / "bodies.yaml").string()});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("100 frames, 2 bodies, 8 markers"), std::string::npos) << output;
  const json csv = read_back("motive_csv_read.mjs", dir / "bag.csv");
  ASSERT_TRUE(csv.is_object());
  EXPECT_EQ(csv["info"]["Format Version"], "1.23");
  EXPECT_EQ(csv["info"]["Length Units"], "Meters");
  EXPECT_EQ(csv["info"]["Rotation Type"], "Quaternion");
  EXPECT_EQ(csv["info"]["Total Exported Frames"], "100");
  EXPECT_NEAR(std::stod(csv["info"]["Export Frame Rate"].get<std::string>()), 1e9 / kPeriod, 1e-6);
  EXPECT_EQ(csv["frames"], 100);
  // Motive's Y up: a turn of -90 degrees about x.
  const Eigen::Quaterniond y_up_from_ours(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  for (const auto& [name, truth_of] : {std::pair{"wand", &wand}, {"drone", &drone}}) {
    const json& rows = csv["rigid_bodies"][name];
    ASSERT_EQ(rows.size(), 100u) << name;
    for (int k = 0; k < 100; ++k) {
      const json& row = rows[static_cast<size_t>(k)];
      EXPECT_EQ(row["frame"], k);
      EXPECT_NEAR(std::stod(row["time"].get<std::string>()), k * kPeriod * 1e-9, 1e-6);
      if (std::string(name) == "drone" && !drone_seen(k)) {
        EXPECT_TRUE(row["position"].is_null()) << row;  // lost: empty cells
        EXPECT_TRUE(row["rotation"].is_null()) << row;
        continue;
      }
      const Truth truth = truth_of(k);
      const Eigen::Vector3d position = y_up_from_ours * truth.position;
      Eigen::Quaterniond rotation = y_up_from_ours * truth.orientation.normalized();
      if (rotation.w() < 0) rotation.coeffs() *= -1;
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(row["position"][i].get<double>(), position[i], 1e-6);
      for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(row["rotation"][i].get<double>(), rotation.coeffs()[i], 1e-6) << row;
      }
    }
  }
  for (int k = 0; k < 100; ++k) {
    for (const auto& [name, point] : points_of_frame(k)) {
      if (name.ends_with("_origin") || name.ends_with("_x") || name.ends_with("_y") ||
          name.ends_with("_z")) {
        continue;  // a body's virtual points: C3D's and TRC's, not Motive's
      }
      const size_t cut = name.rfind('_');
      const std::string body = name.substr(0, cut), number = name.substr(cut + 1);
      const std::string motive_name =
          body == "unlabeled" ? "Unlabeled " + number : body + ":Marker" + number;
      ASSERT_TRUE(csv["markers"].contains(motive_name)) << motive_name;
      const json& got = csv["markers"][motive_name][static_cast<size_t>(k)];
      if (!point) {
        EXPECT_TRUE(got.is_null()) << motive_name << " at frame " << k;
        continue;
      }
      ASSERT_FALSE(got.is_null()) << motive_name << " at frame " << k;
      const Eigen::Vector3d expected = y_up_from_ours * *point;
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i].get<double>(), expected[i], 1e-6);
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
  std::tie(code, output) =
      mocap_bag({"export", (dir / "bag").string(), "--format", "c3d", "--markers"});
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("no /mocap/markers messages in the bag (its topics: /mocap/poses)"),
            std::string::npos)
      << output;
  test::write_file(dir / "bodies.yaml", "bodies:\n  - name: wand\n    markers: [[0, 0, 0]]\n");
  write_bag(dir / "marked", 3, true, true);
  std::tie(code, output) =
      mocap_bag({"export", (dir / "marked").string(), "--format", "c3d", "--markers",
                 "--bodies-file", (dir / "bodies.yaml").string()});
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("bodies.yaml"), std::string::npos) << output;
  std::tie(code, output) = mocap_bag({"export", (dir / "bag").string(), "--format", "bvh"});
  EXPECT_EQ(code, 2);
  EXPECT_NE(output.find("--format bvh"), std::string::npos) << output;
}

}  // namespace
}  // namespace mocap
