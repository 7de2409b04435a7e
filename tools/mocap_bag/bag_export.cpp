#include "mocap_bag/bag_export.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/message_time.hpp>
#include <mocap/message_type.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

#include "common/pose_message/pose_message.hpp"
#include "recording/motion_export/body_trajectories.hpp"
#include "recording/motion_export/trc_writer.hpp"
#include "recording/motion_export/tum_writer.hpp"

namespace mocap::bag_export {
namespace {

using motion_export::BodyTrajectories;

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

BodyTrajectories read_poses(const std::string& path, const ExportOptions& options) {
  bag::BagReader reader(path);
  const bag::BagTopic* topic = nullptr;
  std::vector<std::string> names;
  for (const bag::BagTopic& t : reader.metadata().topics) {
    names.push_back(t.name);
    if (t.name == options.poses_topic) topic = &t;
  }
  if (topic == nullptr || topic->message_count == 0) {
    throw std::runtime_error(fmt::format("{}: no {} messages in the bag (its topics: {})", path,
                                         options.poses_topic, fmt::join(names, ", ")));
  }
  reader.set_topic_filter({options.poses_topic});
  const MessageType& type = message_type<mocap_msgs::msg::ConstellationPoseArray>();
  BodyTrajectories trajectories;
  ProgressBar progress(topic->message_count);
  bag::BagMessage message;
  mocap_msgs::msg::ConstellationPoseArray array;
  uint64_t read = 0, undecodable = 0;
  while (reader.next(message)) {
    progress.at(++read);
    try {
      type.deserialize(message.data, &array);
    } catch (const SerializationError&) {
      ++undecodable;
      continue;
    }
    trajectories.add_frame(to_nanoseconds(array.header().stamp()));
    for (const auto& pose : array.poses()) {
      trajectories.add(pose.name(), to_nanoseconds(array.header().stamp()),
                       to_isometry(pose.pose().pose()));
    }
  }
  for (const std::string& problem : reader.problems())
    fmt::print(stderr, "{}: {}\n", path, problem);
  if (undecodable > 0) {
    fmt::print(stderr, "{}: {} {} messages could not be decoded\n", path, undecodable,
               options.poses_topic);
  }
  return trajectories;
}

// One <body>.tum per body in the output folder.
int write_tum_files(const std::string& path, const ExportOptions& options,
                    const BodyTrajectories& trajectories, const std::vector<std::string>& bodies) {
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
    motion_export::write_tum(out, body, trajectories.bodies().at(body));
    if (!out.flush()) {
      fmt::print(stderr, "mocap_bag: cannot write {}\n", file.string());
      return 1;
    }
    fmt::print("{}: {} poses\n", file.string(), trajectories.bodies().at(body).size());
  }
  return 0;
}

// One .trc file of every body's virtual points.
int write_trc_file(const std::string& path, const ExportOptions& options,
                   const BodyTrajectories& trajectories, const std::vector<std::string>& bodies) {
  const std::filesystem::path file =
      options.output.value_or(std::filesystem::path(path).filename().string() + ".trc");
  std::ofstream out(file);
  motion_export::write_trc(out, file.filename().string(), trajectories, bodies);
  if (!out.flush()) {
    fmt::print(stderr, "mocap_bag: cannot write {}\n", file.string());
    return 1;
  }
  fmt::print("{}: {} frames, {} bodies as {} points\n", file.string(), trajectories.frames().size(),
             bodies.size(), 4 * bodies.size());
  return 0;
}

}  // namespace

int export_bag(const std::string& path, const ExportOptions& options) {
  if (options.format != "tum" && options.format != "trc") {
    fmt::print(stderr, "mocap_bag: --format {}: expected tum or trc (c3d and csv are to come)\n",
               options.format);
    return 2;
  }
  BodyTrajectories trajectories;
  try {
    trajectories = read_poses(path, options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_bag: {}\n", e.what());
    return 1;
  }
  std::vector<std::string> known;
  for (const auto& [name, poses] : trajectories.bodies()) known.push_back(name);
  std::vector<std::string> bodies = options.bodies.empty() ? known : options.bodies;
  for (const std::string& body : bodies) {
    if (!trajectories.bodies().count(body)) {
      fmt::print(stderr, "mocap_bag: --bodies {}: not in {} (its bodies: {})\n", body, path,
                 fmt::join(known, ", "));
      return 1;
    }
  }
  const int written = options.format == "tum" ? write_tum_files(path, options, trajectories, bodies)
                                              : write_trc_file(path, options, trajectories, bodies);
  if (written != 0) return written;
  if (trajectories.invalid_poses() > 0) {
    fmt::print(stderr, "mocap_bag: {} poses that were no pose left out\n",
               trajectories.invalid_poses());
  }
  return 0;
}

}  // namespace mocap::bag_export
