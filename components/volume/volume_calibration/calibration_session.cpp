#include "volume/volume_calibration/calibration_session.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "volume/volume_calibration/calibration_messages.hpp"

namespace mocap::volume {
namespace {

// The session's share of each stage: reading the bags is most of a short solve's time.
constexpr double kReadingShare = 0.3;
constexpr double kSolvingEnd = 0.95;
// Levenberg–Marquardt ends once an iteration lowers the cost by less than this share.
constexpr double kFunctionTolerance = 1e-10;

// Reports where the session is, unless a stop was asked for.
struct Reporter {
  const std::function<void(const SessionProgress&)>& callback;
  std::stop_token stop;
  // False, reporting nothing, once a stop was asked for: for Ceres's callback, which must not
  // throw.
  bool operator()(const std::string& stage, double fraction, std::string detail = {}) const {
    if (stop.stop_requested()) return false;
    if (callback) callback({stage, std::clamp(fraction, 0.0, 1.0), std::move(detail)});
    return true;
  }
  // Ends the session where a stop was asked for.
  void step(const std::string& stage, double fraction, std::string detail = {}) const {
    if (!(*this)(stage, fraction, std::move(detail))) throw VolumeCalibrationError("stopped");
  }
};

// The board's sightings in the bag at `path`, reading its share [from, to) of the session.
std::vector<BoardSighting> read_sightings(const std::string& path,
                                          const std::vector<std::string>& cameras,
                                          const constellations::ConstellationModel& board,
                                          RecordingRead& read, const Reporter& report, double from,
                                          double to) {
  read.path = path;
  read.sightings_per_camera.assign(cameras.size(), 0);
  std::vector<BoardSighting> sightings;
  try {
    bag::BagReader reader(path);
    std::map<std::string, size_t> camera_of_topic;
    std::vector<std::string> wanted;
    for (size_t c = 0; c < cameras.size(); ++c) {
      const std::string topic = topics::member_of(topics::kVolumeConstellations, cameras[c]);
      camera_of_topic[topic] = c;
      wanted.push_back(topic);
    }
    uint64_t total = 0;
    for (const bag::BagTopic& topic : reader.metadata().topics) {
      if (camera_of_topic.contains(topic.name)) total += topic.message_count;
    }
    reader.set_topic_filter(wanted);
    const MessageType& type = message_type<mocap_msgs::msg::ConstellationArray>();
    bag::BagMessage message;
    mocap_msgs::msg::ConstellationArray array;
    size_t undecodable = 0;
    uint64_t done = 0;
    const std::string name = std::filesystem::path(path).filename().string();
    while (reader.next(message)) {
      if (++done % 256 == 0 && total > 0) {
        report.step("reading", from + (to - from) * static_cast<double>(done) / total,
                    fmt::format("{}: {} of {} messages", name, done, total));
      }
      try {
        type.deserialize(message.data, &array);
      } catch (const SerializationError&) {
        ++undecodable;
        continue;
      }
      if (auto sighting = board_sighting(array, camera_of_topic.at(message.topic->name), board)) {
        ++read.sightings_per_camera[sighting->camera];
        sightings.push_back(std::move(*sighting));
      }
    }
    read.problems = reader.problems();
    if (undecodable > 0) {
      read.problems.push_back(fmt::format("{} messages could not be decoded", undecodable));
    }
  } catch (const bag::BagError& e) {
    throw CalibrationSessionError(e.what());
  }
  return sightings;
}

// How near the solve is to its end, 0 to 1, from the iterations' relative decrease in cost:
// its order of magnitude falls from about 1 towards the tolerance.
class SolveGauge {
 public:
  double operator()(const calibration::SolveIteration& iteration) {
    if (iteration.relative_decrease > 0) {
      const double orders = -std::log10(std::max(iteration.relative_decrease, kFunctionTolerance));
      reached_ = std::max(reached_, orders / -std::log10(kFunctionTolerance));
    }
    return reached_;
  }

