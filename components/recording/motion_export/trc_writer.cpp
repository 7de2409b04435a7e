#include "recording/motion_export/trc_writer.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace mocap::motion_export {

void write_trc(std::ostream& out, const std::string& file_name, const PointTable& table) {
  const size_t frames = table.frames.size(), markers = table.points.size();
  fmt::print(out, "PathFileType\t4\t(X/Y/Z)\t{}\n", file_name);
  fmt::print(out,
             "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
             "OrigDataStartFrame\tOrigNumFrames\n");
  fmt::print(out, "{:.6f}\t{:.6f}\t{}\t{}\tm\t{:.6f}\t1\t{}\n", table.rate_hz, table.rate_hz,
             frames, markers, table.rate_hz, frames);
  std::string names = "Frame#\tTime", axes = "\t";
  for (const PointColumn& point : table.points) names += fmt::format("\t{}\t\t", point.name);
  for (size_t m = 1; m <= markers; ++m) axes += fmt::format("\tX{}\tY{}\tZ{}", m, m, m);
  fmt::print(out, "{}\n{}\n\n", names, axes);

  PointRows rows(table);
  std::string row;
  for (uint32_t f = 0; f < frames; ++f) {
    rows.go_to(f);
    row = fmt::format("{}\t{:.9f}", f + 1, (table.frames[f] - table.frames[0]) * 1e-9);
    for (size_t m = 0; m < markers; ++m) {
      if (const PointSample* sample = rows.at(m)) {
        // OpenSim's Y up.
        const Eigen::Vector3d& p = sample->position;
        fmt::format_to(std::back_inserter(row), "\t{:.9f}\t{:.9f}\t{:.9f}", p.x(), p.z(), -p.y());
      } else {
        row += "\t\t\t";
      }
    }
    row += '\n';
    out << row;
  }
}

}  // namespace mocap::motion_export
