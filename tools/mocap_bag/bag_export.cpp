#include "mocap_bag/bag_export.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "recording/motion_export/c3d_writer.hpp"
#include "recording/motion_export/motive_csv_writer.hpp"
#include "recording/motion_export/point_table.hpp"
#include "recording/motion_export/trc_writer.hpp"
#include "recording/motion_export/tum_writer.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/swarm/swarm_database.hpp"

namespace mocap::bag_export {
namespace {

using motion_export::BodyTrajectories;
using motion_export::MarkerTrajectories;

// "[=====>     ] 42 %" on one line of stderr, redrawn as it grows; nothing when stderr is no
// terminal (a log keeps the summary only).
class ProgressBar {
 public:
  explicit ProgressBar(uint64_t total) : total_(total), shown_(isatty(STDERR_FILENO) == 1) {}
  ~ProgressBar() {
    if (shown_ && drawn_ >= 0) fmt::print(stderr, "\n");
  }
  void at(uint64_t done) {
    if (!shown_ || total_ == 0) return;
    const int percent = static_cast<int>(100 * std::min(done, total_) / total_);
    if (percent == drawn_) return;
    drawn_ = percent;
    const int width = 40, filled = percent * width / 100;
    fmt::print(stderr, "\r[{}{}] {:3d} %", std::string(static_cast<size_t>(filled), '='),
               std::string(static_cast<size_t>(width - filled), ' '), percent);
  }

 private:
  uint64_t total_;
  bool shown_;
  int drawn_ = -1;
};

// What an export writes: the bodies of the poses topic and, when asked, the markers of the cloud.
struct Recording {
  BodyTrajectories bodies;
  MarkerTrajectories markers;
  std::vector<int64_t> frames;  // every pose array's and cloud's stamp
};

// The names a cloud's `body` index stands for: the fusion's bodies then its robots.
std::vector<std::string> cloud_body_names(const ExportOptions& options) {
  std::vector<std::string> names;
  if (options.bodies_file) {
    for (const volume::RigidBody& body :
         volume::load_rigid_bodies(*options.bodies_file, 0, volume::kNoConfusionCheck).bodies) {
      names.push_back(body.name);
    }
  }
  if (options.robots_file) {
    for (const volume::SwarmRobot& robot : volume::load_swarm(*options.robots_file, 0).robots) {
      names.push_back(robot.name);
    }
  }
  return names;
}

const bag::BagTopic& topic_in(const bag::BagReader& reader, const std::string& path,
                              const std::string& name) {
  std::vector<std::string> names;
  for (const bag::BagTopic& topic : reader.metadata().topics) {
    if (topic.name == name && topic.message_count > 0) return topic;
    names.push_back(topic.name);
  }
  throw std::runtime_error(fmt::format("{}: no {} messages in the bag (its topics: {})", path, name,
                                       fmt::join(names, ", ")));
}

Recording read_bag(const std::string& path, const ExportOptions& options) {
  bag::BagReader reader(path);
  uint64_t total = topic_in(reader, path, options.poses_topic).message_count;
  std::vector<std::string> body_names;
  if (options.markers) {
    total += topic_in(reader, path, options.markers_topic).message_count;
    body_names = cloud_body_names(options);
    reader.set_topic_filter({options.poses_topic, options.markers_topic});
  } else {
    reader.set_topic_filter({options.poses_topic});
  }
  const MessageType& poses_type = message_type<mocap_msgs::msg::ConstellationPoseArray>();
  const MessageType& cloud_type = message_type<sensor_msgs::msg::PointCloud2>();
  Recording recording;
  ProgressBar progress(total);
  bag::BagMessage message;
  mocap_msgs::msg::ConstellationPoseArray array;
  sensor_msgs::msg::PointCloud2 cloud;
  uint64_t read = 0, undecodable = 0;
  std::set<int32_t> unnamed_bodies;
  while (reader.next(message)) {
    progress.at(++read);
    const bool is_poses = message.topic->name == options.poses_topic;
    try {
      (is_poses ? poses_type : cloud_type)
          .deserialize(message.data,
                       is_poses ? static_cast<void*>(&array) : static_cast<void*>(&cloud));
    } catch (const SerializationError&) {
      ++undecodable;
      continue;
    }
    if (is_poses) {
      const int64_t stamp = to_nanoseconds(array.header().stamp());
      recording.frames.push_back(stamp);
      for (const auto& pose : array.poses()) {
        recording.bodies.add(pose.name(), stamp, to_isometry(pose.pose().pose()));
      }
      continue;
    }
    const auto markers = markers_from_point_cloud(cloud);
    if (!markers) {
      ++undecodable;
      continue;
    }
    const int64_t stamp = to_nanoseconds(cloud.header().stamp());
    recording.frames.push_back(stamp);
    for (const LabeledMarker& marker : *markers) {
      motion_export::MarkerKey key{"", marker.id};
      if (marker.body >= 0) {
        const auto body = static_cast<size_t>(marker.body);
        if (body >= body_names.size()) unnamed_bodies.insert(marker.body);
        key = {body < body_names.size() ? body_names[body] : fmt::format("body{}", marker.body),
               marker.marker};
      }
      recording.markers.add(key, {stamp, marker.position.cast<double>(), marker.cameras});
    }
  }
  for (const std::string& problem : reader.problems())
    fmt::print(stderr, "{}: {}\n", path, problem);
  if (undecodable > 0) {
    fmt::print(stderr, "{}: {} messages could not be decoded\n", path, undecodable);
  }
  if (!unnamed_bodies.empty()) {
    fmt::print(stderr,
               "mocap_bag: the markers of {} bodies named by their index (body{}...): give "
               "--bodies-file and --robots-file as the recording's fusion had them\n",
               unnamed_bodies.size(), *unnamed_bodies.begin());
  }
  return recording;
}

// One <body>.tum per body in the output folder.
int write_tum_files(const std::string& path, const ExportOptions& options,
                    const Recording& recording, const std::vector<std::string>& bodies) {
  const std::filesystem::path folder =
      options.output.value_or(std::filesystem::path(path).filename().string() + "_tum");
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) {
    fmt::print(stderr, "mocap_bag: -o {}: {}\n", folder.string(), error.message());
    return 1;
  }
  for (const std::string& body : bodies) {
    const std::filesystem::path file = folder / (body + ".tum");
    std::ofstream out(file);
    motion_export::write_tum(out, body, recording.bodies.bodies().at(body));
    if (!out.flush()) {
      fmt::print(stderr, "mocap_bag: cannot write {}\n", file.string());
      return 1;
    }
    fmt::print("{}: {} poses\n", file.string(), recording.bodies.bodies().at(body).size());
  }
  return 0;
}

// One file of points: the markers, then each body's virtual points.
int write_points_file(const std::string& path, const ExportOptions& options,
                      const Recording& recording, const std::vector<std::string>& bodies) {
  motion_export::PointTable table = motion_export::make_point_table(recording.frames);
  if (options.markers) motion_export::add_marker_points(table, recording.markers);
  const size_t markers = table.points.size();
  for (const std::string& body : bodies) {
    motion_export::add_body_points(table, body, recording.bodies.bodies().at(body));
  }
  const std::filesystem::path file = options.output.value_or(
      std::filesystem::path(path).filename().string() + "." + options.format);
  std::ofstream out(file, std::ios::binary);
  try {
    if (options.format == "c3d") {
      motion_export::write_c3d(out, table);
    } else {
      motion_export::write_trc(out, file.filename().string(), table);
    }
  } catch (const motion_export::C3dError& e) {
    fmt::print(stderr, "mocap_bag: {}: {}\n", file.string(), e.what());
    return 1;
  }
  if (!out.flush()) {
    fmt::print(stderr, "mocap_bag: cannot write {}\n", file.string());
    return 1;
  }
  fmt::print("{}: {} frames at {:.3f} Hz, {} markers, {} bodies as {} points\n", file.string(),
             table.frames.size(), table.rate_hz, markers, bodies.size(), 4 * bodies.size());
  return 0;
}

// One Motive CSV file: the bodies, then the markers.
int write_csv_file(const std::string& path, const ExportOptions& options,
                   const Recording& recording, const std::vector<std::string>& bodies) {
  const std::filesystem::path file =
      options.output.value_or(std::filesystem::path(path).filename().string() + ".csv");
  std::ofstream out(file, std::ios::binary);
  const size_t rows = motion_export::write_motive_csv(
      out, std::filesystem::path(path).filename().string(), recording.frames, recording.bodies,
      bodies, recording.markers);
  if (!out.flush()) {
    fmt::print(stderr, "mocap_bag: cannot write {}\n", file.string());
    return 1;
  }
  fmt::print("{}: {} frames, {} bodies, {} markers\n", file.string(), rows, bodies.size(),
             recording.markers.markers().size());
  return 0;
}

}  // namespace

