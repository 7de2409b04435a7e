// mocap_volume_calibrate: a volume's cameras calibrated from two recorded sessions
// (volume_calibration.hpp): the board waved through the volume, then laid on the floor where
// the world's origin is to be, or at three or more measured marks, a bag each. Each bag holds
// the cameras' /volume/<camera>/constellations (launch_yaml/volume_calibration.yaml records
// them); the camera files give the intrinsics and the names. Writes each camera file again,
// with its calibrated `pose`, into the output folder.
//
//   mocap_volume_calibrate --waved BAG --floor BAG[:X,Y]... --output DIR [--board NAME]
//                          [--database FILE] CAMERA_FILE...
//
// Exit status: 0 calibrated, 1 the sessions cannot calibrate the volume, 2 bad arguments or
// unreadable files.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/config_files.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "volume/volume_calibration/board_sighting_message.hpp"
#include "volume/volume_calibration/calibration_coverage.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace {

using mocap::volume::BoardSighting;

constexpr const char* kUsage =
    "usage: mocap_volume_calibrate --waved BAG --floor BAG[:X,Y]... --output DIR\n"
    "                              [--board NAME] [--database FILE] CAMERA_FILE...\n"
    "  BAG: a recording of /volume/<camera>/constellations (launch_yaml/volume_calibration.yaml)\n"
    "  --floor: the board lying on the floor, its centre at the mark X,Y (metres, default 0,0);\n"
    "           once (its axes are the room's), or at three marks or more not in a line\n"
    "  --board: the board waved and laid on the floor (default board_a), in --database\n"
    "           (default the shipped config/constellations.yaml)\n";

struct FloorBag {
  std::string path;
  Eigen::Vector2d mark = Eigen::Vector2d::Zero();
};

struct Arguments {
  std::string waved, output, board = "board_a";
  std::vector<FloorBag> floor;
  std::string database = mocap::config_file("constellations.yaml");
  std::vector<std::string> cameras;
};

// The board's sightings in `bag`: each camera's markers by the board's marker index.
std::vector<BoardSighting> read_sightings(const std::string& path,
                                          const std::vector<std::string>& cameras,
                                          const mocap::constellations::ConstellationModel& board) {
  mocap::bag::BagReader reader(path);
  std::map<std::string, size_t> camera_of_topic;
  std::vector<std::string> wanted;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const std::string topic =
        mocap::topics::member_of(mocap::topics::kVolumeConstellations, cameras[c]);
    camera_of_topic[topic] = c;
    wanted.push_back(topic);
  }
  reader.set_topic_filter(wanted);
  const mocap::MessageType& type = mocap::message_type<mocap_msgs::msg::ConstellationArray>();
  std::vector<BoardSighting> sightings;
  mocap::bag::BagMessage message;
  mocap_msgs::msg::ConstellationArray array;
  size_t undecodable = 0;
  while (reader.next(message)) {
    try {
      type.deserialize(message.data, &array);
    } catch (const mocap::SerializationError&) {
      ++undecodable;
      continue;
    }
    if (auto sighting =
            mocap::volume::board_sighting(array, camera_of_topic.at(message.topic->name), board)) {
      sightings.push_back(std::move(*sighting));
    }
  }
  for (const std::string& problem : reader.problems())
    fmt::print(stderr, "{}: {}\n", path, problem);
  if (undecodable > 0)
    fmt::print(stderr, "{}: {} messages could not be decoded\n", path, undecodable);
  std::vector<size_t> per_camera(cameras.size(), 0);
  for (const BoardSighting& s : sightings) ++per_camera[s.camera];
  std::string counts;
  for (size_t c = 0; c < cameras.size(); ++c) {
    counts += fmt::format("{}{} {}", c ? ", " : "", cameras[c], per_camera[c]);
  }
  fmt::print("{}: {} sightings of {} ({})\n", path, sightings.size(), board.name, counts);
  return sightings;
}

// How the waved session covered each camera's image (calibration_coverage.hpp), as the
// coverage component shows it live: what a poor solve of one camera comes from.
void print_coverage(const std::vector<BoardSighting>& waved,
                    const std::vector<mocap::calibration::CameraFile>& files) {
  std::vector<mocap::volume::CoverageCamera> cameras;
  for (const auto& file : files) {
    cameras.push_back({file.name, {file.model->width(), file.model->height()}});
  }
  mocap::volume::CalibrationCoverage coverage(cameras);
  for (const BoardSighting& sighting : waved) coverage.add(sighting);
  for (size_t c = 0; c < coverage.camera_count(); ++c) {
    const auto& camera = coverage.camera(c);
    fmt::print("waved coverage: {} {}{}{}\n", camera.name,
               mocap::volume::progress_bar(camera.progress),
               camera.missing.empty() ? "" : ": missing ", fmt::join(camera.missing, ", "));
  }
}