 private:
  double reached_ = 0;
};

std::string reading_line(const RecordingRead& read, const std::vector<std::string>& cameras,
                         const std::string& board) {
  size_t all = 0;
  std::vector<std::string> counts;
  for (size_t c = 0; c < cameras.size(); ++c) {
    all += read.sightings_per_camera[c];
    counts.push_back(fmt::format("{} {}", cameras[c], read.sightings_per_camera[c]));
  }
  return fmt::format("{}: {} sightings of {} ({})", read.path, all, board, fmt::join(counts, ", "));
}

}  // namespace

std::optional<FloorRecording> parse_floor_recording(const std::string& argument) {
  const size_t colon = argument.rfind(':');
  if (colon == std::string::npos) return FloorRecording{argument};
  const std::string mark = argument.substr(colon + 1);
  const size_t comma = mark.find(',');
  if (comma == std::string::npos) return FloorRecording{argument};
  try {
    size_t x_end = 0, y_end = 0;
    const double x = std::stod(mark.substr(0, comma), &x_end);
    const double y = std::stod(mark.substr(comma + 1), &y_end);
    if (x_end != comma || y_end != mark.size() - comma - 1 || !std::isfinite(x) ||
        !std::isfinite(y)) {
      return std::nullopt;
    }
    return FloorRecording{argument.substr(0, colon), Eigen::Vector2d(x, y)};
  } catch (const std::logic_error&) {  // std::stod's invalid_argument, out_of_range
    return std::nullopt;
  }
}

CalibrationSessionResult run_calibration_session(
    const CalibrationSession& session, const std::function<void(const SessionProgress&)>& progress,
    std::stop_token stop) {
  const Reporter report{progress, stop};
  report.step("reading", 0);
  std::vector<calibration::CameraFile> files;
  std::vector<CalibrationCamera> cameras;
  std::vector<std::string> names;
  std::vector<CoverageCamera> coverage_cameras;
  try {
    for (const std::string& path : session.camera_files) {
      files.push_back(calibration::load_camera_file(path));
      cameras.push_back({files.back().name, files.back().model});
      names.push_back(files.back().name);
      coverage_cameras.push_back(
          {files.back().name, {files.back().model->width(), files.back().model->height()}});
    }
  } catch (const std::exception& e) {  // the camera file's own message names file and field
    throw CalibrationSessionError(e.what());
  }
  constellations::ConstellationDatabase database;
  try {
    database = constellations::load_database(session.database);
  } catch (const std::exception& e) {
    throw CalibrationSessionError(e.what());
  }
  const constellations::ConstellationModel* board = database.find(session.board);
  if (board == nullptr) {
    throw CalibrationSessionError(
        fmt::format("board: no '{}' in {}", session.board, session.database));
  }

  CalibrationSessionResult result;
  result.board = session.board;
  result.marks = session.floor;
  const double bag_share = kReadingShare / static_cast<double>(1 + session.floor.size());
  const std::vector<BoardSighting> waved =
      read_sightings(session.waved, names, *board, result.waved, report, 0, bag_share);
  CalibrationCoverage coverage(coverage_cameras);
  for (const BoardSighting& sighting : waved) coverage.add(sighting);
  result.coverage = coverage.cameras();
  result.coverage_stamp_ns = coverage.latest_stamp_ns();
  std::vector<FloorPlacement> floor;
  for (size_t f = 0; f < session.floor.size(); ++f) {
    RecordingRead& read = result.floor.emplace_back();
    const double from = bag_share * static_cast<double>(1 + f);
    floor.push_back({session.floor[f].mark, read_sightings(session.floor[f].bag, names, *board,
                                                           read, report, from, from + bag_share)});
  }

  report.step("solving", kReadingShare,
              fmt::format("{} sightings of the waved board", waved.size()));
  VolumeCalibrationOptions options;
  SolveGauge gauge;
  options.on_iteration = [&](const calibration::SolveIteration& iteration) {
    return report(
        "solving", kReadingShare + (kSolvingEnd - kReadingShare) * gauge(iteration),
        fmt::format("iteration {}, RMS {:.3f} px", iteration.iteration, iteration.rms_px));
  };
  try {
    result.calibration = calibrate_volume(cameras, board->points, waved, floor, options);
  } catch (const VolumeCalibrationError&) {
    if (stop.stop_requested()) throw VolumeCalibrationError("stopped");
    throw;
  }

  report.step("writing", kSolvingEnd, session.output);
  std::filesystem::create_directories(session.output);
  for (size_t c = 0; c < files.size(); ++c) {
    CalibratedCamera& camera = result.cameras.emplace_back();
    camera.name = names[c];
    camera.rms_px = result.calibration.report.cameras[c].rms_px;
    camera.shots = result.calibration.report.cameras[c].shots;
    camera.world_from_camera = result.calibration.camera_from_world[c].inverse();
    camera.previous = files[c].world_from_camera;
    if (camera.previous) {
      camera.moved_m =
          (camera.world_from_camera.translation() - camera.previous->translation()).norm();
      camera.turned_deg = Eigen::AngleAxisd(camera.world_from_camera.linear() *
                                            camera.previous->linear().transpose())
                              .angle() *
                          180 / M_PI;
    }
    files[c].world_from_camera = camera.world_from_camera;
    camera.file = (std::filesystem::path(session.output) /
                   std::filesystem::path(session.camera_files[c]).filename())
                      .string();
    calibration::save_camera_file(camera.file, files[c]);
  }
  return result;
}

std::vector<std::string> report_lines(const CalibrationSessionResult& result) {
  std::vector<std::string> names;
  for (const CalibratedCamera& camera : result.cameras) names.push_back(camera.name);
  std::vector<std::string> lines;
  lines.push_back(reading_line(result.waved, names, result.board));
  for (const RecordingRead& read : result.floor) {
    lines.push_back(reading_line(read, names, result.board));
  }
  for (const CameraCoverage& camera : result.coverage) {
    lines.push_back("waved coverage: " + coverage_line(camera));
  }
  const VolumeCalibration& calibration = result.calibration;
  lines.push_back(fmt::format(
      "waved: {} capture times with the board whole in two cameras or more; RMS reprojection "
      "error {:.3f} px over {} points ({} iterations)",
      calibration.frames_used, calibration.report.rms_px, calibration.report.points,
      calibration.report.iterations));
  for (size_t p = 0; p < calibration.floor.size(); ++p) {
    const VolumeCalibration::Placement& placement = calibration.floor[p];
    std::string line = fmt::format("floor at ({}, {}): the board seen by {} cameras, RMS {:.3f} px",
                                   result.marks[p].mark.x(), result.marks[p].mark.y(),
                                   placement.cameras, placement.rms_px);
    if (calibration.floor.size() > 1) {
      line += fmt::format("; {:.3f} mm from its mark", placement.off_mark_m * 1e3);
    }
    lines.push_back(line);
  }
  for (const CalibratedCamera& camera : result.cameras) {
    const Eigen::Vector3d p = camera.world_from_camera.translation();
    std::string against;
    if (camera.previous) {
      against = fmt::format("; {:.2f} mm and {:.4f} deg from the input file's pose",
                            camera.moved_m * 1e3, camera.turned_deg);
    }
    lines.push_back(fmt::format("{}: at ({:.4f}, {:.4f}, {:.4f}) m{}, RMS {:.3f} px -> {}",
                                camera.name, p.x(), p.y(), p.z(), against, camera.rms_px,
                                camera.file));
  }
  return lines;
}

std::vector<std::string> problem_lines(const CalibrationSessionResult& result) {
  std::vector<std::string> lines;
  auto add = [&](const RecordingRead& read) {
    for (const std::string& problem : read.problems) lines.push_back(read.path + ": " + problem);
  };
  add(result.waved);
  for (const RecordingRead& read : result.floor) add(read);
  return lines;
}

std::string progress_line(const SessionProgress& progress) {
  return fmt::format("solve {} {}{}{}", progress_bar(progress.fraction), progress.stage,
                     progress.detail.empty() ? "" : ", ", progress.detail);
}

}  // namespace mocap::volume
