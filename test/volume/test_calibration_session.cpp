// A volume's calibration from its recorded sessions (calibration_session.hpp): bags of the
// shipped board as the cameras' identifiers publish it, waved and on the floor, solved through
// the camera files, with its progress, its report and its messages; stopped; bad input named.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <regex>
#include <stop_token>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/bag/bag_writer.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>

#include "test/test_support.hpp"
#include "test/volume/synthetic_volume.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "volume/volume_calibration/calibration_messages.hpp"
#include "volume/volume_calibration/calibration_session.hpp"

namespace mocap::volume {
namespace {

constexpr int64_t kStart = 1'700'000'000'000'000'000;
constexpr int64_t kPeriod = 33'333'333;  // 30 Hz

std::vector<calibration::CameraFile> shipped_cameras() {
  std::vector<calibration::CameraFile> cameras;
  for (int c = 0; c < 4; ++c) {
    cameras.push_back(calibration::load_camera_file(
        config_file("volume/cameras/cam_" + std::to_string(c) + ".yaml")));
  }
  return cameras;
}

// The board at `world_from_board` as camera `camera` identifies it (each line's fiducials in the
// model's order), or nothing when any of its markers is out of the image.
std::optional<mocap_msgs::msg::ConstellationArray> identified(
    const calibration::CameraFile& camera, const constellations::ConstellationModel& board,
    const Eigen::Isometry3d& world_from_board, int64_t stamp_ns) {
  mocap_msgs::msg::ConstellationArray array;
  const auto stamp =
      to_time_msg(std::chrono::system_clock::time_point(std::chrono::nanoseconds(stamp_ns)));
  array.header().stamp(stamp);
  mocap_msgs::msg::Constellation& constellation = array.constellations().emplace_back();
  constellation.name(board.name);
  const Eigen::Isometry3d camera_from_board =
      camera.world_from_camera->inverse() * world_from_board;
  for (const auto& line : board.lines) {
    mocap_msgs::msg::SubConstellation& sub = constellation.sub_constellations().emplace_back();
    sub.name(line.name);
    sub.fiducial_array().header().stamp(stamp);
    for (int point : line.points) {
      const auto pixel =
          camera.model->project(camera_from_board * board.points[static_cast<size_t>(point)]);
      if (!pixel || !camera.model->in_image(*pixel)) return std::nullopt;
      mocap_msgs::msg::Fiducial& fiducial = sub.fiducial_array().fiducials().emplace_back();
      fiducial.x(static_cast<float>(pixel->x()));
      fiducial.y(static_cast<float>(pixel->y()));
    }
  }
  return array;
}

// A bag of every camera's identified board at each of `poses`, one capture time each.
void write_session(const std::filesystem::path& path,
                   const std::vector<calibration::CameraFile>& cameras,
                   const constellations::ConstellationModel& board,
                   const std::vector<Eigen::Isometry3d>& poses) {
  bag::BagWriter writer(path.string());
  const MessageType& type = message_type<mocap_msgs::msg::ConstellationArray>();
  std::vector<uint32_t> topics;
  for (const auto& camera : cameras) {
    topics.push_back(writer.add_topic(
        {"/volume/" + camera.name + "/constellations", type.name(), "cdr", {}, 0}));
  }
  for (size_t k = 0; k < poses.size(); ++k) {
    const int64_t stamp = kStart + static_cast<int64_t>(k) * kPeriod;
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (auto array = identified(cameras[c], board, poses[k], stamp)) {
        std::vector<uint8_t> data(type.serialized_size(&*array));
        data.resize(type.serialize(&*array, data));
        writer.write(topics[c], stamp + 2'000'000, data);
      }
    }
  }
  writer.close();
}

// The shipped volume's cameras and board: a waved session of 200 shots and the board on the
// floor at the origin, recorded; the camera files given to the session have cam_1 3 cm off and
// half a degree turned, as after a bump.
class CalibrationSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_ = shipped_cameras();
    database_ = constellations::load_database(config_file("constellations.yaml"));
    const constellations::ConstellationModel& board = *database_.find("board_a");
    std::mt19937 random(5);
    std::vector<Eigen::Isometry3d> waved;
    for (int k = 0; k < 200; ++k) waved.push_back(test::random_pose(random));
    write_session(dir_ / "waved", truth_, board, waved);
    // Face down, its x along the world's: as calibration_floor.yaml lays it, its axes the room's.
    Eigen::Isometry3d on_floor = Eigen::Isometry3d::Identity();
    on_floor.linear() = Eigen::AngleAxisd(test::kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
    write_session(dir_ / "floor", truth_, board, std::vector<Eigen::Isometry3d>(30, on_floor));

    session_.waved = (dir_ / "waved").string();
    session_.floor = {FloorRecording{(dir_ / "floor").string(), Eigen::Vector2d::Zero()}};
    session_.database = config_file("constellations.yaml");
    session_.output = (dir_ / "calibrated").string();
    for (calibration::CameraFile camera : truth_) {
      if (camera.name == "cam_1") {
        Eigen::Isometry3d bumped = *camera.world_from_camera;
        bumped.translation() += Eigen::Vector3d(0.03, 0, 0);
        bumped.linear() =
            bumped.linear() * Eigen::AngleAxisd(0.5 * test::kPi / 180, Eigen::Vector3d::UnitX());
        camera.world_from_camera = bumped;
      }
      const auto path = dir_ / (camera.name + ".yaml");
      calibration::save_camera_file(path.string(), camera);
      session_.camera_files.push_back(path.string());
    }
  }

