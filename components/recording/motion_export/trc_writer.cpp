#include "recording/motion_export/trc_writer.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace mocap::motion_export {
namespace {

Eigen::Vector3d y_up(const Eigen::Vector3d& world) { return {world.x(), world.z(), -world.y()}; }

double frame_rate(const std::vector<int64_t>& frames) {
  if (frames.size() < 2) return 0;
  std::vector<int64_t> intervals;
  for (size_t i = 1; i < frames.size(); ++i) intervals.push_back(frames[i] - frames[i - 1]);
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  const int64_t median = intervals[intervals.size() / 2];
  return median > 0 ? 1e9 / static_cast<double>(median) : 0;
}

}  // namespace

void write_trc(std::ostream& out, const std::string& file_name,
               const BodyTrajectories& trajectories, const std::vector<std::string>& bodies) {
  const std::vector<int64_t>& frames = trajectories.frames();
  const double rate = frame_rate(frames);
  const size_t markers = 4 * bodies.size();
  fmt::print(out, "PathFileType\t4\t(X/Y/Z)\t{}\n", file_name);
  fmt::print(out,
             "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
             "OrigDataStartFrame\tOrigNumFrames\n");
  fmt::print(out, "{:.6f}\t{:.6f}\t{}\t{}\tm\t{:.6f}\t1\t{}\n", rate, rate, frames.size(), markers,
             rate, frames.size());
  std::string names = "Frame#\tTime", axes = "\t";
  for (const std::string& body : bodies) {
    for (const char* point : {"origin", "x", "y", "z"}) {
      names += fmt::format("\t{}_{}\t\t", body, point);
    }
  }
  for (size_t m = 1; m <= markers; ++m) axes += fmt::format("\tX{}\tY{}\tZ{}", m, m, m);
  fmt::print(out, "{}\n{}\n\n", names, axes);

  // Each body's pose by frame stamp.
  std::vector<std::map<int64_t, const StampedPose*>> posed(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (const StampedPose& pose : trajectories.bodies().at(bodies[b])) {
      posed[b][pose.stamp_ns] = &pose;
    }
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    std::string row = fmt::format("{}\t{:.9f}", f + 1, (frames[f] - frames[0]) * 1e-9);
    for (size_t b = 0; b < bodies.size(); ++b) {
      const auto found = posed[b].find(frames[f]);
      if (found == posed[b].end()) {
        row += std::string(12, '\t');  // four points' x y z, missing
        continue;
      }
      const Eigen::Isometry3d& pose = found->second->world_from_body;
      for (const Eigen::Vector3d& point :
           {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(kAxisLength, 0, 0),
            Eigen::Vector3d(0, kAxisLength, 0), Eigen::Vector3d(0, 0, kAxisLength)}) {
        const Eigen::Vector3d p = y_up(pose * point);
        row += fmt::format("\t{:.9f}\t{:.9f}\t{:.9f}", p.x(), p.y(), p.z());
      }
    }
    fmt::print(out, "{}\n", row);
  }
}

}  // namespace mocap::motion_export