// BAG or BAG:X,Y. A path whose last ':' is not followed by a mark is all path.
std::optional<FloorBag> floor_bag(const std::string& argument) {
  const size_t colon = argument.rfind(':');
  if (colon == std::string::npos) return FloorBag{argument};
  const std::string mark = argument.substr(colon + 1);
  const size_t comma = mark.find(',');
  if (comma == std::string::npos) return FloorBag{argument};
  try {
    size_t x_end = 0, y_end = 0;
    const double x = std::stod(mark.substr(0, comma), &x_end);
    const double y = std::stod(mark.substr(comma + 1), &y_end);
    if (x_end != comma || y_end != mark.size() - comma - 1 || !std::isfinite(x) ||
        !std::isfinite(y)) {
      return std::nullopt;
    }
    return FloorBag{argument.substr(0, colon), Eigen::Vector2d(x, y)};
  } catch (const std::logic_error&) {  // std::stod's invalid_argument, out_of_range
    return std::nullopt;
  }
}

int run(const Arguments& arguments) {
  std::vector<mocap::calibration::CameraFile> files;
  std::vector<mocap::volume::CalibrationCamera> cameras;
  std::vector<std::string> names;
  for (const std::string& path : arguments.cameras) {
    files.push_back(mocap::calibration::load_camera_file(path));
    cameras.push_back({files.back().name, files.back().model});
    names.push_back(files.back().name);
  }
  const auto database = mocap::constellations::load_database(arguments.database);
  const mocap::constellations::ConstellationModel* board = database.find(arguments.board);
  if (board == nullptr) {
    fmt::print(stderr, "--board: no board '{}' in {}\n", arguments.board, arguments.database);
    return 2;
  }
  const auto waved = read_sightings(arguments.waved, names, *board);
  print_coverage(waved, files);
  std::vector<mocap::volume::FloorPlacement> floor;
  for (const FloorBag& bag : arguments.floor) {
    floor.push_back({bag.mark, read_sightings(bag.path, names, *board)});
  }

  mocap::volume::VolumeCalibration result;
  try {
    result = mocap::volume::calibrate_volume(cameras, board->points, waved, floor);
  } catch (const mocap::volume::VolumeCalibrationError& e) {
    fmt::print(stderr, "cannot calibrate the volume: {}\n", e.what());
    return 1;
  }
  fmt::print(
      "waved: {} capture times with the board whole in two cameras or more; RMS "
      "reprojection error {:.3f} px over {} points ({} iterations)\n",
      result.frames_used, result.report.rms_px, result.report.points, result.report.iterations);
  for (size_t p = 0; p < floor.size(); ++p) {
    const auto& placement = result.floor[p];
    fmt::print("floor at ({}, {}): the board seen by {} cameras, RMS {:.3f} px", floor[p].mark.x(),
               floor[p].mark.y(), placement.cameras, placement.rms_px);
    if (floor.size() > 1) fmt::print("; {:.3f} mm from its mark", placement.off_mark_m * 1e3);
    fmt::print("\n");
  }
  std::filesystem::create_directories(arguments.output);
  for (size_t c = 0; c < files.size(); ++c) {
    const Eigen::Isometry3d world_from_camera = result.camera_from_world[c].inverse();
    std::string against;
    if (files[c].world_from_camera) {
      const Eigen::Isometry3d& before = *files[c].world_from_camera;
      against = fmt::format(
          "; {:.2f} mm and {:.4f} deg from the input file's pose",
          (world_from_camera.translation() - before.translation()).norm() * 1e3,
          Eigen::AngleAxisd(world_from_camera.linear() * before.linear().transpose()).angle() *
              180 / M_PI);
    }
    files[c].world_from_camera = world_from_camera;
    const auto path = std::filesystem::path(arguments.output) /
                      std::filesystem::path(arguments.cameras[c]).filename();
    mocap::calibration::save_camera_file(path.string(), files[c]);
    const Eigen::Vector3d p = world_from_camera.translation();
    fmt::print("{}: at ({:.4f}, {:.4f}, {:.4f}) m{} -> {}\n", names[c], p.x(), p.y(), p.z(),
               against, path.string());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments arguments;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        fmt::print(stderr, "{} needs a value\n{}", argument, kUsage);
        std::exit(2);
      }
      return argv[++i];
    };
    if (argument == "--waved") {
      arguments.waved = value();
    } else if (argument == "--floor") {
      std::optional<FloorBag> bag = floor_bag(value());
      if (!bag) {
        fmt::print(stderr, "--floor {}: the mark after ':' is not X,Y in metres\n", argv[i]);
        return 2;
      }
      arguments.floor.push_back(*bag);
    } else if (argument == "--output") {
      arguments.output = value();
    } else if (argument == "--board") {
      arguments.board = value();
    } else if (argument == "--database") {
      arguments.database = value();
    } else if (argument == "-h" || argument == "--help") {
      fmt::print("{}", kUsage);
      return 0;
    } else if (argument.starts_with("--")) {
      fmt::print(stderr, "unknown option {}\n{}", argument, kUsage);
      return 2;
    } else {
      arguments.cameras.push_back(argument);
    }
  }
  if (arguments.waved.empty() || arguments.floor.empty() || arguments.output.empty() ||
      arguments.cameras.empty()) {
    fmt::print(stderr, "--waved, --floor, --output and camera files are needed\n{}", kUsage);
    return 2;
  }
  try {
    return run(arguments);
  } catch (const std::exception& e) {  // unreadable bags, camera files, databases
    fmt::print(stderr, "{}\n", e.what());
    return 2;
  }
}