  ::mocap::test::TempDir dir_;
  std::vector<calibration::CameraFile> truth_;
  constellations::ConstellationDatabase database_;
  CalibrationSession session_;
};

TEST_F(CalibrationSessionTest, CalibratesReportsAndSaysHowFarItHasCome) {
  std::vector<SessionProgress> progress;
  const CalibrationSessionResult result =
      run_calibration_session(session_, [&](const SessionProgress& p) { progress.push_back(p); });

  ASSERT_EQ(result.cameras.size(), 4u);
  for (size_t c = 0; c < 4; ++c) {
    const CalibratedCamera& camera = result.cameras[c];
    const Eigen::Isometry3d& truth = *truth_[c].world_from_camera;
    EXPECT_LT((camera.world_from_camera.translation() - truth.translation()).norm(), 1e-5)
        << camera.name;
    EXPECT_LT(
        Eigen::AngleAxisd(camera.world_from_camera.linear() * truth.linear().transpose()).angle(),
        1e-6)
        << camera.name;
    EXPECT_LT(camera.rms_px, 0.01) << camera.name;  // the pixels are float32
    EXPECT_GT(camera.shots, 20) << camera.name;
    // Against the input file: cam_1 as bumped, the others where they were.
    ASSERT_TRUE(camera.previous.has_value());
    EXPECT_NEAR(camera.moved_m, c == 1 ? 0.03 : 0.0, 1e-5) << camera.name;
    EXPECT_NEAR(camera.turned_deg, c == 1 ? 0.5 : 0.0, 1e-4) << camera.name;
    // The file written holds the calibrated pose.
    const calibration::CameraFile written = calibration::load_camera_file(camera.file);
    EXPECT_EQ(written.name, camera.name);
    EXPECT_LT((written.world_from_camera->translation() - truth.translation()).norm(), 1e-5);
  }
  EXPECT_EQ(result.waved.sightings_per_camera.size(), 4u);
  EXPECT_EQ(result.calibration.floor.at(0).cameras, 4u);

  // The progress: from reading to writing, never back, the solve's iterations with their RMS.
  ASSERT_GE(progress.size(), 3u);
  EXPECT_EQ(progress.front().stage, "reading");
  EXPECT_EQ(progress.front().fraction, 0.0);
  EXPECT_EQ(progress.back().stage, "writing");
  const std::vector<std::string> order = {"reading", "solving", "writing"};
  size_t stage = 0;
  int iterations = 0;
  for (size_t i = 0; i < progress.size(); ++i) {
    const auto at = std::find(order.begin(), order.end(), progress[i].stage);
    ASSERT_NE(at, order.end()) << progress[i].stage;
    EXPECT_GE(static_cast<size_t>(at - order.begin()), stage) << progress[i].stage;
    stage = static_cast<size_t>(at - order.begin());
    if (i > 0) {
      EXPECT_GE(progress[i].fraction, progress[i - 1].fraction) << i;
    }
    iterations += progress[i].detail.starts_with("iteration ");
  }
  EXPECT_GE(iterations, 2);

  // The report, as the tool prints it, from the same figures.
  const std::vector<std::string> lines = report_lines(result);
  const std::regex cam_1(
      R"(cam_1: at \((-?[0-9.]+), (-?[0-9.]+), (-?[0-9.]+)\) m; ([0-9.]+) mm and )"
      R"(([0-9.]+) deg from the input file's pose, RMS ([0-9.]+) px -> (.*))");
  int matched = 0;
  for (const std::string& line : lines) {
    std::smatch m;
    if (!std::regex_match(line, m, cam_1)) continue;
    ++matched;
    const Eigen::Vector3d p = result.cameras[1].world_from_camera.translation();
    EXPECT_NEAR(std::stod(m[1]), p.x(), 5e-5);
    EXPECT_NEAR(std::stod(m[3]), p.z(), 5e-5);
    EXPECT_EQ(m[4], "30.00");
    EXPECT_EQ(m[5], "0.5000");
    EXPECT_EQ(m[7], result.cameras[1].file);
  }
  EXPECT_EQ(matched, 1) << ::testing::PrintToString(lines);
  EXPECT_NE(std::find(lines.begin(), lines.end(),
                      "floor at (0, 0): the board seen by 4 cameras, RMS " +
                          fmt::format("{:.3f}", result.calibration.floor[0].rms_px) + " px"),
            lines.end())
      << ::testing::PrintToString(lines);

  // The page's message carries the same figures.
  const mocap_msgs::msg::VolumeCalibrationResult message = result_message(result);
  ASSERT_EQ(message.cameras().size(), 4u);
  EXPECT_EQ(message.cameras()[1].name(), "cam_1");
  EXPECT_EQ(message.cameras()[1].moved_m(), result.cameras[1].moved_m);
  EXPECT_EQ(message.cameras()[1].turned_deg(), result.cameras[1].turned_deg);
  EXPECT_EQ(message.cameras()[1].rms_px(), result.cameras[1].rms_px);
  EXPECT_TRUE(message.cameras()[1].has_previous_pose());
  EXPECT_EQ(message.cameras()[1].pose().position().x(),
            result.cameras[1].world_from_camera.translation().x());
  EXPECT_EQ(message.rms_px(), result.calibration.report.rms_px);
  ASSERT_EQ(message.floor().size(), 1u);
  EXPECT_EQ(message.floor()[0].off_mark_m(), -1.0);  // one mark: its axes set the frame
}