int export_bag(const std::string& path, const ExportOptions& options) {
  if (options.format != "c3d" && options.format != "trc" && options.format != "csv" &&
      options.format != "tum") {
    fmt::print(stderr, "mocap_bag: --format {}: expected c3d, trc, csv or tum\n", options.format);
    return 2;
  }
  if (options.markers && options.format == "tum") {
    fmt::print(stderr, "mocap_bag: --markers: TUM files hold poses only\n");
    return 2;
  }
  Recording recording;
  try {
    recording = read_bag(path, options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_bag: {}\n", e.what());
    return 1;
  }
  std::vector<std::string> known;
  for (const auto& [name, poses] : recording.bodies.bodies()) known.push_back(name);
  std::vector<std::string> bodies = options.bodies.empty() ? known : options.bodies;
  for (const std::string& body : bodies) {
    if (!recording.bodies.bodies().count(body)) {
      fmt::print(stderr, "mocap_bag: --bodies {}: not in {} (its bodies: {})\n", body, path,
                 fmt::join(known, ", "));
      return 1;
    }
  }
  int written = 0;
  if (options.format == "tum") {
    written = write_tum_files(path, options, recording, bodies);
  } else if (options.format == "csv") {
    written = write_csv_file(path, options, recording, bodies);
  } else {
    written = write_points_file(path, options, recording, bodies);
  }
  if (written != 0) return written;
  if (recording.bodies.invalid_poses() > 0) {
    fmt::print(stderr, "mocap_bag: {} poses that were no pose left out\n",
               recording.bodies.invalid_poses());
  }
  return 0;
}

}  // namespace mocap::bag_export