TEST_F(CalibrationSessionTest, AStopEndsItAndBadInputIsNamed) {
  std::stop_source stop;
  stop.request_stop();
  try {
    run_calibration_session(session_, {}, stop.get_token());
    ADD_FAILURE() << "not stopped";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_STREQ(e.what(), "stopped");
  }
  // Stopped in the middle of the solve.
  std::stop_source during;
  try {
    run_calibration_session(
        session_,
        [&](const SessionProgress& p) {
          if (p.detail.starts_with("iteration 1")) during.request_stop();
        },
        during.get_token());
    ADD_FAILURE() << "not stopped";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_STREQ(e.what(), "stopped");
  }

  CalibrationSession missing = session_;
  missing.waved = (dir_ / "no_such_bag").string();
  try {
    run_calibration_session(missing);
    ADD_FAILURE() << "no error";
  } catch (const CalibrationSessionError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_bag"), std::string::npos) << e.what();
  }
  CalibrationSession unknown = session_;
  unknown.board = "board_z";
  try {
    run_calibration_session(unknown);
    ADD_FAILURE() << "no error";
  } catch (const CalibrationSessionError& e) {
    EXPECT_EQ(std::string(e.what()), "board: no 'board_z' in " + session_.database);
  }
}

TEST(FloorRecording, IsABagAndAnOptionalMark) {
  EXPECT_EQ(parse_floor_recording("/b/floor")->bag, "/b/floor");
  EXPECT_EQ(parse_floor_recording("/b/floor")->mark, Eigen::Vector2d::Zero());
  const auto marked = parse_floor_recording("/b/floor_1_-1:1,-0.5");
  ASSERT_TRUE(marked.has_value());
  EXPECT_EQ(marked->bag, "/b/floor_1_-1");
  EXPECT_EQ(marked->mark, Eigen::Vector2d(1, -0.5));
  EXPECT_EQ(parse_floor_recording("C:/b/floor")->bag, "C:/b/floor");  // no comma: all path
  EXPECT_FALSE(parse_floor_recording("/b/floor:1,x").has_value());
  EXPECT_FALSE(parse_floor_recording("/b/floor:1,nan").has_value());
}

}  // namespace
}  // namespace mocap::volume
